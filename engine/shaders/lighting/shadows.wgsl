// Lighting shader, part 2 of 6: shadow lookups (filters, the point-light atlas, variance
// maps) and the visibility of a surface point from the shadowed light.

fn shadow_tap(uv: vec2<f32>, reference: f32, bounds: vec4<f32>) -> f32 {
    return textureSampleCompareLevel(shadow_map, shadow_sampler, clamp(uv, bounds.xy, bounds.zw), reference);
}

// Where a point light's atlas is read for a camera-relative point `p` at `d` = p - light.
struct AtlasTap {
    uv: vec2<f32>,
    reference: f32,
    // Min uv (xy) and max uv (zw) of the face, half a texel in, so taps never read a neighbour.
    bounds: vec4<f32>,
}

fn atlas_tap(p: vec3<f32>, d: vec3<f32>) -> AtlasTap {
    let a = abs(d);
    var face = 0u;
    if a.x >= a.y && a.x >= a.z {
        face = select(1u, 0u, d.x > 0.0);
    } else if a.y >= a.z {
        face = select(3u, 2u, d.y > 0.0);
    } else {
        face = select(5u, 4u, d.z > 0.0);
    }
    let clip = shadow.faces[face] * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    let tile = vec2<f32>(f32(face % 3u), f32(face / 3u));
    let face_uv = clamp(vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5), vec2<f32>(0.0), vec2<f32>(1.0));
    let half_texel = 0.5 * shadow.map.yz;
    var tap: AtlasTap;
    tap.uv = (tile + face_uv) / vec2<f32>(3.0, 2.0);
    tap.reference = clamp(ndc.z, 0.0, 1.0);
    tap.bounds = vec4<f32>(tile / vec2<f32>(3.0, 2.0) + half_texel, (tile + 1.0) / vec2<f32>(3.0, 2.0) - half_texel);
    return tap;
}

// A filtered shadow lookup: the receiver's map coordinates, and for point lights what the soft
// filters need to offset the lookup direction instead (Listing 3 of the Quarantamaula engine
// document), so their kernels
// cross cube-face edges instead of being clamped at them.
struct ShadowLookup {
    uv: vec2<f32>,
    reference: f32,
    bounds: vec4<f32>,
    pixel: vec2<i32>,
    // Point lights: the light's camera-relative position, the receiver minus the light, and two
    // axes perpendicular to it whose length is the soft filter's radius at the receiver.
    light: vec3<f32>,
    d: vec3<f32>,
    axis_u: vec3<f32>,
    axis_v: vec3<f32>,
}

// One tap of a soft filter at `o` in the unit disk (scaled to the soft radius).
fn soft_tap(look: ShadowLookup, o: vec2<f32>) -> f32 {
    if SHADOW_KIND != 2u {
        return shadow_tap(look.uv + o * (shadow.soft.x * shadow.map.yz), look.reference, look.bounds);
    }
    let q = normalize(look.d + o.x * look.axis_u + o.y * look.axis_v) * length(look.d);
    let tap = atlas_tap(look.light + q, q);
    return shadow_tap(tap.uv, tap.reference, tap.bounds);
}

// Stratified soft shadows (GPU Gems 2, ch. 17, as the Quarantamaula engine uses them): the
// outer ring's four samples first; if they agree (all lit or all shadowed) and early-out is on,
// that is the answer; otherwise all sixteen samples are averaged.
fn shadow_soft(look: ShadowLookup, early_out: bool) -> f32 {
    let cell = vec2<i32>(look.pixel.x & 31, look.pixel.y & 31);
    var outer = 0.0;
    for (var k = 0; k < 2; k++) {
        let o = textureLoad(shadow_jitter, cell, 6 + k, 0);
        outer += soft_tap(look, o.xy);
        outer += soft_tap(look, o.zw);
    }
    if early_out && (outer == 0.0 || outer == 4.0) {
        return outer * 0.25;
    }
    var sum = outer;
    for (var layer = 0; layer < 6; layer++) {
        let o = textureLoad(shadow_jitter, cell, layer, 0);
        sum += soft_tap(look, o.xy);
        sum += soft_tap(look, o.zw);
    }
    return sum / 16.0;
}

// Soft filter on a golden-angle (Vogel) disk of VOGEL_SAMPLES samples, no jitter: the `vogel` filter,
// and at 1024 samples the converged reference for sweeps.
fn shadow_vogel(look: ShadowLookup) -> f32 {
    let count = max(i32(VOGEL_SAMPLES), 1);
    var sum = 0.0;
    for (var i = 0; i < count; i++) {
        let r = sqrt((f32(i) + 0.5) / f32(count));
        let angle = f32(i) * 2.39996323;
        sum += soft_tap(look, vec2<f32>(cos(angle), sin(angle)) * r);
    }
    return sum / f32(count);
}

// Variance shadow maps (directional lights): Chebyshev's upper bound on the lit fraction from
// the filtered moments, with a minimum variance and light-bleeding reduction (as the io7m r2
// renderer implements GPU Gems 3, ch. 8).
fn shadow_vsm(look: ShadowLookup) -> f32 {
    let m = textureSampleLevel(shadow_moments, moments_sampler, look.uv, 0.0);
    let mean = m.r + m.g;
    if look.reference <= mean {
        return 1.0;
    }
    let variance = max((m.b + m.a) - mean * mean, shadow.vsm.x);
    let delta = look.reference - mean;
    let p_max = variance / (variance + delta * delta);
    let cut = shadow.vsm.y;
    return clamp((p_max - cut) / (1.0 - cut), 0.0, 1.0);
}

// Filtered comparison of the receiver against the map, by the draw's filter; hard and 3x3 PCF
// taps stay in the map's uv space, clamped inside `bounds` (a point light's face).
fn shadow_lookup(look: ShadowLookup) -> f32 {
    if SHADOW_FILTER == 6u || SHADOW_FILTER == 4u {
        return shadow_vogel(look);
    }
    if SHADOW_FILTER == 5u {
        return shadow_vsm(look);
    }
    if SHADOW_FILTER == 2u || SHADOW_FILTER == 3u {
        return shadow_soft(look, SHADOW_FILTER == 2u);
    }
    if SHADOW_FILTER == 0u || SHADOW_FILTER == 7u {
        return shadow_tap(look.uv, look.reference, look.bounds);
    }
    if SHADOW_FILTER == 8u {
        let h = 0.5 * shadow.map.yz;
        return 0.25 * (shadow_tap(look.uv + vec2<f32>(-h.x, -h.y), look.reference, look.bounds)
            + shadow_tap(look.uv + vec2<f32>(h.x, -h.y), look.reference, look.bounds)
            + shadow_tap(look.uv + vec2<f32>(-h.x, h.y), look.reference, look.bounds)
            + shadow_tap(look.uv + vec2<f32>(h.x, h.y), look.reference, look.bounds));
    }
    var sum = 0.0;
    for (var y = -1; y <= 1; y++) {
        for (var x = -1; x <= 1; x++) {
            let offset = vec2<f32>(f32(x), f32(y)) * shadow.map.yz;
            sum += shadow_tap(look.uv + offset, look.reference, look.bounds);
        }
    }
    return sum / 9.0;
}

// Fraction of the light reaching the surface (1 = lit) for the draw's shadowed light.
fn shadow_visibility(s: Surface, l: vec3<f32>, light: LightData) -> f32 {
    if SHADOW_KIND == 0u {
        return 1.0;
    }
    let n_dot_l = clamp(dot(s.normal, l), 0.0, 1.0);
    let tan_theta = min(sqrt(max(1.0 - n_dot_l * n_dot_l, 0.0)) / max(n_dot_l, 1e-4), 10.0);
    // Texel size at the receiver, in meters.
    var texel = shadow.map.w;
    if SHADOW_KIND == 2u {
        texel = shadow.map.w * length(light.position.xyz - s.position);
    }
    // Slope-scaled and normal-offset parts are in texels, times the filter's reach (3x3 PCF
    // reads one texel further out than a single tap, the soft filters their radius further).
    let reach = shadow.soft.y;
    let bias = shadow.params.y + shadow.params.z * texel * tan_theta * reach;
    let p = s.position + s.normal * (shadow.params.w * texel * reach) + l * bias;
    var look: ShadowLookup;
    look.pixel = s.pixel;
    if SHADOW_KIND == 1u {
        let clip = shadow.faces[0] * vec4<f32>(p, 1.0);
        let ndc = clip.xyz / clip.w;
        look.uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
        if any(look.uv < vec2<f32>(0.0)) || any(look.uv > vec2<f32>(1.0)) {
            return 1.0;
        }
        // Receivers beyond the casters' far plane compare at the far plane.
        look.reference = min(ndc.z, 1.0);
        look.bounds = vec4<f32>(0.0, 0.0, 1.0, 1.0);
        return shadow_lookup(look);
    }
    let d = p - light.position.xyz;
    let tap = atlas_tap(p, d);
    look.uv = tap.uv;
    look.reference = tap.reference;
    look.bounds = tap.bounds;
    look.light = light.position.xyz;
    look.d = d;
    let n = safe_normalize(d, vec3<f32>(0.0, 0.0, 1.0));
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    let u_axis = normalize(cross(n, helper));
    // The disk is `soft_radius` texels of the face at this direction: a face texel subtends
    // less angle off the face's axis, by about s^1.5 with s = |d| / (largest |d| component).
    let a = abs(d);
    let s_off_axis = length(d) / max(max(a.x, max(a.y, a.z)), 1e-20);
    let radius = shadow.soft.x * texel / (s_off_axis * sqrt(s_off_axis));
    look.axis_u = u_axis * radius;
    look.axis_v = cross(n, u_axis) * radius;
    return shadow_lookup(look);
}

