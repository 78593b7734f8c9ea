//! The scene-level choice of a light (DESIGN.md §9 S1 "Scene level"): the selection weights
//! at a receiver (power, a receiver-aware bound, or the exact irradiance), the tables a scene
//! keeps for them, the choice by the weights' CDF, and the mixture density `Σ P(l | x) ·
//! pdf_l(ω)`.

use glam::DVec3;

use super::cone::Cone;
use super::{LightAt, luminance};
use crate::cpu::irradiance::{Adaptive, irradiance_with};
use crate::model::LightType;
use crate::prepare::Prepared;
use crate::prepare::env_table::{EnvTable, ReceiverTiles};

/// How `sample_scene` chooses a light at a receiver (DESIGN.md §9 S1 "Scene level").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Selection {
    /// By power (luminous flux; for a dome or distant light, its irradiance on a receiver
    /// facing it), the same at every receiver.
    Power,
    /// By an estimate of what the light delivers at (x, n): luminance × solid angle (from a
    /// bounding sphere) × the largest cosine the receiver can see it at, as light trees
    /// bound a cluster (Conty Estevez & Kulla, "Importance Sampling of Many Lights with
    /// Adaptive Tree Splitting", HPG 2018, §4.1).
    #[default]
    Bound,
    /// By luxeval's exact irradiance of each light at (x, n) (needs normals).
    Exact,
}

/// A weight that is positive whenever any channel is: the luminance, or where that is 0 (a
/// colour with luminance 0 but a positive channel cannot occur for non-negative colours, but a
/// tint can cancel), the largest channel.
pub(crate) fn weight_of(c: DVec3) -> f64 {
    let y = luminance(c);
    if y > 0.0 { y } else { c.max_element().max(0.0) }
}

/// The per-light data of a scene's sampler: the dome tables and, for `Selection::Exact`, the
/// lights with `diffuse` 1 (the estimator targets irradiance / diffuse, S1).
pub struct SceneTables {
    pub env: std::sync::Arc<Vec<Option<EnvTable>>>,
    power: Vec<f64>,
    undiffused: Vec<Prepared>,
    /// Textured domes' receiver tiles by (light, normal's bits): a falloff map's receivers share
    /// one normal, and a tile table costs a pass over the tiles. Holds at most
    /// [`TILE_CACHE`] entries; past that, tables are built per receiver.
    tiles: std::sync::Mutex<TileCache>,
}

/// Receiver tile tables by (light, the normal's bits).
type TileCache = std::collections::HashMap<(usize, [u64; 3]), std::sync::Arc<ReceiverTiles>>;

/// The most receiver tile tables a scene keeps.
const TILE_CACHE: usize = 4096;

/// Each light's environment table (textured domes; `None` for the others).
pub fn env_tables(lights: &[Prepared]) -> Vec<Option<EnvTable>> {
    lights
        .iter()
        .map(|p| p.dome_texture().and_then(EnvTable::new))
        .collect()
}

impl SceneTables {
    /// Each light's power weight (`Selection::Power` tables only; empty for the others).
    pub fn power_weights(&self) -> &[f64] {
        &self.power
    }

    /// The tables for `selection`, sharing `env` (built once per scene by [`env_tables`]).
    pub fn new(
        lights: &[Prepared],
        selection: Selection,
        env: std::sync::Arc<Vec<Option<EnvTable>>>,
    ) -> SceneTables {
        let power = match selection {
            Selection::Power => lights.iter().map(power_weight).collect(),
            _ => Vec::new(),
        };
        let undiffused = match selection {
            Selection::Exact => lights
                .iter()
                .map(|p| {
                    let mut q = p.clone();
                    q.light.inputs.diffuse = 1.0;
                    q
                })
                .collect(),
            _ => Vec::new(),
        };
        SceneTables {
            env,
            power,
            undiffused,
            tiles: Default::default(),
        }
    }

    /// Light k's strategy at (x, n), a textured dome's tiles taken from the cache.
    pub fn light_at<'s>(
        &'s self,
        k: usize,
        p: &Prepared,
        x: DVec3,
        n: Option<DVec3>,
    ) -> LightAt<'s> {
        let lookup = |t: &EnvTable, n: DVec3| {
            let key = (k, n.to_array().map(f64::to_bits));
            if let Some(hit) = self.tiles.lock().ok().and_then(|m| m.get(&key).cloned()) {
                return Some(hit);
            }
            let built = std::sync::Arc::new(t.receiver_tiles(n)?);
            if let Ok(mut m) = self.tiles.lock()
                && m.len() < TILE_CACHE
            {
                m.insert(key, built.clone());
            }
            Some(built)
        };
        LightAt::with_tiles(p, self.env[k].as_ref(), x, n, &lookup)
    }
}

/// Power as a selection weight (constant over receivers).
pub(crate) fn power_weight(p: &Prepared) -> f64 {
    let facing = match p.light.kind {
        // A uniform dome's irradiance on a receiver facing anywhere: π L.
        LightType::Dome => Some(std::f64::consts::PI),
        // A distant cone facing the receiver: π sin²θ (closed.rs `cap_irradiance`); delta: 1.
        LightType::Distant { .. } => {
            let t = p.distant_half_angle();
            Some(if t == 0.0 {
                1.0
            } else {
                std::f64::consts::PI * t.sin().powi(2)
            })
        }
        // The unoccluded flux `π L A` per emitting side, shaping left out: an upper bound of
        // a mesh light's flux (its self-occlusion has no closed form, cpu::power), and any
        // positive weight keeps the choice unbiased.
        LightType::Mesh {
            ref geometry,
            double_sided,
            ..
        } => {
            let sides = if double_sided { 2.0 } else { 1.0 };
            Some(std::f64::consts::PI * geometry.area * sides)
        }
        _ => None,
    };
    match facing {
        Some(k) => weight_of(p.base * k),
        None => crate::cpu::power::flux(p).map_or(0.0, weight_of),
    }
}

/// The unnormalised selection weights of every light at (x, n).
pub fn selection_weights(
    lights: &[Prepared],
    tables: &SceneTables,
    x: DVec3,
    n: Option<DVec3>,
    selection: Selection,
    rule: &Adaptive,
    out: &mut Vec<f64>,
) {
    out.clear();
    for (k, p) in lights.iter().enumerate() {
        let w = match selection {
            Selection::Power => tables.power[k],
            Selection::Exact => match n {
                Some(n) => weight_of(irradiance_with(&tables.undiffused[k], x, n, rule)),
                None => 0.0,
            },
            Selection::Bound => bound_weight(p, x, n),
        };
        out.push(if w.is_finite() { w } else { 0.0 });
    }
}

/// [`Selection::Bound`]'s estimate: `Y(base) · Ω̃ · cos_bound · spot_bound`, with Ω̃ the solid
/// angle of the bounding sphere (2π from inside it), cos_bound the cosine of the angle between n
/// and the nearest direction of that sphere (1 without a normal) and spot_bound the largest cone
/// factor toward x ([`spot_bound`]). Positive wherever the light can deliver light to (x, n);
/// zero behind a one-sided shape, below the receiver's horizon or outside a spot's cone.
fn bound_weight(p: &Prepared, x: DVec3, n: Option<DVec3>) -> f64 {
    if p.profile.dark {
        return 0.0;
    }
    let y = weight_of(p.base);
    // The bound's cone: its axis toward the light, half-angle α with (cos α, sin α), and Ω̃.
    let (axis, alpha, (cos_a, sin_a), omega) = match p.light.kind {
        LightType::Dome => return y * std::f64::consts::PI,
        LightType::Distant { .. } => {
            let t = p.distant_half_angle();
            (
                -p.axis,
                t,
                (t.cos(), t.sin()),
                if t == 0.0 {
                    1.0
                } else {
                    Cone::with_angle(-p.axis, t).solid_angle()
                },
            )
        }
        _ => {
            let xl = p.to_local * (x - p.origin);
            let one_sided = matches!(
                p.light.kind,
                LightType::Rect { .. } | LightType::Disk { .. }
            );
            if one_sided && !(xl.z < 0.0) {
                return 0.0;
            }
            let w = p.origin - x;
            let d = w.length();
            let r = p.bound_radius();
            if !(d > r) {
                (
                    w.normalize_or(DVec3::Y),
                    std::f64::consts::PI,
                    (-1.0, 0.0),
                    2.0 * std::f64::consts::PI,
                )
            } else {
                let c = Cone::subtended(w / d, r, d);
                let s = r / d;
                (
                    (w / d),
                    s.asin(),
                    ((1.0 - s * s).max(0.0).sqrt(), s),
                    c.solid_angle().max(f64::MIN_POSITIVE),
                )
            }
        }
    };
    // cos(max(θ − α, 0)) for θ the angle between n and the axis: 1 where θ ≤ α (cos θ ≥
    // cos α), else cos θ cos α + sin θ sin α, with sin θ = |n × axis| — no acos, whose f32
    // twin loses ~1e-4 rad near the axis and whose error grows without bound relative to a
    // cosine near 0.
    let cos = match n {
        Some(n) => {
            let (c, s) = (n.dot(axis), n.cross(axis).length());
            if c >= cos_a {
                1.0
            } else {
                (c * cos_a + s * sin_a).max(0.0)
            }
        }
        None => 1.0,
    };
    // A receiver grazing the bound still gets a positive weight when the sphere straddles its
    // horizon (theta − alpha < π/2 strictly).
    y * omega * cos * spot_bound(p, -axis, alpha)
}

/// The largest cone factor of ShapingAPI (DESIGN.md §2 "Shaping") over the emission directions
/// within `alpha` of `e` — the directions from a finite light's bounding sphere toward the
/// receiver — so that a spot weighs 0 exactly where none of its light reaches the receiver
/// (the factor falls with the angle off the axis: its maximum is at the smallest angle). 1 for
/// an unshaped light, a dome or a distant light.
fn spot_bound(p: &Prepared, e: DVec3, alpha: f64) -> f64 {
    match (&p.shaping, &p.light.kind) {
        (
            Some(s),
            LightType::Sphere { .. }
            | LightType::Rect { .. }
            | LightType::Disk { .. }
            | LightType::Cylinder { .. }
            | LightType::Mesh { .. },
        ) => {
            let theta = (crate::cpu::shaping::off_axis_angle(p.axis, e) - alpha).max(0.0);
            crate::cpu::shaping::cone_factor(theta, s.cone, s.start)
        }
        _ => 1.0,
    }
}

/// The light chosen for uniform `u` by the normalised weights' CDF, with its probability;
/// never a light of weight 0.
pub fn choose(weights: &[f64], total: f64, u: f64) -> Option<(usize, f64)> {
    if !(total > 0.0) {
        return None;
    }
    let target = u * total;
    let mut acc = 0.0;
    let mut last = None;
    for (k, &w) in weights.iter().enumerate() {
        if w > 0.0 {
            acc += w;
            last = Some(k);
            if target < acc {
                return Some((k, w / total));
            }
        }
    }
    last.map(|k| (k, weights[k] / total))
}

/// `P(l | x) · pdf_l(ω)` summed over lights (DESIGN.md §9 S1); with `per_light`, one value per
/// light written to `rows`.
pub fn scene_pdf(
    lights: &[Prepared],
    tables: &SceneTables,
    weights: &[f64],
    x: DVec3,
    n: Option<DVec3>,
    w: DVec3,
    rows: &mut [f64],
) -> f64 {
    let total: f64 = weights.iter().sum();
    let mut sum = 0.0;
    for (k, p) in lights.iter().enumerate() {
        let v = if total > 0.0 && weights[k] > 0.0 {
            let at = tables.light_at(k, p, x, n);
            weights[k] / total * at.pdf(p, x, w)
        } else {
            0.0
        };
        if let Some(r) = rows.get_mut(k) {
            *r = v;
        }
        sum += v;
    }
    sum
}
