//! The exact irradiance of a textured dome masked by portals (DESIGN.md §8 P2 mask mode,
//! `DomeIrradiance::irradiance_within`) against independent values, for every format, both
//! filters, the identity and a non-conformal dome frame:
//!
//! 1. six portals closing a box around x pass the whole dome: the masked value equals the
//!    unmasked exact dome irradiance (its own tests: tests/dome_irradiance.rs) to ≤ 1e-9
//!    (measured ≤ 7.4e-14);
//! 2. a constant texture through a tilted portal partly below the horizon is `L ×` Lambert's
//!    formula for the portal clipped at the horizon (`closed::polygon_irradiance`, tested on its
//!    own) to ≤ 1e-9 (measured ≤ 2.1e-14);
//! 3. a random texture through two overlapping portals (the farther partly below the horizon)
//!    agrees with a brute force written here: tensor Gauss–Legendre on a grid of sub-squares of
//!    each portal's plane (`L(ω) max(0, n·ω) cos θ_portal / r²` with the lookup of
//!    `cpu::emission`, the nearer portal's shadow cut out of the farther by hand), to within the
//!    brute force's own error, estimated by halving its grid: 1e-6 for bilinear (its kinks
//!    are integrated to O(h²)), only 5e-3 for nearest (its jumps to O(h)); the nearest filter's
//!    exactness rests on 1 and 2.

use std::sync::Arc;

use glam::{DMat3, DMat4, DQuat, DVec3};

use crate::cpu::emission::emission;
use crate::cpu::irradiance::closed::polygon_irradiance;
use crate::cpu::irradiance::dome::quadrature::gauss_legendre;
use crate::cpu::irradiance::irradiance;
use crate::model::{Light, Portal};
use crate::prepare::texture::{DomeFormat, DomeFrame, Filter, Image, PreparedTexture};
use crate::prepare::{KindData, PortalMode, Prepared, TemperatureMode};
use crate::synthetic::Rng;

/// Random texels in [0.1, 2) with a few bright ones (×20).
fn random_image(w: usize, h: usize, seed: u64) -> Image {
    let mut rng = Rng::new(seed);
    let rgb = (0..w * h)
        .map(|_| {
            let k = if rng.chance(0.1) { 20.0 } else { 1.0 };
            [0, 1, 2].map(|_| (k * (0.1 + 1.9 * rng.f64())) as f32)
        })
        .collect();
    Image::from_rgb(w, h, rgb, "random.exr").unwrap()
}

const CONSTANT: [f32; 3] = [0.75, 1.25, 2.5];

fn constant_image(w: usize, h: usize) -> Image {
    Image::from_rgb(w, h, vec![CONSTANT; w * h], "constant.exr").unwrap()
}

/// A rotation × a non-uniform scale × a shear: a non-conformal dome frame.
fn skew() -> DMat3 {
    DMat3::from_quat(DQuat::from_axis_angle(
        DVec3::new(1.0, 2.0, 3.0).normalize(),
        0.7,
    )) * DMat3::from_diagonal(DVec3::new(1.4, 0.6, 1.0))
        * DMat3::from_cols(DVec3::X, DVec3::new(0.3, 1.0, 0.0), DVec3::Z)
}

/// Every format at a small size, both filters, the identity and the skewed frame.
fn configs() -> Vec<(DomeFormat, usize, usize, Filter, DMat3)> {
    let mut v = vec![];
    for (format, w, h) in [
        (DomeFormat::LatLong, 8, 4),
        (DomeFormat::MirroredBall, 8, 8),
        (DomeFormat::Angular, 8, 8),
        (DomeFormat::Cross, 6, 8),
    ] {
        for filter in [Filter::Bilinear, Filter::Nearest] {
            for m in [DMat3::IDENTITY, skew()] {
                v.push((format, w, h, filter, m));
            }
        }
    }
    v
}

/// The dome with `img` and `portals`: (masked, unmasked).
fn domes(
    img: &Image,
    format: DomeFormat,
    filter: Filter,
    frame: DMat3,
    portals: &[Portal],
) -> (Prepared, Prepared) {
    let light = portals.iter().fold(
        Light::dome()
            .with_intensity(1.5)
            .with_color(DVec3::new(1.0, 0.8, 0.6))
            .with_diffuse(0.8)
            .with_transform(DMat4::from_mat3(frame)),
        |d, q| d.with_portal(q.clone()),
    );
    let mut p = Prepared::new(&light, TemperatureMode::Spec).unwrap();
    p.kind = KindData::Dome {
        texture: Some(PreparedTexture {
            image: Arc::new(img.clone()),
            format,
            frame: DomeFrame::new(frame, DMat3::IDENTITY).unwrap(),
            filter,
            irradiance: Default::default(),
        }),
    };
    let plain = p.clone();
    p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
        .unwrap();
    assert!(portals.is_empty() || p.portals.as_ref().is_some_and(|v| v.len() == portals.len()));
    (p, plain)
}

fn rel(a: DVec3, b: DVec3) -> f64 {
    (a - b).abs().max_element() / b.abs().max_element()
}

/// Six `2h × 2h` portals on the faces of the cube of half-size h around `c`, each face's +Z
/// outward (rays from inside cross them toward +Z).
fn closed_box(c: DVec3, h: f64) -> Vec<Portal> {
    [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ]
    .into_iter()
    .enumerate()
    .map(|(k, out)| {
        let rot = DQuat::from_rotation_arc(DVec3::Z, out);
        Portal::new(2.0 * h, 2.0 * h)
            .with_path(format!("/Box{k}"))
            .with_transform(DMat4::from_rotation_translation(rot, c + out * h))
    })
    .collect()
}

#[test]
fn a_closed_box_of_portals_passes_the_whole_dome() {
    let portals = closed_box(DVec3::new(0.1, 0.0, -0.2), 1.0);
    // Tilted normals; and one ⊥ Z, whose horizon passes through the disk formats' rim
    // direction −Z (the box's edges along Z do too).
    let receivers = [
        (DVec3::new(0.2, -0.3, 0.1), DVec3::new(0.3, -0.5, 0.8)),
        (DVec3::new(-0.5, 0.6, -0.7), DVec3::new(-0.7, 0.2, -0.1)),
        (DVec3::new(0.3, 0.2, 0.4), DVec3::new(0.6, 0.8, 0.0)),
    ];
    // And other sizes (odd ones, a finer latlong and cross) under the skewed frame.
    let mut all = configs();
    for (format, w, h) in [
        (DomeFormat::LatLong, 16, 8),
        (DomeFormat::MirroredBall, 17, 17),
        (DomeFormat::Angular, 9, 9),
        (DomeFormat::Cross, 12, 16),
    ] {
        for filter in [Filter::Bilinear, Filter::Nearest] {
            all.push((format, w, h, filter, skew()));
        }
    }
    // Maps large enough that whole blocks of tiles (tables.rs) lie inside a face, outside it
    // and across its edges (one filter each: a disk map of this size takes seconds).
    all.extend([
        (DomeFormat::LatLong, 256, 128, Filter::Nearest, skew()),
        (DomeFormat::MirroredBall, 96, 96, Filter::Bilinear, skew()),
        (DomeFormat::Cross, 72, 96, Filter::Nearest, skew()),
    ]);
    let mut worst: f64 = 0.0;
    for (k, (format, w, h, filter, frame)) in all.into_iter().enumerate() {
        let img = random_image(w, h, 11 + k as u64);
        let (masked, plain) = domes(&img, format, filter, frame, &portals);
        for (x, n) in receivers {
            let n = n.normalize();
            let got = irradiance(&masked, x, n);
            let want = irradiance(&plain, x, n);
            let e = rel(got, want);
            worst = worst.max(e);
            assert!(
                e <= 1e-9,
                "{format:?} {filter:?} {frame}: {got} vs {want}: {e:e}"
            );
        }
    }
    eprintln!("closed box against the unmasked dome: worst relative error {worst:e}");
}

/// A 3 × 2 portal near x, tilted, with a multiplier.
fn tilted_portal() -> (Portal, DMat4) {
    let world = DMat4::from_rotation_translation(
        DQuat::from_rotation_y(0.4) * DQuat::from_rotation_x(0.3),
        DVec3::new(0.5, 0.0, 1.0),
    );
    let portal = Portal::new(3.0, 2.0)
        .with_path("/Tilted")
        .with_transform(world)
        .with_intensity(2.0)
        .with_color(DVec3::new(1.0, 0.5, 0.25));
    (portal, world)
}

fn corners(world: DMat4, w: f64, h: f64) -> [DVec3; 4] {
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| world.transform_point3(DVec3::new(a * w / 2.0, b * h / 2.0, 0.0)))
}

#[test]
fn a_constant_texture_through_a_tilted_portal_is_lambert() {
    let (portal, world) = tilted_portal();
    let c = corners(world, 3.0, 2.0);
    let x = DVec3::ZERO;
    let mut worst: f64 = 0.0;
    for (format, w, h, filter, frame) in configs() {
        let img = constant_image(w, h);
        let (masked, _) = domes(&img, format, filter, frame, std::slice::from_ref(&portal));
        // Crossed by the horizon, and wholly above it (the portal's own normal).
        for (n, crossed) in [
            (DVec3::new(1.0, 0.3, 0.2), true),
            (world.transform_vector3(DVec3::Z), false),
        ] {
            let n = n.normalize();
            let q = c.map(|p| p - x);
            let below = q.iter().filter(|v| n.dot(**v) < 0.0).count();
            assert_eq!(
                below > 0 && below < 4,
                crossed,
                "the horizon crosses the portal"
            );
            let l = DVec3::from_array(CONSTANT.map(f64::from));
            let want =
                masked.base * l * DVec3::new(2.0, 1.0, 0.5) * polygon_irradiance(&q, n) * 0.8;
            let got = irradiance(&masked, x, n);
            let e = rel(got, want);
            worst = worst.max(e);
            assert!(
                e <= 1e-9,
                "{format:?} {filter:?} {frame}: {got} vs {want}: {e:e}"
            );
        }
    }
    eprintln!("constant texture against Lambert: worst relative error {worst:e}");
}

/// `∫∫ L(ω) max(0, n·ω) |N·ω| / r² du dv` over the rectangle `[u0, u1] × [v0, v1]` of the plane
/// `o + u e1 + v e2` (orthonormal e1, e2; N = e1 × e2) seen from x: `g × g` sub-squares per unit
/// length, each by the tensor 6-point Gauss–Legendre rule.
#[allow(clippy::too_many_arguments)]
fn brute_rect(
    p: &Prepared,
    x: DVec3,
    n: DVec3,
    frame: (DVec3, DVec3, DVec3),
    (u0, u1): (f64, f64),
    (v0, v1): (f64, f64),
    g: f64,
) -> DVec3 {
    let (o, e1, e2) = frame;
    let normal = e1.cross(e2);
    let (nu, nv) = (
        ((u1 - u0) * g).ceil().max(1.0) as usize,
        ((v1 - v0) * g).ceil().max(1.0) as usize,
    );
    let (du, dv) = ((u1 - u0) / nu as f64, (v1 - v0) / nv as f64);
    let (t, wt) = gauss_legendre(6);
    let mut sum = DVec3::ZERO;
    for i in 0..nu {
        for j in 0..nv {
            for (a, wa) in t.iter().zip(wt) {
                for (b, wb) in t.iter().zip(wt) {
                    let u = u0 + du * (i as f64 + 0.5 + 0.5 * a);
                    let v = v0 + dv * (j as f64 + 0.5 + 0.5 * b);
                    let q = o + u * e1 + v * e2 - x;
                    let r2 = q.length_squared();
                    let w = q / r2.sqrt();
                    let c = n.dot(w);
                    if c > 0.0 {
                        sum += emission(p, w) * (c * normal.dot(w).abs() / r2 * wa * wb);
                    }
                }
            }
        }
    }
    sum * (0.25 * du * dv)
}

#[test]
fn two_overlapping_portals_agree_with_a_brute_force() {
    // Parallel planes (the same rotation), so the nearer portal's shadow on the farther one is
    // a rectangle along the same axes: cut out by hand.
    let rot = DQuat::from_rotation_y(0.35) * DQuat::from_rotation_x(-0.25);
    let (e1, e2) = (rot * DVec3::X, rot * DVec3::Y);
    let (near_o, far_o) = (DVec3::new(0.15, 0.05, 1.2), DVec3::new(0.3, 0.0, 2.5));
    let (near_wh, far_wh) = ((1.0, 0.8), (3.0, 2.4));
    let near = Portal::new(near_wh.0, near_wh.1)
        .with_path("/Near")
        .with_transform(DMat4::from_rotation_translation(rot, near_o))
        .with_intensity(3.0);
    let far = Portal::new(far_wh.0, far_wh.1)
        .with_path("/Far")
        .with_transform(DMat4::from_rotation_translation(rot, far_o))
        .with_color(DVec3::new(0.5, 1.0, 2.0));
    let x = DVec3::new(0.05, -0.1, 0.0);
    let n = DVec3::new(1.0, 0.1, 0.25).normalize();
    let normal = e1.cross(e2);
    // The shadow: the near rectangle scaled from x by the ratio of the planes' distances.
    let k = normal.dot(far_o - x) / normal.dot(near_o - x);
    let centre = x + (near_o - x) * k - far_o;
    let (su, sv) = (centre.dot(e1), centre.dot(e2));
    let (hu, hv) = (0.5 * near_wh.0 * k, 0.5 * near_wh.1 * k);
    let (fu, fv) = (0.5 * far_wh.0, 0.5 * far_wh.1);
    assert!(su - hu > -fu && su + hu < fu && sv - hv > -fv && sv + hv < fv);
    // The far portal crosses the horizon.
    let fc = corners(
        DMat4::from_rotation_translation(rot, far_o),
        far_wh.0,
        far_wh.1,
    );
    assert!(fc.iter().any(|c| n.dot(*c - x) < 0.0) && fc.iter().any(|c| n.dot(*c - x) > 0.0));
    let us = [-fu, su - hu, su + hu, fu];
    let vs = [-fv, sv - hv, sv + hv, fv];
    let mut worst = (0.0f64, 0.0f64);
    for (c, (format, w, h, filter, frame)) in configs().into_iter().enumerate() {
        let img = random_image(w, h, 40 + c as u64);
        // Whatever the order the dome names them in: the same value (to rounding: the pieces are
        // summed in another order).
        let both = [[&near, &far], [&far, &near]].map(|order| {
            let ports: Vec<Portal> = order.iter().map(|p| (*p).clone()).collect();
            domes(&img, format, filter, frame, &ports).0
        });
        let got = irradiance(&both[0], x, n);
        let other = irradiance(&both[1], x, n);
        assert!(rel(other, got) <= 1e-13, "{got} vs {other}");
        let masked = &both[0];
        let brute = |g: f64| {
            let mut far_sum = DVec3::ZERO;
            for i in 0..3 {
                for j in 0..3 {
                    if i == 1 && j == 1 {
                        continue;
                    }
                    let f = (far_o, e1, e2);
                    let r = (us[i], us[i + 1]);
                    far_sum += brute_rect(masked, x, n, f, r, (vs[j], vs[j + 1]), g);
                }
            }
            let near_sum = brute_rect(
                masked,
                x,
                n,
                (near_o, e1, e2),
                (-0.5 * near_wh.0, 0.5 * near_wh.0),
                (-0.5 * near_wh.1, 0.5 * near_wh.1),
                g * k,
            );
            (near_sum * 3.0 + far_sum * DVec3::new(0.5, 1.0, 2.0)) * 0.8
        };
        let (coarse, fine) = (brute(64.0), brute(128.0));
        let level = rel(coarse, fine);
        let e = rel(got, fine);
        eprintln!(
            "{format:?} {filter:?}: exact vs brute force {e:.1e}, brute force halving {level:.1e}"
        );
        // What the brute force can prove: its change when its grid is halved estimates its own
        // error, up to a factor of a few (its error where the grid cuts the bilinear kinks, or
        // the nearest jumps, is erratic in h). Measured: ≤ 6.3e-7 bilinear, ≤ 3.5e-3 nearest.
        let proven = match filter {
            Filter::Bilinear => 1e-6,
            Filter::Nearest => 5e-3,
        };
        assert!(
            level <= proven,
            "{format:?} {filter:?}: brute force {level:e}"
        );
        assert!(
            e <= proven,
            "{format:?} {filter:?}: {got} vs {fine}: {e:e} (brute force {level:e})"
        );
        let slot = if filter == Filter::Bilinear {
            &mut worst.0
        } else {
            &mut worst.1
        };
        *slot = slot.max(e);
    }
    eprintln!(
        "against the brute force: worst bilinear {:.1e}, nearest {:.1e}",
        worst.0, worst.1
    );
}

/// Per-receiver cost of a masked textured dome's irradiance (not a test of values; run with
/// `cargo test --release --no-default-features --lib portal_timing -- --ignored --nocapture`):
/// the exact integral against the adaptive cubature it replaced (`integrate_piece` of the
/// dome's radiance over each visible piece, as `portal::irradiance` did before, at the
/// reference's 1e-9 and at 1e-6), on the two-portal room of the tests in `portal.rs` with
/// 1024 × 512 latlong maps. The tables are built before timing.
#[test]
#[ignore]
fn portal_timing() {
    use std::time::Instant;

    use crate::cpu::mesh::visible::{Surface, integrate_piece};
    use crate::model::{Asset, Texture, TextureFormat};

    let room = |tex: Texture| {
        let window = Portal::new(3.0, 2.0).with_path("/Window").with_transform(
            DMat4::from_rotation_translation(
                DQuat::from_rotation_y(0.5),
                DVec3::new(0.5, 0.0, 2.5),
            ),
        );
        let skylight = Portal::new(2.0, 2.0)
            .with_path("/Skylight")
            .with_transform(DMat4::from_translation(DVec3::new(0.0, 0.5, 4.0)));
        Light::dome()
            .with_texture(tex)
            .with_portal(window)
            .with_portal(skylight)
    };
    let mut rng = Rng::new(5);
    let receivers: Vec<(DVec3, DVec3)> = (0..16)
        .map(|_| {
            let x = DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64());
            let n = DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, 1.0).normalize();
            (x, n)
        })
        .collect();
    for name in ["testImage.png", "studio_dwab.exr"] {
        let file = format!("{}/tests/data/textures/{name}", env!("CARGO_MANIFEST_DIR"));
        let tex = Texture::new(Asset::file(file)).with_format(TextureFormat::LatLong);
        let mut p = Prepared::new(&room(tex), TemperatureMode::Spec).unwrap();
        p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
            .unwrap();
        let ports = p.portals.clone().unwrap();
        let t0 = Instant::now();
        let _ = crate::cpu::irradiance::dome::tables(&p)
            .unwrap()
            // The tables, not the latlong sweep that `irradiance` takes unmasked.
            .irradiance_within(DVec3::Z, &[]);
        eprintln!("{name}: tables {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
        let t0 = Instant::now();
        let exact: Vec<DVec3> = receivers
            .iter()
            .map(|&(x, n)| super::irradiance(&p, &ports, x, n))
            .collect();
        let per = t0.elapsed().as_secs_f64() * 1e3 / receivers.len() as f64;
        eprintln!("{name}: exact {per:.2} ms a receiver");
        for rel_tol in [1e-9, 1e-6] {
            let t0 = Instant::now();
            let mut worst: f64 = 0.0;
            for (&(x, n), want) in receivers.iter().zip(&exact) {
                let (triangles, owner) = super::seen_from(&ports, x);
                let surface = Surface {
                    triangles: &triangles,
                    double_sided: true,
                };
                let mut sum = DVec3::ZERO;
                for piece in surface.emitting_above(x, n) {
                    let m = ports[owner[piece.triangle as usize]].multiplier;
                    sum += m * integrate_piece(&piece.verts, n, rel_tol, &mut |w: DVec3| {
                        emission(&p, w)
                    });
                }
                worst = worst.max(rel(sum, *want));
            }
            let per = t0.elapsed().as_secs_f64() * 1e3 / receivers.len() as f64;
            eprintln!(
                "{name}: adaptive to {rel_tol:e}: {per:.2} ms a receiver, {worst:.1e} from exact"
            );
        }
    }
}
