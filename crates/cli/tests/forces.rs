//! `[run] forces_by_origin` (issue 49): each frame carries every cell's force split by origin,
//! the parts add up to the recorded force, `run.json` says what each is, and `export vtk`
//! writes them as cell vectors.

use crate::common::{bin, scene_path, stderr};

/// The nematic scene, 10 TU of relaxation then 10 TU, into `out`, with the overrides `set`.
fn run(out: &std::path::Path, set: &[String]) -> std::process::Output {
    let mut cmd = bin();
    cmd.arg("run")
        .arg(scene_path("nematic.toml"))
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(["--set", "run.relax_time=10", "--set", "run.time=10"]);
    for s in set {
        cmd.args(["--set", s]);
    }
    cmd.output().unwrap()
}

/// The nematic scene with shape activity too (ζ = 0.005), its forces by origin on: the last
/// frame holds `force.pressure`, `force.shape_activity` and `force.nematic_activity`, whose
/// sum is the frame's `force` to 1e-12 of the largest part (the nematic has no whole-cell
/// force, so `cell_force` is zero); a run without the key writes none.
#[test]
fn frames_carry_the_forces_by_origin() {
    let dir = tempfile::tempdir().unwrap();
    let run = |out: &std::path::Path, on: bool| {
        run(
            out,
            &[
                "model.zeta=0.005".into(),
                format!("run.forces_by_origin={on}"),
            ],
        )
    };
    let out = dir.path().join("on");
    let o = run(&out, true);
    assert!(o.status.success(), "{}", stderr(&o));
    let step = rundir::last_frame(&out).unwrap();
    let frame = out.join(format!("frames/frame_{step:08}.npz"));
    let names = [
        "force.pressure",
        "force.shape_activity",
        "force.nematic_activity",
        "force",
        "cell_force",
    ];
    let a = rundir::read_npz(&frame, &names).unwrap();
    let size = a[..3]
        .iter()
        .flat_map(|p| p.data.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(size > 0.0);
    for k in 0..a[3].data.len() {
        let sum: f64 = a[..3].iter().map(|p| p.data[k]).sum();
        let total = a[3].data[k] + a[4].data[k];
        assert!(
            (sum - total).abs() < 1e-12 * size,
            "{k}: {sum} against {total}"
        );
    }
    for p in &a[..3] {
        assert!(
            p.data.iter().any(|v| v.abs() > 1e-6 * size),
            "a part is zero"
        );
    }
    let json = std::fs::read_to_string(out.join("run.json")).unwrap();
    assert!(json.contains("force.nematic_activity"), "{json}");
    let vtk = dir.path().join("vtk");
    let o = bin()
        .args(["export", "vtk"])
        .arg(&out)
        .args(["--frames", &step.to_string(), "--out"])
        .arg(&vtk)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let vtp = std::fs::read(vtk.join(format!("cells_{step:08}.vtp"))).unwrap();
    let name = b"Name=\"force.shape_activity\"";
    assert!(
        vtp.windows(name.len()).any(|w| w == name),
        "no force array in the .vtp"
    );
    let off = dir.path().join("off");
    assert!(run(&off, false).status.success());
    let names = rundir::npz_names(&off.join(format!("frames/frame_{step:08}.npz"))).unwrap();
    assert!(!names.iter().any(|n| n.starts_with("force.")), "{names:?}");
}

/// Friction between cells (`[friction] cells`, issue 49) from the command line: a run with it
/// records its part, `force.friction`, which sums to zero over the cells (1e-12 of its
/// largest: friction is internal); a negative ξ_c is refused by name, with nothing written.
#[test]
fn friction_between_cells_is_a_force_of_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let run = |out: &std::path::Path, cells: &str| {
        run(
            out,
            &[
                "run.forces_by_origin=true".into(),
                format!("friction.cells={cells}"),
            ],
        )
    };
    let o = run(&out, "0.2");
    assert!(o.status.success(), "{}", stderr(&o));
    let step = rundir::last_frame(&out).unwrap();
    let a = rundir::read_npz(
        &out.join(format!("frames/frame_{step:08}.npz")),
        &["force.friction"],
    )
    .unwrap();
    let f = &a[0].data;
    let largest = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(largest > 0.0);
    for axis in 0..2 {
        let sum: f64 = f.iter().skip(axis).step_by(2).sum();
        assert!(sum.abs() < 1e-12 * largest, "{sum:e} of {largest:e}");
    }
    let bad = dir.path().join("bad");
    let o = run(&bad, "-0.1");
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("[friction]") && e.contains("cells"), "{e}");
    assert!(!bad.exists());
}
