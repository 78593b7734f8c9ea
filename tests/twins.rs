//! Twins that read alike (DESIGN.md §1): each WGSL file that implements a concept names its CPU
//! twin in its header ("Twin of src/cpu/….rs"); naga parses the WGSL (with its imports) and
//! lists the functions the file defines; each must have a function of the same name in the
//! Rust twin, in the same order, unless the WGSL header lists it as `GPU-only <name>: reason`.
//! Files without a twin say `No CPU twin: reason`.

use std::path::Path;

use luxeval::testkit::wgsl::{SOURCES, compose_file};

/// The header: the leading comment lines.
fn header(src: &str) -> String {
    src.lines()
        .take_while(|l| l.starts_with("//") || l.trim().is_empty())
        .collect::<Vec<_>>()
        .join("\n")
}

/// Names listed as `// GPU-only a, b: reason`.
fn gpu_only(header: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in header.lines() {
        if let Some(rest) = line
            .trim_start_matches("//")
            .trim()
            .strip_prefix("GPU-only ")
        {
            let names = rest.split(':').next().unwrap_or("");
            out.extend(names.split(',').map(|n| n.trim().to_string()));
        }
    }
    out
}

/// The byte offset of the definition of `fn name` in `text` (`fn name(` or `fn name<`).
fn position(text: &str, name: &str) -> Option<usize> {
    ["(", "<"]
        .iter()
        .filter_map(|end| text.find(&format!("fn {name}{end}")))
        .min()
}

#[test]
fn every_wgsl_function_has_its_cpu_twin_in_the_same_order() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut problems = Vec::new();
    let mut twinned = 0;
    let mut files = 0;
    for (path, src) in SOURCES {
        let head = header(src);
        if head.contains("No CPU twin:") {
            continue;
        }
        files += 1;
        let Some(rust_path) = head
            .find("Twin of ")
            .and_then(|i| head[i + "Twin of ".len()..].split_whitespace().next())
            .map(|w| w.trim_end_matches([',', '.', ';', ':']))
        else {
            problems.push(format!("{path}: no \"Twin of src/cpu/….rs\" in its header"));
            continue;
        };
        let rust = std::fs::read_to_string(root.join(rust_path))
            .unwrap_or_else(|e| panic!("{path}: twin {rust_path}: {e}"));
        let rust_code = match rust.find("#[cfg(test)]") {
            Some(i) => &rust[..i],
            None => &rust[..],
        };
        // naga lists the functions of the file composed with its imports; keep those the file
        // itself defines.
        let composed = compose_file(path).unwrap();
        let module = naga::front::wgsl::parse_str(&composed)
            .unwrap_or_else(|e| panic!("{path}:\n{}", e.emit_to_string(&composed)));
        let mut own: Vec<(usize, String)> = module
            .functions
            .iter()
            .filter_map(|(_, f)| f.name.clone())
            .chain(module.entry_points.iter().map(|e| e.name.clone()))
            .filter_map(|n| position(src, &n).map(|p| (p, n)))
            .collect();
        own.sort();
        assert!(!own.is_empty(), "{path}: naga found no function of its own");
        let exempt = gpu_only(&head);
        for name in &exempt {
            if !own.iter().any(|(_, n)| n == name) && !src.contains(&format!("struct {name}")) {
                problems.push(format!("{path}: GPU-only {name} is not defined there"));
            }
        }
        let mut last = (0usize, String::new());
        for (_, name) in &own {
            match position(rust_code, name) {
                Some(p) => {
                    twinned += 1;
                    if p < last.0 {
                        problems.push(format!(
                            "{path}: {name} comes after {} but precedes it in {rust_path}",
                            last.1
                        ));
                    }
                    last = (p, name.clone());
                }
                None if exempt.contains(name) => {}
                None => problems.push(format!(
                    "{path}: fn {name} has no twin in {rust_path} and is not listed GPU-only"
                )),
            }
        }
    }
    println!("{files} WGSL twins, {twinned} functions with a CPU twin");
    assert!(files >= 12, "only {files} twinned files");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn header_parsing() {
    let h = "// Twin of src/cpu/x.rs.\n// GPU-only a, b: why\n// GPU-only c: why";
    assert_eq!(gpu_only(h), ["a", "b", "c"]);
    assert_eq!(position("fn ab(x)\nfn a(y)", "a"), Some(9));
}
