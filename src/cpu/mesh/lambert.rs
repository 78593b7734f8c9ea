//! The irradiance of a mesh light whose triangles cannot hide one another
//! (`prepare::mesh_class`: planar without overlap, one-sided closed convex): the sum over the
//! triangles x sees an emitting side of of Lambert's formula clipped at the receiver's horizon
//! (`polygon_irradiance`: Lambert 1760; Arvo 1995), which equals the visible pieces' sum
//! ([`super::visible`]) because every such triangle is wholly visible and no two overlap seen
//! from x (the proof is in `prepare::mesh_class`). Twin of `shaders/mesh/lambert.wgsl`.
//!
//! A triangle is skipped as [`super::visible`] skips it: when x is within its `EDGE_ON`
//! (relative) of the triangle's plane, or wholly below the horizon.

use glam::DVec3;

use super::visible::EDGE_ON;
use crate::cpu::irradiance::closed::polygon_irradiance;
use crate::model::MeshTriangle;

/// Unit-radiance irradiance at x (unit normal n) of one triangle, vertices as vectors from x:
/// Lambert's formula on the triangle clipped to n·ω ≥ 0.
pub(crate) fn triangle_lambert(q: &[DVec3; 3], n: DVec3) -> f64 {
    polygon_irradiance(q, n)
}

/// Unit-radiance irradiance at x (unit normal n) of the mesh: the sum of [`triangle_lambert`]
/// over the triangles whose emitting side faces x (the front, `(p1 − p0) × (p2 − p0)`, or
/// either side when double-sided).
pub(crate) fn mesh_lambert(
    triangles: &[MeshTriangle],
    double_sided: bool,
    x: DVec3,
    n: DVec3,
) -> f64 {
    let mut sum = 0.0;
    for t in triangles {
        let q = t.p.map(|p| p - x);
        let front = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize_or_zero();
        let c = front.dot(q[0]);
        let far = q.iter().map(|q| q.length()).fold(0.0, f64::max);
        if !(c.abs() > EDGE_ON * far) || !far.is_finite() {
            continue;
        }
        // x is on the front's side where front·(x − p0) > 0, i.e. c < 0.
        if !(double_sided || c < 0.0) || q.iter().all(|q| !(n.dot(*q) > 0.0)) {
            continue;
        }
        sum += triangle_lambert(&q, n);
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Light, LightType, MeshGeometry, MeshTopology};
    use crate::prepare::{GpuPath, KindData, MeshOcclusion, Prepared, TemperatureMode};
    use crate::synthetic::{Rng, TRANSFORMS, random_light, random_mesh_light};
    use glam::DMat4;

    /// A mesh light of these polygons under `world`.
    fn polygons(points: &[[f64; 3]], counts: &[i32], indices: &[i32], world: DMat4) -> Light {
        let geometry = MeshGeometry::triangulate(
            &MeshTopology {
                points,
                face_vertex_counts: counts,
                face_vertex_indices: indices,
                hole_indices: &[],
                left_handed: false,
            },
            world,
        )
        .unwrap();
        Light::mesh(geometry)
    }

    fn double(mut l: Light) -> Light {
        if let LightType::Mesh { double_sided, .. } = &mut l.kind {
            *double_sided = true;
        }
        l
    }

    /// Flat meshes in z = 0: a quad, a hexagon (one fanned face), a k × k grid of quads.
    fn flat(which: usize, world: DMat4, rng: &mut Rng) -> Light {
        match which {
            0 => polygons(
                &[
                    [-1.0, -0.5, 0.0],
                    [1.0, -0.5, 0.0],
                    [1.0, 0.5, 0.0],
                    [-1.0, 0.5, 0.0],
                ],
                &[4],
                &[0, 1, 2, 3],
                world,
            ),
            1 => {
                let points: Vec<[f64; 3]> = (0..6)
                    .map(|i| {
                        let t = std::f64::consts::TAU * i as f64 / 6.0;
                        [t.cos(), 0.7 * t.sin(), 0.0]
                    })
                    .collect();
                polygons(&points, &[6], &[0, 1, 2, 3, 4, 5], world)
            }
            _ => {
                let k = 2 + rng.below(4);
                let mut points = Vec::new();
                for i in 0..=k {
                    for j in 0..=k {
                        points.push([i as f64 / k as f64, j as f64 / k as f64, 0.0]);
                    }
                }
                let v = |i: usize, j: usize| (i * (k + 1) + j) as i32;
                let mut indices = Vec::new();
                for i in 0..k {
                    for j in 0..k {
                        indices.extend([v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
                    }
                }
                polygons(&points, &vec![4; k * k], &indices, world)
            }
        }
    }

    fn prep(l: &Light) -> Prepared {
        Prepared::new(l, TemperatureMode::Spec).unwrap()
    }

    fn occlusion(p: &Prepared) -> MeshOcclusion {
        match &p.kind {
            KindData::Mesh { occlusion, .. } => *occlusion,
            _ => panic!("a mesh light"),
        }
    }

    /// The Lambert sum and the visible pieces' sum at random receivers around and inside the
    /// mesh: the worst relative difference (on values above 1e-4, absolute over 1e-4 below).
    fn worst(p: &Prepared, rng: &mut Rng) -> f64 {
        let m = super::super::parts(p).unwrap();
        let surface = super::super::visible::Surface {
            triangles: m.triangles,
            double_sided: m.double_sided,
        };
        let verts: Vec<DVec3> = m.triangles.iter().flat_map(|t| t.p).collect();
        let centre = verts.iter().sum::<DVec3>() / verts.len() as f64;
        let extent = verts.iter().map(|v| v.distance(centre)).fold(0.0, f64::max);
        let mut worst = 0.0f64;
        for k in 0..40 {
            // Some receivers well inside (a box's), the others out to 3 extents.
            let r = if k % 5 == 0 {
                0.05
            } else {
                rng.range(0.1, 3.0)
            };
            let x = centre + rng.unit() * (r * extent);
            let n = rng.unit();
            let got = mesh_lambert(m.triangles, m.double_sided, x, n);
            let want = surface.cosine_solid_angle(x, n);
            // Below 1e-4 (of the hemisphere's π) the values are horizon slivers, where both
            // sums are rounding-limited in absolute terms (measured ≤ 1e-16).
            let d = (got - want).abs() / want.abs().max(1e-4);
            worst = worst.max(d);
        }
        worst
    }

    /// The shortcut is the visible pieces' sum (≤ 1e-12 relative) on random unshaped boxes
    /// and flat meshes (one- and double-sided) under every transform kind, mirrors included.
    #[test]
    fn lambert_sum_equals_the_visible_pieces_where_classified() {
        let mut rng = Rng::new(0x22_04);
        let mut overall = 0.0f64;
        for xf in TRANSFORMS {
            for id in 0..3 {
                let mut b = random_mesh_light("box", xf, &mut rng, id);
                b.shaping = None;
                let p = prep(&b);
                assert_eq!(occlusion(&p), MeshOcclusion::ConvexClosed, "{xf}");
                assert!(matches!(p.gpu_path, GpuPath::HostIntensityOnly(_)), "{xf}");
                overall = overall.max(worst(&p, &mut rng));
                let world = random_light(3, xf, &mut rng, id).world;
                for which in 0..3 {
                    for two in [false, true] {
                        let mut l = flat(which, world, &mut rng);
                        if two {
                            l = double(l);
                        }
                        let p = prep(&l);
                        assert_eq!(occlusion(&p), MeshOcclusion::Planar, "{xf} {which}");
                        overall = overall.max(worst(&p, &mut rng));
                    }
                }
            }
        }
        eprintln!("worst relative difference from the visible pieces: {overall:.3e}");
        assert!(overall <= 1e-12, "{overall:e}");
    }

    /// Meshes whose triangles can hide one another, or whose overlap the sum would count
    /// twice, are not classified: tori, L-prisms, height-field patches, double-sided boxes, an
    /// open box, two overlapping coplanar quads, a doubled face.
    #[test]
    fn meshes_that_can_hide_themselves_are_not_classified() {
        let mut rng = Rng::new(7);
        for xf in TRANSFORMS {
            for class in ["torus", "l-prism", "open-patch", "double-sided"] {
                let l = random_mesh_light(class, xf, &mut rng, 0);
                assert_eq!(occlusion(&prep(&l)), MeshOcclusion::General, "{class} {xf}");
            }
            let mut b = random_mesh_light("box", xf, &mut rng, 0);
            b.shaping = None;
            assert_eq!(
                occlusion(&prep(&double(b.clone()))),
                MeshOcclusion::General,
                "double-sided box {xf}"
            );
            // A box missing its last face (two triangles): open.
            if let LightType::Mesh { geometry, .. } = &mut b.kind {
                let n = geometry.triangles.len();
                std::sync::Arc::make_mut(geometry).triangles.truncate(n - 2);
            }
            assert_eq!(
                occlusion(&prep(&b)),
                MeshOcclusion::General,
                "open box {xf}"
            );
            let world = random_light(3, xf, &mut rng, 0).world;
            let overlapping = polygons(
                &[
                    [0.0, 0.0, 0.0],
                    [1.0, 0.0, 0.0],
                    [1.0, 1.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.5, 0.5, 0.0],
                    [1.5, 0.5, 0.0],
                    [1.5, 1.5, 0.0],
                    [0.5, 1.5, 0.0],
                ],
                &[4, 4],
                &[0, 1, 2, 3, 4, 5, 6, 7],
                world,
            );
            assert_eq!(
                occlusion(&prep(&overlapping)),
                MeshOcclusion::General,
                "{xf}"
            );
            // The same face twice, once reversed: closed and flat.
            let doubled = polygons(
                &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                &[3, 3],
                &[0, 1, 2, 0, 2, 1],
                world,
            );
            assert_eq!(occlusion(&prep(&doubled)), MeshOcclusion::General, "{xf}");
            // A shaped box is classified but its irradiance stays on the host.
            let mut shaped = random_mesh_light("box", xf, &mut rng, 0);
            if shaped.shaping.is_some() {
                let p = prep(&shaped);
                if p.shaping.is_some() {
                    assert!(matches!(p.gpu_path, GpuPath::HostIntensity(_)), "{xf}");
                }
            }
            shaped.shaping = None;
            assert!(!prep(&shaped).irradiance_on_host());
        }
    }
}
