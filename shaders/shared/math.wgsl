// Numerical primitives with accuracy the WGSL builtins do not promise.
//
// No CPU twin: these stand in for f64 builtins (atan2, glam's any_orthonormal_pair).
//
// WGSL only bounds atan/atan2 to 4096 ULP, and lavapipe's atan2 errs by ~1e-6 rad, which the
// angle-space cone smoothstep turns into 1e-4 relative errors near a soft cone edge. This atan2
// is within ~2e-7 rad of the true value on any device (measured against f64 in tests/math.rs).
// Its CPU twin is f64::atan2, which the reference uses.

const PI: f32 = 3.14159265358979;
const HALF_PI: f32 = 1.57079632679490;
const SQRT3: f32 = 1.73205080756888;
// tan(π/12) = 2 − √3
const TAN_PI_12: f32 = 0.26794919243112;

// atan(t) for t in [0, 1].
fn atan_unit(t: f32) -> f32 {
    var x = t;
    var offset = 0.0;
    if x > TAN_PI_12 {
        // atan(t) = π/6 + atan((√3·t − 1) / (√3 + t)), which maps [2−√3, 1] into [0, 2−√3].
        x = (SQRT3 * x - 1.0) / (SQRT3 + x);
        offset = PI / 6.0;
    }
    // Taylor series to x^13 on |x| ≤ 0.268: truncation error < 0.268^15/15 ≈ 2.5e-10.
    let x2 = x * x;
    let p = 1.0 + x2 * (-1.0 / 3.0 + x2 * (1.0 / 5.0 + x2 * (-1.0 / 7.0 + x2 * (1.0 / 9.0 + x2 * (-1.0 / 11.0 + x2 * (1.0 / 13.0))))));
    return offset + x * p;
}

// atan2(y, x) in (−π, π], accurate to ~1 ULP of the result's scale.
fn atan2_accurate(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    let hi = max(ax, ay);
    if hi == 0.0 {
        return 0.0;
    }
    var a = atan_unit(min(ax, ay) / hi);
    if ay > ax {
        a = HALF_PI - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    return select(a, -a, y < 0.0);
}

// Building an orthonormal basis, revisited (Duff et al. 2017), as glam's any_orthonormal_pair.
fn orthonormal_pair_a(v: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, v.z >= 0.0);
    let a = -1.0 / (s + v.z);
    let b = v.x * v.y * a;
    return vec3<f32>(1.0 + s * v.x * v.x * a, s * b, -s * v.x);
}

fn orthonormal_pair_b(v: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, v.z >= 0.0);
    let a = -1.0 / (s + v.z);
    let b = v.x * v.y * a;
    return vec3<f32>(b, s + v.y * v.y * a, -v.y);
}
