//! The irradiance of a dome masked by portals (DESIGN.md §8 P2 mask mode) where the device sums
//! it ([`overlaps`]): twin of `shaders/irradiance/portals.wgsl`, the device's form of
//! [`crate::cpu::portal::irradiance`] for such domes (uniform, or textured latlong under a
//! conformal frame: the same sum with the texture's integral over each polygon,
//! [`polygon_texture`]).
//!
//! Why the sum is exact: the dome's radiance along ω is `L(ω)` (`base`, or `base` times the
//! filtered texture), and x receives it along the rays that pass through a portal toward its +Z, that is through a portal whose −Z
//! side x is on (every ray from there through the portal crosses it toward +Z), times the
//! multiplier of the nearest such portal. Where no ray crosses two portals
//! ([`crossing_orders`] says when, for each pair), those directions are the disjoint
//! union of the portals seen from x, each with its own multiplier. Where rays may cross
//! several, let T be the set of portals seen from x that the ray along ω crosses, and
//! `first(T)` the nearest. The weights `c(S) = (−1)^{|S|+1} m_{last(S)}` (`last(S)`: the
//! farthest member along a ray through all of S) satisfy `Σ_{∅≠S⊆T} c(S) = m_{first(T)}` for
//! every T: with T = {t₁, …, t_k} nearest first, the sets whose last member is t_j are {t_j} ∪ R
//! for R ⊆ {t₁, …, t_{j−1}}, and `Σ_R (−1)^{|R|}` is 1 for j = 1 and 0 otherwise. So
//! `E = Σ_S c(S) ∫_{∩S} L(ω) n·ω dω` over the nonempty sets S of portals seen from x. A set with two
//! members no ray crosses together meets in measure zero, so the sum runs over the portals and
//! the cliques of the "crossable" graph that [`overlaps`] lists. Where one member is the
//! farthest among those of other multipliers on every ray through the set, the set names it
//! first and its multiplier is the term's. Otherwise (portals of different multipliers crossed
//! in either order) the set is split: the directions through all of S are partitioned by which
//! member `l` is the farthest, and the term is `Σ_l m_l ∫` over l's piece. Along ω the ray
//! meets portal z's plane at `t_z = d_z / (N_z·ω)`, `d_z = N_z·(O_z − x) > 0` (x on its −Z
//! side) and `N_z·ω > 0` (crossed toward +Z), so z comes before l exactly where
//! `(d_l N_z − d_z N_l)·ω > 0` ([`farther_plane`]): l's piece is the set's polygon clipped by
//! that plane through x for each other member z, a convex polygon again. A pair crossed in one
//! order only needs no plane (coplanar portals, whose plane is 0, are such pairs): l's piece is
//! empty if some member always lies after it, and z's clip is dropped if it always lies before.
//! Each intersection, seen from x, is the first portal's parallelogram clipped by the planes
//! through x and the other portals' edges (a convex polygon: convex sets' intersection), and
//! the irradiance of a uniform convex polygon clipped at the receiver's horizon is Lambert's
//! formula ([`polygon_irradiance`]: Lambert 1760; Arvo 1995); a textured latlong dome's is
//! the exact row integral over the polygon ([`latlong_polygon`]). `crate::cpu::portal::irradiance`,
//! which cuts the portals into their visible pieces nearest first for any set, is this sum's
//! independent check (`tests::the_inclusion_exclusion_sum_is_the_visible_pieces_where_portals_overlap`,
//! and for textured domes `tests::textured::textured_sum_is_the_visible_pieces`).
//!
//! [`crossing_orders`]: crate::prepare::portal::crossing_orders
//! [`overlaps`]: crate::prepare::portal::overlaps

use glam::{DMat3, DVec3};

use super::closed::{clip_above, polygon_irradiance};
use super::latlong_polygon::latlong_polygon;
use super::latlong_rows::Rows;
use crate::prepare::PreparedPortal;
use crate::prepare::portal::Overlap;

/// A textured latlong dome under a conformal frame, as the device integrates it through its
/// portals: its row tables and its world → dome map `A_eff⁻¹` (`latlong_rows` module docs).
pub struct TexturedDome<'a> {
    pub rows: Rows<'a>,
    pub inv: DMat3,
}

/// `Σ multiplier · E(portal clipped at n·ω ≥ 0)` over the portals whose −Z side x is on,
/// and `(−1)^{|S|+1} multiplier · E(∩S clipped)` over the `overlaps` S
/// (`Prepared::portal_overlaps`) whose every member x is on the −Z side of, a split one's
/// pieces each with its member's multiplier ([`split_piece`]); unit-radiance dome, before
/// `base` and `diffuse`. E is Lambert's formula for a uniform dome (`dome` None) and the
/// texture's exact integral over the polygon for a textured one ([`polygon_value`]). Every
/// term's polygons go through one call of [`polygon_value`], as on the device (where each
/// call site is a copy of the texture's integral after inlining).
pub fn portals_irradiance(
    portals: &[PreparedPortal],
    overlaps: &[Overlap],
    x: DVec3,
    n: DVec3,
    dome: Option<&TexturedDome>,
) -> DVec3 {
    let seen = |q: &PreparedPortal| q.normal.dot(x - q.origin) < 0.0;
    let mut sum = DVec3::ZERO;
    for t in 0..portals.len() + overlaps.len() {
        // The term's polygon, sign and multiplier, and for a split overlap its pieces.
        let (poly, sign, m, set) = match portals.get(t) {
            Some(q) => {
                if !seen(q) {
                    continue;
                }
                (q.corners.map(|c| c - x).to_vec(), 1.0, q.multiplier, None)
            }
            None => {
                let set = &overlaps[t - portals.len()];
                if !set.members.iter().all(|&k| seen(&portals[k as usize])) {
                    continue;
                }
                let poly = overlap_polygon(portals, &set.members, x);
                if poly.len() < 3 {
                    continue;
                }
                let sign = if set.members.len().is_multiple_of(2) {
                    -1.0
                } else {
                    1.0
                };
                let m = portals[set.members[0] as usize].multiplier;
                (poly, sign, m, Some(set))
            }
        };
        let pieces = match set {
            Some(s @ Overlap { split: Some(_), .. }) => s.members.len(),
            _ => 1,
        };
        for l in 0..pieces {
            let (piece, m) = match set {
                Some(s) if pieces > 1 => (
                    split_piece(portals, s, &poly, l, x),
                    portals[s.members[l] as usize].multiplier,
                ),
                _ => (poly.clone(), m),
            };
            if piece.len() >= 3 {
                sum += sign * m * polygon_value(&piece, n, dome);
            }
        }
    }
    sum
}

/// What x sees through every portal of `members`: the first one's parallelogram (vectors
/// from x) clipped to the cones from x over the others ([`clip_to_cone`]; fewer than 3
/// vertices where nothing).
pub fn overlap_polygon(portals: &[PreparedPortal], members: &[u32], x: DVec3) -> Vec<DVec3> {
    let mut poly: Vec<DVec3> = portals[members[0] as usize].corners.map(|c| c - x).to_vec();
    for &k in &members[1..] {
        poly = clip_to_cone(&poly, &portals[k as usize].corners.map(|c| c - x));
        if poly.len() < 3 {
            return poly;
        }
    }
    poly
}

/// The piece of the split overlap `set`'s polygon `poly` where its member `l` (a position in
/// `members`) is the farthest: clipped by [`farther_plane`] against each other member that
/// rays cross in either order with it; empty where some member always lies after it
/// ([`Overlap::split`]'s bits).
pub fn split_piece(
    portals: &[PreparedPortal],
    set: &Overlap,
    poly: &[DVec3],
    l: usize,
    x: DVec3,
) -> Vec<DVec3> {
    let before = set.split.unwrap_or(0);
    let ql = &portals[set.members[l] as usize];
    let mut piece = poly.to_vec();
    for (z, &mz) in set.members.iter().enumerate() {
        if z == l || before >> (4 * z + l) & 1 == 1 {
            continue;
        }
        if before >> (4 * l + z) & 1 == 1 {
            return Vec::new();
        }
        piece = clip_above(&piece, farther_plane(ql, &portals[mz as usize], x));
    }
    piece
}

/// The normal of the plane through x on whose positive side a ray crosses `z` before `l`
/// (both toward +Z, x on both −Z sides): `d_l N_z − d_z N_l` with `d = N·(O − x)` (module docs).
pub fn farther_plane(l: &PreparedPortal, z: &PreparedPortal, x: DVec3) -> DVec3 {
    let d = |q: &PreparedPortal| q.normal.dot(q.origin - x);
    d(l) * z.normal - d(z) * l.normal
}

/// E on the convex polygon `poly` (vectors from x): 0 where no vertex is above the horizon,
/// else a fan of Lambert's triangles from its first vertex (the device's form; the fan's inner
/// edges cancel) or the texture's integral ([`polygon_texture`]).
pub fn polygon_value(poly: &[DVec3], n: DVec3, dome: Option<&TexturedDome>) -> DVec3 {
    if poly.iter().all(|v| !(n.dot(*v) > 0.0)) {
        return DVec3::ZERO;
    }
    if let Some(d) = dome {
        return polygon_texture(poly, n, d);
    }
    DVec3::splat(
        (1..poly.len() - 1)
            .map(|i| polygon_irradiance(&[poly[0], poly[i], poly[i + 1]], n))
            .sum(),
    )
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

/// The texture's integral over the convex polygon `poly` (vectors from x) clipped at the
/// horizon `n·ω ≥ 0` and mapped to dome space ([`latlong_polygon`]; the frame is conformal,
/// so the dome-space polygon is the image of the world one and the normal `A_eff⁻¹ n`
/// normalised, as `latlong_rows` maps it).
pub fn polygon_texture(poly: &[DVec3], n: DVec3, dome: &TexturedDome) -> DVec3 {
    let clipped: Vec<DVec3> = clip_above(poly, n)
        .into_iter()
        .map(|v| dome.inv * v)
        .collect();
    if clipped.len() < 3 {
        return DVec3::ZERO;
    }
    latlong_polygon(&dome.rows, &clipped, (dome.inv * n).normalize())
}

#[cfg(test)]
mod tests;
