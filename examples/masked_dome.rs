//! Radiance throughput of the masked dome of assets/window_room.usda (DESIGN.md §8 P2 mask
//! mode): the GPU kernel (the portal crossing of shaders/portal.wgsl), the same dome unmasked
//! (hint mode) on the GPU, and the CPU reference, on the same rays: receivers in the room, half
//! the rays aimed at the window (and just past its edges), half uniform. Prints the best of
//! three calls of `PreparedScene::radiance` each (upload and readback included) and how many
//! rays are lit, which must agree between the masked GPU and CPU rows.
//!
//! ```sh
//! cargo run --release --ignore-rust-version --example masked_dome -- [RAYS]
//! ```
//! (default 4,194,304 rays; `--device`-like choice: the GPU rows need an adapter, lavapipe with
//! `VK_DRIVER_FILES` pointing at it).

use std::time::Instant;

use luxeval::{Accumulate, Evaluator, PortalMode, Rng, Stage};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(4 << 20, |a| a.parse().expect("RAYS: a count"));
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/window_room.usda");
    let lights = Stage::load(std::path::Path::new(scene), None)
        .and_then(|s| s.evaluable(&[]))
        .expect("the window room");
    let mut rng = Rng::new(1);
    let (mut pts, mut dirs) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let x = [
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(0.0, 2.5),
        ];
        // The window: 2 × 1.5 at (0, 1.75, 3), facing +Z.
        let d = if i % 2 == 0 {
            let t = [rng.range(-1.2, 1.2), 1.75 + rng.range(-0.9, 0.9), 3.0];
            [t[0] - x[0], t[1] - x[1], t[2] - x[2]]
        } else {
            rng.unit().to_array()
        };
        pts.push(x.map(|v| v as f32));
        dirs.push(d.map(|v| v as f32));
    }
    let mut rows = vec![("cpu reference, mask", Evaluator::cpu(), PortalMode::Mask)];
    match Evaluator::gpu() {
        Ok(g) => {
            println!("GPU: {}", g.device_name());
            rows.push(("gpu, mask", g.clone(), PortalMode::Mask));
            rows.push(("gpu, hint (unmasked)", g, PortalMode::Hint));
        }
        Err(e) => println!("no GPU rows: {e}"),
    }
    for (name, eval, mode) in rows {
        let scene = eval
            .with_portal_mode(mode)
            .prepare(&lights)
            .expect("prepare");
        // The first call builds the pipelines.
        scene
            .radiance(&pts[..1024], &dirs[..1024], Accumulate::Sum)
            .expect("radiance");
        let (mut best, mut lit) = (f64::INFINITY, 0);
        for _ in 0..3 {
            let t = Instant::now();
            let out = scene
                .radiance(&pts, &dirs, Accumulate::Sum)
                .expect("radiance");
            best = best.min(t.elapsed().as_secs_f64());
            lit = out.iter().filter(|v| v[0] > 0.0).count();
        }
        println!(
            "{name}: {n} rays in {best:.3} s (best of 3): {:.2} M rays/s, {lit} lit",
            n as f64 / best / 1e6
        );
    }
}
