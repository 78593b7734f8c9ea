//! Exact dome irradiance (DESIGN.md §6 D1 last paragraph and "Dome and texture irradiance: what
//! 'exact' means"): `E(n) = ∫ L(ω) max(0, n·ω) dω` over **world** solid angle, of the texture as
//! actually filtered (bilinear or nearest), for every format and any invertible dome transform.
//!
//! In dome space (`ω ∝ A_eff d`, §6 D1) the integrand is
//! `L(d) · max(0, m·d) · w(d)` with `m = A_effᵀ n` and `w(d) = |det A| / |A_eff d|⁴`
//! (`n·ω = m·d / |A_eff d|` times the Jacobian `|det A| / |A_eff d|³`). It is linear in `m`, so a
//! piece of the texture wholly above the horizon contributes `m · V` with the precomputable
//! moment `V = ∫ L d w dd` (RGB × xyz). Only pieces the horizon great circle `m·d = 0` crosses
//! need per-receiver work ([`clip::exact`]).
//!
//! The same holds inside any convex intersection of half-spaces `kᵢ·ω ≥ 0` (DESIGN.md §8 P2 mask
//! mode: a portal piece seen from x is one, an edge each, `cpu/portal.rs`): each is the dome-space
//! half-space `(A_effᵀ kᵢ)·d ≥ 0`, a piece inside all of them and the horizon adds `m · V`, one
//! outside any is skipped, and [`clip::exact`] clips the rest at every boundary circle
//! ([`DomeIrradiance::irradiance_within`]; the unmasked `E(n)` is its case of no `kᵢ`).
//!
//! Tables (built lazily on the first query, in parallel): pieces grouped in tiles of T × T
//! (T = 1 up to 2²⁰ pieces), each with its summed moment and a bounding cap. A receiver adds
//! `m · V` for tiles whose cap is wholly lit, skips wholly dark ones, and descends into the rest.
//! A latlong map under a conformal frame skips the tables for `E(n)`: one pass over the pieces
//! per normal gives the same sum as fast as the walk, without the tables' build ([`latlong`]);
//! the tables serve the other formats and frames, and every masked dome.
//!
//! Moments: latlong under a conformal frame (rotation × uniform scale, `w` constant) is separable
//! — `∫∫ wx wy (sin θ sin φ, cos θ, sin θ cos φ) sin θ dφ dθ` is a product of one column integral
//! and one row integral — computed per axis piece with a 16-point rule (exact to rounding on
//! pieces ≤ π/8). Otherwise an n × n Gauss–Legendre rule per piece with n the smallest order whose
//! term `(2δ(1 + κ))^{2n} / (2n)!` is below 1e-17 (δ the piece's cap radius, κ ≥ the frame's
//! condition number; a rule of order n is exact for degree 2n − 1 and the integrand's derivatives
//! grow like `(1 + κ)^k`), and the adaptive routine for disk-rim pieces and pieces with
//! `δ(1 + κ) > 0.5`. Crossed pieces: adaptive outer integral to 1e-12 of the piece's scale.

pub mod clip;
pub mod horizon;
pub(crate) mod latlong;
pub mod pieces;
pub mod quadrature;
pub mod sh;
mod tables;

use std::sync::{Arc, OnceLock};

use glam::DVec3;
use rayon::prelude::*;

use crate::prepare::texture::Filter;
use crate::prepare::texture::Image;
use crate::prepare::texture::{DomeFormat, DomeFrame, FormatError};
use clip::exact;
use pieces::{Domain, Geometry, Piece, PieceGrid, tensor};
use quadrature::gl;
use tables::Tables;

/// The irradiance tables of a prepared textured dome, built on first use and kept in the
/// texture's [`crate::prepare::texture::PreparedTexture::irradiance`] slot (shared by clones of the
/// light). `None` for a light without a texture, or a cross whose size is not 3N × 4N (which
/// preparation already refuses).
pub fn tables(p: &crate::prepare::Prepared) -> Option<Arc<DomeIrradiance>> {
    let t = p.dome_texture()?;
    let slot = t.irradiance.get_or_init(|| {
        match DomeIrradiance::new(t.image.clone(), t.format, t.filter, t.frame) {
            Ok(d) => Arc::new(d) as Arc<dyn std::any::Any + Send + Sync>,
            Err(_) => Arc::new(()) as Arc<dyn std::any::Any + Send + Sync>,
        }
    });
    slot.clone().downcast::<DomeIrradiance>().ok()
}

/// Relative tolerance of the adaptive integrals (per piece).
const REL_TOL: f64 = 1e-12;

/// A dome texture prepared for irradiance queries.
pub struct DomeIrradiance {
    pub img: Arc<Image>,
    pub format: DomeFormat,
    pub frame: DomeFrame,
    geom: Geometry,
    grids: Vec<PieceGrid>,
    /// `|det A| / |A_eff d|⁴` is constant (conformal frame).
    conformal: Option<f64>,
    /// Upper bound of the frame's condition number.
    kappa: f64,
    tables: OnceLock<Tables>,
    /// A latlong map's per-axis moment factors (conformal frames only, latlong.rs).
    axes: OnceLock<latlong::Axes>,
    /// The texture's filter (the row rule's tables read it).
    #[cfg(test)]
    filter: Filter,
    /// A latlong map's row tables in f64 for the row rule (latlong.rs "The row rule", which
    /// the tests hold against the sweep); `None` over [`latlong::ROWS_MAX_BYTES`].
    #[cfg(test)]
    row_tables: OnceLock<Option<Vec<f64>>>,
    /// The 9-coefficient fast path, projected on first use.
    sh9: OnceLock<sh::IrradianceSh>,
    /// A latlong map's block sums for the sweep's lit runs (latlong.rs "Runs"), built by
    /// [`DomeIrradiance::warm`] for a batch of several normals.
    run_prefix: OnceLock<latlong::RunPrefix>,
}

fn add<const K: usize>(acc: &mut [f64; K], v: &[f64; K]) {
    acc.iter_mut().zip(v).for_each(|(a, b)| *a += b);
}

impl DomeIrradiance {
    /// Fails (naming the file) for a cross whose size is not 3N × 4N; the other formats take any
    /// non-empty image.
    pub fn new(
        img: Arc<Image>,
        format: DomeFormat,
        filter: Filter,
        frame: DomeFrame,
    ) -> Result<DomeIrradiance, FormatError> {
        let (w, h) = (img.width, img.height);
        if format == DomeFormat::Cross && (w == 0 || w % 3 != 0 || h % 4 != 0 || w / 3 != h / 4) {
            return Err(FormatError::BadCross {
                path: img.source.clone(),
                width: w,
                height: h,
            });
        }
        let geom = Geometry::new(format, img.width, img.height);
        let grids = geom.grids(filter);
        let a = frame.a_eff;
        let conformal = frame.conformal_weight();
        let kappa = (a.to_cols_array().iter().map(|v| v * v).sum::<f64>()
            * frame.inv.to_cols_array().iter().map(|v| v * v).sum::<f64>())
        .sqrt()
            / 3.0;
        Ok(DomeIrradiance {
            img,
            format,
            frame,
            geom,
            grids,
            conformal,
            kappa: kappa.max(1.0),
            tables: OnceLock::new(),
            axes: OnceLock::new(),
            #[cfg(test)]
            filter,
            #[cfg(test)]
            row_tables: OnceLock::new(),
            sh9: OnceLock::new(),
            run_prefix: OnceLock::new(),
        })
    }

    /// `w(d) = |det A| / |A_eff d|⁴`.
    #[inline]
    pub fn weight(&self, d: DVec3) -> f64 {
        self.conformal.unwrap_or_else(|| {
            let l2 = (self.frame.a_eff * d).length_squared();
            self.frame.det_abs / (l2 * l2)
        })
    }

    /// The Gauss–Legendre order for a piece of cap radius δ (module docs).
    pub fn order(&self, delta: f64) -> usize {
        let x = 2.0 * delta * (1.0 + self.kappa);
        let mut term = 1.0f64;
        for n in 1..=24usize {
            let k = 2 * n;
            term *= x * x / ((k - 1) as f64 * k as f64);
            if term < 1e-17 {
                return n.max(2);
            }
        }
        24
    }

    fn piece(&self, grid: usize, ix: usize, iy: usize) -> Piece {
        let g = &self.grids[grid];
        Piece {
            ax: g.xs[ix],
            ay: g.ys[iy],
            face: g.face,
        }
    }

    /// The piece's texture scale for tolerances: its largest corner texel (summed channels) times
    /// its solid angle estimate.
    fn scale(&self, p: &Piece) -> f64 {
        let t = |i, j| crate::cpu::texture::tex_fetch(&self.img, i, j);
        let m = [
            t(p.ax.i0, p.ay.i0),
            t(p.ax.i1, p.ay.i0),
            t(p.ax.i0, p.ay.i1),
            t(p.ax.i1, p.ay.i1),
        ]
        .iter()
        .map(|v| v.abs().element_sum())
        .fold(0.0, f64::max);
        let (cx, cy) = (0.5 * (p.ax.x0 + p.ax.x1), 0.5 * (p.ay.x0 + p.ay.x1));
        let (d, j) = self.geom.dir_jac(p.face, cx, cy);
        let area = (p.ax.x1 - p.ax.x0) * (p.ay.x1 - p.ay.x0);
        m * (j.max(1e-3 * 16.0 / (self.geom.w * self.geom.h))) * area * self.weight(d) + 1e-300
    }

    /// `∫ f(d, tex, J)` over a whole piece (no horizon): one tensor Gauss–Legendre rule of
    /// order `order(δ) + extra` where the piece lies inside the image's domain and is small for
    /// the frame (`δ(1 + κ) ≤ 0.5`, see the module docs), else the adaptive [`exact`].
    fn whole_piece<const K: usize>(
        &self,
        p: &Piece,
        dom: Domain,
        extra: usize,
        f: &mut impl FnMut(DVec3, DVec3, f64) -> [f64; K],
    ) -> [f64; K] {
        match self.geom.cap(p) {
            Some((_, delta)) if dom == Domain::Inside && delta * (1.0 + self.kappa) <= 0.5 => {
                tensor(&self.geom, &self.img, p, self.order(delta) + extra, f)
            }
            _ => exact(
                &self.geom,
                &self.img,
                p,
                &[],
                self.order(0.5),
                REL_TOL * self.scale(p),
                f,
            ),
        }
    }

    /// Builds the lazily built tables that a batch's parallel loop will read, here, before that
    /// loop: the tile tables for a masked dome (`masked`) or one the sweep does not take, and
    /// the sweep's block sums for a batch of more than one distinct normal (`normals`; one
    /// normal, a falloff map of a plane, sums its lit pieces directly). Their builds run rayon
    /// jobs inside a `OnceLock`; first reached from inside a rayon loop, the builder, while it
    /// waits for a stolen job, may steal another iteration of that loop, which then waits on the
    /// same `OnceLock` for ever (rayon-rs/rayon#592 and #1251: work stealing makes the
    /// initialisation re-entrant). The latlong sweep's axis factors build without rayon.
    pub fn warm(&self, masked: bool, normals: usize) {
        if masked || !self.sweeps() {
            self.tables();
        } else if normals > 1 {
            self.run_prefix();
        }
    }

    /// The fast path's `E(n)` (see [`sh`]): nine multiply-adds per channel once projected.
    pub fn irradiance_sh9(&self, n: DVec3) -> DVec3 {
        self.sh9
            .get_or_init(|| sh::IrradianceSh::project(self))
            .irradiance(n)
    }

    /// For latlong under a conformal frame: the dome-space moments `∫ L dd`, `∫ L d dd` and
    /// `∫ L d dᵀ dd` (world solid angle = dome solid angle there), per channel, exactly and in
    /// O(W·H): every monomial of degree ≤ 2 in `d = (sin θ sin φ, cos θ, sin θ cos φ)` times
    /// `sin θ` is a product of a function of φ and one of θ, so each texel's weight is a column
    /// factor times a row factor (16-point rules per axis piece, as for the moments of the tables).
    /// `None` for other formats and frames.
    pub fn separable_moments(&self) -> Option<[(f64, DVec3, glam::DMat3); 3]> {
        let w = self.conformal?;
        if self.format != DomeFormat::LatLong {
            return None;
        }
        let (wd, hd) = (self.img.width, self.img.height);
        let pi = std::f64::consts::PI;
        let g = &self.grids[0];
        let mut cols = vec![[0.0f64; 6]; wd];
        for p in &g.xs {
            let v = gl::<12>(16, p.x0, p.x1, |x| {
                let (w0, w1) = p.weights(x);
                let (sp, cp) = (pi - 2.0 * pi * x / self.geom.w).sin_cos();
                let f = [1.0, sp, cp, sp * sp, cp * cp, sp * cp];
                std::array::from_fn(|k| if k < 6 { w0 * f[k] } else { w1 * f[k - 6] })
            });
            for k in 0..6 {
                cols[p.i0 as usize][k] += v[k];
                cols[p.i1 as usize][k] += v[k + 6];
            }
        }
        let mut rows = vec![[0.0f64; 6]; hd];
        for p in &g.ys {
            let v = gl::<12>(16, p.x0, p.x1, |y| {
                let (w0, w1) = p.weights(y);
                let (st, ct) = (pi * y / self.geom.h).sin_cos();
                let f = [
                    st,
                    st * st,
                    ct * st,
                    st * st * st,
                    ct * ct * st,
                    st * st * ct,
                ];
                std::array::from_fn(|k| if k < 6 { w0 * f[k] } else { w1 * f[k - 6] })
            });
            for k in 0..6 {
                rows[p.i0 as usize][k] += v[k];
                rows[p.i1 as usize][k] += v[k + 6];
            }
        }
        // Per channel: the ten monomials 1, x, y, z, xx, yy, zz, xy, yz, xz as (col, row) factors.
        const PAIRS: [(usize, usize); 10] = [
            (0, 0),
            (1, 1),
            (0, 2),
            (2, 1),
            (3, 3),
            (0, 4),
            (4, 3),
            (1, 5),
            (2, 5),
            (5, 3),
        ];
        let m: [f64; 30] = (0..hd)
            .into_par_iter()
            .map(|j| {
                let mut r = [[0.0f64; 6]; 3];
                for (t, a) in self.img.rgb[j * wd..(j + 1) * wd].iter().zip(&cols) {
                    for c in 0..3 {
                        for k in 0..6 {
                            r[c][k] += t[c] as f64 * a[k];
                        }
                    }
                }
                let b = &rows[j];
                let mut out = [0.0; 30];
                for c in 0..3 {
                    for (q, (ka, kb)) in PAIRS.iter().enumerate() {
                        out[10 * c + q] = r[c][*ka] * b[*kb];
                    }
                }
                out
            })
            .reduce(
                || [0.0; 30],
                |mut a, b| {
                    add(&mut a, &b);
                    a
                },
            );
        // Only the solid-angle factor |det A|/|A d|³ = |det A|/s³ applies here (no cosine): it
        // is w·s with the stored w = |det A|/s⁴ and s = |det A|^⅓, i.e. 1 for a conformal frame.
        let k = (2.0 * pi / self.geom.w) * (pi / self.geom.h) * w * self.frame.det_abs.cbrt();
        Some(std::array::from_fn(|c| {
            let v = &m[10 * c..10 * c + 10];
            let s = glam::DMat3::from_cols(
                DVec3::new(v[4], v[7], v[9]),
                DVec3::new(v[7], v[5], v[8]),
                DVec3::new(v[9], v[8], v[6]),
            );
            (v[0] * k, DVec3::new(v[1], v[2], v[3]) * k, s * k)
        }))
    }

    /// `∫ f(ω, L) dω` over the whole sphere in world solid angle, piece by piece with the same
    /// rules as the moments (used by the SH projection). `f` gets the world direction and the
    /// filtered texel and returns K values.
    pub fn integrate_sphere<const K: usize>(
        &self,
        f: &(impl Fn(DVec3, DVec3) -> [f64; K] + Sync),
    ) -> [f64; K] {
        let mut specs = vec![];
        for (gi, g) in self.grids.iter().enumerate() {
            for j in 0..g.ys.len() {
                specs.push((gi, j));
            }
        }
        let a = self.frame.a_eff;
        specs
            .into_par_iter()
            .map(|(gi, j)| {
                let mut acc = [0.0; K];
                for i in 0..self.grids[gi].xs.len() {
                    let p = self.piece(gi, i, j);
                    let dom = self.geom.domain(&p);
                    if dom == Domain::Outside {
                        continue;
                    }
                    let mut g = |d: DVec3, tex: DVec3, jac: f64| {
                        let wd = a * d;
                        let l = wd.length();
                        f(wd / l, tex).map(|v| v * jac * self.frame.det_abs / (l * l * l))
                    };
                    add(&mut acc, &self.whole_piece(&p, dom, 1, &mut g));
                }
                acc
            })
            .reduce(
                || [0.0; K],
                |mut a, b| {
                    add(&mut a, &b);
                    a
                },
            )
    }
}
