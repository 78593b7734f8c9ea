//! Exit codes (DESIGN.md §4): 0 success, 1 runtime failure, 2 bad input. Every failure is
//! reported once, on stderr.

use std::path::Path;

use luxeval::LuxError;

/// A failure with its exit code.
pub struct Failure {
    pub code: u8,
    pub message: String,
}

impl From<LuxError> for Failure {
    fn from(e: LuxError) -> Self {
        Failure {
            code: if e.is_bad_input() { 2 } else { 1 },
            message: e.to_string(),
        }
    }
}

impl Failure {
    pub fn runtime(message: impl Into<String>) -> Self {
        Failure {
            code: 1,
            message: message.into(),
        }
    }

    pub fn bad_input(message: impl Into<String>) -> Self {
        Failure {
            code: 2,
            message: message.into(),
        }
    }
}

pub type CliResult<T = ()> = Result<T, Failure>;

/// An error about a light of `scene`, prefixed with the stage's path.
pub fn in_scene(scene: &Path, e: LuxError) -> Failure {
    let f = Failure::from(e);
    Failure {
        code: f.code,
        message: format!("{}: {}", scene.display(), f.message),
    }
}
