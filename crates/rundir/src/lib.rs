//! # rundir
//!
//! The files of a run directory and nothing else: it knows formats, not physics.
//!
//! | file | written by |
//! |---|---|
//! | `scene.toml` | [`prepare`] and [`write_scene`]: the resolved scene, every default filled in |
//! | `series.csv` | [`SeriesWriter`], one row every `series_every` steps ([`SERIES_HEADER`]) |
//! | `frames/frame_STEP.npz` | [`write_frame`], NumPy archives `numpy.load` reads as they are |
//! | `checkpoints/checkpoint_STEP.npz` | [`add_checkpoints`]: the complete state, for `monolayer run --resume` ([`checkpoint`]) |
//! | `lineage.csv` | with `[division]`: every cell that lived, with its parent, birth, death and why ([`lineage`]), with every frame |
//! | `run.json` | [`write_scene`]: version, precision, axes, the unit of every column |
//! | `vtk/*.vti`, `*.vtp`, `*.pvd` | [`vtk`]: ParaView files (by `monolayer export vtk`) |
//!
//! [`add_writers`] adds the series and frame writers to a [`mechanics::Simulation`];
//! [`read_npz`] reads frames back; [`initial_tissue`] builds a scene's initial tissue, from a
//! saved frame or checkpoint when it has `init = "frame"` ([`state`]). Errors name the file ([`RunDirError`]).
#![deny(missing_docs)]

pub mod checkpoint;
mod frame;
pub mod lineage;
pub mod memory;
pub mod run;
mod series;
mod sidecar;
pub mod state;
pub mod vtk;
mod writers;

use std::path::{Path, PathBuf};

pub use checkpoint::read_extensions;
pub use frame::{
    last_frame, npy, npz_names, read_npz, write_frame, write_frame_with, write_npz, Array,
    FRAME_FORMAT, FRAME_FORMATS_READ,
};
pub use lineage::{read_lineage, write_lineage, LINEAGE_HEADER};
pub use run::{lock_dir, DirLock, Interrupt, Outcome, RunDir, RunError, LOCK};
pub use series::{SeriesWriter, MSD_HEADER, OBSERVABLES_HEADER, SERIES_HEADER};
pub use sidecar::{write_run_json, AXES};
pub use state::{
    initial_state, initial_tissue, not_carried, prepare_new_run, read_state, state_warnings,
    NewRun, PrepareError, StateError,
};
pub use writers::{
    add_checkpoints, add_checkpoints_with, add_writers, add_writers_resumed, FinalToo, Written,
};

/// A file of a run directory could not be read or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunDirError {
    /// An I/O operation on a file failed.
    #[error("cannot {action} {}", path.display())]
    Io {
        /// What was being done (`create`, `write`, `open`, ...).
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The error of the operating system.
        #[source]
        source: std::io::Error,
    },
    /// A file is not a zip archive.
    #[error("{} is not a readable .npz archive (truncated?): {reason}", path.display())]
    Archive {
        /// The file.
        path: PathBuf,
        /// What the zip reader said.
        reason: String,
    },
    /// An archive lacks an array.
    #[error("{} has no array '{name}'", path.display())]
    MissingArray {
        /// The file.
        path: PathBuf,
        /// The array.
        name: String,
    },
    /// An array cannot be decoded.
    #[error("bad array '{name}' in {}: {reason}", path.display())]
    BadArray {
        /// The file.
        path: PathBuf,
        /// The array.
        name: String,
        /// What the decoder said.
        reason: String,
    },
    /// The directory already holds a run.
    #[error("{} already holds a run (series.csv); choose another --out or pass --overwrite to replace it", dir.display())]
    Occupied {
        /// The directory.
        dir: PathBuf,
    },
}

impl RunDirError {
    pub(crate) fn io(action: &'static str, path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            action,
            path: path.to_path_buf(),
            source,
        }
    }
}

/// The result of this crate's operations.
pub type Result<T> = std::result::Result<T, RunDirError>;

/// Makes `dir` ready for a new run: creates it, and makes sure it holds no earlier run. With
/// `overwrite`, removes an earlier run's `series.csv`, `scene.toml`, `lineage.csv`, `frames/`,
/// `checkpoints/` and `analysis/` (which described the old run); without,
/// refuses.
///
/// # Errors
/// [`RunDirError::Occupied`] when `dir` holds a run and `overwrite` is false; I/O errors.
pub fn prepare(dir: &Path, overwrite: bool) -> Result<()> {
    let series = dir.join("series.csv");
    if series.exists() {
        if !overwrite {
            return Err(RunDirError::Occupied {
                dir: dir.to_path_buf(),
            });
        }
        std::fs::remove_file(&series).map_err(|e| RunDirError::io("remove", &series, e))?;
        let _ = std::fs::remove_file(dir.join("scene.toml"));
        let _ = std::fs::remove_file(dir.join("run.json"));
        let _ = std::fs::remove_file(dir.join("lineage.csv"));
        for sub in ["frames", "checkpoints", "analysis"] {
            let d = dir.join(sub);
            if d.exists() {
                std::fs::remove_dir_all(&d).map_err(|e| RunDirError::io("remove", &d, e))?;
            }
        }
    }
    std::fs::create_dir_all(dir).map_err(|e| RunDirError::io("create", dir, e))
}

/// The file that marks a finished run: a copy of its resolved `scene.toml`, written after
/// the last output, so a directory without it (or with another scene in it) is still being
/// written, was killed, or was extended.
pub const COMPLETE: &str = "complete";

/// Marks the run in `dir` complete ([`COMPLETE`]) with its resolved scene.
///
/// # Errors
/// When the mark cannot be written.
pub fn mark_complete(dir: &Path, scene: &scene::Scene) -> Result<()> {
    let path = dir.join(COMPLETE);
    std::fs::write(&path, scene.to_toml()).map_err(|e| RunDirError::io("write", &path, e))
}

/// Whether the run in `dir` is marked complete for the scene in its `scene.toml`.
pub fn is_complete(dir: &Path) -> bool {
    match (
        std::fs::read_to_string(dir.join(COMPLETE)),
        std::fs::read_to_string(dir.join("scene.toml")),
    ) {
        (Ok(mark), Ok(scene)) => mark == scene,
        _ => false,
    }
}

/// Writes the resolved scene as `dir/scene.toml` (removing a [`COMPLETE`] mark), and `dir/run.json` (what the files mean:
/// version, precision, lattice, axes, the unit of every column).
///
/// # Errors
/// When the file cannot be written.
pub fn write_scene(dir: &Path, scene: &scene::Scene) -> Result<()> {
    let _ = std::fs::remove_file(dir.join(COMPLETE));
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene.to_toml()).map_err(|e| RunDirError::io("write", &path, e))?;
    sidecar::write_run_json(dir, scene)
}
