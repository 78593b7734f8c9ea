//! Portal lights (DESIGN.md §8 P1) as plain data: a rectangle a dome's light passes through,
//! with its multiplier inputs, attached to the domes whose `portals` relationship names it.
//! Nothing here evaluates light: what a portal changes (P2) is `prepare::portal`'s and the
//! CPU reference's (`cpu::portal`) to say.

use glam::{DMat4, DVec3};

use crate::error::{LuxError, Result};

/// How a dome's portals are read (DESIGN.md §8 P2; `--portal-mode`, Python `portal_mode=`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PortalMode {
    /// The schema's words, "guide light sampling" (Cycles, Karma, Mitsuba): portals change no
    /// emission, radiance, irradiance or intensity.
    #[default]
    Hint,
    /// hdPrman, Arnold `interior_only`, pbrt-v4: the dome reaches a point only through its
    /// portals, each scaling what passes by its multiplier.
    Mask,
}

impl PortalMode {
    pub const ALL: [PortalMode; 2] = [Self::Hint, Self::Mask];

    pub fn name(self) -> &'static str {
        match self {
            Self::Hint => "hint",
            Self::Mask => "mask",
        }
    }
}

impl std::str::FromStr for PortalMode {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown portal mode {s:?} (expected hint or mask)"))
    }
}

impl std::fmt::Display for PortalMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One `PortalLight`: a `width × height` rectangle in its local XY plane, centred on its
/// origin; light passes through it toward its local −Z (P1).
#[derive(Clone, Debug, PartialEq)]
pub struct Portal {
    pub path: String,
    /// `inputs:width`, `inputs:height` (fallback 1).
    pub width: f64,
    pub height: f64,
    /// The multiplier's LightAPI inputs (P2): `intensity · 2^exposure · color ⊙
    /// temperature(T)`; normalize, diffuse and specular do not apply to a portal.
    pub intensity: f64,
    pub exposure: f64,
    pub color: DVec3,
    pub enable_color_temperature: bool,
    pub color_temperature: f64,
    /// Local-to-world, column-vector convention, as [`super::Light::world`].
    pub world: DMat4,
    /// The domes whose `portals` relationship names this portal, in stage order; empty when
    /// none does (the portal then changes nothing, P1).
    pub domes: Vec<String>,
}

impl Portal {
    /// A `width × height` portal at the origin (light passing toward −Z) with the LightAPI
    /// fallbacks for its multiplier (1), named by no dome yet.
    pub fn new(width: f64, height: f64) -> Self {
        use super::schema::light_api as f;
        Portal {
            path: "<PortalLight>".into(),
            width,
            height,
            intensity: f::INTENSITY,
            exposure: f::EXPOSURE,
            color: DVec3::from_array(f::COLOR),
            enable_color_temperature: f::ENABLE_COLOR_TEMPERATURE,
            color_temperature: f::COLOR_TEMPERATURE,
            world: DMat4::IDENTITY,
            domes: Vec::new(),
        }
    }
    pub fn with_path(mut self, path: impl Into<String>) -> Self {
        self.path = path.into();
        self
    }
    /// Sets the local-to-world transform (column-vector convention).
    pub fn with_transform(mut self, world: DMat4) -> Self {
        self.world = world;
        self
    }
    pub fn with_intensity(mut self, intensity: f64) -> Self {
        self.intensity = intensity;
        self
    }
    pub fn with_exposure(mut self, exposure: f64) -> Self {
        self.exposure = exposure;
        self
    }
    pub fn with_color(mut self, color: DVec3) -> Self {
        self.color = color;
        self
    }
    /// Enables `colorTemperature` at `kelvin`.
    pub fn with_temperature(mut self, kelvin: f64) -> Self {
        self.enable_color_temperature = true;
        self.color_temperature = kelvin;
        self
    }

    /// Checks the inputs a portal is evaluated with (mask mode, DESIGN.md §8 P2), naming the
    /// portal and the attribute: finite sizes ≥ 0, a finite multiplier, an affine finite world
    /// transform. A zero-size or flattened portal is not refused: it passes no light.
    pub fn validate(&self) -> Result<()> {
        let p = &self.path;
        let finite = |name: &str, v: f64| -> Result<()> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(LuxError::attr(p, name, v, "not a finite number"))
            }
        };
        for (name, v) in [("inputs:width", self.width), ("inputs:height", self.height)] {
            finite(name, v)?;
            if v < 0.0 {
                return Err(LuxError::attr(p, name, v, "a size must not be negative"));
            }
        }
        finite("inputs:intensity", self.intensity)?;
        finite("inputs:exposure", self.exposure)?;
        for c in self.color.to_array() {
            finite("inputs:color", c)?;
        }
        finite("inputs:colorTemperature", self.color_temperature)?;
        if !2f64.powf(self.exposure).is_finite() {
            return Err(LuxError::attr(
                p,
                "inputs:exposure",
                self.exposure,
                "2^exposure overflows",
            ));
        }
        let m = self.world.to_cols_array();
        if m.iter().any(|v| !v.is_finite()) {
            return Err(LuxError::InvalidTransform {
                light: p.clone(),
                reason: "has a non-finite entry".into(),
            });
        }
        // Column-vector convention: the last row holds the projective part.
        let last = [m[3], m[7], m[11], m[15]];
        if last != [0.0, 0.0, 0.0, 1.0] {
            return Err(LuxError::InvalidTransform {
                light: p.clone(),
                reason: format!("is not affine (last column {last:?}, expected [0, 0, 0, 1])"),
            });
        }
        Ok(())
    }
}
