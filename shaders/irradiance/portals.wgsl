// The irradiance of a dome masked by portals (DESIGN.md §8 P2 mask mode) where the device sums
// it (prepare::portal::overlaps, prepare::gpu_path::masked): the sum over the portals x is on
// the −Z side of of the portal's multiplier times E on its parallelogram clipped at the
// horizon, and by inclusion–exclusion over the overlaps the mesh atlas lists after the
// portals, ± the multiplier of the one each names first times E on the first portal's
// parallelogram clipped to the cones from x over the others; a split overlap (portals of
// different multipliers crossed in either order) sums each member's multiplier times E on
// the piece where it is the farthest (farther_plane). E is Lambert's formula for a uniform
// dome and the texture's exact integral over the polygon for a textured latlong one
// (irradiance/latlong_polygon.wgsl). Twin of src/cpu/irradiance/portals.rs, which carries the
// proof; textured domes of other formats or non-conformal frames keep their irradiance on the
// host (GpuPath::HostIrradiance).
//
// f32: every polygon, a portal's parallelogram included, is a fan of triangles through
//   mesh/lambert.wgsl's triangle_lambert (with its sliver form for polygons low over the
//   horizon), as on the CPU (where each triangle is Lambert's formula on its corners).
// f32: the side test is the f32 sign of normal·(x − origin), as the radiance kernel's
//   (portal.wgsl); a receiver within ~1e-6 (relative) of a portal's plane may count it or not
//   differently from the reference, where the portal is seen edge-on (the conformance check
//   excludes that band, conformance::band::irradiance_margin).
// f32: clip_polygon writes at most PORTAL_OVERLAP_VERTICES vertices (gpu::mesh_atlas): a
//   convex polygon gains at most one a clip (4 + 4·3 for four portals, 3 more for a split
//   overlap's piece and one at the horizon for a textured dome), and a rounded one that would
//   gain more keeps the first ones (the CPU's Vec has no bound).
// f32: farther_plane is formed from the portal's f32 origin and normal; the plane is exact
//   (a member's piece ends where two portals are crossed at once), so a rounded one moves
//   that boundary by ~1e-7 relative, where either member's multiplier is right to that order.
// GPU-only PortalDome: the twin's Option<&TexturedDome>.
// GPU-only clip_polygon, parallelogram: the twin's closed::clip_above and corner list, on the
//   device's fixed-size polygon, which also carries each edge's plane.
// f32: a textured dome's polygon carries each edge's plane through x from the portal's edges
//   and the clip planes, where the CPU takes it from the cross product of the edge's ends: a
//   clip through (nearly) a vertex leaves an edge of ~1e-5 rad, whose ends' f32 cross product
//   has no direction (lavapipe: 3.9e-4 off on a triple overlap with such an edge).
// GPU-only portal_at, portal_multiplier, portal_seen, portal_corners: they read a portal's
//   words in the mesh atlas (the CPU reads PreparedPortal's fields).
// GPU-only portal_origin, portal_normal: the same, for farther_plane.
// f32: lavapipe stops an invocation's loops after 65,535 iterations in all: for a uniform dome
//   a portal costs at most ~34 (a parallelogram, two triangles), an overlap of two, three or
//   four at most 121, 238 or 387 (250, 675, 1,342 split: prepare::portal::overlap_iterations),
//   and prepare::portal::overlaps keeps a dome's overlaps within 49,000 (OVERLAP_ITERATIONS),
//   so up to ~1,900 portals without overlaps stay inside it; a textured dome's polygons cost
//   far more (latlong_polygon.wgsl). The term and piece loops, each clip's vertex loop and the
//   fan's check their own condition after they end and set irr_cut if they stopped short, and
//   the host recomputes that receiver (shared/record.wgsl).

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
// the overlaps after them whose every portal x is on the −Z side of, a split one's pieces
// each with its own (split_piece); E is Lambert's formula for a uniform dome, the texture's
// integral (latlong_polygon.wgsl) for a textured one. Every term's polygons go through the
// one call of polygon_value, so that the texture's integral is inlined once (each call site
// of a function is a copy of it after inlining: with three, lavapipe took 108 s and 1.2 GB to
// compile the textured kernel, against 44 s and 0.7 GB with two).
fn portals_irradiance(at: u32, x: vec3<f32>, n: vec3<f32>, dome: PortalDome) -> vec3<f32> {
    let count = bitcast<u32>(mesh_atlas[at]);
    // The overlaps follow the last portal.
    let sets_at = portal_at(at, count);
    let sets = bitcast<u32>(mesh_atlas[sets_at]);
    var sum = vec3<f32>(0.0);
    var t = 0u;
    for (; t < count + sets; t++) {
        // The term's polygon, sign and multiplier, and for a split overlap its pieces.
        var poly: OverlapPolygon;
        var sign = 1.0;
        var m: vec3<f32>;
        var pieces = 1u;
        var o = 0u;
        var size = 0u;
        var split = 0u;
        if t < count {
            let q = portal_at(at, t);
            if !portal_seen(q, x) {
                continue;
            }
            poly = parallelogram(portal_corners(q, x));
            m = portal_multiplier(q);
        } else {
            o = sets_at + 1u + (t - count) * PORTAL_OVERLAP_WORDS;
            var all_seen = true;
            var j = 0u;
            for (; j < PORTAL_OVERLAP_MEMBERS; j++) {
                let member = bitcast<u32>(mesh_atlas[o + j]);
                if member == 0xffffffffu {
                    break;
                }
                size += 1u;
                all_seen = all_seen && portal_seen(portal_at(at, member), x);
            }
            if j < PORTAL_OVERLAP_MEMBERS && bitcast<u32>(mesh_atlas[o + j]) != 0xffffffffu {
                irr_cut = true;
            }
            if !all_seen {
                continue;
            }
            poly = overlap_polygon(at, o, size, x);
            if poly.count < 3u {
                continue;
            }
            sign = select(1.0, -1.0, size % 2u == 0u);
            m = portal_multiplier(portal_at(at, bitcast<u32>(mesh_atlas[o])));
            split = bitcast<u32>(mesh_atlas[o + PORTAL_OVERLAP_MEMBERS]);
            if (split & PORTAL_OVERLAP_SPLIT) != 0u {
                pieces = size;
            }
        }
        var l = 0u;
        for (; l < pieces; l++) {
            var piece = poly;
            if pieces > 1u {
                piece = split_piece(at, o, size, split, poly, l, x);
                m = portal_multiplier(portal_at(at, bitcast<u32>(mesh_atlas[o + l])));
            }
            if piece.count >= 3u {
                sum += sign * m * polygon_value(piece, n, dome);
            }
        }
        if l < pieces {
            irr_cut = true;
        }
    }
    if t < count + sets {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}

// What x sees through each of the `size` portals listed at `o`: the first one's
// parallelogram clipped to the cones over the others (count < 3 where nothing).
fn overlap_polygon(at: u32, o: u32, size: u32, x: vec3<f32>) -> OverlapPolygon {
    let first = portal_corners(portal_at(at, bitcast<u32>(mesh_atlas[o])), x);
    var poly = parallelogram(first);
    var j = 1u;
    for (; j < size; j++) {
        let cone = portal_corners(portal_at(at, bitcast<u32>(mesh_atlas[o + j])), x);
        poly = clip_to_cone(poly, cone);
        if poly.count < 3u {
            return poly;
        }
    }
    if j < size {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return poly;
}

// The piece of a split overlap's polygon `poly` where its member l is the farthest: clipped
// by farther_plane against each other member that rays cross in either order with it (bit
// 4i + j of `split`: member i lies before member j on every ray through both; count 0 where
// some member always lies after l).
fn split_piece(at: u32, o: u32, size: u32, split: u32, poly: OverlapPolygon, l: u32, x: vec3<f32>) -> OverlapPolygon {
    var piece = poly;
    let ql = portal_at(at, bitcast<u32>(mesh_atlas[o + l]));
    var z = 0u;
    for (; z < size; z++) {
        if z == l || ((split >> (4u * z + l)) & 1u) == 1u {
            continue;
        }
        if ((split >> (4u * l + z)) & 1u) == 1u {
            piece.count = 0u;
            return piece;
        }
        let qz = portal_at(at, bitcast<u32>(mesh_atlas[o + z]));
        piece = clip_polygon(piece, farther_plane(ql, qz, x));
    }
    if z < size {
        irr_cut = true;
    }
    return piece;
}

// The normal of the plane through x on whose positive side a ray crosses the portal at qz
// before the one at ql (both toward +Z, x on both −Z sides): d_l N_z − d_z N_l with
// d = N·(O − x).
fn farther_plane(ql: u32, qz: u32, x: vec3<f32>) -> vec3<f32> {
    let nl = portal_normal(ql);
    let nz = portal_normal(qz);
    return dot(nl, portal_origin(ql) - x) * nz - dot(nz, portal_origin(qz) - x) * nl;
}

// E on the convex polygon `poly` (vectors from x): 0 where no vertex is above the horizon,
// else a fan of Lambert's triangles from its first vertex or the texture's integral.
fn polygon_value(poly: OverlapPolygon, n: vec3<f32>, dome: PortalDome) -> vec3<f32> {
    var above = false;
    var v = 0u;
    for (; v < poly.count; v++) {
        above = above || dot(n, poly.p[v]) > 0.0;
    }
    if v < poly.count {
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

// The origin and the unit normal of the portal whose words start at q.
fn portal_origin(q: u32) -> vec3<f32> {
    return vec3<f32>(mesh_atlas[q], mesh_atlas[q + 1u], mesh_atlas[q + 2u]);
}

fn portal_normal(q: u32) -> vec3<f32> {
    return vec3<f32>(mesh_atlas[q + 3u], mesh_atlas[q + 4u], mesh_atlas[q + 5u]);
}

// Whether x is on the −Z side of the portal whose words start at q.
fn portal_seen(q: u32, x: vec3<f32>) -> bool {
    return dot(portal_normal(q), x - portal_origin(q)) < 0.0;
}

// The corners of the portal whose words start at q, as vectors from x: c0, c0 + e1,
// c0 + e1 + e3, c0 + e3.
fn portal_corners(q: u32, x: vec3<f32>) -> array<vec3<f32>, 4> {
    let q0 = vec3<f32>(mesh_atlas[q + 20u], mesh_atlas[q + 21u], mesh_atlas[q + 22u]) - x;
    let e1 = vec3<f32>(mesh_atlas[q + 23u], mesh_atlas[q + 24u], mesh_atlas[q + 25u]);
    let e3 = vec3<f32>(mesh_atlas[q + 26u], mesh_atlas[q + 27u], mesh_atlas[q + 28u]);
    return array<vec3<f32>, 4>(q0, q0 + e1, q0 + e1 + e3, q0 + e3);
}
