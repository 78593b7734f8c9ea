//! The stage loader on arbitrary .usdc bytes.
#![no_main]

#[path = "stage.rs"]
mod stage;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    stage::load("usdc", data);
});
