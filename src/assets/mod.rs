//! Readers of the files a stage references (DESIGN.md §1: the assets `prepare` loads): IES
//! photometric profiles (LM-63 and EULUMDAT) and textures (OpenEXR, PNG, JPEG, Radiance HDR).
//! Leaf modules: they depend on nothing else of luxeval, so that a reader can be fuzzed and
//! tested on its own.

pub mod ies;
pub mod package;
pub mod texture;
