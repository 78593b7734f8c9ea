//! The dome sampler's proofs (DESIGN.md §9 S1 (i)–(iv)) for every format, filter and frame.

use std::sync::Arc;

use glam::{DMat3, DMat4, DQuat};

use super::*;
use crate::cpu::emission::emission;
use crate::cpu::irradiance::dome::pieces::Geometry;
use crate::cpu::irradiance::dome::quadrature::gauss_legendre;
use crate::model::Light;
use crate::prepare::texture::{
    DomeFrame, Filter, Image, PreparedTexture, face_at_block, st_to_direction,
};
use crate::prepare::{KindData, TemperatureMode};
use crate::synthetic::Rng;

/// The χ² quantile with tail probability p(z) (z the one-sided normal quantile) for k degrees
/// of freedom, by Wilson–Hilferty: `k (1 − 2/9k + z √(2/9k))³` (accurate to < 1 % in the
/// quantile for k ≥ 10 at these tails).
fn chi2_limit(k: f64, z: f64) -> f64 {
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + z * c.sqrt()).powi(3)
}

/// A small non-uniform test image: random colours, a few bright texels (×40), zero texels
/// (a 2-texel run next to a bright one, so that bilinear filtering spreads light into
/// texels that are themselves 0) and one colour of zero luminance, (1, −0.2973, 0).
fn image(w: usize, h: usize, seed: u64) -> Image {
    let mut rng = Rng::new(seed);
    let mut rgb: Vec<[f32; 3]> = (0..w * h)
        .map(|_| {
            if rng.chance(0.2) {
                [0.0; 3]
            } else {
                let k = if rng.chance(0.1) { 40.0 } else { 1.0 };
                [0, 1, 2].map(|_| (k * rng.f64()) as f32)
            }
        })
        .collect();
    // Around the middle (inside every format's domain).
    let (ci, cj) = (w / 2, h / 2);
    rgb[cj * w + ci] = [30.0, 20.0, 10.0];
    rgb[cj * w + ci - 1] = [0.0; 3];
    rgb[(cj - 1) * w + ci] = [0.0; 3];
    rgb[(cj - 1) * w + ci - 1] = [0.0; 3];
    rgb[cj * w + ci + 1] = [1.0, -(0.2126 / 0.7152) as f32, 0.0];
    Image::from_rgb(w, h, rgb, "test.exr").unwrap()
}

/// The non-conformal frame: a rotation × a non-uniform scale (column convention: ω ∝ R S d).
fn skew() -> DMat3 {
    DMat3::from_quat(DQuat::from_axis_angle(
        DVec3::new(1.0, 2.0, 3.0).normalize(),
        0.7,
    )) * DMat3::from_diagonal(DVec3::new(1.4, 0.6, 1.0))
}

fn dome(img: &Image, format: DomeFormat, filter: Filter, m: DMat3) -> Prepared {
    let light = Light::dome()
        .with_intensity(1.5)
        .with_color(DVec3::new(1.0, 0.8, 0.6))
        .with_transform(DMat4::from_mat3(m));
    let mut p = Prepared::new(&light, TemperatureMode::Spec).unwrap();
    p.kind = KindData::Dome {
        texture: Some(PreparedTexture {
            image: Arc::new(img.clone()),
            format,
            frame: DomeFrame::new(m, DMat3::IDENTITY).unwrap(),
            filter,
            irradiance: Default::default(),
        }),
    };
    p
}

/// Every format with its test size, both filters, the identity and the skewed frame; and a
/// non-square angular map.
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
    // A non-square disk image holds the inscribed ellipse (§6 D3).
    v.push((DomeFormat::Angular, 8, 6, Filter::Bilinear, skew()));
    v
}

/// Sub-cells per texel axis of the χ² test (2 × 2 per texel, so that the test also sees
/// where inside a texel the directions go).
const SUB: usize = 2;

/// The sub-cell (half-texel square of the sheet) that dome direction d falls in, by the
/// lookup's forward maps (independent of the sampler's chart code).
fn subcell(format: DomeFormat, w: usize, h: usize, d: DVec3) -> usize {
    let (sw, sh) = (SUB * w, SUB * h);
    let clamp = |v: f64, n: usize| (v.floor().max(0.0) as usize).min(n - 1);
    let (i, j) = match format {
        DomeFormat::Cross => {
            let c = cross_st(d);
            let n = SUB * w / 3;
            (
                c.z as usize * n + clamp(c.x * n as f64, n),
                c.w as usize * n + clamp(c.y * n as f64, n),
            )
        }
        _ => {
            let st = crate::cpu::texture::direction_to_st(format, d);
            let i = if format == DomeFormat::LatLong {
                ((st.x * sw as f64).floor() as i64).rem_euclid(sw as i64) as usize
            } else {
                clamp(st.x * sw as f64, sw)
            };
            (i, clamp(st.y * sh as f64, sh))
        }
    };
    j * sw + i
}

/// `∫ pdf dω` over sub-cell c's footprint, in sheet coordinates (pixels) through the test's
/// own maps: `prepare::texture::st_to_direction` (§6's inverse maps), the irradiance
/// code's `Geometry::dir_jac` (dome solid angle per pixel²) and `DomeFrame::jacobian` (world
/// per dome solid angle). `order`-point Gauss–Legendre rules; for the disk formats the cell
/// ∩ disk is integrated as a outer (in the unit-disk chart), split where the rim crosses
/// the texel's and the cell's b-lines, with `a = a₀ + L(3s² − 2s³)` so that the rim's √
/// behaviour at the pieces' ends becomes smooth, and b inner over the chord ∩ cell.
fn cell_integral(
    p: &Prepared,
    t: &EnvTable,
    rt: Option<&ReceiverTiles>,
    c: usize,
    order: usize,
) -> f64 {
    let tex = p.dome_texture().unwrap();
    let (w, h) = (tex.image.width, tex.image.height);
    let geom = Geometry::new(tex.format, w, h);
    let sw = SUB * w;
    let (ci, cj) = (c % sw, c / sw);
    let (x0, y0) = (ci as f64 / SUB as f64, cj as f64 / SUB as f64);
    let hs = 1.0 / SUB as f64;
    let face = match tex.format {
        DomeFormat::Cross => {
            let n = w / 3;
            match face_at_block(((x0 as usize) / n) as u32, ((y0 as usize) / n) as u32) {
                Some(f) => f,
                None => return 0.0,
            }
        }
        _ => 0,
    };
    // pdf × world Jacobian × dome Jacobian at sheet point (x, y), per pixel².
    let f = |x: f64, y: f64| -> f64 {
        let st = DVec2::new(x / w as f64, y / h as f64);
        let Some(d) = st_to_direction(tex.format, st) else {
            return 0.0;
        };
        let (_, jac) = geom.dir_jac(face, x, y);
        let wd = tex.frame.a_eff * d;
        let l = wd.length();
        pdf_dome(p, Some(t), None, rt, wd / l) * tex.frame.jacobian(d) * jac
    };
    let (xs, ws) = gauss_legendre(order);
    let rule = |a: f64, b: f64, g: &mut dyn FnMut(f64) -> f64| -> f64 {
        let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
        xs.iter()
            .zip(ws)
            .map(|(x, wt)| wt * g(m + r * x))
            .sum::<f64>()
            * r
    };
    if !matches!(tex.format, DomeFormat::MirroredBall | DomeFormat::Angular) {
        return rule(x0, x0 + hs, &mut |x| rule(y0, y0 + hs, &mut |y| f(x, y)));
    }
    // Disk chart: a = 2x/W − 1, b = 1 − 2y/H; dA_pixel = (W/2)(H/2) dA_ab.
    let (ka, kb) = (2.0 / w as f64, 2.0 / h as f64);
    let (a0, a1) = (x0 * ka - 1.0, (x0 + hs) * ka - 1.0);
    let (b0, b1) = (1.0 - (y0 + hs) * kb, 1.0 - y0 * kb);
    // The texel's b-lines too (the sampler's chord within the texel changes form there).
    let (tj0, tj1) = (1.0 - (y0.floor() + 1.0) * kb, 1.0 - y0.floor() * kb);
    let mut cuts = vec![a0, a1];
    for b in [b0, b1, tj0, tj1] {
        if b.abs() < 1.0 {
            let r = (1.0 - b * b).sqrt();
            cuts.extend([-r, r]);
        }
    }
    cuts.extend([-1.0, 1.0]);
    cuts.retain(|v| *v >= a0 && *v <= a1);
    cuts.sort_by(f64::total_cmp);
    let area = 1.0 / (ka * kb);
    let mut sum = 0.0;
    for pair in cuts.windows(2) {
        let (pa, pb) = (pair[0], pair[1]);
        if !(pb > pa) {
            continue;
        }
        let len = pb - pa;
        sum += rule(0.0, 1.0, &mut |s| {
            let a = pa + len * s * s * (3.0 - 2.0 * s);
            let da = 6.0 * len * s * (1.0 - s);
            let hh = (1.0 - a * a).max(0.0).sqrt();
            let (lo, hi) = (b0.max(-hh), b1.min(hh));
            if !(hi > lo) {
                return 0.0;
            }
            da * rule(lo, hi, &mut |b| f((a + 1.0) / ka, (1.0 - b) / kb) * area)
        });
    }
    sum
}

/// S1 (i), (ii), (iii) and the irradiance (iv) of a textured dome, for every format, both
/// filters and both frames, and a non-square angular map (17 configurations):
/// - (i) the sample counts in the sheet's half-texel cells against `∫_cell pdf dω` (χ², cells
///   with an expected count below 5 merged, threshold at p = 5e-8 per configuration, so
///   < 1e-6 for the 17 together); and `pdf_dome` at every drawn direction equals the
///   returned pdf to 1e-9 relative;
/// - (ii) `Σ_cells ∫ pdf dω = 1` to 1e-9: on each cell the integrand is smooth (constant,
///   when pdf is right: pmf × chart density × Jacobians that cancel), and the rim pieces are
///   made smooth by the substitution, so the 12-point rule is exact to rounding; checked by
///   requiring the 12- and 24-point rules to agree to 1e-11 per cell;
/// - (iii) `pdf > 0` wherever `emission ≠ 0`, at 20 000 random world directions;
/// - (iv) the mean of `emission · max(0, n·ω) / pdf` equals `base ⊙ E(n)` (the exact
///   irradiance, `dome::tables`) for three normals, per channel within z = 5.8 sample
///   standard errors (two-sided 6.6e-9 each; 17 × 3 × 3 comparisons: ≈ 1e-6 together).
#[test]
fn textured_dome_pdf_is_the_density_of_the_draws_and_the_estimator_is_unbiased() {
    let n_samples = 200_000;
    let normals = [
        DVec3::new(0.3, 0.9, -0.2).normalize(),
        DVec3::new(-0.6, -0.3, 0.7).normalize(),
        DVec3::new(0.1, -0.95, -0.3).normalize(),
    ];
    for (ci, (format, w, h, filter, m)) in configs().into_iter().enumerate() {
        // The plain table, and its product with a receiver's cosine (tiles of one texel at
        // these sizes).
        let img = image(w, h, 100 + ci as u64);
        let p = dome(&img, format, filter, m);
        let t = EnvTable::new(p.dome_texture().unwrap()).unwrap();
        for product in [None, Some(normals[ci % 3])] {
            let rts = product.and_then(|n| t.receiver_tiles(n));
            let rt = rts.as_ref();
            assert_eq!(rt.is_some(), product.is_some());
            let what = format!(
                "{format:?} {w}×{h} {filter:?} {} {}",
                if m == DMat3::IDENTITY {
                    "identity"
                } else {
                    "skewed"
                },
                if rt.is_some() { "× cosine" } else { "plain" }
            );

            // (ii) and the expected cell probabilities.
            let cells = SUB * SUB * w * h;
            let prob: Vec<f64> = (0..cells)
                .map(|c| {
                    let (a, b) = (
                        cell_integral(&p, &t, rt, c, 12),
                        cell_integral(&p, &t, rt, c, 24),
                    );
                    assert!((a - b).abs() < 1e-11, "{what} cell {c}: {a} vs {b}");
                    b
                })
                .collect();
            let total: f64 = prob.iter().sum();
            assert!((total - 1.0).abs() < 1e-9, "{what}: ∫ pdf = {total}");

            // (iii), on directions of their own.
            let mut rng = Rng::new(2000 + ci as u64);
            let mut seen = 0;
            for _ in 0..20_000 {
                let wd = rng.unit();
                let e = emission(&p, wd);
                if e != DVec3::ZERO {
                    seen += 1;
                    assert!(
                        pdf_dome(&p, Some(&t), None, rt, wd) > 0.0,
                        "{what}: pdf 0 at {wd}, emission {e}"
                    );
                }
            }
            assert!(seen > 10_000, "{what}");
            // And at the centre and near the corners of every texel (where bilinear filtering
            // reaches the neighbours), through the sheet.
            for k in 0..w * h {
                for (fx, fy) in [
                    (0.5, 0.5),
                    (0.02, 0.02),
                    (0.98, 0.02),
                    (0.02, 0.98),
                    (0.98, 0.98),
                ] {
                    let st = DVec2::new(
                        ((k % w) as f64 + fx) / w as f64,
                        ((k / w) as f64 + fy) / h as f64,
                    );
                    let Some(d) = st_to_direction(format, st) else {
                        continue;
                    };
                    let wd = t.frame.to_world(d);
                    let e = emission(&p, wd);
                    let pdf = pdf_dome(&p, Some(&t), None, rt, wd);
                    assert!(
                        e == DVec3::ZERO || pdf > 0.0,
                        "{what}: pdf 0 at texel {k} ({fx}, {fy}), emission {e}"
                    );
                }
            }

            // (i) draws, and (iv) the estimator on the same draws.
            let mut rng = Rng::new(1000 + ci as u64);
            let mut counts = vec![0u64; cells];
            let mut loose = 0usize;
            let mut acc = vec![(DVec3::ZERO, DVec3::ZERO); normals.len()];
            for _ in 0..n_samples {
                let u = [
                    rng.f64(),
                    rng.f64(),
                    rng.f64(),
                    rng.f64(),
                    rng.f64(),
                    rng.f64(),
                ];
                let (wd, pdf) = sample_dome(&p, Some(&t), None, rt, u);
                assert!((wd.length() - 1.0).abs() < 1e-12 && pdf > 0.0 && pdf.is_finite());
                let again = pdf_dome(&p, Some(&t), None, rt, wd);
                assert_eq!(again, pdf, "{what}: at {wd}");
                // The draw's own texel and chart point (replayed from the same u) give the same
                // density up to the pdf's conditioning near its 1/sin θ points (see
                // sample_dome): a texel mismatch between the draw and the lookup would show as
                // an O(1) difference.
                let k = pick_texel(&t, rt, &u);
                let q = t.texel_point(k, u[0], u[1]);
                let d = t.chart_direction(k, q);
                let l = (t.frame.a_eff * d).length();
                let own = density(&t, rt, k, q, d) * l * l * l / t.frame.det_abs;
                let rel = (own / pdf - 1.0).abs();
                assert!(
                    rel < 1e-4,
                    "{what}: draw's density {own} vs pdf {pdf} at {wd}"
                );
                if rel > 1e-9 {
                    loose += 1;
                }
                counts[subcell(format, w, h, t.frame.to_dome(wd))] += 1;
                let e = emission(&p, wd);
                for (k, n) in normals.iter().enumerate() {
                    let f = e * n.dot(wd).max(0.0) / pdf;
                    acc[k].0 += f;
                    acc[k].1 += f * f;
                }
            }
            assert!(
                loose * 1000 < n_samples,
                "{what}: {loose} draws off by > 1e-9"
            );
            let mut chi2 = 0.0;
            let mut bins = 0usize;
            let (mut pooled_e, mut pooled_o) = (0.0, 0.0);
            for (c, (&pr, &o)) in prob.iter().zip(&counts).enumerate() {
                let e = pr * n_samples as f64;
                if pr == 0.0 {
                    assert_eq!(o, 0, "{what}: {o} draws in cell {c} of probability 0");
                } else if e < 5.0 {
                    pooled_e += e;
                    pooled_o += o as f64;
                } else {
                    chi2 += (o as f64 - e).powi(2) / e;
                    bins += 1;
                }
            }
            if pooled_e > 0.0 {
                chi2 += (pooled_o - pooled_e).powi(2) / pooled_e;
                bins += 1;
            }
            let limit = chi2_limit((bins - 1) as f64, 5.327);
            assert!(chi2 < limit, "{what}: χ² = {chi2} ≥ {limit} ({bins} bins)");

            let tables = crate::cpu::irradiance::dome::tables(&p).unwrap();
            for (k, n) in normals.iter().enumerate() {
                // The product is drawn for one receiver: its estimator is checked there (for
                // another normal it stays unbiased but heavy-tailed, where the floor of its
                // below-horizon texels meets that receiver's light).
                if product.is_some_and(|pn| pn != *n) {
                    continue;
                }
                let exact = p.base * tables.irradiance(*n);
                let mean = acc[k].0 / n_samples as f64;
                let var = acc[k].1 / n_samples as f64 - mean * mean;
                let se = (var / (n_samples - 1) as f64).max(DVec3::ZERO);
                let se = DVec3::new(se.x.sqrt(), se.y.sqrt(), se.z.sqrt());
                let dev = (mean - exact).abs();
                assert!(
                    dev.cmple(5.8 * se + 1e-12 * exact.abs()).all(),
                    "{what} n {n}: mean {mean} vs exact {exact} (se {se})"
                );
            }
        }
    }
}

/// Without a texture: cosine-weighted about n (every draw above the horizon, and the
/// estimator of `base · π` has no variance), uniform without a normal (mean within 5.8
/// standard errors); pdf_dome agrees with each draw; the densities integrate to 1.
#[test]
fn untextured_dome_is_cosine_weighted_with_a_normal_and_uniform_without() {
    let p = Prepared::new(&Light::dome().with_intensity(2.0), TemperatureMode::Spec).unwrap();
    let mut rng = Rng::new(77);
    let m = 100_000;
    for n in [
        DVec3::Z,
        DVec3::NEG_Z,
        DVec3::new(0.3, -0.8, 0.2),
        DVec3::new(1e-9, 0.0, -1.0),
    ] {
        let nn = n.normalize();
        let mut sum_cos = DVec3::ZERO;
        let (mut s, mut s2) = (0.0, 0.0);
        let mut zbins = [0u64; 10];
        for _ in 0..m {
            let u = [rng.f64(), rng.f64(), 0.0, 0.0, 0.0, 0.0];
            let (w, pdf) = sample_dome(&p, None, Some(n), None, u);
            assert!((w.length() - 1.0).abs() < 1e-12 && pdf > 0.0);
            assert_eq!(pdf, pdf_dome(&p, None, Some(n), None, w));
            sum_cos += p.base * nn.dot(w).max(0.0) / pdf;
            // cos θ is distributed as √U: cos² θ uniform.
            zbins[((nn.dot(w).powi(2) * 10.0) as usize).min(9)] += 1;
            let (w, pdf) = sample_dome(&p, None, None, None, u);
            assert_eq!(pdf, pdf_dome(&p, None, None, None, w));
            assert!((w.length() - 1.0).abs() < 1e-12);
            let f = p.base.x * nn.dot(w).max(0.0) / pdf;
            s += f;
            s2 += f * f;
        }
        let mean = sum_cos / m as f64;
        assert!(
            (mean - p.base * PI).abs().max_element() < 1e-9 * p.base.x,
            "{mean}"
        );
        let chi2: f64 = zbins
            .iter()
            .map(|o| (*o as f64 - m as f64 / 10.0).powi(2) / (m as f64 / 10.0))
            .sum();
        assert!(chi2 < chi2_limit(9.0, 5.327), "cos² θ bins χ² = {chi2}");
        let mean = s / m as f64;
        let se = ((s2 / m as f64 - mean * mean) / (m - 1) as f64).sqrt();
        assert!(
            (mean - p.base.x * PI).abs() < 5.8 * se,
            "{mean} vs {}",
            p.base.x * PI
        );
    }
    // ∫ pdf dω over the world sphere = 1: θ and φ Gauss–Legendre, split at the horizon of n = Z.
    let (xs, ws) = gauss_legendre(24);
    let mut cos_total = 0.0;
    let mut uni_total = 0.0;
    for (x, wx) in xs.iter().zip(ws) {
        for (y, wy) in xs.iter().zip(ws) {
            let phi = PI * (1.0 + y);
            for (lo, hi) in [(0.0, PI / 2.0), (PI / 2.0, PI)] {
                let th = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
                let w = DVec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos());
                let jac = th.sin() * 0.5 * (hi - lo) * PI;
                cos_total += wx * wy * jac * pdf_dome(&p, None, Some(DVec3::Z), None, w);
                uni_total += wx * wy * jac * pdf_dome(&p, None, None, None, w);
            }
        }
    }
    assert!(
        (cos_total - 1.0).abs() < 1e-12 && (uni_total - 1.0).abs() < 1e-12,
        "{cos_total} {uni_total}"
    );
}
