//! Typed errors of the IES (LM-63) and EULUMDAT readers.
//!
//! Every error that comes from the content of a file carries the 1-based line number where the
//! offending token (or the missing one) sits, so that the CLI can report `FILE:LINE: reason` and
//! exit 2 (DESIGN.md §4). Readers never panic on input; every failure is one of these.

use std::fmt;

/// A failure to read a photometric file: where (file when known, 1-based line when known) and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct IesError {
    /// The file being read, when the caller named one (`eulumdat::read_file` sets it).
    pub file: Option<String>,
    /// 1-based line of the offending token; `None` for whole-file problems (no `TILT=` line).
    pub line: Option<usize>,
    pub kind: IesErrorKind,
}

impl IesError {
    pub fn at(line: usize, kind: IesErrorKind) -> Self {
        IesError {
            file: None,
            line: Some(line),
            kind,
        }
    }

    pub fn whole_file(kind: IesErrorKind) -> Self {
        IesError {
            file: None,
            line: None,
            kind,
        }
    }
}

impl fmt::Display for IesError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.file, self.line) {
            (Some(file), Some(line)) => write!(f, "{file}:{line}: {}", self.kind),
            (Some(file), None) => write!(f, "{file}: {}", self.kind),
            (None, Some(line)) => write!(f, "line {line}: {}", self.kind),
            (None, None) => write!(f, "{}", self.kind),
        }
    }
}

/// Why a file was refused. `what` names the field as LM-63 / EULUMDAT call it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IesErrorKind {
    #[error("could not read the file: {0}")]
    Io(String),
    #[error(
        "neither LM-63 (no line starts with `TILT=`) nor EULUMDAT (lines 2-7 are not one number each)"
    )]
    UnknownFormat,
    #[error("no `TILT=` line: an LM-63 file needs one before its numeric data")]
    NoTiltLine,
    #[error("the `TILT=` line names no file")]
    EmptyTilt,
    #[error("the TILT file `{name}` named here could not be read: {reason}")]
    TiltFileUnreadable { name: String, reason: String },
    #[error("in the TILT file `{name}` named here{}: {kind}", tilt_line(*.line))]
    InTiltFile {
        name: String,
        line: Option<usize>,
        kind: Box<IesErrorKind>,
    },
    #[error("missing value: expected {what}")]
    MissingValue { what: &'static str },
    #[error("`{token}` is not a number ({what})")]
    NotANumber { what: &'static str, token: String },
    #[error("{what} must be an integer, found {value}")]
    NotAnInteger { what: &'static str, value: f64 },
    #[error("{what} = {value} is out of range ({expected})")]
    OutOfRange {
        what: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error("{what} are not strictly increasing ({prev} then {value})")]
    NotIncreasing {
        what: &'static str,
        prev: f64,
        value: f64,
    },
    #[error("photometric type must be 1 (C), 2 (B) or 3 (A), found {0}")]
    BadPhotometricType(f64),
    #[error(
        "type C horizontal angles {first}..{last} are none of LM-63's coverages (one angle, 0-90, 0-180, 90-270, 0..h with 180 < h <= 360)"
    )]
    BadCoverage { first: f64, last: f64 },
    #[error("{what}: {count} values announced but only {remaining} numbers remain in the file")]
    CountTooLarge {
        what: &'static str,
        count: f64,
        remaining: usize,
    },
    #[error("candela value {0} is negative")]
    NegativeCandela(f64),
    #[error("unexpected `{0}` after the last candela value")]
    TrailingToken(String),
    #[error("a candela value times the multipliers is {0}: not a finite, non-negative number")]
    ScaledCandela(f64),
    #[error("EULUMDAT Isym {isym} with Mc = {mc}: {reason}")]
    BadSymmetry {
        isym: u8,
        mc: usize,
        reason: &'static str,
    },
    /// A hand-built `IesFile` that the readers would have refused (grid sizes, order, tilt).
    #[error("not a valid profile: {0}")]
    InvalidProfile(&'static str),
    #[error("EULUMDAT file has no lamp set: its cd/klm values cannot be scaled to candela")]
    NoLampSet,
}

fn tilt_line(line: Option<usize>) -> String {
    line.map(|l| format!(", line {l}")).unwrap_or_default()
}
