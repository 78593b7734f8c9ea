//! Everything computed once per light in f64 and consumed by both backends (DESIGN.md §1): the
//! validated light, its base radiance (LightAPI multipliers, colour temperature, normalize's
//! sizeFactor), its frame (origin, linear map and inverse, primary axis, emitting normal), the
//! ShapingAPI constants in radians and the kinks of the shaping factor. The CPU reference
//! evaluates these in f64; the GPU packer rounds them once into its record. Nothing here
//! depends on either backend.

pub mod alias;
pub mod assets;
pub mod blackbody;
pub mod env_table;
mod fits_f32;
pub mod gpu_path;
pub mod ies;
pub mod ies_kinks;
pub mod latlong_rows;
pub mod mesh_bvh;
pub mod mesh_class;
pub mod normalize;
pub mod portal;
pub mod profile;
mod shaping;
pub mod texture;
mod transform;
pub mod zero_size;

use std::sync::Arc;

use glam::{DMat3, DVec3};

use crate::error::{AssetError, LuxError, Result};
use crate::model::{Light, LightType, Texture};
use assets::AssetCache;
pub use blackbody::TemperatureMode;
use blackbody::temperature_rgb;
use fits_f32::check_fits_f32;
pub use gpu_path::{GpuPath, MESH_STACK, MESH_TRIANGLES_SUMMED};
pub use mesh_class::MeshOcclusion;
pub use portal::{PortalMode, PreparedPortal};
pub use profile::{Kink, Profile};
pub use shaping::{ShapingConsts, shaping_is_identity};
pub use transform::{is_sheared, similarity_scale, tilt_angle};

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

impl PreparedIes {
    /// The profile's kinks as the GPU quadrature streams them ([`ies_kinks::KinkFamilies`]);
    /// None where the kernel cannot split at them: angleScale (but ±1, which maps θ to itself)
    /// on type B bends the grid lines into surfaces that are neither cones nor planes (the reference's adaptive rules
    /// take them, the f32 rule would miss them), so that light's irradiance is the host's.
    pub fn device_families(&self) -> Option<ies_kinks::KinkFamilies> {
        if ies_kinks::bent(self.profile.kind, self.angle_scale) {
            None
        } else {
            self.kinks.families()
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
    /// The IES profile of ShapingAPI, where authored (and the light shapeable).
    pub ies: Option<PreparedIes>,
    /// What only this kind of light carries.
    pub kind: KindData,
    /// Which of this light's queries the GPU path takes from the device and which from the CPU
    /// reference, decided once here (see [`GpuPath`]); a GPU scene only moves the irradiance
    /// of the latlong domes whose row tables its device has no room for to the reference
    /// (`gpu::texture_atlas::tables_beyond`).
    pub gpu_path: GpuPath,
    /// The files on disk its assets were read from (IES profile, TILT file, texture, or the
    /// package holding them), so that no output is written over one of them.
    pub files_read: Vec<std::path::PathBuf>,
    /// How the light is evaluated other than as authored, naming the prim (a zero-size light,
    /// [`zero_size`]).
    pub warning: Option<String>,
    /// A dome masked by its portals (DESIGN.md §8 P2, [`PortalMode::Mask`]): the portals light
    /// reaches a point through (possibly none that pass light: then the dome lights nothing). On
    /// the device they are in the mesh atlas (`gpu::mesh_atlas`, shaders/portal.wgsl).
    /// `None`: not masked (hint mode, another type, a dome naming no visible portal).
    pub portals: Option<Vec<PreparedPortal>>,
    /// Where a masked dome's irradiance is the device's: the sets of its portals one ray may
    /// cross together ([`portal::overlaps`]), the inclusion–exclusion terms the kernel sums
    /// beyond the portals' own (shaders/irradiance/portals.wgsl). Empty otherwise.
    pub portal_overlaps: Vec<portal::Overlap>,
}

/// What one kind of light carries beyond the shared frame, base radiance and shaping of
/// [`Prepared`] (pbrt-v4 gives each light its class; here each kind its variant). The shape's
/// own sizes stay in the model's [`LightType`].
#[derive(Clone, Debug)]
pub enum KindData {
    /// Sphere, disk and cylinder lights: nothing beyond their size and frame.
    Shape,
    /// A RectLight, with its image where `texture:file` is authored (DESIGN.md §6 "RectLight
    /// texture").
    Rect {
        texture: Option<texture::RectTexture>,
    },
    /// A DistantLight: θmax, half its angular diameter in radians (0: a delta light).
    Distant { half_angle: f64 },
    /// A DomeLight, with its environment map where `texture:file` is authored (DESIGN.md §6
    /// D1–D6).
    Dome {
        texture: Option<texture::PreparedTexture>,
    },
    /// A mesh light (DESIGN.md §7): the hierarchy over its triangles (the model's, in world
    /// space) and the distinct directions its emitting sides face, which decide where it emits
    /// at all (M3 `emission`).
    Mesh {
        bvh: std::sync::Arc<mesh_bvh::MeshBvh>,
        fronts: std::sync::Arc<Vec<DVec3>>,
        /// The running sum of the triangles' areas, in order (the last is the mesh's area):
        /// the table a point is drawn by area from (DESIGN.md §9 S2 "by their geometry").
        cumulative_area: std::sync::Arc<Vec<f64>>,
        /// The farthest vertex's distance from the prim's origin ([`Prepared::bound_radius`]),
        /// computed once: the light choice reads it per receiver.
        bound_radius: f64,
        /// Whether its triangles can hide one another ([`mesh_class`]): where they cannot,
        /// its unshaped irradiance is the triangles' Lambert sum, on the CPU reference
        /// (`cpu::mesh::lambert`) and on the device ([`GpuPath::HostIntensityOnly`]).
        occlusion: MeshOcclusion,
    },
}

impl Prepared {
    /// A distant light's θmax (half its angular diameter, radians); 0 for other types.
    pub fn distant_half_angle(&self) -> f64 {
        match self.kind {
            KindData::Distant { half_angle } => half_angle,
            _ => 0.0,
        }
    }

    /// The radius of a sphere about the light's origin holding its world shape (0 for a dome
    /// or distant light): `Σ |half extent_i| |M e_i|` bounds `|M v|` over the local shape's box.
    /// The receiver-aware light choice of sampling bounds a light by it (DESIGN.md §9 S1).
    pub fn bound_radius(&self) -> f64 {
        let ext = match self.light.kind {
            LightType::Rect { width, height } => DVec3::new(width / 2.0, height / 2.0, 0.0),
            LightType::Disk { radius } => DVec3::new(radius, radius, 0.0),
            LightType::Sphere { radius, .. } => DVec3::splat(radius),
            LightType::Cylinder { length, radius, .. } => DVec3::new(length / 2.0, radius, radius),
            LightType::Dome | LightType::Distant { .. } => DVec3::ZERO,
            // World-space triangles: the farthest vertex from the origin, found when prepared.
            LightType::Mesh { .. } => {
                return match self.kind {
                    KindData::Mesh { bound_radius, .. } => bound_radius,
                    _ => 0.0,
                };
            }
        };
        ext.x * self.linear.x_axis.length()
            + ext.y * self.linear.y_axis.length()
            + ext.z * self.linear.z_axis.length()
    }

    /// A dome's environment map, where authored.
    pub fn dome_texture(&self) -> Option<&texture::PreparedTexture> {
        match &self.kind {
            KindData::Dome { texture } => texture.as_ref(),
            _ => None,
        }
    }

    /// A RectLight's image, where authored.
    pub fn rect_texture(&self) -> Option<&texture::RectTexture> {
        match &self.kind {
            KindData::Rect { texture } => texture.as_ref(),
            _ => None,
        }
    }

    /// Whether this light's irradiance depends on the receiver's normal alone, not its
    /// position: distant lights and domes, but not a dome masked by portals (what a receiver
    /// sees through them depends on where it is). The irradiance kernel's
    /// `LIGHTS_NORMAL_ONLY` pass integrates these lights (the record's `FLAG_NORMAL_ONLY` is
    /// set from this).
    pub fn irradiance_is_normal_only(&self) -> bool {
        match self.light.kind {
            LightType::Distant { .. } => true,
            LightType::Dome => self.portals.is_none(),
            _ => false,
        }
    }

    /// Whether the GPU path takes this light's irradiance from the CPU reference
    /// ([`Prepared::gpu_path`]).
    pub fn irradiance_on_host(&self) -> bool {
        !matches!(
            self.gpu_path,
            GpuPath::Device | GpuPath::HostIntensityOnly(_)
        )
    }

    /// Whether the GPU path takes this light's intensity from the CPU reference
    /// ([`Prepared::gpu_path`]): some query besides irradiance is the host's (a light whose
    /// emission is the host's has its intensity there too). Sampling reads it: a scene holding
    /// such a light is sampled on the CPU reference.
    pub fn on_host(&self) -> bool {
        matches!(
            self.gpu_path,
            GpuPath::HostIntensity(_)
                | GpuPath::HostIntensityOnly(_)
                | GpuPath::RadianceOnDevice(_)
                | GpuPath::Host(_)
        )
    }

    /// Whether the GPU path takes this light's emission from the CPU reference.
    pub fn emission_on_host(&self) -> bool {
        matches!(
            self.gpu_path,
            GpuPath::RadianceOnDevice(_) | GpuPath::Host(_)
        )
    }

    /// Whether the GPU path takes this light's radiance from the CPU reference.
    pub fn radiance_on_host(&self) -> bool {
        matches!(self.gpu_path, GpuPath::Host(_))
    }

    /// Reads the dome's portals as `mode` says (DESIGN.md §8 P2): in mask mode a dome naming
    /// portals is masked; on a GPU evaluator its emission and radiance are the device's (the
    /// radiance kernel tests the portal crossings), and so is its irradiance where the dome is
    /// untextured or latlong under a conformal frame and its overlaps fit the kernel
    /// ([`portal::overlaps`]: an inclusion–exclusion sum of Lambert's formula or the texture's
    /// integral over the portals and their overlaps, shaders/irradiance/portals.wgsl); else its
    /// irradiance is the CPU reference's ([`GpuPath::HostIrradiance`]). Hint mode changes
    /// nothing.
    pub fn apply_portal_mode(
        &mut self,
        mode: PortalMode,
        temperature: TemperatureMode,
    ) -> Result<()> {
        self.portals = portal::prepare_portals(&self.light, mode, temperature)?;
        if let Some(portals) = &self.portals {
            (self.gpu_path, self.portal_overlaps) = gpu_path::masked(portals, self.dome_texture());
        }
        Ok(())
    }

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
        // DESIGN.md §2 "Zero-size lights": evaluated in their place, never refused.
        let substituted = zero_size::substitute(light);
        let (light, warning) = match &substituted {
            Some((substitute, warning)) => (substitute, Some(warning.clone())),
            None => (light, None),
        };
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
        check_fits_f32(light, base, size_factor, mode)?;
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
        let ies = match evaluated.shaping.as_ref().and_then(|s| s.ies.as_ref()) {
            Some(i) if evaluated.kind.is_shapeable() => {
                let profile = cache.ies(&i.file).map_err(|source| {
                    LuxError::asset(
                        &light.path,
                        "inputs:shaping:ies:file",
                        &i.file.authored,
                        source,
                    )
                })?;
                // The one refusal of a profile both paths cannot evaluate alike (the GPU holds
                // candela values in float32 and looks grids up with a bounded search).
                if let Err(reason) = ies::check_evaluable(&profile) {
                    return Err(LuxError::attr(
                        &light.path,
                        "inputs:shaping:ies:file",
                        format!("@{}@", i.file.authored),
                        reason,
                    ));
                }
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
        let kind = match evaluated.kind {
            LightType::Distant { angle } => KindData::Distant {
                half_angle: normalize::distant_half_angle(angle),
            },
            LightType::Rect { .. } => KindData::Rect {
                texture: match &light.texture {
                    Some(t) => Some(prepare_rect_texture(light, t, cache)?),
                    None => None,
                },
            },
            LightType::Dome => KindData::Dome {
                texture: match &light.texture {
                    Some(t) => Some(prepare_texture(light, t, linear, cache)?),
                    None => None,
                },
            },
            LightType::Mesh {
                ref geometry,
                double_sided,
                ..
            } => KindData::Mesh {
                occlusion: mesh_class::classify(
                    &geometry.triangles,
                    double_sided,
                    MESH_TRIANGLES_SUMMED,
                ),
                bvh: std::sync::Arc::new(mesh_bvh::MeshBvh::build(&geometry.triangles)),
                fronts: std::sync::Arc::new(distinct_fronts(&geometry.triangles)),
                cumulative_area: std::sync::Arc::new(
                    geometry
                        .triangles
                        .iter()
                        .scan(0.0, |sum, t| {
                            *sum += t.area();
                            Some(*sum)
                        })
                        .collect(),
                ),
                bound_radius: geometry
                    .triangles
                    .iter()
                    .flat_map(|t| t.p)
                    .map(|v| v.distance(light.origin()))
                    .fold(0.0, f64::max),
            },
            _ => {
                // A texture on any other type is refused rather than evaluated as if untextured.
                if let Some(t) = &light.texture {
                    return Err(LuxError::attr(
                        &light.path,
                        "inputs:texture:file",
                        &t.file.authored,
                        format!(
                            "{} textures are not evaluated (only DomeLight and RectLight textures are)",
                            light.kind.usd_type()
                        ),
                    ));
                }
                KindData::Shape
            }
        };
        let gpu_path = gpu_path::decide(&kind, shaping.is_some(), ies.as_ref(), &to_local);
        // The files the assets above were loaded from (the profile's, the texture's).
        let files_read = [
            evaluated
                .shaping
                .as_ref()
                .and_then(|s| s.ies.as_ref())
                .filter(|_| ies.is_some())
                .map(|i| &i.file),
            light.texture.as_ref().map(|t| &t.file),
        ]
        .into_iter()
        .flatten()
        .flat_map(|a| cache.files(a))
        .collect();
        Ok(Prepared {
            portals: None,
            portal_overlaps: Vec::new(),
            warning,
            files_read,
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
            ies,
            kind,
            gpu_path,
            light: evaluated,
        })
    }
}

/// Loads a dome's texture (once per file, through `cache`) and resolves its format and frame
/// (DESIGN.md §6 D1–D6). A RectLight's is [`prepare_rect_texture`].
fn prepare_texture(
    light: &Light,
    t: &Texture,
    linear: DMat3,
    cache: &mut AssetCache,
) -> Result<texture::PreparedTexture> {
    let asset_err = |attr: &str, source: AssetError| {
        LuxError::asset(&light.path, attr, &t.file.authored, source)
    };
    let image = cache
        .texture(&t.file)
        .map_err(|e| asset_err("inputs:texture:file", e))?;
    let format = texture::resolve_format(t.format, &image)
        .map_err(|e| asset_err("inputs:texture:format", e.into()))?;
    let frame = texture::DomeFrame::new(linear, texture::pole_offset(t.pole_axis, light.stage_up))
        .ok_or_else(|| LuxError::InvalidTransform {
            light: light.path.clone(),
            reason: "is singular, so the dome has no direction".into(),
        })?;
    Ok(texture::PreparedTexture {
        image,
        format,
        frame,
        filter: t.filter,
        irradiance: Default::default(),
    })
}

/// Loads a RectLight's texture (once per file, through `cache`) with its filter and its exact
/// area mean (DESIGN.md §6 "RectLight texture").
fn prepare_rect_texture(
    light: &Light,
    t: &Texture,
    cache: &mut AssetCache,
) -> Result<texture::RectTexture> {
    let image = cache.texture(&t.file).map_err(|source| {
        LuxError::asset(&light.path, "inputs:texture:file", &t.file.authored, source)
    })?;
    Ok(texture::RectTexture::new(image, t.filter))
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
    // A mesh light's material tint multiplies like color (DESIGN.md §7 M2).
    let material = match light.kind {
        LightType::Mesh { tint, .. } => tint,
        _ => DVec3::ONE,
    };
    scalar * i.color * tint * material
}

/// The distinct unit directions the triangles' fronts face (exact duplicates removed), the
/// largest-area direction first: emission along ω is non-zero where one of them has `n·ω > 0`
/// (DESIGN.md §7 M3), and a flat or boxy light answers after one or a few tests.
fn distinct_fronts(triangles: &[crate::model::MeshTriangle]) -> Vec<DVec3> {
    let mut by_area: std::collections::HashMap<[u64; 3], f64> = Default::default();
    for t in triangles {
        let n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
        let Some(u) = n.try_normalize() else { continue };
        *by_area.entry(u.to_array().map(f64::to_bits)).or_default() += n.length();
    }
    let mut fronts: Vec<([u64; 3], f64)> = by_area.into_iter().collect();
    fronts.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    fronts
        .into_iter()
        .map(|(k, _)| DVec3::from_array(k.map(f64::from_bits)))
        .collect()
}

/// Prepares every light, failing on the first invalid one; a file referenced by several lights
/// is loaded once.
pub fn prepare(
    lights: &[Light],
    mode: TemperatureMode,
    portal_mode: PortalMode,
) -> Result<Vec<Prepared>> {
    let mut cache = AssetCache::default();
    lights
        .iter()
        .map(|l| {
            let mut p = Prepared::with_assets(l, mode, &mut cache)?;
            p.apply_portal_mode(portal_mode, mode)?;
            Ok(p)
        })
        .collect()
}
