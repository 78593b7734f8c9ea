//! A dome masked by its portals (DESIGN.md §8 P2, mask mode) on the CPU (f64). Twin of
//! `shaders/portal.wgsl` (`crossing`); the irradiance kernel sums Lambert's formula (an
//! untextured dome) or a latlong texture's row integral over the portals and, by
//! inclusion–exclusion, their overlaps (`irradiance/portals.rs`, checked against
//! [`irradiance`]; `prepare::portal::overlaps` and `prepare::gpu_path::masked` say where);
//! every other masked dome's irradiance is this module's on the GPU path too
//! (`GpuPath::HostIrradiance`).
//!
//! - `radiance(x, ω)`: the dome's radiance along ω ⊙ the multiplier of the nearest portal the
//!   ray `x + tω`, t > 0, passes through moving toward the portal's +Z (against the light it
//!   transmits); crossings toward −Z are ignored (portals are not opaque); none → 0.
//! - `irradiance(x, n)`: x sees the dome through the portals whose −Z side it is on (only those
//!   are crossed toward +Z, a portal being planar). Their visible parts seen from x, nearest
//!   first and overlaps counted once for the nearer ([`Surface::emitting_above`] on two triangles
//!   a portal, ties to the earlier portal in the `portals` relationship), are convex planar
//!   polygons. An untextured dome is uniform, so each piece is `L ⊙ multiplier` times Lambert's
//!   formula clipped at the horizon ([`polygon_irradiance`]): exact. A textured dome's is exact
//!   too, in the sense of §6 "what 'exact' means" as P2 asks: a convex polygon seen from x is
//!   the intersection of the half-spaces `k·ω ≥ 0` through x and its edges, and the dome's
//!   exact texel integral, which clips the filtered texture's polynomial pieces at the horizon,
//!   clips them at those half-spaces as well
//!   ([`DomeIrradiance::irradiance_over_polygon`](super::irradiance::dome::DomeIrradiance::irradiance_over_polygon)):
//!   pieces inside all of them add their precomputed moment, pieces outside one are skipped,
//!   the rest are integrated between the clip circles' crossings. No query tolerance enters.
//!   Proofs: `exact_tests.rs` (a closed box of portals gives the unmasked dome, a constant
//!   texture gives Lambert, both to ≤ 1e-9; a brute force over the portals' planes).

use glam::DVec3;

use super::emission::emission;
use super::irradiance::closed::polygon_irradiance;
use super::irradiance::dome;
use super::mesh::visible::Surface;
use crate::model::MeshTriangle;
use crate::prepare::{Prepared, PreparedPortal};

/// The multiplier of the portal the ray `x + tω` (t > 0) passes through toward its +Z, nearest
/// first (ties to the earlier portal); `None` when it passes through none. Edges are inclusive,
/// as a rect light's are (`shapes::rect_hit`).
pub fn crossing(portals: &[PreparedPortal], x: DVec3, w: DVec3) -> Option<DVec3> {
    let mut best: Option<(f64, DVec3)> = None;
    for q in portals {
        let toward = q.normal.dot(w);
        let side = q.normal.dot(x - q.origin);
        // Moving toward +Z (toward > 0) from the −Z side (side < 0): t > 0.
        if !(toward > 0.0 && side < 0.0) {
            continue;
        }
        let t = -side / toward;
        let h = q.to_local * (x + t * w - q.origin);
        let inside = h.x.abs() <= q.half.x && h.y.abs() <= q.half.y;
        if inside && best.is_none_or(|(tb, _)| t < tb) {
            best = Some((t, q.multiplier));
        }
    }
    best.map(|(_, m)| m)
}

/// radiance at x from the unit direction w of a masked dome (`p.portals` is `Some`).
pub fn radiance(p: &Prepared, portals: &[PreparedPortal], x: DVec3, w: DVec3) -> DVec3 {
    match crossing(portals, x, w) {
        Some(m) => emission(p, w) * m,
        None => DVec3::ZERO,
    }
}

/// The portals x can see the dome through (those whose −Z side it is on), as triangles for
/// [`Surface`] (two a portal, `face` = the portal's index in `portals`), and the portal of each
/// triangle.
fn seen_from(portals: &[PreparedPortal], x: DVec3) -> (Vec<MeshTriangle>, Vec<usize>) {
    let mut triangles = Vec::new();
    let mut owner = Vec::new();
    for (k, q) in portals.iter().enumerate() {
        if !(q.normal.dot(x - q.origin) < 0.0) {
            continue;
        }
        let c = q.corners;
        for tri in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
            triangles.push(MeshTriangle {
                p: tri,
                face: k as u32,
            });
            owner.push(k);
        }
    }
    (triangles, owner)
}

/// irradiance at x for receiver normal n of a masked dome, before `diffuse`: exact for every
/// dome (see the module docs).
pub fn irradiance(p: &Prepared, portals: &[PreparedPortal], x: DVec3, n: DVec3) -> DVec3 {
    let (triangles, owner) = seen_from(portals, x);
    if triangles.is_empty() {
        return DVec3::ZERO;
    }
    // Double-sided: every piece seen passes light (the portals behind x were left out above).
    let surface = Surface {
        triangles: &triangles,
        double_sided: true,
    };
    let tables = match p.dome_texture() {
        Some(_) => match dome::tables(p) {
            Some(t) => Some(t),
            // As the unmasked dome: a texture with no tables (a bad cross) has no value.
            None => return DVec3::NAN,
        },
        None => None,
    };
    let mut sum = DVec3::ZERO;
    // Portals wholly below the receiver's horizon neither pass light it receives nor hide any.
    for piece in surface.emitting_above(x, n) {
        let m = portals[owner[piece.triangle as usize]].multiplier;
        sum += m * match &tables {
            // The filtered texture's exact integral over the piece's spherical polygon clipped
            // at the horizon (DESIGN.md §8 P2, §6 "what 'exact' means").
            Some(t) => t.irradiance_over_polygon(n, &piece.verts),
            None => DVec3::splat(polygon_irradiance(&piece.verts, n)),
        };
    }
    p.base * sum
}

#[cfg(test)]
mod exact_tests;

#[cfg(test)]
mod tests;
