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

    /// Opens `dir/series.csv` of a resumed run: keeps its header and the rows before step
    /// `from` and drops the rest (the resumed run writes them again), then appends.
    ///
    /// # Errors
    /// A missing or foreign `series.csv`, or one that cannot be rewritten.
    pub fn resume(dir: &Path, from: u64) -> Result<Self> {
        let path = dir.join("series.csv");
        let text = std::fs::read_to_string(&path).map_err(|e| RunDirError::io("read", &path, e))?;
        let mut lines = text.lines();
        if lines.next() != Some(SERIES_HEADER) {
            return Err(RunDirError::BadArray {
                path: path.clone(),
                name: "header".into(),
                reason: "not the header this version writes".into(),
            });
        }
        let mut kept = format!("{SERIES_HEADER}\n");
        for l in lines {
            match l.split(',').next().and_then(|s| s.parse::<u64>().ok()) {
                Some(step)
                    if step < from && l.split(',').count() == SERIES_HEADER.split(',').count() =>
                {
                    kept.push_str(l);
                    kept.push('\n');
                }
                _ => break,
            }
        }
        let tmp = dir.join("series.csv.partial");
        std::fs::write(&tmp, &kept).map_err(|e| RunDirError::io("write", &tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| RunDirError::io("rename", &tmp, e))?;
        let f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| RunDirError::io("open", &path, e))?;
        Ok(Self {
            path,
            out: BufWriter::new(f),
        })
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
