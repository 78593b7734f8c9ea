//! The first triangle of a mesh light a ray meets (DESIGN.md §7 M3 `radiance`), through the
//! prepared hierarchy ([`crate::prepare::mesh_bvh`]).
//!
//! Ray–triangle intersection by Möller & Trumbore (1997, "Fast, minimum storage ray-triangle
//! intersection"), in f64, with the edge tests inclusive (a ray through an edge or a vertex shared
//! by two triangles hits one of them, never neither). Equal distances keep the triangle that
//! comes first in face and fan order (M1), whatever order the traversal meets them in.

use glam::DVec3;

use crate::prepare::mesh_bvh::{Aabb, MeshBvh};

/// The hit: the triangle's index, its distance along the ray and whether the ray meets the
/// triangle's front (the side its cross product points to, against the ray).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub triangle: u32,
    pub t: f64,
    pub front: bool,
}

/// The distance `t > 0` at which the ray `o + t·d` meets the triangle `(p0, p1 − p0, p2 − p0)`
/// ([`MeshBvh::edges`]; edges included), and whether it meets its front; `None` when it misses
/// or runs in the triangle's plane.
fn intersect_edges(&[p0, e1, e2]: &[DVec3; 3], o: DVec3, d: DVec3) -> Option<(f64, bool)> {
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - p0;
    let u = s.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if !(v >= 0.0 && u + v <= 1.0) {
        return None;
    }
    let t = e2.dot(q) * inv;
    // det = −d·(e1 × e2): positive when the ray runs against the front normal.
    (t > 0.0 && t.is_finite()).then_some((t, det > 0.0))
}

/// The slab test (Kay & Kajiya 1986): the distance at which the ray enters `b` (0 when it
/// starts inside), or `None` when it misses `b` or enters it beyond `t_max`.
fn enter_box(b: &Aabb, o: DVec3, inv_d: DVec3, t_max: f64) -> Option<f64> {
    let t0 = (b.min - o) * inv_d;
    let t1 = (b.max - o) * inv_d;
    // NaN (0 · ∞ for a ray in a slab's plane) is treated as inside: min/max ignore it.
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element();
    (near <= far && near <= t_max).then_some(near)
}

/// Deepest traversal stack: a binned-SAH tree over at most 2³² triangles stays far below it,
/// and a deeper one (a pathological split) falls back to a heap-allocated stack.
const STACK: usize = 64;

/// The traversal's stack of (node, distance at which the ray enters its box): on the call's
/// own stack up to [`STACK`] entries, then on the heap.
struct Stack {
    fixed: [(u32, f64); STACK],
    top: usize,
    spill: Vec<(u32, f64)>,
}

impl Stack {
    fn new() -> Stack {
        Stack {
            fixed: [(0, 0.0); STACK],
            top: 0,
            spill: Vec::new(),
        }
    }

    fn push(&mut self, k: u32, t: f64) {
        if self.top < STACK {
            self.fixed[self.top] = (k, t);
            self.top += 1;
        } else {
            self.spill.push((k, t));
        }
    }

    fn pop(&mut self) -> Option<(u32, f64)> {
        if let Some(k) = self.spill.pop() {
            return Some(k);
        }
        self.top = self.top.checked_sub(1)?;
        Some(self.fixed[self.top])
    }
}

/// The first triangle the ray `o + t·d`, t > 0, meets. Children are visited nearer first, so
/// that the nearest hit found early prunes the rest; a node's box is tested once, when its
/// parent is, and skipped when popped if a hit nearer than its entry was found since.
pub fn first_hit(bvh: &MeshBvh, o: DVec3, d: DVec3) -> Option<Hit> {
    if bvh.nodes.is_empty() {
        return None;
    }
    let inv_d = d.recip();
    let mut best: Option<Hit> = None;
    let mut stack = Stack::new();
    match enter_box(&bvh.nodes[0].bounds, o, inv_d, f64::INFINITY) {
        Some(t) => stack.push(0, t),
        None => return None,
    }
    while let Some((k, t_enter)) = stack.pop() {
        let t_max = best.map_or(f64::INFINITY, |h| h.t);
        if t_enter > t_max {
            continue;
        }
        let node = &bvh.nodes[k as usize];
        if node.count == 0 {
            let (left, right) = (k + 1, node.first);
            let tl = enter_box(&bvh.nodes[left as usize].bounds, o, inv_d, t_max);
            let tr = enter_box(&bvh.nodes[right as usize].bounds, o, inv_d, t_max);
            // Push the farther first, so the nearer is popped next.
            match (tl, tr) {
                (Some(a), Some(b)) if a <= b => {
                    stack.push(right, b);
                    stack.push(left, a);
                }
                (Some(a), Some(b)) => {
                    stack.push(left, a);
                    stack.push(right, b);
                }
                (Some(a), None) => stack.push(left, a),
                (None, Some(b)) => stack.push(right, b),
                (None, None) => {}
            }
            continue;
        }
        let range = node.first as usize..(node.first + node.count) as usize;
        for (&i, edges) in bvh.order[range.clone()].iter().zip(&bvh.edges[range]) {
            if let Some((t, front)) = intersect_edges(edges, o, d) {
                let better = match best {
                    None => true,
                    Some(b) => t < b.t || (t == b.t && i < b.triangle),
                };
                if better {
                    best = Some(Hit {
                        triangle: i,
                        t,
                        front,
                    });
                }
            }
        }
    }
    best
}

/// Every triangle the ray `o + t·d`, t > 0, meets, in no particular order: `hit(triangle, t)`.
/// The density of a direction drawn by area sums over all of them (`cpu::mesh::sample`).
pub fn all_hits(bvh: &MeshBvh, o: DVec3, d: DVec3, mut hit: impl FnMut(u32, f64)) {
    if bvh.nodes.is_empty() {
        return;
    }
    let inv_d = d.recip();
    let mut stack = Stack::new();
    stack.push(0, 0.0);
    while let Some((k, _)) = stack.pop() {
        let node = &bvh.nodes[k as usize];
        if enter_box(&node.bounds, o, inv_d, f64::INFINITY).is_none() {
            continue;
        }
        if node.count == 0 {
            stack.push(node.first, 0.0);
            stack.push(k + 1, 0.0);
            continue;
        }
        let range = node.first as usize..(node.first + node.count) as usize;
        for (&i, edges) in bvh.order[range.clone()].iter().zip(&bvh.edges[range]) {
            if let Some((t, _)) = intersect_edges(edges, o, d) {
                hit(i, t);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::MeshTriangle;

    fn tri(z: f64, flip: bool) -> MeshTriangle {
        let (a, b) = (DVec3::new(2.0, -1.0, z), DVec3::new(-1.0, 2.0, z));
        let p = if flip {
            [DVec3::new(-1.0, -1.0, z), b, a]
        } else {
            [DVec3::new(-1.0, -1.0, z), a, b]
        };
        MeshTriangle { p, face: 0 }
    }

    #[test]
    fn nearest_of_a_stack_and_its_side() {
        // Fronts toward +z (cross of (3,0,0) and (0,3,0)); the ray comes from below going up.
        let tris: Vec<MeshTriangle> = (0..40).map(|k| tri(k as f64, k % 2 == 1)).collect();
        let bvh = MeshBvh::build(&tris);
        let o = DVec3::new(0.1, 0.2, 12.5);
        let up = first_hit(&bvh, o, DVec3::Z).unwrap();
        assert_eq!((up.triangle, up.t), (13, 0.5));
        assert!(up.front); // flipped: its front faces −z, toward the ray's origin.
        let down = first_hit(&bvh, o, -DVec3::Z).unwrap();
        assert_eq!((down.triangle, down.t), (12, 0.5));
        assert!(down.front);
        let miss = first_hit(&bvh, DVec3::new(5.0, 5.0, 0.5), DVec3::Z);
        assert!(miss.is_none());
    }

    #[test]
    fn equal_distances_keep_the_first_triangle_and_shared_edges_are_hit() {
        // Two coincident triangles, and a ray through the diagonal of a quad's two triangles.
        let t = tri(1.0, false);
        let tris = vec![t, t, t];
        let bvh = MeshBvh::build(&tris);
        let h = first_hit(&bvh, DVec3::ZERO, DVec3::Z).unwrap();
        assert_eq!(h.triangle, 0);
        let quad = [
            MeshTriangle {
                p: [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0)],
                face: 0,
            },
            MeshTriangle {
                p: [DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
                face: 0,
            },
        ];
        let bvh = MeshBvh::build(&quad);
        let h = first_hit(&bvh, DVec3::new(0.5, 0.5, -1.0), DVec3::Z).unwrap();
        assert_eq!((h.triangle, h.t, h.front), (0, 1.0, false));
    }
}
