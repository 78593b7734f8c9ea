//! The persistent pipeline cache (src/gpu/cache.rs), through the command line so that each run
//! is a fresh process with its own environment: the cache file is written under
//! `LUXEVAL_CACHE_DIR` once a pipeline is compiled, a corrupt or truncated file costs nothing but
//! a compile (the results are bitwise the same), an empty `LUXEVAL_CACHE_DIR` disables it, and
//! `luxeval info` reports each case.

use crate::common;
use crate::support::{asset, command};

use std::path::Path;
use std::process::Output;

fn luxeval(cache_dir: &Path, args: &[&str]) -> Output {
    let o = command()
        .args(args)
        .env("LUXEVAL_CACHE_DIR", cache_dir)
        .output()
        .expect("run luxeval");
    assert!(
        o.status.success(),
        "luxeval {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn emission(cache_dir: &Path, out: &Path) -> Vec<u8> {
    luxeval(
        cache_dir,
        &[
            "emission",
            &asset("studio.usda"),
            "--dirs",
            &asset("dirs.npy"),
            "-o",
            out.to_str().unwrap(),
            "--device",
            "gpu",
        ],
    );
    std::fs::read(out).unwrap()
}

fn cache_files(dir: &Path) -> Vec<std::path::PathBuf> {
    match std::fs::read_dir(dir) {
        Ok(entries) => entries.map(|e| e.unwrap().path()).collect(),
        Err(_) => Vec::new(),
    }
}

#[test]
fn pipeline_cache_is_written_survives_corruption_and_can_be_disabled() {
    let Some(eval) = common::gpu() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let out = tmp.path().join("e.npy");

    if eval.pipeline_cache().is_some_and(|c| c.reason.is_some()) {
        // An adapter without a pipeline cache (not Vulkan, or no PIPELINE_CACHE): info says so.
        let info = luxeval(&cache, &["info"]);
        assert!(String::from_utf8_lossy(&info.stdout).contains("pipeline cache: not used"));
        return;
    }
    // A first run compiles and saves: exactly one cache file, named for the adapter.
    let first = emission(&cache, &out);
    let files = cache_files(&cache);
    assert_eq!(files.len(), 1, "{files:?}");
    let file = &files[0];
    assert!(
        file.file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with("wgpu_pipeline_cache_"),
        "{file:?}"
    );
    assert!(std::fs::metadata(file).unwrap().len() > 0);
    let info = String::from_utf8_lossy(&luxeval(&cache, &["info"]).stdout).into_owned();
    assert!(
        info.contains(&file.display().to_string()) && info.contains("bytes loaded"),
        "{info}"
    );

    // A second run reads it; the results are the same bits.
    assert_eq!(emission(&cache, &out), first);

    // Garbage, or a truncated copy, in place of the file: ignored (wgpu and the driver check
    // their headers), same results, and the file is rewritten whole.
    let good = std::fs::read(file).unwrap();
    for bad in [
        b"not a pipeline cache".to_vec(),
        good[..good.len() / 2].to_vec(),
    ] {
        std::fs::write(file, &bad).unwrap();
        assert_eq!(emission(&cache, &out), first);
        assert_ne!(std::fs::read(file).unwrap(), bad);
    }
    // No temporary file is left beside it.
    assert_eq!(cache_files(&cache).len(), 1, "{:?}", cache_files(&cache));

    // An empty LUXEVAL_CACHE_DIR disables the cache.
    let info = String::from_utf8_lossy(&luxeval(Path::new(""), &["info"]).stdout).into_owned();
    assert!(
        info.contains("pipeline cache: not used: disabled"),
        "{info}"
    );
}
