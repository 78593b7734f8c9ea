//! Convex polygons in a chart's plane: splitting by a line (Sutherland–Hodgman, 1974, one
//! clipping line at a time, keeping both sides), the separating-axis overlap test and the
//! difference of two convex polygons as convex pieces.
//!
//! Every classification takes a tolerance: a vertex within it of a line counts as on the line.
//! Without one, two triangles that share an edge (the common case in a mesh) would cut each
//! other into slivers one rounding error wide, which add nothing to any integral but multiply
//! the pieces; with it, a cut that would leave less than the tolerance on one side is not made,
//! which moves the result by at most the tolerance times the piece's perimeter.

use glam::DVec2;

/// A convex polygon, counter-clockwise.
pub(super) type Poly = Vec<DVec2>;

/// The line n·p + c = 0 with n a unit vector: [`Line::eval`] is the signed distance, positive
/// on the left of the edge it was built from (the inside of a counter-clockwise polygon).
#[derive(Clone, Copy, Debug)]
pub(super) struct Line {
    n: DVec2,
    c: f64,
}

impl Line {
    /// The line through a and b, or None when they coincide (a repeated vertex has no edge).
    pub(super) fn through(a: DVec2, b: DVec2) -> Option<Line> {
        let e = b - a;
        let len = e.length();
        if !(len > 0.0) {
            return None;
        }
        let n = DVec2::new(-e.y, e.x) / len;
        Some(Line { n, c: -n.dot(a) })
    }

    pub(super) fn eval(&self, p: DVec2) -> f64 {
        self.n.dot(p) + self.c
    }
}

/// The edge lines of a counter-clockwise convex polygon (its inside is where all are ≥ 0).
pub(super) fn edge_lines(p: &[DVec2]) -> Vec<Line> {
    (0..p.len())
        .filter_map(|k| Line::through(p[k], p[(k + 1) % p.len()]))
        .collect()
}

/// Twice the signed area (shoelace formula): positive when counter-clockwise.
pub(super) fn area2(p: &[DVec2]) -> f64 {
    let mut s = 0.0;
    for k in 0..p.len() {
        s += p[k].perp_dot(p[(k + 1) % p.len()]);
    }
    s
}

/// The bounding box (min, max) of a polygon.
pub(super) fn bounds(p: &[DVec2]) -> (DVec2, DVec2) {
    p.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &q| (lo.min(q), hi.max(q)),
    )
}

/// Where a convex polygon lies with respect to a signed function given at its vertices.
pub(super) enum Side {
    /// Every vertex ≥ −tol: the polygon is (up to the tolerance) on the non-negative side.
    Inside,
    /// Every vertex ≤ tol (and some below −tol).
    Outside,
    /// Both sides: (the part where d ≥ 0, the part where d ≤ 0), both convex.
    Split(Poly, Poly),
}

/// Splits a convex polygon by an affine function given by its values `d` at the vertices
/// (Sutherland–Hodgman for one clipping line, both outputs kept). The crossing points are
/// interpolated linearly, which is exact for an affine function.
pub(super) fn split(p: &[DVec2], d: &[f64], tol: f64) -> Side {
    let class = |v: f64| -> i8 {
        if v > tol {
            1
        } else if v < -tol {
            -1
        } else {
            0
        }
    };
    let has_neg = d.iter().any(|&v| class(v) < 0);
    if !has_neg {
        return Side::Inside;
    }
    let has_pos = d.iter().any(|&v| class(v) > 0);
    if !has_pos {
        return Side::Outside;
    }
    let n = p.len();
    let mut inside = Vec::with_capacity(n + 2);
    let mut outside = Vec::with_capacity(n + 2);
    for k in 0..n {
        let j = (k + 1) % n;
        let (sa, sb) = (class(d[k]), class(d[j]));
        if sa >= 0 {
            inside.push(p[k]);
        }
        if sa <= 0 {
            outside.push(p[k]);
        }
        if sa * sb < 0 {
            // |d[k]| and |d[j]| both exceed tol with opposite signs: the ratio is in (0, 1).
            let t = d[k] / (d[k] - d[j]);
            let m = p[k] + (p[j] - p[k]) * t;
            inside.push(m);
            outside.push(m);
        }
    }
    Side::Split(inside, outside)
}

/// Whether two convex polygons overlap in more than the tolerance: by the separating axis
/// theorem (for convex polygons an edge line of one of them separates them whenever anything
/// does). s's edge lines are given; p's are only made when s's do not separate.
pub(super) fn overlap(p: &[DVec2], s: &[DVec2], s_lines: &[Line], tol: f64) -> bool {
    let separates = |l: &Line, q: &[DVec2]| q.iter().all(|&v| l.eval(v) <= tol);
    if s_lines.iter().any(|l| separates(l, p)) {
        return false;
    }
    !(0..p.len())
        .any(|k| Line::through(p[k], p[(k + 1) % p.len()]).is_some_and(|l| separates(&l, s)))
}

/// Appends to `out` the convex pieces of p outside the convex polygon s (given by its edge
/// lines): the part outside s's first edge, then of the rest the part outside the second edge,
/// and so on; what is left at the end is inside s and is dropped. Pieces of no more than
/// `tiny` doubled area are dropped too.
pub(super) fn subtract(p: Poly, s_lines: &[Line], tol: f64, tiny: f64, out: &mut Vec<Poly>) {
    let mut rest = p;
    let mut d = Vec::with_capacity(rest.len() + 2);
    for l in s_lines {
        d.clear();
        d.extend(rest.iter().map(|&v| l.eval(v)));
        match split(&rest, &d, tol) {
            Side::Inside => {}
            Side::Outside => {
                out.push(rest);
                return;
            }
            Side::Split(inside, outside) => {
                if area2(&outside) > tiny {
                    out.push(outside);
                }
                rest = inside;
            }
        }
    }
}
