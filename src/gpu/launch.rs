//! How one call is laid out on the device, for the host path (`dispatch`), the GPU-resident
//! queries (`resident`) and sampling (`sample`) alike: the lights cut into groups of one
//! dispatch each, the 2D grid of workgroups, one `Params` block per group in a uniform buffer
//! at the device's dynamic offset alignment, the compute passes that read them in order, and
//! the bind group entries.

use super::record::{Params, WORKGROUP_SIZE};
use super::{GpuContext, Kernel};

impl GpuContext {
    /// The light groups `[first, end)` of `lights` lights that one dispatch each of `kernel`
    /// evaluates ([`GpuContext::lights_per_dispatch`]).
    pub(super) fn light_groups(&self, kernel: Kernel, lights: usize) -> Vec<(usize, usize)> {
        let per_group = self.lights_per_dispatch(kernel).max(1);
        (0..lights)
            .step_by(per_group)
            .map(|g| (g, (g + per_group).min(lights)))
            .collect()
    }

    /// The 2D dispatch grid `(x, y)` of workgroups covering `count` samples: x up to the
    /// device's per-dimension limit, then rows of x (`sample_index` in record.wgsl).
    pub(super) fn grid(&self, count: u32) -> (u32, u32) {
        let max_groups = self.limits.max_compute_workgroups_per_dimension.max(1);
        let wg = count.div_ceil(WORKGROUP_SIZE);
        let gx = wg.min(max_groups).max(1);
        (gx, wg.div_ceil(gx))
    }

    /// The stride of the Params blocks in their uniform buffer: one block rounded up to the
    /// device's dynamic offset alignment (a multiple of it, as every offset must be).
    pub(super) fn params_align(&self) -> usize {
        let align = (self.limits.min_uniform_buffer_offset_alignment as usize).max(1);
        std::mem::size_of::<Params>().div_ceil(align) * align
    }
}

/// One Params block per light group at stride `align`: group g evaluates its lights over
/// `count` samples and, after the first, adds to the sums the groups before it wrote.
pub(super) fn params_block(
    groups: &[(usize, usize)],
    align: usize,
    count: u32,
    per_light: bool,
    (gx, _): (u32, u32),
    lane_stride: u32,
    light_filter: u32,
) -> Vec<u8> {
    let mut block = vec![0u8; groups.len() * align];
    for (g, &(first, end)) in groups.iter().enumerate() {
        let params = Params {
            count,
            light_first: first as u32,
            light_end: end as u32,
            per_light: per_light as u32,
            row_stride: gx * WORKGROUP_SIZE,
            accumulate: (g > 0) as u32,
            lane_stride,
            light_filter,
            ..Params::default()
        };
        block[g * align..g * align + std::mem::size_of::<Params>()]
            .copy_from_slice(bytemuck::bytes_of(&params));
    }
    block
}

/// Records one compute pass per light group, each with its Params block (dynamic offset
/// g · align): passes are ordered, so a group reads the sums of the last.
pub(super) fn record_passes(
    enc: &mut wgpu::CommandEncoder,
    kernel: Kernel,
    pipeline: &wgpu::ComputePipeline,
    bind_group: &wgpu::BindGroup,
    groups: usize,
    align: usize,
    (gx, gy): (u32, u32),
) {
    for g in 0..groups {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(kernel.entry_point()),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[(g * align) as u32]);
        pass.dispatch_workgroups(gx, gy, 1);
    }
}

/// Binding 0: one `Params` block of `buffer`, at the dynamic offset of the pass.
pub(super) fn params_entry(buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding: 0,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
        }),
    }
}

pub(super) fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
