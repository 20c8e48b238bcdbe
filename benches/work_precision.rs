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

use mechanics::{ModelParams, StepParams, Tissue, Workspace};
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
}

fn run<T: Real>(start: &Cells, centres: &[[f64; 2]], c: &Config) -> (Tissue<T>, f64) {
    let lattice = start.lattice();
    let cells = start
        .resampled(PatchShape::new(lattice, c.margin).unwrap(), centres)
        .to_precision::<T>();
    let steps = (T_ACTIVE / c.dt).round() as usize;
    let sp = StepParams::new(c.dt, c.npc);
    let mut best = f64::INFINITY;
    let mut last = None;
    for rep in 0..3 {
        let mut t = Tissue::new(cells.clone(), ModelParams::paper(ZETA));
        let mut ws = Workspace::new(t.cells());
        let t0 = Instant::now();
        for _ in 0..steps {
            t.step(&mut ws, &sp).expect("stable");
        }
        let wall = t0.elapsed().as_secs_f64();
        best = best.min(wall);
        last = Some(t);
        if wall > 2.0 || rep == 2 {
            break;
        }
    }
    (last.unwrap(), best)
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
    };
    let (reference, ref_wall) = run::<f64>(&start, &centres, &reference_cfg);
    eprintln!("reference: {ref_wall:.1} s");

    let mut configs = Vec::new();
    for m in [10, 12, 16, 20, 25] {
        configs.push(Config {
            name: format!("margin {m}, Heun, dt 0.05"),
            margin: m,
            dt: 0.05,
            npc: 1,
            f32: false,
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
            });
        }
    }
    configs.push(Config {
        name: "margin 16, Euler, dt 0.2".into(),
        margin: 16,
        dt: 0.2,
        npc: 0,
        f32: false,
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
            });
        }
    }

    let mut csv = String::from("config,margin,dt,npc,precision,wall_s,centre_error,phi_error\n");
    let mut table = String::from(
        "| configuration | wall s (20 TU) | centre error | max φ error |\n|---|---|---|---|\n",
    );
    writeln!(table, "| {} | {ref_wall:.2} | 0 | 0 |", reference_cfg.name).unwrap();
    for c in &configs {
        let (wall, (e_c, e_phi)) = if c.f32 {
            let (t, wall) = run::<f32>(&start, &centres, c);
            (wall, errors(&reference, &t))
        } else {
            let (t, wall) = run::<f64>(&start, &centres, c);
            (wall, errors(&reference, &t))
        };
        eprintln!("{}: {wall:.3} s, centre {e_c:.2e}, phi {e_phi:.2e}", c.name);
        writeln!(
            csv,
            "\"{}\",{},{},{},{},{wall:.4},{e_c:.3e},{e_phi:.3e}",
            c.name,
            c.margin,
            c.dt,
            c.npc,
            if c.f32 { "f32" } else { "f64" }
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
    std::fs::write(format!("{dir}/work_precision.csv"), csv).unwrap();
    println!("{table}");
}
