//! The error of reading a run directory's frames and analysing them ([`AnalyzeError`]), shared
//! by the frame reader ([`crate::frame`]), the analysis ([`crate::analyze`]) and the views
//! ([`crate::view`]), so that none of them imports another for it.

use std::path::{Path, PathBuf};

/// What stops the analysis of a run, naming the file or option.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnalyzeError {
    /// A file of the run is missing, damaged or inconsistent with the scene.
    #[error("{}: {why}", path.display())]
    Input {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong, and what to do.
        why: String,
    },
    /// An option cannot be used.
    #[error("{0}")]
    Options(String),
    /// An output file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
}

pub(crate) type Result<T, E = AnalyzeError> = std::result::Result<T, E>;

pub(crate) fn input(path: &Path, why: impl Into<String>) -> AnalyzeError {
    AnalyzeError::Input {
        path: path.to_path_buf(),
        why: why.into(),
    }
}
