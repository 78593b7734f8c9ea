//! Seeded synthetic inputs: a small deterministic generator, randomised lights of every type
//! and transform kind, mesh lights, and samples aimed at each light. The conformance check
//! (`luxeval check`) draws its samples here and `luxeval bench` its lights; the test suites use
//! the same ones through `testkit`.

mod lights;
mod mesh;
#[cfg(any(test, feature = "testkit"))]
mod portals;
mod rng;
pub(crate) mod samples;

pub use lights::synthetic_lights;
#[cfg(any(test, feature = "testkit"))]
pub use lights::{TRANSFORMS, random_light, random_lights, transform};
#[cfg(any(test, feature = "testkit"))]
pub use mesh::{MESH_CLASSES, MeshSource, random_mesh_light, random_mesh_lights, torus};
pub use mesh::{synthetic_mesh_light, torus_rays};
#[cfg(any(test, feature = "testkit"))]
pub use portals::random_portal_dome;
pub use rng::Rng;
pub use samples::{emission_samples, irradiance_samples, radiance_samples};
