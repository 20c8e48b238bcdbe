//! Shared set-up of the criterion benchmarks and studies in this package (`step.rs`,
//! `analysis.rs`, `work_precision.rs`, `stability.rs`, `view.rs`).

use mechanics::{ModelParams, StepParams, Tissue, Workspace};
use phasefield::{init, Lattice, PatchShape, Real};
use scene::Scene;

/// A rayon pool of `threads` threads, for timing on a fixed number of cores.
///
/// # Panics
/// If the pool cannot be built.
pub fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// A shipped scene (`scenes/NAME`) with `--set`-style overrides, built and relaxed for
/// `relax_steps` steps at ζ = 0 with its own integrator, then set to activity `zeta`, with
/// the fields stored in precision `T`.
///
/// # Panics
/// If the scene does not parse, validate or run.
pub fn relaxed_scene<T: Real>(
    name: &str,
    overrides: &[String],
    relax_steps: usize,
    zeta: f64,
) -> (Tissue<T>, Workspace<T>, Scene) {
    let path = format!("{}/../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    let s = Scene::parse(&std::fs::read_to_string(path).unwrap(), overrides).unwrap();
    let mut t = s.tissue::<T>().expect("a scene of discs builds");
    let mut ws = Workspace::new(t.cells());
    t.params_mut().zeta = 0.0;
    for _ in 0..relax_steps {
        t.step(&mut ws, &s.step_params()).unwrap();
    }
    t.params_mut().zeta = zeta;
    (t, ws, s)
}

/// The `--set` overrides of the scaling runs: `n` cells in an `l × l` box with the paper's
/// margin 12 and dt 0.2 (`large.toml` has the paper's density).
pub fn scaling_overrides(n: usize, l: usize) -> [String; 5] {
    [
        format!("cells.count={n}"),
        format!("domain.lx={l}"),
        format!("domain.ly={l}"),
        "integrator.margin=12".into(),
        "integrator.dt=0.2".into(),
    ]
}

/// The studies' starting state: 60 cells in 100² (paper parameters, seed 1) relaxed for
/// 50 TU at ζ = 0 with dt 0.2 and the given patch margin.
pub fn relaxed_paper_state(margin: usize) -> Tissue {
    let lattice = Lattice::new(100, 100);
    let centres = init::positions(lattice, 60, 4.0, &init::Layout::Random { seed: 1 }).unwrap();
    let cells = init::discs(
        lattice,
        PatchShape::new(lattice, margin).unwrap(),
        &centres,
        4.0,
        2.5,
    );
    let mut relax = Tissue::new(cells, ModelParams::paper(0.0));
    let mut ws = Workspace::new(relax.cells());
    for _ in 0..250 {
        relax.step(&mut ws, &StepParams::new(0.2, 1)).unwrap();
    }
    relax
}
