//! The GPU step's throughput, for `docs/gpu_check.sh` and docs/performance.md: `N` cells at
//! the paper's density (15 cells per 50², a square box of side `L = ⌈√(N · 2500/15)⌉`),
//! hexagonally placed discs of radius 7 (R = 8: the cells touch, as in a confluent tissue),
//! paper parameters, ζ = 0.005, dt 0.2, Heun, f32, on the first Vulkan adapter.
//!
//! ```text
//! cargo run --release -p monolayer-benches --example gpu_throughput -- N [STEPS] [MARGIN] [BANDWIDTH_GB_S]
//! ```
//!
//! Prints one line of `key=value` pairs: the adapter, cells, chunks, seconds per step,
//! node-updates per second (cells × patch nodes per step, the unit of the CPU benches), bytes
//! moved per node-update as counted from the kernels, and the fraction of the bandwidth roof
//! when `BANDWIDTH_GB_S` (the device's memory bandwidth) is given.

use std::time::Instant;

use mechanics::backend::Backend;
use scene::Scene;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: gpu_throughput N [STEPS] [MARGIN] [BANDWIDTH_GB_S]";
    let n: usize = args.first().and_then(|a| a.parse().ok()).expect(usage);
    let steps: usize = args.get(1).map_or(50, |a| a.parse().expect(usage));
    let margin: usize = args.get(2).map_or(16, |a| a.parse().expect(usage));
    let bandwidth: Option<f64> = args.get(3).map(|a| a.parse::<f64>().expect(usage) * 1e9);
    let l = ((n as f64 * 2500.0 / 15.0).sqrt()).ceil() as usize;
    let overrides = [
        format!("cells.count={n}"),
        format!("domain.lx={l}"),
        format!("domain.ly={l}"),
        "cells.init=\"hexagonal\"".to_string(),
        "cells.init_radius=7".to_string(),
        format!("integrator.margin={margin}"),
        "integrator.dt=0.2".to_string(),
        "model.zeta=0.005".to_string(),
        "run.relax_time=0".to_string(),
    ];
    let path = format!("{}/../scenes/paper.toml", env!("CARGO_MANIFEST_DIR"));
    let scene = Scene::parse(&std::fs::read_to_string(path).unwrap(), &overrides).unwrap();
    let t0 = Instant::now();
    let mut tissue = scene.tissue::<f32>().expect("the scene builds");
    tissue.sort_cells(&mut Vec::new());
    let sp = scene.step_params();
    let build = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let mut gpu = gpu::GpuBackend::new(&tissue, &sp).unwrap_or_else(|e| panic!("{e}"));
    let upload = t0.elapsed().as_secs_f64();
    // Warm-up: pipelines compiled, caches and clocks up.
    for _ in 0..5 {
        gpu.step(&tissue, &sp).unwrap();
    }
    gpu.wait().unwrap();
    let t0 = Instant::now();
    for _ in 0..steps {
        gpu.step(&tissue, &sp).unwrap();
    }
    gpu.wait().unwrap();
    let per_step = t0.elapsed().as_secs_f64() / steps as f64;
    // The state is checked (a failed step reports here), so the timing is of real steps.
    gpu.sync(&mut tissue).unwrap();
    let nodes = (n * tissue.cells().patch_len()) as f64;
    let rate = nodes / per_step;
    let bytes = gpu.bytes_per_node_update();
    let mut line = format!(
        "adapter=\"{}\" cells={n} lattice={l} margin={margin} chunks={} steps={steps} s_per_step={per_step:.4e} node_updates_per_s={rate:.3e} bytes_per_node_update={bytes:.1} build_s={build:.1} upload_s={upload:.1}",
        gpu.adapter(),
        gpu.n_chunks(),
    );
    if let Some(bw) = bandwidth {
        let roof = bw / bytes;
        line += &format!(
            " roof_node_updates_per_s={roof:.3e} roof_fraction={:.3}",
            rate / roof
        );
    }
    println!("{line}");
}
