//! Sampling a mesh light (DESIGN.md §9 S2: "other shapes by their geometry"): a triangle chosen
//! with probability proportional to its area, a point uniform on it (Turk 1990, "Generating
//! random points in triangles": barycentrics `(1 − √u₀, √u₀ (1 − u₁), √u₀ u₁)`), the direction
//! toward it. A direction ω is drawn through every triangle it crosses, so its density per unit
//! solid angle is the sum over all of them of the area density `1/A` carried to solid angle by
//! `t²/|cos θ|` (pbrt-v4 §12.2.3, the area-to-solid-angle Jacobian):
//!
//! `pdf(ω) = Σ_{triangles j the ray x + tω, t > 0, meets} t_j² / (A |n̂_j·ω|)`,
//!
//! and its radiance is the first hit's (`cpu::mesh::radiance`), so occluded and back-facing
//! draws carry what the receiver actually sees. Unbiased: every direction that reaches an emitting
//! side is drawn with positive density.

use glam::DVec3;

use super::ray;
use crate::model::MeshTriangle;
use crate::prepare::Prepared;
use crate::prepare::mesh_bvh::MeshBvh;

/// A prepared mesh light's triangles, hierarchy and running area sum ([`super::parts`]);
/// `None` for other lights and for a mesh without area.
pub fn parts(p: &Prepared) -> Option<(&[MeshTriangle], &MeshBvh, &[f64])> {
    let m = super::parts(p)?;
    m.cumulative_area
        .last()
        .is_some_and(|a| *a > 0.0)
        .then_some((m.triangles, m.bvh, m.cumulative_area))
}

/// A direction from `x` toward a point drawn by area for `u` (u[0], u[1] the point, u[2] the
/// triangle, with 53 bits), and its density; `None` where the drawn point is x itself.
pub fn sample(p: &Prepared, x: DVec3, u: [f64; 3]) -> Option<(DVec3, f64)> {
    let (triangles, bvh, cum) = parts(p)?;
    let total = *cum.last()?;
    // The first triangle whose running sum exceeds u·A (never one of zero area).
    let target = u[2] * total;
    let k = cum.partition_point(|&c| c <= target).min(cum.len() - 1);
    let t = &triangles[k];
    let s = u[0].sqrt();
    let y = t.p[0] * (1.0 - s) + t.p[1] * (s * (1.0 - u[1])) + t.p[2] * (s * u[1]);
    let w = y - x;
    let d = w.length();
    if !(d > 0.0) {
        return None;
    }
    let dir = w / d;
    // The drawn triangle's own term, also where rounding puts the ray just outside it.
    let mut own = false;
    let mut sum = 0.0;
    ray::all_hits(bvh, x, dir, |j, tj| {
        sum += term(&triangles[j as usize], dir, tj, total);
        own |= j as usize == k;
    });
    if !own {
        sum += term(t, dir, d, total);
    }
    Some((dir, sum))
}

/// The density [`sample`] draws the unit direction `w` with.
pub fn pdf(p: &Prepared, x: DVec3, w: DVec3) -> f64 {
    let Some((triangles, bvh, cum)) = parts(p) else {
        return 0.0;
    };
    let total = cum[cum.len() - 1];
    let mut sum = 0.0;
    ray::all_hits(bvh, x, w, |j, t| {
        sum += term(&triangles[j as usize], w, t, total);
    });
    sum
}

/// One triangle's share of the density: `t² / (A_total |n̂·ω|)`.
fn term(t: &MeshTriangle, w: DVec3, dist: f64, total: f64) -> f64 {
    let n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
    let cos = (n.dot(w) / n.length()).abs();
    if cos > 0.0 {
        dist * dist / (total * cos)
    } else {
        0.0
    }
}
