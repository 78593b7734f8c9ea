//! irradiance(x, n) on the CPU (f64). Twin of `shaders/irradiance.wgsl`.
//!
//! DESIGN.md §3: `E = diffuse · ∫ radiance(x, ω) max(0, n·ω) dω` over all directions, per light,
//! with no occlusion; the receiver is one-sided (n·ω ≤ 0 contributes nothing). The target is
//! 1e-6 relative to the exact value; every path below meets it with margin (the tests compare
//! them with closed forms and with independent quadrature written in the tests).
//!
//! # Closed forms
//! - **Dome** (uniform): `π·L`.
//! - **Distant**, delta (angle 0): `L·max(0, n·c)`, c = direction toward the light (DESIGN.md §2
//!   "Edge cases"). Finite cone of half-angle α around c: [`cap_irradiance`], the clipped
//!   spherical cap integrated by Stokes' theorem over its boundary (the small-circle arc above the
//!   horizon plus the horizon arc inside the cap), written without cancellation for small caps;
//!   caps wider than a hemisphere (angle up to 360°) by the complement.
//! - **Sphere** under a similarity transform, unshaped: the same cap, α = asin(r/d); a point inside
//!   the sphere receives 0.
//! - **Rect**, unshaped: Lambert's polygon formula `E = (L/2)·Σ Θᵢ n·ĝᵢ` on the parallelogram
//!   clipped to the receiver's upper half-space, edge angles Θ by atan2 of cross and dot.
//! - **treatAsPoint**: `E = L(e)·A(e)·max(0, n·ω)/d²`, A(e) = π r²·|det M|·|M⁻¹e| the projected
//!   area of the full-size (ellipsoidal) sphere along e (DESIGN.md §2 "Edge cases").
//!
//! # Quadrature (everything else)
//! Shaped lights, disks (an ellipse under any linear map), ellipsoids, cylinders and
//! `treatAsLine` use one deterministic scheme, [`chart_irradiance`]. The set of directions V in
//! which x sees the emitting surface is parametrised by a plane *chart*
//! `w(X, Y) = W0 + X·E1 + Y·E2` (w = vector from x; a direction is ŵ):
//! - rect/disk: the light's own plane (region: the square / unit disk);
//! - sphere/ellipsoid: the disk bounded by the contact ellipse of the tangent cone from x (the
//!   tangent cone is the cone over that disk);
//! - cylinder: the plane through the axis facing x; V is `|Y| ≤ Yg` (the tangent planes), and on
//!   each line Y = const the X-range whose rays meet the side before an open end (closed form).
//!
//! In the chart `dω = H dA / |w|³`, so `E = L·∫∫ S(−ŵ)·max(0, n·w)·J/|w|⁴ dX dY` with
//! `J = |W0·(E1 × E2)|` (distance to the chart plane × area scale) and S the RGB shaping factor
//! of the emission direction e = −ŵ (any function of e: cone, softness, focus, tint now; IES and
//! textures later). The integral is taken over lines Y = const (planes through x containing E1):
//! - **inner** (along a line): the region's X-interval, clipped at the receiver horizon
//!   (n·w = 0: linear in X), split where S is not smooth. Every such set is a cone of emission
//!   angle θ around the light's axis (cone edge, smoothstep start: quadratic in X) or a plane
//!   through x (focus at θ = 90°: linear; IES φ planes would be the same): the split points are
//!   exact roots. Unshaped: closed form after X = X* + w·tan u (the line's closest approach X*,
//!   width w), which turns `(n·w)/|w|⁴ dX` into a trigonometric polynomial. Shaped: adaptive
//!   Gauss–Kronrod (G7K15) on each smooth piece, with the same tan map when the piece reaches
//!   within a few widths of the closest approach (the near-field peak), and a cubic grading at
//!   the focus plane where |cos θ|^focus is not smooth.
//! - **outer** (across lines): split at every Y where the inner structure changes: the region's
//!   ends (square edges; disk and cylinder ends, where the X-interval closes like a square
//!   root), the horizon crossing the region boundary, the cone-edge cones tangent to a line of
//!   the pencil (closed form: a plane through x containing E1 tangent to a circular cone),
//!   crossing the region boundary (quadratic for straight edges; for elliptic boundaries the
//!   degree-2 trigonometric equation is solved by bracketing and bisection) or the horizon, and
//!   the focus plane crossing either. Each piece is mapped by a cosine substitution
//!   `Y = Y0 + (Y1 − Y0)(1 − cos πs)/2`, which makes square-root ends smooth, after a tan map
//!   around the foot of x when x is close to the chart plane; then adaptive G7K15 to 1e-10
//!   relative. Kinks at the ends of a piece cost nothing; a split placed slightly off (bisection
//!   precision) leaves an error of second order in the offset.
//!
//! `treatAsLine` is one inner line: the segment along the axis, whose intensity along e is
//! `L(e)·2·length·r·|det M|·|(M⁻¹e)_yz|`, which gives the weight `2 r |det M| ρ` (ρ = distance
//! of x from the axis in light space) for the same integrand.

// `!(a > b)` is deliberate throughout: a NaN fails the test and takes the safe branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::{DMat3, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};

use super::PreparedLight;
use super::normalize::distant_half_angle;
use super::quadrature::{Tolerance, integrate};
use super::shaping::shaping;
use crate::light::{LightType, Shaping};

/// Relative tolerance of the outer adaptive integral (the tests measure the result within
/// ~1e-8 of independent references).
const OUTER_REL: f64 = 1e-9;
/// Relative tolerance of each inner (line) integral.
const INNER_REL: f64 = 1e-10;
/// A tan map is used on a piece when the line's closest approach (a pole at distance `width`
/// off the real axis) lies within this Bernstein-ellipse parameter of the piece.
pub const TAN_MAP_RHO: f64 = 3.0;
/// Samples per arc when bracketing the roots of a degree-2 trigonometric polynomial.
const ARC_SAMPLES: usize = 64;

/// irradiance at `x` for a receiver with normal `n` (any non-zero length; normalised here),
/// `diffuse` applied. A zero or non-finite normal gives 0.
pub fn irradiance(p: &PreparedLight, x: DVec3, n: DVec3) -> DVec3 {
    irradiance_with(p, x, n, Rule::Adaptive)
}

/// [`irradiance`] with the quadrature's [`Rule`] chosen (closed forms are used either way).
pub fn irradiance_with(p: &PreparedLight, x: DVec3, n: DVec3, rule: Rule) -> DVec3 {
    let len = n.length();
    if !(len > 0.0 && len.is_finite()) {
        return DVec3::ZERO;
    }
    let n = n / len;
    let e = match p.light.kind {
        LightType::Dome => p.base * PI,
        LightType::Distant { angle } => {
            let c = -p.axis;
            let theta_max = distant_half_angle(angle);
            let sg = n.dot(c);
            if theta_max == 0.0 {
                p.base * sg.max(0.0)
            } else {
                p.base * cap_irradiance(theta_max, sg, n.cross(c).length())
            }
        }
        LightType::Sphere {
            radius,
            treat_as_point: true,
        } => point_irradiance(p, x, n, radius),
        LightType::Sphere { radius, .. } => {
            match (&p.light.shaping, similarity_scale(p.light.linear())) {
                (None, Some(scale)) => p.base * sphere_cap(p.origin, radius * scale, x, n),
                _ => match sphere_chart(p, x, radius) {
                    Some(c) => chart_irradiance(p, &c, n, rule),
                    None => DVec3::ZERO,
                },
            }
        }
        LightType::Rect { width, height } => {
            let xl = p.to_local * (x - p.origin);
            if !(xl.z < 0.0) {
                DVec3::ZERO
            } else if p.light.shaping.is_none() {
                p.base * rect_lambert(p, x, n, width / 2.0, height / 2.0)
            } else {
                chart_irradiance(
                    p,
                    &plane_chart(p, x, width / 2.0, height / 2.0, Region::Square),
                    n,
                    rule,
                )
            }
        }
        LightType::Disk { radius } => {
            let xl = p.to_local * (x - p.origin);
            if !(xl.z < 0.0) {
                DVec3::ZERO
            } else {
                chart_irradiance(p, &plane_chart(p, x, radius, radius, Region::Disk), n, rule)
            }
        }
        LightType::Cylinder {
            length,
            radius,
            treat_as_line: true,
        } => line_irradiance(p, x, n, length / 2.0, radius, rule),
        LightType::Cylinder { length, radius, .. } => {
            match cylinder_chart(p, x, length / 2.0, radius) {
                Some(c) => chart_irradiance(p, &c, n, rule),
                None => DVec3::ZERO,
            }
        }
    };
    e * p.light.inputs.diffuse
}

// ---------------------------------------------------------------------------------------------
// Closed forms
// ---------------------------------------------------------------------------------------------

/// ∫ max(0, n·ω) dω over the spherical cap of half-angle `alpha` (radians, (0, π]) around a unit
/// direction c, given `sg = n·c` (the sine of c's elevation γ above the receiver's horizon) and
/// `cg = |n × c|` (its cosine).
///
/// By Stokes' theorem, ∫_R n·ω dω = ½ ∮_∂R n·(ω × dω). For the part of the cap above the
/// horizon, ∂R is the cap's circle for |φ| ≤ φ0 (φ = azimuth around c from the side of n,
/// cos φ0 = −cot α·tan γ) and the horizon arc inside the cap (half-angle ψ0, sin ψ0 = sin α sin φ0):
/// `E = φ0 sin²α sin γ − sin α cos α cos γ sin φ0 + ψ0` (Snyder's sphere-light formula). With
/// k = sin α sin φ0 = √(sin(α−γ) sin(α+γ))/cos γ the last two terms are
/// `(asin k − k) + k·(2 sin²(α/2) + 2 cos α sin²(γ/2))`: no cancellation for small caps.
/// Fully above the horizon: `π sin²α sin γ`; fully below: 0. A cap wider than a hemisphere is
/// the sphere (π) minus its complement.
pub fn cap_irradiance(alpha: f64, sg: f64, cg: f64) -> f64 {
    if !(alpha > 0.0) {
        return 0.0;
    }
    if alpha > FRAC_PI_2 {
        let ac = PI - alpha;
        let gamma = sg.atan2(cg);
        if -gamma >= ac {
            // The complement lies wholly above the horizon of −n: π − π sin²ac·|sin γ|, written
            // as π(cos²ac + sin²ac·(1 − |sin γ|)).
            let (sa, ca) = ac.sin_cos();
            let q = (0.5 * (FRAC_PI_2 - gamma.abs())).sin();
            return PI * (ca * ca + sa * sa * 2.0 * q * q);
        }
        return PI - cap_within_hemisphere(ac, -sg, cg);
    }
    cap_within_hemisphere(alpha, sg, cg)
}

/// [`cap_irradiance`] for α ≤ π/2.
fn cap_within_hemisphere(alpha: f64, sg: f64, cg: f64) -> f64 {
    let (sa, ca) = alpha.sin_cos();
    let gamma = sg.atan2(cg);
    if gamma >= alpha {
        return PI * sa * sa * sg;
    }
    if gamma <= -alpha {
        return 0.0;
    }
    // |γ| < α ≤ π/2, so cos γ > 0 and sin α > 0.
    let t = sg * ca / (cg * sa);
    let root = ((alpha - gamma).sin() * (alpha + gamma).sin())
        .max(0.0)
        .sqrt();
    let k = (root / cg).min(1.0);
    let sin_phi0 = root / (cg * sa);
    let phi0 = sin_phi0.atan2(-t);
    let (h, g) = ((0.5 * alpha).sin(), (0.5 * gamma).sin());
    // ψ0 = asin k, with cos ψ0 = cos α / cos γ (ψ0 ≤ π/2): atan2 stays accurate as k → 1.
    phi0 * sa * sa * sg + asin_minus_x(k, ca / cg) + k * (2.0 * h * h + 2.0 * ca * g * g)
}

/// asin(k) − k for k in [0, 1] given also kc = √(1 − k²): by its series where the difference
/// cancels, else atan2(k, kc) − k (asin itself loses half the digits near 1).
pub fn asin_minus_x(k: f64, kc: f64) -> f64 {
    if k > 0.1 {
        return k.atan2(kc) - k;
    }
    // Σ_{j≥1} (2j)!/(4^j (j!)² (2j+1)) k^(2j+1); ten terms: truncation < 1e-21 relative at 0.1.
    let k2 = k * k;
    let mut c = 1.0f64; // (2j)!/(4^j (j!)²)
    let mut term_pow = k;
    let mut sum = 0.0;
    for j in 1..=10 {
        c *= (2 * j - 1) as f64 / (2 * j) as f64;
        term_pow *= k2;
        sum += c * term_pow / (2 * j + 1) as f64;
    }
    sum
}

/// The scale s when `m` is a similarity (s times an orthogonal matrix) to 1e-12, else None.
pub fn similarity_scale(m: DMat3) -> Option<f64> {
    let g = m.transpose() * m;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let dev = (g - DMat3::from_diagonal(DVec3::splat(s2))).to_cols_array();
    if s2 > 0.0 && dev.iter().all(|d| d.abs() <= 1e-12 * s2) {
        Some(s2.sqrt())
    } else {
        None
    }
}

/// Unit-radiance irradiance of a uniform sphere of world radius `r` centred at `o`.
pub fn sphere_cap(o: DVec3, r: f64, x: DVec3, n: DVec3) -> f64 {
    let w = o - x;
    let d = w.length();
    if !(d > r) {
        return 0.0;
    }
    let c = w / d;
    // sin α = r/d, written through asin for the cap formula.
    let alpha = (r / d).asin();
    cap_irradiance(alpha, n.dot(c), n.cross(c).length())
}

/// Unit-radiance irradiance of an unshaped rect (half extents `hw`, `hh`) by Lambert's formula
/// on the parallelogram clipped to n·(P − x) ≥ 0. The caller checks that x is on the emitting
/// side.
fn rect_lambert(p: &PreparedLight, x: DVec3, n: DVec3, hw: f64, hh: f64) -> f64 {
    let m = p.light.linear();
    let o = p.origin - x;
    let q =
        [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)].map(|(a, b)| o + m * DVec3::new(a, b, 0.0));
    polygon_irradiance(&q, n)
}

/// Lambert's formula for a convex planar polygon given by the vectors `q` from x to its vertices
/// (in order), clipped to the receiver's upper half-space.
pub fn polygon_irradiance(q: &[DVec3], n: DVec3) -> f64 {
    if q.len() < 3 {
        return 0.0;
    }
    // Orientation: +1 when the vertices run counter-clockwise seen from x.
    let sigma = ((q[1] - q[0]).cross(q[2] - q[1])).dot(q[0]).signum();
    let mut clipped: Vec<DVec3> = Vec::with_capacity(q.len() + 1);
    for i in 0..q.len() {
        let (a, b) = (q[i], q[(i + 1) % q.len()]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            clipped.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped.push(a + (b - a) * (da / (da - db)));
        }
    }
    let mut sum = 0.0;
    for i in 0..clipped.len() {
        let (a, b) = (clipped[i], clipped[(i + 1) % clipped.len()]);
        let c = a.cross(b);
        let len = c.length();
        if len > 0.0 {
            sum += len.atan2(a.dot(b)) * n.dot(c) / len;
        }
    }
    (0.5 * sigma * sum).max(0.0)
}

/// treatAsPoint: the full-size sphere's intensity from its origin (DESIGN.md §2).
fn point_irradiance(p: &PreparedLight, x: DVec3, n: DVec3, radius: f64) -> DVec3 {
    let w = p.origin - x;
    let d = w.length();
    if !(d > 0.0) {
        return DVec3::ZERO;
    }
    let cos_r = n.dot(w) / d;
    if !(cos_r > 0.0) {
        return DVec3::ZERO;
    }
    let e = -w / d;
    let xl = p.to_local * (x - p.origin);
    // Projected area of the ellipsoid {M y : |y| ≤ r} along e: π r² |det M| |M⁻¹ e|.
    let area = PI * radius * radius * p.light.linear().determinant().abs() * xl.length() / d;
    shaped(p, e) * (area * cos_r / (d * d))
}

/// The RGB radiance of the light along emission direction e (unit), before one-sidedness.
fn shaped(p: &PreparedLight, e: DVec3) -> DVec3 {
    match &p.light.shaping {
        Some(s) => p.base * shaping(s, p.axis, e),
        None => p.base,
    }
}

// ---------------------------------------------------------------------------------------------
// Quadrature
// ---------------------------------------------------------------------------------------------

/// Where the integrand is not smooth, as sets of vectors w from x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kink {
    /// Emission directions at angle acos(cos) from the axis: `−ŵ·a = cos` (cos ≠ 0).
    Cone { cos: f64 },
    /// The plane m·w = 0 through x; `graded` marks a plane where the integrand behaves like
    /// |m·ŵ|^p (the focus plane), which the inner quadrature grades toward.
    Plane { m: DVec3, graded: bool },
}

/// The shaping function of a light as the quadrature sees it.
#[derive(Clone, Debug)]
pub struct Profile {
    pub shaping: Option<Shaping>,
    pub axis: DVec3,
    pub kinks: Vec<Kink>,
    /// ShapingAPI makes the light dark everywhere (cone angle ≤ 0).
    pub dark: bool,
    /// The factor is not smooth at the axis directions themselves (θ = 0 when the smoothstep
    /// starts there, softness ≥ 1: a |θ|³ term; θ = π when the smoothstep is active there,
    /// cone > 180°: a |π − θ| cone point).
    pub axis_singular: bool,
}

impl Profile {
    pub fn new(shaping: Option<&Shaping>, axis: DVec3) -> Self {
        let mut kinks = Vec::new();
        let mut dark = false;
        let mut axis_singular = false;
        if let Some(s) = shaping {
            let cone = s.cone_angle.to_radians();
            let start = (1.0 - s.cone_softness.clamp(0.0, 1.0)) * cone;
            dark = !(cone > 0.0);
            axis_singular = cone > 0.0 && (start == 0.0 || (cone > PI && start < PI));
            let mut focus_plane = false;
            for theta in [start, cone] {
                if theta > 0.0 && theta < PI {
                    if theta == FRAC_PI_2 {
                        focus_plane = true;
                    } else {
                        let k = Kink::Cone { cos: theta.cos() };
                        if !kinks.contains(&k) {
                            kinks.push(k);
                        }
                    }
                }
            }
            let focus_active = s.focus > 0.0 && s.focus_tint != DVec3::ONE;
            if focus_active || focus_plane {
                kinks.push(Kink::Plane {
                    m: axis,
                    graded: focus_active,
                });
            }
        }
        Profile {
            shaping: shaping.cloned(),
            axis,
            kinks,
            dark,
            axis_singular,
        }
    }

    /// The RGB shaping factor of emission direction e (unit).
    pub fn factor(&self, e: DVec3) -> DVec3 {
        match &self.shaping {
            Some(s) => shaping(s, self.axis, e),
            None => DVec3::ONE,
        }
    }
}

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

impl Arc {
    pub fn at(&self, t: f64) -> DVec3 {
        self.c + self.u * t.cos() + self.v * t.sin()
    }
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

impl Chart {
    fn new(w0: DVec3, e1: DVec3, e2: DVec3, region: Region) -> Self {
        Chart {
            w0,
            e1,
            e2,
            jac: w0.dot(e1.cross(e2)).abs(),
            region,
        }
    }

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
    pub fn y_of(&self, w: DVec3) -> Option<f64> {
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

/// The chart of a rect (`Region::Square`, half extents hx, hy) or disk (`Region::Disk`,
/// hx = hy = radius): the light's plane.
pub fn plane_chart(p: &PreparedLight, x: DVec3, hx: f64, hy: f64, region: Region) -> Chart {
    let m = p.light.linear();
    Chart::new(p.origin - x, m * DVec3::X * hx, m * DVec3::Y * hy, region)
}

/// The chart of a sphere (any linear map: an ellipsoid) seen from x: the disk bounded by the
/// contact ellipse of the tangent cone. None when x is inside or on the sphere.
pub fn sphere_chart(p: &PreparedLight, x: DVec3, r: f64) -> Option<Chart> {
    let m = p.light.linear();
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
    Some(Chart::new(w0, m * e1 * rc, m * e2 * rc, Region::Disk))
}

/// The chart of a cylinder seen from x: the plane through the axis perpendicular to x's radial
/// direction (light space). None when x is inside the infinite cylinder (it sees only the
/// non-emitting inside, or nothing).
pub fn cylinder_chart(p: &PreparedLight, x: DVec3, hl: f64, r: f64) -> Option<Chart> {
    let m = p.light.linear();
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
    Some(Chart::new(
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

/// Everything one quadrature evaluation needs.
struct Ctx<'a> {
    prof: &'a Profile,
    n: DVec3,
    /// Use the closed-form inner integral (no shaping).
    unshaped: bool,
    rule: &'a Nodes,
}

/// How [`chart_integral`] integrates each smooth piece.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Adaptive Gauss–Kronrod to 1e-10 (outer) / 1e-11 (inner) relative: the reference.
    Adaptive,
    /// The scheme of the WGSL kernel, run here in f64 so that tests can separate its quadrature
    /// error from f32 rounding: per outer span the Gauss–Kronrod 7/15 pair, halved while they
    /// differ by more than `IRR_OUTER_TOL` (at most `IRR_OUTER_DEPTH` times); per inner span
    /// `IRR_GL_INNER`-point Gauss–Legendre, halved while halves and parent differ by more than
    /// `IRR_INNER_TOL` (at most `IRR_INNER_DEPTH` times). Constants in `gpu::pack`.
    Kernel,
}

/// The quadrature of [`chart_integral`] and [`line_integral`]: the reference or the kernel's.
struct Nodes {
    /// The kernel rule's inner Gauss–Legendre nodes and weights on [0, 1]; None: the reference.
    kernel: Option<(Vec<f64>, Vec<f64>)>,
    /// Absolute tolerances of the adaptive outer (0) and inner (1) integrals (see
    /// [`ABS_FRACTION`]); 0 where no scale is known.
    abs: [f64; 2],
}

/// The adaptive reference also stops once its error estimate is below this fraction of the
/// whole irradiance (estimated first with the kernel's rule): pieces that contribute
/// nothing measurable (a factor that is zero up to rounding, a far corner of a cone's tail)
/// cannot reach a relative tolerance of their own, and would each run to the interval cap.
pub const ABS_FRACTION: f64 = 1e-12;

impl Nodes {
    fn new(rule: Rule) -> Self {
        Nodes {
            kernel: match rule {
                Rule::Adaptive => None,
                Rule::Kernel => Some(super::quadrature::gauss_legendre(
                    crate::gpu::pack::IRR_GL_INNER,
                )),
            },
            abs: [0.0; 2],
        }
    }

    /// ∫₀¹ f by the kernel's outer (0) or inner (1) rule, or by the adaptive reference.
    fn integrate(&self, which: usize, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        match &self.kernel {
            Some((x, w)) => {
                if which == 0 {
                    // The kernel's outer rule: Gauss–Kronrod 7/15 per span, halved while the
                    // pair disagrees by more than IRR_OUTER_TOL (relative), depth first.
                    use crate::gpu::pack::{IRR_OUTER_DEPTH, IRR_OUTER_TOL};
                    let mut sum = DVec3::ZERO;
                    let mut stack = vec![(0.0, 1.0, 0)];
                    while let Some((s0, s1, depth)) = stack.pop() {
                        let (k, err) = super::quadrature::gk15(f, s0, s1);
                        if depth + 1 >= IRR_OUTER_DEPTH
                            || err <= IRR_OUTER_TOL * k.abs().max_element()
                        {
                            sum += k;
                        } else {
                            let mid = 0.5 * (s0 + s1);
                            stack.push((mid, s1, depth + 1));
                            stack.push((s0, mid, depth + 1));
                        }
                    }
                    return sum;
                }
                let mut rule = |s0: f64, s1: f64| -> DVec3 {
                    let h = s1 - s0;
                    x.iter().zip(w).map(|(x, w)| f(s0 + h * x) * (w * h)).sum()
                };
                // The kernel's inner rule: halving until the halves agree with their parent to
                // IRR_INNER_TOL (relative, the integrand is ≥ 0) or IRR_INNER_DEPTH is reached,
                // depth first, in the same order as the WGSL twin.
                use crate::gpu::pack::{IRR_INNER_DEPTH, IRR_INNER_TOL};
                let mut sum = DVec3::ZERO;
                let mut stack = vec![(0.0, 1.0, rule(0.0, 1.0), 0)];
                while let Some((s0, s1, q, depth)) = stack.pop() {
                    let mid = 0.5 * (s0 + s1);
                    let (ql, qr) = (rule(s0, mid), rule(mid, s1));
                    let fine = ql + qr;
                    if depth + 1 >= IRR_INNER_DEPTH
                        || (fine - q).abs().max_element()
                            <= IRR_INNER_TOL * fine.abs().max_element()
                    {
                        sum += fine;
                    } else {
                        stack.push((mid, s1, qr, depth + 1));
                        stack.push((s0, mid, ql, depth + 1));
                    }
                }
                sum
            }
            None => integrate(
                f,
                &[0.0, 1.0],
                Tolerance {
                    rel: if which == 0 { OUTER_REL } else { INNER_REL },
                    abs: self.abs[which],
                    max_intervals: if which == 0 { 4000 } else { 400 },
                },
            ),
        }
    }
}

/// A tan-mapped piece spanning more than this many radians of u is cut into equal spans, so
/// that the kernel's rule resolves both the near-field peak and the piece's ends.
pub const MAX_U_SPAN: f64 = 0.8;

/// Unit-base irradiance (times `p.base`) of the chart's region by the scheme in the module docs.
pub fn chart_irradiance(p: &PreparedLight, chart: &Chart, n: DVec3, rule: Rule) -> DVec3 {
    let prof = Profile::new(p.light.shaping.as_ref(), p.axis);
    p.base * chart_integral(&prof, chart, n, rule)
}

/// `∫∫ S(−ŵ)·max(0, n·w)·J/|w|⁴ dX dY` over the chart's region.
pub fn chart_integral(prof: &Profile, chart: &Chart, n: DVec3, rule: Rule) -> DVec3 {
    if prof.dark || !(chart.jac > 0.0) || !chart.jac.is_finite() {
        return DVec3::ZERO;
    }
    let mut nodes = Nodes::new(rule);
    let ys = critical_ys(chart, prof, n);
    if rule == Rule::Adaptive {
        // The scale of the answer from the kernel's rule; an inner error δ on every line moves
        // the outer integral by δ·jac·(Y extent).
        let scale = chart_integral(prof, chart, n, Rule::Kernel)
            .abs()
            .max_element();
        let extent = chart.jac * (ys[ys.len() - 1] - ys[0]);
        if scale > 0.0 && scale.is_finite() && extent > 0.0 && extent.is_finite() {
            nodes.abs = [ABS_FRACTION * scale, ABS_FRACTION * scale / extent];
        }
    }
    let ctx = Ctx {
        prof,
        n,
        unshaped: prof.shaping.is_none(),
        rule: &nodes,
    };
    let mut total = DVec3::ZERO;
    for w in ys.windows(2) {
        let (y_foot, width) = outer_pole(chart, w[0], w[1]);
        for piece in PieceMap::new(w[0], w[1], y_foot, width).spans(ctx.rule) {
            total += nodes.integrate(0, &mut |s: f64| {
                let (y, dy) = piece.eval(s, true);
                if dy == 0.0 {
                    return DVec3::ZERO;
                }
                match chart.x_interval(y) {
                    Some((x0, x1)) => {
                        line_integral(&ctx, chart.w0 + chart.e2 * y, chart.e1, x0, x1)
                            * (dy * chart.jac)
                    }
                    None => DVec3::ZERO,
                }
            });
        }
    }
    total
}

/// The nearest singularity `y_foot ± i·width` of the outer integrand on the piece [y0, y1].
///
/// Along a line Y, min over X of |w|² is |(w0 + Y e2) × e1|²/|e1|² = |U + Y V|²/|e1|²
/// (U = w0 × e1, V = e2 × e1) = H² + |V|²(Y − y_foot)²/|e1|², H = jac/|V| the distance from x to
/// the chart plane: a Lorentzian of width H|e1|/|V| when the foot of x lies inside the region.
/// When it lies a chart distance D outside the region's X-interval, the line's integrand never
/// reaches that minimum and the peak widens to √(H² + D²|e1|²)·|e1|/|V|.
fn outer_pole(chart: &Chart, y0: f64, y1: f64) -> (f64, f64) {
    let u = chart.w0.cross(chart.e1);
    let v = chart.e2.cross(chart.e1);
    let vv = v.length_squared();
    let y_foot = -u.dot(v) / vv;
    let e1l = chart.e1.length();
    let h = chart.jac / vv.sqrt();
    let x_foot = -(chart.w0 + chart.e2 * y_foot).dot(chart.e1) / (e1l * e1l);
    let d = match chart.x_interval(y_foot.clamp(y0, y1)) {
        Some((x0, x1)) => (x0 - x_foot).max(x_foot - x1).max(0.0),
        None => 0.0,
    };
    (y_foot, (h * h + (d * e1l).powi(2)).sqrt() * e1l / vv.sqrt())
}

/// The map of one piece [v0, v1] of an outer (cosine map) or inner (no cosine map) integral:
/// an optional tan map `t = c + w·tan u` around a near pole, then the unit parameter s.
#[derive(Clone, Copy, Debug)]
struct PieceMap {
    c: f64,
    w: f64,
    tan: bool,
    u0: f64,
    u1: f64,
    grade_lo: bool,
    grade_hi: bool,
}

impl PieceMap {
    /// `c + i·w` is the pole of the integrand nearest to the real axis.
    fn new(t0: f64, t1: f64, c: f64, w: f64) -> Self {
        let tan = w.is_finite() && w > 0.0 && bernstein_rho(t0, t1, c, w) < TAN_MAP_RHO;
        let (u0, u1) = if tan {
            (((t0 - c) / w).atan(), ((t1 - c) / w).atan())
        } else {
            (t0, t1)
        };
        PieceMap {
            c,
            w,
            tan,
            u0,
            u1,
            grade_lo: false,
            grade_hi: false,
        }
    }

    /// For the kernel's rule, the piece cut into equal u-spans of at most [`MAX_U_SPAN`] when
    /// tan-mapped (the grading stays on the outer ends); the adaptive rule needs no cut.
    fn spans(&self, rule: &Nodes) -> Vec<PieceMap> {
        let k = if self.tan && rule.kernel.is_some() {
            ((self.u1 - self.u0).abs() / MAX_U_SPAN).ceil().max(1.0) as usize
        } else {
            1
        };
        (0..k)
            .map(|j| PieceMap {
                u0: self.u0 + (self.u1 - self.u0) * j as f64 / k as f64,
                u1: self.u0 + (self.u1 - self.u0) * (j + 1) as f64 / k as f64,
                grade_lo: self.grade_lo && j == 0,
                grade_hi: self.grade_hi && j + 1 == k,
                ..*self
            })
            .collect()
    }

    /// (t, dt/ds) at s ∈ [0, 1]; `cosine` applies the square-root-removing cosine map.
    fn eval(&self, s: f64, cosine: bool) -> (f64, f64) {
        let (mut g, mut dg) = (s, 1.0);
        if self.grade_lo || self.grade_hi {
            let (g2, dg2) = grading(g, self.grade_lo, self.grade_hi);
            g = g2;
            dg *= dg2;
        }
        if cosine {
            let (sn, cs) = (PI * g).sin_cos();
            dg *= 0.5 * PI * sn;
            g = 0.5 * (1.0 - cs);
        }
        let u = self.u0 + (self.u1 - self.u0) * g;
        let du = (self.u1 - self.u0) * dg;
        if self.tan {
            let tn = u.tan();
            (self.c + self.w * tn, self.w * (1.0 + tn * tn) * du)
        } else {
            (u, du)
        }
    }
}

/// A cubic grading toward the flagged ends of [0, 1]: g ~ s³ there.
fn grading(s: f64, lo: bool, hi: bool) -> (f64, f64) {
    match (lo, hi) {
        (true, false) => (s * s * s, 3.0 * s * s),
        (false, true) => {
            let r = 1.0 - s;
            (1.0 - r * r * r, 3.0 * r * r)
        }
        _ => {
            let (a, b) = (s * s * s, (1.0 - s).powi(3));
            let d = a + b;
            let da = 3.0 * s * s;
            let db = -3.0 * (1.0 - s) * (1.0 - s);
            (a / d, (da * d - a * (da + db)) / (d * d))
        }
    }
}

/// The Bernstein-ellipse parameter ρ of the point c + i·w for the interval [t0, t1]: Gauss
/// rules on a function with a pole there converge like ρ^(−2n).
pub fn bernstein_rho(t0: f64, t1: f64, c: f64, w: f64) -> f64 {
    let half = 0.5 * (t1 - t0);
    if !(half > 0.0) {
        return f64::INFINITY;
    }
    let (zr, zi) = ((c - 0.5 * (t0 + t1)) / half, w / half);
    // ρ = |z ± √(z² − 1)|, the larger.
    let (ar, ai) = (zr * zr - zi * zi - 1.0, 2.0 * zr * zi);
    let m = (ar * ar + ai * ai).sqrt().sqrt();
    let ang = 0.5 * ai.atan2(ar);
    let (sr, si) = (m * ang.cos(), m * ang.sin());
    let p = ((zr + sr).powi(2) + (zi + si).powi(2)).sqrt();
    let q = ((zr - sr).powi(2) + (zi - si).powi(2)).sqrt();
    p.max(q)
}

/// `∫ S(−ŵ)·max(0, n·w)/|w|⁴ dX` along w = a + X e1 for X in [x0, x1].
fn line_integral(ctx: &Ctx, a: DVec3, e1: DVec3, x0: f64, x1: f64) -> DVec3 {
    let (lo, hi) = match clip_horizon(ctx.n, a, e1, x0, x1) {
        Some(v) => v,
        None => return DVec3::ZERO,
    };
    // Breakpoints with their grading flag.
    let mut bps: Vec<(f64, bool)> = vec![(lo, false), (hi, false)];
    for k in &ctx.prof.kinks {
        match *k {
            Kink::Cone { cos } => {
                for xk in cone_roots_on_line(ctx.prof.axis, cos, a, e1) {
                    bps.push((xk, false));
                }
            }
            Kink::Plane { m, graded } => {
                let den = m.dot(e1);
                if den != 0.0 {
                    bps.push((-m.dot(a) / den, graded));
                }
            }
        }
    }
    if ctx.prof.axis_singular {
        bps.extend(axis_approach(ctx.prof.axis, a, e1).map(|xa| (xa, false)));
    }
    bps.retain(|b| b.0 >= lo && b.0 <= hi);
    bps.sort_by(|p, q| p.0.total_cmp(&q.0));
    // The line's closest approach to x: X* and the width √m/|e1|, m = |a × e1|²/|e1|².
    let e12 = e1.length_squared();
    let x_star = -a.dot(e1) / e12;
    let perp = a + e1 * x_star;
    let cr = a.cross(e1).length();
    let width = cr / e12;
    let m = cr * cr / e12;
    let mut sum = DVec3::ZERO;
    for w in bps.windows(2) {
        let ((t0, g0), (t1, g1)) = (w[0], w[1]);
        if !(t1 > t0) {
            continue;
        }
        let map = PieceMap::new(t0, t1, x_star, width);
        if ctx.unshaped && (map.tan || ctx.rule.kernel.is_none()) {
            // Closed form (the GPU uses it where it maps with tan, where it cannot cancel).
            sum += DVec3::splat(unshaped_segment(ctx.n, perp, e1, m, width, x_star, t0, t1));
            continue;
        }
        for (p0, p1, glo, ghi) in graded_parts(t0, t1, g0, g1) {
            let mut map = PieceMap::new(p0, p1, x_star, width);
            map.grade_lo = glo;
            map.grade_hi = ghi;
            for piece in map.spans(ctx.rule) {
                sum += ctx.rule.integrate(1, &mut |s: f64| {
                    let (xx, dx) = piece.eval(s, false);
                    let wv = a + e1 * xx;
                    let nw = ctx.n.dot(wv);
                    if !(nw > 0.0) || dx == 0.0 {
                        return DVec3::ZERO;
                    }
                    let l2 = wv.length_squared();
                    let e = -wv / l2.sqrt();
                    ctx.prof.factor(e) * (nw / (l2 * l2) * dx)
                });
            }
        }
    }
    sum
}

/// A sub-interval with graded ends split so that only the quarter next to each graded end is
/// graded (the cubic grading starves the rest of the interval of nodes): (t0, t1, lo, hi).
fn graded_parts(t0: f64, t1: f64, g0: bool, g1: bool) -> Vec<(f64, f64, bool, bool)> {
    let q = 0.25 * (t1 - t0);
    match (g0, g1) {
        (false, false) => vec![(t0, t1, false, false)],
        (true, false) => vec![(t0, t0 + q, true, false), (t0 + q, t1, false, false)],
        (false, true) => vec![(t0, t1 - q, false, false), (t1 - q, t1, false, true)],
        (true, true) => vec![
            (t0, t0 + q, true, false),
            (t0 + q, t1 - q, false, false),
            (t1 - q, t1, false, true),
        ],
    }
}

/// X where w = a + X e1 makes its smallest (or largest) angle with the axis: the stationary
/// point of ŵ·axis, `(e1·p)|w|² = (w·p)(w·e1)`, which is linear in X.
fn axis_approach(axis: DVec3, a: DVec3, e1: DVec3) -> Option<f64> {
    let (ap, ep, ae) = (a.dot(axis), e1.dot(axis), a.dot(e1));
    let den = ep * ae - ap * e1.length_squared();
    (den != 0.0).then(|| (ap * ae - ep * a.length_squared()) / den)
}

/// The X-interval of [x0, x1] where n·(a + X e1) ≥ 0.
fn clip_horizon(n: DVec3, a: DVec3, e1: DVec3, x0: f64, x1: f64) -> Option<(f64, f64)> {
    let (na, ne) = (n.dot(a), n.dot(e1));
    let (mut lo, mut hi) = (x0, x1);
    if ne > 0.0 {
        lo = lo.max(-na / ne);
    } else if ne < 0.0 {
        hi = hi.min(-na / ne);
    } else if !(na > 0.0) {
        return None;
    }
    (hi > lo).then_some((lo, hi))
}

/// `∫_{t0}^{t1} (n·w)/|w|⁴ dX` for w = perp + (X − X*) e1 (perp ⊥ e1, |perp|² = m), in closed
/// form: with X − X* = width·tan u the integrand is `(width/m²)(n·perp cos²u + width n·e1 sin u cos u)`.
#[allow(clippy::too_many_arguments)]
fn unshaped_segment(
    n: DVec3,
    perp: DVec3,
    e1: DVec3,
    m: f64,
    width: f64,
    x_star: f64,
    t0: f64,
    t1: f64,
) -> f64 {
    if !(m > 0.0) {
        return 0.0;
    }
    let (u0, u1) = (
        ((t0 - x_star) / width).atan(),
        ((t1 - x_star) / width).atan(),
    );
    let np = n.dot(perp);
    let ne = n.dot(e1) * width;
    let prim = |u: f64| np * (0.5 * u + 0.25 * (2.0 * u).sin()) + ne * 0.5 * u.sin().powi(2);
    (width / (m * m) * (prim(u1) - prim(u0))).max(0.0)
}

/// X where w = a + X e1 lies on the kink cone −ŵ·axis = cos (the correct nappe only).
fn cone_roots_on_line(axis: DVec3, cos: f64, a: DVec3, e1: DVec3) -> Vec<f64> {
    let c2 = cos * cos;
    let (aa, ea) = (a.dot(axis), e1.dot(axis));
    let qa = ea * ea - c2 * e1.length_squared();
    let qb = aa * ea - c2 * a.dot(e1);
    let qc = aa * aa - c2 * a.length_squared();
    let mut out = Vec::new();
    for xk in quadratic_roots(qa, qb, qc) {
        let wa = -(aa + xk * ea);
        if wa * cos > 0.0 {
            out.push(xk);
        }
    }
    out
}

/// Real roots of qa·t² + 2·qb·t + qc = 0 (numerically stable).
pub fn quadratic_roots(qa: f64, qb: f64, qc: f64) -> Vec<f64> {
    if qa == 0.0 {
        return if qb != 0.0 {
            vec![-qc / (2.0 * qb)]
        } else {
            vec![]
        };
    }
    let disc = qb * qb - qa * qc;
    if disc < 0.0 {
        return vec![];
    }
    let q = -(qb + qb.signum() * disc.sqrt());
    if q == 0.0 {
        return vec![0.0];
    }
    vec![q / qa, qc / q]
}

/// Roots of A cos t + B sin t = C.
fn lin_trig_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    let r = a.hypot(b);
    if !(r > 0.0) || c.abs() > r {
        return vec![];
    }
    let phi = b.atan2(a);
    let d = (c / r).clamp(-1.0, 1.0).acos();
    vec![phi + d, phi - d]
}

/// t wrapped into [t0, t0 + 2π).
fn wrap_into(t: f64, t0: f64) -> f64 {
    t0 + (t - t0).rem_euclid(2.0 * PI)
}

/// Roots of a smooth periodic function on [t0, t1] by bracketing on a uniform grid, with a
/// check of each grid interval's interior extremum for pairs of roots, then bisection.
fn bracket_roots(f: &impl Fn(f64) -> (f64, f64), t0: f64, t1: f64, samples: usize) -> Vec<f64> {
    let mut out = Vec::new();
    let h = (t1 - t0) / samples as f64;
    let bisect = |mut lo: f64, mut hi: f64, g: &dyn Fn(f64) -> f64| {
        let glo = g(lo);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if (g(mid) > 0.0) == (glo > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let val = |t: f64| f(t).0;
    let der = |t: f64| f(t).1;
    for i in 0..samples {
        let (a, b) = (t0 + h * i as f64, t0 + h * (i + 1) as f64);
        let (fa, fb) = (f(a), f(b));
        if fa.0 == 0.0 {
            out.push(a);
        }
        if (fa.0 > 0.0) != (fb.0 > 0.0) && fa.0 != 0.0 && fb.0 != 0.0 {
            out.push(bisect(a, b, &val));
        } else if fa.1 * fb.1 < 0.0 {
            // An interior extremum: two roots when it crosses zero.
            let te = bisect(a, b, &der);
            let fe = val(te);
            if (fe > 0.0) != (fa.0 > 0.0) && fe != 0.0 {
                out.push(bisect(a, te, &val));
                out.push(bisect(te, b, &val));
            }
        }
    }
    if val(t1) == 0.0 {
        out.push(t1);
    }
    out
}

/// The Y values where the inner structure of the chart integral changes (see the module docs),
/// sorted, within and including the region's Y-range.
fn critical_ys(chart: &Chart, prof: &Profile, n: DVec3) -> Vec<f64> {
    let (ya, yb) = chart.y_range();
    let mut ys = vec![ya, yb];
    let mut planes: Vec<DVec3> = vec![n];
    let mut cones: Vec<f64> = Vec::new();
    for k in &prof.kinks {
        match *k {
            Kink::Cone { cos } => cones.push(cos),
            Kink::Plane { m, .. } => planes.push(m),
        }
    }
    let (w0, e1, e2) = (chart.w0, chart.e1, chart.e2);
    // Straight region edges X = const (the square's sides), and elliptic arcs.
    let segs: Vec<f64> = match &chart.region {
        Region::Square => vec![-1.0, 1.0],
        _ => vec![],
    };
    let arcs: Vec<Arc> = match &chart.region {
        Region::Square => vec![],
        Region::Disk => vec![Arc {
            c: w0,
            u: e1,
            v: e2,
            t0: 0.0,
            t1: 2.0 * PI,
        }],
        Region::Cylinder(c) => c.arcs.to_vec(),
    };
    let push_dir = |ys: &mut Vec<f64>, w: DVec3| {
        if let Some(y) = chart.y_of(w) {
            ys.push(y);
        }
    };
    for &m in &planes {
        let (me1, me2, mw0) = (m.dot(e1), m.dot(e2), m.dot(w0));
        if me1.abs() <= 1e-12 * m.length() * e1.length() && me2 != 0.0 {
            // A plane of the pencil: one line Y = const lies in it.
            ys.push(-mw0 / me2);
        }
        if me2 != 0.0 {
            for &xs in &segs {
                ys.push(-(mw0 + xs * me1) / me2);
            }
        }
        for arc in &arcs {
            for t in lin_trig_roots(m.dot(arc.u), m.dot(arc.v), -m.dot(arc.c)) {
                let t = wrap_into(t, arc.t0);
                if t <= arc.t1 {
                    push_dir(&mut ys, arc.at(t));
                }
            }
        }
        // Plane ∩ plane: the line through x along m × m'.
        for &m2 in &planes {
            let d = m.cross(m2);
            if d.length_squared() > 0.0 {
                push_dir(&mut ys, d);
                push_dir(&mut ys, -d);
            }
        }
        // Plane ∩ kink cones.
        for &c in &cones {
            for w in plane_cone_dirs(m, prof.axis, c) {
                push_dir(&mut ys, w);
            }
        }
    }
    for &c in &cones {
        // Planes of the pencil (through x, containing e1) tangent to the cone: unit normals
        // m ⊥ e1 with |m·axis| = sin θ.
        let s = (1.0 - c * c).max(0.0).sqrt();
        let (m1, m2) = e1.normalize().any_orthonormal_pair();
        let (pa, pb) = (m1.dot(prof.axis), m2.dot(prof.axis));
        let ra = pa.hypot(pb);
        if ra >= s && ra > 0.0 {
            let t0 = pb.atan2(pa);
            let d = (s / ra).clamp(-1.0, 1.0).acos();
            for t in [t0 + d, t0 - d] {
                let mm = m1 * t.cos() + m2 * t.sin();
                let me2 = mm.dot(e2);
                if me2 != 0.0 {
                    ys.push(-mm.dot(w0) / me2);
                }
            }
        }
        // Cone ∩ straight edges X = xs: quadratic in Y.
        for &xs in &segs {
            let base = w0 + e1 * xs;
            for y in cone_roots_on_line(prof.axis, c, base, e2) {
                ys.push(y);
            }
        }
        // Cone ∩ elliptic arcs: F(t) = (w·a)² − c²|w|², degree 2 in (cos t, sin t).
        for arc in &arcs {
            let a = prof.axis;
            let f = |t: f64| {
                let w = arc.at(t);
                let dw = arc.v * t.cos() - arc.u * t.sin();
                let wa = w.dot(a);
                (
                    wa * wa - c * c * w.length_squared(),
                    2.0 * wa * dw.dot(a) - 2.0 * c * c * w.dot(dw),
                )
            };
            for t in bracket_roots(&f, arc.t0, arc.t1, ARC_SAMPLES) {
                let w = arc.at(t);
                if -w.dot(prof.axis) * c > 0.0 {
                    push_dir(&mut ys, w);
                }
            }
        }
    }
    // The outer integrand peaks where a curve bounding the inner intervals (a region edge, a
    // cone edge, the focus line) comes nearest to x: split there too.
    for &xs in &segs {
        ys.push(-(w0 + e1 * xs).dot(e2) / e2.length_squared());
    }
    for arc in &arcs {
        let d = |t: f64| {
            let w = arc.at(t);
            let dw = arc.v * t.cos() - arc.u * t.sin();
            let ddw = -arc.u * t.cos() - arc.v * t.sin();
            (w.dot(dw), dw.length_squared() + w.dot(ddw))
        };
        for t in bracket_roots(&d, arc.t0, arc.t1, ARC_SAMPLES) {
            if d(t).1 > 0.0 {
                push_dir(&mut ys, arc.at(t));
            }
        }
    }
    let nrm = e1.cross(e2).normalize() * w0.dot(e1.cross(e2)).signum();
    for &c in &cones {
        // The cone's generator nearest to the chart plane's normal: the nearest point of the
        // cone-edge curve.
        let p = -prof.axis;
        let perp = nrm - p * nrm.dot(p);
        if perp.length_squared() > 0.0 {
            push_dir(
                &mut ys,
                p * c + perp.normalize() * (1.0 - c * c).max(0.0).sqrt(),
            );
        }
    }
    for &m in planes.iter().skip(1) {
        // The nearest point of the plane's line in the chart plane.
        let mu = m.normalize();
        let perp = nrm - mu * nrm.dot(mu);
        if perp.length_squared() > 0.0 {
            push_dir(&mut ys, perp);
        }
    }
    if prof.axis_singular {
        // The line of the pencil through the axis directions.
        let m = e1.cross(prof.axis);
        if m.dot(e2) != 0.0 {
            ys.push(-m.dot(w0) / m.dot(e2));
        }
    }
    ys.retain(|y| y.is_finite() && *y >= ya && *y <= yb);
    ys.sort_by(f64::total_cmp);
    let span = yb - ya;
    ys.dedup_by(|b, a| (*b - *a).abs() <= 1e-13 * span);
    ys
}

/// Unit vectors w in the plane m·w = 0 with −ŵ·axis = cos.
fn plane_cone_dirs(m: DVec3, axis: DVec3, cos: f64) -> Vec<DVec3> {
    let ml = m.length();
    if !(ml > 0.0) {
        return vec![];
    }
    let (h1, h2) = (m / ml).any_orthonormal_pair();
    let (pa, pb) = (h1.dot(axis), h2.dot(axis));
    lin_trig_roots(pa, pb, -cos)
        .into_iter()
        .map(|s| h1 * s.cos() + h2 * s.sin())
        .collect()
}

/// treatAsLine: the segment along the light's X axis (DESIGN.md §2), see the module docs.
fn line_irradiance(p: &PreparedLight, x: DVec3, n: DVec3, hl: f64, r: f64, rule: Rule) -> DVec3 {
    let m = p.light.linear();
    let xl = p.to_local * (x - p.origin);
    let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
    let weight = 2.0 * r * m.determinant().abs() * rho;
    if !(weight > 0.0) || !(hl > 0.0) {
        return DVec3::ZERO;
    }
    let prof = Profile::new(p.light.shaping.as_ref(), p.axis);
    if prof.dark {
        return DVec3::ZERO;
    }
    let nodes = Nodes::new(rule);
    let ctx = Ctx {
        prof: &prof,
        n,
        unshaped: prof.shaping.is_none(),
        rule: &nodes,
    };
    p.base * line_integral(&ctx, p.origin - x, m * DVec3::X, -hl, hl) * weight
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::TemperatureMode;
    use crate::light::Light;
    use glam::{DMat4, DQuat};

    fn prep(l: &Light) -> PreparedLight {
        PreparedLight::new(l, TemperatureMode::Spec).unwrap()
    }

    fn rel(a: f64, b: f64) -> f64 {
        if a == b {
            0.0
        } else {
            (a - b).abs() / b.abs().max(a.abs())
        }
    }

    #[test]
    fn asin_series_matches_direct() {
        for k in [1e-6f64, 1e-3, 0.02, 0.0999, 0.1, 0.5] {
            let direct = k.asin() - k;
            let kc = (1.0 - k * k).sqrt();
            assert!(rel(asin_minus_x(k, kc), direct) < 1e-9 || k < 1e-3, "{k}");
        }
        // Small k: the series is the accurate one.
        let k = 1e-3f64;
        assert!(
            rel(
                asin_minus_x(k, (1.0 - k * k).sqrt()),
                1e-9 / 6.0 + 3.0e-15 / 40.0
            ) < 1e-12
        );
    }

    #[test]
    fn cap_limits() {
        // Hemisphere around c at elevation γ: π(1 + sin γ)/2.
        for g in [-1.2f64, -0.3, 0.0, 0.4, 1.5] {
            let e = cap_irradiance(FRAC_PI_2, g.sin(), g.cos());
            assert!(rel(e, PI * (1.0 + g.sin()) / 2.0) < 1e-14, "{g}: {e}");
        }
        // The whole sphere: π for any receiver.
        assert!(rel(cap_irradiance(PI, 0.3, 0.3f64.asin().cos()), PI) < 1e-15);
        // Continuity across the full / partial boundary and across α = π/2.
        let a = 0.3f64;
        let e1 = cap_irradiance(a, (a + 1e-9).sin(), (a + 1e-9).cos());
        let e2 = cap_irradiance(a, (a - 1e-9).sin(), (a - 1e-9).cos());
        assert!(rel(e1, e2) < 1e-7);
        let g = -0.2f64;
        let e1 = cap_irradiance(FRAC_PI_2 - 1e-9, g.sin(), g.cos());
        let e2 = cap_irradiance(FRAC_PI_2 + 1e-9, g.sin(), g.cos());
        assert!(rel(e1, e2) < 1e-8, "{e1} {e2}");
    }

    /// The cap formula against an independent 2-D quadrature over the cap (polar coordinates
    /// around c, the receiver's max(0, ·) integrated in closed form over the azimuth).
    #[test]
    fn cap_against_quadrature() {
        for &(alpha, gamma) in &[
            (0.3f64, 0.1f64),
            (0.3, -0.25),
            (1.0, 0.2),
            (2.0, -0.5),
            (2.9, 0.3),
            (0.01, 0.004),
        ] {
            let q = integrate(
                &mut |t: f64| {
                    // ∫ max(0, sinγ cos t + cosγ sin t cos φ) dφ over [−π, π].
                    let (a, b) = (gamma.sin() * t.cos(), gamma.cos() * t.sin());
                    let v = if a >= b {
                        2.0 * PI * a
                    } else if a <= -b {
                        0.0
                    } else {
                        let ph = (-a / b).acos();
                        2.0 * (a * ph + b * ph.sin())
                    };
                    DVec3::splat(v * t.sin())
                },
                &[0.0, (FRAC_PI_2 - gamma).abs().min(alpha), alpha],
                Tolerance {
                    rel: 1e-13,
                    abs: 0.0,
                    max_intervals: 2000,
                },
            )
            .x;
            let e = cap_irradiance(alpha, gamma.sin(), gamma.cos());
            assert!(rel(e, q) < 1e-10, "α={alpha} γ={gamma}: {e} vs {q}");
        }
    }

    #[test]
    fn engine_matches_lambert_and_cap_for_unshaped_lights() {
        let m = DMat4::from_rotation_translation(
            DQuat::from_rotation_x(-1.2),
            DVec3::new(0.3, 1.0, -0.2),
        );
        let rect = prep(&Light::rect(1.5, 0.7).with_transform(m));
        let sphere = prep(&Light::sphere(0.4).with_transform(m));
        let pts = [
            (DVec3::new(0.2, -0.5, 0.1), DVec3::new(0.1, 1.0, 0.2)),
            (DVec3::new(1.5, -0.1, 2.0), DVec3::new(-0.3, 0.4, -1.0)),
            (DVec3::new(0.4, 0.9, 0.3), DVec3::new(0.0, 0.2, 1.0)),
            (DVec3::new(-3.0, 2.0, 4.0), DVec3::new(1.0, -0.3, -1.0)),
        ];
        for (x, n) in pts {
            let n = n.normalize();
            let xl = rect.to_local * (x - rect.origin);
            if xl.z < 0.0 {
                let lam = rect_lambert(&rect, x, n, 0.75, 0.35);
                let q = chart_irradiance(
                    &rect,
                    &plane_chart(&rect, x, 0.75, 0.35, Region::Square),
                    n,
                    Rule::Adaptive,
                )
                .x;
                assert!(rel(q, lam) < 1e-9, "rect {x}: {q} vs {lam}");
            }
            let cap = sphere_cap(sphere.origin, 0.4, x, n);
            let q = match sphere_chart(&sphere, x, 0.4) {
                Some(c) => chart_irradiance(&sphere, &c, n, Rule::Adaptive).x,
                None => 0.0,
            };
            assert!(rel(q, cap) < 1e-9, "sphere {x}: {q} vs {cap}");
        }
    }
}
