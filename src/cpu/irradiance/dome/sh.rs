//! The fast path: 9-coefficient spherical harmonics of the dome (Ramamoorthi & Hanrahan 2001,
//! "An efficient representation for irradiance environment maps"; Filament's `libs/ibl` does the
//! same with pre-scaled coefficients). `c_lm = ∫ L(ω) Y_lm(ω) dω` is projected from the *same
//! filtered texture* in world solid angle (piece by piece, [`DomeIrradiance::integrate_sphere`]),
//! then `E(n) ≈ Σ_l Â_l Σ_m c_lm Y_lm(n)` with the clamped-cosine kernel's `Â₀ = π`,
//! `Â₁ = 2π/3`, `Â₂ = π/4`. Bands l ≥ 3 are dropped, so the error depends on the map; the
//! measured figures (tests/sh.rs) are in the crate README.

use glam::DVec3;

use super::DomeIrradiance;

const PI: f64 = std::f64::consts::PI;

/// The nine real SH basis functions at unit `w` (order: (0,0), (1,−1), (1,0), (1,1), (2,−2),
/// (2,−1), (2,0), (2,1), (2,2); y is the m = −1 axis of band 1 as in Ramamoorthi–Hanrahan).
pub fn basis(w: DVec3) -> [f64; 9] {
    let c0 = 0.5 / PI.sqrt();
    let c1 = (3.0 / (4.0 * PI)).sqrt();
    let c2 = (15.0 / (4.0 * PI)).sqrt();
    let c20 = (5.0 / (16.0 * PI)).sqrt();
    let c22 = (15.0 / (16.0 * PI)).sqrt();
    let (x, y, z) = (w.x, w.y, w.z);
    [
        c0,
        c1 * y,
        c1 * z,
        c1 * x,
        c2 * x * y,
        c2 * y * z,
        c20 * (3.0 * z * z - 1.0),
        c2 * x * z,
        c22 * (x * x - y * y),
    ]
}

/// Band of each coefficient and the clamped-cosine convolution factor `Â_l`.
const BAND_FACTOR: [f64; 9] = [
    PI,
    2.0 * PI / 3.0,
    2.0 * PI / 3.0,
    2.0 * PI / 3.0,
    PI / 4.0,
    PI / 4.0,
    PI / 4.0,
    PI / 4.0,
    PI / 4.0,
];

/// Irradiance SH: `Â_l c_lm` per coefficient, RGB.
#[derive(Clone, Debug)]
pub struct IrradianceSh {
    pub coeffs: [DVec3; 9],
}

impl IrradianceSh {
    /// Projects the dome's filtered texture (world solid angle, the dome's transform included).
    pub fn project(dome: &DomeIrradiance) -> IrradianceSh {
        if let Some(m) = dome.separable_moments() {
            return IrradianceSh::from_moments(dome, &m);
        }
        IrradianceSh::project_pieces(dome)
    }

    /// The projection piece by piece with the moments' quadrature (any format and frame).
    pub fn project_pieces(dome: &DomeIrradiance) -> IrradianceSh {
        let raw = dome.integrate_sphere::<27>(&|w, l| {
            let y = basis(w);
            let mut out = [0.0; 27];
            for k in 0..9 {
                out[3 * k] = l.x * y[k];
                out[3 * k + 1] = l.y * y[k];
                out[3 * k + 2] = l.z * y[k];
            }
            out
        });
        IrradianceSh {
            coeffs: std::array::from_fn(|k| {
                DVec3::new(raw[3 * k], raw[3 * k + 1], raw[3 * k + 2]) * BAND_FACTOR[k]
            }),
        }
    }

    /// From dome-space moments (ν, μ, S) of a conformal frame: with `ω = R d`
    /// (`R = A_eff / |det A|^⅓`), `∫ L ω = Rμ` and `∫ L ω ωᵀ = R S Rᵀ`, and each of the nine
    /// basis functions is a combination of 1, ω and ω ωᵀ.
    pub fn from_moments(dome: &DomeIrradiance, m: &[(f64, DVec3, glam::DMat3); 3]) -> IrradianceSh {
        let r = dome.frame.a_eff * (1.0 / dome.frame.det_abs.cbrt());
        let c0 = 0.5 / PI.sqrt();
        let c1 = (3.0 / (4.0 * PI)).sqrt();
        let c2 = (15.0 / (4.0 * PI)).sqrt();
        let c20 = (5.0 / (16.0 * PI)).sqrt();
        let c22 = (15.0 / (16.0 * PI)).sqrt();
        let per = |(nu, mu, s): &(f64, DVec3, glam::DMat3)| {
            let (mu, s) = (r * *mu, r * *s * r.transpose());
            let e = |i: usize, j: usize| s.col(j)[i];
            [
                c0 * nu,
                c1 * mu.y,
                c1 * mu.z,
                c1 * mu.x,
                c2 * e(0, 1),
                c2 * e(1, 2),
                c20 * (3.0 * e(2, 2) - nu),
                c2 * e(0, 2),
                c22 * (e(0, 0) - e(1, 1)),
            ]
        };
        let (a, b, c) = (per(&m[0]), per(&m[1]), per(&m[2]));
        IrradianceSh {
            coeffs: std::array::from_fn(|k| DVec3::new(a[k], b[k], c[k]) * BAND_FACTOR[k]),
        }
    }

    /// `E(n)` for a unit world normal: nine multiply-adds per channel.
    pub fn irradiance(&self, n: DVec3) -> DVec3 {
        let y = basis(n);
        self.coeffs.iter().zip(y).map(|(c, y)| *c * y).sum()
    }
}
