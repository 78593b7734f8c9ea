//! Running the sample kernel (shaders/sample.wgsl) over rows of (point, normal, light, keys):
//! one direction per row toward the row's light, its density and the radiance along it
//! (DESIGN.md §9 S1); and the pdf kernel over rows of (point, normal, light, direction). The light is chosen on the host (the CPU's `P(l | x)`); the kernel draws
//! u from the same counter-based keys (S3), so a row gives the same direction on any chunking.

use crate::error::{GpuFailure, LuxError, Result};
use crate::prepare::env_table::EnvTable;

use super::dispatch::GpuLights;
use super::launch::{entry, params_block, params_entry, record_passes};
use super::texture_atlas::env_table_words;
use super::{GpuContext, Kernel};

/// What the sample and pdf kernels bind at 1 and 6 in place of the scene's records and texture
/// atlas: the same, plus each textured dome's sampling table appended to the atlas and its
/// offset in the dome's record (`tex[2]`; 0 for a dome without a table, which samples as
/// untextured, as the CPU's `EnvTable::new` = None does). Built on the first sampling call
/// (the tables cost a pass over the texels), so scenes that are never sampled pay nothing.
pub(crate) struct SampleLights {
    pub(crate) buffer: wgpu::Buffer,
    pub(crate) tex_atlas: wgpu::Buffer,
    /// The records `buffer` holds, for [`SampleLights::with_power`].
    records: Vec<super::record::Record>,
    /// `buffer`'s records with the power weights filled (`Record::select[0]`), uploaded on the
    /// first `Selection::Power` GPU-resident call.
    power: std::sync::OnceLock<wgpu::Buffer>,
}

impl SampleLights {
    /// The records with each light's power weight (`weights()[k]`, scaled to the scene's
    /// largest) in `select[0]`, for a `Selection::Power` GPU-resident call: built and uploaded
    /// on the first such call (`weights` is called then only).
    pub(crate) fn with_power(
        &self,
        ctx: &GpuContext,
        weights: &dyn Fn() -> Vec<f32>,
    ) -> &wgpu::Buffer {
        self.power.get_or_init(|| {
            let mut records = self.records.clone();
            for (r, w) in records.iter_mut().zip(weights()) {
                r.select[0] = w;
            }
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lights (sampling by power)"),
                size: std::mem::size_of_val(records.as_slice()).max(4) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            ctx.queue
                .write_buffer(&buffer, 0, bytemuck::cast_slice(&records));
            buffer
        })
    }
}

/// One row of the sample kernel's input.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleRow {
    pub point: [f32; 3],
    /// The receiver's unit normal, zero for none.
    pub normal: [f32; 3],
    /// The light's index in the scene's records.
    pub light: u32,
    /// The generator's keys (DESIGN.md §9 S3): seed, point index, sample index.
    pub seed: u32,
    pub point_key: u32,
    pub sample_key: u32,
}

/// One row of the sample kernel's output.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleOut {
    pub dir: [f32; 3],
    /// The light's own density per unit solid angle, `+∞` for a delta light.
    pub pdf: f32,
    pub radiance: [f32; 3],
}

/// One row of the pdf kernel's input.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PdfRow {
    pub point: [f32; 3],
    /// The receiver's unit normal, zero for none.
    pub normal: [f32; 3],
    pub light: u32,
    /// The unit direction.
    pub dir: [f32; 3],
}

/// Floats per output row of the sample kernel: ω, pdf_l, L.
const OUT_FLOATS: usize = 7;

impl GpuContext {
    /// The records and atlas of [`SampleLights`] for `lights` and the lights' sampling tables
    /// (`tables[k]` light k's, None for every light that is not a textured dome with one);
    /// `Err(bytes)` where the textures and tables need `bytes`, over the device's storage
    /// binding limit.
    pub(crate) fn sample_lights(
        &self,
        lights: &GpuLights,
        tables: &[Option<EnvTable>],
    ) -> std::result::Result<SampleLights, u64> {
        if tables.iter().all(Option::is_none) {
            return Ok(SampleLights {
                buffer: lights.buffer.clone(),
                tex_atlas: lights.tex_atlas.clone(),
                records: lights.records.clone(),
                power: Default::default(),
            });
        }
        let mut records = lights.records.clone();
        // Each table at the next multiple of 4 after the texture atlas.
        let mut chunks: Vec<(usize, Vec<f32>)> = Vec::new();
        let mut end = lights.tex_words;
        for (record, table) in records.iter_mut().zip(tables) {
            let Some(t) = table else { continue };
            let base = end.next_multiple_of(4).max(4);
            let words = u32::try_from(base)
                .ok()
                .filter(|b| (*b as usize) < u32::MAX as usize / 2)
                .map(|b| env_table_words(t, b));
            let Some(words) = words else {
                return Err(base as u64 * 4);
            };
            end = base + words.len();
            record.tex[2] = base as u32;
            chunks.push((base, words));
        }
        let bytes = (end * 4) as u64;
        if bytes > self.limits.max_storage_buffer_binding_size || end > u32::MAX as usize {
            return Err(end as u64 * 4);
        }
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lights (sampling)"),
            size: std::mem::size_of_val(records.as_slice()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(&records));
        let tex_atlas = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture atlas (sampling)"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // The textures by a device-side copy (no second host copy of the texels).
        let copy = (lights.tex_words * 4) as u64;
        if copy > 0 {
            let mut enc = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("texture atlas (sampling)"),
                });
            enc.copy_buffer_to_buffer(
                &lights.tex_atlas,
                0,
                &tex_atlas,
                0,
                copy.next_multiple_of(4),
            );
            self.queue.submit([enc.finish()]);
        }
        for (base, words) in &chunks {
            self.queue
                .write_buffer(&tex_atlas, (*base * 4) as u64, bytemuck::cast_slice(words));
        }
        Ok(SampleLights {
            buffer,
            tex_atlas,
            records,
            power: Default::default(),
        })
    }

    /// Runs the sample kernel over `rows`, in chunks that fit the device's limits.
    pub(crate) fn run_sample(
        &self,
        lights: &GpuLights,
        sampling: &SampleLights,
        rows: &[SampleRow],
    ) -> Result<Vec<SampleOut>> {
        let a: Vec<f32> = rows
            .iter()
            .flat_map(|r| r.point.into_iter().chain(r.normal))
            .collect();
        let b: Vec<u32> = rows
            .iter()
            .flat_map(|r| [r.light, r.point_key, r.sample_key, r.seed])
            .collect();
        let values = self.run_rows(
            Kernel::Sample,
            lights,
            sampling,
            rows.len(),
            &a,
            &b,
            OUT_FLOATS,
        )?;
        Ok(values
            .chunks_exact(OUT_FLOATS)
            .map(|v| SampleOut {
                dir: [v[0], v[1], v[2]],
                // −1 stands for +∞ (a delta light).
                pdf: if v[3] < 0.0 { f32::INFINITY } else { v[3] },
                radiance: [v[4], v[5], v[6]],
            })
            .collect())
    }

    /// Runs the pdf kernel over `rows`: each row's light's density of its direction.
    pub(crate) fn run_pdf(
        &self,
        lights: &GpuLights,
        sampling: &SampleLights,
        rows: &[PdfRow],
    ) -> Result<Vec<f32>> {
        let a: Vec<f32> = rows
            .iter()
            .flat_map(|r| r.point.into_iter().chain(r.normal))
            .collect();
        let b: Vec<u32> = rows
            .iter()
            .flat_map(|r| {
                [
                    r.light,
                    r.dir[0].to_bits(),
                    r.dir[1].to_bits(),
                    r.dir[2].to_bits(),
                ]
            })
            .collect();
        self.run_rows(Kernel::Pdf, lights, sampling, rows.len(), &a, &b, 1)
    }

    /// Runs `kernel` (sample or pdf) over `n` rows of 6 floats in `a` and 4 words in `b`,
    /// `out_floats` floats out per row, in chunks that fit the device's limits.
    #[allow(clippy::too_many_arguments)]
    fn run_rows(
        &self,
        kernel: Kernel,
        lights: &GpuLights,
        sampling: &SampleLights,
        n: usize,
        a: &[f32],
        b: &[u32],
        out_floats: usize,
    ) -> Result<Vec<f32>> {
        let mut out = Vec::with_capacity(n * out_floats);
        if n == 0 {
            return Ok(out);
        }
        let pipeline = self.pipeline(kernel, lights.variant(kernel, super::record::LIGHTS_ALL))?;
        // The widest buffer holds 28 bytes a row; chunk_capacity counts 12.
        let chunk = (self.chunk_capacity(1, false) * 12 / 28).max(1).min(n);
        let dev = &self.device;
        let validation = dev.push_error_scope(wgpu::ErrorFilter::Validation);
        let storage = |label, size: usize, usage: wgpu::BufferUsages| {
            dev.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (size * 4) as u64,
                usage,
                mapped_at_creation: false,
            })
        };
        let input = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let buf_a = storage("sample in_a", chunk * 6, input);
        let buf_b = storage("sample in_b", chunk * 4, input);
        let buf_out = storage(
            "sample out",
            chunk * out_floats,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        let staging = storage(
            "sample readback",
            chunk * out_floats,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let align = self.params_align();
        let params = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sample params"),
            size: align as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("luxeval sample"),
            layout: &self.layout,
            entries: &[
                params_entry(&params),
                entry(1, &sampling.buffer),
                entry(2, &buf_a),
                entry(3, &buf_b),
                entry(4, &buf_out),
                entry(5, &lights.ies_atlas),
                entry(6, &sampling.tex_atlas),
                entry(7, &lights.mesh_atlas),
            ],
        });
        let mut result = Ok(());
        for start in (0..n).step_by(chunk) {
            let count = chunk.min(n - start);
            let a = &a[6 * start..6 * (start + count)];
            let b = &b[4 * start..4 * (start + count)];
            self.queue.write_buffer(&buf_a, 0, bytemuck::cast_slice(a));
            self.queue.write_buffer(&buf_b, 0, bytemuck::cast_slice(b));
            let grid = self.grid(count as u32);
            let block = params_block(
                &[(0, 0)],
                align,
                count as u32,
                false,
                grid,
                1,
                super::record::LIGHTS_ALL,
            );
            self.queue.write_buffer(&params, 0, &block);
            let mut enc = dev.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some(kernel.entry_point()),
            });
            record_passes(&mut enc, kernel, &pipeline, &bind_group, 1, align, grid);
            let used = (count * out_floats * 4) as u64;
            enc.copy_buffer_to_buffer(&buf_out, 0, &staging, 0, used);
            self.queue.submit([enc.finish()]);
            let slice = staging.slice(..used);
            let (tx, rx) = std::sync::mpsc::channel();
            slice.map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
            if let Err(e) = dev.poll(wgpu::PollType::wait_indefinitely()) {
                result = Err(LuxError::gpu("waiting for the device", e));
                break;
            }
            match rx.recv() {
                Ok(Ok(())) => {}
                Ok(Err(e)) => {
                    result = Err(LuxError::gpu("mapping the result buffer", e));
                    break;
                }
                Err(_) => {
                    result = Err(LuxError::gpu("reading the results back", GpuFailure::Lost));
                    break;
                }
            }
            {
                let view = match slice.get_mapped_range() {
                    Ok(v) => v,
                    Err(e) => {
                        result = Err(LuxError::gpu("reading the result buffer", e));
                        break;
                    }
                };
                out.extend(bytemuck::pod_collect_to_vec::<u8, f32>(&view));
            }
            staging.unmap();
        }
        let validation = pollster::block_on(validation.pop());
        if let Some(why) = self.lost() {
            return Err(LuxError::gpu(
                format!(
                    "the device was lost ({why}) while running {}",
                    kernel.entry_point()
                ),
                GpuFailure::Lost,
            ));
        }
        if let Some(e) = validation {
            return Err(LuxError::gpu(
                format!("running {}", kernel.entry_point()),
                e,
            ));
        }
        result.map(|_| out)
    }
}
