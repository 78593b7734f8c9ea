//! Packing prepared lights into GPU records. Twin of the `Record` struct in
//! `shaders/shared/record.wgsl`; `tests/wgsl.rs` checks this layout against naga's layouter.
//!
//! Every value comes from `prepare` (computed once per light in f64) and is rounded once here.

use bytemuck::{Pod, Zeroable};

use super::shaders::Features;
use crate::model::LightType;
use crate::prepare::{Kink, Prepared};

/// Record kinds; the WGSL prelude declares the same names from [`WGSL_CONSTANTS`].
pub const KIND_DISTANT: u32 = 0;
pub const KIND_SPHERE: u32 = 1;
pub const KIND_DISK: u32 = 2;
pub const KIND_RECT: u32 = 3;
pub const KIND_CYLINDER: u32 = 4;
pub const KIND_DOME: u32 = 5;
/// A mesh light (DESIGN.md §7): its BVH and triangles in the scene's mesh atlas
/// (`super::mesh_atlas`), located by `tex`.
pub const KIND_MESH: u32 = 6;

/// ShapingAPI is applied.
pub const FLAG_SHAPING: u32 = 1;
/// `treatAsPoint` (sphere) or `treatAsLine` (cylinder) is set.
pub const FLAG_TREAT_AS_POINT_OR_LINE: u32 = 2;
/// The linear map is a similarity (a sphere stays a sphere: the irradiance cap applies).
pub const FLAG_SIMILARITY: u32 = 4;
/// Irradiance kink cones (`irr.z`, `irr.w` hold their cos θ): the shaping's cone edge and
/// smoothstep start, as `prepare::Profile` lists them.
pub const FLAG_KINK_A: u32 = 8;
pub const FLAG_KINK_B: u32 = 16;
/// The plane ⊥ the axis (θ = 90°) is a kink of the shaping.
pub const FLAG_FOCUS_PLANE: u32 = 32;
/// ... and |cos θ|^focus is not smooth there (the quadrature grades toward it).
pub const FLAG_FOCUS_GRADED: u32 = 64;
/// ShapingAPI makes the light dark everywhere (cone angle ≤ 0).
pub const FLAG_DARK: u32 = 128;
/// The shaping is not smooth at the axis directions (`prepare::Profile::axis_singular`).
pub const FLAG_AXIS_SINGULAR: u32 = 256;
/// ShapingAPI carries an IES profile (`ies`: atlas base, angleScale, scale).
pub const FLAG_IES: u32 = 512;
/// A dome with a texture (`tex_inv`, `tex`: the dome frame and the atlas offset, see
/// `gpu::texture_atlas` and `shaders/shared/texture.wgsl`).
pub const FLAG_DOME_TEXTURE: u32 = 1024;
/// A rect with a texture (`tex`: the atlas offset and filter; `tex_inv[0]`: the texture's mean
/// colour, DESIGN.md §6 "RectLight texture"; see `shaders/shared/texture.wgsl`).
pub const FLAG_RECT_TEXTURE: u32 = 2048;
/// The irradiance kernel gives 0: the host adds the CPU reference's value
/// (`prepare::Prepared::irradiance_on_host`).
pub const FLAG_HOST_IRRADIANCE: u32 = 4096;
/// A rect whose world shape is a parallelogram, not a rectangle: the sampler takes Arvo's two
/// spherical triangles (`prepare::is_sheared`, the test
/// `cpu::sample::rect::RectSampler::new` takes, in f64).
pub const FLAG_SHEARED_RECT: u32 = 8192;
/// A mesh light whose triangles emit from both sides (`doubleSided`, DESIGN.md §7 M2).
pub const FLAG_DOUBLE_SIDED: u32 = 16384;
/// A mesh light whose front directions are in the mesh atlas at `tex.w`: its emission is the
/// device's (`GpuPath::HostIntensity`, `super::mesh_atlas`).
pub const FLAG_MESH_FRONTS: u32 = 32768;
/// A dome masked by portals, which are in the mesh atlas at `tex.w` (DESIGN.md §8 P2 mask
/// mode; `super::mesh_atlas`, shaders/portal.wgsl).
pub const FLAG_PORTALS: u32 = 65536;
/// The light's irradiance depends on the receiver's normal alone
/// (`prepare::Prepared::irradiance_is_normal_only`): the irradiance kernel's
/// [`LIGHTS_NORMAL_ONLY`] pass integrates it, [`LIGHTS_POSITIONAL`] skips it.
pub const FLAG_NORMAL_ONLY: u32 = 131072;

/// Threads per workgroup of every kernel.
pub const WORKGROUP_SIZE: u32 = 64;

/// The record constants the WGSL prelude declares, by name.
pub const WGSL_CONSTANTS: &[(&str, u32)] = &[
    ("KIND_DISTANT", KIND_DISTANT),
    ("KIND_SPHERE", KIND_SPHERE),
    ("KIND_DISK", KIND_DISK),
    ("KIND_RECT", KIND_RECT),
    ("KIND_CYLINDER", KIND_CYLINDER),
    ("KIND_DOME", KIND_DOME),
    ("KIND_MESH", KIND_MESH),
    ("FLAG_SHAPING", FLAG_SHAPING),
    ("FLAG_TREAT_AS_POINT_OR_LINE", FLAG_TREAT_AS_POINT_OR_LINE),
    ("FLAG_SIMILARITY", FLAG_SIMILARITY),
    ("FLAG_KINK_A", FLAG_KINK_A),
    ("FLAG_KINK_B", FLAG_KINK_B),
    ("FLAG_FOCUS_PLANE", FLAG_FOCUS_PLANE),
    ("FLAG_FOCUS_GRADED", FLAG_FOCUS_GRADED),
    ("FLAG_DARK", FLAG_DARK),
    ("FLAG_AXIS_SINGULAR", FLAG_AXIS_SINGULAR),
    ("FLAG_IES", FLAG_IES),
    ("FLAG_DOME_TEXTURE", FLAG_DOME_TEXTURE),
    ("FLAG_RECT_TEXTURE", FLAG_RECT_TEXTURE),
    ("FLAG_HOST_IRRADIANCE", FLAG_HOST_IRRADIANCE),
    ("FLAG_SHEARED_RECT", FLAG_SHEARED_RECT),
    ("FLAG_DOUBLE_SIDED", FLAG_DOUBLE_SIDED),
    ("FLAG_MESH_FRONTS", FLAG_MESH_FRONTS),
    ("FLAG_PORTALS", FLAG_PORTALS),
    ("FLAG_NORMAL_ONLY", FLAG_NORMAL_ONLY),
    ("WORKGROUP_SIZE", WORKGROUP_SIZE),
    ("LIGHTS_ALL", LIGHTS_ALL),
    ("LIGHTS_NORMAL_ONLY", LIGHTS_NORMAL_ONLY),
    ("LIGHTS_POSITIONAL", LIGHTS_POSITIONAL),
    ("LIGHTS_SKIP_TEXTURED_RECTS", LIGHTS_SKIP_TEXTURED_RECTS),
    ("SELECT_POWER", SELECT_POWER),
    ("SELECT_BOUND", SELECT_BOUND),
    ("SELECT_HAS_NORMALS", SELECT_HAS_NORMALS),
];

/// One light as the kernels read it (see `shaders/shared/record.wgsl` for each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Record {
    pub to_local: [[f32; 4]; 3],
    pub axis: [f32; 4],
    pub normal: [f32; 4],
    pub base: [f32; 4],
    pub focus_tint: [f32; 4],
    pub cone: [f32; 4],
    pub size: [f32; 4],
    /// Columns of the local-to-world linear map M (images of local X, Y, Z); w: the world origin.
    pub world: [[f32; 4]; 3],
    /// Irradiance: (diffuse, |det M|, cos θ of kink A, cos θ of kink B).
    pub irr: [f32; 4],
    /// IES (FLAG_IES): (atlas base of the profile, exact in f32; angleScale; normalisation or
    /// tilt scale; base of its kinks block, `super::ies_atlas`).
    pub ies: [f32; 4],
    /// Textured dome (FLAG_DOME_TEXTURE): columns of `A_eff⁻¹` (world → dome, §6 D1); w: 0.
    /// Textured rect (FLAG_RECT_TEXTURE): `tex_inv[0]` is the texture's mean colour.
    pub tex_inv: [[f32; 4]; 3],
    /// Textured dome or rect: (atlas offset of the texture's header, filter code, 0, 0); in the
    /// sample and pdf kernels' copy a textured dome's `tex[2]` is its sampling table's offset
    /// (0: none; `gpu::sample::SampleLights`). A masked dome (FLAG_PORTALS): `tex[3]` is its
    /// portals' offset in the mesh atlas. A mesh light: its words in the mesh atlas
    /// (`gpu::mesh_atlas`).
    pub tex: [u32; 4],
    pub kind: u32,
    pub flags: u32,
    pub pad: [u32; 2],
    /// The light choice of GPU-resident sampling (`shaders/sample/select.wgsl`): (power weight,
    /// the luminance weight of `base`, the world bounding-sphere radius, 0), each weight divided
    /// by the scene's largest (`cpu::sample::select` has the f64 weights; `query::scene` fills
    /// the luminance weight, and the power weight only in the sampling records of a
    /// `Selection::Power` call, `gpu::sample::SampleLights::with_power`).
    pub select: [f32; 4],
}

impl Record {
    /// The optional parts of the kernels this light needs (gpu::shaders::Features): IES and
    /// TEXTURE from its flags; CHART and LINE by the switch of shaders/irradiance.wgsl, case by
    /// case (a rect or disk takes the chart at some receivers and a closed form at others: it
    /// counts as needing the chart). A light the host integrates needs neither.
    pub fn features(&self) -> Features {
        let has = |f: u32| self.flags & f != 0;
        let (chart, line) = if has(FLAG_HOST_IRRADIANCE) {
            (false, false)
        } else {
            match self.kind {
                KIND_SPHERE => (
                    !has(FLAG_TREAT_AS_POINT_OR_LINE)
                        && (has(FLAG_SHAPING) || !has(FLAG_SIMILARITY)),
                    false,
                ),
                KIND_RECT | KIND_DISK => (true, false),
                KIND_CYLINDER => (
                    !has(FLAG_TREAT_AS_POINT_OR_LINE),
                    has(FLAG_TREAT_AS_POINT_OR_LINE),
                ),
                _ => (false, false),
            }
        };
        Features {
            ies: has(FLAG_IES),
            texture: has(FLAG_DOME_TEXTURE | FLAG_RECT_TEXTURE),
            chart,
            line,
        }
    }
}

/// The kernel-side parameters of one dispatch (`Params` in `shaders/shared/record.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub count: u32,
    pub light_first: u32,
    pub light_end: u32,
    pub per_light: u32,
    pub row_stride: u32,
    pub accumulate: u32,
    /// Invocations per sample (1, or on llvmpipe more for an irradiance call with a light whose
    /// quadrature is long: `GpuContext::lane_stride`); the others return at once.
    pub lane_stride: u32,
    /// Which lights the irradiance kernel integrates ([`LIGHTS_ALL`], [`LIGHTS_NORMAL_ONLY`],
    /// [`LIGHTS_POSITIONAL`]); the others give 0. 0 for every other kernel.
    pub light_filter: u32,
    /// GPU-resident sampling (`sample_resident_main`): the generator's seed, samples per point,
    /// the first point's key (DESIGN.md §9 S3) and the light choice ([`SELECT_POWER`] or
    /// [`SELECT_BOUND`], plus [`SELECT_HAS_NORMALS`]). 0 for every other kernel.
    pub seed: u32,
    pub per_point: u32,
    pub first_point: u32,
    pub select: u32,
}

/// `Params::light_filter`: every light.
pub const LIGHTS_ALL: u32 = 0;
/// `Params::light_filter`: only the lights whose irradiance depends on the receiver's normal
/// alone (distant lights and domes: `Prepared::irradiance_is_normal_only`), for a pass over
/// the distinct normals of the receivers (`query::scene`).
pub const LIGHTS_NORMAL_ONLY: u32 = 1;
/// `Params::light_filter`: every light but those of [`LIGHTS_NORMAL_ONLY`].
pub const LIGHTS_POSITIONAL: u32 = 2;
/// `Params::light_filter`, a bit beside one of the values above: skip the textured rects
/// without an IES profile (FLAG_RECT_TEXTURE without FLAG_IES: those `cpu::irradiance::rect_fast`
/// takes), whose irradiance a host-path call at a tolerance of 1e-4 or looser takes from the
/// CPU's moment path instead (`query::scene` `host_takes`).
pub const LIGHTS_SKIP_TEXTURED_RECTS: u32 = 4;

/// `Params::select`: choose lights by power.
pub const SELECT_POWER: u32 = 0;
/// `Params::select`: choose lights by the receiver-aware bound.
pub const SELECT_BOUND: u32 = 1;
/// `Params::select`: the normals buffer holds a normal per point.
pub const SELECT_HAS_NORMALS: u32 = 16;

fn v4(v: glam::DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

/// Rounds a prepared light's f64 constants to its GPU record; `ies_base` is where its IES
/// profile starts in the scene's atlas (`gpu::ies_atlas`), `tex_offset` where its texture (and
/// a dome's row tables) start in the scene's texture atlas (`gpu::texture_atlas`), `atlas` its `tex` words in the
/// scene's mesh atlas (`gpu::mesh_atlas`: a mesh light's, a masked dome's).
pub fn pack(
    p: &Prepared,
    ies_base: Option<super::ies_atlas::IesBases>,
    tex_offset: Option<super::texture_atlas::LightTex>,
    atlas: Option<[u32; 4]>,
) -> Record {
    if p.radiance_on_host() {
        return host_record();
    }
    let m = p.to_local;
    // Local = M⁻¹·(x − o): row i is (row_i(M⁻¹), −row_i(M⁻¹)·o).
    let row = |i: usize| v4(m.row(i), -m.row(i).dot(p.origin));
    let lin = p.linear;
    let mut r = Record {
        to_local: [row(0), row(1), row(2)],
        axis: v4(p.axis, 0.0),
        normal: v4(p.normal, 0.0),
        base: v4(p.base, 0.0),
        world: [
            v4(lin.x_axis, p.origin.x),
            v4(lin.y_axis, p.origin.y),
            v4(lin.z_axis, p.origin.z),
        ],
        irr: [p.light.inputs.diffuse as f32, p.det as f32, 0.0, 0.0],
        select: [0.0, 0.0, p.bound_radius() as f32, 0.0],
        ..Record::default()
    };
    if p.similarity.is_some() {
        r.flags |= FLAG_SIMILARITY;
    }
    // The shaping's kinks exactly as the CPU quadrature lists them.
    let profile = &p.profile;
    if profile.dark {
        r.flags |= FLAG_DARK;
    }
    if profile.axis_singular {
        r.flags |= FLAG_AXIS_SINGULAR;
    }
    let mut cones = 0;
    for k in &profile.kinks {
        match *k {
            Kink::Cone { cos } => {
                r.irr[2 + cones] = cos as f32;
                r.flags |= if cones == 0 { FLAG_KINK_A } else { FLAG_KINK_B };
                cones += 1;
            }
            Kink::Plane { graded, .. } => {
                r.flags |= FLAG_FOCUS_PLANE;
                if graded {
                    r.flags |= FLAG_FOCUS_GRADED;
                }
            }
        }
    }
    if let Some(s) = &p.shaping {
        r.flags |= FLAG_SHAPING;
        r.focus_tint = v4(s.focus_tint, s.focus);
        r.cone = [s.cone as f32, s.start as f32, 0.0, 0.0];
    }
    if let (Some(ies), Some(base)) = (&p.ies, ies_base) {
        r.flags |= FLAG_IES;
        r.ies = [
            base.profile as f32,
            ies.angle_scale as f32,
            ies.scale as f32,
            base.kinks as f32,
        ];
    }
    if let (Some(t), Some(at)) = (p.dome_texture(), tex_offset) {
        r.flags |= FLAG_DOME_TEXTURE;
        let inv = t.frame.inv;
        r.tex_inv = [
            v4(inv.x_axis, 0.0),
            v4(inv.y_axis, 0.0),
            v4(inv.z_axis, 0.0),
        ];
        // The row tables of a dome whose irradiance the kernel integrates
        // (irradiance/latlong_rows.wgsl).
        r.tex = [at.texture, t.filter.code(), at.rows.unwrap_or(0), 0];
    }
    if let (Some(t), Some(at)) = (p.rect_texture(), tex_offset) {
        r.flags |= FLAG_RECT_TEXTURE;
        r.tex_inv[0] = v4(t.mean(), 0.0);
        r.tex = [at.texture, t.filter().code(), 0, 0];
    }
    if p.irradiance_on_host() {
        r.flags |= FLAG_HOST_IRRADIANCE;
    }
    if p.irradiance_is_normal_only() {
        r.flags |= FLAG_NORMAL_ONLY;
    }
    let (kind, size) = match p.light.kind {
        LightType::Distant { .. } => {
            r.axis[3] = p.distant_half_angle() as f32;
            (KIND_DISTANT, [0.0; 4])
        }
        LightType::Sphere {
            radius,
            treat_as_point,
        } => {
            if treat_as_point {
                r.flags |= FLAG_TREAT_AS_POINT_OR_LINE;
            }
            (KIND_SPHERE, [radius as f32, 0.0, 0.0, 0.0])
        }
        LightType::Disk { radius } => (KIND_DISK, [radius as f32, 0.0, 0.0, 0.0]),
        LightType::Rect { width, height } => {
            if crate::prepare::is_sheared(
                p.linear * glam::DVec3::new(width, 0.0, 0.0),
                p.linear * glam::DVec3::new(0.0, height, 0.0),
            ) {
                r.flags |= FLAG_SHEARED_RECT;
            }
            (
                KIND_RECT,
                [(width / 2.0) as f32, (height / 2.0) as f32, 0.0, 0.0],
            )
        }
        LightType::Cylinder {
            length,
            radius,
            treat_as_line,
        } => {
            if treat_as_line {
                r.flags |= FLAG_TREAT_AS_POINT_OR_LINE;
            }
            (
                KIND_CYLINDER,
                [(length / 2.0) as f32, radius as f32, 0.0, 0.0],
            )
        }
        LightType::Dome => {
            // A masked dome: its portals' offset in the mesh atlas (radiance, portal.wgsl; and
            // irradiance where it is the device's, irradiance/portals.wgsl).
            if let (Some(_), Some(words)) = (&p.portals, atlas) {
                r.flags |= FLAG_PORTALS;
                r.tex[3] = words[3];
            }
            (KIND_DOME, [0.0; 4])
        }
        LightType::Mesh { double_sided, .. } => {
            if double_sided {
                r.flags |= FLAG_DOUBLE_SIDED;
            }
            // The kernels traverse its BVH for radiance and, where its emission is the device's
            // (GpuPath::HostIntensity), test its fronts; intensity is the host's (the kernel
            // gives 0 for KIND_MESH), and emission too under GpuPath::RadianceOnDevice.
            // Irradiance is the host's too (FLAG_HOST_IRRADIANCE) but under
            // GpuPath::HostIntensityOnly, where the kernel sums Lambert's formula over its
            // size.x triangles (at most MESH_TRIANGLES_SUMMED: exact in f32) in the atlas.
            r.tex = atlas.unwrap_or([0; 4]);
            if !p.emission_on_host() {
                r.flags |= FLAG_MESH_FRONTS;
            }
            let summed = match &p.kind {
                crate::prepare::KindData::Mesh { bvh, .. } if !p.irradiance_on_host() => {
                    bvh.order.len() as f32
                }
                _ => 0.0,
            };
            (KIND_MESH, [summed, 0.0, 0.0, 0.0])
        }
    };
    r.kind = kind;
    r.size = size;
    r
}

/// The record of a light every query takes from the CPU reference (`GpuPath::Host`: mesh
/// lights the device cannot hold, domes masked by too many portals): a `treatAsPoint` sphere of zero radiance at the origin, with an identity frame, so
/// that every kernel gives exactly 0 for it and the sampling kernels' light choice never picks
/// it (its luminance weight is 0); the host adds the reference's values.
fn host_record() -> Record {
    let id = |i: usize| {
        let mut r = [0.0; 4];
        r[i] = 1.0;
        r
    };
    Record {
        to_local: [id(0), id(1), id(2)],
        axis: [0.0, 0.0, -1.0, 0.0],
        normal: [0.0, 0.0, -1.0, 0.0],
        world: [id(0), id(1), id(2)],
        irr: [0.0, 1.0, 0.0, 0.0],
        kind: KIND_SPHERE,
        flags: FLAG_TREAT_AS_POINT_OR_LINE | FLAG_HOST_IRRADIANCE | FLAG_SIMILARITY,
        ..Record::default()
    }
}
