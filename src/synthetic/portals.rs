//! Randomised domes seen through portals (DESIGN.md §8), for the conformance suite and `luxeval
//! check`'s tests: one to three portals around the origin (random size, orientation, shear or
//! non-uniform scale, multiplier), facing outward so that points near the origin see the dome
//! through them, some overlapping as seen from there, and now and then one turned inward (which
//! passes no light to the origin's side and hides none).

use glam::{DMat4, DQuat, DVec3};

use super::Rng;
use crate::model::{Light, Portal};

/// A random portal at 1.5–4 units from the origin along a random direction, its +Z outward
/// (light passes toward −Z, i.e. toward the origin), 15 % of them turned inward.
fn random_portal(rng: &mut Rng, k: usize) -> Portal {
    let out = rng.unit();
    let centre = out * rng.range(1.5, 4.0);
    let outward = if rng.chance(0.15) { -out } else { out };
    let spin = DQuat::from_axis_angle(outward, rng.range(0.0, std::f64::consts::TAU));
    let face = spin * DQuat::from_rotation_arc(DVec3::Z, outward);
    let mut world = DMat4::from_rotation_translation(face, centre);
    if rng.chance(0.3) {
        // A non-uniform scale or a shear of the portal's plane (still a parallelogram).
        let shear = DMat4::from_cols_array_2d(&[
            [rng.range(0.5, 1.5), rng.range(-0.4, 0.4), 0.0, 0.0],
            [rng.range(-0.4, 0.4), rng.range(0.5, 1.5), 0.0, 0.0],
            [0.0, 0.0, rng.range(0.5, 2.0), 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        world *= shear;
    }
    let mut p = Portal::new(rng.range(0.5, 4.0), rng.range(0.5, 4.0))
        .with_path(format!("/random/portal_{k}"))
        .with_transform(world)
        .with_intensity(rng.range(0.2, 3.0))
        .with_exposure(rng.range(-1.0, 1.0))
        .with_color(DVec3::new(
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
        ));
    if rng.chance(0.3) {
        p = p.with_temperature(rng.range(2000.0, 12000.0));
    }
    p
}

/// A dome (the random LightAPI inputs of [`super::random_light`], a random rotation) naming one
/// to three random portals; `dome` may carry a texture (set before or after).
pub fn random_portal_dome(rng: &mut Rng, id: usize) -> Light {
    let xf = if rng.chance(0.5) {
        "rotate"
    } else {
        "identity"
    };
    let mut dome = super::random_light(5, xf, rng, id);
    dome.shaping = None;
    dome.path = format!("/random/{id}_dome_portals");
    for k in 0..1 + rng.below(3) {
        dome = dome.with_portal(random_portal(rng, 10 * id + k));
    }
    dome
}
