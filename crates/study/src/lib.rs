//! # study
//!
//! Workflows over many runs (the layout's floor 4). Today: parameter sweeps.
//!
//! A sweep is a scene, `--set` overrides, axes ([`Vary`], `section.key=V1,V2,...`) and
//! [`Seeds`]. [`plan`] expands them into [`Point`]s, the last axis fastest and the seeds
//! fastest of all, and validates every point's scene before anything runs. [`run_points`]
//! runs them, `jobs` at a time, each in `DIR/runs/NAME/` as an ordinary run directory, and
//! marks each finished run with a `complete` file holding its resolved scene. A second call
//! with the same arguments skips the complete runs and starts the others again from their
//! beginning. [`write_summary`] writes `DIR/summary.csv`: one row per run, with time averages
//! of `v_rms`, `s_rms` and `area_mean` over the second half of the active phase, and the
//! growth rate of `ln v_rms` there ([`summary`]).
//!
//! Beyond one machine, [`write_job_array`] writes a SLURM job array with one task per pending
//! point, each running `monolayer run` on the point's resolved scene and then marking it
//! complete; [`write_summary`] then collects the finished runs.
//!
//! [`threshold`] estimates the activity threshold from a sweep's growth rates (its protocol is
//! in the module docs), and [`threshold::threshold_table`] does so for every combination of
//! the other axes of a sweep's `summary.csv` (`monolayer threshold DIR`).
//!
//! Results do not depend on `jobs`, threads or the backend: every run is bit-identical for any
//! thread count.
//!
//! ```
//! use study::{plan, Vary};
//!
//! let scene = "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 2\n[run]\ntime = 1\n";
//! let zeta: Vary = "model.zeta=0,0.005".parse()?;
//! let points = plan(scene, &[], &[zeta], Some("1-2".parse()?))?;
//! let names: Vec<&str> = points.iter().map(|p| p.name.as_str()).collect();
//! assert_eq!(names, [
//!     "model.zeta=0_seed=1",
//!     "model.zeta=0_seed=2",
//!     "model.zeta=0.005_seed=1",
//!     "model.zeta=0.005_seed=2",
//! ]);
//! assert_eq!(points[3].scene.file().model.zeta, 0.005);
//! # Ok::<(), study::SweepError>(())
//! ```
#![deny(missing_docs)]

pub mod analyze;
mod error;
mod frame;
mod plan;
mod region;
mod slurm;
mod spec;
pub mod summary;
mod sweep;
pub mod threshold;
pub mod view;

use std::path::PathBuf;

pub use plan::{plan, Point, Seeds, Vary};
pub use slurm::{write_job_array, JobArray};
pub use spec::SweepSpec;
pub use sweep::{
    analyze_points, in_jobs, is_complete, pending, run_dir, run_points, write_summary, Stopped,
    SweepInfo, SweepParams, COMPLETE,
};

/// What stops a sweep, naming the argument, the point or the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SweepError {
    /// A `--vary` argument is malformed.
    #[error("--vary {arg}: {why}; write --vary section.key=V1,V2,..., e.g. --vary model.zeta=0.004,0.006")]
    BadVary {
        /// The argument.
        arg: String,
        /// What is wrong.
        why: String,
    },
    /// A `--seeds` argument is malformed.
    #[error("--seeds {arg}: write a range A-B with A ≤ B (at most 10000 seeds) or one seed, e.g. --seeds 1-5")]
    BadSeeds {
        /// The argument.
        arg: String,
    },
    /// A point's scene is invalid.
    #[error("sweep point {point}")]
    Scene {
        /// The point (or "the base scene").
        point: String,
        /// The scene's error.
        #[source]
        source: Box<scene::SceneError>,
    },
    /// A run directory could not be written.
    #[error("sweep point {point}")]
    RunDir {
        /// The point.
        point: String,
        /// The error.
        #[source]
        source: rundir::RunDirError,
    },
    /// A run stopped early.
    #[error("sweep point {point}: the run stopped")]
    Run {
        /// The point.
        point: String,
        /// The error.
        #[source]
        source: mechanics::SimulationError,
    },
    /// A point's run directory is held by another process, or its run failed.
    #[error("sweep point {point}")]
    Held {
        /// The point.
        point: String,
        /// The error.
        #[source]
        source: Box<rundir::RunError>,
    },
    /// A signal stopped the sweep; the runs in progress wrote a checkpoint.
    #[error("stopped by signal {signal}: {}; run the same sweep command again to continue", runs.iter().map(|r| format!("{} at step {} (t = {})", r.dir.display(), r.step, r.time)).collect::<Vec<_>>().join(", "))]
    Interrupted {
        /// The signal.
        signal: i32,
        /// The runs it stopped.
        runs: Vec<crate::sweep::Stopped>,
    },
    /// A series cannot be summarised.
    #[error("{}: {why}", path.display())]
    Series {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
    /// A point has no complete run.
    #[error("sweep point {point} has no complete run: run the sweep (again) first")]
    Incomplete {
        /// The point.
        point: String,
    },
    /// A directory holds no record of a sweep.
    #[error("{} holds no sweep (no sweep/scene.toml and sweep/args.txt): give the directory a sweep wrote with --out", dir.display())]
    NoRecord {
        /// The directory.
        dir: PathBuf,
    },
    /// A threshold cannot be estimated from a summary.
    #[error("threshold: {why}")]
    Threshold {
        /// What is wrong.
        why: String,
    },
    /// A run could not be analysed.
    #[error("analysing {}", run.display())]
    Analyze {
        /// The run directory.
        run: PathBuf,
        /// The error.
        #[source]
        source: analyze::AnalyzeError,
    },
    /// A figure cannot be made.
    #[error("reproduce: {why}")]
    Reproduce {
        /// What is wrong.
        why: String,
    },
    /// The thread pools could not be built.
    #[error("cannot start the worker threads: {0}")]
    Threads(String),
}

impl SweepError {
    /// A file of the sweep (`what`: the point or the record it belongs to) could not be
    /// written.
    pub fn write(what: &str, path: &std::path::Path, source: std::io::Error) -> Self {
        Self::RunDir {
            point: what.to_string(),
            source: rundir::RunDirError::Io {
                action: "write",
                path: path.to_path_buf(),
                source,
            },
        }
    }
}
