//! The one opening path of every scene command: load the stage, print its warnings, select and
//! validate the lights, open the device, prepare the lights once.

use std::path::{Path, PathBuf};

use indicatif::ProgressDrawTarget;
use luxeval::{Evaluator, Light, LuxError, PreparedScene, Stage};

use crate::args::{DeviceArg, SceneArgs, ToleranceArg};
use crate::exit::{CliResult, Failure, in_scene};

/// The selected, visible, evaluable lights of the stage, validated (an invalid attribute is
/// reported with the stage it comes from), their textures read with `--texture-filter`. Prints
/// the stage's warnings.
pub fn lights(args: &SceneArgs) -> CliResult<Vec<Light>> {
    Ok(lights_and_layers(args)?.0)
}

/// [`lights`] and every file read to compose the stage (its layers).
fn lights_and_layers(args: &SceneArgs) -> CliResult<(Vec<Light>, Vec<PathBuf>)> {
    let scene = load(&args.scene, args.time.time)?;
    for w in scene.warnings_in(args.portal.portal_mode.into()) {
        eprintln!("warning: {w}");
    }
    let mut lights = scene.evaluable(&args.lights).map_err(|e| match e {
        e @ LuxError::InvalidAttribute { .. } => in_scene(&args.scene, e),
        e => e.into(),
    })?;
    // One line for everything a renderer would apply and luxeval does not (filters, linking,
    // shaping inputs without ShapingAPI, light lists); `luxeval lights` lists each.
    if let Some(w) = scene.unapplied(&args.lights) {
        eprintln!("warning: {}: {w}", args.scene.display());
    }
    for l in &mut lights {
        l.validate().map_err(|e| in_scene(&args.scene, e))?;
        if let Some(t) = &mut l.texture {
            t.filter = args.texture_filter.into();
        }
    }
    Ok((lights, scene.files_read))
}

/// Loads the stage; an error about a light's attribute or transform is prefixed with the stage's
/// path (file errors already name their file). A load that takes longer than half a second
/// says on a terminal's stderr which step it is at (`Stage::load_with_progress`), and clears
/// the line when done.
pub fn load(path: &std::path::Path, time: Option<f64>) -> CliResult<Stage> {
    let start = std::time::Instant::now();
    // Hidden until the load has taken half a second: most stages read in milliseconds, and a
    // line flashed on every command would be noise. indicatif draws nothing where stderr is
    // not a terminal.
    let bar = indicatif::ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            .expect("static template"),
    );
    let mut shown = false;
    let stage = Stage::load_with_progress(path, time, |p| {
        if !shown && start.elapsed() >= std::time::Duration::from_millis(500) {
            shown = true;
            bar.set_draw_target(ProgressDrawTarget::stderr());
            // openusd's parse and composition report nothing for seconds on big stages.
            bar.enable_steady_tick(std::time::Duration::from_millis(200));
        }
        bar.set_message(format!("reading {}: {p}", path.display()));
        std::ops::ControlFlow::Continue(())
    });
    bar.finish_and_clear();
    stage.map_err(|e| match e {
        LuxError::InvalidAttribute { .. } | LuxError::InvalidTransform { .. } => in_scene(path, e),
        e => e.into(),
    })
}

/// The evaluator `device` asks for: the GPU (an error when there is none), the CPU, or
/// by default (`auto`) a hardware GPU, else the CPU reference with a warning saying why.
pub fn evaluator(device: Option<DeviceArg>, args: &SceneArgs) -> CliResult<Evaluator> {
    let eval = match device {
        Some(DeviceArg::Cpu) => Evaluator::cpu(),
        Some(DeviceArg::Gpu) => Evaluator::gpu()?,
        None | Some(DeviceArg::Auto) => {
            let (eval, why) = Evaluator::auto()?;
            // Said when it is not the GPU one might expect (a GPU choice is what `auto` means).
            if !eval.is_gpu() {
                eprintln!("warning: --device auto: {why}");
            }
            eval
        }
    };
    Ok(eval
        .with_temperature_mode(args.temperature_mode.into())
        .with_portal_mode(args.portal.portal_mode.into()))
}

/// Loads, selects and prepares the lights on the chosen device, then refuses `outputs` that
/// name a file the command read through the stage (a layer, an IES profile, a TILT file, a
/// texture, a package), before anything is written (DESIGN.md §4; the files named on the
/// command line are checked before the stage is read).
pub fn prepare(
    args: &SceneArgs,
    device: Option<DeviceArg>,
    outputs: &[(&str, &Path)],
) -> CliResult<(Evaluator, PreparedScene)> {
    prepare_with(args, device, None, outputs)
}

/// [`prepare`] for irradiance to a relative tolerance (`--tolerance`); checked before the stage
/// is read, so that a bad value costs nothing.
pub fn prepare_irradiance(
    args: &SceneArgs,
    device: Option<DeviceArg>,
    tolerance: ToleranceArg,
    outputs: &[(&str, &Path)],
) -> CliResult<(Evaluator, PreparedScene)> {
    prepare_with(args, device, Some(tolerance.tolerance), outputs)
}

fn prepare_with(
    args: &SceneArgs,
    device: Option<DeviceArg>,
    tolerance: Option<f64>,
    outputs: &[(&str, &Path)],
) -> CliResult<(Evaluator, PreparedScene)> {
    if let Some(rel) = tolerance {
        // The range alone, before the stage is read (the device's own bound is checked below).
        Evaluator::cpu()
            .with_irradiance_tolerance(rel)
            .map_err(|e| Failure::bad_input(format!("--{e}")))?;
    }
    let (lights, layers) = lights_and_layers(args)?;
    if lights.is_empty() {
        eprintln!(
            "warning: {}: no light to evaluate; the output is all zeros",
            args.scene.display()
        );
    }
    let mut eval = evaluator(device, args)?;
    if let Some(rel) = tolerance {
        eval = eval
            .with_irradiance_tolerance(rel)
            .map_err(|e| Failure::bad_input(format!("--{e}")))?;
    }
    let scene = eval
        .prepare(&lights)
        .map_err(|e| in_scene(&args.scene, e))?;
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
    // Every file the command read, by what it was: no output may be one of them.
    let mut inputs: Vec<(String, &Path)> = layers
        .iter()
        .map(|f| (format!("layer of {}", args.scene.display()), f.as_path()))
        .collect();
    inputs.extend(
        scene
            .files_read()
            .into_iter()
            .map(|f| (format!("file of a light of {}", args.scene.display()), f)),
    );
    let inputs: Vec<(&str, &Path)> = inputs.iter().map(|(n, p)| (n.as_str(), *p)).collect();
    crate::io::check_outputs(outputs, &inputs)?;
    Ok((eval, scene))
}
