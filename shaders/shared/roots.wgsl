// Root finding for the irradiance quadrature's breakpoints. Twin of src/cpu/roots.rs, which
// carries the derivations.
//
// f32: roots are returned in fixed-size vectors with a count or validity mask (no dynamic
//   arrays in WGSL).
// f32: lin_trig_roots takes the arc cosine as atan2_accurate(√(1 − q²), q): f32 acos loses
//   ~1e-4 rad near ±1.
// GPU-only Dirs: the two directions plane_cone_dirs returns (a Vec on the CPU).

// #import shared/math.wgsl

// Roots of A cos t + B sin t = C: (t1, t2, valid).
fn lin_trig_roots(a: f32, b: f32, c: f32) -> vec3<f32> {
    let r = sqrt(a * a + b * b);
    if !(r > 0.0) || abs(c) > r {
        return vec3<f32>(0.0);
    }
    let phi = atan2_accurate(b, a);
    let q = clamp(c / r, -1.0, 1.0);
    let d = atan2_accurate(sqrt(max(1.0 - q * q, 0.0)), q);
    return vec3<f32>(phi + d, phi - d, 1.0);
}

// t wrapped into [t0, t0 + 2π).
fn wrap_into(t: f32, t0: f32) -> f32 {
    let tau = 2.0 * PI;
    return t0 + (t - t0) - floor((t - t0) / tau) * tau;
}

// Real roots of qa t² + 2 qb t + qc = 0: (t1, t2, count).
fn quadratic_roots(qa: f32, qb: f32, qc: f32) -> vec3<f32> {
    if qa == 0.0 {
        if qb != 0.0 {
            return vec3<f32>(-qc / (2.0 * qb), 0.0, 1.0);
        }
        return vec3<f32>(0.0);
    }
    let disc = qb * qb - qa * qc;
    if disc < 0.0 {
        return vec3<f32>(0.0);
    }
    let q = -(qb + select(-1.0, 1.0, qb >= 0.0) * sqrt(disc));
    if q == 0.0 {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    return vec3<f32>(q / qa, qc / q, 2.0);
}

// X where w = a + X e1 lies on the kink cone −ŵ·axis = cs (correct nappe): (x1, x2, count);
// a root failing the nappe test is replaced by NaN-free sentinel via the count mask bits
// (bit 0: x1 valid, bit 1: x2 valid) in z.
fn cone_roots_on_line(axis: vec3<f32>, cs: f32, a: vec3<f32>, e1: vec3<f32>) -> vec3<f32> {
    let c2 = cs * cs;
    let aa = dot(a, axis);
    let ea = dot(e1, axis);
    let r = quadratic_roots(ea * ea - c2 * dot(e1, e1), aa * ea - c2 * dot(a, e1), aa * aa - c2 * dot(a, a));
    var mask = 0u;
    if r.z >= 1.0 && -(aa + r.x * ea) * cs > 0.0 {
        mask |= 1u;
    }
    if r.z >= 2.0 && -(aa + r.y * ea) * cs > 0.0 {
        mask |= 2u;
    }
    return vec3<f32>(r.x, r.y, f32(mask));
}

// Unit vectors w in the plane m·w = 0 with −ŵ·axis = cs: (w1, w2) valid when count > 0.
struct Dirs {
    a: vec3<f32>,
    b: vec3<f32>,
    ok: bool,
}

fn plane_cone_dirs(m: vec3<f32>, axis: vec3<f32>, cs: f32) -> Dirs {
    var out: Dirs;
    out.ok = false;
    let ml = length(m);
    if !(ml > 0.0) {
        return out;
    }
    let h1 = orthonormal_pair_a(m / ml);
    let h2 = orthonormal_pair_b(m / ml);
    let r = lin_trig_roots(dot(h1, axis), dot(h2, axis), -cs);
    if r.z > 0.0 {
        out.a = h1 * cos(r.x) + h2 * sin(r.x);
        out.b = h1 * cos(r.y) + h2 * sin(r.y);
        out.ok = true;
    }
    return out;
}

// X where w = a + X e1 makes its smallest (or largest) angle with the axis: (x, valid).
fn axis_approach(axis: vec3<f32>, a: vec3<f32>, e1: vec3<f32>) -> vec2<f32> {
    let ap = dot(a, axis);
    let ep = dot(e1, axis);
    let ae = dot(a, e1);
    let den = ep * ae - ap * dot(e1, e1);
    if den == 0.0 {
        return vec2<f32>(0.0);
    }
    return vec2<f32>((ap * ae - ep * dot(a, a)) / den, 1.0);
}
