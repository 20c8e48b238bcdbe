//! Scenes with physics terms (`[polarity]`) end to end: a resumed run and a run on another
//! thread count end byte-identical, and `init = "frame"` carries the polarity.

use crate::common::{bin, run_files, scene_path, stderr};

const ARGS: [&str; 8] = [
    "--set",
    "run.relax_time=20",
    "--set",
    "run.output_every=20",
    "--set",
    "run.checkpoint_every=20",
    "--set",
    "run.series_every=5",
];

fn run(out: &std::path::Path, time: &str, threads: &str) -> std::process::Output {
    bin()
        .arg("run")
        .arg(scene_path("polar.toml"))
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(ARGS)
        .args(["--set", &format!("run.time={time}"), "--threads", threads])
        .output()
        .unwrap()
}

/// The polar scene for 100 TU on two threads equals, byte for byte, the same run on one
/// thread, and a run of 40 TU extended with `--resume --set run.time=100`: the polarity is
/// in the checkpoint and its noise is keyed by cell, step and seed, not by a generator's
/// position.
#[test]
fn a_polar_run_resumes_bit_for_bit_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    let o = run(&full, "100", "2");
    assert!(o.status.success(), "{}", stderr(&o));
    let want = run_files(&full);
    let frame = want
        .iter()
        .find(|(name, _)| name.ends_with(".npz"))
        .expect("a frame");
    let arrays = rundir::read_npz(
        &full.join("frames").join(&frame.0),
        &["polarity", "polarity.theta", "cell_force"],
    )
    .expect("a polar frame has its polarity and propulsion");
    assert_eq!(arrays[0].data.len(), 2 * arrays[1].data.len());
    let one = dir.path().join("one");
    assert!(run(&one, "100", "1").status.success());
    assert!(run_files(&one) == want, "one thread differs from two");
    let short = dir.path().join("short");
    assert!(run(&short, "40", "1").status.success());
    let o = bin()
        .args(["run", "--resume"])
        .arg(&short)
        .args(["--quiet", "--set", "run.time=100"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(run_files(&short) == want, "the resumed run differs");
}

/// A run that starts from a frame of a polar run (`init = "frame"`) starts with the frame's
/// polarities, cell by cell, not fresh ones from its seed.
#[test]
fn init_from_a_frame_carries_the_polarity() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first");
    assert!(run(&first, "40", "1").status.success());
    let step = rundir::last_frame(&first).expect("frames");
    let last = first.join(format!("frames/frame_{step:08}.npz"));
    let saved = rundir::read_npz(&last, &["polarity.theta"]).unwrap();
    let second = dir.path().join("second");
    let o = bin()
        .arg("run")
        .arg(scene_path("polar.toml"))
        .arg("--out")
        .arg(&second)
        .arg("--quiet")
        .args([
            "--set",
            "cells.init=\"frame\"",
            "--set",
            &format!("cells.from=\"{}\"", last.display()),
            "--set",
            "run.relax_time=0",
            "--set",
            "run.time=10",
            "--set",
            "run.seed=99",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let start = second.join("frames/frame_00000000.npz");
    let got = rundir::read_npz(&start, &["polarity.theta"]).unwrap();
    assert_eq!(got[0].data, saved[0].data);
}
