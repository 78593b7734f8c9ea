// ShapingAPI on the GPU. Twin of src/cpu/shaping.rs, which carries the spec citations
// (spec/002 cone:angle, cone:softness, focus, focusTint; DESIGN.md §2 "Shaping").
//
// f32: θoff uses atan2_accurate (WGSL's builtin atan2 may err by ~1e-6 rad on lavapipe, which
//   the angle-space smoothstep turns into 1e-4 relative errors near a soft cone edge).
// f32: cone_factor evaluates 1 − smoothstep(θ; start, cone) as smoothstep(cone − θ; 0,
//   cone − start) (equal in exact arithmetic), so that f32 does not cancel where the factor is
//   small; the CPU evaluates the spec's form.
// f32: pow(0, focus) is undefined in WGSL; focus_factor uses the limit 0.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import shared/ies.wgsl

// θoff in radians: atan2(|e × a|, e · a), accurate near 0 where acos is not.
fn off_axis_angle(axis: vec3<f32>, e: vec3<f32>) -> f32 {
    return atan2_accurate(length(cross(e, axis)), dot(e, axis));
}

// UsdLux's _Smoothstep(t, [lo, hi]): a zero-width range is a step that is 0 at and below lo.
fn smoothstep_angle(t: f32, lo: f32, hi: f32) -> f32 {
    if hi - lo == 0.0 {
        return select(1.0, 0.0, t <= lo);
    }
    let s = clamp((t - lo) / (hi - lo), 0.0, 1.0);
    return s * s * (3.0 - 2.0 * s);
}

// 1 - smoothstep(θ; start, θcone), and θ > θcone is always 0.
fn cone_factor(theta: f32, cone: f32, start: f32) -> f32 {
    if theta > cone {
        return 0.0;
    }
    // 1 − smoothstep(s) = smoothstep(1 − s): evaluated from the cone end so that f32 does not
    // cancel where the factor is small.
    if cone - start == 0.0 {
        return 1.0;
    }
    return smoothstep_angle(cone - theta, 0.0, cone - start);
}

// lerp(|cos|^focus, focusTint, 1); white when focus <= 0.
fn focus_factor(focus: f32, tint: vec3<f32>, cos_off: f32) -> vec3<f32> {
    if focus <= 0.0 {
        return vec3<f32>(1.0);
    }
    let c = abs(cos_off);
    // pow(0, y) is undefined in WGSL; the limit for y > 0 is 0.
    let f = select(pow(c, focus), 0.0, c == 0.0);
    return tint + f * (vec3<f32>(1.0) - tint);
}

// The RGB factor ShapingAPI applies along unit emission direction e.
fn shaping(light: Record, e: vec3<f32>) -> vec3<f32> {
    if !has_flag(light, FLAG_SHAPING) {
        return vec3<f32>(1.0);
    }
    let axis = light.axis.xyz;
    let theta = off_axis_angle(axis, e);
    return focus_factor(light.focus_tint.w, light.focus_tint.xyz, dot(e, axis))
        * cone_factor(theta, light.cone.x, light.cone.y) * ies_of(light, e);
}
