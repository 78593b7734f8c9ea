//! Light sampling on the CPU (f64), DESIGN.md §9: for a receiver point x (and optionally its
//! normal n), a direction ω toward a light with its density per unit solid angle at x and the
//! radiance along it, exactly as `radiance` gives it; the density of any direction; and the
//! scene-level choice of a light.
//!
//! Each light's strategy (S2), set up once per (light, receiver) by [`LightAt::new`]:
//! - sphere seen from outside: uniform in the cone it subtends ([`cone`]); a shaped sphere
//!   under a similarity takes the smaller of that cone and the spot cone's cap (both contain
//!   every lit direction; of two uniform densities over supersets of the support, the smaller
//!   has the smaller variance); under a non-uniform scale (an ellipsoid) the local cone carried
//!   to world ([`area`]);
//! - rect: uniform in solid angle, Ureña's spherical rectangle or Arvo's two triangles for a
//!   sheared rect ([`rect`]); a shaped rect takes the spot cone's cap where it is the smaller;
//! - disk: uniform by area; cylinder: uniform over the visible band ([`area`]);
//! - distant with angle > 0: uniform in its cone; dome: the filtered texture's alias table —
//!   with a normal, its product with the receiver's cosine bound over tiles of texels — or, untextured,
//!   cosine-weighted about n ([`dome`]);
//! - delta lights (distant with angle 0, `treatAsPoint`, `treatAsLine`): one direction, density
//!   +∞, and `L` such that `L · max(0, n·ω)` is (on average over u, for a line) the
//!   irradiance without `diffuse` (S1).
//!
//! - mesh light: a triangle by area, a point uniform on it; the density sums every triangle the
//!   direction crosses ([`crate::cpu::mesh::sample`]).
//!
//! IES-shaped, shaped rects, disks and cylinders, and textured rects are sampled by their
//! geometry (S2 "other shapes by their geometry"); their radiance carries the shaping.

pub mod area;
pub mod cone;
pub mod cubature;
pub mod dome;
pub mod rect;
pub mod report;
pub mod rng;
pub mod select;

use glam::DVec3;

use super::radiance::radiance;
use super::shaping::shaping;
use crate::model::LightType;
use crate::prepare::Prepared;
use crate::prepare::blackbody::REC709_LUMA;
use crate::prepare::env_table::{EnvTable, ReceiverTiles};
use area::{cylinder_pdf, cylinder_sample, disk_pdf, disk_sample, ellipsoid_pdf, ellipsoid_sample};
use cone::Cone;
use rect::RectSampler;
pub use select::{SceneTables, Selection, choose, env_tables, scene_pdf, selection_weights};

/// One drawn direction: unit `dir` from x toward the light, its density per unit solid angle
/// (`+∞` for a delta light, 0 where the light delivers nothing at x), and the RGB radiance
/// along it (DESIGN.md §9 S1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub dir: DVec3,
    pub pdf: f64,
    pub radiance: DVec3,
}

/// Rec. 709 luminance (S1: variances and weights are of luminance).
pub fn luminance(c: DVec3) -> f64 {
    c.dot(REC709_LUMA)
}

/// A light's strategy set up for one receiver.
#[derive(Clone)]
pub enum LightAt<'a> {
    /// The light delivers nothing at x (inside a sphere, behind a one-sided shape, dark): any
    /// unit direction, density 0.
    Nothing(DVec3),
    /// A delta light: its one direction and `L` (a line light draws its point in `sample`).
    Delta(DVec3, DVec3),
    /// `treatAsLine`: the segment from `a` along `e` (world, X ∈ [−hl, hl]) and the constant
    /// `base · 2r·|det M|·ρ · 2hl` of its L (outer.rs `line_irradiance`).
    Line {
        a: DVec3,
        e: DVec3,
        hl: f64,
        k: DVec3,
    },
    /// Uniform in a world cone.
    Cone(Cone),
    Ellipsoid {
        xl: DVec3,
        r: f64,
    },
    Rect(RectSampler),
    Disk {
        xl: DVec3,
        r: f64,
    },
    Cylinder {
        xl: DVec3,
        hl: f64,
        r: f64,
    },
    /// A mesh light: a point drawn by area ([`crate::cpu::mesh::sample`]).
    Mesh,
    /// A dome: its texture's table and, with a normal, the table's product with the
    /// receiver's cosine by tiles (`EnvTable::receiver_tiles`).
    Dome {
        env: Option<&'a EnvTable>,
        n: Option<DVec3>,
        tiles: Option<std::sync::Arc<ReceiverTiles>>,
    },
}

impl<'a> LightAt<'a> {
    /// Sets up light `p`'s strategy for the receiver at `x` (normal `n`, where given); `env` is
    /// the light's alias table if it is a textured dome.
    pub fn new(p: &Prepared, env: Option<&'a EnvTable>, x: DVec3, n: Option<DVec3>) -> LightAt<'a> {
        Self::with_tiles(p, env, x, n, &|t, n| {
            t.receiver_tiles(n).map(std::sync::Arc::new)
        })
    }

    /// [`LightAt::new`], taking a textured dome's tiles for the receiver from `tiles` (a cache,
    /// [`SceneTables::light_at`]).
    pub fn with_tiles(
        p: &Prepared,
        env: Option<&'a EnvTable>,
        x: DVec3,
        n: Option<DVec3>,
        tiles: &dyn Fn(&EnvTable, DVec3) -> Option<std::sync::Arc<ReceiverTiles>>,
    ) -> LightAt<'a> {
        let toward = (p.origin - x).try_normalize().or(n).unwrap_or(DVec3::Y);
        if p.profile.dark {
            return LightAt::Nothing(toward);
        }
        let xl = p.to_local * (x - p.origin);
        match p.light.kind {
            LightType::Mesh { .. } if super::mesh::sample::parts(p).is_some() => LightAt::Mesh,
            LightType::Mesh { .. } => LightAt::Nothing(toward),
            LightType::Dome => LightAt::Dome {
                env,
                n,
                tiles: env.zip(n).and_then(|(t, n)| tiles(t, n)),
            },
            LightType::Distant { .. } => {
                let theta = p.distant_half_angle();
                if theta == 0.0 {
                    LightAt::Delta(-p.axis, p.base)
                } else {
                    LightAt::Cone(Cone::with_angle(-p.axis, theta))
                }
            }
            LightType::Sphere {
                radius,
                treat_as_point: true,
            } => {
                // closed.rs `point_irradiance`: E = base·S(e)·A_proj·cos/d², A_proj the
                // projected area of the ellipsoid along e, π r² |det M| |M⁻¹ e|.
                let w = p.origin - x;
                let d = w.length();
                if !(d > 0.0) {
                    return LightAt::Nothing(toward);
                }
                let area = std::f64::consts::PI * radius * radius * p.det * xl.length() / d;
                LightAt::Delta(w / d, p.base * shaping(p, -w / d) * (area / (d * d)))
            }
            LightType::Sphere { radius, .. } => {
                if !(xl.length() > radius) {
                    return LightAt::Nothing(toward);
                }
                match (p.similarity, spot_cap(p)) {
                    (Some(s), Some(spot)) => {
                        let w = p.origin - x;
                        let d = w.length();
                        let ball = Cone::subtended(w / d, radius * s, d);
                        LightAt::Cone(if spot.solid_angle() < ball.solid_angle() {
                            spot
                        } else {
                            ball
                        })
                    }
                    _ => LightAt::Ellipsoid { xl, r: radius },
                }
            }
            LightType::Rect { width, height } => {
                if !(xl.z < 0.0) {
                    return LightAt::Nothing(toward);
                }
                let corner = p.origin + p.linear * DVec3::new(-width / 2.0, -height / 2.0, 0.0);
                let e1 = p.linear * DVec3::new(width, 0.0, 0.0);
                let e2 = p.linear * DVec3::new(0.0, height, 0.0);
                match RectSampler::new(x, corner, e1, e2) {
                    // Both densities are uniform over a set holding every lit direction, so
                    // the smaller set is never worse (module docs): a spot cone narrower than
                    // the rect seen from x is sampled instead.
                    Some(r) => match spot_cap(p) {
                        Some(cap) if cap.solid_angle() < r.solid_angle() => LightAt::Cone(cap),
                        _ => LightAt::Rect(r),
                    },
                    None => LightAt::Nothing(toward),
                }
            }
            LightType::Disk { radius } => {
                if !(xl.z < 0.0) {
                    return LightAt::Nothing(toward);
                }
                LightAt::Disk { xl, r: radius }
            }
            LightType::Cylinder {
                length,
                radius,
                treat_as_line: true,
            } => {
                let hl = length / 2.0;
                let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
                let weight = 2.0 * radius * p.det * rho;
                if !(weight > 0.0) || !(hl > 0.0) {
                    return LightAt::Nothing(toward);
                }
                LightAt::Line {
                    a: p.origin - x,
                    e: p.linear * DVec3::X,
                    hl,
                    k: p.base * (weight * 2.0 * hl),
                }
            }
            LightType::Cylinder { length, radius, .. } => {
                let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
                if !(rho > radius) {
                    return LightAt::Nothing(toward);
                }
                LightAt::Cylinder {
                    xl,
                    hl: length / 2.0,
                    r: radius,
                }
            }
        }
    }

    /// Whether this is a delta light (its density is +∞).
    #[cfg(any(test, feature = "testkit"))]
    pub fn is_delta(&self) -> bool {
        matches!(self, LightAt::Delta(..) | LightAt::Line { .. })
    }

    /// Draws a direction for `u ∈ [0,1)⁶` (u[0], u[1] the point; u[2], u[3] an environment
    /// map's texel, u[2] with 53 bits; u[4], u[5] its tile): `(ω, pdf)`, and for delta lights
    /// their `L`.
    fn draw(&self, p: &Prepared, x: DVec3, u: [f64; 6]) -> (DVec3, f64, Option<DVec3>) {
        let uv = [u[0], u[1]];
        match self.clone() {
            LightAt::Nothing(w) => (w, 0.0, Some(DVec3::ZERO)),
            LightAt::Delta(w, l) => (w, f64::INFINITY, Some(l)),
            LightAt::Line { a, e, hl, k } => {
                // A point uniform by length: density 1/(2hl) in X, so L·cos is the line
                // integrand of outer.rs times 2hl: `L = k · S(−ω) / |w|³` (S1 "treatAsLine").
                let w = a + e * (hl * (2.0 * u[0] - 1.0));
                let d = w.length();
                if !(d > 0.0) {
                    return (e.normalize(), f64::INFINITY, Some(DVec3::ZERO));
                }
                let dir = w / d;
                (dir, f64::INFINITY, Some(k * shaping(p, -dir) / (d * d * d)))
            }
            LightAt::Cone(c) => (c.sample(uv), 1.0 / c.solid_angle(), None),
            LightAt::Ellipsoid { xl, r } => match ellipsoid_sample(p, xl, r, uv) {
                Some((w, pdf)) => (w, pdf, None),
                None => (DVec3::Y, 0.0, Some(DVec3::ZERO)),
            },
            LightAt::Rect(r) => (r.sample(x, uv), 1.0 / r.solid_angle(), None),
            LightAt::Disk { xl, r } => {
                let (w, pdf) = disk_sample(p, xl, r, uv);
                (w, pdf, None)
            }
            LightAt::Cylinder { xl, hl, r } => match cylinder_sample(p, xl, hl, r, uv) {
                Some((w, pdf)) => (w, pdf, None),
                None => (
                    (p.origin - x).normalize_or(DVec3::Y),
                    0.0,
                    Some(DVec3::ZERO),
                ),
            },
            LightAt::Dome { env, n, tiles } => {
                let (w, pdf) = dome::sample_dome(p, env, n, tiles.as_deref(), u);
                (w, pdf, None)
            }
            LightAt::Mesh => match super::mesh::sample::sample(p, x, [u[0], u[1], u[2]]) {
                Some((w, pdf)) => (w, pdf, None),
                None => (DVec3::Y, 0.0, Some(DVec3::ZERO)),
            },
        }
    }

    /// A direction toward the light for `u` (see `draw`), its density and the radiance along it.
    pub fn sample(&self, p: &Prepared, x: DVec3, u: [f64; 6]) -> Sample {
        let (dir, pdf, l) = self.draw(p, x, u);
        let radiance = match l {
            Some(l) => l,
            None if pdf > 0.0 => radiance(p, x, dir),
            None => DVec3::ZERO,
        };
        Sample { dir, pdf, radiance }
    }

    /// The density [`LightAt::sample`] draws the unit `w` with (0 for delta lights: a given
    /// direction never hits them, S1).
    pub fn pdf(&self, p: &Prepared, x: DVec3, w: DVec3) -> f64 {
        match *self {
            LightAt::Nothing(_) | LightAt::Delta(..) | LightAt::Line { .. } => 0.0,
            LightAt::Cone(c) => c.pdf(w),
            LightAt::Ellipsoid { xl, r } => ellipsoid_pdf(p, xl, r, w),
            LightAt::Rect(r) => match p.light.kind {
                LightType::Rect { width, height } => {
                    let xl = p.to_local * (x - p.origin);
                    if crate::cpu::shapes::rect_hit(xl, p.to_local * w, width / 2.0, height / 2.0) {
                        1.0 / r.solid_angle()
                    } else {
                        0.0
                    }
                }
                _ => 0.0,
            },
            LightAt::Disk { xl, r } => disk_pdf(p, xl, r, w),
            LightAt::Cylinder { xl, hl, r } => cylinder_pdf(p, xl, hl, r, w),
            LightAt::Dome { env, n, ref tiles } => dome::pdf_dome(p, env, n, tiles.as_deref(), w),
            LightAt::Mesh => super::mesh::sample::pdf(p, x, w),
        }
    }
}

/// The directions ω toward a shaped light whose emission direction −ω lies inside its spot
/// cone (`shaping:cone:angle` about the axis; the shaping factor is 0 beyond it, DESIGN.md §2):
/// the cap about −axis. `None` for an unshaped light.
fn spot_cap(p: &Prepared) -> Option<Cone> {
    p.shaping
        .as_ref()
        .map(|sh| Cone::with_angle(-p.axis, sh.cone))
}

/// The strategy that samples `p`, in words (for `lights --json`, the sampler report and docs).
pub fn strategy(p: &Prepared) -> &'static str {
    match p.light.kind {
        LightType::Dome if p.dome_texture().is_some() => {
            "alias table over the filtered texture, times the receiver's cosine by tiles when a normal is given"
        }
        LightType::Dome => "cosine-weighted about the normal (uniform without one)",
        LightType::Distant { .. } if p.distant_half_angle() == 0.0 => "delta (one direction)",
        LightType::Distant { .. } => "uniform in its cone",
        LightType::Sphere {
            treat_as_point: true,
            ..
        } => "delta (treatAsPoint)",
        LightType::Sphere { .. } if p.similarity.is_none() => {
            "uniform in the local subtended cone (ellipsoid)"
        }
        LightType::Sphere { .. } if p.shaping.is_some() => {
            "uniform in the smaller of the subtended cone and the spot cone"
        }
        LightType::Sphere { .. } => "uniform in the subtended cone",
        LightType::Rect { .. } if p.shaping.is_some() => {
            "uniform in solid angle over the smaller of the rect (spherical rectangle or triangles) and the spot cone"
        }
        LightType::Rect { .. } => "uniform in solid angle (spherical rectangle or triangles)",
        LightType::Disk { .. } => "uniform by area",
        LightType::Cylinder {
            treat_as_line: true,
            ..
        } => "delta (treatAsLine, uniform by length)",
        LightType::Cylinder { .. } => "uniform over the visible band by area",
        LightType::Mesh { .. } => {
            "uniform by area over the triangles (the density summed over every triangle crossed)"
        }
    }
}

#[cfg(test)]
mod tests;
