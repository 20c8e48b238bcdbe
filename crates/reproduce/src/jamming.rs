//! `reproduce jamming`: the solid–liquid transition of a confluent tissue of self-propelled
//! cells (issue 41, item 3). Self-propelled Voronoi models jam below a critical propulsion
//! that grows with the cells' preferred shape index (Bi, Yang, Marchetti & Manning, Phys. Rev.
//! X 2016), and phase-field models of deformable cells fluidise with motility and
//! deformability (Loewe, Chiang, Marenduzzo & Marchetti, Phys. Rev. Lett. 2020).
//!
//! One sweep over the propulsion α and the interface stiffness γ of the paper's tissue with
//! persistent random propulsion (`align = "none"`). Arrest is decided by caging (issue 54): the
//! statistic of a run is the exponent β of its mean squared displacement at long lags, the
//! least-squares slope of `ln MSD` against `ln τ` over `[τ_L/4, τ_L]` (τ_L the longest lag, half
//! the active phase), with the tissue's drift removed (`analysis/msd.csv`); a caged cell's MSD
//! levels off (β → 0), a free or fluid one's grows linearly (β → 1). A point is solid when the
//! seed mean of β is below ½ by two standard errors, fluid when above ½ by two; the transition
//! α_c(γ) is where the seed mean crosses ½, linear in `ln α`, its error the jackknife over
//! seeds. Beside it, `D_eff/D_free = MSD(τ_L)/MSD_free(τ_L)`, the MSD against that of a lone
//! cell with the same propulsion (`2 v₀² τ_p [t − τ_p (1 − e^{−t/τ_p})]`, `v₀ = α/ξ`,
//! `τ_p = 1/D_r`). The earlier criterion, `MSD(τ_L) < R²`, called a slow free cell arrested: a
//! control of a dilute gas of four cells that seldom touch (`cells.count = 4`) must read fluid
//! at every α, and the old criterion's verdict on it is reported beside.

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

/// The cell radius: the earlier criterion was `MSD(τ_L) = R²`.
const RADIUS: f64 = 8.0;

/// The long-lag MSD exponent halfway between a cage's plateau (0) and diffusion (1): solid
/// below it by two standard errors, fluid above.
pub(crate) const CAGE_EXPONENT: f64 = 0.5;

/// Friction ξ and rotational diffusion D_r of the scene (the free cell's MSD).
const XI: f64 = 2.0;
const D_R: f64 = 0.01;

/// Cells of the gas control.
const GAS_CELLS: usize = 4;

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
    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::Fluid => "fluid",
            Self::Solid => "solid",
            Self::NotEstablished => "not established",
        }
    }
}

/// A point's phase from the mean and standard error over seeds of the long-lag MSD exponent.
pub(crate) fn phase((m, se): (f64, f64)) -> Phase {
    // Which side of ½: the rule of an effect on β − ½ whose smallest size that counts is any
    // (the least positive number): fluid when it holds (above ½ by two s.e.), solid when it
    // does not (below ½ by two), not established otherwise and without an error.
    let rule = super::rule::Rule::effect("β − ½", f64::MIN_POSITIVE);
    match rule.decide(m - CAGE_EXPONENT, se).verdict {
        Verdict::Holds => Phase::Fluid,
        Verdict::DoesNotHold => Phase::Solid,
        Verdict::Inconclusive => Phase::NotEstablished,
    }
}

/// The propulsion where the MSD exponent (by seed, at the increasing `alphas`) first crosses
/// [`CAGE_EXPONENT`] upward, linear in `ln α`, from the seed mean; and its jackknife error over
/// seeds (NaN with fewer than three seeds or where a jackknife sample has no crossing).
pub(crate) fn critical_alpha(alphas: &[f64], ln_msd: &[Vec<f64>]) -> (Option<f64>, f64) {
    let cage = CAGE_EXPONENT;
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
/// γ: the weighted least-squares slope of `ln α_c` against `ln γ` with its error, by the rule
/// of an effect with [`DEFORMABILITY`] counting (inconclusive with fewer than three α_c).
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
    let o =
        super::rule::Rule::effect("d ln α_c / d ln γ", DEFORMABILITY).decide(f.coef[1], f.se[1]);
    (o.verdict, o.why)
}

/// The smallest exponent of `α_c ∝ γ^b` that counts for "deformability fluidises": ¼.
const DEFORMABILITY: f64 = 0.25;

/// How far q(α_c) may lie from [`VERTEX_Q`] and still mark the transition: 0.1 (the vertex
/// models put it at 3.81; a cell's disc is 3.545).
const SHAPE_Q: f64 = 0.1;

/// "The shape index marks the transition" (a structural order parameter, as in vertex models,
/// `q* ≈ 3.81`): from the mean shape index at each α_c (interpolated as α_c is) with its spread
/// over seeds, each by the rule of an absence on `q(α_c) − q*` with [`SHAPE_Q`] counting: holds
/// when every one holds, does not hold when one does not, inconclusive otherwise.
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
    let rule = super::rule::Rule::absence("q(α_c) − q*", SHAPE_Q);
    let outcomes: Vec<super::rule::Outcome> = q
        .iter()
        .map(|(m, s)| rule.decide(m - VERTEX_Q, *s))
        .collect();
    let (v, why) = super::rules::all_of(&outcomes);
    (v, format!("q(α_c) = {text}: {why}"))
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
         - Statistic (issue 54: arrest by caging): the exponent β of the mean squared displacement at long lags, the least-squares slope of ln MSD against ln τ over [τ_L/4, τ_L], τ_L = {} TU (half the active phase), with the tissue's drift removed (`analysis/msd.csv`); its mean ± standard error over seeds. Solid when β + 2 se < ½ (the MSD levels off: a cage), fluid when β − 2 se > ½ (it grows towards diffusion, β = 1). α_c: where the seed mean of β crosses ½, linear in ln α; error: jackknife over seeds. Beside it, D_eff/D_free = MSD(τ_L) / MSD_free(τ_L), against a lone cell with the same propulsion (2 v₀² τ_p [t − τ_p(1 − e^(−t/τ_p))], v₀ = α/ξ, τ_p = 1/D_r), and D_eff = MSD/(4τ_L) in `jamming_runs.csv`. The earlier criterion (solid when MSD(τ_L) < R²) is kept in the tables (`ln_msd_*`) and in the control's line. The shape index q = P/√A (`shape_index` of `analysis/observables.csv`), mean over the second half.\n\
         - Control: the same scene with {GAS_CELLS} cells (area fraction 8 %: they seldom touch), γ = {GAS_GAMMA}, every α (`jamming_gas*.csv`); the line's rule on it must read \"does not hold\" (every point fluid).\n\
         - Rules: claim 1 holds when at every γ the weakest α is solid, the strongest fluid and α_c has an error, does not hold when every point is on one side. Claim 2: the weighted slope of ln α_c against ln γ, by the rule of an effect with ¼ counting (issue 54's `Rule`: resolved by two standard errors and at least ¼ holds; below ¼ by two does not). Claim 3: each q(α_c) − 3.81 by the rule of an absence with 0.1 counting; holds when every one holds, does not hold when one does not.\n\
         - Data: `jamming_runs.csv`, `jamming.csv`, `jamming_gas_runs.csv`, `jamming_gas.csv`; plots `jamming_exponent.png`, `jamming_msd.png`, `jamming_shape_index.png`, `jamming_line.png`.",
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
    let runs = PerRun::read(&points, 200.0 + t / 2.0)?;
    p.reporter
        .stage("jamming: the control, a dilute gas of cells");
    let gas_points = sweep_gas(p, t)?.points(None)?;
    let gas = PerRun::read(&gas_points, 200.0 + t / 2.0)?;
    let (lines, gas_lines, claims) = analyse(&runs, &gas);
    let Lines {
        points_csv,
        ac_pts,
        plot,
        qplot,
        bplot,
        ..
    } = lines;
    let mut made = Made::new(Vec::new(), String::new())
        .table("jamming_runs.csv", runs.runs_csv)
        .table("jamming.csv", points_csv)
        .table("jamming_gas_runs.csv", gas.runs_csv)
        .table("jamming_gas.csv", gas_lines.points_csv)
        .plot("jamming_msd.png", plot)
        .plot("jamming_exponent.png", bplot)
        .plot("jamming_shape_index.png", qplot);
    if let Some(lplot) = line_plot(&gammas(), &ac_pts) {
        made = made.plot("jamming_line.png", lplot);
    }
    let lag_l = runs.lag_l;
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

/// The exponent of `MSD ∝ τ^β` at long lags: the least-squares slope of `ln MSD` against
/// `ln τ` over `[τ_L/4, τ_L]`, `τ_L` the longest lag (NaN with fewer than two lags there).
pub(crate) fn long_lag_exponent(lags: &[f64], msd: &[f64]) -> f64 {
    let top = lags.iter().copied().fold(f64::NAN, f64::max);
    let (x, y): (Vec<f64>, Vec<f64>) = lags
        .iter()
        .zip(msd)
        .filter(|(l, m)| **l >= top / 4.0 && **l > 0.0 && **m > 0.0)
        .map(|(l, m)| (l.ln(), m.ln()))
        .unzip();
    study::summary::slope(&x, &y)
}

/// The MSD of a lone cell with propulsion `alpha` at lag `t`: a persistent random walk,
/// `2 v₀² τ_p [t − τ_p (1 − e^{−t/τ_p})]` with `v₀ = α/ξ` and `τ_p = 1/D_r`.
pub(crate) fn free_msd(alpha: f64, t: f64) -> f64 {
    let (v0, tp) = (alpha / XI, 1.0 / D_R);
    2.0 * v0 * v0 * tp * (t - tp * (1.0 - (-t / tp).exp()))
}

/// γ of the gas control.
const GAS_GAMMA: &str = "0.01";

/// The control: [`GAS_CELLS`] cells in the same box (area fraction 8 %), γ = [`GAS_GAMMA`],
/// every α.
fn sweep_gas(p: &ReproduceParams, t: f64) -> Result<super::SweepResult, SweepError> {
    let mut sets = vec![format!("run.time={t}"), format!("cells.count={GAS_CELLS}")];
    sets.extend(p.scale.own_dt_set());
    super::sweep(
        p,
        SweepJob {
            name: format!("jamming-gas-{}", p.scale.name()),
            scene: JAMMING_SCENE,
            sets,
            varies: vec![
                format!("model.gamma={GAS_GAMMA}"),
                format!("polarity.alpha={}", ALPHAS.join(",")),
            ],
            analyze: Some(AnalyzeOptions::default()),
            seeds: None,
        },
    )
}

/// The control's claim: "a dilute gas of cells is arrested at some propulsion", by the rule of
/// the line (`verdict_line` on its phases), which must read "does not hold"; with the earlier
/// criterion's count of gas points it called solid (`MSD(τ_L) < R²`).
fn gas_claim(rows: &[(Vec<Phase>, Option<f64>, f64)], gas: &PerRun, gi: usize) -> Claim {
    let (v, why) = verdict_line(rows);
    let r2 = (RADIUS * RADIUS).ln();
    let n_alpha = ALPHAS.len();
    let old_solid = (0..n_alpha)
        .filter(|&ai| {
            let (m, se) = mean_se(&gas.ln_msd[gi].iter().map(|s| s[ai]).collect::<Vec<_>>());
            m + 2.0 * se < r2
        })
        .count();
    let betas: Vec<String> = (0..n_alpha)
        .map(|ai| {
            let (m, se) = mean_se(&gas.beta[gi].iter().map(|s| s[ai]).collect::<Vec<_>>());
            let (r, _) = mean_se(&gas.ratio[gi].iter().map(|s| s[ai]).collect::<Vec<_>>());
            format!(
                "α = {}: β = {} ± {}, D_eff/D_free = {}",
                ALPHAS[ai],
                g(m),
                g(se),
                g(r)
            )
        })
        .collect();
    Claim::new(
        format!("Control (jamming): a dilute gas of {GAS_CELLS} cells that seldom touch is arrested at some propulsion (must not hold)"),
        betas.join("; "),
        v,
        format!(
            "{why}; the earlier criterion MSD(τ_L) < R² called {old_solid} of its {n_alpha} propulsions solid"
        ),
    )
}

/// What each run gives, by `[γ][seed][α]`: the long-lag MSD exponent, `ln MSD(τ_L)`,
/// `D_eff/D_free` and the late shape index; the lag `τ_L`; and the table of the runs.
struct PerRun {
    beta: Vec<Vec<Vec<f64>>>,
    ratio: Vec<Vec<Vec<f64>>>,
    ln_msd: Vec<Vec<Vec<f64>>>,
    q: Vec<Vec<Vec<f64>>>,
    lag_l: f64,
    runs_csv: Csv,
}

impl PerRun {
    /// Reads every run of `points` (whose values are γ and α), its shape index averaged from
    /// `from`.
    fn read(points: &[super::pipeline::PointRuns], from: f64) -> Result<Self, SweepError> {
        let n_seeds = points.first().map_or(0, |pt| pt.runs.len());
        // [γ][seed][α]: the exponent, ln MSD(τ_L), D_eff/D_free and the shape index.
        let mut ln_msd = vec![vec![vec![f64::NAN; ALPHAS.len()]; n_seeds]; GAMMAS.len()];
        let mut q = ln_msd.clone();
        let mut beta = ln_msd.clone();
        let mut ratio = ln_msd.clone();
        let mut lag_l = f64::NAN;
        let mut runs_csv = Csv::new(&[
            "gamma",
            "alpha",
            "seed",
            "lag",
            "msd",
            "d_eff",
            "d_eff_over_d_free",
            "msd_exponent",
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
            let alpha: f64 = pt.values[1].parse().unwrap_or(f64::NAN);
            let b = long_lag_exponent(&lags, &msd);
            let r_free = v / free_msd(alpha, lag);
            let qm = super::late_mean(
                &r.run.join("analysis/observables.csv"),
                "shape_index",
                from,
                |v| v,
            )?;
            ln_msd[gi][si][ai] = v.ln();
            q[gi][si][ai] = qm;
            beta[gi][si][ai] = b;
            ratio[gi][si][ai] = r_free;
            runs_csv.row([
                cell(&pt.values[0]),
                cell(&pt.values[1]),
                cell(r.seed),
                cell(lag),
                sci(v),
                sci(v / (4.0 * lag)),
                sci(r_free),
                cell(b),
                cell(qm),
            ]);
        }
        Ok(Self {
            beta,
            ratio,
            ln_msd,
            q,
            lag_l,
            runs_csv,
        })
    }
}

impl PerRun {
    /// The runs of a table that [`PerRun::read`] wrote (`jamming_runs.csv` or
    /// `jamming_gas_runs.csv`), as it had them: each point's runs in the table's order.
    #[cfg(test)]
    fn from_table(path: &std::path::Path) -> Result<Self, SweepError> {
        let t = super::Table::read(path)?;
        let (gc, ac) = (t.col("gamma")?, t.col("alpha")?);
        let (lag, msd, ratio_c, beta_c, q_c) = (
            t.f64s("lag")?,
            t.f64s("msd")?,
            t.f64s("d_eff_over_d_free")?,
            t.f64s("msd_exponent")?,
            t.f64s("shape_index")?,
        );
        let index = |k: usize, col: usize, of: &[&str]| -> Result<usize, SweepError> {
            of.iter()
                .position(|v| *v == t.rows[k][col])
                .ok_or_else(|| SweepError::Reproduce {
                    why: format!(
                        "{}: row {}: {} is not of the sweep",
                        path.display(),
                        k + 1,
                        t.rows[k][col]
                    ),
                })
        };
        // The seed index of a run: how many runs of its point came before it.
        let mut seen = vec![vec![0usize; ALPHAS.len()]; GAMMAS.len()];
        let mut at = Vec::new();
        for k in 0..t.rows.len() {
            let (gi, ai) = (index(k, gc, &GAMMAS)?, index(k, ac, &ALPHAS)?);
            at.push((gi, seen[gi][ai], ai));
            seen[gi][ai] += 1;
        }
        let n_seeds = seen.iter().flatten().copied().max().unwrap_or(0);
        let mut ln_msd = vec![vec![vec![f64::NAN; ALPHAS.len()]; n_seeds]; GAMMAS.len()];
        let (mut q, mut beta, mut ratio) = (ln_msd.clone(), ln_msd.clone(), ln_msd.clone());
        for (k, &(gi, si, ai)) in at.iter().enumerate() {
            ln_msd[gi][si][ai] = msd[k].ln();
            q[gi][si][ai] = q_c[k];
            beta[gi][si][ai] = beta_c[k];
            ratio[gi][si][ai] = ratio_c[k];
        }
        Ok(Self {
            beta,
            ratio,
            ln_msd,
            q,
            lag_l: lag.last().copied().unwrap_or(f64::NAN),
            runs_csv: Csv::new(&[]),
        })
    }
}

/// The scan's propulsions and stiffnesses as numbers.
fn alphas() -> Vec<f64> {
    ALPHAS
        .iter()
        .map(|a| a.parse().expect("a number"))
        .collect()
}

fn gammas() -> Vec<f64> {
    GAMMAS
        .iter()
        .map(|a| a.parse().expect("a number"))
        .collect()
}

/// Each γ's line of the tissue's runs, the gas control's line, and the figure's claims: what
/// [`make`] draws and writes, and what the stored tables give back.
fn analyse(runs: &PerRun, gas: &PerRun) -> (Lines, Lines, Vec<Claim>) {
    let alphas = alphas();
    let mut lines = Lines::new(runs.lag_l);
    for (gi, gamma) in GAMMAS.iter().enumerate() {
        lines.add(gamma, &alphas, runs, gi);
    }
    let gi = GAMMAS
        .iter()
        .position(|v| *v == GAS_GAMMA)
        .expect("the gas's γ is one of the sweep's");
    let mut gas_lines = Lines::new(gas.lag_l);
    gas_lines.add(GAS_GAMMA, &alphas, gas, gi);
    let mut claims = claims(
        &lines.rows,
        &gammas(),
        &lines.ac_pts,
        &lines.q_at,
        &lines.line_text,
    );
    claims.push(gas_claim(&gas_lines.rows, gas, gi));
    (lines, gas_lines, claims)
}

/// The claims of the figure's tables kept in `dir` (`jamming_runs.csv`,
/// `jamming_gas_runs.csv`), as [`make`] gives them.
#[cfg(test)]
fn verdicts_from_tables(dir: &std::path::Path) -> Result<Vec<(String, Verdict)>, SweepError> {
    let runs = PerRun::from_table(&dir.join("jamming_runs.csv"))?;
    let gas = PerRun::from_table(&dir.join("jamming_gas_runs.csv"))?;
    let (_, _, claims) = analyse(&runs, &gas);
    Ok(claims.into_iter().map(|c| (c.claim, c.verdict)).collect())
}

/// The points of each γ's line, and what the figure draws and claims of them.
struct Lines {
    points_csv: Csv,
    rows: Vec<(Vec<Phase>, Option<f64>, f64)>,
    ac_pts: Vec<(f64, f64)>,
    q_at: Vec<(f64, f64)>,
    plot: Plot,
    qplot: Plot,
    bplot: Plot,
    line_text: Vec<String>,
}

impl Lines {
    fn new(lag_l: f64) -> Self {
        let points_csv = Csv::new(&[
            "gamma",
            "alpha",
            "msd_exponent_mean",
            "msd_exponent_se",
            "d_eff_over_d_free_mean",
            "d_eff_over_d_free_se",
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
        plot.hlines = vec![(1.0, "a radius: the earlier criterion".into())];
        let mut bplot = Plot::new(
            "Long-lag exponent of the MSD, over [τ_L/4, τ_L]",
            "propulsion α",
            "β (MSD ∝ τ^β), mean ± s.e. over seeds",
        );
        bplot.log_x = true;
        bplot.legend = render::LegendAt::LowerRight;
        bplot.hlines = vec![
            (CAGE_EXPONENT, "½: solid below, fluid above".into()),
            (1.0, "diffusion".into()),
        ];
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
            bplot,
            line_text,
        }
    }

    /// Adds the line of `gamma` from the runs' `[gi]` (by seed and α): phases and α_c from
    /// the MSD exponent, the MSD and the shape index drawn.
    fn add(&mut self, gamma: &str, alphas: &[f64], runs: &PerRun, gi: usize) {
        let Self {
            points_csv,
            rows,
            ac_pts,
            q_at,
            plot,
            qplot,
            bplot,
            line_text,
        } = self;
        let (beta, ln_msd, q) = (&runs.beta[gi], &runs.ln_msd[gi], &runs.q[gi]);
        let over = |v: &[Vec<f64>]| -> Vec<(f64, f64)> {
            (0..ALPHAS.len())
                .map(|ai| mean_se(&v.iter().map(|s| s[ai]).collect::<Vec<_>>()))
                .collect()
        };
        let (stats, qstats) = (over(ln_msd), over(q));
        let (bstats, rstats) = (over(beta), over(&runs.ratio[gi]));
        let phases: Vec<Phase> = bstats.iter().map(|s| phase(*s)).collect();
        for (ai, alpha) in ALPHAS.iter().enumerate() {
            points_csv.row([
                cell(gamma),
                cell(alpha),
                cell(bstats[ai].0),
                cell(bstats[ai].1),
                sci(rstats[ai].0),
                sci(rstats[ai].1),
                sci(stats[ai].0),
                sci(stats[ai].1),
                sci(stats[ai].0.exp()),
                cell(qstats[ai].0),
                sci(qstats[ai].1),
                cell(phases[ai].name()),
            ]);
        }
        let (ac, err) = critical_alpha(alphas, beta);
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
        bplot
            .series
            .push(Series::new(format!("γ = {gamma}")).with_points(
                alphas,
                &bstats.iter().map(|s| s.0).collect::<Vec<_>>(),
                &bstats.iter().map(|s| s.1).collect::<Vec<_>>(),
            ));
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

    /// The jamming section of docs/reproduction.md states the verdicts of the figure's runs,
    /// kept in `docs/data/jamming/quick/jamming_runs.csv` and `jamming_gas_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let want = verdicts_from_tables(&crate::stored_tables("jamming/quick")).unwrap();
        assert_eq!(want.len(), 4);
        crate::assert_doc_verdicts("jamming", "**Verdicts (quick):**", &want);
    }

    /// Synthetic seeds: β = ½ + 0.3 ln(α/α_c) with a seed's scatter.
    fn synthetic(ac: f64, scatter: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
        let alphas: Vec<f64> = ALPHAS.iter().map(|a| a.parse().unwrap()).collect();
        let cage = CAGE_EXPONENT;
        let runs = (0..4)
            .map(|s| {
                let off = scatter * (s as f64 - 1.5);
                alphas
                    .iter()
                    .map(|a| cage + 0.3 * (a / ac).ln() + off)
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

    /// The exponent of an exact power law is its power; a cage's plateau reads 0 and a lone
    /// persistent walker's MSD reads diffusion at lags far beyond its persistence time, and
    /// ballistic motion far below it.
    #[test]
    fn the_long_lag_exponent_tells_a_cage_from_a_free_walk() {
        let lags: Vec<f64> = (1..=50).map(|k| 20.0 * k as f64).collect();
        for p in [0.0, 0.4, 1.0] {
            let msd: Vec<f64> = lags.iter().map(|l| 3.0 * l.powf(p)).collect();
            assert!((long_lag_exponent(&lags, &msd) - p).abs() < 1e-12, "{p}");
        }
        let free: Vec<f64> = lags.iter().map(|l| free_msd(0.05, *l)).collect();
        // It approaches 1 from above (t/(t − τ_p) at long lags): 1.23 over [250, 1000].
        let b = long_lag_exponent(&lags, &free);
        assert!(b > 1.0 && b < 1.3, "{b}");
        // Limits: v₀² t² for t ≪ τ_p, 4 (v₀² τ_p / 2) t for t ≫ τ_p.
        let v0 = 0.05 / XI;
        assert!((free_msd(0.05, 0.01) / (v0 * v0 * 1e-4) - 1.0).abs() < 1e-3);
        let long = 1e6;
        assert!((free_msd(0.05, long) / (2.0 * v0 * v0 / D_R * long) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn the_critical_propulsion_is_recovered_with_an_error() {
        let (a, runs) = synthetic(0.1, 0.01);
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
            let (a, runs) = synthetic(ac, 0.01);
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
        // Flat and resolved: an exponent of ¼ is excluded, so it does not hold.
        let flat = [(0.1, 0.02), (0.11, 0.02), (0.1, 0.02), (0.09, 0.02)];
        assert_eq!(
            verdict_deformability(&gammas, &flat).0,
            Verdict::DoesNotHold
        );
        // Flat within errors that allow ¼: inconclusive.
        let loose = [(0.1, 0.08), (0.11, 0.08), (0.1, 0.08), (0.09, 0.08)];
        assert_eq!(
            verdict_deformability(&gammas, &loose).0,
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
