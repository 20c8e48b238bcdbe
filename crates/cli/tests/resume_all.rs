//! Every shipped scene resumes bit for bit: each scene of `scenes/`, at a small scale, run to
//! its end in one go and, separately, stopped by a signal mid-run then continued with
//! `--resume`, writes
//! the same `series.csv`, frames and (with `[division]`) `lineage.csv`, byte for byte. This
//! checks, for every extension a shipped scene uses (walls, a wound, polarity, adhesion,
//! populations, division), that a checkpoint restores all of it: the walls were once lost
//! on resume.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{bin, quarter_scene, run_files, scene_path, stderr};

/// The overrides that make a scene short: a relaxation of 40 TU (the initial discs grow to their cells; a wound opens and a
/// clock starts inside the run) and `time` TU of activity, frames every 10 TU.
fn short(time: u32) -> Vec<String> {
    [
        "run.relax_time=40".to_string(),
        format!("run.time={time}"),
        "run.output_every=10".into(),
        "run.series_every=2".into(),
    ]
    .into_iter()
    .flat_map(|s| ["--set".to_string(), s])
    .collect()
}

/// The scene `name` at a quarter of its area and cells ([`quarter_scene`]), written into
/// `dir`.
fn small(name: &str, dir: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scene_path(name)).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, quarter_scene(&text)).unwrap();
    path
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = run_files(dir);
    if let Ok(l) = std::fs::read(dir.join("lineage.csv")) {
        v.push(("lineage.csv".into(), l));
    }
    v
}

/// Runs the small scene `scene` to `time` TU of activity into `out`, stopped by SIGTERM as
/// soon as its sixth frame is written (10 TU after its relaxation, when a wound has opened
/// and the first cells may have divided): the step it stopped at, or `None` when it finished
/// before the signal came.
fn stopped_run(scene: &Path, out: &Path, time: u32) -> Option<u64> {
    let mut child = bin()
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .args(["--quiet", "--threads", "1"])
        .args(short(time))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let frames = || std::fs::read_dir(out.join("frames")).map_or(0, |d| d.count());
    while frames() < 6 && child.try_wait().unwrap().is_none() {
        assert!(start.elapsed() < Duration::from_secs(60), "never started");
        std::thread::sleep(Duration::from_micros(200));
    }
    let _ = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status();
    let o = child.wait_with_output().unwrap();
    if o.status.success() {
        return None;
    }
    let err = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(128 + 15),
        "{}: {err}",
        scene.display()
    );
    let step = err
        .split("stopped at step ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{}: no 'stopped at step N': {err}", scene.display()));
    Some(step)
}

/// Each shipped scene, stopped by SIGTERM mid-run and resumed with `--resume` (on two
/// threads), writes the same files as a run in one go (on one). A run that ends before the
/// signal comes is run again four times as long, so that every scene is stopped.
#[test]
fn every_shipped_scene_resumes_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let mut names: Vec<String> = std::fs::read_dir(scene_path(""))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 13, "the shipped scenes: {names:?}");
    for name in names {
        let scene = small(&name, tmp.path());
        let half = tmp.path().join(format!("{name}.half"));
        let mut time = 30;
        let step = loop {
            if let Some(step) = stopped_run(&scene, &half, time) {
                break step;
            }
            assert!(time < 30 * 4usize.pow(3) as u32, "{name}: never stopped");
            time *= 4;
            std::fs::remove_dir_all(&half).unwrap();
        };
        let o = bin()
            .args(["run", "--resume"])
            .arg(&half)
            .args(["--quiet", "--threads", "2"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: resume: {}", stderr(&o));
        let full = tmp.path().join(format!("{name}.full"));
        let o = bin()
            .arg("run")
            .arg(&scene)
            .arg("--out")
            .arg(&full)
            .args(["--quiet", "--threads", "1"])
            .args(short(time))
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let (want, got) = (files(&full), files(&half));
        assert_eq!(
            want.iter().map(|f| &f.0).collect::<Vec<_>>(),
            got.iter().map(|f| &f.0).collect::<Vec<_>>(),
            "{name}: the files (stopped at step {step})"
        );
        for (w, g) in want.iter().zip(&got) {
            assert!(
                w.1 == g.1,
                "{name}: {} differs after the resume from step {step}",
                w.0
            );
        }
        eprintln!("{name}: stopped at step {step} of a run of {time} TU, resumed bit for bit");
    }
}
