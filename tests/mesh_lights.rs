//! Mesh lights (DESIGN.md §7) against independent references:
//! - a flat quad mesh is the RectLight of the same size and frame on every query (M2, M3), to
//!   1e-9 on the CPU reference, shaped and unshaped, normalized or not, under a rotation,
//!   translation and mirror (the RectLight's values are closed forms and chart quadratures
//!   proven elsewhere);
//! - the exact, self-occluded irradiance of non-convex meshes (an L-shaped prism, a polygonal
//!   ring) equals a Monte Carlo estimate of the first-hit radiance, `π/N Σ L(ω_i)` over
//!   cosine-distributed directions, within 5 standard errors;
//! - on a GPU evaluator a mesh light's radiance is traversed on the device (within 1e-4 of the
//!   reference away from triangle edges, also for a mesh too large to test naively within
//!   lavapipe's loop budget), its emission agrees (tests/mesh_emission_gpu.rs compares it) and
//!   its intensity and irradiance are the reference's.

use std::f64::consts::PI;

use glam::{DMat4, DQuat, DVec3};
use luxeval::testkit::Rng;
use luxeval::{
    Accumulate, Evaluator, Light, LightType, MeshGeometry, MeshTopology, Reference, SampleOptions,
    Selection, Shaping, TemperatureMode,
};

fn r(l: &Light) -> Reference {
    Reference::new(l, TemperatureMode::Spec).unwrap()
}

fn rel(a: DVec3, b: DVec3) -> f64 {
    let d = (a - b).abs().max_element();
    if d == 0.0 {
        0.0
    } else {
        d / a.abs().max_element().max(b.abs().max_element())
    }
}

/// A mesh of `points` and polygons `faces` (object space) under `world`.
pub(crate) fn mesh(points: &[[f64; 3]], faces: &[&[i32]], world: DMat4) -> MeshGeometry {
    let counts: Vec<i32> = faces.iter().map(|f| f.len() as i32).collect();
    let indices: Vec<i32> = faces.iter().flat_map(|f| f.iter().copied()).collect();
    MeshGeometry::triangulate(
        &MeshTopology {
            points,
            face_vertex_counts: &counts,
            face_vertex_indices: &indices,
            hole_indices: &[],
            left_handed: false,
        },
        world,
    )
    .unwrap()
}

/// The quad of a `w × h` RectLight: in its local XY plane, wound so that its front is local −Z,
/// the RectLight's emitting side.
pub(crate) fn rect_quad(w: f64, h: f64, world: DMat4) -> MeshGeometry {
    let (a, b) = (w / 2.0, h / 2.0);
    let pts = [[-a, -b, 0.0], [-a, b, 0.0], [a, b, 0.0], [a, -b, 0.0]];
    mesh(&pts, &[&[0, 1, 2, 3]], world)
}

fn frames() -> Vec<DMat4> {
    vec![
        DMat4::IDENTITY,
        DMat4::from_rotation_translation(
            DQuat::from_euler(glam::EulerRot::XYZ, 0.7, -0.4, 1.9),
            DVec3::new(0.5, 2.0, -1.0),
        ),
        // A mirror: the authored front stays the front (M2), as the RectLight's −Z does.
        DMat4::from_scale_rotation_translation(
            DVec3::new(-1.0, 1.0, 1.0),
            DQuat::from_rotation_y(0.3),
            DVec3::new(0.0, 1.5, 0.0),
        ),
    ]
}

fn shapings() -> Vec<Option<Shaping>> {
    vec![
        None,
        Some(Shaping {
            cone_angle: 40.0,
            cone_softness: 0.3,
            focus: 2.0,
            ..Shaping::default()
        }),
    ]
}

/// Every query of a quad mesh equals the RectLight's (M2, M3; issue: "a flat quad mesh equals
/// the RectLight of the same size on every query, ≤ 1e-9 CPU").
#[test]
fn a_flat_quad_mesh_is_its_rect_light_on_every_query() {
    let mut rng = Rng::new(7);
    let mut worst = [0.0f64; 4];
    for world in frames() {
        for shaping in shapings() {
            for normalize in [false, true] {
                let mut rect = Light::rect(1.5, 0.8)
                    .with_transform(world)
                    .with_intensity(3.0)
                    .with_color(DVec3::new(1.0, 0.5, 0.25))
                    .with_normalize(normalize);
                let mut quad = Light::mesh(rect_quad(1.5, 0.8, world))
                    .with_transform(world)
                    .with_intensity(3.0)
                    .with_color(DVec3::new(1.0, 0.5, 0.25))
                    .with_normalize(normalize);
                if let Some(s) = &shaping {
                    rect = rect.with_shaping(s.clone());
                    quad = quad.with_shaping(s.clone());
                }
                let (a, b) = (r(&rect), r(&quad));
                let o = world.transform_point3(DVec3::ZERO);
                for _ in 0..200 {
                    let e = rng.unit();
                    worst[0] = worst[0].max(rel(a.emission(e), b.emission(e)));
                    worst[1] = worst[1].max(rel(a.intensity(e), b.intensity(e)));
                    // Points around the light, directions toward a point near it.
                    let x = o + rng.unit() * (0.3 + 3.0 * rng.f64());
                    let toward = (o + 0.6 * rng.unit() - x).normalize();
                    worst[2] = worst[2].max(rel(a.radiance(x, toward), b.radiance(x, toward)));
                }
                for _ in 0..40 {
                    let x = o + rng.unit() * (0.2 + 3.0 * rng.f64());
                    let n = rng.unit();
                    worst[3] = worst[3].max(rel(a.irradiance(x, n), b.irradiance(x, n)));
                }
            }
        }
    }
    eprintln!(
        "quad mesh vs RectLight, worst relative: emission {:.1e}, intensity {:.1e}, radiance {:.1e}, irradiance {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    for (q, w) in ["emission", "intensity", "radiance", "irradiance"]
        .iter()
        .zip(worst)
    {
        assert!(w <= 1e-9, "{q}: {w:e}");
    }
}

/// An L-shaped prism (a non-convex closed mesh, outward fronts) and a ring of quads facing
/// inward and outward (non-convex, double-sided): the exact self-occluded irradiance against a
/// Monte Carlo of the first-hit radiance.
pub(crate) fn l_prism() -> MeshGeometry {
    // The L in the XY plane, extruded along Z from 0 to 1; polygons wound counter-clockwise
    // seen from outside.
    let l = [
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];
    let mut pts = Vec::new();
    for z in [0.0, 1.0] {
        for p in l {
            pts.push([p[0], p[1], z]);
        }
    }
    let bottom: Vec<i32> = vec![0, 5, 4, 3, 2, 1];
    let top: Vec<i32> = vec![6, 7, 8, 9, 10, 11];
    let mut sides: Vec<Vec<i32>> = Vec::new();
    for i in 0..6 {
        let j = (i + 1) % 6;
        sides.push(vec![i, j, j + 6, i + 6]);
    }
    let mut faces: Vec<&[i32]> = vec![&bottom, &top];
    faces.extend(sides.iter().map(|s| s.as_slice()));
    mesh(&pts, &faces, DMat4::IDENTITY)
}

pub(crate) fn ring(k: usize) -> MeshGeometry {
    let mut pts = Vec::new();
    for i in 0..k {
        let t = 2.0 * PI * i as f64 / k as f64;
        pts.push([t.cos(), t.sin(), 0.0]);
        pts.push([t.cos(), t.sin(), 0.4]);
    }
    let faces: Vec<Vec<i32>> = (0..k as i32)
        .map(|i| {
            let j = (i + 1) % k as i32;
            vec![2 * i, 2 * j, 2 * j + 1, 2 * i + 1]
        })
        .collect();
    let faces: Vec<&[i32]> = faces.iter().map(|f| f.as_slice()).collect();
    mesh(&pts, &faces, DMat4::IDENTITY)
}

#[test]
fn exact_self_occluded_irradiance_matches_a_monte_carlo_of_first_hit_radiance() {
    let mut rng = Rng::new(11);
    // (name, light, receivers as (point, normal)).
    type Case = (&'static str, Light, Vec<(DVec3, DVec3)>);
    let cases: Vec<Case> = vec![
        (
            "L prism",
            Light::mesh(l_prism()).with_intensity(2.0),
            vec![
                // In the L's notch, seeing both inner walls; beside it; above it, tilted.
                (DVec3::new(1.6, 1.6, 0.5), DVec3::new(-1.0, -1.0, 0.2)),
                (DVec3::new(3.0, 0.5, 0.5), DVec3::new(-1.0, 0.1, 0.0)),
                (DVec3::new(1.5, 1.5, 2.0), DVec3::new(-0.3, -0.3, -1.0)),
            ],
        ),
        {
            let mut l = Light::mesh(ring(24)).with_intensity(1.5);
            if let LightType::Mesh { double_sided, .. } = &mut l.kind {
                *double_sided = true;
            }
            (
                "double-sided ring",
                l,
                vec![
                    // Inside, seeing the inner wall and (through the gaps above) nothing else;
                    // outside, seeing the near outer wall; above, looking down into it.
                    (DVec3::new(0.2, 0.1, 0.2), DVec3::X),
                    (DVec3::new(2.5, 0.3, 0.3), DVec3::new(-1.0, 0.0, 0.1)),
                    (DVec3::new(0.3, 0.0, 1.5), DVec3::new(0.2, 0.0, -1.0)),
                ],
            )
        },
    ];
    for (name, light, receivers) in cases {
        let p = r(&light);
        let l = p.base_radiance().x;
        for (x, n) in receivers {
            let n = n.normalize();
            let exact = p.irradiance(x, n).x;
            // Cosine-weighted directions about n: E = π/N Σ L(ω_i) (Malley's method).
            let count = 200_000;
            let (t, b) = n.any_orthonormal_pair();
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..count {
                let (u1, u2) = (rng.f64(), rng.f64());
                let (s, phi) = (u1.sqrt(), 2.0 * PI * u2);
                let w = t * (s * phi.cos()) + b * (s * phi.sin()) + n * (1.0 - u1).sqrt();
                let v = PI * p.radiance(x, w).x;
                sum += v;
                sum2 += v * v;
            }
            let mean = sum / count as f64;
            let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
            eprintln!("{name} at {x}: exact {exact:.6}, Monte Carlo {mean:.6} ± {se:.1e} (L {l})");
            assert!(exact > 0.0, "{name} at {x}: nothing seen");
            assert!(
                (exact - mean).abs() <= 5.0 * se.max(1e-12),
                "{name} at {x}: exact {exact} vs Monte Carlo {mean} ± {se}"
            );
        }
    }
}

/// A closed convex mesh (an octahedron, fronts outward) seen from outside gives the irradiance of
/// its silhouette, which is that of its front-facing faces alone: each face's Lambert formula,
/// computed here independently, summed.
#[test]
fn a_closed_convex_mesh_gives_its_silhouettes_irradiance() {
    let v = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let faces: [&[i32]; 8] = [
        &[0, 2, 4],
        &[2, 1, 4],
        &[1, 3, 4],
        &[3, 0, 4],
        &[2, 0, 5],
        &[1, 2, 5],
        &[3, 1, 5],
        &[0, 3, 5],
    ];
    let g = mesh(&v, &faces, DMat4::IDENTITY);
    let tris = g.triangles.clone();
    let p = r(&Light::mesh(g));
    let mut rng = Rng::new(3);
    for _ in 0..50 {
        let x = rng.unit() * (1.8 + 2.0 * rng.f64());
        let n = rng.unit();
        // Lambert (1760): E = ½ Σ_edges Θ_e n·γ_e over the face seen from x, clipped at the
        // horizon by Sutherland–Hodgman, faces whose front faces x only.
        let mut want = 0.0;
        for t in &tris {
            let front = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
            if front.dot(x - t.p[0]) <= 0.0 {
                continue;
            }
            let q: Vec<DVec3> = t.p.iter().map(|&v| v - x).collect();
            want += lambert_clipped(&q, n);
        }
        let got = p.irradiance(x, n).x;
        assert!(
            (got - want).abs() <= 1e-9 * want.max(1e-300) || (got - want).abs() < 1e-15,
            "at {x}, n {n}: {got} vs {want}"
        );
    }
}

/// Lambert's formula for the polygon `q` (vectors from x), clipped to n·ω ≥ 0.
fn lambert_clipped(q: &[DVec3], n: DVec3) -> f64 {
    let mut c: Vec<DVec3> = Vec::new();
    for i in 0..q.len() {
        let (a, b) = (q[i], q[(i + 1) % q.len()]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            c.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            c.push(a + (b - a) * (da / (da - db)));
        }
    }
    let mut sum = 0.0;
    for i in 0..c.len() {
        let (a, b) = (c[i].normalize(), c[(i + 1) % c.len()].normalize());
        let g = a.cross(b);
        if g.length() > 0.0 {
            sum += a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(g.normalize());
        }
    }
    (0.5 * sum).abs()
}

/// On a GPU evaluator a mesh light's radiance is the kernel's first hit through its BVH and its
/// emission the kernel's test of its fronts (GpuPath::HostIntensity), within 1e-4 of the
/// reference away from triangle edges; its intensity and irradiance are the reference's (rows of
/// its own with --per-light, summed with the kernels' other lights); sampling runs on the CPU
/// reference.
#[test]
fn a_gpu_evaluator_traverses_mesh_lights_for_radiance_and_takes_the_rest_from_the_reference() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let mut ring_light = Light::mesh(ring(24)).with_intensity(1.5).with_path("/Ring");
    if let LightType::Mesh { double_sided, .. } = &mut ring_light.kind {
        *double_sided = true;
    }
    let lights = vec![
        Light::sphere(0.2).with_transform(DMat4::from_translation(DVec3::new(0.0, 3.0, 0.0))),
        Light::mesh(l_prism())
            .with_path("/Prism")
            .with_intensity(2.0)
            .with_shaping(Shaping {
                cone_angle: 70.0,
                cone_softness: 0.2,
                ..Shaping::default()
            }),
        ring_light,
    ];
    let cpu = Evaluator::cpu().prepare(&lights).unwrap();
    let dev = gpu.prepare(&lights).unwrap();
    let mut rng = Rng::new(5);
    let n = 2048;
    let dirs: Vec<[f32; 3]> = (0..n).map(|_| rng.unit().as_vec3().to_array()).collect();
    let pts: Vec<[f32; 3]> = (0..n)
        .map(|_| {
            (rng.unit() * 3.0 + DVec3::new(1.0, 1.0, 0.5))
                .as_vec3()
                .to_array()
        })
        .collect();
    // Toward points near the meshes, so that most rays hit one.
    let toward: Vec<[f32; 3]> = pts
        .iter()
        .map(|p| {
            let target = DVec3::new(0.8, 0.8, 0.4) + rng.unit() * rng.range(0.0, 1.2);
            (target - DVec3::from_array(p.map(f64::from)))
                .as_vec3()
                .to_array()
        })
        .collect();
    let per = Accumulate::PerLight;
    // Emission is the device's (GpuPath::HostIntensity): tests/mesh_emission_gpu.rs
    // `mesh_emission_runs_on_the_device` compares it; here it only has to agree.
    let (ce, ge) = (
        cpu.emission(&dirs, per).unwrap(),
        dev.emission(&dirs, per).unwrap(),
    );
    for (a, b) in ce[n..].iter().zip(&ge[n..]) {
        let scale = a.iter().chain(b).fold(0.0f32, |s, v| s.max(v.abs()));
        let err = a
            .iter()
            .zip(b)
            .fold(0.0f32, |e, (a, b)| e.max((a - b).abs()));
        assert!(err <= 1e-4 * scale, "emission: CPU {a:?}, GPU {b:?}");
    }
    for (q, c, g) in [
        (
            "intensity",
            cpu.intensity(&dirs, per).unwrap(),
            dev.intensity(&dirs, per).unwrap(),
        ),
        (
            "irradiance",
            cpu.irradiance(&pts, &dirs, per).unwrap(),
            dev.irradiance(&pts, &dirs, per).unwrap(),
        ),
    ] {
        // The mesh lights' rows (the second and third) are the reference's exactly.
        assert_eq!(&c[n..], &g[n..], "{q}");
        assert!(c[n..2 * n].iter().any(|v| v[0] > 0.0), "{q}: nothing lit");
    }
    let c = cpu.radiance(&pts, &toward, per).unwrap();
    let g = dev.radiance(&pts, &toward, per).unwrap();
    let meshes: Vec<Vec<luxeval::MeshTriangle>> = lights[1..]
        .iter()
        .map(|l| match &l.kind {
            LightType::Mesh { geometry, .. } => geometry.triangles.clone(),
            _ => unreachable!(),
        })
        .collect();
    let (mut compared, mut lit, mut worst) = (0, 0, 0.0f64);
    for (m, tris) in meshes.iter().enumerate() {
        for i in 0..n {
            let x = DVec3::from_array(pts[i].map(f64::from));
            let w = DVec3::from_array(toward[i].map(f64::from)).normalize();
            if edge_margin(tris, x, w) < 1e-4 {
                continue;
            }
            // The shaped prism's cone edge: the band the conformance check excludes
            // (±4e-3·θcone, src/conformance), where f32 shaping of a tiny tail differs.
            let cone = 70f64.to_radians();
            if m == 0 && (w.z.clamp(-1.0, 1.0).acos() - cone).abs() < 4e-3 * cone {
                continue;
            }
            let (a, b) = (c[(m + 1) * n + i], g[(m + 1) * n + i]);
            let scale = a.iter().chain(&b).fold(0.0f32, |s, v| s.max(v.abs())) as f64;
            let err = a
                .iter()
                .zip(&b)
                .fold(0.0f64, |e, (a, b)| e.max((a - b).abs() as f64));
            let rel = if scale > 0.0 { err / scale } else { 0.0 };
            worst = worst.max(rel);
            assert!(rel <= 1e-4, "mesh {m}, ray {i}: CPU {a:?}, GPU {b:?}");
            compared += 1;
            lit += usize::from(a[0] > 0.0);
        }
    }
    eprintln!(
        "mesh radiance GPU vs CPU: {compared} rays compared ({lit} lit), worst relative {worst:.1e}"
    );
    assert!(
        compared > 3000 && lit > 500,
        "{compared} compared, {lit} lit"
    );
    // Sampling runs on the CPU reference for such a scene, row for row the CPU evaluator's.
    assert_eq!(dev.sampling_device(), "cpu");
    let a = cpu.sample(&pts, None, 4, &Default::default()).unwrap();
    let b = dev.sample(&pts, None, 4, &Default::default()).unwrap();
    assert_eq!((a.dirs, a.pdf, a.radiance), (b.dirs, b.pdf, b.radiance));
}

/// How far (relative to the triangle's size) the ray x + tω, t > 0, passes from the nearest
/// edge of any triangle whose plane it crosses: below ~1e-6 f32 may hit where f64 misses.
fn edge_margin(tris: &[luxeval::MeshTriangle], x: DVec3, w: DVec3) -> f64 {
    let mut m = f64::INFINITY;
    for t in tris {
        let (e1, e2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
        let n = e1.cross(e2);
        let denom = n.dot(w);
        if denom == 0.0 {
            continue;
        }
        let s = n.dot(t.p[0] - x) / denom;
        if s <= 0.0 {
            continue;
        }
        let h = x + s * w - t.p[0];
        // Barycentrics by Cramer's rule, then the smallest distance to an edge line, scaled by
        // the triangle's longest edge.
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (h1, h2) = (h.dot(e1), h.dot(e2));
        let det = d11 * d22 - d12 * d12;
        let v = (d22 * h1 - d12 * h2) / det;
        let u = (d11 * h2 - d12 * h1) / det;
        let bary = [1.0 - u - v, v, u];
        let size = e1.length().max(e2.length()).max((e2 - e1).length());
        let area2 = n.length();
        let heights = [
            area2 / (e2 - e1).length(),
            area2 / e2.length(),
            area2 / e1.length(),
        ];
        for k in 0..3 {
            m = m.min((bary[k] * heights[k]).abs() / size);
        }
    }
    m
}

/// A mesh of 72,200 triangles (a rippled 190 × 190 grid): testing every triangle would take more
/// loop iterations than lavapipe gives an invocation (65,535); the BVH traversal takes far
/// fewer, and the GPU's radiance equals the reference's away from edges.
#[test]
fn a_mesh_too_large_to_test_naively_is_traversed_on_the_device() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let k = 190;
    let mut pts = Vec::new();
    for i in 0..=k {
        for j in 0..=k {
            let (x, z) = (
                i as f64 / k as f64 * 4.0 - 2.0,
                j as f64 / k as f64 * 4.0 - 2.0,
            );
            pts.push([x, 0.1 * (3.0 * x).sin() * (2.0 * z).cos(), z]);
        }
    }
    let faces: Vec<Vec<i32>> = (0..k)
        .flat_map(|i| {
            (0..k).map(move |j| {
                let v = |a: usize, b: usize| (a * (k + 1) + b) as i32;
                vec![v(i, j), v(i, j + 1), v(i + 1, j + 1), v(i + 1, j)]
            })
        })
        .collect();
    let faces: Vec<&[i32]> = faces.iter().map(|f| f.as_slice()).collect();
    let g = mesh(&pts, &faces, DMat4::IDENTITY);
    assert_eq!(g.triangles.len(), 72_200);
    let tris = g.triangles.clone();
    let lights = vec![Light::mesh(g).with_intensity(3.0)];
    let cpu = Evaluator::cpu().prepare(&lights).unwrap();
    let dev = gpu.prepare(&lights).unwrap();
    let mut rng = Rng::new(9);
    let n = 512;
    let (mut pts, mut dirs) = (Vec::new(), Vec::new());
    for _ in 0..n {
        let x = DVec3::new(
            rng.range(-2.0, 2.0),
            rng.range(-1.0, 1.0) * 1.5,
            rng.range(-2.0, 2.0),
        );
        let target = DVec3::new(rng.range(-1.9, 1.9), 0.0, rng.range(-1.9, 1.9));
        pts.push(x.as_vec3().to_array());
        dirs.push((target - x).as_vec3().to_array());
    }
    let c = cpu.radiance(&pts, &dirs, Accumulate::Sum).unwrap();
    let d = dev.radiance(&pts, &dirs, Accumulate::Sum).unwrap();
    let (mut compared, mut lit) = (0, 0);
    for i in 0..n {
        let x = DVec3::from_array(pts[i].map(f64::from));
        let w = DVec3::from_array(dirs[i].map(f64::from)).normalize();
        if edge_margin(&tris, x, w) < 1e-4 {
            continue;
        }
        assert!(
            (c[i][0] - d[i][0]).abs() <= 1e-4 * c[i][0].abs().max(d[i][0].abs()),
            "ray {i}: {:?} vs {:?}",
            c[i],
            d[i]
        );
        compared += 1;
        lit += usize::from(c[i][0] > 0.0);
    }
    eprintln!("72,200-triangle mesh: {compared} rays compared, {lit} lit");
    assert!(
        compared > 400 && lit > 100,
        "{compared} compared, {lit} lit"
    );
}

fn luma(c: [f32; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

/// DESIGN.md §9 S1 (iii) for mesh lights: the mean of `Y(L) · max(0, n·ω) / pdf` over the
/// scene sampler's draws equals the exact self-occluded irradiance within 5 standard errors,
/// for every way of choosing a light, with a mesh light beside a sphere (shaped and unshaped,
/// single- and double-sided); and the pdf query returns each draw's density.
#[test]
fn sampling_mesh_lights_is_unbiased_against_the_exact_irradiance() {
    let mut ring_light = Light::mesh(ring(24)).with_intensity(1.5).with_path("/Ring");
    if let LightType::Mesh { double_sided, .. } = &mut ring_light.kind {
        *double_sided = true;
    }
    let shaped_prism = Light::mesh(l_prism())
        .with_path("/Prism")
        .with_intensity(2.0)
        .with_transform(DMat4::from_rotation_x(-0.4))
        .with_shaping(Shaping {
            cone_angle: 60.0,
            cone_softness: 0.5,
            ..Shaping::default()
        });
    let sphere = Light::sphere(0.3)
        .with_path("/Sphere")
        .with_transform(DMat4::from_translation(DVec3::new(3.0, 3.0, 0.0)));
    let scenes = [
        vec![
            Light::mesh(l_prism())
                .with_path("/Prism")
                .with_intensity(2.0),
            sphere.clone(),
        ],
        vec![shaped_prism, ring_light.clone()],
        vec![ring_light],
    ];
    let points: Vec<[f32; 3]> = vec![
        [1.6, 1.6, 0.5],
        [3.0, 0.5, 0.5],
        [0.2, 0.1, 0.2],
        [0.5, 0.5, -1.5],
    ];
    let normals: Vec<[f32; 3]> = vec![
        [-0.7, -0.7, 0.14],
        [-1.0, 0.1, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let k = 20_000;
    for (s, lights) in scenes.iter().enumerate() {
        let scene = Evaluator::cpu().prepare(lights).unwrap();
        let per = scene
            .irradiance(&points, &normals, Accumulate::PerLight)
            .unwrap();
        for selection in [Selection::Bound, Selection::Power, Selection::Exact] {
            let opts = SampleOptions {
                seed: 23,
                selection,
                first_point: 0,
            };
            let out = scene.sample(&points, Some(&normals), k, &opts).unwrap();
            let pdfs = scene
                .pdf(
                    &points
                        .iter()
                        .flat_map(|p| std::iter::repeat_n(*p, k))
                        .collect::<Vec<_>>(),
                    Some(
                        &normals
                            .iter()
                            .flat_map(|n| std::iter::repeat_n(*n, k))
                            .collect::<Vec<_>>(),
                    ),
                    &out.dirs,
                    selection,
                    Accumulate::PerLight,
                )
                .unwrap();
            let m = points.len() * k;
            let mut off = 0;
            for (i, x) in points.iter().enumerate() {
                let n = DVec3::from_array(normals[i].map(f64::from)).normalize();
                let exact: f64 = (0..lights.len())
                    .map(|l| luma(per[l * points.len() + i]))
                    .sum();
                let (mut s1, mut s2) = (0.0, 0.0);
                for j in 0..k {
                    let r = i * k + j;
                    let d = DVec3::from_array(out.dirs[r].map(f64::from));
                    let f = luma(out.radiance[r]) * n.dot(d).max(0.0);
                    let v = if out.pdf[r] > 0.0 {
                        f / out.pdf[r] as f64
                    } else {
                        assert_eq!(f, 0.0, "scene {s}: light at pdf 0");
                        0.0
                    };
                    s1 += v;
                    s2 += v * v;
                    // A row's pdf is its light's `P(l | x) · pdf_l`: the per-light query's row.
                    let l = out.light[r];
                    if l >= 0 {
                        let (a, b) = (out.pdf[r] as f64, pdfs[l as usize * m + r] as f64);
                        if (a - b).abs() > 1e-4 * a.max(b) {
                            off += 1;
                        }
                    }
                }
                let mean = s1 / k as f64;
                let se = ((s2 / k as f64 - mean * mean).max(0.0) / k as f64).sqrt();
                eprintln!(
                    "scene {s} {selection:?} at {x:?}: mean {mean:.5} ± {se:.1e}, exact {exact:.5}"
                );
                assert!(exact > 0.0, "scene {s} at {x:?}: unlit receiver");
                assert!(
                    (mean - exact).abs() <= 5.0 * se + 1e-5 * exact,
                    "scene {s} ({selection:?}) at {x:?}: mean {mean} ± {se}, exact {exact}"
                );
            }
            // The query's density is the draw's, but for directions that graze an edge shared
            // by two triangles (the f32 direction crosses one of them, the f64 one the other).
            eprintln!("scene {s} {selection:?}: {off} of {m} rows' pdf differ from the query's");
            assert!(off * 10_000 <= m, "scene {s}: {off} rows off");
        }
    }
}
