//! `reproduce channel`: the flow transition of an active tissue in a channel (issue 28, T3.4
//! of the extensions; redone in issue 41). Continuum active nematics confined to a channel are
//! quiescent below a critical width `W_c ∝ √(K/ζ)` and flow spontaneously above it, with a net
//! flow along the channel (Voituriez, Joanny & Prost, Europhys. Lett. 2005; in cell
//! monolayers, Duclos et al., Nat. Phys. 2018); here `W_c` is measured against ζ and its
//! exponent compared with −½.
//!
//! Each width is a sweep of its own (the cell count follows the width, at the paper's
//! density), over ζ = 0 and four activities, from W = 24 (three cell radii: narrower channels
//! clip an R = 8 cell's patch). The order parameter vanishes at rest: the net flow along the
//! channel, `Φ = ⟨|v̄_x|⟩`, the time mean over the second half of the active phase of the
//! magnitude of the lattice mean of `v_x` (`v_mean_x` of `analysis/observables.csv`). A run's
//! statistic is its coherence `C = Φ / v_rms`: 1 for a plug flow, about `1/√(πN)` for N cells
//! moving in random directions. `W_c` is the narrowest width at which the seed mean of C
//! reaches [`FLOWS`] (half the flow is net flow along the channel), interpolated linearly from
//! the width below: a fixed level, so `W_c` does not depend on the widest width. The exponent
//! is the least-squares slope of `ln W_c` against `ln ζ`, its error from the jackknife over
//! seeds.

use render::{Plot, Series};

use super::pipeline::{cell, sci, Csv, Made, PerSeed};
use super::rule::Rule;
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};
use study::SweepError;

/// The activities; ζ = 0 is the baseline.
const ZETAS: [&str; 5] = ["0", "0.001", "0.0025", "0.005", "0.01"];

/// The coherence `Φ/v_rms` from which a channel flows along itself: half the flow is net
/// flow.
pub(crate) const FLOWS: f64 = 0.5;

/// The wall frictions ξ_w (`[walls] friction`): free walls, and walls that hold the cells
/// touching them (a cell pressed on a wall of thickness 1 overlaps it by a few nodes, so
/// ξ_w = 1 about doubles its friction).
const FRICTIONS: [&str; 2] = ["0", "1"];

/// The polar control's widths (the narrowest first: its claim) and run length.
const POLAR_WIDTHS: [usize; 2] = [24, 48];
const POLAR_TIME: f64 = 2000.0;

/// The continuum exponent of `W_c ∝ ζ^b`.
pub(crate) const CONTINUUM: f64 = -0.5;

/// Nodes per cell: the paper's density (60 cells on 100²).
const AREA_PER_CELL: f64 = 10_000.0 / 60.0;

fn widths(scale: Scale) -> Vec<usize> {
    match scale {
        Scale::Quick => vec![24, 32, 40, 48, 64, 96],
        Scale::Paper => vec![24, 28, 32, 40, 48, 64, 96, 128],
    }
}

/// Where the flow sets in, from the mean ratios at the increasing widths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Onset {
    /// The narrowest width at which the ratio reaches [`FLOWS`], interpolated from the width
    /// below.
    At(f64),
    /// Already at the narrowest width: no quiescent channel in the range.
    Narrower,
    /// At no width.
    Wider,
}

/// The critical width from the mean ratios `ratio[k]` at the increasing widths `widths`: the
/// narrowest width with `ratio ≥ FLOWS`, linear between it and the width below.
pub(crate) fn critical_width(widths: &[f64], ratio: &[f64]) -> Onset {
    match ratio.iter().position(|&r| r >= FLOWS) {
        None => Onset::Wider,
        Some(0) => Onset::Narrower,
        Some(k) => {
            let t = (FLOWS - ratio[k - 1]) / (ratio[k] - ratio[k - 1]);
            Onset::At(widths[k - 1] + t * (widths[k] - widths[k - 1]))
        }
    }
}

/// The least-squares slope of `y` against `x`.
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// The exponent `b` of `W_c ∝ ζ^b` from per-seed ratios `ratio[seed][zeta][width]`, and its
/// jackknife error over seeds, with the onsets of the seed means. NaN exponent when fewer than
/// two activities have an onset inside the widths.
pub(crate) fn exponent(
    widths: &[f64],
    zetas: &[f64],
    ratio: &[Vec<Vec<f64>>],
) -> (f64, f64, Vec<Onset>) {
    let fit = |seeds: &[usize]| -> (f64, Vec<Onset>) {
        let wc: Vec<Onset> = (0..zetas.len())
            .map(|z| {
                let mean: Vec<f64> = (0..widths.len())
                    .map(|w| {
                        seeds.iter().map(|&s| ratio[s][z][w]).sum::<f64>() / seeds.len() as f64
                    })
                    .collect();
                critical_width(widths, &mean)
            })
            .collect();
        let (x, y): (Vec<f64>, Vec<f64>) = zetas
            .iter()
            .zip(&wc)
            .filter_map(|(z, w)| match w {
                Onset::At(w) => Some((z.ln(), w.ln())),
                _ => None,
            })
            .unzip();
        (
            if x.len() >= 2 {
                slope(&x, &y)
            } else {
                f64::NAN
            },
            wc,
        )
    };
    let all: Vec<usize> = (0..ratio.len()).collect();
    let (b, wc) = fit(&all);
    if !b.is_finite() {
        return (b, f64::NAN, wc);
    }
    let err = super::jackknife(ratio.len(), |seeds| {
        let b = fit(seeds).0;
        b.is_finite().then_some(b)
    });
    (b, err, wc)
}

/// The verdict on `W_c ∝ ζ^{−1/2}` from the exponent `b ± se` and the onsets, by
/// [`exponent_rule`] (inconclusive when the exponent or its error could not be measured);
/// "not testable" (inconclusive) when no
/// activity flows coherently at any width, or every one that does already flows at the
/// narrowest width, so that no channel that resolves a cell is quiescent.
pub(crate) fn verdict(b: f64, se: f64, onsets: &[Onset]) -> (Verdict, String) {
    if !onsets.is_empty() && onsets.iter().all(|o| *o == Onset::Wider) {
        return (
            Verdict::Inconclusive,
            format!("not testable in this model: no activity has a coherent shear flow across the channel (Σ/v_rms ≥ {FLOWS}) at any width: the active flow in a channel is undirected, so there is no onset of spontaneous flow to scale"),
        );
    }
    let flowing: Vec<&Onset> = onsets.iter().filter(|o| **o != Onset::Wider).collect();
    if !flowing.is_empty() && flowing.iter().all(|o| **o == Onset::Narrower) {
        return (
            Verdict::Inconclusive,
            "not testable in this model: every activity that flows already flows at the narrowest width that resolves a cell, so there is no quiescent channel to find the onset from".into(),
        );
    }
    if !(b.is_finite() && se.is_finite()) {
        return (
            Verdict::Inconclusive,
            "the onset lies inside the widths at fewer than two activities (or in fewer than three seeds' jackknife samples)".into(),
        );
    }
    let o = exponent_rule().decide(b - CONTINUUM, se);
    (o.verdict, o.why)
}

/// The rule on the exponent: its distance from −½, with ¼ counting (an absence: the law holds
/// when the exponent is resolved within ¼ of −½, and does not when it is resolved at least ¼
/// from it).
fn exponent_rule() -> Rule {
    Rule::absence("exponent b − (−½)", 0.25)
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 600.0,
        Scale::Paper => 1500.0,
    };
    let lx = 200usize;
    let ws = widths(p.scale);
    // Each width's points (ζ, ξ_w), each with its runs' net flow, shear and v_rms by seed.
    let mut flows: Vec<(usize, Vec<Flow>)> = Vec::new();
    for &w in &ws {
        let res = width_sweep(p, lx, w, t)?;
        let by_point = res
            .points(None)?
            .iter()
            .map(|pt| Flow::of(pt, 200.0 + t / 2.0))
            .collect::<Result<_, SweepError>>()?;
        flows.push((w, by_point));
    }
    let polar = polar_control(p, lx)?;
    p.reporter.stage("channel: tables and plots");
    let mut made =
        analyse(&flows, &polar, lx)?.table("channel_runs.csv", runs_table(&flows, &polar));
    made.settings = settings(p.scale, lx, t, &ws);
    Ok(made)
}

/// `channel_runs.csv`: every run's late flows, the figure's raw data.
fn runs_table(flows: &[(usize, Vec<Flow>)], polar: &[(usize, Flow)]) -> Csv {
    let mut csv = Csv::new(&[
        "kind",
        "width",
        "zeta",
        "wall_friction",
        "seed",
        "net_flow",
        "shear",
        "v_rms",
    ]);
    let nematic = flows
        .iter()
        .flat_map(|(w, f)| f.iter().map(move |f| ("nematic", *w, f)));
    let polar = polar.iter().map(|(w, f)| ("polar", *w, f));
    for (kind, w, f) in nematic.chain(polar) {
        for (k, seed) in f.net.seeds.iter().enumerate() {
            csv.row(
                [
                    cell(kind),
                    cell(w),
                    cell(&f.zeta),
                    cell(&f.friction),
                    cell(seed),
                ]
                .into_iter()
                .chain([f.net.values[k], f.shear.values[k], f.v_rms.values[k]].map(sci)),
            );
        }
    }
    csv
}

/// The flows of `channel_runs.csv` in `dir`, as [`make`] had them: the nematic tissue's by
/// width and point, and the polar control's by width.
#[cfg(test)]
type Flows = (Vec<(usize, Vec<Flow>)>, Vec<(usize, Flow)>);

#[cfg(test)]
fn flows_from_table(dir: &std::path::Path) -> Result<Flows, SweepError> {
    let t = super::Table::read(&dir.join("channel_runs.csv"))?;
    let (kind, width, zeta, fr, seed) = (
        t.col("kind")?,
        t.col("width")?,
        t.col("zeta")?,
        t.col("wall_friction")?,
        t.col("seed")?,
    );
    let (net, shear, v) = (t.f64s("net_flow")?, t.f64s("shear")?, t.f64s("v_rms")?);
    let mut nematic: Vec<(usize, Vec<Flow>)> = Vec::new();
    let mut polar: Vec<(usize, Flow)> = Vec::new();
    for (k, row) in t.rows.iter().enumerate() {
        let w: usize = row[width].parse().map_err(|_| SweepError::Reproduce {
            why: format!("{}: row {}: width {}", t.path.display(), k + 1, row[width]),
        })?;
        let s: u64 = row[seed].parse().unwrap_or(0);
        let flow = if row[kind] == "polar" {
            if !polar.iter().any(|p| p.0 == w) {
                polar.push((w, Flow::empty(&row[zeta], &row[fr])));
            }
            &mut polar.iter_mut().find(|p| p.0 == w).expect("pushed").1
        } else {
            if !nematic.iter().any(|p| p.0 == w) {
                nematic.push((w, Vec::new()));
            }
            let list = &mut nematic.iter_mut().find(|p| p.0 == w).expect("pushed").1;
            if !list
                .iter()
                .any(|f| f.zeta == row[zeta] && f.friction == row[fr])
            {
                list.push(Flow::empty(&row[zeta], &row[fr]));
            }
            list.iter_mut()
                .find(|f| f.zeta == row[zeta] && f.friction == row[fr])
                .expect("pushed")
        };
        for (per, x) in [
            (&mut flow.net, net[k]),
            (&mut flow.shear, shear[k]),
            (&mut flow.v_rms, v[k]),
        ] {
            per.seeds.push(s);
            per.values.push(x);
        }
    }
    Ok((nematic, polar))
}

/// The claims of the figure's tables kept in `dir` (`channel_runs.csv`).
#[cfg(test)]
pub(crate) fn verdicts_from_tables(
    dir: &std::path::Path,
) -> Result<Vec<(String, Verdict)>, SweepError> {
    let (flows, polar) = flows_from_table(dir)?;
    Ok(analyse(&flows, &polar, 200)?
        .claims
        .into_iter()
        .map(|c| (c.claim, c.verdict))
        .collect())
}

/// The tables, plots and claims of the flows: the nematic tissue's `flows` by width (each
/// point a ζ and a wall friction) and the polar control's, in channels `lx` long.
fn analyse(
    flows: &[(usize, Vec<Flow>)],
    polar: &[(usize, Flow)],
    lx: usize,
) -> Result<Made, SweepError> {
    let ws: Vec<usize> = flows.iter().map(|f| f.0).collect();
    let zetas: Vec<f64> = ZETAS[1..]
        .iter()
        .map(|z| z.parse().expect("a number"))
        .collect();
    let flow = |w: usize, z: &str, f: &str| -> Result<&Flow, SweepError> {
        flows
            .iter()
            .find(|(ww, _)| *ww == w)
            .and_then(|(_, fl)| fl.iter().find(|x| x.zeta == z && x.friction == f))
            .ok_or_else(|| SweepError::Reproduce {
                why: format!("the channel sweep of width {w} has no ζ = {z}, ξ_w = {f}"),
            })
    };
    let n_seeds = flows[0].1[0].net.values.len();
    let wf: Vec<f64> = ws.iter().map(|&w| w as f64).collect();

    let mut csv = Csv::new(&[
        "width",
        "zeta",
        "wall_friction",
        "net_flow",
        "net_flow_se",
        "net_coherence",
        "net_coherence_se",
        "shear",
        "shear_se",
        "shear_coherence",
        "shear_coherence_se",
        "v_rms",
        "v_rms_se",
    ]);
    let mut claims = Vec::new();
    let mut plots = Vec::new();
    // The largest seed mean of the net coherence over every active point, with its error.
    let mut largest_net: (f64, f64, String) = (f64::NEG_INFINITY, f64::NAN, String::new());
    for fr in FRICTIONS {
        // shear[seed][zeta][width]: the shear coherence Σ/v_rms.
        let mut shear = vec![vec![vec![f64::NAN; ws.len()]; ZETAS.len() - 1]; n_seeds];
        let mut plot = Plot::new(
            format!("Shear across a channel against its width, wall friction ξ_w = {fr}"),
            "channel width W (nodes)",
            "C_s = Σ / v_rms, mean ± s.e. over seeds",
        );
        plot.log_y = true;
        plot.hlines = vec![(FLOWS, "shear flow: half the flow is shear across".into())];
        for (zi, z) in ZETAS.iter().enumerate() {
            let (mut ys, mut es) = (Vec::new(), Vec::new());
            for (wi, &w) in ws.iter().enumerate() {
                let f = flow(w, z, fr)?;
                let (cn, cs) = (f.net_coherence(), f.shear_coherence());
                if zi > 0 {
                    for (s, c) in cs.iter().enumerate() {
                        shear[s][zi - 1][wi] = *c;
                    }
                    let m = mean_se(&cn);
                    if m.0 > largest_net.0 {
                        largest_net = (m.0, m.1, format!("W = {w}, ζ = {z}, ξ_w = {fr}"));
                    }
                }
                let (v, sh, u) = (f.net.mean_se(), f.shear.mean_se(), f.v_rms.mean_se());
                let (rn, rs) = (mean_se(&cn), mean_se(&cs));
                csv.row(
                    [w.to_string(), cell(z), cell(fr)]
                        .into_iter()
                        .chain([v.0, v.1, rn.0, rn.1, sh.0, sh.1, rs.0, rs.1, u.0, u.1].map(sci)),
                );
                ys.push(rs.0);
                es.push(if rs.1.is_finite() { rs.1 } else { 0.0 });
            }
            plot.series
                .push(Series::new(format!("ζ = {z}")).with_points(&wf, &ys, &es));
        }
        // N cells moving in random directions: E|v̄_x| = v/√(πN), and about as much shear.
        let random: Vec<f64> = ws
            .iter()
            .map(|&w| {
                let n = (lx * w) as f64 / AREA_PER_CELL;
                1.0 / (std::f64::consts::PI * n).sqrt()
            })
            .collect();
        plot.series.push(
            Series::new("cells in random directions, 1/√(πN)")
                .with_points(&wf, &random, &vec![0.0; wf.len()])
                .line_only(),
        );
        let (b, se, wc) = exponent(&wf, &zetas, &shear);
        let tag = if fr == "0" { "" } else { "_friction" };
        if let Some(wplot) = critical_width_plot(&zetas, &wc) {
            plots.push((format!("channel_critical_width{tag}.png"), wplot));
        }
        plots.push((format!("channel_shear{tag}.png"), plot));
        claims.push(claim(b, se, &wc, ws[0], fr));
    }
    claims.push(no_net_flow(largest_net));
    claims.push(polar_claim(polar));
    let mut pcsv = Csv::new(&[
        "width",
        "net_coherence",
        "net_coherence_se",
        "shear_coherence",
        "shear_coherence_se",
        "v_rms",
    ]);
    for (w, f) in polar {
        let (rn, rs) = (mean_se(&f.net_coherence()), mean_se(&f.shear_coherence()));
        pcsv.row(
            [w.to_string()]
                .into_iter()
                .chain([rn.0, rn.1, rs.0, rs.1, f.v_rms.mean_se().0].map(sci)),
        );
    }
    let mut made = Made::new(Vec::new(), String::new())
        .table("channel_flow.csv", csv)
        .table("channel_polar.csv", pcsv);
    for (name, plot) in plots {
        made = made.plot(&name, plot);
    }
    made.claims = claims;
    Ok(made)
}

/// The polar control: cells that propel themselves and align with their velocity (α = 0.04,
/// rate 1), without activity, in the channels of [`POLAR_WIDTHS`], for [`POLAR_TIME`] TU.
fn polar_control(p: &ReproduceParams, lx: usize) -> Result<Vec<(usize, Flow)>, SweepError> {
    let t = POLAR_TIME;
    let mut out = Vec::new();
    for w in POLAR_WIDTHS {
        let polar = [
            "polarity.alpha=0.04",
            "polarity.align=\"velocity\"",
            "polarity.align_rate=1",
        ];
        let sets = channel_sets(p, lx, w, t, &polar, 12);
        let res = super::sweep(
            p,
            SweepJob {
                scene: super::PAPER_SCENE,
                name: format!("channel-polar-w{w}-{}", p.scale.name()),
                sets,
                varies: vec!["model.zeta=0".into()],
                analyze: Some(study::analyze::AnalyzeOptions::default()),
                seeds: None,
            },
        )?;
        let pts = res.points(None)?;
        let pt = pts.first().ok_or_else(|| SweepError::Reproduce {
            why: format!("the polar control of width {w} has no runs"),
        })?;
        out.push((w, Flow::of(pt, 200.0 + t / 2.0)?));
    }
    Ok(out)
}

/// The active nematic's net flow along the channel: the claim (Duclos et al.) that it stays
/// small, by the rule of an absence with [`FLOWS`] counting, on the largest seed mean of the
/// net coherence over every width, activity and wall friction.
fn no_net_flow((c, se, at): (f64, f64, String)) -> Claim {
    let o = Rule::absence("largest net coherence C = Φ/v_rms", FLOWS).decide(c, se);
    Claim::new(
        "channel: an active nematic tissue has no net flow along a channel (its flow is undirected or a shear, Duclos et al. 2018)",
        format!("largest seed mean of C = Φ/v_rms: {} ± {} ({at})", g(c), g(se)),
        o.verdict,
        o.why,
    )
}

/// The polar control at the narrowest width: polar cells must flow along the channel, by
/// the rule of an effect with [`FLOWS`] counting.
fn polar_claim(polar: &[(usize, Flow)]) -> Claim {
    let (w, f) = &polar[0];
    let (c, se) = mean_se(&f.net_coherence());
    let o = Rule::effect("net coherence C = Φ/v_rms", FLOWS).decide(c, se);
    let others: Vec<String> = polar[1..]
        .iter()
        .map(|(w, f)| {
            let (c, se) = mean_se(&f.net_coherence());
            format!("W = {w}: {} ± {}", g(c), g(se))
        })
        .collect();
    Claim::new(
        format!("channel, control: polar cells (α = 0.04, aligning with their velocity, ζ = 0) flow along a channel of width {w}: the net-flow measure sees a directed flow"),
        format!(
            "C = Φ/v_rms at W = {w}: {} ± {}{}",
            g(c),
            g(se),
            if others.is_empty() { String::new() } else { format!(" ({})", others.join("; ")) }
        ),
        o.verdict,
        o.why,
    )
}

/// The overrides of [`super::PAPER_SCENE`] for a channel `lx` long of free width `w` (ly = w + 2)
/// at the paper's density, the interaction pressure, `extra` settings, runs of `t` TU with
/// frames every 10 TU, the scale's integrator and a margin of at most `margin` (and of
/// (ly − 1)/2, so that the patch fits).
fn channel_sets(
    p: &ReproduceParams,
    lx: usize,
    w: usize,
    t: f64,
    extra: &[&str],
    margin: usize,
) -> Vec<String> {
    let ly = w + 2;
    let count = ((lx * w) as f64 / AREA_PER_CELL).round() as usize;
    let mut sets = vec![
        format!("domain.lx={lx}"),
        format!("domain.ly={ly}"),
        format!("cells.count={count}"),
        "walls.kind=\"channel\"".to_string(),
        "model.pressure=\"interaction\"".to_string(),
    ];
    sets.extend(extra.iter().map(|s| s.to_string()));
    sets.extend([format!("run.time={t}"), "run.output_every=10".to_string()]);
    sets.extend(p.scale.integrator());
    sets.push(format!("integrator.margin={}", margin.min((ly - 1) / 2)));
    sets
}

/// The sweep over ζ of the channel of width `w` (and length `lx`), runs of `t` TU.
fn width_sweep(
    p: &ReproduceParams,
    lx: usize,
    w: usize,
    t: f64,
) -> Result<super::SweepResult, SweepError> {
    let margin: usize = match p.scale {
        Scale::Quick => 16,
        Scale::Paper => 12,
    };
    let sets = channel_sets(p, lx, w, t, &[], margin);
    super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("channel-w{w}-{}", p.scale.name()),
            sets,
            varies: vec![
                format!("model.zeta={}", ZETAS.join(",")),
                format!("walls.friction={}", FRICTIONS.join(",")),
            ],
            analyze: Some(study::analyze::AnalyzeOptions::default()),
            seeds: None,
        },
    )
}

/// The plot of the critical width against ζ, with the continuum's slope through the first
/// point: `None` when no activity has an onset inside the widths.
fn critical_width_plot(zetas: &[f64], wc: &[Onset]) -> Option<Plot> {
    let (x, y): (Vec<f64>, Vec<f64>) = zetas
        .iter()
        .zip(wc)
        .filter_map(|(z, w)| match w {
            Onset::At(w) => Some((*z, *w)),
            _ => None,
        })
        .unzip();
    let mut wplot = Plot::new("Critical width against activity", "ζ", "W_c (nodes)");
    (wplot.log_x, wplot.log_y) = (true, true);
    // Drawn only when an activity has an onset inside the widths.
    if x.is_empty() {
        return None;
    }
    {
        wplot.series.push(
            Series::new("W_c (seed means)")
                .with_points(&x, &y, &vec![0.0; x.len()])
                .markers_only(),
        );
        let c = y[0] * x[0].powf(-CONTINUUM);
        let line: Vec<f64> = x.iter().map(|z| c * z.powf(CONTINUUM)).collect();
        wplot.series.push(
            Series::new("∝ ζ^(−1/2)")
                .with_points(&x, &line, &vec![0.0; x.len()])
                .line_only(),
        );
    }
    Some(wplot)
}

/// The claim on `W_c ∝ ζ^{−1/2}` from the exponent `b ± se`, the onsets `wc` of the activities
/// (of the shear coherence), the narrowest width and the wall friction.
fn claim(b: f64, se: f64, wc: &[Onset], narrowest: usize, friction: &str) -> Claim {
    let (v, reason) = verdict(b, se, wc);
    let wc_text: Vec<String> = ZETAS[1..]
        .iter()
        .zip(wc)
        .map(|(z, w)| {
            format!(
                "ζ = {z}: {}",
                match w {
                    Onset::At(w) => g(*w),
                    Onset::Narrower => format!("flows at W = {narrowest}"),
                    Onset::Wider => "no shear flow".into(),
                }
            )
        })
        .collect();
    Claim::new(
        format!("channel (extensions T3.4), wall friction ξ_w = {friction}: the critical width of the spontaneous shear flow scales as W_c ∝ ζ^(−1/2)"),
        format!(
            "W_c: {}; exponent b = {} ± {} (jackknife over seeds)",
            wc_text.join(", "),
            g(b),
            g(se)
        ),
        v,
        reason,
    )
}

/// The figure's settings, as `verdict.md` states them: channels `lx` long of the widths `ws`,
/// runs of `t` TU at `scale`.
fn settings(scale: Scale, lx: usize, t: f64, ws: &[usize]) -> String {
    format!(
        "- A channel along x: `[walls] kind = \"channel\"`, lx = {lx}, free width W ∈ {{{}}} (ly = W + 2), the paper's density (a cell per {:.1} nodes), the paper's parameters with the interaction pressure (docs/model.md §11.4: in the paper's form the walls' push dominates v_rms); ζ ∈ {{{}}}; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; integrator {} (margin at most (ly − 1)/2); f32 storage; frames every 10 TU, analysed. The narrowest width is 24 nodes (3R): narrower channels clip an R = 8 cell's patch.\n\
         - Wall friction ξ_w ∈ {{{fr}}} (`[walls] friction`, docs/model.md §11.4: a cell moves at F_i/(ξ + ξ_w Σ_x φ_i w)), each over every width and ζ.\n\
         - Order parameters, zero at rest, from `analysis/observables.csv`, each the time mean over the second half of the active phase of a magnitude: the net flow along the channel Φ = ⟨|v̄_x|⟩ (`v_mean_x`, the lattice mean of v_x) and the shear across it Σ = ⟨|v_shear_x|⟩ (half the difference of the mean v_x above and below the middle line: the antisymmetric part of the profile v_x(y), Duclos et al.'s shear flow). Statistics: the coherences C = Φ/v_rms and C_s = Σ/v_rms of each run (1 for a plug flow or a pure shear; about 1/√(πN) for N cells in random directions).\n\
         - W_c: the narrowest width at which the seed mean of C_s reaches {FLOWS}, linear from the width below (a fixed level: it does not depend on the widest width). Exponent: least-squares slope of ln W_c against ln ζ; error: jackknife over seeds. Rule: not testable when no activity has a shear flow at any width, or every one that has already at the narrowest; otherwise the exponent's distance from −½, by the rule of an absence with ¼ counting (2 s.e.).\n\
         - No net flow: the largest seed mean of C over every active point, by the rule of an absence with {FLOWS} counting. Control: polar cells (ζ = 0, α = 0.04, aligning with their velocity at rate 1) in channels W ∈ {{{pw}}}, {POLAR_TIME} TU; the net flow at W = {pw0} must be present (rule of an effect, {FLOWS} counting). Data in `channel_flow.csv` (Φ, Σ, C, C_s, v_rms by width, ζ and ξ_w) and `channel_polar.csv`; plots `channel_shear.png`, `channel_shear_friction.png` and, when an onset is found, `channel_critical_width*.png`.",
        ws.iter().map(|w| w.to_string()).collect::<Vec<_>>().join(", "),
        AREA_PER_CELL,
        ZETAS.join(", "),
        scale.seeds(),
        scale.integrator_name(),
        fr = FRICTIONS.join(", "),
        pw = POLAR_WIDTHS.map(|w| w.to_string()).join(", "),
        pw0 = POLAR_WIDTHS[0],
    )
}

/// One point (activity and wall friction) of one width: its runs' net flow `Φ`, shear `Σ`
/// and `v_rms`, by seed.
struct Flow {
    zeta: String,
    friction: String,
    net: PerSeed,
    shear: PerSeed,
    v_rms: PerSeed,
}

impl Flow {
    /// A point with no runs yet.
    #[cfg(test)]
    fn empty(zeta: &str, friction: &str) -> Self {
        let none = || PerSeed {
            seeds: Vec::new(),
            values: Vec::new(),
        };
        Flow {
            zeta: zeta.into(),
            friction: friction.into(),
            net: none(),
            shear: none(),
            v_rms: none(),
        }
    }

    /// The point's flows, from each run's `analysis/observables.csv` from `from` on.
    fn of(pt: &super::pipeline::PointRuns, from: f64) -> Result<Self, SweepError> {
        // Each run's net flow and shear, from one reading of its observables.
        let flows: Vec<Vec<f64>> = pt
            .runs
            .iter()
            .map(|r| {
                super::late_means(
                    &r.run.join("analysis/observables.csv"),
                    &["v_mean_x", "v_shear_x"],
                    from,
                    f64::abs,
                )
            })
            .collect::<Result<_, _>>()?;
        let column = |k: usize| PerSeed {
            seeds: pt.runs.iter().map(|r| r.seed).collect(),
            values: flows.iter().map(|f| f[k]).collect(),
        };
        Ok(Flow {
            zeta: pt.values[0].clone(),
            friction: pt.values.get(1).cloned().unwrap_or_else(|| "0".into()),
            net: column(0),
            shear: column(1),
            v_rms: pt.measure(|r| Ok(r.summary.v_rms))?,
        })
    }

    /// The coherence `Φ/v_rms` of each seed's run.
    fn net_coherence(&self) -> Vec<f64> {
        ratio(&self.net, &self.v_rms)
    }

    /// The shear coherence `Σ/v_rms` of each seed's run.
    fn shear_coherence(&self) -> Vec<f64> {
        ratio(&self.shear, &self.v_rms)
    }
}

fn ratio(a: &PerSeed, b: &PerSeed) -> Vec<f64> {
    a.values.iter().zip(&b.values).map(|(v, u)| v / u).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic coherences `0.05 + 0.9 W⁴/(W⁴ + W_c⁴)` with `W_c = c ζ^b` and a seed's
    /// scatter: the onset (C = ½) is at `W_c`.
    fn synthetic(b: f64, scatter: f64, c: f64) -> (Verdict, f64, f64) {
        let widths: [f64; 9] = [24.0, 28.0, 32.0, 40.0, 48.0, 64.0, 96.0, 128.0, 192.0];
        let zetas: [f64; 3] = [0.0025, 0.005, 0.01];
        let ratio: Vec<Vec<Vec<f64>>> = (0..4)
            .map(|s| {
                zetas
                    .iter()
                    .enumerate()
                    .map(|(zi, &z)| {
                        // A scatter that differs between seeds and activities.
                        let k = ((7 * s + 3 * zi) % 5) as f64 - 2.0;
                        let wc = c * z.powf(b) * (1.0 + scatter * k / 2.0);
                        widths
                            .iter()
                            .map(|&w| 0.05 + 0.9 * w.powi(4) / (w.powi(4) + wc.powi(4)))
                            .collect()
                    })
                    .collect()
            })
            .collect();
        let (e, se, onsets) = exponent(&widths, &zetas, &ratio);
        (verdict(e, se, &onsets).0, e, se)
    }

    #[test]
    fn the_rule_reaches_each_verdict() {
        // W_c = 80 at ζ = 0.005 with the continuum exponent: holds.
        let c = 80.0 / 0.005f64.powf(-0.5);
        let (v, b, se) = synthetic(-0.5, 0.04, c);
        assert_eq!(v, Verdict::Holds, "{b} ± {se}");
        assert!((b + 0.5).abs() < 0.1, "{b}");
        // A steeper law, W_c ∝ ζ^(−1.2): does not hold.
        let c = 80.0 / 0.005f64.powf(-1.2);
        let (v, b, se) = synthetic(-1.2, 0.02, c);
        assert_eq!(v, Verdict::DoesNotHold, "{b} ± {se}");
        // Every width flows at every activity: not testable, inconclusive.
        let (v, ..) = synthetic(-0.5, 0.02, 0.1);
        assert_eq!(v, Verdict::Inconclusive);
        // No width flows at any activity: not testable either.
        let (v, ..) = synthetic(-0.5, 0.02, 1e5);
        assert_eq!(v, Verdict::Inconclusive);
        assert!(verdict(f64::NAN, f64::NAN, &[Onset::Wider, Onset::Wider])
            .1
            .starts_with("not testable"));
        assert!(
            verdict(f64::NAN, f64::NAN, &[Onset::Narrower, Onset::Wider])
                .1
                .starts_with("not testable")
        );
        // A large scatter between seeds: inconclusive.
        assert_eq!(
            verdict(-0.9, 0.25, &[Onset::At(30.0), Onset::At(40.0)]).0,
            Verdict::Inconclusive
        );
    }

    /// A flow with net coherences `c` by seed (v_rms 1, no shear).
    fn flow_of(c: &[f64]) -> Flow {
        let per = |v: Vec<f64>| PerSeed {
            seeds: (0..v.len() as u64).collect(),
            values: v,
        };
        Flow {
            zeta: "0".into(),
            friction: "0".into(),
            net: per(c.to_vec()),
            shear: per(vec![0.0; c.len()]),
            v_rms: per(vec![1.0; c.len()]),
        }
    }

    /// The polar control and the no-net-flow claim reach each outcome: a plug flow, an
    /// undirected flow, and a flow too scattered to decide.
    #[test]
    fn the_net_flow_rules_reach_each_verdict() {
        let polar = |c: &[f64]| polar_claim(&[(24, flow_of(c)), (48, flow_of(&[0.3, 0.2]))]);
        assert_eq!(polar(&[0.84, 0.79, 0.86]).verdict, Verdict::Holds);
        assert_eq!(polar(&[0.05, 0.08, 0.06]).verdict, Verdict::DoesNotHold);
        assert_eq!(polar(&[0.1, 0.9, 0.4]).verdict, Verdict::Inconclusive);
        assert!(polar(&[0.84, 0.79, 0.86]).measured.contains("W = 48"));
        let none = |c: f64, se: f64| no_net_flow((c, se, "W = 24".into())).verdict;
        assert_eq!(none(0.08, 0.02), Verdict::Holds);
        assert_eq!(none(0.8, 0.05), Verdict::DoesNotHold);
        assert_eq!(none(0.4, 0.1), Verdict::Inconclusive);
    }

    /// The channel section of docs/reproduction.md states the verdicts that the figure's own
    /// runs give, kept in `docs/data/channel/quick/channel_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let want = verdicts_from_tables(&crate::stored_tables("channel/quick")).unwrap();
        assert_eq!(want.len(), 4);
        crate::assert_doc_verdicts("channel", "**Verdicts (quick):**", &want);
    }

    #[test]
    fn the_critical_width_is_the_first_reaching_the_level() {
        let w = [10.0, 20.0, 40.0];
        // 0.25, 0.75, 0.9: the level ½ half-way from 10 to 20, whatever the widest does.
        assert_eq!(critical_width(&w, &[0.25, 0.75, 0.9]), Onset::At(15.0));
        assert_eq!(critical_width(&w, &[0.25, 0.75, 0.55]), Onset::At(15.0));
        assert_eq!(critical_width(&w, &[0.6, 0.8, 0.9]), Onset::Narrower);
        assert_eq!(critical_width(&w, &[0.1, 0.2, 0.3]), Onset::Wider);
        // A dip after the first crossing does not move it.
        assert_eq!(critical_width(&w, &[0.25, 0.75, 0.1]), Onset::At(15.0));
    }
}
