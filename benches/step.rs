//! One relaxed time step (Heun, dt = 0.2, ζ = 0.005) of the shipped scenes `paper.toml`
//! (60 cells, 100²) and `large.toml` (960 cells, 400²), with patch margins 12 and 25, on one
//! and two threads, with the fields stored in `f64` and (960 cells, margin 12) in `f32`. Throughput is in node updates: cells × patch nodes per step (each step is
//! two sweeps, predictor and corrector), the unit of `node_substeps_per_s` in the reference code's measurements
//! (quoted in `docs/performance.md`).
//!
//! Run with `cargo bench -p monolayer-benches --bench step`.

use criterion::measurement::WallTime;
use criterion::{criterion_main, BenchmarkGroup, BenchmarkId, Criterion, Throughput};
use mechanics::{Tissue, Workspace};
use monolayer_benches::{pool, relaxed_scene, scaling_overrides};
use phasefield::Real;
use scene::Scene;

/// Relaxation before timing, in steps (20 TU): the initial discs have grown to confluence.
const RELAX_STEPS: usize = 100;

fn relaxed<T: Real>(scene: &str, margin: usize) -> (Tissue<T>, Workspace<T>, Scene) {
    relaxed_scene(
        scene,
        &[format!("integrator.margin={margin}")],
        RELAX_STEPS,
        0.005,
    )
}

/// Times one step of `scene` with patch margin `margin` and fields stored as `T`, on one and
/// two threads, under the name `name`.
fn bench_scene<T: Real>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    scene: &str,
    margin: usize,
) {
    let (mut t, mut ws, s) = pool(2).install(|| relaxed::<T>(scene, margin));
    let sp = s.step_params();
    g.throughput(Throughput::Elements(
        (t.cells().n_cells() * t.cells().patch_len()) as u64,
    ));
    for threads in [1, 2] {
        let pool = pool(threads);
        let id = BenchmarkId::new(name, format!("threads={threads}"));
        g.bench_function(id, |b| {
            pool.install(|| b.iter(|| t.step(&mut ws, &sp).unwrap()));
        });
    }
}

fn bench_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("step");
    g.sample_size(10);
    for scene in ["paper.toml", "large.toml"] {
        for margin in [12, 25] {
            let name = format!("{}-m{margin}", scene.trim_end_matches(".toml"));
            bench_scene::<f64>(&mut g, &name, scene, margin);
        }
    }
    // Single-precision storage of the large scene.
    bench_scene::<f32>(&mut g, "large-m12-f32", "large.toml", 12);
    g.finish();
}

/// Cost per cell from 60 to 9600 cells at the paper's density (margin 12, 2 threads),
/// with the cells sorted along a Morton curve (as `monolayer run` keeps them) and in their
/// random initial order, and sorted with the fields stored in `f32`. Throughput is in cells.
fn bench_scaling(c: &mut Criterion) {
    let mut g = c.benchmark_group("scaling");
    g.sample_size(10);
    let pool = pool(2);
    for (n, l) in [
        (60usize, 100usize),
        (240, 200),
        (960, 400),
        (3840, 800),
        (9600, 1265),
    ] {
        let overrides = scaling_overrides(n, l);
        let (mut t, mut ws, s) =
            pool.install(|| relaxed_scene::<f64>("large.toml", &overrides, RELAX_STEPS, 0.005));
        let sp = s.step_params();
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::new("unsorted", n), |b| {
            pool.install(|| b.iter(|| t.step(&mut ws, &sp).unwrap()))
        });
        let mut scratch = Vec::new();
        t.sort_cells(&mut scratch);
        g.bench_function(BenchmarkId::new("sorted", n), |b| {
            pool.install(|| b.iter(|| t.step(&mut ws, &sp).unwrap()))
        });
        let (mut t, mut ws, _) =
            pool.install(|| relaxed_scene::<f32>("large.toml", &overrides, RELAX_STEPS, 0.005));
        t.sort_cells(&mut Vec::new());
        g.bench_function(BenchmarkId::new("sorted-f32", n), |b| {
            pool.install(|| b.iter(|| t.step(&mut ws, &sp).unwrap()))
        });
    }
    g.finish();
}

#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::bench_step, super::bench_scaling);
}
use group::benches;
criterion_main!(benches);
