//! Randomised samples per light for conformance checks, tests and benchmarks: emission
//! directions, radiance rays and irradiance receivers concentrated where a light is interesting
//! (around its axis, its cone edge, its horizon, its silhouette).

use glam::DVec3;

use super::Rng;
use crate::model::{Light, LightType};
use crate::query::Reference;

pub(crate) fn f32x3(v: DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

/// The local-space half extent of a light's shape, for scaling samples.
pub(crate) fn local_extent(l: &Light) -> DVec3 {
    match l.kind {
        LightType::Rect { width, height } => DVec3::new(width / 2.0, height / 2.0, 0.0),
        LightType::Disk { radius } => DVec3::new(radius, radius, 0.0),
        LightType::Sphere { radius, .. } => DVec3::splat(radius),
        LightType::Cylinder { length, radius, .. } => DVec3::new(length / 2.0, radius, radius),
        LightType::Distant { .. } | LightType::Dome => DVec3::ONE,
        LightType::Mesh { ref geometry, .. } => {
            let r = geometry
                .triangles
                .iter()
                .flat_map(|t| t.p)
                .map(|v| (v - l.origin()).abs())
                .fold(DVec3::ZERO, DVec3::max);
            r.max(DVec3::splat(1e-3))
        }
    }
}

/// Emission directions for one light: half uniform, half concentrated where the light is
/// interesting (around its axis, its cone edge, its horizon).
pub fn emission_samples(r: &Reference, n: usize, rng: &mut Rng) -> Vec<[f32; 3]> {
    let p = &r.p;
    (0..n)
        .map(|i| {
            let e = if i % 2 == 0 {
                rng.unit()
            } else {
                match (&p.light.kind, &p.light.shaping) {
                    (LightType::Distant { .. }, _) => {
                        rng.cone(p.axis, (2.0 * p.distant_half_angle()).max(1e-3))
                    }
                    (_, Some(s)) => rng.cone(
                        p.axis,
                        (1.3 * s.cone_angle.to_radians()).clamp(0.05, std::f64::consts::PI),
                    ),
                    _ => rng.cone(p.axis, std::f64::consts::FRAC_PI_2 * 1.1),
                }
            };
            f32x3(e)
        })
        .collect()
}

/// Radiance rays for one light: origins around the light (up to a few sizes away), aimed at
/// random points of a box slightly larger than the shape, so that hits, misses and silhouettes
/// all occur; for distant lights, rays around the direction toward the light.
pub fn radiance_samples(r: &Reference, n: usize, rng: &mut Rng) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let p = &r.p;
    let l = &p.light;
    let ext = local_extent(l);
    let size = ext.max_element().max(1e-3);
    let mut points = Vec::with_capacity(n);
    let mut dirs = Vec::with_capacity(n);
    for _ in 0..n {
        let (x, w) = match l.kind {
            LightType::Distant { .. } => {
                let x = DVec3::new(
                    rng.range(-10.0, 10.0),
                    rng.range(-10.0, 10.0),
                    rng.range(-10.0, 10.0),
                );
                (
                    x,
                    rng.cone(-p.axis, (2.0 * p.distant_half_angle()).max(1e-3)),
                )
            }
            LightType::Dome => {
                let x = DVec3::new(
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                );
                match &p.portals {
                    // A masked dome (DESIGN.md §8 P2): half the rays aim at a point on or just
                    // beyond one of its portals, so that crossings and their edges are tested
                    // (a uniform direction from a random point rarely meets a small window).
                    Some(portals) if !portals.is_empty() && rng.chance(0.5) => {
                        let q = &portals[(rng.range(0.0, portals.len() as f64) as usize)
                            .min(portals.len() - 1)];
                        let (a, b) = (rng.range(-0.1, 1.1), rng.range(-0.1, 1.1));
                        let c = q.corners;
                        let target = c[0] + a * (c[1] - c[0]) + b * (c[3] - c[0]);
                        (x, (target - x).try_normalize().unwrap_or(DVec3::Z))
                    }
                    _ => (x, rng.unit()),
                }
            }
            _ => {
                // Origin in local space: a random direction at 1.05..6 sizes from the centre,
                // biased to the emitting side for one-sided shapes.
                let mut o = rng.unit() * size * rng.range(1.05, 6.0);
                if matches!(l.kind, LightType::Rect { .. } | LightType::Disk { .. })
                    && rng.chance(0.8)
                {
                    o.z = -o.z.abs();
                }
                let target = DVec3::new(
                    rng.range(-1.2, 1.2) * ext.x.max(0.05 * size),
                    rng.range(-1.2, 1.2) * ext.y.max(0.05 * size),
                    rng.range(-1.2, 1.2) * ext.z.max(0.05 * size),
                );
                let x = l.world.transform_point3(o);
                let t = l.world.transform_point3(target);
                let w = t - x;
                let w = if w.length() > 0.0 {
                    w.normalize()
                } else {
                    rng.unit()
                };
                (x, w)
            }
        };
        points.push(f32x3(x));
        dirs.push(f32x3(w));
    }
    (points, dirs)
}

/// Irradiance receivers for one light: points around the light as for radiance (1.05–6 sizes
/// from its centre, mostly on the emitting side of rects and disks, half of them inside a
/// shaped light's cone), normals half uniform and half toward the light (perturbed); for
/// distant and dome lights, points in a box and normals around the direction of the light.
pub fn irradiance_samples(
    r: &Reference,
    n: usize,
    rng: &mut Rng,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let p = &r.p;
    let l = &p.light;
    let ext = local_extent(l);
    let size = ext.max_element().max(1e-3);
    let mut points = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(n);
    for i in 0..n {
        let (x, toward) = match l.kind {
            LightType::Distant { .. } | LightType::Dome => (
                DVec3::new(
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                ),
                -p.axis,
            ),
            _ => {
                let mut o = match &l.shaping {
                    // Inside (or around) the cone, in light space: −Z is the axis.
                    Some(s) if i % 2 == 0 => {
                        let cone =
                            (1.2 * s.cone_angle.to_radians()).clamp(0.05, std::f64::consts::PI);
                        rng.cone(DVec3::NEG_Z, cone)
                    }
                    _ => rng.unit(),
                } * size
                    * rng.range(1.05, 6.0);
                if matches!(l.kind, LightType::Rect { .. } | LightType::Disk { .. })
                    && rng.chance(0.9)
                {
                    o.z = -o.z.abs();
                }
                let x = l.world.transform_point3(o);
                (x, (p.origin - x).normalize())
            }
        };
        let nrm = if i % 4 < 2 {
            rng.unit()
        } else {
            (toward + rng.unit() * rng.range(0.0, 1.2)).normalize()
        };
        points.push(f32x3(x));
        normals.push(f32x3(if nrm.is_finite() { nrm } else { DVec3::Z }));
    }
    (points, normals)
}
