//! Mesh lights (MeshLightAPI, DESIGN.md §7) on the CPU reference, in f64.
//!
//! - [`lambert`]: the irradiance of a mesh whose triangles cannot hide one another (prepare's
//!   `MeshOcclusion`): Lambert's formula summed over the triangles, no visible-piece search.
//! - [`ray`]: the first triangle a ray meets, through the prepared hierarchy (M3 `radiance`).
//! - [`sample`]: directions drawn by area, with the density summed over every triangle crossed.
//! - [`shaped`]: a shaped mesh light's irradiance over one visible piece, in polar coordinates
//!   about its primary axis.
//! - [`visible`]: the parts of a mesh's triangles seen from a point (gnomonic charts) or from a
//!   direction at infinity (orthographic), with the mesh's self-occlusion, exactly: what M3's
//!   irradiance and intensity integrate.
//!
//! Emission leaves a triangle from its front (`(p1 − p0) × (p2 − p0)`, already oriented for
//! `orientation` and a mirroring transform by the model), from both sides when `doubleSided`;
//! every triangle occludes the mesh's own light from either side (M2, M3).

pub(crate) mod lambert;
pub(crate) mod ray;
pub mod sample;
pub(crate) mod shaped;
pub(crate) mod visible;

use glam::DVec3;

use super::shaping::shaping;
use crate::model::{LightType, MeshTriangle};
use crate::prepare::mesh_bvh::MeshBvh;
use crate::prepare::{KindData, MeshOcclusion, Prepared};

/// What a prepared mesh light carries, read together: its model's triangles and sides and its
/// prepared hierarchy, front directions and running area sum.
pub(crate) struct MeshParts<'a> {
    pub triangles: &'a [MeshTriangle],
    pub double_sided: bool,
    pub bvh: &'a MeshBvh,
    pub fronts: &'a [DVec3],
    pub cumulative_area: &'a [f64],
    pub occlusion: MeshOcclusion,
}

/// A prepared mesh light's [`MeshParts`]; `None` for other lights.
pub(crate) fn parts(p: &Prepared) -> Option<MeshParts<'_>> {
    match (&p.light.kind, &p.kind) {
        (
            LightType::Mesh {
                geometry,
                double_sided,
                ..
            },
            KindData::Mesh {
                bvh,
                fronts,
                cumulative_area,
                occlusion,
                ..
            },
        ) => Some(MeshParts {
            occlusion: *occlusion,
            triangles: &geometry.triangles,
            double_sided: *double_sided,
            bvh,
            fronts,
            cumulative_area,
        }),
        _ => None,
    }
}

/// M3 `emission(ω)`: `L(ω)` where some triangle emits along the unit direction `e`
/// (`n·e > 0`, or `≠ 0` when double-sided), else 0.
pub fn emission(p: &Prepared, e: DVec3) -> DVec3 {
    let Some(m) = parts(p) else {
        return DVec3::ZERO;
    };
    let emits = m.fronts.iter().any(|n| {
        let c = n.dot(e);
        c > 0.0 || (m.double_sided && c != 0.0)
    });
    if emits {
        p.base * shaping(p, e)
    } else {
        DVec3::ZERO
    }
}

/// M3 `radiance(x, ω)`: where the ray `x + tω`, t > 0, first meets the mesh on an emitting side,
/// the emission back along −ω; 0 where it meets a non-emitting side (the mesh is opaque to its
/// own light) or nothing.
pub fn radiance(p: &Prepared, x: DVec3, w: DVec3) -> DVec3 {
    let Some(m) = parts(p) else {
        return DVec3::ZERO;
    };
    match ray::first_hit(m.bvh, x, w) {
        Some(h) if h.front || m.double_sided => p.base * shaping(p, -w),
        _ => DVec3::ZERO,
    }
}

/// The emitting area visible from the unit direction `e` at infinity, projected on the plane
/// ⟂ e, self-occlusion included: M3 `intensity(e) = L(e) · projected_area(e)`.
pub fn projected_area(p: &Prepared, e: DVec3) -> f64 {
    let Some(m) = parts(p) else {
        return 0.0;
    };
    visible::Surface {
        triangles: m.triangles,
        double_sided: m.double_sided,
    }
    .projected_area(e)
}

/// M3 `irradiance(x, n)` before `diffuse`, to relative tolerance `rel` where shaped: unshaped, `L`
/// times the cosine-weighted solid angle of the visible emitting pieces, each by Lambert's
/// formula clipped at the horizon (exact; where the triangles cannot hide one another, the
/// same sum over whole triangles, [`lambert`]); shaped, the shaping of the emission direction `−ω`
/// integrated over the same pieces.
pub fn irradiance(p: &Prepared, x: DVec3, n: DVec3, rel: f64) -> DVec3 {
    let Some(m) = parts(p) else {
        return DVec3::ZERO;
    };
    let surface = visible::Surface {
        triangles: m.triangles,
        double_sided: m.double_sided,
    };
    if p.shaping.is_none() {
        if m.occlusion.free() {
            return p.base * lambert::mesh_lambert(m.triangles, m.double_sided, x, n);
        }
        return p.base * surface.cosine_solid_angle(x, n);
    }
    let mut sum = DVec3::ZERO;
    for piece in surface.emitting_above(x, n) {
        sum += shaped::piece(p, &piece.verts, n, rel);
    }
    p.base * sum
}
