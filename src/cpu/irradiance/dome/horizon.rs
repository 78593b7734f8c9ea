//! A receiver's horizon great circle drawn on a mirroredBall or angular image, cut into
//! monotone segments: its crossings with the inner lines and edges of the pieces.

use glam::{DVec2, DVec3};

use super::pieces::TAU;
use crate::cpu::texture;
use crate::prepare::texture::DomeFormat;

/// A receiver's horizon great circle `m·d = 0` drawn on a disk image (§6 D3/D4, "bisected" in
/// DESIGN.md's words): `γ ↦ (a, b)` of `d(γ) = cos γ·e₁ + sin γ·e₂`, sampled adaptively (image
/// steps ≤ 0.01), cut at the extrema of `a` and of `b` (refined by golden-section search) into
/// monotone segments, on which `a(γ) = a₀` or `b(γ) = b₀` has exactly one solution (regula falsi).
/// This finds every root of the horizon on an inner line and every point where it turns (a
/// vertical tangent) or crosses a piece edge, which sampling alone could miss.
pub struct HorizonCurve {
    format: DomeFormat,
    e1: DVec3,
    e2: DVec3,
    /// Per coordinate (a, b): monotone segments (γ₀, γ₁, v₀, v₁), γ₁ > γ₀.
    segments: [Vec<(f64, f64, f64, f64)>; 2],
    /// The adaptive samples `(γ, (a, b))` over `[0, 4π)` (the circle twice, so that every
    /// segment's samples are one run), and per coordinate and segment the run of them strictly
    /// inside it: a crossing is bracketed between two neighbours before it is solved.
    samples: Vec<(f64, DVec2)>,
    runs: [Vec<(usize, usize)>; 2],
}

impl HorizonCurve {
    pub fn new(format: DomeFormat, m: DVec3) -> HorizonCurve {
        let mh = m.normalize();
        let e1 = mh.any_orthonormal_vector();
        let e2 = mh.cross(e1);
        let mut c = HorizonCurve {
            format,
            e1,
            e2,
            segments: [vec![], vec![]],
            samples: vec![],
            runs: [vec![], vec![]],
        };
        let tau = TAU;
        let mut g: Vec<f64> = (0..=512).map(|k| tau * k as f64 / 512.0).collect();
        let mut k = 0;
        while k + 1 < g.len() {
            let (g0, g1) = (g[k], g[k + 1]);
            if (c.point(g1) - c.point(g0)).length() > 0.01 && g1 - g0 > 1e-12 && g.len() < 1 << 16 {
                g.insert(k + 1, 0.5 * (g0 + g1));
            } else {
                k += 1;
            }
        }
        let pts: Vec<DVec2> = g.iter().map(|&x| c.point(x)).collect();
        for axis in 0..2 {
            let v = |i: usize| pts[i % (pts.len() - 1)][axis];
            let n = pts.len() - 1;
            let mut ext = vec![];
            for i in 0..n {
                let (prev, cur, next) = (v(i + n - 1), v(i), v(i + 1));
                if (cur - prev) * (next - cur) < 0.0 || (cur == prev && next != cur) {
                    let lo = if i == 0 { g[n - 1] - tau } else { g[i - 1] };
                    ext.push(c.extremum(axis, lo, g[i + 1], next < cur));
                }
            }
            ext.sort_by(f64::total_cmp);
            if ext.len() >= 2 {
                let first = ext[0];
                ext.push(first + tau);
                c.segments[axis] = ext
                    .windows(2)
                    .map(|w| (w[0], w[1], c.point(w[0])[axis], c.point(w[1])[axis]))
                    .collect();
            }
        }
        let n = pts.len() - 1;
        c.samples = (0..2 * n)
            .map(|i| (g[i % n] + tau * (i / n) as f64, pts[i % n]))
            .collect();
        for axis in 0..2 {
            c.runs[axis] = c.segments[axis]
                .iter()
                .map(|&(g0, g1, _, _)| {
                    let first = c.samples.partition_point(|s| s.0 <= g0);
                    (first, first.max(c.samples.partition_point(|s| s.0 < g1)))
                })
                .collect();
        }
        c
    }

    /// Image point (a, b) of the horizon at γ.
    pub fn point(&self, g: f64) -> DVec2 {
        let d = g.cos() * self.e1 + g.sin() * self.e2;
        let st = if self.format == DomeFormat::MirroredBall {
            texture::mirrored_ball_st(d)
        } else {
            texture::angular_st(d)
        };
        DVec2::new(2.0 * st.x - 1.0, 1.0 - 2.0 * st.y)
    }

    /// Golden-section search for the maximum (or minimum) of coordinate `axis` on `[lo, hi]`.
    fn extremum(&self, axis: usize, mut lo: f64, mut hi: f64, max: bool) -> f64 {
        let f = |g: f64| {
            if max {
                self.point(g)[axis]
            } else {
                -self.point(g)[axis]
            }
        };
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
        let (mut f1, mut f2) = (f(x1), f(x2));
        for _ in 0..80 {
            if hi - lo < 1e-15 {
                break;
            }
            if f1 < f2 {
                lo = x1;
                (x1, f1) = (x2, f2);
                x2 = lo + r * (hi - lo);
                f2 = f(x2);
            } else {
                hi = x2;
                (x2, f2) = (x1, f1);
                x1 = hi - r * (hi - lo);
                f1 = f(x1);
            }
        }
        0.5 * (lo + hi)
    }

    /// Every horizon point whose coordinate `axis` equals `v`, appended as (a, b). On each
    /// monotone segment the samples inside it bracket the crossing to one sample step first
    /// (a binary search: it ends between two neighbours across which `coordinate − v` changes
    /// sign, whatever the samples), then regula falsi (Illinois) solves it there.
    pub fn crossings(&self, axis: usize, v: f64, out: &mut Vec<DVec2>) {
        for (&(g0, g1, v0, v1), &(first, last)) in self.segments[axis].iter().zip(&self.runs[axis])
        {
            if (v0 - v) * (v1 - v) < 0.0 {
                let below = v0 < v;
                let run = &self.samples[first..last];
                let k = run.partition_point(|s| (s.1[axis] < v) == below);
                let (a, fa) = match k {
                    0 => (g0, v0 - v),
                    _ => (run[k - 1].0, run[k - 1].1[axis] - v),
                };
                let (b, fb) = match run.get(k) {
                    Some(s) => (s.0, s.1[axis] - v),
                    None => (g1, v1 - v),
                };
                let g = if fb == 0.0 {
                    b
                } else {
                    // The segment's own stopping width (what solving on the whole segment
                    // stopped at), at least a few ulps of γ: the bracket is far narrower.
                    let tol = (1e-15 * (g1 - g0)).max(4.0 * f64::EPSILON * b.abs()) + 1e-300;
                    let f = &mut |g| self.point(g)[axis] - v;
                    super::quadrature::illinois_to(f, a, b, fa, fb, tol)
                };
                out.push(self.point(g));
            }
        }
    }

    /// The `a` values where the curve turns (vertical tangents in the image).
    pub fn a_extrema(&self) -> impl Iterator<Item = f64> + '_ {
        self.segments[0].iter().map(|s| s.2)
    }
}
