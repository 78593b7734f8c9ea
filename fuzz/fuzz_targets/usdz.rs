//! The stage loader on arbitrary .usdz bytes.
#![no_main]

#[path = "stage.rs"]
mod stage;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    stage::load("usdz", data);
});
