//! File input and output shared by the CLI and library users: `.npy` arrays, and writes that
//! never leave a partial file behind.

pub mod npy;

use std::io::Write;
use std::path::Path;

use crate::error::{LuxError, Result};

/// Writes `path` atomically: the bytes go to a temporary file in the same directory, which is
/// renamed over `path` only once everything was written and flushed. On any error nothing is
/// left at `path` (an existing file there is untouched).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let io_err = |source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".luxeval-")
        .suffix(".part")
        .tempfile_in(dir)
        .map_err(io_err)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut w).map_err(io_err)?;
        w.flush().map_err(io_err)?;
    }
    tmp.as_file().sync_all().map_err(io_err)?;
    tmp.persist(path).map_err(|e| io_err(e.error))?;
    Ok(())
}
