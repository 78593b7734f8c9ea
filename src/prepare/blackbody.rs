//! `colorTemperature` → RGB multiplier (spec/001 `inputs:colorTemperature`, DESIGN.md §2).
//!
//! Computed once per light in f64 and uploaded to the GPU as part of the light's base radiance,
//! so this module has no WGSL twin.
//!
//! Three modes:
//! - [`TemperatureMode::Spec`] (default): the spec's text, "normalized such that the fallback
//!   value of 6500 will always result in white": `B(T) / B(6500)` per channel, `B` being UsdLux's
//!   own function below.
//! - [`TemperatureMode::Usd`]: `B(T)` as is, i.e. Pixar's `UsdLuxBlackbodyTemperatureAsRgb`
//!   (reference/openusd-reference.md §2.3 (a)): uniform Catmull-Rom over John Walker's Rec.709
//!   table, 1000–10000 K every 500 K, normalised to Rec.709 luma 1, negatives clamped to 0.
//! - [`TemperatureMode::Planckian`]: the OpenUSD reference renderer's path (§2.3 (b)): Krystek's
//!   Planckian-locus fit, XYZ → linear Rec.709, absolute values, luminance 1.

use glam::DVec3;

/// How `colorTemperature` becomes an RGB multiplier.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TemperatureMode {
    /// `B(T) / B(6500)`: 6500 K is exactly white, as the spec text says.
    #[default]
    Spec,
    /// `B(T)`: equal to Pixar's `UsdLux.BlackbodyTemperatureAsRgb`.
    Usd,
    /// The Planckian locus as hdEmbree computes it (GfColor, Rec.709, luminance 1).
    Planckian,
}

impl TemperatureMode {
    pub const ALL: [TemperatureMode; 3] = [Self::Spec, Self::Usd, Self::Planckian];

    pub fn name(self) -> &'static str {
        match self {
            Self::Spec => "spec",
            Self::Usd => "usd",
            Self::Planckian => "planckian",
        }
    }

    /// The RGB multiplier of `kelvin` in this mode (T clamped to [`Self::valid_range`]).
    pub fn rgb(self, kelvin: f64) -> DVec3 {
        temperature_rgb(kelvin, self)
    }

    /// The temperature range the mode clamps to, in kelvin.
    pub fn valid_range(self) -> (f64, f64) {
        match self {
            Self::Spec | Self::Usd => (1000.0, 10000.0),
            // Newer nanocolor clamps to [1000, 15000] (older versions returned NaN outside).
            Self::Planckian => (1000.0, 15000.0),
        }
    }
}

impl std::str::FromStr for TemperatureMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                format!("unknown temperature mode {s:?} (expected spec, usd or planckian)")
            })
    }
}

impl std::fmt::Display for TemperatureMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The RGB multiplier for `kelvin` in `mode` (T clamped to the mode's valid range).
pub fn temperature_rgb(kelvin: f64, mode: TemperatureMode) -> DVec3 {
    match mode {
        TemperatureMode::Usd => usdlux_blackbody(kelvin),
        TemperatureMode::Spec => usdlux_blackbody(kelvin) / usdlux_blackbody(6500.0),
        TemperatureMode::Planckian => planckian_rec709(kelvin),
    }
}

/// Walker's table (specrend.c): Rec.709 chromaticities from 1000 K to 10000 K every 500 K, with
/// the end knots repeated so that the Catmull-Rom spline needs no special cases.
const KNOTS: [[f64; 3]; 22] = [
    [1.000000, 0.027490, 0.000000], // 1000 K (repeated)
    [1.000000, 0.027490, 0.000000], // 1000 K
    [1.000000, 0.149664, 0.000000], // 1500 K
    [1.000000, 0.256644, 0.008095], // 2000 K
    [1.000000, 0.372033, 0.067450], // 2500 K
    [1.000000, 0.476725, 0.153601], // 3000 K
    [1.000000, 0.570376, 0.259196], // 3500 K
    [1.000000, 0.653480, 0.377155], // 4000 K
    [1.000000, 0.726878, 0.501606], // 4500 K
    [1.000000, 0.791543, 0.628050], // 5000 K
    [1.000000, 0.848462, 0.753228], // 5500 K
    [1.000000, 0.898581, 0.874905], // 6000 K
    [1.000000, 0.942771, 0.991642], // 6500 K
    [0.906947, 0.890456, 1.000000], // 7000 K
    [0.828247, 0.841838, 1.000000], // 7500 K
    [0.765791, 0.801896, 1.000000], // 8000 K
    [0.715255, 0.768579, 1.000000], // 8500 K
    [0.673683, 0.740423, 1.000000], // 9000 K
    [0.638992, 0.716359, 1.000000], // 9500 K
    [0.609681, 0.695588, 1.000000], // 10000 K
    [0.609681, 0.695588, 1.000000], // 10000 K (repeated)
    [0.609681, 0.695588, 1.000000], // 10000 K (repeated)
];

/// Rec.709 luma weights as UsdLux uses them (rounded, not derived from the primaries); also the
/// luminance that light sampling weighs and reports variances in (DESIGN.md §9 S1).
pub const REC709_LUMA: DVec3 = DVec3::new(0.2126, 0.7152, 0.0722);

/// UsdLuxBlackbodyTemperatureAsRgb in f64 (reference/openusd-reference.md §2.3 (a)).
pub fn usdlux_blackbody(kelvin: f64) -> DVec3 {
    let u = ((kelvin - 1000.0) / 9000.0).clamp(0.0, 1.0);
    // 22 knots give 18 segments plus a trailing one that starts at u == 1.
    let x = u * (KNOTS.len() - 4) as f64;
    let seg = x.floor() as usize;
    let t = x - seg as f64;
    let k = |i: usize| DVec3::from_array(KNOTS[seg + i]);
    let (k0, k1, k2, k3) = (k(0), k(1), k(2), k(3));
    // Uniform Catmull-Rom basis.
    let a = -0.5 * k0 + 1.5 * k1 - 1.5 * k2 + 0.5 * k3;
    let b = k0 - 2.5 * k1 + 2.0 * k2 - 0.5 * k3;
    let c = -0.5 * k0 + 0.5 * k2;
    let d = k1;
    let rgb = ((a * t + b) * t + c) * t + d;
    // Luma 1 first, then clamp (so luma may end slightly above 1 where a channel was negative).
    (rgb / rgb.dot(REC709_LUMA)).max(DVec3::ZERO)
}

/// Linear Rec.709 RGB→XYZ built from the primaries and D65 white, no chromatic adaptation
/// (as GfColorSpace builds it).
fn rec709_rgb_to_xyz() -> glam::DMat3 {
    let xy_to_xyz = |x: f64, y: f64| DVec3::new(x / y, 1.0, (1.0 - x - y) / y);
    let r = xy_to_xyz(0.64, 0.33);
    let g = xy_to_xyz(0.30, 0.60);
    let b = xy_to_xyz(0.15, 0.06);
    let w = xy_to_xyz(0.3127, 0.3290);
    let p = glam::DMat3::from_cols(r, g, b);
    let s = p.inverse() * w;
    glam::DMat3::from_cols(r * s.x, g * s.y, b * s.z)
}

/// hdEmbree's `_BlackbodyTemperatureAsRgb` (GfColor::SetFromPlanckianLocus in linear Rec.709,
/// then luminance 1), reference/openusd-reference.md §2.3 (b).
pub fn planckian_rec709(kelvin: f64) -> DVec3 {
    let t = kelvin.clamp(1000.0, 15000.0);
    // Krystek 1985: CIE 1960 (u, v) of the Planckian locus.
    let u = (0.860117757 + 1.54118254e-4 * t + 1.28641212e-7 * t * t)
        / (1.0 + 8.42420235e-4 * t + 7.08145163e-7 * t * t);
    let v = (0.317398726 + 4.22806245e-5 * t + 4.20481691e-8 * t * t)
        / (1.0 - 2.89741816e-5 * t + 1.61456053e-7 * t * t);
    // CIE 1960 uv → 1976 u'v' → xy → XYZ with Y = 1.
    let vp = 1.5 * v;
    let d = 6.0 * u - 16.0 * vp + 12.0;
    let x = 9.0 * u / d;
    let y = 4.0 * vp / d;
    let xyz = DVec3::new(x / y, 1.0, (1.0 - x - y) / y);
    let to_xyz = rec709_rgb_to_xyz();
    // nanocolor takes absolute values (after scaling by the largest magnitude, which the
    // luminance normalisation below cancels).
    let rgb = (to_xyz.inverse() * xyz).abs();
    let luminance = to_xyz.row(1);
    rgb / rgb.dot(luminance)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: [f64; 3], tol: f64) -> bool {
        (a - DVec3::from_array(b)).abs().max_element() <= tol
    }

    /// reference/luxtest.md §6 A7 (values from usd-core 26.11).
    #[test]
    fn a7_usd_table_values() {
        let cases = [
            (2000.0, [2.52057, 0.64689, 0.02040]),
            (4250.0, [1.35368, 0.93584, 0.59406]),
            (6500.0, [1.04333, 0.98362, 1.03461]),
            (8750.0, [0.91387, 0.99352, 1.31780]),
            (10000.0, [0.87184, 0.99469, 1.43000]),
            (11000.0, [0.87184, 0.99469, 1.43000]),
        ];
        for (t, want) in cases {
            let got = temperature_rgb(t, TemperatureMode::Usd);
            assert!(close(got, want, 6e-6), "{t} K: {got} vs {want:?}");
        }
    }

    /// reference/luxtest.md §6 A7, GfColor column.
    #[test]
    fn a7_planckian_values() {
        let cases = [
            (2000.0, [2.51989, 0.64698, 0.02045]),
            (4250.0, [1.35461, 0.93540, 0.59549]),
            (6500.0, [1.04415, 0.98327, 1.03569]),
            (8750.0, [0.91330, 0.99384, 1.31636]),
            (10000.0, [0.87080, 0.99519, 1.42826]),
            (11000.0, [0.84535, 0.99529, 1.50216]),
        ];
        for (t, want) in cases {
            let got = temperature_rgb(t, TemperatureMode::Planckian);
            assert!(close(got, want, 1.5e-5), "{t} K: {got} vs {want:?}");
        }
        // reference/openusd-reference.md §2.3: at 1000 K the blue channel comes from abs().
        let got = temperature_rgb(1000.0, TemperatureMode::Planckian);
        assert!(close(got, [4.54012, 0.03923, 0.09053], 2e-5), "{got}");
    }

    #[test]
    fn spec_mode_is_white_at_6500_and_clamps() {
        assert_eq!(temperature_rgb(6500.0, TemperatureMode::Spec), DVec3::ONE);
        assert_eq!(
            temperature_rgb(500.0, TemperatureMode::Spec),
            temperature_rgb(1000.0, TemperatureMode::Spec)
        );
        assert_eq!(
            temperature_rgb(40000.0, TemperatureMode::Usd),
            temperature_rgb(10000.0, TemperatureMode::Usd)
        );
        // Warm is red-dominant, cool blue-dominant.
        let warm = temperature_rgb(3000.0, TemperatureMode::Spec);
        let cool = temperature_rgb(9000.0, TemperatureMode::Spec);
        assert!(warm.x > warm.z && cool.z > cool.x);
    }
}
