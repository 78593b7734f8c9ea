//! `luxeval bench`'s dome row: how long a large lat-long EXR takes from file to a prepared scene
//! (decode, sanitise, format resolution, and on the GPU path the atlas upload), the step Storm
//! needs ~10 s for on an 8k map (OpenUSD #3342). Issue 9 sets the bar at ≤ 1 s of CPU time for
//! an 8192 × 4096 EXR on the reference machine (2 cores).
//!
//! The map is generated once per run (half-float RGB, ZIP, scanlines: what DCC tools write for
//! environment maps) unless `--dome-texture` names one; generating it is not timed.

use std::path::{Path, PathBuf};
use std::time::Instant;

use luxeval::{Asset, Evaluator, Light, Texture};

use crate::exit::{CliResult, Failure};

/// One measurement: wall and process CPU seconds of `Evaluator::prepare` on one textured dome.
#[derive(serde::Serialize)]
pub struct DomeRow {
    pub texture: String,
    pub width: u32,
    pub height: u32,
    pub device: String,
    /// Median over the repetitions.
    pub wall_seconds: f64,
    /// Process CPU time (user + system, every thread) of the median repetition; `None` where
    /// the platform does not report it.
    pub cpu_seconds: Option<f64>,
}

/// User + system CPU time of this process so far (Linux: /proc/self/stat, in clock ticks of
/// 1/100 s).
fn cpu_time() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name: state is field 3, utime 14, stime 15.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let (u, s): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
    Some((u + s) / 100.0)
}

/// Writes a `w × h` half-float RGB, ZIP-compressed lat-long EXR: a smooth sky gradient with a
/// few bright discs (the dynamic range of a real environment map).
fn generate(path: &Path, w: usize, h: usize) -> Result<(), String> {
    use exr::prelude::*;
    let suns = [(0.3, 0.25, 0.01, 5000.0), (0.7, 0.4, 0.02, 200.0)];
    let pixel = |x: usize, y: usize| {
        let (u, v) = ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
        let mut c = [0.2 + 0.6 * (1.0 - v), 0.3 + 0.5 * (1.0 - v), 0.5 + 0.4 * u];
        for (su, sv, r, k) in suns {
            if (u - su).hypot(v - sv) < r {
                c = c.map(|x| x * k);
            }
        }
        (
            f16::from_f64(c[0]),
            f16::from_f64(c[1]),
            f16::from_f64(c[2]),
        )
    };
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| pixel(p.x(), p.y()));
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new((w, h), LayerAttributes::named("rgb"), encoding, channels);
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Times `prepare` of one dome on `texture` (generated as `size` when `None`) on every evaluator.
pub fn run(
    evaluators: &[Evaluator],
    texture: Option<&Path>,
    size: (u32, u32),
    repeat: usize,
) -> CliResult<Vec<DomeRow>> {
    let dir;
    let path: PathBuf = match texture {
        Some(p) => p.to_path_buf(),
        None => {
            dir = tempfile::tempdir().map_err(|e| Failure::runtime(format!("temp dir: {e}")))?;
            let p = dir.path().join(format!("dome_{}x{}.exr", size.0, size.1));
            eprintln!(
                "bench: writing a {} × {} half-float ZIP lat-long EXR (not timed) …",
                size.0, size.1
            );
            generate(&p, size.0 as usize, size.1 as usize).map_err(Failure::runtime)?;
            p
        }
    };
    let light = Light::dome()
        .with_path("/BenchDome")
        .with_texture(Texture::new(Asset::file(path.display().to_string())));
    let mut rows = Vec::new();
    for eval in evaluators {
        // Each repetition loads the file afresh (a new scene has its own asset cache).
        let mut runs = Vec::new();
        let mut dims = (0, 0);
        for _ in 0..repeat.max(1) {
            let (c0, t0) = (cpu_time(), Instant::now());
            let scene = eval.prepare(std::slice::from_ref(&light))?;
            let wall = t0.elapsed().as_secs_f64();
            if runs.is_empty() {
                for w in scene.warnings() {
                    eprintln!("warning: {w}");
                }
            }
            let cpu = cpu_time().zip(c0).map(|(a, b)| a - b);
            dims = scene.texture_size(0).unwrap_or((0, 0));
            drop(scene);
            runs.push((wall, cpu));
        }
        runs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (wall, cpu) = runs[runs.len() / 2];
        rows.push(DomeRow {
            texture: path.display().to_string(),
            width: dims.0,
            height: dims.1,
            device: eval.device_name(),
            wall_seconds: wall,
            cpu_seconds: cpu,
        });
    }
    Ok(rows)
}
