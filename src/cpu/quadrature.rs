//! Quadrature rules for the irradiance reference (f64) and the constants of the GPU kernel.
//!
//! - [`gk15`]: the 7-point Gauss / 15-point Kronrod pair (QUADPACK `qk15` nodes and weights),
//!   whose difference is the local error estimate of [`integrate`], a global adaptive driver
//!   (bisect the interval with the largest estimate until the sum of estimates meets the
//!   tolerance), as in QUADPACK's `qag`.
//! - [`gauss_legendre`]: n-point Gauss–Legendre nodes and weights on [0, 1], computed in f64 by
//!   Newton's method on Pₙ. The WGSL kernel's Gauss–Legendre nodes come from here through the
//!   generated prelude (`src/gpu/shaders.rs`), so no node is retyped; [`gk15_unit`] gives it the
//!   Gauss–Kronrod pair the same way.
//!
//! Values are RGB ([`DVec3`]); an error is measured in the largest channel.

// The nodes and weights are QUADPACK's published 33-digit values, kept verbatim.
#![allow(clippy::excessive_precision)]

use glam::DVec3;

/// Kronrod nodes on [−1, 1] (the positive half; the last is the centre).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];
/// Kronrod weights for [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];
/// Gauss weights for the odd-indexed Kronrod nodes XGK[1], XGK[3], XGK[5], XGK[7].
const WG: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

fn norm(v: DVec3) -> f64 {
    v.abs().max_element()
}

/// The Kronrod estimate of ∫ₐᵇ f and |Kronrod − Gauss| (largest channel).
pub fn gk15(f: &mut impl FnMut(f64) -> DVec3, a: f64, b: f64) -> (DVec3, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = fc * WGK[7];
    let mut g = fc * WG[3];
    for j in 0..7 {
        let dx = h * XGK[j];
        let s = f(c - dx) + f(c + dx);
        k += s * WGK[j];
        if j % 2 == 1 {
            g += s * WG[j / 2];
        }
    }
    (k * h, norm((k - g) * h))
}

/// The 15 Gauss–Kronrod nodes on [0, 1], ascending, with their Kronrod weights and Gauss
/// weights (0 at the nodes that are not Gauss nodes): the WGSL kernel's outer rule, passed to it
/// through the generated prelude.
pub fn gk15_unit() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rows: Vec<(f64, f64, f64)> = Vec::with_capacity(15);
    for j in 0..8 {
        let wg = if j % 2 == 1 { WG[j / 2] } else { 0.0 };
        rows.push((0.5 * (1.0 - XGK[j]), 0.5 * WGK[j], 0.5 * wg));
        if j < 7 {
            rows.push((0.5 * (1.0 + XGK[j]), 0.5 * WGK[j], 0.5 * wg));
        }
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    (
        rows.iter().map(|r| r.0).collect(),
        rows.iter().map(|r| r.1).collect(),
        rows.iter().map(|r| r.2).collect(),
    )
}

/// Tolerances and limits of [`integrate`].
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// Stop when the summed error estimate is at most `rel · |result|` ...
    pub rel: f64,
    /// ... or at most `abs`.
    pub abs: f64,
    /// Largest number of intervals (each costs 15 evaluations); the best estimate so far is
    /// returned when it is reached.
    pub max_intervals: usize,
}

/// ∫ f over the union of consecutive intervals `breaks[i]..breaks[i+1]`, globally adaptive.
/// Breaks are where f is not smooth; f is never evaluated at a break.
pub fn integrate(f: &mut impl FnMut(f64) -> DVec3, breaks: &[f64], tol: Tolerance) -> DVec3 {
    let mut parts: Vec<(f64, f64, DVec3, f64)> = Vec::with_capacity(breaks.len() + 16);
    for w in breaks.windows(2) {
        if w[1] > w[0] {
            let (v, e) = gk15(f, w[0], w[1]);
            parts.push((w[0], w[1], v, e));
        }
    }
    loop {
        let total: DVec3 = parts.iter().map(|p| p.2).sum();
        let err: f64 = parts.iter().map(|p| p.3).sum();
        if err <= tol.rel * norm(total) || err <= tol.abs || parts.len() >= tol.max_intervals {
            return total;
        }
        let (i, _) = parts
            .iter()
            .enumerate()
            .max_by(|x, y| x.1.3.total_cmp(&y.1.3))
            .expect("at least one interval when the error is positive");
        let (a, b, _, _) = parts[i];
        let m = 0.5 * (a + b);
        if !(m > a && m < b) {
            // The interval cannot be split further in f64; accept it.
            parts[i].3 = 0.0;
            continue;
        }
        let (v1, e1) = gk15(f, a, m);
        let (v2, e2) = gk15(f, m, b);
        parts[i] = (a, m, v1, e1);
        parts.push((m, b, v2, e2));
    }
}

/// n-point Gauss–Legendre nodes and weights on [0, 1] (ascending nodes).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Initial guess for the i-th largest root of Pₙ on [−1, 1].
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 1 { z } else { p1 };
            let pm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * p - pm1) / (z * z - 1.0);
            let dz = p / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        // Map [−1, 1] → [0, 1].
        x[n - 1 - i] = 0.5 * (1.0 + z);
        x[i] = 0.5 * (1.0 - z);
        w[n - 1 - i] = 0.5 * wi;
        w[i] = 0.5 * wi;
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in [1usize, 2, 5, 8, 12, 16] {
            let (x, w) = gauss_legendre(n);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            for k in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!((q - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "n={n} k={k}");
            }
            assert!(x.windows(2).all(|p| p[0] < p[1]));
        }
    }

    #[test]
    fn gk15_unit_matches_gk15() {
        let (x, wk, wg) = gk15_unit();
        assert_eq!(x.len(), 15);
        assert!(x.windows(2).all(|p| p[0] < p[1]));
        assert!((wk.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!((wg.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let f = |t: f64| (3.0 * t).sin() + t * t;
        let k: f64 = x.iter().zip(&wk).map(|(x, w)| w * f(*x)).sum();
        let g: f64 = x.iter().zip(&wg).map(|(x, w)| w * f(*x)).sum();
        let (kk, e) = gk15(&mut |t| DVec3::splat(f(t)), 0.0, 1.0);
        assert!((k - kk.x).abs() < 1e-15 && ((k - g).abs() - e).abs() < 1e-15);
    }

    #[test]
    fn adaptive_handles_kinks_and_endpoint_singularities() {
        let tol = Tolerance {
            rel: 1e-12,
            abs: 0.0,
            max_intervals: 2000,
        };
        // √x on [0, 1] = 2/3; |x − 0.3| on [0, 1] = 0.29.
        let v = integrate(&mut |x: f64| DVec3::splat(x.sqrt()), &[0.0, 1.0], tol);
        assert!((v.x - 2.0 / 3.0).abs() < 1e-11, "{}", v.x);
        let v = integrate(
            &mut |x: f64| DVec3::splat((x - 0.3).abs()),
            &[0.0, 1.0],
            tol,
        );
        assert!((v.x - 0.29).abs() < 1e-12);
        let (v, e) = gk15(&mut |x: f64| DVec3::splat(x.exp()), 0.0, 1.0);
        assert!((v.x - (1f64.exp() - 1.0)).abs() < 1e-15 && e < 1e-9);
    }
}
