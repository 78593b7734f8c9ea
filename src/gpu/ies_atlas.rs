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
//!
//! After the profiles, one block of kinks per distinct (profile, angleScale) whose irradiance
//! the device integrates (`prepare::ies_kinks::KinkFamilies`, streamed by
//! shaders/irradiance/line.wgsl), at `kb` (the record's `ies.w`):
//! ```text
//! kb + 0      Kc, the number of cones      kb + 1..3   their common axis (light frame)
//! kb + 4      Kp, planes of the pencil     kb + 5..7   the pencil's axis P
//! kb + 8..10  u ⊥ P (azimuths from u towards P × u)
//! kb + 11     Ke ≤ 2, other planes         kb + 12..17 their unit normals
//! kb + 18     the Kc cone cosines, ascending; then the Kp plane azimuths δ ∈ [0, π),
//!             ascending; then the Kp normals' (u, v) coordinates, in pairs
//! ```

use std::sync::Arc;

use crate::prepare::Prepared;
use crate::prepare::ies::PhotometricType;
use crate::prepare::ies::{HFold, Profile, VFold};
use crate::prepare::ies_kinks::KinkFamilies;

/// Floats in a profile header.
pub const HEADER_LEN: usize = 8;
/// Floats in a kinks block's header (the lists follow).
pub const KINKS_HEADER_LEN: usize = 18;
const _: () = assert!(KINKS_HEADER_LEN == 12 + 3 * crate::prepare::ies_kinks::MAX_EXTRA_PLANES);
/// Written-out steps of the kink lists' binary search (shaders/irradiance/line.wgsl,
/// `kink_count`): a list of n entries needs ⌈log₂(n + 1)⌉.
pub const KINK_SEARCH_STEPS: u32 = 18;
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
    #[error("a profile has {0} grid cones or planes, more than the GPU's kink search covers")]
    TooManyKinks(usize),
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
        ("IES_KINKS_HEADER", KINKS_HEADER_LEN as u32),
    ]
}

/// Appends the kinks block of `f` (layout in the module documentation) and returns its base.
fn pack_kinks(data: &mut Vec<f32>, f: &KinkFamilies) -> Result<u32, AtlasError> {
    let longest = f.cone_cos.len().max(f.planes.len());
    if longest >= (1 << KINK_SEARCH_STEPS) {
        return Err(AtlasError::TooManyKinks(longest));
    }
    let base = data.len();
    let v3 = |d: &mut Vec<f32>, v: glam::DVec3| d.extend([v.x as f32, v.y as f32, v.z as f32]);
    data.push(f.cone_cos.len() as f32);
    v3(data, f.cone_axis);
    data.push(f.planes.len() as f32);
    v3(data, f.pencil_axis);
    v3(data, f.pencil_u);
    data.push(f.extra.len() as f32);
    for k in 0..crate::prepare::ies_kinks::MAX_EXTRA_PLANES {
        v3(data, f.extra.get(k).copied().unwrap_or_default());
    }
    debug_assert_eq!(data.len() - base, KINKS_HEADER_LEN);
    data.extend(f.cone_cos.iter().map(|&c| c as f32));
    data.extend(f.planes.iter().map(|p| p.0 as f32));
    data.extend(f.planes.iter().flat_map(|p| [p.1 as f32, p.2 as f32]));
    Ok(base as u32)
}

/// Where one light's IES data starts in the scene's atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IesBases {
    /// The profile's header.
    pub profile: u32,
    /// Its kinks block, for a light whose irradiance the device integrates (else 0).
    pub kinks: u32,
}

/// The atlas of the distinct profiles of `lights` (shared `Arc`s are packed once), then the
/// kinks blocks of the distinct (profile, angleScale) pairs the device integrates, and per
/// light where its data start.
pub fn scene_atlas(lights: &[Prepared]) -> Result<(Atlas, Vec<Option<IesBases>>), AtlasError> {
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
    let mut atlas = pack_atlas(&profiles)?;
    let mut blocks: Vec<(usize, u64, u32)> = Vec::new();
    let mut bases = Vec::with_capacity(lights.len());
    for (p, k) in lights.iter().zip(&index) {
        let (Some(k), Some(ies)) = (*k, &p.ies) else {
            bases.push(None);
            continue;
        };
        let mut kinks = 0;
        if !p.irradiance_on_host()
            && let Some(f) = ies.device_families()
        {
            let key = (k, ies.angle_scale.to_bits());
            kinks = match blocks.iter().find(|b| (b.0, b.1) == key) {
                Some(b) => b.2,
                None => {
                    let kb = pack_kinks(&mut atlas.data, &f)?;
                    blocks.push((key.0, key.1, kb));
                    kb
                }
            };
        }
        bases.push(Some(IesBases {
            profile: atlas.bases[k],
            kinks,
        }));
    }
    if atlas.data.len() >= MAX_LEN {
        return Err(AtlasError::TooLarge(atlas.data.len()));
    }
    Ok((atlas, bases))
}
