//! A latlong dome's exact irradiance through a convex spherical polygon, by rows of its
//! texture: the method of the device's kernel (`shaders/irradiance/latlong_polygon.wgsl`, whose
//! f64 twin this is), for a textured dome masked by portals (DESIGN.md §8 P2 mask mode; the
//! polygons are `irradiance/portals.rs`'s). The CPU reference integrates the same filtered
//! texture by pieces clipped at the polygon's edge planes
//! (`dome::DomeIrradiance::irradiance_over_polygon`); the tests hold this method to it, which
//! checks both, since they share only the texture.
//!
//! **The integral.** For a convex polygon P of dome directions above the receiver's horizon
//! (the portal's cone from x clipped at `n·ω ≥ 0`, mapped to dome space by the conformal frame,
//! as `latlong_rows` maps n), `E_P = ∫_P tex(d) n·d dd`. In the texture's angles (`latlong_rows`
//! module docs: `d = (sin θ sin u, cos θ, −sin θ cos u)`, `n·d = a + sin θ (p sin u + q cos u)`)
//! the latitude circle θ meets P in arcs `[u_e(θ), u_l(θ)]`, so
//! `E_P = ∫ sin θ Σ_arcs [(1 − f_y) I_{j₀} + f_y I_{j₁}] dθ` with
//! `I_j = a Q⁰_j + sin θ (p Qˢ_j + q Qᶜ_j)` and `Q_j = C_j(u_l) − C_j(u_e)`: `latlong_rows`'s
//! cumulative moments, no clamp (the polygon lies above the horizon).
//!
//! **The arcs' ends.** Each edge lies on the great circle `k·d = 0` (k the edge plane's normal,
//! oriented into P, as `dome::tables::edge_planes`), which on latitude θ is
//! `k_y cos θ + ρ_k sin θ cos(u − ψ_k) = 0` with `ρ_k = √(k_x² + k_z²)`, `ψ_k = atan2(k_x, −k_z)`:
//! P's side is the arc `|u − ψ_k| < α_k`, `α_k = atan2(√(b² − a²), −a)` with `a = k_y cos θ`,
//! `b = ρ_k sin θ`, so the edge enters P (moving toward +u) at `ψ_k − α_k` and leaves at
//! `ψ_k + α_k`. Which edges end which arcs changes only at the θ of a vertex or of an edge's
//! highest or lowest point; between them it is read once, at the interval's middle (a root on
//! the edge's arc, each entering end paired with the nearest leaving end toward +u), and
//! every node follows those ends (`α` continuous in θ). No crossings at the middle: the circle
//! is inside P (P holds a pole: its whole row) or outside it.
//!
//! **The θ integral** is Gauss–Legendre ([`crate::rules::IRR_GL_ROWS`] nodes) between every θ
//! where the integrand is not smooth: the piece rows' boundaries, the vertices' θ (an arc's end
//! changes edge: a kink), the edges' highest and lowest points (an edge touches the latitude
//! circle: the arc appears or closes with a square-root branch point), and the θ at which an
//! edge crosses a piece boundary `u_m` (the end's partial piece changes: the second derivative
//! jumps, as in `latlong_rows`). Between its highest and lowest points an edge's θ and u are
//! monotone (along a great circle `du/ds = −k_y / sin²θ`), so each such sub-arc's crossings come
//! in θ order by meridian index: the breakpoints are a merge of the rows and of each sub-arc's
//! start, crossings and end. Each interval is integrated in `t` with
//! `θ = lo + L(3t² − 2t³)`, which makes a square-root branch point at either end
//! (`θ − lo ∝ t²`, `hi − θ ∝ (1 − t)²`) smooth in t, and intervals longer than
//! [`crate::rules::IRR_ROWS_MAX_SPAN`] are cut in equal parts.

use glam::DVec3;
use std::f64::consts::PI;

use super::latlong_rows::{
    Moments, Rows, about_tangent, cumulative, piece_partial, row_entry, row_pair,
};
use crate::rules::{
    IRR_GL_POLYGON, IRR_GL_ROWS, IRR_ROWS_MAX_SPAN, LATLONG_MIN_ALPHA_SPAN, LATLONG_SHORT_SPAN,
    gauss_legendre,
};

/// A monotone piece of an edge, oriented toward growing θ, as the sweep reads it: its edge
/// plane `k`, its θ at both ends, and the piece boundaries it crosses: `count` meridians
/// `u_m = u₀ + m·h` from `m = first` in steps of `dir` (±1).
#[derive(Clone, Copy)]
pub struct SubArc {
    pub k: DVec3,
    pub theta_a: f64,
    pub theta_b: f64,
    pub first: f64,
    pub dir: f64,
    pub count: usize,
}

/// One arc of a latitude circle inside the polygon: the edge that begins it, the edge that ends
/// it, and its width at the interval's middle.
#[derive(Clone, Copy)]
pub struct Span {
    pub enter: usize,
    pub leave: usize,
    pub width: f64,
}

/// `E_P = ∫_P tex(d) n·d dd` over the convex spherical polygon with vertices `poly` (dome-space
/// vectors, in order, above the horizon of the dome-space unit normal `n`; module docs).
pub fn latlong_polygon(t: &Rows, poly: &[DVec3], n: DVec3) -> DVec3 {
    let m = poly.len();
    if m < 3 {
        return DVec3::ZERO;
    }
    let d: Vec<DVec3> = poly.iter().map(|v| v.normalize()).collect();
    // Inward edge normals (dome::tables::edge_planes' orientation); a polygon of no solid
    // angle has none.
    let area2: DVec3 = (0..m).map(|i| d[i].cross(d[(i + 1) % m])).sum();
    let volume = area2.dot(d[0]);
    if !(volume.abs() > 1e-12) {
        return DVec3::ZERO;
    }
    let sigma = volume.signum();
    let mut ends = Vec::with_capacity(m);
    let mut edges = Vec::with_capacity(m);
    let mut arcs: Vec<SubArc> = Vec::with_capacity(2 * m);
    for i in 0..m {
        let (a, b) = (d[i], d[(i + 1) % m]);
        let k = a.cross(b) * sigma;
        if !(k.length() > 1e-12) {
            // Coincident vertices: the neighbours meet there.
            continue;
        }
        edges.push(k);
        ends.push((a, b));
        edge_arcs(t, k, a, b, &mut arcs);
    }
    if edges.len() < 3 {
        return DVec3::ZERO;
    }
    // θ range: the sub-arcs' ends, or a pole inside P.
    let mut lo = arcs.iter().map(|s| s.theta_a).fold(PI, f64::min);
    let mut hi = arcs.iter().map(|s| s.theta_b).fold(0.0, f64::max);
    if edges.iter().all(|k| k.y >= 0.0) {
        lo = 0.0;
    }
    if edges.iter().all(|k| k.y <= 0.0) {
        hi = PI;
    }
    let h = t.height as f64;
    let rows = if t.bilinear { t.height + 1 } else { t.height };
    let row_end = |r: usize| -> f64 {
        if r + 1 >= rows {
            PI
        } else if t.bilinear {
            PI * (r as f64 + 0.5) / h
        } else {
            PI * (r + 1) as f64 / h
        }
    };
    // The row holding lo.
    let mut r = if t.bilinear {
        ((lo / PI * h + 0.5).floor().max(0.0) as usize).min(t.height)
    } else {
        ((lo / PI * h).floor().max(0.0) as usize).min(t.height - 1)
    };
    let mut next_of = vec![0usize; arcs.len()];
    let mut cur = lo;
    let mut sum = DVec3::ZERO;
    while cur < hi && r < rows {
        // The nearest breakpoint: the row's end or some sub-arc's next point.
        let mut next = row_end(r);
        let mut which = usize::MAX;
        for (s, arc) in arcs.iter().enumerate() {
            if next_of[s] <= arc.count + 1 {
                let th = arc_theta(t, arc, next_of[s]);
                if th < next {
                    next = th;
                    which = s;
                }
            }
        }
        let end = next.max(cur).min(hi);
        if end > cur {
            let parts = ((end - cur) / IRR_ROWS_MAX_SPAN).ceil().max(1.0);
            let len = (end - cur) / parts;
            let count = parts as usize;
            for i in 0..count {
                let a = cur + i as f64 * len;
                let b = if i + 1 == count { end } else { a + len };
                sum += polygon_interval(t, r, &edges, &ends, a, b, n);
            }
        }
        cur = end;
        if which == usize::MAX {
            r += 1;
        } else {
            next_of[which] += 1;
        }
    }
    sum
}

/// Appends edge `k`'s sub-arcs from `a` to `b` (unit vectors), split at the edge's highest or
/// lowest point where it lies inside the edge (an arc shorter than π holds at most one).
pub fn edge_arcs(t: &Rows, k: DVec3, a: DVec3, b: DVec3, out: &mut Vec<SubArc>) {
    let along = a.cross(b);
    // The highest point of the circle k·d = 0: e_y less its component along k.
    let top = DVec3::Y - k * (k.y / k.length_squared());
    let mut split = None;
    if top.length() > 1e-12 {
        for p in [top.normalize(), -top.normalize()] {
            if a.cross(p).dot(along) > 0.0 && p.cross(b).dot(along) > 0.0 {
                split = Some(p);
            }
        }
    }
    match split {
        Some(p) => {
            out.push(sub_arc(t, k, a, p));
            out.push(sub_arc(t, k, p, b));
        }
        None => out.push(sub_arc(t, k, a, b)),
    }
}

/// The sub-arc of edge `k` from `a` to `b` (θ monotone between them), oriented toward growing
/// θ, with the piece boundaries it crosses strictly between its ends.
pub fn sub_arc(t: &Rows, k: DVec3, a: DVec3, b: DVec3) -> SubArc {
    let angles = |d: DVec3| ((d.x * d.x + d.z * d.z).sqrt().atan2(d.y), d.x.atan2(-d.z));
    let (mut ta, mut ua) = angles(a);
    let (mut tb, mut ub) = angles(b);
    if ta > tb {
        (ta, tb) = (tb, ta);
        (ua, ub) = (ub, ua);
    }
    let step = 2.0 * PI / t.width as f64;
    let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
    // u moves monotonically by less than π along an arc shorter than π.
    let mut du = ub - ua;
    du -= (du / (2.0 * PI)).round() * 2.0 * PI;
    let xa = (ua - u0) / step;
    let xb = xa + du / step;
    let (first, dir, count) = if du >= 0.0 {
        let first = xa.floor() + 1.0;
        (first, 1.0, (xb.ceil() - first).max(0.0) as usize)
    } else {
        let first = xa.ceil() - 1.0;
        (first, -1.0, (first - xb.floor()).max(0.0) as usize)
    };
    SubArc {
        k,
        theta_a: ta,
        theta_b: tb,
        first,
        dir,
        count,
    }
}

/// The sub-arc's `i`-th breakpoint in θ order: its start, its `count` crossings of piece
/// boundaries, its end.
pub fn arc_theta(t: &Rows, s: &SubArc, i: usize) -> f64 {
    if i == 0 {
        s.theta_a
    } else if i > s.count {
        s.theta_b
    } else {
        let step = 2.0 * PI / t.width as f64;
        let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
        let u = u0 + (s.first + s.dir * (i - 1) as f64) * step;
        meridian_theta(s.k, u).clamp(s.theta_a, s.theta_b)
    }
}

/// The θ ∈ [0, π] where the great circle `k·d = 0` crosses the meridian u:
/// `k_y cos θ + sin θ (k_x sin u − k_z cos u) = 0`.
pub fn meridian_theta(k: DVec3, u: f64) -> f64 {
    let s = k.x * u.sin() - k.z * u.cos();
    let sg = if k.y >= 0.0 { 1.0 } else { -1.0 };
    k.y.abs().atan2(-s * sg)
}

/// `∫_lo^hi` of the integrand in piece row `r`, the arcs' ends read at the interval's middle.
/// An arc's share `C_j(u_l) − C_j(u_e)` is the difference of two terms, each a function of one
/// edge's root (`u_l` on its branch: the middle's width less a whole number of turns), so each
/// is integrated on its own in `σ = √|θ − θ_b|` about its edge's branch point nearest the
/// interval ([`end_integral`]): two edges' branch points near the interval, one on each side
/// (a polygon about a pole, its edges touching nearby latitudes), then cost nothing.
pub fn polygon_interval(
    t: &Rows,
    r: usize,
    edges: &[DVec3],
    ends: &[(DVec3, DVec3)],
    lo: f64,
    hi: f64,
    n: DVec3,
) -> DVec3 {
    let mid = 0.5 * (lo + hi);
    let (spans, full) = spans_at(edges, ends, mid);
    let (x, w) = gauss_legendre(IRR_GL_ROWS);
    let mut sum = DVec3::ZERO;
    if full {
        // The whole circle: smooth in θ.
        let len = hi - lo;
        for (g, wt) in x.iter().zip(&w) {
            sum += full_node(t, r, lo + len * g, n) * (wt * len);
        }
    }
    for s in &spans {
        let ue = edge_roots(edges[s.enter], mid).0;
        let ul = edge_roots(edges[s.leave], mid).1;
        let shift = ((ue + s.width - ul) / (2.0 * PI)).round() * 2.0 * PI;
        sum += end_integral(t, r, edges[s.leave], true, shift, ue, lo, hi, n)
            - end_integral(t, r, edges[s.enter], false, 0.0, ue, lo, hi, n);
    }
    sum
}

/// `∫_lo^hi` of one arc end's term (`C_j` at edge `k`'s leaving root plus `shift`, or at its
/// entering root). Its only singularities near the real line are k's branch points, where
/// latitude circles touch k's great circle: its highest point `θ_t = atan2(|k_y|, ρ_k)` and its
/// lowest `π − θ_t`, one on each side of the interval (neither lies inside it: there k would
/// touch the circle on its arc, a breakpoint), where `α` has a square-root branch point. Two
/// variables remove them: `σ = √|θ − θ_b|` about the nearer one (smooth there, the other one
/// left as a singularity of σ beyond the interval), or α itself, in which
/// `θ = atan2(|k_y|, −sgn(k_y) ρ_k cos α)` is smooth but for the complex poles
/// `α = π/2 ± i asinh(|k_y|/ρ_k)` (a great circle passing near a pole: θ races through it).
/// The rule is Gauss–Legendre in whichever variable puts the remaining singularity farther from
/// the interval, relative to its half-length (the Bernstein ellipse through it is larger), but
/// never in α over less than [`LATLONG_MIN_ALPHA_SPAN`]: along an edge near a meridian α barely moves
/// (`α ≈ π/2`), and f32 cannot place nodes a few ulps apart.
#[allow(clippy::too_many_arguments)]
pub fn end_integral(
    t: &Rows,
    r: usize,
    k: DVec3,
    leave: bool,
    shift: f64,
    u_ref: f64,
    lo: f64,
    hi: f64,
    n: DVec3,
) -> DVec3 {
    let rho = (k.x * k.x + k.z * k.z).sqrt();
    let top = k.y.abs().atan2(rho);
    let mid = 0.5 * (lo + hi);
    // σ about the nearer branch point: the other one's σ, against the interval's.
    let (near, far) = if mid - top <= PI - top - mid {
        (top.min(lo), PI - top)
    } else {
        ((PI - top).max(hi), top)
    };
    let (s0, s1) = ((lo - near).abs().sqrt(), (hi - near).abs().sqrt());
    let (s_lo, s_hi) = (s0.min(s1), s0.max(s1));
    let ratio_sigma = ((far - near).abs().sqrt() - 0.5 * (s_lo + s_hi)) / (0.5 * (s_hi - s_lo));
    // In α: the poles' distance from the interval's middle, against its half-length.
    let alpha = |theta: f64| edge_roots(k, theta).2;
    let (a_lo, a_hi) = (alpha(lo), alpha(hi));
    let ratio_alpha = (0.5 * (a_lo + a_hi) - 0.5 * PI).hypot((k.y.abs() / rho).asinh())
        / (0.5 * (a_hi - a_lo).abs());
    // The end's piece is the same at every node (its crossings of piece boundaries are
    // breakpoints), so the moments from u_ref to the piece's start are the interval's
    // ([`span_base`]) and each node adds its partial piece.
    let step = 2.0 * PI / t.width as f64;
    let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
    let (ue, ul, _) = edge_roots(k, mid);
    let piece = ((if leave { ul + shift } else { ue } - u0) / step).floor();
    let (j0, j1, _) = row_pair(t, r, mid);
    let bases = [
        span_base(t, j0, u_ref, piece),
        span_base(t, j1, u_ref, piece),
    ];
    let (x, w) = gauss_legendre(IRR_GL_POLYGON);
    if ratio_sigma >= ratio_alpha
        || !ratio_alpha.is_finite()
        || (a_hi - a_lo).abs() < LATLONG_MIN_ALPHA_SPAN
    {
        about_tangent(lo, hi, near, (&x, &w), |theta| {
            end_node(t, r, k, leave, shift, piece, &bases, theta, alpha(theta), n)
        })
    } else {
        // θ(α) and dθ/dα = −k_y ρ sin α / (k_y² + ρ² cos² α), signed: α runs either way.
        let sg = if k.y >= 0.0 { 1.0 } else { -1.0 };
        let mut sum = DVec3::ZERO;
        for (g, wt) in x.iter().zip(&w) {
            let al = a_lo + (a_hi - a_lo) * g;
            let (sin_a, cos_a) = al.sin_cos();
            let theta = k.y.abs().atan2(-sg * rho * cos_a);
            let dtheta = -k.y * rho * sin_a / (k.y * k.y + rho * rho * cos_a * cos_a);
            sum += end_node(t, r, k, leave, shift, piece, &bases, theta, al, n)
                * (wt * (a_hi - a_lo) * dtheta);
        }
        sum
    }
}

/// Edge `k`'s entering and leaving roots `(ψ − α, ψ + α)` on latitude θ, and α (clamped to
/// [0, π] where the circle misses the edge's great circle).
pub fn edge_roots(k: DVec3, theta: f64) -> (f64, f64, f64) {
    let (sin_t, cos_t) = theta.sin_cos();
    let a = k.y * cos_t;
    let b = (k.x * k.x + k.z * k.z).sqrt() * sin_t;
    let alpha = (b * b - a * a).max(0.0).sqrt().atan2(-a);
    let psi = k.x.atan2(-k.z);
    (psi - alpha, psi + alpha, alpha)
}

/// The arcs of latitude θ inside the polygon: each entering end (a root on its edge's arc)
/// paired with the nearest leaving end toward +u; with none, whether the whole circle is inside.
pub fn spans_at(edges: &[DVec3], ends: &[(DVec3, DVec3)], theta: f64) -> (Vec<Span>, bool) {
    let (sin_t, cos_t) = theta.sin_cos();
    let at = |u: f64| DVec3::new(sin_t * u.sin(), cos_t, -sin_t * u.cos());
    let on_edge = |i: usize, u: f64| {
        let (a, b) = ends[i];
        let along = a.cross(b);
        let p = at(u);
        a.cross(p).dot(along) >= 0.0 && p.cross(b).dot(along) >= 0.0
    };
    let mut enters = Vec::new();
    let mut leaves = Vec::new();
    for (i, &k) in edges.iter().enumerate() {
        let b = (k.x * k.x + k.z * k.z).sqrt() * sin_t;
        if !(b > (k.y * cos_t).abs()) {
            continue;
        }
        let (ue, ul, _) = edge_roots(k, theta);
        if on_edge(i, ue) {
            enters.push((i, ue));
        }
        if on_edge(i, ul) {
            leaves.push((i, ul));
        }
    }
    let mut spans = Vec::new();
    for &(e, ue) in &enters {
        let mut best: Option<Span> = None;
        for &(l, ul) in &leaves {
            let width = (ul - ue).rem_euclid(2.0 * PI);
            if best.is_none_or(|b| width < b.width) {
                best = Some(Span {
                    enter: e,
                    leave: l,
                    width,
                });
            }
        }
        spans.extend(best);
    }
    let full = enters.is_empty() && edges.iter().all(|k| k.dot(at(0.0)) >= 0.0);
    (spans, full)
}

/// One arc end's term of the integrand at θ in piece row `r`:
/// `sin θ [(1 − f_y) I_{j₀} + f_y I_{j₁}]` with `I_j = a D⁰_j(u) + sin θ (p Dˢ_j(u) + q Dᶜ_j(u))`,
/// `D_j(u) = C_j(u) − C_j(u_ref)`: the interval's `bases` (to the start of the end's piece
/// `g`, rows j₀ and j₁) plus the partial piece to u (the arc's two ends share `u_ref`, so
/// their difference is the arc's), at edge `k`'s leaving root `ψ + α` plus `shift`, or at its
/// entering root `ψ − α`.
#[allow(clippy::too_many_arguments)]
pub fn end_node(
    t: &Rows,
    r: usize,
    k: DVec3,
    leave: bool,
    shift: f64,
    g: f64,
    bases: &[Moments; 2],
    theta: f64,
    alpha: f64,
    n: DVec3,
) -> DVec3 {
    let (sin_t, cos_t) = theta.sin_cos();
    let psi = k.x.atan2(-k.z);
    let u = if leave {
        psi + alpha + shift
    } else {
        psi - alpha
    };
    let w = t.width as f64;
    let step = 2.0 * PI / w;
    let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
    let piece = (g - (g / w).floor() * w) as usize;
    let tau = ((u - u0) / step - g) * step;
    let (j0, j1, fy) = row_pair(t, r, theta);
    let row = |j: usize, base: &Moments| -> DVec3 {
        let part = piece_partial(t, j, piece, tau);
        let c: Moments = std::array::from_fn(|i| base[i] + part[i]);
        n.y * cos_t * c[0] + sin_t * (n.x * c[1] - n.z * c[2])
    };
    let mut v = row(j0, &bases[0]);
    if j1 != j0 {
        v += (row(j1, &bases[1]) - v) * fy;
    }
    sin_t * v
}

/// The integrand at θ in piece row `r` where the whole latitude circle is inside the polygon:
/// the rows' totals.
pub fn full_node(t: &Rows, r: usize, theta: f64, n: DVec3) -> DVec3 {
    let (sin_t, cos_t) = theta.sin_cos();
    let (j0, j1, fy) = row_pair(t, r, theta);
    let row = |j: usize| -> DVec3 {
        let q: Moments = row_entry(t, j, t.width).0;
        n.y * cos_t * q[0] + sin_t * (n.x * q[1] - n.z * q[2])
    };
    let mut v = row(j0);
    if j1 != j0 {
        v += (row(j1) - v) * fy;
    }
    sin_t * v
}

/// `∫_{u_ref}^{u₀ + g·h} R_j {1, sin u, cos u} du`: to the start of piece `g` (a global index,
/// turns · W + k): the partial piece at u_ref in closed form and the whole pieces between
/// summed one by one from the texel values where there are at most [`LATLONG_SHORT_SPAN`],
/// else the prefix sums' difference.
pub fn span_base(t: &Rows, j: usize, u_ref: f64, g: f64) -> Moments {
    let w = t.width as f64;
    let step = 2.0 * PI / w;
    let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
    let xa = (u_ref - u0) / step;
    let ga = xa.floor();
    if (g - ga).abs() > LATLONG_SHORT_SPAN {
        let (c1, c0) = (cumulative(t, j, u0 + g * step), cumulative(t, j, u_ref));
        return std::array::from_fn(|i| c1[i] - c0[i]);
    }
    let piece = |g: f64| (g - (g / w).floor() * w) as usize;
    let pa = piece_partial(t, j, piece(ga), (xa - ga) * step);
    let mut out: Moments = std::array::from_fn(|i| -pa[i]);
    let (lo, hi, sign) = if g >= ga { (ga, g, 1.0) } else { (g, ga, -1.0) };
    let mut p = lo;
    while p < hi {
        let whole = piece_partial(t, j, piece(p), step);
        for i in 0..3 {
            out[i] += sign * whole[i];
        }
        p += 1.0;
    }
    out
}

#[cfg(test)]
mod tests;
