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
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};
use study::SweepError;

/// The activities; ζ = 0 is the baseline.
const ZETAS: [&str; 5] = ["0", "0.001", "0.0025", "0.005", "0.01"];

/// The coherence `Φ/v_rms` from which a channel flows along itself: half the flow is net
/// flow.
pub(crate) const FLOWS: f64 = 0.5;

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

/// The verdict on `W_c ∝ ζ^{−1/2}` from the exponent `b ± se` and the onsets: holds within 2
/// standard errors (and an error below 0.25), does not hold beyond 3, inconclusive between or
/// when the exponent or its error could not be measured; "not testable" (inconclusive) when no
/// activity flows coherently at any width, or every one that does already flows at the
/// narrowest width, so that no channel that resolves a cell is quiescent.
pub(crate) fn verdict(b: f64, se: f64, onsets: &[Onset]) -> (Verdict, String) {
    if !onsets.is_empty() && onsets.iter().all(|o| *o == Onset::Wider) {
        return (
            Verdict::Inconclusive,
            format!("not testable in this model: no activity has a coherent net flow along the channel (Φ/v_rms ≥ {FLOWS}) at any width: the active flow in a channel is undirected, so there is no onset of spontaneous flow to scale"),
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
    let off = (b - CONTINUUM).abs() / se.max(1e-12);
    if off <= 2.0 && se < 0.25 {
        (
            Verdict::Holds,
            format!("the exponent is {} standard errors from −½", g(off)),
        )
    } else if off > 3.0 {
        (
            Verdict::DoesNotHold,
            format!("the exponent is {} standard errors from −½", g(off)),
        )
    } else {
        (
            Verdict::Inconclusive,
            format!("the exponent is {} standard errors from −½ with an error of {}: the data do not decide", g(off), g(se)),
        )
    }
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 600.0,
        Scale::Paper => 1500.0,
    };
    let lx = 200usize;
    let ws = widths(p.scale);
    let zetas: Vec<f64> = ZETAS[1..]
        .iter()
        .map(|z| z.parse().expect("a number"))
        .collect();
    // Each width's activities, each with its runs' net flow Φ and v_rms by seed.
    let mut flows: Vec<(usize, Vec<Flow>)> = Vec::new();
    for &w in &ws {
        let res = width_sweep(p, lx, w, t)?;
        let by_zeta = res
            .points(None)?
            .iter()
            .map(|pt| {
                Ok(Flow {
                    zeta: pt.values[0].clone(),
                    net: pt.measure(|r| {
                        super::late_mean(
                            &r.run.join("analysis/observables.csv"),
                            "v_mean_x",
                            200.0 + t / 2.0,
                            f64::abs,
                        )
                    })?,
                    v_rms: pt.measure(|r| Ok(r.summary.v_rms))?,
                })
            })
            .collect::<Result<_, SweepError>>()?;
        flows.push((w, by_zeta));
    }
    p.reporter.stage("channel: tables and plots");
    let flow = |w: usize, z: &str| -> Result<&Flow, SweepError> {
        flows
            .iter()
            .find(|(ww, _)| *ww == w)
            .and_then(|(_, f)| f.iter().find(|f| f.zeta == z))
            .ok_or_else(|| SweepError::Reproduce {
                why: format!("the channel sweep of width {w} has no ζ = {z}"),
            })
    };
    let n_seeds = flows[0].1[0].net.values.len();
    // ratio[seed][zeta][width] of the net flow Φ to v_rms.
    let mut ratio = vec![vec![vec![f64::NAN; ws.len()]; ZETAS.len() - 1]; n_seeds];
    for (zi, z) in ZETAS[1..].iter().enumerate() {
        for (wi, &w) in ws.iter().enumerate() {
            for (s, c) in flow(w, z)?.coherence().into_iter().enumerate() {
                ratio[s][zi][wi] = c;
            }
        }
    }
    let wf: Vec<f64> = ws.iter().map(|&w| w as f64).collect();
    let (b, se, wc) = exponent(&wf, &zetas, &ratio);

    let mut csv = Csv::new(&[
        "width",
        "zeta",
        "net_flow",
        "net_flow_se",
        "coherence",
        "coherence_se",
        "v_rms",
        "v_rms_se",
    ]);
    let mut plot = Plot::new(
        "Coherence of the flow along a channel against its width",
        "channel width W (nodes)",
        "C = Φ / v_rms, mean ± s.e. over seeds",
    );
    plot.log_y = true;
    plot.hlines = vec![(FLOWS, "coherent: half the flow is net flow".into())];
    for (zi, z) in ZETAS[1..].iter().enumerate() {
        let mut ys = Vec::new();
        let mut es = Vec::new();
        for (wi, &w) in ws.iter().enumerate() {
            let r = mean_se(&ratio.iter().map(|s| s[zi][wi]).collect::<Vec<_>>());
            let f = flow(w, z)?;
            let (v, u) = (f.net.mean_se(), f.v_rms.mean_se());
            csv.row(
                [w.to_string(), cell(z)]
                    .into_iter()
                    .chain([v.0, v.1, r.0, r.1, u.0, u.1].map(sci)),
            );
            ys.push(r.0);
            es.push(if r.1.is_finite() { r.1 } else { 0.0 });
        }
        plot.series
            .push(Series::new(format!("ζ = {z}")).with_points(&wf, &ys, &es));
    }
    // N cells moving in random directions: E|v̄_x| = v/√(πN).
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
    for &w in &ws {
        let f = flow(w, "0")?;
        let (v, u, c) = (f.net.mean_se(), f.v_rms.mean_se(), mean_se(&f.coherence()));
        csv.row(
            [w.to_string(), cell(0)]
                .into_iter()
                .chain([v.0, v.1, c.0, c.1, u.0, u.1].map(sci)),
        );
    }
    let mut made = Made::new(Vec::new(), String::new())
        .table("channel_flow.csv", csv)
        .plot("channel_flow.png", plot);
    if let Some(wplot) = critical_width_plot(&zetas, &wc) {
        made = made.plot("channel_critical_width.png", wplot);
    }
    let claims = vec![claim(b, se, &wc, ws[0])];
    let settings = settings(p.scale, lx, t, &ws);
    made.claims = claims;
    made.settings = settings;
    Ok(made)
}

/// The sweep over ζ of the channel of width `w` (and length `lx`), runs of `t` TU.
fn width_sweep(
    p: &ReproduceParams,
    lx: usize,
    w: usize,
    t: f64,
) -> Result<super::SweepResult, SweepError> {
    let ly = w + 2;
    let count = ((lx * w) as f64 / AREA_PER_CELL).round() as usize;
    let mut sets = vec![
        format!("domain.lx={lx}"),
        format!("domain.ly={ly}"),
        format!("cells.count={count}"),
        "walls.kind=\"channel\"".to_string(),
        "model.pressure=\"interaction\"".to_string(),
        format!("run.time={t}"),
        "run.output_every=10".to_string(),
    ];
    sets.extend(p.scale.integrator());
    let margin: usize = match p.scale {
        Scale::Quick => 16,
        Scale::Paper => 12,
    };
    sets.push(format!("integrator.margin={}", margin.min((ly - 1) / 2)));
    super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("channel-w{w}-{}", p.scale.name()),
            sets,
            varies: vec![format!("model.zeta={}", ZETAS.join(","))],
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
/// and the narrowest width.
fn claim(b: f64, se: f64, wc: &[Onset], narrowest: usize) -> Claim {
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
                    Onset::Wider => "does not flow".into(),
                }
            )
        })
        .collect();
    Claim::new(
        "channel (extensions T3.4): the critical width of channel flow scales as W_c ∝ ζ^(−1/2)",
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
         - Order parameter, zero at rest: the net flow along the channel Φ = ⟨|v̄_x|⟩, the time mean over the second half of the active phase of the magnitude of the lattice mean of v_x (`v_mean_x` of `analysis/observables.csv`). Statistic: the coherence C = Φ/v_rms of each run (1 for a plug flow, about 1/√(πN) for N cells in random directions). W_c: the narrowest width at which the seed mean of C reaches {FLOWS}, linear from the width below (a fixed level: it does not depend on the widest width). Exponent: least-squares slope of ln W_c against ln ζ; error: jackknife over seeds. Rule: not testable when no activity flows coherently at any width, or every one that does already at the narrowest; holds within 2 standard errors of −½ (error below 0.25), does not hold beyond 3, inconclusive between. Data in `channel_flow.csv` (Φ, C and v_rms), plots `channel_flow.png` and, when an onset is found, `channel_critical_width.png`.",
        ws.iter().map(|w| w.to_string()).collect::<Vec<_>>().join(", "),
        AREA_PER_CELL,
        ZETAS.join(", "),
        scale.seeds(),
        scale.integrator_name()
    )
}

/// One activity of one width: its runs' net flow `Φ` and `v_rms`, by seed.
struct Flow {
    zeta: String,
    net: PerSeed,
    v_rms: PerSeed,
}

impl Flow {
    /// The coherence `Φ/v_rms` of each seed's run.
    fn coherence(&self) -> Vec<f64> {
        self.net
            .values
            .iter()
            .zip(&self.v_rms.values)
            .map(|(v, u)| v / u)
            .collect()
    }
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
            verdict(-0.9, 0.19, &[Onset::At(30.0), Onset::At(40.0)]).0,
            Verdict::Inconclusive
        );
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
