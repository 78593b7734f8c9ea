//! The report `luxeval ies FILE` prints (and writes as JSON): the header, the integrated flux
//! against the header's lumens, the peak, beam and field angles in the two main plane pairs,
//! and a polar candela plot.

use std::path::Path;

use serde::Serialize;

use crate::plot::numbers::decimal;
use crate::plot::{Canvas, polar};
use luxeval::{
    IesFile, IesFormat as Format, IesPlane as Plane, IesProfile as Profile, Lm63Version,
    PhotometricType, TiltSource,
};

/// Integrated and rated flux may differ by this much before the report warns (a luminaire's
/// light output ratio is normally ≤ 1, relative photometry scales by it; a larger mismatch is a
/// sign of wrong multipliers or a truncated grid).
pub const FLUX_MISMATCH: f64 = 0.02;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Range {
    pub count: usize,
    pub first: f64,
    pub last: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlaneReport {
    pub plane: &'static str,
    pub max_candela: f64,
    /// Full angle where the intensity falls to 50 % of the plane's maximum, degrees.
    pub beam_angle: Option<f64>,
    /// Full angle at 10 %, degrees.
    pub field_angle: Option<f64>,
}

/// Everything `luxeval ies` shows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    pub file: String,
    pub format: String,
    pub labels: Vec<String>,
    pub keywords: Vec<(String, String)>,
    pub photometric_type: &'static str,
    pub symmetry: String,
    pub horizontal_angles: Range,
    pub vertical_angles: Range,
    pub lamps: f64,
    /// Lumens per lamp as written (−1: absolute photometry).
    pub lumens_per_lamp: f64,
    pub candela_multiplier: f64,
    pub ballast_factor: f64,
    pub input_watts: f64,
    /// Luminous dimensions (width, length, height) in the file's units.
    pub dimensions: [f64; 3],
    pub units: &'static str,
    /// `NONE`, `INCLUDE` or the tilt file's name.
    pub tilt: String,
    /// lamps × lumens per lamp, `None` for absolute photometry.
    pub rated_lumens: Option<f64>,
    /// ∫ I dω of the bilinear interpolant (DESIGN.md §6 I6), multipliers applied.
    pub integrated_lumens: f64,
    pub lumen_ratio: Option<f64>,
    pub peak_candela: f64,
    /// The peak's file angles (H, V), degrees.
    pub peak_direction: [f64; 2],
    pub planes: Vec<PlaneReport>,
    pub warnings: Vec<String>,
}

fn format_name(f: Format) -> String {
    match f {
        Format::Eulumdat => "EULUMDAT".into(),
        Format::Lm63(v) => match v {
            Lm63Version::V1986 => "LM-63-1986",
            Lm63Version::V1991 => "LM-63-1991 (IESNA91)",
            Lm63Version::V1995 => "IESNA:LM-63-1995",
            Lm63Version::V2002 => "IESNA:LM-63-2002",
            Lm63Version::V2019 => "IES:LM-63-2019",
        }
        .into(),
    }
}

impl Report {
    /// The report of a file read as `file` and prepared as `profile`.
    pub fn new(path: &Path, file: &IesFile, profile: &Profile) -> Report {
        let range = |g: &[f64]| Range {
            count: g.len(),
            first: g.first().copied().unwrap_or(f64::NAN),
            last: g.last().copied().unwrap_or(f64::NAN),
        };
        let flux = profile.flux_check(file);
        let peak = profile.peak();
        let intensity = |e| profile.candela(e, 0.0);
        let planes = [(Plane::C0C180, "C0-C180"), (Plane::C90C270, "C90-C270")]
            .into_iter()
            .map(|(plane, name)| {
                let s = profile.spread(plane, &intensity);
                PlaneReport {
                    plane: name,
                    max_candela: s.max_candela,
                    beam_angle: s.beam,
                    field_angle: s.field,
                }
            })
            .collect();
        let mut warnings = Vec::new();
        if let Some(ratio) = flux.ratio
            && (ratio - 1.0).abs() > FLUX_MISMATCH
        {
            warnings.push(format!(
                "the integrated flux is {:.1} % of the header's {} lm ({} lm): {}",
                100.0 * ratio,
                trimmed(flux.rated_lm.unwrap_or(0.0)),
                trimmed(flux.integrated_lm),
                if ratio < 1.0 {
                    "a light output ratio below 1 (or a grid that does not cover the whole emission)"
                } else {
                    "more light than the lamps emit: check the multipliers"
                }
            ));
        }
        Report {
            file: path.display().to_string(),
            format: format_name(file.format),
            labels: file.labels.clone(),
            keywords: file.keywords.clone(),
            photometric_type: match file.photometric_type {
                PhotometricType::C => "C",
                PhotometricType::B => "B",
                PhotometricType::A => "A",
            },
            symmetry: format!("{:?}", profile.h_fold),
            horizontal_angles: range(&file.horizontal_angles),
            vertical_angles: range(&file.vertical_angles),
            lamps: file.lamps,
            lumens_per_lamp: file.lumens_per_lamp,
            candela_multiplier: file.candela_multiplier,
            ballast_factor: file.ballast_factor,
            input_watts: file.input_watts,
            dimensions: [file.width, file.length, file.height],
            units: if file.units == 1.0 { "feet" } else { "meters" },
            tilt: match &file.tilt {
                None => "NONE".into(),
                Some(t) => match &t.source {
                    TiltSource::Include => "INCLUDE".into(),
                    TiltSource::File(name) => name.clone(),
                },
            },
            rated_lumens: flux.rated_lm,
            integrated_lumens: flux.integrated_lm,
            lumen_ratio: flux.ratio,
            peak_candela: peak.candela,
            peak_direction: [peak.h, peak.v],
            planes,
            warnings,
        }
    }

    /// The polar candela plot of `profile` (multipliers applied, no tilt, no angleScale).
    pub fn plot(&self, profile: &Profile) -> Canvas {
        let curves = polar::c_plane_curves(|e| profile.candela(e, 0.0), 0.5);
        let name = Path::new(&self.file)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| self.file.clone());
        polar::render(
            &name,
            &format!(
                "{} type {}, peak {} cd, {} lm",
                self.format,
                self.photometric_type,
                trimmed(self.peak_candela),
                trimmed(self.integrated_lumens)
            ),
            &curves,
        )
    }
}

/// A number with at most 4 decimals, none from 1000 up, without trailing zeros.
pub fn trimmed(v: f64) -> String {
    decimal(v, if v.abs() >= 1000.0 { 0 } else { 4 })
}
