//! IES profile lookup on the CPU (f64). Twin of `shaders/shared/ies.wgsl`: the same functions,
//! with the same names, in the same order, one per step of DESIGN.md §6:
//! 1. light-space emission direction `e` → photometric angles `(H, V)` of type C, B or A (I2);
//! 2. `ies:angleScale` on the polar angle θ (I4);
//! 3. the symmetry folds `H'`, `V'` (I3);
//! 4. the interval of a non-uniform grid holding an angle (bounded binary search);
//! 5. bilinear interpolation on the file's own grid (I3); outside the grid → 0.
//!
//! Frame (§2, §6 I2): nadir = light −Z (θ = 0, the primary axis), C0 = +X, C90 = +Y, up = +Z.
//! All angles are degrees, as the grids are. Where an azimuth is undefined (both atan2 arguments
//! zero, at the poles of a type's frame) it is 0, whatever the signs of the zeros: that is what
//! the GPU's atan2_accurate returns, where f64::atan2(0, −0) would give 180°.

use glam::DVec3;

use crate::prepare::Prepared;
use crate::prepare::ies::PhotometricType;
use crate::prepare::ies::{HFold, Profile, VFold};

/// Type C `(H, V)`: `V = atan2(√(ex²+ey²), −ez)`, `H = atan2(ey, ex) mod 360` (§6 I2). V is also
/// the polar angle θ from nadir and H the azimuth φ that angleScale works with (§6 I4).
pub fn type_c_angles(e: DVec3) -> (f64, f64) {
    let v = e.x.hypot(e.y).atan2(-e.z).to_degrees();
    let mut h = if e.x == 0.0 && e.y == 0.0 {
        0.0
    } else {
        e.y.atan2(e.x).to_degrees()
    };
    if h < 0.0 {
        h += 360.0;
    }
    (h, v)
}

/// Type B `(H, V)`: `V = atan2(ex, −ez) ∈ (−180, 180]`, `H = atan2(−ey, √(ex²+ez²)) ∈ [−90, 90]`
/// (§6 I2; planes `V = const` contain the light's Y axis, H is the elevation toward −Y;
/// Radiance's source.cal `srcB_vert`, `srcB_horiz` with D = −e).
pub fn type_b_angles(e: DVec3) -> (f64, f64) {
    let v = if e.x == 0.0 && e.z == 0.0 {
        0.0
    } else {
        e.x.atan2(-e.z).to_degrees()
    };
    let h = (-e.y).atan2(e.x.hypot(e.z)).to_degrees();
    (h, v)
}

/// Type A `(H, V)`: `V = atan2(ez, √(ex²+ey²)) ∈ [−90, 90]`, `H = atan2(−ey, ex) ∈ (−180, 180]`
/// (§6 I2: type C with `V_A = θ − 90`, `H_A = −φ`; `(0, 0)` points along +X).
pub fn type_a_angles(e: DVec3) -> (f64, f64) {
    let v = e.z.atan2(e.x.hypot(e.y)).to_degrees();
    let h = if e.x == 0.0 && e.y == 0.0 {
        0.0
    } else {
        (-e.y).atan2(e.x).to_degrees()
    };
    (h, v)
}

/// §6 I4 / §2: `s > 0: θ/s`; `s = 0: θ`; `s < 0: (θ − 180)/(−s) + 180` (degrees; the map is
/// linear, so degrees and radians agree). The caller treats a result outside [0, 180] as 0.
pub fn scale_polar_angle(theta: f64, s: f64) -> f64 {
    if s > 0.0 {
        theta / s
    } else if s < 0.0 {
        (theta - 180.0) / -s + 180.0
    } else {
        theta
    }
}

/// `e' = (sin θ' cos φ, sin θ' sin φ, −cos θ')` (§6 I4) with `(cos φ, sin φ)` taken from `e`
/// itself (no round trip through φ); on the axis, where φ is undefined, φ = 0 as atan2(0, 0).
pub fn scaled_direction(e: DVec3, theta: f64) -> DVec3 {
    let rho = e.x.hypot(e.y);
    let (c, s) = if rho > 0.0 {
        (e.x / rho, e.y / rho)
    } else {
        (1.0, 0.0)
    };
    let (st, ct) = theta.to_radians().sin_cos();
    DVec3::new(st * c, st * s, -ct)
}

/// `(H, V)` of the profile's type for emission direction `e` after angleScale `s`, or `None`
/// where §6 I4 gives 0 (θ' outside [0, 180]). Type C takes `V = θ'`, `H = φ`; B and A rebuild
/// `e'` from θ' and φ and read the I2 table on it (untouched `e` when θ' = θ, e.g. s = 0 or 1).
pub fn photometric_angles(kind: PhotometricType, e: DVec3, s: f64) -> Option<(f64, f64)> {
    if kind == PhotometricType::C {
        let (h, v) = type_c_angles(e);
        let t = scale_polar_angle(v, s);
        return (0.0..=180.0).contains(&t).then_some((h, t));
    }
    let mut d = e;
    if s != 0.0 {
        let (_, theta) = type_c_angles(e);
        let t = scale_polar_angle(theta, s);
        if !(0.0..=180.0).contains(&t) {
            return None;
        }
        if t != theta {
            d = scaled_direction(e, t);
        }
    }
    Some(if kind == PhotometricType::B {
        type_b_angles(d)
    } else {
        type_a_angles(d)
    })
}

/// Type C horizontal fold `H'` for `H ∈ [0, 360]` (§6 I3):
/// 0..90: `H > 180 → 360 − H`, then `H > 90 → 180 − H`; 0..180: `H > 180 → 360 − H`;
/// 90..270: `H < 90 → 180 − H`, `H > 270 → 540 − H`; otherwise `H` as is.
pub fn fold_h_type_c(h: f64, fold: HFold) -> f64 {
    let mut x = h;
    match fold {
        HFold::Quadrant | HFold::Half => {
            if x > 180.0 {
                x = 360.0 - x;
            }
            if fold == HFold::Quadrant && x > 90.0 {
                x = 180.0 - x;
            }
        }
        HFold::HalfC90 => {
            if x < 90.0 {
                x = 180.0 - x;
            }
            if x > 270.0 {
                x = 540.0 - x;
            }
        }
        _ => {}
    }
    x
}

/// Types A and B (§6 I3): an axis whose first angle is 0 is mirrored, `x' = |x|`.
pub fn fold_mirror(x: f64, mirrored: bool) -> f64 {
    if mirrored { x.abs() } else { x }
}

/// `(i, t)` with `grid[i] ≤ x ≤ grid[i+1]`, `t = (x − grid[i])/(grid[i+1] − grid[i])`; ends
/// inclusive, `None` outside (or NaN). A binary search (⌈log₂ n⌉ steps; the WGSL twin bounds
/// its loop by 32 steps because lavapipe caps an invocation's total loop iterations).
pub fn find_interval(grid: &[f64], x: f64) -> Option<(usize, f64)> {
    let n = grid.len();
    if n == 0 || !(x >= grid[0] && x <= grid[n - 1]) {
        return None;
    }
    if n == 1 {
        return Some((0, 0.0));
    }
    let (mut lo, mut hi) = (0, n - 1);
    // Invariant: grid[lo] ≤ x ≤ grid[hi].
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if grid[mid] <= x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some((lo, (x - grid[lo]) / (grid[lo + 1] - grid[lo])))
}

/// §6 I3: `I = (1−t)((1−u)I₀₀ + u I₀₁) + t((1−u)I₁₀ + u I₁₁)`, first index horizontal.
pub fn bilinear(i00: f64, i01: f64, i10: f64, i11: f64, t: f64, u: f64) -> f64 {
    (1.0 - t) * ((1.0 - u) * i00 + u * i01) + t * ((1.0 - u) * i10 + u * i11)
}

/// The profile's candela toward light-space unit direction `e_local`, after angleScale, before
/// `ies:normalize` and the tilt factor (the caller multiplies both, §6 I5–I7); 0 outside the
/// (folded) grid.
pub fn ies_factor(profile: &Profile, e_local: DVec3, angle_scale: f64) -> f64 {
    let p = profile;
    let Some((h, v)) = photometric_angles(p.kind, e_local, angle_scale) else {
        return 0.0;
    };
    let (hq, vq) = if p.kind == PhotometricType::C {
        (fold_h_type_c(h, p.h_fold), v)
    } else {
        (
            fold_mirror(h, p.h_fold == HFold::Mirror),
            fold_mirror(v, p.v_fold == VFold::Mirror),
        )
    };
    let Some((j, u)) = find_interval(&p.v, vq) else {
        return 0.0;
    };
    let n_h = p.h.len();
    let h_last = p.h[n_h - 1];
    let (i0, i1, t) = if p.h_fold == HFold::Constant {
        // Type C: rotational. A/B: the one plane over H ∈ [−90, 90] (type A's H reaches ±180).
        if p.kind != PhotometricType::C && hq.abs() > 90.0 {
            return 0.0;
        }
        (0, 0, 0.0)
    } else if p.h_fold == HFold::Full && hq > h_last {
        // The wrap cell (h_L, 360): from the h_L column back to the 0 column (§6 I3).
        (n_h - 1, 0, (hq - h_last) / (360.0 - h_last))
    } else {
        let Some((i, t)) = find_interval(&p.h, hq) else {
            return 0.0;
        };
        (i, (i + 1).min(n_h - 1), t)
    };
    let j1 = (j + 1).min(p.v.len() - 1);
    bilinear(p.at(i0, j), p.at(i0, j1), p.at(i1, j), p.at(i1, j1), t, u)
}

/// The IES factor of a prepared light along the unit world emission direction `e`: the profile
/// at `e_local = normalize(M⁻¹ e)` (DESIGN.md §6, the light's own frame: `worldToLight` applied
/// to a direction), times the light's normalisation or tilt scale; 1 without a profile.
pub fn ies_of(p: &Prepared, e: DVec3) -> f64 {
    match &p.ies {
        Some(i) => i.scale * ies_factor(&i.profile, (p.to_local * e).normalize(), i.angle_scale),
        None => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_search_on_a_non_uniform_grid() {
        let g = [0.0, 1.0, 5.0, 5.5, 90.0];
        assert_eq!(find_interval(&g, 0.0), Some((0, 0.0)));
        assert_eq!(find_interval(&g, 3.0), Some((1, 0.5)));
        assert_eq!(find_interval(&g, 5.25), Some((2, 0.5)));
        assert_eq!(find_interval(&g, 90.0), Some((3, 1.0)));
        assert_eq!(find_interval(&g, 90.0001), None);
        assert_eq!(find_interval(&g, -1e-9), None);
        assert_eq!(find_interval(&g, f64::NAN), None);
        assert_eq!(find_interval(&[7.0], 7.0), Some((0, 0.0)));
    }

    #[test]
    fn folds_of_section_6_i3() {
        assert_eq!(fold_h_type_c(200.0, HFold::Quadrant), 20.0);
        assert_eq!(fold_h_type_c(120.0, HFold::Quadrant), 60.0);
        assert_eq!(fold_h_type_c(300.0, HFold::Quadrant), 60.0);
        assert_eq!(fold_h_type_c(300.0, HFold::Half), 60.0);
        assert_eq!(fold_h_type_c(120.0, HFold::Half), 120.0);
        assert_eq!(fold_h_type_c(30.0, HFold::HalfC90), 150.0);
        assert_eq!(fold_h_type_c(300.0, HFold::HalfC90), 240.0);
        assert_eq!(fold_h_type_c(360.0, HFold::HalfC90), 180.0);
        assert_eq!(fold_h_type_c(300.0, HFold::Full), 300.0);
        assert_eq!(fold_mirror(-30.0, true), 30.0);
        assert_eq!(fold_mirror(-30.0, false), -30.0);
    }

    /// Every place where a direction's bilinear cell changes (the grid intervals `(H', V')` of
    /// the lookup falls in, or the range it leaves) lies on a surface that
    /// `prepare::ies_kinks` lists, for types C and A under angleScale (their families stay
    /// cones and planes, so the device splits at them) and every type without it or at ±1
    /// (θ' = θ): random arcs
    /// walked in 4,000 steps, a cell change between two steps needing a listed surface that
    /// changes sign between them. Fails when type A under angleScale lists nothing (the old
    /// rule) or its cones are mirrored (`+cos θ`).
    #[test]
    fn listed_kinks_hold_every_cell_change_of_the_lookup() {
        use crate::prepare::ies_kinks::ies_kinks;
        use crate::prepare::ies_kinks::tests::profile;
        use crate::synthetic::Rng;
        let cases = [
            profile(
                PhotometricType::A,
                &[0.0, 25.0, 60.0, 90.0],
                &[0.0, 10.0, 45.0, 80.0],
                HFold::Mirror,
                VFold::Mirror,
            ),
            profile(
                PhotometricType::A,
                &[-70.0, -5.0, 40.0],
                &[-85.0, -30.0, 20.0, 75.0],
                HFold::AsGiven,
                VFold::AsGiven,
            ),
            profile(
                PhotometricType::A,
                &[0.0],
                &[-60.0, 0.0, 35.0],
                HFold::Constant,
                VFold::AsGiven,
            ),
            profile(
                PhotometricType::C,
                &[0.0, 30.0, 90.0],
                &[0.0, 20.0, 70.0, 120.0],
                HFold::Quadrant,
                VFold::AsGiven,
            ),
            profile(
                PhotometricType::B,
                &[0.0, 20.0, 90.0],
                &[0.0, 30.0, 90.0],
                HFold::Mirror,
                VFold::Mirror,
            ),
        ];
        // The lookup's cell: how many grid angles lie at or below the folded (H', V'), or None
        // outside angleScale's window.
        let cell = |p: &Profile, e: DVec3, s: f64| {
            let (h, v) = photometric_angles(p.kind, e, s)?;
            let (hq, vq) = if p.kind == PhotometricType::C {
                (fold_h_type_c(h, p.h_fold), v)
            } else {
                (
                    fold_mirror(h, p.h_fold == HFold::Mirror),
                    fold_mirror(v, p.v_fold == VFold::Mirror),
                )
            };
            // Outside a grid's range the factor is 0 (one cell, whichever side).
            let below = |g: &[f64], x: f64| {
                (g[0] <= x && x <= g[g.len() - 1]).then(|| g.iter().filter(|&&a| a <= x).count())
            };
            let hc = if p.h_fold == HFold::Constant {
                (p.kind == PhotometricType::C || hq.abs() <= 90.0).then_some(0)
            } else {
                below(&p.h, hq)
            };
            hc.zip(below(&p.v, vq))
        };
        let mut rng = Rng::new(0xA5CA1E);
        let mut changes = 0;
        for p in &cases {
            let scales: &[f64] = if p.kind == PhotometricType::B {
                &[0.0, 1.0, -1.0]
            } else {
                &[0.0, 0.8, 1.3, 0.45, -0.7, -1.4, 1.0, -1.0]
            };
            for &s in scales {
                let k = ies_kinks(p, s);
                let sides = |e: DVec3| -> Vec<f64> {
                    let cones = k.cones.iter().map(|(a, c)| a.dot(e) - c);
                    cones.chain(k.planes.iter().map(|m| m.dot(e))).collect()
                };
                for _ in 0..100 {
                    let (a, b) = (rng.unit(), rng.unit());
                    let steps = 4000;
                    let at = |i: usize| a.lerp(b, i as f64 / steps as f64).normalize();
                    let mut prev = (cell(p, at(0), s), sides(at(0)));
                    for i in 1..=steps {
                        let now = (cell(p, at(i), s), sides(at(i)));
                        if now.0 != prev.0 {
                            changes += 1;
                            let listed = prev.1.iter().zip(&now.1).any(|(x, y)| {
                                x.signum() != y.signum() || x.abs() < 1e-12 || y.abs() < 1e-12
                            });
                            assert!(
                                listed,
                                "{:?} s {s}: cell {:?} → {:?} between {} and {} on no listed kink",
                                p.kind,
                                prev.0,
                                now.0,
                                at(i - 1),
                                at(i)
                            );
                        }
                        prev = now;
                    }
                }
            }
        }
        assert!(changes > 2000, "only {changes} cell changes crossed");
    }

    #[test]
    fn angle_scale_formula() {
        assert_eq!(scale_polar_angle(60.0, 0.5), 120.0);
        assert_eq!(scale_polar_angle(60.0, 0.0), 60.0);
        assert_eq!(scale_polar_angle(150.0, -2.0), 165.0);
    }
}
