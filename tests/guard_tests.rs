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
    let t = s.tissue::<T>().expect("a scene of discs builds");
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

/// Keys of a scene file, and hostile and ordinary values for them (TOML literals).
const KEYS: [&str; 56] = [
    "domain.lx",
    "domain.ly",
    "cells.count",
    "cells.radius",
    "cells.init_radius",
    "cells.init",
    "cells.positions",
    "cells.from",
    "model.gamma",
    "model.mu",
    "model.lambda",
    "model.kappa",
    "model.xi",
    "model.zeta",
    "model.pressure",
    "integrator.dt",
    "integrator.npc",
    "integrator.margin",
    "integrator.precision",
    "integrator.stability_check",
    "integrator.adaptive",
    "integrator.tolerance",
    "integrator.dt_max",
    "run.relax_time",
    "run.time",
    "run.seed",
    "run.output_every",
    "run.series_every",
    "polarity.alpha",
    "polarity.rotational_diffusion",
    "polarity.align",
    "polarity.align_rate",
    "polarity.propulsion",
    "polarity.angle",
    "adhesion.omega",
    "polarity.contact_inhibition",
    "population.0.gamma",
    "population.1.zeta",
    "population.0.radius",
    "population.0.align_rate",
    "integrator.backend",
    "walls.kind",
    "walls.kind",
    "walls.thickness",
    "walls.kappa",
    "walls.omega",
    "walls.width",
    "walls.radius",
    "division.cycle_time",
    "division.cycle_spread",
    "division.growth_time",
    "division.axis",
    "division.max_cells",
    "division.extrusion",
    "division.death_rate",
    "division.pressure_gate",
];
const VALUES: [&str; 45] = [
    "0",
    "-1",
    "1",
    "2",
    "8",
    "12",
    "100",
    "0.5",
    "2.5",
    "1e-300",
    "1e300",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "4294967296",
    "-9223372036854775808",
    "\"x\"",
    "true",
    "[[1.0, 2.0]]",
    "[[50.0, 50.0], [10.0, 10.0]]",
    "[]",
    "\"random\"",
    "\"hexagonal\"",
    "\"positions\"",
    "\"frame\"",
    FRAME,
    "\"paper\"",
    "\"interaction\"",
    "\"f32\"",
    "\"f64\"",
    "{ a = 1 }",
    "\"velocity\"",
    "\"force\"",
    "\"shape\"",
    "\"density\"",
    "\"channel\"",
    "\"disc\"",
    "\"wound\"",
    "\"box\"",
    "\"long\"",
    "0.3",
    "\"gpu\"",
    "\"cpu\"",
    "1000",
];

/// Stands for the path of a real frame of the base scene (`frame_path`) among [`VALUES`].
const FRAME: &str = "FRAME";

/// A frame of the fuzz corpus's base scene (48², 4 cells), written once, as a TOML string.
fn frame_path() -> &'static str {
    static PATH: std::sync::OnceLock<(tempfile::TempDir, String)> = std::sync::OnceLock::new();
    &PATH
        .get_or_init(|| {
            let dir = tempfile::tempdir().unwrap();
            let s = Scene::parse(FUZZ_BASE, &[]).unwrap();
            let t = s.tissue::<f32>().unwrap();
            let mut ws = Workspace::new(t.cells());
            t.observe(&mut ws);
            let path = rundir::write_frame(dir.path(), &t, &ws).unwrap();
            let quoted = format!("{:?}", path.display().to_string());
            (dir, quoted)
        })
        .1
}

/// The base scene the fuzz corpus overrides.
const FUZZ_BASE: &str =
    "[domain]\nlx = 48\nly = 48\n[cells]\ncount = 4\nradius = 6.0\n[run]\ntime = 1\nrelax_time = 0\n";

/// What a fuzzed scene ended in.
#[derive(Debug, Default)]
struct Tally {
    cases: usize,
    errors: usize,
    runs: usize,
    run_errors: usize,
    too_big: usize,
    runs_from_frame: usize,
}

/// One fuzzed scene: parse and validate it; if valid and small, build it and take two steps.
/// Returns a message for a panic or an error without a key; records the outcome.
fn fuzz_one(overrides: &[String], tally: &mut Tally) -> Result<(), String> {
    tally.cases += 1;
    let parsed = std::panic::catch_unwind(|| Scene::parse(FUZZ_BASE, overrides))
        .map_err(|_| format!("{overrides:?}: Scene::parse panicked"))?;
    let s = match parsed {
        Err(e) => {
            let msg = e.to_string();
            if msg.is_empty() || msg.contains("0.000 ") {
                return Err(format!("{overrides:?}: unhelpful message {msg:?}"));
            }
            tally.errors += 1;
            return Ok(());
        }
        Ok(s) => s,
    };
    // What the CLI's memory guard would refuse, and lattices too large for a test.
    if s.memory_estimate() > 256.0 * 1024.0 * 1024.0 || s.lattice().len() > 200_000 {
        tally.too_big += 1;
        return Ok(());
    }
    let stepped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // A saved state that cannot be read or does not fit is a clean error too.
        let mut t = rundir::initial_tissue::<f32>(&s).map_err(|e| e.to_string())?;
        let mut ws = Workspace::new(t.cells());
        let p = s.step_params();
        Ok::<_, String>((0..2).try_for_each(|_| match s.adaptive() {
            None => t.step(&mut ws, &p).map(|_| {
                t.proliferate(&mut ws);
            }),
            Some(a) => {
                let mut c = mechanics::Controller::new(p.dt);
                let check = &mut mechanics::StateCheck::default();
                t.step_adaptive(&mut ws, &a, &mut c, s.end_time(), check)
                    .map(|_| ())
            }
        }))
    }))
    .map_err(|_| format!("{overrides:?}: building or stepping the valid scene panicked"))?;
    match stepped {
        Err(msg) if msg.contains("[cells] from") || msg.contains(".npz") => tally.errors += 1,
        Err(msg) => return Err(format!("{overrides:?}: unhelpful message {msg:?}")),
        Ok(stepped) => {
            tally.runs += 1;
            tally.runs_from_frame += usize::from(s.init_from().is_some());
            if stepped.is_err() {
                tally.run_errors += 1;
            }
        }
    }
    Ok(())
}

/// The scene fuzz corpus: random sets of 1–3 overrides drawn from every key and from hostile
/// values (zero, negative, tiny, huge, NaN, ±inf, 2⁶³−1, wrong types, tables). Every case ends
/// in a clean validation error (a message with its key) or a valid scene that builds and
/// steps (or stops with a step error), never a panic. 300 cases in CI; set
/// `MONOLAYER_FUZZ_CASES` for more (the issue-13 note quotes 10⁴).
#[test]
fn fuzzed_scenes_end_in_a_clean_error_or_a_valid_run() {
    use proptest::prelude::*;
    use proptest::test_runner::{Config, TestRng, TestRunner};
    let cases: u32 = std::env::var("MONOLAYER_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300);
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::deterministic_rng(config.rng_algorithm);
    let mut runner = TestRunner::new_with_rng(config, rng);
    // A third of the cases start from a saved frame of the base scene, so that overrides meet
    // `init = "frame"` too; half have a channel, so that the wall keys meet walls; half divide
    // (a cycle of 0.5 TU: the cells divide within the two steps).
    let overrides = (
        prop::collection::vec((0..KEYS.len(), 0..VALUES.len()), 1..=3),
        0..3,
        proptest::bool::ANY,
        proptest::bool::ANY,
    )
        .prop_map(|(v, base, walls, divide)| {
            let from_frame = (base == 0).then(|| {
                [
                    "cells.init=\"frame\"".to_string(),
                    format!("cells.from={}", frame_path()),
                ]
            });
            let channel = walls.then(|| "walls.kind=\"channel\"".to_string());
            let division = divide.then(|| "division.cycle_time=0.5".to_string());
            from_frame
                .into_iter()
                .flatten()
                .chain(channel)
                .chain(division)
                .chain(v.into_iter().map(|(k, x)| match VALUES[x] {
                    FRAME => format!("{}={}", KEYS[k], frame_path()),
                    v => format!("{}={v}", KEYS[k]),
                }))
                .collect::<Vec<_>>()
        });
    let tally = std::cell::RefCell::new(Tally::default());
    // Silence the default panic message of caught panics; they are reported as failures.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = runner.run(&overrides, |o| {
        fuzz_one(&o, &mut tally.borrow_mut()).map_err(TestCaseError::fail)
    });
    std::panic::set_hook(hook);
    let t = tally.into_inner();
    eprintln!(
        "scene fuzz: {} cases, {} clean errors, {} valid runs ({} from a saved frame, {} stopped by a step error), {} valid but too large to run here",
        t.cases, t.errors, t.runs, t.runs_from_frame, t.run_errors, t.too_big
    );
    result.unwrap();
    assert!(
        t.errors > 0 && t.runs > 0 && t.runs_from_frame > 0,
        "{t:?}: the corpus must reach both outcomes"
    );
}

/// `Workspace::heap_bytes` counts the patch scratch of every thread of the pool: one cell on
/// a full 64² domain, where the scratch (about 56 bytes per patch node per thread) is more
/// than the lattice sums and the stage buffers together, so that leaving it out would fail.
/// In a pool of 3 threads, whatever the machine.
#[test]
fn the_workspace_counts_every_threads_patch_scratch() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    pool.install(workspace_counts_every_threads_patch_scratch);
}

fn workspace_counts_every_threads_patch_scratch() {
    let s = scene(
        "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 1\nradius = 8.0\n[run]\ntime = 1\n",
        &["integrator.margin=0", "integrator.precision=\"f32\""],
    );
    let t = s.tissue::<f32>().expect("one disc builds");
    let ws = Workspace::new(t.cells());
    let shape = t.cells().shape();
    let scratch = 3 * mechanics::thread_scratch_bytes(shape);
    let sums = 8 * 8 * t.lattice().len();
    let stages = 3 * 4 * shape.len();
    assert!(scratch > sums + stages, "the test must not be vacuous");
    assert!(
        ws.heap_bytes() >= scratch + sums + stages,
        "{} bytes counted, below the {scratch} of the scratch and {} of the sums and stages",
        ws.heap_bytes(),
        sums + stages
    );
}
