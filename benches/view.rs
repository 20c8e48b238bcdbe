//! Pictures and ParaView files of one 400 × 400 frame of `large.toml` (960 cells, ζ = 0.005
//! after 40 TU of relaxation and 20 TU of activity), each as a user runs it on a run
//! directory: read the frame, rebuild and evaluate the state, then
//! - `render-plain`: contours of the cells, PNG written (1000 px wide, the default);
//! - `render-full`: cells filled by speed with a colour bar, director, defects, flow and
//!   deformation axes (the smoothing and the defect detection included);
//! - `export-vtk`: the `.vti` of the fields, the `.vtp` of the cells and the two `.pvd`.
//!
//! Run with `cargo bench -p monolayer-benches --bench view`.

use criterion::{criterion_main, Criterion};
use mechanics::Workspace;
use scene::Scene;
use study::view::{export_vtk, render_run, Colour, Frames, RenderOptions};

fn run_dir(dir: &std::path::Path) {
    let path = format!("{}/../scenes/large.toml", env!("CARGO_MANIFEST_DIR"));
    let s = Scene::parse(&std::fs::read_to_string(path).unwrap(), &[]).unwrap();
    let mut t = s.tissue::<f32>().expect("a scene of discs builds");
    let mut ws = Workspace::new(t.cells());
    for k in 0..300 {
        t.params_mut().zeta = if k < 200 { 0.0 } else { 0.005 };
        t.step(&mut ws, &s.step_params()).unwrap();
    }
    t.observe(&mut ws);
    rundir::write_scene(dir, &s).unwrap();
    rundir::write_frame(dir, &t, &ws).unwrap();
}

fn bench_view(c: &mut Criterion) {
    let pool = monolayer_benches::pool(2);
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    pool.install(|| run_dir(dir));
    let out = dir.join("out");
    let mut g = c.benchmark_group("view-400-960-cells");
    g.sample_size(10);
    let plain = RenderOptions::default();
    let full = RenderOptions {
        colour: Colour::Velocity,
        director: true,
        defects: true,
        flow: true,
        axes: true,
        ..RenderOptions::default()
    };
    for (name, opts) in [("render-plain", plain), ("render-full", full)] {
        g.bench_function(name, |b| {
            pool.install(|| b.iter(|| render_run(dir, &out, &opts, &mut |_, _| ()).unwrap()))
        });
    }
    g.bench_function("export-vtk", |b| {
        pool.install(|| b.iter(|| export_vtk(dir, &out, &Frames::All, &mut |_, _| ()).unwrap()))
    });
    g.finish();
}

#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::bench_view);
}
use group::benches;
criterion_main!(benches);
