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

mod irradiance;
pub use irradiance::{F32_ROUNDING, IRRADIANCE_SLIVER_FACTOR, irradiance_margin};

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
