//! Packing prepared lights into GPU records. Twin of the `Light` struct in
//! `shaders/shared/light.wgsl`; `tests/wgsl.rs` checks this layout against naga's layouter.

use bytemuck::{Pod, Zeroable};

use crate::cpu::PreparedLight;
use crate::cpu::irradiance;
use crate::light::LightType;

/// Record kinds; the WGSL prelude declares the same names from this table.
pub const KIND_DISTANT: u32 = 0;
pub const KIND_SPHERE: u32 = 1;
pub const KIND_DISK: u32 = 2;
pub const KIND_RECT: u32 = 3;
pub const KIND_CYLINDER: u32 = 4;
pub const KIND_DOME: u32 = 5;

/// ShapingAPI is applied.
pub const FLAG_SHAPING: u32 = 1;
/// `treatAsPoint` (sphere) or `treatAsLine` (cylinder) is set.
pub const FLAG_TREAT_AS_POINT_OR_LINE: u32 = 2;
/// The linear map is a similarity (a sphere stays a sphere: the irradiance cap applies).
pub const FLAG_SIMILARITY: u32 = 4;
/// Irradiance kink cones (`irr.z`, `irr.w` hold their cos θ): the shaping's cone edge and
/// smoothstep start, as `cpu::irradiance::Profile` lists them.
pub const FLAG_KINK_A: u32 = 8;
pub const FLAG_KINK_B: u32 = 16;
/// The plane ⊥ the axis (θ = 90°) is a kink of the shaping.
pub const FLAG_FOCUS_PLANE: u32 = 32;
/// ... and |cos θ|^focus is not smooth there (the quadrature grades toward it).
pub const FLAG_FOCUS_GRADED: u32 = 64;
/// ShapingAPI makes the light dark everywhere (cone angle ≤ 0).
pub const FLAG_DARK: u32 = 128;
/// The shaping is not smooth at the axis directions (`Profile::axis_singular`).
pub const FLAG_AXIS_SINGULAR: u32 = 256;

/// Threads per workgroup of every kernel.
pub const WORKGROUP_SIZE: u32 = 64;

/// Irradiance kernel: Gauss–Legendre points of the elevation integral of a sphere cap cut by the
/// horizon (`cap_sliver`).
pub const IRR_GL_CAP: usize = 12;
/// Irradiance kernel: Gauss–Legendre points per inner span.
/// (The WGSL writes the inner rule's 10 nodes out: changing this needs `inner_rule` changed.)
pub const IRR_GL_INNER: usize = 10;
/// Irradiance kernel: each inner span is integrated adaptively: the rule on the span against the
/// rule on its halves; halves whose difference exceeds `IRR_INNER_TOL` of their value are split
/// again, at most `IRR_INNER_DEPTH` times (the order is chosen per light and receiver).
pub const IRR_INNER_TOL: f64 = 1e-5;
pub const IRR_INNER_DEPTH: usize = 6;
/// Irradiance kernel: each outer span is integrated by the 7-point Gauss / 15-point Kronrod
/// pair; a span whose Gauss and Kronrod values differ by more than `IRR_OUTER_TOL` of the
/// Kronrod value is halved, at most `IRR_OUTER_DEPTH` times. (Kronrod's error is far below that
/// difference, which measures Gauss's: the test `kernel_rule_in_f64_is_within_1e_5_of_the_reference`
/// holds the whole rule to 1e-5.)
pub const IRR_OUTER_TOL: f64 = 1e-3;
pub const IRR_OUTER_DEPTH: usize = 5;
/// Irradiance kernel: samples per elliptic arc when bracketing cone crossings.
pub const IRR_ARC_SAMPLES: u32 = 24;
/// Irradiance kernel: an unshaped rect uses Lambert's formula only where its edge terms cannot
/// cancel much in f32: (d / smaller half-extent) · (d / height above its plane) ≤ this. The
/// terms of a rect that is far, thin or seen near its plane cancel like each factor (measured on
/// lavapipe: 1.8e-4 at 590, a 0.2 × 2 rect 5 m away at 5° above its plane); past it, the
/// quadrature (all positive terms) is used.
pub const IRR_LAMBERT_COND: f64 = 16.0;

/// The `u32` constants shared with WGSL, by name.
pub const WGSL_CONSTANTS: &[(&str, u32)] = &[
    ("KIND_DISTANT", KIND_DISTANT),
    ("KIND_SPHERE", KIND_SPHERE),
    ("KIND_DISK", KIND_DISK),
    ("KIND_RECT", KIND_RECT),
    ("KIND_CYLINDER", KIND_CYLINDER),
    ("KIND_DOME", KIND_DOME),
    ("FLAG_SHAPING", FLAG_SHAPING),
    ("FLAG_TREAT_AS_POINT_OR_LINE", FLAG_TREAT_AS_POINT_OR_LINE),
    ("FLAG_SIMILARITY", FLAG_SIMILARITY),
    ("FLAG_KINK_A", FLAG_KINK_A),
    ("FLAG_KINK_B", FLAG_KINK_B),
    ("FLAG_FOCUS_PLANE", FLAG_FOCUS_PLANE),
    ("FLAG_FOCUS_GRADED", FLAG_FOCUS_GRADED),
    ("FLAG_DARK", FLAG_DARK),
    ("FLAG_AXIS_SINGULAR", FLAG_AXIS_SINGULAR),
    ("WORKGROUP_SIZE", WORKGROUP_SIZE),
    ("IRR_GL_CAP", IRR_GL_CAP as u32),
    ("IRR_GL_INNER", IRR_GL_INNER as u32),
    ("IRR_INNER_DEPTH", IRR_INNER_DEPTH as u32),
    ("IRR_OUTER_DEPTH", IRR_OUTER_DEPTH as u32),
    ("IRR_ARC_SAMPLES", IRR_ARC_SAMPLES),
];

/// The `f32` constants shared with WGSL, by name.
pub const WGSL_F32_CONSTANTS: &[(&str, f64)] = &[
    ("IRR_LAMBERT_COND", IRR_LAMBERT_COND),
    ("IRR_INNER_TOL", IRR_INNER_TOL),
    ("IRR_OUTER_TOL", IRR_OUTER_TOL),
    ("IRR_TAN_MAP_RHO", crate::cpu::irradiance::TAN_MAP_RHO),
    ("IRR_MAX_U_SPAN", crate::cpu::irradiance::MAX_U_SPAN),
];

/// The `f32` arrays shared with WGSL (emitted as module-scope `var<private>` so that they can be
/// indexed at run time): the irradiance kernel's Gauss–Legendre rules on [0, 1].
pub fn wgsl_f32_arrays() -> Vec<(&'static str, Vec<f64>)> {
    let (xo, wo) = crate::cpu::quadrature::gauss_legendre(IRR_GL_CAP);
    let (xi, wi) = crate::cpu::quadrature::gauss_legendre(IRR_GL_INNER);
    let gk = crate::cpu::quadrature::gk15_unit();
    vec![
        ("IRR_GL_CAP_X", xo),
        ("IRR_GL_CAP_W", wo),
        ("IRR_GL_INNER_X", xi),
        ("IRR_GL_INNER_W", wi),
        ("IRR_GK_X", gk.0),
        ("IRR_GK_WK", gk.1),
        ("IRR_GK_WG", gk.2),
    ]
}

/// One light as the kernels read it (see `shaders/shared/light.wgsl` for each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightRecord {
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
    pub kind: u32,
    pub flags: u32,
    pub pad: [u32; 2],
}

/// The kernel-side parameters of one dispatch (`Params` in `shaders/shared/light.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub count: u32,
    pub light_first: u32,
    pub light_end: u32,
    pub per_light: u32,
    pub row_stride: u32,
    pub accumulate: u32,
    pub pad: [u32; 2],
}

fn v4(v: glam::DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

/// Rounds a prepared light's f64 constants to its GPU record.
pub fn pack(p: &PreparedLight) -> LightRecord {
    let m = p.to_local;
    // Local = M⁻¹·(x − o): row i is (row_i(M⁻¹), −row_i(M⁻¹)·o).
    let row = |i: usize| v4(m.row(i), -m.row(i).dot(p.origin));
    let lin = p.light.linear();
    let mut r = LightRecord {
        to_local: [row(0), row(1), row(2)],
        axis: v4(p.axis, 0.0),
        normal: v4(p.normal, 0.0),
        base: v4(p.base, 0.0),
        world: [
            v4(lin.x_axis, p.origin.x),
            v4(lin.y_axis, p.origin.y),
            v4(lin.z_axis, p.origin.z),
        ],
        irr: [
            p.light.inputs.diffuse as f32,
            lin.determinant().abs() as f32,
            0.0,
            0.0,
        ],
        ..LightRecord::default()
    };
    if irradiance::similarity_scale(lin).is_some() {
        r.flags |= FLAG_SIMILARITY;
    }
    // The shaping's kinks exactly as the CPU quadrature lists them.
    let profile = irradiance::Profile::new(p.light.shaping.as_ref(), p.axis);
    if profile.dark {
        r.flags |= FLAG_DARK;
    }
    if profile.axis_singular {
        r.flags |= FLAG_AXIS_SINGULAR;
    }
    let mut cones = 0;
    for k in &profile.kinks {
        match *k {
            irradiance::Kink::Cone { cos } => {
                r.irr[2 + cones] = cos as f32;
                r.flags |= if cones == 0 { FLAG_KINK_A } else { FLAG_KINK_B };
                cones += 1;
            }
            irradiance::Kink::Plane { graded, .. } => {
                r.flags |= FLAG_FOCUS_PLANE;
                if graded {
                    r.flags |= FLAG_FOCUS_GRADED;
                }
            }
        }
    }
    if let Some(s) = &p.light.shaping {
        r.flags |= FLAG_SHAPING;
        r.focus_tint = v4(s.focus_tint, s.focus);
        let cone = s.cone_angle.to_radians();
        let start = (1.0 - s.cone_softness.clamp(0.0, 1.0)) * cone;
        r.cone = [cone as f32, start as f32, 0.0, 0.0];
    }
    let (kind, size) = match p.light.kind {
        LightType::Distant { angle } => {
            r.axis[3] = crate::cpu::normalize::distant_half_angle(angle) as f32;
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
        LightType::Rect { width, height } => (
            KIND_RECT,
            [(width / 2.0) as f32, (height / 2.0) as f32, 0.0, 0.0],
        ),
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
        LightType::Dome => (KIND_DOME, [0.0; 4]),
    };
    r.kind = kind;
    r.size = size;
    r
}
