//! GPU-resident evaluation (`Evaluator::from_wgpu`, `PreparedScene::encode_*`): a renderer
//! opens its own device, hands it to luxeval, keeps its data in its own buffers and records the
//! queries into its own encoder. The results must be those of the host path
//! (`PreparedScene::emission` and the others) on the same lights and the same device: the same
//! kernels run on the same inputs (up to the host path's f64 normalisation of unit vectors).

use crate::common;

use luxeval::testkit::{Rng, ies::with_random_ies, random_light, synthetic_lights};
use luxeval::wgpu;
use luxeval::{
    Accumulate, Asset, Evaluator, Light, LuxError, Reference, RowLayout, TemperatureMode, Texture,
    TextureFormat,
};

/// What a renderer holds: its own device and queue.
pub(crate) struct Renderer {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    /// `None` for a device luxeval opened.
    adapter: Option<wgpu::Adapter>,
}

/// The renderer's device, opened the way a renderer would (luxeval's wgpu, the default
/// high-performance adapter, `limits` or the adapter's own); `None` (a skip, as
/// `common::gpu` does) without an adapter, a failure under CI=true.
pub(crate) fn renderer_with(limits: Option<wgpu::Limits>) -> Option<Renderer> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    })) {
        Ok(a) => a,
        Err(e) => {
            if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") {
                panic!("CI=true but no GPU adapter: {e}");
            }
            eprintln!("skipping GPU test: {e}");
            return None;
        }
    };
    let required_limits = limits.unwrap_or_else(|| adapter.limits());
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("renderer"),
        required_limits,
        ..Default::default()
    }))
    .expect("the adapter opens a device");
    Some(Renderer {
        device,
        queue,
        adapter: Some(adapter),
    })
}

pub(crate) fn renderer() -> Option<Renderer> {
    renderer_with(None)
}

impl Renderer {
    /// A second device on the same adapter (and so the same wgpu instance: wgpu cannot tell
    /// objects of another instance apart from its own).
    fn another_device(&self) -> Renderer {
        let adapter = self.adapter.clone().expect("a renderer's own device");
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
                .expect("the adapter opens a second device");
        Renderer {
            device,
            queue,
            adapter: Some(adapter),
        }
    }

    pub(crate) fn buffer(&self, rows: &[[f32; 3]], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        let b = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("renderer input"),
            size: (rows.len() * 12).max(12) as u64,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&b, 0, bytemuck::cast_slice(rows));
        b
    }

    /// An output of `rows` rows, filled with garbage (1e6) so that a row the call should have
    /// written but did not, or added to instead of writing, shows.
    pub(crate) fn output(&self, rows: usize) -> wgpu::Buffer {
        self.buffer(
            &vec![[1.0e6; 3]; rows],
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        )
    }

    pub(crate) fn encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("renderer frame"),
            })
    }

    /// Submits `encoder` and reads the first `rows` rows of `out` back.
    fn finish(
        &self,
        encoder: wgpu::CommandEncoder,
        out: &wgpu::Buffer,
        rows: usize,
    ) -> Vec<[f32; 3]> {
        self.finish_floats(encoder, out, 3 * rows)
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect()
    }

    /// Submits `encoder` and reads the first `floats` f32 of `out` back.
    pub(crate) fn finish_floats(
        &self,
        mut encoder: wgpu::CommandEncoder,
        out: &wgpu::Buffer,
        floats: usize,
    ) -> Vec<f32> {
        let size = (floats * 4) as u64;
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_buffer_to_buffer(out, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| tx.send(r).unwrap());
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the device finishes");
        rx.recv().unwrap().expect("the readback maps");
        let data = bytemuck::cast_slice::<u8, f32>(&slice.get_mapped_range().unwrap()).to_vec();
        staging.unmap();
        data
    }
}

pub(crate) fn unit_rows(rng: &mut Rng, n: usize) -> Vec<[f32; 3]> {
    (0..n).map(|_| rng.unit().as_vec3().to_array()).collect()
}

/// Points around the lights (synthetic lights sit within a few metres of the origin).
pub(crate) fn points(rng: &mut Rng, n: usize) -> Vec<[f32; 3]> {
    (0..n)
        .map(|_| (rng.unit() * rng.range(0.5, 6.0)).as_vec3().to_array())
        .collect()
}

/// Resident and host rows agree to 1e-6 of the larger magnitude of the pair (1e-30 absolute
/// for zeros), component by component; and at least some are non-zero, so that the test sees
/// values.
fn assert_same(what: &str, resident: &[[f32; 3]], host: &[[f32; 3]]) {
    assert_eq!(resident.len(), host.len(), "{what}: row count");
    let mut worst = 0.0f64;
    for (i, (r, h)) in resident.iter().zip(host).enumerate() {
        for c in 0..3 {
            let (r, h) = (r[c] as f64, h[c] as f64);
            let scale = r.abs().max(h.abs());
            assert!(
                (r - h).abs() <= 1e-6 * scale + 1e-30,
                "{what}: row {i} channel {c}: resident {r} vs host {h}"
            );
            if scale > 0.0 {
                worst = worst.max((r - h).abs() / scale);
            }
        }
    }
    let lit = host.iter().filter(|h| h.iter().any(|c| *c != 0.0)).count();
    assert!(
        lit * 10 >= host.len(),
        "{what}: only {lit} of {} rows lit",
        host.len()
    );
    eprintln!(
        "{what}: {} rows, {lit} lit, largest relative difference {worst:.3e}",
        host.len()
    );
}

/// Lights for emission and radiance: the benchmark's mix (shaped and not) and two IES-shaped
/// lights, so the pipeline variant with the IES lookup runs too.
pub(crate) fn lights_with_ies() -> Vec<Light> {
    let mut rng = Rng::new(11);
    let mut lights = synthetic_lights(12);
    lights.push(with_random_ies(
        random_light(1, "rotate", &mut rng, 100),
        &mut rng,
        3,
        false,
    ));
    lights.push(with_random_ies(
        random_light(3, "translate", &mut rng, 101),
        &mut rng,
        1,
        true,
    ));
    lights
}

#[test]
fn emission_and_intensity_match_the_host_path() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    assert!(
        eval.device_name().contains("caller's device"),
        "{}",
        eval.device_name()
    );
    let scene = eval.prepare(&lights_with_ies()).unwrap();
    let mut rng = Rng::new(1);
    // Not a multiple of the workgroup size (64).
    let n = 10_007;
    let dirs = unit_rows(&mut rng, n);
    let dirs_buf = r.buffer(&dirs, wgpu::BufferUsages::STORAGE);
    for (acc, rows) in [
        (Accumulate::Sum, n),
        (Accumulate::PerLight, scene.len() * n),
    ] {
        let out = r.output(rows);
        let mut enc = r.encoder();
        scene
            .encode_emission(&mut enc, &dirs_buf, &out, n as u32, acc)
            .unwrap();
        let got = r.finish(enc, &out, rows);
        assert_same(
            &format!("emission {acc:?}"),
            &got,
            &scene.emission(&dirs, acc).unwrap(),
        );

        let out = r.output(rows);
        let mut enc = r.encoder();
        scene
            .encode_intensity(&mut enc, &dirs_buf, &out, n as u32, acc)
            .unwrap();
        let got = r.finish(enc, &out, rows);
        assert_same(
            &format!("intensity {acc:?}"),
            &got,
            &scene.intensity(&dirs, acc).unwrap(),
        );
    }
}

#[test]
fn radiance_matches_the_host_path() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let scene = eval.prepare(&lights_with_ies()).unwrap();
    let mut rng = Rng::new(2);
    let n = 20_001;
    // Directions aimed at a light's origin (jittered), so that many rays hit a shape.
    let lights: Vec<Light> = scene.lights().cloned().collect();
    let pts = points(&mut rng, n);
    let dirs: Vec<[f32; 3]> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let o = lights[i % lights.len()].world.w_axis.truncate();
            let p = glam::DVec3::from_array(p.map(f64::from));
            ((o - p).normalize() + rng.unit() * 0.05)
                .normalize()
                .as_vec3()
                .to_array()
        })
        .collect();
    let pts_buf = r.buffer(&pts, wgpu::BufferUsages::STORAGE);
    let dirs_buf = r.buffer(&dirs, wgpu::BufferUsages::STORAGE);
    for (acc, rows) in [
        (Accumulate::Sum, n),
        (Accumulate::PerLight, scene.len() * n),
    ] {
        let out = r.output(rows);
        let mut enc = r.encoder();
        scene
            .encode_radiance(&mut enc, &pts_buf, &dirs_buf, &out, n as u32, acc)
            .unwrap();
        let got = r.finish(enc, &out, rows);
        let host = scene.radiance(&pts, &dirs, acc).unwrap();
        if acc == Accumulate::Sum {
            assert_same("radiance Sum", &got, &host);
        } else {
            // Per light most rows miss; compare all, require hits only in the sum above.
            assert_eq!(got.len(), host.len());
            for (i, (g, h)) in got.iter().zip(&host).enumerate() {
                for c in 0..3 {
                    let scale = g[c].abs().max(h[c].abs()) as f64;
                    assert!(
                        ((g[c] - h[c]) as f64).abs() <= 1e-6 * scale + 1e-30,
                        "radiance PerLight row {i}: {g:?} vs {h:?}"
                    );
                }
            }
        }
    }
}

/// `rows` as 16-byte rows whose fourth float is NaN: a kernel that read it would show it.
fn vec4_buffer(r: &Renderer, rows: &[[f32; 3]]) -> wgpu::Buffer {
    let floats: Vec<f32> = rows
        .iter()
        .flat_map(|v| [v[0], v[1], v[2], f32::NAN])
        .collect();
    let b = r.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("renderer input, vec4 rows"),
        size: (floats.len() * 4).max(16) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    r.queue.write_buffer(&b, 0, bytemuck::cast_slice(&floats));
    b
}

#[test]
fn vec4_rows_are_the_packed_rows() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    // The IES mix for emission, intensity and radiance; five lights for irradiance (five
    // dispatch groups on lavapipe, so the later groups add to rows the first wrote).
    // The vec4 scene also takes three rows per invocation (a real GPU's resident path may;
    // lavapipe's default is one), so that both the stride and the row loop are checked.
    let packed = eval.prepare(&lights_with_ies()).unwrap();
    let vec4 = luxeval::testkit::with_rows_per_invocation(
        eval.prepare(&lights_with_ies())
            .unwrap()
            .with_row_layout(RowLayout::Vec4),
        3,
    );
    assert_eq!(vec4.row_layout(), RowLayout::Vec4);
    assert_eq!(packed.row_layout(), RowLayout::Packed);
    let mut rng = Rng::new(24);
    let n = 4_099;
    let dirs = unit_rows(&mut rng, n);
    let pts = points(&mut rng, n);
    let (dirs3, pts3) = (
        r.buffer(&dirs, wgpu::BufferUsages::STORAGE),
        r.buffer(&pts, wgpu::BufferUsages::STORAGE),
    );
    let (dirs4, pts4) = (vec4_buffer(&r, &dirs), vec4_buffer(&r, &pts));
    // Runs one query in both layouts; the vec4 rows' fourth floats must be 0 and the rows
    // past the call's untouched (the garbage `output` wrote).
    let compare = |what: &str,
                   rows: usize,
                   run3: &dyn Fn(&mut wgpu::CommandEncoder, &wgpu::Buffer),
                   run4: &dyn Fn(&mut wgpu::CommandEncoder, &wgpu::Buffer)| {
        let out3 = r.output(rows);
        let mut enc = r.encoder();
        run3(&mut enc, &out3);
        let want = r.finish(enc, &out3, rows);
        // 4 floats a row, plus one row past the end.
        let out4 = r.output((rows + 1) * 4 / 3 + 1);
        let mut enc = r.encoder();
        run4(&mut enc, &out4);
        let got = r.finish_floats(enc, &out4, 4 * rows + 4);
        for i in 0..rows {
            assert_eq!(got[4 * i + 3], 0.0, "{what}: row {i}'s fourth float");
        }
        assert_eq!(
            &got[4 * rows..],
            &[1.0e6; 4],
            "{what}: the row past the call"
        );
        let rows4: Vec<[f32; 3]> = got[..4 * rows]
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        assert_same(what, &rows4, &want);
    };
    for acc in [Accumulate::Sum, Accumulate::PerLight] {
        let rows = if acc == Accumulate::Sum {
            n
        } else {
            packed.len() * n
        };
        compare(
            &format!("emission {acc:?}"),
            rows,
            &|e, o| packed.encode_emission(e, &dirs3, o, n as u32, acc).unwrap(),
            &|e, o| vec4.encode_emission(e, &dirs4, o, n as u32, acc).unwrap(),
        );
        compare(
            &format!("intensity {acc:?}"),
            rows,
            &|e, o| {
                packed
                    .encode_intensity(e, &dirs3, o, n as u32, acc)
                    .unwrap()
            },
            &|e, o| vec4.encode_intensity(e, &dirs4, o, n as u32, acc).unwrap(),
        );
    }
    // Radiance toward the lights' origins, so that rays hit shapes.
    let origins: Vec<glam::DVec3> = packed.lights().map(|l| l.world.w_axis.truncate()).collect();
    let aimed: Vec<[f32; 3]> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let p = glam::DVec3::from_array(p.map(f64::from));
            ((origins[i % origins.len()] - p).normalize() + rng.unit() * 0.05)
                .normalize()
                .as_vec3()
                .to_array()
        })
        .collect();
    let (aimed3, aimed4) = (
        r.buffer(&aimed, wgpu::BufferUsages::STORAGE),
        vec4_buffer(&r, &aimed),
    );
    let sum = Accumulate::Sum;
    compare(
        "radiance Sum",
        n,
        &|e, o| {
            packed
                .encode_radiance(e, &pts3, &aimed3, o, n as u32, sum)
                .unwrap()
        },
        &|e, o| {
            vec4.encode_radiance(e, &pts4, &aimed4, o, n as u32, sum)
                .unwrap()
        },
    );
    let packed = eval.prepare(&synthetic_lights(5)).unwrap();
    let vec4 = eval
        .prepare(&synthetic_lights(5))
        .unwrap()
        .with_row_layout(RowLayout::Vec4);
    let m = 513;
    compare(
        "irradiance Sum",
        m,
        &|e, o| {
            packed
                .encode_irradiance(e, &pts3, &dirs3, o, m as u32, sum)
                .unwrap()
        },
        &|e, o| {
            vec4.encode_irradiance(e, &pts4, &dirs4, o, m as u32, sum)
                .unwrap()
        },
    );
    // Packed rows, five per invocation (4,099 rows: the last invocation takes fewer).
    let packed5 =
        luxeval::testkit::with_rows_per_invocation(eval.prepare(&lights_with_ies()).unwrap(), 5);
    let packed = eval.prepare(&lights_with_ies()).unwrap();
    for acc in [Accumulate::Sum, Accumulate::PerLight] {
        let rows = if acc == Accumulate::Sum {
            n
        } else {
            packed.len() * n
        };
        let run = |scene: &luxeval::PreparedScene| {
            let out = r.output(rows + 1);
            let mut enc = r.encoder();
            scene
                .encode_emission(&mut enc, &dirs3, &out, n as u32, acc)
                .unwrap();
            r.finish(enc, &out, rows + 1)
        };
        let (got, want) = (run(&packed5), run(&packed));
        assert_eq!(got[rows], [1.0e6; 3], "the row past the call");
        assert_same(
            &format!("emission {acc:?}, 5 rows an invocation"),
            &got[..rows],
            &want[..rows],
        );
    }
    // A buffer of 12-byte rows is too small for `count` 16-byte ones.
    let mut enc = r.encoder();
    let out = r.output(4 * n);
    let err = vec4
        .encode_emission(&mut enc, &dirs3, &out, n as u32, sum)
        .unwrap_err();
    assert!(
        matches!(&err, LuxError::InvalidInput { .. }) && err.to_string().contains("x, y, z, w"),
        "{err}"
    );
}

#[test]
fn irradiance_matches_the_host_path_over_several_light_groups() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    // Five lights: five dispatch groups on lavapipe (one light each), accumulating in order.
    let scene = eval.prepare(&synthetic_lights(5)).unwrap();
    let mut rng = Rng::new(3);
    let n = 1_003;
    let pts = points(&mut rng, n);
    let normals = unit_rows(&mut rng, n);
    assert_resident_irradiance_is_the_host_paths(&r, &scene, &pts, &normals);
}

/// `encode_irradiance` of `scene` gives the host path's rows, summed and per light.
fn assert_resident_irradiance_is_the_host_paths(
    r: &Renderer,
    scene: &luxeval::PreparedScene,
    pts: &[[f32; 3]],
    normals: &[[f32; 3]],
) {
    let n = pts.len();
    let pts_buf = r.buffer(pts, wgpu::BufferUsages::STORAGE);
    let nrm_buf = r.buffer(normals, wgpu::BufferUsages::STORAGE);
    for (acc, rows) in [
        (Accumulate::Sum, n),
        (Accumulate::PerLight, scene.len() * n),
    ] {
        // Garbage in `out` (see Renderer::output): summed mode must write, not add.
        let out = r.output(rows);
        let mut enc = r.encoder();
        scene
            .encode_irradiance(&mut enc, &pts_buf, &nrm_buf, &out, n as u32, acc)
            .unwrap();
        let got = r.finish(enc, &out, rows);
        let host = scene.irradiance(pts, normals, acc).unwrap();
        assert_same(&format!("irradiance {acc:?}"), &got, &host);
    }
}

/// `encode_irradiance` over `pts` and `normals` refuses `scene` with
/// [`LuxError::NotOnDevice`] naming `light`, its reason containing `why`.
fn assert_irradiance_refused(
    r: &Renderer,
    scene: &luxeval::PreparedScene,
    pts: &[[f32; 3]],
    normals: &[[f32; 3]],
    light: &str,
    why: &str,
) {
    let n = pts.len();
    let pts_buf = r.buffer(pts, wgpu::BufferUsages::STORAGE);
    let nrm_buf = r.buffer(normals, wgpu::BufferUsages::STORAGE);
    let out = r.output(n);
    let mut enc = r.encoder();
    match scene.encode_irradiance(
        &mut enc,
        &pts_buf,
        &nrm_buf,
        &out,
        n as u32,
        Accumulate::Sum,
    ) {
        Err(LuxError::NotOnDevice {
            light: named,
            reason,
            ..
        }) => {
            assert_eq!(named, light);
            assert!(reason.contains(why), "{reason}");
        }
        other => panic!("expected NotOnDevice, got {other:?}"),
    }
}

/// `img` encoded as a PNG texture named `name` (in memory).
fn png_texture(name: &str, img: &image::RgbImage) -> Texture {
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    Texture::new(Asset::from_bytes(name, bytes.into_inner()))
}

/// A textured rect of up to `RECT_TEXELS_ON_DEVICE` (64 × 64) texels has its irradiance on the
/// device (the texture factor of irradiance/line.wgsl), so the GPU-resident call accepts it and
/// gives the host path's rows; one of more texels is the host's, and the call refuses it by
/// name.
#[test]
fn small_textured_rect_irradiance_is_resident() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let mut rng = Rng::new(33);
    let png = |w: u32, h: u32, rng: &mut Rng| {
        let img = image::RgbImage::from_fn(w, h, |_, _| {
            image::Rgb([0, 1, 2].map(|_| 40 + rng.below(200) as u8))
        });
        png_texture(&format!("rect-{w}x{h}.png"), &img)
    };
    let mut lights = synthetic_lights(2);
    lights.push(
        Light::rect(2.0, 1.0)
            .with_path("/Small")
            .with_intensity(3.0)
            .with_texture(png(3, 2, &mut rng)),
    );
    let scene = eval.prepare(&lights).unwrap();
    let n = 129;
    let pts = points(&mut rng, n);
    let normals = unit_rows(&mut rng, n);
    assert_resident_irradiance_is_the_host_paths(&r, &scene, &pts, &normals);
    lights[2] = Light::rect(2.0, 1.0)
        .with_path("/Large")
        .with_texture(png(65, 64, &mut rng));
    let scene = eval.prepare(&lights).unwrap();
    assert_irradiance_refused(&r, &scene, &pts, &normals, "/Large", "texels");
}

/// A textured latlong dome's irradiance is the kernel's (irradiance/latlong_rows.wgsl), so the
/// GPU-resident call accepts it and gives the host path's rows; a mirroredBall dome's is the
/// host's, and the call refuses it by name.
#[test]
fn textured_latlong_dome_irradiance_is_resident() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let mut rng = Rng::new(21);
    let png = |format: TextureFormat, w: u32, h: u32, rng: &mut Rng| {
        let img = image::RgbImage::from_fn(w, h, |_, _| {
            image::Rgb([0, 1, 2].map(|_| 40 + rng.below(200) as u8))
        });
        png_texture(&format!("gen-{w}x{h}.png"), &img).with_format(format)
    };
    let mut lights = synthetic_lights(2);
    lights.push(Light::dome().with_path("/Env").with_texture(png(
        TextureFormat::LatLong,
        32,
        16,
        &mut rng,
    )));
    let scene = eval.prepare(&lights).unwrap();
    let n = 257;
    let pts = points(&mut rng, n);
    let normals = unit_rows(&mut rng, n);
    assert_resident_irradiance_is_the_host_paths(&r, &scene, &pts, &normals);
    lights[2] = Light::dome().with_path("/Ball").with_texture(png(
        TextureFormat::MirroredBall,
        16,
        16,
        &mut rng,
    ));
    let scene = eval.prepare(&lights).unwrap();
    assert_irradiance_refused(&r, &scene, &pts, &normals, "/Ball", "latlong");
}

#[test]
fn a_gpu_evaluators_device_serves_resident_calls_and_an_empty_scene_writes_zeros() {
    let Some(eval) = common::gpu() else { return };
    let r = Renderer {
        device: eval.wgpu_device().unwrap().clone(),
        queue: eval.wgpu_queue().unwrap().clone(),
        adapter: None,
    };
    let n = 100;
    let dirs = r.buffer(&vec![[0.0, 0.0, -1.0]; n], wgpu::BufferUsages::STORAGE);
    let empty = eval.prepare(&[]).unwrap();
    let out = r.output(n);
    let mut enc = r.encoder();
    empty
        .encode_emission(&mut enc, &dirs, &out, n as u32, Accumulate::Sum)
        .unwrap();
    assert_eq!(r.finish(enc, &out, n), vec![[0.0; 3]; n]);
    // Per light over no lights: nothing to write, nothing written.
    let mut enc = r.encoder();
    empty
        .encode_emission(&mut enc, &dirs, &out, n as u32, Accumulate::PerLight)
        .unwrap();
    assert_eq!(r.finish(enc, &out, n), vec![[0.0; 3]; n]);
}

pub(crate) fn invalid_input(e: LuxError) -> (String, String) {
    match e {
        LuxError::InvalidInput { what, reason } => (what, reason),
        other => panic!("expected InvalidInput, got {other:?}"),
    }
}

#[test]
fn bad_buffers_are_refused_with_typed_errors() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let scene = eval.prepare(&synthetic_lights(3)).unwrap();
    let n = 64;
    let dirs = r.buffer(&vec![[0.0, 0.0, 1.0]; n], wgpu::BufferUsages::STORAGE);
    let out = r.output(3 * n);
    let mut enc = r.encoder();

    // No STORAGE usage.
    let vertex = r.buffer(&vec![[0.0, 0.0, 1.0]; n], wgpu::BufferUsages::VERTEX);
    let (what, reason) = invalid_input(
        scene
            .encode_emission(&mut enc, &vertex, &out, n as u32, Accumulate::Sum)
            .unwrap_err(),
    );
    assert_eq!(what, "directions");
    assert!(reason.contains("STORAGE"), "{reason}");

    // An input too small for `count`.
    let (what, reason) = invalid_input(
        scene
            .encode_emission(&mut enc, &dirs, &out, n as u32 + 1, Accumulate::Sum)
            .unwrap_err(),
    );
    assert_eq!(what, "directions");
    assert!(reason.contains(&format!("{} bytes", n * 12)), "{reason}");

    // An output large enough summed but not per light (3 lights × n rows).
    let small = r.output(n);
    let (what, reason) = invalid_input(
        scene
            .encode_emission(&mut enc, &dirs, &small, n as u32, Accumulate::PerLight)
            .unwrap_err(),
    );
    assert_eq!(what, "out");
    assert!(reason.contains(&format!("need {}", 3 * n * 12)), "{reason}");

    // The output is an input.
    let both = r.buffer(&vec![[0.0, 0.0, 1.0]; n], wgpu::BufferUsages::STORAGE);
    let (what, _) = invalid_input(
        scene
            .encode_emission(&mut enc, &both, &both, n as u32, Accumulate::Sum)
            .unwrap_err(),
    );
    assert_eq!(what, "out");

    // A buffer of another device: wgpu refuses the bind group, luxeval reports it.
    let other = r.another_device();
    let foreign = other.buffer(&vec![[0.0, 0.0, 1.0]; n], wgpu::BufferUsages::STORAGE);
    match scene.encode_emission(&mut enc, &foreign, &out, n as u32, Accumulate::Sum) {
        Err(LuxError::Gpu { .. }) => {}
        other => panic!("expected a GPU error for another device's buffer, got {other:?}"),
    }

    // A scene on the CPU reference has no device.
    let cpu_scene = Evaluator::cpu().prepare(&synthetic_lights(1)).unwrap();
    let (what, _) = invalid_input(
        cpu_scene
            .encode_emission(&mut enc, &dirs, &out, n as u32, Accumulate::Sum)
            .unwrap_err(),
    );
    assert_eq!(what, "backend");

    // Nothing was recorded by the refused calls: the encoder still finishes and submits.
    r.queue.submit([enc.finish()]);
    r.device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
}

/// IES-shaped lights' irradiance is integrated on the device (shaders/irradiance/line.wgsl):
/// GPU-resident calls give the host path's values, rows the kernel could not finish (NaN,
/// recomputed by the host path) aside.
#[test]
fn ies_irradiance_matches_the_host_path() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let scene = eval.prepare(&lights_with_ies()[11..]).unwrap();
    let mut rng = Rng::new(5);
    let n = 97;
    let pts = points(&mut rng, n);
    let normals = unit_rows(&mut rng, n);
    let pts_buf = r.buffer(&pts, wgpu::BufferUsages::STORAGE);
    let nrm_buf = r.buffer(&normals, wgpu::BufferUsages::STORAGE);
    let rows = scene.len() * n;
    let out = r.output(rows);
    let mut enc = r.encoder();
    scene
        .encode_irradiance(
            &mut enc,
            &pts_buf,
            &nrm_buf,
            &out,
            n as u32,
            Accumulate::PerLight,
        )
        .unwrap();
    let got = r.finish(enc, &out, rows);
    let host = scene
        .irradiance(&pts, &normals, Accumulate::PerLight)
        .unwrap();
    let finished: Vec<usize> = (0..rows).filter(|&i| !got[i][0].is_nan()).collect();
    assert!(
        finished.len() * 10 >= rows * 9,
        "{} of {rows} rows finished",
        finished.len()
    );
    let pick = |v: &[[f32; 3]]| finished.iter().map(|&i| v[i]).collect::<Vec<_>>();
    assert_same("IES irradiance PerLight", &pick(&got), &pick(&host));
}

#[test]
fn host_irradiance_lights_are_refused_by_name() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let mut lights = lights_with_ies();
    // A type B profile under angleScale: its grid lines are bent, its irradiance the host's.
    let mut rng = Rng::new(12);
    let mut bent = with_random_ies(random_light(2, "rotate", &mut rng, 102), &mut rng, 6, false);
    if let Some(ies) = bent.shaping.as_mut().and_then(|s| s.ies.as_mut()) {
        ies.angle_scale = 0.8;
    }
    lights.insert(12, bent);
    let ies_path = lights[12].path.clone();
    let scene = eval.prepare(&lights).unwrap();
    let n = 64;
    let pts = r.buffer(&vec![[0.0, 0.0, 0.0]; n], wgpu::BufferUsages::STORAGE);
    let nrm = r.buffer(&vec![[0.0, 1.0, 0.0]; n], wgpu::BufferUsages::STORAGE);
    let out = r.output(n);
    let mut enc = r.encoder();
    match scene.encode_irradiance(&mut enc, &pts, &nrm, &out, n as u32, Accumulate::Sum) {
        Err(e @ LuxError::NotOnDevice { .. }) => {
            let LuxError::NotOnDevice {
                light,
                query,
                reason,
            } = &e
            else {
                unreachable!()
            };
            assert_eq!(light, &ies_path);
            assert_eq!(query, "irradiance");
            assert!(reason.contains("IES"), "{reason}");
            assert!(e.to_string().contains(&ies_path), "{e}");
        }
        other => panic!("expected NotOnDevice, got {other:?}"),
    }
    // Emission and radiance of the same scene are evaluated on the device (the IES lookup is
    // in those kernels).
    scene
        .encode_emission(&mut enc, &nrm, &out, n as u32, Accumulate::Sum)
        .unwrap();
}

/// A textured latlong dome's irradiance tables are exact and never halved. On a device with a
/// 1 MiB storage binding: a 64 × 32 dome's tables (101 KB) and texture fit as they are; a
/// 192 × 96 dome's tables (889 KB) fit once its texture is halved (with the warning), and the
/// kernel integrates it within 1e-4 of the reference; a 256 × 128 dome's tables (1.6 MB) do
/// not fit at all: its irradiance is the reference's bit for bit on that device (no longer a
/// refusal), and the GPU-resident query, which has no host step, refuses it by name.
#[test]
fn irradiance_tables_over_the_binding_limit_are_the_references() {
    let Some(r) = renderer_with(Some(wgpu::Limits {
        max_storage_buffer_binding_size: 1 << 20,
        ..wgpu::Limits::default()
    })) else {
        return;
    };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let cpu = Evaluator::cpu();
    let png = |w: u32, h: u32| {
        let img = image::RgbImage::from_fn(w, h, |x, y| {
            image::Rgb([(x % 200) as u8 + 40, (y % 200) as u8 + 20, 90])
        });
        png_texture(&format!("big-{w}x{h}.png"), &img).with_format(TextureFormat::LatLong)
    };
    let normals = vec![
        [0.0f32, 1.0, 0.0],
        [0.6, 0.0, 0.8],
        [-0.3, -0.5, 0.812_403_8],
    ];
    let points = vec![[0.0f32; 3]; normals.len()];
    for (w, h, halved, device) in [
        (64, 32, false, true),
        (192, 96, true, true),
        (256, 128, false, false),
    ] {
        let dome = vec![Light::dome().with_path("/Dome").with_texture(png(w, h))];
        let scene = eval.prepare(&dome).unwrap();
        let reduced = scene.warnings().iter().any(|m| m.contains("reduced to"));
        assert_eq!(reduced, halved, "{w} × {h}: {:?}", scene.warnings());
        let got = scene
            .irradiance(&points, &normals, Accumulate::Sum)
            .unwrap();
        let want = cpu
            .irradiance(&dome, &points, &normals, Accumulate::Sum)
            .unwrap();
        let pts = r.buffer(&points, wgpu::BufferUsages::STORAGE);
        let nrm = r.buffer(&normals, wgpu::BufferUsages::STORAGE);
        let out = r.output(normals.len());
        let mut enc = r.encoder();
        let resident = scene.encode_irradiance(&mut enc, &pts, &nrm, &out, 3, Accumulate::Sum);
        if device {
            assert!(got != want, "{w} × {h}: the reference's rows");
            for (g, v) in got.iter().zip(&want) {
                let scale = v[0].max(v[1]).max(v[2]);
                assert!(
                    (0..3).all(|c| (g[c] - v[c]).abs() <= 1e-4 * scale),
                    "{g:?} {v:?}"
                );
            }
            resident.unwrap();
            if !halved {
                // `check` compares all four queries.
                let reference = Reference::new(&dome[0], TemperatureMode::Spec).unwrap();
                let report = luxeval::check_against_reference(&eval, &[reference], 16, 3).unwrap();
                assert!(report.host_only.is_empty(), "{:?}", report.host_only);
                assert!(report.pass(), "{report:?}");
            }
        } else {
            assert_eq!(got, want, "{w} × {h}");
            // `check` compares its emission and radiance and says why not its irradiance.
            let reference = Reference::new(&dome[0], TemperatureMode::Spec).unwrap();
            let report = luxeval::check_against_reference(&eval, &[reference], 16, 3).unwrap();
            assert!(
                report
                    .host_only
                    .iter()
                    .any(|(l, why)| l == "/Dome" && why.contains("row tables")),
                "{:?}",
                report.host_only
            );
            assert!(report.pass(), "{report:?}");
            match resident {
                Err(LuxError::NotOnDevice { light, reason, .. }) => {
                    assert_eq!(light, "/Dome");
                    assert!(reason.contains("row tables"), "{reason}");
                }
                other => panic!("expected NotOnDevice, got {other:?}"),
            }
        }
    }
}

#[test]
fn counts_over_the_binding_limit_are_refused_with_the_most_one_call_takes() {
    // A renderer whose device has a 1 MiB storage binding limit (its buffers may be larger).
    let limit = 1u64 << 20;
    let Some(r) = renderer_with(Some(wgpu::Limits {
        max_storage_buffer_binding_size: limit,
        ..wgpu::Limits::default()
    })) else {
        return;
    };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let scene = eval.prepare(&synthetic_lights(2)).unwrap();
    let fits = (limit / 12) as usize;
    let dirs = r.buffer(
        &vec![[0.0, 0.0, 1.0]; fits + 1],
        wgpu::BufferUsages::STORAGE,
    );
    let out = r.output(2 * (fits + 1));
    let mut enc = r.encoder();
    let (what, reason) = invalid_input(
        scene
            .encode_emission(&mut enc, &dirs, &out, fits as u32 + 1, Accumulate::Sum)
            .unwrap_err(),
    );
    assert_eq!(what, "count");
    assert!(
        reason.contains(&format!("at most {fits} samples")),
        "{reason}"
    );
    // Per light, the output binding holds both lights' rows: half as many samples fit.
    let (_, reason) = invalid_input(
        scene
            .encode_emission(&mut enc, &dirs, &out, fits as u32, Accumulate::PerLight)
            .unwrap_err(),
    );
    assert!(
        reason.contains(&format!("at most {} samples", fits / 2)),
        "{reason}"
    );
    // The largest call that fits runs, over buffers larger than the binding limit.
    scene
        .encode_emission(&mut enc, &dirs, &out, fits as u32, Accumulate::Sum)
        .unwrap();
    let got = r.finish(enc, &out, fits);
    let host = scene
        .emission(&vec![[0.0, 0.0, 1.0]; fits], Accumulate::Sum)
        .unwrap();
    assert_eq!(got, host);
}

/// A dome masked by its portals (DESIGN.md §8 P2 mask mode) has its emission and radiance on
/// the device: the GPU-resident `encode_emission` and `encode_radiance` give the host path's
/// values. Untextured behind one window its irradiance is the device's too (Lambert's formula
/// over the portals: `encode_irradiance` gives the host path's rows), and with a second pane of
/// another multiplier above the window (inclusion–exclusion over their overlap), and with a
/// pane through the window at an angle (crossed in either order: the overlap split where the
/// two are crossed at once), within 1e-4 of the reference; `check` lists nothing as host-only.
/// In hint mode the same dome runs on the device as without portals.
#[test]
fn masked_domes_run_on_the_device_where_portals_hide_one_another() {
    let Some(r) = renderer() else { return };
    let dome = Light::dome().with_path("/World/Sky").with_portal(
        luxeval::Portal::new(2.0, 1.0)
            .with_path("/World/Window")
            .with_intensity(3.0)
            .with_transform(glam::DMat4::from_translation(glam::DVec3::new(
                0.0, 0.0, 3.0,
            ))),
    );
    let n = 16;
    let up = vec![[0.0, 0.0, 1.0]; n];
    // Half the points under the window (lit through it), half beside it (dark).
    let points: Vec<[f32; 3]> = (0..n)
        .map(|i| [if i % 2 == 0 { 0.1 } else { 5.0 }, 0.2, 0.0])
        .collect();
    let dirs = r.buffer(&up, wgpu::BufferUsages::STORAGE);
    let pts = r.buffer(&points, wgpu::BufferUsages::STORAGE);
    let out = r.output(n);
    for mode in [luxeval::PortalMode::Hint, luxeval::PortalMode::Mask] {
        let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone())
            .unwrap()
            .with_portal_mode(mode);
        let scene = eval.prepare(std::slice::from_ref(&dome)).unwrap();
        let mut enc = r.encoder();
        scene
            .encode_emission(&mut enc, &dirs, &out, n as u32, Accumulate::Sum)
            .unwrap();
        assert_eq!(r.finish(enc, &out, n), vec![[1.0; 3]; n], "{mode:?}");
        let mut enc = r.encoder();
        scene
            .encode_radiance(&mut enc, &pts, &dirs, &out, n as u32, Accumulate::Sum)
            .unwrap();
        let got = r.finish(enc, &out, n);
        assert_eq!(
            got,
            scene.radiance(&points, &up, Accumulate::Sum).unwrap(),
            "{mode:?}"
        );
        let want: Vec<[f32; 3]> = (0..n)
            .map(|i| match (mode, i % 2) {
                (luxeval::PortalMode::Mask, 0) => [3.0; 3],
                (luxeval::PortalMode::Mask, _) => [0.0; 3],
                _ => [1.0; 3],
            })
            .collect();
        assert_eq!(got, want, "{mode:?}");
        // `encode_irradiance` on a dome's own scene gives the host path's rows bit for bit.
        let device_irradiance = |light: &Light| {
            let scene = eval.prepare(std::slice::from_ref(light)).unwrap();
            let mut enc = r.encoder();
            scene
                .encode_irradiance(&mut enc, &pts, &dirs, &out, n as u32, Accumulate::Sum)
                .unwrap();
            let got = r.finish(enc, &out, n);
            assert_eq!(
                got,
                scene.irradiance(&points, &up, Accumulate::Sum).unwrap(),
                "{mode:?}"
            );
            got
        };
        let got = device_irradiance(&dome);
        if mode == luxeval::PortalMode::Mask {
            // Under the window it fills much of the sky; beside it, it is seen obliquely.
            assert!(got[0][0] > 5.0 * got[1][0] && got[1][0] > 0.0, "{got:?}");
        }
        // A second pane above the window, of another multiplier: a ray up crosses both, the
        // window first (its multiplier counts there), so the device sums it by
        // inclusion–exclusion, as the host path does.
        let pane = |turn: f64, z: f64| {
            luxeval::Portal::new(2.0, 1.0)
                .with_path("/World/Pane")
                .with_transform(glam::DMat4::from_rotation_translation(
                    glam::DQuat::from_rotation_x(turn),
                    glam::DVec3::new(0.0, 0.0, z),
                ))
        };
        device_irradiance(&dome.clone().with_portal(pane(0.0, 3.5)));
        // A pane through the window at 57°: rays cross the two in either order, so which
        // multiplier a ray gets depends on where it starts; the device splits their overlap
        // where they are crossed at once and sums it on the device too.
        let crossed = dome.clone().with_portal(pane(1.0, 3.0));
        device_irradiance(&crossed);
        // Every row finished, within 1e-4 of the reference.
        resident_masked_irradiance_finishes(&r, &crossed, &points, &up, mode);
        if mode == luxeval::PortalMode::Mask {
            let reference = luxeval::Reference::with_portal_mode(
                &crossed,
                luxeval::TemperatureMode::Spec,
                mode,
            )
            .unwrap();
            let report = luxeval::check_against_reference(&eval, &[reference], 16, 3).unwrap();
            assert!(report.host_only.is_empty(), "{:?}", report.host_only);
            assert!(report.pass(), "{report:?}");
        }
    }
}

/// A grid of portals: 20 long thin windows across x (z = 0) and 20 long thin panes of another
/// multiplier across y above them (z = 1), so that from below the middle every window's cone
/// crosses every pane's: 400 overlaps of two, the most that `prepare::portal::
/// OVERLAP_ITERATIONS` admits, most of them clipped for real at each receiver. The kernel sums
/// them within lavapipe's loop budget: `encode_irradiance` (which has no host step, and gives
/// NaN where the kernel is cut short) matches the host path and the reference within 1e-4.
#[test]
fn a_masked_dome_with_the_most_overlaps_the_budget_admits_finishes_on_the_device() {
    let Some(r) = renderer() else { return };
    let strips = 20;
    let strip = |i: usize, z: f64, k: f64| {
        let c = 1.5 * i as f64 - 0.75 * (strips - 1) as f64;
        let (w, h, at) = if z == 0.0 {
            (40.0, 0.5, glam::DVec3::new(0.0, c, z))
        } else {
            (0.5, 40.0, glam::DVec3::new(c, 0.0, z))
        };
        luxeval::Portal::new(w, h)
            .with_path(format!("/World/P{i}_{z}"))
            .with_intensity(k)
            .with_transform(glam::DMat4::from_translation(at))
    };
    let dome = (0..strips).fold(Light::dome().with_path("/World/Sky"), |l, i| {
        l.with_portal(strip(i, 0.0, 1.0))
            .with_portal(strip(i, 1.0, 2.0))
    });
    let n = 64;
    let points: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            [
                -4.0 + (i % 8) as f32,
                -4.0 + (i / 8) as f32,
                -1.0 - (i % 3) as f32 * 0.5,
            ]
        })
        .collect();
    let normals: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let t = i as f32 * 0.37;
            let v = [0.3 * t.sin(), 0.3 * t.cos(), 1.0];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l)
        })
        .collect();
    resident_masked_irradiance_finishes(&r, &dome, &points, &normals, luxeval::PortalMode::Mask);
}

/// A latlong-textured dome masked by a window, a pane of another intensity above it (one ray
/// crosses both: their overlap counts by inclusion–exclusion) and a second window in a wall:
/// its irradiance is the device's (the texture's row integral over each portal and overlap,
/// shaders/irradiance/latlong_polygon.wgsl), so `encode_irradiance` accepts it, and on lavapipe
/// the kernel finishes every receiver of a 32 × 16 map (a row cut short would read NaN) within
/// 1e-4 of the host path and of the CPU reference.
#[test]
fn a_masked_textured_dome_is_resident() {
    let Some(r) = renderer() else { return };
    let mut rng = luxeval::testkit::Rng::new(0x7E_5D);
    let portal = |path: &str, w: f64, h: f64, k: f64, world: glam::DMat4| {
        luxeval::Portal::new(w, h)
            .with_path(path)
            .with_intensity(k)
            .with_transform(world)
    };
    let dome = Light::dome()
        .with_path("/World/Sky")
        .with_texture(
            Texture::new(luxeval::testkit::dome::random_png(32, 16, &mut rng))
                .with_format(TextureFormat::LatLong),
        )
        .with_portal(portal(
            "/World/Window",
            2.0,
            1.0,
            3.0,
            glam::DMat4::from_translation(glam::DVec3::new(0.0, 0.0, 3.0)),
        ))
        .with_portal(portal(
            "/World/Pane",
            2.4,
            1.6,
            1.5,
            glam::DMat4::from_rotation_translation(
                glam::DQuat::from_rotation_x(0.2),
                glam::DVec3::new(0.2, 0.1, 3.6),
            ),
        ))
        .with_portal(portal(
            "/World/Side",
            1.5,
            1.2,
            2.0,
            glam::DMat4::from_rotation_translation(
                glam::DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
                glam::DVec3::new(3.0, 0.5, 1.0),
            ),
        ));
    let n = 64;
    let points: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            [
                -2.0 + 0.5 * (i % 8) as f32,
                -2.0 + 0.5 * (i / 8) as f32,
                (i % 3) as f32 * 0.4,
            ]
        })
        .collect();
    let normals: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let t = i as f32 * 0.61;
            let v = [0.5 * t.sin(), 0.5 * t.cos(), 1.0];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l)
        })
        .collect();
    resident_masked_irradiance_finishes(&r, &dome, &points, &normals, luxeval::PortalMode::Mask);
}

/// `dome` in portal mode `mode` through `encode_irradiance` at (`points`, `normals`): every row lit,
/// finished (the kernel writes NaN where lavapipe's loop budget cut it short, and this path
/// has no host step) and within 1e-4 of the host path and of the CPU reference.
fn resident_masked_irradiance_finishes(
    r: &Renderer,
    dome: &Light,
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    mode: luxeval::PortalMode,
) {
    let n = points.len();
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone())
        .unwrap()
        .with_portal_mode(mode);
    let scene = eval.prepare(std::slice::from_ref(dome)).unwrap();
    let pts = r.buffer(points, wgpu::BufferUsages::STORAGE);
    let nrm = r.buffer(normals, wgpu::BufferUsages::STORAGE);
    let out = r.output(n);
    let mut enc = r.encoder();
    scene
        .encode_irradiance(&mut enc, &pts, &nrm, &out, n as u32, Accumulate::Sum)
        .unwrap();
    let got = r.finish(enc, &out, n);
    let host = scene.irradiance(points, normals, Accumulate::Sum).unwrap();
    let reference = Evaluator::cpu()
        .with_portal_mode(mode)
        .prepare(std::slice::from_ref(dome))
        .unwrap()
        .irradiance(points, normals, Accumulate::Sum)
        .unwrap();
    for i in 0..n {
        let (g, h, c) = (got[i], host[i], reference[i]);
        let scale = c.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "{i}: dark");
        for k in 0..3 {
            assert!(g[k].is_finite(), "{i}: cut short: {g:?}");
            assert!(
                (g[k] - h[k]).abs() <= 1e-4 * scale,
                "{i}: {g:?} vs host path {h:?}"
            );
            assert!(
                (g[k] - c[k]).abs() <= 1e-4 * scale,
                "{i}: {g:?} vs reference {c:?}"
            );
        }
    }
}
