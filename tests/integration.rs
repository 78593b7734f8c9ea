//! The library's integration tests (the command line's are in cli/tests/): one test binary (Cargo.toml: `autotests = false` and this `[[test]]`)
//! whose modules are the files of tests/, each test named `FILE::TEST` (`cargo test
//! --ignore-rust-version a11_floor::` runs tests/a11_floor.rs). One binary instead of one per
//! file: each test binary links wgpu, naga and openusd, and 32 of those links were most of the
//! build time of `cargo test`. A new test file is a module listed here.
//!
//! The tests of all the files run in this one process, two or more at a time (libtest's
//! threads), so no test changes process-wide state (environment variables, current
//! directory): a test that needs another environment runs the command line with it
//! (`Command::env`). The files that need the `usd` or `cli` feature say so with
//! `#![cfg(feature = ...)]` at their top, which removes the module when it is off.

mod common;
mod ies_common;

mod a11_floor;
mod blackbody_fixture;
mod conformance;
mod determinism;
mod dome_conformance;
mod dome_formats;
mod dome_irradiance;
mod ies_atlas;
mod ies_conformance;
mod ies_eulumdat;
mod ies_integrals;
mod ies_lm63;
mod ies_lookup;
mod ies_luxtest;
mod ies_report;
mod intensity;
mod irradiance;
mod layers;
mod luxtest_check;
mod math;
mod mesh_conformance;
mod mesh_emission_gpu;
mod mesh_irradiance_gpu;
mod mesh_lights;
mod portal_gpu;
mod rect_conformance;
mod resident;
mod robustness;
mod sample_conformance;
mod sample_resident;
mod sampling;
mod stage_progress;
mod tolerance;
mod twins;
mod usd_fixtures;
mod usd_parity;
mod usd_rect_texture;
mod wgsl;

/// Every file of tests/ is a module above (with `autotests = false`, a file left out would be
/// compiled by nothing and its tests would never run).
#[test]
fn every_test_file_is_a_module_of_this_binary() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    common::assert_every_file_is_a_module(&dir);
}
