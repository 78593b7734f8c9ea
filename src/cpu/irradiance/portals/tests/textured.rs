//! The device's sum for a textured latlong dome (`super::super::polygon_texture` in place of
//! Lambert's formula) against the visible pieces.

use super::*;
use crate::cpu::irradiance::latlong_rows::Rows;

/// `masked(portals)` with the latlong texture `img` under the dome frame `frame`.
fn masked_textured(
    portals: Vec<Portal>,
    img: &crate::prepare::texture::Image,
    filter: crate::prepare::texture::Filter,
    frame: glam::DMat3,
) -> Prepared {
    use crate::prepare::KindData;
    use crate::prepare::texture::{DomeFormat, DomeFrame, PreparedTexture};
    let dome = portals.into_iter().fold(
        Light::dome()
            .with_intensity(1.5)
            .with_color(DVec3::new(1.0, 0.6, 0.3))
            .with_transform(DMat4::from_mat3(frame)),
        |l, q| l.with_portal(q),
    );
    let mut p = Prepared::new(&dome, TemperatureMode::Spec).unwrap();
    p.kind = KindData::Dome {
        texture: Some(PreparedTexture {
            image: std::sync::Arc::new(img.clone()),
            format: DomeFormat::LatLong,
            frame: DomeFrame::new(frame, glam::DMat3::IDENTITY).unwrap(),
            filter,
            irradiance: Default::default(),
        }),
    };
    p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
        .unwrap();
    p
}

/// A textured latlong dome's sum (the texture's row integral over each portal and overlap,
/// `polygon_texture`) is the visible pieces' irradiance (`cpu::portal::irradiance`: the exact
/// texel integral clipped at each piece's edge planes, nearest portal first) within 1e-10
/// relative (measured 2.5e-12), for window rooms and stacks of overlapping panes (of one
/// multiplier, or each its own and crossed in either order: split overlaps), both filters, under the
/// identity and a turned, scaled frame (conformal), receivers of every orientation.
#[test]
fn textured_sum_is_the_visible_pieces() {
    use crate::cpu::irradiance::dome::latlong::tests::image;
    use crate::prepare::GpuPath;
    use crate::prepare::latlong_rows::tables;
    use crate::prepare::texture::Filter;
    let mut rng = Rng::new(0x7E47);
    let mut crossed = Rng::new(0xC2055);
    let img = image(16, 8, 99, false);
    let turned = glam::DMat3::from_quat(DQuat::from_axis_angle(
        DVec3::new(1.0, 2.0, 3.0).normalize(),
        0.7,
    )) * 2.0;
    let mut worst: f64 = 0.0;
    let (mut lit, mut sets, mut overlapping, mut split) = (0, 0, 0, 0);
    for filter in [Filter::Bilinear, Filter::Nearest] {
        let mut data = Vec::new();
        tables(&img, filter, |v| v, &mut data);
        for frame in [glam::DMat3::IDENTITY, turned] {
            for case in 0..24 {
                // The crossed cases draw apart, so that the others keep their draw.
                let rng = if case < 16 { &mut rng } else { &mut crossed };
                let ps = if case >= 16 {
                    // Each its own multiplier, tilted so that pairs cross in either order.
                    (0..3)
                        .map(|_| {
                            random_pane(rng, 0.8, 1.6, 1.0, 0.0).with_intensity(rng.range(0.5, 3.0))
                        })
                        .collect()
                } else if case % 2 == 0 {
                    window_room(rng, 4, 2.0)
                } else {
                    (0..2 + rng.below(2))
                        .map(|_| random_pane(rng, 0.5, 3.0, 0.5, 0.15))
                        .collect()
                };
                let p = masked_textured(ps, &img, filter, frame);
                if p.gpu_path != GpuPath::Device {
                    continue;
                }
                sets += 1;
                overlapping += usize::from(!p.portal_overlaps.is_empty());
                split += usize::from(p.portal_overlaps.iter().any(|s| s.split.is_some()));
                let portals = p.portals.as_ref().unwrap();
                let dome = TexturedDome {
                    rows: Rows {
                        data: &data,
                        width: img.width,
                        height: img.height,
                        bilinear: filter == Filter::Bilinear,
                    },
                    inv: p.dome_texture().unwrap().frame.inv,
                };
                for _ in 0..12 {
                    let x = if case % 2 == 0 && case < 16 {
                        in_cube(rng, 2.5)
                    } else {
                        DVec3::new(
                            rng.range(-3.0, 3.0),
                            rng.range(-3.0, 3.0),
                            rng.range(-2.0, 4.0),
                        )
                    };
                    let n = rng.unit();
                    let want = crate::cpu::portal::irradiance(&p, portals, x, n);
                    let got =
                        p.base * portals_irradiance(portals, &p.portal_overlaps, x, n, Some(&dome));
                    let scale = want.abs().max_element().max(1e-6 * p.base.max_element());
                    if want.max_element() > 0.0 {
                        lit += 1;
                    }
                    let e = (got - want).abs().max_element() / scale;
                    assert!(
                        e < 1e-10,
                        "{filter:?} x={x} n={n}: {got} vs {want} ({e:.2e})"
                    );
                    worst = worst.max(e);
                }
            }
        }
    }
    eprintln!(
        "{sets} sets ({overlapping} with overlaps, {split} split), {lit} lit receivers, \
         worst relative difference {worst:e}"
    );
    assert!(
        sets >= 50 && overlapping >= 15 && split >= 10 && lit > 200,
        "{sets} sets, {overlapping} overlapping, {split} split, {lit} lit"
    );
}
