//! Adaptive 2D Gauss–Legendre cubature over a rectangle of parameters (f64): the light
//! sampling proofs' cell probabilities (`tests.rs`) and the sampler report's integrals of
//! `f²/p` ([`super::report`]). Panels whose probes straddle the integrand's support (some zero,
//! some not) are split down to a depth; smooth ones until the rule on their quarters agrees
//! with the rule on the whole.

/// 4-point Gauss–Legendre nodes and weights on [0, 1].
const GL4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// The 4 × 4 rule on [a0, a1] × [b0, b1].
fn rule(g: &impl Fn(f64, f64) -> f64, a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    let mut s = 0.0;
    for &(ua, wa) in &GL4 {
        for &(ub, wb) in &GL4 {
            s += wa * wb * g(a0 + ua * (a1 - a0), b0 + ub * (b1 - b0));
        }
    }
    s * (a1 - a0) * (b1 - b0)
}

/// `∫∫ g da db` over the panel [a0, a1] × [b0, b1]: split `split` times regardless (so that a
/// corner of the support poking into a cell is seen), then refined as the module docs say
/// down to `depth`, smooth panels until their quarters agree within `tol` (absolute). Returns
/// the integral and an error bound for the panels left unresolved at the finest level (the
/// integral over a mixed panel lies in [0, area · max g at its probes], charged in full; a
/// smooth one's quarter-vs-whole difference).
pub fn integrate(
    g: &impl Fn(f64, f64) -> f64,
    (a0, a1): (f64, f64),
    (b0, b1): (f64, f64),
    depth: u32,
    split: u32,
    tol: f64,
) -> (f64, f64) {
    let (mut zeros, mut probes) = (0, 0);
    let mut hi = 0f64;
    let mut probe = |v: f64| {
        probes += 1;
        zeros += (v == 0.0) as usize;
        hi = hi.max(v);
    };
    let mut sum = 0.0;
    for &(ua, wa) in &GL4 {
        for &(ub, wb) in &GL4 {
            let v = g(a0 + ua * (a1 - a0), b0 + ub * (b1 - b0));
            probe(v);
            sum += wa * wb * v;
        }
    }
    // The Gauss nodes stay 7 % away from the panel's edges, where an edge running along it
    // could hide: the corners and edge midpoints are probed too.
    for (ua, ub) in [
        (0.0, 0.0),
        (0.5, 0.0),
        (1.0, 0.0),
        (0.0, 0.5),
        (1.0, 0.5),
        (0.0, 1.0),
        (0.5, 1.0),
        (1.0, 1.0),
        (0.5, 0.5),
    ] {
        probe(g(a0 + ua * (a1 - a0), b0 + ub * (b1 - b0)));
    }
    let area = (a1 - a0) * (b1 - b0);
    let whole = sum * area;
    let mixed = zeros > 0 && zeros < probes;
    let (am, bm) = (0.5 * (a0 + a1), 0.5 * (b0 + b1));
    let quads = [
        ((a0, am), (b0, bm)),
        ((am, a1), (b0, bm)),
        ((a0, am), (bm, b1)),
        ((am, a1), (bm, b1)),
    ];
    let recurse = || {
        quads.iter().fold((0.0, 0.0), |acc, &(ra, rb)| {
            let r = integrate(g, ra, rb, depth - 1, split.saturating_sub(1), tol);
            (acc.0 + r.0, acc.1 + r.1)
        })
    };
    if depth > 0 && (mixed || split > 0) {
        return recurse();
    }
    if mixed {
        return (whole, area * hi);
    }
    let fine: f64 = quads
        .iter()
        .map(|&((w, x), (y, z))| rule(g, w, x, y, z))
        .sum();
    let err = (fine - whole).abs();
    if err > tol && depth > 0 {
        return recurse();
    }
    (fine, if err > tol { err } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The area of a quarter disk (a support with a curved edge) and a smooth integral.
    #[test]
    fn integrates_a_disk_and_a_smooth_function() {
        let disk = |a: f64, b: f64| if a * a + b * b <= 1.0 { 1.0 } else { 0.0 };
        let (v, bound) = integrate(&disk, (0.0, 1.0), (0.0, 1.0), 10, 2, 1e-12);
        let want = std::f64::consts::FRAC_PI_4;
        // The bound charges each unresolved edge panel in full (2e-3 here); the estimate itself
        // is far closer.
        assert!(
            (v - want).abs() <= bound + 1e-12 && bound < 1e-2,
            "{v} ± {bound}"
        );
        assert!((v - want).abs() < 1e-5, "{v} vs {want}");
        let smooth = |a: f64, b: f64| (a * b).exp();
        let (v, bound) = integrate(&smooth, (0.0, 1.0), (0.0, 2.0), 8, 0, 1e-13);
        // ∫₀¹∫₀² e^{ab} db da = ∫₀¹ (e^{2a} − 1)/a da = Ei(2) − ln 2 − γ.
        let want = 4.954_234_356_001_89 - std::f64::consts::LN_2 - 0.577_215_664_901_532_9;
        assert!((v - want).abs() < 1e-11 && bound == 0.0, "{v} vs {want}");
    }
}
