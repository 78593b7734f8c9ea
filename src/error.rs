//! Typed library errors. Every variant names what the user must look at (the light's prim path,
//! the attribute, the file) and keeps the error it came from as its `source`. `Display` already
//! includes the source's message, so a caller reports an error once by printing it.

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

    /// Query input arrays of the wrong shape or content, or a bad argument.
    #[error("{what}: {reason}")]
    InvalidInput { what: String, reason: String },

    /// A light that a GPU-resident query (`PreparedScene::encode_*`) cannot evaluate on the
    /// device: its value is computed on the host (the irradiance of textured domes and rects,
    /// of most masked domes, and of IES profiles bent by angleScale), and the GPU-resident path
    /// has no host step.
    #[error("light {light}: {query} cannot be evaluated GPU-resident: {reason}")]
    NotOnDevice {
        light: String,
        query: String,
        reason: String,
    },

    /// A query luxeval does not perform for this light yet (sampling a mesh light): refused
    /// rather than answered without it.
    #[error("light {light}: {query} is not supported for it yet: {reason}")]
    NotSupported {
        light: String,
        query: String,
        reason: String,
    },

    /// No wgpu adapter could be found.
    #[error(
        "no GPU adapter found ({reason}); use --device cpu, or install a Vulkan driver (e.g. Mesa's lavapipe: mesa-vulkan-drivers)"
    )]
    NoAdapter {
        reason: String,
        #[source]
        source: Option<wgpu::RequestAdapterError>,
    },

    /// The adapter refused to open a device.
    #[error("GPU: cannot open {adapter}: {source}")]
    DeviceRequest {
        adapter: String,
        #[source]
        source: wgpu::RequestDeviceError,
    },

    /// The GPU failed while working: validation, out of memory, device lost, readback.
    #[error("GPU: {context}: {source}")]
    Gpu {
        context: String,
        #[source]
        source: GpuFailure,
    },

    /// A file could not be read (or an output could not be created where the path says).
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// Writing an output failed once it was under way (disk full, I/O error): a runtime failure,
    /// not bad input.
    #[error("writing {}: {source}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// A file a light references (an IES profile, a texture) cannot be read or parsed.
    #[error("light {light}: {attr} @{path}@: {source}")]
    Asset {
        light: String,
        attr: String,
        path: String,
        /// Boxed: the readers' errors are large, and every `Result` of the crate carries this.
        #[source]
        source: Box<AssetError>,
    },

    /// The caller gave up reading a stage ([`crate::Stage::load_with_progress`]'s `progress`
    /// returned `Break`).
    #[error("{}: reading the stage was cancelled", path.display())]
    Cancelled { path: PathBuf },

    /// A file's content is malformed or unsupported.
    #[error("{}{}: {reason}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Format {
        path: PathBuf,
        line: Option<usize>,
        reason: String,
    },
}

/// Why a referenced file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum AssetError {
    /// The stage resolves the path to no existing file.
    #[error("cannot be resolved: no such file beside the layer that authors it")]
    Unresolved,
    /// Reading it failed.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// An IES (LM-63) or EULUMDAT profile that cannot be read (the message names the line).
    #[error(transparent)]
    Ies(#[from] crate::assets::ies::IesError),
    /// A texture that cannot be decoded (the message names the file and, for OpenEXR, an
    /// unsupported compression).
    #[error(transparent)]
    Texture(#[from] crate::assets::texture::TextureError),
    /// A dome texture whose `texture:format` does not fit the image (DESIGN.md §6 D5, D6).
    #[error(transparent)]
    TextureFormat(#[from] crate::assets::texture::FormatError),
}

/// What went wrong on the GPU, keeping wgpu's own error.
#[derive(Debug, thiserror::Error)]
pub enum GpuFailure {
    /// Validation, out-of-memory or internal errors caught by an error scope.
    #[error(transparent)]
    Wgpu(#[from] wgpu::Error),
    /// Waiting for the device failed.
    #[error(transparent)]
    Poll(#[from] wgpu::PollError),
    /// Mapping a readback buffer failed.
    #[error(transparent)]
    Map(#[from] wgpu::BufferAsyncError),
    /// Viewing a mapped buffer failed.
    #[error(transparent)]
    View(#[from] wgpu::MapRangeError),
    /// The device went away (a callback was dropped unanswered).
    #[error("the device was lost")]
    Lost,
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

    /// A file light `light` references through attribute `attr` (authored as `path`) cannot
    /// be used.
    pub(crate) fn asset(light: &str, attr: &str, path: &str, source: AssetError) -> Self {
        LuxError::Asset {
            light: light.into(),
            attr: attr.into(),
            path: path.into(),
            source: Box::new(source),
        }
    }

    /// [`LuxError::InvalidInput`]: `what` (an argument, a file, a prim) is refused for `reason`.
    pub fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        LuxError::InvalidInput {
            what: what.into(),
            reason: reason.into(),
        }
    }

    pub(crate) fn gpu(context: impl Into<String>, source: impl Into<GpuFailure>) -> Self {
        LuxError::Gpu {
            context: context.into(),
            source: source.into(),
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
                | LuxError::NotOnDevice { .. }
                | LuxError::NotSupported { .. }
                | LuxError::Io { .. }
                | LuxError::Asset { .. }
                | LuxError::Format { .. }
        )
    }
}
