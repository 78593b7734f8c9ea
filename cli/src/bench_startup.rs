//! `luxeval bench`'s cold start: a fresh process opens the GPU (instance, adapter, device) and
//! compiles the emission, radiance and irradiance pipelines by running each query once. It runs
//! twice in child processes sharing a new, empty pipeline cache directory (gpu/cache.rs): the
//! first compiles with an empty cache ("without cache"), the second finds the file the first
//! saved ("with cache"). Times inside the child come from `Evaluator::startup`; the parent also
//! times each child's whole life (exec to exit).

use std::process::Command;
use std::time::Instant;

use luxeval::synthetic_lights;
use luxeval::{Accumulate, Evaluator};

use crate::exit::{CliResult, Failure};

/// The hidden flag that makes `luxeval bench` the child.
pub const PROBE_FLAG: &str = "--startup-probe";

#[derive(serde::Serialize, serde::Deserialize)]
pub struct Probe {
    pub instance_seconds: f64,
    pub adapter_seconds: f64,
    pub device_seconds: f64,
    /// Each pipeline compiled, by name, with its compile time.
    pub pipelines: Vec<(String, f64)>,
    /// Bytes the pipeline cache file held when the device was opened.
    pub cache_loaded_bytes: u64,
    /// The first call of each query (pipeline compile, buffers, one sample), in the order run.
    pub first_call_seconds: Vec<(String, f64)>,
}

#[derive(serde::Serialize)]
pub struct StartupRow {
    /// "without cache" (empty cache directory) or "with cache" (the file the first run saved).
    pub cache: &'static str,
    /// The child process from spawn to exit.
    pub process_seconds: f64,
    #[serde(flatten)]
    pub probe: Probe,
}

/// The child: open the GPU, run each query once on one sample, print the probe as JSON.
pub fn probe() -> CliResult {
    let eval = Evaluator::gpu()?;
    let lights = synthetic_lights(8);
    let scene = eval.prepare(&lights)?;
    let one = [[0.0f32, 0.0, 1.0]];
    let at = [[0.3f32, -2.0, 0.5]];
    let mut first = Vec::new();
    for query in ["emission", "radiance", "irradiance"] {
        let t = Instant::now();
        match query {
            "emission" => scene.emission(&one, Accumulate::Sum)?,
            "radiance" => scene.radiance(&at, &one, Accumulate::Sum)?,
            _ => scene.irradiance(&at, &one, Accumulate::Sum)?,
        };
        first.push((query.to_string(), t.elapsed().as_secs_f64()));
    }
    let s = eval.startup().expect("a GPU evaluator");
    let probe = Probe {
        instance_seconds: s.instance.as_secs_f64(),
        adapter_seconds: s.adapter.as_secs_f64(),
        device_seconds: s.device.as_secs_f64(),
        pipelines: s
            .pipelines
            .iter()
            .map(|(n, d)| (n.clone(), d.as_secs_f64()))
            .collect(),
        cache_loaded_bytes: eval.pipeline_cache().map_or(0, |c| c.loaded_bytes),
        first_call_seconds: first,
    };
    outln!(
        "{}",
        serde_json::to_string(&probe).map_err(|e| Failure::runtime(e.to_string()))?
    );
    Ok(())
}

/// Runs the child twice on a fresh cache directory.
pub fn measure() -> CliResult<Vec<StartupRow>> {
    let exe = std::env::current_exe()
        .map_err(|e| Failure::runtime(format!("bench: finding luxeval's own executable: {e}")))?;
    let dir = tempfile::tempdir().map_err(|e| Failure::runtime(format!("temp dir: {e}")))?;
    let mut rows = Vec::new();
    for cache in ["without cache", "with cache"] {
        let t = Instant::now();
        let out = Command::new(&exe)
            .args(["bench", PROBE_FLAG])
            .env(luxeval::PIPELINE_CACHE_DIR_ENV, dir.path())
            .output()
            .map_err(|e| Failure::runtime(format!("bench: starting {}: {e}", exe.display())))?;
        let process_seconds = t.elapsed().as_secs_f64();
        if !out.status.success() {
            return Err(Failure::runtime(format!(
                "bench: the start-up probe failed ({}): {}",
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        let probe: Probe = serde_json::from_slice(&out.stdout)
            .map_err(|e| Failure::runtime(format!("bench: the start-up probe's output: {e}")))?;
        rows.push(StartupRow {
            cache,
            process_seconds,
            probe,
        });
    }
    Ok(rows)
}
