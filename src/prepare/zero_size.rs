//! Zero-size lights (DESIGN.md §2 "Zero-size lights"): DCCs write point lights as radius-0
//! spheres, animators scale lights to 0 to hide them. Such a light is evaluated, with a warning,
//! never refused:
//!
//! - a sphere of zero world size (radius 0, or a transform that maps it to a point) with
//!   `normalize` on is the limit of a shrinking normalized sphere: a point at its centre whose
//!   intensity along every direction is `L·πr² = intensity · 2^exposure · color ⊙ temperature / 4`
//!   (shaping applies), `treatAsPoint` or not; radiance from it is 0;
//! - every other sphere, disk, rect or cylinder whose world emitting area is 0, or whose world
//!   transform is singular (it is flattened: no frame to evaluate it in), emits nothing.
//!
//! Both are evaluated as an ordinary light in its place (so that both backends, every query and
//! the per-light rows treat them alike): the point as a normalized `treatAsPoint` unit sphere
//! (its intensity is `L·π = X/(4π)·π = X/4` exactly as the limit says), the dark light as a
//! unit sphere of intensity 0. The point keeps the light's orientation (its primary axis for
//! shaping; the light's frame for IES) without its scale; where the transform maps the primary
//! axis to 0 the world's −Z is used.

use glam::{DMat3, DMat4, DVec3};

use super::normalize::world_area;
use crate::model::{Light, LightType};

/// The light evaluated in place of a zero-size `light`, with the warning that names it; `None`
/// for a light of non-zero size (and for distant and dome lights, which have none).
pub fn substitute(light: &Light) -> Option<(Light, String)> {
    let radius = match light.kind {
        LightType::Sphere { radius, .. } => Some(radius),
        LightType::Disk { .. } | LightType::Rect { .. } | LightType::Cylinder { .. } => None,
        LightType::Distant { .. } | LightType::Dome => return None,
        // A mesh's triangles are in world space: only a mesh of no area is dark (its
        // transform matters to shaping alone, and validation refuses a singular one there).
        LightType::Mesh { ref geometry, .. } => match geometry.area > 0.0 {
            true => return None,
            false => None,
        },
    };
    let m = light.linear();
    let singular = light.is_singular() && !matches!(light.kind, LightType::Mesh { .. });
    if !singular && world_area(light) > 0.0 {
        return None;
    }
    let path = &light.path;
    let to_point = m.x_axis == DVec3::ZERO && m.y_axis == DVec3::ZERO && m.z_axis == DVec3::ZERO;
    if let Some(r) = radius
        && (r == 0.0 || to_point)
        && light.inputs.normalize
    {
        let mut point = Light::sphere(1.0).with_path(path.clone());
        point.kind = LightType::Sphere {
            radius: 1.0,
            treat_as_point: true,
        };
        point.inputs = light.inputs.clone();
        point.shaping = light.shaping.clone();
        point.stage_up = light.stage_up;
        let point =
            point.with_transform(DMat4::from_mat3_translation(orientation(m), light.origin()));
        return Some((
            point,
            format!(
                "{path}: a sphere of zero world size with normalize: evaluated as a point of \
                 intensity intensity · 2^exposure · color / 4 along every direction (DESIGN.md §2)"
            ),
        ));
    }
    let mut dark = Light::sphere(1.0).with_path(path.clone());
    dark.inputs.intensity = 0.0;
    dark.inputs.normalize = false;
    dark.stage_up = light.stage_up;
    let dark = dark.with_transform(DMat4::from_translation(light.origin()));
    let why = if singular {
        "its world transform is singular (it is flattened)"
    } else {
        "its world emitting area is 0"
    };
    Some((
        dark,
        format!("{path}: {why}, so it emits nothing (DESIGN.md §2 \"Zero-size lights\")"),
    ))
}

/// A rotation whose −Z is the direction of `m`'s image of −Z (the light's primary axis), its X
/// as near `m`'s image of X as allowed: the light's orientation without its scale.
fn orientation(m: DMat3) -> DMat3 {
    let z = (m * DVec3::Z).try_normalize().unwrap_or(DVec3::Z);
    let x = (m * DVec3::X - (m * DVec3::X).dot(z) * z)
        .try_normalize()
        .unwrap_or_else(|| z.any_orthonormal_vector());
    DMat3::from_cols(x, z.cross(x), z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare::{Prepared, TemperatureMode};

    #[test]
    fn a_normalized_radius_0_sphere_is_a_point_of_a_quarter_of_its_power() {
        let l = Light::sphere(0.0).with_intensity(8.0).with_normalize(true);
        let (point, warning) = substitute(&l).unwrap();
        assert!(warning.contains("point"), "{warning}");
        let p = Prepared::new(&point, TemperatureMode::Spec).unwrap();
        // L · π r² along every direction: 8 / 4 = 2.
        for e in [
            DVec3::X,
            DVec3::NEG_Y,
            DVec3::new(0.3, 0.4, -0.866).normalize(),
        ] {
            let i = crate::cpu::intensity::intensity(&p, e);
            assert!((i - DVec3::splat(2.0)).abs().max_element() < 1e-14, "{i}");
        }
    }

    #[test]
    fn flattened_and_empty_lights_emit_nothing() {
        let flat = Light::disk(1.0).with_transform(DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0)));
        let (dark, warning) = substitute(&flat).unwrap();
        assert!(warning.contains("singular"), "{warning}");
        assert_eq!(dark.inputs.intensity, 0.0);
        let (_, warning) = substitute(&Light::rect(0.0, 2.0)).unwrap();
        assert!(warning.contains("area is 0"), "{warning}");
        // Without normalize, a radius-0 sphere emits nothing.
        let (dark, _) = substitute(&Light::sphere(0.0).with_normalize(false)).unwrap();
        assert_eq!(dark.inputs.intensity, 0.0);
        assert!(substitute(&Light::sphere(0.5)).is_none());
        assert!(substitute(&Light::distant(0.0)).is_none());
    }
}
