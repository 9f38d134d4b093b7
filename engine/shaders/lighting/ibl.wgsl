// Lighting shader, part 5 of 6: image-based lighting (the split sum, and filtered importance
// sampling of the radiance chain).

// World direction to environment-map direction (the rotation about +Y, as skybox.wgsl).
fn environment_direction(d: vec3<f32>) -> vec3<f32> {
    let c = u.ibl.z;
    let s = u.ibl.w;
    return vec3<f32>(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

fn ibl_irradiance_at(n: vec3<f32>) -> vec3<f32> {
    return textureSampleLevel(ibl_irradiance, ibl_sampler, environment_direction(n), 0.0).rgb;
}

fn ibl_prefiltered(r: vec3<f32>, roughness: f32) -> vec3<f32> {
    let lod = clamp(roughness, 0.0, 1.0) * u.ibl.y;
    return textureSampleLevel(ibl_specular, ibl_sampler, environment_direction(r), lod).rgb;
}

// The radiance chain's (binding 19) level-0 texel solid angle and top level, asked once per
// pixel.
struct RadianceChain {
    texel_solid_angle: f32,
    top: f32,
}

fn radiance_chain() -> RadianceChain {
    let size = f32(textureDimensions(ibl_radiance).x);
    return RadianceChain(4.0 * PI / (6.0 * size * size), f32(textureNumLevels(ibl_radiance) - 1u));
}

fn ibl_radiance_at(chain: RadianceChain, l: vec3<f32>, sample_solid_angle: f32) -> vec3<f32> {
    let footprint = IBL_FOOTPRINT * sample_solid_angle;
    let lod = clamp(0.5 * log2(footprint / chain.texel_solid_angle), 0.0, chain.top);
    return textureSampleLevel(ibl_radiance, ibl_sampler, environment_direction(l), lod).rgb;
}

// The PBR specular IBL by filtered importance sampling (Krivanek and Colbert 2008): `samples`
// (IBL_SAMPLES, or IBL_ANISOTROPIC_SAMPLES on anisotropic pixels) samples of the GGX lobe
// (anisotropic where the surface is; the stretched-slope sampling of Heitz's "Understanding the
// Masking-Shadowing Function", so the pdf is D(h) n.h), stratified in the radial variable and
// radical-inverse in the angle, each weighted by F V 4 v.h n.l / n.h and read from the radiance
// chain (the environment box-filtered, not GGX-prefiltered: a read blurs its footprint once) at
// the level whose texels cover IBL_FOOTPRINT times the sample's solid angle 1 / (N pdf): lod =
// log2(that / a level-0 texel's solid angle) / 2. Krivanek and Colbert read one level up (a
// footprint of 4); the IBL sweep measured 1 closer to the path tracer under both shipped skies.
// Unlike the split sum, the lobe follows the view.
fn ibl_specular_sampled(s: Surface, v: vec3<f32>, f0: vec3<f32>, samples: u32) -> vec3<f32> {
    let n = s.normal;
    let n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    let alpha = s.roughness * s.roughness + 0.001;
    var t: vec3<f32>;
    var at = alpha;
    var ab = alpha;
    let anisotropic = ANISOTROPY && s.anisotropy != 0.0;
    if anisotropic {
        // Sampling needs an orthonormal frame: the stored tangent, made perpendicular to n.
        t = safe_normalize(s.tangent - n * dot(n, s.tangent), s.tangent);
        at = max(alpha * (1.0 + s.anisotropy), 0.001);
        ab = max(alpha * (1.0 - s.anisotropy), 0.001);
    } else {
        let up = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), abs(n.z) < 0.999);
        t = normalize(cross(up, n));
    }
    let b = cross(n, t);
    let count = f32(samples);
    let chain = radiance_chain();
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < samples; i++) {
        let u1 = (f32(i) + 0.5) / count;
        let u2 = f32(reverseBits(i)) * 2.3283064365386963e-10;
        let slope = sqrt(u1 / (1.0 - u1));
        let phi = 2.0 * PI * u2;
        let local = normalize(vec3<f32>(at * slope * cos(phi), ab * slope * sin(phi), 1.0));
        let h = normalize(t * local.x + b * local.y + n * local.z);
        let v_dot_h = dot(v, h);
        if v_dot_h <= 0.0 {
            continue;
        }
        let l = 2.0 * v_dot_h * h - v;
        let n_dot_l = dot(n, l);
        if n_dot_l <= 0.0 {
            continue;
        }
        let n_dot_h = max(local.z, 1e-4);
        var d: f32;
        var vis: f32;
        if anisotropic {
            d = d_ggx_anisotropic(at, ab, local.x, local.y, n_dot_h);
            vis = v_smith_ggx_correlated_anisotropic(
                at, ab, dot(t, v), dot(b, v), dot(t, l), dot(b, l), n_dot_v, n_dot_l);
        } else {
            d = d_ggx(n, h, n_dot_h, alpha);
            vis = v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha);
        }
        let pdf = max(d * n_dot_h / (4.0 * v_dot_h), 1e-6);
        let fresnel = f0 + (vec3<f32>(1.0) - f0) * pow5(1.0 - v_dot_h);
        sum += ibl_radiance_at(chain, l, 1.0 / (count * pdf)) * fresnel * (vis * 4.0 * v_dot_h * n_dot_l / n_dot_h);
    }
    return sum / count;
}

// The split sum of an anisotropic pixel as taps of the prefiltered cube (IBL_ANISOTROPIC_TAPS;
// docs/renderer.md has the sweep behind each choice): the lobe stretched along the axis with the
// larger alpha `at` read as ANISOTROPIC_TAPS lookups at half vectors tilted along that axis by
// the stratified quantiles of the GGX slope marginal (`x = spread q / sqrt(1 - q^2)`, q the
// midpoints of -1..1), each lookup's own alpha covering a third of the stretch (so neighbouring
// taps overlap) or the narrow axis's `ab` where that is wider, leaned towards N by Frostbite's
// rule at that alpha, and weighted down where it reflects below the surface (the masking and
// n.l that the true integral applies there; without it the rough taps read up to 2x too bright).
fn ibl_anisotropic_taps(s: Surface, v: vec3<f32>) -> vec3<f32> {
    let n = s.normal;
    let alpha = s.roughness * s.roughness + 0.001;
    let at = alpha * (1.0 + abs(s.anisotropy));
    let ab = alpha * (1.0 - abs(s.anisotropy));
    // `at` lies on the tangent when anisotropy > 0 (ibl_specular_sampled's frame).
    let wide_axis = select(s.tangent, cross(n, s.tangent), s.anisotropy < 0.0);
    let wide = safe_normalize(wide_axis - n * dot(n, wide_axis), wide_axis);
    let stretch = sqrt(max(at * at - ab * ab, 0.0));
    let alpha_tap = min(max(ab, 0.35 * stretch), 1.0);
    let spread = sqrt(max(at * at - alpha_tap * alpha_tap, 0.0));
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < ANISOTROPIC_TAPS; i++) {
        let q = (f32(i) + 0.5) / f32(ANISOTROPIC_TAPS) * 2.0 - 1.0;
        let h = normalize(n + wide * (spread * q / sqrt(1.0 - q * q)));
        let r = reflect(-v, h);
        let horizon = clamp(4.0 * dot(n, r) + 0.5, 0.0, 1.0);
        sum += ibl_prefiltered(frostbite_dominant(n, r, alpha_tap), sqrt(alpha_tap)) * horizon;
    }
    return sum / f32(ANISOTROPIC_TAPS);
}

// Lagarde and de Rousiers' dominant direction of a GGX lobe of alpha `a` about normal `n` with
// mirror direction `r`: (1 - a)(sqrt(1 - a) + a) of the way from `n` to `r`.
fn frostbite_dominant(n: vec3<f32>, r: vec3<f32>, a: f32) -> vec3<f32> {
    return safe_normalize(mix(n, r, (1.0 - a) * (sqrt(1.0 - a) + a)), r);
}

// Lookups per anisotropic pixel of ibl_anisotropic_taps.
const ANISOTROPIC_TAPS: u32 = 4u;

// Whether the surface's lobe is wider than a texel of the prefiltered cube's level 0 (GGX alpha
// against the texel's 2 / size radians): a narrower lobe is the single level-0 lookup of the
// split sum, whatever else the variant does there (samples' solid-angle lod would blur the tail
// samples' reads, and taps would all read the same texel).
fn lobe_wider_than_a_texel(s: Surface) -> bool {
    return s.roughness * s.roughness >= 2.0 / f32(textureDimensions(ibl_specular).x);
}

// Split-sum IBL of the PBR model (unexposed; the caller scales by u.ibl.x); the specular part by
// filtered importance sampling instead when IBL_SAMPLES > 0 (or IBL_ANISOTROPIC_SAMPLES on the
// anisotropic pixels), or by taps on the anisotropic pixels with IBL_ANISOTROPIC_TAPS.
fn pbr_ibl(s: Surface, v: vec3<f32>, occlusion: f32) -> vec3<f32> {
    let n = s.normal;
    let n_dot_v = max(dot(n, v), MIN_N_DOT_V);
    let f0 = vec3<f32>(0.16 * s.specular * s.specular * (1.0 - s.metallic)) + s.base_color * s.metallic;
    // Texel i of the table holds parameter i / (size - 1) (crate::ibl::dfg): remap so that 0 and 1
    // land on the first and last texel centers.
    let dfg_size = vec2<f32>(textureDimensions(ibl_dfg));
    let dfg_uv = (vec2<f32>(n_dot_v, clamp(s.roughness, 0.0, 1.0)) * (dfg_size - 1.0) + 0.5) / dfg_size;
    let dfg = textureSampleLevel(ibl_dfg, ibl_sampler, dfg_uv, 0.0).xy;
    let e = f0 * dfg.x + vec3<f32>(dfg.y);
    // Anisotropy: reflect about a normal bent towards the anisotropic direction (Filament's
    // getReflectedVector), scaled down for smooth surfaces.
    var bent = n;
    if ANISOTROPY && s.anisotropy != 0.0 {
        let b = cross(n, s.tangent);
        let direction = select(s.tangent, b, s.anisotropy >= 0.0);
        let anisotropic_tangent = cross(direction, v);
        let anisotropic_normal = cross(anisotropic_tangent, direction);
        let amount = abs(s.anisotropy) * clamp(5.0 * s.roughness, 0.0, 1.0);
        bent = safe_normalize(mix(n, anisotropic_normal, amount), n);
    }
    // The lobe's dominant direction leans from R towards N as roughness grows: the split sum's
    // N = V = R assumption misses that. Filament's getSpecularDominantDirection leans by
    // roughness^4; Lagarde and de Rousiers' ("Moving Frostbite to PBR", 2014) keep
    // (1 - a)(sqrt(1 - a) + a) of R, a = roughness^2, which leans further.
    let r = reflect(-v, bent);
    var dominant: vec3<f32>;
    if IBL_FROSTBITE_DOMINANT {
        dominant = frostbite_dominant(bent, r, s.roughness * s.roughness);
    } else {
        dominant = safe_normalize(mix(r, bent, s.roughness * s.roughness * s.roughness * s.roughness), r);
    }
    var specular: vec3<f32>;
    // Samples: IBL_SAMPLES on every pixel, or IBL_ANISOTROPIC_SAMPLES on the anisotropic ones
    // (where the split sum is furthest off), else none.
    var samples = IBL_SAMPLES;
    if samples == 0u && ANISOTROPY && s.anisotropy != 0.0 {
        samples = IBL_ANISOTROPIC_SAMPLES;
    }
    // (`&&` short-circuits: a variant without samples or taps makes no size query.)
    if samples > 0u && lobe_wider_than_a_texel(s) {
        specular = ibl_specular_sampled(s, v, f0, samples);
    } else if IBL_ANISOTROPIC_TAPS && ANISOTROPY && s.anisotropy != 0.0 && lobe_wider_than_a_texel(s) {
        specular = ibl_anisotropic_taps(s, v) * e;
    } else {
        specular = ibl_prefiltered(dominant, s.roughness) * e;
    }
    var diffuse = s.base_color * (1.0 - s.metallic) * (vec3<f32>(1.0) - e) * ibl_irradiance_at(n);
    if AMBIENT_OCCLUSION {
        diffuse *= occlusion;
    }
    if !CLEARCOAT {
        return diffuse + specular;
    }
    let clearcoat_fresnel = (0.04 + 0.96 * pow5(1.0 - n_dot_v)) * s.clearcoat;
    let clearcoat = ibl_prefiltered(reflect(-v, n), s.clearcoat_roughness) * clearcoat_fresnel;
    return (diffuse + specular) * (1.0 - clearcoat_fresnel) + clearcoat;
}

