// Lighting shader, part 6 of 6: the input floor, the shading of a pixel, and the fragment
// entry points (one per lighting model, the shadow term, the routing draw).

const MODEL_UNLIT: u32 = 4u;

// The lighting pass's input floor: every input `model`'s shading reads, summed into the output,
// and no shading. Unlit reads the albedo only; the others also position and normal (and depth
// where positions come from it), PBR and Blinn-Phong the material target, and the tangent only
// where a material is anisotropic (the only use of it).
fn input_floor(model: u32, pixel: vec2<i32>) -> vec4<f32> {
    var sum = textureLoad(gbuffer_albedo, pixel, 0);
    if model != MODEL_UNLIT {
        sum += textureLoad(gbuffer_position, pixel, 0) + textureLoad(gbuffer_normal, pixel, 0);
        if POSITION_MODE == 2u {
            sum += textureLoad(scene_depth, pixel, 0);
        }
    }
    if model == MODEL_PBR || model == MODEL_BLINN_PHONG {
        sum += textureLoad(gbuffer_material, pixel, 0);
    }
    if ANISOTROPY {
        sum += textureLoad(gbuffer_tangent, pixel, 0);
    }
    if AMBIENT_OCCLUSION {
        sum += textureLoad(ambient_occlusion, pixel, 0);
    }
    return finish(sum.rgb * 1e-3 + vec3<f32>(sum.a * 1e-3));
}

// Exposed radiance of a masked pixel under the draw's ambient and lights. Ambient is diffuse:
// PBR scales it by (1 - metallic), the other models by the base color alone. With
// AMBIENT_OCCLUSION, the ambient and the IBL diffuse light are scaled by the occlusion.
fn shade(model: u32, pixel: vec2<i32>) -> vec4<f32> {
    if INPUT_FLOOR {
        return input_floor(model, pixel);
    }
    let s = load_surface(pixel);
    let v = safe_normalize(-s.position, s.normal);
    var occlusion = 1.0;
    if AMBIENT_OCCLUSION {
        occlusion = textureLoad(ambient_occlusion, pixel, 0).r;
    }
    var radiance = s.base_color * u.ambient.rgb;
    if model == MODEL_PBR {
        radiance *= 1.0 - s.metallic;
    }
    if AMBIENT_OCCLUSION {
        radiance *= occlusion;
    }
    if IBL {
        if model == MODEL_PBR {
            radiance += pbr_ibl(s, v, occlusion) * u.ibl.x;
        } else {
            var diffuse = s.base_color * ibl_irradiance_at(s.normal);
            if AMBIENT_OCCLUSION {
                diffuse *= occlusion;
            }
            radiance += diffuse * u.ibl.x;
        }
    }
    for (var i = 0u; i < min(LIGHT_COUNT, MAX_LIGHTS); i++) {
        let light = incoming(u.lights[i], s);
        var brdf: vec3<f32>;
        if SUN_DISC && model == MODEL_PBR && u.lights[i].position.w < 0.5
            && u.lights[i].params.y > 0.0 {
            brdf = pbr_disc_times_cosine(s, v, light.direction, u.lights[i].params.yz);
        } else {
            brdf = brdf_times_cosine(model, s, v, light.direction);
        }
        radiance += brdf * light.radiance * visibility(i, s, light.direction, u.lights[i]);
    }
    if KEEP_INPUTS {
        radiance += input_floor(model, pixel).rgb * u.ambient.w;
    }
    return finish(radiance);
}

@fragment
fn fs_pbr(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_PBR, vec2<i32>(frag.xy));
}

@fragment
fn fs_blinn_phong(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_BLINN_PHONG, vec2<i32>(frag.xy));
}

@fragment
fn fs_lambert(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_LAMBERT, vec2<i32>(frag.xy));
}

@fragment
fn fs_toon(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return shade(MODEL_TOON, vec2<i32>(frag.xy));
}

// Debug output: the shadow term of the draw's shadowed light (slot 0), as the passes above use it.
@fragment
fn fs_shadow_term(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let s = load_surface(vec2<i32>(frag.xy));
    let light = incoming(u.lights[0], s);
    let v = shadow_visibility(s, light.direction, u.lights[0]);
    return vec4<f32>(v, v, v, 1.0);
}

// The first draw of every lighting pass: writes depth 0 (vs_fullscreen's) into the pass's cleared
// routing target where the pixel is this model's, and adds nothing to the light buffer. The
// draws that shade follow with an equal-depth test, which the driver runs before their fragment
// shaders: pixels of other models are never shaded, and no shading draw discards.
@fragment
fn fs_route(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    if masked(vec2<i32>(frag.xy)) {
        discard;
    }
    return vec4<f32>(0.0);
}

@fragment
fn fs_unlit(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    if INPUT_FLOOR {
        return input_floor(MODEL_UNLIT, pixel);
    }
    let s = load_surface(pixel);
    return finish(s.base_color * f32(u.counts.y));
}
