//! Malformed .npy input never panics: truncated and corrupted files give errors.

use crate::common::fuzz_file;

#[test]
fn corrupted_npy_never_panics() {
    let root = crate::repo();
    fuzz_file(
        &root.join("tests/data/npy/dirs_f32.npy"),
        "npy",
        300,
        3,
        |p| {
            let _ = luxeval_cli::io::npy::read_vec3(p);
        },
    );
}
