//! All IES profiles of a stage packed into one flat `f32` storage buffer for
//! `shaders/shared/ies.wgsl` (its f32 replay for tests is `testkit::ies_replay`).
//!
//! Layout (indices into the `f32` array; every integer is stored as an exactly representable
//! f32 value, so the atlas must stay below 2²⁴ floats = 64 MiB):
//! ```text
//! base + 0  photometric type (1 = C, 2 = B, 3 = A)
//! base + 1  horizontal fold (HFold code: 0 as given, 1 mirror, 2 constant, 3 quadrant,
//!           4 half, 5 half C90, 6 full)
//! base + 2  vertical fold (VFold code: 0 as given, 1 mirror)
//! base + 3  nH
//! base + 4  nV
//! base + 5  offset of the nH horizontal angles (degrees, strictly increasing)
//! base + 6  offset of the nV vertical angles (degrees, strictly increasing)
//! base + 7  offset of the nH·nV candela values (multipliers applied), h-major: [i·nV + j]
//! base + 8  the horizontal angles, then the vertical angles, then the candela values
//! ```
//! A light record stores its profile's `base` (`Atlas::bases[k]`). The grids are the profile's
//! own, non-uniform ones: nothing is resampled. An atlas without profiles is one 0 (a storage
//! binding cannot be empty).

use std::sync::Arc;

use crate::prepare::Prepared;
use crate::prepare::ies::PhotometricType;
use crate::prepare::ies::{HFold, Profile, VFold};

/// Floats in a profile header.
pub const HEADER_LEN: usize = 8;
/// Largest atlas length whose offsets and counts are exact in f32.
pub const MAX_LEN: usize = 1 << 24;
/// Written-out steps of the WGSL binary search (no loop: lavapipe stops an invocation's loops
/// after 65,535 iterations in total, and irradiance looks a profile up thousands of times):
/// enough for any grid of up to 2^16 + 1 angles, which the packer enforces.
pub const SEARCH_STEPS: u32 = 16;
/// The longest angle grid the shader's search covers (prepare refuses longer ones for both
/// paths, naming the light and the file).
pub const MAX_ANGLES: usize = crate::prepare::ies::MAX_ANGLES;
const _: () = assert!(MAX_ANGLES == (1 << SEARCH_STEPS) + 1);

/// Packed profiles: `data` is the `ies_atlas` buffer, `bases[k]` the header of profile k.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    pub data: Vec<f32>,
    pub bases: Vec<u32>,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AtlasError {
    #[error("the IES atlas would hold {0} floats; offsets are exact in f32 only below 2^24")]
    TooLarge(usize),
    #[error("profile {profile}: candela value {value} does not fit in an f32")]
    NotF32 { profile: usize, value: f64 },
    #[error(
        "profile {profile}: {count} angles on one axis, more than the {MAX_ANGLES} the GPU lookup covers"
    )]
    TooManyAngles { profile: usize, count: usize },
}

/// Packs `profiles` in order (layout in the module documentation).
pub fn pack_atlas(profiles: &[&Profile]) -> Result<Atlas, AtlasError> {
    let len: usize = profiles
        .iter()
        .map(|p| HEADER_LEN + p.h.len() + p.v.len() + p.candela.len())
        .sum();
    if len >= MAX_LEN {
        return Err(AtlasError::TooLarge(len));
    }
    let mut data = Vec::with_capacity(len.max(1));
    let mut bases = Vec::with_capacity(profiles.len());
    for (k, p) in profiles.iter().enumerate() {
        if let Some(count) = [p.h.len(), p.v.len()].into_iter().find(|&n| n > MAX_ANGLES) {
            return Err(AtlasError::TooManyAngles { profile: k, count });
        }
        let base = data.len();
        let h_off = base + HEADER_LEN;
        let v_off = h_off + p.h.len();
        let c_off = v_off + p.v.len();
        let header = [
            p.kind.code() as usize,
            p.h_fold.code() as usize,
            p.v_fold.code() as usize,
            p.h.len(),
            p.v.len(),
            h_off,
            v_off,
            c_off,
        ];
        data.extend(header.iter().map(|&x| x as f32));
        data.extend(p.h.iter().map(|&x| x as f32));
        data.extend(p.v.iter().map(|&x| x as f32));
        for &c in &p.candela {
            let f = c as f32;
            if !f.is_finite() {
                return Err(AtlasError::NotF32 {
                    profile: k,
                    value: c,
                });
            }
            data.push(f);
        }
        bases.push(base as u32);
    }
    if data.is_empty() {
        data.push(0.0);
    }
    Ok(Atlas { data, bases })
}

/// The `u32` constants `ies.wgsl` uses, by name, for the generated WGSL prelude (DESIGN.md §1:
/// shared constants are generated into the WGSL, never retyped).
pub fn wgsl_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("IES_TYPE_C", PhotometricType::C.code()),
        ("IES_TYPE_B", PhotometricType::B.code()),
        ("IES_TYPE_A", PhotometricType::A.code()),
        ("IES_FOLD_AS_GIVEN", HFold::AsGiven.code()),
        ("IES_FOLD_MIRROR", HFold::Mirror.code()),
        ("IES_FOLD_CONSTANT", HFold::Constant.code()),
        ("IES_FOLD_QUADRANT", HFold::Quadrant.code()),
        ("IES_FOLD_HALF", HFold::Half.code()),
        ("IES_FOLD_HALF_C90", HFold::HalfC90.code()),
        ("IES_FOLD_FULL", HFold::Full.code()),
        ("IES_V_MIRROR", VFold::Mirror.code()),
        ("IES_SEARCH_STEPS", SEARCH_STEPS),
    ]
}

/// The atlas of the distinct profiles of `lights` (shared `Arc`s are packed once) and, per
/// light, the base of its profile.
pub fn scene_atlas(lights: &[Prepared]) -> Result<(Atlas, Vec<Option<u32>>), AtlasError> {
    let mut distinct: Vec<&Arc<Profile>> = Vec::new();
    let index: Vec<Option<usize>> = lights
        .iter()
        .map(|p| {
            p.ies.as_ref().map(
                |i| match distinct.iter().position(|d| Arc::ptr_eq(d, &i.profile)) {
                    Some(k) => k,
                    None => {
                        distinct.push(&i.profile);
                        distinct.len() - 1
                    }
                },
            )
        })
        .collect();
    let profiles: Vec<&Profile> = distinct.iter().map(|p| p.as_ref()).collect();
    let atlas = pack_atlas(&profiles)?;
    let bases = index.iter().map(|k| k.map(|k| atlas.bases[k])).collect();
    Ok((atlas, bases))
}
