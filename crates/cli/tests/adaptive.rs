//! `[integrator] adaptive = true` end to end: outputs land on their times, the run is
//! bit-identical for any thread count, and a resumed run (mid-run checkpoint, controller
//! state included) ends byte-identical to the uninterrupted one.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::{paper, run_files};

/// `monolayer ARGS PATHS`.
fn monolayer(args: &[&str], paths: &[&Path]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_monolayer"));
    c.args(args).args(paths);
    c.output().expect("the binary runs")
}

/// `monolayer run scenes/paper.toml --out OUT ARGS`.
fn run_paper(out: &Path, args: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_monolayer"));
    c.arg("run").arg(paper()).arg("--out").arg(out).args(args);
    c.output().expect("the binary runs")
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The paper scene with the adaptive step: 40 TU of relaxation, 160 TU at ζ = 0.005.
const ADAPTIVE: [&str; 14] = [
    "--set",
    "integrator.adaptive=true",
    "--set",
    "integrator.dt=0.5",
    "--set",
    "run.relax_time=40",
    "--set",
    "run.time=160",
    "--set",
    "run.output_every=25",
    "--set",
    "run.series_every=5",
    "--set",
    "run.checkpoint_every=30",
];

fn run(out: &Path, threads: &str) {
    let mut args = ADAPTIVE.to_vec();
    args.extend(["--quiet", "--threads", threads]);
    ok(&run_paper(out, &args));
}

/// Rows land on every multiple of `series_every` and frames on every multiple of
/// `output_every`, exactly (the clock is set to the landing time, not summed); the activity
/// switches on at `relax_time`; the run takes fewer steps than the fixed dt 0.5 would (400);
/// 1 and 2 threads give byte-identical files.
#[test]
fn an_adaptive_run_lands_on_its_output_times_and_is_thread_independent() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    run(&a, "1");
    run(&b, "2");
    assert!(run_files(&a) == run_files(&b), "1 and 2 threads differ");
    let series = std::fs::read_to_string(a.join("series.csv")).unwrap();
    let rows: Vec<Vec<f64>> = series
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 41, "a row every 5 TU from 0 to 200");
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[1], 5.0 * k as f64, "row {k} at t = {}", r[1]);
        assert_eq!(
            r[2],
            if r[1] >= 40.0 { 0.005 } else { 0.0 },
            "ζ at t = {}",
            r[1]
        );
    }
    let steps = rows.last().unwrap()[0];
    assert!(steps < 400.0, "{steps} steps, no fewer than fixed dt 0.5");
    let mut times = Vec::new();
    for (name, _) in run_files(&a).iter().skip(1) {
        let t = rundir::read_npz(&a.join("frames").join(name), &["time"]).unwrap()[0].data[0];
        times.push(t);
    }
    assert_eq!(
        times,
        [0.0, 25.0, 50.0, 75.0, 100.0, 125.0, 150.0, 175.0, 200.0]
    );
    // analyze finds no frame missing from the schedule.
    let o = monolayer(&["analyze"], &[&a]);
    ok(&o);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("missing"));
}

/// Resumed from its older (mid-run) checkpoint, after the newer one is removed as a kill would
/// have left it, the run ends byte-identical: the checkpoint keeps the controller's step,
/// error history and counts. Extending a finished adaptive run with `--set run.time=T` equals
/// the run of T.
#[test]
fn an_adaptive_run_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    run(&full, "2");
    let want = run_files(&full);
    let cut = dir.path().join("cut");
    run(&cut, "2");
    let all = rundir::checkpoint::checkpoints(&cut);
    assert_eq!(all.len(), 2);
    std::fs::remove_file(&all[1].1).unwrap();
    std::fs::remove_file(cut.join(rundir::COMPLETE)).unwrap();
    let c = rundir::checkpoint::read_controller(&all[0].1)
        .unwrap()
        .unwrap();
    assert!(
        c.accepted > 0 && c.dt > 0.5,
        "{c:?}: a mid-run controller state"
    );
    ok(&monolayer(
        &["run", "--quiet", "--threads", "1", "--resume"],
        &[&cut],
    ));
    assert!(run_files(&cut) == want, "the resumed run differs");

    let short = dir.path().join("short");
    let mut args = ADAPTIVE.to_vec();
    args.extend(["--set", "run.time=60", "--quiet"]);
    ok(&run_paper(&short, &args));
    ok(&monolayer(
        &["run", "--quiet", "--set", "run.time=160", "--resume"],
        &[&short],
    ));
    assert!(run_files(&short) == want, "the extended run differs");
}
