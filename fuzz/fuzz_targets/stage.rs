//! Shared by the stage targets: the bytes become a file with the format's extension (openusd
//! reads stages from paths) and go through everything `luxeval lights` and every query do to a
//! stage: the arc walk, openusd's composition, reading every light at its default time, and
//! validating and preparing each evaluable light. Any error is fine; a panic, an abort, a hang
//! or unbounded memory is what libFuzzer reports.

use std::io::Write;
use std::path::PathBuf;

/// A file in memory-backed /dev/shm when there is one (fast), else the temporary directory;
/// one per process, rewritten for every input.
fn scratch(ext: &str) -> PathBuf {
    let dir = if std::path::Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    dir.join(format!("luxeval-fuzz-{}.{ext}", std::process::id()))
}

pub fn load(ext: &str, data: &[u8]) {
    let path = scratch(ext);
    {
        let mut f = std::fs::File::create(&path).expect("scratch file");
        f.write_all(data).expect("scratch write");
    }
    if let Ok(scene) = luxeval::Scene::load(&path, None) {
        let _ = serde_json_free_walk(&scene);
        if let Ok(lights) = scene.evaluable(&[]) {
            for l in &lights {
                let _ = luxeval::Reference::new(l, luxeval::TemperatureMode::Spec);
            }
        }
    }
}

/// Touches every listed input (what `lights` prints).
fn serde_json_free_walk(scene: &luxeval::Scene) -> usize {
    scene
        .lights
        .iter()
        .map(|l| l.inputs.len() + l.warning.as_ref().map_or(0, String::len))
        .sum()
}
