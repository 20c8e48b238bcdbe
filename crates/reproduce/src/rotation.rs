//! `reproduce rotation`: collective rotation of polar cells confined to a disc (issue 41,
//! item 1; T1.4 of the extensions). Epithelial cells on small circular micropatterns rotate
//! persistently (Doxzen et al., Integr. Biol. 2013; Segerer et al., Phys. Rev. Lett. 2015),
//! and models with polarity aligned to the velocity or to the contact forces reproduce it.
//!
//! Each disc radius and density is a sweep of its own (the domain and the cell count follow
//! the radius), over the alignment rule (`velocity`, `force`), its rate `J` and the
//! propulsion `α`. The statistic of a frame is the angular order parameter
//! `Ω = ⟨(r_i × v_i)/(|r_i||v_i|)⟩` about the disc's centre (`rotation` of
//! `analysis/observables.csv`); of a run, its time mean `Ω̄` over the second half of the active
//! phase and the persistence of its sign (the share of those frames whose `Ω` has the sign of
//! `Ω̄`); of a point, the mean and standard error over seeds of `|Ω̄|` and the mean
//! persistence. [`classify`] says whether a point rotates.

use render::{Plot, Series};
use study::analyze::AnalyzeOptions;
use study::SweepError;

use super::pipeline::{cell, sci, Csv, Made};
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};

/// The disc scene: polar cells of radius 8 in a disc, the interaction pressure (docs/model.md
/// §11.4), no activity; the figure sets the disc's radius, the domain and the cell count.
pub const DISC_SCENE: &str = "\
[domain]
lx = 100
ly = 100

[cells]
count = 30
radius = 8.0

[model]
pressure = \"interaction\"
zeta = 0.0

[polarity]
alpha = 0.04
rotational_diffusion = 4.5e-4
align = \"velocity\"
align_rate = 1.0

[walls]
kind = \"disc\"
thickness = 1.0
kappa = 1.0

[integrator]
dt = 0.5

[run]
relax_time = 100.0
time = 3000.0
seed = 1
output_every = 20.0
series_every = 20.0
";

/// The cell radius of [`DISC_SCENE`].
const RADIUS: f64 = 8.0;

/// Mean `|Ω̄|` (less two standard errors) from which a point rotates.
pub(crate) const ROTATES: f64 = 0.5;

/// Mean persistence of the sign from which a point rotates.
pub(crate) const PERSISTENT: f64 = 0.9;

/// Mean `|Ω̄|` (plus two standard errors) below which a point does not rotate.
pub(crate) const STILL: f64 = 0.25;

/// The alignment rules and rates, the propulsions.
const RULES: [&str; 2] = ["velocity", "force"];
const RATES: [&str; 2] = ["0.1", "1"];
const ALPHAS: [&str; 2] = ["0.02", "0.04"];

/// The disc radii in cell radii, the area fractions `N R²/R_d²`, the active time.
fn settings(scale: Scale) -> (Vec<f64>, Vec<f64>, f64) {
    match scale {
        Scale::Quick => (vec![2.0, 3.0, 4.0, 6.0], vec![0.6, 0.85], 3000.0),
        Scale::Paper => (vec![2.0, 3.0, 4.0, 5.0, 6.0, 8.0], vec![0.6, 0.85], 6000.0),
    }
}

/// More seeds than the paper's figures: with 3, a change of the initial placements alone
/// moved the verdict on the disc's size between "inconclusive" and "does not hold".
fn seeds(scale: Scale) -> study::Seeds {
    scale.seeds_up_to(6, 10)
}

/// What a point does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum State {
    /// Persistent collective rotation.
    Rotates,
    /// No collective rotation.
    Still,
    /// The seeds do not decide.
    NotEstablished,
}

impl State {
    fn name(self) -> &'static str {
        match self {
            Self::Rotates => "rotates",
            Self::Still => "still",
            Self::NotEstablished => "not established",
        }
    }
}

/// A run's statistic from its frames' times and `Ω`: the mean `Ω̄` over the frames at or after
/// `from`, and the share of them whose `Ω` has the sign of `Ω̄`. NaN without such frames.
pub(crate) fn run_statistic(times: &[f64], omega: &[f64], from: f64) -> (f64, f64) {
    let w: Vec<f64> = times
        .iter()
        .zip(omega)
        .filter(|(t, o)| **t >= from && o.is_finite())
        .map(|(_, o)| *o)
        .collect();
    if w.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    let same = w.iter().filter(|o| o.signum() == mean.signum()).count();
    (mean, same as f64 / w.len() as f64)
}

/// A point's state from its seeds' `Ω̄` and persistences: [`State::Rotates`] when the mean of
/// `|Ω̄|` less two standard errors is at least [`ROTATES`] and the mean persistence at least
/// [`PERSISTENT`]; [`State::Still`] when the mean of `|Ω̄|` plus two standard errors is below
/// [`STILL`]; not established otherwise (and with fewer than two seeds).
pub(crate) fn classify(omega: &[f64], persistence: &[f64]) -> (State, (f64, f64), f64) {
    let abs: Vec<f64> = omega.iter().map(|o| o.abs()).collect();
    let (m, se) = mean_se(&abs);
    let p = mean_se(persistence).0;
    let state = if !se.is_finite() {
        State::NotEstablished
    } else if m - 2.0 * se >= ROTATES && p >= PERSISTENT {
        State::Rotates
    } else if m + 2.0 * se < STILL {
        State::Still
    } else {
        State::NotEstablished
    };
    (state, (m, se), p)
}

/// The claim that confined polar cells rotate: holds when some point rotates, does not hold
/// when every point is still, inconclusive otherwise.
pub(crate) fn verdict_rotates(states: &[State]) -> (Verdict, String) {
    let n = |s: State| states.iter().filter(|&&x| x == s).count();
    let (r, st, ne) = (n(State::Rotates), n(State::Still), n(State::NotEstablished));
    let counts = format!("{r} points rotate, {st} are still, {ne} not established");
    let verdicts = states.iter().map(|s| match s {
        State::Rotates => Verdict::Holds,
        State::Still => Verdict::DoesNotHold,
        State::NotEstablished => Verdict::Inconclusive,
    });
    (super::rules::any_holds(verdicts), counts)
}

/// The claim that coherent rotation is lost as the disc grows, from each combination of the
/// other parameters' states at the smallest and the largest radius: holds when one
/// combination rotates in the smallest disc and is still in the largest; does not hold when
/// every combination that rotates in the smallest disc (at least one) also rotates in the
/// largest; inconclusive otherwise.
pub(crate) fn verdict_size(pairs: &[(State, State)]) -> (Verdict, String) {
    let small: Vec<&(State, State)> = pairs.iter().filter(|p| p.0 == State::Rotates).collect();
    let lost = small.iter().filter(|p| p.1 == State::Still).count();
    let kept = small.iter().filter(|p| p.1 == State::Rotates).count();
    let counts = format!(
        "of {} combinations rotating in the smallest disc, {lost} are still and {kept} rotate in the largest",
        small.len()
    );
    if lost > 0 {
        (Verdict::Holds, counts)
    } else if !small.is_empty() && kept == small.len() {
        (Verdict::DoesNotHold, counts)
    } else {
        (Verdict::Inconclusive, counts)
    }
}

/// One point of the scan and what its seeds did.
#[derive(Clone)]
struct PointResult {
    radius: f64,
    density: f64,
    cells: usize,
    rule: String,
    rate: String,
    alpha: String,
    /// `(seed, Ω̄, persistence)`.
    runs: Vec<(u64, f64, f64)>,
    state: State,
    abs: (f64, f64),
    persistence: f64,
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let (radii, densities, t) = settings(p.scale);
    let from = RELAX + t / 2.0;
    let (points, series_of_scene) = run_points(p, &radii, &densities, t, from)?;
    p.reporter
        .stage("rotation: the null, the same discs with alignment off");
    let nulls = null_points(p, &radii, &densities, t, from)?;
    p.reporter.stage("rotation: tables and plots");
    let all: Vec<PointResult> = points.iter().chain(&nulls).cloned().collect();
    let (runs_csv, points_csv) = tables(&all);
    let mut made = Made::new(Vec::new(), String::new())
        .table("rotation_runs.csv", runs_csv)
        .table("rotation_points.csv", points_csv);
    for (name, plot) in plots(&points, &densities, &series_of_scene) {
        made = made.plot(name, plot);
    }
    made.claims = claims(&points, &nulls, &radii, &densities);
    p.reporter
        .stage("rotation: saturation, the largest disc run three times as long");
    let (claim, plot, csv) = saturation(p, &points, &radii, &densities, t)?;
    made.claims.push(claim);
    made = made
        .plot("rotation_saturation.png", plot)
        .table("rotation_saturation.csv", csv);
    made.settings = settings_text(p, &radii, &densities, t);
    Ok(made)
}

/// The relaxation before the activity (`relax_time` of [`DISC_SCENE`]).
const RELAX: f64 = 100.0;

/// An empty plot of Ω against time, titled `title`.
fn omega_in_time(title: String) -> Plot {
    Plot::new(title, "time (TU)", "Ω = ⟨(r × v)/(|r||v|)⟩")
}

/// How much longer the saturation runs are than the figure's.
const SATURATION_FACTOR: f64 = 3.0;

/// Saturation (issue 54): the largest disc at the scene's point (align to the velocity, J = 1,
/// α = 0.04), each density, run [`SATURATION_FACTOR`] times as long. Its `|Ω̄|` over the second
/// half of the long runs against the figure's (over the second half of `t`), seed by seed:
/// the rule of an absence on the difference, with [`STILL`] counting, for each density; the
/// claim holds when each does. The plot shows Ω(t) of every long run.
fn saturation(
    p: &ReproduceParams,
    points: &[PointResult],
    radii: &[f64],
    densities: &[f64],
    t: f64,
) -> Result<(Claim, Plot, Csv), SweepError> {
    let rk = *radii.last().expect("radii");
    let long = SATURATION_FACTOR * t;
    let mut plot = omega_in_time(format!(
        "Ω(t) of the largest disc (R_d = {rk}R), align = \"{}\", J = {}, α = {}, {long} TU",
        SCENE_POINT.0, SCENE_POINT.1, SCENE_POINT.2
    ));
    plot.hlines = vec![(0.0, String::new())];
    let mut csv = Csv::new(&[
        "area_fraction",
        "seed",
        "omega_mean_short",
        "omega_mean_long",
    ]);
    let mut per_density = Vec::new();
    for &dens in densities {
        let (mut sets, _) = disc(rk, dens, long, p.scale);
        sets.extend([
            format!("polarity.align=\"{}\"", SCENE_POINT.0),
            format!("polarity.align_rate={}", SCENE_POINT.1),
            format!("polarity.alpha={}", SCENE_POINT.2),
        ]);
        let res = super::sweep(
            p,
            SweepJob {
                name: format!("rotation-saturation-r{rk}-d{dens}-{}", p.scale.name()),
                scene: DISC_SCENE,
                sets,
                varies: Vec::new(),
                analyze: Some(AnalyzeOptions::default()),
                seeds: Some(seeds(p.scale)),
            },
        )?;
        let Some(short) = points.iter().find(|q| {
            q.radius == rk
                && q.density == dens
                && (q.rule.as_str(), q.rate.as_str(), q.alpha.as_str()) == SCENE_POINT
        }) else {
            continue;
        };
        let mut long_runs = Vec::new();
        for pt in res.points(None)? {
            let mut seen = |seed: u64, times: &[f64], omega: &[f64]| {
                plot.series.push(
                    Series::new(format!("area fraction {dens}, seed {seed}"))
                        .with_points(times, omega, &vec![0.0; times.len()])
                        .line_only(),
                );
            };
            long_runs.extend(statistics(&pt, RELAX + long / 2.0, &mut seen)?);
        }
        let mut pairs = Vec::new();
        for (seed, o_long, _) in &long_runs {
            if let Some((_, o_short, _)) = short.runs.iter().find(|r| r.0 == *seed) {
                csv.row([cell(dens), cell(seed), sci(*o_short), sci(*o_long)]);
                pairs.push((*seed, *o_short, *o_long));
            }
        }
        per_density.push((dens, short.abs, pairs));
    }
    let claim = saturation_claim(rk, t, &per_density);
    Ok((claim, plot, csv))
}

/// Each density's `(area fraction, |Ω̄| of the figure's runs (mean, s.e.), (seed, Ω̄ of the
/// figure's run, Ω̄ of the long run) paired by seed)`.
type Saturation = Vec<(f64, (f64, f64), Vec<(u64, f64, f64)>)>;

/// The saturation claim on the largest disc (`rk` radii) from the figure's runs of `t` TU and
/// the long runs: the rule of an absence on `|Ω̄|(long) − |Ω̄|(short)` paired by seed, with
/// [`STILL`] counting, for each density; holds when each does.
fn saturation_claim(rk: f64, t: f64, per_density: &Saturation) -> Claim {
    let long = SATURATION_FACTOR * t;
    let rule = super::rule::Rule::absence("|Ω̄|(long runs) − |Ω̄|(figure's runs)", STILL);
    let (mut outcomes, mut text) = (Vec::new(), Vec::new());
    for (dens, short_abs, pairs) in per_density {
        let diffs: Vec<f64> = pairs.iter().map(|p| p.2.abs() - p.1.abs()).collect();
        let (m, se) = mean_se(&diffs);
        let o = rule.decide(m, se);
        let abs_long = mean_se(&pairs.iter().map(|p| p.2.abs()).collect::<Vec<_>>());
        text.push(format!(
            "area fraction {dens}: |Ω̄| {} at {t} TU, {} at {long} TU",
            super::pm(*short_abs),
            super::pm(abs_long)
        ));
        outcomes.push(super::rule::Outcome {
            verdict: o.verdict,
            why: format!("area fraction {dens}: {}", o.why),
        });
    }
    let (v, why) = super::rules::all_of(&outcomes);
    Claim::new(
        format!("saturation (issue 54): the largest disc (R_d = {rk}R) has reached its lasting rotation within the figure's {t} TU (the same discs run {long} TU)"),
        text.join("; "),
        v,
        why,
    )
}

/// The points of `rotation_runs.csv` in `dir` (the figure's, then the nulls'), as
/// [`make`] had them.
#[cfg(test)]
fn points_from_table(dir: &std::path::Path) -> Result<Vec<PointResult>, SweepError> {
    let t = super::Table::read(&dir.join("rotation_runs.csv"))?;
    let c = |n: &str| t.col(n);
    let (rad, den, cells, rule, rate, alpha, seed) = (
        t.f64s("radius_over_r")?,
        t.f64s("area_fraction")?,
        c("cells")?,
        c("align")?,
        c("align_rate")?,
        c("alpha")?,
        c("seed")?,
    );
    let (om, per) = (t.f64s("omega_mean")?, t.f64s("persistence")?);
    type Key = (u64, u64, String, String, String, String);
    type Runs = Vec<(u64, f64, f64)>;
    let mut keys: Vec<(Key, usize, Runs)> = Vec::new();
    for (k, row) in t.rows.iter().enumerate() {
        let key: Key = (
            rad[k].to_bits(),
            den[k].to_bits(),
            row[rule].clone(),
            row[rate].clone(),
            row[alpha].clone(),
            row[cells].clone(),
        );
        let run = (row[seed].parse().unwrap_or(0), om[k], per[k]);
        match keys.iter_mut().find(|x| x.0 == key) {
            Some(x) => x.2.push(run),
            None => keys.push((key, k, vec![run])),
        }
    }
    Ok(keys
        .into_iter()
        .map(|((_, _, rule, rate, alpha, n), k, runs)| {
            PointResult::new(
                rad[k],
                den[k],
                n.parse().unwrap_or(0),
                &rule,
                &rate,
                &alpha,
                runs,
            )
        })
        .collect())
}

/// The claims of the figure's tables kept in `dir` (`rotation_runs.csv`,
/// `rotation_saturation.csv`) at `scale`, as [`make`] gives them.
#[cfg(test)]
fn verdicts_from_tables(
    dir: &std::path::Path,
    scale: Scale,
) -> Result<Vec<(String, Verdict)>, SweepError> {
    let (radii, densities, t) = settings(scale);
    let all = points_from_table(dir)?;
    let (nulls, points): (Vec<PointResult>, Vec<PointResult>) =
        all.into_iter().partition(|p| p.rule == NULL);
    let mut claims = claims(&points, &nulls, &radii, &densities);
    let rk = *radii.last().expect("radii");
    let sat = super::Table::read(&dir.join("rotation_saturation.csv"))?;
    let (dens, seed) = (sat.f64s("area_fraction")?, sat.col("seed")?);
    let (short, long) = (sat.f64s("omega_mean_short")?, sat.f64s("omega_mean_long")?);
    let mut per_density: Saturation = Vec::new();
    for &d in &densities {
        let Some(pt) = points.iter().find(|q| {
            q.radius == rk
                && q.density == d
                && (q.rule.as_str(), q.rate.as_str(), q.alpha.as_str()) == SCENE_POINT
        }) else {
            continue;
        };
        let pairs = (0..sat.rows.len())
            .filter(|&k| dens[k] == d)
            .map(|k| (sat.rows[k][seed].parse().unwrap_or(0), short[k], long[k]))
            .collect();
        per_density.push((d, pt.abs, pairs));
    }
    claims.push(saturation_claim(rk, t, &per_density));
    Ok(claims.into_iter().map(|c| (c.claim, c.verdict)).collect())
}

/// The rule name of the null points: alignment off.
const NULL: &str = "none";

/// The overrides of [`DISC_SCENE`] for a disc of `rk` cell radii at area fraction `dens`, run
/// for `t` TU at `scale` (the square domain's side is 2R_d + 2: the disc's default radius,
/// side/2 − 1, is R_d, as `scenes/disc.toml` writes it), and its cell count.
fn disc(rk: f64, dens: f64, t: f64, scale: Scale) -> (Vec<String>, usize) {
    let side = (2.0 * rk * RADIUS).round() as usize + 2;
    let cells = ((dens * rk * rk).round() as usize).max(1);
    let mut sets = vec![
        format!("domain.lx={side}"),
        format!("domain.ly={side}"),
        format!("cells.count={cells}"),
        format!("run.time={t}"),
    ];
    sets.extend(scale.own_dt_set());
    (sets, cells)
}

/// Told each run's seed, frame times and Ω(t).
type Seen<'a> = dyn FnMut(u64, &[f64], &[f64]) + 'a;

/// Each run's `(seed, Ω̄, persistence)` from `from` on; `seen` gets each run's Ω(t).
fn statistics(
    pt: &super::pipeline::PointRuns,
    from: f64,
    seen: &mut Seen,
) -> Result<Vec<(u64, f64, f64)>, SweepError> {
    let mut runs = Vec::new();
    for r in &pt.runs {
        let tab = super::Table::read(&r.run.join("analysis/observables.csv"))?;
        let (times, omega) = (tab.f64s("time")?, tab.f64s("rotation")?);
        let (o, per) = run_statistic(&times, &omega, from);
        runs.push((r.seed, o, per));
        seen(r.seed, &times, &omega);
    }
    Ok(runs)
}

impl PointResult {
    fn new(
        radius: f64,
        density: f64,
        cells: usize,
        rule: &str,
        rate: &str,
        alpha: &str,
        runs: Vec<(u64, f64, f64)>,
    ) -> Self {
        let (state, abs, persistence) = classify(
            &runs.iter().map(|r| r.1).collect::<Vec<_>>(),
            &runs.iter().map(|r| r.2).collect::<Vec<_>>(),
        );
        Self {
            radius,
            density,
            cells,
            rule: rule.into(),
            rate: rate.into(),
            alpha: alpha.into(),
            runs,
            state,
            abs,
            persistence,
        }
    }
}

/// Each Ω(t) of `scenes/disc.toml`'s point: the seed, the times and Ω.
type SceneSeries = Vec<(u64, Vec<f64>, Vec<f64>)>;

/// Every point of the sweeps (one per disc radius and density), with its runs' statistics
/// from `from` on, and Ω(t) of `scenes/disc.toml`'s point.
fn run_points(
    p: &ReproduceParams,
    radii: &[f64],
    densities: &[f64],
    t: f64,
    from: f64,
) -> Result<(Vec<PointResult>, SceneSeries), SweepError> {
    let mut points: Vec<PointResult> = Vec::new();
    let mut series_of_scene: SceneSeries = Vec::new();
    for &rk in radii {
        for &dens in densities {
            let (sets, cells) = disc(rk, dens, t, p.scale);
            let res = super::sweep(
                p,
                SweepJob {
                    name: format!("rotation-r{rk}-d{dens}-s2-{}", p.scale.name()),
                    scene: DISC_SCENE,
                    sets,
                    varies: vec![
                        format!(
                            "polarity.align={}",
                            RULES.map(|r| format!("\"{r}\"")).join(",")
                        ),
                        format!("polarity.align_rate={}", RATES.join(",")),
                        format!("polarity.alpha={}", ALPHAS.join(",")),
                    ],
                    analyze: Some(AnalyzeOptions::default()),
                    seeds: Some(seeds(p.scale)),
                },
            )?;
            // The points in the sweep's order: rule, then rate, then α.
            for pt in res.points(None)? {
                let (rule, rate, alpha) = (
                    pt.values[0].trim_matches('"'),
                    pt.values[1].as_str(),
                    pt.values[2].as_str(),
                );
                let scene_point = (rule, rate, alpha) == SCENE_POINT
                    && rk == SCENE_RADIUS
                    && dens == SCENE_DENSITY;
                let runs = statistics(&pt, from, &mut |seed, times, omega| {
                    if scene_point {
                        series_of_scene.push((seed, times.to_vec(), omega.to_vec()));
                    }
                })?;
                points.push(PointResult::new(rk, dens, cells, rule, rate, alpha, runs));
            }
        }
    }
    Ok((points, series_of_scene))
}

/// The null of each disc (issue 54): the same cells with alignment off (`align = "none"`), at
/// each α: what |Ω̄| N cells reach by chance.
fn null_points(
    p: &ReproduceParams,
    radii: &[f64],
    densities: &[f64],
    t: f64,
    from: f64,
) -> Result<Vec<PointResult>, SweepError> {
    let mut points: Vec<PointResult> = Vec::new();
    for &rk in radii {
        for &dens in densities {
            let (mut sets, cells) = disc(rk, dens, t, p.scale);
            sets.extend([
                "polarity.align=\"none\"".to_string(),
                "polarity.align_rate=0".to_string(),
            ]);
            let res = super::sweep(
                p,
                SweepJob {
                    name: format!("rotation-null-r{rk}-d{dens}-{}", p.scale.name()),
                    scene: DISC_SCENE,
                    sets,
                    varies: vec![format!("polarity.alpha={}", ALPHAS.join(","))],
                    analyze: Some(AnalyzeOptions::default()),
                    seeds: Some(seeds(p.scale)),
                },
            )?;
            for pt in res.points(None)? {
                let runs = statistics(&pt, from, &mut |_, _, _| {})?;
                points.push(PointResult::new(
                    rk,
                    dens,
                    cells,
                    NULL,
                    "–",
                    &pt.values[0],
                    runs,
                ));
            }
        }
    }
    Ok(points)
}

/// The runs' and the points' tables.
fn tables(points: &[PointResult]) -> (Csv, Csv) {
    let point_columns = [
        "radius_over_r",
        "area_fraction",
        "cells",
        "align",
        "align_rate",
        "alpha",
    ];
    let mut runs_csv =
        Csv::new(&[&point_columns[..], &["seed", "omega_mean", "persistence"]].concat());
    let mut points_csv = Csv::new(
        &[
            &point_columns[..],
            &["abs_omega_mean", "abs_omega_se", "persistence", "state"],
        ]
        .concat(),
    );
    for pt in points {
        let point = [
            cell(pt.radius),
            cell(pt.density),
            cell(pt.cells),
            cell(&pt.rule),
            cell(&pt.rate),
            cell(&pt.alpha),
        ];
        for (seed, o, per) in &pt.runs {
            runs_csv.row(
                point
                    .iter()
                    .cloned()
                    .chain([cell(seed), sci(*o), sci(*per)]),
            );
        }
        points_csv.row(point.into_iter().chain([
            sci(pt.abs.0),
            sci(pt.abs.1),
            sci(pt.persistence),
            cell(pt.state.name()),
        ]));
    }
    (runs_csv, points_csv)
}

/// |Ω̄| against the disc radius for each alignment rule, and Ω(t) of the scene's point.
fn plots(
    points: &[PointResult],
    densities: &[f64],
    series_of_scene: &SceneSeries,
) -> Vec<(String, Plot)> {
    let mut out = Vec::new();
    for rule in RULES {
        let mut plot = Plot::new(
            format!("Rotation in a disc, align = \"{rule}\""),
            "disc radius / cell radius",
            "|Ω̄| over the second half, mean ± s.e. over seeds",
        );
        plot.zero_y = true;
        plot.hlines = vec![
            (ROTATES, "rotates (less 2 s.e.)".into()),
            (STILL, "still (plus 2 s.e.)".into()),
        ];
        for rate in RATES {
            for alpha in ALPHAS {
                for &dens in densities {
                    let sel: Vec<&PointResult> = points
                        .iter()
                        .filter(|q| {
                            q.rule == rule
                                && q.rate == rate
                                && q.alpha == alpha
                                && q.density == dens
                        })
                        .collect();
                    let x: Vec<f64> = sel.iter().map(|q| q.radius).collect();
                    let y: Vec<f64> = sel.iter().map(|q| q.abs.0).collect();
                    let e: Vec<f64> = sel.iter().map(|q| q.abs.1).collect();
                    plot.series.push(
                        Series::new(format!("J = {rate}, α = {alpha}, area fraction {dens}"))
                            .with_points(&x, &y, &e),
                    );
                }
            }
        }
        out.push((format!("rotation_{rule}.png"), plot));
    }
    let mut tplot = omega_in_time(format!(
        "Ω(t) at R_d = {SCENE_RADIUS}R, area fraction {SCENE_DENSITY}, align = \"{}\", J = {}, α = {}",
        SCENE_POINT.0, SCENE_POINT.1, SCENE_POINT.2
    ));
    for (seed, times, omega) in series_of_scene {
        tplot.series.push(
            Series::new(format!("seed {seed}"))
                .with_points(times, omega, &vec![0.0; times.len()])
                .line_only(),
        );
    }
    if !series_of_scene.is_empty() {
        out.push(("rotation_in_time.png".to_string(), tplot));
    }

    out
}

/// The state of a point in the largest disc against its null (issue 54): the effect is how
/// far its `|Ω̄|` lies above that of the same disc and α with alignment off, and the smallest
/// that counts is [`STILL`]: rotating when that holds ([`Rule::effect`]), still when it does
/// not, not established otherwise.
pub(crate) fn against_null(point: (f64, f64), null: (f64, f64)) -> (State, String) {
    let rule = super::rule::Rule::effect("|Ω̄| − |Ω̄| with alignment off", STILL);
    let o = rule.decide(point.0 - null.0, point.1.hypot(null.1));
    let state = match o.verdict {
        Verdict::Holds => State::Rotates,
        Verdict::DoesNotHold => State::Still,
        _ => State::NotEstablished,
    };
    (state, o.why)
}

/// The claims: rotation at some point (a point that rotates must also lie above its null by
/// [`against_null`]), its loss with the disc's size (the largest disc against the null of the
/// same N), and the control: with alignment off, no point rotates.
fn claims(
    points: &[PointResult],
    nulls: &[PointResult],
    radii: &[f64],
    densities: &[f64],
) -> Vec<Claim> {
    // Each point's state beyond chance: a point that rotates must also lie above the null of
    // its disc and α (issue 54); one that does not is not established.
    let null_of = |q: &PointResult| {
        nulls
            .iter()
            .find(|n| n.radius == q.radius && n.density == q.density && n.alpha == q.alpha)
    };
    let beyond = |q: &PointResult| match (q.state, null_of(q)) {
        (State::Rotates, Some(n)) if against_null(q.abs, n.abs).0 == State::Rotates => {
            State::Rotates
        }
        (State::Rotates, _) => State::NotEstablished,
        (s, _) => s,
    };
    let states: Vec<State> = points.iter().map(beyond).collect();
    let best = points
        .iter()
        .filter(|q| beyond(q) == State::Rotates)
        .max_by(|a, b| a.abs.0.total_cmp(&b.abs.0));
    let (v1, why1) = verdict_rotates(&states);
    let (rmin, rmax) = (radii[0], *radii.last().expect("radii"));
    let mut pairs = Vec::new();
    let mut pair_text = Vec::new();
    for rule in RULES {
        for rate in RATES {
            for alpha in ALPHAS {
                for &dens in densities {
                    let at = |rk: f64| {
                        points.iter().find(|q| {
                            q.radius == rk
                                && q.rule == rule
                                && q.rate == rate
                                && q.alpha == alpha
                                && q.density == dens
                        })
                    };
                    let null = nulls
                        .iter()
                        .find(|q| q.radius == rmax && q.alpha == alpha && q.density == dens);
                    if let (Some(a), Some(b), Some(n)) = (at(rmin), at(rmax), null) {
                        let (large, _) = against_null(b.abs, n.abs);
                        let small = beyond(a);
                        pairs.push((small, large));
                        if small == State::Rotates {
                            pair_text.push(format!(
                                "{rule}, J = {rate}, α = {alpha}, {dens}: {} → {} ± {} against the null's {} ± {}: {}",
                                g(a.abs.0),
                                g(b.abs.0),
                                g(b.abs.1),
                                g(n.abs.0),
                                g(n.abs.1),
                                large.name()
                            ));
                        }
                    }
                }
            }
        }
    }
    let (v2, why2) = verdict_size(&pairs);
    let null_states: Vec<State> = nulls.iter().map(|q| q.state).collect();
    let (v3, why3) = verdict_rotates(&null_states);
    let null_text = nulls
        .iter()
        .map(|q| {
            format!(
                "R_d = {}R, {}, α = {}: {} ± {}",
                q.radius,
                q.density,
                q.alpha,
                g(q.abs.0),
                g(q.abs.1)
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    vec![
        Claim::new(
            "rotation (issue 41, T1.4 of the extensions): polar cells confined to a disc rotate collectively and persistently for some parameters (Doxzen et al. 2013; Segerer et al. 2015)",
            match best {
                Some(b) => format!(
                    "strongest: |Ω̄| = {} ± {}, persistence {} at R_d = {}R, area fraction {}, align = \"{}\", J = {}, α = {}",
                    g(b.abs.0), g(b.abs.1), g(b.persistence), b.radius, b.density, b.rule, b.rate, b.alpha
                ),
                None => "no point rotates".into(),
            },
            v1,
            why1,
        ),
        Claim::new(
            format!("rotation: coherent rotation is lost as the disc grows (from R_d = {rmin}R to {rmax}R, the largest against the null of the same N)"),
            if pair_text.is_empty() { "no combination rotates in the smallest disc".into() } else { pair_text.join("; ") },
            v2,
            why2,
        ),
        Claim::new(
            "Control (rotation): polar cells in a disc with alignment off rotate collectively (must not hold)",
            format!("|Ω̄|: {null_text}"),
            v3,
            why3,
        ),
    ]
}

/// The figure's settings, for its verdict.
fn settings_text(p: &ReproduceParams, radii: &[f64], densities: &[f64], t: f64) -> String {
    format!(
        "- Polar cells (R = 8, docs/model.md §11.1) in a disc of radius R_d ∈ {{{}}}·R (`[walls] kind = \"disc\"` at its default radius, in a square domain of side 2R_d + 2), at area fractions N R²/R_d² ∈ {{{}}}; alignment to the velocity or to the interface force, J ∈ {{{}}}, α ∈ {{{}}}, D_r = 4.5·10⁻⁴, ζ = 0, the interaction pressure; seeds {}.\n\
         - 100 TU of relaxation, then {t} TU; dt = {}; frames every 20 TU.\n\
         - Statistic: Ω = ⟨(r_i × v_i)/(|r_i||v_i|)⟩ about the disc's centre at each frame (`rotation` of `analysis/observables.csv`); a run's Ω̄ is its mean over the second half of the active phase, its persistence the share of those frames with the sign of Ω̄. A point rotates when the mean over seeds of |Ω̄| less two standard errors is at least {ROTATES} and the mean persistence at least {PERSISTENT}; it is still when the mean of |Ω̄| plus two standard errors is below {STILL}; otherwise not established. (Undirected motion of N cells gives Ω of spread about 1/√(2N) per frame, less in the time mean.)\n\
         - Claim 1 holds when a point rotates, does not hold when every point is still. Claim 2 holds when a combination rotating in the smallest disc is still in the largest, does not hold when every such combination also rotates in the largest.\n\
         - Null and control (issue 54): the same discs and α with alignment off (`align = \"none\"`, rule `none` in the tables): what |Ω̄| N cells reach by chance. \"Lost with size\" compares each combination in the largest disc with its null: |Ω̄| − |Ω̄|_null, by the rule of an effect with {STILL} the smallest that counts (rotating when it holds, still when it does not hold). The control, that the null points rotate, must not hold.\n\
         - Saturation (issue 54): the largest disc at `scenes/disc.toml`'s point, each area fraction, run {SATURATION_FACTOR}× as long; per seed, |Ω̄| over the second half of the long run less |Ω̄| of the figure's run; the mean difference by the rule of an absence with {STILL} counting, for each area fraction (`rotation_saturation.csv`, Ω(t) in `rotation_saturation.png`).\n\
         - Data: `rotation_runs.csv` (every run), `rotation_points.csv` (every point and its state); plots `rotation_velocity.png`, `rotation_force.png` (|Ω̄| against R_d), `rotation_in_time.png` (Ω(t) of each seed at R_d = {SCENE_RADIUS}R, area fraction {SCENE_DENSITY}, align = \"{}\", J = {}, α = {}: `scenes/disc.toml`'s settings).",
        radii.iter().map(|r| g(*r)).collect::<Vec<_>>().join(", "),
        densities.iter().map(|d| g(*d)).collect::<Vec<_>>().join(", "),
        RATES.join(", "),
        ALPHAS.join(", "),
        seeds(p.scale),
        p.scale.own_dt(),
        SCENE_POINT.0,
        SCENE_POINT.1,
        SCENE_POINT.2,
    )
}

/// The alignment rule, rate and propulsion of `scenes/disc.toml`, drawn in time.
const SCENE_POINT: (&str, &str, &str) = ("velocity", "1", "0.04");

/// The disc radius (in cell radii) and area fraction of `scenes/disc.toml`.
const SCENE_RADIUS: f64 = 4.0;
const SCENE_DENSITY: f64 = 0.85;

#[cfg(test)]
mod tests {
    use super::*;

    /// The rotation section of docs/reproduction.md states the verdicts of the figure's runs,
    /// kept in `docs/data/rotation/quick/` (`rotation_runs.csv`, `rotation_saturation.csv`).
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let dir = crate::stored_tables("rotation/quick");
        let want = verdicts_from_tables(&dir, Scale::Quick).unwrap();
        assert_eq!(want.len(), 4);
        crate::assert_doc_verdicts("rotation", "**Verdicts (quick):**", &want);
    }

    /// Against the null: well above it rotates, within it is still, a wide spread decides
    /// neither.
    #[test]
    fn a_large_disc_is_judged_against_its_null() {
        assert_eq!(against_null((0.8, 0.03), (0.1, 0.02)).0, State::Rotates);
        assert_eq!(against_null((0.15, 0.02), (0.1, 0.02)).0, State::Still);
        assert_eq!(
            against_null((0.4, 0.2), (0.1, 0.02)).0,
            State::NotEstablished
        );
    }

    #[test]
    fn a_run_is_its_time_mean_and_the_persistence_of_its_sign() {
        let times = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0];
        let omega = [0.9, 0.9, -0.2, 0.6, 0.8, f64::NAN];
        // From t = 20: −0.2, 0.6, 0.8 (the NaN left out): mean 0.4, two of three positive.
        let (m, p) = run_statistic(&times, &omega, 20.0);
        assert!((m - 0.4).abs() < 1e-12);
        assert!((p - 2.0 / 3.0).abs() < 1e-12);
        assert!(run_statistic(&times, &omega, 60.0).0.is_nan());
    }

    #[test]
    fn each_state_and_each_verdict_is_reached() {
        // Three seeds rotating either way, persistently: rotates (the sign does not count).
        let (s, ..) = classify(&[0.9, -0.85, 0.8], &[1.0, 1.0, 0.95]);
        assert_eq!(s, State::Rotates);
        // As strong but its sign flips: not persistent, not established.
        let (s, ..) = classify(&[0.9, -0.85, 0.8], &[0.6, 0.7, 0.8]);
        assert_eq!(s, State::NotEstablished);
        // Small means: still.
        let (s, ..) = classify(&[0.05, -0.02, 0.08], &[0.6, 0.5, 0.7]);
        assert_eq!(s, State::Still);
        // One seed rotates, two do not: the seeds do not decide.
        let (s, ..) = classify(&[0.9, 0.05, 0.1], &[1.0, 0.6, 0.6]);
        assert_eq!(s, State::NotEstablished);
        // One seed: no error, not established.
        assert_eq!(classify(&[0.95], &[1.0]).0, State::NotEstablished);

        use State::*;
        assert_eq!(verdict_rotates(&[Still, Rotates]).0, Verdict::Holds);
        assert_eq!(verdict_rotates(&[Still, Still]).0, Verdict::DoesNotHold);
        assert_eq!(
            verdict_rotates(&[Still, NotEstablished]).0,
            Verdict::Inconclusive
        );
        assert_eq!(verdict_rotates(&[]).0, Verdict::Inconclusive);

        assert_eq!(
            verdict_size(&[(Rotates, Rotates), (Rotates, Still)]).0,
            Verdict::Holds
        );
        assert_eq!(
            verdict_size(&[(Rotates, Rotates), (Still, Still)]).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            verdict_size(&[(Rotates, NotEstablished), (Rotates, Rotates)]).0,
            Verdict::Inconclusive
        );
        assert_eq!(verdict_size(&[(Still, Still)]).0, Verdict::Inconclusive);
    }
}
