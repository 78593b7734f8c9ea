//! Synthetic mesh lights (DESIGN.md §7): the benchmark's bumpy torus of a chosen triangle count
//! (`luxeval bench`, `benches/mesh_light.rs`) and, for the conformance suite and `luxeval
//! check`'s tests, randomised meshes of every shape class the issue names (closed convex,
//! closed non-convex, open, double-sided), under every transform kind (mirrors included),
//! shaped or not.

use std::f64::consts::TAU;

use glam::DMat4;

use crate::model::{Light, MeshGeometry, MeshTopology};

/// Points and polygons of a mesh in its own space.
#[derive(Clone, Debug, Default)]
pub struct MeshSource {
    pub points: Vec<[f64; 3]>,
    pub counts: Vec<i32>,
    pub indices: Vec<i32>,
}

impl MeshSource {
    /// Fan-triangulated under `world` (the prim's local-to-world transform).
    pub fn geometry(&self, world: DMat4) -> MeshGeometry {
        MeshGeometry::triangulate(
            &MeshTopology {
                points: &self.points,
                face_vertex_counts: &self.counts,
                face_vertex_indices: &self.indices,
                hole_indices: &[],
                left_handed: false,
            },
            world,
        )
        .expect("a synthetic mesh is valid")
    }

    fn quad(&mut self, q: [i32; 4]) {
        self.counts.push(4);
        self.indices.extend(q);
    }
}

/// A torus of `around × across` quads (ring radius 2, tube radius 0.5 with a 5 % bump seven
/// times along the ring, so that no two quads are alike), fronts outward: closed and
/// non-convex, so rays and receivers meet self-occlusion. Its fan has `2 · around · across`
/// triangles.
pub fn torus(around: usize, across: usize) -> MeshSource {
    let mut m = MeshSource::default();
    for i in 0..around {
        let a = TAU * i as f64 / around as f64;
        for j in 0..across {
            let b = TAU * j as f64 / across as f64;
            let tube = 0.5 * (1.0 + 0.05 * (7.0 * a).sin());
            let rho = 2.0 + tube * b.cos();
            m.points
                .push([rho * a.cos(), tube * b.sin(), rho * a.sin()]);
        }
    }
    let v = |i: usize, j: usize| ((i % around) * across + (j % across)) as i32;
    for i in 0..around {
        for j in 0..across {
            m.quad([v(i, j), v(i, j + 1), v(i + 1, j + 1), v(i + 1, j)]);
        }
    }
    m
}

/// The benchmark's mesh light: a [`torus`] with at least `triangles` triangles (exactly that
/// many when `triangles / 2` factors as `around × across` with `around = 1.25 · across`, as
/// 100,000 does: 250 × 200), unit intensity, identity transform.
pub fn synthetic_mesh_light(triangles: usize) -> Light {
    let quads = triangles.div_ceil(2).max(9);
    let across = ((quads as f64 / 1.25).sqrt().round() as usize).max(3);
    let around = quads.div_ceil(across).max(3);
    Light::mesh(torus(around, across).geometry(DMat4::IDENTITY))
        .with_path(format!("/bench/torus_{}", 2 * around * across))
}

/// `n` rays from a shell 3–6 units from the origin toward random points within 2 units of it:
/// most meet the benchmark [`torus`] (ring radius 2), some pass through its hole or miss.
/// (points, directions), as the queries take them.
pub fn torus_rays(n: usize, rng: &mut super::Rng) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let points: Vec<[f32; 3]> = (0..n)
        .map(|_| (rng.unit() * rng.range(3.0, 6.0)).as_vec3().to_array())
        .collect();
    let dirs = points
        .iter()
        .map(|p| {
            let target = rng.unit() * 2.0;
            (target - glam::DVec3::from_array(p.map(f64::from)))
                .as_vec3()
                .to_array()
        })
        .collect();
    (points, dirs)
}

/// The shape classes of [`random_mesh_light`].
#[cfg(any(test, feature = "testkit"))]
pub const MESH_CLASSES: [&str; 5] = ["box", "torus", "l-prism", "open-patch", "double-sided"];

/// A box `2a × 2b × 2c` about the origin, fronts outward (closed, convex).
#[cfg(any(test, feature = "testkit"))]
fn cuboid(a: f64, b: f64, c: f64) -> MeshSource {
    let mut m = MeshSource::default();
    for k in 0..8 {
        let s = |bit: usize, v: f64| if k & bit != 0 { v } else { -v };
        m.points.push([s(1, a), s(2, b), s(4, c)]);
    }
    // Counter-clockwise seen from outside (right-handed orientation: front = (p1−p0)×(p2−p0)).
    for q in [
        [0, 2, 3, 1], // −z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // −y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // −x
        [1, 3, 7, 5], // +x
    ] {
        m.quad(q);
    }
    m
}

/// An L-shaped prism (the L of `w` with arms of thickness `t`, extruded by `d` along z): closed
/// and non-convex; one L face is a single non-convex hexagon whose fan stays unfolded from its
/// reflex corner.
#[cfg(any(test, feature = "testkit"))]
fn l_prism(w: f64, t: f64, d: f64) -> MeshSource {
    let outline = [[t, t], [w, t], [w, 0.0], [0.0, 0.0], [0.0, w], [t, w]];
    let mut m = MeshSource::default();
    for z in [0.0, d] {
        for [x, y] in outline {
            m.points.push([x - w / 2.0, y - w / 2.0, z - d / 2.0]);
        }
    }
    let n = outline.len() as i32;
    // The outline runs clockwise seen from +z: the front (z = d) face reverses it, the back
    // (z = 0) keeps it (its front faces −z).
    m.counts.push(n);
    m.indices.extend(0..n);
    // Reversed from the same reflex corner (t, t), so that both fans stay inside the L.
    m.counts.push(n);
    m.indices.push(n);
    m.indices.extend((1..n).rev().map(|i| i + n));
    for i in 0..n {
        let j = (i + 1) % n;
        m.quad([i, i + n, j + n, j]);
    }
    m
}

/// An open height-field patch of `k × k` quads over `[-1, 1]²` with random heights (fronts
/// toward +z, non-convex, seen from both sides).
#[cfg(any(test, feature = "testkit"))]
fn patch(k: usize, rng: &mut super::Rng) -> MeshSource {
    let mut m = MeshSource::default();
    let amp = rng.range(0.1, 0.8);
    let (fx, fy, ph) = (
        rng.range(1.0, 4.0),
        rng.range(1.0, 4.0),
        rng.range(0.0, TAU),
    );
    for i in 0..=k {
        for j in 0..=k {
            let (x, y) = (
                -1.0 + 2.0 * i as f64 / k as f64,
                -1.0 + 2.0 * j as f64 / k as f64,
            );
            let z = amp * (fx * x + ph).sin() * (fy * y).cos();
            m.points.push([x, y, z]);
        }
    }
    let v = |i: usize, j: usize| (i * (k + 1) + j) as i32;
    for i in 0..k {
        for j in 0..k {
            m.quad([v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    m
}

/// A random mesh light of shape class `class` ([`MESH_CLASSES`]) under transform kind `xf`
/// ([`super::TRANSFORMS`]), with the random LightAPI and ShapingAPI inputs of
/// [`super::random_light`] (the mesh is the light's prim: the transform places its points and
/// gives the shaping axis).
#[cfg(any(test, feature = "testkit"))]
pub fn random_mesh_light(class: &str, xf: &str, rng: &mut super::Rng, id: usize) -> Light {
    let source = match class {
        "box" => cuboid(
            rng.range(0.1, 1.0),
            rng.range(0.1, 1.0),
            rng.range(0.1, 1.0),
        ),
        "torus" => {
            let mut t = torus(6 + rng.below(6), 4 + rng.below(4));
            let s = rng.range(0.2, 0.5);
            t.points.iter_mut().for_each(|p| *p = p.map(|c| c * s));
            t
        }
        "l-prism" => l_prism(
            rng.range(0.5, 1.5),
            rng.range(0.1, 0.4),
            rng.range(0.1, 1.0),
        ),
        "open-patch" | "double-sided" => patch(2 + rng.below(4), rng),
        other => panic!("unknown mesh class {other}"),
    };
    // Everything but the shape from random_light (a rect's draw of inputs, shaping included).
    let template = super::random_light(3, xf, rng, id);
    let world = template.world;
    let mut l = Light::mesh(source.geometry(world));
    if class == "double-sided"
        && let crate::model::LightType::Mesh { double_sided, .. } = &mut l.kind
    {
        *double_sided = true;
    }
    l.path = format!("/random/{id}_mesh_{class}_{xf}");
    l.world = world;
    l.inputs = template.inputs;
    l.shaping = template.shaping;
    l
}

/// Every mesh class × transform kind, `per_combo` lights each.
#[cfg(any(test, feature = "testkit"))]
pub fn random_mesh_lights(rng: &mut super::Rng, per_combo: usize) -> Vec<Light> {
    let mut lights = Vec::new();
    for class in MESH_CLASSES {
        for xf in super::TRANSFORMS {
            for _ in 0..per_combo {
                let id = lights.len();
                lights.push(random_mesh_light(class, xf, rng, id));
            }
        }
    }
    lights
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::LightType;

    #[test]
    fn the_benchmark_torus_has_the_triangles_asked_for() {
        let l = synthetic_mesh_light(100_000);
        let LightType::Mesh { geometry, .. } = &l.kind else {
            panic!("a mesh light")
        };
        assert_eq!(geometry.triangles.len(), 100_000);
        // Area of a torus 4π²Rr = 4π²·2·0.5 ≈ 39.48 (the bump changes it by < 1 %).
        assert!((geometry.area / (4.0 * std::f64::consts::PI.powi(2)) - 1.0).abs() < 0.01);
        let small = synthetic_mesh_light(1000);
        let LightType::Mesh { geometry, .. } = &small.kind else {
            panic!("a mesh light")
        };
        assert!(geometry.triangles.len() >= 1000);
    }

    /// A closed mesh's fronts point outward: the signed volume `Σ p0·(p1×p2)/6` of its fan is
    /// positive, and equals the box's or the prism's volume (independent closed forms).
    #[test]
    fn closed_classes_are_outward_and_watertight() {
        let vol = |m: &MeshGeometry| {
            m.triangles
                .iter()
                .map(|t| t.p[0].dot(t.p[1].cross(t.p[2])) / 6.0)
                .sum::<f64>()
        };
        let b = cuboid(0.5, 0.25, 1.0).geometry(DMat4::IDENTITY);
        assert!((vol(&b) - 1.0).abs() < 1e-12, "{}", vol(&b));
        assert!((b.area - 2.0 * (0.5 + 2.0 + 1.0)).abs() < 1e-12);
        let l = l_prism(1.0, 0.25, 0.5).geometry(DMat4::IDENTITY);
        let section = 2.0 * 0.25 - 0.25 * 0.25;
        assert!((vol(&l) - section * 0.5).abs() < 1e-12, "{}", vol(&l));
        assert!(l.folded_faces.is_empty());
        let t = torus(12, 8).geometry(DMat4::IDENTITY);
        assert!(vol(&t) > 0.0);
    }
}
