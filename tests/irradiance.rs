//! irradiance(x, n) against values that do not come from the code under test: the tables of
//! reference/luxtest.md §6 (A2, A3, A4, A6), closed forms, and an independent quadrature written
//! here (`pole_reference`: polar coordinates around the light's axis, visibility from this
//! file's own ray tests, the shaping written out from spec/002). The CPU reference must be within
//! 1e-6 of these; the GPU is compared with the CPU in tests/conformance.rs, and here on the
//! luxtest tables.

// Table values are kept as printed in reference/luxtest.md (0.785398 is I0 = L·π r², not π/4);
// `!(a > b)` is deliberate: NaN takes the safe branch.
#![allow(
    clippy::approx_constant,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments
)]

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DMat3, DMat4, DQuat, DVec3};
use luxeval::testkit::Rng;
use luxeval::{Light, LightType, Reference, Shaping, TemperatureMode};

fn prep(l: &Light) -> Reference {
    Reference::new(l, TemperatureMode::Spec).unwrap()
}

fn cpu_e(l: &Light, x: DVec3, n: DVec3) -> DVec3 {
    prep(l).irradiance(x, n)
}

/// Largest-channel relative difference.
fn rel(got: DVec3, want: DVec3) -> f64 {
    let d = (got - want).abs().max_element();
    if d == 0.0 {
        0.0
    } else {
        d / want.abs().max_element().max(got.abs().max_element())
    }
}

// ---------------------------------------------------------------------------------------------
// An independent reference integrator
// ---------------------------------------------------------------------------------------------

/// Adaptive Simpson on [a, b] for an RGB integrand, to absolute tolerance `tol`.
fn simpson(f: &dyn Fn(f64) -> DVec3, a: f64, b: f64, tol: f64) -> DVec3 {
    fn rec(
        f: &dyn Fn(f64) -> DVec3,
        a: f64,
        b: f64,
        fa: DVec3,
        fm: DVec3,
        fb: DVec3,
        whole: DVec3,
        tol: f64,
        depth: u32,
    ) -> DVec3 {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = (fa + flm * 4.0 + fm) * ((m - a) / 6.0);
        let right = (fm + frm * 4.0 + fb) * ((b - m) / 6.0);
        let diff = left + right - whole;
        if depth == 0 || diff.abs().max_element() <= 15.0 * tol {
            return left + right + diff / 15.0;
        }
        rec(f, a, m, fa, flm, fm, left, tol / 2.0, depth - 1)
            + rec(f, m, b, fm, frm, fb, right, tol / 2.0, depth - 1)
    }
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (fa + fm * 4.0 + fb) * ((b - a) / 6.0);
    rec(f, a, b, fa, fm, fb, whole, tol, 48)
}

/// The spec's shaping factor (spec/002 as pinned by DESIGN.md §2) as a function of the angle θ
/// between the emission direction and the axis, written out independently of src/cpu/shaping.rs.
fn spec_shaping(s: &Option<Shaping>, theta: f64) -> DVec3 {
    let Some(s) = s else { return DVec3::ONE };
    let cone = s.cone_angle.to_radians();
    let soft = s.cone_softness.clamp(0.0, 1.0);
    let cone_f = if theta > cone {
        0.0
    } else {
        let lo = (1.0 - soft) * cone;
        if cone - lo == 0.0 {
            1.0
        } else {
            let t = ((theta - lo) / (cone - lo)).clamp(0.0, 1.0);
            1.0 - t * t * (3.0 - 2.0 * t)
        }
    };
    let focus = if s.focus > 0.0 {
        let f = theta.cos().abs().powf(s.focus);
        s.focus_tint + (DVec3::ONE - s.focus_tint) * f
    } else {
        DVec3::ONE
    };
    focus * cone_f
}

/// The emitting shape in light space, with this file's own ray tests (first hit on the emitting
/// side, DESIGN.md §2).
#[derive(Clone, Copy, Debug)]
enum Shape {
    Rect(f64, f64),
    Disk(f64),
    Sphere(f64),
    Cylinder(f64, f64),
}

fn shape_of(l: &Light) -> Shape {
    match l.kind {
        LightType::Rect { width, height } => Shape::Rect(width / 2.0, height / 2.0),
        LightType::Disk { radius } => Shape::Disk(radius),
        LightType::Sphere { radius, .. } => Shape::Sphere(radius),
        LightType::Cylinder { length, radius, .. } => Shape::Cylinder(length / 2.0, radius),
        _ => unreachable!(),
    }
}

/// A continuous function of the ray (origin o, direction d, light space) that is positive
/// exactly when the ray's first hit is on the emitting side of the shape (DESIGN.md §2):
/// the distance of the hit point from the shape's edge, and across silhouettes the distance by
/// which the ray misses.
fn margin(shape: Shape, o: DVec3, d: DVec3) -> f64 {
    const MISS: f64 = -1e9;
    match shape {
        Shape::Rect(..) | Shape::Disk(..) => {
            if !(o.z < 0.0 && d.z > 0.0) {
                return MISS;
            }
            let p = o - d * (o.z / d.z);
            match shape {
                Shape::Rect(hw, hh) => (hw - p.x.abs()).min(hh - p.y.abs()),
                Shape::Disk(r) => r - (p.x * p.x + p.y * p.y).sqrt(),
                _ => unreachable!(),
            }
        }
        Shape::Sphere(r) => {
            let u = d.normalize();
            let tc = -o.dot(u);
            if !(tc > 0.0) || o.length() <= r {
                return MISS;
            }
            r - (o + u * tc).length()
        }
        Shape::Cylinder(hl, r) => {
            // With ρ(t) = distance of the ray point from the axis (convex in t) and [t_in, t_out]
            // the ray's stay in the slab |x| ≤ hl, the first hit is on the side within the slab
            // iff ρ(t_in) ≥ r (it does not enter the slab inside the tube) and ρ ≤ r somewhere
            // in [t_in, t_out]: two margins without square roots.
            let (t_in, t_out) = if d.x == 0.0 {
                if o.x.abs() > hl {
                    return MISS;
                }
                (0.0, f64::INFINITY)
            } else {
                let (a, b) = ((-hl - o.x) / d.x, (hl - o.x) / d.x);
                (a.min(b).max(0.0), a.max(b))
            };
            if !(t_out > t_in) {
                return MISS;
            }
            let rho = |t: f64| (o.y + t * d.y).hypot(o.z + t * d.z);
            let dd = d.y * d.y + d.z * d.z;
            let tc = if dd > 0.0 {
                -(o.y * d.y + o.z * d.z) / dd
            } else {
                t_in
            };
            let t_star = tc.clamp(t_in, t_out.min(1e300));
            (rho(t_in) - r).min(r - rho(t_star))
        }
    }
}

/// `∫ S(θ) max(0, n·ω) [ray x→ω hits the light] dω` (unit radiance), in polar coordinates
/// (θ, φ) around P = −axis, θ being the emission angle from the axis. On each circle θ = const
/// the visible arcs are found by sampling `samples` points over the part of the circle inside
/// the light's bounding cone and bisecting every change; the azimuth integral of n·ω over an
/// arc is exact. The θ integral is adaptive Gauss–Kronrod with breaks at the shaping's kinks.
fn pole_reference(l: &Light, x: DVec3, n: DVec3, samples: usize, tol: f64) -> DVec3 {
    let n = n.normalize();
    let m = DMat3::from_mat4(l.world);
    let inv = m.inverse();
    let o = l.world.w_axis.truncate();
    let xl = inv * (x - o);
    let shape = shape_of(l);
    let axis = (m * DVec3::NEG_Z).normalize();
    let pole = -axis;
    let (t1, t2) = pole.any_orthonormal_pair();
    // Bounding sphere of the light in world space: centre o, radius from dense samples of the
    // shape's outline (1 % margin; the outline's farthest point bounds the convex shape).
    let outline = |t: f64, k: usize| -> DVec3 {
        let (c, s) = (t.cos(), t.sin());
        match shape {
            Shape::Rect(a, b) => DVec3::new(
                a * if k.is_multiple_of(2) { 1.0 } else { -1.0 },
                b * if k / 2 == 0 { 1.0 } else { -1.0 },
                0.0,
            ),
            Shape::Disk(r) => DVec3::new(r * c, r * s, 0.0),
            Shape::Sphere(r) => {
                let z = -1.0 + 2.0 * (k as f64 + 0.5) / 4.0;
                let q = (1.0 - z * z).sqrt();
                DVec3::new(r * q * c, r * q * s, r * z)
            }
            Shape::Cylinder(hl, r) => {
                DVec3::new(if k.is_multiple_of(2) { hl } else { -hl }, r * c, r * s)
            }
        }
    };
    let mut rb = 0.0f64;
    for i in 0..720 {
        for k in 0..4 {
            rb = rb.max((m * outline(i as f64 * PI / 360.0, k)).length());
        }
    }
    if let Shape::Sphere(r) = shape {
        // The largest singular value of M, by power iteration on MᵀM.
        let mut v = DVec3::new(0.3, 0.5, 0.8);
        for _ in 0..200 {
            v = (m.transpose() * (m * v)).normalize();
        }
        rb = rb.max((m * v).length() * r);
    }
    let rb = rb * 1.01;
    let dc = o - x;
    let dist = dc.length();
    assert!(dist > rb, "reference needs x outside the bounding sphere");
    let cb = dc / dist;
    let beta = (rb / dist).asin();
    let theta_c = pole.dot(cb).clamp(-1.0, 1.0).acos();
    let (th_lo, th_hi) = ((theta_c - beta).max(0.0), (theta_c + beta).min(PI));
    let cbt = (cb.dot(t1), cb.dot(t2));
    let (ct, phic) = (cbt.0.hypot(cbt.1), cbt.1.atan2(cbt.0));
    let (np, nt, nb) = (n.dot(pole), n.dot(t1), n.dot(t2));
    let size = rb;
    let marg = |th: f64, ph: f64| {
        let w = pole * th.cos() + (t1 * ph.cos() + t2 * ph.sin()) * th.sin();
        (margin(shape, xl, inv * w) / size).min(n.dot(w))
    };
    let shaping = l.shaping.clone();
    let g = |th: f64| -> DVec3 {
        // The arc of the circle θ inside the bounding cone: ω·cb ≥ cos β.
        let (a, b) = (th.cos() * pole.dot(cb), th.sin() * ct);
        let (lo, hi) = if b <= 1e-300 || a - b >= beta.cos() {
            (0.0, 2.0 * PI)
        } else if a + b < beta.cos() {
            return DVec3::ZERO;
        } else {
            let h = ((beta.cos() - a) / b).clamp(-1.0, 1.0).acos();
            (phic - h, phic + h)
        };
        let step = (hi - lo) / samples as f64;
        let phis: Vec<f64> = (0..=samples).map(|i| lo + step * i as f64).collect();
        let ms: Vec<f64> = phis.iter().map(|&ph| marg(th, ph)).collect();
        let mut edges: Vec<f64> = Vec::new();
        find_edges(&|ph| marg(th, ph), &phis, &ms, 0, &mut edges);
        edges.sort_by(f64::total_cmp);
        edges.dedup();
        // Walk the edges from the first sample's state.
        let mut total = 0.0;
        let mut state = ms[0] > 0.0;
        let mut start = lo;
        for &e in &edges {
            if state {
                total += arc(start, e, th, np, nt, nb);
            }
            state = !state;
            start = e;
        }
        if state {
            total += arc(start, hi, th, np, nt, nb);
        }
        spec_shaping(&shaping, th) * (total * th.sin())
    };
    let mut breaks = vec![th_lo, th_hi];
    if let Some(s) = &l.shaping {
        let cone = s.cone_angle.to_radians();
        for t in [
            cone,
            (1.0 - s.cone_softness.clamp(0.0, 1.0)) * cone,
            FRAC_PI_2,
        ] {
            if t > th_lo && t < th_hi {
                breaks.push(t);
            }
        }
    }
    breaks.sort_by(f64::total_cmp);
    kronrod(&g, &breaks, tol)
}

/// Globally adaptive 7/15-point Gauss–Kronrod (the nodes of Abramowitz & Stegun 25.4.30 /
/// Piessens et al.), written here independently of src/cpu/quadrature.rs, to relative `tol`.
fn kronrod(f: &dyn Fn(f64) -> DVec3, breaks: &[f64], tol: f64) -> DVec3 {
    const X: [f64; 8] = [
        0.991455371120813,
        0.949107912342759,
        0.864864423359769,
        0.741531185599394,
        0.586087235467691,
        0.405845151377397,
        0.207784955007898,
        0.0,
    ];
    const WK: [f64; 8] = [
        0.022935322010529,
        0.063092092629979,
        0.104790010322250,
        0.140653259715525,
        0.169004726639267,
        0.190350578064785,
        0.204432940075298,
        0.209482141084728,
    ];
    const WG: [f64; 4] = [
        0.129484966168870,
        0.279705391489277,
        0.381830050505119,
        0.417959183673469,
    ];
    let rule = |a: f64, b: f64| {
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        let fc = f(c);
        let (mut k, mut g) = (fc * WK[7], fc * WG[3]);
        for j in 0..7 {
            let s = f(c - h * X[j]) + f(c + h * X[j]);
            k += s * WK[j];
            if j % 2 == 1 {
                g += s * WG[j / 2];
            }
        }
        (k * h, ((k - g) * h).abs().max_element())
    };
    let mut parts: Vec<(f64, f64, DVec3, f64)> = breaks
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| {
            let (v, e) = rule(w[0], w[1]);
            (w[0], w[1], v, e)
        })
        .collect();
    for _ in 0..3000 {
        let total: DVec3 = parts.iter().map(|p| p.2).sum();
        let err: f64 = parts.iter().map(|p| p.3).sum();
        if err <= tol * total.abs().max_element() {
            break;
        }
        let i = (0..parts.len())
            .max_by(|&i, &j| parts[i].3.total_cmp(&parts[j].3))
            .unwrap();
        let (a, b, _, _) = parts[i];
        let m = 0.5 * (a + b);
        let ((v1, e1), (v2, e2)) = (rule(a, m), rule(m, b));
        parts[i] = (a, m, v1, e1);
        parts.push((m, b, v2, e2));
    }
    parts.iter().map(|p| p.2).sum()
}

/// The sign changes of `f` (sampled as `ms` at `phis`): every sample interval whose values are
/// within twice the local sample-to-sample variation of zero at one end (a crossing, or a hidden pair of
/// crossings, is possible there) is resampled 8× finer, three levels deep; sign changes at the
/// finest level are bisected. Arcs thinner than 1/512 of a sample interval may be missed.
fn find_edges(f: &dyn Fn(f64) -> f64, phis: &[f64], ms: &[f64], depth: u32, edges: &mut Vec<f64>) {
    let k = ms.len() - 1;
    let var = |j: usize| {
        if j < k {
            (ms[j + 1] - ms[j]).abs()
        } else {
            0.0
        }
    };
    for i in 0..k {
        let (m0, m1) = (ms[i], ms[i + 1]);
        if m0.max(m1) < -1e8 {
            continue;
        }
        let local = var(i).max(var(i.saturating_sub(1))).max(var(i + 1));
        let crossing = (m0 > 0.0) != (m1 > 0.0);
        if !(crossing || m0.abs().min(m1.abs()) <= 2.0 * local) {
            continue;
        }
        if depth < 3 {
            let sub: Vec<f64> = (0..=8)
                .map(|j| phis[i] + (phis[i + 1] - phis[i]) * j as f64 / 8.0)
                .collect();
            let mut sm: Vec<f64> = sub.iter().map(|&p| f(p)).collect();
            sm[0] = m0;
            sm[8] = m1;
            find_edges(f, &sub, &sm, depth + 1, edges);
        } else if crossing {
            let (mut a0, mut b0) = (phis[i], phis[i + 1]);
            for _ in 0..45 {
                let mid = 0.5 * (a0 + b0);
                if (f(mid) > 0.0) == (m0 > 0.0) {
                    a0 = mid
                } else {
                    b0 = mid
                }
            }
            edges.push(0.5 * (a0 + b0));
        }
    }
}

/// ∫ n·ω dφ over φ ∈ [a, b] on the circle θ (n·ω = np cos θ + sin θ (nt cos φ + nb sin φ)).
fn arc(a: f64, b: f64, th: f64, np: f64, nt: f64, nb: f64) -> f64 {
    np * th.cos() * (b - a) + th.sin() * (nt * (b.sin() - a.sin()) - nb * (b.cos() - a.cos()))
}

// ---------------------------------------------------------------------------------------------
// reference/luxtest.md §6
// ---------------------------------------------------------------------------------------------

/// A2: the distant light's normalize table (intensity 0.3, surface facing the light).
#[test]
fn a2_distant_normalize_table() {
    let table = [
        (0.0, 0.30000),
        (20.0, 0.02842),
        (40.0, 0.11025),
        (60.0, 0.23562),
        (80.0, 0.38941),
        (100.0, 0.55307),
        (120.0, 0.70686),
        (140.0, 0.83223),
        (160.0, 0.91406),
        (180.0, 0.94248),
    ];
    // Light aimed down −Y, floor normal +Y.
    let down = DMat4::from_quat(DQuat::from_rotation_x(-FRAC_PI_2));
    for (angle, off) in table {
        for normalize in [false, true] {
            let l = Light::distant(angle)
                .with_intensity(0.3)
                .with_normalize(normalize)
                .with_transform(down);
            let e = cpu_e(&l, DVec3::new(1.0, 0.0, 2.0), DVec3::Y);
            let want = if normalize { 0.3 } else { off };
            assert!(
                (e.x - want).abs() <= 5e-6,
                "angle {angle} normalize {normalize}: {e}"
            );
            assert_eq!(e.x, e.y);
        }
    }
}

/// A3: the cosine law for a tilted distant light (intensity 3720, angle 0.53°).
#[test]
fn a3_distant_cosine_law() {
    let want = [0.249998, 0.234921, 0.191509, 0.124999, 0.043412];
    for (k, tilt) in [0.0f64, 20.0, 40.0, 60.0, 80.0].iter().enumerate() {
        let q = DQuat::from_rotation_z(tilt.to_radians()) * DQuat::from_rotation_x(-FRAC_PI_2);
        let l = Light::distant(0.53)
            .with_intensity(3720.0)
            .with_transform(DMat4::from_quat(q));
        let e = cpu_e(&l, DVec3::ZERO, DVec3::Y);
        assert!(
            (e.x - want[k]).abs() <= 1e-6,
            "tilt {tilt}: {} vs {}",
            e.x,
            want[k]
        );
        // E⊥ = 3720·π·sin²(0.265°) for a receiver facing the light.
        let face = cpu_e(&l, DVec3::ZERO, -(q * DVec3::NEG_Z));
        assert!((face.x - 0.249_997_81).abs() < 1e-8, "{}", face.x);
    }
}

fn a4_light(shaping: Shaping, treat_as_point: bool) -> Light {
    // r = 5 mm, L = 1e4 nits ⇒ I0 = L·π r² = 0.785398 cd; at (0, 1, 0) aimed −Y.
    let mut l = Light::sphere(0.005)
        .with_intensity(1e4)
        .with_shaping(shaping)
        .with_transform(DMat4::from_rotation_translation(
            DQuat::from_rotation_x(-FRAC_PI_2),
            DVec3::Y,
        ));
    l.kind = LightType::Sphere {
        radius: 0.005,
        treat_as_point,
    };
    l
}

const A4_ROWS: [(f64, [f64; 4]); 8] = [
    (0.0, [0.785398, 0.785398, 0.785398, 0.785398]),
    (0.1, [0.773763, 0.773763, 0.700326, 0.766102]),
    (0.2, [0.740525, 0.740525, 0.504136, 0.712044]),
    (0.3, [0.690161, 0.665597, 0.286694, 0.633175]),
    (0.4, [0.628641, 0.358110, 0.115189, 0.541932]),
    (0.5, [0.561985, 0.074913, 0.020415, 0.449588]),
    (0.6, [0.0, 0.0, 0.0, 0.364118]),
    (1.0, [0.0, 0.0, 0.0, 0.138840]),
];

fn a4_variants() -> [Shaping; 4] {
    let cone = |softness| Shaping {
        cone_angle: 30.0,
        cone_softness: softness,
        ..Shaping::default()
    };
    [
        cone(0.0),
        cone(0.5),
        cone(1.0),
        Shaping {
            cone_angle: 180.0,
            focus: 2.0,
            focus_tint: DVec3::ZERO,
            ..Shaping::default()
        },
    ]
}

/// A4: the spot profile under a small shaped sphere light. The table is the point-source limit:
/// treatAsPoint reproduces it to its printed digits; the finite 5 mm sphere is compared ≥ 5°
/// inside the cone edge (and everywhere for the focus variant, which has no edge) within 3e-4,
/// and against the independent reference within 1e-6.
#[test]
fn a4_spot_profile() {
    for (k, s) in a4_variants().into_iter().enumerate() {
        for (x, want) in A4_ROWS {
            let p = DVec3::new(x, 0.0, 0.0);
            let point = cpu_e(&a4_light(s.clone(), true), p, DVec3::Y);
            assert!(
                (point.x - want[k]).abs() <= 1.5e-6,
                "point, variant {k} x {x}: {} vs {}",
                point.x,
                want[k]
            );
            let theta = x.atan().to_degrees();
            if k == 3 || theta <= 25.0 {
                let sphere = cpu_e(&a4_light(s.clone(), false), p, DVec3::Y);
                assert!(
                    (sphere.x - want[k]).abs() <= 3e-4 * want[k],
                    "sphere, variant {k} x {x}: {} vs {}",
                    sphere.x,
                    want[k]
                );
            }
        }
    }
}

/// A4's finite sphere against the independent reference, across the cone edge too.
#[test]
fn a4_finite_sphere_against_reference() {
    for (k, s) in a4_variants().into_iter().enumerate() {
        for x in [0.0, 0.3, 0.575, 0.577, 0.58, 0.8] {
            let l = a4_light(s.clone(), false);
            let p = DVec3::new(x, 0.0, 0.0);
            let got = cpu_e(&l, p, DVec3::Y);
            let want = pole_reference(&l, p, DVec3::Y, 64, 1e-10) * 1e4;
            let err = rel(got, want);
            assert!(
                err <= 1e-6 || (got - want).abs().max_element() < 1e-12,
                "variant {k} x {x}: {got} vs {want} ({err:e})"
            );
        }
    }
}

/// A6: with normalize on, far-field irradiance is invariant across the size sweep to < 1 %
/// (sphere/disk radius 0.1–0.5, rect width 0.2–2 (height 2), cylinder radius 0.1–0.5
/// (length 1); distance ≥ 10× the size, ≥ 100× for cylinders).
#[test]
fn a6_normalize_far_field_invariance() {
    let down = DQuat::from_rotation_x(-FRAC_PI_2);
    let sweep = [0.1, 0.2, 0.3, 0.4, 0.5];
    type Make = fn(f64) -> Light;
    let cases: [(&str, Make, f64); 4] = [
        ("sphere", |s| Light::sphere(s), 10.0),
        ("disk", |s| Light::disk(s), 10.0),
        ("rect", |s| Light::rect(4.0 * s, 2.0), 10.0),
        ("cylinder", |s| Light::cylinder(1.0, s), 100.0),
    ];
    for (name, make, factor) in cases {
        let size = |s: f64| match name {
            "rect" => 2.0f64.max(4.0 * s),
            "cylinder" => 1.0f64.max(2.0 * s),
            _ => 2.0 * s,
        };
        let h = factor * size(0.5);
        let es: Vec<f64> = sweep
            .iter()
            .map(|&s| {
                let l = make(s)
                    .with_intensity(5.0)
                    .with_normalize(true)
                    .with_transform(DMat4::from_rotation_translation(
                        down,
                        DVec3::new(0.0, h, 0.0),
                    ));
                // Cylinders (axis X) seen broadside from below.
                cpu_e(&l, DVec3::ZERO, DVec3::Y).x
            })
            .collect();
        let (lo, hi) = es
            .iter()
            .fold((f64::MAX, 0.0f64), |(a, b), &e| (a.min(e), b.max(e)));
        assert!(lo > 0.0 && (hi - lo) / hi < 0.01, "{name}: {es:?}");
        // And the far-field value itself: I/h² with I = 5/π (a Lambertian unit-area disk, rect,
        // sphere) ... for the sphere I = L·π r² = 5/4, for the cylinder L·2rℓ = 5/π.
        let want = match name {
            "sphere" => 5.0 / 4.0,
            "cylinder" => 5.0 / PI,
            _ => 5.0,
        } / (h * h);
        assert!(
            (es[0] - want).abs() / want < 0.01,
            "{name}: {} vs {want}",
            es[0]
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Closed forms and quadrature against the independent reference
// ---------------------------------------------------------------------------------------------

/// A random transform of the given kind (as in tests/conformance.rs).
fn transform(kind: usize, rng: &mut Rng) -> DMat4 {
    let q = DQuat::from_axis_angle(rng.unit(), rng.range(0.0, 2.0 * PI));
    let t = DVec3::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
    );
    match kind {
        0 => DMat4::from_rotation_translation(q, t),
        1 => DMat4::from_scale_rotation_translation(DVec3::splat(rng.range(0.5, 2.0)), q, t),
        2 => DMat4::from_scale_rotation_translation(
            DVec3::new(
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
                rng.range(0.5, 2.0),
            ),
            q,
            t,
        ),
        _ => {
            DMat4::from_rotation_translation(q, t)
                * DMat4::from_cols_array_2d(&[
                    [rng.range(0.8, 1.5), rng.range(-0.5, 0.5), 0.0, 0.0],
                    [0.0, 1.0, rng.range(-0.5, 0.5), 0.0],
                    [rng.range(-0.8, 0.8), 0.0, rng.range(0.5, 1.2), 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ])
        }
    }
}

/// A point at 1.5–4 bounding radii from the light (on the emitting side of rects and disks,
/// inside the cone of a shaped light) and a normal toward the light, perturbed, so that the
/// light is seen (mostly) above the receiver's horizon and some of it crosses it.
fn receiver(l: &Light, rng: &mut Rng) -> (DVec3, DVec3) {
    let m = DMat3::from_mat4(l.world);
    let o = l.world.w_axis.truncate();
    let size = match shape_of(l) {
        Shape::Rect(a, b) => a.hypot(b),
        Shape::Disk(r) | Shape::Sphere(r) => r,
        Shape::Cylinder(hl, r) => hl.hypot(r),
    };
    let mnorm =
        (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt();
    let axis = (m * DVec3::NEG_Z).normalize();
    let spread = match (&l.shaping, shape_of(l)) {
        (Some(s), _) => 0.8 * s.cone_angle.to_radians().min(PI),
        (None, Shape::Rect(..) | Shape::Disk(..)) => 1.3,
        _ => PI,
    };
    loop {
        let x = o + rng.cone(axis, spread) * size * mnorm * rng.range(1.5, 4.0);
        if matches!(shape_of(l), Shape::Rect(..) | Shape::Disk(..))
            && (m.inverse() * (x - o)).z >= 0.0
        {
            continue;
        }
        let n = ((o - x).normalize() + rng.unit() * 0.7).normalize();
        return (x, n);
    }
}

fn random_shaping(rng: &mut Rng) -> Shaping {
    Shaping {
        cone_angle: rng.range(10.0, 170.0),
        cone_softness: if rng.chance(0.4) {
            0.0
        } else {
            rng.range(0.0, 1.0)
        },
        focus: if rng.chance(0.5) {
            rng.range(0.2, 6.0)
        } else {
            0.0
        },
        focus_tint: DVec3::new(rng.f64(), rng.f64(), rng.f64()),
        ies: None,
    }
}

/// Every area light type, unshaped (closed forms: Lambert's rect, the sphere cap; and the
/// quadrature of disks, ellipsoids and cylinders) and shaped (the quadrature), under rotations,
/// uniform and non-uniform scale and shear, at random receivers: within 1e-6 of the
/// independent reference.
#[test]
fn area_lights_against_independent_reference() {
    use rayon::prelude::*;
    let mut rng = Rng::new(2024);
    let mut cases = Vec::new();
    for ty in 0..4 {
        for xf in 0..4 {
            for shaped in [false, true] {
                let mut l = match ty {
                    0 => Light::rect(rng.range(0.3, 2.0), rng.range(0.3, 2.0)),
                    1 => Light::disk(rng.range(0.2, 1.0)),
                    2 => Light::sphere(rng.range(0.2, 1.0)),
                    _ => Light::cylinder(rng.range(0.5, 2.0), rng.range(0.1, 0.5)),
                }
                .with_intensity(rng.range(0.5, 3.0))
                .with_transform(transform(xf, &mut rng));
                if shaped {
                    l = l.with_shaping(random_shaping(&mut rng));
                }
                let (x, n) = receiver(&l, &mut rng);
                cases.push((l, x, n, xf, shaped));
            }
        }
    }
    let results: Vec<(f64, bool, String)> = cases
        .par_iter()
        .map(|(l, x, n, xf, shaped)| {
            let got = cpu_e(l, *x, *n);
            let samples = 64;
            let want = pole_reference(l, *x, *n, samples, 1e-8) * l.inputs.intensity;
            let err = rel(got, want);
            let what = format!(
                "{} xf {xf} shaped {shaped}: {got} vs reference {want} ({err:e}); x {x} n {n} {:?}",
                l.kind.usd_type(),
                l.shaping
            );
            (err, got.max_element() > 0.0, what)
        })
        .collect();
    let worst = results.iter().map(|r| r.0).fold(0.0, f64::max);
    let lit = results.iter().filter(|r| r.1).count();
    println!(
        "{} configurations ({lit} lit), largest relative difference {worst:e}",
        results.len()
    );
    for (err, _, what) in &results {
        assert!(*err <= 1e-6, "{what}");
    }
    assert!(
        lit * 10 >= results.len() * 9,
        "only {lit} of {} receivers see their light",
        results.len()
    );
}

/// The receiver horizon cutting through a light: rect (Lambert on the clipped polygon), disk,
/// sphere cap partly below the horizon, and a distant cone partly below it.
#[test]
fn horizon_clipping() {
    let down = DMat4::from_rotation_translation(
        DQuat::from_rotation_x(-FRAC_PI_2),
        DVec3::new(0.0, 2.0, 0.0),
    );
    // A wall receiver at x = 0.2 facing +X cuts each light through its middle.
    let (x, n) = (DVec3::new(0.2, 0.0, 0.0), DVec3::X);
    for l in [
        Light::rect(2.0, 1.0),
        Light::disk(0.8),
        Light::sphere(0.5),
        Light::cylinder(2.0, 0.3),
    ] {
        let l = l.with_transform(down);
        let got = cpu_e(&l, x, n);
        let want = pole_reference(&l, x, n, 64, 1e-10);
        assert!(
            got.x > 0.0 && rel(got, want) <= 1e-6,
            "{}: {got} vs {want}",
            l.kind.usd_type()
        );
        // Half of it: the opposite wall sees the rest; together they see the whole light as a
        // receiver facing... (both halves are positive and smaller than the light seen facing it).
        let other = cpu_e(&l, x, -n);
        assert!(other.x > 0.0);
    }
    // Sphere cap partly below the horizon: independent 1-D check (a sphere at distance d,
    // elevation γ above a receiver's horizon) via the reference.
    let s = Light::sphere(0.5).with_transform(DMat4::from_translation(DVec3::new(2.0, 0.1, 0.0)));
    let got = cpu_e(&s, DVec3::ZERO, DVec3::Y);
    let want = pole_reference(&s, DVec3::ZERO, DVec3::Y, 64, 1e-10);
    assert!(rel(got, want) <= 1e-6, "{got} vs {want}");
    // Distant cone (angle 40°) with its centre 10° above the horizon: by the cap formula's
    // independent statement, ∫ over the cap of max(0, n·ω).
    let tilt = DQuat::from_rotation_z((80.0f64).to_radians()) * DQuat::from_rotation_x(-FRAC_PI_2);
    let d = Light::distant(40.0)
        .with_intensity(1.0)
        .with_transform(DMat4::from_quat(tilt));
    let got = cpu_e(&d, DVec3::ZERO, DVec3::Y).x;
    let c = -(tilt * DVec3::NEG_Z);
    let want = simpson(
        &|t: f64| {
            // Cap of half-angle 20° around c, polar coordinates (t, φ) around c.
            let (u, v) = c.any_orthonormal_pair();
            let mut s = 0.0;
            let k = 2000;
            for j in 0..k {
                let ph = (j as f64 + 0.5) * 2.0 * PI / k as f64;
                let w = c * t.cos() + (u * ph.cos() + v * ph.sin()) * t.sin();
                s += w.y.max(0.0);
            }
            DVec3::splat(s * 2.0 * PI / k as f64 * t.sin())
        },
        0.0,
        20f64.to_radians(),
        1e-10,
    )
    .x;
    assert!((got - want).abs() / want < 1e-6, "{got} vs {want}");
}

#[test]
fn zero_cases() {
    let s = Light::sphere(1.0).with_transform(DMat4::from_translation(DVec3::new(0.0, 0.0, 5.0)));
    // Inside the sphere, on its surface, and a receiver facing away.
    assert_eq!(cpu_e(&s, DVec3::new(0.0, 0.3, 5.2), DVec3::Z), DVec3::ZERO);
    assert_eq!(cpu_e(&s, DVec3::new(0.0, 0.0, 4.0), DVec3::Z), DVec3::ZERO);
    assert_eq!(cpu_e(&s, DVec3::ZERO, DVec3::NEG_Z), DVec3::ZERO);
    // An ellipsoid, a shaped sphere: inside is 0 too.
    let e = s
        .clone()
        .with_transform(DMat4::from_scale_rotation_translation(
            DVec3::new(2.0, 1.0, 1.0),
            DQuat::IDENTITY,
            DVec3::Z * 5.0,
        ));
    assert_eq!(cpu_e(&e, DVec3::new(1.5, 0.0, 5.0), DVec3::X), DVec3::ZERO);
    assert!(cpu_e(&e, DVec3::new(2.5, 0.0, 5.0), DVec3::NEG_X).x > 0.0);
    // Behind a rect / disk, and in their plane.
    for l in [Light::rect(1.0, 1.0), Light::disk(0.5)] {
        assert_eq!(
            cpu_e(&l, DVec3::new(0.0, 0.0, 1.0), DVec3::NEG_Z),
            DVec3::ZERO
        );
        assert_eq!(
            cpu_e(&l, DVec3::new(2.0, 0.0, 0.0), DVec3::NEG_X),
            DVec3::ZERO
        );
        assert!(cpu_e(&l, DVec3::new(0.0, 0.0, -1.0), DVec3::Z).x > 0.0);
        assert_eq!(
            cpu_e(&l, DVec3::new(0.0, 0.0, -1.0), DVec3::NEG_Z),
            DVec3::ZERO
        );
    }
    // Inside a cylinder's tube (sees only its non-emitting inside), and along its axis.
    let c = Light::cylinder(2.0, 0.5);
    assert_eq!(cpu_e(&c, DVec3::new(0.5, 0.1, 0.0), DVec3::Y), DVec3::ZERO);
    assert_eq!(
        cpu_e(&c, DVec3::new(3.0, 0.0, 0.0), DVec3::NEG_X),
        DVec3::ZERO
    );
    // A cone angle ≤ 0 lights nothing; a delta distant light below the horizon gives 0.
    let dark = Light::sphere(0.5).with_shaping(Shaping {
        cone_angle: -1.0,
        ..Shaping::default()
    });
    assert_eq!(
        cpu_e(&dark, DVec3::new(0.0, 0.0, -3.0), DVec3::Z),
        DVec3::ZERO
    );
    assert_eq!(
        cpu_e(&Light::distant(0.0), DVec3::ZERO, DVec3::NEG_Z),
        DVec3::ZERO
    );
    // A zero normal is not a direction: 0, not NaN.
    assert_eq!(cpu_e(&Light::dome(), DVec3::ZERO, DVec3::ZERO), DVec3::ZERO);
}

#[test]
fn dome_and_diffuse() {
    // A uniform dome gives π·L on any receiver; diffuse scales the result.
    let d = Light::dome()
        .with_intensity(2.0)
        .with_color(DVec3::new(1.0, 0.5, 0.25))
        .with_diffuse(0.5);
    let e = cpu_e(&d, DVec3::new(3.0, 1.0, 2.0), DVec3::new(0.3, -0.2, 0.9));
    assert!((e - DVec3::new(1.0, 0.5, 0.25) * PI).abs().max_element() < 1e-14);
    let r = Light::rect(1.0, 1.0);
    let a = cpu_e(&r, DVec3::new(0.1, 0.2, -1.0), DVec3::Z);
    let b = cpu_e(
        &r.clone().with_diffuse(0.25),
        DVec3::new(0.1, 0.2, -1.0),
        DVec3::Z,
    );
    assert!((b - a * 0.25).abs().max_element() < 1e-15);
}

/// treatAsPoint and treatAsLine: the point/segment with the full-size light's projected area.
#[test]
fn point_and_line_sources() {
    // Point: an ellipsoid (scale 2, 1, 1) seen along its long axis and broadside.
    let mut s = Light::sphere(0.5).with_transform(DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0)));
    s.kind = LightType::Sphere {
        radius: 0.5,
        treat_as_point: true,
    };
    // Along X: projected area π·0.5²·1·1; broadside along Z: π·(0.5·2)(0.5).
    let ex = cpu_e(&s, DVec3::new(10.0, 0.0, 0.0), DVec3::NEG_X).x;
    assert!((ex - PI * 0.25 / 100.0).abs() < 1e-15);
    let ez = cpu_e(&s, DVec3::new(0.0, 0.0, 10.0), DVec3::new(0.0, 0.6, -0.8)).x;
    assert!((ez - PI * 0.5 * 0.8 / 100.0).abs() < 1e-15, "{ez}");
    // Far away the point and the finite ellipsoid agree to O((size/d)²).
    let mut f = s.clone();
    f.kind = LightType::Sphere {
        radius: 0.5,
        treat_as_point: false,
    };
    let x = DVec3::new(30.0, 20.0, 10.0);
    let n = -x.normalize();
    assert!(rel(cpu_e(&f, x, n), cpu_e(&s, x, n)) < 1e-3);
    // Line: a segment of length 2 along X with radius 0.25; the intensity along e is
    // L·2·ℓ·r·|e_yz|, spread evenly along the segment; check against a direct 1-D sum.
    let mut c = Light::cylinder(2.0, 0.25).with_intensity(3.0);
    c.kind = LightType::Cylinder {
        length: 2.0,
        radius: 0.25,
        treat_as_line: true,
    };
    let (x, n) = (
        DVec3::new(0.7, 0.4, -0.3),
        DVec3::new(-0.2, -0.9, 0.3).normalize(),
    );
    let got = cpu_e(&c, x, n).x;
    let want = simpson(
        &|sx: f64| {
            let w = DVec3::new(sx, 0.0, 0.0) - x;
            let d = w.length();
            let e = -w / d;
            let intensity = 3.0 * 2.0 * 2.0 * 0.25 * (e.y * e.y + e.z * e.z).sqrt() / 2.0;
            DVec3::splat(intensity * (n.dot(w) / d).max(0.0) / (d * d))
        },
        -1.0,
        1.0,
        1e-13,
    )
    .x;
    assert!((got - want).abs() / want < 1e-9, "{got} vs {want}");
    // Shaped line and point against the same sums with the spec's shaping.
    let sh = Shaping {
        cone_angle: 60.0,
        cone_softness: 0.3,
        focus: 1.5,
        focus_tint: DVec3::new(0.2, 0.5, 1.0),
        ies: None,
    };
    let cs = c.clone().with_shaping(sh.clone());
    let got = cpu_e(&cs, x, n);
    let want = simpson(
        &|sx: f64| {
            let w = DVec3::new(sx, 0.0, 0.0) - x;
            let d = w.length();
            let e = -w / d;
            let theta = e.dot(DVec3::NEG_Z).clamp(-1.0, 1.0).acos();
            let intensity = 3.0 * 2.0 * 2.0 * 0.25 * (e.y * e.y + e.z * e.z).sqrt() / 2.0;
            spec_shaping(&Some(sh.clone()), theta) * (intensity * (n.dot(w) / d).max(0.0) / (d * d))
        },
        -1.0,
        1.0,
        1e-13,
    );
    assert!(rel(got, want) < 1e-6, "{got} vs {want}");
}

/// The GPU kernel's quadrature (adaptive Gauss–Kronrod outer rule, adaptive inner halving), run in
/// f64 on the CPU, against the adaptive reference over random lights and receivers: its own
/// error must leave room for f32 rounding within the 1e-4 GPU tolerance.
#[test]
fn kernel_rule_in_f64_is_within_1e_5_of_the_reference() {
    use luxeval::testkit::{irradiance_samples, kernel_rule_irradiance, random_lights};
    let mut rng = Rng::new(0xF1_7ED);
    let lights = random_lights(&mut rng, 2);
    let mut worst = (0.0f64, String::new());
    let mut compared = 0;
    for l in &lights {
        let p = prep(l);
        let (pts, nrms) = irradiance_samples(&p, 30, &mut rng);
        for (x, n) in pts.iter().zip(&nrms) {
            let x = glam::Vec3::from_array(*x).as_dvec3();
            let n = glam::Vec3::from_array(*n).as_dvec3();
            let a = p.irradiance(x, n);
            if a.max_element() <= 0.0 {
                continue;
            }
            compared += 1;
            let f = kernel_rule_irradiance(&p, x, n);
            let e = (f - a).abs().max_element() / a.abs().max_element();
            if e > worst.0 {
                worst = (e, format!("{} at x {x} n {n}: {f} vs {a}", l.path));
            }
        }
    }
    println!(
        "kernel rule in f64: {compared} receivers, worst {:.3e} {}",
        worst.0, worst.1
    );
    assert!(compared > 1000, "only {compared} receivers");
    assert!(worst.0 <= 1e-5, "worst {:.3e}: {}", worst.0, worst.1);
}
