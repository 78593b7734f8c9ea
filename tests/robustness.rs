//! Malformed input never panics: truncated and corrupted stages and .npy files give errors.
#![cfg(feature = "usd")]

use std::path::Path;

use luxeval::Scene;
use luxeval::testkit::Rng;

fn mutate(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
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

fn fuzz_file(src: &Path, ext: &str, rounds: usize, seed: u64, load: impl Fn(&Path)) {
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

#[test]
fn corrupted_usda_never_panics() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    fuzz_file(&root.join("assets/studio.usda"), "usda", 300, 1, |p| {
        let _ = Scene::load(p, None).and_then(|s| s.evaluable(&[]));
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
            let _ = Scene::load(p, None).and_then(|s| s.evaluable(&[]));
        });
    }
}

#[test]
fn corrupted_npy_never_panics() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    fuzz_file(
        &root.join("tests/data/npy/dirs_f32.npy"),
        "npy",
        300,
        3,
        |p| {
            let _ = luxeval::io::npy::read_vec3(p);
        },
    );
}
