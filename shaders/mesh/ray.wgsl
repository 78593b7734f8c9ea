// The first triangle of a mesh light a ray meets (DESIGN.md §7 M3 radiance), through its BVH in
// the scene's mesh atlas (layout: src/gpu/mesh_atlas.rs).
// Twin of src/cpu/mesh/ray.rs, which carries the citations (Möller & Trumbore 1997; Kay &
// Kajiya 1986) and the tie rule.
//
// f32: the nodes' boxes are rounded outward, so no box the f64 traversal enters is skipped;
//   a ray within ~1e-6 (relative) of a triangle's edge may hit or miss it differently from the
//   reference (the conformance tests exclude that band).
// f32: the traversal stack holds MESH_STACK nodes; prepare keeps meshes whose BVH is deeper on
//   the host (GpuPath::Host), so it never overflows.
// f32: each visited node and leaf triangle is one loop iteration; lavapipe stops an
//   invocation's loops after 65,535 iterations in all, which a BVH traversal stays far below
//   for the meshes the device holds (tests/mesh_lights.rs traverses a 72,200-triangle mesh).

// #import shared/record.wgsl

// A triangle (p0, p1 − p0, p2 − p0) at atlas word k: (t, 1 if the ray meets its front else 0);
// t = -1 when it misses or runs in its plane.
fn intersect_edges(k: u32, o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    let p0 = vec3<f32>(mesh_atlas[k], mesh_atlas[k + 1u], mesh_atlas[k + 2u]);
    let e1 = vec3<f32>(mesh_atlas[k + 3u], mesh_atlas[k + 4u], mesh_atlas[k + 5u]);
    let e2 = vec3<f32>(mesh_atlas[k + 6u], mesh_atlas[k + 7u], mesh_atlas[k + 8u]);
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return vec2<f32>(-1.0, 0.0);
    }
    let inv = 1.0 / det;
    let s = o - p0;
    let u = dot(s, pv) * inv;
    if !(u >= 0.0 && u <= 1.0) {
        return vec2<f32>(-1.0, 0.0);
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if !(v >= 0.0 && u + v <= 1.0) {
        return vec2<f32>(-1.0, 0.0);
    }
    let t = dot(e2, q) * inv;
    if !(t > 0.0) {
        return vec2<f32>(-1.0, 0.0);
    }
    // det = −d·(e1 × e2): positive when the ray runs against the front.
    return vec2<f32>(t, select(0.0, 1.0, det > 0.0));
}

// The slab test: the distance at which the ray enters the node's box at atlas word k (0 when
// it starts inside), or -1 when it misses it or enters it beyond t_max.
fn enter_box(k: u32, o: vec3<f32>, inv_d: vec3<f32>, t_max: f32) -> f32 {
    let lo = vec3<f32>(mesh_atlas[k], mesh_atlas[k + 1u], mesh_atlas[k + 2u]);
    let hi = vec3<f32>(mesh_atlas[k + 3u], mesh_atlas[k + 4u], mesh_atlas[k + 5u]);
    let t0 = (lo - o) * inv_d;
    let t1 = (hi - o) * inv_d;
    let tn = min(t0, t1);
    let tf = max(t0, t1);
    // A ray in a slab's plane (0 · ∞ = NaN) counts as inside that slab, as the CPU's min/max.
    let near = max(max(max(select(tn.x, 0.0, tn.x != tn.x), select(tn.y, 0.0, tn.y != tn.y)),
        select(tn.z, 0.0, tn.z != tn.z)), 0.0);
    let far = min(min(select(tf.x, 3.4e38, tf.x != tf.x), select(tf.y, 3.4e38, tf.y != tf.y)),
        select(tf.z, 3.4e38, tf.z != tf.z));
    if near <= far && near <= t_max {
        return near;
    }
    return -1.0;
}

// The first triangle of light's mesh the ray o + t·d, t > 0, meets: (t, 1 if met on its front
// else 0, 1 if found else 0). Children nearer first; each box tested once, with its parent.
fn first_hit(light: Record, o: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let nodes = light.tex.x;
    let tris = light.tex.z;
    if light.tex.y == 0u {
        return vec3<f32>(0.0);
    }
    let inv_d = 1.0 / d;
    var best_t = 3.4e38;
    var best_front = 0.0;
    var best_index = 0xffffffffu;
    var stack_node: array<u32, MESH_STACK>;
    var stack_t: array<f32, MESH_STACK>;
    var top = 0u;
    let root = enter_box(nodes, o, inv_d, best_t);
    if root < 0.0 {
        return vec3<f32>(0.0);
    }
    stack_node[0] = 0u;
    stack_t[0] = root;
    top = 1u;
    while top > 0u {
        top -= 1u;
        let k = stack_node[top];
        if stack_t[top] > best_t {
            continue;
        }
        let base = nodes + k * MESH_NODE_WORDS;
        let first = bitcast<u32>(mesh_atlas[base + 6u]);
        let count = bitcast<u32>(mesh_atlas[base + 7u]);
        if count == 0u {
            let left = k + 1u;
            let right = first;
            let tl = enter_box(nodes + left * MESH_NODE_WORDS, o, inv_d, best_t);
            let tr = enter_box(nodes + right * MESH_NODE_WORDS, o, inv_d, best_t);
            // Push the farther first, so the nearer is popped next.
            if tl >= 0.0 && tr >= 0.0 {
                if tl <= tr {
                    stack_node[top] = right;
                    stack_t[top] = tr;
                    stack_node[top + 1u] = left;
                    stack_t[top + 1u] = tl;
                } else {
                    stack_node[top] = left;
                    stack_t[top] = tl;
                    stack_node[top + 1u] = right;
                    stack_t[top + 1u] = tr;
                }
                top += 2u;
            } else if tl >= 0.0 {
                stack_node[top] = left;
                stack_t[top] = tl;
                top += 1u;
            } else if tr >= 0.0 {
                stack_node[top] = right;
                stack_t[top] = tr;
                top += 1u;
            }
            continue;
        }
        for (var j = first; j < first + count; j++) {
            let w = tris + j * MESH_TRIANGLE_WORDS;
            let hit = intersect_edges(w, o, d);
            let index = bitcast<u32>(mesh_atlas[w + 9u]);
            if hit.x > 0.0 && (hit.x < best_t || (hit.x == best_t && index < best_index)) {
                best_t = hit.x;
                best_front = hit.y;
                best_index = index;
            }
        }
    }
    if best_index == 0xffffffffu {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(best_t, best_front, 1.0);
}
