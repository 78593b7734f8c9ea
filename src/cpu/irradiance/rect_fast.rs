//! Fast irradiance of a textured rect at a loose tolerance (issue 24 item 4), f64, CPU only.
//!
//! The reference (`rect_texture`, DESIGN.md §6 "RectLight texture" and "Dome and texture
//! irradiance: what 'exact' means") splits the chart quadrature at every texel line: ~2M smooth
//! pieces for a 2048 × 1024 texture, ~50 s per receiver. This path computes the same integral,
//! `E = L ∫∫ t(X, Y) · K(X, Y) dX dY` with `K = S(−ŵ)·max(0, n·w)·J/|w|⁴` (everything but the
//! texture t, see `cpu::irradiance`), to a relative tolerance `rel` ≥ [`MIN_TOLERANCE`]:
//!
//! - Linearity in the texture: on a chart rectangle R with the 3 × 3 Gauss–Legendre points
//!   `x_ab` of R and the tensor Lagrange basis `ℓ_ab` on them, `∫_R t·K ≈ ∫_R t·I(K) =
//!   Σ_ab K(x_ab)·W_ab` with the texture's *Lagrange moments* `W_ab = ∫_R t·ℓ_ab`. They are exact
//!   integrals of the interpolant actually used (DESIGN.md "what 'exact' means"): t is bilinear
//!   (or constant) on each texel piece (`prepare::texture::axis_pieces`) and ℓ_ab biquadratic,
//!   so the 3-point Gauss–Legendre rule of each piece (exact to degree 5 per axis) integrates
//!   `t·ℓ_ab` exactly. A parent's moments follow exactly from its children's, because the
//!   parent's ℓ restricted to a child is the child's biquadratic interpolant of it:
//!   `W^P_ab = Σ_children Σ_cd W^C_cd ℓ^P_ab(x^C_cd)`. The moments of a quadtree over the texel
//!   pieces (blocks of ≤ [`LEAF_PIECES`] pieces at its leaves) are built once per texture
//!   ([`tree`], lazily, in the texture's `irradiance` slot); below a leaf they are computed on
//!   the fly from the pieces, and below one piece from the piece's Gauss points (a sub-rect of
//!   a piece: `W_ab = Σ gauss weight · t · ℓ_ab`).
//! - Per receiver, globally adaptive subdivision of that tree (QUADPACK `qag` in 2-D, Piessens
//!   et al. 1983, with the moment rule of a cell as the basic rule): every active cell carries
//!   the sum of its children's rules as its value and `|Σ children − own rule|` as its error
//!   estimate; the cell with the largest error is replaced by its children until the summed
//!   error is below `rel/8` of the summed value in every channel. Cells continue below texel
//!   pieces (quadrants of a piece), so the near-field peak is resolved by subdivision.
//! - Where K is not smooth the moment rule is not used: a cell the receiver's horizon crosses
//!   (K's kink `max(0, n·w)`, a line of the chart) or that a shaping kink may cross (cone edge,
//!   smoothstep start, focus plane: `Prepared::profile`) is integrated by
//!   [`Kernel::clipped`], a 5 × 5 Gauss rule on the part in front of the horizon whose lines
//!   are split at the shaping's kinks (the roots `line::line_integral` splits at), with t
//!   sampled; no rule point then lies where K = 0, so no lit sliver goes unseen. Subdivision
//!   goes on below pieces until the estimates meet the tolerance.
//! - Guard against a peak no rule point sees: a cell is split without being trusted while its
//!   world half-diagonal R exceeds half the lower bound `|w_c| − R` of its distance from x
//!   (FMM's well-separated criterion), unless the receiver's horizon hides all of it.
//!
//! Threshold ([`MIN_TOLERANCE`], `Rule::texture_tolerance`): `Adaptive::for_tolerance(rel)`
//! with rel ≥ 1e-4 (the CLI's and Python's default) takes this path; tighter tolerances and the
//! reference (`Adaptive::REFERENCE`, 1e-9) keep the exact split path unchanged. At 1e-5 the
//! estimates were measured to miss by 2–4× (1.9e-5 unshaped nearest, 3.6e-5 shaped).
//!
//! What this does not prove: the error estimate is a-posteriori (as the reference's
//! Gauss–Kronrod estimates are), not an a-priori bound; the tests measure the result against
//! the 1e-9 reference on random textures (sizes to 64 × 32 in the default run, 256 × 128 with
//! `--ignored`), shaped and unshaped, near, grazing and far receivers. [`applies`] leaves IES
//! profiles and sharp cone edges to the exact path.

use std::collections::BinaryHeap;
use std::sync::Arc;

use glam::DVec3;

use super::chart::Chart;
use crate::cpu::roots::{axis_approach, cone_roots_on_line};
use crate::cpu::shaping::shaping;
use crate::prepare::Kink;
use crate::prepare::Prepared;
use crate::prepare::texture::{AxisPiece, Filter, Image, RectTexture, axis_pieces};

/// The tightest tolerance the fast path takes: below it
/// (`Adaptive::for_tolerance` of 1e-9 to 1e-6, and the reference) the exact split path runs.
pub const MIN_TOLERANCE: f64 = 1e-4;

/// A leaf of the stored tree holds at most this many texel pieces (4 × 4): the tree of a
/// 2048 × 1024 texture then has ~175k nodes (~50 MB).
pub const LEAF_PIECES: u32 = 16;

/// At most this many cells are split per receiver (then the current sum is returned).
const MAX_SPLITS: usize = 2_000_000;

/// 3-point Gauss–Legendre on [−1, 1] (A&S 25.4.29).
const A: f64 = 0.774_596_669_241_483_4;
const GX: [f64; 3] = [-A, 0.0, A];
const GW: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];

/// 5-point Gauss–Legendre on [−1, 1] (A&S 25.4.29).
const G5X: [f64; 5] = [
    -0.906_179_845_938_664,
    -0.538_469_310_105_683,
    0.0,
    0.538_469_310_105_683,
    0.906_179_845_938_664,
];
const G5W: [f64; 5] = [
    0.236_926_885_056_189_1,
    0.478_628_670_499_366_5,
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
];

/// The Lagrange basis on the nodes `GX`, at u (node coordinates in [−1, 1]).
#[inline]
fn lagrange(u: f64) -> [f64; 3] {
    let a2 = A * A;
    [
        u * (u - A) / (2.0 * a2),
        (a2 - u * u) / a2,
        u * (u + A) / (2.0 * a2),
    ]
}

/// A chart rectangle [x0, x1] × [y0, y1].
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Rect {
    fn centre(&self) -> (f64, f64, f64, f64) {
        (
            0.5 * (self.x0 + self.x1),
            0.5 * (self.y0 + self.y1),
            0.5 * (self.x1 - self.x0),
            0.5 * (self.y1 - self.y0),
        )
    }
}

type Moments = [DVec3; 9];

/// A node of the stored tree: a block of pieces `[i0, i1) × [j0, j1)` and its moments.
struct Node {
    rect: Rect,
    range: [u32; 4],
    w: Moments,
    children: Vec<u32>,
}

/// A texture's pieces and moment tree.
pub struct Tree {
    img: Arc<Image>,
    /// Pieces along s (columns) and t (rows), with their chart intervals.
    px: Vec<(AxisPiece, f64, f64)>,
    py: Vec<(AxisPiece, f64, f64)>,
    nodes: Vec<Node>,
}

/// The chart interval `[1 − 2·x1/n, 1 − 2·x0/n]` of each piece of an axis of n texels.
fn chart_pieces(n: usize, filter: Filter) -> Vec<(AxisPiece, f64, f64)> {
    let nf = n as f64;
    axis_pieces(n as u32, false, filter)
        .into_iter()
        .map(|p| (p, 1.0 - 2.0 * p.x1 / nf, 1.0 - 2.0 * p.x0 / nf))
        .collect()
}

/// Whether the fast path takes `p` (a textured rect): not with an IES profile (its grid kinks
/// are untested here) nor with a cone edge sharper than softness 0.25 (a smoothstep over less
/// than a quarter of the cone angle): at softness 0 S jumps, and the subdivision's error
/// estimates were measured to miss the error by up to 30× (6e-4 at 1e-4; 1.35e-4 at 1e-4 for
/// softness 0.05), the inner integral's derivative being singular in u where the edge is
/// tangent to the rule's lines. Those keep the exact split path.
pub fn applies(p: &Prepared) -> bool {
    p.rect_texture().is_some()
        && p.ies.is_none()
        && p.shaping
            .as_ref()
            .is_none_or(|s| s.start <= 0.75 * s.cone || !(s.cone < std::f64::consts::PI))
}

/// The moment tree of `t`, built on first use and shared by clones of the light.
pub fn tree(t: &RectTexture) -> Option<Arc<Tree>> {
    let slot = t
        .irradiance
        .get_or_init(|| Arc::new(Tree::new(t.image.clone(), t.filter())));
    slot.clone().downcast::<Tree>().ok()
}

impl Tree {
    fn new(img: Arc<Image>, filter: Filter) -> Tree {
        let px = chart_pieces(img.width, filter);
        let py = chart_pieces(img.height, filter);
        let mut t = Tree {
            img,
            px,
            py,
            nodes: Vec::new(),
        };
        let (nx, ny) = (t.px.len() as u32, t.py.len() as u32);
        t.build([0, nx, 0, ny]);
        t
    }

    /// The union of the pieces `range` as a chart rectangle (X decreases with s).
    fn block_rect(&self, r: [u32; 4]) -> Rect {
        Rect {
            x0: self.px[r[1] as usize - 1].1,
            x1: self.px[r[0] as usize].2,
            y0: self.py[r[3] as usize - 1].1,
            y1: self.py[r[2] as usize].2,
        }
    }

    /// Builds the subtree of `range`, returning its index.
    fn build(&mut self, r: [u32; 4]) -> u32 {
        let rect = self.block_rect(r);
        let idx = self.nodes.len() as u32;
        self.nodes.push(Node {
            rect,
            range: r,
            w: [DVec3::ZERO; 9],
            children: Vec::new(),
        });
        let w = if (r[1] - r[0]) * (r[3] - r[2]) <= LEAF_PIECES {
            self.block_moments(r, rect)
        } else {
            let kids: Vec<u32> = split_range(r).into_iter().map(|c| self.build(c)).collect();
            let mut w = [DVec3::ZERO; 9];
            for &k in &kids {
                let c = &self.nodes[k as usize];
                add_child_moments(&mut w, rect, c.rect, &c.w);
            }
            self.nodes[idx as usize].children = kids;
            w
        };
        self.nodes[idx as usize].w = w;
        idx
    }

    /// The filtered texture on piece (i, j) at chart (X, Y) (inside the piece).
    #[inline]
    fn value(&self, i: usize, j: usize, x: f64, y: f64) -> DVec3 {
        let (pi, pj) = (&self.px[i].0, &self.py[j].0);
        let (ax, bx) = pi.weights(0.5 * (1.0 - x) * self.img.width as f64);
        let (ay, by) = pj.weights(0.5 * (1.0 - y) * self.img.height as f64);
        let w = self.img.width;
        let texel = |col: u32, row: u32| {
            DVec3::from_array(self.img.rgb[row as usize * w + col as usize].map(f64::from))
        };
        let row0 = texel(pi.i0, pj.i0) * ax + texel(pi.i1, pj.i0) * bx;
        let row1 = texel(pi.i0, pj.i1) * ax + texel(pi.i1, pj.i1) * bx;
        row0 * ay + row1 * by
    }

    /// The filtered texture at any chart point of the square (its piece found by bisection).
    fn value_at(&self, x: f64, y: f64) -> DVec3 {
        let find = |pieces: &[(AxisPiece, f64, f64)], n: usize, c: f64| {
            let px = 0.5 * (1.0 - c) * n as f64;
            pieces
                .partition_point(|p| p.0.x1 <= px)
                .min(pieces.len() - 1)
        };
        let i = find(&self.px, self.img.width, x);
        let j = find(&self.py, self.img.height, y);
        self.value(i, j, x, y)
    }

    /// `W_ab = ∫ t·ℓ_ab` over `rect` (inside the pieces `r`), exact: each piece's part of
    /// `rect` by its 3 × 3 Gauss–Legendre rule.
    fn block_moments(&self, r: [u32; 4], rect: Rect) -> Moments {
        let (cx, cy, hx, hy) = rect.centre();
        let mut w = [DVec3::ZERO; 9];
        for j in r[2]..r[3] {
            let (_, py0, py1) = self.py[j as usize];
            let (y0, y1) = (py0.max(rect.y0), py1.min(rect.y1));
            if !(y1 > y0) {
                continue;
            }
            for i in r[0]..r[1] {
                let (_, px0, px1) = self.px[i as usize];
                let (x0, x1) = (px0.max(rect.x0), px1.min(rect.x1));
                if !(x1 > x0) {
                    continue;
                }
                let (mx, my, sx, sy) = (
                    0.5 * (x0 + x1),
                    0.5 * (y0 + y1),
                    0.5 * (x1 - x0),
                    0.5 * (y1 - y0),
                );
                for (gb, &vb) in GX.iter().zip(&GW) {
                    let y = my + sy * gb;
                    let lb = lagrange((y - cy) / hy);
                    for (ga, &va) in GX.iter().zip(&GW) {
                        let x = mx + sx * ga;
                        let la = lagrange((x - cx) / hx);
                        let tv = self.value(i as usize, j as usize, x, y) * (va * vb * sx * sy);
                        for b in 0..3 {
                            for a in 0..3 {
                                w[3 * b + a] += tv * (la[a] * lb[b]);
                            }
                        }
                    }
                }
            }
        }
        w
    }
}

/// The children of a block of pieces: its ranges halved on each axis longer than one piece.
fn split_range(r: [u32; 4]) -> Vec<[u32; 4]> {
    let xs = if r[1] - r[0] > 1 {
        let m = (r[0] + r[1]) / 2;
        vec![(r[0], m), (m, r[1])]
    } else {
        vec![(r[0], r[1])]
    };
    let ys = if r[3] - r[2] > 1 {
        let m = (r[2] + r[3]) / 2;
        vec![(r[2], m), (m, r[3])]
    } else {
        vec![(r[2], r[3])]
    };
    let mut v = Vec::with_capacity(4);
    for &(j0, j1) in &ys {
        for &(i0, i1) in &xs {
            v.push([i0, i1, j0, j1]);
        }
    }
    v
}

/// `W^P += Σ_cd W^C_cd ℓ^P_ab(x^C_cd)`: exact, since ℓ^P_ab is biquadratic (module docs).
fn add_child_moments(w: &mut Moments, parent: Rect, child: Rect, wc: &Moments) {
    let (cx, cy, hx, hy) = parent.centre();
    let (ccx, ccy, chx, chy) = child.centre();
    let lx: [[f64; 3]; 3] = GX.map(|g| lagrange((ccx + chx * g - cx) / hx));
    let ly: [[f64; 3]; 3] = GX.map(|g| lagrange((ccy + chy * g - cy) / hy));
    for d in 0..3 {
        for c in 0..3 {
            let v = wc[3 * d + c];
            for b in 0..3 {
                for a in 0..3 {
                    w[3 * b + a] += v * (lx[c][a] * ly[d][b]);
                }
            }
        }
    }
}

/// A cell of the per-receiver subdivision: a stored node, or a block of pieces (below a leaf)
/// restricted to `rect` (a sub-rect of its piece when the block is one piece).
#[derive(Clone, Copy, Debug)]
enum Cell {
    Node(u32),
    Block([u32; 4], Rect),
}

impl Tree {
    fn rect(&self, c: &Cell) -> Rect {
        match c {
            Cell::Node(i) => self.nodes[*i as usize].rect,
            Cell::Block(_, r) => *r,
        }
    }

    fn moments(&self, c: &Cell) -> Moments {
        match c {
            Cell::Node(i) => self.nodes[*i as usize].w,
            Cell::Block(r, rect) => self.block_moments(*r, *rect),
        }
    }

    /// The cell's children; none when it is a sub-rect too small to split.
    fn children(&self, c: &Cell) -> Vec<Cell> {
        match *c {
            Cell::Node(i) => {
                let n = &self.nodes[i as usize];
                if n.children.is_empty() {
                    split_range(n.range)
                        .into_iter()
                        .map(|r| Cell::Block(r, self.block_rect(r)))
                        .collect()
                } else {
                    n.children.iter().map(|&k| Cell::Node(k)).collect()
                }
            }
            Cell::Block(r, _) if (r[1] - r[0]) * (r[3] - r[2]) > 1 => split_range(r)
                .into_iter()
                .map(|r| Cell::Block(r, self.block_rect(r)))
                .collect(),
            Cell::Block(r, rect) => {
                let (cx, cy, hx, hy) = rect.centre();
                if !(hx > 1e-12 * (1.0 + cx.abs()) && hy > 1e-12 * (1.0 + cy.abs())) {
                    return Vec::new();
                }
                let xs = [(rect.x0, cx), (cx, rect.x1)];
                let ys = [(rect.y0, cy), (cy, rect.y1)];
                let mut v = Vec::with_capacity(4);
                for &(y0, y1) in &ys {
                    for &(x0, x1) in &xs {
                        v.push(Cell::Block(r, Rect { x0, x1, y0, y1 }));
                    }
                }
                v
            }
        }
    }
}

/// The smooth kernel `K = S(−ŵ)·max(0, n·w)·J/|w|⁴` of the chart integral (module docs).
struct Kernel<'a> {
    p: &'a Prepared,
    chart: &'a Chart,
    n: DVec3,
    shaped: bool,
}

impl Kernel<'_> {
    #[inline]
    fn eval(&self, x: f64, y: f64) -> DVec3 {
        let w = self.chart.w0 + self.chart.e1 * x + self.chart.e2 * y;
        let nw = self.n.dot(w);
        if !(nw > 0.0) {
            return DVec3::ZERO;
        }
        let l2 = w.length_squared();
        let v = nw * self.chart.jac / (l2 * l2);
        if self.shaped {
            shaping(self.p, -w / l2.sqrt()) * v
        } else {
            DVec3::splat(v)
        }
    }

    /// The horizon's affine function `h = n·w` on the chart: (c, a, b) with h = c + aX + bY.
    fn horizon(&self) -> (f64, f64, f64) {
        (
            self.n.dot(self.chart.w0),
            self.n.dot(self.chart.e1),
            self.n.dot(self.chart.e2),
        )
    }

    /// The cell's rule: 0 behind the horizon, the moment rule where the horizon does not cross
    /// it, else [`Kernel::clipped`].
    fn cell_rule(&self, tree: &Tree, cell: &Cell) -> DVec3 {
        let r = tree.rect(cell);
        let (c, a, b) = self.horizon();
        let hs = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)]
            .map(|(x, y)| c + a * x + b * y);
        if hs.iter().all(|&h| !(h > 0.0)) {
            return DVec3::ZERO;
        }
        if hs.iter().all(|&h| h > 0.0) && !self.kinked(r) {
            return self.rule(r, &tree.moments(cell));
        }
        self.clipped(tree, r)
    }

    /// Whether a kink of the shaping factor (`Prepared::profile`: the cone edge, the
    /// smoothstep's start, the focus plane) may cross the cell: a cone whose angle lies within
    /// α = asin(R/|w_c|) of the centre direction's, or a plane with corners on both sides.
    fn kinked(&self, r: Rect) -> bool {
        if !self.shaped {
            return false;
        }
        let (cx, cy, hx, hy) = r.centre();
        let c = self.chart;
        let wc = c.w0 + c.e1 * cx + c.e2 * cy;
        let (d, rad) = (wc.length(), (c.e1 * hx).length() + (c.e2 * hy).length());
        let cone = (rad < d).then(|| {
            (
                (rad / d).asin() + 1e-9,
                (-wc / d).dot(self.p.axis).clamp(-1.0, 1.0).acos(),
            )
        });
        let corners = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)];
        self.p.profile.kinks.iter().any(|k| match *k {
            Kink::Cone { cos } => match cone {
                Some((alpha, theta)) => (cos.clamp(-1.0, 1.0).acos() - theta).abs() <= alpha,
                None => true,
            },
            Kink::Plane { m, .. } => {
                let sg = corners.map(|(x, y)| m.dot(c.w0 + c.e1 * x + c.e2 * y));
                sg.iter().any(|&v| v > 0.0) && sg.iter().any(|&v| !(v > 0.0))
            }
        }) || (self.p.profile.axis_singular && cone.is_none_or(|(a, t)| t <= a))
    }

    /// `∫ t·K` over the part of `r` in front of the horizon (a line h = 0 of the chart, where K
    /// has a kink), each line of the inner rule also split where the shaping's kinks meet it
    /// (the roots of `line::line_integral`): that part is bounded by the line and the sides, so with the coordinate the
    /// line is a graph over (the one along which |∂h| is smaller) split where the line leaves
    /// through a side, it is a union of trapezoids mapped onto squares, each integrated by the
    /// 5 × 5 Gauss–Legendre rule of `t·K` (K smooth there, t sampled). No rule point lies
    /// behind the horizon, so no sliver in front of it goes unseen.
    fn clipped(&self, tree: &Tree, r: Rect) -> DVec3 {
        let (c, a, b) = self.horizon();
        // Work in (u, v) with v the graph coordinate: v_line(u) = −(c + p·u)/q.
        let swap = b.abs() < a.abs();
        let (p, q, u0, u1, v0, v1) = if swap {
            (b, a, r.y0, r.y1, r.x0, r.x1)
        } else {
            (a, b, r.x0, r.x1, r.y0, r.y1)
        };
        let vl = |u: f64| -(c + p * u) / q;
        let mut cuts = vec![u0, u1];
        if q == 0.0 {
            // h does not depend on v: the line is u = −c/p (or absent).
            if p != 0.0 && -c / p > u0 && -c / p < u1 {
                cuts.push(-c / p);
            }
        } else if p != 0.0 {
            for v in [v0, v1] {
                let u = -(c + q * v) / p;
                if u > u0 && u < u1 {
                    cuts.push(u);
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let lim = |u: f64| {
            if q == 0.0 {
                return if c + p * u > 0.0 { (v0, v1) } else { (v0, v0) };
            }
            let l = vl(u).clamp(v0, v1);
            if q > 0.0 { (l, v1) } else { (v0, l) }
        };
        let mut sum = DVec3::ZERO;
        for w in cuts.windows(2) {
            let (ua, ub) = (w[0], w[1]);
            if !(ub > ua) {
                continue;
            }
            let (um, uh) = (0.5 * (ua + ub), 0.5 * (ub - ua));
            let (lo, hi) = lim(um);
            if !(hi > lo) {
                continue;
            }
            for (gu, wu) in G5X.iter().zip(&G5W) {
                let u = um + uh * gu;
                let (lo, hi) = lim(u);
                if !(hi > lo) {
                    continue;
                }
                // The line u = const, w = a + v·ev, split where the shaping's kinks meet it.
                let (a, ev) = if swap {
                    (self.chart.w0 + self.chart.e2 * u, self.chart.e1)
                } else {
                    (self.chart.w0 + self.chart.e1 * u, self.chart.e2)
                };
                let mut bps = vec![lo, hi];
                if self.shaped {
                    for k in &self.p.profile.kinks {
                        match *k {
                            Kink::Cone { cos } => {
                                bps.extend(cone_roots_on_line(self.p.axis, cos, a, ev));
                            }
                            Kink::Plane { m, .. } => {
                                let den = m.dot(ev);
                                if den != 0.0 {
                                    bps.push(-m.dot(a) / den);
                                }
                            }
                        }
                    }
                    if self.p.profile.axis_singular {
                        bps.extend(axis_approach(self.p.axis, a, ev));
                    }
                }
                bps.retain(|&v| v >= lo && v <= hi);
                bps.sort_by(f64::total_cmp);
                for seg in bps.windows(2) {
                    let (vm, vh) = (0.5 * (seg[0] + seg[1]), 0.5 * (seg[1] - seg[0]));
                    if !(vh > 0.0) {
                        continue;
                    }
                    for (gv, wv) in G5X.iter().zip(&G5W) {
                        let v = vm + vh * gv;
                        let (x, y) = if swap { (v, u) } else { (u, v) };
                        sum += self.eval(x, y) * tree.value_at(x, y) * (wu * wv * uh * vh);
                    }
                }
            }
        }
        sum
    }

    /// The cell's moment rule `Σ K(x_ab) W_ab`.
    fn rule(&self, r: Rect, w: &Moments) -> DVec3 {
        let (cx, cy, hx, hy) = r.centre();
        let mut s = DVec3::ZERO;
        for b in 0..3 {
            let y = cy + hy * GX[b];
            for a in 0..3 {
                let wab = w[3 * b + a];
                if wab != DVec3::ZERO {
                    s += self.eval(cx + hx * GX[a], y) * wab;
                }
            }
        }
        s
    }

    /// Whether the cell must be split before its rule is trusted: it is not well separated
    /// from x (half-diagonal R > ½ (|w_c| − R)) and the horizon does not hide all of it.
    fn near(&self, r: Rect) -> bool {
        let (cx, cy, hx, hy) = r.centre();
        let c = self.chart;
        let wc = c.w0 + c.e1 * cx + c.e2 * cy;
        let rad = (c.e1 * hx).length() + (c.e2 * hy).length();
        if !(rad > 0.5 * (wc.length() - rad)) {
            return false;
        }
        let corners = [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1)];
        corners
            .iter()
            .any(|&(x, y)| self.n.dot(c.w0 + c.e1 * x + c.e2 * y) > 0.0)
    }
}

/// An active cell: its value (the sum of its children's rules), their rules, its error.
struct Active {
    key: f64,
    value: DVec3,
    err: DVec3,
    kids: Vec<(Cell, DVec3)>,
}

impl PartialEq for Active {
    fn eq(&self, o: &Self) -> bool {
        self.key.total_cmp(&o.key).is_eq()
    }
}
impl Eq for Active {}
impl PartialOrd for Active {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Active {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.key.total_cmp(&o.key)
    }
}

/// The chart integral `∫∫ t·K dX dY` of the textured rect `p` (base radiance not applied) to
/// relative tolerance `rel` (module docs). None when `p` has no texture.
pub fn chart_integral(p: &Prepared, chart: &Chart, n: DVec3, rel: f64) -> Option<DVec3> {
    let tree = tree(p.rect_texture()?)?;
    let k = Kernel {
        p,
        chart,
        n,
        shaped: p.shaping.is_some(),
    };
    let activate = |cell: Cell, own: DVec3| -> Active {
        let kids: Vec<(Cell, DVec3)> = tree
            .children(&cell)
            .into_iter()
            .map(|c| {
                let v = k.cell_rule(&tree, &c);
                (c, v)
            })
            .collect();
        if kids.is_empty() {
            return Active {
                key: 0.0,
                value: own,
                err: DVec3::ZERO,
                kids,
            };
        }
        let value: DVec3 = kids.iter().map(|c| c.1).sum();
        let err = (value - own).abs();
        let r = tree.rect(&cell);
        let key = if k.near(r) {
            f64::INFINITY
        } else {
            err.max_element()
        };
        Active {
            key,
            value,
            err,
            kids,
        }
    };
    let root = Cell::Node(0);
    let own = k.cell_rule(&tree, &root);
    let first = activate(root, own);
    let (mut total, mut err) = (first.value, first.err);
    let mut forced = usize::from(first.key == f64::INFINITY);
    let mut heap = BinaryHeap::new();
    heap.push(first);
    let q = rel / 8.0;
    for _ in 0..MAX_SPLITS {
        let tiny = 1e-14 * total.abs().max_element();
        let done = forced == 0
            && (err.x <= q * total.x.abs() + tiny)
            && (err.y <= q * total.y.abs() + tiny)
            && (err.z <= q * total.z.abs() + tiny);
        if done {
            break;
        }
        let Some(top) = heap.pop() else { break };
        if top.key == 0.0 && forced == 0 {
            heap.push(top);
            break;
        }
        if top.key == f64::INFINITY {
            forced -= 1;
        }
        total -= top.value;
        err -= top.err;
        for (c, own) in top.kids {
            let a = activate(c, own);
            total += a.value;
            err += a.err;
            forced += usize::from(a.key == f64::INFINITY);
            heap.push(a);
        }
    }
    // The running sums lose digits as large terms leave: the final value is summed afresh.
    Some(heap.iter().map(|a| a.value).sum())
}

#[cfg(test)]
mod tests {
    use std::time::Instant;

    use glam::{DMat3, DMat4, DQuat};

    use super::*;
    use crate::cpu::irradiance::{Adaptive, Rule, irradiance, irradiance_with};
    use crate::model::{Light, Shaping};
    use crate::prepare::TemperatureMode;
    use crate::synthetic::Rng;

    fn textured(l: &Light, w: usize, h: usize, rgb: Vec<[f32; 3]>, filter: Filter) -> Prepared {
        let mut p = Prepared::new(l, TemperatureMode::Spec).unwrap();
        let img = Image::from_rgb(w, h, rgb, "test.exr").unwrap();
        p.kind = crate::prepare::KindData::Rect {
            texture: Some(RectTexture::new(Arc::new(img), filter)),
        };
        p
    }

    fn random_rgb(rng: &mut Rng, n: usize) -> Vec<[f32; 3]> {
        (0..n)
            .map(|_| [0, 1, 2].map(|_| (0.05 + rng.f64()) as f32))
            .collect()
    }

    /// The sheared transform of `rect_texture`'s tests.
    fn skewed() -> DMat4 {
        let shear = DMat4::from_mat3(DMat3::from_cols(
            DVec3::new(1.3, 0.0, 0.0),
            DVec3::new(0.4, 0.8, 0.0),
            DVec3::new(0.0, 0.2, 1.1),
        ));
        DMat4::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 0.9),
            DVec3::new(0.2, -0.4, 0.7),
        ) * shear
    }

    /// A wide soft cone with a tinted focus, and a narrow cone with the thinnest smoothstep the
    /// fast path takes (softness 0.25; its edge crosses the rect for several receivers).
    fn shapings() -> [Option<Shaping>; 3] {
        [
            None,
            Some(Shaping {
                focus: 1.5,
                focus_tint: DVec3::new(0.2, 0.5, 1.0),
                cone_angle: 50.0,
                cone_softness: 0.4,
                ies: None,
            }),
            Some(Shaping {
                focus: 0.7,
                focus_tint: DVec3::ONE,
                cone_angle: 30.0,
                cone_softness: 0.25,
                ies: None,
            }),
        ]
    }

    /// Receivers in local coordinates (in front: local −Z) with local normals: near the surface
    /// (inside the near field: 0.02 and 0.002 from it), cut by their horizon, grazing (the
    /// horizon through the rect's middle, as luxtest visibleRect's floor), and far.
    fn receivers() -> Vec<(DVec3, DVec3)> {
        vec![
            (DVec3::new(0.1, 0.2, -1.0), DVec3::new(0.0, 0.1, 1.0)),
            (DVec3::new(0.05, -0.1, -0.02), DVec3::Z),
            (DVec3::new(-0.2, 0.13, -0.002), DVec3::new(0.2, 0.1, 1.0)),
            (DVec3::new(0.3, -0.1, -0.6), DVec3::new(1.0, 0.2, 0.3)),
            (DVec3::new(-0.4, 0.3, -0.4), DVec3::new(-0.3, -1.0, 0.5)),
            (DVec3::new(0.1, 0.0, -0.05), DVec3::Y),
            (DVec3::new(0.2, 0.01, -0.3), DVec3::Y),
            (DVec3::new(1.5, 0.9, -2.0), DVec3::new(-0.5, -0.3, 1.0)),
            (DVec3::new(-3.0, 2.0, -9.0), DVec3::new(0.3, -0.2, 1.0)),
        ]
    }

    fn world(p: &Prepared, x: DVec3, n: DVec3) -> (DVec3, DVec3) {
        (p.origin + p.linear * x, (p.linear * n).normalize())
    }

    fn rel_err(a: DVec3, b: DVec3) -> f64 {
        ((a - b).abs() / b.abs()).max_element()
    }

    /// The fast path against the 1e-9 reference (the exact split path, `rect_texture`) on random
    /// textures, both filters, unshaped and shaped (cone, softness, focus with tint), under the
    /// identity and a sheared transform, at every receiver of [`receivers`]: the relative error
    /// of every channel within the requested tolerance.
    fn against_reference(sizes: &[(usize, usize)], seed: u64) {
        let mut rng = Rng::new(seed);
        let mut worst = [0.0f64; 3];
        for &(tw, th) in sizes {
            let rgb = random_rgb(&mut rng, tw * th);
            for m in [DMat4::IDENTITY, skewed()] {
                for shaping in shapings() {
                    let mut l = Light::rect(1.2, 0.8).with_intensity(2.0).with_transform(m);
                    if let Some(s) = &shaping {
                        l = l.with_shaping(s.clone());
                    }
                    for filter in [Filter::Bilinear, Filter::Nearest] {
                        let p = textured(&l, tw, th, rgb.clone(), filter);
                        for (xl, nl) in receivers() {
                            let (x, n) = world(&p, xl, nl);
                            let reference = irradiance(&p, x, n);
                            if reference.max_element() <= 0.0 {
                                continue;
                            }
                            for (k, tol) in [1e-4, 1e-3, 1e-2].into_iter().enumerate() {
                                let rule = Adaptive::for_tolerance(tol);
                                assert!(rule.texture_tolerance().is_some());
                                let fast = irradiance_with(&p, x, n, &rule);
                                let err = rel_err(fast, reference);
                                worst[k] = worst[k].max(err / tol);
                                assert!(
                                    err <= tol,
                                    "{tw}x{th} {filter:?} shaped={} skewed={} at {xl} n {nl} \
                                     tol {tol:e}: {fast} vs {reference} ({err:e})",
                                    shaping.is_some(),
                                    m != DMat4::IDENTITY
                                );
                            }
                        }
                    }
                }
            }
        }
        println!("worst error / tolerance at 1e-4, 1e-3, 1e-2: {worst:?}");
    }

    #[test]
    fn small_random_textures_meet_the_tolerance_against_the_reference() {
        against_reference(&[(16, 8), (5, 3), (1, 1)], 3);
    }

    #[test]
    fn medium_random_textures_meet_the_tolerance_against_the_reference() {
        against_reference(&[(64, 32)], 5);
    }

    /// The largest size, release build only (the reference takes seconds a receiver in a debug
    /// build): `cargo test --release -p luxeval --lib rect_fast -- --ignored`.
    #[test]
    #[ignore]
    fn large_random_textures_meet_the_tolerance_against_the_reference() {
        against_reference(&[(256, 128)], 9);
    }

    /// A cone edge sharper than softness 0.25 keeps the exact path ([`applies`]).
    #[test]
    fn a_hard_cone_keeps_the_exact_path() {
        let mut s = shapings()[2].clone().unwrap();
        let l = |s: &Shaping| Light::rect(1.2, 0.8).with_shaping(s.clone());
        assert!(applies(&textured(
            &l(&s),
            2,
            2,
            vec![[1.0; 3]; 4],
            Filter::Nearest
        )));
        for soft in [0.0, 0.05, 0.24] {
            s.cone_softness = soft;
            assert!(!applies(&textured(
                &l(&s),
                2,
                2,
                vec![[1.0; 3]; 4],
                Filter::Nearest
            )));
        }
        s.cone_softness = 0.0;
        assert!(!applies(&textured(
            &l(&s),
            2,
            2,
            vec![[1.0; 3]; 4],
            Filter::Nearest
        )));
    }

    /// A constant texture c multiplies the untextured rect by c: Lambert's closed form unshaped
    /// (`closed::rect_lambert`), the untextured rect's reference chart quadrature shaped.
    #[test]
    fn a_constant_texture_gives_the_untextured_rect() {
        let c = [0.7f32, 1.3, 2.0];
        for m in [DMat4::IDENTITY, skewed()] {
            for shaping in shapings() {
                let mut l = Light::rect(1.2, 0.8).with_intensity(2.0).with_transform(m);
                if let Some(s) = &shaping {
                    l = l.with_shaping(s.clone());
                }
                let plain = Prepared::new(&l, TemperatureMode::Spec).unwrap();
                for (w, h) in [(1, 1), (7, 5), (40, 30)] {
                    for filter in [Filter::Bilinear, Filter::Nearest] {
                        let p = textured(&l, w, h, vec![c; w * h], filter);
                        for (xl, nl) in receivers() {
                            let (x, n) = world(&p, xl, nl);
                            let want =
                                irradiance(&plain, x, n) * DVec3::from_array(c.map(f64::from));
                            if want.max_element() <= 0.0 {
                                continue;
                            }
                            for tol in [1e-4, 1e-3, 1e-2] {
                                let got = irradiance_with(&p, x, n, &Adaptive::for_tolerance(tol));
                                let err = rel_err(got, want);
                                assert!(
                                    err <= tol,
                                    "{w}x{h} {filter:?} at {xl}: {got} vs {want} ({err:e})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// Timing (no assertion on time): ms per receiver on a random 2048 × 1024 texture at the
    /// CLI's default tolerance 1e-4, tree build separately. Release only:
    /// `cargo test --release -p luxeval --lib rect_fast::tests::timing -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn timing_2048_by_1024() {
        let mut rng = Rng::new(1);
        let (tw, th) = (2048, 1024);
        let rgb = random_rgb(&mut rng, tw * th);
        let l = Light::rect(1.0, 1.0).with_intensity(1.0);
        let p = textured(&l, tw, th, rgb, Filter::Bilinear);
        let t0 = Instant::now();
        let _ = tree(p.rect_texture().unwrap());
        println!("tree build: {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
        let rule = Adaptive::for_tolerance(1e-4);
        for (xl, nl) in receivers() {
            let (x, n) = world(&p, xl, nl);
            let t = Instant::now();
            let e = irradiance_with(&p, x, n, &rule);
            println!(
                "receiver {xl} n {nl}: {e} in {:.2} ms",
                t.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}
