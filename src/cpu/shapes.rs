//! Ray–shape tests on the CPU (f64). Twin of `shaders/shared/shapes.wgsl`.
//!
//! Everything is in the light's local frame: `x` is the ray origin and `d` its direction (any
//! length), both mapped by the inverse of the light's linear map, so rect, disk, sphere and
//! cylinder keep their canonical shapes under any rotation, scale or shear (DESIGN.md §2
//! "Frames and shapes"). A ray–shape hit in local space is a hit in world space.
//!
//! Each test answers "does the ray see the *emitting* side of the shape first":
//! - rect/disk emit toward local −Z only, so the ray must travel toward +Z (`d.z > 0`, which is
//!   `ω · n > 0` for the world normal n = inverse-transpose image of −Z, strictly);
//! - a sphere emits outward; a ray from inside (or on) the sphere sees nothing;
//! - a cylinder (axis X) emits from its outer side only: a ray that starts inside the infinite
//!   cylinder, or that enters through an open end, sees the non-emitting inside.

use glam::DVec3;

/// Where a ray from the −Z side meets the plane z = 0 travelling toward +Z.
pub fn plane_hit(x: DVec3, d: DVec3) -> Option<DVec3> {
    if !(d.z > 0.0 && x.z < 0.0) {
        return None;
    }
    let t = -x.z / d.z;
    Some(x + t * d)
}

/// Rect of half extents `hw` × `hh` in the XY plane, emitting toward −Z.
pub fn rect_hit(x: DVec3, d: DVec3, hw: f64, hh: f64) -> bool {
    match plane_hit(x, d) {
        Some(p) => p.x.abs() <= hw && p.y.abs() <= hh,
        None => false,
    }
}

/// Disk of radius `r` in the XY plane, emitting toward −Z.
pub fn disk_hit(x: DVec3, d: DVec3, r: f64) -> bool {
    match plane_hit(x, d) {
        Some(p) => p.x * p.x + p.y * p.y <= r * r,
        None => false,
    }
}

/// Sphere of radius `r` at the origin, seen from outside.
pub fn sphere_hit(x: DVec3, d: DVec3, r: f64) -> bool {
    let r2 = r * r;
    if x.length_squared() <= r2 {
        return false;
    }
    let u = d.normalize();
    // Closest approach along the ray; the perpendicular-distance form avoids the cancellation
    // of b² − ac when the ray origin is far away.
    let tc = -x.dot(u);
    if tc <= 0.0 {
        return false;
    }
    (x + tc * u).length_squared() <= r2
}

/// Open cylinder along X (length `2·hl`, radius `r`), seen from outside its side.
pub fn cylinder_hit(x: DVec3, d: DVec3, hl: f64, r: f64) -> bool {
    let r2 = r * r;
    let rho2 = x.y * x.y + x.z * x.z;
    if rho2 <= r2 {
        return false;
    }
    let dl = (d.y * d.y + d.z * d.z).sqrt();
    if dl == 0.0 {
        return false;
    }
    let (uy, uz) = (d.y / dl, d.z / dl);
    // Closest approach of the ray's YZ projection to the axis.
    let tc = -(x.y * uy + x.z * uz);
    if tc <= 0.0 {
        return false;
    }
    let (cy, cz) = (x.y + tc * uy, x.z + tc * uz);
    let h2 = r2 - (cy * cy + cz * cz);
    if h2 < 0.0 {
        return false;
    }
    // Entry point on the outer wall (the first root), as a parameter along `d`.
    let t1 = (tc - h2.sqrt()) / dl;
    (x.x + t1 * d.x).abs() <= hl
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rect_is_one_sided() {
        let x = DVec3::new(0.1, 0.2, -3.0);
        assert!(rect_hit(x, DVec3::Z, 0.5, 0.5));
        assert!(!rect_hit(-x, -DVec3::Z, 0.5, 0.5)); // from the back
        assert!(!rect_hit(x, DVec3::new(1.0, 0.0, 1.0), 0.5, 0.5)); // misses
    }

    #[test]
    fn sphere_inside_and_tangent() {
        assert!(!sphere_hit(DVec3::new(0.1, 0.0, 0.0), DVec3::X, 1.0));
        assert!(sphere_hit(DVec3::new(-5.0, 0.99, 0.0), DVec3::X, 1.0));
        assert!(!sphere_hit(DVec3::new(-5.0, 1.01, 0.0), DVec3::X, 1.0));
        assert!(!sphere_hit(DVec3::new(-5.0, 0.0, 0.0), -DVec3::X, 1.0));
    }

    #[test]
    fn cylinder_open_ends_and_side() {
        // Side hit.
        assert!(cylinder_hit(
            DVec3::new(0.2, 0.0, -3.0),
            DVec3::Z,
            0.5,
            0.25
        ));
        // Beyond the end along the side direction: miss.
        assert!(!cylinder_hit(
            DVec3::new(0.7, 0.0, -3.0),
            DVec3::Z,
            0.5,
            0.25
        ));
        // Down the axis through the open end: sees the inside (or nothing).
        assert!(!cylinder_hit(
            DVec3::new(-3.0, 0.0, 0.0),
            DVec3::X,
            0.5,
            0.25
        ));
        // Entering the open end obliquely and hitting the inner wall: 0.
        let x = DVec3::new(-2.0, 0.0, 0.0);
        let d = DVec3::new(2.0, 0.2, 0.0); // reaches y = 0.25 at x = 0.5 -> inside wall
        assert!(!cylinder_hit(x, d, 0.5, 0.25));
        // From inside the tube: 0.
        assert!(!cylinder_hit(
            DVec3::new(0.0, 0.1, 0.0),
            DVec3::Y,
            0.5,
            0.25
        ));
    }
}
