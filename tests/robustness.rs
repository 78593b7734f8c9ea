//! Malformed input never panics: truncated and corrupted stages give errors (the .npy reader:
//! cli/tests/robustness.rs).
#![cfg(feature = "usd")]

use std::path::Path;

use crate::common::fuzz_file;
use luxeval::Stage;

#[test]
fn corrupted_usda_never_panics() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    fuzz_file(&root.join("assets/studio.usda"), "usda", 300, 1, |p| {
        let _ = Stage::load(p, None).and_then(|s| s.evaluable(&[]));
    });
}

#[test]
fn corrupted_usdc_and_usdz_never_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (f, ext) in [
        ("tests/data/usd/composition/root.usdc", "usdc"),
        ("tests/data/usd/composition/scene.usdz", "usdz"),
    ] {
        let src = root.join(f);
        if !src.exists() {
            panic!("missing fixture {f}");
        }
        fuzz_file(&src, ext, 150, 2, |p| {
            let _ = Stage::load(p, None).and_then(|s| s.evaluable(&[]));
        });
    }
}
