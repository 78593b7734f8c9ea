//! Mesh lights (MeshLightAPI, DESIGN.md §7) as plain data: the mesh's triangles in world space
//! with their emitting front, its exact area and its tint. Nothing here evaluates light: a
//! [`MeshLight`] becomes a [`Light`] of kind [`LightType::Mesh`], which the queries evaluate.

use std::sync::Arc;

use glam::{DMat4, DVec3};

use super::light::{Light, LightInputs, LightType, Shaping, UpAxis};

/// One triangle of the fan of one face, in world space. Its front, the side it emits toward,
/// is `(p[1] − p[0]) × (p[2] − p[0])`: [`MeshGeometry::triangulate`] orders the vertices so
/// that this holds for either `orientation` and for a mirroring world transform (M2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshTriangle {
    pub p: [DVec3; 3],
    /// The index of the face (in `faceVertexCounts`) the triangle belongs to: a ray that hits
    /// two triangles at the same distance takes the one that comes first (M1: face order, then
    /// fan order, which is the order of the triangles).
    pub face: u32,
}

impl MeshTriangle {
    /// The triangle's world-space area.
    pub fn area(&self) -> f64 {
        0.5 * (self.p[1] - self.p[0])
            .cross(self.p[2] - self.p[0])
            .length()
    }
}

/// A mesh's polygons as authored, in object space: what [`MeshGeometry::triangulate`] reads.
#[derive(Clone, Copy, Debug)]
pub struct MeshTopology<'a> {
    /// `points` at the query time.
    pub points: &'a [[f64; 3]],
    pub face_vertex_counts: &'a [i32],
    pub face_vertex_indices: &'a [i32],
    pub hole_indices: &'a [i32],
    /// `orientation` is `leftHanded`: the object-space front is `−(p1 − p0) × (p2 − p0)` (M2).
    pub left_handed: bool,
}

/// Why a mesh's topology cannot be a light (M1 "bad topology"): the attribute at fault, its
/// offending value as written, and why. A query refuses the light naming the prim and this.
#[derive(Clone, Debug, PartialEq)]
pub struct TopologyError {
    pub attr: &'static str,
    pub value: String,
    pub reason: String,
}

/// A mesh light's surface: the fan triangles of its faces (holes removed, degenerate triangles
/// dropped) in world space, and their exact total area.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshGeometry {
    pub triangles: Vec<MeshTriangle>,
    /// The sum of the triangles' world-space areas, one side (also when double-sided): the
    /// sizeFactor of `normalize` (M2).
    pub area: f64,
    /// Triangles of the fans dropped as degenerate (world area ≤ [`DEGENERATE_AREA`] × the
    /// mesh's largest): they emit nothing and occlude nothing (M1).
    pub degenerate: usize,
    /// Faces removed because `holeIndices` names them (each counted once).
    pub holes: usize,
    /// Faces whose fan folds over itself (a non-convex polygon whose fan has triangles facing
    /// opposite ways), in face order: evaluated as that fan, as Hydra renders it, and said
    /// (M1).
    pub folded_faces: Vec<u32>,
}

/// A triangle whose world area is at most this fraction of the mesh's largest triangle is
/// degenerate (M1).
pub const DEGENERATE_AREA: f64 = 1e-12;

impl MeshGeometry {
    /// The number of fan triangles `topology` makes (holes removed, degenerate ones not yet
    /// dropped), checking the counts; what a caller compares with its limit before
    /// [`MeshGeometry::triangulate`] allocates them.
    pub fn fan_triangles(topology: &MeshTopology) -> Result<u64, TopologyError> {
        let holes = hole_mask(topology)?;
        let mut n: u64 = 0;
        for (face, &count) in topology.face_vertex_counts.iter().enumerate() {
            if count < 3 {
                return Err(TopologyError {
                    attr: "faceVertexCounts",
                    value: format!("[{face}] = {count}"),
                    reason: "a face needs at least 3 vertices".into(),
                });
            }
            if !holes[face] {
                n += count as u64 - 2;
            }
        }
        Ok(n)
    }

    /// The fan triangulation `(v0, v_i, v_{i+1})`, i = 1 … n−2, of every face not in
    /// `holeIndices` (Hydra's; M1), carried to world space by `world` (column-vector
    /// convention), each ordered so that its cross product is its emitting front (M2: the
    /// object-space normal, negated for `leftHanded`, carried by the inverse transpose of
    /// `world` — which is the world-space cross product times det(world)'s sign, so a
    /// mirroring transform swaps two vertices). Degenerate triangles are dropped.
    ///
    /// Bad topology (M1): a count < 3, an index negative or out of range, counts that do not
    /// sum to the number of indices, a non-finite point, a hole index out of range.
    pub fn triangulate(topology: &MeshTopology, world: DMat4) -> Result<Self, TopologyError> {
        let t = topology;
        let fan = Self::fan_triangles(t)?;
        let total: u64 = t.face_vertex_counts.iter().map(|&c| c as u64).sum();
        if total != t.face_vertex_indices.len() as u64 {
            return Err(TopologyError {
                attr: "faceVertexIndices",
                value: format!("{} indices", t.face_vertex_indices.len()),
                reason: format!("faceVertexCounts sums to {total}; the two must agree"),
            });
        }
        for (i, &index) in t.face_vertex_indices.iter().enumerate() {
            if index < 0 || index as usize >= t.points.len() {
                return Err(TopologyError {
                    attr: "faceVertexIndices",
                    value: format!("[{i}] = {index}"),
                    reason: format!("not an index of the {} points", t.points.len()),
                });
            }
        }
        for (i, p) in t.points.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(TopologyError {
                    attr: "points",
                    value: format!("[{i}] = ({}, {}, {})", p[0], p[1], p[2]),
                    reason: "not finite".into(),
                });
            }
        }
        let holes = hole_mask(t)?;
        let world_points: Vec<DVec3> = t
            .points
            .iter()
            .map(|p| world.transform_point3(DVec3::from_array(*p)))
            .collect();
        // Swap two vertices when exactly one of leftHanded and a mirroring transform holds.
        let flip = t.left_handed != (world.determinant() < 0.0);
        let mut triangles = Vec::with_capacity(usize::try_from(fan).unwrap_or(0));
        let mut start = 0usize;
        for (face, &count) in t.face_vertex_counts.iter().enumerate() {
            let ids = &t.face_vertex_indices[start..start + count as usize];
            start += count as usize;
            if holes[face] {
                continue;
            }
            let v = |k: usize| world_points[ids[k] as usize];
            for i in 1..ids.len() - 1 {
                let p = match flip {
                    false => [v(0), v(i), v(i + 1)],
                    true => [v(0), v(i + 1), v(i)],
                };
                triangles.push(MeshTriangle {
                    p,
                    face: face as u32,
                });
            }
        }
        let largest = triangles.iter().map(MeshTriangle::area).fold(0.0, f64::max);
        let before = triangles.len();
        triangles.retain(|tri| tri.area() > DEGENERATE_AREA * largest);
        let area = triangles.iter().map(MeshTriangle::area).sum();
        Ok(MeshGeometry {
            degenerate: before - triangles.len(),
            area,
            folded_faces: folded_faces(&triangles),
            triangles,
            holes: holes.iter().filter(|h| **h).count(),
        })
    }
}

/// The faces among `triangles` (in face order, degenerate ones already dropped) with a triangle
/// facing against the face's summed normal: their fan folds over itself.
fn folded_faces(triangles: &[MeshTriangle]) -> Vec<u32> {
    let cross = |t: &MeshTriangle| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
    triangles
        .chunk_by(|a, b| a.face == b.face)
        .filter(|fan| {
            let sum: DVec3 = fan.iter().map(cross).sum();
            fan.iter().any(|t| cross(t).dot(sum) < 0.0)
        })
        .map(|fan| fan[0].face)
        .collect()
}

/// Per face: whether `holeIndices` names it; an index that names no face is bad topology.
fn hole_mask(t: &MeshTopology) -> Result<Vec<bool>, TopologyError> {
    let mut holes = vec![false; t.face_vertex_counts.len()];
    for (i, &h) in t.hole_indices.iter().enumerate() {
        match usize::try_from(h).ok().and_then(|h| holes.get_mut(h)) {
            Some(slot) => *slot = true,
            None => {
                return Err(TopologyError {
                    attr: "holeIndices",
                    value: format!("[{i}] = {h}"),
                    reason: format!("not an index of the {} faces", t.face_vertex_counts.len()),
                });
            }
        }
    }
    Ok(holes)
}

/// Where a mesh light's tint came from (M2), said by `luxeval lights`.
#[derive(Clone, Debug, PartialEq)]
pub struct Tint {
    pub rgb: DVec3,
    /// A short description, e.g. `emissiveColor of /Looks/Neon/Surface (authored)`,
    /// `materialSyncMode independent`, `no material bound`.
    pub source: String,
}

/// A mesh light as read (M1, M2): its LightAPI inputs, shaping, world transform and surface.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshLight {
    pub path: String,
    pub inputs: LightInputs,
    /// `Some` where ShapingAPI is applied; its primary axis is the prim's local −Z (M2).
    pub shaping: Option<Shaping>,
    /// Local-to-world, column-vector convention, as [`super::Light::world`].
    pub world: DMat4,
    /// Shared with the [`Light`] of [`MeshLight::light`], not copied.
    pub geometry: Arc<MeshGeometry>,
    /// `doubleSided`: every triangle emits toward both sides.
    pub double_sided: bool,
    pub tint: Tint,
    /// `subdivisionScheme` as read: anything but `none` is evaluated as its control cage (M1).
    pub subdivision_scheme: String,
}

impl MeshLight {
    /// The light the queries evaluate, on a stage whose up axis is `stage_up`.
    pub fn light(&self, stage_up: UpAxis) -> Light {
        Light {
            path: self.path.clone(),
            kind: LightType::Mesh {
                geometry: Arc::clone(&self.geometry),
                double_sided: self.double_sided,
                tint: self.tint.rgb,
            },
            world: self.world,
            inputs: self.inputs.clone(),
            shaping: self.shaping.clone(),
            stage_up,
            texture: None,
            portals: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn topo<'a>(
        points: &'a [[f64; 3]],
        counts: &'a [i32],
        indices: &'a [i32],
        holes: &'a [i32],
    ) -> MeshTopology<'a> {
        MeshTopology {
            points,
            face_vertex_counts: counts,
            face_vertex_indices: indices,
            hole_indices: holes,
            left_handed: false,
        }
    }

    const QUAD: [[f64; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];

    #[test]
    fn a_quad_is_two_fan_triangles_facing_its_winding() {
        let g = MeshGeometry::triangulate(&topo(&QUAD, &[4], &[0, 1, 2, 3], &[]), DMat4::IDENTITY)
            .unwrap();
        assert_eq!(g.triangles.len(), 2);
        assert_eq!(g.area, 2.0);
        for t in &g.triangles {
            let n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
            assert!(n.z > 0.0);
        }
        // Fan order: (v0, v1, v2), (v0, v2, v3).
        assert_eq!(g.triangles[1].p[2], DVec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn left_handed_and_mirroring_each_flip_the_front_and_together_cancel() {
        let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
        let front = |left: bool, world: DMat4| {
            let mut t = topo(&QUAD, &[4], &[0, 1, 2, 3], &[]);
            t.left_handed = left;
            let g = MeshGeometry::triangulate(&t, world).unwrap();
            let tri = g.triangles[0];
            (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).z.signum()
        };
        assert_eq!(front(false, DMat4::IDENTITY), 1.0);
        assert_eq!(front(true, DMat4::IDENTITY), -1.0);
        // Mirrored in x the world-space winding reverses; the authored outside (+z) stays front.
        assert_eq!(front(false, mirror), 1.0);
        assert_eq!(front(true, mirror), -1.0);
    }

    #[test]
    fn holes_and_degenerate_triangles_are_removed() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0], // collinear with 0 and 1
        ];
        let g = MeshGeometry::triangulate(
            &topo(&pts, &[4, 3, 3], &[0, 1, 2, 3, 0, 1, 4, 1, 2, 3], &[2]),
            DMat4::IDENTITY,
        )
        .unwrap();
        assert_eq!((g.triangles.len(), g.degenerate, g.holes), (2, 1, 1));
        assert_eq!(g.area, 1.0);
    }

    #[test]
    fn a_fan_that_folds_over_itself_is_kept_and_named() {
        // A dart whose fan from v0 has a triangle facing the other way.
        let dart = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 0.5, 0.0],
        ];
        let g = MeshGeometry::triangulate(
            &topo(&dart, &[4, 4], &[0, 1, 2, 3, 0, 1, 2, 3], &[]),
            DMat4::IDENTITY,
        )
        .unwrap();
        assert_eq!(g.triangles.len(), 4);
        assert_eq!(g.folded_faces, vec![0, 1]);
        // One side each: |T1| + |T2| = 2 + 0.5.
        assert_eq!(g.area, 5.0);
        let square =
            MeshGeometry::triangulate(&topo(&QUAD, &[4], &[0, 1, 2, 3], &[]), DMat4::IDENTITY);
        assert!(square.unwrap().folded_faces.is_empty());
    }

    #[test]
    fn bad_topology_names_the_attribute() {
        let bad = |counts: &[i32], indices: &[i32], holes: &[i32], pts: &[[f64; 3]]| {
            MeshGeometry::triangulate(&topo(pts, counts, indices, holes), DMat4::IDENTITY)
                .unwrap_err()
                .attr
        };
        assert_eq!(bad(&[2], &[0, 1], &[], &QUAD), "faceVertexCounts");
        assert_eq!(bad(&[3], &[0, 1, 4], &[], &QUAD), "faceVertexIndices");
        assert_eq!(bad(&[3], &[0, 1, -1], &[], &QUAD), "faceVertexIndices");
        assert_eq!(bad(&[3], &[0, 1, 2, 3], &[], &QUAD), "faceVertexIndices");
        assert_eq!(bad(&[3], &[0, 1, 2], &[1], &QUAD), "holeIndices");
        assert_eq!(bad(&[3], &[0, 1, 2], &[-1], &QUAD), "holeIndices");
        let mut nan = QUAD;
        nan[1][2] = f64::NAN;
        assert_eq!(bad(&[3], &[0, 1, 2], &[], &nan), "points");
    }
}
