//! Test support for the test suites and benches (behind the `testkit` feature; nothing the
//! command line ships): the seeded lights and samples of `synthetic`, textured and IES-shaped
//! variants, the WGSL irradiance kernel's rule replayed in f64 (so that tests can separate its
//! quadrature error from f32 rounding), and the internals the tests look into (the IES reader
//! and lookup step by step, the WGSL sources, the conformance check's margins).

pub mod dome;
pub mod ies;
pub mod ies_replay;
pub mod kernel_rule;
pub mod rect;
pub mod sample;

pub use crate::synthetic::{
    MESH_CLASSES, MeshSource, Rng, TRANSFORMS, emission_samples, irradiance_samples,
    radiance_samples, random_light, random_lights, random_mesh_light, random_mesh_lights,
    random_portal_dome, synthetic_lights, synthetic_mesh_light, torus, torus_rays, transform,
};
pub use kernel_rule::kernel_rule_irradiance;

/// `scene` with its GPU-resident emission, intensity and radiance queries taking `rows` rows
/// per invocation (1 to 16; WGSL's `ROWS_PER_INVOCATION`), on any adapter: the tests' way to run
/// the several-rows path on lavapipe, and the benchmark's to compare counts
/// (`examples/resident.rs`). On llvmpipe, keep `rows ×` the lights of a dispatch well under
/// its loop budget (65,535 iterations an invocation).
pub fn with_rows_per_invocation(
    mut scene: crate::PreparedScene,
    rows: u32,
) -> crate::PreparedScene {
    scene.rows_per_invocation = Some(rows);
    scene
}

/// The WGSL sources and the GPU record layouts, for the offline naga checks of `tests/wgsl.rs`
/// and `tests/twins.rs`.
pub mod wgsl {
    pub use crate::gpu::record::{Params, Record};
    pub use crate::gpu::shaders::{Features, Kernel, SOURCES, compose, compose_file};
    pub use crate::rules::IRR_GL_INNER;
}

/// The IES reader and the f64 lookup step by step (twin of `shaders/shared/ies.wgsl`):
/// light-space direction → photometric angles → angleScale → folds → bilinear on the file's
/// own grid.
pub mod ies_parts {
    pub use crate::assets::ies::eulumdat::parse_eulumdat;
    pub use crate::assets::ies::lm63::{TypeCCoverage, type_c_coverage};
    pub use crate::assets::ies::{parse_any, parse_lm63};

    pub mod lookup {
        pub use crate::cpu::ies::{
            bilinear, fold_h_type_c, fold_mirror, ies_factor, photometric_angles,
            scale_polar_angle, scaled_direction, type_a_angles, type_b_angles, type_c_angles,
        };
    }
    pub use lookup::ies_factor;
}

/// The conformance check and its parts: per-sample errors, sample counts and the excluded
/// band.
pub mod check {
    pub use crate::conformance::band::{
        F32_ROUNDING, IRRADIANCE_SLIVER_FACTOR, emission_margin, intensity_margin,
        irradiance_margin, near_texture_edge, radiance_margin, texture_floor,
    };
    pub use crate::conformance::{
        BAND, CONE_BAND, CheckReport, CheckedQuery, QueryReport, Samples, TOLERANCE, WorstSample,
        check, check_with, rel_error, rel_error_above,
    };
}
