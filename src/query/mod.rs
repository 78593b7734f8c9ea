//! The queries of DESIGN.md §3 behind one front (DESIGN.md §1 "query"): an [`Evaluator`] picks
//! the backend (the f64 CPU reference or a wgpu device) and prepares a set of lights once into a
//! [`PreparedScene`], which answers any number of emission / radiance / irradiance calls and
//! returns float32 RGB rows. [`Reference`] is the f64 reference of one light, sample by sample.

mod ies;
mod reference;
mod resident;
mod sample;
mod scene;

use std::sync::Arc;

use crate::error::{LuxError, Result};
use crate::gpu::{AdapterSummary, CacheStatus, DeviceLimits, GpuContext, Startup};
use crate::input::RowKind;
use crate::model::Light;
use crate::prepare::{PortalMode, TemperatureMode};
#[cfg(feature = "usd")]
mod lights;
#[cfg(feature = "usd")]
pub use lights::{lights_json, portal_multiplier};
pub use reference::{Power, Reference};
pub use sample::{SampleOptions, SamplerCheck, Samples, Selection, StrategyVariance};
pub use scene::PreparedScene;

/// Where queries run.
#[derive(Clone, Debug)]
pub(crate) enum Backend {
    /// The f64 CPU reference (rayon-parallel), rounded to f32 on output.
    Cpu,
    /// A wgpu compute device.
    Gpu(Arc<GpuContext>),
}

/// The relative tolerances [`Evaluator::with_irradiance_tolerance`] accepts.
pub(crate) const IRRADIANCE_TOLERANCE_RANGE: (f64, f64) = (1e-9, 0.1);

/// Refuses an irradiance tolerance out of [`IRRADIANCE_TOLERANCE_RANGE`], or below the GPU's
/// bound on a GPU (see [`Evaluator::with_irradiance_tolerance`]).
pub(crate) fn check_tolerance(rel: f64, gpu: bool) -> Result<()> {
    if !(IRRADIANCE_TOLERANCE_RANGE.0..=IRRADIANCE_TOLERANCE_RANGE.1).contains(&rel) {
        return Err(LuxError::input(
            "tolerance",
            format!(
                "{rel}: a relative tolerance must be from {:e} (the reference's own) to {}",
                IRRADIANCE_TOLERANCE_RANGE.0, IRRADIANCE_TOLERANCE_RANGE.1
            ),
        ));
    }
    if gpu && rel < crate::rules::GPU_TOLERANCE {
        return Err(LuxError::input(
            "tolerance",
            format!(
                "{rel} is tighter than the GPU's irradiance rule is held to ({:e}, f32); use the CPU reference for it",
                crate::rules::GPU_TOLERANCE
            ),
        ));
    }
    Ok(())
}

/// Sum the lights per sample, or keep one row per (light, sample).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Accumulate {
    /// `N` rows: the sum over lights (lights do not occlude each other).
    #[default]
    Sum,
    /// `L × N` rows, light-major: row `l·N + i` is light `l` at sample `i`.
    PerLight,
}

/// How the rows of a GPU-resident query's buffers are laid out ([`PreparedScene::with_row_layout`]):
/// the directions, points and normals read and the rows written by
/// [`PreparedScene::encode_emission`], `encode_intensity`, `encode_radiance` and
/// `encode_irradiance` (not `encode_sample`, whose rows are its own).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RowLayout {
    /// Three tightly packed `f32` a row (x, y, z or r, g, b): a 12-byte stride.
    #[default]
    Packed,
    /// Four `f32` a row, a 16-byte stride (WGSL's `array<vec3<f32>>` and `array<vec4<f32>>`,
    /// HLSL's `float4`): the fourth input float is ignored and the fourth output float is
    /// written 0. Each row is one aligned 16-byte access, which a GPU's memory system serves
    /// in fewer transactions than a 12-byte row's three 4-byte ones (BENCHMARKS.md, issue 24
    /// item 7).
    Vec4,
}

impl RowLayout {
    /// The `f32` words of one row.
    pub const fn words(self) -> u32 {
        match self {
            RowLayout::Packed => 3,
            RowLayout::Vec4 => 4,
        }
    }
}

/// Evaluates the queries on one backend with one set of options. Cloning is cheap (the device
/// is shared).
#[derive(Clone, Debug)]
pub struct Evaluator {
    backend: Backend,
    temperature_mode: TemperatureMode,
    /// How domes read their portals (DESIGN.md §8 P2).
    portal_mode: PortalMode,
    /// Relative tolerance of irradiance (None: the reference's 1e-9).
    irradiance_tolerance: Option<f64>,
}

impl Evaluator {
    /// The CPU reference.
    pub fn cpu() -> Self {
        Evaluator {
            backend: Backend::Cpu,
            temperature_mode: TemperatureMode::default(),
            portal_mode: PortalMode::default(),
            irradiance_tolerance: None,
        }
    }

    /// A GPU evaluator on the adapter named by `LUXEVAL_ADAPTER` (a name substring), else the
    /// default high-performance adapter. Pipelines are compiled when a query first needs them.
    pub fn gpu() -> Result<Self> {
        Ok(Evaluator {
            backend: Backend::Gpu(Arc::new(GpuContext::new()?)),
            temperature_mode: TemperatureMode::default(),
            portal_mode: PortalMode::default(),
            irradiance_tolerance: None,
        })
    }

    /// `--device auto` (DESIGN.md §4): a GPU evaluator on a hardware adapter when there is one
    /// (the best matching `LUXEVAL_ADAPTER` when set), else the CPU reference. A software adapter
    /// (lavapipe/llvmpipe, SwiftShader, WARP) is never picked: it runs the kernels on the same
    /// cores as the f64 reference, more slowly; [`Evaluator::gpu`] opens one. Returns the
    /// evaluator and a sentence saying what was chosen and why, for `info` and the first warning.
    pub fn auto() -> Result<(Self, String)> {
        match GpuContext::new_hardware() {
            Ok(ctx) => {
                let a = ctx.adapter();
                let why = format!(
                    "the hardware adapter {} ({}, {})",
                    a.name, a.device_type, a.backend
                );
                let eval = Evaluator {
                    backend: Backend::Gpu(Arc::new(ctx)),
                    temperature_mode: TemperatureMode::default(),
                    portal_mode: PortalMode::default(),
                    irradiance_tolerance: None,
                };
                Ok((eval, why))
            }
            Err(LuxError::NoAdapter { reason, .. }) => Ok((
                Evaluator::cpu(),
                format!(
                    "the CPU reference: {reason} (a software adapter is slower than the f64 \
                     reference on the same cores; --device gpu uses one)"
                ),
            )),
            Err(e) => Err(e),
        }
    }

    pub fn with_temperature_mode(mut self, mode: TemperatureMode) -> Self {
        self.temperature_mode = mode;
        self
    }

    pub fn temperature_mode(&self) -> TemperatureMode {
        self.temperature_mode
    }

    /// How domes read their portals (DESIGN.md §8 P2): [`PortalMode::Hint`] (the default)
    /// changes no value; [`PortalMode::Mask`] lets a dome that names portals reach a point only
    /// through them (on every device from the CPU reference).
    pub fn with_portal_mode(mut self, mode: PortalMode) -> Self {
        self.portal_mode = mode;
        self
    }

    pub fn portal_mode(&self) -> PortalMode {
        self.portal_mode
    }

    /// Computes irradiance to relative tolerance `rel` rather than to the reference's 1e-9
    /// (`luxeval irradiance --tolerance`, whose default is 1e-4): the CPU's adaptive rules stop
    /// there (the CPU's `Adaptive::for_tolerance`; closed forms stay exact). It also takes
    /// exact per-receiver shortcuts (a shaping factor uniformly 0 or 1 over the light), and
    /// from 1e-5 on a 7-point Gauss–Kronrod pair and a 3-point coarse scale: the luxtest floor
    /// maps cost 2.7–17× less than before at 1e-2 (BENCHMARKS.md, "The jobs people run").
    /// The GPU's f32 rule is fixed and held to 1e-4 by the conformance tests (the tolerance of `luxeval check`), so a GPU evaluator accepts no
    /// tighter `rel`. Errors: `rel` not in [1e-9, 0.1], or below the GPU's bound on
    /// a GPU evaluator.
    pub fn with_irradiance_tolerance(mut self, rel: f64) -> Result<Self> {
        check_tolerance(rel, self.is_gpu())?;
        self.irradiance_tolerance = Some(rel);
        Ok(self)
    }

    /// The relative tolerance irradiance is computed to (None: the reference's 1e-9).
    pub fn irradiance_tolerance(&self) -> Option<f64> {
        self.irradiance_tolerance
    }

    /// The backend, for the conformance check.
    pub(crate) fn backend(&self) -> &Backend {
        &self.backend
    }

    /// Whether queries run on a GPU.
    pub fn is_gpu(&self) -> bool {
        matches!(self.backend, Backend::Gpu(_))
    }

    /// The GPU adapter, when queries run on one.
    pub fn adapter(&self) -> Option<AdapterSummary> {
        match &self.backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g.adapter()),
        }
    }

    /// Whether and where compiled pipelines are cached across processes, when queries run on a
    /// GPU (`luxeval info`).
    pub fn pipeline_cache(&self) -> Option<CacheStatus> {
        match &self.backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g.cache_status()),
        }
    }

    /// How long opening the device and compiling each pipeline so far took, when queries run
    /// on a GPU (`luxeval bench`).
    pub fn startup(&self) -> Option<Startup> {
        match &self.backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g.startup()),
        }
    }

    /// The device limits that bound a batch, when queries run on a GPU.
    pub fn device_limits(&self) -> Option<DeviceLimits> {
        match &self.backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g.device_limits()),
        }
    }

    /// "cpu (f64 reference)" or the adapter's name and backend (marked "caller's device" for
    /// an evaluator made by [`Evaluator::from_wgpu`]).
    pub fn device_name(&self) -> String {
        match &self.backend {
            Backend::Cpu => "cpu (f64 reference)".into(),
            Backend::Gpu(g) if g.is_callers_device() => format!(
                "{} ({}, caller's device)",
                g.adapter().name,
                g.adapter().backend
            ),
            Backend::Gpu(g) => format!("{} ({})", g.adapter().name, g.adapter().backend),
        }
    }

    /// Validates the lights, computes their per-light constants once and, on a GPU, uploads
    /// them: the prepared scene answers any number of queries.
    pub fn prepare(&self, lights: &[Light]) -> Result<PreparedScene> {
        PreparedScene::new(
            self.backend.clone(),
            lights,
            self.temperature_mode,
            self.portal_mode,
            self.irradiance_tolerance,
        )
    }

    /// emission(light, ω) for every direction (DESIGN.md §3); prepares `lights` for this one
    /// call (use [`Evaluator::prepare`] to query the same lights many times).
    pub fn emission(
        &self,
        lights: &[Light],
        dirs: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_directions("directions", dirs)?;
        self.prepare(lights)?.emission(dirs, acc)
    }

    /// intensity(light, ω) for every direction (DESIGN.md §3).
    pub fn intensity(
        &self,
        lights: &[Light],
        dirs: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_directions("directions", dirs)?;
        self.prepare(lights)?.intensity(dirs, acc)
    }

    /// radiance(x, ω) for every (point, direction) pair (DESIGN.md §3).
    pub fn radiance(
        &self,
        lights: &[Light],
        points: &[[f32; 3]],
        dirs: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_pairs(points, "points", dirs, "directions")?;
        self.prepare(lights)?.radiance(points, dirs, acc)
    }

    /// irradiance(x, n) for every (point, receiver normal) pair (DESIGN.md §3): the
    /// diffuse-weighted irradiance `diffuse · ∫ radiance(x, ω) max(0, n·ω) dω`.
    pub fn irradiance(
        &self,
        lights: &[Light],
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_pairs(points, "points", normals, "normals")?;
        self.prepare(lights)?.irradiance(points, normals, acc)
    }
}

/// Every point must be finite (the one rule of [`crate::input`]).
pub(crate) fn check_points(what: &str, points: &[[f32; 3]]) -> Result<()> {
    RowKind::Points
        .check_f32(0, points)
        .map_err(|e| LuxError::input(what, e.to_string()))
}

/// Every direction must be finite and non-zero (it is normalised before use).
pub(crate) fn check_directions(what: &str, dirs: &[[f32; 3]]) -> Result<()> {
    RowKind::Directions
        .check_f32(0, dirs)
        .map_err(|e| LuxError::input(what, e.to_string()))
}

/// Points and directions (or normals) that pair up row by row.
pub(crate) fn check_pairs(
    points: &[[f32; 3]],
    what_points: &str,
    dirs: &[[f32; 3]],
    what_dirs: &str,
) -> Result<()> {
    check_points(what_points, points)?;
    check_directions(what_dirs, dirs)?;
    if points.len() != dirs.len() {
        return Err(LuxError::input(
            format!("{what_points}/{what_dirs}"),
            format!(
                "{} {what_points} but {} {what_dirs}; they pair up row by row",
                points.len(),
                dirs.len()
            ),
        ));
    }
    Ok(())
}

/// A GPU evaluator for the unit tests, or `None` (with a note) without an adapter; under
/// `CI=true`, where CI installs lavapipe, a missing adapter fails the test instead.
#[cfg(test)]
pub(crate) fn test_gpu() -> Option<Evaluator> {
    match Evaluator::gpu() {
        Ok(e) => Some(e),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") => {
            panic!("CI=true but no GPU adapter: {e}")
        }
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}
