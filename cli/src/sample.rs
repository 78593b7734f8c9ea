//! `luxeval sample` and `luxeval pdf` (DESIGN.md §9 S4): directions drawn toward a stage's
//! lights with their densities, streamed chunk by chunk into an `.npz`; and the density of
//! given directions into an `.npy`. Both run on the f64 CPU reference (the GPU samplers are not
//! written yet; `--device gpu` says so and runs there too).

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
    /// `auto` and `cpu` run on the CPU reference; `gpu` too, with a warning (no GPU samplers
    /// yet).
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

/// The scene on the CPU reference, whatever `--device` says (module docs).
fn prepare(
    scene: &SceneArgs,
    device: Option<DeviceArg>,
    outputs: &[(&str, &Path)],
) -> CliResult<PreparedScene> {
    if matches!(device, Some(DeviceArg::Gpu)) {
        eprintln!(
            "warning: --device gpu: sampling runs on the CPU reference (the GPU samplers are not written yet)"
        );
    }
    Ok(open::prepare(scene, Some(DeviceArg::Cpu), outputs)?.1)
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
    let bar = query::progress_bar(n, "points", "sample on cpu".into());
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
    let bar = query::progress_bar(m, "rows", "pdf on cpu".into());
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
