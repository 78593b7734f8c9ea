//! Falloff maps as arrays (DESIGN.md §4 `falloff`): the summed irradiance over a rectangle of a
//! plane, pixel by pixel. The command line writes them as EXR and false-colour PNG; Python
//! returns them as an (H, W, 3) array.
//!
//! The plane is the parallelogram `origin + s·u + t·v`, s, t ∈ [0, 1]; the receiver normal is
//! `normalize(u × v)`, so the map shows the plane as seen from the side its normal points to,
//! with `u` to the right and `v` up. Pixel (column i, row j), row 0 at the top of the image, is
//! evaluated at its centre: `origin + (i + ½)/W·u + (1 − (j + ½)/H)·v`.

use glam::DVec3;

use crate::error::{LuxError, Result};
use crate::query::{Accumulate, PreparedScene};

/// The most pixels one map may have (memory for points, normals and results stays < 4 GiB).
const MAX_PIXELS: u64 = 1 << 27;

/// A rectangle of a plane sampled at pixel centres.
#[derive(Clone, Debug, PartialEq)]
pub struct FalloffPlane {
    /// The corner at the image's bottom-left.
    pub origin: DVec3,
    /// The image's horizontal edge (left to right).
    pub u: DVec3,
    /// The image's vertical edge (bottom to top).
    pub v: DVec3,
    pub width: u32,
    pub height: u32,
}

impl FalloffPlane {
    /// The most pixels one map may have (memory for points, normals and results stays < 4 GiB).
    pub const MAX_PIXELS: u64 = MAX_PIXELS;

    /// Validates the plane: finite vectors, u and v not parallel, 1 ≤ pixels ≤ [`FalloffPlane::MAX_PIXELS`].
    pub fn new(origin: DVec3, u: DVec3, v: DVec3, width: u32, height: u32) -> Result<Self> {
        for (name, x) in [("--origin", origin), ("--u", u), ("--v", v)] {
            if !x.is_finite() {
                return Err(LuxError::input(name, format!("{x} is not finite")));
            }
        }
        if !(u.cross(v).length() > 0.0) {
            return Err(LuxError::input(
                "--u/--v",
                format!("u = {u} and v = {v} are parallel or zero: they span no plane"),
            ));
        }
        if width == 0 || height == 0 || width as u64 * height as u64 > MAX_PIXELS {
            return Err(LuxError::input(
                "--res",
                format!("{width}×{height}: need 1 to {MAX_PIXELS} pixels"),
            ));
        }
        Ok(FalloffPlane {
            origin,
            u,
            v,
            width,
            height,
        })
    }

    /// The receiver normal, `normalize(u × v)`.
    pub fn normal(&self) -> DVec3 {
        self.u.cross(self.v).normalize()
    }

    /// The centre of pixel (column i, row j), row 0 at the top.
    pub fn pixel_centre(&self, i: u32, j: u32) -> DVec3 {
        let s = (i as f64 + 0.5) / self.width as f64;
        let t = 1.0 - (j as f64 + 0.5) / self.height as f64;
        self.origin + s * self.u + t * self.v
    }

    /// Every pixel centre, row-major from the top row.
    pub fn points(&self) -> Vec<[f32; 3]> {
        (0..self.height)
            .flat_map(|j| (0..self.width).map(move |i| (j, i)))
            .map(|(j, i)| self.pixel_centre(i, j).as_vec3().to_array())
            .collect()
    }

    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

/// An evaluated map: linear RGB irradiance (lux for lights in nits), row-major from the top row.
#[derive(Clone, Debug, PartialEq)]
pub struct FalloffMap {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[f32; 3]>,
}

impl FalloffMap {
    /// Rec.709 luminance of each pixel: the photometric value the PNG shows.
    pub fn luminance(&self) -> Vec<f64> {
        self.rgb
            .iter()
            .map(|c| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64)
            .collect()
    }
}

/// Pixels evaluated per call (in whole image rows), so that progress can be reported and the
/// points and normals of one band are all the input held; the map itself is held whole, for
/// the EXR and PNG writers (docs/INPUTS.md "Streaming").
const BLOCK_PIXELS: usize = 1 << 16;

impl PreparedScene {
    /// The summed irradiance of the prepared lights over `plane`, in blocks of rows (the
    /// scene's buffers are reused from block to block); `progress(done, total)` is called after
    /// each block (pixels).
    pub fn falloff(
        &self,
        plane: &FalloffPlane,
        mut progress: impl FnMut(usize, usize),
    ) -> Result<FalloffMap> {
        let scene = self;
        let n = plane.normal().as_vec3().to_array();
        let total = plane.pixels();
        let rows_per_block = (BLOCK_PIXELS / plane.width as usize).max(1) as u32;
        let mut rgb = Vec::with_capacity(total);
        let mut j0 = 0;
        while j0 < plane.height {
            let j1 = (j0 + rows_per_block).min(plane.height);
            let points: Vec<[f32; 3]> = (j0..j1)
                .flat_map(|j| (0..plane.width).map(move |i| (i, j)))
                .map(|(i, j)| plane.pixel_centre(i, j).as_vec3().to_array())
                .collect();
            let normals = vec![n; points.len()];
            rgb.extend(scene.irradiance(&points, &normals, Accumulate::Sum)?);
            progress(rgb.len(), total);
            j0 = j1;
        }
        Ok(FalloffMap {
            width: plane.width,
            height: plane.height,
            rgb,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_centres_and_normal() {
        // The luxtest top camera's floor: x right, −Z up the image, normal +Y.
        let half = 6.2865;
        let p = FalloffPlane::new(
            DVec3::new(-half, 0.0, half),
            DVec3::X * 2.0 * half,
            DVec3::NEG_Z * 2.0 * half,
            512,
            512,
        )
        .unwrap();
        assert!((p.normal() - DVec3::Y).length() < 1e-15);
        // Column i → x = (2(i+0.5)/512 − 1)·6.2865; row j (top = 0) → z = (2(j+0.5)/512 − 1)·6.2865.
        let c = p.pixel_centre(0, 0);
        assert!((c.x - (1.0 / 512.0 - 1.0) * half).abs() < 1e-12);
        assert!((c.z - (1.0 / 512.0 - 1.0) * half).abs() < 1e-12);
        let c = p.pixel_centre(511, 511);
        assert!(
            (c.x - (1.0 - 1.0 / 512.0) * half).abs() < 1e-12
                && (c.z - (1.0 - 1.0 / 512.0) * half).abs() < 1e-12
        );
        assert_eq!(p.points().len(), 512 * 512);
        assert!(FalloffPlane::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0, 4, 4).is_err());
        assert!(FalloffPlane::new(DVec3::ZERO, DVec3::X, DVec3::Y, 0, 4).is_err());
    }
}
