//! Every mesh light's BVH and triangles in one f32 array per scene, for the radiance kernel's
//! first-hit traversal (shaders/mesh/ray.wgsl; DESIGN.md §7 M3). Per mesh light, from its base
//! offset:
//! - its nodes, 8 words each: the box's min xyz and max xyz, rounded outward to f32 (so the f32
//!   traversal never skips a box the f64 one enters), then `first` and `count` as u32 bits
//!   (prepare::mesh_bvh's layout: a leaf holds `count > 0` triangles from `first`; an inner
//!   node's left child is the next node, its right child `first`);
//! - then its triangles in the leaves' order, 10 words each: `p0`, `p1 − p0`, `p2 − p0` (the
//!   edges subtracted in f64, then rounded), and the triangle's index in face and fan order as
//!   u32 bits (ties keep the lower, as the CPU reference does).
//!
//! The record's `tex` holds (nodes' offset, node count, triangles' offset, 0).

use crate::prepare::{GpuPath, KindData, Prepared};

/// Words per node and per triangle.
pub const NODE_WORDS: u32 = 8;
pub const TRIANGLE_WORDS: u32 = 10;

/// The constants shaders/mesh/ray.wgsl reads from the WGSL prelude.
pub fn wgsl_constants() -> [(&'static str, u32); 3] {
    [
        ("MESH_NODE_WORDS", NODE_WORDS),
        ("MESH_TRIANGLE_WORDS", TRIANGLE_WORDS),
        ("MESH_STACK", crate::prepare::MESH_STACK as u32),
    ]
}

/// The scene's mesh atlas and, per light, its `tex` words where the kernel traverses it.
pub fn scene_atlas(lights: &[Prepared]) -> (Vec<f32>, Vec<Option<[u32; 4]>>) {
    let mut data: Vec<f32> = Vec::new();
    let offsets = lights
        .iter()
        .map(|p| {
            let KindData::Mesh { bvh, .. } = &p.kind else {
                return None;
            };
            if !matches!(p.gpu_path, GpuPath::RadianceOnDevice(_)) {
                return None;
            }
            let nodes = data.len() as u32;
            for n in &bvh.nodes {
                for v in n.bounds.min.to_array() {
                    data.push(down(v));
                }
                for v in n.bounds.max.to_array() {
                    data.push(up(v));
                }
                data.push(f32::from_bits(n.first));
                data.push(f32::from_bits(n.count));
            }
            let triangles = data.len() as u32;
            for (&i, e) in bvh.order.iter().zip(&bvh.edges) {
                for v in e {
                    data.extend(v.to_array().map(|c| c as f32));
                }
                data.push(f32::from_bits(i));
            }
            Some([nodes, bvh.nodes.len() as u32, triangles, 0])
        })
        .collect();
    (data, offsets)
}

/// The largest f32 at most `v`.
fn down(v: f64) -> f32 {
    let f = v as f32;
    if f as f64 > v { f.next_down() } else { f }
}

/// The smallest f32 at least `v`.
fn up(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) < v { f.next_up() } else { f }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_round_outward() {
        for v in [0.1, -0.1, 1.0 / 3.0, -7.3e5, 1e-30] {
            assert!(down(v) as f64 <= v && up(v) as f64 >= v, "{v}");
        }
        assert_eq!((down(0.5), up(0.5)), (0.5, 0.5));
    }
}
