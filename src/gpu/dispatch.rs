//! Running a kernel over a batch: the lights uploaded once per prepared scene ([`GpuLights`]),
//! input/output/readback buffers kept between calls of the same size class ([`Scratch`]), and
//! the batch cut into chunks that fit the device's binding and dispatch limits. The host's share
//! of a call (mapping the inputs into the staging memory, copying the results out of the
//! readback buffer) runs on every core: on a real GPU it is most of the call (BENCHMARKS.md
//! "A real GPU").

use rayon::prelude::*;

use crate::error::{GpuFailure, LuxError, Result};

use super::launch::{entry, params_block, params_entry, record_passes};
use super::record::{
    FLAG_HOST_IRRADIANCE, FLAG_IES, FLAG_RECT_TEXTURE, LIGHTS_SKIP_TEXTURED_RECTS, Record,
};
use super::shaders::Features;
use super::{GpuContext, Kernel};

/// A prepared scene's light records, IES atlas, texture atlas and mesh atlas on the device.
pub(crate) struct GpuLights {
    pub(super) buffer: wgpu::Buffer,
    pub(super) ies_atlas: wgpu::Buffer,
    pub(super) tex_atlas: wgpu::Buffer,
    /// Mesh lights' BVHs and triangles (`super::mesh_atlas`).
    pub(super) mesh_atlas: wgpu::Buffer,
    /// The records as uploaded and the texture atlas's length in f32 words: the sample and pdf
    /// kernels' copy with textured domes' sampling tables appended starts from them
    /// (`GpuContext::sample_lights`).
    pub(super) records: Vec<Record>,
    /// The texture atlas's textures (the row tables after them are the irradiance kernel's
    /// only; the sampling copy leaves them out).
    pub(super) tex_words: usize,
    count: usize,
    /// The optional kernel parts any of the lights needs (`Record::features`).
    features: Features,
    /// The row tables reserved in the texture atlas and not yet written
    /// ([`GpuLights::write_row_tables`]).
    pending_rows: std::sync::Mutex<Vec<super::texture_atlas::RowTables>>,
}

/// The most words of a latlong dome's row tables built and copied to the device at once
/// ([`GpuLights::write_row_tables`]): 32 MiB.
const ROW_TABLE_PIECE_WORDS: usize = 8 << 20;

impl GpuLights {
    /// Builds and writes the latlong row tables the texture atlas reserves, on the first call
    /// of the irradiance kernel (the only one that reads them, `texture_atlas::RowTables`), in
    /// pieces of at most [`ROW_TABLE_PIECE_WORDS`]: each piece is copied to the device and its
    /// staging memory released (an empty submit, then a wait) before the next is built, so the
    /// host holds one piece at a time, not the tables (1.6 GB for 8192 × 4096). The copies
    /// precede every later submission, the caller's own encoder's included.
    pub(super) fn write_row_tables(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<()> {
        let mut pending = self
            .pending_rows
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        for t in pending.drain(..) {
            let pieces = crate::prepare::latlong_rows::device_chunks(
                &t.image,
                t.filter,
                ROW_TABLE_PIECE_WORDS,
            );
            for (o, words) in pieces {
                queue.write_buffer(
                    &self.tex_atlas,
                    (u64::from(t.offset) + o as u64) * 4,
                    bytemuck::cast_slice(&words),
                );
                drop(words);
                queue.submit(std::iter::empty());
                device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .map_err(|e| LuxError::gpu("writing a latlong dome's row tables", e))?;
            }
        }
        Ok(())
    }

    /// How many row tables wait for [`GpuLights::write_row_tables`].
    #[cfg(test)]
    pub(crate) fn rows_pending(&self) -> usize {
        self.pending_rows
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .len()
    }

    /// The records the irradiance kernel integrates in a call with `light_filter`: not those
    /// whose irradiance is the host's (FLAG_HOST_IRRADIANCE), nor, with
    /// [`LIGHTS_SKIP_TEXTURED_RECTS`], the textured rects without a profile (the same test as
    /// shaders/irradiance.wgsl's).
    fn integrated(&self, light_filter: u32) -> impl Iterator<Item = &Record> {
        let skip = light_filter & LIGHTS_SKIP_TEXTURED_RECTS != 0;
        self.records.iter().filter(move |r| {
            r.flags & FLAG_HOST_IRRADIANCE == 0
                && !(skip && r.flags & FLAG_RECT_TEXTURE != 0 && r.flags & FLAG_IES == 0)
        })
    }

    /// Whether some light's irradiance quadrature may run long on the device in a call with
    /// `light_filter` (an IES-shaped light it integrates, whose kinks multiply a line's pieces,
    /// or a textured rect, whose texel lines do: GpuContext::lane_stride).
    pub(super) fn long_quadrature(&self, light_filter: u32) -> bool {
        self.integrated(light_filter)
            .any(|r| r.flags & (FLAG_IES | FLAG_RECT_TEXTURE) != 0)
    }

    /// The pipeline variant `kernel` needs for these lights: the optional parts some light
    /// needs (`GpuContext::pipeline` drops those the kernel's source lacks). The irradiance
    /// kernel needs only those of the lights it integrates in a call with `light_filter`
    /// ([`GpuLights::integrated`]): the IES lookup for IES-shaped ones, its TEXTURE part (the
    /// row integral of a textured latlong dome, irradiance/latlong_rows.wgsl; a textured
    /// rect's texture factor, irradiance/line.wgsl) for textured ones, the chart quadrature
    /// for those that take it; so a scene whose textured rects a call leaves to the host
    /// compiles none of it for them.
    pub(super) fn variant(&self, kernel: Kernel, light_filter: u32) -> Features {
        if kernel == Kernel::Irradiance {
            self.integrated(light_filter)
                .fold(Features::default(), |f, r| f.union(r.features()))
        } else {
            self.features
        }
    }
}

/// The buffers of one size class: a chunk capacity (a power of two, or the device's largest
/// chunk), the rows per sample (lights with `per_light`, else 1), and the light groups of a
/// kernel. A call of the same class reuses them.
#[derive(Clone, Debug, PartialEq, Eq)]
struct ScratchKey {
    chunk: usize,
    rows: usize,
    groups: Vec<(usize, usize)>,
    two_inputs: bool,
}

/// Rows per piece of the parallel readback copy: large enough to amortise rayon's scheduling,
/// small enough to spread a chunk over every core.
const PIECE_ROWS: usize = 1 << 14;

/// Rows per staging view of the parallel upload (1.5 MiB): each view is a staging allocation of
/// its own, so fewer and larger than the readback's pieces.
const UPLOAD_PIECE_ROWS: usize = 1 << 17;

/// One input of a batch: its rows and the map each row goes through on its way to the device
/// (the query layer normalises directions in f64 there, DESIGN.md §3).
#[derive(Clone, Copy)]
pub(crate) struct Input<'a> {
    pub rows: &'a [[f32; 3]],
    pub map: &'a (dyn Fn([f32; 3]) -> [f32; 3] + Sync),
}

/// Reusable input, output, readback and parameter buffers with their bind group.
pub(crate) struct Scratch {
    key: ScratchKey,
    buf_a: wgpu::Buffer,
    buf_b: Option<wgpu::Buffer>,
    buf_out: wgpu::Buffer,
    staging: wgpu::Buffer,
    params: wgpu::Buffer,
    align: usize,
    bind_group: wgpu::BindGroup,
}

impl GpuContext {
    /// Uploads the records, the IES atlas, the texture atlas and the mesh atlas of a prepared
    /// scene (None when there are no lights).
    pub fn upload(
        &self,
        records: &[Record],
        ies_atlas: &[f32],
        tex_atlas: &super::texture_atlas::Atlas,
        mesh_atlas: &[f32],
    ) -> Result<Option<GpuLights>> {
        if records.is_empty() {
            return Ok(None);
        }
        let bytes = std::mem::size_of_val(records) as u64;
        if bytes > self.limits.max_storage_buffer_binding_size {
            return Err(LuxError::input(
                "lights",
                format!(
                    "{} lights need {bytes} bytes, over this device's storage binding limit of {} bytes; split the stage with --light",
                    records.len(),
                    self.limits.max_storage_buffer_binding_size
                ),
            ));
        }
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lights"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(records));
        let atlas_bytes = std::mem::size_of_val(ies_atlas) as u64;
        if atlas_bytes > self.limits.max_storage_buffer_binding_size {
            return Err(LuxError::input(
                "IES profiles",
                format!(
                    "the scene's IES profiles need {atlas_bytes} bytes, over this device's storage binding limit of {} bytes; split the stage with --light",
                    self.limits.max_storage_buffer_binding_size
                ),
            ));
        }
        let ies_atlas_buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ies atlas"),
            size: atlas_bytes.max(4),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        if !ies_atlas.is_empty() {
            self.queue
                .write_buffer(&ies_atlas_buffer, 0, bytemuck::cast_slice(ies_atlas));
        }
        // One atlas per scene, reduced to fit the binding limit (texture_atlas::scene_atlas) where
        // its textures allow; refused whole when it still does not fit.
        let tex_bytes = (tex_atlas.len() * 4) as u64;
        if tex_bytes > self.atlas_limit() {
            let files: Vec<String> = tex_atlas
                .entries
                .iter()
                .map(|e| {
                    format!(
                        "{} ({} × {})",
                        e.image.source.display(),
                        e.image.width,
                        e.image.height
                    )
                })
                .collect();
            return Err(LuxError::input(
                "dome textures",
                format!(
                    "the scene's textures ({}) need {tex_bytes} bytes, over this device's storage binding limit of {} bytes, and cannot be halved further (odd sizes); use smaller textures or --device cpu",
                    files.join(", "),
                    self.atlas_limit()
                ),
            ));
        }
        let tex_atlas_buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture atlas"),
            size: tex_bytes.max(4),
            // COPY_SRC: the sampling kernels' atlas starts as a device-side copy of this one.
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        // Each image straight to its offset: no concatenated host copy.
        for (offset, data) in tex_atlas.chunks() {
            if !data.is_empty() {
                self.queue.write_buffer(
                    &tex_atlas_buffer,
                    (offset * 4) as u64,
                    bytemuck::cast_slice(data),
                );
            }
        }
        let mesh_bytes = std::mem::size_of_val(mesh_atlas) as u64;
        if mesh_bytes > self.limits.max_storage_buffer_binding_size {
            return Err(LuxError::input(
                "mesh lights",
                format!(
                    "the scene's mesh lights need {mesh_bytes} bytes of BVH and triangles, over \
                     this device's storage binding limit of {} bytes; split the stage with \
                     --light or use --device cpu",
                    self.limits.max_storage_buffer_binding_size
                ),
            ));
        }
        let mesh_atlas_buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mesh atlas"),
            size: mesh_bytes.max(4),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        if !mesh_atlas.is_empty() {
            self.queue
                .write_buffer(&mesh_atlas_buffer, 0, bytemuck::cast_slice(mesh_atlas));
        }
        Ok(Some(GpuLights {
            buffer,
            ies_atlas: ies_atlas_buffer,
            tex_atlas: tex_atlas_buffer,
            mesh_atlas: mesh_atlas_buffer,
            records: records.to_vec(),
            tex_words: tex_atlas.textures_len(),
            count: records.len(),
            features: records
                .iter()
                .fold(Features::default(), |f, r| f.union(r.features())),
            pending_rows: std::sync::Mutex::new(tex_atlas.rows.clone()),
        }))
    }

    /// Runs `kernel` over `a` (and `b`) for every light: `count` rows summed over lights, or
    /// `lights × count` rows in light-major order with `per_light`. `scratch` holds the buffers
    /// of the last call and is replaced when this call needs another size class. The
    /// irradiance kernel integrates only the lights `light_filter` names (`record::LIGHTS_*`;
    /// the others' rows are 0); the other kernels ignore it.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        kernel: Kernel,
        lights: &GpuLights,
        scratch: &mut Option<Scratch>,
        a: Input<'_>,
        b: Option<Input<'_>>,
        per_light: bool,
        light_filter: u32,
    ) -> Result<Vec<[f32; 3]>> {
        let n = a.rows.len();
        let count = lights.count;
        let rows = if per_light { count } else { 1 };
        let mut out = vec![[0f32; 3]; rows * n];
        if n == 0 || count == 0 {
            return Ok(out);
        }
        let pipeline = self.pipeline(kernel, lights.variant(kernel, light_filter))?;
        if kernel == Kernel::Irradiance {
            lights.write_row_tables(&self.device, &self.queue)?;
        }
        let capacity = self.chunk_capacity(count, per_light);
        let key = ScratchKey {
            chunk: n.next_power_of_two().min(capacity),
            rows,
            groups: self.light_groups(kernel, count),
            two_inputs: b.is_some(),
        };
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        if scratch.as_ref().is_none_or(|s| s.key != key) {
            *scratch = Some(self.scratch(key, lights));
        }
        let s = scratch.as_ref().expect("set above");
        let lane_stride = self.lane_stride(kernel, lights, light_filter);
        let result = self.run_chunks(
            &pipeline,
            kernel,
            s,
            a,
            b,
            per_light,
            lane_stride,
            light_filter,
            &mut out,
        );
        let oom = pollster::block_on(oom.pop());
        let validation = pollster::block_on(validation.pop());
        // A lost device fails every later call with validation errors about invalid buffers;
        // the loss itself is what to report.
        if let Some(why) = self.lost()
            && (oom.is_some() || validation.is_some() || result.is_err())
        {
            *scratch = None;
            return Err(LuxError::gpu(
                format!(
                    "the device was lost ({why}) while running {}",
                    kernel.entry_point()
                ),
                GpuFailure::Lost,
            ));
        }
        if let Some(e) = oom {
            *scratch = None;
            return Err(LuxError::gpu("out of memory", e));
        }
        if let Some(e) = validation {
            *scratch = None;
            return Err(LuxError::gpu(
                format!("running {}", kernel.entry_point()),
                e,
            ));
        }
        result.map(|_| out)
    }

    fn scratch(&self, key: ScratchKey, lights: &GpuLights) -> Scratch {
        let dev = &self.device;
        let storage = |label, size: u64, extra: wgpu::BufferUsages| {
            dev.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | extra,
                mapped_at_creation: false,
            })
        };
        let in_bytes = (key.chunk * 12) as u64;
        let out_bytes = (key.chunk * key.rows * 12) as u64;
        let buf_a = storage("in_a", in_bytes, wgpu::BufferUsages::COPY_DST);
        let buf_b = key
            .two_inputs
            .then(|| storage("in_b", in_bytes, wgpu::BufferUsages::COPY_DST));
        let buf_out = storage("out", out_bytes, wgpu::BufferUsages::COPY_SRC);
        let staging = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: out_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // One Params block per light group at the uniform offset alignment.
        let align = self.params_align();
        let params = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: (key.groups.len() * align) as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("luxeval queries"),
            layout: &self.layout,
            entries: &[
                params_entry(&params),
                entry(1, &lights.buffer),
                entry(2, &buf_a),
                // Emission reads no second input; bind the first again (read-only aliasing).
                entry(3, buf_b.as_ref().unwrap_or(&buf_a)),
                entry(4, &buf_out),
                entry(5, &lights.ies_atlas),
                entry(6, &lights.tex_atlas),
                entry(7, &lights.mesh_atlas),
            ],
        });
        Scratch {
            key,
            buf_a,
            buf_b,
            buf_out,
            staging,
            params,
            align,
            bind_group,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn run_chunks(
        &self,
        pipeline: &wgpu::ComputePipeline,
        kernel: Kernel,
        s: &Scratch,
        a: Input<'_>,
        b: Option<Input<'_>>,
        per_light: bool,
        lane_stride: u32,
        light_filter: u32,
        out: &mut [[f32; 3]],
    ) -> Result<()> {
        let n = a.rows.len();
        let rows = s.key.rows;
        let groups = &s.key.groups;
        let align = s.align;
        let mut start = 0;
        while start < n {
            let count = s.key.chunk.min(n - start);
            self.write_rows(&s.buf_a, a, start..start + count)?;
            if let (Some(buf), Some(b)) = (&s.buf_b, b) {
                self.write_rows(buf, b, start..start + count)?;
            }
            let grid = self.grid(count as u32 * lane_stride);
            let block = params_block(
                groups,
                align,
                count as u32,
                per_light,
                grid,
                lane_stride,
                light_filter,
            );
            self.queue.write_buffer(&s.params, 0, &block);
            let mut enc = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some(kernel.entry_point()),
                });
            record_passes(
                &mut enc,
                kernel,
                pipeline,
                &s.bind_group,
                groups.len(),
                align,
                grid,
            );
            let used = (count * rows * 12) as u64;
            enc.copy_buffer_to_buffer(&s.buf_out, 0, &s.staging, 0, used);
            self.queue.submit([enc.finish()]);

            self.read_back(&s.staging, used, |values| {
                // Light-major: this chunk's rows of light l go to rows l·n + start.. (per
                // light), or to rows start.. (summed, one "light").
                out.par_chunks_mut(n)
                    .zip(values.par_chunks(count))
                    .for_each(|(dst, src)| copy_rows(&mut dst[start..start + count], src));
            })?;
            start += count;
        }
        Ok(())
    }

    /// Writes `input`'s rows `range`, mapped, to the start of `buffer`, in pieces on every core
    /// (one staging view each: a view is `Send`, the pieces of one view are not).
    fn write_rows(
        &self,
        buffer: &wgpu::Buffer,
        input: Input<'_>,
        range: std::ops::Range<usize>,
    ) -> Result<()> {
        let rows = &input.rows[range];
        let views = rows
            .chunks(UPLOAD_PIECE_ROWS)
            .enumerate()
            .map(|(i, piece)| {
                let offset = (i * UPLOAD_PIECE_ROWS * 12) as u64;
                let size = wgpu::BufferSize::new((piece.len() * 12) as u64)?;
                // None only on a validation failure, which the caller's error scope reports.
                self.queue.write_buffer_with(buffer, offset, size)
            })
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| LuxError::gpu("staging the inputs", GpuFailure::Lost))?;
        views
            .into_par_iter()
            .zip(rows.par_chunks(UPLOAD_PIECE_ROWS))
            .for_each(|(mut view, piece)| {
                let (slots, _) = view.slice(..).into_chunks::<12>();
                slots.write_iter(
                    piece
                        .iter()
                        .map(|&row| bytemuck::cast::<[f32; 3], [u8; 12]>((input.map)(row))),
                );
            });
        Ok(())
    }

    /// Maps the first `size` bytes of `staging`, hands them to `take` as rows, and unmaps.
    fn read_back(
        &self,
        staging: &wgpu::Buffer,
        size: u64,
        take: impl FnOnce(&[[f32; 3]]),
    ) -> Result<()> {
        let slice = staging.slice(..size);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| LuxError::gpu("waiting for the device", e))?;
        rx.recv()
            .map_err(|_| LuxError::gpu("reading the results back", GpuFailure::Lost))?
            .map_err(|e| LuxError::gpu("mapping the result buffer", e))?;
        {
            let view = slice
                .get_mapped_range()
                .map_err(|e| LuxError::gpu("reading the result buffer", e))?;
            // Mapped memory is at least 4-byte aligned on every backend; copy if it ever is not.
            match bytemuck::try_cast_slice::<u8, [f32; 3]>(&view) {
                Ok(rows) => take(rows),
                Err(_) => take(&bytemuck::pod_collect_to_vec::<u8, [f32; 3]>(&view)),
            }
        }
        staging.unmap();
        Ok(())
    }
}

/// `dst.copy_from_slice(src)` in pieces on every core.
fn copy_rows(dst: &mut [[f32; 3]], src: &[[f32; 3]]) {
    dst.par_chunks_mut(PIECE_ROWS)
        .zip(src.par_chunks(PIECE_ROWS))
        .for_each(|(d, s)| d.copy_from_slice(s));
}
