// Directions uniform in a cone (f32): the sphere seen from outside, a distant light's disc and a
// spot's cone (DESIGN.md §9 S2). Twin of src/cpu/sample/cone.rs.
//
// A cone is a vec4: xyz its unit axis, w its 1 − cos θ (computed cancellation-free, as the CPU
// does, so that tiny cones such as the sun's keep their digits).
// f32: basis takes the sign of n.z from its sign bit, as f64::copysign does (−0 gives −1), so
//   that both paths build the same frame wherever n.z has the same sign on both.

// #import shared/math.wgsl

// The cone of half-angle theta (0 ≤ θ ≤ π): 1 − cos θ = 2 sin²(θ/2).
fn with_angle(axis: vec3<f32>, theta: f32) -> vec4<f32> {
    let s = sin(0.5 * clamp(theta, 0.0, PI));
    return vec4<f32>(axis, 2.0 * s * s);
}

// The cone a sphere of radius r at distance d > r subtends: 1 − cos α = (r/d)² / (1 + √(1 − (r/d)²)).
fn subtended(axis: vec3<f32>, r: f32, d: f32) -> vec4<f32> {
    let s2 = (r / d) * (r / d);
    return vec4<f32>(axis, s2 / (1.0 + sqrt(max(1.0 - s2, 0.0))));
}

// Its solid angle, 2π (1 − cos θ).
fn solid_angle(c: vec4<f32>) -> f32 {
    return 2.0 * PI * c.w;
}

// A direction uniform in the cone: cos uniform in [cos θ, 1], azimuth uniform.
fn sample(c: vec4<f32>, u: vec2<f32>) -> vec3<f32> {
    let omc = u.x * c.w;
    let cs = 1.0 - omc;
    let sn = sqrt(max(omc * (2.0 - omc), 0.0));
    let phi = 2.0 * PI * u.y;
    let b = basis(c.xyz);
    return normalize(b[0] * (sn * cos(phi)) + b[1] * (sn * sin(phi)) + c.xyz * cs);
}

// Whether the unit w lies in the cone (boundary included): 1 − cos from the chord, |w − axis|²/2.
fn contains(c: vec4<f32>, w: vec3<f32>) -> bool {
    let chord = w - c.xyz;
    return 0.5 * dot(chord, chord) <= c.w;
}

// The uniform density, 1/Ω inside and 0 outside.
fn pdf(c: vec4<f32>, w: vec3<f32>) -> f32 {
    return select(0.0, 1.0 / solid_angle(c), contains(c, w));
}

// An orthonormal pair completing the unit n to a right-handed frame (Duff et al. 2017, Listing 3).
fn basis(n: vec3<f32>) -> mat2x3<f32> {
    let sign = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y),
    );
}
