//! Portal lights (DESIGN.md §8 P1) as plain data: a rectangle a dome's light passes through,
//! with its multiplier inputs, attached to the domes whose `portals` relationship names it.
//! Nothing here evaluates light: what a portal changes (P2) is a later step.

use glam::{DMat4, DVec3};

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
