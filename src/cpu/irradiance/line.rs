//! The inner (line) integrals of the chart quadrature (f64). Twin of
//! `shaders/irradiance/line.wgsl`.
//!
//! Along a line Y = const of the chart, `∫ S(−ŵ)·max(0, n·w)/|w|⁴ dX` over the region's
//! X-interval, clipped at the receiver horizon (n·w = 0: linear in X), split where the shaping
//! factor S is not smooth. Every such set is a cone of emission angle θ around the light's axis
//! (cone edge, smoothstep start: quadratic in X) or a plane through x (focus at θ = 90°:
//! linear): the split points are exact roots (`cpu::roots`). Unshaped: closed form after
//! X = X* + w·tan u (the line's closest approach X*, width w), which turns `(n·w)/|w|⁴ dX` into
//! a trigonometric polynomial. Shaped: the rule's inner integral on each smooth piece, with the
//! tan map when the piece reaches within a few widths of the closest approach (the near-field
//! peak), and a cubic grading at the focus plane where |cos θ|^focus is not smooth.

use glam::DVec3;

use super::pieces::{graded_parts, map_eval, piece_map, span, span_count};
use super::{Ctx, Rule};
use crate::cpu::roots::{axis_approach, cone_roots_on_line};
use crate::cpu::shaping::shaping;
use crate::prepare::Kink;

thread_local! {
    /// `line_integral`'s breakpoint list, kept by each thread between lines: a new list per
    /// line cost a malloc and a realloc or two, and on many cores those calls contend for
    /// malloc's arena locks (on a 16-core VM a 1024² map spent 3× its user time in the kernel:
    /// BENCHMARKS.md, "The CPU path's system time").
    static BREAKPOINTS: std::cell::RefCell<Vec<(f64, bool)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// `∫ S(−ŵ)·max(0, n·w)/|w|⁴ dX` along w = a + X e1 for X in [x0, x1], the line Y = `y` of the
/// chart (`y` is read only for a textured rect's texture factor, `rect_texture`).
pub fn line_integral<R: Rule>(
    ctx: &Ctx<R>,
    a: DVec3,
    e1: DVec3,
    x0: f64,
    x1: f64,
    y: f64,
) -> DVec3 {
    let (lo, hi) = match clip_horizon(ctx.n, a, e1, x0, x1) {
        Some(v) => v,
        None => return DVec3::ZERO,
    };
    // Breakpoints with their grading flag, in the thread's list (taken, so that a nested call
    // would get a list of its own).
    let mut bps = BREAKPOINTS.with(|b| std::mem::take(&mut *b.borrow_mut()));
    bps.clear();
    bps.extend([(lo, false), (hi, false)]);
    // (An unshaped line has no shaping kinks; one whose factor is uniformly 1 ignores them.)
    let kinks: &[Kink] = if ctx.unshaped {
        &[]
    } else {
        &ctx.p.profile.kinks
    };
    for k in kinks {
        match *k {
            Kink::Cone { cos } => {
                for xk in cone_roots_on_line(ctx.p.axis, cos, a, e1) {
                    bps.push((xk, false));
                }
            }
            Kink::Plane { m, graded } => {
                let den = m.dot(e1);
                if den != 0.0 {
                    bps.push((-m.dot(a) / den, graded));
                }
            }
        }
    }
    if ctx.p.profile.axis_singular && !ctx.unshaped {
        bps.extend(axis_approach(ctx.p.axis, a, e1).map(|xa| (xa, false)));
    }
    if let Some(ies) = &ctx.p.ies {
        // The profile's grid lines, in the light's frame: the line maps to a line there (only
        // those that can meet the chart, when the chart has listed them).
        let kinks = ctx.ies_kinks.as_ref().unwrap_or(&ies.kinks);
        let (al, el) = (ctx.p.to_local * a, ctx.p.to_local * e1);
        for &(axis, cos) in &kinks.cones {
            bps.extend(
                cone_roots_on_line(axis, cos, al, el)
                    .into_iter()
                    .map(|x| (x, false)),
            );
        }
        for &m in &kinks.planes {
            let den = m.dot(el);
            if den != 0.0 {
                bps.push((-m.dot(al) / den, false));
            }
        }
    }
    if let Some(t) = &ctx.tex {
        // The texture's vertical break lines (texel-centre lines or texel edges).
        bps.extend(t.xs.iter().map(|&x| (x, false)));
    }
    bps.retain(|b| b.0 >= lo && b.0 <= hi);
    bps.sort_by(|p, q| p.0.total_cmp(&q.0));
    // The line's closest approach to x: X* and the width √m/|e1|, m = |a × e1|²/|e1|².
    let e12 = e1.length_squared();
    let x_star = -a.dot(e1) / e12;
    let perp = a + e1 * x_star;
    let cr = a.cross(e1).length();
    let width = cr / e12;
    let m = cr * cr / e12;
    let mut sum = DVec3::ZERO;
    for w in bps.windows(2) {
        let ((t0, g0), (t1, g1)) = (w[0], w[1]);
        if !(t1 > t0) {
            continue;
        }
        let map = piece_map(t0, t1, x_star, width, false, false);
        if ctx.unshaped && ctx.rule.unshaped_closed_form(map.tan_map) {
            // Closed form (the kernel uses it only where it maps with tan: there it cannot
            // cancel in f32).
            sum += DVec3::splat(unshaped_segment(ctx.n, perp, e1, m, width, x_star, t0, t1));
            continue;
        }
        for (p0, p1, glo, ghi) in graded_parts(t0, t1, g0, g1) {
            let map = piece_map(p0, p1, x_star, width, glo, ghi);
            let k = span_count(&map, ctx.rule.max_u_span());
            for j in 0..k {
                let piece = span(&map, j, k);
                sum += ctx.rule.inner(&mut |s: f64| {
                    let (xx, dx) = map_eval(&piece, s, false);
                    let wv = a + e1 * xx;
                    let nw = ctx.n.dot(wv);
                    if !(nw > 0.0) || dx == 0.0 {
                        return DVec3::ZERO;
                    }
                    let l2 = wv.length_squared();
                    let e = -wv / l2.sqrt();
                    let v = shaping(ctx.p, e) * (nw / (l2 * l2) * dx);
                    match &ctx.tex {
                        Some(t) => v * t.value(xx, y),
                        None => v,
                    }
                });
            }
        }
    }
    BREAKPOINTS.with(|b| *b.borrow_mut() = bps);
    sum
}

/// The X-interval of [x0, x1] where n·(a + X e1) ≥ 0.
pub fn clip_horizon(n: DVec3, a: DVec3, e1: DVec3, x0: f64, x1: f64) -> Option<(f64, f64)> {
    let (na, ne) = (n.dot(a), n.dot(e1));
    let (mut lo, mut hi) = (x0, x1);
    if ne > 0.0 {
        lo = lo.max(-na / ne);
    } else if ne < 0.0 {
        hi = hi.min(-na / ne);
    } else if !(na > 0.0) {
        return None;
    }
    (hi > lo).then_some((lo, hi))
}

/// `∫_{t0}^{t1} (n·w)/|w|⁴ dX` for w = perp + (X − X*) e1 (perp ⊥ e1, |perp|² = m), in closed
/// form: with X − X* = width·tan u the integrand is `(width/m²)(n·perp cos²u + width n·e1 sin u cos u)`.
#[allow(clippy::too_many_arguments)]
pub fn unshaped_segment(
    n: DVec3,
    perp: DVec3,
    e1: DVec3,
    m: f64,
    width: f64,
    x_star: f64,
    t0: f64,
    t1: f64,
) -> f64 {
    if !(m > 0.0) {
        return 0.0;
    }
    let (u0, u1) = (
        ((t0 - x_star) / width).atan(),
        ((t1 - x_star) / width).atan(),
    );
    let np = n.dot(perp);
    let ne = n.dot(e1) * width;
    let prim = |u: f64| np * (0.5 * u + 0.25 * (2.0 * u).sin()) + ne * 0.5 * u.sin().powi(2);
    (width / (m * m) * (prim(u1) - prim(u0))).max(0.0)
}
