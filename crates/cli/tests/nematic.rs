//! `[nematic]` (issue 49): the cells' own nematic end to end. A run writes each cell's axis
//! and tensor into its frames and the cells' nematic order into its analysis, resumes bit for
//! bit on another thread count, hands its axes to a run that starts from its frame, and is
//! refused by the GPU by name before anything is written; bad keys are refused by name.

use crate::common::{bin, run_files, scene_path, stderr};

fn run(out: &std::path::Path, time: &str, threads: &str, extra: &[&str]) -> std::process::Output {
    let mut cmd = bin();
    cmd.arg("run")
        .arg(scene_path("nematic.toml"))
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args([
            "--set",
            "run.relax_time=10",
            "--set",
            "run.output_every=10",
            "--set",
            "run.checkpoint_every=10",
            "--set",
            "run.series_every=5",
            "--set",
            "nematic.rotational_diffusion=0.01",
        ])
        .args(["--set", &format!("run.time={time}"), "--threads", threads]);
    for e in extra {
        cmd.args(["--set", e]);
    }
    cmd.output().unwrap()
}

/// The nematic scene for 60 TU on two threads equals, byte for byte, the run on one thread
/// and a run of 20 TU extended to 60 with `--resume`: the angles are in the checkpoint, their
/// noise is keyed by cell and step, and the lattice measurement of the elastic and vorticity
/// torques is thread-count independent. Its frames hold `nematic.theta` and the tensor
/// `nematic` (`S (cos 2θ, sin 2θ)`, to round-off), and `analyze` writes the cells' nematic
/// order, below 1 once the noise has turned the axes.
#[test]
fn a_nematic_run_resumes_bit_for_bit_and_writes_its_axes() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    let o = run(&full, "60", "2", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let want = run_files(&full);
    let last = rundir::last_frame(&full).unwrap();
    let arrays = rundir::read_npz(
        &full.join(format!("frames/frame_{last:08}.npz")),
        &["nematic.theta", "nematic"],
    )
    .expect("a nematic frame has its axes and tensors");
    let (theta, q) = (&arrays[0].data, &arrays[1].data);
    assert_eq!(q.len(), 2 * theta.len());
    for (t, q) in theta.iter().zip(q.chunks_exact(2)) {
        assert!(((2.0 * t).cos() - q[0]).abs() < 1e-12 && ((2.0 * t).sin() - q[1]).abs() < 1e-12);
    }
    let one = dir.path().join("one");
    assert!(run(&one, "60", "1", &[]).status.success());
    assert!(run_files(&one) == want, "one thread differs from two");
    let short = dir.path().join("short");
    assert!(run(&short, "20", "1", &[]).status.success());
    let o = bin()
        .args(["run", "--resume"])
        .arg(&short)
        .args(["--quiet", "--set", "run.time=60"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(run_files(&short) == want, "the resumed run differs");
    let o = bin()
        .arg("analyze")
        .arg(&full)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let obs = std::fs::read_to_string(full.join("analysis/observables.csv")).unwrap();
    let header: Vec<&str> = obs.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "cell_nematic_order")
        .unwrap();
    let order: Vec<f64> = obs
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    assert!(
        (order[0] - 1.0).abs() < 1e-12,
        "every axis along x at the start: {order:?}"
    );
    assert!(
        *order.last().unwrap() < 0.999,
        "the noise turns them: {order:?}"
    );
}

/// A run from a frame of a nematic run (`init = "frame"`) starts with the frame's axes, not
/// the scene's `angle`, and says so.
#[test]
fn init_from_a_frame_carries_the_nematic_axes() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first");
    assert!(run(&first, "20", "1", &[]).status.success());
    let step = rundir::last_frame(&first).unwrap();
    let last = first.join(format!("frames/frame_{step:08}.npz"));
    let saved = rundir::read_npz(&last, &["nematic.theta"]).unwrap();
    let second = dir.path().join("second");
    let from = format!("cells.from=\"{}\"", last.display());
    let o = run(
        &second,
        "10",
        "1",
        &[
            "cells.init=\"frame\"",
            &from,
            "run.relax_time=0",
            "run.seed=99",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("[nematic] angle") && stderr(&o).contains("nematic.theta"),
        "{}",
        stderr(&o)
    );
    let got = rundir::read_npz(
        &second.join("frames/frame_00000000.npz"),
        &["nematic.theta"],
    )
    .unwrap();
    assert_eq!(got[0].data, saved[0].data);
}

/// The GPU does not run the cell nematic yet: refused naming `[nematic]`'s keys and the fix,
/// with nothing written. Bad keys are refused by name.
#[test]
fn the_nematic_is_refused_where_it_cannot_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gpu");
    let o = run(&out, "10", "1", &["integrator.backend=\"gpu\""]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("[nematic] zeta"), "{e}");
    assert!(!out.exists(), "nothing written");
    for (set, key) in [
        ("nematic.elastic=-1", "elastic"),
        ("nematic.order=-0.5", "order"),
        ("nematic.align_rate=0.5", "align_rate"),
    ] {
        let out = dir.path().join(key);
        let o = run(&out, "10", "1", &[set]);
        assert!(!o.status.success(), "{set}");
        let e = stderr(&o);
        assert!(e.contains("[nematic]") && e.contains(key), "{set}: {e}");
        assert!(!out.exists(), "nothing written");
    }
}

/// `analyze` finds the defects of the cells' own nematic field `M = Σ φ_i q_i`
/// (`analysis/defects_nematic.csv`), as it finds the shape field's: axes dealt at random (the
/// scene without `angle`) make ±½ defects of M at the start, of both signs (not in equal
/// numbers: the initial discs do not cover the box, and defects outside the tissue are
/// dropped); axes all along x make none. A scene without `[nematic]` writes no such file.
/// `render --director-of nematic` draws M's director and defects, and is refused by name
/// without `[nematic]`.
#[test]
fn analyze_finds_the_defects_of_the_cells_nematic() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene_path("nematic.toml")).unwrap();
    let random: String = text
        .lines()
        .filter(|l| !l.starts_with("angle"))
        .map(|l| format!("{l}\n"))
        .collect();
    let path = dir.path().join("random.toml");
    std::fs::write(&path, random).unwrap();
    // Runs `scene` for 5 + 5 TU into `name` and analyses it.
    let analysed = |scene: &std::path::Path, name: &str| -> std::path::PathBuf {
        let out = dir.path().join(name);
        let o = bin()
            .arg("run")
            .arg(scene)
            .arg("--out")
            .arg(&out)
            .args([
                "--quiet",
                "--set",
                "run.relax_time=5",
                "--set",
                "run.time=5",
            ])
            .args(["--set", "run.output_every=5"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        let o = bin()
            .arg("analyze")
            .arg(&out)
            .arg("--quiet")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        out.join("analysis")
    };
    let first_frame_defects = |scene: &std::path::Path, name: &str| -> Vec<f64> {
        let csv =
            std::fs::read_to_string(analysed(scene, name).join("defects_nematic.csv")).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("frame,time,x,y,charge,angle"));
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        let first = rows.first().map(|r| r[0].to_string());
        rows.iter()
            .filter(|r| Some(r[0].to_string()) == first)
            .map(|r| r[4].parse().unwrap())
            .collect()
    };
    let charges = first_frame_defects(&path, "random");
    assert!(charges.len() >= 2, "random axes make defects: {charges:?}");
    assert!(
        charges.iter().all(|&c| c == 0.5 || c == -0.5),
        "{charges:?}"
    );
    assert!(
        charges.contains(&0.5) && charges.contains(&-0.5),
        "{charges:?}"
    );
    let aligned = first_frame_defects(&scene_path("nematic.toml"), "aligned");
    assert!(aligned.is_empty(), "axes along x: {aligned:?}");
    // Without [nematic]: no file.
    let plain = analysed(&scene_path("paper.toml"), "plain");
    assert!(plain.join("defects.csv").exists());
    assert!(!plain.join("defects_nematic.csv").exists());
    // `render --director-of nematic` draws M's director and defects, not the shapes' Q: the
    // pictures of the random axes differ from those of the shapes. A run without [nematic] is
    // refused by name, writing no picture; an unknown field is named.
    let render = |run: &str, of: &str| -> (std::process::Output, std::path::PathBuf) {
        let out = dir.path().join(format!("{run}-{of}-png"));
        let o = bin()
            .arg("render")
            .arg(dir.path().join(run))
            .arg("--out")
            .arg(&out)
            .args(["--quiet", "--director", "--defects", "--director-of", of])
            .output()
            .unwrap();
        (o, out)
    };
    let pictures = |out: &std::path::Path| -> Vec<Vec<u8>> {
        let mut files: Vec<_> = std::fs::read_dir(out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        files.iter().map(|f| std::fs::read(f).unwrap()).collect()
    };
    let (o, shape) = render("random", "shape");
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, nematic) = render("random", "nematic");
    assert!(o.status.success(), "{}", stderr(&o));
    let (a, b) = (pictures(&shape), pictures(&nematic));
    assert!(!a.is_empty() && a.len() == b.len());
    assert_ne!(a, b, "M's director and defects are drawn, not Q's");
    let (o, out) = render("plain", "nematic");
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("--director-of nematic") && err.contains("[nematic]"),
        "{err}"
    );
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    let (o, _) = render("random", "flow");
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--director-of flow"), "{}", stderr(&o));
}
