//! `monolayer run`: builds the scene's [`mechanics::Simulation`], adds the run directory's
//! writers (`rundir::add_writers`) and a progress report, and runs it.

use std::io::IsTerminal;
use std::path::Path;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mechanics::{Callback, CallbackError, Observation, Precision};
use phasefield::{Cells, Real};
use scene::Scene;

use rundir::FinalToo;

/// What a finished run reports.
#[derive(Debug, Clone, Copy)]
pub struct RunInfo {
    /// Steps taken.
    pub steps: u64,
    /// Wall time in seconds.
    pub wall_s: f64,
    /// Frames written.
    pub frames: usize,
}

/// Runs a valid scene, writing into `out`, from `state` when the scene starts from a saved
/// one (`rundir::initial_state`, read before `out` is prepared). On a step error the output
/// written so far is kept and the error is returned.
///
/// # Errors
/// When the directory cannot be written or the run stops early.
pub fn run(scene: &Scene, state: Option<&Cells<f64>>, out: &Path, quiet: bool) -> Result<RunInfo> {
    rundir::write_scene(out, scene)?;
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
    let from = match state {
        Some(s) => Start::State(s),
        None => Start::Scene,
    };
    match scene.precision() {
        Precision::F64 => run_in::<f64>(scene, out, quiet, from),
        Precision::F32 => run_in::<f32>(scene, out, quiet, from),
    }
}

/// `[cells] from` made absolute, as an override appended to `set`: a relative path given with
/// `--set cells.from=P` is taken from the current directory, one in the scene file from the
/// scene file's directory, so that the resolved scene (`DIR/scene.toml`, a sweep's points, a
/// SLURM task) names the same file from anywhere.
///
/// # Errors
/// A scene that does not parse (the caller's validation reports it with its context).
pub fn absolute_from(scene_path: &Path, text: &str, set: &[String]) -> Result<Vec<String>> {
    let mut set = set.to_vec();
    let cwd = std::env::current_dir().context("cannot read the current directory")?;
    let quoted = |p: &Path| {
        let s = p.to_string_lossy();
        let escaped = s.replace('\\', "\\\\").replace('"', "\\\"");
        format!("cells.from=\"{escaped}\"")
    };
    for o in &mut set {
        if let Some((k, v)) = o.split_once('=') {
            if k.trim() == "cells.from" {
                let v = v.trim().trim_matches('"');
                // An empty path is left for the validation to name.
                if !v.is_empty() && Path::new(v).is_relative() {
                    *o = quoted(&cwd.join(v));
                }
            }
        }
    }
    if let Ok(file) = scene::SceneFile::parse(text, &set) {
        if let Some(from) = file.cells.from.as_deref() {
            if !from.trim().is_empty() && Path::new(from).is_relative() {
                let base = scene_path.parent().unwrap_or(Path::new(""));
                set.push(quoted(&cwd.join(base).join(from)));
            }
        }
    }
    Ok(set)
}

/// Where a run's state comes from.
#[derive(Clone, Copy)]
enum Start<'a> {
    /// The scene's initial discs.
    Scene,
    /// A saved state (`init = "frame"`).
    State(&'a Cells<f64>),
    /// A checkpoint of this run (`--resume`).
    Checkpoint(&'a Path),
}

/// Continues the run in `dir` from its latest readable checkpoint to the end of its scene,
/// with `set` overrides of `run.time` (to extend a finished run). Rows and frames at or
/// after the checkpoint are written again, so the directory ends as one uninterrupted run
/// would have left it. Returns the step it resumed from and what the run did.
///
/// # Errors
/// No usable checkpoint, an override other than `run.time`, a run already at its end, or
/// what [`run`] can fail with.
pub fn resume(dir: &Path, set: &[String], quiet: bool) -> Result<(u64, RunInfo)> {
    for s in set {
        let key = s.split('=').next().unwrap_or("");
        anyhow::ensure!(
            key.trim() == "run.time",
            "--resume continues the run as it was: only --set run.time=T (to extend it) can change; {key} would make it another run (start a new scene instead)"
        );
    }
    let all = rundir::checkpoint::checkpoints(dir);
    anyhow::ensure!(
        !all.is_empty(),
        "{} has no checkpoints/ to resume from (runs write them every [run] checkpoint_every; this one was killed before the first, or was not run by monolayer run)",
        dir.display()
    );
    let mut last_err = None;
    for (step, path) in all.iter().rev() {
        let attempt = || -> Result<(Scene, u64)> {
            let text = rundir::checkpoint::checkpoint_scene(path)?;
            let scene = Scene::parse(&text, set)
                .with_context(|| format!("the scene in {}", path.display()))?;
            Ok((scene, *step))
        };
        match attempt() {
            Ok((scene, step)) => {
                let time = rundir::read_npz(path, &["time"])?[0]
                    .scalar()
                    .unwrap_or(f64::NAN);
                let total = scene.step_counts().total_steps();
                let (complete, at) = match scene.adaptive() {
                    Some(_) => (
                        time >= scene.end_time() * (1.0 - 1e-12),
                        format!("t = {time} of {}", scene.end_time()),
                    ),
                    None => (step >= total, format!("step {step} of {total}")),
                };
                anyhow::ensure!(
                    !complete,
                    "the run in {} is complete ({at}); extend it with --set run.time=T, T above {}",
                    dir.display(),
                    scene.file().run.time
                );
                rundir::write_scene(dir, &scene)?;
                let from = Start::Checkpoint(path);
                let info = match scene.precision() {
                    Precision::F64 => run_in::<f64>(&scene, dir, quiet, from),
                    Precision::F32 => run_in::<f32>(&scene, dir, quiet, from),
                }?;
                return Ok((step, info));
            }
            Err(e) => {
                if !quiet {
                    eprintln!("note: skipping {}: {e:#}", path.display());
                }
                last_err = Some(e);
            }
        }
    }
    Err(last_err.expect("at least one checkpoint was tried"))
}

fn run_in<T: Real>(scene: &Scene, out: &Path, quiet: bool, from: Start<'_>) -> Result<RunInfo> {
    let schedules = scene.output_schedules();
    let (mut sim, written) = match from {
        Start::Scene | Start::State(_) => {
            let tissue = match from {
                Start::State(state) => scene.tissue_from_state::<T>(state)?,
                _ => scene.tissue::<T>()?,
            };
            let mut sim = scene.simulation_from(tissue);
            let w = rundir::add_writers(&mut sim, out, &schedules)?;
            (sim, w)
        }
        Start::Checkpoint(path) => {
            let tissue = rundir::checkpoint::read_checkpoint::<T>(path, scene)?;
            let step = tissue.iteration();
            let mut sim = scene.simulation_from(tissue);
            if let Some(c) = rundir::checkpoint::read_controller(path)? {
                sim.set_controller(c);
            }
            let w = rundir::add_writers_resumed(&mut sim, out, &schedules, step)?;
            (sim, w)
        }
    };
    rundir::add_checkpoints(&mut sim, out, schedules.checkpoints, &scene.to_toml());
    sim.add_output_writer(
        "progress",
        schedules.series,
        FinalToo::new(Progress::new(scene.end_time(), quiet)),
    );
    let result = sim.run();
    let info = result.map_err(|e| {
        let kept = stopped(out, sim.tissue().iteration(), &e);
        anyhow::Error::new(e).context(kept)
    })?;
    rundir::mark_complete(out, scene)?;
    Ok(RunInfo {
        steps: info.iterations,
        wall_s: info.wall_time.as_secs_f64(),
        frames: written.frames(),
    })
}

/// What a run that stopped at `step` with `error` has kept in `out`, and how to go on.
fn stopped(out: &Path, step: u64, error: &mechanics::SimulationError) -> String {
    let frames = match rundir::last_frame(out) {
        Some(f) => format!("frames up to step {f}"),
        None => "no frame".into(),
    };
    let mut msg = format!(
        "the run stopped at step {step}; {} keeps {frames} and series.csv up to its last whole row",
        out.display()
    );
    // A step error would happen again; a failed write (a full disk) can be resumed.
    if matches!(error, mechanics::SimulationError::Callback { .. }) {
        match rundir::checkpoint::checkpoints(out).last() {
            Some((c, _)) => msg.push_str(&format!(
                "; once the cause is fixed, monolayer run --resume {} continues from the checkpoint at step {c}",
                out.display()
            )),
            None => msg.push_str("; there is no checkpoint to resume from"),
        }
    }
    msg
}

/// A progress bar on a terminal, plain lines (about every 10 %) otherwise, in model time
/// (an adaptive run does not know its number of steps in advance).
struct Progress {
    bar: Option<ProgressBar>,
    end: f64,
    quiet: bool,
    next_line: f64,
}

/// Bar positions per run.
const PROGRESS_TICKS: u64 = 1000;

impl Progress {
    fn new(end: f64, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = ProgressBar::new(PROGRESS_TICKS);
            b.set_style(
                ProgressStyle::with_template(
                    "{bar:40} {percent:>3}%  {msg}  [{elapsed_precise} < {eta_precise}]",
                )
                .expect("valid template"),
            );
            b
        });
        Self {
            bar,
            end,
            quiet,
            next_line: 0.0,
        }
    }
}

impl<T: Real> Callback<T> for Progress {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        let (step, time, v_rms) = (obs.iteration(), obs.time(), obs.observables().v_rms);
        let end = self.end;
        if let Some(b) = &self.bar {
            let done = if end > 0.0 {
                (time / end).min(1.0)
            } else {
                1.0
            };
            b.set_position((done * PROGRESS_TICKS as f64) as u64);
            b.set_message(format!("step {step}  t = {time:.1}  v_rms = {v_rms:.3e}"));
        } else if !self.quiet && (time >= self.next_line || time >= end) {
            eprintln!("step {step}  t = {time:.1}/{end}  v_rms = {v_rms:.3e}");
            self.next_line = time + end / 10.0;
        }
        Ok(())
    }

    fn finalize(&mut self, _: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        if let Some(b) = &self.bar {
            b.finish();
        }
        Ok(())
    }
}
