//! Mesh lights (MeshLightAPI, DESIGN.md §7) on the CPU reference, in f64: what the queries need
//! beyond the model's triangles.
//!
//! - [`visible`]: the parts of a mesh's triangles seen from a point (gnomonic charts) or from a
//!   direction at infinity (orthographic), with the mesh's self-occlusion, exactly: what M3's
//!   irradiance and intensity integrate.

pub(crate) mod visible;
