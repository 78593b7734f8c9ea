//! GPU-resident evaluation end to end, as a renderer would call it: its own device, its own
//! buffers, luxeval recording the emission query into its own encoder. Also the benchmark of
//! emission from GPU-resident buffers: the median time of repeated submits of
//! `encode_emission` with only a `device.poll(wait)` between them (no upload, no readback).
//!
//! ```sh
//! cargo run --release --ignore-rust-version --example resident -- [LIGHTS] [DIRECTIONS] [REPEATS]
//! ```
//! (defaults: 8 lights, 4,000,000 directions, 10 repeats; the lights are
//! `testkit::synthetic_lights`, the benchmark's mix of shaped and unshaped analytic lights).

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
        size: (n * 12) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });

    // 4. A frame: record, submit, wait. The first builds the pipeline and is not timed.
    let frame = || -> Result<Duration, Box<dyn std::error::Error>> {
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        scene.encode_emission(&mut encoder, &dirs_buf, &out, n as u32, Accumulate::Sum)?;
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(start.elapsed())
    };
    frame()?;
    let mut times: Vec<Duration> = (0..repeats).map(|_| frame()).collect::<Result<_, _>>()?;
    times.sort();
    let median = times[times.len() / 2].as_secs_f64();
    let evals = (lights * n) as f64;
    println!("device: {}", eval.device_name());
    println!(
        "emission, GPU-resident: {lights} lights × {n} directions, median of {repeats} submits: \
         {:.3} ms ({:.3e} evaluations/s; fastest {:.3} ms, slowest {:.3} ms)",
        median * 1e3,
        evals / median,
        times[0].as_secs_f64() * 1e3,
        times[times.len() - 1].as_secs_f64() * 1e3,
    );

    // 5. The results stay on the device for the renderer; read three rows back here only to
    //    show them, next to the host path's values for the same directions.
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
    let host = scene.emission(&dirs[..rows], Accumulate::Sum)?;
    for i in 0..rows {
        println!(
            "row {i}: resident {:?}, host path {:?}",
            resident[i], host[i]
        );
    }
    Ok(())
}
