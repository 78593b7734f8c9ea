//! `luxeval falloff`: irradiance over a rectangle of a plane, as EXR and false-colour PNG.

use std::path::{Path, PathBuf};

use clap::Args;

use luxeval::FalloffPlane as Plane;

use crate::io::exr;
use crate::plot::falloff as png;

use crate::args::{
    DeviceArg, ScaleArg, SceneArgs, ToleranceArg, parse_range, parse_res, parse_vec3,
};
use crate::exit::{CliResult, Failure};
use crate::open;

/// A falloff map: the summed irradiance over a rectangle of a plane, written as a linear float
/// RGB EXR and optionally a false-colour PNG with a colour bar in lux.
///
/// The rectangle is origin + s·u + t·v for s, t in [0, 1]; the receiver normal is
/// normalize(u × v). The image shows the plane from the side the normal points to, u to the
/// right and v up; each pixel is evaluated at its centre. Example, a 10 m floor at y = 0 seen
/// from above with -Z up the image: --origin -5,0,5 --u 10,0,0 --v 0,0,-10 --res 512,512
#[derive(Args)]
pub struct FalloffArgs {
    #[command(flatten)]
    scene: SceneArgs,
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
    #[arg(long, value_name = "LOW,HIGH", value_parser = parse_range, allow_hyphen_values = true)]
    range: Option<(f64, f64)>,
    /// Draw isolux contours on the PNG at the colour bar's tick values.
    #[arg(long)]
    contours: bool,
    /// Where to evaluate (default: the GPU, falling back to the CPU reference with a warning).
    #[arg(long, value_enum)]
    device: Option<DeviceArg>,
    #[command(flatten)]
    tolerance: ToleranceArg,
}

pub fn run(a: &FalloffArgs) -> CliResult {
    let mut outputs = vec![("-o", a.output.as_path())];
    if let Some(png) = &a.png {
        outputs.push(("--png", png.as_path()));
    }
    crate::io::check_outputs(&outputs, &[("SCENE", &a.scene.scene)])?;
    // The formats are fixed; a name that says otherwise (`-o map.npy`) is likely a mistake.
    for (flag, path, ext, format) in [
        ("-o", Some(&a.output), "exr", "OpenEXR"),
        ("--png", a.png.as_ref(), "png", "PNG"),
    ] {
        if let Some(path) = path
            && !path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case(ext))
        {
            eprintln!(
                "warning: {flag} {}: falloff writes {format} there whatever the file's name",
                path.display()
            );
        }
    }
    luxeval::Limits::from_env()?.check_samples("--res", u64::from(a.res.0) * u64::from(a.res.1))?;
    let plane = Plane::new(a.origin.into(), a.u.into(), a.v.into(), a.res.0, a.res.1)?;
    if a.png.is_some() {
        png::check_size(a.res.0, a.res.1)?;
    }
    let style = png::Style {
        scale: match a.scale {
            ScaleArg::Log => png::Scale::Log,
            ScaleArg::Linear => png::Scale::Linear,
        },
        range: a.range,
        contours: a.contours,
    };
    if let Some((lo, _)) = style.range
        && style.scale == png::Scale::Log
        && lo <= 0.0
    {
        return Err(Failure::bad_input("--range: a log scale needs LOW > 0"));
    }
    let (eval, scene) = open::prepare_irradiance(&a.scene, a.device, a.tolerance, &outputs)?;
    let bar = crate::query::progress_bar(
        plane.pixels() as u64,
        "px",
        format!("falloff on {}", eval.device_name()),
    );
    let map = scene.falloff(&plane, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    crate::query::check_finite(&scene, 0, map.rgb.len(), &map.rgb)?;
    crate::query::note_host_recomputed(&scene, map.rgb.len() as u64);
    let n = plane.normal();
    let comment = format!(
        "luxeval falloff: {} at {}; origin {:?} u {:?} v {:?}; normal ({}, {}, {}); {} lights on {}",
        a.scene.scene.display(),
        a.scene
            .time
            .time
            .map(|t| t.to_string())
            .unwrap_or_else(|| "the default time".into()),
        plane.origin.to_array(),
        plane.u.to_array(),
        plane.v.to_array(),
        n.x,
        n.y,
        n.z,
        scene.len(),
        eval.device_name()
    );
    // Render the PNG before writing anything, so that a bad style leaves no file.
    let rendered = match &a.png {
        Some(_) => Some(png::render(&map, &plane, &style)?),
        None => None,
    };
    exr::write_exr(&a.output, &map, &comment)?;
    if let (Some(path), Some(r)) = (&a.png, rendered)
        && let Err(e) = png::write(path, &r)
    {
        // No half-finished pair: the EXR goes too.
        let _ = std::fs::remove_file(&a.output);
        return Err(e.into());
    }
    let lum = map.luminance();
    let max = lum.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "{}: {}×{} px, max {:.6} lux{}",
        a.output.display(),
        plane.width,
        plane.height,
        max,
        a.png
            .as_deref()
            .map(|p: &Path| format!("; {}", p.display()))
            .unwrap_or_default()
    );
    Ok(())
}
