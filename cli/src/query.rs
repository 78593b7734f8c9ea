//! `luxeval emission | radiance | irradiance | intensity`: a query over `.npy` arrays.

use std::path::Path;

use crate::io;
use crate::io::npy::{self, RowKind};
use crate::plot::polar;
use luxeval::{Accumulate, Evaluator, PreparedScene, Reference};

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

    /// The command's name, for the progress bar.
    fn name(&self) -> &'static str {
        match self {
            Query::Emission { .. } => "emission",
            Query::Radiance { .. } => "radiance",
            Query::Irradiance { .. } => "irradiance",
            Query::Intensity { .. } => "intensity",
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
    let chunk = npy::chunk_rows_from_env()?;
    // The headers are read and checked (dtype, shape, size, paired row counts) before the stage
    // is opened: a malformed array is reported without the cost of opening a device. The rows
    // are read, checked and evaluated chunk by chunk below (docs/INPUTS.md "Streaming").
    let mut readers = match query {
        Query::Emission { dirs } | Query::Intensity { dirs, .. } => {
            vec![npy::Reader::open_streaming(dirs, RowKind::Directions)?]
        }
        Query::Radiance { points, dirs } => {
            let p = npy::Reader::open_streaming(points, RowKind::Points)?;
            let d = npy::Reader::open_streaming(dirs, RowKind::Directions)?;
            same_rows(("--points", &p), ("--dirs", &d))?;
            vec![p, d]
        }
        Query::Irradiance {
            points, normals, ..
        } => {
            let p = npy::Reader::open_streaming(points, RowKind::Points)?;
            let n = npy::Reader::open_streaming(normals, RowKind::Directions)?;
            same_rows(("--points", &p), ("--normals", &n))?;
            vec![p, n]
        }
    };
    if let Query::Intensity { png: Some(_), .. } = query
        && args.scene.lights.len() != 1
    {
        return Err(Failure::bad_input(
            "--png plots one light: select it with --light PATH",
        ));
    }
    let n = readers[0].rows();
    let (eval, scene) = match query {
        Query::Irradiance { tolerance, .. } => {
            open::prepare_irradiance(&args.scene, args.device, tolerance, &outputs)?
        }
        _ => open::prepare(&args.scene, args.device, &outputs)?,
    };
    check_output_rows(&scene, n, args.per_light)?;
    let lights = scene.len() as u64;
    let shape: Vec<u64> = if args.per_light {
        vec![lights, n, 3]
    } else {
        vec![n, 3]
    };
    // Rows go to a temporary file beside the output as they are evaluated; on any error below
    // it is removed (dropped) and the output path is left as it was.
    let mut writer = npy::Writer::create(output, &shape)?;
    let bar = progress_bar(
        n,
        "rows",
        format!("{} on {}", query.name(), eval.device_name()),
    );
    let mut start = 0u64;
    loop {
        let mut chunks = Vec::with_capacity(readers.len());
        for r in &mut readers {
            chunks.push(r.next_chunk(chunk)?);
        }
        // The readers hold the same number of rows and read the same chunk size: they end
        // together.
        let Some(Some(first)) = chunks.first() else {
            break;
        };
        let m = first.len();
        let second = || chunks[1].as_deref().expect("paired inputs end together");
        let out = match query {
            Query::Emission { .. } => scene.emission(first, acc)?,
            Query::Intensity { .. } => scene.intensity(first, acc)?,
            Query::Radiance { .. } => scene.radiance(first, second(), acc)?,
            Query::Irradiance { .. } => scene.irradiance(first, second(), acc)?,
        };
        check_finite(&scene, start, m, &out)?;
        if args.per_light {
            // Light-major (L, N, 3): light l's rows of this chunk go to rows l·N + start…
            for (l, rows) in out.chunks_exact(m.max(1)).enumerate() {
                writer.write_rows(l as u64 * n + start, rows)?;
            }
        } else {
            writer.write_rows(start, &out)?;
        }
        start += m as u64;
        bar.set_position(start);
    }
    bar.finish_and_clear();
    if let Query::Irradiance { .. } = query {
        note_host_recomputed(&scene, n * if args.per_light { lights } else { 1 });
    }
    if let Query::Intensity { png: Some(png), .. } = query {
        plot_light(&eval, &scene, &args.scene, png)?;
    }
    writer.finish()?;
    Ok(())
}

/// Says on stderr how many of `rows` irradiance rows the device could not finish and the CPU
/// reference recomputed (`PreparedScene::host_recomputed_rows`), when any: their values are
/// the reference's, and they took the CPU's time.
pub fn note_host_recomputed(scene: &PreparedScene, rows: u64) {
    let k = scene.host_recomputed_rows();
    if k > 0 {
        eprintln!(
            "note: {k} of {rows} irradiance rows were recomputed on the CPU reference: the \
             device could not finish their quadrature (more breakpoints than the kernel holds, \
             or a software GPU's loop budget)"
        );
    }
}

/// A progress bar on a terminal for `total` items, nothing when stderr is redirected (indicatif
/// hides itself there).
pub fn progress_bar(total: u64, unit: &str, message: String) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{{msg}} [{{bar:40}}] {{percent:>3}}% {{pos}}/{{len}} {unit}, eta {{eta}}"
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_message(message);
    bar
}

/// Two arrays that pair up row by row, or an error naming both files; from their headers,
/// before any row is read.
fn same_rows(a: (&str, &npy::Reader), b: (&str, &npy::Reader)) -> CliResult {
    if a.1.rows() != b.1.rows() {
        return Err(Failure::bad_input(format!(
            "{} {} has {} rows but {} {} has {}; they pair up row by row",
            a.0,
            a.1.path().display(),
            a.1.rows(),
            b.0,
            b.1.path().display(),
            b.1.rows()
        )));
    }
    Ok(())
}

/// The output is written chunk by chunk, never held (docs/INPUTS.md "Streaming"): any number of
/// rows the disk holds, `--per-light`'s lights × rows included; only a size that does not fit a
/// file's 64-bit length is refused.
fn check_output_rows(scene: &PreparedScene, n: u64, per_light: bool) -> CliResult {
    let lights = if per_light { scene.len().max(1) } else { 1 };
    if (lights as u64)
        .checked_mul(n)
        .and_then(|rows| rows.checked_mul(12))
        .is_none()
    {
        return Err(Failure::bad_input(format!(
            "the output ({lights} lights × {n} rows of 12 bytes) does not fit a 64-bit file size"
        )));
    }
    Ok(())
}

/// No NaN or infinity is ever written for finite input (docs/INPUTS.md): every per-light
/// constant fits float32 (checked when the lights are prepared), but a sum over many lights, or
/// the irradiance of a point-like light at a receiver almost on it, can still overflow float32.
/// Such a result is refused, naming the row (and light), instead of writing `inf`.
///
/// `rows` are the results of the `m` samples from sample `start` on (`m` rows, or light-major
/// L × `m` with `--per-light`); the message names the sample's row in the whole input.
pub fn check_finite(scene: &PreparedScene, start: u64, m: usize, rows: &[[f32; 3]]) -> CliResult {
    if let Some(k) = rows.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
        let at = if rows.len() > m && m > 0 {
            let light = scene.lights().nth(k / m).map(|l| l.path.clone());
            format!(
                "row {} of light {}",
                start + (k % m) as u64,
                light.unwrap_or_default()
            )
        } else {
            format!("row {}", start + k as u64)
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
        .unwrap_or_else(|| match light.kind {
            luxeval::LightType::Mesh { .. } => "flux not computed for mesh lights".into(),
            _ => "no finite flux".into(),
        });
    polar::render(
        &light.path,
        &format!("{}, peak {peak:.6} cd, {flux}", args.scene.display()),
        &curves,
    )
    .write_png(png, &format!("polar candela plot of {}", light.path))?;
    Ok(())
}
