// Copies one depth image into an RGBA8 unorm target, texel for texel, with the f32's bits packed
// into the four bytes (least significant in red). Unorm stores k/255 exactly, so the CPU gets the
// exact depth back. The wgpu backends read depth this way: wgpu cannot copy depth to a buffer on
// every API, and wgpu's GL backend cannot render to R32F.

// Bound as an unfilterable-float texture (WebGPU allows this for depth formats): naga's GLSL
// backend cannot textureLoad from texture_depth_2d. The depth is in the red channel.
@group(0) @binding(0) var depth_tex: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_copy(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let bits = bitcast<u32>(textureLoad(depth_tex, vec2<i32>(position.xy), 0).r);
    let bytes = vec4<u32>(bits & 0xffu, (bits >> 8u) & 0xffu, (bits >> 16u) & 0xffu, bits >> 24u);
    return vec4<f32>(bytes) / 255.0;
}
