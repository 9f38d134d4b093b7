#version 450 core
// GL-only geometry stage of the single-pass point-light shadow (the seed's Listing 2; WGSL has
// no geometry shaders). The vertex stage (`vs_shadow_object` in shadow.wgsl) passes object-space
// positions through; here each caster triangle is emitted once per cube face, transformed by
// that face's object-to-clip matrix and routed to the face's atlas tile with gl_ViewportIndex.
// The arithmetic per vertex (one mat4 * vec4 of the same f32 values) is the six-pass path's, so
// both give the same depth.

layout(triangles) in;
layout(triangle_strip, max_vertices = 18) out;

// Object to light clip space, per face (+X, -X, +Y, -Y, +Z, -Z), composed in f64 on the CPU.
layout(std140, binding = 0) uniform PointShadowCaster {
    mat4 face_mvp[6];
};

void main() {
    for (int face = 0; face < 6; ++face) {
        for (int i = 0; i < 3; ++i) {
            gl_ViewportIndex = face;
            gl_Position = face_mvp[face] * gl_in[i].gl_Position;
            EmitVertex();
        }
        EndPrimitive();
    }
}
