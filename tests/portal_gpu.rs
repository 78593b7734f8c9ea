//! A dome masked by portals (DESIGN.md §8 P2 mask mode) on a GPU evaluator: emission and
//! radiance on the device (shaders/portal.wgsl); irradiance on the device for untextured and
//! latlong domes whose portals cannot hide one another or overlap, in one order or in either
//! (shaders/irradiance/portals.wgsl, the last four tests); intensity from the CPU reference. Radiance is compared with
//! the reference within 1e-4 relative away from the portals' edges and planes (a band of 1e-4 of the portal's size, the
//! one `luxeval check` excludes, computed here from the portals' transforms); the excluded count
//! is printed. Hint mode is bitwise the dome without portals.

use glam::{DMat3, DMat4, DQuat, DVec3};
use luxeval::testkit::Rng;
use luxeval::{
    Accumulate, Asset, Evaluator, Light, Portal, PortalMode, Texture, TextureFilter, TextureFormat,
};

/// Half-width of the excluded band, as `conformance::BAND`.
const BAND: f64 = 1e-4;

fn rel(a: [f32; 3], b: [f32; 3]) -> f64 {
    let (a, b) = (
        DVec3::from_array(a.map(f64::from)),
        DVec3::from_array(b.map(f64::from)),
    );
    let d = (a - b).abs().max_element();
    if d == 0.0 {
        0.0
    } else {
        d / a.abs().max_element().max(b.abs().max_element())
    }
}

/// Portals of several kinds: overlapping at different depths (a skylight above a larger,
/// deeper-in-the-view one), one turned the other way (its +Z faces down), one rotated and
/// non-uniformly scaled, multipliers ≠ 1 (intensity, exposure, colour).
fn portals() -> Vec<(Portal, DMat4, f64, f64)> {
    let rot = DMat4::from_quat(DQuat::from_rotation_x(0.4) * DQuat::from_rotation_z(0.7));
    let specs = [
        // A window in the wall x = 3, turned about Y by −90°: its +Z faces world −X, so it
        // passes light toward +X, to points beyond the wall.
        (
            DMat4::from_rotation_translation(
                DQuat::from_rotation_y(-std::f64::consts::FRAC_PI_2),
                DVec3::new(3.0, 0.0, 0.5),
            ),
            2.0,
            1.5,
            (1.0, 0.0, DVec3::new(0.9, 0.8, 0.7)),
        ),
        // A skylight at z = 4 and a larger one above it at z = 6 (overlapping as seen from
        // below: the nearer counts).
        (
            DMat4::from_translation(DVec3::new(0.0, 0.5, 4.0)),
            2.0,
            2.0,
            (2.0, 0.0, DVec3::ONE),
        ),
        (
            DMat4::from_translation(DVec3::new(0.3, 0.0, 6.0)),
            5.0,
            4.0,
            (1.0, -1.0, DVec3::new(0.5, 1.0, 0.25)),
        ),
        // Turned the other way: +Z faces down, so only rays moving down cross it toward +Z.
        (
            DMat4::from_rotation_translation(
                DQuat::from_rotation_x(std::f64::consts::PI),
                DVec3::new(-1.0, -1.0, -3.0),
            ),
            3.0,
            2.0,
            (0.5, 1.0, DVec3::ONE),
        ),
        // Rotated and non-uniformly scaled (and sheared by the rotation after the scale).
        (
            DMat4::from_translation(DVec3::new(-2.5, 1.0, 1.0))
                * rot
                * DMat4::from_scale(DVec3::new(1.5, 0.6, 2.0)),
            1.5,
            2.0,
            (3.0, 0.0, DVec3::new(1.0, 0.7, 0.2)),
        ),
    ];
    specs
        .into_iter()
        .enumerate()
        .map(|(i, (world, w, h, (intensity, exposure, color)))| {
            let p = Portal::new(w, h)
                .with_path(format!("/P{i}"))
                .with_transform(world)
                .with_intensity(intensity)
                .with_exposure(exposure)
                .with_color(color);
            (p, world, w, h)
        })
        .collect()
}

/// How far the ray x + tω is from changing the portal it passes through (as
/// `conformance::band::portal_margin`, written out again here): the crossing point's distance
/// to each portal's edges and the origin's distance to each plane (fractions of the portal's
/// larger half extent, in its local units), and the grazing angle.
fn margin(ps: &[(Portal, DMat4, f64, f64)], x: DVec3, w: DVec3) -> f64 {
    let mut m = f64::INFINITY;
    for (_, world, wd, ht) in ps {
        let inv = DMat3::from_mat4(*world).inverse();
        let xl = inv * (x - world.w_axis.truncate());
        let dl = inv * w;
        let (hw, hh) = (wd / 2.0, ht / 2.0);
        let s = hw.max(hh);
        m = m.min(xl.z.abs() / s).min(dl.normalize().z.abs());
        if dl.z != 0.0 && -xl.z / dl.z > 0.0 {
            let h = xl - xl.z / dl.z * dl;
            m = m.min(((h.x.abs() - hw).abs() / s).min((h.y.abs() - hh).abs() / s));
        }
    }
    m
}

fn textured(l: Light) -> Light {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/textures/testImage.png"
    );
    l.with_texture(Texture::new(Asset::file(file)).with_format(TextureFormat::LatLong))
}

fn masked(l: Light, ps: &[(Portal, DMat4, f64, f64)]) -> Light {
    ps.iter().fold(l, |l, (p, ..)| l.with_portal(p.clone()))
}

/// Points inside the room and outside it (on both sides of every portal), rays aimed at the
/// portals (and past their edges) and in uniform directions.
fn rays(ps: &[(Portal, DMat4, f64, f64)], n: usize, seed: u64) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut rng = Rng::new(seed);
    let (mut pts, mut dirs) = (Vec::new(), Vec::new());
    for i in 0..n {
        let x = DVec3::new(
            rng.range(-4.0, 4.0),
            rng.range(-4.0, 4.0),
            rng.range(-5.0, 7.0),
        );
        let w = if i % 3 == 0 {
            rng.unit()
        } else {
            let (_, world, wd, ht) = &ps[i % ps.len()];
            let local = DVec3::new(rng.range(-0.6, 0.6) * wd, rng.range(-0.6, 0.6) * ht, 0.0);
            (world.transform_point3(local) - x).normalize()
        };
        pts.push(x.as_vec3().to_array());
        dirs.push(w.as_vec3().to_array());
    }
    (pts, dirs)
}

/// GPU radiance of masked domes, untextured and textured, within 1e-4 of the reference away
/// from the portals' edges and planes; emission is the dome's own on both; intensity is the
/// reference's exactly; irradiance is the device's, within 1e-4 away from the check's bands.
#[test]
fn masked_dome_radiance_runs_on_the_device_within_tolerance() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let ps = portals();
    let domes = [
        masked(
            Light::dome()
                .with_intensity(1.5)
                .with_color(DVec3::new(1.0, 0.6, 0.3))
                .with_path("/Sky"),
            &ps,
        ),
        masked(textured(Light::dome().with_path("/Map")), &ps),
    ];
    let cpu = Evaluator::cpu().with_portal_mode(PortalMode::Mask);
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    let n = 6000;
    let (pts, dirs) = rays(&ps, n, 11);
    for dome in &domes {
        let l = std::slice::from_ref(dome);
        let c = cpu.prepare(l).unwrap();
        let g = gpu.prepare(l).unwrap();
        let (rc, rg) = (
            c.radiance(&pts, &dirs, Accumulate::Sum).unwrap(),
            g.radiance(&pts, &dirs, Accumulate::Sum).unwrap(),
        );
        let (mut excluded, mut lit, mut worst) = (0, 0, 0.0f64);
        for i in 0..n {
            let x = DVec3::from_array(pts[i].map(f64::from));
            let w = DVec3::from_array(dirs[i].map(f64::from));
            if margin(&ps, x, w) < BAND {
                excluded += 1;
                continue;
            }
            if rc[i] != [0.0; 3] {
                lit += 1;
            }
            let e = rel(rc[i], rg[i]);
            assert!(
                e <= 1e-4,
                "{}: ray {i} from {x} along {w}: cpu {:?} gpu {:?} ({e:e})",
                dome.path,
                rc[i],
                rg[i]
            );
            worst = worst.max(e);
        }
        eprintln!(
            "{}: {n} rays, {excluded} within {BAND:e} of a portal edge or plane (excluded), \
             {lit} lit, worst relative error {worst:e}",
            dome.path
        );
        assert!(lit > n / 10, "{lit} lit of {n}");
        assert!(excluded < n / 50, "{excluded} excluded");
        // Emission is the dome's own (within f32 rounding of the texture lookup: the dome
        // check compares it); irradiance and intensity are the reference's rows.
        let e_dirs = &dirs[..256];
        for (a, b) in c
            .emission(e_dirs, Accumulate::Sum)
            .unwrap()
            .iter()
            .zip(g.emission(e_dirs, Accumulate::Sum).unwrap())
        {
            assert!(rel(*a, b) <= 1e-4, "emission {a:?} vs {b:?}");
        }
        let (ic, ig) = (
            c.irradiance(&pts[..64], &dirs[..64], Accumulate::PerLight)
                .unwrap(),
            g.irradiance(&pts[..64], &dirs[..64], Accumulate::PerLight)
                .unwrap(),
        );
        {
            // These portals overlap in one order each, so the device sums it (the textured
            // dome's texture is large for lavapipe's loop budget: most receivers are cut
            // short and recomputed by the host, see masked_textured_dome_irradiance_…).
            use luxeval::testkit::check;
            let reference = luxeval::Reference::with_portal_mode(
                dome,
                luxeval::TemperatureMode::Spec,
                PortalMode::Mask,
            )
            .unwrap();
            for i in 0..64 {
                let x = DVec3::from_array(pts[i].map(f64::from));
                let nn = DVec3::from_array(dirs[i].map(f64::from));
                if check::irradiance_margin(&reference, x, nn) >= check::BAND {
                    assert!(
                        rel(ic[i], ig[i]) <= check::TOLERANCE,
                        "{i}: {:?} {:?}",
                        ic[i],
                        ig[i]
                    );
                }
            }
        }
        assert_eq!(
            c.intensity(e_dirs, Accumulate::Sum).unwrap(),
            g.intensity(e_dirs, Accumulate::Sum).unwrap()
        );
    }
}

/// Each multiplier applies where its portal is the nearest crossed toward +Z: straight up from
/// under the skylights, the lower one's (2); from between them, the upper one's (0.5·colour);
/// straight down onto the turned portal from above, its own (0.5·2); up through it (toward its
/// −Z, ignored) and past every other portal, none.
#[test]
fn the_nearest_portal_crossed_toward_its_front_counts_on_the_device() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let ps = portals();
    let dome = masked(Light::dome().with_path("/Sky"), &ps);
    let g = gpu
        .with_portal_mode(PortalMode::Mask)
        .prepare(std::slice::from_ref(&dome))
        .unwrap();
    let pts = [
        [0.0f32, 0.5, 0.0],
        [0.3, 0.0, 5.0],
        [-1.0, -1.0, -1.0],
        [-2.4, -1.9, -5.0],
    ];
    let dirs = [
        [0.0f32, 0.0, 1.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [0.0, 0.0, 1.0],
    ];
    let got = g.radiance(&pts, &dirs, Accumulate::Sum).unwrap();
    assert_eq!(got[0], [2.0; 3]);
    assert_eq!(got[1], [0.25, 0.5, 0.125]);
    assert_eq!(got[2], [1.0; 3]);
    assert_eq!(got[3], [0.0; 3]);
    let c = Evaluator::cpu()
        .with_portal_mode(PortalMode::Mask)
        .prepare(std::slice::from_ref(&dome))
        .unwrap();
    assert_eq!(got, c.radiance(&pts, &dirs, Accumulate::Sum).unwrap());
}

/// A dome whose every portal passes no light (zero width) lights nothing in mask mode, on the
/// device as on the reference; a dome naming no portal is unchanged; hint mode is bitwise the
/// dome without portals on every query.
#[test]
fn invisible_portals_and_hint_mode_on_the_device() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let ps = portals();
    let (pts, dirs) = rays(&ps, 512, 3);
    let plain = Light::dome().with_intensity(1.5).with_path("/Sky");
    // Masked by portals that pass nothing: every ray 0 on both paths.
    let shut = plain
        .clone()
        .with_portal(Portal::new(0.0, 1.0).with_path("/Shut"));
    let s = std::slice::from_ref(&shut);
    let g = gpu
        .clone()
        .with_portal_mode(PortalMode::Mask)
        .prepare(s)
        .unwrap();
    let c = Evaluator::cpu()
        .with_portal_mode(PortalMode::Mask)
        .prepare(s)
        .unwrap();
    let rg = g.radiance(&pts, &dirs, Accumulate::Sum).unwrap();
    assert!(rg.iter().all(|v| *v == [0.0; 3]));
    assert_eq!(rg, c.radiance(&pts, &dirs, Accumulate::Sum).unwrap());
    // Hint mode, and mask mode without portals: bitwise the plain dome on the device.
    let reference = gpu.prepare(std::slice::from_ref(&plain)).unwrap();
    let hinted = masked(plain.clone(), &ps);
    for (mode, l) in [(PortalMode::Hint, &hinted), (PortalMode::Mask, &plain)] {
        let g = gpu
            .clone()
            .with_portal_mode(mode)
            .prepare(std::slice::from_ref(l))
            .unwrap();
        let acc = Accumulate::PerLight;
        assert_eq!(
            g.radiance(&pts, &dirs, acc).unwrap(),
            reference.radiance(&pts, &dirs, acc).unwrap()
        );
        assert_eq!(
            g.emission(&dirs, acc).unwrap(),
            reference.emission(&dirs, acc).unwrap()
        );
        assert_eq!(
            g.irradiance(&pts, &dirs, acc).unwrap(),
            reference.irradiance(&pts, &dirs, acc).unwrap()
        );
    }
}

/// An untextured dome seen through windows that cannot hide one another (a box room's walls and
/// ceiling, several windows a wall, rotated and non-uniformly scaled in their plane, tinted):
/// its irradiance is the device's (Lambert's formula summed over the portals,
/// shaders/irradiance/portals.wgsl), within 1e-4 of the reference (its visible pieces,
/// cpu::portal::irradiance) for receivers inside and outside the room, of every orientation,
/// away from the portals' planes and horizon slivers (`check::irradiance_margin`); `luxeval
/// check`'s comparison passes and lists nothing as host-only.
#[test]
fn masked_dome_irradiance_runs_on_the_device_where_portals_cannot_hide_one_another() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    // Windows (centre on the wall, in-plane rotation and scale) on the room [−3, 3]³: +Z out.
    let walls = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z];
    let specs = [
        (0, 0.0, 0.8, 0.3, 1.4, 1.0),
        (0, 1.9, -0.6, 1.0, 1.2, 0.6),
        (1, 0.4, 0.2, 0.0, 2.0, 1.5),
        (2, -1.5, 0.5, 0.7, 1.0, 2.2),
        (3, 1.0, -1.0, 2.0, 1.6, 0.8),
        (4, 0.0, 0.0, 0.4, 2.5, 2.5),
        (4, 2.2, 2.0, 0.0, 0.8, 0.8),
    ];
    let dome = specs.iter().enumerate().fold(
        Light::dome()
            .with_path("/Sky")
            .with_intensity(2.0)
            .with_color(DVec3::new(0.9, 0.7, 1.0)),
        |l, (i, &(wall, u, v, turn, w, h))| {
            let out = walls[wall];
            let (t1, t2) = out.any_orthonormal_pair();
            let rot = DQuat::from_rotation_arc(DVec3::Z, out) * DQuat::from_rotation_z(turn);
            let world = DMat4::from_rotation_translation(rot, out * 3.0 + t1 * u + t2 * v)
                * DMat4::from_scale(DVec3::new(1.3, 0.8, 1.0));
            l.with_portal(
                Portal::new(w, h)
                    .with_path(format!("/W{i}"))
                    .with_transform(world)
                    .with_intensity(0.5 + i as f64 * 0.4)
                    .with_color(DVec3::new(1.0, 0.8 - 0.1 * i as f64, 0.5)),
            )
        },
    );
    let n = 3000;
    let (excluded, lit, worst) = irradiance_matches_the_reference(&gpu, &dome, 0xD0_0E);
    eprintln!(
        "masked dome irradiance: {n} receivers, {excluded} excluded, {lit} lit, worst relative \
         error {worst:e}"
    );
    assert!(lit > n / 3, "{lit} lit of {n}");
    assert!(excluded < n / 50, "{excluded} excluded");
}

/// An untextured dome seen through portals that rays may cross several of, each of its own
/// intensity and colour: a skylight under two tilted, turned panes (three crossed by one ray),
/// two overlapping windows in one wall, a window with a pane outside it, a window apart. Its
/// irradiance is the device's (inclusion–exclusion over the portals and their overlaps, each
/// with its farthest portal's multiplier, shaders/irradiance/portals.wgsl),
/// within 1e-4 of the reference (the visible pieces, nearest first) for receivers inside and
/// outside the room, away from the check's bands; `luxeval check` passes, nothing host-only.
#[test]
fn masked_dome_irradiance_runs_on_the_device_where_portals_overlap() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    let dome = glazed(
        Light::dome()
            .with_path("/Sky")
            .with_intensity(2.0)
            .with_color(DVec3::new(0.9, 0.7, 1.0)),
    );
    let n = 3000;
    let (excluded, lit, worst) = irradiance_matches_the_reference(&gpu, &dome, 0x0E_1A9);
    eprintln!(
        "masked dome irradiance through overlapping portals: {n} receivers, {excluded} \
         excluded, {lit} lit, worst relative error {worst:e}"
    );
    assert!(lit > n / 3, "{lit} lit of {n}");
    // Eight portals' f32 bands (measured: 66 receivers, 2.2 %).
    assert!(excluded < n / 30, "{excluded} excluded");
}

/// The same glazing over textured latlong domes (random 32 × 16 texels; the default bilinear
/// filter and nearest; the identity frame and a turned, scaled one): the device integrates the
/// texture over each portal and overlap by rows (shaders/irradiance/latlong_polygon.wgsl),
/// within 1e-4 of the reference's exact texel integral over the visible pieces, away from the
/// check's bands; `luxeval check` passes, nothing host-only. (tests/resident.rs shows the
/// kernel finishes these on lavapipe rather than leaving them to the host.)
#[test]
fn masked_textured_dome_irradiance_runs_on_the_device() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    let mut rng = Rng::new(0x7E_47);
    let turned = DMat4::from_scale_rotation_translation(
        DVec3::splat(3.0),
        DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
        DVec3::new(1.0, -2.0, 0.5),
    );
    for (i, (filter, frame)) in [
        (TextureFilter::Nearest, DMat4::IDENTITY),
        (TextureFilter::Bilinear, turned),
        (TextureFilter::Bilinear, DMat4::IDENTITY),
        (TextureFilter::Nearest, turned),
    ]
    .into_iter()
    .enumerate()
    {
        let texture = Texture::new(luxeval::testkit::dome::random_png(32, 16, &mut rng))
            .with_format(TextureFormat::LatLong)
            .with_filter(filter);
        let dome = glazed(
            Light::dome()
                .with_path("/Map")
                .with_intensity(1.5)
                .with_transform(frame)
                .with_texture(texture),
        );
        let n = 3000;
        let (excluded, lit, worst) =
            irradiance_matches_the_reference(&gpu, &dome, 0x7E_0E + i as u64);
        eprintln!(
            "textured masked dome irradiance ({filter:?}): {n} receivers, {excluded} excluded, \
             {lit} lit, worst relative error {worst:e}"
        );
        assert!(lit > n / 3, "{lit} lit of {n}");
        assert!(excluded < n / 30, "{excluded} excluded");
    }
}

/// Portals of different multipliers that rays cross in either order (panes through a skylight
/// and through a window at steep angles, three through one another over the skylight, a
/// second skylight overlapping the first in its plane): the
/// device splits each such overlap where its members are crossed at once and gives each piece
/// its farthest portal's multiplier (`prepare::portal::Overlap::split`), within 1e-4 of the
/// reference (the visible pieces, nearest first) away from the check's bands, for a uniform
/// dome and a textured latlong one; `luxeval check` passes, nothing host-only.
#[test]
fn masked_dome_irradiance_runs_on_the_device_where_portals_cross() {
    let Some(gpu) = crate::common::gpu() else {
        return;
    };
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    let mut rng = Rng::new(0xC2_055);
    let texture = Texture::new(luxeval::testkit::dome::random_png(32, 16, &mut rng))
        .with_format(TextureFormat::LatLong);
    for (i, dome) in [
        Light::dome().with_path("/Sky").with_intensity(2.0),
        Light::dome().with_path("/Map").with_texture(texture),
    ]
    .into_iter()
    .enumerate()
    {
        let dome = crossed(dome);
        let n = 3000;
        let (excluded, lit, worst) =
            irradiance_matches_the_reference(&gpu, &dome, 0xC2_0E + i as u64);
        eprintln!(
            "masked dome irradiance through crossed portals ({}): {n} receivers, {excluded} \
             excluded, {lit} lit, worst relative error {worst:e}",
            dome.path
        );
        assert!(lit > n / 4, "{lit} lit of {n}");
        assert!(excluded < n / 30, "{excluded} excluded");
    }
}

/// Six portals on `dome`, each of its own intensity and colour: a skylight with two panes
/// through it at steep angles (crossing it and each other), a window with a pane through it,
/// and a second skylight in the first one's plane overlapping it (a coplanar pair, crossed
/// in one order: the panes' split sets that hold both rely on the set's `before` bits).
fn crossed(dome: Light) -> Light {
    // (rotation, centre, width, height)
    let specs = [
        (DQuat::IDENTITY, DVec3::new(0.0, 0.0, 3.0), 2.0, 2.4),
        (DQuat::IDENTITY, DVec3::new(0.8, 0.5, 3.0), 1.4, 1.2),
        (
            DQuat::from_rotation_x(1.0),
            DVec3::new(0.2, 0.1, 3.1),
            1.8,
            1.6,
        ),
        (
            DQuat::from_rotation_y(-0.8),
            DVec3::new(-0.3, 0.2, 3.2),
            1.6,
            1.6,
        ),
        (
            DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
            DVec3::new(3.0, 0.5, 0.0),
            2.0,
            1.4,
        ),
        (
            DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2) * DQuat::from_rotation_x(0.9),
            DVec3::new(3.1, 0.4, 0.2),
            1.6,
            1.2,
        ),
    ];
    with_tinted_portals(dome, "/C", specs, |i| {
        (
            0.6 + 0.7 * i,
            DVec3::new(1.0, 0.9 - 0.15 * i, 0.3 + 0.15 * i),
        )
    })
}

/// `dome` with a portal per `(rotation, centre, width, height)`, named `prefix` and its
/// index i, of intensity and colour `tint(i)`.
fn with_tinted_portals(
    dome: Light,
    prefix: &str,
    placed: impl IntoIterator<Item = (DQuat, DVec3, f64, f64)>,
    tint: impl Fn(f64) -> (f64, DVec3),
) -> Light {
    placed
        .into_iter()
        .enumerate()
        .fold(dome, |l, (i, (rot, c, w, h))| {
            let (intensity, color) = tint(i as f64);
            l.with_portal(
                Portal::new(w, h)
                    .with_path(format!("{prefix}{i}"))
                    .with_transform(DMat4::from_rotation_translation(rot, c))
                    .with_intensity(intensity)
                    .with_color(color),
            )
        })
}

/// Eight portals on `dome`, each of its own intensity and colour: a skylight under two tilted,
/// turned panes, two overlapping windows in one wall, a window with a pane outside it, a
/// window apart.
fn glazed(dome: Light) -> Light {
    // (facing, centre, turn about the facing, width, height)
    let tilt = |x: f64, y: f64| DVec3::new(x, y, 1.0).normalize();
    let specs = [
        (DVec3::Z, DVec3::new(0.0, 0.0, 3.0), 0.0, 2.0, 2.4),
        (tilt(0.2, -0.1), DVec3::new(0.3, 0.2, 3.6), 0.5, 2.2, 1.8),
        (tilt(-0.15, 0.25), DVec3::new(-0.2, 0.4, 4.3), 1.1, 2.6, 2.0),
        (DVec3::X, DVec3::new(3.0, 0.5, -0.5), 0.2, 2.0, 1.2),
        (DVec3::X, DVec3::new(3.0, 1.4, 0.2), 0.9, 1.6, 1.4),
        (-DVec3::Y, DVec3::new(-1.0, -3.0, 0.0), 0.0, 1.5, 1.5),
        (tilt(0.0, -3.0), DVec3::new(-0.8, -3.7, 0.3), 0.3, 2.0, 1.6),
        (-DVec3::X, DVec3::new(-3.0, 0.0, 0.5), 0.6, 1.2, 2.0),
    ];
    let placed = specs.map(|(facing, c, turn, w, h)| {
        let rot = DQuat::from_rotation_arc(DVec3::Z, facing) * DQuat::from_rotation_z(turn);
        (rot, c, w, h)
    });
    with_tinted_portals(dome, "/P", placed, |i| {
        (
            0.8 + 0.3 * i,
            DVec3::new(1.0, 0.9 - 0.08 * i, 0.4 + 0.05 * i),
        )
    })
}

/// Compares the masked `dome`'s irradiance on `gpu` with the reference's at 3,000 receivers
/// (two in three inside the room [−2.9, 2.9]³, the rest in [−5, 5]³; normals uniform, or +Z)
/// within the check's tolerance, away from `check::irradiance_margin`'s bands; then `luxeval
/// check`'s comparison: nothing host-only, every row passing, irradiance among them. Returns
/// (excluded, lit, worst relative error).
fn irradiance_matches_the_reference(
    gpu: &Evaluator,
    dome: &Light,
    seed: u64,
) -> (usize, usize, f64) {
    use luxeval::testkit::check;
    let cpu = Evaluator::cpu().with_portal_mode(PortalMode::Mask);
    let l = std::slice::from_ref(dome);
    let reference = luxeval::Reference::with_portal_mode(
        dome,
        luxeval::TemperatureMode::Spec,
        PortalMode::Mask,
    )
    .unwrap();
    let mut rng = Rng::new(seed);
    let n = 3000;
    let (mut pts, mut nrms) = (Vec::new(), Vec::new());
    for i in 0..n {
        // Two in three inside the room, the rest around it; normals uniform, or up.
        let r = if i % 3 == 2 { 5.0 } else { 2.9 };
        let x = DVec3::new(rng.range(-r, r), rng.range(-r, r), rng.range(-r, r));
        let nn = if i % 4 == 0 { DVec3::Z } else { rng.unit() };
        pts.push(x.as_vec3().to_array());
        nrms.push(nn.as_vec3().to_array());
    }
    let c = cpu
        .prepare(l)
        .unwrap()
        .irradiance(&pts, &nrms, Accumulate::Sum)
        .unwrap();
    let g = gpu
        .prepare(l)
        .unwrap()
        .irradiance(&pts, &nrms, Accumulate::Sum)
        .unwrap();
    let (mut excluded, mut lit, mut worst) = (0, 0, 0.0f64);
    for i in 0..n {
        let x = DVec3::from_array(pts[i].map(f64::from));
        let nn = DVec3::from_array(nrms[i].map(f64::from));
        if check::irradiance_margin(&reference, x, nn) < check::BAND {
            excluded += 1;
            continue;
        }
        if c[i] != [0.0; 3] {
            lit += 1;
        }
        let e = rel(c[i], g[i]);
        assert!(
            e <= check::TOLERANCE,
            "receiver {i} at {x} normal {nn}: cpu {:?} gpu {:?} ({e:e})",
            c[i],
            g[i]
        );
        worst = worst.max(e);
    }
    let report = check::check_with(
        gpu,
        std::slice::from_ref(&reference),
        check::Samples {
            emission: 64,
            intensity: 0,
            radiance: 256,
            irradiance: 256,
        },
        3,
    )
    .unwrap();
    assert!(report.host_only.is_empty(), "{:?}", report.host_only);
    assert!(report.rows.iter().all(|r| r.pass), "{:?}", report.rows);
    assert!(
        report
            .rows
            .iter()
            .any(|r| format!("{:?}", r.query) == "Irradiance" && r.samples == 256)
    );
    (excluded, lit, worst)
}
