// The scene-level light choice of GPU-resident sampling (DESIGN.md §9 S1 "Scene level"), f32.
// Twin of src/cpu/sample/select.rs, which carries the weights' reasons and their citation.
//
// The f64 per-light factors (the power weight; the luminance of base) come from the record's
// `select`, each divided by the scene's largest (query::scene fills them, so that f32 holds their
// ratios whatever the scene's units); the receiver-aware factors are computed here.
// f32: choose compares u·total with a running f32 sum, so that near the border between two
//   lights' shares of [0, 1) it may name the neighbour of the light the CPU names.
// f32: α = asin(r/d) as atan2_accurate(r/d, √(1 − (r/d)²)): lavapipe's asin errs by ~3e-4 rad
//   (measured here: a bound weight 3e-4 off in its spot factor), where atan2_accurate stays
//   within ~2e-7 rad (shared/math.wgsl).
// GPU-only selection_weight: one light's weight, the body of selection_weights' loop (WGSL keeps
//   no per-receiver array of weights: choose evaluates each weight twice, for the total and the
//   pick).

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import shared/shaping.wgsl
// #import sample/cone.wgsl

// Light `light`'s weight at (x, n) (n zero for none) under params.select's rule.
fn selection_weight(light: Record, x: vec3<f32>, n: vec3<f32>) -> f32 {
    var w = light.select.x;
    if (params.select & 15u) == SELECT_BOUND {
        w = bound_weight(light, x, n);
    }
    return select(0.0, w, w > 0.0 && w < 3.0e38);
}

// Selection::Bound's estimate: Y(base) · Ω̃ · cos_bound · spot_bound (cpu::sample::select).
fn bound_weight(light: Record, x: vec3<f32>, n: vec3<f32>) -> f32 {
    if has_flag(light, FLAG_DARK) {
        return 0.0;
    }
    let y = light.select.y;
    // The bound's cone: its axis toward the light, half-angle α with (cos α, sin α), and Ω̃.
    var axis = vec3<f32>(0.0, 1.0, 0.0);
    var alpha = 0.0;
    var cos_a = 1.0;
    var sin_a = 0.0;
    var omega = 1.0;
    switch light.kind {
        case KIND_DOME: {
            return y * PI;
        }
        case KIND_DISTANT: {
            let t = light.axis.w;
            axis = -light.axis.xyz;
            alpha = t;
            cos_a = cos(t);
            sin_a = sin(t);
            if t != 0.0 {
                omega = solid_angle(with_angle(-light.axis.xyz, t));
            }
        }
        default: {
            let xl = to_local_point(light, x);
            let one_sided = light.kind == KIND_RECT || light.kind == KIND_DISK;
            if one_sided && !(xl.z < 0.0) {
                return 0.0;
            }
            let w = world_origin(light) - x;
            let d = length(w);
            let r = light.select.z;
            if !(d > r) {
                if d > 0.0 {
                    axis = w / d;
                }
                alpha = PI;
                cos_a = -1.0;
                omega = 2.0 * PI;
            } else {
                let s = r / d;
                axis = w / d;
                cos_a = sqrt(max(1.0 - s * s, 0.0));
                alpha = atan2_accurate(s, cos_a);
                sin_a = s;
                omega = max(solid_angle(subtended(w / d, r, d)), 1.17549435e-38);
            }
        }
    }
    // cos(max(θ − α, 0)), without acos (cpu::sample::select::bound_weight).
    var cs = 1.0;
    if length(n) > 0.0 {
        let c = dot(n, axis);
        if c < cos_a {
            cs = max(c * cos_a + length(cross(n, axis)) * sin_a, 0.0);
        }
    }
    return y * omega * cs * spot_bound(light, -axis, alpha);
}

// The largest cone factor over the emission directions within alpha of e; 1 for an unshaped
// light, a dome or a distant light.
fn spot_bound(light: Record, e: vec3<f32>, alpha: f32) -> f32 {
    if !has_flag(light, FLAG_SHAPING) || light.kind == KIND_DOME || light.kind == KIND_DISTANT {
        return 1.0;
    }
    let theta = max(off_axis_angle(light.axis.xyz, e) - alpha, 0.0);
    return cone_factor(theta, light.cone.x, light.cone.y);
}

// The light chosen for uniform u among lights [light_first, light_end) by their weights' CDF,
// with its probability: (index, P(l | x)); (−1, 0) where no light has a positive weight. Never a
// light of weight 0.
fn choose(x: vec3<f32>, n: vec3<f32>, u: f32) -> vec2<f32> {
    var total = 0.0;
    for (var k = params.light_first; k < params.light_end; k++) {
        total += selection_weight(lights[k], x, n);
    }
    if !(total > 0.0) {
        return vec2<f32>(-1.0, 0.0);
    }
    let target_sum = u * total;
    var acc = 0.0;
    var last = -1.0;
    var last_w = 0.0;
    for (var k = params.light_first; k < params.light_end; k++) {
        let w = selection_weight(lights[k], x, n);
        if w > 0.0 {
            acc += w;
            last = f32(k);
            last_w = w;
            if target_sum < acc {
                return vec2<f32>(f32(k), w / total);
            }
        }
    }
    return vec2<f32>(last, last_w / total);
}
