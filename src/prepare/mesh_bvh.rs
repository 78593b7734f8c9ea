//! A mesh light's bounding volume hierarchy (DESIGN.md §7 M3: "its acceleration structure is
//! built once per prepared scene"), in f64 for the CPU reference.
//!
//! Binned surface-area heuristic (Wald 2007, "On fast construction of SAH-based bounding volume
//! hierarchies"): at each node the triangles' centroids are binned along the widest centroid
//! axis and the split minimising `A_left·N_left + A_right·N_right` is taken; a node of at most
//! [`LEAF`] triangles, or one whose centroids all coincide, is a leaf. The nodes are stored depth first,
//! the left child right after its parent, so a traversal needs only the right child's index.
//!
//! Leaves hold a contiguous range of `order`, the triangle indices permuted; each leaf's range is
//! sorted by triangle index, so that a traversal comparing equal distances can keep the triangle
//! that comes first in face and fan order (M1) without a second pass.

use glam::DVec3;

use crate::model::MeshTriangle;

/// The most triangles a leaf holds.
pub const LEAF: usize = 4;
/// Centroid bins per split.
const BINS: usize = 16;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn of_triangle(t: &MeshTriangle) -> Aabb {
        Aabb {
            min: t.p[0].min(t.p[1]).min(t.p[2]),
            max: t.p[0].max(t.p[1]).max(t.p[2]),
        }
    }

    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn grow(self, p: DVec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Half the surface area (what the heuristic compares); 0 for an empty box.
    fn half_area(&self) -> f64 {
        let d = self.max - self.min;
        if d.min_element() < 0.0 {
            return 0.0;
        }
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// One node: a leaf (`count > 0`) holding `order[first .. first + count]`, or an inner node
/// whose left child is the next node and whose right child is `first`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub bounds: Aabb,
    pub first: u32,
    pub count: u32,
}

/// The hierarchy over a mesh's triangles; node 0 is the root (absent for an empty mesh).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshBvh {
    pub nodes: Vec<Node>,
    /// Triangle indices, each leaf's range sorted ascending.
    pub order: Vec<u32>,
    /// `(p0, p1 − p0, p2 − p0)` of triangle `order[k]` at k: what a ray test reads, laid out
    /// leaf by leaf so that a leaf's triangles are contiguous in memory.
    pub edges: Vec<[DVec3; 3]>,
}

impl MeshBvh {
    /// The most nodes on a path from the root to a leaf (0 for an empty mesh): what a
    /// traversal's stack must hold.
    pub fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack = Vec::new();
        if !self.nodes.is_empty() {
            stack.push((0usize, 1usize));
        }
        while let Some((k, d)) = stack.pop() {
            deepest = deepest.max(d);
            let node = self.nodes[k];
            if node.count == 0 {
                stack.push((k + 1, d + 1));
                stack.push((node.first as usize, d + 1));
            }
        }
        deepest
    }

    pub fn build(triangles: &[MeshTriangle]) -> MeshBvh {
        let mut bvh = MeshBvh {
            nodes: Vec::with_capacity(2 * triangles.len().div_ceil(LEAF)),
            order: (0..triangles.len() as u32).collect(),
            edges: Vec::new(),
        };
        if triangles.is_empty() {
            return bvh;
        }
        let boxes: Vec<Aabb> = triangles.iter().map(Aabb::of_triangle).collect();
        let centroids: Vec<DVec3> = boxes.iter().map(|b| 0.5 * (b.min + b.max)).collect();
        // An explicit stack, so a deep hierarchy never recurses: (the inner node whose right
        // child this is, first, count). A node's slot is taken when it is popped; the left
        // child is pushed last, so it is popped next and lands right after its parent.
        let mut stack: Vec<(Option<usize>, usize, usize)> = vec![(None, 0, triangles.len())];
        while let Some((parent, first, count)) = stack.pop() {
            let slot = bvh.nodes.len();
            if let Some(parent) = parent {
                bvh.nodes[parent].first = slot as u32;
            }
            let range = first..first + count;
            let bounds = bvh.order[range.clone()]
                .iter()
                .fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
            let split = (count > LEAF)
                .then(|| split(&bvh.order[range.clone()], &boxes, &centroids))
                .flatten();
            let Some(split) = split else {
                bvh.order[range].sort_unstable();
                bvh.nodes.push(Node {
                    bounds,
                    first: first as u32,
                    count: count as u32,
                });
                continue;
            };
            // Partition: the items of the bins left of the split go left. Both sides hold
            // items, since the split was chosen between two non-empty groups of bins and the
            // partition reads the same bins (not a threshold compared afresh, which rounding
            // could put on either side of a bin's edge: all items on one side, the same node
            // pushed again, for ever).
            let items = &mut bvh.order[range];
            let mut left = 0;
            for k in 0..items.len() {
                if split.goes_left(centroids[items[k] as usize]) {
                    items.swap(k, left);
                    left += 1;
                }
            }
            debug_assert!(left > 0 && left < count);
            bvh.nodes.push(Node {
                bounds,
                first: 0,
                count: 0,
            });
            stack.push((Some(slot), first + left, count - left));
            stack.push((None, first, left));
        }
        bvh.edges = bvh
            .order
            .iter()
            .map(|&i| {
                let p = triangles[i as usize].p;
                [p[0], p[1] - p[0], p[2] - p[0]]
            })
            .collect();
        bvh
    }
}

/// A split of a node's items: those whose centroid falls in a bin below `k` on `axis` (bins of
/// `width / BINS` from `lo`) go left.
struct Split {
    axis: usize,
    lo: f64,
    width: f64,
    k: usize,
}

impl Split {
    fn bin(&self, c: f64) -> usize {
        (((c - self.lo) / self.width * BINS as f64) as usize).min(BINS - 1)
    }

    fn goes_left(&self, centroid: DVec3) -> bool {
        self.bin(centroid[self.axis]) < self.k
    }
}

/// The binned SAH split of `items`, or `None` where splitting does not beat a leaf or every
/// centroid coincides.
fn split(items: &[u32], boxes: &[Aabb], centroids: &[DVec3]) -> Option<Split> {
    let cb = items
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.grow(centroids[i as usize]));
    let extent = cb.max - cb.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let (lo, width) = (cb.min[axis], extent[axis]);
    if !(width > 0.0) {
        return None;
    }
    let mut at = Split {
        axis,
        lo,
        width,
        k: 0,
    };
    let mut bins = [(Aabb::EMPTY, 0usize); BINS];
    for &i in items {
        let b = &mut bins[at.bin(centroids[i as usize][axis])];
        b.0 = b.0.union(boxes[i as usize]);
        b.1 += 1;
    }
    // Sweep from the right for the right-hand costs, then from the left.
    let mut right = [(0.0, 0usize); BINS];
    let mut acc = (Aabb::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc = (acc.0.union(bins[k].0), acc.1 + bins[k].1);
        right[k] = (acc.0.half_area(), acc.1);
    }
    let mut best: Option<(f64, usize)> = None;
    let mut acc = (Aabb::EMPTY, 0);
    for k in 1..BINS {
        acc = (acc.0.union(bins[k - 1].0), acc.1 + bins[k - 1].1);
        if acc.1 == 0 || right[k].1 == 0 {
            continue;
        }
        let cost = acc.0.half_area() * acc.1 as f64 + right[k].0 * right[k].1 as f64;
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, k));
        }
    }
    // A node larger than LEAF is always split (a leaf's cost grows with its size); the
    // heuristic only chooses where.
    at.k = best?.1;
    Some(at)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> Vec<MeshTriangle> {
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f64, j as f64);
                let p = |a: f64, b: f64| DVec3::new(a, b, (a * 0.3).sin());
                t.push(MeshTriangle {
                    p: [p(x, y), p(x + 1.0, y), p(x + 1.0, y + 1.0)],
                    face: t.len() as u32,
                });
                t.push(MeshTriangle {
                    p: [p(x, y), p(x + 1.0, y + 1.0), p(x, y + 1.0)],
                    face: t.len() as u32,
                });
            }
        }
        t
    }

    /// Every triangle in exactly one leaf, each inside every box on its path, leaves sorted.
    #[test]
    fn leaves_partition_the_triangles_inside_their_boxes() {
        let tris = grid(23);
        check_leaves(&tris, &MeshBvh::build(&tris), false);
    }

    /// Every triangle in exactly one leaf, each inside every box on its path, leaves sorted and
    /// of at most LEAF triangles (more only where `coincident` allows it and their centroids
    /// coincide, which no split separates).
    fn check_leaves(tris: &[MeshTriangle], bvh: &MeshBvh, coincident: bool) {
        let mut seen = vec![0; tris.len()];
        let mut stack = vec![(0usize, vec![])];
        while let Some((k, path)) = stack.pop() {
            let node = bvh.nodes[k];
            let mut path: Vec<Aabb> = path;
            path.push(node.bounds);
            if node.count > 0 {
                let leaf = &bvh.order[node.first as usize..(node.first + node.count) as usize];
                let centroid = |i: u32| {
                    let b = Aabb::of_triangle(&tris[i as usize]);
                    0.5 * (b.min + b.max)
                };
                let same = leaf.iter().all(|&i| centroid(i) == centroid(leaf[0]));
                assert!(leaf.len() <= LEAF || (coincident && same));
                assert!(leaf.windows(2).all(|w| w[0] < w[1]));
                for &i in leaf {
                    seen[i as usize] += 1;
                    let b = Aabb::of_triangle(&tris[i as usize]);
                    for a in &path {
                        assert!(a.min.cmple(b.min).all() && b.max.cmple(a.max).all());
                    }
                }
            } else {
                stack.push((k + 1, path.clone()));
                stack.push((node.first as usize, path));
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    /// Centroids on and one ulp either side of the bins' edges `lo + width·j/16`, at scales
    /// where those edges round: the partition reads the bins the split was chosen from, so
    /// neither side is empty (a fuzzed mesh light's points once put every item on one side of
    /// a threshold compared afresh: a debug assertion, and in release the same node pushed for
    /// ever).
    #[test]
    fn centroids_on_the_bins_edges_split_into_two_sides() {
        let mut rng = crate::synthetic::Rng::new(29);
        for _ in 0..3000 {
            let lo = rng.range(-1.0, 1.0) * 10f64.powi(rng.below(12) as i32 - 6);
            let width = rng.range(0.1, 1.0) * 10f64.powi(rng.below(12) as i32 - 6);
            let n = 5 + rng.below(24);
            let tris: Vec<MeshTriangle> = (0..n)
                .map(|i| {
                    let edge = lo + width * rng.below(BINS + 1) as f64 / BINS as f64;
                    let x = match rng.below(3) {
                        0 => edge,
                        1 => edge.next_up(),
                        _ => edge.next_down(),
                    };
                    let x = if i == 0 {
                        lo
                    } else if i == 1 {
                        lo + width
                    } else {
                        x
                    };
                    let p = DVec3::new(x, 0.0, 0.0);
                    MeshTriangle {
                        p: [p; 3],
                        face: i as u32,
                    }
                })
                .collect();
            check_leaves(&tris, &MeshBvh::build(&tris), true);
        }
    }

    #[test]
    fn coincident_triangles_make_one_leaf_and_empty_meshes_no_node() {
        let t = grid(1)[0];
        let same = vec![t; 9];
        let bvh = MeshBvh::build(&same);
        assert_eq!(bvh.nodes.len(), 1);
        assert_eq!(bvh.nodes[0].count, 9);
        assert!(MeshBvh::build(&[]).nodes.is_empty());
    }
}
