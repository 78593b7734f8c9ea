// Plane charts of the directions a receiver sees a light in.
// Twin of src/cpu/irradiance/chart.rs, which carries the derivations.
//
// f32: the region and its arcs live in one flat struct (no enums with data in WGSL); an
//   invalid chart has jac = 0 where the CPU returns None.
// GPU-only Chart: the CPU's Chart, Region, CylinderRegion and Arc in one struct.

// #import shared/record.wgsl
// #import shared/math.wgsl

const REGION_SQUARE: u32 = 0u;
const REGION_DISK: u32 = 1u;
const REGION_CYLINDER: u32 = 2u;

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
fn plane_chart(light: Record, x: vec3<f32>, hx: f32, hy: f32, region: u32) -> Chart {
    return make_chart(world_origin(light) - x, light.world_x.xyz * hx, light.world_y.xyz * hy, region);
}

// The chart of a sphere (ellipsoid) from x: the disk of the tangent cone's contact ellipse.
// jac = 0 when x is inside or on the sphere.
fn sphere_chart(light: Record, x: vec3<f32>) -> Chart {
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
fn cylinder_chart(light: Record, x: vec3<f32>) -> Chart {
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
