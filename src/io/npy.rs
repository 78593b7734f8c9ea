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

use std::io::Read;
use std::path::Path;

use npyz::WriterBuilder;

use crate::error::{LuxError, Result};
use crate::io::write_atomic;
use crate::limits::{ENV_MAX_FILE_BYTES, Limits, raise_hint};

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

/// Reads an (N, 3) float array as rows of f32. Float64 values outside the float32 range are
/// refused (naming the file and row); NaN and infinities are returned as they are.
pub fn read_vec3(path: &Path) -> Result<Vec<[f32; 3]>> {
    match read_rows(path)? {
        Rows::F32(rows) => Ok(rows),
        Rows::F64(rows) => rows
            .iter()
            .enumerate()
            .map(|(i, r)| {
                if r.iter().any(|v| v.is_finite() && v.abs() > f32::MAX as f64) {
                    return Err(format_err(
                        path,
                        format!(
                            "row {i} {r:?} does not fit float32 (largest {:e})",
                            f32::MAX
                        ),
                    ));
                }
                Ok(r.map(|v| v as f32))
            })
            .collect(),
    }
}

/// Reads (N, 3) points: every row finite and within float32.
pub fn read_points(path: &Path) -> Result<Vec<[f32; 3]>> {
    let rows = read_vec3(path)?;
    if let Some(i) = rows.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
        return Err(format_err(
            path,
            format!("row {i} is not finite: {:?}", rows[i]),
        ));
    }
    Ok(rows)
}

/// Reads (N, 3) directions. float64 rows are normalised in f64, so that any finite non-zero row
/// (also one whose components are subnormal or beyond float32) becomes the float32 unit vector
/// nearest its direction; float32 rows are kept as they are (the queries normalise in f64). A
/// row that is not finite or is zero is refused, naming the file and the row.
pub fn read_directions(path: &Path) -> Result<Vec<[f32; 3]>> {
    fn unit(path: &Path, i: usize, r: [f64; 3]) -> Result<[f32; 3]> {
        if r.iter().any(|v| !v.is_finite()) {
            return Err(format_err(path, format!("row {i} is not finite: {r:?}")));
        }
        // Scale by the largest component first: the squares of 1e300 or 1e-320 do not fit f64.
        let m = r.iter().fold(0f64, |m, v| m.max(v.abs()));
        if m == 0.0 {
            return Err(format_err(
                path,
                format!("row {i} is the zero vector, which has no direction"),
            ));
        }
        let s = r.map(|v| v / m);
        let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        Ok(s.map(|v| (v / len) as f32))
    }
    match read_rows(path)? {
        // float32 rows are checked and kept as they are: the queries normalise every direction
        // in f64 themselves (on both paths), and a row normalised here first would round twice
        // and differ in the last bit from the same array given to the library (Python).
        Rows::F32(rows) => rows
            .iter()
            .enumerate()
            .map(|(i, r)| unit(path, i, r.map(f64::from)).map(|_| *r))
            .collect(),
        Rows::F64(rows) => rows
            .iter()
            .enumerate()
            .map(|(i, r)| unit(path, i, *r))
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

fn read_rows(path: &Path) -> Result<Rows> {
    let limits = Limits::from_env()?;
    let io_err = |source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io_err)?;
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
                raise_hint(ENV_MAX_FILE_BYTES)
            ),
        ));
    }
    let mut r = std::io::BufReader::new(file);
    let mut read = |buf: &mut [u8], what: &str| -> Result<()> {
        r.read_exact(buf).map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                format_err(path, format!("the file ends inside the {what}"))
            } else {
                io_err(e)
            }
        })
    };
    let mut pre = [0u8; 8];
    read(&mut pre, "magic string")?;
    if &pre[..6] != b"\x93NUMPY" {
        return Err(format_err(
            path,
            "not a .npy file (it does not start with \\x93NUMPY)",
        ));
    }
    let header_len = match pre[6] {
        1 => {
            let mut b = [0u8; 2];
            read(&mut b, "header length")?;
            u16::from_le_bytes(b) as usize
        }
        2 | 3 => {
            let mut b = [0u8; 4];
            read(&mut b, "header length")?;
            u32::from_le_bytes(b) as usize
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
    read(&mut text, "header")?;
    let text = String::from_utf8(text).map_err(|_| format_err(path, "the header is not text"))?;
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
                    raise_hint(ENV_MAX_FILE_BYTES)
                ),
            )
        })?;
    let mut data = vec![0u8; bytes as usize];
    read(
        &mut data,
        "data (the header declares more rows than the file holds)",
    )?;
    let mut extra = [0u8; 1];
    match r.read(&mut extra) {
        Ok(0) => {}
        Ok(_) => {
            return Err(format_err(
                path,
                format!(
                    "more data than the {} rows of 3 the header declares",
                    h.rows
                ),
            ));
        }
        Err(e) => return Err(io_err(e)),
    }
    let n = h.rows as usize;
    // Element k of the file is row k / 3, column k % 3 (C order) or row k % n, column k / n.
    let at = |k: usize| {
        if h.fortran {
            (k % n, k / n)
        } else {
            (k / 3, k % 3)
        }
    };
    Ok(match h.item {
        4 => {
            let mut rows = vec![[0f32; 3]; n];
            for (k, c) in data.chunks_exact(4).enumerate() {
                let b = [c[0], c[1], c[2], c[3]];
                let (i, j) = at(k);
                rows[i][j] = if h.little_endian {
                    f32::from_le_bytes(b)
                } else {
                    f32::from_be_bytes(b)
                };
            }
            Rows::F32(rows)
        }
        _ => {
            let mut rows = vec![[0f64; 3]; n];
            for (k, c) in data.chunks_exact(8).enumerate() {
                let b = [c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]];
                let (i, j) = at(k);
                rows[i][j] = if h.little_endian {
                    f64::from_le_bytes(b)
                } else {
                    f64::from_be_bytes(b)
                };
            }
            Rows::F64(rows)
        }
    })
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
mod numpy_files {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/npy")
            .join(name)
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
