// Shadow-map pass: shadow casters drawn depth-only from a light. Directional lights use one
// orthographic view fitted to the casters; point lights draw six 90-degree perspective faces into
// a 3x2 atlas, one viewport per face. `mvp` maps object space to the light's clip space (through
// camera-relative world space, computed in f64 on the CPU).

struct ShadowCaster {
    mvp: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> caster: ShadowCaster;

@vertex
fn vs_shadow(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return caster.mvp * vec4<f32>(position, 1.0);
}

// Variance shadow maps (directional lights with filter `vsm`): the caster pass also writes the
// first two moments of depth. RGBA16F is filterable on every backend but holds only 11 bits, so
// each moment is stored as a pair: its top 11 significant bits (r, b; exact in fp16) and the
// remainder (g, a). The pair sums back to ~21 bits, and since filtering and blurring are linear,
// they act on the sums.
fn split_moments(m: vec2<f32>) -> vec4<f32> {
    let high = bitcast<vec2<f32>>(bitcast<vec2<u32>>(m) & vec2<u32>(0xffffe000u));
    let low = m - high;
    return vec4<f32>(high.x, low.x, high.y, low.y);
}

@fragment
fn fs_shadow_moments(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let depth = frag.z;
    return split_moments(vec2<f32>(depth, depth * depth));
}

// One direction of the separable Gaussian blur of the moments (taps clamped to the map's edge),
// as a full-screen draw. The normalized weights come from the CPU (`shadows::blur_weights`).
struct MomentsBlur {
    // xy = texel step (1, 0) or (0, 1); z = radius in texels (at most 16).
    step: vec4<f32>,
    // Weight of the taps at distance 0..16, four to a vector.
    weights: array<vec4<f32>, 5>,
}

@group(0) @binding(1) var<uniform> moments_blur: MomentsBlur;
@group(0) @binding(2) var moments_source: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_moments_blur(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(moments_source));
    let center = vec2<i32>(frag.xy);
    let step = vec2<i32>(moments_blur.step.xy);
    let radius = i32(moments_blur.step.z);
    var sum = vec2<f32>(0.0);
    for (var k = -radius; k <= radius; k++) {
        let texel = textureLoad(moments_source, clamp(center + step * k, vec2<i32>(0), size - 1), 0);
        let distance = u32(abs(k));
        let w = moments_blur.weights[distance / 4u][distance % 4u];
        sum += w * vec2<f32>(texel.r + texel.g, texel.b + texel.a);
    }
    return split_moments(sum);
}

// The single-pass point-light path (gl only): object-space positions pass through to the
// geometry stage engine/shaders/gl/point_shadow_faces.geom, which applies each face's matrix.
@vertex
fn vs_shadow_object(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return vec4<f32>(position, 1.0);
}
