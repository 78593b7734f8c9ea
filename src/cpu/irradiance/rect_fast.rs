//! Fast irradiance of a textured rect at a loose tolerance (issue 24 item 4), f64, CPU only.
//!
//! The reference (`rect_texture`, DESIGN.md §6 "RectLight texture" and "Dome and texture
//! irradiance: what 'exact' means") splits the chart quadrature at every texel line: ~2M smooth
//! pieces for a 2048 × 1024 texture, ~50 s per receiver. This path computes the same integral,
//! `E = L ∫∫ t(X, Y) · K(X, Y) dX dY` with `K = S(−ŵ)·max(0, n·w)·J/|w|⁴` (everything but the
//! texture t, see `cpu::irradiance`), to a relative tolerance `rel` ≥ [`MIN_TOLERANCE`]:
//!
//! - Linearity in the texture: on a chart rectangle R with the 3 × 3 Gauss–Legendre points
//!   `x_ab` of R and the tensor Lagrange basis `ℓ_ab` on them, `∫_R t·K ≈ ∫_R t·I(K) =
//!   Σ_ab K(x_ab)·W_ab` with the texture's *Lagrange moments* `W_ab = ∫_R t·ℓ_ab`. They are exact
//!   integrals of the interpolant actually used (DESIGN.md "what 'exact' means"): t is bilinear
//!   (or constant) on each texel piece (`prepare::texture::axis_pieces`) and ℓ_ab biquadratic,
//!   so the 3-point Gauss–Legendre rule of each piece (exact to degree 5 per axis) integrates
//!   `t·ℓ_ab` exactly. A parent's moments follow exactly from its children's, because the
//!   parent's ℓ restricted to a child is the child's biquadratic interpolant of it:
//!   `W^P_ab = Σ_children Σ_cd W^C_cd ℓ^P_ab(x^C_cd)`. The moments of a quadtree over the texel
//!   pieces (blocks of ≤ [`tree::LEAF_PIECES`] pieces at its leaves) are built once per texture
//!   ([`tree`], lazily, in the texture's `irradiance` slot); below a leaf they are computed on
//!   the fly from the pieces, and below one piece from the piece's Gauss points (a sub-rect of
//!   a piece: `W_ab = Σ gauss weight · t · ℓ_ab`).
//! - Per receiver, globally adaptive subdivision of that tree (QUADPACK `qag` in 2-D, Piessens
//!   et al. 1983, with the moment rule of a cell as the basic rule): every active cell carries
//!   the sum of its children's rules as its value and `|Σ children − own rule|` as its error
//!   estimate; the cell with the largest error is replaced by its children until the summed
//!   error is below `rel/16` of the summed value in every channel. Cells continue below texel
//!   pieces (quadrants of a piece), so the near-field peak is resolved by subdivision.
//! - Where K is not smooth the moment rule is not used: a cell the receiver's horizon crosses
//!   (K's kink `max(0, n·w)`, a line of the chart) or that a shaping kink may cross (cone edge,
//!   smoothstep start, focus plane: `Prepared::profile`) is integrated by
//!   [`Kernel::clipped`], a 5 × 5 Gauss rule on the part in front of the horizon whose lines
//!   are split at the shaping's kinks (the roots `line::line_integral` splits at), with t
//!   sampled; no rule point then lies where K = 0, so no lit sliver goes unseen along a line.
//!   Across lines the rule is split where a kink's inner roots change (a kink cone crossing
//!   the cell's sides or the horizon line, or tangent to the pencil of lines; the focus plane
//!   crossing them), as `critical::critical_ys` splits the reference's outer integral, so
//!   that the outer integrand is smooth on each part and no lit cap of the cone lies between
//!   two lines unseen. Subdivision goes on below pieces until the estimates meet the tolerance.
//! - The clipped rule samples t, so over several texel pieces it samples across t's kinks
//!   (bilinear) or jumps (nearest): neither it nor its children's rules converge there, and
//!   the estimate can read 0 while both miss a texel (a cell whose lit part lies in one child
//!   gets that child's very rule points). This was the bias that kept shaped rects on the
//!   exact path: at 256 × 128, nearest, sheared, grazing receiver (the lit part a few texels
//!   between the horizon and the cone), 1.0e-4 and 3.0e-4 error at 1e-4 and at 1e-3, 1.1e-4
//!   and 4.6e-4 at 1e-2 (not the tolerance's); with the texture lit in one texel of it only, 33 % of that texel's light found,
//!   the same at rel 1e-4, 1e-6, 1e-8. A clipped cell over more than one piece that a
//!   shaping kink may cross is therefore split untrusted down to single pieces (where t is a polynomial and
//!   the rule converges): that case then < 5e-8, every shaped 256 × 128 one ≤ 5e-7 at 1e-4. The outer splits above were
//!   needed too: without them (in a variant that split only the kink-crossed cells) 4
//!   one-texel textures of 16 × 8 of shaped rects were missed entirely (a lit cap between
//!   two lines).
//! - A cell over several pieces that the horizon cuts, or that only a soft cone's kink cones
//!   (softness > 0) may cross, is not sampled at all ([`Kernel::bracket`]): the horizon's
//!   factor `max(0, n·w)` is bracketed on it by two parallel planes of the chart, and the cone
//!   factor by its range over the cell's directions (of the square of the cell's angular size
//!   astride a kink: the smoothstep's slope is 0 at both ends), so its rule is the moment rule
//!   of a smooth kernel (every texel counted through the exact moments) and its error has an
//!   a-priori bound (for the horizon alone `(D/2)·max|S·J/|w|⁴|·∫|t|`, D the band's height),
//!   which shrinks like the cell's size cubed (to the fourth for a kink cone); the adaptive
//!   split refines such cells only as far as the tolerance needs, and their bounds are held
//!   to half the tolerance ([`BOUND_SHARE`]; the estimates to rel/16). Hard cones' edges, the
//!   focus plane and a singular axis still split a crossed cell down to single pieces. History: while such cells of unshaped rects took the sampled clipped rule
//!   trusted on its estimate, one-texel 16 × 8 textures (both filters, both transforms, the 9
//!   receivers of the tests) were off by 1.2e-4 to 100 % at 1e-4 (random textures did not
//!   show it); the bound of the whole contribution instead ([`Kernel::cut_bound`], still the
//!   fallback where smaller) made visibleRect's 128² map take 28 s; the bracket takes it to
//!   0.63 s and shaped rects' focus-only receivers from 20–39 ms to 1–4 ms; bracketing soft
//!   cones' kinks took their receivers from up to 364 ms to up to ~60 ms (BENCHMARKS.md).
//! - Guard against a peak no rule point sees: a cell is split without being trusted while its
//!   world half-diagonal R exceeds half the lower bound `|w_c| − R` of its distance from x
//!   (FMM's well-separated criterion), unless the receiver's horizon hides all of it.
//!
//! Threshold ([`MIN_TOLERANCE`], `Rule::texture_tolerance`): `Adaptive::for_tolerance(rel)`
//! with rel ≥ 1e-4 (the CLI's and Python's default) takes this path; tighter tolerances and the
//! reference (`Adaptive::REFERENCE`, 1e-9) keep the exact split path unchanged. At 1e-5 the
//! estimates were measured to miss by 2–4× (1.9e-5 unshaped nearest, 3.6e-5 shaped, the latter
//! before the shaped fix above; not measured since).
//!
//! What this does not prove: the error estimates of smooth cells are a-posteriori (as the
//! reference's Gauss–Kronrod estimates are), not a-priori bounds, and the bracket bound
//! trusts the moment rule of its smooth kernel; the tests measure the result against
//! the 1e-9 reference on random textures, unshaped and shaped (cones with softness 0 to 0.4,
//! focus with tint, focus alone; sizes to 64 × 32 in the default run, 256 × 128 with
//! `--ignored`), and on one-texel textures of unshaped and shaped rects (8 × 4; 16 × 8 with `--ignored`),
//! near, grazing and far receivers.
//! IES profiles are left to the exact path ([`applies`]: never tried here).

use std::collections::BinaryHeap;
use std::f64::consts::PI;

use glam::DVec3;

use super::chart::Chart;
use crate::cpu::roots::{axis_approach, cone_roots_on_line};
use crate::cpu::shaping::{cone_factor, focus_factor, shaping};
use crate::prepare::Kink;
use crate::prepare::Prepared;
use tree::{Cell, GX, Moments, Rect, Tree};

/// The tightest tolerance the fast path takes: below it (`Adaptive::for_tolerance` of less
/// than 1e-4, and the reference) the exact split path runs. At 1e-5 the error estimates were
/// measured to miss by 2–4× (module docs), at 1e-4 to 1e-2 the tests hold every receiver.
pub const MIN_TOLERANCE: f64 = 1e-4;

/// The share of the tolerance the summed error estimates are held to. The estimates are not
/// bounds, so the sum stops well inside rel (the shaped bias once measured did not change from
/// rel/8 to rel/16: it was not the stop's, see the module docs).
const ESTIMATE_SHARE: f64 = 1.0 / 16.0;

/// The share of the tolerance the summed a-priori bounds (horizon-cut cells of unshaped lights,
/// [`Kernel::bracket`]) are held to: they hold whatever the texture, so half of it.
const BOUND_SHARE: f64 = 0.5;

/// At most this many cells are split per receiver (then the current sum is returned).
const MAX_SPLITS: usize = 2_000_000;

/// 5-point Gauss–Legendre on [−1, 1] (A&S 25.4.29).
const G5X: [f64; 5] = [
    -0.906_179_845_938_664,
    -0.538_469_310_105_683,
    0.0,
    0.538_469_310_105_683,
    0.906_179_845_938_664,
];
const G5W: [f64; 5] = [
    0.236_926_885_056_189_1,
    0.478_628_670_499_366_5,
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
];

/// Whether the fast path takes `p`: a textured rect, unshaped or shaped by ShapingAPI's cone,
/// softness, focus and focusTint (their kinks handled as the module docs say; the shaped bias
/// once measured here was the clipped rule sampling the texture across texel pieces). With an
/// IES profile the exact split path runs: its kinks (`prepare::ies_kinks`) are not listed by
/// `Prepared::profile`, which [`Kernel::kinked`] and the clipped rule read, and it was never
/// measured here.
pub fn applies(p: &Prepared) -> bool {
    p.rect_texture().is_some() && p.ies.is_none()
}

/// The rule of a cell (see [`Kernel::rule_kind`]).
#[derive(Clone, Copy, PartialEq)]
enum RuleKind {
    Zero,
    Moments,
    Clipped,
}

/// The smooth kernel `K = S(−ŵ)·max(0, n·w)·J/|w|⁴` of the chart integral (module docs).
struct Kernel<'a> {
    p: &'a Prepared,
    chart: &'a Chart,
    n: DVec3,
    shaped: bool,
    /// A bound of the shaping factor's size, per channel (`ShapingConsts::factor_bound`).
    s_max: DVec3,
    /// The cone factor is C¹ across its kink cones: softness > 0 (`1 − smoothstep` has zero
    /// slope at both ends), so near them it differs from its value there by the square of
    /// the distance in angle ([`Kernel::bracket`]).
    soft_cone: bool,
}

/// How the shaping's kinks meet a cell ([`Kernel::kinks`]).
#[derive(Clone, Copy, PartialEq, Debug)]
enum Kinks {
    None,
    /// Only kink cones of a soft cone (the smoothstep's start or the cone's edge).
    SoftCone,
    /// A hard cone's edge, the focus plane, or the axis where the factor is singular.
    Other,
}

impl<'a> Kernel<'a> {
    fn new(p: &'a Prepared, chart: &'a Chart, n: DVec3) -> Self {
        let s = p.shaping.as_ref();
        Kernel {
            p,
            chart,
            n,
            shaped: s.is_some(),
            s_max: s.map_or(DVec3::ONE, |s| s.factor_bound()),
            soft_cone: s.is_some_and(|s| s.start < s.cone),
        }
    }
}

impl Kernel<'_> {
    #[inline]
    fn eval(&self, x: f64, y: f64) -> DVec3 {
        let w = self.chart.w0 + self.chart.e1 * x + self.chart.e2 * y;
        let nw = self.n.dot(w);
        if !(nw > 0.0) {
            return DVec3::ZERO;
        }
        let l2 = w.length_squared();
        let v = nw * self.chart.jac / (l2 * l2);
        if self.shaped {
            shaping(self.p, -w / l2.sqrt()) * v
        } else {
            DVec3::splat(v)
        }
    }

    /// The horizon's affine function `h = n·w` on the chart: (c, a, b) with h = c + aX + bY.
    fn horizon(&self) -> (f64, f64, f64) {
        (
            self.n.dot(self.chart.w0),
            self.n.dot(self.chart.e1),
            self.n.dot(self.chart.e2),
        )
    }

    /// Which rule a cell takes: none behind the horizon, the moment rule where neither the
    /// horizon nor a shaping kink may cross it (K smooth on it), else [`Kernel::clipped`].
    fn rule_kind(&self, r: Rect) -> RuleKind {
        let (c, a, b) = self.horizon();
        let hs = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)]
            .map(|(x, y)| c + a * x + b * y);
        if hs.iter().all(|&h| !(h > 0.0)) {
            RuleKind::Zero
        } else if hs.iter().all(|&h| h > 0.0) && !self.kinked(r) {
            RuleKind::Moments
        } else {
            RuleKind::Clipped
        }
    }

    /// The cell's rule (see [`Kernel::rule_kind`]) and a bound of its error where that is known
    /// a priori (the bracket rule's), else 0: a cell over several texel pieces that the horizon
    /// cuts or a soft cone's kink cones may cross, and no other kink, takes
    /// [`Kernel::bracket`], other cut or kinked cells [`Kernel::clipped`].
    fn cell_rule(&self, tree: &Tree, cell: &Cell) -> (DVec3, DVec3) {
        let r = tree.rect(cell);
        match self.rule_kind(r) {
            RuleKind::Zero => (DVec3::ZERO, DVec3::ZERO),
            RuleKind::Moments => (self.rule(r, &tree.moments(cell)), DVec3::ZERO),
            RuleKind::Clipped if tree.pieces(cell) > 1 && self.kinks(r) != Kinks::Other => {
                let w = tree.moments(cell);
                self.bracket(r, &w, tree.abs_integral(cell, r, &w))
            }
            RuleKind::Clipped => (self.clipped(tree, r), DVec3::ZERO),
        }
    }

    /// The bracket rule of a cell `r` that the horizon cuts or a soft cone's kink cones may
    /// cross (no other kink), with the texture's exact moments `w` and `tabs ≥ ∫|t|` over it:
    /// its value and a bound of its error. There `K = c·max(0, h)·g`:
    /// - `h = n·w` is affine on the chart (its range [h₋, h₊] on the cell is that of the
    ///   corners). `max(0, h)` is convex, so on [h₋, h₊] it lies between the line `λh`
    ///   (λ = h₊/(h₊ − h₋), h₋ taken ≤ 0) and the parallel chord through the ends `λ(h − h₋)`,
    ///   a band of height `D = λ·(−h₋) ≤ (h₊ − h₋)/4` (0 when the horizon does not cut): with
    ///   `q = λh + D/2`, `|max(0, h) − q| ≤ D/2` on the cell, and `|q| ≤ λh₊ + D/2`.
    /// - `c` is the cone factor `1 − smoothstep(θ; start, cone)` where a soft cone's kink
    ///   cones cross the cell (else 1, and the whole shaping factor is in g). It does not
    ///   increase with θ, so over the cell's θ range [θc − α, θc + α] (`Kernel::angles`) it lies
    ///   in [c₋, c₊] = [c(θc + α), c(θc − α)]; a cell astride a kink has a range of the square
    ///   of its angular size (the smoothstep's slope is 0 at both ends).
    /// - `g = F·J/|w|⁴` is smooth, F the rest of the shaping factor (focus, or all of it),
    ///   `|F| ≤ s_max`, `J/|w|⁴ ≤ J/(|w_c| − R)⁴`.
    ///
    /// The rule is `c_m·∫ t·q·g` with `c_m = (c₋ + c₊)/2`, the moment rule of a smooth kernel
    /// (no sampling of t: no texel goes unseen), and
    /// `|c·max(0, h) − c_m·q| ≤ c₊·D/2 + |q|·(c₊ − c₋)/2`, so its error is at most that times
    /// `max|g|·∫|t|`. For the horizon alone the bound shrinks like the cell's size cubed, as
    /// [`Kernel::cut_bound`] (the whole contribution's) does, but with `D/2 ≤ h₊/4` against
    /// `h₊` and `∫|t|` against `t_max · area`; for a kink cone like its size to the fourth.
    fn bracket(&self, r: Rect, w: &Moments, tabs: DVec3) -> (DVec3, DVec3) {
        let (c0, a, b) = self.horizon();
        let hs = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)]
            .map(|(x, y)| c0 + a * x + b * y);
        let hmax = hs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let hmin = hs.iter().copied().fold(f64::INFINITY, f64::min).min(0.0);
        if !(hmax > 0.0) {
            return (DVec3::ZERO, DVec3::ZERO);
        }
        let lambda = hmax / (hmax - hmin);
        let d = lambda * -hmin;
        // The cone factor's range where a soft cone's kinks cross (`Kernel::kinks`).
        let coned = self.kinks(r) == Kinks::SoftCone;
        let (c_lo, c_hi) = match (coned, self.p.shaping.as_ref(), self.angles(r)) {
            (true, Some(s), Some((theta, alpha))) => (
                cone_factor((theta + alpha).min(PI), s.cone, s.start),
                cone_factor((theta - alpha).max(0.0), s.cone, s.start),
            ),
            (true, ..) => return (DVec3::ZERO, DVec3::INFINITY),
            (false, ..) => (1.0, 1.0),
        };
        let c_mid = 0.5 * (c_lo + c_hi);
        let ch = self.chart;
        let (cx, cy, hx, hy) = r.centre();
        let mut value = DVec3::ZERO;
        for j in 0..3 {
            let y = cy + hy * GX[j];
            for i in 0..3 {
                let wab = w[3 * j + i];
                if wab == DVec3::ZERO {
                    continue;
                }
                let x = cx + hx * GX[i];
                let wv = ch.w0 + ch.e1 * x + ch.e2 * y;
                let l2 = wv.length_squared();
                let q = lambda * (c0 + a * x + b * y) + 0.5 * d;
                let g = q * ch.jac / (l2 * l2);
                let e = -wv / l2.sqrt();
                value += match self.p.shaping.as_ref() {
                    None => wab * g,
                    Some(s) if coned => {
                        wab * focus_factor(s.focus, s.focus_tint, e.dot(self.p.axis)) * g
                    }
                    Some(_) => wab * shaping(self.p, e) * g,
                };
            }
        }
        let wc = ch.w0 + ch.e1 * cx + ch.e2 * cy;
        let dmin = wc.length() - ((ch.e1 * hx).length() + (ch.e2 * hy).length());
        let band = c_hi * 0.5 * d + (lambda * hmax + 0.5 * d) * 0.5 * (c_hi - c_lo);
        let bound = if dmin > 0.0 {
            tabs * self.s_max * (band * ch.jac / (dmin * dmin * dmin * dmin))
        } else {
            DVec3::INFINITY
        };
        (value * c_mid, bound)
    }

    /// Whether a kink of the shaping factor (`Prepared::profile`: the cone edge, the
    /// smoothstep's start, the focus plane) may cross the cell ([`Kernel::kinks`]).
    fn kinked(&self, r: Rect) -> bool {
        self.kinks(r) != Kinks::None
    }

    /// The cell's directions: the centre direction's angle θ from the axis and a bound α of
    /// the angle between it and any direction of the cell (`asin(R/|w_c|)`); None when the
    /// cell may reach x.
    fn angles(&self, r: Rect) -> Option<(f64, f64)> {
        let (cx, cy, hx, hy) = r.centre();
        let c = self.chart;
        let wc = c.w0 + c.e1 * cx + c.e2 * cy;
        let (d, rad) = (wc.length(), (c.e1 * hx).length() + (c.e2 * hy).length());
        (rad < d).then(|| {
            (
                (-wc / d).dot(self.p.axis).clamp(-1.0, 1.0).acos(),
                (rad / d).asin() + 1e-9,
            )
        })
    }

    /// Which kinks of the shaping factor may cross the cell: a cone whose angle lies within α
    /// of the centre direction's, or a plane with corners on both sides. Only the kink cones
    /// of a soft cone ([`Kinks::SoftCone`]) can be bracketed.
    fn kinks(&self, r: Rect) -> Kinks {
        if !self.shaped {
            return Kinks::None;
        }
        let c = self.chart;
        let dirs = self.angles(r);
        let corners = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)];
        let mut out = Kinks::None;
        for k in &self.p.profile.kinks {
            let crosses = match *k {
                Kink::Cone { cos } => match dirs {
                    Some((theta, alpha)) => (cos.clamp(-1.0, 1.0).acos() - theta).abs() <= alpha,
                    None => true,
                },
                Kink::Plane { m, .. } => {
                    let sg = corners.map(|(x, y)| m.dot(c.w0 + c.e1 * x + c.e2 * y));
                    sg.iter().any(|&v| v > 0.0) && sg.iter().any(|&v| !(v > 0.0))
                }
            };
            if crosses {
                if matches!(k, Kink::Cone { .. }) && self.soft_cone && dirs.is_some() {
                    out = Kinks::SoftCone;
                } else {
                    return Kinks::Other;
                }
            }
        }
        if self.p.profile.axis_singular && dirs.is_none_or(|(t, a)| t <= a) {
            return Kinks::Other;
        }
        out
    }

    /// `∫ t·K` over the part of `r` in front of the horizon (a line h = 0 of the chart, where K
    /// has a kink), each line of the inner rule also split where the shaping's kinks meet it
    /// (the roots of `line::line_integral`): that part is bounded by the line and the sides, so with the coordinate the
    /// line is a graph over (the one along which |∂h| is smaller) split where the line leaves
    /// through a side, it is a union of trapezoids mapped onto squares, each integrated by the
    /// 5 × 5 Gauss–Legendre rule of `t·K` (K smooth there, t sampled). No rule point lies
    /// behind the horizon, so no sliver in front of it goes unseen.
    fn clipped(&self, tree: &Tree, r: Rect) -> DVec3 {
        let (c, a, b) = self.horizon();
        // Work in (u, v) with v the graph coordinate: v_line(u) = −(c + p·u)/q.
        let swap = b.abs() < a.abs();
        let (p, q, u0, u1, v0, v1) = if swap {
            (b, a, r.y0, r.y1, r.x0, r.x1)
        } else {
            (a, b, r.x0, r.x1, r.y0, r.y1)
        };
        let vl = |u: f64| -(c + p * u) / q;
        let mut cuts = vec![u0, u1];
        if q == 0.0 {
            // h does not depend on v: the line is u = −c/p (or absent).
            if p != 0.0 && -c / p > u0 && -c / p < u1 {
                cuts.push(-c / p);
            }
        } else if p != 0.0 {
            for v in [v0, v1] {
                let u = -(c + q * v) / p;
                if u > u0 && u < u1 {
                    cuts.push(u);
                }
            }
        }
        if self.shaped {
            self.kink_cuts(&mut cuts, swap, (c, p, q), (u0, u1, v0, v1));
        }
        cuts.sort_by(f64::total_cmp);
        let lim = |u: f64| {
            if q == 0.0 {
                return if c + p * u > 0.0 { (v0, v1) } else { (v0, v0) };
            }
            let l = vl(u).clamp(v0, v1);
            if q > 0.0 { (l, v1) } else { (v0, l) }
        };
        let mut sum = DVec3::ZERO;
        for w in cuts.windows(2) {
            let (ua, ub) = (w[0], w[1]);
            if !(ub > ua) {
                continue;
            }
            let (um, uh) = (0.5 * (ua + ub), 0.5 * (ub - ua));
            let (lo, hi) = lim(um);
            if !(hi > lo) {
                continue;
            }
            for (gu, wu) in G5X.iter().zip(&G5W) {
                let u = um + uh * gu;
                let (lo, hi) = lim(u);
                if !(hi > lo) {
                    continue;
                }
                // The line u = const, w = a + v·ev, split where the shaping's kinks meet it.
                let (a, ev) = if swap {
                    (self.chart.w0 + self.chart.e2 * u, self.chart.e1)
                } else {
                    (self.chart.w0 + self.chart.e1 * u, self.chart.e2)
                };
                let mut bps = vec![lo, hi];
                if self.shaped {
                    for k in &self.p.profile.kinks {
                        match *k {
                            Kink::Cone { cos } => {
                                bps.extend(cone_roots_on_line(self.p.axis, cos, a, ev));
                            }
                            Kink::Plane { m, .. } => {
                                let den = m.dot(ev);
                                if den != 0.0 {
                                    bps.push(-m.dot(a) / den);
                                }
                            }
                        }
                    }
                    if self.p.profile.axis_singular {
                        bps.extend(axis_approach(self.p.axis, a, ev));
                    }
                }
                bps.retain(|&v| v >= lo && v <= hi);
                bps.sort_by(f64::total_cmp);
                for seg in bps.windows(2) {
                    let (vm, vh) = (0.5 * (seg[0] + seg[1]), 0.5 * (seg[1] - seg[0]));
                    if !(vh > 0.0) {
                        continue;
                    }
                    for (gv, wv) in G5X.iter().zip(&G5W) {
                        let v = vm + vh * gv;
                        let (x, y) = if swap { (v, u) } else { (u, v) };
                        sum += self.eval(x, y) * tree.value_at(x, y) * (wu * wv * uh * vh);
                    }
                }
            }
        }
        sum
    }

    /// The outer cuts of [`Kernel::clipped`] that the shaping's kinks need: the u where the
    /// inner structure of the lines u = const changes, so that the outer integrand (the inner
    /// integral as a function of u) is smooth between cuts and the 5-point rule across lines
    /// converges at its order, as `critical::critical_ys` splits the reference's outer
    /// integral. They are where a kink curve crosses the cell's sides v = v0, v1 or the
    /// horizon line (a root enters or leaves a line's interval), where a kink cone is tangent
    /// to a line of the pencil (two roots appear together: the inner integral has a
    /// square-root-type point there), and the line through the axis direction when the
    /// shaping is singular there. `h = c + p·u + q·v` is the horizon in (u, v).
    fn kink_cuts(
        &self,
        cuts: &mut Vec<f64>,
        swap: bool,
        (c, p, q): (f64, f64, f64),
        (u0, u1, v0, v1): (f64, f64, f64, f64),
    ) {
        let ch = self.chart;
        let (eu, ev) = if swap { (ch.e2, ch.e1) } else { (ch.e1, ch.e2) };
        // The lines along which u runs: the sides v = v0, v1 and the horizon line.
        let mut edges = vec![(ch.w0 + ev * v0, eu), (ch.w0 + ev * v1, eu)];
        if q != 0.0 {
            edges.push((ch.w0 - ev * (c / q), eu - ev * (p / q)));
        }
        let mut us = Vec::new();
        let axis = self.p.axis;
        for k in &self.p.profile.kinks {
            match *k {
                Kink::Cone { cos } => {
                    for &(a, d) in &edges {
                        us.extend(cone_roots_on_line(axis, cos, a, d));
                    }
                    // Planes through x containing ev (the lines u = const) tangent to the
                    // cone: normals m ⊥ ev with |m·axis| = sin θ (as `critical.rs`'s
                    // pencil tangents, with the roles of the chart axes swapped or not).
                    let s = (1.0 - cos * cos).max(0.0).sqrt();
                    let (m1, m2) = ev.normalize().any_orthonormal_pair();
                    let (pa, pb) = (m1.dot(axis), m2.dot(axis));
                    let ra = pa.hypot(pb);
                    if ra >= s && ra > 0.0 {
                        let t0 = pb.atan2(pa);
                        let d = (s / ra).clamp(-1.0, 1.0).acos();
                        for t in [t0 + d, t0 - d] {
                            let m = m1 * t.cos() + m2 * t.sin();
                            if m.dot(eu) != 0.0 {
                                us.push(-m.dot(ch.w0) / m.dot(eu));
                            }
                        }
                    }
                }
                Kink::Plane { m, .. } => {
                    for &(a, d) in &edges {
                        if m.dot(d) != 0.0 {
                            us.push(-m.dot(a) / m.dot(d));
                        }
                    }
                }
            }
        }
        if self.p.profile.axis_singular {
            // The line of the pencil through the axis directions.
            let m = ev.cross(axis);
            if m.dot(eu) != 0.0 {
                us.push(-m.dot(ch.w0) / m.dot(eu));
            }
        }
        cuts.extend(us.into_iter().filter(|&u| u > u0 && u < u1));
    }

    /// The cell's moment rule `Σ K(x_ab) W_ab`.
    fn rule(&self, r: Rect, w: &Moments) -> DVec3 {
        let (cx, cy, hx, hy) = r.centre();
        let mut s = DVec3::ZERO;
        for b in 0..3 {
            let y = cy + hy * GX[b];
            for a in 0..3 {
                let wab = w[3 * b + a];
                if wab != DVec3::ZERO {
                    s += self.eval(cx + hx * GX[a], y) * wab;
                }
            }
        }
        s
    }

    /// Whether the cell must be split before its rule is trusted: it is not well separated
    /// from x (half-diagonal R > ½ (|w_c| − R)) and the horizon does not hide all of it.
    /// An upper bound of `|∫ t·K|` over the cell `r`, per channel: `K = S·max(0, n·w)·J/|w|⁴`
    /// with `|S| ≤ s_max`, `n·w` linear (largest at a corner) and `|w| ≥ |w_c| − R` (see
    /// [`Kernel::near`]), times `t_max` and the cell's area. Infinite when the cell may reach x.
    fn cut_bound(&self, tmax: DVec3, r: Rect) -> DVec3 {
        let (cx, cy, hx, hy) = r.centre();
        let c = self.chart;
        let wc = c.w0 + c.e1 * cx + c.e2 * cy;
        let dmin = wc.length() - ((c.e1 * hx).length() + (c.e2 * hy).length());
        if !(dmin > 0.0) {
            return DVec3::INFINITY;
        }
        let corners = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)];
        let hmax = corners
            .iter()
            .map(|&(x, y)| self.n.dot(c.w0 + c.e1 * x + c.e2 * y))
            .fold(0.0, f64::max);
        let area = (r.x1 - r.x0) * (r.y1 - r.y0);
        tmax * self.s_max * (hmax * c.jac * area / (dmin * dmin * dmin * dmin))
    }

    fn near(&self, r: Rect) -> bool {
        let (cx, cy, hx, hy) = r.centre();
        let c = self.chart;
        let wc = c.w0 + c.e1 * cx + c.e2 * cy;
        let rad = (c.e1 * hx).length() + (c.e2 * hy).length();
        if !(rad > 0.5 * (wc.length() - rad)) {
            return false;
        }
        let corners = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)];
        corners
            .iter()
            .any(|&(x, y)| self.n.dot(c.w0 + c.e1 * x + c.e2 * y) > 0.0)
    }
}

/// An active cell: its value (the sum of its children's rules), their rules and error
/// bounds, its error (an estimate, or an a-priori bound when `bounded`).
struct Active {
    key: f64,
    value: DVec3,
    err: DVec3,
    bounded: bool,
    kids: Vec<(Cell, (DVec3, DVec3))>,
}

impl PartialEq for Active {
    fn eq(&self, o: &Self) -> bool {
        self.key.total_cmp(&o.key).is_eq()
    }
}
impl Eq for Active {}
impl PartialOrd for Active {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Active {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.key.total_cmp(&o.key)
    }
}

/// The chart integral `∫∫ t·K dX dY` of the textured rect `p` (base radiance not applied) to
/// relative tolerance `rel` (module docs). None when `p` has no texture.
pub fn chart_integral(p: &Prepared, chart: &Chart, n: DVec3, rel: f64) -> Option<DVec3> {
    let tree = tree(p.rect_texture()?)?;
    let k = Kernel::new(p, chart, n);
    let activate = |cell: Cell, (own, own_bound): (DVec3, DVec3)| -> Active {
        let kids: Vec<(Cell, (DVec3, DVec3))> = tree
            .children(&cell)
            .into_iter()
            .map(|c| {
                let v = k.cell_rule(&tree, &c);
                (c, v)
            })
            .collect();
        if kids.is_empty() {
            return Active {
                key: 0.0,
                value: own,
                err: DVec3::ZERO,
                bounded: false,
                kids,
            };
        }
        let value: DVec3 = kids.iter().map(|c| c.1.0).sum();
        let err = (value - own).abs();
        let r = tree.rect(&cell);
        // A clipped rule samples t at its Gauss points; over more than one texel piece it
        // samples across t's kinks (bilinear) or jumps (nearest), where neither it nor its
        // children's rules converge, and both can miss the same texel: a cell whose lit part
        // lies in one child gets that child's very rule points (estimate exactly 0), and a
        // lit texel between the points of both goes unseen. Measured (module docs): a shaped
        // 256 × 128 rect off by 3.0e-4 at every tolerance, a one-texel texture found to 33 %.
        // So such a cell is not trusted on its estimate. Where a shaping kink may cross it, it
        // is split untrusted down to single pieces, where t is a polynomial and the clipped
        // rule converges. Where only the horizon cuts it, its own rule is the bracket rule
        // (`Kernel::bracket`: no sampling) whose error is at most `own_bound`, so the
        // children's sum is off by at most `own_bound + |Σ children − own|` (or the whole
        // contribution's `Kernel::cut_bound`, where smaller): a bound, not an estimate, held to
        // its own share of the tolerance (`BOUND_SHARE`). One-texel textures were missed by up
        // to 100 % while such cells were trusted on their estimates (module docs).
        let cut = tree.pieces(&cell) > 1 && k.rule_kind(r) == RuleKind::Clipped;
        let (key, err, bounded) = if k.near(r) || (cut && k.kinks(r) == Kinks::Other) {
            (f64::INFINITY, err, false)
        } else if cut {
            let b = (own_bound + err).min(k.cut_bound(tree.t_max(&cell), r));
            (b.max_element() * (ESTIMATE_SHARE / BOUND_SHARE), b, true)
        } else {
            (err.max_element(), err, false)
        };
        Active {
            key,
            value,
            err,
            bounded,
            kids,
        }
    };
    let root = Cell::Node(0);
    let own = k.cell_rule(&tree, &root);
    let first = activate(root, own);
    // Estimated errors and a-priori bounds are summed apart, each held to its share of rel.
    let mut total = first.value;
    let mut err = [DVec3::ZERO; 2];
    err[usize::from(first.bounded)] += first.err;
    let mut forced = usize::from(first.key == f64::INFINITY);
    let mut heap = BinaryHeap::new();
    heap.push(first);
    let shares = [ESTIMATE_SHARE * rel, BOUND_SHARE * rel];
    for _ in 0..MAX_SPLITS {
        let tiny = 1e-14 * total.abs().max_element();
        let done = forced == 0
            && err.iter().zip(shares).all(|(e, q)| {
                (e.x <= q * total.x.abs() + tiny)
                    && (e.y <= q * total.y.abs() + tiny)
                    && (e.z <= q * total.z.abs() + tiny)
            });
        if done {
            break;
        }
        let Some(top) = heap.pop() else { break };
        if top.key == 0.0 && forced == 0 {
            heap.push(top);
            break;
        }
        if top.key == f64::INFINITY {
            forced -= 1;
        }
        total -= top.value;
        err[usize::from(top.bounded)] -= top.err;
        for (c, own) in top.kids {
            let a = activate(c, own);
            total += a.value;
            err[usize::from(a.bounded)] += a.err;
            forced += usize::from(a.key == f64::INFINITY);
            heap.push(a);
        }
    }
    // The running sums lose digits as large terms leave: the final value is summed afresh.
    Some(heap.iter().map(|a| a.value).sum())
}

pub mod tree;

pub use tree::tree;

#[cfg(test)]
mod tests;
