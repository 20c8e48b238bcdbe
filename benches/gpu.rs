//! The GPU step (the `gpu` crate) on whichever Vulkan adapter is present: lavapipe, Mesa's
//! CPU driver, on the development machines and CI; a GPU where there is one. One relaxed step
//! (Heun, dt = 0.2, ζ = 0.005, margin 12, f32) of `paper.toml` (60 cells) and `large.toml`
//! (960 cells), timed as 8 steps queued and waited for, so that the figure includes the
//! dispatches but no read-back. Throughput in node updates (cells × patch nodes per step),
//! the unit of the `step` bench.
//!
//! Without an adapter the bench says so and times nothing.
//!
//! Run with `cargo bench -p monolayer-benches --bench gpu`; larger states and the bandwidth
//! roof: `docs/gpu_check.sh`.

use criterion::{criterion_main, Criterion, Throughput};
use mechanics::backend::Backend;
use monolayer_benches::relaxed_scene;

const RELAX_STEPS: usize = 100;
const BATCH: u64 = 8;

fn bench_gpu(c: &mut Criterion) {
    if let Err(e) = gpu::adapter_info() {
        eprintln!("no GPU bench: {e}");
        return;
    }
    let mut g = c.benchmark_group("gpu");
    g.sample_size(10);
    for scene in ["paper.toml", "large.toml"] {
        let (tissue, _, s) = relaxed_scene::<f32>(
            scene,
            &["integrator.margin=12".into(), "integrator.dt=0.2".into()],
            RELAX_STEPS,
            0.005,
        );
        let sp = s.step_params();
        let mut backend = gpu::GpuBackend::new(&tissue, &sp).unwrap();
        g.throughput(Throughput::Elements(
            BATCH * (tissue.cells().n_cells() * tissue.cells().patch_len()) as u64,
        ));
        let name = format!("{}-m12-x{BATCH}", scene.trim_end_matches(".toml"));
        g.bench_function(name, |b| {
            b.iter(|| {
                for _ in 0..BATCH {
                    backend.step(&tissue, &sp).unwrap();
                }
                backend.wait().unwrap();
            });
        });
    }
    g.finish();
}

fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench_gpu(&mut c);
    c.final_summary();
}

criterion_main!(benches);
