//! The command line's files: `.npy` arrays streamed in and out, falloff maps as EXR, writes that
//! never leave a partial file behind, and the check that no output names an input.

pub mod exr;
pub mod npy;
pub mod npz;

use std::io::Write;
use std::path::Path;

use luxeval::{Limits, LuxError, Result};

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
    let mut tmp = temp_beside(path)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut w).map_err(write_err)?;
        w.flush().map_err(write_err)?;
    }
    tmp.as_file().sync_all().map_err(write_err)?;
    tmp.persist(path).map_err(|e| io_err(e.error))?;
    Ok(())
}

/// A new temporary file in the directory of `path` (so that it can be renamed over `path`),
/// named `.luxeval-*.part`, removed when dropped. No file can be created there:
/// [`LuxError::Io`].
pub fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
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
    builder.tempfile_in(dir).map_err(|source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Where a path leads, for comparing spellings: the file's identity (device and inode) when it
/// exists, else its canonical directory joined with its name.
#[derive(Debug, PartialEq, Eq)]
enum Identity {
    #[cfg(unix)]
    Inode(u64, u64),
    Path(std::path::PathBuf),
}

fn identity(path: &Path) -> Option<Identity> {
    if let Ok(meta) = std::fs::metadata(path) {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            return Some(Identity::Inode(meta.dev(), meta.ino()));
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            return std::fs::canonicalize(path).ok().map(Identity::Path);
        }
    }
    let name = path.file_name()?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::canonicalize(dir)
        .ok()
        .map(|d| Identity::Path(d.join(name)))
}

/// Refuses outputs that would destroy an input or each other, before anything is read or
/// written (DESIGN.md §4): an output that is one of `inputs` by any spelling (`..`, a symbolic
/// or hard link: the same file), two outputs that are the same file, and an output that exists
/// but is not a regular file (a directory, a device such as `/dev/null`, a pipe), which an
/// atomic replace would destroy or could not replace. `outputs` and `inputs` are
/// `(option name, path)` pairs, named in the message.
pub fn check_outputs(outputs: &[(&str, &Path)], inputs: &[(&str, &Path)]) -> Result<()> {
    for (k, (oname, out)) in outputs.iter().enumerate() {
        if let Ok(meta) = std::fs::metadata(out)
            && !meta.is_file()
        {
            return Err(LuxError::input(
                format!("{oname} {}", out.display()),
                "exists and is not a regular file (outputs are written to a temporary file \
                 and renamed over the path, which would replace it)",
            ));
        }
        let Some(id) = identity(out) else { continue };
        for (iname, input) in inputs {
            if identity(input).as_ref() == Some(&id) {
                return Err(LuxError::input(
                    format!("{oname} {}", out.display()),
                    format!(
                        "is the input {iname} {} (the same file); writing it would destroy the input",
                        input.display()
                    ),
                ));
            }
        }
        for (other_name, other) in &outputs[..k] {
            if identity(other).as_ref() == Some(&id) {
                return Err(LuxError::input(
                    format!("{oname} {}", out.display()),
                    format!(
                        "is also the output {other_name} {}; give each output its own file",
                        other.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Reads a whole input file, refusing more than [`Limits::max_file_bytes`] (also from a pipe or
/// a device, which is never read further than that), a directory and a character or block
/// device (`/dev/zero` would be read to the limit for nothing). For readers of assets (IES
/// profiles, textures) that need the bytes in memory.
pub fn read_limited(path: &Path) -> Result<Vec<u8>> {
    let limits = Limits::from_env()?;
    let io_err = |source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io_err)?;
    let meta = file.metadata().map_err(io_err)?;
    check_input_kind(path, &meta)?;
    let too_big = |len: u64| LuxError::Format {
        path: path.to_path_buf(),
        line: None,
        reason: format!(
            "{len} bytes exceed the limit of {} bytes ({})",
            limits.max_file_bytes,
            Limits::raise_hint(Limits::ENV_MAX_FILE_BYTES)
        ),
    };
    if meta.len() > limits.max_file_bytes {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::new();
    use std::io::Read;
    file.take(limits.max_file_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(io_err)?;
    if bytes.len() as u64 > limits.max_file_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Refuses a directory or a device as an input file.
pub fn check_input_kind(path: &Path, meta: &std::fs::Metadata) -> Result<()> {
    let kind = if meta.is_dir() {
        Some("a directory")
    } else {
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            let t = meta.file_type();
            (t.is_char_device() || t.is_block_device()).then_some("a device")
        }
        #[cfg(not(unix))]
        None
    };
    match kind {
        Some(kind) => Err(LuxError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("is {kind}, not a file"),
            ),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_that_are_inputs_by_any_spelling_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.npy");
        std::fs::write(&a, b"x").unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let dotted = dir.path().join("sub/../a.npy");
        let fresh = dir.path().join("b.npy");
        assert!(check_outputs(&[("-o", &fresh)], &[("--dirs", &a)]).is_ok());
        let e = check_outputs(&[("-o", &dotted)], &[("--dirs", &a)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("--dirs") && e.contains("-o"), "{e}");
        #[cfg(unix)]
        {
            let link = dir.path().join("link.npy");
            std::os::unix::fs::symlink(&a, &link).unwrap();
            assert!(check_outputs(&[("-o", &link)], &[("--dirs", &a)]).is_err());
            let hard = dir.path().join("hard.npy");
            std::fs::hard_link(&a, &hard).unwrap();
            assert!(check_outputs(&[("-o", &hard)], &[("--dirs", &a)]).is_err());
        }
        // Two outputs that do not exist yet but are one path.
        let e = check_outputs(
            &[("-o", &fresh), ("--png", &dir.path().join("sub/../b.npy"))],
            &[],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("--png") && e.contains("-o"), "{e}");
        // A directory in the way.
        let e = check_outputs(&[("-o", &dir.path().join("sub"))], &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
}
