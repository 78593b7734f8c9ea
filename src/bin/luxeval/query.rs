//! `luxeval emission | radiance | irradiance | intensity`: a query over `.npy` arrays.

use std::path::Path;

use luxeval::io::{self, npy};
use luxeval::plot::polar;
use luxeval::{Accumulate, Evaluator, Limits, PreparedScene, Reference};

use crate::args::{QueryArgs, SceneArgs, ToleranceArg};
use crate::exit::{CliResult, Failure, in_scene};
use crate::open;

/// Which query, with its input files.
pub enum Query<'a> {
    Emission {
        dirs: &'a Path,
    },
    Radiance {
        points: &'a Path,
        dirs: &'a Path,
    },
    Irradiance {
        points: &'a Path,
        normals: &'a Path,
        tolerance: ToleranceArg,
    },
    Intensity {
        dirs: &'a Path,
        png: Option<&'a Path>,
    },
}

impl Query<'_> {
    /// The input arrays, with the options that name them.
    fn inputs(&self) -> Vec<(&'static str, &Path)> {
        match *self {
            Query::Emission { dirs } => vec![("--dirs", dirs)],
            Query::Radiance { points, dirs } => vec![("--points", points), ("--dirs", dirs)],
            Query::Irradiance {
                points, normals, ..
            } => {
                vec![("--points", points), ("--normals", normals)]
            }
            Query::Intensity { dirs, .. } => vec![("--dirs", dirs)],
        }
    }
}

pub fn run(args: &QueryArgs, query: Query, output: &Path) -> CliResult {
    let mut inputs = query.inputs();
    inputs.push(("SCENE", &args.scene.scene));
    let mut outputs = vec![("-o", output)];
    if let Query::Intensity { png: Some(png), .. } = query {
        outputs.push(("--png", png));
    }
    io::check_outputs(&outputs, &inputs)?;
    let acc = args.accumulate();
    // Inputs are read before the stage is opened: a bad array is reported without the cost of
    // opening a device. Directions and normals are normalised in f64 as they are read.
    let (n, scene, out) = match query {
        Query::Emission { dirs } => {
            let dirs = npy::read_directions(dirs)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            check_output_rows(&scene, dirs.len(), args.per_light)?;
            let out = scene.emission(&dirs, acc)?;
            (dirs.len(), scene, out)
        }
        Query::Radiance {
            points: pp,
            dirs: dp,
        } => {
            let points = npy::read_points(pp)?;
            let dirs = npy::read_directions(dp)?;
            same_rows(("--points", pp, points.len()), ("--dirs", dp, dirs.len()))?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            check_output_rows(&scene, dirs.len(), args.per_light)?;
            let out = scene.radiance(&points, &dirs, acc)?;
            (dirs.len(), scene, out)
        }
        Query::Irradiance {
            points: pp,
            normals: np,
            tolerance,
        } => {
            let points = npy::read_points(pp)?;
            let normals = npy::read_directions(np)?;
            same_rows(
                ("--points", pp, points.len()),
                ("--normals", np, normals.len()),
            )?;
            let (_, scene) = open::prepare_irradiance(&args.scene, args.device, tolerance)?;
            check_output_rows(&scene, points.len(), args.per_light)?;
            let out = scene.irradiance(&points, &normals, acc)?;
            (points.len(), scene, out)
        }
        Query::Intensity { dirs, png } => {
            let dirs = npy::read_directions(dirs)?;
            if png.is_some() && args.scene.lights.len() != 1 {
                return Err(Failure::bad_input(
                    "--png plots one light: select it with --light PATH",
                ));
            }
            let (eval, scene) = open::prepare(&args.scene, args.device)?;
            check_output_rows(&scene, dirs.len(), args.per_light)?;
            let out = scene.intensity(&dirs, acc)?;
            if let Some(png) = png {
                plot_light(&eval, &scene, &args.scene, png)?;
            }
            (dirs.len(), scene, out)
        }
    };
    check_finite(&scene, n, &out)?;
    write_rows(output, args, &scene, n, &out)
}

/// Two arrays that pair up row by row, or an error naming both files.
fn same_rows(a: (&str, &Path, usize), b: (&str, &Path, usize)) -> CliResult {
    if a.2 != b.2 {
        return Err(Failure::bad_input(format!(
            "{} {} has {} rows but {} {} has {}; they pair up row by row",
            a.0,
            a.1.display(),
            a.2,
            b.0,
            b.1.display(),
            b.2
        )));
    }
    Ok(())
}

/// `--per-light` writes lights × rows: bounded like any other array.
fn check_output_rows(scene: &PreparedScene, n: usize, per_light: bool) -> CliResult {
    let lights = if per_light { scene.len().max(1) } else { 1 };
    let rows = (lights as u64).saturating_mul(n as u64);
    Limits::from_env()?.check_samples("the output (lights × rows)", rows)?;
    Ok(())
}

/// No NaN or infinity is ever written for finite input (docs/INPUTS.md): every per-light
/// constant fits float32 (checked when the lights are prepared), but a sum over many lights, or
/// the irradiance of a point-like light at a receiver almost on it, can still overflow float32.
/// Such a result is refused, naming the row (and light), instead of writing `inf`.
pub fn check_finite(scene: &PreparedScene, n: usize, rows: &[[f32; 3]]) -> CliResult {
    if let Some(k) = rows.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
        let at = if rows.len() > n && n > 0 {
            let light = scene.lights().nth(k / n).map(|l| l.path.clone());
            format!("row {} of light {}", k % n, light.unwrap_or_default())
        } else {
            format!("row {k}")
        };
        let what = if rows[k].iter().any(|v| v.is_nan()) {
            // NaN from finite input is a defect of luxeval, not of the input.
            return Err(Failure::runtime(format!(
                "internal error: the result at {at} is NaN ({:?}); please report it",
                rows[k]
            )));
        } else {
            "overflows float32"
        };
        return Err(Failure::bad_input(format!(
            "the result at {at} {what} ({:?}); scale the lights' intensity down or move the \
             receivers away from the lights",
            rows[k]
        )));
    }
    Ok(())
}

fn write_rows(
    path: &Path,
    args: &QueryArgs,
    scene: &PreparedScene,
    n: usize,
    rows: &[[f32; 3]],
) -> CliResult {
    let shape: Vec<u64> = if args.per_light {
        vec![scene.len() as u64, n as u64, 3]
    } else {
        vec![n as u64, 3]
    };
    npy::write_f32(path, &shape, rows)?;
    Ok(())
}

/// The polar candela plot of the one light of `scene`: its intensity's luminance (Rec.709 Y)
/// in the light's own C0–C180 and C90–C270 planes (light-space directions mapped to world by its
/// transform), evaluated on the scene's device.
fn plot_light(eval: &Evaluator, scene: &PreparedScene, args: &SceneArgs, png: &Path) -> CliResult {
    let Some(light) = scene.lights().next() else {
        return Err(Failure::bad_input(format!(
            "{}: the selected light is not evaluated (see the warnings above)",
            args.scene.display()
        )));
    };
    let r = Reference::new(light, eval.temperature_mode()).map_err(|e| in_scene(&args.scene, e))?;
    let m = light.linear();
    // The plot's light-space plane directions, mapped to world, on the device.
    let planes = polar::plane_directions(0.5);
    let mut curves = Vec::new();
    for (label, colour, dirs) in planes {
        let world: Vec<[f32; 3]> = dirs
            .iter()
            .map(|(_, e)| (m * *e).normalize().as_vec3().to_array())
            .collect();
        let rgb = scene.intensity(&world, Accumulate::Sum)?;
        curves.push(polar::Curve {
            label: label.into(),
            colour,
            samples: dirs
                .iter()
                .zip(&rgb)
                .map(|((s, _), c)| {
                    let y = 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
                    (*s, y)
                })
                .collect(),
        });
    }
    let peak = curves
        .iter()
        .flat_map(|c| c.samples.iter().map(|s| s.1))
        .fold(0.0, f64::max);
    let flux = r
        .flux()
        .map(|f| format!("{:.6} lm", 0.2126 * f.x + 0.7152 * f.y + 0.0722 * f.z))
        .unwrap_or_else(|| "no finite flux".into());
    polar::render(
        &light.path,
        &format!("{}, peak {peak:.6} cd, {flux}", args.scene.display()),
        &curves,
    )
    .write_png(png, &format!("polar candela plot of {}", light.path))?;
    Ok(())
}
