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

mod header;
mod read;
mod write;

use std::path::Path;

use luxeval::{Limits, LuxError, Result};

pub use read::{Reader, RowKind, read_array, read_directions, read_points, read_vec3};
pub use write::{Writer, write_f32};

fn format_err(path: &Path, reason: impl Into<String>) -> LuxError {
    LuxError::Format {
        path: path.to_path_buf(),
        line: None,
        reason: reason.into(),
    }
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
