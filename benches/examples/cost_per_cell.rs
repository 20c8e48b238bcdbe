//! The documented run for the cost per cell at sizes too large for criterion (issue 4):
//! `N` cells in an `L × L` box at the paper's density (15 cells per 50²), margin 12, dt 0.2,
//! Heun, ζ = 0.005, cells sorted along the Morton curve as `monolayer run` keeps them.
//! `RELAX_STEPS` (default 3) steps at ζ = 0 from the initial discs, then `STEPS` timed steps.
//!
//! ```text
//! cargo run --release -p monolayer-benches --example cost_per_cell -- N L [STEPS] [THREADS] [f32|f64] [RELAX_STEPS] [MARGIN]
//! cargo run --release -p monolayer-benches --example cost_per_cell -- 100000 4082 4
//! ```
//!
//! Prints the wall time per step and per cell and step. The kernels do not branch on the
//! field values, but the cost depends on where the patches sit: a patch that crosses the
//! lattice's edge has its columns cut into two runs. After 3 steps few cells have moved; give
//! more `RELAX_STEPS` for a state in which the cells have spread out (issue 14 uses 250).
//! `MARGIN` replaces the paper's margin 12 (the default of `monolayer run` is 16).

use std::time::Instant;

use mechanics::{Tissue, Workspace};
use monolayer_benches::relaxed_scene;
use phasefield::Real;

/// Not inlined, so that callgrind can count it alone (`--toggle-collect='*time_steps*'`).
#[inline(never)]
fn time_steps<T: Real>(
    mut t: Tissue<T>,
    mut ws: Workspace<T>,
    sp: mechanics::StepParams,
    steps: usize,
) -> f64 {
    t.sort_cells(&mut Vec::new());
    let t0 = Instant::now();
    for _ in 0..steps {
        t.step(&mut ws, &sp).expect("stable");
    }
    t0.elapsed().as_secs_f64() / steps as f64
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: cost_per_cell N L [STEPS] [THREADS] [f32|f64] [RELAX_STEPS] [MARGIN]";
    let n: usize = args.first().and_then(|a| a.parse().ok()).expect(usage);
    let l: usize = args.get(1).and_then(|a| a.parse().ok()).expect(usage);
    let steps: usize = args.get(2).map_or(10, |a| a.parse().expect(usage));
    let threads: usize = args.get(3).map_or(2, |a| a.parse().expect(usage));
    let f32 = args.get(4).is_some_and(|a| a == "f32");
    let relax: usize = args.get(5).map_or(3, |a| a.parse().expect(usage));
    let mut overrides = monolayer_benches::scaling_overrides(n, l).to_vec();
    if let Some(m) = args.get(6) {
        let m: usize = m.parse().expect(usage);
        overrides.push(format!("integrator.margin={m}"));
    }
    let pool = monolayer_benches::pool(threads);
    let step_s = pool.install(|| {
        if f32 {
            let (t, ws, s) = relaxed_scene::<f32>("large.toml", &overrides, relax, 0.005);
            time_steps(t, ws, s.step_params(), steps)
        } else {
            let (t, ws, s) = relaxed_scene::<f64>("large.toml", &overrides, relax, 0.005);
            time_steps(t, ws, s.step_params(), steps)
        }
    });
    println!(
        "{n} cells, {l}², {threads} threads, {}: {:.4} s per step, {:.2} µs per cell and step",
        if f32 { "f32" } else { "f64" },
        step_s,
        step_s * 1e6 / n as f64
    );
}
