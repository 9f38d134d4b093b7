// Floor passes for benchmarks: the cheapest pass that writes the same attachments as a real pass,
// over every pixel of them: a full-screen triangle (at depth 0.5 where the pass has a depth
// target) whose fragments write a value made from their position. Not a constant: llvmpipe turns
// a constant-color shader into something like a clear, which would time memory bandwidth rather
// than a pass. A pass's time against its floor's says how much of it is its own work and how
// much the driver's cost of running fragments into those targets at all.

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.5, 1.0);
}

fn floor_value(frag: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(frag.xy * 1e-3, 0.5, 1.0);
}

@fragment
fn fs_floor_1(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return floor_value(frag);
}

struct Floor2 {
    @location(0) c0: vec4<f32>,
    @location(1) c1: vec4<f32>,
}

@fragment
fn fs_floor_2(@builtin(position) frag: vec4<f32>) -> Floor2 {
    let v = floor_value(frag);
    return Floor2(v, v);
}

struct Floor3 {
    @location(0) c0: vec4<f32>,
    @location(1) c1: vec4<f32>,
    @location(2) c2: vec4<f32>,
}

@fragment
fn fs_floor_3(@builtin(position) frag: vec4<f32>) -> Floor3 {
    let v = floor_value(frag);
    return Floor3(v, v, v);
}

struct Floor4 {
    @location(0) c0: vec4<f32>,
    @location(1) c1: vec4<f32>,
    @location(2) c2: vec4<f32>,
    @location(3) c3: vec4<f32>,
}

@fragment
fn fs_floor_4(@builtin(position) frag: vec4<f32>) -> Floor4 {
    let v = floor_value(frag);
    return Floor4(v, v, v, v);
}

struct Floor5 {
    @location(0) c0: vec4<f32>,
    @location(1) c1: vec4<f32>,
    @location(2) c2: vec4<f32>,
    @location(3) c3: vec4<f32>,
    @location(4) c4: vec4<f32>,
}

@fragment
fn fs_floor_5(@builtin(position) frag: vec4<f32>) -> Floor5 {
    let v = floor_value(frag);
    return Floor5(v, v, v, v, v);
}
