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
// GPU-only oosterom: the solid angle of a triangle by Van Oosterom & Strackee (1983), see below.
// GPU-only sub_rect_solid_angle: the solid angle of Ureña's sub-rectangle, for the bisection.
// f32: the solid angles Ω (the density 1/Ω and the u[0] scale) are Van Oosterom & Strackee's
//   atan2 formula with the triple product formed from the exact edges, not Girard's Σγ − π, which
//   loses every digit of a small Ω in f32 (a 0.1 m rect 5 m away: Ω ≈ 4e-4, Girard's f32 error
//   1e-3 relative); its atan2 is shared/math.wgsl's atan2_accurate. Ureña's k, b0, b1 and Arvo's
//   angle α are not needed (see the next item).
// f32: the first step of each parametrization — Ureña's edge xu, Arvo's vertex Ĉ — is the same
//   point (the sub-rectangle or sub-triangle of solid angle u[0]·Ω), found by 26 bisection steps
//   on that solid angle (Van Oosterom & Strackee again) instead of the closed forms, whose f32
//   cancellations (cos(au)·b0 − b1, 1 − q²) put small lights' directions 1e-3 of their angular
//   size (Ureña) to 10 % (Arvo) off. Arvo's second step takes 1 − cos from the chord |Ĉ − B|²/2.
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
    // Ω; 0 when o lies in the rectangle's plane.
    solid_angle: f32,
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
    // Both triangles (v00, v10, v11) and (v00, v11, v01) have triple product z0·lx·ly.
    let triple = r.z0 * lx * ly;
    r.solid_angle = oosterom(v00, v10, v11, triple) + oosterom(v00, v11, v01, triple);
    return r;
}

// The solid angle of the sub-rectangle [x0, xu] × [y0, y1] (Ureña's frame).
fn sub_rect_solid_angle(r: SphRect, xu: f32) -> f32 {
    let a = vec3<f32>(r.x0, r.y0, r.z0);
    let b = vec3<f32>(xu, r.y0, r.z0);
    let c = vec3<f32>(xu, r.y1, r.z0);
    let d = vec3<f32>(r.x0, r.y1, r.z0);
    let triple = r.z0 * (xu - r.x0) * (r.y1 - r.y0);
    return oosterom(a, b, c, triple) + oosterom(a, c, d, triple);
}

// The direction from o toward the rectangle's point for u (Ureña 2013, Algorithm 2): the edge xu
// of the sub-rectangle of solid angle u[0]·Ω, then the height along it by u[1].
fn sample_point(r: SphRect, u: vec2<f32>) -> vec3<f32> {
    // xu by bisection on the sub-rectangle's solid angle (see the header): 26 halvings leave
    // (x1 − x0)·2⁻²⁶, below the f32 rounding of xu.
    let goal = u.x * r.solid_angle;
    var lo = r.x0;
    var hi = r.x1;
    for (var i = 0; i < 26; i++) {
        let mid = 0.5 * (lo + hi);
        if sub_rect_solid_angle(r, mid) < goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let xu = 0.5 * (lo + hi);
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

// A spherical triangle: its vertex vectors va, vb, vc from the receiver (their directions are the
// vertices), the triple product va·(vb × vc), and Ω (0: none).
struct SphTri {
    va: vec3<f32>,
    vb: vec3<f32>,
    vc: vec3<f32>,
    triple: f32,
    solid_angle: f32,
}

fn spherical_triangle(va: vec3<f32>, vb: vec3<f32>, vc: vec3<f32>, triple: f32) -> SphTri {
    let omega = oosterom(va, vb, vc, triple);
    return SphTri(va, vb, vc, triple, select(0.0, omega, omega > 0.0 && omega < 4.0 * PI));
}

// A direction uniform in the triangle (Arvo 1995): Ĉ on the arc AC where the sub-triangle A B Ĉ
// has solid angle u[0]·Ω, then the point on the arc B Ĉ whose 1 − cos of its distance from B is
// u[1] times the arc's.
fn triangle_sample(t: SphTri, u: vec2<f32>) -> vec3<f32> {
    // Ĉ = va + s (vc − va) (the chord projects onto the arc; the sub-triangle's triple product
    // is s·triple) by bisection on s (see the header).
    let goal = u.x * t.solid_angle;
    let ac = t.vc - t.va;
    var lo = 0.0;
    var hi = 1.0;
    for (var i = 0; i < 26; i++) {
        let mid = 0.5 * (lo + hi);
        if oosterom(t.va, t.vb, t.va + mid * ac, mid * t.triple) < goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c_hat = normalize(t.va + (0.5 * (lo + hi)) * ac);
    let b = normalize(t.vb);
    // 1 − cos from the chord, |Ĉ − b|²/2, which keeps its digits for short arcs.
    let chord = c_hat - b;
    let omc = u.y * 0.5 * dot(chord, chord);
    let z = 1.0 - omc;
    return normalize(z * b + sqrt(max(omc * (2.0 - omc), 0.0)) * ortho(c_hat, b));
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
    let t1 = spherical_triangle(va, vb, vc, triple);
    let t2 = spherical_triangle(va, vc, vd, triple);
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
