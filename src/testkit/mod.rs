//! Test support shared by the test suites, `luxeval check` and `luxeval bench` (behind the
//! `testkit` feature; the `cli` feature enables it): a seeded generator, randomised lights of
//! every type and transform, sample generators, and the WGSL irradiance kernel's rule replayed
//! in f64 (so that tests can separate its quadrature error from f32 rounding).

pub mod dome;
pub mod ies;
pub mod ies_replay;
pub mod kernel_rule;
pub mod lights;
pub mod rect;
mod rng;
pub mod samples;

pub use kernel_rule::kernel_rule_irradiance;
pub use lights::{TRANSFORMS, random_light, random_lights, synthetic_lights, transform};
pub use rng::Rng;
pub use samples::{emission_samples, irradiance_samples, radiance_samples};

/// The WGSL sources and the GPU record layouts, for the offline naga checks of `tests/wgsl.rs`
/// and `tests/twins.rs`.
pub mod wgsl {
    pub use crate::gpu::record::{Params, Record};
    pub use crate::gpu::shaders::{Features, Kernel, SOURCES, compose, compose_file};
    pub use crate::rules::IRR_GL_INNER;
}
