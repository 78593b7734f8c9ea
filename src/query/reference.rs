//! The f64 reference of one light, sample by sample: what the CPU path evaluates before it
//! rounds to f32, for users who check a renderer against the spec and for tests.

use glam::DVec3;

use crate::cpu;
use crate::error::Result;
use crate::model::Light;
use crate::prepare::{PortalMode, Prepared, TemperatureMode};

/// One light, validated and prepared, evaluated in f64 on the CPU.
#[derive(Clone, Debug)]
pub struct Reference {
    pub(crate) p: Prepared,
}

impl Reference {
    /// Validates `light` and computes its per-light constants for `mode`.
    pub fn new(light: &Light, mode: TemperatureMode) -> Result<Self> {
        Ok(Reference {
            p: Prepared::new(light, mode)?,
        })
    }

    /// [`Reference::new`] with a dome's portals read as `portal_mode` says (DESIGN.md §8 P2;
    /// `new` reads them as hints, which change nothing).
    pub fn with_portal_mode(
        light: &Light,
        mode: TemperatureMode,
        portal_mode: PortalMode,
    ) -> Result<Self> {
        let mut p = Prepared::new(light, mode)?;
        p.apply_portal_mode(portal_mode, mode)?;
        Ok(Reference { p })
    }

    /// How the light is evaluated other than as authored, naming the prim: a zero-size light
    /// (DESIGN.md §2) is a point or emits nothing.
    pub fn warning(&self) -> Option<&str> {
        self.p.warning.as_deref()
    }

    /// The light as evaluated (a ShapingAPI whose factor is 1 everywhere is dropped).
    pub fn light(&self) -> &Light {
        &self.p.light
    }

    /// `intensity · 2^exposure · color ⊙ temperature(T) / sizeFactor`.
    pub fn base_radiance(&self) -> DVec3 {
        self.p.base
    }

    /// The sizeFactor the base radiance was divided by (1 when normalize is off).
    pub fn size_factor(&self) -> f64 {
        self.p.size_factor
    }

    /// The unit primary axis in world space (the image of local −Z).
    pub fn axis(&self) -> DVec3 {
        self.p.axis
    }

    /// The world-space origin.
    pub fn origin(&self) -> DVec3 {
        self.p.origin
    }

    /// emission along `e` (any non-zero length; normalised here).
    pub fn emission(&self, e: DVec3) -> DVec3 {
        cpu::emission::emission(&self.p, e.normalize())
    }

    /// radiance arriving at `x` from direction `w` (any non-zero length; normalised here).
    pub fn radiance(&self, x: DVec3, w: DVec3) -> DVec3 {
        cpu::radiance::radiance(&self.p, x, w.normalize())
    }

    /// intensity along `e` (any non-zero length; normalised here): `∫ L cos dA` far-field.
    pub fn intensity(&self, e: DVec3) -> DVec3 {
        cpu::intensity::intensity(&self.p, e.normalize())
    }

    /// The emitting surface's projected area along `e` (any non-zero length).
    pub fn projected_area(&self, e: DVec3) -> f64 {
        cpu::intensity::projected_area(&self.p, e.normalize())
    }

    /// The total emitted power, RGB (lm per channel for L in nits): the integral of the
    /// intensity over the sphere; `None` for distant and dome lights.
    pub fn flux(&self) -> Option<DVec3> {
        cpu::power::flux(&self.p)
    }

    /// [`flux`](Self::flux) as `luxeval lights --json` reports it: RGB, lumens (the
    /// luminance of the RGB flux, Rec. 709 weights) and watts at 683 lm/W.
    pub fn power(&self) -> Option<Power> {
        self.flux().map(|f| {
            let lumens = 0.2126 * f.x + 0.7152 * f.y + 0.0722 * f.z;
            Power {
                rgb: f.to_array(),
                lumens,
                watts: lumens / LUMENS_PER_WATT,
            }
        })
    }

    /// A textured dome's irradiance on a receiver with normal `n` by the fast path: the dome's
    /// filtered texture projected once onto 9 spherical-harmonic coefficients (Ramamoorthi and
    /// Hanrahan; what Filament and most real-time renderers use), then 9 multiply-adds per
    /// normal. An approximation: bands ≥ 3 are dropped, and README "Dome textures" gives its
    /// measured error against the exact [`Reference::irradiance`]. `None` for other lights (and
    /// a zero normal).
    pub fn dome_irradiance_sh9(&self, n: DVec3) -> Option<DVec3> {
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        cpu::irradiance::irradiance_sh9(&self.p, n / len)
    }

    /// irradiance at `x` on a receiver with normal `n` (any length; 0 for a zero normal),
    /// `diffuse` applied.
    pub fn irradiance(&self, x: DVec3, n: DVec3) -> DVec3 {
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return DVec3::ZERO;
        }
        cpu::irradiance::irradiance(&self.p, x, n / len)
    }
}

/// Lumens per watt at 555 nm: the photometric watts a luminous flux stands for.
pub const LUMENS_PER_WATT: f64 = 683.0;

/// A light's total emitted power ([`Reference::power`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Power {
    /// RGB flux (lm per channel for lights in nits).
    pub rgb: [f64; 3],
    /// Luminous flux: the luminance of `rgb`.
    pub lumens: f64,
    /// `lumens` / 683.
    pub watts: f64,
}
