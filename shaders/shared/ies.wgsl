// IES (LM-63) and EULUMDAT profiles on the GPU. Twin of src/cpu/ies.rs:
// the same functions with the same names in the same order; the Rust file carries the formulas
// with their citations (DESIGN.md §6 I2 frames, I3 folds and bilinear lookup, I4 angleScale).
//
// Reads `ies_atlas: array<f32>` (declared in shared/record.wgsl at @group(0) @binding(5)),
// packed by src/gpu/ies_atlas.rs: a profile header at `base` = [type, h fold, v fold, nH, nV, h offset,
// v offset, candela offset], then the file's own (non-uniform) angle grids in degrees and the
// candela values h-major. The IES_* constants are generated from Rust (gpu::ies_atlas::wgsl_constants).
//
// Deliberate f32 divergences from the f64 twin, each with its reason:
// 1. Angles come from an f32 direction through atan2_accurate (≤ ~2e-7 rad, math.wgsl) and are
//    converted to degrees in f32: H and V carry ~1e-5° of error near 360°, which moves the
//    interpolation weight by ~1e-5°/Δ (Δ the grid step). The builtin atan2 is not used: it is off
//    by ~3e-6 rad on lavapipe.
// 2. Grid angles and candela values are the f64 profile rounded to f32 (relative 6e-8); a node
//    such as 134.9° moves by ~6e-6°, so on a cell Δ wide the weight moves by ~1e-5°/Δ (1e-4 of
//    the jump on luxtest's 0.1° ramps, which count as discontinuities), and a direction exactly
//    on a grid end can fall just outside (→ 0) where the CPU gives the end value: the range
//    ends are discontinuities, excluded from §5's 1e-4 tolerance.
// 3. angleScale for types B and A rebuilds e' with the builtin sin/cos of θ' (WGSL promises only
//    2^-11 absolute on [−π, π]; lavapipe is near 1 ULP); (cos φ, sin φ) come from e itself, as on
//    the CPU, so only θ' goes through trigonometry.
// 4. The interval search is a binary search written out as IES_SEARCH_STEPS (16) halving steps,
//    with no loop at all: lavapipe silently ends an invocation's loops after 65,535 iterations
//    in total, and the irradiance quadrature looks the profile up thousands of times per
//    receiver; the packer refuses grids of more than 2^16 + 1 angles. The CPU loops while
//    hi − lo > 1 and finds the same interval.
// 5. Counts and offsets are read from f32 atlas values (u32(x)): exact because the packer refuses
//    atlases of 2^24 floats or more.
// 6. The lookup in ies_of is the optional part IES (`// #if IES`, gpu::shaders::Features): each
//    kernel is built without it for scenes with no profile, the irradiance kernel for scenes
//    whose IES-shaped lights all keep their irradiance on the host (GpuLights::variant). The
//    irradiance quadrature calls it once per inner node, in one copy (irradiance/line.wgsl):
//    inlined at every shaping call of the old quadrature, it took lavapipe's compiler minutes.
// GPU-only search_step: the CPU's loop body in find_interval, written out (divergence 4).
// Not divergences (checked): at a frame's poles (both atan2 arguments zero) atan2_accurate gives
// 0 and the CPU twin returns 0 explicitly (f64::atan2(0, −0) would be π); the folds 360 − H,
// 180 − H and 540 − H are exact in f32 on their ranges (Sterbenz).

// #import shared/record.wgsl
// #import shared/math.wgsl

const IES_DEG_PER_RAD: f32 = 57.2957795130823;
const IES_RAD_PER_DEG: f32 = 0.0174532925199433;

struct IesAngles {
    h: f32,
    v: f32,
    inside: bool,
}

struct IesInterval {
    index: u32,
    t: f32,
    inside: bool,
}

// Type C (H, V): V = atan2(√(ex²+ey²), −ez), H = atan2(ey, ex) mod 360 (degrees).
fn type_c_angles(e: vec3<f32>) -> vec2<f32> {
    let v = atan2_accurate(length(e.xy), -e.z) * IES_DEG_PER_RAD;
    var h = atan2_accurate(e.y, e.x) * IES_DEG_PER_RAD;
    if h < 0.0 {
        h += 360.0;
    }
    return vec2<f32>(h, v);
}

// Type B (H, V): V = atan2(ex, −ez), H = atan2(−ey, √(ex²+ez²)).
fn type_b_angles(e: vec3<f32>) -> vec2<f32> {
    let v = atan2_accurate(e.x, -e.z) * IES_DEG_PER_RAD;
    let h = atan2_accurate(-e.y, length(e.xz)) * IES_DEG_PER_RAD;
    return vec2<f32>(h, v);
}

// Type A (H, V): V = atan2(ez, √(ex²+ey²)), H = atan2(−ey, ex).
fn type_a_angles(e: vec3<f32>) -> vec2<f32> {
    let v = atan2_accurate(e.z, length(e.xy)) * IES_DEG_PER_RAD;
    let h = atan2_accurate(-e.y, e.x) * IES_DEG_PER_RAD;
    return vec2<f32>(h, v);
}

// angleScale on θ in degrees: s > 0: θ/s; s = 0: θ; s < 0: (θ − 180)/(−s) + 180.
fn scale_polar_angle(theta: f32, s: f32) -> f32 {
    if s > 0.0 {
        return theta / s;
    }
    if s < 0.0 {
        return (theta - 180.0) / -s + 180.0;
    }
    return theta;
}

// e' = (sin θ' cos φ, sin θ' sin φ, −cos θ') with (cos φ, sin φ) from e; φ = 0 on the axis.
fn scaled_direction(e: vec3<f32>, theta: f32) -> vec3<f32> {
    let rho = length(e.xy);
    var c = vec2<f32>(1.0, 0.0);
    if rho > 0.0 {
        c = e.xy / rho;
    }
    let t = theta * IES_RAD_PER_DEG;
    let st = sin(t);
    return vec3<f32>(st * c.x, st * c.y, -cos(t));
}

// (H, V) of the profile's type after angleScale; inside = false where θ' leaves [0, 180].
fn photometric_angles(kind: u32, e: vec3<f32>, s: f32) -> IesAngles {
    if kind == IES_TYPE_C {
        let hv = type_c_angles(e);
        let t = scale_polar_angle(hv.y, s);
        return IesAngles(hv.x, t, t >= 0.0 && t <= 180.0);
    }
    var d = e;
    if s != 0.0 {
        let theta = type_c_angles(e).y;
        let t = scale_polar_angle(theta, s);
        if !(t >= 0.0 && t <= 180.0) {
            return IesAngles(0.0, 0.0, false);
        }
        if t != theta {
            d = scaled_direction(e, t);
        }
    }
    var hv: vec2<f32>;
    if kind == IES_TYPE_B {
        hv = type_b_angles(d);
    } else {
        hv = type_a_angles(d);
    }
    return IesAngles(hv.x, hv.y, true);
}

// Type C horizontal fold for H in [0, 360]: quadrant, half, half about 90–270, else as is.
fn fold_h_type_c(h: f32, fold: u32) -> f32 {
    var x = h;
    if fold == IES_FOLD_QUADRANT || fold == IES_FOLD_HALF {
        if x > 180.0 {
            x = 360.0 - x;
        }
        if fold == IES_FOLD_QUADRANT && x > 90.0 {
            x = 180.0 - x;
        }
    } else if fold == IES_FOLD_HALF_C90 {
        if x < 90.0 {
            x = 180.0 - x;
        }
        if x > 270.0 {
            x = 540.0 - x;
        }
    }
    return x;
}

// Types A and B: an axis whose first angle is 0 is mirrored, x' = |x|.
fn fold_mirror(x: f32, mirrored: bool) -> f32 {
    return select(x, abs(x), mirrored);
}

// Interval of the n angles at ies_atlas[offset..] holding x, ends inclusive: a binary search of
// IES_SEARCH_STEPS written-out steps.
fn find_interval(offset: u32, n: u32, x: f32) -> IesInterval {
    if !(x >= ies_atlas[offset] && x <= ies_atlas[offset + n - 1u]) {
        return IesInterval(0u, 0.0, false);
    }
    if n == 1u {
        return IesInterval(0u, 0.0, true);
    }
    // Invariant: grid[lo] ≤ x and x lies in the `len` cells from lo. Each step halves `len`;
    // IES_SEARCH_STEPS (16) steps cover any grid of up to 2^16 + 1 angles (the packer refuses
    // longer ones). Written out, not looped: see the header (divergence 4).
    var lo = 0u;
    var len = n - 1u;
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    lo = search_step(offset, x, lo, &len);
    let g0 = ies_atlas[offset + lo];
    return IesInterval(lo, (x - g0) / (ies_atlas[offset + lo + 1u] - g0), true);
}

// One step of find_interval's binary search over `len` cells from `lo`.
fn search_step(offset: u32, x: f32, lo: u32, len: ptr<function, u32>) -> u32 {
    let half = *len / 2u;
    *len = *len - half;
    return select(lo, lo + half, half > 0u && ies_atlas[offset + lo + half] <= x);
}

// (1−t)((1−u)I00 + u I01) + t((1−u)I10 + u I11), first index horizontal.
fn bilinear(i00: f32, i01: f32, i10: f32, i11: f32, t: f32, u: f32) -> f32 {
    return (1.0 - t) * ((1.0 - u) * i00 + u * i01) + t * ((1.0 - u) * i10 + u * i11);
}

// Candela of the profile at `base` toward light-space unit direction e after angleScale s,
// before ies:normalize and tilt; 0 outside the folded grid.
fn ies_factor(base: u32, e: vec3<f32>, s: f32) -> f32 {
    let kind = u32(ies_atlas[base]);
    let h_fold = u32(ies_atlas[base + 1u]);
    let v_fold = u32(ies_atlas[base + 2u]);
    let n_h = u32(ies_atlas[base + 3u]);
    let n_v = u32(ies_atlas[base + 4u]);
    let h_off = u32(ies_atlas[base + 5u]);
    let v_off = u32(ies_atlas[base + 6u]);
    let c_off = u32(ies_atlas[base + 7u]);
    if n_h == 0u || n_v < 2u {
        return 0.0;
    }
    let a = photometric_angles(kind, e, s);
    if !a.inside {
        return 0.0;
    }
    var hq: f32;
    var vq: f32;
    if kind == IES_TYPE_C {
        hq = fold_h_type_c(a.h, h_fold);
        vq = a.v;
    } else {
        hq = fold_mirror(a.h, h_fold == IES_FOLD_MIRROR);
        vq = fold_mirror(a.v, v_fold == IES_V_MIRROR);
    }
    let vi = find_interval(v_off, n_v, vq);
    if !vi.inside {
        return 0.0;
    }
    let h_last = ies_atlas[h_off + n_h - 1u];
    var i0 = 0u;
    var i1 = 0u;
    var t = 0.0;
    if h_fold == IES_FOLD_CONSTANT {
        if kind != IES_TYPE_C && abs(hq) > 90.0 {
            return 0.0;
        }
    } else if h_fold == IES_FOLD_FULL && hq > h_last {
        i0 = n_h - 1u;
        t = (hq - h_last) / (360.0 - h_last);
    } else {
        let hi = find_interval(h_off, n_h, hq);
        if !hi.inside {
            return 0.0;
        }
        i0 = hi.index;
        i1 = min(hi.index + 1u, n_h - 1u);
        t = hi.t;
    }
    let j = vi.index;
    let j1 = min(j + 1u, n_v - 1u);
    return bilinear(
        ies_atlas[c_off + i0 * n_v + j],
        ies_atlas[c_off + i0 * n_v + j1],
        ies_atlas[c_off + i1 * n_v + j],
        ies_atlas[c_off + i1 * n_v + j1],
        t,
        vi.t,
    );
}

// The IES factor of a light record along unit world emission direction e (1 without FLAG_IES);
// twin of cpu::ies::ies_of.
fn ies_of(light: Record, e: vec3<f32>) -> f32 {
    // #if IES
    if has_flag(light, FLAG_IES) {
        let el = normalize(to_local_dir(light, e));
        return light.ies.z * ies_factor(u32(light.ies.x), el, light.ies.y);
    }
    // #endif
    return 1.0;
}
