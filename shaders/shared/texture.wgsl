// Twin of src/cpu/texture.rs
//
// Texture lookup on the GPU, a dome's environment map and a rect's image: the same functions with
// the same names in the same order as the Rust twin, which carries the DESIGN.md §6 D1–D5 and
// "RectLight texture" citations for every formula.
//
// Texels live in one flat storage buffer, `tex_atlas: array<f32>` (declared in
// shared/record.wgsl at @group(0) @binding(6)), packed by src/gpu/texture_atlas.rs: a texture at
// offset `o` (in f32 units, a multiple of 4) is a TEX_HEADER_WORDS-word header — width, height,
// format code, 0 (u32 bit patterns) — followed by width × height RGB triplets, row-major, row 0
// at the top: texel (i, j) is at o + 4 + 3·(j·width + i). A light record carries its texture's
// offset and filter in `tex`, and A_eff⁻¹ in `tex_inv0..2` (FLAG_DOME_TEXTURE); a textured rect
// (FLAG_RECT_TEXTURE) its offset and filter in `tex` and its mean colour in `tex_inv0.rgb`. The FORMAT_*,
// FILTER_* codes and §6 D5's cube-cross table (CROSS_FACE_TABLE) are generated from Rust
// (gpu::texture_atlas::wgsl_constants, wgsl_f32_arrays).
//
// Deliberate f32 divergences from the f64 twin, and why:
// 1. Everything is f32. Pixel coordinates s·W carry about W·2⁻²⁴ px of rounding (5e-4 px at
//    W = 8192), so the bilinear weights differ by that much; nearest lookups within that distance
//    of a texel edge, and any lookup at a latlong seam or cross face edge, may pick the neighbour.
//    The bilinear value's error is that fraction of a pixel times the footprint's contrast: on a
//    high-dynamic-range map, more than 1e-4 of a dark texel beside a bright one (8.7e-4 seen on
//    Blender's studio map), but below 1e-4 of the footprint's largest texel, which is what
//    `check` measures it against (check::texture_floor).
// 2. atan2 is math.wgsl's atan2_accurate, not the builtin (lavapipe's errs by ~3e-6 rad, and
//    WGSL only bounds it to 4096 ULP). No acos anywhere: §6 D2's atan2 form keeps the poles.
// 3. No sin/cos: WGSL only bounds them to 2⁻¹¹ absolute. mirroredBall's r = sin(θ/2) is written
//    algebraically (the same form in the f64 twin): with ρ = √(dx² + dy²),
//    r/ρ = 1/√(2(1 + dz)) for dz ≥ 0 and √((1 − dz)/2)/ρ for dz < 0 (exact identities; the
//    second loses accuracy only within ~1e-3 rad of −Z, the rim, where the image is singular).
// 4. dome_direction normalises in f32 (relative error ~1e-7); A_eff⁻¹ is rounded to f32 once.
// 5. The texture's size and format come from the atlas header (tex_info reads it); the f64
//    twin reads them from the image. The lookup has no loop (lavapipe's loop budget).
// 6. The lookups of dome_factor, rect_mean and rect_factor are the optional part TEXTURE
//    (`// #if TEXTURE`, gpu::shaders::Features): kernels are built without them for scenes
//    without a textured dome or rect, so their pipelines are unchanged.
// 7. A rect's hit point is f32 (the ray–plane intersection), so (s, t) carries its rounding;
//    its mean colour is computed in f64 by prepare and rounded once.
// GPU-only TexInfo, FaceBasis: structs standing in for the Rust tuples.

// #import shared/record.wgsl
// #import shared/math.wgsl

struct TexInfo {
    base: u32,
    width: u32,
    height: u32,
    format: u32,
}

struct FaceBasis {
    f: vec3<f32>,
    r: vec3<f32>,
    u: vec3<f32>,
    block: vec2<f32>,
}

// The header of the texture at atlas offset `offset`.
fn tex_info(offset: u32) -> TexInfo {
    return TexInfo(
        offset + TEX_HEADER_WORDS,
        bitcast<u32>(tex_atlas[offset]),
        bitcast<u32>(tex_atlas[offset + 1u]),
        bitcast<u32>(tex_atlas[offset + 2u]),
    );
}

// Texel (i, j), row 0 at the top.
fn tex_fetch(t: TexInfo, i: u32, j: u32) -> vec3<f32> {
    let k = t.base + 3u * (j * t.width + i);
    return vec3<f32>(tex_atlas[k], tex_atlas[k + 1u], tex_atlas[k + 2u]);
}

// d = normalize(A_eff⁻¹ ω).
fn dome_direction(inv: mat3x3<f32>, w: vec3<f32>) -> vec3<f32> {
    return normalize(inv * w);
}

fn latlong_st(d: vec3<f32>) -> vec2<f32> {
    let s = 0.5 - atan2_accurate(d.x, d.z) / (2.0 * PI);
    let t = atan2_accurate(sqrt(d.x * d.x + d.z * d.z), d.y) / PI;
    return vec2<f32>(s, t);
}

fn disk_to_st(a: f32, b: f32) -> vec2<f32> {
    return vec2<f32>(0.5 * (a + 1.0), 0.5 * (1.0 - b));
}

fn mirrored_ball_st(d: vec3<f32>) -> vec2<f32> {
    let rho = sqrt(d.x * d.x + d.y * d.y);
    if rho == 0.0 {
        return select(disk_to_st(0.0, 1.0), disk_to_st(0.0, 0.0), d.z >= 0.0);
    }
    // r/ρ with r = sin(θ/2), trig-free (divergence 3).
    var k: f32;
    if d.z >= 0.0 {
        k = 1.0 / sqrt(2.0 * (1.0 + d.z));
    } else {
        k = sqrt(0.5 * (1.0 - d.z)) / rho;
    }
    return disk_to_st(k * d.x, k * d.y);
}

fn angular_st(d: vec3<f32>) -> vec2<f32> {
    let rho = sqrt(d.x * d.x + d.y * d.y);
    if rho == 0.0 {
        return select(disk_to_st(0.0, 1.0), disk_to_st(0.0, 0.0), d.z >= 0.0);
    }
    let r = atan2_accurate(rho, d.z) / PI;
    return disk_to_st(r * d.x / rho, r * d.y / rho);
}

// +X, −X, +Y, −Y, +Z, −Z = 0..5; ties x before y before z.
fn cross_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x > 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y > 0.0);
    }
    return select(5u, 4u, d.z > 0.0);
}

// §6 D5's table entry of face f, from the generated CROSS_FACE_TABLE.
fn cross_basis(f: u32) -> FaceBasis {
    let k = min(f, 5u) * CROSS_FACE_STRIDE;
    return FaceBasis(
        vec3<f32>(CROSS_FACE_TABLE[k], CROSS_FACE_TABLE[k + 1u], CROSS_FACE_TABLE[k + 2u]),
        vec3<f32>(CROSS_FACE_TABLE[k + 3u], CROSS_FACE_TABLE[k + 4u], CROSS_FACE_TABLE[k + 5u]),
        vec3<f32>(CROSS_FACE_TABLE[k + 6u], CROSS_FACE_TABLE[k + 7u], CROSS_FACE_TABLE[k + 8u]),
        vec2<f32>(CROSS_FACE_TABLE[k + 9u], CROSS_FACE_TABLE[k + 10u]),
    );
}

// Face-local (s_f, t_f) and the face's block (column, row).
fn cross_st(d: vec3<f32>) -> vec4<f32> {
    let b = cross_basis(cross_face(d));
    let inv = 1.0 / dot(d, b.f);
    let st = disk_to_st(dot(d, b.r) * inv, dot(d, b.u) * inv);
    return vec4<f32>(clamp(st.x, 0.0, 1.0), clamp(st.y, 0.0, 1.0), b.block.x, b.block.y);
}

fn axis_index(k: i32, n: u32, wrap: bool) -> u32 {
    let ni = i32(n);
    if wrap {
        return u32(((k % ni) + ni) % ni);
    }
    return u32(clamp(k, 0, ni - 1));
}

fn filter_block(t: TexInfo, x0: u32, y0: u32, w: u32, h: u32, st: vec2<f32>, wrap_x: bool, filt: u32) -> vec3<f32> {
    let px = st.x * f32(w);
    let py = st.y * f32(h);
    if filt == FILTER_NEAREST {
        let i = axis_index(i32(floor(px)), w, wrap_x);
        let j = axis_index(i32(floor(py)), h, false);
        return tex_fetch(t, x0 + i, y0 + j);
    }
    let x = px - 0.5;
    let y = py - 0.5;
    let fi = floor(x);
    let fj = floor(y);
    let fx = x - fi;
    let fy = y - fj;
    let i0 = axis_index(i32(fi), w, wrap_x);
    let i1 = axis_index(i32(fi) + 1, w, wrap_x);
    let j0 = axis_index(i32(fj), h, false);
    let j1 = axis_index(i32(fj) + 1, h, false);
    let top = tex_fetch(t, x0 + i0, y0 + j0) * (1.0 - fx) + tex_fetch(t, x0 + i1, y0 + j0) * fx;
    let bottom = tex_fetch(t, x0 + i0, y0 + j1) * (1.0 - fx) + tex_fetch(t, x0 + i1, y0 + j1) * fx;
    return top * (1.0 - fy) + bottom * fy;
}

fn dome_texel(t: TexInfo, d: vec3<f32>, filt: u32) -> vec3<f32> {
    let w = t.width;
    let h = t.height;
    switch t.format {
        case FORMAT_LATLONG: { return filter_block(t, 0u, 0u, w, h, latlong_st(d), true, filt); }
        case FORMAT_MIRRORED_BALL: { return filter_block(t, 0u, 0u, w, h, mirrored_ball_st(d), false, filt); }
        case FORMAT_ANGULAR: { return filter_block(t, 0u, 0u, w, h, angular_st(d), false, filt); }
        default: {
            let c = cross_st(d);
            let n = w / 3u;
            return filter_block(t, u32(c.z) * n, u32(c.w) * n, n, n, c.xy, false, filt);
        }
    }
}

// The dome's texture factor for world direction w, texture at atlas offset `offset`.
fn dome_lookup(offset: u32, inv: mat3x3<f32>, w: vec3<f32>, filt: u32) -> vec3<f32> {
    return dome_texel(tex_info(offset), dome_direction(inv, w), filt);
}

fn rect_st(x: f32, y: f32, w: f32, h: f32) -> vec2<f32> {
    return vec2<f32>(0.5 - x / w, 0.5 - y / h);
}

fn rect_texel(offset: u32, x: f32, y: f32, w: f32, h: f32, filt: u32) -> vec3<f32> {
    let t = tex_info(offset);
    return filter_block(t, 0u, 0u, t.width, t.height, rect_st(x, y, w, h), false, filt);
}

// The texture factor of a dome record along the world direction e toward the environment: 1
// without a texture (or in a pipeline built without TEXTURE).
fn dome_factor(light: Record, e: vec3<f32>) -> vec3<f32> {
    // #if TEXTURE
    if has_flag(light, FLAG_DOME_TEXTURE) {
        let inv = mat3x3<f32>(light.tex_inv0.xyz, light.tex_inv1.xyz, light.tex_inv2.xyz);
        return dome_lookup(light.tex.x, inv, e, light.tex.y);
    }
    // #endif
    return vec3<f32>(1.0);
}

// A rect record's texture factor for emission: the texture's exact area mean, rounded once
// (tex_inv0.rgb, FLAG_RECT_TEXTURE); 1 without a texture.
fn rect_mean(light: Record) -> vec3<f32> {
    // #if TEXTURE
    if has_flag(light, FLAG_RECT_TEXTURE) {
        return light.tex_inv0.xyz;
    }
    // #endif
    return vec3<f32>(1.0);
}

// A rect record's texture factor for radiance at the local hit point (x, y); 1 without one.
fn rect_factor(light: Record, hit: vec2<f32>) -> vec3<f32> {
    // #if TEXTURE
    if has_flag(light, FLAG_RECT_TEXTURE) {
        return rect_texel(light.tex.x, hit.x, hit.y, 2.0 * light.size.x, 2.0 * light.size.y, light.tex.y);
    }
    // #endif
    return vec3<f32>(1.0);
}
