// irradiance(x, n): diffuse · ∫ radiance(x, ω) max(0, n·ω) dω (DESIGN.md §3).
// Twin of src/cpu/irradiance.rs, which carries the derivations and spec citations; functions
// here have the names of their CPU twins. Differences, all for f32:
// - per span, a Gauss–Kronrod 7/15 outer rule and an IRR_GL_INNER-point Gauss–Legendre inner
//   rule, each halved locally while its error test fails (depth-limited, see gpu::pack), instead
//   of the reference's global adaptive Gauss–Kronrod, on the same pieces and substitutions;
// - cone crossings on elliptic arcs bracketed on IRR_ARC_SAMPLES samples;
// - an unshaped rect goes to the quadrature (all positive terms) rather than Lambert's formula
//   when (d / smaller half-extent)·(d / height above its plane) exceeds IRR_LAMBERT_COND
//   (Lambert's edge terms cancel like each factor), or when it is cut by the receiver's horizon
//   (a clipped sliver cancels like its thinness);
// - a cap whose centre is below the horizon is integrated over elevation (cap_sliver).

// #import shared/light.wgsl
// #import shared/math.wgsl
// #import shared/shaping.wgsl

const MAX_YS: u32 = 48u;
const MAX_BPS: u32 = 10u;
const REGION_SQUARE: u32 = 0u;
const REGION_DISK: u32 = 1u;
const REGION_CYLINDER: u32 = 2u;

// ---------------------------------------------------------------------------------------------
// Closed forms
// ---------------------------------------------------------------------------------------------

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
fn rect_lambert(light: Light, x: vec3<f32>, n: vec3<f32>) -> f32 {
    let o = world_origin(light) - x;
    let a = light.world_x.xyz * light.size.x;
    let b = light.world_y.xyz * light.size.y;
    var q = array<vec3<f32>, 4>(o - a - b, o + a - b, o + a + b, o - a + b);
    let sigma = sign(dot(cross(q[1] - q[0], q[2] - q[1]), q[0]));
    var clipped: array<vec3<f32>, 6>;
    var count = 0u;
    for (var i = 0u; i < 4u; i++) {
        let p0 = q[i];
        let p1 = q[(i + 1u) % 4u];
        let d0 = dot(n, p0);
        let d1 = dot(n, p1);
        if d0 >= 0.0 {
            clipped[count] = p0;
            count += 1u;
        }
        if (d0 >= 0.0) != (d1 >= 0.0) {
            clipped[count] = p0 + (p1 - p0) * (d0 / (d0 - d1));
            count += 1u;
        }
    }
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        let p0 = clipped[i];
        let p1 = clipped[(i + 1u) % count];
        let c = cross(p0, p1);
        let len = length(c);
        if len > 0.0 {
            sum += atan2_accurate(len, dot(p0, p1)) * dot(n, c) / len;
        }
    }
    return max(0.5 * sigma * sum, 0.0);
}

// Whether the whole rect lies above the receiver's horizon (Lambert's sum is then a sum of
// like-signed terms up to the d/size cancellation; a clipped sliver is left to the quadrature).
fn rect_above_horizon(light: Light, x: vec3<f32>, n: vec3<f32>) -> bool {
    let o = world_origin(light) - x;
    let a = light.world_x.xyz * light.size.x;
    let b = light.world_y.xyz * light.size.y;
    return min(min(dot(n, o - a - b), dot(n, o + a - b)), min(dot(n, o + a + b), dot(n, o - a + b))) > 0.0;
}

// treatAsPoint: intensity L(e)·π r² |det M| |M⁻¹e| from the origin.
fn point_irradiance(light: Light, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
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

// ---------------------------------------------------------------------------------------------
// Quadrature
// ---------------------------------------------------------------------------------------------

// A plane chart of the directions x sees the light in: w(X, Y) = w0 + X e1 + Y e2.
struct Chart {
    w0: vec3<f32>,
    e1: vec3<f32>,
    e2: vec3<f32>,
    jac: f32,
    region: u32,
    ya: f32,
    yb: f32,
    // Cylinder: x at axial xa and distance rho from the axis; radius r, half length hl.
    xa: f32,
    rho: f32,
    r: f32,
    hl: f32,
    // Elliptic boundary arcs w(t) = c + u cos t + v sin t, t ∈ [t0, t1]: the disk's circle
    // (arc_c0), or the cylinder's two end rings (arc_c0, arc_c1).
    n_arcs: u32,
    arc_c0: vec3<f32>,
    arc_c1: vec3<f32>,
    arc_u: vec3<f32>,
    arc_v: vec3<f32>,
    t0: f32,
    t1: f32,
}

fn make_chart(w0: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>, region: u32) -> Chart {
    var c: Chart;
    c.w0 = w0;
    c.e1 = e1;
    c.e2 = e2;
    c.jac = abs(dot(w0, cross(e1, e2)));
    c.region = region;
    c.ya = -1.0;
    c.yb = 1.0;
    c.n_arcs = 0u;
    if region == REGION_DISK {
        c.n_arcs = 1u;
        c.arc_c0 = w0;
        c.arc_u = e1;
        c.arc_v = e2;
        c.t0 = 0.0;
        c.t1 = 2.0 * PI;
    }
    return c;
}

// The chart of a rect or disk: the light's plane.
fn plane_chart(light: Light, x: vec3<f32>, hx: f32, hy: f32, region: u32) -> Chart {
    return make_chart(world_origin(light) - x, light.world_x.xyz * hx, light.world_y.xyz * hy, region);
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

// The chart of a sphere (ellipsoid) from x: the disk of the tangent cone's contact ellipse.
// jac = 0 when x is inside or on the sphere.
fn sphere_chart(light: Light, x: vec3<f32>) -> Chart {
    let r = light.size.x;
    let xl = to_local_point(light, x);
    let rho = length(xl);
    if !(rho > r) {
        var none: Chart;
        none.jac = 0.0;
        return none;
    }
    let k = (rho - r) * (rho + r);
    let rc = r * sqrt(k) / rho;
    let u = xl / rho;
    let w0 = (world_origin(light) - x) * (k / (rho * rho));
    return make_chart(
        w0,
        to_world_dir(light, orthonormal_pair_a(u)) * rc,
        to_world_dir(light, orthonormal_pair_b(u)) * rc,
        REGION_DISK,
    );
}

// The chart of a cylinder from x: the plane through the axis facing x. jac = 0 when x is
// inside the infinite cylinder.
fn cylinder_chart(light: Light, x: vec3<f32>) -> Chart {
    let hl = light.size.x;
    let r = light.size.y;
    let xl = to_local_point(light, x);
    let rho = length(xl.yz);
    if !(rho > r) || !(hl > 0.0) || !(r > 0.0) {
        var none: Chart;
        none.jac = 0.0;
        return none;
    }
    let ry = xl.y / rho;
    let rz = xl.z / rho;
    let w0 = world_origin(light) - x;
    let e1 = light.world_x.xyz;
    let e2 = light.world_y.xyz * (-rz) + light.world_z.xyz * ry;
    var c = make_chart(w0, e1, e2, REGION_CYLINDER);
    let k = (rho - r) * (rho + r);
    c.yb = r * rho / sqrt(k);
    c.ya = -c.yb;
    c.xa = xl.x;
    c.rho = rho;
    c.r = r;
    c.hl = hl;
    c.n_arcs = 2u;
    c.arc_c0 = w0 - e1 * hl;
    c.arc_c1 = w0 + e1 * hl;
    c.arc_u = light.world_y.xyz * r;
    c.arc_v = light.world_z.xyz * r;
    let tx = atan2_accurate(rz, ry);
    let half = atan2_accurate(sqrt(k), r);
    c.t0 = tx - half;
    c.t1 = tx + half;
    return c;
}

// The region's X-interval on the line Y = y: (x0, x1, valid).
fn x_interval(c: Chart, y: f32) -> vec3<f32> {
    if c.region == REGION_SQUARE {
        return vec3<f32>(-1.0, 1.0, 1.0);
    }
    if c.region == REGION_DISK {
        let h = sqrt(max(1.0 - y * y, 0.0));
        return vec3<f32>(-h, h, 1.0);
    }
    let rho2 = c.rho * c.rho;
    let k = (c.rho - c.r) * (c.rho + c.r);
    let tau = k / (rho2 + sqrt(max(k * (c.yb * c.yb - y * y), 0.0)));
    if !(tau > 0.0) {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(c.xa + (-c.hl - c.xa) / tau, c.xa + (c.hl - c.xa) / tau, 1.0);
}

// The chart's Y for the direction w: (y, valid).
fn chart_y(c: Chart, w: vec3<f32>) -> vec2<f32> {
    let nrm = cross(c.e1, c.e2);
    let den = dot(w, nrm);
    if den == 0.0 {
        return vec2<f32>(0.0);
    }
    let lambda = dot(c.w0, nrm) / den;
    if !(lambda > 0.0) {
        return vec2<f32>(0.0);
    }
    let p = w * lambda - c.w0;
    return vec2<f32>(dot(p, cross(nrm, c.e1)) / dot(nrm, nrm), 1.0);
}

fn arc_at(c: Chart, i: u32, t: f32) -> vec3<f32> {
    let base = select(c.arc_c0, c.arc_c1, i == 1u);
    return base + c.arc_u * cos(t) + c.arc_v * sin(t);
}

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

// The kink cones of the light's shaping (cpu::irradiance::Profile): count, and their cosines.
fn kink_count(light: Light) -> u32 {
    return select(0u, 1u, has_flag(light, FLAG_KINK_A)) + select(0u, 1u, has_flag(light, FLAG_KINK_B));
}

fn kink_cos(light: Light, i: u32) -> f32 {
    return select(light.irr.z, light.irr.w, i == 1u);
}

fn push_y(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, y: f32, c: Chart) {
    if *count < MAX_YS && y >= c.ya && y <= c.yb {
        (*ys)[*count] = y;
        *count += 1u;
    }
}

fn push_dir(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, w: vec3<f32>, c: Chart) {
    let y = chart_y(c, w);
    if y.y > 0.0 {
        push_y(ys, count, y.x, c);
    }
}

// Crossings of the cone −ŵ·axis = cs with elliptic arc i: bracketing on IRR_ARC_SAMPLES
// samples, a check of each sample interval's interior extremum, then bisection.
fn arc_cone_crossings(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, i: u32, axis: vec3<f32>, cs: f32) {
    let h = (c.t1 - c.t0) / f32(IRR_ARC_SAMPLES);
    var ta = c.t0;
    var fa = arc_f(c, i, axis, cs, ta);
    for (var j = 1u; j <= IRR_ARC_SAMPLES; j++) {
        let tb = c.t0 + h * f32(j);
        let fb = arc_f(c, i, axis, cs, tb);
        if (fa.x > 0.0) != (fb.x > 0.0) {
            arc_push_root(ys, count, c, i, axis, cs, arc_bisect(c, i, axis, cs, ta, tb, false));
        } else if fa.y * fb.y < 0.0 {
            let te = arc_bisect(c, i, axis, cs, ta, tb, true);
            let fe = arc_f(c, i, axis, cs, te).x;
            if (fe > 0.0) != (fa.x > 0.0) {
                arc_push_root(ys, count, c, i, axis, cs, arc_bisect(c, i, axis, cs, ta, te, false));
                arc_push_root(ys, count, c, i, axis, cs, arc_bisect(c, i, axis, cs, te, tb, false));
            }
        }
        ta = tb;
        fa = fb;
    }
}

// Local minima of |w(t)|² on arc i (w·w' = 0 rising through zero): the arc's nearest points.
fn arc_nearest(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, i: u32) {
    let h = (c.t1 - c.t0) / f32(IRR_ARC_SAMPLES);
    var ta = c.t0;
    var da = arc_d(c, i, ta);
    for (var j = 1u; j <= IRR_ARC_SAMPLES; j++) {
        let tb = c.t0 + h * f32(j);
        let db = arc_d(c, i, tb);
        if da < 0.0 && db >= 0.0 {
            var lo = ta;
            var hi = tb;
            for (var k = 0; k < 26; k++) {
                let mid = 0.5 * (lo + hi);
                if arc_d(c, i, mid) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            push_dir(ys, count, arc_at(c, i, 0.5 * (lo + hi)), c);
        }
        ta = tb;
        da = db;
    }
}

// ½ d|w|²/dt on arc i.
fn arc_d(c: Chart, i: u32, t: f32) -> f32 {
    return dot(arc_at(c, i, t), c.arc_v * cos(t) - c.arc_u * sin(t));
}

// F(t) = (w·a)² − cs²|w|² and F'(t) on arc i.
fn arc_f(c: Chart, i: u32, axis: vec3<f32>, cs: f32, t: f32) -> vec2<f32> {
    let w = arc_at(c, i, t);
    let dw = c.arc_v * cos(t) - c.arc_u * sin(t);
    let wa = dot(w, axis);
    return vec2<f32>(wa * wa - cs * cs * dot(w, w), 2.0 * wa * dot(dw, axis) - 2.0 * cs * cs * dot(w, dw));
}

// A sign change of F (derivative = false) or of F' (true) in [a, b], by bisection.
fn arc_bisect(c: Chart, i: u32, axis: vec3<f32>, cs: f32, a: f32, b: f32, derivative: bool) -> f32 {
    var lo = a;
    var hi = b;
    let flo = arc_f(c, i, axis, cs, lo);
    let slo = select(flo.x, flo.y, derivative) > 0.0;
    for (var k = 0; k < 26; k++) {
        let mid = 0.5 * (lo + hi);
        let fm = arc_f(c, i, axis, cs, mid);
        if (select(fm.x, fm.y, derivative) > 0.0) == slo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return 0.5 * (lo + hi);
}

fn arc_push_root(ys: ptr<function, array<f32, MAX_YS>>, count: ptr<function, u32>, c: Chart, i: u32, axis: vec3<f32>, cs: f32, t: f32) {
    let w = arc_at(c, i, t);
    if -dot(w, axis) * cs > 0.0 {
        push_dir(ys, count, w, c);
    }
}

// The Y values where the inner structure of the chart integral changes, sorted and
// de-duplicated, including the region's Y-range ends (see the CPU twin).
fn critical_ys(light: Light, c: Chart, n: vec3<f32>, ys: ptr<function, array<f32, MAX_YS>>) -> u32 {
    var count = 0u;
    (*ys)[0] = c.ya;
    (*ys)[1] = c.yb;
    count = 2u;
    let axis = light.axis.xyz;
    let n_planes = select(1u, 2u, has_flag(light, FLAG_FOCUS_PLANE));
    let n_cones = kink_count(light);
    for (var pi = 0u; pi < n_planes; pi++) {
        let m = select(n, axis, pi == 1u);
        let me1 = dot(m, c.e1);
        let me2 = dot(m, c.e2);
        let mw0 = dot(m, c.w0);
        if abs(me1) <= 1e-5 * length(m) * length(c.e1) && me2 != 0.0 {
            push_y(ys, &count, -mw0 / me2, c);
        }
        if c.region == REGION_SQUARE && me2 != 0.0 {
            push_y(ys, &count, -(mw0 - me1) / me2, c);
            push_y(ys, &count, -(mw0 + me1) / me2, c);
        }
        for (var ai = 0u; ai < c.n_arcs; ai++) {
            let cc = select(c.arc_c0, c.arc_c1, ai == 1u);
            let r = lin_trig_roots(dot(m, c.arc_u), dot(m, c.arc_v), -dot(m, cc));
            if r.z > 0.0 {
                let ta = wrap_into(r.x, c.t0);
                if ta <= c.t1 {
                    push_dir(ys, &count, arc_at(c, ai, ta), c);
                }
                let tb = wrap_into(r.y, c.t0);
                if tb <= c.t1 {
                    push_dir(ys, &count, arc_at(c, ai, tb), c);
                }
            }
        }
        // Plane ∩ the other plane.
        if n_planes == 2u {
            let d = cross(n, axis);
            if dot(d, d) > 0.0 && pi == 0u {
                push_dir(ys, &count, d, c);
                push_dir(ys, &count, -d, c);
            }
        }
        for (var ci = 0u; ci < n_cones; ci++) {
            let dirs = plane_cone_dirs(m, axis, kink_cos(light, ci));
            if dirs.ok {
                push_dir(ys, &count, dirs.a, c);
                push_dir(ys, &count, dirs.b, c);
            }
        }
    }
    let e1u = normalize(c.e1);
    let m1 = orthonormal_pair_a(e1u);
    let m2 = orthonormal_pair_b(e1u);
    let pa = dot(m1, axis);
    let pb = dot(m2, axis);
    let ra = sqrt(pa * pa + pb * pb);
    for (var ci = 0u; ci < n_cones; ci++) {
        let cs = kink_cos(light, ci);
        // Planes of the pencil tangent to the cone: |m·axis| = sin θ.
        let s = sqrt(max(1.0 - cs * cs, 0.0));
        if ra >= s && ra > 0.0 {
            let t0 = atan2_accurate(pb, pa);
            let q = clamp(s / ra, -1.0, 1.0);
            let d = atan2_accurate(sqrt(max(1.0 - q * q, 0.0)), q);
            for (var k = 0; k < 2; k++) {
                let t = select(t0 - d, t0 + d, k == 0);
                let mm = m1 * cos(t) + m2 * sin(t);
                let me2 = dot(mm, c.e2);
                if me2 != 0.0 {
                    push_y(ys, &count, -dot(mm, c.w0) / me2, c);
                }
            }
        }
        if c.region == REGION_SQUARE {
            for (var k = 0; k < 2; k++) {
                let xs = select(1.0, -1.0, k == 0);
                let r = cone_roots_on_line(axis, cs, c.w0 + c.e1 * xs, c.e2);
                let mask = u32(r.z);
                if (mask & 1u) != 0u {
                    push_y(ys, &count, r.x, c);
                }
                if (mask & 2u) != 0u {
                    push_y(ys, &count, r.y, c);
                }
            }
        }
        for (var ai = 0u; ai < c.n_arcs; ai++) {
            arc_cone_crossings(ys, &count, c, ai, axis, cs);
        }
    }
    // The outer integrand peaks where a curve bounding the inner intervals (a region edge, a
    // cone edge, the focus line) comes nearest to x: split there too.
    if c.region == REGION_SQUARE {
        let e22 = dot(c.e2, c.e2);
        push_y(ys, &count, -dot(c.w0 - c.e1, c.e2) / e22, c);
        push_y(ys, &count, -dot(c.w0 + c.e1, c.e2) / e22, c);
    }
    for (var ai = 0u; ai < c.n_arcs; ai++) {
        arc_nearest(ys, &count, c, ai);
    }
    let nc = cross(c.e1, c.e2);
    let nrm = normalize(nc) * sign(dot(c.w0, nc));
    let p = -axis;
    let perp = nrm - p * dot(nrm, p);
    for (var ci = 0u; ci < n_cones; ci++) {
        let cs = kink_cos(light, ci);
        if dot(perp, perp) > 0.0 {
            push_dir(ys, &count, p * cs + normalize(perp) * sqrt(max(1.0 - cs * cs, 0.0)), c);
        }
    }
    if n_planes == 2u && dot(perp, perp) > 0.0 {
        push_dir(ys, &count, perp, c);
    }
    if has_flag(light, FLAG_AXIS_SINGULAR) {
        let m = cross(c.e1, axis);
        let me2 = dot(m, c.e2);
        if me2 != 0.0 {
            push_y(ys, &count, -dot(m, c.w0) / me2, c);
        }
    }
    // Insertion sort, then drop near-duplicates.
    for (var i = 1u; i < count; i++) {
        let v = (*ys)[i];
        var j = i;
        while j > 0u && (*ys)[j - 1u] > v {
            (*ys)[j] = (*ys)[j - 1u];
            j -= 1u;
        }
        (*ys)[j] = v;
    }
    let span = c.yb - c.ya;
    var kept = 1u;
    for (var i = 1u; i < count; i++) {
        if (*ys)[i] - (*ys)[kept - 1u] > 1e-6 * span {
            (*ys)[kept] = (*ys)[i];
            kept += 1u;
        }
    }
    // Keep the upper end exact.
    (*ys)[kept - 1u] = c.yb;
    return kept;
}

// The map of one piece [t0, t1]: an optional tan map t = c + w·tan u around a near pole, a
// cubic grading toward flagged ends, and (outer pieces) the cosine map.
struct PieceMap {
    c: f32,
    w: f32,
    tan_map: bool,
    u0: f32,
    u1: f32,
    grade_lo: bool,
    grade_hi: bool,
}

fn bernstein_rho(t0: f32, t1: f32, c: f32, w: f32) -> f32 {
    let half = 0.5 * (t1 - t0);
    if !(half > 0.0) {
        return 1e30;
    }
    let zr = (c - 0.5 * (t0 + t1)) / half;
    let zi = w / half;
    let ar = zr * zr - zi * zi - 1.0;
    let ai = 2.0 * zr * zi;
    let m = sqrt(sqrt(ar * ar + ai * ai));
    let ang = 0.5 * atan2_accurate(ai, ar);
    let sr = m * cos(ang);
    let si = m * sin(ang);
    let p = sqrt((zr + sr) * (zr + sr) + (zi + si) * (zi + si));
    let q = sqrt((zr - sr) * (zr - sr) + (zi - si) * (zi - si));
    return max(p, q);
}

fn piece_map(t0: f32, t1: f32, c: f32, w: f32, glo: bool, ghi: bool) -> PieceMap {
    var m: PieceMap;
    m.c = c;
    m.w = w;
    m.tan_map = w > 0.0 && w < 1e30 && bernstein_rho(t0, t1, c, w) < IRR_TAN_MAP_RHO;
    if m.tan_map {
        m.u0 = atan2_accurate(t0 - c, w);
        m.u1 = atan2_accurate(t1 - c, w);
    } else {
        m.u0 = t0;
        m.u1 = t1;
    }
    m.grade_lo = glo;
    m.grade_hi = ghi;
    return m;
}

// A tan-mapped piece is cut into equal u-spans of at most IRR_MAX_U_SPAN (grading stays on
// the outer ends).
fn span_count(m: PieceMap) -> u32 {
    if !m.tan_map {
        return 1u;
    }
    return max(u32(ceil(abs(m.u1 - m.u0) / IRR_MAX_U_SPAN)), 1u);
}

fn span(m: PieceMap, j: u32, k: u32) -> PieceMap {
    var out = m;
    out.u0 = m.u0 + (m.u1 - m.u0) * f32(j) / f32(k);
    out.u1 = m.u0 + (m.u1 - m.u0) * f32(j + 1u) / f32(k);
    out.grade_lo = m.grade_lo && j == 0u;
    out.grade_hi = m.grade_hi && j + 1u == k;
    return out;
}

// (t, dt/ds) at s ∈ [0, 1].
fn map_eval(m: PieceMap, s: f32, cosine: bool) -> vec2<f32> {
    var g = s;
    var dg = 1.0;
    if m.grade_lo && !m.grade_hi {
        g = s * s * s;
        dg = 3.0 * s * s;
    } else if m.grade_hi && !m.grade_lo {
        let r = 1.0 - s;
        g = 1.0 - r * r * r;
        dg = 3.0 * r * r;
    } else if m.grade_lo && m.grade_hi {
        let a = s * s * s;
        let b = (1.0 - s) * (1.0 - s) * (1.0 - s);
        let d = a + b;
        let da = 3.0 * s * s;
        let db = -3.0 * (1.0 - s) * (1.0 - s);
        g = a / d;
        dg = (da * d - a * (da + db)) / (d * d);
    }
    if cosine {
        dg *= 0.5 * PI * sin(PI * g);
        g = 0.5 * (1.0 - cos(PI * g));
    }
    let u = m.u0 + (m.u1 - m.u0) * g;
    let du = (m.u1 - m.u0) * dg;
    if m.tan_map {
        let tn = sin(u) / cos(u);
        return vec2<f32>(m.c + m.w * tn, m.w * (1.0 + tn * tn) * du);
    }
    return vec2<f32>(u, du);
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

// Node k of the inner Gauss–Legendre rule on [s0, s0 + h] of one span's parameter.
fn inner_node(light: Light, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, sp: PieceMap, s0: f32, h: f32, k: u32) -> vec3<f32> {
    let xd = map_eval(sp, s0 + h * IRR_GL_INNER_X[k], false);
    let w = a + e1 * xd.x;
    let nw = dot(n, w);
    if nw > 0.0 && xd.y != 0.0 {
        let l2 = dot(w, w);
        let e = -w / sqrt(l2);
        return shaping(light, e) * (IRR_GL_INNER_W[k] * h * nw / (l2 * l2) * xd.y);
    }
    return vec3<f32>(0.0);
}

// The inner rule on [s0, s1], its IRR_GL_INNER = 10 nodes written out rather than looped:
// llvmpipe stops a shader invocation's loops after 65535 iterations in total (see
// GpuContext::lights_per_dispatch), and this is the innermost, most repeated loop.
fn inner_rule(light: Light, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, sp: PieceMap, s0: f32, s1: f32) -> vec3<f32> {
    let h = s1 - s0;
    return inner_node(light, n, a, e1, sp, s0, h, 0u) + inner_node(light, n, a, e1, sp, s0, h, 1u)
        + inner_node(light, n, a, e1, sp, s0, h, 2u) + inner_node(light, n, a, e1, sp, s0, h, 3u)
        + inner_node(light, n, a, e1, sp, s0, h, 4u) + inner_node(light, n, a, e1, sp, s0, h, 5u)
        + inner_node(light, n, a, e1, sp, s0, h, 6u) + inner_node(light, n, a, e1, sp, s0, h, 7u)
        + inner_node(light, n, a, e1, sp, s0, h, 8u) + inner_node(light, n, a, e1, sp, s0, h, 9u);
}

fn max3(v: vec3<f32>) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// One span by halving until the halves agree with their parent to IRR_INNER_TOL (relative; the
// integrand is ≥ 0) or IRR_INNER_DEPTH is reached, depth first (the CPU twin: Nodes::integrate
// in src/cpu/irradiance.rs). A depth-first stack never holds more than depth + 1 entries.
fn inner_adaptive(light: Light, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, sp: PieceMap) -> vec3<f32> {
    var lo: array<f32, IRR_INNER_DEPTH + 1u>;
    var hi: array<f32, IRR_INNER_DEPTH + 1u>;
    var q: array<vec3<f32>, IRR_INNER_DEPTH + 1u>;
    var dep: array<u32, IRR_INNER_DEPTH + 1u>;
    lo[0] = 0.0;
    hi[0] = 1.0;
    q[0] = inner_rule(light, n, a, e1, sp, 0.0, 1.0);
    dep[0] = 0u;
    var top = 1u;
    var sum = vec3<f32>(0.0);
    while top > 0u {
        top -= 1u;
        let s0 = lo[top];
        let s1 = hi[top];
        let parent = q[top];
        let d = dep[top];
        let mid = 0.5 * (s0 + s1);
        let ql = inner_rule(light, n, a, e1, sp, s0, mid);
        let qr = inner_rule(light, n, a, e1, sp, mid, s1);
        let fine = ql + qr;
        if d + 1u >= IRR_INNER_DEPTH || max3(abs(fine - parent)) <= IRR_INNER_TOL * max3(abs(fine)) {
            sum += fine;
        } else {
            lo[top] = mid;
            hi[top] = s1;
            q[top] = qr;
            dep[top] = d + 1u;
            lo[top + 1u] = s0;
            hi[top + 1u] = mid;
            q[top + 1u] = ql;
            dep[top + 1u] = d + 1u;
            top += 2u;
        }
    }
    return sum;
}

// ∫ S(−ŵ)·max(0, n·w)/|w|⁴ dX along w = a + X e1, X ∈ [x0, x1].
fn line_integral(light: Light, n: vec3<f32>, a: vec3<f32>, e1: vec3<f32>, x0: f32, x1: f32) -> vec3<f32> {
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
    for (var ci = 0u; ci < kink_count(light); ci++) {
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
    for (var i = 1u; i < count; i++) {
        let v = bp[i];
        let g = graded[i];
        var j = i;
        while j > 0u && bp[j - 1u] > v {
            bp[j] = bp[j - 1u];
            graded[j] = graded[j - 1u];
            j -= 1u;
        }
        bp[j] = v;
        graded[j] = g;
    }
    // The line's closest approach to x: X* and the width √m/|e1|, m = |a × e1|²/|e1|².
    let e12 = dot(e1, e1);
    let x_star = -dot(a, e1) / e12;
    let perp = a + e1 * x_star;
    let cr = length(cross(a, e1));
    let width = cr / e12;
    let m = cr * cr / e12;
    let unshaped = !has_flag(light, FLAG_SHAPING);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i + 1u < count; i++) {
        let t0 = bp[i];
        let t1 = bp[i + 1u];
        if !(t1 > t0) {
            continue;
        }
        let pm = piece_map(t0, t1, x_star, width, false, false);
        if unshaped && pm.tan_map && m > 0.0 {
            // (n·w)/|w|⁴ dX = (width/m²)(n·perp cos²u + width n·e1 sin u cos u) du.
            let np = dot(n, perp);
            let nw = ne * width;
            let p1 = np * (0.5 * pm.u1 + 0.25 * sin(2.0 * pm.u1)) + nw * 0.5 * sin(pm.u1) * sin(pm.u1);
            let p0 = np * (0.5 * pm.u0 + 0.25 * sin(2.0 * pm.u0)) + nw * 0.5 * sin(pm.u0) * sin(pm.u0);
            sum += vec3<f32>(max(width / (m * m) * (p1 - p0), 0.0));
            continue;
        }
        // Grade only the quarter next to a graded end (see graded_parts in the CPU twin).
        let g0 = graded[i] != 0u;
        let g1 = graded[i + 1u] != 0u;
        let q = 0.25 * (t1 - t0);
        var cuts = array<f32, 4>(t0, t0, t1, t1);
        if g0 {
            cuts[1] = t0 + q;
        }
        if g1 {
            cuts[2] = t1 - q;
        }
        for (var part = 0u; part < 3u; part++) {
            let p0 = cuts[part];
            let p1 = cuts[part + 1u];
            if !(p1 > p0) {
                continue;
            }
            let pp = piece_map(p0, p1, x_star, width, part == 0u && g0, part == 2u && g1);
            let spans = span_count(pp);
            for (var j = 0u; j < spans; j++) {
                sum += inner_adaptive(light, n, a, e1, span(pp, j, spans));
            }
        }
    }
    return sum;
}

// The nearest singularity (y_foot, width) of the outer integrand on [y0, y1]: the Lorentzian of
// the distance to the chart plane, widened when the foot of x lies outside the region's
// X-interval (see the CPU twin).
fn outer_pole(c: Chart, y0: f32, y1: f32) -> vec2<f32> {
    let u = cross(c.w0, c.e1);
    let v = cross(c.e2, c.e1);
    let vv = dot(v, v);
    let y_foot = -dot(u, v) / vv;
    let e1l = length(c.e1);
    let h = c.jac / sqrt(vv);
    let x_foot = -dot(c.w0 + c.e2 * y_foot, c.e1) / (e1l * e1l);
    let xi = x_interval(c, clamp(y_foot, y0, y1));
    var d = 0.0;
    if xi.z > 0.0 {
        d = max(max(xi.x - x_foot, x_foot - xi.y), 0.0);
    }
    return vec2<f32>(y_foot, sqrt(h * h + d * e1l * d * e1l) * e1l / sqrt(vv));
}

// The Gauss–Kronrod 7/15 pair on [s0, s1] of one outer span's parameter: (Kronrod value,
// |Kronrod − Gauss| in the largest channel).
fn outer_gk(light: Light, c: Chart, n: vec3<f32>, sp: PieceMap, s0: f32, s1: f32) -> vec4<f32> {
    let h = s1 - s0;
    var k = vec3<f32>(0.0);
    var g = vec3<f32>(0.0);
    for (var i = 0u; i < 15u; i++) {
        let yd = map_eval(sp, s0 + h * IRR_GK_X[i], true);
        if yd.y == 0.0 {
            continue;
        }
        let xi = x_interval(c, yd.x);
        if xi.z > 0.0 {
            let v = line_integral(light, n, c.w0 + c.e2 * yd.x, c.e1, xi.x, xi.y) * (h * yd.y * c.jac);
            k += IRR_GK_WK[i] * v;
            g += IRR_GK_WG[i] * v;
        }
    }
    return vec4<f32>(k, max3(abs(k - g)));
}

// One outer span: the pair, halved while it disagrees by more than IRR_OUTER_TOL (relative) and
// depth allows, depth first (the CPU twin: Nodes::integrate in src/cpu/irradiance.rs).
fn outer_adaptive(light: Light, c: Chart, n: vec3<f32>, sp: PieceMap) -> vec3<f32> {
    var lo: array<f32, IRR_OUTER_DEPTH + 1u>;
    var hi: array<f32, IRR_OUTER_DEPTH + 1u>;
    var dep: array<u32, IRR_OUTER_DEPTH + 1u>;
    lo[0] = 0.0;
    hi[0] = 1.0;
    dep[0] = 0u;
    var top = 1u;
    var sum = vec3<f32>(0.0);
    while top > 0u {
        top -= 1u;
        let s0 = lo[top];
        let s1 = hi[top];
        let d = dep[top];
        let r = outer_gk(light, c, n, sp, s0, s1);
        if d + 1u >= IRR_OUTER_DEPTH || r.w <= IRR_OUTER_TOL * max3(abs(r.xyz)) {
            sum += r.xyz;
        } else {
            let mid = 0.5 * (s0 + s1);
            lo[top] = mid;
            hi[top] = s1;
            dep[top] = d + 1u;
            lo[top + 1u] = s0;
            hi[top + 1u] = mid;
            dep[top + 1u] = d + 1u;
            top += 2u;
        }
    }
    return sum;
}

// ∫∫ S(−ŵ)·max(0, n·w)·J/|w|⁴ dX dY over the chart's region (the base radiance not applied).
fn chart_integral(light: Light, c: Chart, n: vec3<f32>) -> vec3<f32> {
    if has_flag(light, FLAG_DARK) || !(c.jac > 0.0) {
        return vec3<f32>(0.0);
    }
    var ys: array<f32, MAX_YS>;
    let count = critical_ys(light, c, n, &ys);
    var total = vec3<f32>(0.0);
    for (var i = 0u; i + 1u < count; i++) {
        let pole = outer_pole(c, ys[i], ys[i + 1u]);
        let pm = piece_map(ys[i], ys[i + 1u], pole.x, pole.y, false, false);
        let spans = span_count(pm);
        for (var j = 0u; j < spans; j++) {
            total += outer_adaptive(light, c, n, span(pm, j, spans));
        }
    }
    return total;
}

// treatAsLine: the segment along the axis with weight 2 r |det M| ρ (see the CPU twin).
fn line_irradiance(light: Light, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let hl = light.size.x;
    let r = light.size.y;
    let xl = to_local_point(light, x);
    let weight = 2.0 * r * light.irr.y * length(xl.yz);
    if !(weight > 0.0) || !(hl > 0.0) || has_flag(light, FLAG_DARK) {
        return vec3<f32>(0.0);
    }
    return light.base.xyz * line_integral(light, n, world_origin(light) - x, light.world_x.xyz, -hl, hl) * weight;
}

fn irradiance_of(light: Light, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let base = light.base.xyz;
    var e = vec3<f32>(0.0);
    switch light.kind {
        case KIND_DOME: {
            e = base * PI;
        }
        case KIND_DISTANT: {
            let c = -light.axis.xyz;
            let theta_max = light.axis.w;
            let sg = dot(n, c);
            if theta_max == 0.0 {
                e = base * max(sg, 0.0);
            } else {
                e = base * cap_irradiance(theta_max, sg, length(cross(n, c)));
            }
        }
        case KIND_SPHERE: {
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
                e = point_irradiance(light, x, n);
            } else if !has_flag(light, FLAG_SHAPING) && has_flag(light, FLAG_SIMILARITY) {
                let r = light.size.x * length(light.world_x.xyz);
                e = base * sphere_cap(world_origin(light), r, x, n);
            } else {
                e = base * chart_integral(light, sphere_chart(light, x), n);
            }
        }
        case KIND_RECT: {
            let xl = to_local_point(light, x);
            if xl.z < 0.0 {
                let size = min(light.size.x * length(light.world_x.xyz), light.size.y * length(light.world_y.xyz));
                // Lambert only where its sum cannot cancel much (see IRR_LAMBERT_COND), and not
                // clipped by the horizon.
                let d = length(world_origin(light) - x);
                let h = abs(dot(x - world_origin(light), light.normal.xyz));
                let lambert = d * d <= IRR_LAMBERT_COND * size * h;
                if !has_flag(light, FLAG_SHAPING) && lambert && rect_above_horizon(light, x, n) {
                    e = base * rect_lambert(light, x, n);
                } else {
                    e = base * chart_integral(light, plane_chart(light, x, light.size.x, light.size.y, REGION_SQUARE), n);
                }
            }
        }
        case KIND_DISK: {
            let xl = to_local_point(light, x);
            if xl.z < 0.0 {
                e = base * chart_integral(light, plane_chart(light, x, light.size.x, light.size.x, REGION_DISK), n);
            }
        }
        case KIND_CYLINDER: {
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
                e = line_irradiance(light, x, n);
            } else {
                e = base * chart_integral(light, cylinder_chart(light, x), n);
            }
        }
        default: {}
    }
    return e * light.irr.x;
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn irradiance_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = sample_index(gid);
    if i >= params.count {
        return;
    }
    let x = load3(false, i);
    let nraw = load3(true, i);
    let len = length(nraw);
    let valid = len > 0.0;
    let n = nraw / select(1.0, len, valid);
    var sum = vec3<f32>(0.0);
    for (var l = params.light_first; l < params.light_end; l++) {
        var v = vec3<f32>(0.0);
        if valid {
            v = irradiance_of(lights[l], x, n);
        }
        add(i, l, v, &sum);
    }
    finish(i, sum);
}
