//! Every shipped scene resumes bit for bit: each scene of `scenes/`, at a small scale, run to
//! its end in one go and, separately, run to half way then continued with `--resume`, writes
//! the same `series.csv`, frames and (with `[division]`) `lineage.csv`, byte for byte. This
//! checks, for every extension a shipped scene uses (walls, a wound, polarity, adhesion,
//! populations, division), that a checkpoint restores all of it: the walls were once lost
//! on resume.

use std::path::Path;

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
        let run = |out: &Path, time: u32| {
            let o = bin()
                .arg("run")
                .arg(&scene)
                .arg("--out")
                .arg(out)
                .args(["--quiet", "--threads", "1"])
                .args(short(time))
                .output()
                .unwrap();
            assert!(o.status.success(), "{name}: {}", stderr(&o));
        };
        let full = tmp.path().join(format!("{name}.full"));
        run(&full, 30);
        let half = tmp.path().join(format!("{name}.half"));
        run(&half, 10);
        let o = bin()
            .args(["run", "--resume"])
            .arg(&half)
            .args(["--quiet", "--threads", "2", "--set", "run.time=30"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: resume: {}", stderr(&o));
        let (want, got) = (files(&full), files(&half));
        assert_eq!(
            want.iter().map(|f| &f.0).collect::<Vec<_>>(),
            got.iter().map(|f| &f.0).collect::<Vec<_>>(),
            "{name}: the files"
        );
        for (w, g) in want.iter().zip(&got) {
            assert!(w.1 == g.1, "{name}: {} differs after the resume", w.0);
        }
    }
}
