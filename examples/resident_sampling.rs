//! GPU-resident light sampling as a renderer would call it (`PreparedScene::encode_sample`):
//! its own device, its shading points and normals in its own buffers, luxeval recording the
//! draws (a light chosen per sample on the device, then a direction, its density and the
//! radiance along it) into its own encoder. Also the benchmark of samples per second from
//! GPU-resident buffers: the median time of repeated submits with only a `device.poll(wait)`
//! between them (no upload, no readback).
//!
//! ```sh
//! cargo run --release --ignore-rust-version --example resident_sampling -- \
//!     [LIGHTS] [POINTS] [SAMPLES_PER_POINT] [REPEATS] [bound|power] [PASSES]
//! ```
//! (defaults: 8 lights, 65,536 points × 64 samples = 4,194,304 samples, 10 repeats, `bound`,
//! 1 pass; the lights are `testkit::synthetic_lights`, the benchmark's mix of shaped and
//! unshaped analytic lights). PASSES records the draw that many times into one encoder per
//! submit; the time printed is per pass.

use std::time::{Duration, Instant};

use luxeval::wgpu;
use luxeval::{Evaluator, SampleOptions, Selection};

fn arg(i: usize, default: usize) -> usize {
    std::env::args()
        .nth(i)
        .map(|a| {
            a.replace('_', "")
                .parse()
                .unwrap_or_else(|_| panic!("argument {i} must be a count, not {a:?}"))
        })
        .unwrap_or(default)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let lights = arg(1, 8);
    let n = arg(2, 65_536);
    let k = arg(3, 64).max(1);
    let repeats = arg(4, 10).max(1);
    let selection = match std::env::args().nth(5).as_deref() {
        None | Some("bound") => Selection::Bound,
        Some("power") => Selection::Power,
        Some(other) => panic!("argument 5 must be bound or power, not {other:?}"),
    };
    let passes = arg(6, 1).max(1);

    // 1. The renderer's device and luxeval on it; the lights prepared (uploaded) once.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("renderer"),
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;
    let eval = Evaluator::from_wgpu(device.clone(), queue.clone())?;
    let scene = eval.prepare(&luxeval::testkit::synthetic_lights(lights))?;

    // 2. The renderer's shading points and normals, already on the device (three packed f32
    //    a row). Uploaded here only because this example has no renderer: a 256-wide grid on
    //    the floor y = −2 under the lights, facing up.
    let side = 256usize;
    let points: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let (a, b) = ((i % side) as f32, ((i / side) % side) as f32);
            [
                a / side as f32 * 12.0 - 6.0,
                -2.0,
                b / side as f32 * 12.0 - 6.0,
            ]
        })
        .collect();
    let normals = vec![[0.0f32, 1.0, 0.0]; n];
    let upload = |label, rows: &[[f32; 3]]| {
        let b = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (rows.len() * 12) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&b, 0, bytemuck::cast_slice(rows));
        b
    };
    let points_buf = upload("points", &points);
    let normals_buf = upload("normals", &normals);
    let rows = n * k;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("samples"),
        size: (rows * 32) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let opts = SampleOptions {
        seed: 1,
        selection,
        first_point: 0,
    };

    // 3. A frame: record PASSES draws, submit, wait. The first builds the pipeline, untimed.
    let frame = || -> Result<Duration, Box<dyn std::error::Error>> {
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        for _ in 0..passes {
            scene.encode_sample(
                &mut encoder,
                &points_buf,
                Some(&normals_buf),
                &out,
                n as u32,
                k as u32,
                &opts,
            )?;
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(start.elapsed() / passes as u32)
    };
    frame()?;
    let mut times: Vec<Duration> = (0..repeats).map(|_| frame()).collect::<Result<_, _>>()?;
    times.sort();
    let median = times[times.len() / 2].as_secs_f64();
    // The fewest bytes a pass moves: each point and normal read once per sample (24 bytes,
    // mostly from cache), each 32-byte row written once.
    let bytes = (n * 24 + rows * 32) as f64;
    println!("device: {}", eval.device_name());
    println!(
        "sampling, GPU-resident, {selection:?}: {lights} lights, {n} points × {k} samples, \
         {passes} pass(es) a submit, median of {repeats} submits: {:.4} ms a pass ({:.3e} \
         samples/s, {:.1} GB/s of the {:.1} MB a pass must move; fastest {:.4} ms, slowest \
         {:.4} ms)",
        median * 1e3,
        rows as f64 / median,
        bytes / median / 1e9,
        bytes / 1e6,
        times[0].as_secs_f64() * 1e3,
        times[times.len() - 1].as_secs_f64() * 1e3,
    );

    // 4. The rows stay on the device for the renderer; read point 0's first three back here
    //    only to show them, next to the host path's rows for the same keys.
    let show = k.min(3);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (show * 32) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, (show * 32) as u64);
    queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |r| {
        r.expect("the readback maps");
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let resident: Vec<[f32; 8]> =
        bytemuck::cast_slice(&staging.slice(..).get_mapped_range()?).to_vec();
    let host = scene.sample(&points[..1], Some(&normals[..1]), k, &opts)?;
    for (j, r) in resident.iter().enumerate() {
        println!(
            "sample {j}: resident ω {:?} pdf {} L {:?} light {}; host path ω {:?} pdf {} L {:?} \
             light {}",
            &r[..3],
            r[3],
            &r[4..7],
            r[7],
            host.dirs[j],
            host.pdf[j],
            host.radiance[j],
            host.light[j]
        );
    }
    Ok(())
}
