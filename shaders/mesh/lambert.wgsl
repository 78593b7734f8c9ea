// The irradiance of a mesh light whose triangles cannot hide one another (prepare::mesh_class:
// planar without overlap, one-sided closed convex; GpuPath::HostIntensityOnly): Lambert's
// formula clipped at the horizon, summed over the triangles whose emitting side faces x, read
// from the mesh atlas (layout: src/gpu/mesh_atlas.rs) in the leaves' order.
// Twin of src/cpu/mesh/lambert.rs, which carries the proof that the sum is exact and the
// citations.
//
// f32: triangle_lambert is the CPU's triangle_lambert and polygon_irradiance in one function,
//   as closed.wgsl's rect_lambert; the edge-on test is c == 0 (the CPU: |c| ≤ 1e-12 of the
//   farthest vertex), a triangle that nearly contains x subtending nearly nothing on both.
// f32: one loop iteration a triangle, at most MESH_TRIANGLES_SUMMED (4096) of them: far inside
//   lavapipe's 65,535 iterations per invocation.

// #import shared/record.wgsl
// #import shared/math.wgsl

// Unit-radiance irradiance of the triangle q0 q1 q2 (vectors from x) clipped to n·ω ≥ 0.
fn triangle_lambert(q0: vec3<f32>, q1: vec3<f32>, q2: vec3<f32>, n: vec3<f32>) -> f32 {
    let q = array<vec3<f32>, 3>(q0, q1, q2);
    let sigma = sign(dot(cross(q1 - q0, q2 - q1), q0));
    var clipped: array<vec3<f32>, 4>;
    var count = 0u;
    for (var i = 0u; i < 3u; i++) {
        let p0 = q[i];
        let p1 = q[(i + 1u) % 3u];
        let d0 = dot(n, p0);
        let d1 = dot(n, p1);
        if d0 >= 0.0 {
            clipped[count] = p0;
            count += 1u;
        }
        if (d0 >= 0.0) != (d1 >= 0.0) {
            clipped[count] = p0 + (p1 - p0) * (d0 / (d0 - d1));
            count += 1u;
        }
    }
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        let p0 = clipped[i];
        let p1 = clipped[(i + 1u) % count];
        let c = cross(p0, p1);
        let len = length(c);
        if len > 0.0 {
            sum += atan2_accurate(len, dot(p0, p1)) * dot(n, c) / len;
        }
    }
    return max(0.5 * sigma * sum, 0.0);
}

// Unit-radiance irradiance at x of the mesh light's light.size.x triangles at atlas word
// light.tex.z: the triangles whose emitting side (the front, or either when double-sided) faces
// x and that reach above the horizon.
fn mesh_lambert(light: Record, x: vec3<f32>, n: vec3<f32>) -> f32 {
    let count = u32(light.size.x);
    let double_sided = has_flag(light, FLAG_DOUBLE_SIDED);
    var sum = 0.0;
    for (var t = 0u; t < count; t++) {
        let k = light.tex.z + t * MESH_TRIANGLE_WORDS;
        let q0 = vec3<f32>(mesh_atlas[k], mesh_atlas[k + 1u], mesh_atlas[k + 2u]) - x;
        let e1 = vec3<f32>(mesh_atlas[k + 3u], mesh_atlas[k + 4u], mesh_atlas[k + 5u]);
        let e2 = vec3<f32>(mesh_atlas[k + 6u], mesh_atlas[k + 7u], mesh_atlas[k + 8u]);
        let q1 = q0 + e1;
        let q2 = q0 + e2;
        let c = dot(cross(e1, e2), q0);
        let facing = c < 0.0 || (double_sided && c != 0.0);
        let above = max(max(dot(n, q0), dot(n, q1)), dot(n, q2)) > 0.0;
        if facing && above {
            sum += triangle_lambert(q0, q1, q2, n);
        }
    }
    return sum;
}
