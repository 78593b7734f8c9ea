//! The exact integral of a function of the dome direction over one piece of the filtered
//! texture ([`super::pieces`]), optionally clipped to a receiver's lit half or to a convex
//! intersection of half-spaces (DESIGN.md §6 "Dome and texture irradiance: what 'exact' means";
//! §8 P2 mask mode).
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
//!
//! The clip may be several half-spaces ([`Clip`]; DESIGN.md §8 P2 mask mode, a portal piece seen
//! from a receiver): each inner line is cut at every circle's roots and the parts where all are
//! positive kept, and the outer integral is also split where two circles cross inside the piece
//! (a vertex of the polygon, where the lit part's end switches circle: a kink).

use glam::DVec3;

use super::horizon::HorizonCurve;
use super::pieces::{Domain, Geometry, Line, PI, Piece, texture_at};
use super::quadrature::{adaptive, gl, sign_change_roots};
use crate::cpu::texture;
use crate::prepare::texture::DomeFormat;
use crate::prepare::texture::Image;

/// Most outer sub-intervals per smooth part of a piece (bounds the work of near-singular cases).
const MAX_INTERVALS: usize = 64;

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
    let dark = |line: &Line, y: f64| {
        if clips.is_empty() {
            return false;
        }
        let d = g.dir_jac_on(line, y).0;
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
                    edge_roots(g, p.face, c.m, ye, x0, x1, &mut breaks);
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
        let line = g.line(p.face, x);
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
                None => inner_roots(g, &line, c.m, ylo, yhi, &mut roots, disk),
            }
        }
        if clips.len() > 1 {
            roots[1..].sort_by(f64::total_cmp);
        }
        roots.push(yhi);
        let mut sum = [0.0; K];
        for k in 0..roots.len() - 1 {
            let (a, b) = (roots[k], roots[k + 1]);
            if b <= a || dark(&line, 0.5 * (a + b)) {
                continue;
            }
            let v = if ball {
                // b = B sin τ with B = √(1 − a²): the ball's √(1 − r²) = B cos τ is smooth in τ.
                let bmax = (1.0 - (2.0 * x / g.w - 1.0).powi(2)).max(0.0).sqrt();
                let tau = |y: f64| ((1.0 - 2.0 * y / g.h) / bmax).clamp(-1.0, 1.0).asin();
                gl(n, tau(b), tau(a), |t| {
                    let (st, ct) = t.sin_cos();
                    let y = 0.5 * g.h * (1.0 - bmax * st);
                    let (d, j) = g.dir_jac_on(&line, y);
                    f(d, texture_at(img, p, x, y), j).map(|c| c * 0.5 * g.h * bmax * ct)
                })
            } else {
                gl(n, a, b, |y| {
                    let (d, j) = g.dir_jac_on(&line, y);
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

/// The x in `(x0, x1)` where the circle `m·d = 0` crosses the sheet's horizontal line at
/// height `ye` of `face`, appended (unsorted), in closed form for latlong and cross:
/// - latlong: on the latitude `θ = πy/H`, `m·d = m_y cos θ + R sin θ cos(φ − β)` with
///   `R = √(m_x² + m_z²)`, `β = atan2(m_x, m_z)` (§6 D2's `d = (sin θ sin φ, cos θ, sin θ cos φ)`,
///   `φ = π − 2πx/W`): zero at `φ = β ± acos(−m_y cos θ / (R sin θ))`, each taken to the period
///   of x that holds the piece (a tangency, `|…| = 1`, adds one break where the sign does not
///   change: harmless);
/// - cross: `m·(F + aR + bU) = 0` is a line of the face's `(a, b)`, met once at fixed b;
/// - otherwise sign changes between samples.
///
/// Sampling 16 points per edge for every clip was most of a masked latlong dome's crossed
/// pieces' directions.
fn edge_roots(g: &Geometry, face: u32, m: DVec3, ye: f64, x0: f64, x1: f64, out: &mut Vec<f64>) {
    match g.format {
        DomeFormat::LatLong => {
            let (st, ct) = (PI * ye / g.h).sin_cos();
            let r = m.x.hypot(m.z) * st;
            if !(r > 0.0) {
                return;
            }
            let c = -m.y * ct / r;
            if !(c.abs() <= 1.0) {
                return;
            }
            let (beta, half) = (m.x.atan2(m.z), c.acos());
            for phi in [beta - half, beta + half] {
                let x = g.w * (PI - phi) / (2.0 * PI);
                let x = x - g.w * ((x - x0) / g.w).floor();
                if x > x0 && x < x1 {
                    out.push(x);
                }
            }
        }
        DomeFormat::Cross => {
            let (f, r, u, blk) = texture::cross_basis(face);
            let b = 1.0 - 2.0 * (ye - blk.y * g.n) / g.n;
            let mr = m.dot(r);
            if mr != 0.0 {
                let a = -(m.dot(f) + b * m.dot(u)) / mr;
                let x = blk.x * g.n + 0.5 * g.n * (a + 1.0);
                if x > x0 && x < x1 {
                    out.push(x);
                }
            }
        }
        _ => sign_change_roots(&mut |x| m.dot(g.dir_jac(face, x, ye).0), x0, x1, 16, out),
    }
}

/// Roots of `m·d` along `line` strictly inside `(ylo, yhi)`, appended in increasing order.
fn inner_roots(
    g: &Geometry,
    line: &Line,
    m: DVec3,
    ylo: f64,
    yhi: f64,
    out: &mut Vec<f64>,
    disk: bool,
) {
    let start = out.len();
    match g.format {
        DomeFormat::LatLong => {
            // m·d = m_y cos θ + c sin θ = R cos(θ − α), zero at θ = α ± π/2 (mod π).
            let (sp, cp) = line.phi;
            let c = m.x * sp + m.z * cp;
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
            let (f, r, u, blk) = texture::cross_basis(line.face);
            let a = 2.0 * (line.x - blk.x * g.n) / g.n - 1.0;
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
                &mut |y| m.dot(g.dir_jac_on(line, y).0),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::Rng;

    /// The closed-form edge crossings are those a dense sampling of the edge finds (4,096
    /// intervals, refined), on latlong maps (pieces straddling the seam included) and on every
    /// face of a cross, for random circles.
    #[test]
    fn edge_roots_in_closed_form_are_the_sampled_ones() {
        let mut rng = Rng::new(17);
        let mut found = 0;
        for (format, w, h) in [
            (DomeFormat::LatLong, 8, 4),
            (DomeFormat::LatLong, 64, 32),
            (DomeFormat::Cross, 12, 16),
        ] {
            let g = Geometry::new(format, w, h);
            for _ in 0..4000 {
                let m = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let (face, x0, ye) = if format == DomeFormat::Cross {
                    let face = rng.below(6) as u32;
                    let blk = texture::cross_basis(face).3;
                    let x0 = blk.x * g.n + rng.range(0.0, 0.8) * g.n;
                    (face, x0, blk.y * g.n + rng.f64() * g.n)
                } else {
                    (0, rng.range(-1.0, g.w + 1.0), rng.f64() * g.h)
                };
                let x1 = x0 + rng.range(0.01, 0.2) * g.w.min(g.n.max(1.0) * 3.0);
                let mut want = vec![];
                sign_change_roots(
                    &mut |x| m.dot(g.dir_jac(face, x, ye).0),
                    x0,
                    x1,
                    4096,
                    &mut want,
                );
                let mut got = vec![];
                edge_roots(&g, face, m, ye, x0, x1, &mut got);
                got.sort_by(f64::total_cmp);
                assert_eq!(
                    got.len(),
                    want.len(),
                    "{format:?} m {m} y {ye} x {x0}..{x1}: {got:?} vs {want:?}"
                );
                for (a, b) in got.iter().zip(&want) {
                    assert!(
                        (a - b).abs() <= 1e-9 * g.w,
                        "{format:?}: {got:?} vs {want:?}"
                    );
                }
                found += got.len();
            }
        }
        assert!(found > 1000, "only {found} crossings: the test saw too few");
    }
}
