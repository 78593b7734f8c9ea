//! Portals from the command line (DESIGN.md §8 P2): `--portal-mode` on the scene commands, the
//! window fixture (tests/data/usd/portal/window.usda, checked to open with usd-core) evaluated
//! in both modes against Lambert's formula computed here.

use std::path::Path;

use luxeval_cli::io::npy;

use crate::support::*;

/// Unit-radiance irradiance of a planar polygon wholly above the receiver's horizon, from the
/// vectors `v` from x to its vertices: `½ |Σ θ_i n·û_i|` (Lambert 1760).
fn lambert(v: &[[f64; 3]], n: [f64; 3]) -> f64 {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let unit = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        a.map(|c| c / l)
    };
    let mut s = 0.0;
    for i in 0..v.len() {
        let (a, b) = (unit(v[i]), unit(v[(i + 1) % v.len()]));
        s += dot(a, b).clamp(-1.0, 1.0).acos() * dot(n, unit(cross(a, b)));
    }
    0.5 * s.abs()
}

fn irradiance(dir: &Path, extra: &[&str], per_light: bool) -> (Vec<u64>, Vec<f32>) {
    let points = dir.join("p.npy");
    let normals = dir.join("n.npy");
    // Receivers at the origin facing the window (+Z) and away from it (−Z); one on the
    // window's +Z side (z = 4) facing −Z, which the dome does not reach through it.
    npy::write_f32(&points, &[3, 3], &[[0.0; 3], [0.0; 3], [0.0, 1.0, 4.0]]).unwrap();
    npy::write_f32(
        &normals,
        &[3, 3],
        &[[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0]],
    )
    .unwrap();
    let out = dir.join("e.npy");
    let mut args = vec![
        "irradiance",
        "REPLACE",
        "--points",
        points.to_str().unwrap(),
        "--normals",
        normals.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--device",
        "cpu",
    ];
    let scene = repo_file("tests/data/usd/portal/window.usda");
    args[1] = &scene;
    if per_light {
        args.push("--per-light");
    }
    args.extend_from_slice(extra);
    let o = luxeval(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    read_npy_f32(&out)
}

/// `--portal-mode mask` changes the irradiance of a stage with a window portal: the dome's 2
/// nits times the window's multiplier 0.5 times Lambert's formula of the 2 × 1 window at
/// z = 3 (centre (0, 1)), 0 facing away and from the window's +Z side; hint mode (the default)
/// is the unmasked dome, π · 2. The dome also names an invisible 10 × 10 portal in front of the
/// window with multiplier 100: ignored, as if not named (P1). Portals are never rows of
/// `--per-light`.
#[test]
fn portal_mode_mask_changes_irradiance_through_a_window() {
    let dir = tempfile::tempdir().unwrap();
    let (shape, hint) = irradiance(dir.path(), &[], false);
    assert_eq!(shape, vec![3, 3]);
    // π L for a uniform dome of L = 2 on a receiver facing up.
    let pi_l = (std::f64::consts::PI * 2.0) as f32;
    assert_eq!(&hint[0..3], &[pi_l; 3]);
    let (_, explicit) = irradiance(dir.path(), &["--portal-mode", "hint"], false);
    assert_eq!(explicit, hint);

    let (shape, mask) = irradiance(dir.path(), &["--portal-mode", "mask"], false);
    assert_eq!(shape, vec![3, 3]);
    let window = [
        [-1.0, 0.5, 3.0],
        [1.0, 0.5, 3.0],
        [1.0, 1.5, 3.0],
        [-1.0, 1.5, 3.0],
    ];
    let want = 2.0 * 0.5 * lambert(&window, [0.0, 0.0, 1.0]);
    for &c in &mask[0..3] {
        let got = c as f64;
        assert!((got - want).abs() <= 1e-6 * want, "{got} vs {want}");
    }
    assert_eq!(&mask[3..9], &[0.0; 6]);
    assert_ne!(mask, hint);

    // One dome, one row block: the portals are not lights of their own.
    let (shape, per_light) = irradiance(dir.path(), &["--portal-mode", "mask"], true);
    assert_eq!(shape, vec![1, 3, 3]);
    assert_eq!(per_light, mask);
}

/// Every scene command takes `--portal-mode` (DESIGN.md §4), and sampling refuses a masked
/// dome, naming it, rather than draw with a density that misses the portals.
#[test]
fn every_scene_command_takes_portal_mode() {
    for cmd in [
        "emission",
        "radiance",
        "irradiance",
        "intensity",
        "falloff",
        "check",
        "lights",
        "sample",
        "pdf",
    ] {
        let o = luxeval(&[cmd, "--help"]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("--portal-mode"), "{cmd}: {text}");
    }
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("p.npy");
    npy::write_f32(&points, &[1, 3], &[[0.0; 3]]).unwrap();
    let scene = repo_file("tests/data/usd/portal/window.usda");
    let out = dir.path().join("s.npz");
    let o = luxeval(&[
        "sample",
        &scene,
        "--points",
        points.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--device",
        "cpu",
        "--portal-mode",
        "mask",
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("/World/Sky") && err.contains("portal"),
        "{err}"
    );
    assert!(!out.exists());
}

/// `check` on the window room in mask mode compares the masked dome's emission and radiance
/// (on the device since the portal kernel, shaders/portal.wgsl) and, its dome untextured and
/// its windows unable to hide one another, its irradiance (shaders/irradiance/portals.wgsl);
/// nothing of it is host-only.
#[test]
fn check_compares_a_masked_domes_radiance_and_irradiance() {
    check_compares_the_masked_dome(&asset("window_room.usda"));
}

/// The same for a skylight under glazing tilted 5° and turned in its plane (the glazing's own
/// intensity and colour; a ray up crosses the skylight, then the glazing, never the other way)
/// beside a window, read from a stage: the
/// device sums its irradiance by inclusion–exclusion over the overlap
/// (prepare::portal::overlaps), and `check` compares it.
#[test]
fn check_compares_a_domes_irradiance_through_glazing() {
    check_compares_the_glazed_dome("", GLAZING_ABOVE);
}

/// The same with the glazing tilted 30° through the skylight: rays cross the two in either
/// order, so the device splits their overlap where they are crossed at once
/// (prepare::portal::Overlap::split), and `check` compares it, nothing host-only.
#[test]
fn check_compares_a_domes_irradiance_through_crossed_glazing() {
    check_compares_the_glazed_dome(
        "",
        "double3 xformOp:translate = (0.2, 3.05, 0.1)\n        float xformOp:rotateX = -120",
    );
}

/// The glazing's place: 0.4 above the skylight, tilted 5° (rays cross the skylight first).
const GLAZING_ABOVE: &str =
    "double3 xformOp:translate = (0.2, 3.4, 0.1)\n        float xformOp:rotateX = -95";

/// The same glazing over a latlong-textured dome (testImage.png): its irradiance is the
/// device's too (the texture's row integral over each portal and overlap,
/// shaders/irradiance/latlong_polygon.wgsl; on lavapipe the loop budget leaves most receivers
/// of a 1024 × 512 map to the host), and `check` compares it, listing nothing as host-only.
#[test]
fn check_compares_a_textured_domes_irradiance_through_glazing() {
    check_compares_the_glazed_dome(
        concat!(
            "asset inputs:texture:file = @",
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/data/textures/testImage.png@\n        token inputs:texture:format = \"latlong\""
        ),
        GLAZING_ABOVE,
    );
}

/// Writes the glazed stage, `sky` added to the dome's attributes and `glazing` placing the
/// glazing (its translate and rotateX), and checks its dome.
fn check_compares_the_glazed_dome(sky: &str, glazing: &str) {
    let dir = tempfile::tempdir().unwrap();
    let stage = dir.path().join("glazed.usda");
    std::fs::write(
        &stage,
        r#"#usda 1.0
(
    upAxis = "Y"
)

def Xform "World"
{
    def DomeLight "Sky"
    {
        rel portals = [</World/Skylight>, </World/Glazing>, </World/Window>]
        SKY
    }

    def PortalLight "Skylight"
    {
        float inputs:width = 2
        float inputs:height = 2
        double3 xformOp:translate = (0, 3, 0)
        float3 xformOp:rotateXYZ = (-90, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }

    def PortalLight "Glazing"
    {
        float inputs:width = 2.5
        float inputs:height = 2.2
        float inputs:intensity = 0.8
        color3f inputs:color = (0.9, 0.95, 1)
        GLAZING
        float xformOp:rotateZ = 25
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateX", "xformOp:rotateZ"]
    }

    def PortalLight "Window"
    {
        float inputs:width = 2
        float inputs:height = 1.5
        double3 xformOp:translate = (0, 1.75, 3)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
}
"#
        .replace("SKY", sky)
        .replace("GLAZING", glazing),
    )
    .unwrap();
    check_compares_the_masked_dome(stage.to_str().unwrap());
}

/// `check --portal-mode mask` on `stage` compares /World/Sky's emission, radiance and
/// irradiance (something lit in each) and passes, listing nothing of it as host-only.
fn check_compares_the_masked_dome(stage: &str) {
    if crate::common::gpu().is_none() {
        return;
    }
    let o = luxeval(&[
        "check",
        stage,
        "--portal-mode",
        "mask",
        "--samples",
        "400",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    let row = |q: &str| {
        rows.iter()
            .find(|r| r["light"] == "/World/Sky" && r["query"] == q)
            .unwrap_or_else(|| panic!("no {q} row: {v}"))
    };
    let radiance = row("radiance");
    assert!(radiance["samples"].as_u64().unwrap() > 0, "{radiance}");
    assert!(
        radiance["nonzero"].as_u64().unwrap() > 0,
        "nothing lit: {radiance}"
    );
    assert_eq!(radiance["pass"], true, "{radiance}");
    assert!(row("emission")["samples"].as_u64().unwrap() > 0);
    let irradiance = row("irradiance");
    assert!(irradiance["samples"].as_u64().unwrap() > 0, "{irradiance}");
    assert!(
        irradiance["nonzero"].as_u64().unwrap() > 0,
        "nothing lit: {irradiance}"
    );
    assert_eq!(irradiance["pass"], true, "{irradiance}");
    assert!(
        v["host_only"]
            .as_array()
            .unwrap()
            .iter()
            .all(|h| h[0] != "/World/Sky"),
        "{v}"
    );
    eprintln!(
        "{stage}, mask mode: radiance {} samples, {} excluded, {} lit, worst {}; irradiance {} \
         samples, {} excluded, worst {}",
        radiance["samples"],
        radiance["excluded"],
        radiance["nonzero"],
        radiance["max_rel_error"],
        irradiance["samples"],
        irradiance["excluded"],
        irradiance["max_rel_error"]
    );
}
