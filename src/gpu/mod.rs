//! The wgpu side: adapter and device, one compute pipeline per kernel (built once per context),
//! and chunked dispatch so that any batch fits the device's buffer and dispatch limits.

pub mod pack;
pub mod shaders;

use std::collections::HashMap;
use std::sync::Arc;

use crate::error::{LuxError, Result};
pub use pack::{LightRecord, Params};
pub use shaders::Kernel;

/// What `luxeval info` reports about an adapter.
#[derive(Clone, Debug)]
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

/// Environment variable that picks an adapter by (case-insensitive) name substring.
pub const ADAPTER_ENV: &str = "LUXEVAL_ADAPTER";

fn instance() -> wgpu::Instance {
    // Backends and flags honour WGPU_BACKEND, WGPU_VALIDATION, ... (wgpu's own variables).
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Every adapter wgpu can see on this machine.
pub fn list_adapters() -> Vec<AdapterSummary> {
    let instance = instance();
    pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
        .iter()
        .map(|a| AdapterSummary::from(&a.get_info()))
        .collect()
}

/// A device with the luxeval pipelines. Creating one costs tens of milliseconds (adapter,
/// device, shader compilation); keep it for the whole batch.
pub struct GpuContext {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    layout: wgpu::BindGroupLayout,
    pipelines: HashMap<Kernel, wgpu::ComputePipeline>,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("adapter", &self.info.name)
            .finish()
    }
}

impl GpuContext {
    /// Opens the adapter named by `LUXEVAL_ADAPTER` (a name substring), else the default
    /// high-performance adapter, and builds every pipeline.
    pub fn new() -> Result<Self> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Self> {
        let instance = instance();
        let adapter = match std::env::var(ADAPTER_ENV) {
            Ok(want) if !want.is_empty() => {
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
                    .ok_or_else(|| {
                        LuxError::NoAdapter(format!(
                            "{ADAPTER_ENV}={want:?} matches none of {names:?}"
                        ))
                    })?
            }
            _ => instance
                .request_adapter(&wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    ..Default::default()
                })
                .await
                .map_err(|e| LuxError::NoAdapter(e.to_string()))?,
        };
        let info = adapter.get_info();
        // Ask for everything the adapter offers: big batches want its largest buffers.
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("luxeval"),
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| LuxError::Gpu(format!("cannot open {}: {e}", info.name)))?;
        // wgpu's default handler panics; errors are caught by scopes around each dispatch, and
        // anything that escapes them is logged rather than aborting the process.
        device.on_uncaptured_error(Arc::new(|e| log::error!("wgpu: {e}")));

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
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("luxeval queries"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut pipelines = HashMap::new();
        for kernel in Kernel::ALL {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(kernel.file()),
                source: wgpu::ShaderSource::Wgsl(shaders::compose(kernel).into()),
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(kernel.entry_point()),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(kernel.entry_point()),
                compilation_options: Default::default(),
                cache: None,
            });
            pipelines.insert(kernel, pipeline);
        }
        if let Some(e) = scope.pop().await {
            return Err(LuxError::Gpu(format!("building the pipelines: {e}")));
        }
        Ok(GpuContext {
            device,
            queue,
            info,
            limits,
            layout,
            pipelines,
        })
    }

    pub fn adapter(&self) -> AdapterSummary {
        AdapterSummary::from(&self.info)
    }

    pub fn limits(&self) -> &wgpu::Limits {
        &self.limits
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
        match (kernel, self.is_llvmpipe()) {
            (Kernel::Irradiance, true) => 1,
            (Kernel::Irradiance, false) => 64,
            (_, true) => 16384,
            (_, false) => usize::MAX,
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
        let by_dispatch = groups * groups * pack::WORKGROUP_SIZE as u64;
        by_output.min(by_input).min(by_dispatch).max(1) as usize
    }

    /// Runs `kernel` over `a` (and `b`) for every light record: `count` rows summed over lights,
    /// or `lights × count` rows in light-major order with `per_light`.
    pub fn run(
        &self,
        kernel: Kernel,
        records: &[LightRecord],
        a: &[[f32; 3]],
        b: Option<&[[f32; 3]]>,
        per_light: bool,
    ) -> Result<Vec<[f32; 3]>> {
        let n = a.len();
        let rows = if per_light { records.len() } else { 1 };
        let mut out = vec![[0f32; 3]; rows * n];
        if n == 0 || records.is_empty() {
            return Ok(out);
        }
        let record_bytes = std::mem::size_of_val(records) as u64;
        if record_bytes > self.limits.max_storage_buffer_binding_size {
            return Err(LuxError::input(
                "lights",
                format!(
                    "{} lights need {record_bytes} bytes, over this device's storage binding limit of {} bytes; split the stage with --light",
                    records.len(),
                    self.limits.max_storage_buffer_binding_size
                ),
            ));
        }
        let chunk = self.chunk_capacity(records.len(), per_light).min(n);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let result = self.run_chunks(kernel, records, a, b, per_light, chunk, &mut out);
        let oom = pollster::block_on(oom.pop());
        let validation = pollster::block_on(validation.pop());
        if let Some(e) = oom {
            return Err(LuxError::Gpu(format!("out of memory: {e}")));
        }
        if let Some(e) = validation {
            return Err(LuxError::Gpu(format!("validation: {e}")));
        }
        result.map(|_| out)
    }

    #[allow(clippy::too_many_arguments)]
    fn run_chunks(
        &self,
        kernel: Kernel,
        records: &[LightRecord],
        a: &[[f32; 3]],
        b: Option<&[[f32; 3]]>,
        per_light: bool,
        chunk: usize,
        out: &mut [[f32; 3]],
    ) -> Result<()> {
        let n = a.len();
        let lights = records.len();
        let rows = if per_light { lights } else { 1 };
        let dev = &self.device;
        let storage = |label, size: u64, extra: wgpu::BufferUsages| {
            dev.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | extra,
                mapped_at_creation: false,
            })
        };
        let in_bytes = (chunk * 12) as u64;
        let out_bytes = (chunk * rows * 12) as u64;
        let light_buf = storage(
            "lights",
            std::mem::size_of_val(records) as u64,
            wgpu::BufferUsages::COPY_DST,
        );
        self.queue
            .write_buffer(&light_buf, 0, bytemuck::cast_slice(records));
        let buf_a = storage("in_a", in_bytes, wgpu::BufferUsages::COPY_DST);
        let buf_b = b.map(|_| storage("in_b", in_bytes, wgpu::BufferUsages::COPY_DST));
        let buf_out = storage("out", out_bytes, wgpu::BufferUsages::COPY_SRC);
        let staging = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: out_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // Light groups, and one Params block per group at the uniform offset alignment.
        let per_group = self.lights_per_dispatch(kernel).max(1);
        let groups: Vec<(usize, usize)> = (0..lights)
            .step_by(per_group)
            .map(|g| (g, (g + per_group).min(lights)))
            .collect();
        let align = (self.limits.min_uniform_buffer_offset_alignment as usize)
            .max(std::mem::size_of::<Params>());
        let params_buf = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: (groups.len() * align) as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("luxeval queries"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &params_buf,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
                    }),
                },
                entry(1, &light_buf),
                entry(2, &buf_a),
                // Emission reads no second input; bind the first again (read-only aliasing).
                entry(3, buf_b.as_ref().unwrap_or(&buf_a)),
                entry(4, &buf_out),
            ],
        });
        let pipeline = &self.pipelines[&kernel];
        let max_groups = self.limits.max_compute_workgroups_per_dimension.max(1);

        let mut start = 0;
        while start < n {
            let count = chunk.min(n - start);
            self.queue
                .write_buffer(&buf_a, 0, bytemuck::cast_slice(&a[start..start + count]));
            if let (Some(buf), Some(b)) = (&buf_b, b) {
                self.queue
                    .write_buffer(buf, 0, bytemuck::cast_slice(&b[start..start + count]));
            }
            let wg = (count as u32).div_ceil(pack::WORKGROUP_SIZE);
            let gx = wg.min(max_groups);
            let gy = wg.div_ceil(gx);
            let mut block = vec![0u8; groups.len() * align];
            for (g, &(first, end)) in groups.iter().enumerate() {
                let params = Params {
                    count: count as u32,
                    light_first: first as u32,
                    light_end: end as u32,
                    per_light: per_light as u32,
                    row_stride: gx * pack::WORKGROUP_SIZE,
                    accumulate: (g > 0) as u32,
                    pad: [0; 2],
                };
                block[g * align..g * align + std::mem::size_of::<Params>()]
                    .copy_from_slice(bytemuck::bytes_of(&params));
            }
            self.queue.write_buffer(&params_buf, 0, &block);
            let mut enc = dev.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some(kernel.entry_point()),
            });
            for g in 0..groups.len() {
                // A pass per group: passes are ordered, so a group reads the sums of the last.
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(kernel.entry_point()),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind_group, &[(g * align) as u32]);
                pass.dispatch_workgroups(gx, gy, 1);
            }
            let used = (count * rows * 12) as u64;
            enc.copy_buffer_to_buffer(&buf_out, 0, &staging, 0, used);
            self.queue.submit([enc.finish()]);

            let data = self.read_back(&staging, used)?;
            let values: &[[f32; 3]] = bytemuck::cast_slice(&data);
            if per_light {
                for l in 0..lights {
                    out[l * n + start..l * n + start + count]
                        .copy_from_slice(&values[l * count..(l + 1) * count]);
                }
            } else {
                out[start..start + count].copy_from_slice(values);
            }
            start += count;
        }
        Ok(())
    }

    fn read_back(&self, staging: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
        let slice = staging.slice(..size);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| LuxError::Gpu(format!("waiting for the device: {e}")))?;
        rx.recv()
            .map_err(|_| LuxError::Gpu("the readback was dropped (device lost?)".into()))?
            .map_err(|e| LuxError::Gpu(format!("mapping the result buffer: {e}")))?;
        let bytes = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| LuxError::Gpu(format!("reading the result buffer: {e}")))?;
            view.to_vec()
        };
        staging.unmap();
        Ok(bytes)
    }
}

fn layout_entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
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

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
