//! Where an IES profile's factor is not smooth, as surfaces of light-space directions (for the
//! irradiance quadrature): every grid line of the bilinear interpolant (DESIGN.md §6 I3) is a
//! kink, and the range ends (beyond which the profile is 0) are jumps. In the light's frame
//! (§6 I2) each grid line is a circular cone around a frame axis or a plane through one:
//! - type C: V = const is the cone of angle V around −Z; H = const the plane through Z at
//!   azimuth H (with its images under the folds);
//! - type B: V = const is a plane through Y; H = const the cone around −Y with cos = sin H;
//! - type A: V = const is the cone around +Z with cos = sin V; H = const a plane through Z.
//!
//! angleScale maps the polar angle θ about −Z to θ' = f(θ) and keeps the azimuth, which keeps
//! cones around ±Z cones (at θ = f⁻¹(θ')) and planes through Z planes: types C and A keep
//! their families. For type B it bends its surfaces (neither cones nor planes), which are then
//! left to the adaptive rules, unless it is ±1 (θ' = θ).

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

/// Whether angleScale `s` bends a `kind` profile's grid surfaces into ones that are neither
/// cones nor planes: type B's (its planes hold Y, which the polar remap about Z does not
/// keep), unless `s` is 0 or ±1 (θ' = θ). [`ies_kinks`] lists no kinks for such a profile,
/// and the device cannot split at them (`PreparedIes::device_families`).
pub fn bent(kind: PhotometricType, s: f64) -> bool {
    kind == PhotometricType::B && s != 0.0 && s.abs() != 1.0
}

/// The kinks and jumps of `profile` looked up with angleScale `s`.
pub fn ies_kinks(profile: &Profile, s: f64) -> IesKinks {
    let mut k = IesKinks::default();
    let mirror = |x: f64, on: bool| if on { vec![x, -x] } else { vec![x] };
    // The cone of the directions whose θ' (their polar angle θ about −Z after angleScale) is
    // `theta_prime`, on the family's `axis` (±Z, so its cosine is `∓cos θ`).
    let polar = |k: &mut IesKinks, axis: DVec3, theta_prime: f64| {
        if let Some(t) = unscaled(theta_prime, s) {
            k.cone(axis, -axis.z * t.to_radians().cos());
        }
    };
    // angleScale's window θ' ∈ [0, 180], beyond which the factor is 0.
    let window = |k: &mut IesKinks, axis: DVec3| {
        if s != 0.0 {
            polar(k, axis, 0.0);
            polar(k, axis, 180.0);
        }
    };
    match profile.kind {
        PhotometricType::C => {
            for &v in &profile.v {
                polar(&mut k, DVec3::NEG_Z, v);
            }
            window(&mut k, DVec3::NEG_Z);
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
        PhotometricType::B if !bent(PhotometricType::B, s) => {
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
        PhotometricType::A => {
            // Type A is type C with V_A = θ' − 90° and H_A = −φ (§6 I2), and angleScale maps θ
            // to θ' keeping φ (I4): V_A = const is the cone around −Z at θ = f⁻¹(V_A + 90°),
            // i.e. around +Z with cos = −cos θ (= sin V_A when s = 0), and H_A = const the
            // same plane through Z for every s.
            for &v in &profile.v {
                for a in mirror(v, profile.v_fold == VFold::Mirror) {
                    if s == 0.0 {
                        // sin V_A, as it always was for unscaled profiles (−cos(V_A + 90°)
                        // differs from it in the last bits).
                        k.cone(DVec3::Z, a.to_radians().sin());
                    } else {
                        polar(&mut k, DVec3::Z, a + 90.0);
                    }
                }
            }
            window(&mut k, DVec3::Z);
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

/// The most planes outside the pencil that [`IesKinks::families`] keeps (the kernel adds them
/// to a line's fixed breakpoints, whose array is sized for them).
pub const MAX_EXTRA_PLANES: usize = 2;

/// [`IesKinks`] as the GPU quadrature streams them along a line (shaders/irradiance/line.wgsl):
/// every profile cone shares one axis (type C: −Z, B: −Y, A: +Z) and every plane but a cone of
/// 90° contains one axis (C and A: Z, B: Y). Along a line `w = a + X e` the cosine of `−ŵ` with
/// the cone axis has one extremum, and the azimuth of `w` about the pencil's axis turns one
/// way, so on each side of those points the crossed cones (planes) are a run of the list
/// sorted by cosine (azimuth), found by binary search: no breakpoint array of the profile's
/// size is needed.
#[derive(Clone, Debug, PartialEq)]
pub struct KinkFamilies {
    /// The cones' common axis and their cosines, ascending (duplicates dropped).
    pub cone_axis: DVec3,
    pub cone_cos: Vec<f64>,
    /// The pencil's axis P and a unit `u ⊥ P` (with `v = P × u` the frame of azimuths).
    pub pencil_axis: DVec3,
    pub pencil_u: DVec3,
    /// Per plane of the pencil, ascending in δ ∈ [0, π): the azimuth δ (from u towards v) of
    /// the directions the plane holds, and its unit normal's (u, v) coordinates.
    pub planes: Vec<(f64, f64, f64)>,
    /// Planes not through P (the cone of 90°, a plane ⊥ the cone axis): unit normals.
    pub extra: Vec<DVec3>,
}

impl IesKinks {
    /// The kinks grouped as [`KinkFamilies`]; None when they are not one family of coaxial
    /// cones and one pencil of planes plus at most [`MAX_EXTRA_PLANES`] others (angleScale on
    /// type B lists no kinks at all and gives an empty family; any other mixture cannot
    /// come from [`ies_kinks`], and is refused rather than streamed wrongly).
    pub fn families(&self) -> Option<KinkFamilies> {
        let cone_axis = self.cones.first().map_or(DVec3::NEG_Z, |c| c.0);
        if self.cones.iter().any(|c| c.0 != cone_axis) {
            return None;
        }
        let mut cone_cos: Vec<f64> = self.cones.iter().map(|c| c.1).collect();
        cone_cos.sort_by(f64::total_cmp);
        cone_cos.dedup();
        let unit: Vec<DVec3> = self
            .planes
            .iter()
            .map(|m| m.normalize_or_zero())
            .filter(|m| *m != DVec3::ZERO)
            .collect();
        // The pencil's axis: ⊥ to most normals. Candidates: the frame axes the types use.
        let on = |p: DVec3, m: &DVec3| m.dot(p).abs() <= 1e-12;
        let pencil_axis = [DVec3::Z, DVec3::Y, DVec3::X]
            .into_iter()
            .max_by_key(|p| unit.iter().filter(|m| on(*p, m)).count())
            .unwrap_or(DVec3::Z);
        let (pencil, extra): (Vec<DVec3>, Vec<DVec3>) =
            unit.iter().partition(|m| on(pencil_axis, m));
        if extra.len() > MAX_EXTRA_PLANES {
            return None;
        }
        let pencil_u = pencil_axis.any_orthonormal_vector();
        let pencil_v = pencil_axis.cross(pencil_u);
        let mut planes: Vec<(f64, f64, f64)> = pencil
            .iter()
            .map(|m| {
                let (mu, mv) = (m.dot(pencil_u), m.dot(pencil_v));
                // The plane holds the azimuths of (−mv, mu) and its opposite.
                let d = mu.atan2(-mv).rem_euclid(std::f64::consts::PI);
                let d = if d >= std::f64::consts::PI { 0.0 } else { d };
                (d, mu, mv)
            })
            .collect();
        planes.sort_by(|a, b| a.0.total_cmp(&b.0));
        planes.dedup_by(|a, b| a.0 == b.0);
        Some(KinkFamilies {
            cone_axis,
            cone_cos,
            pencil_axis,
            pencil_u,
            planes,
            extra,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A profile of unit candela on the given grids (its kinks depend on the grids alone).
    pub(crate) fn profile(
        kind: PhotometricType,
        h: &[f64],
        v: &[f64],
        h_fold: HFold,
        v_fold: VFold,
    ) -> Profile {
        Profile {
            kind,
            h: h.to_vec(),
            v: v.to_vec(),
            candela: vec![1.0; h.len() * v.len()],
            h_fold,
            v_fold,
            tilt: None,
        }
    }

    /// Every kink of every type and fold is in the families exactly as the kernel streams it:
    /// cones on one axis with their cosines ascending, planes of the pencil ascending in
    /// azimuth δ ∈ [0, π), each holding the direction at δ, the rest among the extras.
    #[test]
    fn families_hold_every_kink_sorted() {
        use HFold::*;
        use PhotometricType::*;
        let cases = [
            profile(
                C,
                &[0.0],
                &[0.0, 10.0, 35.5, 90.0, 120.0],
                Constant,
                VFold::AsGiven,
            ),
            profile(
                C,
                &[0.0, 30.0, 90.0],
                &[0.0, 45.0, 90.0],
                Quadrant,
                VFold::AsGiven,
            ),
            profile(
                C,
                &[0.0, 45.0, 180.0],
                &[90.0, 135.0, 180.0],
                Half,
                VFold::AsGiven,
            ),
            profile(
                C,
                &[90.0, 180.0, 270.0],
                &[0.0, 60.0],
                HalfC90,
                VFold::AsGiven,
            ),
            profile(
                C,
                &[0.0, 100.0, 200.0, 300.0, 360.0],
                &[0.0, 20.0],
                Full,
                VFold::AsGiven,
            ),
            profile(
                B,
                &[0.0, 20.0, 90.0],
                &[0.0, 30.0, 90.0],
                Mirror,
                VFold::Mirror,
            ),
            profile(
                B,
                &[-40.0, 0.0, 50.0],
                &[-80.0, -10.0, 90.0],
                AsGiven,
                VFold::AsGiven,
            ),
            profile(
                A,
                &[0.0, 25.0, 90.0],
                &[0.0, 45.0, 90.0],
                Mirror,
                VFold::Mirror,
            ),
            profile(
                A,
                &[0.0],
                &[-90.0, 0.0, 15.0, 90.0],
                Constant,
                VFold::AsGiven,
            ),
        ];
        for p in &cases {
            for s in [0.0, 0.8, -1.2] {
                let k = ies_kinks(p, s);
                let f = k.families().expect("families");
                assert!(
                    f.cone_cos.windows(2).all(|w| w[0] < w[1]),
                    "{:?}",
                    f.cone_cos
                );
                for (axis, cos) in &k.cones {
                    assert_eq!(*axis, f.cone_axis);
                    assert!(f.cone_cos.contains(cos), "cone {cos} of {:?}", p.kind);
                }
                let pv = f.pencil_axis.cross(f.pencil_u);
                assert!(f.planes.windows(2).all(|w| w[0].0 < w[1].0));
                for &(d, mu, mv) in &f.planes {
                    assert!((0.0..std::f64::consts::PI).contains(&d), "δ {d}");
                    let m = f.pencil_u * mu + pv * mv;
                    let held = f.pencil_u * d.cos() + pv * d.sin();
                    assert!(m.dot(held).abs() < 1e-12 && m.dot(f.pencil_axis).abs() < 1e-12);
                }
                for m in &k.planes {
                    let m = m.normalize();
                    let in_pencil = f
                        .planes
                        .iter()
                        .any(|&(_, mu, mv)| (f.pencil_u * mu + pv * mv).cross(m).length() < 1e-12);
                    let extra = f.extra.iter().any(|e| e.cross(m).length() < 1e-12);
                    assert!(in_pencil || extra, "plane {m} of {:?} s {s}", p.kind);
                }
            }
        }
    }

    /// angleScale bends the grid lines of type B: the light keeps its irradiance on the host
    /// (PreparedIes::device_families), whose kinks list is empty for it.
    #[test]
    fn bent_profiles_list_no_kinks() {
        let p = profile(
            PhotometricType::B,
            &[0.0, 30.0],
            &[0.0, 40.0],
            HFold::Mirror,
            VFold::Mirror,
        );
        assert_eq!(ies_kinks(&p, 0.7), IesKinks::default());
        assert!(!ies_kinks(&p, 0.0).planes.is_empty());
        // ±1 maps θ to itself: the same kinks as 0.
        assert_eq!(ies_kinks(&p, 1.0), ies_kinks(&p, 0.0));
        assert_eq!(ies_kinks(&p, -1.0), ies_kinks(&p, 0.0));
    }
}
