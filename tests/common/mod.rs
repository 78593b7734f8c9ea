//! Helpers shared by the integration tests.
#![allow(dead_code)]

use luxeval::Evaluator;

/// A GPU evaluator, or `None` (with a note) when this machine has no adapter. Under `CI=true` a
/// missing adapter fails the test instead: CI installs lavapipe, so no adapter there is a bug.
pub fn gpu() -> Option<Evaluator> {
    match Evaluator::gpu() {
        Ok(g) => Some(g),
        Err(e) => {
            if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") {
                panic!("CI=true but no GPU adapter: {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}

/// Whether the evaluator runs on Mesa's llvmpipe (lavapipe, CI's CPU Vulkan driver).
pub fn is_llvmpipe(eval: &Evaluator) -> bool {
    eval.adapter()
        .is_some_and(|a| a.name.to_lowercase().contains("llvmpipe"))
}
