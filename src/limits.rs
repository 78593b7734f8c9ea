//! Limits on what luxeval reads and allocates (docs/INPUTS.md "Limits"). Every input is read
//! through one of these bounds, so that no file, header or argument can make luxeval read without
//! end, allocate without bound or recurse until the stack overflows; what exceeds a limit is
//! refused as bad input, naming the limit and the environment variable that raises it.
//!
//! The defaults let a command at every limit at once fit in about 16 GB of memory. Each can be
//! raised (or lowered) for one process through its environment variable; a value that is not a
//! positive integer is itself refused.

use crate::error::{LuxError, Result};

/// The bounds in force. [`Limits::from_env`] gives the defaults overridden by the environment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// The largest file luxeval reads, in bytes: every `.npy` input and every USD layer (each
    /// layer of a stage on its own, packages included). `LUXEVAL_MAX_FILE_BYTES`.
    pub max_file_bytes: u64,
    /// The most rows of one query: rows of an input array, rows of an output (light × sample
    /// with `--per-light`), falloff pixels, `check` and `bench` samples. `LUXEVAL_MAX_SAMPLES`.
    pub max_samples: u64,
    /// The most prims a stage may compose to (an upper bound computed from its composition arcs
    /// before composing; every variant counted). `LUXEVAL_MAX_PRIMS`.
    pub max_prims: u64,
    /// The deepest namespace a stage may compose to (`/a/b/c` is 3 deep), arcs included.
    /// `LUXEVAL_MAX_PRIM_DEPTH`.
    pub max_prim_depth: u64,
    /// The most triangles of one mesh light (its faces' fans, holes removed; DESIGN.md §7 M3).
    /// `LUXEVAL_MAX_MESH_TRIANGLES`.
    pub max_mesh_triangles: u64,
}

// Environment variables, in the order of the fields of [`Limits`] (also its associated
// constants, which name them for callers).
pub(crate) const ENV_MAX_FILE_BYTES: &str = "LUXEVAL_MAX_FILE_BYTES";
pub(crate) const ENV_MAX_SAMPLES: &str = "LUXEVAL_MAX_SAMPLES";
pub(crate) const ENV_MAX_PRIMS: &str = "LUXEVAL_MAX_PRIMS";
pub(crate) const ENV_MAX_PRIM_DEPTH: &str = "LUXEVAL_MAX_PRIM_DEPTH";
pub(crate) const ENV_MAX_MESH_TRIANGLES: &str = "LUXEVAL_MAX_MESH_TRIANGLES";

/// The longest chain of nested composition arcs (references, payloads, inherits, specializes)
/// openusd 0.8 composes: measured, a prim at the head of a chain of 98 references composes and
/// one of 99 is abandoned as if it were a cycle (openusd's `MAX_DEPTH` of 100 counts the frames
/// around the chain; usd-core has no such limit). Not configurable: luxeval cannot change its USD
/// reader, so a longer chain is refused with this limit named instead of being composed without
/// its light. `tests/bad_inputs.rs` checks both sides of it.
#[cfg(feature = "usd")]
pub(crate) const MAX_ARC_DEPTH: u64 = 98;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            // 2^26 rows of float64 (N, 3) with its header.
            max_file_bytes: 2 << 30,
            // 2^26 rows: 1.5 GiB of f64 RGB on the CPU path, 0.75 GiB of float32 output.
            max_samples: 1 << 26,
            // Measured on a release build: ~2.5 KB per plain prim, ~9 KB per prim composed through
            // references, ~0.4 ms each: a stage at the limit needs a few GB and tens of seconds.
            max_prims: 1_000_000,
            max_prim_depth: 1_000,
            // 2^22 triangles: 300 MiB of f64 world-space vertices, and a mesh 40 times the
            // 100,000 triangles the benchmark prepares. The points behind them are
            // already bounded by the file limit.
            max_mesh_triangles: 1 << 22,
        }
    }
}

impl Limits {
    /// The variable that sets [`Limits::max_file_bytes`].
    pub const ENV_MAX_FILE_BYTES: &str = ENV_MAX_FILE_BYTES;
    /// The variable that sets [`Limits::max_samples`].
    pub const ENV_MAX_SAMPLES: &str = ENV_MAX_SAMPLES;
    /// The variable that sets [`Limits::max_prims`].
    pub const ENV_MAX_PRIMS: &str = ENV_MAX_PRIMS;
    /// The variable that sets [`Limits::max_prim_depth`].
    pub const ENV_MAX_PRIM_DEPTH: &str = ENV_MAX_PRIM_DEPTH;
    /// The variable that sets [`Limits::max_mesh_triangles`].
    pub const ENV_MAX_MESH_TRIANGLES: &str = ENV_MAX_MESH_TRIANGLES;

    /// "set NAME to raise it; see docs/INPUTS.md": the end of every message about a limit.
    pub fn raise_hint(env: &str) -> String {
        raise_hint(env)
    }

    /// A positive integer from the environment variable `name` (underscores allowed), or
    /// `default` when it is unset; anything else is refused naming the variable. The one
    /// parser of luxeval's `LUXEVAL_*` numbers.
    pub fn env_var(name: &str, default: u64) -> Result<u64> {
        var(name, default)
    }

    /// The defaults, each overridden by its environment variable when set.
    pub fn from_env() -> Result<Limits> {
        let d = Limits::default();
        Ok(Limits {
            max_file_bytes: var(ENV_MAX_FILE_BYTES, d.max_file_bytes)?,
            max_samples: var(ENV_MAX_SAMPLES, d.max_samples)?,
            max_prims: var(ENV_MAX_PRIMS, d.max_prims)?,
            max_prim_depth: var(ENV_MAX_PRIM_DEPTH, d.max_prim_depth)?,
            max_mesh_triangles: var(ENV_MAX_MESH_TRIANGLES, d.max_mesh_triangles)?,
        })
    }

    /// Refuses `count` rows of `what` over [`Limits::max_samples`].
    pub fn check_samples(&self, what: &str, count: u64) -> Result<()> {
        if count > self.max_samples {
            return Err(LuxError::input(
                what,
                format!(
                    "{count} rows exceed the limit of {} ({})",
                    self.max_samples,
                    raise_hint(ENV_MAX_SAMPLES)
                ),
            ));
        }
        Ok(())
    }
}

/// "set NAME to raise it": the end of every message about a limit.
pub(crate) fn raise_hint(env: &str) -> String {
    format!("set {env} to raise it; see docs/INPUTS.md")
}

/// A positive integer from the environment variable `name`, or `default` when it is unset.
pub(crate) fn var(name: &str, default: u64) -> Result<u64> {
    match std::env::var(name) {
        Err(std::env::VarError::NotPresent) => Ok(default),
        Ok(s) => match s.trim().replace('_', "").parse::<u64>() {
            Ok(v) if v > 0 => Ok(v),
            _ => Err(LuxError::input(
                name,
                format!("{s:?} is not a positive integer"),
            )),
        },
        Err(e) => Err(LuxError::input(name, e.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_over_the_limit_name_the_variable() {
        let l = Limits {
            max_samples: 10,
            ..Limits::default()
        };
        assert!(l.check_samples("--samples", 10).is_ok());
        let e = l.check_samples("--samples", 11).unwrap_err().to_string();
        assert!(
            e.contains("--samples") && e.contains("11") && e.contains(ENV_MAX_SAMPLES),
            "{e}"
        );
    }
}
