//! Plane charts of the directions a receiver sees a light in (f64). Twin of
//! `shaders/irradiance/chart.wgsl`.
//!
//! The set of directions V in which x sees the emitting surface is parametrised by a plane
//! chart `w(X, Y) = W0 + X·E1 + Y·E2` (w = vector from x; a direction is ŵ):
//! - rect/disk: the light's own plane (region: the square / unit disk);
//! - sphere/ellipsoid: the disk bounded by the contact ellipse of the tangent cone from x (the
//!   tangent cone is the cone over that disk);
//! - cylinder: the plane through the axis facing x; V is `|Y| ≤ Yg` (the tangent planes), and on
//!   each line Y = const the X-range whose rays meet the side before an open end (closed form).
//!
//! In the chart `dω = H dA / |w|³`, so irradiance becomes a plane integral with the Jacobian
//! `J = |W0·(E1 × E2)|` (see `cpu::irradiance`).

// `!(a > b)` is deliberate throughout: a NaN fails the test and takes the safe branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::DVec3;

use crate::prepare::Prepared;

/// The region of a chart, in chart coordinates (X, Y).
#[derive(Clone, Debug)]
pub enum Region {
    /// |X|, |Y| ≤ 1.
    Square,
    /// X² + Y² ≤ 1.
    Disk,
    /// The cylinder seen from x (see [`cylinder_chart`]).
    Cylinder(Box<CylinderRegion>),
}

/// Light-space data of a cylinder chart: x at axial coordinate `xa` and distance `rho` from the
/// axis, radius `r`, half length `hl`; V spans |Y| ≤ `yg`.
#[derive(Clone, Debug)]
pub struct CylinderRegion {
    pub xa: f64,
    pub rho: f64,
    pub r: f64,
    pub hl: f64,
    pub yg: f64,
    /// The front arcs of the two end rings, as vectors from x.
    pub arcs: [Arc; 2],
}

/// An arc of a world-space ellipse as vectors from x: `w(t) = c + u cos t + v sin t`, t ∈ [t0, t1].
#[derive(Clone, Copy, Debug)]
pub struct Arc {
    pub c: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub t0: f64,
    pub t1: f64,
}

/// A plane chart of the directions x sees the light in: `w(X, Y) = w0 + X e1 + Y e2`.
#[derive(Clone, Debug)]
pub struct Chart {
    pub w0: DVec3,
    pub e1: DVec3,
    pub e2: DVec3,
    /// |w0 · (e1 × e2)|.
    pub jac: f64,
    pub region: Region,
}

/// The chart `w(X, Y) = w0 + X e1 + Y e2` over `region`.
pub fn make_chart(w0: DVec3, e1: DVec3, e2: DVec3, region: Region) -> Chart {
    Chart {
        w0,
        e1,
        e2,
        jac: w0.dot(e1.cross(e2)).abs(),
        region,
    }
}

/// The chart of a rect (`Region::Square`, half extents hx, hy) or disk (`Region::Disk`,
/// hx = hy = radius): the light's plane.
pub fn plane_chart(p: &Prepared, x: DVec3, hx: f64, hy: f64, region: Region) -> Chart {
    let m = p.linear;
    make_chart(p.origin - x, m * DVec3::X * hx, m * DVec3::Y * hy, region)
}

/// The chart of a sphere (any linear map: an ellipsoid) seen from x: the disk bounded by the
/// contact ellipse of the tangent cone. None when x is inside or on the sphere.
pub fn sphere_chart(p: &Prepared, x: DVec3, r: f64) -> Option<Chart> {
    let m = p.linear;
    let xl = p.to_local * (x - p.origin);
    let rho = xl.length();
    if !(rho > r) {
        return None;
    }
    // Contact circle in light space: centre xl·r²/ρ², radius r·√(ρ² − r²)/ρ, in the plane ⊥ xl.
    let k = (rho - r) * (rho + r);
    let rc = r * k.sqrt() / rho;
    let (e1, e2) = (xl / rho).any_orthonormal_pair();
    // w0 = M(c − xl) = −(ρ² − r²)/ρ² · (x − o).
    let w0 = (p.origin - x) * (k / (rho * rho));
    Some(make_chart(w0, m * e1 * rc, m * e2 * rc, Region::Disk))
}

/// The chart of a cylinder seen from x: the plane through the axis perpendicular to x's radial
/// direction (light space). None when x is inside the infinite cylinder (it sees only the
/// non-emitting inside, or nothing).
pub fn cylinder_chart(p: &Prepared, x: DVec3, hl: f64, r: f64) -> Option<Chart> {
    let m = p.linear;
    let xl = p.to_local * (x - p.origin);
    let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
    if !(rho > r) || !(hl > 0.0) || !(r > 0.0) {
        return None;
    }
    let (ry, rz) = (xl.y / rho, xl.z / rho);
    let perp = DVec3::new(0.0, -rz, ry);
    let w0 = p.origin - x;
    let e1 = m * DVec3::X;
    let e2 = m * perp;
    let yg = r * rho / ((rho - r) * (rho + r)).sqrt();
    // Front arcs of the end rings: ring points whose outward normal faces x.
    let tx = rz.atan2(ry);
    let half = (r / rho).acos();
    let ring = |end: f64| Arc {
        c: w0 + e1 * end,
        u: m * DVec3::Y * r,
        v: m * DVec3::Z * r,
        t0: tx - half,
        t1: tx + half,
    };
    Some(make_chart(
        w0,
        e1,
        e2,
        Region::Cylinder(Box::new(CylinderRegion {
            xa: xl.x,
            rho,
            r,
            hl,
            yg,
            arcs: [ring(-hl), ring(hl)],
        })),
    ))
}

impl Chart {
    pub fn y_range(&self) -> (f64, f64) {
        match &self.region {
            Region::Square | Region::Disk => (-1.0, 1.0),
            Region::Cylinder(c) => (-c.yg, c.yg),
        }
    }

    /// The region's X-interval on the line Y = y.
    pub fn x_interval(&self, y: f64) -> Option<(f64, f64)> {
        match &self.region {
            Region::Square => Some((-1.0, 1.0)),
            Region::Disk => {
                let h = (1.0 - y * y).max(0.0).sqrt();
                Some((-h, h))
            }
            Region::Cylinder(c) => {
                let (r2, rho2) = (c.r * c.r, c.rho * c.rho);
                let k = rho2 - r2;
                // First hit of the ray's light-space yz projection with the circle, as a
                // fraction of the way to the chart plane.
                let tau = k / (rho2 + (k * (c.yg * c.yg - y * y)).max(0.0).sqrt());
                if !(tau > 0.0) {
                    return None;
                }
                Some((c.xa + (-c.hl - c.xa) / tau, c.xa + (c.hl - c.xa) / tau))
            }
        }
    }

    /// The chart's Y for the direction w (from x), or None when the ray does not reach the
    /// chart plane.
    pub fn chart_y(&self, w: DVec3) -> Option<f64> {
        let nrm = self.e1.cross(self.e2);
        let den = w.dot(nrm);
        if den == 0.0 {
            return None;
        }
        let lambda = self.w0.dot(nrm) / den;
        if !(lambda > 0.0) {
            return None;
        }
        let pnt = w * lambda - self.w0;
        Some(pnt.dot(nrm.cross(self.e1)) / nrm.length_squared())
    }
}

/// The point of `arc` at parameter t.
pub fn arc_at(arc: &Arc, t: f64) -> DVec3 {
    arc.c + arc.u * t.cos() + arc.v * t.sin()
}
