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
// f32: a triangle low over the horizon (every arc of its clipped polygon below SLIVER_SIN in
//   elevation) is integrated over azimuth instead (sliver_lambert): Lambert's edge terms are
//   then ~ the arcs' lengths and cancel to ~ their elevation², which cost 2e-4 relative on
//   lavapipe (a box whose top corner rose 0.03 rad above the horizon, a flat hexagon seen
//   0.015 rad above it);
//   ∮ ½ sin²(elevation) dφ along the boundary (Green's theorem in azimuth and elevation) has
//   terms ~ elevation² · azimuth, each arc by 8-point Gauss–Legendre in two halves (the
//   integrand is analytic, its poles several half-widths away for arcs that low; f64 replay
//   of the rule: ~1e-14 relative on the slivers of tests/mesh_irradiance_gpu.rs).
// GPU-only arc_node, arc_half, sliver_lambert: see above.
// f32: lavapipe stops an invocation's loops after 65,535 iterations in all: a triangle costs
//   at most 12 (one in mesh_lambert, 3 clipping, 4 Lambert edges, 4 sliver arcs; the
//   quadrature is written out), so at most MESH_TRIANGLES_SUMMED (4096) triangles stay inside
//   it (49,152) for one such mesh per dispatch group; the triangle loop still checks its own
//   condition after it ends and sets irr_cut if it stopped short (shared/record.wgsl).

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import irradiance/closed.wgsl

// The sine of the highest elevation of a clipped arc for which sliver_lambert is used.
const SLIVER_SIN: f32 = 0.3;

// Unit-radiance irradiance of the triangle q0 q1 q2 (vectors from x) clipped to n·ω ≥ 0.
fn triangle_lambert(q0: vec3<f32>, q1: vec3<f32>, q2: vec3<f32>, n: vec3<f32>) -> f32 {
    let sigma = sign(dot(cross(q1 - q0, q2 - q1), q0));
    // The last entry is unused (3 vertices).
    let cp = clip_above(array<vec3<f32>, 4>(q0, q1, q2, q0), 3u, n);
    let count = cp.count;
    let clipped = cp.p;
    var sum = 0.0;
    // Every arc low: the sliver form (see the header).
    var low = true;
    for (var i = 0u; i < count; i++) {
        let p0 = clipped[i];
        let p1 = clipped[(i + 1u) % count];
        let c = cross(p0, p1);
        let len = length(c);
        if len > 0.0 {
            sum += atan2_accurate(len, dot(p0, p1)) * dot(n, c) / len;
            // The arc's highest point: an end, or the top of its great circle where that lies
            // between the ends.
            let m = c / len;
            let u0 = normalize(p0);
            let u1 = normalize(p1);
            var top = max(dot(n, u0), dot(n, u1));
            let peak = n - dot(n, m) * m;
            if dot(cross(u0, peak), m) >= 0.0 && dot(cross(peak, u1), m) >= 0.0 {
                top = max(top, length(peak));
            }
            low = low && top <= SLIVER_SIN;
        }
    }
    if low && count >= 3u {
        return sliver_lambert(clipped, count, n);
    }
    return max(0.5 * sigma * sum, 0.0);
}

// One Gauss–Legendre node of arc_half: weight w at h0 + s·dh (not normalised: |v|² is the
// Jacobian of the azimuth in s): (m·ĥ)² / ((m·ĥ)² + (m·n)²) / |v|², with sin² e of the great
// circle with pole m at the horizontal direction ĥ being that ratio.
fn arc_node(m: vec3<f32>, mn: f32, h0: vec3<f32>, dh: vec3<f32>, s: f32, w: f32) -> f32 {
    let v = h0 + s * dh;
    let vv = dot(v, v);
    let mv = dot(m, v);
    let mh2 = mv * mv / vv;
    let d = mh2 + mn * mn;
    return select(0.0, w * mh2 / (d * vv), d > 0.0 && vv > 0.0);
}

// ∫ ½ sin²(elevation) dφ along the great circle with unit pole m between the horizontal unit
// directions h0 and h1 (less than π/2 apart): with v(s) = h0 + s (h1 − h0), dφ = n·(h0 × h1)
// / |v|² ds; 8-point Gauss–Legendre in s on [0, 1], written out (no loop: lavapipe's
// iteration budget, see the header). No trigonometric builtin: lavapipe's sin, cos and atan2
// err by ~1e-6, which cost 1e-4 on slivers 0.01 rad wide.
fn arc_half(m: vec3<f32>, n: vec3<f32>, h0: vec3<f32>, h1: vec3<f32>) -> f32 {
    let mn = dot(m, n);
    let dh = h1 - h0;
    let a = 0.5 * (1.0 - 0.9602898564975363);
    let b = 0.5 * (1.0 - 0.7966664774136267);
    let c = 0.5 * (1.0 - 0.5255324099163290);
    let d = 0.5 * (1.0 - 0.1834346424956498);
    let wa = 0.1012285362903763;
    let wb = 0.2223810344533745;
    let wc = 0.3137066458778873;
    let wd = 0.3626837833783620;
    let sum = arc_node(m, mn, h0, dh, a, wa) + arc_node(m, mn, h0, dh, 1.0 - a, wa)
        + arc_node(m, mn, h0, dh, b, wb) + arc_node(m, mn, h0, dh, 1.0 - b, wb)
        + arc_node(m, mn, h0, dh, c, wc) + arc_node(m, mn, h0, dh, 1.0 - c, wc)
        + arc_node(m, mn, h0, dh, d, wd) + arc_node(m, mn, h0, dh, 1.0 - d, wd);
    // ½ for sin², ½ for the rule's interval.
    return 0.25 * dot(n, cross(h0, h1)) * sum;
}

// The clipped polygon's cosine-weighted solid angle as ∮ ½ sin²(elevation) dφ over its
// boundary: |Σ| when the zenith is outside (the azimuth turns by 0 around it), π − |Σ| when it
// is inside (by ±2π). Each arc is integrated in two halves, split at its ends' mean
// horizontal direction.
fn sliver_lambert(clipped: array<vec3<f32>, 6>, count: u32, n: vec3<f32>) -> f32 {
    var sum = 0.0;
    var turn = 0.0;
    for (var i = 0u; i < count; i++) {
        let p0 = clipped[i];
        let p1 = clipped[(i + 1u) % count];
        let c = cross(p0, p1);
        let len = length(c);
        let h0 = normalize(p0 - dot(n, p0) * n);
        let h1 = normalize(p1 - dot(n, p1) * n);
        turn += atan2_accurate(dot(n, cross(h0, h1)), dot(h0, h1));
        let mid = h0 + h1;
        let ml = length(mid);
        if len > 0.0 && ml > 1e-6 {
            let m = c / len;
            let hm = mid / ml;
            sum += arc_half(m, n, h0, hm) + arc_half(m, n, hm, h1);
        }
    }
    if abs(turn) > PI {
        return max(PI - abs(sum), 0.0);
    }
    return abs(sum);
}

// Unit-radiance irradiance at x of the mesh light's light.size.x triangles at atlas word
// light.tex.z: the triangles whose emitting side (the front, or either when double-sided) faces
// x and that reach above the horizon.
fn mesh_lambert(light: Record, x: vec3<f32>, n: vec3<f32>) -> f32 {
    let count = u32(light.size.x);
    let double_sided = has_flag(light, FLAG_DOUBLE_SIDED);
    var sum = 0.0;
    {
        var t = 0u;
        for (; t < count; t++) {
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
        if t < count {
            // Cut short by the device's loop budget (see irr_cut).
            irr_cut = true;
        }
    }
    return sum;
}
