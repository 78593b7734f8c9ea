//! Walker's alias method, built by Vose's O(n) algorithm (M. D. Vose, "A linear algorithm for
//! generating random numbers with a given distribution", IEEE TSE 17(9), 1991; A. J. Walker,
//! ACM TOMS 3(3), 1977): one uniform picks a discrete index with probability `w_i / Σw` in O(1)
//! (DESIGN.md §9 S2 "dome": "an alias table (O(1) per sample)").
//!
//! The table is n cells of equal probability `1/n`; cell `i` keeps index `i` with probability
//! `prob[i]` and otherwise gives `alias[i]`. Drawing: `x = u·n`, cell `i = ⌊x⌋`, and the
//! fraction `f = x − i` decides between `i` and `alias[i]`; what is left of `f` after that
//! decision is again uniform in [0, 1) and is handed back, so that one uniform both picks the
//! index and leaves one for the caller (pbrt-v4's `AliasTable::Sample` does the same).
//!
//! Storage is three flat arrays (`prob`, `alias`, `pmf`) so that a GPU packer can copy them as
//! `f32`/`u32` buffers ([`AliasTable::to_f32`]); the CPU keeps f64.

/// An alias table over non-negative weights.
#[derive(Clone, Debug)]
pub struct AliasTable {
    /// Probability that cell i keeps its own index (0 for a zero weight: it always aliases).
    prob: Vec<f64>,
    /// The index cell i gives otherwise (always one with a positive weight).
    alias: Vec<u32>,
    /// `w_i / Σw`, exactly as the caller's pdf uses it.
    pmf: Vec<f64>,
}

/// The largest f64 below 1 (a uniform in [0, 1) must stay below 1 after rescaling).
const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;

/// 2⁵³: a 53-bit uniform's resolution.
const TWO_53: f64 = 9_007_199_254_740_992.0;

impl AliasTable {
    /// The table of `weights` (index i drawn with probability `w_i / Σw`). `None` when no
    /// weight is positive, or any is negative or not finite, or there are more than `u32::MAX`
    /// of them.
    pub fn new(weights: &[f64]) -> Option<AliasTable> {
        let n = weights.len();
        if n == 0 || n > u32::MAX as usize || weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        let max = weights.iter().cloned().fold(0.0, f64::max);
        if max <= 0.0 {
            return None;
        }
        let sum: f64 = weights.iter().sum();
        let pmf: Vec<f64> = if sum.is_finite() {
            weights.iter().map(|w| w / sum).collect()
        } else {
            // Σw overflows: divide by the largest weight first (then Σ ≤ n).
            let scaled: Vec<f64> = weights.iter().map(|w| w / max).collect();
            let sum: f64 = scaled.iter().sum();
            scaled.iter().map(|w| w / sum).collect()
        };
        // Vose: each cell's mass in units of the mean, 1 on average; cells below 1 ("small")
        // are topped up from cells above 1 ("large"), which become their alias.
        let mut q: Vec<f64> = pmf.iter().map(|p| p * n as f64).collect();
        let mut prob = vec![0.0; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<u32>, Vec<u32>) =
            (0..n as u32).partition(|&i| q[i as usize] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            // (Rounding can leave a drained large cell a hair below 0.)
            prob[s as usize] = q[s as usize].clamp(0.0, 1.0);
            alias[s as usize] = l;
            // The large cell gives what the small one lacked.
            q[l as usize] = (q[l as usize] + q[s as usize]) - 1.0;
            if q[l as usize] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left is 1 up to rounding (Vose's argument): keep the own index, except for a
        // cell whose weight is 0, which rounding alone can leave here and which must never be
        // drawn: it aliases the heaviest cell.
        let heaviest = pmf
            .iter()
            .enumerate()
            .fold(0, |b, (i, p)| if *p > pmf[b] { i } else { b }) as u32;
        for i in small.into_iter().chain(large) {
            if pmf[i as usize] > 0.0 {
                prob[i as usize] = 1.0;
            } else {
                prob[i as usize] = 0.0;
                alias[i as usize] = heaviest;
            }
        }
        Some(AliasTable { prob, alias, pmf })
    }

    /// The number of indices.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// The probability of index `i`: `w_i / Σw`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f64 {
        self.pmf[i]
    }

    /// Index i with probability `pmf(i)` from two uniforms: `cell` picks the cell (give it 53
    /// bits for large tables, `cpu::sample::rng::uniform53`), `coin` keeps it or takes its
    /// alias.
    ///
    /// The cell is `⌊X·n / 2⁵³⌋` for `X = ⌊cell·2⁵³⌋` in exact integer arithmetic (not the
    /// rounded product `cell·n`, which names the next cell when it rounds up to an integer), so
    /// that the WGSL twin (`shaders/sample/dome.wgsl`), which holds the 53 bits as two u32
    /// words, names the very same cell.
    #[inline]
    pub fn pick(&self, cell: f64, coin: f64) -> usize {
        let n = self.prob.len();
        let x = (cell.clamp(0.0, ONE_MINUS_EPS) * TWO_53) as u64;
        let i = ((x as u128 * n as u128) >> 53) as usize;
        if coin < self.prob[i] {
            i
        } else {
            self.alias[i] as usize
        }
    }

    /// Cell i's keep-probability as the integer threshold `T = ⌈prob·2²⁴⌉`: for a coin that is
    /// a multiple of 2⁻²⁴ (`cpu::sample::rng::uniform`), `coin < prob` exactly when
    /// `coin·2²⁴ < T` (both sides integers), so the GPU compares integers and keeps the
    /// cell exactly when the CPU does.
    #[inline]
    pub fn keep_threshold(&self, i: usize) -> u32 {
        (self.prob[i] * 16_777_216.0).ceil() as u32
    }

    /// The index cell i gives when it does not keep its own.
    #[inline]
    pub fn alias(&self, i: usize) -> u32 {
        self.alias[i]
    }

    /// The cells' keep-probabilities, aliases and pmf (f64 on the CPU).
    #[cfg(test)]
    pub fn cells(&self) -> (&[f64], &[u32], &[f64]) {
        (&self.prob, &self.alias, &self.pmf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::Rng;

    #[test]
    fn refuses_empty_zero_negative_and_non_finite_weights() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, -1.0]).is_none());
        assert!(AliasTable::new(&[1.0, f64::NAN]).is_none());
        assert!(AliasTable::new(&[1.0, f64::INFINITY]).is_none());
        // Huge weights do not overflow the sum.
        let t = AliasTable::new(&[f64::MAX, f64::MAX, 0.0]).unwrap();
        assert_eq!(t.pmf(0), 0.5);
        assert_eq!(t.pmf(2), 0.0);
    }

    /// The probability each index is drawn with, read exactly off the cells:
    /// `(prob[i] + Σ_{alias[j] = i} (1 − prob[j])) / n`.
    fn drawn(t: &AliasTable) -> Vec<f64> {
        let n = t.len();
        let mut p = vec![0.0; n];
        for i in 0..n {
            p[i] += t.prob[i] / n as f64;
            p[t.alias[i] as usize] += (1.0 - t.prob[i]) / n as f64;
        }
        p
    }

    #[test]
    fn cells_give_the_pmf_and_zero_weights_are_never_drawn() {
        let mut rng = Rng::new(7);
        for n in [1usize, 2, 3, 10, 257] {
            for _ in 0..20 {
                let w: Vec<f64> = (0..n)
                    .map(|_| {
                        if rng.chance(0.3) {
                            0.0
                        } else {
                            rng.f64().powi(4) * 1e3
                        }
                    })
                    .collect();
                let Some(t) = AliasTable::new(&w) else {
                    assert!(w.iter().all(|v| *v == 0.0));
                    continue;
                };
                let sum: f64 = w.iter().sum();
                for (i, p) in drawn(&t).iter().enumerate() {
                    assert!(
                        (p - w[i] / sum).abs() < 1e-14,
                        "n {n} i {i}: {p} vs {}",
                        w[i] / sum
                    );
                    assert_eq!(t.pmf(i), w[i] / sum);
                    if w[i] == 0.0 {
                        assert_eq!(t.prob[i], 0.0);
                    }
                    assert!(w[t.alias[i] as usize] > 0.0 || t.prob[i] == 1.0);
                }
                let (prob, alias, pmf) = t.cells();
                assert_eq!((prob.len(), alias.len(), pmf.len()), (n, n, n));
                for _ in 0..200 {
                    let i = t.pick(rng.f64(), rng.f64());
                    assert!(w[i] > 0.0);
                }
                // The ends of [0, 1).
                for u in [0.0, ONE_MINUS_EPS, 1.0] {
                    for c in [0.0, ONE_MINUS_EPS, 1.0] {
                        assert!(w[t.pick(u, c)] > 0.0);
                    }
                }
            }
        }
    }

    /// The picks follow the pmf: a χ² over the indices (p ≈ 1e-6).
    #[test]
    fn picks_follow_the_pmf() {
        let w = [0.0, 3.0, 1.0, 0.5, 2.0, 0.0, 0.25];
        let t = AliasTable::new(&w).unwrap();
        let mut rng = Rng::new(11);
        let m = 200_000;
        let mut counts = [[0u32; 4]; 7];
        for _ in 0..m {
            // Four independent runs per index (the coin's quarters), as four cells each.
            let coin = rng.f64();
            let i = t.pick(rng.f64(), coin);
            counts[i][(rng.f64() * 4.0) as usize] += 1;
        }
        let sum: f64 = w.iter().sum();
        let mut chi2 = 0.0;
        let mut dof = 0;
        for (i, row) in counts.iter().enumerate() {
            if w[i] == 0.0 {
                assert_eq!(row.iter().sum::<u32>(), 0);
                continue;
            }
            for c in row {
                let e = m as f64 * w[i] / sum / 4.0;
                chi2 += (*c as f64 - e).powi(2) / e;
                dof += 1;
            }
        }
        // 20 cells, 19 degrees of freedom; the threshold is the χ² quantile at p = 1e-6 by
        // Wilson–Hilferty (χ²_p ≈ k(1 − 2/9k + z·√(2/9k))³, z = 4.753 the normal 1e-6 quantile).
        assert_eq!(dof, 20);
        let k = 19.0f64;
        let limit = k * (1.0 - 2.0 / (9.0 * k) + 4.753 * (2.0 / (9.0 * k)).sqrt()).powi(3);
        assert!(chi2 < limit, "χ² = {chi2} ≥ {limit}");
    }
}
