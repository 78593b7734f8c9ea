//! A dome masked by its portals (DESIGN.md §8 P2, mask mode) on the CPU (f64). No WGSL twin: a
//! masked dome is evaluated on the host on every device (`GpuPath::Host`).
//!
//! - `radiance(x, ω)`: the dome's radiance along ω ⊙ the multiplier of the nearest portal the
//!   ray `x + tω`, t > 0, passes through moving toward the portal's +Z (against the light it
//!   transmits); crossings toward −Z are ignored (portals are not opaque); none → 0.
//! - `irradiance(x, n)`: x sees the dome through the portals whose −Z side it is on (only those
//!   are crossed toward +Z, a portal being planar). Their visible parts seen from x, nearest
//!   first and overlaps counted once for the nearer ([`Surface::visible_from`] on two triangles
//!   a portal, ties to the earlier portal in the `portals` relationship), are convex planar
//!   polygons. An untextured dome is uniform, so each piece is `L ⊙ multiplier` times Lambert's
//!   formula clipped at the horizon ([`polygon_irradiance`]): exact. A textured dome's radiance
//!   is integrated over each piece adaptively ([`integrate_piece`]) to the query's tolerance,
//!   not split at texel lines as §6 "what exact means" asks: see docs/PORTALS.md.

use glam::DVec3;

use super::emission::emission;
use super::irradiance::closed::polygon_irradiance;
use super::mesh::visible::{Surface, integrate_piece};
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

/// irradiance at x for receiver normal n of a masked dome, before `diffuse`: exact for an
/// untextured dome, to relative tolerance `rel` for a textured one (see the module docs).
pub fn irradiance(p: &Prepared, portals: &[PreparedPortal], x: DVec3, n: DVec3, rel: f64) -> DVec3 {
    let (triangles, owner) = seen_from(portals, x);
    if triangles.is_empty() {
        return DVec3::ZERO;
    }
    // Double-sided: every piece seen passes light (the portals behind x were left out above).
    let surface = Surface {
        triangles: &triangles,
        double_sided: true,
    };
    let textured = p.dome_texture().is_some();
    let mut sum = DVec3::ZERO;
    for piece in surface.visible_from(x) {
        let m = portals[owner[piece.triangle as usize]].multiplier;
        if textured {
            let e = integrate_piece(&piece.verts, n, rel, &mut |w: DVec3| emission(p, w));
            sum += m * e;
        } else {
            sum += m * polygon_irradiance(&piece.verts, n);
        }
    }
    if textured { sum } else { p.base * sum }
}
