//! Mesh lights end to end (DESIGN.md §7): every query command evaluates the neon ring stage
//! (`assets/neon_ring.usda`) as the library does, bit for bit; `check` says a mesh light is not
//! compared (the CPU reference answers it on every device); `sample` draws from it.

use crate::support::*;

use luxeval::{Accumulate, Evaluator, Stage};
use luxeval_cli::io::npy;

#[test]
fn every_query_command_evaluates_a_mesh_light_as_the_library_does() {
    let dir = tempfile::tempdir().unwrap();
    let scene = asset("neon_ring.usda");
    let lights = Stage::load(std::path::Path::new(&scene), None)
        .unwrap()
        .evaluable(&[])
        .unwrap();
    assert_eq!(lights.len(), 1);
    let lib = Evaluator::cpu().prepare(&lights).unwrap();
    // Receivers on the floor under and beside the ring, facing up; directions from them
    // toward the tube.
    let pts: Vec<[f32; 3]> = (0..16)
        .map(|i| [-3.0 + 0.4 * i as f32, 0.0, 0.25 * i as f32 - 2.0])
        .collect();
    let up = vec![[0.0f32, 1.0, 0.0]; pts.len()];
    let dirs: Vec<[f32; 3]> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let a = i as f32 * 0.4;
            [2.0 * a.cos() - p[0], 1.2 - p[1], 2.0 * a.sin() - p[2]]
        })
        .collect();
    let (p, n, d) = (
        dir.path().join("p.npy"),
        dir.path().join("n.npy"),
        dir.path().join("d.npy"),
    );
    npy::write_f32(&p, &[16, 3], &pts).unwrap();
    npy::write_f32(&n, &[16, 3], &up).unwrap();
    npy::write_f32(&d, &[16, 3], &dirs).unwrap();
    let run = |args: &[&str], out: &str| -> Vec<f32> {
        let o = dir.path().join(out);
        let mut all: Vec<&str> = args.to_vec();
        all.extend([
            "-o",
            o.to_str().unwrap(),
            "--device",
            "cpu",
            "--tolerance",
            "1e-9",
        ]);
        if !matches!(args[0], "irradiance") {
            all.truncate(all.len() - 2);
        }
        let r = luxeval(&all);
        assert!(r.status.success(), "{args:?}: {}", stderr(&r));
        read_npy_f32(&o).1
    };
    let flat = |v: Vec<[f32; 3]>| v.into_iter().flatten().collect::<Vec<f32>>();
    let (ps, ns, ds) = (
        p.to_str().unwrap(),
        n.to_str().unwrap(),
        d.to_str().unwrap(),
    );
    let e = run(
        &["irradiance", &scene, "--points", ps, "--normals", ns],
        "e.npy",
    );
    assert_eq!(e, flat(lib.irradiance(&pts, &up, Accumulate::Sum).unwrap()));
    assert!(e.iter().filter(|v| **v > 0.0).count() >= 30, "{e:?}");
    let l = run(&["radiance", &scene, "--points", ps, "--dirs", ds], "l.npy");
    assert_eq!(l, flat(lib.radiance(&pts, &dirs, Accumulate::Sum).unwrap()));
    assert!(l.iter().any(|v| *v > 0.0));
    let em = run(&["emission", &scene, "--dirs", ds], "em.npy");
    assert_eq!(em, flat(lib.emission(&dirs, Accumulate::Sum).unwrap()));
    let i = run(&["intensity", &scene, "--dirs", ds], "i.npy");
    assert_eq!(i, flat(lib.intensity(&dirs, Accumulate::Sum).unwrap()));
    assert!(i.iter().any(|v| *v > 0.0));

    // Sampling draws from the mesh light.
    let npz = dir.path().join("s.npz");
    let r = luxeval(&[
        "sample",
        &scene,
        "--points",
        ps,
        "--normals",
        ns,
        "--count",
        "8",
        "-o",
        npz.to_str().unwrap(),
        "--device",
        "cpu",
    ]);
    assert!(r.status.success(), "{}", stderr(&r));
}

#[test]
fn check_says_a_mesh_light_is_not_compared() {
    if crate::common::gpu().is_none() {
        return;
    }
    let o = luxeval(&["check", &asset("neon_ring.usda"), "--samples", "20"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("/NeonRing: not compared: it is a mesh light") && text.contains("radiance"),
        "{text}"
    );
    // Emission and radiance run on the device (GpuPath::HostIntensity): both rows compared.
    for q in ["emission", "radiance"] {
        assert!(
            text.lines()
                .any(|l| l.contains(" Mesh ") && l.contains(q) && l.trim_end().ends_with("ok")),
            "{q}: {text}"
        );
    }
    assert!(
        !text
            .lines()
            .any(|l| l.contains(" Mesh ") && l.contains("intensity"))
    );
}
