//! `monolayer run`: the run directory ([`rundir::RunDir`]: lock, writers, checkpoints,
//! signals) with a progress report added, run to its end or to a signal.

use std::io::IsTerminal;
use std::path::Path;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mechanics::{Callback, CallbackError, Needs, Observation, Precision};
use phasefield::Real;
use rundir::{FinalToo, Interrupt, Outcome, RunDir, RunError};
use scene::Scene;

/// What a run reports: finished, or stopped by a signal.
#[derive(Debug, Clone, Copy)]
pub struct RunInfo {
    /// Steps taken.
    pub steps: u64,
    /// Wall time in seconds.
    pub wall_s: f64,
    /// Frames written.
    pub frames: usize,
    /// The step a resumed run continued from.
    pub resumed_from: Option<u64>,
    /// `Some((step, time, signal))` when a signal stopped the run (it is resumable).
    pub stopped: Option<(u64, f64, i32)>,
}

/// Runs a valid scene, writing into `out` (prepared by [`RunDir::create`]), from what
/// [`rundir::prepare_new_run`] checked and read before `out` was touched (the saved state the
/// scene starts from, and the warnings, said once the directory is taken). On a step error
/// the output written so far is kept and the error is returned.
///
/// # Errors
/// When the directory is held by another process, cannot be written, or the run stops early.
pub fn run(
    scene: &Scene,
    new: rundir::NewRun,
    out: &Path,
    overwrite: bool,
    quiet: bool,
) -> Result<RunInfo> {
    let opened = crate::backend::open(scene)?;
    let dir = RunDir::create(
        out,
        scene.clone(),
        new.state,
        overwrite,
        Interrupt::install()?,
    )?;
    for w in new.warnings {
        crate::say!("warning: {w}");
    }
    drive(&dir, opened, quiet)
}

/// The scene's file paths made absolute ([`scene::absolute_paths`]), with the current
/// directory named in the error.
///
/// # Errors
/// The current directory cannot be read.
pub fn absolute_from(scene_path: &Path, text: &str, set: &[String]) -> Result<Vec<String>> {
    scene::absolute_paths(scene_path, text, set).context("cannot read the current directory")
}

/// Continues the run in `dir` from its latest readable checkpoint to the end of its scene,
/// with `set` overrides of `run.time` (to extend a finished run) and `integrator.backend`. Rows and frames at or
/// after the checkpoint are written again, so the directory ends as one uninterrupted run
/// would have left it.
///
/// # Errors
/// No usable checkpoint, a checkpoint of another run, an override other than `run.time`, a
/// run already at its end, a run larger than `--max-memory` (or the memory available), or
/// what [`run`] can fail with.
pub fn resume(
    dir: &Path,
    set: &[String],
    quiet: bool,
    max_memory: Option<&str>,
) -> Result<RunInfo> {
    // A move to a backend that cannot run the scene is refused before the directory is
    // touched (resuming rewrites its scene.toml and removes its analysis).
    if let Ok(text) = std::fs::read_to_string(dir.join("scene.toml")) {
        if let Ok(scene) = Scene::parse(&text, set) {
            crate::backend::check(&scene)?;
        }
    }
    let run = RunDir::resume(dir, set, Interrupt::install()?)?;
    // The memory guard of `monolayer run`, before anything is allocated or written (a resume
    // writes nothing until its simulation is ready).
    crate::guard::memory(run.scene(), max_memory)?;
    if !quiet {
        for s in run.skipped() {
            crate::say!("note: skipping {s}");
        }
    }
    let opened = crate::backend::open(run.scene())?;
    drive(&run, opened, quiet)
}

fn drive(dir: &RunDir, opened: crate::backend::Opened, quiet: bool) -> Result<RunInfo> {
    if let (false, Some(adapter)) = (quiet, opened.describe()) {
        crate::say!("steps on the GPU: {adapter}");
    }
    match dir.scene().precision() {
        Precision::F64 => drive_in::<f64>(dir, opened, quiet),
        Precision::F32 => drive_in::<f32>(dir, opened, quiet),
    }
}

fn drive_in<T: Real>(dir: &RunDir, opened: crate::backend::Opened, quiet: bool) -> Result<RunInfo> {
    // The backend attaches before anything is written: a refusal leaves a resumed run's
    // directory as it was.
    let (mut sim, written) =
        dir.simulation_with::<T, _>(|sim| crate::backend::attach(sim, opened).map_err(anyhow_box))?;
    let scene = dir.scene();
    sim.add_output_writer(
        "progress",
        scene.output_schedules().series,
        FinalToo::new(Progress::new(scene.end_time(), quiet)),
    );
    let outcome = dir.run(&mut sim).map_err(|e| {
        let kept = match &e {
            RunError::Simulation(s) => stopped(dir.dir(), sim.tissue().iteration(), s),
            _ => String::new(),
        };
        anyhow::Error::new(e).context(kept)
    })?;
    let (info, stopped) = match outcome {
        Outcome::Complete(info) => (info, None),
        Outcome::Stopped {
            step,
            time,
            signal,
            info,
        } => (info, Some((step, time, signal))),
    };
    Ok(RunInfo {
        steps: info.iterations,
        wall_s: info.wall_time.as_secs_f64(),
        frames: written.frames(),
        resumed_from: dir.resumed_from(),
        stopped,
    })
}

/// An `anyhow` error as a boxed standard error, with its chain of causes in the message.
fn anyhow_box(e: anyhow::Error) -> Box<dyn std::error::Error + Send + Sync> {
    format!("{e:#}").into()
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
            None => msg.push_str(&format!(
                "; it wrote no checkpoint before it stopped (the first is due after a minute of wall time, and the final one failed too), so it cannot be resumed: once the cause is fixed (space freed on a full disk), start it again with monolayer run {0}/scene.toml --out {0} --overwrite",
                out.display()
            )),
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
    lines: crate::lines::Lines,
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
            lines: crate::lines::Lines::new(),
        }
    }
}

impl<T: Real> Callback<T> for Progress {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        let (step, time, v_rms) = (obs.iteration(), obs.time(), obs.observables().v_rms);
        let end = self.end;
        // With `[division]` the number of cells changes: say it.
        let cells = match obs.tissue().proliferation() {
            Some(_) => format!("  cells = {}", obs.tissue().n_cells()),
            None => String::new(),
        };
        if let Some(b) = &self.bar {
            let done = if end > 0.0 {
                (time / end).min(1.0)
            } else {
                1.0
            };
            b.set_position((done * PROGRESS_TICKS as f64) as u64);
            b.set_message(format!(
                "step {step}  t = {time:.1}  v_rms = {v_rms:.3e}{cells}"
            ));
        } else if !self.quiet && self.lines.due(time, end) {
            crate::say!("step {step}  t = {time:.1}/{end}  v_rms = {v_rms:.3e}{cells}");
        }
        Ok(())
    }

    fn finalize(&mut self, _: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        if let Some(b) = &self.bar {
            b.finish();
        }
        Ok(())
    }

    /// The clock, the number of cells and v_rms.
    fn needs(&self) -> Needs {
        Needs::Observables
    }
}
