//! radiance(x, ω) on the CPU (f64). Twin of `shaders/radiance.wgsl`.
//!
//! DESIGN.md §3: the RGB radiance arriving at x from direction ω (ω points from x toward the
//! light): the emission along −ω where a ray from x along ω first meets the light's emitting
//! surface, the distant light's value inside its cone, or the dome's in that direction; else 0.
//! Lights do not occlude each other. `treatAsPoint` / `treatAsLine` lights are zero-size, so no
//! ray meets them (DESIGN.md §2 "Edge cases").

use glam::DVec3;

use super::emission::{emission, surface_emission};
use super::shapes::{cylinder_hit, disk_hit, plane_hit, rect_hit, sphere_hit};
use super::texture::rect_factor;
use crate::model::LightType;
use crate::prepare::Prepared;

/// radiance at `x` from the unit direction `w`.
pub fn radiance(p: &Prepared, x: DVec3, w: DVec3) -> DVec3 {
    if matches!(p.light.kind, LightType::Mesh { .. }) {
        // DESIGN.md §7 M3: the first triangle hit, with the side it is hit on.
        super::mesh::radiance(p, x, w)
    } else if let Some(portals) = &p.portals {
        // A dome masked by its portals (DESIGN.md §8 P2 mask mode).
        super::portal::radiance(p, portals, x, w)
    } else if matches!(p.light.kind, LightType::Dome) {
        // A dome's emission is indexed by the direction toward the environment (DESIGN.md §3),
        // which is ω itself.
        emission(p, w)
    } else if hits_emitting_surface(p, x, w) {
        if p.rect_texture().is_some() {
            // DESIGN.md §6 "RectLight texture": L(−ω) ⊙ tex(s, t) at the hit point, not the
            // texture's mean that emission carries.
            let xl = p.to_local * (x - p.origin);
            let dl = p.to_local * w;
            match plane_hit(xl, dl) {
                Some(h) => surface_emission(p, -w) * rect_factor(p, h.truncate()),
                None => DVec3::ZERO,
            }
        } else {
            emission(p, -w)
        }
    } else {
        DVec3::ZERO
    }
}

/// Whether a ray from `x` along `w` (any length) sees the light: always for a dome, inside the
/// cone for a distant light (decided by its emission), the first hit on an emitting surface
/// otherwise.
pub fn hits_emitting_surface(p: &Prepared, x: DVec3, w: DVec3) -> bool {
    let xl = p.to_local * (x - p.origin);
    let dl = p.to_local * w;
    match p.light.kind {
        // A masked dome is seen only through a portal crossed toward its +Z (§8 P2).
        LightType::Dome if let Some(portals) = &p.portals => {
            super::portal::crossing(portals, x, w.normalize()).is_some()
        }
        LightType::Dome | LightType::Distant { .. } => true,
        LightType::Rect { width, height } => rect_hit(xl, dl, width / 2.0, height / 2.0),
        LightType::Disk { radius } => disk_hit(xl, dl, radius),
        LightType::Sphere {
            treat_as_point: true,
            ..
        } => false,
        LightType::Sphere { radius, .. } => sphere_hit(xl, dl, radius),
        LightType::Cylinder {
            treat_as_line: true,
            ..
        } => false,
        LightType::Cylinder { length, radius, .. } => cylinder_hit(xl, dl, length / 2.0, radius),
        LightType::Mesh { .. } => super::mesh::radiance(p, x, w) != DVec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Light;
    use crate::prepare::TemperatureMode;
    use glam::{DMat4, DQuat};

    fn prep(l: &Light) -> Prepared {
        Prepared::new(l, TemperatureMode::Spec).unwrap()
    }

    #[test]
    fn rect_seen_from_its_emitting_side_only() {
        // A rect at (0, 1, 0) rotated to face down (−Z → −Y).
        let m = DMat4::from_rotation_translation(
            DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2),
            DVec3::Y,
        );
        let p = prep(&Light::rect(1.0, 2.0).with_intensity(3.0).with_transform(m));
        assert!((p.axis - DVec3::NEG_Y).length() < 1e-15);
        assert_eq!(radiance(&p, DVec3::ZERO, DVec3::Y), DVec3::splat(3.0));
        assert_eq!(
            radiance(&p, DVec3::new(0.0, 2.0, 0.0), DVec3::NEG_Y),
            DVec3::ZERO
        );
        // Height 2 lies along world ±Z after the rotation: z = 0.9 hits, x = 0.6 misses.
        assert_eq!(
            radiance(&p, DVec3::new(0.0, 0.0, 0.9), DVec3::Y),
            DVec3::splat(3.0)
        );
        assert_eq!(
            radiance(&p, DVec3::new(0.6, 0.0, 0.0), DVec3::Y),
            DVec3::ZERO
        );
    }

    #[test]
    fn scaled_sphere_is_an_ellipsoid() {
        let m = DMat4::from_scale_rotation_translation(
            DVec3::new(4.0, 1.0, 1.0),
            DQuat::IDENTITY,
            DVec3::new(0.0, 0.0, -10.0),
        );
        let p = prep(&Light::sphere(0.5));
        let q = prep(&Light::sphere(0.5).with_transform(m));
        // x = 1.9 along X is inside the stretched sphere's silhouette (semi-axis 2).
        assert_eq!(
            radiance(&q, DVec3::new(1.9, 0.0, 0.0), DVec3::NEG_Z),
            DVec3::ONE
        );
        assert_eq!(
            radiance(&q, DVec3::new(2.1, 0.0, 0.0), DVec3::NEG_Z),
            DVec3::ZERO
        );
        assert_eq!(radiance(&p, DVec3::ZERO, DVec3::X), DVec3::ZERO); // inside
    }

    #[test]
    fn distant_cone_and_delta() {
        let p = prep(&Light::distant(10.0).with_intensity(2.0));
        // Toward the light is +Z (it emits along −Z).
        assert_eq!(radiance(&p, DVec3::ZERO, DVec3::Z), DVec3::splat(2.0));
        assert_eq!(radiance(&p, DVec3::ZERO, DVec3::NEG_Z), DVec3::ZERO);
        let delta = prep(&Light::distant(0.0));
        assert_eq!(radiance(&delta, DVec3::ZERO, DVec3::Z), DVec3::ZERO);
    }

    #[test]
    fn treat_as_point_and_line_have_no_radiance() {
        let mut s = Light::sphere(0.5);
        s.kind = LightType::Sphere {
            radius: 0.5,
            treat_as_point: true,
        };
        let p = prep(&s.with_transform(DMat4::from_translation(DVec3::Z * 3.0)));
        assert_eq!(radiance(&p, DVec3::ZERO, DVec3::Z), DVec3::ZERO);
        assert_eq!(emission(&p, DVec3::Z), DVec3::ONE);
    }
}
