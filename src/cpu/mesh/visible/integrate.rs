//! A test oracle for the visible pieces' integrals: adaptive cubature of any integrand over a
//! planar convex piece seen from x, by spherical triangles (Radon's degree-5 rule, refined
//! where the children's sum differs from the parent's value). The tests check the closed forms
//! (Lambert's formula on the pieces, the shaped integrals) against it; nothing else uses it.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::DVec3;

use super::clip3_into;

/// One cell of [`integrate_piece`]: a spherical triangle (unit vertices), its four children's
/// rule values, their sum (the cell's value) and its difference from the cell's own rule value
/// (the cell's error estimate).
struct Cell {
    tri: [DVec3; 3],
    children: [DVec3; 4],
    fine: DVec3,
    err: f64,
}

impl PartialEq for Cell {
    fn eq(&self, o: &Self) -> bool {
        self.err.total_cmp(&o.err) == Ordering::Equal
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Cell {
    fn cmp(&self, o: &Self) -> Ordering {
        self.err.total_cmp(&o.err)
    }
}

/// The four children of a spherical triangle: its edges' midpoints pushed out to the sphere.
fn split_cell(t: &[DVec3; 3]) -> [[DVec3; 3]; 4] {
    let m = |a: DVec3, b: DVec3| (a + b).normalize();
    let (ab, bc, ca) = (m(t[0], t[1]), m(t[1], t[2]), m(t[2], t[0]));
    [[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]
}

/// Radon's degree-5 seven-point rule on a triangle (Stroud 1971, T2:5-1): barycentric points
/// and weights (summing to 1).
fn radon7() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a1, b1, w1) = (
        (6.0 - s) / 21.0,
        (9.0 + 2.0 * s) / 21.0,
        (155.0 - s) / 1200.0,
    );
    let (a2, b2, w2) = (
        (6.0 + s) / 21.0,
        (9.0 - 2.0 * s) / 21.0,
        (155.0 + s) / 1200.0,
    );
    [
        ([1.0 / 3.0; 3], 9.0 / 40.0),
        ([a1, a1, b1], w1),
        ([a1, b1, a1], w1),
        ([b1, a1, a1], w1),
        ([a2, a2, b2], w2),
        ([a2, b2, a2], w2),
        ([b2, a2, a2], w2),
    ]
}

/// ∫ f(ω) max(0, n·ω) dω over a piece: the spherical polygon of the directions of `verts`
/// (vectors from x to a convex planar polygon's vertices, in order), adaptively to relative
/// tolerance `rel` (of the largest component) — for shaped meshes, whose radiance varies with
/// ω.
///
/// The polygon is clipped at the horizon (the plane n·q = 0 through x, where max(0, n·ω) has
/// its kink) and fanned into spherical triangles. A spherical triangle ABC (unit vertices) is
/// the central projection of the flat triangle ABC, and on a flat triangle q = λ·(A, B, C) the
/// solid angle element is dω = |A·(B×C)| / |q|³ dλ (the cosine over distance squared of a
/// planar patch, cosθ/r² dA = |q̂·N| dA / |q|²), so a triangle rule applies on the flat
/// triangle. Cells are split in four at their edges' midpoints pushed out to the sphere
/// (geodesic subdivision: the four children tile the parent exactly), largest error first,
/// the error of a cell being its rule value against its children's sum.
///
/// Test-only: the tests of shaped meshes use it as an independent integral (a masked textured
/// dome, which used it, is now integrated exactly, `cpu/portal.rs`).
pub(crate) fn integrate_piece(
    verts: &[DVec3],
    n: DVec3,
    rel: f64,
    f: &mut impl FnMut(DVec3) -> DVec3,
) -> DVec3 {
    /// A bound on the work: cells (each 28 evaluations of f when made).
    const MAX_CELLS: usize = 20_000;
    let poly: Vec<(DVec3, u8)> = verts.iter().map(|&q| (q, 0)).collect();
    let mut units: Vec<DVec3> = Vec::new();
    clip3_into(&poly, n, 0, |(q, _)| units.extend(q.try_normalize()));
    if units.len() < 3 {
        return DVec3::ZERO;
    }
    let rule = radon7();
    let mut value = |t: &[DVec3; 3]| -> DVec3 {
        let det = t[0].dot(t[1].cross(t[2])).abs();
        if !(det > 0.0) {
            return DVec3::ZERO;
        }
        let mut s = DVec3::ZERO;
        for (l, w) in &rule {
            let q = l[0] * t[0] + l[1] * t[1] + l[2] * t[2];
            let r = q.length();
            let u = q / r;
            s += f(u) * (w * n.dot(u).max(0.0) / (r * r * r));
        }
        s * (0.5 * det)
    };
    let mut make = |t: [DVec3; 3], coarse: Option<DVec3>| -> Cell {
        let coarse = coarse.unwrap_or_else(|| value(&t));
        let children = split_cell(&t).map(|c| value(&c));
        let fine = children.iter().sum::<DVec3>();
        Cell {
            tri: t,
            children,
            fine,
            err: (fine - coarse).abs().max_element(),
        }
    };
    // Start from cells no wider than about 0.5 rad, where the rule is already close.
    let mut start: Vec<[DVec3; 3]> = (1..units.len() - 1)
        .map(|k| [units[0], units[k], units[k + 1]])
        .collect();
    let mut heap = BinaryHeap::new();
    while let Some(t) = start.pop() {
        let wide = (0..3).any(|k| (t[k] - t[(k + 1) % 3]).length() > 0.5);
        if wide && heap.len() + start.len() < MAX_CELLS / 4 {
            start.extend(split_cell(&t));
        } else {
            heap.push(make(t, None));
        }
    }
    // Running sums, recomputed exactly when they say to stop (and at the end).
    let mut total: DVec3 = heap.iter().map(|c| c.fine).sum();
    let mut err: f64 = heap.iter().map(|c| c.err).sum();
    loop {
        if err <= rel * total.abs().max_element() || heap.len() + 3 > MAX_CELLS {
            total = heap.iter().map(|c| c.fine).sum();
            err = heap.iter().map(|c| c.err).sum();
            if err <= rel * total.abs().max_element() || heap.len() + 3 > MAX_CELLS {
                return total;
            }
        }
        let Some(worst) = heap.pop() else {
            return total;
        };
        total -= worst.fine;
        err -= worst.err;
        for (t, coarse) in split_cell(&worst.tri).into_iter().zip(worst.children) {
            let c = make(t, Some(coarse));
            total += c.fine;
            err += c.err;
            heap.push(c);
        }
    }
}
