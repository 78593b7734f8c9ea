//! The integration tests: one test binary (Cargo.toml: `autotests = false` and this `[[test]]`)
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
mod bad_inputs;
mod blackbody_fixture;
mod cli;
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
mod pipeline_cache;
mod rect_conformance;
mod resident;
mod robustness;
mod stream;
mod tolerance;
mod twins;
mod usd_fixtures;
mod usd_rect_texture;
mod wgsl;

/// Every file of tests/ is a module above (with `autotests = false`, a file left out would be
/// compiled by nothing and its tests would never run).
#[test]
fn every_test_file_is_a_module_of_this_binary() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let root = std::fs::read_to_string(dir.join("integration.rs")).unwrap();
    let listed: Vec<&str> = root
        .lines()
        .filter_map(|l| l.strip_prefix("mod ")?.strip_suffix(';'))
        .collect();
    let mut files = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let name = if p.is_dir() && p.join("mod.rs").is_file() {
            p.file_name().unwrap().to_string_lossy().into_owned()
        } else if p.extension().is_some_and(|x| x == "rs") && !p.ends_with("integration.rs") {
            p.file_stem().unwrap().to_string_lossy().into_owned()
        } else {
            continue;
        };
        files += 1;
        assert!(
            listed.contains(&name.as_str()),
            "tests/{name} is not a module of tests/integration.rs: its tests would not run"
        );
    }
    assert_eq!(files, listed.len(), "{listed:?}");
}
