//! GPU-resident evaluation: a kernel recorded into the caller's command encoder over the
//! caller's buffers, on the caller's device. Nothing is submitted, mapped or read back here; the
//! caller submits when it wants the results and keeps them on the device.
//!
//! The bindings, the Params block per light group and the pass per group are those of
//! `dispatch::run_chunks`, so both paths run the same kernels with the same accumulation order.

use wgpu::util::DeviceExt;

use crate::error::{LuxError, Result};

use super::dispatch::GpuLights;
use super::launch::{entry, params_block, params_entry, record_passes};
use super::record::{Params, Record, SELECT_HAS_NORMALS, WORKGROUP_SIZE};
use super::sample::SampleLights;
use super::{GpuContext, Kernel};

/// One caller buffer and the name errors give it ("directions", "points", "out", ...).
#[derive(Clone, Copy)]
pub(crate) struct Operand<'a> {
    pub name: &'static str,
    pub buffer: &'a wgpu::Buffer,
}

/// Bytes per row of the sampler's inputs: three tightly packed f32.
const ROW_BYTES: u64 = 12;

/// An input or query output row, and the GPU-resident sampler's output row, for messages.
const TRIPLE: (u64, &str) = (ROW_BYTES, "f32 x, y, z");
const QUAD: (u64, &str) = (16, "f32 x, y, z, w");
const SAMPLE_ROW: (u64, &str) = (
    SAMPLE_ROW_FLOATS * 4,
    "f32 ω x, y, z, pdf, L r, g, b, light",
);

impl GpuContext {
    /// A context on a device the caller opened (a renderer's own device): its limits are those
    /// the device was created with. luxeval installs no uncaptured-error handler and no
    /// device-lost callback on it (wgpu keeps one of each per device, and they are the
    /// caller's); luxeval's own calls catch their errors with error scopes.
    pub(crate) fn from_device(device: wgpu::Device, queue: wgpu::Queue) -> Result<Self> {
        let limits = device.limits();
        check_limits(&limits)?;
        let info = device.adapter_info();
        // The layouts are created on the caller's device: a failure there must come back as
        // an error, not reach the caller's uncaptured-error handler (wgpu's default panics).
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut ctx = Self::with_device(
            device.clone(),
            queue,
            info,
            limits,
            std::sync::Arc::new(std::sync::Mutex::new(None)),
            super::Startup::default(),
        );
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(LuxError::gpu(
                "creating luxeval's layouts on the caller's device",
                e,
            ));
        }
        ctx.callers_device = true;
        Ok(ctx)
    }

    /// Whether the device is the caller's (opened by `from_device`).
    pub(crate) fn is_callers_device(&self) -> bool {
        self.callers_device
    }

    /// A light buffer for a scene with no lights: the kernels need a bound record array even
    /// when they evaluate none (summed mode still writes its zero rows).
    pub(crate) fn no_lights(&self) -> Result<GpuLights> {
        let atlas = super::texture_atlas::Atlas::new();
        Ok(self
            .upload(&[Record::default()], &[], &atlas, &[])?
            .expect("one record uploaded"))
    }

    /// Records `kernel` over `count` rows of `a` (and `b`) into `encoder`, writing `out`:
    /// `count` rows summed over lights `0..n_lights`, or `n_lights × count` rows, light-major,
    /// with `per_light`; every row of `row_words` f32 (3: packed, 4: vec4), several rows per
    /// invocation where [`GpuContext::rows_per_invocation`] says so. Validates the buffers first (usage, size, aliasing, the device's
    /// binding and dispatch limits); the first call of a kernel builds its pipeline.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        kernel: Kernel,
        lights: &GpuLights,
        n_lights: usize,
        a: Operand<'_>,
        b: Option<Operand<'_>>,
        out: Operand<'_>,
        count: u32,
        per_light: bool,
        row_words: u32,
        rows_per_invocation: Option<u32>,
    ) -> Result<()> {
        let rows = if per_light { n_lights as u64 } else { 1 };
        let (row_bytes, row) = if row_words == 4 { QUAD } else { TRIPLE };
        let in_bytes = count as u64 * row_bytes;
        let out_bytes = rows
            .checked_mul(in_bytes)
            .ok_or_else(|| LuxError::input(out.name, "the output size overflows u64"))?;
        let limit = self.limits.max_storage_buffer_binding_size;
        for (op, n) in [
            (Some(a), count as u64),
            (b, count as u64),
            (Some(out), rows * count as u64),
        ] {
            let Some(op) = op else { continue };
            check_buffer(op, wgpu::BufferUsages::STORAGE, n, (row_bytes, row))?;
        }
        check_distinct([Some(a), b], out)?;
        // The kernels index the output as f32 with u32 arithmetic (ROW_WORDS · row + 3), and
        // each binding must fit the device's storage binding limit.
        let per_call = limit.min(4 * u32::MAX as u64) / (row_bytes * rows.max(1));
        if out_bytes > limit || in_bytes > limit || count as u64 > per_call {
            return Err(LuxError::input(
                "count",
                format!(
                    "{count} samples{} need {} bytes in one binding, over this device's storage \
                     binding limit of {limit} bytes; encode at most {per_call} samples per call",
                    if per_light {
                        format!(" × {n_lights} lights")
                    } else {
                        String::new()
                    },
                    out_bytes.max(in_bytes),
                ),
            ));
        }
        let max_groups = self.limits.max_compute_workgroups_per_dimension.max(1);
        let wg = count.div_ceil(WORKGROUP_SIZE);
        let lane_stride = self.lane_stride(kernel, lights, super::record::LIGHTS_ALL);
        // Several rows per invocation (emission, intensity, radiance on a hardware adapter):
        // ⌈count / r⌉ invocations (shaders/shared/record.wgsl, `row_step`).
        let shape = super::RowShape {
            words: row_words,
            per_invocation: self.rows_per_invocation(kernel, rows_per_invocation),
        };
        let grid = self.grid(count.div_ceil(shape.per_invocation) * lane_stride);
        if grid.1 > max_groups {
            return Err(LuxError::input(
                "count",
                format!(
                    "{count} samples need {wg} workgroups, over this device's {max_groups} × \
                     {max_groups} dispatch grid; encode fewer samples per call"
                ),
            ));
        }
        if count == 0 || rows == 0 {
            return Ok(());
        }

        let groups: Vec<(usize, usize)> = if n_lights == 0 {
            // Summed mode over no lights: one dispatch that writes the zero rows.
            vec![(0, 0)]
        } else {
            self.light_groups(kernel, n_lights)
        };
        // One Params block per light group at the uniform offset alignment.
        let align = self.params_align();
        let block = params_block(
            &groups,
            align,
            count,
            per_light,
            grid,
            lane_stride,
            super::record::LIGHTS_ALL,
        );
        // Emission and intensity read no second input; bind the first again (read-only
        // aliasing is allowed).
        let bound = [(a, in_bytes), (b.unwrap_or(a), in_bytes), (out, out_bytes)];
        self.record_resident(
            encoder,
            kernel,
            lights,
            None,
            &block,
            groups.len(),
            bound,
            grid,
            shape,
        )?;
        Ok(())
    }
}

/// Floats per output row of the GPU-resident sampler: ω, pdf, L, the light.
pub(crate) const SAMPLE_ROW_FLOATS: u64 = 8;

/// The most lights the GPU-resident sampler chooses among on a CPU driver: its choice loops
/// over the lights twice per row, and llvmpipe leaves an invocation's loops silently after
/// 65,535 iterations in total ([`GpuContext::lights_per_dispatch`]); the rest is the samplers'
/// own loops.
pub(crate) const LLVMPIPE_SAMPLE_LIGHTS: usize = 16_384;

/// What one GPU-resident sampling call draws (`PreparedScene::encode_sample`).
#[derive(Clone, Copy)]
pub(crate) struct ResidentDraw<'a> {
    pub points: u32,
    pub per_point: u32,
    pub seed: u32,
    pub first_point: u32,
    /// `SELECT_POWER` or `SELECT_BOUND`.
    pub selection: u32,
    /// With `SELECT_POWER`: each light's power weight, scaled to the scene's largest (called
    /// on the first such call of a scene only, [`SampleLights::with_power`]).
    pub power: Option<&'a dyn Fn() -> Vec<f32>>,
}

impl GpuContext {
    /// Records the GPU-resident sampler (`sample_resident_main`) into `encoder`, with the
    /// sampling kernels' records and atlas (`sampling`: textured domes' tables appended):
    /// `draw.points`
    /// rows of `points` (and `normals`), `points × per_point` rows of [`SAMPLE_ROW_FLOATS`]
    /// floats into `out`, point-major. Validates the buffers as [`GpuContext::encode`] does.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode_sample(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        lights: &GpuLights,
        sampling: &SampleLights,
        n_lights: usize,
        points: Operand<'_>,
        normals: Option<Operand<'_>>,
        out: Operand<'_>,
        draw: ResidentDraw<'_>,
    ) -> Result<()> {
        if draw.per_point == 0 {
            return Err(LuxError::input(
                "count",
                "0: draw at least one sample per point",
            ));
        }
        if self.is_llvmpipe() && n_lights > LLVMPIPE_SAMPLE_LIGHTS {
            return Err(LuxError::input(
                "lights",
                format!(
                    "{n_lights} lights: on a CPU driver ({}) the GPU-resident sampler chooses among \
                     at most {LLVMPIPE_SAMPLE_LIGHTS} (its loops stop after 65,535 iterations); use \
                     PreparedScene::sample",
                    self.info.name
                ),
            ));
        }
        let in_bytes = draw.points as u64 * ROW_BYTES;
        let rows = draw.points as u64 * draw.per_point as u64;
        let out_bytes = rows * SAMPLE_ROW_FLOATS * 4;
        for (op, n, row) in [
            (Some(points), draw.points as u64, TRIPLE),
            (normals, draw.points as u64, TRIPLE),
            (Some(out), rows, SAMPLE_ROW),
        ] {
            let Some(op) = op else { continue };
            check_buffer(op, wgpu::BufferUsages::STORAGE, n, row)?;
        }
        check_distinct([Some(points), normals], out)?;
        // The kernel indexes the output as f32 with u32 arithmetic (8 · row + 7), and each
        // binding must fit the device's storage binding limit.
        let limit = self.limits.max_storage_buffer_binding_size;
        let most_rows = (limit / (SAMPLE_ROW_FLOATS * 4)).min(u32::MAX as u64 / SAMPLE_ROW_FLOATS);
        if rows > most_rows || in_bytes > limit {
            return Err(LuxError::input(
                "count",
                format!(
                    "{} points × {} samples need {out_bytes} bytes of output in one binding; this \
                     device takes at most {most_rows} rows per call (storage binding limit \
                     {limit} bytes): encode fewer points per call (first_point keeps the draws \
                     of the whole input)",
                    draw.points, draw.per_point
                ),
            ));
        }
        let count = rows as u32;
        let max_groups = self.limits.max_compute_workgroups_per_dimension.max(1);
        let grid = self.grid(count);
        if grid.1 > max_groups {
            return Err(LuxError::input(
                "count",
                format!(
                    "{count} rows need {} workgroups, over this device's {max_groups} × \
                     {max_groups} dispatch grid; encode fewer points per call",
                    count.div_ceil(WORKGROUP_SIZE)
                ),
            ));
        }
        if count == 0 {
            return Ok(());
        }
        // By power: the records with the power weights filled (uploaded once).
        let records = match draw.power {
            Some(weights) => sampling.with_power(self, weights),
            None => &sampling.buffer,
        };
        let align = self.params_align();
        let mut block = params_block(
            &[(0, n_lights)],
            align,
            count,
            false,
            grid,
            1,
            super::record::LIGHTS_ALL,
        );
        let params = Params {
            seed: draw.seed,
            per_point: draw.per_point,
            first_point: draw.first_point,
            select: draw.selection
                | if normals.is_some() {
                    SELECT_HAS_NORMALS
                } else {
                    0
                },
            ..*bytemuck::from_bytes::<Params>(&block[..std::mem::size_of::<Params>()])
        };
        block[..std::mem::size_of::<Params>()].copy_from_slice(bytemuck::bytes_of(&params));
        // Without normals the kernel reads none; bind the points again.
        let bound = [
            (points, in_bytes),
            (normals.unwrap_or(points), in_bytes),
            (out, out_bytes),
        ];
        self.record_resident(
            encoder,
            Kernel::SampleResident,
            lights,
            Some((records, &sampling.tex_atlas)),
            &block,
            1,
            bound,
            grid,
            super::RowShape::HOST,
        )?;
        Ok(())
    }
}

impl GpuContext {
    /// Records `kernel` over the caller's buffers (`bound`: binding 2, 3 and 4 with the bytes
    /// each call reads or writes; `sampling`'s records and texture atlas where given, in place
    /// of the scene's), one pass per Params block of `block` (`passes` of them at
    /// [`GpuContext::params_align`]). The Params buffer is this call's own, written at
    /// creation (nothing goes through the queue) and kept alive by the command buffer that
    /// uses it. The first call of a kernel builds its pipeline.
    #[allow(clippy::too_many_arguments)]
    fn record_resident(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        kernel: Kernel,
        lights: &GpuLights,
        sampling: Option<(&wgpu::Buffer, &wgpu::Buffer)>,
        block: &[u8],
        passes: usize,
        bound: [(Operand<'_>, u64); 3],
        grid: (u32, u32),
        rows: super::RowShape,
    ) -> Result<()> {
        let pipeline = self.pipeline_with_rows(
            kernel,
            lights.variant(kernel, super::record::LIGHTS_ALL),
            rows,
        )?;
        if kernel == Kernel::Irradiance {
            lights.write_row_tables(&self.device, &self.queue)?;
        }
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let params = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("luxeval params (resident)"),
                contents: block,
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let [(a, a_bytes), (b, b_bytes), (out, out_bytes)] = bound;
        let (records, tex_atlas) = sampling.unwrap_or((&lights.buffer, &lights.tex_atlas));
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("luxeval queries (resident)"),
            layout: &self.layout,
            entries: &[
                params_entry(&params),
                entry(1, records),
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: range(a, a_bytes),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: range(b, b_bytes),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: range(out, out_bytes),
                },
                entry(5, &lights.ies_atlas),
                entry(6, tex_atlas),
                entry(7, &lights.mesh_atlas),
            ],
        });
        // Buffers of another device, for one, fail here.
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(LuxError::gpu(
                format!("binding the caller's buffers for {}", kernel.entry_point()),
                e,
            ));
        }
        let align = self.params_align();
        record_passes(encoder, kernel, &pipeline, &bind_group, passes, align, grid);
        Ok(())
    }
}

/// The output is none of the inputs: a buffer bound both read-only and read-write in one pass
/// is a wgpu usage conflict that would only surface when the caller finishes the encoder.
fn check_distinct(inputs: [Option<Operand<'_>>; 2], out: Operand<'_>) -> Result<()> {
    for op in inputs.into_iter().flatten() {
        if op.buffer == out.buffer {
            return Err(LuxError::input(
                out.name,
                format!(
                    "the output buffer is also the {} buffer; use distinct buffers",
                    op.name
                ),
            ));
        }
    }
    Ok(())
}

/// The buffer has `usage` and holds at least `rows` rows of `row`: (bytes, layout in words).
fn check_buffer(
    op: Operand<'_>,
    usage: wgpu::BufferUsages,
    rows: u64,
    row: (u64, &str),
) -> Result<()> {
    if !op.buffer.usage().contains(usage) {
        return Err(LuxError::input(
            op.name,
            format!(
                "the buffer's usage {:?} lacks {usage:?}; create it with wgpu::BufferUsages::STORAGE",
                op.buffer.usage()
            ),
        ));
    }
    let need = rows.saturating_mul(row.0);
    if op.buffer.size() < need {
        return Err(LuxError::input(
            op.name,
            format!(
                "the buffer holds {} bytes; {rows} rows need {need} ({} bytes a row: {}, no \
                 padding)",
                op.buffer.size(),
                row.0,
                row.1
            ),
        ));
    }
    Ok(())
}

/// The device limits the kernels and their bind group layout need. A device opened with
/// `wgpu::Limits::default()` or its adapter's limits has them; downlevel limits may not, and
/// wgpu would then fail inside the layout with a less telling message.
fn check_limits(l: &wgpu::Limits) -> Result<()> {
    let params = std::mem::size_of::<Params>() as u64;
    let needs: [(&str, u64, u64); 8] = [
        ("max_bind_groups", l.max_bind_groups as u64, 1),
        (
            "max_bindings_per_bind_group",
            l.max_bindings_per_bind_group as u64,
            7,
        ),
        (
            "max_storage_buffers_per_shader_stage",
            l.max_storage_buffers_per_shader_stage as u64,
            6,
        ),
        (
            "max_uniform_buffers_per_shader_stage",
            l.max_uniform_buffers_per_shader_stage as u64,
            1,
        ),
        (
            "max_dynamic_uniform_buffers_per_pipeline_layout",
            l.max_dynamic_uniform_buffers_per_pipeline_layout as u64,
            1,
        ),
        (
            "max_uniform_buffer_binding_size",
            l.max_uniform_buffer_binding_size,
            params,
        ),
        (
            "max_compute_workgroup_size_x",
            l.max_compute_workgroup_size_x as u64,
            WORKGROUP_SIZE as u64,
        ),
        (
            "max_compute_invocations_per_workgroup",
            l.max_compute_invocations_per_workgroup as u64,
            WORKGROUP_SIZE as u64,
        ),
    ];
    for (name, has, need) in needs {
        if has < need {
            return Err(LuxError::input(
                "device",
                format!(
                    "limits.{name} is {has}, luxeval's kernels need at least {need}; open the \
                     device with wgpu::Limits::default() or the adapter's limits"
                ),
            ));
        }
    }
    Ok(())
}

/// The first `size` bytes of a caller's buffer (it may be larger than the call needs, even
/// larger than the binding limit).
fn range<'a>(op: Operand<'a>, size: u64) -> wgpu::BindingResource<'a> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer: op.buffer,
        offset: 0,
        size: wgpu::BufferSize::new(size),
    })
}
