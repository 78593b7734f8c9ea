//! Tests of the fast textured-rect path against the 1e-9 reference (`rect_texture`).

use std::sync::Arc;
use std::time::Instant;

use glam::{DMat3, DMat4, DQuat};

use super::kernel::{Kinks, RuleKind};
use super::tree::Tree;
use super::*;
use crate::cpu::irradiance::{Adaptive, Rule, irradiance, irradiance_with};
use crate::model::{Light, Shaping};
use crate::prepare::TemperatureMode;
use crate::prepare::texture::{Filter, Image, RectTexture};
use crate::synthetic::Rng;

fn textured(l: &Light, w: usize, h: usize, rgb: Vec<[f32; 3]>, filter: Filter) -> Prepared {
    let mut p = Prepared::new(l, TemperatureMode::Spec).unwrap();
    let img = Image::from_rgb(w, h, rgb, "test.exr").unwrap();
    p.kind = crate::prepare::KindData::Rect {
        texture: Some(RectTexture::new(Arc::new(img), filter)),
    };
    p
}

fn random_rgb(rng: &mut Rng, n: usize) -> Vec<[f32; 3]> {
    (0..n)
        .map(|_| [0, 1, 2].map(|_| (0.05 + rng.f64()) as f32))
        .collect()
}

/// The sheared transform of `rect_texture`'s tests.
fn skewed() -> DMat4 {
    let shear = DMat4::from_mat3(DMat3::from_cols(
        DVec3::new(1.3, 0.0, 0.0),
        DVec3::new(0.4, 0.8, 0.0),
        DVec3::new(0.0, 0.2, 1.1),
    ));
    DMat4::from_rotation_translation(
        DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 0.9),
        DVec3::new(0.2, -0.4, 0.7),
    ) * shear
}

/// A wide soft cone with a tinted focus, a narrow cone with the thinnest smoothstep the
/// fast path takes (softness 0.25; its edge crosses the rect for several receivers), and a
/// tinted focus alone (no cone: its only kink is the focus plane, |cos θ|^0.7 there, which
/// crosses the sheared rect for the three receivers nearest to it), and a hard 35° cone
/// (softness 0: a jump at its edge).
fn shapings() -> [Option<Shaping>; 5] {
    [
        None,
        Some(Shaping {
            focus: 1.5,
            focus_tint: DVec3::new(0.2, 0.5, 1.0),
            cone_angle: 50.0,
            cone_softness: 0.4,
            ies: None,
        }),
        Some(Shaping {
            focus: 0.7,
            focus_tint: DVec3::ONE,
            cone_angle: 30.0,
            cone_softness: 0.25,
            ies: None,
        }),
        Some(Shaping {
            focus: 0.7,
            focus_tint: DVec3::new(0.2, 0.5, 1.0),
            cone_angle: 180.0,
            cone_softness: 0.0,
            ies: None,
        }),
        Some(Shaping {
            focus: 0.0,
            focus_tint: DVec3::ONE,
            cone_angle: 35.0,
            cone_softness: 0.0,
            ies: None,
        }),
    ]
}

/// Receivers in local coordinates (in front: local −Z) with local normals: near the surface
/// (inside the near field: 0.02 and 0.002 from it), cut by their horizon, grazing (the
/// horizon through the rect's middle, as luxtest visibleRect's floor), and far.
fn receivers() -> Vec<(DVec3, DVec3)> {
    vec![
        (DVec3::new(0.1, 0.2, -1.0), DVec3::new(0.0, 0.1, 1.0)),
        (DVec3::new(0.05, -0.1, -0.02), DVec3::Z),
        (DVec3::new(-0.2, 0.13, -0.002), DVec3::new(0.2, 0.1, 1.0)),
        (DVec3::new(0.3, -0.1, -0.6), DVec3::new(1.0, 0.2, 0.3)),
        (DVec3::new(-0.4, 0.3, -0.4), DVec3::new(-0.3, -1.0, 0.5)),
        (DVec3::new(0.1, 0.0, -0.05), DVec3::Y),
        (DVec3::new(0.2, 0.01, -0.3), DVec3::Y),
        (DVec3::new(1.5, 0.9, -2.0), DVec3::new(-0.5, -0.3, 1.0)),
        (DVec3::new(-3.0, 2.0, -9.0), DVec3::new(0.3, -0.2, 1.0)),
    ]
}

fn world(p: &Prepared, x: DVec3, n: DVec3) -> (DVec3, DVec3) {
    (p.origin + p.linear * x, (p.linear * n).normalize())
}

fn rel_err(a: DVec3, b: DVec3) -> f64 {
    ((a - b).abs() / b.abs()).max_element()
}

/// The fast path against the 1e-9 reference (the exact split path, `rect_texture`) on random
/// textures, both filters, unshaped and shaped (cone, softness, focus with tint), under the
/// identity and a sheared transform, at every receiver of [`receivers`]: the relative error
/// of every channel within the requested tolerance.
fn against_reference(sizes: &[(usize, usize)], seed: u64) {
    let mut rng = Rng::new(seed);
    let mut worst = [0.0f64; 3];
    for &(tw, th) in sizes {
        let rgb = random_rgb(&mut rng, tw * th);
        for m in [DMat4::IDENTITY, skewed()] {
            for shaping in shapings() {
                let mut l = Light::rect(1.2, 0.8).with_intensity(2.0).with_transform(m);
                if let Some(s) = &shaping {
                    l = l.with_shaping(s.clone());
                }
                for filter in [Filter::Bilinear, Filter::Nearest] {
                    let p = textured(&l, tw, th, rgb.clone(), filter);
                    for (xl, nl) in receivers() {
                        let (x, n) = world(&p, xl, nl);
                        let reference = irradiance(&p, x, n);
                        if reference.max_element() <= 0.0 {
                            continue;
                        }
                        for (k, tol) in [1e-4, 1e-3, 1e-2].into_iter().enumerate() {
                            let rule = Adaptive::for_tolerance(tol);
                            assert!(rule.texture_tolerance().is_some());
                            let fast = irradiance_with(&p, x, n, &rule);
                            let err = rel_err(fast, reference);
                            worst[k] = worst[k].max(err / tol);
                            assert!(
                                err <= tol,
                                "{tw}x{th} {filter:?} shaped={} skewed={} at {xl} n {nl} \
                                 tol {tol:e}: {fast} vs {reference} ({err:e})",
                                shaping.is_some(),
                                m != DMat4::IDENTITY
                            );
                        }
                    }
                }
            }
        }
    }
    println!("worst error / tolerance at 1e-4, 1e-3, 1e-2: {worst:?}");
}

#[test]
fn small_random_textures_meet_the_tolerance_against_the_reference() {
    against_reference(&[(16, 8), (5, 3), (1, 1)], 3);
}

#[test]
fn medium_random_textures_meet_the_tolerance_against_the_reference() {
    against_reference(&[(64, 32)], 5);
}

/// The largest size, release build only (the reference takes seconds a receiver in a debug
/// build): `cargo test --release -p luxeval --lib rect_fast -- --ignored`.
#[test]
#[ignore]
fn large_random_textures_meet_the_tolerance_against_the_reference() {
    against_reference(&[(256, 128)], 9);
}

/// A small map like luxtest visibleRect's floor (an unshaped 1 × 1 rect at the origin facing
/// −Z, receivers on the plane y = 0 with normal +Y, so every receiver's horizon cuts the
/// rect through its middle), 6 × 6 receivers in front of it, a random 32 × 16 texture in both
/// filters: every pixel within the tolerance of the 1e-9 reference.
#[test]
fn a_visible_rect_floor_map_meets_the_tolerance() {
    let mut rng = Rng::new(17);
    let rgb = random_rgb(&mut rng, 32 * 16);
    let l = Light::rect(1.0, 1.0);
    let mut worst = 0.0f64;
    for filter in [Filter::Bilinear, Filter::Nearest] {
        let p = textured(&l, 32, 16, rgb.clone(), filter);
        for i in 0..6 {
            for j in 0..6 {
                let x = DVec3::new(-1.5 + 0.6 * i as f64, 0.0, -0.03 - 0.4 * j as f64);
                let reference = irradiance(&p, x, DVec3::Y);
                for tol in [1e-4, 1e-2] {
                    let fast = irradiance_with(&p, x, DVec3::Y, &Adaptive::for_tolerance(tol));
                    let err = rel_err(fast, reference);
                    worst = worst.max(err / tol);
                    assert!(
                        err <= tol,
                        "{filter:?} at {x} tol {tol:e}: {fast} vs {reference}"
                    );
                }
            }
        }
    }
    println!("worst error / tolerance: {worst:.3}");
}

/// Textured rects take the fast path unshaped and shaped (cone, softness, focus, focusTint);
/// with an IES profile they keep the exact path ([`applies`]).
#[test]
fn shaped_rects_take_the_fast_path_ies_ones_do_not() {
    let tex = || vec![[1.0f32; 3]; 4];
    assert!(applies(&textured(
        &Light::rect(1.2, 0.8),
        2,
        2,
        tex(),
        Filter::Nearest
    )));
    let mut rng = Rng::new(7);
    for s in shapings().into_iter().flatten() {
        let l = Light::rect(1.2, 0.8).with_shaping(s);
        let p = textured(&l, 2, 2, tex(), Filter::Bilinear);
        assert!(p.shaping.is_some() && applies(&p));
        let l = crate::testkit::ies::with_random_ies(l, &mut rng, 0, true);
        let p = textured(&l, 2, 2, tex(), Filter::Bilinear);
        assert!(p.ies.is_some() && !applies(&p));
    }
    // Not a textured rect.
    assert!(!applies(
        &Prepared::new(&Light::rect(1.2, 0.8), TemperatureMode::Spec).unwrap()
    ));
}

/// Textures lit in one texel only, each texel in turn, unshaped and shaped lights ([`shapings`]), both
/// filters, identity and sheared transforms, every receiver of [`receivers`]: the fast path
/// must find each texel's light to the tolerance of the 1e-9 reference. Random textures hide
/// a rule that samples the texture across texel pieces (the cause of the shaped bias, see
/// `chart_integral`): a cell and its children can all miss a texel, and a cell whose lit part
/// lies in one child has that child's very rule points, so the estimate reads 0.
fn single_texels(tw: usize, th: usize) {
    let mut worst = [0.0f64; 2];
    for m in [DMat4::IDENTITY, skewed()] {
        for s in shapings() {
            let mut l = Light::rect(1.2, 0.8).with_intensity(2.0).with_transform(m);
            if let Some(s) = s {
                l = l.with_shaping(s);
            }
            for filter in [Filter::Bilinear, Filter::Nearest] {
                for k in 0..tw * th {
                    let mut rgb = vec![[0.0f32; 3]; tw * th];
                    rgb[k] = [1.0, 0.5, 0.25];
                    let p = textured(&l, tw, th, rgb, filter);
                    for (xl, nl) in receivers() {
                        let (x, n) = world(&p, xl, nl);
                        let reference = irradiance(&p, x, n);
                        if reference.min_element() <= 0.0 {
                            continue;
                        }
                        // At 1e-2 the bracketed horizon-cut cells (`Kernel::bracket`) stay
                        // large: a bound that did not hold would show there first.
                        for (ti, tol) in [1e-4, 1e-2].into_iter().enumerate() {
                            let fast = irradiance_with(&p, x, n, &Adaptive::for_tolerance(tol));
                            let err = rel_err(fast, reference);
                            worst[ti] = worst[ti].max(err / tol);
                            assert!(
                                err <= tol,
                                "{tw}x{th} {filter:?} skewed={} texel {k} at {xl} n {nl} \
                                 tol {tol:e}: {fast} vs {reference} ({err:e})",
                                m != DMat4::IDENTITY
                            );
                        }
                    }
                }
            }
        }
    }
    println!("worst error / tolerance at 1e-4, 1e-2: {worst:.3?}");
}

#[test]
fn single_texel_textures_meet_the_tolerance() {
    single_texels(8, 4);
}

/// The same on 16 × 8 textures, release build only (~2 min):
/// `cargo test --release -p luxeval --lib rect_fast -- --ignored`.
#[test]
#[ignore]
fn single_texel_16_by_8_textures_meet_the_tolerance() {
    single_texels(16, 8);
}

/// A constant texture c multiplies the untextured rect by c: Lambert's closed form unshaped
/// (`closed::rect_lambert`), the untextured rect's reference chart quadrature shaped.
#[test]
fn a_constant_texture_gives_the_untextured_rect() {
    let c = [0.7f32, 1.3, 2.0];
    for m in [DMat4::IDENTITY, skewed()] {
        for shaping in shapings() {
            let mut l = Light::rect(1.2, 0.8).with_intensity(2.0).with_transform(m);
            if let Some(s) = &shaping {
                l = l.with_shaping(s.clone());
            }
            let plain = Prepared::new(&l, TemperatureMode::Spec).unwrap();
            for (w, h) in [(1, 1), (7, 5), (40, 30)] {
                for filter in [Filter::Bilinear, Filter::Nearest] {
                    let p = textured(&l, w, h, vec![c; w * h], filter);
                    for (xl, nl) in receivers() {
                        let (x, n) = world(&p, xl, nl);
                        let want = irradiance(&plain, x, n) * DVec3::from_array(c.map(f64::from));
                        if want.max_element() <= 0.0 {
                            continue;
                        }
                        for tol in [1e-4, 1e-3, 1e-2] {
                            let got = irradiance_with(&p, x, n, &Adaptive::for_tolerance(tol));
                            let err = rel_err(got, want);
                            assert!(
                                err <= tol,
                                "{w}x{h} {filter:?} at {xl}: {got} vs {want} ({err:e})"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// Timing (no assertion on time): ms per receiver on a random 2048 × 1024 texture at the
/// CLI's default tolerance 1e-4, tree build separately, for an unshaped rect and for the
/// shaped ones of [`shapings`]. Release only:
/// `cargo test --release -p luxeval --lib rect_fast::tests::timing -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_2048_by_1024() {
    let mut rng = Rng::new(1);
    let (tw, th) = (2048, 1024);
    let rgb = random_rgb(&mut rng, tw * th);
    let img = Arc::new(Image::from_rgb(tw, th, rgb, "test.exr").unwrap());
    let tex = RectTexture::new(img, Filter::Bilinear);
    let t0 = Instant::now();
    let _ = tree(&tex);
    println!("tree build: {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
    let rule = Adaptive::for_tolerance(1e-4);
    for shaping in shapings() {
        let mut l = Light::rect(1.0, 1.0).with_intensity(1.0);
        if let Some(s) = &shaping {
            l = l.with_shaping(s.clone());
        }
        // The texture (and its tree, built above) shared by the three lights.
        let mut p = Prepared::new(&l, TemperatureMode::Spec).unwrap();
        p.kind = crate::prepare::KindData::Rect {
            texture: Some(tex.clone()),
        };
        println!("shaping {shaping:?}");
        for (xl, nl) in receivers() {
            let (x, n) = world(&p, xl, nl);
            let t = Instant::now();
            let e = irradiance_with(&p, x, n, &rule);
            println!(
                "receiver {xl} n {nl}: {e} in {:.2} ms",
                t.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}

/// `∫ t·K` over a cell to near rounding: each texel piece of it cut into `4^depth` sub-rects,
/// each integrated by the clipped rule (t a polynomial there, K smooth on the lit part).
fn fine_cell_integral(k: &Kernel, tree: &Tree, cell: Cell, depth: u32) -> DVec3 {
    if tree.pieces(&cell) == 1 && depth == 0 {
        return k.clipped(tree.rect(&cell), |x, y| tree.value_in(&cell, x, y));
    }
    let d = if tree.pieces(&cell) == 1 {
        depth - 1
    } else {
        depth
    };
    tree.children(&cell)
        .into_iter()
        .map(|c| fine_cell_integral(k, tree, c, d))
        .sum()
}

/// The bracket rule's bound holds ([`Kernel::bracket`]): on every cell over several pieces that
/// the horizon cuts or a soft cone's kink cones may cross (no other kink), well separated from
/// x, random
/// 16 × 8 textures, both filters, unshaped and shaped, receivers whose horizons cut the rect,
/// `|bracket − ∫ t·K| ≤ bound` with `∫ t·K` summed over 64 sub-rects per texel piece.
#[test]
fn the_bracket_rule_is_within_its_bound() {
    let mut rng = Rng::new(23);
    let (mut cells, mut soft, mut worst) = (0usize, 0usize, 0.0f64);
    for filter in [Filter::Bilinear, Filter::Nearest] {
        for s in shapings() {
            let mut l = Light::rect(1.2, 0.8).with_transform(skewed());
            if let Some(s) = s.clone() {
                l = l.with_shaping(s);
            }
            let p = textured(&l, 16, 8, random_rgb(&mut rng, 16 * 8), filter);
            let tree = tree(p.rect_texture().unwrap()).unwrap();
            for _ in 0..6 {
                // A receiver 0.3–1.3 in front whose horizon plane passes near the rect's middle.
                let xl = DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, -0.3 - rng.f64());
                let t = DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, 0.0) * 0.6 - xl;
                let nl = t.any_orthonormal_pair().0 * (rng.f64() - 0.5).signum();
                let (x, n) = world(&p, xl, nl);
                let chart = crate::cpu::irradiance::chart::plane_chart(
                    &p,
                    x,
                    0.6,
                    0.4,
                    crate::cpu::irradiance::chart::Region::Square,
                );
                let k = Kernel::new(&p, &chart, n);
                let mut stack = vec![Cell::Node(0)];
                while let Some(c) = stack.pop() {
                    let r = tree.rect(&c);
                    let class = k.class(&tree, &c);
                    if tree.pieces(&c) < 2 || class.kind != RuleKind::Clipped {
                        continue;
                    }
                    stack.extend(tree.children(&c));
                    if !class.bracketed || class.forced {
                        continue;
                    }
                    let coned = class.kinks == Kinks::SoftCone;
                    soft += usize::from(coned);
                    let w = tree.moments(&c);
                    let (value, bound) = k.bracket(r, &w, tree.abs_integral(&c, r, &w), coned);
                    let exact = fine_cell_integral(&k, &tree, c, 3);
                    let err = (value - exact).abs();
                    cells += 1;
                    worst = worst.max((err / bound).max_element());
                    assert!(
                        err.cmple(bound).all(),
                        "{filter:?} {s:?} at {xl} n {nl}, cell {r:?}: {value} vs {exact}, \
                         bound {bound}"
                    );
                }
            }
        }
    }
    assert!(cells > 100, "only {cells} bracketed cells were checked");
    assert!(
        soft > 20,
        "only {soft} cells crossed by a soft cone's kinks were checked"
    );
    println!(
        "{cells} cells ({soft} crossed by a soft cone's kinks), worst error / bound {worst:.3}"
    );
}
