//! The work–precision study of issue 4: run time against error for every accuracy knob.
//!
//! `cargo bench -p monolayer-benches --bench work_precision` regenerates
//! `docs/work_precision.csv` and prints it as a markdown table; `python3
//! docs/plot_work_precision.py` draws `docs/work_precision.png` from it.
//!
//! Protocol. 60 cells in 100² (paper parameters, seed 1) relax for 50 TU at ζ = 0 with
//! margin 25 and dt 0.2. From that one state every configuration runs 20 TU at ζ = 0.005
//! (short enough that trajectories have not separated by chaos). The reference stores every
//! cell on the full domain, in f64, with Heun and dt = 0.01. Errors at the end: the largest
//! centre-of-mass distance to the reference over cells, and the largest |Δφ| over cells and
//! lattice nodes. Time: wall time of the 20 TU on 2 threads (best of 3 runs for runs
//! shorter than 2 s). Configurations marked f32 store the fields in single precision
//! (arithmetic stays f64); the start state is rounded to f32 once.

use std::fmt::Write as _;
use std::time::Instant;

use mechanics::{
    AdaptiveParams, Controller, ModelParams, StateCheck, StepParams, Tissue, Workspace,
};
use phasefield::{Cells, PatchShape, Real};

const T_ACTIVE: f64 = 20.0;
const ZETA: f64 = 0.005;

struct Config {
    name: String,
    margin: usize,
    dt: f64,
    npc: usize,
    /// Single-precision storage.
    f32: bool,
    /// An adaptive step with this local error tolerance (`dt` is the first attempt; the
    /// largest step is the scene's stability estimate).
    adaptive: Option<f64>,
}

/// A run's final state, its best wall time and its evaluations of the right-hand side.
fn run<T: Real>(start: &Cells, centres: &[[f64; 2]], c: &Config) -> (Tissue<T>, f64, u64) {
    let lattice = start.lattice();
    let cells = start
        .resampled(PatchShape::new(lattice, c.margin).unwrap(), centres)
        .to_precision::<T>();
    let steps = (T_ACTIVE / c.dt).round() as usize;
    let sp = StepParams::new(c.dt, c.npc);
    let mut best = f64::INFINITY;
    let mut last = None;
    let mut evaluations = (steps * (1 + c.npc)) as u64;
    for rep in 0..3 {
        let mut t = Tissue::new(cells.clone(), ModelParams::paper(ZETA));
        let mut ws = Workspace::new(t.cells());
        let t0 = Instant::now();
        match c.adaptive {
            None => {
                for _ in 0..steps {
                    t.step(&mut ws, &sp).expect("stable");
                }
            }
            Some(tol) => {
                let p = AdaptiveParams::new(tol, ModelParams::paper(ZETA).max_stable_dt());
                let mut ctrl = Controller::new(c.dt);
                while t.time() < T_ACTIVE {
                    t.step_adaptive(&mut ws, &p, &mut ctrl, T_ACTIVE, &mut StateCheck::default())
                        .expect("stable");
                }
                evaluations = ctrl.evaluations();
            }
        }
        let wall = t0.elapsed().as_secs_f64();
        best = best.min(wall);
        last = Some(t);
        if wall > 2.0 || rep == 2 {
            break;
        }
    }
    (last.unwrap(), best, evaluations)
}

fn errors<T: Real>(reference: &Tissue, t: &Tissue<T>) -> (f64, f64) {
    let lattice = reference.lattice();
    let mut e_c: f64 = 0.0;
    let mut e_phi: f64 = 0.0;
    for i in 0..t.cells().n_cells() {
        e_c = e_c.max(lattice.distance(reference.centres()[i], t.centres()[i]));
        for x in 0..lattice.lx {
            for y in 0..lattice.ly {
                e_phi = e_phi
                    .max((reference.cells().value_at(i, x, y) - t.cells().value_at(i, x, y)).abs());
            }
        }
    }
    (e_c, e_phi)
}

fn main() {
    // cargo bench passes --bench; nothing else is read.
    let pool = monolayer_benches::pool(2);
    pool.install(study);
}

fn study() {
    let relax = monolayer_benches::relaxed_paper_state(25);
    let start = relax.cells().clone();
    let centres = relax.centres().to_vec();

    let reference_cfg = Config {
        name: "reference: full, Heun, dt 0.01".into(),
        margin: 0,
        dt: 0.01,
        npc: 1,
        f32: false,
        adaptive: None,
    };
    let (reference, ref_wall, _) = run::<f64>(&start, &centres, &reference_cfg);
    eprintln!("reference: {ref_wall:.1} s");

    let mut configs = Vec::new();
    for m in [10, 12, 16, 20, 25] {
        configs.push(Config {
            name: format!("margin {m}, Heun, dt 0.05"),
            margin: m,
            dt: 0.05,
            npc: 1,
            f32: false,
            adaptive: None,
        });
    }
    for dt in [1.0, 0.5, 0.2, 0.1, 0.05, 0.02] {
        for (npc, integ) in [(0, "Euler"), (1, "Heun"), (2, "Heun npc 2")] {
            if npc == 0 && dt > 0.2 {
                continue;
            }
            configs.push(Config {
                name: format!("full, {integ}, dt {dt}"),
                margin: 0,
                dt,
                npc,
                f32: false,
                adaptive: None,
            });
        }
    }
    for m in [12, 16, 20, 25] {
        for dt in [1.0, 0.5, 0.2, 0.1] {
            configs.push(Config {
                name: format!("margin {m}, Heun, dt {dt}"),
                margin: m,
                dt,
                npc: 1,
                f32: false,
                adaptive: None,
            });
        }
    }
    configs.push(Config {
        name: "margin 16, Euler, dt 0.2".into(),
        margin: 16,
        dt: 0.2,
        npc: 0,
        f32: false,
        adaptive: None,
    });
    for (m, dts) in [
        (0, &[0.5, 0.1, 0.02][..]),
        (12, &[0.5, 0.2][..]),
        (16, &[0.5, 0.2][..]),
        (25, &[0.5, 0.2, 0.05][..]),
    ] {
        for &dt in dts {
            let place = if m == 0 {
                "full".to_string()
            } else {
                format!("margin {m}")
            };
            configs.push(Config {
                name: format!("{place}, Heun, dt {dt}, f32"),
                margin: m,
                dt,
                npc: 1,
                f32: true,
                adaptive: None,
            });
        }
    }

    // The adaptive step (Heun–Euler pair, PI controller) at several tolerances, from dt 0.5.
    for m in [16, 25, 0] {
        for tol in [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5] {
            let place = if m == 0 {
                "full".to_string()
            } else {
                format!("margin {m}")
            };
            configs.push(Config {
                name: format!("{place}, adaptive, tol {tol:.0e}"),
                margin: m,
                dt: 0.5,
                npc: 1,
                f32: false,
                adaptive: Some(tol),
            });
        }
    }
    // Only the configurations whose name contains WORK_PRECISION_ONLY (all without it).
    if let Ok(only) = std::env::var("WORK_PRECISION_ONLY") {
        configs.retain(|c| c.name.contains(&only));
    }

    let mut csv = String::from(
        "config,margin,dt,npc,precision,adaptive_tolerance,evaluations,wall_s,centre_error,phi_error\n",
    );
    let mut table = String::from(
        "| configuration | wall s (20 TU) | centre error | max φ error |\n|---|---|---|---|\n",
    );
    writeln!(table, "| {} | {ref_wall:.2} | 0 | 0 |", reference_cfg.name).unwrap();
    for c in &configs {
        let (wall, evals, (e_c, e_phi)) = if c.f32 {
            let (t, wall, evals) = run::<f32>(&start, &centres, c);
            (wall, evals, errors(&reference, &t))
        } else {
            let (t, wall, evals) = run::<f64>(&start, &centres, c);
            (wall, evals, errors(&reference, &t))
        };
        eprintln!(
            "{}: {wall:.3} s, {evals} evaluations, centre {e_c:.2e}, phi {e_phi:.2e}",
            c.name
        );
        writeln!(
            csv,
            "\"{}\",{},{},{},{},{},{evals},{wall:.4},{e_c:.3e},{e_phi:.3e}",
            c.name,
            c.margin,
            c.dt,
            c.npc,
            if c.f32 { "f32" } else { "f64" },
            c.adaptive.map_or(String::new(), |t| format!("{t:e}")),
        )
        .unwrap();
        writeln!(
            table,
            "| {} | {wall:.3} | {e_c:.1e} | {e_phi:.1e} |",
            c.name
        )
        .unwrap();
    }
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs");
    std::fs::create_dir_all(dir).unwrap();
    if std::env::var("WORK_PRECISION_ONLY").is_err() {
        std::fs::write(format!("{dir}/work_precision.csv"), csv).unwrap();
    }
    println!("{table}");
}
