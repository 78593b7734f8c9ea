// sample(light, x, u): a direction toward one light, its density per unit solid angle and the
// radiance along it; pdf(light, x, ω): the density sample draws ω with (DESIGN.md §9 S1).
// Twin of src/cpu/sample/mod.rs, which carries the strategies (S2) and their reasons.
//
// Rows (src/gpu/sample.rs packs them): in_a holds (point xyz, normal xyz) per row, a zero normal
// standing for none; in_b holds the u32 bits of (light index, point key, sample key, seed). The
// row's u is rng_uniform(seed, point key, sample key, 0 and 1), the CPU's dimensions 0 and 1
// (S3); the light was chosen on the host with dimension 2, so that P(l | x) is the CPU's.
// out_rgb holds (ω xyz, pdf_l, L rgb) per row, pdf_l = −1 standing for +∞ (a delta light).
// pdf_main's rows: in_a as sample_main's, in_b the u32 bits of the light index and the unit ω
// (f32) per row; out_rgb one pdf_l per row (0 for delta lights, S1).
// A textured dome draws its texel and tile from dimensions 3–6 of the same keys (draw passes
// them on), reading its sampling table from the texture atlas (sample/dome.wgsl).
//
// draw is LightAt::new and LightAt::draw in one (WGSL has no enums to carry the strategy).
// GPU-only drawn, fixed: Drawn's two constructors (a drawn density, or a fixed L).
// GPU-only sample_main: the kernel's entry point.
// GPU-only drawn_radiance: LightAt::sample's radiance step (both entry points share it).
// GPU-only sample_resident_main: the GPU-resident kernel's entry point (PreparedScene::
//   encode_sample): the light chosen on the device (sample/select.wgsl), then drawn as
//   sample_main draws it.
// GPU-only light_pdf, pdf_main: LightAt::new and LightAt::pdf in one (cone.wgsl's pdf holds the
//   name), and the pdf kernel's entry point. A rect's Ω comes from rect_sample (its draw is
//   discarded).

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import shared/shaping.wgsl
// #import radiance.wgsl
// #import sample/rng.wgsl
// #import sample/cone.wgsl
// #import sample/rect.wgsl
// #import sample/area.wgsl
// #import sample/dome.wgsl
// #import sample/select.wgsl

struct Drawn {
    dir: vec3<f32>,
    // The density; −1 for a delta light (+∞), 0 where the light delivers nothing.
    pdf: f32,
    // L where the strategy fixes it (delta lights, nothing); else the radiance along dir.
    l: vec3<f32>,
    has_l: bool,
}

fn drawn(dir: vec3<f32>, pdf: f32) -> Drawn {
    return Drawn(dir, pdf, vec3<f32>(0.0), false);
}

fn fixed(dir: vec3<f32>, pdf: f32, l: vec3<f32>) -> Drawn {
    return Drawn(dir, pdf, l, true);
}

// The light's strategy set up for the receiver at x (normal n, zero for none) and drawn for u;
// `keys` (seed, point key, sample key) give a textured dome its further dimensions.
fn draw(light: Record, x: vec3<f32>, n: vec3<f32>, u: vec2<f32>, keys: vec3<u32>) -> Drawn {
    let o = world_origin(light);
    let to = o - x;
    var toward = vec3<f32>(0.0, 1.0, 0.0);
    if length(to) > 0.0 {
        toward = normalize(to);
    } else if length(n) > 0.0 {
        toward = n;
    }
    let nothing = fixed(toward, 0.0, vec3<f32>(0.0));
    if has_flag(light, FLAG_DARK) {
        return nothing;
    }
    let xl = to_local_point(light, x);
    let base = light.base.xyz;
    switch light.kind {
        case KIND_DOME: {
            let s = sample_dome(light, n, u, keys);
            return drawn(s.xyz, s.w);
        }
        case KIND_DISTANT: {
            let theta = light.axis.w;
            if theta == 0.0 {
                return fixed(-light.axis.xyz, -1.0, base);
            }
            let c = with_angle(-light.axis.xyz, theta);
            return drawn(sample(c, u), 1.0 / solid_angle(c));
        }
        case KIND_SPHERE: {
            let r = light.size.x;
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
                // E = base·S(e)·A_proj·cos/d², A_proj = π r² |det M| |M⁻¹ e|.
                let d = length(to);
                if !(d > 0.0) {
                    return nothing;
                }
                let area = PI * r * r * light.irr.y * length(xl) / d;
                return fixed(to / d, -1.0, base * shaping(light, -to / d) * (area / (d * d)));
            }
            if !(length(xl) > r) {
                return nothing;
            }
            if has_flag(light, FLAG_SIMILARITY) && has_flag(light, FLAG_SHAPING) {
                let d = length(to);
                let ball = subtended(to / d, r * length(light.world_x.xyz), d);
                let spot = with_angle(-light.axis.xyz, light.cone.x);
                var c = ball;
                if spot.w < ball.w {
                    c = spot;
                }
                return drawn(sample(c, u), 1.0 / solid_angle(c));
            }
            let s = ellipsoid_sample(light, xl, r, u);
            if !(s.w > 0.0) {
                return fixed(vec3<f32>(0.0, 1.0, 0.0), 0.0, vec3<f32>(0.0));
            }
            return drawn(s.xyz, s.w);
        }
        case KIND_RECT: {
            if !(xl.z < 0.0) {
                return nothing;
            }
            let s = rect_sample(light, x, u);
            if !(s.w > 0.0) {
                return nothing;
            }
            // A spot cone narrower than the rect seen from x is sampled instead (both uniform
            // over a superset of the lit directions; cpu::sample::LightAt::new).
            if has_flag(light, FLAG_SHAPING) {
                let spot = with_angle(-light.axis.xyz, light.cone.x);
                if solid_angle(spot) < s.w {
                    return drawn(sample(spot, u), 1.0 / solid_angle(spot));
                }
            }
            return drawn(s.xyz, 1.0 / s.w);
        }
        case KIND_DISK: {
            if !(xl.z < 0.0) {
                return nothing;
            }
            let s = disk_sample(light, xl, light.size.x, u);
            return drawn(s.xyz, s.w);
        }
        case KIND_CYLINDER: {
            let hl = light.size.x;
            let r = light.size.y;
            let rho = sqrt(xl.y * xl.y + xl.z * xl.z);
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
                // A point uniform by length on the segment; L = k·S(−ω)/|w|³ with
                // k = base·2r·|det M|·ρ·2hl.
                let weight = 2.0 * r * light.irr.y * rho;
                if !(weight > 0.0) || !(hl > 0.0) {
                    return nothing;
                }
                let e = light.world_x.xyz;
                let w = to + e * (hl * (2.0 * u.x - 1.0));
                let d = length(w);
                if !(d > 0.0) {
                    return fixed(normalize(e), -1.0, vec3<f32>(0.0));
                }
                let dir = w / d;
                let k = base * (weight * 2.0 * hl);
                return fixed(dir, -1.0, k * shaping(light, -dir) / (d * d * d));
            }
            if !(rho > r) {
                return nothing;
            }
            let s = cylinder_sample(light, xl, hl, r, u);
            if !(s.w > 0.0) {
                var w = vec3<f32>(0.0, 1.0, 0.0);
                if length(to) > 0.0 {
                    w = normalize(to);
                }
                return fixed(w, 0.0, vec3<f32>(0.0));
            }
            return drawn(s.xyz, s.w);
        }
        default: {}
    }
    return nothing;
}

// The radiance along a drawn direction: the strategy's own L where it fixes one (delta lights,
// nothing), else the light's radiance along it where the density is positive.
fn drawn_radiance(light: Record, x: vec3<f32>, s: Drawn) -> vec3<f32> {
    if s.has_l {
        return s.l;
    }
    return select(vec3<f32>(0.0), radiance(light, x, s.dir), s.pdf > 0.0);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn sample_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = sample_index(gid);
    if i >= params.count {
        return;
    }
    let x = vec3<f32>(in_a[6u * i], in_a[6u * i + 1u], in_a[6u * i + 2u]);
    let n = vec3<f32>(in_a[6u * i + 3u], in_a[6u * i + 4u], in_a[6u * i + 5u]);
    let light = lights[bitcast<u32>(in_b[4u * i])];
    let point = bitcast<u32>(in_b[4u * i + 1u]);
    let smp = bitcast<u32>(in_b[4u * i + 2u]);
    let seed = bitcast<u32>(in_b[4u * i + 3u]);
    let u = vec2<f32>(rng_uniform(seed, point, smp, 0u), rng_uniform(seed, point, smp, 1u));
    let s = draw(light, x, n, u, vec3<u32>(seed, point, smp));
    let l = drawn_radiance(light, x, s);
    let o = 7u * i;
    out_rgb[o] = s.dir.x;
    out_rgb[o + 1u] = s.dir.y;
    out_rgb[o + 2u] = s.dir.z;
    out_rgb[o + 3u] = s.pdf;
    out_rgb[o + 4u] = l.x;
    out_rgb[o + 5u] = l.y;
    out_rgb[o + 6u] = l.z;
}

// The density draw draws the unit w with, for the receiver at x (normal n, zero for none).
fn light_pdf(light: Record, x: vec3<f32>, n: vec3<f32>, w: vec3<f32>) -> f32 {
    if has_flag(light, FLAG_DARK) {
        return 0.0;
    }
    let to = world_origin(light) - x;
    let xl = to_local_point(light, x);
    switch light.kind {
        case KIND_DOME: {
            return pdf_dome(light, n, w);
        }
        case KIND_DISTANT: {
            let theta = light.axis.w;
            if theta == 0.0 {
                return 0.0;
            }
            return pdf(with_angle(-light.axis.xyz, theta), w);
        }
        case KIND_SPHERE: {
            let r = light.size.x;
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) || !(length(xl) > r) {
                return 0.0;
            }
            if has_flag(light, FLAG_SIMILARITY) && has_flag(light, FLAG_SHAPING) {
                let d = length(to);
                let ball = subtended(to / d, r * length(light.world_x.xyz), d);
                let spot = with_angle(-light.axis.xyz, light.cone.x);
                var c = ball;
                if spot.w < ball.w {
                    c = spot;
                }
                return pdf(c, w);
            }
            return ellipsoid_pdf(light, xl, r, w);
        }
        case KIND_RECT: {
            if !(xl.z < 0.0) {
                return 0.0;
            }
            let omega = rect_sample(light, x, vec2<f32>(0.5)).w;
            if !(omega > 0.0) {
                return 0.0;
            }
            if has_flag(light, FLAG_SHAPING) {
                let spot = with_angle(-light.axis.xyz, light.cone.x);
                if solid_angle(spot) < omega {
                    return pdf(spot, w);
                }
            }
            if !rect_hit(xl, to_local_dir(light, w), light.size.x, light.size.y) {
                return 0.0;
            }
            return 1.0 / omega;
        }
        case KIND_DISK: {
            if !(xl.z < 0.0) {
                return 0.0;
            }
            return disk_pdf(light, xl, light.size.x, w);
        }
        case KIND_CYLINDER: {
            let r = light.size.y;
            let rho = sqrt(xl.y * xl.y + xl.z * xl.z);
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) || !(rho > r) {
                return 0.0;
            }
            return cylinder_pdf(light, xl, light.size.x, r, w);
        }
        default: {}
    }
    return 0.0;
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn pdf_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = sample_index(gid);
    if i >= params.count {
        return;
    }
    let x = vec3<f32>(in_a[6u * i], in_a[6u * i + 1u], in_a[6u * i + 2u]);
    let n = vec3<f32>(in_a[6u * i + 3u], in_a[6u * i + 4u], in_a[6u * i + 5u]);
    let light = lights[bitcast<u32>(in_b[4u * i])];
    let w = vec3<f32>(in_b[4u * i + 1u], in_b[4u * i + 2u], in_b[4u * i + 3u]);
    out_rgb[i] = light_pdf(light, x, n, w);
}

// GPU-resident sampling (PreparedScene::encode_sample): params.count = points × K rows, row i is
// sample j = i mod K of point p = i / K (params.per_point = K). in_a holds the caller's points and
// in_b its normals (three packed f32 each; in_b is read only with SELECT_HAS_NORMALS, and a zero
// normal stands for none). The point's key is params.first_point + p (wrapping, as the host's
// u64 → u32 key). out_rgb gets 8 floats a row: ω xyz, P(l | x) · pdf_l (+∞ for a delta light, 0
// where no light reaches the point), L rgb, and the light's index (−1 for none) as an f32.
@compute @workgroup_size(WORKGROUP_SIZE)
fn sample_resident_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = sample_index(gid);
    if i >= params.count {
        return;
    }
    let p = i / params.per_point;
    let j = i - p * params.per_point;
    let x = load3(false, p);
    var n = vec3<f32>(0.0);
    if (params.select & SELECT_HAS_NORMALS) != 0u {
        let m = load3(true, p);
        if length(m) > 0.0 {
            n = normalize(m);
        }
    }
    let key = params.first_point + p;
    let seed = params.seed;
    let c = choose(x, n, rng_uniform(seed, key, j, 2u));
    var dir = select(vec3<f32>(0.0, 1.0, 0.0), n, length(n) > 0.0);
    var pdf = 0.0;
    var l = vec3<f32>(0.0);
    if c.x >= 0.0 {
        let light = lights[u32(c.x)];
        let u = vec2<f32>(rng_uniform(seed, key, j, 0u), rng_uniform(seed, key, j, 1u));
        let s = draw(light, x, n, u, vec3<u32>(seed, key, j));
        dir = s.dir;
        l = drawn_radiance(light, x, s);
        // −1 stands for a delta light's +∞.
        pdf = select(c.y * s.pdf, bitcast<f32>(0x7f800000u), s.pdf < 0.0);
    }
    let o = 8u * i;
    out_rgb[o] = dir.x;
    out_rgb[o + 1u] = dir.y;
    out_rgb[o + 2u] = dir.z;
    out_rgb[o + 3u] = pdf;
    out_rgb[o + 4u] = l.x;
    out_rgb[o + 5u] = l.y;
    out_rgb[o + 6u] = l.z;
    out_rgb[o + 7u] = c.x;
}
