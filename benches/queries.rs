//! Criterion benchmarks of the queries on the GPU and the CPU reference:
//! `cargo bench --ignore-rust-version --bench queries`. For a one-shot table with the GPU/CPU
//! ratio, use `luxeval bench`.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use luxeval::testkit::{Rng, synthetic_lights};
use luxeval::{Accumulate, Evaluator};

fn queries(c: &mut Criterion) {
    let lights = synthetic_lights(16);
    let mut rng = Rng::new(7);
    let n = 1 << 18;
    let dirs: Vec<[f32; 3]> = (0..n).map(|_| rng.unit().as_vec3().to_array()).collect();
    let points: Vec<[f32; 3]> = (0..n)
        .map(|_| (rng.unit() * rng.range(0.5, 6.0)).as_vec3().to_array())
        .collect();
    let mut evals = vec![("cpu", Evaluator::cpu(), n / 16)];
    match Evaluator::gpu() {
        Ok(g) => evals.push(("gpu", g, n)),
        Err(e) => eprintln!("no GPU adapter ({e}); benchmarking the CPU only"),
    }
    let mut group = c.benchmark_group("queries");
    group.sample_size(10);
    for (name, eval, m) in &evals {
        group.throughput(Throughput::Elements((m * lights.len()) as u64));
        group.bench_with_input(BenchmarkId::new("emission", name), m, |b, &m| {
            b.iter(|| {
                eval.emission(&lights, &dirs[..m], Accumulate::Sum)
                    .expect("emission")
            })
        });
        group.bench_with_input(BenchmarkId::new("radiance", name), m, |b, &m| {
            b.iter(|| {
                eval.radiance(&lights, &points[..m], &dirs[..m], Accumulate::Sum)
                    .expect("radiance")
            })
        });
        // Irradiance: a quadrature per (light, receiver), on 1/64 of the samples.
        let mi = (m / 64).max(1);
        group.throughput(Throughput::Elements((mi * lights.len()) as u64));
        group.bench_with_input(BenchmarkId::new("irradiance", name), &mi, |b, &mi| {
            b.iter(|| {
                eval.irradiance(&lights, &points[..mi], &dirs[..mi], Accumulate::Sum)
                    .expect("irradiance")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, queries);
criterion_main!(benches);
