//! Every dome and rect texture of a scene packed into one flat `f32` storage buffer for
//! `shaders/shared/dome.wgsl` (`tex_atlas`, binding 6). Ported from the staged crate
//! `luxeval-dome` (`src/atlas.rs`), on the model of [`super::ies_atlas`]: one atlas per scene.
//!
//! Layout: textures one after another; a texture at offset `o` (f32 units, a multiple of 4) is
//! `[width, height, format, 0]` as u32 bit patterns ([`HEADER_WORDS`] words), then
//! `width × height` RGB f32 triplets, row-major, row 0 at the top: texel (i, j) at
//! `o + 4 + 3(j·width + i)`. A light record stores its texture's offset as a u32 (exact, unlike
//! the IES atlas's f32 bases), so the atlas holds at most 2³² − 1 floats; the device's storage
//! binding limit is usually far lower and is checked at upload
//! (`GpuContext::upload`). An atlas without textures uploads one word (a storage binding cannot
//! be empty).
//!
//! Packing computes the layout only and keeps the images shared (`Arc`): the texels are copied
//! once, by the upload, from each image straight to its offset ([`Atlas::chunks`]); a file
//! shared by several domes (the same `Arc`, see `AssetCache::texture`) with the same format is
//! packed once.

use std::sync::Arc;

use crate::prepare::Prepared;
use crate::prepare::dome::{
    CROSS_FACES, FILTER_BILINEAR, FILTER_NEAREST, FORMAT_ANGULAR, FORMAT_CROSS, FORMAT_LATLONG,
    FORMAT_MIRRORED_BALL, FORMAT_RECT, Image,
};

/// Words before a texture's texels.
pub const HEADER_WORDS: usize = 4;

/// Why a texture does not fit the atlas.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("{path}: a {width} × {height} texture does not fit the texture atlas (u32 offsets)")]
pub struct AtlasFull {
    pub path: String,
    pub width: usize,
    pub height: usize,
}

/// One packed texture.
#[derive(Debug, Clone)]
pub struct AtlasEntry {
    /// Offset of the header, in f32 units.
    pub offset: u32,
    /// `[width, height, format, 0]` as f32 bit patterns.
    pub header: [f32; HEADER_WORDS],
    pub image: Arc<Image>,
}

/// The layout of the atlas and the images it holds.
#[derive(Default, Debug, Clone)]
pub struct Atlas {
    pub entries: Vec<AtlasEntry>,
    len: usize,
}

impl Atlas {
    pub fn new() -> Atlas {
        Atlas::default()
    }

    /// Appends `img` with the format code the lookup dispatches on (`FORMAT_*`) and returns its
    /// offset (what a light record gets).
    pub fn push(&mut self, img: Arc<Image>, format: u32) -> Result<u32, AtlasFull> {
        let offset = self.len.next_multiple_of(4);
        let end = offset + HEADER_WORDS + 3 * img.width * img.height;
        if end > u32::MAX as usize {
            return Err(AtlasFull {
                path: img.source.display().to_string(),
                width: img.width,
                height: img.height,
            });
        }
        let header = [img.width as u32, img.height as u32, format, 0].map(f32::from_bits);
        self.entries.push(AtlasEntry {
            offset: offset as u32,
            header,
            image: img,
        });
        self.len = end;
        Ok(offset as u32)
    }

    /// Length of the buffer in f32 units.
    pub fn len(&self) -> usize {
        self.len
    }

    /// What to upload where: (offset in f32 units, data), headers and texels, in order. Gaps
    /// (alignment padding) are never read.
    pub fn chunks(&self) -> impl Iterator<Item = (usize, &[f32])> {
        self.entries.iter().flat_map(|e| {
            let o = e.offset as usize;
            [
                (o, &e.header[..]),
                (o + HEADER_WORDS, e.image.rgb.as_flattened()),
            ]
        })
    }

    /// Writes the whole buffer into `dst` (at least [`Self::len`] floats); padding words are
    /// left as they are.
    #[cfg(test)]
    pub fn write_into(&self, dst: &mut [f32]) {
        for (o, data) in self.chunks() {
            dst[o..o + data.len()].copy_from_slice(data);
        }
    }

    /// The buffer as one vector (tests, CPU replays of the WGSL).
    #[cfg(test)]
    pub fn to_vec(&self) -> Vec<f32> {
        let mut v = vec![0.0; self.len];
        self.write_into(&mut v);
        v
    }
}

/// The `u32` constants `dome.wgsl` uses, by name, for the generated WGSL prelude (DESIGN.md §1:
/// shared constants are generated into the WGSL, never retyped).
pub fn wgsl_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("FORMAT_LATLONG", FORMAT_LATLONG),
        ("FORMAT_MIRRORED_BALL", FORMAT_MIRRORED_BALL),
        ("FORMAT_ANGULAR", FORMAT_ANGULAR),
        ("FORMAT_CROSS", FORMAT_CROSS),
        ("FORMAT_RECT", FORMAT_RECT),
        ("FILTER_BILINEAR", FILTER_BILINEAR),
        ("FILTER_NEAREST", FILTER_NEAREST),
        ("TEX_HEADER_WORDS", HEADER_WORDS as u32),
        ("CROSS_FACE_STRIDE", CROSS_FACE_STRIDE as u32),
    ]
}

/// Floats per face of [`CROSS_FACES`] in the generated `CROSS_FACE_TABLE`: F, R, U, block.
pub const CROSS_FACE_STRIDE: usize = 11;

/// The f32 arrays `dome.wgsl` reads, for the generated prelude: §6 D5's cube-cross table
/// ([`CROSS_FACES`]) flattened face by face as (F, R, U, block column, block row).
pub fn wgsl_f32_arrays() -> Vec<(&'static str, Vec<f64>)> {
    let table = CROSS_FACES
        .iter()
        .flat_map(|(f, r, u, b)| f.iter().chain(r).chain(u).chain(b).copied())
        .collect::<Vec<f64>>();
    debug_assert_eq!(table.len(), 6 * CROSS_FACE_STRIDE);
    vec![("CROSS_FACE_TABLE", table)]
}

/// The atlas of the distinct textures of `lights` (a shared image with the same format is
/// packed once) and, per light, the offset of its texture.
pub fn scene_atlas(lights: &[Prepared]) -> Result<(Atlas, Vec<Option<u32>>), AtlasFull> {
    let mut atlas = Atlas::new();
    let mut packed: Vec<(Arc<Image>, u32, u32)> = Vec::new();
    let mut offsets = Vec::with_capacity(lights.len());
    for p in lights {
        // A dome's texture with its format's code; a rect's with FORMAT_RECT.
        let (image, code) = match (&p.texture, &p.rect_texture) {
            (Some(t), _) => (&t.image, t.format.code()),
            (None, Some(t)) => (&t.image, FORMAT_RECT),
            (None, None) => {
                offsets.push(None);
                continue;
            }
        };
        let found = packed
            .iter()
            .find(|(img, f, _)| Arc::ptr_eq(img, image) && *f == code)
            .map(|e| e.2);
        let offset = match found {
            Some(o) => o,
            None => {
                let o = atlas.push(Arc::clone(image), code)?;
                packed.push((Arc::clone(image), code, o));
                o
            }
        };
        offsets.push(Some(offset));
    }
    Ok((atlas, offsets))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: usize, h: usize, v: f32) -> Arc<Image> {
        Arc::new(Image::from_rgb(w, h, vec![[v, 2.0 * v, 3.0 * v]; w * h], "t.png").unwrap())
    }

    #[test]
    fn textures_follow_their_headers_at_aligned_offsets() {
        let mut a = Atlas::new();
        let o0 = a.push(img(3, 1, 1.0), FORMAT_LATLONG).unwrap();
        let o1 = a.push(img(2, 2, 5.0), FORMAT_CROSS).unwrap();
        assert_eq!((o0, o1), (0, 16));
        let v = a.to_vec();
        assert_eq!(v.len(), 16 + 4 + 12);
        assert_eq!(v[16].to_bits(), 2);
        assert_eq!(v[17].to_bits(), 2);
        assert_eq!(v[18].to_bits(), FORMAT_CROSS);
        assert_eq!(&v[4..7], &[1.0, 2.0, 3.0]);
        assert_eq!(&v[20..23], &[5.0, 10.0, 15.0]);
    }
}
