//! Tests of the device's sum for masked domes (`super`): the crossing orders and their
//! cliques against brute force, the sums against the visible pieces.

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

/// 1 to `most` windows ([`window`]) on random walls of the room [−a, a]³.
fn window_room(rng: &mut Rng, most: usize, a: f64) -> Vec<Portal> {
    let count = 1 + rng.below(most);
    (0..count)
        .map(|_| {
            let wall = rng.below(6);
            window(rng, wall, a)
        })
        .collect()
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
        let p = masked(window_room(&mut rng, 6, 1.0));
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
    let pane = |z: f64| Portal::new(1.0, 1.0).with_transform(DMat4::from_translation(DVec3::Z * z));
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
        let p = masked(window_room(&mut rng, 5, 2.0));
        let portals = p.portals.as_ref().unwrap();
        if !cannot_hide_one_another(portals) {
            continue;
        }
        sets += 1;
        for _ in 0..40 {
            let x = in_cube(&mut rng, 2.5);
            let n = rng.unit();
            let want = crate::cpu::portal::irradiance(&p, portals, x, n);
            let got = p.base * portals_irradiance(portals, &p.portal_overlaps, x, n, None);
            // Below 1e-6 of the base radiance both sides are slivers whose Lambert terms
            // cancel (to ~1e-17 absolute, measured): compared absolutely there.
            let scale = want.abs().max_element().max(1e-6 * p.base.max_element());
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

/// `crossing_orders` is exact in each order on random pairs of portals anywhere (a third of
/// them coplanar and overlapping): where an order is possible, a ray built from the proof's
/// corners (moved a little inside each portal) crosses the two in that order; where it is
/// not, none of 4,000 rays from random points (half aimed at a portal) does; coplanar
/// overlapping pairs give the earlier portal first and never the later (a ray counts as
/// crossing in an order where the parameters differ by more than 1e-9 relative: coplanar
/// portals' own planes round apart).
#[test]
fn crossing_orders_are_exact_in_each_order() {
    use crate::prepare::PreparedPortal;
    use crate::prepare::portal::crossing_orders;
    // The parameters at which the ray x + tω crosses q toward its +Z (edges inclusive).
    let hit = |q: &PreparedPortal, x: DVec3, w: DVec3| {
        let (toward, side) = (q.normal.dot(w), q.normal.dot(x - q.origin));
        if !(toward > 0.0 && side < 0.0) {
            return None;
        }
        let t = -side / toward;
        let h = q.to_local * (x + t * w - q.origin);
        (h.x.abs() <= q.half.x && h.y.abs() <= q.half.y).then_some(t)
    };
    let centre = |q: &PreparedPortal| (q.corners[0] + q.corners[2]) * 0.5;
    let mut rng = Rng::new(0x0_4DE5);
    let mut seen = [[0usize; 2]; 2];
    for case in 0..300 {
        let ps: Vec<Portal> = (0..2)
            .map(|k| {
                let rot = DQuat::from_rotation_arc(DVec3::Z, rng.unit())
                    * DQuat::from_rotation_z(rng.range(0.0, 6.3));
                let c = in_cube(&mut rng, 3.0);
                Portal::new(rng.range(0.5, 3.0), rng.range(0.5, 3.0))
                    .with_transform(DMat4::from_rotation_translation(rot, c))
                    .with_path(format!("/P{k}"))
            })
            .collect();
        let ps = if case % 3 == 0 {
            // The second in the first's plane, shifted and turned in it.
            let first = ps[0].clone();
            let shift = DMat4::from_translation(DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                0.0,
            )) * DMat4::from_rotation_z(rng.range(0.0, 6.3));
            let second = first.clone().with_transform(first.world * shift);
            vec![first, second]
        } else {
            ps
        };
        let p = masked(ps);
        let q = p.portals.as_ref().unwrap();
        if q.len() < 2 {
            continue;
        }
        let (a, b) = (&q[0], &q[1]);
        let orders = crossing_orders(a, b);
        for (k, (first, second), possible) in [(0, (a, b), orders.0), (1, (b, a), orders.1)] {
            seen[k][usize::from(possible)] += 1;
            let in_order = |x: DVec3, w: DVec3| {
                matches!((hit(first, x, w), hit(second, x, w)), (Some(s), Some(t)) if s < t - 1e-9 * t)
                    || (case % 3 == 0
                        && k == 0
                        && hit(first, x, w).is_some()
                        && hit(second, x, w).is_some())
            };
            if possible {
                let witness = first.corners.iter().any(|cf| {
                    second.corners.iter().any(|cs| {
                        let yf = *cf + (centre(first) - *cf) * 1e-3;
                        let ys = *cs + (centre(second) - *cs) * 1e-3;
                        let w = (ys - yf).normalize_or_zero();
                        in_order(yf - w * 1e-3, w)
                    })
                }) || (0..4000).any(|_| {
                    let x = in_cube(&mut rng, 5.0);
                    let c = second.corners;
                    let y = c[0] + (c[1] - c[0]) * rng.f64() + (c[3] - c[0]) * rng.f64();
                    in_order(x, (y - x).normalize())
                });
                assert!(
                    witness,
                    "case {case}: order {k} said possible, no ray found"
                );
            } else {
                let found = (0..4000).any(|_| {
                    let x = in_cube(&mut rng, 5.0);
                    let c = [first, second][rng.below(2)].corners;
                    let y = c[0] + (c[1] - c[0]) * rng.f64() + (c[3] - c[0]) * rng.f64();
                    in_order(x, (y - x).normalize())
                });
                assert!(
                    !found,
                    "case {case}: order {k} said impossible, a ray found"
                );
            }
        }
    }
    eprintln!(
        "orders (impossible, possible): a then b {:?}, b then a {:?}",
        seen[0], seen[1]
    );
    assert!(seen.iter().all(|s| s[0] >= 50 && s[1] >= 30), "{seen:?}");
}

/// A pane of random size (0.5 to 2.5 a side) centred in [−1, 1]² × [z0, z1], facing up
/// tilted by up to `tilt` along x and y (down with probability `down`), turned at random
/// about its normal.
fn random_pane(rng: &mut Rng, z0: f64, z1: f64, tilt: f64, down: f64) -> Portal {
    let c = DVec3::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(z0, z1),
    );
    let up = DVec3::new(rng.range(-tilt, tilt), rng.range(-tilt, tilt), 1.0);
    let facing = if rng.chance(down) { -up } else { up };
    let rot = DQuat::from_rotation_arc(DVec3::Z, facing.normalize())
        * DQuat::from_rotation_z(rng.range(0.0, 6.3));
    Portal::new(rng.range(0.5, 2.5), rng.range(0.5, 2.5))
        .with_transform(DMat4::from_rotation_translation(rot, c))
}

/// Where the device sums a masked dome's irradiance with overlaps (portals that rays may
/// cross several of: panes stacked with random tilts, offsets and turns, some facing down,
/// of one multiplier or each its own, those crossed in either order split), the
/// inclusion–exclusion sum is the visible pieces' irradiance (`cpu::portal::irradiance`,
/// which cuts the portals nearest first) to 1e-9 relative (1e-15 of the base radiance
/// where the answer is below 1e-6 of it: horizon slivers, whose Lambert terms cancel), for
/// receivers below, between and above the panes, of every orientation.
#[test]
fn the_inclusion_exclusion_sum_is_the_visible_pieces_where_portals_overlap() {
    let mut rng = Rng::new(0x1E_0E);
    let mut worst: f64 = 0.0;
    let (mut lit, mut sets, mut deep, mut mixed, mut split) = (0, 0, 0, 0, 0);
    for _ in 0..160 {
        let count = 2 + rng.below(4);
        let tint = DVec3::new(
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
        );
        let intensity = rng.range(0.5, 3.0);
        let own = rng.chance(0.5);
        let ps: Vec<Portal> = (0..count)
            .map(|_| {
                let pane = random_pane(&mut rng, 0.5, 3.0, 0.5, 0.15);
                if own {
                    pane.with_intensity(rng.range(0.5, 3.0))
                        .with_color(DVec3::new(
                            rng.range(0.2, 1.0),
                            rng.range(0.2, 1.0),
                            rng.range(0.2, 1.0),
                        ))
                } else {
                    pane.with_intensity(intensity).with_color(tint)
                }
            })
            .collect();
        let p = masked(ps);
        if p.gpu_path != crate::prepare::GpuPath::Device || p.portal_overlaps.is_empty() {
            continue;
        }
        sets += 1;
        deep += usize::from(p.portal_overlaps.iter().any(|s| s.members.len() >= 3));
        mixed += usize::from(own);
        split += usize::from(p.portal_overlaps.iter().any(|s| s.split.is_some()));
        let portals = p.portals.as_ref().unwrap();
        for r in 0..60 {
            let x = DVec3::new(
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(-2.0, 4.0),
            );
            let n = if r % 3 == 0 { DVec3::Z } else { rng.unit() };
            let want = crate::cpu::portal::irradiance(&p, portals, x, n);
            let got = p.base * portals_irradiance(portals, &p.portal_overlaps, x, n, None);
            // Below 1e-6 of the base radiance both sides are slivers whose Lambert terms
            // cancel (to ~1e-17 absolute, measured): compared absolutely there.
            let scale = want.abs().max_element().max(1e-6 * p.base.max_element());
            if want.max_element() > 0.0 {
                lit += 1;
            }
            let e = (got - want).abs().max_element() / scale;
            worst = worst.max(e);
        }
    }
    eprintln!(
        "{sets} sets ({deep} with three or more crossed, {mixed} of several multipliers, \
         {split} split), {lit} lit receivers, worst relative difference {worst:e}"
    );
    assert!(
        sets >= 80 && deep >= 20 && mixed >= 30 && split >= 20 && lit > 3000,
        "{sets} sets, {deep} deep, {mixed} mixed, {split} split, {lit} lit"
    );
    assert!(worst < 1e-9, "worst relative difference {worst:e}");
}

mod overlaps;
mod textured;
