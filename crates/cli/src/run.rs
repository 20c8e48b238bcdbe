//! `monolayer run`: builds the scene's [`mechanics::Simulation`] and adds the output writers of a run
//! directory (series rows, frames) and a progress report, each on its schedule.

use std::cell::Cell;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mechanics::{Callback, CallbackError, Observation, Precision, Schedule};
use phasefield::Real;
use scene::Scene;

use crate::output::{write_frame, SeriesWriter};

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

/// Makes sure `out` holds no earlier run: with `overwrite`, removes its `series.csv`,
/// `scene.toml` and `frames/`; without, refuses.
///
/// # Errors
/// When `out` already holds a run and `overwrite` is false, or files cannot be removed.
pub fn prepare_output(out: &Path, overwrite: bool) -> Result<()> {
    let series = out.join("series.csv");
    if !series.exists() {
        return Ok(());
    }
    anyhow::ensure!(
        overwrite,
        "{} already holds a run (series.csv); choose another --out or pass --overwrite to replace it",
        out.display()
    );
    std::fs::remove_file(&series)?;
    let _ = std::fs::remove_file(out.join("scene.toml"));
    let frames = out.join("frames");
    if frames.exists() {
        std::fs::remove_dir_all(&frames)
            .with_context(|| format!("cannot remove {}", frames.display()))?;
    }
    Ok(())
}

/// Runs a valid scene, writing into `out`. On a step error the output written so far is
/// kept and the error is returned.
///
/// # Errors
/// When the directory cannot be written or the run stops early.
pub fn run(scene: &Scene, out: &Path, quiet: bool) -> Result<RunInfo> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;
    std::fs::write(out.join("scene.toml"), scene.to_toml())?;
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
    match scene.precision() {
        Precision::F64 => run_in::<f64>(scene, out, quiet),
        Precision::F32 => run_in::<f32>(scene, out, quiet),
    }
}

fn run_in<T: Real>(scene: &Scene, out: &Path, quiet: bool) -> Result<RunInfo> {
    let counts = scene.step_counts();
    let mut sim = scene.simulation::<T>();
    let frames = Rc::new(Cell::new(0));
    sim.add_output_writer(
        "series.csv",
        Schedule::IterationInterval(counts.series_every),
        FinalToo::new(SeriesRows(SeriesWriter::create(out)?)),
    );
    sim.add_output_writer(
        "frame writer",
        Schedule::IterationInterval(counts.frame_every),
        FinalToo::new(Frames {
            out: out.to_path_buf(),
            written: frames.clone(),
        }),
    );
    sim.add_output_writer(
        "progress",
        Schedule::IterationInterval(counts.series_every.min(counts.frame_every)),
        FinalToo::new(Progress::new(counts.total_steps(), quiet)),
    );
    let result = sim.run();
    let info = result.with_context(|| {
        format!(
            "the run stopped; output up to step {} is kept in {}",
            sim.tissue().iteration(),
            out.display()
        )
    })?;
    Ok(RunInfo {
        steps: info.iterations,
        wall_s: info.wall_time.as_secs_f64(),
        frames: frames.get(),
    })
}

/// A writer that also writes the final state, unless its schedule just did.
struct FinalToo<W> {
    inner: W,
    last: Option<u64>,
}

impl<W> FinalToo<W> {
    fn new(inner: W) -> Self {
        Self { inner, last: None }
    }
}

impl<T: Real, W: Callback<T>> Callback<T> for FinalToo<W> {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        self.last = Some(obs.iteration());
        self.inner.call(obs)
    }

    fn finalize(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        if self.last != Some(obs.iteration()) {
            self.call(obs)?;
        }
        self.inner.finalize(obs)
    }
}

/// Rows of `series.csv`.
struct SeriesRows(SeriesWriter);

impl<T: Real> Callback<T> for SeriesRows {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        let o = obs.observables();
        self.0.row(obs.tissue(), &o)?;
        Ok(())
    }
}

/// Frames in `frames/`.
struct Frames {
    out: PathBuf,
    written: Rc<Cell<usize>>,
}

impl<T: Real> Callback<T> for Frames {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        let tissue = obs.tissue();
        let ws = obs.workspace();
        write_frame(&self.out, tissue, ws)?;
        self.written.set(self.written.get() + 1);
        Ok(())
    }
}

/// A progress bar on a terminal, plain lines (about every 10 %) otherwise.
struct Progress {
    bar: Option<ProgressBar>,
    total: u64,
    quiet: bool,
    next_line: u64,
}

impl Progress {
    fn new(total: u64, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = ProgressBar::new(total);
            b.set_style(
                ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  {msg}  [{elapsed_precise} < {eta_precise}]",
                )
                .expect("valid template"),
            );
            b
        });
        Self {
            bar,
            total,
            quiet,
            next_line: 0,
        }
    }
}

impl<T: Real> Callback<T> for Progress {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        let (step, time, v_rms) = (obs.iteration(), obs.time(), obs.observables().v_rms);
        if let Some(b) = &self.bar {
            b.set_position(step);
            b.set_message(format!("t = {time:.1}  v_rms = {v_rms:.3e}"));
        } else if !self.quiet && (step >= self.next_line || step == self.total) {
            eprintln!(
                "step {step}/{}  t = {time:.1}  v_rms = {v_rms:.3e}",
                self.total
            );
            self.next_line = step + self.total.div_ceil(10).max(1);
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
