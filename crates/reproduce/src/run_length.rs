//! `reproduce run-length`: how the threshold of the paper's random packing moves with the run
//! length T, and whether it has a finite limit.
//!
//! The growth estimate of ζ_cr (where the late growth rate of ln v_rms, over the second half of
//! the active phase, turns positive) falls by about a third per doubling of T at T = 100–400:
//! the random packings keep coarsening at ζ = 0, so a run never reaches a clean baseline. Here
//! the same runs are cut at T = 100, 200, …, 3200 TU (a run is deterministic, so its first T TU
//! are the run of length T); ζ_cr(T) is found per seed, and `ζ_cr(T) = ζ_∞ + a T^(−b)` is
//! fitted to the seed means.

use std::path::Path;

use render::{Plot, Series};

use super::{drawn, g, mean_se, write_text, Claim, ReproduceParams, Scale, SweepJob, Verdict};
use study::threshold::{growth_threshold, RatePoint, Threshold};
use study::SweepError;

/// The activities: few, around the brackets of every T (ζ_cr is near 0.004 at T = 100 and has
/// fallen below 0.001 by T = 800).
const ZETAS: &str = "0.0005,0.001,0.0015,0.002,0.003,0.004,0.006";

/// The run lengths read from the same runs.
const LENGTHS: [f64; 6] = [100.0, 200.0, 400.0, 800.0, 1600.0, 3200.0];

const PRESSURES: [&str; 2] = ["paper", "interaction"];

/// More seeds than the other figures' (the per-seed spread of ζ_cr is as large as the effects
/// it is compared with): 6 at the quick scale, 10 at the paper scale.
fn seeds_of(scale: Scale) -> study::Seeds {
    match scale {
        Scale::Quick => study::Seeds { first: 1, last: 6 },
        Scale::Paper => study::Seeds { first: 1, last: 10 },
    }
}

/// A fit of `ζ_cr(T) = ζ_∞ + a T^(−b)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PowerFit {
    pub zeta_inf: f64,
    /// The error of ζ_∞: over the exponents b within Δχ² ≤ 1 of the best, the widest reach of
    /// ζ_∞ ± its standard error at fixed b.
    pub zeta_inf_err: f64,
    pub a: f64,
    pub b: f64,
    /// The range of b within Δχ² ≤ 1.
    pub b_range: (f64, f64),
    pub chi2: f64,
    pub dof: usize,
}

/// Weighted least squares of `y = ζ_∞ + a x^(−b)`: for each b on a grid over (0, 3], the linear
/// fit in `(ζ_∞, a)`; the best b minimises χ². `None` with fewer than four points.
pub(crate) fn fit_power(t: &[f64], y: &[f64], e: &[f64]) -> Option<PowerFit> {
    if t.len() < 4 {
        return None;
    }
    let fits: Vec<(f64, stability::fit::Fit)> = (1..=300)
        .filter_map(|k| {
            let b = k as f64 * 0.01;
            let x: Vec<f64> = t.iter().map(|t| t.powf(-b)).collect();
            stability::fit::line(&x, y, Some(e)).map(|f| (b, f))
        })
        .collect();
    let (b, best) = fits
        .iter()
        .min_by(|p, q| p.1.chi2.total_cmp(&q.1.chi2))?
        .clone();
    let near: Vec<&(f64, stability::fit::Fit)> = fits
        .iter()
        .filter(|(_, f)| f.chi2 <= best.chi2 + 1.0)
        .collect();
    let lo = near
        .iter()
        .map(|(_, f)| f.coef[0] - f.se[0])
        .fold(f64::INFINITY, f64::min);
    let hi = near
        .iter()
        .map(|(_, f)| f.coef[0] + f.se[0])
        .fold(f64::NEG_INFINITY, f64::max);
    let b_lo = near.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let b_hi = near.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    Some(PowerFit {
        zeta_inf: best.coef[0],
        zeta_inf_err: (best.coef[0] - lo).max(hi - best.coef[0]),
        a: best.coef[1],
        b,
        b_range: (b_lo, b_hi),
        chi2: best.chi2,
        dof: best.dof,
    })
}

/// A finite threshold of the random packing: holds (established) when `ζ_∞ − 2 err > 0`; does
/// not hold (ruled out) when `ζ_∞ + 2 err ≤ 0`; inconclusive (undecided at this scale)
/// otherwise, or without a fit.
pub(crate) fn rule_finite(fit: Option<&PowerFit>) -> (Verdict, String) {
    let Some(f) = fit else {
        return (
            Verdict::Inconclusive,
            "fewer than four run lengths with a bracketed ζ_cr: no fit".into(),
        );
    };
    let what = format!(
        "ζ_cr(T) = ζ_∞ + a T^(−b): ζ_∞ = {} ± {}, b = {} (Δχ² ≤ 1: {}–{}), χ² = {} for {} dof",
        g(f.zeta_inf),
        g(f.zeta_inf_err),
        g(f.b),
        g(f.b_range.0),
        g(f.b_range.1),
        g(f.chi2),
        f.dof
    );
    if f.zeta_inf - 2.0 * f.zeta_inf_err > 0.0 {
        (
            Verdict::Holds,
            format!("{what}: ζ_∞ > 0 by more than 2 errors"),
        )
    } else if f.zeta_inf + 2.0 * f.zeta_inf_err <= 0.0 {
        (
            Verdict::DoesNotHold,
            format!("{what}: ζ_∞ ≤ 0 by more than 2 errors"),
        )
    } else {
        (
            Verdict::Inconclusive,
            format!("{what}: 0 lies within 2 errors of ζ_∞, so the data do not decide"),
        )
    }
}

/// The per-seed ζ_cr: where that seed's growth rate first turns positive.
fn per_seed(rates: &[(f64, u64, f64)], seed: u64) -> Option<f64> {
    let points: Vec<RatePoint> = rates
        .iter()
        .filter(|r| r.1 == seed)
        .map(|r| RatePoint {
            zeta: r.0,
            rates: vec![r.2],
        })
        .collect();
    match growth_threshold(&points) {
        Threshold::Bracketed { zeta_cr, .. } => Some(zeta_cr),
        _ => None,
    }
}

pub(super) fn make(p: &ReproduceParams, dir: &Path) -> Result<(Vec<Claim>, String), SweepError> {
    let t_max = LENGTHS[LENGTHS.len() - 1];
    let mut sets = vec![
        format!("run.time={t_max}"),
        format!("run.output_every={t_max}"),
    ];
    sets.extend(p.scale.integrator());
    let res = super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("run-length-{}", p.scale.name()),
            sets,
            varies: vec![
                format!("model.pressure={}", PRESSURES.join(",")),
                format!("model.zeta={ZETAS}"),
            ],
            analyze: None,
            seeds: Some(seeds_of(p.scale)),
        },
    )?;
    p.reporter.stage("run-length: ζ_cr against T");
    let seeds: Vec<u64> = {
        let s = seeds_of(p.scale);
        (s.first..=s.last).collect()
    };
    let mut csv = String::from("pressure,run_time,seed,zeta_cr\n");
    let mut means = String::from("pressure,run_time,zeta_cr,zeta_cr_se,seeds_bracketed,seeds\n");
    let mut plot = Plot::new(
        "ζ_cr of the random packing against the run length (L = 100, γ = 0.01)",
        "run length T (TU)",
        "ζ_cr (mean ± s.e. over seeds)",
    );
    plot.log_x = true;
    plot.zero_y = true;
    let mut claims = Vec::new();
    let mut fits = String::from("pressure,zeta_inf,zeta_inf_err,a,b,b_lo,b_hi,chi2,dof\n");
    for pressure in PRESSURES {
        let mut pts = Vec::new();
        for &t in &LENGTHS {
            let recs = res.records(Some(t))?;
            let rates: Vec<(f64, u64, f64)> = recs
                .iter()
                .filter(|r| r.values[0] == pressure)
                .map(|r| {
                    (
                        r.values[1].parse().unwrap_or(f64::NAN),
                        r.seed,
                        r.summary.growth_rate,
                    )
                })
                .collect();
            let mut z = Vec::new();
            for &s in &seeds {
                let v = per_seed(&rates, s);
                csv += &format!(
                    "{pressure},{t},{s},{}\n",
                    v.map_or(String::new(), |v| v.to_string())
                );
                z.extend(v);
            }
            let (m, se) = mean_se(&z);
            means += &format!("{pressure},{t},{m:e},{se:e},{},{}\n", z.len(), seeds.len());
            if z.len() >= 2 {
                pts.push((t, m, se));
            }
        }
        let (t, y, e): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            pts.iter().map(|p| p.0).collect(),
            pts.iter().map(|p| p.1).collect(),
            pts.iter().map(|p| p.2.max(1e-6)).collect(),
        );
        plot.series
            .push(Series::new(format!("{pressure} form")).with_points(&t, &y, &e));
        let fit = fit_power(&t, &y, &e);
        if let Some(f) = &fit {
            fits += &format!(
                "{pressure},{:e},{:e},{:e},{},{},{},{},{}\n",
                f.zeta_inf, f.zeta_inf_err, f.a, f.b, f.b_range.0, f.b_range.1, f.chi2, f.dof
            );
            let tt: Vec<f64> = (0..=40)
                .map(|k| 100.0 * (t_max / 100.0).powf(k as f64 / 40.0))
                .collect();
            let yy: Vec<f64> = tt.iter().map(|t| f.zeta_inf + f.a * t.powf(-f.b)).collect();
            plot.series.push(
                Series::new(format!("{pressure}: ζ_∞ + a T^(−b)"))
                    .with_points(&tt, &yy, &vec![0.0; tt.len()])
                    .line_only(),
            );
        }
        let (v, why) = rule_finite(fit.as_ref());
        claims.push(Claim::new(
            format!("9.1: the random packing has a finite threshold as T → ∞ ({pressure} form)"),
            pts.iter()
                .map(|p| format!("T = {}: {} ± {}", p.0, g(p.1), g(p.2)))
                .collect::<Vec<_>>()
                .join(", "),
            v,
            why,
        ));
    }
    write_text(&dir.join("zeta_cr_per_seed.csv"), &csv)?;
    write_text(&dir.join("zeta_cr_vs_run_length.csv"), &means)?;
    write_text(&dir.join("fit.csv"), &fits)?;
    drawn(plot.save_png(&dir.join("zeta_cr_vs_run_length.png")))?;
    let settings = format!(
        "- The paper's scene (L = 100, 60 cells, γ = 0.01, random packing relaxed 200 TU at ζ = 0), {}, both pressure forms, ζ ∈ {{{ZETAS}}}, seeds {}–{}, each run {t_max} TU of activity.\n\
         - ζ_cr(T): each run cut at T ∈ {{{}}} TU; per seed, where its growth rate of ln v_rms over [T/2, T] first turns positive (linear interpolation between the activities around the crossing); mean ± standard error over the seeds whose crossing lies inside the grid (`zeta_cr_per_seed.csv`, `zeta_cr_vs_run_length.csv`).\n\
         - Fit: `ζ_cr(T) = ζ_∞ + a T^(−b)`, weighted by the standard errors, b on a grid over (0, 3]; the error of ζ_∞ is the widest reach of ζ_∞ ± its standard error over the b within Δχ² ≤ 1 (`fit.csv`). Verdict: established when ζ_∞ − 2 err > 0, ruled out when ζ_∞ + 2 err ≤ 0, undecided otherwise.\n\
         - Files: `zeta_cr_vs_run_length.png`, the CSVs above.",
        p.scale.integrator_name(),
        seeds.first().copied().unwrap_or(1),
        seeds.last().copied().unwrap_or(1),
        LENGTHS.map(|t| t.to_string()).join(", "),
    );
    Ok((claims, settings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_power_fit_recovers_its_parameters() {
        let t = LENGTHS;
        let y: Vec<f64> = t.iter().map(|t| 8e-4 + 0.02 * t.powf(-0.6)).collect();
        let f = fit_power(&t, &y, &[1e-6; 6]).unwrap();
        assert!((f.zeta_inf - 8e-4).abs() < 2e-5, "{f:?}");
        assert!((f.b - 0.6).abs() < 0.02, "{f:?}");
        assert!(fit_power(&t[..3], &y[..3], &[1e-6; 3]).is_none());
    }

    /// A limit well above zero is established; one that tends to zero with small errors is
    /// ruled out only when a positive limit is excluded; large errors leave it undecided.
    #[test]
    fn the_finite_threshold_rule_gives_each_outcome() {
        let t = LENGTHS;
        let finite: Vec<f64> = t.iter().map(|t| 8e-4 + 0.02 * t.powf(-0.6)).collect();
        let f = fit_power(&t, &finite, &[1e-6; 6]);
        assert_eq!(rule_finite(f.as_ref()).0, Verdict::Holds);
        let to_zero: Vec<f64> = t.iter().map(|t| -2e-4 + 0.02 * t.powf(-0.5)).collect();
        let f = fit_power(&t, &to_zero, &[1e-6; 6]);
        assert_eq!(rule_finite(f.as_ref()).0, Verdict::DoesNotHold);
        let noisy = fit_power(&t, &finite, &[5e-4; 6]);
        assert_eq!(rule_finite(noisy.as_ref()).0, Verdict::Inconclusive);
        assert_eq!(rule_finite(None).0, Verdict::Inconclusive);
    }
}
