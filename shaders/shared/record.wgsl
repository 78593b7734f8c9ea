// The GPU light record and the query bindings shared by every kernel.
//
// No CPU twin: the record is packed by src/gpu/record.rs, whose layout tests/wgsl.rs checks
//   against naga; the bindings have no CPU counterpart.
//
// The record's Rust twin is `Record` in src/gpu/record.rs; tests/wgsl.rs asserts both layouts
// against naga's layouter. The constants KIND_* and FLAG_* come from a prelude that
// src/gpu/shaders.rs generates from the Rust constants, so they are never retyped here.
//
// All per-light constants (base radiance including colour temperature and normalize, the
// world->local map, axes, cone angles) are computed on the CPU in f64 and rounded once.

struct Record {
    // Rows of the world->local affine map: local = (dot(row.xyz, p) + row.w) for points,
    // dot(row.xyz, v) for directions.
    to_local0: vec4<f32>,
    to_local1: vec4<f32>,
    to_local2: vec4<f32>,
    // xyz: unit primary axis in world space (the image of local -Z); w: distant θmax (radians).
    axis: vec4<f32>,
    // xyz: unit world normal of the emitting side of a rect or disk (inverse transpose of -Z).
    normal: vec4<f32>,
    // rgb: intensity · 2^exposure · color ⊙ temperature / sizeFactor.
    base: vec4<f32>,
    // rgb: shaping:focusTint; w: shaping:focus.
    focus_tint: vec4<f32>,
    // x: cone angle θcone (radians); y: smoothstep start (1 - softness)·θcone.
    cone: vec4<f32>,
    // rect: (width/2, height/2); disk, sphere: (radius); cylinder: (length/2, radius).
    size: vec4<f32>,
    // Columns of the local-to-world linear map M (images of local X, Y, Z); w: world origin.
    world_x: vec4<f32>,
    world_y: vec4<f32>,
    world_z: vec4<f32>,
    // Irradiance: (diffuse, |det M|, cos θ of kink A, cos θ of kink B) (FLAG_KINK_A/B).
    irr: vec4<f32>,
    // IES (FLAG_IES): (atlas base of the profile, an exact integer in f32; angleScale;
    // normalisation or tilt scale; base of its kinks block, read by irradiance/line.wgsl).
    ies: vec4<f32>,
    // Textured dome (FLAG_DOME_TEXTURE): columns of A_eff⁻¹ (world → dome, DESIGN.md §6 D1).
    // Textured rect (FLAG_RECT_TEXTURE): tex_inv0.rgb is the texture's mean colour.
    tex_inv0: vec4<f32>,
    tex_inv1: vec4<f32>,
    tex_inv2: vec4<f32>,
    // Textured dome or rect: (atlas offset of the texture's header, filter code, offset of a
    // dome's row tables when its irradiance is the device's (irradiance/latlong_rows.wgsl), 0); in the
    // sample and pdf kernels' copy a textured dome's z is its sampling table's offset (0: none;
    // gpu::sample::SampleLights).
    // A masked dome (FLAG_PORTALS): w is its portals' offset in the mesh atlas. A mesh light:
    // (nodes' offset, node count, triangles' offset, fronts' offset) in the mesh atlas.
    tex: vec4<u32>,
    kind: u32,
    flags: u32,
    pad0: u32,
    pad1: u32,
    // The light choice of GPU-resident sampling (sample/select.wgsl): (power weight, luminance
    // weight of base, world bounding-sphere radius, 0), the weights divided by the scene's
    // largest.
    select: vec4<f32>,
}

struct Params {
    // Samples in this dispatch.
    count: u32,
    // This dispatch evaluates lights [light_first, light_end) of the light buffer (the host
    // splits the lights into groups; see `GpuContext::lights_per_dispatch`).
    light_first: u32,
    light_end: u32,
    // 1: write (light, sample) rows; 0: write the sum over lights.
    per_light: u32,
    // Invocations per row of the 2D dispatch grid (workgroups_x · WORKGROUP_SIZE).
    row_stride: u32,
    // Summed mode, not the first group: add this group's sum to the row already written.
    accumulate: u32,
    // Invocations per sample: lavapipe's loop budget (see irr_cut) is shared by the
    // invocations it runs together, so an irradiance call whose quadrature is long runs one
    // sample per lane_stride invocations (GpuContext::lane_stride).
    lane_stride: u32,
    // Which lights irradiance_main integrates (LIGHTS_ALL; LIGHTS_NORMAL_ONLY: distant lights
    // and domes, whose irradiance depends on the normal alone, in a pass over the distinct
    // normals; LIGHTS_POSITIONAL: the others); the rest give 0. 0 for every other kernel.
    light_filter: u32,
    // GPU-resident sampling (sample_resident_main): the generator's seed, samples per point, the
    // first point's key (DESIGN.md §9 S3), the light choice (SELECT_POWER or SELECT_BOUND, plus
    // SELECT_HAS_NORMALS). 0 for every other kernel.
    seed: u32,
    per_point: u32,
    first_point: u32,
    select: u32,
}

// Set when a loop of the irradiance quadrature ends before its own condition says so: lavapipe
// leaves an invocation's loops silently once they have run 65,535 iterations in all (Mesa's
// gallivm loop limiter), and every loop after that point runs at most once. A loop that stops
// short is the only way such a cut changes a value, so the quadrature's loops check their own
// condition after they end, and irradiance_main writes NaN for a cut (light, sample), which the
// host recomputes on the CPU reference (query::PreparedScene::irradiance). A real GPU never
// cuts.
var<private> irr_cut: bool;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> lights: array<Record>;
// Float triples: directions (emission) or points (radiance, irradiance).
@group(0) @binding(2) var<storage, read> in_a: array<f32>;
// Float triples: directions (radiance) or receiver normals (irradiance); unused by emission.
@group(0) @binding(3) var<storage, read> in_b: array<f32>;
@group(0) @binding(4) var<storage, read_write> out_rgb: array<f32>;
// Every IES profile of the scene (shared/ies.wgsl reads it; layout in src/gpu/ies_atlas.rs).
@group(0) @binding(5) var<storage, read> ies_atlas: array<f32>;
// Every dome and rect texture of the scene (shared/texture.wgsl reads it; layout in src/gpu/texture_atlas.rs).
@group(0) @binding(6) var<storage, read> tex_atlas: array<f32>;
// Every mesh light's BVH, triangles and fronts, and every masked dome's portals (mesh/ray.wgsl,
// emission.wgsl and portal.wgsl read it; layout in src/gpu/mesh_atlas.rs).
@group(0) @binding(7) var<storage, read> mesh_atlas: array<f32>;

fn sample_index(gid: vec3<u32>) -> u32 {
    return gid.x + gid.y * params.row_stride;
}

// The f32 words of a row of in_a, in_b and out_rgb in the queries (not the sampling kernels'
// own rows): 3 (packed, the host path's) or 4 (RowLayout::Vec4, GPU-resident only: 16-byte
// rows, the fourth float ignored on input and written 0). A pipeline constant, so that the
// driver sees the stride and can serve a 16-byte row in one aligned access.
override ROW_WORDS: u32 = 3u;

// Rows per invocation of the emission, intensity and radiance kernels: 1 on the host path and
// on CPU drivers; GPU-resident calls on a hardware adapter take 2 (`GpuContext::rows_per_invocation`)
// (a pipeline constant, like ROW_WORDS). Invocation j takes rows j, j + s, j + 2s, … with
// s = row_step() = ⌈count / ROWS_PER_INVOCATION⌉, so that neighbouring invocations still read
// and write neighbouring rows (coalesced), and each has several rows' loads in flight.
override ROWS_PER_INVOCATION: u32 = 1u;

fn row_step() -> u32 {
    return (params.count + ROWS_PER_INVOCATION - 1u) / ROWS_PER_INVOCATION;
}

fn load3(buf_is_b: bool, i: u32) -> vec3<f32> {
    let k = ROW_WORDS * i;
    if buf_is_b {
        return vec3<f32>(in_b[k], in_b[k + 1u], in_b[k + 2u]);
    }
    return vec3<f32>(in_a[k], in_a[k + 1u], in_a[k + 2u]);
}

// Writes one result: to the (light, sample) row when per_light, else (the caller passes the sum)
// to the sample's row.
fn store3(row: u32, v: vec3<f32>) {
    let k = ROW_WORDS * row;
    out_rgb[k] = v.x;
    out_rgb[k + 1u] = v.y;
    out_rgb[k + 2u] = v.z;
    if ROW_WORDS == 4u {
        out_rgb[k + 3u] = 0.0;
    }
}

// Every kernel loops over the lights for its sample i: `add` stores light l's value to its own
// row (per_light) or adds it to the running sum, and `finish` stores the sum.
fn add(i: u32, l: u32, v: vec3<f32>, sum: ptr<function, vec3<f32>>) {
    if params.per_light != 0u {
        store3(l * params.count + i, v);
    } else {
        *sum += v;
    }
}

fn finish(i: u32, sum: vec3<f32>) {
    if params.per_light == 0u {
        var total = sum;
        if params.accumulate != 0u {
            let k = ROW_WORDS * i;
            total += vec3<f32>(out_rgb[k], out_rgb[k + 1u], out_rgb[k + 2u]);
        }
        store3(i, total);
    }
}

fn has_flag(light: Record, flag: u32) -> bool {
    return (light.flags & flag) != 0u;
}

fn to_local_point(light: Record, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        dot(light.to_local0.xyz, p) + light.to_local0.w,
        dot(light.to_local1.xyz, p) + light.to_local1.w,
        dot(light.to_local2.xyz, p) + light.to_local2.w,
    );
}

fn to_local_dir(light: Record, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(light.to_local0.xyz, v), dot(light.to_local1.xyz, v), dot(light.to_local2.xyz, v));
}

// The local-to-world linear map applied to a local vector.
fn to_world_dir(light: Record, v: vec3<f32>) -> vec3<f32> {
    return light.world_x.xyz * v.x + light.world_y.xyz * v.y + light.world_z.xyz * v.z;
}

fn world_origin(light: Record) -> vec3<f32> {
    return vec3<f32>(light.world_x.w, light.world_y.w, light.world_z.w);
}

// The kink cones of the light's shaping (prepare::Profile): count, and their cosines.
fn kink_count(light: Record) -> u32 {
    return select(0u, 1u, has_flag(light, FLAG_KINK_A)) + select(0u, 1u, has_flag(light, FLAG_KINK_B));
}

fn kink_cos(light: Record, i: u32) -> f32 {
    return select(light.irr.z, light.irr.w, i == 1u);
}
