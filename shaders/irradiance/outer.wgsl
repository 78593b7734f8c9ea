// The outer (across lines) integral of the chart quadrature, and treatAsLine.
// Twin of src/cpu/irradiance/outer.rs, which carries the derivations.
//
// f32: the kernel's outer rule: per span the Gauss–Kronrod 7/15 pair, halved while Gauss and
//   Kronrod differ by more than IRR_OUTER_TOL of the Kronrod value, at most IRR_OUTER_DEPTH
//   times, depth first, instead of the reference's globally adaptive Gauss–Kronrod to 1e-9.
// f32: every loop checks its own condition after it ends and sets irr_cut if it stopped short
//   (lavapipe's loop budget, see shared/record.wgsl); the CPU has no such limit.
// f32: a textured rect's horizontal break lines (texel-centre lines or texel edges) are
//   streamed into the pieces between the critical Ys (irradiance/line.wgsl texel_break_after;
//   the CPU lists them in critical_ys). The Ys where the vertical ones meet the receiver's
//   horizon, the focus plane or the kink cones or come nearest to x (the CPU's critical_ys
//   treats them as straight edges) are not split at: the outer integrand stays continuous
//   there (each line is split at the texture's lines, and the horizon's factor vanishes on
//   it), only a derivative changes abruptly, and the adaptive outer rule resolves that;
//   tests/rect_conformance.rs holds the result to the reference's.
// GPU-only outer_gk, outer_adaptive: the kernel's outer rule (above).

// #import irradiance/chart.wgsl
// #import irradiance/critical.wgsl
// #import irradiance/pieces.wgsl
// #import irradiance/line.wgsl

// The nearest singularity (y_foot, width) of the outer integrand on [y0, y1]: the Lorentzian of
// the distance to the chart plane, widened when the foot of x lies outside the region's
// X-interval (see the CPU twin).
fn outer_pole(c: Chart, y0: f32, y1: f32) -> vec2<f32> {
    let u = cross(c.w0, c.e1);
    let v = cross(c.e2, c.e1);
    let vv = dot(v, v);
    let y_foot = -dot(u, v) / vv;
    let e1l = length(c.e1);
    let h = c.jac / sqrt(vv);
    let x_foot = -dot(c.w0 + c.e2 * y_foot, c.e1) / (e1l * e1l);
    let xi = x_interval(c, clamp(y_foot, y0, y1));
    var d = 0.0;
    if xi.z > 0.0 {
        d = max(max(xi.x - x_foot, x_foot - xi.y), 0.0);
    }
    return vec2<f32>(y_foot, sqrt(h * h + d * e1l * d * e1l) * e1l / sqrt(vv));
}

// A cone holding every direction of the chart's region (see the CPU twin): (unit ŵ0, half-angle
// asin(R/|w0|)), or w = -1 where R is not below |w0|/2 and for a cylinder's region (the CPU
// bounds that one too; the kernel does not use it).
fn direction_cone(c: Chart) -> vec4<f32> {
    var r = -1.0;
    if c.region == REGION_SQUARE {
        r = length(c.e1) + length(c.e2);
    } else if c.region == REGION_DISK {
        r = sqrt(dot(c.e1, c.e1) + dot(c.e2, c.e2));
    }
    let d = length(c.w0);
    if !(r >= 0.0) || !(r < 0.5 * d) {
        return vec4<f32>(0.0, 0.0, 0.0, -1.0);
    }
    return vec4<f32>(c.w0 / d, asin(r / d));
}

// The Gauss–Kronrod 7/15 pair on [s0, s1] of one outer span's parameter: (Kronrod value,
// |Kronrod − Gauss| in the largest channel).
fn outer_gk(light: Record, c: Chart, n: vec3<f32>, sp: PieceMap, s0: f32, s1: f32) -> vec4<f32> {
    let h = s1 - s0;
    var k = vec3<f32>(0.0);
    var g = vec3<f32>(0.0);
    {
        var i = 0u;
        for (; i < 15u; i++) {
            let yd = map_eval(sp, s0 + h * IRR_GK_X[i], true);
            if yd.y == 0.0 {
                continue;
            }
            let xi = x_interval(c, yd.x);
            if xi.z > 0.0 {
                let v = line_integral(light, n, c.w0 + c.e2 * yd.x, c.e1, yd.x, xi.x, xi.y) * (h * yd.y * c.jac);
                k += IRR_GK_WK[i] * v;
                g += IRR_GK_WG[i] * v;
            }
        }
        if i < 15u {
            // Cut short by the device's loop budget (see irr_cut).
            irr_cut = true;
        }
    }
    return vec4<f32>(k, max3(abs(k - g)));
}

// One outer span: the pair, halved while it disagrees by more than IRR_OUTER_TOL (relative) and
// depth allows, depth first (the CPU twin: Nodes::integrate in src/cpu/irradiance.rs).
fn outer_adaptive(light: Record, c: Chart, n: vec3<f32>, sp: PieceMap) -> vec3<f32> {
    var lo: array<f32, IRR_OUTER_DEPTH + 1u>;
    var hi: array<f32, IRR_OUTER_DEPTH + 1u>;
    var dep: array<u32, IRR_OUTER_DEPTH + 1u>;
    lo[0] = 0.0;
    hi[0] = 1.0;
    dep[0] = 0u;
    var top = 1u;
    var sum = vec3<f32>(0.0);
    while top > 0u {
        top -= 1u;
        let s0 = lo[top];
        let s1 = hi[top];
        let d = dep[top];
        let r = outer_gk(light, c, n, sp, s0, s1);
        if d + 1u >= IRR_OUTER_DEPTH || r.w <= IRR_OUTER_TOL * max3(abs(r.xyz)) {
            sum += r.xyz;
        } else {
            let mid = 0.5 * (s0 + s1);
            lo[top] = mid;
            hi[top] = s1;
            dep[top] = d + 1u;
            lo[top + 1u] = s0;
            hi[top + 1u] = mid;
            dep[top + 1u] = d + 1u;
            top += 2u;
        }
    }
    if top > 0u {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}

// ∫∫ S(−ŵ)·max(0, n·w)·J/|w|⁴ dX dY over the chart's region (the base radiance not applied).
fn chart_integral(light: Record, c: Chart, n: vec3<f32>) -> vec3<f32> {
    if has_flag(light, FLAG_DARK) || !(c.jac > 0.0) {
        return vec3<f32>(0.0);
    }
    var ys: array<f32, MAX_YS>;
    let count = critical_ys(light, c, n, &ys);
    // A textured rect's horizontal break lines, streamed into the pieces (see the header).
    let rows = texel_axis(light, false);
    var total = vec3<f32>(0.0);
    {
        var i = 0u;
        for (; i + 1u < count; i++) {
            var y0 = ys[i];
            var more = true;
            while more {
                var y1 = texel_break_after(rows, y0);
                if !(y1 < ys[i + 1u]) {
                    y1 = ys[i + 1u];
                    more = false;
                }
                let pole = outer_pole(c, y0, y1);
                let pm = piece_map(y0, y1, pole.x, pole.y, false, false);
                let spans = span_count(pm);
                {
                    var j = 0u;
                    for (; j < spans; j++) {
                        total += outer_adaptive(light, c, n, span(pm, j, spans));
                    }
                    if j < spans {
                        // Cut short by the device's loop budget (see irr_cut).
                        irr_cut = true;
                    }
                }
                y0 = y1;
            }
            if more {
                // Cut short by the device's loop budget (see irr_cut).
                irr_cut = true;
            }
        }
        if i + 1u < count {
            // Cut short by the device's loop budget (see irr_cut).
            irr_cut = true;
        }
    }
    return total;
}

// treatAsLine: the segment along the axis with weight 2 r |det M| ρ (see the CPU twin).
fn line_irradiance(light: Record, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let hl = light.size.x;
    let r = light.size.y;
    let xl = to_local_point(light, x);
    let weight = 2.0 * r * light.irr.y * length(xl.yz);
    if !(weight > 0.0) || !(hl > 0.0) || has_flag(light, FLAG_DARK) {
        return vec3<f32>(0.0);
    }
    return light.base.xyz * line_integral(light, n, world_origin(light) - x, light.world_x.xyz, 0.0, -hl, hl) * weight;
}
