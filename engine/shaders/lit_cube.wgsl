// The first end-to-end scene: a textured cube lit by one directional light (Lambert plus
// Blinn-Phong), written to an HDR RGBA16F target and, Reinhard-tone-mapped, to an sRGB RGBA8
// target in the same pass.

struct Globals {
    view_proj: mat4x4<f32>,
    model: mat4x4<f32>,
    // Direction towards the light (xyz).
    light_dir: vec4<f32>,
    // Light radiance (rgb).
    light_color: vec4<f32>,
    // Ambient radiance (rgb).
    ambient: vec4<f32>,
    // Camera position in world space (xyz).
    camera_pos: vec4<f32>,
}

@group(0) @binding(0) var<uniform> globals: Globals;
@group(0) @binding(1) var albedo_tex: texture_2d<f32>;
@group(0) @binding(2) var albedo_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let world = globals.model * vec4<f32>(v.position, 1.0);
    var out: VertexOut;
    out.clip = globals.view_proj * world;
    out.world_pos = world.xyz;
    // The model matrix is a rotation and uniform scale, so it transforms normals too.
    out.normal = (globals.model * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    return out;
}

struct Targets {
    @location(0) hdr: vec4<f32>,
    @location(1) ldr: vec4<f32>,
}

@fragment
fn fs_main(in: VertexOut) -> Targets {
    let n = normalize(in.normal);
    let l = normalize(globals.light_dir.xyz);
    let v = normalize(globals.camera_pos.xyz - in.world_pos);
    let h = normalize(l + v);
    let albedo = textureSample(albedo_tex, albedo_sampler, in.uv).rgb;
    let n_dot_l = max(dot(n, l), 0.0);
    let specular = select(0.0, 0.25 * pow(max(dot(n, h), 0.0), 32.0), n_dot_l > 0.0);
    let radiance = globals.light_color.rgb * (albedo * n_dot_l + vec3<f32>(specular))
        + globals.ambient.rgb * albedo;
    var out: Targets;
    out.hdr = vec4<f32>(radiance, 1.0);
    out.ldr = vec4<f32>(radiance / (vec3<f32>(1.0) + radiance), 1.0);
    return out;
}
