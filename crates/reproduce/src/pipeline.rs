//! The pipeline every figure goes through, in one place: a figure's sweeps give runs, grouped
//! here by point and seed ([`PointRuns`]); a per-run measure gives each point its values by
//! seed ([`PerSeed`]) and their statistics; the figure turns those into tables ([`Csv`]),
//! plots and claims, and returns them as one [`Made`], which [`crate::reproduce`] writes: the
//! CSV files, the PNG plots and `verdict.md` with the settings.
//!
//! A figure writes nothing itself, but for what it keeps to resume (the `stability` figure's
//! finished configurations).

use std::collections::BTreeMap;
use std::path::Path;

use render::{Heatmap, Plot};
use study::SweepError;

use crate::{drawn, mean_se, write_text, Claim, Rec, Stat, SweepResult, Table};

/// What a figure made: its claims and settings for `verdict.md`, and the tables and plots
/// that the pipeline writes into the figure's directory under the names given.
pub(crate) struct Made {
    pub claims: Vec<Claim>,
    pub settings: String,
    pub tables: Vec<(String, Csv)>,
    pub plots: Vec<(String, Picture)>,
}

/// A picture of a figure, drawn by the `render` crate.
pub(crate) enum Picture {
    /// A plot of series.
    Plot(Plot),
    /// Panels of heat maps in `cols` columns, `panel_px` pixels each, under a title.
    Heatmaps {
        title: String,
        panels: Vec<Heatmap>,
        cols: usize,
        panel_px: u32,
    },
    /// A picture already drawn (a tissue).
    Raster(render::Picture),
}

impl From<Plot> for Picture {
    fn from(p: Plot) -> Self {
        Self::Plot(p)
    }
}

impl Picture {
    fn save_png(&self, path: &Path) -> Result<(), render::RenderError> {
        match self {
            Self::Plot(p) => p.save_png(path),
            Self::Heatmaps {
                title,
                panels,
                cols,
                panel_px,
            } => render::save_heatmaps(path, title, panels, *cols, *panel_px),
            Self::Raster(p) => p.save_png(path),
        }
    }
}

impl Made {
    /// Claims and settings, the files to come ([`Made::table`], [`Made::plot`]).
    pub(crate) fn new(claims: Vec<Claim>, settings: String) -> Self {
        Self {
            claims,
            settings,
            tables: Vec::new(),
            plots: Vec::new(),
        }
    }

    /// With the table `csv` written as `name`.
    pub(crate) fn table(mut self, name: impl Into<String>, csv: Csv) -> Self {
        self.add_table(name, csv);
        self
    }

    /// With the picture `plot` drawn as `name`.
    pub(crate) fn plot(mut self, name: impl Into<String>, plot: impl Into<Picture>) -> Self {
        self.add_plot(name, plot);
        self
    }

    /// Adds the table `csv`, to be written as `name`.
    pub(crate) fn add_table(&mut self, name: impl Into<String>, csv: Csv) {
        self.tables.push((name.into(), csv));
    }

    /// Adds the picture `plot`, to be drawn as `name`.
    pub(crate) fn add_plot(&mut self, name: impl Into<String>, plot: impl Into<Picture>) {
        self.plots.push((name.into(), plot.into()));
    }

    /// Writes the tables and draws the plots into `dir`.
    pub(crate) fn write_files(&self, dir: &Path) -> Result<(), SweepError> {
        for (name, csv) in &self.tables {
            write_text(&dir.join(name), &csv.text())?;
        }
        for (name, plot) in &self.plots {
            drawn(plot.save_png(&dir.join(name)))?;
        }
        Ok(())
    }
}

/// A table to be written as CSV: its header, then rows of cells that the figure formatted
/// ([`sci`] for measured values, so that they keep every digit).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Csv {
    columns: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    /// An empty table with these columns.
    pub(crate) fn new(columns: &[&str]) -> Self {
        Self {
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Adds a row. Panics unless it has a cell for every column (a figure's bug).
    pub(crate) fn row(&mut self, cells: impl IntoIterator<Item = String>) {
        let row: Vec<String> = cells.into_iter().collect();
        assert_eq!(
            row.len(),
            self.columns.len(),
            "a cell for each of the columns {:?}",
            self.columns
        );
        self.rows.push(row);
    }

    /// The CSV text: the header and the rows, one a line.
    pub(crate) fn text(&self) -> String {
        let mut s = self.columns.join(",");
        s.push('\n');
        for r in &self.rows {
            s += &r.join(",");
            s.push('\n');
        }
        s
    }
}

/// The frames of a run directory (`RUN/frames/*.npz`), in step order; `what` names the
/// measurement in the error when the directory cannot be read.
pub(crate) fn frame_paths(run: &Path, what: &str) -> Result<Vec<std::path::PathBuf>, SweepError> {
    let frames = run.join("frames");
    let mut paths: Vec<std::path::PathBuf> = std::fs::read_dir(&frames)
        .map_err(|e| SweepError::write(what, &frames, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "npz"))
        .collect();
    paths.sort();
    Ok(paths)
}

/// A measured value as a CSV cell, to every digit (`{:e}`).
pub(crate) fn sci(v: f64) -> String {
    format!("{v:e}")
}

/// Any value as a CSV cell, as `Display` writes it (a setting, a name).
pub(crate) fn cell(v: impl std::fmt::Display) -> String {
    v.to_string()
}

/// The runs of one point of a figure (its values on the sweep's axes), in seed order.
pub(crate) struct PointRuns {
    pub values: Vec<String>,
    pub runs: Vec<Rec>,
}

impl SweepResult {
    /// Every point's runs, summarised as [`SweepResult::records`] does (over `time` TU of the
    /// active phase), in the order of the sweep's points, each point's runs in seed order.
    pub(crate) fn points(&self, time: Option<f64>) -> Result<Vec<PointRuns>, SweepError> {
        let mut order: Vec<Vec<String>> = Vec::new();
        let mut by: BTreeMap<Vec<String>, Vec<Rec>> = BTreeMap::new();
        for r in self.records(time)? {
            if !by.contains_key(&r.values) {
                order.push(r.values.clone());
            }
            by.entry(r.values.clone()).or_default().push(r);
        }
        Ok(order
            .into_iter()
            .map(|values| {
                let mut runs = by.remove(&values).expect("each point listed once");
                runs.sort_by_key(|r| r.seed);
                PointRuns { values, runs }
            })
            .collect())
    }
}

/// Every run of `points` with its summary, one a row: the point's values under the names
/// `axes`, the seed, then the summary's columns (`study::summary::SUMMARY_COLUMNS`), to every
/// digit. The raw table of a figure whose verdicts come from its runs' summaries alone, kept
/// in `docs/data` and read back by [`points_from_runs_table`] (issue 54).
pub(crate) fn runs_table(axes: &[&str], points: &[PointRuns]) -> Csv {
    let mut columns = axes.to_vec();
    columns.push("seed");
    columns.extend(study::summary::SUMMARY_COLUMNS.split(','));
    let mut csv = Csv::new(&columns);
    for pt in points {
        for r in &pt.runs {
            csv.row(
                pt.values
                    .iter()
                    .map(cell)
                    .chain([cell(r.seed)])
                    .chain(r.summary.csv().split(',').map(str::to_string)),
            );
        }
    }
    csv
}

/// The points of a table that [`runs_table`] wrote with `axes` value columns, in the order of
/// their first rows, each point's runs in seed order. The runs have no directory: only what
/// their summaries say.
///
/// # Errors
/// When the file cannot be read, lacks a column, or has a field that is not a number.
#[cfg(test)]
pub(crate) fn points_from_runs_table(
    path: &Path,
    axes: usize,
) -> Result<Vec<PointRuns>, SweepError> {
    let t = Table::read(path)?;
    let seed = t.col("seed")?;
    let mut points: Vec<PointRuns> = Vec::new();
    for (k, row) in t.rows.iter().enumerate() {
        let values: Vec<String> = row[..axes].to_vec();
        let summary = summary_of_row(&t, k)?;
        let rec = Rec {
            values: values.clone(),
            seed: row[seed].parse().map_err(|_| SweepError::Reproduce {
                why: format!("{}: row {}: seed is not a number", path.display(), k + 1),
            })?,
            run: std::path::PathBuf::new(),
            summary,
        };
        match points.iter_mut().find(|p| p.values == values) {
            Some(p) => p.runs.push(rec),
            None => points.push(PointRuns {
                values,
                runs: vec![rec],
            }),
        }
    }
    for p in &mut points {
        p.runs.sort_by_key(|r| r.seed);
    }
    Ok(points)
}

/// The run summary in row `k` of a table with the columns of
/// `study::summary::SUMMARY_COLUMNS` (as [`runs_table`] writes them).
///
/// # Errors
/// When a column is missing or a field is not a number, naming the file, the row and the
/// column.
#[cfg(test)]
pub(crate) fn summary_of_row(
    t: &Table,
    k: usize,
) -> Result<study::summary::RunSummary, SweepError> {
    let row = &t.rows[k];
    let f = |name: &str| -> Result<f64, SweepError> {
        row[t.col(name)?]
            .parse()
            .map_err(|_| SweepError::Reproduce {
                why: format!(
                    "{}: row {}: {name} is not a number",
                    t.path.display(),
                    k + 1
                ),
            })
    };
    Ok(study::summary::RunSummary {
        window_start: f("window_start")?,
        window_end: f("window_end")?,
        rows: f("rows")? as usize,
        v_rms: f("v_rms")?,
        s_rms: f("s_rms")?,
        area_mean: f("area_mean")?,
        growth_rate: f("growth_rate")?,
        growth_exponent: f("growth_exponent")?,
    })
}

/// The point whose values are `values`, if the sweep has it.
pub(crate) fn point<'a>(points: &'a [PointRuns], values: &[&str]) -> Option<&'a PointRuns> {
    points.iter().find(|p| p.values.iter().eq(values.iter()))
}

impl PointRuns {
    /// Its runs by reference (for the helpers that take a list of runs).
    pub(crate) fn refs(&self) -> Vec<&Rec> {
        self.runs.iter().collect()
    }

    /// `f(run, twin)` for each of its runs that `other` has a run of the same seed for: a
    /// measure paired by seed.
    pub(crate) fn paired(&self, other: &PointRuns, f: impl Fn(&Rec, &Rec) -> f64) -> Vec<f64> {
        self.runs
            .iter()
            .filter_map(|r| {
                other
                    .runs
                    .iter()
                    .find(|b| b.seed == r.seed)
                    .map(|b| f(r, b))
            })
            .collect()
    }

    /// `f` of each run: the point's values by seed.
    pub(crate) fn measure(
        &self,
        f: impl Fn(&Rec) -> Result<f64, SweepError>,
    ) -> Result<PerSeed, SweepError> {
        Ok(PerSeed {
            seeds: self.runs.iter().map(|r| r.seed).collect(),
            values: self.runs.iter().map(f).collect::<Result<_, _>>()?,
        })
    }

    /// The column `column` of every run's table `file` against its column `index`, averaged
    /// over the runs row by row, over the rows they all have: `(index of the first run, mean)`.
    pub(crate) fn mean_series(
        &self,
        file: &str,
        index: &str,
        column: &str,
    ) -> Result<(Vec<f64>, Vec<f64>), SweepError> {
        let series: Vec<(Vec<f64>, Vec<f64>)> = self
            .runs
            .iter()
            .map(|r| {
                let t = Table::read(&r.run.join(file))?;
                Ok((t.f64s(index)?, t.f64s(column)?))
            })
            .collect::<Result<_, SweepError>>()?;
        let rows = series.iter().map(|s| s.0.len()).min().unwrap_or(0);
        let mean = (0..rows)
            .map(|k| series.iter().map(|s| s.1[k]).sum::<f64>() / series.len() as f64)
            .collect();
        let index = series.first().map_or(Vec::new(), |s| s.0[..rows].to_vec());
        Ok((index, mean))
    }
}

/// One quantity of a point, a value for each seed's run.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PerSeed {
    pub seeds: Vec<u64>,
    pub values: Vec<f64>,
}

impl PerSeed {
    /// The mean and standard error over seeds ([`mean_se`]).
    pub(crate) fn mean_se(&self) -> Stat {
        mean_se(&self.values)
    }

    /// The values with `digits` decimals, separated by spaces (a CSV cell).
    pub(crate) fn joined(&self, digits: usize) -> String {
        self.values
            .iter()
            .map(|v| format!("{v:.digits$}"))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CSV text is the header and the rows as written, and a row with a cell missing is
    /// refused.
    #[test]
    fn a_csv_is_its_header_and_rows() {
        let mut t = Csv::new(&["a", "b"]);
        t.row([cell("x"), sci(0.25)]);
        t.row([cell(3), sci(f64::NAN)]);
        assert_eq!(t.text(), "a,b\nx,2.5e-1\n3,NaN\n");
        let short = std::panic::catch_unwind(move || t.clone().row([cell(1)]));
        assert!(short.is_err(), "a row without every cell");
    }

    /// Seed statistics are those of the values: the mean and standard error of 1, 2, 3 are 2
    /// and 1/√3.
    #[test]
    fn seed_statistics() {
        let p = PerSeed {
            seeds: vec![1, 2, 3],
            values: vec![1.0, 2.0, 3.0],
        };
        let (m, se) = p.mean_se();
        assert_eq!(m, 2.0);
        assert!((se - 1.0 / 3f64.sqrt()).abs() < 1e-15);
        assert_eq!(p.joined(2), "1.00 2.00 3.00");
    }
}

/// A result kept on disk with the settings that made it.
#[derive(serde::Serialize, serde::Deserialize)]
struct Kept<T> {
    /// The settings, as `{:?}` writes them: a result made with others is made again.
    fingerprint: String,
    value: T,
}

/// The value kept in `path` ([`keep`]) when it was made with `fingerprint`.
pub(crate) fn kept<T: serde::de::DeserializeOwned>(path: &Path, fingerprint: &str) -> Option<T> {
    let text = std::fs::read_to_string(path).ok()?;
    let kept = toml::from_str::<Kept<T>>(&text).ok()?;
    (kept.fingerprint == fingerprint).then_some(kept.value)
}

/// Keeps `value`, made with `fingerprint`, in `path` (written whole, under a temporary name
/// first).
pub(crate) fn keep<T: serde::Serialize>(
    path: &Path,
    fingerprint: &str,
    value: T,
) -> Result<T, SweepError> {
    let kept = Kept {
        fingerprint: fingerprint.to_string(),
        value,
    };
    let text = toml::to_string(&kept).map_err(|e| SweepError::Reproduce {
        why: format!("cannot keep {}: {e}", path.display()),
    })?;
    write_text(path, &text)?;
    Ok(kept.value)
}
