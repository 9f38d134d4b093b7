// Skybox pass: fills the light buffer's pixels that no object covers (all shader-mask channels
// zero) with the environment's exposed radiance, looked up in the equirectangular image.
//
// Equirectangular convention: u = 0.5 + atan2(d.x, -d.z) / 2pi (u = 0.5 looks down -Z, u grows
// towards +X), v = acos(d.y) / pi (north pole at the top row). The environment is rotated about
// +Y by `rotation` radians before the lookup.
//
// The angles come from arithmetic (`atan2_portable`), not from the built-in atan2 and acos: the
// shading languages let those be any approximation within thousands of ULP, and they differ
// by compiler. With Mesa's, a sky pixel was up to 26% off the CPU's lookup
// (`engine::ibl::cube::sample_equirect`) where the image changes fast, and on one NVIDIA GPU
// the OpenGL and Vulkan compilers' disagreed with each other by up to 8%
// (docs/2026-11-26-nvidia-gpu.md). Sums, products, quotients and square roots are within a few
// ULP everywhere; `harness`'s test `the_sky_is_the_cpu_lookup_of_the_environment` holds it.

const PI: f32 = 3.14159265358979;

struct SkyboxUniforms {
    // Clip space (with z = 1) to camera-relative world direction.
    inverse_view_proj: mat4x4<f32>,
    // x = width, y = height, z = rotation about +Y (radians), w = intensity * exposure.
    params: vec4<f32>,
}

@group(0) @binding(0) var<uniform> u: SkyboxUniforms;
@group(0) @binding(1) var shader_mask0: texture_2d<f32>;
@group(0) @binding(2) var shader_mask1: texture_2d<f32>;
@group(0) @binding(3) var environment: texture_2d<f32>;
@group(0) @binding(4) var environment_sampler: sampler;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

// atan on [0, 1]: t * P(t^2), least squares on Chebyshev nodes; at most 3.5e-7 rad off in f32.
fn atan_unit(t: f32) -> f32 {
    let s = t * t;
    let p = 0.006842671 * s - 0.033726087;
    let p1 = (p * s + 0.079811392) * s - 0.132475340;
    let p2 = (p1 * s + 0.198132168) * s - 0.333183033;
    return t * (p2 * s + 0.999996635);
}

// atan2 from arithmetic alone (see the top of the file).
fn atan2_portable(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    let hi = max(ax, ay);
    var a = atan_unit(select(min(ax, ay) / hi, 0.0, hi == 0.0));
    a = select(a, 0.5 * PI - a, ay > ax);
    a = select(a, PI - a, x < 0.0);
    return select(a, -a, y < 0.0);
}

fn equirect_uv(d: vec3<f32>) -> vec2<f32> {
    // acos(y) = atan2(sqrt(1 - y^2), y), with 1 - y^2 as a product (no cancellation near the
    // poles, nothing for a compiler to fuse).
    let y = clamp(d.y, -1.0, 1.0);
    let polar = atan2_portable(sqrt((1.0 - y) * (1.0 + y)), y);
    return vec2<f32>(0.5 + atan2_portable(d.x, -d.z) / (2.0 * PI), polar / PI);
}

@fragment
fn fs_skybox(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let coverage = textureLoad(shader_mask0, pixel, 0) + textureLoad(shader_mask1, pixel, 0);
    if dot(coverage, vec4<f32>(1.0)) > 0.5 {
        discard;
    }
    let ndc = vec2<f32>(frag.x / u.params.x * 2.0 - 1.0, 1.0 - frag.y / u.params.y * 2.0);
    let far = u.inverse_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let d = normalize(far.xyz / far.w);
    let c = cos(u.params.z);
    let s = sin(u.params.z);
    let rotated = vec3<f32>(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
    let radiance = textureSampleLevel(environment, environment_sampler, equirect_uv(rotated), 0.0).rgb;
    return vec4<f32>(min(radiance * u.params.w, vec3<f32>(65000.0)), 1.0);
}
