//! `reproduce jamming`: the solid–liquid transition of a confluent tissue of self-propelled
//! cells (issue 41, item 3). Self-propelled Voronoi models jam below a critical propulsion
//! that grows with the cells' preferred shape index (Bi, Yang, Marchetti & Manning, Phys. Rev.
//! X 2016), and phase-field models of deformable cells fluidise with motility and
//! deformability (Loewe, Chiang, Marenduzzo & Marchetti, Phys. Rev. Lett. 2020).
//!
//! One sweep over the propulsion α and the interface stiffness γ of the paper's tissue with
//! persistent random propulsion (`align = "none"`). The statistic of a run is its mean squared
//! displacement at the longest lag τ_L (half the active phase), with the tissue's drift
//! removed (`analysis/msd.csv`); of a point, the mean and standard error over seeds of its
//! logarithm. A cell that has moved by more than its radius relative to the tissue in τ_L has
//! left its cage: a point is fluid when `ln MSD(τ_L) − 2 se > ln R²`, solid when
//! `ln MSD(τ_L) + 2 se < ln R²`. The transition α_c(γ) is where the seed mean crosses `ln R²`,
//! linear in `ln α`, its error the jackknife over seeds.

use render::{Plot, Series};
use study::analyze::AnalyzeOptions;
use study::SweepError;

use super::pipeline::{cell, sci, Csv, Made};
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};

/// The paper's tissue (60 cells of radius 8 in a periodic 100² box) with persistent random
/// propulsion: `D_r = 0.01` (a persistence time of 100 TU), no alignment, ζ = 0.
pub const JAMMING_SCENE: &str = "\
[domain]
lx = 100
ly = 100

[cells]
count = 60
radius = 8.0

[model]
zeta = 0.0

[polarity]
alpha = 0.04
rotational_diffusion = 0.01
align = \"none\"

[integrator]
dt = 0.5

[run]
relax_time = 200.0
time = 2000.0
seed = 1
output_every = 20.0
series_every = 20.0
";

/// The cell radius: the cage criterion is `MSD(τ_L) = R²`.
const RADIUS: f64 = 8.0;

/// The shape index of the vertex and Voronoi models' transition (Bi et al. 2015, 2016).
pub(crate) const VERTEX_Q: f64 = 3.81;

const ALPHAS: [&str; 6] = ["0.03", "0.06", "0.09", "0.12", "0.18", "0.24"];
const GAMMAS: [&str; 4] = ["0.005", "0.01", "0.02", "0.04"];

/// Which side of the cage criterion a point is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Phase {
    /// Cells leave their cages within τ_L.
    Fluid,
    /// They do not.
    Solid,
    /// The seeds do not decide.
    NotEstablished,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
            Self::Fluid => "fluid",
            Self::Solid => "solid",
            Self::NotEstablished => "not established",
        }
    }
}

/// A point's phase from the mean and standard error of `ln MSD(τ_L)` over seeds.
pub(crate) fn phase((m, se): (f64, f64)) -> Phase {
    let cage = (RADIUS * RADIUS).ln();
    if !se.is_finite() {
        Phase::NotEstablished
    } else if m - 2.0 * se > cage {
        Phase::Fluid
    } else if m + 2.0 * se < cage {
        Phase::Solid
    } else {
        Phase::NotEstablished
    }
}

/// The propulsion where `ln MSD` (by seed, at the increasing `alphas`) first crosses `ln R²`
/// upward, linear in `ln α`, from the seed mean; and its jackknife error over seeds (NaN with
/// fewer than three seeds or where a jackknife sample has no crossing).
pub(crate) fn critical_alpha(alphas: &[f64], ln_msd: &[Vec<f64>]) -> (Option<f64>, f64) {
    let cage = (RADIUS * RADIUS).ln();
    let crossing = |seeds: &[usize]| -> Option<f64> {
        let m = super::seed_mean(ln_msd, seeds);
        let k = m.iter().position(|&v| v > cage)?;
        if k == 0 {
            return None;
        }
        let t = (cage - m[k - 1]) / (m[k] - m[k - 1]);
        Some((alphas[k - 1].ln() + t * (alphas[k].ln() - alphas[k - 1].ln())).exp())
    };
    let all: Vec<usize> = (0..ln_msd.len()).collect();
    let Some(ac) = crossing(&all) else {
        return (None, f64::NAN);
    };
    // The error of ln α_c, carried to α_c.
    let err = super::jackknife(ln_msd.len(), |seeds| crossing(seeds).map(f64::ln));
    (Some(ac), ac * err)
}

/// "A transition line exists": holds when at every γ the lowest propulsion is solid, the
/// highest fluid and α_c has an error; does not hold when every point is on one side (all
/// fluid or all solid: no transition in the scanned range); inconclusive otherwise.
pub(crate) fn verdict_line(rows: &[(Vec<Phase>, Option<f64>, f64)]) -> (Verdict, String) {
    let all: Vec<Phase> = rows.iter().flat_map(|r| r.0.iter().copied()).collect();
    if !all.is_empty() && all.iter().all(|&p| p == Phase::Fluid) {
        return (
            Verdict::DoesNotHold,
            "every point is fluid: no solid in the scanned range".into(),
        );
    }
    if !all.is_empty() && all.iter().all(|&p| p == Phase::Solid) {
        return (
            Verdict::DoesNotHold,
            "every point is solid: no fluid in the scanned range".into(),
        );
    }
    let line = !rows.is_empty()
        && rows.iter().all(|(ph, ac, err)| {
            ph.first() == Some(&Phase::Solid)
                && ph.last() == Some(&Phase::Fluid)
                && ac.is_some()
                && err.is_finite()
        });
    if line {
        (
            Verdict::Holds,
            format!(
                "at each of the {} stiffnesses the weakest propulsion is solid and the strongest fluid, and α_c has a jackknife error",
                rows.len()
            ),
        )
    } else {
        (
            Verdict::Inconclusive,
            "at some stiffness the scan does not bracket the transition by two standard errors each way, or α_c has no error".into(),
        )
    }
}

/// "Deformability fluidises": softer cells (smaller γ) need less propulsion, so α_c grows with
/// γ: the weighted least-squares slope of `ln α_c` against `ln γ` with its error; holds when
/// it is positive by two standard errors, does not hold when negative by two, inconclusive
/// otherwise (or with fewer than three α_c).
pub(crate) fn verdict_deformability(gammas: &[f64], ac: &[(f64, f64)]) -> (Verdict, String) {
    let pts: Vec<(f64, f64, f64)> = gammas
        .iter()
        .zip(ac)
        .filter(|(_, (a, e))| a.is_finite() && e.is_finite() && *e > 0.0)
        .map(|(gm, (a, e))| (gm.ln(), a.ln(), e / a))
        .collect();
    if pts.len() < 3 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} stiffnesses with α_c and its error: a slope needs three",
                pts.len()
            ),
        );
    }
    let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let e: Vec<f64> = pts.iter().map(|p| p.2).collect();
    let Some(f) = stability::fit::line(&x, &y, Some(&e)) else {
        return (Verdict::Inconclusive, "the fit is singular".into());
    };
    let (b, se) = (f.coef[1], f.se[1]);
    let what = format!("d ln α_c / d ln γ = {} ± {}", g(b), g(se));
    if b - 2.0 * se > 0.0 {
        (
            Verdict::Holds,
            format!("{what}: softer cells fluidise at a lower propulsion"),
        )
    } else if b + 2.0 * se < 0.0 {
        (
            Verdict::DoesNotHold,
            format!("{what}: softer cells need a larger propulsion to fluidise"),
        )
    } else {
        (
            Verdict::Inconclusive,
            format!("{what}: within two standard errors of zero"),
        )
    }
}

/// "The shape index marks the transition" (a structural order parameter, as in vertex models,
/// `q* ≈ 3.81`): from the mean shape index at each α_c (interpolated as α_c is) with its spread
/// over seeds. Holds when every q(α_c) lies within 0.05 of [`VERTEX_Q`] (more than two
/// standard errors counted); does not hold when one lies further than 0.1 and two standard
/// errors from it; inconclusive otherwise.
pub(crate) fn verdict_shape(q: &[(f64, f64)]) -> (Verdict, String) {
    let q: Vec<(f64, f64)> = q.iter().copied().filter(|v| v.0.is_finite()).collect();
    if q.is_empty() {
        return (Verdict::Inconclusive, "no transition to read q at".into());
    }
    let text = q
        .iter()
        .map(|(m, s)| format!("{} ± {}", g(*m), g(*s)))
        .collect::<Vec<_>>()
        .join(", ");
    let off = |(m, s): &(f64, f64)| (m - VERTEX_Q).abs() - 2.0 * s.max(0.0);
    if q.iter()
        .all(|v| (v.0 - VERTEX_Q).abs() + 2.0 * v.1.max(0.0) <= 0.05)
    {
        (
            Verdict::Holds,
            format!("q(α_c) = {text}: all within 0.05 of {VERTEX_Q}"),
        )
    } else if q.iter().any(|v| off(v) > 0.1) {
        (
            Verdict::DoesNotHold,
            format!("q(α_c) = {text}: at least one is more than 0.1 and two standard errors from {VERTEX_Q}"),
        )
    } else {
        (Verdict::Inconclusive, format!("q(α_c) = {text}"))
    }
}

/// The transition line α_c against γ, with its jackknife errors: `None` when no γ has an α_c.
fn line_plot(gammas: &[f64], ac_pts: &[(f64, f64)]) -> Option<Plot> {
    let (x, y): (Vec<f64>, Vec<f64>) = gammas
        .iter()
        .zip(ac_pts)
        .filter(|(_, a)| a.0.is_finite())
        .map(|(g, a)| (*g, a.0))
        .unzip();
    let e: Vec<f64> = ac_pts
        .iter()
        .filter(|a| a.0.is_finite())
        .map(|a| if a.1.is_finite() { a.1 } else { 0.0 })
        .collect();
    if x.is_empty() {
        return None;
    }
    {
        let mut lplot = Plot::new(
            "The transition line: α_c against γ",
            "interface stiffness γ",
            "α_c (MSD(τ_L) = R²), ± jackknife",
        );
        lplot.log_x = true;
        lplot.zero_y = true;
        lplot
            .series
            .push(Series::new("α_c").with_points(&x, &y, &e));
        Some(lplot)
    }
}

/// The figure's claims from each γ's phases and α_c (`rows`), the α_c with their errors, the
/// shape index at α_c, and the text of the line.
fn claims(
    rows: &[(Vec<Phase>, Option<f64>, f64)],
    gammas: &[f64],
    ac_pts: &[(f64, f64)],
    q_at: &[(f64, f64)],
    line_text: &[String],
) -> Vec<Claim> {
    let (v1, w1) = verdict_line(rows);
    let (v2, w2) = verdict_deformability(gammas, ac_pts);
    let (v3, w3) = verdict_shape(q_at);
    let line = line_text.join("; ");
    vec![
        Claim::new(
            "jamming (issue 41): a confluent tissue of self-propelled cells has a solid–liquid transition line α_c(γ) (Bi et al. 2016; Loewe et al. 2020)",
            line.clone(),
            v1,
            w1,
        ),
        Claim::new(
            "jamming: deformability fluidises: softer cells (smaller γ) fluidise at a lower propulsion",
            line.clone(),
            v2,
            w2,
        ),
        Claim::new(
            "jamming: the shape index marks the transition, q(α_c) ≈ 3.81 as in vertex models",
            line,
            v3,
            w3,
        ),
    ]
}

/// The figure's settings, as `verdict.md` states them, for runs of `t` TU at `scale` and the
/// longest lag `lag_l`.
fn settings(scale: Scale, t: f64, lag_l: f64) -> String {
    format!(
        "- The paper's tissue (60 cells, R = 8, periodic 100², ζ = 0) with persistent random propulsion: `[polarity] align = \"none\"`, D_r = 0.01 (persistence time 100 TU); γ ∈ {{{}}}, α ∈ {{{}}}; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; dt = {}; frames every 20 TU.\n\
         - Statistic: the mean squared displacement at the longest lag τ_L = {} TU (half the active phase) with the tissue's drift removed (`analysis/msd.csv`), its logarithm's mean ± standard error over seeds; D_eff = MSD/(4τ_L) in `jamming_runs.csv`. Fluid when ln MSD − 2 se > ln R², solid when ln MSD + 2 se < ln R² (a cell that moved its radius relative to the tissue in τ_L has left its cage; a finite-time criterion: longer runs can only move the line to lower α). α_c: where the seed mean crosses ln R², linear in ln α; error: jackknife over seeds. The shape index q = P/√A (`shape_index` of `analysis/observables.csv`), mean over the second half.\n\
         - Rules: claim 1 holds when at every γ the weakest α is solid, the strongest fluid and α_c has an error, does not hold when every point is on one side. Claim 2: the weighted slope of ln α_c against ln γ, positive or negative by two standard errors. Claim 3: every q(α_c) within 0.05 of 3.81 (errors counted) holds; one more than 0.1 and two errors away does not hold.\n\
         - Data: `jamming_runs.csv`, `jamming.csv`; plots `jamming_msd.png`, `jamming_shape_index.png`, `jamming_line.png`.",
        GAMMAS.join(", "),
        ALPHAS.join(", "),
        scale.seeds(),
        scale.own_dt(),
        g(lag_l),
    )
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 2000.0,
        Scale::Paper => 5000.0,
    };
    let res = sweep(p, t)?;
    p.reporter.stage("jamming: tables and plots");
    let points = res.points(None)?;
    let alphas: Vec<f64> = ALPHAS
        .iter()
        .map(|a| a.parse().expect("a number"))
        .collect();
    let gammas: Vec<f64> = GAMMAS
        .iter()
        .map(|a| a.parse().expect("a number"))
        .collect();
    let PerRun {
        ln_msd,
        q,
        lag_l,
        runs_csv,
    } = PerRun::read(&points, 200.0 + t / 2.0)?;
    let mut lines = Lines::new(lag_l);
    for (gi, gamma) in GAMMAS.iter().enumerate() {
        lines.add(gamma, &alphas, &ln_msd[gi], &q[gi]);
    }
    let Lines {
        points_csv,
        rows,
        ac_pts,
        q_at,
        plot,
        qplot,
        line_text,
    } = lines;
    let mut made = Made::new(Vec::new(), String::new())
        .table("jamming_runs.csv", runs_csv)
        .table("jamming.csv", points_csv)
        .plot("jamming_msd.png", plot)
        .plot("jamming_shape_index.png", qplot);
    if let Some(lplot) = line_plot(&gammas, &ac_pts) {
        made = made.plot("jamming_line.png", lplot);
    }
    let claims = claims(&rows, &gammas, &ac_pts, &q_at, &line_text);
    let settings = settings(p.scale, t, lag_l);
    made.claims = claims;
    made.settings = settings;
    Ok(made)
}

/// The sweep over γ and α at run length `t`.
fn sweep(p: &ReproduceParams, t: f64) -> Result<super::SweepResult, SweepError> {
    let mut sets = vec![format!("run.time={t}")];
    sets.extend(p.scale.own_dt_set());
    super::sweep(
        p,
        SweepJob {
            name: format!("jamming-{}", p.scale.name()),
            scene: JAMMING_SCENE,
            sets,
            varies: vec![
                format!("model.gamma={}", GAMMAS.join(",")),
                format!("polarity.alpha={}", ALPHAS.join(",")),
            ],
            analyze: Some(AnalyzeOptions::default()),
            seeds: None,
        },
    )
}

/// What each run gives, by `[γ][seed][α]`: `ln MSD(τ_L)` and the late shape index; the lag
/// `τ_L`; and the table of the runs.
struct PerRun {
    ln_msd: Vec<Vec<Vec<f64>>>,
    q: Vec<Vec<Vec<f64>>>,
    lag_l: f64,
    runs_csv: Csv,
}

impl PerRun {
    /// Reads every run of `points`, its shape index averaged from `from`.
    fn read(points: &[super::pipeline::PointRuns], from: f64) -> Result<Self, SweepError> {
        let n_seeds = points.first().map_or(0, |pt| pt.runs.len());
        // [γ][seed][α]: ln MSD(τ_L) and the shape index; τ_L per run.
        let mut ln_msd = vec![vec![vec![f64::NAN; ALPHAS.len()]; n_seeds]; GAMMAS.len()];
        let mut q = ln_msd.clone();
        let mut lag_l = f64::NAN;
        let mut runs_csv = Csv::new(&[
            "gamma",
            "alpha",
            "seed",
            "lag",
            "msd",
            "d_eff",
            "shape_index",
        ]);
        for (pt, (si, r)) in points
            .iter()
            .flat_map(|pt| pt.runs.iter().enumerate().map(move |r| (pt, r)))
        {
            let gi = GAMMAS
                .iter()
                .position(|v| *v == pt.values[0])
                .expect("a γ of the sweep");
            let ai = ALPHAS
                .iter()
                .position(|v| *v == pt.values[1])
                .expect("an α of the sweep");
            let m = super::Table::read(&r.run.join("analysis/msd.csv"))?;
            let (lags, msd) = (m.f64s("lag")?, m.f64s("msd")?);
            let (lag, v) = (
                lags.last().copied().unwrap_or(f64::NAN),
                msd.last().copied().unwrap_or(f64::NAN),
            );
            lag_l = lag;
            let qm = super::late_mean(
                &r.run.join("analysis/observables.csv"),
                "shape_index",
                from,
                |v| v,
            )?;
            ln_msd[gi][si][ai] = v.ln();
            q[gi][si][ai] = qm;
            runs_csv.row([
                cell(&pt.values[0]),
                cell(&pt.values[1]),
                cell(r.seed),
                cell(lag),
                sci(v),
                sci(v / (4.0 * lag)),
                cell(qm),
            ]);
        }
        Ok(Self {
            ln_msd,
            q,
            lag_l,
            runs_csv,
        })
    }
}

/// The points of each γ's line, and what the figure draws and claims of them.
struct Lines {
    points_csv: Csv,
    rows: Vec<(Vec<Phase>, Option<f64>, f64)>,
    ac_pts: Vec<(f64, f64)>,
    q_at: Vec<(f64, f64)>,
    plot: Plot,
    qplot: Plot,
    line_text: Vec<String>,
}

impl Lines {
    fn new(lag_l: f64) -> Self {
        let points_csv = Csv::new(&[
            "gamma",
            "alpha",
            "ln_msd_mean",
            "ln_msd_se",
            "msd_geometric_mean",
            "shape_index_mean",
            "shape_index_se",
            "phase",
        ]);
        let rows: Vec<(Vec<Phase>, Option<f64>, f64)> = Vec::new();
        let ac_pts: Vec<(f64, f64)> = Vec::new();
        let q_at: Vec<(f64, f64)> = Vec::new();
        let mut plot = Plot::new(
            format!("Mean squared displacement at the lag τ_L = {} TU", g(lag_l)),
            "propulsion α",
            "MSD(τ_L) / R², geometric mean ± s.e. over seeds",
        );
        (plot.log_x, plot.log_y) = (true, true);
        plot.hlines = vec![(1.0, "a radius: the cage".into())];
        let mut qplot = Plot::new(
            "Shape index against propulsion",
            "propulsion α",
            "q = P/√A, second half, mean ± s.e. over seeds",
        );
        qplot.log_x = true;
        qplot.hlines = vec![(VERTEX_Q, "3.81: vertex models' transition".into())];
        let line_text = Vec::new();
        Self {
            points_csv,
            rows,
            ac_pts,
            q_at,
            plot,
            qplot,
            line_text,
        }
    }

    /// Adds the line of `gamma`: its per-seed `ln_msd[seed][α]` and shape indices `q`.
    fn add(&mut self, gamma: &str, alphas: &[f64], ln_msd: &[Vec<f64>], q: &[Vec<f64>]) {
        let Self {
            points_csv,
            rows,
            ac_pts,
            q_at,
            plot,
            qplot,
            line_text,
        } = self;
        let stats: Vec<(f64, f64)> = (0..ALPHAS.len())
            .map(|ai| mean_se(&ln_msd.iter().map(|s| s[ai]).collect::<Vec<_>>()))
            .collect();
        let qstats: Vec<(f64, f64)> = (0..ALPHAS.len())
            .map(|ai| mean_se(&q.iter().map(|s| s[ai]).collect::<Vec<_>>()))
            .collect();
        let phases: Vec<Phase> = stats.iter().map(|s| phase(*s)).collect();
        for (ai, alpha) in ALPHAS.iter().enumerate() {
            points_csv.row([
                cell(gamma),
                cell(alpha),
                sci(stats[ai].0),
                sci(stats[ai].1),
                sci(stats[ai].0.exp()),
                cell(qstats[ai].0),
                sci(qstats[ai].1),
                cell(phases[ai].name()),
            ]);
        }
        let (ac, err) = critical_alpha(alphas, ln_msd);
        // q at α_c, interpolated as α_c is, with the larger spread of the two points.
        let qa = ac.map_or((f64::NAN, f64::NAN), |a| {
            let k = alphas
                .iter()
                .position(|&x| x > a)
                .unwrap_or(alphas.len() - 1)
                .max(1);
            let t = (a.ln() - alphas[k - 1].ln()) / (alphas[k].ln() - alphas[k - 1].ln());
            (
                qstats[k - 1].0 + t * (qstats[k].0 - qstats[k - 1].0),
                qstats[k - 1].1.max(qstats[k].1),
            )
        });
        line_text.push(format!(
            "γ = {gamma}: α_c = {} ± {}, q(α_c) = {}",
            ac.map_or("–".into(), g),
            g(err),
            g(qa.0)
        ));
        ac_pts.push((ac.unwrap_or(f64::NAN), err));
        q_at.push(qa);
        rows.push((phases, ac, err));
        let r2 = RADIUS * RADIUS;
        plot.series.push(
            Series::new(format!("γ = {gamma}")).with_points(
                alphas,
                &stats.iter().map(|s| s.0.exp() / r2).collect::<Vec<_>>(),
                // The upper half-width of the band exp(m ± se), for the log axis.
                &stats
                    .iter()
                    .map(|s| (s.0 + s.1).exp() / r2 - s.0.exp() / r2)
                    .collect::<Vec<_>>(),
            ),
        );
        qplot
            .series
            .push(Series::new(format!("γ = {gamma}")).with_points(
                alphas,
                &qstats.iter().map(|s| s.0).collect::<Vec<_>>(),
                &qstats.iter().map(|s| s.1).collect::<Vec<_>>(),
            ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic seeds: ln MSD = ln R² + 3 ln(α/α_c) with a seed's scatter.
    fn synthetic(ac: f64, scatter: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
        let alphas: Vec<f64> = ALPHAS.iter().map(|a| a.parse().unwrap()).collect();
        let cage = (RADIUS * RADIUS).ln();
        let runs = (0..4)
            .map(|s| {
                let off = scatter * (s as f64 - 1.5);
                alphas
                    .iter()
                    .map(|a| cage + 3.0 * (a / ac).ln() + off)
                    .collect()
            })
            .collect();
        (alphas, runs)
    }

    fn phases(runs: &[Vec<f64>]) -> Vec<Phase> {
        (0..runs[0].len())
            .map(|k| phase(mean_se(&runs.iter().map(|r| r[k]).collect::<Vec<_>>())))
            .collect()
    }

    #[test]
    fn the_critical_propulsion_is_recovered_with_an_error() {
        let (a, runs) = synthetic(0.1, 0.1);
        let (ac, err) = critical_alpha(&a, &runs);
        let ac = ac.unwrap();
        assert!((ac / 0.1 - 1.0).abs() < 0.05, "{ac}");
        assert!(err > 0.0 && err < 0.05 * ac, "{err}");
        let p = phases(&runs);
        assert_eq!(p[0], Phase::Solid);
        assert_eq!(p[5], Phase::Fluid);
    }

    #[test]
    fn each_outcome_of_each_claim_is_reached() {
        let row = |ac: f64| {
            let (a, runs) = synthetic(ac, 0.1);
            let (c, e) = critical_alpha(&a, &runs);
            (phases(&runs), c, e)
        };
        // A line inside the scan at every γ: holds.
        assert_eq!(verdict_line(&[row(0.1), row(0.12)]).0, Verdict::Holds);
        // Everything fluid (α_c far below the scan), or everything solid: does not hold.
        assert_eq!(
            verdict_line(&[row(0.001), row(0.002)]).0,
            Verdict::DoesNotHold
        );
        assert_eq!(verdict_line(&[row(5.0), row(9.0)]).0, Verdict::DoesNotHold);
        // One γ bracketed, one all solid: inconclusive.
        assert_eq!(verdict_line(&[row(0.1), row(5.0)]).0, Verdict::Inconclusive);

        let gammas = [0.005, 0.01, 0.02, 0.04];
        let rising: Vec<(f64, f64)> = gammas.iter().map(|g| (2.0 * g, 0.002 * g)).collect();
        assert_eq!(verdict_deformability(&gammas, &rising).0, Verdict::Holds);
        let falling: Vec<(f64, f64)> = gammas.iter().map(|g| (1e-3 / g, 2e-5 / g)).collect();
        assert_eq!(
            verdict_deformability(&gammas, &falling).0,
            Verdict::DoesNotHold
        );
        let flat = [(0.1, 0.02), (0.11, 0.02), (0.1, 0.02), (0.09, 0.02)];
        assert_eq!(
            verdict_deformability(&gammas, &flat).0,
            Verdict::Inconclusive
        );
        assert_eq!(
            verdict_deformability(&gammas[..2], &flat[..2]).0,
            Verdict::Inconclusive
        );

        assert_eq!(
            verdict_shape(&[(3.81, 0.01), (3.83, 0.005)]).0,
            Verdict::Holds
        );
        assert_eq!(
            verdict_shape(&[(3.81, 0.01), (4.3, 0.02)]).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            verdict_shape(&[(3.81, 0.01), (3.9, 0.01)]).0,
            Verdict::Inconclusive
        );
        assert_eq!(verdict_shape(&[]).0, Verdict::Inconclusive);
    }
}
