//! Light sampling on a prepared scene (DESIGN.md §9 S1, S4): `sample` draws directions toward
//! the lights with their densities, `pdf` gives the density of any direction. Both run on the
//! f64 CPU reference (`cpu::sample`) on every device: the WGSL samplers are not written yet, so
//! on a GPU evaluator these queries are the host's (said by [`PreparedScene::sampling_device`]).

use glam::DVec3;
use rayon::prelude::*;

use super::{Accumulate, PreparedScene, check_directions, check_pairs, check_points};
use crate::cpu::dvec;
use crate::cpu::sample::{
    LightAt, SceneTables, choose, rng, scene_pdf, selection_weights, strategy,
};
use crate::error::{LuxError, Result};

pub use crate::cpu::sample::Selection;

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

impl PreparedScene {
    /// Where sampling runs: always the CPU reference for now (`"cpu"`); a GPU evaluator says
    /// so in its warnings (the CLI prints it).
    pub fn sampling_device(&self) -> &'static str {
        "cpu"
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
        let tables = SceneTables::new(&self.lights, opts.selection);
        let rows: Vec<Vec<(DVec3, f64, DVec3, f64, i32)>> = points
            .par_iter()
            .enumerate()
            .map(|(i, &pt)| {
                let x = dvec(pt);
                let n = normals.map(|ns| dvec(ns[i]).normalize());
                let key = (opts.first_point + i as u64) as u32;
                let mut weights = Vec::new();
                selection_weights(
                    &self.lights,
                    &tables,
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
                        // bits) and 4 an environment map's texel.
                        let u = |d: u32| rng::uniform(opts.seed, key, j as u32, d);
                        let Some((k, pk)) = choose(&weights, total, u(2)) else {
                            return (n.unwrap_or(DVec3::Y), 0.0, DVec3::ZERO, 0.0, -1);
                        };
                        let p = &self.lights[k];
                        let at = *cache[k]
                            .get_or_insert_with(|| LightAt::new(p, tables.env[k].as_ref(), x, n));
                        let s = at.sample(
                            p,
                            x,
                            [
                                u(0),
                                u(1),
                                rng::uniform53(opts.seed, key, j as u32, 3),
                                u(4),
                            ],
                        );
                        (s.dir, pk * s.pdf, s.radiance, pk, k as i32)
                    })
                    .collect()
            })
            .collect();
        let mut out = Samples {
            count,
            ..Samples::default()
        };
        for (dir, pdf, l, pk, k) in rows.into_iter().flatten() {
            out.dirs.push(dir.as_vec3().to_array());
            out.pdf.push(pdf as f32);
            out.radiance.push(l.as_vec3().to_array());
            out.light_pdf.push(pk as f32);
            out.light.push(k);
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
        let tables = SceneTables::new(&self.lights, selection);
        let l = self.lights.len();
        let rows: Vec<Vec<f64>> = points
            .par_iter()
            .enumerate()
            .map(|(i, &pt)| {
                let x = dvec(pt);
                let n = normals.map(|ns| dvec(ns[i]).normalize());
                let w = dvec(dirs[i]).normalize();
                let mut weights = Vec::new();
                selection_weights(
                    &self.lights,
                    &tables,
                    x,
                    n,
                    selection,
                    &self.rule,
                    &mut weights,
                );
                let mut per = vec![0.0; l + 1];
                let sum = scene_pdf(&self.lights, &tables, &weights, x, n, w, &mut per[..l]);
                per[l] = sum;
                per
            })
            .collect();
        Ok(match acc {
            Accumulate::Sum => rows.iter().map(|r| r[l] as f32).collect(),
            Accumulate::PerLight => (0..l)
                .flat_map(|k| rows.iter().map(move |r| r[k] as f32))
                .collect(),
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
        Ok(())
    }
}
