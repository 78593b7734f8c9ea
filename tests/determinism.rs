//! Device faults and determinism (docs/INPUTS.md "Devices"): repeated runs on one adapter give
//! bitwise identical outputs, through the library and through the CLI; directions whose float32
//! components are subnormal or near 1e38 give the CPU reference's answer on the GPU too.

use crate::common;

use luxeval::testkit::{Rng, synthetic_lights};
use luxeval::{Accumulate, Evaluator};

fn samples(n: usize, seed: u64) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut rng = Rng::new(seed);
    let dirs = (0..n).map(|_| rng.unit().as_vec3().to_array()).collect();
    let points = (0..n)
        .map(|_| (rng.unit() * rng.range(0.5, 6.0)).as_vec3().to_array())
        .collect();
    (dirs, points)
}

fn bits(rows: &[[f32; 3]]) -> Vec<u32> {
    rows.iter().flatten().map(|v| v.to_bits()).collect()
}

#[test]
fn repeated_runs_on_one_adapter_are_bitwise_identical() {
    let lights = synthetic_lights(12);
    let (dirs, points) = samples(3000, 5);
    let (pi, ni) = (&points[..64], &dirs[..64]);
    let mut evaluators = vec![Evaluator::cpu()];
    if let Some(g) = common::gpu() {
        evaluators.push(g);
        // A second device on the same adapter: nothing may depend on the device's history.
        evaluators.push(Evaluator::gpu().unwrap());
    }
    for acc in [Accumulate::Sum, Accumulate::PerLight] {
        let mut first: Vec<Option<[Vec<u32>; 3]>> = vec![None, None];
        for (k, eval) in evaluators.iter().enumerate() {
            let kind = usize::from(eval.is_gpu());
            let scene = eval.prepare(&lights).unwrap();
            for _ in 0..2 {
                let run = [
                    bits(&scene.emission(&dirs, acc).unwrap()),
                    bits(&scene.radiance(&points, &dirs, acc).unwrap()),
                    bits(&scene.irradiance(pi, ni, acc).unwrap()),
                ];
                match &first[kind] {
                    None => first[kind] = Some(run),
                    Some(want) => {
                        for q in 0..3 {
                            assert!(
                                want[q] == run[q],
                                "{} (evaluator {k}), query {q}, {acc:?}: outputs differ between runs",
                                eval.device_name()
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn subnormal_and_huge_directions_on_the_gpu_match_the_cpu() {
    let Some(gpu) = common::gpu() else { return };
    let lights = synthetic_lights(8);
    let (dirs, points) = samples(256, 9);
    for scale in [1e-40f32, 1e-38, 3e38, 1e38] {
        let scaled: Vec<[f32; 3]> = dirs.iter().map(|d| d.map(|c| c * scale)).collect();
        // Components that underflow to zero would change the direction: keep rows that survive.
        let keep: Vec<usize> = (0..dirs.len())
            .filter(|&i| {
                (0..3).all(|j| (dirs[i][j] == 0.0) == (scaled[i][j] == 0.0))
                    && scaled[i].iter().all(|c| c.is_finite())
            })
            .collect();
        let s: Vec<[f32; 3]> = keep.iter().map(|&i| scaled[i]).collect();
        let p: Vec<[f32; 3]> = keep.iter().map(|&i| points[i]).collect();
        assert!(s.len() > 200, "{scale}: {} rows", s.len());
        for (query, g, c) in [
            (
                "emission",
                gpu.emission(&lights, &s, Accumulate::PerLight).unwrap(),
                Evaluator::cpu()
                    .emission(&lights, &s, Accumulate::PerLight)
                    .unwrap(),
            ),
            (
                "radiance",
                gpu.radiance(&lights, &p, &s, Accumulate::PerLight).unwrap(),
                Evaluator::cpu()
                    .radiance(&lights, &p, &s, Accumulate::PerLight)
                    .unwrap(),
            ),
        ] {
            let mut bad = 0;
            for (a, b) in g.iter().zip(&c) {
                assert!(a.iter().all(|v| v.is_finite()), "{query} {scale}: {a:?}");
                let scale_ref = b.iter().fold(0f32, |m, v| m.max(v.abs()));
                let diff = a.iter().zip(b).fold(0f32, |m, (x, y)| m.max((x - y).abs()));
                // Edges (cone, horizon, silhouettes) may flip; the bulk must agree.
                if diff > 1e-3 * scale_ref.max(1e-20) {
                    bad += 1;
                }
            }
            assert!(
                bad * 100 <= g.len(),
                "{query} at scale {scale}: {bad} of {} rows differ from the CPU",
                g.len()
            );
        }
    }
}
