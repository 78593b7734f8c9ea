//! luxtest A11 (reference/luxtest.md §6): the 10 m floor under the rect, sphere, disk and
//! cylinder scenes at frames 1–15 and the distant scene at frames 1–5, irradiance at the pixel
//! centres of a 512 × 512 map of the floor (y = 0, x and z in [−5, 5], normal +Y), GPU against
//! the f64 CPU reference within check::TOLERANCE.
//!
//! Pixels where f32 legitimately cannot resolve 1e-4 (check::irradiance_margin: a light seen as
//! a sliver at the floor's horizon or its own plane, a receiver on the light) are counted, not
//! compared. On llvmpipe (CI's CPU Vulkan driver, ~10 s per 512² frame) the test takes every
//! 4th pixel centre in each direction of the same grid (128 × 128 per frame); on any other
//! adapter, or with LUXEVAL_A11_FULL=1, all 512 × 512.
#![cfg(feature = "usd")]

use crate::common;

use std::path::Path;

use glam::DVec3;
use luxeval::FalloffPlane as Plane;
use luxeval::testkit::check::{self, BAND, TOLERANCE};
use luxeval::{Accumulate, Reference, Stage, TemperatureMode};

fn dvec(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

#[test]
fn a11_floor_maps_gpu_match_cpu() {
    let Some(eval) = common::gpu() else { return };
    let full =
        !common::is_llvmpipe(&eval) || std::env::var("LUXEVAL_A11_FULL").is_ok_and(|v| v == "1");
    let device = eval.device_name();
    let stride = if full { 1 } else { 4 };
    let plane = Plane::new(
        DVec3::new(-5.0, 0.0, 5.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -10.0),
        512,
        512,
    )
    .unwrap();
    let normal = plane.normal();
    assert_eq!(normal, DVec3::Y);
    let points: Vec<[f32; 3]> = (0..512)
        .step_by(stride)
        .flat_map(|j| (0..512).step_by(stride).map(move |i| (i, j)))
        .map(|(i, j)| plane.pixel_centre(i, j).as_vec3().to_array())
        .collect();
    let normals = vec![normal.as_vec3().to_array(); points.len()];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/luxtest/usd");
    let (mut compared, mut excluded, mut lit, mut frames) = (0usize, 0usize, 0usize, 0usize);
    let mut worst = (0.0f64, String::new());
    for (name, last) in [
        ("rect", 15),
        ("sphere", 15),
        ("disk", 15),
        ("cylinder", 15),
        ("distant", 5),
    ] {
        for frame in 1..=last {
            let scene = Stage::load(&dir.join(format!("{name}.usda")), Some(frame as f64))
                .unwrap_or_else(|e| panic!("{name} frame {frame}: {e}"));
            let lights = scene.evaluable(&[]).expect("evaluable lights");
            assert!(!lights.is_empty(), "{name} frame {frame}: no light");
            let refs: Vec<Reference> = lights
                .iter()
                .map(|l| Reference::new(l, TemperatureMode::Spec).unwrap())
                .collect();
            let gpu = eval
                .irradiance(&lights, &points, &normals, Accumulate::PerLight)
                .unwrap();
            frames += 1;
            for (l, p) in refs.iter().enumerate() {
                let cpu: Vec<DVec3> = {
                    use rayon::prelude::*;
                    points
                        .par_iter()
                        .map(|x| p.irradiance(dvec(*x), normal))
                        .collect()
                };
                for (i, x) in points.iter().enumerate() {
                    let k = l * points.len() + i;
                    if check::irradiance_margin(p, dvec(*x), normal) < BAND {
                        excluded += 1;
                        continue;
                    }
                    compared += 1;
                    if cpu[i].max_element() > 0.0 {
                        lit += 1;
                    }
                    let err = check::rel_error(cpu[i], gpu[k]);
                    if err > worst.0 {
                        worst = (
                            err,
                            format!(
                                "{name} frame {frame} {} at {x:?}: cpu {} gpu {:?}",
                                p.light().path,
                                cpu[i],
                                gpu[k]
                            ),
                        );
                    }
                }
            }
        }
    }
    println!(
        "A11 on {device}: {frames} frames × {} pixel centres (stride {stride}); {compared} compared ({lit} lit), {excluded} excluded; worst {:.3e}: {}",
        points.len(),
        worst.0,
        worst.1
    );
    assert_eq!(frames, 65);
    assert!(lit * 2 > compared, "only {lit} of {compared} lit");
    assert!(
        excluded * 100 < compared,
        "{excluded} excluded of {compared}"
    );
    assert!(worst.0 <= TOLERANCE, "worst {:.3e}: {}", worst.0, worst.1);
}
