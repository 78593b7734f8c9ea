//! Quadrature and root finding for the exact dome irradiance (f64).
//!
//! - Gauss–Legendre rules of every order up to [`MAX_ORDER`], built once by
//!   [`crate::rules::gauss_legendre_pm1`] (luxeval's one builder) and kept.
//! - Adaptive bisection on top of an n-point rule: an interval is accepted when the rule on it
//!   and the sum of the rule on its two halves agree to the tolerance (the halves' sum is kept).
//! - Roots: sign changes on a sample grid, refined by the Illinois variant of regula falsi.

use std::sync::OnceLock;

use crate::rules::gauss_legendre_pm1;

/// The largest rule cached.
pub const MAX_ORDER: usize = 48;

/// The n-point Gauss–Legendre rule on [−1, 1]: (nodes, weights), n clamped to 1..=[`MAX_ORDER`].
pub fn gauss_legendre(n: usize) -> &'static (Vec<f64>, Vec<f64>) {
    static RULES: OnceLock<Vec<(Vec<f64>, Vec<f64>)>> = OnceLock::new();
    let rules = RULES.get_or_init(|| (0..=MAX_ORDER).map(gauss_legendre_pm1).collect());
    &rules[n.clamp(1, MAX_ORDER)]
}

/// `∫_a^b f` by the n-point rule, for vector-valued `f` (K components).
pub fn gl<const K: usize>(
    n: usize,
    a: f64,
    b: f64,
    mut f: impl FnMut(f64) -> [f64; K],
) -> [f64; K] {
    let (x, w) = gauss_legendre(n);
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut s = [0.0; K];
    for (xi, wi) in x.iter().zip(w) {
        let v = f(c + h * xi);
        for k in 0..K {
            s[k] += wi * v[k];
        }
    }
    s.map(|v| v * h)
}

fn dist<const K: usize>(a: &[f64; K], b: &[f64; K]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Globally adaptive bisection with the n-point rule: each interval's error estimate is
/// `|Q(a,b) − Q(a,m) − Q(m,b)|` (max over components) and its value the halves' sum; the
/// interval with the largest estimate is split until the estimates sum to at most `tol` or
/// `max_intervals` are in use. Returns the integral and the summed estimate (a pessimistic
/// bound: the halves' sum is typically far better than the difference).
pub fn adaptive<const K: usize>(
    n: usize,
    a: f64,
    b: f64,
    tol: f64,
    max_intervals: usize,
    f: &mut impl FnMut(f64) -> [f64; K],
) -> ([f64; K], f64) {
    let mut parts = vec![split(n, a, b, gl(n, a, b, &mut *f), f)];
    loop {
        let total: f64 = parts.iter().map(|p| p.3).sum();
        if total <= tol || parts.len() >= max_intervals {
            let s = parts.iter().fold([0.0; K], |acc, p| add(&acc, &p.2));
            return (s, total);
        }
        let (worst, _) =
            parts.iter().enumerate().fold(
                (0, -1.0),
                |best, (i, p)| if p.3 > best.1 { (i, p.3) } else { best },
            );
        let (pa, pb, _, _, l, r) = parts.swap_remove(worst);
        let m = 0.5 * (pa + pb);
        if !(m > pa && m < pb) {
            // Cannot split further in f64: keep it as it is.
            parts.push((pa, pb, add(&l, &r), 0.0, l, r));
            continue;
        }
        parts.push(split(n, pa, m, l, f));
        parts.push(split(n, m, pb, r, f));
    }
}

type Part<const K: usize> = (f64, f64, [f64; K], f64, [f64; K], [f64; K]);

fn add<const K: usize>(a: &[f64; K], b: &[f64; K]) -> [f64; K] {
    std::array::from_fn(|k| a[k] + b[k])
}

/// An interval with its halves' rules, their sum and the error estimate.
fn split<const K: usize>(
    n: usize,
    a: f64,
    b: f64,
    whole: [f64; K],
    f: &mut impl FnMut(f64) -> [f64; K],
) -> Part<K> {
    let m = 0.5 * (a + b);
    let l = gl(n, a, m, &mut *f);
    let r = gl(n, m, b, &mut *f);
    let both = add(&l, &r);
    let err = dist(&both, &whole);
    (a, b, both, err, l, r)
}

/// A root of `f` in `[a, b]` given `f(a)`, `f(b)` of opposite signs (Illinois regula falsi,
/// converged to ~1e-15 of the interval or 100 steps).
pub fn illinois(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, fa: f64, fb: f64) -> f64 {
    let tol = 1e-15 * (b - a).abs().max(1e-300) + 1e-300;
    illinois_to(f, a, b, fa, fb, tol)
}

/// [`illinois`] stopping once the bracket is at most `tol` wide (or after 100 steps).
pub fn illinois_to(
    f: &mut impl FnMut(f64) -> f64,
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
    tol: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..100 {
        if (b - a).abs() <= tol {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a.min(b) && c < a.max(b)) {
            c = 0.5 * (a + b);
        }
        let fc = f(c);
        if fc == 0.0 {
            return c;
        }
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}

/// Roots of `f` in `(a, b)` seen as sign changes between `samples + 1` equally spaced points,
/// each refined by [`illinois`]. Roots closer than the spacing that cancel in sign are missed;
/// callers use this only where a piece holds at most one or two well-separated roots.
pub fn sign_change_roots(
    f: &mut impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    samples: usize,
    out: &mut Vec<f64>,
) {
    let mut x0 = a;
    let mut f0 = f(a);
    for k in 1..=samples {
        let x1 = if k == samples {
            b
        } else {
            a + (b - a) * k as f64 / samples as f64
        };
        let f1 = f(x1);
        if (f0 < 0.0 && f1 > 0.0) || (f0 > 0.0 && f1 < 0.0) {
            out.push(illinois(f, x0, x1, f0, f1));
        } else if f1 == 0.0 && k < samples {
            out.push(x1);
        }
        x0 = x1;
        f0 = f1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_exactly() {
        for n in 1..=20 {
            // ∫_{-1}^{1} x^k = 2/(k+1) for even k; exact up to degree 2n − 1.
            for k in 0..2 * n {
                let q = gl::<1>(n, -1.0, 1.0, |x| [x.powi(k as i32)])[0];
                let exact = if k % 2 == 0 {
                    2.0 / (k as f64 + 1.0)
                } else {
                    0.0
                };
                assert!((q - exact).abs() < 1e-14, "n={n} k={k}: {q} vs {exact}");
            }
        }
    }

    #[test]
    fn adaptive_handles_a_sqrt_endpoint() {
        // ∫_0^1 √x dx = 2/3: an endpoint singularity that a single rule integrates poorly.
        let (v, _) = adaptive::<1>(8, 0.0, 1.0, 1e-13, 200, &mut |x| [x.sqrt()]);
        assert!((v[0] - 2.0 / 3.0).abs() < 1e-12, "{}", v[0]);
    }

    #[test]
    fn roots_are_found_and_refined() {
        let mut out = vec![];
        sign_change_roots(&mut |x: f64| x.cos(), 0.0, 7.0, 16, &mut out);
        let want = [0.5, 1.5].map(|k: f64| k * std::f64::consts::PI);
        assert_eq!(out.len(), 2, "{out:?}");
        for (r, w) in out.iter().zip(want) {
            assert!((r - w).abs() < 1e-13, "{r} vs {w}");
        }
    }
}
