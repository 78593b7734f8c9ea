// The inner (line) integrals of the chart quadrature. Twin of src/cpu/irradiance/line.rs,
// which carries the derivations.
//
// f32: the kernel's inner rule: per span IRR_GL_INNER-point Gauss–Legendre, halved while the
//   halves and their parent differ by more than IRR_INNER_TOL (relative; the integrand is ≥ 0),
//   at most IRR_INNER_DEPTH times, depth first, instead of the reference's globally adaptive
//   Gauss–Kronrod; tan-mapped pieces are cut into spans of at most IRR_MAX_U_SPAN radians. Its
//   f64 replay is testkit::kernel_rule.
// f32: an unshaped line piece takes the closed form only where it is tan-mapped (there its terms
//   cannot cancel), else the inner rule (the CPU: the closed form everywhere).
// f32: at most MAX_BPS breakpoints per line besides an IES profile's, which are streamed: the
//   CPU lists the profile's cones and planes that can meet the chart and sorts all their roots;
//   the kernel, which has no array of a profile's size, walks the cones (planes) a line crosses
//   in the order it crosses them, as a run of the list sorted by cosine (azimuth) on each side
//   of the cosine's extremum (the pencil's closest approach), found by binary search
//   (irradiance/kinks.wgsl), and merges them with
//   the fixed breakpoints. A crossing is the quadratic's root on its side, clamped to the side.
//   The two split points are fixed breakpoints too (the CPU has no such points): a crossing
//   exactly there (an axis-aligned line meeting a plane of the pencil at its closest approach)
//   belongs to neither side's run.
// f32: every loop checks its own condition after it ends and sets irr_cut if it stopped short
//   (lavapipe's loop budget, see shared/record.wgsl); the CPU has no such limit.
// f32: a textured rect's vertical break lines (texel-centre lines, bilinear; texel edges,
//   nearest) are streamed too (texel_break_after: they are evenly spaced, so the next one after
//   X is a closed form); the CPU lists them (rect_texture::ChartTexture::xs) with the rest.
// GPU-only inner_node, inner_rule, max3, inner_adaptive: the kernel's inner rule (above).
// GPU-only line_piece: the body of the CPU's loop over pieces, a function here because the
//   merge loop above calls it once per piece.
// GPU-only TexelAxis, texel_axis, texel_break_after, rect_texture_factor: the streamed texel
//   lines (above) and the texture factor of the integrand (the CPU:
//   rect_texture::ChartTexture::value).

// #import shared/record.wgsl
// #import shared/shaping.wgsl
// #import shared/roots.wgsl
// #import irradiance/pieces.wgsl
// #import irradiance/kinks.wgsl
// #import shared/texture.wgsl

const MAX_BPS: u32 = 14u;

// Node k of the inner Gauss–Legendre rule on [s0, s0 + h] of one span's parameter.
fn inner_node(light: Record, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, y: f32, sp: PieceMap, s0: f32, h: f32, k: u32) -> vec3<f32> {
    let xd = map_eval(sp, s0 + h * IRR_GL_INNER_X[k], false);
    let w = a + e1 * xd.x;
    let nw = dot(n, w);
    if nw > 0.0 && xd.y != 0.0 {
        let l2 = dot(w, w);
        let e = -w / sqrt(l2);
        return shaping(light, e) * rect_texture_factor(light, xd.x, y) * (IRR_GL_INNER_W[k] * h * nw / (l2 * l2) * xd.y);
    }
    return vec3<f32>(0.0);
}

// The inner rule on [s0, s1], its IRR_GL_INNER = 10 nodes written out rather than looped:
// llvmpipe stops a shader invocation's loops after 65535 iterations in total (see
// GpuContext::lights_per_dispatch), and this is the innermost, most repeated loop.
fn inner_rule(light: Record, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, y: f32, sp: PieceMap, s0: f32, s1: f32) -> vec3<f32> {
    let h = s1 - s0;
    return inner_node(light, n, a, e1, y, sp, s0, h, 0u) + inner_node(light, n, a, e1, y, sp, s0, h, 1u)
        + inner_node(light, n, a, e1, y, sp, s0, h, 2u) + inner_node(light, n, a, e1, y, sp, s0, h, 3u)
        + inner_node(light, n, a, e1, y, sp, s0, h, 4u) + inner_node(light, n, a, e1, y, sp, s0, h, 5u)
        + inner_node(light, n, a, e1, y, sp, s0, h, 6u) + inner_node(light, n, a, e1, y, sp, s0, h, 7u)
        + inner_node(light, n, a, e1, y, sp, s0, h, 8u) + inner_node(light, n, a, e1, y, sp, s0, h, 9u);
}

fn max3(v: vec3<f32>) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// One span by halving until the halves agree with their parent to IRR_INNER_TOL (relative; the
// integrand is ≥ 0) or IRR_INNER_DEPTH is reached, depth first (the CPU twin: Nodes::integrate
// in src/cpu/irradiance.rs). A depth-first stack never holds more than depth + 1 entries.
// Each pass of the loop applies the rule to one interval (the span, then the left and the right
// half of the interval in hand), so that the rule, inlined with its ten shaping calls, is
// compiled once rather than three times: on lavapipe those copies were half of the irradiance
// pipeline's compile. The halves are compared and summed in the same order as before (and as
// testkit::kernel_rule replays); the loop runs once per rule, 1 + 2 per halving, well inside
// llvmpipe's loop budget (see GpuContext::lights_per_dispatch).
fn inner_adaptive(light: Record, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, y: f32, sp: PieceMap) -> vec3<f32> {
    var lo: array<f32, IRR_INNER_DEPTH + 1u>;
    var hi: array<f32, IRR_INNER_DEPTH + 1u>;
    var q: array<vec3<f32>, IRR_INNER_DEPTH + 1u>;
    var dep: array<u32, IRR_INNER_DEPTH + 1u>;
    var top = 0u;
    var sum = vec3<f32>(0.0);
    // The interval in hand [p0, p1] at depth d with its own rule's value `parent`; `step` says
    // which rule this pass applies: 0 the whole span's, 1 the left half's, 2 the right half's.
    var p0 = 0.0;
    var p1 = 1.0;
    var d = 0u;
    var parent = vec3<f32>(0.0);
    var ql = vec3<f32>(0.0);
    var step = 0u;
    var done = false;
    loop {
        let mid = 0.5 * (p0 + p1);
        let r = inner_rule(light, n, a, e1, y, sp, select(p0, mid, step == 2u), select(p1, mid, step == 1u));
        if step == 0u {
            parent = r;
            step = 1u;
            continue;
        }
        if step == 1u {
            ql = r;
            step = 2u;
            continue;
        }
        let qr = r;
        let fine = ql + qr;
        if d + 1u >= IRR_INNER_DEPTH || max3(abs(fine - parent)) <= IRR_INNER_TOL * max3(abs(fine)) {
            sum += fine;
            if top == 0u {
                done = true;
                break;
            }
            top -= 1u;
            p0 = lo[top];
            p1 = hi[top];
            parent = q[top];
            d = dep[top];
        } else {
            // The right half waits on the stack; the left half is next.
            lo[top] = mid;
            hi[top] = p1;
            q[top] = qr;
            dep[top] = d + 1u;
            top += 1u;
            p1 = mid;
            parent = ql;
            d += 1u;
        }
        step = 1u;
    }
    if !done {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}

// ∫ S(−ŵ)·max(0, n·w)/|w|⁴ dX along w = a + X e1, X ∈ [x0, x1], the line Y = y of the chart
// (y is read only for a textured rect's texture factor).
fn line_integral(light: Record, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, y: f32, x0: f32, x1: f32) -> vec3<f32> {
    let na = dot(n, a);
    let ne = dot(n, e1);
    var lo = x0;
    var hi = x1;
    if ne > 0.0 {
        lo = max(lo, -na / ne);
    } else if ne < 0.0 {
        hi = min(hi, -na / ne);
    } else if !(na > 0.0) {
        return vec3<f32>(0.0);
    }
    if !(hi > lo) {
        return vec3<f32>(0.0);
    }
    // Breakpoints (value, graded) inside [lo, hi].
    var bp: array<f32, MAX_BPS>;
    var graded: array<u32, MAX_BPS>;
    bp[0] = lo;
    graded[0] = 0u;
    bp[1] = hi;
    graded[1] = 0u;
    var count = 2u;
    let axis = light.axis.xyz;
    {
        var ci = 0u;
        for (; ci < kink_count(light); ci++) {
            let r = cone_roots_on_line(axis, kink_cos(light, ci), a, e1);
            let mask = u32(r.z);
            if (mask & 1u) != 0u && r.x > lo && r.x < hi {
                bp[count] = r.x;
                graded[count] = 0u;
                count += 1u;
            }
            if (mask & 2u) != 0u && r.y > lo && r.y < hi {
                bp[count] = r.y;
                graded[count] = 0u;
                count += 1u;
            }
        }
        if ci < kink_count(light) {
            // Cut short by the device's loop budget (see irr_cut).
            irr_cut = true;
        }
    }
    if has_flag(light, FLAG_FOCUS_PLANE) {
        let den = dot(axis, e1);
        if den != 0.0 {
            let xf = -dot(axis, a) / den;
            if xf > lo && xf < hi {
                bp[count] = xf;
                graded[count] = select(0u, 1u, has_flag(light, FLAG_FOCUS_GRADED));
                count += 1u;
            }
        }
    }
    if has_flag(light, FLAG_AXIS_SINGULAR) {
        let xa = axis_approach(axis, a, e1);
        if xa.y > 0.0 && xa.x > lo && xa.x < hi {
            bp[count] = xa.x;
            graded[count] = 0u;
            count += 1u;
        }
    }
    // An IES profile's planes that are not in its pencil (a cone of 90°) are fixed breakpoints;
    // its cones and the pencil's planes are streamed below.
    let has_ies = has_flag(light, FLAG_IES);
    let kb = u32(light.ies.w);
    let al = to_local_dir(light, a);
    let el = to_local_dir(light, e1);
    if has_ies {
        // The streams' split points too (where the line is nearest the cone axis and the
        // pencil's axis): a crossing exactly there (an axis-aligned line through a plane of
        // the pencil, a cone touched) belongs to neither side's run.
        let axis_c = kink_vec(kb, 1u);
        let xe = axis_approach(axis_c, al, el);
        if ies_atlas[kb] > 0.0 && xe.y > 0.0 && xe.x > lo && xe.x < hi {
            bp[count] = xe.x;
            graded[count] = 0u;
            count += 1u;
        }
        let axis_p = kink_vec(kb, 5u);
        let ep = el - axis_p * dot(el, axis_p);
        if ies_atlas[kb + 4u] > 0.0 && dot(ep, ep) > 0.0 {
            let xp = -dot(al, ep) / dot(ep, ep);
            if xp > lo && xp < hi {
                bp[count] = xp;
                graded[count] = 0u;
                count += 1u;
            }
        }
        let extra = u32(ies_atlas[kb + 11u]);
        {
            var k = 0u;
            for (; k < extra; k++) {
                let o = kb + 12u + 3u * k;
                let m = kink_vec(o, 0u);
                let den = dot(m, el);
                if den != 0.0 {
                    let xk = -dot(m, al) / den;
                    if xk > lo && xk < hi {
                        bp[count] = xk;
                        graded[count] = 0u;
                        count += 1u;
                    }
                }
            }
            if k < extra {
                // Cut short by the device's loop budget (see irr_cut).
                irr_cut = true;
            }
        }
    }
    {
        var i = 1u;
        for (; i < count; i++) {
            let v = bp[i];
            let g = graded[i];
            var j = i;
            while j > 0u && bp[j - 1u] > v {
                bp[j] = bp[j - 1u];
                graded[j] = graded[j - 1u];
                j -= 1u;
            }
            if j > 0u && bp[j - 1u] > v {
                // Cut short by the device's loop budget (see irr_cut).
                irr_cut = true;
            }
            bp[j] = v;
            graded[j] = g;
        }
        if i < count {
            // Cut short by the device's loop budget (see irr_cut).
            irr_cut = true;
        }
    }
    // The line's closest approach to x: X* and the width √m/|e1|, m = |a × e1|²/|e1|².
    let e12 = dot(e1, e1);
    let x_star = -dot(a, e1) / e12;
    let perp = a + e1 * x_star;
    let cr = length(cross(a, e1));
    let width = cr / e12;
    let m = cr * cr / e12;
    // (The closed form has no texture factor.)
    let unshaped = !has_flag(light, FLAG_SHAPING) && !has_flag(light, FLAG_RECT_TEXTURE);
    // A textured rect's vertical break lines, streamed (see the header); none without one.
    let tex_cols = texel_axis(light, true);
    var tex_next = texel_break_after(tex_cols, lo);
    // The streamed IES crossings (see the header); none without a profile.
    var cones: KinkRun;
    cones.next = 1e30;
    var planes: KinkRun;
    planes.next = 1e30;
    if has_ies {
        cones = cone_run(kb, al, el, lo, hi);
        planes = plane_run(kb, al, el, lo, hi);
    }
    var sum = vec3<f32>(0.0);
    // Pieces [t0, t1] between consecutive breakpoints of the fixed list (index fi next) merged
    // with the two runs.
    var t0 = bp[0];
    var gr0 = graded[0];
    var fi = 1u;
    var done = false;
    loop {
        var t1 = bp[fi];
        var gr1 = graded[fi];
        var src_kind = 0u;
        if cones.next < t1 {
            t1 = cones.next;
            gr1 = 0u;
            src_kind = 1u;
        }
        if planes.next < t1 {
            t1 = planes.next;
            gr1 = 0u;
            src_kind = 2u;
        }
        if tex_next < t1 {
            t1 = tex_next;
            gr1 = 0u;
            src_kind = 3u;
        }
        if t1 > t0 {
            sum += line_piece(light, n, a, e1, y, t0, t1, gr0 != 0u, gr1 != 0u, x_star, width, m, perp, unshaped);
            t0 = t1;
        }
        gr0 = gr1;
        if src_kind == 1u {
            cones = run_next(cones, kb, al, el, true, true);
        } else if src_kind == 2u {
            planes = run_next(planes, kb, al, el, false, true);
        } else if src_kind == 3u {
            tex_next = texel_break_after(tex_cols, t1);
        } else {
            fi += 1u;
            if fi >= count {
                done = true;
                break;
            }
        }
    }
    if !done {
        // Cut short by the device's loop budget (see irr_cut).
        irr_cut = true;
    }
    return sum;
}

// One smooth piece [t0, t1] of a line (g0, g1: whether its ends are graded), see line_integral.
fn line_piece(light: Record, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, y: f32, t0: f32, t1: f32, g0: bool, g1: bool, x_star: f32, width: f32, m: f32, perp: vec3<f32>, unshaped: bool) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    let pm = piece_map(t0, t1, x_star, width, false, false);
    if unshaped && pm.tan_map && m > 0.0 {
        // (n·w)/|w|⁴ dX = (width/m²)(n·perp cos²u + width n·e1 sin u cos u) du.
        let ne = dot(n, e1);
        let np = dot(n, perp);
        let nw = ne * width;
        let p1 = np * (0.5 * pm.u1 + 0.25 * sin(2.0 * pm.u1)) + nw * 0.5 * sin(pm.u1) * sin(pm.u1);
        let p0 = np * (0.5 * pm.u0 + 0.25 * sin(2.0 * pm.u0)) + nw * 0.5 * sin(pm.u0) * sin(pm.u0);
        return vec3<f32>(max(width / (m * m) * (p1 - p0), 0.0));
    }
    {
        // Grade only the quarter next to a graded end (see graded_parts in the CPU twin).
        let q = 0.25 * (t1 - t0);
        var cuts = array<f32, 4>(t0, t0, t1, t1);
        if g0 {
            cuts[1] = t0 + q;
        }
        if g1 {
            cuts[2] = t1 - q;
        }
        {
            var part = 0u;
            for (; part < 3u; part++) {
                let p0 = cuts[part];
                let p1 = cuts[part + 1u];
                if !(p1 > p0) {
                    continue;
                }
                let pp = piece_map(p0, p1, x_star, width, part == 0u && g0, part == 2u && g1);
                let spans = span_count(pp);
                {
                    var j = 0u;
                    for (; j < spans; j++) {
                        sum += inner_adaptive(light, n, a, e1, y, span(pp, j, spans));
                    }
                    if j < spans {
                        // Cut short by the device's loop budget (see irr_cut).
                        irr_cut = true;
                    }
                }
            }
            if part < 3u {
                // Cut short by the device's loop budget (see irr_cut).
                irr_cut = true;
            }
        }
    }
    return sum;
}

// The break lines of one axis of a textured rect's texture in chart coordinates (X = 1 − 2s,
// Y = 1 − 2t, src/cpu/irradiance/rect_texture.rs): `n` texels, `c` 1 for texel-centre lines
// (bilinear: −1 + (2j + 1)/n, j = 0 … n − 1; none for one texel, whose reconstruction is
// constant) or 0 for texel edges (nearest: −1 + 2j/n, j = 1 … n − 1), the ends of
// prepare::texture::axis_pieces. n = 0: no texture, no lines.
struct TexelAxis {
    n: f32,
    c: f32,
}

// The horizontal (columns = true: the vertical) break lines of `light`'s texture when it is a
// textured rect integrated here; none otherwise (and in a pipeline built without TEXTURE).
fn texel_axis(light: Record, columns: bool) -> TexelAxis {
    var axis = TexelAxis(0.0, 0.0);
    // #if TEXTURE
    if has_flag(light, FLAG_RECT_TEXTURE) {
        let t = tex_info(light.tex.x);
        let nearest = light.tex.y == FILTER_NEAREST;
        let n = select(t.height, t.width, columns);
        if nearest || n >= 2u {
            axis = TexelAxis(f32(n), select(1.0, 0.0, nearest));
        }
    }
    // #endif
    return axis;
}

// The first break line of `axis` strictly after chart coordinate `t` (1e30 when none): the
// lines are evenly spaced, so its index is a closed form (corrected once for rounding).
fn texel_break_after(axis: TexelAxis, t: f32) -> f32 {
    if axis.n == 0.0 {
        return 1e30;
    }
    var j = max(floor(((t + 1.0) * axis.n - axis.c) * 0.5) + 1.0, 1.0 - axis.c);
    var x = -1.0 + (2.0 * j + axis.c) / axis.n;
    if x <= t {
        j += 1.0;
        x = -1.0 + (2.0 * j + axis.c) / axis.n;
    }
    if j > axis.n - 1.0 {
        return 1e30;
    }
    return x;
}

// The texture factor of the integrand at chart point (X, Y) of a textured rect: the filtered
// texture at s = (1 − X)/2, t = (1 − Y)/2 (rect_texel's local (x, y) over a 2 × 2 square); 1
// for every other light.
fn rect_texture_factor(light: Record, x: f32, y: f32) -> vec3<f32> {
    // #if TEXTURE
    if has_flag(light, FLAG_RECT_TEXTURE) {
        return rect_texel(light.tex.x, x, y, 2.0, 2.0, light.tex.y);
    }
    // #endif
    return vec3<f32>(1.0);
}
