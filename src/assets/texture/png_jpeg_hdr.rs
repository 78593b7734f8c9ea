//! PNG, JPEG and Radiance `.hdr` textures through the `image` crate: 8/16-bit sRGB values
//! decoded to linear with §6's formula (lookup tables), `.hdr` kept as linear float.

use std::io::Cursor;
use std::path::Path;
use std::sync::OnceLock;

use super::{Image, TextureError, check_size, guarded};

/// §6: `c = value / 255` (or `/ 65535`); linear `= c / 12.92` for `c ≤ 0.04045`, else
/// `((c + 0.055) / 1.055)^2.4`. Evaluated in f64, rounded once to f32.
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn lut8() -> &'static [f32; 256] {
    static T: OnceLock<[f32; 256]> = OnceLock::new();
    T.get_or_init(|| std::array::from_fn(|v| srgb_to_linear(v as f64 / 255.0) as f32))
}

fn lut16() -> &'static [f32] {
    static T: OnceLock<Vec<f32>> = OnceLock::new();
    T.get_or_init(|| {
        (0..65536)
            .map(|v| srgb_to_linear(v as f64 / 65535.0) as f32)
            .collect()
    })
}

pub(super) fn load_ldr_or_hdr(path: &Path, bytes: &[u8]) -> Result<Image, TextureError> {
    use image::{DynamicImage, ImageReader, Limits};
    let dec_err = |source| TextureError::Decode {
        path: path.to_owned(),
        source,
    };
    let reader = || {
        ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|source| TextureError::Io {
                path: path.to_owned(),
                source,
            })
    };
    let (w, h) = guarded(path, || reader()?.into_dimensions().map_err(dec_err))?;
    check_size(path, w as u64, h as u64)?;
    let mut limits = Limits::default();
    limits.max_image_width = Some(w);
    limits.max_image_height = Some(h);
    // The decoded buffer (at most 4 × 16-bit or 4 × f32 per pixel) plus the decoders' scratch.
    limits.max_alloc = Some((w as u64 * h as u64 * 16).saturating_add(1 << 26));
    let img = guarded(path, || {
        let mut r = reader()?;
        r.limits(limits);
        r.decode().map_err(dec_err)
    })?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let l8 = lut8();
    let rgb: Vec<[f32; 3]> = match &img {
        DynamicImage::ImageLuma8(b) => b.pixels().map(|p| [l8[p[0] as usize]; 3]).collect(),
        DynamicImage::ImageLumaA8(b) => b.pixels().map(|p| [l8[p[0] as usize]; 3]).collect(),
        DynamicImage::ImageRgb8(b) => b.pixels().map(|p| p.0.map(|v| l8[v as usize])).collect(),
        DynamicImage::ImageRgba8(b) => b
            .pixels()
            .map(|p| [0, 1, 2].map(|k| l8[p[k] as usize]))
            .collect(),
        DynamicImage::ImageLuma16(b) => b.pixels().map(|p| [lut16()[p[0] as usize]; 3]).collect(),
        DynamicImage::ImageLumaA16(b) => b.pixels().map(|p| [lut16()[p[0] as usize]; 3]).collect(),
        DynamicImage::ImageRgb16(b) => b
            .pixels()
            .map(|p| p.0.map(|v| lut16()[v as usize]))
            .collect(),
        DynamicImage::ImageRgba16(b) => b
            .pixels()
            .map(|p| [0, 1, 2].map(|k| lut16()[p[k] as usize]))
            .collect(),
        // Radiance HDR decodes to linear float.
        DynamicImage::ImageRgb32F(b) => b.pixels().map(|p| p.0).collect(),
        DynamicImage::ImageRgba32F(b) => b.pixels().map(|p| [p[0], p[1], p[2]]).collect(),
        other => {
            return Err(TextureError::Unsupported {
                path: path.to_owned(),
                what: format!("pixel layout {:?}", other.color()),
            });
        }
    };
    if rgb.len() != width * height {
        return Err(TextureError::Unsupported {
            path: path.to_owned(),
            what: "decoded size differs from the header".into(),
        });
    }
    Ok(Image {
        width,
        height,
        rgb,
        envmap: None,
        source: path.to_owned(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::load;
    use super::super::tests::tmp;
    use super::*;

    #[test]
    fn srgb_decoding_is_the_pinned_piecewise_formula() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-15);
        assert!((srgb_to_linear(0.04045) - 0.04045 / 12.92).abs() < 1e-18);
        assert!((srgb_to_linear(0.5) - ((0.5 + 0.055) / 1.055f64).powf(2.4)).abs() < 1e-15);
        assert_eq!(lut8()[255], 1.0);
        assert_eq!(lut16()[65535], 1.0);
    }

    #[test]
    fn png_8_and_16_bit_decode_to_linear_rows_from_the_top() {
        let (_d, p) = tmp("a.png");
        let mut img = image::RgbImage::new(3, 2);
        img.put_pixel(2, 0, image::Rgb([255, 128, 0]));
        img.save(&p).unwrap();
        let t = load(&p).unwrap();
        assert_eq!((t.width, t.height, t.envmap), (3, 2, None));
        let half = srgb_to_linear(128.0 / 255.0) as f32;
        assert_eq!(t.texel(2, 0), [1.0, half, 0.0]);
        assert_eq!(t.texel(0, 1), [0.0; 3]);
        let (_d2, p16) = tmp("b.png");
        let mut g = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::new(2, 1);
        g.put_pixel(1, 0, image::Luma([65535]));
        g.save(&p16).unwrap();
        let t = load(&p16).unwrap();
        assert_eq!(t.rgb, vec![[0.0; 3], [1.0; 3]]);
    }
}
