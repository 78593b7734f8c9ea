//! The sweep's lit and not wholly dark runs of columns, and the block sums of the lit ones
//! (latlong.rs module docs "Runs").

use glam::DVec3;
use rayon::prelude::*;

use super::Axes;
use crate::cpu::irradiance::dome::DomeIrradiance;

impl DomeIrradiance {
    /// `Σ m·V / k` over the lit pieces `ls, ls + 1, …` (`ll` of them, cyclically) of row piece
    /// `j`: per texel row of the piece, `m·` the summed column factors `Q_t` (module docs
    /// "Runs"), from the block sums where they are built.
    pub(super) fn lit_run(
        &self,
        axes: &Axes,
        prefix: Option<&RunPrefix>,
        j: usize,
        ls: usize,
        ll: usize,
        m: DVec3,
    ) -> DVec3 {
        let g = &self.grids[0];
        let (py, ry) = (g.ys[j], &axes.rows[j]);
        let n = g.xs.len();
        let mut out = DVec3::ZERO;
        for (t, r) in [(py.i0, ry[0]), (py.i1, ry[1])] {
            if r == [0.0; 2] {
                continue;
            }
            let mut q = [DVec3::ZERO; 3];
            let end = ls + ll;
            for (a, b) in [(ls, end.min(n)), (0, end.saturating_sub(n))] {
                if b > a {
                    let part = self.column_sum(axes, prefix, t as usize, a, b);
                    (0..3).for_each(|c| q[c] += part[c]);
                }
            }
            out += q[0] * (m.x * r[0]) + q[1] * (m.y * r[1]) + q[2] * (m.z * r[0]);
        }
        out
    }

    /// `Σ_{a ≤ i < b} Q_t(i)`: the block sums between the blocks' edges, the ends piece by
    /// piece.
    fn column_sum(
        &self,
        axes: &Axes,
        prefix: Option<&RunPrefix>,
        t: usize,
        a: usize,
        b: usize,
    ) -> [DVec3; 3] {
        let mut q = [DVec3::ZERO; 3];
        let mut add = |i: usize| {
            let qi = self.column_factor(axes, t, i);
            (0..3).for_each(|c| q[c] += qi[c]);
        };
        match prefix {
            Some(p) if b - a > 2 * p.block => {
                let (k0, k1) = (a.div_ceil(p.block), b / p.block);
                (a..k0 * p.block).for_each(&mut add);
                let (s0, s1) = (p.at(t, k0), p.at(t, k1));
                (k1 * p.block..b).for_each(&mut add);
                (0..3).for_each(|c| q[c] += s1[c] - s0[c]);
            }
            _ => (a..b).for_each(add),
        }
        q
    }

    /// `Q_t(i) = Σ_a L(texel (i_a, t)) · cols[i][a]`: column piece `i`'s factors on texel row
    /// `t`, the part of a lit piece's moment that does not depend on its row piece.
    fn column_factor(&self, axes: &Axes, t: usize, i: usize) -> [DVec3; 3] {
        let px = self.grids[0].xs[i];
        let cx = &axes.cols[i];
        let (l0, l1) = (
            crate::cpu::texture::tex_fetch(&self.img, px.i0, t as u32),
            crate::cpu::texture::tex_fetch(&self.img, px.i1, t as u32),
        );
        [0, 1, 2].map(|c| l0 * cx[0][c] + l1 * cx[1][c])
    }

    /// The block sums of [`RunPrefix`], built once (in parallel: see `DomeIrradiance::warm`).
    pub(in crate::cpu::irradiance::dome) fn run_prefix(&self) -> &RunPrefix {
        self.run_prefix.get_or_init(|| {
            let g = &self.grids[0];
            let block = RunPrefix::block_for(g.xs.len(), self.img.height);
            RunPrefix::new(self, self.axes(), block)
        })
    }
}

/// The lit (or not wholly dark) pieces of a row piece, found without testing every column:
/// where `c(i)` (the least, or the greatest, `cos(φ − φ₀)` over column piece `i`) is
/// unimodal around the circle of columns, and the test is monotone in `c(i)` (module docs
/// "Runs"), the pieces that pass are one cyclic run through the peak, whose ends a bisection
/// on either side finds.
pub(super) struct Runs {
    n: usize,
    peak: usize,
    trough: usize,
}

impl Runs {
    pub(super) fn new(c: impl Iterator<Item = f64> + Clone) -> Runs {
        let first = |better: fn(f64, f64) -> bool| {
            c.clone()
                .enumerate()
                .fold((0, f64::NAN), |(k, v), (i, x)| {
                    if v.is_nan() || better(x, v) {
                        (i, x)
                    } else {
                        (k, v)
                    }
                })
                .0
        };
        Runs {
            n: c.clone().count(),
            peak: first(|x, v| x > v),
            trough: first(|x, v| x < v),
        }
    }

    /// The run `(start, length)` of the columns that pass `test`, cyclically, or `None`.
    pub(super) fn run(&self, test: impl Fn(usize) -> bool) -> Option<(usize, usize)> {
        let n = self.n;
        if n == 0 || !test(self.peak) {
            return None;
        }
        if test(self.trough) {
            return Some((0, n));
        }
        // The last offset from the peak toward the trough that passes, on each side.
        let last = |span: usize, at: &dyn Fn(usize) -> usize| {
            let (mut lo, mut hi) = (0, span); // test(at(lo)) holds, test(at(hi)) does not.
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                if test(at(mid)) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        let (p, t) = (self.peak, self.trough);
        let right = last((t + n - p) % n, &|k| (p + k) % n);
        let left = last((p + n - t) % n, &|k| (p + n - k) % n);
        Some(((p + n - left) % n, left + right + 1))
    }
}

/// Per texel row `t`, the column factors `Q_t(i)` ([`DomeIrradiance::column_factor`]) summed
/// over every column piece before each block's start: `sums[t][k] = Σ_{i < k·block} Q_t(i)`.
/// A lit run then costs two lookups and at most two blocks' pieces per texel row, instead of
/// one moment per piece (module docs "Runs").
pub(in crate::cpu::irradiance::dome) struct RunPrefix {
    block: usize,
    stride: usize,
    sums: Vec<[DVec3; 3]>,
}

impl RunPrefix {
    /// The block, at least [`RUN_BLOCK`] columns, that keeps the sums within
    /// [`RUN_PREFIX_MAX_BYTES`].
    fn block_for(cols: usize, rows: usize) -> usize {
        let bytes = cols.saturating_mul(rows).saturating_mul(72);
        RUN_BLOCK.max(bytes.div_ceil(RUN_PREFIX_MAX_BYTES))
    }

    pub(in crate::cpu::irradiance::dome) fn new(
        d: &DomeIrradiance,
        axes: &Axes,
        block: usize,
    ) -> RunPrefix {
        let n = d.grids[0].xs.len();
        let stride = n / block + 1;
        let mut sums = vec![[DVec3::ZERO; 3]; d.img.height * stride];
        sums.par_chunks_mut(stride)
            .enumerate()
            .for_each(|(t, row)| {
                let mut acc = [DVec3::ZERO; 3];
                for (k, s) in row.iter_mut().enumerate() {
                    *s = acc;
                    for i in k * block..((k + 1) * block).min(n) {
                        let q = d.column_factor(axes, t, i);
                        (0..3).for_each(|c| acc[c] += q[c]);
                    }
                }
            });
        RunPrefix {
            block,
            stride,
            sums,
        }
    }

    fn at(&self, t: usize, k: usize) -> [DVec3; 3] {
        self.sums[t * self.stride + k]
    }
}

/// The fewest column pieces a block of [`RunPrefix`] holds.
const RUN_BLOCK: usize = 32;
/// The most bytes of block sums: 8192 × 4096 takes blocks of 36 columns.
const RUN_PREFIX_MAX_BYTES: usize = 64 << 20;
