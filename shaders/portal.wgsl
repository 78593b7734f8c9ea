// A dome masked by its portals (DESIGN.md §8 P2, mask mode): which portal a ray passes through.
// Twin of src/cpu/portal.rs, which carries the rule (nearest crossing toward the portal's +Z,
// edges inclusive, ties to the earlier portal). Its irradiance: irradiance/portals.wgsl for an
// untextured dome (but portals of different multipliers crossed in either order,
// prepare::portal::overlaps), else the CPU reference's, which the host adds
// (GpuPath::HostIrradiance).
//
// f32: a ray within ~1e-6 (relative) of a portal's edge, or from a point within that of a
//   portal's plane, may cross it or not differently from the reference (the conformance check
//   excludes that band, conformance::band::portal_margin).
// f32: one loop iteration a portal; prepare keeps domes with more than PORTALS_ON_DEVICE
//   portals on the host (GpuPath::Host), within lavapipe's 65,535 iterations an invocation.

// #import shared/record.wgsl

// The multiplier of the portal the ray x + tω (t > 0) passes through toward its +Z, nearest
// first, in xyz, and 1 in w; 0 in w when it passes through none. The portals are in the mesh
// atlas at `at` (layout: src/gpu/mesh_atlas.rs).
fn crossing(at: u32, x: vec3<f32>, w: vec3<f32>) -> vec4<f32> {
    let count = bitcast<u32>(mesh_atlas[at]);
    var best = vec4<f32>(0.0);
    var best_t = 0.0;
    for (var k = 0u; k < count; k++) {
        let q = at + 1u + k * PORTAL_WORDS;
        let origin = vec3<f32>(mesh_atlas[q], mesh_atlas[q + 1u], mesh_atlas[q + 2u]);
        let normal = vec3<f32>(mesh_atlas[q + 3u], mesh_atlas[q + 4u], mesh_atlas[q + 5u]);
        let toward = dot(normal, w);
        let side = dot(normal, x - origin);
        // Moving toward +Z (toward > 0) from the −Z side (side < 0): t > 0.
        if !(toward > 0.0 && side < 0.0) {
            continue;
        }
        let t = -side / toward;
        let r = x + t * w - origin;
        let hx = dot(vec3<f32>(mesh_atlas[q + 6u], mesh_atlas[q + 7u], mesh_atlas[q + 8u]), r);
        let hy = dot(vec3<f32>(mesh_atlas[q + 9u], mesh_atlas[q + 10u], mesh_atlas[q + 11u]), r);
        let inside = abs(hx) <= mesh_atlas[q + 15u] && abs(hy) <= mesh_atlas[q + 16u];
        if inside && (best.w == 0.0 || t < best_t) {
            best = vec4<f32>(mesh_atlas[q + 17u], mesh_atlas[q + 18u], mesh_atlas[q + 19u], 1.0);
            best_t = t;
        }
    }
    return best;
}
