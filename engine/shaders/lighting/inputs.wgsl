// Lighting shader, part 1 of 6: the specialisation constants, uniforms and bindings. The parts
// are concatenated in order into one module, `lighting.wgsl` (engine::shaders::LIGHTING).
//
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
// How many times its own solid angle each of those samples reads from the radiance chain.
override IBL_FOOTPRINT: f32 = 1.0;
// Filtered importance samples of the anisotropic pixels only, where IBL_SAMPLES is 0 (the split
// sum elsewhere).
override IBL_ANISOTROPIC_SAMPLES: u32 = 0u;
// The split sum's dominant direction: Lagarde and de Rousiers' (true) or Filament's.
override IBL_FROSTBITE_DOMINANT: bool = false;
// The split sum reads anisotropic pixels by taps along the wide axis instead of one lookup about
// a bent normal.
override IBL_ANISOTROPIC_TAPS: bool = false;
// Whether any surface of this model can have clearcoat or anisotropy: per-pixel values, so when
// true the shader still branches on the pixel's value.
override CLEARCOAT: bool = true;
override ANISOTROPY: bool = true;
// G-buffer storage: position 0 camera-relative, 1 world, 2 reconstructed from depth; normal
// 0 fp16 xyz, 1 octahedral in xy.
override POSITION_MODE: u32 = 0u;
override NORMAL_MODE: u32 = 0u;
// Cost breakdown (harness bench --breakdown): read the inputs and write their sum, no shading.
// Draws of this model's pass: they add into the same pixels of the light buffer, so each clamps
// its output to FP16_SAFE_MAX / DRAWS (see `finish`) and their sum stays finite.
override DRAWS: u32 = 1u;
override INPUT_FLOOR: bool = false;
// Cost breakdown: every variant with a part taken away still reads all the inputs (as the whole
// pass does), adding them times a uniform zero, so that taking a light away does not also take
// away the reads of the G-buffer targets only it needed, which the input floor already counts.
override KEEP_INPUTS: bool = false;
// The scene's screen-space ambient occlusion scales this draw's ambient and IBL diffuse light
// (first draws of a lit model, in scenes with [quality.ssao]).
override AMBIENT_OCCLUSION: bool = false;

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

// Screen-space ambient occlusion (shaders/ssao.wgsl; r = 1 unoccluded .. 0), read where
// AMBIENT_OCCLUSION is set.
@group(0) @binding(18) var ambient_occlusion: texture_2d<f32>;

// The environment cube with box-filtered mips (crate::ibl, `radiance`), read by the filtered
// importance samples of IBL_SAMPLES and IBL_ANISOTROPIC_SAMPLES (a 1 x 1 black placeholder in
// scenes that take none).
@group(0) @binding(19) var ibl_radiance: texture_cube<f32>;

