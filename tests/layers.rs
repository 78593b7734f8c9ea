//! The data flow of DESIGN.md §1, enforced: each module under `src/` names (as `crate::…`) only
//! the modules before it in model → usd → prepare → cpu | gpu → query → falloff, conformance
//! (the command line and Python are crates around the library, which names neither).
//! In particular `src/cpu` never names the gpu module and `src/gpu` never names the cpu module.
//! Test code (`#[cfg(test)]` sections) is not scanned.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Each layer and the crate modules it may name.
const ALLOWED: &[(&str, &[&str])] = &[
    ("assets", &["assets"]),
    ("model", &["error", "model"]),
    // `limits` is a leaf like `error`: the bounds every reader checks (docs/INPUTS.md).
    ("limits", &["error", "limits"]),
    // The one rule for query input rows, used by `query` and by the crates around the library.
    ("input", &["input"]),
    ("usd", &["error", "limits", "model", "usd"]),
    ("prepare", &["assets", "error", "model", "prepare"]),
    ("rules", &["rules"]),
    ("cpu", &["error", "model", "prepare", "rules", "cpu"]),
    ("gpu", &["error", "model", "prepare", "rules", "gpu"]),
    (
        "query",
        // `usd` only for the light records of a stage (query/lights.rs, feature `usd`);
        // `rules` for the tolerance the GPU is held to (irradiance `--tolerance`).
        &[
            "error", "input", "model", "usd", "prepare", "rules", "cpu", "gpu", "query",
        ],
    ),
    // Seeded lights and the samples aimed at them (through the f64 reference).
    ("synthetic", &["model", "query", "synthetic"]),
    ("falloff", &["error", "query", "falloff"]),
    (
        "conformance",
        &[
            "error",
            "model",
            "prepare",
            "rules",
            "cpu",
            "query",
            "synthetic",
            "conformance",
        ],
    ),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Whether `path` is an out-of-line test module: a file `NAME.rs` (e.g. `tests.rs`,
/// `exact_tests.rs`) that its parent module (`mod.rs` beside it, or the `<dir>.rs` it sits
/// under) declares as `#[cfg(test)] mod NAME;`.
fn is_test_module(path: &Path) -> bool {
    let Some(stem) = path.file_stem().and_then(|s| s.to_str()) else {
        return false;
    };
    if stem == "mod" {
        return false;
    }
    let Some(dir) = path.parent() else {
        return false;
    };
    let declaration = format!("#[cfg(test)]\nmod {stem};");
    let parents = [dir.join("mod.rs"), dir.with_extension("rs")];
    parents
        .iter()
        .any(|p| std::fs::read_to_string(p).is_ok_and(|t| t.contains(&declaration)))
}

/// The crate modules a source file names outside its test sections (an out-of-line test
/// module is one whole test section).
fn named_modules(path: &Path) -> BTreeSet<String> {
    if is_test_module(path) {
        return BTreeSet::new();
    }
    let text = std::fs::read_to_string(path).unwrap();
    let code = match text.find("#[cfg(test)]") {
        Some(i) => &text[..i],
        None => &text,
    };
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        // `crate::{a, b}` lists.
        if name.is_empty() && rest.starts_with('{') {
            let end = rest.find('}').unwrap_or(rest.len());
            for part in rest[1..end].split(',') {
                let m: String = part
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !m.is_empty() {
                    out.insert(m);
                }
            }
        } else if !name.is_empty() {
            out.insert(name);
        }
    }
    out
}

#[test]
fn every_module_names_only_the_layers_before_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut problems = Vec::new();
    let mut scanned = 0;
    for (layer, allowed) in ALLOWED {
        let mut files = Vec::new();
        let dir = src.join(layer);
        if dir.is_dir() {
            rust_files(&dir, &mut files);
        }
        let single = src.join(format!("{layer}.rs"));
        if single.is_file() {
            files.push(single);
        }
        assert!(!files.is_empty(), "no source for layer {layer}");
        for f in files {
            scanned += 1;
            for m in named_modules(&f) {
                if !allowed.contains(&m.as_str()) {
                    problems.push(format!("{} names crate::{m}", f.display()));
                }
            }
        }
    }
    assert!(scanned > 30, "only {scanned} files scanned");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The scanner itself sees a forbidden name (the test above cannot pass vacuously).
#[test]
fn the_scanner_finds_crate_paths() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("x.rs");
    std::fs::write(
        &f,
        "use crate::gpu::record;\nuse crate::{cpu, model::Light};\n#[cfg(test)]\nuse crate::testkit;\n",
    )
    .unwrap();
    let names: Vec<String> = named_modules(&f).into_iter().collect();
    assert_eq!(names, ["cpu", "gpu", "model"]);
}
