//! `series.csv`: one row of observables every `series_every` steps.

use std::fs::File;
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use mechanics::{Observables, Tissue};
use phasefield::Real;

use crate::{Result, RunDirError};

/// The header of `series.csv`.
pub const SERIES_HEADER: &str =
    "step,time,zeta,v_rms,s_rms,area_mean,area_min,area_max,cell_speed_rms,phi_min,phi_max,cells";

/// The header of `analysis/observables.csv`, one row per analysed frame (written by
/// `monolayer analyze`; its columns are described in docs/outputs.md).
pub const OBSERVABLES_HEADER: &str = "frame,time,v_rms,s_rms,s_rms_rel,n_plus,n_minus,n_other,net_charge,defect_density,creations,annihilations,unpaired,creation_rate,v_rms_smooth,demixing,polar_order,gap,rotation,shape_index,v_mean_x,v_mean_y,v_shear_x,radial_excess";

/// The header of `analysis/msd.csv`: the mean squared displacement of the cells at each lag
/// between analysed frames, with the tissue's mean displacement removed (`msd`) and kept
/// (`msd_raw`), and the number of (cell, time origin) pairs averaged.
pub const MSD_HEADER: &str = "lag,msd,msd_raw,samples";

/// Writes `series.csv` row by row, each row in one write, so that a run that stops keeps
/// them; a row that fails (a full disk) is cut off again, so the file always ends with a
/// whole row.
pub struct SeriesWriter {
    path: PathBuf,
    out: File,
    /// Bytes of whole rows (and the header).
    len: u64,
}

impl SeriesWriter {
    /// Creates `dir/series.csv` with its header.
    ///
    /// # Errors
    /// When the file cannot be created or written.
    pub fn create(dir: &Path) -> Result<Self> {
        let path = dir.join("series.csv");
        let out = File::create(&path).map_err(|e| RunDirError::io("create", &path, e))?;
        let mut w = Self { path, out, len: 0 };
        w.append(&format!("{SERIES_HEADER}\n"))?;
        Ok(w)
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
        let mut out = std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(|e| RunDirError::io("open", &path, e))?;
        let len = kept.len() as u64;
        out.seek(SeekFrom::Start(len))
            .map_err(|e| RunDirError::io("open", &path, e))?;
        Ok(Self { path, out, len })
    }

    /// Appends one row.
    ///
    /// # Errors
    /// When the row cannot be written.
    pub fn row<T: Real>(&mut self, tissue: &Tissue<T>, o: &Observables) -> Result<()> {
        self.append(&format!(
            "{},{:.6},{},{:e},{:e},{},{},{},{:e},{},{},{}\n",
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
            o.phi_max,
            tissue.n_cells()
        ))
    }

    /// Writes `text` after the last whole row; on an error, cuts the file back to it.
    fn append(&mut self, text: &str) -> Result<()> {
        match self.out.write_all(text.as_bytes()) {
            Ok(()) => {
                self.len += text.len() as u64;
                Ok(())
            }
            Err(e) => {
                let _ = self.out.set_len(self.len);
                let _ = self.out.seek(SeekFrom::Start(self.len));
                Err(RunDirError::io("write", &self.path, e))
            }
        }
    }
}
