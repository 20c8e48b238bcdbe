//! `reproduce defect-fields`: Fig. 4. Flow, stress, pressure and Q averaged around ±½
//! defects in their own frame, at ζ = 5e-3, γ = 1.4e-2.

use std::path::Path;

use analysis::crop::COMPONENTS;
use render::Heatmap;

use super::pipeline::{cell, point, sci, Csv, Made, Picture};
use super::{g, mean_se, mean_std, pm, Claim, ReproduceParams, Scale, SweepJob, Verdict};
use study::analyze::AnalyzeOptions;
use study::SweepError;

/// Side of the crops: ±30 nodes, about four cell radii.
const CROP: usize = 61;
/// The cell radius of the paper scene: the core is the disc of this radius.
const R: f64 = 8.0;

/// The averaged crops of one run: `(n_plus, n_minus, plus[component], minus[component])`.
pub(crate) type Crops = (f64, f64, Vec<Vec<f64>>, Vec<Vec<f64>>);

pub(crate) fn read_crops(path: &Path) -> Result<Crops, SweepError> {
    let mut names: Vec<String> = vec!["n_plus".into(), "n_minus".into()];
    for prefix in ["plus", "minus"] {
        names.extend(COMPONENTS.iter().map(|c| format!("{prefix}_{c}")));
    }
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let a = rundir::read_npz(path, &refs).map_err(|e| SweepError::Series {
        path: path.to_path_buf(),
        why: e.to_string(),
    })?;
    let k = COMPONENTS.len();
    Ok((
        a[0].data[0],
        a[1].data[0],
        a[2..2 + k].iter().map(|x| x.data.clone()).collect(),
        a[2 + k..].iter().map(|x| x.data.clone()).collect(),
    ))
}

/// Bilinear value of a crop at `(u, v)` nodes from its centre.
fn at(field: &[f64], u: f64, v: f64) -> f64 {
    let h = (CROP / 2) as f64;
    let (x, y) = (u + h, v + h);
    let (i, j) = (x.floor() as usize, y.floor() as usize);
    if i + 1 >= CROP || j + 1 >= CROP {
        return f64::NAN;
    }
    let (fx, fy) = (x - i as f64, y - j as f64);
    let f = |a: usize, b: usize| field[a * CROP + b];
    f(i, j) * (1.0 - fx) * (1.0 - fy)
        + f(i + 1, j) * fx * (1.0 - fy)
        + f(i, j + 1) * (1.0 - fx) * fy
        + f(i + 1, j + 1) * fx * fy
}

/// The mean of a crop over the disc of radius `r`.
pub(crate) fn disc_mean(field: &[f64], r: f64) -> f64 {
    let h = (CROP / 2) as f64;
    let (mut s, mut n) = (0.0, 0.0);
    for k in 0..CROP * CROP {
        let (u, v) = ((k / CROP) as f64 - h, (k % CROP) as f64 - h);
        if u * u + v * v <= r * r && field[k].is_finite() {
            s += field[k];
            n += 1.0;
        }
    }
    s / n
}

/// Amplitudes `|c_m|`, m = 0..=4, of the radial velocity on the ring `r`.
#[cfg(test)]
fn ring_modes(vu: &[f64], vv: &[f64], r: f64) -> [f64; 5] {
    ring_coefficients(vu, vv, r).map(|(a, b)| a.hypot(b))
}

/// The Fourier coefficients `c_m = (re, im)`, m = 0..=4, of the radial velocity on the ring
/// `r`: linear in the field, so the pooled average's are the runs' weighted by their defects.
fn ring_coefficients(vu: &[f64], vv: &[f64], r: f64) -> [(f64, f64); 5] {
    let n = 72;
    let mut c = [(0.0f64, 0.0f64); 5];
    for k in 0..n {
        let phi = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        let (s, co) = phi.sin_cos();
        let vr = at(vu, r * co, r * s) * co + at(vv, r * co, r * s) * s;
        for (m, cm) in c.iter_mut().enumerate() {
            let (sm, cmm) = (m as f64 * phi).sin_cos();
            cm.0 += vr * cmm / n as f64;
            cm.1 += vr * sm / n as f64;
        }
    }
    c
}

/// What the claims read of one run's crops: a row of `defect_field_runs.csv` (the crops
/// themselves, 3 MB a figure, are not kept in the docs). Every statistic the claims pool is
/// linear in the crops, so the pooled ones are these weighted by the run's defects.
#[derive(Debug, Clone, PartialEq)]
struct RunStats {
    seed: u64,
    n_plus: f64,
    n_minus: f64,
    /// The mean core velocity (r ≤ R) around +½, along the axis and across it.
    plus_core: [f64; 2],
    /// The same around −½ (along an arm, across).
    minus_core: [f64; 2],
    /// P at the head and at the tail of +½ (u = ∓1.5R).
    head_tail: [f64; 2],
    /// ω(0, −1.5R) − ω(0, +1.5R) around +½.
    vortex_pair: f64,
    /// The Fourier coefficients of the radial velocity on the ring 1.5R around −½.
    ring: [(f64, f64); 5],
}

/// The columns of `defect_field_runs.csv`.
const RUN_COLUMNS: [&str; 22] = [
    "pressure",
    "seed",
    "n_plus",
    "n_minus",
    "plus_core_u",
    "plus_core_v",
    "minus_core_u",
    "minus_core_v",
    "p_head",
    "p_tail",
    "vortex_pair",
    "ring_re_0",
    "ring_re_1",
    "ring_re_2",
    "ring_re_3",
    "ring_re_4",
    "ring_im_0",
    "ring_im_1",
    "ring_im_2",
    "ring_im_3",
    "ring_im_4",
    "ring_radius",
];

impl RunStats {
    fn of(seed: u64, c: &Crops) -> Self {
        let (np, nm, plus, minus) = c;
        Self {
            seed,
            n_plus: *np,
            n_minus: *nm,
            plus_core: [disc_mean(&plus[0], R), disc_mean(&plus[1], R)],
            minus_core: [disc_mean(&minus[0], R), disc_mean(&minus[1], R)],
            head_tail: [at(&plus[5], -1.5 * R, 0.0), at(&plus[5], 1.5 * R, 0.0)],
            vortex_pair: vorticity_at(&plus[0], &plus[1], 0.0, -1.5 * R)
                - vorticity_at(&plus[0], &plus[1], 0.0, 1.5 * R),
            ring: ring_coefficients(&minus[0], &minus[1], 1.5 * R),
        }
    }

    fn row(&self, pressure: &str) -> Vec<String> {
        [
            cell(pressure),
            cell(self.seed),
            cell(self.n_plus),
            cell(self.n_minus),
        ]
        .into_iter()
        .chain(
            self.plus_core
                .iter()
                .chain(&self.minus_core)
                .chain(&self.head_tail)
                .chain([&self.vortex_pair])
                .chain(self.ring.iter().map(|c| &c.0))
                .chain(self.ring.iter().map(|c| &c.1))
                .map(|v| sci(*v)),
        )
        .chain([cell(1.5 * R)])
        .collect()
    }

    /// The runs of `pressure` in a table that [`RunStats::row`] wrote.
    #[cfg(test)]
    fn from_table(t: &super::Table, pressure: &str) -> Result<Vec<Self>, SweepError> {
        let (pc, sc) = (t.col("pressure")?, t.col("seed")?);
        let cols: Vec<Vec<f64>> = RUN_COLUMNS[2..21]
            .iter()
            .map(|c| t.f64s(c))
            .collect::<Result<_, _>>()?;
        Ok(t.rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r[pc] == pressure)
            .map(|(k, r)| {
                let v = |i: usize| cols[i][k];
                Self {
                    seed: r[sc].parse().unwrap_or(0),
                    n_plus: v(0),
                    n_minus: v(1),
                    plus_core: [v(2), v(3)],
                    minus_core: [v(4), v(5)],
                    head_tail: [v(6), v(7)],
                    vortex_pair: v(8),
                    ring: std::array::from_fn(|m| (v(9 + m), v(14 + m))),
                }
            })
            .collect())
    }
}

/// The claims of the figure's table kept in `dir` (`defect_field_runs.csv`).
#[cfg(test)]
fn verdicts_from_tables(dir: &Path) -> Result<Vec<(String, Verdict)>, SweepError> {
    let t = super::Table::read(&dir.join("defect_field_runs.csv"))?;
    let mut out = Vec::new();
    for pressure in ["paper", "interaction"] {
        let runs = RunStats::from_table(&t, pressure)?;
        out.extend(
            claims(pressure, &runs)
                .into_iter()
                .map(|c| (c.claim, c.verdict)),
        );
    }
    Ok(out)
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let (res, t, from) = sweep(p)?;
    p.reporter.stage("defect-fields: averages and pictures");
    let points = res.points(None)?;
    let mut claims = Vec::new();
    let mut made = Made::new(Vec::new(), String::new());
    let columns: Vec<&str> = ["pressure", "charge", "u", "v"]
        .into_iter()
        .chain(COMPONENTS)
        .chain(["defects"])
        .collect();
    let mut csv = Csv::new(&columns);
    let mut runs_csv = Csv::new(&RUN_COLUMNS);
    for pressure in ["paper", "interaction"] {
        let recs = point(&points, &[pressure]).map_or(&[][..], |pt| &pt.runs);
        let runs: Vec<Crops> = recs
            .iter()
            .map(|r| read_crops(&r.run.join("analysis/defect_averages.npz")))
            .collect::<Result<_, _>>()?;
        let pooled = Pooled::of(&runs);
        pooled.rows(pressure, &mut csv);
        for (name, picture) in pooled.pictures(pressure) {
            made = made.plot(name, picture);
        }
        let stats: Vec<RunStats> = recs
            .iter()
            .zip(&runs)
            .map(|(r, c)| RunStats::of(r.seed, c))
            .collect();
        for st in &stats {
            runs_csv.row(st.row(pressure));
        }
        claims.extend(self::claims(pressure, &stats));
    }
    made.claims = claims;
    made.settings = settings(p, t, from);
    Ok(made
        .table("defect_fields.csv", csv)
        .table("defect_field_runs.csv", runs_csv))
}

/// The overrides of the paper's scene for the defect figures' tissue: 240 cells on 200² at
/// γ = 0.014, `t` TU active, a frame every 10 TU, the scale's integrator.
pub(crate) fn tissue_sets(scale: Scale, t: f64) -> Vec<String> {
    let mut sets = vec![
        "domain.lx=200".to_string(),
        "domain.ly=200".into(),
        "cells.count=240".into(),
        "model.gamma=0.014".into(),
        format!("run.time={t}"),
        "run.output_every=10".into(),
    ];
    sets.extend(scale.integrator());
    sets
}

/// The sweep: the paper's scene at ζ = 0.005, γ = 0.014, both pressure forms, with its
/// active time `t` and the time `from` which the frames are analysed.
fn sweep(p: &ReproduceParams) -> Result<(super::SweepResult, f64, f64), SweepError> {
    let t = match p.scale {
        Scale::Quick => 400.0,
        Scale::Paper => 1000.0,
    };
    let from = 200.0 + 0.5 * t;
    let mut sets = tissue_sets(p.scale, t);
    sets.push("model.zeta=0.005".into());
    let res = super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("defect-fields-{}", p.scale.name()),
            sets,
            varies: vec!["model.pressure=paper,interaction".into()],
            analyze: Some(AnalyzeOptions {
                from: Some(from),
                crop_side: Some(CROP),
                ..AnalyzeOptions::default()
            }),
            seeds: None,
        },
    )?;
    Ok((res, t, from))
}

/// The crops of every defect of every run of one pressure form, pooled: the number of +½
/// and −½ defects and their average fields.
struct Pooled {
    np: f64,
    plus: Vec<Vec<f64>>,
    nm: f64,
    minus: Vec<Vec<f64>>,
}

impl Pooled {
    /// The averages over every defect of every run (weighted by the defects of each run).
    fn of(runs: &[Crops]) -> Self {
        let pool = |plus: bool| -> (f64, Vec<Vec<f64>>) {
            let n: f64 = runs.iter().map(|r| if plus { r.0 } else { r.1 }).sum();
            let mut sum = vec![vec![0.0; CROP * CROP]; COMPONENTS.len()];
            for r in runs {
                let (w, f) = if plus { (r.0, &r.2) } else { (r.1, &r.3) };
                if w == 0.0 {
                    continue;
                }
                for (s, x) in sum.iter_mut().zip(f) {
                    for (a, b) in s.iter_mut().zip(x) {
                        *a += w * b / n;
                    }
                }
            }
            (n, sum)
        };
        let (np, plus) = pool(true);
        let (nm, minus) = pool(false);
        Self {
            np,
            plus,
            nm,
            minus,
        }
    }

    /// Its rows of `defect_fields.csv`: every crop node of both charges.
    fn rows(&self, pressure: &str, csv: &mut Csv) {
        let Self {
            np,
            plus,
            nm,
            minus,
        } = self;
        let (np, nm) = (*np, *nm);
        let h = (CROP / 2) as f64;
        for (charge, n, f) in [("+1/2", np, plus), ("-1/2", nm, minus)] {
            for k in 0..CROP * CROP {
                csv.row(
                    [
                        cell(pressure),
                        cell(charge),
                        cell((k / CROP) as f64 - h),
                        cell((k % CROP) as f64 - h),
                    ]
                    .into_iter()
                    .chain(f.iter().map(|c| sci(c[k])))
                    .chain([cell(n)]),
                );
            }
        }
    }

    /// Fig. 4a and 4b at one pressure form (each where it has a defect).
    fn pictures(&self, pressure: &str) -> Vec<(String, Picture)> {
        let Self {
            np,
            plus,
            nm,
            minus,
        } = self;
        let (np, nm) = (*np, *nm);
        let mut out = Vec::new();
        // The isotropic parts carry the mean pressure of the tissue: show their variation.
        let less_mean = |v: &[f64]| -> Vec<f64> {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            v.iter().map(|x| x - m).collect()
        };
        let panels = |f: &[Vec<f64>], name: &str, u: &str| {
            let axes = |h: Heatmap| h.with_axes(u, "v, nodes");
            vec![
                axes(
                    Heatmap::new("Q_xx, director lines (defect frame)", CROP, f[6].clone())
                        .with_director(f[6].clone(), f[7].clone()),
                ),
                axes(Heatmap::new("σ_xx − mean", CROP, less_mean(&f[2]))),
                axes(Heatmap::new("σ_xy", CROP, f[4].clone())),
                axes(
                    Heatmap::new("flow: v_u, arrows v", CROP, f[0].clone())
                        .with_arrows(f[0].clone(), f[1].clone()),
                ),
                axes(Heatmap::new("σ_yy − mean", CROP, less_mean(&f[3]))),
                axes(Heatmap::new(
                    format!("P − mean ({name} form)"),
                    CROP,
                    less_mean(&f[5]),
                )),
            ]
        };
        for (file, title, f, n, u) in [
            (
                "fig4a_plus",
                "+1/2",
                plus,
                np,
                "u, nodes (towards the tail, ∇·Q)",
            ),
            ("fig4b_minus", "−1/2", minus, nm, "u, nodes (along an arm)"),
        ] {
            if n == 0.0 {
                continue;
            }
            out.push((
            format!("{file}_{pressure}.png"),
            Picture::Heatmaps {
                title: format!("Fig. 4: averages around {n} {title} defects (ζ = 0.005, γ = 0.014, {pressure} pressure; u along the defect axis)"),
                panels: panels(f, pressure, u),
                cols: 3,
                panel_px: 380,
            },
        ));
        }
        out
    }
}

/// The statistics of the runs with +½ (`plus`) or −½ defects.
fn with(runs: &[RunStats], plus: bool) -> impl Iterator<Item = &RunStats> {
    runs.iter().filter(move |r| {
        if plus {
            r.n_plus > 0.0
        } else {
            r.n_minus > 0.0
        }
    })
}

/// A per-run statistic pooled over every defect: weighted by each run's defects.
fn pooled(runs: &[RunStats], plus: bool, f: impl Fn(&RunStats) -> f64) -> f64 {
    let n = |r: &RunStats| if plus { r.n_plus } else { r.n_minus };
    let total: f64 = runs.iter().map(n).sum();
    with(runs, plus).map(|r| n(r) * f(r) / total).sum()
}

/// The claims of Fig. 4 at one pressure form, from its runs' statistics.
fn claims(pressure: &str, runs: &[RunStats]) -> Vec<Claim> {
    let core = |plus: bool, comp: usize| -> Vec<f64> {
        with(runs, plus)
            .map(|r| {
                if plus {
                    r.plus_core[comp]
                } else {
                    r.minus_core[comp]
                }
            })
            .collect()
    };
    let (vu, vv) = (mean_std(&core(true, 0)), mean_std(&core(true, 1)));
    let plus_speed = vu.0.hypot(vv.0);
    let np: f64 = runs.iter().map(|r| r.n_plus).sum();
    let nm: f64 = runs.iter().map(|r| r.n_minus).sum();
    vec![
        propulsion_claim(pressure, np, &core(true, 0), &core(true, 1)),
        three_fold_claim(pressure, runs, nm, plus_speed),
        stress_claim(pressure, runs, np),
        vortex_claim(pressure, runs, np),
        drift_claim(pressure, nm, &core(false, 0), &core(false, 1), plus_speed),
        three_fold_each_claim(pressure, runs),
    ]
}

/// A +½ defect self-propels along its axis, towards its head.
fn propulsion_claim(pressure: &str, np: f64, pu: &[f64], pv: &[f64]) -> Claim {
    let (vu, vv) = (mean_std(pu), mean_std(pv));
    let (v_dir, why_dir) = propulsion(pu, pv);
    Claim::new(
        format!("9.6 ({pressure} pressure): a +1/2 defect self-propels along its axis, towards its head"),
        format!(
            "core (r ≤ R) velocity over {np} defects: along the axis v_u = {}, across v_v = {} (per-run spread); v_u {} 0: towards the {}",
            pm(vu),
            pm(vv),
            if vu.0 < 0.0 { "<" } else { ">" },
            if vu.0 < 0.0 { "head (−∇·Q), as in extensile active nematics" } else { "tail (+∇·Q), as in contractile active nematics" }
        ),
        if np == 0.0 { Verdict::Inconclusive } else { v_dir },
        why_dir,
    )
}

/// The flow around a −½ defect is three-fold (pooled).
fn three_fold_claim(pressure: &str, runs: &[RunStats], nm: f64, plus_speed: f64) -> Claim {
    let modes: [f64; 5] = std::array::from_fn(|m| {
        pooled(runs, false, |r| r.ring[m].0).hypot(pooled(runs, false, |r| r.ring[m].1))
    });
    let three = modes[3] > modes[1] && modes[3] > modes[2] && modes[3] > modes[4];
    let core_minus =
        pooled(runs, false, |r| r.minus_core[0]).hypot(pooled(runs, false, |r| r.minus_core[1]));
    Claim::new(
        format!("9.6 ({pressure} pressure): the flow around a −1/2 defect is three-fold"),
        format!(
            "radial velocity on the ring r = 1.5R over {nm} defects, Fourier amplitudes m = 0..4: {}; core speed {} (against {} for +1/2)",
            modes.iter().map(|m| g(*m)).collect::<Vec<_>>().join(", "),
            g(core_minus),
            g(plus_speed)
        ),
        if nm == 0.0 { Verdict::Inconclusive } else if three { Verdict::Holds } else { Verdict::DoesNotHold },
        if three {
            "the m = 3 mode dominates m = 1, 2 and 4"
        } else {
            "another mode than m = 3 dominates"
        },
    )
}

/// The isotropic stress −P at the head and the tail of +½ (u = ∓1.5R), pooled and per run
/// (the verdict reads the runs' signs).
fn stress_claim(pressure: &str, runs: &[RunStats], np: f64) -> Claim {
    let (head, tail) = (
        pooled(runs, true, |r| r.head_tail[0]),
        pooled(runs, true, |r| r.head_tail[1]),
    );
    let diffs: Vec<f64> = with(runs, true)
        .map(|r| r.head_tail[0] - r.head_tail[1])
        .collect();
    let (v_head, why_head) = same_sign(&diffs);
    Claim::new(
        format!("9.6 ({pressure} pressure): the isotropic stress around +1/2 follows the continuum and experimental pattern"),
        format!(
            "pressure P (isotropic stress −P) at 1.5R from the core along the axis, pooled: head side {} vs tail side {}; head − tail per run: {}",
            g(head),
            g(tail),
            diffs.iter().map(|d| g(*d)).collect::<Vec<_>>().join(", ")
        ),
        if np == 0.0 { Verdict::Inconclusive } else { v_head },
        why_head,
    )
}

/// The vortex pair of +½: per run, ω below the axis minus ω above it, at v = ∓1.5R.
fn vortex_claim(pressure: &str, runs: &[RunStats], np: f64) -> Claim {
    let pair: Vec<f64> = with(runs, true).map(|r| r.vortex_pair).collect();
    let (v_pair, why_pair) = sign_rule(
        &pair,
        &format!("counter-rotating vortices on the two sides of the axis in every one of {} runs, clear of 0 by two s.e.", pair.len()),
        "the vortices turn the other way round, by more than two standard errors: flow towards the tail along the axis",
        "runs have the pair turning as extensile self-propulsion makes it",
    );
    Claim::new(
        format!("9.6 ({pressure} pressure): a +1/2 defect carries a vortex pair, one on each side of its axis"),
        format!(
            "ω(0, −1.5R) − ω(0, +1.5R) per run: {}",
            pair.iter().map(|d| g(*d)).collect::<Vec<_>>().join(", ")
        ),
        if np == 0.0 { Verdict::Inconclusive } else { v_pair },
        why_pair,
    )
}

/// −½: no drift of the core (three-fold symmetry forbids one).
fn drift_claim(pressure: &str, nm: f64, du: &[f64], dv: &[f64], plus_speed: f64) -> Claim {
    let (v_drift, why_drift) = no_drift(du, dv, plus_speed);
    Claim::new(
        format!("9.6 ({pressure} pressure): a −1/2 defect does not self-propel (its three-fold symmetry forbids a drift)"),
        format!(
            "core (r ≤ R) velocity per run along an arm {}, across {}; +1/2 core speed {}",
            du.iter().map(|d| g(*d)).collect::<Vec<_>>().join(", "),
            dv.iter().map(|d| g(*d)).collect::<Vec<_>>().join(", "),
            g(plus_speed)
        ),
        if nm == 0.0 { Verdict::Inconclusive } else { v_drift },
        why_drift,
    )
}

/// The −½ flow is three-fold in every run: m = 3 run by run.
fn three_fold_each_claim(pressure: &str, runs: &[RunStats]) -> Claim {
    let per_run_modes: Vec<[f64; 5]> = with(runs, false)
        .map(|r| r.ring.map(|(a, b)| a.hypot(b)))
        .collect();
    let three_each = per_run_modes
        .iter()
        .filter(|m| m[3] > m[1] && m[3] > m[2] && m[3] > m[4])
        .count();
    Claim::new(
        format!("9.6 ({pressure} pressure): the −1/2 flow is three-fold in every run"),
        format!(
            "m = 3 the largest of m = 1..4 in {three_each} of {} runs; m = 1 / m = 3 per run: {}",
            per_run_modes.len(),
            per_run_modes.iter().map(|m| g(m[1] / m[3])).collect::<Vec<_>>().join(", ")
        ),
        if per_run_modes.len() < 3 {
            Verdict::Inconclusive
        } else if three_each == per_run_modes.len() {
            Verdict::Holds
        } else if 2 * three_each < per_run_modes.len() {
            Verdict::DoesNotHold
        } else {
            Verdict::Inconclusive
        },
        "holds when m = 3 leads in every run (at least three), does not hold when it leads in fewer than half, inconclusive between",
    )
}

/// The figure's settings, for its verdict.
fn settings(p: &ReproduceParams, t: f64, from: f64) -> String {
    format!(
        "- Paper scene on L = 200 (240 cells), ζ = 0.005, γ = 0.014, both pressure forms; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; integrator {}; a frame every 10 TU, analysed from t = {from}.\n\
         - Each ±1/2 defect of the smoothed Q (3R box): the raw fields cropped {CROP}×{CROP} around it, rotated into its frame (u along its axis: for +1/2 the direction of ∇·Q, i.e. towards the tail; for −1/2 one of its arms) and averaged over every defect of every frame and run.\n\
         - σ = −P·1 − ζQ (docs/model.md §3), so the isotropic stress is −P.\n\
         - Files: `defect_fields.csv` (every crop node, both charges and forms), `fig4a_plus_*.png`, `fig4b_minus_*.png`.",
        p.scale.seeds(),
        p.scale.integrator_name()
    )
}

/// The verdict on "a +½ defect self-propels along its axis, towards its head" from each run's
/// mean core velocity along the axis `vu` (positive towards the tail, `∇·Q`) and across it `vv`,
/// by the rule of an effect ([`super::rule::Rule::effect`]): the effect is the mean core speed
/// towards the head, `−⟨vu⟩` over runs, and the smallest that counts is 3× the mean speed
/// across the axis, `3 |⟨vv⟩|` (motion along the axis). Holds when the effect is resolved by two
/// standard errors and at least that; does not hold when it is below that by two standard
/// errors (towards the tail, as a contractile defect, or not along the axis); inconclusive
/// otherwise, and with fewer than two runs.
fn propulsion(vu: &[f64], vv: &[f64]) -> (Verdict, String) {
    if vu.len() < 2 {
        return (
            Verdict::Inconclusive,
            format!("{} runs with +1/2 defects: too few for a spread", vu.len()),
        );
    }
    let (mu, se) = mean_se(vu);
    let (mv, _) = mean_std(vv);
    let rule = super::rule::Rule::effect(
        "the core speed towards the head, −⟨v_u⟩ over runs, against 3× the speed across the axis",
        (3.0 * mv.abs()).max(f64::MIN_POSITIVE),
    );
    let o = rule.decide(-mu, se);
    (o.verdict, o.why)
}

/// The vorticity `∂_u v_v − ∂_v v_u` of a crop at `(u, v)`, by central differences two nodes
/// wide (bilinear values).
fn vorticity_at(vu: &[f64], vv: &[f64], u: f64, v: f64) -> f64 {
    (at(vv, u + 2.0, v) - at(vv, u - 2.0, v)) / 4.0
        - (at(vu, u, v + 2.0) - at(vu, u, v - 2.0)) / 4.0
}

/// No drift of the −½ core: per-run core velocities `du` (along an arm) and `dv` (across), against
/// the +½ core speed `plus`, by the rule of an absence ([`super::rule::Rule::absence`]): the
/// effect is the mean core speed `|(⟨du⟩, ⟨dv⟩)|` with its standard error (propagated from the
/// two components'), and the smallest drift that counts is a quarter of `plus`. Holds when the
/// speed is below that by two standard errors; does not hold when it is resolved and at least
/// that; inconclusive otherwise, and with fewer than two runs.
fn no_drift(du: &[f64], dv: &[f64], plus: f64) -> (Verdict, String) {
    if du.len() < 2 {
        return (
            Verdict::Inconclusive,
            format!("{} runs with −1/2 defects: too few for a spread", du.len()),
        );
    }
    let (mu, su) = mean_se(du);
    let (mv, sv) = mean_se(dv);
    let speed = mu.hypot(mv);
    // The error of |(mu, mv)| to first order; at zero speed, the larger component error.
    let s = if speed > 0.0 {
        (mu * su).hypot(mv * sv) / speed
    } else {
        su.max(sv)
    };
    let rule = super::rule::Rule::absence(
        format!(
            "the −1/2 core speed, from ({} ± {}, {} ± {}) s.e. ({} of the +1/2 core speed)",
            g(mu),
            g(su),
            g(mv),
            g(sv),
            g(speed / plus)
        ),
        0.25 * plus,
    );
    let o = rule.decide(speed, s);
    (o.verdict, o.why)
}

/// The verdict on a sign claim measured once per run (`d` > 0 claimed): holds when every run
/// (at least three) has the sign and the mean is above 0 by two standard errors; does not hold
/// when the mean is below 0 by two standard errors; inconclusive otherwise (runs disagree, or
/// too few).
fn same_sign(d: &[f64]) -> (Verdict, String) {
    sign_rule(
        d,
        &format!("more compressive at the head than at the tail in every one of {} runs (the sign Saw et al. (2017) measured in MDCK monolayers, which the paper cites); no continuum magnitude is checked", d.len()),
        "the head is less compressed than the tail, by more than two standard errors over runs: the opposite of Saw et al. (2017)",
        "runs have the head more compressed",
    )
}

/// A sign claim measured once per run (`d` > 0 claimed): holds when every run (at least three)
/// has the sign and the mean is above 0 by two standard errors (`holds` says why); does not
/// hold when the mean is below 0 by two standard errors (`fails`); inconclusive otherwise.
fn sign_rule(d: &[f64], holds: &str, fails: &str, counted: &str) -> (Verdict, String) {
    if d.len() < 3 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} runs: too few to judge the sign run by run (three needed)",
                d.len()
            ),
        );
    }
    let (m, se) = mean_se(d);
    let positive = d.iter().filter(|x| **x > 0.0).count();
    // A sign: the rule of an effect whose smallest size that counts is any (the least positive
    // number), so that it holds when the mean is above 0 by two s.e. and does not hold when it
    // is below 0 by two.
    let o = super::rule::Rule::effect("the per-run mean", f64::MIN_POSITIVE).decide(m, se);
    if o.verdict == Verdict::Holds && positive == d.len() {
        (Verdict::Holds, holds.to_string())
    } else if o.verdict == Verdict::DoesNotHold {
        (Verdict::DoesNotHold, fails.to_string())
    } else {
        (Verdict::Inconclusive, format!("{positive} of {} {counted}: the runs disagree, or the mean is within two standard errors of 0", d.len()))
    }
}

#[cfg(test)]
mod tests {
    /// The defect-fields section of docs/reproduction.md states the verdicts of the figure's
    /// runs, kept in `docs/data/defect-fields/quick/defect_field_runs.csv`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let dir = crate::stored_tables("defect-fields/quick");
        let want = super::verdicts_from_tables(&dir).unwrap();
        assert_eq!(want.len(), 12);
        crate::assert_doc_verdicts("defect-fields", "**Verdicts (quick):**", &want);
    }

    /// The pooled statistics read from the runs' equal those of the pooled crops: the ring's
    /// Fourier amplitudes and the pressure at the head, on synthetic crops of two runs.
    #[test]
    fn pooling_the_runs_statistics_pools_the_crops() {
        use super::*;
        let field = |a: f64, b: f64| -> Vec<f64> {
            (0..CROP * CROP)
                .map(|k| {
                    let (u, v) = ((k / CROP) as f64 - 30.0, (k % CROP) as f64 - 30.0);
                    a * (0.3 * u).sin() * (0.2 * v).cos() + b * u * v / 900.0
                })
                .collect()
        };
        let crops = |a: f64, b: f64, n: f64| -> Crops {
            let comps: Vec<Vec<f64>> = (0..COMPONENTS.len())
                .map(|c| field(a + c as f64, b - c as f64))
                .collect();
            (n, n + 1.0, comps.clone(), comps)
        };
        let runs = [crops(1.0, 0.5, 3.0), crops(-0.4, 2.0, 7.0)];
        let stats: Vec<RunStats> = runs.iter().map(|c| RunStats::of(1, c)).collect();
        let pool = Pooled::of(&runs);
        let direct = ring_modes(&pool.minus[0], &pool.minus[1], 1.5 * R);
        for (m, d) in direct.iter().enumerate() {
            let from_runs =
                pooled(&stats, false, |r| r.ring[m].0)
                    .hypot(pooled(&stats, false, |r| r.ring[m].1));
            assert!(
                (from_runs - d).abs() <= 1e-12 * d.abs().max(1e-3),
                "m = {m}"
            );
        }
        let head = at(&pool.plus[5], -1.5 * R, 0.0);
        assert!((pooled(&stats, true, |r| r.head_tail[0]) - head).abs() < 1e-12);
    }
    /// The +½ rule gives each outcome on synthetic per-run core velocities.
    #[test]
    fn the_propulsion_rule_gives_each_outcome() {
        use super::{propulsion, Verdict};
        let across = [0.001, -0.001, 0.0005];
        assert_eq!(
            propulsion(&[-0.02, -0.025, -0.022], &across).0,
            Verdict::Holds
        );
        assert_eq!(
            propulsion(&[0.02, 0.025, 0.022], &across).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            propulsion(&[-0.02, -0.025, -0.022], &[0.02, 0.02, 0.02]).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            propulsion(&[-0.02, 0.025, -0.002], &across).0,
            Verdict::Inconclusive
        );
        assert_eq!(propulsion(&[-0.02], &[0.0]).0, Verdict::Inconclusive);
    }

    /// The per-run sign rule: all runs agree and clear of 0 holds; one run against is
    /// inconclusive (the pooled mean could still be positive); clearly negative does not hold.
    #[test]
    fn the_drift_rule_gives_each_outcome() {
        use super::{no_drift, Verdict};
        assert_eq!(
            no_drift(&[1e-4, -1e-4, 0.0], &[0.0, 1e-4, -1e-4], 0.01).0,
            Verdict::Holds
        );
        assert_eq!(
            no_drift(&[0.005, 0.006, 0.0055], &[0.0, 1e-4, -1e-4], 0.01).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            no_drift(&[0.009, -0.001, 0.008], &[0.0, 1e-4, -1e-4], 0.01).0,
            Verdict::Inconclusive
        );
    }

    /// A vortex pair of the sense extensile propulsion drives has ω > 0 below the axis.
    #[test]
    fn vorticity_of_a_vortex_pair() {
        use super::{vorticity_at, CROP};
        // v_u = −cos(π v/40): flow towards −u on the axis, back along ±20.
        let h = (CROP / 2) as f64;
        let mut vu = vec![0.0; CROP * CROP];
        for k in 0..CROP * CROP {
            let v = (k % CROP) as f64 - h;
            vu[k] = -(std::f64::consts::PI * v / 40.0).cos();
        }
        let vv = vec![0.0; CROP * CROP];
        let below = vorticity_at(&vu, &vv, 0.0, -12.0);
        let above = vorticity_at(&vu, &vv, 0.0, 12.0);
        assert!(below > 0.0 && above < 0.0 && (below + above).abs() < 1e-12);
    }

    #[test]
    fn the_sign_rule_gives_each_outcome() {
        use super::{same_sign, Verdict};
        assert_eq!(same_sign(&[0.01, 0.012, 0.011]).0, Verdict::Holds);
        assert_eq!(same_sign(&[0.03, 0.02, -0.005]).0, Verdict::Inconclusive);
        assert_eq!(same_sign(&[-0.01, -0.012, -0.011]).0, Verdict::DoesNotHold);
        assert_eq!(same_sign(&[0.01, 0.02]).0, Verdict::Inconclusive);
    }

    use super::*;

    /// A purely radial flow v_r = cos 3φ (the linear active flow of a −½ defect) has all its
    /// ring amplitude in m = 3, half the peak; a uniform flow along u is m = 1 and its disc
    /// mean is the flow itself.
    #[test]
    fn ring_modes_find_a_three_fold_flow() {
        let h = (CROP / 2) as f64;
        let (mut vu, mut vv) = (vec![0.0; CROP * CROP], vec![0.0; CROP * CROP]);
        for k in 0..CROP * CROP {
            let (u, v) = ((k / CROP) as f64 - h, (k % CROP) as f64 - h);
            let phi = v.atan2(u);
            let vr = (3.0 * phi).cos();
            vu[k] = vr * phi.cos();
            vv[k] = vr * phi.sin();
        }
        let m = ring_modes(&vu, &vv, 12.0);
        assert!((m[3] - 0.5).abs() < 0.03, "{m:?}");
        assert!(m[1] < 0.03 && m[2] < 0.03 && m[4] < 0.03, "{m:?}");
        let ones = vec![1.0; CROP * CROP];
        let zeros = vec![0.0; CROP * CROP];
        let m = ring_modes(&ones, &zeros, 12.0);
        assert!((m[1] - 0.5).abs() < 1e-12 && m[3] < 1e-12, "{m:?}");
        assert!((disc_mean(&ones, R) - 1.0).abs() < 1e-12);
        // Bilinear interpolation is exact on a linear field.
        let lin: Vec<f64> = (0..CROP * CROP).map(|k| (k / CROP) as f64 - h).collect();
        assert!((at(&lin, 3.25, -7.5) - 3.25).abs() < 1e-12);
    }
}
