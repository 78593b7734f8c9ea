// The closed forms of irradiance. Twin of src/cpu/irradiance/closed.rs, which carries the
// derivations and citations.
//
// f32: asin_minus_x switches to its series below k = 0.5 (the CPU at 0.1): in f32 the atan2
//   form cancels up to k ≈ 0.5.
// f32: a cap whose centre is below the horizon is integrated over elevation (cap_sliver):
//   the closed form's terms are O(α²|γ|) and its value can be far smaller.
// GPU-only cap_sliver: see above.
// GPU-only rect_above_horizon: the kernel leaves a rect clipped by the receiver's horizon to
//   the quadrature (a clipped sliver cancels like its thinness in f32), see irradiance.wgsl.
// f32: rect_lambert is the CPU's rect_lambert and polygon_irradiance in one function.
// f32: clip_above takes at most 4 vertices (a rect's, a triangle's) and returns at most 6 in a
//   fixed array (ClippedPolygon); the CPU's takes a slice and returns a Vec.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import shared/shaping.wgsl

// asin(k) − k given kc = √(1 − k²): the series where the difference cancels.
fn asin_minus_x(k: f32, kc: f32) -> f32 {
    if k > 0.5 {
        return atan2_accurate(k, kc) - k;
    }
    // Σ_{j≥1} (2j)!/(4^j (j!)² (2j+1)) k^(2j+1); ten terms: truncation < 1e-7 relative at 0.5.
    let k2 = k * k;
    var c = 1.0;
    var p = k;
    var sum = 0.0;
    for (var j = 1; j <= 10; j++) {
        c *= f32(2 * j - 1) / f32(2 * j);
        p *= k2;
        sum += c * p / f32(2 * j + 1);
    }
    return sum;
}

// The clipped cap for α ≤ π/2 (see cap_irradiance).
fn cap_within_hemisphere(alpha: f32, sg: f32, cg: f32) -> f32 {
    let sa = sin(alpha);
    let ca = cos(alpha);
    let gamma = atan2_accurate(sg, cg);
    if gamma >= alpha {
        return PI * sa * sa * sg;
    }
    if gamma <= -alpha {
        return 0.0;
    }
    if gamma < 0.0 {
        // Centre below the horizon: the closed form's terms are O(α²|γ|) and its value can be
        // far smaller, so in f32 integrate the part above the horizon directly (cap_sliver).
        return cap_sliver(alpha, gamma);
    }
    let t = sg * ca / (cg * sa);
    let root = sqrt(max(sin(alpha - gamma) * sin(alpha + gamma), 0.0));
    let k = min(root / cg, 1.0);
    let sin_phi0 = root / (cg * sa);
    let phi0 = atan2_accurate(sin_phi0, -t);
    let h = sin(0.5 * alpha);
    let g = sin(0.5 * gamma);
    return phi0 * sa * sa * sg + asin_minus_x(k, ca / cg) + k * (2.0 * h * h + 2.0 * ca * g * g);
}

// The part of the cap (half-angle alpha, centre at elevation gamma < 0) above the horizon, as
// ∫₀^top sin t cos t · 2ψ(t) dt over the elevation t, top = α + γ, where ±ψ(t) bounds the cap's
// azimuth at elevation t: cos ψ = (cos α − sin t sin γ)/(cos t cos γ), so
// sin²(ψ/2) = sin((α + t − γ)/2) sin((α − t + γ)/2)/(cos t cos γ) without cancellation. ψ
// vanishes like √(top − t); t = top·(1 − s²) makes the integrand smooth in s for the fixed rule.
// All terms are positive.
fn cap_sliver(alpha: f32, gamma: f32) -> f32 {
    let top = alpha + gamma;
    let cg = cos(gamma);
    var sum = 0.0;
    for (var k = 0u; k < IRR_GL_CAP; k++) {
        let s = IRR_GL_CAP_X[k];
        let t = top * (1.0 - s * s);
        let q = sin(0.5 * (alpha + t - gamma)) * sin(0.5 * (top - t)) / (cos(t) * cg);
        let sh = sqrt(clamp(q, 0.0, 1.0));
        let psi = 2.0 * atan2_accurate(sh, sqrt(max(1.0 - sh * sh, 0.0)));
        sum += IRR_GL_CAP_W[k] * sin(t) * cos(t) * 2.0 * psi * 2.0 * top * s;
    }
    return sum;
}

// ∫ max(0, n·ω) dω over the cap of half-angle alpha around c; sg = n·c, cg = |n × c|.
fn cap_irradiance(alpha: f32, sg: f32, cg: f32) -> f32 {
    if !(alpha > 0.0) {
        return 0.0;
    }
    if alpha > HALF_PI {
        let ac = PI - alpha;
        let gamma = atan2_accurate(sg, cg);
        if -gamma >= ac {
            let sa = sin(ac);
            let ca = cos(ac);
            let q = sin(0.5 * (HALF_PI - abs(gamma)));
            return PI * (ca * ca + sa * sa * 2.0 * q * q);
        }
        return PI - cap_within_hemisphere(ac, -sg, cg);
    }
    return cap_within_hemisphere(alpha, sg, cg);
}

// Unit-radiance irradiance of a uniform sphere of world radius r centred at o.
fn sphere_cap(o: vec3<f32>, r: f32, x: vec3<f32>, n: vec3<f32>) -> f32 {
    let w = o - x;
    let d = length(w);
    if !(d > r) {
        return 0.0;
    }
    let c = w / d;
    let alpha = atan2_accurate(r, sqrt((d - r) * (d + r)));
    return cap_irradiance(alpha, dot(n, c), length(cross(n, c)));
}

// Lambert's formula on the rect's parallelogram clipped to n·(P − x) ≥ 0.
fn rect_lambert(light: Record, x: vec3<f32>, n: vec3<f32>) -> f32 {
    let o = world_origin(light) - x;
    let a = light.world_x.xyz * light.size.x;
    let b = light.world_y.xyz * light.size.y;
    let q = array<vec3<f32>, 4>(o - a - b, o + a - b, o + a + b, o - a + b);
    let sigma = sign(dot(cross(q[1] - q[0], q[2] - q[1]), q[0]));
    let clipped = clip_above(q, 4u, n);
    let count = clipped.count;
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        let p0 = clipped.p[i];
        let p1 = clipped.p[(i + 1u) % count];
        let c = cross(p0, p1);
        let len = length(c);
        if len > 0.0 {
            sum += atan2_accurate(len, dot(p0, p1)) * dot(n, c) / len;
        }
    }
    return max(0.5 * sigma * sum, 0.0);
}

// A polygon of at most 6 vertices (vectors from x): what clip_above returns.
struct ClippedPolygon {
    p: array<vec3<f32>, 6>,
    count: u32,
}

// The polygon q[0..k] (vectors from x, k ≤ 4) clipped to the receiver's upper half-space
// n·ω ≥ 0 (Sutherland & Hodgman 1974): rect_lambert's and mesh/lambert.wgsl's
// triangle_lambert's horizon.
fn clip_above(q: array<vec3<f32>, 4>, k: u32, n: vec3<f32>) -> ClippedPolygon {
    var out: ClippedPolygon;
    out.count = 0u;
    for (var i = 0u; i < k; i++) {
        let p0 = q[i];
        let p1 = q[(i + 1u) % k];
        let d0 = dot(n, p0);
        let d1 = dot(n, p1);
        if d0 >= 0.0 {
            out.p[out.count] = p0;
            out.count += 1u;
        }
        if (d0 >= 0.0) != (d1 >= 0.0) {
            out.p[out.count] = p0 + (p1 - p0) * (d0 / (d0 - d1));
            out.count += 1u;
        }
    }
    return out;
}

// Whether the whole rect lies above the receiver's horizon (Lambert's sum is then a sum of
// like-signed terms up to the d/size cancellation; a clipped sliver is left to the quadrature).
fn rect_above_horizon(light: Record, x: vec3<f32>, n: vec3<f32>) -> bool {
    let o = world_origin(light) - x;
    let a = light.world_x.xyz * light.size.x;
    let b = light.world_y.xyz * light.size.y;
    return min(min(dot(n, o - a - b), dot(n, o + a - b)), min(dot(n, o + a + b), dot(n, o - a + b))) > 0.0;
}

// treatAsPoint: intensity L(e)·π r² |det M| |M⁻¹e| from the origin.
fn point_irradiance(light: Record, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let w = world_origin(light) - x;
    let d = length(w);
    if !(d > 0.0) {
        return vec3<f32>(0.0);
    }
    let cos_r = dot(n, w) / d;
    if !(cos_r > 0.0) {
        return vec3<f32>(0.0);
    }
    let e = -w / d;
    let xl = to_local_point(light, x);
    let r = light.size.x;
    let area = PI * r * r * light.irr.y * length(xl) / d;
    return light.base.xyz * shaping(light, e) * (area * cos_r / (d * d));
}
