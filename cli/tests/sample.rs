//! `luxeval sample` and `luxeval pdf` (DESIGN.md §9 S4): the `.npz` holds the arrays S4 names
//! with their shapes, its rows are the library's bit for bit on any chunking, `pdf` gives back
//! each drawn direction's density, and bad input exits 2 naming the argument.

use crate::stream::{luxeval, s};
use crate::support::*;

use luxeval::{Evaluator, SampleOptions, Stage};
use luxeval_cli::io::npy;
use npyz::WriterBuilder;

fn npz_array(path: &std::path::Path, name: &str) -> (Vec<u64>, Vec<u8>) {
    use std::io::Read;
    let mut zip = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    let mut f = zip.by_name(&format!("{name}.npy")).unwrap();
    let mut bytes = Vec::new();
    f.read_to_end(&mut bytes).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    let shape = npy.shape().to_vec();
    let hl = bytes.len() - (shape.iter().product::<u64>() * 4) as usize;
    (shape, bytes[hl..].to_vec())
}

#[test]
fn sample_writes_the_arrays_of_s4_on_any_chunking() {
    let dir = tempfile::tempdir().unwrap();
    let pts: Vec<[f32; 3]> = (0..7)
        .map(|i| [i as f32 - 3.0, 0.0, 1.0 - 0.5 * i as f32])
        .collect();
    let nrm = vec![[0.0f32, 1.0, 0.0]; pts.len()];
    let (p, n) = (dir.path().join("p.npy"), dir.path().join("n.npy"));
    npy::write_f32(&p, &[7, 3], &pts).unwrap();
    npy::write_f32(&n, &[7, 3], &nrm).unwrap();
    let scene = luxtest("sphere.usda");
    let mut outs = Vec::new();
    for (tag, chunk) in [("whole", None), ("chunked", Some("10"))] {
        let o = dir.path().join(format!("{tag}.npz"));
        let r = luxeval(
            &[
                "sample",
                &scene,
                "--time",
                "31",
                "--points",
                s(&p),
                "--normals",
                s(&n),
                "--count",
                "4",
                "--seed",
                "9",
                "-o",
                s(&o),
            ],
            chunk,
        );
        assert!(r.status.success(), "{}", stderr(&r));
        outs.push(o);
    }
    for name in ["dirs", "pdf", "radiance", "light_pdf", "light"] {
        let a = npz_array(&outs[0], name);
        assert_eq!(a, npz_array(&outs[1], name), "{name}");
        let want: Vec<u64> = if matches!(name, "dirs" | "radiance") {
            vec![7, 4, 3]
        } else {
            vec![7, 4]
        };
        assert_eq!(a.0, want, "{name}");
    }
    // The library's draws, bit for bit.
    let lights = Stage::load(std::path::Path::new(&scene), Some(31.0))
        .unwrap()
        .evaluable(&[])
        .unwrap();
    let lib = Evaluator::cpu()
        .prepare(&lights)
        .unwrap()
        .sample(
            &pts,
            Some(&nrm),
            4,
            &SampleOptions {
                seed: 9,
                ..Default::default()
            },
        )
        .unwrap();
    let pdf: Vec<f32> = npz_array(&outs[0], "pdf")
        .1
        .chunks(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(pdf, lib.pdf);
    // `pdf` of the drawn directions: the same densities (float32 directions, 1e-4).
    let dirs: Vec<[f32; 3]> = lib.dirs.clone();
    let rep: Vec<[f32; 3]> = pts
        .iter()
        .flat_map(|q| std::iter::repeat_n(*q, 4))
        .collect();
    let repn = vec![[0.0f32, 1.0, 0.0]; rep.len()];
    let (dp, pp, np_, q) = (
        dir.path().join("d.npy"),
        dir.path().join("pp.npy"),
        dir.path().join("nn.npy"),
        dir.path().join("q.npy"),
    );
    npy::write_f32(&dp, &[28, 3], &dirs).unwrap();
    npy::write_f32(&pp, &[28, 3], &rep).unwrap();
    npy::write_f32(&np_, &[28, 3], &repn).unwrap();
    let r = luxeval(
        &[
            "pdf",
            &scene,
            "--time",
            "31",
            "--points",
            s(&pp),
            "--dirs",
            s(&dp),
            "--normals",
            s(&np_),
            "-o",
            s(&q),
        ],
        None,
    );
    assert!(r.status.success(), "{}", stderr(&r));
    let (shape, back) = read_npy_f32(&q);
    assert_eq!(shape, vec![28]);
    for (g, w) in back.iter().zip(&lib.pdf) {
        assert!(
            *w == 0.0 || ((g - w) / w).abs() < 1e-4 || *g == 0.0,
            "{g} vs {w}"
        );
    }
}

#[test]
fn sample_and_pdf_refuse_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("p.npy");
    npy::write_f32(&p, &[1, 3], &[[0.0, 0.0, 0.0]]).unwrap();
    let scene = luxtest("sphere.usda");
    let o = dir.path().join("o.npz");
    for (args, says) in [
        (vec!["--count", "0"], "--count"),
        (vec!["--selection", "exact"], "--normals"),
    ] {
        let mut a = vec!["sample", scene.as_str(), "--points", s(&p), "-o", s(&o)];
        a.extend(args);
        let r = luxeval(&a, None);
        assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
        assert!(stderr(&r).contains(says), "{}", stderr(&r));
        assert!(!o.exists());
    }
    // The output may not be an input.
    let r = luxeval(&["sample", &scene, "--points", s(&p), "-o", s(&p)], None);
    assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
    let r = luxeval(
        &[
            "pdf",
            &scene,
            "--points",
            s(&p),
            "--dirs",
            s(&p),
            "-o",
            s(&p),
        ],
        None,
    );
    assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
}

/// `luxeval sampling`: the report names each light's strategy and its three figures; `--check`
/// passes luxeval's own draws (their pdfs), and fails (exit 1) the same directions with every
/// density halved (a sampler that claims half its true density is biased by 2×).
#[test]
fn sampling_report_and_check() {
    let dir = tempfile::tempdir().unwrap();
    let pts: Vec<[f32; 3]> = vec![[0.0, 0.0, 0.0], [1.0, 0.0, -1.0]];
    let nrm = vec![[0.0f32, 1.0, 0.0]; 2];
    let (p, n) = (dir.path().join("p.npy"), dir.path().join("n.npy"));
    npy::write_f32(&p, &[2, 3], &pts).unwrap();
    npy::write_f32(&n, &[2, 3], &nrm).unwrap();
    let scene = luxtest("sphere.usda");
    let r = luxeval(
        &[
            "sampling",
            &scene,
            "--time",
            "31",
            "--points",
            s(&p),
            "--normals",
            s(&n),
        ],
        None,
    );
    assert!(r.status.success(), "{}", stderr(&r));
    let out = String::from_utf8_lossy(&r.stdout);
    for word in [
        "/lights/sphere_light",
        "luxeval",
        "uniform area",
        "cosine",
        "samples to 1 %",
    ] {
        assert!(out.contains(word), "{out}");
    }
    // luxeval's own samples, as another renderer would hand them over.
    let o = dir.path().join("s.npz");
    let r = luxeval(
        &[
            "sample",
            &scene,
            "--time",
            "31",
            "--points",
            s(&p),
            "--normals",
            s(&n),
            "--count",
            "4000",
            "-o",
            s(&o),
        ],
        None,
    );
    assert!(r.status.success(), "{}", stderr(&r));
    let (dshape, dbytes) = npz_array(&o, "dirs");
    let (pshape, pbytes) = npz_array(&o, "pdf");
    let write = |path: &std::path::Path, shape: &[u64], bytes: &[u8], scale: f32| {
        let vals: Vec<f32> = bytes
            .chunks(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()) * scale)
            .collect();
        let mut w = npyz::WriteOptions::<f32>::new()
            .default_dtype()
            .shape(shape)
            .writer(std::fs::File::create(path).unwrap())
            .begin_nd()
            .unwrap();
        w.extend(vals).unwrap();
        w.finish().unwrap();
    };
    let (d, good, half) = (
        dir.path().join("d.npy"),
        dir.path().join("pdf.npy"),
        dir.path().join("half.npy"),
    );
    write(&d, &dshape, &dbytes, 1.0);
    write(&good, &pshape, &pbytes, 1.0);
    write(&half, &pshape, &pbytes, 0.5);
    let check = |pdfs: &std::path::Path| {
        luxeval(
            &[
                "sampling",
                &scene,
                "--time",
                "31",
                "--points",
                s(&p),
                "--normals",
                s(&n),
                "--check",
                s(&d),
                s(pdfs),
            ],
            None,
        )
    };
    let r = check(&good);
    assert!(
        r.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&r.stdout),
        stderr(&r)
    );
    let r = check(&half);
    assert_eq!(
        r.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&r.stdout)
    );
    assert!(stderr(&r).contains("biased"), "{}", stderr(&r));
    // A shape that does not pair up: exit 2 naming the files.
    let r = check(&d);
    assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
}
