// Ray–shape tests in the light's local frame. Twin of src/cpu/shapes.rs, which states the
// one-sidedness rules (DESIGN.md §2 "Frames and shapes", "Edge cases").
// x: ray origin, d: ray direction (any length), both already mapped to local space.
//
// f32: plane_hit returns the hit point in xyz with w = 1 for a hit, w = 0 for none (the CPU: an
//   Option).

// Where a ray from the -Z side meets z = 0 travelling toward +Z; w = 0 when it does not.
fn plane_hit(x: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    if !(d.z > 0.0 && x.z < 0.0) {
        return vec4<f32>(0.0);
    }
    let t = -x.z / d.z;
    return vec4<f32>(x + t * d, 1.0);
}

fn rect_hit(x: vec3<f32>, d: vec3<f32>, hw: f32, hh: f32) -> bool {
    let p = plane_hit(x, d);
    return p.w > 0.0 && abs(p.x) <= hw && abs(p.y) <= hh;
}

fn disk_hit(x: vec3<f32>, d: vec3<f32>, r: f32) -> bool {
    let p = plane_hit(x, d);
    return p.w > 0.0 && p.x * p.x + p.y * p.y <= r * r;
}

fn sphere_hit(x: vec3<f32>, d: vec3<f32>, r: f32) -> bool {
    let r2 = r * r;
    if dot(x, x) <= r2 {
        return false;
    }
    let u = normalize(d);
    let tc = -dot(x, u);
    if tc <= 0.0 {
        return false;
    }
    let c = x + tc * u;
    return dot(c, c) <= r2;
}

fn cylinder_hit(x: vec3<f32>, d: vec3<f32>, hl: f32, r: f32) -> bool {
    let r2 = r * r;
    if x.y * x.y + x.z * x.z <= r2 {
        return false;
    }
    let dl = length(d.yz);
    if dl == 0.0 {
        return false;
    }
    let u = d.yz / dl;
    let tc = -dot(x.yz, u);
    if tc <= 0.0 {
        return false;
    }
    let c = x.yz + tc * u;
    let h2 = r2 - dot(c, c);
    if h2 < 0.0 {
        return false;
    }
    let t1 = (tc - sqrt(h2)) / dl;
    return abs(x.x + t1 * d.x) <= hl;
}
