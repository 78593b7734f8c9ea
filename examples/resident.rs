//! GPU-resident evaluation end to end, as a renderer would call it: its own device, its own
//! buffers, luxeval recording the emission query into its own encoder. Also the benchmark of
//! emission from GPU-resident buffers: the median time of repeated submits of
//! `encode_emission` with only a `device.poll(wait)` between them (no upload, no readback).
//!
//! ```sh
//! cargo run --release --ignore-rust-version --example resident -- \
//!     [LIGHTS] [DIRECTIONS] [REPEATS] [sum|per-light] [PASSES]
//! ```
//! (defaults: 8 lights, 4,000,000 directions, 10 repeats, `sum`, 1 pass; the lights are
//! `testkit::synthetic_lights`, the benchmark's mix of shaped and unshaped analytic lights).
//! PASSES records the query that many times into one encoder per submit, so that a fast GPU's
//! submit-and-wait overhead is spread over them; the time printed is per pass. The bytes a pass
//! must move (each direction read once, each output row written once) over that time give the
//! achieved bandwidth, to compare with the card's (BENCHMARKS.md, issue 11 item 7).

use std::time::{Duration, Instant};

use luxeval::wgpu;
use luxeval::{Accumulate, Evaluator};

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
    let n = arg(2, 4_000_000);
    let repeats = arg(3, 10).max(1);
    let acc = match std::env::args().nth(4).as_deref() {
        None | Some("sum") => Accumulate::Sum,
        Some("per-light") => Accumulate::PerLight,
        Some(other) => panic!("argument 4 must be sum or per-light, not {other:?}"),
    };
    let passes = arg(5, 1).max(1);
    let out_rows = match acc {
        Accumulate::Sum => n,
        Accumulate::PerLight => lights * n,
    };

    // 1. The renderer's device (luxeval::wgpu, so that the types are luxeval's).
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("renderer"),
        // The adapter's own limits: the largest storage bindings it offers.
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;

    // 2. luxeval on that device, and the lights prepared (uploaded) once.
    let eval = Evaluator::from_wgpu(device.clone(), queue.clone())?;
    let scene = eval.prepare(&luxeval::testkit::synthetic_lights(lights))?;

    // 3. The renderer's data, already on the device: unit directions as tightly packed f32
    //    triples (12 bytes a row). Uploaded here only because this example has no renderer.
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let dirs: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            // A Fibonacci sphere: every direction once, evenly spread.
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            [(r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32]
        })
        .collect();
    let dirs_buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("directions"),
        size: (n * 12) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&dirs_buf, 0, bytemuck::cast_slice(&dirs));
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("emission"),
        size: (out_rows * 12) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });

    // 4. A frame: record PASSES queries, submit, wait. The first builds the pipeline and is not
    //    timed.
    let frame = || -> Result<Duration, Box<dyn std::error::Error>> {
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        for _ in 0..passes {
            scene.encode_emission(&mut encoder, &dirs_buf, &out, n as u32, acc)?;
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(start.elapsed() / passes as u32)
    };
    frame()?;
    let mut times: Vec<Duration> = (0..repeats).map(|_| frame()).collect::<Result<_, _>>()?;
    times.sort();
    let median = times[times.len() / 2].as_secs_f64();
    let evals = (lights * n) as f64;
    // The fewest bytes a pass moves through device memory: every direction read once, every
    // output row written once (the light records are a few hundred bytes, read from cache).
    let bytes = (n * 12 + out_rows * 12) as f64;
    println!("device: {}", eval.device_name());
    println!(
        "emission, GPU-resident, {acc:?}: {lights} lights × {n} directions, {passes} pass(es) a \
         submit, median of {repeats} submits: {:.4} ms a pass ({:.3e} evaluations/s, {:.1} GB/s \
         of the {:.1} MB a pass must move; fastest {:.4} ms, slowest {:.4} ms)",
        median * 1e3,
        evals / median,
        bytes / median / 1e9,
        bytes / 1e6,
        times[0].as_secs_f64() * 1e3,
        times[times.len() - 1].as_secs_f64() * 1e3,
    );

    // 5. The results stay on the device for the renderer; read three rows back here only to
    //    show them, next to the host path's values for the same directions.
    // (Per light, the first rows are light 0's.)
    let rows = n.min(3);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (rows * 12) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, (rows * 12) as u64);
    queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |r| {
        r.expect("the readback maps");
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let resident: Vec<[f32; 3]> =
        bytemuck::cast_slice(&staging.slice(..).get_mapped_range()?).to_vec();
    let host = scene.emission(&dirs[..rows], acc)?;
    for i in 0..rows {
        println!(
            "row {i}: resident {:?}, host path {:?}",
            resident[i], host[i]
        );
    }
    Ok(())
}
