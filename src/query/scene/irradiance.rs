//! The irradiance query of a prepared scene: how a GPU evaluator splits the receivers and the
//! lights between its passes (`irradiance_plan`), and the rows the host computes or recomputes
//! beside the kernel's.

use glam::DVec3;
use rayon::prelude::*;

use super::super::{Accumulate, Backend, check_pairs};
use super::{PreparedScene, add_rows};
use crate::cpu;
use crate::cpu::irradiance::{Adaptive, Rule, rect_fast};
use crate::error::Result;
use crate::gpu::Kernel;
use crate::gpu::record::{
    LIGHTS_ALL, LIGHTS_NORMAL_ONLY, LIGHTS_POSITIONAL, LIGHTS_SKIP_TEXTURED_RECTS,
};
use crate::prepare::Prepared;

impl PreparedScene {
    /// irradiance(x, n) for every (point, receiver normal) pair (DESIGN.md §3): the
    /// diffuse-weighted irradiance `diffuse · ∫ radiance(x, ω) max(0, n·ω) dω` on a one-sided
    /// receiver, no occlusion.
    pub fn irradiance(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        acc: Accumulate,
    ) -> Result<Vec<[f32; 3]>> {
        self.irradiance_by(points, normals, acc, &self.rule)
    }

    /// [`PreparedScene::irradiance`] to relative tolerance `rel` for this call, whatever the
    /// evaluator's (see [`Evaluator::with_irradiance_tolerance`](super::super::Evaluator::with_irradiance_tolerance) for what it means and
    /// which values each backend takes).
    pub fn irradiance_with_tolerance(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        acc: Accumulate,
        rel: f64,
    ) -> Result<Vec<[f32; 3]>> {
        super::super::check_tolerance(rel, matches!(self.backend, Backend::Gpu(_)))?;
        self.irradiance_by(points, normals, acc, &Adaptive::for_tolerance(rel))
    }

    fn irradiance_by(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        acc: Accumulate,
        rule: &Adaptive,
    ) -> Result<Vec<[f32; 3]>> {
        check_pairs(points, "points", normals, "normals")?;
        let per_light = acc == Accumulate::PerLight;
        let lights = if per_light { self.lights.len() } else { 1 };
        // The kernel skips the textured rects this call takes on the host (host_takes).
        let skip = match self
            .lights
            .iter()
            .any(|p| host_takes(p, rule) && !p.irradiance_on_host())
        {
            true => LIGHTS_SKIP_TEXTURED_RECTS,
            false => 0,
        };
        let mut out = match self.irradiance_plan(normals, rule) {
            // One kernel row per distinct normal, copied to the rows that share it (the same
            // input bits give the same output bits, so this is the undeduplicated answer):
            // every light the kernel integrates, where all depend on the normal only; else
            // (`split`: a textured dome beside lights that depend on the position) the
            // normal-only ones, the others going over every receiver in a pass of their own,
            // added. Per light, one of the two rows is exactly 0; summed, the sum of the two
            // subsets' f32 sums (another order of additions than one pass).
            Some((distinct, of_row, split)) => {
                let origin = vec![[0.0f32; 3]; distinct.len()];
                let filter = if split {
                    LIGHTS_NORMAL_ONLY
                } else {
                    LIGHTS_ALL
                };
                let by_normal = self.run_filtered(
                    Kernel::Irradiance,
                    &origin,
                    Some(&distinct),
                    per_light,
                    filter | skip,
                    || cpu::irradiance_batch(&self.lights, &origin, &distinct, per_light, rule),
                )?;
                let everywhere = match split {
                    true => Some(self.run_filtered(
                        Kernel::Irradiance,
                        points,
                        Some(normals),
                        per_light,
                        LIGHTS_POSITIONAL | skip,
                        || cpu::irradiance_batch(&self.lights, points, normals, per_light, rule),
                    )?),
                    false => None,
                };
                let (n, m) = (normals.len(), distinct.len());
                (0..lights * n)
                    .map(|r| {
                        let q = by_normal[(r / n) * m + of_row[r % n]];
                        match &everywhere {
                            Some(p) => [p[r][0] + q[0], p[r][1] + q[1], p[r][2] + q[2]],
                            None => q,
                        }
                    })
                    .collect()
            }
            None => self.run_filtered(
                Kernel::Irradiance,
                points,
                Some(normals),
                per_light,
                LIGHTS_ALL | skip,
                || cpu::irradiance_batch(&self.lights, points, normals, per_light, rule),
            )?,
        };
        if matches!(self.backend, Backend::Gpu(_)) {
            self.redo_spent_rows(points, normals, per_light, rule, &mut out);
            self.add_host_irradiance(points, normals, per_light, rule, &mut out);
        }
        Ok(out)
    }

    /// How a GPU evaluator integrates irradiance over `normals`: `None`, every receiver in one
    /// pass; else the distinct normals, each row's index among them, and whether to split.
    /// Without a split: every light the kernel integrates depends on the normal only (domes,
    /// distant lights: `Prepared::irradiance_is_normal_only`; a textured dome's row integral
    /// costs the same for every receiver, and a falloff map of a plane has one normal), so
    /// one pass over the distinct normals. With a split: the kernel integrates a textured dome
    /// beside lights that depend on the position, which go over every receiver in one pass
    /// (`LIGHTS_POSITIONAL`) while the normal-only lights go over the distinct normals in
    /// another (`LIGHTS_NORMAL_ONLY`). `None` on the CPU reference or when every normal
    /// differs. The host's lights are added afterwards at every row (`add_host_irradiance`).
    fn irradiance_plan(
        &self,
        normals: &[[f32; 3]],
        rule: &Adaptive,
    ) -> Option<(Vec<[f32; 3]>, Vec<usize>, bool)> {
        if !matches!(self.backend, Backend::Gpu(_)) || normals.len() < 2 {
            return None;
        }
        let on_device = |p: &&Prepared| !host_takes(p, rule);
        let positional = self
            .lights
            .iter()
            .filter(on_device)
            .any(|p| !p.irradiance_is_normal_only());
        // The split pays only where the normal-only part is costly: a textured dome's row
        // integral (an untextured dome and a distant light are closed forms).
        let textured_dome = self
            .lights
            .iter()
            .filter(on_device)
            .any(|p| p.irradiance_is_normal_only() && p.light.texture.is_some());
        if positional && !textured_dome {
            return None;
        }
        let mut index = std::collections::HashMap::new();
        let mut distinct = Vec::new();
        let of_row: Vec<usize> = normals
            .iter()
            .map(|n| {
                *index.entry(n.map(f32::to_bits)).or_insert_with(|| {
                    distinct.push(*n);
                    distinct.len() - 1
                })
            })
            .collect();
        (distinct.len() < normals.len()).then_some((distinct, of_row, positional))
    }

    /// Rows the irradiance kernel could not finish (NaN: a chart with more outer breakpoints
    /// than the kernel holds, or on llvmpipe a loop cut short by its budget,
    /// `GpuContext::lane_stride`; `irr_cut` in shaders/shared/record.wgsl) are recomputed here
    /// on the CPU reference: with `per_light` that light's row, else the receiver's sum over
    /// the lights the device integrates (the host lights are added after). Finite inputs never
    /// give NaN otherwise (DESIGN.md §5), so a NaN row is exactly such a row.
    fn redo_spent_rows(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        per_light: bool,
        rule: &Adaptive,
        out: &mut [[f32; 3]],
    ) {
        let n = points.len();
        let spent: Vec<usize> = (0..out.len())
            .filter(|&r| out[r].iter().any(|v| v.is_nan()))
            .collect();
        if spent.is_empty() {
            return;
        }
        self.spent_rows
            .fetch_add(spent.len(), std::sync::atomic::Ordering::Relaxed);
        let redo: Vec<(usize, [f32; 3])> = spent
            .par_iter()
            .map(|&r| {
                let (i, lights) = if per_light {
                    (r % n, &self.lights[r / n..r / n + 1])
                } else {
                    (r, &self.lights[..])
                };
                let (x, nn) = (&points[i..i + 1], &normals[i..i + 1]);
                let sum: DVec3 = lights
                    .iter()
                    .filter(|l| !host_takes(l, rule))
                    .map(|l| cpu::irradiance_batch(std::slice::from_ref(l), x, nn, true, rule)[0])
                    .sum();
                (r, sum.as_vec3().to_array())
            })
            .collect();
        for (r, v) in redo {
            out[r] = v;
        }
    }

    /// How many irradiance rows (receivers, or receiver × light with `PerLight`) the device
    /// could not finish and the CPU reference recomputed, over this scene's calls: a chart with
    /// more outer breakpoints than the kernel holds, or on a software GPU (llvmpipe) a
    /// quadrature cut short by its loop budget. Their values are the reference's at the
    /// scene's tolerance, and they cost the CPU's time; 0 on the CPU backend. The command
    /// line reports it after an irradiance query or a falloff map.
    pub fn host_recomputed_rows(&self) -> usize {
        self.spent_rows.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The GPU irradiance kernel gives 0 for the lights [`host_takes`] names (see the header
    /// of shaders/irradiance.wgsl): their irradiance is the CPU reference's, added here.
    fn add_host_irradiance(
        &self,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        per_light: bool,
        rule: &Adaptive,
        out: &mut [[f32; 3]],
    ) {
        for (k, light) in self.lights.iter().enumerate() {
            if !host_takes(light, rule) {
                continue;
            }
            let values =
                cpu::irradiance_batch(std::slice::from_ref(light), points, normals, true, rule);
            add_rows(out, k, per_light, values);
        }
    }
}

/// Whether a host-path call under `rule` takes `p`'s irradiance from the CPU reference: the
/// lights whose irradiance is the host's on every call ([`Prepared::irradiance_on_host`]), and
/// the textured rects the kernel integrates (up to `prepare::RECT_TEXELS_ON_DEVICE` texels)
/// where the CPU's moment path takes them (`rect_fast::applies`, at a tolerance of 1e-4 or
/// looser): its cost per receiver does not grow with the texels, the kernel's split at every
/// texel line does (BENCHMARKS.md "Small textured rects' irradiance on the device"). The
/// GPU-resident call, which has no host step, and calls at the reference's tolerance (where
/// the CPU splits at every texel line too) integrate them on the device. The kernel's
/// `LIGHTS_SKIP_TEXTURED_RECTS` test (FLAG_RECT_TEXTURE without FLAG_IES) is
/// `rect_fast::applies`.
fn host_takes(p: &Prepared, rule: &Adaptive) -> bool {
    p.irradiance_on_host() || (rule.texture_tolerance().is_some() && rect_fast::applies(p))
}

#[cfg(test)]
mod tests {
    use crate::model::{Light, Texture, TextureFormat};
    use crate::query::Accumulate;

    /// A 4 × 2 latlong dome texture (PNG bytes).
    fn textured_dome() -> Light {
        let png = crate::Asset::png(4, 2, |x, y| [40 * x as u8 + 10, 90, 30 * y as u8 + 5]);
        Light::dome().with_texture(Texture::new(png).with_format(TextureFormat::LatLong))
    }

    /// Which scenes integrate irradiance once per distinct normal, and which split the
    /// lights into a pass over every receiver and one over the distinct normals.
    #[test]
    fn irradiance_plan_splits_only_a_textured_dome_from_positional_lights() {
        let Some(eval) = crate::query::test_gpu() else {
            return;
        };
        let repeated = vec![[0.0f32, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]];
        let distinct = vec![[0.0f32, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let sphere = Light::sphere(0.5).with_intensity(3.0);
        let plan = |lights: &[Light], normals: &[[f32; 3]]| {
            eval.prepare(lights)
                .expect("the lights prepare")
                .irradiance_plan(normals, &crate::cpu::irradiance::Adaptive::REFERENCE)
                .map(|(d, of_row, split)| (d.len(), of_row, split))
        };
        // Normal-only lights alone: one pass over the distinct normals.
        assert_eq!(
            plan(&[textured_dome(), Light::distant(0.5)], &repeated),
            Some((2, vec![0, 1, 0], false))
        );
        // A textured dome beside a sphere: split.
        assert_eq!(
            plan(&[sphere.clone(), textured_dome()], &repeated),
            Some((2, vec![0, 1, 0], true))
        );
        // A sphere beside closed forms only (a distant light, an untextured dome): one pass.
        assert_eq!(
            plan(
                &[sphere.clone(), Light::distant(0.5), Light::dome()],
                &repeated
            ),
            None
        );
        // Every normal differs: one pass.
        assert_eq!(plan(&[sphere.clone(), textured_dome()], &distinct), None);
        // The CPU reference never plans.
        let cpu = crate::query::Evaluator::cpu();
        let scene = cpu.prepare(&[sphere, textured_dome()]).unwrap();
        assert!(
            scene
                .irradiance_plan(&repeated, &crate::cpu::irradiance::Adaptive::REFERENCE)
                .is_none()
        );
    }

    /// A textured rect the kernel integrates (up to RECT_TEXELS_ON_DEVICE texels) is the CPU
    /// moment path's in a host-path call at a loose tolerance (`host_takes`): its rows are the
    /// CPU evaluator's at that tolerance, bit for bit, while the sphere beside it stays the
    /// device's; at the reference tolerance the device integrates it (within 1e-4 of the
    /// reference, and not the reference's rows rounded).
    #[test]
    fn textured_rects_take_the_cpu_moment_path_at_loose_tolerances() {
        let Some(eval) = crate::query::test_gpu() else {
            return;
        };
        let png = crate::Asset::png(4, 3, |x, y| [30 * x as u8 + 40, 90, 50 * y as u8 + 20]);
        let lights = [
            Light::rect(2.0, 1.0)
                .with_intensity(3.0)
                .with_texture(Texture::new(png)),
            Light::sphere(0.3).with_intensity(2.0),
        ];
        let points: Vec<[f32; 3]> = (0..12)
            .map(|i| {
                let i = i as f32;
                [0.3 * (i % 4.0) - 0.5, 0.1 * i - 0.4, -1.0 - 0.1 * i]
            })
            .collect();
        let normals = vec![[0.1f32, -0.2, 1.0]; points.len()];
        let n = points.len();
        let gpu = eval.prepare(&lights).unwrap();
        let cpu = crate::query::Evaluator::cpu().prepare(&lights).unwrap();
        let acc = Accumulate::PerLight;
        let loose_gpu = gpu
            .irradiance_with_tolerance(&points, &normals, acc, 1e-4)
            .unwrap();
        let loose_cpu = cpu
            .irradiance_with_tolerance(&points, &normals, acc, 1e-4)
            .unwrap();
        assert_eq!(loose_gpu[..n], loose_cpu[..n], "the rect's rows at 1e-4");
        assert_ne!(loose_gpu[n..], loose_cpu[n..], "the sphere's rows at 1e-4");
        let exact_gpu = gpu.irradiance(&points, &normals, acc).unwrap();
        let exact_cpu = cpu.irradiance(&points, &normals, acc).unwrap();
        assert_ne!(exact_gpu[..n], exact_cpu[..n], "the rect's rows at 1e-9");
        for (g, c) in exact_gpu[..n].iter().zip(&exact_cpu[..n]) {
            for k in 0..3 {
                assert!((g[k] - c[k]).abs() <= 1e-4 * c[k].abs(), "{g:?} vs {c:?}");
            }
        }
        assert!(exact_cpu[..n].iter().all(|c| c[0] > 0.0));
        assert_eq!(gpu.host_recomputed_rows(), 0);
    }

    /// A textured latlong dome's row tables (four times its texture) are built and written by
    /// the scene's first irradiance call, not when it is prepared nor by emission or radiance,
    /// which do not read them; that call's values are the kernel's, within 1e-4 of the
    /// reference.
    #[test]
    fn row_tables_wait_for_the_first_irradiance_call() {
        let Some(eval) = crate::query::test_gpu() else {
            return;
        };
        let scene = eval.prepare(&[textured_dome()]).unwrap();
        let pending = || scene.gpu.as_ref().expect("a GPU scene").rows_pending();
        assert_eq!(pending(), 1);
        let dirs = [[0.0f32, 1.0, 0.0], [0.6, 0.0, -0.8]];
        scene.emission(&dirs, Accumulate::Sum).unwrap();
        scene
            .radiance(&[[0.0; 3]; 2], &dirs, Accumulate::Sum)
            .unwrap();
        assert_eq!(pending(), 1);
        let normals = [[0.0f32, 1.0, 0.0], [0.6, 0.0, -0.8], [0.0, -0.6, 0.8]];
        let points = [[0.0f32; 3]; 3];
        let got = scene
            .irradiance(&points, &normals, Accumulate::Sum)
            .unwrap();
        assert_eq!(pending(), 0);
        let want = crate::query::Evaluator::cpu()
            .prepare(&[textured_dome()])
            .unwrap()
            .irradiance(&points, &normals, Accumulate::Sum)
            .unwrap();
        assert!(got != want, "the reference's rows");
        for (g, w) in got.iter().zip(&want) {
            let scale = w[0].max(w[1]).max(w[2]);
            assert!(
                (0..3).all(|c| (g[c] - w[c]).abs() <= 1e-4 * scale),
                "{g:?} {w:?}"
            );
        }
    }
}
