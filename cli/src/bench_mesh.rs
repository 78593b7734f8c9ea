//! `luxeval bench`'s mesh-light rows (DESIGN.md §7; the targets on the reference
//! machine: preparing a 100,000-triangle mesh light, its BVH included, ≤ 0.5 s; the radiance of
//! 1M rays ≥ 5M rays/s on the CPU path and ≥ 1G rays/s on a real GPU; the exact self-occluded
//! irradiance at one receiver ≤ 50 ms on the CPU path).
//!
//! The light is the synthetic bumpy torus (`luxeval::synthetic_mesh_light`): closed and
//! non-convex, so rays and receivers meet self-occlusion. Rays start on a shell around it and aim
//! at points near its ring (most hit); receivers sit on the same shell with normals toward the
//! centre.

use std::time::Instant;

use luxeval::{Accumulate, Evaluator, Rng, synthetic_mesh_light, torus_rays};

use crate::exit::CliResult;

#[derive(serde::Serialize)]
pub struct MeshRow {
    /// "prepare", "radiance" or "irradiance".
    pub query: &'static str,
    pub device: String,
    pub triangles: usize,
    /// Rays (radiance) or receivers (irradiance) per timed run; 1 for prepare.
    pub samples: usize,
    pub median_seconds: f64,
    /// Rays or receivers per second (prepare: 1 / median).
    pub per_second: f64,
}

/// Receivers per timed irradiance run: each is an exact visibility computation, ~10-100 ms on
/// the reference machine.
const RECEIVERS: usize = 8;

fn median_of(repeat: usize, mut f: impl FnMut() -> luxeval::Result<()>) -> luxeval::Result<f64> {
    f()?; // warm-up: pipelines, allocations
    let mut times = Vec::with_capacity(repeat.max(1));
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(crate::bench::median(times))
}

/// Times one mesh light of about `triangles` triangles on every evaluator (`samples`: the
/// radiance rays of each, as the query rows use).
pub fn run(
    evaluators: &[(Evaluator, usize)],
    triangles: usize,
    repeat: usize,
) -> CliResult<Vec<MeshRow>> {
    let light = synthetic_mesh_light(triangles);
    let tris = match &light.kind {
        luxeval::LightType::Mesh { geometry, .. } => geometry.triangles.len(),
        _ => 0,
    };
    let lights = std::slice::from_ref(&light);
    let mut rows = Vec::new();
    let mut rng = Rng::new(11);
    for (eval, n) in evaluators {
        let device = eval.device_name();
        eprintln!("bench: mesh light of {tris} triangles on {device} …");
        let prepare = median_of(repeat, || eval.prepare(lights).map(drop))?;
        rows.push(MeshRow {
            query: "prepare",
            device: device.clone(),
            triangles: tris,
            samples: 1,
            median_seconds: prepare,
            per_second: 1.0 / prepare,
        });
        let scene = eval.prepare(lights)?;
        let (points, dirs) = torus_rays(*n, &mut rng);
        let t = median_of(repeat, || {
            scene.radiance(&points, &dirs, Accumulate::Sum).map(drop)
        })?;
        rows.push(MeshRow {
            query: "radiance",
            device: device.clone(),
            triangles: tris,
            samples: *n,
            median_seconds: t,
            per_second: *n as f64 / t,
        });
        let receivers: Vec<[f32; 3]> = (0..RECEIVERS)
            .map(|_| (rng.unit() * rng.range(2.5, 4.0)).as_vec3().to_array())
            .collect();
        let normals: Vec<[f32; 3]> = receivers.iter().map(|p| p.map(|c| -c)).collect();
        let t = median_of(repeat.min(3), || {
            scene
                .irradiance(&receivers, &normals, Accumulate::Sum)
                .map(drop)
        })?;
        rows.push(MeshRow {
            query: "irradiance",
            device,
            triangles: tris,
            samples: RECEIVERS,
            median_seconds: t,
            per_second: RECEIVERS as f64 / t,
        });
    }
    Ok(rows)
}
