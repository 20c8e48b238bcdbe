//! `reproduce run-length`: how the threshold of the paper's random packing moves with the run
//! length T, and whether it has a finite limit.
//!
//! The growth estimate of ζ_cr (where the late growth rate of ln v_rms, over the second half of
//! the active phase, turns positive) falls by about a third per doubling of T at T = 100–400:
//! the random packings keep coarsening at ζ = 0, so a run never reaches a clean baseline. Here
//! the same runs are cut at T = 100, 200, …, 3200 TU (a run is deterministic, so its first T TU
//! are the run of length T); ζ_cr(T) is found per seed, and `ζ_cr(T) = ζ_∞ + a T^(−b)` is
//! fitted to the seed means.

use render::{Plot, Series};

use super::pipeline::{cell, sci, Csv, Made, PointRuns};
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};
use study::threshold::{growth_threshold, RatePoint, Threshold};
use study::SweepError;

/// The activities: few, around the brackets of every T (ζ_cr is near 0.004 at T = 100 and has
/// fallen below 0.001 by T = 800), reaching below the lowest per-seed threshold measured with
/// the grid that started at 5·10⁻⁴ (a seed of the paper form fell below it at T = 3200).
const ZETAS: &str = "0.0001,0.00025,0.0005,0.001,0.0015,0.002,0.003,0.004,0.006";

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

/// A fit of `ζ_cr(T) = a T^(−b)`: the threshold falls to zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ZeroFit {
    pub a: f64,
    pub b: f64,
    pub chi2: f64,
    pub dof: usize,
}

/// Weighted least squares of `y = a x^(−b)` (no constant), b on the grid of [`fit_power`].
/// `None` with fewer than three points.
pub(crate) fn fit_zero(t: &[f64], y: &[f64], e: &[f64]) -> Option<ZeroFit> {
    if t.len() < 3 {
        return None;
    }
    (1..=300)
        .map(|k| {
            let b = k as f64 * 0.01;
            let x: Vec<f64> = t.iter().map(|t| t.powf(-b)).collect();
            // The weighted fit through the origin: a = Σ w x y / Σ w x².
            let (sxy, sxx) = x
                .iter()
                .zip(y)
                .zip(e)
                .fold((0.0, 0.0), |(a, c), ((x, y), e)| {
                    let w = 1.0 / (e * e);
                    (a + w * x * y, c + w * x * x)
                });
            let a = sxy / sxx;
            let chi2: f64 = x
                .iter()
                .zip(y)
                .zip(e)
                .map(|((x, y), e)| ((y - a * x) / e).powi(2))
                .sum();
            ZeroFit {
                a,
                b,
                chi2,
                dof: t.len() - 2,
            }
        })
        .min_by(|p, q| p.chi2.total_cmp(&q.chi2))
}

/// The 99 % point of χ² with `dof` degrees of freedom (Wilson–Hilferty: within 1 % of the
/// exact quantile from 3 degrees of freedom up, and 4 % at 1).
pub(crate) fn chi2_99(dof: usize) -> f64 {
    let n = dof.max(1) as f64;
    let h = 2.0 / (9.0 * n);
    n * (1.0 - h + 2.326_348 * h.sqrt()).powi(3)
}

/// A finite threshold of the random packing, from the free fit `ζ_∞ + a T^(−b)`, the fit with
/// the limit zero `a T^(−b)`, and the smallest threshold measured `floor`:
/// - inconclusive when the free fit fails its goodness of fit (χ² above its 99 % point) or
///   there is no fit;
/// - otherwise the rule of an effect (issue 54's `Rule`) on `ζ_∞ ± err` with `floor/2`
///   counting: holds (a finite limit) when `ζ_∞` is resolved by two errors and at least
///   `floor/2`, and the zero-limit fit is worse by `Δχ² ≥ 4` (inconclusive when it is not);
///   does not hold (the limit is at most half the smallest threshold measured, zero for this
///   protocol) when `ζ_∞ + 2 err < floor/2`; inconclusive otherwise.
pub(crate) fn rule_finite(
    fit: Option<&PowerFit>,
    zero: Option<&ZeroFit>,
    floor: f64,
) -> (Verdict, String) {
    let Some(f) = fit else {
        return (
            Verdict::Inconclusive,
            "fewer than four run lengths with a measured ζ_cr: no fit".into(),
        );
    };
    let mut what = format!(
        "ζ_cr(T) = ζ_∞ + a T^(−b): ζ_∞ = {} ± {}, b = {} (Δχ² ≤ 1: {}–{}), χ² = {} for {} dof (99 % point {})",
        g(f.zeta_inf),
        g(f.zeta_inf_err),
        g(f.b),
        g(f.b_range.0),
        g(f.b_range.1),
        g(f.chi2),
        f.dof,
        g(chi2_99(f.dof))
    );
    let delta = zero.map_or(f64::NAN, |z| z.chi2 - f.chi2);
    if let Some(z) = zero {
        what += &format!(
            "; with ζ_∞ = 0: b = {}, χ² = {} for {} dof (99 % point {}), Δχ² = {}",
            g(z.b),
            g(z.chi2),
            z.dof,
            g(chi2_99(z.dof)),
            g(delta)
        );
    }
    if f.dof == 0 || f.chi2 > chi2_99(f.dof) {
        return (
            Verdict::Inconclusive,
            format!("{what}: the free fit fails its goodness of fit (or has no degree of freedom left), so its ζ_∞ says nothing"),
        );
    }
    // The limit by the rule of an effect (issue 54's `Rule`): ζ_∞ with its error as the
    // standard error, half the smallest threshold measured counting.
    let o = super::rule::Rule::effect("ζ_∞ of the free fit", floor / 2.0)
        .decide(f.zeta_inf, f.zeta_inf_err);
    match o.verdict {
        Verdict::Holds if delta >= 4.0 => (
            Verdict::Holds,
            format!("{what}: {}; and the limit 0 fits worse by Δχ² ≥ 4", o.why),
        ),
        Verdict::Holds => (
            Verdict::Inconclusive,
            format!(
                "{what}: {}; but the limit 0 fits nearly as well (Δχ² < 4)",
                o.why
            ),
        ),
        Verdict::DoesNotHold => (
            Verdict::DoesNotHold,
            format!(
                "{what}: {}: the limit is at most half the smallest threshold measured",
                o.why
            ),
        ),
        Verdict::Inconclusive => (
            Verdict::Inconclusive,
            format!(
                "{what}: {}: neither a positive limit nor the limit 0 is established",
                o.why
            ),
        ),
    }
}

/// The mean threshold of the seeds at one run length, with the seeds whose crossing lies below
/// the grid counted as censored, not dropped: each lies somewhere in `[0, lowest ζ]`. The
/// mean with them at their interval's middle, and an error of the seeds' standard error and
/// the half-width of the mean's range (censored seeds from 0 to the lowest ζ) in quadrature.
/// `None` when a seed's crossing lies above the grid (the mean is then unbounded) or fewer
/// than two seeds have a value.
pub(crate) fn censored_mean(found: &[f64], below: &[f64]) -> Option<(f64, f64)> {
    let n = found.len() + below.len();
    if n < 2 {
        return None;
    }
    let mid: Vec<f64> = found
        .iter()
        .copied()
        .chain(below.iter().map(|hi| hi / 2.0))
        .collect();
    let (m, se) = mean_se(&mid);
    let half = below.iter().sum::<f64>() / 2.0 / n as f64;
    Some((m, se.hypot(half)))
}

/// The per-seed ζ_cr: where that seed's growth rate first turns positive.
fn per_seed(rates: &[(f64, u64, f64)], seed: u64) -> Threshold {
    let points: Vec<RatePoint> = rates
        .iter()
        .filter(|r| r.1 == seed)
        .map(|r| RatePoint {
            zeta: r.0,
            rates: vec![r.2],
        })
        .collect();
    growth_threshold(&points)
}

/// What a seed's threshold at run length T is read from: where it turns positive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Estimator {
    /// The growth rate of ln v_rms over [T/2, T] (per TU).
    Rate,
    /// The local exponent d ln v_rms / d ln t over [T/2, T] (issue 54): scale-free, so a
    /// packing that relaxes as a power law keeps a negative exponent at every T, where its
    /// growth rate tends to zero as ~1/T.
    Exponent,
}

impl Estimator {
    const ALL: [Estimator; 2] = [Estimator::Rate, Estimator::Exponent];

    fn name(self) -> &'static str {
        match self {
            Self::Rate => "growth rate",
            Self::Exponent => "local exponent",
        }
    }

    fn of(self, s: &study::summary::RunSummary) -> f64 {
        match self {
            Self::Rate => s.growth_rate,
            Self::Exponent => s.growth_exponent,
        }
    }
}

/// The mean ζ_cr of the runs of `pressure` cut at each run length, with its standard error:
/// `(T, ζ_cr, s.e.)` where it is measured; each seed's threshold into `csv` and each mean
/// into `means`.
fn thresholds_by_length(
    cut: &[(f64, Vec<PointRuns>)],
    estimator: Estimator,
    pressure: &str,
    seeds: &[u64],
    csv: &mut Csv,
    means: &mut Csv,
) -> Result<Vec<(f64, f64, f64)>, SweepError> {
    let mut pts = Vec::new();
    for (t, points) in cut {
        let t = *t;
        // Each run cut at T.
        let rates = rates(points, pressure, estimator);
        let (mut found, mut below, mut above) = (Vec::new(), Vec::new(), 0usize);
        for &s in seeds {
            let (value, censored) = match per_seed(&rates, s) {
                Threshold::Bracketed { zeta_cr, .. } => {
                    found.push(zeta_cr);
                    (zeta_cr.to_string(), "")
                }
                Threshold::Below { hi } => {
                    below.push(hi);
                    (String::new(), "below")
                }
                // Above the grid (`Threshold::Above`; the enum may grow).
                _ => {
                    above += 1;
                    (String::new(), "above")
                }
            };
            csv.row([
                cell(estimator.name()),
                cell(pressure),
                cell(t),
                cell(s),
                value,
                cell(censored),
            ]);
        }
        let mean = if above > 0 {
            None
        } else {
            censored_mean(&found, &below)
        };
        let (m, se) = mean.unwrap_or((f64::NAN, f64::NAN));
        means.row([
            cell(estimator.name()),
            cell(pressure),
            cell(t),
            sci(m),
            sci(se),
            cell(found.len()),
            cell(below.len()),
            cell(above),
            cell(seeds.len()),
        ]);
        if mean.is_some() {
            pts.push((t, m, se));
        }
    }
    Ok(pts)
}

/// What the figure makes of its runs cut at each run length.
struct Analysis {
    claims: Vec<Claim>,
    per_seed: Csv,
    means: Csv,
    fits: Csv,
    plot: Plot,
}

/// The claims, tables and plot from the runs `cut` at each run length (its points' values
/// `[pressure, ζ]`) of `seeds`.
fn analyse(cut: &[(f64, Vec<PointRuns>)], seeds: &[u64]) -> Result<Analysis, SweepError> {
    let t_max = LENGTHS[LENGTHS.len() - 1];
    let mut csv = Csv::new(&[
        "estimator",
        "pressure",
        "run_time",
        "seed",
        "zeta_cr",
        "censored",
    ]);
    let mut means = Csv::new(&[
        "estimator",
        "pressure",
        "run_time",
        "zeta_cr",
        "zeta_cr_err",
        "seeds_bracketed",
        "seeds_below",
        "seeds_above",
        "seeds",
    ]);
    let mut plot = Plot::new(
        "ζ_cr of the random packing against the run length (L = 100, γ = 0.01)",
        "run length T (TU)",
        "ζ_cr (mean ± s.e. over seeds)",
    );
    plot.log_x = true;
    plot.zero_y = true;
    let mut claims = Vec::new();
    let mut fits = Csv::new(&[
        "estimator",
        "pressure",
        "zeta_inf",
        "zeta_inf_err",
        "a",
        "b",
        "b_lo",
        "b_hi",
        "chi2",
        "dof",
        "zero_a",
        "zero_b",
        "zero_chi2",
        "zero_dof",
    ]);
    for (estimator, pressure) in Estimator::ALL
        .into_iter()
        .flat_map(|e| PRESSURES.map(|p| (e, p)))
    {
        let en = estimator.name();
        let pts = thresholds_by_length(cut, estimator, pressure, seeds, &mut csv, &mut means)?;
        let (t, y, e): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            pts.iter().map(|p| p.0).collect(),
            pts.iter().map(|p| p.1).collect(),
            pts.iter().map(|p| p.2.max(1e-6)).collect(),
        );
        plot.series
            .push(Series::new(format!("{pressure} form, {en}")).with_points(&t, &y, &e));
        let fit = fit_power(&t, &y, &e);
        let zero = fit_zero(&t, &y, &e);
        let floor = y.iter().copied().fold(f64::INFINITY, f64::min);
        if let Some(f) = &fit {
            let z = zero.unwrap_or(ZeroFit {
                a: f64::NAN,
                b: f64::NAN,
                chi2: f64::NAN,
                dof: 0,
            });
            fits.row([
                cell(en),
                cell(pressure),
                sci(f.zeta_inf),
                sci(f.zeta_inf_err),
                sci(f.a),
                cell(f.b),
                cell(f.b_range.0),
                cell(f.b_range.1),
                cell(f.chi2),
                cell(f.dof),
                sci(z.a),
                cell(z.b),
                cell(z.chi2),
                cell(z.dof),
            ]);
            let tt: Vec<f64> = (0..=40)
                .map(|k| 100.0 * (t_max / 100.0).powf(k as f64 / 40.0))
                .collect();
            let yy: Vec<f64> = tt.iter().map(|t| f.zeta_inf + f.a * t.powf(-f.b)).collect();
            plot.series.push(
                Series::new(format!("{pressure}, {en}: ζ_∞ + a T^(−b)"))
                    .with_points(&tt, &yy, &vec![0.0; tt.len()])
                    .line_only(),
            );
        }
        let (v, why) = rule_finite(fit.as_ref(), zero.as_ref(), floor);
        claims.push(Claim::new(
            format!(
                "9.1: the random packing has a finite threshold as T → ∞ ({pressure} form, by the {en})"
            ),
            pts.iter()
                .map(|p| format!("T = {}: {} ± {}", p.0, g(p.1), g(p.2)))
                .collect::<Vec<_>>()
                .join(", "),
            v,
            why,
        ));
    }

    Ok(Analysis {
        claims,
        per_seed: csv,
        means,
        fits,
        plot,
    })
}

/// `run_length_runs.csv`: every run's summary at each run length (issue 54's raw table).
fn runs_table(cut: &[(f64, Vec<PointRuns>)]) -> Csv {
    let points: Vec<PointRuns> = cut
        .iter()
        .flat_map(|(t, pts)| {
            pts.iter().map(move |pt| PointRuns {
                values: std::iter::once(t.to_string())
                    .chain(pt.values.iter().cloned())
                    .collect(),
                runs: pt.runs.clone(),
            })
        })
        .collect();
    super::pipeline::runs_table(&["run_time", "pressure", "zeta"], &points)
}

/// The runs of `run_length_runs.csv` in `dir`, cut at each run length as [`make`] had them,
/// and their seeds.
#[cfg(test)]
type Cut = (Vec<(f64, Vec<PointRuns>)>, Vec<u64>);

#[cfg(test)]
fn cut_from_table(dir: &std::path::Path) -> Result<Cut, SweepError> {
    let all = super::pipeline::points_from_runs_table(&dir.join("run_length_runs.csv"), 3)?;
    let mut cut: Vec<(f64, Vec<PointRuns>)> = Vec::new();
    let mut seeds: Vec<u64> = Vec::new();
    for pt in all {
        let t: f64 = pt.values[0].parse().unwrap_or(f64::NAN);
        seeds.extend(pt.runs.iter().map(|r| r.seed));
        let point = PointRuns {
            values: pt.values[1..].to_vec(),
            runs: pt.runs,
        };
        match cut.iter_mut().find(|c| c.0 == t) {
            Some(c) => c.1.push(point),
            None => cut.push((t, vec![point])),
        }
    }
    seeds.sort_unstable();
    seeds.dedup();
    Ok((cut, seeds))
}

/// Seeds of the systematic sweeps: the first three.
const SYSTEMATIC_SEEDS: study::Seeds = study::Seeds { first: 1, last: 3 };

/// The systematics (issue 54): the same sweep (overrides `sets`) at half the time step and on
/// a grid twice as fine, for the first three seeds, each run summarised over the second half of
/// the longest run length: `(case, points)`.
fn systematic_runs(
    p: &ReproduceParams,
    sets: &[String],
) -> Result<Vec<(String, Vec<PointRuns>)>, SweepError> {
    let t_max = LENGTHS[LENGTHS.len() - 1];
    let half = super::systematics::half_dt(super::PAPER_SCENE, sets)?;
    let finer = super::systematics::finer_grid(super::PAPER_SCENE, sets)?;
    let mut out = Vec::new();
    for (tag, extra) in [("dt-half", vec![half]), ("grid-half", finer)] {
        let res = super::sweep(
            p,
            SweepJob {
                scene: super::PAPER_SCENE,
                name: format!("run-length-{tag}-{}", p.scale.name()),
                sets: [sets.to_vec(), extra].concat(),
                varies: vec![
                    format!("model.pressure={}", PRESSURES.join(",")),
                    format!("model.zeta={ZETAS}"),
                ],
                analyze: None,
                seeds: Some(SYSTEMATIC_SEEDS),
            },
        )?;
        out.push((tag.to_string(), res.points(Some(t_max))?));
    }
    Ok(out)
}

/// Every run of `pressure` in `points` (values `[pressure, ζ]`) as `(ζ, seed, statistic)`, the
/// statistic read by `estimator`: what [`per_seed`] finds each seed's threshold in.
fn rates(points: &[PointRuns], pressure: &str, estimator: Estimator) -> Vec<(f64, u64, f64)> {
    points
        .iter()
        .filter(|pt| pt.values[0] == pressure)
        .flat_map(|pt| &pt.runs)
        .map(|r| {
            (
                r.values[1].parse().unwrap_or(f64::NAN),
                r.seed,
                estimator.of(&r.summary),
            )
        })
        .collect()
}

/// Each seed's growth-rate threshold in `points` (values `[pressure, ζ]`) of `pressure`: where
/// it crosses, half the lowest ζ where it crosses below the grid, `None` above it.
fn seed_thresholds(points: &[PointRuns], pressure: &str) -> Vec<(u64, Option<f64>)> {
    let rates = rates(points, pressure, Estimator::Rate);
    let mut seeds: Vec<u64> = rates.iter().map(|r| r.1).collect();
    seeds.sort_unstable();
    seeds.dedup();
    seeds
        .into_iter()
        .map(|s| match per_seed(&rates, s) {
            Threshold::Bracketed { zeta_cr, .. } => (s, Some(zeta_cr)),
            // Below the lowest ζ: censored at the middle of [0, lowest], as the censored mean
            // puts it.
            Threshold::Below { hi } => (s, Some(0.5 * hi)),
            _ => (s, None),
        })
        .collect()
}

/// Discretisation (issue 54): the growth-rate ζ_cr at the longest run length, paired by seed
/// between the figure's runs (`base`) and the systematic sweeps, each relative shift by the
/// rule of an absence with [`super::systematics::SHIFT`] counting; holds when every one holds.
fn claim_discretisation(base: &[PointRuns], systematic: &[(String, Vec<PointRuns>)]) -> Claim {
    let t_max = LENGTHS[LENGTHS.len() - 1];
    let rule = super::rule::Rule::absence("relative shift of ζ_cr", super::systematics::SHIFT);
    let (mut outcomes, mut text) = (Vec::new(), Vec::new());
    for pressure in PRESSURES {
        let b = seed_thresholds(base, pressure);
        let mut shifts = [f64::NAN; 2];
        let mut stat = (f64::NAN, f64::NAN);
        let mut per_seed_text = Vec::new();
        for (k, (tag, pts)) in systematic.iter().enumerate().take(2) {
            let v = seed_thresholds(pts, pressure);
            let pairs: Vec<(f64, f64)> = v
                .iter()
                .filter_map(|(s, z)| {
                    let zb = b.iter().find(|x| x.0 == *s)?.1?;
                    Some((zb, (*z)?))
                })
                .collect();
            let zb: Vec<f64> = pairs.iter().map(|p| p.0).collect();
            let d: Vec<f64> = pairs.iter().map(|p| p.1 - p.0).collect();
            per_seed_text.push(format!(
                "{tag}: {}",
                pairs
                    .iter()
                    .map(|p| format!("{} → {}", g(p.0), g(p.1)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
            let (m, se) = mean_se(&d);
            stat = mean_se(&zb);
            shifts[k] = m;
            let o = rule.decide(m / stat.0, se / stat.0);
            outcomes.push(super::rule::Outcome {
                verdict: o.verdict,
                why: format!("{pressure}, {tag} ({} seeds): {}", pairs.len(), o.why),
            });
        }
        let sys = super::systematics::Systematics {
            value: stat.0,
            stat: stat.1,
            dt: shifts[0],
            grid: shifts[1],
        };
        text.push(format!(
            "{pressure} form: ζ_cr({t_max}) over seeds {}–{} = {} (per seed, {})",
            SYSTEMATIC_SEEDS.first,
            SYSTEMATIC_SEEDS.last,
            sys.describe(),
            per_seed_text.join("; ")
        ));
    }
    let (v, why) = super::rules::all_of(&outcomes);
    Claim::new(
        format!("Discretisation (issue 54): the growth-rate ζ_cr at T = {t_max} moves by less than 20 % at half the time step and on a grid twice as fine"),
        text.join("; "),
        v,
        why,
    )
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
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
            sets: sets.clone(),
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
    // Each run cut at each run length T.
    let cut: Vec<(f64, Vec<PointRuns>)> = LENGTHS
        .iter()
        .map(|&t| Ok((t, res.points(Some(t))?)))
        .collect::<Result<_, SweepError>>()?;
    let Analysis {
        mut claims,
        per_seed: csv,
        means,
        fits,
        plot,
    } = analyse(&cut, &seeds)?;
    p.reporter
        .stage("run-length: the systematics, at dt/2 and on a grid twice as fine");
    let systematic = systematic_runs(p, &sets)?;
    let base_last = &cut.last().expect("run lengths").1;
    claims.push(claim_discretisation(base_last, &systematic));
    let settings = format!(
        "- The paper's scene (L = 100, 60 cells, γ = 0.01, random packing relaxed 200 TU at ζ = 0), {}, both pressure forms, ζ ∈ {{{ZETAS}}}, seeds {}–{}, each run {t_max} TU of activity.\n\
         - ζ_cr(T): each run cut at T ∈ {{{}}} TU; per seed, where its growth rate of ln v_rms over [T/2, T] (per TU), or its local exponent d ln v_rms / d ln t over [T/2, T] (t from the start of the activity; issue 54: scale-free, so a power-law relaxation keeps a negative exponent at every T where its rate tends to zero as ~1/T), first turns positive (linear interpolation between the activities around the crossing); seeds whose crossing lies below the lowest ζ are censored, not dropped: each lies in [0, lowest ζ], and the mean puts them at the middle with the half-width of the mean's range added to its standard error in quadrature; a run length where a seed's crossing lies above the grid is left out (`zeta_cr_per_seed.csv`, `zeta_cr_vs_run_length.csv`).\n\
         - Fit: `ζ_cr(T) = ζ_∞ + a T^(−b)`, weighted by the standard errors, b on a grid over (0, 3]; the error of ζ_∞ is the widest reach of ζ_∞ ± its standard error over the b within Δχ² ≤ 1 (`fit.csv`). Also fitted: the limit zero, `ζ_cr(T) = a T^(−b)`. Verdict: inconclusive when the free fit's χ² exceeds its 99 % point; otherwise the rule of an effect (issue 54) on ζ_∞ ± err with half the smallest threshold measured counting: holds when ζ_∞ − 2 err > 0, ζ_∞ is at least that, and the zero-limit fit is worse by Δχ² ≥ 4 (inconclusive when it is not); does not hold (the limit is at most half the smallest threshold measured) when ζ_∞ + 2 err is below it; inconclusive otherwise.\n\
         - Systematics (issue 54): seeds {}–{} again at half the time step and on a grid twice as fine (every length doubled in nodes), each run's summary at T = {t_max} in `run_length_systematics.csv`; the growth-rate ζ_cr at T = {t_max} paired by seed, each relative shift by the rule of an absence with 20 % counting.\n\
         - Files: `zeta_cr_vs_run_length.png`, the CSVs above, `run_length_runs.csv` (every run's summary at every T).",
        SYSTEMATIC_SEEDS.first,
        SYSTEMATIC_SEEDS.last,
        p.scale.integrator_name(),
        seeds.first().copied().unwrap_or(1),
        seeds.last().copied().unwrap_or(1),
        LENGTHS.map(|t| t.to_string()).join(", "),
    );
    let mut sys_points: Vec<PointRuns> = Vec::new();
    for (tag, pts) in &systematic {
        sys_points.extend(pts.iter().map(|pt| {
            PointRuns {
                values: std::iter::once(tag.clone())
                    .chain(pt.values.iter().cloned())
                    .collect(),
                runs: pt.runs.clone(),
            }
        }));
    }
    Ok(Made::new(claims, settings)
        .table("run_length_runs.csv", runs_table(&cut))
        .table(
            "run_length_systematics.csv",
            super::pipeline::runs_table(&["case", "pressure", "zeta"], &sys_points),
        )
        .table("zeta_cr_per_seed.csv", csv)
        .table("zeta_cr_vs_run_length.csv", means)
        .table("fit.csv", fits)
        .plot("zeta_cr_vs_run_length.png", plot))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The run-length section of docs/reproduction.md states the verdicts of the figure's
    /// runs, kept in `docs/data/run-length/quick/run_length_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let dir = crate::stored_tables("run-length/quick");
        let (cut, seeds) = cut_from_table(&dir).unwrap();
        let mut claims = analyse(&cut, &seeds).unwrap().claims;
        let sys =
            crate::pipeline::points_from_runs_table(&dir.join("run_length_systematics.csv"), 3)
                .unwrap();
        let mut systematic: Vec<(String, Vec<PointRuns>)> = Vec::new();
        for pt in sys {
            let point = PointRuns {
                values: pt.values[1..].to_vec(),
                runs: pt.runs,
            };
            match systematic.iter_mut().find(|s| s.0 == pt.values[0]) {
                Some(s) => s.1.push(point),
                None => systematic.push((pt.values[0].clone(), vec![point])),
            }
        }
        claims.push(claim_discretisation(&cut.last().unwrap().1, &systematic));
        let want: Vec<(String, Verdict)> =
            claims.into_iter().map(|c| (c.claim, c.verdict)).collect();
        assert_eq!(want.len(), 5);
        crate::assert_doc_verdicts("run-length", "**Verdicts (quick):**", &want);
    }

    #[test]
    fn the_power_fit_recovers_its_parameters() {
        let t = LENGTHS;
        let y: Vec<f64> = t.iter().map(|t| 8e-4 + 0.02 * t.powf(-0.6)).collect();
        let f = fit_power(&t, &y, &[1e-6; 6]).unwrap();
        assert!((f.zeta_inf - 8e-4).abs() < 2e-5, "{f:?}");
        assert!((f.b - 0.6).abs() < 0.02, "{f:?}");
        assert!(fit_power(&t[..3], &y[..3], &[1e-6; 3]).is_none());
    }

    /// Synthetic seed means at the figure's run lengths with relative scatter `noise` that
    /// alternates in sign (a fixed pattern, not a fit's exact points).
    fn data(f: impl Fn(f64) -> f64, err: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let t = LENGTHS.to_vec();
        let y: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(k, &t)| f(t) + err * [0.6, -0.9, 0.3, 0.8, -0.5, -0.2][k])
            .collect();
        (t, y, vec![err; LENGTHS.len()])
    }

    fn judge(t: &[f64], y: &[f64], e: &[f64]) -> Verdict {
        let floor = y.iter().copied().fold(f64::INFINITY, f64::min);
        rule_finite(
            fit_power(t, y, e).as_ref(),
            fit_zero(t, y, e).as_ref(),
            floor,
        )
        .0
    }

    /// Each outcome from data made for it: a limit well above zero is established; a power law
    /// to zero is recognised as the limit zero (which the old rule could not say); large errors
    /// leave it undecided; a form that does not fit is not judged.
    #[test]
    fn the_finite_threshold_rule_gives_each_outcome() {
        // ζ_∞ = 8e-4 with errors of 2e-5: holds.
        let (t, y, e) = data(|t| 8e-4 + 0.02 * t.powf(-0.6), 2e-5);
        assert_eq!(judge(&t, &y, &e), Verdict::Holds);
        // To zero, a T^(−0.5) with errors of 2e-5: the limit is zero.
        let (t, y, e) = data(|t| 0.04 * t.powf(-0.5), 2e-5);
        let z = fit_zero(&t, &y, &e).unwrap();
        assert!((z.b - 0.5).abs() < 0.05, "{z:?}");
        assert_eq!(judge(&t, &y, &e), Verdict::DoesNotHold);
        // A positive limit resolved from zero but below half the smallest threshold measured:
        // it does not count as the finite threshold of this protocol.
        let (t, y, e) = data(|t| 1e-4 + 0.05 * t.powf(-0.5), 1e-6);
        assert_eq!(judge(&t, &y, &e), Verdict::DoesNotHold);
        // A negative limit, well measured: does not hold either.
        let (t, y, e) = data(|t| -2e-4 + 0.02 * t.powf(-0.5), 1e-6);
        assert_eq!(judge(&t, &y, &e), Verdict::DoesNotHold);
        // The finite limit with errors as large as it: undecided.
        let (t, y, e) = data(|t| 8e-4 + 0.02 * t.powf(-0.6), 5e-4);
        assert_eq!(judge(&t, &y, &e), Verdict::Inconclusive);
        // A step the form cannot follow, with small errors: the fit fails, not judged.
        let (t, y, e) = data(|t| if t < 500.0 { 3e-3 } else { 1e-3 }, 2e-5);
        let f = fit_power(&t, &y, &e).unwrap();
        assert!(f.chi2 > chi2_99(f.dof), "{f:?}");
        assert_eq!(judge(&t, &y, &e), Verdict::Inconclusive);
        assert_eq!(rule_finite(None, None, 1e-3).0, Verdict::Inconclusive);
    }

    /// The 99 % points of χ² against tables: 6.63 (1 dof), 11.34 (3), 15.09 (5), 23.21 (10).
    #[test]
    fn the_chi2_points_match_the_tables() {
        for (dof, exact) in [(1, 6.635), (3, 11.345), (5, 15.086), (10, 23.209)] {
            let rel = (chi2_99(dof) / exact - 1.0).abs();
            assert!(
                rel < if dof == 1 { 0.04 } else { 0.01 },
                "{dof}: {}",
                chi2_99(dof)
            );
        }
    }

    /// Censored seeds widen the mean's error instead of raising it: with one of three seeds
    /// below a grid starting at 5e-4, the mean is that of (6e-4, 8e-4, 2.5e-4) and its error
    /// grows by the range the censored seed leaves open.
    #[test]
    fn censored_seeds_are_counted_not_dropped() {
        let (m, e) = censored_mean(&[6e-4, 8e-4], &[5e-4]).unwrap();
        assert!((m - (6e-4 + 8e-4 + 2.5e-4) / 3.0).abs() < 1e-15);
        let (_, se) = mean_se(&[6e-4, 8e-4, 2.5e-4]);
        assert!((e - se.hypot(5e-4 / 2.0 / 3.0)).abs() < 1e-15);
        // Dropping it would have given 7e-4: an upward bias the censored mean does not have.
        assert!(m < 7e-4);
        assert_eq!(censored_mean(&[6e-4], &[]), None);
        let (m, _) = censored_mean(&[6e-4, 8e-4], &[]).unwrap();
        assert!((m - 7e-4).abs() < 1e-15);
    }
}
