//! Typed library errors. Every variant names what the user must look at: the light (prim path),
//! the attribute, the file.

use std::path::PathBuf;

/// Result alias used across the library.
pub type Result<T, E = LuxError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum LuxError {
    /// An attribute value luxeval cannot evaluate (NaN, infinite, negative size, ...).
    #[error("light {light}: attribute {attr} = {value}: {reason}")]
    InvalidAttribute {
        light: String,
        attr: String,
        value: String,
        reason: String,
    },

    /// A light's world transform cannot be used (not affine, singular, not finite).
    #[error("light {light}: world transform {reason}")]
    InvalidTransform { light: String, reason: String },

    /// Query input arrays of the wrong shape or content.
    #[error("{what}: {reason}")]
    InvalidInput { what: String, reason: String },

    /// No wgpu adapter could be found.
    #[error(
        "no GPU adapter found ({0}); use --device cpu, or install a Vulkan driver (e.g. Mesa's lavapipe: mesa-vulkan-drivers)"
    )]
    NoAdapter(String),

    /// The GPU device failed: creation, validation, out of memory, device lost, readback.
    #[error("GPU: {0}")]
    Gpu(String),

    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// A file's content is malformed or unsupported.
    #[error("{}{}: {reason}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Format {
        path: PathBuf,
        line: Option<usize>,
        reason: String,
    },
}

impl LuxError {
    pub(crate) fn attr(
        light: &str,
        attr: &str,
        value: impl std::fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        LuxError::InvalidAttribute {
            light: light.to_string(),
            attr: attr.to_string(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }

    pub(crate) fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        LuxError::InvalidInput {
            what: what.into(),
            reason: reason.into(),
        }
    }

    /// True for errors caused by the user's input (exit code 2 in the CLI), false for runtime
    /// failures (exit code 1).
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            LuxError::InvalidAttribute { .. }
                | LuxError::InvalidTransform { .. }
                | LuxError::InvalidInput { .. }
                | LuxError::Io { .. }
                | LuxError::Format { .. }
        )
    }
}
