//! The irradiance of an untextured dome masked by portals (DESIGN.md §8 P2 mask mode) where the
//! device sums it ([`overlaps`]): twin of `shaders/irradiance/portals.wgsl`, the device's form
//! of [`crate::cpu::portal::irradiance`] for such domes.
//!
//! Why the sum is exact: the dome's radiance is `base` along every direction, and x receives it
//! along the rays that pass through a portal toward its +Z, that is through a portal whose −Z
//! side x is on (every ray from there through the portal crosses it toward +Z), times the
//! multiplier of the nearest such portal. Where no ray crosses two portals
//! ([`crossing_orders`] says when, for each pair), those directions are the disjoint
//! union of the portals seen from x, each with its own multiplier. Where rays may cross
//! several, let T be the set of portals seen from x that the ray along ω crosses, and
//! `first(T)` the nearest. The weights `c(S) = (−1)^{|S|+1} m_{last(S)}` (`last(S)`: the
//! farthest member along a ray through all of S) satisfy `Σ_{∅≠S⊆T} c(S) = m_{first(T)}` for
//! every T: with T = {t₁, …, t_k} nearest first, the sets whose last member is t_j are {t_j} ∪ R
//! for R ⊆ {t₁, …, t_{j−1}}, and `Σ_R (−1)^{|R|}` is 1 for j = 1 and 0 otherwise. So
//! `E = Σ_S c(S) ∫_{∩S} n·ω dω` over the nonempty sets S of portals seen from x. A set with two
//! members no ray crosses together meets in measure zero, so the sum runs over the portals and
//! the cliques of the "crossable" graph that [`overlaps`] lists, each with the multiplier of
//! the member it names first; that member's multiplier is the same on every ray through the
//! set because [`overlaps`] refuses pairs of different multipliers crossed in either order.
//! Each intersection, seen from x, is the first portal's parallelogram clipped by the planes
//! through x and the other portals' edges (a convex polygon: convex sets' intersection), and
//! the irradiance of a uniform convex polygon clipped at the receiver's horizon is Lambert's
//! formula ([`polygon_irradiance`]: Lambert 1760; Arvo 1995). `crate::cpu::portal::irradiance`,
//! which cuts the portals into their visible pieces nearest first for any set, is this sum's
//! independent check (`tests::the_inclusion_exclusion_sum_is_the_visible_pieces_where_portals_overlap`).
//!
//! [`crossing_orders`]: crate::prepare::portal::crossing_orders
//! [`overlaps`]: crate::prepare::portal::overlaps

use glam::DVec3;

use super::closed::{clip_above, polygon_irradiance};
use crate::prepare::PreparedPortal;

/// `Σ multiplier · Lambert(portal clipped at n·ω ≥ 0)` over the portals whose −Z side x is on,
/// and `(−1)^{|S|+1} multiplier(S's first member) · Lambert(∩S clipped)` over the `overlaps` S
/// (`Prepared::portal_overlaps`) whose every member x is on the −Z side of (unit-radiance dome,
/// before `base` and `diffuse`).
pub fn portals_lambert(
    portals: &[PreparedPortal],
    overlaps: &[Vec<u32>],
    x: DVec3,
    n: DVec3,
) -> DVec3 {
    let seen = |q: &PreparedPortal| q.normal.dot(x - q.origin) < 0.0;
    let mut sum = DVec3::ZERO;
    for q in portals {
        if !seen(q) {
            continue;
        }
        let v = q.corners.map(|c| c - x);
        if v.iter().all(|v| !(n.dot(*v) > 0.0)) {
            continue;
        }
        sum += q.multiplier * polygon_irradiance(&v, n);
    }
    for set in overlaps {
        if !set.iter().all(|&k| seen(&portals[k as usize])) {
            continue;
        }
        let sign = if set.len() % 2 == 0 { -1.0 } else { 1.0 };
        sum += sign * portals[set[0] as usize].multiplier * overlap_lambert(portals, set, x, n);
    }
    sum
}

/// Lambert's formula (clipped at n·ω ≥ 0) on what x sees through every portal of `set`: the
/// first one's parallelogram (vectors from x) clipped to the cones from x over the others
/// ([`clip_to_cone`]), as a fan of triangles from its first vertex (the device's form; the
/// fan's inner edges cancel).
pub fn overlap_lambert(portals: &[PreparedPortal], set: &[u32], x: DVec3, n: DVec3) -> f64 {
    let mut poly: Vec<DVec3> = portals[set[0] as usize].corners.map(|c| c - x).to_vec();
    for &k in &set[1..] {
        poly = clip_to_cone(&poly, &portals[k as usize].corners.map(|c| c - x));
        if poly.len() < 3 {
            return 0.0;
        }
    }
    if poly.iter().all(|v| !(n.dot(*v) > 0.0)) {
        return 0.0;
    }
    (1..poly.len() - 1)
        .map(|i| polygon_irradiance(&[poly[0], poly[i], poly[i + 1]], n))
        .sum()
}

/// The part of the convex polygon `poly` (vectors from x) inside the cone from x over the
/// convex quadrilateral `cone` (vectors from x): clipped to `k·v ≥ 0` for each edge's plane
/// through x, k oriented toward the quadrilateral's other corners (`clip_above`'s
/// Sutherland–Hodgman step with k for the normal).
pub fn clip_to_cone(poly: &[DVec3], cone: &[DVec3; 4]) -> Vec<DVec3> {
    (0..4).fold(poly.to_vec(), |cur, e| {
        let (a, b, c) = (cone[e], cone[(e + 1) % 4], cone[(e + 2) % 4]);
        let k = a.cross(b);
        clip_above(&cur, if k.dot(c) < 0.0 { -k } else { k })
    })
}

#[cfg(test)]
mod tests;
