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

/// libFuzzer's panic hook aborts on every panic, also on one that luxeval catches. The stage
/// loader catches panics on its reading thread and reports them as errors naming the file
/// (openusd 0.8 has debug assertions that malformed files reach; see `on_large_stack` in
/// src/usd/scene.rs). This hook lets exactly those through, panics located in openusd's
/// sources, and still aborts on every other panic: one in luxeval's own code is a bug to fix.
fn tolerate_openusd_panics() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let abort_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let in_openusd = info
                .location()
                .is_some_and(|l| l.file().contains("/openusd-"));
            if !in_openusd {
                abort_hook(info);
            }
        }));
    });
}

pub fn load(ext: &str, data: &[u8]) {
    tolerate_openusd_panics();
    let path = scratch(ext);
    {
        let mut f = std::fs::File::create(&path).expect("scratch file");
        f.write_all(data).expect("scratch write");
    }
    if let Ok(scene) = luxeval::Stage::load(&path, None) {
        let _ = serde_json_free_walk(&scene);
        if let Ok(lights) = scene.evaluable(&[]) {
            for l in &lights {
                let _ = luxeval::Reference::new(l, luxeval::TemperatureMode::Spec);
                // Mask mode reads a dome's portals (whatever its `portals` relationship named).
                if !l.portals.is_empty() {
                    let _ = luxeval::Reference::with_portal_mode(
                        l,
                        luxeval::TemperatureMode::Spec,
                        luxeval::PortalMode::Mask,
                    );
                }
            }
        }
    }
}

/// Touches every listed input (what `lights` prints).
fn serde_json_free_walk(scene: &luxeval::Stage) -> usize {
    scene
        .lights
        .iter()
        .map(|l| l.inputs.len() + l.warning.as_ref().map_or(0, String::len))
        .sum()
}
