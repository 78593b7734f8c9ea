//! The `luxeval` command line (DESIGN.md §4). Every failure is reported once, on stderr, naming
//! the file, prim or attribute; exit codes: 0 success, 1 runtime failure (no device, device lost,
//! conformance over tolerance), 2 bad input. No command leaves a partial output file.

/// `println!` that ends the process quietly when stdout is closed (`luxeval lights … | head`)
/// instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => { $crate::write_stdout(format_args!($($arg)*)) };
}

mod bench;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};

use luxeval::check;
use luxeval::falloff::{self, Plane};
use luxeval::gpu::{self, GpuContext};
use luxeval::io::npy;
use luxeval::scene::Scene;
use luxeval::{Accumulate, Evaluator, Light, LuxError, TemperatureMode};

#[derive(Parser)]
#[command(
    name = "luxeval",
    version,
    about = "Evaluate USD lights (UsdLux) on the GPU, cross-checked against an f64 CPU reference",
    long_about = "Evaluate USD lights (UsdLux) on the GPU with WGSL compute shaders, cross-checked \
                  against an f64 CPU reference.\n\nArrays are .npy files: inputs of shape (N, 3) \
                  (float32 or float64), outputs float32 (N, 3), or (L, N, 3) with --per-light.\n\
                  Exit codes: 0 success, 1 runtime failure (no device, device lost, conformance \
                  over tolerance), 2 bad input (unreadable or malformed file, bad argument)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the GPU adapters, the one luxeval uses, and its limits.
    Info {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// List the lights of a stage: path, type, visibility, world matrix, and every input with its
    /// value and whether it was authored (else the schema fallback).
    Lights {
        /// The stage: .usda, .usdc or .usdz.
        scene: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        time: TimeArg,
    },
    /// emission(light, ω): RGB radiance leaving each light along each direction ω (pointing away
    /// from the light; for a dome, toward the environment).
    Emission {
        #[command(flatten)]
        common: Common,
        /// Directions, float (N, 3); normalised before use.
        #[arg(long, value_name = "D.npy")]
        dirs: PathBuf,
        /// Output: float32 (N, 3), or (L, N, 3) with --per-light.
        #[arg(short, long, value_name = "OUT.npy")]
        output: PathBuf,
    },
    /// radiance(x, ω): RGB radiance arriving at each point x from direction ω (pointing from x
    /// toward the light); 0 where the ray misses every light.
    Radiance {
        #[command(flatten)]
        common: Common,
        /// Points, float (N, 3), world space.
        #[arg(long, value_name = "P.npy")]
        points: PathBuf,
        /// Directions, float (N, 3), paired row by row with the points; normalised before use.
        #[arg(long, value_name = "D.npy")]
        dirs: PathBuf,
        /// Output: float32 (N, 3), or (L, N, 3) with --per-light.
        #[arg(short, long, value_name = "OUT.npy")]
        output: PathBuf,
    },
    /// irradiance(x, n): diffuse-weighted RGB irradiance at each point x on a one-sided receiver
    /// with normal n (lux for lights in nits), no occlusion.
    Irradiance {
        #[command(flatten)]
        common: Common,
        /// Points, float (N, 3), world space.
        #[arg(long, value_name = "P.npy")]
        points: PathBuf,
        /// Receiver normals, float (N, 3), paired row by row with the points; normalised before use.
        #[arg(long, value_name = "N.npy")]
        normals: PathBuf,
        /// Output: float32 (N, 3), or (L, N, 3) with --per-light.
        #[arg(short, long, value_name = "OUT.npy")]
        output: PathBuf,
    },
    /// A falloff map: the summed irradiance over a rectangle of a plane, written as a linear float
    /// RGB EXR and optionally a false-colour PNG with a colour bar in lux.
    ///
    /// The rectangle is origin + s·u + t·v for s, t in [0, 1]; the receiver normal is
    /// normalize(u × v). The image shows the plane from the side the normal points to, u to the
    /// right and v up; each pixel is evaluated at its centre. Example, a 10 m floor at y = 0 seen
    /// from above with -Z up the image: --origin -5,0,5 --u 10,0,0 --v 0,0,-10 --res 512,512
    Falloff {
        /// The stage: .usda, .usdc or .usdz.
        scene: PathBuf,
        /// The corner of the rectangle at the image's bottom-left, X,Y,Z.
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
        origin: [f64; 3],
        /// The rectangle's horizontal edge (image left to right), X,Y,Z.
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
        u: [f64; 3],
        /// The rectangle's vertical edge (image bottom to top), X,Y,Z.
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
        v: [f64; 3],
        /// Pixels, W,H.
        #[arg(long, value_name = "W,H", value_parser = parse_res)]
        res: (u32, u32),
        /// Output EXR: linear float R, G, B irradiance.
        #[arg(short, long, value_name = "MAP.exr")]
        output: PathBuf,
        /// Also write a false-colour PNG (luminance of the irradiance in lux, viridis) with a colour
        /// bar in lux and the plane's extent.
        #[arg(long, value_name = "MAP.png")]
        png: Option<PathBuf>,
        /// Colour scale of the PNG.
        #[arg(long, value_enum, default_value_t = ScaleArg::Log)]
        scale: ScaleArg,
        /// Colour bar range of the PNG in lux, LOW,HIGH. Default: the map's maximum and three
        /// decades below it (log) or 0 (linear).
        #[arg(long, value_name = "LOW,HIGH", value_parser = parse_range)]
        range: Option<(f64, f64)>,
        /// Draw isolux contours on the PNG at the colour bar's tick values.
        #[arg(long)]
        contours: bool,
        /// Evaluate only this light (prim path); repeatable.
        #[arg(long = "light", value_name = "PATH")]
        lights: Vec<String>,
        /// Where to evaluate (default: the GPU, falling back to the CPU reference with a warning).
        #[arg(long, value_enum)]
        device: Option<DeviceArg>,
        #[command(flatten)]
        time: TimeArg,
        /// How colorTemperature becomes RGB.
        #[arg(long, value_enum, default_value_t = ModeArg::Spec)]
        temperature_mode: ModeArg,
    },
    /// Run every query on the CPU reference and on the GPU for randomised samples of every light
    /// in the stage, and print the largest relative errors per light and query. Exits 1 when any
    /// is over tolerance (1e-4 away from the documented excluded band).
    Check {
        /// The stage: .usda, .usdc or .usdz.
        scene: PathBuf,
        /// Samples per light and query.
        #[arg(long, default_value_t = 2000)]
        samples: usize,
        /// Seed of the sample generator (a check is reproducible from it).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Check only this light (prim path); repeatable.
        #[arg(long = "light", value_name = "PATH")]
        lights: Vec<String>,
        #[command(flatten)]
        time: TimeArg,
        /// How colorTemperature becomes RGB.
        #[arg(long, value_enum, default_value_t = ModeArg::Spec)]
        temperature_mode: ModeArg,
    },
    /// Measure the throughput of the GPU and CPU paths on a synthetic set of lights.
    Bench(bench::BenchArgs),
}

/// Options shared by the array queries.
#[derive(Args)]
struct Common {
    /// The stage: .usda, .usdc or .usdz.
    scene: PathBuf,
    /// Evaluate only this light (prim path); repeatable. Default: every visible light that luxeval
    /// evaluates, in stage order.
    #[arg(long = "light", value_name = "PATH")]
    lights: Vec<String>,
    /// One result per light, shape (L, N, 3), in the order `luxeval lights` lists them, instead of
    /// the sum over lights.
    #[arg(long)]
    per_light: bool,
    /// Where to evaluate. Default: the GPU, falling back to the CPU reference with a warning when
    /// no adapter exists.
    #[arg(long, value_enum)]
    device: Option<DeviceArg>,
    #[command(flatten)]
    time: TimeArg,
    /// How colorTemperature becomes RGB: spec (6500 K is white), usd (Pixar's
    /// UsdLux.BlackbodyTemperatureAsRgb), planckian (the OpenUSD reference renderer's path).
    #[arg(long, value_enum, default_value_t = ModeArg::Spec)]
    temperature_mode: ModeArg,
}

#[derive(Args)]
struct TimeArg {
    /// USD time code to evaluate at. Default: the stage's startTimeCode when authored, else each
    /// attribute's earliest time sample (USD's EarliestTime).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    time: Option<f64>,
}

#[derive(Clone, Copy, ValueEnum)]
enum ScaleArg {
    Log,
    Linear,
}

fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!("expected three finite numbers X,Y,Z, got {s:?}")),
    }
}

fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let parts: Vec<&str> = s.split(',').collect();
    match parts.as_slice() {
        [w, h] => {
            let w: u32 = w.trim().parse().map_err(|e| format!("width {w:?}: {e}"))?;
            let h: u32 = h.trim().parse().map_err(|e| format!("height {h:?}: {e}"))?;
            if w == 0 || h == 0 {
                Err("width and height must be at least 1".into())
            } else {
                Ok((w, h))
            }
        }
        _ => Err(format!("expected W,H, got {s:?}")),
    }
}

fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [lo, hi] if lo.is_finite() && hi.is_finite() && hi > lo => Ok((*lo, *hi)),
        _ => Err(format!("expected LOW,HIGH with LOW < HIGH, got {s:?}")),
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum DeviceArg {
    Gpu,
    Cpu,
}

#[derive(Clone, Copy, ValueEnum)]
enum ModeArg {
    Spec,
    Usd,
    Planckian,
}

impl From<ModeArg> for TemperatureMode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::Spec => TemperatureMode::Spec,
            ModeArg::Usd => TemperatureMode::Usd,
            ModeArg::Planckian => TemperatureMode::Planckian,
        }
    }
}

/// A failure with its exit code.
struct Failure {
    code: u8,
    message: String,
}

impl From<LuxError> for Failure {
    fn from(e: LuxError) -> Self {
        Failure {
            code: if e.is_bad_input() { 2 } else { 1 },
            message: e.to_string(),
        }
    }
}

impl Failure {
    fn runtime(message: impl Into<String>) -> Self {
        Failure {
            code: 1,
            message: message.into(),
        }
    }
}

type CliResult<T = ()> = Result<T, Failure>;

fn write_stdout(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|_| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: writing to stdout: {e}");
        std::process::exit(1);
    }
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("error: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

fn run(cli: Cli) -> CliResult {
    match cli.command {
        Command::Info { json } => info(json),
        Command::Lights { scene, json, time } => lights(&scene, json, time.time),
        Command::Emission {
            common,
            dirs,
            output,
        } => {
            let dirs = npy::read_vec3(&dirs)?;
            let (eval, lights) = open(&common)?;
            let out = eval.emission(&lights, &dirs, accumulate(&common))?;
            write_rows(&output, &common, lights.len(), dirs.len(), &out)
        }
        Command::Radiance {
            common,
            points,
            dirs,
            output,
        } => {
            let points = npy::read_vec3(&points)?;
            let dirs = npy::read_vec3(&dirs)?;
            let (eval, lights) = open(&common)?;
            let out = eval.radiance(&lights, &points, &dirs, accumulate(&common))?;
            write_rows(&output, &common, lights.len(), dirs.len(), &out)
        }
        Command::Irradiance {
            common,
            points,
            normals,
            output,
        } => {
            let points = npy::read_vec3(&points)?;
            let normals = npy::read_vec3(&normals)?;
            let (eval, lights) = open(&common)?;
            let out = eval.irradiance(&lights, &points, &normals, accumulate(&common))?;
            write_rows(&output, &common, lights.len(), points.len(), &out)
        }
        Command::Falloff {
            scene,
            origin,
            u,
            v,
            res,
            output,
            png,
            scale,
            range,
            contours,
            lights,
            device,
            time,
            temperature_mode,
        } => {
            let common = Common {
                scene,
                lights,
                per_light: false,
                device,
                time,
                temperature_mode,
            };
            let plane = Plane::new(origin.into(), u.into(), v.into(), res.0, res.1)?;
            let style = falloff::png::Style {
                scale: match scale {
                    ScaleArg::Log => falloff::png::Scale::Log,
                    ScaleArg::Linear => falloff::png::Scale::Linear,
                },
                range,
                contours,
            };
            falloff_cmd(&common, &plane, &output, png.as_deref(), &style)
        }
        Command::Check {
            scene,
            samples,
            seed,
            json,
            lights,
            time,
            temperature_mode,
        } => check_cmd(
            &scene,
            samples,
            seed,
            json,
            &lights,
            time.time,
            temperature_mode.into(),
        ),
        Command::Bench(args) => bench::run(args),
    }
}

/// An error about a light of `scene`, prefixed with the stage's path.
fn in_scene(scene: &Path, e: LuxError) -> Failure {
    let f = Failure::from(e);
    Failure {
        code: f.code,
        message: format!("{}: {}", scene.display(), f.message),
    }
}

fn accumulate(c: &Common) -> Accumulate {
    if c.per_light {
        Accumulate::PerLight
    } else {
        Accumulate::Sum
    }
}

/// Loads the scene, prints its warnings, selects lights and opens the device.
fn open(c: &Common) -> CliResult<(Evaluator, Vec<Light>)> {
    let scene = Scene::load(&c.scene, c.time.time)?;
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
    let lights = scene.evaluable(&c.lights)?;
    // Validate here so that an invalid attribute is reported with the stage it comes from.
    for l in &lights {
        l.validate().map_err(|e| in_scene(&c.scene, e))?;
    }
    if lights.is_empty() {
        eprintln!(
            "warning: {}: no light to evaluate; the output is all zeros",
            c.scene.display()
        );
    }
    let eval = match c.device {
        Some(DeviceArg::Cpu) => Evaluator::cpu(),
        Some(DeviceArg::Gpu) => Evaluator::gpu()?,
        None => match Evaluator::gpu() {
            Ok(e) => e,
            Err(LuxError::NoAdapter(why)) => {
                eprintln!("warning: no GPU adapter ({why}); using the CPU reference");
                Evaluator::cpu()
            }
            Err(e) => return Err(e.into()),
        },
    };
    Ok((
        eval.with_temperature_mode(c.temperature_mode.into()),
        lights,
    ))
}

fn write_rows(path: &Path, c: &Common, lights: usize, n: usize, rows: &[[f32; 3]]) -> CliResult {
    let shape: Vec<u64> = if c.per_light {
        vec![lights as u64, n as u64, 3]
    } else {
        vec![n as u64, 3]
    };
    npy::write_f32(path, &shape, rows)?;
    Ok(())
}

fn falloff_cmd(
    c: &Common,
    plane: &Plane,
    exr: &Path,
    png: Option<&Path>,
    style: &falloff::png::Style,
) -> CliResult {
    if let Some((lo, _)) = style.range
        && style.scale == falloff::png::Scale::Log
        && lo <= 0.0
    {
        return Err(Failure {
            code: 2,
            message: "--range: a log scale needs LOW > 0".into(),
        });
    }
    let (eval, lights) = open(c)?;
    // A bar on a terminal, nothing when stderr is redirected (indicatif hides itself there).
    let bar = indicatif::ProgressBar::new(plane.pixels() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} [{bar:40}] {percent:>3}% {pos}/{len} px, eta {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_message(format!("falloff on {}", eval.device_name()));
    let map = falloff::evaluate(&eval, &lights, plane, |done, _| {
        bar.set_position(done as u64)
    })?;
    bar.finish_and_clear();
    let n = plane.normal();
    let comment = format!(
        "luxeval falloff: {} at {}; origin {:?} u {:?} v {:?}; normal ({}, {}, {}); {} lights on {}",
        c.scene.display(),
        c.time
            .time
            .map(|t| t.to_string())
            .unwrap_or_else(|| "the default time".into()),
        plane.origin.to_array(),
        plane.u.to_array(),
        plane.v.to_array(),
        n.x,
        n.y,
        n.z,
        lights.len(),
        eval.device_name()
    );
    // Render the PNG before writing anything, so that a bad style leaves no file.
    let rendered = match png {
        Some(_) => Some(falloff::png::render(&map, plane, style)?),
        None => None,
    };
    falloff::write_exr(exr, &map, &comment)?;
    if let (Some(path), Some(r)) = (png, rendered)
        && let Err(e) = falloff::png::write(path, &r)
    {
        // No half-finished pair: the EXR goes too.
        let _ = std::fs::remove_file(exr);
        return Err(e.into());
    }
    let lum = map.luminance();
    let max = lum.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "{}: {}×{} px, max {:.6} lux{}",
        exr.display(),
        plane.width,
        plane.height,
        max,
        png.map(|p| format!("; {}", p.display()))
            .unwrap_or_default()
    );
    Ok(())
}

fn info(json: bool) -> CliResult {
    let adapters = gpu::list_adapters();
    let chosen = GpuContext::new();
    if json {
        let v = serde_json::json!({
            "version": env!("CARGO_PKG_VERSION"),
            "adapters": adapters.iter().map(|a| serde_json::json!({
                "name": a.name, "backend": a.backend, "device_type": a.device_type, "driver": a.driver,
            })).collect::<Vec<_>>(),
            "chosen": match &chosen {
                Ok(g) => serde_json::json!({
                    "name": g.adapter().name,
                    "backend": g.adapter().backend,
                    "limits": {
                        "max_storage_buffer_binding_size": g.limits().max_storage_buffer_binding_size,
                        "max_buffer_size": g.limits().max_buffer_size,
                        "max_compute_workgroups_per_dimension": g.limits().max_compute_workgroups_per_dimension,
                        "max_compute_invocations_per_workgroup": g.limits().max_compute_invocations_per_workgroup,
                    },
                    "samples_per_dispatch_one_light": g.chunk_capacity(1, false),
                }),
                Err(e) => serde_json::json!({ "error": e.to_string() }),
            },
        });
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).expect("JSON of plain values")
        );
    } else {
        outln!("luxeval {}", env!("CARGO_PKG_VERSION"));
        outln!("adapters:");
        if adapters.is_empty() {
            outln!("  (none)");
        }
        for a in &adapters {
            outln!(
                "  {} [{}; {}; {}]",
                a.name,
                a.backend,
                a.device_type,
                a.driver
            );
        }
        match &chosen {
            Ok(g) => {
                let l = g.limits();
                outln!("chosen: {} ({})", g.adapter().name, g.adapter().backend);
                outln!(
                    "  max storage binding: {} bytes",
                    l.max_storage_buffer_binding_size
                );
                outln!("  max buffer:          {} bytes", l.max_buffer_size);
                outln!(
                    "  max workgroups/dim:  {}",
                    l.max_compute_workgroups_per_dimension
                );
                outln!(
                    "  samples per dispatch (one light): {}",
                    g.chunk_capacity(1, false)
                );
            }
            Err(e) => {
                outln!("chosen: none: {e}\n  queries fall back to the CPU reference (--device cpu)")
            }
        }
    }
    Ok(())
}

fn lights(path: &Path, json: bool, time: Option<f64>) -> CliResult {
    let scene = Scene::load(path, time)?;
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&scene).map_err(|e| Failure::runtime(e.to_string()))?
        );
        return Ok(());
    }
    outln!("{}", scene.file.display());
    outln!(
        "  upAxis {}, metersPerUnit {}, time {}",
        scene.up_axis,
        scene.meters_per_unit,
        scene.time
    );
    for l in &scene.lights {
        let status = match (&l.light, l.visible) {
            (Some(_), true) => "evaluated",
            (_, false) => "invisible: skipped",
            (None, true) => "not evaluated",
        };
        outln!("\n{} ({}) [{}]", l.path, l.usd_type, status);
        if !l.applied_schemas.is_empty() {
            outln!("  apiSchemas: {}", l.applied_schemas.join(", "));
        }
        if let Some(w) = &l.warning {
            outln!("  warning: {w}");
        }
        for row in &l.world {
            outln!(
                "  world  {:>12.6} {:>12.6} {:>12.6} {:>12.6}",
                row[0],
                row[1],
                row[2],
                row[3]
            );
        }
        for i in &l.inputs {
            outln!(
                "  {:<34} {}{}",
                i.name,
                i.value,
                if i.authored { "" } else { "  (fallback)" }
            );
        }
    }
    Ok(())
}

fn check_cmd(
    path: &Path,
    samples: usize,
    seed: u64,
    json: bool,
    select: &[String],
    time: Option<f64>,
    mode: TemperatureMode,
) -> CliResult {
    if samples == 0 {
        return Err(Failure {
            code: 2,
            message: "--samples must be at least 1".into(),
        });
    }
    let scene = Scene::load(path, time)?;
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
    let lights = scene.evaluable(select)?;
    if lights.is_empty() {
        eprintln!(
            "warning: {}: no light luxeval evaluates (see the warnings above); nothing to check",
            path.display()
        );
        return Ok(());
    }
    let prepared = luxeval::cpu::prepare(&lights, mode).map_err(|e| in_scene(path, e))?;
    let gpu = GpuContext::new()
        .map_err(|e| Failure::runtime(format!("check compares against a GPU: {e}")))?;
    let device = format!("{} ({})", gpu.adapter().name, gpu.adapter().backend);
    let report = check::check(&gpu, &device, &prepared, samples, seed)?;
    if json {
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
            check::CONE_BAND
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
