//! The moment tree of a rect texture (see `rect_fast`'s module docs): the texel pieces' chart
//! rectangles, the exact Lagrange moments `W_ab = ∫ t·ℓ_ab` of a quadtree over them, and the
//! cells of the per-receiver subdivision (stored nodes, blocks of pieces, sub-rects of a piece).

use std::sync::Arc;

use glam::DVec3;

use crate::prepare::texture::{AxisPiece, Filter, Image, RectTexture, axis_pieces};

/// A leaf of the stored tree holds at most this many texel pieces (4 × 4): the tree of a
/// 2048 × 1024 texture then has ~175k nodes (~50 MB).
pub const LEAF_PIECES: u32 = 16;

/// 3-point Gauss–Legendre on [−1, 1] (A&S 25.4.29).
pub(super) const A: f64 = 0.774_596_669_241_483_4;
pub(super) const GX: [f64; 3] = [-A, 0.0, A];
pub(super) const GW: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];

/// The Lagrange basis on the nodes `GX`, at u (node coordinates in [−1, 1]).
#[inline]
pub(super) fn lagrange(u: f64) -> [f64; 3] {
    let a2 = A * A;
    [
        u * (u - A) / (2.0 * a2),
        (a2 - u * u) / a2,
        u * (u + A) / (2.0 * a2),
    ]
}

/// A chart rectangle [x0, x1] × [y0, y1].
#[derive(Clone, Copy, Debug)]
pub(super) struct Rect {
    pub(super) x0: f64,
    pub(super) x1: f64,
    pub(super) y0: f64,
    pub(super) y1: f64,
}

impl Rect {
    pub(super) fn centre(&self) -> (f64, f64, f64, f64) {
        (
            0.5 * (self.x0 + self.x1),
            0.5 * (self.y0 + self.y1),
            0.5 * (self.x1 - self.x0),
            0.5 * (self.y1 - self.y0),
        )
    }
}

pub(super) type Moments = [DVec3; 9];

/// A node of the stored tree: a block of pieces `[i0, i1) × [j0, j1)` and its moments.
struct Node {
    rect: Rect,
    range: [u32; 4],
    w: Moments,
    /// The largest |t| on the node, per channel (`Tree::t_max`).
    tmax: DVec3,
    children: Vec<u32>,
}

/// A texture's pieces and moment tree.
pub struct Tree {
    img: Arc<Image>,
    /// Pieces along s (columns) and t (rows), with their chart intervals.
    px: Vec<(AxisPiece, f64, f64)>,
    py: Vec<(AxisPiece, f64, f64)>,
    nodes: Vec<Node>,
    /// Every texel is ≥ 0 in every channel: then `∫|t| = ∫t = Σ_ab W_ab` on any cell
    /// ([`Tree::abs_integral`]).
    nonnegative: bool,
}

/// The chart interval `[1 − 2·x1/n, 1 − 2·x0/n]` of each piece of an axis of n texels.
fn chart_pieces(n: usize, filter: Filter) -> Vec<(AxisPiece, f64, f64)> {
    let nf = n as f64;
    axis_pieces(n as u32, false, filter)
        .into_iter()
        .map(|p| (p, 1.0 - 2.0 * p.x1 / nf, 1.0 - 2.0 * p.x0 / nf))
        .collect()
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
        let nonnegative = img.rgb.iter().flatten().all(|&v| v >= 0.0);
        let mut t = Tree {
            img,
            px,
            py,
            nodes: Vec::new(),
            nonnegative,
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
            tmax: DVec3::ZERO,
            children: Vec::new(),
        });
        let (w, tmax) = if (r[1] - r[0]) * (r[3] - r[2]) <= LEAF_PIECES {
            (self.block_moments(r, rect), self.block_tmax(r))
        } else {
            let kids: Vec<u32> = split_range(r).into_iter().map(|c| self.build(c)).collect();
            let mut w = [DVec3::ZERO; 9];
            let mut tmax = DVec3::ZERO;
            for &k in &kids {
                let c = &self.nodes[k as usize];
                add_child_moments(&mut w, rect, c.rect, &c.w);
                tmax = tmax.max(c.tmax);
            }
            self.nodes[idx as usize].children = kids;
            (w, tmax)
        };
        self.nodes[idx as usize].w = w;
        self.nodes[idx as usize].tmax = tmax;
        idx
    }

    /// The largest |t| over the pieces `r`: on a piece t is bilinear (or constant), so |t| is
    /// largest at one of its corners.
    fn block_tmax(&self, r: [u32; 4]) -> DVec3 {
        let mut m = DVec3::ZERO;
        for j in r[2] as usize..r[3] as usize {
            let (_, y0, y1) = self.py[j];
            for i in r[0] as usize..r[1] as usize {
                let (_, x0, x1) = self.px[i];
                for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                    m = m.max(self.value(i, j, x, y).abs());
                }
            }
        }
        m
    }

    /// The largest |t| on the cell, per channel (an upper bound for a sub-rect of a piece).
    pub(super) fn t_max(&self, c: &Cell) -> DVec3 {
        match c {
            Cell::Node(i) => self.nodes[*i as usize].tmax,
            Cell::Block(r, _) => self.block_tmax(*r),
        }
    }

    /// An upper bound of `∫|t|` over the cell `r` with moments `w`, per channel: the exact
    /// `∫t = Σ_ab W_ab` (the ℓ_ab sum to 1) when the texture is nonnegative (bilinear and
    /// nearest filtering keep it so), else `t_max · area`.
    pub(super) fn abs_integral(&self, c: &Cell, r: Rect, w: &Moments) -> DVec3 {
        if self.nonnegative {
            w.iter().sum::<DVec3>().max(DVec3::ZERO)
        } else {
            self.t_max(c) * ((r.x1 - r.x0) * (r.y1 - r.y0))
        }
    }

    /// The four texels that piece (i, j) blends: (i0, j0), (i1, j0), (i0, j1), (i1, j1).
    #[inline]
    fn texels(&self, i: usize, j: usize) -> [DVec3; 4] {
        let (pi, pj) = (&self.px[i].0, &self.py[j].0);
        let w = self.img.width;
        let texel = |col: u32, row: u32| {
            DVec3::from_array(self.img.rgb[row as usize * w + col as usize].map(f64::from))
        };
        [
            texel(pi.i0, pj.i0),
            texel(pi.i1, pj.i0),
            texel(pi.i0, pj.i1),
            texel(pi.i1, pj.i1),
        ]
    }

    /// The texel weights of piece i along X at chart X (and of piece j along Y at chart Y).
    #[inline]
    fn weights_x(&self, i: usize, x: f64) -> (f64, f64) {
        self.px[i]
            .0
            .weights(0.5 * (1.0 - x) * self.img.width as f64)
    }

    #[inline]
    fn weights_y(&self, j: usize, y: f64) -> (f64, f64) {
        self.py[j]
            .0
            .weights(0.5 * (1.0 - y) * self.img.height as f64)
    }

    /// The filtered texture on piece (i, j) at chart (X, Y) (inside the piece).
    #[inline]
    fn value(&self, i: usize, j: usize, x: f64, y: f64) -> DVec3 {
        let [t00, t10, t01, t11] = self.texels(i, j);
        let (ax, bx) = self.weights_x(i, x);
        let (ay, by) = self.weights_y(j, y);
        (t00 * ax + t10 * bx) * ay + (t01 * ax + t11 * bx) * by
    }

    /// The filtered texture at any chart point of the square (its piece found by bisection).
    pub(super) fn value_at(&self, x: f64, y: f64) -> DVec3 {
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

    /// The filtered texture at a chart point of the cell: read from its piece directly where
    /// the cell is one piece (or part of one), else found by [`Tree::value_at`].
    #[inline]
    pub(super) fn value_in(&self, c: &Cell, x: f64, y: f64) -> DVec3 {
        match c {
            Cell::Block(r, _) if r[1] - r[0] == 1 && r[3] - r[2] == 1 => {
                self.value(r[0] as usize, r[2] as usize, x, y)
            }
            _ => self.value_at(x, y),
        }
    }

    /// `W_ab = ∫ t·ℓ_ab` over `rect` (inside the pieces `r`), exact: each piece's part of
    /// `rect` by its 3 × 3 Gauss–Legendre rule. The rule is a tensor product and so are t on
    /// a piece (bilinear: its texels read once) and ℓ_ab, so the sum over the x points is taken
    /// first (54 products per piece instead of 81; the tree's build and the cells below its
    /// leaves spend most of their time here).
    fn block_moments(&self, r: [u32; 4], rect: Rect) -> Moments {
        let (cx, cy, hx, hy) = rect.centre();
        let mut w = [DVec3::ZERO; 9];
        for j in r[2]..r[3] {
            let j = j as usize;
            let (_, py0, py1) = self.py[j];
            let (y0, y1) = (py0.max(rect.y0), py1.min(rect.y1));
            if !(y1 > y0) {
                continue;
            }
            let (my, sy) = (0.5 * (y0 + y1), 0.5 * (y1 - y0));
            let ys = GX.map(|g| my + sy * g);
            let wy = ys.map(|y| self.weights_y(j, y));
            let ly = ys.map(|y| lagrange((y - cy) / hy));
            for i in r[0]..r[1] {
                let i = i as usize;
                let (_, px0, px1) = self.px[i];
                let (x0, x1) = (px0.max(rect.x0), px1.min(rect.x1));
                if !(x1 > x0) {
                    continue;
                }
                let (mx, sx) = (0.5 * (x0 + x1), 0.5 * (x1 - x0));
                let xs = GX.map(|g| mx + sx * g);
                let [t00, t10, t01, t11] = self.texels(i, j);
                // The texture along each x point's column, at the two rows it blends.
                let cols = xs.map(|x| {
                    let (ax, bx) = self.weights_x(i, x);
                    (t00 * ax + t10 * bx, t01 * ax + t11 * bx)
                });
                let lx = xs.map(|x| lagrange((x - cx) / hx));
                for (gb, &vb) in GW.iter().enumerate() {
                    let (ay, by) = wy[gb];
                    // Σ over the x points of t·weight·ℓ_a, for this y point.
                    let mut row = [DVec3::ZERO; 3];
                    for (ga, &va) in GW.iter().enumerate() {
                        let tv = (cols[ga].0 * ay + cols[ga].1 * by) * (va * sx);
                        for (a, ra) in row.iter_mut().enumerate() {
                            *ra += tv * lx[ga][a];
                        }
                    }
                    let f = vb * sy;
                    for b in 0..3 {
                        let lb = ly[gb][b] * f;
                        for a in 0..3 {
                            w[3 * b + a] += row[a] * lb;
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
pub(super) enum Cell {
    Node(u32),
    Block([u32; 4], Rect),
}

impl Tree {
    pub(super) fn rect(&self, c: &Cell) -> Rect {
        match c {
            Cell::Node(i) => self.nodes[*i as usize].rect,
            Cell::Block(_, r) => *r,
        }
    }

    pub(super) fn moments(&self, c: &Cell) -> Moments {
        match c {
            Cell::Node(i) => self.nodes[*i as usize].w,
            Cell::Block(r, rect) => self.block_moments(*r, *rect),
        }
    }

    /// How many texel pieces the cell covers (1 for a sub-rect of a piece).
    pub(super) fn pieces(&self, c: &Cell) -> u32 {
        let r = match c {
            Cell::Node(i) => self.nodes[*i as usize].range,
            Cell::Block(r, _) => *r,
        };
        (r[1] - r[0]) * (r[3] - r[2])
    }

    /// Whether [`Tree::children`] has any: all but sub-rects too small to split.
    pub(super) fn splits(&self, c: &Cell) -> bool {
        match *c {
            Cell::Block(r, rect) if (r[1] - r[0]) * (r[3] - r[2]) == 1 => {
                let (cx, cy, hx, hy) = rect.centre();
                hx > 1e-12 * (1.0 + cx.abs()) && hy > 1e-12 * (1.0 + cy.abs())
            }
            _ => true,
        }
    }

    /// The cell's children; none when it is a sub-rect too small to split.
    pub(super) fn children(&self, c: &Cell) -> Vec<Cell> {
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
                if !self.splits(c) {
                    return Vec::new();
                }
                let (cx, cy, _, _) = rect.centre();
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
