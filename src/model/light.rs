//! The light model: resolved UsdLux lights, independent of where they came from (a USD stage,
//! or built in code). Every input is stored with its resolved value (authored or the schema
//! fallback of [`super::schema`]); angles are in degrees as USD authors them.
//!
//! Transforms: `world` is the light's local-to-world matrix in glam's column-vector convention
//! (`p_world = world * p_local`). USD writes the same matrix in row-vector form
//! (`p_world = p_local * M`); [`Light::with_usd_matrix`] and [`Light::usd_matrix`] convert,
//! the one being the transpose of the other.

use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3};

use super::asset::Asset;
use super::mesh::MeshGeometry;
use super::portal::Portal;

use super::schema;
use crate::error::{LuxError, Result};

/// LightAPI inputs shared by every light (spec/001).
#[derive(Clone, Debug, PartialEq)]
pub struct LightInputs {
    pub intensity: f64,
    pub exposure: f64,
    pub color: DVec3,
    pub enable_color_temperature: bool,
    /// Kelvin.
    pub color_temperature: f64,
    pub normalize: bool,
    /// Multiplies the diffuse response of receivers (applied by irradiance), not the emission.
    pub diffuse: f64,
    /// Multiplies the specular response of receivers; carried for renderers, unused by queries.
    pub specular: f64,
}

impl Default for LightInputs {
    fn default() -> Self {
        use schema::light_api as f;
        LightInputs {
            intensity: f::INTENSITY,
            exposure: f::EXPOSURE,
            color: DVec3::from_array(f::COLOR),
            enable_color_temperature: f::ENABLE_COLOR_TEMPERATURE,
            color_temperature: f::COLOR_TEMPERATURE,
            normalize: f::NORMALIZE,
            diffuse: f::DIFFUSE,
            specular: f::SPECULAR,
        }
    }
}

/// ShapingAPI inputs (spec/002). Present on a light only where ShapingAPI is applied.
#[derive(Clone, Debug, PartialEq)]
pub struct Shaping {
    /// `inputs:shaping:focus`; values ≤ 0 are ignored.
    pub focus: f64,
    /// `inputs:shaping:focusTint`.
    pub focus_tint: DVec3,
    /// `inputs:shaping:cone:angle`, degrees off the primary axis.
    pub cone_angle: f64,
    /// `inputs:shaping:cone:softness`, clamped to [0, 1] when evaluated.
    pub cone_softness: f64,
    /// `inputs:shaping:ies:*`, where `ies:file` is authored (DESIGN.md §6 I1–I7).
    pub ies: Option<Ies>,
}

/// ShapingAPI's IES inputs (spec/002; DESIGN.md §6).
#[derive(Clone, Debug, PartialEq)]
pub struct Ies {
    /// `inputs:shaping:ies:file`: an LM-63 or EULUMDAT file (detected by content).
    pub file: Asset,
    /// `inputs:shaping:ies:angleScale` (§6 I4).
    pub angle_scale: f64,
    /// `inputs:shaping:ies:normalize`: divide by the profile's mean intensity (§6 I6).
    pub normalize: bool,
}

impl Ies {
    /// The profile in `file` with the schema's fallbacks for angleScale and normalize.
    pub fn new(file: Asset) -> Self {
        Ies {
            file,
            angle_scale: schema::shaping_api::IES_ANGLE_SCALE,
            normalize: schema::shaping_api::IES_NORMALIZE,
        }
    }
}

/// `inputs:texture:format` of DomeLight / DomeLight_1 as authored (DESIGN.md §6 D2–D6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureFormat {
    /// Decided from the file (§6 D6): the EXR `envmap` attribute, else the image's aspect.
    #[default]
    Automatic,
    LatLong,
    MirroredBall,
    Angular,
    CubeMapVerticalCross,
}

impl TextureFormat {
    /// The format a `texture:format` token names, `None` for a token the schema does not allow.
    pub fn from_token(token: &str) -> Option<Self> {
        Some(match token {
            "automatic" => TextureFormat::Automatic,
            "latlong" => TextureFormat::LatLong,
            "mirroredBall" => TextureFormat::MirroredBall,
            "angular" => TextureFormat::Angular,
            "cubeMapVerticalCross" => TextureFormat::CubeMapVerticalCross,
            _ => return None,
        })
    }
}

/// DomeLight_1's `poleAxis` (spec/004; DESIGN.md §6 D1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PoleAxis {
    /// Follow the stage's `upAxis`.
    #[default]
    Scene,
    Y,
    Z,
}

impl PoleAxis {
    /// The axis a `poleAxis` token names, `None` for a token the schema does not allow.
    pub fn from_token(token: &str) -> Option<Self> {
        Some(match token {
            "scene" => PoleAxis::Scene,
            "Y" => PoleAxis::Y,
            "Z" => PoleAxis::Z,
            _ => return None,
        })
    }
}

/// A light's `inputs:texture:*` (DomeLight, DomeLight_1, RectLight), where `texture:file` is
/// authored.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// `inputs:texture:file`.
    pub file: Asset,
    /// `inputs:texture:format` (domes; `Automatic` and unused for a RectLight).
    pub format: TextureFormat,
    /// DomeLight_1's `poleAxis`; `None` for a plain DomeLight (always Y-up, §6 D1) and for a
    /// RectLight.
    pub pole_axis: Option<PoleAxis>,
    /// How texels are reconstructed between their centres (not a UsdLux input: luxeval's
    /// `--texture-filter`, DESIGN.md §4). Bilinear by default.
    pub filter: TextureFilter,
}

/// Texture reconstruction (DESIGN.md §6 D1 and "RectLight texture"): bilinear between texel
/// centres (the default), or the nearest texel. Irradiance integrates whichever is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TextureFilter {
    #[default]
    Bilinear,
    Nearest,
}

impl Texture {
    /// A texture file with the schema fallbacks: format `automatic`, no pole offset.
    pub fn new(file: Asset) -> Self {
        Texture {
            file,
            format: TextureFormat::Automatic,
            pole_axis: None,
            filter: TextureFilter::Bilinear,
        }
    }
    pub fn with_filter(mut self, filter: TextureFilter) -> Self {
        self.filter = filter;
        self
    }
    pub fn with_format(mut self, format: TextureFormat) -> Self {
        self.format = format;
        self
    }
    /// Makes the light a DomeLight_1 with `poleAxis` = `axis`.
    pub fn with_pole_axis(mut self, axis: PoleAxis) -> Self {
        self.pole_axis = Some(axis);
        self
    }
}

/// The stage's up axis (`upAxis` metadata): what "down" means for an IES profile's TILT
/// (DESIGN.md §6 I5) and what DomeLight_1's `poleAxis = scene` follows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpAxis {
    #[default]
    Y,
    Z,
}

impl Default for Shaping {
    /// The ShapingAPI schema fallbacks: what applying the API with nothing authored means
    /// (a 90° cone: the hemisphere around −Z).
    fn default() -> Self {
        use schema::shaping_api as f;
        Shaping {
            focus: f::FOCUS,
            focus_tint: DVec3::from_array(f::FOCUS_TINT),
            cone_angle: f::CONE_ANGLE,
            cone_softness: f::CONE_SOFTNESS,
            ies: None,
        }
    }
}

/// The light types luxeval evaluates, with their type-specific inputs.
#[derive(Clone, Debug, PartialEq)]
pub enum LightType {
    /// DistantLight: `angle` is the full angular diameter in degrees; 0 is a delta light.
    Distant { angle: f64 },
    /// SphereLight.
    Sphere { radius: f64, treat_as_point: bool },
    /// DiskLight in the local XY plane, emitting toward −Z.
    Disk { radius: f64 },
    /// RectLight in the local XY plane (width along X), emitting toward −Z.
    Rect { width: f64, height: f64 },
    /// CylinderLight along local X, emitting from its side only.
    Cylinder {
        length: f64,
        radius: f64,
        treat_as_line: bool,
    },
    /// DomeLight / DomeLight_1: a uniform environment, or the map in [`Light::texture`].
    Dome,
    /// A `Mesh` with MeshLightAPI (DESIGN.md §7): its world-space triangles (shared, not copied,
    /// when the light is cloned), whether both sides emit, and the tint of
    /// `light:materialSyncMode` (M2), which multiplies the emission like `inputs:color`.
    /// [`Light::world`] is the prim's world transform: shaping's primary axis is its local −Z.
    Mesh {
        geometry: Arc<MeshGeometry>,
        double_sided: bool,
        tint: DVec3,
    },
}

impl LightType {
    /// The USD schema type name.
    pub fn usd_type(&self) -> &'static str {
        match self {
            LightType::Distant { .. } => "DistantLight",
            LightType::Sphere { .. } => "SphereLight",
            LightType::Disk { .. } => "DiskLight",
            LightType::Rect { .. } => "RectLight",
            LightType::Cylinder { .. } => "CylinderLight",
            LightType::Dome => "DomeLight",
            LightType::Mesh { .. } => "Mesh",
        }
    }

    /// A light of this USD type with every type-specific input at its schema fallback.
    pub fn fallback(usd_type: &str) -> Option<LightType> {
        Some(match usd_type {
            "DistantLight" => LightType::Distant {
                angle: schema::distant::ANGLE,
            },
            "SphereLight" => LightType::Sphere {
                radius: schema::sphere::RADIUS,
                treat_as_point: schema::sphere::TREAT_AS_POINT,
            },
            "DiskLight" => LightType::Disk {
                radius: schema::disk::RADIUS,
            },
            "RectLight" => LightType::Rect {
                width: schema::rect::WIDTH,
                height: schema::rect::HEIGHT,
            },
            "CylinderLight" => LightType::Cylinder {
                length: schema::cylinder::LENGTH,
                radius: schema::cylinder::RADIUS,
                treat_as_line: schema::cylinder::TREAT_AS_LINE,
            },
            "DomeLight" | "DomeLight_1" => LightType::Dome,
            _ => return None,
        })
    }

    /// Whether ShapingAPI affects this type (DESIGN.md §2: distant and dome lights are not shaped).
    pub fn is_shapeable(&self) -> bool {
        !matches!(self, LightType::Distant { .. } | LightType::Dome)
    }
}

/// One resolved light.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Prim path (or any name for lights built in code); used in every error message.
    pub path: String,
    pub kind: LightType,
    /// Local-to-world, column-vector convention (see the module docs).
    pub world: DMat4,
    pub inputs: LightInputs,
    /// `Some` where ShapingAPI is applied.
    pub shaping: Option<Shaping>,
    /// The up axis of the stage the light belongs to (Y for lights built in code).
    pub stage_up: UpAxis,
    /// `inputs:texture:*` where `texture:file` is authored (DomeLight, DomeLight_1, RectLight).
    pub texture: Option<Texture>,
    /// A dome's portals (DESIGN.md §8 P1): the visible PortalLights its `portals` relationship
    /// names, in relationship order. Empty for every other type, and for a dome that names
    /// none; what they change depends on the portal mode (P2, `prepare::PortalMode`).
    pub portals: Vec<Portal>,
}

impl Light {
    /// A light of `kind` at the origin with the schema fallbacks of its type (a DistantLight
    /// gets intensity 50000, every other type 1).
    pub fn new(kind: LightType) -> Self {
        let mut inputs = LightInputs::default();
        if matches!(kind, LightType::Distant { .. }) {
            inputs.intensity = schema::distant::INTENSITY;
        }
        Light {
            path: format!("<{}>", kind.usd_type()),
            kind,
            world: DMat4::IDENTITY,
            inputs,
            shaping: None,
            stage_up: UpAxis::Y,
            texture: None,
            portals: Vec::new(),
        }
    }

    pub fn distant(angle_deg: f64) -> Self {
        Self::new(LightType::Distant { angle: angle_deg })
    }
    pub fn sphere(radius: f64) -> Self {
        Self::new(LightType::Sphere {
            radius,
            treat_as_point: false,
        })
    }
    pub fn disk(radius: f64) -> Self {
        Self::new(LightType::Disk { radius })
    }
    pub fn rect(width: f64, height: f64) -> Self {
        Self::new(LightType::Rect { width, height })
    }
    pub fn cylinder(length: f64, radius: f64) -> Self {
        Self::new(LightType::Cylinder {
            length,
            radius,
            treat_as_line: false,
        })
    }
    pub fn dome() -> Self {
        Self::new(LightType::Dome)
    }
    /// A mesh light (DESIGN.md §7) of `geometry`'s world-space triangles, single-sided, untinted.
    pub fn mesh(geometry: MeshGeometry) -> Self {
        Self::new(LightType::Mesh {
            geometry: Arc::new(geometry),
            double_sided: false,
            tint: DVec3::ONE,
        })
    }

    pub fn with_path(mut self, path: impl Into<String>) -> Self {
        self.path = path.into();
        self
    }
    pub fn with_intensity(mut self, intensity: f64) -> Self {
        self.inputs.intensity = intensity;
        self
    }
    pub fn with_exposure(mut self, exposure: f64) -> Self {
        self.inputs.exposure = exposure;
        self
    }
    pub fn with_color(mut self, color: DVec3) -> Self {
        self.inputs.color = color;
        self
    }
    /// Enables `colorTemperature` at `kelvin`.
    pub fn with_temperature(mut self, kelvin: f64) -> Self {
        self.inputs.enable_color_temperature = true;
        self.inputs.color_temperature = kelvin;
        self
    }
    pub fn with_normalize(mut self, normalize: bool) -> Self {
        self.inputs.normalize = normalize;
        self
    }
    pub fn with_diffuse(mut self, diffuse: f64) -> Self {
        self.inputs.diffuse = diffuse;
        self
    }
    pub fn with_shaping(mut self, shaping: Shaping) -> Self {
        self.shaping = Some(shaping);
        self
    }
    /// Sets `inputs:texture:*` (a dome's environment map, a rect's image).
    pub fn with_texture(mut self, texture: Texture) -> Self {
        self.texture = Some(texture);
        self
    }
    /// Adds a portal to a dome (DESIGN.md §8 P1), after those it has: the order of a `portals`
    /// relationship, which decides between portals overlapping at the same depth.
    pub fn with_portal(mut self, portal: Portal) -> Self {
        self.portals.push(portal);
        self
    }
    /// Sets the stage's up axis (TILT of IES profiles, DomeLight_1 `poleAxis = scene`).
    pub fn with_stage_up(mut self, up: UpAxis) -> Self {
        self.stage_up = up;
        self
    }
    /// Sets the local-to-world transform (column-vector convention).
    pub fn with_transform(mut self, world: DMat4) -> Self {
        self.world = world;
        self
    }
    /// Sets the local-to-world transform from a USD row-vector matrix (`rows[3]` = translation).
    pub fn with_usd_matrix(mut self, rows: [[f64; 4]; 4]) -> Self {
        self.world = DMat4::from_cols_array_2d(&rows);
        self
    }
    /// The local-to-world transform as a USD row-vector matrix.
    pub fn usd_matrix(&self) -> [[f64; 4]; 4] {
        self.world.to_cols_array_2d()
    }

    /// Checks every input for values luxeval cannot evaluate and returns the first problem,
    /// naming the light and attribute. Called by every query before any work.
    pub fn validate(&self) -> Result<()> {
        let p = &self.path;
        let finite = |name: &str, v: f64| -> Result<()> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(LuxError::attr(p, name, v, "not a finite number"))
            }
        };
        let size = |name: &str, v: f64| -> Result<()> {
            finite(name, v)?;
            if v < 0.0 {
                Err(LuxError::attr(p, name, v, "a size must not be negative"))
            } else {
                Ok(())
            }
        };
        let i = &self.inputs;
        finite("inputs:intensity", i.intensity)?;
        finite("inputs:exposure", i.exposure)?;
        for c in i.color.to_array() {
            finite("inputs:color", c)?;
        }
        finite("inputs:colorTemperature", i.color_temperature)?;
        finite("inputs:diffuse", i.diffuse)?;
        finite("inputs:specular", i.specular)?;
        let scale = 2f64.powf(i.exposure);
        if !scale.is_finite() || (scale == 0.0 && i.intensity != 0.0) {
            return Err(LuxError::attr(
                p,
                "inputs:exposure",
                i.exposure,
                "2^exposure over- or underflows",
            ));
        }
        match self.kind {
            LightType::Distant { angle } => finite("inputs:angle", angle)?,
            LightType::Sphere { radius, .. } | LightType::Disk { radius } => {
                size("inputs:radius", radius)?
            }
            LightType::Rect { width, height } => {
                size("inputs:width", width)?;
                size("inputs:height", height)?;
            }
            LightType::Cylinder { length, radius, .. } => {
                size("inputs:length", length)?;
                size("inputs:radius", radius)?;
            }
            // A dome's portals are checked where they are evaluated (mask mode,
            // `prepare::portal`): hint mode ignores them, as if not named (DESIGN.md §8 P2).
            LightType::Dome => {}
            LightType::Mesh { tint, .. } => {
                for c in tint.to_array() {
                    finite("emissiveColor (the mesh light's tint)", c)?;
                }
            }
        }
        if let Some(s) = &self.shaping {
            finite("inputs:shaping:focus", s.focus)?;
            for c in s.focus_tint.to_array() {
                finite("inputs:shaping:focusTint", c)?;
            }
            finite("inputs:shaping:cone:angle", s.cone_angle)?;
            finite("inputs:shaping:cone:softness", s.cone_softness)?;
            if let Some(ies) = &s.ies {
                finite("inputs:shaping:ies:angleScale", ies.angle_scale)?;
            }
        }
        self.validate_transform()
    }

    fn validate_transform(&self) -> Result<()> {
        let m = self.usd_matrix();
        if m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(LuxError::InvalidTransform {
                light: self.path.clone(),
                reason: "has a non-finite entry".into(),
            });
        }
        let last_col = [m[0][3], m[1][3], m[2][3], m[3][3]];
        if last_col != [0.0, 0.0, 0.0, 1.0] {
            return Err(LuxError::InvalidTransform {
                light: self.path.clone(),
                reason: format!("is not affine (last column {last_col:?}, expected [0, 0, 0, 1])"),
            });
        }
        // A singular map flattens an area light to zero size, which DESIGN.md §2 "Zero-size
        // lights" evaluates (prepare::zero_size) instead of refusing; the other types need their
        // frame.
        // A mesh light's triangles are already in world space, so a singular transform only
        // loses shaping's primary axis (its local −Z).
        let sized = match self.kind {
            LightType::Distant { .. } | LightType::Dome => false,
            LightType::Mesh { .. } => self.shaping.is_none(),
            _ => true,
        };
        if !sized && self.is_singular() {
            let det = self.linear().determinant();
            return Err(LuxError::InvalidTransform {
                light: self.path.clone(),
                reason: format!("is singular (determinant {det:e})"),
            });
        }
        Ok(())
    }

    /// Whether the world transform's linear part is singular: `|det| ≤ 1e-12 ·` the product
    /// of its column lengths (docs/INPUTS.md), or a column is zero.
    pub fn is_singular(&self) -> bool {
        let a = self.linear();
        let det = a.determinant();
        let scale = a.x_axis.length() * a.y_axis.length() * a.z_axis.length();
        !(det.abs() > 1e-12 * scale) || scale == 0.0
    }

    /// The linear part of the world transform (columns: images of local X, Y, Z).
    pub fn linear(&self) -> DMat3 {
        DMat3::from_mat4(self.world)
    }

    /// The world-space origin of the light.
    pub fn origin(&self) -> DVec3 {
        self.world.w_axis.truncate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usd_rows_round_trip_and_translation() {
        let rows = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 2.0, 0.0, 0.0],
            [0.5, 0.0, 3.0, 0.0],
            [4.0, 5.0, 6.0, 1.0],
        ];
        let l = Light::sphere(1.0).with_usd_matrix(rows);
        assert_eq!(l.usd_matrix(), rows);
        assert_eq!(l.origin(), DVec3::new(4.0, 5.0, 6.0));
        // Row-vector: local Z (0,0,1) maps to row 2 = (0.5, 0, 3).
        assert_eq!(
            l.world.transform_vector3(DVec3::Z),
            DVec3::new(0.5, 0.0, 3.0)
        );
    }

    #[test]
    fn distant_gets_its_own_intensity_fallback() {
        assert_eq!(Light::distant(0.53).inputs.intensity, 50000.0);
        assert_eq!(Light::rect(1.0, 1.0).inputs.intensity, 1.0);
    }

    #[test]
    fn validation_names_light_and_attribute() {
        let e = Light::sphere(f64::NAN)
            .with_path("/lights/key")
            .validate()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/lights/key") && e.contains("inputs:radius"),
            "{e}"
        );
        let e = Light::rect(1.0, -2.0).validate().unwrap_err().to_string();
        assert!(e.contains("inputs:height"), "{e}");
        // A singular transform leaves a distant light without a direction: refused.
        let e = Light::distant(0.5)
            .with_transform(DMat4::from_scale(DVec3::new(1.0, 1.0, 0.0)))
            .validate()
            .unwrap_err()
            .to_string();
        assert!(e.contains("singular"), "{e}");
        // A disk scaled flat is a zero-size light (DESIGN.md §2), evaluated by prepare.
        let flat = Light::disk(1.0).with_transform(DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0)));
        assert!(flat.validate().is_ok() && flat.is_singular());
    }
}
