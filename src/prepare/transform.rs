//! Properties of a light's world transform that prepare and both paths read: its tilt
//! against the stage's down (IES), whether its rect edges are sheared, whether it is a
//! similarity.

use glam::{DMat3, DVec3};

use crate::model::UpAxis;

/// The tilt angle τ of DESIGN.md §6 I5 in degrees: between the light's world primary axis and
/// the stage's world down (−Y for `upAxis` Y, −Z for Z).
pub fn tilt_angle(axis: DVec3, up: UpAxis) -> f64 {
    let down = match up {
        UpAxis::Y => DVec3::NEG_Y,
        UpAxis::Z => DVec3::NEG_Z,
    };
    axis.cross(down).length().atan2(axis.dot(down)).to_degrees()
}

/// Whether the parallelogram of world edges `e1`, `e2` (both non-zero) is sheared, i.e. not a
/// rectangle: the rect sampler's choice between Ureña's spherical rectangle and Arvo's two
/// triangles (`cpu::sample::rect::RectSampler`), made once in f64 for both paths.
pub fn is_sheared(e1: DVec3, e2: DVec3) -> bool {
    e1.dot(e2).abs() > 1e-12 * e1.length() * e2.length()
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
