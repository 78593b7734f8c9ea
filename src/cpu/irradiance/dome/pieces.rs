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
//! Integration over a piece: outer variable x, inner y. For each outer node the lit part of the
//! inner line is found exactly — latlong: the line is a meridian, which meets the horizon great
//! circle once, at `θ = α ± π/2` with `α = atan2(m_x sin φ + m_z cos φ, m_y)`; cross: the horizon
//! is a straight line in the face's gnomonic (a, b); disks: sign changes on 8 sub-intervals refined
//! by regula falsi — and integrated with an n-point Gauss–Legendre rule. The outer integral is split
//! at the x where the horizon (or the disk rim) crosses the piece's top or bottom edge, so each
//! outer part is smooth, and integrated adaptively. The mirror ball's `√(1 − r²)` is removed by
//! integrating its inner lines in τ with `b = √(1 − a²)·sin τ`; for the disks the outer parts use
//! `x = x₀ + L(3u² − 2u³)`, which turns the `√` behaviour at the rim's ends and at the horizon's
//! turning points into a polynomial in u.

use glam::{DVec2, DVec3};

use super::horizon::HorizonCurve;
use super::quadrature::{adaptive, gl, sign_change_roots};
use crate::cpu::texture;
use crate::prepare::texture::Image;
use crate::prepare::texture::{AxisPiece, Filter, axis_pieces};
use crate::prepare::texture::{DomeFormat, ball_dir};

const PI: f64 = std::f64::consts::PI;
pub(super) const TAU: f64 = std::f64::consts::TAU;
/// Most outer sub-intervals per smooth part of a piece (bounds the work of near-singular cases).
const MAX_INTERVALS: usize = 64;

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

    fn is_disk(&self) -> bool {
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

    /// Dome direction and dome solid angle per unit sheet area at (x, y) (module docs).
    #[inline]
    pub fn dir_jac(&self, face: u32, x: f64, y: f64) -> (DVec3, f64) {
        match self.format {
            DomeFormat::LatLong => {
                let phi = PI - 2.0 * PI * x / self.w;
                let theta = PI * y / self.h;
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = phi.sin_cos();
                (
                    DVec3::new(st * sp, ct, st * cp),
                    st * (2.0 * PI / self.w) * (PI / self.h),
                )
            }
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
        gl(n, p.ay.x0, p.ay.x1, |y| {
            let (d, j) = g.dir_jac(p.face, x, y);
            f(d, texture_at(img, p, x, y), j)
        })
    })
}

/// One clipping half-space `m·d > 0` of dome space (a receiver's horizon, or the plane through
/// x and an edge of a portal piece mapped to dome space), with its great circle drawn on the
/// image for the disk formats ([`HorizonCurve`]; `None` for latlong and cross, whose crossings are
/// found in closed form).
#[derive(Clone, Copy)]
pub struct Clip<'a> {
    pub m: DVec3,
    pub curve: Option<&'a HorizonCurve>,
    /// Disk formats only: the circle passes through the rim's direction −Z (`m_z ≈ 0`), so it
    /// is the diameter `m_x a + m_y b = 0` of the image (the disks keep the azimuth,
    /// `d ∝ (a, b, ·)`): its crossings are solved in closed form (its curve would jump across
    /// the image at −Z, and sampling the edges would step outside the disk).
    pub line: bool,
}

/// `∫∫ f(d, tex, J) dx dy` over the piece ∩ domain ∩ {m·d > 0 for every clip} (no clip: the
/// whole piece), exactly in the sense of the module docs. `n` is the inner rule's order, `tol`
/// the absolute tolerance of the adaptive outer integral.
///
/// With several clips (a convex spherical polygon, DESIGN.md §8 P2 mask mode) the lit part of an
/// inner line is the part where every clip is positive: the line is cut at every clip's roots
/// and each sub-interval kept when all clips are positive at its middle. Where two clip circles
/// cross inside the piece (a vertex of the polygon) the endpoint of the lit part switches from
/// one root to the other, a kink of the outer integrand, so the outer integral is also split at
/// the x of those crossings. With one clip this is the horizon-only computation, unchanged.
#[allow(clippy::too_many_arguments)]
pub fn exact<const K: usize>(
    g: &Geometry,
    img: &Image,
    p: &Piece,
    clips: &[Clip],
    n: usize,
    tol: f64,
    f: &mut impl FnMut(DVec3, DVec3, f64) -> [f64; K],
) -> [f64; K] {
    let (x0, x1, y0, y1) = (p.ax.x0, p.ax.x1, p.ay.x0, p.ay.x1);
    let boundary = g.domain(p) == Domain::Boundary;
    let disk = g.is_disk();
    // `!(m·d <= 0)` as the one-clip code had it (a NaN counts as lit there).
    let dark = |x: f64, y: f64| {
        if clips.is_empty() {
            return false;
        }
        let d = g.dir_jac(p.face, x, y).0;
        clips.iter().any(|c| c.m.dot(d) <= 0.0)
    };
    let mut breaks = vec![x0, x1];
    let to_x = |a: f64| 0.5 * g.w * (a + 1.0);
    for c in clips {
        if c.line {
            for ye in [y0, y1] {
                if c.m.x != 0.0 {
                    breaks.push(to_x(-c.m.y * (1.0 - 2.0 * ye / g.h) / c.m.x));
                }
            }
            continue;
        }
        match c.curve {
            Some(curve) => {
                // Disk formats: where the circle crosses the top/bottom edges, and where it turns.
                let mut pts = Vec::new();
                for ye in [y0, y1] {
                    curve.crossings(1, 1.0 - 2.0 * ye / g.h, &mut pts);
                }
                breaks.extend(pts.iter().map(|p| to_x(p.x)));
                breaks.extend(curve.a_extrema().map(to_x));
            }
            None => {
                for ye in [y0, y1] {
                    let m = c.m;
                    sign_change_roots(
                        &mut |x| m.dot(g.dir_jac(p.face, x, ye).0),
                        x0,
                        x1,
                        16,
                        &mut breaks,
                    );
                }
            }
        }
    }
    // Where two clip circles cross inside the piece (both crossing points ±(mᵢ × mⱼ)).
    for (i, a) in clips.iter().enumerate() {
        for b in &clips[i + 1..] {
            let v = a.m.cross(b.m);
            let l = v.length();
            if !(l > 0.0) {
                continue;
            }
            for d in [v / l, -v / l] {
                if let Some((x, y)) = g.sheet_point(p.face, d) {
                    let slack = 1e-9 * (y1 - y0);
                    if x > x0 && x < x1 && y >= y0 - slack && y <= y1 + slack {
                        breaks.push(x);
                    }
                }
            }
        }
    }
    if boundary {
        // Where the rim crosses the piece's top and bottom edges, and the disk's left/right ends.
        for ye in [y0, y1] {
            let b = 1.0 - 2.0 * ye / g.h;
            if b.abs() < 1.0 {
                let a = (1.0 - b * b).sqrt();
                breaks.extend([-a, a].map(|a| 0.5 * g.w * (a + 1.0)));
            }
        }
        breaks.extend([0.0, g.w]);
    }
    breaks.retain(|&x| (x0..=x1).contains(&x));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14 * g.w);
    let ball = g.format == DomeFormat::MirroredBall;
    let mut roots = Vec::with_capacity(8);
    let mut inner = |x: f64| -> [f64; K] {
        // The inner line's part inside the disk.
        let (mut ylo, mut yhi) = (y0, y1);
        if boundary {
            let a = 2.0 * x / g.w - 1.0;
            if a.abs() >= 1.0 {
                return [0.0; K];
            }
            let bmax = (1.0 - a * a).sqrt();
            let (ylo_d, yhi_d) = (0.5 * g.h * (1.0 - bmax), 0.5 * g.h * (1.0 + bmax));
            ylo = ylo.max(ylo_d);
            yhi = yhi.min(yhi_d);
            if ylo >= yhi {
                return [0.0; K];
            }
        }
        roots.clear();
        roots.push(ylo);
        for c in clips {
            if c.line {
                if c.m.y != 0.0 {
                    let b = -c.m.x * (2.0 * x / g.w - 1.0) / c.m.y;
                    let y = 0.5 * g.h * (1.0 - b);
                    if y > ylo && y < yhi {
                        roots.push(y);
                    }
                }
                continue;
            }
            match c.curve {
                Some(curve) => {
                    let start = roots.len();
                    let mut pts = Vec::new();
                    curve.crossings(0, 2.0 * x / g.w - 1.0, &mut pts);
                    roots.extend(
                        pts.iter()
                            .map(|p| 0.5 * g.h * (1.0 - p.y))
                            .filter(|&y| y > ylo && y < yhi),
                    );
                    roots[start..].sort_by(f64::total_cmp);
                }
                None => inner_roots(g, p.face, c.m, x, ylo, yhi, &mut roots, disk),
            }
        }
        if clips.len() > 1 {
            roots[1..].sort_by(f64::total_cmp);
        }
        roots.push(yhi);
        let mut sum = [0.0; K];
        for k in 0..roots.len() - 1 {
            let (a, b) = (roots[k], roots[k + 1]);
            if b <= a || dark(x, 0.5 * (a + b)) {
                continue;
            }
            let v = if ball {
                // b = B sin τ with B = √(1 − a²): the ball's √(1 − r²) = B cos τ is smooth in τ.
                let bmax = (1.0 - (2.0 * x / g.w - 1.0).powi(2)).max(0.0).sqrt();
                let tau = |y: f64| ((1.0 - 2.0 * y / g.h) / bmax).clamp(-1.0, 1.0).asin();
                gl(n, tau(b), tau(a), |t| {
                    let (st, ct) = t.sin_cos();
                    let y = 0.5 * g.h * (1.0 - bmax * st);
                    let (d, j) = g.dir_jac(p.face, x, y);
                    f(d, texture_at(img, p, x, y), j).map(|c| c * 0.5 * g.h * bmax * ct)
                })
            } else {
                gl(n, a, b, |y| {
                    let (d, j) = g.dir_jac(p.face, x, y);
                    f(d, texture_at(img, p, x, y), j)
                })
            };
            for c in 0..K {
                sum[c] += v[c];
            }
        }
        sum
    };
    let mut total = [0.0; K];
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let (v, _) = adaptive(n, 0.0, 1.0, tol, MAX_INTERVALS, &mut |u| {
            let (x, dx) = substitute(a, b, u, disk, disk);
            inner(x).map(|c| c * dx)
        });
        for c in 0..K {
            total[c] += v[c];
        }
    }
    total
}

/// `u ∈ [0, 1]` → `y ∈ [a, b]` and `dy/du`: linear, or the smoothstep `a + L(3u² − 2u³)` at the
/// ends flagged singular (it turns `√(end − y)` behaviour into a polynomial in u).
#[inline]
fn substitute(a: f64, b: f64, u: f64, lo: bool, hi: bool) -> (f64, f64) {
    let l = b - a;
    match (lo, hi) {
        (false, false) => (a + l * u, l),
        (true, true) => (a + l * u * u * (3.0 - 2.0 * u), 6.0 * l * u * (1.0 - u)),
        (true, false) => (a + l * u * u, 2.0 * l * u),
        (false, true) => (a + l * (2.0 * u - u * u), 2.0 * l * (1.0 - u)),
    }
}

/// Roots of `m·d(x, ·)` strictly inside `(ylo, yhi)`, appended in increasing order.
#[allow(clippy::too_many_arguments)]
fn inner_roots(
    g: &Geometry,
    face: u32,
    m: DVec3,
    x: f64,
    ylo: f64,
    yhi: f64,
    out: &mut Vec<f64>,
    disk: bool,
) {
    let start = out.len();
    match g.format {
        DomeFormat::LatLong => {
            // m·d = m_y cos θ + c sin θ = R cos(θ − α), zero at θ = α ± π/2 (mod π).
            let phi = PI - 2.0 * PI * x / g.w;
            let c = m.x * phi.sin() + m.z * phi.cos();
            if c == 0.0 && m.y == 0.0 {
                return;
            }
            let alpha = c.atan2(m.y);
            for th in [alpha - 0.5 * PI, alpha + 0.5 * PI, alpha + 1.5 * PI] {
                let y = th * g.h / PI;
                if y > ylo && y < yhi {
                    out.push(y);
                }
            }
        }
        DomeFormat::Cross => {
            // m·(F + aR + bU) = 0 is a line in the face's (a, b).
            let (f, r, u, blk) = texture::cross_basis(face);
            let a = 2.0 * (x - blk.x * g.n) / g.n - 1.0;
            let mu = m.dot(u);
            if mu != 0.0 {
                let b = -(m.dot(f) + a * m.dot(r)) / mu;
                let y = blk.y * g.n + 0.5 * g.n * (1.0 - b);
                if y > ylo && y < yhi {
                    out.push(y);
                }
            }
        }
        _ => {
            debug_assert!(disk);
            let mut found = Vec::with_capacity(4);
            sign_change_roots(
                &mut |y| m.dot(g.dir_jac(face, x, y).0),
                ylo,
                yhi,
                8,
                &mut found,
            );
            out.extend(found.into_iter().filter(|&y| y > ylo && y < yhi));
        }
    }
    out[start..].sort_by(f64::total_cmp);
}
