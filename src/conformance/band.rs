//! The excluded band of a conformance check: how far a sample lies from a place where an f32
//! rounding legitimately flips or amplifies the answer (a cone edge, a one-sided horizon, a
//! silhouette, a sliver of a light above a receiver's horizon). See the module docs of
//! [`super`].

use glam::DVec3;

use super::{BAND, CONE_BAND};
use crate::cpu::ies::{
    fold_mirror, ies_factor, photometric_angles, scale_polar_angle, type_c_angles,
};
use crate::cpu::radiance;
use crate::cpu::shaping::off_axis_angle;
use crate::model::LightType;
use crate::model::TextureFilter;
use crate::prepare::Prepared;
use crate::prepare::ies::{HFold, PhotometricType, VFold};
use crate::prepare::texture::DomeFormat;
use crate::query::Reference;
use crate::synthetic::samples::local_extent;

/// [`emission_margin`] for the intensity query, which also excludes the sliver where the
/// projected area vanishes: a rect or disk seen within `IRRADIANCE_SLIVER_FACTOR·2·F32_ROUNDING`
/// rad of its own plane, a cylinder within that of its axis. There the projected area is a
/// cosine of a rounded f32 direction, off by ~2·F32_ROUNDING/t relative at angle t (measured:
/// 1.4e-4 at t ≈ 1e-3 rad on lavapipe); scaled to reach `BAND` at the sliver's edge.
pub fn intensity_margin(r: &Reference, e: DVec3) -> f64 {
    let p = &r.p;
    let e = e.normalize();
    let band = IRRADIANCE_SLIVER_FACTOR * 2.0 * F32_ROUNDING;
    let v = (p.to_local * e).normalize();
    let t = match p.light.kind {
        LightType::Rect { .. } | LightType::Disk { .. } => v.z.abs().min(1.0).asin(),
        LightType::Cylinder { .. } => (v.y * v.y + v.z * v.z).sqrt().min(1.0).asin(),
        _ => f64::INFINITY,
    };
    emission_margin(r, e).min(t / band * BAND)
}

/// How far the ray `x + tω`, t > 0, passes from the nearest edge of any mesh triangle whose
/// plane it crosses, as a fraction of that triangle's longest edge: where it is small the f32
/// ray test of shaders/mesh/ray.wgsl may hit where the f64 one misses, or the other triangle of
/// an edge. Every triangle is tested (a diagnostic, not a query).
pub fn mesh_edge_margin(triangles: &[crate::model::MeshTriangle], x: DVec3, w: DVec3) -> f64 {
    let mut m = f64::INFINITY;
    for t in triangles {
        let (e1, e2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
        let n = e1.cross(e2);
        let denom = n.dot(w);
        let s = n.dot(t.p[0] - x) / denom;
        if !(s > 0.0) || !s.is_finite() {
            continue;
        }
        let h = x + s * w - t.p[0];
        // Barycentrics (Cramer's rule) times each vertex's height over its opposite edge: the
        // hit point's distance to that edge's line.
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (h1, h2) = (h.dot(e1), h.dot(e2));
        let det = d11 * d22 - d12 * d12;
        let (v, u) = ((d22 * h1 - d12 * h2) / det, (d11 * h2 - d12 * h1) / det);
        let area2 = n.length();
        let sides = [(e2 - e1).length(), e2.length(), e1.length()];
        let size = sides[0].max(sides[1]).max(sides[2]);
        for (b, side) in [1.0 - u - v, v, u].into_iter().zip(sides) {
            m = m.min((b * area2 / side).abs() / size);
        }
    }
    m
}

/// How far the ray `x + tω`, t > 0, is from changing which portal of a masked dome it passes
/// through (DESIGN.md §8 P2), as a rect light's silhouette is measured (the fraction of the
/// portal's larger half extent): the crossing point's distance to each portal's edges, the
/// ray's origin's distance to each portal's plane, and the grazing angle, minimised over every
/// portal whose plane the ray meets (a crossing toward −Z or outside the rectangle may turn into
/// one that counts under f32 rounding); and the relative gap in depth between the nearest
/// crossing that counts and the next (where two portals cut through each other the nearer may
/// change, and with it the multiplier).
pub fn portal_margin(portals: &[crate::prepare::PreparedPortal], x: DVec3, w: DVec3) -> f64 {
    let mut m = f64::INFINITY;
    let mut depths = Vec::new();
    for q in portals {
        let xl = q.to_local * (x - q.origin);
        let dl = q.to_local * w;
        let s = q.half.x.max(q.half.y);
        m = m.min(xl.z.abs() / s).min(dl.normalize().z.abs());
        if dl.z != 0.0 && -xl.z / dl.z > 0.0 {
            let h = xl - xl.z / dl.z * dl;
            m = m.min(((h.x.abs() - q.half.x).abs() / s).min((h.y.abs() - q.half.y).abs() / s));
            if dl.z > 0.0 && h.x.abs() <= q.half.x && h.y.abs() <= q.half.y {
                // t in world units: the local z advances dl.z a unit of t.
                depths.push(-xl.z / dl.z);
            }
        }
    }
    depths.sort_by(f64::total_cmp);
    if let [a, b, ..] = depths[..] {
        m = m.min((b - a) / b);
    }
    m
}

/// Distance of an emission direction from the light's discontinuities, in radians.
pub fn emission_margin(r: &Reference, e: DVec3) -> f64 {
    let p = &r.p;
    let e = e.normalize();
    let mut m = f64::INFINITY;
    match p.light.kind {
        LightType::Distant { .. } => {
            let tm = p.distant_half_angle();
            m = m.min((off_axis_angle(p.axis, e) - tm).abs());
        }
        LightType::Rect { .. } | LightType::Disk { .. } => {
            // Angle from the horizon of the emitting side.
            m = m.min(e.dot(p.normal).clamp(-1.0, 1.0).asin().abs());
        }
        LightType::Cylinder { .. } => {
            let el = (p.to_local * e).normalize();
            m = m.min((el.y * el.y + el.z * el.z).sqrt().asin());
        }
        LightType::Dome => {
            if near_texture_edge(p, e, TEXEL_BAND) {
                m = 0.0;
            }
        }
        LightType::Sphere { .. } => {}
        // DESIGN.md §7 M3: L(e) where some front faces e. Where one faces it by more than BAND
        // rad the f32 test agrees; else the nearest front to edge-on decides.
        LightType::Mesh { double_sided, .. } => {
            if let crate::prepare::KindData::Mesh { fronts, .. } = &p.kind {
                let facing = |n: &DVec3| {
                    let c = n.dot(e);
                    if double_sided { c.abs() } else { c }
                };
                if !fronts.iter().any(|n| facing(n).asin() > BAND) {
                    let near = fronts
                        .iter()
                        .map(|n| n.dot(e).clamp(-1.0, 1.0).asin().abs());
                    m = m.min(near.fold(f64::INFINITY, f64::min));
                }
            }
        }
    }
    if let (Some(s), true) = (&p.light.shaping, p.light.kind.is_shapeable()) {
        // The cone edge, hard or soft: scaled so that the band is BAND where
        // |θoff − θcone| = CONE_BAND·θcone.
        let cone = s.cone_angle.to_radians();
        if cone > 0.0 {
            m = m.min((off_axis_angle(p.axis, e) - cone).abs() / (CONE_BAND * cone) * BAND);
        }
    }
    m.min(ies_margin(p, e))
}

/// How far the GPU's light-space direction may be from the exact one: f32 rounding of the
/// direction and of the world-to-light map, amplified by the map's condition (radians).
const IES_DIRECTION_ROUNDING: f64 = 2e-6;

/// Distance (radians, conservatively) of unit emission direction `e` from where f32 cannot
/// resolve the light's IES factor to the tolerance:
/// - the jumps of the profile (DESIGN.md §6 I3, I4): the ends of its angle ranges beyond which
///   it is 0 (not the poles of type C, nor a mirror fold, which are continuous) and angleScale's
///   window θ' ∈ [0°, 180°]. A distance along an azimuth-like angle is scaled by the cosine of
///   the other angle (it shrinks toward its poles); angleScale s stretches polar distances by
///   1/|s|;
/// - near a zero of the interpolant (a profile falling to 0 toward a range end, or at a mirror
///   plane): the factor's relative change over `IES_DIRECTION_ROUNDING`, which the GPU's f32
///   direction legitimately makes, scaled so that it reaches `BAND` where that change is half the
///   tolerance (as a soft cone edge is excluded where its factor vanishes).
fn ies_margin(p: &Prepared, e: DVec3) -> f64 {
    let Some(ies) = &p.ies else {
        return f64::INFINITY;
    };
    let prof = &ies.profile;
    let el = (p.to_local * e).normalize();
    let f0 = ies_factor(prof, el, ies.angle_scale);
    let (t1, t2) = el.any_orthonormal_pair();
    let mut change: f64 = 0.0;
    for d in [t1, -t1, t2, -t2] {
        let f = ies_factor(
            prof,
            (el + d * IES_DIRECTION_ROUNDING).normalize(),
            ies.angle_scale,
        );
        change = change.max((f - f0).abs());
    }
    let sensitivity = if change == 0.0 {
        f64::INFINITY
    } else if f0 == 0.0 {
        0.0
    } else {
        BAND * (0.5 * super::TOLERANCE) / (change / f0)
    };
    sensitivity.min(ies_jumps(p, el))
}

/// The distance part of [`ies_margin`] for the light-space direction `el`.
fn ies_jumps(p: &Prepared, el: DVec3) -> f64 {
    let Some(ies) = &p.ies else {
        return f64::INFINITY;
    };
    let prof = &ies.profile;
    let s = ies.angle_scale;
    let stretch = if s != 0.0 { s.abs().min(1.0) } else { 1.0 };
    let mut deg = f64::INFINITY;
    if s != 0.0 {
        let t = scale_polar_angle(type_c_angles(el).1, s);
        deg = deg.min(t.abs().min((t - 180.0).abs()));
    }
    let Some((h, v)) = photometric_angles(prof.kind, el, s) else {
        return deg.to_radians() * stretch;
    };
    let (h0, h1) = (prof.h[0], prof.h[prof.h.len() - 1]);
    let (v0, v1) = (prof.v[0], prof.v[prof.v.len() - 1]);
    let near = |x: f64, a: f64| (x - a).abs();
    match prof.kind {
        PhotometricType::C => {
            if v0 > 0.0 {
                deg = deg.min(near(v, v0));
            }
            if v1 < 180.0 {
                deg = deg.min(near(v, v1));
            }
        }
        PhotometricType::B | PhotometricType::A => {
            let hq = fold_mirror(h, prof.h_fold == HFold::Mirror);
            let vq = fold_mirror(v, prof.v_fold == VFold::Mirror);
            // B: H is a cone angle about Y, V a plane through Y; A: V a cone angle about Z, H
            // a plane through Z.
            let (h_w, v_w) = match prof.kind {
                PhotometricType::B => (1.0, h.to_radians().cos().abs()),
                _ => (v.to_radians().cos().abs(), 1.0),
            };
            let mut dh = f64::INFINITY;
            match prof.h_fold {
                HFold::Constant if prof.kind == PhotometricType::A => dh = near(hq.abs(), 90.0),
                HFold::Constant => {}
                HFold::Mirror => dh = near(hq, h1),
                _ => dh = near(hq, h0).min(near(hq, h1)),
            }
            let dv = if prof.v_fold == VFold::Mirror {
                near(vq, v1)
            } else {
                near(vq, v0).min(near(vq, v1))
            };
            deg = deg.min(dh * h_w).min(dv * v_w);
        }
    }
    deg.to_radians() * stretch
}

/// Distance of a radiance ray from the light's discontinuities (dimensionless: radians, or a
/// fraction of the shape's size).
pub fn radiance_margin(r: &Reference, x: DVec3, w: DVec3) -> f64 {
    let p = &r.p;
    let w = w.normalize();
    // A dome's emission is indexed by the direction toward the environment, as its radiance is
    // (DESIGN.md §3); every other light's by the direction light travels.
    let m_emit = if p.light.kind == LightType::Dome {
        emission_margin(r, w)
    } else {
        emission_margin(r, -w)
    };
    let xl = p.to_local * (x - p.origin);
    let dl = p.to_local * w;
    let u = dl.normalize();
    let m_shape = match p.light.kind {
        // A masked dome (§8 P2): the ray's crossings of its portals' edges and planes.
        LightType::Dome if let Some(portals) = &p.portals => portal_margin(portals, x, w),
        LightType::Distant { .. } | LightType::Dome => f64::INFINITY,
        LightType::Mesh { ref geometry, .. } => mesh_edge_margin(&geometry.triangles, x, w),
        LightType::Sphere {
            treat_as_point: true,
            ..
        }
        | LightType::Cylinder {
            treat_as_line: true,
            ..
        } => f64::INFINITY,
        LightType::Rect { width, height } => {
            let (hw, hh) = (width / 2.0, height / 2.0);
            let s = hw.max(hh);
            let mut m = (xl.z.abs() / s).min(u.z.abs());
            if dl.z != 0.0 {
                let h = xl - xl.z / dl.z * dl;
                m = m.min(((h.x.abs() - hw).abs() / s).min((h.y.abs() - hh).abs() / s));
            }
            m
        }
        LightType::Disk { radius } => {
            let mut m = (xl.z.abs() / radius).min(u.z.abs());
            if dl.z != 0.0 {
                let h = xl - xl.z / dl.z * dl;
                m = m.min(((h.x * h.x + h.y * h.y).sqrt() - radius).abs() / radius);
            }
            m
        }
        LightType::Sphere { radius, .. } => {
            let tc = -xl.dot(u);
            let closest = (xl + tc * u).length();
            ((closest - radius).abs() / radius)
                .min((xl.length() - radius).abs() / radius)
                .min(tc.abs() / radius)
        }
        LightType::Cylinder { length, radius, .. } => {
            let hl = length / 2.0;
            let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
            let mut m = (rho - radius).abs() / radius;
            let dyz = (dl.y * dl.y + dl.z * dl.z).sqrt();
            m = m.min(dyz / dl.length());
            if dyz > 0.0 {
                let (uy, uz) = (dl.y / dyz, dl.z / dyz);
                let tc = -(xl.y * uy + xl.z * uz);
                let (cy, cz) = (xl.y + tc * uy, xl.z + tc * uz);
                let closest = (cy * cy + cz * cz).sqrt();
                m = m
                    .min((closest - radius).abs() / radius)
                    .min(tc.abs() / radius);
                let h2 = radius * radius - closest * closest;
                if h2 >= 0.0 {
                    let t1 = (tc - h2.sqrt()) / dyz;
                    m = m.min(((xl.x + t1 * dl.x).abs() - hl).abs() / hl.max(radius));
                }
            }
            m
        }
    };
    m_emit.min(m_shape)
}

/// Irradiance slivers (see [`irradiance_margin`]) narrower than this many times η, the angular
/// resolution of the light's f32 geometry seen from the receiver, are excluded. A sliver of
/// angular thickness t has irradiance ∝ t^k: k = 2 for a straight edge (area ∝ t, cosine ∝ t),
/// k = 5/2 for a curved outline (a circle's segment has area ∝ t^{3/2}). Moving the geometry by
/// η changes it by k·η/t relative, so 5e4 keeps that at 1e-4/2 for k = 5/2 (a sphere seen
/// 0.07 radii from its surface, behind the receiver, measured 3e-4 at 1.3e4·η on lavapipe).
pub const IRRADIANCE_SLIVER_FACTOR: f64 = 5e4;

/// Half of f32's machine epsilon: the relative rounding of one f32 coordinate.
pub const F32_ROUNDING: f64 = f32::EPSILON as f64 / 2.0;

/// World-space points on the outline of what x sees of the light (the boundary of its solid
/// angle): rect edges, disk rim, the sphere's contact ellipse, the cylinder's front patch
/// (tangent generators and front arcs of the end rings); the origin of a point light and the
/// ends of a line light. Empty when x sees nothing (inside a sphere or a cylinder's tube).
pub fn irradiance_outline(r: &Reference, x: DVec3) -> Vec<DVec3> {
    let p = &r.p;
    let m = p.linear;
    let o = p.origin;
    let xl = p.to_local * (x - o);
    let k = 64;
    let ring = |c: DVec3, u: DVec3, v: DVec3, t0: f64, t1: f64| -> Vec<DVec3> {
        (0..=k)
            .map(|j| {
                let t = t0 + (t1 - t0) * j as f64 / k as f64;
                o + m * (c + u * t.cos() + v * t.sin())
            })
            .collect()
    };
    match p.light.kind {
        // Evaluated on the host on every backend (GpuPath::Host): no silhouette to avoid.
        LightType::Mesh { .. } => vec![],
        LightType::Rect { width, height } => {
            let (hw, hh) = (width / 2.0, height / 2.0);
            let c = [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)];
            let mut out = Vec::new();
            for e in 0..4 {
                let (a, b) = (c[e], c[(e + 1) % 4]);
                for j in 0..k {
                    let t = j as f64 / k as f64;
                    out.push(o + m * DVec3::new(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), 0.0));
                }
            }
            out
        }
        LightType::Disk { radius } => ring(
            DVec3::ZERO,
            DVec3::X * radius,
            DVec3::Y * radius,
            0.0,
            std::f64::consts::TAU,
        ),
        LightType::Sphere {
            treat_as_point: true,
            ..
        } => vec![o],
        LightType::Sphere { radius, .. } => {
            let rho = xl.length();
            if !(rho > radius) {
                return vec![];
            }
            let kk = (rho - radius) * (rho + radius);
            let (u, v) = (xl / rho).any_orthonormal_pair();
            let rc = radius * kk.sqrt() / rho;
            ring(
                xl * (radius * radius / (rho * rho)),
                u * rc,
                v * rc,
                0.0,
                std::f64::consts::TAU,
            )
        }
        LightType::Cylinder {
            length,
            treat_as_line: true,
            ..
        } => vec![
            o + m * DVec3::X * (length / 2.0),
            o - m * DVec3::X * (length / 2.0),
        ],
        LightType::Cylinder { length, radius, .. } => {
            let hl = length / 2.0;
            let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
            if !(rho > radius) {
                return vec![];
            }
            let tx = xl.z.atan2(xl.y);
            let half = (radius / rho).acos();
            let mut out = ring(
                DVec3::X * hl,
                DVec3::Y * radius,
                DVec3::Z * radius,
                tx - half,
                tx + half,
            );
            out.extend(ring(
                -DVec3::X * hl,
                DVec3::Y * radius,
                DVec3::Z * radius,
                tx - half,
                tx + half,
            ));
            for t in [tx - half, tx + half] {
                for j in 0..=k {
                    let a = -hl + 2.0 * hl * j as f64 / k as f64;
                    out.push(o + m * DVec3::new(a, radius * t.cos(), radius * t.sin()));
                }
            }
            out
        }
        LightType::Distant { .. } | LightType::Dome => vec![],
    }
}

/// How much wider than a rect's the band of a mesh light's irradiance is (see
/// [`mesh_irradiance_margin`]).
pub const MESH_SLIVER_WIDER: f64 = 4.0;

/// A mesh light's irradiance margin (its irradiance is the device's only where its triangles
/// cannot hide one another: `GpuPath::HostIntensityOnly`, shaders/mesh/lambert.wgsl), as a
/// rect's: the highest elevation above the receiver's horizon of its triangles' edges (a
/// mesh wholly at the horizon is a sliver), and the largest over the triangles of x's
/// elevation above a triangle's plane seen from its vertices (a flat mesh seen edge-on), each
/// within
/// the f32 band η of the geometry's rounding seen from x, widened by [`MESH_SLIVER_WIDER`]: the
/// kernel has no quadrature to fall back on, and its f32 sums lose up to ~1e-3 relative where
/// the whole mesh lies within ~0.015 rad of the horizon (a flat hexagon seen from 0.16 above
/// its plane and 1.5 from its centre, measured on lavapipe).
fn mesh_irradiance_margin(triangles: &[crate::model::MeshTriangle], x: DVec3, n: DVec3) -> f64 {
    let scale = |v: f64, band: f64| v.abs() / band * BAND;
    let k = 16;
    let mut points = Vec::with_capacity(triangles.len() * 3 * k);
    for t in triangles {
        for e in 0..3 {
            let (a, b) = (t.p[e], t.p[(e + 1) % 3]);
            points.extend((0..k).map(|j| a + (b - a) * (j as f64 / k as f64)));
        }
    }
    if points.is_empty() {
        return f64::INFINITY;
    }
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let size = (hi - lo).length();
    let nearest = points
        .iter()
        .map(|q| (*q - x).length())
        .fold(f64::INFINITY, f64::min);
    let eta = F32_ROUNDING * (x.length() + (0.5 * (lo + hi)).length() + size) / nearest;
    let band = MESH_SLIVER_WIDER * IRRADIANCE_SLIVER_FACTOR * eta;
    let top = points
        .iter()
        .map(|q| n.dot((*q - x).normalize()).clamp(-1.0, 1.0).asin())
        .fold(f64::NEG_INFINITY, f64::max);
    // Edge-on: x near the plane of every triangle (a flat mesh's); a box's face seen edge-on
    // adds little to the sum of the others.
    let mut edge_on = 0.0f64;
    for t in triangles {
        let Some(nt) = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).try_normalize() else {
            continue;
        };
        let h = (x - t.p[0]).dot(nt);
        let elev =
            t.p.iter()
                .map(|q| (h / (x - *q).length()).clamp(-1.0, 1.0).asin().abs())
                .fold(0.0, f64::max);
        edge_on = edge_on.max(elev);
    }
    scale(top, band).min(scale(edge_on, band))
}

/// Distance of an irradiance receiver from the places where f32 legitimately cannot resolve the
/// answer to 1e-4 (dimensionless, compared with [`BAND`]).
///
/// The GPU sees the light through f32 coordinates: its position and shape move by about
/// `F32_ROUNDING·(|x| + |o| + size)`, which x sees as an angle η (that length over the distance
/// to the nearest point of the light; at least `F32_ROUNDING` for distant lights, whose axis is
/// rounded). Where x sees only a sliver of the light, the sliver's thickness t changes by ~η and
/// the irradiance by ~η/t relative. The bands, each scaled to reach `BAND` at its edge:
/// - the receiver's horizon passing within `IRRADIANCE_SLIVER_FACTOR·η` of the top of what x
///   sees (only a sliver above the horizon), or of a distant cone's top;
/// - a rect or disk seen within `IRRADIANCE_SLIVER_FACTOR·η` of its own plane (x near the plane;
///   this includes x on the light), and likewise a cylinder's tube seen edge-on from x near the
///   infinite tube through it (beyond an end);
/// - x within `BAND` (relative) of a sphere's or cylinder's surface;
/// - a ShapingAPI cone edge (hard or soft) within max([`CONE_BAND`]·θcone,
///   `IRRADIANCE_SLIVER_FACTOR·η`) of the smallest emission angle at which x sees the light
///   (x in the outer sliver of the penumbra, where the lit part of the light is a sliver and
///   the factor vanishes there).
pub fn irradiance_margin(r: &Reference, x: DVec3, n: DVec3) -> f64 {
    let p = &r.p;
    let n = n.normalize();
    let scale = |v: f64, band: f64| v.abs() / band * BAND;
    let mut m = f64::INFINITY;
    let xl = p.to_local * (x - p.origin);
    match p.light.kind {
        LightType::Dome => return f64::INFINITY,
        LightType::Distant { .. } => {
            let band = IRRADIANCE_SLIVER_FACTOR * 2.0 * F32_ROUNDING;
            let top = n.dot(-p.axis).clamp(-1.0, 1.0).asin() + p.distant_half_angle();
            return scale(top, band);
        }
        LightType::Sphere {
            radius,
            treat_as_point: false,
        } => {
            m = m.min(scale((xl.length() - radius) / radius, BAND));
        }
        LightType::Cylinder {
            radius,
            treat_as_line: false,
            ..
        } => {
            let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
            m = m.min(scale((rho - radius) / radius, BAND));
        }
        _ => {}
    }
    if let LightType::Mesh { geometry, .. } = &p.light.kind {
        return m.min(mesh_irradiance_margin(&geometry.triangles, x, n));
    }
    let outline = irradiance_outline(r, x);
    if outline.is_empty() {
        return m;
    }
    let lin = p.linear;
    let size = (lin * local_extent(&p.light)).length()
        + lin
            .x_axis
            .length()
            .max(lin.y_axis.length())
            .max(lin.z_axis.length())
            * local_extent(&p.light).max_element();
    let nearest = outline
        .iter()
        .map(|q| (*q - x).length())
        .fold(f64::INFINITY, f64::min);
    let eta = F32_ROUNDING * (x.length() + p.origin.length() + size) / nearest;
    let band = IRRADIANCE_SLIVER_FACTOR * eta;
    // Receiver horizon: the highest elevation of the outline above it.
    let top = outline
        .iter()
        .map(|q| n.dot((*q - x).normalize()).clamp(-1.0, 1.0).asin())
        .fold(f64::NEG_INFINITY, f64::max);
    m = m.min(scale(top, band));
    // A rect's or disk's own plane: the largest elevation of x above it seen from the outline.
    if matches!(
        p.light.kind,
        LightType::Rect { .. } | LightType::Disk { .. }
    ) {
        let h = (x - p.origin).dot(p.normal);
        let elev = outline
            .iter()
            .map(|q| (h / (x - *q).length()).clamp(-1.0, 1.0).asin().abs())
            .fold(0.0, f64::max);
        m = m.min(scale(elev, band));
    }
    // A cylinder's own surface, the same way: x near the infinite tube through it (beyond an
    // end) sees the tube edge-on. h: x's distance from that tube surface, in world units.
    if let LightType::Cylinder {
        radius,
        treat_as_line: false,
        ..
    } = p.light.kind
    {
        let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
        let h = (rho - radius) * 0.5 * (lin.y_axis.length() + lin.z_axis.length());
        let elev = outline
            .iter()
            .map(|q| (h / (x - *q).length()).clamp(-1.0, 1.0).asin().abs())
            .fold(0.0, f64::max);
        m = m.min(scale(elev, band));
    }
    // The cone edge: the smallest emission angle at which x sees the light.
    if let Some(s) = &p.light.shaping {
        let cone = s.cone_angle.to_radians();
        if cone > 0.0 && cone < std::f64::consts::PI {
            let sees_axis = match p.light.kind {
                LightType::Sphere {
                    treat_as_point: true,
                    ..
                }
                | LightType::Cylinder {
                    treat_as_line: true,
                    ..
                } => false,
                _ => radiance::hits_emitting_surface(p, x, -p.axis),
            };
            let theta_min = if sees_axis {
                0.0
            } else {
                outline
                    .iter()
                    .map(|q| off_axis_angle(p.axis, (x - *q).normalize()))
                    .fold(f64::INFINITY, f64::min)
            };
            m = m.min(scale(theta_min - cone, (CONE_BAND * cone).max(band)));
        }
    }
    // An IES profile's jumps (its range ends, ies_jumps) bound the lit part as the cone edge
    // does: where every lit direction of the outline lies within IES_JUMP_BAND of a jump, the
    // lit part is a sliver whose width the GPU's f32 direction (IES_DIRECTION_ROUNDING) moves
    // by more than half the tolerance of itself.
    if let Some(ies) = &p.ies {
        let lit_distance = outline
            .iter()
            .map(|q| (p.to_local * (x - *q)).normalize())
            .filter(|el| ies_factor(&ies.profile, *el, ies.angle_scale) > 0.0)
            .map(|el| ies_jumps(p, el))
            .fold(f64::NEG_INFINITY, f64::max);
        if lit_distance.is_finite() {
            m = m.min(scale(lit_distance, IES_JUMP_BAND.max(band)));
        }
    }
    m
}

/// The width (radians) below which a lit sliver bounded by an IES jump is excluded from the
/// irradiance comparison: the GPU's direction error `IES_DIRECTION_ROUNDING` moves the jump by
/// half the tolerance of a sliver this wide (see `irradiance_margin`).
const IES_JUMP_BAND: f64 = IES_DIRECTION_ROUNDING / (0.5 * super::TOLERANCE);

/// How close (in pixels, or relative for a cross face edge) a textured dome's sample may come to
/// a discontinuity f32 may straddle before it is excluded: 2000 times the ~W·2⁻²⁴ px of f32
/// pixel-coordinate rounding at W = 8192 is still under 1 % of the texels.
pub const TEXEL_BAND: f64 = 1e-3;

/// A textured dome's comparison floor along world direction `w` (toward the environment):
/// the largest channel of `base ⊙ texel` over the texels the lookup may read there (the 2 × 2
/// bilinear footprint, or the nearest texel and its neighbours). Divergence 1 of
/// shaders/shared/texture.wgsl: f32 pixel coordinates carry ~W·2⁻²⁴ px of rounding (plus the f32
/// direction's ~1e-7 rad), so the GPU's bilinear value differs from the reference by that
/// fraction of a pixel times the footprint's contrast. On a high-dynamic-range map (a 100:1 step
/// between neighbouring texels is common) that is far more than 1e-4 of a dark texel's value,
/// but always far below 1e-4 of the footprint's largest texel: errors are measured against that.
/// 0 for other lights.
pub fn texture_floor(p: &Prepared, w: DVec3) -> f64 {
    let (LightType::Dome, Some(t)) = (&p.light.kind, p.dome_texture()) else {
        return 0.0;
    };
    let (wd, hd) = (t.image.width, t.image.height);
    let st = crate::cpu::texture::direction_to_st(t.format, t.frame.to_dome(w.normalize()));
    let around = |x: f64, n: usize| {
        let c = (x * n as f64 - 0.5).floor() as i64;
        [c - 1, c, c + 1, c + 2].map(|i| i.clamp(0, n as i64 - 1) as u32)
    };
    let mut m = 0.0f64;
    for j in around(st.y, hd) {
        for i in around(st.x, wd) {
            let v = crate::cpu::texture::tex_fetch(&t.image, i, j) * p.base;
            m = m.max(v.abs().max_element());
        }
    }
    m
}

/// Whether a textured dome has a discontinuity within `margin` of world direction `w` that f32
/// may straddle (divergence 1 of shaders/shared/texture.wgsl): with the nearest filter, a texel
/// edge within `margin` pixels; with either filter, a cube-cross face edge (the two largest
/// |d| within a relative `margin`: each face clamps to its own edge texels). In f64, on the
/// reference's dome direction. False for other lights.
pub fn near_texture_edge(p: &Prepared, w: DVec3, margin: f64) -> bool {
    let (LightType::Dome, Some(t)) = (&p.light.kind, p.dome_texture()) else {
        return false;
    };
    let d = t.frame.to_dome(w.normalize());
    if t.format == DomeFormat::Cross {
        let mut a = d.abs().to_array();
        a.sort_by(f64::total_cmp);
        if a[2] - a[1] < margin * a[2] {
            return true;
        }
    }
    if t.filter != TextureFilter::Nearest {
        return false;
    }
    let near_int = |x: f64| (x - x.round()).abs() < margin;
    let st = crate::cpu::texture::direction_to_st(t.format, d);
    near_int(st.x * t.image.width as f64) || near_int(st.y * t.image.height as f64)
}
