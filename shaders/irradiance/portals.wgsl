// The irradiance of a dome masked by portals (DESIGN.md §8 P2 mask mode) where the device sums
// it (prepare::portal::overlaps, prepare::gpu_path::masked): the sum over the portals x is on
// the −Z side of of the portal's multiplier times E on its parallelogram clipped at the
// horizon, and by inclusion–exclusion over the overlaps the mesh atlas lists after the
// portals, ± the multiplier of the one each names first times E on the first portal's
// parallelogram clipped to the cones from x over the others. E is Lambert's formula for a
// uniform dome and the texture's exact integral over the polygon for a textured latlong one
// (irradiance/latlong_polygon.wgsl). Twin of src/cpu/irradiance/portals.rs, which carries the
// proof; portals of different multipliers that rays cross in either order, and textured
// domes of other formats or non-conformal frames, keep their irradiance on the host
// (GpuPath::HostIrradiance).
//
// f32: the parallelogram is two triangles through mesh/lambert.wgsl's triangle_lambert (with
//   its sliver form for portals low over the horizon); the CPU takes Lambert's formula on the
//   four corners (the shared diagonal's terms cancel in exact arithmetic). An overlap's
//   polygon is a fan of triangles on both.
// f32: the side test is the f32 sign of normal·(x − origin), as the radiance kernel's
//   (portal.wgsl); a receiver within ~1e-6 (relative) of a portal's plane may count it or not
//   differently from the reference, where the portal is seen edge-on (the conformance check
//   excludes that band, conformance::band::irradiance_margin).
// f32: clip_polygon writes at most PORTAL_OVERLAP_VERTICES vertices (gpu::mesh_atlas): a
//   convex polygon gains at most one a clip (4 + 4·3 for four portals, and one more at the
//   horizon for a textured dome), and a rounded one that would gain more keeps the first ones
//   (the CPU's Vec has no bound).
// GPU-only PortalDome: the twin's Option<&TexturedDome>.
// GPU-only clip_polygon, parallelogram: the twin's closed::clip_above and corner list, on the
//   device's fixed-size polygon, which also carries each edge's plane.
// f32: a textured dome's polygon carries each edge's plane through x from the portal's edges
//   and the clip planes, where the CPU takes it from the cross product of the edge's ends: a
//   clip through (nearly) a vertex leaves an edge of ~1e-5 rad, whose ends' f32 cross product
//   has no direction (lavapipe: 3.9e-4 off on a triple overlap with such an edge).
// GPU-only portal_at, portal_multiplier, portal_seen, portal_corners: they read a portal's
//   words in the mesh atlas (the CPU reads PreparedPortal's fields).
// f32: lavapipe stops an invocation's loops after 65,535 iterations in all: for a uniform dome
//   a portal costs at most ~25 (two triangles), an overlap of two, three or four at most 120,
//   237 or 386, and prepare::portal::overlaps keeps a dome's overlaps within 48,000
//   (OVERLAP_ITERATIONS), so up to ~2,600 portals without overlaps stay inside it; a textured
//   dome's polygons cost far more (latlong_polygon.wgsl). The portal and overlap loops, each
//   clip's vertex loop and the fan's check their own condition after they end and set irr_cut
//   if they stopped short, and the host recomputes that receiver (shared/record.wgsl).

// #import shared/record.wgsl
// #import mesh/lambert.wgsl
// #import irradiance/latlong_rows.wgsl
// #import irradiance/latlong_polygon.wgsl

// A convex polygon (vectors from x) of `count` vertices, and the inward normal of the plane
// through x and each edge p[i] → p[i + 1] (carried through the clips: see the header).
struct OverlapPolygon {
    p: array<vec3<f32>, PORTAL_OVERLAP_VERTICES>,
    k: array<vec3<f32>, PORTAL_OVERLAP_VERTICES>,
    count: u32,
}

// The masked dome's texture where the kernel integrates it: its row tables' offset in the
// texture atlas and its world → dome map A_eff⁻¹ (textured: false for a uniform dome).
struct PortalDome {
    textured: bool,
    rows: u32,
    inv: mat3x3<f32>,
}

// Σ multiplier · E(portal clipped at n·ω ≥ 0) over the portals at `at` in the mesh atlas
// (layout: src/gpu/mesh_atlas.rs) whose −Z side x is on, and ± multiplier · E(overlap) over
// the overlaps after them whose every portal x is on the −Z side of; E is Lambert's formula
// for a uniform dome, the texture's integral (latlong_polygon.wgsl) for a textured one.
fn portals_irradiance(at: u32, x: vec3<f32>, n: vec3<f32>, dome: PortalDome) -> vec3<f32> {
    let count = bitcast<u32>(mesh_atlas[at]);
    var sum = vec3<f32>(0.0);
    var k = 0u;
    for (; k < count; k++) {
        let q = portal_at(at, k);
        if !portal_seen(q, x) {
            continue;
        }
        let c = portal_corners(q, x);
        let above = max(max(dot(n, c[0]), dot(n, c[1])), max(dot(n, c[2]), dot(n, c[3]))) > 0.0;
        if above {
            sum += portal_multiplier(q) * portal_value(c, n, dome);
        }
    }
    if k < count {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    // The overlaps follow the last portal.
    let sets_at = portal_at(at, count);
    let sets = bitcast<u32>(mesh_atlas[sets_at]);
    var s = 0u;
    for (; s < sets; s++) {
        let o = sets_at + 1u + s * PORTAL_OVERLAP_WORDS;
        var size = 0u;
        var all_seen = true;
        var j = 0u;
        for (; j < PORTAL_OVERLAP_WORDS; j++) {
            let member = bitcast<u32>(mesh_atlas[o + j]);
            if member == 0xffffffffu {
                break;
            }
            size += 1u;
            all_seen = all_seen && portal_seen(portal_at(at, member), x);
        }
        if j < PORTAL_OVERLAP_WORDS && bitcast<u32>(mesh_atlas[o + j]) != 0xffffffffu {
            irr_cut = true;
        }
        if all_seen {
            let m = portal_multiplier(portal_at(at, bitcast<u32>(mesh_atlas[o])));
            let sign = select(1.0, -1.0, size % 2u == 0u);
            sum += sign * m * overlap_value(at, o, size, x, n, dome);
        }
    }
    if s < sets {
        irr_cut = true;
    }
    return sum;
}

// E on one portal's parallelogram (corners c, vectors from x): two triangles through Lambert's
// formula, or the texture's integral.
fn portal_value(c: array<vec3<f32>, 4>, n: vec3<f32>, dome: PortalDome) -> vec3<f32> {
    if dome.textured {
        return polygon_texture(parallelogram(c), n, dome);
    }
    return vec3<f32>(triangle_lambert(c[0], c[1], c[2], n) + triangle_lambert(c[0], c[2], c[3], n));
}

// E on what x sees through each of the `size` portals listed at `o`: the first one's
// parallelogram clipped to the cones over the others, as a fan of Lambert's triangles or
// through the texture's integral.
fn overlap_value(at: u32, o: u32, size: u32, x: vec3<f32>, n: vec3<f32>, dome: PortalDome) -> vec3<f32> {
    let first = portal_corners(portal_at(at, bitcast<u32>(mesh_atlas[o])), x);
    var poly = parallelogram(first);
    var j = 1u;
    for (; j < size; j++) {
        let cone = portal_corners(portal_at(at, bitcast<u32>(mesh_atlas[o + j])), x);
        poly = clip_to_cone(poly, cone);
        if poly.count < 3u {
            return vec3<f32>(0.0);
        }
    }
    var above = false;
    var v = 0u;
    for (; v < poly.count; v++) {
        above = above || dot(n, poly.p[v]) > 0.0;
    }
    if j < size || v < poly.count {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    if !above {
        return vec3<f32>(0.0);
    }
    if dome.textured {
        return polygon_texture(poly, n, dome);
    }
    var sum = 0.0;
    var i = 1u;
    for (; i + 1u < poly.count; i++) {
        sum += triangle_lambert(poly.p[0], poly.p[i], poly.p[i + 1u], n);
    }
    if i + 1u < poly.count {
        irr_cut = true;
    }
    return vec3<f32>(sum);
}

// The part of `poly` inside the cone from x over the convex quadrilateral `cone` (vectors from
// x): clipped to k·v ≥ 0 for each edge's plane through x, k toward the other corners.
fn clip_to_cone(poly: OverlapPolygon, cone: array<vec3<f32>, 4>) -> OverlapPolygon {
    var cur = poly;
    var e = 0u;
    for (; e < 4u; e++) {
        var k = cross(cone[e], cone[(e + 1u) % 4u]);
        if dot(k, cone[(e + 2u) % 4u]) < 0.0 {
            k = -k;
        }
        cur = clip_polygon(cur, k);
    }
    if e < 4u {
        irr_cut = true;
    }
    return cur;
}

// The texture's integral over the convex polygon `poly` (vectors from x) clipped at the
// horizon n·ω ≥ 0 and mapped to dome space (latlong_rows.wgsl's frame: conformal, so the
// dome-space polygon is the image's and the normal A_eff⁻¹ n normalised).
fn polygon_texture(poly: OverlapPolygon, n: vec3<f32>, dome: PortalDome) -> vec3<f32> {
    var e = vec3<f32>(0.0);
    // #if TEXTURE
    var d = clip_polygon(poly, n);
    var i = 0u;
    for (; i < d.count; i++) {
        d.p[i] = dome.inv * d.p[i];
        d.k[i] = dome.inv * d.k[i];
    }
    if i < d.count {
        irr_cut = true;
    }
    if d.count >= 3u {
        e = latlong_polygon(rows_info(dome.rows), d, normalize(dome.inv * n));
    }
    // #endif
    return e;
}

// `poly` clipped to k·v ≥ 0 (Sutherland–Hodgman; the twin's closed::clip_above), each edge
// keeping its plane: a kept vertex and a point where the boundary comes back in start edges
// along their input edge's plane, a point where it leaves starts one along k.
fn clip_polygon(poly: OverlapPolygon, k: vec3<f32>) -> OverlapPolygon {
    var out: OverlapPolygon;
    out.count = 0u;
    var i = 0u;
    for (; i < poly.count; i++) {
        let p0 = poly.p[i];
        let p1 = poly.p[(i + 1u) % poly.count];
        let d0 = dot(k, p0);
        let d1 = dot(k, p1);
        if d0 >= 0.0 && out.count < PORTAL_OVERLAP_VERTICES {
            out.p[out.count] = p0;
            out.k[out.count] = poly.k[i];
            out.count += 1u;
        }
        if (d0 >= 0.0) != (d1 >= 0.0) && out.count < PORTAL_OVERLAP_VERTICES {
            out.p[out.count] = p0 + (p1 - p0) * (d0 / (d0 - d1));
            out.k[out.count] = select(poly.k[i], k, d0 >= 0.0);
            out.count += 1u;
        }
    }
    if i < poly.count {
        // Cut short by the device's loop budget: so is the polygon.
        irr_cut = true;
    }
    return out;
}

// The parallelogram with corners c (vectors from x) and its edges' inward planes through x.
fn parallelogram(c: array<vec3<f32>, 4>) -> OverlapPolygon {
    var poly: OverlapPolygon;
    poly.count = 4u;
    var e = 0u;
    for (; e < 4u; e++) {
        var k = cross(c[e], c[(e + 1u) % 4u]);
        if dot(k, c[(e + 2u) % 4u]) < 0.0 {
            k = -k;
        }
        poly.p[e] = c[e];
        poly.k[e] = k;
    }
    if e < 4u {
        irr_cut = true;
    }
    return poly;
}

// Where the words of portal k of the block at `at` start.
fn portal_at(at: u32, k: u32) -> u32 {
    return at + 1u + k * PORTAL_WORDS;
}

// The multiplier of the portal whose words start at q.
fn portal_multiplier(q: u32) -> vec3<f32> {
    return vec3<f32>(mesh_atlas[q + 17u], mesh_atlas[q + 18u], mesh_atlas[q + 19u]);
}

// Whether x is on the −Z side of the portal whose words start at q.
fn portal_seen(q: u32, x: vec3<f32>) -> bool {
    let origin = vec3<f32>(mesh_atlas[q], mesh_atlas[q + 1u], mesh_atlas[q + 2u]);
    let normal = vec3<f32>(mesh_atlas[q + 3u], mesh_atlas[q + 4u], mesh_atlas[q + 5u]);
    return dot(normal, x - origin) < 0.0;
}

// The corners of the portal whose words start at q, as vectors from x: c0, c0 + e1,
// c0 + e1 + e3, c0 + e3.
fn portal_corners(q: u32, x: vec3<f32>) -> array<vec3<f32>, 4> {
    let q0 = vec3<f32>(mesh_atlas[q + 20u], mesh_atlas[q + 21u], mesh_atlas[q + 22u]) - x;
    let e1 = vec3<f32>(mesh_atlas[q + 23u], mesh_atlas[q + 24u], mesh_atlas[q + 25u]);
    let e3 = vec3<f32>(mesh_atlas[q + 26u], mesh_atlas[q + 27u], mesh_atlas[q + 28u]);
    return array<vec3<f32>, 4>(q0, q0 + e1, q0 + e1 + e3, q0 + e3);
}
