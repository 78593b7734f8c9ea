//! irradiance(x, n) on the CPU (f64). Twin of `shaders/irradiance.wgsl`; its parts are the
//! modules below, each the twin of the WGSL file of the same name under `shaders/irradiance/`
//! (root finding: `cpu::roots` ↔ `shaders/shared/roots.wgsl`).
//!
//! DESIGN.md §3: `E = diffuse · ∫ radiance(x, ω) max(0, n·ω) dω` over all directions, per light,
//! with no occlusion; the receiver is one-sided (n·ω ≤ 0 contributes nothing). The target is
//! 1e-6 relative to the exact value; every path below meets it with margin (the tests compare
//! them with closed forms and with independent quadrature written in the tests).
//!
//! - [`closed`]: the closed forms (dome, distant delta and cone, unshaped sphere under a
//!   similarity, unshaped rect by Lambert's formula, `treatAsPoint`).
//! - Everything else (shaped lights, disks, ellipsoids, cylinders, `treatAsLine`) is one
//!   deterministic scheme: a plane [`chart`] of the directions x sees the light in, in which
//!   `E = L·∫∫ S(−ŵ)·max(0, n·w)·J/|w|⁴ dX dY` (S the RGB shaping factor of the emission
//!   direction e = −ŵ: cone, softness, focus, tint, IES; a rect's texture, [`rect_texture`];
//!   from `--tolerance` 1e-4 on a textured rect takes [`rect_fast`]), integrated over
//!   lines Y = const ([`line`]) across the pieces between [`critical`] Ys ([`outer`]), each
//!   piece mapped to remove peaks and square-root ends ([`pieces`]).
//!
//! How each smooth piece is integrated is a [`Rule`]: the reference's [`Adaptive`] rule
//! (globally adaptive Gauss–Kronrod to ~1e-9 relative, stopping on its own error estimates),
//! the same driver for a looser `--tolerance` ([`Adaptive::for_tolerance`]: cheaper pairs and
//! exact per-receiver shortcuts), or, for tests, the WGSL kernel's rule replayed in f64
//! (`testkit`).

// `!(a > b)` is deliberate throughout: a NaN fails the test and takes the safe branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod chart;
pub mod closed;
pub mod critical;
pub mod dome;
// The device's method in f64, checked against the reference by its tests (which are its only
// callers: the reference integrates by pieces, dome.rs).
#[cfg_attr(not(test), allow(dead_code))]
pub mod latlong_polygon;
#[cfg_attr(not(test), allow(dead_code))]
pub mod latlong_rows;
pub mod line;
pub mod outer;
pub mod pieces;
// The device's sum for masked domes (prepare::portal::overlaps), checked
// against the visible pieces of cpu::portal::irradiance by its tests (its only callers).
#[cfg_attr(not(test), allow(dead_code))]
pub mod portals;
pub mod rect_fast;
pub mod rect_texture;

use glam::DVec3;
use std::f64::consts::PI;

use super::quadrature::{Pair, Tolerance, integrate_with};
use crate::model::LightType;
use crate::prepare::{Prepared, Profile};
use chart::{Chart, Region, cylinder_chart, plane_chart, sphere_chart};
use closed::{cap_irradiance, point_irradiance, rect_lambert, sphere_cap};
use outer::{chart_integral, chart_integral_as, line_irradiance};

/// irradiance at `x` for a receiver with unit normal `n`, `diffuse` applied, by the reference
/// rule.
pub fn irradiance(p: &Prepared, x: DVec3, n: DVec3) -> DVec3 {
    irradiance_with(p, x, n, &Adaptive::REFERENCE)
}

/// A textured dome's irradiance by the 9-coefficient spherical-harmonics fast path
/// ([`dome::sh`]), `diffuse` applied: an approximation whose error against [`irradiance`] depends
/// on the map (README "Dome textures" gives measured figures). `None` for other lights.
pub fn irradiance_sh9(p: &Prepared, n: DVec3) -> Option<DVec3> {
    // A masked dome (DESIGN.md §8 P2) is not a function of the normal alone.
    if p.light.kind != LightType::Dome || p.portals.is_some() {
        return None;
    }
    let t = dome::tables(p)?;
    Some(p.base * t.irradiance_sh9(n) * p.light.inputs.diffuse)
}

/// [`irradiance`] with the quadrature's [`Rule`] chosen (closed forms are used either way).
pub fn irradiance_with<R: Rule>(p: &Prepared, x: DVec3, n: DVec3, rule: &R) -> DVec3 {
    let e = match p.light.kind {
        LightType::Mesh { .. } => super::mesh::irradiance(p, x, n, rule.piece_tolerance()),
        // A dome masked by its portals (DESIGN.md §8 P2 mask mode), see cpu/portal.rs.
        LightType::Dome if let Some(portals) = &p.portals => {
            super::portal::irradiance(p, portals, x, n)
        }
        // A textured dome's irradiance is the exact integral of its filtered texture (DESIGN.md
        // §6 "Dome and texture irradiance: what 'exact' means"), see dome.rs.
        LightType::Dome if p.dome_texture().is_some() => match dome::tables(p) {
            Some(t) => p.base * t.irradiance(n),
            None => DVec3::NAN,
        },
        LightType::Dome => p.base * PI,
        LightType::Distant { .. } => {
            let c = -p.axis;
            let theta_max = p.distant_half_angle();
            let sg = n.dot(c);
            if theta_max == 0.0 {
                p.base * sg.max(0.0)
            } else {
                p.base * cap_irradiance(theta_max, sg, n.cross(c).length())
            }
        }
        LightType::Sphere {
            radius,
            treat_as_point: true,
        } => point_irradiance(p, x, n, radius),
        LightType::Sphere { radius, .. } => match (&p.shaping, p.similarity) {
            (None, Some(scale)) => p.base * sphere_cap(p.origin, radius * scale, x, n),
            (Some(_), Some(scale))
                if rule.shortcuts()
                    && let Some(k) = sphere_uniform(p, x, radius * scale) =>
            {
                p.base * (k * sphere_cap(p.origin, radius * scale, x, n))
            }
            _ => match sphere_chart(p, x, radius) {
                Some(c) => chart_irradiance(p, &c, n, rule),
                None => DVec3::ZERO,
            },
        },
        LightType::Rect { width, height } => {
            let xl = p.to_local * (x - p.origin);
            if !(xl.z < 0.0) {
                DVec3::ZERO
            } else if p.shaping.is_none() && p.rect_texture().is_none() {
                p.base * rect_lambert(p, x, n, width / 2.0, height / 2.0)
            } else if let Some(k) = (rule.shortcuts() && p.rect_texture().is_none())
                .then(|| {
                    let c = plane_chart(p, x, width / 2.0, height / 2.0, Region::Square);
                    outer::direction_cone(&c, c.w0, c.e1, c.e2)
                        .and_then(|(d, alpha)| uniform_shaping(p, d, alpha))
                })
                .flatten()
            {
                p.base * (k * rect_lambert(p, x, n, width / 2.0, height / 2.0))
            } else if let Some(rel) = rule.texture_tolerance()
                && rect_fast::applies(p)
            {
                // The fast path of a textured rect at a loose tolerance (rect_fast.rs).
                let c = plane_chart(p, x, width / 2.0, height / 2.0, Region::Square);
                if p.profile.dark || !(c.jac > 0.0) || !c.jac.is_finite() {
                    DVec3::ZERO
                } else {
                    p.base * rect_fast::chart_integral(p, &c, n, rel).unwrap_or(DVec3::NAN)
                }
            } else {
                let c = plane_chart(p, x, width / 2.0, height / 2.0, Region::Square);
                chart_irradiance(p, &c, n, rule)
            }
        }
        LightType::Disk { radius } => {
            let xl = p.to_local * (x - p.origin);
            if !(xl.z < 0.0) {
                DVec3::ZERO
            } else {
                let c = plane_chart(p, x, radius, radius, Region::Disk);
                chart_irradiance(p, &c, n, rule)
            }
        }
        LightType::Cylinder {
            length,
            radius,
            treat_as_line: true,
        } => line_irradiance(p, x, n, length / 2.0, radius, rule),
        LightType::Cylinder { length, radius, .. } => {
            match cylinder_chart(p, x, length / 2.0, radius) {
                Some(c) => chart_irradiance(p, &c, n, rule),
                None => DVec3::ZERO,
            }
        }
    };
    e * p.light.inputs.diffuse
}

/// [`uniform_shaping`] for a sphere of world radius `r` (under a similarity) seen from x: its
/// directions fill the cone of half-angle asin(r/d) around the centre's.
fn sphere_uniform(p: &Prepared, x: DVec3, r: f64) -> Option<f64> {
    let w = p.origin - x;
    let d = w.length();
    if !(d > r) {
        return None;
    }
    uniform_shaping(p, w / d, (r / d).asin())
}

/// The chart integral times the base radiance.
pub fn chart_irradiance<R: Rule>(p: &Prepared, chart: &Chart, n: DVec3, rule: &R) -> DVec3 {
    p.base * rule.chart(p, chart, n)
}

/// How the chart quadrature integrates each smooth piece (mapped to [0, 1]).
pub trait Rule {
    /// ∫₀¹ f over one outer piece.
    fn outer(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3;
    /// ∫₀¹ f over one inner piece.
    fn inner(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3;
    /// A tan-mapped piece is cut into equal spans of at most this many radians of u (None:
    /// never cut).
    fn max_u_span(&self) -> Option<f64> {
        None
    }
    /// Whether an unshaped line piece takes the closed form (else the inner rule), given
    /// whether the piece is tan-mapped.
    fn unshaped_closed_form(&self, tan_mapped: bool) -> bool {
        let _ = tan_mapped;
        true
    }
    /// Whether the exact per-receiver shortcuts of [`uniform_shaping`] are taken.
    fn shortcuts(&self) -> bool {
        false
    }
    /// The relative tolerance a shaped mesh light's visible pieces are integrated to
    /// (`cpu::mesh::irradiance`): the reference's 1e-9 unless the rule says otherwise.
    fn piece_tolerance(&self) -> f64 {
        1e-9
    }
    /// The relative tolerance a textured rect's fast path ([`rect_fast`]) is run to; None: the
    /// exact split path (`rect_texture`) runs.
    fn texture_tolerance(&self) -> Option<f64> {
        None
    }
    /// The whole chart integral (the base radiance not applied).
    fn chart(&self, p: &Prepared, chart: &Chart, n: DVec3) -> DVec3
    where
        Self: Sized,
    {
        if p.profile.dark || !(chart.jac > 0.0) || !chart.jac.is_finite() {
            return DVec3::ZERO;
        }
        let ys = critical::critical_ys(p, chart, n);
        chart_integral(p, chart, n, &ys, self)
    }
}

/// The reference's rule: globally adaptive Gauss–Kronrod (QUADPACK `qag`) on every piece.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    pub outer: Tolerance,
    pub inner: Tolerance,
    /// The rule also stops once its error estimate is below this fraction of the whole
    /// irradiance, estimated first by the [`Coarse`] pass (see [`ABS_FRACTION`]); 0: never.
    pub scale_fraction: f64,
    /// The Gauss–Kronrod pair of every interval across lines ...
    pub outer_pair: Pair,
    /// ... and along them.
    pub inner_pair: Pair,
    /// How the whole irradiance is estimated for `scale_fraction`.
    pub coarse: Coarse,
    /// Take the exact per-receiver shortcuts of [`uniform_shaping`] (a shaping factor that is
    /// exactly 0 or 1 on every direction the light is seen in): the value changes by rounding
    /// only, but not bit for bit, so the reference does not.
    pub shortcuts: bool,
}

/// The first, cheap pass that estimates the scale of the whole irradiance (only to set
/// [`Adaptive`]'s absolute thresholds).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coarse {
    /// [`Adaptive::COARSE`]: the reference's (Gauss–Kronrod 15 with small interval caps).
    Adaptive,
    /// The 3-point Gauss–Legendre rule once per outer piece and once per line piece
    /// ([`Gauss3`]): 9 evaluations per pair of pieces instead of Gauss–Kronrod 15's 225 or
    /// more. What a rough estimate costs the accuracy is bounded by how `scale_fraction` uses
    /// it: a scale over by a factor k loosens the absolute thresholds by k, which the loose
    /// tolerances' budget (`rel/8` against `rel`) absorbs for k < 2.
    Gauss3,
}

impl Adaptive {
    /// The reference: 1e-9 relative across lines, 1e-10 along them (the tests measure the result
    /// within ~1e-8 of independent references).
    pub const REFERENCE: Adaptive = Adaptive {
        outer: Tolerance {
            rel: 1e-9,
            abs: 0.0,
            max_intervals: 4000,
        },
        inner: Tolerance {
            rel: 1e-10,
            abs: 0.0,
            max_intervals: 400,
        },
        scale_fraction: ABS_FRACTION,
        outer_pair: Pair::Gk15,
        inner_pair: Pair::Gk15,
        coarse: Coarse::Adaptive,
        shortcuts: false,
    };

    /// The rule for a relative tolerance `rel` of the whole irradiance (`luxeval irradiance
    /// --tolerance`; [`Adaptive::REFERENCE`] for `rel` at or below its own 1e-9). The error
    /// budget is split with margin: the outer rule stops at `rel/4` of its value, each line at
    /// `rel/40` of its own (the outer rule integrates the lines' errors), and either stops once
    /// its estimate is below `rel/8` of the coarse estimate of the whole (pieces that contribute
    /// nothing measurable). Gauss–Kronrod's estimates are themselves pessimistic, and the test
    /// `tolerance_maps_hold_the_reference` measures the result against the reference.
    ///
    /// What a loose tolerance buys (issue 24; BENCHMARKS.md "The jobs people run"): every rule
    /// here takes the exact shortcuts of [`uniform_shaping`]; from [`LOOSE`] on, the 3-point
    /// Gauss / 7-point Kronrod pair ([`crate::rules::gk7`]: 7 evaluations a piece where
    /// Gauss–Kronrod 15 takes 15, 49 instead of 225 for a piece of the nested integral), the
    /// [`Coarse::Gauss3`] scale, the IES profile's grid surfaces as outer breakpoints
    /// (`critical::ies_ys`) and the GPU kernel's 24 samples per arc for the arcs' roots.
    pub fn for_tolerance(rel: f64) -> Adaptive {
        if !(rel > Self::REFERENCE.outer.rel) {
            return Self::REFERENCE;
        }
        Adaptive {
            outer: Tolerance {
                rel: rel / 4.0,
                ..Self::REFERENCE.outer
            },
            inner: Tolerance {
                rel: rel / 40.0,
                ..Self::REFERENCE.inner
            },
            scale_fraction: rel / 8.0,
            outer_pair: if rel >= LOOSE { Pair::Gk7 } else { Pair::Gk15 },
            inner_pair: if rel >= LOOSE { Pair::Gk7 } else { Pair::Gk15 },
            coarse: if rel >= LOOSE {
                Coarse::Gauss3
            } else {
                Coarse::Adaptive
            },
            shortcuts: true,
        }
    }

    /// A cheap estimate of the same integral, used only to scale [`ABS_FRACTION`].
    pub const COARSE: Adaptive = Adaptive {
        outer: Tolerance {
            rel: 1e-3,
            abs: 0.0,
            max_intervals: 32,
        },
        inner: Tolerance {
            rel: 1e-4,
            abs: 0.0,
            max_intervals: 8,
        },
        scale_fraction: 0.0,
        outer_pair: Pair::Gk15,
        inner_pair: Pair::Gk15,
        coarse: Coarse::Adaptive,
        shortcuts: false,
    };
}

/// From this relative tolerance on, [`Adaptive::for_tolerance`] takes the 7-point pair and the
/// [`Coarse::Gauss3`] scale.
pub const LOOSE: f64 = 1e-5;

/// The 3-point Gauss–Legendre rule on [0, 1] for outer and inner pieces alike, no error
/// estimate: [`Coarse::Gauss3`].
pub struct Gauss3;

impl Gauss3 {
    fn apply(f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        // Nodes (1 ± √(3/5))/2 and 1/2, weights 5/18, 8/18 (A&S 25.4.29 mapped to [0, 1]).
        const D: f64 = 0.387_298_334_620_741_688_517_926_539_978;
        (f(0.5 - D) + f(0.5 + D)) * (5.0 / 18.0) + f(0.5) * (8.0 / 18.0)
    }
}

impl Rule for Gauss3 {
    fn outer(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        Self::apply(f)
    }

    fn inner(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        Self::apply(f)
    }
}

/// The reference also stops once its error estimate is below this fraction of the whole
/// irradiance, estimated first by a coarse pass of the same rule ([`Adaptive::COARSE`]): pieces
/// that contribute nothing measurable (a factor that is zero up to rounding, a far corner of a
/// cone's tail) cannot reach a relative tolerance of their own, and would each run to the
/// interval cap (a 200 s receiver was seen before this).
pub const ABS_FRACTION: f64 = 1e-12;

impl Rule for Adaptive {
    fn outer(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        integrate_with(f, &[0.0, 1.0], self.outer, self.outer_pair)
    }

    fn inner(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        integrate_with(f, &[0.0, 1.0], self.inner, self.inner_pair)
    }

    fn shortcuts(&self) -> bool {
        self.shortcuts
    }

    fn piece_tolerance(&self) -> f64 {
        self.outer.rel
    }

    /// The tolerance asked of [`Adaptive::for_tolerance`] (its outer rule stops at a quarter of
    /// it) when it is at least [`rect_fast::MIN_TOLERANCE`]; the reference (no shortcuts) and
    /// tighter rules keep the exact split path.
    fn texture_tolerance(&self) -> Option<f64> {
        let rel = 4.0 * self.outer.rel;
        (self.shortcuts && rel >= rect_fast::MIN_TOLERANCE * (1.0 - 1e-12)).then_some(rel)
    }

    fn chart(&self, p: &Prepared, chart: &Chart, n: DVec3) -> DVec3 {
        if p.profile.dark || !(chart.jac > 0.0) || !chart.jac.is_finite() {
            return DVec3::ZERO;
        }
        let uniform = self.shortcuts
            && p.rect_texture().is_none()
            && match outer::direction_cone(chart, chart.w0, chart.e1, chart.e2) {
                Some((c, alpha)) => match uniform_shaping(p, c, alpha) {
                    Some(0.0) => return DVec3::ZERO,
                    Some(_) => true,
                    None => false,
                },
                None => false,
            };
        let unshaped_profile = Profile::new(None, p.axis);
        let arc_samples = if self.outer_pair == Pair::Gk7 {
            critical::LOOSE_ARC_SAMPLES
        } else {
            critical::ARC_SAMPLES
        };
        let prof = if uniform {
            &unshaped_profile
        } else {
            &p.profile
        };
        let mut ys = critical::critical_ys_with(p, prof, chart, n, arc_samples);
        let mut rule = *self;
        if let Some(ies) = &p.ies
            && self.outer_pair == Pair::Gk7
        {
            // An IES profile's grid lines are breakpoints of every line but not of the
            // reference's outer integral (`critical_ys` lists the shaping's kinks only): across
            // lines the integrand has kinks (where a line first meets a grid cone) that the
            // 7-point pair's estimate can miss (measured: 1.4e-2 on a 1e-2 map of luxtest
            // iesTest). The loose rules split there too.
            critical::add_ies_ys(p, ies, chart, n, &mut ys);
        }
        if self.outer.abs == 0.0 && self.scale_fraction > 0.0 {
            // The scale of the answer from a coarse pass; an inner error δ on every line moves
            // the outer integral by δ·jac·(Y extent).
            let scale = match self.coarse {
                Coarse::Adaptive => chart_integral_as(p, chart, n, &ys, &Self::COARSE, uniform),
                Coarse::Gauss3 => chart_integral_as(p, chart, n, &ys, &Gauss3, uniform),
            };
            let scale = scale.abs().max_element();
            let extent = chart.jac * (ys[ys.len() - 1] - ys[0]);
            if scale > 0.0 && scale.is_finite() && extent > 0.0 && extent.is_finite() {
                rule.outer.abs = self.scale_fraction * scale;
                rule.inner.abs = self.scale_fraction * scale / extent;
            }
        }
        chart_integral_as(p, chart, n, &ys, &rule, uniform)
    }
}

/// The shaping factor's value when it is exactly the same, 0 or 1, on every emission
/// direction of a light seen from x within the cone of directions (unit `c` toward the light,
/// half-angle `alpha`), else None. The emission directions are then within `alpha` of `−c`, so
/// their angles θ off the primary axis lie within `alpha` of `−c`'s. With no IES profile and an
/// inactive focus (focus ≤ 0 or a white tint: `lerp` gives exactly 1) the factor is the cone's
/// `1 − smoothstep(θ; start, cone)`: exactly 1 for θ ≤ start and exactly 0 for θ > cone
/// (`cpu::shaping`). A margin of 1e-9 rad covers the rounding of θ. The irradiance is then that
/// of the unshaped light (closed forms, or the unshaped lines) or 0: exact, not a far-field
/// approximation.
pub fn uniform_shaping(p: &Prepared, c: DVec3, alpha: f64) -> Option<f64> {
    const MARGIN: f64 = 1e-9;
    let s = p.shaping.as_ref()?;
    if p.ies.is_some() || !(alpha >= 0.0) {
        return None;
    }
    let theta = crate::cpu::shaping::off_axis_angle(p.axis, -c);
    if theta - alpha > s.cone + MARGIN {
        return Some(0.0);
    }
    let focus_inactive = !(s.focus > 0.0) || s.focus_tint == DVec3::ONE;
    (focus_inactive && theta + alpha + MARGIN < s.start && s.start <= s.cone).then_some(1.0)
}

/// Everything one line integral needs.
pub struct Ctx<'a, R> {
    pub p: &'a Prepared,
    pub n: DVec3,
    /// Use the closed-form inner integral (no shaping, no texture).
    pub unshaped: bool,
    pub rule: &'a R,
    /// A textured rect's texture (rect_texture.rs): one more factor of the integrand, and its
    /// break lines.
    pub tex: Option<rect_texture::ChartTexture<'a>>,
    /// The IES profile's kink surfaces that can meet the chart's directions
    /// ([`outer::chart_ies_kinks`]); None: all of the profile's (or no profile).
    pub ies_kinks: Option<crate::prepare::ies_kinks::IesKinks>,
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::model::Light;
    use crate::prepare::TemperatureMode;
    use glam::{DMat4, DQuat};

    fn prep(l: &Light) -> Prepared {
        Prepared::new(l, TemperatureMode::Spec).unwrap()
    }

    /// Relative difference, 0 for equal values.
    pub(crate) fn rel(a: f64, b: f64) -> f64 {
        if a == b {
            0.0
        } else {
            (a - b).abs() / b.abs().max(a.abs())
        }
    }

    #[test]
    fn engine_matches_lambert_and_cap_for_unshaped_lights() {
        let m = DMat4::from_rotation_translation(
            DQuat::from_rotation_x(-1.2),
            DVec3::new(0.3, 1.0, -0.2),
        );
        let rect = prep(&Light::rect(1.5, 0.7).with_transform(m));
        let sphere = prep(&Light::sphere(0.4).with_transform(m));
        let pts = [
            (DVec3::new(0.2, -0.5, 0.1), DVec3::new(0.1, 1.0, 0.2)),
            (DVec3::new(1.5, -0.1, 2.0), DVec3::new(-0.3, 0.4, -1.0)),
            (DVec3::new(0.4, 0.9, 0.3), DVec3::new(0.0, 0.2, 1.0)),
            (DVec3::new(-3.0, 2.0, 4.0), DVec3::new(1.0, -0.3, -1.0)),
        ];
        for (x, n) in pts {
            let n = n.normalize();
            let xl = rect.to_local * (x - rect.origin);
            if xl.z < 0.0 {
                let lam = closed::rect_lambert(&rect, x, n, 0.75, 0.35);
                let q = chart_irradiance(
                    &rect,
                    &plane_chart(&rect, x, 0.75, 0.35, Region::Square),
                    n,
                    &Adaptive::REFERENCE,
                )
                .x;
                assert!(rel(q, lam) < 1e-9, "rect {x}: {q} vs {lam}");
            }
            let cap = closed::sphere_cap(sphere.origin, 0.4, x, n);
            let q = match sphere_chart(&sphere, x, 0.4) {
                Some(c) => chart_irradiance(&sphere, &c, n, &Adaptive::REFERENCE).x,
                None => 0.0,
            };
            assert!(rel(q, cap) < 1e-9, "sphere {x}: {q} vs {cap}");
        }
    }
}
