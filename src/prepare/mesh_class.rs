//! Which mesh lights cannot hide any of their own emitting surface from a receiver (DESIGN.md
//! §7 M3): for those, the exact self-occluded irradiance is the sum over the triangles x sees
//! an emitting side of of Lambert's formula clipped at the horizon, with no visible-piece
//! search (`cpu::mesh::lambert`, shaders/mesh/lambert.wgsl). Decided once, when the light is
//! prepared ([`KindData::Mesh`](super::KindData::Mesh)'s `occlusion`), and read by the CPU
//! reference and the GPU decision ([`GpuPath::HostIntensityOnly`](super::GpuPath)).
//!
//! # The classes, and why the sum is exact
//! - [`MeshOcclusion::Planar`]: every vertex within [`FLAT`] × the mesh's extent of one plane,
//!   one- or double-sided, fronts in any directions, and no two triangles overlapping in that
//!   plane (each pair separated by an edge line of one of them, within [`FLAT`] × the extent:
//!   neighbours sharing an edge touch, they do not overlap). From x off the plane, a ray meets
//!   the plane once, so it meets at most one triangle: no triangle hides another, and each
//!   triangle whose emitting side faces x is wholly visible. From x in the plane every triangle
//!   is edge-on: 0 on both. Overlapping coplanar triangles are refused: the visible pieces count
//!   their overlap once (the earlier triangle is nearer, M1), the naive sum twice.
//! - [`MeshOcclusion::ConvexClosed`]: one-sided, every edge (by its end points' positions)
//!   shared by exactly two triangles running it in opposite directions, every vertex on or
//!   behind (within [`FLAT`] × the extent) every triangle's front plane, and not flat (some
//!   vertex more than [`THICK`] × the extent behind the largest triangle's plane). Then the
//!   triangles tile the boundary of the convex hull once with their fronts outward (a double
//!   cover would run some hull edge four times; an inward front would have the hull in front
//!   of it). From x outside, the triangles whose front faces x are exactly the visible
//!   emitting ones and do not overlap seen from x (a ray from outside crosses the boundary of a
//!   convex body at most twice, entering through a front-facing triangle and leaving through a
//!   back-facing one); from inside, x sees back sides only: 0 on both.
//!
//! Not classified (their irradiance stays the visible pieces'): double-sided closed meshes
//! (from outside the far triangles' back sides, which then emit, are hidden by the near ones,
//! and the sum would need an inside/outside test first), meshes with more than
//! [`MESH_TRIANGLES_SUMMED`](super::MESH_TRIANGLES_SUMMED) triangles (the checks are quadratic
//! at worst), meshes with a degenerate triangle (area below [`FLAT`] × the extent², whose
//! orientation the overlap test cannot read), and everything else (tori, L-prisms, open curved
//! patches). Shaping does not enter the class; the GPU path sums only unshaped meshes.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use crate::model::MeshTriangle;

/// A relative tolerance (of the mesh's bounding-box diagonal) under which a vertex counts as on
/// a plane and two triangles as touching, not overlapping. A planar mesh authored flat and
/// transformed in f64 is flat to ~1e-16 of its coordinates; a fold or overlap this small moves
/// the sum by about this fraction of a triangle's irradiance (the reference treats depth
/// differences below 1e-12 as ties too).
pub const FLAT: f64 = 1e-12;

/// A closed mesh thinner than this fraction of its extent is not classified convex.
pub const THICK: f64 = 1e-9;

/// Whether a mesh light's triangles can hide one another from a receiver, as far as prepare
/// proved (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshOcclusion {
    /// Not proved free of self-occlusion: the visible pieces decide.
    General,
    /// All triangles in one plane, none overlapping.
    Planar,
    /// One-sided, closed and convex, fronts outward.
    ConvexClosed,
}

impl MeshOcclusion {
    /// Whether the triangles' Lambert sum is the exact irradiance.
    pub fn free(self) -> bool {
        self != MeshOcclusion::General
    }
}

/// The class of a mesh with these triangles (world space) and sides; `General` for more than
/// `cap` triangles.
pub fn classify(triangles: &[MeshTriangle], double_sided: bool, cap: usize) -> MeshOcclusion {
    if triangles.is_empty() || triangles.len() > cap {
        return MeshOcclusion::General;
    }
    let (lo, hi) = triangles.iter().flat_map(|t| t.p).fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let extent = (hi - lo).length();
    if !(extent > 0.0) || !extent.is_finite() {
        return MeshOcclusion::General;
    }
    let tol = FLAT * extent;
    let normal = |t: &MeshTriangle| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
    // Degenerate triangles: refused (see the module's documentation).
    if triangles
        .iter()
        .any(|t| !(normal(t).length() > FLAT * extent * extent))
    {
        return MeshOcclusion::General;
    }
    let largest = triangles
        .iter()
        .max_by(|a, b| normal(a).length().total_cmp(&normal(b).length()))
        .expect("not empty");
    let n0 = normal(largest).normalize();
    let p0 = largest.p[0];
    let heights = triangles.iter().flat_map(|t| t.p).map(|v| n0.dot(v - p0));
    let (hmin, hmax) = heights.fold((0.0f64, 0.0f64), |(a, b), h| (a.min(h), b.max(h)));
    if hmin >= -tol && hmax <= tol {
        return if planar_disjoint(triangles, n0, 0.5 * (lo + hi), tol) {
            MeshOcclusion::Planar
        } else {
            MeshOcclusion::General
        };
    }
    if double_sided || !(hmin < -THICK * extent) || !closed(triangles) {
        return MeshOcclusion::General;
    }
    let mut vertices: Vec<DVec3> = triangles.iter().flat_map(|t| t.p).collect();
    vertices.sort_by(|a, b| {
        a.to_array()
            .iter()
            .zip(b.to_array().iter())
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    vertices.dedup();
    let convex = triangles.iter().all(|t| {
        let n = normal(t).normalize();
        vertices.iter().all(|v| n.dot(*v - t.p[0]) <= tol)
    });
    if convex {
        MeshOcclusion::ConvexClosed
    } else {
        MeshOcclusion::General
    }
}

/// Every edge, by its end points' positions, run once in each direction by the triangles.
fn closed(triangles: &[MeshTriangle]) -> bool {
    let key = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut edges: HashMap<([u64; 3], [u64; 3]), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *edges
                .entry((key(t.p[k]), key(t.p[(k + 1) % 3])))
                .or_insert(0) += 1;
        }
    }
    edges
        .iter()
        .all(|(&(a, b), &count)| count == 1 && edges.get(&(b, a)) == Some(&1))
}

/// Whether no two of the triangles (all in the plane ⟂ `n` through about `o`) overlap: each
/// pair whose boxes meet is separated by an edge line of one of them, within `tol`.
fn planar_disjoint(triangles: &[MeshTriangle], n: DVec3, o: DVec3, tol: f64) -> bool {
    let (a, b) = n.any_orthonormal_pair();
    struct Flat {
        v: [DVec2; 3],
        /// +1 counter-clockwise, −1 clockwise.
        s: f64,
        lo: DVec2,
        hi: DVec2,
    }
    let mut flat: Vec<Flat> = triangles
        .iter()
        .map(|t| {
            let v = t.p.map(|p| DVec2::new((p - o).dot(a), (p - o).dot(b)));
            let s = (v[1] - v[0]).perp_dot(v[2] - v[0]).signum();
            Flat {
                v,
                s,
                lo: v[0].min(v[1]).min(v[2]),
                hi: v[0].max(v[1]).max(v[2]),
            }
        })
        .collect();
    // Separated when every vertex of `q` is within `tol` of the outside of an edge of `p`.
    let separates = |p: &Flat, q: &Flat| {
        (0..3).any(|k| {
            let (e0, e1) = (p.v[k], p.v[(k + 1) % 3]);
            let d = e1 - e0;
            let len = d.length();
            q.v.iter().all(|w| p.s * d.perp_dot(*w - e0) <= tol * len)
        })
    };
    flat.sort_by(|p, q| p.lo.x.total_cmp(&q.lo.x));
    for i in 0..flat.len() {
        for j in i + 1..flat.len() {
            let (p, q) = (&flat[i], &flat[j]);
            if q.lo.x > p.hi.x + tol {
                break;
            }
            if q.lo.y > p.hi.y + tol || p.lo.y > q.hi.y + tol {
                continue;
            }
            if !separates(p, q) && !separates(q, p) {
                return false;
            }
        }
    }
    true
}
