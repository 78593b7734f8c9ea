//! IES photometry as a library (DESIGN.md §6 "IES"): read LM-63 and EULUMDAT files, prepare a
//! profile (symmetry folds, the exact mean intensity over the bilinear interpolant, tilt), look
//! up its candela toward a light-space direction exactly as both backends do, and the numbers a
//! photometric report shows. `luxeval ies FILE` prints them.

mod report;

pub use report::{FLUX_MISMATCH, PlaneReport, Range, Report, trimmed};

pub use crate::assets::ies::eulumdat::{EulumdatInfo, LampSet, parse_eulumdat};
pub use crate::assets::ies::lm63::{
    Format, Lm63Version, Tilt, TiltSource, TypeCCoverage, type_c_coverage,
};
pub use crate::assets::ies::{
    IesError, IesErrorKind, IesFile, PhotometricType, parse_any, parse_lm63, read_file,
};
pub use crate::prepare::ies::{FluxCheck, HFold, Peak, Plane, Profile, Spread, VFold};

/// The f64 lookup, step by step (twin of `shaders/shared/ies.wgsl`): light-space direction →
/// photometric angles → angleScale → folds → bilinear on the file's own grid.
pub mod lookup {
    pub use crate::cpu::ies::{
        bilinear, fold_h_type_c, fold_mirror, ies_factor, photometric_angles, scale_polar_angle,
        scaled_direction, type_a_angles, type_b_angles, type_c_angles,
    };
}

pub use lookup::ies_factor;
