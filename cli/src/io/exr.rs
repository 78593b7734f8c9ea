//! Falloff maps as OpenEXR files: linear float R, G, B, written atomically.

use std::path::Path;

use luxeval::{FalloffMap, LuxError, Result};

use super::write_atomic;

/// Writes the map as a scanline EXR with linear float R, G, B channels (ZIP compressed),
/// atomically.
pub fn write_exr(path: &Path, map: &FalloffMap, comment: &str) -> Result<()> {
    use exr::prelude::*;
    let (w, h) = (map.width as usize, map.height as usize);
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let c = map.rgb[y * w + x];
        (c[0], c[1], c[2])
    });
    let mut attributes = LayerAttributes::named("irradiance");
    attributes.comments = Some(Text::from(comment));
    attributes.software_name = Some(Text::from(concat!("luxeval ", env!("CARGO_PKG_VERSION"))));
    let layer = Layer::new((w, h), attributes, Encoding::SMALL_LOSSLESS, channels);
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| LuxError::Write {
            path: path.to_path_buf(),
            source: std::io::Error::other(format!("encoding EXR: {e}")),
        })?;
    write_atomic(path, |f| f.write_all(bytes.get_ref()))
}

/// Reads an RGB(A) EXR back as a map (used by tests and tools; alpha is dropped).
pub fn read_exr(path: &Path) -> Result<FalloffMap> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![[0f32; 3]; resolution.width() * resolution.height()],
            )
        },
        |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b]
        },
    )
    .map_err(|e| LuxError::Format {
        path: path.to_path_buf(),
        line: None,
        reason: format!("reading EXR: {e}"),
    })?;
    let size = image.layer_data.size;
    Ok(FalloffMap {
        width: size.width() as u32,
        height: size.height() as u32,
        rgb: image.layer_data.channel_data.pixels.1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.exr");
        let map = FalloffMap {
            width: 3,
            height: 2,
            rgb: (0..6)
                .map(|i| [i as f32, 0.5 * i as f32, 1e-3 * i as f32])
                .collect(),
        };
        write_exr(&path, &map, "test").unwrap();
        assert_eq!(read_exr(&path).unwrap(), map);
    }
}
