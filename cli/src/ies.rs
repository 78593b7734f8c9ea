//! `luxeval ies FILE`: an LM-63 or EULUMDAT file's report (header, integrated flux against the
//! header's lumens, peak, beam and field angles) and a polar candela plot.

use std::path::PathBuf;

use clap::Args;

use luxeval::IesProfile as Profile;

use crate::ies_report::{Report, trimmed};

use crate::exit::{CliResult, Failure};

#[derive(Args)]
pub struct IesArgs {
    /// The photometric file: LM-63 (.ies, any version) or EULUMDAT (.ldt), detected by content.
    file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Also write a polar candela plot (C0–C180 and C90–C270 planes) as PNG.
    #[arg(long, value_name = "PLOT.png")]
    png: Option<PathBuf>,
}

pub fn run(a: &IesArgs) -> CliResult {
    if let Some(png) = &a.png {
        crate::io::check_outputs(&[("--png", png)], &[("FILE", &a.file)])?;
    }
    let file = luxeval::read_ies(&a.file).map_err(|e| Failure::bad_input(e.to_string()))?;
    // The TILT file the profile names is read too: the plot must not overwrite it.
    if let (Some(png), Some(tilt)) = (&a.png, file.tilt_file(&a.file)) {
        crate::io::check_outputs(&[("--png", png)], &[("the TILT file of FILE", &tilt)])?;
    }
    let profile = Profile::new(&file)
        .map_err(|e| Failure::bad_input(format!("{}: {e}", a.file.display())))?;
    let report = Report::new(&a.file, &file, &profile);
    if let Some(png) = &a.png {
        report
            .plot(&profile)
            .write_png(png, &format!("polar candela plot of {}", a.file.display()))?;
    }
    for w in &report.warnings {
        eprintln!("warning: {}: {w}", a.file.display());
    }
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| Failure::runtime(e.to_string()))?
        );
        return Ok(());
    }
    let r = &report;
    outln!("{}", r.file);
    outln!("  format            {}", r.format);
    // Keyword lines ([KEYWORD] text) once, other labels as they are.
    for l in r.labels.iter().filter(|l| !l.trim_start().starts_with('[')) {
        outln!("  label             {l}");
    }
    for (k, v) in &r.keywords {
        outln!("  [{k}] {v}");
    }
    outln!(
        "  photometry        type {}, symmetry {}, tilt {}",
        r.photometric_type,
        r.symmetry,
        r.tilt
    );
    outln!(
        "  angles            {} horizontal ({}° to {}°), {} vertical ({}° to {}°)",
        r.horizontal_angles.count,
        trimmed(r.horizontal_angles.first),
        trimmed(r.horizontal_angles.last),
        r.vertical_angles.count,
        trimmed(r.vertical_angles.first),
        trimmed(r.vertical_angles.last)
    );
    outln!(
        "  lamps             {} × {} lm{}",
        trimmed(r.lamps),
        trimmed(r.lumens_per_lamp),
        if r.lumens_per_lamp < 0.0 {
            " (absolute photometry)"
        } else {
            ""
        }
    );
    outln!(
        "  multipliers       candela {}, ballast {}; input {} W",
        trimmed(r.candela_multiplier),
        trimmed(r.ballast_factor),
        trimmed(r.input_watts)
    );
    outln!(
        "  luminous size     {} × {} × {} {}",
        trimmed(r.dimensions[0]),
        trimmed(r.dimensions[1]),
        trimmed(r.dimensions[2]),
        r.units
    );
    outln!(
        "  flux              {} lm integrated{}",
        trimmed(r.integrated_lumens),
        match (r.rated_lumens, r.lumen_ratio) {
            (Some(rated), Some(ratio)) =>
                format!("; rated {} lm ({:.1} %)", trimmed(rated), 100.0 * ratio),
            _ => String::new(),
        }
    );
    outln!(
        "  peak              {} cd at H {}°, V {}°",
        trimmed(r.peak_candela),
        trimmed(r.peak_direction[0]),
        trimmed(r.peak_direction[1])
    );
    for p in &r.planes {
        let angle = |a: Option<f64>| a.map(|v| format!("{}°", trimmed(v))).unwrap_or("-".into());
        outln!(
            "  {:<17} max {} cd, beam {}, field {}",
            p.plane,
            trimmed(p.max_candela),
            angle(p.beam_angle),
            angle(p.field_angle)
        );
    }
    if let Some(png) = &a.png {
        outln!("  plot              {}", png.display());
    }
    Ok(())
}
