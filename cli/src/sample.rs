//! `luxeval sample` and `luxeval pdf` (DESIGN.md §9 S4): directions drawn toward a stage's
//! lights with their densities, streamed chunk by chunk into an `.npz`; and the density of
//! given directions into an `.npy`. Both run where `--device` says (the light is chosen on the
//! host; a textured dome's rows are drawn by the CPU reference on every device);
//! `luxeval sampling` (the report and `--check`) runs on the CPU reference.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use luxeval::{Accumulate, PreparedScene, SampleOptions, Selection};

use crate::args::{DeviceArg, SceneArgs};
use crate::exit::{CliResult, Failure};
use crate::io::npy::{self, RowKind};
use crate::io::npz::{Dtype, FlatNpy, NpzWriter};
use crate::{io, open, query};

/// The most samples per point (each point's samples are held together while drawn); more
/// come from more seeds.
pub const MAX_COUNT: usize = 1 << 20;

/// How a light is chosen at each receiver (DESIGN.md §9 S1 "Scene level").
#[derive(Clone, Copy, ValueEnum)]
pub enum SelectionArg {
    /// By power (flux; a dome or distant light by its irradiance on a receiver facing it).
    Power,
    /// By a bound of what each light can deliver at (x, n): luminance × solid angle × the
    /// largest cosine.
    Bound,
    /// By each light's exact irradiance at (x, n) (needs --normals).
    Exact,
}

impl From<SelectionArg> for Selection {
    fn from(s: SelectionArg) -> Selection {
        match s {
            SelectionArg::Power => Selection::Power,
            SelectionArg::Bound => Selection::Bound,
            SelectionArg::Exact => Selection::Exact,
        }
    }
}

#[derive(Args)]
pub struct SampleArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Receiver points, float (N, 3), world space.
    #[arg(long, value_name = "P.npy")]
    pub points: PathBuf,
    /// Receiver normals, float (N, 3), paired with the points (the cosine-weighted dome, the
    /// receiver-aware choice of light).
    #[arg(long, value_name = "N.npy")]
    pub normals: Option<PathBuf>,
    /// Samples per point (at most 2²⁰).
    #[arg(long, default_value_t = 1)]
    pub count: usize,
    /// Seed of the counter-based generator: the same seed draws the same directions on any
    /// chunking.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[arg(long, value_enum, default_value_t = SelectionArg::Bound)]
    pub selection: SelectionArg,
    /// Where to draw: `auto` (default: a hardware GPU when there is one, else the CPU
    /// reference), `gpu`, `cpu`. The light is chosen on the host, and a textured dome's rows
    /// are drawn by the CPU reference on every device.
    #[arg(long, value_enum)]
    pub device: Option<DeviceArg>,
    /// Output .npz: float32 dirs (N, K, 3), pdf (N, K) (inf for a delta light), radiance
    /// (N, K, 3), light_pdf (N, K); int32 light (N, K) (−1 where no light reaches the point).
    #[arg(short, long, value_name = "OUT.npz")]
    pub output: PathBuf,
}

#[derive(Args)]
pub struct PdfArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Points, float (M, 3), world space.
    #[arg(long, value_name = "P.npy")]
    pub points: PathBuf,
    /// Directions from each point, float (M, 3); normalised before use.
    #[arg(long, value_name = "D.npy")]
    pub dirs: PathBuf,
    /// Receiver normals, float (M, 3), as given to `sample`.
    #[arg(long, value_name = "N.npy")]
    pub normals: Option<PathBuf>,
    /// One row per light, (L, M): P(l | x) · pdf_l(ω), whose sum is the default output.
    #[arg(long)]
    pub per_light: bool,
    #[arg(long, value_enum, default_value_t = SelectionArg::Bound)]
    pub selection: SelectionArg,
    #[arg(long, value_enum)]
    pub device: Option<DeviceArg>,
    /// Output: float32 (M,), or (L, M) with --per-light.
    #[arg(short, long, value_name = "OUT.npy")]
    pub output: PathBuf,
}

/// The scene on `device` (the report and the check: the CPU reference).
fn prepare(
    scene: &SceneArgs,
    device: Option<DeviceArg>,
    outputs: &[(&str, &Path)],
) -> CliResult<PreparedScene> {
    Ok(open::prepare(scene, device, outputs)?.1)
}

fn open_normals(path: Option<&Path>, points: &npy::Reader) -> CliResult<Option<npy::Reader>> {
    let Some(path) = path else { return Ok(None) };
    let n = npy::Reader::open_streaming(path, RowKind::Directions)?;
    if n.rows() != points.rows() {
        return Err(Failure::bad_input(format!(
            "--points {} has {} rows but --normals {} has {}; they pair up row by row",
            points.path().display(),
            points.rows(),
            n.path().display(),
            n.rows()
        )));
    }
    Ok(Some(n))
}

pub fn run_sample(a: &SampleArgs) -> CliResult {
    let mut inputs: Vec<(&str, &Path)> = vec![("--points", &a.points), ("SCENE", &a.scene.scene)];
    if let Some(n) = &a.normals {
        inputs.push(("--normals", n));
    }
    let outputs = [("-o", a.output.as_path())];
    io::check_outputs(&outputs, &inputs)?;
    if !(1..=MAX_COUNT).contains(&a.count) {
        return Err(Failure::bad_input(format!(
            "--count {}: from 1 to {MAX_COUNT} samples per point (use more seeds for more)",
            a.count
        )));
    }
    if matches!(a.selection, SelectionArg::Exact) && a.normals.is_none() {
        return Err(Failure::bad_input(
            "--selection exact needs --normals (the irradiance is of a receiver)",
        ));
    }
    let mut points = npy::Reader::open_streaming(&a.points, RowKind::Points)?;
    let mut normals = open_normals(a.normals.as_deref(), &points)?;
    let n = points.rows();
    let k = a.count as u64;
    let scene = prepare(&a.scene, a.device, &outputs)?;
    let mut out = NpzWriter::new(&a.output);
    let dirs = out.add("dirs", Dtype::F32, &[n, k, 3])?;
    let pdf = out.add("pdf", Dtype::F32, &[n, k])?;
    let rad = out.add("radiance", Dtype::F32, &[n, k, 3])?;
    let lpdf = out.add("light_pdf", Dtype::F32, &[n, k])?;
    let light = out.add("light", Dtype::I32, &[n, k])?;
    // Points per chunk such that a chunk holds about as many rows as a query chunk.
    let chunk = (npy::chunk_rows_from_env()? / a.count).max(1);
    let bar = query::progress_bar(
        n,
        "points",
        format!("sample on {}", scene.sampling_device()),
    );
    let mut start = 0u64;
    while let Some(p) = points.next_chunk(chunk)? {
        let nrm = match &mut normals {
            Some(r) => r.next_chunk(chunk)?,
            None => None,
        };
        let opts = SampleOptions {
            seed: a.seed,
            selection: a.selection.into(),
            first_point: start,
        };
        let s = scene.sample(&p, nrm.as_deref(), a.count, &opts)?;
        query::check_finite(&scene, start * k, s.radiance.len(), &s.radiance)?;
        out.append_f32(dirs, s.dirs.as_flattened())?;
        out.append_f32(pdf, &s.pdf)?;
        out.append_f32(rad, s.radiance.as_flattened())?;
        out.append_f32(lpdf, &s.light_pdf)?;
        out.append_i32(light, &s.light)?;
        start += p.len() as u64;
        bar.set_position(start);
    }
    bar.finish_and_clear();
    out.finish()?;
    Ok(())
}

pub fn run_pdf(a: &PdfArgs) -> CliResult {
    let mut inputs: Vec<(&str, &Path)> = vec![
        ("--points", &a.points),
        ("--dirs", &a.dirs),
        ("SCENE", &a.scene.scene),
    ];
    if let Some(n) = &a.normals {
        inputs.push(("--normals", n));
    }
    let outputs = [("-o", a.output.as_path())];
    io::check_outputs(&outputs, &inputs)?;
    if matches!(a.selection, SelectionArg::Exact) && a.normals.is_none() {
        return Err(Failure::bad_input(
            "--selection exact needs --normals (the irradiance is of a receiver)",
        ));
    }
    let mut points = npy::Reader::open_streaming(&a.points, RowKind::Points)?;
    let mut dirs = npy::Reader::open_streaming(&a.dirs, RowKind::Directions)?;
    if dirs.rows() != points.rows() {
        return Err(Failure::bad_input(format!(
            "--points {} has {} rows but --dirs {} has {}; they pair up row by row",
            a.points.display(),
            points.rows(),
            a.dirs.display(),
            dirs.rows()
        )));
    }
    let mut normals = open_normals(a.normals.as_deref(), &points)?;
    let m = points.rows();
    let scene = prepare(&a.scene, a.device, &outputs)?;
    let l = scene.len() as u64;
    let rows = if a.per_light { l } else { 1 };
    let mut out = FlatNpy::new(&a.output, rows, m, a.per_light)?;
    let chunk = npy::chunk_rows_from_env()?;
    let acc = if a.per_light {
        Accumulate::PerLight
    } else {
        Accumulate::Sum
    };
    let bar = query::progress_bar(m, "rows", format!("pdf on {}", scene.sampling_device()));
    let mut start = 0u64;
    while let Some(p) = points.next_chunk(chunk)? {
        let d = dirs.next_chunk(chunk)?.unwrap_or_default();
        let nrm = match &mut normals {
            Some(r) => r.next_chunk(chunk)?,
            None => None,
        };
        let v = scene.pdf(&p, nrm.as_deref(), &d, a.selection.into(), acc)?;
        for (r, part) in v.chunks(p.len().max(1)).enumerate() {
            out.append(r, part)?;
        }
        start += p.len() as u64;
        bar.set_position(start);
    }
    bar.finish_and_clear();
    out.finish()?;
    Ok(())
}

#[derive(Args)]
pub struct SamplingArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Receiver points, float (N, 3).
    #[arg(long, value_name = "P.npy")]
    pub points: PathBuf,
    /// Receiver normals, float (N, 3), paired with the points.
    #[arg(long, value_name = "N.npy")]
    pub normals: PathBuf,
    /// Judge another renderer's sampler instead: its directions, float (N, K, 3), K per point
    /// (point-major), and the densities it claims for them, float (N, K), per unit solid
    /// angle, against the exact irradiance of the selected lights (--light for one).
    #[arg(long, num_args = 2, value_names = ["DIRS.npy", "PDFS.npy"])]
    pub check: Option<Vec<PathBuf>>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The median of `v` (sorted in place; the mean of the middle two for an even count), `None`
/// when empty.
fn median(v: &mut [f64]) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    (!v.is_empty()).then(|| 0.5 * (v[(v.len() - 1) / 2] + v[v.len() / 2]))
}

/// Samples to 1 % noise: the relative variance per sample over 10⁻⁴, at least 1.
fn samples_to_1pc(rv: f64) -> u64 {
    (rv / 1e-4).ceil().max(1.0) as u64
}

pub fn run_sampling(a: &SamplingArgs) -> CliResult {
    let points = npy::read_points(&a.points)?;
    let normals = npy::read_directions(&a.normals)?;
    if points.len() != normals.len() {
        return Err(Failure::bad_input(format!(
            "--points {} has {} rows but --normals {} has {}; they pair up row by row",
            a.points.display(),
            points.len(),
            a.normals.display(),
            normals.len()
        )));
    }
    let scene = prepare(&a.scene, Some(DeviceArg::Cpu), &[])?;
    let paths: Vec<String> = scene.lights().map(|l| l.path.clone()).collect();
    if let Some(files) = &a.check {
        return run_check(a, &scene, &points, &normals, &files[0], &files[1]);
    }
    let report = scene.sampling_report(&points, &normals)?;
    let n = points.len();
    let mut json = Vec::new();
    for (k, path) in paths.iter().enumerate() {
        let rows = &report[k * n..(k + 1) * n];
        let lit: Vec<_> = rows.iter().filter(|r| r.irradiance > 0.0).collect();
        let pick = |f: &dyn Fn(&luxeval::StrategyVariance) -> Option<f64>| {
            let mut v: Vec<f64> = lit.iter().filter_map(|r| f(r)).collect();
            let max = v
                .iter()
                .copied()
                .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
            (median(&mut v), max)
        };
        let lux = pick(&|r| r.luxeval);
        let area = pick(&|r| r.area);
        let cos = pick(&|r| r.cosine);
        let strategy = scene.sampling_strategy(k).unwrap_or("");
        if a.json {
            json.push(serde_json::json!({
                "light": path,
                "strategy": strategy,
                "receivers_lit": lit.len(),
                "receivers": rows.iter().map(|r| serde_json::json!({
                    "irradiance": r.irradiance,
                    "luxeval": r.luxeval,
                    "area": r.area,
                    "cosine": r.cosine,
                })).collect::<Vec<_>>(),
            }));
            continue;
        }
        crate::write_stdout(format_args!("{path}: {strategy}"));
        crate::write_stdout(format_args!(
            "  receivers lit: {} of {n}; relative variance per sample, median / max over them; samples to 1 % noise at the median",
            lit.len()
        ));
        for (name, (med, max)) in [("luxeval", lux), ("uniform area", area), ("cosine", cos)] {
            match (med, max) {
                (Some(m), Some(x)) => crate::write_stdout(format_args!(
                    "  {name:<13} {m:>12.4} / {x:<12.4} {:>10}",
                    samples_to_1pc(m)
                )),
                _ => crate::write_stdout(format_args!("  {name:<13} {:>12}", "n/a")),
            }
        }
    }
    if a.json {
        crate::write_stdout(format_args!(
            "{}",
            serde_json::to_string_pretty(&serde_json::Value::Array(json)).unwrap_or_default()
        ));
    }
    Ok(())
}

fn run_check(
    a: &SamplingArgs,
    scene: &PreparedScene,
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    dirs_path: &Path,
    pdfs_path: &Path,
) -> CliResult {
    let (dshape, dvals) = npy::read_array(dirs_path)?;
    let (pshape, pvals) = npy::read_array(pdfs_path)?;
    let n = points.len() as u64;
    let k = match (dshape.as_slice(), pshape.as_slice()) {
        ([dn, dk, 3], [pn, pk]) if *dn == n && *pn == n && dk == pk => *dk as usize,
        _ => {
            return Err(Failure::bad_input(format!(
                "--check: {} has shape {dshape:?} and {} has {pshape:?}; expected (N, K, 3) and (N, K) with N = {n} points",
                dirs_path.display(),
                pdfs_path.display()
            )));
        }
    };
    let dirs: Vec<[f32; 3]> = dvals
        .chunks_exact(3)
        .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
        .collect();
    let pdfs: Vec<f32> = pvals.iter().map(|&v| v as f32).collect();
    let checks = scene.check_sampler(points, normals, &dirs, &pdfs, k)?;
    let biased: Vec<usize> = (0..checks.len())
        .filter(|&i| checks[i].z.abs() > 5.0)
        .collect();
    let worst = checks.iter().map(|c| c.z.abs()).fold(0.0, f64::max);
    let worst_cell = checks.iter().map(|c| c.worst_cell_z).fold(0.0, f64::max);
    let bad: u64 = checks.iter().map(|c| c.bad_pdf).sum();
    if a.json {
        crate::write_stdout(format_args!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "samples_per_point": k,
                "worst_abs_z": worst,
                "points_over_5_sigma": biased.len(),
                "worst_cell_z": worst_cell,
                "bad_pdf": bad,
                "points": checks.iter().map(|c| serde_json::json!({
                    "exact": c.exact, "mean": c.mean, "stderr": c.stderr, "z": c.z,
                    "worst_cell_z": c.worst_cell_z, "bad_pdf": c.bad_pdf,
                })).collect::<Vec<_>>(),
            }))
            .unwrap_or_default()
        ));
    } else {
        for (i, c) in checks.iter().enumerate() {
            crate::write_stdout(format_args!(
                "point {i}: mean of f/p {:.6} ± {:.6}, exact {:.6}, z = {:+.2}; worst cell z {:+.2}; {} samples with no usable pdf",
                c.mean, c.stderr, c.exact, c.z, c.worst_cell_z, c.bad_pdf
            ));
        }
        crate::write_stdout(format_args!(
            "{} of {} points biased beyond 5 standard errors (worst |z| {worst:.2}); worst cell z {worst_cell:.2}; {bad} samples with no usable pdf",
            biased.len(),
            checks.len()
        ));
    }
    if !biased.is_empty() || bad > 0 || worst_cell > 5.0 {
        return Err(Failure::runtime(format!(
            "the sampler is inconsistent: {} points biased beyond 5σ, worst cell z {worst_cell:.2}, {bad} samples with a pdf ≤ 0 where light arrives",
            biased.len()
        )));
    }
    Ok(())
}
