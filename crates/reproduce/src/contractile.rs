//! `reproduce contractile`: the supplementary figure of ζ = −0.0018, which stays at rest,
//! against ζ = 0 and an extensile ζ = 0.005 from the same relaxed states.

use render::{Plot, Series};

use super::column_stats;
use super::pipeline::{cell, point, sci, Csv, Made, PointRuns};
use super::{g, mean_se, mean_std, pm, Claim, Rec, ReproduceParams, Scale, SweepJob, Verdict};
use study::SweepError;

const ZETAS: [&str; 3] = ["-0.0018", "0", "0.005"];

/// The extensile run's v_rms over the passive one's (less two standard errors) above which
/// the runs are long enough to show flow.
const CONTRAST: f64 = 3.0;

/// The smallest decay rate of the contractile flow that counts as "stays at rest": 10⁻⁴ per TU
/// (an e-fold in 10⁴ TU, a tenth of the passive packing's own relaxation rate at ζ = 0).
const DECAY: f64 = 1e-4;

/// The verdict on "contractile activity stays stable" from the contractile runs' late growth
/// rate `d ln v_rms/dt` (mean, standard error over seeds) and the extensile runs' v_rms ratio
/// to ζ = 0 (mean, standard error): the rule of an effect on the decay rate `−r` with
/// [`DECAY`] counting (issue 54's `Rule`). "Holds" also needs the extensile contrast above
/// [`CONTRAST`] by two standard errors (else inconclusive: runs too short to show the extensile
/// flow); "does not hold" does not. Inconclusive without an error.
pub(crate) fn rule(rate: (f64, f64), extensile: (f64, f64)) -> (Verdict, String) {
    let (r, e) = rate;
    if !e.is_finite() {
        return (
            Verdict::Inconclusive,
            "fewer than two seeds: the growth rate has no error".into(),
        );
    }
    let o = super::rule::Rule::effect("decay rate −d ln v_rms/dt (1/TU)", DECAY).decide(-r, e);
    // A flow that is resolved not to decay does not hold, whatever the contrast.
    if o.verdict != Verdict::DoesNotHold && extensile.0 - 2.0 * extensile.1.max(0.0) <= CONTRAST {
        return (
            Verdict::Inconclusive,
            format!(
                "the extensile contrast does not flow clearly ({}× ζ = 0, less two standard errors not above {CONTRAST}): the runs may be too short",
                g(extensile.0)
            ),
        );
    }
    (
        o.verdict,
        format!(
            "{}; the extensile run flows {}× faster than ζ = 0",
            o.why,
            g(extensile.0)
        ),
    )
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 1000.0,
        Scale::Paper => 2000.0,
    };
    let mut sets = vec![format!("run.time={t}"), format!("run.output_every={t}")];
    sets.extend(p.scale.integrator());
    let res = super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("contractile-{}", p.scale.name()),
            sets,
            varies: vec![
                "model.pressure=paper,interaction".to_string(),
                format!("model.zeta={}", ZETAS.join(",")),
            ],
            analyze: None,
            seeds: None,
        },
    )?;
    p.reporter.stage("contractile: tables and plots");
    let points = res.points(None)?;
    let mut claims = Vec::new();
    let mut plots = Vec::new();
    let mut csv = Csv::new(&[
        "pressure",
        "zeta",
        "time",
        "v_rms",
        "v_rms_std",
        "s_rms",
        "s_rms_std",
    ]);
    for pressure in ["paper", "interaction"] {
        let of = |z: &str| -> Result<&PointRuns, SweepError> {
            point(&points, &[pressure, z]).ok_or_else(|| SweepError::Reproduce {
                why: format!("the sweep has no point {pressure}, ζ = {z}"),
            })
        };
        let mut v = Plot::new(
            format!("v_rms in time: contractile, passive, extensile ({pressure} pressure)"),
            "time (TU; activity from t = 200)",
            "v_rms (mean ± std over seeds)",
        );
        v.log_y = true;
        let mut s = Plot::new(
            format!("Cell deformation in time ({pressure} pressure)"),
            "time (TU; activity from t = 200)",
            "S_rms (mean ± std over seeds)",
        );
        for z in ZETAS {
            let st = column_stats(
                &of(z)?.refs(),
                "series.csv",
                "time",
                &["v_rms", "s_rms"],
                10,
            )?;
            for (time, c) in &st {
                csv.row([
                    cell(pressure),
                    cell(z),
                    cell(time),
                    sci(c[0].0),
                    sci(c[0].1),
                    sci(c[1].0),
                    sci(c[1].1),
                ]);
            }
            let time: Vec<f64> = st.iter().map(|x| x.0).collect();
            let pick = |i: usize, j: bool| -> Vec<f64> {
                st.iter()
                    .map(|x| if j { x.1[i].1 } else { x.1[i].0 })
                    .collect()
            };
            // Error bars every tenth point keep the curves readable.
            let sparse = |e: Vec<f64>| -> Vec<f64> {
                e.iter()
                    .enumerate()
                    .map(|(k, &x)| if k % 10 == 5 { x } else { 0.0 })
                    .collect()
            };
            let label = format!("ζ = {z}");
            v.series.push(
                Series::new(&label)
                    .with_points(&time, &pick(0, false), &sparse(pick(0, true)))
                    .line_only(),
            );
            s.series.push(
                Series::new(&label)
                    .with_points(&time, &pick(1, false), &sparse(pick(1, true)))
                    .line_only(),
            );
        }
        plots.push((format!("contractile_v_rms_{pressure}.png"), v));
        plots.push((format!("contractile_s_rms_{pressure}.png"), s));

        claims.push(claim(&points, pressure)?);
    }
    let settings = format!(
        "- Paper scene (docs/model.md §8): 60 cells, L = 100, γ = 0.01, both pressure forms; ζ ∈ {{{}}}; seeds {}.\n\
         - 200 TU of relaxation at ζ = 0, then {t} TU; integrator {}; f32 storage.\n\
         - Verdict from the second half of the active phase (each run's summary over it in `contractile_runs.csv`); the series every 10 TU in `contractile_series.csv`, plotted in `contractile_v_rms_*.png` and `contractile_s_rms_*.png` (one per pressure form).",
        ZETAS.join(", "),
        p.scale.seeds(),
        p.scale.integrator_name()
    );
    let mut made = Made::new(claims, settings)
        .table("contractile_series.csv", csv)
        .table(
            "contractile_runs.csv",
            super::pipeline::runs_table(&["pressure", "zeta"], &points),
        );
    for (name, plot) in plots {
        made = made.plot(name, plot);
    }
    Ok(made)
}

/// The verdict on the contractile runs of one pressure form, from the sweep's `points`: the
/// contractile flow decays, paired by seed with ζ = 0 and the extensile contrast.
fn claim(points: &[PointRuns], pressure: &str) -> Result<Claim, SweepError> {
    let of = |z: &str| -> Result<&PointRuns, SweepError> {
        point(points, &[pressure, z]).ok_or_else(|| SweepError::Reproduce {
            why: format!("the sweep has no point {pressure}, ζ = {z}"),
        })
    };
    // The verdict: the contractile flow decays at least as the passive one, paired by seed.
    // `f(run, its ζ = 0 twin)` for every run of activity z with a twin of the same seed.
    let rest = of("0")?;
    let (contractile, extensile) = (of("-0.0018")?, of("0.005")?);
    let rate_excess = |r: &Rec, b: &Rec| r.summary.growth_rate - b.summary.growth_rate;
    let v_rms_ratio = |r: &Rec, b: &Rec| r.summary.v_rms / b.summary.v_rms;
    let d_rate = mean_std(&contractile.paired(rest, rate_excess));
    let d_s = mean_std(&contractile.paired(rest, |r, b| r.summary.s_rms - b.summary.s_rms));
    let v_ratio = mean_std(&contractile.paired(rest, v_rms_ratio));
    let e_ratio = mean_std(&extensile.paired(rest, v_rms_ratio));
    let e_rate = mean_std(&extensile.paired(rest, rate_excess));
    // Stable: its flow decays, ⟨r⟩ < 0 beyond its error, the threshold protocol's "below
    // ζ_cr".
    let rate = contractile
        .measure(|r| Ok(r.summary.growth_rate))?
        .mean_se();
    let e_ratio_se = mean_se(&extensile.paired(rest, v_rms_ratio));
    let (verdict, reason) = rule(rate, e_ratio_se);
    Ok(Claim::new(
        format!("9.3 ({pressure} pressure): contractile activity (ζ = −0.0018) stays stable"),
        format!(
            "over the second half of the active phase: late growth rate d ln v_rms/dt = {} /TU (mean ± s.e.); against ζ = 0 from the same seeds (mean ± std): v_rms ratio {}, excess growth rate {} /TU, S_rms excess {}; extensile ζ = 0.005 for contrast: v_rms ratio {}, excess growth rate {} /TU",
            pm(rate),
            pm(v_ratio),
            pm(d_rate),
            pm(d_s),
            pm(e_ratio),
            pm(e_rate)
        ),
        verdict,
        reason,
))
}

/// The claims of the figure's table kept in `dir` (`contractile_runs.csv`).
#[cfg(test)]
fn verdicts_from_tables(dir: &std::path::Path) -> Result<Vec<(String, Verdict)>, SweepError> {
    let points = super::pipeline::points_from_runs_table(&dir.join("contractile_runs.csv"), 2)?;
    ["paper", "interaction"]
        .iter()
        .map(|p| claim(&points, p).map(|c| (c.claim, c.verdict)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_outcome_is_reached() {
        // Decays beyond its error, with a clear extensile contrast: holds.
        assert_eq!(rule((-2e-3, 4e-4), (12.0, 1.0)).0, Verdict::Holds);
        // Grows beyond its error: does not hold (whatever the contrast).
        assert_eq!(rule((1e-3, 2e-4), (12.0, 1.0)).0, Verdict::DoesNotHold);
        assert_eq!(rule((1e-3, 2e-4), (1.0, 0.1)).0, Verdict::DoesNotHold);
        // Negative but within two standard errors of zero: inconclusive.
        assert_eq!(rule((-2e-4, 4e-4), (12.0, 1.0)).0, Verdict::Inconclusive);
        // Decays, but resolved slower than an e-fold in 10⁴ TU: does not count as at rest.
        assert_eq!(rule((-3e-5, 1e-5), (12.0, 1.0)).0, Verdict::DoesNotHold);
        // Decays, but the extensile runs do not flow clearly: inconclusive.
        assert_eq!(rule((-2e-3, 4e-4), (3.5, 1.0)).0, Verdict::Inconclusive);
        // One seed: no error.
        assert_eq!(
            rule((-2e-3, f64::NAN), (12.0, 1.0)).0,
            Verdict::Inconclusive
        );
    }

    /// The contractile section of docs/reproduction.md states the verdicts of the figure's
    /// runs, kept in `docs/data/contractile/quick/contractile_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let want = verdicts_from_tables(&crate::stored_tables("contractile/quick")).unwrap();
        assert_eq!(want.len(), 2);
        crate::assert_doc_verdicts("contractile", "**Verdicts (quick):**", &want);
    }
}
