//! A mesh light's irradiance on a GPU evaluator where its triangles cannot hide one another
//! (DESIGN.md §7 M3; `prepare::mesh_class`, `GpuPath::HostIntensityOnly`): the kernel's sum of
//! Lambert's formula over the triangles that face x (shaders/mesh/lambert.wgsl) against the CPU
//! reference, within 1e-4 relative, on unshaped random boxes under every transform kind
//! (mirrors included) and on flat quads, polygon fans and grids (one- and double-sided,
//! mirrored), receivers inside and outside; receivers in `luxeval check`'s band (the mesh at
//! the horizon, x nearly in a triangle's plane) excluded and counted. Also an ignored
//! throughput measurement (receivers per second, GPU vs CPU).

use glam::{DMat4, DQuat, DVec3};
use luxeval::testkit::check::{self, BAND, irradiance_margin, rel_error_above};
use luxeval::testkit::{Rng, TRANSFORMS, random_light, random_mesh_light};
use luxeval::{Accumulate, Evaluator, Light, LightType, Reference, TemperatureMode};

use crate::mesh_lights::{mesh, rect_quad};

fn double(mut l: Light) -> Light {
    if let LightType::Mesh { double_sided, .. } = &mut l.kind {
        *double_sided = true;
    }
    l
}

/// Receivers around the mesh's vertices' centre: a fifth near the centre (inside a box), the
/// rest out to three times its radius; normals uniform.
fn receivers(light: &Light, n: usize, rng: &mut Rng) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let LightType::Mesh { geometry, .. } = &light.kind else {
        unreachable!()
    };
    let verts: Vec<DVec3> = geometry.triangles.iter().flat_map(|t| t.p).collect();
    let centre = verts.iter().sum::<DVec3>() / verts.len() as f64;
    let radius = verts.iter().map(|v| v.distance(centre)).fold(0.0, f64::max);
    (0..n)
        .map(|i| {
            let r = if i % 5 == 0 {
                0.05
            } else {
                rng.range(0.1, 3.0)
            };
            let x = centre + rng.unit() * (r * radius);
            (x.as_vec3().to_array(), rng.unit().as_vec3().to_array())
        })
        .unzip()
}

/// GPU irradiance of one light against the reference at `n` receivers: (compared, excluded,
/// worst relative error); asserts each compared one within 1e-4.
fn compare(
    gpu: &Evaluator,
    name: &str,
    light: &Light,
    n: usize,
    rng: &mut Rng,
) -> (usize, usize, f64) {
    let lights = std::slice::from_ref(light);
    let dev = gpu.prepare(lights).unwrap();
    let reference = Reference::new(light, TemperatureMode::Spec).unwrap();
    let (pts, nrms) = receivers(light, n, rng);
    let g = dev.irradiance(&pts, &nrms, Accumulate::Sum).unwrap();
    let (mut compared, mut excluded, mut worst) = (0, 0, 0.0f64);
    for i in 0..n {
        let x = DVec3::from_array(pts[i].map(f64::from));
        let nn = DVec3::from_array(nrms[i].map(f64::from));
        if irradiance_margin(&reference, x, nn) < BAND {
            excluded += 1;
            continue;
        }
        let want = reference.irradiance(x, nn);
        let err = rel_error_above(want, g[i], 0.0);
        assert!(
            err <= 1e-4,
            "{name}, x {x}, n {nn}: CPU {want}, GPU {:?} ({err:.2e}), margin {:.3e}, top {:.3e}, base-relative {:.3e}",
            g[i],
            irradiance_margin(&reference, x, nn),
            top(light, x, nn),
            want.x
                / reference
                    .irradiance(x, (DVec3::splat(0.5) - x).normalize())
                    .x
                    .max(1e-300)
        );
        worst = worst.max(err);
        compared += 1;
    }
    (compared, excluded, worst)
}

fn top(light: &Light, x: DVec3, n: DVec3) -> f64 {
    let LightType::Mesh { geometry, .. } = &light.kind else {
        unreachable!()
    };
    geometry
        .triangles
        .iter()
        .flat_map(|t| t.p)
        .map(|q| n.dot((q - x).normalize()).asin())
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn mesh_irradiance_runs_on_the_device_where_the_triangles_cannot_hide_one_another() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let mut rng = Rng::new(0x22_0004);
    let mut lights: Vec<(String, Light)> = Vec::new();
    for xf in TRANSFORMS {
        for id in 0..3 {
            let mut b = random_mesh_light("box", xf, &mut rng, id);
            b.shaping = None;
            lights.push((format!("box {xf} {id}"), b));
        }
        let world = random_light(3, xf, &mut rng, 0).world;
        lights.push((
            format!("quad {xf}"),
            Light::mesh(rect_quad(1.5, 0.8, world)),
        ));
        lights.push((
            format!("double-sided quad {xf}"),
            double(Light::mesh(rect_quad(1.5, 0.8, world))),
        ));
        let hexagon: Vec<[f64; 3]> = (0..6)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 6.0;
                [t.cos(), 0.6 * t.sin(), 0.0]
            })
            .collect();
        lights.push((
            format!("hexagon fan {xf}"),
            Light::mesh(mesh(&hexagon, &[&[0, 1, 2, 3, 4, 5]], world)).with_intensity(3.0),
        ));
        // A 3 × 3 grid of quads, double-sided.
        let mut pts = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                pts.push([i as f64 / 3.0, j as f64 / 3.0, 0.0]);
            }
        }
        let v = |i: i32, j: i32| i * 4 + j;
        let quads: Vec<[i32; 4]> = (0..3)
            .flat_map(|i| (0..3).map(move |j| [v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]))
            .collect();
        let faces: Vec<&[i32]> = quads.iter().map(|q| &q[..]).collect();
        lights.push((
            format!("double-sided grid {xf}"),
            double(Light::mesh(mesh(&pts, &faces, world))),
        ));
    }
    // A mirrored quad and grid with the mirror in the light's transform too.
    let mirror = DMat4::from_scale_rotation_translation(
        DVec3::new(-1.0, 1.0, 1.0),
        DQuat::from_rotation_y(0.3),
        DVec3::new(0.0, 1.5, 0.0),
    );
    lights.push((
        "mirrored quad".into(),
        Light::mesh(rect_quad(1.0, 2.0, mirror)).with_transform(mirror),
    ));
    let (mut compared, mut excluded, mut worst) = (0, 0, 0.0f64);
    for (name, light) in &lights {
        // The device's (else the values below would be the reference's own): `luxeval check`
        // compares an irradiance row for it.
        let r = Reference::new(light, TemperatureMode::Spec).unwrap();
        let counts = check::Samples {
            emission: 0,
            intensity: 0,
            radiance: 0,
            irradiance: 8,
        };
        let report = check::check_with(&gpu, &[r], counts, 3).unwrap();
        assert!(
            report
                .rows
                .iter()
                .any(|r| r.query == check::CheckedQuery::Irradiance && r.pass),
            "{name}: irradiance should be the device's and compared: {:?}",
            report.host_only
        );
        let (c, e, w) = compare(&gpu, name, light, 300, &mut rng);
        compared += c;
        excluded += e;
        worst = worst.max(w);
    }
    eprintln!(
        "mesh irradiance GPU vs CPU: {} lights, {compared} receivers compared, {excluded} \
         excluded (band), worst relative {worst:.2e}",
        lights.len()
    );
    // A fifth of the receivers are near the mesh's centre: a flat mesh's are then near its
    // plane, which the band excludes as it does a rect's.
    assert!(excluded * 2 < compared, "{excluded} excluded of {compared}");
}

/// Receivers per second of an unshaped box's irradiance, GPU (whatever adapter runs the tests;
/// lavapipe in CI) vs the CPU reference (its Lambert sum, cpu::mesh::lambert). Run with
/// `--release -- --ignored --nocapture`.
#[test]
#[ignore]
fn mesh_irradiance_throughput() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let mut rng = Rng::new(5);
    let mut b = random_mesh_light("box", "rotate", &mut rng, 0);
    b.shaping = None;
    let lights = std::slice::from_ref(&b);
    let n = 1 << 18;
    let (pts, nrms) = receivers(&b, n, &mut rng);
    let dev = gpu.prepare(lights).unwrap();
    let cpu = Evaluator::cpu().prepare(lights).unwrap();
    let _ = dev
        .irradiance(&pts[..1024], &nrms[..1024], Accumulate::Sum)
        .unwrap();
    let t = std::time::Instant::now();
    let _ = dev.irradiance(&pts, &nrms, Accumulate::Sum).unwrap();
    let g = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let _ = cpu.irradiance(&pts, &nrms, Accumulate::Sum).unwrap();
    let c = t.elapsed().as_secs_f64();
    // The same box double-sided: not classified, so the reference searches visible pieces
    // (what every box took before the Lambert shortcut).
    let two = double(b.clone());
    let cpu2 = Evaluator::cpu()
        .prepare(std::slice::from_ref(&two))
        .unwrap();
    let m = 1 << 12;
    let t = std::time::Instant::now();
    let _ = cpu2
        .irradiance(&pts[..m], &nrms[..m], Accumulate::Sum)
        .unwrap();
    let p = t.elapsed().as_secs_f64();
    eprintln!(
        "unshaped box (12 triangles), {n} receivers: GPU {:.3e} receivers/s ({}), CPU reference \
         (Lambert sum) {:.3e} receivers/s; the same box double-sided (visible pieces, {m} \
         receivers) {:.3e} receivers/s",
        n as f64 / g,
        gpu.device_name(),
        n as f64 / c,
        m as f64 / p
    );
}

/// A flat grid of 4050 triangles (under the 4096 cap) seen low over the horizon, where every
/// triangle takes the sliver form (the most loop iterations a triangle costs): the sum is the
/// reference's, so lavapipe's 65,535-iteration budget was not cut short.
#[test]
fn a_mesh_at_the_triangle_cap_seen_low_is_summed_whole() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let k = 45;
    let mut pts = Vec::new();
    for i in 0..=k {
        for j in 0..=k {
            pts.push([i as f64 / k as f64, j as f64 / k as f64, 0.0]);
        }
    }
    let v = |i: i32, j: i32| i * (k + 1) + j;
    let quads: Vec<[i32; 4]> = (0..k)
        .flat_map(|i| (0..k).map(move |j| [v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]))
        .collect();
    let faces: Vec<&[i32]> = quads.iter().map(|q| &q[..]).collect();
    let light = Light::mesh(mesh(&pts, &faces, DMat4::IDENTITY));
    let reference = Reference::new(&light, TemperatureMode::Spec).unwrap();
    let dev = gpu.prepare(std::slice::from_ref(&light)).unwrap();
    let pts = [[3.0f32, 0.5, 0.4], [0.5, -2.0, 0.3], [-1.5, 1.5, 0.6]];
    let nrms = [[0.0f32, 0.0, -1.0], [0.0, 0.0, -1.0], [0.3, 0.0, -1.0]];
    let g = dev.irradiance(&pts, &nrms, Accumulate::Sum).unwrap();
    for i in 0..pts.len() {
        let x = DVec3::from_array(pts[i].map(f64::from));
        let n = DVec3::from_array(nrms[i].map(f64::from)).normalize();
        let want = reference.irradiance(x, n);
        let err = rel_error_above(want, g[i], 0.0);
        eprintln!(
            "grid of 4050 at {x}: CPU {:.6e}, GPU {:.6e}, {err:.1e}",
            want.x, g[i][0]
        );
        assert!(
            want.x > 0.0 && err <= 1e-4,
            "{x}: CPU {want}, GPU {:?}",
            g[i]
        );
    }
}
