//! `luxeval check`: every query on the CPU reference and on the GPU for randomised samples of
//! every light of a stage, with the largest relative errors per light and query.

use clap::Args;

use luxeval::{CHECK_CONE_BAND, Evaluator, Reference, TemperatureMode, check_against_reference};

use crate::args::SceneArgs;
use crate::exit::{CliResult, Failure, in_scene};
use crate::open;

#[derive(Args)]
pub struct CheckArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Samples per light and query (irradiance: a quarter of them).
    #[arg(long, default_value_t = 2000)]
    samples: usize,
    /// Seed of the sample generator (a check is reproducible from it).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

pub fn run(a: &CheckArgs) -> CliResult {
    if a.samples == 0 {
        return Err(Failure::bad_input("--samples must be at least 1"));
    }
    luxeval::Limits::from_env()?.check_samples("--samples", a.samples as u64)?;
    let path = &a.scene.scene;
    let lights = open::lights(&a.scene)?;
    if lights.is_empty() {
        eprintln!(
            "warning: {}: no light luxeval evaluates (see the warnings above); nothing to check",
            path.display()
        );
        return Ok(());
    }
    let mode: TemperatureMode = a.scene.temperature_mode.into();
    let refs = lights
        .iter()
        .map(|l| Reference::with_portal_mode(l, mode, a.scene.portal.portal_mode.into()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| in_scene(path, e))?;
    let gpu = Evaluator::gpu()
        .map_err(|e| Failure::runtime(format!("check compares against a GPU: {e}")))?
        .with_temperature_mode(mode)
        .with_portal_mode(a.scene.portal.portal_mode.into());
    let device = gpu.device_name();
    let report = check_against_reference(&gpu, &refs, a.samples, a.seed)?;
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| Failure::runtime(e.to_string()))?
        );
    } else {
        outln!(
            "{}: {} lights on {device}, temperature mode {mode}",
            path.display(),
            lights.len()
        );
        outln!(
            "tolerance {:e} relative; excluded band ±{:e} (rad or fraction of size), cone edges ±{:e}·θcone",
            report.tolerance,
            report.band,
            CHECK_CONE_BAND
        );
        outln!(
            "{:<40} {:<14} {:<10} {:>8} {:>8} {:>12}  result",
            "light",
            "type",
            "query",
            "samples",
            "excluded",
            "max rel err"
        );
        for r in &report.rows {
            outln!(
                "{:<40} {:<14} {:<10} {:>8} {:>8} {:>12.3e}  {}",
                r.light,
                r.light_type,
                format!("{:?}", r.query).to_lowercase(),
                r.samples,
                r.excluded,
                r.max_rel_error,
                if r.pass { "ok" } else { "OVER TOLERANCE" }
            );
        }
        for (light, why) in &report.host_only {
            outln!("{light}: not compared: {why}");
        }
        outln!(
            "{} samples, {} excluded, largest relative error {:.3e}: {}",
            report.samples,
            report.excluded,
            report.max_rel_error(),
            if report.pass() { "pass" } else { "FAIL" }
        );
    }
    if report.pass() {
        Ok(())
    } else {
        Err(Failure::runtime(format!(
            "{}: GPU differs from the CPU reference by more than {:e}",
            path.display(),
            report.tolerance
        )))
    }
}
