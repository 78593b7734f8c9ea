//! Reading lights from USD stages into the model (DESIGN.md §1): the only module that imports
//! openusd, and it depends on nothing of luxeval but [`crate::model`] and the errors.
//!
//! [`stage`] opens `.usda`, `.usdc` and `.usdz` files with full composition (sublayers,
//! references, payloads all loaded, variant selections, inherits, specializes, instancing) and
//! returns plain data: stage metadata, and for every light prim its type, applied schemas,
//! visibility, world matrix and every attribute of [`crate::model::schema::attrs_for`] resolved
//! at one time. [`scene`] decides what each light means to luxeval (each prim converted by
//! [`light`]).
//!
//! Value resolution and transforms are openusd's, checked against Pixar's usd-core in
//! `tests/usd_fixtures.rs`, except where openusd 0.8 gives other numbers than usd-core; there
//! this module computes what usd-core does:
//! - a time-sampled `orient` op between samples: usd-core's `GfSlerp` rounds to the
//!   quaternion's scalar type ([`xform`]);
//! - between a sample and a blocked one: usd-core holds the lower sample ([`values`]), for
//!   inputs, xformOps and `visibility` alike;
//! - spline-valued attributes, which openusd reads as unauthored, are refused ([`values`]).
//!
//! Fallbacks of unauthored attributes come from luxeval's schema table, not from openusd's
//! registry, so there is exactly one table of them.

mod arcs;
mod diagnostics;
mod light;
mod mesh;
mod portals;
mod progress;
mod reading;
mod resolver;
pub(crate) mod scene;
pub(crate) mod stage;
mod unapplied;
mod usda;
mod values;
mod xform;

pub use light::RefusedInput;
pub use progress::LoadProgress;
pub use scene::{Stage, StageLight, TimeRule};
pub use stage::{StageInfo, UsdStage};
pub use unapplied::{LightList, LinkCollection};
