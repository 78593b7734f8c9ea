//! The light model: lights as plain data, independent of where they came from (a USD stage, or
//! built in code), with the one table of UsdLux schema fallbacks and the resolved values of
//! authored inputs. Depends on nothing else in the crate (DESIGN.md §1).

pub mod asset;
pub mod light;
pub mod mesh;
pub mod portal;
pub mod schema;
pub mod value;

pub use asset::Asset;
pub use light::{
    Ies, Light, LightInputs, LightType, PoleAxis, Shaping, Texture, TextureFilter, TextureFormat,
    UpAxis,
};
pub use mesh::{MeshGeometry, MeshLight, MeshTopology, MeshTriangle, Tint, TopologyError};
pub use portal::{Portal, PortalMode};
pub use value::{Input, Value};
