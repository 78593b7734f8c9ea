//! Reading `.npy` inputs: the streaming [`Reader`] (header and sizes checked at open, rows by
//! chunk), the whole-file `read_*` functions and the check of each row by its [`RowKind`].

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use luxeval::{BadRow, Limits, LuxError, Result, RowProblem};

use super::format_err;
use super::header::{Header, MAX_HEADER_BYTES, parse_header};

/// The rows of an (N, 3) file in the precision it stores.
enum Rows {
    F32(Vec<[f32; 3]>),
    F64(Vec<[f64; 3]>),
}

/// What the rows of an input stand for, which decides how each row is checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// Any values; float64 values beyond float32 are refused, NaN and infinities kept
    /// ([`read_vec3`]).
    Vec3,
    /// Every row finite and within float32 ([`read_points`]).
    Points,
    /// Every row finite and non-zero; float64 rows normalised in f64 ([`read_directions`]).
    Directions,
}

/// Reads an (N, 3) float array as rows of f32. Float64 values outside the float32 range are
/// refused (naming the file and row); NaN and infinities are returned as they are.
pub fn read_vec3(path: &Path) -> Result<Vec<[f32; 3]>> {
    Reader::open(path, RowKind::Vec3)?.read_all()
}

/// Reads (N, 3) points: every row finite and within float32.
pub fn read_points(path: &Path) -> Result<Vec<[f32; 3]>> {
    Reader::open(path, RowKind::Points)?.read_all()
}

/// Reads (N, 3) directions. float64 rows are normalised in f64, so that any finite non-zero row
/// (also one whose components are subnormal or beyond float32) becomes the float32 unit vector
/// nearest its direction; float32 rows are kept as they are (the queries normalise in f64). A
/// row that is not finite or is zero is refused, naming the file and the row.
pub fn read_directions(path: &Path) -> Result<Vec<[f32; 3]>> {
    Reader::open(path, RowKind::Directions)?.read_all()
}

/// Where the data of an open file comes from.
enum Source {
    /// C order: rows in file order, read front to back (also from a pipe).
    Sequential(std::io::BufReader<File>),
    /// Fortran order in a regular file: column j of rows a..b lies at `data + (j·n + a)·item`,
    /// read with three seeks per chunk.
    Columns { file: File, data: u64 },
    /// Fortran order from a pipe or device, which cannot seek: the data was read whole at open
    /// (bounded by the limits, as every input was before streaming).
    Whole(Vec<u8>),
}

/// A whole float32/float64 `.npy` array of any shape in C order (`luxeval sampling --check`'s
/// directions (N, K, 3) and densities (N, K)), with its shape: held in memory, so the file is
/// bounded by [`Limits`]' file size; NaN refused (naming the flat index); ±inf kept (a delta
/// light's density).
pub fn read_array(path: &Path) -> Result<(Vec<u64>, Vec<f64>)> {
    let limits = Limits::from_env()?;
    let io_err = |source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io_err)?;
    if meta.len() > limits.max_file_bytes {
        return Err(format_err(
            path,
            format!(
                "{} bytes exceed the limit of {} bytes ({})",
                meta.len(),
                limits.max_file_bytes,
                Limits::raise_hint(Limits::ENV_MAX_FILE_BYTES)
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(io_err)?;
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(format_err(
            path,
            "not a .npy file (it does not start with \\x93NUMPY)",
        ));
    }
    let (header_len, start): (usize, usize) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(format_err(path, format!("unknown .npy version {v}"))),
    };
    let text = bytes
        .get(start..start.saturating_add(header_len))
        .and_then(|t| std::str::from_utf8(t).ok())
        .ok_or_else(|| format_err(path, "the header is cut short or not text"))?;
    let (little, item, fortran, shape) =
        super::header::parse_dict(text).map_err(|why| format_err(path, format!("header {why}")))?;
    if fortran && shape.len() > 1 {
        return Err(format_err(
            path,
            "a Fortran-order array: save it in C order (np.ascontiguousarray)",
        ));
    }
    let count = shape
        .iter()
        .try_fold(1u64, |a, &d| a.checked_mul(d))
        .filter(|c| {
            c.checked_mul(item as u64)
                .is_some_and(|b| b <= limits.max_file_bytes)
        })
        .ok_or_else(|| format_err(path, format!("shape {shape:?} is too large")))?;
    let data = &bytes[start + header_len..];
    if data.len() as u64 != count * item as u64 {
        return Err(format_err(
            path,
            format!(
                "shape {shape:?} needs {} data bytes, the file holds {}",
                count * item as u64,
                data.len()
            ),
        ));
    }
    let values: Vec<f64> = data
        .chunks_exact(item)
        .map(|b| match (item, little) {
            (4, true) => f32::from_le_bytes(b.try_into().unwrap_or_default()) as f64,
            (4, false) => f32::from_be_bytes(b.try_into().unwrap_or_default()) as f64,
            (_, true) => f64::from_le_bytes(b.try_into().unwrap_or_default()),
            (_, false) => f64::from_be_bytes(b.try_into().unwrap_or_default()),
        })
        .collect();
    if let Some(i) = values.iter().position(|v| v.is_nan()) {
        return Err(format_err(path, format!("value {i} (flat index) is NaN")));
    }
    Ok((shape, values))
}

/// A streaming reader of an (N, 3) `.npy` input: the header is parsed and checked (dtype, shape,
/// sizes against the file and [`Limits`]) by [`Reader::open`], then rows come chunk by chunk
/// from [`Reader::next_chunk`], each row checked as its [`RowKind`] says, errors naming the file
/// and the row's index in the whole array. Memory: one chunk (and its bytes).
pub struct Reader {
    path: PathBuf,
    kind: RowKind,
    header: Header,
    /// The first row the next chunk holds.
    next_row: u64,
    source: Source,
    /// The bytes of the last chunk, kept to be reused.
    bytes: Vec<u8>,
}

impl Reader {
    /// Opens `path` and reads and checks its header, for an array that will be held whole: its
    /// rows and bytes are bounded by [`Limits`]. For a regular file, a data size that differs
    /// from what the header declares (a truncated file, trailing bytes) is refused here, before
    /// any row is read; from a pipe it is refused when the stream ends.
    pub fn open(path: &Path, kind: RowKind) -> Result<Reader> {
        Self::open_with(path, kind, false)
    }

    /// [`Reader::open`] for an array read chunk by chunk and never held (the query commands,
    /// docs/INPUTS.md "Streaming"): any number of rows, since memory holds a few chunks whatever
    /// the array's size. The limits still bound what would be held whole: a Fortran-order array
    /// from a pipe, which cannot be read by columns.
    pub fn open_streaming(path: &Path, kind: RowKind) -> Result<Reader> {
        Self::open_with(path, kind, true)
    }

    fn open_with(path: &Path, kind: RowKind, streaming: bool) -> Result<Reader> {
        let limits = Limits::from_env()?;
        let io_err = |source| LuxError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = File::open(path).map_err(io_err)?;
        let meta = file.metadata().map_err(io_err)?;
        if meta.is_dir() {
            return Err(io_err(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "is a directory, not a .npy file",
            )));
        }
        // What this reader will hold: the whole array unless it streams from a file or in C
        // order (decided once the header is read); the file's size bounds it up front.
        if !streaming && meta.is_file() && meta.len() > limits.max_file_bytes {
            return Err(format_err(
                path,
                format!(
                    "{} bytes exceed the limit of {} bytes ({})",
                    meta.len(),
                    limits.max_file_bytes,
                    Limits::raise_hint(Limits::ENV_MAX_FILE_BYTES)
                ),
            ));
        }
        let mut r = std::io::BufReader::new(file);
        let mut pre = [0u8; 8];
        read_exact(&mut r, path, &mut pre, "magic string")?;
        if &pre[..6] != b"\x93NUMPY" {
            return Err(format_err(
                path,
                "not a .npy file (it does not start with \\x93NUMPY)",
            ));
        }
        let (header_len, len_bytes) = match pre[6] {
            1 => {
                let mut b = [0u8; 2];
                read_exact(&mut r, path, &mut b, "header length")?;
                (u16::from_le_bytes(b) as usize, 2)
            }
            2 | 3 => {
                let mut b = [0u8; 4];
                read_exact(&mut r, path, &mut b, "header length")?;
                (u32::from_le_bytes(b) as usize, 4)
            }
            v => {
                return Err(format_err(
                    path,
                    format!("unsupported .npy format version {v}.{}", pre[7]),
                ));
            }
        };
        if header_len > MAX_HEADER_BYTES {
            return Err(format_err(
                path,
                format!("a header of {header_len} bytes is longer than {MAX_HEADER_BYTES}"),
            ));
        }
        let mut text = vec![0u8; header_len];
        read_exact(&mut r, path, &mut text, "header")?;
        let text =
            String::from_utf8(text).map_err(|_| format_err(path, "the header is not text"))?;
        let h = parse_header(&text).map_err(|why| format_err(path, format!("header {why}")))?;
        let held_whole = !streaming || (h.fortran && !meta.is_file());
        if held_whole {
            limits.check_samples(&path.display().to_string(), h.rows)?;
        }
        // Overflow-free: a header whose rows × 3 × itemsize wraps around is refused, not read as
        // empty.
        let bytes = h.rows.checked_mul(3 * h.item as u64).ok_or_else(|| {
            format_err(
                path,
                format!(
                    "{} rows of 3 × {} bytes do not fit a 64-bit size",
                    h.rows, h.item
                ),
            )
        })?;
        if held_whole && bytes > limits.max_file_bytes {
            return Err(format_err(
                path,
                format!(
                    "{} rows of 3 × {} bytes exceed the limit of {} bytes ({})",
                    h.rows,
                    h.item,
                    limits.max_file_bytes,
                    Limits::raise_hint(Limits::ENV_MAX_FILE_BYTES)
                ),
            ));
        }
        let data = (8 + len_bytes + header_len) as u64;
        if meta.is_file() {
            // A regular file tells its size: a truncated or padded file is refused before any
            // row is evaluated, as when inputs were read whole.
            let held = meta.len() - data.min(meta.len());
            if held < bytes {
                return Err(format_err(path, format!("the file ends inside the {DATA}")));
            }
            if held > bytes {
                return Err(more_data(path, h.rows));
            }
        }
        let source = if !h.fortran {
            Source::Sequential(r)
        } else if meta.is_file() {
            Source::Columns {
                file: r.into_inner(),
                data,
            }
        } else {
            let mut whole = vec![0u8; bytes as usize];
            read_exact(&mut r, path, &mut whole, DATA)?;
            check_end(&mut r, path, h.rows)?;
            Source::Whole(whole)
        };
        let mut reader = Reader {
            path: path.to_path_buf(),
            kind,
            header: h,
            next_row: 0,
            source,
            bytes: Vec::new(),
        };
        if reader.header.rows == 0 {
            reader.end()?;
        }
        Ok(reader)
    }

    /// The rows the header declares.
    pub fn rows(&self) -> u64 {
        self.header.rows
    }

    /// The file being read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The next at most `max_rows` rows (at least 1 is read when `max_rows` is 0), checked, or
    /// `None` once every row was read.
    pub fn next_chunk(&mut self, max_rows: usize) -> Result<Option<Vec<[f32; 3]>>> {
        let (n, start) = (self.header.rows, self.next_row);
        if start >= n {
            return Ok(None);
        }
        // m ≤ n − start ≤ n, and n × 3 × item was checked to fit the byte limit at open.
        let m = (n - start).min(max_rows.max(1) as u64) as usize;
        let item = self.header.item;
        let len = m * 3 * item;
        self.bytes.resize(len, 0);
        // After this, `bytes` holds the chunk in C order (row-major) or as three columns of m
        // values each (`columns`).
        let columns = match &mut self.source {
            Source::Sequential(r) => {
                read_exact(r, &self.path, &mut self.bytes, DATA)?;
                false
            }
            Source::Columns { file, data } => {
                let io_err = |source| LuxError::Io {
                    path: self.path.clone(),
                    source,
                };
                for (j, column) in self.bytes.chunks_exact_mut(m * item).enumerate() {
                    let at = *data + (j as u64 * n + start) * item as u64;
                    file.seek(SeekFrom::Start(at)).map_err(io_err)?;
                    read_exact(file, &self.path, column, DATA)?;
                }
                true
            }
            Source::Whole(whole) => {
                let n = n as usize;
                for (j, column) in self.bytes.chunks_exact_mut(m * item).enumerate() {
                    let at = (j * n + start as usize) * item;
                    column.copy_from_slice(&whole[at..at + m * item]);
                }
                true
            }
        };
        let rows = decode(&self.bytes, m, item, self.header.little_endian, columns);
        let out = check_rows(&self.path, self.kind, start, rows)?;
        self.next_row += m as u64;
        if self.next_row == n {
            self.end()?;
        }
        Ok(Some(out))
    }

    /// Every remaining row in one chunk.
    pub fn read_all(mut self) -> Result<Vec<[f32; 3]>> {
        let left = self.header.rows - self.next_row;
        Ok(self
            .next_chunk(usize::try_from(left).unwrap_or(usize::MAX))?
            .unwrap_or_default())
    }

    /// After the last row: a stream must end there.
    fn end(&mut self) -> Result<()> {
        if let Source::Sequential(r) = &mut self.source {
            check_end(r, &self.path, self.header.rows)?;
        }
        Ok(())
    }
}

/// What a file that ends too early ends inside.
const DATA: &str = "data (the header declares more rows than the file holds)";

fn more_data(path: &Path, rows: u64) -> LuxError {
    format_err(
        path,
        format!("more data than the {rows} rows of 3 the header declares"),
    )
}

/// Reads exactly `buf`; an early end is a format error naming what it ends inside.
fn read_exact(r: &mut impl Read, path: &Path, buf: &mut [u8], what: &str) -> Result<()> {
    r.read_exact(buf).map_err(|e| {
        if e.kind() == std::io::ErrorKind::UnexpectedEof {
            format_err(path, format!("the file ends inside the {what}"))
        } else {
            LuxError::Io {
                path: path.to_path_buf(),
                source: e,
            }
        }
    })
}

/// The stream must hold nothing after the data the header declares.
fn check_end(r: &mut impl Read, path: &Path, rows: u64) -> Result<()> {
    let mut extra = [0u8; 1];
    loop {
        return match r.read(&mut extra) {
            Ok(0) => Ok(()),
            Ok(_) => Err(more_data(path, rows)),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => Err(LuxError::Io {
                path: path.to_path_buf(),
                source: e,
            }),
        };
    }
}

/// `m` rows from their bytes: row-major, or (`columns`) three columns of `m` values each.
fn decode(bytes: &[u8], m: usize, item: usize, little_endian: bool, columns: bool) -> Rows {
    // Element k of `bytes` is row k / 3, column k % 3 (row-major) or row k % m, column k / m.
    let at = |k: usize| {
        if columns {
            (k % m, k / m)
        } else {
            (k / 3, k % 3)
        }
    };
    if item == 4 {
        let mut rows = vec![[0f32; 3]; m];
        for (k, c) in bytes.chunks_exact(4).enumerate() {
            let b = [c[0], c[1], c[2], c[3]];
            let (i, j) = at(k);
            rows[i][j] = if little_endian {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            };
        }
        Rows::F32(rows)
    } else {
        let mut rows = vec![[0f64; 3]; m];
        for (k, c) in bytes.chunks_exact(8).enumerate() {
            let b = [c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]];
            let (i, j) = at(k);
            rows[i][j] = if little_endian {
                f64::from_le_bytes(b)
            } else {
                f64::from_be_bytes(b)
            };
        }
        Rows::F64(rows)
    }
}

/// Checks and converts the rows of a chunk whose first row is row `start` of the file, by the
/// library's one rule for query inputs ([`luxeval::RowKind`]). Each row is checked completely
/// before the next, so the first bad row of the file is the one reported whatever the chunk
/// size.
fn check_rows(path: &Path, kind: RowKind, start: u64, rows: Rows) -> Result<Vec<[f32; 3]>> {
    let bad = |e: BadRow| format_err(path, e.to_string());
    let rule = match kind {
        RowKind::Vec3 => None,
        RowKind::Points => Some(luxeval::RowKind::Points),
        RowKind::Directions => Some(luxeval::RowKind::Directions),
    };
    match (rule, rows) {
        // float32 rows are checked and kept as they are: the queries normalise every direction
        // in f64 themselves (on both paths), and a row normalised here first would round twice
        // and differ in the last bit from the same array given to the library (Python).
        (Some(rule), Rows::F32(rows)) => {
            rule.check_f32(start, &rows).map_err(bad)?;
            Ok(rows)
        }
        (Some(rule), Rows::F64(rows)) => rule.f32_from_f64(start, &rows).map_err(bad),
        (None, Rows::F32(rows)) => Ok(rows),
        // Any values, but each must fit float32 (NaN and infinities are kept).
        (None, Rows::F64(rows)) => rows
            .iter()
            .enumerate()
            .map(|(i, r)| {
                if r.iter().any(|v| v.is_finite() && v.abs() > f32::MAX as f64) {
                    return Err(bad(BadRow {
                        row: start + i as u64,
                        values: format!("{r:?}"),
                        problem: RowProblem::OutsideFloat32,
                    }));
                }
                Ok(r.map(|v| v as f32))
            })
            .collect(),
    }
}

#[cfg(test)]
mod numpy_files {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/npy")).join(name)
    }

    /// Files written by NumPy (tools/gen_npy_fixtures.py): every accepted layout reads the same.
    #[test]
    fn numpy_layouts_read_the_same() {
        let want = read_vec3(&data("dirs_f32.npy")).unwrap();
        assert_eq!(want[1], [0.3, -0.9, 0.1]);
        for f in [
            "dirs_f64.npy",
            "dirs_f32_fortran.npy",
            "dirs_f32_bigendian.npy",
        ] {
            assert_eq!(read_vec3(&data(f)).unwrap(), want, "{f}");
        }
    }

    #[test]
    fn numpy_files_with_the_wrong_dtype_or_shape_are_named_errors() {
        let e = read_vec3(&data("dirs_int.npy")).unwrap_err().to_string();
        assert!(
            e.contains("dirs_int.npy") && e.contains("float32 or float64"),
            "{e}"
        );
        let e = read_vec3(&data("dirs_shape_4x2.npy"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("dirs_shape_4x2.npy") && e.contains("[4, 2]"),
            "{e}"
        );
    }
}
