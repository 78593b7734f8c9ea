// A textured latlong dome's exact irradiance through a convex spherical polygon (a portal or an
// overlap of portals seen from x, clipped at the horizon: irradiance/portals.wgsl), by rows of
// its texture. Twin of src/cpu/irradiance/latlong_polygon.rs, which carries the derivation
// (DESIGN.md §6 "what 'exact' means", §8 P2 mask mode); the row tables and cumulative moments
// are irradiance/latlong_rows.wgsl's.
//
// f32 divergences from the f64 twin, and why:
// 1. latlong_rows.wgsl's divergences 1–3 (prefix sums rounded once, the partial piece's τ, the
//    builtins' sin and cos); atan2 is atan2_accurate (lavapipe's builtin is off by ~3e-6 rad).
// 2. An arc's share is the difference of two cumulative moments (C_j at its ends, each up to
//    the row's total): f32 keeps it to ~1e-7 of the row's total, not of the arc's part.
// 3. The polygon has at most PORTAL_OVERLAP_VERTICES vertices (portals.wgsl keeps the first
//    ones of a rounded polygon that would gain more), so at most twice as many sub-arcs.
// 4. Every loop checks its condition after it ends and sets irr_cut when the device's loop
//    budget cut it short (shared/record.wgsl): the sweep runs one interval per row and per
//    piece boundary an edge crosses, each ~2 × IRR_GL_POLYGON nodes per arc of the latitude
//    circle inside the polygon, so a portal seen wide across a large texture exceeds lavapipe's
//    65,535 iterations and the host recomputes that receiver; a real GPU has no such budget.
// 5. Everything here is the optional part TEXTURE (gpu::shaders::Features).
// 6. The edges' planes come with the polygon (portals.wgsl carries them through its clips)
//    and the arcs' orientation from them; the CPU takes both from the vertices' cross products.
// GPU-only SubArc, Span, Spans, ArcEnd: the twin's structs, (Vec, bool) pair and tuples; the private arrays
//   stand in for the twin's Vecs.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import irradiance/latlong_rows.wgsl
// #import irradiance/portals.wgsl

// #if TEXTURE
struct SubArc {
    k: vec3<f32>,
    theta_a: f32,
    theta_b: f32,
    first: f32,
    dir: f32,
    count: u32,
}

struct Span {
    enter: u32,
    leave: u32,
    width: f32,
}

struct Spans {
    count: u32,
    full: bool,
}

struct ArcEnd {
    edge: u32,
    u: f32,
}

const POLYGON_ARCS: u32 = 2u * PORTAL_OVERLAP_VERTICES;

var<private> poly_edges: array<vec3<f32>, PORTAL_OVERLAP_VERTICES>;
var<private> poly_from: array<vec3<f32>, PORTAL_OVERLAP_VERTICES>;
var<private> poly_to: array<vec3<f32>, PORTAL_OVERLAP_VERTICES>;
var<private> poly_edge_count: u32;
var<private> poly_sigma: f32;
var<private> poly_arcs: array<SubArc, POLYGON_ARCS>;
var<private> poly_next: array<u32, POLYGON_ARCS>;
var<private> poly_arc_count: u32;
var<private> poly_spans: array<Span, PORTAL_OVERLAP_VERTICES>;
var<private> poly_enters: array<ArcEnd, PORTAL_OVERLAP_VERTICES>;
var<private> poly_leaves: array<ArcEnd, PORTAL_OVERLAP_VERTICES>;

// E_P = ∫_P tex(d) n·d dd over the convex polygon `poly` (dome-space vectors, in order, above
// the horizon of the dome-space unit normal n).
fn latlong_polygon(t: RowsInfo, poly: OverlapPolygon, n: vec3<f32>) -> vec3<f32> {
    let m = poly.count;
    if m < 3u {
        return vec3<f32>(0.0);
    }
    var area2 = vec3<f32>(0.0);
    var v = 0u;
    for (; v < m; v++) {
        area2 += cross(normalize(poly.p[v]), normalize(poly.p[(v + 1u) % m]));
    }
    if v < m {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    let volume = dot(area2, normalize(poly.p[0]));
    if !(abs(volume) > 1e-12) {
        return vec3<f32>(0.0);
    }
    // The edges' planes are the polygon's (see portals.wgsl's header): inward; the arc from a
    // to b runs counter-clockwise about sigma · k.
    poly_sigma = sign(volume);
    poly_edge_count = 0u;
    poly_arc_count = 0u;
    var i = 0u;
    for (; i < m; i++) {
        let a = normalize(poly.p[i]);
        let b = normalize(poly.p[(i + 1u) % m]);
        let k = poly.k[i];
        if !(length(k) > 0.0) {
            continue;
        }
        poly_edges[poly_edge_count] = k;
        poly_from[poly_edge_count] = a;
        poly_to[poly_edge_count] = b;
        poly_edge_count += 1u;
        edge_arcs(t, k, a, b);
    }
    if i < m {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    if poly_edge_count < 3u {
        return vec3<f32>(0.0);
    }
    var lo = PI;
    var hi = 0.0;
    var north = true;
    var south = true;
    var steps = 4u;
    var a = 0u;
    for (; a < poly_arc_count; a++) {
        lo = min(lo, poly_arcs[a].theta_a);
        hi = max(hi, poly_arcs[a].theta_b);
        poly_next[a] = 0u;
        steps += poly_arcs[a].count + 2u;
    }
    var e = 0u;
    for (; e < poly_edge_count; e++) {
        north = north && poly_edges[e].y >= 0.0;
        south = south && poly_edges[e].y <= 0.0;
    }
    if a < poly_arc_count || e < poly_edge_count {
        irr_cut = true;
    }
    if north {
        lo = 0.0;
    }
    if south {
        hi = PI;
    }
    let h = f32(t.height);
    let rows = select(t.height, t.height + 1u, t.bilinear);
    steps += rows;
    var r = min(u32(max(floor(lo / PI * h), 0.0)), t.height - 1u);
    if t.bilinear {
        r = min(u32(max(floor(lo / PI * h + 0.5), 0.0)), t.height);
    }
    var cur = lo;
    var sum = vec3<f32>(0.0);
    for (var step_i = 0u; step_i < steps && cur < hi && r < rows; step_i++) {
        // The nearest breakpoint: the row's end or some sub-arc's next point.
        var next = PI;
        if r + 1u < rows {
            next = PI * select(f32(r + 1u), f32(r) + 0.5, t.bilinear) / h;
        }
        var which = 0xffffffffu;
        var s = 0u;
        for (; s < poly_arc_count; s++) {
            if poly_next[s] <= poly_arcs[s].count + 1u {
                let th = arc_theta(t, poly_arcs[s], poly_next[s]);
                if th < next {
                    next = th;
                    which = s;
                }
            }
        }
        if s < poly_arc_count {
            irr_cut = true;
        }
        let end = min(max(next, cur), hi);
        if end > cur {
            let count = u32(max(ceil((end - cur) / IRR_ROWS_MAX_SPAN), 1.0));
            let len = (end - cur) / f32(count);
            var p = 0u;
            for (; p < count; p++) {
                let a = cur + f32(p) * len;
                let b = select(a + len, end, p + 1u == count);
                sum += polygon_interval(t, r, a, b, n);
            }
            if p < count {
                irr_cut = true;
            }
        }
        cur = end;
        if which == 0xffffffffu {
            r += 1u;
        } else {
            poly_next[which] += 1u;
        }
    }
    if cur < hi && r < rows {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}

// Appends edge k's sub-arcs from a to b, split at its highest or lowest point inside it.
fn edge_arcs(t: RowsInfo, k: vec3<f32>, a: vec3<f32>, b: vec3<f32>) {
    let along = poly_sigma * k;
    let top = vec3<f32>(0.0, 1.0, 0.0) - k * (k.y / dot(k, k));
    var split = false;
    var at = vec3<f32>(0.0);
    if length(top) > 1e-12 {
        let up = normalize(top);
        if dot(cross(a, up), along) > 0.0 && dot(cross(up, b), along) > 0.0 {
            split = true;
            at = up;
        }
        if dot(cross(a, -up), along) > 0.0 && dot(cross(-up, b), along) > 0.0 {
            split = true;
            at = -up;
        }
    }
    if split {
        poly_arcs[poly_arc_count] = sub_arc(t, k, a, at);
        poly_arcs[poly_arc_count + 1u] = sub_arc(t, k, at, b);
        poly_arc_count += 2u;
    } else {
        poly_arcs[poly_arc_count] = sub_arc(t, k, a, b);
        poly_arc_count += 1u;
    }
}

// The sub-arc of edge k from a to b, oriented toward growing θ, with the piece boundaries it
// crosses strictly between its ends.
fn sub_arc(t: RowsInfo, k: vec3<f32>, a: vec3<f32>, b: vec3<f32>) -> SubArc {
    var ta = atan2_accurate(length(a.xz), a.y);
    var ua = atan2_accurate(a.x, -a.z);
    var tb = atan2_accurate(length(b.xz), b.y);
    var ub = atan2_accurate(b.x, -b.z);
    if ta > tb {
        let t0 = ta;
        ta = tb;
        tb = t0;
        let u = ua;
        ua = ub;
        ub = u;
    }
    let step = 2.0 * PI / f32(t.width);
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    var du = ub - ua;
    du -= round(du / (2.0 * PI)) * 2.0 * PI;
    let xa = (ua - u0) / step;
    let xb = xa + du / step;
    if du >= 0.0 {
        let first = floor(xa) + 1.0;
        return SubArc(k, ta, tb, first, 1.0, u32(max(ceil(xb) - first, 0.0)));
    }
    let first = ceil(xa) - 1.0;
    return SubArc(k, ta, tb, first, -1.0, u32(max(first - floor(xb), 0.0)));
}

// The sub-arc's i-th breakpoint in θ order: its start, its crossings, its end.
fn arc_theta(t: RowsInfo, s: SubArc, i: u32) -> f32 {
    if i == 0u {
        return s.theta_a;
    }
    if i > s.count {
        return s.theta_b;
    }
    let step = 2.0 * PI / f32(t.width);
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    let u = u0 + (s.first + s.dir * f32(i - 1u)) * step;
    return clamp(meridian_theta(s.k, u), s.theta_a, s.theta_b);
}

// The θ where the great circle k·d = 0 crosses the meridian u.
fn meridian_theta(k: vec3<f32>, u: f32) -> f32 {
    let s = k.x * sin(u) - k.z * cos(u);
    let sg = select(-1.0, 1.0, k.y >= 0.0);
    return atan2_accurate(abs(k.y), -s * sg);
}

// ∫_lo^hi of the integrand in piece row r, the arcs' ends read at the interval's middle.
fn polygon_interval(t: RowsInfo, r: u32, lo: f32, hi: f32, n: vec3<f32>) -> vec3<f32> {
    let mid = 0.5 * (lo + hi);
    let spans = spans_at(mid);
    var sum = vec3<f32>(0.0);
    if spans.full {
        let len = hi - lo;
        var g = 0u;
        for (; g < IRR_GL_ROWS; g++) {
            sum += full_node(t, r, lo + len * IRR_GL_ROWS_X[g], n) * (IRR_GL_ROWS_W[g] * len);
        }
        if g < IRR_GL_ROWS {
            irr_cut = true;
        }
    }
    var i = 0u;
    for (; i < spans.count; i++) {
        let s = poly_spans[i];
        let ue = edge_roots(poly_edges[s.enter], mid).x;
        let ul = edge_roots(poly_edges[s.leave], mid).y;
        let shift = round((ue + s.width - ul) / (2.0 * PI)) * 2.0 * PI;
        sum += end_integral(t, r, poly_edges[s.leave], true, shift, ue, lo, hi, n)
            - end_integral(t, r, poly_edges[s.enter], false, 0.0, ue, lo, hi, n);
    }
    if i < spans.count {
        irr_cut = true;
    }
    return sum;
}

// ∫_lo^hi of one arc end's term, in σ about k's nearer branch point or in α (see the twin).
fn end_integral(t: RowsInfo, r: u32, k: vec3<f32>, leave: bool, shift: f32, u_ref: f32, lo: f32, hi: f32, n: vec3<f32>) -> vec3<f32> {
    let rho = length(k.xz);
    let top = atan2_accurate(abs(k.y), rho);
    let mid = 0.5 * (lo + hi);
    var near = min(top, lo);
    var far = PI - top;
    if mid - top > PI - top - mid {
        near = max(PI - top, hi);
        far = top;
    }
    let s0 = sqrt(abs(lo - near));
    let s1 = sqrt(abs(hi - near));
    let s_lo = min(s0, s1);
    let s_hi = max(s0, s1);
    let ratio_sigma = (sqrt(abs(far - near)) - 0.5 * (s_lo + s_hi)) / (0.5 * (s_hi - s_lo));
    let a_lo = edge_roots(k, lo).z;
    let a_hi = edge_roots(k, hi).z;
    let ratio_alpha = length(vec2<f32>(0.5 * (a_lo + a_hi) - 0.5 * PI, asinh(abs(k.y) / rho)))
        / (0.5 * abs(a_hi - a_lo));
    // The end's piece is the same at every node: the moments to its start are the interval's.
    let step = 2.0 * PI / f32(t.width);
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    let roots = edge_roots(k, mid);
    let piece = floor((select(roots.x, roots.y + shift, leave) - u0) / step);
    let rp = row_pair(t, r, mid);
    let base0 = span_base(t, rp.j0, u_ref, piece);
    var base1 = base0;
    if rp.j1 != rp.j0 {
        base1 = span_base(t, rp.j1, u_ref, piece);
    }
    var sum = vec3<f32>(0.0);
    var g = 0u;
    if ratio_sigma >= ratio_alpha || !(abs(ratio_alpha) <= 3.0e38) || abs(a_hi - a_lo) < LATLONG_MIN_ALPHA_SPAN {
        let above = lo >= near;
        let len = s1 - s0;
        for (; g < IRR_GL_POLYGON; g++) {
            let sg = s0 + len * IRR_GL_POLYGON_X[g];
            let theta = select(near - sg * sg, near + sg * sg, above);
            let v = end_node(t, r, k, leave, shift, piece, base0, base1, theta, edge_roots(k, theta).z, n);
            sum += v * (IRR_GL_POLYGON_W[g] * len * 2.0 * sg * select(-1.0, 1.0, above));
        }
    } else {
        let sg = select(-1.0, 1.0, k.y >= 0.0);
        for (; g < IRR_GL_POLYGON; g++) {
            let al = a_lo + (a_hi - a_lo) * IRR_GL_POLYGON_X[g];
            let c = cos(al);
            let theta = atan2_accurate(abs(k.y), -sg * rho * c);
            let dtheta = -k.y * rho * sin(al) / (k.y * k.y + rho * rho * c * c);
            sum += end_node(t, r, k, leave, shift, piece, base0, base1, theta, al, n) * (IRR_GL_POLYGON_W[g] * (a_hi - a_lo) * dtheta);
        }
    }
    if g < IRR_GL_POLYGON {
        irr_cut = true;
    }
    return sum;
}

// Edge k's roots on latitude θ: (ψ − α, ψ + α, α).
fn edge_roots(k: vec3<f32>, theta: f32) -> vec3<f32> {
    let a = k.y * cos(theta);
    let b = length(k.xz) * sin(theta);
    let alpha = atan2_accurate(sqrt(max(b * b - a * a, 0.0)), -a);
    let psi = atan2_accurate(k.x, -k.z);
    return vec3<f32>(psi - alpha, psi + alpha, alpha);
}

// The arcs of latitude θ inside the polygon (into poly_spans), or whether the whole circle is.
fn spans_at(theta: f32) -> Spans {
    let sin_t = sin(theta);
    let cos_t = cos(theta);
    var enters = 0u;
    var leaves = 0u;
    var e = 0u;
    for (; e < poly_edge_count; e++) {
        let k = poly_edges[e];
        if !(length(k.xz) * sin_t > abs(k.y * cos_t)) {
            continue;
        }
        let roots = edge_roots(k, theta);
        let along = poly_sigma * k;
        let pe = vec3<f32>(sin_t * sin(roots.x), cos_t, -sin_t * cos(roots.x));
        if dot(cross(poly_from[e], pe), along) >= 0.0 && dot(cross(pe, poly_to[e]), along) >= 0.0 {
            poly_enters[enters] = ArcEnd(e, roots.x);
            enters += 1u;
        }
        let pl = vec3<f32>(sin_t * sin(roots.y), cos_t, -sin_t * cos(roots.y));
        if dot(cross(poly_from[e], pl), along) >= 0.0 && dot(cross(pl, poly_to[e]), along) >= 0.0 {
            poly_leaves[leaves] = ArcEnd(e, roots.y);
            leaves += 1u;
        }
    }
    if e < poly_edge_count {
        irr_cut = true;
    }
    // Each entering end with the nearest leaving end toward +u.
    var count = 0u;
    var i = 0u;
    for (; i < enters; i++) {
        var best = Span(poly_enters[i].edge, 0u, 1e30);
        var l = 0u;
        for (; l < leaves; l++) {
            var width = poly_leaves[l].u - poly_enters[i].u;
            width -= floor(width / (2.0 * PI)) * 2.0 * PI;
            if width < best.width {
                best = Span(poly_enters[i].edge, poly_leaves[l].edge, width);
            }
        }
        if l < leaves {
            irr_cut = true;
        }
        if best.width < 1e30 {
            poly_spans[count] = best;
            count += 1u;
        }
    }
    if i < enters {
        irr_cut = true;
    }
    var full = enters == 0u;
    let p0 = vec3<f32>(0.0, cos_t, -sin_t);
    var k = 0u;
    for (; k < poly_edge_count && full; k++) {
        full = dot(poly_edges[k], p0) >= 0.0;
    }
    if full && k < poly_edge_count {
        irr_cut = true;
    }
    return Spans(count, full);
}

// One arc end's term of the integrand at θ in piece row r (at edge k's leaving root plus
// shift, or its entering root): the interval's moments from u_ref to the start of the end's
// piece (base0, base1 for rows j0, j1) plus the partial piece.
fn end_node(t: RowsInfo, r: u32, k: vec3<f32>, leave: bool, shift: f32, piece: f32, base0: RowMoments, base1: RowMoments, theta: f32, alpha: f32, n: vec3<f32>) -> vec3<f32> {
    let sin_t = sin(theta);
    let cos_t = cos(theta);
    let psi = atan2_accurate(k.x, -k.z);
    let u = select(psi - alpha, psi + alpha + shift, leave);
    let w = f32(t.width);
    let step = 2.0 * PI / w;
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    let kp = min(u32(max(piece - floor(piece / w) * w, 0.0)), t.width - 1u);
    let tau = ((u - u0) / step - piece) * step;
    let rp = row_pair(t, r, theta);
    let p0 = piece_partial(t, rp.j0, kp, tau);
    var v = n.y * cos_t * (base0.q0 + p0.q0) + sin_t * (n.x * (base0.qs + p0.qs) - n.z * (base0.qc + p0.qc));
    if rp.j1 != rp.j0 {
        let p1 = piece_partial(t, rp.j1, kp, tau);
        let v1 = n.y * cos_t * (base1.q0 + p1.q0) + sin_t * (n.x * (base1.qs + p1.qs) - n.z * (base1.qc + p1.qc));
        v += (v1 - v) * rp.fy;
    }
    return sin_t * v;
}

// The integrand at θ in piece row r where the whole latitude circle is inside the polygon.
fn full_node(t: RowsInfo, r: u32, theta: f32, n: vec3<f32>) -> vec3<f32> {
    let sin_t = sin(theta);
    let cos_t = cos(theta);
    let rp = row_pair(t, r, theta);
    let q0 = row_entry(t, rp.j0, t.width).m;
    var v = n.y * cos_t * q0.q0 + sin_t * (n.x * q0.qs - n.z * q0.qc);
    if rp.j1 != rp.j0 {
        let q1 = row_entry(t, rp.j1, t.width).m;
        v += (n.y * cos_t * q1.q0 + sin_t * (n.x * q1.qs - n.z * q1.qc) - v) * rp.fy;
    }
    return sin_t * v;
}
// ∫ R_j {1, sin u, cos u} du from u_ref to the start of piece g (turns · W + k): the partial
// piece at u_ref and the whole pieces between one by one from the texel values where there
// are at most LATLONG_SHORT_SPAN of them, else the prefix sums' difference (the twin explains
// why).
fn span_base(t: RowsInfo, j: u32, u_ref: f32, g: f32) -> RowMoments {
    let w = f32(t.width);
    let step = 2.0 * PI / w;
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    let xa = (u_ref - u0) / step;
    let ga = floor(xa);
    if abs(g - ga) > LATLONG_SHORT_SPAN {
        let c1 = cumulative(t, j, u0 + g * step);
        let c0 = cumulative(t, j, u_ref);
        return RowMoments(c1.q0 - c0.q0, c1.qs - c0.qs, c1.qc - c0.qc);
    }
    let ka = min(u32(max(ga - floor(ga / w) * w, 0.0)), t.width - 1u);
    let pa = piece_partial(t, j, ka, (xa - ga) * step);
    var out = RowMoments(-pa.q0, -pa.qs, -pa.qc);
    let sign = select(-1.0, 1.0, g >= ga);
    let count = u32(abs(g - ga));
    let lo = min(ga, g);
    var i = 0u;
    for (; i < count; i++) {
        let p = lo + f32(i);
        let k = min(u32(max(p - floor(p / w) * w, 0.0)), t.width - 1u);
        let whole = piece_partial(t, j, k, step);
        out = RowMoments(out.q0 + sign * whole.q0, out.qs + sign * whole.qs, out.qc + sign * whole.qc);
    }
    if i < count {
        irr_cut = true;
    }
    return out;
}
// #endif
