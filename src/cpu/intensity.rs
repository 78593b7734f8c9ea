//! intensity(light, ω) on the CPU (f64). Twin of `shaders/intensity.wgsl`.
//!
//! DESIGN.md §3: the far-field RGB intensity `∫ L cos dA` over the light's emitting surface
//! along ω (cd for L in nits). Along a far-field direction every surface point emits along the
//! same e = ω, so `I(ω) = L(ω) · A⊥(ω)` with `A⊥(ω) = ∫ max(0, n·ω) dA` the surface's
//! projected area (one side of a rect or disk, the whole sphere, the cylinder's side).
//! Under the light's linear map M the area elements transform by the cofactor, so
//! `A⊥(ω) = |det M| · A⊥_local(M⁻¹ω)` with the local shape's projected area along the
//! (unnormalised) vector M⁻¹ω: rect `w·h·max(0, −v_z)`, disk `πr²·max(0, −v_z)`, sphere
//! `πr²·|v|`, cylinder side `2·length·r·|v_yz|`. `treatAsPoint`/`treatAsLine` lights have the
//! full-size light's intensity (DESIGN.md §2 "Edge cases"). Distant and dome lights are at
//! infinity and have no finite intensity: 0.

use glam::DVec3;
use std::f64::consts::PI;

use super::emission::emission;
use crate::model::LightType;
use crate::prepare::Prepared;

/// `A⊥(e)`: the emitting surface's projected area along unit direction `e` (world units²).
pub fn projected_area(p: &Prepared, e: DVec3) -> f64 {
    if matches!(p.light.kind, LightType::Mesh { .. }) {
        // DESIGN.md §7 M3: the visible emitting surface, self-occlusion included.
        return super::mesh::projected_area(p, e);
    }
    let v = p.to_local * e;
    let local = match p.light.kind {
        LightType::Rect { width, height } => width * height * (-v.z).max(0.0),
        LightType::Disk { radius } => PI * radius * radius * (-v.z).max(0.0),
        LightType::Sphere { radius, .. } => PI * radius * radius * v.length(),
        LightType::Cylinder { length, radius, .. } => {
            2.0 * length * radius * (v.y * v.y + v.z * v.z).sqrt()
        }
        LightType::Distant { .. } | LightType::Dome | LightType::Mesh { .. } => 0.0,
    };
    local * p.det
}

/// intensity along the unit direction `e` (pointing away from the light).
pub fn intensity(p: &Prepared, e: DVec3) -> DVec3 {
    emission(p, e) * projected_area(p, e)
}
