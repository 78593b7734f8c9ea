//! Every dome and rect texture of a scene packed into one flat `f32` storage buffer for
//! `shaders/shared/texture.wgsl` (`tex_atlas`, binding 6), on the model of [`super::ies_atlas`]:
//! one atlas per scene.
//!
//! Layout: textures one after another; a texture at offset `o` (f32 units, a multiple of 4) is
//! `[width, height, format, 0]` as u32 bit patterns ([`HEADER_WORDS`] words), then
//! `width × height` RGB f32 triplets, row-major, row 0 at the top: texel (i, j) at
//! `o + 4 + 3(j·width + i)`. After every texture, room for the row tables of each textured latlong
//! dome whose irradiance the device integrates (`prepare::latlong_rows`, read by
//! `shaders/irradiance/latlong_rows.wgsl`), built and written only by the scene's first
//! irradiance call ([`RowTables`]; the sampling kernels' copy of the atlas stops before
//! them, [`Atlas::textures_len`]). A light record stores its texture's offset as a u32 (exact, unlike
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
use crate::prepare::env_table::EnvTable;
use crate::prepare::latlong_rows;
use crate::prepare::texture::Filter;
use crate::prepare::texture::{
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
    /// Row tables of textured latlong domes whose irradiance the device integrates
    /// (`prepare::latlong_rows`), after every texture: reserved, not built.
    pub rows: Vec<RowTables>,
    len: usize,
    /// Where the textures end (the sampling kernels copy only them, `gpu::sample`).
    textures_len: usize,
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
        self.textures_len = end;
        Ok(offset as u32)
    }

    /// Reserves room for the row tables of `image` read through `filter` (after every
    /// texture: push them last) and returns their offset (a record's `tex.z`).
    pub fn push_rows(&mut self, image: Arc<Image>, filter: Filter) -> Result<u32, AtlasFull> {
        let offset = self.len.next_multiple_of(4);
        let end = offset + latlong_rows::words_len(image.width, image.height);
        if end > u32::MAX as usize {
            return Err(AtlasFull {
                path: image.source.display().to_string(),
                width: image.width,
                height: image.height,
            });
        }
        self.rows.push(RowTables {
            offset: offset as u32,
            image,
            filter,
        });
        self.len = end;
        Ok(offset as u32)
    }

    /// Length of the buffer in f32 units.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Length of the textures' part (the row tables follow it).
    pub fn textures_len(&self) -> usize {
        self.textures_len
    }

    /// What to upload where: (offset in f32 units, data), headers and texels, in order (the
    /// row tables are written later, [`RowTables`]). Gaps (alignment padding) are never read.
    pub fn chunks(&self) -> impl Iterator<Item = (usize, &[f32])> {
        self.entries.iter().flat_map(|e| {
            let o = e.offset as usize;
            [
                (o, &e.header[..]),
                (o + HEADER_WORDS, e.image.rgb.as_flattened()),
            ]
        })
    }

    /// Writes the whole buffer into `dst` (at least [`Self::len`] floats), the row tables
    /// built; padding words are left as they are.
    #[cfg(test)]
    pub fn write_into(&self, dst: &mut [f32]) {
        for (o, data) in self.chunks() {
            dst[o..o + data.len()].copy_from_slice(data);
        }
        for t in &self.rows {
            let (o, words) = (t.offset as usize, t.words());
            dst[o..o + words.len()].copy_from_slice(&words);
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

/// A latlong dome's row tables as the atlas reserves them: where they go and what they are
/// built from. They take four times the texture's memory (403 MB for 4096 × 2048) and only the
/// irradiance kernel reads them, so they are built and written by the scene's first irradiance
/// call (`GpuLights::write_row_tables`), never for a scene asked only for emission, radiance,
/// intensity or samples.
#[derive(Debug, Clone)]
pub struct RowTables {
    /// Offset in f32 units.
    pub offset: u32,
    pub image: Arc<Image>,
    pub filter: Filter,
}

impl RowTables {
    /// The tables as the device reads them (`prepare::latlong_rows::device_words`; the device's
    /// copy is written in pieces, `GpuLights::write_row_tables`).
    #[cfg(test)]
    pub fn words(&self) -> Vec<f32> {
        latlong_rows::device_words(&self.image, self.filter)
    }
}

/// The `u32` constants `texture.wgsl` uses, by name, for the generated WGSL prelude (DESIGN.md §1:
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
        ("ENV_HEADER_WORDS", ENV_HEADER_WORDS as u32),
        ("ENV_TEXEL_WORDS", ENV_TEXEL_WORDS as u32),
        ("ENV_TILE_WORDS", ENV_TILE_WORDS as u32),
        ("ENV_INNER_WORDS", ENV_INNER_WORDS as u32),
        ("ENV_NO_INNER", ENV_NO_INNER),
        (
            "LATLONG_ROWS_HEADER_WORDS",
            latlong_rows::HEADER_WORDS as u32,
        ),
        ("LATLONG_ROWS_ENTRY_WORDS", latlong_rows::ENTRY_WORDS as u32),
    ]
}

/// The `f32` constants the sampling kernels read, for the generated prelude: the receiver tiles'
/// floor (`prepare::env_table::HORIZON_FLOOR`).
pub fn wgsl_f32_constants() -> Vec<(&'static str, f64)> {
    vec![("HORIZON_FLOOR", crate::prepare::env_table::HORIZON_FLOOR)]
}

/// Words of an environment table's header ([`env_table_words`]).
pub const ENV_HEADER_WORDS: usize = 20;
/// Words per texel of an environment table: keep threshold, alias, pmf.
pub const ENV_TEXEL_WORDS: usize = 3;
/// Words per tile: `W_t`, the cap's centre (3), `cos r`, `sin r`, its inner table's offset, 0.
pub const ENV_TILE_WORDS: usize = 8;
/// Words per texel of a tile's inner table: keep threshold, local alias.
pub const ENV_INNER_WORDS: usize = 2;
/// The inner-table offset of a tile of weight 0 (never drawn).
pub const ENV_NO_INNER: u32 = u32::MAX;

/// A textured dome's sampling table (`prepare::env_table::EnvTable`) as the sample and pdf
/// kernels read it (`shaders/sample/env_table.wgsl`), to be placed at atlas offset `base` (a
/// multiple of 4; the inner tables' offsets are absolute). u32 values are stored as their bit
/// patterns. Layout, in f32 words from `base`:
/// - header ([`ENV_HEADER_WORDS`]): width, height, format code, tile side, tiles per row, tile
///   count (u32; 0 tiles for a table without them), `|det A|`, 0, then `A_eff`'s columns (dome →
///   world, 9 floats), 0, 0, 0. The table's size is the file's even where the GPU holds the
///   texture reduced (`scene_atlas`): the sampler is the reference's;
/// - per texel k ([`ENV_TEXEL_WORDS`]): the alias cell's keep threshold
///   (`AliasTable::keep_threshold`), its alias, `pmf(k)`;
/// - per tile ([`ENV_TILE_WORDS`]): `W_t`, the cap's centre, `cos r`, `sin r`, the absolute
///   offset of its inner table ([`ENV_NO_INNER`] for none), 0;
/// - the tiles' inner tables in tile order, per local texel ([`ENV_INNER_WORDS`]): keep
///   threshold, local alias. A texel's probability within its tile is `pmf(k) / W_t`, as the
///   inner table was built from.
pub fn env_table_words(t: &EnvTable, base: u32) -> Vec<f32> {
    let n = t.width as usize * t.height as usize;
    let tl = &t.tiles;
    let tiles = tl.inner.len();
    let bits = f32::from_bits;
    let a = t.frame.a_eff;
    let mut v: Vec<f32> = vec![
        bits(t.width),
        bits(t.height),
        bits(t.format.code()),
        bits(tl.side),
        bits(tl.nx),
        bits(tiles as u32),
        t.frame.det_abs as f32,
        0.0,
    ];
    v.extend(
        [a.x_axis, a.y_axis, a.z_axis]
            .iter()
            .flat_map(|c| [c.x as f32, c.y as f32, c.z as f32]),
    );
    v.extend([0.0; 3]);
    debug_assert_eq!(v.len(), ENV_HEADER_WORDS);
    v.reserve(n * (ENV_TEXEL_WORDS + ENV_INNER_WORDS) + tiles * ENV_TILE_WORDS);
    for k in 0..n {
        v.extend([
            bits(t.table.keep_threshold(k)),
            bits(t.table.alias(k)),
            t.table.pmf(k) as f32,
        ]);
    }
    let mut inner_at = base as usize + v.len() + tiles * ENV_TILE_WORDS;
    for (i, inner) in tl.inner.iter().enumerate() {
        let (c, r) = tl.cap[i];
        let (sin_r, cos_r) = r.sin_cos();
        let at = match inner {
            Some(inner) => {
                let at = inner_at as u32;
                inner_at += inner.len() * ENV_INNER_WORDS;
                at
            }
            None => ENV_NO_INNER,
        };
        v.extend([
            tl.weight[i] as f32,
            c.x as f32,
            c.y as f32,
            c.z as f32,
            cos_r as f32,
            sin_r as f32,
            bits(at),
            0.0,
        ]);
    }
    for inner in tl.inner.iter().flatten() {
        for k in 0..inner.len() {
            v.extend([bits(inner.keep_threshold(k)), bits(inner.alias(k))]);
        }
    }
    debug_assert_eq!(base as usize + v.len(), inner_at);
    v
}

/// Floats per face of [`CROSS_FACES`] in the generated `CROSS_FACE_TABLE`: F, R, U, block.
pub const CROSS_FACE_STRIDE: usize = 11;

/// The f32 arrays `texture.wgsl` reads, for the generated prelude: §6 D5's cube-cross table
/// ([`CROSS_FACES`]) flattened face by face as (F, R, U, block column, block row).
pub fn wgsl_f32_arrays() -> Vec<(&'static str, Vec<f64>)> {
    let table = CROSS_FACES
        .iter()
        .flat_map(|(f, r, u, b)| f.iter().chain(r).chain(u).chain(b).copied())
        .collect::<Vec<f64>>();
    debug_assert_eq!(table.len(), 6 * CROSS_FACE_STRIDE);
    vec![("CROSS_FACE_TABLE", table)]
}

/// The atlas, each light's offsets in it, and the textures reduced to fit.
pub type SceneAtlas = (Atlas, Vec<Option<LightTex>>, Vec<Reduced>);

/// Where a light's texture, and a textured latlong dome's row tables, lie in the atlas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightTex {
    pub texture: u32,
    /// Present for a dome whose irradiance the device integrates
    /// (`prepare::Prepared::irradiance_on_host` false).
    pub rows: Option<u32>,
}

/// A texture the GPU holds at a lower resolution than the file (see [`scene_atlas`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reduced {
    pub path: String,
    pub from: (usize, usize),
    pub to: (usize, usize),
}

/// The atlas of the distinct textures of `lights` (a shared image with the same format is
/// packed once), per light the offset of its texture, and the textures reduced to fit.
///
/// When the atlas would exceed `limit_bytes` (the device's storage binding limit), the largest
/// reducible texture is halved in both axes by a 2 × 2 box average, again until the atlas fits
/// (DESIGN.md §6: a texture over the adapter's limit is tiled or reduced with a warning that
/// says which). A texture is reducible when both sizes are even and, for a cube cross, the face
/// size too (boxes never straddle faces); a latlong stays 2:1. Halving is what a mip level is:
/// each reduced texel is the mean of the four it covers. The CPU reference always reads the
/// full texture, so the GPU's values for a reduced texture differ from it by design.
pub fn scene_atlas(lights: &[Prepared], limit_bytes: u64) -> Result<SceneAtlas, AtlasFull> {
    // The distinct (image, format) pairs, and each light's index into them.
    let mut distinct: Vec<(Arc<Image>, u32)> = Vec::new();
    let mut which = Vec::with_capacity(lights.len());
    // The distinct (image, filter) pairs of the domes whose irradiance the device integrates
    // (their row tables, prepare::latlong_rows), and each light's index into them.
    let mut row_tables: Vec<(Arc<Image>, Filter)> = Vec::new();
    let mut which_rows = Vec::with_capacity(lights.len());
    for p in lights {
        which_rows.push(match p.dome_texture() {
            Some(t) if !p.irradiance_on_host() => {
                let found = row_tables
                    .iter()
                    .position(|(img, f)| Arc::ptr_eq(img, &t.image) && *f == t.filter);
                Some(found.unwrap_or_else(|| {
                    row_tables.push((Arc::clone(&t.image), t.filter));
                    row_tables.len() - 1
                }))
            }
            _ => None,
        });
        // A dome's texture with its format's code; a rect's with FORMAT_RECT.
        let (image, code) = match (p.dome_texture(), p.rect_texture()) {
            (Some(t), _) => (&t.image, t.format.code()),
            (None, Some(t)) => (&t.image, FORMAT_RECT),
            (None, None) => {
                which.push(None);
                continue;
            }
        };
        let k = match distinct
            .iter()
            .position(|(img, f)| Arc::ptr_eq(img, image) && *f == code)
        {
            Some(k) => k,
            None => {
                distinct.push((Arc::clone(image), code));
                distinct.len() - 1
            }
        };
        which.push(Some(k));
    }
    // The row tables are exact and never reduced; the textures make room for them.
    let rows_words: usize = row_tables
        .iter()
        .map(|(img, _)| latlong_rows::words_len(img.width, img.height) + 3)
        .sum();
    let reduced = fit(&mut distinct, limit_bytes, rows_words);
    let mut atlas = Atlas::new();
    let offsets: Vec<u32> = distinct
        .iter()
        .map(|(img, code)| atlas.push(Arc::clone(img), *code))
        .collect::<Result<_, _>>()?;
    let rows_offsets: Vec<u32> = row_tables
        .iter()
        .map(|(img, filter)| atlas.push_rows(Arc::clone(img), *filter))
        .collect::<Result<_, _>>()?;
    let per_light = which
        .into_iter()
        .zip(which_rows)
        .map(|(k, r)| {
            k.map(|k| LightTex {
                texture: offsets[k],
                rows: r.map(|r| rows_offsets[r]),
            })
        })
        .collect();
    Ok((atlas, per_light, reduced))
}

/// Why a dome [`tables_beyond`] names takes its irradiance from the CPU reference.
pub const TABLES_BEYOND: &str = "it is a textured latlong dome whose row tables do not fit this \
     device's storage binding limit beside the scene's textures";

/// The lights whose latlong row tables (`prepare::latlong_rows`: four times their texture's
/// size, never halved) this device cannot hold: the scene's distinct textures, each at its
/// smallest (halved as far as [`fit`] can halve it), and its distinct tables must fit
/// `limit_bytes` together, and the largest tables are left out first until the rest do. Those
/// domes take their irradiance from the CPU reference on this device ([`TABLES_BEYOND`];
/// `query::PreparedScene` sets their `gpu_path` before [`scene_atlas`] packs the tables that
/// fit). The limit is the device's, known once it is open, which is why this is not decided
/// in `prepare` with the rest of `prepare::latlong_rows::gpu_path`.
pub fn tables_beyond(lights: &[Prepared], limit_bytes: u64) -> Vec<usize> {
    let mut textures: Vec<(*const Image, u32)> = Vec::new();
    let mut texture_words = 0usize;
    // (image, filter, words, the lights that read them)
    let mut tables: Vec<(*const Image, Filter, usize, Vec<usize>)> = Vec::new();
    for (k, p) in lights.iter().enumerate() {
        let (image, code) = match (p.dome_texture(), p.rect_texture()) {
            (Some(t), _) => (&t.image, t.format.code()),
            (None, Some(t)) => (&t.image, FORMAT_RECT),
            (None, None) => continue,
        };
        if !textures.contains(&(Arc::as_ptr(image), code)) {
            textures.push((Arc::as_ptr(image), code));
            let (mut w, mut h) = (image.width, image.height);
            while reducible_size(w, h, code) {
                (w, h) = (w / 2, h / 2);
            }
            // 3: the most alignment padding before it.
            texture_words += 3 + HEADER_WORDS + 3 * w * h;
        }
        if let Some(t) = p.dome_texture().filter(|_| !p.irradiance_on_host()) {
            let key = (Arc::as_ptr(&t.image), t.filter);
            match tables.iter_mut().find(|e| (e.0, e.1) == key) {
                Some(e) => e.3.push(k),
                None => tables.push((
                    key.0,
                    key.1,
                    3 + latlong_rows::words_len(t.image.width, t.image.height),
                    vec![k],
                )),
            }
        }
    }
    let words: Vec<usize> = tables.iter().map(|e| e.2).collect();
    let mut beyond: Vec<usize> = left_out(texture_words, &words, limit_bytes)
        .into_iter()
        .flat_map(|i| tables[i].3.iter().copied())
        .collect();
    beyond.sort_unstable();
    beyond
}

/// Which of the tables of `table_words` words to leave out, largest first, until the rest and
/// `texture_words` fit `limit_bytes`.
fn left_out(texture_words: usize, table_words: &[usize], limit_bytes: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..table_words.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(table_words[i]));
    let mut total = texture_words + table_words.iter().sum::<usize>();
    let mut out = Vec::new();
    for i in order {
        if (total as u64).saturating_mul(4) <= limit_bytes {
            break;
        }
        total -= table_words[i];
        out.push(i);
    }
    out
}

/// Halves the largest reducible texture of `distinct` until the packed atlas, with
/// `extra_words` of row tables after it, needs at most `limit_bytes` (or none is reducible);
/// returns what was reduced (see [`scene_atlas`]).
fn fit(distinct: &mut [(Arc<Image>, u32)], limit_bytes: u64, extra_words: usize) -> Vec<Reduced> {
    let words = |d: &[(Arc<Image>, u32)]| {
        d.iter().fold(extra_words, |n, (img, _)| {
            n.next_multiple_of(4) + HEADER_WORDS + 3 * img.width * img.height
        })
    };
    let mut reduced: Vec<Reduced> = Vec::new();
    // Tables that alone exceed the limit: nothing to gain from halving (the upload refuses).
    if (extra_words as u64).saturating_mul(4) > limit_bytes {
        return reduced;
    }
    while (words(distinct) as u64).saturating_mul(4) > limit_bytes {
        let largest = distinct
            .iter()
            .enumerate()
            .filter(|(_, (img, code))| reducible(img, *code))
            .max_by_key(|(_, (img, _))| img.width * img.height)
            .map(|(k, _)| k);
        let Some(k) = largest else { break };
        let (img, code) = &distinct[k];
        let half = Arc::new(halve(img));
        let path = img.source.display().to_string();
        match reduced.iter_mut().find(|r| r.path == path) {
            Some(r) => r.to = (half.width, half.height),
            None => reduced.push(Reduced {
                path,
                from: (img.width, img.height),
                to: (half.width, half.height),
            }),
        }
        distinct[k] = (half, *code);
    }
    reduced
}

/// Whether [`halve`] keeps `img`'s format: even sizes, and an even face size for a cross.
fn reducible(img: &Image, code: u32) -> bool {
    reducible_size(img.width, img.height, code)
}

/// [`reducible`] of a `width × height` texture.
fn reducible_size(width: usize, height: usize, code: u32) -> bool {
    let even = width.is_multiple_of(2) && height.is_multiple_of(2) && width >= 2 && height >= 2;
    even && (code != FORMAT_CROSS || (width / 3).is_multiple_of(2))
}

/// `img` at half the resolution: each texel the mean of the 2 × 2 texels it covers.
fn halve(img: &Image) -> Image {
    let (w, h) = (img.width / 2, img.height / 2);
    let mut rgb = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            let t = |di: usize, dj: usize| img.rgb[(2 * j + dj) * img.width + 2 * i + di];
            let (a, b, c, d) = (t(0, 0), t(1, 0), t(0, 1), t(1, 1));
            rgb.push(std::array::from_fn(|k| 0.25 * (a[k] + b[k] + c[k] + d[k])));
        }
    }
    Image {
        width: w,
        height: h,
        rgb,
        envmap: img.envmap,
        source: img.source.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: usize, h: usize, v: f32) -> Arc<Image> {
        Arc::new(Image::from_rgb(w, h, vec![[v, 2.0 * v, 3.0 * v]; w * h], "t.png").unwrap())
    }

    #[test]
    fn textures_over_the_limit_are_halved_until_they_fit() {
        // A 16 × 8 latlong of distinct texels, a 6 × 8 cross (N = 2, even) and an odd 3 × 3.
        let lat = Arc::new(
            Image::from_rgb(
                16,
                8,
                (0..128).map(|k| [k as f32, 1.0, 2.0]).collect(),
                "lat.exr",
            )
            .unwrap(),
        );
        let mut d = vec![
            (lat.clone(), FORMAT_LATLONG),
            (img(6, 8, 1.0), FORMAT_CROSS),
            (img(3, 3, 1.0), FORMAT_ANGULAR),
        ];
        let words = |d: &[(Arc<Image>, u32)]| {
            d.iter().fold(0usize, |n, (i, _)| {
                n.next_multiple_of(4) + HEADER_WORDS + 3 * i.width * i.height
            })
        };
        // Room for everything: nothing reduced.
        let all = 4 * words(&d) as u64;
        assert!(fit(&mut d, all, 0).is_empty());
        // One word short: the largest reducible texture (the latlong) is halved once.
        let r = fit(&mut d, all - 4, 0);
        assert_eq!(
            r,
            vec![Reduced {
                path: "lat.exr".into(),
                from: (16, 8),
                to: (8, 4)
            }]
        );
        // Each reduced texel is the mean of the 2 × 2 it covers: texel (i, j) of the original is
        // 16j + i, so reduced (1, 1) averages 34, 35, 50, 51.
        assert_eq!(d[0].0.rgb[8 + 1], [42.5, 1.0, 2.0]);
        // Far too little room: the 6 × 8 cross (N = 2) halves to 3 × 4 (N = 1, not halvable
        // again), the latlong down to 2 × 1; the odd 3 × 3 is never touched.
        let r = fit(&mut d, 4, 0);
        let sizes: Vec<(usize, usize)> = d.iter().map(|(i, _)| (i.width, i.height)).collect();
        assert_eq!(sizes, [(2, 1), (3, 4), (3, 3)]);
        assert_eq!(r.len(), 2, "{r:?}");
    }

    /// Tables are left out largest first, only until the rest fit beside the textures; none
    /// when all fit; all when the textures alone do not.
    #[test]
    fn the_largest_tables_are_left_out_until_the_rest_fit() {
        let tables = [300, 1000, 200, 1000];
        assert!(left_out(100, &tables, 4 * 2600).is_empty());
        assert_eq!(left_out(100, &tables, 4 * 2599), vec![1]);
        assert_eq!(left_out(100, &tables, 4 * 1600), vec![1]);
        assert_eq!(left_out(100, &tables, 4 * 1599), vec![1, 3]);
        assert_eq!(left_out(100, &tables, 4 * 300), vec![1, 3, 0]);
        assert_eq!(left_out(100, &tables, 4 * 100), vec![1, 3, 0, 2]);
        assert_eq!(left_out(100, &tables, 4 * 99), vec![1, 3, 0, 2]);
        assert!(left_out(100, &[], 0).is_empty());
    }

    /// Row tables after the textures count toward the limit (the textures are halved to make
    /// room for them); tables that alone exceed it halve nothing.
    #[test]
    fn row_tables_are_made_room_for_and_never_halved() {
        let mut d = vec![(img(16, 8, 1.0), FORMAT_LATLONG)];
        let texture = 4 * (HEADER_WORDS + 3 * 16 * 8) as u64;
        assert!(fit(&mut d, texture + 400, 100).is_empty());
        let r = fit(&mut d, texture + 400, 101);
        assert_eq!(r.len(), 1);
        assert_eq!((d[0].0.width, d[0].0.height), (8, 4));
        let mut d = vec![(img(16, 8, 1.0), FORMAT_LATLONG)];
        assert!(fit(&mut d, 400, 101).is_empty());
        assert_eq!((d[0].0.width, d[0].0.height), (16, 8));
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
