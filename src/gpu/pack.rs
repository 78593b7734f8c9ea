//! Packing prepared lights into GPU records. Twin of the `Light` struct in
//! `shaders/shared/light.wgsl`; `tests/wgsl.rs` checks this layout against naga's layouter.

use bytemuck::{Pod, Zeroable};

use crate::cpu::PreparedLight;
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

/// Threads per workgroup of every kernel.
pub const WORKGROUP_SIZE: u32 = 64;

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
    ("WORKGROUP_SIZE", WORKGROUP_SIZE),
];

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
    pub kind: u32,
    pub flags: u32,
    pub pad: [u32; 2],
}

/// The kernel-side parameters of one dispatch (`Params` in `shaders/shared/light.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub count: u32,
    pub light_count: u32,
    pub per_light: u32,
    pub row_stride: u32,
}

fn v4(v: glam::DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

/// Rounds a prepared light's f64 constants to its GPU record.
pub fn pack(p: &PreparedLight) -> LightRecord {
    let m = p.to_local;
    // Local = M⁻¹·(x − o): row i is (row_i(M⁻¹), −row_i(M⁻¹)·o).
    let row = |i: usize| v4(m.row(i), -m.row(i).dot(p.origin));
    let mut r = LightRecord {
        to_local: [row(0), row(1), row(2)],
        axis: v4(p.axis, 0.0),
        normal: v4(p.normal, 0.0),
        base: v4(p.base, 0.0),
        ..LightRecord::default()
    };
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
