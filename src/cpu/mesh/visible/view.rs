//! One chart's projected triangles and what each hides of the others (the parent module's
//! "Method" and "Cost"): the grid of candidate occluders, the exact rejections, and the
//! subtraction that leaves each triangle's visible pieces.

use super::clip::{Line, Pieces, Poly, Scratch, Side, Small};
use super::*;

/// A triangle projected in a chart.
pub(super) struct Proj {
    pub(super) tri: u32,
    pub(super) emitting: bool,
    /// Whether its visible part is asked for (all projected triangles occlude).
    pub(super) wanted: bool,
    pub(super) poly: Poly,
    pub(super) lines: Small<Line, 8>,
    /// Nearness z(u, v) = z.x u + z.y v + z.z, larger nearer the viewer.
    pub(super) z: DVec3,
    /// max |z| over the polygon: the scale of its depth ties.
    pub(super) zmax: f64,
    pub(super) lo: DVec2,
    pub(super) hi: DVec2,
}

impl Proj {
    /// None when the polygon is degenerate (no area) or not finite.
    pub(super) fn new(
        tri: u32,
        emitting: bool,
        wanted: bool,
        mut poly: Poly,
        z: DVec3,
    ) -> Option<Proj> {
        // Repeated vertices out (Vec::dedup), then a last one equal to the first.
        let mut m = 0;
        let v = poly.as_mut_slice();
        for k in 0..v.len() {
            if m == 0 || v[k] != v[m - 1] {
                v[m] = v[k];
                m += 1;
            }
        }
        poly.retain_first(m);
        while poly.len() > 1 && poly[0] == poly[poly.len() - 1] {
            poly.pop();
        }
        let a2 = clip::area2(&poly);
        if poly.len() < 3 || !(a2 != 0.0) || !a2.is_finite() || !z.is_finite() {
            return None;
        }
        if a2 < 0.0 {
            poly.as_mut_slice().reverse();
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

    pub(super) fn depth(&self, q: DVec2) -> f64 {
        self.z.x * q.x + self.z.y * q.y + self.z.z
    }
}

/// What of a triangle j may hide a triangle i ([`View::hider`]). Made for a few candidates
/// only, so its size does not matter.
#[allow(clippy::large_enum_variant)]
enum Hider {
    /// All of proj(j) (its polygon and edge lines are the [`Proj`]'s).
    Whole,
    /// The part of proj(j) nearer than i, and its edge lines.
    Part(Poly, Small<Line, 8>),
}

/// A polygon in a cell of the grid, its box kept with it (the scan of a cell reads no
/// polygon).
#[derive(Clone, Copy)]
struct Member {
    lo: DVec2,
    hi: DVec2,
    k: u32,
}

/// A polygon's depth function and its scale ([`Proj::z`], [`Proj::zmax`]).
#[derive(Clone, Copy)]
struct Depth {
    z: DVec3,
    zmax: f64,
}

/// The projected triangles of one chart.
pub(super) struct View {
    polys: Vec<Proj>,
    /// Their depths, in a compact array (read for every candidate).
    depths: Vec<Depth>,
    /// The chart's length tolerance (see [`clip`]) and the smallest doubled area kept.
    tol: f64,
    tiny: f64,
    /// A floor under the depth scale of ties (the orthographic heights can all be near zero).
    zfloor: f64,
    /// The candidate grid: cells of the chart's bounding box, cell c listing the polygons
    /// whose boxes meet it in `members[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    members: Vec<Member>,
    g: usize,
    glo: DVec2,
    cell: DVec2,
}

impl View {
    pub(super) fn new(polys: Vec<Proj>, zfloor: f64) -> View {
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
        // Cells about the size of a typical polygon (the median of the boxes' larger sides):
        // a polygon then meets a few cells and a cell a few polygons. A bounded grid.
        let mut sizes: Vec<f64> = polys.iter().map(|p| (p.hi - p.lo).max_element()).collect();
        let typical = if sizes.is_empty() {
            0.0
        } else {
            let mid = sizes.len() / 2;
            *sizes.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let g = if typical > 0.0 && extent.is_finite() {
            ((extent / typical).ceil().min(256.0) as usize).max(1)
        } else {
            1
        };
        let cell = ((ghi - glo) / g as f64).max(DVec2::splat(f64::MIN_POSITIVE));
        let depths = polys
            .iter()
            .map(|p| Depth {
                z: p.z,
                zmax: p.zmax,
            })
            .collect();
        let mut view = View {
            polys,
            depths,
            tol,
            tiny: tol * tol,
            zfloor,
            start: vec![0; g * g + 1],
            members: Vec::new(),
            g,
            glo,
            cell,
        };
        // Counting sort of (cell, polygon) pairs: counts, prefix sums, then the members.
        for p in &view.polys {
            let ((x0, y0), (x1, y1)) = view.cells(p.lo, p.hi);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    view.start[y * g + x + 1] += 1;
                }
            }
        }
        for c in 0..g * g {
            view.start[c + 1] += view.start[c];
        }
        let mut fill: Vec<u32> = view.start[..g * g].to_vec();
        view.members = vec![
            Member {
                lo: DVec2::ZERO,
                hi: DVec2::ZERO,
                k: 0
            };
            view.start[g * g] as usize
        ];
        for (k, p) in view.polys.iter().enumerate() {
            let ((x0, y0), (x1, y1)) = view.cells(p.lo, p.hi);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let f = &mut fill[y * g + x];
                    view.members[*f as usize] = Member {
                        lo: p.lo,
                        hi: p.hi,
                        k: k as u32,
                    };
                    *f += 1;
                }
            }
        }
        view
    }

    /// The cell of a point (clamped to the grid).
    fn cell_of(&self, v: DVec2) -> (usize, usize) {
        // Truncation is the floor on the non-negative values kept (and NaN goes to 0).
        let r = (v - self.glo) / self.cell;
        let clamp = |f: f64| (f.max(0.0) as usize).min(self.g - 1);
        (clamp(r.x), clamp(r.y))
    }

    /// The cell range a box covers (widened by the tolerance).
    fn cells(&self, lo: DVec2, hi: DVec2) -> ((usize, usize), (usize, usize)) {
        (self.cell_of(lo - self.tol), self.cell_of(hi + self.tol))
    }

    /// The depth tolerance of ties between i and j.
    fn ztol(&self, i: &Proj, j: &Proj) -> f64 {
        DEPTH_TOL * (i.zmax + j.zmax + self.zfloor)
    }

    /// The part of j that may hide i: proj(j) ∩ {j nearer than i}, or None.
    fn hider(&self, i: &Proj, j: &Proj) -> Option<Hider> {
        let mut d = [0.0; 8];
        for (d, &q) in d.iter_mut().zip(j.poly.iter()) {
            *d = j.depth(q) - i.depth(q);
        }
        let d = &d[..j.poly.len()];
        let tol = self.ztol(i, j);
        if d.iter().all(|v| v.abs() <= tol) {
            // Coplanar: the first in the slice is nearer (DESIGN.md M1).
            return (j.tri < i.tri).then_some(Hider::Whole);
        }
        let mut nearer = Poly::default();
        match clip::split(&j.poly, d, tol, &mut nearer, &mut clip::Drop) {
            Side::Inside => Some(Hider::Whole),
            Side::Outside => None,
            Side::Split => {
                let lines = clip::edge_lines(&nearer);
                Some(Hider::Part(nearer, lines))
            }
        }
    }

    /// Whether j (its box and depth given: read from compact arrays, not from the large
    /// [`Proj`]) is farther than i by more than twice their tie tolerance all over the box
    /// where their boxes (widened by the length tolerance) meet: then no part of j nearer than
    /// i, even up to the tolerance, meets proj(i), and j hides nothing of it. The depth
    /// difference is affine, so its largest value over the box is at a corner.
    fn behind(&self, i: &Proj, j: &Member, jz: &Depth) -> bool {
        let lo = i.lo.max(j.lo) - self.tol;
        let hi = i.hi.min(j.hi) + self.tol;
        let dz = jz.z - i.z;
        let top = dz.z + (dz.x * lo.x).max(dz.x * hi.x) + (dz.y * lo.y).max(dz.y * hi.y);
        top < -2.0 * DEPTH_TOL * (i.zmax + jz.zmax + self.zfloor)
    }

    /// Calls `per` with each wanted polygon and its visible pieces (not when it is hidden),
    /// and returns what it appended to its output, in the polygons' order. The polygons are
    /// shared out in fixed chunks among rayon's threads, and the outputs put back in order:
    /// the result does not depend on the number of threads.
    pub(super) fn visible<R: Send>(
        &self,
        per: impl Fn(&Proj, &Pieces, &mut Bufs, &mut Vec<R>) + Sync,
    ) -> impl Iterator<Item = R> {
        /// Polygons per chunk: enough to make a chunk's work large beside its scheduling.
        const CHUNK: usize = 256;
        let n = self.polys.len();
        let chunks: Vec<Vec<R>> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map_init(
                || Work::new(n),
                |w, c| {
                    let mut out = Vec::new();
                    for i in c * CHUNK..n.min((c + 1) * CHUNK) {
                        let pi = &self.polys[i];
                        if pi.wanted && self.visible_one(i, w) {
                            per(pi, &w.pieces, &mut w.bufs, &mut out);
                        }
                    }
                    out
                },
            )
            .collect();
        chunks.into_iter().flatten()
    }

    /// The visible pieces of polygon i, in `w.pieces`; false when it is hidden.
    fn visible_one(&self, i: usize, w: &mut Work) -> bool {
        let Work {
            cand,
            stamp,
            pieces,
            next,
            scratch,
            ..
        } = w;
        let pi = &self.polys[i];
        {
            cand.clear();
            let (ilo, ihi) = (pi.lo - self.tol, pi.hi + self.tol);
            let ((x0, y0), (x1, y1)) = self.cells(pi.lo, pi.hi);
            let centre = pi.poly.iter().copied().sum::<DVec2>() / pi.poly.len() as f64;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let c = y * self.g + x;
                    for m in &self.members[self.start[c] as usize..self.start[c + 1] as usize] {
                        let k = m.k;
                        // Non-short-circuit: one branch, rarely taken, instead of four.
                        let meet = (m.lo.x <= ihi.x)
                            & (m.lo.y <= ihi.y)
                            & (m.hi.x >= ilo.x)
                            & (m.hi.y >= ilo.y);
                        if !meet || k as usize == i {
                            continue;
                        }
                        if stamp[k as usize] == i as u32 {
                            continue;
                        }
                        stamp[k as usize] = i as u32;
                        if self.behind(pi, m, &self.depths[k as usize]) {
                            continue;
                        }
                        let pk = &self.polys[k as usize];
                        // The pieces lie in proj(i) and a hider in proj(k): when an edge line
                        // of either separates the two (up to the tolerance) k hides nothing.
                        if clip::separated(&pi.poly, &pi.lines, &pk.poly, &pk.lines, self.tol) {
                            continue;
                        }
                        cand.push((pk.depth(centre), k));
                    }
                }
            }
            // Nearest first: the big occluders in front usually hide the most, so the pieces
            // disappear before they fragment. The order changes nothing in the result.
            cand.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            pieces.clear();
            pieces.push(&pi.poly);
            let (mut plo, mut phi) = (pi.lo, pi.hi);
            for &(_, k) in cand.iter() {
                let pk = &self.polys[k as usize];
                // Nothing left where pk is.
                if !(pk.lo.cmple(phi + self.tol).all() && pk.hi.cmpge(plo - self.tol).all()) {
                    continue;
                }
                let Some(hider) = self.hider(pi, pk) else {
                    continue;
                };
                let (hider, hider_lines) = match &hider {
                    Hider::Whole => (&pk.poly, &pk.lines),
                    Hider::Part(p, l) => (p, l),
                };
                let (hlo, hhi) = clip::bounds(hider);
                next.clear();
                for n in 0..pieces.len() {
                    // Cheapest rejections first: boxes, then the hider's edges (no allocation),
                    // then the piece's own edges.
                    let (piece, lo, hi) = pieces.get(n);
                    let boxes_meet =
                        lo.cmple(hhi + self.tol).all() && hi.cmpge(hlo - self.tol).all();
                    if boxes_meet && clip::overlap(piece, hider, hider_lines, self.tol) {
                        clip::subtract(piece, hider_lines, self.tol, self.tiny, next, scratch);
                    } else {
                        next.push(piece);
                    }
                }
                std::mem::swap(pieces, next);
                if pieces.is_empty() {
                    break;
                }
                (plo, phi) = pieces.bounds();
            }
            !pieces.is_empty()
        }
    }
}

/// Buffers for the callers' use in [`View::visible`].
#[derive(Default)]
pub(super) struct Bufs {
    pub(super) verts: Vec<DVec3>,
    pub(super) lambert: Vec<DVec3>,
}

/// A thread's scratch in [`View::visible`].
struct Work {
    cand: Vec<(f64, u32)>,
    /// stamp[k] = i when polygon k has been met already as a candidate of polygon i.
    stamp: Vec<u32>,
    pieces: Pieces,
    next: Pieces,
    scratch: Scratch,
    bufs: Bufs,
}

impl Work {
    fn new(n: usize) -> Work {
        Work {
            cand: Vec::new(),
            stamp: vec![u32::MAX; n],
            pieces: Pieces::default(),
            next: Pieces::default(),
            scratch: Scratch::default(),
            bufs: Bufs::default(),
        }
    }
}
