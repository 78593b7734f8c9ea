//! `luxeval emission | radiance | irradiance | intensity`: a query over `.npy` arrays.

use std::path::Path;

use luxeval::io::npy;
use luxeval::plot::polar;
use luxeval::{Accumulate, Evaluator, PreparedScene, Reference};

use crate::args::{QueryArgs, SceneArgs};
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
    },
    Intensity {
        dirs: &'a Path,
        png: Option<&'a Path>,
    },
}

pub fn run(args: &QueryArgs, query: Query, output: &Path) -> CliResult {
    let acc = args.accumulate();
    // Inputs are read before the stage is opened: a bad array is reported without the cost of
    // opening a device.
    let (n, scene, out) = match query {
        Query::Emission { dirs } => {
            let dirs = npy::read_vec3(dirs)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.emission(&dirs, acc)?;
            (dirs.len(), scene, out)
        }
        Query::Radiance { points, dirs } => {
            let points = npy::read_vec3(points)?;
            let dirs = npy::read_vec3(dirs)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.radiance(&points, &dirs, acc)?;
            (dirs.len(), scene, out)
        }
        Query::Irradiance { points, normals } => {
            let points = npy::read_vec3(points)?;
            let normals = npy::read_vec3(normals)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.irradiance(&points, &normals, acc)?;
            (points.len(), scene, out)
        }
        Query::Intensity { dirs, png } => {
            let dirs = npy::read_vec3(dirs)?;
            if png.is_some() && args.scene.lights.len() != 1 {
                return Err(Failure::bad_input(
                    "--png plots one light: select it with --light PATH",
                ));
            }
            let (eval, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.intensity(&dirs, acc)?;
            if let Some(png) = png {
                plot_light(&eval, &scene, &args.scene, png)?;
            }
            (dirs.len(), scene, out)
        }
    };
    write_rows(output, args, &scene, n, &out)
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
