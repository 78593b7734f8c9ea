//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::Path;

use luxeval::Evaluator;
use luxeval::testkit::Rng;

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

/// `bytes` with one random corruption: truncated, overwritten, cut or with junk inserted.
pub fn mutate(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = bytes.to_vec();
    match rng.below(4) {
        0 => b.truncate(rng.below(b.len().max(1))),
        1 => {
            for _ in 0..1 + rng.below(8) {
                let i = rng.below(b.len().max(1));
                if i < b.len() {
                    b[i] = (rng.next_u64() & 0xff) as u8;
                }
            }
        }
        2 => {
            let i = rng.below(b.len().max(1));
            let j = (i + rng.below(64)).min(b.len());
            b.drain(i..j);
        }
        _ => {
            let i = rng.below(b.len().max(1));
            let junk: Vec<u8> = (0..rng.below(16))
                .map(|_| b"{}()[]\"=:;@,.-0123456789e#\n "[rng.below(27)])
                .collect();
            b.splice(i..i, junk);
        }
    }
    b
}

pub fn fuzz_file(src: &Path, ext: &str, rounds: usize, seed: u64, load: impl Fn(&Path)) {
    let bytes = std::fs::read(src).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng::new(seed);
    for k in 0..rounds {
        let m = mutate(&bytes, &mut rng);
        let p = dir.path().join(format!("m{k}.{ext}"));
        std::fs::write(&p, &m).unwrap();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load(&p)));
        assert!(
            r.is_ok(),
            "panic on mutation {k} of {} (kept at {})",
            src.display(),
            {
                let keep = std::env::temp_dir().join(format!("luxeval-crash-{k}.{ext}"));
                std::fs::write(&keep, &m).unwrap();
                keep.display().to_string()
            }
        );
    }
}

/// Every file (or folder with a `mod.rs`) of the test folder `dir` is a `mod` line of its
/// `integration.rs` (with `autotests = false`, a file left out would be compiled by nothing and
/// its tests would never run).
pub fn assert_every_file_is_a_module(dir: &Path) {
    let root = std::fs::read_to_string(dir.join("integration.rs")).unwrap();
    let listed: Vec<&str> = root
        .lines()
        .filter_map(|l| l.strip_prefix("mod ")?.strip_suffix(';'))
        .collect();
    let mut files = 0;
    for e in std::fs::read_dir(dir).unwrap() {
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
            "{}/{name} is not a module of its integration.rs: its tests would not run",
            dir.display()
        );
    }
    assert!(files > 0, "no test files in {}", dir.display());
}
