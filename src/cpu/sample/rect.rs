//! Directions uniform in the solid angle a RectLight subtends (f64), DESIGN.md §9 S2: the
//! spherical rectangle of Ureña, Fajardo & King, "An Area-Preserving Parametrization for
//! Spherical Rectangles" (EGSR 2013, Algorithms 1–2) when the world shape is a rectangle, and
//! two spherical triangles of Arvo, "Stratified Sampling of Spherical Triangles" (SIGGRAPH 1995,
//! Figure 2) when a shear makes it a parallelogram. Either way the density is `1/Ω`.

use glam::DVec3;
use std::f64::consts::PI;

/// A rectangle (corner `s`, unit orthogonal edges `ex`, `ey` of lengths `lx`, `ly`) seen from
/// `o`, set up for Ureña's parametrization (2013, Algorithm 1).
#[derive(Clone, Copy, Debug)]
pub struct SphericalRect {
    o: DVec3,
    x: DVec3,
    y: DVec3,
    z: DVec3,
    z0: f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    b0: f64,
    b1: f64,
    k: f64,
    /// The solid angle Ω.
    pub solid_angle: f64,
}

impl SphericalRect {
    /// `None` when `o` lies in the rectangle's plane (it subtends nothing).
    pub fn new(o: DVec3, s: DVec3, ex: DVec3, ey: DVec3, lx: f64, ly: f64) -> Option<Self> {
        let (x, y) = (ex, ey);
        let mut z = x.cross(y);
        let d = s - o;
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        if !(z0 < 0.0) {
            return None;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + lx, y0 + ly);
        let v00 = DVec3::new(x0, y0, z0);
        let v01 = DVec3::new(x0, y1, z0);
        let v10 = DVec3::new(x1, y0, z0);
        let v11 = DVec3::new(x1, y1, z0);
        // The inner normals of the four great circles through the edges.
        let n0 = v00.cross(v10).normalize();
        let n1 = v10.cross(v11).normalize();
        let n2 = v11.cross(v01).normalize();
        let n3 = v01.cross(v00).normalize();
        // Interior angles; Ω = Σγ − 2π (Girard).
        let angle = |a: DVec3, b: DVec3| (-a.dot(b)).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        if !(solid_angle > 0.0) {
            return None;
        }
        Some(SphericalRect {
            o,
            x,
            y,
            z,
            z0,
            x0,
            x1,
            y0,
            y1,
            b0: n0.z,
            b1: n2.z,
            k,
            solid_angle,
        })
    }

    /// The point of the rectangle for `u ∈ [0,1)²` (Ureña 2013, Algorithm 2): `u[0]` fixes the
    /// sub-rectangle of solid angle `u[0]·Ω` (its edge xu), `u[1]` the height along it, both
    /// area-preserving, so the direction toward the point is uniform in solid angle.
    pub fn sample_point(&self, u: [f64; 2]) -> DVec3 {
        let au = u[0] * self.solid_angle + self.k;
        let (sa, ca) = au.sin_cos();
        let fu = (ca * self.b0 - self.b1) / sa;
        let cu = (1f64.copysign(fu) / (fu * fu + self.b0 * self.b0).sqrt()).clamp(-1.0, 1.0);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(self.x0, self.x1);
        let d = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (d * d + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (d * d + self.y1 * self.y1).sqrt();
        let hv = h0 + u[1] * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-14 {
            (hv * d / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1)
        } else {
            self.y1
        };
        self.o + xu * self.x + yv * self.y + self.z0 * self.z
    }
}

/// A spherical triangle (unit vertex directions `a`, `b`, `c` from the receiver), set up for
/// Arvo's sampling (1995, Figure 2).
#[derive(Clone, Copy, Debug)]
pub struct SphericalTriangle {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    alpha: f64,
    cos_c: f64,
    /// The solid angle Ω = α + β + γ − π (Girard).
    pub solid_angle: f64,
}

impl SphericalTriangle {
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Option<Self> {
        let nab = a.cross(b).normalize();
        let nac = a.cross(c).normalize();
        let nbc = b.cross(c).normalize();
        // The angle at a vertex is the dihedral angle of the two great circles through it.
        let alpha = nab.dot(nac).clamp(-1.0, 1.0).acos();
        let beta = (-nab.dot(nbc)).clamp(-1.0, 1.0).acos();
        let gamma = nac.dot(nbc).clamp(-1.0, 1.0).acos();
        let solid_angle = alpha + beta + gamma - PI;
        (solid_angle > 0.0 && solid_angle.is_finite()).then_some(SphericalTriangle {
            a,
            b,
            c,
            alpha,
            cos_c: a.dot(b),
            solid_angle,
        })
    }

    /// A direction uniform in the triangle (Arvo 1995): `u[0]` chooses the sub-triangle
    /// A B Ĉ of area `u[0]·Ω` (Ĉ on the arc AC), `u[1]` the point on the arc B Ĉ by the
    /// cosine of its distance from B.
    pub fn sample(&self, u: [f64; 2]) -> DVec3 {
        let (sin_a, cos_a) = self.alpha.sin_cos();
        let (s, t) = (u[0] * self.solid_angle - self.alpha).sin_cos();
        let uu = t - cos_a;
        let vv = s + sin_a * self.cos_c;
        let q = (((vv * t - uu * s) * cos_a - vv) / ((vv * s + uu * t) * sin_a)).clamp(-1.0, 1.0);
        let c_hat = q * self.a + (1.0 - q * q).max(0.0).sqrt() * ortho(self.c, self.a);
        let z = 1.0 - u[1] * (1.0 - c_hat.dot(self.b));
        (z * self.b + (1.0 - z * z).max(0.0).sqrt() * ortho(c_hat, self.b)).normalize()
    }
}

/// The unit component of `v` orthogonal to the unit `w`.
fn ortho(v: DVec3, w: DVec3) -> DVec3 {
    (v - v.dot(w) * w).normalize_or_zero()
}

/// The solid angle of a planar parallelogram from `o`: how the rect sampler is chosen and
/// what its density is.
#[derive(Clone, Copy, Debug)]
pub enum RectSampler {
    Rect(SphericalRect),
    /// The two triangles (corner, corner + e1, corner + e1 + e2) and (corner, corner + e1 + e2,
    /// corner + e2), with their total solid angle.
    Triangles(Option<SphericalTriangle>, Option<SphericalTriangle>, f64),
}

impl RectSampler {
    /// The parallelogram with corner `s` and edges `e1`, `e2` (world), seen from `o`.
    pub fn new(o: DVec3, s: DVec3, e1: DVec3, e2: DVec3) -> Option<RectSampler> {
        let (l1, l2) = (e1.length(), e2.length());
        if !(l1 > 0.0 && l2 > 0.0) {
            return None;
        }
        if !crate::prepare::is_sheared(e1, e2) {
            // A rectangle in the world (the transform does not shear it): Ureña.
            let ey = (e2 - e1 * (e1.dot(e2) / (l1 * l1))).normalize();
            return SphericalRect::new(o, s, e1 / l1, ey, l1, l2).map(RectSampler::Rect);
        }
        let dir = |p: DVec3| (p - o).normalize();
        let (a, b, c, d) = (dir(s), dir(s + e1), dir(s + e1 + e2), dir(s + e2));
        let t1 = SphericalTriangle::new(a, b, c);
        let t2 = SphericalTriangle::new(a, c, d);
        let total = t1.map_or(0.0, |t| t.solid_angle) + t2.map_or(0.0, |t| t.solid_angle);
        (total > 0.0).then_some(RectSampler::Triangles(t1, t2, total))
    }

    /// The solid angle Ω the density `1/Ω` is taken over.
    pub fn solid_angle(&self) -> f64 {
        match self {
            RectSampler::Rect(r) => r.solid_angle,
            RectSampler::Triangles(_, _, total) => *total,
        }
    }

    /// A unit direction from `o` uniform in the solid angle.
    pub fn sample(&self, o: DVec3, u: [f64; 2]) -> DVec3 {
        match self {
            RectSampler::Rect(r) => (r.sample_point(u) - o).normalize(),
            RectSampler::Triangles(t1, t2, total) => {
                // The first triangle with probability Ω₁/Ω, u[0] rescaled to stay uniform.
                let p1 = t1.map_or(0.0, |t| t.solid_angle) / total;
                match (t1, t2) {
                    (Some(t1), _) if u[0] < p1 => t1.sample([u[0] / p1, u[1]]),
                    (_, Some(t2)) => t2.sample([((u[0] - p1) / (1.0 - p1)).clamp(0.0, 1.0), u[1]]),
                    (Some(t1), None) => t1.sample(u),
                    (None, None) => o.normalize_or_zero(),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::Rng;

    /// Van Oosterom & Strackee's solid angle of a triangle (IEEE Trans. Biomed. Eng. 30(2),
    /// 1983): an independent check of Girard's formula used by both samplers.
    fn oosterom(a: DVec3, b: DVec3, c: DVec3) -> f64 {
        let num = a.dot(b.cross(c)).abs();
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * num.atan2(den)
    }

    #[test]
    fn solid_angles_match_van_oosterom() {
        let o = DVec3::new(0.3, -2.0, 0.7);
        let s = DVec3::new(-1.0, 0.0, -0.5);
        let (e1, e2) = (DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 1.0));
        let want = oosterom(s - o, s + e1 - o, s + e1 + e2 - o)
            + oosterom(s - o, s + e1 + e2 - o, s + e2 - o);
        let r = RectSampler::new(o, s, e1, e2).unwrap();
        assert!(matches!(r, RectSampler::Rect(_)));
        assert!(
            (r.solid_angle() / want - 1.0).abs() < 1e-12,
            "{} {want}",
            r.solid_angle()
        );
        // Sheared: the triangles.
        let e2s = DVec3::new(0.6, 0.0, 1.0);
        let want = oosterom(s - o, s + e1 - o, s + e1 + e2s - o)
            + oosterom(s - o, s + e1 + e2s - o, s + e2s - o);
        let t = RectSampler::new(o, s, e1, e2s).unwrap();
        assert!(matches!(t, RectSampler::Triangles(..)));
        assert!((t.solid_angle() / want - 1.0).abs() < 1e-12);
    }

    /// Every sample lands on the parallelogram, and the fraction landing in its left half (a
    /// sub-parallelogram) equals that half's solid angle over the whole (5σ, 10⁵ samples).
    #[test]
    fn samples_land_on_the_shape_with_area_preserving_density() {
        let o = DVec3::new(0.3, -2.0, 0.7);
        let s = DVec3::new(-1.0, 0.0, -0.5);
        let e1 = DVec3::new(2.0, 0.0, 0.0);
        for e2 in [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.6, 0.0, 1.0)] {
            let r = RectSampler::new(o, s, e1, e2).unwrap();
            let half =
                RectSampler::new(o, s, e1 * 0.5, e2).unwrap().solid_angle() / r.solid_angle();
            let mut rng = Rng::new(11);
            let n = 100_000;
            let mut hits = 0usize;
            for _ in 0..n {
                let w = r.sample(o, [rng.f64(), rng.f64()]);
                // Intersect with the plane y = 0 and read the parallelogram coordinates.
                let t = -o.y / w.y;
                let p = o + t * w - s;
                let b = p.z / e2.z;
                let a = (p.x - b * e2.x) / e1.x;
                assert!(
                    (-1e-9..=1.0 + 1e-9).contains(&a) && (-1e-9..=1.0 + 1e-9).contains(&b),
                    "{a} {b}"
                );
                hits += (a < 0.5) as usize;
            }
            let f = hits as f64 / n as f64;
            let sigma = (half * (1.0 - half) / n as f64).sqrt();
            assert!((f - half).abs() < 5.0 * sigma, "{f} vs {half}");
        }
    }
}
