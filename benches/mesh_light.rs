//! Criterion benchmarks of a mesh light (DESIGN.md §7) on the CPU reference, at the sizes of
//! issue "Mesh lights and portals": preparing a 100,000-triangle mesh light (its BVH included),
//! the radiance of 1,000,000 rays against it (and on a GPU evaluator, where one opens), and its
//! exact self-occluded irradiance at one receiver.
//! `cargo bench --ignore-rust-version --features testkit --bench mesh_light`.
//!
//! The mesh is the synthetic bumpy torus (`testkit::torus`, 250 × 200 quads, fronts outward; the
//! one `luxeval bench` times): non-convex, so rays and receivers meet self-occlusion.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DMat4;
use luxeval::testkit::{Rng, torus, torus_rays};
use luxeval::{Accumulate, Evaluator, Light};

fn mesh_light(c: &mut Criterion) {
    let geometry = torus(250, 200).geometry(DMat4::IDENTITY);
    assert_eq!(geometry.triangles.len(), 100_000);
    let light = Light::mesh(geometry);
    let cpu = Evaluator::cpu();
    let mut group = c.benchmark_group("mesh_light");
    group.sample_size(10);
    group.bench_function("prepare 100k triangles", |b| {
        b.iter(|| cpu.prepare(std::slice::from_ref(&light)).expect("prepare"))
    });
    let scene = cpu.prepare(std::slice::from_ref(&light)).expect("prepare");
    let mut rng = Rng::new(3);
    let n = 1_000_000;
    // Rays from a shell around the torus toward points near it: most hit.
    let (points, dirs) = torus_rays(n, &mut rng);
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function("radiance 1M rays", |b| {
        b.iter(|| {
            scene
                .radiance(&points, &dirs, Accumulate::Sum)
                .expect("radiance")
        })
    });
    // The same rays on a GPU evaluator, where there is one (the kernel traverses the BVH on
    // the device: GpuPath::HostIntensity or RadianceOnDevice); Mesa's lavapipe proves it runs,
    // not its speed.
    match Evaluator::gpu() {
        Ok(g) => {
            let dev = g
                .prepare(std::slice::from_ref(&light))
                .expect("prepare on the GPU");
            group.bench_function("radiance 1M rays on the GPU", |b| {
                b.iter(|| {
                    dev.radiance(&points, &dirs, Accumulate::Sum)
                        .expect("radiance")
                })
            });
        }
        Err(e) => eprintln!("no GPU adapter ({e}): the GPU radiance is not measured"),
    }
    group.throughput(Throughput::Elements(1));
    // A receiver inside the ring, above the torus' plane, facing down into it.
    let x = [[0.5f32, 1.0, 0.3]];
    let nrm = [[0.0f32, -1.0, 0.0]];
    group.bench_function("irradiance at one receiver", |b| {
        b.iter(|| {
            scene
                .irradiance(&x, &nrm, Accumulate::Sum)
                .expect("irradiance")
        })
    });
    group.finish();
}

criterion_group!(benches, mesh_light);
criterion_main!(benches);
