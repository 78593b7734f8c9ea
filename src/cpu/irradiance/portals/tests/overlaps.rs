//! Which overlaps `prepare::portal::overlaps` lists (the cliques of the crossable pairs) and
//! how it splits them where the farthest member's multiplier depends on the ray.

use super::*;

/// `overlaps` lists exactly the sets of two or more portals that are pairwise crossable by
/// one ray (checked against every subset of random sets of 2 to 7 portals, panes stacked
/// with random tilts and offsets so that many are), ascending, in lexicographic order, or
/// refuses with the reason: five portals pairwise crossable, or more sets than the kernel
/// sums. Sets whose farthest member's multiplier depends on the ray are split.
#[test]
fn overlaps_are_the_cliques_of_the_crossable_pairs() {
    use crate::prepare::portal::{
        MOST_PORTALS_ONE_RAY_CROSSES, OVERLAP_ITERATIONS, Overlap, one_ray_may_cross_both,
        overlap_iterations, overlaps,
    };
    let mut rng = Rng::new(0x0E_C11);
    let (mut listed, mut triples, mut fours, mut refused) = (0, 0, 0, 0);
    for case in 0..300 {
        let count = 2 + rng.below(6);
        let ps: Vec<Portal> = (0..count)
            .map(|_| random_pane(&mut rng, 0.0, 4.0, 0.4, 0.2))
            .collect();
        let p = masked(ps);
        let portals = p.portals.as_ref().unwrap();
        let n = portals.len();
        let linked = |i: usize, j: usize| one_ray_may_cross_both(&portals[i], &portals[j]);
        let mut want: Vec<Vec<u32>> = (1u32..1 << n)
            .filter(|m| m.count_ones() >= 2)
            .map(|m| {
                (0..n as u32)
                    .filter(|k| m >> k & 1 == 1)
                    .collect::<Vec<u32>>()
            })
            .filter(|s| {
                s.iter()
                    .enumerate()
                    .all(|(a, &i)| s[a + 1..].iter().all(|&j| linked(i as usize, j as usize)))
            })
            .collect();
        want.sort();
        match overlaps(portals) {
            Ok(sets) => {
                // One multiplier: never split, the lowest member first.
                assert!(sets.iter().all(|s| s.split.is_none()), "case {case}");
                let sets: Vec<Vec<u32>> = sets.into_iter().map(|s| s.members).collect();
                assert_eq!(sets, want, "case {case}");
                listed += 1;
                triples += usize::from(sets.iter().any(|s| s.len() == 3));
                fours += usize::from(sets.iter().any(|s| s.len() == 4));
            }
            Err(why) => {
                refused += 1;
                assert!(
                    want.iter().any(|s| s.len() > MOST_PORTALS_ONE_RAY_CROSSES)
                        || want
                            .iter()
                            .map(|s| overlap_iterations(s.len(), false))
                            .sum::<usize>()
                            > OVERLAP_ITERATIONS,
                    "case {case}: refused ({why}) with {} sets, the largest {}",
                    want.len(),
                    want.iter().map(Vec::len).max().unwrap_or(0)
                );
            }
        }
    }
    eprintln!("{listed} listed ({triples} with triples, {fours} with fours), {refused} refused");
    assert!(listed >= 150 && triples >= 30 && fours >= 10 && refused >= 5);
    // Different multipliers on a pair crossed lower first: the farther (upper) one named
    // first; three of them, each crossed after the ones below; a pane through another at
    // 57° (crossed in either order): split, neither always before the other; apart: listed
    // as nothing.
    let pane = |z: f64| Portal::new(1.0, 1.0).with_transform(DMat4::from_translation(DVec3::Z * z));
    let tinted = masked(vec![pane(2.0).with_intensity(2.0), pane(1.0)]);
    assert_eq!(
        overlaps(tinted.portals.as_ref().unwrap()),
        Ok(vec![Overlap::whole(&[0, 1])])
    );
    let three = masked(vec![
        pane(1.0),
        pane(3.0).with_intensity(3.0),
        pane(2.0).with_intensity(2.0),
    ]);
    assert_eq!(
        overlaps(three.portals.as_ref().unwrap()),
        Ok(vec![
            Overlap::whole(&[1, 0]),
            Overlap::whole(&[1, 0, 2]),
            Overlap::whole(&[2, 0]),
            Overlap::whole(&[1, 2])
        ])
    );
    let turned = Portal::new(1.0, 1.0)
        .with_transform(DMat4::from_rotation_translation(
            DQuat::from_rotation_x(1.0),
            DVec3::Z,
        ))
        .with_intensity(2.0);
    let crossing = masked(vec![pane(1.0), turned.clone()]);
    let split = |members: &[u32], before: u16| Overlap {
        members: members.to_vec(),
        split: Some(before),
    };
    assert_eq!(
        overlaps(crossing.portals.as_ref().unwrap()),
        Ok(vec![split(&[0, 1], 0)])
    );
    assert_eq!(crossing.gpu_path, crate::prepare::GpuPath::Device);
    // A pane below both (index 2) is crossed before each: bits 4·2 + 0 and 4·2 + 1 in the
    // triple, whose farthest is 0 or 1 by the ray; a pane above both is always the farthest,
    // so the triple with it is whole, named first.
    let floored = masked(vec![
        pane(1.0),
        turned.clone(),
        pane(0.0).with_intensity(3.0),
    ]);
    assert_eq!(
        overlaps(floored.portals.as_ref().unwrap()),
        Ok(vec![
            split(&[0, 1], 0),
            split(&[0, 1, 2], 1 << 8 | 1 << 9),
            Overlap::whole(&[0, 2]),
            Overlap::whole(&[1, 2])
        ])
    );
    let capped = masked(vec![pane(1.0), turned, pane(3.0).with_intensity(3.0)]);
    assert_eq!(
        overlaps(capped.portals.as_ref().unwrap()),
        Ok(vec![
            split(&[0, 1], 0),
            Overlap::whole(&[2, 0, 1]),
            Overlap::whole(&[2, 0]),
            Overlap::whole(&[2, 1])
        ])
    );
    let apart = masked(vec![
        pane(1.0),
        pane(2.0).with_transform(DMat4::from_translation(DVec3::new(5.0, 0.0, 1.0))),
    ]);
    assert_eq!(overlaps(apart.portals.as_ref().unwrap()), Ok(vec![]));
    // Five stacked panes: a ray crosses all five.
    let five = masked((0..5).map(|k| pane(1.0 + k as f64)).collect());
    assert!(matches!(
        five.gpu_path,
        crate::prepare::GpuPath::HostIrradiance(_)
    ));
    let four = masked((0..4).map(|k| pane(1.0 + k as f64)).collect());
    assert_eq!(four.gpu_path, crate::prepare::GpuPath::Device);
    assert_eq!(four.portal_overlaps.len(), 11);
    // k windows in a row and a pane 1 above each: every window and every pane are
    // crossable (a ray slanting up from under one window through another's pane), no two
    // windows nor two panes are: k² sets of two, up to OVERLAP_ITERATIONS (20² · 121 =
    // 48,400; 21² · 121 = 53,361), each naming its pane
    // first (of another multiplier, always crossed after the window).
    let facade = |k: usize| {
        let at = |i: usize, z: f64| {
            Portal::new(1.0, 1.0).with_transform(DMat4::from_translation(DVec3::new(
                3.0 * i as f64,
                0.0,
                z,
            )))
        };
        masked(
            (0..k)
                .flat_map(|i| [at(i, 0.0), at(i, 1.0).with_intensity(2.0)])
                .collect(),
        )
    };
    let many = facade(20);
    assert_eq!(many.gpu_path, crate::prepare::GpuPath::Device);
    assert_eq!(many.portal_overlaps.len(), 400);
    assert!(
        many.portal_overlaps
            .iter()
            .all(|s| s.members.len() == 2 && s.members[0] % 2 == 1 && s.split.is_none())
    );
    assert_eq!(
        facade(21).gpu_path,
        crate::prepare::GpuPath::HostIrradiance(
            "it is masked by portals that overlap in more ways than the irradiance kernel \
             sums"
        )
    );
}

/// A split set whose members include a coplanar pair: two overlapping panes in one plane of
/// different multipliers (the earlier is the nearer where they overlap, P2's tie; their plane
/// in `farther_plane` vanishes, so the split relies on the set's `before` bits) and a third
/// pane through both at an angle, of a third multiplier. The sum is the visible pieces'
/// irradiance to 1e-9 for receivers below the panes, of every orientation.
#[test]
fn a_split_set_with_coplanar_members_is_the_visible_pieces() {
    use crate::prepare::portal::Overlap;
    let at = |x: f64, turn: f64, k: f64| {
        Portal::new(2.0, 1.5)
            .with_transform(DMat4::from_rotation_translation(
                DQuat::from_rotation_y(turn),
                DVec3::new(x, 0.0, 2.0),
            ))
            .with_intensity(k)
    };
    let p = masked(vec![
        at(-0.5, 0.0, 1.0),
        at(0.5, 0.0, 2.0),
        at(0.1, 0.9, 3.0),
    ]);
    assert_eq!(p.gpu_path, crate::prepare::GpuPath::Device);
    // Pane 0 lies before pane 1 on every ray through both (bit 4·0 + 1); pane 2 crosses
    // each in either order.
    assert!(
        p.portal_overlaps.contains(&Overlap {
            members: vec![0, 1, 2],
            split: Some(1 << 1),
        }),
        "{:?}",
        p.portal_overlaps
    );
    let portals = p.portals.as_ref().unwrap();
    let mut rng = Rng::new(0xC0_9A);
    let (mut worst, mut lit) = (0.0f64, 0);
    for _ in 0..400 {
        let x = DVec3::new(
            rng.range(-2.5, 2.5),
            rng.range(-2.0, 2.0),
            rng.range(-1.0, 1.9),
        );
        let n = if rng.chance(0.3) {
            DVec3::Z
        } else {
            rng.unit()
        };
        let want = crate::cpu::portal::irradiance(&p, portals, x, n);
        let got = p.base * portals_irradiance(portals, &p.portal_overlaps, x, n, None);
        let scale = want.abs().max_element().max(1e-6 * p.base.max_element());
        lit += usize::from(want.max_element() > 1e-3);
        worst = worst.max((got - want).abs().max_element() / scale);
    }
    eprintln!("{lit} lit of 400, worst relative difference {worst:e}");
    assert!(lit > 200, "{lit} lit");
    assert!(worst < 1e-9, "worst relative difference {worst:e}");
}
