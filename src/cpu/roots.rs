//! Root finding for the irradiance quadrature's breakpoints (f64). Twin of
//! `shaders/shared/roots.wgsl`.
//!
//! Every breakpoint of the chart quadrature (`cpu::irradiance`) is where a line or an elliptic
//! arc of the chart meets a kink surface of the integrand: the receiver's horizon or the focus
//! plane (planes through x) or a cone of emission directions around the light's axis (the
//! shaping's cone edge and smoothstep start). Lines meet planes and cones in closed form
//! (linear and quadratic equations); arcs meet planes in closed form (`A cos t + B sin t = C`)
//! and cones by bracketing and bisection ([`bracket_roots`]).

use arrayvec::ArrayVec;
use glam::DVec3;
use std::f64::consts::PI;

/// Roots of A cos t + B sin t = C.
pub fn lin_trig_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    let r = a.hypot(b);
    if !(r > 0.0) || c.abs() > r {
        return vec![];
    }
    let phi = b.atan2(a);
    let d = (c / r).clamp(-1.0, 1.0).acos();
    vec![phi + d, phi - d]
}

/// t wrapped into [t0, t0 + 2π).
pub fn wrap_into(t: f64, t0: f64) -> f64 {
    t0 + (t - t0).rem_euclid(2.0 * PI)
}

/// Real roots of qa·t² + 2·qb·t + qc = 0 (numerically stable).
pub fn quadratic_roots(qa: f64, qb: f64, qc: f64) -> ArrayVec<f64, 2> {
    let mut out = ArrayVec::new();
    if qa == 0.0 {
        if qb != 0.0 {
            out.push(-qc / (2.0 * qb));
        }
        return out;
    }
    let disc = qb * qb - qa * qc;
    if disc < 0.0 {
        return out;
    }
    let q = -(qb + qb.signum() * disc.sqrt());
    if q == 0.0 {
        out.push(0.0);
        return out;
    }
    out.extend([q / qa, qc / q]);
    out
}

/// X where w = a + X e1 lies on the kink cone −ŵ·axis = cos (the correct nappe only):
/// `(w·axis)² = cos²|w|²` is quadratic in X.
pub fn cone_roots_on_line(axis: DVec3, cos: f64, a: DVec3, e1: DVec3) -> ArrayVec<f64, 2> {
    let c2 = cos * cos;
    let (aa, ea) = (a.dot(axis), e1.dot(axis));
    let qa = ea * ea - c2 * e1.length_squared();
    let qb = aa * ea - c2 * a.dot(e1);
    let qc = aa * aa - c2 * a.length_squared();
    let mut out = ArrayVec::new();
    for xk in quadratic_roots(qa, qb, qc) {
        let wa = -(aa + xk * ea);
        if wa * cos > 0.0 {
            out.push(xk);
        }
    }
    out
}

/// Unit vectors w in the plane m·w = 0 with −ŵ·axis = cos.
pub fn plane_cone_dirs(m: DVec3, axis: DVec3, cos: f64) -> Vec<DVec3> {
    let ml = m.length();
    if !(ml > 0.0) {
        return vec![];
    }
    let (h1, h2) = (m / ml).any_orthonormal_pair();
    let (pa, pb) = (h1.dot(axis), h2.dot(axis));
    lin_trig_roots(pa, pb, -cos)
        .into_iter()
        .map(|s| h1 * s.cos() + h2 * s.sin())
        .collect()
}

/// The planes through the origin that contain the direction `d` and are tangent to the cone of
/// unit `axis` and cosine `cos`: unit normals m ⊥ d with |m·axis| = sin θ. None where no such
/// plane exists (the line of d runs inside the cone). The CPU's rules split there: a pencil of
/// lines along d meets the cone in two roots that appear together at these planes, so the
/// integral across the lines has a square-root point there (`critical::pencil_tangent_ys`,
/// `rect_fast`'s `kink_cuts`). CPU only: the WGSL `pencil_tangent_ys` inlines it.
pub fn pencil_tangent_normals(d: DVec3, axis: DVec3, cos: f64) -> Option<[DVec3; 2]> {
    let s = (1.0 - cos * cos).max(0.0).sqrt();
    let (m1, m2) = d.normalize().any_orthonormal_pair();
    let (pa, pb) = (m1.dot(axis), m2.dot(axis));
    let ra = pa.hypot(pb);
    if !(ra >= s && ra > 0.0) {
        return None;
    }
    let t0 = pb.atan2(pa);
    let dt = (s / ra).clamp(-1.0, 1.0).acos();
    Some([t0 + dt, t0 - dt].map(|t| m1 * t.cos() + m2 * t.sin()))
}

/// X where w = a + X e1 makes its smallest (or largest) angle with the axis: the stationary
/// point of ŵ·axis, `(e1·p)|w|² = (w·p)(w·e1)`, which is linear in X.
pub fn axis_approach(axis: DVec3, a: DVec3, e1: DVec3) -> Option<f64> {
    let (ap, ep, ae) = (a.dot(axis), e1.dot(axis), a.dot(e1));
    let den = ep * ae - ap * e1.length_squared();
    (den != 0.0).then(|| (ap * ae - ep * a.length_squared()) / den)
}

/// Roots of a smooth periodic function on [t0, t1] given as `f(t) = (value, derivative)`, by
/// bracketing on a uniform grid of `samples` intervals, with a check of each interval's
/// interior extremum for pairs of roots, then bisection. (The WGSL twin specialises this to
/// the arcs of a chart: `arc_cone_crossings`, `arc_nearest`.)
pub fn bracket_roots(f: &impl Fn(f64) -> (f64, f64), t0: f64, t1: f64, samples: usize) -> Vec<f64> {
    let mut out = Vec::new();
    let h = (t1 - t0) / samples as f64;
    let bisect = |mut lo: f64, mut hi: f64, g: &dyn Fn(f64) -> f64| {
        let glo = g(lo);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                // lo and hi are adjacent doubles: every further step leaves 0.5·(lo + hi) at
                // this mid (it keeps lo and hi, or makes them equal to it), so stopping here
                // returns what the 80 steps return, bit for bit.
                return mid;
            }
            if (g(mid) > 0.0) == (glo > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let val = |t: f64| f(t).0;
    let der = |t: f64| f(t).1;
    // Each sample is evaluated once (the next interval's start is this one's end).
    let mut fb = f(t0);
    for i in 0..samples {
        let (a, b) = (t0 + h * i as f64, t0 + h * (i + 1) as f64);
        let fa = fb;
        fb = f(b);
        if fa.0 == 0.0 {
            out.push(a);
        }
        if (fa.0 > 0.0) != (fb.0 > 0.0) && fa.0 != 0.0 && fb.0 != 0.0 {
            out.push(bisect(a, b, &val));
        } else if fa.1 * fb.1 < 0.0 {
            // An interior extremum: two roots when it crosses zero.
            let te = bisect(a, b, &der);
            let fe = val(te);
            if (fe > 0.0) != (fa.0 > 0.0) && fe != 0.0 {
                out.push(bisect(a, te, &val));
                out.push(bisect(te, b, &val));
            }
        }
    }
    if val(t1) == 0.0 {
        out.push(t1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_and_trig_roots() {
        // t² − 3t + 2 = 0 → 1, 2 (qb is half the linear coefficient).
        let mut r = quadratic_roots(1.0, -1.5, 2.0);
        r.sort_by(f64::total_cmp);
        assert_eq!(r.as_slice(), &[1.0, 2.0]);
        assert!(quadratic_roots(1.0, 0.0, 1.0).is_empty());
        // cos t = 0.5 → ±π/3.
        let r = lin_trig_roots(1.0, 0.0, 0.5);
        assert!(r.iter().any(|t| (t - PI / 3.0).abs() < 1e-15));
        assert!(r.iter().any(|t| (t + PI / 3.0).abs() < 1e-15));
        assert!((wrap_into(-0.5, 0.0) - (2.0 * PI - 0.5)).abs() < 1e-15);
    }

    #[test]
    fn bracketing_finds_paired_roots() {
        // (cos t − 0.99) has two roots ±acos(0.99) inside one grid interval: found through the interior extremum.
        let f = |t: f64| (t.cos() - 0.99, -t.sin());
        let r = bracket_roots(&f, -1.0, 1.0, 1);
        assert_eq!(r.len(), 2, "{r:?}");
        for t in r {
            assert!((t.abs() - 0.99f64.acos()).abs() < 1e-12);
        }
    }
}
