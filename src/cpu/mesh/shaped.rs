//! The irradiance of a shaped mesh light over one visible piece (DESIGN.md §7 M3: "shaped
//! meshes integrate the shaping over those pieces"), to the query's relative tolerance.
//!
//! Cone, softness and focus depend on the emission direction e = −ω only through its angle θ to
//! the primary axis (spec/002; DESIGN.md §2 "Shaping"), so the piece is integrated in polar
//! coordinates about c = −axis, where dω = sin θ dθ dφ:
//!
//! `∫ S(θ) max(0, n·ω) dω = ∫ S(θ) sin θ [∫_{Φ(θ)} n·ω(θ, φ) dφ] dθ`.
//!
//! - The piece, clipped first at the receiver's horizon (Sutherland–Hodgman), is a convex
//!   spherical polygon: the intersection of the half-spaces `g_i·ω ≥ 0` of its edges' great
//!   circles. On the circle of constant θ each is `A + R cos(φ − φ_i) ≥ 0`, one arc, so Φ(θ) is
//!   an intersection of arcs, computed exactly.
//! - On Φ(θ), `n·ω = (n·c) cos θ + sin θ ((n·u) cos φ + (n·v) sin φ)` integrates in closed
//!   form; the horizon clip makes it non-negative there.
//! - Across θ the inner value is smooth between the vertices' θ, each edge's nearest and
//!   farthest θ (where the circle turns tangent to the edge: square-root ends) and the shaping's
//!   kinks (the smoothstep's start, the cone, a type C IES profile's vertical angles under a
//!   similarity): those are the breaks, and each piece between breaks is mapped by
//!   `θ = a + (b − a)(3t² − 2t³)`, which makes square-root ends smooth, then integrated by the
//!   reference's adaptive Gauss–Kronrod (`cpu::quadrature`).
//! - An IES profile also varies with φ: the inner integral is then the same adaptive rule over
//!   each arc of Φ(θ), split where its horizontal-angle planes cross the circle.

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use crate::cpu::irradiance::closed::clip_above;
use crate::cpu::quadrature::{Tolerance, integrate};
use crate::cpu::shaping::shaping;
use crate::prepare::Prepared;

/// `∫ S(−ω) max(0, n·ω) dω` over the convex planar polygon `verts` (vectors from the receiver,
/// any orientation), S the light's RGB shaping factor, to relative tolerance `rel`.
pub fn piece(p: &Prepared, verts: &[DVec3], n: DVec3, rel: f64) -> DVec3 {
    let poly: Vec<DVec3> = clip_above(verts, n)
        .into_iter()
        .filter_map(DVec3::try_normalize)
        .collect();
    if poly.len() < 3 {
        return DVec3::ZERO;
    }
    let mut poly = poly;
    let m: DVec3 = poly.iter().copied().sum();
    // Counter-clockwise seen from the receiver, so that each edge's `a × b` points inward.
    if poly[0].cross(poly[1]).dot(m) < 0.0 {
        poly.reverse();
    }
    let k = poly.len();
    let edges: Vec<(DVec3, DVec3, DVec3)> = (0..k)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % k]);
            (a, b, a.cross(b).try_normalize().unwrap_or(DVec3::ZERO))
        })
        .filter(|e| e.2 != DVec3::ZERO)
        .collect();
    if edges.len() < 3 {
        return DVec3::ZERO;
    }
    let c = -p.axis;
    let (u, v) = c.any_orthonormal_pair();
    let theta = |w: DVec3| w.dot(c).clamp(-1.0, 1.0).acos();

    // The θ range and its breaks.
    let mut breaks: Vec<f64> = poly.iter().map(|&w| theta(w)).collect();
    for &(a, b, g) in &edges {
        let proj = c - c.dot(g) * g;
        if let Some(near) = proj.try_normalize() {
            for t in [near, -near] {
                // On the arc from a to b (both turn the same way about g).
                if a.cross(t).dot(g) >= 0.0 && t.cross(b).dot(g) >= 0.0 {
                    breaks.push(theta(t));
                }
            }
        }
    }
    if edges.iter().all(|e| e.2.dot(c) >= 0.0) {
        breaks.push(0.0);
    }
    if edges.iter().all(|e| e.2.dot(c) <= 0.0) {
        breaks.push(PI);
    }
    let lo = breaks.iter().copied().fold(PI, f64::min);
    let mut hi = breaks.iter().copied().fold(0.0, f64::max);
    let s = p.shaping.as_ref();
    if let Some(s) = s {
        // Beyond the cone the factor is exactly 0 (spec/002).
        if s.cone < PI {
            hi = hi.min(s.cone);
        }
        breaks.extend([s.start, s.cone]);
    }
    let mut phi_breaks: Vec<f64> = Vec::new();
    if let (Some(ies), Some(_)) = (&p.ies, p.similarity) {
        // Under a similarity, a light-space cone about ±Z is a world cone about the axis and a
        // plane through Z is a plane through the axis (prepare::ies_kinks).
        for &(axis, cos) in &ies.kinks.cones {
            let world = (p.linear * axis).normalize();
            if world.dot(p.axis).abs() > 1.0 - 1e-12 {
                let cos_axis = if world.dot(p.axis) > 0.0 { cos } else { -cos };
                breaks.push(cos_axis.clamp(-1.0, 1.0).acos());
            }
        }
        for &normal in &ies.kinks.planes {
            let g = (p.to_local.transpose() * normal).normalize();
            if g.dot(c).abs() < 1e-12 {
                let phi = (-g.dot(u)).atan2(g.dot(v));
                phi_breaks.extend([phi.rem_euclid(TAU), (phi + PI).rem_euclid(TAU)]);
            }
        }
    }
    breaks.retain(|&t| t >= lo && t <= hi);
    breaks.extend([lo, hi]);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    if !(hi > lo) {
        return DVec3::ZERO;
    }
    let (nc, nu, nv) = (n.dot(c), n.dot(u), n.dot(v));
    let outer = Tolerance {
        rel,
        abs: 0.0,
        max_intervals: 200,
    };
    let inner = Tolerance {
        rel: rel * 0.1,
        abs: 0.0,
        max_intervals: 100,
    };
    let radial = p.ies.is_none();
    let ring = |th: f64| -> DVec3 {
        let (st, ct) = th.sin_cos();
        let arcs = arcs_at(&edges, c, u, v, st, ct);
        if radial {
            let len: f64 = arcs
                .iter()
                .map(|&(a, b)| {
                    nc * ct * (b - a) + st * (nu * (b.sin() - a.sin()) - nv * (b.cos() - a.cos()))
                })
                .sum();
            if len <= 0.0 {
                return DVec3::ZERO;
            }
            shaping(p, -(c * ct + u * st)) * (st * len)
        } else {
            let mut sum = DVec3::ZERO;
            for &(a, b) in &arcs {
                let mut cuts = vec![a, b];
                for &f in &phi_breaks {
                    for k in [-1.0, 0.0, 1.0, 2.0] {
                        let f = f + k * TAU;
                        if f > a && f < b {
                            cuts.push(f);
                        }
                    }
                }
                cuts.sort_by(f64::total_cmp);
                sum += integrate(
                    &mut |phi: f64| {
                        let (sp, cp) = phi.sin_cos();
                        let w = c * ct + (u * cp + v * sp) * st;
                        shaping(p, -w) * n.dot(w).max(0.0)
                    },
                    &cuts,
                    inner,
                );
            }
            sum * st
        }
    };
    let mut total = DVec3::ZERO;
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        if !(b > a) {
            continue;
        }
        total += integrate(
            &mut |t: f64| {
                let th = a + (b - a) * t * t * (3.0 - 2.0 * t);
                ring(th) * (6.0 * t * (1.0 - t) * (b - a))
            },
            &[0.0, 1.0],
            outer,
        );
    }
    total
}

/// The arcs `[a, b]` of φ (a < b, within one turn) where `ω(θ, φ) = c cos θ + sin θ (u cos φ +
/// v sin φ)` lies inside every edge's half-space `g·ω ≥ 0`.
fn arcs_at(
    edges: &[(DVec3, DVec3, DVec3)],
    c: DVec3,
    u: DVec3,
    v: DVec3,
    st: f64,
    ct: f64,
) -> Vec<(f64, f64)> {
    // Start from the whole circle; each edge keeps one arc of it.
    let mut set: Option<Vec<(f64, f64)>> = None;
    for &(_, _, g) in edges {
        let a = g.dot(c) * ct;
        let (gu, gv) = (g.dot(u) * st, g.dot(v) * st);
        let r = (gu * gu + gv * gv).sqrt();
        // A + R cos(φ − φg) ≥ 0.
        let arc = if r <= a.abs() * 1e-15 || r == 0.0 {
            if a >= 0.0 {
                continue;
            }
            return Vec::new();
        } else {
            let k = -a / r;
            if k <= -1.0 {
                continue;
            }
            if k >= 1.0 {
                return Vec::new();
            }
            let d = k.acos();
            let center = gv.atan2(gu);
            (center - d, center + d)
        };
        set = Some(match set {
            None => vec![arc],
            Some(list) => intersect(&list, arc),
        });
        if set.as_ref().is_some_and(Vec::is_empty) {
            return Vec::new();
        }
    }
    set.unwrap_or_else(|| vec![(0.0, TAU)])
}

/// The intervals of `list` (within one turn of its first start) inside the arc `[s, e]`
/// (e − s < 2π), taken modulo 2π.
fn intersect(list: &[(f64, f64)], (s, e): (f64, f64)) -> Vec<(f64, f64)> {
    let base = list[0].0;
    let shift = ((s - base) / TAU).floor() * TAU;
    let (s, e) = (s - shift, e - shift);
    let mut out = Vec::new();
    for &(a, b) in list {
        for k in [-1.0, 0.0, 1.0] {
            let (s, e) = (s + k * TAU, e + k * TAU);
            let (lo, hi) = (a.max(s), b.min(e));
            if hi > lo {
                out.push((lo, hi));
            }
        }
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Light, Shaping};
    use crate::prepare::TemperatureMode;

    /// Without shaping the polar integral is Lambert's formula (closed form), to rounding, in
    /// any orientation and across the receiver's horizon.
    #[test]
    fn unshaped_is_lamberts_formula() {
        let p = Prepared::new(&Light::sphere(1.0), TemperatureMode::Spec).unwrap();
        for q in polys() {
            for n in normals() {
                let got = piece(&p, &q, n, 1e-10).x;
                let want = crate::cpu::irradiance::closed::polygon_irradiance(&q, n);
                assert!(
                    (got - want).abs() <= 1e-12 * want.max(1e-300),
                    "{got} vs {want}"
                );
                let rev: Vec<DVec3> = q.iter().rev().copied().collect();
                assert!((piece(&p, &rev, n, 1e-10).x - got).abs() <= 1e-13 * got.max(1e-300));
            }
        }
    }

    fn polys() -> Vec<Vec<DVec3>> {
        vec![
            vec![
                DVec3::new(-1.0, -1.0, -2.0),
                DVec3::new(1.0, -1.0, -2.0),
                DVec3::new(0.0, 1.0, -2.0),
            ],
            vec![
                DVec3::new(0.5, -1.0, -1.0),
                DVec3::new(2.0, -1.0, -1.0),
                DVec3::new(2.0, 1.0, -1.5),
                DVec3::new(0.5, 1.0, -1.0),
            ],
            // Around the pole c = +Z (the sphere light's −axis) and crossing the horizon of n = X.
            vec![
                DVec3::new(-1.0, -1.0, 1.0),
                DVec3::new(1.0, -1.0, 1.0),
                DVec3::new(1.0, 1.0, 1.0),
                DVec3::new(-1.0, 1.0, 1.0),
            ],
        ]
    }

    fn normals() -> Vec<DVec3> {
        vec![
            DVec3::NEG_Z,
            DVec3::new(0.5, 0.2, -1.0).normalize(),
            DVec3::X,
            DVec3::Z,
        ]
    }

    /// Against the visible module's adaptive cubature over the sphere (independent code).
    #[test]
    fn polar_integral_matches_an_adaptive_cubature() {
        let shaped = |cone: f64, soft: f64, focus: f64| {
            let l = Light::sphere(1.0).with_shaping(Shaping {
                cone_angle: cone,
                cone_softness: soft,
                focus,
                ..Shaping::default()
            });
            Prepared::new(&l, TemperatureMode::Spec).unwrap()
        };
        let mut lit = 0;
        for p in [
            shaped(40.0, 0.3, 2.0),
            shaped(70.0, 0.0, 0.0),
            shaped(180.0, 0.0, 3.0),
        ] {
            for q in &polys() {
                for n in normals() {
                    let got = piece(&p, q, n, 1e-10);
                    let want = crate::cpu::mesh::visible::integrate_piece(q, n, 1e-9, &mut |w| {
                        shaping(&p, -w)
                    });
                    let err =
                        (got - want).abs().max_element() / want.abs().max_element().max(1e-300);
                    assert!(err < 1e-7, "{got} vs {want}");
                    lit += usize::from(got.x > 0.0);
                }
            }
        }
        assert!(lit >= 10, "only {lit} lit cases");
    }
}
