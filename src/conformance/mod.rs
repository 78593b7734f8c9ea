//! CPU-vs-GPU conformance: randomised samples per light, the GPU result compared with the f64
//! reference, and the largest errors reported. Used by `luxeval check` and by the conformance
//! test suite (DESIGN.md §5).
//!
//! Error measure: for each sample, `‖gpu − cpu‖∞ / ‖cpu‖∞` over the RGB channels (0 when both
//! are 0; a sample where exactly one side is 0 has error 1). Tolerance 1e-4.
//!
//! Excluded band: samples near a discontinuity, where an f32 rounding legitimately flips or
//! amplifies the answer, are counted and reported but not compared:
//! - within [`BAND`] rad of a distant light's cone edge, of the one-sided horizon of a rect or
//!   disk, or of a cylinder's axis direction;
//! - within [`CONE_BAND`]·θcone of a ShapingAPI cone edge, hard or soft (see its docs);
//! - for a mesh light's emission, directions within `BAND` rad of edge-on to every front that
//!   could decide it (DESIGN.md §7 M3);
//! - for radiance, a shape's silhouette: the hit point or the closest approach within `BAND` of
//!   the boundary (as a fraction of the shape's size), grazing rays, and ray origins within
//!   `BAND` of the surface; for a masked dome (§8 P2) the same of each portal's rectangle, and
//!   near ties in depth between two portals crossed (`band::portal_margin`);
//! - for intensity, also directions that see a rect or disk nearly edge-on or a cylinder
//!   nearly end-on (the projected area is a vanishing cosine): see [`intensity_margin`];
//! - for irradiance, receivers that see only a sliver of the light (at the receiver's horizon,
//!   at the light's own plane, at a cone edge) or sit on the light: see [`irradiance_margin`].
//!
//! Everything else must be within tolerance.

pub(crate) mod band;

use glam::DVec3;
use rayon::prelude::*;

use crate::cpu::{self, dvec};
use crate::error::Result;
use crate::query::{Accumulate, Evaluator, PreparedScene, Reference};
use crate::synthetic::{Rng, emission_samples, irradiance_samples, radiance_samples};
use band::{emission_margin, intensity_margin, irradiance_margin, radiance_margin, texture_floor};

/// Relative tolerance of GPU (f32) against CPU (f64).
pub const TOLERANCE: f64 = crate::rules::GPU_TOLERANCE;
/// Half-width of the excluded band around discontinuities (radians, or a fraction of the
/// shape's size).
pub const BAND: f64 = 1e-4;

/// Relative half-width of the band around a cone edge, as a fraction of the cone angle.
///
/// f32 angles carry ~1.5e-7·θ of rounding (the direction and the axis are f32), and the cone
/// factor 1 − smoothstep vanishes quadratically at θcone, so its relative error is
/// 2δθ/(θcone − θoff): it exceeds 1e-4 within ~4e-3·θcone of the edge, soft or hard.
pub const CONE_BAND: f64 = 4e-3;

/// The queries `check` compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CheckedQuery {
    Emission,
    Radiance,
    Irradiance,
    Intensity,
}

/// One light's result for one query.
#[derive(Clone, Debug, serde::Serialize)]
pub struct QueryReport {
    pub light: String,
    pub light_type: &'static str,
    pub query: CheckedQuery,
    pub samples: usize,
    /// Samples in the excluded band (not compared).
    pub excluded: usize,
    /// Compared samples where the CPU value is non-zero.
    pub nonzero: usize,
    pub max_rel_error: f64,
    /// The worst compared sample.
    pub worst: Option<WorstSample>,
    pub pass: bool,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct WorstSample {
    pub index: usize,
    /// Direction (emission) or point (radiance, irradiance).
    pub a: [f32; 3],
    /// Direction (radiance) or receiver normal (irradiance).
    pub b: Option<[f32; 3]>,
    pub cpu: [f64; 3],
    pub gpu: [f32; 3],
}

/// The whole comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CheckReport {
    pub device: String,
    pub tolerance: f64,
    pub band: f64,
    pub samples: usize,
    pub excluded: usize,
    pub rows: Vec<QueryReport>,
    /// The lights some or all of whose queries the CPU reference answers on every device
    /// (`GpuPath::Host`, `GpuPath::RadianceOnDevice`, `GpuPath::HostIntensity`: mesh lights;
    /// `GpuPath::HostIrradiance`: large textured rects, bent IES profiles, some textured and masked
    /// domes) or on this one (a latlong dome whose row tables it cannot hold), with what is
    /// not compared and why.
    pub host_only: Vec<(String, String)>,
}

impl CheckReport {
    pub fn pass(&self) -> bool {
        self.rows.iter().all(|r| r.pass)
    }

    pub fn max_rel_error(&self) -> f64 {
        self.rows
            .iter()
            .map(|r| r.max_rel_error)
            .fold(0.0, f64::max)
    }
}

/// Relative error of one sample (see the module docs).
#[cfg(any(test, feature = "testkit"))]
pub fn rel_error(cpu: DVec3, gpu: [f32; 3]) -> f64 {
    rel_error_above(cpu, gpu, 0.0)
}

/// [`rel_error`] relative to at least `floor` (a textured dome's footprint, see
/// [`band::texture_floor`]).
pub fn rel_error_above(cpu: DVec3, gpu: [f32; 3], floor: f64) -> f64 {
    let g = DVec3::new(gpu[0] as f64, gpu[1] as f64, gpu[2] as f64);
    let scale = cpu.abs().max_element().max(floor);
    let diff = (g - cpu).abs().max_element();
    if diff == 0.0 {
        0.0
    } else if scale == 0.0 {
        1.0
    } else {
        (diff / scale).min(1.0)
    }
}

/// Samples per light and query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Samples {
    pub emission: usize,
    pub radiance: usize,
    pub irradiance: usize,
    /// Intensity is checked on the first this many emission directions (it draws none of its
    /// own, so adding it changes no other sample).
    pub intensity: usize,
}

impl Samples {
    /// `n` emission directions (also used for intensity) and radiance rays, and `n/4` (rounded
    /// up) irradiance receivers: each irradiance sample is a quadrature on both sides, ~100× the
    /// cost of the others.
    pub fn per_query(n: usize) -> Self {
        Samples {
            emission: n,
            radiance: n,
            irradiance: n.div_ceil(4),
            intensity: n,
        }
    }
}

/// Compares `eval` (a GPU) with the f64 reference of each light (`lights`, in order) on
/// `samples` emission directions (also used for intensity) and radiance rays and `samples/4`
/// (rounded up) irradiance receivers per light, drawn from `seed`: the comparison `luxeval
/// check` prints. Tolerance [`TOLERANCE`] (relative), samples within [`BAND`] of a
/// discontinuity counted but not compared (DESIGN.md §5).
pub fn check(
    eval: &Evaluator,
    lights: &[Reference],
    samples: usize,
    seed: u64,
) -> Result<CheckReport> {
    check_with(eval, lights, Samples::per_query(samples), seed)
}

/// Compares `eval` with the f64 reference on the given number of samples per light and query
/// (a query with 0 samples is skipped). Each light is packed from exactly the prepared
/// constants the reference evaluates.
pub fn check_with(
    eval: &Evaluator,
    lights: &[Reference],
    counts: Samples,
    seed: u64,
) -> Result<CheckReport> {
    let mut rng = Rng::new(seed);
    let mut rows = Vec::new();
    let mut host_only = Vec::new();
    for r in lights {
        let p = &r.p;
        match p.gpu_path {
            crate::prepare::GpuPath::Host(why) => {
                host_only.push((
                    p.light.path.clone(),
                    format!("{why}, whose every query the CPU reference answers on every device"),
                ));
                continue;
            }
            crate::prepare::GpuPath::RadianceOnDevice(why) => host_only.push((
                p.light.path.clone(),
                format!(
                    "{why}, whose emission, intensity and irradiance the CPU reference answers \
                     on every device (its radiance is compared)"
                ),
            )),
            crate::prepare::GpuPath::HostIntensity(why) => host_only.push((
                p.light.path.clone(),
                format!(
                    "{why}, whose intensity and irradiance the CPU reference answers on every \
                     device (its emission and radiance are compared)"
                ),
            )),
            crate::prepare::GpuPath::HostIntensityOnly(why) => host_only.push((
                p.light.path.clone(),
                format!(
                    "{why}, whose intensity the CPU reference answers on every device (its \
                     emission, radiance and irradiance are compared)"
                ),
            )),
            _ => {}
        }
        let scene = PreparedScene::from_prepared(eval.backend().clone(), vec![p.clone()])?;
        // A texture the GPU holds reduced (over the device's binding limit) differs from the
        // reference by design: there is nothing to check on this device.
        if let Some(w) = scene.device_warnings().first() {
            return Err(crate::error::LuxError::input(
                &p.light.path,
                format!("cannot check on this device: {w}"),
            ));
        }
        // A light whose irradiance the GPU path takes from the reference (on every device, or
        // on this one: a latlong dome whose row tables it cannot hold,
        // gpu::texture_atlas::tables_beyond): nothing to compare, and the report says so.
        let irradiance_on_host = scene.prepared(0).irradiance_on_host();
        if let crate::prepare::GpuPath::HostIrradiance(why) = scene.prepared(0).gpu_path {
            let which = if p.irradiance_on_host() {
                "every"
            } else {
                "this"
            };
            host_only.push((
                p.light.path.clone(),
                format!(
                    "{why}, whose irradiance the CPU reference answers on {which} device (its \
                     emission, intensity and radiance are compared)"
                ),
            ));
        }
        // Emission (not for a light whose emission the host computes).
        let samples = if p.emission_on_host() {
            0
        } else {
            counts.emission
        };
        let dirs = emission_samples(r, samples, &mut rng);
        let got = scene.emission(&dirs, Accumulate::Sum)?;
        rows.push(compare(r, CheckedQuery::Emission, samples, |i| {
            let e = dvec(dirs[i]).normalize();
            (
                cpu::emission::emission(p, e),
                emission_margin(r, e),
                got[i],
                dirs[i],
                None,
                texture_floor(p, e),
            )
        }));
        // Intensity, on the same directions: `L(ω)·A⊥(ω)`, whose discontinuities are the
        // emission's (the one-sided horizon zeroes both), plus the edge-on sliver.
        // Not for a light whose intensity the host computes (mesh lights).
        let ni = if p.on_host() {
            0
        } else {
            counts.intensity.min(dirs.len())
        };
        let got = scene.intensity(&dirs[..ni], Accumulate::Sum)?;
        rows.push(compare(r, CheckedQuery::Intensity, ni, |i| {
            let e = dvec(dirs[i]).normalize();
            (
                cpu::intensity::intensity(p, e),
                intensity_margin(r, e),
                got[i],
                dirs[i],
                None,
                0.0,
            )
        }));
        // Radiance.
        let samples = counts.radiance;
        let (pts, dirs) = radiance_samples(r, samples, &mut rng);
        let got = scene.radiance(&pts, &dirs, Accumulate::Sum)?;
        rows.push(compare(r, CheckedQuery::Radiance, samples, |i| {
            let (x, w) = (dvec(pts[i]), dvec(dirs[i]).normalize());
            (
                cpu::radiance::radiance(p, x, w),
                radiance_margin(r, x, w),
                got[i],
                pts[i],
                Some(dirs[i]),
                texture_floor(p, w),
            )
        }));
        // Irradiance: the CPU values (quadratures) are computed in parallel. Not for the lights
        // whose irradiance the GPU path takes from the CPU reference (textured rects of more
        // than prepare::RECT_TEXELS_ON_DEVICE texels, textured
        // domes but the latlong ones the kernel integrates, bent IES profiles:
        // Prepared::irradiance_on_host), so there is nothing to compare.
        let ni = if irradiance_on_host {
            0
        } else {
            counts.irradiance
        };
        let (pts, nrms) = irradiance_samples(r, ni, &mut rng);
        let got = scene.irradiance(&pts, &nrms, Accumulate::Sum)?;
        let reference: Vec<(DVec3, f64)> = (0..ni)
            .into_par_iter()
            .map(|i| {
                let (x, nn) = (dvec(pts[i]), dvec(nrms[i]));
                (r.irradiance(x, nn), irradiance_margin(r, x, nn))
            })
            .collect();
        rows.push(compare(r, CheckedQuery::Irradiance, ni, |i| {
            (
                reference[i].0,
                reference[i].1,
                got[i],
                pts[i],
                Some(nrms[i]),
                irradiance_floor(p, dvec(pts[i])),
            )
        }));
    }
    rows.retain(|r| r.samples > 0);
    Ok(CheckReport {
        device: eval.device_name(),
        tolerance: TOLERANCE,
        band: BAND,
        samples: rows.iter().map(|r| r.samples).sum(),
        excluded: rows.iter().map(|r| r.excluded).sum(),
        rows,
        host_only,
    })
}

/// The smallest irradiance a comparison resolves at `x`: [`IRRADIANCE_FLOOR`] of the light's
/// unshaped scale there, `max(base) · Ω` with Ω the solid angle of its bounding sphere seen
/// from x (2π for a dome, a distant light or x inside the sphere). An f32 sum of terms of that
/// scale cannot resolve less: a lit sliver whose reference value is a few 1e-33 of it (an IES
/// profile's range end grazing the light) is 0 on the device, and both are "nothing".
pub fn irradiance_floor(p: &crate::prepare::Prepared, x: DVec3) -> f64 {
    let r = p.bound_radius();
    let d = (x - p.origin).length();
    let omega = if r > 0.0 && d > r {
        let s = r / d;
        2.0 * std::f64::consts::PI * (1.0 - (1.0 - s * s).sqrt())
    } else {
        2.0 * std::f64::consts::PI
    };
    IRRADIANCE_FLOOR * p.base.abs().max_element() * omega
}

/// See [`irradiance_floor`]: 1e-10, three orders of magnitude below f32's resolution of such a
/// sum (~1e-7) and six below the tolerance.
pub const IRRADIANCE_FLOOR: f64 = 1e-10;

/// (CPU value, margin, GPU value, input a, input b, error floor).
type SampleEval = (DVec3, f64, [f32; 3], [f32; 3], Option<[f32; 3]>, f64);

fn compare(
    r: &Reference,
    query: CheckedQuery,
    n: usize,
    f: impl Fn(usize) -> SampleEval,
) -> QueryReport {
    let mut report = QueryReport {
        light: r.light().path.clone(),
        light_type: r.light().kind.usd_type(),
        query,
        samples: n,
        excluded: 0,
        nonzero: 0,
        max_rel_error: 0.0,
        worst: None,
        pass: true,
    };
    for i in 0..n {
        let (cpu, margin, gpu, a, b, floor) = f(i);
        if margin < BAND {
            report.excluded += 1;
            continue;
        }
        if cpu != DVec3::ZERO {
            report.nonzero += 1;
        }
        let err = rel_error_above(cpu, gpu, floor);
        if err > report.max_rel_error || report.worst.is_none() {
            report.max_rel_error = report.max_rel_error.max(err);
            report.worst = Some(WorstSample {
                index: i,
                a,
                b,
                cpu: cpu.to_array(),
                gpu,
            });
        }
    }
    report.pass = report.max_rel_error <= TOLERANCE;
    report
}
