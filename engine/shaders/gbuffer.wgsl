// Geometry pass (fs_gbuffer) and shader-mask pass (fs_mask_1 / fs_mask_2) of the deferred
// renderer. Both passes run vs_main, so their depths match exactly and the mask pass can
// depth-test with less-equal against the geometry pass's depth buffer.
//
// G-buffer layout (five RGBA16F targets, positions camera-relative in world orientation):
//   0 position: xyz = world position - camera position, w = roughness (other storages with
//               quality.gbuffer: world position, or nothing when rebuilt from depth)
//   1 normal:   xyz = unit normal after normal mapping,  w = specular (octahedral: xy)
//   2 tangent:  xyz = unit tangent orthogonal to the normal, w = handedness (+1 or -1)
//   3 albedo:   rgb = linear base color, a = anisotropy (-1..1)
//   4 material: metallic, clearcoat, clearcoat roughness, Blinn-Phong specular exponent

struct ObjectUniforms {
    // Object space to camera-relative world space (translation already minus the camera, in f64).
    model: mat4x4<f32>,
    // Inverse transpose of model's upper 3x3 (for normals).
    normal_matrix: mat4x4<f32>,
    // Camera-relative world space to clip space.
    view_proj: mat4x4<f32>,
    // rgb = base color, a = anisotropy.
    base_color: vec4<f32>,
    // roughness, metallic, specular, clearcoat.
    params: vec4<f32>,
    // clearcoat roughness, specular exponent, fault flag (1: swap albedo red and blue; only the
    // harness's mutation self-test sets it), handedness (-1 where the model matrix mirrors,
    // else 1: a mirrored tangent frame's bitangent is the other cross product).
    params2: vec4<f32>,
    // 1.0 where a map replaces the scalar: base color, normal, roughness, metallic.
    maps: vec4<f32>,
    // clearcoat, specular (1.0 where a map replaces the scalar), position storage (0
    // camera-relative, 1 world, 2 none: rebuilt from depth), normal encoding (0 fp16 xyz,
    // 1 octahedral).
    maps2: vec4<f32>,
    // One-hot shader-mask value for mask targets 0 and 1.
    mask0: vec4<f32>,
    mask1: vec4<f32>,
    // World position of the camera (f32), for world-space position storage.
    camera_world: vec4<f32>,
}

@group(0) @binding(0) var<uniform> object: ObjectUniforms;
@group(0) @binding(1) var base_color_map: texture_2d<f32>;
@group(0) @binding(2) var normal_map: texture_2d<f32>;
@group(0) @binding(3) var roughness_map: texture_2d<f32>;
@group(0) @binding(4) var metallic_map: texture_2d<f32>;
@group(0) @binding(5) var clearcoat_map: texture_2d<f32>;
@group(0) @binding(6) var specular_map: texture_2d<f32>;
@group(0) @binding(7) var material_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) relative_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let world = object.model * vec4<f32>(v.position, 1.0);
    var out: VertexOut;
    out.clip = object.view_proj * world;
    out.relative_position = world.xyz;
    out.normal = (object.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    out.tangent = vec4<f32>(
        (object.model * vec4<f32>(v.tangent.xyz, 0.0)).xyz,
        v.tangent.w * object.params2.w,
    );
    return out;
}

struct GBuffer {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) tangent: vec4<f32>,
    @location(3) albedo: vec4<f32>,
    @location(4) material: vec4<f32>,
}

// A unit vector orthogonal to n (used when a tangent degenerates).
fn any_orthogonal(n: vec3<f32>) -> vec3<f32> {
    let axis = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    return normalize(cross(axis, n));
}

// Gram-Schmidt: t made orthogonal to n and unit length, with a fallback when it degenerates.
fn orthogonalise(t: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let projected = t - n * dot(n, t);
    let length_squared = dot(projected, projected);
    if length_squared < 1e-12 {
        return any_orthogonal(n);
    }
    return projected * inverseSqrt(length_squared);
}

// Octahedral encoding (Cigolle et al. 2014): a unit vector as two values in -1..1.
fn octahedral_encode(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return p;
    }
    let signs = select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
    return (vec2<f32>(1.0) - abs(p.yx)) * signs;
}

@fragment
fn fs_gbuffer(in: VertexOut) -> GBuffer {
    // OBJ texture coordinates have v growing upwards; textures are stored top row first.
    let uv = vec2<f32>(in.uv.x, 1.0 - in.uv.y);
    let base_sample = textureSample(base_color_map, material_sampler, uv);
    let normal_sample = textureSample(normal_map, material_sampler, uv);
    let roughness_sample = textureSample(roughness_map, material_sampler, uv);
    let metallic_sample = textureSample(metallic_map, material_sampler, uv);
    let clearcoat_sample = textureSample(clearcoat_map, material_sampler, uv);
    let specular_sample = textureSample(specular_map, material_sampler, uv);

    var n = normalize(in.normal);
    var t = orthogonalise(in.tangent.xyz, n);
    let handedness = select(-1.0, 1.0, in.tangent.w >= 0.0);
    if object.maps.y > 0.5 {
        let b = cross(n, t) * handedness;
        let m = normal_sample.xyz * 2.0 - 1.0;
        n = normalize(t * m.x + b * m.y + n * m.z);
        t = orthogonalise(t, n);
    }

    var base_color = mix(object.base_color.rgb, base_sample.rgb, object.maps.x);
    if object.params2.z > 0.5 {
        base_color = base_color.bgr;
    }
    let roughness = mix(object.params.x, roughness_sample.r, object.maps.z);
    let metallic = mix(object.params.y, metallic_sample.r, object.maps.w);
    let specular = mix(object.params.z, specular_sample.r, object.maps2.y);
    let clearcoat = mix(object.params.w, clearcoat_sample.r, object.maps2.x);

    var out: GBuffer;
    var stored_position = in.relative_position;
    if object.maps2.z > 1.5 {
        stored_position = vec3<f32>(0.0);
    } else if object.maps2.z > 0.5 {
        stored_position = in.relative_position + object.camera_world.xyz;
    }
    out.position = vec4<f32>(stored_position, roughness);
    if object.maps2.w > 0.5 {
        out.normal = vec4<f32>(octahedral_encode(n), 0.0, specular);
    } else {
        out.normal = vec4<f32>(n, specular);
    }
    out.tangent = vec4<f32>(t, handedness);
    out.albedo = vec4<f32>(base_color, object.base_color.a);
    out.material = vec4<f32>(metallic, clearcoat, object.params2.x, object.params2.y);
    return out;
}

@fragment
fn fs_mask_1() -> @location(0) vec4<f32> {
    return object.mask0;
}

struct TwoMasks {
    @location(0) mask0: vec4<f32>,
    @location(1) mask1: vec4<f32>,
}

@fragment
fn fs_mask_2() -> TwoMasks {
    return TwoMasks(object.mask0, object.mask1);
}
