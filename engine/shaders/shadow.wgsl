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
