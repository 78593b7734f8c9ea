// Directions uniform in the solid angle a RectLight subtends (f32), DESIGN.md §9 S2: Ureña, Fajardo
// & King's spherical rectangle (EGSR 2013) for a rectangle in the world, Arvo's two spherical
// triangles (SIGGRAPH 1995) for a sheared one (a parallelogram). Twin of src/cpu/sample/rect.rs,
// which carries the citations.
//
// GPU-only spherical_rect, spherical_triangle, triangle_sample, rect_sample: WGSL has one
//   namespace and no methods; they are SphericalRect::new, SphericalTriangle::new,
//   SphericalTriangle::sample and RectSampler::{new, solid_angle, sample}. Which of the two
//   samplers a rect takes is the host's f64 decision (FLAG_SHEARED_RECT, gpu/record.rs), with
//   RectSampler::new's own test.
// GPU-only great_circle_angle, oosterom: the f32 forms of the interior angle and of the solid
//   angle of a triangle (Van Oosterom & Strackee 1983), see below.
// f32: the solid angles Ω (the density 1/Ω and the u[0] scale) are Van Oosterom & Strackee's
//   atan2 formula with the triple product formed from the exact edges, not Girard's Σγ − π, which
//   loses every digit of a small Ω in f32 (a 0.1 m rect 5 m away: Ω ≈ 4e-4, Girard's f32 error
//   1e-3 relative). The interior angles are atan2(|a × b|, −a·b) (shared/math.wgsl's
//   atan2_accurate), not acos, which loses half the digits near 0 and π. The spherical
//   triangles' plane normals are crossed from the exact edge vectors rather than from the unit
//   vertex directions.
// f32: the Ureña point is returned as its direction from o, without adding o and subtracting it.

// #import shared/math.wgsl
// #import shared/record.wgsl

struct SphRect {
    x: vec3<f32>,
    y: vec3<f32>,
    z: vec3<f32>,
    z0: f32,
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    b0: f32,
    b1: f32,
    k: f32,
    // Ω; 0 when o lies in the rectangle's plane.
    solid_angle: f32,
}

// The angle between two great circles of inner normals a and b: acos(−a·b), by atan2.
fn great_circle_angle(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return atan2_accurate(length(cross(a, b)), -dot(a, b));
}

// 2·atan2(|triple|, la lb lc + (a·b) lc + (a·c) lb + (b·c) la): the solid angle of the triangle
// of vertex vectors a, b, c whose triple product a·(b × c) is `triple`.
fn oosterom(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, triple: f32) -> f32 {
    let la = length(a);
    let lb = length(b);
    let lc = length(c);
    let den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    return 2.0 * atan2_accurate(abs(triple), den);
}

// The rectangle (corner s − o = `d`, unit orthogonal edges ex, ey of lengths lx, ly) seen from o.
fn spherical_rect(d: vec3<f32>, ex: vec3<f32>, ey: vec3<f32>, lx: f32, ly: f32) -> SphRect {
    var r: SphRect;
    r.x = ex;
    r.y = ey;
    r.z = cross(ex, ey);
    r.z0 = dot(d, r.z);
    if r.z0 > 0.0 {
        r.z = -r.z;
        r.z0 = -r.z0;
    }
    r.solid_angle = 0.0;
    if !(r.z0 < 0.0) {
        return r;
    }
    r.x0 = dot(d, r.x);
    r.y0 = dot(d, r.y);
    r.x1 = r.x0 + lx;
    r.y1 = r.y0 + ly;
    let v00 = vec3<f32>(r.x0, r.y0, r.z0);
    let v01 = vec3<f32>(r.x0, r.y1, r.z0);
    let v10 = vec3<f32>(r.x1, r.y0, r.z0);
    let v11 = vec3<f32>(r.x1, r.y1, r.z0);
    let n0 = normalize(cross(v00, v10));
    let n1 = normalize(cross(v10, v11));
    let n2 = normalize(cross(v11, v01));
    let n3 = normalize(cross(v01, v00));
    let g2 = great_circle_angle(n2, n3);
    let g3 = great_circle_angle(n3, n0);
    r.k = 2.0 * PI - g2 - g3;
    // Both triangles (v00, v10, v11) and (v00, v11, v01) have triple product z0·lx·ly.
    let triple = r.z0 * lx * ly;
    r.solid_angle = oosterom(v00, v10, v11, triple) + oosterom(v00, v11, v01, triple);
    r.b0 = n0.z;
    r.b1 = n2.z;
    return r;
}

// The direction from o toward the rectangle's point for u (Ureña 2013, Algorithm 2).
fn sample_point(r: SphRect, u: vec2<f32>) -> vec3<f32> {
    let au = u.x * r.solid_angle + r.k;
    let sa = sin(au);
    let ca = cos(au);
    let fu = (ca * r.b0 - r.b1) / sa;
    let cu = clamp(select(1.0, -1.0, fu < 0.0) / sqrt(fu * fu + r.b0 * r.b0), -1.0, 1.0);
    let xu = clamp(-(cu * r.z0) / sqrt(max(1.0 - cu * cu, 0.0)), r.x0, r.x1);
    let d = sqrt(xu * xu + r.z0 * r.z0);
    let h0 = r.y0 / sqrt(d * d + r.y0 * r.y0);
    let h1 = r.y1 / sqrt(d * d + r.y1 * r.y1);
    let hv = h0 + u.y * (h1 - h0);
    let hv2 = hv * hv;
    var yv = r.y1;
    if hv2 < 1.0 {
        yv = clamp(hv * d / sqrt(1.0 - hv2), r.y0, r.y1);
    }
    return normalize(xu * r.x + yv * r.y + r.z0 * r.z);
}

// A spherical triangle: unit vertex directions a, b, c and the angle α at a; Ω its solid angle
// (0: none).
struct SphTri {
    a: vec3<f32>,
    b: vec3<f32>,
    c: vec3<f32>,
    alpha: f32,
    cos_c: f32,
    solid_angle: f32,
}

// The triangle of vertex vectors va, vb, vc from the receiver, with the exact edges ab = vb − va,
// ac = vc − va, bc = vc − vb and the triple product va·(vb × vc).
fn spherical_triangle(
    va: vec3<f32>,
    vb: vec3<f32>,
    vc: vec3<f32>,
    ab: vec3<f32>,
    ac: vec3<f32>,
    triple: f32,
) -> SphTri {
    var t: SphTri;
    t.a = normalize(va);
    t.b = normalize(vb);
    t.c = normalize(vc);
    let nab = normalize(cross(va, ab));
    let nac = normalize(cross(va, ac));
    t.alpha = atan2_accurate(length(cross(nab, nac)), dot(nab, nac));
    t.cos_c = dot(t.a, t.b);
    let omega = oosterom(va, vb, vc, triple);
    t.solid_angle = select(0.0, omega, omega > 0.0 && omega < 4.0 * PI);
    return t;
}

// A direction uniform in the triangle (Arvo 1995).
fn triangle_sample(t: SphTri, u: vec2<f32>) -> vec3<f32> {
    let sin_a = sin(t.alpha);
    let cos_a = cos(t.alpha);
    let phi = u.x * t.solid_angle - t.alpha;
    let s = sin(phi);
    let tt = cos(phi);
    let uu = tt - cos_a;
    let vv = s + sin_a * t.cos_c;
    let q = clamp(((vv * tt - uu * s) * cos_a - vv) / ((vv * s + uu * tt) * sin_a), -1.0, 1.0);
    let c_hat = q * t.a + sqrt(max(1.0 - q * q, 0.0)) * ortho(t.c, t.a);
    let z = 1.0 - u.y * (1.0 - dot(c_hat, t.b));
    return normalize(z * t.b + sqrt(max(1.0 - z * z, 0.0)) * ortho(c_hat, t.b));
}

// The unit component of v orthogonal to the unit w (zero when there is none).
fn ortho(v: vec3<f32>, w: vec3<f32>) -> vec3<f32> {
    let p = v - dot(v, w) * w;
    let l = length(p);
    return select(vec3<f32>(0.0), p / l, l > 0.0);
}

// The rect light's parallelogram seen from o: vec4(ω, Ω) for u, Ω = 0 where it subtends nothing.
fn rect_sample(light: Record, o: vec3<f32>, u: vec2<f32>) -> vec4<f32> {
    let hw = light.size.x;
    let hh = light.size.y;
    let mx = light.world_x.xyz;
    let my = light.world_y.xyz;
    // The corner relative to o, and the edges.
    let d = world_origin(light) - o - mx * hw - my * hh;
    let e1 = mx * (2.0 * hw);
    let e2 = my * (2.0 * hh);
    let l1 = length(e1);
    let l2 = length(e2);
    if !(l1 > 0.0 && l2 > 0.0) {
        return vec4<f32>(0.0);
    }
    if !has_flag(light, FLAG_SHEARED_RECT) {
        let ex = e1 / l1;
        let ey = normalize(e2 - e1 * (dot(e1, e2) / (l1 * l1)));
        let r = spherical_rect(d, ex, ey, l1, l2);
        if !(r.solid_angle > 0.0) {
            return vec4<f32>(0.0);
        }
        return vec4<f32>(sample_point(r, u), r.solid_angle);
    }
    // Triangles (A, B, C) and (A, C, D) of the corners A = d, B = A + e1, C = B + e2, D = A + e2.
    let va = d;
    let vb = d + e1;
    let vc = d + e1 + e2;
    let vd = d + e2;
    let triple = dot(d, cross(e1, e2));
    let t1 = spherical_triangle(va, vb, vc, e1, e1 + e2, triple);
    let t2 = spherical_triangle(va, vc, vd, e1 + e2, e2, triple);
    let total = t1.solid_angle + t2.solid_angle;
    if !(total > 0.0) {
        return vec4<f32>(0.0);
    }
    // The first triangle with probability Ω₁/Ω, u[0] rescaled to stay uniform.
    let p1 = t1.solid_angle / total;
    var w: vec3<f32>;
    if t1.solid_angle > 0.0 && u.x < p1 {
        w = triangle_sample(t1, vec2<f32>(u.x / p1, u.y));
    } else if t2.solid_angle > 0.0 {
        w = triangle_sample(t2, vec2<f32>(clamp((u.x - p1) / (1.0 - p1), 0.0, 1.0), u.y));
    } else {
        w = triangle_sample(t1, u);
    }
    return vec4<f32>(w, total);
}
