// Orientation probe. `fs_marker` copies a marker texture texel for texel (texture row 0 must land
// in image row 0, the top); `vs_corner` draws a counter-clockwise triangle in the top-left
// quadrant of normalized device coordinates (y up), which must survive back-face culling and
// appear top-left in the read-back image.

@group(0) @binding(0) var marker: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_marker(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(marker, vec2<i32>(position.xy), 0);
}

@vertex
fn vs_corner(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    var corners = array<vec2<f32>, 3>(vec2<f32>(-1.0, 1.0), vec2<f32>(-1.0, 0.0), vec2<f32>(0.0, 1.0));
    return vec4<f32>(corners[index], 0.5, 1.0);
}

@fragment
fn fs_solid() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0, 1.0, 0.0, 1.0);
}
