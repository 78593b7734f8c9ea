//! Light sampling on a prepared scene (DESIGN.md §9 S1, S4): `sample` draws directions toward
//! the lights with their densities, `pdf` gives the density of any direction.
//!
//! On a GPU evaluator `sample` chooses each row's light on the host (the CPU's `P(l | x)`, from
//! the generator's dimension 2) and draws the direction, its density `pdf_l` and the radiance
//! with the WGSL samplers (shaders/sample.wgsl, keyed by the same (seed, point, sample) as the
//! CPU). Every light is drawn on the device, textured domes included: their sampling tables
//! (`prepare::env_table::EnvTable`, built on the first sampling call) go to the device with
//! the texture atlas (`gpu::sample::SampleLights`). `pdf` likewise: `P(l | x)` on the host,
//! each light's `pdf_l(ω)` on the device (shaders/sample.wgsl `pdf_main`).

use glam::DVec3;
use rayon::prelude::*;

use super::{Accumulate, Backend, PreparedScene, check_directions, check_pairs, check_points};
use crate::cpu::dvec;
use crate::cpu::sample::{
    LightAt, SceneTables, choose, env_tables, rng, scene_pdf, selection_weights, strategy,
};
use crate::error::{LuxError, Result};
use crate::gpu::sample::{PdfRow, SampleLights, SampleRow};

pub use crate::cpu::sample::Selection;
pub use crate::cpu::sample::report::StrategyVariance;

/// How another renderer's directions and densities at one receiver fare against luxeval's exact
/// irradiance ([`PreparedScene::check_sampler`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SamplerCheck {
    /// Σ over the lights of irradiance / diffuse (luminance): what the mean should be.
    pub exact: f64,
    /// The mean of `Y(L) · max(0, n·ω) / pdf` over the K samples.
    pub mean: f64,
    /// Its standard error (sample standard deviation / √K).
    pub stderr: f64,
    /// `(mean − exact) / stderr` (0 when both agree exactly).
    pub z: f64,
    /// The pdf's consistency (S4): over 8 × 16 cells B of equal solid angle about n, the mean
    /// of `1_B(ω)/pdf(ω)` estimates B's solid angle where the sampler reaches all of B; the
    /// largest z-score of an estimate *above* |B| (a density reported too small, which biases
    /// the estimator; one below |B| may be support the sampler does not cover) among cells
    /// with at least 30 draws.
    pub worst_cell_z: f64,
    /// Samples with a density ≤ 0 or not finite where `f > 0` (the estimator cannot be formed).
    pub bad_pdf: u64,
}

/// Options of [`PreparedScene::sample`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SampleOptions {
    /// The seed of the counter-based generator (DESIGN.md §9 S3).
    pub seed: u32,
    /// How a light is chosen at each receiver.
    pub selection: Selection,
    /// The index of the first point in the whole input: the generator is keyed by
    /// (seed, point index, sample index, dimension), so a chunk of points starting at row
    /// `first_point` draws exactly what the whole input would draw for those rows.
    pub first_point: u64,
}

/// What [`PreparedScene::sample`] returns for N points × K samples, point-major (row `i·K + j`
/// is sample j of point i), as DESIGN.md §9 S4's `.npz` holds it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Samples {
    /// K, the samples per point.
    pub count: usize,
    /// Unit directions from the point toward the chosen light.
    pub dirs: Vec<[f32; 3]>,
    /// `P(l | x) · pdf_l(ω)`, per unit solid angle; `+∞` for a delta light; 0 where no light
    /// reaches the point.
    pub pdf: Vec<f32>,
    /// The chosen light's radiance along the direction (for a delta light, the value whose
    /// product with `max(0, n·ω)` is its irradiance without `diffuse`, S1).
    pub radiance: Vec<[f32; 3]>,
    /// `P(l | x)` of the chosen light (0 where none is chosen).
    pub light_pdf: Vec<f32>,
    /// The chosen light's row index (the order of [`PreparedScene::lights`]), −1 where no light
    /// can reach the point.
    pub light: Vec<i32>,
}

/// One point of [`PreparedScene::pdf`]: `P(l | x) · pdf_l(ω)` per light and their sum (last),
/// and the lights the device evaluates, with their `P(l | x)` and kernel rows.
type PointPdf = (Vec<f64>, Vec<(usize, f64, PdfRow)>);

/// One drawn row of [`PreparedScene::sample`]: ω, `P(l | x) · pdf_l`, L, `P(l | x)`, the light
/// (−1: none), and the kernel's input where the device draws it.
#[derive(Clone, Copy, Debug, Default)]
struct Row {
    dir: DVec3,
    pdf: f64,
    radiance: DVec3,
    pk: f64,
    light: i32,
    gpu: Option<SampleRow>,
}

impl Row {
    fn done(dir: DVec3, pdf: f64, radiance: DVec3, pk: f64, light: i32) -> Row {
        Row {
            dir,
            pdf,
            radiance,
            pk,
            light,
            gpu: None,
        }
    }
}

impl PreparedScene {
    /// Where `sample` draws directions and `pdf` evaluates densities: `"gpu"` on a GPU evaluator
    /// with lights, else `"cpu"` — also on a GPU whose storage binding limit cannot hold the
    /// scene's textures with its textured domes' sampling tables (built by this call if no
    /// sampling call has built them yet).
    pub fn sampling_device(&self) -> &'static str {
        match self.sampling_gpu() {
            Some(_) => "gpu",
            None => "cpu",
        }
    }

    /// The bytes the scene's textures and sampling tables would need on the device where they
    /// exceed its storage binding limit (then sampling runs on the CPU reference); None
    /// elsewhere.
    pub(super) fn sampling_tables_too_large(&self) -> Option<u64> {
        self.sampling_gpu();
        self.sampling_gpu
            .get()
            .and_then(|r| r.as_ref().err().copied())
    }

    /// The device, the scene's lights on it and the sample kernels' records and atlas (textured
    /// domes' sampling tables appended, built on the first call and kept); None on the CPU
    /// reference, and where the textures and tables exceed the device's storage binding limit
    /// (the rows are then the CPU reference's: a textured dome's tables must be whole to be
    /// drawn from).
    #[allow(clippy::type_complexity)]
    pub(super) fn sampling_gpu(
        &self,
    ) -> Option<(
        &crate::gpu::GpuContext,
        &crate::gpu::dispatch::GpuLights,
        &SampleLights,
    )> {
        let (Backend::Gpu(g), Some(lights)) = (&self.backend, &self.gpu) else {
            return None;
        };
        // A mesh light's rows are the CPU reference's (GpuPath::Host): the whole scene is
        // sampled there, so that one light choice and one set of rows serve every light.
        if self.lights.iter().any(|p| p.on_host()) {
            return None;
        }
        let built = self.sampling_gpu.get_or_init(|| {
            let env = self
                .sampling_env
                .get_or_init(|| std::sync::Arc::new(env_tables(&self.lights)));
            g.sample_lights(lights, env)
        });
        built.as_ref().ok().map(|s| (&**g, lights, s))
    }

    /// The strategy light `k` is sampled with, in words (DESIGN.md §9 S2).
    pub fn sampling_strategy(&self, k: usize) -> Option<&'static str> {
        self.lights.get(k).map(strategy)
    }

    /// Draws `count` directions per point toward the scene's lights (DESIGN.md §9 S1): a light
    /// chosen by `opts.selection`, then a direction by that light's strategy. `normals`, where
    /// given, pair up with the points (needed by `Selection::Exact` and used by the cosine-
    /// weighted dome and the receiver-aware choice).
    pub fn sample(
        &self,
        points: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        count: usize,
        opts: &SampleOptions,
    ) -> Result<Samples> {
        self.check_sampling_inputs(points, normals, opts.selection)?;
        if count == 0 {
            return Err(LuxError::input(
                "count",
                "0: draw at least one sample per point",
            ));
        }
        let tables = self.sampling_tables(opts.selection);
        // On a GPU evaluator the device draws every row.
        let gpu = self.sampling_gpu();
        let rows: Vec<Vec<Row>> = points
            .par_iter()
            .enumerate()
            .map(|(i, &pt)| {
                let x = dvec(pt);
                let n = normals.map(|ns| dvec(ns[i]).normalize());
                let key = (opts.first_point + i as u64) as u32;
                let mut weights = Vec::new();
                selection_weights(
                    &self.lights,
                    tables,
                    x,
                    n,
                    opts.selection,
                    &self.rule,
                    &mut weights,
                );
                let total: f64 = weights.iter().sum();
                let mut cache: Vec<Option<LightAt>> = vec![None; self.lights.len()];
                (0..count)
                    .map(|j| {
                        // Dimensions (S3): 0, 1 the point on the light, 2 the light, 3 (53
                        // bits) and 4 an environment map's texel, 5 and 6 (48 bits together)
                        // its tile.
                        let u = |d: u32| rng::uniform(opts.seed, key, j as u32, d);
                        let Some((k, pk)) = choose(&weights, total, u(2)) else {
                            return Row::done(n.unwrap_or(DVec3::Y), 0.0, DVec3::ZERO, 0.0, -1);
                        };
                        if gpu.is_some() {
                            // Drawn on the device below.
                            return Row {
                                pk,
                                light: k as i32,
                                gpu: Some(SampleRow {
                                    point: pt,
                                    normal: n.map_or([0.0; 3], |n| n.as_vec3().to_array()),
                                    light: k as u32,
                                    seed: opts.seed,
                                    point_key: key,
                                    sample_key: j as u32,
                                }),
                                ..Row::default()
                            };
                        }
                        let p = &self.lights[k];
                        let at = cache[k].get_or_insert_with(|| tables.light_at(k, p, x, n));
                        let fine = rng::uniform53(opts.seed, key, j as u32, 3);
                        let s = at.sample(p, x, [u(0), u(1), fine, u(4), u(5), u(6)]);
                        Row::done(s.dir, pk * s.pdf, s.radiance, pk, k as i32)
                    })
                    .collect()
            })
            .collect();
        let mut rows: Vec<Row> = rows.into_iter().flatten().collect();
        if let Some((g, lights, sampling)) = gpu {
            let (index, input): (Vec<usize>, Vec<SampleRow>) = rows
                .iter()
                .enumerate()
                .filter_map(|(r, row)| row.gpu.map(|g| (r, g)))
                .unzip();
            let drawn = g.run_sample(lights, sampling, &input)?;
            for (r, d) in index.into_iter().zip(drawn) {
                let row = &mut rows[r];
                row.dir = DVec3::from_array(d.dir.map(f64::from));
                row.pdf = row.pk * d.pdf as f64;
                row.radiance = DVec3::from_array(d.radiance.map(f64::from));
            }
        }
        let mut out = Samples {
            count,
            ..Samples::default()
        };
        for row in rows {
            out.dirs.push(row.dir.as_vec3().to_array());
            out.pdf.push(row.pdf as f32);
            out.radiance.push(row.radiance.as_vec3().to_array());
            out.light_pdf.push(row.pk as f32);
            out.light.push(row.light);
        }
        Ok(out)
    }

    /// The density `sample` draws each (point, direction) pair's direction with, `Σ_l P(l | x)
    /// · pdf_l(ω)` (delta lights contribute 0); with `Accumulate::PerLight`, one row per light
    /// (light-major, L × M), whose sum is the summed value (DESIGN.md §9 S1).
    pub fn pdf(
        &self,
        points: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        dirs: &[[f32; 3]],
        selection: Selection,
        acc: Accumulate,
    ) -> Result<Vec<f32>> {
        self.check_sampling_inputs(points, normals, selection)?;
        check_pairs(points, "points", dirs, "directions")?;
        let tables = self.sampling_tables(selection);
        let l = self.lights.len();
        let gpu = self.sampling_gpu();
        // Per point: P(l | x) · pdf_l(ω) per light and the sum (row l) on the CPU; on a GPU
        // evaluator the lights' rows left for the device with their P(l | x).
        let mut rows: Vec<PointPdf> = points
            .par_iter()
            .enumerate()
            .map(|(i, &pt)| {
                let x = dvec(pt);
                let n = normals.map(|ns| dvec(ns[i]).normalize());
                let w = dvec(dirs[i]).normalize();
                let mut weights = Vec::new();
                selection_weights(
                    &self.lights,
                    tables,
                    x,
                    n,
                    selection,
                    &self.rule,
                    &mut weights,
                );
                let mut per = vec![0.0; l + 1];
                let mut device = Vec::new();
                if gpu.is_none() {
                    per[l] = scene_pdf(&self.lights, tables, &weights, x, n, w, &mut per[..l]);
                    return (per, device);
                }
                let total: f64 = weights.iter().sum();
                for (k, &wk) in weights.iter().enumerate() {
                    if !(total > 0.0 && wk > 0.0) {
                        continue;
                    }
                    device.push((
                        k,
                        wk / total,
                        PdfRow {
                            point: pt,
                            normal: n.map_or([0.0; 3], |n| n.as_vec3().to_array()),
                            light: k as u32,
                            dir: w.as_vec3().to_array(),
                        },
                    ));
                }
                (per, device)
            })
            .collect();
        if let Some((g, lights, sampling)) = gpu {
            let input: Vec<PdfRow> = rows
                .iter()
                .flat_map(|(_, d)| d.iter().map(|r| r.2))
                .collect();
            let mut values = g.run_pdf(lights, sampling, &input)?.into_iter();
            for (per, device) in &mut rows {
                for &(k, pk, _) in device.iter() {
                    per[k] = pk * values.next().unwrap_or(0.0) as f64;
                }
                per[l] = per[..l].iter().sum();
            }
        }
        Ok(match acc {
            Accumulate::Sum => rows.iter().map(|r| r.0[l] as f32).collect(),
            Accumulate::PerLight => (0..l)
                .flat_map(|k| rows.iter().map(move |r| r.0[k] as f32))
                .collect(),
        })
    }

    /// The sampler report (DESIGN.md §9 S4): for every light and receiver, the relative
    /// variance per sample of luxeval's strategy and of the uniform-area and cosine baselines,
    /// by deterministic cubature; light-major (row `l·N + i`).
    pub fn sampling_report(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
    ) -> Result<Vec<StrategyVariance>> {
        check_pairs(points, "points", normals, "normals")?;
        let tables = self.sampling_tables(Selection::Bound);
        let mut out = Vec::with_capacity(self.lights.len() * points.len());
        for (k, p) in self.lights.iter().enumerate() {
            let rows: Vec<StrategyVariance> = points
                .par_iter()
                .zip(normals)
                .map(|(x, n)| {
                    crate::cpu::sample::report::strategy_variance(
                        p,
                        tables.env[k].as_ref(),
                        dvec(*x),
                        dvec(*n).normalize(),
                    )
                })
                .collect();
            out.extend(rows);
        }
        Ok(out)
    }

    /// Judges another renderer's sampler at N receivers from its K directions per point
    /// (`dirs`, point-major N·K) and the densities it claims for them (`pdfs`, per unit solid
    /// angle): the bias of `f/p` against the exact irradiance of the scene's lights with its
    /// standard error, and the density's consistency over cells (see [`SamplerCheck`]).
    pub fn check_sampler(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        dirs: &[[f32; 3]],
        pdfs: &[f32],
        count: usize,
    ) -> Result<Vec<SamplerCheck>> {
        check_pairs(points, "points", normals, "normals")?;
        check_directions("directions", dirs)?;
        if count == 0 || dirs.len() != points.len() * count || pdfs.len() != dirs.len() {
            return Err(LuxError::input(
                "directions/pdfs",
                format!(
                    "{} points × {count} samples need as many directions and pdfs; got {} and {}",
                    points.len(),
                    dirs.len(),
                    pdfs.len()
                ),
            ));
        }
        let per = crate::cpu::irradiance_batch(&self.lights, points, normals, true, &self.rule);
        let diffuse: Vec<f64> = self.lights.iter().map(|p| p.light.inputs.diffuse).collect();
        let n_points = points.len();
        Ok((0..n_points)
            .into_par_iter()
            .map(|i| {
                let x = dvec(points[i]);
                let n = dvec(normals[i]).normalize();
                let exact: f64 = (0..self.lights.len())
                    .filter(|&l| diffuse[l] > 0.0)
                    .map(|l| crate::cpu::sample::luminance(per[l * n_points + i]) / diffuse[l])
                    .sum();
                let (mut s1, mut s2, mut bad) = (0.0, 0.0, 0u64);
                const NT: usize = 8;
                const NP: usize = 16;
                let mut cell = [[0.0f64; 2]; NT * NP];
                let mut hits = [0u64; NT * NP];
                let (ta, tb) = crate::cpu::sample::cone::basis(n);
                for j in 0..count {
                    let r = i * count + j;
                    let w = dvec(dirs[r]).normalize();
                    let pdf = pdfs[r] as f64;
                    let l: DVec3 = self
                        .lights
                        .iter()
                        .map(|p| crate::cpu::radiance::radiance(p, x, w))
                        .sum();
                    let f = crate::cpu::sample::luminance(l) * n.dot(w).max(0.0);
                    let v = if pdf > 0.0 && pdf.is_finite() {
                        f / pdf
                    } else {
                        if f > 0.0 {
                            bad += 1;
                        }
                        0.0
                    };
                    s1 += v;
                    s2 += v * v;
                    // Cells of equal solid angle: 1 − cos θ about n in NT bands over [0, 2],
                    // azimuth in NP.
                    if pdf > 0.0 && pdf.is_finite() {
                        let t = (1.0 - n.dot(w)).clamp(0.0, 2.0);
                        let mut phi = w.dot(tb).atan2(w.dot(ta));
                        if phi < 0.0 {
                            phi += 2.0 * std::f64::consts::PI;
                        }
                        let c = ((t / 2.0 * NT as f64) as usize).min(NT - 1) * NP
                            + ((phi / (2.0 * std::f64::consts::PI) * NP as f64) as usize)
                                .min(NP - 1);
                        cell[c][0] += 1.0 / pdf;
                        cell[c][1] += 1.0 / (pdf * pdf);
                        hits[c] += 1;
                    }
                }
                let k = count as f64;
                let mean = s1 / k;
                let stderr = ((s2 / k - mean * mean).max(0.0) / k).sqrt();
                let z = if stderr > 0.0 {
                    (mean - exact) / stderr
                } else if (mean - exact).abs() <= 1e-6 * exact.abs() {
                    0.0
                } else {
                    f64::INFINITY.copysign(mean - exact)
                };
                let size = 4.0 * std::f64::consts::PI / (NT * NP) as f64;
                let worst_cell_z = (0..NT * NP)
                    .filter(|&c| hits[c] >= 30)
                    .map(|c| {
                        let m = cell[c][0] / k;
                        let se = ((cell[c][1] / k - m * m).max(0.0) / k).sqrt();
                        if se > 0.0 { (m - size) / se } else { 0.0 }
                    })
                    .fold(0.0, f64::max);
                SamplerCheck {
                    exact,
                    mean,
                    stderr,
                    z,
                    worst_cell_z,
                    bad_pdf: bad,
                }
            })
            .collect())
    }

    /// The sampling tables for `selection`, built on the first call and kept.
    pub(super) fn sampling_tables(&self, selection: Selection) -> &SceneTables {
        let slot = match selection {
            Selection::Power => 0,
            Selection::Bound => 1,
            Selection::Exact => 2,
        };
        self.sampling_tables[slot].get_or_init(|| {
            let env = self
                .sampling_env
                .get_or_init(|| std::sync::Arc::new(env_tables(&self.lights)))
                .clone();
            SceneTables::new(&self.lights, selection, env)
        })
    }

    fn check_sampling_inputs(
        &self,
        points: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        selection: Selection,
    ) -> Result<()> {
        check_points("points", points)?;
        match normals {
            Some(ns) => {
                check_directions("normals", ns)?;
                check_pairs(points, "points", ns, "normals")?;
            }
            None if selection == Selection::Exact => {
                return Err(LuxError::input(
                    "normals",
                    "selection by exact irradiance needs a receiver normal per point",
                ));
            }
            None => {}
        }
        self.check_sampled()
    }

    /// Sampling refuses a dome masked by portals (§8 P2 mask mode; hint mode samples as
    /// without portals): its lights would be drawn with a density that misses where its light
    /// comes from.
    pub(super) fn check_sampled(&self) -> Result<()> {
        match self.lights.iter().find(|p| p.portals.is_some()) {
            Some(p) => Err(LuxError::NotSupported {
                light: p.light.path.clone(),
                query: "sampling".into(),
                reason: "a dome masked by its portals (--portal-mode mask) is evaluated but not \
                         sampled yet; sample with --portal-mode hint or leave it out with --light"
                    .into(),
            }),
            None => Ok(()),
        }
    }

    /// GPU-resident sampling refuses a scene holding a light whose rows the CPU reference draws
    /// (`Prepared::on_host`: mesh lights, through their BVH): the device cannot draw them.
    /// `PreparedScene::sample` samples such a scene on the CPU reference.
    pub(super) fn check_sampled_on_device(&self) -> Result<()> {
        self.check_sampled()?;
        match self.lights.iter().find(|p| p.on_host()) {
            Some(p) => Err(LuxError::NotOnDevice {
                light: p.light.path.clone(),
                query: "sampling".into(),
                reason: "it is a mesh light, whose directions the CPU reference draws (through \
                         its BVH); use PreparedScene::sample, which samples such a scene on the \
                         CPU reference"
                    .into(),
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Accumulate, Backend};
    use super::{SampleOptions, Selection};

    /// The sample and pdf kernels' rows cut into many device chunks (6 rows each, the last
    /// partial) are the rows of one chunk.
    #[test]
    fn many_sample_chunks_equal_one_chunk() {
        let Some(eval) = super::super::test_gpu() else {
            return;
        };
        let Backend::Gpu(ctx) = &eval.backend else {
            unreachable!("a GPU evaluator")
        };
        let scene = eval
            .prepare(&crate::synthetic::synthetic_lights(5))
            .expect("the synthetic lights prepare");
        assert_eq!(scene.sampling_device(), "gpu");
        let points: Vec<[f32; 3]> = (0..37)
            .map(|i| {
                [
                    (i % 7) as f32 - 3.0,
                    (i % 5) as f32 - 2.5,
                    (i % 3) as f32 + 1.5,
                ]
            })
            .collect();
        let opts = SampleOptions {
            seed: 9,
            ..SampleOptions::default()
        };
        let one = scene.sample(&points, None, 11, &opts).unwrap();
        let xs: Vec<[f32; 3]> = points
            .iter()
            .flat_map(|p| std::iter::repeat_n(*p, 11))
            .collect();
        let pdf = |s: &super::PreparedScene| {
            s.pdf(&xs, None, &one.dirs, Selection::Bound, Accumulate::PerLight)
                .unwrap()
        };
        let pdf_one = pdf(&scene);
        // chunk_capacity 16 rows of 12 bytes: 6 rows of the sample kernel's 28 a chunk.
        ctx.cap_chunk_rows(16);
        let many = scene.sample(&points, None, 11, &opts).unwrap();
        let pdf_many = pdf(&scene);
        ctx.cap_chunk_rows(usize::MAX);
        assert_eq!(one, many);
        assert_eq!(pdf_one, pdf_many);
        assert!(pdf_one.iter().any(|&p| p > 0.0));
        assert!(one.pdf.iter().any(|&p| p > 0.0 && p.is_finite()));
    }
}
