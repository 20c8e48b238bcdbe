//! `reproduce channel`: the flow transition of an active tissue in a channel (issue 28, T3.4
//! of the extensions). Continuum active nematics confined to a channel flow spontaneously
//! only above a critical width `W_c ∝ √(K/ζ)`; here `W_c` is measured against ζ and its
//! exponent compared with −½.
//!
//! Each width is a sweep of its own (the cell count follows the width, at the paper's
//! density), over ζ = 0 and three activities. The statistic of a run is its `v_rms` over the
//! second half of its active phase, divided by that of the ζ = 0 run of the same width and
//! seed (the passive baseline: coarsening and the walls' push, docs/model.md §11.4). `W_c` is
//! the width where the active part of the mean ratio, `ratio − 1`, reaches half its value in
//! the widest channel (an activity whose widest channel does not flow, ratio ≤ [`FLOWS`], has
//! none). The exponent is the least-squares slope of `ln W_c` against `ln ζ`, its error from
//! the jackknife over seeds.

use std::path::Path;

use render::{Plot, Series};

use super::{drawn, g, mean_se, write_text, Claim, Rec, ReproduceParams, Scale, SweepJob, Verdict};
use study::SweepError;

/// The activities; ζ = 0 is the baseline.
const ZETAS: [&str; 5] = ["0", "0.001", "0.0025", "0.005", "0.01"];

/// The ratio of `v_rms` to the passive baseline above which the widest channel flows: below
/// it the activity is too weak for a width to be found at this run length.
pub(crate) const FLOWS: f64 = 2.0;

/// The continuum exponent of `W_c ∝ ζ^b`.
pub(crate) const CONTINUUM: f64 = -0.5;

/// Nodes per cell: the paper's density (60 cells on 100²).
const AREA_PER_CELL: f64 = 10_000.0 / 60.0;

fn widths(scale: Scale) -> Vec<usize> {
    match scale {
        Scale::Quick => vec![16, 20, 24, 32, 40, 48, 64, 96],
        Scale::Paper => vec![16, 20, 24, 28, 32, 40, 48, 64, 96, 128],
    }
}

/// The critical width from the mean ratios `ratio[k]` at the increasing widths `widths`: the
/// width at which the active part of the flow, `(ratio − 1)/(ratio_widest − 1)`, reaches ½,
/// interpolated linearly above the widest width where it is below ½. `None` when the widest
/// channel does not flow (its ratio at most [`FLOWS`]) or when no width is below ½.
pub(crate) fn critical_width(widths: &[f64], ratio: &[f64]) -> Option<f64> {
    let widest = *ratio.last()?;
    if widest.is_nan() || widest <= FLOWS {
        return None;
    }
    let f: Vec<f64> = ratio.iter().map(|r| (r - 1.0) / (widest - 1.0)).collect();
    let below = (0..f.len()).rev().find(|&k| f[k].is_nan() || f[k] < 0.5)?;
    let k = below + 1;
    let t = (0.5 - f[below]) / (f[k] - f[below]);
    Some(widths[below] + t * (widths[k] - widths[below]))
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
/// jackknife error over seeds, with the critical widths of the seed means (`None` where not
/// bracketed). NaN exponent when fewer than two activities bracket `W_c`.
pub(crate) fn exponent(
    widths: &[f64],
    zetas: &[f64],
    ratio: &[Vec<Vec<f64>>],
) -> (f64, f64, Vec<Option<f64>>) {
    let fit = |seeds: &[usize]| -> (f64, Vec<Option<f64>>) {
        let wc: Vec<Option<f64>> = (0..zetas.len())
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
            .filter_map(|(z, w)| w.map(|w| (z.ln(), w.ln())))
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
    let n = ratio.len();
    if n < 3 || !b.is_finite() {
        return (b, f64::NAN, wc);
    }
    let leave: Vec<f64> = (0..n)
        .map(|out| {
            fit(&all
                .iter()
                .copied()
                .filter(|&s| s != out)
                .collect::<Vec<_>>())
            .0
        })
        .collect();
    if leave.iter().any(|v| !v.is_finite()) {
        return (b, f64::NAN, wc);
    }
    let m = leave.iter().sum::<f64>() / n as f64;
    let var = (n as f64 - 1.0) / n as f64 * leave.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
    (b, var.sqrt(), wc)
}

/// The verdict on `W_c ∝ ζ^{−1/2}` from the exponent `b ± se`: holds within 2 standard
/// errors (and an error below 0.25), does not hold beyond 3, inconclusive between, or when
/// the exponent or its error could not be measured.
pub(crate) fn verdict(b: f64, se: f64) -> (Verdict, String) {
    if !(b.is_finite() && se.is_finite()) {
        return (
            Verdict::Inconclusive,
            "W_c is bracketed by the widths at fewer than two activities (or in fewer than three seeds' jackknife samples): widen the range of widths".into(),
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

pub(super) fn make(p: &ReproduceParams, dir: &Path) -> Result<(Vec<Claim>, String), SweepError> {
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
    let mut recs: Vec<(usize, Vec<Rec>)> = Vec::new();
    for &w in &ws {
        let ly = w + 2;
        let count = ((lx * w) as f64 / AREA_PER_CELL).round() as usize;
        let mut sets = vec![
            format!("domain.lx={lx}"),
            format!("domain.ly={ly}"),
            format!("cells.count={count}"),
            "walls.kind=\"channel\"".to_string(),
            "model.pressure=\"interaction\"".to_string(),
            format!("run.time={t}"),
            format!("run.output_every={t}"),
        ];
        sets.extend(p.scale.integrator());
        let margin: usize = match p.scale {
            Scale::Quick => 16,
            Scale::Paper => 12,
        };
        sets.push(format!("integrator.margin={}", margin.min((ly - 1) / 2)));
        let res = super::sweep(
            p,
            SweepJob {
                scene: super::PAPER_SCENE,
                name: format!("channel-w{w}-{}", p.scale.name()),
                sets,
                varies: vec![format!("model.zeta={}", ZETAS.join(","))],
                analyze: None,
                seeds: None,
            },
        )?;
        recs.push((w, res.records(None)?));
    }
    p.reporter.stage("channel: tables and plots");
    let seeds: Vec<u64> = {
        let mut s: Vec<u64> = recs[0].1.iter().map(|r| r.seed).collect();
        s.sort_unstable();
        s.dedup();
        s
    };
    // ratio[seed][zeta][width]
    let v_of = |w: usize, z: &str, seed: u64| -> f64 {
        recs.iter()
            .find(|(ww, _)| *ww == w)
            .and_then(|(_, rs)| rs.iter().find(|r| r.values[0] == z && r.seed == seed))
            .map_or(f64::NAN, |r| r.summary.v_rms)
    };
    let ratio: Vec<Vec<Vec<f64>>> = seeds
        .iter()
        .map(|&s| {
            ZETAS[1..]
                .iter()
                .map(|z| {
                    ws.iter()
                        .map(|&w| v_of(w, z, s) / v_of(w, "0", s))
                        .collect()
                })
                .collect()
        })
        .collect();
    let wf: Vec<f64> = ws.iter().map(|&w| w as f64).collect();
    let (b, se, wc) = exponent(&wf, &zetas, &ratio);

    let mut csv = String::from("width,zeta,v_rms,v_rms_se,ratio,ratio_se\n");
    let mut plot = Plot::new(
        "Flow in a channel against its width",
        "channel width W (nodes)",
        "v_rms / v_rms(ζ = 0), mean ± s.e. over seeds",
    );
    plot.log_y = true;
    for (zi, z) in ZETAS[1..].iter().enumerate() {
        let mut ys = Vec::new();
        let mut es = Vec::new();
        for (wi, &w) in ws.iter().enumerate() {
            let r = mean_se(&ratio.iter().map(|s| s[zi][wi]).collect::<Vec<_>>());
            let v = mean_se(&seeds.iter().map(|&s| v_of(w, z, s)).collect::<Vec<_>>());
            csv += &format!("{w},{z},{:e},{:e},{:e},{:e}\n", v.0, v.1, r.0, r.1);
            ys.push(r.0);
            es.push(if r.1.is_finite() { r.1 } else { 0.0 });
        }
        plot.series
            .push(Series::new(format!("ζ = {z}")).with_points(&wf, &ys, &es));
    }
    for (w, _) in &recs {
        let v = mean_se(&seeds.iter().map(|&s| v_of(*w, "0", s)).collect::<Vec<_>>());
        csv += &format!("{w},0,{:e},{:e},1,0\n", v.0, v.1);
    }
    write_text(&dir.join("channel_flow.csv"), &csv)?;
    drawn(plot.save_png(&dir.join("channel_flow.png")))?;
    let (x, y): (Vec<f64>, Vec<f64>) = zetas
        .iter()
        .zip(&wc)
        .filter_map(|(z, w)| w.map(|w| (*z, w)))
        .unzip();
    let mut wplot = Plot::new("Critical width against activity", "ζ", "W_c (nodes)");
    (wplot.log_x, wplot.log_y) = (true, true);
    if !x.is_empty() {
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
    drawn(wplot.save_png(&dir.join("channel_critical_width.png")))?;
    let (v, reason) = verdict(b, se);
    let wc_text: Vec<String> = ZETAS[1..]
        .iter()
        .zip(&wc)
        .map(|(z, w)| format!("ζ = {z}: {}", w.map_or("not bracketed".into(), g)))
        .collect();
    let claims = vec![Claim::new(
        "channel (extensions T3.4): the critical width of channel flow scales as W_c ∝ ζ^(−1/2)",
        format!(
            "W_c: {}; exponent b = {} ± {} (jackknife over seeds)",
            wc_text.join(", "),
            g(b),
            g(se)
        ),
        v,
        reason,
    )];
    let settings = format!(
        "- A channel along x: `[walls] kind = \"channel\"`, lx = {lx}, free width W ∈ {{{}}} (ly = W + 2), the paper's density (a cell per {:.1} nodes), the paper's parameters with the interaction pressure (docs/model.md §11.4: in the paper's form the walls' push dominates v_rms); ζ ∈ {{{}}}; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; integrator {} (margin at most (ly − 1)/2); f32 storage.\n\
         - Statistic: the ratio of v_rms over the second half of the active phase to that of ζ = 0 at the same width and seed; W_c is where the active part of the mean ratio, ratio − 1, reaches half its value in the widest channel (linear interpolation above the widest width below half; none when the widest channel's ratio is at most {FLOWS}). Exponent: least-squares slope of ln W_c against ln ζ; error: jackknife over seeds. Rule: holds within 2 standard errors of −½ (error below 0.25), does not hold beyond 3, inconclusive between. Data in `channel_flow.csv`, plots `channel_flow.png`, `channel_critical_width.png`.",
        ws.iter().map(|w| w.to_string()).collect::<Vec<_>>().join(", "),
        AREA_PER_CELL,
        ZETAS.join(", "),
        p.scale.seeds(),
        p.scale.integrator_name()
    );
    Ok((claims, settings))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic ratios `1 + 5 W⁴/(W⁴ + W_c⁴)` with `W_c = c ζ^b` and a seed's scatter: the
    /// rule finds each outcome.
    fn synthetic(b: f64, scatter: f64, c: f64) -> (Verdict, f64, f64) {
        let widths: [f64; 10] = [16.0, 20.0, 24.0, 32.0, 40.0, 48.0, 64.0, 96.0, 128.0, 192.0];
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
                            .map(|&w| 1.0 + 5.0 * w.powi(4) / (w.powi(4) + wc.powi(4)))
                            .collect()
                    })
                    .collect()
            })
            .collect();
        let (e, se, _) = exponent(&widths, &zetas, &ratio);
        (verdict(e, se).0, e, se)
    }

    #[test]
    fn the_rule_reaches_each_verdict() {
        // W_c = 30 at ζ = 0.005 with the continuum exponent: holds.
        let c = 30.0 / 0.005f64.powf(-0.5);
        let (v, b, se) = synthetic(-0.5, 0.04, c);
        assert_eq!(v, Verdict::Holds, "{b} ± {se}");
        assert!((b + 0.5).abs() < 0.1, "{b}");
        // A steeper law, W_c ∝ ζ^(−1.2): does not hold.
        let c = 30.0 / 0.005f64.powf(-1.2);
        let (v, b, se) = synthetic(-1.2, 0.02, c);
        assert_eq!(v, Verdict::DoesNotHold, "{b} ± {se}");
        // Every width flows at every activity: nothing bracketed, inconclusive.
        let (v, ..) = synthetic(-0.5, 0.02, 0.1);
        assert_eq!(v, Verdict::Inconclusive);
        // A large scatter between seeds: inconclusive.
        assert_eq!(verdict(-0.9, 0.19).0, Verdict::Inconclusive);
    }

    #[test]
    fn the_critical_width_interpolates_the_crossing() {
        let w = [10.0, 20.0, 40.0];
        // Active part 0, 2, 4 of the widest 4: half at 20.
        assert!((critical_width(&w, &[1.0, 3.0, 5.0]).unwrap() - 20.0).abs() < 1e-12);
        // 0.25 and 0.75 of it: half-way between 10 and 20.
        assert!((critical_width(&w, &[2.0, 4.0, 5.0]).unwrap() - 15.0).abs() < 1e-12);
        // Every width above half, or the widest not flowing: none.
        assert_eq!(critical_width(&w, &[3.5, 4.0, 5.0]), None);
        assert_eq!(critical_width(&w, &[1.0, 1.2, 1.5]), None);
        // A dip above a wider width: the crossing above the widest width below half.
        let expected = 20.0 + 20.0 / 3.0;
        assert!((critical_width(&w, &[3.0, 2.0, 5.0]).unwrap() - expected).abs() < 1e-12);
    }
}
