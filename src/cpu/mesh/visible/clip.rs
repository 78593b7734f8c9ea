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

/// A triangle's convex polygon in a chart, counter-clockwise (at most 7 vertices, see [`Small`]).
pub(super) type Poly = Small<DVec2, 8>;

/// The line n·p + c = 0 with n a unit vector: [`Line::eval`] is the signed distance, positive
/// on the left of the edge it was built from (the inside of a counter-clockwise polygon).
#[derive(Clone, Copy, Debug, Default)]
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

/// The edge lines of a counter-clockwise convex polygon of at most 8 vertices (its inside is
/// where all are ≥ 0).
pub(super) fn edge_lines(p: &[DVec2]) -> Small<Line, 8> {
    let mut out = Small::default();
    for k in 0..p.len() {
        if let Some(l) = Line::through(p[k], p[(k + 1) % p.len()]) {
            out.add(l);
        }
    }
    out
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
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Side {
    /// Every vertex ≥ −tol: the polygon is (up to the tolerance) on the non-negative side.
    Inside,
    /// Every vertex ≤ tol (and some below −tol).
    Outside,
    /// Both sides: [`split`] wrote the part where d ≥ 0 and the part where d ≤ 0, both convex.
    Split,
}

/// Somewhere to put a polygon's vertices: a growable buffer or a fixed one ([`Small`]).
pub(super) trait Push {
    fn push(&mut self, v: DVec2);
}

impl Push for Vec<DVec2> {
    fn push(&mut self, v: DVec2) {
        Vec::push(self, v)
    }
}

/// A convex polygon of at most N vertices, in place (no allocation): a triangle clipped by the
/// four planes of a cube map's pyramid has at most 7, and cut once more by a line at most 8.
#[derive(Clone, Copy, Debug)]
pub(super) struct Small<T: Copy + Default, const N: usize> {
    v: [T; N],
    n: usize,
}

impl<T: Copy + Default, const N: usize> Default for Small<T, N> {
    fn default() -> Self {
        Small {
            v: [T::default(); N],
            n: 0,
        }
    }
}

impl<T: Copy + Default, const N: usize> Small<T, N> {
    /// Appends v; panics past N (the bounds above are geometric facts, not tolerances).
    pub(super) fn add(&mut self, v: T) {
        self.v[self.n] = v;
        self.n += 1;
    }

    pub(super) fn pop(&mut self) {
        self.n -= 1;
    }

    pub(super) fn retain_first(&mut self, n: usize) {
        self.n = self.n.min(n);
    }

    pub(super) fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.v[..self.n]
    }
}

impl<T: Copy + Default, const N: usize> std::ops::Deref for Small<T, N> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.v[..self.n]
    }
}

impl<const N: usize> Push for Small<DVec2, N> {
    fn push(&mut self, v: DVec2) {
        self.add(v)
    }
}

/// A sink that drops what it is given (the side of a split that is not wanted).
pub(super) struct Drop;

impl Push for Drop {
    fn push(&mut self, _: DVec2) {}
}

/// Where a polygon lies with respect to the signed values `d` at its vertices, up to `tol`.
pub(super) fn classify(d: &[f64], tol: f64) -> Side {
    let (mut neg, mut pos) = (false, false);
    for &v in d {
        neg |= v < -tol;
        pos |= v > tol;
    }
    match (neg, pos) {
        (false, _) => Side::Inside,
        (true, false) => Side::Outside,
        (true, true) => Side::Split,
    }
}

/// Splits a convex polygon by an affine function given by its values `d` at the vertices
/// (Sutherland–Hodgman for one clipping line, both outputs kept): appends the part where
/// d ≥ 0 to `inside` and the part where d ≤ 0 to `outside`, when [`classify`] says `Split`
/// (otherwise nothing is written). The crossing points are interpolated linearly, which is
/// exact for an affine function.
pub(super) fn split(
    p: &[DVec2],
    d: &[f64],
    tol: f64,
    inside: &mut impl Push,
    outside: &mut impl Push,
) -> Side {
    let side = classify(d, tol);
    if side != Side::Split {
        return side;
    }
    let class = |v: f64| -> i8 {
        if v > tol {
            1
        } else if v < -tol {
            -1
        } else {
            0
        }
    };
    let n = p.len();
    for k in 0..n {
        let j = if k + 1 == n { 0 } else { k + 1 };
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
    Side::Split
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

/// Whether an edge line of p or of s leaves the other outside (up to the tolerance): the two
/// convex polygons overlap in no more than the tolerance ([`overlap`] with both polygons'
/// edge lines known).
pub(super) fn separated(
    p: &[DVec2],
    p_lines: &[Line],
    s: &[DVec2],
    s_lines: &[Line],
    tol: f64,
) -> bool {
    let separates = |l: &Line, q: &[DVec2]| q.iter().all(|&v| l.eval(v) <= tol);
    s_lines.iter().any(|l| separates(l, p)) || p_lines.iter().any(|l| separates(l, s))
}

/// Convex polygons stored one after the other in one buffer (no allocation per polygon), each
/// with its bounding box.
#[derive(Default)]
pub(super) struct Pieces {
    verts: Vec<DVec2>,
    /// (first vertex, end, box min, box max) of each polygon.
    index: Vec<(usize, usize, DVec2, DVec2)>,
}

impl Pieces {
    pub(super) fn clear(&mut self) {
        self.verts.clear();
        self.index.clear();
    }

    pub(super) fn len(&self) -> usize {
        self.index.len()
    }

    pub(super) fn is_empty(&self) -> bool {
        self.index.is_empty()
    }

    pub(super) fn push(&mut self, p: &[DVec2]) {
        let (lo, hi) = bounds(p);
        let start = self.verts.len();
        self.verts.extend_from_slice(p);
        self.index.push((start, self.verts.len(), lo, hi));
    }

    /// The k-th polygon and its box.
    pub(super) fn get(&self, k: usize) -> (&[DVec2], DVec2, DVec2) {
        let (a, b, lo, hi) = self.index[k];
        (&self.verts[a..b], lo, hi)
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = &[DVec2]> {
        self.index.iter().map(|&(a, b, _, _)| &self.verts[a..b])
    }

    /// The box of all the polygons.
    pub(super) fn bounds(&self) -> (DVec2, DVec2) {
        self.index.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &(_, _, a, b)| (lo.min(a), hi.max(b)),
        )
    }
}

/// Scratch buffers of [`subtract`].
#[derive(Default)]
pub(super) struct Scratch {
    rest: Vec<DVec2>,
    inside: Vec<DVec2>,
    outside: Vec<DVec2>,
    d: Vec<f64>,
}

/// Appends to `out` the convex pieces of p outside the convex polygon s (given by its edge
/// lines): the part outside s's first edge, then of the rest the part outside the second edge,
/// and so on; what is left at the end is inside s and is dropped. Pieces of no more than
/// `tiny` doubled area are dropped too.
pub(super) fn subtract(
    p: &[DVec2],
    s_lines: &[Line],
    tol: f64,
    tiny: f64,
    out: &mut Pieces,
    w: &mut Scratch,
) {
    w.rest.clear();
    w.rest.extend_from_slice(p);
    for l in s_lines {
        w.d.clear();
        w.d.extend(w.rest.iter().map(|&v| l.eval(v)));
        w.inside.clear();
        w.outside.clear();
        match split(&w.rest, &w.d, tol, &mut w.inside, &mut w.outside) {
            Side::Inside => {}
            Side::Outside => {
                out.push(&w.rest);
                return;
            }
            Side::Split => {
                if area2(&w.outside) > tiny {
                    out.push(&w.outside);
                }
                std::mem::swap(&mut w.rest, &mut w.inside);
            }
        }
    }
}
