// The maps of one piece of the chart quadrature. Twin of src/cpu/irradiance/pieces.rs, which
// carries the derivations.
//
// f32: the tan map's angles are atan2_accurate(t − c, w) (the CPU: atan((t − c)/w)), and tan u
//   is sin u / cos u.
// f32: the cubic grading is written inline in map_eval (the CPU: grading).
// GPU-only PieceMap: a struct, as on the CPU.

// #import shared/math.wgsl

// The map of one piece [t0, t1]: an optional tan map t = c + w·tan u around a near pole, a
// cubic grading toward flagged ends, and (outer pieces) the cosine map.
struct PieceMap {
    c: f32,
    w: f32,
    tan_map: bool,
    u0: f32,
    u1: f32,
    grade_lo: bool,
    grade_hi: bool,
}

fn bernstein_rho(t0: f32, t1: f32, c: f32, w: f32) -> f32 {
    let half = 0.5 * (t1 - t0);
    if !(half > 0.0) {
        return 1e30;
    }
    let zr = (c - 0.5 * (t0 + t1)) / half;
    let zi = w / half;
    let ar = zr * zr - zi * zi - 1.0;
    let ai = 2.0 * zr * zi;
    let m = sqrt(sqrt(ar * ar + ai * ai));
    let ang = 0.5 * atan2_accurate(ai, ar);
    let sr = m * cos(ang);
    let si = m * sin(ang);
    let p = sqrt((zr + sr) * (zr + sr) + (zi + si) * (zi + si));
    let q = sqrt((zr - sr) * (zr - sr) + (zi - si) * (zi - si));
    return max(p, q);
}

fn piece_map(t0: f32, t1: f32, c: f32, w: f32, glo: bool, ghi: bool) -> PieceMap {
    var m: PieceMap;
    m.c = c;
    m.w = w;
    m.tan_map = w > 0.0 && w < 1e30 && bernstein_rho(t0, t1, c, w) < IRR_TAN_MAP_RHO;
    if m.tan_map {
        m.u0 = atan2_accurate(t0 - c, w);
        m.u1 = atan2_accurate(t1 - c, w);
    } else {
        m.u0 = t0;
        m.u1 = t1;
    }
    m.grade_lo = glo;
    m.grade_hi = ghi;
    return m;
}

// A tan-mapped piece is cut into equal u-spans of at most IRR_MAX_U_SPAN (grading stays on
// the outer ends).
fn span_count(m: PieceMap) -> u32 {
    if !m.tan_map {
        return 1u;
    }
    return max(u32(ceil(abs(m.u1 - m.u0) / IRR_MAX_U_SPAN)), 1u);
}

fn span(m: PieceMap, j: u32, k: u32) -> PieceMap {
    var out = m;
    out.u0 = m.u0 + (m.u1 - m.u0) * f32(j) / f32(k);
    out.u1 = m.u0 + (m.u1 - m.u0) * f32(j + 1u) / f32(k);
    out.grade_lo = m.grade_lo && j == 0u;
    out.grade_hi = m.grade_hi && j + 1u == k;
    return out;
}

// (t, dt/ds) at s ∈ [0, 1].
fn map_eval(m: PieceMap, s: f32, cosine: bool) -> vec2<f32> {
    var g = s;
    var dg = 1.0;
    if m.grade_lo && !m.grade_hi {
        g = s * s * s;
        dg = 3.0 * s * s;
    } else if m.grade_hi && !m.grade_lo {
        let r = 1.0 - s;
        g = 1.0 - r * r * r;
        dg = 3.0 * r * r;
    } else if m.grade_lo && m.grade_hi {
        let a = s * s * s;
        let b = (1.0 - s) * (1.0 - s) * (1.0 - s);
        let d = a + b;
        let da = 3.0 * s * s;
        let db = -3.0 * (1.0 - s) * (1.0 - s);
        g = a / d;
        dg = (da * d - a * (da + db)) / (d * d);
    }
    if cosine {
        dg *= 0.5 * PI * sin(PI * g);
        g = 0.5 * (1.0 - cos(PI * g));
    }
    let u = m.u0 + (m.u1 - m.u0) * g;
    let du = (m.u1 - m.u0) * dg;
    if m.tan_map {
        let tn = sin(u) / cos(u);
        return vec2<f32>(m.c + m.w * tn, m.w * (1.0 + tn * tn) * du);
    }
    return vec2<f32>(u, du);
}
