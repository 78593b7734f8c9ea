//! Where an IES profile's factor is not smooth, as surfaces of light-space directions (for the
//! irradiance quadrature): every grid line of the bilinear interpolant (DESIGN.md §6 I3) is a
//! kink, and the range ends (beyond which the profile is 0) are jumps. In the light's frame
//! (§6 I2) each grid line is a circular cone around a frame axis or a plane through one:
//! - type C: V = const is the cone of angle V around −Z; H = const the plane through Z at
//!   azimuth H (with its images under the folds);
//! - type B: V = const is a plane through Y; H = const the cone around −Y with cos = sin H;
//! - type A: V = const is the cone around +Z with cos = sin V; H = const a plane through Z.
//!
//! angleScale maps type C's polar angle θ' = f(θ), which keeps cones cones (at θ = f⁻¹(V));
//! for types B and A it bends their surfaces, which are then left to the adaptive rules.

use glam::DVec3;

use super::ies::{HFold, PhotometricType, Profile, VFold};

/// Kink surfaces in the light's frame: cones `(unit axis, cos)` (the directions u with
/// `û·axis = cos`) and planes (their normals).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IesKinks {
    pub cones: Vec<(DVec3, f64)>,
    pub planes: Vec<DVec3>,
}

impl IesKinks {
    fn cone(&mut self, axis: DVec3, cos: f64) {
        if cos.abs() < 1e-15 {
            // A cone of angle 90° is the plane ⊥ its axis.
            self.planes.push(axis);
        } else if cos.abs() < 1.0 {
            self.cones.push((axis, cos));
        }
    }

    fn plane(&mut self, normal: DVec3) {
        if !self.planes.contains(&normal) {
            self.planes.push(normal);
        }
    }
}

/// The polar angle θ (degrees) at which angleScale `s` maps to θ' (§6 I4), when in [0, 180].
fn unscaled(theta_prime: f64, s: f64) -> Option<f64> {
    let t = if s > 0.0 {
        theta_prime * s
    } else if s < 0.0 {
        180.0 + (theta_prime - 180.0) * -s
    } else {
        theta_prime
    };
    (0.0..=180.0).contains(&t).then_some(t)
}

/// The kinks and jumps of `profile` looked up with angleScale `s`.
pub fn ies_kinks(profile: &Profile, s: f64) -> IesKinks {
    let mut k = IesKinks::default();
    let mirror = |x: f64, on: bool| if on { vec![x, -x] } else { vec![x] };
    match profile.kind {
        PhotometricType::C => {
            for &v in &profile.v {
                if let Some(t) = unscaled(v, s) {
                    k.cone(DVec3::NEG_Z, t.to_radians().cos());
                }
            }
            // angleScale's window θ' ∈ [0, 180].
            if s != 0.0 {
                for edge in [0.0, 180.0] {
                    if let Some(t) = unscaled(edge, s) {
                        k.cone(DVec3::NEG_Z, t.to_radians().cos());
                    }
                }
            }
            if profile.h_fold != HFold::Constant {
                for &h in &profile.h {
                    // A plane through Z holds azimuths H and H + 180; the folds add the mirror
                    // images −H (about the 0–180 plane) and 180 − H (about the 90–270 plane).
                    let images = match profile.h_fold {
                        HFold::Quadrant | HFold::Half | HFold::HalfC90 => vec![h, -h],
                        _ => vec![h],
                    };
                    for a in images {
                        let a = a.to_radians();
                        k.plane(DVec3::new(-a.sin(), a.cos(), 0.0));
                    }
                }
                if profile.h_fold == HFold::Full {
                    k.plane(DVec3::Y);
                }
            }
        }
        PhotometricType::B if s == 0.0 => {
            for &v in &profile.v {
                for a in mirror(v, profile.v_fold == VFold::Mirror) {
                    let a = a.to_radians();
                    k.plane(DVec3::new(a.cos(), 0.0, a.sin()));
                }
            }
            if profile.h_fold != HFold::Constant {
                for &h in &profile.h {
                    for a in mirror(h, profile.h_fold == HFold::Mirror) {
                        k.cone(DVec3::NEG_Y, a.to_radians().sin());
                    }
                }
            }
        }
        PhotometricType::A if s == 0.0 => {
            for &v in &profile.v {
                for a in mirror(v, profile.v_fold == VFold::Mirror) {
                    k.cone(DVec3::Z, a.to_radians().sin());
                }
            }
            let hs: Vec<f64> = if profile.h_fold == HFold::Constant {
                vec![90.0]
            } else {
                profile.h.clone()
            };
            for h in hs {
                for a in mirror(h, profile.h_fold == HFold::Mirror) {
                    let a = a.to_radians();
                    k.plane(DVec3::new(a.sin(), a.cos(), 0.0));
                }
            }
        }
        _ => {}
    }
    k
}
