//! The outer (across lines) integral of the chart quadrature, and `treatAsLine` (f64). Twin of
//! `shaders/irradiance/outer.wgsl`.
//!
//! The chart's Y-range is split at the critical Ys (`critical`); each piece is mapped by the
//! cosine substitution (square-root ends become smooth) after a tan map around the foot of x
//! when x is close to the chart plane (`pieces`), and integrated by the rule's outer integral of
//! the line integrals (`line`).
//!
//! `treatAsLine` is one inner line: the segment along the axis, whose intensity along e is
//! `L(e)·2·length·r·|det M|·|(M⁻¹e)_yz|` (DESIGN.md §2 "Edge cases"), which gives the weight
//! `2 r |det M| ρ` (ρ = distance of x from the axis in light space) for the same integrand.

use glam::DVec3;

use super::chart::{Chart, Region};
use super::line::line_integral;
use super::pieces::{map_eval, piece_map, span, span_count};
use super::{Ctx, Rule};
use crate::prepare::Prepared;
use crate::prepare::ies_kinks::IesKinks;

/// The nearest singularity `y_foot ± i·width` of the outer integrand on the piece [y0, y1].
///
/// Along a line Y, min over X of |w|² is |(w0 + Y e2) × e1|²/|e1|² = |U + Y V|²/|e1|²
/// (U = w0 × e1, V = e2 × e1) = H² + |V|²(Y − y_foot)²/|e1|², H = jac/|V| the distance from x to
/// the chart plane: a Lorentzian of width H|e1|/|V| when the foot of x lies inside the region.
/// When it lies a chart distance D outside the region's X-interval, the line's integrand never
/// reaches that minimum and the peak widens to √(H² + D²|e1|²)·|e1|/|V|.
fn outer_pole(chart: &Chart, y0: f64, y1: f64) -> (f64, f64) {
    let u = chart.w0.cross(chart.e1);
    let v = chart.e2.cross(chart.e1);
    let vv = v.length_squared();
    let y_foot = -u.dot(v) / vv;
    let e1l = chart.e1.length();
    let h = chart.jac / vv.sqrt();
    let x_foot = -(chart.w0 + chart.e2 * y_foot).dot(chart.e1) / (e1l * e1l);
    let d = match chart.x_interval(y_foot.clamp(y0, y1)) {
        Some((x0, x1)) => (x0 - x_foot).max(x_foot - x1).max(0.0),
        None => 0.0,
    };
    (y_foot, (h * h + (d * e1l).powi(2)).sqrt() * e1l / vv.sqrt())
}

/// A cone of directions that holds every direction of the chart's region, written with the
/// vectors `w0, e1, e2` of the chart (world) or of its image under a linear map (the light's
/// frame): (unit ŵ0, half-angle α). The region's vectors are `w0 + X e1 + Y e2` with
/// `|X e1 + Y e2| ≤ R`, so every direction lies within `α = asin(R/|w0|)` of `ŵ0`. None when
/// R is not below |w0|/2 (a bound that wide filters nothing).
pub fn direction_cone(chart: &Chart, w0: DVec3, e1: DVec3, e2: DVec3) -> Option<(DVec3, f64)> {
    let r = match &chart.region {
        Region::Square => e1.length() + e2.length(),
        Region::Disk => (e1.length_squared() + e2.length_squared()).sqrt(),
        Region::Cylinder(c) => {
            // The X-interval is widest at Y = 0 (`Chart::x_interval`).
            let (x0, x1) = chart.x_interval(0.0)?;
            x0.abs().max(x1.abs()) * e1.length() + c.yg * e2.length()
        }
    };
    let d = w0.length();
    if !(r < 0.5 * d) || !r.is_finite() {
        return None;
    }
    Some((w0 / d, (r / d).asin()))
}

/// The IES kink surfaces (cones and planes of light-space emission directions) that can meet a
/// direction of the chart's region; None when the light has no profile or the region's
/// directions are not bounded away from all directions.
///
/// In the light's frame the region's vectors are `w0 + X e1 + Y e2` with `|X e1 + Y e2| ≤ R`,
/// so every direction lies within `α = asin(R/|w0|)` of `ŵ0`. A cone `−ŵ·axis = cos` whose
/// angle differs from that of `−ŵ0` by more than α, or a plane whose angle with `ŵ0` exceeds
/// α, has no point inside the region: its roots on every line of the chart lie outside the
/// line's interval, where `line_integral` drops them. Dropping them here (with a margin of
/// 1e-6 rad for rounding) spares the line integrals solving for them and changes no
/// breakpoint: a small or distant light meets few of a profile's grid lines.
pub fn chart_ies_kinks(p: &Prepared, chart: &Chart) -> Option<IesKinks> {
    let ies = p.ies.as_ref()?;
    let (w0, alpha) = direction_cone(
        chart,
        p.to_local * chart.w0,
        p.to_local * chart.e1,
        p.to_local * chart.e2,
    )?;
    const MARGIN: f64 = 1e-6;
    let alpha = alpha + MARGIN;
    let c = -w0;
    let cones = ies
        .kinks
        .cones
        .iter()
        .filter(|(axis, cos)| {
            let theta_c = c.cross(*axis).length().atan2(c.dot(*axis));
            (theta_c - cos.clamp(-1.0, 1.0).acos()).abs() <= alpha
        })
        .copied()
        .collect();
    let planes = ies
        .kinks
        .planes
        .iter()
        .filter(|m| (m.normalize().dot(c).abs().min(1.0)).asin() <= alpha)
        .copied()
        .collect();
    Some(IesKinks { cones, planes })
}

/// `∫∫ S(−ŵ)·max(0, n·w)·J/|w|⁴ dX dY` over the chart's region, split at `ys` (the critical
/// Ys of `critical::critical_ys`, which include the ends of the region's Y-range).
pub fn chart_integral<R: Rule>(
    p: &Prepared,
    chart: &Chart,
    n: DVec3,
    ys: &[f64],
    rule: &R,
) -> DVec3 {
    chart_integral_as(p, chart, n, ys, rule, false)
}

/// [`chart_integral`]; `uniform`: the caller has shown that the shaping factor is exactly 1 on
/// every direction of the chart (`super::uniform_shaping`), so each line takes the unshaped
/// closed form.
pub fn chart_integral_as<R: Rule>(
    p: &Prepared,
    chart: &Chart,
    n: DVec3,
    ys: &[f64],
    rule: &R,
    uniform: bool,
) -> DVec3 {
    if p.profile.dark || !(chart.jac > 0.0) || !chart.jac.is_finite() {
        return DVec3::ZERO;
    }
    let tex = super::rect_texture::chart_texture(p, chart);
    let ctx = Ctx {
        p,
        n,
        unshaped: (p.shaping.is_none() || uniform) && tex.is_none(),
        rule,
        tex,
        ies_kinks: chart_ies_kinks(p, chart),
    };
    let mut total = DVec3::ZERO;
    for w in ys.windows(2) {
        let (y_foot, width) = outer_pole(chart, w[0], w[1]);
        let map = piece_map(w[0], w[1], y_foot, width, false, false);
        let k = span_count(&map, rule.max_u_span());
        for j in 0..k {
            let piece = span(&map, j, k);
            total += rule.outer(&mut |s: f64| {
                let (y, dy) = map_eval(&piece, s, true);
                if dy == 0.0 {
                    return DVec3::ZERO;
                }
                match chart.x_interval(y) {
                    Some((x0, x1)) => {
                        line_integral(&ctx, chart.w0 + chart.e2 * y, chart.e1, x0, x1, y)
                            * (dy * chart.jac)
                    }
                    None => DVec3::ZERO,
                }
            });
        }
    }
    total
}

/// treatAsLine: the segment along the light's X axis (DESIGN.md §2), see the module docs.
pub fn line_irradiance<R: Rule>(
    p: &Prepared,
    x: DVec3,
    n: DVec3,
    hl: f64,
    r: f64,
    rule: &R,
) -> DVec3 {
    let m = p.linear;
    let xl = p.to_local * (x - p.origin);
    let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
    let weight = 2.0 * r * p.det * rho;
    if !(weight > 0.0) || !(hl > 0.0) {
        return DVec3::ZERO;
    }
    if p.profile.dark {
        return DVec3::ZERO;
    }
    let ctx = Ctx {
        p,
        n,
        unshaped: p.shaping.is_none(),
        rule,
        tex: None,
        ies_kinks: None,
    };
    p.base * line_integral(&ctx, p.origin - x, m * DVec3::X, -hl, hl, 0.0) * weight
}
