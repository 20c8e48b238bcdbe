//! The `monolayer` binary end to end: output files, reproducibility across thread counts, and
//! every bad-scene case with its message and exit status.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::{
    bin, check_rejected, python_has, resume_matches, run_files, run_python, scene_path, stderr,
};

fn run(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut c = bin();
    c.arg("run").arg(scene).arg("--out").arg(out).arg("--quiet");
    for e in extra {
        c.arg(e);
    }
    c.output().expect("the binary runs")
}

/// A short version of the paper scene: 4 TU relaxation, 6 TU activity.
const SHORT: [&str; 8] = [
    "--set",
    "run.relax_time=4",
    "--set",
    "run.time=6",
    "--set",
    "run.output_every=2",
    "--set",
    "run.series_every=1",
];

#[test]
fn a_run_writes_scene_series_and_frames() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&scene_path("paper.toml"), dir.path(), &SHORT);
    assert!(o.status.success(), "{}", stderr(&o));
    let series = std::fs::read_to_string(dir.path().join("series.csv")).unwrap();
    let mut lines = series.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("step,time,zeta,v_rms,s_rms,area_mean,area_min,area_max"));
    // 10 TU at dt = 0.2 with a row every TU: rows at t = 0, 1, ..., 10.
    assert_eq!(lines.count(), 11);
    let frames: Vec<_> = std::fs::read_dir(dir.path().join("frames"))
        .unwrap()
        .collect();
    assert_eq!(frames.len(), 6, "frames at t = 0, 2, ..., 10");
    // The resolved scene parses back and has every default filled in.
    let resolved = std::fs::read_to_string(dir.path().join("scene.toml")).unwrap();
    let scene = scene::Scene::parse(&resolved, &[]).unwrap();
    assert_eq!(scene.file().run.time, 6.0);
    assert_eq!(scene.file().integrator.margin, 12);
    // series.csv is a plain table, and run.json says what its columns are.
    csv_rows(&dir.path().join("series.csv"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("run.json")).unwrap())
            .unwrap();
    assert_eq!(json["precision"], "f32");
    assert_eq!(json["lattice"], serde_json::json!([100, 100]));
    assert_eq!(json["frame_format"], 3);
    assert_eq!(json["columns"]["series.csv"]["v_rms"], "nodes/TU");
    let header = series.lines().next().unwrap();
    for column in header.split(',') {
        assert!(
            json["columns"]["series.csv"][column].is_string(),
            "run.json has no unit for series.csv column {column}"
        );
    }
}

/// The README's three-line snippet, run by NumPy itself. CI installs NumPy; elsewhere the test
/// says so and passes only if NumPy is missing *and* we are not in CI.
#[test]
fn frames_load_in_numpy_without_custom_code() {
    if !python_has("numpy", "numpy") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = run(&scene_path("paper.toml"), dir.path(), &SHORT);
    assert!(o.status.success(), "{}", stderr(&o));
    let script = format!(
        r#"
import numpy as np
f = np.load("{}/frames/frame_00000050.npz")
phi, origin, lx_ly = f["phi"], f["origin"], f["lattice"]
assert phi.shape == (60, 25, 25), phi.shape
# The run's storage precision (f32 by default); widened exactly for the checks below.
assert phi.dtype == np.float32, phi.dtype
phi = phi.astype(np.float64)
assert f["centre"].shape == (60, 2) and f["velocity"].shape == (60, 2) and f["area"].shape == (60,)
assert abs(float(f["time"]) - 10.0) < 1e-9
# The area in the frame is the sum of phi^2 over the patch.
assert np.allclose((phi ** 2).sum(axis=(1, 2)), f["area"], rtol=1e-12)
# Patch element [u, v] sits at lattice node (origin + [u, v]) mod L: its centre of mass agrees.
L = lx_ly.astype(float)
for i in range(60):
    u, v = np.meshgrid(np.arange(25), np.arange(25), indexing="ij")
    for s, idx in ((0, u), (1, v)):
        z = (phi[i] * np.exp(2j * np.pi * ((origin[i, s] + idx) % L[s]) / L[s])).sum()
        c = (np.angle(z) / (2 * np.pi) * L[s]) % L[s]
        d = (c - f["centre"][i, s] + L[s] / 2) % L[s] - L[s] / 2
        assert abs(d) < 1e-9, (i, s, c, f["centre"][i, s])
print("ok")
"#,
        dir.path().display()
    );
    run_python(&script);
}

#[test]
fn the_same_seed_gives_identical_output_with_one_and_two_threads_in_both_precisions() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let mut series = Vec::new();
    for precision in ["f64", "f32"] {
        let p = format!("integrator.precision={precision}");
        for (dir, threads) in [(&a, "1"), (&b, "2")] {
            let mut args = SHORT.to_vec();
            args.extend([
                "--threads",
                threads,
                "--set",
                "model.zeta=0.01",
                "--set",
                &p,
            ]);
            args.push("--overwrite");
            let o = run(&scene_path("paper.toml"), dir.path(), &args);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        let read = |d: &Path, f: &str| std::fs::read(d.join(f)).unwrap();
        assert_eq!(read(a.path(), "series.csv"), read(b.path(), "series.csv"));
        series.push(read(a.path(), "series.csv"));
        for t in ["00000000", "00000030", "00000050"] {
            let f = format!("frames/frame_{t}.npz");
            assert_eq!(read(a.path(), &f), read(b.path(), &f), "{precision} {f}");
        }
    }
    assert_ne!(series[0], series[1], "f32 storage rounds the fields");
}

/// Writes a scene to a temporary file, runs it and returns (exit success, stderr).
fn run_text(text: &str, extra: &[&str]) -> (bool, String, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let o = run(&path, &dir.path().join("out"), extra);
    (o.status.success(), stderr(&o), dir)
}

const GOOD: &str = r#"
[domain]
lx = 100
ly = 100
[cells]
count = 60
radius = 8.0
[run]
time = 1.0
output_every = 1.0
"#;

/// Each bad scene: the binary exits non-zero and names the key and a fix.
#[test]
fn bad_scenes_are_rejected_with_the_key_and_the_fix() {
    let cases: &[(&str, &[&str], &[&str])] = &[
        (
            "unknown key",
            &["--set", "model.zetta=0.01"],
            &["zetta", "expected one of"],
        ),
        (
            "unknown precision",
            &["--set", "integrator.precision=f16"],
            &["integrator.precision", "f64", "f32"],
        ),
        (
            "unknown section",
            &["--set", "physics.zeta=0.01"],
            &["physics"],
        ),
        (
            "adaptive tolerance out of range",
            &[
                "--set",
                "integrator.adaptive=true",
                "--set",
                "integrator.tolerance=2",
            ],
            &["[integrator] tolerance = 2", "between 0 and 1", "use 1e-3"],
        ),
        (
            "dt_max without adaptive",
            &["--set", "integrator.dt_max=1"],
            &["[integrator] dt_max", "only read with adaptive = true"],
        ),
        (
            "adaptive dt_max above the stability estimate",
            &[
                "--set",
                "integrator.adaptive=true",
                "--set",
                "integrator.dt_max=50",
            ],
            &[
                "[integrator] dt_max = 50",
                "leave dt_max out",
                "stability_check = false",
            ],
        ),
        (
            "adaptive Euler",
            &[
                "--set",
                "integrator.adaptive=true",
                "--set",
                "integrator.npc=0",
            ],
            &["[integrator] npc = 0", "Heun with one corrector"],
        ),
        (
            "negative radius",
            &["--set", "cells.radius=-3"],
            &["[cells] radius", "must be positive"],
        ),
        (
            "margin smaller than the radius",
            &["--set", "integrator.margin=5"],
            &["[integrator] margin", "use margin"],
        ),
        (
            "patch larger than the domain",
            &["--set", "integrator.margin=60"],
            &["[integrator] margin", "at most 49"],
        ),
        (
            "more cells than fit",
            &["--set", "cells.count=1000"],
            &["[cells] count", "do not fit", "fewer cells"],
        ),
        (
            "unstable dt",
            &["--set", "integrator.dt=5"],
            &[
                "[integrator] dt",
                "unstable",
                "use dt ≤",
                "stability_check = false",
            ],
        ),
        (
            "zero dt",
            &["--set", "integrator.dt=0"],
            &["[integrator] dt", "positive"],
        ),
        (
            "negative lambda",
            &["--set", "model.lambda=-1"],
            &["[model] lambda"],
        ),
        ("wrong type", &["--set", "cells.count=\"many\""], &["count"]),
        (
            "positions without init",
            &["--set", "cells.positions=[[1.0, 2.0]]"],
            &["[cells] positions", "init = \"positions\""],
        ),
        (
            "positions off the domain",
            &[
                "--set",
                "cells.init=\"positions\"",
                "--set",
                "cells.count=1",
                "--set",
                "cells.positions=[[150.0, 2.0]]",
            ],
            &["[cells] positions", "outside the domain"],
        ),
        (
            "bad override",
            &["--set", "zeta"],
            &["--set zeta", "section.key=value"],
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("scene.toml");
    std::fs::write(&good, GOOD).unwrap();
    for (k, (name, extra, needles)) in cases.iter().enumerate() {
        let pairs: Vec<&[&str]> = extra.chunks(2).collect();
        assert!(
            pairs.iter().all(|p| p.len() == 2 && p[0] == "--set"),
            "{name}"
        );
        let set: Vec<&str> = pairs.iter().map(|p| p[1]).collect();
        check_rejected(&good, &dir.path().join(format!("case{k}")), &set, needles);
    }
    let (ok, err, _d) = run_text("[domain]\nlx = 100\n", &[]);
    assert!(
        !ok && err.contains("missing field") && err.contains("ly"),
        "{err}"
    );
    let (ok, err, _d) = run_text(GOOD, &[]);
    assert!(ok, "the good scene runs: {err}");
    // Guards before work (issue 13): a scene over the memory limit is refused with its
    // estimate and the keys to change; a thread count beyond the cores is capped, not an
    // error, since results do not depend on it.
    let (ok, err, dir) = run_text(GOOD, &["--max-memory", "1M"]);
    assert!(!ok, "over --max-memory must fail");
    for n in [
        "needs about",
        "60 cell(s) of 33×33 patch nodes",
        "--max-memory 1M",
        "[cells] count",
    ] {
        assert!(err.contains(n), "{err:?} lacks {n:?}");
    }
    assert!(!dir.path().join("out/series.csv").exists());
    let (ok, err, _d) = run_text(GOOD, &["--max-memory", "lots"]);
    assert!(!ok && err.contains("give a size such as 8G"), "{err}");
    // A --max-memory above what the machine has lets the estimate through; the allocator's
    // refusal is then the same kind of error, before the directory is written, and not an
    // abort in the first large allocation (issue 53: a 256 GiB lattice aborted with
    // "memory allocation of 206158430208 bytes failed" and left run.json behind). The kernel
    // refuses 256 GiB at once unless it overcommits without a check (vm.overcommit_memory = 1).
    let overcommits =
        std::fs::read_to_string("/proc/sys/vm/overcommit_memory").is_ok_and(|m| m.trim() == "1");
    if !overcommits {
        let (ok, err, dir) = run_text(
            GOOD,
            &[
                "--set",
                "domain.lx=65536",
                "--set",
                "domain.ly=65536",
                "--max-memory",
                "100000T",
            ],
        );
        assert!(!ok, "a run the allocator refuses must fail");
        for n in ["needs about", "allocator refused", "[domain] lx and ly"] {
            assert!(err.contains(n), "{err:?} lacks {n:?}");
        }
        assert!(!err.contains("memory allocation of"), "{err}");
        assert!(!dir.path().join("out").exists(), "nothing is written");
    }
    let (ok, err, _d) = run_text(
        GOOD,
        &["--set", "domain.lx=20000", "--set", "domain.ly=20000"],
    );
    assert!(
        !ok && err.contains("needs about") && !err.contains("panicked"),
        "{err}"
    );
    let (ok, err, _d) = run_text(GOOD, &["--threads", "100000"]);
    assert!(ok && err.contains("capped at the"), "{err}");
}

/// A run that blows up stops with an error naming the step and the cell, exits non-zero and
/// keeps the series written so far. Without line tension (γ = 0) nothing smooths the
/// interfaces, and forward Euler at dt 0.5 (inside the validator's limit) blows up near
/// t = 145 at ζ = 0.01 (measured).
#[test]
fn a_diverging_run_stops_with_the_step_and_the_cell_and_keeps_its_output() {
    let (ok, err, dir) = run_text(
        GOOD,
        &[
            "--set",
            "model.gamma=0",
            "--set",
            "model.zeta=0.01",
            "--set",
            "integrator.npc=0",
            "--set",
            "integrator.dt=0.5",
            "--set",
            "integrator.stability_check=false",
            "--set",
            "run.time=400",
            "--set",
            "run.output_every=50",
            "--set",
            "run.series_every=1",
        ],
    );
    assert!(!ok);
    assert!(
        err.contains("warning: [integrator] dt = 0.5 is above"),
        "{err}"
    );
    assert!(
        err.contains("at step") && err.contains("cell ") && err.contains("reduce [integrator] dt"),
        "{err}"
    );
    // The message names the last whole frame on disk (the last good state, written at the stop).
    let last = rundir::last_frame(&dir.path().join("out")).unwrap();
    assert!(
        err.contains(&format!("keeps frames up to step {last} ")),
        "{err}"
    );
    assert!(
        !err.contains("--resume"),
        "a blow-up is not resumable: {err}"
    );
    let series = std::fs::read_to_string(dir.path().join("out/series.csv")).unwrap();
    assert!(
        series.lines().count() > 10,
        "rows before the blow-up are kept"
    );
    assert!(series
        .lines()
        .skip(1)
        .all(|l| !l.contains("NaN") && !l.contains("inf")));
    assert!(dir.path().join("out/frames/frame_00000000.npz").exists());
}

/// Issue 53: a blow-up in the last step of a run is an error, not a complete run. The run
/// above is run once to find the step that blows up, then again to end exactly on it: on
/// today's main that second run ended as complete (the check ran only at the start of the
/// next step). It must fail naming that step, with no `complete` mark, and keep the last good
/// state: every row finite, and the final frame and checkpoint from before the step.
#[test]
fn a_blow_up_in_the_last_step_is_an_error_and_keeps_the_last_good_state() {
    let args = |time: &str| -> Vec<String> {
        [
            "model.gamma=0",
            "model.zeta=0.01",
            "integrator.npc=0",
            "integrator.dt=0.5",
            "integrator.stability_check=false",
            "run.relax_time=0",
            "run.output_every=50",
            "run.series_every=1",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain(std::iter::once(format!("run.time={time}")))
        .flat_map(|s| ["--set".to_string(), s])
        .collect()
    };
    let first = args("400");
    let first: Vec<&str> = first.iter().map(String::as_str).collect();
    let (ok, err, _dir) = run_text(GOOD, &first);
    assert!(!ok, "the run does not blow up: {err}");
    let step = crate::common::error_step(&err);
    let time = format!("{}", step as f64 * 0.5);
    let second = args(&time);
    let second: Vec<&str> = second.iter().map(String::as_str).collect();
    let (ok, err, dir) = run_text(GOOD, &second);
    let out = dir.path().join("out");
    assert!(
        !ok,
        "a run whose last step blows up ended as a success: {err}"
    );
    assert!(err.contains(&format!("at step {step} ")), "{err}");
    assert!(!out.join(rundir::COMPLETE).exists(), "marked complete");
    let series = std::fs::read_to_string(out.join("series.csv")).unwrap();
    let last_row: u64 = series
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert_eq!(last_row, step - 1, "the last row is the last good state");
    assert!(series
        .lines()
        .skip(1)
        .all(|l| !l.contains("NaN") && !l.contains("inf")));
    let frame = rundir::last_frame(&out).unwrap();
    assert_eq!(frame, step - 1, "the final frame is the last good state");
    let (checkpoint, _) = rundir::checkpoint::checkpoints(&out).pop().unwrap();
    assert_eq!(
        checkpoint,
        step - 1,
        "the final checkpoint is the last good state"
    );
}

/// Every shipped scene parses and validates; `single.toml` runs whole, and its isolated cell
/// stays at rest (velocity at round-off, see the isolated-cell test) and grows towards its
/// equilibrium area: 195.5 after the scene's 500 TU, 195.76 at 1000 TU (measured), below
/// πR² = 201 because the line tension γ compresses the cell against the area constraint μ.
#[test]
fn shipped_scenes_are_valid_and_the_single_cell_rests() {
    for name in ["paper.toml", "single.toml", "large.toml"] {
        let text = std::fs::read_to_string(scene_path(name)).unwrap();
        scene::Scene::parse(&text, &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    let dir = tempfile::tempdir().unwrap();
    let o = run(&scene_path("single.toml"), dir.path(), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let series = std::fs::read_to_string(dir.path().join("series.csv")).unwrap();
    let last: Vec<f64> = series
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let (v_rms, area) = (last[3], last[5]);
    assert!(v_rms < 1e-14, "{v_rms}");
    assert!((area - 195.5).abs() < 0.5, "{area}");
}

/// A second run into the same directory is refused unless `--overwrite` is given, which
/// replaces the old frames instead of mixing them.
#[test]
fn an_earlier_run_is_not_overwritten_by_accident() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&scene_path("paper.toml"), dir.path(), &SHORT);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&scene_path("paper.toml"), dir.path(), &SHORT);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--overwrite"), "{}", stderr(&o));
    let mut args = SHORT.to_vec();
    args.extend(["--overwrite", "--set", "run.output_every=5"]);
    let o = run(&scene_path("paper.toml"), dir.path(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let n = std::fs::read_dir(dir.path().join("frames"))
        .unwrap()
        .count();
    assert_eq!(n, 3, "frames at t = 0, 5, 10 only; the old ones are gone");
}

/// The rows of a CSV after its header, checking that it is a plain table: one header line,
/// no comment lines, every row as long as the header (what pandas and numpy read with their
/// defaults).
fn csv_rows(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let header = text.lines().next().unwrap_or("").split(',').count();
    for (k, l) in text.lines().enumerate() {
        assert!(
            !l.starts_with('#'),
            "{}: comment line {}",
            path.display(),
            k + 1
        );
        assert_eq!(
            l.split(',').count(),
            header,
            "{}: line {}",
            path.display(),
            k + 1
        );
    }
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// `monolayer run` on a short active scene, then `monolayer analyze`: every file is there and
/// the row counts agree with each other.
#[test]
fn analyze_after_run_writes_consistent_files() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--set",
        "run.relax_time=60",
        "--set",
        "run.time=100",
        "--set",
        "run.output_every=10",
        "--set",
        "model.zeta=0.01",
    ];
    let o = run(&scene_path("paper.toml"), dir.path(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let a = bin().arg("analyze").arg(dir.path()).output().unwrap();
    assert!(a.status.success(), "{}", stderr(&a));
    let an = dir.path().join("analysis");
    let obs = csv_rows(&an.join("observables.csv"));
    // Frames at t = 60, 70, ..., 160: the default --from is the end of relaxation.
    assert_eq!(obs.len(), 11);
    let col = |name: &str| -> usize {
        let header = std::fs::read_to_string(an.join("observables.csv")).unwrap();
        header
            .lines()
            .next()
            .unwrap()
            .split(',')
            .position(|c| c == name)
            .unwrap()
    };
    let sum = |name: &str| -> usize {
        obs.iter()
            .map(|r| r[col(name)].parse::<usize>().unwrap())
            .sum()
    };
    let defects = csv_rows(&an.join("defects.csv"));
    assert_eq!(
        defects.len(),
        sum("n_plus") + sum("n_minus") + sum("n_other")
    );
    assert!(sum("n_plus") > 0, "an active monolayer has defects");
    for r in &obs {
        assert_eq!(r[col("net_charge")].parse::<f64>().unwrap(), 0.0);
    }
    let events = csv_rows(&an.join("defect_events.csv"));
    assert_eq!(events.len(), sum("creations") + sum("annihilations"));
    let corr = csv_rows(&an.join("correlations.csv"));
    assert_eq!(corr.len(), 51, "r = 0..=50 on a 100² lattice");
    assert_eq!(corr[0], vec!["0", "1e0", "1e0", "1e0"]);
    let lengths = csv_rows(&an.join("lengths.csv"));
    assert_eq!(lengths.len(), 3);
    let avg = rundir::read_npz(
        &an.join("defect_averages.npz"),
        &["n_plus", "n_minus", "plus_vx", "minus_qxx"],
    )
    .unwrap();
    assert_eq!(avg[0].data[0] as usize, sum("n_plus"));
    assert_eq!(avg[1].data[0] as usize, sum("n_minus"));
    assert_eq!(avg[2].shape, vec![101, 101]);
    // --from restricts the frames.
    let a = bin()
        .arg("analyze")
        .arg(dir.path())
        .args(["--from", "140"])
        .output()
        .unwrap();
    assert!(a.status.success(), "{}", stderr(&a));
    assert_eq!(csv_rows(&an.join("observables.csv")).len(), 3);
    pandas_reads_every_table(dir.path());
}

/// Every CSV of a run directory loads with `pandas.read_csv(path)` and no options, with the
/// columns `run.json` lists and one row per data line. CI installs pandas (`.ci/run`);
/// elsewhere the check is skipped when pandas is missing.
fn pandas_reads_every_table(run_dir: &Path) {
    if !python_has("pandas", "pandas") {
        return;
    }
    let script = format!(
        r#"
import json, os, pandas as pd
d = "{}"
meta = json.load(open(os.path.join(d, "run.json")))
for name, units in meta["columns"].items():
    path = os.path.join(d, name)
    df = pd.read_csv(path)
    lines = open(path).read().splitlines()
    assert sorted(df.columns) == sorted(units), (name, list(df.columns))
    assert len(df) == len(lines) - 1, (name, len(df), len(lines))
print("ok")
"#,
        run_dir.display()
    );
    run_python(&script);
}

/// A missing, partial or foreign run directory gets a message that says what is wrong.
#[test]
fn analyze_explains_what_is_wrong_with_a_run_directory() {
    let dir = tempfile::tempdir().unwrap();
    let analyze = |p: &Path, extra: &[&str]| {
        let o = bin().arg("analyze").arg(p).args(extra).output().unwrap();
        (o.status.success(), stderr(&o))
    };
    let (ok, err) = analyze(&dir.path().join("nowhere"), &[]);
    assert!(!ok && err.contains("no run directory"), "{err}");
    let (ok, err) = analyze(dir.path(), &[]);
    assert!(!ok && err.contains("scene.toml is missing"), "{err}");
    let o = run(&scene_path("paper.toml"), &dir.path().join("run"), &SHORT);
    assert!(o.status.success());
    let rd = dir.path().join("run");
    let (ok, err) = analyze(&rd, &["--from", "1000"]);
    assert!(!ok && err.contains("no frame at or after"), "{err}");
    let (ok, err) = analyze(&rd, &["--box", "24"]);
    assert!(!ok && err.contains("must be odd"), "{err}");
    // Options that aborted or were used as if fine (issue 13).
    for (args, want) in [
        (&["--crop", "100001"][..], "use an odd side up to 201"),
        (
            &["--max-link", "nan"][..],
            "--max-link NaN: give a positive number",
        ),
        (
            &["--max-pair=-1"][..],
            "--max-pair -1: give a positive number",
        ),
    ] {
        let (ok, err) = analyze(&rd, args);
        assert!(!ok && err.contains(want), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // A damaged (truncated) frame.
    let f = rd.join("frames/frame_00000050.npz");
    let bytes = std::fs::read(&f).unwrap();
    std::fs::write(&f, &bytes[..bytes.len() / 2]).unwrap();
    let (ok, err) = analyze(&rd, &[]);
    assert!(!ok && err.contains("frame_00000050.npz"), "{err}");
    // A frame of another format: an archive without the format array.
    std::fs::remove_file(&f).unwrap();
    {
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&f).unwrap());
        zip.start_file("time.npy", zip::write::SimpleFileOptions::default())
            .unwrap();
        std::io::Write::write_all(&mut zip, b"\x93NUMPY").unwrap();
        zip.finish().unwrap();
    }
    let (ok, err) = analyze(&rd, &[]);
    assert!(!ok && err.contains("another version"), "{err}");
    // No frames at all.
    std::fs::remove_dir_all(rd.join("frames")).unwrap();
    let (ok, err) = analyze(&rd, &[]);
    assert!(!ok && err.contains("no frames/ directory"), "{err}");
}

/// The paper's figure 4 in miniature (ζ = 0.005, γ = 0.014; 100 TU relaxation, 600 TU
/// activity, a frame every 5 TU, ~420 defects of each sign): averaged in its own frame, a
/// `+½` defect moves along its axis, and a `−½` defect hardly moves. Measured on the 5 × 5
/// core: `+½` velocity (−0.021, 0.0003) for seed 1 and (−0.013, −0.0010) for seed 2 (along
/// −u, towards the comet's head, as extensile activity drives it); `−½` speed 0.0065 and
/// 0.0037. Asserted: the `+½` motion is along −u, at least 5× its transverse part and 2× the
/// `−½` speed.
#[test]
fn plus_half_defects_self_propel_along_their_axis() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--set",
        "run.relax_time=100",
        "--set",
        "run.time=600",
        "--set",
        "run.output_every=5",
        "--set",
        "model.zeta=0.005",
        "--set",
        "model.gamma=0.014",
        "--set",
        "run.seed=1",
    ];
    let o = run(&scene_path("paper.toml"), dir.path(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let a = bin()
        .arg("analyze")
        .arg(dir.path())
        .args(["--crop", "21"])
        .output()
        .unwrap();
    assert!(a.status.success(), "{}", stderr(&a));
    let names = ["plus_vx", "plus_vy", "minus_vx", "minus_vy", "n_plus"];
    let f = rundir::read_npz(&dir.path().join("analysis/defect_averages.npz"), &names).unwrap();
    assert!(
        f[4].data[0] > 100.0,
        "enough defects to average: {}",
        f[4].data[0]
    );
    let core = |a: &[f64]| -> f64 {
        let mut s = 0.0;
        for u in 8..13 {
            for v in 8..13 {
                s += a[u * 21 + v];
            }
        }
        s / 25.0
    };
    let (pu, pv) = (core(&f[0].data), core(&f[1].data));
    let minus = core(&f[2].data).hypot(core(&f[3].data));
    eprintln!("+1/2 core velocity ({pu:.4}, {pv:.4}); -1/2 core speed {minus:.4}");
    assert!(pu < 0.0 && pu.abs() > 5.0 * pv.abs() && pu.abs() > 2.0 * minus);
}

/// The same scene gives byte-identical frame files whatever the output interval: frames every
/// 10 TU and every 50 TU of the paper scene (50 TU of relaxation, then 250 TU of activity;
/// 1500 steps, six memory re-sorts) agree, file for file, where both write one, and so do the
/// rows of `series.csv`.
#[test]
fn frames_are_identical_whatever_the_output_interval() {
    let (often, rarely) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for (dir, every) in [(&often, "10"), (&rarely, "50")] {
        let o = run(
            &scene_path("paper.toml"),
            dir.path(),
            &[
                "--set",
                "run.relax_time=50",
                "--set",
                "run.time=250",
                "--set",
                &format!("run.output_every={every}"),
            ],
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let names = |d: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d.join("frames"))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    };
    let (a, b) = (names(often.path()), names(rarely.path()));
    assert_eq!(
        (a.len(), b.len()),
        (31, 7),
        "frames at 0, 10, ..., 300 and 0, 50, ..., 300"
    );
    for name in &b {
        assert!(a.contains(name), "{name} is missing from the frequent run");
        let fa = std::fs::read(often.path().join("frames").join(name)).unwrap();
        let fb = std::fs::read(rarely.path().join("frames").join(name)).unwrap();
        assert!(fa == fb, "{name} differs between the output intervals");
    }
    // And every row of the sparse series.csv is in the dense one, character for character.
    let rows = |d: &Path| std::fs::read_to_string(d.join("series.csv")).unwrap();
    let dense = rows(often.path());
    for row in rows(rarely.path()).lines() {
        assert!(dense.lines().any(|r| r == row), "series row {row} differs");
    }
}

/// `monolayer sweep` end to end: a 2 × 2 grid of the paper scene runs, writes one row per run
/// to summary.csv, and a second call takes no run; a bad axis stops before anything runs.
#[test]
fn a_sweep_runs_its_grid_once_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = || {
        bin()
            .args(["sweep"])
            .arg(scene_path("paper.toml"))
            .args(["--vary", "model.zeta=0,0.005", "--seeds", "1-2"])
            .args([
                "--set",
                "run.relax_time=4",
                "--set",
                "run.time=4",
                "--jobs",
                "2",
                "--out",
            ])
            .arg(dir.path())
            .output()
            .unwrap()
    };
    let o = sweep();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("4 of 4 runs taken"), "{}", stderr(&o));
    let summary = std::fs::read_to_string(dir.path().join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 5, "{summary}");
    assert!(summary.starts_with("model.zeta,seed,window_start,"));
    let o = sweep();
    assert!(
        o.status.success() && stderr(&o).contains("0 of 4 runs taken"),
        "{}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("summary.csv")).unwrap(),
        summary
    );
    let bad = bin()
        .args(["sweep"])
        .arg(scene_path("paper.toml"))
        .args(["--vary", "zeta=1", "--out"])
        .arg(dir.path().join("bad"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(
        stderr(&bad).contains("--vary zeta=1: the key needs a section"),
        "{}",
        stderr(&bad)
    );
    assert!(
        !dir.path().join("bad").exists(),
        "nothing is written before the plan is valid"
    );
}

/// `--backend slurm` writes a job array of one task per run that is not complete, and
/// `--collect` refuses to summarise before the runs are done; the real-SLURM round trip is
/// `tests/slurm/check.sh` (run by `.ci/run`).
#[test]
fn the_slurm_backend_writes_one_array_task_per_pending_run() {
    let dir = tempfile::tempdir().unwrap();
    let o = bin()
        .args(["sweep"])
        .arg(scene_path("paper.toml"))
        .args([
            "--vary",
            "model.zeta=0,0.005",
            "--seeds",
            "1-2",
            "--backend",
            "slurm",
            "--threads",
            "2",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let script = std::fs::read_to_string(dir.path().join("slurm/sweep.sbatch")).unwrap();
    assert!(
        script.contains("#SBATCH --array=0-3") && script.contains("--cpus-per-task=2"),
        "{script}"
    );
    assert!(
        script.contains(" run \"$run/scene.toml\" --out \"$run\" --overwrite --threads 2"),
        "{script}"
    );
    let points = std::fs::read_to_string(dir.path().join("slurm/points.txt")).unwrap();
    assert_eq!(points.lines().count(), 4);
    for run in points.lines() {
        let scene = std::fs::read_to_string(Path::new(run).join("scene.toml")).unwrap();
        assert!(scene::Scene::parse(&scene, &[]).is_ok(), "{run}");
    }
    let o = bin()
        .args(["sweep", "--collect", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(stderr(&o).contains("has no complete run"), "{}", stderr(&o));
}

/// `monolayer sweep --analyze` analyses every run once and adds the lengths and defect
/// statistics to the summary; a second call analyses nothing again.
#[test]
fn a_sweep_with_analyze_adds_the_analysis_columns() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = || {
        bin()
            .args(["sweep"])
            .arg(scene_path("paper.toml"))
            .args([
                "--vary",
                "model.zeta=0,0.01",
                "--set",
                "run.relax_time=4",
                "--set",
                "run.time=8",
            ])
            .args([
                "--set",
                "run.output_every=2",
                "--analyze",
                "--quiet",
                "--out",
            ])
            .arg(dir.path())
            .output()
            .unwrap()
    };
    let o = sweep();
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = std::fs::read_to_string(dir.path().join("summary.csv")).unwrap();
    assert!(
        summary.lines().next().unwrap().ends_with(
            ",growth_rate,growth_exponent,length_velocity,length_vorticity,length_q,defect_density,creation_rate"
        ),
        "{summary}"
    );
    assert_eq!(summary.lines().count(), 3);
    let mark = dir
        .path()
        .join("runs/model.zeta=0.01_seed=1/analysis/complete");
    let t0 = std::fs::metadata(&mark).unwrap().modified().unwrap();
    let o = sweep();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::metadata(&mark).unwrap().modified().unwrap(), t0);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("summary.csv")).unwrap(),
        summary
    );
}

/// `monolayer threshold` reads a sweep's summary.csv and writes threshold.csv; without a
/// sweep it says what to run.
#[test]
fn the_threshold_command_tabulates_a_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let o = bin().arg("threshold").arg(dir.path()).output().unwrap();
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("run monolayer sweep --out"),
        "{}",
        stderr(&o)
    );
    std::fs::write(
        dir.path().join("summary.csv"),
        "model.zeta,seed,growth_rate\n0,1,-0.004\n0.004,1,-0.005\n0.008,1,0.002\n",
    )
    .unwrap();
    let o = bin().arg("threshold").arg(dir.path()).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let table = std::fs::read_to_string(dir.path().join("threshold.csv")).unwrap();
    // The rate is −0.005 at ζ = 0.004 and +0.002 at 0.008: the growth estimate is
    // 0.004 + 0.004·5/7. The excess rate is −0.001 and +0.006: 0.004 + 0.004/7.
    let row: Vec<f64> = table
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(
        (row[0] - (0.004 + 0.004 * 5.0 / 7.0)).abs() < 1e-15,
        "{table}"
    );
    assert_eq!(&row[1..3], &[0.004, 0.008]);
    assert!((row[3] - (0.004 + 0.004 / 7.0)).abs() < 1e-15, "{table}");
    assert_eq!(&row[4..], &[0.004, 0.008, 1.0, 2.0]);
}

/// `reproduce` refuses an unknown figure or scale before anything runs, naming the choices,
/// and leaves no output behind.
#[test]
fn reproduce_refuses_unknown_figures_and_scales() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let o = bin()
        .args(["reproduce", "fig9", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("no figure fig9") && e.contains("defect-fields") && e.contains("all"),
        "{e}"
    );
    let o = bin()
        .args(["reproduce", "threshold", "--scale", "huge", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("--scale huge: write quick or paper"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// Rewrites a frame with `change` applied to its arrays (all written back as float64, int64
/// for the integer ones), as a damaged or foreign file would be.
fn rewrite_frame(path: &Path, change: impl Fn(&str, &mut Vec<f64>)) {
    const NAMES: [&str; 13] = [
        "format",
        "id",
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
    let arrays = rundir::read_npz(path, &NAMES).unwrap();
    let mut out = Vec::new();
    for (name, mut a) in NAMES.iter().zip(arrays) {
        change(name, &mut a.data);
        let bytes = if ["format", "id", "step", "lattice", "origin"].contains(name) {
            rundir::npy(&a.shape, a.data.iter().map(|&v| v as i64))
        } else {
            rundir::npy(&a.shape, a.data.iter().copied())
        };
        out.push((name.to_string(), bytes.unwrap()));
    }
    rundir::write_npz(path, out).unwrap();
}

/// `analyze` validates what it reads (issue 13): a frame with NaN φ or a patch origin off the
/// lattice is refused with the file and the array (where NaN φ gave 10 046 "defects" and an
/// origin off the lattice panicked); a stray `frame_abc.npz` is ignored with a note; frames
/// are taken in the order of their `step` arrays, not of their names; no empty table is left
/// behind by a refusal.
#[test]
fn analyze_validates_frames_and_orders_them_by_step() {
    let dir = tempfile::tempdir().unwrap();
    let rd = dir.path().join("run");
    let o = run(&scene_path("paper.toml"), &rd, &SHORT);
    assert!(o.status.success(), "{}", stderr(&o));
    let analyze = || {
        let o = bin().arg("analyze").arg(&rd).output().unwrap();
        (o.status.success(), stderr(&o))
    };
    // Names out of step order: the frame of step 50 renamed to sort first.
    let frames = rd.join("frames");
    std::fs::rename(
        frames.join("frame_00000050.npz"),
        frames.join("frame_0.npz"),
    )
    .unwrap();
    std::fs::write(frames.join("frame_abc.npz"), b"not a frame").unwrap();
    let (ok, err) = analyze();
    assert!(ok, "{err}");
    assert!(
        err.contains("ignored 1 file(s)") && err.contains("frame_abc.npz"),
        "{err}"
    );
    let obs = std::fs::read_to_string(rd.join("analysis/observables.csv")).unwrap();
    let steps: Vec<u64> = obs
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(steps.windows(2).all(|w| w[0] < w[1]), "steps {steps:?}");
    assert_eq!(*steps.last().unwrap(), 50);
    assert!(!err.contains("missing"), "{err}");
    std::fs::remove_dir_all(rd.join("analysis")).unwrap();
    // A frame of the schedule removed (as a full disk would leave it): noted with its step.
    let gone = frames.join("frame_00000030.npz");
    let kept = std::fs::read(&gone).unwrap();
    std::fs::remove_file(&gone).unwrap();
    let (ok, err) = analyze();
    assert!(ok, "{err}");
    assert!(
        err.contains("1 frame(s) of the run's schedule are missing, the first at t ≈ 6.000"),
        "{err}"
    );
    std::fs::write(&gone, kept).unwrap();
    std::fs::remove_dir_all(rd.join("analysis")).unwrap();

    let f = frames.join("frame_00000040.npz");
    let good = std::fs::read(&f).unwrap();
    rewrite_frame(&f, |name, d| {
        if name == "phi" {
            d[7] = f64::NAN;
        }
    });
    let (ok, err) = analyze();
    assert!(
        !ok && err.contains("frame_00000040.npz") && err.contains("'phi' holds 1 non-finite"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    std::fs::write(&f, &good).unwrap();
    rewrite_frame(&f, |name, d| {
        if name == "origin" {
            d[2] = 1e6;
        }
    });
    let (ok, err) = analyze();
    assert!(
        !ok && err.contains("'origin' puts patch 1") && err.contains("off the 100×100 lattice"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    for t in ["observables.csv", "defects.csv", "defect_events.csv"] {
        assert!(!rd.join("analysis").join(t).exists(), "{t} left behind");
    }
}

/// Killed with SIGKILL at three points of its run and resumed with `--resume` (on another
/// thread count), a run directory ends byte-identical to an uninterrupted run: `series.csv`
/// and every frame. A finished run extended with `--set run.time=T` equals a run of T from the
/// start. Resuming a complete run, a directory without checkpoints, or with another override,
/// is refused with what to do.
#[test]
fn a_run_killed_at_random_points_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--set",
        "run.relax_time=20",
        "--set",
        "run.time=300",
        "--set",
        "run.output_every=20",
        "--set",
        "run.series_every=5",
        "--set",
        "run.checkpoint_every=10",
        "--threads",
        "1",
    ];
    let full = dir.path().join("full");
    let started = std::time::Instant::now();
    let o = run(&scene_path("paper.toml"), &full, &args);
    let whole = started.elapsed().as_millis() as u64;
    assert!(o.status.success(), "{}", stderr(&o));
    let want = run_files(&full);
    // Kill points spread over the run, as shares of the uninterrupted run's wall time (about a
    // second; fixed times were passed by a fast machine, which had finished by the last one).
    let mut resumed = 0;
    for (k, ms) in [15u64, 40, 70]
        .into_iter()
        .map(|pct| whole * pct / 100)
        .enumerate()
    {
        let out = dir.path().join(format!("killed{k}"));
        let mut child = bin()
            .arg("run")
            .arg(scene_path("paper.toml"))
            .arg("--out")
            .arg(&out)
            .arg("--quiet")
            .args(args)
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(ms));
        if child.try_wait().unwrap().is_some() {
            continue; // it finished before the kill: nothing was interrupted
        }
        let _ = child.kill(); // SIGKILL
        child.wait().unwrap();
        if !out.join("checkpoints").exists() || rundir::is_complete(&out) {
            continue; // killed before the first checkpoint, or after the last write
        }
        assert!(
            !rundir::is_complete(&out),
            "a killed run is not marked complete"
        );
        let a = bin()
            .arg("analyze")
            .arg(&out)
            .args(["--from", "0"])
            .output()
            .unwrap();
        assert!(
            stderr(&a).contains("is not marked complete"),
            "{}",
            stderr(&a)
        );
        resume_matches(&out, &want, &format!("kill at {ms} ms"));
        resumed += 1;
    }
    assert!(
        resumed >= 2,
        "only {resumed} of the kills left a checkpoint to resume from"
    );
    // Extension of a finished run.
    let short = dir.path().join("short");
    let mut a: Vec<&str> = args.to_vec();
    a.extend(["--set", "run.time=100"]);
    assert!(run(&scene_path("paper.toml"), &short, &a).status.success());
    let o = bin()
        .args(["run", "--resume"])
        .arg(&short)
        .args(["--quiet", "--set", "run.time=300"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        run_files(&short) == want,
        "the extended run differs from the full one"
    );
    // Refusals.
    let refuse = |d: &Path, extra: &[&str], needle: &str| {
        let o = bin()
            .args(["run", "--resume"])
            .arg(d)
            .args(extra)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert!(!o.status.success() && e.contains(needle), "{e}");
    };
    refuse(
        &full,
        &[],
        "is complete (step 1600 of 1600); extend it with --resume",
    );
    refuse(
        &full,
        &["--set", "model.zeta=0.01"],
        "only --set run.time=T",
    );
    refuse(dir.path(), &[], "has no checkpoint to resume from");
}

/// A local sweep checks memory for its largest point times `--jobs` before anything runs,
/// and names the point and `--jobs` in the refusal.
#[test]
fn a_sweep_too_large_for_memory_is_refused_before_it_runs() {
    let dir = tempfile::tempdir().unwrap();
    let o = bin()
        .arg("sweep")
        .arg(scene_path("paper.toml"))
        .args(["--vary", "model.zeta=0,0.005", "--jobs", "2", "--quiet"])
        .args([
            "--set",
            "run.relax_time=0",
            "--set",
            "run.time=1",
            "--max-memory",
            "30M",
        ])
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let e = stderr(&o);
    assert!(!o.status.success(), "{e}");
    for n in [
        "in sweep point",
        "2 runs at a time (use a smaller --jobs)",
        "--max-memory 30M",
    ] {
        assert!(e.contains(n), "{e:?} lacks {n:?}");
    }
    assert!(!dir.path().join("runs").exists(), "nothing ran");
    // One at a time fits.
    let o = bin()
        .arg("sweep")
        .arg(scene_path("paper.toml"))
        .args(["--vary", "model.zeta=0,0.005", "--jobs", "1", "--quiet"])
        .args([
            "--set",
            "run.relax_time=0",
            "--set",
            "run.time=1",
            "--max-memory",
            "30M",
        ])
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A full disk, for real: a run on a 600 KiB tmpfs (mounted by the test; skipped with a note
/// where mounting is not allowed) stops with an error that names the last whole frame and the
/// checkpoint to resume from, exits non-zero and leaves no partial file and no cut row; once
/// the tmpfs is enlarged, `--resume` ends byte-identical to an uninterrupted run.
#[test]
fn a_full_disk_stops_the_run_cleanly_and_it_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let small = dir.path().join("small");
    std::fs::create_dir(&small).unwrap();
    let mount = |opts: &str| {
        Command::new("mount")
            .args(["-t", "tmpfs", "-o", opts, "tmpfs"])
            .arg(&small)
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !mount("size=600k") {
        eprintln!("skipped: cannot mount a tmpfs here (needs root)");
        return;
    }
    struct Unmount<'a>(&'a Path);
    impl Drop for Unmount<'_> {
        fn drop(&mut self) {
            let _ = Command::new("umount").arg(self.0).status();
        }
    }
    let _unmount = Unmount(&small);
    let args = [
        "--set",
        "run.relax_time=0",
        "--set",
        "run.time=100",
        "--set",
        "run.output_every=10",
        "--set",
        "run.checkpoint_every=20",
    ];
    let full = dir.path().join("full");
    let o = run(&scene_path("paper.toml"), &full, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = small.join("run");
    let o = run(&scene_path("paper.toml"), &out, &args);
    let e = stderr(&o);
    assert!(!o.status.success(), "the run fitted in 600 KiB");
    assert!(!e.contains("panicked") && !e.contains("drop failed"), "{e}");
    assert!(e.contains("No space left on device"), "{e}");
    let last = rundir::last_frame(&out).expect("a frame fits");
    assert!(
        e.contains(&format!("keeps frames up to step {last} ")),
        "{e}"
    );
    let ckpt = rundir::checkpoint::checkpoints(&out).last().unwrap().0;
    assert!(
        e.contains(&format!(
            "--resume {} continues from the checkpoint at step {ckpt}",
            out.display()
        )),
        "{e}"
    );
    for sub in ["frames", "checkpoints"] {
        for f in std::fs::read_dir(out.join(sub)).unwrap() {
            let name = f.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.ends_with(".partial"), "{sub}/{name} left behind");
        }
    }
    let series = std::fs::read_to_string(out.join("series.csv")).unwrap();
    assert!(series.ends_with('\n'), "a cut row ends series.csv");
    assert!(
        series.lines().all(|l| l.split(',').count() == 12),
        "{series}"
    );
    // More room, and the run goes on where its checkpoint left it.
    assert!(mount("remount,size=32m"), "cannot enlarge the tmpfs");
    let o = bin()
        .args(["run", "--resume"])
        .arg(&out)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let (got, want) = (run_files(&out), run_files(&full));
    assert_eq!(got.len(), want.len(), "file count");
    for (g, w) in got.iter().zip(&want) {
        assert!(g == w, "{} differs", w.0);
    }
    // Full in the first minute, with the default checkpoints (the first a minute of wall
    // time in): no checkpoint at all. The message says so and how to start again, and that
    // command, once there is room, runs.
    std::fs::remove_dir_all(&out).unwrap();
    assert!(mount("remount,size=200k"), "cannot shrink the tmpfs");
    let first = small.join("first");
    let default_ckpt: Vec<&str> = args[..6].to_vec();
    let o = run(&scene_path("paper.toml"), &first, &default_ckpt);
    let e = stderr(&o);
    assert!(!o.status.success(), "the run fitted in 200 KiB: {e}");
    assert!(rundir::checkpoint::checkpoints(&first).is_empty(), "{e}");
    let again = format!(
        "monolayer run {0}/scene.toml --out {0} --overwrite",
        first.display()
    );
    assert!(
        e.contains("it wrote no checkpoint") && e.contains(&again),
        "{e}"
    );
    let o = bin()
        .args(["run", "--resume"])
        .arg(&first)
        .output()
        .unwrap();
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("no checkpoint to resume from") && e.contains(&again),
        "{e}"
    );
    assert!(mount("remount,size=32m"), "cannot enlarge the tmpfs");
    let o = bin()
        .arg("run")
        .arg(first.join("scene.toml"))
        .arg("--out")
        .arg(&first)
        .args(["--overwrite", "--quiet"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Issue 25's cases, each a regression test: every one ends in a clear error that names the
/// key and a fix, before anything is written (where it gave exit 0 and a wrong run, an abort
/// or a hang before).
#[test]
fn scenes_that_did_something_else_than_asked_are_refused_with_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 8] = [
        (
            &["integrator.tolerance=-5"],
            "[integrator] tolerance = -5: tolerance is only read with adaptive = true",
        ),
        (
            &["integrator.tolerance=1e-4"],
            "tolerance is only read with adaptive = true; set adaptive = true or remove tolerance",
        ),
        (
            &["integrator.adaptive=true", "integrator.dt_max=1e-300"],
            "[integrator] dt_max = 1e-300: relax_time + time = 1200 with steps of at most 1e-300 is more than the 1e9 steps",
        ),
        (
            &["cells.count=18446744073709551615"],
            "18446744073709551615 is out of range",
        ),
        (
            &["cells.radius=0.5"],
            "[cells] radius = 0.5: a cell smaller than one node",
        ),
        (
            &["cells.radius=1.5"],
            "[cells] radius = 1.5: the initial discs (radius R/2 = 0.75 by default)",
        ),
        (
            &[
                "cells.init=\"positions\"",
                "cells.count=3",
                "cells.positions=[[5,5],[5,5],[5,5]]",
            ],
            "cells 0 and 1 are 0.000 nodes apart (periodically), closer than the initial radius 4: they would start stacked",
        ),
        (
            &[
                "cells.init=\"positions\"",
                "cells.count=2",
                "cells.positions=[[1,50],[99.5,50]]",
            ],
            "cells 0 and 1 are 1.500 nodes apart (periodically)",
        ),
    ];
    for (k, (set, needle)) in cases.iter().enumerate() {
        let out = dir.path().join(format!("case{k}"));
        check_rejected(&scene_path("paper.toml"), &out, set, &[needle]);
    }
}

/// A checkpoint of another run (another ζ) put into a run directory is refused by `--resume`,
/// which names the file and the key that differs and leaves the directory as it was; a
/// `--resume --set run.time=T` that would end before the newest checkpoint says so.
#[test]
fn a_foreign_checkpoint_and_a_shortened_resume_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = SHORT.to_vec();
    args.extend(["--set", "run.checkpoint_every=2"]);
    let a = dir.path().join("a");
    assert!(run(&scene_path("paper.toml"), &a, &args).status.success());
    let mut other = args.clone();
    other.extend(["--set", "model.zeta=0.01"]);
    let b = dir.path().join("b");
    assert!(run(&scene_path("paper.toml"), &b, &other).status.success());
    let (_, newest) = rundir::checkpoint::checkpoints(&b).pop().unwrap();
    let foreign = a.join("checkpoints/checkpoint_000000000999.npz");
    std::fs::copy(newest, &foreign).unwrap();
    let before = (
        std::fs::read(a.join("series.csv")).unwrap(),
        std::fs::read(a.join("scene.toml")).unwrap(),
    );
    let o = bin()
        .args(["run", "--resume"])
        .arg(&a)
        .args(["--set", "run.time=20"])
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("checkpoint_000000000999.npz was not written by the run in")
            && err.contains("model.zeta is 0.01 there, 0.005 here"),
        "{err}"
    );
    let after = (
        std::fs::read(a.join("series.csv")).unwrap(),
        std::fs::read(a.join("scene.toml")).unwrap(),
    );
    assert!(before == after, "the refused resume changed the run");
    std::fs::remove_file(&foreign).unwrap();
    let o = bin()
        .args(["run", "--resume"])
        .arg(&a)
        .args(["--set", "run.time=2"])
        .output()
        .unwrap();
    let err = stderr(&o);
    assert!(
        !o.status.success()
            && err.contains("--set run.time would end the run at step 30")
            && err.contains("give run.time above 6"),
        "{err}"
    );
}

/// Frames whose per-cell arrays are rolled by one cell against `phi` (each cell given its
/// neighbour's centre, velocity, ...) are refused by `render`, `export vtk` and `analyze`,
/// naming the frame and the cell; a `frames/` that cannot be read (a symlink loop) is named as
/// such, not as "no frame yet".
#[test]
fn frames_whose_cells_do_not_match_their_phi_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let rd = dir.path().join("run");
    assert!(run(&scene_path("paper.toml"), &rd, &SHORT).status.success());
    let f = rd.join("frames/frame_00000050.npz");
    rewrite_frame(&f, |name, d| {
        if ["centre", "velocity", "force", "area", "shape_tensor"].contains(&name) {
            let per = if name == "area" { 1 } else { 2 };
            d.rotate_left(per);
        }
    });
    for args in [
        vec!["render", "--frames", "50", "--out"],
        vec!["export", "vtk", "--frames", "50", "--out"],
    ] {
        let o = bin()
            .args(&args)
            .arg(dir.path().join("view"))
            .arg(&rd)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert!(
            !o.status.success()
                && err.contains("frame_00000050.npz")
                && err.contains("array 'centre' puts cell 0 at"),
            "{args:?}: {err}"
        );
    }
    let o = bin().arg("analyze").arg(&rd).output().unwrap();
    assert!(
        stderr(&o).contains("array 'centre' puts cell 0"),
        "{}",
        stderr(&o)
    );
    let frames = rd.join("frames");
    std::fs::remove_dir_all(&frames).unwrap();
    std::os::unix::fs::symlink(&frames, &frames).unwrap();
    let o = bin().arg("analyze").arg(&rd).output().unwrap();
    let err = stderr(&o);
    assert!(
        !o.status.success() && err.contains("cannot be read") && !err.contains("no frame yet"),
        "{err}"
    );
}

/// A redone sweep run drops its earlier analysis (it described another run) and is analysed
/// afresh; `sweep --analyze` takes `analyze`'s options; on a lattice too small for the default
/// crop, `analyze` fits the crop to it instead of refusing.
#[test]
fn a_redone_sweep_run_is_analysed_afresh_on_a_small_lattice() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = || {
        bin()
            .arg("sweep")
            .arg(scene_path("paper.toml"))
            .args(["--vary", "model.zeta=0,0.01", "--seeds", "1"])
            .args([
                "--set",
                "domain.lx=40",
                "--set",
                "domain.ly=40",
                "--set",
                "cells.count=9",
            ])
            .args(SHORT)
            .args(["--analyze", "--from", "4", "--box", "9", "--quiet", "--out"])
            .arg(dir.path())
            .output()
            .unwrap()
    };
    let o = sweep();
    assert!(o.status.success(), "{}", stderr(&o));
    let run0 = dir.path().join("runs/model.zeta=0_seed=1");
    let opts = std::fs::read_to_string(run0.join("analysis/complete")).unwrap();
    // Analysed with the sweep's --box, and the default crop fitted to the 40² lattice (101
    // would be refused there).
    assert!(opts.contains("box_side: Some(9)"), "{opts}");
    assert!(run0.join("analysis/defect_averages.npz").exists());
    std::fs::write(run0.join("analysis/stale"), "from the run before").unwrap();
    std::fs::remove_file(run0.join("complete")).unwrap();
    let o = sweep();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        !run0.join("analysis/stale").exists(),
        "the old analysis was kept"
    );
    assert!(run0.join("analysis/complete").exists());
    // Analysis options without --analyze are refused.
    let o = bin()
        .arg("sweep")
        .arg(scene_path("paper.toml"))
        .args(["--vary", "model.zeta=0", "--crop", "21", "--out"])
        .arg(dir.path().join("x"))
        .output()
        .unwrap();
    assert!(stderr(&o).contains("add --analyze"), "{}", stderr(&o));
}

/// Under an address-space limit (`ulimit -v`, as a batch system sets) or a cgroup's memory
/// limit a scene that does not fit is refused with the limit named, where it aborted on
/// allocation; a run's log (stderr not a terminal) gets about ten progress lines.
#[test]
fn the_memory_guard_reads_the_process_limits_and_logs_are_short() {
    let dir = tempfile::tempdir().unwrap();
    let script = format!(
        "ulimit -v 6000000; exec {} run {} --out {} --set domain.lx=3000 --set domain.ly=3000 --set integrator.margin=0",
        env!("CARGO_BIN_EXE_monolayer"),
        scene_path("paper.toml").display(),
        dir.path().join("big").display()
    );
    let o = Command::new("bash")
        .arg("-c")
        .arg(&script)
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the address-space limit (ulimit -v)") && err.contains("reduce [cells] count"),
        "{err}"
    );
    // A cgroup's memory limit (SLURM's --mem), where this machine lets the test make one (cgroup
    // v1's memory controller, as root): a child cgroup of 2 GB and a scene of 4.4 GB.
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
    let base = cgroup.lines().find_map(|l| {
        let mut p = l.splitn(3, ':').skip(1);
        let (controllers, path) = (p.next()?, p.next()?);
        controllers
            .split(',')
            .any(|c| c == "memory")
            .then(|| format!("/sys/fs/cgroup/memory{path}"))
    });
    let child =
        base.map(|b| PathBuf::from(b).join(format!("monolayer-test-{}", std::process::id())));
    match child.filter(|c| std::fs::create_dir(c).is_ok()) {
        Some(cg) => {
            std::fs::write(cg.join("memory.limit_in_bytes"), "2G").unwrap();
            let script = format!(
                "echo $$ > {}/cgroup.procs; exec {} run {} --out {} --set domain.lx=1500 --set domain.ly=1500 --set integrator.margin=0",
                cg.display(),
                env!("CARGO_BIN_EXE_monolayer"),
                scene_path("paper.toml").display(),
                dir.path().join("cgroup").display()
            );
            let o = Command::new("bash")
                .arg("-c")
                .arg(&script)
                .output()
                .unwrap();
            let _ = std::fs::remove_dir(&cg);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(1), "{err}");
            assert!(
                err.contains(
                    "more than 2.0 GiB (the memory limit of this process's cgroup less its usage)"
                ),
                "{err}"
            );
        }
        None => eprintln!(
            "note: no cgroup v1 memory controller to write here; the cgroup limit is not tested"
        ),
    }
    let o = bin()
        .arg("run")
        .arg(scene_path("paper.toml"))
        .arg("--out")
        .arg(dir.path().join("log"))
        .args(["--set", "run.time=100", "--set", "run.relax_time=20"])
        .output()
        .unwrap();
    assert!(o.status.success());
    let lines = stderr(&o)
        .lines()
        .filter(|l| l.starts_with("step "))
        .count();
    assert!(
        (10..=13).contains(&lines),
        "{lines} progress lines:\n{}",
        stderr(&o)
    );
}

/// Issue 53: `monolayer threshold` on the tour's sweep (two activities, short runs) says why
/// its estimate is empty and what to run instead (on main it printed an empty field without
/// a word).
#[test]
fn a_threshold_that_is_not_bracketed_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, GOOD).unwrap();
    let out = dir.path().join("sweep");
    let o = bin()
        .arg("sweep")
        .arg(&scene)
        .args([
            "--vary",
            "model.zeta=0,0.005",
            "--seeds",
            "1-2",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .args(["--set", "run.time=4", "--set", "cells.count=20"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = bin().arg("threshold").arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.lines().nth(1).is_some_and(|l| l.starts_with(',')),
        "{table}"
    );
    let e = stderr(&o);
    assert!(
        e.contains("no estimate")
            && e.contains("activities on both sides")
            && e.contains("--vary model.zeta="),
        "{e}"
    );
}
