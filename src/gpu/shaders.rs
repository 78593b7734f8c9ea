//! WGSL composition: each kernel file names the modules it needs with `// #import path` lines;
//! the composer inlines them once each, in dependency order, after a prelude of the constants
//! shared with Rust: the record's kinds and flags ([`super::record::WGSL_CONSTANTS`]), the IES
//! atlas codes ([`super::ies_atlas::wgsl_constants`]), the dome texture codes
//! ([`super::dome_atlas::wgsl_constants`]) and the
//! quadrature rules and tuning constants of [`crate::rules`]. No constant is retyped in WGSL.

use std::collections::HashSet;

use super::record::WGSL_CONSTANTS;
use super::{dome_atlas, ies_atlas};
use crate::rules;

/// Every WGSL source file, by its path under `shaders/`.
pub const SOURCES: &[(&str, &str)] = &[
    (
        "shared/record.wgsl",
        include_str!("../../shaders/shared/record.wgsl"),
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
    (
        "shared/roots.wgsl",
        include_str!("../../shaders/shared/roots.wgsl"),
    ),
    (
        "shared/ies.wgsl",
        include_str!("../../shaders/shared/ies.wgsl"),
    ),
    (
        "shared/dome.wgsl",
        include_str!("../../shaders/shared/dome.wgsl"),
    ),
    ("emission.wgsl", include_str!("../../shaders/emission.wgsl")),
    ("radiance.wgsl", include_str!("../../shaders/radiance.wgsl")),
    (
        "intensity.wgsl",
        include_str!("../../shaders/intensity.wgsl"),
    ),
    (
        "irradiance.wgsl",
        include_str!("../../shaders/irradiance.wgsl"),
    ),
    (
        "irradiance/closed.wgsl",
        include_str!("../../shaders/irradiance/closed.wgsl"),
    ),
    (
        "irradiance/chart.wgsl",
        include_str!("../../shaders/irradiance/chart.wgsl"),
    ),
    (
        "irradiance/critical.wgsl",
        include_str!("../../shaders/irradiance/critical.wgsl"),
    ),
    (
        "irradiance/pieces.wgsl",
        include_str!("../../shaders/irradiance/pieces.wgsl"),
    ),
    (
        "irradiance/line.wgsl",
        include_str!("../../shaders/irradiance/line.wgsl"),
    ),
    (
        "irradiance/outer.wgsl",
        include_str!("../../shaders/irradiance/outer.wgsl"),
    ),
];

/// A compute kernel: the file that holds its entry point, and the entry point's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    Emission,
    Radiance,
    Irradiance,
    Intensity,
}

impl Kernel {
    /// Every kernel (tests/wgsl.rs validates each, through the `testkit` feature).
    #[cfg_attr(not(feature = "testkit"), allow(dead_code))]
    pub const ALL: [Kernel; 4] = [
        Kernel::Emission,
        Kernel::Radiance,
        Kernel::Irradiance,
        Kernel::Intensity,
    ];

    pub fn file(self) -> &'static str {
        match self {
            Kernel::Emission => "emission.wgsl",
            Kernel::Radiance => "radiance.wgsl",
            Kernel::Irradiance => "irradiance.wgsl",
            Kernel::Intensity => "intensity.wgsl",
        }
    }

    pub fn entry_point(self) -> &'static str {
        match self {
            Kernel::Emission => "emission_main",
            Kernel::Radiance => "radiance_main",
            Kernel::Irradiance => "irradiance_main",
            Kernel::Intensity => "intensity_main",
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
    let mut s = String::from(
        "// Generated from src/gpu/record.rs, src/gpu/ies_atlas.rs, src/gpu/dome_atlas.rs and \
         src/rules.rs.\n",
    );
    for (name, value) in WGSL_CONSTANTS
        .iter()
        .copied()
        .chain(rules::wgsl_u32_constants())
        .chain(ies_atlas::wgsl_constants())
        .chain(dome_atlas::wgsl_constants())
    {
        s.push_str(&format!("const {name}: u32 = {value}u;\n"));
    }
    for (name, value) in rules::wgsl_f32_constants() {
        s.push_str(&format!("const {name}: f32 = {};\n", f32_literal(value)));
    }
    for (name, values) in rules::wgsl_f32_arrays()
        .into_iter()
        .chain(dome_atlas::wgsl_f32_arrays())
    {
        let items: Vec<String> = values.iter().map(|v| f32_literal(*v)).collect();
        s.push_str(&format!(
            "var<private> {name}: array<f32, {}> = array<f32, {}>({});\n",
            values.len(),
            values.len(),
            items.join(", ")
        ));
    }
    s
}

/// A WGSL f32 literal that rounds to the nearest f32 of `v`.
fn f32_literal(v: f64) -> String {
    let f = v as f32;
    // `{:?}` prints the shortest decimal that round-trips the f32, always with a '.' or 'e'.
    format!("{f:?}")
}

/// The complete WGSL module for `kernel`.
pub fn compose(kernel: Kernel) -> String {
    compose_file(kernel.file()).unwrap_or_default()
}

/// The prelude, the modules `path` imports and `path` itself: a module naga can parse on its
/// own (None when `path` is not one of [`SOURCES`]).
pub fn compose_file(path: &str) -> Option<String> {
    let path = SOURCES.iter().map(|(p, _)| *p).find(|p| *p == path)?;
    let mut out = prelude();
    let mut seen = HashSet::new();
    append(path, &mut out, &mut seen);
    Some(out)
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
