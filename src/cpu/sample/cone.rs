//! Directions uniform in a cone (f64): the sphere seen from outside, a distant light's disc and
//! a spot's cone (DESIGN.md §9 S2). A uniform density over a set that contains every lit
//! direction has `E[f²/p] = |Ω| ∫ f²`, so of two such cones the one of smaller solid angle is
//! never worse.

use glam::DVec3;
use std::f64::consts::PI;

/// The cone of directions within angle θ of the unit `axis`, held as `1 − cos θ` (computed by
/// the caller in a cancellation-free form: tiny cones, such as the sun's 0.27°, keep every
/// digit).
#[derive(Clone, Copy, Debug)]
pub struct Cone {
    pub axis: DVec3,
    pub one_minus_cos: f64,
}

impl Cone {
    /// The cone of half-angle `theta` (0 ≤ θ ≤ π): `1 − cos θ = 2 sin²(θ/2)`.
    pub fn with_angle(axis: DVec3, theta: f64) -> Cone {
        let s = (0.5 * theta.clamp(0.0, PI)).sin();
        Cone {
            axis,
            one_minus_cos: 2.0 * s * s,
        }
    }

    /// The cone a sphere of radius `r` at distance `d > r` subtends: `sin α = r/d`, so
    /// `1 − cos α = (r/d)² / (1 + √(1 − (r/d)²))`.
    pub fn subtended(axis: DVec3, r: f64, d: f64) -> Cone {
        let s2 = (r / d) * (r / d);
        Cone {
            axis,
            one_minus_cos: s2 / (1.0 + (1.0 - s2).max(0.0).sqrt()),
        }
    }

    /// Its solid angle, `2π (1 − cos θ)`.
    pub fn solid_angle(&self) -> f64 {
        2.0 * PI * self.one_minus_cos
    }

    /// A direction uniform in the cone: `cos` uniform in [cos θ, 1], azimuth uniform.
    pub fn sample(&self, u: [f64; 2]) -> DVec3 {
        let omc = u[0] * self.one_minus_cos;
        let cos = 1.0 - omc;
        let sin = (omc * (2.0 - omc)).max(0.0).sqrt();
        let (sp, cp) = (2.0 * PI * u[1]).sin_cos();
        let (t, b) = basis(self.axis);
        (t * (sin * cp) + b * (sin * sp) + self.axis * cos).normalize()
    }

    /// Whether the unit `w` lies in the cone (boundary included): `1 − cos` from the chord,
    /// `|w − axis|² / 2`, which keeps its digits for tiny cones.
    pub fn contains(&self, w: DVec3) -> bool {
        0.5 * (w - self.axis).length_squared() <= self.one_minus_cos
    }

    /// The uniform density, `1/Ω` inside and 0 outside.
    pub fn pdf(&self, w: DVec3) -> f64 {
        if self.contains(w) {
            1.0 / self.solid_angle()
        } else {
            0.0
        }
    }
}

/// An orthonormal pair completing the unit `n` to a right-handed frame, without a branch on
/// which component is small (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1),
/// 2017, Listing 3).
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.4, 0.866),
        ] {
            let n = n.normalize();
            let (t, b) = basis(n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(v).abs() < 1e-15);
            }
            assert!((t.length() - 1.0).abs() < 1e-15 && (b.length() - 1.0).abs() < 1e-15);
            assert!((t.cross(b) - n).length() < 1e-15);
        }
    }

    /// Samples stay in the cone, and the subtended cone's 1 − cos equals the direct formula.
    #[test]
    fn samples_stay_inside() {
        let c = Cone::subtended(DVec3::new(0.0, 0.6, 0.8), 1.0, 3.0);
        let direct = 1.0 - (1.0f64 - 1.0 / 9.0).sqrt();
        assert!((c.one_minus_cos - direct).abs() < 1e-15);
        let mut rng = crate::synthetic::Rng::new(5);
        for _ in 0..10_000 {
            let w = c.sample([rng.f64(), rng.f64()]);
            assert!((w.length() - 1.0).abs() < 1e-14);
            assert!(1.0 - w.dot(c.axis) <= c.one_minus_cos + 1e-12);
        }
    }
}
