//! The visible parts of a mesh light's triangles (DESIGN.md §7 M3). Written next.
// TEMPORARY interface stubs until the module lands (replaced at the merge).
use glam::DVec3;
use crate::model::MeshTriangle;
pub(crate) struct Surface<'a> { pub triangles: &'a [MeshTriangle], pub double_sided: bool }
pub(crate) struct Piece { pub triangle: u32, pub emitting: bool, pub verts: Vec<DVec3> }
impl Surface<'_> {
    pub(crate) fn visible_from(&self, _x: DVec3) -> Vec<Piece> { unimplemented!() }
    pub(crate) fn cosine_solid_angle(&self, _x: DVec3, _n: DVec3) -> f64 { unimplemented!() }
    pub(crate) fn projected_area(&self, _w: DVec3) -> f64 { unimplemented!() }
}
pub(crate) fn integrate_piece(_verts: &[DVec3], _n: DVec3, _rel: f64, _f: &mut impl FnMut(DVec3) -> DVec3) -> DVec3 { unimplemented!() }
