//! Exact irradiance of a textured rect (DESIGN.md §6 "RectLight texture" and "Dome and texture
//! irradiance: what 'exact' means"), f64, CPU only: the GPU path takes it from here
//! (`prepare::Prepared::irradiance_on_host`), so this module has no WGSL twin.
//!
//! The rect's plane chart (`chart::plane_chart`) is `X = x/hx`, `Y = y/hy` ∈ [−1, 1] in the
//! light's local coordinates, so by §6's `s = 0.5 − x/w`, `t = 0.5 − y/h` the texture at chart
//! point (X, Y) is `tex((1 − X)/2, (1 − Y)/2)`. The irradiance is the chart integral of
//! `cpu::irradiance` with the texture as one more factor of the integrand,
//! `E = L ∫∫ S(−ŵ) · tex(X, Y) · max(0, n·w) · J/|w|⁴ dX dY`, i.e. the integral of the filtered
//! texture over the surface (with L's shaping, cosines and the receiver's horizon), not a sum of
//! texel solid angles. The reconstruction is a polynomial on each cell between texel-centre
//! lines (bilinear: its kinks, with the clamped half-texel borders constant) or texel edges
//! (nearest: its jumps), so the quadrature splits there:
//! - along each line Y = const at the X of every such vertical line ([`ChartTexture::xs`],
//!   breakpoints of `line::line_integral`);
//! - across lines at every such horizontal line ([`texel_ys`]), and where the vertical lines
//!   meet the receiver's horizon, the focus plane and the kink cones, and come nearest to x (the
//!   vertical lines join the square's sides as straight edges in `critical::critical_ys`).
//!
//! Each smooth piece is integrated by the reference's adaptive Gauss–Kronrod rule to its
//! tolerance (`Adaptive::REFERENCE`, ~1e-9 relative), as for an untextured shaped rect. This
//! costs ~225 kernel evaluations per texel per receiver (~50 s for 2048 × 1024); at tolerances
//! from 1e-4 on, `rect_fast` computes the same integral from moments of the texture instead.

use glam::{DVec2, DVec3};

use super::chart::{Chart, Region};
use crate::cpu::texture::sample_rect;
use crate::prepare::Prepared;
use crate::prepare::texture::{Filter, Image, axis_pieces};

/// A textured rect's texture as the chart quadrature reads it.
pub struct ChartTexture<'a> {
    img: &'a Image,
    filter: Filter,
    /// Chart X of the vertical lines where the reconstruction is not smooth, inside (−1, 1).
    pub xs: Vec<f64>,
}

impl ChartTexture<'_> {
    /// The filtered texture at chart point (X, Y).
    pub fn value(&self, x: f64, y: f64) -> DVec3 {
        sample_rect(
            self.img,
            DVec2::new(0.5 * (1.0 - x), 0.5 * (1.0 - y)),
            self.filter,
        )
    }
}

/// The texture of `p` when it is a textured rect integrated over its square chart.
pub fn chart_texture<'a>(p: &'a Prepared, chart: &Chart) -> Option<ChartTexture<'a>> {
    let t = p.rect_texture()?;
    if !matches!(chart.region, Region::Square) {
        return None;
    }
    let xs = breaks(t.image.width, t.filter())
        .into_iter()
        .map(|s| 1.0 - 2.0 * s)
        .collect();
    Some(ChartTexture {
        img: &t.image,
        filter: t.filter(),
        xs,
    })
}

/// Where the reconstruction of an axis of `n` texels is not smooth, as fractions of the axis
/// in (0, 1): the ends of `prepare::texture::axis_pieces` (clamped, so no wrap), interior only.
fn breaks(n: usize, filter: Filter) -> Vec<f64> {
    let nf = n as f64;
    let mut v: Vec<f64> = axis_pieces(n as u32, false, filter)
        .iter()
        .map(|piece| piece.x0 / nf)
        .filter(|&s| s > 0.0 && s < 1.0)
        .collect();
    v.dedup();
    v
}

/// The chart X of the texture's vertical break lines (textured rect on its square chart;
/// empty otherwise): `critical::critical_ys` treats them as straight edges X = const.
pub fn texel_xs(p: &Prepared, chart: &Chart) -> Vec<f64> {
    chart_texture(p, chart).map(|t| t.xs).unwrap_or_default()
}

/// The chart Y of the texture's horizontal break lines (textured rect on its square chart;
/// empty otherwise).
pub fn texel_ys(p: &Prepared, chart: &Chart) -> Vec<f64> {
    match (p.rect_texture(), &chart.region) {
        (Some(t), Region::Square) => breaks(t.image.height, t.filter())
            .into_iter()
            .map(|t| 1.0 - 2.0 * t)
            .collect(),
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{DMat3, DMat4, DQuat};

    use super::*;
    use crate::cpu::emission::emission;
    use crate::cpu::intensity::intensity;
    use crate::cpu::irradiance::irradiance;
    use crate::cpu::radiance::radiance;
    use crate::cpu::shaping::shaping;
    use crate::model::{Light, LightType, Shaping};
    use crate::prepare::TemperatureMode;
    use crate::prepare::texture::RectTexture;
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

    const FILTERS: [Filter; 2] = [Filter::Bilinear, Filter::Nearest];

    /// A sheared, non-uniformly scaled, rotated and translated transform.
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

    /// DESIGN.md §6 "RectLight texture": pixel (0, 0) at the light's (+X, +Y) corner, columns
    /// toward −X, rows toward −Y. A 2 × 3 texture of distinct colours, seen from the emitting
    /// side near each corner and in the middle of each texel row, under the identity and a
    /// rotation with translation, in both filters.
    #[test]
    fn each_corner_shows_the_pixel_design_md_pins_there() {
        let colours: Vec<[f32; 3]> = vec![
            [1.0, 0.0, 0.0], // (0, 0): +X, +Y
            [0.0, 1.0, 0.0], // (1, 0): −X, +Y
            [0.0, 0.0, 1.0], // (0, 1)
            [1.0, 1.0, 0.0], // (1, 1)
            [0.0, 1.0, 1.0], // (0, 2): +X, −Y
            [1.0, 0.0, 1.0], // (1, 2): −X, −Y
        ];
        // (local corner signs, pixel)
        let corners = [
            ((1.0, 1.0), 0),
            ((-1.0, 1.0), 1),
            ((1.0, -1.0), 4),
            ((-1.0, -1.0), 5),
            ((1.0, 0.0), 2),
            ((-1.0, 0.0), 3),
        ];
        let (w, h) = (2.0, 3.0);
        for m in [
            DMat4::IDENTITY,
            DMat4::from_rotation_translation(
                DQuat::from_rotation_y(0.7) * DQuat::from_rotation_x(-0.4),
                DVec3::new(1.0, 2.0, -3.0),
            ),
        ] {
            let l = Light::rect(w, h).with_intensity(3.0).with_transform(m);
            for filter in FILTERS {
                let p = textured(&l, 2, 3, colours.clone(), filter);
                for ((sx, sy), pix) in corners {
                    // A point 1 unit in front of the emitting side (local −Z), looking at the
                    // local point (0.95·sx·w/2, 0.95·sy·h/2) along local +Z.
                    let target = DVec3::new(0.95 * sx * w / 2.0, 0.95 * sy * h / 2.0, 0.0);
                    let x = m.transform_point3(target - DVec3::Z);
                    let dir = m.transform_vector3(DVec3::Z).normalize();
                    let got = radiance(&p, x, dir);
                    let want = 3.0 * DVec3::from_array(colours[pix].map(f64::from));
                    assert!(
                        (got - want).abs().max_element() < 1e-12,
                        "{filter:?} corner ({sx}, {sy}): {got} vs pixel {pix} {want}"
                    );
                    // From behind (the non-emitting side) nothing.
                    let behind = m.transform_point3(target + DVec3::Z);
                    assert_eq!(radiance(&p, behind, -dir), DVec3::ZERO);
                }
            }
        }
    }

    /// The bilinear reconstruction clamped at the borders, written here independently of
    /// `cpu::texture::filter_block`: texel centres at (i + ½)/W.
    fn bilinear(rgb: &[[f32; 3]], w: usize, h: usize, s: f64, t: f64) -> DVec3 {
        let tex = |i: f64, j: f64| {
            let i = i.clamp(0.0, (w - 1) as f64) as usize;
            let j = j.clamp(0.0, (h - 1) as f64) as usize;
            DVec3::from_array(rgb[j * w + i].map(f64::from))
        };
        let (x, y) = (s * w as f64 - 0.5, t * h as f64 - 0.5);
        let (i, j) = (x.floor(), y.floor());
        let (fx, fy) = (x - i, y - j);
        (tex(i, j) * (1.0 - fx) + tex(i + 1.0, j) * fx) * (1.0 - fy)
            + (tex(i, j + 1.0) * (1.0 - fx) + tex(i + 1.0, j + 1.0) * fx) * fy
    }

    fn nearest(rgb: &[[f32; 3]], w: usize, h: usize, s: f64, t: f64) -> DVec3 {
        let i = ((s * w as f64).floor() as usize).min(w - 1);
        let j = ((t * h as f64).floor() as usize).min(h - 1);
        DVec3::from_array(rgb[j * w + i].map(f64::from))
    }

    fn reconstruct(rgb: &[[f32; 3]], w: usize, h: usize, s: f64, t: f64, f: Filter) -> DVec3 {
        match f {
            Filter::Bilinear => bilinear(rgb, w, h, s, t),
            Filter::Nearest => nearest(rgb, w, h, s, t),
        }
    }

    /// emission = L ⊙ the area mean of the reconstruction: checked against the plain texel
    /// mean (the closed form: each texel's 1-D weight over a clamped bilinear axis is
    /// ½ + ½ = 1, its clamped half-texel plus its tent's half) and against a midpoint rule of
    /// the reconstruction written above, with 200 samples per texel (exact for a bilinear
    /// function on each cell: the kinks at texel centres fall on the grid's cell boundaries).
    /// intensity = emission × projected area.
    #[test]
    fn emission_is_the_area_mean_of_the_reconstruction() {
        let mut rng = Rng::new(7);
        for (w, h) in [(1, 1), (2, 3), (5, 3), (4, 1)] {
            let rgb = random_rgb(&mut rng, w * h);
            let closed = rgb
                .iter()
                .map(|c| DVec3::from_array(c.map(f64::from)))
                .sum::<DVec3>()
                / (w * h) as f64;
            let l = Light::rect(1.5, 0.5)
                .with_intensity(2.0)
                .with_transform(skewed());
            for filter in FILTERS {
                let p = textured(&l, w, h, rgb.clone(), filter);
                let e = emission(&p, p.normal) / 2.0;
                assert!((e - closed).abs().max_element() < 1e-12, "{e} vs {closed}");
                let (nx, ny) = (200 * w, 200 * h);
                let mut sum = DVec3::ZERO;
                for j in 0..ny {
                    for i in 0..nx {
                        let s = (i as f64 + 0.5) / nx as f64;
                        let t = (j as f64 + 0.5) / ny as f64;
                        sum += reconstruct(&rgb, w, h, s, t, filter);
                    }
                }
                let mid = sum / (nx * ny) as f64;
                assert!((e - mid).abs().max_element() < 1e-12, "{e} vs {mid}");
                // Behind: 0. Intensity: emission × projected area (|det M| w h |(M⁻¹e)_z|).
                assert_eq!(emission(&p, -p.normal), DVec3::ZERO);
                let dir = (p.normal + DVec3::new(0.3, -0.2, 0.1)).normalize();
                let area = p.det * 1.5 * 0.5 * (-(p.to_local * dir).z).max(0.0);
                let i = intensity(&p, dir);
                let want = emission(&p, dir) * area;
                assert!((i - want).abs().max_element() < 1e-12 * want.max_element());
            }
        }
    }

    fn shapes() -> Vec<Option<Shaping>> {
        vec![
            None,
            Some(Shaping {
                focus: 1.5,
                focus_tint: DVec3::new(0.2, 0.5, 1.0),
                cone_angle: 50.0,
                cone_softness: 1.0,
                ies: None,
            }),
        ]
    }

    /// Receivers in front of the light (local −Z side), in local coordinates, with normals; the
    /// second and third see the rect cut by their horizon.
    fn receivers() -> [(DVec3, DVec3); 4] {
        [
            (DVec3::new(0.1, 0.2, -1.0), DVec3::new(0.0, 0.1, 1.0)),
            (DVec3::new(0.3, -0.1, -0.6), DVec3::new(1.0, 0.2, 0.3)),
            (DVec3::new(-0.4, 0.3, -0.4), DVec3::new(-0.3, -1.0, 0.5)),
            (DVec3::new(1.5, 0.9, -2.0), DVec3::new(-0.5, -0.3, 1.0)),
        ]
    }

    fn light(shaping: &Option<Shaping>) -> Light {
        let mut l = Light::rect(1.2, 0.8)
            .with_intensity(2.0)
            .with_transform(skewed());
        if let Some(s) = shaping {
            l = l.with_shaping(s.clone());
        }
        l
    }

    /// World receiver and unit normal from the local ones of [`receivers`] (the normal through
    /// the linear map, then normalised: any unit normal will do).
    fn world(p: &Prepared, x: DVec3, n: DVec3) -> (DVec3, DVec3) {
        (p.origin + p.linear * x, (p.linear * n).normalize())
    }

    /// A uniform white texture multiplies by 1: the textured quadrature (split at every texel
    /// line) gives the untextured irradiance (Lambert's closed form unshaped, the chart
    /// quadrature shaped) to ~1e-9.
    #[test]
    fn a_white_texture_gives_the_untextured_irradiance() {
        for shaping in shapes() {
            let l = light(&shaping);
            let plain = Prepared::new(&l, TemperatureMode::Spec).unwrap();
            for (w, h) in [(1, 1), (3, 2), (7, 5)] {
                for filter in FILTERS {
                    let p = textured(&l, w, h, vec![[1.0; 3]; w * h], filter);
                    for (xl, nl) in receivers() {
                        let (x, n) = world(&p, xl, nl);
                        let a = irradiance(&p, x, n);
                        let b = irradiance(&plain, x, n);
                        let err = (a - b).abs().max_element() / b.abs().max_element();
                        assert!(
                            err < 1e-9,
                            "{w}x{h} {filter:?} shaped={} at {xl}: {a} vs {b} ({err:e})",
                            shaping.is_some()
                        );
                    }
                }
            }
        }
    }

    /// The brute force: a midpoint rule over the rect's local (u, v) with `k` cells per half
    /// texel on each axis (so texel edges and texel-centre lines are cell boundaries), of
    /// `L(e) · tex(u, v) · max(0, n·ω) · max(0, N_a·e) / r²`, with `N_a = |det M| M⁻ᵀ(−Z)` the
    /// area-weighted emitting normal, `ω` from x to the surface point and `e = −ω`. Written here
    /// from DESIGN.md §2, §3 and §6 only (the shaping factor is `cpu::shaping`).
    #[allow(clippy::too_many_arguments)]
    fn brute_force(
        p: &Prepared,
        rgb: &[[f32; 3]],
        tw: usize,
        th: usize,
        x: DVec3,
        n: DVec3,
        f: Filter,
        k: usize,
    ) -> DVec3 {
        let LightType::Rect { width, height } = p.light.kind else {
            unreachable!()
        };
        let na = p.det * (p.to_local.transpose() * DVec3::NEG_Z);
        let (nx, ny) = (2 * k * tw, 2 * k * th);
        let (du, dv) = (width / nx as f64, height / ny as f64);
        let mut sum = DVec3::ZERO;
        for j in 0..ny {
            let v = -height / 2.0 + (j as f64 + 0.5) * dv;
            for i in 0..nx {
                let u = -width / 2.0 + (i as f64 + 0.5) * du;
                let y = p.origin + p.linear * DVec3::new(u, v, 0.0);
                let d = y - x;
                let r2 = d.length_squared();
                let om = d / r2.sqrt();
                let (cr, cl) = (n.dot(om), na.dot(-om));
                if cr <= 0.0 || cl <= 0.0 {
                    continue;
                }
                let tex = reconstruct(rgb, tw, th, 0.5 - u / width, 0.5 - v / height, f);
                sum += p.base * shaping(p, -om) * tex * (cr * cl / r2);
            }
        }
        sum * du * dv * p.light.inputs.diffuse
    }

    /// A random 3 × 2 texture, both filters, shaped and unshaped, under a sheared transform,
    /// against [`brute_force`] at 160 and 320 cells per texel and axis. The midpoint rule's
    /// error is O(h²) on smooth cells and on the cells the horizon crosses (a kink): the finer
    /// result is within about ⅓ of the two results' difference of the exact value (Richardson),
    /// so the reference must lie within that difference of it (plus 1e-9 relative).
    #[test]
    fn a_random_texture_agrees_with_a_brute_force_surface_integral() {
        let mut rng = Rng::new(11);
        let (tw, th) = (3, 2);
        let rgb = random_rgb(&mut rng, tw * th);
        let mut worst = 0.0f64;
        for shaping in shapes() {
            let l = light(&shaping);
            for filter in FILTERS {
                let p = textured(&l, tw, th, rgb.clone(), filter);
                for (xl, nl) in receivers() {
                    let (x, n) = world(&p, xl, nl);
                    let e = irradiance(&p, x, n);
                    let coarse = brute_force(&p, &rgb, tw, th, x, n, filter, 80);
                    let fine = brute_force(&p, &rgb, tw, th, x, n, filter, 160);
                    let scale = fine.abs().max_element();
                    let err = (e - fine).abs().max_element() / scale;
                    let bound = (fine - coarse).abs().max_element() / scale + 1e-9;
                    worst = worst.max(err);
                    println!(
                        "{filter:?} shaped={} at {xl}: reference {e}, brute force {fine}, rel diff {err:.2e}, bound {bound:.2e}",
                        shaping.is_some()
                    );
                    assert!(err <= bound, "{err:e} > {bound:e}");
                    assert!(err < 1e-5, "{err:e}");
                }
            }
        }
        println!("worst relative difference from the brute force: {worst:.2e}");
    }
}
