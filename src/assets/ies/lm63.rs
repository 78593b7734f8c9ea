//! ANSI/IES LM-63 photometric files (1986, 1991, 1995, 2002, 2019), read from scratch.
//!
//! The contract is DESIGN.md §6 I1 (reading) and I3 (which type C horizontal coverages exist):
//! - the version comes from the first non-empty line (`IES:LM-63-2019`, `IESNA:LM-63-2002`,
//!   `IESNA:LM-63-1995`, `IESNA91`, anything else → 1986);
//! - every line before the first line starting (after blanks) with `TILT=` is a label or a
//!   `[KEYWORD] text` line, kept for reports; a file may begin with `TILT=`;
//! - after that line the file is numbers separated by any mix of blanks, tabs, CR, LF and commas,
//!   line breaks meaning nothing (LM-63-2002 §3);
//! - `TILT=INCLUDE` / `TILT=<file>`: geometry, count, angles, multipliers (LM-63-2002 §3.2.1);
//! - then the 10 + 3 header numbers, the vertical and horizontal angles and the candela values,
//!   horizontal angle by horizontal angle, and nothing after them.
//!
//! Candela used (§6 I1): `value · m · b · (f₃ only for 1986/1991)`: f₃ is the ballast-lamp
//! photometric factor up to LM-63-1991, "future use" in 1995/2002 and the file generation type
//! in 2019 (Radiance's ies2rad drops it from 1995 on for the same reason).

use super::error::{IesError, IesErrorKind as K};
use super::eulumdat::EulumdatInfo;
use super::text::{Tokens, split_lines, trim};

/// LM-63 edition, from the first non-empty line (§6 I1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Lm63Version {
    V1986,
    V1991,
    V1995,
    V2002,
    V2019,
}

/// Where a profile came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Lm63(Lm63Version),
    /// EULUMDAT (.ldt), converted to the equivalent type C layout (see `eulumdat`).
    Eulumdat,
}

/// LM-63 photometric type (file codes 1, 2, 3), LM-63-2002 §3.16; frames in §6 I2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotometricType {
    C,
    B,
    A,
}

impl PhotometricType {
    /// The LM-63 code: 1 = C, 2 = B, 3 = A.
    pub fn code(self) -> u32 {
        match self {
            PhotometricType::C => 1,
            PhotometricType::B => 2,
            PhotometricType::A => 3,
        }
    }
}

/// Where the tilt table came from.
#[derive(Clone, Debug, PartialEq)]
pub enum TiltSource {
    Include,
    /// `TILT=<name>`: the name as written in the file.
    File(String),
}

/// LM-63 tilt data (§6 I5): multiplier versus luminaire tilt angle, measured with lamp-to-
/// luminaire geometry `geometry` (1, 2 or 3; validated and reported, no effect on values).
#[derive(Clone, Debug, PartialEq)]
pub struct Tilt {
    pub source: TiltSource,
    pub geometry: u8,
    /// Strictly increasing, degrees.
    pub angles: Vec<f64>,
    /// Non-negative multipliers, one per angle.
    pub factors: Vec<f64>,
}

/// Type C horizontal coverage (§6 I3): which of LM-63's symmetries a grid `h₀..h_L` means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TypeCCoverage {
    /// One angle (any value): rotationally symmetric.
    Single,
    /// 0..90: symmetric about the 0–180 and 90–270 planes.
    Quadrant,
    /// 0..180: symmetric about the 0–180 plane.
    Half,
    /// 90..270: symmetric about the 90–270 plane.
    HalfC90,
    /// 0..h_L with 180 < h_L ≤ 360: no symmetry; `(h_L, 360)` wraps to the 0 column.
    Full,
}

/// Grid ends are recognised within this many degrees (§6 I3, like Cycles' `angle_close`).
pub const END_TOLERANCE_DEG: f64 = 1e-4;

/// Classifies a strictly increasing type C horizontal grid, or `None` when LM-63 gives it no
/// meaning (malformed, §6 I3 "anything else").
pub fn type_c_coverage(h: &[f64]) -> Option<TypeCCoverage> {
    coverage_and_ends(h).map(|(c, _)| c)
}

/// The coverage and the exact ends the recognised grid ends stand for (`None` for one angle):
/// the profile snaps its first and last angles to them so that folded angles land inside. A
/// grid whose inner angles would not stay strictly inside the snapped ends is malformed.
pub fn coverage_and_ends(h: &[f64]) -> Option<(TypeCCoverage, Option<(f64, f64)>)> {
    let near = |a: f64, b: f64| (a - b).abs() <= END_TOLERANCE_DEG;
    let (&first, &last) = (h.first()?, h.last()?);
    let n = h.len();
    if n == 1 {
        return Some((TypeCCoverage::Single, None));
    }
    let (coverage, ends) = if near(first, 0.0) && near(last, 90.0) {
        (TypeCCoverage::Quadrant, (0.0, 90.0))
    } else if near(first, 0.0) && near(last, 180.0) {
        (TypeCCoverage::Half, (0.0, 180.0))
    } else if near(first, 0.0) && last > 180.0 && last <= 360.0 + END_TOLERANCE_DEG {
        (
            TypeCCoverage::Full,
            (0.0, if near(last, 360.0) { 360.0 } else { last }),
        )
    } else if near(first, 90.0) && near(last, 270.0) {
        (TypeCCoverage::HalfC90, (90.0, 270.0))
    } else {
        return None;
    };
    let inside = n == 2 || (h[1] > ends.0 && h[n - 2] < ends.1);
    inside.then_some((coverage, Some(ends)))
}

/// A photometric file as read: the header fields for reports and the grid as written.
#[derive(Clone, Debug, PartialEq)]
pub struct IesFile {
    pub format: Format,
    /// Label lines before `TILT=` (the version line excluded), lossy UTF-8.
    pub labels: Vec<String>,
    /// `[KEYWORD] text` label lines, split.
    pub keywords: Vec<(String, String)>,
    pub tilt: Option<Tilt>,
    pub lamps: f64,
    /// −1 = absolute photometry.
    pub lumens_per_lamp: f64,
    /// `m`.
    pub candela_multiplier: f64,
    pub photometric_type: PhotometricType,
    /// 1 = feet, 2 = metres (reported only).
    pub units: f64,
    pub width: f64,
    pub length: f64,
    pub height: f64,
    /// `b`.
    pub ballast_factor: f64,
    /// `f₃`: ballast-lamp photometric factor (1986/1991), future use (1995/2002), file
    /// generation type (2019).
    pub f3: f64,
    pub input_watts: f64,
    /// Degrees, strictly increasing, at least 2.
    pub vertical_angles: Vec<f64>,
    /// Degrees, strictly increasing, at least 1.
    pub horizontal_angles: Vec<f64>,
    /// Values as written (before multipliers), horizontal angle by horizontal angle:
    /// `candela[i·nV + j]` is at `(horizontal_angles[i], vertical_angles[j])`.
    pub candela: Vec<f64>,
    /// The EULUMDAT fields, for files read by `eulumdat::parse_eulumdat`.
    pub eulumdat: Option<EulumdatInfo>,
}

impl IesFile {
    /// The TILT file this profile names (`TILT=<name>`), where `luxeval::read_ies` read it
    /// from for the profile file at `profile`; `None` for `TILT=NONE` or `INCLUDE`.
    pub fn tilt_file(&self, profile: &std::path::Path) -> Option<std::path::PathBuf> {
        match &self.tilt.as_ref()?.source {
            TiltSource::File(name) => Some(super::eulumdat::tilt_path(profile, name)),
            TiltSource::Include => None,
        }
    }

    /// `m · b · (f₃ for 1986/1991)`: what every stored value is multiplied by (§6 I1).
    pub fn candela_scale(&self) -> f64 {
        let f3 = match self.format {
            Format::Lm63(Lm63Version::V1986 | Lm63Version::V1991) => self.f3,
            _ => 1.0,
        };
        self.candela_multiplier * self.ballast_factor * f3
    }

    /// Rated lamp lumens from the header (`lamps · lumens/lamp`), `None` for absolute
    /// photometry (lumens −1). EULUMDAT: the first lamp set's total flux.
    pub fn rated_lumens(&self) -> Option<f64> {
        if let Some(info) = &self.eulumdat {
            return info.lamp_sets.first().map(|s| s.flux_lm);
        }
        (self.lumens_per_lamp >= 0.0).then_some(self.lamps * self.lumens_per_lamp)
    }
}

/// Reads an LM-63 file. `tilt_resolver` returns the bytes of the file named by `TILT=<name>`
/// (the caller resolves it against the `.ies` file's directory) or a reason it cannot.
pub fn parse_lm63(
    text: &[u8],
    tilt_resolver: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<IesFile, IesError> {
    let text = text.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(text);
    let lines = split_lines(text);
    let end_line = lines.last().map_or(1, |l| l.0);
    let tilt_at = lines
        .iter()
        .position(|(_, l)| trim(l).starts_with(b"TILT="))
        .ok_or_else(|| IesError::whole_file(K::NoTiltLine))?;
    let (tilt_no, tilt_line) = lines[tilt_at];

    // §6 I1: the version line is the first non-empty one; anything unrecognised is 1986, whose
    // files start with free label lines (so that line is a label too).
    let first = lines[..tilt_at].iter().find(|(_, l)| !trim(l).is_empty());
    let version = first.map_or(Lm63Version::V1986, |(_, l)| version_of(trim(l)));
    let mut labels = Vec::new();
    let mut keywords = Vec::new();
    for (n, l) in &lines[..tilt_at] {
        let l = trim(l);
        if l.is_empty() || (version != Lm63Version::V1986 && Some(*n) == first.map(|f| f.0)) {
            continue;
        }
        let s = String::from_utf8_lossy(l).into_owned();
        if let Some(rest) = s.strip_prefix('[')
            && let Some((key, value)) = rest.split_once(']')
        {
            keywords.push((key.to_string(), value.trim().to_string()));
        }
        labels.push(s);
    }

    let mut toks = Tokens::new(&lines[tilt_at + 1..], end_line);
    let tilt_value = trim(&trim(tilt_line)[b"TILT=".len()..]);
    let tilt = if tilt_value.eq_ignore_ascii_case(b"NONE") {
        None
    } else if tilt_value.eq_ignore_ascii_case(b"INCLUDE") {
        Some(read_tilt(&mut toks, TiltSource::Include)?)
    } else if tilt_value.is_empty() {
        return Err(IesError::at(tilt_no, K::EmptyTilt));
    } else {
        let name = String::from_utf8_lossy(tilt_value).into_owned();
        Some(read_tilt_file(&name, tilt_no, tilt_resolver)?)
    };

    // LM-63-2002 §3.3–3.15: the two header lines.
    let (lamps, _) = toks.number("number of lamps")?;
    let (lumens_per_lamp, _) = toks.number("lumens per lamp")?;
    let (candela_multiplier, m_line) = toks.number("candela multiplier")?;
    non_negative(candela_multiplier, m_line, "candela multiplier")?;
    let (n_v, n_v_line) = toks.count("number of vertical angles", 2, 1)?;
    let (n_h, _) = toks.count("number of horizontal angles", 1, 1)?;
    let (kind, kind_line) = toks.number("photometric type")?;
    let photometric_type = match kind {
        1.0 => PhotometricType::C,
        2.0 => PhotometricType::B,
        3.0 => PhotometricType::A,
        other => return Err(IesError::at(kind_line, K::BadPhotometricType(other))),
    };
    let (units, _) = toks.number("units type")?;
    let (width, _) = toks.number("luminous width")?;
    let (length, _) = toks.number("luminous length")?;
    let (height, _) = toks.number("luminous height")?;
    let (ballast_factor, b_line) = toks.number("ballast factor")?;
    non_negative(ballast_factor, b_line, "ballast factor")?;
    let (f3, f3_line) = toks.number("ballast-lamp photometric factor / file generation type")?;
    if version <= Lm63Version::V1991 {
        non_negative(f3, f3_line, "ballast-lamp photometric factor")?;
    }
    let (input_watts, _) = toks.number("input watts")?;

    // nV and nH each fit in what remains (checked by `count`); their product is only used to
    // bound the allocation by the tokens left, so a short file ends in a MissingValue error at
    // its last line rather than in an allocation the file cannot justify.
    let Some(n_values) = n_v.checked_mul(n_h) else {
        return Err(IesError::at(
            n_v_line,
            K::CountTooLarge {
                what: "candela values",
                count: n_v as f64 * n_h as f64,
                remaining: toks.remaining(),
            },
        ));
    };

    let (lo, hi, range) = match photometric_type {
        PhotometricType::C => (0.0, 180.0, "type C vertical angles lie in [0, 180]"),
        _ => (-90.0, 90.0, "type A/B angles lie in [-90, 90]"),
    };
    let (vertical_angles, _) = toks.increasing(n_v, "vertical angles", lo, hi, range)?;
    let (horizontal_angles, h_line) = match photometric_type {
        PhotometricType::C => toks.increasing(
            n_h,
            "horizontal angles",
            f64::MIN,
            f64::MAX,
            "any finite value",
        )?,
        _ => toks.increasing(n_h, "horizontal angles", lo, hi, range)?,
    };
    if photometric_type == PhotometricType::C && type_c_coverage(&horizontal_angles).is_none() {
        return Err(IesError::at(
            h_line,
            K::BadCoverage {
                first: horizontal_angles[0],
                last: horizontal_angles[n_h - 1],
            },
        ));
    }

    let mut candela = Vec::with_capacity(n_values.min(toks.remaining()));
    let mut peak = 0.0f64;
    for _ in 0..n_values {
        let (v, line) = toks.number("candela value")?;
        if v < 0.0 {
            return Err(IesError::at(line, K::NegativeCandela(v)));
        }
        peak = peak.max(v);
        candela.push(v);
    }
    if let Some((tok, line)) = toks.peek() {
        return Err(IesError::at(line, K::TrailingToken(super::text::show(tok))));
    }

    let file = IesFile {
        format: Format::Lm63(version),
        labels,
        keywords,
        tilt,
        lamps,
        lumens_per_lamp,
        candela_multiplier,
        photometric_type,
        units,
        width,
        length,
        height,
        ballast_factor,
        f3,
        input_watts,
        vertical_angles,
        horizontal_angles,
        candela,
        eulumdat: None,
    };
    // Each factor is finite, but their product with the largest value may not be.
    let scaled = peak * file.candela_scale();
    if !scaled.is_finite() {
        return Err(IesError::at(m_line, K::ScaledCandela(scaled)));
    }
    Ok(file)
}

/// §6 I1's version table.
fn version_of(line: &[u8]) -> Lm63Version {
    if line.starts_with(b"IES:LM-63-2019") {
        Lm63Version::V2019
    } else if line.starts_with(b"IESNA:LM-63-2002") {
        Lm63Version::V2002
    } else if line.starts_with(b"IESNA:LM-63-1995") {
        Lm63Version::V1995
    } else if line.starts_with(b"IESNA91") {
        Lm63Version::V1991
    } else {
        Lm63Version::V1986
    }
}

fn non_negative(v: f64, line: usize, what: &'static str) -> Result<(), IesError> {
    if v < 0.0 {
        return Err(IesError::at(
            line,
            K::OutOfRange {
                what,
                value: v,
                expected: "must not be negative",
            },
        ));
    }
    Ok(())
}

/// LM-63-2002 §3.2.1: lamp-to-luminaire geometry (1, 2, 3), number of pairs, the angles
/// (strictly increasing), the multipliers (§6 I5).
fn read_tilt(toks: &mut Tokens, source: TiltSource) -> Result<Tilt, IesError> {
    let (geometry, _) = toks.integer("TILT lamp-to-luminaire geometry", 1.0, 3.0, "1, 2 or 3")?;
    let (n, _) = toks.count("number of TILT angles", 1, 2)?;
    let (angles, _) = toks.increasing(n, "TILT angles", f64::MIN, f64::MAX, "any finite value")?;
    let mut factors = Vec::with_capacity(n);
    for _ in 0..n {
        let (f, line) = toks.number("TILT multiplier")?;
        non_negative(f, line, "TILT multiplier")?;
        factors.push(f);
    }
    Ok(Tilt {
        source,
        geometry: geometry as u8,
        angles,
        factors,
    })
}

/// `TILT=<name>`: the same four items read from the named file, which holds nothing else.
/// Errors carry the `TILT=` line of the photometric file and the name (and line) in the other.
fn read_tilt_file(
    name: &str,
    tilt_line: usize,
    resolver: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Tilt, IesError> {
    let bytes = resolver(name).map_err(|reason| {
        IesError::at(
            tilt_line,
            K::TiltFileUnreadable {
                name: name.to_string(),
                reason,
            },
        )
    })?;
    let wrap = |e: IesError| {
        IesError::at(
            tilt_line,
            K::InTiltFile {
                name: name.to_string(),
                line: e.line,
                kind: Box::new(e.kind),
            },
        )
    };
    let lines = split_lines(&bytes);
    let end = lines.last().map_or(1, |l| l.0);
    let mut toks = Tokens::new(&lines, end);
    let tilt = read_tilt(&mut toks, TiltSource::File(name.to_string())).map_err(wrap)?;
    if let Some((tok, line)) = toks.peek() {
        return Err(wrap(IesError::at(
            line,
            K::TrailingToken(super::text::show(tok)),
        )));
    }
    Ok(tilt)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_sets_of_section_6_i3() {
        use TypeCCoverage::*;
        assert_eq!(type_c_coverage(&[42.0]), Some(Single));
        assert_eq!(type_c_coverage(&[0.0, 45.0, 90.0]), Some(Quadrant));
        assert_eq!(type_c_coverage(&[0.0, 90.00005]), Some(Quadrant));
        assert_eq!(type_c_coverage(&[0.0, 180.0]), Some(Half));
        assert_eq!(type_c_coverage(&[90.0, 270.0]), Some(HalfC90));
        assert_eq!(type_c_coverage(&[0.0, 200.0]), Some(Full));
        assert_eq!(type_c_coverage(&[0.0, 360.0]), Some(Full));
        assert_eq!(type_c_coverage(&[0.0, 45.0]), None);
        assert_eq!(type_c_coverage(&[0.0, 120.0]), None);
        assert_eq!(type_c_coverage(&[0.0, 361.0]), None);
        assert_eq!(type_c_coverage(&[10.0, 350.0]), None);
        assert_eq!(type_c_coverage(&[90.0, 180.0]), None);
        // Snapping 90.00005 to 90 would put it below 90.00001.
        assert_eq!(type_c_coverage(&[0.0, 90.00001, 90.00005]), None);
        assert_eq!(
            coverage_and_ends(&[0.00002, 359.99999]),
            Some((Full, Some((0.0, 360.0))))
        );
    }

    #[test]
    fn version_table() {
        assert_eq!(version_of(b"IES:LM-63-2019"), Lm63Version::V2019);
        assert_eq!(version_of(b"IESNA:LM-63-2002"), Lm63Version::V2002);
        assert_eq!(version_of(b"IESNA:LM-63-1995"), Lm63Version::V1995);
        assert_eq!(version_of(b"IESNA91"), Lm63Version::V1991);
        assert_eq!(version_of(b"IESNA:LM-63-1986"), Lm63Version::V1986);
        assert_eq!(version_of(b"ACME LIGHTING"), Lm63Version::V1986);
    }
}
