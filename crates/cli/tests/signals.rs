//! SIGINT, SIGTERM and SIGHUP stop a run after its step in progress, with a checkpoint and a
//! line that says how to resume; the resumed run ends byte-identical to an uninterrupted one.
//! One process writes a run directory at a time.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{bin, paper, resume_matches, run_files, stderr};

/// The paper scene for about a second, with the default checkpoint interval (a twentieth of
/// the run, at least a minute of wall time apart): a run stopped by a signal has only the
/// checkpoint the signal made.
const ARGS: [&str; 10] = [
    "--set",
    "run.relax_time=20",
    "--set",
    "run.time=300",
    "--set",
    "run.output_every=20",
    "--set",
    "run.series_every=5",
    "--threads",
    "1",
];

fn spawn(out: &Path) -> Child {
    bin()
        .arg("run")
        .arg(paper())
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(ARGS)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn send(child: &Child, signal: &str) {
    let ok = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(ok.success(), "kill -{signal}");
}

/// Waits until `dir`'s lock file names its holder (the run has started).
fn wait_for_lock(dir: &Path) {
    let start = Instant::now();
    while std::fs::read_to_string(dir.join(rundir::LOCK)).map_or(true, |s| s.is_empty()) {
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "the run never started"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// SIGTERM, SIGINT and SIGHUP at points drawn from a fixed seed (so a failure repeats): each
/// stops the run with status 128 + the signal, the message, a checkpoint at the step it
/// names and no `complete` mark; `--resume` (on another thread count) then ends byte-identical
/// to the uninterrupted run, `series.csv` and every frame.
#[test]
fn a_signalled_run_stops_with_a_checkpoint_and_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    let o = bin()
        .arg("run")
        .arg(paper())
        .arg("--out")
        .arg(&full)
        .arg("--quiet")
        .args(ARGS)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let want = run_files(&full);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut draw = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut stopped = 0;
    for (k, (signal, number)) in [("TERM", 15), ("INT", 2), ("HUP", 1), ("TERM", 15)]
        .into_iter()
        .enumerate()
    {
        // Within the first 300 ms: the run takes 0.5 s on a fast, quiet machine (60 cells, 1600
        // steps on one thread) and longer elsewhere.
        let ms = 20 + draw() % 280;
        let out = dir.path().join(format!("stopped{k}"));
        let child = spawn(&out);
        wait_for_lock(&out);
        std::thread::sleep(Duration::from_millis(ms));
        send(&child, signal);
        let o = child.wait_with_output().unwrap();
        let err = stderr(&o);
        if o.status.success() {
            continue; // it finished before the signal
        }
        assert_eq!(o.status.code(), Some(128 + number), "SIG{signal}: {err}");
        let step: u64 = err
            .split("stopped at step ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("SIG{signal} at {ms} ms: no 'stopped at step N': {err}"));
        assert!(
            err.contains(&format!(
                "resume with monolayer run --resume {}",
                out.display()
            )),
            "{err}"
        );
        assert!(!rundir::is_complete(&out), "a stopped run is not complete");
        let newest = rundir::checkpoint::checkpoints(&out).last().cloned();
        assert_eq!(
            newest.map(|c| c.0),
            Some(step),
            "the checkpoint is at the stop"
        );
        resume_matches(&out, &want, &format!("SIG{signal} at {ms} ms"));
        stopped += 1;
    }
    assert!(stopped >= 3, "only {stopped} of 4 signals stopped the run");
}

/// While a run writes a directory, a second `run --out` (even with `--overwrite`) and a
/// `--resume` of it are refused, naming the holder's process; `analyze` is refused too.
/// Two signals in a row end the run at once.
#[test]
fn a_second_writer_is_refused_and_a_second_signal_exits_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("busy");
    let child = spawn(&out);
    wait_for_lock(&out);
    let pid = child.id();
    for extra in [vec!["--overwrite"], vec![]] {
        let o = bin()
            .arg("run")
            .arg(paper())
            .arg("--out")
            .arg(&out)
            .args(&extra)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.contains("in use by another monolayer process")
                && err.contains(&format!("pid {pid}")),
            "{err}"
        );
    }
    let o = bin().args(["run", "--resume"]).arg(&out).output().unwrap();
    assert!(stderr(&o).contains(&format!("pid {pid}")), "{}", stderr(&o));
    let o = bin().arg("analyze").arg(&out).output().unwrap();
    assert!(!o.status.success());
    assert!(stderr(&o).contains(&format!("pid {pid}")), "{}", stderr(&o));
    send(&child, "TERM");
    send(&child, "TERM");
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(143), "{}", stderr(&o));
}

/// SIGTERM during a local sweep stops the run in progress after its step, with a checkpoint,
/// lists it, and exits 143; the same command then continues it (and the runs not started), and
/// the summary equals that of a sweep never stopped.
#[test]
fn a_signalled_sweep_stops_and_the_same_command_continues_it() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = |out: &Path| {
        let mut c = bin();
        c.arg("sweep")
            .arg(paper())
            .args(["--vary", "model.zeta=0.004,0.006", "--seeds", "1"])
            .args(["--jobs", "1", "--threads", "1", "--quiet", "--out"])
            .arg(out)
            .args(&ARGS[..8]);
        c
    };
    let whole = dir.path().join("whole");
    let o = sweep(&whole).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let want = std::fs::read_to_string(whole.join("summary.csv")).unwrap();
    let out = dir.path().join("stopped");
    let child = sweep(&out).stderr(Stdio::piped()).spawn().unwrap();
    wait_for_lock(&out.join("runs/model.zeta=0.004_seed=1"));
    std::thread::sleep(Duration::from_millis(150));
    send(&child, "TERM");
    let o = child.wait_with_output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(143), "{err}");
    assert!(
        err.contains("stopped by signal 15")
            && err.contains("model.zeta=0.004_seed=1 at step")
            && err.contains("run the same sweep command again"),
        "{err}"
    );
    assert!(!out.join("summary.csv").exists());
    let o = sweep(&out).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let got = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(got, want, "the continued sweep differs from the whole one");
}

/// A log that goes away (stderr a pipe whose reader has closed, as after `| head`, or a
/// terminal that hung up) does not change how a run ends: it completes with status 0, where
/// the first progress line after the close panicked.
#[test]
fn a_closed_stderr_does_not_stop_a_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let mut child = bin()
        .arg("run")
        .arg(paper())
        .arg("--out")
        .arg(&out)
        .args(&ARGS[..8])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status}");
    assert!(rundir::is_complete(&out));
}
