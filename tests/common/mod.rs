//! Helpers shared by the integration tests.
#![allow(dead_code)]

use luxeval::gpu::GpuContext;

/// A GPU context, or `None` (with a note) when this machine has no adapter. Under `CI=true` a
/// missing adapter fails the test instead: CI installs lavapipe, so no adapter there is a bug.
pub fn gpu() -> Option<GpuContext> {
    match GpuContext::new() {
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
