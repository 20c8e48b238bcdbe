//! Where an adaptive time step could pay: phases whose speed changes in time.
//!
//! `cargo run --release -p monolayer-benches --example adaptive_phases`
//!
//! Two phases of the paper scene (60 cells, 100², seed 1, margin 16, f64, 2 threads), each run
//! with fixed steps and with the adaptive step (`mechanics::adaptive`) at several tolerances,
//! against a reference of the same margin with dt 0.02 (so the errors are time-step errors
//! only): the largest centre-of-mass distance at the end, and the evaluations of the
//! right-hand side (the cost; wall time in brackets).
//! - relaxation: 100 TU at ζ = 0 from the initial discs of radius R/2, fast at first (the
//!   cells grow and meet) and slow after;
//! - near the threshold: 50 TU at ζ = 0.002 from the relaxed state, a slow flow.

use std::time::Instant;

use mechanics::{
    AdaptiveParams, Controller, ModelParams, StateCheck, StepParams, Tissue, Workspace,
};
use phasefield::{init, Lattice, PatchShape};

fn start() -> Tissue {
    let lattice = Lattice::new(100, 100);
    let centres = init::positions(lattice, 60, 4.0, &init::Layout::Random { seed: 1 }).unwrap();
    let cells = init::discs(
        lattice,
        PatchShape::new(lattice, 16).unwrap(),
        &centres,
        4.0,
        2.5,
    );
    Tissue::new(cells, ModelParams::paper(0.0))
}

/// Runs `t` for `span` TU with a fixed `dt` (`tol = None`) or adaptively; returns the final
/// tissue, the evaluations and the wall time.
fn run(t: &Tissue, span: f64, dt: f64, tol: Option<f64>) -> (Tissue, u64, f64) {
    let mut t = t.clone();
    let mut ws = Workspace::new(t.cells());
    let end = t.time() + span;
    let t0 = Instant::now();
    let evals = match tol {
        None => {
            let steps = (span / dt).round() as u64;
            for _ in 0..steps {
                t.step(&mut ws, &StepParams::new(dt, 1)).unwrap();
            }
            2 * steps
        }
        Some(tol) => {
            let p = AdaptiveParams::new(tol, t.params().max_stable_dt());
            let mut c = Controller::new(dt);
            while t.time() < end {
                t.step_adaptive(&mut ws, &p, &mut c, end, &mut StateCheck::default())
                    .unwrap();
            }
            eprintln!(
                "    tol {tol:.0e}: {} steps, {} rejected, last dt {:.3}, cap {:.3}",
                c.accepted, c.rejected, c.dt, p.dt_max
            );
            c.evaluations()
        }
    };
    (t, evals, t0.elapsed().as_secs_f64())
}

fn error(a: &Tissue, b: &Tissue) -> f64 {
    let l = a.lattice();
    a.centres()
        .iter()
        .zip(b.centres())
        .map(|(p, q)| l.distance(*p, *q))
        .fold(0.0, f64::max)
}

fn phase(name: &str, from: &Tissue, span: f64) -> Tissue {
    println!("\n{name} ({span} TU)\n| integrator | evaluations | wall s | centre error |\n|---|---|---|---|");
    let (reference, _, _) = run(from, span, 0.02, None);
    for dt in [1.0, 0.5, 0.2, 0.1] {
        let (t, n, w) = run(from, span, dt, None);
        println!(
            "| fixed dt {dt} | {n} | {w:.3} | {:.2e} |",
            error(&t, &reference)
        );
    }
    for tol in [1e-2, 3e-3, 1e-3, 3e-4, 1e-4] {
        let (t, n, w) = run(from, span, 0.5, Some(tol));
        println!(
            "| adaptive tol {tol:.0e} | {n} | {w:.3} | {:.2e} |",
            error(&t, &reference)
        );
    }
    reference
}

fn main() {
    monolayer_benches::pool(2).install(|| {
        let relaxed = phase(
            "relaxation at ζ = 0 from the initial discs",
            &start(),
            100.0,
        );
        let mut near = relaxed.clone();
        near.params_mut().zeta = 0.002;
        phase("near the threshold, ζ = 0.002", &near, 50.0);
    });
}
