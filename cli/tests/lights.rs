//! The `lights` command end to end — every input and whether it was authored, mesh lights and
//! portals, what luxeval reads and does not apply — and the one warning each query prints about
//! the latter.

use crate::support::*;

#[test]
fn lights_json_lists_every_input_and_whether_authored() {
    let o = luxeval(&["lights", &asset("studio.usda"), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let lights = v["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 6);
    let key = lights.iter().find(|l| l["path"] == "/lights/key").unwrap();
    let inputs = key["inputs"].as_array().unwrap();
    let width = inputs.iter().find(|i| i["name"] == "inputs:width").unwrap();
    assert_eq!(width["authored"], true);
    let diffuse = inputs
        .iter()
        .find(|i| i["name"] == "inputs:diffuse")
        .unwrap();
    assert_eq!(diffuse["authored"], false);
}

/// `lights --json` lists each mesh light (triangle count, world area, tint and its source,
/// doubleSided, subdivision), each portal (size, multiplier, the domes naming it) and each
/// dome's portals (DESIGN.md §7, §8), with the numbers usd-core and NumPy computed for the
/// fixture (tests/data/usd/expected/mesh_lights.json, its earliest-time sample); the text
/// lists the same, and says the mesh lights are evaluated, the portal the dome names guides
/// sampling (hint mode, the default) and the one no dome names is read, not evaluated.
#[test]
fn lights_lists_mesh_lights_and_portals() {
    let scene = repo_file("tests/data/usd/mesh/mesh_lights.usda");
    let exp: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_file("tests/data/usd/expected/mesh_lights.json")).unwrap(),
    )
    .unwrap();
    let earliest = &exp["samples"][0];
    assert!(earliest["time"].is_null());
    let o = luxeval(&["lights", &scene, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let lights = v["lights"].as_array().unwrap();
    let record = |path: &str| lights.iter().find(|l| l["path"] == path).unwrap();
    for e in earliest["meshes"].as_array().unwrap() {
        let l = record(e["path"].as_str().unwrap());
        assert_eq!(l["evaluable"], true, "{l}");
        let m = &l["mesh"];
        assert_eq!(m["triangles"], e["triangles"], "{l}");
        let (area, want) = (m["area"].as_f64().unwrap(), e["area"].as_f64().unwrap());
        assert!((area - want).abs() <= 1e-6 * want, "{l}");
        assert_eq!(m["double_sided"], e["double_sided"], "{l}");
        assert_eq!(m["subdivision_scheme"], e["subdivision_scheme"], "{l}");
        for k in 0..3 {
            let t = m["tint"][k].as_f64().unwrap();
            assert!((t - e["tint"][k].as_f64().unwrap()).abs() <= 1e-6, "{l}");
        }
        assert!(
            m["tint_source"].as_str().is_some_and(|s| !s.is_empty()),
            "{l}"
        );
    }
    for e in earliest["portals"].as_array().unwrap() {
        let l = record(e["path"].as_str().unwrap());
        assert_eq!(l["portal"]["width"], e["width"], "{l}");
        assert_eq!(l["portal"]["height"], e["height"], "{l}");
        assert_eq!(l["portal"]["domes"], e["domes"], "{l}");
    }
    // intensity 2 · 2^exposure 1 · color (1, 0.5, 0.25).
    assert_eq!(
        record("/World/Window")["portal"]["multiplier"],
        serde_json::json!([4.0, 2.0, 1.0])
    );
    for e in earliest["domes"].as_array().unwrap() {
        assert_eq!(record(e["path"].as_str().unwrap())["portals"], e["portals"]);
    }
    // Other lights' records have no such fields.
    assert!(record("/World/Sky").get("mesh").is_none());
    // DESIGN.md §8 P2: the mode, and the dome's portals as evaluated (the PortalLights among
    // its targets, the mesh light left out), not masked in hint mode.
    assert_eq!(v["portal_mode"], "hint");
    assert_eq!(
        record("/World/Sky")["portals_evaluated"],
        serde_json::json!(["/World/Window"])
    );
    assert_eq!(record("/World/Sky")["masked"], false);
    let o = luxeval(&["lights", &scene, "--json", "--portal-mode", "mask"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(m["portal_mode"], "mask");
    let sky = m["lights"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["path"] == "/World/Sky")
        .unwrap();
    assert_eq!(sky["masked"], true);

    let o = luxeval(&["lights", &scene]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for want in [
        "/World/Signs/Quads (Mesh) [evaluated]",
        "  mesh  4 triangles (0 hole faces removed, 0 degenerate triangles dropped), area 4.000000, doubleSided false",
        "  tint  (2, 1, 0.5) from emissiveColor of /World/Looks/Glow/Surface (authored)",
        "/World/Window (PortalLight) [guides sampling only (hint mode)]",
        "/World/Skylight (PortalLight) [read, not evaluated yet]",
        "  portals evaluated (hint mode)  /World/Window",
        "  portal  2 x 1.5, multiplier (4, 2, 1), named by /World/Sky",
        "  portal  1 x 1, multiplier (1, 1, 1), named by no dome",
        "  portals  /World/Window, /World/Signs/Quads",
    ] {
        assert!(text.contains(want), "{want:?} not in:\n{text}");
    }

    // Bad topology: listed with the attribute named, refused by the queries.
    let o = luxeval(&[
        "lights",
        &repo_file("tests/data/usd/mesh/bad/count_below_3.usda"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("/Bad: faceVertexCounts") && text.contains("the queries refuse this light"),
        "{text}"
    );
}

/// The fixture of what a renderer applies and luxeval does not (tests/data/usd/unapplied/,
/// made with usd-core by tools/gen_usd_fixtures.py --only-unapplied).
fn unapplied_scene() -> String {
    repo_file("tests/data/usd/unapplied/unapplied.usda")
}

/// `lights` lists each light's filters, its restricting link collections and its shaping inputs
/// without ShapingAPI, and the stage's light lists, each marked as not applied; `--json` has
/// them as fields, as usd-core composes them (tests/data/usd/expected/unapplied_links.json).
#[test]
fn lights_says_what_luxeval_does_not_apply() {
    let o = luxeval(&["lights", &unapplied_scene()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    let block = |path: &str| -> String {
        let start = text
            .find(&format!("\n{path} ("))
            .unwrap_or_else(|| panic!("{path} not listed:\n{text}"));
        let rest = &text[start + 1..];
        rest[..rest.find("\n\n").unwrap_or(rest.len())].to_string()
    };
    for (path, says) in [
        (
            "/World/Filtered",
            &["light:filters  /World/Gobo, /World/Barn  (not applied)"][..],
        ),
        (
            "/World/Linked",
            &[
                "collection:lightLink  includeRoot false, includes /World/Geo/Floor, \
                 excludes /World/Geo/Floor/Tile, expansionRule explicitOnly  (not applied)",
                "collection:shadowLink  includeRoot true, excludes /World/Geo/Wall",
                "not applied by luxeval: light linking (collection:lightLink), shadow linking",
            ],
        ),
        (
            "/World/UnshapedSpot",
            &[
                "without ShapingAPI  inputs:shaping:cone:angle, inputs:shaping:cone:softness",
                "ShapingAPI is not applied",
            ],
        ),
        // Mapped into the instance, as usd-core maps them.
        (
            "/World/Inst/Key",
            &[
                "light:filters  /World/Inst/Gobo  (not applied)",
                "includes /World/Inst/Prop",
            ],
        ),
    ] {
        let b = block(path);
        for s in says {
            assert!(b.contains(s), "{path} lacks {s:?}:\n{b}");
        }
    }
    // ShapingAPI applied, an empty or unrestricting collection: nothing to say.
    for quiet in ["/World/ShapedSpot", "/World/Quiet"] {
        let b = block(quiet);
        assert!(
            !b.contains("not applied") && !b.contains("warning") && !b.contains("ShapingAPI  "),
            "{b}"
        );
    }
    assert!(text.contains(
        "lightList on /World (ListAPI): /World/Filtered, /World/Linked, /World/Rig/Key; \
         cacheBehavior consumeAndHalt"
    ));
    assert!(text.contains("lightList on /Lists (LightListAPI): /World/Linked;"));

    let o = luxeval(&["lights", &unapplied_scene(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let usd_core: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_file("tests/data/usd/expected/unapplied_links.json"))
            .unwrap(),
    )
    .unwrap();
    let lights = v["lights"].as_array().unwrap();
    for (ours, theirs) in lights.iter().zip(usd_core["lights"].as_array().unwrap()) {
        assert_eq!(ours["path"], theirs["path"]);
        assert_eq!(ours["light_filters"], theirs["filters"], "{}", ours["path"]);
        assert!(ours["link_collections"].is_array() && ours["shaping_without_api"].is_array());
    }
    let linked = lights
        .iter()
        .find(|l| l["path"] == "/World/Linked")
        .unwrap();
    let link = &linked["link_collections"][0];
    assert_eq!(
        (
            &link["name"],
            &link["include_root"],
            &link["expansion_rule"]
        ),
        (
            &serde_json::json!("lightLink"),
            &serde_json::json!(false),
            &serde_json::json!("explicitOnly")
        )
    );
    // At the stage's startTimeCode (0), as usd-core reads the lists then.
    let at_start = usd_core["samples"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["time"] == 0)
        .unwrap();
    assert_eq!(v["light_lists"], at_start["light_lists"]);
}

/// A query command says once, on stderr, what the lights it evaluates have that luxeval does
/// not apply, counted by kind, the same text on every run; it says nothing for a light (or a
/// stage) that has none of it.
#[test]
fn a_query_warns_once_about_what_it_does_not_apply() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.npy");
    let run = |extra: &[&str]| {
        let scene = unapplied_scene();
        let mut args = vec!["emission", &scene, "--dirs", &asset("dirs.npy")]
            .into_iter()
            .map(str::to_string)
            .collect::<Vec<_>>();
        args.extend(["-o", out.to_str().unwrap(), "--device", "cpu"].map(str::to_string));
        args.extend(extra.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = luxeval(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        err.lines()
            .filter(|l| l.contains("not applied by luxeval"))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    // Counted by hand from the fixture: filters on Filtered, Rig/Key, Inst/Key; light links on
    // Linked, Expr, Rig/Key, Inst/Key; shadow links on Linked, RootOff; shaping inputs
    // without ShapingAPI on UnshapedSpot; light lists on /World, /Lists, /Bare.
    let want = format!(
        "warning: {}: 3 lights have light filters, 4 have light-link collections, \
         2 have shadow-link collections, 1 has shaping inputs without ShapingAPI (evaluated \
         unshaped), the stage has 3 light lists (lightList): not applied by luxeval (see \
         `luxeval lights`)",
        unapplied_scene()
    );
    assert_eq!(run(&[]), vec![want.clone()]);
    assert_eq!(run(&[]), vec![want], "the same text on every run");
    // Only the selected lights count; the stage's light lists always do.
    assert_eq!(
        run(&["--light", "/World/ShapedSpot"]),
        vec![format!(
            "warning: {}: the stage has 3 light lists (lightList): not applied by luxeval \
             (see `luxeval lights`)",
            unapplied_scene()
        )]
    );
    assert_eq!(
        run(&[
            "--light",
            "/World/Filtered",
            "--light",
            "/World/UnshapedSpot"
        ]),
        vec![format!(
            "warning: {}: 1 light has light filters, 1 has shaping inputs without ShapingAPI \
             (evaluated unshaped), the stage has 3 light lists (lightList): not applied by \
             luxeval (see `luxeval lights`)",
            unapplied_scene()
        )]
    );
    // A stage with none of it: no such line.
    let o = luxeval(&[
        "emission",
        &asset("studio.usda"),
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        out.to_str().unwrap(),
        "--device",
        "cpu",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("not applied"), "{}", stderr(&o));
}

/// A light prim can author a light list itself (no ListAPI / LightListAPI): `lightList` with
/// targets, or `lightList:cacheBehavior` alone, is listed; `rel lightList` declared without
/// targets is not (no authored targets). The light's authored property names decide which of
/// these are asked about (`unapplied::list_site`), so this pins that a light's own list is not
/// lost on the way.
#[test]
fn a_light_list_authored_on_a_light_is_listed() {
    let dir = tempfile::tempdir().unwrap();
    let stage = dir.path().join("lists_on_lights.usda");
    std::fs::write(
        &stage,
        r#"#usda 1.0
def Xform "World"
{
    def SphereLight "Self"
    {
        rel lightList = </World/Self>
        token lightList:cacheBehavior = "consumeAndHalt"
    }
    def SphereLight "Declared"
    {
        rel lightList
    }
    def SphereLight "Behaviour"
    {
        token lightList:cacheBehavior = "ignore"
    }
}
"#,
    )
    .unwrap();
    let o = luxeval(&["lights", stage.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        v["light_lists"],
        serde_json::json!([
            {"path": "/World/Self", "api": null, "targets": ["/World/Self"],
             "cache_behavior": "consumeAndHalt"},
            {"path": "/World/Behaviour", "api": null, "targets": [],
             "cache_behavior": "ignore"},
        ])
    );
    assert_eq!(v["lights"].as_array().unwrap().len(), 3);
}
