//! Textures as both backends use them, a dome's environment map and a rect's image (DESIGN.md
//! §6 D1–D6, "RectLight texture"): which format a file is (`automatic`), the dome's frame
//! (poleAxis offset `P` composed with the world 3×3 `A`), the codes and the cube-cross table the
//! lookups share, the inverse maps (image coordinates → direction, for tests and irradiance) and
//! the reconstruction's pieces. The per-lookup forward maps are the CPU twin of `texture.wgsl`,
//! `src/cpu/texture.rs`, which reads this module.

use std::sync::Arc;

use glam::{DMat3, DVec2, DVec3};

pub use crate::assets::texture::{EnvMap, Image};
use crate::model::{PoleAxis, TextureFormat, UpAxis};

/// Format codes shared with the WGSL header (`FORMAT_*` constants there).
pub const FORMAT_LATLONG: u32 = 0;
pub const FORMAT_MIRRORED_BALL: u32 = 1;
pub const FORMAT_ANGULAR: u32 = 2;
pub const FORMAT_CROSS: u32 = 3;
/// A rect light's texture: both axes clamp (§6 "RectLight texture").
pub const FORMAT_RECT: u32 = 4;
/// Filter codes shared with the WGSL (`FILTER_*` there).
pub const FILTER_BILINEAR: u32 = 0;
pub const FILTER_NEAREST: u32 = 1;

/// One face of §6 D5's table: F, R, U and the block (column, row).
pub type CrossFace = ([f64; 3], [f64; 3], [f64; 3], [f64; 2]);

/// §6 D5's table, faces numbered +X, −X, +Y, −Y, +Z, −Z = 0..5: (F, R, U) and the face's block
/// (column, row) in the vertical cross.
pub const CROSS_FACES: [CrossFace; 6] = [
    (
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0],
    ),
    (
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [0.0, 1.0, 0.0],
        [2.0, 1.0],
    ),
    (
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0],
    ),
    (
        [0.0, -1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 2.0],
    ),
    (
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0],
    ),
    (
        [0.0, 0.0, -1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [1.0, 3.0],
    ),
];

/// Texture filter (`--texture-filter`), §6 D1: the model's choice.
pub use crate::model::TextureFilter as Filter;

impl Filter {
    /// The code shared with the WGSL (`FILTER_*`).
    pub fn code(self) -> u32 {
        match self {
            Filter::Bilinear => FILTER_BILINEAR,
            Filter::Nearest => FILTER_NEAREST,
        }
    }
}

/// A resolved format (never `automatic`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DomeFormat {
    LatLong,
    MirroredBall,
    Angular,
    /// §6 D5; the face size is `N = W/3`.
    Cross,
}

impl DomeFormat {
    #[cfg(test)]
    pub const ALL: [DomeFormat; 4] = [
        DomeFormat::LatLong,
        DomeFormat::MirroredBall,
        DomeFormat::Angular,
        DomeFormat::Cross,
    ];

    /// The code shared with the WGSL (`FORMAT_*`).
    pub fn code(self) -> u32 {
        match self {
            DomeFormat::LatLong => FORMAT_LATLONG,
            DomeFormat::MirroredBall => FORMAT_MIRRORED_BALL,
            DomeFormat::Angular => FORMAT_ANGULAR,
            DomeFormat::Cross => FORMAT_CROSS,
        }
    }
}

/// A format that does not fit the file (defined with the other texture-file errors).
pub use crate::assets::texture::FormatError;

/// §6 D6 (`automatic`) and D5's size rule.
pub fn resolve_format(requested: TextureFormat, img: &Image) -> Result<DomeFormat, FormatError> {
    let (w, h) = (img.width, img.height);
    let path = || img.source.clone();
    let f = match requested {
        TextureFormat::LatLong => DomeFormat::LatLong,
        TextureFormat::MirroredBall => DomeFormat::MirroredBall,
        TextureFormat::Angular => DomeFormat::Angular,
        TextureFormat::CubeMapVerticalCross => DomeFormat::Cross,
        TextureFormat::Automatic => match img.envmap {
            Some(EnvMap::LatLong) => DomeFormat::LatLong,
            Some(EnvMap::Cube) => return Err(FormatError::EnvmapCube { path: path() }),
            None if w == 2 * h => DomeFormat::LatLong,
            None if 4 * w == 3 * h => DomeFormat::Cross,
            None if w == h => DomeFormat::Angular,
            None => {
                return Err(FormatError::Ambiguous {
                    path: path(),
                    width: w,
                    height: h,
                });
            }
        },
    };
    if f == DomeFormat::Cross && (w % 3 != 0 || h % 4 != 0 || w / 3 != h / 4 || w == 0) {
        return Err(FormatError::BadCross {
            path: path(),
            width: w,
            height: h,
        });
    }
    Ok(f)
}

/// §6 D1: `P = R_x(+90°)` (dome +Y → world +Z, dome +Z → −Y) for DomeLight_1 with poleAxis `Z`,
/// or `scene` on a Z-up stage; identity otherwise, and always for plain DomeLight (`None`).
/// Returned in glam's column-vector convention: `P_col · d = d · P_usd`.
pub fn pole_offset(pole_axis: Option<PoleAxis>, stage_up: UpAxis) -> DMat3 {
    let rotate = match pole_axis {
        Some(PoleAxis::Z) => true,
        Some(PoleAxis::Scene) => stage_up == UpAxis::Z,
        Some(PoleAxis::Y) | None => false,
    };
    if rotate {
        // USD rows (1,0,0), (0,0,1), (0,−1,0) are glam's columns.
        DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::NEG_Y)
    } else {
        DMat3::IDENTITY
    }
}

/// A dome's frame: `A_eff = P · A` in USD's row-vector order, stored in glam's column-vector
/// convention as `world · P` (world direction `ω ∝ A_eff · d`).
#[derive(Clone, Copy, Debug)]
pub struct DomeFrame {
    /// Dome space → world (column-vector convention).
    pub a_eff: DMat3,
    /// World → dome (`A_eff⁻¹`): `d = normalize(inv · ω)` (§6 D1).
    pub inv: DMat3,
    /// `|det A|` (the Jacobian's numerator, §6 D1 last sentence).
    pub det_abs: f64,
}

impl DomeFrame {
    /// `w = |det A| / |A_eff d|⁴` (§6 D1's Jacobian over the normalisation's length, the
    /// irradiance integrand's weight in dome space) when it is the same for every `d`: a
    /// conformal frame, `A_effᵀ A_eff = s² I` (rotation × uniform scale) to 1e-13.
    pub fn conformal_weight(&self) -> Option<f64> {
        let gram = self.a_eff.transpose() * self.a_eff;
        let s2 = self.det_abs.powf(2.0 / 3.0);
        ((gram - DMat3::IDENTITY * s2)
            .to_cols_array()
            .iter()
            .all(|v| v.abs() <= 1e-13 * s2))
        .then(|| self.det_abs / (s2 * s2))
    }

    /// `world` is the dome's world 3×3 (parents included) as glam's column-vector matrix
    /// ([`crate::model::Light::linear`]). Returns `None` for a singular matrix, which has no
    /// dome direction.
    pub fn new(world: DMat3, pole: DMat3) -> Option<DomeFrame> {
        let a_eff = world * pole;
        let det = a_eff.determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return None;
        }
        Some(DomeFrame {
            a_eff,
            inv: a_eff.inverse(),
            det_abs: det.abs(),
        })
    }

    #[cfg(test)]
    pub fn identity() -> DomeFrame {
        DomeFrame {
            a_eff: DMat3::IDENTITY,
            inv: DMat3::IDENTITY,
            det_abs: 1.0,
        }
    }

    /// World direction → dome direction (§6 D1; `dome_direction` of `src/cpu/texture.rs`).
    pub fn to_dome(self, w: DVec3) -> DVec3 {
        (self.inv * w).normalize()
    }

    /// Dome direction → world direction (unit).
    #[cfg(test)]
    pub fn to_world(self, d: DVec3) -> DVec3 {
        (self.a_eff * d).normalize()
    }

    /// The receiver's horizon in dome space: `n · ω ∝ (A_effᵀ n) · d`, so the lit half of the
    /// dome is `m · d > 0` with `m = A_effᵀ n` (not normalised: `n·ω = m·d / |A_eff d|`).
    pub fn horizon(&self, n: DVec3) -> DVec3 {
        self.a_eff.transpose() * n
    }

    /// World solid angle per dome solid angle at dome direction `d` (§6 D1):
    /// `|det A| / |A_eff d|³`.
    #[cfg(test)]
    pub fn jacobian(&self, d: DVec3) -> f64 {
        let l = (self.a_eff * d).length();
        self.det_abs / (l * l * l)
    }
}

/// A light's texture as both backends evaluate it: loaded once per file
/// ([`super::assets::AssetCache::texture`]) and shared.
#[derive(Clone, Debug)]
pub struct PreparedTexture {
    pub image: Arc<Image>,
    /// The resolved format (§6 D6).
    pub format: DomeFormat,
    /// World ↔ dome (§6 D1).
    pub frame: DomeFrame,
    /// Bilinear (default) or nearest (§6 D1).
    pub filter: Filter,
    /// The irradiance tables of this texture (built lazily by the CPU reference on the first
    /// irradiance query, `src/cpu/irradiance/dome.rs`, and shared by clones of the light). Typed
    /// `Any` because prepare does not name cpu types (tests/layers.rs).
    pub irradiance: IrradianceSlot,
}

/// A RectLight's texture as both backends evaluate it (DESIGN.md §6 "RectLight texture"): the
/// image (loaded once per file, shared with any dome using it), its filter, and the exact area
/// mean of the filtered reconstruction, which `emission` multiplies by. Built by
/// [`RectTexture::new`] so that the mean always belongs to the filter.
#[derive(Clone, Debug)]
pub struct RectTexture {
    pub image: Arc<Image>,
    filter: Filter,
    mean: DVec3,
    /// The moment tree of the fast irradiance path (built lazily by the CPU on the first query
    /// at a loose tolerance, `src/cpu/irradiance/rect_fast.rs`, and shared by clones). Typed
    /// `Any` because prepare does not name cpu types.
    pub irradiance: IrradianceSlot,
}

impl RectTexture {
    pub fn new(image: Arc<Image>, filter: Filter) -> RectTexture {
        let mean = area_mean(&image, filter);
        RectTexture {
            image,
            filter,
            mean,
            irradiance: IrradianceSlot::default(),
        }
    }

    /// Bilinear (default) or nearest, both axes clamped.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The area mean of the clamped-bilinear (or nearest) reconstruction over the image
    /// ([`area_mean`]): `emission = L ⊙ mean`, so that `intensity = emission × projected area`.
    pub fn mean(&self) -> DVec3 {
        self.mean
    }
}

/// A lazily filled, shared slot for a texture's irradiance tables (see
/// [`PreparedTexture::irradiance`]).
pub type IrradianceSlot = Arc<std::sync::OnceLock<Arc<dyn std::any::Any + Send + Sync>>>;

/// §6 D5's table entry of face `f` as vectors: (F, R, U, block).
pub fn cross_face_basis(f: u32) -> (DVec3, DVec3, DVec3, DVec2) {
    let (fw, r, u, b) = CROSS_FACES[f.min(5) as usize];
    (
        DVec3::from_array(fw),
        DVec3::from_array(r),
        DVec3::from_array(u),
        DVec2::from_array(b),
    )
}

#[cfg(test)]
/// `(s, t)` → dome direction, the inverse of the forward maps (`src/cpu/texture.rs`). `None`
/// outside the format's domain (outside the disk for mirroredBall/angular, outside the six faces
/// for the cross).
pub fn st_to_direction(format: DomeFormat, st: DVec2) -> Option<DVec3> {
    let (s, t) = (st.x, st.y);
    match format {
        DomeFormat::LatLong => Some(latlong_dir(s, t)),
        DomeFormat::MirroredBall | DomeFormat::Angular => {
            let (a, b) = (2.0 * s - 1.0, 1.0 - 2.0 * t);
            let r2 = a * a + b * b;
            if r2 > 1.0 {
                return None;
            }
            Some(if format == DomeFormat::MirroredBall {
                ball_dir(a, b)
            } else {
                angular_dir(a, b)
            })
        }
        DomeFormat::Cross => {
            let (cx, cy) = ((s * 3.0).floor().min(2.0), (t * 4.0).floor().min(3.0));
            let f = face_at_block(cx as u32, cy as u32)?;
            let (a, b) = (2.0 * (s * 3.0 - cx) - 1.0, 1.0 - 2.0 * (t * 4.0 - cy));
            Some(cross_dir(f, a, b))
        }
    }
}

#[cfg(test)]
/// Inverse of §6 D2: `φ = 2π(0.5 − s)`, `θ = πt`, `d = (sin θ sin φ, cos θ, sin θ cos φ)`.
pub fn latlong_dir(s: f64, t: f64) -> DVec3 {
    let phi = std::f64::consts::TAU * (0.5 - s);
    let theta = std::f64::consts::PI * t;
    let (st, ct) = theta.sin_cos();
    DVec3::new(st * phi.sin(), ct, st * phi.cos())
}

/// §6 D3: `d = (2a√(1−r²), 2b√(1−r²), 1 − 2r²)`.
pub fn ball_dir(a: f64, b: f64) -> DVec3 {
    let r2 = (a * a + b * b).min(1.0);
    let q = 2.0 * (1.0 - r2).sqrt();
    DVec3::new(a * q, b * q, 1.0 - 2.0 * r2)
}

#[cfg(test)]
/// §6 D4: `d = (a·sin(πr)/r, b·sin(πr)/r, cos πr)` (sin(πr)/r → π at the centre).
pub fn angular_dir(a: f64, b: f64) -> DVec3 {
    let r = (a * a + b * b).sqrt().min(1.0);
    let pr = std::f64::consts::PI * r;
    let k = if r < 1e-8 {
        std::f64::consts::PI * (1.0 - pr * pr / 6.0)
    } else {
        pr.sin() / r
    };
    DVec3::new(a * k, b * k, pr.cos())
}

#[cfg(test)]
/// §6 D5: `d = normalize(F + a·R + b·U)` on face `f`.
pub fn cross_dir(f: u32, a: f64, b: f64) -> DVec3 {
    let (fw, r, u, _) = cross_face_basis(f);
    (fw + a * r + b * u).normalize()
}

#[cfg(test)]
/// The face stored in block (column, row) of the vertical cross, if any.
pub fn face_at_block(col: u32, row: u32) -> Option<u32> {
    (0..6).find(|&f| {
        let b = CROSS_FACES[f as usize].3;
        b[0] as u32 == col && b[1] as u32 == row
    })
}

/// One piece of a 1-D reconstruction on an axis of `n` texels (pixel units): on `[x0, x1]` the
/// value is `(1 − f)·T[i0] + f·T[i1]` with `f = x − origin` (bilinear), or `T[i0]` (nearest,
/// `i0 = i1`). The 2-D reconstruction is the tensor product of two axes' pieces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisPiece {
    pub x0: f64,
    pub x1: f64,
    pub i0: u32,
    pub i1: u32,
    pub origin: f64,
}

impl AxisPiece {
    /// The two texel weights at `x` (they sum to 1).
    #[inline]
    pub fn weights(&self, x: f64) -> (f64, f64) {
        let f = if self.i0 == self.i1 {
            0.0
        } else {
            x - self.origin
        };
        (1.0 - f, f)
    }

    /// `∫_{x0}^{x1}` of the two weights (exact: they are linear).
    pub fn weight_integrals(&self) -> (f64, f64) {
        let len = self.x1 - self.x0;
        if self.i0 == self.i1 {
            return (len, 0.0);
        }
        let m = 0.5 * (self.x0 + self.x1) - self.origin;
        (len * (1.0 - m), len * m)
    }
}

/// §6 D1 on one axis of `n ≥ 1` texels: the pieces between texel-centre lines (bilinear kinks,
/// at `k + 0.5`) or texel edges (nearest jumps, at `k`), with the axis' wrap or clamp rule.
/// Bilinear clamp: `[0, ½]` and `[n − ½, n]` are constant (the edge texel); wrap: they blend
/// texels `n − 1` and `0` across the seam.
pub fn axis_pieces(n: u32, wrap: bool, filter: Filter) -> Vec<AxisPiece> {
    let nf = n as f64;
    if filter == Filter::Nearest {
        return (0..n)
            .map(|k| AxisPiece {
                x0: k as f64,
                x1: k as f64 + 1.0,
                i0: k,
                i1: k,
                origin: k as f64,
            })
            .collect();
    }
    if n == 1 {
        return vec![AxisPiece {
            x0: 0.0,
            x1: 1.0,
            i0: 0,
            i1: 0,
            origin: 0.0,
        }];
    }
    let mut v = Vec::with_capacity(n as usize + 1);
    v.push(if wrap {
        AxisPiece {
            x0: 0.0,
            x1: 0.5,
            i0: n - 1,
            i1: 0,
            origin: -0.5,
        }
    } else {
        AxisPiece {
            x0: 0.0,
            x1: 0.5,
            i0: 0,
            i1: 0,
            origin: 0.0,
        }
    });
    for k in 1..n {
        let c = k as f64 - 0.5;
        v.push(AxisPiece {
            x0: c,
            x1: c + 1.0,
            i0: k - 1,
            i1: k,
            origin: c,
        });
    }
    v.push(if wrap {
        AxisPiece {
            x0: nf - 0.5,
            x1: nf,
            i0: n - 1,
            i1: 0,
            origin: nf - 0.5,
        }
    } else {
        AxisPiece {
            x0: nf - 0.5,
            x1: nf,
            i0: n - 1,
            i1: n - 1,
            origin: nf - 0.5,
        }
    });
    v
}

/// The exact area mean of the clamped-bilinear (or nearest) reconstruction over the whole image
/// (§6 "RectLight texture": a textured rect's `emission` is `L ⊙` this). Each texel's weight is
/// the integral of its 1-D weights over the axis (separable), so the mean is
/// `Σ T_ij a_i b_j / (W H)` in f64.
pub fn area_mean(img: &Image, filter: Filter) -> DVec3 {
    let axis = |n: usize| {
        let mut w = vec![0.0f64; n];
        for p in axis_pieces(n as u32, false, filter) {
            let (a, b) = p.weight_integrals();
            w[p.i0 as usize] += a;
            w[p.i1 as usize] += b;
        }
        w
    };
    let (a, b) = (axis(img.width), axis(img.height));
    let mut sum = DVec3::ZERO;
    for (j, row) in img.rgb.chunks_exact(img.width).enumerate() {
        let mut r = DVec3::ZERO;
        for (i, t) in row.iter().enumerate() {
            r += a[i] * DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64);
        }
        sum += b[j] * r;
    }
    sum / (img.width as f64 * img.height as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: usize, h: usize) -> Image {
        Image::from_rgb(w, h, vec![[1.0; 3]; w * h], "t.png").unwrap()
    }

    #[test]
    fn automatic_follows_the_aspect_and_the_cross_needs_3n_by_4n() {
        let f = |w, h| resolve_format(TextureFormat::Automatic, &img(w, h));
        assert_eq!(f(8, 4), Ok(DomeFormat::LatLong));
        assert_eq!(f(6, 8), Ok(DomeFormat::Cross));
        assert_eq!(f(5, 5), Ok(DomeFormat::Angular));
        assert!(matches!(f(7, 4), Err(FormatError::Ambiguous { .. })));
        let mut e = img(6, 6);
        e.envmap = Some(EnvMap::LatLong);
        assert_eq!(
            resolve_format(TextureFormat::Automatic, &e),
            Ok(DomeFormat::LatLong)
        );
        e.envmap = Some(EnvMap::Cube);
        assert!(resolve_format(TextureFormat::Automatic, &e).is_err());
        let bad = resolve_format(TextureFormat::CubeMapVerticalCross, &img(6, 9)).unwrap_err();
        assert!(bad.to_string().contains("t.png"), "{bad}");
    }

    #[test]
    fn pole_offset_is_the_dome_only_rotation_of_d1() {
        let p = pole_offset(Some(PoleAxis::Z), UpAxis::Y);
        assert_eq!(p * DVec3::Y, DVec3::Z);
        assert_eq!(p * DVec3::Z, DVec3::NEG_Y);
        assert_eq!(
            pole_offset(Some(PoleAxis::Scene), UpAxis::Z),
            pole_offset(Some(PoleAxis::Z), UpAxis::Y)
        );
        assert_eq!(pole_offset(None, UpAxis::Z), DMat3::IDENTITY);
        assert_eq!(pole_offset(Some(PoleAxis::Y), UpAxis::Z), DMat3::IDENTITY);
        assert_eq!(
            pole_offset(Some(PoleAxis::Scene), UpAxis::Y),
            DMat3::IDENTITY
        );
    }

    #[test]
    fn area_mean_of_a_uniform_image_is_its_value() {
        for f in [Filter::Bilinear, Filter::Nearest] {
            let m = area_mean(&img(5, 3), f);
            assert!((m - DVec3::ONE).abs().max_element() < 1e-15);
        }
    }

    #[test]
    fn cross_blocks_hold_six_faces() {
        let mut n = 0;
        for row in 0..4 {
            for col in 0..3 {
                n += face_at_block(col, row).is_some() as u32;
            }
        }
        assert_eq!(n, 6);
    }
}
