//! Loading the files lights reference, once per prepared scene: a profile referenced by several
//! lights is read, parsed and packed once.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use super::ies::Profile;
use crate::assets::ies::parse_any;
use crate::assets::package;
use crate::assets::texture::{self, Image};
use crate::error::AssetError;
use crate::model::Asset;

/// Profiles and textures already loaded, by resolved path (or by address for in-memory
/// contents), with the files each one read.
#[derive(Default)]
pub struct AssetCache {
    profiles: HashMap<String, Arc<Profile>>,
    textures: HashMap<String, Arc<Image>>,
    /// The files on disk each asset read (itself or its package; a profile's TILT file too):
    /// what a command must never write over (DESIGN.md §4).
    files: HashMap<String, Vec<PathBuf>>,
}

/// The cache key of `asset`: its resolved path, or the address of contents given in memory.
fn key(asset: &Asset) -> Result<String, AssetError> {
    match (&asset.bytes, &asset.resolved) {
        (Some(b), _) => Ok(format!("<bytes {:p}>", b.as_ptr())),
        (None, Some(r)) => Ok(r.clone()),
        (None, None) => Err(AssetError::Unresolved),
    }
}

impl AssetCache {
    /// The files on disk `asset` was read from, once loaded (none for contents in memory).
    pub fn files(&self, asset: &Asset) -> Vec<PathBuf> {
        key(asset)
            .ok()
            .and_then(|k| self.files.get(&k).cloned())
            .unwrap_or_default()
    }

    /// The texture in `asset` (OpenEXR, PNG, JPEG or Radiance HDR, detected by content; also
    /// inside a `.usdz` package), decoded to linear RGB once per file.
    pub fn texture(&mut self, asset: &Asset) -> Result<Arc<Image>, AssetError> {
        let key = key(asset)?;
        if let Some(t) = self.textures.get(&key) {
            return Ok(t.clone());
        }
        let name = std::path::PathBuf::from(asset.display());
        let image = match (&asset.bytes, &asset.resolved) {
            (Some(b), _) => texture::decode(b, &name)?,
            (None, Some(r)) => {
                let bytes = package::read(r).map_err(|source| AssetError::Io {
                    path: r.clone(),
                    source,
                })?;
                self.files
                    .insert(key.clone(), vec![package::file_of(r).to_path_buf()]);
                texture::decode(&bytes, &name)?
            }
            (None, None) => return Err(AssetError::Unresolved),
        };
        let image = Arc::new(image);
        self.textures.insert(key, image.clone());
        Ok(image)
    }

    /// The IES profile in `asset` (LM-63 or EULUMDAT, detected by content; a `TILT=<file>` is
    /// read beside it, also inside a package).
    pub fn ies(&mut self, asset: &Asset) -> Result<Arc<Profile>, AssetError> {
        let key = match (&asset.bytes, &asset.resolved) {
            (Some(b), _) => format!("<bytes {:p}>", b.as_ptr()),
            (None, Some(r)) => r.clone(),
            (None, None) => return Err(AssetError::Unresolved),
        };
        if let Some(p) = self.profiles.get(&key) {
            return Ok(p.clone());
        }
        let bytes: Vec<u8> = match (&asset.bytes, &asset.resolved) {
            (Some(b), _) => b.to_vec(),
            (None, Some(r)) => package::read(r).map_err(|source| AssetError::Io {
                path: r.clone(),
                source,
            })?,
            (None, None) => return Err(AssetError::Unresolved),
        };
        let here = asset.display().to_string();
        let read = RefCell::new(
            asset
                .resolved
                .iter()
                .filter(|_| asset.bytes.is_none())
                .map(|r| package::file_of(r).to_path_buf())
                .collect::<Vec<_>>(),
        );
        let resolver = |name: &str| -> Result<Vec<u8>, String> {
            match &asset.resolved {
                Some(r) => {
                    let path = package::sibling(r, name);
                    let bytes = package::read(&path).map_err(|e| format!("{path}: {e}"))?;
                    read.borrow_mut()
                        .push(package::file_of(&path).to_path_buf());
                    Ok(bytes)
                }
                None => Err(format!(
                    "TILT={name}: {here} was given in memory, so no file beside it can be read"
                )),
            }
        };
        let profile = parse_any(&bytes, &resolver)
            .and_then(|f| Profile::new(&f))
            .map_err(|mut e| {
                e.file.get_or_insert(here.clone());
                e
            })?;
        let profile = Arc::new(profile);
        self.files.insert(key.clone(), read.take());
        self.profiles.insert(key, profile.clone());
        Ok(profile)
    }
}
