//! CPU-vs-GPU conformance: randomised samples per light, the GPU result compared with the f64
//! reference, and the largest errors reported. Used by `luxeval check` and by the conformance
//! test suite (DESIGN.md §5).
//!
//! Error measure: for each sample, `‖gpu − cpu‖∞ / ‖cpu‖∞` over the RGB channels (0 when both
//! are 0; a sample where exactly one side is 0 has error 1). Tolerance 1e-4.
//!
//! Excluded band: samples near a discontinuity, where an f32 rounding legitimately flips or
//! amplifies the answer, are counted and reported but not compared:
//! - within [`BAND`] rad of a distant light's cone edge, of the one-sided horizon of a rect or
//!   disk, or of a cylinder's axis direction;
//! - within [`CONE_BAND`]·θcone of a ShapingAPI cone edge, hard or soft (see its docs);
//! - for radiance, a shape's silhouette: the hit point or the closest approach within `BAND` of
//!   the boundary (as a fraction of the shape's size), grazing rays, and ray origins within
//!   `BAND` of the surface;
//! - for irradiance, receivers that see only a sliver of the light (at the receiver's horizon,
//!   at the light's own plane, at a cone edge) or sit on the light: see [`irradiance_margin`].
//!
//! Everything else must be within tolerance.

use glam::{DMat4, DQuat, DVec3};

use crate::cpu::normalize::distant_half_angle;
use crate::cpu::shaping::off_axis_angle;
use crate::cpu::{PreparedLight, emission, irradiance, radiance};
use crate::error::Result;
use crate::gpu::{GpuContext, Kernel, pack};
use crate::light::{Light, LightType, Shaping};

/// Relative tolerance of GPU (f32) against CPU (f64).
pub const TOLERANCE: f64 = 1e-4;
/// Half-width of the excluded band around discontinuities (radians, or a fraction of the
/// shape's size).
pub const BAND: f64 = 1e-4;

/// Relative half-width of the band around a cone edge, as a fraction of the cone angle.
///
/// f32 angles carry ~1.5e-7·θ of rounding (the direction and the axis are f32), and the cone
/// factor 1 − smoothstep vanishes quadratically at θcone, so its relative error is
/// 2δθ/(θcone − θoff): it exceeds 1e-4 within ~4e-3·θcone of the edge, soft or hard.
pub const CONE_BAND: f64 = 4e-3;

/// The queries `check` compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Query {
    Emission,
    Radiance,
    Irradiance,
}

/// One light's result for one query.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QueryReport {
    pub light: String,
    pub light_type: &'static str,
    pub query: Query,
    pub samples: usize,
    /// Samples in the excluded band (not compared).
    pub excluded: usize,
    /// Compared samples where the CPU value is non-zero.
    pub nonzero: usize,
    pub max_rel_error: f64,
    /// The worst compared sample.
    pub worst: Option<Worst>,
    pub pass: bool,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Worst {
    pub index: usize,
    /// Direction (emission) or point (radiance, irradiance).
    pub a: [f32; 3],
    /// Direction (radiance) or receiver normal (irradiance).
    pub b: Option<[f32; 3]>,
    pub cpu: [f64; 3],
    pub gpu: [f32; 3],
}

/// The whole comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CheckReport {
    pub device: String,
    pub tolerance: f64,
    pub band: f64,
    pub samples: usize,
    pub excluded: usize,
    pub rows: Vec<QueryReport>,
}

impl CheckReport {
    pub fn pass(&self) -> bool {
        self.rows.iter().all(|r| r.pass)
    }

    pub fn max_rel_error(&self) -> f64 {
        self.rows
            .iter()
            .map(|r| r.max_rel_error)
            .fold(0.0, f64::max)
    }
}

/// A small deterministic generator (SplitMix64) so that a check is reproducible from its seed.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.f64() * n as f64) as usize % n.max(1)
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.f64() < p
    }
    /// Uniform on the unit sphere.
    pub fn unit(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }
    /// Uniform within `max_angle` of `axis` (unit).
    pub fn cone(&mut self, axis: DVec3, max_angle: f64) -> DVec3 {
        let cos_max = max_angle.min(std::f64::consts::PI).cos();
        let z = self.range(cos_max, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (t, b) = axis.any_orthonormal_pair();
        (r * phi.cos() * t + r * phi.sin() * b + z * axis).normalize()
    }
}

fn f32x3(v: DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

/// The local-space half extent of a light's shape, for scaling samples.
fn local_extent(l: &Light) -> DVec3 {
    match l.kind {
        LightType::Rect { width, height } => DVec3::new(width / 2.0, height / 2.0, 0.0),
        LightType::Disk { radius } => DVec3::new(radius, radius, 0.0),
        LightType::Sphere { radius, .. } => DVec3::splat(radius),
        LightType::Cylinder { length, radius, .. } => DVec3::new(length / 2.0, radius, radius),
        LightType::Distant { .. } | LightType::Dome => DVec3::ONE,
    }
}

/// Emission directions for one light: half uniform, half concentrated where the light is
/// interesting (around its axis, its cone edge, its horizon).
pub fn emission_samples(p: &PreparedLight, n: usize, rng: &mut Rng) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let e = if i % 2 == 0 {
                rng.unit()
            } else {
                match (&p.light.kind, &p.light.shaping) {
                    (LightType::Distant { angle }, _) => {
                        rng.cone(p.axis, (2.0 * distant_half_angle(*angle)).max(1e-3))
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
pub fn radiance_samples(
    p: &PreparedLight,
    n: usize,
    rng: &mut Rng,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let l = &p.light;
    let ext = local_extent(l);
    let size = ext.max_element().max(1e-3);
    let mut points = Vec::with_capacity(n);
    let mut dirs = Vec::with_capacity(n);
    for _ in 0..n {
        let (x, w) = match l.kind {
            LightType::Distant { angle } => {
                let x = DVec3::new(
                    rng.range(-10.0, 10.0),
                    rng.range(-10.0, 10.0),
                    rng.range(-10.0, 10.0),
                );
                (
                    x,
                    rng.cone(-p.axis, (2.0 * distant_half_angle(angle)).max(1e-3)),
                )
            }
            LightType::Dome => (
                DVec3::new(
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                    rng.range(-5.0, 5.0),
                ),
                rng.unit(),
            ),
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

/// Distance of an emission direction from the light's discontinuities, in radians.
pub fn emission_margin(p: &PreparedLight, e: DVec3) -> f64 {
    let e = e.normalize();
    let mut m = f64::INFINITY;
    match p.light.kind {
        LightType::Distant { angle } => {
            let tm = distant_half_angle(angle);
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
        LightType::Sphere { .. } | LightType::Dome => {}
    }
    if let (Some(s), true) = (&p.light.shaping, p.light.kind.is_shapeable()) {
        // The cone edge, hard or soft: scaled so that the band is BAND where
        // |θoff − θcone| = CONE_BAND·θcone.
        let cone = s.cone_angle.to_radians();
        if cone > 0.0 {
            m = m.min((off_axis_angle(p.axis, e) - cone).abs() / (CONE_BAND * cone) * BAND);
        }
    }
    m
}

/// Distance of a radiance ray from the light's discontinuities (dimensionless: radians, or a
/// fraction of the shape's size).
pub fn radiance_margin(p: &PreparedLight, x: DVec3, w: DVec3) -> f64 {
    let w = w.normalize();
    let m_emit = emission_margin(p, -w);
    let xl = p.to_local * (x - p.origin);
    let dl = p.to_local * w;
    let u = dl.normalize();
    let m_shape = match p.light.kind {
        LightType::Distant { .. } | LightType::Dome => f64::INFINITY,
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

/// Irradiance receivers for one light: points around the light as for radiance (1.05–6 sizes
/// from its centre, mostly on the emitting side of rects and disks, half of them inside a
/// shaped light's cone), normals half uniform and half toward the light (perturbed); for
/// distant and dome lights, points in a box and normals around the direction of the light.
pub fn irradiance_samples(
    p: &PreparedLight,
    n: usize,
    rng: &mut Rng,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
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
pub fn irradiance_outline(p: &PreparedLight, x: DVec3) -> Vec<DVec3> {
    let m = p.light.linear();
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
pub fn irradiance_margin(p: &PreparedLight, x: DVec3, n: DVec3) -> f64 {
    let n = n.normalize();
    let scale = |v: f64, band: f64| v.abs() / band * BAND;
    let mut m = f64::INFINITY;
    let xl = p.to_local * (x - p.origin);
    match p.light.kind {
        LightType::Dome => return f64::INFINITY,
        LightType::Distant { angle } => {
            let band = IRRADIANCE_SLIVER_FACTOR * 2.0 * F32_ROUNDING;
            let top = n.dot(-p.axis).clamp(-1.0, 1.0).asin() + distant_half_angle(angle);
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
    let outline = irradiance_outline(p, x);
    if outline.is_empty() {
        return m;
    }
    let lin = p.light.linear();
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
    m
}

/// Relative error of one sample (see the module docs).
pub fn rel_error(cpu: DVec3, gpu: [f32; 3]) -> f64 {
    let g = DVec3::new(gpu[0] as f64, gpu[1] as f64, gpu[2] as f64);
    let scale = cpu.abs().max_element();
    let diff = (g - cpu).abs().max_element();
    if diff == 0.0 {
        0.0
    } else if scale == 0.0 {
        1.0
    } else {
        (diff / scale).min(1.0)
    }
}

/// Samples per light and query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Samples {
    pub emission: usize,
    pub radiance: usize,
    pub irradiance: usize,
}

impl Samples {
    /// `n` emission directions and radiance rays, and `n/4` (rounded up) irradiance receivers:
    /// each irradiance sample is a quadrature on both sides, ~100× the cost of the others.
    pub fn per_query(n: usize) -> Self {
        Samples {
            emission: n,
            radiance: n,
            irradiance: n.div_ceil(4),
        }
    }
}

/// Compares GPU and CPU on [`Samples::per_query`]`(samples)` per light.
pub fn check(
    gpu: &GpuContext,
    device: &str,
    lights: &[PreparedLight],
    samples: usize,
    seed: u64,
) -> Result<CheckReport> {
    check_with(gpu, device, lights, Samples::per_query(samples), seed)
}

/// Compares GPU and CPU on the given number of samples per light and query (a query with 0
/// samples is skipped).
pub fn check_with(
    gpu: &GpuContext,
    device: &str,
    lights: &[PreparedLight],
    counts: Samples,
    seed: u64,
) -> Result<CheckReport> {
    let mut rng = Rng::new(seed);
    let mut rows = Vec::new();
    for p in lights {
        let rec = [pack::pack(p)];
        // Emission.
        let samples = counts.emission;
        let dirs = emission_samples(p, samples, &mut rng);
        let got = gpu.run(Kernel::Emission, &rec, &dirs, None, false)?;
        rows.push(compare(p, Query::Emission, samples, |i| {
            let e = crate::cpu::dvec(dirs[i]);
            (
                emission::emission(p, e),
                emission_margin(p, e),
                got[i],
                dirs[i],
                None,
            )
        }));
        // Radiance.
        let samples = counts.radiance;
        let (pts, dirs) = radiance_samples(p, samples, &mut rng);
        let got = gpu.run(Kernel::Radiance, &rec, &pts, Some(&dirs), false)?;
        rows.push(compare(p, Query::Radiance, samples, |i| {
            let (x, w) = (crate::cpu::dvec(pts[i]), crate::cpu::dvec(dirs[i]));
            (
                radiance::radiance(p, x, w),
                radiance_margin(p, x, w),
                got[i],
                pts[i],
                Some(dirs[i]),
            )
        }));
        // Irradiance: the CPU values (quadratures) are computed in parallel.
        let ni = counts.irradiance;
        let (pts, nrms) = irradiance_samples(p, ni, &mut rng);
        let got = gpu.run(Kernel::Irradiance, &rec, &pts, Some(&nrms), false)?;
        let cpu: Vec<(DVec3, f64)> = {
            use rayon::prelude::*;
            (0..ni)
                .into_par_iter()
                .map(|i| {
                    let (x, nn) = (crate::cpu::dvec(pts[i]), crate::cpu::dvec(nrms[i]));
                    (
                        irradiance::irradiance(p, x, nn),
                        irradiance_margin(p, x, nn),
                    )
                })
                .collect()
        };
        rows.push(compare(p, Query::Irradiance, ni, |i| {
            (cpu[i].0, cpu[i].1, got[i], pts[i], Some(nrms[i]))
        }));
    }
    rows.retain(|r| r.samples > 0);
    Ok(CheckReport {
        device: device.to_string(),
        tolerance: TOLERANCE,
        band: BAND,
        samples: rows.iter().map(|r| r.samples).sum(),
        excluded: rows.iter().map(|r| r.excluded).sum(),
        rows,
    })
}

type SampleEval = (DVec3, f64, [f32; 3], [f32; 3], Option<[f32; 3]>);

fn compare(
    p: &PreparedLight,
    query: Query,
    n: usize,
    f: impl Fn(usize) -> SampleEval,
) -> QueryReport {
    let mut report = QueryReport {
        light: p.light.path.clone(),
        light_type: p.light.kind.usd_type(),
        query,
        samples: n,
        excluded: 0,
        nonzero: 0,
        max_rel_error: 0.0,
        worst: None,
        pass: true,
    };
    for i in 0..n {
        let (cpu, margin, gpu, a, b) = f(i);
        if margin < BAND {
            report.excluded += 1;
            continue;
        }
        if cpu != DVec3::ZERO {
            report.nonzero += 1;
        }
        let err = rel_error(cpu, gpu);
        if err > report.max_rel_error || report.worst.is_none() {
            report.max_rel_error = report.max_rel_error.max(err);
            report.worst = Some(Worst {
                index: i,
                a,
                b,
                cpu: cpu.to_array(),
                gpu,
            });
        }
    }
    report.pass = report.max_rel_error <= TOLERANCE;
    report
}

// ---------------------------------------------------------------------------------------
// Randomised lights: every type, transform kind and attribute (the conformance suite, `bench`).

/// The transform kinds the conformance suite covers for every type.
pub const TRANSFORMS: [&str; 7] = [
    "identity",
    "translate",
    "rotate",
    "uniform-scale",
    "nonuniform-scale",
    "shear",
    "mirror",
];

pub fn transform(kind: &str, rng: &mut Rng) -> DMat4 {
    let t = DVec3::new(
        rng.range(-3.0, 3.0),
        rng.range(-3.0, 3.0),
        rng.range(-3.0, 3.0),
    );
    let q = DQuat::from_axis_angle(rng.unit(), rng.range(0.0, std::f64::consts::TAU));
    match kind {
        "identity" => DMat4::IDENTITY,
        "translate" => DMat4::from_translation(t),
        "rotate" => DMat4::from_rotation_translation(q, t),
        "uniform-scale" => {
            DMat4::from_scale_rotation_translation(DVec3::splat(rng.range(0.3, 3.0)), q, t)
        }
        "nonuniform-scale" => DMat4::from_scale_rotation_translation(
            DVec3::new(
                rng.range(0.3, 3.0),
                rng.range(0.3, 3.0),
                rng.range(0.3, 3.0),
            ),
            q,
            t,
        ),
        "shear" => {
            // luxtest frames 26-30 use rows (1.25,0,0),(0,1,0),(0.6,0,0.75) under a rotation.
            let shear = DMat4::from_cols_array_2d(&[
                [rng.range(0.8, 1.5), rng.range(-0.5, 0.5), 0.0, 0.0],
                [0.0, 1.0, rng.range(-0.5, 0.5), 0.0],
                [rng.range(-0.8, 0.8), 0.0, rng.range(0.5, 1.2), 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]);
            DMat4::from_rotation_translation(q, t) * shear
        }
        "mirror" => {
            DMat4::from_rotation_translation(q, t)
                * DMat4::from_scale(DVec3::new(-1.0, rng.range(0.5, 2.0), 1.0))
        }
        other => panic!("unknown transform kind {other}"),
    }
}

/// A random light of type `ty` (0 distant, 1 sphere, 2 disk, 3 rect, 4 cylinder, 5 dome)
/// under transform kind `xf`, with random LightAPI and (70 %) ShapingAPI inputs.
pub fn random_light(ty: usize, xf: &str, rng: &mut Rng, id: usize) -> Light {
    let mut l = match ty {
        0 => Light::distant(if rng.chance(0.15) {
            0.0
        } else {
            rng.range(0.1, 250.0)
        }),
        1 => {
            let mut l = Light::sphere(rng.range(0.05, 1.0));
            if rng.chance(0.15) {
                l.kind = LightType::Sphere {
                    radius: rng.range(0.05, 1.0),
                    treat_as_point: true,
                };
            }
            l
        }
        2 => Light::disk(rng.range(0.05, 1.0)),
        3 => Light::rect(rng.range(0.1, 2.0), rng.range(0.1, 2.0)),
        4 => {
            let mut l = Light::cylinder(rng.range(0.2, 2.0), rng.range(0.05, 0.5));
            if rng.chance(0.15) {
                l.kind = LightType::Cylinder {
                    length: 1.0,
                    radius: 0.2,
                    treat_as_line: true,
                };
            }
            l
        }
        _ => Light::dome(),
    };
    let name = format!("/random/{id}_{}_{xf}", l.kind.usd_type());
    l = l
        .with_path(name)
        .with_intensity(rng.range(0.1, 100.0))
        .with_exposure(rng.range(-4.0, 4.0))
        .with_color(DVec3::new(
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
        ))
        .with_normalize(rng.chance(0.5))
        .with_transform(transform(xf, rng));
    if rng.chance(0.4) {
        l = l.with_temperature(rng.range(800.0, 16000.0));
    }
    if rng.chance(0.7) {
        let cone_angle = match rng.below(4) {
            0 => 90.0,
            1 => rng.range(5.0, 90.0),
            2 => rng.range(90.0, 180.0),
            _ => rng.range(-10.0, 200.0),
        };
        l = l.with_shaping(Shaping {
            focus: if rng.chance(0.6) {
                rng.range(-1.0, 8.0)
            } else {
                0.0
            },
            focus_tint: DVec3::new(rng.f64(), rng.f64(), rng.f64()),
            cone_angle,
            cone_softness: if rng.chance(0.3) {
                0.0
            } else {
                rng.range(-0.2, 1.3)
            },
        });
    }
    l
}

/// Every type × transform kind, `per_combo` lights each.
pub fn random_lights(rng: &mut Rng, per_combo: usize) -> Vec<Light> {
    let mut lights = Vec::new();
    for ty in 0..6 {
        for xf in TRANSFORMS {
            for _ in 0..per_combo {
                let id = lights.len();
                lights.push(random_light(ty, xf, rng, id));
            }
        }
    }
    lights
}

/// The benchmark's lights: every analytic type under every transform kind (shaped or not),
/// cycled to `n`; deterministic.
pub fn synthetic_lights(n: usize) -> Vec<Light> {
    let mut rng = Rng::new(2026);
    let pool = random_lights(&mut rng, 1);
    // Domes are uniform and trivially cheap; keep the mix on the shapes.
    let shaped: Vec<Light> = pool
        .into_iter()
        .filter(|l| !matches!(l.kind, LightType::Dome))
        .collect();
    (0..n)
        .map(|i| shaped[(i * 7) % shaped.len()].clone())
        .collect()
}
