//! The module as it was before the performance work (commit 5e84afc), kept for the timing
//! comparisons in the tests only: old and new are timed in the same run.
#![allow(dead_code, clippy::all)]

#[path = "old_clip.rs"]
mod clip;

use crate::cpu::irradiance::closed::polygon_irradiance;
use crate::model::MeshTriangle;
use clip::{Line, Poly, Side};
use glam::{DVec2, DVec3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Which sides emit.
#[allow(dead_code)]
pub(crate) struct Surface<'a> {
    pub triangles: &'a [MeshTriangle],
    pub double_sided: bool,
}

/// A visible part of one triangle as seen from x: its vertices as vectors from x (points of the
/// triangle: convex, planar, in order), the triangle's index in the slice, and whether the side
/// seen emits.
#[allow(dead_code)]
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    pub triangle: u32,
    pub emitting: bool,
    pub verts: Vec<DVec3>,
}

/// A triangle's plane as seen from x, relative to x.
struct Seen {
    /// The unit normal turned toward the side away from x: n·(p − x) = c > 0 on the plane.
    n: DVec3,
    c: f64,
    emitting: bool,
    /// The vertices relative to x.
    q: [DVec3; 3],
}

/// The cube map's faces: (axis e, tangents a, b). Their pyramids |w·a|, |w·b| ≤ w·e tile the
/// sphere of directions (overlapping only on their boundaries, of no measure).
const FACES: [[DVec3; 3]; 6] = [
    [DVec3::X, DVec3::Y, DVec3::Z],
    [DVec3::NEG_X, DVec3::Y, DVec3::Z],
    [DVec3::Y, DVec3::Z, DVec3::X],
    [DVec3::NEG_Y, DVec3::Z, DVec3::X],
    [DVec3::Z, DVec3::X, DVec3::Y],
    [DVec3::NEG_Z, DVec3::X, DVec3::Y],
];

/// A plane through x whose distance to a triangle is below this fraction of the triangle's
/// distance from x contains it for our purposes: the triangle is seen edge-on and subtends no
/// solid angle (and hides none); dividing by its c would only amplify rounding.
const EDGE_ON: f64 = 1e-12;

/// Chart lengths below this fraction of the chart's extent count as zero (see [`clip`]).
const LENGTH_TOL: f64 = 1e-13;

/// Depth differences below this fraction of the depths count as ties (coplanar triangles).
const DEPTH_TOL: f64 = 1e-12;

impl Surface<'_> {
    /// Every visible piece of the surface seen from x (both emitting and not), self-occlusion
    /// exact.
    #[allow(dead_code)]
    pub(crate) fn visible_from(&self, x: DVec3) -> Vec<Piece> {
        let mut out = Vec::new();
        self.pieces_from(x, |_| true, |_| true, |piece| out.push(piece));
        out
    }

    /// The visible pieces seen from x of the emitting triangles with a point above the
    /// horizon of the unit normal n: what irradiance integrates. A triangle wholly below the
    /// horizon is left out as an occluder too: it can hide only directions below the horizon.
    pub(crate) fn emitting_above(&self, x: DVec3, n: DVec3) -> Vec<Piece> {
        let above = |s: &Seen| s.q.iter().any(|q| n.dot(*q) > 0.0);
        let mut out = Vec::new();
        self.pieces_from(
            x,
            |s| s.emitting && above(s),
            above,
            |piece| {
                if piece.emitting {
                    out.push(piece)
                }
            },
        );
        out
    }

    /// Unit-radiance irradiance at x for the unit receiver normal n: the sum over the visible
    /// emitting pieces of Lambert's formula clipped at the horizon (the unshaped M3 irradiance
    /// over L).
    #[allow(dead_code)]
    pub(crate) fn cosine_solid_angle(&self, x: DVec3, n: DVec3) -> f64 {
        let mut sum = 0.0;
        // Only emitting triangles with a vertex above the horizon can add anything; the others
        // are computed only as occluders.
        let above = |s: &Seen| s.q.iter().any(|q| n.dot(*q) > 0.0);
        let wanted = |s: &Seen| s.emitting && above(s);
        // A triangle wholly below the horizon hides only directions below it: left out.
        self.pieces_from(x, wanted, above, |piece| {
            if piece.emitting {
                sum += lambert(&piece.verts, n);
            }
        });
        sum
    }

    /// The emitting area visible from direction w at infinity, projected on the plane ⟂ w
    /// (intensity(w) / L(w)). w need not be normalised; zero gives zero.
    #[allow(dead_code)]
    pub(crate) fn projected_area(&self, w: DVec3) -> f64 {
        let w = w.normalize_or_zero();
        if w == DVec3::ZERO || self.triangles.is_empty() {
            return 0.0;
        }
        let (a, b) = w.any_orthonormal_pair();
        // Chart coordinates relative to the mesh's centre keep the heights (and their tie
        // tolerance) on the mesh's own scale whatever its position.
        let (lo, hi) = self.triangles.iter().flat_map(|t| t.p).fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
        let o = 0.5 * (lo + hi);
        let extent = (hi - lo).length();
        let mut polys = Vec::with_capacity(self.triangles.len());
        for (i, t) in self.triangles.iter().enumerate() {
            let nn = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
            let nhat = nn.normalize_or_zero();
            let nw = nhat.dot(w);
            // Edge-on: its projected area is ≤ EDGE_ON times its area.
            if !(nw.abs() > EDGE_ON) {
                continue;
            }
            let emitting = if self.double_sided { true } else { nw > 0.0 };
            let poly: Poly =
                t.p.iter()
                    .map(|&p| DVec2::new((p - o).dot(a), (p - o).dot(b)))
                    .collect();
            // Height over (u, v): s = (n·(p0 − o) − u n·a − v n·b) / (n·w).
            let z = DVec3::new(-nhat.dot(a), -nhat.dot(b), nhat.dot(t.p[0] - o)) / nw;
            if let Some(p) = Proj::new(i as u32, emitting, emitting, poly, z) {
                polys.push(p);
            }
        }
        let view = View::new(polys, extent);
        let mut area = 0.0;
        view.visible(|_, pieces| {
            area += pieces.iter().map(|p| 0.5 * clip::area2(p)).sum::<f64>();
        });
        area
    }

    /// Calls `sink` with every visible piece seen from x of the triangles `wanted` accepts;
    /// the triangles `occludes` accepts hide them (a wanted triangle must be one).
    fn pieces_from(
        &self,
        x: DVec3,
        wanted: impl Fn(&Seen) -> bool,
        occludes: impl Fn(&Seen) -> bool,
        mut sink: impl FnMut(Piece),
    ) {
        let seen: Vec<Option<Seen>> = self
            .triangles
            .iter()
            .map(|t| self.seen(t, x).filter(&occludes))
            .collect();
        for [e, a, b] in FACES {
            // The pyramid's four planes through x, inside where m·w ≥ 0.
            let planes = [e - a, e + a, e - b, e + b];
            let mut polys = Vec::new();
            for (i, s) in seen.iter().enumerate() {
                let Some(s) = s else { continue };
                if planes.iter().any(|m| s.q.iter().all(|q| m.dot(*q) < 0.0)) {
                    continue;
                }
                // Each vertex carries the set of pyramid planes it was cut on (see clip3).
                let mut w3: Vec<(DVec3, u8)> = s.q.iter().map(|&q| (q, 0)).collect();
                for (bit, m) in planes.iter().enumerate() {
                    w3 = clip3(&w3, *m, 1 << bit);
                    if w3.len() < 3 {
                        break;
                    }
                }
                if w3.len() < 3 {
                    continue;
                }
                // w·e ≥ |w|/√3 inside the pyramid, and w ≠ 0 because x is off the plane.
                if w3.iter().any(|(w, _)| !(w.dot(e) > 0.0)) {
                    continue;
                }
                // A vertex cut on a pyramid plane lies on the chart's border u = ±1 or v = ±1
                // exactly: say so rather than keep the rounding of its construction. This
                // matters where x is close to the triangle's plane: a corner of the chart's
                // square inside the triangle is then reached by cutting segments between far
                // vertices, whose rounding (relative to their length) is large relative to
                // the corner's distance; the corner itself is known exactly.
                let poly: Poly = w3
                    .iter()
                    .map(|&(w, cut)| {
                        let mut uv = DVec2::new(w.dot(a), w.dot(b)) / w.dot(e);
                        for (bit, (axis, value)) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)]
                            .into_iter()
                            .enumerate()
                        {
                            if cut & (1 << bit) != 0 {
                                uv[axis] = value;
                            }
                        }
                        uv
                    })
                    .collect();
                // Inverse depth h = n·(e + u a + v b) / c.
                let z = DVec3::new(s.n.dot(a), s.n.dot(b), s.n.dot(e)) / s.c;
                if let Some(p) = Proj::new(i as u32, s.emitting, wanted(s), poly, z) {
                    polys.push(p);
                }
            }
            let view = View::new(polys, 0.0);
            view.visible(|p, pieces| {
                for piece in pieces {
                    let verts = piece
                        .iter()
                        .map(|uv| {
                            let w = e + uv.x * a + uv.y * b;
                            let h = p.depth(*uv);
                            // h > 0 inside the triangle's projection; the guard is for rounding
                            // only (the direction is what Lambert's formula needs).
                            if h > 0.0 { w / h } else { w }
                        })
                        .collect();
                    sink(Piece {
                        triangle: p.tri,
                        emitting: p.emitting,
                        verts,
                    });
                }
            });
        }
    }

    /// A triangle's plane relative to x, or None when the plane contains x (edge-on).
    fn seen(&self, t: &MeshTriangle, x: DVec3) -> Option<Seen> {
        let q = t.p.map(|p| p - x);
        let front = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
        let n = front.normalize_or_zero();
        let c = n.dot(q[0]);
        let far = q.iter().map(|q| q.length()).fold(0.0, f64::max);
        if !(c.abs() > EDGE_ON * far) || !far.is_finite() {
            return None;
        }
        // The side facing x is the front when x is on the front's side: front·(x − p0) > 0.
        let emitting = self.double_sided || c < 0.0;
        let (n, c) = if c < 0.0 { (-n, -c) } else { (n, c) };
        Some(Seen { n, c, emitting, q })
    }
}

/// A triangle projected in a chart.
struct Proj {
    tri: u32,
    emitting: bool,
    /// Whether its visible part is asked for (all projected triangles occlude).
    wanted: bool,
    poly: Poly,
    lines: Vec<Line>,
    /// Nearness z(u, v) = z.x u + z.y v + z.z, larger nearer the viewer.
    z: DVec3,
    /// max |z| over the polygon: the scale of its depth ties.
    zmax: f64,
    lo: DVec2,
    hi: DVec2,
}

impl Proj {
    /// None when the polygon is degenerate (no area) or not finite.
    fn new(tri: u32, emitting: bool, wanted: bool, mut poly: Poly, z: DVec3) -> Option<Proj> {
        poly.dedup();
        while poly.len() > 1 && poly[0] == poly[poly.len() - 1] {
            poly.pop();
        }
        let a2 = clip::area2(&poly);
        if poly.len() < 3 || !(a2 != 0.0) || !a2.is_finite() || !z.is_finite() {
            return None;
        }
        if a2 < 0.0 {
            poly.reverse();
        }
        let lines = clip::edge_lines(&poly);
        let (lo, hi) = clip::bounds(&poly);
        let mut p = Proj {
            tri,
            emitting,
            wanted,
            poly,
            lines,
            z,
            zmax: 0.0,
            lo,
            hi,
        };
        p.zmax = p.poly.iter().map(|&q| p.depth(q).abs()).fold(0.0, f64::max);
        Some(p)
    }

    fn depth(&self, q: DVec2) -> f64 {
        self.z.x * q.x + self.z.y * q.y + self.z.z
    }
}

/// What of a triangle j may hide a triangle i ([`View::hider`]).
enum Hider {
    /// All of proj(j) (its polygon and edge lines are the [`Proj`]'s).
    Whole,
    /// The part of proj(j) nearer than i, and its edge lines.
    Part(Poly, Vec<Line>),
}

/// The projected triangles of one chart.
struct View {
    polys: Vec<Proj>,
    /// The chart's length tolerance (see [`clip`]) and the smallest doubled area kept.
    tol: f64,
    tiny: f64,
    /// A floor under the depth scale of ties (the orthographic heights can all be near zero).
    zfloor: f64,
    /// The candidate grid: cells of the chart's bounding box, each listing the polygons whose
    /// boxes meet it.
    grid: Vec<Vec<u32>>,
    g: usize,
    glo: DVec2,
    cell: DVec2,
}

impl View {
    fn new(polys: Vec<Proj>, zfloor: f64) -> View {
        let (glo, ghi) = polys.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p.lo), hi.max(p.hi)),
        );
        let extent = if polys.is_empty() {
            0.0
        } else {
            (ghi - glo).max_element()
        };
        let tol = LENGTH_TOL * extent;
        // About one polygon per cell on average, and a bounded grid.
        let g = ((polys.len() as f64).sqrt().ceil() as usize).clamp(1, 256);
        let cell = ((ghi - glo) / g as f64).max(DVec2::splat(f64::MIN_POSITIVE));
        let mut view = View {
            polys,
            tol,
            tiny: tol * tol,
            zfloor,
            grid: vec![Vec::new(); g * g],
            g,
            glo,
            cell,
        };
        for (k, p) in view.polys.iter().enumerate() {
            let ((x0, y0), (x1, y1)) = view.cells(p);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    view.grid[y * g + x].push(k as u32);
                }
            }
        }
        view
    }

    /// The cell range a polygon's box covers (widened by the tolerance).
    fn cells(&self, p: &Proj) -> ((usize, usize), (usize, usize)) {
        let c = |v: DVec2| {
            let r = ((v - self.glo) / self.cell).floor();
            let clamp = |f: f64| (f.max(0.0) as usize).min(self.g - 1);
            (clamp(r.x), clamp(r.y))
        };
        (c(p.lo - self.tol), c(p.hi + self.tol))
    }

    /// The part of j that may hide i: proj(j) ∩ {j nearer than i}, or None.
    fn hider(&self, i: &Proj, j: &Proj) -> Option<Hider> {
        let d: Vec<f64> = j.poly.iter().map(|&q| j.depth(q) - i.depth(q)).collect();
        let tol = DEPTH_TOL * (i.zmax + j.zmax + self.zfloor);
        if d.iter().all(|v| v.abs() <= tol) {
            // Coplanar: the first in the slice is nearer (DESIGN.md M1).
            return (j.tri < i.tri).then_some(Hider::Whole);
        }
        match clip::split(&j.poly, &d, tol) {
            Side::Inside => Some(Hider::Whole),
            Side::Outside => None,
            Side::Split(nearer, _) => {
                let lines = clip::edge_lines(&nearer);
                Some(Hider::Part(nearer, lines))
            }
        }
    }

    /// Calls `sink` with each wanted polygon and its visible pieces (none when it is hidden).
    fn visible(&self, mut sink: impl FnMut(&Proj, &[Poly])) {
        let mut stamp = vec![usize::MAX; self.polys.len()];
        let mut cand: Vec<(f64, usize)> = Vec::new();
        let mut next: Vec<Poly> = Vec::new();
        for (i, pi) in self.polys.iter().enumerate() {
            if !pi.wanted {
                continue;
            }
            cand.clear();
            let ((x0, y0), (x1, y1)) = self.cells(pi);
            let centre = pi.poly.iter().copied().sum::<DVec2>() / pi.poly.len() as f64;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    for &k in &self.grid[y * self.g + x] {
                        let k = k as usize;
                        if k == i || stamp[k] == i {
                            continue;
                        }
                        stamp[k] = i;
                        let pk = &self.polys[k];
                        if pk.lo.cmple(pi.hi + self.tol).all()
                            && pk.hi.cmpge(pi.lo - self.tol).all()
                        {
                            cand.push((pk.depth(centre), k));
                        }
                    }
                }
            }
            // Nearest first: the big occluders in front usually hide the most, so the pieces
            // disappear before they fragment. The order changes nothing in the result.
            cand.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut pieces: Vec<Poly> = vec![pi.poly.clone()];
            for &(_, k) in &cand {
                let pk = &self.polys[k];
                let Some(hider) = self.hider(pi, pk) else {
                    continue;
                };
                let (hider, hider_lines) = match &hider {
                    Hider::Whole => (&pk.poly, &pk.lines),
                    Hider::Part(p, l) => (p, l),
                };
                let (hlo, hhi) = clip::bounds(hider);
                next.clear();
                for piece in pieces.drain(..) {
                    // Cheapest rejections first: boxes, then the hider's edges (no allocation),
                    // then the piece's own edges.
                    let (plo, phi) = clip::bounds(&piece);
                    let boxes_meet =
                        plo.cmple(hhi + self.tol).all() && phi.cmpge(hlo - self.tol).all();
                    if boxes_meet && clip::overlap(&piece, hider, hider_lines, self.tol) {
                        clip::subtract(piece, hider_lines, self.tol, self.tiny, &mut next);
                    } else {
                        next.push(piece);
                    }
                }
                std::mem::swap(&mut pieces, &mut next);
                if pieces.is_empty() {
                    break;
                }
            }
            if !pieces.is_empty() {
                sink(pi, &pieces);
            }
        }
    }
}

/// Sutherland–Hodgman against one plane through the origin: the part of the convex polygon
/// where m·w ≥ 0. Each vertex carries a set of planes (bits): a vertex made on this plane gets
/// `bit` and the planes its segment's two ends share (the planes the segment lies in).
fn clip3(p: &[(DVec3, u8)], m: DVec3, bit: u8) -> Vec<(DVec3, u8)> {
    let mut out = Vec::with_capacity(p.len() + 1);
    for k in 0..p.len() {
        let ((a, ma), (b, mb)) = (p[k], p[(k + 1) % p.len()]);
        let (da, db) = (m.dot(a), m.dot(b));
        if da >= 0.0 {
            out.push((a, ma));
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            out.push((a + (b - a) * (da / (da - db)), (ma & mb) | bit));
        }
    }
    out
}

/// [`polygon_irradiance`] with the vertex list rotated so that its orientation test (the sign
/// of the first corner's turn against q0) is made at the sharpest corner: a piece can have a
/// corner that is nearly straight (a cut through a vertex), where that sign is rounding.
fn lambert(q: &[DVec3], n: DVec3) -> f64 {
    let m = q.len();
    if m < 3 {
        return 0.0;
    }
    let turn = |k: usize| {
        let (a, b, c) = (q[k], q[(k + 1) % m], q[(k + 2) % m]);
        (b - a).cross(c - b).dot(a).abs()
    };
    let best = (0..m)
        .max_by(|&a, &b| turn(a).total_cmp(&turn(b)))
        .unwrap_or(0);
    if best == 0 {
        return polygon_irradiance(q, n);
    }
    let rotated: Vec<DVec3> = q[best..].iter().chain(&q[..best]).copied().collect();
    polygon_irradiance(&rotated, n)
}

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
#[allow(dead_code)]
pub(crate) fn integrate_piece(
    verts: &[DVec3],
    n: DVec3,
    rel: f64,
    f: &mut impl FnMut(DVec3) -> DVec3,
) -> DVec3 {
    /// A bound on the work: cells (each 28 evaluations of f when made).
    const MAX_CELLS: usize = 20_000;
    let poly: Vec<(DVec3, u8)> = verts.iter().map(|&q| (q, 0)).collect();
    let units: Vec<DVec3> = clip3(&poly, n, 0)
        .iter()
        .filter_map(|(q, _)| q.try_normalize())
        .collect();
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
