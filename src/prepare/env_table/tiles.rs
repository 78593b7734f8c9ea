//! An environment table's texels grouped in tiles, for the product of the table with a
//! receiver's cosine (docs/SAMPLING.md "The dome's product with the cosine"): per tile its
//! probability, a cap of world directions holding its image and an alias table over its
//! texels; per receiver, the tiles' probabilities weighted by the largest cosine their caps can
//! have with its normal.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::super::alias::AliasTable;
use super::EnvTable;
use crate::prepare::texture::DomeFormat;

const PI: f64 = std::f64::consts::PI;

/// Square tiles of `side` texels (the last row and column may be narrower; for a cross `side`
/// divides the face size, so a tile never straddles faces), about 4096 of them: each with the
/// sum of its texels' probabilities, a cap of world directions holding its image, and an alias
/// table over its texels.
#[derive(Clone, Debug, Default)]
pub struct Tiles {
    pub side: u32,
    pub nx: u32,
    /// `W_t = Σ pmf(k)` over the tile's texels.
    pub weight: Vec<f64>,
    /// World centre and angular radius of a cap holding the tile's directions (radius π where
    /// no bound is kept).
    pub cap: Vec<(DVec3, f64)>,
    /// Over the tile's texels (local index `(j − j₀)·w_t + (i − i₀)`), by `pmf(k) / W_t`;
    /// `None` for a tile of weight 0.
    pub inner: Vec<Option<AliasTable>>,
}

/// A receiver's tile probabilities: `P(t | n) = q_t / Σq`, `q_t` the weight
/// `W_t · max(cos_bound_t(n), FLOOR)` in 48-bit fixed point (`⌊w·2⁴⁸⌋`), drawn by inverting
/// the running sum of the `q_t` in exact integer arithmetic. Not an alias table: the GPU twin
/// recomputes the weights per receiver in a loop over the tiles, where a Vose construction
/// does not fit; and integers, so that both backends' running sums and totals are exact and
/// they differ only by their weights' own rounding (f32 vs f64), not by a rounded sum of
/// thousands of terms (whose ~1e-6 would move every boundary of the running sum).
#[derive(Clone, Debug)]
pub struct ReceiverTiles {
    /// The running sum of the `q_t` in tile order (its last entry is the total).
    cdf: Vec<u64>,
}

/// 2⁴⁸, the tile weights' fixed point.
const FIXED: f64 = 281_474_976_710_656.0;

impl ReceiverTiles {
    /// The receiver's tile probabilities for `weights` (each in [0, 1]); `None` where none is
    /// positive in 48-bit fixed point.
    fn new(weights: impl Iterator<Item = f64>) -> Option<ReceiverTiles> {
        let mut sum = 0u64;
        let cdf: Vec<u64> = weights
            .map(|w| {
                sum += (w.clamp(0.0, 1.0) * FIXED).floor() as u64;
                sum
            })
            .collect();
        (sum > 0).then_some(ReceiverTiles { cdf })
    }

    /// `P(t | n)`.
    #[inline]
    pub fn pmf(&self, t: usize) -> f64 {
        let below = if t == 0 { 0 } else { self.cdf[t - 1] };
        (self.cdf[t] - below) as f64 / self.cdf[self.cdf.len() - 1] as f64
    }

    /// The tile drawn by two 24-bit uniforms `hi`, `lo` (48 bits, `U = ⌊hi·2²⁴⌋·2²⁴ +
    /// ⌊lo·2²⁴⌋`: a tile of probability 10⁻⁸ under the horizon floor is still drawn in
    /// proportion): the first tile whose running sum exceeds `⌊U·total / 2⁴⁸⌋`; a tile of
    /// weight 0 never (its sum equals its predecessor's).
    #[inline]
    pub fn pick(&self, hi: f64, lo: f64) -> usize {
        let digit = |v: f64| ((v * 16_777_216.0) as u64).min(0xFF_FFFF);
        let u = (digit(hi) << 24) | digit(lo);
        let total = self.cdf[self.cdf.len() - 1];
        let target = ((u as u128 * total as u128) >> 48) as u64;
        // target < total (u < 2⁴⁸), so some running sum exceeds it.
        self.cdf.partition_point(|&c| c <= target)
    }
}

/// The least factor a tile's weight keeps below the receiver's horizon: a tile whose cap bound
/// were wrong would still be drawn (the pdf stays > 0 wherever the plain table's is); the draws
/// wasted below the horizon are this factor times the ratio of the weight there to the
/// cosine-weighted weight above (≈ 2·10⁻⁴ for an even map).
pub const HORIZON_FLOOR: f64 = 1e-4;

/// The most tiles a table keeps: the GPU twin walks every tile twice per draw (the total, then
/// the pick), and lavapipe ends an invocation's loops silently after 65,535 iterations in
/// all. Only a map whose tile grid would be larger (a cross whose face size has no divisor near
/// the target side, e.g. a prime; an extreme aspect ratio) has none: its receivers draw from
/// the plain table, as without a normal.
pub const MAX_TILES: u32 = 16_384;

/// The largest cosine a cap of centre `c` and angular radius `r` (given as `cos r`, `sin r`)
/// can have with the unit normal n: 1 when n lies in the cap (`θ ≤ r`, θ = angle(n, c)), else
/// `cos(θ − r) = cos θ cos r + sin θ sin r` where that is positive, else 0 — written without
/// acos so that the f32 twin keeps its accuracy (f32 acos loses ~1e-4 rad near ±1; `sin θ =
/// |n × c|` keeps its relative precision).
#[inline]
pub fn cos_bound(n: DVec3, c: DVec3, cos_r: f64, sin_r: f64) -> f64 {
    let cos_t = n.dot(c).clamp(-1.0, 1.0);
    if cos_t >= cos_r {
        return 1.0;
    }
    let sin_t = n.cross(c).length().min(1.0);
    (cos_t * cos_r + sin_t * sin_r).max(0.0)
}

impl EnvTable {
    /// The tile side: about 4096 tiles (a receiver's table is one pass over them); for a cross, the largest divisor of the face size N not
    /// above that.
    fn tile_side(&self) -> u32 {
        let target = ((self.width as f64 * self.height as f64 / 4096.0)
            .sqrt()
            .round() as u32)
            .max(1);
        if self.format == DomeFormat::Cross {
            let n = self.width / 3;
            (1..=target.min(n))
                .rev()
                .find(|d| n.is_multiple_of(*d))
                .unwrap_or(1)
        } else {
            target
        }
    }

    /// The tile holding texel k and k's local index in it.
    #[inline]
    pub fn tile_of(&self, k: usize) -> (usize, usize) {
        let t = &self.tiles;
        let (i, j) = (
            (k % self.width as usize) as u32,
            (k / self.width as usize) as u32,
        );
        let (tx, ty) = (i / t.side, j / t.side);
        let tw = t.side.min(self.width - tx * t.side);
        (
            (ty * t.nx + tx) as usize,
            ((j - ty * t.side) * tw + (i - tx * t.side)) as usize,
        )
    }

    /// Texel k of local index `local` in tile `t` (the inverse of [`Self::tile_of`]).
    #[inline]
    pub fn texel_of(&self, t: usize, local: usize) -> usize {
        let tl = &self.tiles;
        let (tx, ty) = (t as u32 % tl.nx, t as u32 / tl.nx);
        let tw = tl.side.min(self.width - tx * tl.side);
        let (i, j) = (
            tx * tl.side + local as u32 % tw,
            ty * tl.side + local as u32 / tw,
        );
        (j * self.width + i) as usize
    }

    /// The unit world direction of chart point q in texel k.
    fn world_direction(&self, k: usize, q: DVec2) -> DVec3 {
        (self.frame.a_eff * self.chart_direction(k, q)).normalize()
    }

    pub(super) fn build_tiles(&self) -> Tiles {
        let side = self.tile_side();
        let (nx, ny) = (self.width.div_ceil(side), self.height.div_ceil(side));
        if nx as u64 * ny as u64 > MAX_TILES as u64 {
            return Tiles::default();
        }
        let per_tile: Vec<(f64, (DVec3, f64), Option<AliasTable>)> = (0..(nx * ny) as usize)
            .into_par_iter()
            .map(|t| {
                let (tx, ty) = (t as u32 % nx, t as u32 / nx);
                let (i0, j0) = (tx * side, ty * side);
                let (i1, j1) = ((i0 + side).min(self.width), (j0 + side).min(self.height));
                let mut pm = Vec::with_capacity(((i1 - i0) * (j1 - j0)) as usize);
                let mut corners = Vec::new();
                for j in j0..j1 {
                    for i in i0..i1 {
                        let k = (j * self.width + i) as usize;
                        pm.push(self.table.pmf(k));
                        // The image of the tile is bounded by that of its border texels; each
                        // contributes its corners.
                        if self.table.pmf(k) > 0.0
                            && (i == i0 || i + 1 == i1 || j == j0 || j + 1 == j1)
                        {
                            for (u0, u1) in
                                [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)]
                            {
                                corners.push(self.world_direction(k, self.texel_point(k, u0, u1)));
                            }
                        }
                    }
                }
                let w: f64 = pm.iter().sum();
                let cap = if corners.is_empty() || corners.iter().any(|c| !c.is_finite()) {
                    (DVec3::Z, PI)
                } else {
                    let c = corners.iter().copied().sum::<DVec3>().normalize_or_zero();
                    if c == DVec3::ZERO {
                        (DVec3::Z, PI)
                    } else {
                        // The largest angle to a corner, plus the largest angle between
                        // corners (the boundary between sampled corners bulges by at most a
                        // texel).
                        let r = corners
                            .iter()
                            .map(|d| c.dot(*d).clamp(-1.0, 1.0).acos())
                            .fold(0.0, f64::max);
                        (c, (2.0 * r + 1e-9).min(PI))
                    }
                };
                (w, cap, AliasTable::new(&pm))
            })
            .collect();
        let mut tiles = Tiles {
            side,
            nx,
            ..Tiles::default()
        };
        for (w, cap, inner) in per_tile {
            tiles.weight.push(w);
            tiles.cap.push(cap);
            tiles.inner.push(inner);
        }
        tiles
    }

    /// The tile probabilities for a receiver with unit world normal `n`: `W_t` times the
    /// largest cosine the tile's cap can have with n ([`cos_bound`], 0 for a cap wholly below
    /// the horizon), floored at [`HORIZON_FLOOR`] (module docs). `None` for a table without
    /// tiles ([`MAX_TILES`]).
    pub fn receiver_tiles(&self, n: DVec3) -> Option<ReceiverTiles> {
        ReceiverTiles::new(
            self.tiles
                .weight
                .iter()
                .zip(&self.tiles.cap)
                .map(|(&wt, &(c, r))| {
                    let (sin_r, cos_r) = r.sin_cos();
                    wt * cos_bound(n, c, cos_r, sin_r).max(HORIZON_FLOOR)
                }),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::tex;
    use super::*;
    use crate::prepare::texture::Filter;

    /// Tiles: `tile_of` and `texel_of` are inverse, the tile weights sum to 1, each tile's
    /// inner table gives its texels' probabilities over the tile's weight, and every texel's
    /// corners and centre (world directions) lie in its tile's cap — for maps whose size is not
    /// a multiple of the tile side, and a cross (tiles inside faces). A receiver's product puts
    /// (almost) nothing on tiles wholly below its horizon.
    #[test]
    fn tiles_partition_the_texels_and_their_caps_hold_them() {
        for (format, w, h) in [
            (DomeFormat::LatLong, 300, 150),
            (DomeFormat::Cross, 192, 256),
            (DomeFormat::Angular, 130, 130),
            (DomeFormat::MirroredBall, 129, 97),
        ] {
            let rgb: Vec<[f32; 3]> = (0..w * h)
                .map(|k| [1.0 + (k % 7) as f32, 0.5, (k % 3) as f32])
                .collect();
            let t = EnvTable::new(&tex(w, h, rgb, format, Filter::Bilinear)).unwrap();
            let tl = &t.tiles;
            assert!(tl.side > 1, "{format:?}: side {}", tl.side);
            if format == DomeFormat::Cross {
                assert_eq!((w as u32 / 3) % tl.side, 0);
            }
            let total: f64 = tl.weight.iter().sum();
            assert!((total - 1.0).abs() < 1e-9, "{format:?}: {total}");
            for k in 0..w * h {
                let (tile, local) = t.tile_of(k);
                assert_eq!(t.texel_of(tile, local), k);
                if t.table.pmf(k) > 0.0 {
                    let inner = tl.inner[tile].as_ref().unwrap();
                    let want = t.table.pmf(k) / tl.weight[tile];
                    assert!((inner.pmf(local) - want).abs() <= 1e-12 * want.max(1e-300) + 1e-15);
                    let (c, r) = tl.cap[tile];
                    for (u0, u1) in [
                        (0.0, 0.0),
                        (1.0, 0.0),
                        (0.0, 1.0),
                        (1.0, 1.0),
                        (0.5, 0.5),
                        (0.3, 0.8),
                    ] {
                        let d = t.world_direction(k, t.texel_point(k, u0, u1));
                        let a = c.dot(d).clamp(-1.0, 1.0).acos();
                        assert!(
                            a <= r + 1e-9,
                            "{format:?}: texel {k} at {a} outside cap {r}"
                        );
                    }
                }
            }
            let n = DVec3::new(0.2, 0.9, -0.1).normalize();
            let rt = t.receiver_tiles(n).unwrap();
            let below: f64 = (0..tl.weight.len())
                .filter(|&i| {
                    let (c, r) = tl.cap[i];
                    n.dot(c).clamp(-1.0, 1.0).acos() - r >= PI / 2.0
                })
                .map(|i| rt.pmf(i))
                .sum();
            // Tiles below the horizon keep only the floor: a fraction ≤ 1e-3 of the draws here.
            assert!(
                below > 0.0 && below < 1e-3,
                "{format:?}: {below} below the horizon"
            );
        }
    }
}
