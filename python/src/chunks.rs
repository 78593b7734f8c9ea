//! Chunked queries: how many rows each call into the library evaluates ([`Chunks`]), and the
//! zeroed result buffer the chunks are written into.

use std::time::Instant;

use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;

use crate::errors::no_panic;

/// How many rows each call into the library evaluates. Between two calls the GIL is taken back
/// and Ctrl-C is checked, so a call should take about [`Chunks::TARGET_S`] whatever the device
/// and the query cost (irradiance on the CPU reference costs ~10 000 times what emission on a
/// GPU does): the first chunk is small, and each next one is sized from the last one's time.
/// Sizes are powers of two, so that the GPU's buffers (kept per power-of-two size class) are
/// reused from chunk to chunk once the size settles.
pub(crate) struct Chunks {
    pub(crate) rows: usize,
    max: usize,
}

impl Chunks {
    const TARGET_S: f64 = 0.25;
    /// At most this many light-samples (rows × lights) per call: bounds the chunk's memory.
    const MAX_SAMPLES: usize = 1 << 22;

    pub(crate) fn new(first: usize, lights: usize) -> Chunks {
        let max = (Self::MAX_SAMPLES / lights.max(1)).max(1);
        Chunks {
            rows: first.min(max).max(1),
            max,
        }
    }

    /// Runs `f(start, end)` on consecutive ranges of the rows `0..n`, each as long as the last
    /// one's time says ([`Chunks::update`]), with the GIL released and a panic turned into an
    /// error; Ctrl-C raises `KeyboardInterrupt` between two ranges.
    pub(crate) fn run(
        &mut self,
        py: Python<'_>,
        n: usize,
        mut f: impl FnMut(usize, usize) -> PyResult<()> + Send,
    ) -> PyResult<()> {
        let mut start = 0;
        while start < n {
            let end = (start + self.rows).min(n);
            let t0 = Instant::now();
            py.detach(|| no_panic(|| f(start, end)))?;
            if end < n {
                self.update(end - start, t0.elapsed().as_secs_f64());
            }
            py.check_signals()?;
            start = end;
        }
        Ok(())
    }

    /// After a chunk of `rows` rows took `secs`: the size of the next one, within 4× of it.
    pub(crate) fn update(&mut self, rows: usize, secs: f64) {
        let rows = rows.max(1);
        let ideal = if secs > 0.0 {
            rows as f64 * Self::TARGET_S / secs
        } else {
            f64::INFINITY
        };
        let ideal = ideal.clamp((rows / 4).max(1) as f64, rows.saturating_mul(4) as f64);
        self.rows = if ideal >= self.max as f64 {
            self.max
        } else {
            // The power of two at or below the ideal size.
            let ideal = ideal as usize;
            1usize << (usize::BITS - 1 - ideal.leading_zeros())
        };
    }
}

/// A zeroed buffer of `len` values (`None`: more than `usize` can count), or `MemoryError`
/// rather than an abort when it cannot be allocated.
pub(crate) fn zeros<T: Copy + Default>(len: Option<usize>) -> PyResult<Vec<T>> {
    let too_big =
        |what: String| PyMemoryError::new_err(format!("cannot allocate the result: {what}"));
    let len = len.ok_or_else(|| too_big("more values than memory can address".into()))?;
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        too_big(format!(
            "{len} values of {} bytes ({} bytes)",
            size_of::<T>(),
            len.saturating_mul(size_of::<T>())
        ))
    })?;
    v.resize(len, T::default());
    Ok(v)
}
