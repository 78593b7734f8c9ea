//! EULUMDAT (`.ldt`) files, and `parse_any`, which tells the two formats apart by content.
//!
//! EULUMDAT (Stockmar 1990; EULUMDAT/2, CIBSE 1998) is line-based: lines 1–25 are fixed fields,
//! line 26 the number `n` of standard lamp sets, then six groups of `n` lines (26a number of
//! lamps, 26b type, 26c total luminous flux of the set's lamps in lm, 26d colour, 26e colour
//! rendering, 26f watts incl. ballast), 10 direct ratios, the `Mc` C-plane angles, the `Ng` γ
//! angles and the intensities in cd/klm, plane by plane, for planes `Mc1..=Mc2`:
//!
//! | Isym | symmetry | stored planes (1-based) |
//! | --- | --- | --- |
//! | 0 | none | 1..Mc |
//! | 1 | about the vertical axis | 1 |
//! | 2 | to plane C0–C180 | 1..Mc/2+1 (C0..C180) |
//! | 3 | to plane C90–C270 | 3Mc/4+1..3Mc/4+1+Mc/2, wrapping past Mc (C270..C360=C0..C90) |
//! | 4 | to C0–C180 and C90–C270 | 1..Mc/4+1 (C0..C90) |
//!
//! The C-γ system is LM-63's type C (γ = 0 nadir, C0 the photometric horizontal, C90 a quarter
//! turn counter-clockwise seen from above), so a file becomes an `IesFile` of photometric type C
//! whose horizontal grid is one of §6 I3's coverages — exactly, without resampling:
//! Isym 1 → one angle; 2 → 0..180; 4 → 0..90; 3 → the stored planes mirrored about the 90–270
//! plane (`C' = 180 − C mod 360`, which is the same light) so that they read 90..270; 0 → 0..h_L
//! (wrapping to C0), with a copy of the C0 plane appended at 360 when `h_L ≤ 180`.
//!
//! **Candela.** `I = value · conversion factor (line 24) · Φ/1000`, where Φ is line 26c of the
//! **first** lamp set: the total luminous flux of all the lamps of that set (the field already
//! counts the set's 26a lamps, so it is not multiplied by them again). Further sets are
//! alternative lampings of the same luminaire, kept for reports, never summed. A negative lamp
//! count (absolute photometry in some LED files) changes nothing: Φ is then the flux the cd/klm
//! values refer to.

use std::path::Path;

use super::error::{IesError, IesErrorKind as K};
use super::lm63::{Format, IesFile, PhotometricType, TypeCCoverage, parse_lm63, type_c_coverage};
use super::text::{Tokens, parse_number_decimal_comma, show, split_lines, trim};

/// One standard lamp set (lines 26a–26f).
#[derive(Clone, Debug, PartialEq)]
pub struct LampSet {
    /// 26a; negative in some absolute-photometry files.
    pub count: f64,
    pub kind: String,
    /// 26c: total luminous flux of the set's lamps, lm.
    pub flux_lm: f64,
    pub colour: String,
    pub colour_rendering: String,
    pub watts: f64,
}

/// The EULUMDAT fields kept for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct EulumdatInfo {
    pub company: String,
    pub ityp: u8,
    pub isym: u8,
    pub mc: usize,
    pub dc: f64,
    pub ng: usize,
    pub dg: f64,
    pub report_number: String,
    pub luminaire_name: String,
    pub luminaire_number: String,
    pub file_name: String,
    pub date_user: String,
    /// Lines 13–21 in mm: luminaire length, width, height; luminous area length, width;
    /// luminous area height at C0, C90, C180, C270.
    pub dimensions_mm: [f64; 9],
    pub downward_flux_fraction: f64,
    pub light_output_ratio: f64,
    pub conversion_factor: f64,
    /// Line 25: tilt during measurement (reported; not an LM-63 tilt table).
    pub measurement_tilt_deg: f64,
    pub lamp_sets: Vec<LampSet>,
    pub direct_ratios: Vec<f64>,
    /// All `Mc` C-plane angles of line 28, as written.
    pub c_angles: Vec<f64>,
}

/// Reads a photometric file of either format. The format is told **by content**, never by the
/// file name:
/// 1. a line that starts (after blanks) with `TILT=` → LM-63 (LM-63 requires that line, and an
///    EULUMDAT file has no reason to hold one);
/// 2. otherwise lines 2–7 each holding exactly one number (Ityp, Isym, Mc, Dc, Ng, Dg) →
///    EULUMDAT;
/// 3. otherwise an error (`UnknownFormat`, no line).
pub fn parse_any(
    text: &[u8],
    tilt_resolver: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<IesFile, IesError> {
    let lines = split_lines(text);
    if lines.iter().any(|(_, l)| trim(l).starts_with(b"TILT=")) {
        return parse_lm63(text, tilt_resolver);
    }
    let one_number = |l: &[u8]| {
        let t = trim(l);
        !t.is_empty()
            && !t.contains(&b' ')
            && !t.contains(&b'\t')
            && parse_number_decimal_comma(t, "").is_ok()
    };
    if lines.len() >= 7 && lines[1..7].iter().all(|(_, l)| one_number(l)) {
        return parse_eulumdat(text);
    }
    Err(IesError::whole_file(K::UnknownFormat))
}

/// Where `TILT=<name>` of the profile file `profile` is read from: beside it (LM-63-2002 §3;
/// DESIGN.md §6 I1).
pub(crate) fn tilt_path(profile: &Path, name: &str) -> std::path::PathBuf {
    profile
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
        .join(name)
}

/// Reads `path` with `parse_any`, resolving `TILT=<name>` against the file's directory
/// (§6 I1). Every error names `path`; a missing TILT file's error names both files.
pub fn read_file(path: &Path) -> Result<IesFile, IesError> {
    let name = path.display().to_string();
    let with_file = |mut e: IesError| {
        e.file = Some(name.clone());
        e
    };
    let bytes = crate::assets::package::read_file(path)
        .map_err(|e| with_file(IesError::whole_file(K::Io(e.to_string()))))?;
    let resolver = |tilt: &str| {
        let p = tilt_path(path, tilt);
        crate::assets::package::read_file(&p).map_err(|e| format!("{}: {e}", p.display()))
    };
    parse_any(&bytes, &resolver).map_err(with_file)
}

/// The fixed-line part of an EULUMDAT file.
struct Fixed<'a> {
    lines: Vec<(usize, &'a [u8])>,
    next: usize,
}

impl<'a> Fixed<'a> {
    /// The next line (1-based number `self.next + 1`) or a "missing" error naming it.
    fn line(&mut self, what: &'static str) -> Result<(usize, &'a [u8]), IesError> {
        let n = self.next + 1;
        let l = self
            .lines
            .get(self.next)
            .map(|&(_, l)| l)
            .ok_or_else(|| IesError::at(n, K::MissingValue { what }))?;
        self.next += 1;
        Ok((n, l))
    }

    fn text(&mut self, what: &'static str) -> Result<String, IesError> {
        let (_, l) = self.line(what)?;
        Ok(String::from_utf8_lossy(trim(l)).into_owned())
    }

    /// A line holding exactly one number.
    fn number(&mut self, what: &'static str) -> Result<(f64, usize), IesError> {
        let (n, l) = self.line(what)?;
        let t = trim(l);
        if t.is_empty() {
            return Err(IesError::at(n, K::MissingValue { what }));
        }
        parse_number_decimal_comma(t, what)
            .map(|v| (v, n))
            .map_err(|k| IesError::at(n, k))
    }

    fn integer(&mut self, what: &'static str, lo: f64, hi: f64) -> Result<f64, IesError> {
        let (v, n) = self.number(what)?;
        if v.fract() != 0.0 {
            return Err(IesError::at(n, K::NotAnInteger { what, value: v }));
        }
        if v < lo || v > hi {
            return Err(out_of_range(
                n,
                what,
                v,
                "outside the values EULUMDAT defines",
            ));
        }
        Ok(v)
    }

    fn non_negative(&mut self, what: &'static str) -> Result<f64, IesError> {
        let (v, n) = self.number(what)?;
        if v < 0.0 {
            return Err(out_of_range(n, what, v, "must not be negative"));
        }
        Ok(v)
    }
}

/// The error for `value` of `what` on line `n` outside its range.
fn out_of_range(n: usize, what: &'static str, value: f64, expected: &'static str) -> IesError {
    IesError::at(
        n,
        K::OutOfRange {
            what,
            value,
            expected,
        },
    )
}

/// Reads an EULUMDAT file into the type C layout described in the module documentation.
pub fn parse_eulumdat(text: &[u8]) -> Result<IesFile, IesError> {
    let text = text.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(text);
    let lines = split_lines(text);
    let end_line = lines.last().map_or(1, |l| l.0);
    let mut f = Fixed { lines, next: 0 };
    let company = f.text("company identification")?;
    let ityp = f.integer("Ityp", 0.0, 3.0)? as u8;
    let isym = f.integer("Isym", 0.0, 4.0)? as u8;
    let mc_line = f.next + 1;
    // Mc and Ng are bounded by the file's size below, before anything is allocated.
    let mc = f.integer("Mc (number of C-planes)", 1.0, f64::MAX)?;
    // Mc1..Mc2 (module docs) need Mc even for Isym 2 and a multiple of 4 for Isym 3 and 4.
    let reason = match isym {
        2 if mc % 2.0 != 0.0 => Some("Mc must be even"),
        3 | 4 if mc % 4.0 != 0.0 => Some("Mc must be a multiple of 4"),
        _ => None,
    };
    if let Some(reason) = reason {
        let mc = mc as usize;
        return Err(IesError::at(mc_line, K::BadSymmetry { isym, mc, reason }));
    }
    let dc = f.number("Dc")?.0;
    let ng_line = f.next + 1;
    let ng = f.integer("Ng (number of intensities per C-plane)", 2.0, f64::MAX)?;
    let dg = f.number("Dg")?.0;
    let report_number = f.text("measurement report number")?;
    let luminaire_name = f.text("luminaire name")?;
    let luminaire_number = f.text("luminaire number")?;
    let file_name = f.text("file name")?;
    let date_user = f.text("date/user")?;
    let mut dimensions_mm = [0.0; 9];
    for d in &mut dimensions_mm {
        *d = f.number("luminaire dimension (mm)")?.0;
    }
    let downward_flux_fraction = f.number("downward flux fraction")?.0;
    let light_output_ratio = f.number("light output ratio")?.0;
    let conversion_factor = f.non_negative("conversion factor for luminous intensities")?;
    let measurement_tilt_deg = f.number("tilt during measurement")?.0;
    let sets_line = f.next + 1;
    let n_sets = f.integer("number of standard sets of lamps", 0.0, f64::MAX)?;
    if n_sets == 0.0 {
        return Err(IesError::at(sets_line, K::NoLampSet));
    }
    let lines_left = f.lines.len().saturating_sub(f.next);
    if n_sets * 6.0 > lines_left as f64 {
        return Err(IesError::at(
            sets_line,
            K::CountTooLarge {
                what: "standard sets of lamps (6 lines each)",
                count: n_sets,
                remaining: lines_left,
            },
        ));
    }
    let n_sets = n_sets as usize;
    let mut counts = Vec::with_capacity(n_sets);
    for _ in 0..n_sets {
        counts.push(f.number("number of lamps")?.0);
    }
    let mut kinds = Vec::with_capacity(n_sets);
    for _ in 0..n_sets {
        kinds.push(f.text("type of lamps")?);
    }
    let mut fluxes = Vec::with_capacity(n_sets);
    for _ in 0..n_sets {
        fluxes.push(f.non_negative("total luminous flux of lamps")?);
    }
    let mut colours = Vec::with_capacity(n_sets);
    for _ in 0..n_sets {
        colours.push(f.text("colour appearance")?);
    }
    let mut rendering = Vec::with_capacity(n_sets);
    for _ in 0..n_sets {
        rendering.push(f.text("colour rendering")?);
    }
    let mut lamp_sets = Vec::with_capacity(n_sets);
    for i in 0..n_sets {
        lamp_sets.push(LampSet {
            count: counts[i],
            kind: std::mem::take(&mut kinds[i]),
            flux_lm: fluxes[i],
            colour: std::mem::take(&mut colours[i]),
            colour_rendering: std::mem::take(&mut rendering[i]),
            watts: f.number("wattage including ballast")?.0,
        });
    }

    // From here on: numbers separated by blanks or line breaks (one per line in practice).
    let mut toks = Tokens::new_decimal_comma(&f.lines[f.next..], end_line);
    let mut direct_ratios = Vec::with_capacity(10);
    for _ in 0..10 {
        direct_ratios.push(toks.number("direct ratio")?.0);
    }
    let too_many = |what, count: f64, line, remaining| {
        IesError::at(
            line,
            K::CountTooLarge {
                what,
                count,
                remaining,
            },
        )
    };
    if mc > toks.remaining() as f64 {
        return Err(too_many("C-plane angles", mc, mc_line, toks.remaining()));
    }
    let mc = mc as usize;
    let (c_angles, c_line) = toks.increasing(mc, "C-plane angles", 0.0, 360.0, "[0, 360)")?;
    if c_angles[mc - 1] >= 360.0 {
        let expected = "[0, 360)";
        let value = c_angles[mc - 1];
        return Err(out_of_range(c_line, "C-plane angles", value, expected));
    }
    if ng > toks.remaining() as f64 {
        return Err(too_many("gamma angles", ng, ng_line, toks.remaining()));
    }
    let ng = ng as usize;
    let (gamma, _) = toks.increasing(ng, "gamma angles", 0.0, 180.0, "[0, 180]")?;

    let stored: Vec<usize> = match isym {
        0 => (0..mc).collect(),
        1 => vec![0],
        2 => (0..=mc / 2).collect(),
        3 => (0..=mc / 2).map(|k| (3 * mc / 4 + k) % mc).collect(),
        _ => (0..=mc / 4).collect(),
    };
    // Mc and Ng each fit in what remains; the intensities' allocation is bounded by it too, so
    // a short file ends in MissingValue at its last line.
    let mut planes: Vec<Vec<f64>> = Vec::with_capacity(stored.len());
    for _ in &stored {
        let mut plane = Vec::with_capacity(ng.min(toks.remaining()));
        for _ in 0..ng {
            let (v, line) = toks.number("luminous intensity (cd/klm)")?;
            if v < 0.0 {
                return Err(IesError::at(line, K::NegativeCandela(v)));
            }
            plane.push(v);
        }
        planes.push(plane);
    }
    if let Some((tok, line)) = toks.peek() {
        return Err(IesError::at(line, K::TrailingToken(show(tok))));
    }

    // The equivalent LM-63 type C horizontal grid (module docs), checked against §6 I3.
    let (mut h, want): (Vec<f64>, TypeCCoverage) = match isym {
        1 => (vec![0.0], TypeCCoverage::Single),
        2 => (
            stored.iter().map(|&k| c_angles[k]).collect(),
            TypeCCoverage::Half,
        ),
        4 => (
            stored.iter().map(|&k| c_angles[k]).collect(),
            TypeCCoverage::Quadrant,
        ),
        3 => {
            // Mirror about the 90–270 plane: C' = 180 − C (mod 360) maps C270..C0..C90 onto
            // 270..180..90; reversed, the planes read 90..270 in increasing order.
            planes.reverse();
            let mirrored = stored
                .iter()
                .rev()
                .map(|&k| (180.0 - c_angles[k]).rem_euclid(360.0));
            (mirrored.collect(), TypeCCoverage::HalfC90)
        }
        _ if mc == 1 => (vec![c_angles[0]], TypeCCoverage::Single),
        _ => (c_angles.clone(), TypeCCoverage::Full),
    };
    if want == TypeCCoverage::Full && h[h.len() - 1] <= 180.0 {
        // Isym 0 with every plane in 0..180: the 180..360 span interpolates back to C0,
        // which a copy of C0 at 360 expresses exactly.
        h.push(360.0);
        planes.push(planes[0].clone());
    }
    let increasing = h.windows(2).all(|w| w[0] < w[1]);
    if !increasing || type_c_coverage(&h) != Some(want) {
        return Err(IesError::at(
            c_line,
            K::BadSymmetry {
                isym,
                mc,
                reason: "the C-plane angles of the stored planes do not span the symmetry's range",
            },
        ));
    }

    let flux = lamp_sets[0].flux_lm;
    let scale = conversion_factor * flux / 1000.0;
    let peak = planes.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
    if !(peak * scale).is_finite() {
        return Err(IesError::at(sets_line, K::ScaledCandela(peak * scale)));
    }
    let first = &lamp_sets[0];
    let labels = [
        &company,
        &report_number,
        &luminaire_name,
        &luminaire_number,
        &file_name,
        &date_user,
    ]
    .into_iter()
    .filter(|s| !s.is_empty())
    .cloned()
    .collect();
    Ok(IesFile {
        format: Format::Eulumdat,
        labels,
        keywords: Vec::new(),
        tilt: None,
        lamps: first.count,
        lumens_per_lamp: if first.count > 0.0 {
            flux / first.count
        } else {
            flux
        },
        candela_multiplier: scale,
        photometric_type: PhotometricType::C,
        units: 2.0,
        width: dimensions_mm[1] / 1000.0,
        length: dimensions_mm[0] / 1000.0,
        height: dimensions_mm[2] / 1000.0,
        ballast_factor: 1.0,
        f3: 1.0,
        input_watts: first.watts,
        vertical_angles: gamma,
        horizontal_angles: h,
        candela: planes.concat(),
        eulumdat: Some(EulumdatInfo {
            company,
            ityp,
            isym,
            mc,
            dc,
            ng,
            dg,
            report_number,
            luminaire_name,
            luminaire_number,
            file_name,
            date_user,
            dimensions_mm,
            downward_flux_fraction,
            light_output_ratio,
            conversion_factor,
            measurement_tilt_deg,
            lamp_sets,
            direct_ratios,
            c_angles,
        }),
    })
}
