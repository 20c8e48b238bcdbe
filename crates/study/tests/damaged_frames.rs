//! The frame fuzz corpus: damaged frames of a real run end in a clean error from `analyze`,
//! `render_run` and `export_vtk` (or in a result, where the damage is harmless), never in a
//! panic. 60 cases in CI; `MONOLAYER_FUZZ_CASES` for more.

use std::cell::Cell;
use std::path::Path;

use mechanics::Workspace;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRng, TestRunner};
use study::analyze::{analyze, AnalyzeOptions};
use study::view::{export_vtk, render_run, Frames, RenderOptions};

const NAMES: [&str; 12] = [
    "format",
    "step",
    "time",
    "zeta",
    "lattice",
    "centre",
    "velocity",
    "force",
    "area",
    "shape_tensor",
    "origin",
    "phi",
];

/// A run directory of three frames of a small scene.
fn run_dir(dir: &Path) {
    let text = "[domain]\nlx = 40\nly = 40\n[cells]\ncount = 6\nradius = 5.0\n[model]\nzeta = 0.01\n[integrator]\nmargin = 10\n[run]\ntime = 4\nrelax_time = 0\noutput_every = 1\n";
    let s = scene::Scene::parse(text, &[]).unwrap();
    rundir::prepare(dir, false).unwrap();
    rundir::write_scene(dir, &s).unwrap();
    let mut t = s.tissue::<f32>().expect("a scene of discs builds");
    let mut ws = Workspace::new(t.cells());
    for _ in 0..3 {
        t.observe(&mut ws);
        rundir::write_frame(dir, &t, &ws).unwrap();
        t.step(&mut ws, &s.step_params()).unwrap();
        t.step(&mut ws, &s.step_params()).unwrap();
    }
}

/// How a frame is damaged.
#[derive(Debug, Clone)]
enum Damage {
    /// One value of an array set to this.
    Value(usize, usize, f64),
    /// An array cut to this fraction of its values (its shape no longer matches).
    Cut(usize, f64),
    /// An array left out.
    Drop(usize),
    /// The file cut to this fraction of its bytes.
    Truncate(f64),
    /// One byte of the file changed.
    Flip(f64, u8),
}

fn damage() -> impl Strategy<Value = Damage> {
    let v = prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-1.0),
        Just(1e12),
        Just(0.5),
        Just(-9.3e18)
    ];
    prop_oneof![
        (0..NAMES.len(), 0..64usize, v).prop_map(|(a, i, x)| Damage::Value(a, i, x)),
        (0..NAMES.len(), 0.0..1.0f64).prop_map(|(a, f)| Damage::Cut(a, f)),
        (0..NAMES.len()).prop_map(Damage::Drop),
        (0.0..1.0f64).prop_map(Damage::Truncate),
        (0.0..1.0f64, any::<u8>()).prop_map(|(f, b)| Damage::Flip(f, b)),
    ]
}

fn apply(path: &Path, d: &Damage) {
    match d {
        Damage::Truncate(f) => {
            let b = std::fs::read(path).unwrap();
            std::fs::write(path, &b[..(b.len() as f64 * f) as usize]).unwrap();
        }
        Damage::Flip(f, x) => {
            let mut b = std::fs::read(path).unwrap();
            let k = ((b.len() - 1) as f64 * f) as usize;
            b[k] ^= x | 1;
            std::fs::write(path, &b).unwrap();
        }
        _ => {
            let arrays = rundir::read_npz(path, &NAMES).unwrap();
            let mut out = Vec::new();
            for (k, (name, mut a)) in NAMES.iter().zip(arrays).enumerate() {
                let mut shape = a.shape.clone();
                match *d {
                    Damage::Value(j, i, x) if j == k => {
                        let n = a.data.len();
                        a.data[i % n] = x;
                    }
                    Damage::Cut(j, f) if j == k => {
                        let n = (a.data.len() as f64 * f) as usize;
                        a.data.truncate(n);
                        shape = vec![n as u64];
                    }
                    Damage::Drop(j) if j == k => continue,
                    _ => {}
                }
                let bytes = if ["format", "step", "lattice", "origin"].contains(name) {
                    rundir::npy(&shape, a.data.iter().map(|&v| v as i64))
                } else {
                    rundir::npy(&shape, a.data.iter().copied())
                };
                out.push((name.to_string(), bytes.unwrap()));
            }
            rundir::write_npz(path, out).unwrap();
        }
    }
}

#[test]
fn damaged_frames_end_in_a_clean_error_never_a_panic() {
    let cases: u32 = std::env::var("MONOLAYER_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(60);
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good");
    run_dir(&good);
    let frames: Vec<_> = {
        let mut v: Vec<_> = std::fs::read_dir(good.join("frames"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    };
    assert_eq!(frames.len(), 3);
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(
        config.clone(),
        TestRng::deterministic_rng(config.rng_algorithm),
    );
    let (errors, fine, count) = (Cell::new(0), Cell::new(0), Cell::new(0));
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = runner.run(&(0..3usize, damage()), |(which, d)| {
        count.set(count.get() + 1);
        let dir = tmp.path().join(format!("case{}", count.get()));
        std::fs::create_dir_all(dir.join("frames")).unwrap();
        std::fs::copy(good.join("scene.toml"), dir.join("scene.toml")).unwrap();
        for f in &frames {
            std::fs::copy(f, dir.join("frames").join(f.file_name().unwrap())).unwrap();
        }
        apply(
            &dir.join("frames").join(frames[which].file_name().unwrap()),
            &d,
        );
        let outcome = std::panic::catch_unwind(|| {
            let a = analyze(
                &dir,
                &AnalyzeOptions {
                    crop_side: Some(21),
                    ..Default::default()
                },
            )
            .map(|_| ())
            .map_err(|e| e.to_string());
            let r = render_run(
                &dir,
                &dir.join("png"),
                &RenderOptions::default(),
                &mut |_, _| (),
            )
            .map(|_| ())
            .map_err(|e| e.to_string());
            let v = export_vtk(&dir, &dir.join("vtk"), &Frames::All, &mut |_, _| ())
                .map(|_| ())
                .map_err(|e| e.to_string());
            [a, r, v]
        })
        .map_err(|_| TestCaseError::fail(format!("{d:?} on frame {which}: a panic")))?;
        for o in outcome {
            match o {
                Ok(()) => fine.set(fine.get() + 1),
                Err(e) if e.contains("frame_") || e.contains("frames") => {
                    errors.set(errors.get() + 1)
                }
                Err(e) => {
                    return Err(TestCaseError::fail(format!(
                        "{d:?}: an error that names no file: {e}"
                    )))
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
        Ok(())
    });
    std::panic::set_hook(hook);
    eprintln!(
        "frame fuzz: {} cases × 3 commands: {} clean errors, {} results",
        count.get(),
        errors.get(),
        fine.get()
    );
    result.unwrap();
    assert!(errors.get() > 0);
}
