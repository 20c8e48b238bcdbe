//! `[integrator] backend = "gpu"` end to end, on whichever Vulkan adapter is present
//! (lavapipe in CI, where `MONOLAYER_GPU_REQUIRED=1` makes a missing adapter a failure):
//! runs are bit-identical run to run and for any number of lavapipe threads; a checkpoint
//! written by one backend resumes on the other; what the GPU does not run is refused by
//! name before any output is written.

use std::path::Path;
use std::process::Output;

use crate::common::{bin, paper, run_files, scene_path, stderr};

/// The paper's scene, short (lavapipe steps it at about 1.5·10⁶ node-updates/s, 25 ms a
/// step): 4 TU of relaxation and 4 TU at ζ = 0.005 (40 steps of 0.2), frames every 2 TU,
/// checkpoints every 2.
const SHORT: [&str; 12] = [
    "--set",
    "run.relax_time=4",
    "--set",
    "run.time=4",
    "--set",
    "run.output_every=2",
    "--set",
    "run.series_every=0.4",
    "--set",
    "run.checkpoint_every=2",
    "--set",
    "model.zeta=0.005",
];

fn run_paper(out: &Path, backend: &str, lp_threads: &str, extra: &[&str]) -> Output {
    bin()
        .arg("run")
        .arg(paper())
        .arg("--out")
        .arg(out)
        .args(SHORT)
        .args(["--set", &format!("integrator.backend={backend}"), "--quiet"])
        .args(extra)
        .env("LP_NUM_THREADS", lp_threads)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap()
}

/// Whether a failed GPU run failed for want of an adapter, which skips the test unless
/// `MONOLAYER_GPU_REQUIRED=1`.
fn no_adapter(o: &Output) -> bool {
    let e = stderr(o);
    if o.status.success() || !e.contains("no Vulkan adapter") {
        return false;
    }
    assert!(
        std::env::var("MONOLAYER_GPU_REQUIRED").as_deref() != Ok("1"),
        "MONOLAYER_GPU_REQUIRED=1 and: {e}"
    );
    eprintln!("skipped: {e}");
    true
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

/// Two runs on 2 lavapipe threads and one on 1 thread write byte-identical series and
/// frames; the run says which adapter it stepped on.
#[test]
#[cfg_attr(
    no_vulkan_driver,
    ignore = "no Vulkan driver was installed when the tests were built (apt-get install mesa-vulkan-drivers libvulkan1, then build again)"
)]
fn gpu_runs_are_bit_identical_for_any_driver_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    let o = run_paper(&a, "gpu", "2", &[]);
    if no_adapter(&o) {
        return;
    }
    ok(&o);
    ok(&run_paper(&b, "gpu", "2", &[]));
    ok(&run_paper(&c, "gpu", "1", &[]));
    let want = run_files(&a);
    assert_eq!(want.len(), 6, "series.csv and five frames");
    for (other, what) in [(&b, "a second run"), (&c, "one lavapipe thread")] {
        let got = run_files(other);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!(g == w, "{what}: {} differs", w.0);
        }
    }
    let scene = std::fs::read_to_string(a.join("scene.toml")).unwrap();
    assert!(scene.contains("backend = \"gpu\""), "{scene}");
}

/// The columns of `series.csv` by name, as numbers, row by row.
fn series(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

/// A run that starts on one backend and is resumed from its checkpoint on the other follows
/// the run done on the first backend throughout: the rows from the checkpoint on agree in
/// v_rms, S_rms and the mean area to f32 round-off amplified over 10 steps (1e-3 of their
/// value; the backends differ by ~1e-6 in φ per step), and the clock is the same.
#[test]
#[cfg_attr(
    no_vulkan_driver,
    ignore = "no Vulkan driver was installed when the tests were built (apt-get install mesa-vulkan-drivers libvulkan1, then build again)"
)]
fn a_checkpoint_resumes_on_the_other_backend() {
    let dir = tempfile::tempdir().unwrap();
    for (first, second) in [("cpu", "gpu"), ("gpu", "cpu")] {
        let whole = dir.path().join(format!("{first}-whole"));
        let part = dir.path().join(format!("{first}-then-{second}"));
        let o = run_paper(&whole, first, "2", &[]);
        if no_adapter(&o) {
            return;
        }
        ok(&o);
        let o = run_paper(&part, first, "2", &["--set", "run.time=2"]);
        if no_adapter(&o) {
            return;
        }
        ok(&o);
        // The same run cut at 6 TU (its checkpoint there, above), then extended on the other.
        let o = bin()
            .args(["run", "--resume"])
            .arg(&part)
            .args([
                "--set",
                "run.time=4",
                "--set",
                &format!("integrator.backend={second}"),
                "--quiet",
            ])
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap();
        // The first pair runs on the CPU first: its resume is the first GPU run.
        if no_adapter(&o) {
            return;
        }
        ok(&o);
        let (head, want) = series(&whole);
        let (_, got) = series(&part);
        assert_eq!(got.len(), want.len(), "{first} then {second}: rows");
        let col = |name: &str| head.iter().position(|h| h == name).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g[col("step")], w[col("step")]);
            for name in ["v_rms", "s_rms", "area_mean"] {
                let (a, b) = (g[col(name)], w[col(name)]);
                assert!(
                    (a - b).abs() <= 1e-3 * b.abs(),
                    "{first} then {second}: {name} at step {}: {a} against {b}",
                    w[col("step")]
                );
            }
        }
        let scene = std::fs::read_to_string(part.join("scene.toml")).unwrap();
        assert!(
            scene.contains("backend = \"gpu\"") == (second == "gpu"),
            "the resumed run records where its steps run: {scene}"
        );
    }
}

/// Physics beyond the paper's model and settings the GPU does not run are refused, each by
/// its key and with the fix, before the output directory is made.
#[test]
fn the_gpu_refuses_what_it_does_not_run_by_name() {
    let dir = tempfile::tempdir().unwrap();
    for (scene, set, says) in [
        ("paper.toml", "integrator.adaptive=true", "adaptive"),
        ("paper.toml", "integrator.npc=0", "npc"),
        ("paper.toml", "integrator.margin=0", "margin"),
        ("paper.toml", "integrator.precision=\"f64\"", "precision"),
    ] {
        let out = dir.path().join(scene).join(set.replace(['=', '"'], "_"));
        let o = bin()
            .arg("run")
            .arg(scene_path(scene))
            .arg("--out")
            .arg(&out)
            .args(["--set", "integrator.backend=gpu", "--set", set, "--quiet"])
            .output()
            .unwrap();
        let e = stderr(&o);
        assert!(!o.status.success(), "{scene} {set}: refused");
        assert!(
            e.contains(says) && e.contains("backend = \"cpu\""),
            "{scene} {set}: the message names {says} and the fix: {e}"
        );
        assert!(!out.exists(), "{scene} {set}: nothing written");
    }
}

/// More populations than the device's table holds (`gpu::MAX_KINDS`) are refused by the
/// `[[population]]` key before anything is written, with or without an adapter.
#[test]
fn the_gpu_refuses_more_populations_than_it_holds_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = std::fs::read_to_string(scene_path("extensile_contractile.toml")).unwrap();
    let (head, _) = text.split_at(text.find("[[population]]").unwrap());
    let mut scene = head.to_string();
    // 17 populations of the scene's 240 cells: 16 of 14 and one of 16.
    let n = gpu::MAX_KINDS + 1;
    for k in 0..n {
        let count = if k + 1 == n { 240 - 14 * (n - 1) } else { 14 };
        scene.push_str(&format!(
            "[[population]]\nname = \"p{k}\"\ncount = {count}\n\n"
        ));
    }
    text = scene;
    let path = dir.path().join("many.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.path().join("out");
    let o = bin()
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(&out)
        .args(["--set", "integrator.backend=gpu", "--quiet"])
        .output()
        .unwrap();
    let e = stderr(&o);
    assert!(!o.status.success());
    assert!(
        e.contains("[[population]]") && e.contains("at most 16") && e.contains("backend = \"cpu\""),
        "names the key, the limit and the fix: {e}"
    );
    assert!(!out.exists(), "nothing written");
}

/// Every shipped scene: the paper's model (`paper.toml`, `single.toml`, `large.toml`),
/// populations (`mixture.toml`; `extensile_contractile.toml`, two populations of opposite ζ), walls
/// (`channel.toml`),
/// adhesion (`doublet.toml`, two cells that adhere), polarity (`polar.toml`; `walker.toml`,
/// one cell; `disc.toml`, aligning to the velocity in a disc wall; `wound.toml`, whose wall
/// goes when the activity starts) and division (`colony.toml`, from one cell;
/// `proliferation.toml`), run on the GPU and follow the CPU's run: every row of `series.csv`
/// has the same number of cells, and agrees in v_rms, S_rms and the mean area to 1e-3 of its
/// value (f32 round-off amplified over the steps, as across a resume). The polar scenes'
/// noise and the division clock's draws are the same on both (Philox from the same keys).
#[test]
#[cfg_attr(
    no_vulkan_driver,
    ignore = "no Vulkan driver was installed when the tests were built (apt-get install mesa-vulkan-drivers libvulkan1, then build again)"
)]
fn shipped_scenes_run_on_the_gpu_as_on_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    // The division scenes on a short clock, so that cells divide within the run (the colony
    // from one cell, the proliferating tissue from 240 cells to its 600).
    let short_clock: &[&str] = &[
        "division.cycle_time=3",
        "division.cycle_spread=1",
        "division.growth_time=1",
        "run.time=14",
    ];
    for (scene, extra) in [
        ("paper.toml", &[][..]),
        ("single.toml", &[]),
        ("large.toml", &[]),
        ("mixture.toml", &[]),
        ("extensile_contractile.toml", &[]),
        ("channel.toml", &[]),
        ("doublet.toml", &[]),
        ("polar.toml", &[]),
        ("walker.toml", &[]),
        ("disc.toml", &[]),
        ("wound.toml", &[]),
        ("colony.toml", short_clock),
        // (Without its extrusion rule: its initial discs, relaxed here for 2 TU instead of
        // its 100, would all be extruded when the activity starts.)
        (
            "proliferation.toml",
            &[
                "division.cycle_time=3",
                "division.cycle_spread=1",
                "division.growth_time=1",
                "division.extrusion=0",
                "run.time=8",
            ][..],
        ),
    ] {
        let path = scene_path(scene);
        let run = |backend: &str| {
            let out = dir.path().join(scene).join(backend);
            let mut cmd = bin();
            cmd.arg("run").arg(&path).arg("--out").arg(&out).args([
                "--set",
                "run.relax_time=2",
                "--set",
                "run.time=4",
            ]);
            for set in extra {
                cmd.args(["--set", set]);
            }
            let o = cmd
                .args(["--set", &format!("integrator.backend={backend}"), "--quiet"])
                .env("XDG_RUNTIME_DIR", std::env::temp_dir())
                .output()
                .unwrap();
            (out, o)
        };
        let (gpu, o) = run("gpu");
        if no_adapter(&o) {
            return;
        }
        ok(&o);
        let (cpu, o) = run("cpu");
        ok(&o);
        let ((head, g), (_, c)) = (series(&gpu), series(&cpu));
        assert_eq!(g.len(), c.len(), "{scene}: the same rows");
        let k = head.iter().position(|h| h == "cells").unwrap();
        let counts = |rows: &[Vec<f64>]| rows.iter().map(|r| r[k]).collect::<Vec<_>>();
        assert_eq!(counts(&g), counts(&c), "{scene}: the same number of cells");
        if !extra.is_empty() {
            let (first, last) = (c[0][k], c[c.len() - 1][k]);
            assert!(last > first, "{scene}: cells divided ({first} → {last})");
        }
        for name in ["v_rms", "s_rms", "area_mean"] {
            let k = head.iter().position(|h| h == name).unwrap();
            for (a, b) in g.iter().zip(&c) {
                // Plus, for S_rms, 1e-6: f32 round-off of the deformation tensor's terms
                // (of order 1, 1e-7 in one evaluation), which cancel in a round cell
                // (walker.toml's S_rms is 1.6e-6); for v_rms, 1e-9: the f32 round-off of the
                // force densities, which cancel in a cell at rest (single.toml's v_rms is
                // 2e-19 on the CPU and 9e-12 on the GPU).
                let floor = match name {
                    "s_rms" => 1e-6,
                    "v_rms" => 1e-9,
                    _ => 0.0,
                };
                assert!(
                    (a[k] - b[k]).abs() <= 1e-3 * b[k].abs() + floor,
                    "{scene}: {name} at t = {}: {} on the GPU, {} on the CPU",
                    b[1],
                    a[k],
                    b[k]
                );
            }
        }
    }
}

/// Issue 53: the GPU's start-up cost for `[division] max_cells` is stated before it is paid.
/// The backend allocates every per-cell buffer for `max_cells` at the start (on main,
/// `max_cells = 100000` with 8 cells took 80 s to start on lavapipe, without a word); the run
/// now says so, with the estimate, before it opens the device (here with no adapter visible,
/// so that the note comes whatever this machine has), and says nothing at a `max_cells` near
/// the cells present.
#[test]
fn the_gpu_states_what_max_cells_costs_before_it_pays_it() {
    let dir = tempfile::tempdir().unwrap();
    let run = |max_cells: &str| {
        crate::common::bin()
            .arg("run")
            .arg(crate::common::scene_path("proliferation.toml"))
            .arg("--out")
            .arg(dir.path().join(format!("out{max_cells}")))
            .args(
                [
                    "domain.lx=60",
                    "domain.ly=60",
                    "cells.count=8",
                    "integrator.backend=\"gpu\"",
                    &format!("division.max_cells={max_cells}"),
                    "run.time=1",
                ]
                .iter()
                .flat_map(|s| ["--set", s]),
            )
            .env("VK_ICD_FILENAMES", "/nonexistent.json")
            .env("VK_DRIVER_FILES", "/nonexistent.json")
            .output()
            .unwrap()
    };
    let e = crate::common::stderr(&run("100000"));
    assert!(
        e.contains(
            "note: the GPU backend allocates its buffers for [division] max_cells = 100000 cells"
        ) && e.contains("GB of device memory"),
        "{e}"
    );
    let e = crate::common::stderr(&run("20"));
    assert!(!e.contains("allocates its buffers"), "{e}");
}

/// Issue 53 on the GPU: a blow-up in the last step of a run is an error, not a complete run.
/// As the CPU's test in `cli.rs`: one run finds the step that blows up, a second ends exactly
/// on it. The device checks a state at the start of each step only; the driver checks the
/// state it brings back at the end (on main the second run ended as complete) and keeps the
/// last good one it had, so no frame or checkpoint holds the bad state.
#[test]
#[cfg_attr(
    no_vulkan_driver,
    ignore = "no Vulkan driver was installed when the tests were built (apt-get install mesa-vulkan-drivers libvulkan1, then build again)"
)]
fn a_blow_up_in_the_last_step_on_the_gpu_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let blowing = |out: &Path, time: &str| {
        let mut set: Vec<String> = [
            "model.gamma=0",
            "model.zeta=0.01",
            "integrator.dt=1",
            "integrator.stability_check=false",
            "integrator.backend=\"gpu\"",
            "run.relax_time=0",
            "run.output_every=50",
            "run.series_every=1",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        set.push(format!("run.time={time}"));
        bin()
            .arg("run")
            .arg(paper())
            .arg("--out")
            .arg(out)
            .arg("--quiet")
            .args(set.iter().flat_map(|s| ["--set".to_string(), s.clone()]))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap()
    };
    // Without line tension and at dt = 1 (Heun), the tissue blows up near t = 144 on lavapipe.
    let o = blowing(&dir.path().join("first"), "600");
    if no_adapter(&o) {
        return;
    }
    let err = stderr(&o);
    assert!(!o.status.success(), "no blow-up: {err}");
    let step = crate::common::error_step(&err);
    let out = dir.path().join("second");
    let o = blowing(&out, &format!("{step}"));
    let err = stderr(&o);
    assert!(
        !o.status.success(),
        "a GPU run whose last step blows up ended as a success: {err}"
    );
    assert!(err.contains(&format!("at step {step} ")), "{err}");
    assert!(!out.join(rundir::COMPLETE).exists());
    let series = std::fs::read_to_string(out.join("series.csv")).unwrap();
    assert!(series
        .lines()
        .skip(1)
        .all(|l| !l.contains("NaN") && !l.contains("inf")));
    // The last frame is a state the host had, at its own step (not the bad one, nor an old
    // state written under the failing step's number), and its fields are finite.
    let last = rundir::last_frame(&out).unwrap();
    assert!(last < step, "frame {last} of a bad state");
    let phi = rundir::read_npz(
        &out.join(format!("frames/frame_{last:08}.npz")),
        &["phi", "step"],
    )
    .unwrap();
    assert!(phi[0].data.iter().all(|v| v.is_finite()));
    assert_eq!(phi[1].scalar(), Some(last as f64));
    let rows: Vec<u64> = series
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').next()?.parse().ok())
        .collect();
    assert!(rows.iter().all(|&r| r < step), "a row of the bad state");
}

/// A physics term of a user's, which runs on the host.
#[derive(Debug)]
struct HostTerm;

impl mechanics::terms::CellTerm for HostTerm {
    fn name(&self) -> &str {
        "host_only"
    }
}

/// The GPU declares the settings it implements, not only the parts (issue 48): every setting
/// of every shipped scene is among them, with the polarity's contact inhibition and a wound
/// besides; a term of a user's is refused by its table, a value the kernels do not know and a
/// key no part had when the GPU's list was written are refused by name.
#[test]
fn the_gpu_refuses_a_setting_it_has_not_implemented_by_name() {
    let scenes = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"));
    let mut seen = std::collections::BTreeSet::new();
    for path in scenes {
        let text = std::fs::read_to_string(&path).unwrap();
        for set in [&[][..], &["polarity.contact_inhibition=1.0"][..]] {
            let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
            let Ok(scene) = scene::Scene::parse(&text, &set) else {
                continue; // a scene without [polarity]
            };
            let ext = scene.configured_extensions();
            let params = scene.model_params(scene.zeta());
            // The cell nematic (`nematic.toml`) and the pair matrices (`sorting.toml`) are not
            // on the GPU yet: refused by their keys, and by nothing else.
            let refused: Vec<String> = gpu::unsupported(&ext, &params)
                .into_iter()
                .filter(|k| {
                    !k.starts_with("[nematic]")
                        && !k.starts_with("[adhesion] pairs")
                        && !k.starts_with("[repulsion] pairs")
                })
                .collect();
            assert_eq!(refused, Vec::<String>::new(), "{}", path.display());
            if scene.file().nematic.is_some() {
                assert!(
                    gpu::unsupported(&ext, &params)
                        .iter()
                        .any(|k| k.starts_with("[nematic] zeta")),
                    "{}",
                    path.display()
                );
            }
            seen.extend(ext.settings(&params).into_iter().map(|s| s.key));
        }
    }
    for key in [
        "[polarity] align",
        "[polarity] contact_inhibition",
        "[walls] kind",
        "[division] extrusion",
        "[[population]] zeta",
    ] {
        assert!(seen.contains(key), "no shipped scene sets {key}: {seen:?}");
    }
    // A term of a user's: its table.
    let mut terms = mechanics::terms::Terms::default();
    terms.add(std::sync::Arc::new(HostTerm));
    let ext = mechanics::Extensions::none().with(terms);
    let params = mechanics::ModelParams::default();
    let refused = gpu::unsupported(&ext, &params);
    assert!(
        refused.len() == 1 && refused[0].starts_with("[terms.host_only] = "),
        "{refused:?}"
    );
    // A value the kernels do not know, and a key they have never heard of.
    let setting = |key: &str, value: &str| mechanics::Setting {
        part: mechanics::Part::Terms,
        key: key.into(),
        value: value.into(),
    };
    let refused = mechanics::backend::unsupported_settings(
        &[
            setting("[polarity] align", "velocity"),
            setting("[polarity] align", "neighbours"),
            setting("[polarity] chirality", "0.1"),
        ],
        gpu::SETTINGS,
    );
    assert_eq!(
        refused,
        [
            "[polarity] align = neighbours",
            "[polarity] chirality = 0.1"
        ]
    );
}
