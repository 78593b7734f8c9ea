//! OpenEXR textures through the `exr` crate: the header checked first (size, compression,
//! channels), then R, G, B (or a lone Y) decoded into linear RGB, sanitised as they are stored.

use std::io::Cursor;
use std::path::Path;

use super::{EnvMap, Image, TextureError, check_size, guarded};

fn compression_name(c: exr::compression::Compression) -> Option<&'static str> {
    use exr::compression::Compression::*;
    // The ones `exr` 1.74 decodes; HTJ2K (and anything newer) is refused by name.
    Some(match c {
        Uncompressed => "none",
        RLE => "rle",
        ZIP1 => "zips",
        ZIP16 => "zip",
        PIZ => "piz",
        PXR24 => "pxr24",
        B44 => "b44",
        B44A => "b44a",
        DWAA(_) => "dwaa",
        DWAB(_) => "dwab",
        _ => return None,
    })
}

pub(super) fn load_exr(path: &Path, bytes: &[u8]) -> Result<Image, TextureError> {
    use exr::prelude::*;
    let exr_err = |source| TextureError::Exr {
        path: path.to_owned(),
        source,
    };
    // Header first: refuse absurd sizes and undecodable compressions before any pixel allocation.
    let meta = guarded(path, || {
        exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(exr_err)
    })?;
    let Some(header) = meta.headers.iter().find(|h| !h.deep) else {
        return Err(TextureError::Unsupported {
            path: path.to_owned(),
            what: "only deep-data parts in this OpenEXR file".into(),
        });
    };
    let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
    check_size(path, w, h)?;
    if compression_name(header.compression).is_none() {
        return Err(TextureError::UnsupportedCompression {
            path: path.to_owned(),
            compression: format!("{:?}", header.compression),
        });
    }
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    if header
        .channels
        .list
        .iter()
        .any(|c| c.sampling != Vec2(1, 1))
    {
        return Err(TextureError::Unsupported {
            path: path.to_owned(),
            what: format!("subsampled channels in {names:?}"),
        });
    }
    let envmap = header.own_attributes.environment_map.map(|e| match e {
        exr::meta::attribute::EnvironmentMap::LatitudeLongitude => EnvMap::LatLong,
        exr::meta::attribute::EnvironmentMap::Cube => EnvMap::Cube,
    });
    let find = |n: &str| names.iter().position(|c| c == n);
    let plan: [usize; 3] = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => [r, g, b],
        (_, _, _, Some(y)) if find("RY").is_none() && find("BY").is_none() => [y, y, y],
        _ => {
            return Err(TextureError::Unsupported {
                path: path.to_owned(),
                what: format!("no R, G, B (or lone Y) channels; found {names:?}"),
            });
        }
    };
    let map_err = |source| match source {
        exr::error::Error::NotSupported(ref what) if what.contains("compression") => {
            TextureError::UnsupportedCompression {
                path: path.to_owned(),
                compression: what.to_string(),
            }
        }
        source => exr_err(source),
    };
    // Negative and NaN samples become 0 as they are stored (Image::sanitize's rule, folded into
    // the decode so that an 8k map is not walked twice).
    // Not `clamp`: f32::clamp keeps NaN, max(0) turns it into 0.
    #[allow(clippy::manual_clamp)]
    let clean = |v: f32| v.max(0.0).min(f32::MAX);
    let (width, height, rgb) = if plan[0] != plan[1] {
        // R, G, B: exr's batched sample conversion straight into the interleaved buffer.
        let image = guarded(path, || {
            read()
                .no_deep_data()
                .largest_resolution_level()
                .specific_channels()
                .required("R")
                .required("G")
                .required("B")
                .collect_pixels(
                    |size: Vec2<usize>, _| (size.0, size.1, vec![[0f32; 3]; size.0 * size.1]),
                    move |px: &mut (usize, usize, Vec<[f32; 3]>),
                          pos: Vec2<usize>,
                          (r, g, b): (f32, f32, f32)| {
                        px.2[pos.1 * px.0 + pos.0] = [clean(r), clean(g), clean(b)];
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(Cursor::new(bytes))
                .map_err(map_err)
        })?;
        image.layer_data.channel_data.pixels
    } else {
        // A lone Y channel.
        let image = guarded(path, || {
            read()
                .no_deep_data()
                .largest_resolution_level()
                .specific_channels()
                .required("Y")
                .collect_pixels(
                    |size: Vec2<usize>, _| (size.0, size.1, vec![[0f32; 3]; size.0 * size.1]),
                    move |px: &mut (usize, usize, Vec<[f32; 3]>),
                          pos: Vec2<usize>,
                          (y,): (f32,)| {
                        px.2[pos.1 * px.0 + pos.0] = [clean(y); 3];
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(Cursor::new(bytes))
                .map_err(map_err)
        })?;
        image.layer_data.channel_data.pixels
    };
    // The decoded layer must be the one whose header we checked.
    if (width as u64, height as u64) != (w, h) || rgb.len() != width * height {
        return Err(TextureError::Unsupported {
            path: path.to_owned(),
            what: "the first decodable layer differs from the first header".into(),
        });
    }
    Ok(self::Image {
        width,
        height,
        rgb,
        envmap,
        source: path.to_owned(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::load;
    use super::super::tests::{attr_value, small_exr, tmp};
    use super::*;

    #[test]
    fn exr_half_zip_float_tiled_and_lone_y_channel() {
        use exr::prelude::*;
        let (_d, p) = tmp("zip.exr");
        std::fs::write(&p, small_exr(8, 4)).unwrap();
        let img = load(&p).unwrap();
        assert_eq!((img.width, img.height), (8, 4));
        assert_eq!(img.texel(4, 3), [1.0, 3.0, 0.5]);
        // A tiled float RGB file with a data window offset from the origin: row 0 = data
        // window min.y.
        let (_d, p) = tmp("tiled.exr");
        let ch = SpecificChannels::rgb(|pos: Vec2<usize>| (pos.0 as f32, pos.1 as f32, 0.5f32));
        let mut layer = Layer::new(
            (5, 3),
            LayerAttributes::named("t"),
            Encoding {
                compression: Compression::PIZ,
                blocks: Blocks::Tiles(Vec2(2, 2)),
                line_order: LineOrder::Increasing,
            },
            ch,
        );
        layer.attributes.layer_position = Vec2(10, -4);
        exr::prelude::Image::from_layer(layer)
            .write()
            .to_file(&p)
            .unwrap();
        let img = load(&p).unwrap();
        assert_eq!((img.width, img.height), (5, 3));
        assert_eq!(img.texel(4, 2), [4.0, 2.0, 0.5]);
        // A lone Y channel is grey.
        let (_d, p) = tmp("grey.exr");
        let ch = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
            "Y",
            FlatSamples::F16(vec![f16::from_f32(0.25); 6]),
        )]));
        exr::prelude::Image::from_layer(Layer::new(
            (3, 2),
            LayerAttributes::named("g"),
            Encoding::UNCOMPRESSED,
            ch,
        ))
        .write()
        .to_file(&p)
        .unwrap();
        let img = load(&p).unwrap();
        assert_eq!(img.rgb, vec![[0.25; 3]; 6]);
    }

    #[test]
    fn an_undecodable_compression_is_a_typed_error_naming_file_and_compression() {
        let mut bytes = small_exr(8, 4);
        // Compression codes: 10 = HTJ2K256 (OpenEXR 3.4), which exr 1.74 does not decode.
        let v = attr_value(&bytes, "compression");
        bytes[v] = 10;
        let (_d, p) = tmp("htj2k.exr");
        std::fs::write(&p, &bytes).unwrap();
        match load(&p) {
            Err(e @ TextureError::UnsupportedCompression { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains("htj2k.exr") && msg.to_lowercase().contains("htj2k"),
                    "{msg}"
                );
            }
            other => panic!("expected UnsupportedCompression, got {other:?}"),
        }
    }
}
