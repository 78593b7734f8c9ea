//! The counter-based random numbers of DESIGN.md §9 S3 (f64 side). Twin of
//! `shaders/sample/rng.wgsl`.
//!
//! `u(seed, point, sample, dimension)` is a pure function of its four keys, so a seed gives the
//! same directions on any chunking, thread count or machine. Each key is folded in by the PCG
//! hash of Jarzynski & Olano, "Hash Functions for GPU Rendering" (JCGT 9(3), 2020, §2: the
//! `pcg` output permutation of one LCG step), whose 32-bit avalanche passes their statistical
//! tests; chaining it over the keys is their "nested" construction. The top 24 bits make the
//! uniform, so it is an exact f32 and both paths see the very same `u`.

/// One PCG step and its output permutation (Jarzynski & Olano 2020, `pcg`).
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The uniform in [0, 1) for the four keys: 24 bits, a multiple of 2⁻²⁴ (exact in f32).
pub fn uniform(seed: u32, point: u32, sample: u32, dim: u32) -> f64 {
    let h = pcg_hash(dim.wrapping_add(pcg_hash(
        sample.wrapping_add(pcg_hash(point.wrapping_add(pcg_hash(seed)))),
    )));
    (h >> 8) as f64 * (1.0 / 16_777_216.0)
}

/// A uniform in [0, 1) with 53 bits for the same keys: the 32-bit hash of [`uniform`] and 21
/// bits of one more PCG round of it. For choosing one of millions of cells (an environment
/// map's alias table): 24 bits would give each of 2²¹ cells 8 or 9 of the 2²⁴ values, a 12 %
/// error in its probability; 53 bits leave ≤ n/2⁵³.
pub fn uniform53(seed: u32, point: u32, sample: u32, dim: u32) -> f64 {
    let h = pcg_hash(dim.wrapping_add(pcg_hash(
        sample.wrapping_add(pcg_hash(point.wrapping_add(pcg_hash(seed)))),
    )));
    let lo = pcg_hash(h);
    (((h as u64) << 21) | (lo as u64 >> 11)) as f64 * (1.0 / 9_007_199_254_740_992.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Jarzynski & Olano's reference values of `pcg` (computed by hand from their listing:
    /// state = v·747796405 + 2891336453, word = ((state >> ((state >> 28) + 4)) ^ state) ·
    /// 277803737, out = (word >> 22) ^ word, all mod 2³²).
    #[test]
    fn pcg_matches_the_published_recurrence() {
        // v = 0: state = 2891336453 = 0xAC564B05, state >> 28 = 10, shift 14.
        let state: u64 = 2_891_336_453;
        let word = (((state >> 14) ^ state) * 277_803_737) & 0xFFFF_FFFF;
        let out = ((word >> 22) ^ word) as u32;
        assert_eq!(pcg_hash(0), out);
        assert_ne!(pcg_hash(1), pcg_hash(0));
    }

    /// The uniforms are uniform: a χ² test over 64 bins of 2²⁰ draws across every key
    /// (threshold 133.6, p = 1e-6 for 63 degrees of freedom) and the mean within 5σ.
    #[test]
    fn uniforms_are_uniform_across_keys() {
        let mut bins = [0u64; 64];
        let mut sum = 0.0;
        let n = 1u32 << 20;
        for i in 0..n {
            let u = uniform(7, i >> 10, i & 1023, i % 3);
            assert!((0.0..1.0).contains(&u));
            bins[(u * 64.0) as usize] += 1;
            sum += u;
        }
        let e = n as f64 / 64.0;
        let chi2: f64 = bins.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
        assert!(chi2 < 133.6, "χ² = {chi2}");
        let mean = sum / n as f64;
        let sigma = (1.0 / 12.0 / n as f64).sqrt();
        assert!((mean - 0.5).abs() < 5.0 * sigma, "mean {mean}");
        // Neighbouring keys are not correlated: the dimension-0 and -1 uniforms of one sample.
        let mut cov = 0.0;
        for i in 0..n {
            cov += (uniform(3, 0, i, 0) - 0.5) * (uniform(3, 0, i, 1) - 0.5);
        }
        let cov = cov / n as f64;
        assert!(cov.abs() < 5.0 / 12.0 / (n as f64).sqrt(), "cov {cov}");
    }

    /// The fine uniform shares its top 24 bits with the plain one and fills the cells of a
    /// table of 3·2²⁰ (not a power of two) evenly: a χ² over 96 groups of cells.
    #[test]
    fn fine_uniforms_refine_the_plain_ones() {
        let n = 3u64 << 20;
        let mut bins = [0u64; 96];
        let draws = 1u32 << 20;
        for i in 0..draws {
            let f = uniform53(1, i, 0, 3);
            let c = uniform(1, i, 0, 3);
            assert!((0.0..1.0).contains(&f) && (f - c).abs() < 1.0 / 16_777_216.0 && f >= c);
            let cell = (f * n as f64) as u64;
            bins[(cell * 96 / n) as usize] += 1;
        }
        let e = draws as f64 / 96.0;
        let chi2: f64 = bins.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
        // 95 degrees of freedom, p = 1e-6: 175.
        assert!(chi2 < 175.0, "χ² = {chi2}");
    }
}
