//! The WGSL IES lookup (`shaders/shared/ies.wgsl`) replayed in f32 on the packed atlas
//! (`gpu::ies_atlas`): tests hold it to the f64 lookup, which separates the shader's arithmetic
//! from the rest of the GPU path.

use glam::Vec3;

use crate::prepare::ies::{HFold, PhotometricType, VFold};

pub use crate::gpu::ies_atlas::{
    Atlas, AtlasError, HEADER_LEN, KINK_SEARCH_STEPS, MAX_LEN, SEARCH_STEPS, pack_atlas,
    wgsl_constants,
};

/// math.wgsl's `atan2_accurate`, replayed in f32 (the shader's atan2 for every angle).
pub fn atan2_accurate(y: f32, x: f32) -> f32 {
    const PI: f32 = std::f32::consts::PI;
    const TAN_PI_12: f32 = 0.267_949_2;
    let (ax, ay) = (x.abs(), y.abs());
    let hi = ax.max(ay);
    if hi == 0.0 {
        return 0.0;
    }
    let mut t = ax.min(ay) / hi;
    let mut offset = 0.0;
    if t > TAN_PI_12 {
        t = (3f32.sqrt() * t - 1.0) / (3f32.sqrt() + t);
        offset = PI / 6.0;
    }
    let x2 = t * t;
    let p = 1.0
        + x2 * (-1.0 / 3.0
            + x2 * (1.0 / 5.0
                + x2 * (-1.0 / 7.0 + x2 * (1.0 / 9.0 + x2 * (-1.0 / 11.0 + x2 * (1.0 / 13.0))))));
    let mut a = offset + t * p;
    if ay > ax {
        a = PI / 2.0 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 { -a } else { a }
}

/// `ies_factor` of `ies.wgsl`, replayed step by step in f32 on the packed atlas. Reads out of
/// the buffer give 0, as robust buffer access does on the GPU.
pub fn replay_ies_factor(atlas: &[f32], base: u32, e: Vec3, angle_scale: f32) -> f32 {
    const DEG: f32 = 57.295_78;
    const RAD: f32 = 0.017_453_292;
    // u64 indices: a corrupt header cannot overflow, and out-of-range reads give 0.
    let at = |i: u64| atlas.get(i as usize).copied().unwrap_or(0.0);
    let field = |k: u64| at(base as u64 + k) as u64;
    let (kind, h_fold, v_fold) = (field(0) as u32, field(1) as u32, field(2) as u32);
    let (n_h, n_v) = (field(3), field(4));
    let (h_off, v_off, c_off) = (field(5), field(6), field(7));
    if n_h == 0 || n_v < 2 {
        return 0.0;
    }
    let (type_c, type_b) = (PhotometricType::C.code(), PhotometricType::B.code());
    let type_c_angles = |d: Vec3| {
        let v = atan2_accurate(Vec3::new(d.x, d.y, 0.0).length(), -d.z) * DEG;
        let mut h = atan2_accurate(d.y, d.x) * DEG;
        if h < 0.0 {
            h += 360.0;
        }
        (h, v)
    };
    let scale_polar_angle = |theta: f32| {
        if angle_scale > 0.0 {
            theta / angle_scale
        } else if angle_scale < 0.0 {
            (theta - 180.0) / -angle_scale + 180.0
        } else {
            theta
        }
    };
    // photometric_angles
    let (h, v) = if kind == type_c {
        let (h, v) = type_c_angles(e);
        let t = scale_polar_angle(v);
        if !(0.0..=180.0).contains(&t) {
            return 0.0;
        }
        (h, t)
    } else {
        let mut d = e;
        if angle_scale != 0.0 {
            let (_, theta) = type_c_angles(e);
            let t = scale_polar_angle(theta);
            if !(0.0..=180.0).contains(&t) {
                return 0.0;
            }
            if t != theta {
                // scaled_direction
                let rho = Vec3::new(e.x, e.y, 0.0).length();
                let (c, s) = if rho > 0.0 {
                    (e.x / rho, e.y / rho)
                } else {
                    (1.0, 0.0)
                };
                let (st, ct) = ((t * RAD).sin(), (t * RAD).cos());
                d = Vec3::new(st * c, st * s, -ct);
            }
        }
        if kind == type_b {
            let v = atan2_accurate(d.x, -d.z) * DEG;
            (
                atan2_accurate(-d.y, Vec3::new(d.x, 0.0, d.z).length()) * DEG,
                v,
            )
        } else {
            let v = atan2_accurate(d.z, Vec3::new(d.x, d.y, 0.0).length()) * DEG;
            (atan2_accurate(-d.y, d.x) * DEG, v)
        }
    };
    // fold_h_type_c, fold_mirror
    let (quadrant, half, half_c90) = (
        HFold::Quadrant.code(),
        HFold::Half.code(),
        HFold::HalfC90.code(),
    );
    let (hq, vq) = if kind == type_c {
        let mut x = h;
        if h_fold == quadrant || h_fold == half {
            if x > 180.0 {
                x = 360.0 - x;
            }
            if h_fold == quadrant && x > 90.0 {
                x = 180.0 - x;
            }
        } else if h_fold == half_c90 {
            if x < 90.0 {
                x = 180.0 - x;
            }
            if x > 270.0 {
                x = 540.0 - x;
            }
        }
        (x, v)
    } else {
        let mirror_h = h_fold == HFold::Mirror.code();
        let mirror_v = v_fold == VFold::Mirror.code();
        (
            if mirror_h { h.abs() } else { h },
            if mirror_v { v.abs() } else { v },
        )
    };
    // find_interval: the bounded binary search
    let find_interval = |off: u64, n: u64, x: f32| -> Option<(u64, f32)> {
        if !(x >= at(off) && x <= at(off + n - 1)) {
            return None;
        }
        if n == 1 {
            return Some((0, 0.0));
        }
        // The shader's written-out steps: halve the cell count, keep grid[lo] ≤ x.
        let (mut lo, mut len) = (0u64, n - 1);
        for _ in 0..SEARCH_STEPS {
            let half = len / 2;
            len -= half;
            if half > 0 && at(off + lo + half) <= x {
                lo += half;
            }
        }
        let g0 = at(off + lo);
        Some((lo, (x - g0) / (at(off + lo + 1) - g0)))
    };
    let Some((j, u)) = find_interval(v_off, n_v, vq) else {
        return 0.0;
    };
    let h_last = at(h_off + n_h - 1);
    let (i0, i1, t) = if h_fold == HFold::Constant.code() {
        if kind != type_c && hq.abs() > 90.0 {
            return 0.0;
        }
        (0, 0, 0.0)
    } else if h_fold == HFold::Full.code() && hq > h_last {
        (n_h - 1, 0, (hq - h_last) / (360.0 - h_last))
    } else {
        let Some((i, t)) = find_interval(h_off, n_h, hq) else {
            return 0.0;
        };
        (i, (i + 1).min(n_h - 1), t)
    };
    let j1 = (j + 1).min(n_v - 1);
    // bilinear
    let c = |i: u64, j: u64| at(c_off + i * n_v + j);
    (1.0 - t) * ((1.0 - u) * c(i0, j) + u * c(i0, j1)) + t * ((1.0 - u) * c(i1, j) + u * c(i1, j1))
}
