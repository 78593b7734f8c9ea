//! Photometric files read from scratch (DESIGN.md §6 I1): ANSI/IES LM-63 (1986, 1991, 1995,
//! 2002, 2019; TILT NONE, INCLUDE and `<file>`) and EULUMDAT (`.ldt`), detected by content. No
//! permissively licensed crate reads LM-63-2019 (reference/rust-ecosystem.md §2).

pub mod error;
pub mod eulumdat;
pub mod lm63;
mod text;

pub use error::{IesError, IesErrorKind};
pub use eulumdat::{parse_any, read_file};
#[cfg(any(test, feature = "testkit"))]
pub use lm63::parse_lm63;
pub use lm63::{IesFile, PhotometricType};
