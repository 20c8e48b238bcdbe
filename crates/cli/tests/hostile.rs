//! The silent and unclear cases of the model's extensions (issue 38), each refused with a
//! message that names the key or file and the fix, or made right: one test per class.

use std::path::Path;
use std::process::Output;

use crate::common::{bin, scene_path, stderr};

fn run(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut c = bin();
    c.arg("run").arg(scene).arg("--out").arg(out).arg("--quiet");
    for e in extra {
        c.args(["--set", e]);
    }
    c.output().expect("the binary runs")
}

/// Refused: a non-zero exit, every `says` in the message, no panic.
fn refused(o: &Output, says: &[&str], what: &str) {
    let e = stderr(o);
    assert!(!o.status.success(), "{what}: refused");
    assert!(!e.contains("panicked"), "{what}: {e}");
    for s in says {
        assert!(e.contains(s), "{what}: the message says {s:?}: {e}");
    }
}

/// Scenes that would run and do something other than asked are refused before anything is
/// written: a population whose radius does not fit the patch (its cells ended at a tenth of
/// their area), a wound without a relaxation (no wound at all); and the three messages that
/// were serde's name the fix.
#[test]
fn scenes_that_would_silently_differ_are_refused_by_key() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mixture = scene_path("mixture.toml");
    refused(
        &run(&mixture, &out, &["population.0.radius=20"]),
        &["population", "radius", "margin"],
        "a population radius beyond the margin",
    );
    refused(
        &run(&scene_path("wound.toml"), &out, &["run.relax_time=0"]),
        &["relax_time", "wound"],
        "a wound without relaxation",
    );
    refused(
        &run(&scene_path("paper.toml"), &out, &["population.0.zeta=0.01"]),
        &["no [[population]]", "population.0.zeta"],
        "--set population.0 without populations",
    );
    refused(
        &run(&scene_path("paper.toml"), &out, &["integrator.backend=1"]),
        &["integrator.backend", "`cpu` or `gpu`"],
        "a number for a word",
    );
    let single = dir.path().join("single.toml");
    std::fs::write(
        &single,
        std::fs::read_to_string(&mixture)
            .unwrap()
            .replace("[[population]]", "[population]"),
    )
    .unwrap();
    refused(
        &run(&single, &out, &[]),
        &["[population]", "[[population]] (two brackets)"],
        "[population] for [[population]]",
    );
    assert!(!out.exists(), "nothing written");
}

/// Runs that went wrong without a word now stop and say why: an alignment rate far beyond
/// what the time step can integrate (θ jumped by tens of radians between frames), and a death
/// rate that kills every cell (one immortal cell was kept, by a rule written nowhere). The
/// outputs up to the stop are kept.
#[test]
fn runs_that_would_silently_differ_stop_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stiff");
    refused(
        &run(
            &scene_path("polar.toml"),
            &out,
            &[
                "polarity.align_rate=1000",
                "run.time=20",
                "run.relax_time=5",
            ],
        ),
        &["polarity", "align_rate", "2/dt"],
        "a stiff alignment",
    );
    assert!(out.join("series.csv").exists(), "outputs kept");
    let out = dir.path().join("extinct");
    refused(
        &run(
            &scene_path("colony.toml"),
            &out,
            &["division.death_rate=2", "run.time=50"],
        ),
        &["every cell is gone", "death_rate"],
        "every cell dies",
    );
    assert!(out.join("lineage.csv").exists(), "outputs kept");
}

/// A dividing run's outputs that do not fit together are refused by analyze and render,
/// naming the file: a frame whose `id` array was removed, a `lineage.csv` of another run, a
/// NaN birth, a missing `lineage.csv`.
#[test]
fn damaged_outputs_of_a_dividing_run_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let colony = scene_path("colony.toml");
    let args = [
        "division.cycle_time=15",
        "division.cycle_spread=5",
        "division.growth_time=10",
        "division.extrusion=0",
        "run.time=60",
        "run.output_every=10",
    ];
    let a = dir.path().join("a");
    let o = run(&colony, &a, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let b = dir.path().join("b");
    let o = run(&colony, &b, &[&args[..], &["run.seed=2"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let lineage = std::fs::read_to_string(a.join("lineage.csv")).unwrap();
    assert!(lineage.lines().count() > 4, "cells divided: {lineage}");
    let tool = |what: &[&str], dir: &Path| {
        let png = dir.join("png");
        let mut c = bin();
        c.args(what).arg(dir).arg("-q");
        if what[0] == "render" {
            c.arg("--out").arg(&png);
        }
        let o = c.output().unwrap();
        let _ = std::fs::remove_dir_all(dir.join("analysis"));
        o
    };
    let analyze: &[&str] = &["analyze"];
    let render: &[&str] = &["render", "--colour", "generation"];
    assert!(tool(analyze, &a).status.success());
    // Another run's lineage (seed 2): its cells are born at other times.
    std::fs::copy(b.join("lineage.csv"), a.join("lineage.csv")).unwrap();
    for t in [analyze, render] {
        refused(&tool(t, &a), &["lineage.csv", "not of the same run"], t[0]);
    }
    // A NaN birth.
    let nan: String = lineage
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == 1 {
                let mut f: Vec<&str> = l.split(',').collect();
                f[2] = "NaN";
                f.join(",") + "\n"
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    std::fs::write(a.join("lineage.csv"), nan).unwrap();
    refused(
        &tool(&["render", "--colour", "lineage"], &a),
        &["lineage.csv", "line 2"],
        "a NaN birth",
    );
    // No lineage.csv.
    std::fs::remove_file(a.join("lineage.csv")).unwrap();
    refused(
        &tool(analyze, &a),
        &["lineage.csv", "is missing", "[division]"],
        "no lineage",
    );
    std::fs::write(a.join("lineage.csv"), &lineage).unwrap();
    assert!(tool(analyze, &a).status.success(), "the run's own lineage");
    // A frame without its `id` array.
    let frame = std::fs::read_dir(a.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .max()
        .unwrap();
    let names = rundir::npz_names(&frame).unwrap();
    let keep: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|&n| n != "id")
        .collect();
    let arrays = rundir::read_npz(&frame, &keep).unwrap();
    let out: Vec<(String, Vec<u8>)> = keep
        .iter()
        .zip(arrays)
        .map(|(n, a)| {
            (
                n.to_string(),
                rundir::npy(&a.shape, a.data.iter().copied()).unwrap(),
            )
        })
        .collect();
    rundir::write_npz(&frame, out).unwrap();
    for t in [analyze, render] {
        refused(&tool(t, &a), &["'id' is missing", "frame_"], t[0]);
    }
}

/// `init = "frame"` from a two-population run carries each cell's population from the frame's
/// `population` array, where it was dealt again by the new scene's seed.
#[test]
fn a_state_from_a_mixture_keeps_its_populations() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    let o = run(
        &scene_path("mixture.toml"),
        &a,
        &["run.time=10", "run.output_every=10"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let frame = a.join("frames/frame_00000020.npz");
    let want = rundir::read_npz(&frame, &["population"])
        .unwrap()
        .remove(0)
        .data;
    let b = dir.path().join("b");
    let from = format!("cells.from=\"{}\"", frame.display());
    let o = run(
        &scene_path("mixture.toml"),
        &b,
        &[
            "cells.init=frame",
            &from,
            "run.seed=9",
            "run.time=10",
            "run.output_every=10",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let got = rundir::read_npz(&b.join("frames/frame_00000000.npz"), &["population"])
        .unwrap()
        .remove(0)
        .data;
    assert_eq!(got, want, "the frame's populations, not a new deal");
    assert!(!stderr(&o).contains("not carried"), "{}", stderr(&o));
    // The same frame into a scene without populations: the run goes on (the scene says
    // so), and says that the frame's `population` is not carried.
    let plain = dir.path().join("plain.toml");
    std::fs::write(
        &plain,
        "[domain]\nlx = 100\nly = 100\n[cells]\ncount = 48\nradius = 8.0\n\
         [model]\nmu = 5.0\nxi = 1.5\n[integrator]\ndt = 0.5\n\
         [run]\nrelax_time = 0.0\ntime = 1.0\n",
    )
    .unwrap();
    let o = run(&plain, &dir.path().join("d"), &["cells.init=frame", &from]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("its arrays population are not carried"),
        "{}",
        stderr(&o)
    );
    // The deal of seed 9 differs, so the check can fail.
    let c = dir.path().join("c");
    let o = run(
        &scene_path("mixture.toml"),
        &c,
        &["run.seed=9", "run.time=0", "run.output_every=10"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let dealt = rundir::read_npz(&c.join("frames/frame_00000000.npz"), &["population"])
        .unwrap()
        .remove(0)
        .data;
    assert_ne!(dealt, want);
}

/// A small paper run (8 cells on 40², 2 TU of relaxation and 2 of activity) into `out`, with
/// frames as `output_every` says.
fn small_paper_run(out: &Path, output_every: &str) {
    let o = run(
        &scene_path("paper.toml"),
        out,
        &[
            "domain.lx=40",
            "domain.ly=40",
            "cells.count=8",
            "run.relax_time=2",
            "run.time=2",
            output_every,
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Every file of `dir` (recursively, the lock file aside: it names the last process that
/// held it) with its bytes.
fn snapshot(dir: &Path) -> std::collections::BTreeMap<std::path::PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().is_some_and(|n| n != rundir::LOCK) {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

/// Issue 53: a resume that is refused leaves the run directory as it was, byte for byte (its
/// lock file aside), for every way a resume can be refused: an override of another key, a
/// complete run, a shorter run.time, the GPU where no Vulkan adapter is (on main this one
/// rewrote scene.toml and removed the `complete` mark), a run whose scene changed, a run
/// that another process holds, and no checkpoint.
#[test]
fn a_refused_resume_leaves_the_directory_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    small_paper_run(&out, "run.output_every=1");
    std::fs::create_dir_all(out.join("analysis")).unwrap();
    std::fs::write(out.join("analysis/kept.txt"), "the analysis of the run").unwrap();
    let resume = |args: &[&str], envs: &[(&str, &str)]| {
        let mut c = bin();
        c.args(["run", "--quiet", "--resume"]).arg(&out);
        for a in args {
            c.args(["--set", a]);
        }
        for (k, v) in envs {
            c.env(k, v);
        }
        c.output().expect("the binary runs")
    };
    // No Vulkan driver visible to the loader, whatever this machine has.
    let no_gpu = [
        ("VK_ICD_FILENAMES", "/nonexistent.json"),
        ("VK_DRIVER_FILES", "/nonexistent.json"),
    ];
    // (what, --set overrides, environment, what the message says)
    type Case<'a> = (
        &'a str,
        &'a [&'a str],
        &'a [(&'a str, &'a str)],
        &'a [&'a str],
    );
    let cases: &[Case] = &[
        ("another key", &["model.zeta=0.1"], &[], &["model.zeta"]),
        ("a complete run", &[], &[], &["complete"]),
        ("a shorter run", &["run.time=1"], &[], &["run.time"]),
        (
            "the GPU without an adapter",
            &["run.time=3", "integrator.backend=gpu"],
            &no_gpu,
            &["gpu"],
        ),
        (
            "the GPU without an adapter, not extended",
            &["integrator.backend=gpu"],
            &no_gpu,
            &[],
        ),
    ];
    let before = snapshot(&out);
    assert!(before.contains_key(Path::new(rundir::COMPLETE)));
    for (what, args, envs, says) in cases {
        let o = resume(args, envs);
        refused(&o, says, what);
        assert!(snapshot(&out) == before, "{what}: the directory changed");
    }
    // Larger than the memory it is given: the guard of `monolayer run`, before anything.
    let o = bin()
        .args(["run", "--quiet", "--max-memory", "1K", "--resume"])
        .arg(&out)
        .args(["--set", "run.time=3"])
        .output()
        .unwrap();
    refused(&o, &["--max-memory 1K", "needs about"], "over --max-memory");
    assert!(
        snapshot(&out) == before,
        "over --max-memory: the directory changed"
    );
    // Held by another process (this one).
    {
        let _held = rundir::lock_dir(&out).unwrap();
        let o = resume(&["run.time=3"], &[]);
        refused(&o, &["in use by another monolayer process"], "a held lock");
        assert!(
            snapshot(&out) == before,
            "a held lock: the directory changed"
        );
    }
    // A scene that is not its checkpoints' any more.
    let scene = std::fs::read_to_string(out.join("scene.toml")).unwrap();
    std::fs::write(
        out.join("scene.toml"),
        scene.replace("zeta = 0.005", "zeta = 0.007"),
    )
    .unwrap();
    let before = snapshot(&out);
    refused(
        &resume(&["run.time=3"], &[]),
        &["checkpoint"],
        "another run's checkpoints",
    );
    assert!(
        snapshot(&out) == before,
        "another run: the directory changed"
    );
    std::fs::write(out.join("scene.toml"), scene).unwrap();
    // No checkpoint.
    std::fs::remove_dir_all(out.join("checkpoints")).unwrap();
    let before = snapshot(&out);
    refused(
        &resume(&["run.time=3"], &[]),
        &["no checkpoint"],
        "no checkpoint",
    );
    assert!(
        snapshot(&out) == before,
        "no checkpoint: the directory changed"
    );
}

/// Issue 53: reading a run needs no code that reading does not run. A run whose scene names
/// a term this binary does not register (`[terms.push]`, as a user's own program would have
/// run it) is rendered, exported to ParaView and analysed (on main each refused: "no term
/// named push is registered"); its frames' fields are rebuilt with the whole-cell forces the
/// frames recorded, so the pictures are those of the same run without the table (whose
/// recorded forces are zero here). Running its scene, which steps the term, is refused by
/// name.
#[test]
fn a_run_with_an_unregistered_term_is_read_but_not_resumed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    small_paper_run(&out, "run.output_every=2");
    let read = |what: &str, args: &[&str], to: &Path| {
        let o = bin().args(args).output().unwrap();
        assert!(o.status.success(), "{what}: {}", stderr(&o));
        let mut files: Vec<_> = std::fs::read_dir(to)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        files
            .iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect::<Vec<_>>()
    };
    let outs = out.display().to_string();
    let png = |tag: &str| dir.path().join(format!("png-{tag}"));
    let render = |tag: &str| {
        let to = png(tag);
        read(
            "render",
            &[
                "render",
                &outs,
                "--colour",
                "velocity",
                "--flow",
                "--out",
                &to.display().to_string(),
            ],
            &to,
        )
    };
    let plain = render("plain");
    let scene = std::fs::read_to_string(out.join("scene.toml")).unwrap();
    std::fs::write(
        out.join("scene.toml"),
        format!("{scene}\n[terms.push]\nstrength = 0.01\n"),
    )
    .unwrap();
    assert_eq!(render("term"), plain, "the pictures of the same run");
    let vtk = read("export vtk", &["export", "vtk", &outs], &out.join("vtk"));
    assert!(!vtk.is_empty());
    let o = bin().args(["analyze", &outs]).output().unwrap();
    assert!(o.status.success(), "analyze: {}", stderr(&o));
    // Stepping it needs the term: refused by name.
    let o = run(&out.join("scene.toml"), &dir.path().join("again"), &[]);
    refused(&o, &["push", "register"], "a run of an unregistered term");
}

/// Issue 53: the messages about the stress-based extrusion name its key. `extrusion_pressure
/// = 0` is refused before the run (on main it ran, extruded every cell, and the message named
/// `death_rate or extrusion`); a rule so low that the tissue dies out names
/// `extrusion_pressure` as the key to raise.
#[test]
fn the_extrusion_pressure_messages_name_their_key() {
    let dir = tempfile::tempdir().unwrap();
    let small = [
        "domain.lx=60",
        "domain.ly=60",
        "cells.count=12",
        "division.max_cells=40",
        "run.relax_time=10",
        "run.time=40",
    ];
    let with = |p: &str| -> Vec<String> {
        small
            .iter()
            .map(|s| s.to_string())
            .chain([format!("division.extrusion_pressure={p}")])
            .collect()
    };
    for p in ["0", "-0.01"] {
        let set = with(p);
        let set: Vec<&str> = set.iter().map(String::as_str).collect();
        let out = dir.path().join(format!("refused{p}"));
        let o = run(&scene_path("proliferation.toml"), &out, &set);
        refused(&o, &["extrusion_pressure", "positive"], p);
        assert!(!out.exists());
    }
    let set = with("1e-9");
    let set: Vec<&str> = set.iter().map(String::as_str).collect();
    let o = run(
        &scene_path("proliferation.toml"),
        &dir.path().join("gone"),
        &set,
    );
    refused(
        &o,
        &["every cell is gone", "raise [division] extrusion_pressure"],
        "a tissue extruded to the last cell",
    );
}
