//! The one per-light decision of which queries a GPU evaluator takes from the device and which
//! from the CPU reference (DESIGN.md §1: made once in `prepare`, read by both sides), and the
//! limits it applies.

use glam::DMat3;

use super::texture::PreparedTexture;
use super::{KindData, PreparedIes, PreparedPortal, latlong_rows, portal};
use portal::Overlap;

/// Where the GPU path takes a light's values from: the one decision, made per light when it is
/// prepared, that the record (`FLAG_HOST_IRRADIANCE`, `FLAG_MESH_FRONTS`, or a record that emits
/// nothing), the mesh atlas, the host's sums in `query::PreparedScene`, the GPU-resident
/// refusals and the conformance check all read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuPath {
    /// Every query on the device.
    Device,
    /// Every query on the device but irradiance, which is the CPU reference's until the f32
    /// quadrature can match it; the reason is a phrase ("it is a textured rect"):
    /// - IES profiles of type B under angleScale (but ±1): it bends their grid lines into
    ///   surfaces that are neither cones nor planes, which the kernel cannot split at
    ///   (`PreparedIes::device_families`; every other IES-shaped light is integrated on the
    ///   device, its lines split at the profile's grid cones and planes).
    /// - Textured domes the kernel does not integrate by rows (`prepare::latlong_rows::gpu_path`:
    ///   mirroredBall, angular and cross maps, frames that are not a rotation times a uniform
    ///   scale; on a given device, latlong maps whose row tables do not fit its storage binding
    ///   beside the scene's textures, `gpu::texture_atlas::tables_beyond`): the exact integral of the filtered texture
    ///   (DESIGN.md §6 "what 'exact' means", src/cpu/irradiance/dome.rs) splits at texel-centre
    ///   lines and the horizon; a dome's irradiance depends on the normal only, so the reference
    ///   evaluates it once per distinct normal (one for a whole falloff map).
    /// - Textured rects of more than [`RECT_TEXELS_ON_DEVICE`] texels: the exact integral of
    ///   the filtered texture over the surface splits at texel-centre lines (bilinear) or texel
    ///   edges (nearest) and the receiver's horizon (src/cpu/irradiance/rect_texture.rs), so
    ///   its cost grows with the texels; the kernel integrates smaller ones
    ///   (shaders/irradiance/line.wgsl and outer.wgsl), the CPU reference larger ones (from
    ///   `--tolerance` 1e-4 on by moments of the texture, rect_fast.rs).
    /// - Masked domes whose portals may hide one another in more ways than the kernel sums
    ///   (`portal::overlaps`; §8 P2 mask mode), and masked textured domes the row integral does not take (the formats and
    ///   frames above): emission is the dome's own and radiance tests the portal crossings on
    ///   the device (shaders/portal.wgsl, the portals in the mesh atlas); irradiance needs the
    ///   portals' visible pieces (cpu::portal::irradiance), which have no kernel. Other masked
    ///   domes are [`Device`] (`Prepared::apply_portal_mode`: Lambert's formula, or a latlong
    ///   texture's row integral over each polygon, summed over the portals and, by
    ///   inclusion–exclusion, their overlaps, split where portals of different multipliers
    ///   are crossed in either order, shaders/irradiance/portals.wgsl and
    ///   latlong_polygon.wgsl). A dome's intensity is 0 on both paths.
    ///
    ///   [`Device`]: GpuPath::Device
    HostIrradiance(&'static str),
    /// Emission and radiance on the device (the mesh's distinct front directions and its BVH in
    /// the mesh atlas: shaders/emission.wgsl, shaders/mesh/ray.wgsl); intensity and irradiance
    /// from the CPU reference: mesh lights (DESIGN.md §7) with at most
    /// [`MESH_FRONTS_ON_DEVICE`] front directions, but those of
    /// [`HostIntensityOnly`](GpuPath::HostIntensityOnly). Their intensity and irradiance need the exact
    /// visible pieces (cpu::mesh::visible), which have no kernel.
    HostIntensity(&'static str),
    /// Emission, radiance and irradiance on the device, intensity from the CPU reference: the
    /// unshaped mesh lights of [`HostIntensity`](GpuPath::HostIntensity)'s kind whose triangles
    /// cannot hide one another (`prepare::mesh_class`: planar meshes without overlap, one-sided
    /// closed convex meshes) and that have at most [`MESH_TRIANGLES_SUMMED`] triangles. Their
    /// exact irradiance is the sum over the triangles x sees an emitting side of of Lambert's
    /// formula clipped at the horizon (shaders/mesh/lambert.wgsl, the triangles in the mesh
    /// atlas); their intensity still needs the visible pieces.
    HostIntensityOnly(&'static str),
    /// Radiance on the device; emission, intensity and irradiance from the CPU reference: mesh
    /// lights with more than [`MESH_FRONTS_ON_DEVICE`] front directions (the emission kernel
    /// tests each in turn).
    RadianceOnDevice(&'static str),
    /// Every query from the CPU reference: mesh lights the device cannot hold or traverse (a
    /// hierarchy deeper than the kernel's stack, more data than [`MESH_DEVICE_BYTES`], a
    /// singular transform), and domes masked by more than [`PORTALS_ON_DEVICE`] portals. The
    /// record the kernels see emits nothing.
    Host(&'static str),
}

/// A light's [`GpuPath`] from what prepare made of it (`Prepared::with_assets`): its kind's
/// data, whether it is shaped, its IES profile and its world → local map.
pub(super) fn decide(
    kind: &KindData,
    shaped: bool,
    ies: Option<&PreparedIes>,
    to_local: &DMat3,
) -> GpuPath {
    if let KindData::Mesh {
        bvh,
        fronts,
        occlusion,
        ..
    } = kind
    {
        let bytes = 32 * bvh.nodes.len() as u64 + 40 * bvh.order.len() as u64;
        if bvh.depth() > MESH_STACK {
            GpuPath::Host("it is a mesh light whose BVH is deeper than the kernel's stack")
        } else if bytes > MESH_DEVICE_BYTES {
            GpuPath::Host("it is a mesh light too large for the device")
        } else if !to_local.is_finite() {
            GpuPath::Host("it is a mesh light with a singular transform")
        } else if fronts.len() > MESH_FRONTS_ON_DEVICE {
            GpuPath::RadianceOnDevice(
                "it is a mesh light facing more directions than the emission kernel tests",
            )
        } else if occlusion.free() && !shaped {
            GpuPath::HostIntensityOnly(
                "it is a mesh light (its triangles cannot hide one another: irradiance on the device)",
            )
        } else {
            GpuPath::HostIntensity("it is a mesh light")
        }
    } else if ies.is_some_and(|i| i.device_families().is_none()) {
        GpuPath::HostIrradiance("its IES profile's grid lines are bent by angleScale (type B)")
    } else {
        match kind {
            KindData::Dome { texture: Some(t) } => latlong_rows::gpu_path(t),
            KindData::Rect { texture: Some(t) }
                if t.image.width * t.image.height > RECT_TEXELS_ON_DEVICE =>
            {
                GpuPath::HostIrradiance(
                    "it is a textured rect with more texels than the device integrates",
                )
            }
            _ => GpuPath::Device,
        }
    }
}

/// A dome's [`GpuPath`] once it is masked by `portals` (`Prepared::apply_portal_mode`, DESIGN.md
/// §8 P2), and the overlaps the device sums: emission and radiance on the device (up to
/// [`PORTALS_ON_DEVICE`] portals), and irradiance too where the dome is uniform or latlong
/// under a conformal frame ([`latlong_rows::gpu_path`]) and the overlaps of its portals fit the
/// kernel ([`portal::overlaps`]: Lambert's formula or the texture's row integral summed over
/// them by inclusion–exclusion, shaders/irradiance/portals.wgsl).
pub(super) fn masked(
    portals: &[PreparedPortal],
    textured: Option<&PreparedTexture>,
) -> (GpuPath, Vec<Overlap>) {
    if portals.len() > PORTALS_ON_DEVICE {
        (
            GpuPath::Host("it is masked by more portals than the radiance kernel tests"),
            Vec::new(),
        )
    } else if let Some(t) = textured
        && let path @ GpuPath::HostIrradiance(_) = latlong_rows::gpu_path(t)
    {
        // Another format or a non-conformal frame: no row tables to integrate through them.
        (path, Vec::new())
    } else {
        match portal::overlaps(portals) {
            Ok(sets) => (GpuPath::Device, sets),
            Err(why) => (GpuPath::HostIrradiance(why), Vec::new()),
        }
    }
}

/// The most texels of a textured rect whose irradiance the kernel integrates (a larger one's is
/// the CPU reference's, [`GpuPath::HostIrradiance`]): 64 × 64. The kernel splits its quadrature
/// at every texel line, as the reference's exact path does (src/cpu/irradiance/rect_texture.rs),
/// so its cost grows with the texels (≥ 450 evaluations of the integrand per texel per receiver
/// with its f32 rule: 15 lines per texel row, 30 evaluations per piece of a line; lavapipe takes
/// 16 ms per receiver at 8 × 8 and runs out of its loop budget past about 4 × 4), while the
/// CPU's moment path (rect_fast.rs, from the default tolerance 1e-4 on) costs about the same at
/// any size (20–40 µs per receiver on 2 cores for 8 × 8 to 64 × 64 seen from a few sizes away;
/// BENCHMARKS.md "Small textured rects' irradiance on the device"). So host-path calls at such
/// tolerances take textured rects without an IES profile from the CPU (`query::scene`
/// `host_takes`), and the device integrates them in GPU-resident calls (which have no host step,
/// and would refuse them otherwise) and at the reference's tolerance (a GPU evaluator given
/// none, the only one tighter than 1e-4 it takes; the CPU's path there splits at every texel
/// line too). Past 64 × 64 the split would cost a receiver ~2·10⁶ evaluations or more:
/// such textures stay on the host until a kernel of the moment path exists.
pub const RECT_TEXELS_ON_DEVICE: usize = 64 * 64;

/// The most distinct front directions of a mesh light whose emission the kernel tests
/// ([`GpuPath::HostIntensity`]); a mesh with more takes its emission from the host
/// ([`GpuPath::RadianceOnDevice`]). The kernel loops once per direction: 4096 keeps one mesh
/// well inside lavapipe's 65,535 loop iterations per invocation (with room for a dozen such
/// meshes in one dispatch) and bounds the cost of a direction that no front faces (every front
/// is read) at about the cost of a BVH traversal; flat, boxy and low-polygon lights have a
/// handful, a smooth closed mesh about as many as triangles (those past 4096 stay on the host).
pub const MESH_FRONTS_ON_DEVICE: usize = 4096;

/// The most triangles of a mesh light that prepare classifies ([`crate::prepare::mesh_class`])
/// and whose irradiance the kernel sums ([`GpuPath::HostIntensityOnly`]): one triangle per loop
/// iteration, for lavapipe's budget as [`MESH_FRONTS_ON_DEVICE`]; the classification's checks
/// are quadratic in the worst case, which this bounds too.
pub const MESH_TRIANGLES_SUMMED: usize = 4096;

/// The most portals of a masked dome whose crossings the radiance kernel tests (one loop
/// iteration each, for lavapipe's budget as [`MESH_FRONTS_ON_DEVICE`]); a dome masked by more is
/// evaluated on the host ([`GpuPath::Host`]).
pub const PORTALS_ON_DEVICE: usize = 4096;

/// The most bytes of BVH nodes and triangles one mesh light may take on the device (32 bytes a
/// node, 40 a triangle: about 800,000 triangles); a larger mesh is evaluated on the host
/// ([`GpuPath::Host`]), so that a scene's meshes fit WebGPU's default storage binding limit
/// (128 MiB) with room for others.
pub const MESH_DEVICE_BYTES: u64 = 48 << 20;

/// The deepest BVH the radiance kernel traverses: its stack holds this many nodes.
pub const MESH_STACK: usize = 64;
