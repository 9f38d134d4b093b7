// Screen-space ambient occlusion, after the io7m r2 renderer's filter: for each covered pixel, a
// hemisphere of SAMPLES kernel points of radius R is placed on the surface along its normal; a
// point counts as occluded where the surface the depth buffer holds at its pixel lies in front
// of it. The result is 1 - occluded / SAMPLES (1 unoccluded, 0 occluded), in rgb.
//
// Positions are camera-relative, reconstructed from the depth buffer (whatever the G-buffer's
// position storage), normals come from the G-buffer. Differences from r2, and why:
// - the kernel is uniform in the hemisphere's volume (r2 clusters it towards the origin), so
//   that the occlusion of a plane meeting another has a closed form (the harness's reference);
// - no noise texture and no blur: the kernel is the same at every pixel, so the result is smooth
//   (banded where the kernel is small) and the same on every backend;
// - halo removal as r2's: a surface farther than R from the point, in view depth, occludes
//   nothing (a near object in front of a far one darkens no halo around it).
// The kernel arrives in the uniforms (engine::renderer::passes::ambient_occlusion).

// Kernel points read (at most 64, the uniform array's size).
override SAMPLES: u32 = 32u;
// G-buffer normal encoding: 0 fp16 xyz, 1 octahedral in xy (as the lighting shader's).
override NORMAL_MODE: u32 = 0u;

struct SsaoUniforms {
    // Camera-relative world space to clip space, and back.
    view_proj: mat4x4<f32>,
    inverse_view_proj: mat4x4<f32>,
    // xyz = the camera's unit forward direction; w = the hemisphere's radius R (m).
    forward_radius: vec4<f32>,
    // xyz = kernel point in the unit hemisphere (tangent x, bitangent y, normal z).
    kernel: array<vec4<f32>, 64>,
}

@group(0) @binding(0) var<uniform> u: SsaoUniforms;
@group(0) @binding(1) var scene_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

// The camera-relative position of the surface at `pixel`'s center, of depth `depth`.
fn position_at(pixel: vec2<i32>, depth: f32, size: vec2<f32>) -> vec3<f32> {
    let uv = (vec2<f32>(pixel) + 0.5) / size;
    let clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let relative = u.inverse_view_proj * clip;
    return relative.xyz / relative.w;
}

// As the lighting shader's (shaders/lighting/surface.wgsl).
fn octahedral_decode(e: vec2<f32>) -> vec3<f32> {
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if v.z < 0.0 {
        let signs = select(vec2<f32>(-1.0), vec2<f32>(1.0), v.xy >= vec2<f32>(0.0));
        v = vec3<f32>((vec2<f32>(1.0) - abs(v.yx)) * signs, v.z);
    }
    return normalize(v);
}

fn normal_at(pixel: vec2<i32>) -> vec3<f32> {
    let stored = textureLoad(gbuffer_normal, pixel, 0);
    if NORMAL_MODE == 1u {
        return octahedral_decode(stored.xy);
    }
    return normalize(stored.xyz);
}

// An orthonormal tangent frame around unit `n` (Duff et al., "Building an Orthonormal Basis,
// Revisited", 2017); the harness's reference builds the same one.
fn tangent_frame(n: vec3<f32>) -> mat3x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bitangent = vec3<f32>(b, sign + n.y * n.y * a, -n.y);
    return mat3x3<f32>(t, bitangent, n);
}

@fragment
fn fs_ambient_occlusion(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let size = vec2<f32>(textureDimensions(scene_depth));
    let depth = textureLoad(scene_depth, pixel, 0).r;
    if depth >= 1.0 {
        // Nothing drawn here: nothing to occlude.
        return vec4<f32>(1.0);
    }
    let forward = u.forward_radius.xyz;
    let radius = u.forward_radius.w;
    let p = position_at(pixel, depth, size);
    let p_depth = dot(p, forward);
    let frame = tangent_frame(normal_at(pixel));
    // A point counts as behind the surface only past this margin: the surface is read at the
    // center of the point's pixel, which on a plane seen at an angle lies slightly nearer or
    // farther than the point itself.
    let margin = 0.02 * radius;
    var occluded = 0u;
    for (var i = 0u; i < SAMPLES; i++) {
        let q = p + frame * u.kernel[i].xyz * radius;
        let clip = u.view_proj * vec4<f32>(q, 1.0);
        if clip.w <= 0.0 {
            continue;
        }
        let ndc = clip.xy / clip.w;
        let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        if any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0)) {
            continue;
        }
        let q_pixel = vec2<i32>(uv * size);
        let surface_depth = textureLoad(scene_depth, q_pixel, 0).r;
        if surface_depth >= 1.0 {
            continue;
        }
        let s_depth = dot(position_at(q_pixel, surface_depth, size), forward);
        // Halo removal (r2): a surface farther than the radius from the point occludes nothing.
        if abs(p_depth - s_depth) > radius {
            continue;
        }
        if s_depth < dot(q, forward) - margin {
            occluded += 1u;
        }
    }
    let visibility = 1.0 - f32(occluded) / f32(SAMPLES);
    return vec4<f32>(visibility, visibility, visibility, 1.0);
}
