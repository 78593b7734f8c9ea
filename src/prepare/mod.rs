//! Everything computed once per light in f64 and consumed by both backends (DESIGN.md §1): the
//! validated light, its base radiance (LightAPI multipliers, colour temperature, normalize's
//! sizeFactor), its frame (origin, linear map and inverse, primary axis, emitting normal), the
//! ShapingAPI constants in radians and the kinks of the shaping factor. The CPU reference
//! evaluates these in f64; the GPU packer rounds them once into its record. Nothing here
//! depends on either backend.

pub mod assets;
pub mod blackbody;
pub mod ies;
pub mod ies_kinks;
pub mod normalize;
pub mod profile;

use std::sync::Arc;

use glam::{DMat3, DVec3};

use crate::error::{LuxError, Result};
use crate::model::{Light, LightType, Shaping, UpAxis};
use assets::AssetCache;
pub use blackbody::TemperatureMode;
use blackbody::temperature_rgb;
pub use profile::{Kink, Profile};

/// A light's IES profile as both backends evaluate it (DESIGN.md §6 I7): the factor along a
/// light-space emission direction e is `scale · Î(e)` with Î the profile's bilinear interpolant
/// after angleScale.
#[derive(Clone, Debug)]
pub struct PreparedIes {
    pub profile: Arc<ies::Profile>,
    /// `ies:angleScale` (§6 I4).
    pub angle_scale: f64,
    /// `1/mean` with `ies:normalize` (the multipliers and tilt cancel, §6 I6), else the tilt
    /// factor at the light's tilt (§6 I5).
    pub scale: f64,
    /// Where the factor is not smooth, in the light's frame (for the irradiance quadrature).
    pub kinks: ies_kinks::IesKinks,
}

/// ShapingAPI's inputs as the evaluation uses them (DESIGN.md §2 "Shaping", spec/002).
#[derive(Clone, Debug, PartialEq)]
pub struct ShapingConsts {
    /// `shaping:focus` (≤ 0: no focus).
    pub focus: f64,
    /// `shaping:focusTint`.
    pub focus_tint: DVec3,
    /// θcone in radians.
    pub cone: f64,
    /// Where the smoothstep starts: `(1 − softness)·θcone`, softness clamped to [0, 1].
    pub start: f64,
}

impl ShapingConsts {
    pub fn new(s: &Shaping) -> Self {
        let cone = s.cone_angle.to_radians();
        ShapingConsts {
            focus: s.focus,
            focus_tint: s.focus_tint,
            cone,
            start: (1.0 - s.cone_softness.clamp(0.0, 1.0)) * cone,
        }
    }
}

/// A validated light with its per-light constants.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The light as evaluated: the input, except that a ShapingAPI whose factor is 1 everywhere
    /// is dropped (see [`shaping_is_identity`]).
    pub light: Light,
    /// `intensity · 2^exposure · color ⊙ temperature(T) / sizeFactor` (DESIGN.md §2 "Emission").
    pub base: DVec3,
    /// The sizeFactor `base` was divided by (1 when normalize is off).
    pub size_factor: f64,
    /// World-space origin.
    pub origin: DVec3,
    /// Local → world linear map M (columns: images of local X, Y, Z).
    pub linear: DMat3,
    /// World → local linear map M⁻¹.
    pub to_local: DMat3,
    /// |det M|.
    pub det: f64,
    /// Unit primary axis in world space: the image of local −Z as a direction.
    pub axis: DVec3,
    /// Unit world normal of a rect or disk's emitting side: the inverse transpose applied to
    /// local −Z. Equals `axis` unless the transform shears.
    pub normal: DVec3,
    /// The scale s when M is s times an orthogonal matrix (a sphere stays a sphere), to 1e-12.
    pub similarity: Option<f64>,
    /// ShapingAPI constants, where the evaluated light is shaped (and shapeable).
    pub shaping: Option<ShapingConsts>,
    /// Where the shaping factor is not smooth (for the irradiance quadrature).
    pub profile: Profile,
    /// A distant light's θmax (half its angular diameter, radians); 0 for other types.
    pub distant_half_angle: f64,
    /// The IES profile of ShapingAPI, where authored (and the light shapeable).
    pub ies: Option<PreparedIes>,
}

impl Prepared {
    /// Validates `light` and computes its constants for `mode`.
    pub fn new(light: &Light, mode: TemperatureMode) -> Result<Self> {
        Self::with_assets(light, mode, &mut AssetCache::default())
    }

    /// [`Prepared::new`], loading referenced files through `cache`.
    pub fn with_assets(
        light: &Light,
        mode: TemperatureMode,
        cache: &mut AssetCache,
    ) -> Result<Self> {
        light.validate()?;
        let linear = light.linear();
        let to_local = linear.inverse();
        let size_factor = normalize::size_factor(light);
        let base = base_radiance(light, mode) / size_factor;
        if size_factor == 0.0 {
            return Err(LuxError::attr(
                &light.path,
                "inputs:normalize",
                "true",
                "the light has zero world-space size, so normalize would divide by zero",
            ));
        }
        if !base.is_finite() {
            return Err(LuxError::attr(
                &light.path,
                "inputs:intensity",
                light.inputs.intensity,
                format!("intensity · 2^exposure · color overflows ({base})"),
            ));
        }
        let mut evaluated = light.clone();
        if evaluated.shaping.as_ref().is_some_and(shaping_is_identity) {
            evaluated.shaping = None;
        }
        let axis = (linear * DVec3::NEG_Z).normalize();
        // Distant and dome lights are not shaped (DESIGN.md §2); the model keeps what the stage
        // authored, the evaluation ignores it.
        let shaping = evaluated
            .shaping
            .as_ref()
            .filter(|_| evaluated.kind.is_shapeable())
            .map(ShapingConsts::new);
        let profile = Profile::new(shaping.as_ref(), axis);
        let distant_half_angle = match evaluated.kind {
            LightType::Distant { angle } => normalize::distant_half_angle(angle),
            _ => 0.0,
        };
        let ies = match evaluated.shaping.as_ref().and_then(|s| s.ies.as_ref()) {
            Some(i) if evaluated.kind.is_shapeable() => {
                let profile = cache.ies(&i.file).map_err(|source| LuxError::Asset {
                    light: light.path.clone(),
                    attr: "inputs:shaping:ies:file".into(),
                    path: i.file.authored.clone(),
                    source,
                })?;
                let scale = if i.normalize {
                    profile.inverse_mean()
                } else {
                    profile.tilt_factor(tilt_angle(axis, light.stage_up))
                };
                Some(PreparedIes {
                    kinks: ies_kinks::ies_kinks(&profile, i.angle_scale),
                    profile,
                    angle_scale: i.angle_scale,
                    scale,
                })
            }
            _ => None,
        };
        Ok(Prepared {
            base,
            size_factor,
            origin: light.origin(),
            linear,
            to_local,
            det: linear.determinant().abs(),
            axis,
            normal: (to_local.transpose() * DVec3::NEG_Z).normalize(),
            similarity: similarity_scale(linear),
            shaping,
            profile,
            distant_half_angle,
            ies,
            light: evaluated,
        })
    }
}

/// `intensity · 2^exposure · color ⊙ temperature(T)` (spec/001 intensity, exposure, color,
/// colorTemperature), before normalize and shaping.
pub fn base_radiance(light: &Light, mode: TemperatureMode) -> DVec3 {
    let i = &light.inputs;
    let scalar = i.intensity * 2f64.powf(i.exposure);
    let tint = if i.enable_color_temperature {
        temperature_rgb(i.color_temperature, mode)
    } else {
        DVec3::ONE
    };
    scalar * i.color * tint
}

/// Whether ShapingAPI's factor is exactly 1 along every direction: no focus (or a white tint), a
/// cone whose smoothstep starts at or beyond 180° (luxtest authors cone 180, softness 0, to mean
/// "no cone") and no IES profile. Such a ShapingAPI is dropped from [`Prepared::light`]: the
/// values are the same, and irradiance can use its closed forms.
pub fn shaping_is_identity(s: &Shaping) -> bool {
    let no_focus = s.focus <= 0.0 || s.focus_tint == DVec3::ONE;
    let start_deg = (1.0 - s.cone_softness.clamp(0.0, 1.0)) * s.cone_angle;
    no_focus && start_deg >= 180.0 && s.ies.is_none()
}

/// The tilt angle τ of DESIGN.md §6 I5 in degrees: between the light's world primary axis and
/// the stage's world down (−Y for `upAxis` Y, −Z for Z).
pub fn tilt_angle(axis: DVec3, up: UpAxis) -> f64 {
    let down = match up {
        UpAxis::Y => DVec3::NEG_Y,
        UpAxis::Z => DVec3::NEG_Z,
    };
    axis.cross(down).length().atan2(axis.dot(down)).to_degrees()
}

/// Prepares every light, failing on the first invalid one; a file referenced by several lights
/// is loaded once.
pub fn prepare(lights: &[Light], mode: TemperatureMode) -> Result<Vec<Prepared>> {
    let mut cache = AssetCache::default();
    lights
        .iter()
        .map(|l| Prepared::with_assets(l, mode, &mut cache))
        .collect()
}

/// The scale s when `m` is a similarity (s times an orthogonal matrix) to 1e-12, else None.
pub fn similarity_scale(m: DMat3) -> Option<f64> {
    let g = m.transpose() * m;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let dev = (g - DMat3::from_diagonal(DVec3::splat(s2))).to_cols_array();
    if s2 > 0.0 && dev.iter().all(|d| d.abs() <= 1e-12 * s2) {
        Some(s2.sqrt())
    } else {
        None
    }
}
