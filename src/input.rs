//! Query inputs, checked and converted in one place (DESIGN.md §3: points are finite, directions
//! and normals finite and non-zero): the library's queries, the command line's `.npy` streams and
//! the Python package all call these, so that a bad row is refused for the same reason and named
//! the same way everywhere: `row I = VALUES is not finite`.
//!
//! Directions are not normalised here: the queries normalise every direction in f64 themselves
//! (on both paths). float64 rows given as such (a float64 `.npy`) are normalised in f64 before
//! they are rounded to float32, so that a direction too long or too short for float32 keeps its
//! direction.

use std::fmt;

use rayon::prelude::*;

/// What the rows of an input are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// Points: every component finite.
    Points,
    /// Directions or receiver normals: finite and not the zero vector.
    Directions,
}

/// What is wrong with a refused row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowProblem {
    /// A NaN or infinite component.
    NotFinite,
    /// A direction of length 0.
    Zero,
    /// A finite value that float32 cannot hold.
    OutsideFloat32,
}

/// A refused input row: its index in the whole input (not within a chunk), its values as the
/// caller's language writes them, and the problem. `Display`: `row 3 = [0.0, 0.0, 0.0] is the
/// zero vector, which has no direction`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct BadRow {
    pub row: u64,
    pub values: String,
    pub problem: RowProblem,
}

impl fmt::Display for BadRow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let why = match self.problem {
            RowProblem::NotFinite => "is not finite",
            RowProblem::Zero => "is the zero vector, which has no direction",
            RowProblem::OutsideFloat32 => "is outside float32's range",
        };
        write!(f, "row {} = {} {why}", self.row, self.values)
    }
}

impl RowKind {
    /// The problem of one float32 row, if any.
    pub fn problem_f32(self, r: &[f32; 3]) -> Option<RowProblem> {
        if r.iter().any(|c| !c.is_finite()) {
            Some(RowProblem::NotFinite)
        } else if self == RowKind::Directions && r.iter().all(|c| *c == 0.0) {
            Some(RowProblem::Zero)
        } else {
            None
        }
    }

    /// The first bad row of float32 `rows`, whose first row is row `start` of the input
    /// (checked in parallel; the first bad row is reported whatever the thread count).
    pub fn check_f32(self, start: u64, rows: &[[f32; 3]]) -> Result<(), BadRow> {
        match rows
            .par_iter()
            .enumerate()
            .find_map_first(|(i, r)| Some((i, self.problem_f32(r)?)))
        {
            None => Ok(()),
            Some((i, problem)) => Err(BadRow {
                row: start + i as u64,
                values: format!("{:?}", rows[i]),
                problem,
            }),
        }
    }

    /// float64 `rows` (the first is row `start`) as float32, each row checked completely before
    /// the next: points rounded to nearest (a finite value beyond float32 is refused),
    /// directions normalised in f64 first.
    pub fn f32_from_f64(self, start: u64, rows: &[[f64; 3]]) -> Result<Vec<[f32; 3]>, BadRow> {
        rows.iter()
            .enumerate()
            .map(|(i, r)| {
                let bad = |problem| BadRow {
                    row: start + i as u64,
                    values: format!("{r:?}"),
                    problem,
                };
                if r.iter().any(|v| !v.is_finite()) {
                    return Err(bad(RowProblem::NotFinite));
                }
                match self {
                    RowKind::Points => {
                        if r.iter().any(|v| v.abs() > f32::MAX as f64) {
                            return Err(bad(RowProblem::OutsideFloat32));
                        }
                        Ok(r.map(|v| v as f32))
                    }
                    RowKind::Directions => unit_f32(r).ok_or_else(|| bad(RowProblem::Zero)),
                }
            })
            .collect()
    }
}

/// The float32 unit vector nearest the direction of finite `r`; `None` for the zero vector.
fn unit_f32(r: &[f64; 3]) -> Option<[f32; 3]> {
    // Scale by the largest component first: the squares of 1e300 or 1e-320 do not fit f64.
    let m = r.iter().fold(0f64, |m, v| m.max(v.abs()));
    if m == 0.0 {
        return None;
    }
    let s = r.map(|v| v / m);
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    Some(s.map(|v| (v / len) as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_rows_are_named_with_their_row_in_the_whole_input() {
        let rows = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0]];
        let e = RowKind::Directions.check_f32(10, &rows).unwrap_err();
        assert_eq!(
            e.to_string(),
            "row 11 = [0.0, 0.0, 0.0] is the zero vector, which has no direction"
        );
        // A zero point is a point.
        let e = RowKind::Points.check_f32(0, &rows).unwrap_err();
        assert_eq!((e.row, e.problem), (2, RowProblem::NotFinite));
        let e = RowKind::Points
            .f32_from_f64(5, &[[0.0; 3], [1e300, 0.0, 0.0]])
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "row 6 = [1e300, 0.0, 0.0] is outside float32's range"
        );
    }

    #[test]
    fn float64_directions_keep_their_direction() {
        let got = RowKind::Directions
            .f32_from_f64(0, &[[1e300, 1e300, 0.0], [0.0, 3e-320, 0.0]])
            .unwrap();
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert_eq!(got, vec![[h, h, 0.0], [0.0, 1.0, 0.0]]);
    }
}
