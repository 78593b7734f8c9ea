//! Tests of the visible pieces. The expected values come from closed forms on hand-made
//! geometry (Lambert's formula on polygons chosen by hand, π for a receiver enclosed by
//! emitters, |w_x| + |w_y| + |w_z| for a unit cube's shadow), or from a brute-force ray cast
//! written here (first hit of each ray against every triangle) over jittered stratified
//! directions, whose statistical error is measured from independent replicas.

use super::*;
use std::f64::consts::PI;
use std::time::Instant;

fn tri(a: DVec3, b: DVec3, c: DVec3) -> MeshTriangle {
    MeshTriangle {
        p: [a, b, c],
        face: 0,
    }
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// A quad a b c d (in order, front by the right-hand rule) as two triangles.
fn quad(out: &mut Vec<MeshTriangle>, a: DVec3, b: DVec3, c: DVec3, d: DVec3) {
    out.push(tri(a, b, c));
    out.push(tri(a, c, d));
}

/// The corners of the box's six faces, each counter-clockwise seen from outside.
fn box_faces(lo: DVec3, hi: DVec3) -> Vec<[DVec3; 4]> {
    let c = |i: usize| {
        v(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ]
    .iter()
    .map(|f| f.map(c))
    .collect()
}

fn box_mesh(lo: DVec3, hi: DVec3, outward: bool) -> Vec<MeshTriangle> {
    let mut t = Vec::new();
    for [a, b, c, d] in box_faces(lo, hi) {
        if outward {
            quad(&mut t, a, b, c, d);
        } else {
            quad(&mut t, d, c, b, a);
        }
    }
    t
}

fn octahedron(o: DVec3, r: f64) -> Vec<MeshTriangle> {
    let mut t = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                let (a, b, c) = (
                    o + v(sx * r, 0.0, 0.0),
                    o + v(0.0, sy * r, 0.0),
                    o + v(0.0, 0.0, sz * r),
                );
                // Outward: the normal should point along (sx, sy, sz).
                if (b - a).cross(c - a).dot(v(sx, sy, sz)) > 0.0 {
                    t.push(tri(a, b, c));
                } else {
                    t.push(tri(a, c, b));
                }
            }
        }
    }
    t
}

/// A prism over the non-convex L = [0,2]×[0,1] ∪ [0,1]×[1,2], from z = 0 to z = h, outward.
fn l_prism(h: f64) -> Vec<MeshTriangle> {
    let l = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let mut t = Vec::new();
    for k in 0..l.len() {
        let (a, b) = (l[k], l[(k + 1) % l.len()]);
        // The outline runs counter-clockwise seen from +z, so (a, b, b↑, a↑) faces outward.
        quad(
            &mut t,
            v(a.0, a.1, 0.0),
            v(b.0, b.1, 0.0),
            v(b.0, b.1, h),
            v(a.0, a.1, h),
        );
    }
    for (z, up) in [(0.0, false), (h, true)] {
        for [x0, y0, x1, y1] in [[0.0, 0.0, 2.0, 1.0], [0.0, 1.0, 1.0, 2.0]] {
            let (a, b, c, d) = (v(x0, y0, z), v(x1, y0, z), v(x1, y1, z), v(x0, y1, z));
            if up {
                quad(&mut t, a, b, c, d);
            } else {
                quad(&mut t, d, c, b, a);
            }
        }
    }
    t
}

/// A polygonal torus around the z axis: `m` segments, a `k`-gon cross-section of radius r at
/// radius big_r, outward; 2 m k triangles.
fn ring(m: usize, k: usize, big_r: f64, r: f64) -> Vec<MeshTriangle> {
    let p = |i: usize, j: usize| {
        let (a, b) = (
            2.0 * PI * i as f64 / m as f64,
            2.0 * PI * j as f64 / k as f64,
        );
        let rr = big_r + r * b.cos();
        v(rr * a.cos(), rr * a.sin(), r * b.sin())
    };
    let mut t = Vec::new();
    for i in 0..m {
        for j in 0..k {
            // Around the tube with j, along the ring with i: (i,j) (i+1,j) (i+1,j+1) (i,j+1)
            // runs so that the normal points away from the tube's centre line.
            quad(&mut t, p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
        }
    }
    // Check the orientation on one triangle: outward from the tube's centre.
    let t0 = &t[0];
    let centre = v(big_r, 0.0, 0.0);
    let nrm = (t0.p[1] - t0.p[0]).cross(t0.p[2] - t0.p[0]);
    if nrm.dot(t0.p[0] - centre) < 0.0 {
        for x in &mut t {
            x.p.swap(1, 2);
        }
    }
    t
}

/// The first triangle the ray x + t d (t > 0) hits, lower index on ties (Möller–Trumbore).
fn first_hit(tris: &[MeshTriangle], x: DVec3, d: DVec3) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for (i, t) in tris.iter().enumerate() {
        let (e1, e2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det == 0.0 {
            continue;
        }
        let s = x - t.p[0];
        let a = s.dot(pv) / det;
        if !(0.0..=1.0).contains(&a) {
            continue;
        }
        let qv = s.cross(e1);
        let b = d.dot(qv) / det;
        if b < 0.0 || a + b > 1.0 {
            continue;
        }
        let tt = e2.dot(qv) / det;
        // Ties (coplanar triangles: equal t up to rounding) keep the earlier triangle.
        if tt > 1e-12 && best.is_none_or(|(bt, _)| tt < bt * (1.0 - 1e-12)) {
            best = Some((tt, i));
        }
    }
    best.map(|b| b.1)
}

fn emits(t: &MeshTriangle, double_sided: bool, towards: DVec3) -> bool {
    double_sided || (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).dot(towards) > 0.0
}

/// A small deterministic generator (SplitMix64) for the jitter.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// (mean, standard error) over `reps` independent replicas of a jittered `n`×`n` stratified
/// estimate.
fn replicas(reps: usize, n: usize, mut one: impl FnMut(f64, f64) -> f64) -> (f64, f64) {
    let mut rng = Rng(12345);
    let vals: Vec<f64> = (0..reps)
        .map(|_| {
            let mut s = 0.0;
            for i in 0..n {
                for j in 0..n {
                    s += one(
                        (i as f64 + rng.next()) / n as f64,
                        (j as f64 + rng.next()) / n as f64,
                    );
                }
            }
            s / (n * n) as f64
        })
        .collect();
    let mean = vals.iter().sum::<f64>() / reps as f64;
    let var = vals.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (reps - 1) as f64;
    (mean, (var / reps as f64).sqrt())
}

/// ∫ g(ω) [first hit emits] max(0, n·ω) dω by ray casting: cosine-weighted directions (the unit
/// disk's polar map lifted to the hemisphere: pdf cosθ/π), so the integral is π E[g·hit].
fn ray_cast_irradiance(
    s: &Surface,
    x: DVec3,
    n: DVec3,
    g: impl Fn(DVec3) -> f64,
    reps: usize,
    grid: usize,
) -> (f64, f64) {
    let (a, b) = n.any_orthonormal_pair();
    let (m, se) = replicas(reps, grid, |u1, u2| {
        let r = u1.sqrt();
        let phi = 2.0 * PI * u2;
        let d = a * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
        match first_hit(s.triangles, x, d) {
            Some(i) if emits(&s.triangles[i], s.double_sided, -d) => g(d),
            _ => 0.0,
        }
    });
    (PI * m, PI * se)
}

/// The visible emitting projected area along w by ray casting from the observer's side over
/// the bounding square of the mesh's shadow.
fn ray_cast_area(s: &Surface, w: DVec3, reps: usize, grid: usize) -> (f64, f64) {
    let w = w.normalize();
    let (a, b) = w.any_orthonormal_pair();
    let pts: Vec<DVec3> = s.triangles.iter().flat_map(|t| t.p).collect();
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let mut top = f64::NEG_INFINITY;
    for p in &pts {
        let q = DVec2::new(p.dot(a), p.dot(b));
        lo = lo.min(q);
        hi = hi.max(q);
        top = top.max(p.dot(w));
    }
    let (lo, hi) = (lo - 0.01, hi + 0.01);
    let size = hi - lo;
    let (m, se) = replicas(reps, grid, |u1, u2| {
        let o = a * (lo.x + u1 * size.x) + b * (lo.y + u2 * size.y) + w * (top + 1.0);
        match first_hit(s.triangles, o, -w) {
            Some(i) if emits(&s.triangles[i], s.double_sided, w) => 1.0,
            _ => 0.0,
        }
    });
    (m * size.x * size.y, se * size.x * size.y)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Lambert's formula for a hand-made polygon (the reference, independent of the charts).
fn lambert_of(corners: &[DVec3], x: DVec3, n: DVec3) -> f64 {
    polygon_irradiance(&corners.iter().map(|c| *c - x).collect::<Vec<_>>(), n)
}

#[test]
fn flat_quad_matches_lambert_front_and_back() {
    let c = [
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    let mut t = Vec::new();
    quad(&mut t, c[0], c[1], c[2], c[3]);
    let mut worst: f64 = 0.0;
    for (x, n) in [
        (v(0.3, 0.2, 0.7), v(0.1, 0.2, -1.0).normalize()),
        (v(0.3, 0.2, 0.7), v(1.0, 0.3, -0.2).normalize()), // the quad straddles the horizon
        (v(-2.0, 3.0, 0.1), v(0.6, -0.5, -0.3).normalize()),
        (v(0.5, 0.5, 1e-3), DVec3::NEG_Z),
    ] {
        let expect = lambert_of(&c, x, n);
        assert!(expect > 0.0);
        for ds in [false, true] {
            let got = Surface {
                triangles: &t,
                double_sided: ds,
            }
            .cosine_solid_angle(x, n);
            worst = worst.max(rel(got, expect));
            assert!(rel(got, expect) <= 1e-12, "{x} {n}: {got} vs {expect}");
        }
        // Behind: nothing unless double-sided.
        let (xb, nb) = (v(x.x, x.y, -x.z), v(n.x, n.y, -n.z));
        let got = Surface {
            triangles: &t,
            double_sided: false,
        }
        .cosine_solid_angle(xb, nb);
        assert_eq!(got, 0.0);
        let got = Surface {
            triangles: &t,
            double_sided: true,
        }
        .cosine_solid_angle(xb, nb);
        assert!(
            rel(got, expect) <= 1e-12,
            "behind, double-sided: {got} vs {expect}"
        );
    }
    println!("flat quad: worst relative error {worst:.2e}");
}

/// Sum of Lambert's formula over the faces of a convex solid whose emitting side faces x (a
/// convex solid's faces seen from outside do not overlap).
fn convex_reference(faces: &[Vec<DVec3>], x: DVec3, n: DVec3) -> f64 {
    faces
        .iter()
        .filter(|f| (f[1] - f[0]).cross(f[2] - f[0]).dot(x - f[0]) > 0.0)
        .map(|f| lambert_of(f, x, n))
        .sum()
}

fn directions() -> Vec<DVec3> {
    let mut rng = Rng(7);
    let mut d = vec![DVec3::Z, DVec3::NEG_X, v(1.0, 1.0, 1.0).normalize()];
    for _ in 0..12 {
        let z = 2.0 * rng.next() - 1.0;
        let phi = 2.0 * PI * rng.next();
        let s = (1.0 - z * z).sqrt();
        d.push(v(s * phi.cos(), s * phi.sin(), z));
    }
    d
}

#[test]
fn convex_box_and_octahedron_from_outside() {
    let (lo, hi) = (v(-0.5, 0.1, 0.2), v(0.7, 1.3, 0.9));
    let box_t = box_mesh(lo, hi, true);
    let box_f: Vec<Vec<DVec3>> = box_faces(lo, hi).into_iter().map(|f| f.to_vec()).collect();
    let oct_t = octahedron(v(0.2, -0.3, 0.1), 0.8);
    let oct_f: Vec<Vec<DVec3>> = oct_t.iter().map(|t| t.p.to_vec()).collect();
    let mut worst: f64 = 0.0;
    for (tris, faces) in [(&box_t, &box_f), (&oct_t, &oct_f)] {
        for x in [
            v(2.5, 1.7, 3.1),
            v(-1.9, 0.4, 0.5),
            v(0.1, 0.7, -2.0),
            v(0.3, 3.0, 0.6),
        ] {
            for n in directions() {
                let expect = convex_reference(faces, x, n);
                for ds in [false, true] {
                    let got = Surface {
                        triangles: tris,
                        double_sided: ds,
                    }
                    .cosine_solid_angle(x, n);
                    let err = (got - expect).abs() / expect.max(1e-3);
                    worst = worst.max(err);
                    assert!(err <= 1e-9, "{x} {n} ds={ds}: {got} vs {expect}");
                }
            }
        }
    }
    println!("convex solids from outside: worst relative error {worst:.2e}");
}

#[test]
fn inward_box_dark_outside_full_inside() {
    let (lo, hi) = (v(-0.5, 0.1, 0.2), v(0.7, 1.3, 0.9));
    let t = box_mesh(lo, hi, false);
    let s = Surface {
        triangles: &t,
        double_sided: false,
    };
    for x in [v(2.5, 1.7, 3.1), v(-1.9, 0.4, 0.5)] {
        for n in directions() {
            // The near faces show their backs and hide the inner sides of the far ones.
            assert_eq!(s.cosine_solid_angle(x, n), 0.0, "{x} {n}");
        }
    }
    // Inside, every direction meets an emitting inner side: the whole hemisphere, π.
    let mut worst: f64 = 0.0;
    for x in [v(0.1, 0.7, 0.55), v(0.65, 0.2, 0.3)] {
        for n in directions() {
            let got = s.cosine_solid_angle(x, n);
            worst = worst.max(rel(got, PI));
            assert!(rel(got, PI) <= 1e-9, "{x} {n}: {got}");
            // And the faces' sum by hand agrees (the faces tile the sphere around x).
            let faces: Vec<Vec<DVec3>> =
                box_faces(lo, hi).into_iter().map(|f| f.to_vec()).collect();
            let sum: f64 = faces.iter().map(|f| lambert_of(f, x, n)).sum();
            assert!(rel(got, sum) <= 1e-9);
        }
    }
    // The outward box from inside shows only backs.
    let out = box_mesh(lo, hi, true);
    assert_eq!(
        Surface {
            triangles: &out,
            double_sided: false
        }
        .cosine_solid_angle(v(0.1, 0.7, 0.55), DVec3::Z),
        0.0
    );
    println!("inward box from inside: worst relative error against π {worst:.2e}");
}

#[test]
fn occluder_hides_part_of_emitter() {
    // Emitter: the unit square at z = 0, front +z. Occluder: a wide square at z = 0.5 covering
    // x < 0.5, front −z (its side seen from above does not emit).
    let mut t = Vec::new();
    quad(
        &mut t,
        v(-3.0, -1.0, 0.5),
        v(-3.0, 2.0, 0.5),
        v(0.5, 2.0, 0.5),
        v(0.5, -1.0, 0.5),
    );
    quad(
        &mut t,
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(0.0, 1.0, 0.0),
    );
    // From x = (0.7, 0.4, 1), the occluder's edge x = 0.5 (at z = 0.5, half-way down) falls on
    // the emitter at 0.7 + (0.5 − 0.7)·2 = 0.3: the part x ≥ 0.3 is seen.
    let x = v(0.7, 0.4, 1.0);
    let seen = [
        v(0.3, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(0.3, 1.0, 0.0),
    ];
    let mut worst: f64 = 0.0;
    for n in [
        DVec3::NEG_Z,
        v(0.3, -0.2, -1.0).normalize(),
        v(-1.0, 0.1, -0.3).normalize(),
        v(1.0, 0.0, -0.2).normalize(),
    ] {
        let expect = lambert_of(&seen, x, n);
        let got = Surface {
            triangles: &t,
            double_sided: false,
        }
        .cosine_solid_angle(x, n);
        worst = worst.max(rel(got, expect));
        assert!(rel(got, expect) <= 1e-9, "{n}: {got} vs {expect}");
        // The occluder in the other order of the slice changes nothing.
        let mut t2 = t.clone();
        t2.rotate_left(2);
        let got2 = Surface {
            triangles: &t2,
            double_sided: false,
        }
        .cosine_solid_angle(x, n);
        assert!(rel(got2, expect) <= 1e-9);
    }
    println!("occluder: worst relative error {worst:.2e}");
}

/// Lambert's formula summed over every triangle whose emitting side faces x, ignoring
/// occlusion: what a version without self-occlusion would return.
fn without_occlusion(s: &Surface, x: DVec3, n: DVec3) -> f64 {
    s.triangles
        .iter()
        .filter(|t| emits(t, s.double_sided, x - t.p[0]))
        .map(|t| lambert_of(&t.p, x, n))
        .sum()
}

/// Compares cosine_solid_angle with the ray-cast reference at a few receivers; returns the
/// worst error in units of the reference's standard error. It also checks that the cases
/// exercise occlusion: at some receiver, ignoring it would be off by more than 20σ.
fn against_ray_cast(s: &Surface, cases: &[(DVec3, DVec3)], reps: usize, grid: usize) -> f64 {
    let mut worst: f64 = 0.0;
    let mut occlusion_seen: f64 = 0.0;
    for &(x, n) in cases {
        let got = s.cosine_solid_angle(x, n);
        let (m, se) = ray_cast_irradiance(s, x, n, |_| 1.0, reps, grid);
        let sigmas = (got - m).abs() / se.max(1e-12);
        println!("  x={x:.2} n={n:.2}: exact {got:.6} ray cast {m:.6} ± {se:.1e} ({sigmas:.1}σ)");
        assert!(m > 0.0 && got > 0.0, "the case should see some light");
        occlusion_seen = occlusion_seen.max((without_occlusion(s, x, n) - m).abs() / se);
        assert!(
            (got - m).abs() <= 4.0 * se + 1e-12,
            "{x} {n}: {got} vs {m} ± {se}"
        );
        worst = worst.max(sigmas);
    }
    println!("  ignoring occlusion would be off by up to {occlusion_seen:.0}σ");
    assert!(
        occlusion_seen > 20.0,
        "no case tells occlusion from none ({occlusion_seen:.1}σ)"
    );
    worst
}

#[test]
fn interpenetrating_triangles_against_ray_cast() {
    // Two triangles crossing each other (each pierces the other), both emitting up.
    let t = vec![
        tri(v(-1.0, -1.0, 0.0), v(1.5, -0.8, 0.4), v(0.0, 1.2, -0.3)),
        tri(v(-1.2, 0.8, 0.5), v(-0.2, -1.3, -0.4), v(1.3, 0.9, 0.2)),
    ];
    for ds in [false, true] {
        let s = Surface {
            triangles: &t,
            double_sided: ds,
        };
        let w = against_ray_cast(
            &s,
            &[
                (v(0.1, 0.2, 2.0), DVec3::NEG_Z),
                (v(0.9, -0.6, 1.1), v(-0.4, 0.3, -1.0).normalize()),
            ],
            8,
            400,
        );
        println!("interpenetrating (double-sided {ds}): worst {w:.1}σ");
    }
}

#[test]
fn crossing_quads_exact() {
    // A horizontal quad (z = 0, front +z) and a vertical one (x = 0, front +x) crossing along
    // the y axis. From any x with x > 0, z > 0 whose rays through the far halves stay within
    // |y| ≤ 1 (checked by hand for these receivers: the rays to the hidden halves cross the other
    // quad at |y| < 1), the vertical quad's upper half hides the horizontal quad's half x < 0
    // and the horizontal quad's half x > 0 hides the vertical quad's lower half: what is seen is
    // the two near halves.
    let mut t = Vec::new();
    quad(
        &mut t,
        v(-1.0, -1.0, 0.0),
        v(1.0, -1.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(-1.0, 1.0, 0.0),
    );
    quad(
        &mut t,
        v(0.0, -1.0, -1.0),
        v(0.0, 1.0, -1.0),
        v(0.0, 1.0, 1.0),
        v(0.0, -1.0, 1.0),
    );
    let near_h = [
        v(0.0, -1.0, 0.0),
        v(1.0, -1.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    let near_v = [
        v(0.0, -1.0, 0.0),
        v(0.0, 1.0, 0.0),
        v(0.0, 1.0, 1.0),
        v(0.0, -1.0, 1.0),
    ];
    let mut worst: f64 = 0.0;
    for x in [v(0.5, 0.0, 1.0), v(0.7, 0.3, 0.6)] {
        for n in directions() {
            let expect = lambert_of(&near_h, x, n) + lambert_of(&near_v, x, n);
            for ds in [false, true] {
                let got = Surface {
                    triangles: &t,
                    double_sided: ds,
                }
                .cosine_solid_angle(x, n);
                let err = (got - expect).abs() / expect.max(1e-3);
                worst = worst.max(err);
                assert!(err <= 1e-9, "{x} {n} ds={ds}: {got} vs {expect}");
            }
        }
    }
    println!("crossing quads: worst relative error {worst:.2e}");
}

#[test]
fn l_prism_and_ring_against_ray_cast() {
    let l = l_prism(0.8);
    let s = Surface {
        triangles: &l,
        double_sided: false,
    };
    // Receivers in the notch of the L and beyond it, and beside the arm along x, which hides
    // part of the notch's wall x = 1 from them (the rays to it cross the arm).
    let w = against_ray_cast(
        &s,
        &[
            (v(1.6, 1.6, 0.4), v(-1.0, -1.0, 0.0).normalize()),
            (v(2.5, 2.2, 1.5), v(-1.0, -0.8, -0.9).normalize()),
            (v(2.5, 0.5, 0.4), v(-1.0, 0.3, 0.0).normalize()),
            (v(2.4, 0.3, 1.2), v(-1.0, 0.4, -0.5).normalize()),
        ],
        8,
        300,
    );
    println!("L prism: worst {w:.1}σ");
    let r = ring(16, 6, 1.0, 0.3);
    let zmin = r
        .iter()
        .flat_map(|t| t.p)
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min);
    let s = Surface {
        triangles: &r,
        double_sided: false,
    };
    let w = against_ray_cast(
        &s,
        &[
            (v(0.0, 0.0, 0.0), DVec3::X),
            (v(0.2, -0.1, 0.9), v(0.3, 0.1, -1.0).normalize()),
            (v(2.2, 0.3, 0.4), v(-1.0, 0.0, -0.1).normalize()),
            // A floor touching the ring's flat bottom, beside it and under its hole.
            (v(1.45, 0.1, zmin), DVec3::Z),
            (v(0.3, 0.2, zmin), DVec3::Z),
        ],
        8,
        300,
    );
    println!("ring: worst {w:.1}σ");
}

/// `m` random triangles in the unit cube (sides up to `size`), the first half single-sided
/// emitters facing random ways: a soup with interpenetration and cyclic overlap.
fn soup(m: usize, size: f64, seed: u64) -> Vec<MeshTriangle> {
    let mut rng = Rng(seed);
    let r3 = |rng: &mut Rng| v(rng.next(), rng.next(), rng.next());
    (0..m)
        .map(|_| {
            let c = r3(&mut rng);
            let (a, b, d) = (r3(&mut rng) - 0.5, r3(&mut rng) - 0.5, r3(&mut rng) - 0.5);
            tri(c + a * size, c + b * size, c + d * size)
        })
        .collect()
}

#[test]
fn triangle_soup_against_ray_cast() {
    let t = soup(40, 0.8, 99);
    for ds in [false, true] {
        let s = Surface {
            triangles: &t,
            double_sided: ds,
        };
        let w = against_ray_cast(
            &s,
            &[
                (v(0.5, 0.5, 2.0), DVec3::NEG_Z),
                (v(0.5, 0.45, 0.55), v(0.3, 0.2, 1.0).normalize()),
                (v(-0.6, 0.2, 0.4), DVec3::X),
            ],
            8,
            300,
        );
        println!("soup (double-sided {ds}): worst {w:.1}σ");
        for w in [v(0.2, 0.3, 1.0), v(-1.0, 0.1, 0.2)] {
            let got = s.projected_area(w);
            let (m, se) = ray_cast_area(&s, w, 8, 600);
            println!("  soup along {w:.2}: exact {got:.6} ray cast {m:.6} ± {se:.1e}");
            assert!((got - m).abs() <= 4.0 * se, "{w}: {got} vs {m} ± {se}");
        }
    }
}

#[test]
fn projected_area_of_cubes() {
    let t = box_mesh(v(0.3, -0.2, 1.0), v(1.3, 0.8, 2.0), true);
    let inward = box_mesh(v(0.3, -0.2, 1.0), v(1.3, 0.8, 2.0), false);
    let mut worst: f64 = 0.0;
    for w in directions().into_iter().chain([DVec3::X, DVec3::NEG_Y]) {
        // A unit cube's shadow along w has area |w_x| + |w_y| + |w_z| (each face's projection,
        // the three facing w).
        let expect = w.x.abs() + w.y.abs() + w.z.abs();
        for ds in [false, true] {
            let got = Surface {
                triangles: &t,
                double_sided: ds,
            }
            .projected_area(w);
            worst = worst.max(rel(got, expect));
            assert!(rel(got, expect) <= 1e-9, "{w} ds={ds}: {got} vs {expect}");
        }
        assert_eq!(
            Surface {
                triangles: &inward,
                double_sided: false
            }
            .projected_area(w),
            0.0
        );
    }
    // Far from the origin (the chart is centred on the mesh, so nothing changes).
    let far = box_mesh(v(1e6, -2e6, 3e5), v(1e6 + 1.0, -2e6 + 1.0, 3e5 + 1.0), true);
    for w in directions() {
        let expect = w.x.abs() + w.y.abs() + w.z.abs();
        let got = Surface {
            triangles: &far,
            double_sided: false,
        }
        .projected_area(w);
        worst = worst.max(rel(got, expect));
        assert!(rel(got, expect) <= 1e-9, "far {w}: {got} vs {expect}");
    }
    let s3 = 3f64.sqrt();
    let got = Surface {
        triangles: &t,
        double_sided: false,
    }
    .projected_area(v(1.0, 1.0, 1.0));
    assert!(rel(got, s3) <= 1e-12, "{got}");
    println!("cube shadows: worst relative error {worst:.2e}");
}

#[test]
fn projected_area_of_l_prism_against_ray_cast() {
    let l = l_prism(0.8);
    for ds in [false, true] {
        let s = Surface {
            triangles: &l,
            double_sided: ds,
        };
        // Along these the arms of the L hide parts of each other.
        for w in [
            v(1.0, -0.3, 0.1),
            v(-0.3, 1.0, 0.2),
            v(1.0, 1.0, 0.3),
            v(-1.0, -1.0, 0.2),
            v(0.8, -0.5, -0.4),
        ] {
            let got = s.projected_area(w);
            let (m, se) = ray_cast_area(&s, w, 8, 300);
            println!(
                "  L prism along {w:.2} (double-sided {ds}): exact {got:.6} ray cast {m:.6} ± {se:.1e}"
            );
            assert!((got - m).abs() <= 4.0 * se, "{w}: {got} vs {m} ± {se}");
        }
    }
    // Against the sum over the faces facing w, the self-occlusion is visible (the test can
    // tell occlusion from none): along (1, −0.3, 0.1) the arm along y hides part of the wall
    // x = 1 behind the arm along x... seen from the other side: the wall x = 1 (y ∈ [1, 2])
    // looks over the top y = 1 of the arm along x, which hides its lower part.
    let w = v(1.0, -0.3, 0.1).normalize();
    let no_occlusion: f64 = l
        .iter()
        .map(|t| 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).dot(w).max(0.0))
        .sum();
    let got = Surface {
        triangles: &l,
        double_sided: false,
    }
    .projected_area(w);
    assert!(got < no_occlusion - 0.05, "{got} vs {no_occlusion}");
}

#[test]
fn coplanar_overlap_counts_once_first_wins() {
    let big = tri(v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0));
    let small = tri(v(0.2, 0.2, 0.0), v(1.0, 0.2, 0.0), v(0.2, 1.0, 0.0));
    let small_back = tri(small.p[0], small.p[2], small.p[1]);
    let x = v(0.4, 0.5, 1.3);
    let n = v(0.1, 0.2, -1.0).normalize();
    let l_big = lambert_of(&big.p, x, n);
    let l_small = lambert_of(&small.p, x, n);
    let w = v(0.2, -0.1, 1.0);
    let wn = w.normalize();
    let (a_big, a_small) = (big.area() * wn.z, small.area() * wn.z);
    let one = |t: Vec<MeshTriangle>| {
        let s = Surface {
            triangles: &t,
            double_sided: false,
        };
        (s.cosine_solid_angle(x, n), s.projected_area(w))
    };
    // The same triangle twice counts once.
    let (e, a) = one(vec![big, big]);
    assert!(rel(e, l_big) <= 1e-12 && rel(a, a_big) <= 1e-12, "{e} {a}");
    // Overlapping emitters: the union, once.
    let (e, a) = one(vec![small, big]);
    assert!(rel(e, l_big) <= 1e-12 && rel(a, a_big) <= 1e-12, "{e} {a}");
    // A non-emitting (reversed) triangle first hides its part of the emitter ...
    let (e, a) = one(vec![small_back, big]);
    assert!(
        rel(e, l_big - l_small) <= 1e-12 && rel(a, a_big - a_small) <= 1e-12,
        "{e} {a}"
    );
    // ... and second it is hidden by it.
    let (e, a) = one(vec![big, small_back]);
    assert!(rel(e, l_big) <= 1e-12 && rel(a, a_big) <= 1e-12, "{e} {a}");
}

#[test]
fn coplanar_soup_against_ray_cast() {
    // Thirty triangles in one plane (tilted, off the origin), half of them turned over (not
    // emitting): where they overlap, the first in the slice decides.
    let mut rng = Rng(3);
    let (o, a, b) = (
        v(0.2, -0.1, 0.3),
        v(1.0, 0.2, 0.1).normalize(),
        v(-0.1, 0.3, 1.0).normalize(),
    );
    let b = (b - a * a.dot(b)).normalize();
    let mut t = Vec::new();
    for k in 0..30 {
        let mut p = [DVec3::ZERO; 3];
        for q in &mut p {
            *q = o + a * (2.0 * rng.next() - 1.0) + b * (2.0 * rng.next() - 1.0);
        }
        let up = (p[1] - p[0]).cross(p[2] - p[0]).dot(a.cross(b)) > 0.0;
        if up != (k % 2 == 0) {
            p.swap(1, 2);
        }
        t.push(tri(p[0], p[1], p[2]));
    }
    let s = Surface {
        triangles: &t,
        double_sided: false,
    };
    let nrm = a.cross(b);
    let x = o + nrm * 0.7 + a * 0.2;
    let got = s.cosine_solid_angle(x, -nrm);
    let (m, se) = ray_cast_irradiance(&s, x, -nrm, |_| 1.0, 8, 400);
    println!("coplanar soup: exact {got:.6} ray cast {m:.6} ± {se:.1e}");
    assert!((got - m).abs() <= 4.0 * se, "{got} vs {m} ± {se}");
    let got = s.projected_area(nrm);
    let (m, se) = ray_cast_area(&s, nrm, 8, 400);
    println!("coplanar soup: area {got:.6} ray cast {m:.6} ± {se:.1e}");
    assert!((got - m).abs() <= 4.0 * se, "{got} vs {m} ± {se}");
    // The tie rule matters here: with the slice reversed the answer changes.
    let mut r = t.clone();
    r.reverse();
    let other = Surface {
        triangles: &r,
        double_sided: false,
    }
    .projected_area(nrm);
    assert!((other - got).abs() > 20.0 * se, "{other} vs {got}");
}

#[test]
fn receivers_on_the_mesh_are_finite() {
    let (lo, hi) = (v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0));
    let out = box_mesh(lo, hi, true);
    let mut q = Vec::new();
    quad(
        &mut q,
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(0.0, 1.0, 0.0),
    );
    let points = [
        v(0.5, 0.5, 0.0), // a face centre (and the quad's inside)
        v(0.3, 0.3, 0.0), // on the diagonal both triangles of a face share
        v(0.0, 0.0, 0.0), // a corner
        v(0.5, 0.0, 0.0), // an edge
        v(2.0, 0.5, 0.0), // on a face's plane, off the face
        v(0.5, 0.5, 1e-15),
    ];
    for tris in [&out, &q] {
        for ds in [false, true] {
            let s = Surface {
                triangles: tris,
                double_sided: ds,
            };
            for x in points {
                for n in directions() {
                    let e = s.cosine_solid_angle(x, n);
                    assert!(
                        e.is_finite() && (0.0..=PI * (1.0 + 1e-12)).contains(&e),
                        "{x} {n}: {e}"
                    );
                    for p in s.visible_from(x) {
                        assert!(p.verts.iter().all(|q| q.is_finite()));
                    }
                }
            }
        }
    }
    // On the ring's vertices and edges' midpoints, where several triangles meet at x.
    let r = ring(16, 6, 1.0, 0.3);
    for ds in [false, true] {
        let s = Surface {
            triangles: &r,
            double_sided: ds,
        };
        for tr in r.iter().step_by(7) {
            for x in [
                tr.p[0],
                0.5 * (tr.p[1] + tr.p[2]),
                (tr.p[0] + tr.p[1] + tr.p[2]) / 3.0,
            ] {
                for n in directions().into_iter().take(5) {
                    let e = s.cosine_solid_angle(x, n);
                    assert!(
                        e.is_finite() && (0.0..=PI * (1.0 + 1e-12)).contains(&e),
                        "{x} {n}: {e}"
                    );
                }
            }
        }
    }
    // Exact values on the surface: a double-sided box seen from a face's centre looking in is
    // enclosed (π); the outward single-sided box shows only backs there (0).
    let ds = Surface {
        triangles: &out,
        double_sided: true,
    };
    let e = ds.cosine_solid_angle(v(0.5, 0.5, 0.0), DVec3::Z);
    assert!(rel(e, PI) <= 1e-9, "{e}");
    // Tilted, the receiver's hemisphere also reaches below the face, where nothing is: the
    // other five faces, which tile the half-space above it, by hand.
    let (x, n) = (v(0.3, 0.3, 0.0), v(0.2, 0.1, 1.0).normalize());
    let e = ds.cosine_solid_angle(x, n);
    let expect: f64 = box_faces(lo, hi)
        .iter()
        .filter(|f| f.iter().any(|c| c.z > 0.0))
        .map(|f| lambert_of(f, x, n))
        .sum();
    assert!(e < PI - 0.01 && rel(e, expect) <= 1e-9, "{e} vs {expect}");
    let ss = Surface {
        triangles: &out,
        double_sided: false,
    };
    assert_eq!(ss.cosine_solid_angle(v(0.5, 0.5, 0.0), DVec3::Z), 0.0);
    // A floor receiver on the quad's plane beside it sees it edge-on: 0.
    let s = Surface {
        triangles: &q,
        double_sided: true,
    };
    assert_eq!(s.cosine_solid_angle(v(2.0, 0.5, 0.0), DVec3::Z), 0.0);
    assert_eq!(
        Surface {
            triangles: &q,
            double_sided: true
        }
        .projected_area(DVec3::X),
        0.0
    );
}

#[test]
fn visible_pieces_cover_what_is_seen() {
    // The pieces of a box seen from outside: the front faces, tiled (areas add up to the
    // faces' areas), each planar on its triangle, none from the back faces. Also from 1e-9
    // below the floor, where only the floor is seen and the charts' corners fall inside it.
    let (lo, hi) = (v(-0.5, 0.1, 0.2), v(0.7, 1.3, 0.9));
    let t = box_mesh(lo, hi, true);
    for x in [v(2.5, 1.7, 3.1), v(0.1, 0.4, 0.2 - 1e-9)] {
        let pieces = Surface {
            triangles: &t,
            double_sided: false,
        }
        .visible_from(x);
        let mut area = vec![0.0; t.len()];
        for p in &pieces {
            let tr = &t[p.triangle as usize];
            let nrm = (tr.p[1] - tr.p[0]).cross(tr.p[2] - tr.p[0]).normalize();
            for q in &p.verts {
                assert!(
                    (x + *q - tr.p[0]).dot(nrm).abs() < 1e-12,
                    "off the triangle's plane"
                );
            }
            let mut a = DVec3::ZERO;
            for k in 1..p.verts.len() - 1 {
                a += (p.verts[k] - p.verts[0]).cross(p.verts[k + 1] - p.verts[0]);
            }
            area[p.triangle as usize] += 0.5 * a.length();
        }
        for (i, tr) in t.iter().enumerate() {
            let front = (tr.p[1] - tr.p[0])
                .cross(tr.p[2] - tr.p[0])
                .dot(x - tr.p[0])
                > 0.0;
            let expect = if front { tr.area() } else { 0.0 };
            assert!(
                (area[i] - expect).abs() <= 1e-12,
                "{x} {i}: {} vs {expect}",
                area[i]
            );
        }
    }
}

#[test]
fn integrate_piece_of_constant_is_lambert() {
    let (lo, hi) = (v(-0.5, 0.1, 0.2), v(0.7, 1.3, 0.9));
    let t = box_mesh(lo, hi, true);
    let s = Surface {
        triangles: &t,
        double_sided: false,
    };
    let mut worst: f64 = 0.0;
    for x in [v(2.5, 1.7, 3.1), v(0.72, 0.4, 0.5)] {
        for n in directions() {
            let mut sum = DVec3::ZERO;
            for p in s.visible_from(x) {
                sum += integrate_piece(&p.verts, n, 1e-11, &mut |_| DVec3::new(1.0, 2.0, 0.5));
            }
            let expect = s.cosine_solid_angle(x, n);
            let err = (sum - DVec3::new(1.0, 2.0, 0.5) * expect)
                .abs()
                .max_element()
                / expect.max(1e-3);
            worst = worst.max(err);
            assert!(err <= 1e-9, "{x} {n}: {sum} vs {expect}");
        }
    }
    println!("integrate_piece of a constant: worst relative error {worst:.2e}");
}

#[test]
fn integrate_piece_over_an_enclosure_is_the_hemisphere_moment() {
    // From inside an inward box every direction sees an emitting inner side, so the pieces
    // tile the sphere and ∫ f(ω) max(0, n·ω) dω is the hemisphere's: for f = (n·ω)^k it is
    // 2π/(k + 2); for f = (a·ω)² with a ⟂ n it is π/4 (∫ sin²θ cos²φ cosθ sinθ dθ dφ).
    let t = box_mesh(v(-0.5, 0.1, 0.2), v(0.7, 1.3, 0.9), false);
    let s = Surface {
        triangles: &t,
        double_sided: false,
    };
    let mut worst: f64 = 0.0;
    for (x, n) in [
        (v(0.1, 0.7, 0.55), DVec3::Z),
        (v(0.65, 0.2, 0.3), v(0.3, -0.5, 0.8).normalize()),
    ] {
        let a = n.any_orthonormal_vector();
        let mut sum = DVec3::ZERO;
        for p in s.visible_from(x).iter().filter(|p| p.emitting) {
            sum += integrate_piece(&p.verts, n, 1e-11, &mut |w| {
                DVec3::new(n.dot(w).powi(8), a.dot(w).powi(2), 1.0)
            });
        }
        let expect = DVec3::new(2.0 * PI / 10.0, PI / 4.0, PI);
        let err = ((sum - expect) / expect).abs().max_element();
        worst = worst.max(err);
        assert!(err <= 1e-9, "{x} {n}: {sum} vs {expect}");
    }
    println!("integrate_piece over an enclosure: worst relative error {worst:.2e}");
}

#[test]
fn near_and_far_receivers() {
    // 1e-9 from a face, and far away (the chart shrinks to 1e-4 across): the tolerances are
    // relative, so the result stays at Lambert's formula's accuracy. (Measured: ~2e-15 at 1e-9
    // from a face, where the chart's corners inside the face must be exact, see clip3's bits;
    // 3e-10 at 1e4 away, where Lambert's formula itself, in the reference as in the pieces,
    // cancels edge terms of 1e-4 to a sum of 1e-8.)
    let (lo, hi) = (v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0));
    let t = box_mesh(lo, hi, true);
    let faces: Vec<Vec<DVec3>> = box_faces(lo, hi).into_iter().map(|f| f.to_vec()).collect();
    let mut worst: f64 = 0.0;
    for x in [
        v(0.4, 0.3, -1e-9),
        v(0.4, 1.0 + 1e-9, 0.3),
        v(3e3, 2e3, 1e3),
        v(1e4, -3e3, 2e2) + 0.5,
    ] {
        for n in directions() {
            let expect = convex_reference(&faces, x, n);
            let got = Surface {
                triangles: &t,
                double_sided: false,
            }
            .cosine_solid_angle(x, n);
            let err = (got - expect).abs() / expect.max(1e-300);
            assert!(
                err <= 1e-9 || (got - expect).abs() <= 1e-15 * PI,
                "{x} {n}: {got} vs {expect}"
            );
            if expect > 0.0 {
                worst = worst.max(err);
            }
        }
    }
    // Inside a double-sided box, 1e-9 above its floor: enclosed, π.
    let got = Surface {
        triangles: &t,
        double_sided: true,
    }
    .cosine_solid_angle(v(0.4, 0.3, 1e-9), DVec3::Z);
    assert!(rel(got, PI) <= 1e-9, "{got}");
    // A mesh far from the origin.
    let off = v(1e5, -2e5, 3e5);
    let t2: Vec<MeshTriangle> = t
        .iter()
        .map(|tr| tri(tr.p[0] + off, tr.p[1] + off, tr.p[2] + off))
        .collect();
    let faces2: Vec<Vec<DVec3>> = faces
        .iter()
        .map(|f| f.iter().map(|c| *c + off).collect())
        .collect();
    let x = off + v(2.5, 1.7, 3.1);
    for n in directions() {
        let expect = convex_reference(&faces2, x, n);
        let got = Surface {
            triangles: &t2,
            double_sided: false,
        }
        .cosine_solid_angle(x, n);
        assert!(
            (got - expect).abs() <= 1e-9 * expect.max(1e-3),
            "{n}: {got} vs {expect}"
        );
    }
    println!("near and far receivers: worst relative error {worst:.2e}");
}

#[test]
fn integrate_piece_of_shaped_radiance_against_ray_cast() {
    // A radiance peaked along −z (a shaping lobe), over a quad with an occluder.
    let mut t = Vec::new();
    quad(
        &mut t,
        v(-3.0, -1.0, 0.5),
        v(-3.0, 2.0, 0.5),
        v(0.5, 2.0, 0.5),
        v(0.5, -1.0, 0.5),
    );
    quad(
        &mut t,
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(0.0, 1.0, 0.0),
    );
    let s = Surface {
        triangles: &t,
        double_sided: false,
    };
    let x = v(0.7, 0.4, 1.0);
    let n = v(0.3, -0.2, -1.0).normalize();
    let lobe = |w: DVec3| (-w.z).max(0.0).powi(8);
    let mut got = 0.0;
    for p in s.visible_from(x).iter().filter(|p| p.emitting) {
        got += integrate_piece(&p.verts, n, 1e-10, &mut |w| DVec3::splat(lobe(w))).x;
    }
    let (m, se) = ray_cast_irradiance(&s, x, n, lobe, 8, 400);
    println!("shaped: integrate_piece {got:.6} ray cast {m:.6} ± {se:.1e}");
    assert!((got - m).abs() <= 4.0 * se, "{got} vs {m} ± {se}");
}

#[test]
fn timing_ring_of_2000_triangles() {
    let r = ring(125, 8, 1.0, 0.3);
    assert_eq!(r.len(), 2000);
    let s = Surface {
        triangles: &r,
        double_sided: false,
    };
    let receivers = [
        (v(0.0, 0.0, 0.0), DVec3::X),
        (v(0.0, 0.0, 1.0), DVec3::NEG_Z),
        (v(2.5, 0.4, 0.6), v(-1.0, 0.0, -0.2).normalize()),
        (v(0.3, -0.2, -0.8), v(0.0, 0.3, 1.0).normalize()),
        (v(1.0, 0.0, 0.0), DVec3::Z), // inside the tube
    ];
    let start = Instant::now();
    let mut total = 0.0;
    for (x, n) in receivers {
        total += s.cosine_solid_angle(x, n);
    }
    let ms = start.elapsed().as_secs_f64() * 1e3 / receivers.len() as f64;
    let start = Instant::now();
    let mut pieces = 0;
    for (x, _) in receivers {
        pieces += s.visible_from(x).len();
    }
    let ms_all = start.elapsed().as_secs_f64() * 1e3 / receivers.len() as f64;
    let start = Instant::now();
    let mut area = 0.0;
    for w in directions().iter().take(5) {
        area += s.projected_area(*w);
    }
    let ms_area = start.elapsed().as_secs_f64() * 1e3 / 5.0;
    println!(
        "ring of 2000 triangles: cosine_solid_angle {ms:.2} ms per receiver, visible_from {ms_all:.2} ms ({} pieces on average), projected_area {ms_area:.2} ms per direction (sums {total:.4}, {area:.4})",
        pieces / receivers.len()
    );
    assert!(total.is_finite() && area.is_finite());
    // A soup of 2000 random triangles: heavy overlap, the pathological case for fragmentation.
    let t = soup(2000, 0.15, 5);
    let s = Surface {
        triangles: &t,
        double_sided: false,
    };
    let start = Instant::now();
    let mut pieces = 0;
    for (x, _) in receivers {
        pieces += s.visible_from(x).len();
    }
    let ms_soup = start.elapsed().as_secs_f64() * 1e3 / receivers.len() as f64;
    let start = Instant::now();
    let a = s.projected_area(v(0.2, 0.3, 1.0));
    let ms_soup_area = start.elapsed().as_secs_f64() * 1e3;
    println!(
        "soup of 2000 random triangles: visible_from {ms_soup:.2} ms per receiver ({} pieces on average), projected_area {ms_soup_area:.2} ms",
        pieces / receivers.len()
    );
    assert!(a.is_finite());
}

/// The bench's bumpy torus (benches/mesh_light.rs): `around × across` quads, each fanned
/// (a, b, c), (a, c, d).
fn bumpy_torus(around: usize, across: usize) -> Vec<MeshTriangle> {
    use std::f64::consts::TAU;
    let p = |i: usize, j: usize| {
        let a = TAU * (i % around) as f64 / around as f64;
        let b = TAU * (j % across) as f64 / across as f64;
        let tube = 0.5 * (1.0 + 0.05 * (7.0 * a).sin());
        let rho = 2.0 + tube * b.cos();
        v(rho * a.cos(), tube * b.sin(), rho * a.sin())
    };
    let mut out = Vec::with_capacity(2 * around * across);
    for i in 0..around {
        for j in 0..across {
            quad(&mut out, p(i, j), p(i, j + 1), p(i + 1, j + 1), p(i + 1, j));
        }
    }
    out
}

/// Old (the module before the performance work, `old.rs`) against new, alternating in one run,
/// on the bench's 100k-triangle torus: irradiance at the bench's receiver, projected area, and
/// many receivers in parallel (rayon) on a 2,000-triangle ring. Prints the times and asserts
/// the results agree. `cargo test --release ... timing_old_against_new -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_old_against_new() {
    use rayon::prelude::*;
    let reps: usize = std::env::var("TIMING_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let t = bumpy_torus(250, 200);
    assert_eq!(t.len(), 100_000);
    let new = Surface {
        triangles: &t,
        double_sided: false,
    };
    let old = old::Surface {
        triangles: &t,
        double_sided: false,
    };
    let (x, n) = (v(0.5, 1.0, 0.3), DVec3::NEG_Y);
    let w = v(0.3, 0.8, 0.5);
    let time = |f: &mut dyn FnMut() -> f64| {
        let start = Instant::now();
        let r = f();
        (start.elapsed().as_secs_f64() * 1e3, r)
    };
    let ring = ring(125, 8, 1.0, 0.3);
    let rnew = Surface {
        triangles: &ring,
        double_sided: false,
    };
    let rold = old::Surface {
        triangles: &ring,
        double_sided: false,
    };
    let receivers: Vec<(DVec3, DVec3)> = (0..256)
        .map(|k| {
            let (i, j) = ((k % 16) as f64, (k / 16) as f64);
            (v(-1.6 + 0.2 * i, -1.6 + 0.2 * j, 0.5), DVec3::NEG_Z)
        })
        .collect();
    if std::env::var("ONLY_NEW").is_ok() {
        for _ in 0..reps {
            std::hint::black_box(new.cosine_solid_angle(x, n));
        }
        return;
    }
    let mut best = [f64::INFINITY; 6];
    let mut sums = [0.0; 6];
    for _ in 0..reps {
        let r = [
            time(&mut || old.cosine_solid_angle(x, n)),
            time(&mut || new.cosine_solid_angle(x, n)),
            time(&mut || old.projected_area(w)),
            time(&mut || new.projected_area(w)),
            time(&mut || {
                receivers
                    .par_iter()
                    .map(|&(x, n)| rold.cosine_solid_angle(x, n))
                    .sum()
            }),
            time(&mut || {
                receivers
                    .par_iter()
                    .map(|&(x, n)| rnew.cosine_solid_angle(x, n))
                    .sum()
            }),
        ];
        for (k, (ms, v)) in r.into_iter().enumerate() {
            best[k] = best[k].min(ms);
            sums[k] = v;
        }
    }
    println!(
        "100k torus irradiance: old {:.1} ms new {:.1} ms (×{:.2}); projected_area: old {:.1} ms new {:.1} ms (×{:.2}); 256 receivers on 2000-ring in parallel: old {:.1} ms new {:.1} ms (×{:.2})",
        best[0],
        best[1],
        best[0] / best[1],
        best[2],
        best[3],
        best[2] / best[3],
        best[4],
        best[5],
        best[4] / best[5]
    );
    println!(
        "values: {:.15} {:.15} | {:.15} {:.15} | {:.15} {:.15}",
        sums[0], sums[1], sums[2], sums[3], sums[4], sums[5]
    );
    for k in [0, 2, 4] {
        assert!(
            rel(sums[k], sums[k + 1]) < 1e-12,
            "{} vs {}",
            sums[k],
            sums[k + 1]
        );
    }
}
