//! Parity with usd-core on OpenUSD's own light test scenes (tests/data/usd/openusd/, copied from
//! PixarAnimationStudios/OpenUSD v24.08 by `tools/gen_usd_fixtures.py --only-openusd`): every
//! light of every scene, at every time code it authors and under the EarliestTime rule, must
//! read as usd-core reads it (tests/data/usd/expected/openusd_*.json, written by usd-core only).
//! One test per scene, so that a failure names the scene; tests/data/usd/openusd/README.md says
//! what each one exercises. `tools/usd_parity.py` runs the same comparison over a whole OpenUSD
//! checkout with the command line.
#![cfg(feature = "usd")]

use crate::usd_fixtures::check_scene;

macro_rules! openusd_scenes {
    ($($name:ident),* $(,)?) => {
        $(
            #[test]
            fn $name() {
                check_scene(concat!("openusd_", stringify!($name)));
            }
        )*

        /// Every expected file has its test above, and no test lacks its file.
        #[test]
        fn every_openusd_fixture_has_a_test() {
            let listed: std::collections::BTreeSet<String> =
                [$(stringify!($name)),*].iter().map(|s| format!("openusd_{s}.json")).collect();
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/usd/expected");
            let on_disk: std::collections::BTreeSet<String> = std::fs::read_dir(&dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with("openusd_"))
                .collect();
            assert_eq!(listed, on_disk);
        }
    };
}

openusd_scenes! {
    // `//` comment; payloads; a reference (to our stand-in for the teapot).
    light_list_root,
    // root.usda as a sublayer; instanceable payloads (lights as instance proxies).
    light_list_root_with_instances,
    // Eight sphere lights with light-link collections.
    linking_example,
    // Time-sampled visibility.
    usdview_light_visibility_varying,
    // The `config` qualifier.
    usdview_render_settings_edits,
    // Time-sampled transforms, frames 1 to 10.
    usdrecord_motion_blur,
    // A rect light with most inputs authored.
    delegate_inherited_primvars,
    // Time-sampled transforms, frames 1 to 3.
    gl_animated_light_moving,
    // An asset value written as a string.
    gl_dome_light_yup,
    // A dome texture that resolves.
    gl_instanced_cubes,
    // A reference to a MaterialX .mtlx layer; disk and distant lights.
    gl_mx_lights,
    // Numbers written `0.`.
    gl_native_emissive,
    // Numbers written `.1`.
    gl_native_normal_map,
    // A reference to another scene with a point instancer.
    gl_point_instancer_ni_pi_xform,
}
