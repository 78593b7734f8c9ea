//! `luxeval bench`: throughput of the GPU and CPU paths of every query, measured in one run so
//! that the GPU/CPU ratio is meaningful on this machine. Times are end to end (upload, dispatch,
//! readback for the GPU; the rayon-parallel f64 reference for the CPU).

use std::time::{Duration, Instant};

use clap::Args;

use luxeval::{Accumulate, Evaluator};
use luxeval::{Rng, synthetic_lights};

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
    /// Triangles of the synthetic mesh light (a bumpy torus) whose preparation, radiance and
    /// exact irradiance are timed.
    #[arg(long, default_value_t = 100_000)]
    mesh_triangles: usize,
    /// Skip the mesh-light measurement.
    #[arg(long)]
    no_mesh: bool,
    /// Skip the cold-start measurement (two child processes that open the GPU and compile every
    /// pipeline, without and with the pipeline cache).
    #[arg(long)]
    no_startup: bool,
    /// Also measure throughput over every combination of --sweep-samples and --sweep-lights
    /// (irradiance on 1/64 of the samples), on the GPU and the CPU.
    #[arg(long)]
    sweep: bool,
    /// Sample counts of the sweep.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1000,10000,100000,1000000,10000000"
    )]
    sweep_samples: Vec<usize>,
    /// Light counts of the sweep.
    #[arg(long, value_delimiter = ',', default_value = "1,8,64")]
    sweep_lights: Vec<usize>,
    /// Also time this luxeval command line as a whole process, with `--device gpu` and with
    /// `--device cpu`, alternately, `min(--repeat, 3)` times each: wall time and peak RSS (e.g.
    /// "falloff scene.usda --res 1024,1024 -o map.exr"). Split at whitespace, no quoting; the
    /// bench adds `--device`. Repeatable.
    #[arg(long = "command", value_name = "ARGS")]
    commands: Vec<String>,
    /// The child process of the cold-start measurement (internal).
    #[arg(long = "startup-probe", hide = true)]
    startup_probe: bool,
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
        // A texture luxeval would refuse to load is not written in the first place.
        (Some(w), Some(h)) if u64::from(w) * u64::from(h) > luxeval::MAX_TEXTURE_PIXELS => {
            Err(format!(
                "{s:?}: {} pixels, over the {} a texture may have",
                u64::from(w) * u64::from(h),
                luxeval::MAX_TEXTURE_PIXELS
            ))
        }
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!(
            "{s:?}: width and height must be integers from 1 to 65536"
        )),
    }
}

#[derive(serde::Serialize)]
struct Report {
    queries: Vec<Row>,
    /// GPU/CPU throughput per query (same run).
    ratios: Vec<(String, f64)>,
    /// Warm latency: one call of 1,000 samples on a prepared scene (median).
    latency: Vec<Row>,
    startup: Vec<crate::bench_startup::StartupRow>,
    /// `--command`: whole processes, spawn to exit, on each device.
    commands: Vec<crate::bench_command::CommandRow>,
    /// Per `--command` measured on both devices: CPU time ÷ GPU time.
    command_speedups: Vec<(String, f64)>,
    sweep: Vec<Row>,
    dome: Vec<crate::bench_dome::DomeRow>,
    /// The mesh light's preparation, radiance and irradiance on each device.
    mesh: Vec<crate::bench_mesh::MeshRow>,
    /// This process's peak resident set (Linux VmHWM), bytes.
    peak_rss_bytes: Option<u64>,
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

/// The middle value of `v` (the upper one of an even count); `v` is not empty.
pub fn median<T: Copy + PartialOrd>(mut v: Vec<T>) -> T {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
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

/// Latency is measured on this many samples.
const LATENCY_SAMPLES: usize = 1000;

/// One timed measurement of `query` on `m` samples of `dirs`/`points` with `lights` lights.
fn measure(
    eval: &Evaluator,
    lights: &[luxeval::Light],
    query: &'static str,
    dirs: &[[f32; 3]],
    points: &[[f32; 3]],
    repeat: usize,
) -> luxeval::Result<Row> {
    // The scene is prepared once (as a renderer or the CLI would) and its buffers reused.
    let scene = eval.prepare(lights)?;
    let m = dirs.len();
    let t = time(repeat, || {
        match query {
            "emission" => scene.emission(dirs, Accumulate::Sum)?,
            "radiance" => scene.radiance(points, dirs, Accumulate::Sum)?,
            _ => scene.irradiance(points, dirs, Accumulate::Sum)?,
        };
        Ok(())
    })?;
    Ok(Row {
        query,
        device: eval.device_name(),
        lights: lights.len(),
        samples: m,
        median_seconds: t.as_secs_f64(),
        evals_per_second: (m * lights.len()) as f64 / t.as_secs_f64(),
    })
}

/// The peak resident set of this process (Linux), bytes.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

pub fn run(args: BenchArgs) -> CliResult {
    if args.startup_probe {
        return crate::bench_startup::probe();
    }
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
            luxeval::Limits::raise_hint(luxeval::Limits::ENV_MAX_PRIMS)
        )));
    }
    if !args.no_mesh
        && (args.mesh_triangles < 18 || args.mesh_triangles as u64 > limits.max_mesh_triangles)
    {
        return Err(Failure::bad_input(format!(
            "--mesh-triangles {} must be from 18 (the smallest torus) to the limit of {} ({})",
            args.mesh_triangles,
            limits.max_mesh_triangles,
            luxeval::Limits::raise_hint(luxeval::Limits::ENV_MAX_MESH_TRIANGLES)
        )));
    }
    if args.repeat > MAX_REPEAT {
        return Err(Failure::bad_input(format!(
            "--repeat {} exceeds {MAX_REPEAT}: a median of that many runs is already stable",
            args.repeat
        )));
    }
    if args.sweep {
        for &m in &args.sweep_samples {
            limits.check_samples("--sweep-samples", m as u64)?;
        }
        if args.sweep_samples.contains(&0) || args.sweep_lights.contains(&0) {
            return Err(Failure::bad_input(
                "--sweep-samples and --sweep-lights must be at least 1",
            ));
        }
        if let Some(&l) = args
            .sweep_lights
            .iter()
            .find(|&&l| l as u64 > limits.max_prims)
        {
            return Err(Failure::bad_input(format!(
                "--sweep-lights {l} exceeds the limit of {} ({})",
                limits.max_prims,
                luxeval::Limits::raise_hint(luxeval::Limits::ENV_MAX_PRIMS)
            )));
        }
    }
    let commands = args
        .commands
        .iter()
        .map(|c| crate::bench_command::parse(c))
        .collect::<Result<Vec<_>, _>>()
        .map_err(Failure::bad_input)?;
    // Cold start first, in child processes, before this process has touched the GPU.
    let startup = if args.no_startup {
        Vec::new()
    } else {
        eprintln!("bench: cold start (two child processes) …");
        match crate::bench_startup::measure() {
            Ok(rows) => rows,
            Err(e) => {
                eprintln!("warning: {}; no cold-start figures", e.message);
                Vec::new()
            }
        }
    };
    let mut evaluators = vec![(Evaluator::cpu(), args.cpu_samples)];
    match Evaluator::gpu() {
        Ok(g) => evaluators.insert(0, (g, args.samples)),
        Err(e) => eprintln!("warning: no GPU ({e}); measuring the CPU only"),
    }
    // Whole commands next, while this process holds no large arrays.
    let devices: &[&'static str] = if evaluators.len() == 2 {
        &["gpu", "cpu"]
    } else {
        &["cpu"]
    };
    let command_rows = crate::bench_command::measure(&commands, devices, args.repeat.min(3))?;
    let command_speedups = crate::bench_command::speedups(&command_rows);
    let lights = synthetic_lights(args.lights);
    let mut rng = Rng::new(7);
    let sweep_max = if args.sweep {
        args.sweep_samples.iter().copied().max().unwrap_or(0)
    } else {
        0
    };
    let n = args.samples.max(args.cpu_samples).max(sweep_max);
    let dirs: Vec<[f32; 3]> = (0..n).map(|_| rng.unit().as_vec3().to_array()).collect();
    let points: Vec<[f32; 3]> = (0..n)
        .map(|_| (rng.unit() * rng.range(0.5, 6.0)).as_vec3().to_array())
        .collect();

    // Irradiance is a quadrature per (light, receiver): 1/IRRADIANCE_SHARE of the samples.
    let share = |query: &str, m: usize| {
        if query == "irradiance" {
            (m / IRRADIANCE_SHARE).max(1)
        } else {
            m
        }
    };
    let mut rows = Vec::new();
    let mut latency = Vec::new();
    for (eval, m) in &evaluators {
        for query in QUERIES {
            let m = share(query, *m);
            eprintln!("bench: {query} on {} …", eval.device_name());
            rows.push(measure(
                eval,
                &lights,
                query,
                &dirs[..m],
                &points[..m],
                args.repeat,
            )?);
            let k = LATENCY_SAMPLES.min(n);
            latency.push(measure(
                eval,
                &lights,
                query,
                &dirs[..k],
                &points[..k],
                args.repeat.max(20),
            )?);
        }
    }
    let mut sweep = Vec::new();
    if args.sweep {
        for (eval, _) in &evaluators {
            for &l in &args.sweep_lights {
                let set = synthetic_lights(l);
                for &m in &args.sweep_samples {
                    for query in QUERIES {
                        let m = share(query, m);
                        eprintln!(
                            "bench: sweep {query}, {l} lights × {m} samples on {} …",
                            eval.device_name()
                        );
                        sweep.push(measure(
                            eval,
                            &set,
                            query,
                            &dirs[..m],
                            &points[..m],
                            args.repeat.min(3),
                        )?);
                    }
                }
            }
        }
    }
    let ratios: Vec<(String, f64)> = QUERIES
        .iter()
        .filter_map(|&query| {
            let g = rows
                .iter()
                .find(|r| r.query == query && !r.device.starts_with("cpu"))?;
            let c = rows
                .iter()
                .find(|r| r.query == query && r.device.starts_with("cpu"))?;
            Some((query.to_string(), g.evals_per_second / c.evals_per_second))
        })
        .collect();
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
    let mesh = if args.no_mesh {
        Vec::new()
    } else {
        let on: Vec<(Evaluator, usize)> = evaluators
            .iter()
            .map(|(e, m)| (e.clone(), (*m).min(1 << 20)))
            .collect();
        crate::bench_mesh::run(&on, args.mesh_triangles, args.repeat.min(3))?
    };
    if args.json {
        let report = Report {
            queries: rows,
            ratios,
            latency,
            startup,
            commands: command_rows,
            command_speedups,
            sweep,
            dome,
            mesh,
            peak_rss_bytes: peak_rss(),
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
    for r in rows.iter().chain(&sweep) {
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
    for r in &mesh {
        match r.query {
            "prepare" => outln!(
                "mesh light, {} triangles, prepared (BVH included) on {}: median {:.3} s",
                r.triangles,
                r.device,
                r.median_seconds
            ),
            "radiance" => outln!(
                "mesh light, {} triangles, radiance of {} rays on {}: {:.4e} rays/s",
                r.triangles,
                r.samples,
                r.device,
                r.per_second
            ),
            _ => outln!(
                "mesh light, {} triangles, exact irradiance on {}: median {:.1} ms per receiver",
                r.triangles,
                r.device,
                r.median_seconds / r.samples as f64 * 1e3
            ),
        }
    }
    for r in &latency {
        outln!(
            "warm latency, {} × {} samples, {} on {}: median {:.3} ms",
            r.lights,
            r.samples,
            r.query,
            r.device,
            r.median_seconds * 1e3
        );
    }
    for s in &startup {
        let p = &s.probe;
        let pipelines: Vec<String> = p
            .pipelines
            .iter()
            .map(|(n, t)| format!("{n} {t:.3} s"))
            .collect();
        outln!(
            "cold start {} ({} bytes loaded): process {:.3} s; instance {:.3} s, adapter {:.3} s, device {:.3} s; pipelines: {}",
            s.cache,
            p.cache_loaded_bytes,
            s.process_seconds,
            p.instance_seconds,
            p.adapter_seconds,
            p.device_seconds,
            pipelines.join(", ")
        );
    }
    for c in &command_rows {
        let rss = c.peak_rss_bytes.map_or("n/a".to_string(), |b| {
            format!("{:.0} MiB", b as f64 / (1 << 20) as f64)
        });
        outln!(
            "command `luxeval {} --device {}`: median {:.3} s wall of {} runs, peak RSS {rss}",
            c.command,
            c.device,
            c.median_seconds,
            c.runs_seconds.len()
        );
    }
    for (command, speedup) in &command_speedups {
        outln!("command `luxeval {command}`: the GPU path {speedup:.2}× as fast as the CPU path");
    }
    for (query, ratio) in &ratios {
        outln!("{query}: GPU/CPU throughput ratio {ratio:.2}× (same run)");
    }
    if let Some(rss) = peak_rss() {
        outln!(
            "peak RSS of this process: {:.0} MiB",
            rss as f64 / (1 << 20) as f64
        );
    }
    Ok(())
}
