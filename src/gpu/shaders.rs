//! WGSL composition: each kernel file names the modules it needs with `// #import path` lines;
//! the composer inlines them once each, in dependency order, after a prelude of the constants
//! shared with Rust: the record's kinds and flags ([`super::record::WGSL_CONSTANTS`]), the IES
//! atlas codes ([`super::ies_atlas::wgsl_constants`]), the dome texture codes
//! ([`super::texture_atlas::wgsl_constants`]) and the
//! quadrature rules and tuning constants of [`crate::rules`]. No constant is retyped in WGSL.
//!
//! Optional parts of a kernel sit between `// #if NAME` and `// #endif` lines ([`Features`]);
//! the composer drops them from a pipeline that does not need them. Removing them from the
//! source matters on lavapipe: Mesa inlines every call before it removes dead branches, and a
//! branch disabled by a pipeline-overridable constant still cost its compile there (the IES
//! lookup, dead at the irradiance quadrature's 60 shaping calls, took 3 of the irradiance
//! pipeline's 5 seconds).

use std::collections::HashSet;
use std::sync::OnceLock;

use super::record::WGSL_CONSTANTS;
use super::{ies_atlas, mesh_atlas, texture_atlas};
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
        "shared/texture.wgsl",
        include_str!("../../shaders/shared/texture.wgsl"),
    ),
    ("mesh/ray.wgsl", include_str!("../../shaders/mesh/ray.wgsl")),
    (
        "mesh/lambert.wgsl",
        include_str!("../../shaders/mesh/lambert.wgsl"),
    ),
    ("portal.wgsl", include_str!("../../shaders/portal.wgsl")),
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
        "irradiance/kinks.wgsl",
        include_str!("../../shaders/irradiance/kinks.wgsl"),
    ),
    (
        "irradiance/latlong_polygon.wgsl",
        include_str!("../../shaders/irradiance/latlong_polygon.wgsl"),
    ),
    (
        "irradiance/latlong_rows.wgsl",
        include_str!("../../shaders/irradiance/latlong_rows.wgsl"),
    ),
    (
        "irradiance/line.wgsl",
        include_str!("../../shaders/irradiance/line.wgsl"),
    ),
    (
        "irradiance/outer.wgsl",
        include_str!("../../shaders/irradiance/outer.wgsl"),
    ),
    (
        "irradiance/portals.wgsl",
        include_str!("../../shaders/irradiance/portals.wgsl"),
    ),
    ("sample.wgsl", include_str!("../../shaders/sample.wgsl")),
    (
        "sample/rng.wgsl",
        include_str!("../../shaders/sample/rng.wgsl"),
    ),
    (
        "sample/cone.wgsl",
        include_str!("../../shaders/sample/cone.wgsl"),
    ),
    (
        "sample/rect.wgsl",
        include_str!("../../shaders/sample/rect.wgsl"),
    ),
    (
        "sample/area.wgsl",
        include_str!("../../shaders/sample/area.wgsl"),
    ),
    (
        "sample/env_table.wgsl",
        include_str!("../../shaders/sample/env_table.wgsl"),
    ),
    (
        "sample/dome.wgsl",
        include_str!("../../shaders/sample/dome.wgsl"),
    ),
    (
        "sample/select.wgsl",
        include_str!("../../shaders/sample/select.wgsl"),
    ),
];

/// A compute kernel: the file that holds its entry point, and the entry point's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    Emission,
    Radiance,
    Irradiance,
    Intensity,
    /// One direction per row toward a given light (shaders/sample.wgsl; rows in gpu::sample).
    Sample,
    /// The density of one direction per row for a given light (the same file).
    Pdf,
    /// GPU-resident sampling: the light chosen on the device, then one direction per row (the
    /// same file; buffers in gpu::resident).
    SampleResident,
}

impl Kernel {
    /// Every kernel (tests/wgsl.rs validates each, through the `testkit` feature).
    pub const ALL: [Kernel; 7] = [
        Kernel::Emission,
        Kernel::Radiance,
        Kernel::Irradiance,
        Kernel::Intensity,
        Kernel::Sample,
        Kernel::Pdf,
        Kernel::SampleResident,
    ];

    pub fn file(self) -> &'static str {
        match self {
            Kernel::Emission => "emission.wgsl",
            Kernel::Radiance => "radiance.wgsl",
            Kernel::Irradiance => "irradiance.wgsl",
            Kernel::Intensity => "intensity.wgsl",
            Kernel::Sample | Kernel::Pdf | Kernel::SampleResident => "sample.wgsl",
        }
    }

    pub fn entry_point(self) -> &'static str {
        match self {
            Kernel::Emission => "emission_main",
            Kernel::Radiance => "radiance_main",
            Kernel::Irradiance => "irradiance_main",
            Kernel::Intensity => "intensity_main",
            Kernel::Sample => "sample_main",
            Kernel::Pdf => "pdf_main",
            Kernel::SampleResident => "sample_resident_main",
        }
    }
}

/// The optional parts of the kernels, each compiled in only where a scene needs it: the WGSL
/// between `// #if NAME` and `// #endif` (NAME one of [`Features::NAMES`]) is kept when the
/// feature is on and dropped when it is off. [`compose_file`] keeps every part.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Features {
    /// `IES`: the IES profile lookup (shared/ies.wgsl), for scenes with a profile.
    pub ies: bool,
    /// `TEXTURE`: the dome and rect texture lookups (shared/texture.wgsl), for scenes with one.
    pub texture: bool,
    /// `CHART`: the irradiance chart quadrature (irradiance/outer.wgsl), for the lights
    /// [`super::record::Record::features`] says need it.
    pub chart: bool,
    /// `LINE`: the irradiance of a treatAsLine cylinder (a line integral of its own).
    pub line: bool,
}

impl Features {
    /// The names of `// #if` blocks, in the order of the fields.
    pub const NAMES: [&'static str; 4] = ["IES", "TEXTURE", "CHART", "LINE"];

    /// Every part on (for the tests' naga checks).
    #[cfg(any(test, feature = "testkit"))]
    pub const ALL: Features = Features {
        ies: true,
        texture: true,
        chart: true,
        line: true,
    };

    /// Whether the part `name` is on (None for a name that is not one of [`Features::NAMES`]).
    fn get(self, name: &str) -> Option<bool> {
        Some(match name {
            "IES" => self.ies,
            "TEXTURE" => self.texture,
            "CHART" => self.chart,
            "LINE" => self.line,
            _ => return None,
        })
    }

    /// Each part on where `on(NAME)` says so: with [`Features::get`], the only places that
    /// spell the fields out.
    fn from_fn(on: impl Fn(&str) -> bool) -> Features {
        Features {
            ies: on("IES"),
            texture: on("TEXTURE"),
            chart: on("CHART"),
            line: on("LINE"),
        }
    }

    /// Each combination of the parts `kernel`'s source has (tests/wgsl.rs validates each).
    #[cfg(any(test, feature = "testkit"))]
    pub fn variants(kernel: Kernel) -> Vec<Features> {
        let used = Features::used_by(kernel);
        (0..1u32 << Features::NAMES.len())
            .map(|bits| {
                Features::from_fn(|name| {
                    let i = Features::NAMES.iter().position(|n| *n == name);
                    i.is_some_and(|i| bits & (1 << i) != 0)
                })
            })
            .filter(|f| f.restricted_to(used) == *f)
            .collect()
    }

    /// The parts whose `// #if` blocks occur in `kernel`'s composed source (found once).
    pub fn used_by(kernel: Kernel) -> Features {
        static USED: OnceLock<Vec<(Kernel, Features)>> = OnceLock::new();
        let used = USED.get_or_init(|| {
            Kernel::ALL
                .iter()
                .map(|k| {
                    let src = compose_file(k.file()).unwrap_or_default();
                    let f = Features::from_fn(|name| {
                        src.lines()
                            .any(|l| l.trim().strip_prefix("// #if ").map(str::trim) == Some(name))
                    });
                    (*k, f)
                })
                .collect()
        });
        used.iter()
            .find(|(k, _)| *k == kernel)
            .map(|(_, f)| *f)
            .unwrap_or_default()
    }

    /// The parts either needs.
    pub fn union(self, o: Features) -> Features {
        Features::from_fn(|n| self.get(n) == Some(true) || o.get(n) == Some(true))
    }

    /// These features less those `used` lacks (a pipeline is keyed by the parts it has).
    pub fn restricted_to(self, used: Features) -> Features {
        Features::from_fn(|n| self.get(n) == Some(true) && used.get(n) == Some(true))
    }

    /// `+ies+texture+chart+line`, the parts that are on ("" for none).
    pub fn suffix(self) -> String {
        Features::NAMES
            .iter()
            .filter(|n| self.get(n) == Some(true))
            .map(|n| format!("+{}", n.to_lowercase()))
            .collect()
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
        "// Generated from src/gpu/record.rs, src/gpu/ies_atlas.rs, src/gpu/texture_atlas.rs and \
         src/rules.rs.\n",
    );
    for (name, value) in WGSL_CONSTANTS
        .iter()
        .copied()
        .chain(rules::wgsl_u32_constants())
        .chain(ies_atlas::wgsl_constants())
        .chain(texture_atlas::wgsl_constants())
        .chain(mesh_atlas::wgsl_constants())
    {
        s.push_str(&format!("const {name}: u32 = {value}u;\n"));
    }
    for (name, value) in rules::wgsl_f32_constants()
        .into_iter()
        .chain(texture_atlas::wgsl_f32_constants())
    {
        s.push_str(&format!("const {name}: f32 = {};\n", f32_literal(value)));
    }
    for (name, values) in rules::wgsl_f32_arrays()
        .into_iter()
        .chain(texture_atlas::wgsl_f32_arrays())
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

/// The complete WGSL module for `kernel` with the optional parts `features` selects.
pub fn compose(kernel: Kernel, features: Features) -> String {
    select(&compose_file(kernel.file()).unwrap_or_default(), features)
}

/// `src` without the `// #if NAME` … `// #endif` blocks whose feature is off (blocks nest). The
/// markers and the dropped lines become empty lines, so that naga's line numbers are those of
/// [`compose_file`]. An unknown name or an unbalanced marker is a bug in the shaders, which
/// tests/wgsl.rs catches by composing every variant.
fn select(src: &str, features: Features) -> String {
    let mut out = String::with_capacity(src.len());
    // One entry per open block: whether it is kept.
    let mut open: Vec<bool> = Vec::new();
    for line in src.lines() {
        let t = line.trim();
        if let Some(name) = t.strip_prefix("// #if ") {
            let on = features
                .get(name.trim())
                .unwrap_or_else(|| panic!("unknown WGSL feature in `{t}`"));
            open.push(on);
        } else if t == "// #endif" {
            assert!(open.pop().is_some(), "`// #endif` without `// #if`");
        } else if open.iter().all(|on| *on) {
            out.push_str(line);
        }
        out.push('\n');
    }
    assert!(open.is_empty(), "`// #if` without `// #endif`");
    out
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
