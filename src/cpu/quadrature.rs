//! The CPU reference's adaptive quadrature: [`integrate`], a global adaptive driver over the
//! Gauss–Kronrod pair of [`crate::rules::gk15`] (bisect the interval with the largest estimate
//! until the sum of estimates meets the tolerance), as in QUADPACK's `qag`;
//! [`integrate_with`] the same driver over a chosen [`Pair`].
//!
//! Values are RGB ([`DVec3`]); an error is measured in the largest channel.

use glam::DVec3;

use crate::rules::{gk7, gk15};

fn norm(v: DVec3) -> f64 {
    v.abs().max_element()
}

/// Tolerances and limits of [`integrate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Stop when the summed error estimate is at most `rel · |result|` ...
    pub rel: f64,
    /// ... or at most `abs`.
    pub abs: f64,
    /// Largest number of intervals (each costs 15 evaluations); the best estimate so far is
    /// returned when it is reached.
    pub max_intervals: usize,
}

/// The embedded Gauss–Kronrod pair an [`integrate_with`] applies to each interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pair {
    /// 7-point Gauss / 15-point Kronrod (QUADPACK `qk15`): the reference's.
    Gk15,
    /// 3-point Gauss / 7-point Kronrod: a third of the evaluations for loose tolerances.
    Gk7,
}

impl Pair {
    /// (Kronrod estimate, |Kronrod − Gauss|) on [a, b].
    pub fn apply(self, f: &mut impl FnMut(f64) -> DVec3, a: f64, b: f64) -> (DVec3, f64) {
        match self {
            Pair::Gk15 => gk15(f, a, b),
            Pair::Gk7 => gk7(f, a, b),
        }
    }
}

/// ∫ f over the union of consecutive intervals `breaks[i]..breaks[i+1]`, globally adaptive.
/// Breaks are where f is not smooth; f is never evaluated at a break.
pub fn integrate(f: &mut impl FnMut(f64) -> DVec3, breaks: &[f64], tol: Tolerance) -> DVec3 {
    integrate_with(f, breaks, tol, Pair::Gk15)
}

/// [`integrate`] with each interval's pair chosen.
pub fn integrate_with(
    f: &mut impl FnMut(f64) -> DVec3,
    breaks: &[f64],
    tol: Tolerance,
    pair: Pair,
) -> DVec3 {
    let mut parts: Vec<(f64, f64, DVec3, f64)> = Vec::with_capacity(breaks.len() + 16);
    for w in breaks.windows(2) {
        if w[1] > w[0] {
            let (v, e) = pair.apply(f, w[0], w[1]);
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
        let (v1, e1) = pair.apply(f, a, m);
        let (v2, e2) = pair.apply(f, m, b);
        parts[i] = (a, m, v1, e1);
        parts.push((m, b, v2, e2));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
