//! `reproduce flocking`: the flocking transition of polar cells against their rotational
//! noise (issue 41, item 5). Self-propelled particles that align with their own velocity
//! order into a flock below a critical noise (Vicsek et al., Phys. Rev. Lett. 1995); so do
//! deformable polar cells aligning to their velocity (Löber, Ziebert & Aranson, Sci. Rep.
//! 2015; Zhang et al., arXiv:2005.13087, 2020).
//!
//! One sweep over the rotational diffusion `D_r` of `scenes/polar.toml`'s tissue. The statistic
//! of a run is the time mean of the polar order `|⟨p_i⟩|` (`polar_order` of
//! `analysis/observables.csv`) over the second half of the active phase; of a point, its mean
//! and standard error over seeds. The critical noise `D_c` is where the seed mean crosses ½
//! (linear in `ln D_r`), its error the jackknife over seeds.

use render::{Plot, Series};
use study::analyze::AnalyzeOptions;
use study::SweepError;

use super::pipeline::{cell, sci, Csv, Made};
use super::{g, mean_se, Claim, Rec, ReproduceParams, Scale, SweepJob, Verdict};

/// `scenes/polar.toml`'s tissue: 80 polar cells in a periodic 120² box, aligning with their
/// own velocity; the figure sets `D_r` and the run length.
pub const POLAR_SCENE: &str = "\
[domain]
lx = 120
ly = 120

[cells]
count = 80
radius = 8.0

[model]
zeta = 0.0

[polarity]
alpha = 0.04
rotational_diffusion = 4.5e-4
align = \"velocity\"
align_rate = 1.0

[integrator]
dt = 0.5

[run]
relax_time = 100.0
time = 3000.0
seed = 1
output_every = 20.0
series_every = 20.0
";

/// The cell count of [`POLAR_SCENE`].
const CELLS: f64 = 80.0;

/// The order parameter at the transition.
pub(crate) const HALF: f64 = 0.5;

/// The tissues of the finite-size study: `(cells, box side)` at the scene's density (80 cells
/// on 120²), the scene's first.
const SIZES: [(usize, usize); 3] = [(80, 120), (180, 180), (320, 240)];

/// The noises of the systematic runs (half the time step, a grid twice as fine): the quick
/// scale's grid around its D_c.
const SYSTEMATIC_NOISES: [&str; 4] = ["0.002", "0.004", "0.008", "0.016"];

/// A run's moments of the polar order over the frames of the second half of its active phase:
/// `(⟨m²⟩, ⟨m⁴⟩)`.
pub(crate) type Moments = (f64, f64);

/// The Binder cumulant of a two-component order parameter, `U = 1 − ⟨m⁴⟩/(2⟨m²⟩²)`, from
/// runs' moments (each run weighted alike): 0 for a Gaussian (disordered) vector order
/// parameter, ½ for a perfectly ordered one; a dip below 0 marks a discontinuous transition.
pub(crate) fn binder(moments: &[Moments]) -> f64 {
    let n = moments.len() as f64;
    let m2 = moments.iter().map(|m| m.0).sum::<f64>() / n;
    let m4 = moments.iter().map(|m| m.1).sum::<f64>() / n;
    1.0 - m4 / (2.0 * m2 * m2)
}

/// Where the Binder cumulants `small[k]` and `large[k]` of two sizes (at the increasing noises
/// `d[k]`) cross: the first sign change of `large − small` from positive (the larger tissue
/// more ordered) to negative, linear in `ln d`. `None` without such a change.
pub(crate) fn binder_crossing(d: &[f64], small: &[f64], large: &[f64]) -> Option<f64> {
    let diff: Vec<f64> = large.iter().zip(small).map(|(l, s)| l - s).collect();
    let k = (1..diff.len()).find(|&k| diff[k - 1] > 0.0 && diff[k] <= 0.0)?;
    let t = diff[k - 1] / (diff[k - 1] - diff[k]);
    Some((d[k - 1].ln() + t * (d[k].ln() - d[k - 1].ln())).exp())
}

/// The Binder crossing of two sizes from per-seed moments `small[seed][k]`, `large[seed][k]`,
/// and its jackknife error over the seeds both have (NaN with fewer than three, or where a
/// sample has no crossing).
pub(crate) fn binder_crossing_of(
    d: &[f64],
    small: &[Vec<Moments>],
    large: &[Vec<Moments>],
) -> (Option<f64>, f64) {
    let n = small.len().min(large.len());
    let curve = |m: &[Vec<Moments>], seeds: &[usize]| -> Vec<f64> {
        (0..d.len())
            .map(|k| binder(&seeds.iter().map(|&s| m[s][k]).collect::<Vec<_>>()))
            .collect()
    };
    let at = |seeds: &[usize]| binder_crossing(d, &curve(small, seeds), &curve(large, seeds));
    let all: Vec<usize> = (0..n).collect();
    let Some(c) = at(&all) else {
        return (None, f64::NAN);
    };
    let err = super::jackknife(n, |seeds| at(seeds).map(f64::ln));
    (Some(c), c * err)
}

/// The claim that the Binder cumulants of the three sizes cross at one noise (a continuous
/// transition at a D_c that does not move with the size): the two crossings (small–middle,
/// middle–large) by the rule of an absence on their difference relative to their mean, with
/// ¼ counting. Inconclusive where a pair does not cross.
pub(crate) fn binder_claim(crossings: &[(Option<f64>, f64)], lowest_u: f64) -> (Verdict, String) {
    let [(Some(a), ea), (Some(b), eb)] = crossings else {
        return (
            Verdict::Inconclusive,
            format!(
                "not established: a pair of sizes does not cross in the scanned noises (lowest cumulant {})",
                g(lowest_u)
            ),
        );
    };
    let mean = 0.5 * (a + b);
    let o = super::rule::Rule::absence(
        "(D_×(middle, large) − D_×(small, middle)) / their mean",
        0.25,
    )
    .decide((b - a) / mean, ea.hypot(*eb) / mean);
    (
        o.verdict,
        format!("{}; lowest cumulant {}", o.why, g(lowest_u)),
    )
}

fn settings(scale: Scale) -> (Vec<&'static str>, f64) {
    match scale {
        Scale::Quick => (
            vec![
                "0.0005", "0.001", "0.002", "0.004", "0.008", "0.016", "0.032", "0.064",
            ],
            3000.0,
        ),
        Scale::Paper => (
            vec![
                "0.0005", "0.001", "0.0014", "0.002", "0.0028", "0.004", "0.0057", "0.008",
                "0.016", "0.032", "0.064",
            ],
            6000.0,
        ),
    }
}

/// The noise where the order `order[k]` (at the increasing noises `d[k]`) first falls below
/// [`HALF`], linear in `ln d`; `None` when the first point is not above it or no point is
/// below it.
pub(crate) fn crossing(d: &[f64], order: &[f64]) -> Option<f64> {
    let first = *order.first()?;
    if first.is_nan() || first <= HALF {
        return None;
    }
    let k = order.iter().position(|&o| o < HALF)?;
    let (a, b) = (order[k - 1], order[k]);
    let t = (a - HALF) / (a - b);
    Some((d[k - 1].ln() + t * (d[k].ln() - d[k - 1].ln())).exp())
}

/// The critical noise from per-seed orders `order[seed][k]`, and its jackknife error (NaN
/// with fewer than three seeds or where a jackknife sample has no crossing).
pub(crate) fn critical_noise(d: &[f64], order: &[Vec<f64>]) -> (Option<f64>, f64) {
    let all: Vec<usize> = (0..order.len()).collect();
    let Some(dc) = crossing(d, &super::seed_mean(order, &all)) else {
        return (None, f64::NAN);
    };
    // The error of ln D_c, carried to D_c.
    let err = super::jackknife(order.len(), |seeds| {
        crossing(d, &super::seed_mean(order, seeds)).map(f64::ln)
    });
    (Some(dc), dc * err)
}

/// The verdict on "the cells flock below a critical noise and lose their order above it", from
/// the mean and standard error of the order at each noise and the critical noise, through the
/// rule of [`control`] (an effect: the order above ½, 0.05 counting) at each end of the scan:
/// holds when it holds at the lowest noise, does not hold at the highest, and `D_c` has an
/// error; does not hold when it does not hold even at the lowest noise (no flock at any noise
/// scanned); inconclusive otherwise.
pub(crate) fn verdict(stats: &[(f64, f64)], dc: Option<f64>, dc_err: f64) -> (Verdict, String) {
    let (Some(&lo), Some(&hi)) = (stats.first(), stats.last()) else {
        return (Verdict::Inconclusive, "no noise was run".into());
    };
    let (vl, wl) = control(lo);
    let (vh, wh) = control(hi);
    if vl == Verdict::DoesNotHold {
        return (
            Verdict::DoesNotHold,
            format!("even the lowest noise is disordered: {wl}"),
        );
    }
    match dc {
        Some(dc) if vl == Verdict::Holds && vh == Verdict::DoesNotHold && dc_err.is_finite() => (
            Verdict::Holds,
            format!(
                "ordered at the lowest noise ({wl}), disordered at the highest ({wh}); D_c = {} ± {}",
                g(dc),
                g(dc_err)
            ),
        ),
        _ => (
            Verdict::Inconclusive,
            format!(
                "the scan does not bracket a transition (lowest noise: {wl}; highest: {wh}), or D_c has no error (a jackknife sample without a crossing, or a systematic run without one)"
            ),
        ),
    }
}

/// The control (issue 54): the claim that the cells flock, at one noise alone, by the rule of an
/// effect ([`super::rule::Rule::effect`]) on the order above ½, of which 0.05 counts: holds
/// when the order less two standard errors is above ½ and the order at least 0.55; does not hold
/// when the order plus two standard errors is below 0.55. At a noise far above the transition,
/// where no flock can form, it must read "does not hold".
pub(crate) fn control(order: (f64, f64)) -> (Verdict, String) {
    let rule = super::rule::Rule::effect("the polar order above ½, |⟨p⟩| − ½", 0.05);
    let o = rule.decide(order.0 - HALF, order.1);
    (o.verdict, o.why)
}

/// The sweep over the noises `noises` of the polar tissue with the overrides `extra` (a size,
/// a time step, a grid), named `flocking{tag}-SCALE`.
fn noise_sweep(
    p: &ReproduceParams,
    tag: &str,
    t: f64,
    noises: &[&str],
    extra: Vec<String>,
) -> Result<super::SweepResult, SweepError> {
    let mut sets = vec![format!("run.time={t}")];
    sets.extend(p.scale.own_dt_set());
    sets.extend(extra);
    super::sweep(
        p,
        SweepJob {
            name: format!("flocking{tag}-{}", p.scale.name()),
            scene: POLAR_SCENE,
            sets,
            varies: vec![format!(
                "polarity.rotational_diffusion={}",
                noises.join(",")
            )],
            analyze: Some(AnalyzeOptions::default()),
            seeds: None,
        },
    )
}

/// A run's polar order over its frames from `from` on: its mean and its moments `⟨m²⟩`, `⟨m⁴⟩`
/// (NaN without such frames).
fn late_order(r: &Rec, from: f64) -> Result<(f64, f64, f64), SweepError> {
    let t = super::Table::read(&r.run.join("analysis/observables.csv"))?;
    let (times, m) = (t.f64s("time")?, t.f64s("polar_order")?);
    let late: Vec<f64> = times
        .iter()
        .zip(&m)
        .filter(|(t, v)| **t >= from && v.is_finite())
        .map(|(_, v)| *v)
        .collect();
    let n = late.len() as f64;
    Ok((
        late.iter().sum::<f64>() / n,
        late.iter().map(|v| v * v).sum::<f64>() / n,
        late.iter().map(|v| v.powi(4)).sum::<f64>() / n,
    ))
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let (noises, t) = settings(p.scale);
    let relax = 100.0;
    let from = relax + t / 2.0;
    let res = noise_sweep(p, "", t, &noises, Vec::new())?;
    let mut runs = runs_of(&res, "n80", from)?;
    // The finite-size study: the same noises on two larger tissues at the same density.
    for &(n, l) in &SIZES[1..] {
        let r = noise_sweep(
            p,
            &format!("-n{n}"),
            t,
            &noises,
            vec![
                format!("domain.lx={l}"),
                format!("domain.ly={l}"),
                format!("cells.count={n}"),
            ],
        )?;
        runs.extend(runs_of(&r, &format!("n{n}"), from)?);
    }
    // The systematics: half the time step and a grid twice as fine, on the first tissue, at
    // the noises around D_c.
    let base_sets: Vec<String> = std::iter::once(format!("run.time={t}"))
        .chain(p.scale.own_dt_set())
        .collect();
    let sub_noises: Vec<&str> = SYSTEMATIC_NOISES
        .iter()
        .copied()
        .filter(|n| noises.contains(n))
        .collect();
    let half = noise_sweep(
        p,
        "-dt-half",
        t,
        &sub_noises,
        vec![super::systematics::half_dt(POLAR_SCENE, &base_sets)?],
    )?;
    runs.extend(runs_of(&half, "dt_half", from)?);
    let finer = noise_sweep(
        p,
        "-grid-half",
        t,
        &sub_noises,
        super::systematics::finer_grid(POLAR_SCENE, &base_sets)?,
    )?;
    runs.extend(runs_of(&finer, "grid_half", from)?);
    p.reporter.stage("flocking: tables and plots");
    let points = res.points(None)?;
    let tplot = order_in_time(&points)?;
    let mut made = analyse(&runs)?;
    made.settings = settings_text(p, &noises, t);
    Ok(made
        .table("flocking_runs.csv", runs_table(&runs))
        .plot("flocking_in_time.png", tplot))
}

/// One run of the figure: its tissue or variant (`n80`, `n180`, `n320`, `dt_half`,
/// `grid_half`), noise, seed, and its polar order over the second half of its active phase:
/// the time mean and the moments `⟨m²⟩`, `⟨m⁴⟩`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FlockRun {
    pub variant: String,
    pub noise: String,
    pub seed: u64,
    pub order: f64,
    pub m2: f64,
    pub m4: f64,
}

/// The runs of a sweep, tagged `variant`, from `from` on.
fn runs_of(
    res: &super::SweepResult,
    variant: &str,
    from: f64,
) -> Result<Vec<FlockRun>, SweepError> {
    let mut out = Vec::new();
    for pt in res.points(None)? {
        for r in &pt.runs {
            let (order, m2, m4) = late_order(r, from)?;
            out.push(FlockRun {
                variant: variant.into(),
                noise: pt.values[0].clone(),
                seed: r.seed,
                order,
                m2,
                m4,
            });
        }
    }
    Ok(out)
}

/// `flocking_runs.csv`: every run, the figure's raw data.
fn runs_table(runs: &[FlockRun]) -> Csv {
    let mut csv = Csv::new(&[
        "variant",
        "rotational_diffusion",
        "seed",
        "polar_order_mean",
        "m2",
        "m4",
    ]);
    for r in runs {
        csv.row(
            [cell(&r.variant), cell(&r.noise), cell(r.seed)]
                .into_iter()
                .chain([r.order, r.m2, r.m4].map(sci)),
        );
    }
    csv
}

/// The runs of `flocking_runs.csv` in `dir`.
#[cfg(test)]
pub(crate) fn runs_from_table(dir: &std::path::Path) -> Result<Vec<FlockRun>, SweepError> {
    let t = super::Table::read(&dir.join("flocking_runs.csv"))?;
    let (v, n, s) = (
        t.col("variant")?,
        t.col("rotational_diffusion")?,
        t.col("seed")?,
    );
    let (o, m2, m4) = (t.f64s("polar_order_mean")?, t.f64s("m2")?, t.f64s("m4")?);
    Ok(t.rows
        .iter()
        .enumerate()
        .map(|(k, row)| FlockRun {
            variant: row[v].clone(),
            noise: row[n].clone(),
            seed: row[s].parse().unwrap_or(0),
            order: o[k],
            m2: m2[k],
            m4: m4[k],
        })
        .collect())
}

/// A variant's noises (in the order of its runs) and its values `f` as `[seed][noise]` over
/// the seeds every noise has.
fn grid_of<V: Copy>(
    runs: &[FlockRun],
    variant: &str,
    f: impl Fn(&FlockRun) -> V,
) -> (Vec<String>, Vec<Vec<V>>) {
    let mine: Vec<&FlockRun> = runs.iter().filter(|r| r.variant == variant).collect();
    let mut noises: Vec<String> = Vec::new();
    let mut seeds: Vec<u64> = Vec::new();
    for r in &mine {
        if !noises.contains(&r.noise) {
            noises.push(r.noise.clone());
        }
        if !seeds.contains(&r.seed) {
            seeds.push(r.seed);
        }
    }
    let rows = seeds
        .iter()
        .filter_map(|&s| {
            noises
                .iter()
                .map(|n| {
                    mine.iter()
                        .find(|r| r.seed == s && &r.noise == n)
                        .map(|r| f(r))
                })
                .collect::<Option<Vec<V>>>()
        })
        .collect();
    (noises, rows)
}

/// The figure's claims, tables and plots (but the runs' table and Ω(t)) from its runs.
fn analyse(runs: &[FlockRun]) -> Result<Made, SweepError> {
    let (names, order) = grid_of(runs, "n80", |r| r.order);
    if names.is_empty() {
        return Err(SweepError::Reproduce {
            why: "the flocking figure has no runs of its first tissue".into(),
        });
    }
    let noises: Vec<&str> = names.iter().map(String::as_str).collect();
    let d: Vec<f64> = noises
        .iter()
        .map(|v| v.parse().unwrap_or(f64::NAN))
        .collect();
    let stats: Vec<(f64, f64)> = (0..d.len())
        .map(|k| mean_se(&order.iter().map(|row| row[k]).collect::<Vec<_>>()))
        .collect();
    let (dc, dc_stat) = critical_noise(&d, &order);
    let mut sizes_moments = Vec::new();
    let mut sizes_order = Vec::new();
    for (n, _) in SIZES {
        let tag = format!("n{n}");
        sizes_moments.push(grid_of(runs, &tag, |r| (r.m2, r.m4)).1);
        sizes_order.push(grid_of(runs, &tag, |r| r.order).1);
    }
    let crossings: Vec<(Option<f64>, f64)> = sizes_moments
        .windows(2)
        .map(|w| binder_crossing_of(&d, &w[0], &w[1]))
        .collect();
    let sub: Vec<usize> = SYSTEMATIC_NOISES
        .iter()
        .filter_map(|n| noises.iter().position(|m| m == n))
        .collect();
    let sub_d: Vec<f64> = sub.iter().map(|&k| d[k]).collect();
    let sub_noises: Vec<&str> = sub.iter().map(|&k| noises[k]).collect();
    let at_sub = |o: &[Vec<f64>]| -> Option<f64> {
        let all: Vec<usize> = (0..o.len()).collect();
        crossing(&sub_d, &super::seed_mean(o, &all))
    };
    let base_sub: Vec<Vec<f64>> = order
        .iter()
        .map(|row| sub.iter().map(|&k| row[k]).collect())
        .collect();
    let (half_order, finer_order) = (
        grid_of(runs, "dt_half", |r| r.order).1,
        grid_of(runs, "grid_half", |r| r.order).1,
    );
    let shift = |o: &[Vec<f64>]| match (at_sub(o), at_sub(&base_sub)) {
        (Some(a), Some(b)) => a - b,
        _ => f64::NAN,
    };
    let sys = super::systematics::Systematics {
        value: dc.unwrap_or(f64::NAN),
        stat: dc_stat,
        dt: shift(&half_order),
        grid: shift(&finer_order),
    };
    let dc_err = sys.total();
    let null = (std::f64::consts::PI / (4.0 * CELLS)).sqrt();
    let mut points_csv = Csv::new(&["rotational_diffusion", "polar_order_mean", "polar_order_se"]);
    for (v, s) in noises.iter().zip(&stats) {
        points_csv.row([cell(v), sci(s.0), sci(s.1)]);
    }
    let mut plot = Plot::new(
        "Flocking against rotational noise",
        "rotational diffusion D_r (1/TU)",
        "polar order |⟨p⟩|, second half, mean ± s.e. over seeds",
    );
    plot.log_x = true;
    plot.zero_y = true;
    plot.legend = render::LegendAt::UpperRight;
    plot.hlines = vec![
        (HALF, "½: the transition".into()),
        (null, "random orientations √(π/4N)".into()),
    ];
    plot.series.push(
        Series::new("80 cells, align to velocity, J = 1, α = 0.04").with_points(
            &d,
            &stats.iter().map(|s| s.0).collect::<Vec<_>>(),
            &stats.iter().map(|s| s.1).collect::<Vec<_>>(),
        ),
    );
    let (v, why) = verdict(&stats, dc, dc_err);
    // The alignment rate of a cell at its free speed, J α/ξ (ξ = 2).
    let align_rate = 1.0 * 0.04 / 2.0;
    let claims = vec![Claim::new(
        "flocking (issue 41): polar cells aligning with their velocity flock below a critical rotational noise and lose their order above it (Vicsek et al. 1995; Löber et al. 2015)",
        match dc {
            Some(dc) => format!(
                "D_c = {}, between the scanned D_r = {} and {}; D_c/(J α/ξ) = {}; order {} at D_r = {} and {} at {} (random orientations: {})",
                sys.describe(),
                g(d.iter().copied().filter(|&x| x < dc).fold(f64::NAN, f64::max)),
                g(d.iter().copied().filter(|&x| x > dc).fold(f64::NAN, f64::min)),
                g(dc / align_rate),
                super::pm(stats[0]),
                noises[0],
                super::pm(*stats.last().expect("noises")),
                noises.last().expect("noises"),
                g(null)
            ),
            None => format!(
                "no crossing of ½; order {} at D_r = {} and {} at {}",
                super::pm(stats[0]),
                noises[0],
                super::pm(*stats.last().expect("noises")),
                noises.last().expect("noises")
            ),
        },
        v,
        why,
    )];
    let mut claims = claims;
    if let (Some(&top), Some(name)) = (stats.last(), noises.last()) {
        let (cv, cwhy) = control(top);
        let times = dc.map_or(String::new(), |dc| {
            format!(", {}× D_c", g(d[d.len() - 1] / dc))
        });
        claims.push(Claim::new(
            format!("control (issue 54): the cells flock at D_r = {name}{times}, noise far above the transition, where no flock can form (must not hold)"),
            format!("order {} (random orientations: {})", super::pm(top), g(null)),
            cv,
            cwhy,
        ));
    }
    // The Binder cumulants of the sizes, and each size's D_c by the order ½.
    let curves: Vec<Vec<f64>> = sizes_moments
        .iter()
        .map(|m| {
            (0..d.len())
                .map(|k| binder(&m.iter().map(|s| s[k]).collect::<Vec<_>>()))
                .collect()
        })
        .collect();
    let lowest_u = curves
        .iter()
        .flatten()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let (bv, bwhy) = binder_claim(&crossings, lowest_u);
    let size_dc: Vec<(Option<f64>, f64)> =
        sizes_order.iter().map(|o| critical_noise(&d, o)).collect();
    let describe = |c: &(Option<f64>, f64)| match c.0 {
        Some(v) => format!("{} ± {}", g(v), g(c.1)),
        None => "none".into(),
    };
    claims.push(Claim::new(
        "flocking (issue 54): the transition is continuous, at one D_c for every size: the Binder cumulants U = 1 − ⟨m⁴⟩/(2⟨m²⟩²) of 80, 180 and 320 cells cross at one noise",
        format!(
            "Binder crossings 80–180: {}, 180–320: {} (jackknife); D_c by the order ½: {}",
            describe(&crossings[0]),
            describe(&crossings[1]),
            SIZES
                .iter()
                .zip(&size_dc)
                .map(|((n, _), c)| format!("{n} cells {}", describe(c)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        bv,
        bwhy,
    ));
    let mut sizes_csv = Csv::new(&[
        "cells",
        "box",
        "rotational_diffusion",
        "polar_order_mean",
        "polar_order_se",
        "binder",
    ]);
    let mut bplot = Plot::new(
        "Binder cumulant against rotational noise, three sizes",
        "rotational diffusion D_r (1/TU)",
        "U = 1 − ⟨m⁴⟩/(2⟨m²⟩²), over frames and seeds",
    );
    bplot.log_x = true;
    bplot.legend = render::LegendAt::UpperRight;
    bplot.hlines = vec![
        (0.0, "disordered (Gaussian)".into()),
        (0.5, "ordered".into()),
    ];
    for (((n, l), o), u) in SIZES.iter().zip(&sizes_order).zip(&curves) {
        for (k, v) in noises.iter().enumerate() {
            let st = mean_se(&o.iter().map(|row| row[k]).collect::<Vec<_>>());
            sizes_csv.row([cell(n), cell(l), cell(v), sci(st.0), sci(st.1), sci(u[k])]);
        }
        bplot
            .series
            .push(Series::new(format!("{n} cells, {l}²")).with_points(&d, u, &vec![0.0; d.len()]));
    }
    let mut sys_csv = Csv::new(&[
        "variant",
        "rotational_diffusion",
        "polar_order_mean",
        "polar_order_se",
    ]);
    for (name, o) in [
        ("base", &base_sub),
        ("dt_half", &half_order),
        ("grid_half", &finer_order),
    ] {
        for (k, v) in sub_noises.iter().enumerate() {
            let st = mean_se(&o.iter().map(|row| row[k]).collect::<Vec<_>>());
            sys_csv.row([cell(name), cell(v), sci(st.0), sci(st.1)]);
        }
    }
    Ok(Made::new(claims, String::new())
        .table("flocking.csv", points_csv)
        .table("flocking_sizes.csv", sizes_csv)
        .table("flocking_systematics.csv", sys_csv)
        .plot("flocking_binder.png", bplot)
        .plot("flocking.png", plot))
}

/// The figure's settings, for its verdict: the noises `noises` run for `t` TU.
fn settings_text(p: &ReproduceParams, noises: &[&str], t: f64) -> String {
    // The alignment rate of a cell at its free speed, J α/ξ (ξ = 2).
    let align_rate = 1.0 * 0.04 / 2.0;
    let null = (std::f64::consts::PI / (4.0 * CELLS)).sqrt();
    format!(
        "- `scenes/polar.toml`'s tissue: 80 polar cells (R = 8) in a periodic 120² box, ζ = 0, α = 0.04, alignment to the velocity at J = 1 (a free cell's alignment rate J α/ξ = {}), D_r ∈ {{{}}}; seeds {}.\n\
         - 100 TU of relaxation, then {t} TU; dt = {}; frames every 20 TU.\n\
         - Statistic: the polar order |⟨p_i⟩| of each frame (`polar_order` of `analysis/observables.csv`), its time mean over the second half of the active phase per run, mean ± standard error over seeds. D_c: where the seed mean first falls below ½, linear in ln D_r; error: jackknife over seeds (the interpolation's own error is not in it: the scanned noises that bracket D_c are given beside it). Random orientations give √(π/4N) = {}.\n\
         - Rule: the rule of an effect on the order above ½ (0.05 counting, two standard errors) at each end of the scan: holds when it holds at the lowest noise and does not at the highest, and D_c has an error; does not hold when it does not hold even at the lowest noise; inconclusive otherwise.\n\
         - Control (issue 54): the claim that the cells flock, at the highest noise alone, by the rule of an effect on the order above ½; far above the transition it must read \"does not hold\".\n\
         - Systematics (issue 54): the same tissue at half the time step and on a grid twice as fine (every length doubled in nodes, `crates/reproduce/src/systematics.rs`), at D_r ∈ {{{sys}}}; each shifts D_c (found on those four noises, against the base runs on the same four) and the shifts add to the jackknife error in quadrature. The main rule takes that total error.\n\
         - Sizes (issue 54): the same noises for {sizes} at the same density. Binder cumulant U = 1 − ⟨m⁴⟩/(2⟨m²⟩²) of the polar order m over the frames of the second half, pooled over seeds (0 disordered, ½ ordered, a dip below 0 marks a discontinuous transition); each pair of sizes crosses where the larger tissue stops being the more ordered, linear in ln D_r, error by jackknife over seeds. Rule: the two crossings agree (the rule of an absence on their difference over their mean, ¼ counting); inconclusive where a pair does not cross.\n\
         - Data: `flocking_runs.csv`, `flocking.csv`, `flocking_sizes.csv`, `flocking_systematics.csv`; plots `flocking.png`, `flocking_in_time.png`, `flocking_binder.png`.",
        g(align_rate),
        noises.join(", "),
        p.scale.seeds(),
        p.scale.own_dt(),
        g(null),
        sys = SYSTEMATIC_NOISES.join(", "),
        sizes = SIZES
            .iter()
            .map(|(n, l)| format!("{n} cells on {l}²"))
            .collect::<Vec<_>>()
            .join(", "),
    )
}

/// The polar order in time of each noise's first run (the first seed's).
fn order_in_time(points: &[super::pipeline::PointRuns]) -> Result<Plot, SweepError> {
    let first_seed = points
        .first()
        .and_then(|pt| pt.runs.first())
        .map_or(1, |r| r.seed);
    let mut tplot = Plot::new(
        format!("Polar order in time, seed {first_seed}"),
        "time (TU)",
        "|⟨p⟩|",
    );
    tplot.zero_y = true;
    tplot.legend = render::LegendAt::UpperRight;
    for pt in points {
        let Some(r) = pt.runs.first() else { continue };
        let tab = super::Table::read(&r.run.join("analysis/observables.csv"))?;
        let (times, pol) = (tab.f64s("time")?, tab.f64s("polar_order")?);
        tplot.series.push(
            Series::new(format!("D_r = {}", pt.values[0]))
                .with_points(&times, &pol, &vec![0.0; times.len()])
                .line_only(),
        );
    }
    Ok(tplot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mean_se;

    /// A synthetic order `1/(1 + (D/D_c)²)` per seed, with a seed's scatter of `D_c`.
    fn synthetic(dc: f64, scatter: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
        let d: Vec<f64> = (0..8).map(|k| 5e-4 * 2f64.powi(k)).collect();
        let order = (0..4)
            .map(|s| {
                let c = dc * (1.0 + scatter * (s as f64 - 1.5));
                d.iter().map(|x| 1.0 / (1.0 + (x / c).powi(2))).collect()
            })
            .collect();
        (d, order)
    }

    fn stats(order: &[Vec<f64>]) -> Vec<(f64, f64)> {
        (0..order[0].len())
            .map(|k| mean_se(&order.iter().map(|o| o[k]).collect::<Vec<_>>()))
            .collect()
    }

    /// The control reads each outcome: a disordered point does not hold, an ordered one holds
    /// (so the control can fail), one that straddles ½ is inconclusive.
    #[test]
    fn the_control_can_come_out_either_way() {
        assert_eq!(control((0.12, 0.02)).0, Verdict::DoesNotHold);
        assert_eq!(control((0.9, 0.02)).0, Verdict::Holds);
        assert_eq!(control((0.5, 0.1)).0, Verdict::Inconclusive);
    }

    /// The Binder cumulant is ½ for a perfect order and 0 for a Gaussian vector order
    /// parameter (`⟨m⁴⟩ = 2⟨m²⟩²`); the crossing of two sizes is where the larger stops being
    /// the more ordered; the claim reads each outcome.
    #[test]
    fn binder_cumulants_cross_and_the_claim_reads_each_outcome() {
        assert_eq!(binder(&[(1.0, 1.0), (1.0, 1.0)]), 0.5);
        assert!(binder(&[(0.02, 8e-4), (0.02, 8e-4)]).abs() < 1e-12);
        // U_L(D) = ½ / (1 + (D/D_c)^(L)): sharper for the larger L, all through ¼ at D_c.
        let d: Vec<f64> = (0..8).map(|k| 5e-4 * 2f64.powi(k)).collect();
        let curve =
            |l: i32| -> Vec<f64> { d.iter().map(|x| 0.5 / (1.0 + (x / 4e-3).powi(l))).collect() };
        let c = binder_crossing(&d, &curve(2), &curve(4)).unwrap();
        assert!((c / 4e-3 - 1.0).abs() < 1e-9, "{c}");
        // No crossing when the larger is everywhere less ordered.
        assert_eq!(binder_crossing(&d, &curve(4), &curve(2)), None);
        let same = [(Some(4e-3), 0.2e-3), (Some(4.2e-3), 0.2e-3)];
        assert_eq!(binder_claim(&same, 0.01).0, Verdict::Holds);
        let apart = [(Some(2e-3), 0.1e-3), (Some(6e-3), 0.2e-3)];
        assert_eq!(binder_claim(&apart, 0.01).0, Verdict::DoesNotHold);
        let loose = [(Some(4e-3), 2e-3), (Some(5e-3), 2e-3)];
        assert_eq!(binder_claim(&loose, 0.01).0, Verdict::Inconclusive);
        let open = [(None, f64::NAN), (Some(5e-3), 2e-4)];
        assert!(binder_claim(&open, -0.1).1.starts_with("not established"));
    }

    /// The flocking section of docs/reproduction.md states the verdicts that the figure's own
    /// runs give, kept in `docs/data/flocking/quick/flocking_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let runs = runs_from_table(&crate::stored_tables("flocking/quick")).unwrap();
        let want: Vec<(String, Verdict)> = analyse(&runs)
            .unwrap()
            .claims
            .into_iter()
            .map(|c| (c.claim, c.verdict))
            .collect();
        assert_eq!(want.len(), 3);
        crate::assert_doc_verdicts("flocking", "**Verdicts (quick):**", &want);
    }

    #[test]
    fn the_crossing_is_interpolated_in_ln_d() {
        let d = [1.0, 4.0];
        // From 0.75 to 0.25: half-way in ln d, at 2.
        assert!((crossing(&d, &[0.75, 0.25]).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(crossing(&d, &[0.4, 0.2]), None);
        assert_eq!(crossing(&d, &[0.9, 0.8]), None);
    }

    #[test]
    fn each_outcome_is_reached() {
        // A transition at D_c = 4e-3 inside the scan: holds, D_c found within its error.
        let (d, order) = synthetic(4e-3, 0.05);
        let (dc, err) = critical_noise(&d, &order);
        let (v, why) = verdict(&stats(&order), dc, err);
        assert_eq!(v, Verdict::Holds, "{why}");
        let dc = dc.unwrap();
        assert!((dc / 4e-3 - 1.0).abs() < 0.1, "{dc}");
        assert!(err > 0.0 && err < 0.5 * dc, "{err}");
        // The transition below the scan: even the lowest noise is disordered.
        let (d, order) = synthetic(5e-5, 0.05);
        let (dc, err) = critical_noise(&d, &order);
        assert_eq!(verdict(&stats(&order), dc, err).0, Verdict::DoesNotHold);
        // The transition above the scan: all ordered, nothing bracketed.
        let (d, order) = synthetic(1.0, 0.05);
        let (dc, err) = critical_noise(&d, &order);
        assert_eq!(dc, None);
        assert_eq!(verdict(&stats(&order), dc, err).0, Verdict::Inconclusive);
        // Seeds that scatter widely at the lowest noise: not decided.
        let mut order = synthetic(4e-3, 0.05).1;
        for (s, o) in order.iter_mut().enumerate() {
            o[0] = if s % 2 == 0 { 0.95 } else { 0.1 };
        }
        let (dc, err) = critical_noise(&d, &order);
        assert_eq!(verdict(&stats(&order), dc, err).0, Verdict::Inconclusive);
    }
}
