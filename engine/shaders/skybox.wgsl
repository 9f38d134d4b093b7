// Skybox pass: fills the light buffer's pixels that no object covers (all shader-mask channels
// zero) with the environment's exposed radiance, looked up in the equirectangular image.
//
// Equirectangular convention: u = 0.5 + atan2(d.x, -d.z) / 2pi (u = 0.5 looks down -Z, u grows
// towards +X), v = acos(d.y) / pi (north pole at the top row). The environment is rotated about
// +Y by `rotation` radians before the lookup.

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

fn equirect_uv(d: vec3<f32>) -> vec2<f32> {
    return vec2<f32>(0.5 + atan2(d.x, -d.z) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
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
