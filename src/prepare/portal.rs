//! Portals as the evaluation uses them (DESIGN.md §8 P2): the portal mode, and for a dome in
//! mask mode each of its portals' world rectangle, emitting-side normal and multiplier, computed
//! once in f64. Hint mode prepares nothing: its values are bitwise those of a dome with no
//! portal, since nothing downstream can see a portal that was never prepared.

use glam::{DMat3, DVec2, DVec3};

use super::TemperatureMode;
use super::blackbody::temperature_rgb;
use crate::error::{LuxError, Result};
// The mode is plain data of the model, so that `usd` (above `prepare`, DESIGN.md §1) can say
// how a stage's portals are evaluated.
pub use crate::model::PortalMode;
use crate::model::{Light, LightType, Portal};

/// A portal's multiplier (DESIGN.md §8 P2): its own LightAPI product `intensity · 2^exposure ·
/// color ⊙ temperature(T)`, formed as a light's base radiance is (normalize does not apply, P1).
pub fn multiplier(p: &Portal, mode: TemperatureMode) -> DVec3 {
    let tint = if p.enable_color_temperature {
        temperature_rgb(p.color_temperature, mode)
    } else {
        DVec3::ONE
    };
    p.intensity * 2f64.powf(p.exposure) * p.color * tint
}

/// One portal of a masked dome, in world space.
#[derive(Clone, Debug)]
pub struct PreparedPortal {
    /// World-space centre.
    pub origin: DVec3,
    /// World → local linear map (the inverse of the portal's world 3×3).
    pub to_local: DMat3,
    /// Half width and half height in local units.
    pub half: DVec2,
    /// Unit world normal of the portal's local +Z side (the inverse transpose applied to +Z, as
    /// a rect light's normal is formed, DESIGN.md §2 "Frames"): light passes toward −Z, so a
    /// ray counts where it crosses moving along `+normal` (P2).
    pub normal: DVec3,
    /// The world corners, local (−,−), (+,−), (+,+), (−,+): a convex planar quadrilateral
    /// (a parallelogram under any linear map).
    pub corners: [DVec3; 4],
    /// [`multiplier`] in the scene's temperature mode.
    pub multiplier: DVec3,
}

/// The portals a dome is masked by in `mode`: `None` (not masked) in hint mode, for other
/// lights, and for a dome naming no visible portal (P1: unchanged in either mode). A portal of zero area or whose world transform is singular passes no
/// light and is left out (its side, hence the direction light passes it, is undefined); an
/// invalid portal input is refused naming the portal and the attribute.
pub fn prepare_portals(
    light: &Light,
    mode: PortalMode,
    temperature: TemperatureMode,
) -> Result<Option<Vec<PreparedPortal>>> {
    if mode == PortalMode::Hint || light.kind != LightType::Dome || light.portals.is_empty() {
        return Ok(None);
    }
    let mut out = Vec::with_capacity(light.portals.len());
    for p in &light.portals {
        p.validate()?;
        let linear = DMat3::from_mat4(p.world);
        let det = linear.determinant();
        let half = DVec2::new(p.width / 2.0, p.height / 2.0);
        let multiplier = multiplier(p, temperature);
        if !multiplier.is_finite() {
            return Err(LuxError::attr(
                &p.path,
                "inputs:intensity",
                p.intensity,
                format!("intensity · 2^exposure · color overflows ({multiplier})"),
            ));
        }
        // Written so that a NaN also leaves the portal out.
        let passes = det.abs() > 0.0 && half.x > 0.0 && half.y > 0.0;
        if !passes {
            continue;
        }
        let to_local = linear.inverse();
        let Some(normal) = (to_local.transpose() * DVec3::Z).try_normalize() else {
            continue;
        };
        let origin = p.world.w_axis.truncate();
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(a, b)| origin + linear * DVec3::new(a * half.x, b * half.y, 0.0));
        out.push(PreparedPortal {
            origin,
            to_local,
            half,
            normal,
            corners,
            multiplier,
        });
    }
    Ok(Some(out))
}

/// How far (relative to its distance from the other portal's centre) a corner may lie off
/// another portal's plane and still count as in it in [`crossing_orders`]: f64
/// rounding of coplanar portals' corners, ~1e-16 of it. A corner that far across lets only
/// rays within ~1e-9 (relative) of both portals cross both.
const PLANE_SLACK: f64 = 1e-9;

/// Whether no ray can pass through two of `portals` toward their +Z: no pair
/// may be crossed in some order ([`crossing_orders`]; then [`overlaps`] lists nothing, and a masked dome's irradiance
/// is the sum over the portals of each one's own).
#[cfg(test)]
pub fn cannot_hide_one_another(portals: &[PreparedPortal]) -> bool {
    portals.iter().enumerate().all(|(i, a)| {
        portals
            .iter()
            .skip(i + 1)
            .all(|b| !one_ray_may_cross_both(a, b))
    })
}

/// Whether some ray passes through both `a` and `b` toward their +Z: either order of
/// [`crossing_orders`].
#[cfg(test)]
pub(crate) fn one_ray_may_cross_both(a: &PreparedPortal, b: &PreparedPortal) -> bool {
    let (a_first, b_first) = crossing_orders(a, b);
    a_first || b_first
}

/// In which orders rays may cross `a`, then `b` (`.0`), and `b`, then `a` (`.1`), toward their
/// +Z (P2's crossings; in a set of rays of positive measure), `a` being the earlier in the
/// `portals` relationship; either is an edge of the graph whose cliques are [`overlaps`]. A
/// ray crosses A toward +Z at t_A and then B at t_B > t_A exactly when some point of A lies
/// strictly on B's −Z side and some point of B strictly on A's +Z side:
/// - only if: the ray moves toward +Z_B, so before t_B (at A's point) it is on B's −Z side, and
///   toward +Z_A, so after t_A (at B's point) on A's +Z side;
/// - if: through such points a of A and b of B, the ray from just before a along b − a crosses
///   A toward +Z (b is above A's plane) and then B toward +Z (a is below B's), as do the rays
///   near it (the conditions are open).
///
/// For convex portals "some point" is "some corner". Rays meeting both at once pass through
/// the line where their planes meet (measure zero) unless the planes are one: facing opposite
/// ways no ray moves toward both +Z, facing the same way it passes through both where they
/// overlap (that overlap counts once, for the earlier portal: it is the nearer there, `.0`).
/// So this is exact: no two of a convex room's windows and skylights, of several panes in one
/// wall not overlapping, or of windows facing each other across a courtyard are crossable by
/// one ray; a window and a pane in front of it are.
pub(crate) fn crossing_orders(a: &PreparedPortal, b: &PreparedPortal) -> (bool, bool) {
    // Whether some corner of `b` lies beyond `a`'s plane on the side `sign` (+1: +Z).
    let beyond = |a: &PreparedPortal, b: &PreparedPortal, sign: f64| {
        b.corners.iter().any(|c| {
            let d = *c - a.origin;
            sign * a.normal.dot(d) > PLANE_SLACK * d.length()
        })
    };
    let coplanar = !beyond(a, b, 1.0) && !beyond(a, b, -1.0);
    let a_then_b = beyond(b, a, -1.0) && beyond(a, b, 1.0);
    let b_then_a = beyond(a, b, -1.0) && beyond(b, a, 1.0);
    let overlapping = coplanar && a.normal.dot(b.normal) > 0.0 && overlap(a, b);
    (a_then_b || overlapping, b_then_a)
}

/// The most portals one ray may cross (toward their +Z) for the device to sum a masked dome's
/// irradiance ([`overlaps`]): every set of that many pairwise-crossable portals is one
/// inclusion–exclusion term, clipped by the others' edges in the kernel (4 portals: a polygon
/// of at most 16 vertices).
pub const MOST_PORTALS_ONE_RAY_CROSSES: usize = 4;

/// The most loop iterations the kernel may spend on one dome's overlaps ([`overlaps`]) for a
/// receiver that sees every portal: about three quarters of lavapipe's 65,535 an invocation,
/// the rest left to the portals themselves (~34 each) and the scene's other lights. Past it a receiver
/// would be cut short and recomputed on the host (shaders/irradiance/portals.wgsl), so the dome
/// keeps the host's irradiance instead.
pub const OVERLAP_ITERATIONS: usize = 49_000;

/// The kernel's loop iterations for one overlap of `k` portals at most
/// (shaders/irradiance/portals.wgsl): the term loop's own, the members' side tests (and the
/// end of the list), the first parallelogram's 4 corners, `4(k − 1)` clips of up to `4k`
/// vertices, then per piece the piece loop's own, the above-horizon test of up to `v`
/// vertices and a fan of up to `v − 2` triangles of at most 12 each (mesh/lambert.wgsl's
/// count). One piece of `v = 4k` vertices: 121 for two, 238 for three, 387 for four. A split
/// overlap ([`Overlap::split`]) has `k` pieces, each also looping over the members with up to
/// `k − 1` clips, so of up to `v = 5k − 1` vertices (a clip adds one at most): 250 for two,
/// 675 for three, 1,342 for four.
pub const fn overlap_iterations(k: usize, split: bool) -> usize {
    let polygon = 1 + (k + 1) + 4 + 4 * (k - 1) * 4 * k;
    if split {
        let v = 5 * k - 1;
        polygon + k * (piece_iterations(v) + k + (k - 1) * v)
    } else {
        polygon + piece_iterations(4 * k)
    }
}

/// A piece's loop iterations in [`overlap_iterations`]: the piece loop's own, the above-horizon
/// test of `v` vertices and a fan of `v − 2` triangles of at most 12 each.
const fn piece_iterations(v: usize) -> usize {
    1 + v + (v - 2) * 12
}

/// [`overlaps`]' reason past [`OVERLAP_ITERATIONS`].
const TOO_MANY_OVERLAPS: &str =
    "it is masked by portals that overlap in more ways than the irradiance kernel sums";

/// One inclusion–exclusion term beyond the portals' own (`cpu::irradiance::portals`, which
/// carries the proof): a set of two or more portals that one ray may cross together, and whose
/// multiplier the term takes on each ray (that of the set's farthest member along it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Overlap {
    /// Indices into the dome's portals. Unsplit: first the member whose multiplier the term
    /// takes on every ray, then the others ascending. Split: ascending.
    pub members: Vec<u32>,
    /// `None` where one member's multiplier is the farthest's on every ray through the set.
    /// Otherwise (portals of different multipliers that rays cross in either order) the term is
    /// summed over pieces, one per member, each the directions along which that member is the
    /// farthest, clipped from the set's polygon by the plane through x where it and another
    /// member are crossed at once ([`farther_plane`](crate::cpu::irradiance::portals)); bit
    /// `4i + j` says `members[i]` lies before `members[j]` on every ray through both (no plane
    /// between them: `members[i]`'s piece is empty, and `members[j]`'s needs no clip for `i`).
    pub split: Option<u16>,
}

impl Overlap {
    /// An unsplit set, its first member's multiplier the term's (tests).
    #[cfg(test)]
    pub fn whole(members: &[u32]) -> Self {
        Self {
            members: members.to_vec(),
            split: None,
        }
    }
}

/// The sets of two or more of `portals` that one ray may cross together (every pair of the set
/// crossable in some order, [`crossing_orders`]: the cliques of that graph), in lexicographic
/// order of their members, as [`Overlap`]s. They are the terms beyond the portals' own of the
/// inclusion–exclusion sum the device takes a masked dome's irradiance by
/// (`cpu::irradiance::portals`, which carries the proof). Empty exactly when no pair is
/// crossable.
///
/// P2 gives each ray the nearest portal's multiplier, and a set's term the farthest member's.
/// Where every member of another multiplier lies before one member `l` on every ray through
/// them (the farthest on any ray through them all: a set no ray passes through has none, and
/// its term is 0 whichever is named), the set names `l` first and is whole; otherwise (a pair
/// of different multipliers crossed in either order, e.g. a pane through a window at an
/// angle) it is split by the planes where its members are crossed at once. `Err` with the
/// reason the device cannot sum them: more than [`MOST_PORTALS_ONE_RAY_CROSSES`] pairwise
/// crossable portals, or sets costing the kernel more than [`OVERLAP_ITERATIONS`]
/// ([`overlap_iterations`]).
pub fn overlaps(portals: &[PreparedPortal]) -> std::result::Result<Vec<Overlap>, &'static str> {
    // Neighbours above each portal in the graph "one ray may cross both", each with the
    // orders rays cross the pair in (`crossing_orders`).
    let mut above: Vec<Vec<(usize, (bool, bool))>> = vec![Vec::new(); portals.len()];
    let mut cost = 0;
    for (i, a) in portals.iter().enumerate() {
        for (j, b) in portals.iter().enumerate().skip(i + 1) {
            let orders = crossing_orders(a, b);
            if !(orders.0 || orders.1) {
                continue;
            }
            above[i].push((j, orders));
            // Every crossable pair is a set: past the budget already (and no quadratic list).
            cost += overlap_iterations(2, false);
            if cost > OVERLAP_ITERATIONS {
                return Err(TOO_MANY_OVERLAPS);
            }
        }
    }
    // Whether rays through both cross `i` before `j` and never after (i, j crossable).
    let only_before = |i: usize, j: usize| {
        let (lo, hi) = (i.min(j), i.max(j));
        let (_, (lo_first, hi_first)) = above[lo][above[lo].partition_point(|e| e.0 < hi)];
        if i == lo {
            lo_first && !hi_first
        } else {
            hi_first && !lo_first
        }
    };
    let neighbours = |i: usize| -> Vec<usize> { above[i].iter().map(|e| e.0).collect() };
    // Every clique, grown from its lowest member by common neighbours above its highest.
    let mut sets = Vec::new();
    let mut stack: Vec<(Vec<usize>, Vec<usize>)> = (0..portals.len())
        .rev()
        .map(|i| (vec![i], neighbours(i)))
        .collect();
    while let Some((set, common)) = stack.pop() {
        if set.len() > 1 {
            let last = set.iter().copied().find(|&l| {
                set.iter().all(|&z| {
                    z == l || portals[z].multiplier == portals[l].multiplier || only_before(z, l)
                })
            });
            // The pairs' whole cost is counted already.
            cost += overlap_iterations(set.len(), last.is_none())
                - if set.len() == 2 {
                    overlap_iterations(2, false)
                } else {
                    0
                };
            if cost > OVERLAP_ITERATIONS {
                return Err(TOO_MANY_OVERLAPS);
            }
            sets.push(match last {
                Some(last) => Overlap {
                    members: std::iter::once(last)
                        .chain(set.iter().copied().filter(|&k| k != last))
                        .map(|k| k as u32)
                        .collect(),
                    split: None,
                },
                None => {
                    let mut before = 0u16;
                    for (a, &i) in set.iter().enumerate() {
                        for (b, &j) in set.iter().enumerate() {
                            if i != j && only_before(i, j) {
                                before |= 1 << (4 * a + b);
                            }
                        }
                    }
                    Overlap {
                        members: set.iter().map(|&k| k as u32).collect(),
                        split: Some(before),
                    }
                }
            });
        }
        if set.len() == MOST_PORTALS_ONE_RAY_CROSSES && !common.is_empty() {
            return Err(
                "it is masked by more portals than the irradiance kernel clips that \
                 one ray may cross",
            );
        }
        for &k in common.iter().rev() {
            let next: Vec<usize> = common
                .iter()
                .copied()
                .filter(|c| *c > k && above[k].binary_search_by_key(c, |e| e.0).is_ok())
                .collect();
            let mut grown = set.clone();
            grown.push(k);
            stack.push((grown, next));
        }
    }
    Ok(sets)
}

/// Whether two portals in one plane overlap (in more than an edge): no separating line along
/// either parallelogram's edges (the separating axis theorem for convex polygons).
fn overlap(a: &PreparedPortal, b: &PreparedPortal) -> bool {
    let edges = |q: &PreparedPortal| [q.corners[1] - q.corners[0], q.corners[3] - q.corners[0]];
    edges(a).into_iter().chain(edges(b)).all(|e| {
        let axis = a.normal.cross(e);
        let range = |q: &PreparedPortal| {
            q.corners
                .iter()
                .map(|c| c.dot(axis))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                })
        };
        let ((alo, ahi), (blo, bhi)) = (range(a), range(b));
        let slack = PLANE_SLACK * ((ahi - alo) + (bhi - blo));
        ahi > blo + slack && bhi > alo + slack
    })
}
