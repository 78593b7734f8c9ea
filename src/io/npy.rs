//! `.npy` arrays (DESIGN.md §4): inputs are (N, 3) float arrays, outputs float32 (N, 3) or
//! (L, N, 3). Reading and writing go through the maintained `npyz` crate.
//!
//! Inputs may be float32 or float64 (NumPy's default), either byte order, C or Fortran order;
//! anything else is an error naming the file and what was found.

use std::path::Path;

use npyz::WriterBuilder;

use crate::error::{LuxError, Result};
use crate::io::write_atomic;

fn format_err(path: &Path, reason: impl Into<String>) -> LuxError {
    LuxError::Format {
        path: path.to_path_buf(),
        line: None,
        reason: reason.into(),
    }
}

/// Reads an (N, 3) float array as rows of f32.
pub fn read_vec3(path: &Path) -> Result<Vec<[f32; 3]>> {
    let bytes = std::fs::read(path).map_err(|source| LuxError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let npy = npyz::NpyFile::new(&bytes[..])
        .map_err(|e| format_err(path, format!("not a readable .npy file: {e}")))?;
    let shape = npy.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(format_err(
            path,
            format!("expected an array of shape (N, 3), found {shape:?}"),
        ));
    }
    let n = shape[0] as usize;
    let order = npy.order();
    let dtype = npy.dtype();
    let npyz::DType::Plain(ty) = &dtype else {
        return Err(format_err(
            path,
            format!(
                "expected a float32 or float64 array, found dtype {}",
                dtype.descr()
            ),
        ));
    };
    let flat: Vec<f32> = match (ty.type_char(), ty.size_field()) {
        (npyz::TypeChar::Float, 4) => npy
            .into_vec::<f32>()
            .map_err(|e| format_err(path, e.to_string()))?,
        (npyz::TypeChar::Float, 8) => npy
            .into_vec::<f64>()
            .map_err(|e| format_err(path, e.to_string()))?
            .into_iter()
            .map(|v| v as f32)
            .collect(),
        _ => {
            return Err(format_err(
                path,
                format!(
                    "expected a float32 or float64 array, found dtype {}",
                    dtype.descr()
                ),
            ));
        }
    };
    if flat.len() != 3 * n {
        return Err(format_err(
            path,
            format!("header says {} values, file holds {}", 3 * n, flat.len()),
        ));
    }
    let rows = match order {
        npyz::Order::C => flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        // Column-major: all x, then all y, then all z.
        npyz::Order::Fortran => (0..n)
            .map(|i| [flat[i], flat[n + i], flat[2 * n + i]])
            .collect(),
    };
    Ok(rows)
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
