//! The summary of a run: time averages of its series over a stated window, and the late
//! growth rate of `ln v_rms`.

use std::path::Path;

use crate::SweepError;

/// The columns of a run's summary, after the varied keys and `seed`.
pub const SUMMARY_COLUMNS: &str =
    "window_start,window_end,rows,v_rms,s_rms,area_mean,growth_rate,growth_exponent";

/// A run's summary over its window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSummary {
    /// Start of the averaging window (model time).
    pub window_start: f64,
    /// End of the window: the end of the run.
    pub window_end: f64,
    /// Rows of `series.csv` in the window.
    pub rows: usize,
    /// Mean `v_rms` over the window.
    pub v_rms: f64,
    /// Mean `s_rms` over the window.
    pub s_rms: f64,
    /// Mean `area_mean` over the window.
    pub area_mean: f64,
    /// Least-squares slope of `ln v_rms` against time over the window, per TU: positive where
    /// the flow grows, negative where it decays.
    pub growth_rate: f64,
    /// Least-squares slope of `ln v_rms` against `ln(t − t₀)` over the window, `t₀` the start
    /// of the active phase (`2·window_start − window_end`, the window being its second half):
    /// the local exponent of `v_rms ∝ (t − t₀)^p`. Scale-free where the growth rate is not: a
    /// passive packing that relaxes as a power law has a growth rate that tends to 0 from
    /// below as ~1/T whatever the physics, and a constant negative exponent.
    pub growth_exponent: f64,
}

impl RunSummary {
    /// The row, in the order of [`SUMMARY_COLUMNS`].
    pub fn csv(&self) -> String {
        format!(
            "{},{},{},{:e},{:e},{},{:e},{:e}",
            self.window_start,
            self.window_end,
            self.rows,
            self.v_rms,
            self.s_rms,
            self.area_mean,
            self.growth_rate,
            self.growth_exponent
        )
    }
}

/// The window of a run: the second half of its active phase,
/// `[relax_time + time/2, relax_time + time]`, where a flow that is going to develop has had
/// time to, and a passive one to settle.
pub fn window(relax_time: f64, time: f64) -> (f64, f64) {
    (relax_time + 0.5 * time, relax_time + time)
}

/// The least-squares slope of `y` against `t`; `NaN` for fewer than two distinct times.
pub fn slope(t: &[f64], y: &[f64]) -> f64 {
    let n = t.len() as f64;
    if t.len() < 2 {
        return f64::NAN;
    }
    let (mt, my) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let cov: f64 = t.iter().zip(y).map(|(a, b)| (a - mt) * (b - my)).sum();
    let var: f64 = t.iter().map(|a| (a - mt) * (a - mt)).sum();
    if var == 0.0 {
        f64::NAN
    } else {
        cov / var
    }
}

/// Summarises the `series.csv` of `run_dir` over `window` (to within 10⁻⁹ TU at its ends).
///
/// # Errors
/// When the file is missing, malformed, or has no row in the window.
pub fn summarise(run_dir: &Path, window: (f64, f64)) -> Result<RunSummary, SweepError> {
    let path = run_dir.join("series.csv");
    let bad = |why: String| SweepError::Series {
        path: path.clone(),
        why,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| bad(e.to_string()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| bad("empty".into()))?
        .split(',')
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| bad(format!("no column {name}")))
    };
    let (ct, cv, cs, ca) = (
        col("time")?,
        col("v_rms")?,
        col("s_rms")?,
        col("area_mean")?,
    );
    let (mut t, mut ln_v, mut ln_t) = (Vec::new(), Vec::new(), Vec::new());
    let t0 = 2.0 * window.0 - window.1;
    let (mut sv, mut ss, mut sa) = (0.0, 0.0, 0.0);
    for (k, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let num = |c: usize| -> Result<f64, SweepError> {
            f.get(c)
                .and_then(|v| v.parse::<f64>().ok())
                .ok_or_else(|| bad(format!("row {} is malformed", k + 2)))
        };
        let time = num(ct)?;
        if time < window.0 - 1e-9 || time > window.1 + 1e-9 {
            continue;
        }
        let (v, s, a) = (num(cv)?, num(cs)?, num(ca)?);
        t.push(time);
        ln_v.push(v.ln());
        ln_t.push((time - t0).ln());
        sv += v;
        ss += s;
        sa += a;
    }
    if t.is_empty() {
        return Err(bad(format!(
            "no row in the window [{}, {}]: the run is shorter than its scene",
            window.0, window.1
        )));
    }
    let n = t.len() as f64;
    Ok(RunSummary {
        window_start: window.0,
        window_end: window.1,
        rows: t.len(),
        v_rms: sv / n,
        s_rms: ss / n,
        area_mean: sa / n,
        growth_rate: slope(&t, &ln_v),
        growth_exponent: slope(&ln_t, &ln_v),
    })
}

/// The columns an analysed run adds to its summary row.
pub const ANALYSIS_COLUMNS: &str =
    "length_velocity,length_vorticity,length_q,defect_density,creation_rate";

/// A run's `monolayer analyze` results as summary columns: the three correlation lengths
/// (`analysis/lengths.csv`) and the means over the analysed frames of the defect density and
/// of the creation rate (`analysis/observables.csv`; frames where a rate is undefined, the
/// first, are left out).
///
/// # Errors
/// When the files are missing or malformed.
pub fn analysis_columns(run_dir: &Path) -> Result<String, SweepError> {
    let dir = run_dir.join("analysis");
    let read = |name: &str| {
        let path = dir.join(name);
        std::fs::read_to_string(&path)
            .map(|t| (path.clone(), t))
            .map_err(|e| SweepError::Series {
                path,
                why: format!("{e}; analyse the run first (--analyze)"),
            })
    };
    let (path, lengths) = read("lengths.csv")?;
    let length = |field: &str| -> Result<String, SweepError> {
        lengths
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{field},")))
            .map(str::to_string)
            .ok_or_else(|| SweepError::Series {
                path: path.clone(),
                why: format!("no length of {field}"),
            })
    };
    let (path, obs) = read("observables.csv")?;
    let mut lines = obs.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let mean = |name: &str| -> Result<f64, SweepError> {
        let c = header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| SweepError::Series {
                path: path.clone(),
                why: format!("no column {name}"),
            })?;
        let values: Vec<f64> = obs
            .lines()
            .skip(1)
            .filter_map(|l| l.split(',').nth(c)?.parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .collect();
        Ok(values.iter().sum::<f64>() / values.len() as f64)
    };
    Ok(format!(
        "{},{},{},{:e},{:e}",
        length("velocity")?,
        length("vorticity")?,
        length("q")?,
        mean("defect_density")?,
        mean("creation_rate")?
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a synthetic power law `v = v0 (t − t₀)^p` (a passive packing relaxing) the local
    /// exponent is `p` to round-off at every window, while the growth rate tends to 0 from
    /// below as the window moves out (`p/t` for a window at t): the rate's zero is a matter of
    /// the run length, the exponent's is not.
    #[test]
    fn the_exponent_of_a_synthetic_power_law_is_its_power() {
        let dir = tempfile::tempdir().unwrap();
        let (t0, p) = (20.0, -0.7);
        let mut text = String::from("step,time,zeta,v_rms,s_rms,area_mean\n");
        for k in 0..=3200 {
            let t = t0 + k as f64;
            let v = if k == 0 { 1.0 } else { 1e-2 * (t - t0).powf(p) };
            text += &format!("{k},{t},0,{v:e},1.5,160\n");
        }
        std::fs::write(dir.path().join("series.csv"), text).unwrap();
        let mut rates = Vec::new();
        for time in [200.0, 800.0, 3200.0] {
            let s = summarise(dir.path(), window(t0, time)).unwrap();
            assert!(
                (s.growth_exponent - p).abs() < 1e-9,
                "{}",
                s.growth_exponent
            );
            assert!(s.growth_rate < 0.0);
            rates.push(s.growth_rate);
        }
        assert!(rates[0] < rates[1] && rates[1] < rates[2], "{rates:?}");
        assert!(rates[2].abs() < 0.1 * rates[0].abs(), "{rates:?}");
    }

    /// On a synthetic exponential `v = v0 e^{r t}` the growth rate is `r` to round-off, the
    /// averages are the exact means of the rows, and rows outside the window are left out.
    #[test]
    fn the_growth_rate_of_a_synthetic_exponential_is_its_rate() {
        let dir = tempfile::tempdir().unwrap();
        for &rate in &[-0.013, 0.0, 0.021] {
            let mut text = String::from("step,time,zeta,v_rms,s_rms,area_mean\n");
            let mut expected = 0.0;
            for k in 0..=100 {
                let t = k as f64;
                let v = 1e-3 * (rate * t).exp();
                if t >= 60.0 {
                    expected += v;
                }
                text += &format!("{k},{t},0.005,{v:e},1.5,160\n");
            }
            std::fs::write(dir.path().join("series.csv"), text).unwrap();
            let s = summarise(dir.path(), window(20.0, 80.0)).unwrap();
            assert_eq!(s.rows, 41, "t = 60, ..., 100");
            assert!(
                (s.growth_rate - rate).abs() < 1e-12,
                "{} {rate}",
                s.growth_rate
            );
            assert!((s.v_rms - expected / 41.0).abs() < 1e-15 * expected);
            assert_eq!((s.s_rms, s.area_mean), (1.5, 160.0));
        }
    }

    #[test]
    fn a_run_shorter_than_its_window_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("series.csv"),
            "step,time,v_rms,s_rms,area_mean\n0,0,1,1,1\n",
        )
        .unwrap();
        let e = summarise(dir.path(), (10.0, 20.0)).unwrap_err().to_string();
        assert!(
            e.contains("series.csv") && e.contains("no row in the window"),
            "{e}"
        );
    }
}
