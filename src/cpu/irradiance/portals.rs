//! The irradiance of an untextured dome masked by portals that cannot hide one another
//! (DESIGN.md §8 P2 mask mode; [`cannot_hide_one_another`]): twin of
//! `shaders/irradiance/portals.wgsl`, the device's form of [`crate::cpu::portal::irradiance`]
//! for such domes.
//!
//! Why the sum is exact: the dome's radiance is `base` along every direction, and a ray from x
//! passes through at most one portal toward its +Z (up to a set of measure zero;
//! [`cannot_hide_one_another`] proves it), so the directions x receives light along are the
//! disjoint union of the portals it is on the −Z side of (every ray from there through the
//! portal crosses it toward +Z), each carrying that portal's multiplier. The irradiance of a
//! uniform convex polygon clipped at the receiver's horizon is Lambert's formula
//! ([`polygon_irradiance`]: Lambert 1760; Arvo 1995). `crate::cpu::portal::irradiance`, which
//! cuts the portals into their visible pieces for any set, is this sum's independent check
//! (`tests::the_sum_is_the_visible_pieces_where_portals_cannot_hide_one_another`).
//!
//! [`cannot_hide_one_another`]: crate::prepare::portal::cannot_hide_one_another

use glam::DVec3;

use super::closed::polygon_irradiance;
use crate::prepare::PreparedPortal;

/// `Σ multiplier · Lambert(portal clipped at n·ω ≥ 0)` over the portals whose −Z side x is on
/// (unit-radiance dome, before `base` and `diffuse`).
pub fn portals_lambert(portals: &[PreparedPortal], x: DVec3, n: DVec3) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for q in portals {
        if !(q.normal.dot(x - q.origin) < 0.0) {
            continue;
        }
        let v = q.corners.map(|c| c - x);
        if v.iter().all(|v| !(n.dot(*v) > 0.0)) {
            continue;
        }
        sum += q.multiplier * polygon_irradiance(&v, n);
    }
    sum
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, DQuat, DVec3};

    use super::*;
    use crate::model::{Light, Portal};
    use crate::prepare::portal::cannot_hide_one_another;
    use crate::prepare::{PortalMode, Prepared, TemperatureMode};
    use crate::synthetic::Rng;

    fn masked(portals: Vec<Portal>) -> Prepared {
        let dome = portals.into_iter().fold(
            Light::dome()
                .with_intensity(1.5)
                .with_color(DVec3::new(1.0, 0.6, 0.3)),
            |l, q| l.with_portal(q),
        );
        let mut p = Prepared::new(&dome, TemperatureMode::Spec).unwrap();
        p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
            .unwrap();
        p
    }

    /// A window of random size and tint on the wall of a box room, facing out: the walls of
    /// the room [−a, a]³ with the window's centre on the wall and its +Z along the wall's
    /// outward normal.
    fn window(rng: &mut Rng, wall: usize, a: f64) -> Portal {
        let out = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ][wall];
        let rot = DQuat::from_rotation_arc(DVec3::Z, out)
            * DQuat::from_rotation_z(rng.range(0.0, std::f64::consts::TAU));
        let (t1, t2) = out.any_orthonormal_pair();
        let c = out * a + (t1 * rng.range(-0.3, 0.3) + t2 * rng.range(-0.3, 0.3)) * a;
        Portal::new(rng.range(0.2, 0.8) * a, rng.range(0.2, 0.8) * a)
            .with_transform(DMat4::from_rotation_translation(rot, c))
            .with_intensity(rng.range(0.5, 3.0))
            .with_color(DVec3::new(
                rng.range(0.2, 1.0),
                rng.range(0.2, 1.0),
                rng.range(0.2, 1.0),
            ))
    }

    /// How many of `portals` the ray x + tω passes through toward their +Z (edges inclusive,
    /// every one counted: what P2's nearest-first rule would have to choose between).
    fn crossed(portals: &[crate::prepare::PreparedPortal], x: DVec3, w: DVec3) -> usize {
        portals
            .iter()
            .filter(|q| {
                let (toward, side) = (q.normal.dot(w), q.normal.dot(x - q.origin));
                if !(toward > 0.0 && side < 0.0) {
                    return false;
                }
                let h = q.to_local * (x + (-side / toward) * w - q.origin);
                h.x.abs() <= q.half.x && h.y.abs() <= q.half.y
            })
            .count()
    }

    /// Uniform in the cube [−r, r]³.
    fn in_cube(rng: &mut Rng, r: f64) -> DVec3 {
        DVec3::new(rng.range(-r, r), rng.range(-r, r), rng.range(-r, r))
    }

    /// The most portals one of `rays` rays crosses toward their +Z ([`crossed`]): from points
    /// uniform in [−r, r]³, half in uniform directions, half aimed at a uniform point of a
    /// portal.
    fn most_crossed(
        rng: &mut Rng,
        portals: &[crate::prepare::PreparedPortal],
        r: f64,
        rays: usize,
    ) -> usize {
        (0..rays)
            .map(|_| {
                let x = in_cube(rng, r);
                let w = if rng.chance(0.5) {
                    rng.unit()
                } else {
                    let c = portals[rng.below(portals.len())].corners;
                    let (s, t) = (rng.f64(), rng.f64());
                    (c[0] + (c[1] - c[0]) * s + (c[3] - c[0]) * t - x).normalize()
                };
                crossed(portals, x, w)
            })
            .max()
            .unwrap_or(0)
    }

    /// Windows on the walls of a box room (several a wall, coplanar) cannot hide one another
    /// unless two on one wall overlap; a window and a pane outside it, in front, can. Checked
    /// by brute force: no ray crosses two portals of a set the predicate accepts toward their
    /// +Z (from inside the room and outside it), and a set it refuses for an overlap has such
    /// rays.
    #[test]
    fn a_rooms_windows_cannot_hide_one_another_and_stacked_panes_can() {
        let mut rng = Rng::new(0x9047A1);
        let (mut accepted, mut refused) = (0, 0);
        for case in 0..60 {
            let count = 1 + rng.below(6);
            let ps: Vec<Portal> = (0..count)
                .map(|_| {
                    let wall = rng.below(6);
                    window(&mut rng, wall, 1.0)
                })
                .collect();
            let p = masked(ps);
            let portals = p.portals.as_ref().unwrap();
            let apart = cannot_hide_one_another(portals);
            let most = most_crossed(&mut rng, portals, 1.5, 3000);
            if apart {
                accepted += 1;
                assert!(most <= 1, "case {case}: a ray crosses {most} portals");
            } else {
                // Refused: two windows on one wall overlap (a point inside both, on a grid).
                refused += 1;
                let inside = |q: &crate::prepare::PreparedPortal, y: DVec3| {
                    let h = q.to_local * (y - q.origin);
                    h.x.abs() < q.half.x && h.y.abs() < q.half.y && h.z.abs() < 1e-9
                };
                let overlap = portals.iter().any(|a| {
                    portals.iter().any(|b| {
                        !std::ptr::eq(a, b)
                            && (0..=60).any(|i| {
                                (0..=60).any(|j| {
                                    let c = a.corners;
                                    let y = c[0]
                                        + (c[1] - c[0]) * (i as f64 / 60.0)
                                        + (c[3] - c[0]) * (j as f64 / 60.0);
                                    inside(b, y)
                                })
                            })
                    })
                });
                assert!(overlap, "case {case}: refused, but no two portals overlap");
            }
        }
        assert!(
            accepted >= 30 && refused >= 5,
            "{accepted} accepted, {refused} refused"
        );
        // A pane 0.5 outside a window, parallel to it: a ray up through both.
        let pane =
            |z: f64| Portal::new(1.0, 1.0).with_transform(DMat4::from_translation(DVec3::Z * z));
        let stacked = masked(vec![pane(1.0), pane(1.5)]);
        assert!(!cannot_hide_one_another(stacked.portals.as_ref().unwrap()));
        // Two panes in one plane facing opposite ways, overlapping: a ray crosses one toward
        // its +Z only.
        let turned = Portal::new(1.0, 1.0).with_transform(DMat4::from_rotation_translation(
            DQuat::from_rotation_x(std::f64::consts::PI),
            DVec3::new(0.3, 0.0, 1.0),
        ));
        let facing = masked(vec![pane(1.0), turned]);
        assert!(cannot_hide_one_another(facing.portals.as_ref().unwrap()));
    }

    /// The predicate is exact on random pairs and triples of portals anywhere, of any
    /// orientation: where it refuses, a ray through two portals toward their +Z is built from
    /// the corners its proof names (a point of A beyond B's −Z side, one of B beyond A's +Z
    /// side, moved a little inside each) and crosses both; where it accepts, 4,000 rays from
    /// random points, half aimed at a portal, cross one at most. Windows facing each other
    /// across a courtyard are accepted.
    #[test]
    fn the_predicate_is_exact_on_random_portals() {
        use crate::prepare::PreparedPortal;
        let mut rng = Rng::new(0xC0_0A7);
        let (mut accepted, mut refused) = (0, 0);
        for case in 0..200 {
            let count = 2 + rng.below(2);
            let ps: Vec<Portal> = (0..count)
                .map(|_| {
                    let rot = DQuat::from_rotation_arc(DVec3::Z, rng.unit())
                        * DQuat::from_rotation_z(rng.range(0.0, 6.3));
                    let c = in_cube(&mut rng, 3.0);
                    Portal::new(rng.range(0.5, 3.0), rng.range(0.5, 3.0))
                        .with_transform(DMat4::from_rotation_translation(rot, c))
                })
                .collect();
            let p = masked(ps);
            let portals = p.portals.as_ref().unwrap();
            if cannot_hide_one_another(portals) {
                accepted += 1;
                let most = most_crossed(&mut rng, portals, 5.0, 4000);
                assert!(
                    most <= 1,
                    "case {case}: accepted, a ray crosses {most} portals"
                );
            } else {
                refused += 1;
                let centre = |q: &PreparedPortal| (q.corners[0] + q.corners[2]) * 0.5;
                let side = |q: &PreparedPortal, y: DVec3| q.normal.dot(y - q.origin);
                let witness = portals.iter().any(|a| {
                    portals.iter().any(|b| {
                        a.corners.iter().any(|ca| {
                            b.corners.iter().any(|cb| {
                                let ya = *ca + (centre(a) - *ca) * 1e-3;
                                let yb = *cb + (centre(b) - *cb) * 1e-3;
                                let w = (yb - ya).normalize_or_zero();
                                side(b, ya) < 0.0
                                    && side(a, yb) > 0.0
                                    && crossed(portals, ya - w * 1e-3, w) >= 2
                            })
                        })
                    })
                });
                assert!(
                    witness,
                    "case {case}: refused, but no ray through two portals"
                );
            }
        }
        assert!(
            accepted >= 20 && refused >= 20,
            "{accepted} accepted, {refused} refused"
        );
        // Windows in facing walls of a courtyard, each passing light toward its own room.
        let window = |x: f64, out: DVec3| {
            Portal::new(1.5, 1.0).with_transform(DMat4::from_rotation_translation(
                DQuat::from_rotation_arc(DVec3::Z, out),
                DVec3::new(x, 0.0, 1.0),
            ))
        };
        let courtyard = masked(vec![window(1.0, DVec3::X), window(3.0, -DVec3::X)]);
        assert!(cannot_hide_one_another(courtyard.portals.as_ref().unwrap()));
    }

    /// Where the portals cannot hide one another the sum over the portals is the visible
    /// pieces' irradiance (`cpu::portal::irradiance`, which cuts overlaps for any set) to
    /// 1e-9 relative (measured: 2.5e-11), for receivers inside and outside the room, of every
    /// orientation; sets the predicate refuses (overlapping windows) are skipped.
    #[test]
    fn the_sum_is_the_visible_pieces_where_portals_cannot_hide_one_another() {
        let mut rng = Rng::new(0x5EED);
        let mut worst: f64 = 0.0;
        let (mut lit, mut sets) = (0, 0);
        for _ in 0..40 {
            let count = 1 + rng.below(5);
            let ps: Vec<Portal> = (0..count)
                .map(|_| {
                    let wall = rng.below(6);
                    window(&mut rng, wall, 2.0)
                })
                .collect();
            let p = masked(ps);
            let portals = p.portals.as_ref().unwrap();
            if !cannot_hide_one_another(portals) {
                continue;
            }
            sets += 1;
            for _ in 0..40 {
                let x = in_cube(&mut rng, 2.5);
                let n = rng.unit();
                let want = crate::cpu::portal::irradiance(&p, portals, x, n);
                let got = p.base * portals_lambert(portals, x, n);
                let scale = want.abs().max_element().max(1e-300);
                if want.max_element() > 0.0 {
                    lit += 1;
                }
                worst = worst.max((got - want).abs().max_element() / scale);
            }
        }
        assert!(sets >= 20 && lit > 300, "{sets} sets, {lit} lit receivers");
        eprintln!("{sets} sets, {lit} lit receivers, worst relative difference {worst:e}");
        assert!(worst < 1e-9, "worst relative difference {worst:e}");
    }
}
