//! GPU-resident queries: a renderer that already holds its directions, points and normals in
//! `wgpu::Buffer`s on its own device gets the results in its own buffers, recorded into its own
//! command encoder, with no host round trip (no upload, no readback, no submit by luxeval).
//! The buffer contract is in the docs of `PreparedScene::encode_emission` (public, unlike this
//! module's).

use super::sample::{SampleOptions, Selection};
use super::{Accumulate, Backend, Evaluator, PreparedScene, RowLayout};
use crate::error::{LuxError, Result};
use crate::gpu::record::{SELECT_BOUND, SELECT_POWER};
use crate::gpu::resident::{Operand, ResidentDraw};
use crate::gpu::{GpuContext, GpuLights, Kernel};
use crate::prepare::{GpuPath, Prepared};

impl Evaluator {
    /// An evaluator on the caller's device (a renderer's own `wgpu::Device` and `wgpu::Queue`,
    /// from `luxeval::wgpu`, luxeval's wgpu): every query, host path and GPU-resident, runs there.
    /// luxeval installs no error handler or device-lost callback on it. Fails when the device's
    /// limits are below what the kernels need (`wgpu::Limits::default()` is enough).
    ///
    /// [`Evaluator::device_name`] reports the adapter the device belongs to (wgpu keeps its
    /// info), marked "caller's device".
    pub fn from_wgpu(device: wgpu::Device, queue: wgpu::Queue) -> Result<Self> {
        Ok(Evaluator {
            backend: Backend::Gpu(std::sync::Arc::new(GpuContext::from_device(device, queue)?)),
            temperature_mode: Default::default(),
            portal_mode: Default::default(),
            irradiance_tolerance: None,
        })
    }

    /// The device queries run on (the caller's, or the one [`Evaluator::gpu`] opened): create
    /// the buffers of GPU-resident queries on it. `None` on the CPU reference.
    pub fn wgpu_device(&self) -> Option<&wgpu::Device> {
        match &self.backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(&g.device),
        }
    }

    /// The queue of [`Evaluator::wgpu_device`]; submit GPU-resident work on it.
    pub fn wgpu_queue(&self) -> Option<&wgpu::Queue> {
        match &self.backend {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(&g.queue),
        }
    }
}

impl PreparedScene {
    /// This scene with its GPU-resident queries (`encode_emission`, `encode_intensity`,
    /// `encode_radiance`, `encode_irradiance`) reading and writing rows of `layout` in the
    /// caller's buffers: [`RowLayout::Packed`] (12 bytes, the default) or [`RowLayout::Vec4`]
    /// (16 bytes; the fourth input float is ignored and the fourth output float written 0).
    /// Nothing else changes: the host path's queries and `encode_sample` keep their own rows,
    /// and the values are the same in either layout (the same kernels, compiled with the row's
    /// stride as a constant: WGSL's `override ROW_WORDS`).
    pub fn with_row_layout(mut self, layout: RowLayout) -> Self {
        self.row_layout = layout;
        self
    }

    /// The layout of the caller's buffers in GPU-resident queries ([`PreparedScene::with_row_layout`]).
    pub fn row_layout(&self) -> RowLayout {
        self.row_layout
    }

    /// Records emission(light, ω) (see [`PreparedScene::emission`]) for `count` directions in
    /// `dirs` into `encoder`, writing `out`: GPU-resident evaluation, for callers whose data is
    /// already on the device. Nothing is uploaded, submitted or read back; the results are in
    /// `out` once the caller submits the encoder. The first call of each query builds its
    /// pipeline (seconds on a CPU driver such as lavapipe); each call creates a small uniform
    /// buffer and a bind group.
    ///
    /// # Buffers
    ///
    /// Every buffer belongs to this scene's device ([`Evaluator::from_wgpu`], or
    /// [`Evaluator::wgpu_device`] of a GPU evaluator) and has `wgpu::BufferUsages::STORAGE`.
    /// Inputs and outputs are rows of three tightly packed `f32` (x, y, z or r, g, b): a 12-byte
    /// stride with no padding (not a WGSL `array<vec3<f32>>`, whose stride is 16), unless the
    /// scene was given [`RowLayout::Vec4`] ([`PreparedScene::with_row_layout`]): then rows of
    /// four `f32`, 16 bytes, the fourth ignored on input and written 0. Inputs hold
    /// at least `count` rows; `out` at least `count` rows with [`Accumulate::Sum`], or
    /// `lights × count` rows with [`Accumulate::PerLight`], light-major (row `l·count + i` is
    /// light `l` at sample `i`). Only the first rows are read and written: larger buffers are
    /// fine. The output may not be an input.
    ///
    /// The output rows are overwritten, never added to: in summed mode the first light group
    /// writes each row and later groups (one dispatch per group, in order) add to it. Rows past
    /// those the call covers are left as they are.
    ///
    /// # Directions
    ///
    /// Directions (and the normals of [`PreparedScene::encode_irradiance`]) need not be unit
    /// length: the kernel normalises them in f32. The host path ([`PreparedScene::emission`]
    /// and the others) checks them and normalises them in f64 first; here nothing is read on
    /// the host, so nothing is checked: a zero or non-finite row gives an unspecified result
    /// (NaN or zero), and rows with very large components (whose squares overflow f32, from
    /// about 1.8e19) or subnormal ones (which a device may flush to zero) can give other values
    /// than the host path. Pass unit vectors to get the host path's results.
    ///
    /// # Errors
    ///
    /// [`LuxError::InvalidInput`] when a buffer lacks `STORAGE`, is too small for `count`
    /// rows, or the output is an input; when `count` rows (times the lights, per light) exceed
    /// the device's storage binding limit (the message gives the most one call takes: split
    /// the batch); when the scene is on the CPU reference. [`LuxError::Gpu`] when wgpu rejects
    /// the bind group (a buffer of another device, for one) or a pipeline. wgpu cannot tell a
    /// buffer of another `wgpu::Instance` from one of its own (it panics or binds the wrong
    /// buffer), so neither can luxeval: keep the device and the buffers of one instance.
    pub fn encode_emission(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        dirs: &wgpu::Buffer,
        out: &wgpu::Buffer,
        count: u32,
        acc: Accumulate,
    ) -> Result<()> {
        let dirs = Operand {
            name: "directions",
            buffer: dirs,
        };
        self.encode(encoder, Kernel::Emission, dirs, None, out, count, acc)
    }

    /// Records intensity(light, ω) (see [`PreparedScene::intensity`]) for `count` directions,
    /// as [`PreparedScene::encode_emission`] does.
    pub fn encode_intensity(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        dirs: &wgpu::Buffer,
        out: &wgpu::Buffer,
        count: u32,
        acc: Accumulate,
    ) -> Result<()> {
        let dirs = Operand {
            name: "directions",
            buffer: dirs,
        };
        self.encode(encoder, Kernel::Intensity, dirs, None, out, count, acc)
    }

    /// Records radiance(x, ω) (see [`PreparedScene::radiance`]) for `count` (point, direction)
    /// pairs, as [`PreparedScene::encode_emission`] does.
    pub fn encode_radiance(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        points: &wgpu::Buffer,
        dirs: &wgpu::Buffer,
        out: &wgpu::Buffer,
        count: u32,
        acc: Accumulate,
    ) -> Result<()> {
        let points = Operand {
            name: "points",
            buffer: points,
        };
        let dirs = Operand {
            name: "directions",
            buffer: dirs,
        };
        self.encode(
            encoder,
            Kernel::Radiance,
            points,
            Some(dirs),
            out,
            count,
            acc,
        )
    }

    /// Records irradiance(x, n) (see [`PreparedScene::irradiance`]) for `count` (point, normal)
    /// pairs, as [`PreparedScene::encode_emission`] does.
    ///
    /// Refused with [`LuxError::NotOnDevice`] naming the first such light when the scene holds
    /// a light whose irradiance the host path computes on the CPU (textured rects of more than
    /// 64 × 64 texels, `prepare::gpu_path::RECT_TEXELS_ON_DEVICE`; textured
    /// domes, masked or not, but latlong ones under a conformal frame, masked domes whose
    /// portals overlap in more ways than the kernel sums, IES profiles of type B under
    /// angleScale:
    /// `prepare::latlong_rows::gpu_path` and `prepare::gpu_path::GpuPath`): the kernel gives 0
    /// for them, which this path would return as if it were the answer. Prepare those lights in a scene
    /// of their own and use [`PreparedScene::irradiance`] for them.
    ///
    /// A (light, receiver) the kernel cannot finish is NaN (the host path recomputes such rows
    /// on the CPU reference; this path has no host step): on any adapter, a chart that needs
    /// more outer breakpoints than the kernel holds (96: an IES profile with many grid
    /// surfaces across a large light seen from near), and on llvmpipe (lavapipe), whose loops
    /// stop silently after 65,535 iterations per invocation, a quadrature cut short.
    pub fn encode_irradiance(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        points: &wgpu::Buffer,
        normals: &wgpu::Buffer,
        out: &wgpu::Buffer,
        count: u32,
        acc: Accumulate,
    ) -> Result<()> {
        if let Some((p, reason)) = self.lights.iter().find_map(|p| match p.gpu_path {
            GpuPath::HostIrradiance(reason)
            | GpuPath::HostIntensity(reason)
            | GpuPath::RadianceOnDevice(reason)
            | GpuPath::Host(reason) => Some((p, reason)),
            GpuPath::Device | GpuPath::HostIntensityOnly(_) => None,
        }) {
            return Err(LuxError::NotOnDevice {
                light: p.light.path.clone(),
                query: "irradiance".into(),
                reason: format!(
                    "{reason}, and its irradiance is integrated on the host (exactly, in f64); \
                     evaluate it with PreparedScene::irradiance"
                ),
            });
        }
        let points = Operand {
            name: "points",
            buffer: points,
        };
        let normals = Operand {
            name: "normals",
            buffer: normals,
        };
        self.encode(
            encoder,
            Kernel::Irradiance,
            points,
            Some(normals),
            out,
            count,
            acc,
        )
    }

    /// Records [`PreparedScene::sample`] into `encoder` for points and normals already on the
    /// device: `count` directions toward the scene's lights for each of `n_points` points, the
    /// light chosen on the device. GPU-resident sampling for renderers; nothing is uploaded,
    /// submitted or read back, and the buffers follow [`PreparedScene::encode_emission`]'s
    /// contract (`STORAGE`, this scene's device, only the first rows read and written).
    ///
    /// # Buffers
    ///
    /// `points` and `normals` hold `n_points` rows of three packed `f32`. `normals` is optional;
    /// where given, a zero row stands for "no normal" at that point (the host path refuses one)
    /// and the others need not be unit length. `out` receives `n_points × count` rows,
    /// point-major (row `i·count + j` is sample j of point i), of 8 `f32` (32 bytes):
    /// `ω.x, ω.y, ω.z, pdf, L.r, L.g, L.b, light` — the fields of [`Samples`] but
    /// `light_pdf`: `pdf` is `P(l | x) · pdf_l(ω)` (`+∞` for a delta light, 0 where no light
    /// reaches the point) and `light` the chosen light's index as an `f32` (exact below 2²⁴),
    /// `−1` for none.
    ///
    /// # What it draws
    ///
    /// The rows [`PreparedScene::sample`] draws with the same [`SampleOptions`], up to f32:
    /// the generator is keyed alike (DESIGN.md §9 S3, `opts.first_point` the key of the first
    /// point), and the light is chosen by the same weights, evaluated in f32 on the device
    /// (`shaders/sample/select.wgsl`), so that a row whose dimension-2 uniform falls within
    /// f32 rounding of the border between two lights' shares may name the other light.
    /// `Selection::Power` and `Selection::Bound` (the default) run on the device;
    /// `Selection::Exact` integrates each light's irradiance per receiver on the host, and is
    /// refused here.
    ///
    /// # Errors
    ///
    /// [`LuxError::InvalidInput`] for `count` 0, `Selection::Exact`, a buffer that lacks
    /// `STORAGE` or is too small, an output that is an input, more rows than one binding or
    /// dispatch holds (the message gives the most one call takes; split the points and set
    /// `first_point`), more than 16,384 lights on a CPU driver such as lavapipe (whose loops
    /// stop after 65,535 iterations), and a scene on the CPU reference.
    /// [`LuxError::Gpu`] as [`PreparedScene::encode_emission`].
    ///
    /// The first sampling call of a scene with a textured dome (here or on the host path)
    /// builds its sampling tables and uploads them with the textures beside the scene's
    /// (a queue write and a copy submitted on the device's queue, once); a scene whose
    /// textures and tables exceed the device's storage binding limit is refused here
    /// ([`LuxError::InvalidInput`]; the host path samples it on the CPU reference).
    ///
    /// [`Samples`]: super::sample::Samples
    #[allow(clippy::too_many_arguments)]
    pub fn encode_sample(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        points: &wgpu::Buffer,
        normals: Option<&wgpu::Buffer>,
        out: &wgpu::Buffer,
        n_points: u32,
        count: u32,
        opts: &SampleOptions,
    ) -> Result<()> {
        let Backend::Gpu(g) = &self.backend else {
            return Err(no_device());
        };
        self.check_sampled_on_device()?;
        let selection = match opts.selection {
            Selection::Power => SELECT_POWER,
            Selection::Bound => SELECT_BOUND,
            Selection::Exact => {
                return Err(LuxError::input(
                    "selection",
                    "exact: choosing by each light's exact irradiance integrates it per receiver \
                     on the host; use PreparedScene::sample, or Selection::Bound on the device",
                ));
            }
        };
        // The scene's records and the sampling kernels' copy (textured domes' tables appended,
        // uploaded on the first sampling call); a scene with no lights binds a placeholder.
        let mut placeholder = None;
        let own;
        let (lights, sampling) = match self.sampling_gpu() {
            Some((_, lights, sampling)) => (lights, sampling),
            None => {
                if let Some(bytes) = self.sampling_tables_too_large() {
                    return Err(LuxError::input(
                        "dome textures",
                        format!(
                            "the scene's textures and textured domes' sampling tables need \
                             {bytes} bytes, over this device's storage binding limit of {} \
                             bytes; use PreparedScene::sample (it samples such a scene on the \
                             CPU reference)",
                            g.device_limits().max_storage_buffer_binding_size
                        ),
                    ));
                }
                let lights = self.device_lights(g, &mut placeholder)?;
                // No tables: the scene's own buffers (never too large).
                own = g.sample_lights(lights, &[]).map_err(|bytes| {
                    LuxError::input("lights", format!("{bytes} bytes over the binding limit"))
                })?;
                (lights, &own)
            }
        };
        let points = Operand {
            name: "points",
            buffer: points,
        };
        let normals = normals.map(|buffer| Operand {
            name: "normals",
            buffer,
        });
        let out = Operand {
            name: "out",
            buffer: out,
        };
        // The power weights integrate each shaped light's emission: computed on the first
        // call that chooses by power (the host path's tables), not when the scene is prepared
        // nor again on later calls.
        let power_weights =
            || super::scene::scaled_weights(self.sampling_tables(Selection::Power).power_weights());
        let power =
            (opts.selection == Selection::Power).then_some(&power_weights as &dyn Fn() -> Vec<f32>);
        let draw = ResidentDraw {
            points: n_points,
            per_point: count,
            seed: opts.seed,
            first_point: opts.first_point as u32,
            selection,
            power,
        };
        g.encode_sample(
            encoder,
            lights,
            sampling,
            self.lights.len(),
            points,
            normals,
            out,
            draw,
        )
    }

    /// Refuses a GPU-resident query of a scene holding a light whose `kernel` query the host
    /// computes (`GpuPath::Host`: every query; `RadianceOnDevice`: all but radiance;
    /// `HostIntensity`, `HostIntensityOnly`: intensity, of mesh lights): the kernels give 0 for it, which this path
    /// would return as if it were the answer. A masked dome's emission and radiance are the
    /// device's (`GpuPath::HostIrradiance`), so they pass.
    fn check_all_on_device(&self, kernel: Kernel) -> Result<()> {
        let refused = |p: &Prepared| match kernel {
            Kernel::Radiance => p.radiance_on_host(),
            Kernel::Emission => p.emission_on_host(),
            _ => p.on_host(),
        };
        match self.lights.iter().find_map(|p| match p.gpu_path {
            GpuPath::Host(reason)
            | GpuPath::RadianceOnDevice(reason)
            | GpuPath::HostIntensity(reason)
            | GpuPath::HostIntensityOnly(reason)
                if refused(p) =>
            {
                Some((p, reason))
            }
            _ => None,
        }) {
            Some((p, reason)) => Err(LuxError::NotOnDevice {
                light: p.light.path.clone(),
                query: format!("{kernel:?}").to_lowercase(),
                reason: format!(
                    "{reason}, whose {} the host evaluates (in f64); use the PreparedScene \
                     query of the same name",
                    format!("{kernel:?}").to_lowercase()
                ),
            }),
            None => Ok(()),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        kernel: Kernel,
        a: Operand<'_>,
        b: Option<Operand<'_>>,
        out: &wgpu::Buffer,
        count: u32,
        acc: Accumulate,
    ) -> Result<()> {
        let Backend::Gpu(g) = &self.backend else {
            return Err(no_device());
        };
        self.check_all_on_device(kernel)?;
        let out = Operand {
            name: "out",
            buffer: out,
        };
        let per_light = acc == Accumulate::PerLight;
        let mut placeholder = None;
        let lights = self.device_lights(g, &mut placeholder)?;
        g.encode(
            encoder,
            kernel,
            lights,
            self.lights.len(),
            a,
            b,
            out,
            count,
            per_light,
            self.row_layout.words(),
            self.rows_per_invocation,
        )
    }
}

impl PreparedScene {
    /// The scene's lights on the device; a scene with no lights uploads none, and the kernels
    /// still need a record array bound (`placeholder` holds it).
    fn device_lights<'a>(
        &'a self,
        g: &GpuContext,
        placeholder: &'a mut Option<GpuLights>,
    ) -> Result<&'a GpuLights> {
        match &self.gpu {
            Some(l) => Ok(l),
            None => Ok(placeholder.insert(g.no_lights()?)),
        }
    }
}

/// The refusal of GPU-resident work on a scene prepared on the CPU reference.
fn no_device() -> LuxError {
    LuxError::input(
        "backend",
        "this scene was prepared on the CPU reference, which has no device; prepare it with \
         Evaluator::from_wgpu or Evaluator::gpu",
    )
}
