//! Helpers shared by the integration tests: an LM-63 writer and the inverse direction maps of
//! DESIGN.md §6 I2 (written here from the table, independently of src/lookup.rs).
#![allow(dead_code)]

use glam::DVec3;
use luxeval::{IesFile, IesProfile as Profile};

/// An LM-63 file to write. `values` are h-major (`values[i·nV + j]` at `(h[i], v[j])`).
#[derive(Clone)]
pub struct Ies {
    /// Lines before `TILT=` (version line and labels), without line ends.
    pub head: Vec<String>,
    /// The `TILT=` line's value and, for INCLUDE, the tilt data text.
    pub tilt: String,
    pub tilt_data: String,
    pub kind: u8,
    pub h: Vec<f64>,
    pub v: Vec<f64>,
    pub values: Vec<f64>,
    pub lumens: f64,
    pub m: f64,
    pub b: f64,
    pub f3: f64,
    pub eol: &'static str,
}

impl Ies {
    pub fn new(kind: u8, h: &[f64], v: &[f64], values: &[f64]) -> Self {
        Ies {
            head: vec!["IESNA:LM-63-2002".into(), "[TEST] synthetic".into()],
            tilt: "NONE".into(),
            tilt_data: String::new(),
            kind,
            h: h.to_vec(),
            v: v.to_vec(),
            values: values.to_vec(),
            lumens: -1.0,
            m: 1.0,
            b: 1.0,
            f3: 1.0,
            eol: "\r\n",
        }
    }

    /// `f(H, V)` sampled on the grid.
    pub fn from_fn(kind: u8, h: &[f64], v: &[f64], f: impl Fn(f64, f64) -> f64) -> Self {
        let values: Vec<f64> = h
            .iter()
            .flat_map(|&a| v.iter().map(move |&b| (a, b)))
            .map(|(a, b)| f(a, b))
            .collect();
        Self::new(kind, h, v, &values)
    }

    pub fn text(&self) -> String {
        let e = self.eol;
        let list = |xs: &[f64]| {
            xs.iter()
                .map(|x| format!("{x}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let mut s = String::new();
        for l in &self.head {
            s += &format!("{l}{e}");
        }
        s += &format!("TILT={}{e}", self.tilt);
        if !self.tilt_data.is_empty() {
            s += &format!("{}{e}", self.tilt_data);
        }
        s += &format!(
            "1 {} {} {} {} {} 2 0.1 0.2 0.05{e}",
            self.lumens,
            self.m,
            self.v.len(),
            self.h.len(),
            self.kind
        );
        s += &format!("{} {} 40{e}", self.b, self.f3);
        s += &format!("{}{e}{}{e}", list(&self.v), list(&self.h));
        for row in self.values.chunks(self.v.len().max(1)) {
            s += &format!("{}{e}", list(row));
        }
        s
    }

    pub fn file(&self) -> IesFile {
        parse(&self.text())
    }

    pub fn profile(&self) -> Profile {
        Profile::new(&self.file()).expect("profile")
    }
}

/// A resolver for files that name no TILT file.
pub fn no_tilt(name: &str) -> Result<Vec<u8>, String> {
    Err(format!("no TILT file expected, asked for {name}"))
}

pub fn parse(text: &str) -> IesFile {
    luxeval::testkit::ies_parts::parse_any(text.as_bytes(), &no_tilt)
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

pub fn parse_err(text: &str) -> luxeval::IesError {
    match luxeval::testkit::ies_parts::parse_any(text.as_bytes(), &no_tilt) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

/// §6 I2 inverse, type C: `e = (sin V cos H, sin V sin H, −cos V)`.
pub fn dir_c(h: f64, v: f64) -> DVec3 {
    let (h, v) = (h.to_radians(), v.to_radians());
    DVec3::new(v.sin() * h.cos(), v.sin() * h.sin(), -v.cos())
}

/// §6 I2 inverse, type B: `e = (cos H sin V, −sin H, −cos H cos V)`.
pub fn dir_b(h: f64, v: f64) -> DVec3 {
    let (h, v) = (h.to_radians(), v.to_radians());
    DVec3::new(h.cos() * v.sin(), -h.sin(), -h.cos() * v.cos())
}

/// §6 I2 inverse, type A: `e = (cos V cos H, −cos V sin H, sin V)`.
pub fn dir_a(h: f64, v: f64) -> DVec3 {
    let (h, v) = (h.to_radians(), v.to_radians());
    DVec3::new(v.cos() * h.cos(), -v.cos() * h.sin(), v.sin())
}

pub fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300) || a == b
}

/// Asserts `a ≈ b` to `rel` relative (absolute 1e-12 near 0).
#[track_caller]
pub fn assert_close(a: f64, b: f64, rel: f64) {
    assert!(
        (a - b).abs() <= rel * b.abs() || (a - b).abs() <= 1e-12,
        "{a} vs {b} (rel {:e})",
        (a - b).abs() / b.abs()
    );
}
