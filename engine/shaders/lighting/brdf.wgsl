// Lighting shader, part 4 of 6: the lighting models' BRDFs times the cosine (PBR with
// clearcoat and anisotropy, Blinn-Phong, Lambert, toon).

fn pow5(x: f32) -> f32 {
    let x2 = x * x;
    return x2 * x2 * x;
}

// GGX normal distribution; 1 - NoH^2 from |n x h|^2 keeps precision near the highlight's peak.
fn d_ggx(n: vec3<f32>, h: vec3<f32>, n_dot_h: f32, alpha: f32) -> f32 {
    let n_cross_h = cross(n, h);
    let a = n_dot_h * alpha;
    let k = alpha / (dot(n_cross_h, n_cross_h) + a * a);
    return k * k * (1.0 / PI);
}

fn v_smith_ggx_correlated(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let lambda_v = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let lambda_l = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / (lambda_v + lambda_l);
}

fn d_ggx_anisotropic(at: f32, ab: f32, t_dot_h: f32, b_dot_h: f32, n_dot_h: f32) -> f32 {
    let a2 = at * ab;
    let d = vec3<f32>(ab * t_dot_h, at * b_dot_h, a2 * n_dot_h);
    let d2 = dot(d, d);
    let b2 = a2 / d2;
    return a2 * b2 * b2 * (1.0 / PI);
}

fn v_smith_ggx_correlated_anisotropic(
    at: f32, ab: f32, t_dot_v: f32, b_dot_v: f32, t_dot_l: f32, b_dot_l: f32,
    n_dot_v: f32, n_dot_l: f32,
) -> f32 {
    let lambda_v = n_dot_l * length(vec3<f32>(at * t_dot_v, ab * b_dot_v, n_dot_v));
    let lambda_l = n_dot_v * length(vec3<f32>(at * t_dot_l, ab * b_dot_l, n_dot_l));
    return 0.5 / (lambda_v + lambda_l);
}

fn pbr_brdf_times_cosine(s: Surface, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    return pbr_brdf_scaled(s, v, l, 1.0, 1.0);
}

// The PBR BRDF times N.L towards a directional light's disc of angular radius (sine, cosine)
// = disc: the specular lobes are evaluated towards the point of the disc closest to the
// reflection vector and scaled by (alpha / alpha')^2 with alpha' = alpha + sin(radius) / 2, the
// representative point and the sphere-light normalisation of Karis, "Real Shading in Unreal
// Engine 4" (SIGGRAPH 2013 course), for a disc at infinity (a half-vector moves half the angle
// its light direction does). Diffuse uses the same point, within the disc's radius of its
// centre (a sun's is about a degree).
fn pbr_disc_times_cosine(s: Surface, v: vec3<f32>, l: vec3<f32>, disc: vec2<f32>) -> vec3<f32> {
    let r = reflect(-v, s.normal);
    let r_dot_l = dot(r, l);
    let edge = l * disc.y + safe_normalize(r - r_dot_l * l, l) * disc.x;
    let towards = normalize(select(edge, r, r_dot_l >= disc.y));
    let alpha = s.roughness * s.roughness + 0.001;
    let base = alpha / min(alpha + 0.5 * disc.x, 1.0);
    let clearcoat_alpha = s.clearcoat_roughness * s.clearcoat_roughness + 0.001;
    let clearcoat = clearcoat_alpha / min(clearcoat_alpha + 0.5 * disc.x, 1.0);
    return pbr_brdf_scaled(s, v, towards, base * base, clearcoat * clearcoat);
}

// The PBR BRDF times N.L, its base specular lobe scaled by specular_scale and its clearcoat lobe
// by clearcoat_scale (1 and 1: the BRDF itself).
fn pbr_brdf_scaled(
    s: Surface, v: vec3<f32>, l: vec3<f32>, specular_scale: f32, clearcoat_scale: f32,
) -> vec3<f32> {
    let n = s.normal;
    let n_dot_l = clamp(dot(n, l), 0.0, 1.0);
    if n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    let h = safe_normalize(v + l, n);
    let n_dot_h = clamp(dot(n, h), 0.0, 1.0);
    let l_dot_h = clamp(dot(l, h), 0.0, 1.0);

    let alpha = s.roughness * s.roughness + 0.001;
    let f0 = vec3<f32>(0.16 * s.specular * s.specular * (1.0 - s.metallic)) + s.base_color * s.metallic;
    let fresnel = f0 + (vec3<f32>(1.0) - f0) * pow5(1.0 - l_dot_h);

    var d: f32;
    var vis: f32;
    if ANISOTROPY && s.anisotropy != 0.0 {
        let t = s.tangent;
        let b = cross(n, t);
        let at = max(alpha * (1.0 + s.anisotropy), 0.001);
        let ab = max(alpha * (1.0 - s.anisotropy), 0.001);
        d = d_ggx_anisotropic(at, ab, dot(t, h), dot(b, h), n_dot_h);
        vis = v_smith_ggx_correlated_anisotropic(
            at, ab, dot(t, v), dot(b, v), dot(t, l), dot(b, l), n_dot_v, n_dot_l);
    } else {
        d = d_ggx(n, h, n_dot_h, alpha);
        vis = v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha);
    }
    let specular = fresnel * (d * vis * specular_scale);
    let k_d = (vec3<f32>(1.0) - fresnel) * (1.0 - s.metallic);
    let diffuse = s.base_color * k_d * (1.0 / PI);
    if !CLEARCOAT {
        return (diffuse + specular) * n_dot_l;
    }

    let clearcoat_alpha = s.clearcoat_roughness * s.clearcoat_roughness + 0.001;
    let clearcoat_fresnel = (0.04 + 0.96 * pow5(1.0 - l_dot_h)) * s.clearcoat;
    let clearcoat_d = d_ggx(n, h, n_dot_h, clearcoat_alpha);
    let clearcoat_v = 0.25 / max(l_dot_h * l_dot_h, 1e-4);
    let clearcoat = clearcoat_d * clearcoat_v * clearcoat_fresnel * clearcoat_scale;

    return ((diffuse + specular) * (1.0 - clearcoat_fresnel) + vec3<f32>(clearcoat)) * n_dot_l;
}

fn blinn_phong_times_cosine(s: Surface, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let n_dot_l = dot(s.normal, l);
    if n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let h = safe_normalize(v + l, s.normal);
    let n_dot_h = max(dot(s.normal, h), 0.0);
    let specular = s.specular * pow(n_dot_h, max(s.specular_exponent, 0.0));
    return s.base_color * n_dot_l + vec3<f32>(specular);
}

fn toon_times_cosine(s: Surface, l: vec3<f32>) -> vec3<f32> {
    let n_dot_l = dot(s.normal, l);
    let band = select(select(0.0, 0.35, n_dot_l > 0.0), select(0.7, 1.0, n_dot_l > 0.8), n_dot_l > 0.4);
    return s.base_color * band;
}

// Shadow term of light slot `i`: only slot 0 of a draw can be shadowed.
fn visibility(i: u32, s: Surface, l: vec3<f32>, light: LightData) -> f32 {
    if SHADOW_KIND == 0u || i != 0u {
        return 1.0;
    }
    return shadow_visibility(s, l, light);
}

// A draw's output: non-negative, and at most its share of FP16_SAFE_MAX, so that the pass's
// additive draws cannot sum past fp16's range to infinity.
fn finish(radiance: vec3<f32>) -> vec4<f32> {
    let share = FP16_SAFE_MAX / f32(DRAWS);
    return vec4<f32>(min(max(radiance, vec3<f32>(0.0)), vec3<f32>(share)), 1.0);
}

const MODEL_PBR: u32 = 0u;
const MODEL_BLINN_PHONG: u32 = 1u;
const MODEL_LAMBERT: u32 = 2u;
const MODEL_TOON: u32 = 3u;

// One light's contribution (BRDF times N.L) for a lighting model.
fn brdf_times_cosine(model: u32, s: Surface, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    switch model {
        case MODEL_PBR: { return pbr_brdf_times_cosine(s, v, l); }
        case MODEL_BLINN_PHONG: { return blinn_phong_times_cosine(s, v, l); }
        case MODEL_LAMBERT: { return s.base_color * (max(dot(s.normal, l), 0.0) / PI); }
        default: { return toon_times_cosine(s, l); }
    }
}

