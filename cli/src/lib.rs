//! The `luxeval` command line (DESIGN.md §4), one module per command, around the `luxeval`
//! library. Every failure is reported once, on stderr, naming the file, prim or attribute; exit
//! codes: 0 success, 1 runtime failure (no device, device lost, disk full, conformance over
//! tolerance), 2 bad input. No command leaves a partial output file.
//!
//! What only the command line needs lives here: `.npy` streaming and EXR writing ([`io`]), the
//! PNG pictures and their font ([`plot`]), the IES report, and the `check` and `bench`
//! reports. This library is the binary's body (and what its tests and the fuzz targets reach),
//! not an API.

/// `println!` that ends the process quietly when stdout is closed (`luxeval lights … | head`)
/// instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => { $crate::write_stdout(format_args!($($arg)*)) };
}

mod args;
mod bench;
mod bench_command;
mod bench_dome;
mod bench_mesh;
mod bench_startup;
mod check;
mod exit;
mod falloff;
mod ies;
pub mod ies_report;
mod info;
pub mod io;
mod lights;
mod open;
pub mod plot;
mod query;
mod sample;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use args::{PortalArg, QueryArgs, TimeArg};
use exit::CliResult;

#[derive(Parser)]
#[command(
    name = "luxeval",
    version,
    about = "Evaluate USD lights (UsdLux) on the GPU, cross-checked against an f64 CPU reference",
    long_about = "Evaluate USD lights (UsdLux) on the GPU with WGSL compute shaders, cross-checked \
                  against an f64 CPU reference.\n\nArrays are .npy files: inputs of shape (N, 3) \
                  (float32 or float64), outputs float32 (N, 3), or (L, N, 3) with --per-light.\n\
                  Exit codes: 0 success, 1 runtime failure (no device, device lost, disk full, \
                  conformance over tolerance), 2 bad input (unreadable or malformed file, bad \
                  argument)."
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
        #[command(flatten)]
        portal: PortalArg,
    },
    /// emission(light, ω): RGB radiance leaving each light along each direction ω (pointing away
    /// from the light; for a dome, toward the environment).
    Emission {
        #[command(flatten)]
        common: QueryArgs,
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
        common: QueryArgs,
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
        common: QueryArgs,
        /// Points, float (N, 3), world space.
        #[arg(long, value_name = "P.npy")]
        points: PathBuf,
        /// Receiver normals, float (N, 3), paired row by row with the points; normalised before use.
        #[arg(long, value_name = "N.npy")]
        normals: PathBuf,
        #[command(flatten)]
        tolerance: args::ToleranceArg,
        /// Output: float32 (N, 3), or (L, N, 3) with --per-light.
        #[arg(short, long, value_name = "OUT.npy")]
        output: PathBuf,
    },
    /// intensity(light, ω): far-field RGB intensity ∫ L cos dA of each light along each direction
    /// ω (cd for lights in nits); 0 for distant and dome lights, which are at infinity.
    Intensity {
        #[command(flatten)]
        common: QueryArgs,
        /// Directions, float (N, 3); normalised before use.
        #[arg(long, value_name = "D.npy")]
        dirs: PathBuf,
        /// Output: float32 (N, 3), or (L, N, 3) with --per-light.
        #[arg(short, long, value_name = "OUT.npy")]
        output: PathBuf,
        /// Also write a polar candela plot of the one selected light (--light) in its own
        /// frame's C0–C180 and C90–C270 planes (luminance, cd), as PNG.
        #[arg(long, value_name = "PLOT.png")]
        png: Option<PathBuf>,
    },
    Falloff(falloff::FalloffArgs),
    /// Draw directions toward the lights with their densities (DESIGN.md §9): per point, a light
    /// chosen by --selection, then a direction by its strategy; dirs, pdf, radiance, light_pdf
    /// and light into an .npz.
    Sample(sample::SampleArgs),
    /// The density with which `sample` draws each (point, direction) pair's direction:
    /// Σ_l P(l | x) · pdf_l(ω) (delta lights 0), or per light with --per-light.
    Pdf(sample::PdfArgs),
    /// The sampler report (DESIGN.md §9 S4): per light, the relative variance per sample of
    /// luxeval's strategy and of the uniform-area and cosine baselines at the receivers, and
    /// samples to 1 % noise, by deterministic cubature; or, with --check, a judgement of
    /// another renderer's directions and pdfs (exit 1 when biased or inconsistent).
    Sampling(sample::SamplingArgs),
    /// Run every query on the CPU reference and on the GPU for randomised samples of every light
    /// in the stage, and print the largest relative errors per light and query. Exits 1 when any
    /// is over tolerance (1e-4 away from the documented excluded band).
    Check(check::CheckArgs),
    /// Report on an IES (LM-63) or EULUMDAT photometric file: header, integrated flux against
    /// the header's lumens, peak, beam and field angles, and optionally a polar candela plot.
    Ies(ies::IesArgs),
    /// Measure the throughput of the GPU and CPU paths on a synthetic set of lights.
    Bench(bench::BenchArgs),
}

pub(crate) fn write_stdout(args: std::fmt::Arguments) {
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

/// Switches off Mesa's Vulkan device-select layer where it would print "error: XDG_RUNTIME_DIR is
/// invalid or not set" (a headless machine: render-farm nodes, CI runners, containers), unless
/// the user set `NODEVICE_SELECT` themselves: the layer only orders devices for a display, which
/// luxeval never presents to, and its lines read as luxeval's errors.
fn quiet_device_select() {
    let runtime_dir_ok =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if std::env::var_os("NODEVICE_SELECT").is_none() && !runtime_dir_ok {
        // SAFETY: the first thing `main` does, before any thread is started.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

/// The whole command line: parses the arguments, runs the command, reports a failure once.
pub fn main() -> ExitCode {
    quiet_device_select();
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
        Command::Info { json } => info::run(json),
        Command::Lights {
            scene,
            json,
            time,
            portal,
        } => lights::run(&scene, json, time.time, portal.portal_mode.into()),
        Command::Emission {
            common,
            dirs,
            output,
        } => query::run(&common, query::Query::Emission { dirs: &dirs }, &output),
        Command::Radiance {
            common,
            points,
            dirs,
            output,
        } => query::run(
            &common,
            query::Query::Radiance {
                points: &points,
                dirs: &dirs,
            },
            &output,
        ),
        Command::Irradiance {
            common,
            points,
            normals,
            tolerance,
            output,
        } => query::run(
            &common,
            query::Query::Irradiance {
                points: &points,
                normals: &normals,
                tolerance,
            },
            &output,
        ),
        Command::Intensity {
            common,
            dirs,
            output,
            png,
        } => query::run(
            &common,
            query::Query::Intensity {
                dirs: &dirs,
                png: png.as_deref(),
            },
            &output,
        ),
        Command::Falloff(a) => falloff::run(&a),
        Command::Sample(a) => sample::run_sample(&a),
        Command::Pdf(a) => sample::run_pdf(&a),
        Command::Sampling(a) => sample::run_sampling(&a),
        Command::Ies(a) => ies::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Bench(a) => bench::run(a),
    }
}
