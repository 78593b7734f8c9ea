//! openusd's failures as luxeval errors that name the file, the layer and the line.

use std::path::{Path, PathBuf};

use openusd::sdf;
use openusd::usd as ousd;

use crate::error::{LuxError, Result};

/// Layer-level composition failures are errors: a light rig whose reference did not load would
/// otherwise be evaluated without its lights, silently. Other diagnostics (an arc to a prim the
/// layer lacks, a variant selection naming no variant) compose as usd-core does, with a warning.
pub(super) fn check_composition(file: &Path, stage: &ousd::Stage) -> Result<()> {
    use openusd::pcp::CompositionDiagnostic as D;
    for d in stage.composition_errors() {
        match d {
            D::UnresolvedLayer {
                asset_path,
                arc,
                introduced_by,
                site_path,
            } => {
                return Err(LuxError::Io {
                    path: anchored(&introduced_by, &asset_path),
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!(
                            "cannot open the {arc:?} layer @{asset_path}@ authored on {site_path} in {introduced_by}"
                        ),
                    ),
                });
            }
            D::UnresolvedSublayer {
                asset_path,
                introduced_by,
            } => {
                return Err(LuxError::Io {
                    path: anchored(&introduced_by, &asset_path),
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!("cannot open the sublayer @{asset_path}@ of {introduced_by}"),
                    ),
                });
            }
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
    Ok(())
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
        E::Io(source) => LuxError::Io {
            path: path.to_path_buf(),
            source,
        },
        E::Format(sdf::FormatError::Io(source)) => LuxError::Io {
            path: path.to_path_buf(),
            source,
        },
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
