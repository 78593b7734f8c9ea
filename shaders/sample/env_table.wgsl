// A textured dome's sampling table on the GPU (f32): the texel geometry of DESIGN.md §9 S2
// "dome" that the sampler draws in. Twin of src/prepare/env_table.rs, which carries the charts,
// their densities and Jacobians with their sources (§6 D2–D5).
//
// The table lives in the texture atlas (binding 6) at the offset in the dome's record
// (`tex.z`), packed by gpu::texture_atlas::env_table_words: a header (size, format, tiles,
// |det A|, A_eff), per texel (keep threshold, alias, pmf), per tile (W_t, cap centre, cos r,
// sin r, inner table offset) and the tiles' inner tables (keep threshold, local alias). The
// table and its size are the file's even where the GPU holds the texture reduced.
//
// Deliberate f32 divergences from the f64 twin, and why:
// 1. Chart points and directions are f32 (a texel's pixel coordinates carry W·2⁻²⁴ px). The
//    latlong and angular inverse maps use sin/cos (WGSL bounds them loosely, but the samplers
//    of cone.wgsl and dome.wgsl already do; the forward maps of shared/texture.wgsl, which the
//    pdf reads, stay trig-free). sin(πr) is taken as sin(π(1 − r)) past r = ½, as the twin does.
// 2. The cross face of a texel is found by a walk over §6 D5's six blocks (CROSS_FACE_TABLE)
//    instead of the twin's block → face array.
// 3. The tiles' functions (tile_of, texel_of, cos_bound, the receiver's loops) and the alias
//    pick are here, not in files of their own: they read this table's layout.
// GPU-only EnvInfo, env_info: the table's header (the twin's struct fields).
// GPU-only tile_of, texel_of, cos_bound: twins of src/prepare/env_table/tiles.rs's.
// GPU-only tile_texels: a tile's texel count (the twin's inner table knows its length).
// GPU-only fixed48, add64, shr24, fixed_value: 64-bit integers as (high, low) u32 words.
// GPU-only tile_weight, receiver_total, tile_pmf, tile_pick: EnvTable::receiver_tiles, ReceiverTiles::new, pmf and pick (tiles.rs) without
//   a table: a tile's weight is recomputed per receiver in a loop over the tiles (at most
//   MAX_TILES, twice per draw: lavapipe ends an invocation's loops after 65,535 iterations).
//   The weights are f32 (the twin's f64), then, as in the twin, 48-bit fixed point, summed and
//   inverted in exact integer arithmetic on (high, low) u32 words: the two running sums differ
//   only by the weights' own rounding, never by a float sum's (and no compensated float sum,
//   which Mesa's NIR may reassociate, is needed).
// GPU-only mul_wide, cell53, alias_pick: AliasTable::pick (src/prepare/alias.rs) on the two
//   32-bit words of the 53-bit uniform: the cell ⌊X·n/2⁵³⌋ in exact integer arithmetic and the
//   coin against the integer keep threshold, so the GPU names the very texel the CPU names.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import shared/texture.wgsl

struct EnvInfo {
    base: u32,
    width: u32,
    height: u32,
    format: u32,
    side: u32,
    nx: u32,
    tiles: u32,
    det_abs: f32,
    // Dome → world.
    a_eff: mat3x3<f32>,
    // The first texel's and the first tile's words.
    texels: u32,
    tile_words: u32,
}

fn env_info(base: u32) -> EnvInfo {
    let u = base;
    let a = base + 8u;
    let width = bitcast<u32>(tex_atlas[u]);
    let height = bitcast<u32>(tex_atlas[u + 1u]);
    let texels = base + ENV_HEADER_WORDS;
    return EnvInfo(
        base,
        width,
        height,
        bitcast<u32>(tex_atlas[u + 2u]),
        bitcast<u32>(tex_atlas[u + 3u]),
        bitcast<u32>(tex_atlas[u + 4u]),
        bitcast<u32>(tex_atlas[u + 5u]),
        tex_atlas[u + 6u],
        mat3x3<f32>(
            vec3<f32>(tex_atlas[a], tex_atlas[a + 1u], tex_atlas[a + 2u]),
            vec3<f32>(tex_atlas[a + 3u], tex_atlas[a + 4u], tex_atlas[a + 5u]),
            vec3<f32>(tex_atlas[a + 6u], tex_atlas[a + 7u], tex_atlas[a + 8u]),
        ),
        texels,
        texels + ENV_TEXEL_WORDS * width * height,
    );
}

fn is_disk(t: EnvInfo) -> bool {
    return t.format == FORMAT_MIRRORED_BALL || t.format == FORMAT_ANGULAR;
}

// The cross face texel k lies on (0 off the faces).
fn face_of(t: EnvInfo, k: u32) -> u32 {
    let n = t.width / 3u;
    let col = f32((k % t.width) / n);
    let row = f32((k / t.width) / n);
    for (var f = 0u; f < 6u; f++) {
        let b = cross_basis(f).block;
        if b.x == col && b.y == row {
            return f;
        }
    }
    return 0u;
}

// A disk texel's rectangle in (a, b): (a₀, a₁, b₀, b₁).
fn disk_rect(t: EnvInfo, k: u32) -> vec4<f32> {
    let w = f32(t.width);
    let h = f32(t.height);
    let i = f32(k % t.width);
    let j = f32(k / t.width);
    return vec4<f32>(2.0 * i / w - 1.0, 2.0 * (i + 1.0) / w - 1.0, 1.0 - 2.0 * (j + 1.0) / h, 1.0 - 2.0 * j / h);
}

fn a_range(r: vec4<f32>) -> vec2<f32> {
    var m = min(abs(r.z), abs(r.w));
    if r.z <= 0.0 && r.w >= 0.0 {
        m = 0.0;
    }
    let hm = sqrt(max(1.0 - m * m, 0.0));
    return vec2<f32>(max(r.x, -hm), min(r.y, hm));
}

fn chord(r: vec4<f32>, a: f32) -> vec2<f32> {
    let h = sqrt(max(1.0 - a * a, 0.0));
    return vec2<f32>(max(r.z, -h), min(r.w, h));
}

fn texel_point(t: EnvInfo, k: u32, u0: f32, u1: f32) -> vec2<f32> {
    if !is_disk(t) {
        return vec2<f32>(f32(k % t.width) + u0, f32(k / t.width) + u1);
    }
    let r = disk_rect(t, k);
    let x = a_range(r);
    var a = x.x + (x.y - x.x) * u0;
    var c = chord(r, a);
    if !(c.y > c.x) {
        a = 0.5 * (x.x + x.y);
        c = chord(r, a);
    }
    return vec2<f32>(a, c.x + (c.y - c.x) * u1);
}

fn chart_density(t: EnvInfo, k: u32, q: vec2<f32>) -> f32 {
    if !is_disk(t) {
        return 1.0;
    }
    let r = disk_rect(t, k);
    let x = a_range(r);
    let c = chord(r, q.x);
    if x.y > x.x && c.y > c.x {
        return 1.0 / ((x.y - x.x) * (c.y - c.x));
    }
    return 0.0;
}

fn chart_direction(t: EnvInfo, k: u32, q: vec2<f32>) -> vec3<f32> {
    switch t.format {
        case FORMAT_LATLONG: {
            let phi = PI - 2.0 * PI * q.x / f32(t.width);
            let theta = PI * q.y / f32(t.height);
            let st = sin(theta);
            return vec3<f32>(st * sin(phi), cos(theta), st * cos(phi));
        }
        case FORMAT_MIRRORED_BALL: {
            let r2 = min(q.x * q.x + q.y * q.y, 1.0);
            let s = 2.0 * sqrt(1.0 - r2);
            return vec3<f32>(q.x * s, q.y * s, 1.0 - 2.0 * r2);
        }
        case FORMAT_ANGULAR: {
            let r = min(length(q), 1.0);
            var sin_pr = sin(PI * r);
            if r > 0.5 {
                sin_pr = sin(PI * (1.0 - r));
            }
            var s = PI * (1.0 - (PI * r) * (PI * r) / 6.0);
            if r >= 1e-4 {
                s = sin_pr / r;
            }
            return vec3<f32>(q.x * s, q.y * s, cos(PI * r));
        }
        default: {
            let n = f32(t.width / 3u);
            let b = cross_basis(face_of(t, k));
            let a = 2.0 * (q.x - b.block.x * n) / n - 1.0;
            let c = 1.0 - 2.0 * (q.y - b.block.y * n) / n;
            return normalize(b.f + a * b.r + c * b.u);
        }
    }
}

fn chart_jacobian(t: EnvInfo, k: u32, d: vec3<f32>) -> f32 {
    switch t.format {
        case FORMAT_LATLONG: {
            return sqrt(d.x * d.x + d.z * d.z) * (2.0 * PI / f32(t.width)) * (PI / f32(t.height));
        }
        case FORMAT_MIRRORED_BALL: {
            return 4.0;
        }
        case FORMAT_ANGULAR: {
            let rho = sqrt(d.x * d.x + d.y * d.y);
            let r = atan2_accurate(rho, d.z) / PI;
            if r < 1e-30 {
                return PI * PI;
            }
            return PI * rho / r;
        }
        default: {
            let f = cross_basis(face_of(t, k)).f;
            let n = f32(t.width / 3u);
            let c = dot(d, f);
            return (2.0 / n) * (2.0 / n) * c * c * c;
        }
    }
}

// The tile holding texel k and k's local index in it: vec2(tile, local).
fn tile_of(t: EnvInfo, k: u32) -> vec2<u32> {
    let i = k % t.width;
    let j = k / t.width;
    let tx = i / t.side;
    let ty = j / t.side;
    let tw = min(t.side, t.width - tx * t.side);
    return vec2<u32>(ty * t.nx + tx, (j - ty * t.side) * tw + (i - tx * t.side));
}

// Texel of local index `local` in tile `tile`.
fn texel_of(t: EnvInfo, tile: u32, local: u32) -> u32 {
    let tx = tile % t.nx;
    let ty = tile / t.nx;
    let tw = min(t.side, t.width - tx * t.side);
    return (ty * t.side + local / tw) * t.width + tx * t.side + local % tw;
}

// The number of texels in tile `tile`.
fn tile_texels(t: EnvInfo, tile: u32) -> u32 {
    let tx = tile % t.nx;
    let ty = tile / t.nx;
    return min(t.side, t.width - tx * t.side) * min(t.side, t.height - ty * t.side);
}

fn cos_bound(n: vec3<f32>, c: vec3<f32>, cos_r: f32, sin_r: f32) -> f32 {
    let cos_t = clamp(dot(n, c), -1.0, 1.0);
    if cos_t >= cos_r {
        return 1.0;
    }
    let sin_t = min(length(cross(n, c)), 1.0);
    return max(cos_t * cos_r + sin_t * sin_r, 0.0);
}

// W_t · max(cos_bound_t(n), HORIZON_FLOOR) for the unit normal n.
fn tile_weight(t: EnvInfo, tile: u32, n: vec3<f32>) -> f32 {
    let o = t.tile_words + ENV_TILE_WORDS * tile;
    let c = vec3<f32>(tex_atlas[o + 1u], tex_atlas[o + 2u], tex_atlas[o + 3u]);
    return tex_atlas[o] * max(cos_bound(n, c, tex_atlas[o + 4u], tex_atlas[o + 5u]), HORIZON_FLOOR);
}

// A weight in [0, 1] in 48-bit fixed point, ⌊w·2⁴⁸⌋, as a 64-bit (high word, low word):
// w·2²⁴ and its fraction ·2²⁴ are exact in f32 (w has 24 significant bits), and u32()
// truncates.
fn fixed48(w: f32) -> vec2<u32> {
    let s = clamp(w, 0.0, 1.0) * 16777216.0;
    let h = u32(s);
    let l = u32((s - f32(h)) * 16777216.0);
    return vec2<u32>(h >> 8u, (h << 24u) | l);
}

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.y + b.y;
    return vec2<u32>(a.x + b.x + select(0u, 1u, lo < a.y), lo);
}

fn shr24(a: vec2<u32>) -> vec2<u32> {
    return vec2<u32>(a.x >> 24u, (a.x << 8u) | (a.y >> 24u));
}

// A 64-bit fixed-point value ·2⁻⁴⁸ as f32.
fn fixed_value(a: vec2<u32>) -> f32 {
    return f32(a.x) * 1.52587890625e-5 + f32(a.y) * 3.552713678800501e-15;
}

// Σ_t ⌊tile_weight(t)·2⁴⁸⌋, exactly (ReceiverTiles::new): the normalisation of P(t | n).
fn receiver_total(t: EnvInfo, n: vec3<f32>) -> vec2<u32> {
    var total = vec2<u32>(0u);
    for (var i = 0u; i < t.tiles; i++) {
        total = add64(total, fixed48(tile_weight(t, i, n)));
    }
    return total;
}

// P(t | n) = q_t / Σq (ReceiverTiles::pmf).
fn tile_pmf(t: EnvInfo, tile: u32, n: vec3<f32>, total: vec2<u32>) -> f32 {
    return fixed_value(fixed48(tile_weight(t, tile, n))) / fixed_value(total);
}

// ReceiverTiles::pick: the first tile whose running sum of the q_t exceeds ⌊U·total/2⁴⁸⌋,
// U = hi·2²⁴ + lo from two 24-bit uniforms given as integers, all in exact integer arithmetic
// on 64-bit (high, low) words; a tile of weight 0 never.
fn tile_pick(t: EnvInfo, n: vec3<f32>, total: vec2<u32>, hi: u32, lo: u32) -> u32 {
    // total < 2⁴⁹ in 24-bit digits: th·2²⁴ + tl.
    let th = (total.x << 8u) | (total.y >> 24u);
    let tl = total.y & 0xFFFFFFu;
    // U·T/2⁴⁸ = hi·th + (hi·tl + lo·th + (lo·tl)/2²⁴)/2²⁴, floored at each step (exact:
    // ⌊(x + y/2²⁴)/2²⁴⌋ = ⌊(x + ⌊y/2²⁴⌋)/2²⁴⌋ for integers x, y).
    let mid = add64(add64(mul_wide(hi, tl), mul_wide(lo, th)), shr24(mul_wide(lo, tl)));
    let goal = add64(mul_wide(hi, th), shr24(mid));
    var acc = vec2<u32>(0u);
    var last = 0u;
    for (var i = 0u; i < t.tiles; i++) {
        let q = fixed48(tile_weight(t, i, n));
        if q.x == 0u && q.y == 0u {
            continue;
        }
        last = i;
        acc = add64(acc, q);
        if acc.x > goal.x || (acc.x == goal.x && acc.y > goal.y) {
            return i;
        }
    }
    return last;
}

// The full 64-bit product of two u32, as (high word, low word).
fn mul_wide(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xFFFFu;
    let a1 = a >> 16u;
    let b0 = b & 0xFFFFu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let mid = (p00 >> 16u) + (p01 & 0xFFFFu) + (p10 & 0xFFFFu);
    return vec2<u32>(a1 * b1 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u), (p00 & 0xFFFFu) | (mid << 16u));
}

// ⌊X·n / 2⁵³⌋ for X = bits.x·2²¹ + bits.y (the 53-bit uniform's words, rng.wgsl's uniform53).
fn cell53(bits: vec2<u32>, n: u32) -> u32 {
    // X·n = (h·n)·2²¹ + l·n; with h·n = P_hi·2³² + P_lo, ⌊X·n/2⁵³⌋ = P_hi + ⌊A/2⁵³⌋,
    // A = P_lo·2²¹ + l·n < 2⁵⁴.
    let p = mul_wide(bits.x, n);
    let q = mul_wide(bits.y, n);
    let lo = (p.y << 21u) + q.y;
    let carry = select(0u, 1u, lo < q.y);
    let hi = (p.y >> 11u) + q.x + carry;
    return p.x + (hi >> 21u);
}

// AliasTable::pick over `n` cells of `stride` words at atlas offset `base` (keep threshold,
// alias): the cell from the 53-bit uniform's words, the coin as the 24-bit integer.
fn alias_pick(base: u32, stride: u32, n: u32, bits: vec2<u32>, coin: u32) -> u32 {
    let i = min(cell53(bits, n), n - 1u);
    let o = base + stride * i;
    if coin < bitcast<u32>(tex_atlas[o]) {
        return i;
    }
    return bitcast<u32>(tex_atlas[o + 1u]);
}
