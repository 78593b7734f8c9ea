//! Every mesh light's BVH, triangles and front directions, and every masked dome's portals, in
//! one f32 array per scene: what the kernels read of a light beyond its record. Per mesh light,
//! from its base offset:
//! - its nodes, 8 words each: the box's min xyz and max xyz, rounded outward to f32 (so the f32
//!   traversal never skips a box the f64 one enters), then `first` and `count` as u32 bits
//!   (prepare::mesh_bvh's layout: a leaf holds `count > 0` triangles from `first`; an inner
//!   node's left child is the next node, its right child `first`);
//! - then its triangles in the leaves' order, 10 words each: `p0`, `p1 − p0`, `p2 − p0` (the
//!   edges subtracted in f64, then rounded), and the triangle's index in face and fan order as
//!   u32 bits (ties keep the lower, as the CPU reference does);
//! - where its emission is the device's (`GpuPath::HostIntensity`), its distinct front
//!   directions (`KindData::Mesh::fronts`, DESIGN.md §7 M3 emission): their count as u32 bits,
//!   then 3 words each, in prepare's order (largest area first).
//!
//! The record's `tex` holds (nodes' offset, node count, triangles' offset, fronts' offset) and
//! `FLAG_MESH_FRONTS` says the fronts are there.
//!
//! Per masked dome (`Prepared::portals`, DESIGN.md §8 P2; read by shaders/portal.wgsl): the
//! portal count as u32 bits, then [`PORTAL_WORDS`] words a portal, in the `portals`
//! relationship's order (ties go to the earlier): origin xyz, unit normal xyz, the world → local
//! map's rows (3 × 3), half width and height, multiplier rgb. The record's `tex.w` holds the
//! block's offset and `FLAG_PORTALS` says it is there (a textured dome keeps `tex.xyz`).

use crate::prepare::{KindData, Prepared};

/// Words per node, per triangle and per portal.
pub const NODE_WORDS: u32 = 8;
pub const TRIANGLE_WORDS: u32 = 10;
pub const PORTAL_WORDS: u32 = 20;

/// The constants shaders/mesh/ray.wgsl and shaders/portal.wgsl read from the WGSL prelude.
pub fn wgsl_constants() -> [(&'static str, u32); 4] {
    [
        ("MESH_NODE_WORDS", NODE_WORDS),
        ("MESH_TRIANGLE_WORDS", TRIANGLE_WORDS),
        ("MESH_STACK", crate::prepare::MESH_STACK as u32),
        ("PORTAL_WORDS", PORTAL_WORDS),
    ]
}

/// The scene's mesh atlas and, per light, its `tex` words where the kernels read the atlas for
/// it: a mesh light's four (the fronts' offset 0 where its emission is the host's), a masked
/// dome's `[0, 0, 0, portals' offset]`.
pub fn scene_atlas(lights: &[Prepared]) -> (Vec<f32>, Vec<Option<[u32; 4]>>) {
    let mut data: Vec<f32> = Vec::new();
    let offsets = lights
        .iter()
        .map(|p| {
            if let Some(portals) = &p.portals {
                if p.radiance_on_host() {
                    return None;
                }
                let at = data.len() as u32;
                data.push(f32::from_bits(portals.len() as u32));
                for q in portals {
                    data.extend(q.origin.to_array().map(|c| c as f32));
                    data.extend(q.normal.to_array().map(|c| c as f32));
                    for i in 0..3 {
                        data.extend(q.to_local.row(i).to_array().map(|c| c as f32));
                    }
                    data.extend(q.half.to_array().map(|c| c as f32));
                    data.extend(q.multiplier.to_array().map(|c| c as f32));
                }
                return Some([0, 0, 0, at]);
            }
            let KindData::Mesh { bvh, fronts, .. } = &p.kind else {
                return None;
            };
            if p.radiance_on_host() {
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
            let mut front_words = 0;
            if !p.emission_on_host() {
                front_words = data.len() as u32;
                data.push(f32::from_bits(fronts.len() as u32));
                for n in fronts.iter() {
                    data.extend(n.to_array().map(|c| c as f32));
                }
            }
            Some([nodes, bvh.nodes.len() as u32, triangles, front_words])
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
