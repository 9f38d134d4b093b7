// Gizmos pass: colored lines (world axes, directional-light directions, point-light markers)
// drawn over the final image without depth testing.

struct GizmoUniforms {
    // Camera-relative world space to clip space.
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> u: GizmoUniforms;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) color: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec3<f32>,
}

@vertex
fn vs_gizmo(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = u.view_proj * vec4<f32>(v.position, 1.0);
    out.color = v.color;
    return out;
}

@fragment
fn fs_gizmo(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color, 1.0);
}
