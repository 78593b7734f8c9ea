//! Writing `.npz` outputs (`luxeval sample`): NumPy's zip of `.npy` arrays, stored
//! uncompressed as `numpy.savez` writes them. Rows are streamed: each array's data goes to its
//! own anonymous temporary file as it comes (in order), and [`NpzWriter::finish`] copies them
//! into the zip, which is written beside the output and renamed over it, so that memory stays
//! bounded and nothing is left at the output on any error. [`FlatNpy`] does the same for one
//! float32 `.npy` of light rows (`luxeval pdf --per-light`).

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use luxeval::{LuxError, Result};

/// The element types the outputs use.
#[derive(Clone, Copy)]
pub enum Dtype {
    F32,
    I32,
}

impl Dtype {
    fn descr(self) -> &'static str {
        match self {
            Dtype::F32 => "<f4",
            Dtype::I32 => "<i4",
        }
    }
}

/// The bytes of one array (or one light's row) as they come: an anonymous temporary file,
/// appended to in order and copied out once.
struct Spool {
    data: BufWriter<File>,
    bytes: u64,
}

impl Spool {
    fn new(path: &Path) -> Result<Spool> {
        let file = tempfile::tempfile().map_err(|source| LuxError::Write {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Spool {
            data: BufWriter::new(file),
            bytes: 0,
        })
    }

    /// Appends 4-byte little-endian values.
    fn append<const N: usize>(
        &mut self,
        values: impl Iterator<Item = [u8; N]>,
    ) -> std::io::Result<()> {
        let mut buf = Vec::new();
        values.for_each(|v| buf.extend_from_slice(&v));
        self.bytes += buf.len() as u64;
        self.data.write_all(&buf)
    }

    /// Copies everything appended into `w`.
    fn copy_into(self, w: &mut dyn Write) -> std::io::Result<()> {
        let mut file = self.data.into_inner().map_err(|e| e.into_error())?;
        file.seek(SeekFrom::Start(0))?;
        std::io::copy(&mut file, w)?;
        Ok(())
    }
}

struct Array {
    name: String,
    dtype: Dtype,
    shape: Vec<u64>,
    spool: Spool,
}

/// A streaming `.npz` writer (module docs).
pub struct NpzWriter {
    path: PathBuf,
    arrays: Vec<Array>,
}

/// The `.npy` version 1.0 header of an array (NumPy's format: magic, version, a little-endian
/// u16 header length, a Python dict literal padded with spaces and a newline to a multiple of
/// 64 bytes).
fn npy_header(dtype: Dtype, shape: &[u64]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let mut dict = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}",
        dtype.descr()
    );
    let unpadded = 10 + dict.len() + 1;
    dict.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    dict.push('\n');
    let mut h = b"\x93NUMPY\x01\x00".to_vec();
    h.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    h.extend_from_slice(dict.as_bytes());
    h
}

impl NpzWriter {
    pub fn new(path: &Path) -> NpzWriter {
        NpzWriter {
            path: path.to_path_buf(),
            arrays: Vec::new(),
        }
    }

    fn write_err(&self, source: std::io::Error) -> LuxError {
        LuxError::Write {
            path: self.path.clone(),
            source,
        }
    }

    /// Adds an array; its rows are appended with [`NpzWriter::append_f32`] /
    /// [`NpzWriter::append_i32`] in order. Returns its index.
    pub fn add(&mut self, name: &str, dtype: Dtype, shape: &[u64]) -> Result<usize> {
        self.arrays.push(Array {
            name: name.to_string(),
            dtype,
            shape: shape.to_vec(),
            spool: Spool::new(&self.path)?,
        });
        Ok(self.arrays.len() - 1)
    }

    pub fn append_f32(&mut self, array: usize, values: &[f32]) -> Result<()> {
        let r = self.arrays[array]
            .spool
            .append(values.iter().map(|v| v.to_le_bytes()));
        r.map_err(|e| self.write_err(e))
    }

    pub fn append_i32(&mut self, array: usize, values: &[i32]) -> Result<()> {
        let r = self.arrays[array]
            .spool
            .append(values.iter().map(|v| v.to_le_bytes()));
        r.map_err(|e| self.write_err(e))
    }

    /// Checks that every array got the bytes its shape holds, writes the zip beside the output
    /// and renames it over the output.
    pub fn finish(self) -> Result<()> {
        let werr = |source| LuxError::Write {
            path: self.path.clone(),
            source,
        };
        let zerr = |e: zip::result::ZipError| werr(std::io::Error::other(e));
        // The zip writer seeks back to write each entry's sizes, so it takes the temporary
        // file itself rather than `write_atomic`'s stream.
        let mut tmp = crate::io::temp_beside(&self.path)?;
        {
            let mut zip = zip::ZipWriter::new(BufWriter::new(tmp.as_file_mut()));
            for a in self.arrays {
                let want: u64 = a.shape.iter().product::<u64>() * 4;
                if want != a.spool.bytes {
                    return Err(werr(std::io::Error::other(format!(
                        "internal error: array {} has {} bytes, its shape {:?} holds {want}",
                        a.name, a.spool.bytes, a.shape
                    ))));
                }
                let header = npy_header(a.dtype, &a.shape);
                let options = zip::write::SimpleFileOptions::default()
                    .compression_method(zip::CompressionMethod::Stored)
                    .large_file(want + header.len() as u64 >= u32::MAX as u64);
                zip.start_file(format!("{}.npy", a.name), options)
                    .map_err(zerr)?;
                zip.write_all(&header).map_err(werr)?;
                a.spool.copy_into(&mut zip).map_err(werr)?;
            }
            let mut w = zip.finish().map_err(zerr)?;
            w.flush().map_err(werr)?;
        }
        tmp.as_file().sync_all().map_err(werr)?;
        tmp.persist(&self.path).map_err(|e| LuxError::Io {
            path: self.path.clone(),
            source: e.error,
        })?;
        Ok(())
    }
}

/// A float32 `.npy` of shape (M,) or (L, M) streamed in order of M: each of the L rows goes
/// to its own spool as it comes, and [`FlatNpy::finish`] writes the header and the rows one
/// after the other atomically ([`crate::io::write_atomic`]).
pub struct FlatNpy {
    path: PathBuf,
    shape: Vec<u64>,
    rows: Vec<Spool>,
}

impl FlatNpy {
    /// `rows` light rows of `m` values each (shape (m,) when `per_row` is false and `rows` 1).
    pub fn new(path: &Path, rows: u64, m: u64, per_row: bool) -> Result<FlatNpy> {
        let shape = if per_row { vec![rows, m] } else { vec![m] };
        let rows = (0..rows.max(1))
            .map(|_| Spool::new(path))
            .collect::<Result<_>>()?;
        Ok(FlatNpy {
            path: path.to_path_buf(),
            shape,
            rows,
        })
    }

    /// Appends the next values of row `r`.
    pub fn append(&mut self, r: usize, values: &[f32]) -> Result<()> {
        self.rows[r]
            .append(values.iter().map(|v| v.to_le_bytes()))
            .map_err(|source| LuxError::Write {
                path: self.path.clone(),
                source,
            })
    }

    pub fn finish(self) -> Result<()> {
        let (path, shape, rows) = (self.path, self.shape, self.rows);
        crate::io::write_atomic(&path, move |w| {
            w.write_all(&npy_header(Dtype::F32, &shape))?;
            rows.into_iter().try_for_each(|row| row.copy_into(w))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header NumPy writes for these arrays (`np.lib.format.write_array_header_1_0`):
    /// 128 bytes for (2, 3, 3) float32, the dict and its padding as NumPy spells them.
    #[test]
    fn header_is_numpys() {
        let h = npy_header(Dtype::F32, &[2, 3, 3]);
        assert_eq!(h.len() % 64, 0);
        let text = String::from_utf8_lossy(&h[10..]);
        assert!(text.starts_with("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 3), }"));
        assert!(text.ends_with('\n'));
        let h = npy_header(Dtype::I32, &[5]);
        assert!(String::from_utf8_lossy(&h[10..]).contains("'shape': (5,)"));
    }
}
