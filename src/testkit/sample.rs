//! The light samplers' internals that the GPU-vs-CPU sample conformance test looks into
//! (tests/sample_conformance.rs): the generator's uniforms and how far a draw lies from a
//! discontinuity of the sampler map, where an f32 rounding legitimately sends the GPU's draw
//! elsewhere.

use glam::DVec3;

use crate::cpu::dvec;
use crate::cpu::sample::LightAt;
use crate::cpu::sample::rect::RectSampler;
use crate::query::Reference;

pub use crate::cpu::sample::rng::{pcg_hash, uniform};

/// How far the draw for `u` of the light at the receiver `x` (normal `n`) lies from a
/// discontinuity of the sampler map itself (dimensionless; `f64::INFINITY` where the map is
/// smooth), the sample's counterpart of the radiance band:
/// - a sheared rect: `|u[0] − p₁|`, p₁ the first triangle's share (Arvo's two triangles meet
///   there, and the f32 share differs from the f64 one by ~1e-7);
/// - a cone (sphere, spot, distant), an ellipsoid's local cone and a cosine-weighted dome:
///   `|axis.z|`, where Duff et al.'s frame flips with the sign of z (the f32 axis may have the
///   other sign within its rounding, and then every azimuth differs);
/// - a shaped sphere: `|Ω_spot / Ω_ball − 1|`, where the choice between the two cones flips;
/// - a cylinder: the sample's distance from the visible band's edge, `min(u[1], 1 − u[1])`
///   (the silhouette, where the density `∝ 1/cos` is unbounded).
pub fn sampler_margin(r: &Reference, x: [f32; 3], n: Option<[f32; 3]>, u: [f64; 2]) -> f64 {
    let p = &r.p;
    let x = dvec(x);
    let n = n.map(|n| dvec(n).normalize());
    let at = LightAt::new(p, None, x, n);
    if at.is_delta() {
        return f64::INFINITY;
    }
    match at {
        LightAt::Rect(RectSampler::Triangles(t1, _, total)) => {
            let p1 = t1.map_or(0.0, |t| t.solid_angle) / total;
            (u[0] - p1).abs()
        }
        LightAt::Cone(c) => {
            let mut m = c.axis.z.abs();
            if let (Some(s), Some(sh)) = (p.similarity, &p.shaping) {
                let w = p.origin - x;
                let d = w.length();
                let ball = crate::cpu::sample::cone::Cone::subtended(w / d, 1.0 * s * radius(p), d);
                let spot = crate::cpu::sample::cone::Cone::with_angle(-p.axis, sh.cone);
                m = m.min((spot.solid_angle() / ball.solid_angle() - 1.0).abs());
            }
            m
        }
        LightAt::Ellipsoid { xl, .. } => (xl.z / xl.length()).abs(),
        LightAt::Dome { n: Some(n), .. } => n.z.abs(),
        LightAt::Cylinder { .. } => u[1].min(1.0 - u[1]),
        _ => f64::INFINITY,
    }
}

fn radius(p: &crate::prepare::Prepared) -> f64 {
    match p.light.kind {
        crate::model::LightType::Sphere { radius, .. } => radius,
        _ => 0.0,
    }
}

/// The angle between two directions (radians), accurate near 0.
pub fn angle(a: DVec3, b: DVec3) -> f64 {
    let (a, b) = (a.normalize(), b.normalize());
    a.cross(b).length().atan2(a.dot(b))
}
