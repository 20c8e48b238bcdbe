//! The output writers of a run directory, added to a [`Simulation`]: series rows and frames,
//! each on its own schedule and each also writing the final state.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use mechanics::{Callback, CallbackError, Needs, Observation, Schedule, Simulation};
use phasefield::Real;
use scene::OutputSchedules;

use crate::checkpoint::write_checkpoint;
use crate::series::SeriesWriter;
use crate::Result;

/// Counts what the writers of [`add_writers`] wrote.
#[derive(Debug, Clone, Default)]
pub struct Written {
    frames: Arc<AtomicUsize>,
}

impl Written {
    /// Frames written so far.
    pub fn frames(&self) -> usize {
        self.frames.load(Ordering::Relaxed)
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
    schedules: &OutputSchedules,
) -> Result<Written> {
    let series = SeriesWriter::create(dir)?;
    Ok(add_with(sim, dir, schedules, series))
}

/// [`add_writers`] for a run resumed at step `from`: the rows of `series.csv` and the frames
/// at or after `from` are removed, since the resumed run writes them again.
///
/// # Errors
/// When `series.csv` cannot be rewritten or a frame removed.
pub fn add_writers_resumed<T: Real>(
    sim: &mut Simulation<T>,
    dir: &Path,
    schedules: &OutputSchedules,
    from: u64,
) -> Result<Written> {
    let series = SeriesWriter::resume(dir, from)?;
    let frames = dir.join("frames");
    if let Ok(entries) = std::fs::read_dir(&frames) {
        for p in entries.filter_map(|e| e.ok().map(|e| e.path())) {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let step = crate::frame::frame_step(name);
            if name.ends_with(".partial") || step.is_some_and(|s| s >= from) {
                std::fs::remove_file(&p).map_err(|e| crate::RunDirError::io("remove", &p, e))?;
            }
        }
    }
    Ok(add_with(sim, dir, schedules, series))
}

fn add_with<T: Real>(
    sim: &mut Simulation<T>,
    dir: &Path,
    schedules: &OutputSchedules,
    series: SeriesWriter,
) -> Written {
    let written = Written::default();
    sim.add_output_writer(
        "series.csv",
        schedules.series,
        FinalToo::new(SeriesRows(series)),
    );
    sim.add_output_writer(
        "frame writer",
        schedules.frames,
        FinalToo::new(Frames {
            dir: dir.to_path_buf(),
            written: written.frames.clone(),
            forces_by_origin: schedules.forces_by_origin,
        }),
    );
    sim.add_output_writer(
        "lineage.csv",
        schedules.frames,
        FinalToo::new(Lineage(dir.to_path_buf())),
    );
    written
}

/// `lineage.csv`, rewritten with every frame, when cells divide.
struct Lineage(PathBuf);

impl<T: Real> Callback<T> for Lineage {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        if let Some(clock) = obs.tissue().proliferation() {
            crate::lineage::write_lineage(&self.0, clock)?;
        }
        Ok(())
    }
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

    fn needs(&self) -> Needs {
        self.inner.needs()
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

    /// A row is the clock, ζ, the number of cells and the observables: on a device, only
    /// the reduced numbers come back for it.
    fn needs(&self) -> Needs {
        Needs::Observables
    }
}

/// Frames in `frames/`.
struct Frames {
    dir: PathBuf,
    written: Arc<AtomicUsize>,
    /// Whether a frame carries each cell's force by origin (`[run] forces_by_origin`).
    forces_by_origin: bool,
}

impl<T: Real> Callback<T> for Frames {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        let tissue = obs.tissue();
        // The split of the forces evaluates the state once per part, in a workspace of its
        // own (the observation's is shared with the other writers).
        let parts = self.forces_by_origin.then(|| {
            let mut ws = mechanics::Workspace::new(tissue.cells());
            tissue.forces_by_origin(&mut ws)
        });
        let ws = obs.workspace();
        crate::frame::write_frame_with(&self.dir, tissue, ws, parts.as_ref())?;
        self.written.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }
}

/// Adds checkpoints of the run to `sim` (see [`crate::checkpoint`]): on `schedule`, every
/// 10 minutes of wall time, and at the end; `scene_toml` is the resolved scene they carry.
pub fn add_checkpoints<T: Real>(
    sim: &mut Simulation<T>,
    dir: &Path,
    schedule: Schedule,
    scene_toml: &str,
) {
    add_checkpoints_with(sim, dir, schedule, scene_toml, None);
}

/// [`add_checkpoints`], skipping a checkpoint of `schedule` that would come less than
/// `min_wall` of wall time after the last one written (the one at the end is always written).
pub fn add_checkpoints_with<T: Real>(
    sim: &mut Simulation<T>,
    dir: &Path,
    schedule: Schedule,
    scene_toml: &str,
    min_wall: Option<Duration>,
) {
    let writer = |min_wall, at_end| Checkpoints {
        dir: dir.to_path_buf(),
        scene: scene_toml.to_string(),
        min_wall,
        at_end,
        last_wall: None,
        last_step: None,
    };
    sim.add_output_writer("checkpoint", schedule, writer(min_wall, true));
    sim.add_output_writer(
        "checkpoint (wall time)",
        Schedule::WallTimeInterval(Duration::from_secs(600)),
        writer(None, false),
    );
}

/// Checkpoints in `checkpoints/`.
struct Checkpoints {
    dir: PathBuf,
    scene: String,
    /// The least wall time since the last checkpoint for a scheduled one.
    min_wall: Option<Duration>,
    /// Whether the final state gets one too.
    at_end: bool,
    last_wall: Option<Instant>,
    last_step: Option<u64>,
}

impl Checkpoints {
    fn write<T: Real>(
        &mut self,
        obs: &mut Observation<'_, T>,
    ) -> std::result::Result<(), CallbackError> {
        write_checkpoint(&self.dir, obs.tissue(), obs.controller(), &self.scene)?;
        self.last_wall = Some(Instant::now());
        self.last_step = Some(obs.iteration());
        Ok(())
    }
}

impl<T: Real> Callback<T> for Checkpoints {
    fn initialize(&mut self, _: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        // The run's start counts as the last checkpoint for the wall-time rule.
        self.last_wall = Some(Instant::now());
        Ok(())
    }

    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        let recent = match (self.min_wall, self.last_wall) {
            (Some(min), Some(last)) => last.elapsed() < min,
            _ => false,
        };
        if recent || self.last_step == Some(obs.iteration()) {
            return Ok(());
        }
        self.write(obs)
    }

    fn finalize(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        if self.at_end && self.last_step != Some(obs.iteration()) {
            self.write(obs)?;
        }
        Ok(())
    }
}
