// Sampling a dome light (f32), DESIGN.md §9 S2 "dome". Twin of src/cpu/sample/dome.rs, which
// carries the strategy, its density and their reasons.
//
// Textured (a sampling table at atlas offset `tex.z` of the record, sample/env_table.wgsl): a
// texel by the alias table (the generator's dimension 3 with 53 bits and the coin of dimension
// 4) — within the tile that dimensions 5 and 6 draw from the receiver's product with its cosine
// where a normal is given —, a point of the texel's chart from u (dimensions 0, 1), the dome
// direction and the world direction. Its density is evaluated at ω as pdf_dome does.
// Untextured (tex.z = 0: no texture, or one whose table is None on the CPU, e.g. all black):
// cosine-weighted about the normal when one is given (a zero normal stands for none), else
// uniform over the sphere.
//
// Deliberate f32 divergences from the f64 twin, and why:
// 1. The texel is the CPU's exactly (integer arithmetic on the 53-bit uniform's words and the
//    coin against integer keep thresholds, env_table.wgsl's alias_pick); the tile's running
//    sum is exact integer arithmetic on weights computed in f32 (the CPU's in f64), so a draw
//    within their rounding (~1e-7 of a tile's weight) of a boundary of the running sum may
//    take the neighbouring tile (and then another texel).
// 2. The point in the texel, the chart maps and the frame are f32: ω differs by ~1e-7 rad, and
//    locate (the pdf) may name the neighbouring texel within that of a texel edge, where the
//    density jumps (S1's discontinuities: texel seams).
// 3. The receiver's tile weights are recomputed per invocation (a loop over the tiles for the
//    total, one more for the pick), not cached per normal as the CPU does.
// 4. The frame is cone.wgsl's basis, the same formula as dome.rs's (cone::basis).
// GPU-only Located: the struct standing in for locate's tuple.
// GPU-only receiver_tiles: the receiver's tile total where the table has tiles and a normal is
//   given, zero (the plain table) elsewhere (the twin builds EnvTable::receiver_tiles there).

// #import shared/math.wgsl
// #import shared/texture.wgsl
// #import sample/rng.wgsl
// #import sample/cone.wgsl
// #import sample/env_table.wgsl

struct Located {
    k: u32,
    q: vec2<f32>,
}

// The 48-bit total of the receiver's tile weights (env_table.wgsl receiver_total) where the
// table has tiles and n is a unit normal; zero, standing for the plain table, elsewhere.
fn receiver_tiles(t: EnvInfo, nn: vec3<f32>) -> vec2<u32> {
    if length(nn) > 0.0 && t.tiles > 0u {
        return receiver_total(t, nn);
    }
    return vec2<u32>(0u);
}

// The direction toward the dome and its density per unit world solid angle: vec4(ω, pdf).
// `keys` = (seed, point key, sample key) of the generator, for dimensions 3–6.
fn sample_dome(light: Record, n: vec3<f32>, u: vec2<f32>, keys: vec3<u32>) -> vec4<f32> {
    let nn = unit(n);
    // #if TEXTURE
    if light.tex.z != 0u {
        let t = env_info(light.tex.z);
        let total = receiver_tiles(t, nn);
        let k = pick_texel(t, nn, total, keys);
        let q = texel_point(t, k, u.x, u.y);
        let d = chart_direction(t, k, q);
        let ad = t.a_eff * d;
        let l = length(ad);
        let w = ad / l;
        let pdf = textured_pdf(light, t, nn, total, w);
        if pdf > 0.0 {
            return vec4<f32>(w, pdf);
        }
        // Only where ω's lookup names a neighbouring texel of weight 0 (dome.rs).
        return vec4<f32>(w, density(t, nn, total, k, q, d) * (l * l * l) / t.det_abs);
    }
    // #endif
    if length(nn) > 0.0 {
        // Malley's method: uniform on the unit disk lifted to the hemisphere about n.
        let r = sqrt(u.x);
        let phi = 2.0 * PI * u.y;
        let z = sqrt(max(1.0 - u.x, 0.0));
        let b = basis(nn);
        let w = normalize(b[0] * (r * cos(phi)) + b[1] * (r * sin(phi)) + nn * z);
        return vec4<f32>(w, max(dot(nn, w), 0.0) / PI);
    }
    // Uniform on the sphere: z uniform in [−1, 1] (Archimedes), φ uniform.
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec4<f32>(r * cos(phi), r * sin(phi), z, 1.0 / (4.0 * PI));
}

// The texel drawn by dimensions 3 (53 bits) and 4 — within the tile dimensions 5 and 6 draw
// from the receiver's product where `total` (the fixed-point Σq of env_table.wgsl) > 0 (the
// plain table's otherwise, or for a tile of
// weight 0, which the product never draws).
fn pick_texel(t: EnvInfo, n: vec3<f32>, total: vec2<u32>, keys: vec3<u32>) -> u32 {
    let bits = uniform53(keys.x, keys.y, keys.z, 3u);
    // The 24-bit uniforms as the integers they are multiples of 2⁻²⁴ of (exact).
    let coin = u32(rng_uniform(keys.x, keys.y, keys.z, 4u) * 16777216.0);
    if any(total != vec2<u32>(0u)) {
        let hi = u32(rng_uniform(keys.x, keys.y, keys.z, 5u) * 16777216.0);
        let lo = u32(rng_uniform(keys.x, keys.y, keys.z, 6u) * 16777216.0);
        let tile = tile_pick(t, n, total, hi, lo);
        let inner = bitcast<u32>(tex_atlas[t.tile_words + ENV_TILE_WORDS * tile + 6u]);
        if inner != ENV_NO_INNER {
            let local = alias_pick(inner, ENV_INNER_WORDS, tile_texels(t, tile), bits, coin);
            return texel_of(t, tile, local);
        }
    }
    return alias_pick(t.texels, ENV_TEXEL_WORDS, t.width * t.height, bits, coin);
}

// The probability of texel k: the table's, or with the receiver's tiles (total > 0)
// P(tile | n) · pmf(k) / W_tile.
fn texel_pmf(t: EnvInfo, n: vec3<f32>, total: vec2<u32>, k: u32) -> f32 {
    let pmf = tex_atlas[t.texels + ENV_TEXEL_WORDS * k + 2u];
    if any(total != vec2<u32>(0u)) {
        let tile = tile_of(t, k).x;
        let o = t.tile_words + ENV_TILE_WORDS * tile;
        if bitcast<u32>(tex_atlas[o + 6u]) == ENV_NO_INNER {
            return 0.0;
        }
        return tile_pmf(t, tile, n, total) * (pmf / tex_atlas[o]);
    }
    return pmf;
}

// The density sample_dome draws the unit world direction w with, for the receiver's normal n
// (zero for none).
fn pdf_dome(light: Record, n: vec3<f32>, w: vec3<f32>) -> f32 {
    let nn = unit(n);
    // #if TEXTURE
    if light.tex.z != 0u {
        let t = env_info(light.tex.z);
        let total = receiver_tiles(t, nn);
        return textured_pdf(light, t, nn, total, w);
    }
    // #endif
    if length(nn) > 0.0 {
        return max(dot(nn, w), 0.0) / PI;
    }
    return 1.0 / (4.0 * PI);
}

// pdf_dome of a textured dome: d = normalize(A_eff⁻¹ ω), |A_eff d| = 1 / |A_eff⁻¹ ω| (§6 D1).
fn textured_pdf(light: Record, t: EnvInfo, n: vec3<f32>, total: vec2<u32>, w: vec3<f32>) -> f32 {
    let inv = mat3x3<f32>(light.tex_inv0.xyz, light.tex_inv1.xyz, light.tex_inv2.xyz);
    let v = inv * w;
    let li = length(v);
    if !(li > 0.0) {
        return 0.0;
    }
    let d = v / li;
    let at = locate(t, d);
    return density(t, n, total, at.k, at.q, d) / (li * li * li * t.det_abs);
}

// The density per unit dome solid angle at d, found in texel k at chart point q.
fn density(t: EnvInfo, n: vec3<f32>, total: vec2<u32>, k: u32, q: vec2<f32>, d: vec3<f32>) -> f32 {
    let m = texel_pmf(t, n, total, k) * chart_density(t, k, q);
    if m == 0.0 {
        return 0.0;
    }
    return m / max(chart_jacobian(t, k, d), 1e-30);
}

// The texel and chart point of dome direction d by the lookup's forward maps (texture.wgsl):
// latlong columns wrapped, everything else clamped (the cross within its face's block).
fn locate(t: EnvInfo, d: vec3<f32>) -> Located {
    let w = f32(t.width);
    let h = f32(t.height);
    switch t.format {
        case FORMAT_LATLONG: {
            let st = latlong_st(d);
            let x = st.x * w;
            let y = st.y * h;
            let i = axis_index(i32(floor(x)), t.width, true);
            let j = axis_index(i32(floor(y)), t.height, false);
            return Located(j * t.width + i, vec2<f32>(x, y));
        }
        case FORMAT_MIRRORED_BALL, FORMAT_ANGULAR: {
            var st: vec2<f32>;
            if t.format == FORMAT_MIRRORED_BALL {
                st = mirrored_ball_st(d);
            } else {
                st = angular_st(d);
            }
            let i = axis_index(i32(floor(st.x * w)), t.width, false);
            let j = axis_index(i32(floor(st.y * h)), t.height, false);
            return Located(j * t.width + i, vec2<f32>(2.0 * st.x - 1.0, 1.0 - 2.0 * st.y));
        }
        default: {
            let c = cross_st(d);
            let n = t.width / 3u;
            let nf = f32(n);
            let i = u32(c.z) * n + axis_index(i32(floor(c.x * nf)), n, false);
            let j = u32(c.w) * n + axis_index(i32(floor(c.y * nf)), n, false);
            return Located(j * t.width + i, vec2<f32>((c.z + c.x) * nf, (c.w + c.y) * nf));
        }
    }
}

// n normalised, or zero for a zero or non-finite normal.
fn unit(n: vec3<f32>) -> vec3<f32> {
    let l = length(n);
    if l > 0.0 && l < 3.0e38 {
        return n / l;
    }
    return vec3<f32>(0.0);
}
