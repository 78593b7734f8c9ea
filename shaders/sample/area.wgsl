// Disk, cylinder and ellipsoid lights sampled in the light's own frame (f32), DESIGN.md §9 S2.
// Twin of src/cpu/sample/area.rs, which carries the derivation: a local sample carried to world
// by the Jacobian |det A| / |Aω|³ of the direction map.
//
// Each sampler returns vec4(ω, pdf) with pdf 0 where the CPU returns None.
// f32: the cylinder's azimuth of x is shared/math.wgsl's atan2_accurate, and its visible
//   half-width β = acos(r/ρ) is atan2(√((ρ − r)(ρ + r)), r), which keeps its digits for a
//   receiver near the surface (acos loses half of them near 1).
// f32: cylinder_pdf forms the root's c = ρ² − r² as (ρ − r)(ρ + r) and its discriminant
//   b² − 4ac as 4a(r − p)(r + p), p the distance of the ray's yz line from the axis (b² − 4ac
//   cancels to 1e-4 relative when the receiver is 20 radii away); and the entry point's |Δ| as
//   asin(p/r) − γ (γ the ray's angle off the direction toward the axis) rather than from the
//   entry point, whose yz components cancel to r out of ρ-sized terms.

// #import shared/record.wgsl
// #import shared/shapes.wgsl
// #import shared/math.wgsl
// #import sample/cone.wgsl

// World solid angle → local solid angle at the world direction w: |det A| / |Aω|³.
fn local_jacobian(light: Record, w: vec3<f32>) -> f32 {
    let l = length(to_local_dir(light, w));
    return 1.0 / (light.irr.y * l * l * l);
}

// The local direction d_l carried to world, with the world density for the local density pdf_l.
fn to_world(light: Record, d_l: vec3<f32>, pdf_l: f32) -> vec4<f32> {
    let w = normalize(to_world_dir(light, d_l));
    return vec4<f32>(w, pdf_l * local_jacobian(light, w));
}

// Disk of radius r (local XY plane) seen from the local point xl (xl.z < 0): a point uniform in
// its area (Shirley & Chiu's concentric map).
fn disk_sample(light: Record, xl: vec3<f32>, r: f32, u: vec2<f32>) -> vec4<f32> {
    let a = 2.0 * u.x - 1.0;
    let b = 2.0 * u.y - 1.0;
    var rho = 0.0;
    var phi = 0.0;
    if a == 0.0 && b == 0.0 {
        rho = 0.0;
    } else if abs(a) > abs(b) {
        rho = a;
        phi = PI / 4.0 * (b / a);
    } else {
        rho = b;
        phi = PI / 2.0 - PI / 4.0 * (a / b);
    }
    let y = vec3<f32>(r * rho * cos(phi), r * rho * sin(phi), 0.0);
    let d = y - xl;
    let dist2 = dot(d, d);
    let cs = d.z / sqrt(dist2);
    return to_world(light, d, dist2 / (PI * r * r * cs));
}

// The density disk_sample draws the world direction w with.
fn disk_pdf(light: Record, xl: vec3<f32>, r: f32, w: vec3<f32>) -> f32 {
    let dl = to_local_dir(light, w);
    if !disk_hit(xl, dl, r) {
        return 0.0;
    }
    let y = plane_hit(xl, dl);
    if !(y.w > 0.0) {
        return 0.0;
    }
    let d = y.xyz - xl;
    let dist2 = dot(d, d);
    return dist2 / (PI * r * r * (d.z / sqrt(dist2))) * local_jacobian(light, w);
}

// The band of a cylinder (local X axis) the local point xl sees: vec2(x's azimuth, β); β < 0
// from inside the infinite cylinder.
fn visible_band(xl: vec3<f32>, r: f32) -> vec2<f32> {
    let rho = sqrt(xl.y * xl.y + xl.z * xl.z);
    if !(rho > r) {
        return vec2<f32>(0.0, -1.0);
    }
    return vec2<f32>(atan2_accurate(xl.z, xl.y), atan2_accurate(sqrt((rho - r) * (rho + r)), r));
}

// (x − y)·n for the band point at azimuth Δ from x's own: 2ρ sin((β + |Δ|)/2) sin((β − |Δ|)/2).
fn facing(xl: vec3<f32>, beta: f32, delta: f32) -> f32 {
    let rho = sqrt(xl.y * xl.y + xl.z * xl.z);
    let a = abs(delta);
    return 2.0 * rho * sin(0.5 * (beta + a)) * sin(0.5 * (beta - a));
}

// A point uniform in the area of the visible band (half-length hl, radius r).
fn cylinder_sample(light: Record, xl: vec3<f32>, hl: f32, r: f32, u: vec2<f32>) -> vec4<f32> {
    let band = visible_band(xl, r);
    let beta = band.y;
    if !(beta >= 0.0) {
        return vec4<f32>(0.0);
    }
    let delta = beta * (2.0 * u.y - 1.0);
    let ang = band.x + delta;
    let y = vec3<f32>(hl * (2.0 * u.x - 1.0), r * cos(ang), r * sin(ang));
    let d = y - xl;
    let dist2 = dot(d, d);
    let cs = facing(xl, beta, delta) / sqrt(dist2);
    if !(cs > 0.0) {
        return vec4<f32>(0.0);
    }
    return to_world(light, d, dist2 / (4.0 * beta * r * hl * cs));
}

// The density cylinder_sample draws the world direction w with: through the entry point of the
// ray on the outer wall.
fn cylinder_pdf(light: Record, xl: vec3<f32>, hl: f32, r: f32, w: vec3<f32>) -> f32 {
    let dl = to_local_dir(light, w);
    if !cylinder_hit(xl, dl, hl, r) {
        return 0.0;
    }
    let band = visible_band(xl, r);
    let beta = band.y;
    if !(beta >= 0.0) {
        return 0.0;
    }
    // The nearer root of |(x + t d)_yz|² = r², in the cancellation-free form, with the
    // discriminant b² − 4ac = 4a(r² − p²).
    let pyz = vec2<f32>(xl.y, xl.z);
    let dyz = vec2<f32>(dl.y, dl.z);
    let rho = length(pyz);
    let a = dot(dyz, dyz);
    let la = sqrt(a);
    let p = abs(pyz.x * dyz.y - pyz.y * dyz.x) / la;
    let b = 2.0 * dot(pyz, dyz);
    let c = (rho - r) * (rho + r);
    let rp = max((r - p) * (r + p), 0.0);
    let q = -0.5 * (b + select(-1.0, 1.0, b >= 0.0) * sqrt(4.0 * a * rp));
    let t = min(q / a, c / q);
    let d = t * dl;
    let dist2 = dot(d, d);
    // |Δ|, the entry point's azimuth from x's: asin(p/r) − γ, γ the ray's angle off −x_yz.
    let gamma = atan2_accurate(p, -dot(pyz, dyz) / la);
    let delta = atan2_accurate(p, sqrt(rp)) - gamma;
    let cs = facing(xl, beta, delta) / sqrt(dist2);
    if !(cs > 0.0) {
        return 0.0;
    }
    return dist2 / (4.0 * beta * r * hl * cs) * local_jacobian(light, w);
}

// The cone the local sphere of radius r subtends from xl; w < 0 from inside.
fn local_cone(xl: vec3<f32>, r: f32) -> vec4<f32> {
    let d = length(xl);
    if !(d > r) {
        return vec4<f32>(0.0, 0.0, 0.0, -1.0);
    }
    return subtended(-xl / d, r, d);
}

// A sphere light under any transform: uniform in the local subtended cone, carried to world.
fn ellipsoid_sample(light: Record, xl: vec3<f32>, r: f32, u: vec2<f32>) -> vec4<f32> {
    let c = local_cone(xl, r);
    if c.w < 0.0 {
        return vec4<f32>(0.0);
    }
    return to_world(light, sample(c, u), 1.0 / solid_angle(c));
}

// The density ellipsoid_sample draws the world direction w with.
fn ellipsoid_pdf(light: Record, xl: vec3<f32>, r: f32, w: vec3<f32>) -> f32 {
    let c = local_cone(xl, r);
    if c.w < 0.0 {
        return 0.0;
    }
    return pdf(c, normalize(to_local_dir(light, w))) * local_jacobian(light, w);
}
