//! GPU-resident evaluation end to end, as a renderer would call it: its own device, its own
//! buffers, luxeval recording the emission query into its own encoder. Also the benchmark of
//! emission from GPU-resident buffers: the median time of repeated submits of
//! `encode_emission` with only a `device.poll(wait)` between them (no upload, no readback).
//!
//! ```sh
//! cargo run --release --ignore-rust-version --example resident -- \
//!     [LIGHTS] [DIRECTIONS] [REPEATS] [sum|per-light] [PASSES] [packed|vec4] [ROWS]
//! ```
//! (defaults: 8 lights, 4,000,000 directions, 10 repeats, `sum`, 1 pass, `packed` 12-byte rows
//! (`vec4`: 16-byte rows, `RowLayout::Vec4`), the device's rows per invocation (2 on a hardware adapter, 1 on lavapipe; ROWS: 1 to 16,
//! through `testkit::with_rows_per_invocation`); the lights are
//! `testkit::synthetic_lights`, the benchmark's mix of shaped and unshaped analytic lights).
//! PASSES records the query that many times into one encoder per submit, so that a fast GPU's
//! submit-and-wait overhead is spread over them; the time printed is per pass. The bytes a pass
//! must move (each direction read once, each output row written once) over that time give the
//! achieved bandwidth, to compare with the card's (BENCHMARKS.md, issue 11 item 7). Where the
//! adapter has timestamp queries (`TIMESTAMP_QUERY_INSIDE_ENCODERS`), the device's own time
//! between a timestamp before the first pass and one after the last is printed too: the
//! kernels' time without the host's recording, submit and wait.

use std::time::{Duration, Instant};

use luxeval::wgpu;
use luxeval::{Accumulate, Evaluator, RowLayout};

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
    let layout = match std::env::args().nth(6).as_deref() {
        None | Some("packed") => RowLayout::Packed,
        Some("vec4") => RowLayout::Vec4,
        Some(other) => panic!("argument 6 must be packed or vec4, not {other:?}"),
    };
    let words = layout.words() as usize;
    let rows_per_invocation = std::env::args().nth(7).map(|_| arg(7, 1) as u32);
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
        // Timestamps between commands of an encoder, where the adapter has them.
        required_features: adapter.features()
            & (wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS),
        ..Default::default()
    }))?;

    // 2. luxeval on that device, and the lights prepared (uploaded) once.
    let eval = Evaluator::from_wgpu(device.clone(), queue.clone())?;
    let mut scene = eval
        .prepare(&luxeval::testkit::synthetic_lights(lights))?
        .with_row_layout(layout);
    if let Some(r) = rows_per_invocation {
        scene = luxeval::testkit::with_rows_per_invocation(scene, r);
    }

    // 3. The renderer's data, already on the device: unit directions as tightly packed f32
    //    triples (12 bytes a row), or with `vec4` as four f32 (the fourth ignored). Uploaded
    //    here only because this example has no renderer.
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
    let rows_in: Vec<f32> = dirs
        .iter()
        .flat_map(|d| [d[0], d[1], d[2], 0.0].into_iter().take(words))
        .collect();
    let dirs_buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("directions"),
        size: (n * 4 * words) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&dirs_buf, 0, bytemuck::cast_slice(&rows_in));
    drop(rows_in);
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("emission"),
        size: (out_rows * 4 * words) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });

    // 4. A frame: record PASSES queries, submit, wait. The first builds the pipeline and is not
    //    timed. With timestamps, the device's time from before the first pass to after the last.
    let stamps = device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
        .then(|| Stamps::new(&device));
    let frame = || -> Result<(Duration, Option<f64>), Box<dyn std::error::Error>> {
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        if let Some(s) = &stamps {
            encoder.write_timestamp(&s.set, 0);
        }
        for _ in 0..passes {
            scene.encode_emission(&mut encoder, &dirs_buf, &out, n as u32, acc)?;
        }
        if let Some(s) = &stamps {
            encoder.write_timestamp(&s.set, 1);
            s.resolve(&mut encoder);
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let wall = start.elapsed() / passes as u32;
        let gpu = match &stamps {
            Some(s) => Some(s.seconds(&device, &queue)? / passes as f64),
            None => None,
        };
        Ok((wall, gpu))
    };
    frame()?;
    let runs: Vec<(Duration, Option<f64>)> =
        (0..repeats).map(|_| frame()).collect::<Result<_, _>>()?;
    let mut times: Vec<Duration> = runs.iter().map(|r| r.0).collect();
    times.sort();
    let median = times[times.len() / 2].as_secs_f64();
    let evals = (lights * n) as f64;
    // The fewest bytes a pass moves through device memory: every direction read once, every
    // output row written once (the light records are a few hundred bytes, read from cache),
    // at the layout's stride.
    let bytes = ((n + out_rows) * 4 * words) as f64;
    println!("device: {}", eval.device_name());
    println!(
        "emission, GPU-resident, {acc:?}, {layout:?} rows, {} an invocation: {lights} lights × {n} directions, \
         {passes} pass(es) a submit, median of {repeats} submits: {:.4} ms a pass ({:.3e} \
         evaluations/s, {:.1} GB/s of the {:.1} MB a pass must move; fastest {:.4} ms, slowest \
         {:.4} ms)",
        rows_per_invocation.map_or("default".into(), |r| r.to_string()),
        median * 1e3,
        evals / median,
        bytes / median / 1e9,
        bytes / 1e6,
        times[0].as_secs_f64() * 1e3,
        times[times.len() - 1].as_secs_f64() * 1e3,
    );
    let mut device_times: Vec<f64> = runs.iter().filter_map(|r| r.1).collect();
    if device_times.is_empty() {
        println!("timestamps: this adapter has no TIMESTAMP_QUERY_INSIDE_ENCODERS");
    } else {
        device_times.sort_by(f64::total_cmp);
        let t = device_times[device_times.len() / 2];
        println!(
            "emission, device timestamps, {acc:?}, {layout:?} rows: {:.4} ms a pass ({:.3e} \
             evaluations/s, {:.1} GB/s; fastest {:.4} ms, slowest {:.4} ms)",
            t * 1e3,
            evals / t,
            bytes / t / 1e9,
            device_times[0] * 1e3,
            device_times[device_times.len() - 1] * 1e3,
        );
    }

    // 5. The results stay on the device for the renderer; read three rows back here only to
    //    show them, next to the host path's values for the same directions.
    // (Per light, the first rows are light 0's.)
    let rows = n.min(3);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (rows * 4 * words) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
    encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, (rows * 4 * words) as u64);
    queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |r| {
        r.expect("the readback maps");
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let resident: Vec<f32> = bytemuck::cast_slice(&staging.slice(..).get_mapped_range()?).to_vec();
    let host = scene.emission(&dirs[..rows], acc)?;
    for i in 0..rows {
        println!(
            "row {i}: resident {:?}, host path {:?}",
            &resident[i * words..(i + 1) * words],
            host[i]
        );
    }
    Ok(())
}

/// Two timestamps and the buffers their ticks are read back through.
struct Stamps {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl Stamps {
    fn new(device: &wgpu::Device) -> Self {
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Stamps {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolved: buffer(
                "timestamps",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            readback: buffer(
                "timestamps read back",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
        }
    }

    fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2, &self.resolved, 0);
        encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.readback, 0, 16);
    }

    /// The seconds between the two timestamps of the last submitted frame.
    fn seconds(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<f64, Box<dyn std::error::Error>> {
        self.readback
            .slice(..)
            .map_async(wgpu::MapMode::Read, |r| r.expect("the timestamps map"));
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let ticks: [u64; 2] =
            bytemuck::pod_read_unaligned(&self.readback.slice(..).get_mapped_range()?);
        self.readback.unmap();
        Ok(ticks[1].saturating_sub(ticks[0]) as f64 * queue.get_timestamp_period() as f64 * 1e-9)
    }
}
