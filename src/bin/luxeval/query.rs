//! `luxeval emission | radiance | irradiance`: a query over `.npy` arrays.

use std::path::Path;

use luxeval::PreparedScene;
use luxeval::io::npy;

use crate::args::QueryArgs;
use crate::exit::CliResult;
use crate::open;

/// Which query, with its input files.
pub enum Query<'a> {
    Emission { dirs: &'a Path },
    Radiance { points: &'a Path, dirs: &'a Path },
    Irradiance { points: &'a Path, normals: &'a Path },
}

pub fn run(args: &QueryArgs, query: Query, output: &Path) -> CliResult {
    let acc = args.accumulate();
    // Inputs are read before the stage is opened: a bad array is reported without the cost of
    // opening a device.
    let (n, scene, out) = match query {
        Query::Emission { dirs } => {
            let dirs = npy::read_vec3(dirs)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.emission(&dirs, acc)?;
            (dirs.len(), scene, out)
        }
        Query::Radiance { points, dirs } => {
            let points = npy::read_vec3(points)?;
            let dirs = npy::read_vec3(dirs)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.radiance(&points, &dirs, acc)?;
            (dirs.len(), scene, out)
        }
        Query::Irradiance { points, normals } => {
            let points = npy::read_vec3(points)?;
            let normals = npy::read_vec3(normals)?;
            let (_, scene) = open::prepare(&args.scene, args.device)?;
            let out = scene.irradiance(&points, &normals, acc)?;
            (points.len(), scene, out)
        }
    };
    write_rows(output, args, &scene, n, &out)
}

fn write_rows(
    path: &Path,
    args: &QueryArgs,
    scene: &PreparedScene,
    n: usize,
    rows: &[[f32; 3]],
) -> CliResult {
    let shape: Vec<u64> = if args.per_light {
        vec![scene.len() as u64, n as u64, 3]
    } else {
        vec![n as u64, 3]
    };
    npy::write_f32(path, &shape, rows)?;
    Ok(())
}
