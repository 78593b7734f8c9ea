//! The bad-input corpus (`tests/data/bad/`, written by `tools/gen_bad_corpus.py`): one test per
//! case runs the `luxeval` binary and checks the CLI contract (DESIGN.md §4, docs/INPUTS.md):
//! the exit code; the file and the prim, attribute, row or line named in the message; no panic
//! or abort; no output (not even a temporary) left behind by a failure; every input unchanged
//! (hashed before and after); and no NaN or infinity in what a successful run writes.
//!
//! Each case runs in a fresh temporary directory: the corpus files it names (`{in}/NAME`) are
//! copied to `{in}/` first, so a failing case can never damage the corpus; outputs go to
//! `{out}/`. Adding a case (also for IES profiles and textures): put the file in the generator,
//! then one line in the `cases!` table below.

use crate::common;

mod setups;
use setups::*;

use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One corpus case.
#[derive(Default)]
struct Case {
    /// Arguments; `{in}` is the directory of copied inputs, `{out}` the output directory.
    args: &'static [&'static str],
    /// Expected exit code.
    exit: i32,
    /// Substrings the message on stderr must contain (placeholders expanded).
    says: &'static [&'static str],
    /// Extra environment.
    env: &'static [(&'static str, &'static str)],
    /// Prepares `{in}` after the copies (links, pipes, directories).
    setup: Option<fn(&Path)>,
    /// When set, a second run with these arguments writes `{out}/ref.npy`, which must equal the
    /// case's `{out}/out.npy` (for inputs that must mean the same as a plain one).
    same_as: &'static [&'static str],
    /// The case's output must hold a non-zero value (a light that must not have been dropped).
    lit: bool,
    /// Limit the size of files the process may write (simulates a full disk: writes fail with
    /// EFBIG; SIGXFSZ is ignored so that the write fails instead of killing the process).
    fsize: Option<u64>,
    /// Needs a GPU adapter (skipped with a note without one, failed under CI=true).
    gpu: bool,
}

fn corpus() -> PathBuf {
    crate::repo().join("tests/data/bad")
}

fn hash_file(p: &Path) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    std::fs::read(p).unwrap().hash(&mut h);
    h.finish()
}

/// Every entry under `dir` (not following links) with a hash of each regular file's bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Option<u64>> {
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let meta = std::fs::symlink_metadata(&p).unwrap();
            if meta.is_dir() {
                todo.push(p.clone());
                out.insert(p, None);
            } else if meta.is_file() {
                out.insert(p.clone(), Some(hash_file(&p)));
            } else {
                out.insert(p, None);
            }
        }
    }
    out
}

fn expand(s: &str, input: &Path, out: &Path) -> String {
    s.replace("{in}", &input.to_string_lossy())
        .replace("{out}", &out.to_string_lossy())
}

fn command(args: &[String], env: &[(&str, &str)], fsize: Option<u64>) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_luxeval"));
    c.args(args).env("RUST_BACKTRACE", "1");
    for (k, v) in env {
        c.env(k, v);
    }
    if let Some(limit) = fsize {
        use std::os::unix::process::CommandExt;
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            c.pre_exec(move || {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let r = libc::rlimit {
                    rlim_cur: limit,
                    rlim_max: limit,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    c
}

/// Every float of an output the run wrote: `.npy` (float32) or `.exr`.
fn output_values(p: &Path) -> Vec<f32> {
    match p.extension().and_then(|e| e.to_str()) {
        Some("npy") => {
            let bytes = std::fs::read(p).unwrap();
            let f = npyz::NpyFile::new(&bytes[..]).unwrap();
            f.into_vec::<f32>().unwrap()
        }
        Some("exr") => luxeval_cli::io::exr::read_exr(p)
            .unwrap()
            .rgb
            .into_iter()
            .flatten()
            .collect(),
        _ => Vec::new(),
    }
}

/// Longer than any case takes on the slowest machine the tests run on: a case that is still
/// running then hangs (a blocked open, an endless read) and is killed and failed.
const HANG: std::time::Duration = std::time::Duration::from_secs(300);

/// Runs `c` to completion like `Command::output`, but kills it and fails the test when it runs
/// longer than `limit` (so a hang fails the case instead of the whole test run).
fn output_within(
    mut c: Command,
    limit: std::time::Duration,
    args: &[String],
) -> std::process::Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = c
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut b = Vec::new();
        stdout.read_to_end(&mut b).map(|_| b)
    });
    let err = std::thread::spawn(move || {
        let mut b = Vec::new();
        stderr.read_to_end(&mut b).map(|_| b)
    });
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("luxeval {} ran over {limit:?}: a hang", args.join(" "));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    std::process::Output {
        status,
        stdout: out.join().unwrap().unwrap(),
        stderr: err.join().unwrap().unwrap(),
    }
}

fn run(name: &str, case: &Case) {
    if case.gpu && common::gpu().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    let out = tmp.path().join("out");
    std::fs::create_dir(&input).unwrap();
    std::fs::create_dir(&out).unwrap();
    // Copy the corpus files the case names, and the files they compose with.
    for a in case.args.iter().chain(case.same_as) {
        if let Some(name) = a.strip_prefix("{in}/") {
            let src = corpus().join(name);
            if src.is_file() {
                std::fs::copy(&src, input.join(name)).unwrap();
            }
        }
    }
    for companion in [
        "reference_cycle_b.usda",
        "sublayer_cycle_b.usda",
        "big_layer.usda",
        "ies_truncated.ies",
        "ies_huge.ies",
    ] {
        std::fs::copy(corpus().join(companion), input.join(companion)).unwrap();
    }
    if let Some(setup) = case.setup {
        setup(&input);
    }
    let before = snapshot(&input);
    let args: Vec<String> = case.args.iter().map(|a| expand(a, &input, &out)).collect();
    let o = output_within(command(&args, case.env, case.fsize), HANG, &args);
    let stderr = String::from_utf8_lossy(&o.stderr);
    let context = format!("case {name}: luxeval {}\nstderr:\n{stderr}", args.join(" "));
    for crash in [
        "panicked",
        "overflowed its stack",
        "fatal runtime error",
        "RUST_BACKTRACE",
    ] {
        assert!(!stderr.contains(crash), "{context}");
    }
    assert_eq!(o.status.code(), Some(case.exit), "{context}");
    for s in case.says {
        let s = expand(s, &input, &out);
        assert!(
            stderr.contains(&s),
            "expected {s:?} in the message; {context}"
        );
    }
    assert_eq!(snapshot(&input), before, "the inputs changed; {context}");
    let written = snapshot(&out);
    if case.exit != 0 {
        assert!(
            written.is_empty(),
            "a failed run left {written:?}; {context}"
        );
        return;
    }
    let mut any_lit = false;
    for p in written.keys() {
        let v = output_values(p);
        assert!(
            v.iter().all(|x| x.is_finite()),
            "{} holds NaN or infinity; {context}",
            p.display()
        );
        any_lit |= v.iter().any(|x| *x != 0.0);
    }
    assert!(!case.lit || any_lit, "the output is all zeros; {context}");
    if !case.same_as.is_empty() {
        let args: Vec<String> = case
            .same_as
            .iter()
            .map(|a| expand(a, &input, &out))
            .collect();
        let r = command(&args, case.env, None).output().unwrap();
        assert!(r.status.success(), "reference run failed; {context}");
        assert_eq!(
            std::fs::read(out.join("out.npy")).unwrap(),
            std::fs::read(out.join("ref.npy")).unwrap(),
            "not the same output as {:?}; {context}",
            case.same_as
        );
    }
}

/// One `#[test]` per case.
macro_rules! cases {
    ($($name:ident: $case:expr;)*) => {
        $(
            #[test]
            fn $name() {
                run(stringify!($name), &$case);
            }
        )*
        /// Every case's name, for the count below.
        const CASES: &[&str] = &[$(stringify!($name)),*];
    };
}

/// `emission` on the CPU with the given scene and directions.
macro_rules! emission {
    ($scene:expr, $dirs:expr) => {
        &[
            "emission",
            $scene,
            "--dirs",
            $dirs,
            "-o",
            "{out}/out.npy",
            "--device",
            "cpu",
        ]
    };
}

const NO_GPU: &[(&str, &str)] = &[
    ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
    ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
];

cases! {
    // --- An output path that is one of the inputs, by any spelling, or not a file ---------------
    output_is_dirs: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/dirs.npy", "--device", "cpu"], exit: 2, says: &["-o", "--dirs", "dirs.npy", "the same file"], ..Case::default() };
    output_is_points: Case { args: &["radiance", "{in}/ok.usda", "--points", "{in}/points.npy", "--dirs", "{in}/dirs.npy", "-o", "{in}/points.npy", "--device", "cpu"], exit: 2, says: &["--points", "points.npy"], ..Case::default() };
    output_is_radiance_dirs: Case { args: &["radiance", "{in}/ok.usda", "--points", "{in}/points.npy", "--dirs", "{in}/dirs.npy", "-o", "{in}/dirs.npy", "--device", "cpu"], exit: 2, says: &["--dirs", "dirs.npy"], ..Case::default() };
    output_is_normals: Case { args: &["irradiance", "{in}/ok.usda", "--points", "{in}/points.npy", "--normals", "{in}/normals.npy", "-o", "{in}/normals.npy", "--device", "cpu"], exit: 2, says: &["--normals", "normals.npy"], ..Case::default() };
    output_is_scene: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/ok.usda", "--device", "cpu"], exit: 2, says: &["SCENE", "ok.usda"], ..Case::default() };
    output_is_input_through_dotdot: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/sub/../dirs.npy", "--device", "cpu"], exit: 2, says: &["sub/../dirs.npy", "--dirs"], setup: Some(mkdir_sub), ..Case::default() };
    output_is_input_through_symlink: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/link.npy", "--device", "cpu"], exit: 2, says: &["link.npy", "--dirs"], setup: Some(symlink_dirs), ..Case::default() };
    output_is_input_through_hard_link: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/hard.npy", "--device", "cpu"], exit: 2, says: &["hard.npy", "--dirs"], setup: Some(hardlink_dirs), ..Case::default() };
    falloff_png_is_exr: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "4,4", "-o", "{out}/m.exr", "--png", "{out}/m.exr", "--device", "cpu"], exit: 2, says: &["--png", "-o", "m.exr"], ..Case::default() };
    falloff_output_named_tiff: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "4,4", "-o", "{out}/m.tif", "--png", "{out}/m.PNG", "--device", "cpu"], exit: 0, says: &["warning: -o {out}/m.tif: falloff writes OpenEXR"], ..Case::default() };
    falloff_output_is_scene: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "4,4", "-o", "{in}/ok.usda", "--device", "cpu"], exit: 2, says: &["SCENE", "ok.usda"], ..Case::default() };
    // A token the schema does not allow refuses the light (it was skipped with exit 0).
    dome_texture_format_not_a_schema_token: Case { args: emission!("{in}/dome_bad_format.usda", "{in}/dirs.npy"), exit: 2, says: &["dome_bad_format.usda", "/D", "inputs:texture:format", "cube"], ..Case::default() };
    dome1_pole_axis_not_a_schema_token: Case { args: emission!("{in}/dome1_bad_pole_axis.usda", "{in}/dirs.npy"), exit: 2, says: &["dome1_bad_pole_axis.usda", "/D", "poleAxis", "\"X\""], ..Case::default() };
    // Every file a command reads through the stage is an input too: no output may name one.
    output_is_a_sublayer: Case { args: &["emission", "{in}/layered.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/sub.usda", "--device", "cpu"], exit: 2, says: &["-o", "sub.usda", "layer of", "layered.usda"], setup: Some(read_through_the_stage), ..Case::default() };
    output_is_the_ies_profile: Case { args: &["emission", "{in}/layered.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/spot.ies", "--device", "cpu"], exit: 2, says: &["-o", "spot.ies", "a light of", "layered.usda"], setup: Some(read_through_the_stage), ..Case::default() };
    output_is_the_tilt_file: Case { args: &["irradiance", "{in}/layered.usda", "--points", "{in}/points.npy", "--normals", "{in}/normals.npy", "-o", "{in}/spot.tilt", "--device", "cpu"], exit: 2, says: &["-o", "spot.tilt", "a light of"], setup: Some(read_through_the_stage), ..Case::default() };
    output_is_the_texture: Case { args: &["emission", "{in}/textured.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/sky.png", "--device", "cpu"], exit: 2, says: &["-o", "sky.png", "a light of", "textured.usda"], setup: Some(read_through_the_stage), ..Case::default() };
    falloff_png_is_a_sublayer: Case { args: &["falloff", "{in}/layered.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "4,4", "-o", "{out}/m.exr", "--png", "{in}/sub.usda", "--device", "cpu"], exit: 2, says: &["--png", "sub.usda", "layer of"], setup: Some(read_through_the_stage), ..Case::default() };
    ies_png_is_the_tilt_file: Case { args: &["ies", "{in}/spot.ies", "--png", "{in}/spot.tilt"], exit: 2, says: &["--png", "spot.tilt", "TILT file"], setup: Some(read_through_the_stage), ..Case::default() };
    read_through_the_stage_is_read: Case { args: &["emission", "{in}/layered.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 0, lit: true, setup: Some(read_through_the_stage), ..Case::default() };
    output_is_a_pipe: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/pipe", "--device", "cpu"], exit: 2, says: &["pipe", "not a regular file"], setup: Some(fifo), ..Case::default() };
    output_is_a_directory: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{in}/sub", "--device", "cpu"], exit: 2, says: &["sub", "not a regular file"], setup: Some(mkdir_sub), ..Case::default() };
    output_in_missing_directory: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/no/such/dir/o.npy", "--device", "cpu"], exit: 2, says: &["{out}/no/such/dir/o.npy"], ..Case::default() };

    // --- Composition: cycles, depth, arc chains, prim counts ------------------------------------
    self_inherit: Case { args: &["lights", "{in}/self_inherit.usda"], exit: 2, says: &["self_inherit.usda", "</L>", "cycle", "inherits"], ..Case::default() };
    class_inherits_itself: Case { args: &["lights", "{in}/class_inherits_itself.usda"], exit: 2, says: &["class_inherits_itself.usda", "</C>", "cycle"], ..Case::default() };
    class_inherits_itself_usdc: Case { args: &["lights", "{in}/class_inherits_itself.usdc"], exit: 2, says: &["class_inherits_itself.usdc", "</C>", "cycle"], ..Case::default() };
    inherit_ancestor: Case { args: &["lights", "{in}/inherit_ancestor.usda"], exit: 2, says: &["inherit_ancestor.usda", "</A/B>", "cycle"], ..Case::default() };
    inherit_descendant: Case { args: &["lights", "{in}/inherit_descendant.usda"], exit: 2, says: &["inherit_descendant.usda", "</L/C>", "cycle"], ..Case::default() };
    reference_self: Case { args: &["lights", "{in}/reference_self.usda"], exit: 2, says: &["reference_self.usda", "</L>", "references"], ..Case::default() };
    specialize_self: Case { args: &["lights", "{in}/specialize_self.usda"], exit: 2, says: &["specialize_self.usda", "</L>", "specializes"], ..Case::default() };
    reference_cycle_across_files: Case { args: &["lights", "{in}/reference_cycle_a.usda"], exit: 2, says: &["reference_cycle_a.usda", "reference_cycle_b.usda", "cycle"], ..Case::default() };
    sublayer_cycle: Case { args: &["lights", "{in}/sublayer_cycle_a.usda"], exit: 2, says: &["sublayer_cycle_a.usda", "sublayer_cycle_b.usda", "sublayer cycle"], ..Case::default() };
    namespace_10000_deep: Case { args: &["lights", "{in}/deep_10000.usda"], exit: 2, says: &["deep_10000.usda", "LUXEVAL_MAX_PRIM_DEPTH"], ..Case::default() };
    namespace_1001_deep: Case { args: &["lights", "{in}/deep_1001.usda"], exit: 2, says: &["deep_1001.usda", "</p0>", "1001 levels", "LUXEVAL_MAX_PRIM_DEPTH"], ..Case::default() };
    namespace_150_deep_is_legal: Case { args: emission!("{in}/deep_150.usda", "{in}/dirs.npy"), exit: 0, lit: true, ..Case::default() };
    arc_chain_98_is_legal: Case { args: emission!("{in}/chain_98.usda", "{in}/dirs.npy"), exit: 0, lit: true, ..Case::default() };
    arc_chain_99: Case { args: &["lights", "{in}/chain_99.usda"], exit: 2, says: &["chain_99.usda", "</R0>", "99 nested composition arcs", "98"], ..Case::default() };
    arc_chain_150: Case { args: emission!("{in}/chain_150.usda", "{in}/dirs.npy"), exit: 2, says: &["chain_150.usda", "</R", "composition arcs"], ..Case::default() };
    prim_explosion: Case { args: &["lights", "{in}/prim_explosion.usda"], exit: 2, says: &["prim_explosion.usda", "</L0>", "LUXEVAL_MAX_PRIMS"], ..Case::default() };
    prim_limit_lowered: Case { args: &["lights", "{in}/prims_120.usda"], exit: 2, env: &[("LUXEVAL_MAX_PRIMS", "100")], says: &["prims_120.usda", "up to 111 prims", "</L0>", "LUXEVAL_MAX_PRIMS"], ..Case::default() };

    // --- LightAPI on a prim that is not a light type: listed with a warning, not dropped --------
    lightapi_on_xform: Case { args: emission!("{in}/lightapi_on_xform.usda", "{in}/dirs.npy"), exit: 0, says: &["warning", "/Rig", "LightAPI", "Xform"], ..Case::default() };
    lightapi_on_unknown_type: Case { args: emission!("{in}/lightapi_on_unknown_type.usda", "{in}/dirs.npy"), exit: 0, says: &["warning", "/Fancy", "LightAPI", "FancyLight"], ..Case::default() };
    lightapi_on_untyped_prim: Case { args: &["lights", "{in}/lightapi_on_untyped.usda"], exit: 0, ..Case::default() };

    // --- Finite inputs whose values do not fit float32 ------------------------------------------
    exposure_200: Case { args: emission!("{in}/exposure_200.usda", "{in}/dirs.npy"), exit: 2, says: &["exposure_200.usda", "/L", "inputs:exposure", "float32"], ..Case::default() };
    intensity_1e39: Case { args: emission!("{in}/intensity_1e39.usda", "{in}/dirs.npy"), exit: 2, says: &["intensity_1e39.usda", "/L", "inputs:intensity", "float32"], ..Case::default() };
    color_1e39: Case { args: emission!("{in}/color_1e39.usda", "{in}/dirs.npy"), exit: 2, says: &["color_1e39.usda", "inputs:color"], ..Case::default() };
    normalize_tiny_light: Case { args: emission!("{in}/normalize_tiny.usda", "{in}/dirs.npy"), exit: 2, says: &["normalize_tiny.usda", "/L", "inputs:normalize", "float32"], ..Case::default() };
    radius_1e19: Case { args: emission!("{in}/radius_1e19.usda", "{in}/dirs.npy"), exit: 2, says: &["radius_1e19.usda", "/L", "inputs:radius"], ..Case::default() };
    translate_1e19: Case { args: emission!("{in}/translate_1e19.usda", "{in}/dirs.npy"), exit: 2, says: &["translate_1e19.usda", "/L", "world transform"], ..Case::default() };
    sum_over_lights_overflows: Case { args: emission!("{in}/domes_sum_overflows.usda", "{in}/dirs.npy"), exit: 2, says: &["row 0", "overflows float32"], ..Case::default() };
    point_light_irradiance_on_the_light: Case { args: &["irradiance", "{in}/point_light.usda", "--points", "{in}/point_on_light.npy", "--normals", "{in}/normal_down.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 2, says: &["row 0", "overflows float32"], ..Case::default() };
    dirs_f64_huge_mean_their_direction: Case { args: emission!("{in}/ok.usda", "{in}/dirs_f64_huge.npy"), exit: 0, lit: true, same_as: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/ref.npy", "--device", "cpu"], ..Case::default() };
    dirs_f32_subnormal_mean_their_direction: Case { args: emission!("{in}/ok.usda", "{in}/dirs_f32_subnormal.npy"), exit: 0, lit: true, same_as: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/ref.npy", "--device", "cpu"], ..Case::default() };
    dirs_f32_huge_on_the_gpu: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs_f32_huge.npy", "-o", "{out}/out.npy", "--device", "gpu"], exit: 0, lit: true, gpu: true, same_as: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/ref.npy", "--device", "gpu"], ..Case::default() };
    dirs_f32_subnormal_on_the_gpu: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs_f32_subnormal.npy", "-o", "{out}/out.npy", "--device", "gpu"], exit: 0, lit: true, gpu: true, same_as: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/ref.npy", "--device", "gpu"], ..Case::default() };
    points_f64_beyond_float32: Case { args: &["radiance", "{in}/ok.usda", "--points", "{in}/points_f64_huge.npy", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 2, says: &["points_f64_huge.npy", "row 1", "float32"], ..Case::default() };

    // --- Counts and sizes that overflow or exceed a limit; endless inputs -----------------------
    npy_rows_times_size_wraps: Case { args: emission!("{in}/ok.usda", "{in}/npy_rows_wrap.npy"), exit: 2, says: &["npy_rows_wrap.npy", "do not fit a 64-bit size"], ..Case::default() };
    npy_rows_wrap_with_samples_unlimited: Case { args: emission!("{in}/ok.usda", "{in}/npy_rows_wrap.npy"), exit: 2, env: &[("LUXEVAL_MAX_SAMPLES", "18446744073709551615")], says: &["npy_rows_wrap.npy", "do not fit a 64-bit size"], ..Case::default() };
    npy_more_rows_than_data: Case { args: emission!("{in}/ok.usda", "{in}/npy_more_rows_than_data.npy"), exit: 2, says: &["npy_more_rows_than_data.npy", "ends inside the data"], ..Case::default() };
    npy_trailing_data: Case { args: emission!("{in}/ok.usda", "{in}/npy_trailing_data.npy"), exit: 2, says: &["npy_trailing_data.npy", "more data"], ..Case::default() };
    npy_huge_header: Case { args: emission!("{in}/ok.usda", "{in}/npy_huge_header.npy"), exit: 2, says: &["npy_huge_header.npy", "header of"], ..Case::default() };
    check_samples_1e12: Case { args: &["check", "{in}/ok.usda", "--samples", "1000000000000"], exit: 2, says: &["--samples", "LUXEVAL_MAX_SAMPLES"], ..Case::default() };
    bench_samples_1e12: Case { args: &["bench", "--samples", "1000000000000"], exit: 2, says: &["--samples", "LUXEVAL_MAX_SAMPLES"], ..Case::default() };
    bench_lights_1e12: Case { args: &["bench", "--lights", "1000000000000"], exit: 2, says: &["--lights", "LUXEVAL_MAX_PRIMS"], ..Case::default() };
    bench_command_sets_device: Case { args: &["bench", "--no-startup", "--no-dome", "--command", "falloff {in}/ok.usda --device cpu"], exit: 2, says: &["--command", "--device"], ..Case::default() };
    bench_command_empty: Case { args: &["bench", "--no-startup", "--no-dome", "--command", "  "], exit: 2, says: &["--command"], ..Case::default() };
    bench_command_bad_scene: Case { args: &["bench", "--no-startup", "--no-dome", "--samples", "8", "--cpu-samples", "8", "--lights", "1", "--command", "emission {in}/missing.usda --dirs {in}/dirs.npy -o {out}/out.npy"], exit: 2, says: &["--command", "missing.usda"], ..Case::default() };
    falloff_res_1e10_pixels: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "100000,100000", "-o", "{out}/m.exr", "--device", "cpu"], exit: 2, says: &["--res", "LUXEVAL_MAX_SAMPLES"], ..Case::default() };
    falloff_png_too_elongated: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "33818560,1", "-o", "{out}/m.exr", "--png", "{out}/m.png", "--device", "cpu"], exit: 2, says: &["--png", "33818560×1", "pixels"], ..Case::default() };
    falloff_png_subnormal_linear_range: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "8,8", "-o", "{out}/m.exr", "--png", "{out}/m.png", "--scale", "linear", "--range", "0,1e-323", "--device", "cpu"], exit: 0, ..Case::default() };
    falloff_png_negative_low_on_a_linear_scale: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "8,8", "-o", "{out}/m.exr", "--png", "{out}/m.png", "--scale", "linear", "--range", "-1,10", "--device", "cpu"], exit: 0, lit: true, ..Case::default() };
    bench_mesh_triangles_too_few: Case { args: &["bench", "--mesh-triangles", "5", "--samples", "16", "--no-startup"], exit: 2, says: &["--mesh-triangles", "18"], ..Case::default() };
    bench_mesh_triangles_over_the_limit: Case { args: &["bench", "--mesh-triangles", "1000000000", "--samples", "16", "--no-startup"], exit: 2, says: &["--mesh-triangles", "LUXEVAL_MAX_MESH_TRIANGLES"], ..Case::default() };
    bench_dome_size_over_the_texture_limit: Case { args: &["bench", "--dome-size", "65536x65536", "--samples", "16", "--no-startup"], exit: 2, says: &["--dome-size", "65536x65536", "pixels"], ..Case::default() };
    dirs_link_to_dev_zero: Case { args: emission!("{in}/ok.usda", "{in}/zero.npy"), exit: 2, says: &["zero.npy"], setup: Some(zero_dirs), ..Case::default() };
    scene_link_to_dev_zero: Case { args: emission!("{in}/zero.usda", "{in}/dirs.npy"), exit: 2, says: &["zero.usda", "not a regular file"], setup: Some(zero_scene), ..Case::default() };
    sublayer_link_to_dev_zero: Case { args: &["lights", "{in}/sublayer_zero.usda"], exit: 2, says: &["zero.usda", "sublayer_zero.usda"], setup: Some(zero_sublayer), ..Case::default() };
    scene_over_file_limit: Case { args: &["lights", "{in}/ok.usda"], exit: 2, env: &[("LUXEVAL_MAX_FILE_BYTES", "100")], says: &["ok.usda", "LUXEVAL_MAX_FILE_BYTES"], ..Case::default() };
    referenced_layer_over_file_limit: Case { args: &["lights", "{in}/references_big_layer.usda"], exit: 2, env: &[("LUXEVAL_MAX_FILE_BYTES", "1000")], says: &["big_layer.usda", "LUXEVAL_MAX_FILE_BYTES"], ..Case::default() };
    // The query commands stream: the limits on rows and bytes bound what is held in memory,
    // not what is read or written chunk by chunk (docs/INPUTS.md "Streaming").
    streamed_rows_and_bytes_are_not_bounded_by_the_limits: Case { args: emission!("{in}/ok.usda", "{in}/many_dirs.npy"), exit: 0, env: &[("LUXEVAL_MAX_SAMPLES", "3"), ("LUXEVAL_MAX_FILE_BYTES", "300")], setup: Some(many_dirs), lit: true, ..Case::default() };
    a_layer_over_the_file_limit_is_refused: Case { args: emission!("{in}/ok.usda", "{in}/dirs.npy"), exit: 2, env: &[("LUXEVAL_MAX_FILE_BYTES", "100")], says: &["ok.usda", "LUXEVAL_MAX_FILE_BYTES"], ..Case::default() };
    streamed_per_light_rows_are_not_bounded: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "cpu", "--per-light"], exit: 0, env: &[("LUXEVAL_MAX_SAMPLES", "7")], lit: true, ..Case::default() };
    held_rows_are_bounded_by_the_sample_limit: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "4,2", "-o", "{out}/m.exr", "--device", "cpu"], exit: 2, env: &[("LUXEVAL_MAX_SAMPLES", "7")], says: &["--res", "8 rows", "LUXEVAL_MAX_SAMPLES"], ..Case::default() };
    limit_variable_not_a_number: Case { args: emission!("{in}/ok.usda", "{in}/dirs.npy"), exit: 2, env: &[("LUXEVAL_MAX_SAMPLES", "lots")], says: &["LUXEVAL_MAX_SAMPLES", "\"lots\""], ..Case::default() };

    // --- Values of the wrong type, or NaN -------------------------------------------------------
    color_int3: Case { args: emission!("{in}/color_int3.usda", "{in}/dirs.npy"), exit: 2, says: &["color_int3.usda", "/L", "inputs:color", "color3f"], ..Case::default() };
    intensity_int: Case { args: emission!("{in}/intensity_int.usda", "{in}/dirs.npy"), exit: 2, says: &["intensity_int.usda", "/L", "inputs:intensity"], ..Case::default() };
    intensity_string: Case { args: &["lights", "{in}/intensity_string.usda"], exit: 2, says: &["intensity_string.usda", "/L", "inputs:intensity"], ..Case::default() };
    normalize_string: Case { args: emission!("{in}/normalize_string.usda", "{in}/dirs.npy"), exit: 2, says: &["normalize_string.usda", "/L", "inputs:normalize"], ..Case::default() };
    start_time_code_nan: Case { args: emission!("{in}/start_time_nan.usda", "{in}/dirs.npy"), exit: 2, says: &["start_time_nan.usda", "startTimeCode"], ..Case::default() };
    start_time_code_inf: Case { args: &["lights", "{in}/start_time_inf.usda"], exit: 2, says: &["start_time_inf.usda", "startTimeCode"], ..Case::default() };
    intensity_nan: Case { args: emission!("{in}/intensity_nan.usda", "{in}/dirs.npy"), exit: 2, says: &["intensity_nan.usda", "/L", "inputs:intensity", "finite"], ..Case::default() };
    intensity_nan_time_sample: Case { args: emission!("{in}/intensity_nan_sample.usda", "{in}/dirs.npy"), exit: 2, says: &["intensity_nan_sample.usda", "/L", "inputs:intensity"], ..Case::default() };
    time_argument_nan: Case { args: &["lights", "{in}/ok.usda", "--time", "nan"], exit: 2, says: &["--time"], ..Case::default() };

    // --- Messages name the file (and prim, attribute or row) ------------------------------------
    // DESIGN.md §2 "Zero-size lights": evaluated with a warning, never refused.
    zero_size_light_with_normalize_is_a_point: Case { args: emission!("{in}/zero_size_normalize.usda", "{in}/dirs.npy"), exit: 0, lit: true, says: &["warning: /L", "point"], ..Case::default() };
    zero_size_lights_beside_others: Case { args: &["irradiance", "{in}/zero_size_beside_others.usda", "--points", "{in}/points.npy", "--normals", "{in}/normals.npy", "-o", "{out}/out.npy", "--per-light", "--device", "cpu"], exit: 0, lit: true, says: &["warning: /Hidden", "emits nothing", "warning: /Point", "point"], ..Case::default() };
    negative_radius: Case { args: emission!("{in}/negative_radius.usda", "{in}/dirs.npy"), exit: 2, says: &["negative_radius.usda", "/L", "inputs:radius"], ..Case::default() };
    singular_transform_emits_nothing: Case { args: emission!("{in}/singular_scale.usda", "{in}/dirs.npy"), exit: 0, says: &["warning: /L", "singular", "emits nothing"], ..Case::default() };
    dirs_row_nan: Case { args: emission!("{in}/ok.usda", "{in}/dirs_nan.npy"), exit: 2, says: &["dirs_nan.npy", "row 2", "not finite"], ..Case::default() };
    dirs_row_zero: Case { args: emission!("{in}/ok.usda", "{in}/dirs_zero_row.npy"), exit: 2, says: &["dirs_zero_row.npy", "row 1", "zero"], ..Case::default() };
    points_row_inf: Case { args: &["irradiance", "{in}/ok.usda", "--points", "{in}/points_inf.npy", "--normals", "{in}/normals.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 2, says: &["points_inf.npy", "row 0"], ..Case::default() };
    normals_row_zero: Case { args: &["irradiance", "{in}/ok.usda", "--points", "{in}/points.npy", "--normals", "{in}/normals_zero.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 2, says: &["normals_zero.npy", "row 2"], ..Case::default() };
    radiance_row_counts_differ: Case { args: &["radiance", "{in}/ok.usda", "--points", "{in}/points.npy", "--dirs", "{in}/dirs5.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 2, says: &["points.npy", "dirs5.npy", "4 rows", "5"], ..Case::default() };
    irradiance_row_counts_differ: Case { args: &["irradiance", "{in}/ok.usda", "--points", "{in}/points.npy", "--normals", "{in}/dirs5.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 2, says: &["points.npy", "dirs5.npy"], ..Case::default() };

    // --- Malformed files ------------------------------------------------------------------------
    malformed_usda: Case { args: &["lights", "{in}/malformed.usda"], exit: 2, says: &["malformed.usda:"], ..Case::default() };
    // usd-core composes without a reference it cannot find, and so does luxeval, saying so: the
    // light (which authors the reference) is still evaluated.
    missing_reference_is_left_out_with_a_warning: Case { args: emission!("{in}/missing_reference.usda", "{in}/dirs.npy"), exit: 0, says: &["warning:", "does_not_exist.usda", "missing_reference.usda", "cannot be found"], lit: true, ..Case::default() };
    empty_usda: Case { args: &["lights", "{in}/empty.usda"], exit: 2, says: &["empty.usda"], ..Case::default() };
    not_usd: Case { args: &["lights", "{in}/not_usd.usda"], exit: 2, says: &["not_usd.usda"], ..Case::default() };
    truncated_usdc: Case { args: &["lights", "{in}/truncated.usdc"], exit: 2, says: &["truncated.usdc"], ..Case::default() };
    usdc_table_of_contents_far_away: Case { args: &["lights", "{in}/toc_offset.usdc"], exit: 2, says: &["toc_offset.usdc"], ..Case::default() };
    corrupt_usdz: Case { args: &["lights", "{in}/corrupt.usdz"], exit: 2, says: &["corrupt.usdz"], ..Case::default() };
    deflated_usdz: Case { args: &["lights", "{in}/deflated.usdz"], exit: 2, says: &["deflated.usdz"], ..Case::default() };
    npy_int_dtype: Case { args: emission!("{in}/ok.usda", "{in}/npy_int.npy"), exit: 2, says: &["npy_int.npy", "float32 or float64"], ..Case::default() };
    npy_object_dtype: Case { args: emission!("{in}/ok.usda", "{in}/npy_object.npy"), exit: 2, says: &["npy_object.npy", "float32 or float64"], ..Case::default() };
    npy_three_dimensions: Case { args: emission!("{in}/ok.usda", "{in}/npy_3d.npy"), exit: 2, says: &["npy_3d.npy", "(N, 3)"], ..Case::default() };
    npy_header_with_code: Case { args: emission!("{in}/ok.usda", "{in}/npy_header_code.npy"), exit: 2, says: &["npy_header_code.npy", "header"], ..Case::default() };
    npy_not_numpy: Case { args: emission!("{in}/ok.usda", "{in}/npy_not_numpy.npy"), exit: 2, says: &["npy_not_numpy.npy", "not a .npy file"], ..Case::default() };
    light_not_in_stage: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "cpu", "--light", "/nope"], exit: 2, says: &["/nope", "ok.usda"], ..Case::default() };

    // --- IES profiles (shaping:ies:file and `luxeval ies`) -------------------------------------
    ies_profile_missing: Case { args: emission!("{in}/ies_missing_file.usda", "{in}/dirs.npy"), exit: 2, says: &["ies_missing_file.usda", "/L", "inputs:shaping:ies:file", "missing.ies"], ..Case::default() };
    ies_profile_truncated_in_stage: Case { args: emission!("{in}/ies_truncated.usda", "{in}/dirs.npy"), exit: 2, says: &["/L", "inputs:shaping:ies:file", "ies_truncated.ies:7", "candela"], ..Case::default() };
    ies_without_tilt_line: Case { args: &["ies", "{in}/ies_no_tilt.ies"], exit: 2, says: &["ies_no_tilt.ies", "TILT="], ..Case::default() };
    ies_count_not_integer: Case { args: &["ies", "{in}/ies_bad_count.ies"], exit: 2, says: &["ies_bad_count.ies:3", "integer", "3.5"], ..Case::default() };
    ies_tilt_file_missing: Case { args: &["ies", "{in}/ies_tilt_missing.ies"], exit: 2, says: &["ies_tilt_missing.ies:2", "nothere.tilt"], ..Case::default() };
    ies_truncated: Case { args: &["ies", "{in}/ies_truncated.ies", "--png", "{out}/p.png"], exit: 2, says: &["ies_truncated.ies:7", "missing value"], ..Case::default() };
    // Assets are opened only when they are regular files (no blocked open on a FIFO, no read of
    // a device), by the one asset-opening function.
    ies_profile_is_a_fifo: Case { args: emission!("{in}/ies_missing_file.usda", "{in}/dirs.npy"), exit: 2, says: &["/L", "inputs:shaping:ies:file", "missing.ies", "not a regular file"], setup: Some(fifo_ies), ..Case::default() };
    ies_profile_is_dev_zero: Case { args: emission!("{in}/ies_missing_file.usda", "{in}/dirs.npy"), exit: 2, says: &["/L", "inputs:shaping:ies:file", "missing.ies", "not a regular file"], setup: Some(zero_ies), ..Case::default() };
    tilt_file_is_a_fifo: Case { args: &["ies", "{in}/ies_tilt_missing.ies"], exit: 2, says: &["ies_tilt_missing.ies:2", "nothere.tilt", "not a regular file"], setup: Some(fifo_tilt), ..Case::default() };
    dome_texture_is_a_fifo: Case { args: emission!("{in}/dome_sky.usda", "{in}/dirs.npy"), exit: 2, says: &["/D", "inputs:texture:file", "sky.exr", "not a regular file"], setup: Some(fifo_texture), ..Case::default() };
    dome_texture_is_dev_zero: Case { args: emission!("{in}/dome_sky.usda", "{in}/dirs.npy"), exit: 2, says: &["/D", "inputs:texture:file", "sky.exr", "not a regular file"], setup: Some(zero_texture), ..Case::default() };
    // One refusal path for both devices: the same lights refused, naming the light, the
    // attribute and the file (the GPU once said "profile 0"; the CPU evaluated the normalized one).
    ies_candela_beyond_float32: Case { args: emission!("{in}/ies_huge.usda", "{in}/dirs.npy"), exit: 2, says: &["/L", "inputs:shaping:ies:file", "ies_huge.ies", "1e39", "float32"], ..Case::default() };
    ies_candela_beyond_float32_normalized: Case { args: emission!("{in}/ies_huge_normalized.usda", "{in}/dirs.npy"), exit: 2, says: &["/L", "inputs:shaping:ies:file", "ies_huge.ies", "1e39", "float32"], ..Case::default() };
    ies_candela_beyond_float32_on_the_gpu: Case { args: &["emission", "{in}/ies_huge_normalized.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "gpu"], exit: 2, says: &["/L", "inputs:shaping:ies:file", "ies_huge.ies", "1e39", "float32"], gpu: true, ..Case::default() };
    ies_png_is_the_profile: Case { args: &["ies", "{in}/ies_bad_count.ies", "--png", "{in}/ies_bad_count.ies"], exit: 2, says: &["--png", "ies_bad_count.ies"], ..Case::default() };

    // --- Mesh lights (DESIGN.md §7 M1): bad topology refuses the query, naming prim and attribute
    mesh_face_with_two_vertices: Case { args: emission!("{in}/count_below_3.usda", "{in}/dirs.npy"), exit: 2, says: &["count_below_3.usda", "/Bad", "faceVertexCounts", "at least 3"], setup: Some(mesh_stages), ..Case::default() };
    mesh_index_out_of_range: Case { args: emission!("{in}/index_out_of_range.usda", "{in}/dirs.npy"), exit: 2, says: &["index_out_of_range.usda", "/Bad", "faceVertexIndices", "7"], setup: Some(mesh_stages), ..Case::default() };
    mesh_negative_index: Case { args: emission!("{in}/negative_index.usda", "{in}/dirs.npy"), exit: 2, says: &["negative_index.usda", "/Bad", "faceVertexIndices", "-2"], setup: Some(mesh_stages), ..Case::default() };
    mesh_counts_not_summing_to_the_indices: Case { args: emission!("{in}/counts_not_summing.usda", "{in}/dirs.npy"), exit: 2, says: &["counts_not_summing.usda", "/Bad", "faceVertexIndices", "sums to 4"], setup: Some(mesh_stages), ..Case::default() };
    mesh_non_finite_point: Case { args: emission!("{in}/non_finite_point.usda", "{in}/dirs.npy"), exit: 2, says: &["non_finite_point.usda", "/Bad", "points", "not finite"], setup: Some(mesh_stages), ..Case::default() };
    mesh_hole_out_of_range: Case { args: emission!("{in}/hole_out_of_range.usda", "{in}/dirs.npy"), exit: 2, says: &["hole_out_of_range.usda", "/Bad", "holeIndices", "3"], setup: Some(mesh_stages), ..Case::default() };
    mesh_triangles_over_the_limit: Case { args: emission!("{in}/mesh_lights.usda", "{in}/dirs.npy"), exit: 2, env: &[("LUXEVAL_MAX_MESH_TRIANGLES", "3")], says: &["mesh_lights.usda", "/World/Signs/Quads", "4 triangles", "LUXEVAL_MAX_MESH_TRIANGLES"], setup: Some(mesh_stages), ..Case::default() };
    // The dome and the mesh lights are evaluated; a portal the dome names says how it is
    // evaluated (DESIGN.md §8 P2), one no dome names that it is read, not evaluated.
    portals_say_how_they_are_evaluated: Case { args: emission!("{in}/mesh_lights.usda", "{in}/dirs.npy"), exit: 0, lit: true, says: &["/World/Window: portal of /World/Sky: guides sampling only (hint mode)", "/World/Skylight: portal read, not evaluated yet"], setup: Some(mesh_stages), ..Case::default() };
    portal_mode_bogus: Case { args: &["irradiance", "{in}/ok.usda", "--points", "{in}/dirs.npy", "--normals", "{in}/dirs.npy", "-o", "{out}/out.npy", "--portal-mode", "bogus"], exit: 2, says: &["--portal-mode", "bogus", "hint, mask"], ..Case::default() };

    // --- Runtime failures: exit 1 ---------------------------------------------------------------
    disk_full_while_writing_npy: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "cpu"], exit: 1, fsize: Some(100), says: &["writing", "out.npy"], ..Case::default() };
    disk_full_while_writing_exr: Case { args: &["falloff", "{in}/ok.usda", "--origin", "-1,0,-1", "--u", "2,0,0", "--v", "0,0,2", "--res", "64,64", "-o", "{out}/m.exr", "--png", "{out}/m.png", "--device", "cpu"], exit: 1, fsize: Some(1000), says: &["writing", "m.exr"], ..Case::default() };
    no_adapter_with_device_gpu: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "gpu"], exit: 1, env: NO_GPU, says: &["no GPU adapter"], ..Case::default() };
    no_adapter_falls_back_to_the_cpu: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy"], exit: 0, env: NO_GPU, lit: true, says: &["warning: --device auto: the CPU reference: no GPU adapter"], ..Case::default() };
    gpu_device_lost: Case { args: &["emission", "{in}/ok.usda", "--dirs", "{in}/dirs.npy", "-o", "{out}/out.npy", "--device", "gpu"], exit: 1, gpu: true, env: &[("LUXEVAL_TEST_FAULT", "device-lost")], says: &["GPU", "device was lost"], ..Case::default() };
    check_without_adapter: Case { args: &["check", "{in}/ok.usda", "--samples", "10"], exit: 1, env: NO_GPU, says: &["GPU"], ..Case::default() };
}

/// The corpus covers at least 60 kinds of bad input, and no file of it is left unused.
#[test]
fn the_corpus_has_at_least_60_cases_and_every_file_is_used() {
    assert!(CASES.len() >= 60, "{} cases", CASES.len());
    // file!() is relative to the workspace root; tests run in cli/.
    let src = std::fs::read_to_string(crate::repo().join(file!())).unwrap()
        + &std::fs::read_to_string(crate::repo().join("cli/tests/bad_inputs/setups.rs")).unwrap();
    for e in std::fs::read_dir(corpus()).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        assert!(
            src.contains(&format!("{{in}}/{name}")) || src.contains(&format!("\"{name}\"")),
            "tests/data/bad/{name} is used by no case"
        );
    }
}
