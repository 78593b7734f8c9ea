//! Mesh-light topology on arbitrary bytes (DESIGN.md §7 M1): the bytes become a mesh's
//! `points` (any f32, non-finite and huge included), `faceVertexCounts` and `faceVertexIndices`
//! (negative, zero, out of range), `holeIndices`, `orientation`, `doubleSided`, a transform
//! (mirrors, shears, singular ones) and LightAPI/ShapingAPI inputs, and go through what a stage's
//! mesh light goes through: the triangle count checked against its limit, fan triangulation,
//! validation and preparation (the BVH), then every query at a few points.
//! Invariants beyond "no panic, no hang, bounded memory": a light that prepares gives finite,
//! non-negative emission, radiance, irradiance and intensity.
#![no_main]

#[path = "bytes.rs"]
mod bytes;

use bytes::Bytes;
use glam::{DMat4, DVec3};
use luxeval::testkit::Rng;
use luxeval::{Light, LightType, MeshGeometry, MeshTopology, Reference, Shaping, TemperatureMode};

const POINTS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [3.0, 1.0, -2.0],
    [-1.5, -2.0, 0.5],
    [0.2, 6.0, 4.0],
];

fn finite_non_negative(v: DVec3, what: &str) {
    assert!(
        v.is_finite() && v.min_element() >= 0.0,
        "{what}: {v} for finite input"
    );
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let n_points = (b.u8() % 48) as usize;
    let points: Vec<[f64; 3]> = (0..n_points)
        .map(|_| [b.value(), b.value(), b.value()])
        .collect();
    let n_faces = (b.u8() % 32) as usize;
    // Counts: mostly 3-6, any small signed value after a marker.
    let counts: Vec<i32> = (0..n_faces)
        .map(|_| match b.u8() {
            0xFE => i32::from(b.i16()),
            c => 3 + i32::from(c % 4),
        })
        .collect();
    let total: i64 = counts.iter().map(|&c| i64::from(c.max(0))).sum();
    let extra = i64::from(b.u8() % 3) - 1; // a sum that is off by one now and then
    let n_indices = (total + extra).clamp(0, 256) as usize;
    let indices: Vec<i32> = (0..n_indices)
        .map(|_| match b.u8() {
            0xFD => i32::from(b.i16()),
            i => i32::from(i) % (n_points.max(1) as i32),
        })
        .collect();
    let holes: Vec<i32> = (0..b.u8() % 3).map(|_| i32::from(b.i16() % 40)).collect();
    let flags = b.u8();
    let topology = MeshTopology {
        points: &points,
        face_vertex_counts: &counts,
        face_vertex_indices: &indices,
        hole_indices: &holes,
        left_handed: flags & 1 != 0,
    };
    let world = match (flags >> 1) % 6 {
        0 => DMat4::IDENTITY,
        1 => DMat4::from_scale(DVec3::new(-1.0, 2.0, 0.5)),
        2 => DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0)), // singular
        3 => DMat4::from_cols_array(&[
            1.0, 0.3, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.7, 0.0, 1.0, 0.0, 1.0, 2.0, 3.0, 1.0,
        ]),
        4 => DMat4::from_scale(DVec3::splat(1e-9)),
        _ => DMat4::from_rotation_y(b.value()),
    };
    if MeshGeometry::fan_triangles(&topology).is_err() {
        return;
    }
    let Ok(geometry) = MeshGeometry::triangulate(&topology, world) else {
        return;
    };
    let mut light = Light::mesh(geometry)
        .with_path("/Fuzz/Mesh")
        .with_transform(world)
        .with_normalize(flags & 0x10 != 0);
    if let LightType::Mesh { double_sided, .. } = &mut light.kind {
        *double_sided = flags & 0x20 != 0;
    }
    if flags & 0x40 != 0 {
        light = light.with_shaping(Shaping {
            focus: b.value(),
            focus_tint: DVec3::new(0.5, 0.7, 1.0),
            cone_angle: b.value() * 30.0,
            cone_softness: b.value(),
            ies: None,
        });
    }
    let Ok(r) = Reference::new(&light, TemperatureMode::Spec) else {
        return;
    };
    let mut rng = Rng::new(u64::from(flags));
    for p in POINTS {
        let x = DVec3::from_array(p);
        let w = rng.unit();
        finite_non_negative(r.emission(w), "emission");
        finite_non_negative(r.intensity(w), "intensity");
        finite_non_negative(r.radiance(x, w), "radiance");
        finite_non_negative(r.irradiance(x, rng.unit()), "irradiance");
    }
});
