//! The wgpu side (DESIGN.md §1): adapter and device, compute pipelines built lazily (each the
//! first time a query needs it), the packed light records, and chunked dispatch with reusable
//! buffers so that any batch fits the device's buffer and dispatch limits. Depends on the model
//! and `prepare` only, never on `cpu`.

pub(crate) mod cache;
pub(crate) mod dispatch;
pub(crate) mod ies_atlas;
pub(crate) mod launch;
pub(crate) mod mesh_atlas;
pub(crate) mod record;
pub(crate) mod resident;
pub(crate) mod sample;
pub(crate) mod shaders;
pub(crate) mod texture_atlas;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::error::{LuxError, Result};
pub use cache::CacheStatus;
pub(crate) use dispatch::{GpuLights, Input, Scratch};
pub(crate) use record::Params;
pub(crate) use shaders::{Features, Kernel};

/// What `luxeval info` reports about an adapter.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
}

impl From<&wgpu::AdapterInfo> for AdapterSummary {
    fn from(i: &wgpu::AdapterInfo) -> Self {
        AdapterSummary {
            name: i.name.clone(),
            backend: format!("{:?}", i.backend),
            device_type: format!("{:?}", i.device_type),
            driver: format!("{} {}", i.driver, i.driver_info).trim().to_string(),
        }
    }
}

/// The limits of an open device that bound a batch, as `luxeval info` reports them.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct DeviceLimits {
    pub max_storage_buffer_binding_size: u64,
    pub max_buffer_size: u64,
    pub max_compute_workgroups_per_dimension: u32,
    pub max_compute_invocations_per_workgroup: u32,
    /// Samples one dispatch evaluates for one light (summed).
    pub samples_per_dispatch_one_light: usize,
}

/// How long each step of opening a GPU evaluator took (`luxeval bench`'s cold start).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Startup {
    /// Creating the wgpu instance (loading the Vulkan loader and drivers).
    pub instance: std::time::Duration,
    /// Finding the adapter.
    pub adapter: std::time::Duration,
    /// Opening the device.
    pub device: std::time::Duration,
    /// Each pipeline compiled so far, in order, by name (the entry point, with the optional
    /// parts it was built with: `+ies`, `+texture`, `+chart`, `+line`).
    pub pipelines: Vec<(String, std::time::Duration)>,
}

fn pipeline_name(kernel: Kernel, features: Features, rows: RowShape) -> String {
    let mut name = format!("{}{}", kernel.entry_point(), features.suffix());
    if rows.words != RowShape::HOST.words {
        name += &format!("+rows{}", rows.words);
    }
    if rows.per_invocation != RowShape::HOST.per_invocation {
        name += &format!("+x{}", rows.per_invocation);
    }
    name
}

/// The rows of a query's buffers as its pipeline is compiled for them: the f32 words of a row
/// (WGSL's `ROW_WORDS`: 3 packed, 4 for `RowLayout::Vec4`) and the rows each invocation of the
/// emission, intensity and radiance kernels takes (`ROWS_PER_INVOCATION`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct RowShape {
    pub words: u32,
    pub per_invocation: u32,
}

impl RowShape {
    /// The host path's rows (and the WGSL defaults): packed, one per invocation.
    pub const HOST: RowShape = RowShape {
        words: 3,
        per_invocation: 1,
    };

    /// The pipeline constants that differ from the WGSL defaults.
    fn constants(self) -> Vec<(&'static str, f64)> {
        let mut c = Vec::new();
        if self.words != Self::HOST.words {
            c.push(("ROW_WORDS", self.words as f64));
        }
        if self.per_invocation != Self::HOST.per_invocation {
            c.push(("ROWS_PER_INVOCATION", self.per_invocation as f64));
        }
        c
    }
}

/// The rows each invocation of a GPU-resident emission, intensity or radiance query takes on a
/// hardware adapter ([`GpuContext::rows_per_invocation`]). Measured on an H200 (BENCHMARKS.md,
/// "A real GPU: NVIDIA H200"): one light's emission of 16M and 64M rows, the memory-bound
/// case, 1.33 to 1.35× faster with 2 than with 1; 8 lights per light 4 % slower; 4 rows an
/// invocation was no better than 2 at 16M rows and 2.7× slower at 64M.
const ROWS_PER_INVOCATION: u32 = 2;

/// Environment variable that picks an adapter by (case-insensitive) name substring.
pub const ADAPTER_ENV: &str = "LUXEVAL_ADAPTER";

/// The invocations llvmpipe runs together and whose loops share one budget (its SIMD vector
/// of 8 f32 lanes; [`GpuContext::lane_stride`] also spreads samples over whole workgroups if
/// that is measured to be the unit).
pub const LLVMPIPE_SHARED_LANES: u32 = 8;

fn instance() -> wgpu::Instance {
    // Backends and flags honour WGPU_BACKEND, WGPU_VALIDATION, ... (wgpu's own variables).
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// How much `--device auto` prefers an adapter of this type (lower first), `None` for software
/// adapters, which it never picks.
fn hardware_rank(t: wgpu::DeviceType) -> Option<u8> {
    match t {
        wgpu::DeviceType::DiscreteGpu => Some(0),
        wgpu::DeviceType::IntegratedGpu => Some(1),
        wgpu::DeviceType::VirtualGpu => Some(2),
        wgpu::DeviceType::Other => Some(3),
        wgpu::DeviceType::Cpu => None,
    }
}

/// Every adapter wgpu can see on this machine.
pub fn adapters() -> Vec<AdapterSummary> {
    let instance = instance();
    pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
        .iter()
        .map(|a| AdapterSummary::from(&a.get_info()))
        .collect()
}

/// A device and its pipelines. Opening one costs tens of milliseconds (adapter, device); each
/// pipeline is compiled the first time a query needs it (on lavapipe the irradiance pipeline
/// takes seconds, the others a fraction of one). Keep it for the whole batch.
pub(crate) struct GpuContext {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    pub(crate) limits: wgpu::Limits,
    pub(crate) layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: Mutex<HashMap<(Kernel, Features, RowShape), wgpu::ComputePipeline>>,
    /// The persistent pipeline cache and its file (gpu/cache.rs), where the adapter has one.
    cache: Option<(wgpu::PipelineCache, std::path::PathBuf)>,
    cache_status: CacheStatus,
    /// How long opening took, and each pipeline's compile (`luxeval bench`).
    startup: Mutex<Startup>,
    /// Why the device was lost, once it is (set by wgpu's device-lost callback): reported
    /// instead of the validation errors a lost device's buffers then raise.
    lost: Arc<Mutex<Option<String>>>,
    /// Whether the device is the caller's (`from_device`) rather than one luxeval opened.
    callers_device: bool,
    /// A cap on the rows of one chunk, below what the limits allow: tests lower it to cut
    /// small batches into many chunks (`usize::MAX` otherwise).
    chunk_rows_cap: std::sync::atomic::AtomicUsize,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("adapter", &self.info.name)
            .finish()
    }
}

impl GpuContext {
    /// Why the device was lost, if it was.
    pub(crate) fn lost(&self) -> Option<String> {
        self.lost
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clone()
    }

    /// Opens the adapter named by `LUXEVAL_ADAPTER` (a name substring), else the default
    /// high-performance adapter. No pipeline is built yet.
    pub fn new() -> Result<Self> {
        pollster::block_on(Self::new_async(false))
    }

    /// Opens a hardware adapter (`--device auto`, DESIGN.md §4): the best of those matching
    /// `LUXEVAL_ADAPTER` when set, else of all, that is not a software one (wgpu's
    /// `DeviceType::Cpu`: lavapipe/llvmpipe, SwiftShader, WARP run the kernels on the same cores
    /// as the f64 reference, more slowly). `NoAdapter` names the software adapters it passed over.
    pub fn new_hardware() -> Result<Self> {
        pollster::block_on(Self::new_async(true))
    }

    async fn new_async(hardware_only: bool) -> Result<Self> {
        let t0 = std::time::Instant::now();
        let instance = instance();
        let t_instance = t0.elapsed();
        let want = std::env::var(ADAPTER_ENV).unwrap_or_default();
        let adapter = match want.as_str() {
            _ if hardware_only => {
                let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
                let named = |a: &wgpu::Adapter| {
                    want.is_empty()
                        || a.get_info()
                            .name
                            .to_lowercase()
                            .contains(&want.to_lowercase())
                };
                let software: Vec<String> = adapters
                    .iter()
                    .filter(|a| named(a) && a.get_info().device_type == wgpu::DeviceType::Cpu)
                    .map(|a| a.get_info().name)
                    .collect();
                adapters
                    .into_iter()
                    .filter(|a| named(a))
                    .filter_map(|a| Some((hardware_rank(a.get_info().device_type)?, a)))
                    .min_by_key(|(rank, _)| *rank)
                    .map(|(_, a)| a)
                    .ok_or_else(|| LuxError::NoAdapter {
                        reason: match (software.is_empty(), want.is_empty()) {
                            (true, true) => "no GPU adapter".to_string(),
                            (true, false) => format!("no adapter matches {ADAPTER_ENV}={want:?}"),
                            (false, _) => format!(
                                "no hardware GPU adapter, only software ones ({})",
                                software.join(", ")
                            ),
                        },
                        source: None,
                    })?
            }
            want if !want.is_empty() => {
                let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
                let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
                adapters
                    .into_iter()
                    .find(|a| {
                        a.get_info()
                            .name
                            .to_lowercase()
                            .contains(&want.to_lowercase())
                    })
                    .ok_or_else(|| LuxError::NoAdapter {
                        reason: format!("{ADAPTER_ENV}={want:?} matches none of {names:?}"),
                        source: None,
                    })?
            }
            _ => instance
                .request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    ..Default::default()
                })
                .await
                .map_err(|e| LuxError::NoAdapter {
                    reason: e.to_string(),
                    source: Some(e),
                })?,
        };
        let t_adapter = t0.elapsed() - t_instance;
        let info = adapter.get_info();
        // Ask for everything the adapter offers: big batches want its largest buffers.
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("luxeval"),
                required_limits: limits.clone(),
                required_features: adapter.features() & wgpu::Features::PIPELINE_CACHE,
                ..Default::default()
            })
            .await
            .map_err(|source| LuxError::DeviceRequest {
                adapter: info.name.clone(),
                source,
            })?;
        // wgpu's default handler panics; errors are caught by scopes around each dispatch, and
        // anything that escapes them is logged rather than aborting the process.
        // (Only on luxeval's own device: a caller's device keeps the caller's handlers, see
        // `from_device`.)
        device.on_uncaptured_error(Arc::new(|e| log::error!("wgpu: {e}")));
        let lost = Arc::new(Mutex::new(None));
        let on_lost = Arc::clone(&lost);
        device.set_device_lost_callback(move |reason, message| {
            *on_lost
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(format!(
                "{reason:?}{}",
                if message.is_empty() {
                    String::new()
                } else {
                    format!(": {message}")
                }
            ));
        });
        // Fault injection for tests/bad_inputs.rs: a device that is lost once opened, to check
        // that a lost device is a runtime failure (exit 1) with a clear message, not a hang,
        // a panic or garbage.
        #[cfg(feature = "testkit")]
        if std::env::var("LUXEVAL_TEST_FAULT").as_deref() == Ok("device-lost") {
            device.destroy();
        }
        let startup = Startup {
            instance: t_instance,
            adapter: t_adapter,
            device: t0.elapsed() - t_instance - t_adapter,
            pipelines: Vec::new(),
        };
        Ok(Self::with_device(
            device, queue, info, limits, lost, startup,
        ))
    }

    /// The part of opening a context that follows the device: the bind group and pipeline
    /// layouts every kernel shares.
    fn with_device(
        device: wgpu::Device,
        queue: wgpu::Queue,
        info: wgpu::AdapterInfo,
        limits: wgpu::Limits,
        lost: Arc<Mutex<Option<String>>>,
        startup: Startup,
    ) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("luxeval queries"),
            entries: &[
                // One Params block per light group, selected by a dynamic offset.
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(
                            std::mem::size_of::<Params>() as u64
                        ),
                    },
                    count: None,
                },
                layout_entry(1, wgpu::BufferBindingType::Storage { read_only: true }),
                layout_entry(2, wgpu::BufferBindingType::Storage { read_only: true }),
                layout_entry(3, wgpu::BufferBindingType::Storage { read_only: true }),
                layout_entry(4, wgpu::BufferBindingType::Storage { read_only: false }),
                layout_entry(5, wgpu::BufferBindingType::Storage { read_only: true }),
                layout_entry(6, wgpu::BufferBindingType::Storage { read_only: true }),
                layout_entry(7, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("luxeval queries"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        // A caller's device gets a cache only if the caller enabled PIPELINE_CACHE on it.
        let (cache, cache_status) = cache::open(&device, &info);
        GpuContext {
            device,
            queue,
            info,
            limits,
            layout,
            pipeline_layout,
            pipelines: Mutex::new(HashMap::new()),
            cache,
            cache_status,
            startup: Mutex::new(startup),
            lost,
            callers_device: false,
            chunk_rows_cap: std::sync::atomic::AtomicUsize::new(usize::MAX),
        }
    }

    /// The pipeline of `kernel` with the optional parts `features` (see gpu::shaders::Features:
    /// the IES lookup, the texture lookups, the irradiance chart quadrature and treatAsLine),
    /// compiled on first use. Parts the kernel's source lacks are ignored.
    pub fn pipeline(&self, kernel: Kernel, features: Features) -> Result<wgpu::ComputePipeline> {
        self.pipeline_with_rows(kernel, features, RowShape::HOST)
    }

    /// [`GpuContext::pipeline`] for rows of another [`RowShape`] (GPU-resident queries): its
    /// fields are WGSL pipeline constants (`override ROW_WORDS`, `ROWS_PER_INVOCATION` in
    /// shaders/shared/record.wgsl), so that the driver compiles the stride and the row loop as
    /// constants (16-byte rows as single aligned accesses).
    pub fn pipeline_with_rows(
        &self,
        kernel: Kernel,
        features: Features,
        rows: RowShape,
    ) -> Result<wgpu::ComputePipeline> {
        let features = features.restricted_to(Features::used_by(kernel));
        let mut cache = self
            .pipelines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(p) = cache.get(&(kernel, features, rows)) {
            return Ok(p.clone());
        }
        let source = shaders::compose(kernel, features);
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(kernel.file()),
                source: wgpu::ShaderSource::Wgsl(source.as_str().into()),
            });
        let t0 = std::time::Instant::now();
        let constants = rows.constants();
        let pipeline = self
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(kernel.entry_point()),
                layout: Some(&self.pipeline_layout),
                module: &module,
                entry_point: Some(kernel.entry_point()),
                // The WGSL defaults are the host path's: its pipelines set nothing.
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: self.cache.as_ref().map(|(c, _)| c),
            });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(LuxError::gpu(
                format!("building the {} pipeline", kernel.entry_point()),
                e,
            ));
        }
        let took = t0.elapsed();
        if let Some((c, path)) = &self.cache {
            // Saved after every new pipeline: a CLI process may end without dropping the context.
            cache::save(c, path);
        }
        self.startup
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .pipelines
            .push((pipeline_name(kernel, features, rows), took));
        cache.insert((kernel, features, rows), pipeline.clone());
        Ok(pipeline)
    }

    /// Whether and where compiled pipelines are cached.
    pub fn cache_status(&self) -> CacheStatus {
        self.cache_status.clone()
    }

    /// How long opening the device and compiling each pipeline so far took.
    pub fn startup(&self) -> Startup {
        self.startup
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clone()
    }

    pub fn adapter(&self) -> AdapterSummary {
        AdapterSummary::from(&self.info)
    }

    pub fn device_limits(&self) -> DeviceLimits {
        let l = &self.limits;
        DeviceLimits {
            max_storage_buffer_binding_size: l.max_storage_buffer_binding_size,
            max_buffer_size: l.max_buffer_size,
            max_compute_workgroups_per_dimension: l.max_compute_workgroups_per_dimension,
            max_compute_invocations_per_workgroup: l.max_compute_invocations_per_workgroup,
            samples_per_dispatch_one_light: self.chunk_capacity(1, false),
        }
    }

    /// Whether this is Mesa's llvmpipe (lavapipe), the CPU Vulkan driver of CI.
    pub fn is_llvmpipe(&self) -> bool {
        self.info.name.to_lowercase().contains("llvmpipe")
    }

    /// How many lights one dispatch of `kernel` evaluates; larger sets run as several
    /// dispatches over light groups (summed mode accumulates into the same rows).
    ///
    /// Why: llvmpipe (Mesa 22.x, gallivm) caps the loop iterations of one invocation at 65535
    /// *in total over all loops*, counted per SIMD vector of lanes, and silently leaves the loop
    /// after that (measured: a loop of 4×30000 iterations stops at 65535). The emission and
    /// radiance kernels loop once per light; an irradiance quadrature loops thousands of times
    /// per light, so there each dispatch takes one light. Elsewhere, groups bound the time of
    /// one dispatch (an OS watchdog resets a GPU that is busy for seconds).
    pub fn lights_per_dispatch(&self, kernel: Kernel) -> usize {
        // (The irradiance kernel detects a cut too, see `lane_stride`.)
        match (kernel, self.is_llvmpipe()) {
            (Kernel::Irradiance, true) => 1,
            (Kernel::Irradiance, false) => 64,
            (_, true) => 16384,
            (_, false) => usize::MAX,
        }
    }

    /// The rows each invocation of a GPU-resident `kernel` takes: 1 for irradiance and the
    /// samplers (whose WGSL takes one row per invocation) and on llvmpipe (whose loops share
    /// one budget per invocation, [`GpuContext::lights_per_dispatch`]); else `requested` (the
    /// scene's, set by tests and benchmarks through `testkit::with_rows_per_invocation`) or
    /// the default (BENCHMARKS.md, issue 24 item 7).
    pub(crate) fn rows_per_invocation(&self, kernel: Kernel, requested: Option<u32>) -> u32 {
        let simple = matches!(
            kernel,
            Kernel::Emission | Kernel::Intensity | Kernel::Radiance
        );
        match requested {
            _ if !simple => 1,
            Some(r) => r.clamp(1, 16),
            None if self.is_llvmpipe() => 1,
            None => ROWS_PER_INVOCATION,
        }
    }

    /// Invocations per sample of `kernel` over `lights` (`Params::lane_stride`). llvmpipe
    /// leaves an invocation's loops silently after 65,535 iterations, a budget its invocations
    /// share when it runs them together; the irradiance kernel detects a cut (`irr_cut` in
    /// shaders/shared/record.wgsl: NaN, which the host recomputes), and where a light's
    /// quadrature may be long (an IES profile's kinks multiply a line's pieces) runs one sample
    /// per [`LLVMPIPE_SHARED_LANES`] invocations so that each has the budget to itself.
    /// Elsewhere: 1.
    pub(crate) fn lane_stride(&self, kernel: Kernel, lights: &GpuLights, light_filter: u32) -> u32 {
        if self.is_llvmpipe()
            && kernel == Kernel::Irradiance
            && lights.long_quadrature(light_filter)
        {
            LLVMPIPE_SHARED_LANES
        } else {
            1
        }
    }

    /// The largest number of samples one dispatch handles for `lights` lights.
    pub fn chunk_capacity(&self, lights: usize, per_light: bool) -> usize {
        let binding = self
            .limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size);
        // Keep each buffer at most 256 MiB so that host and device memory stay bounded.
        let budget = binding.min(256 << 20);
        let rows = if per_light { lights.max(1) as u64 } else { 1 };
        let by_output = budget / (12 * rows);
        let by_input = budget / 12;
        let groups = self.limits.max_compute_workgroups_per_dimension as u64;
        let by_dispatch = groups * groups * record::WORKGROUP_SIZE as u64;
        let cap = self
            .chunk_rows_cap
            .load(std::sync::atomic::Ordering::Relaxed);
        (by_output.min(by_input).min(by_dispatch).max(1) as usize).min(cap)
    }

    /// The most bytes the texture atlas (textures and latlong row tables, one storage binding)
    /// may take on this device: its storage binding and buffer limits.
    pub(crate) fn atlas_limit(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    /// Caps the rows of one chunk (tests: many chunks from a small batch).
    #[cfg(test)]
    pub(crate) fn cap_chunk_rows(&self, rows: usize) {
        self.chunk_rows_cap
            .store(rows.max(1), std::sync::atomic::Ordering::Relaxed);
    }
}

pub(crate) fn layout_entry(
    binding: u32,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
