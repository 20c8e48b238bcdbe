//! The output writers of a run directory, added to a [`Simulation`]: series rows and frames,
//! each on its own schedule and each also writing the final state.

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use mechanics::{Callback, CallbackError, Observation, Schedule, Simulation};
use phasefield::Real;
use scene::StepCounts;

use crate::frame::write_frame;
use crate::series::SeriesWriter;
use crate::Result;

/// Counts what the writers of [`add_writers`] wrote.
#[derive(Debug, Clone, Default)]
pub struct Written {
    frames: Rc<Cell<usize>>,
}

impl Written {
    /// Frames written so far.
    pub fn frames(&self) -> usize {
        self.frames.get()
    }
}

/// Adds the writers of `dir` to `sim`: a row of `series.csv` every `counts.series_every`
/// steps and a frame every `counts.frame_every` steps, both also at the final state.
///
/// # Errors
/// When `series.csv` cannot be created.
pub fn add_writers<T: Real>(
    sim: &mut Simulation<T>,
    dir: &Path,
    counts: &StepCounts,
) -> Result<Written> {
    let written = Written::default();
    sim.add_output_writer(
        "series.csv",
        Schedule::IterationInterval(counts.series_every),
        FinalToo::new(SeriesRows(SeriesWriter::create(dir)?)),
    );
    sim.add_output_writer(
        "frame writer",
        Schedule::IterationInterval(counts.frame_every),
        FinalToo::new(Frames {
            dir: dir.to_path_buf(),
            written: written.frames.clone(),
        }),
    );
    Ok(written)
}

/// A writer that also writes the final state, unless its schedule just did.
pub struct FinalToo<W> {
    inner: W,
    last: Option<u64>,
}

impl<W> FinalToo<W> {
    /// `inner`, also called at the final state.
    pub fn new(inner: W) -> Self {
        Self { inner, last: None }
    }
}

impl<T: Real, W: Callback<T>> Callback<T> for FinalToo<W> {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        self.last = Some(obs.iteration());
        self.inner.call(obs)
    }

    fn finalize(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        if self.last != Some(obs.iteration()) {
            self.call(obs)?;
        }
        self.inner.finalize(obs)
    }
}

/// Rows of `series.csv`.
struct SeriesRows(SeriesWriter);

impl<T: Real> Callback<T> for SeriesRows {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        let o = obs.observables();
        self.0.row(obs.tissue(), &o)?;
        Ok(())
    }
}

/// Frames in `frames/`.
struct Frames {
    dir: PathBuf,
    written: Rc<Cell<usize>>,
}

impl<T: Real> Callback<T> for Frames {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        let tissue = obs.tissue();
        let ws = obs.workspace();
        write_frame(&self.dir, tissue, ws)?;
        self.written.set(self.written.get() + 1);
        Ok(())
    }
}
