// Lighting passes of the deferred renderer: one full-screen draw per lighting model (and per
// batch of up to 16 lights), each shading only the pixels whose shader-mask channel is set
// (routed by a depth test, see fs_route), added into the HDR light buffer (RGBA16F) with additive
// blending. Light colors arrive pre-multiplied
// by intensity and exposure, so the light buffer holds exposed radiance and stays inside fp16.
//
// PBR follows Filament (surface_brdf.fs): f_r = (f_d k_d + f_s)(1 - F_c) + f_c with Lambert f_d,
// k_d = (1 - F)(1 - metallic), f_s = D_GGX F_Schlick V_SmithGGXCorrelated (anisotropic D and V
// when anisotropy != 0), clearcoat f_c = D_GGX V_Kelemen F_c with F0 = 0.04, F_c = F_Schlick *
// clearcoat, alpha = roughness^2 + 0.001, F0 = 0.16 specular^2 (1 - metallic) + base metallic.
//
// Image-based lighting (first batch of a draw only) is the split sum, as in Filament's
// light_indirect.fs: specular = prefiltered(R, roughness) * (F0 * DFG.x + DFG.y) and diffuse =
// base (1 - metallic) (1 - E) irradiance / pi (E the specular's directional albedo, so white
// furnace energy is conserved); clearcoat attenuates both by (1 - Fc) and adds its own lobe;
// anisotropy bends the reflection vector, and rough lobes lean towards N (the dominant
// direction). Specular occlusion is left out. Other models get the
// irradiance as diffuse ambient.

// Specialisation: the render plan (engine::plan::LightingVariant) sets these per draw from the
// scene, so that a draw compiles only the code its scene uses; a pipeline per distinct set. The
// defaults are never used as such: every pipeline sets every constant.
// The draw's shadowed light (slot 0): 0 none, 1 directional, 2 point.
override SHADOW_KIND: u32 = 0u;
// Its filter: 0 hard, 1 3x3 PCF, 2 stratified soft, 3 stratified soft without early-out,
// 4 converged soft reference (Vogel, 1024 samples), 5 variance shadow map, 6 Vogel disk,
// 7 one bilinear comparison, 8 four bilinear comparisons (3x3 tent); 7 and 8 are bound a
// linear-filtering comparison sampler.
override SHADOW_FILTER: u32 = 0u;
// Samples of the Vogel-disk filters (6, and 4 at 1024), a constant for the same reason.
override VOGEL_SAMPLES: u32 = 0u;
// Lights in the draw (at most 16), and which types among them.
override LIGHT_COUNT: u32 = 0u;
override DIRECTIONAL_LIGHTS: bool = true;
override POINT_LIGHTS: bool = true;
// Whether a directional light of the draw is a disc (an extracted sun; params.yz = sine and
// cosine of its angular radius): the PBR model widens its highlight to the disc.
override SUN_DISC: bool = false;
// Image-based lighting in this draw (the first draw of a scene with an environment).
override IBL: bool = false;
// Filtered importance samples of the PBR specular IBL per pixel; 0: the split sum.
override IBL_SAMPLES: u32 = 0u;
// Whether any surface of this model can have clearcoat or anisotropy: per-pixel values, so when
// true the shader still branches on the pixel's value.
override CLEARCOAT: bool = true;
override ANISOTROPY: bool = true;
// G-buffer storage: position 0 camera-relative, 1 world, 2 reconstructed from depth; normal
// 0 fp16 xyz, 1 octahedral in xy.
override POSITION_MODE: u32 = 0u;
override NORMAL_MODE: u32 = 0u;
// Cost breakdown (harness bench --breakdown): read the inputs and write their sum, no shading.
override INPUT_FLOOR: bool = false;
// Cost breakdown: every variant with a part taken away still reads all the inputs (as the whole
// pass does), adding them times a uniform zero, so that taking a light away does not also take
// away the reads of the G-buffer targets only it needed, which the input floor already counts.
override KEEP_INPUTS: bool = false;

const PI: f32 = 3.14159265358979;
const MAX_LIGHTS: u32 = 16u;
// Largest value written to the RGBA16F light buffer (fp16 max is 65504).
const FP16_SAFE_MAX: f32 = 65000.0;
const MIN_N_DOT_V: f32 = 1e-4;

struct LightData {
    // w = 0: xyz is the unit direction towards a directional light.
    // w = 1: xyz is a point light's camera-relative position.
    position: vec4<f32>,
    // rgb = color * intensity * exposure, a = radius (point lights).
    color: vec4<f32>,
    // x = 1 / falloff (point lights); y, z = sine and cosine of a directional light's disc
    // radius (0 and 0 for a point at infinity).
    params: vec4<f32>,
}

struct LightingUniforms {
    // One-hot selector of this model's channel in the bound mask target.
    mask_select: vec4<f32>,
    // rgb = uniform ambient radiance * exposure (zero after the first batch); w = 0, a zero
    // the compiler cannot see (KEEP_INPUTS).
    ambient: vec4<f32>,
    // y = 1 to emit unlit albedo (first batch only); x, z, w unused (the batch's light count is
    // LIGHT_COUNT).
    counts: vec4<u32>,
    // IBL: x = environment intensity * exposure (0: none, or not the first batch), y = highest
    // specular lod (roughness 1), z, w = cos and sin of the environment's rotation about +Y.
    ibl: vec4<f32>,
    // World position of the camera (f32), for world-space positions.
    camera_world: vec4<f32>,
    // Clip space to camera-relative world space, for positions from depth.
    inverse_view_proj: mat4x4<f32>,
    lights: array<LightData, 16>,
}

// A uniform buffer: llvmpipe and lavapipe load uniforms as scalars, where read-only storage
// costs a bounds-checked load per pixel (measured: chess's lighting pass 46 ms with storage,
// 13 ms with uniforms, on llvmpipe). Storage was used while the feature switches were uniform
// values: lavapipe then recompiled the shader per draw, specialised on the values that steered
// its branches; those are override constants now (see the top of this file).
@group(0) @binding(0) var<uniform> u: LightingUniforms;
@group(0) @binding(1) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_tangent: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(5) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(6) var shader_mask: texture_2d<f32>;

// The shadow map of the one shadowed light of this draw (draws with a shadowed light hold only
// that light, in slot 0); a 1x1 placeholder otherwise. Its kind, filter and sample count are the
// draw's SHADOW_KIND, SHADOW_FILTER and VOGEL_SAMPLES, not values here.
struct ShadowUniforms {
    // Camera-relative world space to the light's clip space: [0] for a directional light, one
    // per cube face (+X, -X, +Y, -Y, +Z, -Z) for a point light.
    faces: array<mat4x4<f32>, 6>,
    // x unused, y = constant bias (m), z = slope bias (texels), w = normal offset (texels).
    params: vec4<f32>,
    // x unused, y = 1 / map width, z = 1 / map height,
    // w = texel size in meters (directional) or per meter of distance (point).
    map: vec4<f32>,
    // x = soft radius (texels), y = reach of the filter in texels (scales the biases), z, w
    // unused.
    soft: vec4<f32>,
    // VSM: x = minimum variance, y = light-bleeding reduction.
    vsm: vec4<f32>,
}

@group(0) @binding(7) var shadow_map: texture_depth_2d;
@group(0) @binding(8) var shadow_sampler: sampler_comparison;
@group(0) @binding(9) var<uniform> shadow: ShadowUniforms;
// Stratified soft shadows: per-pixel jittered sample offsets (unit disk), 32x32 tile, 8 layers;
// layer 2r + k holds two samples of ring r (ring 3 is the outer one) as (x, y, x, y).
@group(0) @binding(10) var shadow_jitter: texture_2d_array<f32>;
// Variance shadow maps: the blurred moments (depth in r + g, depth^2 in b + a; see shadow.wgsl),
// sampled bilinearly.
@group(0) @binding(11) var shadow_moments: texture_2d<f32>;
@group(0) @binding(12) var moments_sampler: sampler;

// Image-based lighting maps (crate::ibl): irradiance / pi, prefiltered specular with roughness
// r at lod r * u.ibl.y, and the DFG table (x = scale, y = bias; NoV across, roughness down).
@group(0) @binding(13) var ibl_irradiance: texture_cube<f32>;
@group(0) @binding(14) var ibl_specular: texture_cube<f32>;
@group(0) @binding(15) var ibl_dfg: texture_2d<f32>;
@group(0) @binding(16) var ibl_sampler: sampler;

// The depth buffer (D32F, read as an unfilterable float texture: naga's GLSL output cannot
// textureLoad a texture_depth_2d), for positions reconstructed from depth.
@group(0) @binding(17) var scene_depth: texture_2d<f32>;

fn shadow_tap(uv: vec2<f32>, reference: f32, bounds: vec4<f32>) -> f32 {
    return textureSampleCompareLevel(shadow_map, shadow_sampler, clamp(uv, bounds.xy, bounds.zw), reference);
}

// Where a point light's atlas is read for a camera-relative point `p` at `d` = p - light.
struct AtlasTap {
    uv: vec2<f32>,
    reference: f32,
    // Min uv (xy) and max uv (zw) of the face, half a texel in, so taps never read a neighbour.
    bounds: vec4<f32>,
}

fn atlas_tap(p: vec3<f32>, d: vec3<f32>) -> AtlasTap {
    let a = abs(d);
    var face = 0u;
    if a.x >= a.y && a.x >= a.z {
        face = select(1u, 0u, d.x > 0.0);
    } else if a.y >= a.z {
        face = select(3u, 2u, d.y > 0.0);
    } else {
        face = select(5u, 4u, d.z > 0.0);
    }
    let clip = shadow.faces[face] * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    let tile = vec2<f32>(f32(face % 3u), f32(face / 3u));
    let face_uv = clamp(vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5), vec2<f32>(0.0), vec2<f32>(1.0));
    let half_texel = 0.5 * shadow.map.yz;
    var tap: AtlasTap;
    tap.uv = (tile + face_uv) / vec2<f32>(3.0, 2.0);
    tap.reference = clamp(ndc.z, 0.0, 1.0);
    tap.bounds = vec4<f32>(tile / vec2<f32>(3.0, 2.0) + half_texel, (tile + 1.0) / vec2<f32>(3.0, 2.0) - half_texel);
    return tap;
}

// A filtered shadow lookup: the receiver's map coordinates, and for point lights what the soft
// filters need to offset the lookup direction instead (Listing 3 of the Quarantamaula engine
// document), so their kernels
// cross cube-face edges instead of being clamped at them.
struct ShadowLookup {
    uv: vec2<f32>,
    reference: f32,
    bounds: vec4<f32>,
    pixel: vec2<i32>,
    // Point lights: the light's camera-relative position, the receiver minus the light, and two
    // axes perpendicular to it whose length is the soft filter's radius at the receiver.
    light: vec3<f32>,
    d: vec3<f32>,
    axis_u: vec3<f32>,
    axis_v: vec3<f32>,
}

// One tap of a soft filter at `o` in the unit disk (scaled to the soft radius).
fn soft_tap(look: ShadowLookup, o: vec2<f32>) -> f32 {
    if SHADOW_KIND != 2u {
        return shadow_tap(look.uv + o * (shadow.soft.x * shadow.map.yz), look.reference, look.bounds);
    }
    let q = normalize(look.d + o.x * look.axis_u + o.y * look.axis_v) * length(look.d);
    let tap = atlas_tap(look.light + q, q);
    return shadow_tap(tap.uv, tap.reference, tap.bounds);
}

// Stratified soft shadows (GPU Gems 2, ch. 17, as the Quarantamaula engine uses them): the
// outer ring's four samples first; if they agree (all lit or all shadowed) and early-out is on,
// that is the answer; otherwise all sixteen samples are averaged.
fn shadow_soft(look: ShadowLookup, early_out: bool) -> f32 {
    let cell = vec2<i32>(look.pixel.x & 31, look.pixel.y & 31);
    var outer = 0.0;
    for (var k = 0; k < 2; k++) {
        let o = textureLoad(shadow_jitter, cell, 6 + k, 0);
        outer += soft_tap(look, o.xy);
        outer += soft_tap(look, o.zw);
    }
    if early_out && (outer == 0.0 || outer == 4.0) {
        return outer * 0.25;
    }
    var sum = outer;
    for (var layer = 0; layer < 6; layer++) {
        let o = textureLoad(shadow_jitter, cell, layer, 0);
        sum += soft_tap(look, o.xy);
        sum += soft_tap(look, o.zw);
    }
    return sum / 16.0;
}

// Soft filter on a golden-angle (Vogel) disk of VOGEL_SAMPLES samples, no jitter: the `vogel` filter,
// and at 1024 samples the converged reference for sweeps.
fn shadow_vogel(look: ShadowLookup) -> f32 {
    let count = max(i32(VOGEL_SAMPLES), 1);
    var sum = 0.0;
    for (var i = 0; i < count; i++) {
        let r = sqrt((f32(i) + 0.5) / f32(count));
        let angle = f32(i) * 2.39996323;
        sum += soft_tap(look, vec2<f32>(cos(angle), sin(angle)) * r);
    }
    return sum / f32(count);
}

// Variance shadow maps (directional lights): Chebyshev's upper bound on the lit fraction from
// the filtered moments, with a minimum variance and light-bleeding reduction (as the io7m r2
// renderer implements GPU Gems 3, ch. 8).
fn shadow_vsm(look: ShadowLookup) -> f32 {
    let m = textureSampleLevel(shadow_moments, moments_sampler, look.uv, 0.0);
    let mean = m.r + m.g;
    if look.reference <= mean {
        return 1.0;
    }
    let variance = max((m.b + m.a) - mean * mean, shadow.vsm.x);
    let delta = look.reference - mean;
    let p_max = variance / (variance + delta * delta);
    let cut = shadow.vsm.y;
    return clamp((p_max - cut) / (1.0 - cut), 0.0, 1.0);
}

// Filtered comparison of the receiver against the map, by the draw's filter; hard and 3x3 PCF
// taps stay in the map's uv space, clamped inside `bounds` (a point light's face).
fn shadow_lookup(look: ShadowLookup) -> f32 {
    if SHADOW_FILTER == 6u || SHADOW_FILTER == 4u {
        return shadow_vogel(look);
    }
    if SHADOW_FILTER == 5u {
        return shadow_vsm(look);
    }
    if SHADOW_FILTER == 2u || SHADOW_FILTER == 3u {
        return shadow_soft(look, SHADOW_FILTER == 2u);
    }
    if SHADOW_FILTER == 0u || SHADOW_FILTER == 7u {
        return shadow_tap(look.uv, look.reference, look.bounds);
    }
    if SHADOW_FILTER == 8u {
        let h = 0.5 * shadow.map.yz;
        return 0.25 * (shadow_tap(look.uv + vec2<f32>(-h.x, -h.y), look.reference, look.bounds)
            + shadow_tap(look.uv + vec2<f32>(h.x, -h.y), look.reference, look.bounds)
            + shadow_tap(look.uv + vec2<f32>(-h.x, h.y), look.reference, look.bounds)
            + shadow_tap(look.uv + vec2<f32>(h.x, h.y), look.reference, look.bounds));
    }
    var sum = 0.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let offset = vec2<f32>(f32(x), f32(y)) * shadow.map.yz;
            sum += shadow_tap(look.uv + offset, look.reference, look.bounds);
        }
    }
    return sum / 9.0;
}

// Fraction of the light reaching the surface (1 = lit) for the draw's shadowed light.
fn shadow_visibility(s: Surface, l: vec3<f32>, light: LightData) -> f32 {
    if SHADOW_KIND == 0u {
        return 1.0;
    }
    let n_dot_l = clamp(dot(s.normal, l), 0.0, 1.0);
    let tan_theta = min(sqrt(max(1.0 - n_dot_l * n_dot_l, 0.0)) / max(n_dot_l, 1e-4), 10.0);
    // Texel size at the receiver, in meters.
    var texel = shadow.map.w;
    if SHADOW_KIND == 2u {
        texel = shadow.map.w * length(light.position.xyz - s.position);
    }
    // Slope-scaled and normal-offset parts are in texels, times the filter's reach (3x3 PCF
    // reads one texel further out than a single tap, the soft filters their radius further).
    let reach = shadow.soft.y;
    let bias = shadow.params.y + shadow.params.z * texel * tan_theta * reach;
    let p = s.position + s.normal * (shadow.params.w * texel * reach) + l * bias;
    var look: ShadowLookup;
    look.pixel = s.pixel;
    if SHADOW_KIND == 1u {
        let clip = shadow.faces[0] * vec4<f32>(p, 1.0);
        let ndc = clip.xyz / clip.w;
        look.uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        if any(look.uv < vec2<f32>(0.0)) || any(look.uv > vec2<f32>(1.0)) {
            return 1.0;
        }
        // Receivers beyond the casters' far plane compare at the far plane.
        look.reference = min(ndc.z, 1.0);
        look.bounds = vec4<f32>(0.0, 0.0, 1.0, 1.0);
        return shadow_lookup(look);
    }
    let d = p - light.position.xyz;
    let tap = atlas_tap(p, d);
    look.uv = tap.uv;
    look.reference = tap.reference;
    look.bounds = tap.bounds;
    look.light = light.position.xyz;
    look.d = d;
    let n = safe_normalize(d, vec3<f32>(0.0, 0.0, 1.0));
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    let u_axis = normalize(cross(n, helper));
    // The disk is `soft_radius` texels of the face at this direction: a face texel subtends
    // less angle off the face's axis, by about s^1.5 with s = |d| / (largest |d| component).
    let a = abs(d);
    let s_off_axis = length(d) / max(max(a.x, max(a.y, a.z)), 1e-20);
    let radius = shadow.soft.x * texel / (s_off_axis * sqrt(s_off_axis));
    look.axis_u = u_axis * radius;
    look.axis_v = cross(n, u_axis) * radius;
    return shadow_lookup(look);
}

// Invariant: the routing draw and the shading draws of a pass must produce the same depth (0)
// for the equal-depth test.
@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @invariant @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

struct Surface {
    pixel: vec2<i32>,
    position: vec3<f32>,
    roughness: f32,
    normal: vec3<f32>,
    specular: f32,
    tangent: vec3<f32>,
    base_color: vec3<f32>,
    anisotropy: f32,
    metallic: f32,
    clearcoat: f32,
    clearcoat_roughness: f32,
    specular_exponent: f32,
}

// Whether a pixel is not this model's (its shader-mask channel is clear).
fn masked(pixel: vec2<i32>) -> bool {
    return dot(textureLoad(shader_mask, pixel, 0), u.mask_select) < 0.5;
}

// Octahedral decoding (Cigolle et al. 2014) of a unit vector stored as two values in -1..1.
fn octahedral_decode(e: vec2<f32>) -> vec3<f32> {
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if v.z < 0.0 {
        let signs = select(vec2<f32>(-1.0), vec2<f32>(1.0), v.xy >= vec2<f32>(0.0));
        v = vec3<f32>((vec2<f32>(1.0) - abs(v.yx)) * signs, v.z);
    }
    return normalize(v);
}

// The camera-relative position at a pixel, as the G-buffer stores it.
fn surface_position(pixel: vec2<i32>, stored: vec3<f32>) -> vec3<f32> {
    if POSITION_MODE == 0u {
        return stored;
    }
    if POSITION_MODE == 1u {
        return stored - u.camera_world.xyz;
    }
    let size = vec2<f32>(textureDimensions(scene_depth));
    let depth = textureLoad(scene_depth, pixel, 0).r;
    let uv = (vec2<f32>(pixel) + 0.5) / size;
    let clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let relative = u.inverse_view_proj * clip;
    return relative.xyz / relative.w;
}

fn load_surface(pixel: vec2<i32>) -> Surface {
    let p = textureLoad(gbuffer_position, pixel, 0);
    let n = textureLoad(gbuffer_normal, pixel, 0);
    let t = textureLoad(gbuffer_tangent, pixel, 0);
    let a = textureLoad(gbuffer_albedo, pixel, 0);
    let m = textureLoad(gbuffer_material, pixel, 0);
    var s: Surface;
    s.pixel = pixel;
    s.position = surface_position(pixel, p.xyz);
    s.roughness = clamp(p.w, 0.0, 1.0);
    if NORMAL_MODE == 1u {
        s.normal = octahedral_decode(n.xy);
    } else {
        s.normal = normalize(n.xyz);
    }
    s.specular = n.w;
    s.tangent = t.xyz;
    s.base_color = a.rgb;
    s.anisotropy = clamp(a.a, -1.0, 1.0);
    s.metallic = m.x;
    s.clearcoat = m.y;
    s.clearcoat_roughness = clamp(m.z, 0.0, 1.0);
    s.specular_exponent = m.w;
    return s;
}

// Direction to the light (xyz) and the light's radiance at the surface (rgb in the second value).
struct Incoming {
    direction: vec3<f32>,
    radiance: vec3<f32>,
}

fn incoming(light: LightData, s: Surface) -> Incoming {
    var result: Incoming;
    if DIRECTIONAL_LIGHTS && !POINT_LIGHTS {
        result.direction = light.position.xyz;
        result.radiance = light.color.rgb;
        return result;
    }
    let to_light = light.position.xyz - s.position;
    let distance = length(to_light);
    // A light exactly at the surface lights it head-on instead of dividing by zero.
    result.direction = select(s.normal, to_light / distance, distance > 1e-6);
    let ratio = min(distance / max(light.color.a, 1e-6), 1.0);
    let attenuation = max(0.0, 1.0 - pow(ratio, light.params.x));
    result.radiance = light.color.rgb * attenuation;
    if DIRECTIONAL_LIGHTS {
        // A draw with both types picks per light with a select, not a branch: lavapipe would
        // compile a new shader for each draw to specialise a branch on uniform data.
        let directional = light.position.w < 0.5;
        result.direction = select(result.direction, light.position.xyz, directional);
        result.radiance = select(result.radiance, light.color.rgb, directional);
    }
    return result;
}

fn safe_normalize(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(v, v);
    return select(fallback, v * inverseSqrt(length_squared), length_squared > 1e-20);
}

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

fn finish(radiance: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(min(max(radiance, vec3<f32>(0.0)), vec3<f32>(FP16_SAFE_MAX)), 1.0);
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

// The PBR specular IBL by filtered importance sampling (Krivanek and Colbert 2008): IBL_SAMPLES
// samples of the GGX lobe (anisotropic where the surface is; the stretched-slope sampling of
// Heitz's "Understanding the Masking-Shadowing Function", so the pdf is D(h) n.h), stratified in
// the radial variable and radical-inverse in the angle, each weighted by F V 4 v.h n.l / n.h
// and read from the prefiltered cube at the roughness whose lobe (about 4 pi alpha^2 steradians)
// covers the sample's solid angle 1 / (N pdf). Unlike the split sum, the lobe follows the view.
fn ibl_specular_sampled(s: Surface, v: vec3<f32>, f0: vec3<f32>) -> vec3<f32> {
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
    let count = f32(IBL_SAMPLES);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < IBL_SAMPLES; i++) {
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
        let lobe_roughness = sqrt(sqrt(1.0 / (count * pdf) / (4.0 * PI)));
        let fresnel = f0 + (vec3<f32>(1.0) - f0) * pow5(1.0 - v_dot_h);
        sum += ibl_prefiltered(l, lobe_roughness) * fresnel * (vis * 4.0 * v_dot_h * n_dot_l / n_dot_h);
    }
    return sum / count;
}

// Split-sum IBL of the PBR model (unexposed; the caller scales by u.ibl.x); the specular part by
// filtered importance sampling instead when IBL_SAMPLES > 0.
fn pbr_ibl(s: Surface, v: vec3<f32>) -> vec3<f32> {
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
    // The lobe's dominant direction leans from R towards N as roughness grows (Filament's
    // getSpecularDominantDirection): the split sum's N = V = R assumption misses that.
    let r = reflect(-v, bent);
    let dominant = safe_normalize(mix(r, bent, s.roughness * s.roughness * s.roughness * s.roughness), r);
    var specular: vec3<f32>;
    if IBL_SAMPLES > 0u {
        specular = ibl_specular_sampled(s, v, f0);
    } else {
        specular = ibl_prefiltered(dominant, s.roughness) * e;
    }
    let diffuse = s.base_color * (1.0 - s.metallic) * (vec3<f32>(1.0) - e) * ibl_irradiance_at(n);
    if !CLEARCOAT {
        return diffuse + specular;
    }
    let clearcoat_fresnel = (0.04 + 0.96 * pow5(1.0 - n_dot_v)) * s.clearcoat;
    let clearcoat = ibl_prefiltered(reflect(-v, n), s.clearcoat_roughness) * clearcoat_fresnel;
    return (diffuse + specular) * (1.0 - clearcoat_fresnel) + clearcoat;
}

const MODEL_UNLIT: u32 = 4u;

// The lighting pass's input floor: every input `model`'s shading reads, summed into the output,
// and no shading. Unlit reads the albedo only; the others also position and normal (and depth
// where positions come from it), PBR and Blinn-Phong the material target, and the tangent only
// where a material is anisotropic (the only use of it).
fn input_floor(model: u32, pixel: vec2<i32>) -> vec4<f32> {
    var sum = textureLoad(gbuffer_albedo, pixel, 0);
    if model != MODEL_UNLIT {
        sum += textureLoad(gbuffer_position, pixel, 0) + textureLoad(gbuffer_normal, pixel, 0);
        if POSITION_MODE == 2u {
            sum += textureLoad(scene_depth, pixel, 0);
        }
    }
    if model == MODEL_PBR || model == MODEL_BLINN_PHONG {
        sum += textureLoad(gbuffer_material, pixel, 0);
    }
    if ANISOTROPY {
        sum += textureLoad(gbuffer_tangent, pixel, 0);
    }
    return finish(sum.rgb * 1e-3 + vec3<f32>(sum.a * 1e-3));
}

// Exposed radiance of a masked pixel under the draw's ambient and lights. Ambient is diffuse:
// PBR scales it by (1 - metallic), the other models by the base color alone.
fn shade(model: u32, pixel: vec2<i32>) -> vec4<f32> {
    if INPUT_FLOOR {
        return input_floor(model, pixel);
    }
    let s = load_surface(pixel);
    let v = safe_normalize(-s.position, s.normal);
    var radiance = s.base_color * u.ambient.rgb;
    if model == MODEL_PBR {
        radiance *= 1.0 - s.metallic;
    }
    if IBL {
        if model == MODEL_PBR {
            radiance += pbr_ibl(s, v) * u.ibl.x;
        } else {
            radiance += s.base_color * ibl_irradiance_at(s.normal) * u.ibl.x;
        }
    }
    for (var i = 0u; i < min(LIGHT_COUNT, MAX_LIGHTS); i++) {
        let light = incoming(u.lights[i], s);
        var brdf: vec3<f32>;
        if SUN_DISC && model == MODEL_PBR && u.lights[i].position.w < 0.5
            && u.lights[i].params.y > 0.0 {
            brdf = pbr_disc_times_cosine(s, v, light.direction, u.lights[i].params.yz);
        } else {
            brdf = brdf_times_cosine(model, s, v, light.direction);
        }
        radiance += brdf * light.radiance * visibility(i, s, light.direction, u.lights[i]);
    }
    if KEEP_INPUTS {
        radiance += input_floor(model, pixel).rgb * u.ambient.w;
    }
    return finish(radiance);
}

@fragment
fn fs_pbr(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_PBR, vec2<i32>(frag.xy));
}

@fragment
fn fs_blinn_phong(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_BLINN_PHONG, vec2<i32>(frag.xy));
}

@fragment
fn fs_lambert(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_LAMBERT, vec2<i32>(frag.xy));
}

@fragment
fn fs_toon(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_TOON, vec2<i32>(frag.xy));
}

// Debug output: the shadow term of the draw's shadowed light (slot 0), as the passes above use it.
@fragment
fn fs_shadow_term(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let s = load_surface(vec2<i32>(frag.xy));
    let light = incoming(u.lights[0], s);
    let v = shadow_visibility(s, light.direction, u.lights[0]);
    return vec4<f32>(v, v, v, 1.0);
}

// The first draw of every lighting pass: writes depth 0 (vs_fullscreen's) into the pass's cleared
// routing target where the pixel is this model's, and adds nothing to the light buffer. The
// draws that shade follow with an equal-depth test, which the driver runs before their fragment
// shaders: pixels of other models are never shaded, and no shading draw discards.
@fragment
fn fs_route(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    if masked(vec2<i32>(frag.xy)) {
        discard;
    }
    return vec4<f32>(0.0);
}

@fragment
fn fs_unlit(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    if INPUT_FLOOR {
        return input_floor(MODEL_UNLIT, pixel);
    }
    let s = load_surface(pixel);
    return finish(s.base_color * f32(u.counts.y));
}
