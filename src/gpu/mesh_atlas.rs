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
//! Per masked dome (`Prepared::portals`, DESIGN.md §8 P2; read by shaders/portal.wgsl and
//! shaders/irradiance/portals.wgsl): the portal count as u32 bits, then [`PORTAL_WORDS`] words
//! a portal, in the `portals` relationship's order (ties go to the earlier): origin xyz, unit
//! normal xyz, the world → local map's rows (3 × 3), half width and height, multiplier rgb,
//! then its parallelogram as corner `c0` (local −,−) and edges `c1 − c0`, `c3 − c0` (xyz each,
//! subtracted in f64, then rounded); then the overlaps whose irradiance terms the device sums
//! (`Prepared::portal_overlaps`, read by shaders/irradiance/portals.wgsl): their count as u32
//! bits, then [`OVERLAP_WORDS`] words each: the portals' indices in `Overlap::members`' order
//! as u32 bits, `u32::MAX` past the last, then the split word ([`SPLIT`]). The record's `tex.w` holds the block's offset and `FLAG_PORTALS`
//! says it is there (a textured dome keeps `tex.xyz`).

use crate::prepare::{KindData, Prepared};

/// Words per node, per triangle and per portal.
pub const NODE_WORDS: u32 = 8;
pub const TRIANGLE_WORDS: u32 = 10;
pub const PORTAL_WORDS: u32 = 29;
/// Member words per overlap: the most portals one ray may cross that the kernel clips.
pub const OVERLAP_MEMBERS: u32 = crate::prepare::portal::MOST_PORTALS_ONE_RAY_CROSSES as u32;
/// Words per overlap: its members, then [`SPLIT`] with the `before` bits where it is split
/// (`prepare::portal::Overlap::split`), 0 where not.
pub const OVERLAP_WORDS: u32 = OVERLAP_MEMBERS + 1;
/// The bit of an overlap's last word that says it is split.
pub const SPLIT: u32 = 1 << 31;

/// The constants shaders/mesh/ray.wgsl, shaders/portal.wgsl and shaders/irradiance/portals.wgsl
/// read from the WGSL prelude.
pub fn wgsl_constants() -> [(&'static str, u32); 8] {
    [
        ("MESH_NODE_WORDS", NODE_WORDS),
        ("MESH_TRIANGLE_WORDS", TRIANGLE_WORDS),
        ("MESH_STACK", crate::prepare::MESH_STACK as u32),
        ("PORTAL_WORDS", PORTAL_WORDS),
        ("PORTAL_OVERLAP_WORDS", OVERLAP_WORDS),
        ("PORTAL_OVERLAP_MEMBERS", OVERLAP_MEMBERS),
        ("PORTAL_OVERLAP_SPLIT", SPLIT),
        // A convex polygon gains at most one vertex a clip: the first portal's four, then one
        // for each edge of the others, for each plane of a split overlap's piece and for the
        // horizon of a textured dome (shaders/irradiance/portals.wgsl).
        (
            "PORTAL_OVERLAP_VERTICES",
            4 * OVERLAP_MEMBERS + (OVERLAP_MEMBERS - 1) + 1,
        ),
    ]
}

/// The scene's mesh atlas and, per light, its `tex` words where the kernels read the atlas for
/// it: a mesh light's four (the fronts' offset 0 where its emission is the host's), a masked
/// dome's `[0, 0, 0, portals' offset]`.
pub fn scene_atlas(lights: &[Prepared]) -> (Vec<f32>, Vec<Option<[u32; 4]>>) {
    let mut data: Vec<f32> = Vec::new();
    let offsets =
        lights
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
                        let c = q.corners;
                        for v in [c[0], c[1] - c[0], c[3] - c[0]] {
                            data.extend(v.to_array().map(|x| x as f32));
                        }
                    }
                    data.push(f32::from_bits(p.portal_overlaps.len() as u32));
                    for set in &p.portal_overlaps {
                        data.extend((0..OVERLAP_MEMBERS as usize).map(|k| {
                            f32::from_bits(set.members.get(k).copied().unwrap_or(u32::MAX))
                        }));
                        let split = set.split.map_or(0, |before| SPLIT | u32::from(before));
                        data.push(f32::from_bits(split));
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
    use crate::model::{Light, MeshGeometry, MeshTopology, Portal};
    use crate::prepare::gpu_path::{MESH_FRONTS_ON_DEVICE, PORTALS_ON_DEVICE};
    use crate::prepare::{GpuPath, PortalMode, Prepared, TemperatureMode};
    use glam::{DMat4, DVec3};

    /// A fan of `k` triangles about the origin, each tilted differently: `k` distinct fronts.
    fn fan(k: usize) -> Light {
        let mut points = vec![[0.0, 0.0, 0.0]];
        for i in 0..=k {
            let t = 3.0 * i as f64 / k as f64;
            points.push([t.cos(), t.sin(), 0.1 * (i % 7) as f64]);
        }
        let counts = vec![3; k];
        let indices: Vec<i32> = (0..k as i32).flat_map(|i| [0, i + 1, i + 2]).collect();
        let geometry = MeshGeometry::triangulate(
            &MeshTopology {
                points: &points,
                face_vertex_counts: &counts,
                face_vertex_indices: &indices,
                hole_indices: &[],
                left_handed: false,
            },
            DMat4::IDENTITY,
        )
        .unwrap();
        Light::mesh(geometry)
    }

    fn prep(l: &Light) -> Prepared {
        Prepared::new(l, TemperatureMode::Spec).unwrap()
    }

    /// A mesh facing at most MESH_FRONTS_ON_DEVICE directions has its fronts in the atlas after
    /// its triangles (`tex.w`: the count, then xyz each); one facing more has none, and its
    /// emission is the host's (the one decision, GpuPath).
    #[test]
    fn fronts_follow_the_triangles_up_to_the_cap() {
        let small = prep(&fan(10));
        assert_eq!(small.gpu_path, GpuPath::HostIntensity("it is a mesh light"));
        let big = prep(&fan(MESH_FRONTS_ON_DEVICE + 1));
        assert!(matches!(big.gpu_path, GpuPath::RadianceOnDevice(_)));
        assert!(big.emission_on_host() && !big.radiance_on_host());
        let (data, words) = scene_atlas(&[small.clone(), big]);
        let w = words[0].unwrap();
        let KindData::Mesh { fronts, bvh, .. } = &small.kind else {
            unreachable!()
        };
        assert_eq!(fronts.len(), 10);
        assert_eq!(w[3], w[2] + TRIANGLE_WORDS * bvh.order.len() as u32);
        assert_eq!(data[w[3] as usize].to_bits(), 10);
        for (k, n) in fronts.iter().enumerate() {
            let at = w[3] as usize + 1 + 3 * k;
            assert_eq!(&data[at..at + 3], &n.to_array().map(|c| c as f32));
        }
        assert_eq!(words[1].unwrap()[3], 0);
    }

    /// A dome masked by more portals than the kernel tests (lavapipe's loop budget) stays on the
    /// host on every query, and nothing of it goes to the atlas.
    #[test]
    fn a_dome_masked_by_too_many_portals_stays_on_the_host() {
        let dome = (0..=PORTALS_ON_DEVICE).fold(Light::dome(), |l, i| {
            l.with_portal(
                Portal::new(0.5, 0.5)
                    .with_transform(DMat4::from_translation(DVec3::new(i as f64, 0.0, 3.0))),
            )
        });
        let mut p = prep(&dome);
        p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
            .unwrap();
        assert!(matches!(p.gpu_path, GpuPath::Host(_)) && p.radiance_on_host());
        let (data, words) = scene_atlas(&[p]);
        assert!(data.is_empty() && words == [None]);
    }

    /// A masked dome's portals: count, then PORTAL_WORDS each, in order; `tex.w` their offset.
    #[test]
    fn portals_are_packed_in_order() {
        let dome = Light::dome()
            .with_portal(
                Portal::new(2.0, 1.0)
                    .with_transform(DMat4::from_translation(DVec3::new(0.0, 0.0, 3.0)))
                    .with_intensity(2.0),
            )
            .with_portal(
                Portal::new(1.0, 4.0).with_transform(DMat4::from_scale(DVec3::splat(2.0))),
            );
        let mut p = prep(&dome);
        p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
            .unwrap();
        // The second portal's plane z = 0 lies below the first (z = 3): a ray up through both,
        // the second first; their multipliers differ, so the first's counts for the overlap.
        assert_eq!(p.gpu_path, GpuPath::Device);
        assert_eq!(
            p.portal_overlaps,
            [crate::prepare::portal::Overlap::whole(&[0, 1])]
        );
        let (data, words) = scene_atlas(&[prep(&fan(3)), p]);
        let at = words[1].unwrap()[3] as usize;
        assert!(at > 0);
        assert_eq!(data[at].to_bits(), 2);
        let first = &data[at + 1..at + 1 + PORTAL_WORDS as usize];
        assert_eq!(&first[..6], &[0.0, 0.0, 3.0, 0.0, 0.0, 1.0]);
        assert_eq!(&first[15..20], &[1.0, 0.5, 2.0, 2.0, 2.0]);
        // Corner (−1, −0.5, 3), edges along x (2) and y (1).
        assert_eq!(
            &first[20..],
            &[-1.0, -0.5, 3.0, 2.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        );
        let second = &data[at + 1 + PORTAL_WORDS as usize..];
        assert_eq!(
            second.len(),
            PORTAL_WORDS as usize + 1 + OVERLAP_WORDS as usize
        );
        // Then the one overlap, the farther portal first.
        let bits: Vec<u32> = second[PORTAL_WORDS as usize..]
            .iter()
            .map(|v| v.to_bits())
            .collect();
        assert_eq!(bits, [1, 0, 1, u32::MAX, u32::MAX, 0]);
        // World → local of a uniform scale 2: rows of 0.5·I; half extents in local units.
        assert_eq!(
            &second[6..17],
            &[0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 0.5, 2.0]
        );
    }

    /// Three stacked panes of one multiplier and a window apart: the overlaps after the
    /// portals, count then OVERLAP_WORDS each (indices ascending, u32::MAX past the last, then
    /// the split word: 0, one multiplier).
    #[test]
    fn overlaps_are_packed_after_the_portals() {
        let pane = |z: f64| {
            Portal::new(1.0, 1.0).with_transform(DMat4::from_translation(DVec3::new(0.0, 0.0, z)))
        };
        let side = Portal::new(1.0, 1.0).with_transform(DMat4::from_rotation_translation(
            glam::DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
            DVec3::new(5.0, 0.0, 0.0),
        ));
        let dome = [pane(1.0), side, pane(2.0), pane(3.0)]
            .into_iter()
            .fold(Light::dome(), |l, q| l.with_portal(q));
        let mut p = prep(&dome);
        p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
            .unwrap();
        assert_eq!(p.gpu_path, GpuPath::Device);
        let (data, words) = scene_atlas(&[p]);
        let at = words[0].unwrap()[3] as usize + 1 + 4 * PORTAL_WORDS as usize;
        let bits: Vec<u32> = data[at..].iter().map(|v| v.to_bits()).collect();
        let none = u32::MAX;
        assert_eq!(
            bits,
            [
                4, 0, 2, none, none, 0, 0, 2, 3, none, 0, 0, 3, none, none, 0, 2, 3, none, none, 0
            ]
        );
    }

    #[test]
    fn boxes_round_outward() {
        for v in [0.1, -0.1, 1.0 / 3.0, -7.3e5, 1e-30] {
            assert!(down(v) as f64 <= v && up(v) as f64 >= v, "{v}");
        }
        assert_eq!((down(0.5), up(0.5)), (0.5, 0.5));
    }
}
