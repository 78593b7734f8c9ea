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
///   a shaped rect likewise `|Ω_spot / Ω_rect − 1|`;
/// - a cylinder: the sample's distance from the visible band's edge, `min(u[1], 1 − u[1])`
///   (the silhouette, where the density `∝ 1/cos` is unbounded), and the receiver's height
///   over its surface, `(ρ − r)/ρ` scaled by [`SURFACE_SCALE`];
/// - a rect or disk: the receiver's elevation over the light's plane (its sine, seen from the
///   light's centre) scaled by [`SURFACE_SCALE`];
/// - a textured dome: the draw's distance from its texel's edge in the texel's chart,
///   `min(u[0], 1 − u[0], u[1], 1 − u[1])` (the density jumps from texel to texel).
pub fn sampler_margin(r: &Reference, x: [f32; 3], n: Option<[f32; 3]>, u: [f64; 2]) -> f64 {
    let p = &r.p;
    let x = dvec(x);
    let n = n.map(|n| dvec(n).normalize());
    if p.dome_texture().is_some() {
        // The point within the drawn texel's chart comes from u: this close to a texel edge the
        // f32 direction's lookup may name the neighbouring texel, whose density differs.
        return u[0].min(1.0 - u[0]).min(u[1]).min(1.0 - u[1]);
    }
    let at = LightAt::new(p, None, x, n);
    if at.is_delta() {
        return f64::INFINITY;
    }
    match at {
        LightAt::Rect(RectSampler::Triangles(t1, _, total)) => {
            let p1 = t1.map_or(0.0, |t| t.solid_angle) / total;
            (u[0] - p1).abs().min(rect_spot_tie(p, x))
        }
        LightAt::Rect(_) => rect_spot_tie(p, x),
        LightAt::Cone(c) => {
            let mut m = c.axis.z.abs().min(rect_spot_tie(p, x));
            if let (Some(s), Some(sh), true) = (p.similarity, &p.shaping, radius(p) > 0.0) {
                let w = p.origin - x;
                let d = w.length();
                let ball = crate::cpu::sample::cone::Cone::subtended(w / d, s * radius(p), d);
                let spot = crate::cpu::sample::cone::Cone::with_angle(-p.axis, sh.cone);
                m = m.min((spot.solid_angle() / ball.solid_angle() - 1.0).abs());
            }
            m
        }
        LightAt::Ellipsoid { xl, .. } => (xl.z / xl.length()).abs(),
        LightAt::Dome { n: Some(n), .. } => n.z.abs(),
        LightAt::Cylinder { xl, r, .. } => {
            let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
            u[1].min(1.0 - u[1]).min((rho - r) / rho * SURFACE_SCALE)
        }
        _ => f64::INFINITY,
    }
    .min(match at {
        LightAt::Rect(_) | LightAt::Disk { .. } => {
            let w = x - p.origin;
            w.dot(p.normal).abs() / w.length() * SURFACE_SCALE
        }
        _ => f64::INFINITY,
    })
}

/// A shaped rect's `|Ω_spot / Ω_rect − 1|`, where its choice between the rect and the spot
/// cone flips (∞ for other lights).
fn rect_spot_tie(p: &crate::prepare::Prepared, x: DVec3) -> f64 {
    let (crate::model::LightType::Rect { width, height }, Some(sh)) = (&p.light.kind, &p.shaping)
    else {
        return f64::INFINITY;
    };
    let corner = p.origin + p.linear * DVec3::new(-width / 2.0, -height / 2.0, 0.0);
    let e1 = p.linear * DVec3::new(*width, 0.0, 0.0);
    let e2 = p.linear * DVec3::new(0.0, *height, 0.0);
    match RectSampler::new(x, corner, e1, e2) {
        Some(r) => {
            let spot = crate::cpu::sample::cone::Cone::with_angle(-p.axis, sh.cone);
            (spot.solid_angle() / r.solid_angle() - 1.0).abs()
        }
        None => f64::INFINITY,
    }
}

/// The scale of the receiver's own margins in [`sampler_margin`]: a density that depends on the
/// receiver's height over a rect's or disk's plane (the triple product, cos θ_l), or over a
/// cylinder's surface (the band's half-width β ≈ √(2(ρ − r)/ρ)), carries the f32 rounding of
/// that height, ~2e-7 of the distance, relative to the height: 1e-4 of the density at a height
/// of 2e-3 of the distance (measured on lavapipe: 5e-5 at 2.5e-3, the receiver's local position
/// rounding with it); the margin is 1e-4 at 1e-2 of the distance.
const SURFACE_SCALE: f64 = 0.01;

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

/// For a textured dome of a disk format (mirroredBall, angular): how well f32 holds the density
/// at the chart point of world direction `w` (`EnvTable::rim_margin`, chart units: the chord
/// through the texel times the rim's `h/|a|`); `f64::INFINITY` for every other light. The
/// density's relative error on the GPU is the f32 chart coordinate's error (~1e-7) over it.
pub fn rim_margin(r: &Reference, w: [f32; 3]) -> f64 {
    let Some(t) =
        r.p.dome_texture()
            .and_then(crate::prepare::env_table::EnvTable::new)
    else {
        return f64::INFINITY;
    };
    let v = t.frame.inv * dvec(w).normalize();
    let (k, q) = crate::cpu::sample::dome::locate(&t, v.normalize());
    t.rim_margin(k, q)
}

/// The radiance conformance's comparison floor for the light along world direction `w`
/// ([`crate::conformance::band::texture_floor`]: for a textured dome, the largest texel the
/// lookup may blend there; 0 for other lights).
pub fn radiance_floor(r: &Reference, w: [f32; 3]) -> f64 {
    crate::conformance::band::texture_floor(&r.p, dvec(w))
}
