// Tone-mapping pass: exposed HDR light buffer -> display values in an sRGB RGBA8 target (the
// target's format does the sRGB encoding). Operators: 0 = ACES (Narkowicz's fit),
// 1 = Reinhard x / (1 + x), 2 = clamp to 0..1.

struct ToneMapUniforms {
    // x = operator.
    tone_operator: vec4<u32>,
    // x = scale applied to the light buffer before the curve: 1, except when the mutation
    // self-test injects a tone-mapping fault (engine::renderer::Variations).
    input_scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> u: ToneMapUniforms;
@group(0) @binding(1) var light_buffer: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

fn aces(x: vec3<f32>) -> vec3<f32> {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

@fragment
fn fs_tonemap(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let hdr = max(textureLoad(light_buffer, vec2<i32>(frag.xy), 0).rgb * u.input_scale.x, vec3<f32>(0.0));
    var ldr: vec3<f32>;
    switch u.tone_operator.x {
        case 0u: { ldr = aces(hdr); }
        case 1u: { ldr = hdr / (vec3<f32>(1.0) + hdr); }
        default: { ldr = clamp(hdr, vec3<f32>(0.0), vec3<f32>(1.0)); }
    }
    return vec4<f32>(ldr, 1.0);
}
