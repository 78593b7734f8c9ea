//! openusd's failures as luxeval errors that name the file, the layer and the line.

use std::path::{Path, PathBuf};

use openusd::sdf;
use openusd::usd as ousd;

use super::resolver::LayerSyntaxError;
use crate::error::{LuxError, Result};

/// What openusd reports while composing, as usd-core treats it: a sublayer, reference or payload
/// that cannot be found, or whose file format luxeval does not read (`.mtlx`, `.drc`, `.abc`, …),
/// is left out of the composition with a warning naming the arc, its layer and the prim, and the
/// rest of the stage (its other lights) is read (docs/INPUTS.md "Stages"). A layer that is
/// found and is USD but malformed is an error: its lights would be missing without a reason a
/// user can act on. Other diagnostics (an arc to a prim the layer lacks, a variant selection
/// naming no variant) compose as usd-core does, logged.
///
/// Diagnostics are taken in sorted order, so a stage gives the same first error every run
/// (openusd's order follows its hash maps). Returns the warnings, sorted.
pub(super) fn check_composition(file: &Path, stage: &ousd::Stage) -> Result<Vec<String>> {
    use openusd::pcp::CompositionDiagnostic as D;
    let mut diagnostics = stage.composition_errors();
    diagnostics.sort_by_cached_key(|d| d.to_string());
    let mut warnings = Vec::new();
    for d in diagnostics {
        match d {
            D::UnresolvedLayer {
                asset_path,
                arc,
                introduced_by,
                site_path,
            } => warnings.push(format!(
                "{introduced_by}: the {arc:?} layer @{asset_path}@ authored on <{site_path}> \
                 cannot be found; the stage is composed without it, as usd-core does, so \
                 lights it would add are missing"
            )),
            D::UnresolvedSublayer {
                asset_path,
                introduced_by,
            } => warnings.push(format!(
                "{introduced_by}: the sublayer @{asset_path}@ cannot be found; the stage is \
                 composed without it, as usd-core does, so lights it would add are missing"
            )),
            D::MalformedLayer {
                asset_path,
                arc,
                introduced_by,
                site_path,
                ..
            } if !readable_format(&asset_path) => warnings.push(format!(
                "{introduced_by}: the {arc:?} layer @{asset_path}@ authored on <{site_path}> is \
                 in a format luxeval does not read; the stage is composed without it, as \
                 usd-core does without that format's plugin, so lights it would add are missing"
            )),
            D::MalformedSublayer {
                asset_path,
                introduced_by,
                ..
            } if !readable_format(&asset_path) => warnings.push(format!(
                "{introduced_by}: the sublayer @{asset_path}@ is in a format luxeval does not \
                 read; the stage is composed without it, as usd-core does without that \
                 format's plugin, so lights it would add are missing"
            )),
            D::MalformedLayer {
                asset_path,
                arc,
                introduced_by,
                site_path,
                reason,
            } => {
                let (line, reason) = located(&reason);
                return Err(LuxError::Format {
                    path: anchored(&introduced_by, &asset_path),
                    line,
                    reason: format!(
                        "{reason} (the {arc:?} layer authored on {site_path} in {introduced_by})"
                    ),
                });
            }
            D::MalformedSublayer {
                asset_path,
                introduced_by,
                reason,
            } => {
                let (line, reason) = located(&reason);
                return Err(LuxError::Format {
                    path: anchored(&introduced_by, &asset_path),
                    line,
                    reason: format!("{reason} (a sublayer of {introduced_by})"),
                });
            }
            // luxeval's own walk (`super::arcs`) refuses every cycle and every chain too deep
            // for openusd before composing; one that openusd still reports would drop a prim
            // (and its light) silently, so it is an error too.
            D::ArcCycle(chain) => {
                return Err(LuxError::Format {
                    path: file.to_path_buf(),
                    line: None,
                    reason: format!(
                        "composition arc cycle at prim <{}> (openusd 0.8 drops the prim; if \
                         usd-core composes this stage, it exceeds what openusd composes)",
                        chain.composing
                    ),
                });
            }
            other => log::warn!("{}: {other}", file.display()),
        }
    }
    warnings.sort();
    warnings.dedup();
    Ok(warnings)
}

/// Whether `asset` names a layer of a format openusd reads (by its extension, as openusd's
/// layer registry chooses the format): `.usda`, `.usdc`, `.usd`, `.usdz`, also inside a package.
pub(super) fn readable_format(asset: &str) -> bool {
    // `pkg.usdz[inner.usda]`: the innermost layer's name; `a.usda:SDF_FORMAT_ARGS:…`: its path.
    let name = asset.trim_end_matches(']');
    let name = name.rsplit('[').next().unwrap_or(name);
    let name = name.split(":SDF_FORMAT_ARGS:").next().unwrap_or(name);
    let ext = Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default()
        .to_ascii_lowercase();
    matches!(ext.as_str(), "usda" | "usdc" | "usd" | "usdz")
}

/// `asset` as a path: itself when absolute (openusd reports some resolved), else anchored to
/// the directory of the filesystem layer `layer` (inside a package, the authored path as is).
fn anchored(layer: &str, asset: &str) -> PathBuf {
    let a = Path::new(asset);
    if a.is_absolute() || layer.contains('[') {
        return a.to_path_buf();
    }
    match Path::new(layer).parent() {
        Some(dir) => dir.join(a),
        None => a.to_path_buf(),
    }
}

/// Splits openusd's rendered diagnostics (`error: why\n --> file:line:col\n | snippet`) into the
/// line and a one-line reason.
fn located(rendered: &str) -> (Option<usize>, String) {
    let mut lines = rendered.lines();
    let first = lines.next().unwrap_or_default();
    let reason = first.strip_prefix("error: ").unwrap_or(first).to_string();
    let line = rendered.lines().find_map(|l| {
        let loc = l.trim_start().strip_prefix("--> ")?;
        // `file:line:col`; the file may itself contain colons, so count from the right.
        let mut parts = loc.rsplitn(3, ':');
        let _col = parts.next()?;
        parts.next()?.parse::<usize>().ok()
    });
    (line, reason)
}

/// Maps a failure to open the root layer.
pub(super) fn open_error(path: &Path, e: openusd::Error) -> LuxError {
    use openusd::Error as E;
    match e {
        E::Io(source) | E::Format(sdf::FormatError::Io(source)) => {
            match source
                .get_ref()
                .and_then(|e| e.downcast_ref::<LayerSyntaxError>())
            {
                Some(syntax) => LuxError::Format {
                    path: path.to_path_buf(),
                    line: Some(syntax.error.line),
                    reason: syntax.error.reason.clone(),
                },
                None => LuxError::Io {
                    path: path.to_path_buf(),
                    source,
                },
            }
        }
        E::Parse(pe) => LuxError::Format {
            path: path.to_path_buf(),
            line: Some(pe.line()),
            reason: located(&pe.to_string()).1,
        },
        E::Format(sdf::FormatError::Decode(inner)) => {
            match inner.downcast_ref::<openusd::usda::ParseError>() {
                Some(pe) => LuxError::Format {
                    path: path.to_path_buf(),
                    line: Some(pe.line()),
                    reason: located(&pe.to_string()).1,
                },
                None => LuxError::Format {
                    path: path.to_path_buf(),
                    line: None,
                    reason: inner.to_string(),
                },
            }
        }
        E::UnresolvedAsset(_) => LuxError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "cannot resolve the file"),
        },
        E::UnsupportedFormat(_) => LuxError::Format {
            path: path.to_path_buf(),
            line: None,
            reason: "not a USD file (expected .usda, .usdc or .usdz)".into(),
        },
        other => stage_error(path, other),
    }
}

/// Any other openusd failure while reading the stage: the file's content is what is wrong.
pub(super) fn stage_error(path: &Path, e: openusd::Error) -> LuxError {
    let rendered = e.to_string();
    let (line, reason) = located(&rendered);
    LuxError::Format {
        path: path.to_path_buf(),
        line,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn located_reads_line_and_reason() {
        let (line, reason) = located(
            "error: Expected a number\n --> /a/b:c.usda:5:30\n  |\n5 |  x = = 3\n  |      ^",
        );
        assert_eq!(line, Some(5));
        assert_eq!(reason, "Expected a number");
        assert_eq!(located("plain failure"), (None, "plain failure".into()));
    }

    #[test]
    fn formats_read_by_extension() {
        for a in [
            "a.usda",
            "b/c.USD",
            "p.usdz",
            "p.usdz[x/y.usdc]",
            "a.usda:SDF_FORMAT_ARGS:x=1",
        ] {
            assert!(readable_format(a), "{a}");
        }
        for a in [
            "looks.mtlx",
            "mesh.drc",
            "anim.abc",
            "p.usdz[x.mtlx]",
            "noext",
        ] {
            assert!(!readable_format(a), "{a}");
        }
    }

    #[test]
    fn anchoring() {
        assert_eq!(
            anchored("/a/b/root.usda", "sub/x.usda"),
            PathBuf::from("/a/b/sub/x.usda")
        );
        assert_eq!(
            anchored("/a/root.usda", "/abs.usda"),
            PathBuf::from("/abs.usda")
        );
        assert_eq!(
            anchored("/a/p.usdz[root.usda]", "x.usda"),
            PathBuf::from("x.usda")
        );
    }
}
