//! `.npy` arrays (DESIGN.md §4): inputs are (N, 3) float arrays, outputs float32 (N, 3) or
//! (L, N, 3). Writing goes through the maintained `npyz` crate; reading is done here, because an
//! input is untrusted: the header is parsed strictly, its sizes are checked with overflow-free
//! arithmetic against the file and against [`Limits`] before anything is allocated, and the file
//! is read as a stream that stops at the size the header declares (an endless device or pipe is
//! refused, never read without end). npyz computes strides from an unchecked shape.
//!
//! Inputs may be float32 or float64 (NumPy's default), either byte order, C or Fortran order;
//! anything else is an error naming the file and what was found. Values that are finite in
//! float64 but overflow float32 are refused with the row named; directions are normalised in
//! float64 first (docs/INPUTS.md).

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use npyz::WriterBuilder;

use luxeval::{BadRow, Limits, LuxError, Result, RowProblem};

use crate::io::write_atomic;

fn format_err(path: &Path, reason: impl Into<String>) -> LuxError {
    LuxError::Format {
        path: path.to_path_buf(),
        line: None,
        reason: reason.into(),
    }
}

/// The longest header accepted (NumPy itself refuses more than 10 000 bytes unless told to).
const MAX_HEADER_BYTES: usize = 65_536;

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

/// The rows read per chunk by the streaming commands unless `LUXEVAL_CHUNK_ROWS` says otherwise:
/// 12 MiB of float32 rows, large enough that a GPU dispatch and a write per chunk cost little,
/// small enough that memory does not grow with the array (docs/INPUTS.md "Streaming").
pub const DEFAULT_CHUNK_ROWS: usize = 1 << 20;

/// The environment variable that sets the rows per chunk (a positive integer).
pub const ENV_CHUNK_ROWS: &str = "LUXEVAL_CHUNK_ROWS";

/// The rows per chunk: [`DEFAULT_CHUNK_ROWS`], or `LUXEVAL_CHUNK_ROWS` when set (anything but a
/// positive integer is refused as bad input, naming the variable).
pub fn chunk_rows_from_env() -> Result<usize> {
    let rows = Limits::env_var(ENV_CHUNK_ROWS, DEFAULT_CHUNK_ROWS as u64)?;
    // Beyond usize (32-bit targets) means "everything in one chunk".
    Ok(usize::try_from(rows).unwrap_or(usize::MAX))
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
    /// Opens `path` and reads and checks its header. For a regular file, a data size that
    /// differs from what the header declares (a truncated file, trailing bytes) is refused
    /// here, before any row is read; from a pipe it is refused when the stream ends.
    pub fn open(path: &Path, kind: RowKind) -> Result<Reader> {
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
        if meta.is_file() && meta.len() > limits.max_file_bytes {
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
        limits.check_samples(&path.display().to_string(), h.rows)?;
        // Overflow-free: a header whose rows × 3 × itemsize wraps around is refused, not read as
        // empty.
        let bytes = h
            .rows
            .checked_mul(3 * h.item as u64)
            .filter(|b| *b <= limits.max_file_bytes)
            .ok_or_else(|| {
                format_err(
                    path,
                    format!(
                        "{} rows of 3 × {} bytes exceed the limit of {} bytes ({})",
                        h.rows,
                        h.item,
                        limits.max_file_bytes,
                        Limits::raise_hint(Limits::ENV_MAX_FILE_BYTES)
                    ),
                )
            })?;
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

/// What the header says.
struct Header {
    little_endian: bool,
    /// 4 or 8.
    item: usize,
    fortran: bool,
    rows: u64,
}

/// Parses NumPy's header, a Python dict literal with exactly the keys `descr`, `fortran_order`
/// and `shape`, e.g. `{'descr': '<f4', 'fortran_order': False, 'shape': (4, 3), }`.
fn parse_header(text: &str) -> std::result::Result<Header, String> {
    let body = text
        .trim_end_matches(['\n', ' ', '\0'])
        .trim_start()
        .strip_prefix('{')
        .and_then(|t| t.strip_suffix('}'))
        .ok_or_else(|| format!("{:?} is not a dict", clip(text)))?;
    let mut descr = None;
    let mut fortran = None;
    let mut shape: Option<Vec<u64>> = None;
    let mut rest = body.trim();
    while !rest.is_empty() {
        let (key, after) =
            string_literal(rest).ok_or_else(|| format!("bad key in {:?}", clip(text)))?;
        let after = after
            .trim_start()
            .strip_prefix(':')
            .ok_or_else(|| format!("no ':' after {key:?}"))?
            .trim_start();
        let after = match key.as_str() {
            "descr" => {
                let (v, a) = string_literal(after).ok_or("descr is not a string")?;
                descr = Some(v);
                a
            }
            "fortran_order" => {
                if let Some(a) = after.strip_prefix("True") {
                    fortran = Some(true);
                    a
                } else if let Some(a) = after.strip_prefix("False") {
                    fortran = Some(false);
                    a
                } else {
                    return Err("fortran_order is not True or False".into());
                }
            }
            "shape" => {
                let inner = after.strip_prefix('(').ok_or("shape is not a tuple")?;
                let close = inner.find(')').ok_or("shape is not a tuple")?;
                let dims = inner[..close]
                    .split(',')
                    .map(str::trim)
                    .filter(|d| !d.is_empty())
                    .map(|d| {
                        d.parse::<u64>()
                            .map_err(|_| format!("shape entry {d:?} is not a size"))
                    })
                    .collect::<std::result::Result<Vec<_>, _>>()?;
                shape = Some(dims);
                &inner[close + 1..]
            }
            other => return Err(format!("has an unexpected key {other:?}")),
        };
        let after = after.trim_start();
        rest = match after.strip_prefix(',') {
            Some(a) => a.trim_start(),
            None if after.is_empty() => after,
            None => return Err(format!("expected ',' in {:?}", clip(text))),
        };
    }
    let (Some(descr), Some(fortran), Some(shape)) = (descr, fortran, shape) else {
        return Err("lacks one of descr, fortran_order, shape".into());
    };
    let (little_endian, item) = match descr.as_str() {
        "<f4" => (true, 4),
        ">f4" => (false, 4),
        "<f8" => (true, 8),
        ">f8" => (false, 8),
        "=f4" => (cfg!(target_endian = "little"), 4),
        "=f8" => (cfg!(target_endian = "little"), 8),
        other => {
            return Err(format!(
                "dtype {other:?}: expected a float32 or float64 array"
            ));
        }
    };
    match shape.as_slice() {
        [rows, 3] => Ok(Header {
            little_endian,
            item,
            fortran,
            rows: *rows,
        }),
        _ => Err(format!(
            "shape {shape:?}: expected an array of shape (N, 3)"
        )),
    }
}

/// A Python string literal in single or double quotes (no escapes: NumPy writes none in these
/// keys and values) and what follows it.
fn string_literal(s: &str) -> Option<(String, &str)> {
    let q = s.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let end = s[1..].find(q)? + 1;
    Some((s[1..end].to_string(), &s[end + 1..]))
}

fn clip(s: &str) -> String {
    s.chars().take(80).collect()
}

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
        let mut tmp = super::temp_beside(path)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_shape_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.npy");
        let rows = vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]];
        write_f32(&p, &[2, 3], &rows).unwrap();
        assert_eq!(read_vec3(&p).unwrap(), rows);
        let q = dir.path().join("b.npy");
        write_f32(&q, &[1, 2, 3], &rows).unwrap();
        let e = read_vec3(&q).unwrap_err().to_string();
        assert!(
            e.contains("b.npy") && e.contains("(N, 3)") && e.contains("[1, 2, 3]"),
            "{e}"
        );
        let e = read_vec3(&dir.path().join("missing.npy")).unwrap_err();
        assert!(matches!(e, LuxError::Io { .. }));
        std::fs::write(dir.path().join("junk.npy"), b"not numpy").unwrap();
        let e = read_vec3(&dir.path().join("junk.npy"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("junk.npy"), "{e}");
        // Only temporaries are removed; no stray files remain.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 3, "{names:?}");
    }
}

#[cfg(test)]
mod streaming {
    use super::*;

    fn rows(n: usize) -> Vec<[f32; 3]> {
        (0..n)
            .map(|i| [i as f32 + 0.5, -(i as f32), 1.0 / (i as f32 + 1.0)])
            .collect()
    }

    /// The streaming writer's bytes are `write_f32`'s, with rows written in any order and any
    /// pieces; the file appears only at `finish`.
    #[test]
    fn the_writer_writes_what_write_f32_writes() {
        let dir = tempfile::tempdir().unwrap();
        let want_path = dir.path().join("want.npy");
        let r = rows(2 * 7);
        write_f32(&want_path, &[2, 7, 3], &r).unwrap();
        let path = dir.path().join("got.npy");
        let mut w = Writer::create(&path, &[2, 7, 3]).unwrap();
        assert_eq!(w.rows(), 14);
        // Light-major pieces, the second light first, in chunks of 3 samples.
        for start in (0..7).step_by(3) {
            let end = (start + 3).min(7);
            w.write_rows(7 + start as u64, &r[7 + start..7 + end])
                .unwrap();
            w.write_rows(start as u64, &r[start..end]).unwrap();
        }
        assert!(!path.exists(), "the output appears only when finished");
        w.finish().unwrap();
        assert_eq!(
            std::fs::read(&path).unwrap(),
            std::fs::read(&want_path).unwrap()
        );

        // Unfinished or misused: nothing at the path, no temporary left.
        let p = dir.path().join("partial.npy");
        let mut w = Writer::create(&p, &[4, 3]).unwrap();
        w.write_rows(0, &r[..3]).unwrap();
        assert!(w.write_rows(2, &r[..3]).is_err(), "rows past the end");
        let e = w.finish().unwrap_err().to_string();
        assert!(e.contains("3 rows were written of the 4"), "{e}");
        assert!(Writer::create(&p, &[4, 2]).is_err());
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }

    /// Chunks of any size give the rows of the whole file, in every layout.
    #[test]
    fn chunks_of_any_size_read_the_whole_file() {
        let data = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/npy"));
        let want = read_vec3(&data.join("dirs_f32.npy")).unwrap();
        for f in [
            "dirs_f32.npy",
            "dirs_f64.npy",
            "dirs_f32_fortran.npy",
            "dirs_f32_bigendian.npy",
        ] {
            for chunk in [0, 1, 2, 3, 1000] {
                let mut r = Reader::open(&data.join(f), RowKind::Vec3).unwrap();
                assert_eq!(r.rows(), want.len() as u64);
                let mut got = Vec::new();
                while let Some(c) = r.next_chunk(chunk).unwrap() {
                    assert!(c.len() <= chunk.max(1));
                    got.extend(c);
                }
                assert_eq!(got, want, "{f}, chunks of {chunk}");
            }
        }
    }

    /// A bad row is named by its row in the file, whatever chunk it falls in; the first bad
    /// row is reported whatever the chunk size.
    #[test]
    fn bad_rows_are_named_by_their_row_in_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("p.npy");
        let mut r = rows(10);
        r[4] = [0.0, 0.0, 0.0];
        r[7] = [f32::NAN, 0.0, 0.0];
        write_f32(&p, &[10, 3], &r).unwrap();
        for (kind, row) in [(RowKind::Points, "row 7 "), (RowKind::Directions, "row 4 ")] {
            for chunk in [1, 3, 10] {
                let mut rd = Reader::open(&p, kind).unwrap();
                let e = loop {
                    match rd.next_chunk(chunk) {
                        Ok(Some(_)) => {}
                        Ok(None) => panic!("no error"),
                        Err(e) => break e.to_string(),
                    }
                };
                assert!(
                    e.contains("p.npy") && e.contains(row),
                    "{kind:?} {chunk}: {e}"
                );
            }
        }
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
