//! Guards before work: the memory estimate bounds what a simulation really holds, and
//! hostile scene values end in a clean error instead of a panic, an abort or a hang.

use mechanics::Workspace;
use phasefield::Real;
use scene::Scene;

fn scene(text: &str, set: &[&str]) -> Scene {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    Scene::parse(text, &set).unwrap()
}

fn held<T: Real>(s: &Scene) -> f64 {
    let t = s.tissue::<T>();
    let ws = Workspace::new(t.cells());
    (t.heap_bytes() + ws.heap_bytes()) as f64
}

/// `Scene::memory_estimate` is at least what the tissue and its workspace hold
/// (`heap_bytes`, counted from the buffers' capacities), and at most 2.5× that plus the
/// 16 MiB it allows for the program: from one cell to a full-domain run, in both precisions.
#[test]
fn the_memory_estimate_bounds_what_a_simulation_holds() {
    let base =
        "[domain]\nlx = 200\nly = 200\n[cells]\ncount = 240\nradius = 8.0\n[run]\ntime = 1\n";
    let cases: &[&[&str]] = &[
        &[],
        &["integrator.margin=12"],
        &["cells.count=1"],
        &[
            "cells.count=4",
            "domain.lx=64",
            "domain.ly=64",
            "integrator.margin=0",
        ],
    ];
    for set in cases {
        for precision in ["\"f32\"", "\"f64\""] {
            let p = format!("integrator.precision={precision}");
            let mut all: Vec<&str> = set.to_vec();
            all.push(&p);
            let s = scene(base, &all);
            let held = match s.precision() {
                mechanics::Precision::F32 => held::<f32>(&s),
                mechanics::Precision::F64 => held::<f64>(&s),
            };
            let est = s.memory_estimate();
            let slack = 16.0 * 1024.0 * 1024.0;
            assert!(
                est >= held,
                "{all:?}: estimate {est} below the {held} bytes held"
            );
            assert!(
                est <= 2.5 * held + slack,
                "{all:?}: estimate {est} more than 2.5× the {held} bytes held"
            );
        }
    }
}

/// The hostile values of issue 13 that panicked or hung now fail validation, each naming
/// its key with a fix that can be followed.
#[test]
fn hostile_values_fail_validation_with_their_key() {
    let base =
        "[domain]\nlx = 100\nly = 100\n[cells]\ncount = 60\nradius = 8.0\n[run]\ntime = 10\n";
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["domain.lx=9223372036854775807"],
            &["[domain] lx", "at most 65536"],
        ),
        (
            &["cells.init_radius=1e-10"],
            &["[cells] init_radius", "[1, 8]"],
        ),
        (
            &["cells.radius=0.5", "cells.init_radius=0.5"],
            &["[cells]", "radius"],
        ),
        (
            &["integrator.dt=1e-300"],
            &["[run] time", "more than the 1e9"],
        ),
        (
            &["run.relax_time=4e18"],
            &["[run] relax_time", "shorten the run"],
        ),
        (&["run.time=1e300"], &["[run] time"]),
        (
            &["model.gamma=0", "model.zeta=0.005"],
            &["[model] gamma", "gamma > 0"],
        ),
        (
            &["cells.init=\"positions\"", "cells.positions=[[1.0, 2.0]]"],
            &[
                "[cells] positions",
                "count = 60 cells but 1 positions",
                "one [x, y] pair per cell",
            ],
        ),
    ];
    for (set, needles) in cases {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let e = match Scene::parse(base, &set) {
            Ok(_) => panic!("{set:?} must fail"),
            Err(e) => e.to_string(),
        };
        for n in *needles {
            assert!(e.contains(n), "{set:?}: {e:?} lacks {n:?}");
        }
        assert!(!e.contains("0.000 "), "{set:?}: {e}");
    }
    // A small stability limit is given with its digits, not rounded to 0.
    let e = Scene::parse(base, &["model.gamma=1e-6".into(), "model.zeta=0.01".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("use dt ≤ 1.00e-3"), "{e}");
}
