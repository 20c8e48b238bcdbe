//! The shell blocks of the README and of `docs/gallery.md` cannot rot: every concrete
//! `monolayer` command in them runs, in order, as written, on the shipped scenes at a small
//! scale (the same scenes on a quarter of the area with a quarter of the cells: the same
//! steps, times and frame numbers, a quarter of the cost); every flag of a synopsis line
//! (`monolayer run SCENE --out DIR [--threads N] ...`) is one its subcommand accepts; every
//! script, benchmark and example they name exists; and the README's test command is the one
//! `.ci/run` runs. Nothing in the repository links to a file outside it.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::quarter_scene;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The ```sh blocks of a Markdown file, each with its continuation lines joined.
fn sh_blocks(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut blocks = Vec::new();
    let mut current: Option<Vec<String>> = None;
    for line in text.lines() {
        match (&mut current, line.trim_start()) {
            (None, l) if l.starts_with("```sh") => current = Some(Vec::new()),
            (Some(_), l) if l.starts_with("```") => blocks.push(current.take().unwrap()),
            (Some(b), _) => match b.last_mut() {
                Some(last) if last.ends_with('\\') => {
                    last.pop();
                    last.push_str(line.trim_start());
                }
                // A synopsis continues on an indented line without a backslash.
                Some(last) if line.starts_with("   ") && last.starts_with("monolayer") => {
                    last.push(' ');
                    last.push_str(line.trim());
                }
                _ => b.push(line.to_string()),
            },
            _ => {}
        }
    }
    blocks
}

/// A synopsis line (placeholders in capitals, options in brackets) rather than a command.
fn is_synopsis(line: &str) -> bool {
    line.contains(" [")
        || line
            .split_whitespace()
            .any(|w| ["SCENE", "DIR", "FIGURE"].contains(&w))
}

/// Checks that every `--flag` of a synopsis is in its subcommand's `--help`.
fn check_synopsis(bin: &Path, line: &str) {
    let words: Vec<&str> = line.split_whitespace().collect();
    let mut sub = vec![words[1]];
    if words[1] == "export" {
        sub.push(words[2]);
    }
    let help = Command::new(bin).args(&sub).arg("--help").output().unwrap();
    assert!(help.status.success(), "monolayer {sub:?} --help");
    let help = String::from_utf8_lossy(&help.stdout);
    for w in &words {
        let flag = w.trim_matches(|c| c == '[' || c == ']');
        let flag = flag.split(['=', ']']).next().unwrap();
        if flag.starts_with("--") && flag.len() > 2 {
            assert!(
                help.contains(&format!("{flag} ")) || help.contains(&format!("{flag}\n")),
                "the documented `{line}` uses {flag}, which `monolayer {}` does not accept",
                sub.join(" ")
            );
        }
    }
}

/// Checks a line that is not run here: the script, bench or example it names exists, and
/// the test command is `.ci/run`'s.
fn check_named(line: &str) {
    let line = line.split('#').next().unwrap().trim();
    let words: Vec<&str> = line.split_whitespace().collect();
    let root = root();
    if let Some(i) = words.iter().position(|w| *w == "--bench") {
        let manifest = std::fs::read_to_string(root.join("benches/Cargo.toml")).unwrap();
        let name = words[i + 1];
        assert!(
            manifest.contains(&format!("name = \"{name}\"")),
            "`{line}`: no bench {name}"
        );
    } else if let Some(i) = words.iter().position(|w| *w == "--example") {
        let path = root.join(format!("benches/examples/{}.rs", words[i + 1]));
        assert!(path.exists(), "`{line}`: no {}", path.display());
    } else if ["bash", "python3"].contains(&words[0]) {
        assert!(root.join(words[1]).exists(), "`{line}`: no {}", words[1]);
    } else if line.starts_with("cargo test") {
        let ci = std::fs::read_to_string(root.join(".ci/run")).unwrap();
        assert!(
            ci.lines().any(|l| l.trim() == format!("{line} --locked")),
            "the README's test command `{line}` is not what .ci/run runs"
        );
    }
}

/// The shipped scenes at a small scale ([`quarter_scene`]), in `dir/scenes/`.
fn small_scenes(dir: &Path) {
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    for e in std::fs::read_dir(root().join("scenes")).unwrap() {
        let path = e.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(scenes.join(path.file_name().unwrap()), quarter_scene(&text)).unwrap();
    }
}

fn run_doc(name: &str) {
    run_doc_with(name, true);
}

/// [`run_doc`]; a page whose blocks are all synopses and named scripts has nothing to run
/// (`must_run` false).
fn run_doc_with(name: &str, must_run: bool) {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_monolayer"));
    let dir = tempfile::tempdir().unwrap();
    small_scenes(dir.path());
    // `monolayer` on the PATH and at target/release/, as after a build.
    let bin_dir = dir.path().join("target/release");
    std::fs::create_dir_all(&bin_dir).unwrap();
    std::os::unix::fs::symlink(&bin, bin_dir.join("monolayer")).unwrap();
    std::fs::create_dir_all(dir.path().join("docs/gallery")).unwrap();
    let mut script = String::from("set -euo pipefail\n");
    let mut ran = 0;
    for block in sh_blocks(&root().join(name)) {
        for line in block {
            let trimmed = line.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            if trimmed.starts_with("monolayer") && is_synopsis(trimmed) {
                check_synopsis(&bin, trimmed);
            } else if let Some(rest) = trimmed.strip_prefix("cargo run --release -- ") {
                script += &format!("monolayer {rest}\n");
                ran += 1;
            } else if trimmed.starts_with("monolayer")
                || trimmed.starts_with("for ")
                || trimmed == "done"
            {
                script += &line;
                script += "\n";
                ran += 1;
            } else if trimmed.starts_with("paraview") {
                // A viewer: the files it opens must exist.
                let file = trimmed.split_whitespace().nth(1).unwrap();
                script += &format!("test -s {file}\n");
            } else {
                check_named(trimmed);
            }
        }
    }
    assert!(ran > 0 || !must_run, "{name} has no command to run");
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let o = Command::new("bash")
        .arg("-c")
        .arg(&script)
        .current_dir(dir.path())
        .env("PATH", path)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{name}'s commands failed:\n{script}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn the_readme_commands_run() {
    run_doc("README.md");
}

#[test]
fn the_gallery_commands_run() {
    run_doc("docs/gallery.md");
}

/// The reference pages the README links to: their commands run and their synopses are
/// the binary's.
#[test]
fn the_reference_pages_commands_run() {
    for page in ["docs/scenes.md", "docs/running.md", "docs/outputs.md"] {
        run_doc_with(page, false);
    }
}

/// Every array a frame can hold is a row of docs/outputs.md's frame table: a frame of a
/// scene with every extension (polarity, populations, adhesion, walls, division) names no
/// array the table lacks.
#[test]
fn every_frame_array_is_documented_in_docs_outputs_md() {
    let doc = std::fs::read_to_string(root().join("docs/outputs.md")).unwrap();
    let documented: Vec<String> = doc
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split(" | ").next())
        .flat_map(|cell| {
            cell.split('`')
                .filter(|w| !w.is_empty() && !w.starts_with(','))
                .map(|w| w.trim_matches(|c| c == ',' || c == ' ').to_string())
                .collect::<Vec<_>>()
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("all.toml");
    std::fs::write(
        &scene,
        "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 6\nradius = 6.0\n\
         [polarity]\nalpha = 0.02\n[adhesion]\nomega = 0.002\n\
         [[population]]\ncount = 3\ngamma = 0.02\n[[population]]\ncount = 3\n\
         [walls]\nkind = \"disc\"\n[division]\ncycle_time = 4.0\n\
         [integrator]\nmargin = 12\n[run]\nrelax_time = 2.0\ntime = 4.0\noutput_every = 2.0\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_monolayer"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frame = out.join("frames/frame_00000012.npz");
    let names = rundir::npz_names(&frame).unwrap();
    assert!(names.len() >= 15, "{names:?}");
    let missing: Vec<&String> = names.iter().filter(|n| !documented.contains(n)).collect();
    assert!(
        missing.is_empty(),
        "frame arrays without a row in docs/outputs.md: {missing:?}"
    );
}

/// No tracked text file points into `../shared` (or any path above the repository): a clone
/// must be complete.
#[test]
fn nothing_links_outside_the_repository() {
    let root = root();
    let files = Command::new("git")
        .args(["ls-files"])
        .current_dir(&root)
        .output()
        .unwrap();
    let mut bad = Vec::new();
    for f in String::from_utf8_lossy(&files.stdout).lines() {
        let Ok(text) = std::fs::read_to_string(root.join(f)) else {
            continue; // binary
        };
        for (k, line) in text.lines().enumerate() {
            if line.contains("../shared") || line.contains("](../") {
                bad.push(format!("{f}:{}: {line}", k + 1));
            }
        }
    }
    // This file names the pattern it looks for.
    bad.retain(|b| !b.starts_with("crates/cli/tests/docs.rs"));
    assert!(
        bad.is_empty(),
        "links outside the repository:\n{}",
        bad.join("\n")
    );
}

/// The keys serde accepts in `section` (every field of its table), read from its own
/// "unknown field" message for a key no table has, so that no list is kept by hand; the
/// sections themselves for `section = None`.
fn scene_keys(section: Option<&str>) -> Vec<String> {
    let base = "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 1\n[[population]]\ncount = 1\n";
    let set = match section {
        None => "zz_no_such_section.k=1".to_string(),
        Some("population") => "population.0.zz_no_such_key=1".to_string(),
        Some(s) => format!("{s}.zz_no_such_key=1"),
    };
    let err = scene::Scene::parse(base, &[set])
        .map(|_| ())
        .unwrap_err()
        .to_string();
    let expected = err
        .split("unknown field")
        .nth(1)
        .and_then(|r| r.split("expected").nth(1))
        .unwrap_or_else(|| panic!("{section:?}: no list of fields in {err:?}"));
    let expected = expected.lines().next().unwrap();
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// Every key of every scene table is in docs/scenes.md's key table: a row whose first cell
/// names the table (`[section]` or `[[section]]`) and the key, so a key added to the scene
/// types without a line of documentation fails here.
#[test]
fn every_scene_key_is_documented_in_docs_scenes_md() {
    let doc = std::fs::read_to_string(root().join("docs/scenes.md")).unwrap();
    let first_cells: Vec<&str> = doc
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split(" | ").next())
        .collect();
    let sections = scene_keys(None);
    assert!(sections.len() >= 9, "{sections:?}");
    let mut missing = Vec::new();
    for section in &sections {
        if section == "terms" {
            // `[terms.NAME]`: a user's term, whose keys are its own.
            if !first_cells.iter().any(|c| c.starts_with("[terms.NAME]")) {
                missing.push("[terms.NAME]".into());
            }
            continue;
        }
        let keys = scene_keys(Some(section));
        assert!(!keys.is_empty(), "{section}");
        for key in keys {
            let table = [format!("[{section}]"), format!("[[{section}]]")];
            let found = first_cells.iter().any(|cell| {
                let (head, rest) = cell.split_once(' ').unwrap_or((cell, ""));
                let head = head.trim_matches('`');
                table.iter().any(|t| t == head)
                    && rest
                        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .any(|w| w == key)
            });
            if !found {
                missing.push(format!("[{section}] {key}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "keys without a row in docs/scenes.md: {missing:?}"
    );
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Issue 53: every message names what exists. Every `--flag` in the libraries' and the
/// binary's sources is a flag of one of `monolayer`'s subcommands (read from their `--help`)
/// or of the other program the text is about (cargo, sbatch: listed below), and every
/// `[section] key` is a key of that scene table (read from serde's own field lists). On main
/// the GPU sweep's refusal suggested `--slurm`, which no subcommand has.
#[test]
fn every_flag_and_key_that_a_message_names_exists() {
    let mut help = String::new();
    for sub in [
        &["run"][..],
        &["sweep"],
        &["threshold"],
        &["reproduce"],
        &["render"],
        &["analyze"],
        &["export", "vtk"],
    ] {
        let o = crate::common::bin()
            .args(sub)
            .arg("--help")
            .output()
            .unwrap();
        help.push_str(&String::from_utf8_lossy(&o.stdout));
    }
    // Flags of the programs a message tells the user to run besides monolayer.
    let other = [
        "--release",       // cargo build --release
        "--features",      // cargo build --features gpu
        "--example",       // cargo run --example threshold
        "--signal",        // the sbatch script's directives
        "--requeue",       //
        "--output",        //
        "--open-mode",     //
        "--ntasks",        //
        "--mem",           //
        "--job-name",      //
        "--cpus-per-task", //
        "--array",         //
    ];
    let sections = scene_keys(None);
    // Words that follow a table's name in prose, not keys.
    let prose = [
        "or", "so", "for", "is", "has", "table", "tables", "counts", "and", "of", "in", "as",
        "with", "keys", "key", "to",
    ];
    let mut files = Vec::new();
    rust_files(&root().join("crates"), &mut files);
    assert!(files.len() > 50, "{}", files.len());
    let mut bad = Vec::new();
    let mut flags_seen = 0;
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let name = f.strip_prefix(root()).unwrap_or(f).display().to_string();
        if name.contains("/tests/") {
            continue;
        }
        for (k, line) in text.lines().enumerate() {
            let at = format!("{name}:{}", k + 1);
            // `--flag`, not `x--y` or `---`.
            for (i, _) in line.match_indices("--") {
                let before = line[..i].chars().last();
                if before.is_some_and(|c| c.is_alphanumeric() || c == '-') {
                    continue;
                }
                let flag: String = line[i + 2..]
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-')
                    .collect();
                if flag.len() < 2 || !flag.starts_with(|c: char| c.is_ascii_lowercase()) {
                    continue;
                }
                let flag = format!("--{}", flag.trim_end_matches('-'));
                flags_seen += 1;
                let known = help.contains(&format!("{flag} "))
                    || help.contains(&format!("{flag}\n"))
                    || help.contains(&format!("{flag}="));
                if !known && !other.contains(&flag.as_str()) {
                    bad.push(format!("{at}: {flag} is no flag of monolayer"));
                }
            }
            // `[section] key` and `[[section]] key`.
            for (i, _) in line.match_indices('[') {
                let rest = &line[i + 1..];
                let rest = rest.strip_prefix('[').unwrap_or(rest);
                let Some((section, after)) = rest.split_once(']') else {
                    continue;
                };
                if !sections.iter().any(|s| s == section) || section == "terms" {
                    continue;
                }
                let after = after.strip_prefix(']').unwrap_or(after);
                let Some(after) = after.strip_prefix(' ') else {
                    continue;
                };
                let key: String = after
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '_')
                    .collect();
                if key.is_empty() || prose.contains(&key.as_str()) {
                    continue;
                }
                if !scene_keys(Some(section)).contains(&key) {
                    bad.push(format!("{at}: [{section}] {key} is no key of [{section}]"));
                }
            }
        }
    }
    assert!(flags_seen > 50, "{flags_seen}");
    assert!(
        bad.is_empty(),
        "messages that name what does not exist:\n{}",
        bad.join("\n")
    );
}
