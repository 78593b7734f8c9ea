//! The command line's integration tests: one test binary (Cargo.toml: `autotests = false` and
//! this `[[test]]`) whose modules are the files of cli/tests/, each test named `FILE::TEST`
//! (`cargo test --ignore-rust-version -p luxeval-cli stream::` runs cli/tests/stream.rs). They
//! run the `luxeval` binary (`CARGO_BIN_EXE_luxeval`) on the repository's test data
//! (tests/data/, assets/) and compare it with the library.
//!
//! As in the library's tests, no test changes process-wide state: a test that needs another
//! environment runs the command line with it (`Command::env`).

use std::path::{Path, PathBuf};

/// The library's test helpers (a GPU evaluator or a skip, the file mutator).
#[path = "../../tests/common/mod.rs"]
mod common;

mod bad_inputs;
mod cli;
mod lights;
mod maps;
mod mesh;
mod pipeline_cache;
mod portals;
mod random_stages;
mod robustness;
mod sample;
mod stream;
mod stream_refusals;
mod support;

/// The repository's root, where tests/data/ and assets/ are.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("cli/ is a folder of the repository")
        .to_path_buf()
}

/// Every file of cli/tests/ is a module above.
#[test]
fn every_test_file_is_a_module_of_this_binary() {
    common::assert_every_file_is_a_module(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests"));
}
