//! The .npy reader on arbitrary bytes: as points, directions and plain rows.
#![no_main]

use std::io::Write;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("luxeval-fuzz-{}.npy", std::process::id()));
    std::fs::File::create(&path)
        .and_then(|mut f| f.write_all(data))
        .expect("scratch file");
    let _ = luxeval_cli::io::npy::read_vec3(&path);
    if let Ok(p) = luxeval_cli::io::npy::read_points(&path) {
        assert!(p.iter().flatten().all(|v| v.is_finite()));
    }
    if let Ok(d) = luxeval_cli::io::npy::read_directions(&path) {
        // Every direction read is finite and non-zero (float64 rows also unit length).
        for r in d {
            let n = (r[0] as f64).hypot(r[1] as f64).hypot(r[2] as f64);
            assert!(n.is_finite() && n > 0.0, "{r:?}");
        }
    }
});
