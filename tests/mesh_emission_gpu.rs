//! A mesh light's emission on a GPU evaluator (DESIGN.md §7 M3; `GpuPath::HostIntensity`):
//! the kernel tests the mesh's distinct front directions (shaders/emission.wgsl, the logic of
//! `cpu::mesh::emission`) and gives the reference's 0 or L on closed, open, double-sided,
//! mirrored and shaped meshes and on the neon ring of assets/neon_ring.usda, away from the
//! directions within 1e-4 rad of edge-on to every front that could decide it.

use glam::{DMat4, DQuat, DVec3};
use luxeval::testkit::Rng;
use luxeval::{Accumulate, Evaluator, Light, LightType, MeshGeometry, Shaping};

use crate::mesh_lights::{l_prism, mesh, rect_quad, ring};

/// An open roof of two quads meeting at a ridge along Y, each tilted `tilt` rad from +Z toward
/// ±X: single-sided it emits where either front faces ω.
fn roof(tilt: f64, world: DMat4) -> MeshGeometry {
    let (c, s) = (tilt.cos(), tilt.sin());
    let pts = [
        [-c, -1.0, -s],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-c, 1.0, -s],
        [c, -1.0, -s],
        [c, 1.0, -s],
    ];
    mesh(&pts, &[&[0, 1, 2, 3], &[1, 4, 5, 2]], world)
}

/// A mesh light's emission on the device (the kernel tests its distinct fronts, GpuPath::
/// HostIntensity) is the reference's 0 or L on closed, open, double-sided and mirrored meshes,
/// shaped and not, away from the directions within 1e-4 rad of edge-on to every front that could
/// decide it (the band `luxeval check` excludes); L to f32 rounding.
#[test]
fn mesh_emission_runs_on_the_device() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let mirror = DMat4::from_scale_rotation_translation(
        DVec3::new(-1.0, 1.0, 1.0),
        DQuat::from_rotation_y(0.3),
        DVec3::new(0.0, 1.5, 0.0),
    );
    let double = |mut l: Light| {
        if let LightType::Mesh { double_sided, .. } = &mut l.kind {
            *double_sided = true;
        }
        l
    };
    let shaped = Shaping {
        cone_angle: 60.0,
        cone_softness: 0.3,
        ..Shaping::default()
    };
    let lights = vec![
        ("closed L prism", Light::mesh(l_prism()).with_intensity(2.0)),
        ("open roof", Light::mesh(roof(0.6, DMat4::IDENTITY))),
        (
            "double-sided roof",
            double(Light::mesh(roof(0.6, DMat4::IDENTITY))),
        ),
        (
            "mirrored roof",
            Light::mesh(roof(0.6, mirror)).with_transform(mirror),
        ),
        (
            "shaped open ring",
            Light::mesh(ring(24)).with_shaping(shaped.clone()),
        ),
        (
            "open quad",
            Light::mesh(rect_quad(1.0, 2.0, DMat4::IDENTITY)).with_color(DVec3::new(1.0, 0.3, 0.1)),
        ),
    ];
    let mut rng = Rng::new(23);
    let n = 4000;
    let dirs = emission_dirs(n, &mut rng);
    for (name, light) in &lights {
        compare_emission(&gpu, name, light, &dirs);
    }
}

/// Emission directions: uniform, plus directions near ±Z and ±Y (edge-on to the rings' and the
/// roofs' fronts) to exercise the ties, and ±Z and Y exactly.
fn emission_dirs(n: usize, rng: &mut Rng) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let e = match i % 4 {
                0 | 1 => rng.unit(),
                2 => (rng.unit() * 0.01 + DVec3::Z * if rng.chance(0.5) { 1.0 } else { -1.0 })
                    .normalize(),
                _ => (rng.unit() * 0.01 + DVec3::Y).normalize(),
            };
            e.as_vec3().to_array()
        })
        .chain([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
        .collect()
}

/// GPU emission of one mesh light against the reference along `dirs`: the same 0 or L, L to
/// 1e-4, away from the edge-on band of the fronts that could decide it and the shaping's cone
/// edge (60° in these tests); prints how many were excluded.
fn compare_emission(gpu: &Evaluator, name: &str, light: &Light, dirs: &[[f32; 3]]) {
    let lights = std::slice::from_ref(light);
    let cpu = Evaluator::cpu().prepare(lights).unwrap();
    let dev = gpu.prepare(lights).unwrap();
    let c = cpu.emission(dirs, Accumulate::Sum).unwrap();
    let g = dev.emission(dirs, Accumulate::Sum).unwrap();
    let fronts = match &light.kind {
        LightType::Mesh {
            geometry,
            double_sided,
            ..
        } => (
            geometry
                .triangles
                .iter()
                .filter_map(|t| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).try_normalize())
                .collect::<Vec<_>>(),
            *double_sided,
        ),
        _ => unreachable!(),
    };
    let (mut excluded, mut lit, mut worst) = (0, 0, 0.0f64);
    for (i, d) in dirs.iter().enumerate() {
        let e = DVec3::from_array(d.map(f64::from)).normalize();
        let facing = |n: &DVec3| {
            let c = n.dot(e);
            if fronts.1 { c.abs() } else { c }
        };
        // Decided by a front within the band of edge-on, or at the shaping's cone edge.
        let decided = fronts.0.iter().any(|n| facing(n).asin() > 1e-4);
        let near = fronts.0.iter().any(|n| n.dot(e).abs() < 1e-4);
        let cone = 60f64.to_radians();
        let at_cone =
            light.shaping.is_some() && ((-e.z).clamp(-1.0, 1.0).acos() - cone).abs() < 4e-3 * cone;
        if (!decided && near) || at_cone {
            excluded += 1;
            continue;
        }
        let (a, b) = (c[i], g[i]);
        assert_eq!(
            a == [0.0; 3],
            b == [0.0; 3],
            "{name}, {e}: CPU {a:?}, GPU {b:?}"
        );
        let scale = a.iter().chain(&b).fold(0.0f32, |s, v| s.max(v.abs())) as f64;
        let err = a
            .iter()
            .zip(&b)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() as f64));
        let rel = if scale > 0.0 { err / scale } else { 0.0 };
        assert!(rel <= 1e-4, "{name}, {e}: CPU {a:?}, GPU {b:?}");
        worst = worst.max(rel);
        lit += usize::from(a != [0.0; 3]);
    }
    eprintln!(
        "{name}: emission GPU vs CPU on {} directions: {excluded} excluded (edge-on band), \
         {lit} lit, worst relative {worst:.1e}",
        dirs.len()
    );
    assert!(excluded < dirs.len() / 20, "{name}: {excluded} excluded");
}

/// The neon ring of assets/neon_ring.usda (a torus-like tube, read from USD): its emission on
/// the device is the reference's, as [`mesh_emission_runs_on_the_device`] checks.
#[cfg(feature = "usd")]
#[test]
fn the_neon_rings_emission_runs_on_the_device() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/neon_ring.usda");
    let lights = luxeval::Stage::load(&path, None)
        .unwrap()
        .evaluable(&[])
        .unwrap();
    let dirs = emission_dirs(4000, &mut Rng::new(31));
    for l in &lights {
        compare_emission(&gpu, &l.path, l, &dirs);
    }
}
