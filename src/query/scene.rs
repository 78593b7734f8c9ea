//! A set of lights prepared once, answering any number of queries.

use std::sync::Mutex;

use glam::DVec3;

use super::{Accumulate, Backend, check_directions, check_pairs};
use crate::cpu;
use crate::cpu::irradiance::Adaptive;
use crate::error::{LuxError, Result};
use crate::gpu::record::LIGHTS_ALL;
use crate::gpu::{GpuLights, Input, Kernel, Scratch, ies_atlas, mesh_atlas, record, texture_atlas};
use crate::model::Light;
use crate::prepare::{self, GpuPath, PortalMode, Prepared, TemperatureMode};

mod irradiance;

/// Lights validated and prepared once (per-light constants in f64; on a GPU, the packed records
/// uploaded and the input/output buffers of the last size class kept), answering emission,
/// radiance and irradiance for any number of batches.
pub struct PreparedScene {
    pub(super) backend: Backend,
    pub(super) lights: Vec<Prepared>,
    pub(super) gpu: Option<GpuLights>,
    /// The buffers of the last GPU call, reused by the next call of the same size class.
    scratch: Mutex<Option<Scratch>>,
    /// What the caller should know about how the scene is evaluated: the lights' own warnings
    /// (zero-size lights), then `device_warnings`; see [`PreparedScene::warnings`].
    warnings: Vec<String>,
    /// How this device's values differ from the reference by design (textures the GPU holds
    /// reduced), which the conformance check cannot compare.
    device_warnings: Vec<String>,
    /// The CPU's irradiance rule (the reference's, or one for a requested tolerance).
    pub(super) rule: Adaptive,
    /// Light sampling's tables, built on first use and kept for every later call (a textured
    /// dome's alias table and tiles cost a pass over its texels): the environment tables, and
    /// the per-selection weights (`query/sample.rs`).
    pub(super) sampling_env:
        std::sync::OnceLock<std::sync::Arc<Vec<Option<crate::prepare::env_table::EnvTable>>>>,
    pub(super) sampling_tables: [std::sync::OnceLock<crate::cpu::sample::SceneTables>; 3],
    /// On a GPU, the sample and pdf kernels' records and texture atlas with the textured domes'
    /// sampling tables appended (`gpu::sample::SampleLights`), built on first use; or the bytes
    /// they would need, over the device's storage binding limit.
    pub(super) sampling_gpu:
        std::sync::OnceLock<std::result::Result<crate::gpu::sample::SampleLights, u64>>,
    /// Irradiance rows the kernel gave up on and the host recomputed (`redo_spent_rows`,
    /// `host_recomputed_rows`).
    spent_rows: std::sync::atomic::AtomicUsize,
    /// The layout of the caller's buffers in GPU-resident queries (`with_row_layout`).
    pub(super) row_layout: super::RowLayout,
    /// The rows each invocation of a GPU-resident emission, intensity or radiance query takes;
    /// `None`: the device's default (`GpuContext::rows_per_invocation`). Set only through
    /// `testkit::with_rows_per_invocation`.
    pub(crate) rows_per_invocation: Option<u32>,
}

impl std::fmt::Debug for PreparedScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedScene")
            .field("backend", &self.backend)
            .field("lights", &self.lights.len())
            .finish()
    }
}

impl PreparedScene {
    pub(crate) fn new(
        backend: Backend,
        lights: &[Light],
        mode: TemperatureMode,
        portal_mode: PortalMode,
        irradiance_tolerance: Option<f64>,
    ) -> Result<Self> {
        let mut scene = Self::from_prepared(backend, prepare::prepare(lights, mode, portal_mode)?)?;
        if let Some(rel) = irradiance_tolerance {
            scene.rule = Adaptive::for_tolerance(rel);
        }
        Ok(scene)
    }

    /// A scene of lights already prepared (the GPU records are packed from exactly these
    /// constants).
    pub(crate) fn from_prepared(backend: Backend, mut lights: Vec<Prepared>) -> Result<Self> {
        let mut device_warnings = Vec::new();
        let gpu = match &backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => {
                let (atlas, bases) = ies_atlas::scene_atlas(&lights)
                    .map_err(|e| LuxError::input("IES profiles", e.to_string()))?;
                let limit = g.atlas_limit();
                // Latlong domes whose row tables this device cannot hold beside the textures:
                // their irradiance is the CPU reference's here (every query reads gpu_path).
                for k in texture_atlas::tables_beyond(&lights, limit) {
                    lights[k].gpu_path = GpuPath::HostIrradiance(texture_atlas::TABLES_BEYOND);
                }
                let (tex_atlas, offsets, reduced) = texture_atlas::scene_atlas(&lights, limit)
                    .map_err(|e| LuxError::input("textures", e.to_string()))?;
                for r in reduced {
                    device_warnings.push(format!(
                        "{}: the GPU reads this {} × {} texture reduced to {} × {} (2 × 2 box \
                         averages), to fit the device's storage binding limit of {limit} bytes; \
                         its GPU values differ from the CPU reference (--device cpu), which reads \
                         it in full",
                        r.path, r.from.0, r.from.1, r.to.0, r.to.1
                    ));
                }
                let (mesh_atlas, meshes) = mesh_atlas::scene_atlas(&lights);
                let mut records: Vec<record::Record> = lights
                    .iter()
                    .zip(bases)
                    .zip(offsets)
                    .zip(meshes)
                    .map(|(((p, base), offset), mesh)| record::pack(p, base, offset, mesh))
                    .collect();
                luminance_weights_into(&lights, &mut records);
                g.upload(&records, &atlas.data, &tex_atlas, &mesh_atlas)?
            }
        };
        // How lights are evaluated other than as authored (zero-size lights), on every device.
        let warnings = lights
            .iter()
            .filter_map(|p| p.warning.clone())
            .chain(device_warnings.iter().cloned())
            .collect();
        Ok(PreparedScene {
            backend,
            lights,
            gpu,
            scratch: Mutex::new(None),
            warnings,
            device_warnings,
            rule: Adaptive::REFERENCE,
            sampling_env: Default::default(),
            sampling_tables: Default::default(),
            sampling_gpu: Default::default(),
            spent_rows: Default::default(),
            row_layout: Default::default(),
            rows_per_invocation: None,
        })
    }

    /// Warnings about how this scene is evaluated: each zero-size light and how it is evaluated
    /// (DESIGN.md §2), then each texture the GPU holds at a lower resolution than its file
    /// because the scene's textures exceed the device's storage binding limit (named with both
    /// sizes; none on the CPU reference).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The warnings of [`PreparedScene::warnings`] that say this device's values differ from
    /// the reference by design (reduced textures).
    pub(crate) fn device_warnings(&self) -> &[String] {
        &self.device_warnings
    }

    /// Light `k` as this scene evaluates it (its `gpu_path` as this device leaves it:
    /// `gpu::texture_atlas::tables_beyond`).
    pub(crate) fn prepared(&self, k: usize) -> &Prepared {
        &self.lights[k]
    }

    /// The number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// The size (width, height) of light `k`'s dome texture as loaded, if it has one.
    pub fn texture_size(&self, k: usize) -> Option<(u32, u32)> {
        let t = self.lights.get(k)?.dome_texture()?;
        Some((t.image.width as u32, t.image.height as u32))
    }

    /// Every file on disk the lights' assets were read from (IES profiles, TILT files, textures,
    /// the packages holding them), each once, in the order first read: what a caller writing
    /// outputs must not write over (DESIGN.md §4).
    pub fn files_read(&self) -> Vec<&std::path::Path> {
        let mut out: Vec<&std::path::Path> = Vec::new();
        for f in self.lights.iter().flat_map(|p| &p.files_read) {
            if !out.contains(&f.as_path()) {
                out.push(f);
            }
        }
        out
    }

    /// The lights as evaluated, in order (a ShapingAPI whose factor is 1 everywhere is dropped).
    pub fn lights(&self) -> impl Iterator<Item = &Light> {
        self.lights.iter().map(|p| &p.light)
    }

    /// emission(light, ω) for every direction (DESIGN.md §3): ω points away from the light (for
    /// a dome, toward the environment); any non-zero length, normalised here.
    pub fn emission(&self, dirs: &[[f32; 3]], acc: Accumulate) -> Result<Vec<[f32; 3]>> {
        check_directions("directions", dirs)?;
        let per_light = acc == Accumulate::PerLight;
        let mut out = self.run(Kernel::Emission, dirs, None, per_light, || {
            cpu::emission_batch(&self.lights, dirs, per_light)
        })?;
        self.add_host(per_light, &mut out, Prepared::emission_on_host, |l| {
            cpu::emission_batch(l, dirs, true)
        });
        Ok(out)
    }

    /// intensity(light, ω) for every direction (DESIGN.md §3): the far-field RGB intensity
    /// `∫ L cos dA` along ω (cd for L in nits); 0 for distant and dome lights.
    pub fn intensity(&self, dirs: &[[f32; 3]], acc: Accumulate) -> Result<Vec<[f32; 3]>> {
        check_directions("directions", dirs)?;
        let per_light = acc == Accumulate::PerLight;
        let mut out = self.run(Kernel::Intensity, dirs, None, per_light, || {
            cpu::intensity_batch(&self.lights, dirs, per_light)
        })?;
        self.add_host(per_light, &mut out, Prepared::on_host, |l| {
            cpu::intensity_batch(l, dirs, true)
        });
        Ok(out)
    }

    /// Each light's total emitted power (RGB, lm per channel for L in nits): the integral of
    /// its intensity over the sphere, in f64 (`None` for distant and dome lights, at infinity).
    pub fn flux(&self) -> Vec<Option<DVec3>> {
        self.lights.iter().map(cpu::power::flux).collect()
    }

    /// radiance(x, ω) for every (point, direction) pair (DESIGN.md §3): ω points from x toward
    /// the light.
    pub fn radiance(
        &self,
        points: &[[f32; 3]],
        dirs: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        check_pairs(points, "points", dirs, "directions")?;
        let per_light = acc == Accumulate::PerLight;
        let mut out = self.run(Kernel::Radiance, points, Some(dirs), per_light, || {
            cpu::radiance_batch(&self.lights, points, dirs, per_light)
        })?;
        self.add_host(per_light, &mut out, Prepared::radiance_on_host, |l| {
            cpu::radiance_batch(l, points, dirs, true)
        });
        Ok(out)
    }

    /// On a GPU evaluator, the kernels give 0 for the lights `on_host` names for the query
    /// ([`Prepared::gpu_path`]: mesh lights): their values are the CPU reference's (`values`
    /// of one light, one row per input row), added here. Nothing to do on the CPU backend.
    fn add_host(
        &self,
        per_light: bool,
        out: &mut [[f32; 3]],
        on_host: impl Fn(&Prepared) -> bool,
        values: impl Fn(&[Prepared]) -> Vec<DVec3>,
    ) {
        if !matches!(self.backend, Backend::Gpu(_)) {
            return;
        }
        for (k, light) in self.lights.iter().enumerate() {
            if on_host(light) {
                add_rows(out, k, per_light, values(std::slice::from_ref(light)));
            }
        }
    }

    fn run(
        &self,
        kernel: Kernel,
        a: &[[f32; 3]],
        b: Option<&[[f32; 3]]>,
        per_light: bool,
        on_cpu: impl FnOnce() -> Vec<DVec3>,
    ) -> Result<Vec<[f32; 3]>> {
        self.run_filtered(kernel, a, b, per_light, LIGHTS_ALL, on_cpu)
    }

    /// [`Self::run`] with the irradiance kernel integrating only the lights `light_filter`
    /// names on a GPU (`gpu::record::LIGHTS_*`). `on_cpu` answers on the CPU reference, for
    /// every light: only `LIGHTS_ALL` is asked for there (`irradiance_plan` splits on a GPU
    /// only).
    fn run_filtered(
        &self,
        kernel: Kernel,
        a: &[[f32; 3]],
        b: Option<&[[f32; 3]]>,
        per_light: bool,
        light_filter: u32,
        on_cpu: impl FnOnce() -> Vec<DVec3>,
    ) -> Result<Vec<[f32; 3]>> {
        match (&self.backend, &self.gpu) {
            (Backend::Cpu, _) => Ok(on_cpu()
                .into_iter()
                .map(|c| c.as_vec3().to_array())
                .collect()),
            (Backend::Gpu(g), Some(lights)) => {
                let mut scratch = self
                    .scratch
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                // Directions (and normals) are normalised in f64 as they are written to the
                // device, as the CPU reference normalises them: the kernels' f32 `normalize`
                // overflows on components near 1e38 and loses subnormal ones (which a device may
                // flush to zero).
                let unit = Input {
                    rows: a,
                    map: &unit_row,
                };
                let (a, b) = match (kernel, b) {
                    (Kernel::Emission | Kernel::Intensity, _) => (unit, None),
                    (_, b) => (
                        Input {
                            rows: a,
                            map: &|r| r,
                        },
                        b.map(|rows| Input {
                            rows,
                            map: &unit_row,
                        }),
                    ),
                };
                g.run(kernel, lights, &mut scratch, a, b, per_light, light_filter)
            }
            // No lights: every row is zero.
            (Backend::Gpu(_), None) => {
                let rows = if per_light { self.lights.len() } else { 1 };
                Ok(vec![[0.0; 3]; rows * a.len()])
            }
        }
    }
}

/// Adds light `k`'s values (one per input row) to `out`: into its own rows (light-major) with
/// `per_light`, else into the sums, in f64 before rounding to f32.
fn add_rows(out: &mut [[f32; 3]], k: usize, per_light: bool, values: Vec<DVec3>) {
    let n = values.len();
    for (i, v) in values.into_iter().enumerate() {
        let row = if per_light { k * n + i } else { i };
        let sum = DVec3::from_array(out[row].map(f64::from)) + v;
        out[row] = sum.as_vec3().to_array();
    }
}

/// A row scaled to unit length in f64 (finite, non-zero rows: checked by the queries). The
/// largest component is divided out first, so that neither 1e38 nor 1e-45 over- or underflows.
fn unit_row(r: [f32; 3]) -> [f32; 3] {
    let d = DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64);
    let m = d.abs().max_element();
    if m == 0.0 {
        return r;
    }
    let u = (d / m).normalize();
    [u.x as f32, u.y as f32, u.z as f32]
}

/// The luminance weight GPU-resident sampling's `bound` choice reads from the records
/// (`Record::select[1]`): the luminance of each light's base (`cpu::sample::select`, in f64),
/// divided by the scene's largest so that f32 holds their ratios whatever the scene's units.
/// The power weights (`select[0]`) cost an integral over each shaped light's emission and are
/// filled only in the records of a `Selection::Power` resident call
/// (`PreparedScene::encode_sample`), from the power tables the host path builds too.
fn luminance_weights_into(lights: &[Prepared], records: &mut [record::Record]) {
    use crate::cpu::sample::select::weight_of;
    let luma: Vec<f64> = lights
        .iter()
        .map(|p| {
            if p.profile.dark {
                0.0
            } else {
                weight_of(p.base)
            }
        })
        .collect();
    for (r, y) in records.iter_mut().zip(scaled_weights(&luma)) {
        r.select[1] = y;
    }
}

/// Weights divided by the largest finite one, as f32; a positive weight stays positive (at
/// least the least normal f32), a non-finite or non-positive one is 0.
pub(super) fn scaled_weights(w: &[f64]) -> Vec<f32> {
    let top = w
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    w.iter()
        .map(|&v| {
            if !(v > 0.0 && v.is_finite() && top > 0.0) {
                0.0
            } else {
                ((v / top) as f32).max(f32::MIN_POSITIVE)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{Accumulate, Backend};

    /// A batch cut into many GPU chunks (the chunk size capped, the last chunk partial, the
    /// first larger than one upload piece) gives the rows one chunk gives, summed and per light,
    /// for one input (emission) and two (radiance).
    #[test]
    fn many_chunks_equal_one_chunk() {
        let Some(eval) = super::super::test_gpu() else {
            return;
        };
        let Backend::Gpu(ctx) = &eval.backend else {
            unreachable!("a GPU evaluator")
        };
        let scene = eval
            .prepare(&crate::synthetic::synthetic_lights(3))
            .expect("the synthetic lights prepare");
        let n = 300_007;
        let dirs: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                let t = i as f32 * 0.618_034;
                [t.cos(), t.sin(), 1.0 - 2.0 * (i as f32 + 0.5) / n as f32]
            })
            .collect();
        let points: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                [
                    (i % 17) as f32 - 8.0,
                    (i % 5) as f32 * 0.5 - 1.0,
                    (i % 11) as f32,
                ]
            })
            .collect();
        for acc in [Accumulate::Sum, Accumulate::PerLight] {
            let emission = scene.emission(&dirs, acc).unwrap();
            let radiance = scene.radiance(&points, &dirs, acc).unwrap();
            // 131,077 rows a chunk: two chunks and a partial third, each of two upload pieces.
            ctx.cap_chunk_rows((1 << 17) + 5);
            assert!(
                scene.emission(&dirs, acc).unwrap() == emission,
                "{acc:?} emission"
            );
            assert!(
                scene.radiance(&points, &dirs, acc).unwrap() == radiance,
                "{acc:?} radiance"
            );
            ctx.cap_chunk_rows(usize::MAX);
            assert_eq!(
                emission.len(),
                n * if acc == Accumulate::PerLight { 3 } else { 1 }
            );
            assert!(emission.iter().flatten().any(|&v| v > 0.0));
        }
    }
}
