// The irradiance of an untextured dome masked by portals that cannot hide one another
// (DESIGN.md §8 P2 mask mode; prepare::portal::cannot_hide_one_another): the dome's radiance is
// uniform and a ray passes through at most one portal, so the irradiance is the sum over the
// portals x is on the −Z side of of the portal's multiplier times Lambert's formula on its
// parallelogram clipped at the horizon. Twin of src/cpu/irradiance/portals.rs, which carries
// the proof; a textured dome, or portals that may hide one another, keep their irradiance on
// the host (GpuPath::HostIrradiance).
//
// f32: the parallelogram is two triangles through mesh/lambert.wgsl's triangle_lambert (with
//   its sliver form for portals low over the horizon); the CPU takes Lambert's formula on the
//   four corners (the shared diagonal's terms cancel in exact arithmetic).
// f32: the side test is the f32 sign of normal·(x − origin), as the radiance kernel's
//   (portal.wgsl); a receiver within ~1e-6 (relative) of a portal's plane may count it or not
//   differently from the reference, where the portal is seen edge-on (the conformance check
//   excludes that band, conformance::band::irradiance_margin).
// f32: lavapipe stops an invocation's loops after 65,535 iterations in all: a portal costs at
//   most ~25 (two triangles), so up to ~2,600 portals stay inside it; the portal loop checks its
//   own condition after it ends and sets irr_cut if it stopped short, and the host recomputes
//   that receiver (shared/record.wgsl).

// #import shared/record.wgsl
// #import mesh/lambert.wgsl

// Σ multiplier · Lambert(portal clipped at n·ω ≥ 0) over the portals at `at` in the mesh atlas
// (layout: src/gpu/mesh_atlas.rs) whose −Z side x is on.
fn portals_lambert(at: u32, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let count = bitcast<u32>(mesh_atlas[at]);
    var sum = vec3<f32>(0.0);
    var k = 0u;
    for (; k < count; k++) {
        let q = at + 1u + k * PORTAL_WORDS;
        let origin = vec3<f32>(mesh_atlas[q], mesh_atlas[q + 1u], mesh_atlas[q + 2u]);
        let normal = vec3<f32>(mesh_atlas[q + 3u], mesh_atlas[q + 4u], mesh_atlas[q + 5u]);
        if !(dot(normal, x - origin) < 0.0) {
            continue;
        }
        let q0 = vec3<f32>(mesh_atlas[q + 20u], mesh_atlas[q + 21u], mesh_atlas[q + 22u]) - x;
        let e1 = vec3<f32>(mesh_atlas[q + 23u], mesh_atlas[q + 24u], mesh_atlas[q + 25u]);
        let e3 = vec3<f32>(mesh_atlas[q + 26u], mesh_atlas[q + 27u], mesh_atlas[q + 28u]);
        let q1 = q0 + e1;
        let q3 = q0 + e3;
        let q2 = q1 + e3;
        let above = max(max(dot(n, q0), dot(n, q1)), max(dot(n, q2), dot(n, q3))) > 0.0;
        if above {
            let m = vec3<f32>(mesh_atlas[q + 17u], mesh_atlas[q + 18u], mesh_atlas[q + 19u]);
            sum += m * (triangle_lambert(q0, q1, q2, n) + triangle_lambert(q0, q2, q3, n));
        }
    }
    if k < count {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}
