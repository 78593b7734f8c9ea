//! Latlong domes under a conformal frame (rotation × uniform scale, so that `w` is constant):
//! the separable moment factors of the pieces (dome.rs "Moments"), and the **sweep**, one
//! receiver's `E(n)` straight from them without the tile tables.
//!
//! The tables (tables.rs) cost one moment and one bounding cap per piece, built once: about
//! 0.15 s and 80 MB for a 2048 × 1024 map, then a walk over their tiles per normal. A falloff map
//! of a plane, the job people run most, asks for one normal: the tables' build was most of
//! that map's time (BENCHMARKS.md "The jobs people run"). The sweep computes the same sum,
//! `E = Σ_lit m·V + Σ_crossed (exact clipped integral)`, in one pass over the pieces:
//!
//! - In dome space `d = (sin θ sin φ, cos θ, sin θ cos φ)` (§6 D2), so on the horizon's side
//!   `m·d = a cos θ + ρ sin θ cos(φ − φ₀)` with `a = m_y`, `ρ = |(m_x, m_z)|`,
//!   `φ₀ = atan2(m_x, m_z)`. On a piece, `sin θ ≥ 0`, so `m·d` is smallest where `cos(φ − φ₀)`
//!   is smallest over the piece's columns (`c_min`) and largest where it is largest
//!   (`c_max`); each is a sinusoid `A cos θ + B sin θ` in θ, positive on arcs of length π, and a
//!   piece's θ span is at most 0.25 rad (pieces.rs `MAX_PIECE_ANGLE`), so it is positive on the
//!   whole span when it is at both ends. A piece is therefore wholly lit when
//!   `a cos θ + ρ sin θ c_min > ε` at both of its row's ends, wholly dark when
//!   `a cos θ + ρ sin θ c_max < −ε` at both, and crossed otherwise. The margin `ε = 1e-12 |m|`
//!   only sends pieces to the exact clipped integral that would not need it.
//! - A lit piece adds `m·V` with `V` the piece's moment from the per-axis factors, the very
//!   moment the tables sum (`DomeIrradiance::moment`): four texels times a column factor times
//!   a row factor. A crossed piece is integrated exactly at the horizon
//!   (`DomeIrradiance::crossed`, the tables' own routine).
//!
//! Per normal this is O(W·H) multiply-adds with no trigonometry but `φ₀`'s (fewer since the
//! lit and dark pieces are found as runs, "Runs" below), plus the crossed
//! pieces that the tables' walk integrates too; the tables cost O(W·H) `sin_cos` and 80 MB once,
//! then O(tiles) per normal. Measured on luxtest's 2048 × 1024 map (release, 2 cores, random
//! normals): about 23 ms per normal for the sweep, 26 ms for the walk, both mostly the crossed
//! pieces, and 0.15 s for the build. So `DomeIrradiance::irradiance` sweeps wherever it can.
//! The rows are summed in order, so the result does not depend on the thread count.
//!
//! # Runs
//!
//! In one row piece the test for "wholly lit" is monotone in `c_min` (`a cos θ + ρ sin θ c`
//! grows with `c` because `sin θ ≥ 0`), and `c_min` of column piece `i` is the cosine of the
//! larger distance of its two ends from `φ₀`: around the circle of columns it rises to a
//! peak at `φ₀` and falls to a trough at `φ₀ + π` (the larger of a quasi-convex function's
//! values at consecutive boundaries is quasi-convex), so the wholly lit pieces are one
//! cyclic run through the peak, and likewise (with `c_max`) the pieces not wholly dark. The
//! sweep finds each run's ends by bisection on either side of the peak (`Runs`, O(log W) tests
//! a row) and integrates exactly the pieces between the two runs' ends, the crossed ones. The
//! lit run's sum `Σ m·V` is, per texel row `t` of the row piece, `m·` the sum of the column
//! factors `Q_t(i) = Σ_a L(i_a, t) · cols[i][a]` over the run; with several normals to
//! integrate, block sums of `Q_t` (`RunPrefix`, every 32 columns at least: 19 MB for
//! 4096 × 2048) make that two lookups and at most two blocks of pieces per texel row, so the
//! lit pieces no longer cost O(W·H) a normal; one normal (a falloff map of a plane) sums them
//! piece by piece. The same pieces and moments as the tables', summed in another order
//! (within 1.3e-15 of `π max L`, the tests below).
//!
//! # Crossed pieces
//!
//! A piece the horizon crosses was integrated by the tables' general clip routine
//! (`DomeIrradiance::crossed`: adaptive, with the clip's roots found per inner line), most of
//! the sweep's time once the runs had removed the lit pieces' cost. In a latlong piece under a
//! conformal frame it has a closed form across the columns
//! (`DomeIrradiance::crossed_piece`): at fixed θ the filtered map is linear in φ on the piece,
//! `m·d = a cos θ + ρ sin θ cos ψ` (`ψ = φ − φ₀`) is positive on the arc `|ψ| < α`,
//! `cos α = −a cos θ / (ρ sin θ)`, and `∫ (ℓ0 + ℓ1 v)(A + B cos ψ) dψ = A(ℓ0 v + ℓ1 v²/2) +
//! B(ℓ0 sin ψ + ℓ1 (v sin ψ + cos ψ))` between the arc's and the piece's ends, whose sines and
//! cosines are `(±sin α, cos α)` or the piece's own. Across the rows it is Gauss–Legendre
//! (8 nodes) on the parts of the piece's θ span between the points where the integrand is not
//! smooth: where an arc end passes a column end of the piece, and the horizon's two
//! tangencies, about the nearer of which the rule runs in `σ = √|θ − θ_t|` (the arc's
//! half-width has a square-root branch point there), as the row rule does for a whole row.
//! Against the tables' routine within 1.3e-15 of `π max L` over the tests' 3,172 cases (pieces
//! of 0.25 rad on 1 × 1 maps, grazing normals, one-texel maps); 6 nodes missed by 2.7e-12 and
//! 3 by 7e-7 there (mutations of the test).
//!
//! # The row rule
//!
//! [`DomeIrradiance::irradiance_by_rows`] integrates by rows of the texture: the device path's
//! method (`cpu::irradiance::latlong_rows`, its f64 twin, which carries the derivation: exact in
//! the column angle from per-row prefix tables, Gauss–Legendre in θ between every point where
//! the integrand is not smooth). The CPU path took it at loose tolerances for many distinct
//! normals (O(W + H) a normal against the sweep's O(W·H), after 192 MB of f64 tables for
//! 2048 × 1024) until the runs and the crossed pieces' closed form made the exact sweep
//! faster (512 normals on luxtest's map: 0.92 s and 44 MB against 1.94 s and 236 MB, the
//! outputs identical in f32); it is now the tests' independent check of the device's method:
//! against the sweep it differs by 1e-15 on that map and at most 2e-9 (of `π max L`) on 1 × 1
//! to 64 × 32 maps with grazing normals, where a row spans up to 0.25 rad (the tests below).

use glam::DVec3;
use rayon::prelude::*;

mod crossed;
mod runs;

use crossed::Horizon;
pub(super) use runs::RunPrefix;
use runs::Runs;

use super::DomeIrradiance;
use super::quadrature::gl;
#[cfg(test)]
use crate::cpu::irradiance::latlong_rows::{Rows, latlong_irradiance};
#[cfg(test)]
use crate::prepare::latlong_rows;
use crate::prepare::texture::DomeFormat;
#[cfg(test)]
use crate::prepare::texture::Filter;

/// The largest f64 row tables the row rule builds: a 2048 × 1024 map's take 192 MB.
#[cfg(test)]
pub(super) const ROWS_MAX_BYTES: usize = 256 << 20;

/// The per-axis factors of a latlong map's piece moments, and the trigonometry of the pieces'
/// ends (both independent of the receiver).
pub(super) struct Axes {
    /// Per column piece and texel weight (a ∈ {0,1}): `∫ w_a(x) (sin φ, 1, cos φ) dx`.
    pub cols: Vec<[[f64; 3]; 2]>,
    /// Per row piece and texel weight (b ∈ {0,1}): `∫ w_b(y) (sin²θ, sin θ cos θ) dy`.
    pub rows: Vec<[[f64; 2]; 2]>,
    /// Per column piece: its lower φ end (at x1), its φ span, and `(sin φ, cos φ)` at the
    /// lower and at the upper end.
    col_ends: Vec<ColumnEnds>,
    /// Per row piece: `(sin θ, cos θ)` at y0 and at y1.
    row_ends: Vec<[[f64; 2]; 2]>,
}

struct ColumnEnds {
    lo: f64,
    span: f64,
    at_lo: [f64; 2],
    at_hi: [f64; 2],
}

impl Axes {
    pub(super) fn new(d: &DomeIrradiance) -> Axes {
        let pi = std::f64::consts::PI;
        let (w, h) = (d.geom.w, d.geom.h);
        let g = &d.grids[0];
        let phi = |x: f64| pi - 2.0 * pi * x / w;
        let theta = |y: f64| pi * y / h;
        // 16-point Gauss–Legendre per axis piece: exact to rounding on pieces ≤ π/8 (dome.rs).
        let cols =
            g.xs.iter()
                .map(|p| {
                    [0, 1].map(|a| {
                        gl::<3>(16, p.x0, p.x1, |x| {
                            let (w0, w1) = p.weights(x);
                            let wt = if a == 0 { w0 } else { w1 };
                            let (s, c) = phi(x).sin_cos();
                            [wt * s, wt, wt * c]
                        })
                    })
                })
                .collect();
        let rows =
            g.ys.iter()
                .map(|p| {
                    [0, 1].map(|b| {
                        gl::<2>(16, p.x0, p.x1, |y| {
                            let (w0, w1) = p.weights(y);
                            let wt = if b == 0 { w0 } else { w1 };
                            let (s, c) = theta(y).sin_cos();
                            [wt * s * s, wt * s * c]
                        })
                    })
                })
                .collect();
        let sin_cos = |t: f64| {
            let (s, c) = t.sin_cos();
            [s, c]
        };
        let col_ends =
            g.xs.iter()
                .map(|p| {
                    let (lo, hi) = (phi(p.x1), phi(p.x0));
                    ColumnEnds {
                        lo,
                        span: hi - lo,
                        at_lo: sin_cos(lo),
                        at_hi: sin_cos(hi),
                    }
                })
                .collect();
        let row_ends =
            g.ys.iter()
                .map(|p| [p.x0, p.x1].map(|y| sin_cos(theta(y))))
                .collect();
        Axes {
            cols,
            rows,
            col_ends,
            row_ends,
        }
    }
}

/// `min` and `max` of `cos(φ − φ₀)` over each column piece, `(sin φ₀, cos φ₀)` given.
fn column_range(axes: &Axes, phi0: f64, s0: f64, c0: f64) -> Vec<[f64; 2]> {
    let tau = std::f64::consts::TAU;
    let pi = std::f64::consts::PI;
    axes.col_ends
        .iter()
        .map(|e| {
            let cos = |[s, c]: [f64; 2]| c * c0 + s * s0;
            let (at_lo, at_hi) = (cos(e.at_lo), cos(e.at_hi));
            let holds = |t: f64| (t - e.lo).rem_euclid(tau) <= e.span;
            let max = if holds(phi0) { 1.0 } else { at_lo.max(at_hi) };
            let min = if holds(phi0 + pi) {
                -1.0
            } else {
                at_lo.min(at_hi)
            };
            [min, max]
        })
        .collect()
}

impl DomeIrradiance {
    pub(super) fn axes(&self) -> &Axes {
        self.axes.get_or_init(|| Axes::new(self))
    }

    /// The row rule's f64 tables, built on first use; `None` over [`ROWS_MAX_BYTES`].
    #[cfg(test)]
    pub(super) fn row_tables(&self) -> Option<&[f64]> {
        self.row_tables
            .get_or_init(|| {
                let words = latlong_rows::words_len(self.img.width, self.img.height);
                (words.saturating_mul(8) <= ROWS_MAX_BYTES).then(|| {
                    let mut data = Vec::with_capacity(words);
                    latlong_rows::tables(&self.img, self.filter, |v| v, &mut data);
                    data
                })
            })
            .as_deref()
    }

    /// `E(n)` by the row rule (module docs "The row rule"); `None` where the sweep does not
    /// apply or the tables would exceed [`ROWS_MAX_BYTES`].
    #[cfg(test)]
    pub fn irradiance_by_rows(&self, n: DVec3) -> Option<DVec3> {
        if !self.sweeps() {
            return None;
        }
        let rows = Rows {
            data: self.row_tables()?,
            width: self.img.width,
            height: self.img.height,
            bilinear: self.filter == Filter::Bilinear,
        };
        // Under a rotation times a uniform scale the dome-space integral is the world one, about
        // the dome-space normal A_effᵀ n normalised (as the kernel reads it, irradiance.wgsl).
        let m = self.frame.horizon(n);
        Some(latlong_irradiance(&rows, m / m.length()))
    }

    /// Whether [`DomeIrradiance::sweep`] applies: a latlong map under a conformal frame.
    pub(super) fn sweeps(&self) -> bool {
        self.format == DomeFormat::LatLong && self.conformal.is_some()
    }

    /// `E(n)` by the sweep (module docs): the tables' value (`irradiance_within(n, &[])`),
    /// summed in another order. `None` where it does not apply ([`DomeIrradiance::sweeps`]).
    pub fn sweep(&self, n: DVec3) -> Option<DVec3> {
        if !self.sweeps() {
            return None;
        }
        let w = self.conformal?;
        let axes = self.axes();
        let m = self.frame.horizon(n);
        let horizon = Horizon::new(m, w);
        let (a, rho) = (horizon.a, horizon.rho);
        let cos_range = column_range(axes, m.x.atan2(m.z), horizon.s0, horizon.c0);
        let eps = 1e-12 * m.length();
        let pi = std::f64::consts::PI;
        let k = w * (2.0 * pi / self.geom.w) * (pi / self.geom.h);
        let g = &self.grids[0];
        let lit_runs = Runs::new(cos_range.iter().map(|c| c[0]));
        let unlit_runs = Runs::new(cos_range.iter().map(|c| c[1]));
        let prefix = self.run_prefix.get();
        let n_cols = cos_range.len();
        // Per row: (Σ over lit pieces of m·V / k, Σ over crossed pieces of their exact part).
        let rows: Vec<(DVec3, DVec3)> = (0..g.ys.len())
            .into_par_iter()
            .map(|j| {
                let ends = axes.row_ends[j];
                let side = |c: f64| ends.map(|[s, ct]| a * ct + rho * s * c);
                // Wholly lit: m·d > ε at both row ends where cos(φ − φ₀) is least over the
                // piece; not wholly dark: not m·d < −ε at both where it is greatest. Each holds
                // on one run of columns (module docs "Runs").
                let lit = |i: usize| side(cos_range[i][0]).iter().all(|h| *h > eps);
                let unlit = |i: usize| !side(cos_range[i][1]).iter().all(|h| *h < -eps);
                let Some((ns, nl)) = unlit_runs.run(unlit) else {
                    return (DVec3::ZERO, DVec3::ZERO);
                };
                let (ls, ll) = lit_runs.run(lit).unwrap_or((ns, 0));
                // The crossed pieces: the unlit run less the lit run, on either side of it.
                let (left, right_len) = if ll == 0 {
                    (nl, 0)
                } else if nl == n_cols {
                    (0, n_cols - ll)
                } else {
                    let left = (ls + n_cols - ns) % n_cols;
                    (left, nl - left - ll)
                };
                let mut crossed = DVec3::ZERO;
                for k in 0..left {
                    crossed += self.crossed_piece(axes, &horizon, (ns + k) % n_cols, j);
                }
                for k in 0..right_len {
                    crossed += self.crossed_piece(axes, &horizon, (ls + ll + k) % n_cols, j);
                }
                let lit = if ll == 0 {
                    DVec3::ZERO
                } else {
                    self.lit_run(axes, prefix, j, ls, ll, m)
                };
                (lit, crossed)
            })
            .collect();
        let (lit, crossed) = rows
            .iter()
            .fold((DVec3::ZERO, DVec3::ZERO), |(l, c), (a, b)| {
                (l + *a, c + *b)
            });
        Some(lit * k + crossed)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use std::sync::Arc;

    use glam::{DMat3, DVec3};

    use super::*;
    use crate::prepare::texture::{DomeFrame, Image};

    /// A random HDR-like map, and one dark map with a single bright texel (a piece lit or missed
    /// whole shows there).
    pub(crate) fn image(w: usize, h: usize, seed: u64, one_texel: bool) -> Arc<Image> {
        let mut state = seed.wrapping_mul(6364136223846793005) ^ 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as f64 / (1u64 << 31) as f64) as f32
        };
        let bright = (w * h) / 3 + w / 2;
        let rgb = (0..w * h)
            .map(|i| match one_texel {
                true if i == bright => [50.0, 20.0, 5.0],
                true => [0.0; 3],
                false => [next() * 4.0, next(), next() * next() * 30.0],
            })
            .collect();
        Arc::new(Image {
            width: w,
            height: h,
            rgb,
            envmap: None,
            source: "random.exr".into(),
        })
    }

    /// The axes and poles, normals grazing the poles, and a spiral of 24 more.
    pub(crate) fn normals() -> Vec<DVec3> {
        let mut v = vec![
            DVec3::Y,
            -DVec3::Y,
            DVec3::X,
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(1e-9, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 1e-13),
            DVec3::new(0.3, 1e-7, -0.9),
            DVec3::new(1.0, 1e-12, 0.0),
        ];
        for i in 0..24 {
            let z = 1.0 - (i as f64 + 0.5) / 12.0;
            let phi = i as f64 * 2.399963;
            let r = (1.0 - z * z).sqrt();
            v.push(DVec3::new(r * phi.cos(), z, r * phi.sin()));
        }
        v.into_iter().map(|n| n.normalize()).collect()
    }

    /// Normals (dome space = world under the identity frame) whose horizon dips into a piece
    /// between its columns' ends at one of its row's ends: the middle of the piece's columns
    /// is `φ₀ + π` (or `φ₀`) and the horizon meets that end halfway between the middle's and
    /// the column ends' values of `cos(φ − φ₀)`. A piece is then neither wholly lit nor wholly
    /// dark although both column ends are, which only the interior extremum of `cos` shows.
    fn grazing(d: &DomeIrradiance) -> Vec<DVec3> {
        let pi = std::f64::consts::PI;
        let g = &d.grids[0];
        let mut out = vec![];
        for (i, j) in [
            (0, 0),
            (g.xs.len() / 2, g.ys.len() / 2),
            (g.xs.len() - 1, g.ys.len() - 1),
        ] {
            let (px, py) = (g.xs[i], g.ys[j]);
            let phi = |x: f64| pi - 2.0 * pi * x / d.geom.w;
            let (phic, half) = (phi(0.5 * (px.x0 + px.x1)), 0.5 * (phi(px.x0) - phi(px.x1)));
            for y in [py.x0, py.x1] {
                let theta = pi * y / d.geom.h;
                if theta.cos().abs() < 1e-3 || theta.sin() < 1e-3 {
                    continue;
                }
                for (phi0, c) in [
                    (phic + pi, -(1.0 + half.cos()) / 2.0),
                    (phic, (1.0 + half.cos()) / 2.0),
                ] {
                    // a cos θ + sin θ · c = 0 with ρ = 1.
                    let a = -theta.sin() * c / theta.cos();
                    out.push(DVec3::new(phi0.sin(), a, phi0.cos()).normalize());
                    out.push(-DVec3::new(phi0.sin(), a, phi0.cos()).normalize());
                }
            }
        }
        out
    }

    /// `warm` builds what a batch's parallel loop would otherwise first build from inside it
    /// (`DomeIrradiance::warm`): the tile tables for a masked dome or a format the sweep does
    /// not take, the sweep's block sums for more than one normal, never the row rule's tables.
    #[test]
    fn warm_builds_what_the_batch_reads() {
        let img = image(8, 4, 3, false);
        let frame = || DomeFrame::new(DMat3::IDENTITY, DMat3::IDENTITY).unwrap();
        let latlong = || {
            DomeIrradiance::new(img.clone(), DomeFormat::LatLong, Filter::Bilinear, frame())
                .unwrap()
        };
        let d = latlong();
        d.warm(false, 1);
        assert!(d.tables.get().is_none() && d.run_prefix.get().is_none());
        d.warm(false, 2);
        assert!(d.run_prefix.get().is_some() && d.tables.get().is_none());
        assert!(d.row_tables.get().is_none());
        let d = latlong();
        d.warm(true, 20);
        assert!(d.tables.get().is_some() && d.run_prefix.get().is_none());
        let ball = DomeIrradiance::new(
            img.clone(),
            DomeFormat::MirroredBall,
            Filter::Bilinear,
            frame(),
        )
        .unwrap();
        ball.warm(false, 20);
        assert!(ball.tables.get().is_some() && ball.run_prefix.get().is_none());
    }

    /// The sweep against the tiles (the same moments and crossed pieces, summed another way:
    /// within 1e-12 of the value), its lit runs summed piece by piece and from block sums of 2
    /// and 3 columns, and against the row rule (the device path's method,
    /// `cpu::irradiance::latlong_rows`, an independent integration of the same filtered map:
    /// within 1e-9, 1e-8 for grazing normals), over sizes from 1 × 1 (pieces cut to 0.25 rad) to 96 × 2, both filters,
    /// the identity, a rotation and a rotation times a uniform scale.
    #[test]
    fn the_sweep_is_the_tables_integral() {
        let axis = DVec3::new(0.3, -0.5, 0.8).normalize();
        let frames = [
            DMat3::IDENTITY,
            DMat3::from_axis_angle(axis, 0.9),
            DMat3::from_axis_angle(axis, -2.1) * 3.0,
        ];
        let (mut worst_tables, mut worst_rows, mut worst_grazing) = (0.0f64, 0.0f64, 0.0f64);
        let mut count = 0;
        for &(w, h) in &[(1, 1), (2, 1), (4, 2), (13, 5), (16, 8), (64, 32), (96, 2)] {
            for filter in [Filter::Bilinear, Filter::Nearest] {
                for one_texel in [false, true] {
                    let img = image(w, h, (w * 31 + h) as u64, one_texel);
                    for a in frames {
                        let frame = DomeFrame::new(a, DMat3::IDENTITY).unwrap();
                        let d =
                            DomeIrradiance::new(img.clone(), DomeFormat::LatLong, filter, frame)
                                .unwrap();
                        assert!(d.sweeps());
                        // The row rule is held to 1e-9 on `normals()`, its own test's set, and to
                        // 1e-8 on the grazing normals that probe the sweep's classification
                        // (against the tables at 1e-12), where its error reached 2e-9.
                        let plain = normals().len();
                        let mut ns = normals();
                        if a == DMat3::IDENTITY {
                            ns.extend(grazing(&d));
                        }
                        let blocks = [2, 3].map(|b| {
                            let mut with = DomeIrradiance::new(
                                img.clone(),
                                DomeFormat::LatLong,
                                filter,
                                DomeFrame::new(a, DMat3::IDENTITY).unwrap(),
                            )
                            .unwrap();
                            with.run_prefix = RunPrefix::new(&with, with.axes(), b).into();
                            with
                        });
                        for (k, n) in ns.into_iter().enumerate() {
                            let want = d.irradiance_within(n, &[]);
                            let got = d.sweep(n).unwrap();
                            for with in &blocks {
                                let by_blocks = with.sweep(n).unwrap();
                                let err = (by_blocks - got).abs().max_element()
                                    / (1e-300 + got.abs().max_element());
                                assert!(
                                    err < 1e-12,
                                    "{w}x{h} {filter:?} frame {a} n={n}: blocks {by_blocks} \
                                     pieces {got}"
                                );
                            }
                            // The map's whole-sphere scale: ∫ L over the lit hemisphere ≤ π max L.
                            let scale = img
                                .rgb
                                .iter()
                                .map(|t| t[0].max(t[1]).max(t[2]) as f64)
                                .fold(0.0, f64::max)
                                * std::f64::consts::PI;
                            let err = (got - want).abs().max_element() / scale;
                            assert!(
                                err < 1e-12,
                                "{w}x{h} {filter:?} one texel {one_texel} frame {a} n={n}: \
                                 sweep {got} tables {want} ({err:.1e})"
                            );
                            worst_tables = worst_tables.max(err);
                            let rows = d.irradiance_by_rows(n).unwrap();
                            let err = (got - rows).abs().max_element() / scale;
                            let (tol, worst) = if k < plain {
                                (1e-9, &mut worst_rows)
                            } else {
                                (1e-8, &mut worst_grazing)
                            };
                            assert!(
                                err < tol,
                                "{w}x{h} {filter:?} frame {a} n={n}: sweep {got} rows {rows} \
                                 ({err:.1e})"
                            );
                            *worst = worst.max(err);
                            count += 1;
                        }
                    }
                }
            }
        }
        eprintln!(
            "{count} normals: sweep − tables ≤ {worst_tables:.1e}, sweep − rows ≤ {worst_rows:.1e} \
             (grazing normals: {worst_grazing:.1e}), of π max L"
        );
    }

    /// Formats and frames the sweep does not cover say so (`irradiance` then walks the tables).
    #[test]
    fn the_sweep_declines_other_formats_and_frames() {
        let img = image(8, 8, 3, false);
        let sheared = DMat3::from_cols(DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::Z);
        let frame = DomeFrame::new(sheared, DMat3::IDENTITY).unwrap();
        let d =
            DomeIrradiance::new(img.clone(), DomeFormat::LatLong, Filter::Bilinear, frame).unwrap();
        assert!(d.sweep(DVec3::Y).is_none());
        let frame = DomeFrame::new(DMat3::IDENTITY, DMat3::IDENTITY).unwrap();
        let d =
            DomeIrradiance::new(img, DomeFormat::MirroredBall, Filter::Bilinear, frame).unwrap();
        assert!(d.sweep(DVec3::Y).is_none());
    }
}
