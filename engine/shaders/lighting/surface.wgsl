// Lighting shader, part 3 of 6: the full-screen triangle, the G-buffer decoded into a Surface,
// and the light arriving at it.

// Invariant: the routing draw and the shading draws of a pass must produce the same depth (0)
// for the equal-depth test.
@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @invariant @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

struct Surface {
    pixel: vec2<i32>,
    position: vec3<f32>,
    roughness: f32,
    normal: vec3<f32>,
    specular: f32,
    tangent: vec3<f32>,
    base_color: vec3<f32>,
    anisotropy: f32,
    metallic: f32,
    clearcoat: f32,
    clearcoat_roughness: f32,
    specular_exponent: f32,
}

// Whether a pixel is not this model's (its shader-mask channel is clear).
fn masked(pixel: vec2<i32>) -> bool {
    return dot(textureLoad(shader_mask, pixel, 0), u.mask_select) < 0.5;
}

// Octahedral decoding (Cigolle et al. 2014) of a unit vector stored as two values in -1..1.
fn octahedral_decode(e: vec2<f32>) -> vec3<f32> {
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if v.z < 0.0 {
        let signs = select(vec2<f32>(-1.0), vec2<f32>(1.0), v.xy >= vec2<f32>(0.0));
        v = vec3<f32>((vec2<f32>(1.0) - abs(v.yx)) * signs, v.z);
    }
    return normalize(v);
}

// The camera-relative position at a pixel, as the G-buffer stores it.
fn surface_position(pixel: vec2<i32>, stored: vec3<f32>) -> vec3<f32> {
    if POSITION_MODE == 0u {
        return stored;
    }
    if POSITION_MODE == 1u {
        return stored - u.camera_world.xyz;
    }
    let size = vec2<f32>(textureDimensions(scene_depth));
    let depth = textureLoad(scene_depth, pixel, 0).r;
    let uv = (vec2<f32>(pixel) + 0.5) / size;
    let clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let relative = u.inverse_view_proj * clip;
    return relative.xyz / relative.w;
}

fn load_surface(pixel: vec2<i32>) -> Surface {
    let p = textureLoad(gbuffer_position, pixel, 0);
    let n = textureLoad(gbuffer_normal, pixel, 0);
    let t = textureLoad(gbuffer_tangent, pixel, 0);
    let a = textureLoad(gbuffer_albedo, pixel, 0);
    let m = textureLoad(gbuffer_material, pixel, 0);
    var s: Surface;
    s.pixel = pixel;
    s.position = surface_position(pixel, p.xyz);
    s.roughness = clamp(p.w, 0.0, 1.0);
    if NORMAL_MODE == 1u {
        s.normal = octahedral_decode(n.xy);
    } else {
        s.normal = normalize(n.xyz);
    }
    s.specular = n.w;
    s.tangent = t.xyz;
    s.base_color = a.rgb;
    s.anisotropy = clamp(a.a, -1.0, 1.0);
    s.metallic = m.x;
    s.clearcoat = m.y;
    s.clearcoat_roughness = clamp(m.z, 0.0, 1.0);
    s.specular_exponent = m.w;
    return s;
}

// Direction to the light (xyz) and the light's radiance at the surface (rgb in the second value).
struct Incoming {
    direction: vec3<f32>,
    radiance: vec3<f32>,
}

fn incoming(light: LightData, s: Surface) -> Incoming {
    var result: Incoming;
    if DIRECTIONAL_LIGHTS && !POINT_LIGHTS {
        result.direction = light.position.xyz;
        result.radiance = light.color.rgb;
        return result;
    }
    let to_light = light.position.xyz - s.position;
    let distance = length(to_light);
    // A light exactly at the surface lights it head-on instead of dividing by zero.
    result.direction = select(s.normal, to_light / distance, distance > 1e-6);
    let ratio = min(distance / max(light.color.a, 1e-6), 1.0);
    let attenuation = max(0.0, 1.0 - pow(ratio, light.params.x));
    result.radiance = light.color.rgb * attenuation;
    if DIRECTIONAL_LIGHTS {
        // A draw with both types picks per light with a select, not a branch: lavapipe would
        // compile a new shader for each draw to specialise a branch on uniform data.
        let directional = light.position.w < 0.5;
        result.direction = select(result.direction, light.position.xyz, directional);
        result.radiance = select(result.radiance, light.color.rgb, directional);
    }
    return result;
}

fn safe_normalize(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(v, v);
    return select(fallback, v * inverseSqrt(length_squared), length_squared > 1e-20);
}

