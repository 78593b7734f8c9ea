//! The photometric reader on arbitrary bytes (`parse_any`: LM-63 of every version and
//! EULUMDAT, told apart by content) and everything a parsed file feeds: the prepared profile, its
//! exact mean over the sphere, flux, tilt, the f64 lookup and the report `luxeval ies` prints.
//! Invariants beyond "no panic, no hang, bounded memory": the mean lies in [0, peak]; every
//! lookup is finite and in [0, peak].
#![no_main]

use glam::DVec3;
use luxeval::IesProfile;
use luxeval::testkit::ies_parts::parse_any;
use luxeval_cli::ies_report::Report;

/// `TILT=<name>`: names starting with 'a' resolve to a small valid table, others are missing.
fn resolver(name: &str) -> Result<Vec<u8>, String> {
    if name.starts_with('a') {
        Ok(b"1\r\n3\r\n0 45 90\r\n1 0.8 0.5\r\n".to_vec())
    } else {
        Err(format!("{name}: not found"))
    }
}

const DIRS: [[f64; 3]; 10] = [
    [0.0, 0.0, -1.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.3, -0.4, -0.866],
    [-0.6, 0.48, 0.64],
    [0.577, 0.577, -0.577],
    [-0.2, -0.9, 0.387],
];

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(file) = parse_any(data, &resolver) else {
        return;
    };
    let Ok(p) = IesProfile::new(&file) else {
        return;
    };
    let peak = p.peak().candela;
    let mean = p.mean_intensity();
    assert!(
        mean.is_finite() && mean >= 0.0 && mean <= peak * (1.0 + 1e-9),
        "mean {mean}, peak {peak}"
    );
    let _ = (p.flux_lm(), p.tilt_factor(30.0));
    for d in DIRS {
        let e = DVec3::from_array(d).normalize();
        for s in [0.0, 0.5, -2.0] {
            let f = p.candela(e, s);
            assert!(
                f.is_finite() && f >= 0.0 && f <= peak * (1.0 + 1e-12),
                "factor {f}, peak {peak}"
            );
        }
    }
    let report = Report::new(std::path::Path::new("fuzz.ies"), &file, &p);
    let _ = report.plot(&p);
});
