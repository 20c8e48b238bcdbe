//! Helpers shared by the binary's test files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `monolayer` binary cargo built for these tests.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_monolayer"))
}

/// A shipped scene, `scenes/NAME`.
pub fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// The paper's scene, `scenes/paper.toml`.
pub fn paper() -> PathBuf {
    scene_path("paper.toml")
}

/// What a command wrote to stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `series.csv` and every frame of a run directory, by name, in name order: what must be
/// byte-identical between two runs that should agree.
pub fn run_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![(
        "series.csv".to_string(),
        std::fs::read(dir.join("series.csv")).unwrap(),
    )];
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    frames.sort();
    for f in frames {
        v.push((
            f.file_name().unwrap().to_string_lossy().into_owned(),
            std::fs::read(&f).unwrap(),
        ));
    }
    v
}

/// Continues the stopped or killed run in `dir` with `--resume` on 2 threads and checks that
/// it ends byte-identical to `want` (the [`run_files`] of the uninterrupted run) and marked
/// complete; `what` names the interruption in a failure.
pub fn resume_matches(dir: &Path, want: &[(String, Vec<u8>)], what: &str) {
    let o = bin()
        .args(["run", "--resume"])
        .arg(dir)
        .args(["--quiet", "--threads", "2"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{what}: {}", stderr(&o));
    let got = run_files(dir);
    assert_eq!(got.len(), want.len(), "{what}: file count");
    for (g, w) in got.iter().zip(want) {
        assert!(g == w, "{what}: {} differs", w.0);
    }
    assert!(
        rundir::is_complete(dir),
        "{what}: the resumed run is marked complete"
    );
}

/// A scene's text at a quarter of its area and cells (the same density, steps and outputs):
/// `lx` and `ly` halved, `count` quartered. A scene that places its cells
/// (`init = "positions"`) stays as it is: its positions do not scale, and it has a few cells.
pub fn quarter_scene(text: &str) -> String {
    if text.contains("init = \"positions\"") {
        return text.to_string();
    }
    let mut out = String::new();
    for line in text.lines() {
        let scaled = |key: &str, div: usize| -> Option<String> {
            let v = line.strip_prefix(key)?.trim().strip_prefix('=')?.trim();
            let n: usize = v.parse().ok()?;
            Some(format!("{key} = {}", (n / div).max(1)))
        };
        let l = scaled("lx", 2)
            .or_else(|| scaled("ly", 2))
            .or_else(|| scaled("count", 4))
            .unwrap_or_else(|| line.to_string());
        out += &l;
        out += "\n";
    }
    out
}

/// The step a step error names (`... at step N (t = ...)`): the last "at step" of a message,
/// since the first is where the run stopped, before it.
pub fn error_step(err: &str) -> u64 {
    err.rsplit("at step ")
        .next()
        .and_then(|r| r.split(|c: char| !c.is_ascii_digit()).next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no step in {err}"))
}

/// `monolayer run BASE --set OVERRIDE ...` must be refused: exit status 1, every string of
/// `expect` in the message (the key, the value, the fix), no panic, and no run directory
/// written (`out` must not exist before). The one check of a bad value's refusal that the
/// validation tests share.
pub fn check_rejected(base: &Path, out: &Path, overrides: &[&str], expect: &[&str]) {
    let mut c = bin();
    c.arg("run").arg(base).arg("--out").arg(out).arg("--quiet");
    for s in overrides {
        c.arg("--set").arg(s);
    }
    let o = c.output().expect("the binary runs");
    let err = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{overrides:?} must be refused: {err}"
    );
    for e in expect {
        assert!(err.contains(e), "{overrides:?}: {err:?} lacks {e:?}");
    }
    assert!(!err.contains("panicked"), "{overrides:?}: {err}");
    assert!(
        !out.exists(),
        "{overrides:?}: the refused run wrote {}",
        out.display()
    );
}

/// Whether Python can `import MODULES` (such as `"vtkmodules.vtkIOXML, numpy"`) for a check by
/// `package`'s own reader. CI must have it (`.ci/run` installs it); elsewhere the caller skips
/// the check, and this says so.
pub fn python_has(modules: &str, package: &str) -> bool {
    let have = Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .status()
        .is_ok_and(|s| s.success());
    if !have {
        assert!(
            std::env::var("CI").is_err(),
            "CI must install {package} (see .ci/run)"
        );
        eprintln!("the {package} Python package is not installed: skipping its check");
    }
    have
}

/// Runs `script` with `python3 -c`, which must succeed (its output is the failure's message).
pub fn run_python(script: &str) {
    let py = Command::new("python3")
        .args(["-c", script])
        .output()
        .unwrap();
    assert!(
        py.status.success(),
        "{}{}",
        String::from_utf8_lossy(&py.stdout),
        String::from_utf8_lossy(&py.stderr)
    );
}
