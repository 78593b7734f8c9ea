//! Portals as the evaluation uses them (DESIGN.md §8 P2): the portal mode, and for a dome in
//! mask mode each of its portals' world rectangle, emitting-side normal and multiplier, computed
//! once in f64. Hint mode prepares nothing: its values are bitwise those of a dome with no
//! portal, since nothing downstream can see a portal that was never prepared.

use glam::{DMat3, DVec2, DVec3};

use super::TemperatureMode;
use super::blackbody::temperature_rgb;
use crate::error::{LuxError, Result};
// The mode is plain data of the model, so that `usd` (above `prepare`, DESIGN.md §1) can say
// how a stage's portals are evaluated.
pub use crate::model::PortalMode;
use crate::model::{Light, LightType, Portal};

/// A portal's multiplier (DESIGN.md §8 P2): its own LightAPI product `intensity · 2^exposure ·
/// color ⊙ temperature(T)`, formed as a light's base radiance is (normalize does not apply, P1).
pub fn multiplier(p: &Portal, mode: TemperatureMode) -> DVec3 {
    let tint = if p.enable_color_temperature {
        temperature_rgb(p.color_temperature, mode)
    } else {
        DVec3::ONE
    };
    p.intensity * 2f64.powf(p.exposure) * p.color * tint
}

/// One portal of a masked dome, in world space.
#[derive(Clone, Debug)]
pub struct PreparedPortal {
    /// World-space centre.
    pub origin: DVec3,
    /// World → local linear map (the inverse of the portal's world 3×3).
    pub to_local: DMat3,
    /// Half width and half height in local units.
    pub half: DVec2,
    /// Unit world normal of the portal's local +Z side (the inverse transpose applied to +Z, as
    /// a rect light's normal is formed, DESIGN.md §2 "Frames"): light passes toward −Z, so a
    /// ray counts where it crosses moving along `+normal` (P2).
    pub normal: DVec3,
    /// The world corners, local (−,−), (+,−), (+,+), (−,+): a convex planar quadrilateral
    /// (a parallelogram under any linear map).
    pub corners: [DVec3; 4],
    /// [`multiplier`] in the scene's temperature mode.
    pub multiplier: DVec3,
}

/// The portals a dome is masked by in `mode`: `None` (not masked) in hint mode, for other
/// lights, and for a dome naming no visible portal (P1: unchanged in either mode). A portal of zero area or whose world transform is singular passes no
/// light and is left out (its side, hence the direction light passes it, is undefined); an
/// invalid portal input is refused naming the portal and the attribute.
pub fn prepare_portals(
    light: &Light,
    mode: PortalMode,
    temperature: TemperatureMode,
) -> Result<Option<Vec<PreparedPortal>>> {
    if mode == PortalMode::Hint || light.kind != LightType::Dome || light.portals.is_empty() {
        return Ok(None);
    }
    let mut out = Vec::with_capacity(light.portals.len());
    for p in &light.portals {
        p.validate()?;
        let linear = DMat3::from_mat4(p.world);
        let det = linear.determinant();
        let half = DVec2::new(p.width / 2.0, p.height / 2.0);
        let multiplier = multiplier(p, temperature);
        if !multiplier.is_finite() {
            return Err(LuxError::attr(
                &p.path,
                "inputs:intensity",
                p.intensity,
                format!("intensity · 2^exposure · color overflows ({multiplier})"),
            ));
        }
        // Written so that a NaN also leaves the portal out.
        let passes = det.abs() > 0.0 && half.x > 0.0 && half.y > 0.0;
        if !passes {
            continue;
        }
        let to_local = linear.inverse();
        let Some(normal) = (to_local.transpose() * DVec3::Z).try_normalize() else {
            continue;
        };
        let origin = p.world.w_axis.truncate();
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(a, b)| origin + linear * DVec3::new(a * half.x, b * half.y, 0.0));
        out.push(PreparedPortal {
            origin,
            to_local,
            half,
            normal,
            corners,
            multiplier,
        });
    }
    Ok(Some(out))
}
