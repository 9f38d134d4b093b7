// Copies one depth image into the red channel of an R32F target, texel for texel. The wgpu
// backends read depth back this way because wgpu's GL backend cannot copy depth to a buffer.

@group(0) @binding(0) var depth_tex: texture_depth_2d;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_copy(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(textureLoad(depth_tex, vec2<i32>(position.xy), 0), 0.0, 0.0, 0.0);
}
