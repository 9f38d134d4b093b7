// Skybox pass: fills the light buffer's pixels that no object covers (all shader-mask channels
// zero) with the environment's exposed radiance, looked up in the equirectangular image.
//
// Equirectangular convention: u = 0.5 + atan2(d.x, -d.z) / 2pi (u = 0.5 looks down -Z, u grows
// towards +X), v = acos(d.y) / pi (north pole at the top row). The environment is rotated about
// +Y by `rotation` radians before the lookup.
//
// The angles come from arithmetic written out here, not from the built-in atan2 and acos: the
// shading languages let those be any approximation within thousands of ULP, and they differ by
// compiler (on one NVIDIA GPU the OpenGL and Vulkan compilers' skies were up to 8% apart:
// docs/2026-11-26-nvidia-gpu.md). The arithmetic is the approximation Mesa's compiler gives
// both (NIR's atan2, and acos with Abramowitz and Stegun's asin form), so that llvmpipe's and
// lavapipe's sky, which the goldens and the other hosts' recorded renders hold, is unchanged,
// and every other compiler now computes the same sums, products, quotients and roots.

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

// atan(t) for t >= 0: reduced to [0, 1] and an odd polynomial of degree 11, its terms summed in
// order (Mesa's NIR atan; about 1e-5 rad off).
fn atan_positive(t: f32) -> f32 {
    let x = min(t, 1.0) / max(t, 1.0);
    let x2 = x * x;
    let x3 = x2 * x;
    let x5 = x3 * x2;
    let x7 = x5 * x2;
    let x9 = x7 * x2;
    let x11 = x9 * x2;
    let p = x * 0.9999793128310355 + x3 * -0.3326756418091246 + x5 * 0.1938924977115610
        + x7 * -0.1173503194786851 + x9 * 0.0536813784310406 + x11 * -0.0121323213173444;
    return select(p, 0.5 * PI - p, t > 1.0);
}

// atan2(y, x): on the left half-plane the coordinates turn a quarter clockwise, so that no
// quotient divides by zero there (Mesa's NIR atan2).
fn atan2_portable(y: f32, x: f32) -> f32 {
    let flip = x <= 0.0;
    let s = select(y, abs(x), flip);
    let t = select(abs(x), y, flip);
    let rcp_t = 1.0 / t;
    let tangent = select(abs(s * rcp_t), 1.0, abs(x) == abs(y));
    let arc = select(0.0, 0.5 * PI, flip) + atan_positive(tangent);
    return select(arc, -arc, min(y, rcp_t) < 0.0);
}

// acos(y) = pi/2 - asin(y), asin(a) = pi/2 - sqrt(1 - a) (pi/2 + a (pi/4 - 1 + a (p0 + a p1)))
// for a = |y| (Mesa's acos coefficients; about 1.6e-4 rad off).
fn acos_portable(y: f32) -> f32 {
    let a = abs(y);
    let p = 0.5 * PI + a * ((0.25 * PI - 1.0) + a * (0.08132463 + a * -0.02363318));
    let asin_a = 0.5 * PI - sqrt(1.0 - a) * p;
    return 0.5 * PI - select(asin_a, -asin_a, y < 0.0);
}

fn equirect_uv(d: vec3<f32>) -> vec2<f32> {
    let polar = acos_portable(clamp(d.y, -1.0, 1.0));
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
