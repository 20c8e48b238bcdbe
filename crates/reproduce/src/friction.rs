//! `reproduce friction`: does viscous friction between cells solidify a tissue (issue 49)?
//! Chiang, Loewe, Marenduzzo & Marchetti (arXiv:2403.10715) find that friction between
//! overlapping cells (`ξ v_i = F_i − ξ_c Σ_j o_ij (v_i − v_j)`, `[friction] cells`) arrests a
//! tissue that moves without it.
//!
//! One sweep over the friction ξ_c and the propulsion α of the `jamming` figure's tissue
//! (60 self-propelled cells, persistent random propulsion, γ = 0.01), decided by the same
//! caging statistic: a run's long-lag MSD exponent β (`jamming::long_lag_exponent`), a point
//! solid when the seed mean of β is below ½ by two standard errors and fluid when above
//! (`jamming::phase`), and the line `α_c(ξ_c)` where the seed mean crosses ½
//! (`jamming::critical_alpha`, with its jackknife error). Beside it, how much friction slows
//! the cells: `D_eff/D_free`, the MSD at the longest lag over a lone cell's, at the largest ξ_c
//! over its value without friction, seed by seed. The control, a dilute gas of four cells
//! that seldom overlap, cannot be arrested by friction between cells.

#[cfg(test)]
use std::path::Path;

use study::analyze::AnalyzeOptions;
use study::SweepError;

use super::jamming::{critical_alpha, free_msd, long_lag_exponent, phase, Phase, JAMMING_SCENE};
use super::pipeline::{cell, sci, Csv, Made};
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};

/// The friction between cells ξ_c of the sweep (0: none; per node of overlap).
const XI_C: [&str; 4] = ["0", "0.1", "1", "10"];

/// The propulsions of the sweep: the `jamming` figure's weakest, a middle and its strongest.
const ALPHAS: [&str; 3] = ["0.03", "0.09", "0.24"];

/// The slowing that counts: friction at its largest halves `D_eff/D_free` or more.
pub(crate) const SLOWING: f64 = 0.5;

fn seeds(scale: Scale) -> study::Seeds {
    scale.seeds_up_to(4, 8)
}

/// One run of the figure: the tissue (`gas` false) or the control; its ξ_c and α (indices
/// into [`XI_C`] and [`ALPHAS`]), its seed, its long-lag MSD exponent and `D_eff/D_free`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Run {
    pub gas: bool,
    pub xi: usize,
    pub alpha: usize,
    pub seed: u64,
    pub beta: f64,
    pub ratio: f64,
}

/// `[ξ_c][α]` → each seed's value of `f` (in seed order) for the tissue (`gas` false) or the
/// control.
fn by_point(runs: &[Run], gas: bool, f: impl Fn(&Run) -> f64) -> Vec<Vec<Vec<f64>>> {
    let mut out = vec![vec![Vec::new(); ALPHAS.len()]; XI_C.len()];
    let mut sorted: Vec<&Run> = runs.iter().filter(|r| r.gas == gas).collect();
    sorted.sort_by_key(|r| r.seed);
    for r in sorted {
        out[r.xi][r.alpha].push(f(r));
    }
    out
}

/// "Friction solidifies the tissue": holds when some point with ξ_c > 0 is solid where the
/// frictionless tissue at the same α is fluid; does not hold when every point with ξ_c > 0 is
/// fluid; inconclusive otherwise.
pub(crate) fn verdict_solidifies(phases: &[Vec<Phase>]) -> (Verdict, String) {
    let (none, with) = phases.split_first().expect("ξ_c = 0 first");
    let arrested = with.iter().enumerate().find_map(|(k, row)| {
        row.iter()
            .zip(none)
            .position(|(&p, &p0)| p == Phase::Solid && p0 == Phase::Fluid)
            .map(|a| (k + 1, a))
    });
    if let Some((x, a)) = arrested {
        return (
            Verdict::Holds,
            format!(
                "at ξ_c = {} and α = {} the tissue is solid, fluid without friction",
                XI_C[x], ALPHAS[a]
            ),
        );
    }
    if with.iter().flatten().all(|&p| p == Phase::Fluid) {
        (
            Verdict::DoesNotHold,
            "every point with friction is fluid: the MSD exponent is above ½ by two standard errors".into(),
        )
    } else {
        (
            Verdict::Inconclusive,
            "some point with friction is solid or not established, but none is solid where the frictionless tissue is fluid".into(),
        )
    }
}

/// "Friction slows the cells": the seed-paired ratio of `D_eff/D_free` at the largest ξ_c to
/// its value without friction (`ratios`, one per seed, each the mean over α), by the rule of an
/// effect on `1 − ratio` with [`SLOWING`] the smallest that counts.
pub(crate) fn verdict_slows(ratios: &[f64]) -> (Verdict, String) {
    let (m, se) = mean_se(ratios);
    let n = ratios.iter().filter(|v| v.is_finite()).count();
    let rule = super::rule::Rule::effect(
        format!("1 − D(ξ_c max)/D(0), the slowing by friction, over {n} seeds"),
        SLOWING,
    );
    let o = rule.decide(1.0 - m, se);
    (o.verdict, o.why)
}

/// The claims from the runs (the tissue's and the control's), with the table of points.
pub(crate) fn analyse(runs: &[Run]) -> (Vec<Claim>, Csv) {
    let alphas: Vec<f64> = ALPHAS.iter().map(|a| a.parse().unwrap()).collect();
    let beta = by_point(runs, false, |r| r.beta);
    let ratio = by_point(runs, false, |r| r.ratio);
    let mut csv = Csv::new(&[
        "xi_c",
        "alpha",
        "msd_exponent_mean",
        "msd_exponent_se",
        "d_eff_over_d_free_mean",
        "phase",
        "alpha_c",
        "alpha_c_err",
    ]);
    let mut phases = Vec::new();
    let mut line = Vec::new();
    for (x, xi) in XI_C.iter().enumerate() {
        let row: Vec<Phase> = beta[x].iter().map(|b| phase(mean_se(b))).collect();
        // By seed, β at each α (seeds as rows, as `critical_alpha` takes them).
        let n_seeds = beta[x].iter().map(Vec::len).min().unwrap_or(0);
        let by_seed: Vec<Vec<f64>> = (0..n_seeds)
            .map(|s| beta[x].iter().map(|b| b[s]).collect())
            .collect();
        let (ac, err) = critical_alpha(&alphas, &by_seed);
        for (a, alpha) in ALPHAS.iter().enumerate() {
            let (m, se) = mean_se(&beta[x][a]);
            csv.row([
                cell(xi),
                cell(alpha),
                sci(m),
                sci(se),
                sci(mean_se(&ratio[x][a]).0),
                cell(row[a].name()),
                sci(ac.unwrap_or(f64::NAN)),
                sci(err),
            ]);
        }
        line.push(match ac {
            Some(ac) => format!("ξ_c {xi}: α_c = {} ± {}", g(ac), g(err)),
            None => format!(
                "ξ_c {xi}: none in range ({})",
                row.iter().map(|p| p.name()).collect::<Vec<_>>().join(", ")
            ),
        });
        phases.push(row);
    }
    let (vs, ws) = verdict_solidifies(&phases);
    // Seed-paired slowing at the largest ξ_c, averaged over α.
    let last = XI_C.len() - 1;
    let n_seeds = ratio[0].iter().map(Vec::len).min().unwrap_or(0);
    let slowing: Vec<f64> = (0..n_seeds)
        .map(|s| {
            (0..ALPHAS.len())
                .map(|a| ratio[last][a][s] / ratio[0][a][s])
                .sum::<f64>()
                / ALPHAS.len() as f64
        })
        .collect();
    let (vd, wd) = verdict_slows(&slowing);
    let (sm, sse) = mean_se(&slowing);
    let gas_beta = by_point(runs, true, |r| r.beta);
    let gas_phases: Vec<Vec<Phase>> = gas_beta
        .iter()
        .map(|row| row.iter().map(|b| phase(mean_se(b))).collect())
        .collect();
    // The control: only ξ_c's largest value is run (the gas rows of the others are empty),
    // judged as friction against a frictionless gas, which is fluid.
    let gas_row: Vec<Phase> = gas_phases[last].clone();
    let (vg, wg) = verdict_solidifies(&[vec![Phase::Fluid; ALPHAS.len()], gas_row.clone()]);
    let claims = vec![
        Claim::new(
            "friction (issue 49): friction between cells solidifies a tissue of self-propelled cells (Chiang et al. 2024): the jamming line α_c against ξ_c",
            format!("long-lag MSD exponent by point (`friction.csv`); the line: {}", line.join("; ")),
            vs,
            ws,
        ),
        Claim::new(
            format!("friction (issue 49): friction between cells slows the cells, D_eff/D_free at ξ_c = {} at most half its value without friction", XI_C[last]),
            format!("D(ξ_c {})/D(0), seed-paired and averaged over α: {} ± {}", XI_C[last], g(sm), g(sse)),
            vd,
            wd,
        ),
        Claim::new(
            format!("Control (friction): friction between cells (ξ_c = {}) arrests a dilute gas of 4 cells that seldom overlap (must not hold)", XI_C[last]),
            format!(
                "the gas's phases at α = {}: {}",
                ALPHAS.join(", "),
                gas_row.iter().map(|p| p.name()).collect::<Vec<_>>().join(", ")
            ),
            vg,
            wg,
        ),
    ];
    (claims, csv)
}

/// The table of runs, the figure's raw data.
fn runs_csv(runs: &[Run]) -> Csv {
    let mut csv = Csv::new(&[
        "kind",
        "xi_c",
        "alpha",
        "seed",
        "msd_exponent",
        "d_eff_over_d_free",
    ]);
    for r in runs {
        csv.row([
            cell(if r.gas { "gas" } else { "tissue" }),
            cell(XI_C[r.xi]),
            cell(ALPHAS[r.alpha]),
            cell(r.seed),
            sci(r.beta),
            sci(r.ratio),
        ]);
    }
    csv
}

/// The runs of `friction_runs.csv` in `dir`, as [`runs_csv`] wrote them.
#[cfg(test)]
fn runs_from_table(dir: &Path) -> Result<Vec<Run>, SweepError> {
    let t = super::Table::read(&dir.join("friction_runs.csv"))?;
    let (kind, xi, alpha, seed) = (
        t.strs("kind")?,
        t.strs("xi_c")?,
        t.strs("alpha")?,
        t.f64s("seed")?,
    );
    let (beta, ratio) = (t.f64s("msd_exponent")?, t.f64s("d_eff_over_d_free")?);
    Ok((0..kind.len())
        .map(|k| Run {
            gas: kind[k] == "gas",
            xi: XI_C
                .iter()
                .position(|v| *v == xi[k])
                .expect("a ξ_c of the sweep"),
            alpha: ALPHAS
                .iter()
                .position(|v| *v == alpha[k])
                .expect("an α of the sweep"),
            seed: seed[k] as u64,
            beta: beta[k],
            ratio: ratio[k],
        })
        .collect())
}

/// The runs of one sweep over `varies` (the gas control: `gas`), read from their MSDs.
fn sweep_runs(
    p: &ReproduceParams,
    t: f64,
    gas: bool,
    mut sets: Vec<String>,
    varies: Vec<String>,
) -> Result<Vec<Run>, SweepError> {
    sets.push(format!("run.time={t}"));
    sets.push("model.gamma=0.01".into());
    sets.extend(p.scale.own_dt_set());
    let res = super::sweep(
        p,
        SweepJob {
            name: format!(
                "friction{}-{}",
                if gas { "-gas" } else { "" },
                p.scale.name()
            ),
            scene: JAMMING_SCENE,
            sets,
            varies,
            analyze: Some(AnalyzeOptions::default()),
            seeds: Some(seeds(p.scale)),
        },
    )?;
    let mut out = Vec::new();
    for pt in res.points(None)? {
        let xi = XI_C
            .iter()
            .position(|v| *v == pt.values[0])
            .expect("a ξ_c of the sweep");
        let alpha = ALPHAS
            .iter()
            .position(|v| *v == pt.values[1])
            .expect("an α of the sweep");
        for r in &pt.runs {
            let m = super::Table::read(&r.run.join("analysis/msd.csv"))?;
            let (lags, msd) = (m.f64s("lag")?, m.f64s("msd")?);
            let lag = lags.last().copied().unwrap_or(f64::NAN);
            let v = msd.last().copied().unwrap_or(f64::NAN);
            let a: f64 = ALPHAS[alpha].parse().unwrap_or(f64::NAN);
            out.push(Run {
                gas,
                xi,
                alpha,
                seed: r.seed,
                beta: long_lag_exponent(&lags, &msd),
                ratio: v / free_msd(a, lag),
            });
        }
    }
    Ok(out)
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 2000.0,
        Scale::Paper => 5000.0,
    };
    let mut runs = sweep_runs(
        p,
        t,
        false,
        Vec::new(),
        vec![
            format!("friction.cells={}", XI_C.join(",")),
            format!("polarity.alpha={}", ALPHAS.join(",")),
        ],
    )?;
    p.reporter
        .stage("friction: the control, a dilute gas of cells");
    let last = XI_C[XI_C.len() - 1];
    runs.extend(sweep_runs(
        p,
        t,
        true,
        vec!["cells.count=4".into()],
        vec![
            format!("friction.cells={last}"),
            format!("polarity.alpha={}", ALPHAS.join(",")),
        ],
    )?);
    p.reporter.stage("friction: tables");
    let (claims, points) = analyse(&runs);
    let settings = format!(
        "- The `jamming` figure's tissue (60 cells, R = 8, periodic 100², persistent random propulsion with D_r = 0.01 and no alignment, ζ = 0) at γ = 0.01, with friction between cells `[friction] cells` ξ_c = {} (per node of overlap; 0: none) and propulsion α = {}; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; dt = {}; frames every 20 TU, analysed.\n\
         - Statistic: a run's long-lag MSD exponent β (the slope of ln MSD against ln τ over the last three quarters of the lags in log, the longest half the active phase, drift removed; `analysis/msd.csv`), as the `jamming` figure: a point is solid when the seed mean of β is below ½ by two standard errors, fluid when above ½ by two, otherwise not established; α_c(ξ_c) where the seed mean crosses ½, linear in ln α, with its jackknife error. Claim: friction solidifies when some point with ξ_c > 0 is solid where ξ_c = 0 at the same α is fluid; it does not when every point with friction is fluid.\n\
         - Slowing: `D_eff/D_free`, the MSD at the longest lag over a lone cell's with the same propulsion, at the largest ξ_c over its value at ξ_c = 0, seed by seed, averaged over α; it counts when friction at least halves it ({SLOWING}), by the rule of an effect.\n\
         - Control: a dilute gas of 4 cells at the largest ξ_c, which friction between cells cannot arrest (its cells seldom overlap); it must read \"does not hold\".\n\
         - Data: `friction_runs.csv` (each run), `friction.csv` (each point, with its phase and the line).",
        XI_C.join(", "),
        ALPHAS.join(", "),
        seeds(p.scale),
        p.scale.own_dt(),
    );
    Ok(Made::new(claims, settings)
        .table("friction_runs.csv", runs_csv(&runs))
        .table("friction.csv", points))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic runs: β by ξ_c index and α index, 4 seeds scattered by ±0.05.
    fn runs(beta: impl Fn(usize, usize) -> f64, ratio: impl Fn(usize) -> f64) -> Vec<Run> {
        let mut out = Vec::new();
        for xi in 0..XI_C.len() {
            for alpha in 0..ALPHAS.len() {
                for seed in 1..=4u64 {
                    let wobble = 0.05 * (seed as f64 - 2.5) / 1.5;
                    out.push(Run {
                        gas: false,
                        xi,
                        alpha,
                        seed,
                        beta: beta(xi, alpha) + wobble,
                        ratio: ratio(xi) * (1.0 + 0.1 * wobble),
                    });
                    if xi == XI_C.len() - 1 {
                        out.push(Run {
                            gas: true,
                            xi,
                            alpha,
                            seed,
                            beta: 1.0 + wobble,
                            ratio: 0.9,
                        });
                    }
                }
            }
        }
        out
    }

    #[test]
    fn each_outcome_is_reached() {
        let verdicts =
            |r: &[Run]| -> Vec<Verdict> { analyse(r).0.into_iter().map(|c| c.verdict).collect() };
        // Fluid everywhere, friction slows by a tenth: neither holds; the gas is fluid.
        let fluid = runs(|_, _| 1.0, |xi| 1.0 - 0.03 * xi as f64);
        assert_eq!(
            verdicts(&fluid),
            [
                Verdict::DoesNotHold,
                Verdict::DoesNotHold,
                Verdict::DoesNotHold
            ]
        );
        // Friction cages the weakest propulsion from ξ_c = 1 on, and quarters D: both hold,
        // and the line has an α_c at those ξ_c.
        let caged = runs(
            |xi, a| if xi >= 2 && a == 0 { 0.1 } else { 1.0 },
            |xi| 1.0 / (1.0 + xi as f64),
        );
        assert_eq!(
            verdicts(&caged),
            [Verdict::Holds, Verdict::Holds, Verdict::DoesNotHold]
        );
        let (_, csv) = analyse(&caged);
        assert!(csv.text().contains("solid"));
        // β at ½ for the friction points: not established, so inconclusive; seeds that
        // scatter the slowing around ½ leave it inconclusive too.
        let undecided = runs(
            |xi, _| if xi > 0 { 0.5 } else { 1.0 },
            |xi| 1.0 - 0.17 * xi as f64,
        );
        let v = verdicts(&undecided);
        assert_eq!(v[0], Verdict::Inconclusive);
        // The control: a gas that friction "arrests" reads holds, which the figure must not.
        let mut arrested = fluid.clone();
        for r in arrested.iter_mut().filter(|r| r.gas) {
            r.beta = 0.1;
        }
        assert_eq!(verdicts(&arrested)[2], Verdict::Holds);
    }

    /// The friction section of docs/reproduction.md states the verdicts of the stored runs,
    /// kept in `docs/data/friction/quick/friction_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let runs = runs_from_table(&crate::stored_tables("friction/quick")).unwrap();
        let want: Vec<(String, Verdict)> = analyse(&runs)
            .0
            .into_iter()
            .map(|c| (c.claim, c.verdict))
            .collect();
        crate::assert_doc_verdicts("friction", "**Verdicts (quick):**", &want);
    }
}
