// A textured latlong dome's exact irradiance by rows of its texture.
// Twin of src/cpu/irradiance/latlong_rows.rs, which carries the derivation (DESIGN.md §6 D1, D2
// and "what 'exact' means"); the tables are prepare::latlong_rows's, packed into the texture atlas
// (tex_atlas, binding 6) after the textures by gpu::texture_atlas; a record's tex.z is their offset.
//
// f32 divergences from the f64 twin, and why:
// 1. The tables' prefix sums are accumulated in f64 and rounded once: a difference of two is
//    within ~1e-7 of the row's total, not of the arc's part of it.
// 2. A partial piece's τ comes from the arc's end in units of pieces (x = (u − u₀)/h, ~2W at most):
//    its rounding moves the end by ~W·2⁻²⁴ pieces, about 2e-7 of the row's total for W = 2048.
// 3. sin and cos are the builtins (WGSL bounds them only to 2⁻¹¹ absolute; lavapipe's keep the
//    kernel within 6.2e-7 of the reference, tests/dome_conformance.rs): in piece_moments, of
//    τ ∈ [0, h]; for the nodes' θ; for the crossing θ's cos δ (a breakpoint moved a little costs
//    nothing: the integrand is C¹ there). The phases cos u_k, sin u_k are the tables' (f64,
//    rounded once), as irradiance/pieces.wgsl and closed.wgsl use the builtins too.
// 4. Every loop checks its condition after it ends and sets irr_cut when the device's loop
//    budget cut it short (shared/record.wgsl): W + H + 4 intervals, each with IRR_GL_ROWS
//    nodes, inside lavapipe's budget up to W + H ≈ 5,900 (prepare::latlong_rows); a real GPU
//    has no such budget.
// 5. Everything here is the optional part TEXTURE (gpu::shaders::Features): an irradiance
//    pipeline without a textured dome to integrate is built without it (lavapipe compiles
//    code it never calls).
// GPU-only RowsInfo, RowMoments, RowEntry, RowPair: structs standing in for the twin's Rows and tuples.
// GPU-only rows_info: reads the tables' header (the twin's Rows holds the numbers).
// GPU-only piece_moments: its f64 form is prepare::latlong_rows::piece_moments, which builds the
//   tables.

// #import shared/record.wgsl
// #import shared/math.wgsl

// #if TEXTURE
struct RowsInfo {
    base: u32,
    width: u32,
    height: u32,
    bilinear: bool,
}

struct RowMoments {
    q0: vec3<f32>,
    qs: vec3<f32>,
    qc: vec3<f32>,
}

struct RowEntry {
    m: RowMoments,
    v: vec3<f32>,
}

struct RowPair {
    j0: u32,
    j1: u32,
    fy: f32,
}

struct Horizon {
    ny: f32,
    p: f32,
    q: f32,
    rho: f32,
    psi: f32,
}

// The tables at atlas offset `offset`: the header, then the column phases and rows at `base`.
fn rows_info(offset: u32) -> RowsInfo {
    return RowsInfo(
        offset + LATLONG_ROWS_HEADER_WORDS,
        bitcast<u32>(tex_atlas[offset]),
        bitcast<u32>(tex_atlas[offset + 1u]),
        bitcast<u32>(tex_atlas[offset + 2u]) == FILTER_BILINEAR,
    );
}

// ∫₀^τ R {1, sin, cos}(u_k + t) dt on a piece of length `len` running from v0 to v1 (see the
// f64 form for the formula).
fn piece_moments(v0: vec3<f32>, v1: vec3<f32>, len: f32, tau: f32, cos_k: f32, sin_k: f32) -> RowMoments {
    let beta = (v1 - v0) / len;
    let s = sin(tau);
    let c = cos(tau);
    let half = sin(0.5 * tau);
    let vers = 2.0 * half * half;
    let re = v0 * s + beta * (tau * s - vers);
    let im = v0 * vers + beta * (s - tau * c);
    return RowMoments(v0 * tau + 0.5 * beta * tau * tau, sin_k * re + cos_k * im, cos_k * re - sin_k * im);
}

fn row_entry(t: RowsInfo, j: u32, k: u32) -> RowEntry {
    let o = t.base + 2u * t.width + LATLONG_ROWS_ENTRY_WORDS * (j * (t.width + 1u) + k);
    let v = vec3<f32>(tex_atlas[o + 9u], tex_atlas[o + 10u], tex_atlas[o + 11u]);
    return RowEntry(
        RowMoments(
            vec3<f32>(tex_atlas[o], tex_atlas[o + 1u], tex_atlas[o + 2u]),
            vec3<f32>(tex_atlas[o + 3u], tex_atlas[o + 4u], tex_atlas[o + 5u]),
            vec3<f32>(tex_atlas[o + 6u], tex_atlas[o + 7u], tex_atlas[o + 8u]),
        ),
        v,
    );
}

fn piece_partial(t: RowsInfo, j: u32, k: u32, tau: f32) -> RowMoments {
    let step = 2.0 * PI / f32(t.width);
    let v0 = row_entry(t, j, k).v;
    var v1 = v0;
    if t.bilinear {
        v1 = row_entry(t, j, k + 1u).v;
    }
    let c = tex_atlas[t.base + 2u * k];
    let s = tex_atlas[t.base + 2u * k + 1u];
    return piece_moments(v0, v1, step, tau, c, s);
}

fn cumulative(t: RowsInfo, j: u32, u: f32) -> RowMoments {
    let w = f32(t.width);
    let step = 2.0 * PI / w;
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    let x = (u - u0) / step;
    let turns = floor(x / w);
    let xt = x - turns * w;
    let k = min(u32(max(floor(xt), 0.0)), t.width - 1u);
    let tau = (xt - f32(k)) * step;
    let total = row_entry(t, j, t.width).m;
    let prefix = row_entry(t, j, k).m;
    let part = piece_partial(t, j, k, tau);
    return RowMoments(
        turns * total.q0 + prefix.q0 + part.q0,
        turns * total.qs + prefix.qs + part.qs,
        turns * total.qc + prefix.qc + part.qc,
    );
}

fn row_value(t: RowsInfo, j: u32, hz: Horizon, cos_t: f32, sin_t: f32) -> vec3<f32> {
    let a = hz.ny * cos_t;
    let b = hz.rho * sin_t;
    var q: RowMoments;
    if a >= b {
        q = row_entry(t, j, t.width).m;
    } else if -a >= b {
        return vec3<f32>(0.0);
    } else {
        let alpha = atan2_accurate(sqrt(max(b * b - a * a, 0.0)), -a);
        let hi = cumulative(t, j, hz.psi + alpha);
        let lo = cumulative(t, j, hz.psi - alpha);
        q = RowMoments(hi.q0 - lo.q0, hi.qs - lo.qs, hi.qc - lo.qc);
    }
    return a * q.q0 + sin_t * (hz.p * q.qs + hz.q * q.qc);
}

// The texture rows (j0, j1) the filtered texture blends at θ in piece row r, and j1's weight.
fn row_pair(t: RowsInfo, r: u32, theta: f32) -> RowPair {
    let py = theta / PI * f32(t.height);
    let j1 = min(r, t.height - 1u);
    if t.bilinear {
        return RowPair(min(max(r, 1u) - 1u, t.height - 1u), j1, clamp(py - f32(r) + 0.5, 0.0, 1.0));
    }
    return RowPair(j1, j1, 0.0);
}

fn node_value(t: RowsInfo, r: u32, hz: Horizon, theta: f32) -> vec3<f32> {
    let sin_t = sin(theta);
    let cos_t = cos(theta);
    let rp = row_pair(t, r, theta);
    var v = row_value(t, rp.j0, hz, cos_t, sin_t);
    if rp.j1 != rp.j0 {
        v += (row_value(t, rp.j1, hz, cos_t, sin_t) - v) * rp.fy;
    }
    return sin_t * v;
}

fn interval_integral(t: RowsInfo, r: u32, hz: Horizon, lo: f32, hi: f32, tangent: f32) -> vec3<f32> {
    let above = lo >= tangent;
    var s0 = sqrt(max(tangent - hi, 0.0));
    var s1 = sqrt(max(tangent - lo, 0.0));
    if above {
        s0 = sqrt(max(lo - tangent, 0.0));
        s1 = sqrt(max(hi - tangent, 0.0));
    }
    let len = s1 - s0;
    var sum = vec3<f32>(0.0);
    var g = 0u;
    for (; g < IRR_GL_ROWS; g++) {
        let sigma = s0 + len * IRR_GL_ROWS_X[g];
        let theta = select(tangent - sigma * sigma, tangent + sigma * sigma, above);
        sum += node_value(t, r, hz, theta) * (IRR_GL_ROWS_W[g] * len * 2.0 * sigma);
    }
    if g < IRR_GL_ROWS {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}

fn crossing_theta(hz: Horizon, c: f32) -> f32 {
    let sg = select(-1.0, 1.0, hz.ny >= 0.0);
    return atan2_accurate(abs(hz.ny), -hz.rho * c * sg);
}

// E = ∫ tex(d) max(0, n·d) dd for the dome-space unit normal n.
fn latlong_irradiance(t: RowsInfo, n: vec3<f32>) -> vec3<f32> {
    let p = n.x;
    let q = -n.z;
    let rho = sqrt(p * p + q * q);
    let hz = Horizon(n.y, p, q, rho, atan2_accurate(p, q));
    let w = t.width;
    let h = f32(t.height);
    let step = 2.0 * PI / f32(w);
    let u0 = select(0.0, 0.5 * step, t.bilinear);
    let rows = select(t.height, t.height + 1u, t.bilinear);
    let k_a = ceil((hz.psi - u0) / step);
    let d_a = u0 + k_a * step - hz.psi;
    let n_a = min(u32(max(ceil((PI - d_a) / step), 0.0)), w);
    let n_b = w - n_a;
    let up = hz.ny >= 0.0;
    let sg = select(-1.0, 1.0, up);
    let t_one = atan2_accurate(abs(hz.ny), -hz.rho * sg);
    let t_two = atan2_accurate(abs(hz.ny), hz.rho * sg);
    let tangents = vec2<f32>(min(t_one, t_two), max(t_one, t_two));
    var r = 0u;
    var ia = 0u;
    var ib = 0u;
    var it = 0u;
    var cur = 0.0;
    var sum = vec3<f32>(0.0);
    // W + H + 4 steps; the bound only guards a device whose comparisons misbehave.
    let steps = w + t.height + 8u;
    for (var step_i = 0u; step_i < steps && r < rows; step_i++) {
        var cand_r = PI;
        if r + 1u < rows {
            cand_r = PI * select(f32(r + 1u), f32(r) + 0.5, t.bilinear) / h;
        }
        var cand_a = 1e30;
        if ia < n_a {
            let i = select(ia, n_a - 1u - ia, up);
            cand_a = crossing_theta(hz, cos(d_a + f32(i) * step));
        }
        var cand_b = 1e30;
        if ib < n_b {
            let i = select(ib + 1u, n_b - ib, up);
            cand_b = crossing_theta(hz, cos(d_a - f32(i) * step));
        }
        var cand_t = 1e30;
        if it < 2u {
            cand_t = tangents[it];
        }
        let next = min(min(cand_r, cand_a), min(cand_b, cand_t));
        let hi = max(next, cur);
        if hi > cur {
            // Long intervals (coarse textures) in equal parts of at most IRR_ROWS_MAX_SPAN.
            let count = u32(max(ceil((hi - cur) / IRR_ROWS_MAX_SPAN), 1.0));
            let len = (hi - cur) / f32(count);
            var i = 0u;
            for (; i < count; i++) {
                let a = cur + f32(i) * len;
                let b = select(a + len, hi, i + 1u == count);
                let tangent = select(tangents.x, tangents.y, a >= tangents.y || a - tangents.x > tangents.y - b);
                sum += interval_integral(t, r, hz, a, b, tangent);
            }
            if i < count {
                // Cut short by the device's loop budget (see irr_cut).
                irr_cut = true;
            }
        }
        cur = hi;
        if next == cand_t {
            it++;
        } else if next == cand_a {
            ia++;
        } else if next == cand_b {
            ib++;
        } else {
            r++;
        }
    }
    if r < rows {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}
// #endif
