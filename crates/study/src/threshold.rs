//! The activity threshold ζ_cr from the late growth rates of `ln v_rms` (issue 11).
//!
//! The paper's criterion (v_rms > 1e-7 after 3000 steps) separates nothing here: at ζ = 0 the
//! packing keeps coarsening and v_rms is still ~1e-3 after 1200 TU. The protocol used instead
//! looks at the late growth rate
//!
//! ```text
//! r = d ln v_rms / dt,   a least-squares slope over the second half of the active phase,
//! ```
//!
//! of runs that start from the same relaxed states (the same seeds and relaxation) at every
//! activity, and gives two estimates from the same runs:
//!
//! - **growth** (the primary one): ζ_cr is where the seed mean ⟨r(ζ)⟩ first turns positive:
//!   above it the activity makes the flow grow against the relaxation, below it the flow
//!   decays. It is a conservative (upper) estimate for a finite run, because the passive
//!   decay r(0) < 0 still has to be overcome; as runs get longer r(0) → 0⁻ and it moves down.
//! - **excess**: ζ_cr is where `Δ(ζ) = ⟨r(ζ)⟩ − ⟨r(0)⟩` first turns positive, i.e. where the
//!   flow decays more slowly than the passive one. Δ(0) = 0 by construction and Δ rises
//!   smoothly from there, so this estimate sits near the smallest activity tried and is set
//!   by the seed noise; it is a lower bound, not a threshold.
//!
//! Both interpolate linearly between the two activities that bracket the sign change and
//! report the bracket. Near the threshold the rates are small and the estimates move as runs
//! get longer, so the run length is part of the protocol.
/// The growth rates of one activity over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct RatePoint {
    /// The activity.
    pub zeta: f64,
    /// The growth rate of each seed.
    pub rates: Vec<f64>,
}

/// What the rates say about ζ_cr.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Threshold {
    /// Δ changes sign between `lo` and `hi`; `zeta_cr` is the linear interpolation.
    Bracketed {
        /// The estimate.
        zeta_cr: f64,
        /// The largest activity with Δ ≤ 0 below the crossing.
        lo: f64,
        /// The smallest activity with Δ > 0 above it.
        hi: f64,
    },
    /// Δ > 0 at every activity: ζ_cr is below the smallest, `hi`.
    Below {
        /// The smallest activity tried.
        hi: f64,
    },
    /// Δ ≤ 0 at every activity: ζ_cr is above the largest, `lo`.
    Above {
        /// The largest activity tried.
        lo: f64,
    },
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// The threshold from the rates of the activities `points` (any order, ζ > 0) against the
/// rates `baseline`: the first activity where the mean rate exceeds the mean baseline, by
/// linear interpolation. With the rates of ζ = 0 as the baseline this is the *excess*
/// estimate of the module docs, with `&[0.0]` the *growth* estimate ([`growth_threshold`]).
/// Activities without a finite rate are left out.
///
/// # Panics
/// If `baseline` is empty.
pub fn threshold(baseline: &[f64], points: &[RatePoint]) -> Threshold {
    assert!(!baseline.is_empty(), "the threshold needs a ζ = 0 baseline");
    let r0 = mean(baseline);
    let mut excess: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.zeta, mean(&p.rates) - r0))
        .filter(|(z, d)| z.is_finite() && d.is_finite())
        .collect();
    excess.sort_by(|a, b| a.0.total_cmp(&b.0));
    match excess.iter().position(|&(_, d)| d > 0.0) {
        None => Threshold::Above {
            lo: excess.last().map_or(0.0, |e| e.0),
        },
        Some(0) => Threshold::Below { hi: excess[0].0 },
        Some(k) => {
            let ((z0, d0), (z1, d1)) = (excess[k - 1], excess[k]);
            Threshold::Bracketed {
                zeta_cr: z0 + (z1 - z0) * (-d0) / (d1 - d0),
                lo: z0,
                hi: z1,
            }
        }
    }
}

/// The *growth* estimate of the module docs: where the mean late growth rate turns positive.
pub fn growth_threshold(points: &[RatePoint]) -> Threshold {
    threshold(&[0.0], points)
}

/// `(estimate, lo, hi)` of a threshold as CSV fields: empty on an open side.
pub fn csv_fields(t: Threshold) -> [String; 3] {
    match t {
        Threshold::Bracketed { zeta_cr, lo, hi } => {
            [zeta_cr.to_string(), lo.to_string(), hi.to_string()]
        }
        Threshold::Below { hi } => [String::new(), String::new(), hi.to_string()],
        Threshold::Above { lo } => [String::new(), lo.to_string(), String::new()],
    }
}

/// The header of `threshold.csv` after the other varied keys: the growth estimate, the excess
/// estimate (module docs), the seeds of the baseline and the number of activities.
pub const THRESHOLD_COLUMNS: &str =
    "zeta_cr,zeta_cr_lo,zeta_cr_hi,zeta_cr_excess,zeta_cr_excess_lo,zeta_cr_excess_hi,seeds,activities";

/// The threshold of every combination of the other axes of a sweep, from its `summary.csv`
/// text: rows grouped by every varied key but `zeta_key`, the rows with ζ = 0 as the
/// baseline, the others as the activities; both estimates of the module docs. Returns the
/// text of `threshold.csv`: the other keys, then [`THRESHOLD_COLUMNS`]; an open bracket
/// leaves the estimate empty, and its `_lo` or `_hi` empty on its open side.
///
/// # Errors
/// [`crate::SweepError::Threshold`] when the summary has no `zeta_key` column, no growth rates, or a
/// group without a ζ = 0 baseline.
pub fn threshold_table(summary: &str, zeta_key: &str) -> Result<String, crate::SweepError> {
    let bad = |why: String| crate::SweepError::Threshold { why };
    let mut lines = summary.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| bad(format!("summary.csv has no column {name}")))
    };
    let (cz, cs, cr) = (col(zeta_key)?, col("seed")?, col("growth_rate")?);
    let others: Vec<usize> = (0..cs).filter(|&c| c != cz).collect();
    // Groups in order of first appearance: key values → (baseline rates, ζ → rates).
    type Group = (Vec<String>, Vec<f64>, Vec<RatePoint>);
    let mut groups: Vec<Group> = Vec::new();
    for (k, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let field = |c: usize| {
            f.get(c)
                .copied()
                .ok_or_else(|| bad(format!("row {} of summary.csv is short", k + 2)))
        };
        let key: Vec<String> = others
            .iter()
            .map(|&c| field(c).map(str::to_string))
            .collect::<Result<_, _>>()?;
        let zeta: f64 = field(cz)?
            .parse()
            .map_err(|_| bad(format!("{zeta_key} = {} is not a number", f[cz])))?;
        let rate: f64 = field(cr)?.parse().unwrap_or(f64::NAN);
        let g = match groups.iter().position(|g| g.0 == key) {
            Some(i) => &mut groups[i],
            None => {
                groups.push((key, Vec::new(), Vec::new()));
                groups.last_mut().expect("just pushed")
            }
        };
        if zeta == 0.0 {
            g.1.push(rate);
        } else if let Some(p) = g.2.iter_mut().find(|p| p.zeta == zeta) {
            p.rates.push(rate);
        } else {
            g.2.push(RatePoint {
                zeta,
                rates: vec![rate],
            });
        }
    }
    let mut out: String = others.iter().map(|&c| format!("{},", header[c])).collect();
    out += THRESHOLD_COLUMNS;
    out += "\n";
    for (key, baseline, points) in &groups {
        if baseline.is_empty() {
            return Err(bad(format!(
                "no {zeta_key} = 0 run for {}: the threshold is measured against ζ = 0 from the same relaxed states; add 0 to --vary {zeta_key}",
                if key.is_empty() { "the sweep".to_string() } else { key.join(",") }
            )));
        }
        let growth = csv_fields(growth_threshold(points)).join(",");
        let excess = csv_fields(threshold(baseline, points)).join(",");
        for v in key {
            out += v;
            out += ",";
        }
        out += &format!("{growth},{excess},{},{}\n", baseline.len(), points.len());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::summary::{summarise, window};

    /// Synthetic growth curves: v_rms(t) = 1e-3 exp((r0 + c (ζ − ζ_cr)) t) plus a seed-dependent
    /// offset of the rate that is the same at every ζ (the same relaxed state), through the
    /// series summary. The estimator recovers ζ_cr to round-off, since the excess rate is
    /// linear in ζ and the seed offsets cancel against the baseline.
    #[test]
    fn the_threshold_of_synthetic_growth_curves_is_recovered() {
        let dir = tempfile::tempdir().unwrap();
        let (r0, c, zeta_cr) = (-0.004, 1.5, 0.0063);
        let seeds = [0.0005, -0.0003, 0.0001];
        let rate_of = |zeta: f64, seed: f64| -> f64 {
            let mut text = String::from("step,time,v_rms,s_rms,area_mean\n");
            let rate = if zeta == 0.0 {
                r0
            } else {
                r0 + c * (zeta - zeta_cr)
            };
            for k in 0..=200 {
                let t = k as f64;
                let v = 1e-3 * ((rate + seed) * t).exp();
                text += &format!("{k},{t},{v:e},1,160\n");
            }
            std::fs::write(dir.path().join("series.csv"), text).unwrap();
            summarise(dir.path(), window(0.0, 200.0))
                .unwrap()
                .growth_rate
        };
        let baseline: Vec<f64> = seeds.iter().map(|&s| rate_of(0.0, s)).collect();
        let points: Vec<RatePoint> = [0.008, 0.002, 0.004, 0.01, 0.006, 0.007]
            .iter()
            .map(|&zeta| RatePoint {
                zeta,
                rates: seeds.iter().map(|&s| rate_of(zeta, s)).collect(),
            })
            .collect();
        match threshold(&baseline, &points) {
            Threshold::Bracketed { zeta_cr: z, lo, hi } => {
                assert_eq!((lo, hi), (0.006, 0.007));
                assert!((z - zeta_cr).abs() < 1e-12, "{z}");
            }
            other => panic!("{other:?}"),
        }
        // All above or all below the threshold: the bracket is open.
        let above: Vec<RatePoint> = points.iter().filter(|p| p.zeta > 0.0065).cloned().collect();
        assert_eq!(threshold(&baseline, &above), Threshold::Below { hi: 0.007 });
        let below: Vec<RatePoint> = points.iter().filter(|p| p.zeta < 0.0063).cloned().collect();
        assert_eq!(threshold(&baseline, &below), Threshold::Above { lo: 0.006 });
    }

    /// The table groups a summary by the other axes, takes ζ = 0 as each group's baseline, and
    /// refuses a group without one.
    #[test]
    fn the_threshold_table_groups_by_the_other_axes() {
        // Two γ; rates r = c (ζ − ζ_cr(γ)) − 0.004, ζ_cr = 0.004 + 0.2 γ, two seeds each.
        let mut summary = String::from("model.gamma,model.zeta,seed,growth_rate\n");
        for gamma in [0.01f64, 0.02] {
            for zeta in [0.0f64, 0.004, 0.006, 0.008, 0.01] {
                for seed in [1, 2] {
                    let rate = if zeta == 0.0 {
                        -0.004
                    } else {
                        1.5 * (zeta - (0.004 + 0.2 * gamma)) - 0.004
                    };
                    summary += &format!("{gamma},{zeta},{seed},{rate}\n");
                }
            }
        }
        let table = threshold_table(&summary, "model.zeta").unwrap();
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(
            lines[0],
            "model.gamma,zeta_cr,zeta_cr_lo,zeta_cr_hi,zeta_cr_excess,zeta_cr_excess_lo,zeta_cr_excess_hi,seeds,activities"
        );
        let fields =
            |line: &str| -> Vec<Option<f64>> { line.split(',').map(|v| v.parse().ok()).collect() };
        // The excess estimate is ζ_cr itself: Δ = 1.5 (ζ − ζ_cr).
        for (line, (gamma, lo, hi)) in lines[1..]
            .iter()
            .zip([(0.01, 0.006, 0.008), (0.02, 0.008, 0.01)])
        {
            let f = fields(line);
            assert_eq!(
                (f[0], f[5], f[6], f[7], f[8]),
                (Some(gamma), Some(lo), Some(hi), Some(2.0), Some(4.0))
            );
            assert!(
                (f[4].unwrap() - (0.004 + 0.2 * gamma)).abs() < 1e-12,
                "{line}"
            );
        }
        // The growth estimate is where r itself turns positive, ζ_cr + 0.004/1.5: bracketed
        // for γ = 0.01, above every activity tried for γ = 0.02 (open bracket).
        let f = fields(lines[1]);
        assert_eq!((f[2], f[3]), (Some(0.008), Some(0.01)));
        assert!(
            (f[1].unwrap() - (0.006 + 0.004 / 1.5)).abs() < 1e-12,
            "{}",
            lines[1]
        );
        let f = fields(lines[2]);
        assert_eq!((f[1], f[2], f[3]), (None, Some(0.01), None));
        let no_base = "model.zeta,seed,growth_rate\n0.005,1,0.1\n";
        let e = threshold_table(no_base, "model.zeta")
            .unwrap_err()
            .to_string();
        assert!(e.contains("add 0 to --vary model.zeta"), "{e}");
    }
}
