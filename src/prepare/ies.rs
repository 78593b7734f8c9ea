//! A photometric profile prepared once in f64 for both backends (DESIGN.md §1 "prepare"): the
//! grid with its multipliers applied, the symmetry folds of §6 I3, the exact mean intensity of
//! §6 I6, the tilt factor of §6 I5, and the numbers a report shows (peak, beam, field, flux).

use std::f64::consts::PI;

use glam::DVec3;

pub use crate::assets::ies::PhotometricType;
use crate::assets::ies::lm63::{
    END_TOLERANCE_DEG, IesFile, Tilt, TypeCCoverage, coverage_and_ends,
};
use crate::assets::ies::{IesError, IesErrorKind as K};

/// How a horizontal angle folds onto the stored grid (§6 I3). Codes are the atlas's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HFold {
    /// A/B, first angle ≠ 0: used as given.
    AsGiven = 0,
    /// A/B, first angle 0: `H' = |H|` (symmetric about the `H = 0` plane).
    Mirror = 1,
    /// One horizontal angle: type C rotationally symmetric; A/B independent of `H` over
    /// `[−90, 90]` (a pin, see `Profile::new`).
    Constant = 2,
    /// C 0..90.
    Quadrant = 3,
    /// C 0..180.
    Half = 4,
    /// C 90..270.
    HalfC90 = 5,
    /// C 0..h_L, 180 < h_L ≤ 360; `(h_L, 360)` interpolates to the 0 column.
    Full = 6,
}

/// How a vertical angle folds (§6 I3): only A/B mirror, when their first vertical angle is 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VFold {
    AsGiven = 0,
    Mirror = 1,
}

impl HFold {
    pub fn code(self) -> u32 {
        self as u32
    }
}

impl VFold {
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// The longest angle grid (on either axis) a profile may have: the GPU's lookup is a binary
/// search written out as 16 halving steps (no loop: lavapipe stops an invocation's loops after
/// 65,535 iterations in total), which covers up to 2^16 + 1 angles. Both paths refuse longer
/// grids, so that they accept the same lights.
pub const MAX_ANGLES: usize = (1 << 16) + 1;

/// Why a profile cannot be evaluated by both paths alike: a grid longer than [`MAX_ANGLES`],
/// or a candela value (multipliers applied) that float32 cannot hold (the GPU keeps the
/// profile in float32; the CPU would evaluate it, and then disagree). `ies:normalize` does not
/// help: it divides at evaluation, after the value is stored.
pub fn check_evaluable(p: &Profile) -> Result<(), String> {
    for (axis, n) in [("horizontal", p.h.len()), ("vertical", p.v.len())] {
        if n > MAX_ANGLES {
            return Err(format!(
                "the profile has {n} {axis} angles, more than the {MAX_ANGLES} a lookup covers"
            ));
        }
    }
    if let Some(c) = p.candela.iter().find(|c| !((**c as f32).is_finite())) {
        return Err(format!(
            "the profile's candela value {c:e} (multipliers applied) does not fit float32 (largest {:e}), which the GPU evaluates in",
            f32::MAX
        ));
    }
    Ok(())
}

/// A profile ready for lookup and normalisation.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    pub kind: PhotometricType,
    /// Horizontal angles in degrees as in the file, with ends recognised by §6 I3 (within
    /// 1e-4°) set to their exact values (0, 90, 180, 270, 360).
    pub h: Vec<f64>,
    /// Vertical angles in degrees as in the file (A/B: a first angle within 1e-4° of 0 set to 0).
    pub v: Vec<f64>,
    /// Candela with the multipliers of §6 I1 applied, `candela[i·v.len() + j]` at `(h[i], v[j])`.
    pub candela: Vec<f64>,
    pub h_fold: HFold,
    pub v_fold: VFold,
    pub tilt: Option<Tilt>,
}

/// The largest grid value and where it is (file angles, degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peak {
    pub candela: f64,
    pub h: f64,
    pub v: f64,
}

/// Beam (50 %) and field (10 %) angles in one plane pair, degrees; `None` where the intensity
/// never falls that low on one side of the plane's maximum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    pub max_candela: f64,
    pub beam: Option<f64>,
    pub field: Option<f64>,
}

/// Rated (header) lumens, integrated lumens and their ratio (`None` for absolute photometry).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxCheck {
    pub rated_lm: Option<f64>,
    pub integrated_lm: f64,
    pub ratio: Option<f64>,
}

/// The plane pairs a report measures beam and field in (directions in the light frame: nadir
/// −Z, C0 +X, C90 +Y, §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    C0C180,
    C90C270,
}

impl Profile {
    /// The profile of a validated file. Files built by hand are re-validated (grid sizes,
    /// coverage) so that lookups can index without checks.
    pub fn new(file: &IesFile) -> Result<Profile, IesError> {
        let (n_h, n_v) = (file.horizontal_angles.len(), file.vertical_angles.len());
        let sizes_ok = n_h >= 1
            && n_v >= 2
            && n_h.checked_mul(n_v) == Some(file.candela.len())
            && [&file.horizontal_angles, &file.vertical_angles]
                .iter()
                .all(|g| g.windows(2).all(|w| w[0] < w[1]) && g.iter().all(|x| x.is_finite()));
        if !sizes_ok {
            return Err(IesError::whole_file(K::InvalidProfile(
                "the grid needs ≥ 1 horizontal and ≥ 2 vertical strictly increasing finite angles and one value per node",
            )));
        }
        if let Some(t) = &file.tilt {
            let ok = !t.angles.is_empty()
                && t.angles.len() == t.factors.len()
                && t.angles.windows(2).all(|w| w[0] < w[1])
                && t.factors.iter().all(|f| f.is_finite() && *f >= 0.0);
            if !ok {
                return Err(IesError::whole_file(K::InvalidProfile(
                    "a tilt table needs increasing angles and one non-negative multiplier each",
                )));
            }
        }
        let scale = file.candela_scale();
        let candela: Vec<f64> = file.candela.iter().map(|&c| c * scale).collect();
        if let Some(&bad) = candela.iter().find(|c| !c.is_finite() || **c < 0.0) {
            return Err(IesError::whole_file(K::ScaledCandela(bad)));
        }
        let mut h = file.horizontal_angles.clone();
        let mut v = file.vertical_angles.clone();
        let near = |a: f64, b: f64| (a - b).abs() <= END_TOLERANCE_DEG;
        let (h_fold, v_fold) = match file.photometric_type {
            PhotometricType::C => {
                let (coverage, ends) =
                    coverage_and_ends(&h).ok_or(IesError::whole_file(K::BadCoverage {
                        first: h[0],
                        last: h[n_h - 1],
                    }))?;
                // Snap the recognised ends so that folded angles land inside the grid exactly.
                if let Some((first, last)) = ends {
                    h[0] = first;
                    h[n_h - 1] = last;
                }
                let fold = match coverage {
                    TypeCCoverage::Single => HFold::Constant,
                    TypeCCoverage::Quadrant => HFold::Quadrant,
                    TypeCCoverage::Half => HFold::Half,
                    TypeCCoverage::HalfC90 => HFold::HalfC90,
                    TypeCCoverage::Full => HFold::Full,
                };
                if v[0] < 0.0 || v[n_v - 1] > 180.0 {
                    return Err(IesError::whole_file(K::OutOfRange {
                        what: "vertical angles",
                        value: if v[0] < 0.0 { v[0] } else { v[n_v - 1] },
                        expected: "type C vertical angles lie in [0, 180]",
                    }));
                }
                (fold, VFold::AsGiven)
            }
            PhotometricType::A | PhotometricType::B => {
                if [&h, &v]
                    .iter()
                    .any(|g| g[0] < -90.0 || g[g.len() - 1] > 90.0)
                {
                    return Err(IesError::whole_file(K::OutOfRange {
                        what: "type A/B angles",
                        value: h[0].min(v[0]),
                        expected: "[-90, 90]",
                    }));
                }
                // §6 I3: a first angle of 0 mirrors that axis. One horizontal angle is not
                // covered by §6 (LM-63 defines no meaning for it); pinned here like type C's
                // single angle: the one plane holds for every H in [−90, 90].
                // A first angle within 1e-4° of 0 counts as 0 when the next one is positive.
                let h_fold = if n_h == 1 {
                    HFold::Constant
                } else if near(h[0], 0.0) && h[1] > 0.0 {
                    h[0] = 0.0;
                    HFold::Mirror
                } else {
                    HFold::AsGiven
                };
                let v_fold = if near(v[0], 0.0) && v[1] > 0.0 {
                    v[0] = 0.0;
                    VFold::Mirror
                } else {
                    VFold::AsGiven
                };
                (h_fold, v_fold)
            }
        };
        Ok(Profile {
            kind: file.photometric_type,
            h,
            v,
            candela,
            h_fold,
            v_fold,
            tilt: file.tilt.clone(),
        })
    }

    /// Candela at grid node `(h[i], v[j])`.
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.candela[i * self.v.len() + j]
    }

    /// `(1/4π) ∫_{S²} Î dω` of the bilinear interpolant of §6 I3 (multipliers applied, tilt not:
    /// a tilt factor T scales this mean by T and cancels under normalisation), integrated
    /// exactly cell by cell (§6 I6). In each cell `[x₀, x₁] × [y₀, y₁]` (x the latitude-like
    /// coordinate with weight w, y the longitude-like one) the interpolant is linear in y, so
    /// `∫∫ Î w(x) dx dy = Δy · (A·(W₀ − W₁) + B·W₁)`, A and B the means of the corners at x₀ and
    /// x₁, `W₀ = ∫ w`, `W₁ = ∫ w·(x − x₀)/Δx`. Type C: x = V, w = sin; B: x = H, w = cos;
    /// A: x = V, w = cos. Folded files count their stored grid once per image.
    pub fn mean_intensity(&self) -> f64 {
        let h_spans = self.h_spans();
        let v_spans: Vec<Span> = (1..self.v.len())
            .map(|j| Span {
                i0: j - 1,
                i1: j,
                a0: self.v[j - 1],
                a1: self.v[j],
            })
            .collect();
        // (x spans, y spans, is x the horizontal axis, weight is sin)
        let (xs, ys, x_is_h, sin_weight) = match self.kind {
            PhotometricType::C => (&v_spans, &h_spans, false, true),
            PhotometricType::A => (&v_spans, &h_spans, false, false),
            PhotometricType::B => (&h_spans, &v_spans, true, false),
        };
        // Integrate I/peak (≤ 1) and scale back, so that no sum can overflow.
        let peak = self.peak().candela;
        if peak.is_nan() || peak <= 0.0 {
            return 0.0;
        }
        let value = |ix: usize, iy: usize| {
            (if x_is_h {
                self.at(ix, iy)
            } else {
                self.at(iy, ix)
            }) / peak
        };
        let mut total = 0.0;
        for x in xs {
            let (x0, x1) = (x.a0.to_radians(), x.a1.to_radians());
            let dx = x1 - x0;
            if dx.is_nan() || dx <= 0.0 {
                continue; // a cell narrower than f64 resolves in radians has no measure
            }
            let (w0, w1) = if sin_weight {
                (x0.cos() - x1.cos(), (x1.sin() - x0.sin()) / dx - x1.cos())
            } else {
                (x1.sin() - x0.sin(), x1.sin() + (x1.cos() - x0.cos()) / dx)
            };
            for y in ys {
                let dy = (y.a1 - y.a0).to_radians();
                let a = 0.5 * (value(x.i0, y.i0) + value(x.i0, y.i1));
                let b = 0.5 * (value(x.i1, y.i0) + value(x.i1, y.i1));
                total += dy * (a * (w0 - w1) + b * w1);
            }
        }
        peak * (self.multiplicity() * total / (4.0 * PI))
    }

    /// Luminous flux in lm of the candela values: `4π · mean` (§6 I6 with §2: `∫ I dω`).
    pub fn flux_lm(&self) -> f64 {
        4.0 * PI * self.mean_intensity()
    }

    /// The `ies:normalize` divisor as a factor: `1/mean`, and 0 when the mean is 0 (§6 I6).
    pub fn inverse_mean(&self) -> f64 {
        let mean = self.mean_intensity();
        if mean > 0.0 { 1.0 / mean } else { 0.0 }
    }

    /// Header lumens against the integrated flux (a report's sanity check: for relative
    /// photometry the ratio is the luminaire's light output ratio, normally ≤ 1).
    pub fn flux_check(&self, file: &IesFile) -> FluxCheck {
        let integrated_lm = self.flux_lm();
        let rated_lm = file.rated_lumens();
        let ratio = rated_lm.filter(|&r| r > 0.0).map(|r| integrated_lm / r);
        FluxCheck {
            rated_lm,
            integrated_lm,
            ratio,
        }
    }

    /// §6 I5: the tilt table interpolated piecewise linearly at `tau_deg`, clamped to the first
    /// / last multiplier outside its angles; 1 without tilt data.
    pub fn tilt_factor(&self, tau_deg: f64) -> f64 {
        let Some(t) = &self.tilt else { return 1.0 };
        let (a, f) = (&t.angles, &t.factors);
        let (Some(&first), Some(&last)) = (a.first(), a.last()) else {
            return 1.0;
        };
        if tau_deg.is_nan() || tau_deg <= first {
            return f[0];
        }
        if tau_deg >= last {
            return f[f.len() - 1];
        }
        let k = a.partition_point(|&x| x <= tau_deg); // a[k−1] ≤ τ < a[k], 1 ≤ k < n
        let s = (tau_deg - a[k - 1]) / (a[k] - a[k - 1]);
        f[k - 1] + s * (f[k] - f[k - 1])
    }

    /// The largest stored value and its `(H, V)` (the first in file order on ties). The
    /// bilinear interpolant's maximum is always at a node.
    pub fn peak(&self) -> Peak {
        let n_v = self.v.len();
        let mut best = Peak {
            candela: self.candela[0],
            h: self.h[0],
            v: self.v[0],
        };
        for (k, &c) in self.candela.iter().enumerate() {
            if c > best.candela {
                best = Peak {
                    candela: c,
                    h: self.h[k / n_v],
                    v: self.v[k % n_v],
                };
            }
        }
        best
    }

    /// Beam and field angle in a plane pair. Definition: the plane through the light's axis
    /// containing C0 and C180 (or C90 and C270), parametrised by the signed angle γ from nadir
    /// (γ > 0 toward C0 / C90, γ < 0 toward C180 / C270), `I(γ) = intensity(e(γ))`; γ* the
    /// first direction of the plane's maximum `I*`; the beam (field) angle is `γ₊ − γ₋`, where
    /// γ₊ > γ* and γ₋ < γ* are the nearest angles at which I falls to 50 % (10 %) of `I*`
    /// (50 % of the plane's own maximum, as NEMA/IES beam spread). The curve is sampled every
    /// 0.01° and each crossing refined by bisection; the interpolant is piecewise linear along
    /// these planes, so the crossing is exact unless a feature is narrower than 0.01°.
    /// `intensity` is the caller's lookup (`|e| lookup::ies_factor(&p, e, 0.0)`): the CPU
    /// lookup lives in the reference backend, which prepared data does not depend on.
    pub fn spread(&self, plane: Plane, intensity: &dyn Fn(DVec3) -> f64) -> Spread {
        let dir = |g: f64| {
            let (s, c) = g.to_radians().sin_cos();
            match plane {
                Plane::C0C180 => DVec3::new(s, 0.0, -c),
                Plane::C90C270 => DVec3::new(0.0, s, -c),
            }
        };
        const STEPS: usize = 36_000;
        let gamma = |k: usize| -180.0 + 360.0 * k as f64 / STEPS as f64;
        let samples: Vec<f64> = (0..=STEPS).map(|k| intensity(dir(gamma(k)))).collect();
        let (k_max, max) =
            samples.iter().enumerate().fold(
                (0, 0.0f64),
                |best, (k, &c)| if c > best.1 { (k, c) } else { best },
            );
        let crossing = |frac: f64, step: isize| -> Option<f64> {
            let level = frac * max;
            let mut k = k_max as isize;
            while k + step >= 0 && k + step <= STEPS as isize {
                let next = k + step;
                if samples[next as usize] < level {
                    // Bisect between the last sample at or above `level` and this one.
                    let (mut inside, mut outside) = (gamma(k as usize), gamma(next as usize));
                    for _ in 0..60 {
                        let mid = 0.5 * (inside + outside);
                        if intensity(dir(mid)) >= level {
                            inside = mid
                        } else {
                            outside = mid
                        }
                    }
                    return Some(0.5 * (inside + outside));
                }
                k = next;
            }
            None
        };
        let width = |frac: f64| Some(crossing(frac, 1)? - crossing(frac, -1)?);
        if max <= 0.0 {
            return Spread {
                max_candela: 0.0,
                beam: None,
                field: None,
            };
        }
        Spread {
            max_candela: max,
            beam: width(0.5),
            field: width(0.1),
        }
    }

    /// The horizontal spans of the stored grid, including the wrap cell of a partial full
    /// circle; a constant profile is one span over its whole horizontal domain.
    fn h_spans(&self) -> Vec<Span> {
        let n = self.h.len();
        if self.h_fold == HFold::Constant {
            let (a0, a1) = if self.kind == PhotometricType::C {
                (0.0, 360.0)
            } else {
                (-90.0, 90.0)
            };
            return vec![Span {
                i0: 0,
                i1: 0,
                a0,
                a1,
            }];
        }
        let mut spans: Vec<Span> = (1..n)
            .map(|i| Span {
                i0: i - 1,
                i1: i,
                a0: self.h[i - 1],
                a1: self.h[i],
            })
            .collect();
        if self.h_fold == HFold::Full && self.h[n - 1] < 360.0 {
            spans.push(Span {
                i0: n - 1,
                i1: 0,
                a0: self.h[n - 1],
                a1: 360.0,
            });
        }
        spans
    }

    /// How many images of the stored grid the folds make (§6 I6).
    fn multiplicity(&self) -> f64 {
        match self.kind {
            PhotometricType::C => match self.h_fold {
                HFold::Quadrant => 4.0,
                HFold::Half | HFold::HalfC90 => 2.0,
                _ => 1.0,
            },
            _ => {
                let h = if self.h_fold == HFold::Mirror {
                    2.0
                } else {
                    1.0
                };
                let v = if self.v_fold == VFold::Mirror {
                    2.0
                } else {
                    1.0
                };
                h * v
            }
        }
    }
}

/// An interval of one grid axis between nodes `i0` and `i1`, from `a0` to `a1` degrees.
struct Span {
    i0: usize,
    i1: usize,
    a0: f64,
    a1: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(kind: u8, h: &str, v: &str, values: &str, n: (usize, usize)) -> IesFile {
        let text = format!(
            "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 {} {} {kind} 2 0 0 0\n1 1 0\n{v}\n{h}\n{values}\n",
            n.1, n.0
        );
        crate::assets::ies::parse_any(text.as_bytes(), &|_| Err(String::new())).unwrap()
    }

    /// Ends within 1e-4° of 0 / 90 are snapped, so that the fold lands inside the grid.
    #[test]
    fn recognised_ends_are_snapped() {
        let f = file(1, "0.00005 45 89.99995", "0 90", "1 1 2 2 3 3", (3, 2));
        let p = Profile::new(&f).unwrap();
        assert_eq!(
            (p.h.clone(), p.h_fold),
            (vec![0.0, 45.0, 90.0], HFold::Quadrant)
        );
        let f = file(2, "0.00005 45", "-0.00002 90", "1 1 2 2", (2, 2));
        let p = Profile::new(&f).unwrap();
        assert_eq!(
            (p.h[0], p.h_fold, p.v[0], p.v_fold),
            (0.0, HFold::Mirror, 0.0, VFold::Mirror)
        );
    }

    /// Hand-built files that the readers would refuse are refused, never indexed out of range.
    #[test]
    fn invalid_hand_built_files_are_refused() {
        let good = file(1, "0 90", "0 90", "1 2 3 4", (2, 2));
        let mut bad = good.clone();
        bad.candela.pop();
        assert!(matches!(
            Profile::new(&bad).unwrap_err().kind,
            K::InvalidProfile(_)
        ));
        let mut bad = good.clone();
        bad.vertical_angles = vec![90.0, 0.0];
        assert!(matches!(
            Profile::new(&bad).unwrap_err().kind,
            K::InvalidProfile(_)
        ));
        let mut bad = good.clone();
        bad.tilt = Some(Tilt {
            source: crate::assets::ies::lm63::TiltSource::Include,
            geometry: 1,
            angles: vec![0.0, 10.0],
            factors: vec![1.0],
        });
        assert!(matches!(
            Profile::new(&bad).unwrap_err().kind,
            K::InvalidProfile(_)
        ));
        let mut bad = good.clone();
        bad.horizontal_angles = vec![0.0, 45.0];
        assert!(matches!(
            Profile::new(&bad).unwrap_err().kind,
            K::BadCoverage { .. }
        ));
        let mut bad = good;
        bad.candela_multiplier = -1.0;
        assert!(matches!(
            Profile::new(&bad).unwrap_err().kind,
            K::ScaledCandela(_)
        ));
    }

    #[test]
    fn tilt_factor_of_nan_is_the_first_multiplier() {
        let mut f = file(1, "0", "0 90", "1 1", (1, 2));
        f.tilt = Some(Tilt {
            source: crate::assets::ies::lm63::TiltSource::Include,
            geometry: 1,
            angles: vec![0.0, 90.0],
            factors: vec![1.0, 0.5],
        });
        let p = Profile::new(&f).unwrap();
        assert_eq!((p.tilt_factor(f64::NAN), p.tilt_factor(45.0)), (1.0, 0.75));
    }
}
