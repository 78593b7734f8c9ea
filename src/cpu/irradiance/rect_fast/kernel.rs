//! The kernel of `rect_fast`'s chart integral and the rules of one cell: the moment rule, the
//! bracket rule of cells the horizon cuts or a soft cone's kinks cross, and the clipped rule
//! (see the parent module's docs).

use std::f64::consts::PI;

use glam::DVec3;

use super::tree::{Cell, GX, Moments, Rect, Tree};
use crate::cpu::irradiance::chart::Chart;
use crate::cpu::roots::{axis_approach, cone_roots_on_line, pencil_tangent_normals};
use crate::cpu::shaping::{cone_factor, focus_factor, shaping};
use crate::prepare::{Kink, Prepared};

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

/// The rule of a cell (see [`Kernel::rule_kind`]).
#[derive(Clone, Copy, PartialEq, Debug)]
pub(super) enum RuleKind {
    Zero,
    Moments,
    Clipped,
}

/// The smooth kernel `K = S(−ŵ)·max(0, n·w)·J/|w|⁴` of the chart integral (module docs).
pub(super) struct Kernel<'a> {
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
    /// The angle from the axis of each of the shaping's kinks that is a cone (NaN for a
    /// plane), in the order of `Prepared::profile`: [`Kernel::kinks`] compares it with every
    /// cell's directions.
    kink_angles: Vec<f64>,
}

/// How a cell is integrated and trusted ([`Kernel::class`]).
#[derive(Clone, Copy, PartialEq, Debug)]
pub(super) struct Class {
    pub(super) kind: RuleKind,
    pub(super) kinks: Kinks,
    /// Over several texel pieces, cut by the horizon or crossed by a soft cone's kink cones
    /// and no other kink: the rule is [`Kernel::bracket`], whose error has a bound.
    pub(super) bracketed: bool,
    /// Split without being trusted: not well separated from x ([`Kernel::near`]), or over
    /// several texel pieces where a hard cone's edge, the focus plane or a singular axis may
    /// cross it (the clipped rule samples t across its texel kinks there).
    pub(super) forced: bool,
}

/// How the shaping's kinks meet a cell ([`Kernel::kinks`]).
#[derive(Clone, Copy, PartialEq, Debug)]
pub(super) enum Kinks {
    None,
    /// Only kink cones of a soft cone (the smoothstep's start or the cone's edge).
    SoftCone,
    /// A hard cone's edge, the focus plane, or the axis where the factor is singular.
    Other,
}

impl<'a> Kernel<'a> {
    pub(super) fn new(p: &'a Prepared, chart: &'a Chart, n: DVec3) -> Self {
        let s = p.shaping.as_ref();
        Kernel {
            p,
            chart,
            n,
            shaped: s.is_some(),
            s_max: s.map_or(DVec3::ONE, |s| s.factor_bound()),
            soft_cone: s.is_some_and(|s| s.start < s.cone),
            kink_angles: p
                .profile
                .kinks
                .iter()
                .map(|k| match *k {
                    Kink::Cone { cos } => cos.clamp(-1.0, 1.0).acos(),
                    Kink::Plane { .. } => f64::NAN,
                })
                .collect(),
        }
    }
}

impl Kernel<'_> {
    #[inline]
    pub(super) fn eval(&self, x: f64, y: f64) -> DVec3 {
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
    pub(super) fn horizon(&self) -> (f64, f64, f64) {
        (
            self.n.dot(self.chart.w0),
            self.n.dot(self.chart.e1),
            self.n.dot(self.chart.e2),
        )
    }

    /// Which rule a cell takes: none behind the horizon, the moment rule where neither the
    /// horizon nor a shaping kink may cross it (K smooth on it), else [`Kernel::clipped`].
    /// `kinks` is the cell's [`Kernel::kinks`], computed once per cell by the caller.
    fn rule_kind(&self, r: Rect, kinks: Kinks) -> RuleKind {
        let (c, a, b) = self.horizon();
        let hs = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)]
            .map(|(x, y)| c + a * x + b * y);
        if hs.iter().all(|&h| !(h > 0.0)) {
            RuleKind::Zero
        } else if hs.iter().all(|&h| h > 0.0) && kinks == Kinks::None {
            RuleKind::Moments
        } else {
            RuleKind::Clipped
        }
    }

    /// How the cell is integrated and trusted, decided once per cell (the parent module's
    /// `chart_integral` reads it when the cell is refined).
    pub(super) fn class(&self, tree: &Tree, cell: &Cell) -> Class {
        let r = tree.rect(cell);
        let kinks = self.kinks(r);
        let kind = self.rule_kind(r, kinks);
        let cut = tree.pieces(cell) > 1 && kind == RuleKind::Clipped;
        let forced = self.near(r) || (cut && kinks == Kinks::Other);
        Class {
            kind,
            kinks,
            bracketed: cut && kinks != Kinks::Other,
            forced,
        }
    }

    /// The cell's rule (see [`Kernel::rule_kind`]) and a bound of its error where that is known
    /// a priori (the bracket rule's), else 0: a cell over several texel pieces that the horizon
    /// cuts or a soft cone's kink cones may cross, and no other kink, takes
    /// [`Kernel::bracket`], other cut or kinked cells [`Kernel::clipped`]. `class` is the
    /// cell's [`Kernel::class`].
    pub(super) fn cell_rule(&self, tree: &Tree, cell: &Cell, class: Class) -> (DVec3, DVec3) {
        let r = tree.rect(cell);
        match class.kind {
            RuleKind::Zero => (DVec3::ZERO, DVec3::ZERO),
            RuleKind::Moments => (self.rule(r, &tree.moments(cell)), DVec3::ZERO),
            RuleKind::Clipped if class.bracketed => {
                let w = tree.moments(cell);
                let coned = class.kinks == Kinks::SoftCone;
                self.bracket(r, &w, tree.abs_integral(cell, r, &w), coned)
            }
            RuleKind::Clipped => (
                self.clipped(r, |x, y| tree.value_in(cell, x, y)),
                DVec3::ZERO,
            ),
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
    /// `coned`: the cell's kinks are [`Kinks::SoftCone`].
    pub(super) fn bracket(&self, r: Rect, w: &Moments, tabs: DVec3, coned: bool) -> (DVec3, DVec3) {
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
        let value = Self::rule_by(r, w, |x, y| {
            let wv = ch.w0 + ch.e1 * x + ch.e2 * y;
            let l2 = wv.length_squared();
            let q = lambda * (c0 + a * x + b * y) + 0.5 * d;
            let g = q * ch.jac / (l2 * l2);
            let e = -wv / l2.sqrt();
            match self.p.shaping.as_ref() {
                None => DVec3::splat(g),
                Some(s) if coned => focus_factor(s.focus, s.focus_tint, e.dot(self.p.axis)) * g,
                Some(_) => shaping(self.p, e) * g,
            }
        });
        let (cx, cy, hx, hy) = r.centre();
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

    /// The cell's directions: the centre direction's angle θ from the axis and a bound α of
    /// the angle between it and any direction of the cell (`asin(R/|w_c|)`); None when the
    /// cell may reach x.
    pub(super) fn angles(&self, r: Rect) -> Option<(f64, f64)> {
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
        for (k, &angle) in self.p.profile.kinks.iter().zip(&self.kink_angles) {
            let crosses = match *k {
                Kink::Cone { .. } => match dirs {
                    Some((theta, alpha)) => (angle - theta).abs() <= alpha,
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
    /// 5 × 5 Gauss–Legendre rule of `t·K` (K smooth there, t sampled: `t(x, y)`). No rule point lies
    /// behind the horizon, so no sliver in front of it goes unseen.
    pub(super) fn clipped(&self, r: Rect, t: impl Fn(f64, f64) -> DVec3) -> DVec3 {
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
        // One buffer for every line's breakpoints (an allocation per line was ~5 % of a
        // shaped receiver's time).
        let mut bps = Vec::with_capacity(8);
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
                bps.clear();
                bps.extend([lo, hi]);
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
                        sum += self.eval(x, y) * t(x, y) * (wu * wv * uh * vh);
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
    pub(super) fn kink_cuts(
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
                    // cone (as `critical.rs`'s pencil tangents, with the roles of the chart
                    // axes swapped or not).
                    for m in pencil_tangent_normals(ev, axis, cos).into_iter().flatten() {
                        if m.dot(eu) != 0.0 {
                            us.push(-m.dot(ch.w0) / m.dot(eu));
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
    pub(super) fn rule(&self, r: Rect, w: &Moments) -> DVec3 {
        Self::rule_by(r, w, |x, y| self.eval(x, y))
    }

    /// The moment rule `Σ f(x_ab) W_ab` of a kernel f (per channel) on the cell's 3 × 3
    /// Gauss–Legendre points; f is not evaluated where the moment is 0.
    pub(super) fn rule_by(r: Rect, w: &Moments, f: impl Fn(f64, f64) -> DVec3) -> DVec3 {
        let (cx, cy, hx, hy) = r.centre();
        let mut s = DVec3::ZERO;
        for b in 0..3 {
            let y = cy + hy * GX[b];
            for a in 0..3 {
                let wab = w[3 * b + a];
                if wab != DVec3::ZERO {
                    s += f(cx + hx * GX[a], y) * wab;
                }
            }
        }
        s
    }

    /// An upper bound of `|∫ t·K|` over the cell `r`, per channel: `K = S·max(0, n·w)·J/|w|⁴`
    /// with `|S| ≤ s_max`, `n·w` linear (largest at a corner) and `|w| ≥ |w_c| − R` (see
    /// [`Kernel::near`]), times `t_max` and the cell's area. Infinite when the cell may reach x.
    pub(super) fn cut_bound(&self, tmax: DVec3, r: Rect) -> DVec3 {
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

    /// Whether the cell must be split before its rule is trusted: it is not well separated
    /// from x (half-diagonal R > ½ (|w_c| − R)) and the horizon does not hide all of it.
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
