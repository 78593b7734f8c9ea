//! The filtered dome texture as pieces on which it is a polynomial, and the exact integral of a
//! function of the dome direction over a piece, optionally clipped to a receiver's lit half
//! (DESIGN.md §6 "Dome and texture irradiance: what 'exact' means").
//!
//! A piece is a rectangle of the image sheet (pixel units) between texel-centre lines (bilinear)
//! or texel edges (nearest), inside one cross face for `cubeMapVerticalCross`; on it the texture
//! is `Σ wx(x)·wy(y)·T` with linear weights ([`crate::prepare::texture::AxisPiece`]). The map sheet → dome
//! direction is smooth inside a piece (§6 D2–D5), with the dome solid angle per pixel area `J`:
//! latlong `sin θ · (2π/W)(π/H)`; mirroredBall `4 · (2/W)(2/H)` (the mirror ball is equal-area);
//! angular `π sin(πr)/r · (2/W)(2/H)`; cross `(2/N)² / |F + aR + bU|³` (gnomonic).
//!
//! The integral over a piece, clipped at a receiver's horizon or at several half-spaces, is
//! [`super::clip::exact`].

use glam::{DVec2, DVec3};

use super::quadrature::gl;
use crate::cpu::texture;
use crate::prepare::texture::Image;
use crate::prepare::texture::{AxisPiece, Filter, axis_pieces};
use crate::prepare::texture::{DomeFormat, ball_dir};

pub(super) const PI: f64 = std::f64::consts::PI;
pub(super) const TAU: f64 = std::f64::consts::TAU;

/// The sheet → dome-direction map of one format.
#[derive(Clone, Copy, Debug)]
pub struct Geometry {
    pub format: DomeFormat,
    pub w: f64,
    pub h: f64,
    /// Cross face size (W/3); unused otherwise.
    pub n: f64,
}

/// One grid of pieces: the whole sheet, or one cross face.
#[derive(Clone, Debug)]
pub struct PieceGrid {
    pub xs: Vec<AxisPiece>,
    pub ys: Vec<AxisPiece>,
    /// Cross face (texture::cross_face numbering); 0 otherwise.
    pub face: u32,
}

/// A piece: one cell of a grid.
#[derive(Clone, Copy, Debug)]
pub struct Piece {
    pub ax: AxisPiece,
    pub ay: AxisPiece,
    pub face: u32,
}

/// The largest angle (radians) a latlong or cross piece may span. The quadrature orders are
/// chosen from a piece's cap radius assuming it is at most ~0.5 rad (`DomeIrradiance::order`);
/// on tiny maps a texel spans far more (90° on a 4 × 2 latlong or a 3 × 4 cross), and under a
/// non-uniform dome scale the fixed inner rule then erred by up to 3.8e-4 (measured). Cutting
/// such pieces (same texels, same weights: the reconstruction is smooth inside a piece) keeps
/// every piece within the assumption; maps wider than ~25 pixels are not affected.
const MAX_PIECE_ANGLE: f64 = 0.25;

/// `pieces` with every piece longer than `max_len` pixels cut into equal parts of at most that
/// length.
fn refine(pieces: Vec<AxisPiece>, max_len: f64) -> Vec<AxisPiece> {
    let mut out = Vec::with_capacity(pieces.len());
    for p in pieces {
        let parts = ((p.x1 - p.x0) / max_len).ceil().max(1.0) as usize;
        for k in 0..parts {
            let at = |k: usize| p.x0 + (p.x1 - p.x0) * k as f64 / parts as f64;
            out.push(AxisPiece {
                x0: at(k),
                x1: if k + 1 == parts { p.x1 } else { at(k + 1) },
                ..p
            });
        }
    }
    out
}

/// One inner line of a piece's integral (a fixed sheet x, `clip.rs`, [`tensor`]): a latlong
/// line is a meridian, whose azimuth's sine and cosine are computed once for every node and
/// clip on it rather than per node (they were a third of a masked dome's crossed pieces).
#[derive(Clone, Copy)]
pub struct Line {
    pub face: u32,
    pub x: f64,
    /// Latlong: `(sin φ, cos φ)` of the meridian's `φ = π − 2πx/W` (§6 D2); unused otherwise.
    pub phi: (f64, f64),
}

/// Where a piece lies with respect to a disk format's rim.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    Inside,
    Boundary,
    Outside,
}

impl Geometry {
    pub fn new(format: DomeFormat, width: usize, height: usize) -> Geometry {
        Geometry {
            format,
            w: width as f64,
            h: height as f64,
            n: width as f64 / 3.0,
        }
    }

    pub(super) fn is_disk(&self) -> bool {
        matches!(self.format, DomeFormat::MirroredBall | DomeFormat::Angular)
    }

    /// The piece grids of this format and filter (§6 D1's wrap/clamp per format). On the
    /// latlong and cross formats, pieces are also cut so that none spans more than
    /// [`MAX_PIECE_ANGLE`] (see there).
    pub fn grids(&self, filter: Filter) -> Vec<PieceGrid> {
        let (w, h) = (self.w as u32, self.h as u32);
        match self.format {
            DomeFormat::LatLong => vec![PieceGrid {
                // Radians per pixel: 2π/W across, π/H down.
                xs: refine(axis_pieces(w, true, filter), MAX_PIECE_ANGLE * self.w / TAU),
                ys: refine(axis_pieces(h, false, filter), MAX_PIECE_ANGLE * self.h / PI),
                face: 0,
            }],
            DomeFormat::MirroredBall | DomeFormat::Angular => {
                vec![PieceGrid {
                    xs: axis_pieces(w, false, filter),
                    ys: axis_pieces(h, false, filter),
                    face: 0,
                }]
            }
            DomeFormat::Cross => {
                let n = self.n as u32;
                (0..6)
                    .map(|f| {
                        let b = texture::cross_basis(f).3;
                        let shift = |p: AxisPiece, k: u32| {
                            let o = (k * n) as f64;
                            AxisPiece {
                                x0: p.x0 + o,
                                x1: p.x1 + o,
                                i0: p.i0 + k * n,
                                i1: p.i1 + k * n,
                                origin: p.origin + o,
                            }
                        };
                        // A face's gnomonic coordinate spans [−1, 1] over N pixels, at most
                        // 2/N radians per pixel (at the face's centre).
                        let max_px = MAX_PIECE_ANGLE * self.n / 2.0;
                        let xs = refine(axis_pieces(n, false, filter), max_px)
                            .into_iter()
                            .map(|p| shift(p, b.x as u32))
                            .collect();
                        let ys = refine(axis_pieces(n, false, filter), max_px)
                            .into_iter()
                            .map(|p| shift(p, b.y as u32))
                            .collect();
                        PieceGrid { xs, ys, face: f }
                    })
                    .collect()
            }
        }
    }

    /// Disk image point (a, b) of sheet (x, y) (§6 D3: `a = 2s − 1`, `b = 1 − 2t`).
    #[inline]
    fn ab(&self, x: f64, y: f64) -> DVec2 {
        DVec2::new(2.0 * x / self.w - 1.0, 1.0 - 2.0 * y / self.h)
    }

    /// The inner line at sheet x of `face` ([`Line`]).
    #[inline]
    pub fn line(&self, face: u32, x: f64) -> Line {
        let phi = if self.format == DomeFormat::LatLong {
            (PI - 2.0 * PI * x / self.w).sin_cos()
        } else {
            (0.0, 0.0)
        };
        Line { face, x, phi }
    }

    /// [`Geometry::dir_jac`] at height y on `line`.
    #[inline]
    pub fn dir_jac_on(&self, line: &Line, y: f64) -> (DVec3, f64) {
        match self.format {
            DomeFormat::LatLong => {
                let theta = PI * y / self.h;
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = line.phi;
                (
                    DVec3::new(st * sp, ct, st * cp),
                    st * (2.0 * PI / self.w) * (PI / self.h),
                )
            }
            _ => self.dir_jac(line.face, line.x, y),
        }
    }

    /// Dome direction and dome solid angle per unit sheet area at (x, y) (module docs).
    #[inline]
    pub fn dir_jac(&self, face: u32, x: f64, y: f64) -> (DVec3, f64) {
        match self.format {
            DomeFormat::LatLong => self.dir_jac_on(&self.line(face, x), y),
            DomeFormat::MirroredBall => {
                let p = self.ab(x, y);
                (ball_dir(p.x, p.y), 16.0 / (self.w * self.h))
            }
            DomeFormat::Angular => {
                let p = self.ab(x, y);
                let r = p.length().min(1.0);
                let k = if r < 1e-8 {
                    PI * (1.0 - (PI * r).powi(2) / 6.0)
                } else {
                    (PI * r).sin() / r
                };
                (
                    DVec3::new(p.x * k, p.y * k, (PI * r).cos()),
                    PI * k * 4.0 / (self.w * self.h),
                )
            }
            DomeFormat::Cross => {
                let (f, r, u, blk) = texture::cross_basis(face);
                let a = 2.0 * (x - blk.x * self.n) / self.n - 1.0;
                let b = 1.0 - 2.0 * (y - blk.y * self.n) / self.n;
                let v = f + a * r + b * u;
                let l = v.length();
                (v / l, 4.0 / (self.n * self.n * l * l * l))
            }
        }
    }

    /// The sheet point (x, y) of dome direction `d` (the inverse of [`Geometry::dir_jac`]'s
    /// direction, §6 D2–D5); for the cross, within `face`'s block, `None` when `d` is not in
    /// front of that face. Used only to place outer break points.
    pub fn sheet_point(&self, face: u32, d: DVec3) -> Option<(f64, f64)> {
        match self.format {
            DomeFormat::LatLong => {
                let x = self.w * (0.5 - d.x.atan2(d.z) / TAU);
                let y = self.h * (d.x.hypot(d.z)).atan2(d.y) / PI;
                Some((x, y))
            }
            DomeFormat::MirroredBall | DomeFormat::Angular => {
                let st = if self.format == DomeFormat::MirroredBall {
                    texture::mirrored_ball_st(d)
                } else {
                    texture::angular_st(d)
                };
                Some((st.x * self.w, st.y * self.h))
            }
            DomeFormat::Cross => {
                let (f, r, u, blk) = texture::cross_basis(face);
                let fd = f.dot(d);
                if !(fd > 0.0) {
                    return None;
                }
                let (a, b) = (r.dot(d) / fd, u.dot(d) / fd);
                Some((
                    blk.x * self.n + 0.5 * self.n * (a + 1.0),
                    blk.y * self.n + 0.5 * self.n * (1.0 - b),
                ))
            }
        }
    }

    /// Inside, on, or outside a disk format's rim (always inside for latlong and cross).
    pub fn domain(&self, p: &Piece) -> Domain {
        if !self.is_disk() {
            return Domain::Inside;
        }
        let (a0, b0) = (self.ab(p.ax.x0, p.ay.y1()), self.ab(p.ax.x1, p.ay.y0()));
        let (lo, hi) = (a0.min(b0), a0.max(b0));
        let near = DVec2::ZERO.clamp(lo, hi).length();
        let far = DVec2::new(lo.x.abs().max(hi.x.abs()), lo.y.abs().max(hi.y.abs())).length();
        if near >= 1.0 {
            Domain::Outside
        } else if far > 1.0 - 1e-12 {
            Domain::Boundary
        } else {
            Domain::Inside
        }
    }

    /// A cap containing the piece's image on the sphere: (centre, angular radius), or `None`
    /// where no finite bound is kept (a disk rim piece). The radius is a Lipschitz bound of the
    /// sheet → sphere map times the half-diagonal: latlong `ds² ≤ (π/H)²dy² + (2π/W)²dx²`;
    /// cross `|∂d/∂(a,b)| ≤ 1/|v| ≤ 1`; angular `≤ π` per unit (a, b); mirroredBall
    /// `≤ 2/√(1 − r²_max)`.
    pub fn cap(&self, p: &Piece) -> Option<(DVec3, f64)> {
        let (hx, hy) = (0.5 * (p.ax.x1 - p.ax.x0), 0.5 * (p.ay.x1 - p.ay.x0));
        let (cx, cy) = (p.ax.x0 + hx, p.ay.x0 + hy);
        let disk_diag = ((2.0 * hx / self.w).powi(2) + (2.0 * hy / self.h).powi(2)).sqrt();
        let radius = match self.format {
            DomeFormat::LatLong => {
                ((2.0 * PI / self.w * hx).powi(2) + (PI / self.h * hy).powi(2)).sqrt()
            }
            DomeFormat::Cross => 2.0 / self.n * (hx * hx + hy * hy).sqrt(),
            DomeFormat::Angular | DomeFormat::MirroredBall => {
                if self.domain(p) != Domain::Inside {
                    return None;
                }
                let far = self.ab(cx, cy).abs() + DVec2::new(2.0 * hx / self.w, 2.0 * hy / self.h);
                let r2 = far.length_squared();
                if self.format == DomeFormat::Angular {
                    PI * disk_diag
                } else if r2 < 1.0 {
                    2.0 / (1.0 - r2).sqrt() * disk_diag
                } else {
                    return None;
                }
            }
        };
        Some((self.dir_jac(p.face, cx, cy).0, radius))
    }
}

impl AxisPiece {
    /// The same piece read as a y-axis piece (bounds).
    #[inline]
    pub fn y0(&self) -> f64 {
        self.x0
    }
    #[inline]
    pub fn y1(&self) -> f64 {
        self.x1
    }
}

/// The filtered texture at (x, y) inside the piece: `Σ wx·wy·T` (§6 D1 bilinear or nearest).
#[inline]
pub fn texture_at(img: &Image, p: &Piece, x: f64, y: f64) -> DVec3 {
    let (wx0, wx1) = p.ax.weights(x);
    let (wy0, wy1) = p.ay.weights(y);
    let t = |i: u32, j: u32| texture::tex_fetch(img, i, j);
    let top = t(p.ax.i0, p.ay.i0) * wx0
        + if wx1 != 0.0 {
            t(p.ax.i1, p.ay.i0) * wx1
        } else {
            DVec3::ZERO
        };
    let bot = if wy1 != 0.0 {
        (t(p.ax.i0, p.ay.i1) * wx0
            + if wx1 != 0.0 {
                t(p.ax.i1, p.ay.i1) * wx1
            } else {
                DVec3::ZERO
            })
            * wy1
    } else {
        DVec3::ZERO
    };
    top * wy0 + bot
}

/// `∫∫_piece f(d, tex, J) dx dy` by the tensor n × n Gauss–Legendre rule (smooth integrand,
/// whole piece inside the domain, no horizon).
pub fn tensor<const K: usize>(
    g: &Geometry,
    img: &Image,
    p: &Piece,
    n: usize,
    f: &mut impl FnMut(DVec3, DVec3, f64) -> [f64; K],
) -> [f64; K] {
    gl(n, p.ax.x0, p.ax.x1, |x| {
        let line = g.line(p.face, x);
        gl(n, p.ay.x0, p.ay.x1, |y| {
            let (d, j) = g.dir_jac_on(&line, y);
            f(d, texture_at(img, p, x, y), j)
        })
    })
}
