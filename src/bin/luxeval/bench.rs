//! `luxeval bench`: throughput of the GPU and CPU paths of every query, measured in one run so
//! that the GPU/CPU ratio is meaningful on this machine. Times are end to end (upload, dispatch,
//! readback for the GPU; the rayon-parallel f64 reference for the CPU).

use std::time::{Duration, Instant};

use clap::Args;

use luxeval::testkit::{Rng, synthetic_lights};
use luxeval::{Accumulate, Evaluator};

use crate::exit::{CliResult, Failure};

#[derive(Args)]
pub struct BenchArgs {
    /// Samples per GPU run (irradiance: 1/64 of them).
    #[arg(long, default_value_t = 1 << 20)]
    samples: usize,
    /// Samples per CPU run (the reference is slower; throughput is per sample).
    #[arg(long, default_value_t = 1 << 16)]
    cpu_samples: usize,
    /// Lights in the synthetic scene (a mix of every analytic type, shaped and not).
    #[arg(long, default_value_t = 16)]
    lights: usize,
    /// Timed repetitions per measurement; the median is reported.
    #[arg(long, default_value_t = 5)]
    repeat: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Time preparing this dome texture instead of a generated lat-long EXR.
    #[arg(long, value_name = "FILE")]
    dome_texture: Option<std::path::PathBuf>,
    /// Size of the generated dome EXR (WxH).
    #[arg(long, value_name = "WxH", default_value = "8192x4096", value_parser = parse_size)]
    dome_size: (u32, u32),
    /// Skip the dome measurement.
    #[arg(long)]
    no_dome: bool,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: expected WxH, e.g. 8192x4096"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| (1..=65536).contains(&v))
    };
    match (p(w), p(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!(
            "{s:?}: width and height must be integers from 1 to 65536"
        )),
    }
}

#[derive(serde::Serialize)]
struct Report {
    queries: Vec<Row>,
    dome: Vec<crate::bench_dome::DomeRow>,
}

#[derive(serde::Serialize)]
struct Row {
    query: &'static str,
    device: String,
    lights: usize,
    samples: usize,
    median_seconds: f64,
    /// (light, sample) evaluations per second.
    evals_per_second: f64,
}

/// The most timed repetitions (more would only make `bench` look hung).
const MAX_REPEAT: usize = 1000;

const QUERIES: [&str; 3] = ["emission", "radiance", "irradiance"];

/// Irradiance runs on this fraction of the samples (random receivers near the lights, random
/// normals).
const IRRADIANCE_SHARE: usize = 64;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time(repeat: usize, mut f: impl FnMut() -> luxeval::Result<()>) -> luxeval::Result<Duration> {
    f()?; // warm-up: pipelines, allocations, caches
    let mut times = Vec::with_capacity(repeat);
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed());
    }
    Ok(median(times))
}

pub fn run(args: BenchArgs) -> CliResult {
    if args.samples == 0 || args.cpu_samples == 0 || args.lights == 0 {
        return Err(Failure {
            code: 2,
            message: "--samples, --cpu-samples and --lights must be at least 1".into(),
        });
    }
    let limits = luxeval::Limits::from_env()?;
    limits.check_samples("--samples", args.samples as u64)?;
    limits.check_samples("--cpu-samples", args.cpu_samples as u64)?;
    // A stage composes to at most max_prims prims, so it has at most that many lights.
    if args.lights as u64 > limits.max_prims {
        return Err(Failure::bad_input(format!(
            "--lights {} exceeds the limit of {} ({})",
            args.lights,
            limits.max_prims,
            luxeval::limits::raise_hint(luxeval::limits::ENV_MAX_PRIMS)
        )));
    }
    if args.repeat > MAX_REPEAT {
        return Err(Failure::bad_input(format!(
            "--repeat {} exceeds {MAX_REPEAT}: a median of that many runs is already stable",
            args.repeat
        )));
    }
    let lights = synthetic_lights(args.lights);
    let mut rng = Rng::new(7);
    let n = args.samples.max(args.cpu_samples);
    let dirs: Vec<[f32; 3]> = (0..n).map(|_| rng.unit().as_vec3().to_array()).collect();
    let points: Vec<[f32; 3]> = (0..n)
        .map(|_| (rng.unit() * rng.range(0.5, 6.0)).as_vec3().to_array())
        .collect();

    let mut evaluators = vec![(Evaluator::cpu(), args.cpu_samples)];
    match Evaluator::gpu() {
        Ok(g) => evaluators.insert(0, (g, args.samples)),
        Err(e) => eprintln!("warning: no GPU ({e}); measuring the CPU only"),
    }
    let mut rows = Vec::new();
    for (eval, m) in &evaluators {
        let (d, p) = (&dirs[..*m], &points[..*m]);
        for query in QUERIES {
            // Irradiance is a quadrature per (light, receiver): 1/IRRADIANCE_SHARE of the samples.
            let m = if query == "irradiance" {
                (*m / IRRADIANCE_SHARE).max(1)
            } else {
                *m
            };
            let (d, p) = (&d[..m], &p[..m]);
            let t = time(args.repeat, || {
                match query {
                    "emission" => eval.emission(&lights, d, Accumulate::Sum)?,
                    "radiance" => eval.radiance(&lights, p, d, Accumulate::Sum)?,
                    _ => eval.irradiance(&lights, p, d, Accumulate::Sum)?,
                };
                Ok(())
            })?;
            rows.push(Row {
                query,
                device: eval.device_name(),
                lights: lights.len(),
                samples: m,
                median_seconds: t.as_secs_f64(),
                evals_per_second: (m * lights.len()) as f64 / t.as_secs_f64(),
            });
        }
    }
    let evals: Vec<Evaluator> = evaluators.iter().map(|(e, _)| e.clone()).collect();
    let dome = if args.no_dome {
        Vec::new()
    } else {
        crate::bench_dome::run(
            &evals,
            args.dome_texture.as_deref(),
            args.dome_size,
            args.repeat.min(3),
        )?
    };
    if args.json {
        let report = Report {
            queries: rows,
            dome,
        };
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| Failure::runtime(e.to_string()))?
        );
        return Ok(());
    }
    outln!(
        "{:<10} {:<44} {:>7} {:>9} {:>12} {:>16}",
        "query",
        "device",
        "lights",
        "samples",
        "median s",
        "evals/s"
    );
    for r in &rows {
        outln!(
            "{:<10} {:<44} {:>7} {:>9} {:>12.6} {:>16.4e}",
            r.query,
            r.device,
            r.lights,
            r.samples,
            r.median_seconds,
            r.evals_per_second
        );
    }
    for d in &dome {
        outln!(
            "dome texture {} × {} from file to prepared scene on {}: median {:.3} s wall, {} CPU",
            d.width,
            d.height,
            d.device,
            d.wall_seconds,
            d.cpu_seconds
                .map_or("n/a".to_string(), |c| format!("{c:.2} s"))
        );
    }
    if evaluators.len() == 2 {
        for query in QUERIES {
            let g = rows
                .iter()
                .find(|r| r.query == query && !r.device.starts_with("cpu"));
            let c = rows
                .iter()
                .find(|r| r.query == query && r.device.starts_with("cpu"));
            if let (Some(g), Some(c)) = (g, c) {
                outln!(
                    "{query}: GPU/CPU throughput ratio {:.1}× (same run)",
                    g.evals_per_second / c.evals_per_second
                );
            }
        }
    }
    Ok(())
}
