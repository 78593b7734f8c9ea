//! `Stage::load_with_progress`: the steps a caller is told about, in order and with counts that
//! match the stage, the same stage as `Stage::load`, and a caller that gives up.
#![cfg(feature = "usd")]

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use luxeval::{LoadProgress, LuxError, Stage};

/// A stage of `n` SphereLights, four to an Xform under `/World` (the shape of
/// tools/gen_big_stage.py): `n + n / 4 + 1` prims.
fn stage_of(dir: &Path, n: usize) -> PathBuf {
    let mut text = String::from("#usda 1.0\n(\n    upAxis = \"Y\"\n)\n\ndef Xform \"World\"\n{\n");
    for g in 0..n / 4 {
        text += &format!("    def Xform \"G{g}\"\n    {{\n");
        for l in 0..4 {
            text += &format!(
                "        def SphereLight \"L{l}\"\n        {{\n            float inputs:intensity = {}\n            double3 xformOp:translate = ({g}, {l}, 0)\n            uniform token[] xformOpOrder = [\"xformOp:translate\"]\n        }}\n",
                1 + l
            );
        }
        text += "    }\n";
    }
    text += "}\n";
    let path = dir.join("lights.usda");
    std::fs::write(&path, text).unwrap();
    path
}

/// The step a report belongs to, in the order they come.
fn step(p: &LoadProgress) -> u8 {
    match p {
        LoadProgress::Opening => 0,
        LoadProgress::Checking => 1,
        LoadProgress::Traversing { .. } => 2,
        LoadProgress::Finding { .. } => 3,
        LoadProgress::Reading { .. } => 4,
        _ => unreachable!("a step this test does not know: {p:?}"),
    }
}

#[test]
fn every_step_is_reported_in_order_with_the_stages_counts() {
    let dir = tempfile::tempdir().unwrap();
    let n = 3000;
    let prims = (n + n / 4 + 1) as u64;
    let path = stage_of(dir.path(), n);
    let mut seen = Vec::new();
    let stage = Stage::load_with_progress(&path, None, |p| {
        // While the reader is silent the last report comes again: kept once.
        if seen.last() != Some(&p) {
            seen.push(p);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(stage, Stage::load(&path, None).unwrap());
    assert_eq!(stage.lights.len(), n);
    let steps: Vec<u8> = seen.iter().map(step).collect();
    assert!(steps.is_sorted(), "steps out of order: {seen:?}");
    assert_eq!(seen[0], LoadProgress::Opening);
    assert_eq!(seen[1], LoadProgress::Checking);
    // Each step from its start to its end, with a report every 1,024 items between.
    let counts = |of: u8| -> Vec<(u64, u64)> {
        seen.iter()
            .filter(|p| step(p) == of)
            .map(|p| match *p {
                LoadProgress::Traversing { prims } => (prims, 0),
                LoadProgress::Finding { done, total } | LoadProgress::Reading { done, total } => {
                    (done, total)
                }
                _ => unreachable!(),
            })
            .collect()
    };
    let every = |end: u64| {
        (0..=end / 1024)
            .map(|k| k * 1024)
            .chain([end])
            .collect::<Vec<_>>()
    };
    let traversed: Vec<u64> = counts(2).iter().map(|c| c.0).collect();
    assert_eq!(traversed, every(prims), "{seen:?}");
    let found = counts(3);
    assert_eq!(
        found,
        every(prims).iter().map(|&d| (d, prims)).collect::<Vec<_>>()
    );
    let read = counts(4);
    assert_eq!(
        read,
        every(n as u64)
            .iter()
            .map(|&d| (d, n as u64))
            .collect::<Vec<_>>()
    );
}

#[test]
fn a_caller_that_gives_up_gets_cancelled_naming_the_stage() {
    let dir = tempfile::tempdir().unwrap();
    let path = stage_of(dir.path(), 3000);
    // At every step in turn, at its first report.
    for stop_at in 0..5u8 {
        let mut after = Vec::new();
        let err = Stage::load_with_progress(&path, None, |p| {
            after.push(p);
            match step(&p) >= stop_at {
                true => ControlFlow::Break(()),
                false => ControlFlow::Continue(()),
            }
        })
        .unwrap_err();
        match &err {
            LuxError::Cancelled { path: p } => assert_eq!(p, &path),
            e => panic!("step {stop_at}: not Cancelled: {e}"),
        }
        assert!(
            err.to_string()
                .contains("lights.usda: reading the stage was cancelled")
        );
        assert!(!err.is_bad_input());
        // Nothing is reported after the Break.
        assert_eq!(step(after.last().unwrap()), stop_at, "{after:?}");
    }
    // A stage that cannot be read is its own error, whatever the caller says.
    let missing = dir.path().join("missing.usda");
    let err = Stage::load_with_progress(&missing, None, |_| ControlFlow::Continue(())).unwrap_err();
    assert!(matches!(err, LuxError::Io { .. }), "{err}");
}
