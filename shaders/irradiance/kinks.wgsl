// The IES profile's kink surfaces a line crosses, in the order it crosses them: the streamed
// breakpoints of irradiance/line.wgsl (its header says how they differ from the CPU's).
//
// No CPU twin: the CPU lists the profile's cones and planes that can meet the chart and sorts
//   all their roots on each line (cpu/irradiance/line.rs); the kernel has no array of a
//   profile's size and walks them instead. Data: a kinks block of the IES atlas
//   (src/gpu/ies_atlas.rs, prepare::ies_kinks::KinkFamilies), at the record's ies.w.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import shared/roots.wgsl

// The vec3 at float offset o of the kinks block at kb (its axes and the extra planes' normals).
fn kink_vec(kb: u32, o: u32) -> vec3<f32> {
    return vec3<f32>(ies_atlas[kb + o], ies_atlas[kb + o + 1u], ies_atlas[kb + o + 2u]);
}

// One binary-search step over the sorted floats ies_atlas[off + i], i < n, for the count of
// those below x (or not above x, with `inclusive`): lh = (lo, hi) brackets the count. Written
// out, not looped (see IES_SEARCH_STEPS in shared/ies.wgsl: lavapipe's loop budget).
fn kink_step(off: u32, x: f32, inclusive: bool, lh: vec2<u32>) -> vec2<u32> {
    if lh.x >= lh.y {
        return lh;
    }
    let mid = (lh.x + lh.y) / 2u;
    let v = ies_atlas[off + mid];
    if v < x || (inclusive && v == x) {
        return vec2<u32>(mid + 1u, lh.y);
    }
    return vec2<u32>(lh.x, mid);
}

// How many of the n sorted floats at ies_atlas[off] are below x (inclusive: not above x);
// KINK_SEARCH_STEPS halvings cover the longest list the packer writes.
fn kink_rank(off: u32, n: u32, x: f32, inclusive: bool) -> u32 {
    var lh = vec2<u32>(0u, n);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    lh = kink_step(off, x, inclusive, lh);
    return lh.x;
}

// A run of IES kinks a line crosses on one side [s0, s1] of its split point: `left` crossings
// remain, the next at list index `idx` (stepping up or down, cyclically for planes); `next` is
// its X (1e30 when none is left).
struct KinkRun {
    s0: f32,
    s1: f32,
    split: f32,
    hi: f32,
    side: u32,
    idx: u32,
    left: u32,
    up: bool,
    next: f32,
}

// The run moved to side `side` (0: [lo, split], 1: [split, hi]), no crossing counted yet.
fn run_side(run: KinkRun, side: u32) -> KinkRun {
    var r = run;
    r.side = side;
    if side == 1u {
        r.s0 = r.split;
        r.s1 = r.hi;
    } else {
        r.s1 = r.split;
    }
    r.left = 0u;
    return r;
}

// Cones: the run on side `side` of the extremum of −ŵ·axis.
fn cone_side(run: KinkRun, kb: u32, al: vec3<f32>, el: vec3<f32>, side: u32) -> KinkRun {
    var r = run_side(run, side);
    let n = u32(ies_atlas[kb]);
    let axis = kink_vec(kb, 1u);
    let off = kb + IES_KINKS_HEADER;
    if n == 0u || !(r.s1 > r.s0) {
        return r;
    }
    let w0 = al + el * r.s0;
    let w1 = al + el * r.s1;
    let c0 = -dot(w0, axis) / length(w0);
    let c1 = -dot(w1, axis) / length(w1);
    if c1 > c0 {
        let first = kink_rank(off, n, c0, true);
        r.left = max(kink_rank(off, n, c1, false), first) - first;
        r.idx = first;
        r.up = true;
    } else if c1 < c0 {
        let below = kink_rank(off, n, c0, false);
        r.left = below - min(kink_rank(off, n, c1, true), below);
        r.idx = below - 1u;
        r.up = false;
    }
    return r;
}

// The run of cones along w = al + X el over [lo, hi] (light frame), its first crossing found.
fn cone_run(kb: u32, al: vec3<f32>, el: vec3<f32>, lo: f32, hi: f32) -> KinkRun {
    var r: KinkRun;
    r.s0 = lo;
    r.hi = hi;
    let axis = kink_vec(kb, 1u);
    let xe = axis_approach(axis, al, el);
    r.split = hi;
    if xe.y > 0.0 && xe.x > lo && xe.x < hi {
        r.split = xe.x;
    }
    r = cone_side(r, kb, al, el, 0u);
    return run_next(r, kb, al, el, true, false);
}

// Planes of the pencil: the run on side `side` of the line's closest approach to the pencil's
// axis (the azimuth about it turns one way, by less than 90°, on each side).
fn plane_side(run: KinkRun, kb: u32, al: vec3<f32>, el: vec3<f32>, side: u32) -> KinkRun {
    var r = run_side(run, side);
    let np = u32(ies_atlas[kb + 4u]);
    let off = kb + IES_KINKS_HEADER + u32(ies_atlas[kb]);
    if np == 0u || !(r.s1 > r.s0) {
        return r;
    }
    let p = kink_vec(kb, 5u);
    let u = kink_vec(kb, 8u);
    let v = cross(p, u);
    let w0 = al + el * r.s0;
    let w1 = al + el * r.s1;
    let q0 = vec2<f32>(dot(w0, u), dot(w0, v));
    let q1 = vec2<f32>(dot(w1, u), dot(w1, v));
    // The azimuth of q0 mod π, and the signed turn from q0 to q1.
    var g0 = atan2_accurate(q0.y, q0.x);
    if g0 < 0.0 {
        g0 += PI;
    }
    if g0 >= PI {
        g0 -= PI;
    }
    let d = atan2_accurate(q0.x * q1.y - q0.y * q1.x, dot(q0, q1));
    let g1 = g0 + d;
    if d > 0.0 {
        let first = kink_rank(off, np, g0, true);
        if g1 < PI {
            r.left = max(kink_rank(off, np, g1, false), first) - first;
        } else {
            r.left = np - first + kink_rank(off, np, g1 - PI, false);
        }
        r.idx = first % np;
        r.up = true;
    } else if d < 0.0 {
        let below = kink_rank(off, np, g0, false);
        if g1 >= 0.0 {
            r.left = below - min(kink_rank(off, np, g1, true), below);
        } else {
            r.left = below + np - kink_rank(off, np, g1 + PI, true);
        }
        r.idx = (below + np - 1u) % np;
        r.up = false;
    }
    return r;
}

// The run of the pencil's planes along w = al + X el over [lo, hi], its first crossing found.
fn plane_run(kb: u32, al: vec3<f32>, el: vec3<f32>, lo: f32, hi: f32) -> KinkRun {
    var r: KinkRun;
    r.s0 = lo;
    r.hi = hi;
    let p = kink_vec(kb, 5u);
    let ep = el - p * dot(el, p);
    let ee = dot(ep, ep);
    r.split = hi;
    if ee > 0.0 {
        let xp = -dot(al, ep) / ee;
        if xp > lo && xp < hi {
            r.split = xp;
        }
    }
    r = plane_side(r, kb, al, el, 0u);
    return run_next(r, kb, al, el, false, false);
}

// The run's next crossing (`advance`: past the current one), moving to the second side when
// the first is done; `cones` says which family the run walks.
fn run_next(run: KinkRun, kb: u32, al: vec3<f32>, el: vec3<f32>, cones: bool, advance: bool) -> KinkRun {
    var r = run;
    if advance && r.left > 0u {
        r.left -= 1u;
        let nc = u32(ies_atlas[kb]);
        let np = u32(ies_atlas[kb + 4u]);
        if cones {
            r.idx = select(r.idx - 1u, r.idx + 1u, r.up);
        } else {
            r.idx = select((r.idx + np - 1u) % np, (r.idx + 1u) % np, r.up);
        }
    }
    if r.left == 0u && r.side == 0u {
        if cones {
            r = cone_side(r, kb, al, el, 1u);
        } else {
            r = plane_side(r, kb, al, el, 1u);
        }
    }
    r.next = 1e30;
    if r.left == 0u {
        return r;
    }
    var x = r.s0;
    if cones {
        let axis = kink_vec(kb, 1u);
        let cs = ies_atlas[kb + IES_KINKS_HEADER + r.idx];
        let roots = cone_roots_on_line(axis, cs, al, el);
        let mask = u32(roots.z);
        // The root on this side: the valid one nearest to [s0, s1].
        var best = 1e30;
        if (mask & 1u) != 0u {
            let d = max(max(r.s0 - roots.x, roots.x - r.s1), 0.0);
            if d < best {
                best = d;
                x = roots.x;
            }
        }
        if (mask & 2u) != 0u {
            let d = max(max(r.s0 - roots.y, roots.y - r.s1), 0.0);
            if d < best {
                best = d;
                x = roots.y;
            }
        }
    } else {
        let np = u32(ies_atlas[kb + 4u]);
        let p = kink_vec(kb, 5u);
        let u = kink_vec(kb, 8u);
        let mo = kb + IES_KINKS_HEADER + u32(ies_atlas[kb]) + np + 2u * r.idx;
        let m = u * ies_atlas[mo] + cross(p, u) * ies_atlas[mo + 1u];
        let den = dot(m, el);
        if den != 0.0 {
            x = -dot(m, al) / den;
        }
    }
    r.next = clamp(x, r.s0, r.s1);
    return r;
}
