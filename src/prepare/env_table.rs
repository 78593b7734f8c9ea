//! A textured dome's importance table (DESIGN.md §9 S2 "dome"): one weight per texel of the
//! image sheet, an alias table over them, and the per-texel geometry that the samplers of both
//! backends share (where a texel lies in its format's chart, the chart → dome-direction map and
//! its Jacobian). The CPU sampler is `src/cpu/sample/dome.rs`.
//!
//! **Charts.** A texel is sampled uniformly in its format's chart (pbrt-v4's image infinite
//! light does the same in its equal-area square; here in the format's own sheet):
//! - latlong and cubeMapVerticalCross: pixel coordinates `q = (x, y)` (§6 D1: texel (i, j) is
//!   `[i, i+1) × [j, j+1)`);
//! - mirroredBall and angular: the image point `q = (a, b)`, `a = 2s − 1`, `b = 1 − 2t` (§6 D3,
//!   D4), so that the rim is the unit circle whatever the image's aspect (a non-square image
//!   holds the inscribed ellipse, §6 D3). A texel is the rectangle `[a₀, a₁] × [b₀, b₁]` with
//!   `a₀ = 2i/W − 1`, `b₁ = 1 − 2j/H`; only its part inside the unit disk is ever looked up.
//!
//! **Rim texels (disk formats).** A texel the rim crosses is sampled exactly inside texel ∩ disk
//! without rejection: `a` uniform on the texel's a-range where the disk's chord meets its b-range
//! (`|a| < √(1 − m²)`, m the least `|b|` of the texel), then `b` uniform on the chord
//! `[max(b₀, −√(1−a²)), min(b₁, √(1−a²))]`. The density in `q` is `1 / (L_a · c(a))` (L_a the
//! a-range's length, c(a) the chord's), which is `1/area` for a texel wholly inside. Every point
//! of texel ∩ open disk is reachable and no point outside the disk is ever produced.
//!
//! **Weights** (§9 S2): the Rec. 709 luminance (0.2126, 0.7152, 0.0722) of the filtered
//! texture's mean over the texel's footprint × the texel's solid angle. The mean of §6 D1's
//! bilinear reconstruction over texel i of one axis is `(T[i−1] + 6·T[i] + T[i+1]) / 8` (the
//! neighbours' tents reach a quarter of the texel with mean weight ½, i.e. 1/8 each), with the
//! neighbours' indices wrapped or clamped exactly as the format filters (latlong columns wrap;
//! rows, the disks' both axes and each cross face's both axes clamp, the cross within its face's
//! block); nearest: the texel itself. The 2-D mean is the separable product.
//! - **Zero-luminance colours and signs.** The luminance is taken of the channels' absolute
//!   values (`Y(|r|, |g|, |b|)`, all coefficients positive). The loader's images are finite and
//!   non-negative (`Image::sanitize`), where this is the plain luminance of the mean; for an
//!   image built in memory with a negative component (whose luminance could be 0 with a
//!   non-zero colour, e.g. (1, −0.297, 0)), it still gives a positive weight. Since the blend's
//!   weights are positive, the weight is > 0 exactly when some texel the filter reaches from the
//!   footprint is non-zero in some channel, hence wherever the filtered radiance is not 0.
//! - **Solid angle**: the texel's **world** solid angle (dome solid angle × §6 D1's Jacobian
//!   `|det A| / |A_eff d|³`), by a 2 × 2 Gauss–Legendre rule over the texel's chart (over texel ∩
//!   disk through the parametrisation above for rim texels). The nodes are interior, so it is
//!   positive for every texel that meets the domain; only the weight's accuracy, never the pdf's,
//!   depends on the rule. World rather than dome solid angle makes the texel probabilities
//!   follow the radiance under a non-conformal frame too (identical under a rotation).
//! - Texels wholly outside a disk format's rim, and the cross's six non-face blocks, get 0.

use super::blackbody::REC709_LUMA;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::alias::AliasTable;
use super::texture::{
    CROSS_FACES, DomeFormat, DomeFrame, Filter, Image, PreparedTexture, ball_dir, cross_face_basis,
};

mod tiles;

pub use tiles::{HORIZON_FLOOR, ReceiverTiles, Tiles};

const PI: f64 = std::f64::consts::PI;

/// A textured dome's importance table and texel geometry (module docs).
#[derive(Clone, Debug)]
pub struct EnvTable {
    /// One cell per texel of the sheet, `k = j·width + i` (row j from the top, §6 D1).
    pub table: AliasTable,
    pub width: u32,
    pub height: u32,
    pub format: DomeFormat,
    /// World ↔ dome (§6 D1), as the texture's.
    pub frame: DomeFrame,
    /// Cross: the face stored in block (column, row), `row·3 + column`; `u8::MAX` for none.
    faces: [u8; 12],
    /// The texels grouped in tiles, for the product with a receiver's cosine
    /// ([`EnvTable::receiver_tiles`]).
    pub tiles: Tiles,
}

impl EnvTable {
    /// The table of a dome's texture; `None` when the filtered texture is 0 everywhere (the dome
    /// emits nothing, and any sampler is as good), or a cross whose size is not 3N × 4N.
    pub fn new(tex: &PreparedTexture) -> Option<EnvTable> {
        let img = &tex.image;
        let (w, h) = (img.width, img.height);
        if w == 0 || h == 0 || w * h > u32::MAX as usize {
            return None;
        }
        if tex.format == DomeFormat::Cross && (w % 3 != 0 || h % 4 != 0 || w / 3 != h / 4) {
            return None;
        }
        let mut faces = [u8::MAX; 12];
        for (f, face) in CROSS_FACES.iter().enumerate() {
            faces[face.3[1] as usize * 3 + face.3[0] as usize] = f as u8;
        }
        let mut t = EnvTable {
            table: AliasTable::new(&[1.0])?,
            width: w as u32,
            height: h as u32,
            format: tex.format,
            frame: tex.frame,
            faces,
            tiles: Tiles::default(),
        };
        let lum = footprint_luminance(img, tex.format, tex.filter);
        let weights: Vec<f64> = lum
            .par_iter()
            .enumerate()
            .map(|(k, y)| if *y > 0.0 { y * t.solid_angle(k) } else { 0.0 })
            .collect();
        t.table = AliasTable::new(&weights)?;
        t.tiles = t.build_tiles();
        Some(t)
    }

    /// Whether the format's chart is the disk image point (a, b) (mirroredBall, angular).
    #[inline]
    fn is_disk(&self) -> bool {
        matches!(self.format, DomeFormat::MirroredBall | DomeFormat::Angular)
    }

    /// The cross face stored in block (column, row), if any (§6 D5's table).
    #[inline]
    pub fn face_at_block(&self, col: u32, row: u32) -> Option<u32> {
        if col > 2 || row > 3 {
            return None;
        }
        let f = self.faces[(row * 3 + col) as usize];
        (f != u8::MAX).then_some(f as u32)
    }

    /// The cross face texel k lies on (0 off the faces and for the other formats).
    #[inline]
    fn face_of(&self, k: usize) -> u32 {
        let n = self.width / 3;
        let (i, j) = (
            (k % self.width as usize) as u32,
            (k / self.width as usize) as u32,
        );
        self.face_at_block(i / n, j / n).unwrap_or(0)
    }

    /// A disk texel's rectangle in (a, b): `(a₀, a₁, b₀, b₁)` (module docs).
    #[inline]
    fn disk_rect(&self, k: usize) -> (f64, f64, f64, f64) {
        let (w, h) = (self.width as f64, self.height as f64);
        let (i, j) = (
            (k % self.width as usize) as f64,
            (k / self.width as usize) as f64,
        );
        (
            2.0 * i / w - 1.0,
            2.0 * (i + 1.0) / w - 1.0,
            1.0 - 2.0 * (j + 1.0) / h,
            1.0 - 2.0 * j / h,
        )
    }

    /// A disk texel's sampled a-range (where the disk's chords meet its b-range), module docs.
    #[inline]
    fn a_range(r: (f64, f64, f64, f64)) -> (f64, f64) {
        let (a0, a1, b0, b1) = r;
        let m = if b0 <= 0.0 && b1 >= 0.0 {
            0.0
        } else {
            b0.abs().min(b1.abs())
        };
        let hm = (1.0 - m * m).max(0.0).sqrt();
        (a0.max(-hm), a1.min(hm))
    }

    /// How well f32 holds the density of disk texel k at chart point `q` (`f64::INFINITY` for
    /// latlong and cross tables): the chord's length `c(a)` through the texel times
    /// `h/|a|`, h = √(1 − a²) the rim's height at a, in chart units. The density is
    /// `1 / (L_a · c(a))`, and where the rim bounds the chord, an error δa in a moves its end
    /// by `|a|/h · δa`: the density's relative error is δa over this margin. Near the rim it
    /// shrinks to 0 (the chord to 0, and the rim's slope to infinity at a = ±1).
    #[cfg(any(test, feature = "testkit"))]
    pub fn rim_margin(&self, k: usize, q: DVec2) -> f64 {
        if !self.is_disk() {
            return f64::INFINITY;
        }
        let r = self.disk_rect(k);
        let (lo, hi) = Self::chord(r, q.x);
        let h = (1.0 - q.x * q.x).max(0.0).sqrt();
        let c = (hi - lo).max(0.0);
        if q.x == 0.0 { c } else { c * h / q.x.abs() }
    }

    /// The chord of the disk at `a` within the texel's b-range.
    #[inline]
    fn chord(r: (f64, f64, f64, f64), a: f64) -> (f64, f64) {
        let h = (1.0 - a * a).max(0.0).sqrt();
        (r.2.max(-h), r.3.min(h))
    }

    /// The point of texel k's chart drawn by the uniforms `(u0, u1)` ∈ [0, 1)²: uniform in the
    /// texel (latlong, cross), uniform in a then in the chord inside the disk (disks, module
    /// docs); never outside the disk. Its density in the chart is [`Self::chart_density`].
    #[inline]
    pub fn texel_point(&self, k: usize, u0: f64, u1: f64) -> DVec2 {
        if !self.is_disk() {
            let (i, j) = (k % self.width as usize, k / self.width as usize);
            return DVec2::new(i as f64 + u0, j as f64 + u1);
        }
        let r = self.disk_rect(k);
        let (xa, xb) = Self::a_range(r);
        let mut a = xa + (xb - xa) * u0;
        let (mut lo, mut hi) = Self::chord(r, a);
        if !(hi > lo) {
            // Only at an end of the a-range where the rim just touches the texel's b-range (a
            // set of measure zero): the middle of the a-range, where the chord is open.
            a = 0.5 * (xa + xb);
            (lo, hi) = Self::chord(r, a);
        }
        DVec2::new(a, lo + (hi - lo) * u1)
    }

    /// The density, per unit chart area, with which [`Self::texel_point`] draws `q` given texel
    /// k: 1 per pixel² (latlong, cross), `1 / (L_a · c(a))` per unit (a, b) area (disks); 0
    /// where the texel's draw never goes.
    #[inline]
    pub fn chart_density(&self, k: usize, q: DVec2) -> f64 {
        if !self.is_disk() {
            return 1.0;
        }
        let r = self.disk_rect(k);
        let (xa, xb) = Self::a_range(r);
        let (lo, hi) = Self::chord(r, q.x);
        if xb > xa && hi > lo {
            1.0 / ((xb - xa) * (hi - lo))
        } else {
            0.0
        }
    }

    /// The dome direction at chart point `q` of texel k (§6 D2–D5's inverse maps).
    #[inline]
    pub fn chart_direction(&self, k: usize, q: DVec2) -> DVec3 {
        match self.format {
            // §6 D2 inverted: φ = π − 2πx/W, θ = πy/H, d = (sin θ sin φ, cos θ, sin θ cos φ).
            DomeFormat::LatLong => {
                let phi = PI - 2.0 * PI * q.x / self.width as f64;
                let (st, ct) = (PI * q.y / self.height as f64).sin_cos();
                let (sp, cp) = phi.sin_cos();
                DVec3::new(st * sp, ct, st * cp)
            }
            // §6 D3.
            DomeFormat::MirroredBall => ball_dir(q.x, q.y),
            // §6 D4: d = (a·sin(πr)/r, b·sin(πr)/r, cos πr); sin(πr) as sin(π(1 − r)) past
            // r = ½, which keeps its relative precision near the rim (−Z).
            DomeFormat::Angular => {
                let r = q.length().min(1.0);
                let sin_pr = if r > 0.5 {
                    (PI * (1.0 - r)).sin()
                } else {
                    (PI * r).sin()
                };
                let k = if r < 1e-8 {
                    PI * (1.0 - (PI * r).powi(2) / 6.0)
                } else {
                    sin_pr / r
                };
                DVec3::new(q.x * k, q.y * k, (PI * r).cos())
            }
            // §6 D5: d ∝ F + a·R + b·U with a = 2s_f − 1, b = 1 − 2t_f in the face's block.
            DomeFormat::Cross => {
                let n = self.width as f64 / 3.0;
                let (f, r, u, blk) = cross_face_basis(self.face_of(k));
                let a = 2.0 * (q.x - blk.x * n) / n - 1.0;
                let b = 1.0 - 2.0 * (q.y - blk.y * n) / n;
                (f + a * r + b * u).normalize()
            }
        }
    }

    /// Dome solid angle per unit chart area at dome direction `d` of texel k, written in `d`
    /// so that the sampler and the pdf evaluate it alike:
    /// - latlong: `sin θ · (2π/W)(π/H)` per pixel², `sin θ = √(dx² + dz²)`;
    /// - mirroredBall: 4 per unit (a, b) area (the mirror ball is equal-area: π ↦ 4π);
    /// - angular: `π sin(πr)/r` per unit (a, b) area (polar coordinates, `dθ = π dr`), with
    ///   `sin(πr) = sin θ = √(dx² + dy²)` and `r = θ/π`;
    /// - cross: `(2/N)² / |F + aR + bU|³ = (2/N)² (d·F)³` per pixel² (gnomonic; `v·F = 1`).
    #[inline]
    pub fn chart_jacobian(&self, k: usize, d: DVec3) -> f64 {
        match self.format {
            DomeFormat::LatLong => {
                (d.x * d.x + d.z * d.z).sqrt()
                    * (2.0 * PI / self.width as f64)
                    * (PI / self.height as f64)
            }
            DomeFormat::MirroredBall => 4.0,
            DomeFormat::Angular => {
                let rho = (d.x * d.x + d.y * d.y).sqrt();
                let r = rho.atan2(d.z) / PI;
                if r < 1e-300 { PI * PI } else { PI * rho / r }
            }
            DomeFormat::Cross => {
                let f = cross_face_basis(self.face_of(k)).0;
                let n = self.width as f64 / 3.0;
                (2.0 / n).powi(2) * d.dot(f).powi(3)
            }
        }
    }

    /// Texel k's world solid angle by a 2 × 2 Gauss–Legendre rule over its chart (module docs);
    /// 0 for a texel outside the domain.
    fn solid_angle(&self, k: usize) -> f64 {
        // 2-point Gauss–Legendre on [0, 1]: nodes ½ ∓ 1/(2√3), weights ½.
        const NODES: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];
        let mut sum = 0.0;
        if self.format == DomeFormat::Cross {
            let (i, j) = (
                (k % self.width as usize) as u32,
                (k / self.width as usize) as u32,
            );
            let n = self.width / 3;
            if self.face_at_block(i / n, j / n).is_none() {
                return 0.0;
            }
        }
        let la = if self.is_disk() {
            let (xa, xb) = Self::a_range(self.disk_rect(k));
            if !(xb > xa) {
                return 0.0;
            }
            xb - xa
        } else {
            1.0
        };
        for u0 in NODES {
            for u1 in NODES {
                let q = self.texel_point(k, u0, u1);
                // The chart area the draw's unit square maps onto, per unit square, is
                // 1/density: L_a·c(a) for the disks, 1 pixel² otherwise.
                let area = if self.is_disk() {
                    let (lo, hi) = Self::chord(self.disk_rect(k), q.x);
                    la * (hi - lo).max(0.0)
                } else {
                    1.0
                };
                let d = self.chart_direction(k, q);
                let l = (self.frame.a_eff * d).length();
                sum += 0.25 * area * self.chart_jacobian(k, d) * self.frame.det_abs / (l * l * l);
            }
        }
        sum
    }
}

/// Per texel: the Rec. 709 luminance of the absolute values of the filtered texture's mean over
/// the texel's footprint (module docs), 0 off the cross's faces.
fn footprint_luminance(img: &Image, format: DomeFormat, filter: Filter) -> Vec<f64> {
    let (w, h) = (img.width, img.height);
    let y: Vec<f64> = img
        .rgb
        .iter()
        .map(|t| (0..3).map(|c| REC709_LUMA[c] * (t[c] as f64).abs()).sum())
        .collect();
    if filter == Filter::Nearest {
        return match format {
            DomeFormat::Cross => mask_cross(y, w),
            _ => y,
        };
    }
    // The blocks filtered independently: the whole sheet, or each cross face (§6 D5).
    let blocks: Vec<(usize, usize, usize, usize, bool)> = match format {
        DomeFormat::LatLong => vec![(0, 0, w, h, true)],
        DomeFormat::MirroredBall | DomeFormat::Angular => vec![(0, 0, w, h, false)],
        DomeFormat::Cross => {
            let n = w / 3;
            CROSS_FACES
                .iter()
                .map(|f| (f.3[0] as usize * n, f.3[1] as usize * n, n, n, false))
                .collect()
        }
    };
    let mut out = vec![0.0; w * h];
    // One axis of [1, 6, 1]/8 with the block's wrap (columns of a latlong) or clamp.
    let index = |k: isize, n: usize, wrap: bool| -> usize {
        if wrap {
            k.rem_euclid(n as isize) as usize
        } else {
            k.clamp(0, n as isize - 1) as usize
        }
    };
    for (x0, y0, bw, bh, wrap_x) in blocks {
        let mut horiz = vec![0.0; bw * bh];
        for j in 0..bh {
            for i in 0..bw {
                let at = |di: isize| y[(y0 + j) * w + x0 + index(i as isize + di, bw, wrap_x)];
                horiz[j * bw + i] = (at(-1) + 6.0 * at(0) + at(1)) / 8.0;
            }
        }
        for j in 0..bh {
            for i in 0..bw {
                let at = |dj: isize| horiz[index(j as isize + dj, bh, false) * bw + i];
                out[(y0 + j) * w + x0 + i] = (at(-1) + 6.0 * at(0) + at(1)) / 8.0;
            }
        }
    }
    out
}

/// Zeroes the texels of the cross's six non-face blocks.
fn mask_cross(mut y: Vec<f64>, w: usize) -> Vec<f64> {
    let n = w / 3;
    for (k, v) in y.iter_mut().enumerate() {
        let (col, row) = ((k % w) / n, (k / w) / n);
        if !CROSS_FACES
            .iter()
            .any(|f| f.3[0] as usize == col && f.3[1] as usize == row)
        {
            *v = 0.0;
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare::texture::st_to_direction;
    use std::sync::Arc;

    pub(super) fn tex(
        w: usize,
        h: usize,
        rgb: Vec<[f32; 3]>,
        format: DomeFormat,
        filter: Filter,
    ) -> PreparedTexture {
        PreparedTexture {
            image: Arc::new(Image::from_rgb(w, h, rgb, "t.exr").unwrap()),
            format,
            frame: DomeFrame::identity(),
            filter,
            irradiance: Default::default(),
        }
    }

    /// One bright texel spreads [1, 6, 1]/8 per axis into its neighbours under bilinear, with
    /// the format's wrap (latlong columns) or clamp; nearest keeps it in place.
    #[test]
    fn footprint_weights_follow_the_filter_and_the_wrap() {
        let (w, h) = (8, 4);
        let mut rgb = vec![[0.0f32; 3]; w * h];
        rgb[w] = [0.0, 1.0, 0.0]; // texel (0, 1): column 0 wraps to column 7 on a latlong
        let y = footprint_luminance(
            &Image::from_rgb(w, h, rgb.clone(), "t").unwrap(),
            DomeFormat::LatLong,
            Filter::Bilinear,
        );
        let g = 0.7152;
        let at = |i: usize, j: usize| y[j * w + i];
        assert!((at(0, 1) - g * 36.0 / 64.0).abs() < 1e-15);
        assert!((at(7, 1) - g * 6.0 / 64.0).abs() < 1e-15);
        assert!((at(0, 0) - g * 6.0 / 64.0).abs() < 1e-15 && (at(1, 0) - g / 64.0).abs() < 1e-15);
        assert!((at(1, 2) - g / 64.0).abs() < 1e-15 && (at(0, 2) - g * 6.0 / 64.0).abs() < 1e-15);
        assert!((at(7, 0) - g / 64.0).abs() < 1e-15);
        assert_eq!(at(2, 1), 0.0);
        assert_eq!(at(0, 3), 0.0);
        // Angular: columns clamp, so column 7 gets nothing and column 0 keeps 7/8 across.
        let y = footprint_luminance(
            &Image::from_rgb(w, h, rgb.clone(), "t").unwrap(),
            DomeFormat::Angular,
            Filter::Bilinear,
        );
        assert_eq!(y[w + 7], 0.0);
        assert!((y[w] - g * 42.0 / 64.0).abs() < 1e-15);
        let y = footprint_luminance(
            &Image::from_rgb(w, h, rgb, "t").unwrap(),
            DomeFormat::LatLong,
            Filter::Nearest,
        );
        assert_eq!(y.iter().filter(|v| **v > 0.0).count(), 1);
        // A colour of zero luminance (a negative channel) still weighs.
        let rgb = vec![[1.0f32, -0.2126 / 0.7152, 0.0]; 2];
        let y = footprint_luminance(
            &Image::from_rgb(2, 1, rgb, "t").unwrap(),
            DomeFormat::LatLong,
            Filter::Nearest,
        );
        assert!(y.iter().all(|v| *v > 0.4));
    }

    /// A black map has no table (the dome emits nothing); one-texel axes still sample.
    #[test]
    fn black_and_tiny_maps() {
        for format in DomeFormat::ALL {
            let (w, h) = if format == DomeFormat::Cross {
                (3, 4)
            } else {
                (2, 1)
            };
            let black = tex(w, h, vec![[0.0; 3]; w * h], format, Filter::Bilinear);
            assert!(EnvTable::new(&black).is_none(), "{format:?}");
            for filter in [Filter::Bilinear, Filter::Nearest] {
                let t = EnvTable::new(&tex(w, h, vec![[0.5; 3]; w * h], format, filter)).unwrap();
                let mut rng = crate::synthetic::Rng::new(3);
                for _ in 0..100 {
                    let (k, v) = (t.table.pick(rng.f64(), rng.f64()), rng.f64());
                    let q = t.texel_point(k, v, rng.f64());
                    let d = t.chart_direction(k, q);
                    assert!((d.length() - 1.0).abs() < 1e-12 && t.chart_density(k, q) > 0.0);
                }
            }
        }
    }

    /// Cross: the filter stays within a face (clamped at its edges), and off-face blocks get 0.
    #[test]
    fn cross_weights_stay_in_their_face() {
        let (w, h) = (6, 8);
        let mut rgb = vec![[1.0f32; 3]; w * h];
        rgb[2 * w + 1] = [0.0; 3]; // inside +X's block (0, 1), its top-right texel
        let t = EnvTable::new(&tex(w, h, rgb, DomeFormat::Cross, Filter::Bilinear)).unwrap();
        assert_eq!((t.format, t.width, t.height), (DomeFormat::Cross, 6, 8));
        for k in 0..w * h {
            let (i, j) = (k % w, k / w);
            let on = t.face_at_block(i as u32 / 2, j as u32 / 2).is_some();
            assert_eq!(t.table.pmf(k) > 0.0, on, "texel ({i},{j})");
        }
    }

    /// Disk formats: texels wholly outside the rim weigh 0; texels the rim crosses weigh
    /// their part inside; the solid angles sum to 4π.
    #[test]
    fn disk_texels_outside_the_rim_weigh_nothing_and_solid_angles_sum_to_4pi() {
        for format in [DomeFormat::MirroredBall, DomeFormat::Angular] {
            for (w, h) in [(8, 8), (9, 6)] {
                let t = EnvTable::new(&tex(w, h, vec![[1.0; 3]; w * h], format, Filter::Nearest))
                    .unwrap();
                let mut total = 0.0;
                for k in 0..w * h {
                    let (a0, a1, b0, b1) = t.disk_rect(k);
                    let near = DVec2::new(0.0f64.clamp(a0, a1), 0.0f64.clamp(b0, b1)).length();
                    let sa = t.solid_angle(k);
                    assert_eq!(sa > 0.0, near < 1.0, "{format:?} {w}×{h} texel {k}");
                    assert_eq!(t.table.pmf(k) > 0.0, near < 1.0);
                    total += sa;
                }
                // A 2 × 2 rule on the rim texels' √ edges: a few per cent at most.
                assert!(
                    (total / (4.0 * PI) - 1.0).abs() < 0.05,
                    "{format:?}: {total}"
                );
                // Samples stay inside the rim and inside their texel.
                let mut rng = crate::synthetic::Rng::new(5);
                for _ in 0..20000 {
                    let (k, v) = (t.table.pick(rng.f64(), rng.f64()), rng.f64());
                    let q = t.texel_point(k, v, rng.f64());
                    let (a0, a1, b0, b1) = t.disk_rect(k);
                    assert!(q.length() <= 1.0, "{q}");
                    assert!(q.x >= a0 && q.x <= a1 && q.y >= b0 && q.y <= b1);
                    assert!(t.chart_density(k, q) > 0.0);
                }
            }
        }
    }

    /// The chart → direction map agrees with §6's inverse maps (prepare::texture's) and the
    /// Jacobian with a finite-difference area of the map.
    #[test]
    fn chart_maps_agree_with_the_format_maps() {
        let mut rng = crate::synthetic::Rng::new(9);
        for (format, w, h) in [
            (DomeFormat::LatLong, 8, 4),
            (DomeFormat::MirroredBall, 8, 8),
            (DomeFormat::Angular, 8, 6),
            (DomeFormat::Cross, 6, 8),
        ] {
            let t =
                EnvTable::new(&tex(w, h, vec![[1.0; 3]; w * h], format, Filter::Bilinear)).unwrap();
            for _ in 0..2000 {
                let (k, v) = (t.table.pick(rng.f64(), rng.f64()), rng.f64());
                let q = t.texel_point(k, v, rng.f64());
                let d = t.chart_direction(k, q);
                // To the sheet's (s, t).
                let st = if t.is_disk() {
                    DVec2::new(0.5 * (q.x + 1.0), 0.5 * (1.0 - q.y))
                } else {
                    DVec2::new(q.x / w as f64, q.y / h as f64)
                };
                let e = st_to_direction(format, st).unwrap();
                assert!((d - e).length() < 1e-12, "{format:?} {q}: {d} vs {e}");
                // Jacobian: |∂d/∂q₁ × ∂d/∂q₂| by central differences.
                let hq = 1e-6;
                let f = |dq: DVec2| t.chart_direction(k, q + dq);
                let dx = (f(DVec2::new(hq, 0.0)) - f(DVec2::new(-hq, 0.0))) / (2.0 * hq);
                let dy = (f(DVec2::new(0.0, hq)) - f(DVec2::new(0.0, -hq))) / (2.0 * hq);
                let fd = dx.cross(dy).length();
                let j = t.chart_jacobian(k, d);
                if q.length() < 0.999 || !t.is_disk() {
                    assert!((fd / j - 1.0).abs() < 1e-5, "{format:?} {q}: {fd} vs {j}");
                }
            }
        }
    }
}
