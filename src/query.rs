//! The queries of DESIGN.md §3 behind one front: the same call runs on the f64 CPU reference or
//! on a wgpu device, and returns float32 RGB rows.

use glam::DVec3;

use crate::cpu::{self, PreparedLight, TemperatureMode};
use crate::error::{LuxError, Result};
use crate::gpu::{self, GpuContext, Kernel};
use crate::light::Light;

/// Where queries run.
#[derive(Debug)]
pub enum Backend {
    /// The f64 CPU reference (rayon-parallel), rounded to f32 on output.
    Cpu,
    /// A wgpu compute device.
    Gpu(Box<GpuContext>),
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

/// Evaluates the queries on one backend with one set of options.
#[derive(Debug)]
pub struct Evaluator {
    backend: Backend,
    temperature_mode: TemperatureMode,
}

impl Evaluator {
    /// The CPU reference.
    pub fn cpu() -> Self {
        Evaluator {
            backend: Backend::Cpu,
            temperature_mode: TemperatureMode::default(),
        }
    }

    /// A GPU evaluator on the default adapter (see [`GpuContext::new`]).
    pub fn gpu() -> Result<Self> {
        Ok(Evaluator {
            backend: Backend::Gpu(Box::new(GpuContext::new()?)),
            temperature_mode: TemperatureMode::default(),
        })
    }

    /// A GPU evaluator on an existing context.
    pub fn from_context(gpu: GpuContext) -> Self {
        Evaluator {
            backend: Backend::Gpu(Box::new(gpu)),
            temperature_mode: TemperatureMode::default(),
        }
    }

    pub fn with_temperature_mode(mut self, mode: TemperatureMode) -> Self {
        self.temperature_mode = mode;
        self
    }

    pub fn temperature_mode(&self) -> TemperatureMode {
        self.temperature_mode
    }

    pub fn backend(&self) -> &Backend {
        &self.backend
    }

    /// "cpu" or the adapter's name.
    pub fn device_name(&self) -> String {
        match &self.backend {
            Backend::Cpu => "cpu (f64 reference)".into(),
            Backend::Gpu(g) => format!("{} ({})", g.adapter().name, g.adapter().backend),
        }
    }

    /// Validates the lights and computes their per-light constants.
    pub fn prepare(&self, lights: &[Light]) -> Result<Vec<PreparedLight>> {
        cpu::prepare(lights, self.temperature_mode)
    }

    /// emission(light, ω) for every direction (DESIGN.md §3).
    pub fn emission(
        &self,
        lights: &[Light],
        dirs: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_directions("directions", dirs)?;
        let prepared = self.prepare(lights)?;
        let per_light = acc == Accumulate::PerLight;
        match &self.backend {
            Backend::Cpu => Ok(to_f32(cpu::emission_batch(&prepared, dirs, per_light))),
            Backend::Gpu(g) => g.run(Kernel::Emission, &records(&prepared), dirs, None, per_light),
        }
    }

    /// radiance(x, ω) for every (point, direction) pair (DESIGN.md §3).
    pub fn radiance(
        &self,
        lights: &[Light],
        points: &[[f32; 3]],
        dirs: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_points("points", points)?;
        check_directions("directions", dirs)?;
        if points.len() != dirs.len() {
            return Err(LuxError::input(
                "points/directions",
                format!(
                    "{} points but {} directions; they pair up row by row",
                    points.len(),
                    dirs.len()
                ),
            ));
        }
        let prepared = self.prepare(lights)?;
        let per_light = acc == Accumulate::PerLight;
        match &self.backend {
            Backend::Cpu => Ok(to_f32(cpu::radiance_batch(
                &prepared, points, dirs, per_light,
            ))),
            Backend::Gpu(g) => g.run(
                Kernel::Radiance,
                &records(&prepared),
                points,
                Some(dirs),
                per_light,
            ),
        }
    }
}

impl Evaluator {
    /// irradiance(x, n) for every (point, receiver normal) pair (DESIGN.md §3): the
    /// diffuse-weighted irradiance `diffuse · ∫ radiance(x, ω) max(0, n·ω) dω`.
    pub fn irradiance(
        &self,
        lights: &[Light],
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_points("points", points)?;
        check_directions("normals", normals)?;
        if points.len() != normals.len() {
            return Err(LuxError::input(
                "points/normals",
                format!(
                    "{} points but {} normals; they pair up row by row",
                    points.len(),
                    normals.len()
                ),
            ));
        }
        let prepared = self.prepare(lights)?;
        let per_light = acc == Accumulate::PerLight;
        match &self.backend {
            Backend::Cpu => Ok(to_f32(cpu::irradiance_batch(
                &prepared, points, normals, per_light,
            ))),
            Backend::Gpu(g) => g.run(
                Kernel::Irradiance,
                &records(&prepared),
                points,
                Some(normals),
                per_light,
            ),
        }
    }
}

fn records(prepared: &[PreparedLight]) -> Vec<gpu::LightRecord> {
    prepared.iter().map(gpu::pack::pack).collect()
}

fn to_f32(v: Vec<DVec3>) -> Vec<[f32; 3]> {
    v.into_iter().map(|c| c.as_vec3().to_array()).collect()
}

/// Every point must be finite.
pub fn check_points(what: &str, points: &[[f32; 3]]) -> Result<()> {
    if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(LuxError::input(
            what,
            format!("row {i} is not finite: {:?}", points[i]),
        ));
    }
    Ok(())
}

/// Every direction must be finite and non-zero (it is normalised before use).
pub fn check_directions(what: &str, dirs: &[[f32; 3]]) -> Result<()> {
    check_points(what, dirs)?;
    if let Some(i) = dirs.iter().position(|d| d.iter().all(|c| *c == 0.0)) {
        return Err(LuxError::input(
            what,
            format!("row {i} is the zero vector, which has no direction"),
        ));
    }
    Ok(())
}
