//! Texture files → linear RGB `f32` images (DESIGN.md §6 "RectLight texture", last bullet, and
//! §6 D1 "Texel grid")
//!
//! - OpenEXR (half, float or uint samples; scanline or tiled; every compression the `exr` crate
//!   decodes, which since 1.74 includes DWAA/DWAB): linear as stored, read through the **data
//!   window** (the display window is ignored), row 0 = data window min.y = top. RGB from the
//!   channels `R`, `G`, `B`; a lone `Y` channel is grey; alpha and any other channel are ignored.
//!   The largest resolution level of a mip/rip-mapped file is used.
//! - PNG (8/16-bit), JPEG: sRGB-encoded, decoded with §6's exact piecewise formula; alpha, gAMA
//!   and iCCP are ignored. Radiance `.hdr`: linear float.
//! - The EXR `envmap` attribute is reported (§6 D6 `automatic` reads it).
//!
//! Robustness: every error names the file and keeps its cause. A file whose declared size exceeds
//! [`MAX_PIXELS`] is refused from its header, before any pixel buffer is allocated. The third-party
//! decoders are additionally run under `catch_unwind`, so that a decoder bug reached by a corrupt
//! file becomes [`TextureError::DecoderPanic`] instead of aborting the caller.

mod openexr;
mod png_jpeg_hdr;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// Largest accepted image: 2^28 pixels (16384 × 16384; a 16k × 8k latlong fits). At 12 bytes per
/// linear RGB texel that is 3 GiB, the most a texture may claim before we refuse it.
pub const MAX_PIXELS: u64 = 1 << 28;

/// The EXR `envmap` attribute (OpenEXR `Envmap`), used by `automatic` (§6 D6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvMap {
    /// `ENVMAP_LATLONG`.
    LatLong,
    /// `ENVMAP_CUBE` (six faces stacked vertically; not a UsdLux format).
    Cube,
}

/// A decoded texture: linear RGB, row-major, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    /// `width × height` texels; texel `(i, j)` (column i, row j) is `rgb[j * width + i]`.
    pub rgb: Vec<[f32; 3]>,
    /// The EXR `envmap` attribute when the file has one.
    pub envmap: Option<EnvMap>,
    /// The file it came from (for error messages downstream).
    pub source: PathBuf,
}

/// Why a texture could not be loaded. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    #[error("{}: cannot read the file: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: unsupported OpenEXR compression `{compression}` (this reader decodes none, rle, zip, zips, piz, pxr24, b44, b44a, dwaa, dwab)", path.display())]
    UnsupportedCompression { path: PathBuf, compression: String },
    #[error("{}: malformed or truncated OpenEXR file: {source}", path.display())]
    Exr {
        path: PathBuf,
        source: exr::error::Error,
    },
    #[error("{}: cannot decode the image: {source}", path.display())]
    Decode {
        path: PathBuf,
        source: image::ImageError,
    },
    #[error("{}: declared size {width} × {height} is over the limit of {max} pixels", path.display(), max = MAX_PIXELS)]
    TooLarge {
        path: PathBuf,
        width: u64,
        height: u64,
    },
    #[error("{}: the image is empty ({width} × {height})", path.display())]
    Empty {
        path: PathBuf,
        width: u64,
        height: u64,
    },
    #[error("{}: {what}", path.display())]
    Unsupported { path: PathBuf, what: String },
    #[error("{}: the decoder failed on this file ({message})", path.display())]
    DecoderPanic { path: PathBuf, message: String },
}

impl Image {
    /// The texel at column `i`, row `j` (no bounds policy: callers apply the format's rule).
    #[inline]
    pub fn texel(&self, i: usize, j: usize) -> [f32; 3] {
        self.rgb[j * self.width + i]
    }

    /// Makes every texel a finite non-negative radiance: negative values and NaN become 0, +∞
    /// becomes `f32::MAX`. Returns how many components changed. [`load`] applies it: lossy
    /// compressions leave tiny negatives (Blender's DWAB studio lights go down to −3.4e-4 where
    /// the true value is 0), and a negative radiance would make irradiance negative.
    pub fn sanitize(&mut self) -> usize {
        let mut changed = 0;
        for c in self.rgb.iter_mut().flat_map(|p| p.iter_mut()) {
            let v = if c.is_nan() || *c < 0.0 {
                0.0
            } else {
                c.min(f32::MAX)
            };
            if v.to_bits() != c.to_bits() {
                changed += 1;
                *c = v;
            }
        }
        changed
    }

    #[cfg(test)]
    /// An image from raw linear texels (tests and generated data). `rgb.len()` must equal
    /// `width × height`, both non-zero.
    pub fn from_rgb(
        width: usize,
        height: usize,
        rgb: Vec<[f32; 3]>,
        source: impl Into<PathBuf>,
    ) -> Result<Image, TextureError> {
        let path = source.into();
        if width == 0 || height == 0 || rgb.len() != width * height {
            return Err(TextureError::Unsupported {
                path,
                what: format!("{} texels for a {width} × {height} image", rgb.len()),
            });
        }
        Ok(Image {
            width,
            height,
            rgb,
            envmap: None,
            source: path,
        })
    }
}

#[cfg(test)]
/// Loads any supported texture file. OpenEXR is recognised by its magic number, everything else
/// goes to the `image` decoders (PNG, JPEG, Radiance HDR, recognised from their content).
/// Texels are then [`Image::sanitize`]d (negatives and NaN → 0).
pub fn load(path: &Path) -> Result<Image, TextureError> {
    let bytes = std::fs::read(path).map_err(|source| TextureError::Io {
        path: path.to_owned(),
        source,
    })?;
    decode(&bytes, path)
}

/// [`load`] for contents already read (a file inside a `.usdz` package, or bytes given in
/// memory); `source` is what errors and [`Image::source`] call it.
pub fn decode(bytes: &[u8], source: &Path) -> Result<Image, TextureError> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        // Sanitised while decoding.
        openexr::load_exr(source, bytes)
    } else {
        let mut img = png_jpeg_hdr::load_ldr_or_hdr(source, bytes)?;
        img.sanitize();
        Ok(img)
    }
}

fn check_size(path: &Path, width: u64, height: u64) -> Result<(), TextureError> {
    if width == 0 || height == 0 {
        return Err(TextureError::Empty {
            path: path.to_owned(),
            width,
            height,
        });
    }
    if width.saturating_mul(height) > MAX_PIXELS {
        return Err(TextureError::TooLarge {
            path: path.to_owned(),
            width,
            height,
        });
    }
    Ok(())
}

/// Runs a third-party decoder, turning a panic into a typed error (see the module docs).
fn guarded<T>(path: &Path, f: impl FnOnce() -> Result<T, TextureError>) -> Result<T, TextureError> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic".into());
            Err(TextureError::DecoderPanic {
                path: path.to_owned(),
                message,
            })
        }
    }
}

/// A format that does not fit the file (exit 2 in the CLI, §6 D5/D6). Names the file.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum FormatError {
    #[error(
        "{}: texture:format automatic cannot tell the layout of a {width} × {height} image (latlong needs W = 2H, cubeMapVerticalCross 4W = 3H, angular W = H)",
        path.display()
    )]
    Ambiguous {
        path: PathBuf,
        width: usize,
        height: usize,
    },
    #[error(
        "{}: the EXR envmap attribute says ENVMAP_CUBE (six faces stacked in a strip), which is not a UsdLux format",
        path.display()
    )]
    EnvmapCube { path: PathBuf },
    #[error(
        "{}: cubeMapVerticalCross needs W = 3N and H = 4N; the image is {width} × {height}",
        path.display()
    )]
    BadCross {
        path: PathBuf,
        width: usize,
        height: usize,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    pub(super) fn tmp(name: &str) -> (tempfile::TempDir, PathBuf) {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join(name);
        (d, p)
    }

    fn crc32(data: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in data {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    /// A small ZIP-compressed half RGB EXR, as the Blender `*_zip_half.exr` copies are.
    pub(super) fn small_exr(w: usize, h: usize) -> Vec<u8> {
        use exr::prelude::*;
        let ch = SpecificChannels::rgb(|pos: Vec2<usize>| {
            (
                f16::from_f32(pos.0 as f32 * 0.25),
                f16::from_f32(pos.1 as f32),
                f16::from_f32(0.5),
            )
        });
        let layer = Layer::new(
            (w, h),
            LayerAttributes::named("t"),
            Encoding::SMALL_LOSSLESS,
            ch,
        );
        let mut out = Cursor::new(Vec::new());
        exr::prelude::Image::from_layer(layer)
            .write()
            .to_buffered(&mut out)
            .unwrap();
        out.into_inner()
    }

    /// Byte offset of an attribute's value in an EXR header.
    pub(super) fn attr_value(bytes: &[u8], name: &str) -> usize {
        let key = [name.as_bytes(), &[0]].concat();
        let at = bytes
            .windows(key.len())
            .position(|w| w == key.as_slice())
            .expect("attribute");
        let ty_end = at
            + key.len()
            + bytes[at + key.len()..]
                .iter()
                .position(|&b| b == 0)
                .unwrap()
            + 1;
        ty_end + 4
    }

    fn assert_error_names(p: &Path) {
        match load(p) {
            Ok(i) => panic!("{} loaded as {}×{}", p.display(), i.width, i.height),
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.contains(&p.display().to_string()), "{msg}");
            }
        }
    }

    #[test]
    fn an_absurd_declared_size_is_refused_before_decoding() {
        let mut bytes = small_exr(8, 4);
        // dataWindow is box2i (xMin, yMin, xMax, yMax): claim 100000 × 100000 pixels.
        let v = attr_value(&bytes, "dataWindow");
        bytes[v + 8..v + 12].copy_from_slice(&99_999i32.to_le_bytes());
        bytes[v + 12..v + 16].copy_from_slice(&99_999i32.to_le_bytes());
        let (_d, p) = tmp("huge.exr");
        std::fs::write(&p, &bytes).unwrap();
        match load(&p) {
            Err(TextureError::TooLarge {
                width,
                height,
                path,
            }) => {
                assert_eq!((width, height), (100_000, 100_000));
                assert_eq!(path, p);
                assert!(width * height > MAX_PIXELS);
            }
            other => panic!("expected TooLarge, got {other:?}"),
        }
        // The same for a PNG header (IHDR width/height, CRC fixed up).
        let (_d, png) = tmp("small.png");
        image::RgbImage::new(4, 4).save(&png).unwrap();
        let mut b = std::fs::read(&png).unwrap();
        b[16..20].copy_from_slice(&40_000u32.to_be_bytes());
        b[20..24].copy_from_slice(&40_000u32.to_be_bytes());
        let crc = crc32(&b[12..29]);
        b[29..33].copy_from_slice(&crc.to_be_bytes());
        std::fs::write(&png, &b).unwrap();
        assert!(matches!(load(&png), Err(TextureError::TooLarge { .. })));
    }

    #[test]
    fn truncated_and_corrupt_files_are_errors_not_panics() {
        let exr = small_exr(64, 32);
        let d = tempfile::tempdir().unwrap();
        for (k, cut) in [exr.len() / 2, 400, 40, 3].into_iter().enumerate() {
            let p = d.path().join(format!("cut{k}.exr"));
            std::fs::write(&p, &exr[..cut.min(exr.len() - 1)]).unwrap();
            assert_error_names(&p);
        }
        // PNG: truncated, and garbage with a PNG signature.
        let png = d.path().join("ok.png");
        image::RgbImage::from_fn(16, 16, |x, y| image::Rgb([x as u8 * 9, y as u8 * 7, 3]))
            .save(&png)
            .unwrap();
        let png = std::fs::read(&png).unwrap();
        let p = d.path().join("cut.png");
        std::fs::write(&p, &png[..png.len() / 2]).unwrap();
        assert_error_names(&p);
        let p = d.path().join("garbage.png");
        std::fs::write(&p, [&png[..8], &[0xAB; 200][..]].concat()).unwrap();
        assert_error_names(&p);
        // Not an image at all, and a missing file.
        let p = d.path().join("text.hdr");
        std::fs::write(&p, b"hello").unwrap();
        assert_error_names(&p);
        assert_error_names(&d.path().join("does-not-exist.exr"));
    }

    #[test]
    fn sanitize_clamps_negatives_and_nan() {
        let mut img = Image::from_rgb(
            2,
            1,
            vec![[-3.4e-4, f32::NAN, 1.0], [f32::INFINITY, 0.5, 0.0]],
            "x",
        )
        .unwrap();
        assert_eq!(img.sanitize(), 3);
        assert_eq!(img.rgb, vec![[0.0, 0.0, 1.0], [f32::MAX, 0.5, 0.0]]);
        assert!(Image::from_rgb(2, 2, vec![[0.0; 3]; 3], "y").is_err());
    }
}
