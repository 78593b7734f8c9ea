//! WGSL composition: each kernel file names the modules it needs with `// #import path` lines;
//! the composer inlines them once each, in dependency order, after a prelude of the constants
//! shared with Rust ([`super::pack::WGSL_CONSTANTS`]).

use std::collections::HashSet;

use super::pack::WGSL_CONSTANTS;

/// Every WGSL source file, by its path under `shaders/`.
pub const SOURCES: &[(&str, &str)] = &[
    (
        "shared/light.wgsl",
        include_str!("../../shaders/shared/light.wgsl"),
    ),
    (
        "shared/math.wgsl",
        include_str!("../../shaders/shared/math.wgsl"),
    ),
    (
        "shared/shaping.wgsl",
        include_str!("../../shaders/shared/shaping.wgsl"),
    ),
    (
        "shared/shapes.wgsl",
        include_str!("../../shaders/shared/shapes.wgsl"),
    ),
    ("emission.wgsl", include_str!("../../shaders/emission.wgsl")),
    ("radiance.wgsl", include_str!("../../shaders/radiance.wgsl")),
];

/// A compute kernel: the file that holds its entry point, and the entry point's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    Emission,
    Radiance,
}

impl Kernel {
    pub const ALL: [Kernel; 2] = [Kernel::Emission, Kernel::Radiance];

    pub fn file(self) -> &'static str {
        match self {
            Kernel::Emission => "emission.wgsl",
            Kernel::Radiance => "radiance.wgsl",
        }
    }

    pub fn entry_point(self) -> &'static str {
        match self {
            Kernel::Emission => "emission_main",
            Kernel::Radiance => "radiance_main",
        }
    }
}

fn source(path: &str) -> &'static str {
    SOURCES
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| *s)
        .unwrap_or_else(|| panic!("WGSL module {path} is not in gpu::shaders::SOURCES"))
}

/// The prelude of shared constants.
pub fn prelude() -> String {
    let mut s = String::from("// Generated from src/gpu/pack.rs WGSL_CONSTANTS.\n");
    for (name, value) in WGSL_CONSTANTS {
        s.push_str(&format!("const {name}: u32 = {value}u;\n"));
    }
    s
}

/// The complete WGSL module for `kernel`.
pub fn compose(kernel: Kernel) -> String {
    let mut out = prelude();
    let mut seen = HashSet::new();
    append(kernel.file(), &mut out, &mut seen);
    out
}

fn append(path: &'static str, out: &mut String, seen: &mut HashSet<&'static str>) {
    if !seen.insert(path) {
        return;
    }
    let src = source(path);
    for line in src.lines() {
        if let Some(dep) = line.trim().strip_prefix("// #import ") {
            let dep = SOURCES
                .iter()
                .map(|(p, _)| *p)
                .find(|p| *p == dep.trim())
                .unwrap_or_else(|| panic!("{path} imports unknown module {dep}"));
            append(dep, out, seen);
        }
    }
    out.push_str(&format!("\n// ---- {path} ----\n"));
    out.push_str(src);
}
