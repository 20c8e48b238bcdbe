//! `series.csv`: one row of observables every `series_every` steps.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use mechanics::{Observables, Tissue};
use phasefield::Real;

use crate::{Result, RunDirError};

/// The header of `series.csv`.
pub const SERIES_HEADER: &str =
    "step,time,zeta,v_rms,s_rms,area_mean,area_min,area_max,cell_speed_rms,phi_min,phi_max";

/// Writes `series.csv` row by row, flushing each row so that a run that stops keeps them.
pub struct SeriesWriter {
    path: PathBuf,
    out: BufWriter<File>,
}

impl SeriesWriter {
    /// Creates `dir/series.csv` with its header.
    ///
    /// # Errors
    /// When the file cannot be created or written.
    pub fn create(dir: &Path) -> Result<Self> {
        let path = dir.join("series.csv");
        let f = File::create(&path).map_err(|e| RunDirError::io("create", &path, e))?;
        let mut out = BufWriter::new(f);
        writeln!(out, "{SERIES_HEADER}")
            .and_then(|_| out.flush())
            .map_err(|e| RunDirError::io("write", &path, e))?;
        Ok(Self { path, out })
    }

    /// Appends one row.
    ///
    /// # Errors
    /// When the row cannot be written.
    pub fn row<T: Real>(&mut self, tissue: &Tissue<T>, o: &Observables) -> Result<()> {
        writeln!(
            self.out,
            "{},{:.6},{},{:e},{:e},{},{},{},{:e},{},{}",
            tissue.iteration(),
            tissue.time(),
            tissue.params().zeta,
            o.v_rms,
            o.s_rms,
            o.area_mean,
            o.area_min,
            o.area_max,
            o.cell_speed_rms,
            o.phi_min,
            o.phi_max
        )
        .and_then(|_| self.out.flush())
        .map_err(|e| RunDirError::io("write", &self.path, e))
    }
}
