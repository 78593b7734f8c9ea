//! The irradiance part of the excluded band: slivers of a light above a receiver's horizon
//! and the outline of what the receiver sees, measured against the f32 resolution of the
//! light's geometry (the parent module's docs).

use super::*;

/// Irradiance slivers (see [`irradiance_margin`]) narrower than this many times η, the angular
/// resolution of the light's f32 geometry seen from the receiver, are excluded. A sliver of
/// angular thickness t has irradiance ∝ t^k: k = 2 for a straight edge (area ∝ t, cosine ∝ t),
/// k = 5/2 for a curved outline (a circle's segment has area ∝ t^{3/2}). Moving the geometry by
/// η changes it by k·η/t relative, so 5e4 keeps that at 1e-4/2 for k = 5/2 (a sphere seen
/// 0.07 radii from its surface, behind the receiver, measured 3e-4 at 1.3e4·η on lavapipe).
pub const IRRADIANCE_SLIVER_FACTOR: f64 = 5e4;

/// Half of f32's machine epsilon: the relative rounding of one f32 coordinate.
pub const F32_ROUNDING: f64 = f32::EPSILON as f64 / 2.0;

/// World-space points on the outline of what x sees of the light (the boundary of its solid
/// angle): rect edges, disk rim, the sphere's contact ellipse, the cylinder's front patch
/// (tangent generators and front arcs of the end rings); the origin of a point light and the
/// ends of a line light. Empty when x sees nothing (inside a sphere or a cylinder's tube).
fn irradiance_outline(r: &Reference, x: DVec3) -> Vec<DVec3> {
    let p = &r.p;
    let m = p.linear;
    let o = p.origin;
    let xl = p.to_local * (x - o);
    let k = 64;
    let ring = |c: DVec3, u: DVec3, v: DVec3, t0: f64, t1: f64| -> Vec<DVec3> {
        (0..=k)
            .map(|j| {
                let t = t0 + (t1 - t0) * j as f64 / k as f64;
                o + m * (c + u * t.cos() + v * t.sin())
            })
            .collect()
    };
    match p.light.kind {
        // Evaluated on the host on every backend (GpuPath::Host): no silhouette to avoid.
        LightType::Mesh { .. } => vec![],
        LightType::Rect { width, height } => {
            let (hw, hh) = (width / 2.0, height / 2.0);
            let c = [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)];
            let mut out = Vec::new();
            for e in 0..4 {
                let (a, b) = (c[e], c[(e + 1) % 4]);
                for j in 0..k {
                    let t = j as f64 / k as f64;
                    out.push(o + m * DVec3::new(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), 0.0));
                }
            }
            out
        }
        LightType::Disk { radius } => ring(
            DVec3::ZERO,
            DVec3::X * radius,
            DVec3::Y * radius,
            0.0,
            std::f64::consts::TAU,
        ),
        LightType::Sphere {
            treat_as_point: true,
            ..
        } => vec![o],
        LightType::Sphere { radius, .. } => {
            let rho = xl.length();
            if !(rho > radius) {
                return vec![];
            }
            let kk = (rho - radius) * (rho + radius);
            let (u, v) = (xl / rho).any_orthonormal_pair();
            let rc = radius * kk.sqrt() / rho;
            ring(
                xl * (radius * radius / (rho * rho)),
                u * rc,
                v * rc,
                0.0,
                std::f64::consts::TAU,
            )
        }
        LightType::Cylinder {
            length,
            treat_as_line: true,
            ..
        } => vec![
            o + m * DVec3::X * (length / 2.0),
            o - m * DVec3::X * (length / 2.0),
        ],
        LightType::Cylinder { length, radius, .. } => {
            let hl = length / 2.0;
            let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
            if !(rho > radius) {
                return vec![];
            }
            let tx = xl.z.atan2(xl.y);
            let half = (radius / rho).acos();
            let mut out = ring(
                DVec3::X * hl,
                DVec3::Y * radius,
                DVec3::Z * radius,
                tx - half,
                tx + half,
            );
            out.extend(ring(
                -DVec3::X * hl,
                DVec3::Y * radius,
                DVec3::Z * radius,
                tx - half,
                tx + half,
            ));
            for t in [tx - half, tx + half] {
                for j in 0..=k {
                    let a = -hl + 2.0 * hl * j as f64 / k as f64;
                    out.push(o + m * DVec3::new(a, radius * t.cos(), radius * t.sin()));
                }
            }
            out
        }
        LightType::Distant { .. } | LightType::Dome => vec![],
    }
}

/// How much wider than a rect's the band of a mesh light's irradiance is (see
/// [`mesh_irradiance_margin`]).
const MESH_SLIVER_WIDER: f64 = 4.0;

/// A mesh light's irradiance margin (its irradiance is the device's only where its triangles
/// cannot hide one another: `GpuPath::HostIntensityOnly`, shaders/mesh/lambert.wgsl), as a
/// rect's: the highest elevation above the receiver's horizon of its triangles' edges (a
/// mesh wholly at the horizon is a sliver), and the largest over the triangles of x's
/// elevation above a triangle's plane seen from its vertices (a flat mesh seen edge-on), each
/// within
/// the f32 band η of the geometry's rounding seen from x, widened by [`MESH_SLIVER_WIDER`]: the
/// kernel has no quadrature to fall back on, and its f32 sums lose up to ~1e-3 relative where
/// the whole mesh lies within ~0.015 rad of the horizon (a flat hexagon seen from 0.16 above
/// its plane and 1.5 from its centre, measured on lavapipe).
fn mesh_irradiance_margin(triangles: &[crate::model::MeshTriangle], x: DVec3, n: DVec3) -> f64 {
    let scale = |v: f64, band: f64| v.abs() / band * BAND;
    let points: Vec<DVec3> = triangles
        .iter()
        .flat_map(|t| outline_points(&t.p))
        .collect();
    if points.is_empty() {
        return f64::INFINITY;
    }
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let size = (hi - lo).length();
    let nearest = points
        .iter()
        .map(|q| (*q - x).length())
        .fold(f64::INFINITY, f64::min);
    let eta = F32_ROUNDING * (x.length() + (0.5 * (lo + hi)).length() + size) / nearest;
    let band = MESH_SLIVER_WIDER * IRRADIANCE_SLIVER_FACTOR * eta;
    let top = points
        .iter()
        .map(|q| n.dot((*q - x).normalize()).clamp(-1.0, 1.0).asin())
        .fold(f64::NEG_INFINITY, f64::max);
    // Edge-on: x near the plane of every triangle (a flat mesh's); a box's face seen edge-on
    // adds little to the sum of the others.
    let mut edge_on = 0.0f64;
    for t in triangles {
        let Some(nt) = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).try_normalize() else {
            continue;
        };
        let h = (x - t.p[0]).dot(nt);
        let elev =
            t.p.iter()
                .map(|q| (h / (x - *q).length()).clamp(-1.0, 1.0).asin().abs())
                .fold(0.0, f64::max);
        edge_on = edge_on.max(elev);
    }
    scale(top, band).min(scale(edge_on, band))
}

/// Points along the edges of the polygon `corners` (closed), 16 an edge: where the
/// irradiance margins look at what x sees of a mesh triangle or a portal.
fn outline_points(corners: &[DVec3]) -> impl Iterator<Item = DVec3> + '_ {
    let k = 16;
    (0..corners.len()).flat_map(move |e| {
        let (a, b) = (corners[e], corners[(e + 1) % corners.len()]);
        (0..k).map(move |j| a + (b - a) * (j as f64 / k as f64))
    })
}

/// A masked dome's (its irradiance on the device is Lambert's formula summed over the portals
/// and, by inclusion–exclusion, their overlaps, shaders/irradiance/portals.wgsl), from the f32 error model of [`mesh_irradiance_margin`]
/// applied to each portal x is on the −Z side of and weighed by its share of the irradiance: a
/// portal whose highest point is at elevation t over the horizon, or seen from t above its own
/// plane (from its nearest outline point), and whose f32 geometry x resolves to η_k, is off by
/// up to `MESH_SLIVER_WIDER · 2.5 · η_k / t` of its own Lambert value E_k (a sliver's k = 5/2,
/// the band `MESH_SLIVER_WIDER · IRRADIANCE_SLIVER_FACTOR · η_k` over t in units of half the
/// tolerance), so the sum is off by `Σ E_k · that / Σ E_k`; the receiver is within the band
/// where that reaches half the tolerance. (Sized on the whole set, as for a
/// mesh light, the band excluded receivers near one window of a room lit through the others.)
/// Where nothing seen is lit, the whole set's sliver decides, as for a mesh; and x's distance
/// to each portal's plane as `band::portal_margin` measures it for radiance (a fraction of the
/// portal's larger half extent, in its local units): closer, the f32 side test may count that
/// portal or not.
fn portal_irradiance_margin(portals: &[crate::prepare::PreparedPortal], x: DVec3, n: DVec3) -> f64 {
    // Σ E_k and Σ E_k · (portal k's error in units of half the tolerance, at most 1/(half the
    // tolerance): all of it).
    let (mut sum, mut off) = (0.0, 0.0);
    let seen: Vec<_> = portals
        .iter()
        .filter(|q| q.normal.dot(x - q.origin) < 0.0)
        .collect();
    for q in &seen {
        let c = q.corners;
        let points: Vec<DVec3> = outline_points(&c).collect();
        let nearest = points
            .iter()
            .map(|p| (*p - x).length())
            .fold(f64::INFINITY, f64::min);
        let size = (c[2] - c[0]).length().max((c[3] - c[1]).length());
        let eta = F32_ROUNDING * (x.length() + q.origin.length() + size) / nearest;
        let band = MESH_SLIVER_WIDER * IRRADIANCE_SLIVER_FACTOR * eta;
        // How thin the portal looks: its highest elevation over the horizon (π/2 where the
        // normal's ray passes through it), and x's elevation above its plane seen from its
        // nearest outline point (π/2 where x lies over the portal itself).
        let inside = |xl: DVec3| xl.x.abs() <= q.half.x && xl.y.abs() <= q.half.y;
        let xl = q.to_local * (x - q.origin);
        let nl = q.to_local * n;
        let top = if nl.z > 0.0 && inside(xl - xl.z / nl.z * nl) {
            std::f64::consts::FRAC_PI_2
        } else {
            points
                .iter()
                .map(|p| n.dot((*p - x).normalize()).clamp(-1.0, 1.0).asin())
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let h = (x - q.origin).dot(q.normal);
        let edge_on = if inside(xl) {
            std::f64::consts::FRAC_PI_2
        } else {
            (h.abs() / nearest).min(1.0).asin()
        };
        let e = crate::cpu::irradiance::closed::polygon_irradiance(&c.map(|v| v - x), n)
            * q.multiplier.max_element();
        let t = top.min(edge_on).max(0.0);
        sum += e;
        off += e * (band / t).min(1.0 / (0.5 * crate::conformance::TOLERANCE));
    }
    let m = if sum > 0.0 {
        BAND / (off / sum)
    } else {
        let triangle = |p: [DVec3; 3]| crate::model::MeshTriangle { p, face: 0 };
        let triangles: Vec<_> = seen
            .iter()
            .flat_map(|q| {
                let c = q.corners;
                [triangle([c[0], c[1], c[2]]), triangle([c[0], c[2], c[3]])]
            })
            .collect();
        mesh_irradiance_margin(&triangles, x, n)
    };
    portals
        .iter()
        .map(|q| (q.to_local * (x - q.origin)).z.abs() / q.half.x.max(q.half.y))
        .fold(m, f64::min)
}

/// Distance of an irradiance receiver from the places where f32 legitimately cannot resolve the
/// answer to 1e-4 (dimensionless, compared with [`BAND`]).
///
/// The GPU sees the light through f32 coordinates: its position and shape move by about
/// `F32_ROUNDING·(|x| + |o| + size)`, which x sees as an angle η (that length over the distance
/// to the nearest point of the light; at least `F32_ROUNDING` for distant lights, whose axis is
/// rounded). Where x sees only a sliver of the light, the sliver's thickness t changes by ~η and
/// the irradiance by ~η/t relative. The bands, each scaled to reach `BAND` at its edge:
/// - the receiver's horizon passing within `IRRADIANCE_SLIVER_FACTOR·η` of the top of what x
///   sees (only a sliver above the horizon), or of a distant cone's top;
/// - a rect or disk seen within `IRRADIANCE_SLIVER_FACTOR·η` of its own plane (x near the plane;
///   this includes x on the light), and likewise a cylinder's tube seen edge-on from x near the
///   infinite tube through it (beyond an end);
/// - x within `BAND` (relative) of a sphere's or cylinder's surface;
/// - a ShapingAPI cone edge (hard or soft) within max([`CONE_BAND`]·θcone,
///   `IRRADIANCE_SLIVER_FACTOR·η`) of the smallest emission angle at which x sees the light
///   (x in the outer sliver of the penumbra, where the lit part of the light is a sliver and
///   the factor vanishes there).
pub fn irradiance_margin(r: &Reference, x: DVec3, n: DVec3) -> f64 {
    let p = &r.p;
    let n = n.normalize();
    let scale = |v: f64, band: f64| v.abs() / band * BAND;
    let mut m = f64::INFINITY;
    let xl = p.to_local * (x - p.origin);
    match p.light.kind {
        LightType::Dome => {
            return p
                .portals
                .as_deref()
                .map_or(f64::INFINITY, |q| portal_irradiance_margin(q, x, n));
        }
        LightType::Distant { .. } => {
            let band = IRRADIANCE_SLIVER_FACTOR * 2.0 * F32_ROUNDING;
            let top = n.dot(-p.axis).clamp(-1.0, 1.0).asin() + p.distant_half_angle();
            return scale(top, band);
        }
        LightType::Sphere {
            radius,
            treat_as_point: false,
        } => {
            m = m.min(scale((xl.length() - radius) / radius, BAND));
        }
        LightType::Cylinder {
            radius,
            treat_as_line: false,
            ..
        } => {
            let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
            m = m.min(scale((rho - radius) / radius, BAND));
        }
        _ => {}
    }
    if let LightType::Mesh { geometry, .. } = &p.light.kind {
        return m.min(mesh_irradiance_margin(&geometry.triangles, x, n));
    }
    let outline = irradiance_outline(r, x);
    if outline.is_empty() {
        return m;
    }
    let lin = p.linear;
    let size = (lin * local_extent(&p.light)).length()
        + lin
            .x_axis
            .length()
            .max(lin.y_axis.length())
            .max(lin.z_axis.length())
            * local_extent(&p.light).max_element();
    let nearest = outline
        .iter()
        .map(|q| (*q - x).length())
        .fold(f64::INFINITY, f64::min);
    let eta = F32_ROUNDING * (x.length() + p.origin.length() + size) / nearest;
    let band = IRRADIANCE_SLIVER_FACTOR * eta;
    // Receiver horizon: the highest elevation of the outline above it.
    let top = outline
        .iter()
        .map(|q| n.dot((*q - x).normalize()).clamp(-1.0, 1.0).asin())
        .fold(f64::NEG_INFINITY, f64::max);
    m = m.min(scale(top, band));
    // A rect's or disk's own plane: the largest elevation of x above it seen from the outline.
    if matches!(
        p.light.kind,
        LightType::Rect { .. } | LightType::Disk { .. }
    ) {
        let h = (x - p.origin).dot(p.normal);
        let elev = outline
            .iter()
            .map(|q| (h / (x - *q).length()).clamp(-1.0, 1.0).asin().abs())
            .fold(0.0, f64::max);
        m = m.min(scale(elev, band));
    }
    // A cylinder's own surface, the same way: x near the infinite tube through it (beyond an
    // end) sees the tube edge-on. h: x's distance from that tube surface, in world units.
    if let LightType::Cylinder {
        radius,
        treat_as_line: false,
        ..
    } = p.light.kind
    {
        let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
        let h = (rho - radius) * 0.5 * (lin.y_axis.length() + lin.z_axis.length());
        let elev = outline
            .iter()
            .map(|q| (h / (x - *q).length()).clamp(-1.0, 1.0).asin().abs())
            .fold(0.0, f64::max);
        m = m.min(scale(elev, band));
    }
    // The cone edge: the smallest emission angle at which x sees the light.
    if let Some(s) = &p.light.shaping {
        let cone = s.cone_angle.to_radians();
        if cone > 0.0 && cone < std::f64::consts::PI {
            let sees_axis = match p.light.kind {
                LightType::Sphere {
                    treat_as_point: true,
                    ..
                }
                | LightType::Cylinder {
                    treat_as_line: true,
                    ..
                } => false,
                _ => radiance::hits_emitting_surface(p, x, -p.axis),
            };
            let theta_min = if sees_axis {
                0.0
            } else {
                outline
                    .iter()
                    .map(|q| off_axis_angle(p.axis, (x - *q).normalize()))
                    .fold(f64::INFINITY, f64::min)
            };
            m = m.min(scale(theta_min - cone, (CONE_BAND * cone).max(band)));
        }
    }
    // An IES profile's jumps (its range ends, ies_jumps) bound the lit part as the cone edge
    // does: where every lit direction of the outline lies within IES_JUMP_BAND of a jump, the
    // lit part is a sliver whose width the GPU's f32 direction (IES_DIRECTION_ROUNDING) moves
    // by more than half the tolerance of itself.
    if let Some(ies) = &p.ies {
        let lit_distance = outline
            .iter()
            .map(|q| (p.to_local * (x - *q)).normalize())
            .filter(|el| ies_factor(&ies.profile, *el, ies.angle_scale) > 0.0)
            .map(|el| ies_jumps(p, el))
            .fold(f64::NEG_INFINITY, f64::max);
        if lit_distance.is_finite() {
            m = m.min(scale(lit_distance, IES_JUMP_BAND.max(band)));
        } else if ies.angle_scale != 0.0 && ies.profile.kind == PhotometricType::A {
            // None of the outline lit: the reference is 0 or nearly, compared with the floor.
            // Type A's angleScale window edges θ' = 0 and 180 are its frame's poles, where
            // every azimuth meets and the lookup takes H = 0 (§6 I2, `type_a_angles`); the
            // GPU's f32 θ' rounds a band ~1e-5° wide onto them, lit where H = 0 is in range
            // and its neighbours are not (measured: a disk dark on the reference, lit on
            // lavapipe along the window edge at ~1e-9 of its scale, above the floor). So a
            // light whose polar angles θ seen from x reach across a window edge (within the
            // f32 direction's rounding) is excluded. θ' is increasing in θ, and θ's extremes
            // over what x sees are on the outline or at the poles θ = 0, 180.
            let thetas = outline
                .iter()
                .map(|q| type_c_angles((p.to_local * (x - *q)).normalize()).1);
            let (mut lo, mut hi) =
                thetas.fold((180.0f64, 0.0f64), |(lo, hi), t| (lo.min(t), hi.max(t)));
            if radiance::hits_emitting_surface(p, x, -p.axis) {
                lo = 0.0;
            }
            if radiance::hits_emitting_surface(p, x, p.axis) {
                hi = 180.0;
            }
            let slack = IES_DIRECTION_ROUNDING.to_degrees();
            let (t_lo, t_hi) = (
                scale_polar_angle(lo - slack, ies.angle_scale),
                scale_polar_angle(hi + slack, ies.angle_scale),
            );
            if [0.0, 180.0].iter().any(|edge| (t_lo..=t_hi).contains(edge)) {
                m = 0.0;
            }
        }
    }
    m
}
