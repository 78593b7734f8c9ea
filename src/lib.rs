//! luxeval evaluates USD lights (UsdLux) in wgpu compute shaders and cross-checks every GPU
//! result against an f64 CPU reference.
//!
//! ```
//! use luxeval::{Accumulate, Evaluator, Light, Shaping};
//! use glam::{DMat4, DVec3};
//!
//! // A 2 × 1 rect light 3 m up, facing down, shaped into a 40° spot.
//! let light = Light::rect(2.0, 1.0)
//!     .with_path("/lights/key")
//!     .with_intensity(10.0)
//!     .with_shaping(Shaping { cone_angle: 40.0, cone_softness: 0.2, ..Shaping::default() })
//!     .with_transform(DMat4::from_rotation_translation(
//!         glam::DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2), // local −Z → world −Y
//!         DVec3::new(0.0, 3.0, 0.0),
//!     ));
//!
//! // Radiance arriving at the floor point (0, 0, 0) looking straight up, on the CPU reference.
//! let cpu = Evaluator::cpu();
//! let rgb = cpu.radiance(&[light.clone()], &[[0.0, 0.0, 0.0]], &[[0.0, 1.0, 0.0]], Accumulate::Sum)?;
//! assert_eq!(rgb[0], [10.0, 10.0, 10.0]);
//!
//! // The same query on the GPU, when one is available.
//! if let Ok(gpu) = Evaluator::gpu() {
//!     let g = gpu.radiance(&[light], &[[0.0, 0.0, 0.0]], &[[0.0, 1.0, 0.0]], Accumulate::Sum)?;
//!     assert!((g[0][0] - 10.0).abs() < 1e-4);
//! }
//! # Ok::<(), luxeval::LuxError>(())
//! ```

// Comparisons written `!(x > y)` reject NaN on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// The data flow of DESIGN.md §1, each module depending only on those above it:
// model → usd → prepare → cpu | gpu → query → io, falloff → the CLI (src/bin/luxeval).
// `assets` (readers of referenced files) is a leaf that `prepare` uses.
// `rules` holds what the WGSL kernels and their f64 counterparts share; neither backend owns it.
pub(crate) mod assets;
#[cfg(any(test, feature = "testkit"))]
pub mod check;
pub(crate) mod cpu;
pub(crate) mod error;
pub mod falloff;
pub(crate) mod gpu;
pub mod ies;
pub mod io;
pub mod limits;
pub(crate) mod model;
pub mod plot;
pub(crate) mod prepare;
pub(crate) mod query;
pub(crate) mod rules;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
#[cfg(feature = "usd")]
pub(crate) mod usd;

/// Compiles and runs the README's examples as doctests.
#[cfg(all(doctest, feature = "usd"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

pub use error::{GpuFailure, LuxError, Result};
pub use gpu::cache::CACHE_DIR_ENV as PIPELINE_CACHE_DIR_ENV;
pub use gpu::{AdapterSummary, CacheStatus, DeviceLimits, Startup, adapters};
pub use limits::Limits;
pub use model::{
    Asset, Ies, Input, Light, LightInputs, LightType, PoleAxis, Shaping, Texture, TextureFilter,
    TextureFormat, UpAxis, Value, schema,
};
pub use prepare::TemperatureMode;
#[cfg(feature = "usd")]
pub use query::lights_json;
pub use query::{Accumulate, Evaluator, Power, PreparedScene, Reference};
#[cfg(feature = "usd")]
pub use usd::{Scene, SceneLight, Stage, StageInfo, TimeRule};
/// The wgpu luxeval is built with: GPU-resident callers ([`Evaluator::from_wgpu`],
/// [`PreparedScene::encode_emission`]) create their device and buffers with this one, so that
/// the types match.
pub use wgpu;
