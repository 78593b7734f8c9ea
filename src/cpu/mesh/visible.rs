//! The visible parts of a mesh light's triangles (DESIGN.md §7 M3), with the mesh's
//! self-occlusion, exactly: seen from a point x (what irradiance integrates) or from a
//! direction at infinity (what intensity integrates).
//!
//! # Method
//! Everything happens in a *chart*, a plane in which every triangle's visible-set question is
//! 2-D and every triangle is a convex polygon:
//! - from a point x, the six faces of a cube map around x, each the gnomonic (central)
//!   projection (u, v) = (w·a / w·e, w·b / w·e) of the directions w with w in the face's pyramid
//!   |w·a|, |w·b| ≤ w·e. The gnomonic projection maps great circles to straight lines (it is the
//!   central projection onto the plane w·e = 1), so a triangle, clipped first in 3-D to the
//!   pyramid (Sutherland–Hodgman against the pyramid's four planes through x), is a convex
//!   polygon in the chart, and a chart point (u, v) is the direction e + u a + v b;
//! - from a direction ω at infinity, the orthographic projection on the plane ⟂ ω.
//!
//! Depth along the line of sight through a chart point is, for each triangle's plane, such that
//! "triangle j is nearer than triangle i" is a half-plane of the chart:
//! - perspective: the ray t w meets the plane n·y = c (n the unit normal turned so that c > 0)
//!   at t = c / (n·w), so its inverse depth h = (n·w)/c is affine in (u, v) and j is nearer
//!   than i where h_j − h_i > 0;
//! - orthographic: the point of the plane over (u, v) has height s = (c − n·(u a + v b)) / (n·ω)
//!   along ω, affine in (u, v), and j is nearer to the observer at +∞ω where s_j − s_i > 0.
//!
//! So the part of i hidden by j is the convex polygon proj(i) ∩ proj(j) ∩ {j nearer}, and
//! visible(i) = proj(i) minus the union over j of those: exact whatever the depth order, also
//! for interpenetrating or cyclically overlapping triangles. Subtracting a convex polygon from
//! a convex one leaves convex pieces (clip by each of the subtrahend's edge lines in turn,
//! [`clip::subtract`]). Where two triangles are coplanar and overlap, the one that comes first
//! in the slice is nearer (DESIGN.md M1: face order, then fan order, is the slice's order).
//! Candidate occluders come from a uniform grid over the chart's bounding boxes, not from all
//! pairs.
//!
//! A visible piece's chart vertices map back to 3-D on its triangle (the ray's hit point), so a
//! piece is a convex planar polygon given as vectors from x, and Lambert's formula
//! ([`polygon_irradiance`]: Lambert 1760; Arvo 1995, "Applications of irradiance tensors",
//! with the horizon clip) gives its cosine-weighted solid angle in closed form.
//!
//! Sources: the gnomonic projection, Snyder 1987, "Map Projections — A Working Manual", §22;
//! polygon clipping, Sutherland & Hodgman 1974, "Reentrant polygon clipping"; the separating
//! axis test for convex polygons, Gottschalk, Lin & Manocha 1996 (OBBTree), in 2-D.
//!
//! # Numbers
//! - A triangle whose plane passes within [`EDGE_ON`] (relative) of x is skipped: it subtends
//!   no solid angle, hides nothing of positive measure, and its depth 1/c would be rounding.
//!   This is what makes receivers on the mesh (a floor touching it) finite.
//! - Lengths in a chart below [`LENGTH_TOL`] of the chart's extent, and depth differences below
//!   [`DEPTH_TOL`] of the depths, count as zero (ties): see [`clip`]. Each moves a result by
//!   at most that fraction of a piece's size, far below the 1e-9 target.
//! - A chart vertex cut on a pyramid plane is put exactly on the chart's border (see
//!   [`clip3`]); without that, x close to a large triangle lost ~1e-8 (measured).
//!
//! # Cost
//! Per chart, each triangle is compared with the triangles whose boxes meet its box (a grid
//! over the chart, cells the size of the median polygon's box). Before a candidate j is made a
//! hider of i, two exact rejections that the subtraction would reach anyway, at the cost of a
//! few products: j farther than i all over their boxes' meet (the depth difference is affine,
//! so its maximum is at a corner: j nearer nowhere there, even by the tie tolerance), and an
//! edge line of i or j that separates the two polygons (the pieces lie in proj(i), a hider in
//! proj(j), so nothing would overlap). On a smooth mesh these leave about 2 % of the box
//! neighbours (the edge-sharing ones are separated by their common edge). Nothing is
//! allocated per candidate or piece: polygons and edge lines are in place (a triangle clipped
//! by the pyramid has at most 7 vertices), pieces share one buffer. The six charts, and each
//! chart's triangles in fixed chunks, run in parallel (rayon); the results are put back in
//! order, so sums are the same whatever the number of threads.
//!
//! The pieces of one triangle are disjoint convex unions of cells of the arrangement of the
//! lines that cut it (its occluders' edges and depth lines), so with m occluders there are
//! O(m²) of them at most, whatever the overlap: the memory is bounded by the worst triangle's
//! arrangement, and nothing can fail. Measured (benches/mesh_light.rs, 2 cores): the
//! 100,000-triangle torus at one receiver in 25–55 ms depending on the machine's load, 2.5–4×
//! the module before this work (results bit-identical).

mod clip;
#[cfg(test)]
mod integrate;
#[cfg(test)]
mod tests;
mod view;
#[cfg(test)]
pub(crate) use integrate::integrate_piece;

use crate::cpu::irradiance::closed::polygon_irradiance;
use crate::model::MeshTriangle;
use clip::{Poly, Small};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use view::{Proj, View};

/// Which sides emit.
pub(crate) struct Surface<'a> {
    pub triangles: &'a [MeshTriangle],
    pub double_sided: bool,
}

/// A visible part of one triangle as seen from x: its vertices as vectors from x (points of the
/// triangle: convex, planar, in order), the triangle's index in the slice, and whether the side
/// seen emits.
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    pub triangle: u32,
    /// Whether the side seen emits: the callers ask for emitting pieces only
    /// ([`Surface::emitting_above`]); the tests read it from [`Surface::visible_from`]'s.
    #[cfg_attr(not(test), allow(dead_code))]
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
pub(crate) const EDGE_ON: f64 = 1e-12;

/// Chart lengths below this fraction of the chart's extent count as zero (see [`clip`]).
const LENGTH_TOL: f64 = 1e-13;

/// Depth differences below this fraction of the depths count as ties (coplanar triangles).
const DEPTH_TOL: f64 = 1e-12;

impl Surface<'_> {
    /// Every visible piece of the surface seen from x (both emitting and not), self-occlusion
    /// exact: what the tests check coverage with (the queries need only
    /// [`Surface::emitting_above`]).
    #[cfg(test)]
    pub(crate) fn visible_from(&self, x: DVec3) -> Vec<Piece> {
        self.collect_pieces(x, |_| true, |_| true)
    }

    /// The visible pieces seen from x of the emitting triangles with a point above the
    /// horizon of the unit normal n: what irradiance integrates. A triangle wholly below the
    /// horizon is left out as an occluder too: it can hide only directions below the horizon.
    pub(crate) fn emitting_above(&self, x: DVec3, n: DVec3) -> Vec<Piece> {
        let above = |s: &Seen| s.q.iter().any(|q| n.dot(*q) > 0.0);
        self.collect_pieces(x, |s| s.emitting && above(s), above)
    }

    /// The visible pieces of the triangles `wanted` accepts, hidden by those `occludes` accepts
    /// ([`Surface::pieces_from`]), as [`Piece`]s.
    fn collect_pieces(
        &self,
        x: DVec3,
        wanted: impl Fn(&Seen) -> bool + Sync,
        occludes: impl Fn(&Seen) -> bool + Sync,
    ) -> Vec<Piece> {
        let mut out = Vec::new();
        self.pieces_from(
            x,
            wanted,
            occludes,
            |triangle, emitting, verts, _, out| {
                out.push(Piece {
                    triangle,
                    emitting,
                    verts: verts.to_vec(),
                })
            },
            |piece| out.push(piece),
        );
        out
    }

    /// Unit-radiance irradiance at x for the unit receiver normal n: the sum over the visible
    /// emitting pieces of Lambert's formula clipped at the horizon (the unshaped M3 irradiance
    /// over L).
    pub(crate) fn cosine_solid_angle(&self, x: DVec3, n: DVec3) -> f64 {
        let mut sum = 0.0;
        // Only emitting triangles with a vertex above the horizon can add anything; the others
        // are computed only as occluders.
        let above = |s: &Seen| s.q.iter().any(|q| n.dot(*q) > 0.0);
        let wanted = |s: &Seen| s.emitting && above(s);
        // A triangle wholly below the horizon hides only directions below it: left out.
        self.pieces_from(
            x,
            wanted,
            above,
            |_, emitting, verts, buf, out| {
                if emitting {
                    out.push(lambert(verts, n, buf))
                }
            },
            |l| sum += l,
        );
        sum
    }

    /// The emitting area visible from direction w at infinity, projected on the plane ⟂ w
    /// (intensity(w) / L(w)). w need not be normalised; zero gives zero.
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
            let mut poly = Poly::default();
            for &p in &t.p {
                poly.add(DVec2::new((p - o).dot(a), (p - o).dot(b)));
            }
            // Height over (u, v): s = (n·(p0 − o) − u n·a − v n·b) / (n·w).
            let z = DVec3::new(-nhat.dot(a), -nhat.dot(b), nhat.dot(t.p[0] - o)) / nw;
            if let Some(p) = Proj::new(i as u32, emitting, emitting, poly, z) {
                polys.push(p);
            }
        }
        let view = View::new(polys, extent);
        let mut area = 0.0;
        for a in view.visible(|_, pieces, _, out| {
            out.push(pieces.iter().map(|p| 0.5 * clip::area2(p)).sum::<f64>())
        }) {
            area += a;
        }
        area
    }

    /// Calls `map` with every visible piece seen from x of the triangles `wanted` accepts (its
    /// triangle, whether the side seen emits, its vertices as vectors from x, and a buffer),
    /// in parallel, and `sink` with what it appended to its output, in order; the triangles
    /// `occludes` accepts hide them (a wanted triangle must be one).
    fn pieces_from<R: Send>(
        &self,
        x: DVec3,
        wanted: impl Fn(&Seen) -> bool + Sync,
        occludes: impl Fn(&Seen) -> bool + Sync,
        map: impl Fn(u32, bool, &[DVec3], &mut Vec<DVec3>, &mut Vec<R>) + Sync,
        sink: impl FnMut(R),
    ) {
        let seen: Vec<Option<Seen>> = self
            .triangles
            .par_iter()
            .with_min_len(4096)
            .map(|t| self.seen(t, x).filter(&occludes))
            .collect();
        // The six charts in parallel (each its triangles in chunks in parallel too), their
        // results put back in the charts' order.
        let charts: Vec<Vec<R>> = FACES
            .par_iter()
            .map(|&face| self.chart(&seen, face, &wanted, &map))
            .collect();
        charts.into_iter().flatten().for_each(sink);
    }

    /// [`Surface::pieces_from`] in one chart: what `map` made of each visible piece, in order.
    fn chart<R: Send>(
        &self,
        seen: &[Option<Seen>],
        [e, a, b]: [DVec3; 3],
        wanted: &(impl Fn(&Seen) -> bool + Sync),
        map: &(impl Fn(u32, bool, &[DVec3], &mut Vec<DVec3>, &mut Vec<R>) + Sync),
    ) -> Vec<R> {
        {
            // The pyramid's four planes through x, inside where m·w ≥ 0.
            let planes = [e - a, e + a, e - b, e + b];
            let inside: Vec<u32> = seen
                .iter()
                .enumerate()
                .filter_map(|(i, s)| {
                    let s = s.as_ref()?;
                    let out = planes.iter().any(|m| s.q.iter().all(|q| m.dot(*q) < 0.0));
                    (!out).then_some(i as u32)
                })
                .collect();
            // Sized at once: a Proj is large (its polygon and lines in place), and growing
            // the buffer would copy them.
            let mut polys = Vec::with_capacity(inside.len());
            for &i in &inside {
                let i = i as usize;
                let Some(s) = &seen[i] else { continue };
                // Each vertex carries the set of pyramid planes it was cut on (see clip3).
                let mut w3 = Clip3::default();
                for &q in &s.q {
                    w3.add((q, 0));
                }
                for (bit, m) in planes.iter().enumerate() {
                    // Most triangles lie inside most of the planes: nothing to cut.
                    if w3.iter().all(|(w, _)| m.dot(*w) >= 0.0) {
                        continue;
                    }
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
                let mut poly = Poly::default();
                for &(w, cut) in w3.iter() {
                    let mut uv = DVec2::new(w.dot(a), w.dot(b)) / w.dot(e);
                    for (bit, (axis, value)) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)]
                        .into_iter()
                        .enumerate()
                    {
                        if cut & (1 << bit) != 0 {
                            uv[axis] = value;
                        }
                    }
                    poly.add(uv);
                }
                // Inverse depth h = n·(e + u a + v b) / c.
                let z = DVec3::new(s.n.dot(a), s.n.dot(b), s.n.dot(e)) / s.c;
                if let Some(p) = Proj::new(i as u32, s.emitting, wanted(s), poly, z) {
                    polys.push(p);
                }
            }
            let view = View::new(polys, 0.0);
            let results = view.visible(|p, pieces, bufs, out| {
                for piece in pieces.iter() {
                    bufs.verts.clear();
                    bufs.verts.extend(piece.iter().map(|uv| {
                        let w = e + uv.x * a + uv.y * b;
                        let h = p.depth(*uv);
                        // h > 0 inside the triangle's projection; the guard is for rounding
                        // only (the direction is what Lambert's formula needs).
                        if h > 0.0 { w / h } else { w }
                    }));
                    map(p.tri, p.emitting, &bufs.verts, &mut bufs.lambert, out);
                }
            });
            results.collect()
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

/// At most 7 vertices (a triangle clipped by four planes), each with its set of planes.
type Clip3 = Small<(DVec3, u8), 8>;

/// Sutherland–Hodgman against one plane through the origin: the part of the convex polygon
/// where m·w ≥ 0. Each vertex carries a set of planes (bits): a vertex made on this plane gets
/// `bit` and the planes its segment's two ends share (the planes the segment lies in).
fn clip3(p: &[(DVec3, u8)], m: DVec3, bit: u8) -> Clip3 {
    let mut out = Clip3::default();
    clip3_into(p, m, bit, |v| out.add(v));
    out
}

/// [`clip3`] for any number of vertices, each vertex of the result given to `out` in order.
fn clip3_into(p: &[(DVec3, u8)], m: DVec3, bit: u8, mut out: impl FnMut((DVec3, u8))) {
    for k in 0..p.len() {
        let ((a, ma), (b, mb)) = (p[k], p[(k + 1) % p.len()]);
        let (da, db) = (m.dot(a), m.dot(b));
        if da >= 0.0 {
            out((a, ma));
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            out((a + (b - a) * (da / (da - db)), (ma & mb) | bit));
        }
    }
}

/// [`polygon_irradiance`] with the vertex list rotated so that its orientation test (the sign
/// of the first corner's turn against q0) is made at the sharpest corner: a piece can have a
/// corner that is nearly straight (a cut through a vertex), where that sign is rounding.
fn lambert(q: &[DVec3], n: DVec3, buf: &mut Vec<DVec3>) -> f64 {
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
    buf.clear();
    buf.extend(q[best..].iter().chain(&q[..best]));
    polygon_irradiance(buf, n)
}
