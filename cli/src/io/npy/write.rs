//! Writing float32 `.npy` outputs: [`write_f32`] for a whole array, the streaming [`Writer`]
//! for rows written at their offsets as they come; both atomic.

use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use npyz::WriterBuilder;

use luxeval::{LuxError, Result};

use crate::io::write_atomic;

/// Writes float32 RGB rows with the given shape (the product of `shape` must be `3·rows`),
/// atomically.
pub fn write_f32(path: &Path, shape: &[u64], rows: &[[f32; 3]]) -> Result<()> {
    let expected = shape.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
    if expected != Some(rows.len() as u64 * 3) {
        return Err(LuxError::input(
            path.display().to_string(),
            format!("shape {shape:?} does not hold {} RGB rows", rows.len()),
        ));
    }
    write_atomic(path, |w| {
        let mut writer = npyz::WriteOptions::new()
            .default_dtype()
            .shape(shape)
            .writer(w)
            .begin_nd()?;
        for r in rows {
            writer.extend(r.iter().copied())?;
        }
        writer.finish()
    })
}

/// A streaming writer of a float32 array of rows of 3 (shape (N, 3) or (L, N, 3)), atomic like
/// [`write_atomic`]: the header goes to a temporary file beside `path` when it is created, rows
/// are written at their offsets as they come (in any order; each row once), and
/// [`Writer::finish`] renames the file over `path` once every row was written, flushed and
/// synced. Dropped unfinished (on any error), the temporary file is removed and `path` is left
/// as it was. The bytes are those [`write_f32`] writes for the same array.
pub struct Writer {
    path: PathBuf,
    tmp: tempfile::NamedTempFile,
    /// Where row 0 starts: the header's length.
    data: u64,
    /// The rows the shape holds.
    rows: u64,
    written: u64,
    /// Where the file's cursor is, to seek only when rows are not written in order.
    pos: u64,
    /// The bytes of the last write, kept to be reused.
    bytes: Vec<u8>,
}

impl Writer {
    /// Creates the temporary file and writes the header of a float32 array of `shape` (whose
    /// last entry must be 3). Errors as [`write_atomic`]'s: no file can be created there is
    /// [`LuxError::Io`], a failing write [`LuxError::Write`].
    pub fn create(path: &Path, shape: &[u64]) -> Result<Writer> {
        let rows = match shape.split_last() {
            Some((3, rest)) => rest.iter().try_fold(1u64, |a, &d| a.checked_mul(d)),
            _ => None,
        }
        .filter(|r| r.checked_mul(12).is_some())
        .ok_or_else(|| {
            LuxError::input(
                path.display().to_string(),
                format!("shape {shape:?} is not an array of RGB rows"),
            )
        })?;
        // npyz writes the header, so that the bytes are exactly those of `write_f32`.
        let mut header = Vec::new();
        npyz::WriteOptions::<f32>::new()
            .default_dtype()
            .shape(shape)
            .writer(&mut header)
            .write_header_only()
            .map_err(|source| LuxError::Write {
                path: path.to_path_buf(),
                source,
            })?;
        let mut tmp = crate::io::temp_beside(path)?;
        let mut w = Writer {
            path: path.to_path_buf(),
            data: header.len() as u64,
            rows,
            written: 0,
            pos: 0,
            bytes: Vec::new(),
            tmp: {
                tmp.as_file_mut()
                    .write_all(&header)
                    .map_err(|source| LuxError::Write {
                        path: path.to_path_buf(),
                        source,
                    })?;
                tmp
            },
        };
        w.pos = w.data;
        Ok(w)
    }

    /// The rows the array holds (the product of the shape but its last entry).
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Writes `rows` as rows `at`, `at + 1`, … of the array (flat index: with shape (L, N, 3),
    /// row `l·N + i` is light `l`, sample `i`).
    pub fn write_rows(&mut self, at: u64, rows: &[[f32; 3]]) -> Result<()> {
        if at
            .checked_add(rows.len() as u64)
            .is_none_or(|end| end > self.rows)
        {
            return Err(LuxError::input(
                self.path.display().to_string(),
                format!(
                    "rows {at}.. ({} of them) lie outside the {} rows of the output",
                    rows.len(),
                    self.rows
                ),
            ));
        }
        self.bytes.clear();
        self.bytes.reserve(rows.len() * 12);
        for v in rows.iter().flatten() {
            self.bytes.extend_from_slice(&v.to_le_bytes());
        }
        let write_err = |source| LuxError::Write {
            path: self.path.clone(),
            source,
        };
        let offset = self.data + at * 12;
        let file = self.tmp.as_file_mut();
        if offset != self.pos {
            file.seek(SeekFrom::Start(offset)).map_err(write_err)?;
        }
        file.write_all(&self.bytes).map_err(write_err)?;
        self.pos = offset + self.bytes.len() as u64;
        self.written += rows.len() as u64;
        Ok(())
    }

    /// Syncs the file and renames it over the output path, once every row was written.
    pub fn finish(self) -> Result<()> {
        if self.written != self.rows {
            return Err(LuxError::input(
                self.path.display().to_string(),
                format!(
                    "{} rows were written of the {} the output holds",
                    self.written, self.rows
                ),
            ));
        }
        self.tmp
            .as_file()
            .sync_all()
            .map_err(|source| LuxError::Write {
                path: self.path.clone(),
                source,
            })?;
        self.tmp.persist(&self.path).map_err(|e| LuxError::Io {
            path: self.path.clone(),
            source: e.error,
        })?;
        Ok(())
    }
}
