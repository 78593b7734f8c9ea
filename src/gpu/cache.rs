//! The persistent pipeline cache (start-up time): wgpu's `PipelineCache` (a Vulkan
//! `VkPipelineCache`) kept in a file per adapter and driver under the user's cache directory, so
//! that a later process skips the driver's compile where the driver caches.
//!
//! Where: `$LUXEVAL_CACHE_DIR` if set (empty: no cache), else `$XDG_CACHE_HOME/luxeval`, else
//! `$HOME/.cache/luxeval`. The file is named by wgpu's key for the adapter (vendor and device)
//! and luxeval's version; the driver checks its own header (driver version, device UUID) and
//! wgpu its own (validation key, size), and a file that fails either is ignored (`fallback`), so
//! a corrupt, truncated or foreign file costs a compile, never a wrong pipeline.
//!
//! Concurrent processes: each writes the whole cache to a temporary file of its own in the same
//! directory and renames it over the old one (atomic on one file system), so a reader sees one
//! complete file or another, never a mixture; the last writer wins.

use std::path::{Path, PathBuf};

/// Environment variable naming the cache directory (empty: do not cache).
pub const CACHE_DIR_ENV: &str = "LUXEVAL_CACHE_DIR";

/// A cache file larger than this is not read (a driver's cache of our few pipelines is a few
/// MiB at most; anything far larger is not ours).
const MAX_CACHE_BYTES: u64 = 256 << 20;

/// Whether and where the pipelines of this device are cached, as `luxeval info` reports it.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct CacheStatus {
    /// The cache file, when a cache is in use.
    pub path: Option<PathBuf>,
    /// Bytes read from the file when the device was opened (0: none yet, or ignored).
    pub loaded_bytes: u64,
    /// Why no cache is used, when none is.
    pub reason: Option<String>,
}

/// The cache directory from the environment, or why there is none.
fn directory() -> Result<PathBuf, String> {
    match std::env::var_os(CACHE_DIR_ENV) {
        Some(d) if d.is_empty() => Err(format!("disabled ({CACHE_DIR_ENV} is empty)")),
        Some(d) => Ok(PathBuf::from(d)),
        None => match (
            std::env::var_os("XDG_CACHE_HOME").filter(|d| !d.is_empty()),
            std::env::var_os("HOME").filter(|d| !d.is_empty()),
        ) {
            (Some(x), _) => Ok(PathBuf::from(x).join("luxeval")),
            (None, Some(h)) => Ok(PathBuf::from(h).join(".cache").join("luxeval")),
            (None, None) => Err(format!(
                "no cache directory (set {CACHE_DIR_ENV}, XDG_CACHE_HOME or HOME)"
            )),
        },
    }
}

/// The device's pipeline cache, primed from its file; `None` (with the reason in the status)
/// when the adapter or the environment allows none.
pub(crate) fn open(
    device: &wgpu::Device,
    info: &wgpu::AdapterInfo,
) -> (Option<(wgpu::PipelineCache, PathBuf)>, CacheStatus) {
    let none = |reason: String| {
        (
            None,
            CacheStatus {
                path: None,
                loaded_bytes: 0,
                reason: Some(reason),
            },
        )
    };
    if !device.features().contains(wgpu::Features::PIPELINE_CACHE) {
        return none("the adapter offers no pipeline cache".into());
    }
    let Some(key) = wgpu::util::pipeline_cache_key(info) else {
        return none(format!(
            "wgpu keeps no pipeline cache for {:?}",
            info.backend
        ));
    };
    let dir = match directory() {
        Ok(d) => d,
        Err(reason) => return none(reason),
    };
    let path = dir.join(format!("{key}_luxeval_{}.bin", env!("CARGO_PKG_VERSION")));
    let data = read_bounded(&path);
    // SAFETY: wgpu requires the data to come from `PipelineCache::get_data` of a compatible
    // adapter; it and the driver validate their headers and, with `fallback`, ignore data that
    // fails them. A file we did not write (corrupt, truncated, tampered) is the residual risk
    // wgpu documents; it lives in the user's own cache directory.
    let cache = unsafe {
        device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
            label: Some("luxeval pipelines"),
            data: data.as_deref(),
            fallback: true,
        })
    };
    let status = CacheStatus {
        path: Some(path.clone()),
        loaded_bytes: data.as_ref().map_or(0, |d| d.len() as u64),
        reason: None,
    };
    (Some((cache, path)), status)
}

fn read_bounded(path: &Path) -> Option<Vec<u8>> {
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_file() || meta.len() > MAX_CACHE_BYTES {
        return None;
    }
    std::fs::read(path).ok()
}

/// Writes the cache's current data to `path` (temporary file + rename). Failures are logged,
/// not raised: a cache that cannot be saved only costs the next process a compile.
pub(crate) fn save(cache: &wgpu::PipelineCache, path: &Path) {
    let Some(data) = cache.get_data() else { return };
    if let Err(e) = write_atomically(path, &data) {
        log::warn!("pipeline cache {}: not saved: {e}", path.display());
    }
}

fn write_atomically(path: &Path, data: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        path.file_name().and_then(|n| n.to_str()).unwrap_or("cache"),
        std::process::id()
    ));
    let result = std::fs::write(&tmp, data).and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
