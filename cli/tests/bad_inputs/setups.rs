//! The bad-input corpus' setups: what a case prepares in `{in}/` after the corpus files are
//! copied there (links, pipes, directories, devices, stages that read files through the stage).

use std::path::Path;

pub(super) fn mkdir_sub(d: &Path) {
    std::fs::create_dir(d.join("sub")).unwrap();
}
pub(super) fn symlink_dirs(d: &Path) {
    std::os::unix::fs::symlink(d.join("dirs.npy"), d.join("link.npy")).unwrap();
}
pub(super) fn hardlink_dirs(d: &Path) {
    std::fs::hard_link(d.join("dirs.npy"), d.join("hard.npy")).unwrap();
}
/// `{in}/many_dirs.npy`: 100 valid float32 directions (1 328 bytes), larger than the limits
/// its case sets.
pub(super) fn many_dirs(d: &Path) {
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (100, 3), }";
    let mut h = header.to_string();
    while !(10 + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(h.len() as u16).to_le_bytes());
    bytes.extend_from_slice(h.as_bytes());
    for i in 0..100 {
        let a = i as f32 * 0.37;
        for v in [a.cos(), -0.5, a.sin()] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(d.join("many_dirs.npy"), bytes).unwrap();
}

pub(super) fn fifo(d: &Path) {
    let p = std::ffi::CString::new(d.join("pipe").to_str().unwrap()).unwrap();
    // SAFETY: a valid C string.
    assert_eq!(unsafe { libc::mkfifo(p.as_ptr(), 0o644) }, 0);
}
pub(super) fn mkfifo(p: &Path) {
    let p = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    // SAFETY: a valid C string.
    assert_eq!(unsafe { libc::mkfifo(p.as_ptr(), 0o644) }, 0);
}
pub(super) fn fifo_ies(d: &Path) {
    mkfifo(&d.join("missing.ies"));
}
pub(super) fn zero_ies(d: &Path) {
    std::os::unix::fs::symlink("/dev/zero", d.join("missing.ies")).unwrap();
}
pub(super) fn fifo_tilt(d: &Path) {
    mkfifo(&d.join("nothere.tilt"));
}
/// A dome whose texture is `sky.exr`, made by `make`.
pub(super) fn dome_with(d: &Path, make: fn(&Path)) {
    std::fs::write(
        d.join("dome_sky.usda"),
        "#usda 1.0\ndef DomeLight \"D\"\n{\n    asset inputs:texture:file = @sky.exr@\n}\n",
    )
    .unwrap();
    make(&d.join("sky.exr"));
}
pub(super) fn fifo_texture(d: &Path) {
    dome_with(d, mkfifo);
}
pub(super) fn zero_texture(d: &Path) {
    dome_with(d, |p| std::os::unix::fs::symlink("/dev/zero", p).unwrap());
}
/// Stages whose light reads files through the stage: `layered.usda` (a sublayer `sub.usda`
/// holding a spot with the profile `spot.ies`, whose TILT table is `spot.tilt`) and
/// `textured.usda` (a dome whose texture is `sky.png`).
pub(super) fn read_through_the_stage(d: &Path) {
    std::fs::write(
        d.join("layered.usda"),
        "#usda 1.0\n(\n    subLayers = [@sub.usda@]\n)\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sub.usda"),
        "#usda 1.0\ndef SphereLight \"L\" (\n    prepend apiSchemas = [\"ShapingAPI\"]\n)\n{\n    asset inputs:shaping:ies:file = @spot.ies@\n}\n",
    )
    .unwrap();
    std::fs::write(
        d.join("spot.ies"),
        "IESNA:LM-63-2002\nTILT=spot.tilt\n1 -1 1 3 1 1 2 0 0 0\n1 1 100\n0 45 90\n0\n100 50 0\n",
    )
    .unwrap();
    std::fs::write(d.join("spot.tilt"), "1\n3\n0 45 90\n1 0.8 0.5\n").unwrap();
    std::fs::write(
        d.join("textured.usda"),
        "#usda 1.0\ndef DomeLight \"D\"\n{\n    asset inputs:texture:file = @sky.png@\n}\n",
    )
    .unwrap();
    std::fs::copy(
        crate::repo().join("tests/data/textures/testImage.png"),
        d.join("sky.png"),
    )
    .unwrap();
}
pub(super) fn zero_dirs(d: &Path) {
    std::os::unix::fs::symlink("/dev/zero", d.join("zero.npy")).unwrap();
}
pub(super) fn zero_scene(d: &Path) {
    std::os::unix::fs::symlink("/dev/zero", d.join("zero.usda")).unwrap();
}
pub(super) fn zero_sublayer(d: &Path) {
    std::os::unix::fs::symlink("/dev/zero", d.join("zero.usda")).unwrap();
    std::fs::write(
        d.join("sublayer_zero.usda"),
        "#usda 1.0\n(\n    subLayers = [@zero.usda@]\n)\n",
    )
    .unwrap();
}

/// The mesh-light stages made by usd-core (tools/gen_usd_fixtures.py --only-mesh): the bad
/// topologies of tests/data/usd/mesh/bad/ and the good scene beside them.
pub(super) fn mesh_stages(d: &Path) {
    let mesh = crate::repo().join("tests/data/usd/mesh");
    for dir in [mesh.join("bad"), mesh.clone()] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                std::fs::copy(&p, d.join(p.file_name().unwrap())).unwrap();
            }
        }
    }
}
