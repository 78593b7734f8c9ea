//! GPU (WGSL, f32) vs CPU (f64) light sampling (DESIGN.md §9 S3): for seeded random lights of
//! every analytic type under every transform kind (non-uniform scale and shear included), random
//! receivers with and without normals and a few hundred samples per light, a seed gives the same
//! rows on both paths: the same light and `P(l | x)` (chosen on the host), directions within
//! 1e-4 rad, densities and radiance within 1e-4 relative; and the pdf query of the drawn
//! directions agrees within 1e-4 relative.
//!
//! Excluded rows (counted; at most 2 % of the random lights' rows, 4 % of the IES-shaped and
//! textured lights', and with the pdf query's own exclusions 5 % and 8 %): those whose draw lies near a discontinuity, where an
//! f32 rounding legitimately sends the GPU elsewhere or amplifies the difference:
//! - of the sampler map (`testkit::sample::sampler_margin` < [`MAP_BAND`]): the seam of a sheared
//!   rect's two triangles, the frame flip of a cone whose axis lies near z = 0, the tie between a
//!   spot's cone and a sphere's, a cylinder's silhouette,
//!   and the receiver's height over a rect's or disk's plane or a cylinder's surface (where the
//!   density carries the f32 rounding of that height); a textured dome's texel edge (in the
//!   drawn texel's chart) and, for the disk formats, a draw within [`RIM_BAND`] of the rim
//!   (where the density `1/(L_a·c)` carries the f32 chart point's error relative to the
//!   chord);
//! - of the radiance along the CPU's direction (not for delta lights, whose L is no radiance):
//!   `check::radiance_margin` < [`RADIANCE_BAND`] (the radiance conformance's own band: a
//!   shape's silhouette, a cone edge, a one-sided horizon, the IES band), a textured rect's edge
//!   within [`RECT_EDGE`] (tests/rect_conformance.rs's band), and rows where the reference's own
//!   radiance along the GPU's direction differs from that along the CPU's by more than half the
//!   tolerance (the radiance is too steep there for two directions ~1e-6 rad apart);
//! - of the density, for the pdf query only: rows where the reference's pdf query along the
//!   direction turned by [`PERTURB`] rad (two ways; the GPU's effective direction error: the
//!   f32 direction, the world → local map and the receiver's local position) moves by more than
//!   half the tolerance. A disk's or cylinder's density follows the hit point, `∝ d²/cos θ_l`,
//!   which is steep toward the silhouette (for a cylinder 20 radii away, 1e-4 per 3e-7 rad over
//!   the outer tenth of the visible band).
//!
//! A textured dome's radiance is compared against the largest texel its lookup blends (the
//! radiance conformance's floor, `check::texture_floor`).

use crate::common;

use glam::DVec3;
use luxeval::testkit::check::radiance_margin;
use luxeval::testkit::ies::{SHAPES, with_random_ies};
use luxeval::testkit::rect::near_rect_discontinuity;
use luxeval::testkit::sample::{angle, radiance_floor, rim_margin, sampler_margin, uniform};
use luxeval::testkit::{Rng, TRANSFORMS, radiance_samples, random_light, random_lights, transform};
use luxeval::{
    Accumulate, Asset, Evaluator, Light, Reference, SampleOptions, Selection, TemperatureMode,
    Texture, TextureFilter, TextureFormat,
};

const TOL: f64 = 1e-4;
const MAP_BAND: f64 = 1e-4;
const RADIANCE_BAND: f64 = 1e-4;
const RECT_EDGE: f64 = 1e-3;
const PERTURB: f64 = 3e-7;
/// A disk-format dome's draws within this margin of its rim (`testkit::sample::rim_margin`,
/// chart units: the chord through the texel times the rim's `h/|a|`): the density `1/(L_a·c)`
/// carries the f32 chart point's error, up to ~6e-7 chart units here (measured: 1.1e-3 of the
/// density at a margin of 5.5e-4), relative to the margin; 1e-2 keeps that under 6e-5.
const RIM_BAND: f64 = 1e-2;

fn d(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// [`rel`] with the scale at least `floor`.
fn rel_above(a: DVec3, b: DVec3, floor: f64) -> f64 {
    let m = a.abs().max_element().max(b.abs().max_element()).max(floor);
    if m == 0.0 {
        0.0
    } else {
        (a - b).abs().max_element() / m
    }
}

fn rel(a: DVec3, b: DVec3) -> f64 {
    let m = a.abs().max_element().max(b.abs().max_element());
    if m == 0.0 {
        0.0
    } else {
        (a - b).abs().max_element() / m
    }
}

#[derive(Default)]
struct Worst {
    angle: (f64, String),
    pdf: (f64, String),
    radiance: (f64, String),
    query: (f64, String),
}

fn note(slot: &mut (f64, String), err: f64, what: impl FnOnce() -> String) {
    if err > slot.0 || err.is_nan() {
        *slot = (err, what());
    }
}

/// What [`compare`] found over a set of lights.
#[derive(Default)]
struct Stats {
    total: usize,
    delta: usize,
    excluded: usize,
    /// Rows left out of the pdf query's comparison only (its density too steep).
    excluded_query: usize,
    why: std::collections::BTreeMap<(&'static str, bool), usize>,
    worst: Worst,
    failures: Vec<String>,
}

impl Stats {
    fn report(&self, what: &str, secs: f64, max_excluded: f64, max_excluded_query: f64) {
        let frac = self.excluded as f64 / self.total as f64;
        let frac_q = (self.excluded + self.excluded_query) as f64 / self.total as f64;
        println!(
            "{what}: {} rows ({} delta), {} excluded ({:.3} %), {} more from the pdf query \
             ({:.3} % in all), {secs:.1} s",
            self.total,
            self.delta,
            self.excluded,
            100.0 * frac,
            self.excluded_query,
            100.0 * frac_q
        );
        println!(
            "excluded by (type, near the sampler map's seam): {:?}",
            self.why
        );
        let w = &self.worst;
        println!("worst angle {:.3e} rad: {}", w.angle.0, w.angle.1);
        println!("worst pdf {:.3e} rel: {}", w.pdf.0, w.pdf.1);
        println!("worst radiance {:.3e} rel: {}", w.radiance.0, w.radiance.1);
        println!("worst pdf query {:.3e} rel: {}", w.query.0, w.query.1);
        let shown: Vec<&String> = self.failures.iter().take(20).collect();
        assert!(
            self.failures.is_empty(),
            "{what}: {} of {} rows differ:\n{shown:#?}",
            self.failures.len(),
            self.total
        );
        assert!(
            frac <= max_excluded,
            "{what}: excluded {:.2} % > {:.0} %",
            100.0 * frac,
            100.0 * max_excluded
        );
        assert!(
            frac_q <= max_excluded_query,
            "{what}: excluded {:.2} % of the pdf queries > {:.0} %",
            100.0 * frac_q,
            100.0 * max_excluded_query
        );
    }
}

/// Samples each light alone on both paths (`points_per_light` receivers from
/// `radiance_samples`, normals for every other light, `count` samples each) and compares the
/// rows (module docs).
fn compare(
    gpu: &Evaluator,
    lights: &[Light],
    points_per_light: usize,
    count: usize,
    rng: &mut Rng,
) -> Stats {
    let cpu = Evaluator::cpu();
    let seed = 41;
    let mut st = Stats::default();
    for (li, light) in lights.iter().enumerate() {
        let r = Reference::new(light, TemperatureMode::Spec).unwrap();
        let (points, _) = radiance_samples(&r, points_per_light, rng);
        // Half the lights with receiver normals (the cosine-weighted dome and the
        // receiver-aware choice use them), half without.
        let normals: Option<Vec<[f32; 3]>> = (li % 2 == 0).then(|| {
            (0..points.len())
                .map(|_| {
                    let u = rng.unit();
                    [u.x as f32, u.y as f32, u.z as f32]
                })
                .collect()
        });
        let opts = SampleOptions {
            seed,
            selection: Selection::Bound,
            first_point: 0,
        };
        let c = cpu.prepare(std::slice::from_ref(light)).unwrap();
        let g = gpu.prepare(std::slice::from_ref(light)).unwrap();
        assert_eq!(g.sampling_device(), "gpu");
        let sc = c.sample(&points, normals.as_deref(), count, &opts).unwrap();
        let sg = g.sample(&points, normals.as_deref(), count, &opts).unwrap();
        assert_eq!(sc.light, sg.light, "{}: light choice", light.path);
        assert_eq!(sc.light_pdf, sg.light_pdf, "{}: P(l | x)", light.path);
        // The reference's radiance along the GPU's own directions: where it differs from the
        // reference's along the CPU's by more than half the tolerance, the radiance is too
        // steep there (a boundary, a focus toward grazing, a texel edge) for directions 1e-5
        // rad apart.
        let xs: Vec<[f32; 3]> = points
            .iter()
            .flat_map(|p| std::iter::repeat_n(*p, count))
            .collect();
        let along_gpu = c.radiance(&xs, &sg.dirs, Accumulate::Sum).unwrap();
        // The pdf query of the CPU's directions on both paths.
        let ns: Option<Vec<[f32; 3]>> = normals.as_ref().map(|ns| {
            ns.iter()
                .flat_map(|n| std::iter::repeat_n(*n, count))
                .collect()
        });
        let qc = c
            .pdf(
                &xs,
                ns.as_deref(),
                &sc.dirs,
                Selection::Bound,
                Accumulate::Sum,
            )
            .unwrap();
        let qg = g
            .pdf(
                &xs,
                ns.as_deref(),
                &sc.dirs,
                Selection::Bound,
                Accumulate::Sum,
            )
            .unwrap();
        // The reference's pdf along the CPU's directions turned by PERTURB rad two ways: where
        // it moves by more than half the tolerance, the density is too steep there (near a
        // silhouette it grows like 1/cos) to compare two f32 evaluations.
        let turned: Vec<Vec<f32>> = (0..2)
            .map(|k| {
                let dirs: Vec<[f32; 3]> = sc
                    .dirs
                    .iter()
                    .map(|&w| {
                        let w = d(w).normalize();
                        let (a, b) = w.any_orthonormal_pair();
                        let t = (w + PERTURB * if k == 0 { a } else { b }).normalize();
                        [t.x as f32, t.y as f32, t.z as f32]
                    })
                    .collect();
                c.pdf(&xs, ns.as_deref(), &dirs, Selection::Bound, Accumulate::Sum)
                    .unwrap()
            })
            .collect();
        // A textured rect's edge where f32 may straddle it (tests/rect_conformance.rs's band).
        let texel = near_rect_discontinuity(light, &xs, &sc.dirs, false, RECT_EDGE).unwrap();
        for i in 0..points.len() {
            for j in 0..count {
                let row = i * count + j;
                st.total += 1;
                let x = points[i];
                let n = normals.as_ref().map(|ns| ns[i]);
                let u = [
                    uniform(seed, i as u32, j as u32, 0),
                    uniform(seed, i as u32, j as u32, 1),
                ];
                let (dc, dg) = (d(sc.dirs[row]), d(sg.dirs[row]));
                let (pc, pg) = (sc.pdf[row] as f64, sg.pdf[row] as f64);
                let (lc, lg) = (d(sc.radiance[row]), d(sg.radiance[row]));
                let what = || {
                    format!(
                        "{} x {x:?} n {n:?} u {u:?}: dir {dc} vs {dg}, pdf {pc} vs {pg}, L {lc} vs {lg}",
                        light.path
                    )
                };
                if sc.light[row] < 0 {
                    continue;
                }
                let near_map = sampler_margin(&r, x, n, u) < MAP_BAND
                    || rim_margin(&r, sc.dirs[row]) < RIM_BAND;
                let q0 = qc[row] as f64;
                let steep_q = turned.iter().any(|q| {
                    let q = q[row] as f64;
                    let e = (q / q0 - 1.0).abs();
                    q != q0 && (e.is_nan() || e > 0.5 * TOL)
                });
                let steep = pc.is_finite() && rel(lc, d(along_gpu[row])) > 0.5 * TOL;
                // A delta light's L is not a radiance along ω (S1): no band.
                let near_edge = pc > 0.0
                    && pc.is_finite()
                    && (steep || texel[row] || radiance_margin(&r, d(x), dc) < RADIANCE_BAND);
                if near_map || near_edge {
                    st.excluded += 1;
                    *st.why.entry((light.kind.usd_type(), near_map)).or_insert(0) += 1;
                    if std::env::var("SHOW_EXCLUDED").is_ok() {
                        println!(
                            "excluded (map {near_map}, margin {:.2e}, q {q0} {} {}): {}",
                            radiance_margin(&r, d(x), dc),
                            turned[0][row],
                            turned[1][row],
                            what()
                        );
                    }
                    continue;
                }
                if pc.is_infinite() {
                    st.delta += 1;
                }
                let e_angle = if pc > 0.0 { angle(dc, dg) } else { 0.0 };
                let e_pdf = if pc.is_infinite() || pg.is_infinite() {
                    if pc == pg { 0.0 } else { f64::INFINITY }
                } else if pc == 0.0 && pg == 0.0 {
                    0.0
                } else {
                    (pg / pc - 1.0).abs()
                };
                // A textured dome's radiance against the largest texel its lookup blends
                // (the radiance conformance's floor, texture.wgsl's divergence 1).
                let e_l = rel_above(lc, lg, radiance_floor(&r, sc.dirs[row]));
                let (qc, qg) = (qc[row] as f64, qg[row] as f64);
                let e_q = if steep_q {
                    st.excluded_query += 1;
                    0.0
                } else if qc == qg {
                    0.0
                } else {
                    (qg / qc - 1.0).abs()
                };
                if e_angle > TOL || e_pdf > TOL || e_l > TOL || e_q > TOL || e_pdf.is_nan() {
                    st.failures.push(format!(
                        "angle {e_angle:.2e} pdf {e_pdf:.2e} L {e_l:.2e} pdf query {qc} vs {qg}: {}",
                        what()
                    ));
                }
                note(&mut st.worst.query, e_q, what);
                note(&mut st.worst.angle, e_angle, what);
                note(&mut st.worst.pdf, e_pdf, what);
                note(&mut st.worst.radiance, e_l, what);
            }
        }
    }
    st
}

#[test]
fn gpu_samples_match_cpu_on_randomised_lights() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(0x05A3_F1E5);
    let lights = random_lights(&mut rng, 4); // 6 types × 7 transforms × 4 = 168 lights
    let t0 = std::time::Instant::now();
    let st = compare(&gpu, &lights, 32, 16, &mut rng);
    st.report(
        &format!("{} random lights", lights.len()),
        t0.elapsed().as_secs_f64(),
        0.02,
        0.05,
    );
}

/// IES-shaped shapes and textured rects (both sampled by their geometry on the GPU; their
/// radiance reads the IES atlas and the texture atlas).
#[test]
fn gpu_samples_match_cpu_on_ies_shaped_and_textured_lights() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(0x1E5_7E47);
    let mut lights = Vec::new();
    for (k, xf) in TRANSFORMS.into_iter().enumerate() {
        for ty in 1..5 {
            let l = random_light(ty, xf, &mut rng, lights.len());
            lights.push(with_random_ies(l, &mut rng, (k + ty) % SHAPES.len(), true));
        }
        let l = random_light(3, xf, &mut rng, lights.len());
        lights.push(l.with_texture(Texture::new(png(7 + k as u32, 5, &mut rng))));
    }
    let t0 = std::time::Instant::now();
    let st = compare(&gpu, &lights, 24, 12, &mut rng);
    st.report(
        &format!("{} IES-shaped and textured lights", lights.len()),
        t0.elapsed().as_secs_f64(),
        // The IES band (check::radiance_margin's ies_margin, the profile's jumps and zeros)
        // and the texels' steep bilinear slopes leave out more rows here.
        0.04,
        0.08,
    );
}

use luxeval::testkit::dome::random_png as png;

/// Textured domes on the device (DESIGN.md §9 S3): every format (latlong, cross, angular,
/// mirroredBall) and both filters, under the identity, a rotation, a uniform and a non-uniform
/// scale (the density carries the frame's Jacobian), with receiver normals for every other
/// dome (the product with the cosine by tiles) and without: the GPU draws the CPU's texels
/// (the 53-bit pick in integer arithmetic) and rows as above, and the pdf query agrees. A
/// quarter of the texels are black, so that the alias tables alias and nearest filtering has
/// texels of weight 0. Excluded rows: draws within [`MAP_BAND`] of their texel's edge
/// (`sampler_margin`), where the f32 lookup may name the neighbour, and the bands above.
#[test]
fn gpu_samples_match_cpu_on_textured_domes() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(99);
    let mut lights = Vec::new();
    for (format, w, h) in [
        (TextureFormat::LatLong, 32, 16),
        (TextureFormat::CubeMapVerticalCross, 24, 32),
        (TextureFormat::Angular, 24, 24),
        (TextureFormat::MirroredBall, 20, 16),
    ] {
        for filter in [TextureFilter::Bilinear, TextureFilter::Nearest] {
            for xf in ["identity", "rotate", "uniform-scale", "nonuniform-scale"] {
                let texture = Texture::new(dome_png(w, h, &mut rng))
                    .with_format(format)
                    .with_filter(filter);
                lights.push(
                    Light::dome()
                        .with_path(format!("/Dome_{format:?}_{filter:?}_{xf}"))
                        .with_intensity(0.5)
                        .with_texture(texture)
                        .with_transform(transform(xf, &mut rng)),
                );
            }
        }
    }
    let t0 = std::time::Instant::now();
    let st = compare(&gpu, &lights, 16, 12, &mut rng);
    st.report(
        &format!("{} textured domes", lights.len()),
        t0.elapsed().as_secs_f64(),
        0.02,
        0.05,
    );
}

/// A PNG of random texels of high contrast, a quarter of them black.
fn dome_png(w: u32, h: u32, rng: &mut Rng) -> Asset {
    let img = image::RgbImage::from_fn(w, h, |_, _| {
        if rng.below(4) == 0 {
            image::Rgb([0, 0, 0])
        } else {
            image::Rgb([0, 1, 2].map(|_| 16 + rng.below(240) as u8))
        }
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    Asset::from_bytes(format!("dome-{w}x{h}.png"), bytes.into_inner())
}

/// A seed gives the same GPU rows whether the points come in one call or in chunks (each keyed
/// by its `first_point`), including point keys whose bits are NaN patterns as f32 (the kernel
/// reads its u32 keys through f32 storage); and the same light choices as the CPU there.
#[test]
fn gpu_samples_do_not_depend_on_chunking() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(7);
    let lights: Vec<_> = random_lights(&mut rng, 1).into_iter().step_by(3).collect();
    let g = gpu.prepare(&lights).unwrap();
    let c = Evaluator::cpu().prepare(&lights).unwrap();
    let points: Vec<[f32; 3]> = (0..40)
        .map(|_| {
            let v = rng.unit() * rng.range(2.0, 6.0);
            [v.x as f32, v.y as f32, v.z as f32]
        })
        .collect();
    let count = 9;
    for first in [0u64, 0xFFC0_0000, 0x7F80_0001] {
        let opts = SampleOptions {
            seed: 3,
            selection: Selection::Bound,
            first_point: first,
        };
        let whole = g.sample(&points, None, count, &opts).unwrap();
        let cpu = c.sample(&points, None, count, &opts).unwrap();
        assert_eq!(whole.light, cpu.light);
        let mut start = 0;
        for len in [1usize, 7, 13, 19] {
            let o = SampleOptions {
                first_point: first + start as u64,
                ..opts
            };
            let part = g
                .sample(&points[start..start + len], None, count, &o)
                .unwrap();
            let rows = start * count..(start + len) * count;
            assert_eq!(
                part.dirs,
                whole.dirs[rows.clone()],
                "first {first} start {start}"
            );
            assert_eq!(part.pdf, whole.pdf[rows.clone()]);
            assert_eq!(part.radiance, whole.radiance[rows.clone()]);
            assert_eq!(part.light, whole.light[rows]);
            start += len;
        }
        assert_eq!(start, points.len());
        // The GPU directions are the CPU's (the keys reached the kernel intact).
        let close = whole
            .dirs
            .iter()
            .zip(&cpu.dirs)
            .zip(&cpu.pdf)
            .filter(|((a, b), p)| **p > 0.0 && angle(d(**a), d(**b)) < 1e-3)
            .count();
        let drawn = cpu.pdf.iter().filter(|p| **p > 0.0).count();
        assert!(
            close as f64 >= 0.97 * drawn as f64,
            "{close} of {drawn} close"
        );
    }
}
