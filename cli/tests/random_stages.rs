//! `luxeval check` on randomised stages (issue "Mesh lights and portals", done when: "`luxeval
//! check` passes on randomised mesh and portal scenes"): the library's random mesh lights (every
//! class, every transform kind, shaped or not) and random domes with portals, written as .usda
//! here, read back by the command line and checked on the GPU against the CPU reference.

use crate::support::*;

use std::fmt::Write as _;
use std::path::Path;

use glam::{DMat4, DVec3};
use luxeval::testkit::{Rng, random_mesh_lights, random_portal_dome};
use luxeval::{Light, LightType, Portal, Stage};

/// A column-vector transform as USD writes it (row vectors: its rows are our columns).
fn matrix(m: DMat4) -> String {
    let rows: Vec<String> = m
        .to_cols_array_2d()
        .iter()
        .map(|c| format!("({:?}, {:?}, {:?}, {:?})", c[0], c[1], c[2], c[3]))
        .collect();
    format!("( {} )", rows.join(", "))
}

fn color(c: DVec3) -> String {
    format!("({:?}, {:?}, {:?})", c.x, c.y, c.z)
}

/// The LightAPI and ShapingAPI inputs of `l`, the transform, one per line.
fn light_inputs(l: &Light, out: &mut String) {
    let i = &l.inputs;
    let _ = writeln!(out, "        float inputs:intensity = {:?}", i.intensity);
    let _ = writeln!(out, "        float inputs:exposure = {:?}", i.exposure);
    let _ = writeln!(out, "        color3f inputs:color = {}", color(i.color));
    let _ = writeln!(out, "        bool inputs:normalize = {}", i.normalize);
    if i.enable_color_temperature {
        let _ = writeln!(out, "        bool inputs:enableColorTemperature = true");
        let _ = writeln!(
            out,
            "        float inputs:colorTemperature = {:?}",
            i.color_temperature
        );
    }
    if let Some(s) = &l.shaping {
        let _ = writeln!(
            out,
            "        float inputs:shaping:cone:angle = {:?}",
            s.cone_angle
        );
        let _ = writeln!(
            out,
            "        float inputs:shaping:cone:softness = {:?}",
            s.cone_softness
        );
        let _ = writeln!(out, "        float inputs:shaping:focus = {:?}", s.focus);
        let _ = writeln!(
            out,
            "        color3f inputs:shaping:focusTint = {}",
            color(s.focus_tint)
        );
    }
    let _ = writeln!(
        out,
        "        matrix4d xformOp:transform = {}",
        matrix(l.world)
    );
    let _ = writeln!(
        out,
        "        uniform token[] xformOpOrder = [\"xformOp:transform\"]"
    );
}

/// A mesh light as a Mesh prim with MeshLightAPI: its world triangles taken back to the prim's
/// space, one face each. Under a mirroring transform the library keeps each world triangle
/// ordered so that its cross product is the front; the local triangle is then wound the other
/// way, which `orientation = "leftHanded"` says.
fn mesh_prim(l: &Light, name: &str) -> String {
    let LightType::Mesh {
        geometry,
        double_sided,
        ..
    } = &l.kind
    else {
        panic!("a mesh light")
    };
    let inv = l.world.inverse();
    let points: Vec<String> = geometry
        .triangles
        .iter()
        .flat_map(|t| t.p)
        .map(|p| {
            let q = inv.transform_point3(p);
            format!("({:?}, {:?}, {:?})", q.x, q.y, q.z)
        })
        .collect();
    let n = geometry.triangles.len();
    let schemas = if l.shaping.is_some() {
        "\"MeshLightAPI\", \"ShapingAPI\""
    } else {
        "\"MeshLightAPI\""
    };
    let mut s = format!(
        "    def Mesh \"{name}\" (\n        prepend apiSchemas = [{schemas}]\n    )\n    {{\n"
    );
    let _ = writeln!(s, "        point3f[] points = [{}]", points.join(", "));
    let _ = writeln!(
        s,
        "        int[] faceVertexCounts = [{}]",
        vec!["3"; n].join(", ")
    );
    let _ = writeln!(
        s,
        "        int[] faceVertexIndices = [{}]",
        (0..3 * n)
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    if l.world.determinant() < 0.0 {
        let _ = writeln!(s, "        uniform token orientation = \"leftHanded\"");
    }
    let _ = writeln!(s, "        uniform bool doubleSided = {double_sided}");
    let _ = writeln!(s, "        uniform token subdivisionScheme = \"none\"");
    light_inputs(l, &mut s);
    s.push_str("    }\n");
    s
}

fn portal_prim(p: &Portal, name: &str) -> String {
    let mut s = format!("    def PortalLight \"{name}\"\n    {{\n");
    let _ = writeln!(s, "        float inputs:width = {:?}", p.width);
    let _ = writeln!(s, "        float inputs:height = {:?}", p.height);
    let _ = writeln!(s, "        float inputs:intensity = {:?}", p.intensity);
    let _ = writeln!(s, "        float inputs:exposure = {:?}", p.exposure);
    let _ = writeln!(s, "        color3f inputs:color = {}", color(p.color));
    if p.enable_color_temperature {
        let _ = writeln!(s, "        bool inputs:enableColorTemperature = true");
        let _ = writeln!(
            s,
            "        float inputs:colorTemperature = {:?}",
            p.color_temperature
        );
    }
    let _ = writeln!(
        s,
        "        matrix4d xformOp:transform = {}",
        matrix(p.world)
    );
    let _ = writeln!(
        s,
        "        uniform token[] xformOpOrder = [\"xformOp:transform\"]"
    );
    s.push_str("    }\n");
    s
}

fn dome_prim(d: &Light, name: &str, portals: &[String], texture: Option<&str>) -> String {
    let mut s = format!("    def DomeLight \"{name}\"\n    {{\n");
    let targets: Vec<String> = portals.iter().map(|p| format!("</World/{p}>")).collect();
    let _ = writeln!(s, "        rel portals = [{}]", targets.join(", "));
    if let Some(t) = texture {
        let _ = writeln!(s, "        asset inputs:texture:file = @{t}@");
    }
    light_inputs(d, &mut s);
    s.push_str("    }\n");
    s
}

fn stage(prims: &[String]) -> String {
    format!(
        "#usda 1.0\n(\n    upAxis = \"Y\"\n)\n\ndef Xform \"World\"\n{{\n{}}}\n",
        prims.concat()
    )
}

/// Runs `luxeval check --json` (plus `extra`) on `path` and returns the report.
fn check(path: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "check",
        path.to_str().unwrap(),
        "--samples",
        "160",
        "--json",
    ];
    args.extend_from_slice(extra);
    let o = luxeval(&args);
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(&o)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The names of the lights whose radiance `check` compared.
fn compared(report: &serde_json::Value) -> Vec<String> {
    report["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["query"] == "radiance")
        .map(|r| r["light"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn check_passes_on_a_randomised_mesh_stage() {
    if crate::common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng::new(0x0022_5EED);
    let lights = random_mesh_lights(&mut rng, 1); // 5 classes × 7 transforms
    let names: Vec<String> = (0..lights.len()).map(|i| format!("Mesh{i}")).collect();
    let prims: Vec<String> = lights
        .iter()
        .zip(&names)
        .map(|(l, n)| mesh_prim(l, n))
        .collect();
    let path = dir.path().join("meshes.usda");
    std::fs::write(&path, stage(&prims)).unwrap();
    // The stage holds the lights written: the same world area (to f32 points' rounding).
    let read = Stage::load(&path, None).unwrap().evaluable(&[]).unwrap();
    assert_eq!(read.len(), lights.len());
    for (r, l) in read.iter().zip(&lights) {
        let area = |l: &Light| match &l.kind {
            LightType::Mesh { geometry, .. } => geometry.area,
            _ => panic!("a mesh light"),
        };
        assert!(
            (area(r) / area(l) - 1.0).abs() < 1e-5,
            "{}: area {} written, {} read",
            l.path,
            area(l),
            area(r)
        );
    }
    let report = check(&path, &[]);
    let radiance = compared(&report);
    for n in &names {
        assert!(
            radiance.contains(&format!("/World/{n}")),
            "{n}: no radiance compared"
        );
    }
    assert_eq!(
        report["rows"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["pass"] != true)
            .count(),
        0
    );
}

#[test]
fn check_passes_on_randomised_portal_stages() {
    if crate::common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng::new(0x0008_5EED);
    let texture = repo_file("tests/data/textures/testImage.png");
    for k in 0..4 {
        let dome = random_portal_dome(&mut rng, k);
        let portals: Vec<String> = (0..dome.portals.len())
            .map(|i| format!("Portal{i}"))
            .collect();
        let mut prims = vec![dome_prim(
            &dome,
            "Sky",
            &portals,
            (k % 2 == 1).then_some(texture.as_str()),
        )];
        prims.extend(
            dome.portals
                .iter()
                .zip(&portals)
                .map(|(p, n)| portal_prim(p, n)),
        );
        let path = dir.path().join(format!("portals{k}.usda"));
        std::fs::write(&path, stage(&prims)).unwrap();
        for mode in ["hint", "mask"] {
            let report = check(&path, &["--portal-mode", mode]);
            let radiance = compared(&report);
            // Either mode's dome radiance is the device's, and compared.
            assert!(
                radiance.contains(&"/World/Sky".to_string()),
                "{} {mode}",
                path.display()
            );
        }
    }
}
