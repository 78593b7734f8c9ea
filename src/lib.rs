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
// model → usd → prepare → cpu | gpu → query → falloff, conformance. The command line, the
// Python package and the fuzz targets are crates of their own around this one (cli/, python/,
// fuzz/). `assets` (readers of referenced files) is a leaf that `prepare` uses; `rules` holds
// what the WGSL kernels and their f64 counterparts share, and neither backend owns it;
// `synthetic` (seeded lights and samples) serves the conformance check and the benchmarks.
//
// Every module is private: the re-exports below are the library's API.
pub(crate) mod assets;
pub(crate) mod conformance;
pub(crate) mod cpu;
pub(crate) mod error;
pub(crate) mod falloff;
pub(crate) mod gpu;
pub(crate) mod input;
pub(crate) mod limits;
pub(crate) mod model;
pub(crate) mod prepare;
pub(crate) mod query;
pub(crate) mod rules;
pub(crate) mod synthetic;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
#[cfg(feature = "usd")]
pub(crate) mod usd;

/// Compiles and runs the README's examples as doctests.
#[cfg(all(doctest, feature = "usd"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

pub use assets::ies::eulumdat::{EulumdatInfo, LampSet};
pub use assets::ies::lm63::{Format as IesFormat, Lm63Version, Tilt as IesTilt, TiltSource};
pub use assets::ies::{IesError, IesErrorKind, IesFile, PhotometricType, read_file as read_ies};
pub use assets::texture::{
    FormatError as TextureFormatError, MAX_PIXELS as MAX_TEXTURE_PIXELS, TextureError,
};
pub use conformance::{
    BAND as CHECK_BAND, CONE_BAND as CHECK_CONE_BAND, CheckReport, CheckedQuery, QueryReport,
    TOLERANCE as CHECK_TOLERANCE, WorstSample, check as check_against_reference,
};
pub use error::{AssetError, GpuFailure, LuxError, Result};
pub use falloff::{FalloffMap, FalloffPlane};
pub use gpu::cache::CACHE_DIR_ENV as PIPELINE_CACHE_DIR_ENV;
pub use gpu::{AdapterSummary, CacheStatus, DeviceLimits, Startup, adapters};
pub use input::{BadRow, RowKind, RowProblem};
pub use limits::Limits;
pub use model::{
    Asset, Ies, Input, Light, LightInputs, LightType, MeshGeometry, MeshLight, MeshTopology,
    MeshTriangle, PoleAxis, Portal, Shaping, Texture, TextureFilter, TextureFormat, Tint,
    TopologyError, UpAxis, Value, schema,
};
pub use prepare::ies::{
    FluxCheck, HFold as IesHFold, Peak as IesPeak, Plane as IesPlane, Profile as IesProfile,
    Spread as IesSpread, VFold as IesVFold,
};
pub use prepare::{PortalMode, TemperatureMode};
pub use query::{
    Accumulate, Evaluator, Power, PreparedScene, Reference, RowLayout, SampleOptions, SamplerCheck,
    Samples, Selection, StrategyVariance,
};
#[cfg(feature = "usd")]
pub use query::{lights_json, portal_multiplier};
pub use synthetic::{Rng, synthetic_lights, synthetic_mesh_light, torus_rays};
#[cfg(feature = "usd")]
pub use usd::{
    LightList, LinkCollection, LoadProgress, RefusedInput, Stage, StageInfo, StageLight, TimeRule,
    UsdStage,
};
/// The wgpu luxeval is built with: GPU-resident callers ([`Evaluator::from_wgpu`],
/// [`PreparedScene::encode_emission`]) create their device and buffers with this one, so that
/// the types match.
pub use wgpu;
