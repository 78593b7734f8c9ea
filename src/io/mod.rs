//! File input and output shared by the CLI and library users: `.npy` arrays, and writes that
//! never leave a partial file behind.

pub mod npy;

use std::io::Write;
use std::path::Path;

use crate::error::{LuxError, Result};

/// Writes `path` atomically: the bytes go to a temporary file in the same directory, which is
/// renamed over `path` only once everything was written and flushed. On any error nothing is
/// left at `path` (an existing file there is untouched).
///
/// Errors: a path where no file can be created (no such directory, no permission, a directory
/// in the way) is [`LuxError::Io`], bad input; a failure while writing (disk full, I/O error)
/// is [`LuxError::Write`], a runtime failure.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let io_err = |source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    };
    let write_err = |source| LuxError::Write {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".luxeval-").suffix(".part");
    // An output file, not a secret: the mode a plain create would give (0666 less the umask),
    // rather than tempfile's private 0600.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(io_err)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut w).map_err(write_err)?;
        w.flush().map_err(write_err)?;
    }
    tmp.as_file().sync_all().map_err(write_err)?;
    tmp.persist(path).map_err(|e| io_err(e.error))?;
    Ok(())
}
