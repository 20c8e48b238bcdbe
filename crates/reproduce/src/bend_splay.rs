//! `reproduce bend-splay`: from a uniform director, is a tissue whose cells' own nematic is
//! extensile unstable to bend, and a contractile one to splay (issue 49)?
//!
//! Every cell's nematic starts along x (`[nematic] angle = 0`, docs/model.md §11.6), with the
//! elastic coupling K, the flow's rotation (W = 1) and a weak noise, and no shape activity
//! (ζ = 0). Each frame's deviations `δθ_i = ½ sin 2(θ_i − θ̄)` from the mean axis θ̄ give the
//! power of the longest modes along each axis, at the cells' centres `r_i`:
//! `P_x = Σ_{m=1,2} |Σ_i δθ_i e^{−i k_m x_i}|² / N` (wave vector along the director: bend) and
//! `P_y` the same along y (across it: splay), `k_m = 2π m / L`.
//!
//! Per run:
//! - the **anisotropy** `a = (ΣP_x − ΣP_y)/(ΣP_x + ΣP_y)` over the frames of the growth phase
//!   (from 100 TU after the activity starts while the cells' nematic order is at least
//!   [`LINEAR`]): +1 for pure bend, −1 for pure splay;
//! - the **loss of order** `1 − S`, S the cells' nematic order `|⟨e^{2iθ_i}⟩|` at the last
//!   frame;
//! - the **growth rates** of `P_x` and `P_y`: least-squares slopes of their logarithms over the
//!   same frames.

#[cfg(test)]
use std::path::Path;

use render::{Plot, Series};
use study::SweepError;

use super::pipeline::{cell, sci, Csv, Made};
use super::rule::Rule;
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};

/// The figure's scene: 240 cells in a periodic 200² box, every nematic along x.
pub const BEND_SPLAY_SCENE: &str = "\
[domain]
lx = 200
ly = 200

[cells]
count = 240
radius = 8.0

[model]
zeta = 0.0

[nematic]
zeta = 0.02
elastic = 0.01
vorticity = 1.0
rotational_diffusion = 1e-5
angle = 0.0

[run]
relax_time = 50.0
time = 1000.0
seed = 1
output_every = 10.0
series_every = 5.0
";

/// The box side and the relaxation time of [`BEND_SPLAY_SCENE`].
const L: f64 = 200.0;
const RELAX: f64 = 50.0;

/// The activities ζ_Q of the sweep: contractile, none (the control), extensile.
const ZETA_Q: [&str; 3] = ["-0.02", "0", "0.02"];

/// The smallest anisotropy that counts: the mode along one axis carries at least 65 % of the
/// power (a = 0.3).
pub(crate) const ANISOTROPY: f64 = 0.3;
/// The order down to which the deviations grow as small ones: the growth phase ends where the
/// cells' nematic order first falls below it (the rms deviation then about 0.23 rad).
pub(crate) const LINEAR: f64 = 0.9;
/// The smallest loss of order that counts as an instability: a fifth of the order.
pub(crate) const LOSS: f64 = 0.2;

/// One run: its ζ_Q (index into [`ZETA_Q`]), its seed and its measures.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Run {
    pub zeta_q: usize,
    pub seed: u64,
    pub anisotropy: f64,
    pub loss: f64,
    pub rate_bend: f64,
    pub rate_splay: f64,
}

/// One frame's time, the bend power `P_x`, the splay power `P_y` and the order S, from the
/// cells' centres (`x, y` pairs) and axes θ in a periodic box of side `side`.
pub(crate) fn modes(centres: &[f64], theta: &[f64], side: f64) -> (f64, f64, f64) {
    let n = theta.len() as f64;
    let (c, s) = theta.iter().fold((0.0, 0.0), |(c, s), t| {
        (c + (2.0 * t).cos(), s + (2.0 * t).sin())
    });
    let order = c.hypot(s) / n;
    let mean = 0.5 * s.atan2(c);
    let power = |axis: usize| -> f64 {
        (1..=2)
            .map(|m| {
                let k = 2.0 * std::f64::consts::PI * m as f64 / side;
                let (re, im) = theta.iter().zip(centres.chunks_exact(2)).fold(
                    (0.0, 0.0),
                    |(re, im), (t, r)| {
                        let d = 0.5 * (2.0 * (t - mean)).sin();
                        (re + d * (k * r[axis]).cos(), im - d * (k * r[axis]).sin())
                    },
                );
                (re * re + im * im) / n
            })
            .sum()
    };
    (power(0), power(1), order)
}

/// A run's measures from its frames' `(time, P_x, P_y, S)` in time order, with the activity
/// from `start`: the anisotropy and the growth rates over the growth phase (from 100 TU after
/// `start` while the order is at least [`LINEAR`]), the loss of order at the last frame.
pub(crate) fn measure(frames: &[(f64, f64, f64, f64)], start: f64) -> [f64; 4] {
    let window: Vec<&(f64, f64, f64, f64)> = frames
        .iter()
        .filter(|f| f.0 >= start + 100.0)
        .take_while(|f| f.3 >= LINEAR)
        .collect();
    let (bx, by) = window
        .iter()
        .fold((0.0, 0.0), |(a, b), f| (a + f.1, b + f.2));
    let anisotropy = (bx - by) / (bx + by);
    let loss = 1.0 - frames.last().map_or(f64::NAN, |f| f.3);
    let slope = |p: fn(&(f64, f64, f64, f64)) -> f64| -> f64 {
        let pts: Vec<(f64, f64)> = window
            .iter()
            .filter(|f| p(f) > 0.0)
            .map(|f| (f.0, p(f).ln()))
            .collect();
        if pts.len() < 3 {
            return f64::NAN;
        }
        let n = pts.len() as f64;
        let (mt, ml) = (
            pts.iter().map(|q| q.0).sum::<f64>() / n,
            pts.iter().map(|q| q.1).sum::<f64>() / n,
        );
        let (num, den) = pts.iter().fold((0.0, 0.0), |(a, b), q| {
            (a + (q.0 - mt) * (q.1 - ml), b + (q.0 - mt) * (q.0 - mt))
        });
        num / den
    };
    [anisotropy, loss, slope(|f| f.1), slope(|f| f.2)]
}

/// A claim that two rules hold together: holds when both hold, does not hold when either does
/// not, inconclusive otherwise (the outcomes exclude each other).
fn both(a: (Verdict, String), b: (Verdict, String)) -> (Verdict, String) {
    let v = match (a.0, b.0) {
        (Verdict::Holds, Verdict::Holds) => Verdict::Holds,
        (Verdict::DoesNotHold, _) | (_, Verdict::DoesNotHold) => Verdict::DoesNotHold,
        _ => Verdict::Inconclusive,
    };
    (v, format!("{}; {}", a.1, b.1))
}

/// The rule on the loss of order of seed values `loss`: the instability.
fn unstable(loss: &[f64]) -> (Verdict, String) {
    let (m, se) = mean_se(loss);
    let o = Rule::effect(
        "the loss of the cells' nematic order, 1 − S at the end",
        LOSS,
    )
    .decide(m, se);
    (o.verdict, o.why)
}

/// The rule on the anisotropy `a` towards `sign` (+1 bend, −1 splay).
fn towards(a: &[f64], sign: f64) -> (Verdict, String) {
    let (m, se) = mean_se(a);
    let what = if sign > 0.0 {
        "the bend anisotropy a = (P_x − P_y)/(P_x + P_y)"
    } else {
        "the splay anisotropy −a"
    };
    let o = Rule::effect(what, ANISOTROPY).decide(sign * m, se);
    (o.verdict, o.why)
}

/// The runs of one ζ_Q.
fn of(runs: &[Run], zeta_q: usize, f: impl Fn(&Run) -> f64) -> Vec<f64> {
    let mut r: Vec<&Run> = runs.iter().filter(|r| r.zeta_q == zeta_q).collect();
    r.sort_by_key(|r| r.seed);
    r.into_iter().map(f).collect()
}

/// The claims and the table of points.
pub(crate) fn analyse(runs: &[Run]) -> (Vec<Claim>, Csv) {
    let mut csv = Csv::new(&[
        "zeta_q",
        "seeds",
        "anisotropy_mean",
        "anisotropy_se",
        "order_loss_mean",
        "order_loss_se",
        "rate_bend_mean",
        "rate_bend_se",
        "rate_splay_mean",
        "rate_splay_se",
    ]);
    let mut text = Vec::new();
    for (k, zq) in ZETA_Q.iter().enumerate() {
        let a = mean_se(&of(runs, k, |r| r.anisotropy));
        let l = mean_se(&of(runs, k, |r| r.loss));
        let b = mean_se(&of(runs, k, |r| r.rate_bend));
        let s = mean_se(&of(runs, k, |r| r.rate_splay));
        csv.row([
            cell(zq),
            cell(of(runs, k, |r| r.anisotropy).len()),
            sci(a.0),
            sci(a.1),
            sci(l.0),
            sci(l.1),
            sci(b.0),
            sci(b.1),
            sci(s.0),
            sci(s.1),
        ]);
        text.push(format!(
            "ζ_Q = {zq}: a = {} ± {}, 1 − S = {} ± {}, growth rates bend {} ± {} and splay {} ± {} per TU",
            g(a.0),
            g(a.1),
            g(l.0),
            g(l.1),
            g(b.0),
            g(b.1),
            g(s.0),
            g(s.1)
        ));
    }
    let idx = |v: &str| ZETA_Q.iter().position(|z| *z == v).expect("a ζ_Q");
    let (c, z, e) = (idx("-0.02"), idx("0"), idx("0.02"));
    let (ve, we) = both(
        unstable(&of(runs, e, |r| r.loss)),
        towards(&of(runs, e, |r| r.anisotropy), 1.0),
    );
    let (vc, wc) = both(
        unstable(&of(runs, c, |r| r.loss)),
        towards(&of(runs, c, |r| r.anisotropy), -1.0),
    );
    let (vz, wz) = unstable(&of(runs, z, |r| r.loss));
    let claims = vec![
        Claim::new(
            "bend-splay (issue 49): a uniform director of cells whose own nematic is extensile (ζ_Q > 0) is unstable to bend: the order falls and the growing mode's wave vector is along the director",
            text[e].clone(),
            ve,
            we,
        ),
        Claim::new(
            "bend-splay (issue 49): a uniform director of cells whose own nematic is contractile (ζ_Q < 0) is unstable to splay: the order falls and the growing mode's wave vector is across the director",
            text[c].clone(),
            vc,
            wc,
        ),
        Claim::new(
            "Control (bend-splay): without activity (ζ_Q = 0) the uniform director is unstable (must not hold)",
            text[z].clone(),
            vz,
            wz,
        ),
    ];
    (claims, csv)
}

/// The table of runs, the figure's raw data.
fn runs_csv(runs: &[Run]) -> Csv {
    let mut csv = Csv::new(&[
        "zeta_q",
        "seed",
        "anisotropy",
        "order_loss",
        "rate_bend",
        "rate_splay",
    ]);
    for r in runs {
        csv.row([
            cell(ZETA_Q[r.zeta_q]),
            cell(r.seed),
            sci(r.anisotropy),
            sci(r.loss),
            sci(r.rate_bend),
            sci(r.rate_splay),
        ]);
    }
    csv
}

/// The runs of `bend_splay_runs.csv` in `dir`, as [`runs_csv`] wrote them.
#[cfg(test)]
fn runs_from_table(dir: &Path) -> Result<Vec<Run>, SweepError> {
    let t = super::Table::read(&dir.join("bend_splay_runs.csv"))?;
    let zq = t.strs("zeta_q")?;
    let (seed, a, l, b, s) = (
        t.f64s("seed")?,
        t.f64s("anisotropy")?,
        t.f64s("order_loss")?,
        t.f64s("rate_bend")?,
        t.f64s("rate_splay")?,
    );
    Ok((0..zq.len())
        .map(|k| Run {
            zeta_q: ZETA_Q.iter().position(|z| *z == zq[k]).expect("a ζ_Q"),
            seed: seed[k] as u64,
            anisotropy: a[k],
            loss: l[k],
            rate_bend: b[k],
            rate_splay: s[k],
        })
        .collect())
}

/// The plotted curves of one ζ_Q: its name, the times and `log10 P_x`, `log10 P_y`.
type Curves = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// The `(time, P_x, P_y, S)` of every frame of a run, in time order.
fn frames_of(run: &std::path::Path) -> Result<Vec<(f64, f64, f64, f64)>, SweepError> {
    let paths = super::pipeline::frame_paths(run, "the director's modes")?;
    let mut out = Vec::new();
    for path in &paths {
        let a = rundir::read_npz(path, &["time", "centre", "nematic.theta"]).map_err(|source| {
            SweepError::RunDir {
                point: run.display().to_string(),
                source,
            }
        })?;
        let t = a[0].data.first().copied().unwrap_or(f64::NAN);
        let (px, py, s) = modes(&a[1].data, &a[2].data, L);
        out.push((t, px, py, s));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 1000.0,
        Scale::Paper => 2000.0,
    };
    let mut sets = vec![format!("run.time={t}")];
    sets.extend(p.scale.own_dt_set());
    let res = super::sweep(
        p,
        SweepJob {
            scene: BEND_SPLAY_SCENE,
            name: format!("bend-splay-{}", p.scale.name()),
            sets,
            varies: vec![format!("nematic.zeta={}", ZETA_Q.join(","))],
            analyze: None,
            seeds: None,
        },
    )?;
    p.reporter.stage("bend-splay: modes of the director");
    let mut runs = Vec::new();
    let mut power: Vec<Curves> = Vec::new();
    for pt in res.points(None)? {
        let zq = ZETA_Q
            .iter()
            .position(|z| *z == pt.values[0])
            .expect("a ζ_Q of the sweep");
        for r in &pt.runs {
            let frames = frames_of(&r.run)?;
            let [anisotropy, loss, rate_bend, rate_splay] = measure(&frames, RELAX);
            if r.seed == 1 && zq != 1 {
                // From the first frame of the activity: before it, every axis is along x.
                let active: Vec<_> = frames.iter().filter(|f| f.0 > RELAX).collect();
                power.push((
                    ZETA_Q[zq].to_string(),
                    active.iter().map(|f| f.0).collect(),
                    active.iter().map(|f| f.1.log10()).collect(),
                    active.iter().map(|f| f.2.log10()).collect(),
                ));
            }
            runs.push(Run {
                zeta_q: zq,
                seed: r.seed,
                anisotropy,
                loss,
                rate_bend,
                rate_splay,
            });
        }
    }
    p.reporter.stage("bend-splay: tables and plot");
    let (claims, points) = analyse(&runs);
    let mut plot = Plot::new(
        "The director's longest modes from a uniform state (seed 1)",
        "time (TU)",
        "log10 power of the axes' deviations",
    );
    for (zq, times, px, py) in &power {
        let zero = vec![0.0; times.len()];
        plot.series.push(
            Series::new(format!("ζ_Q = {zq}: bend (k along the director)"))
                .with_points(times, px, &zero)
                .line_only(),
        );
        plot.series.push(
            Series::new(format!("ζ_Q = {zq}: splay (k across)"))
                .with_points(times, py, &zero)
                .line_only(),
        );
    }
    let settings = format!(
        "- 240 cells (R = 8) in a periodic {L}² box, no shape activity (ζ = 0), each with its own nematic (S = 1) starting along x, elastic K = 0.01, vorticity W = 1, D_r = 1e-5 (`BEND_SPLAY_SCENE`), ζ_Q = {}; seeds {}.\n\
         - {RELAX} TU of relaxation, then {t} TU; dt = {}; a frame every 10 TU.\n\
         - Each frame: `δθ_i = ½ sin 2(θ_i − θ̄)`, and the power of the modes m = 1, 2 along x (the director: bend) and along y (splay), `P = Σ_m |Σ_i δθ_i e^(−i k_m r_i)|²/N` at the cells' centres.\n\
         - The growth phase: from 100 TU after the activity starts while the cells' nematic order S is at least {LINEAR}. Anisotropy `a = (ΣP_x − ΣP_y)/(ΣP_x + ΣP_y)` over it; bend when a ≥ {ANISOTROPY} by the rule of an effect (2 s.e. over seeds), splay when −a ≥ {ANISOTROPY}. Unstable when the loss of order 1 − S at the end is at least {LOSS} by the same rule. A claim holds when both of its rules hold, does not hold when one does not.\n\
         - Growth rates: least-squares slopes of ln P_x and ln P_y over the growth phase.\n\
         - Control: ζ_Q = 0, where only the noise moves the axes; it must read \"does not hold\".\n\
         - Data: `bend_splay_runs.csv` (each run), `bend_splay.csv` (each ζ_Q), `modes.png`.",
        ZETA_Q.join(", "),
        p.scale.seeds(),
        p.scale.own_dt(),
    );
    Ok(Made::new(claims, settings)
        .table("bend_splay_runs.csv", runs_csv(&runs))
        .table("bend_splay.csv", points)
        .plot("modes.png", plot))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bend mode `δθ = ε sin(k x)` puts its power along x, a splay mode along y, to
    /// round-off; the order of a uniform director is 1.
    #[test]
    fn the_modes_of_a_bend_and_a_splay_deviation() {
        let n = 20;
        let mut centres = Vec::new();
        for i in 0..n {
            for j in 0..n {
                centres.extend([
                    L * (i as f64 + 0.5) / n as f64,
                    L * (j as f64 + 0.3) / n as f64,
                ]);
            }
        }
        let k = 2.0 * std::f64::consts::PI / L;
        let eps = 0.01;
        let bend: Vec<f64> = centres.chunks(2).map(|r| eps * (k * r[0]).sin()).collect();
        let splay: Vec<f64> = centres.chunks(2).map(|r| eps * (k * r[1]).sin()).collect();
        let (px, py, s) = modes(&centres, &bend, L);
        assert!(py < 1e-12 * px, "{px} {py}");
        assert!(s > 0.999);
        // |Σ δθ e^{−ikx}|²/N with δθ = ½ sin 2(θ − θ̄) ≈ ε sin(kx): (εN/2)²/N.
        let want = (eps * (n * n) as f64 / 2.0).powi(2) / (n * n) as f64;
        assert!((px / want - 1.0).abs() < 1e-3, "{px} {want}");
        let (px, py, _) = modes(&centres, &splay, L);
        assert!(px < 1e-12 * py);
        let uniform = vec![0.3; n * n];
        let (px, py, s) = modes(&centres, &uniform, L);
        assert!(px < 1e-20 && py < 1e-20 && (s - 1.0).abs() < 1e-12);
    }

    /// Exponential growth at a known rate is measured to round-off over the growth phase, and
    /// what follows it (the order lost, the modes saturated) is left out.
    #[test]
    fn the_growth_rates_of_synthetic_modes() {
        let frames: Vec<(f64, f64, f64, f64)> = (0..=100)
            .map(|k| {
                let t = 10.0 * k as f64;
                let (px, py) = if t <= 700.0 {
                    (1e-4 * (0.01 * t).exp(), 1e-4 * (0.002 * t).exp())
                } else {
                    (1.0, 1.0)
                };
                (t, px, py, if t <= 700.0 { 0.99 } else { 0.5 })
            })
            .collect();
        let [a, loss, rb, rs] = measure(&frames, 50.0);
        assert!(
            (rb - 0.01).abs() < 1e-12 && (rs - 0.002).abs() < 1e-12,
            "{rb} {rs}"
        );
        assert!(a > 0.9 && (loss - 0.5).abs() < 1e-12, "{a} {loss}");
    }

    fn runs(a: [f64; 3], loss: [f64; 3], spread: f64) -> Vec<Run> {
        let mut out = Vec::new();
        for zeta_q in 0..3 {
            for seed in 1..=3u64 {
                let w = spread * (seed as f64 - 2.0);
                out.push(Run {
                    zeta_q,
                    seed,
                    anisotropy: a[zeta_q] + w,
                    loss: loss[zeta_q] + w,
                    rate_bend: 0.01,
                    rate_splay: 0.002,
                });
            }
        }
        out
    }

    #[test]
    fn each_outcome_is_reached() {
        let verdicts =
            |r: &[Run]| -> Vec<Verdict> { analyse(r).0.into_iter().map(|c| c.verdict).collect() };
        // Contractile, control, extensile: the textbook.
        assert_eq!(
            verdicts(&runs([-0.7, 0.0, 0.8], [0.6, 0.02, 0.6], 0.02)),
            [Verdict::Holds, Verdict::Holds, Verdict::DoesNotHold]
        );
        // Both bend: the contractile claim fails; a control that loses its order holds.
        assert_eq!(
            verdicts(&runs([0.7, 0.0, 0.8], [0.6, 0.6, 0.6], 0.02)),
            [Verdict::Holds, Verdict::DoesNotHold, Verdict::Holds]
        );
        // Stable everywhere: neither instability.
        assert_eq!(
            verdicts(&runs([-0.7, 0.0, 0.8], [0.02, 0.02, 0.02], 0.02))[..2],
            [Verdict::DoesNotHold, Verdict::DoesNotHold]
        );
        // At the sizes that count, with scatter: undecided.
        assert_eq!(
            verdicts(&runs([-0.29, 0.0, 0.29], [0.6, 0.19, 0.6], 0.1)),
            [
                Verdict::Inconclusive,
                Verdict::Inconclusive,
                Verdict::Inconclusive
            ]
        );
    }

    /// The bend-splay section of docs/reproduction.md states the verdicts of the stored runs
    /// at both scales, kept in `docs/data/bend-splay/{quick,paper}/`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        for scale in ["quick", "paper"] {
            let dir = crate::stored_tables(&format!("bend-splay/{scale}"));
            let runs = runs_from_table(&dir).unwrap();
            let want: Vec<(String, Verdict)> = analyse(&runs)
                .0
                .into_iter()
                .map(|c| (c.claim, c.verdict))
                .collect();
            crate::assert_doc_verdicts("bend-splay", &format!("**Verdicts ({scale}):**"), &want);
        }
    }
}
