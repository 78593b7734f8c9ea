// The outer breakpoints of the chart quadrature. Twin of src/cpu/irradiance/critical.rs,
// which carries the derivations.
//
// f32: arcs are bracketed on IRR_ARC_SAMPLES samples (the CPU: 64) and bisected 26 times (the
//   CPU: 80, f64 resolution), specialised to the chart's arcs (arc_bisect, arc_push_root) where
//   the CPU calls the generic cpu::roots::bracket_roots.
// f32: near-duplicate Ys are merged within 1e-6 of the Y-range (the CPU: 1e-13). At most
//   MAX_YS are kept: a chart that has more (an IES profile's many grid surfaces near a large
//   light) sets irr_cut (shared/record.wgsl), and the host recomputes that receiver.
// f32: an IES profile's grid surfaces (ies_ys) are listed only where the region is a square or
//   a disk (the CPU's chart_ies_kinks bounds a cylinder's too); a cylinder tests every surface,
//   which adds Ys outside the lit part only. Their angle test has a margin of 1e-4 rad (the
//   CPU: 1e-6).
// f32: a plane of the pencil is detected with |m·e1| ≤ 1e-5·|m||e1| (the CPU: 1e-12).
// GPU-only arc_bisect, arc_push_root: see above.
// GPU-only ies_plane: reads a plane of the kinks block (the CPU holds them in a list).

// #import irradiance/chart.wgsl
// #import shared/roots.wgsl
// #import irradiance/kinks.wgsl

const MAX_YS: u32 = 96u;

fn push_y(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, y: f32, c: Chart) {
    if y >= c.ya && y <= c.yb {
        if *count < MAX_YS {
            (*ys)[*count] = y;
            *count += 1u;
        } else {
            // More breakpoints than the array holds: the host recomputes (see the header).
            irr_cut = true;
        }
    }
}

fn push_dir(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, w: vec3<f32>, c: Chart) {
    let y = chart_y(c, w);
    if y.y > 0.0 {
        push_y(ys, count, y.x, c);
    }
}

// The Ys of the planes of the pencil (the planes through x holding e1) tangent to the cone
// −ŵ·axis = cs: |m·axis| = sin θ.
fn pencil_tangent_ys(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, axis: vec3<f32>, cs: f32) {
    let e1u = normalize(c.e1);
    let m1 = orthonormal_pair_a(e1u);
    let m2 = orthonormal_pair_b(e1u);
    let pa = dot(m1, axis);
    let pb = dot(m2, axis);
    let ra = sqrt(pa * pa + pb * pb);
    let s = sqrt(max(1.0 - cs * cs, 0.0));
    if ra >= s && ra > 0.0 {
        let t0 = atan2_accurate(pb, pa);
        let q = clamp(s / ra, -1.0, 1.0);
        let d = atan2_accurate(sqrt(max(1.0 - q * q, 0.0)), q);
        for (var k = 0; k < 2; k++) {
            let t = select(t0 - d, t0 + d, k == 0);
            let mm = m1 * cos(t) + m2 * sin(t);
            let me2 = dot(mm, c.e2);
            if me2 != 0.0 {
                push_y(ys, count, -dot(mm, c.w0) / me2, c);
            }
        }
    }
}

// Crossings of the cone −ŵ·axis = cs with elliptic arc i: bracketing on IRR_ARC_SAMPLES
// samples, a check of each sample interval's interior extremum, then bisection.
fn arc_cone_crossings(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, i: u32, axis: vec3<f32>, cs: f32) {
    let h = (c.t1 - c.t0) / f32(IRR_ARC_SAMPLES);
    var ta = c.t0;
    var fa = arc_f(c, i, axis, cs, ta);
    for (var j = 1u; j <= IRR_ARC_SAMPLES; j++) {
        let tb = c.t0 + h * f32(j);
        let fb = arc_f(c, i, axis, cs, tb);
        if (fa.x > 0.0) != (fb.x > 0.0) {
            arc_push_root(ys, count, c, i, axis, cs, arc_bisect(c, i, axis, cs, ta, tb, false));
        } else if fa.y * fb.y < 0.0 {
            let te = arc_bisect(c, i, axis, cs, ta, tb, true);
            let fe = arc_f(c, i, axis, cs, te).x;
            if (fe > 0.0) != (fa.x > 0.0) {
                arc_push_root(ys, count, c, i, axis, cs, arc_bisect(c, i, axis, cs, ta, te, false));
                arc_push_root(ys, count, c, i, axis, cs, arc_bisect(c, i, axis, cs, te, tb, false));
            }
        }
        ta = tb;
        fa = fb;
    }
}

// Local minima of |w(t)|² on arc i (w·w' = 0 rising through zero): the arc's nearest points.
fn arc_nearest(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, i: u32) {
    let h = (c.t1 - c.t0) / f32(IRR_ARC_SAMPLES);
    var ta = c.t0;
    var da = arc_d(c, i, ta);
    for (var j = 1u; j <= IRR_ARC_SAMPLES; j++) {
        let tb = c.t0 + h * f32(j);
        let db = arc_d(c, i, tb);
        if da < 0.0 && db >= 0.0 {
            var lo = ta;
            var hi = tb;
            for (var k = 0; k < 26; k++) {
                let mid = 0.5 * (lo + hi);
                if arc_d(c, i, mid) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            push_dir(ys, count, arc_at(c, i, 0.5 * (lo + hi)), c);
        }
        ta = tb;
        da = db;
    }
}

// ½ d|w|²/dt on arc i.
fn arc_d(c: Chart, i: u32, t: f32) -> f32 {
    return dot(arc_at(c, i, t), c.arc_v * cos(t) - c.arc_u * sin(t));
}

// F(t) = (w·a)² − cs²|w|² and F'(t) on arc i.
fn arc_f(c: Chart, i: u32, axis: vec3<f32>, cs: f32, t: f32) -> vec2<f32> {
    let w = arc_at(c, i, t);
    let dw = c.arc_v * cos(t) - c.arc_u * sin(t);
    let wa = dot(w, axis);
    return vec2<f32>(wa * wa - cs * cs * dot(w, w), 2.0 * wa * dot(dw, axis) - 2.0 * cs * cs * dot(w, dw));
}

// A sign change of F (derivative = false) or of F' (true) in [a, b], by bisection.
fn arc_bisect(c: Chart, i: u32, axis: vec3<f32>, cs: f32, a: f32, b: f32, derivative: bool) -> f32 {
    var lo = a;
    var hi = b;
    let flo = arc_f(c, i, axis, cs, lo);
    let slo = select(flo.x, flo.y, derivative) > 0.0;
    for (var k = 0; k < 26; k++) {
        let mid = 0.5 * (lo + hi);
        let fm = arc_f(c, i, axis, cs, mid);
        if (select(fm.x, fm.y, derivative) > 0.0) == slo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return 0.5 * (lo + hi);
}

fn arc_push_root(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, i: u32, axis: vec3<f32>, cs: f32, t: f32) {
    let w = arc_at(c, i, t);
    if -dot(w, axis) * cs > 0.0 {
        push_dir(ys, count, w, c);
    }
}

// The Ys where a plane m·w = 0 through x meets the chart's inner structure: the line of the
// pencil lying in it, its crossings with the square's sides and with the arcs (critical_ys's
// planes and ies_ys's profile planes).
fn plane_ys(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, m: vec3<f32>) {
    let me1 = dot(m, c.e1);
    let me2 = dot(m, c.e2);
    let mw0 = dot(m, c.w0);
    if abs(me1) <= 1e-5 * length(m) * length(c.e1) && me2 != 0.0 {
        push_y(ys, count, -mw0 / me2, c);
    }
    if c.region == REGION_SQUARE && me2 != 0.0 {
        push_y(ys, count, -(mw0 - me1) / me2, c);
        push_y(ys, count, -(mw0 + me1) / me2, c);
    }
    for (var ai = 0u; ai < c.n_arcs; ai++) {
        let cc = select(c.arc_c0, c.arc_c1, ai == 1u);
        let r = lin_trig_roots(dot(m, c.arc_u), dot(m, c.arc_v), -dot(m, cc));
        if r.z > 0.0 {
            let ta = wrap_into(r.x, c.t0);
            if ta <= c.t1 {
                push_dir(ys, count, arc_at(c, ai, ta), c);
            }
            let tb = wrap_into(r.y, c.t0);
            if tb <= c.t1 {
                push_dir(ys, count, arc_at(c, ai, tb), c);
            }
        }
    }
}

// The Ys where the cone of `axis` and cosine cs meets the chart's inner structure: tangent to a
// line of the pencil, crossing the square's sides and the arcs (critical_ys's kink cones and
// ies_ys's profile cones).
fn cone_ys(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, axis: vec3<f32>, cs: f32) {
    pencil_tangent_ys(ys, count, c, axis, cs);
    if c.region == REGION_SQUARE {
        for (var k = 0; k < 2; k++) {
            let xs = select(1.0, -1.0, k == 0);
            let r = cone_roots_on_line(axis, cs, c.w0 + c.e1 * xs, c.e2);
            let mask = u32(r.z);
            if (mask & 1u) != 0u {
                push_y(ys, count, r.x, c);
            }
            if (mask & 2u) != 0u {
                push_y(ys, count, r.y, c);
            }
        }
    }
    for (var ai = 0u; ai < c.n_arcs; ai++) {
        arc_cone_crossings(ys, count, c, ai, axis, cs);
    }
}

// The Y values where the inner structure of the chart integral changes, sorted and
// de-duplicated, including the region's Y-range ends (see the CPU twin).
fn critical_ys(light: Record, c: Chart, n: vec3<f32>, ys: ptr<function, array<f32, MAX_YS>>) -> u32 {
    var count = 0u;
    (*ys)[0] = c.ya;
    (*ys)[1] = c.yb;
    count = 2u;
    let axis = light.axis.xyz;
    let n_planes = select(1u, 2u, has_flag(light, FLAG_FOCUS_PLANE));
    let n_cones = kink_count(light);
    for (var pi = 0u; pi < n_planes; pi++) {
        let m = select(n, axis, pi == 1u);
        plane_ys(ys, &count, c, m);
        // Plane ∩ the other plane.
        if n_planes == 2u {
            let d = cross(n, axis);
            if dot(d, d) > 0.0 && pi == 0u {
                push_dir(ys, &count, d, c);
                push_dir(ys, &count, -d, c);
            }
        }
        for (var ci = 0u; ci < n_cones; ci++) {
            let dirs = plane_cone_dirs(m, axis, kink_cos(light, ci));
            if dirs.ok {
                push_dir(ys, &count, dirs.a, c);
                push_dir(ys, &count, dirs.b, c);
            }
        }
    }
    for (var ci = 0u; ci < n_cones; ci++) {
        cone_ys(ys, &count, c, axis, kink_cos(light, ci));
    }
    // The outer integrand peaks where a curve bounding the inner intervals (a region edge, a
    // cone edge, the focus line) comes nearest to x: split there too.
    if c.region == REGION_SQUARE {
        let e22 = dot(c.e2, c.e2);
        push_y(ys, &count, -dot(c.w0 - c.e1, c.e2) / e22, c);
        push_y(ys, &count, -dot(c.w0 + c.e1, c.e2) / e22, c);
    }
    for (var ai = 0u; ai < c.n_arcs; ai++) {
        arc_nearest(ys, &count, c, ai);
    }
    let nc = cross(c.e1, c.e2);
    let nrm = normalize(nc) * sign(dot(c.w0, nc));
    let p = -axis;
    let perp = nrm - p * dot(nrm, p);
    for (var ci = 0u; ci < n_cones; ci++) {
        let cs = kink_cos(light, ci);
        if dot(perp, perp) > 0.0 {
            push_dir(ys, &count, p * cs + normalize(perp) * sqrt(max(1.0 - cs * cs, 0.0)), c);
        }
    }
    if n_planes == 2u && dot(perp, perp) > 0.0 {
        push_dir(ys, &count, perp, c);
    }
    if has_flag(light, FLAG_AXIS_SINGULAR) {
        let m = cross(c.e1, axis);
        let me2 = dot(m, c.e2);
        if me2 != 0.0 {
            push_y(ys, &count, -dot(m, c.w0) / me2, c);
        }
    }
    if has_flag(light, FLAG_IES) {
        ies_ys(light, c, n, ys, &count);
    }
    // Insertion sort, then drop near-duplicates.
    for (var i = 1u; i < count; i++) {
        let v = (*ys)[i];
        var j = i;
        while j > 0u && (*ys)[j - 1u] > v {
            (*ys)[j] = (*ys)[j - 1u];
            j -= 1u;
        }
        (*ys)[j] = v;
    }
    let span = c.yb - c.ya;
    var kept = 1u;
    for (var i = 1u; i < count; i++) {
        if (*ys)[i] - (*ys)[kept - 1u] > 1e-6 * span {
            (*ys)[kept] = (*ys)[i];
            kept += 1u;
        }
    }
    // Keep the upper end exact.
    (*ys)[kept - 1u] = c.yb;
    return kept;
}

// Plane k of a kinks block (src/gpu/ies_atlas.rs): the pencil's (normal from its (u, v)
// coordinates), then the others.
fn ies_plane(kb: u32, k: u32, np: u32, normals_off: u32, u: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    if k < np {
        return u * ies_atlas[normals_off + 2u * k] + v * ies_atlas[normals_off + 2u * k + 1u];
    }
    return kink_vec(kb, 12u + 3u * (k - np));
}

// The Ys where an IES profile's grid surfaces change the inner structure (see the CPU twin):
// the chart in the light's frame (a linear map keeps X and Y), each cone and plane of the
// kinks block (src/gpu/ies_atlas.rs) that can meet the region's directions tangent to a line
// of the pencil, crossing the region's edges and arcs, the horizon, the focus plane and the
// profile's other surfaces.
fn ies_ys(light: Record, c: Chart, n: vec3<f32>, ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>) {
    let kb = u32(light.ies.w);
    var lc = c;
    lc.w0 = to_local_dir(light, c.w0);
    lc.e1 = to_local_dir(light, c.e1);
    lc.e2 = to_local_dir(light, c.e2);
    lc.arc_c0 = to_local_dir(light, c.arc_c0);
    lc.arc_c1 = to_local_dir(light, c.arc_c1);
    lc.arc_u = to_local_dir(light, c.arc_u);
    lc.arc_v = to_local_dir(light, c.arc_v);
    // Planes through x: a world normal m is Mᵀm here (the receiver's horizon, the focus plane).
    let fixed0 = vec3<f32>(dot(light.world_x.xyz, n), dot(light.world_y.xyz, n), dot(light.world_z.xyz, n));
    let ax = light.axis.xyz;
    let fixed1 = vec3<f32>(dot(light.world_x.xyz, ax), dot(light.world_y.xyz, ax), dot(light.world_z.xyz, ax));
    let n_fixed = select(1u, 2u, has_flag(light, FLAG_FOCUS_PLANE));
    // The region's directions lie within alpha of w0 (CPU: outer::direction_cone).
    var r = 1e30;
    if lc.region == REGION_SQUARE {
        r = length(lc.e1) + length(lc.e2);
    } else if lc.region == REGION_DISK {
        r = sqrt(dot(lc.e1, lc.e1) + dot(lc.e2, lc.e2));
    }
    let dw = length(lc.w0);
    var alpha = 10.0;
    if r < 0.5 * dw {
        alpha = asin(r / dw) + 1e-4;
    }
    let cdir = -lc.w0 / dw;
    let nc = u32(ies_atlas[kb]);
    let axis_c = kink_vec(kb, 1u);
    let theta_c = atan2_accurate(length(cross(cdir, axis_c)), dot(cdir, axis_c));
    let np = u32(ies_atlas[kb + 4u]);
    let p = kink_vec(kb, 5u);
    let u = kink_vec(kb, 8u);
    let v = cross(p, u);
    let ne = u32(ies_atlas[kb + 11u]);
    let cos_off = kb + IES_KINKS_HEADER;
    let normals_off = cos_off + nc + np;
    // Cones: tangent to the pencil, across the square's sides and the arcs, across the fixed
    // planes.
    for (var k = 0u; k < nc; k++) {
        let cs = ies_atlas[cos_off + k];
        let theta_k = atan2_accurate(sqrt(max(1.0 - cs * cs, 0.0)), cs);
        if abs(theta_c - theta_k) > alpha {
            continue;
        }
        cone_ys(ys, count, lc, axis_c, cs);
        for (var f = 0u; f < n_fixed; f++) {
            let dirs = plane_cone_dirs(select(fixed0, fixed1, f == 1u), axis_c, cs);
            if dirs.ok {
                push_dir(ys, count, dirs.a, lc);
                push_dir(ys, count, dirs.b, lc);
            }
        }
    }
    // Planes (the pencil's, then the others): along a line of the pencil, across the square's
    // sides and the arcs, across the fixed planes, the other planes and the cones.
    if np >= 2u {
        push_dir(ys, count, p, lc);
        push_dir(ys, count, -p, lc);
    }
    for (var k = 0u; k < np + ne; k++) {
        let m = ies_plane(kb, k, np, normals_off, u, v);
        if asin(min(abs(dot(normalize(m), cdir)), 1.0)) > alpha {
            continue;
        }
        plane_ys(ys, count, lc, m);
        for (var f = 0u; f < n_fixed; f++) {
            let d = cross(m, select(fixed0, fixed1, f == 1u));
            if dot(d, d) > 0.0 {
                push_dir(ys, count, d, lc);
                push_dir(ys, count, -d, lc);
            }
        }
        // Plane ∩ plane: the pencil's meet on its axis (above); an other plane meets each.
        if k >= np {
            for (var k2 = 0u; k2 < np + ne; k2++) {
                let m2 = ies_plane(kb, k2, np, normals_off, u, v);
                if asin(min(abs(dot(normalize(m2), cdir)), 1.0)) > alpha {
                    continue;
                }
                let d = cross(m, m2);
                if dot(d, d) > 0.0 {
                    push_dir(ys, count, d, lc);
                    push_dir(ys, count, -d, lc);
                }
            }
        }
        for (var kc = 0u; kc < nc; kc++) {
            let cs = ies_atlas[cos_off + kc];
            let theta_k = atan2_accurate(sqrt(max(1.0 - cs * cs, 0.0)), cs);
            if abs(theta_c - theta_k) > alpha {
                continue;
            }
            let dirs = plane_cone_dirs(m, axis_c, cs);
            if dirs.ok {
                push_dir(ys, count, dirs.a, lc);
                push_dir(ys, count, dirs.b, lc);
            }
        }
    }
}
