//! `reproduce lengths`: Fig. 3 (the vorticity correlation and its length against ζ and γ)
//! and the supplementary velocity and Q length figures.

use std::path::Path;

use render::{Plot, Series};

use super::column_stats;
use super::pipeline::{cell, point, sci, Csv, Made, PointRuns};
use super::AtValue;
use super::{g, mean_std, Claim, Rec, ReproduceParams, Scale, SweepJob, SweepResult, Verdict};
use study::analyze::AnalyzeOptions;
use study::SweepError;

/// The activities of the ζ sweep (γ = 0.01).
pub(super) const ZETAS: [&str; 6] = ["0", "0.002", "0.004", "0.006", "0.008", "0.012"];
/// The stiffnesses of the γ sweep, at ζ = [`ZETA_OF_GAMMA_SWEEP`].
pub(super) const GAMMAS: [&str; 4] = ["0.006", "0.01", "0.014", "0.02"];
/// The activity of the γ sweep.
pub(super) const ZETA_OF_GAMMA_SWEEP: &str = "0.01";
/// Activities at or above this are in active turbulence for every γ of the figures.
const ACTIVE: f64 = 0.004;

/// The active time of the turbulence runs and the first analysed time.
pub(super) fn times(scale: Scale) -> (f64, f64) {
    let t = match scale {
        Scale::Quick => 400.0,
        Scale::Paper => 1000.0,
    };
    (t, 200.0 + 0.5 * t)
}

/// The two analysed sweeps of active turbulence on L = 200 (240 cells, the paper's Fig. 2a
/// and 3 size): ζ at γ = 0.01, and γ at ζ = 0.01. Shared with `reproduce defects`.
pub(super) fn turbulence(p: &ReproduceParams) -> Result<(SweepResult, SweepResult), SweepError> {
    let (t, from) = times(p.scale);
    let mut sets = vec![
        "domain.lx=200".to_string(),
        "domain.ly=200".into(),
        "cells.count=240".into(),
        format!("run.time={t}"),
        "run.output_every=10".into(),
    ];
    sets.extend(p.scale.integrator());
    let analyze = Some(AnalyzeOptions {
        from: Some(from),
        ..AnalyzeOptions::default()
    });
    let zeta = super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("turbulence-zeta-{}", p.scale.name()),
            sets: sets.clone(),
            varies: vec![
                format!("model.pressure={}", PRESSURES.join(",")),
                format!("model.zeta={}", ZETAS.join(",")),
            ],
            analyze: analyze.clone(),
            seeds: None,
        },
    )?;
    let mut gsets = sets;
    gsets.push(format!("model.zeta={ZETA_OF_GAMMA_SWEEP}"));
    let gamma = super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("turbulence-gamma-{}", p.scale.name()),
            sets: gsets,
            varies: vec![
                format!("model.pressure={}", PRESSURES.join(",")),
                format!("model.gamma={}", GAMMAS.join(",")),
            ],
            analyze,
            seeds: None,
        },
    )?;
    Ok((zeta, gamma))
}

/// Both pressure forms, compared on every figure (issue 11).
pub(super) const PRESSURES: [&str; 2] = ["paper", "interaction"];

/// The seed statistics of a column of an analysed summary whose axes are
/// `[model.pressure, X]`, for one pressure form, per value of `X`.
pub(super) fn by_value(
    res: &SweepResult,
    pressure: &str,
    values: &[&str],
    column: &str,
) -> Result<Vec<AtValue>, SweepError> {
    let axis = res.summary.header[1].clone();
    let groups = res
        .summary
        .group(&["model.pressure", axis.as_str()], column)?;
    Ok(values
        .iter()
        .filter_map(|v| {
            groups
                .iter()
                .find(|g| g.0[0] == pressure && g.0[1] == *v)
                .map(|g| {
                    (
                        v.parse().unwrap_or(f64::NAN),
                        mean_std(&g.1),
                        g.1.iter().filter(|x| x.is_finite()).count(),
                    )
                })
        })
        .collect())
}

/// The smallest change across a range that counts, as a fraction of the first value: 10 %.
pub(super) const SMALLEST_CHANGE: f64 = 0.1;

/// A quantity's change across an axis, judged by the rule of an effect
/// ([`super::rule::Rule::effect`]).
pub(super) struct Trend {
    pub verdict: Verdict,
    /// The statistic: the first and last values, the change with its error, the slope.
    pub measured: String,
    /// The rule's reading.
    pub why: String,
}

/// Whether a quantity moves with the axis in the expected direction (`sign` ±1), from its
/// first to its last point: the change, in the claim's direction, with the standard error of
/// the difference of the two means, against the smallest change that counts,
/// [`SMALLEST_CHANGE`] of the first value. Holds when the change is resolved by two standard
/// errors and at least that; does not hold when it is below that by two standard errors (no
/// change of that size, or a change the other way); inconclusive otherwise.
pub(super) fn trend(pts: &[AtValue], sign: f64) -> Trend {
    let pts: Vec<&AtValue> = pts.iter().filter(|p| p.1 .0.is_finite()).collect();
    let (Some(a), Some(b)) = (pts.first(), pts.last()) else {
        return Trend {
            verdict: Verdict::Inconclusive,
            measured: "no finite value".into(),
            why: "not measured".into(),
        };
    };
    if pts.len() < 2 {
        return Trend {
            verdict: Verdict::Inconclusive,
            measured: "a single point".into(),
            why: "a change needs two points".into(),
        };
    }
    let se = |p: &AtValue| p.1 .1 / (p.2.max(1) as f64).sqrt();
    let d = b.1 .0 - a.1 .0;
    let err = (se(a).powi(2) + se(b).powi(2)).sqrt();
    let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1 .0).collect();
    let slope = study::summary::slope(&x, &y);
    let measured = format!(
        "from {} at {} to {} at {} (change {} ± {} s.e.; slope {})",
        g(a.1 .0),
        a.0,
        g(b.1 .0),
        b.0,
        g(d),
        g(err),
        g(slope)
    );
    let rule = super::rule::Rule::effect(
        if sign > 0.0 { "the rise" } else { "the fall" },
        SMALLEST_CHANGE * a.1 .0.abs(),
    );
    let o = rule.decide(sign * d, err);
    Trend {
        verdict: o.verdict,
        measured,
        why: format!(
            "{} ({} % of the first value counts)",
            o.why,
            g(100.0 * SMALLEST_CHANGE)
        ),
    }
}

const FIELDS: [(&str, &str); 3] = [
    ("vorticity", "length_vorticity"),
    ("velocity", "length_velocity"),
    ("Q", "length_q"),
];

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let (zeta, gamma) = turbulence(p)?;
    p.reporter.stage("lengths: tables and plots");
    let active: Vec<&str> = ZETAS
        .iter()
        .copied()
        .filter(|z| z.parse::<f64>().unwrap_or(0.0) >= ACTIVE)
        .collect();
    let points = zeta.points(None)?;
    let box_side = analysis::smooth::paper_box_side(8.0) as f64;
    let mut made = Made::new(Vec::new(), String::new());
    let mut corr_csv = Csv::new(&[
        "pressure",
        "zeta",
        "r",
        "c_velocity",
        "c_velocity_std",
        "c_vorticity",
        "c_vorticity_std",
        "c_q",
        "c_q_std",
    ]);
    let mut claims = Vec::new();
    let mut csv_z = Csv::new(&["pressure", "zeta", "field", "length", "length_std", "seeds"]);
    let mut csv_g = Csv::new(&[
        "pressure",
        "gamma",
        "field",
        "length",
        "length_std",
        "seeds",
    ]);
    for pressure in PRESSURES {
        let [c_vorticity, c_velocity, c_q] =
            correlation_plots(&points, pressure, &active, &mut corr_csv)?;
        made = made
            .plot(format!("fig3a_c_vorticity_{pressure}.png"), c_vorticity)
            .plot(format!("c_velocity_{pressure}.png"), c_velocity)
            .plot(format!("c_q_{pressure}.png"), c_q);
        let lengths = Lengths {
            zeta: &zeta,
            gamma: &gamma,
            active: &active,
            box_side,
        };
        let (pz, pg) = lengths.plots(pressure, [&mut csv_z, &mut csv_g], &mut claims)?;
        made = made
            .plot(format!("fig3b_lengths_vs_zeta_{pressure}.png"), pz)
            .plot(format!("fig3c_lengths_vs_gamma_{pressure}.png"), pg);
    }
    made = made.table("net_flow.csv", net_flows(p, &points, &active, &mut claims)?);
    let (v_csv, v_plots) = v_rms_raw_smooth(&points)?;
    for (name, plot) in v_plots {
        made = made.plot(name, plot);
    }
    made = made
        .table("v_rms_raw_smooth.csv", v_csv)
        .table("correlations.csv", corr_csv)
        .table("lengths_vs_zeta.csv", csv_z)
        .table("lengths_vs_gamma.csv", csv_g);
    made.claims = claims;
    made.settings = settings(p, box_side);
    Ok(made)
}

/// The runs of the ζ sweep at one pressure form and activity.
fn runs_of<'a>(points: &'a [PointRuns], pressure: &str, z: &str) -> Vec<&'a Rec> {
    point(points, &[pressure, z]).map_or(Vec::new(), PointRuns::refs)
}

/// The correlation curves of one pressure form, averaged over seeds, per ζ of `active`
/// (rows into `corr_csv`): the vorticity's (Fig. 3a), the velocity's and Q's.
fn correlation_plots(
    points: &[PointRuns],
    pressure: &str,
    active: &[&str],
    corr_csv: &mut Csv,
) -> Result<[Plot; 3], SweepError> {
    let mut plots = [
        Plot::new(
            format!("Fig. 3a: vorticity autocorrelation ({pressure} pressure)"),
            "r (nodes)",
            "C_ω(r)",
        ),
        Plot::new(
            format!("Velocity autocorrelation ({pressure} pressure)"),
            "r (nodes)",
            "C_v(r)",
        ),
        Plot::new(
            format!("Q autocorrelation ({pressure} pressure)"),
            "r (nodes)",
            "C_Q(r)",
        ),
    ];
    for pl in &mut plots {
        pl.hlines.push((0.0, String::new()));
        pl.legend = render::LegendAt::UpperRight;
    }
    for z in active {
        let runs = runs_of(points, pressure, z);
        let cols = ["c_velocity", "c_vorticity", "c_q"];
        let rows = column_stats(&runs, "analysis/correlations.csv", "r", &cols, 1)?;
        if rows.is_empty() {
            continue;
        }
        let r: Vec<f64> = rows.iter().map(|row| row.0).collect();
        let mut stats = vec![Vec::new(); 3];
        for (rk, st) in &rows {
            corr_csv.row(
                [cell(pressure), cell(z), cell(rk)]
                    .into_iter()
                    .chain(st.iter().flat_map(|s| [sci(s.0), sci(s.1)])),
            );
            for (c, s) in st.iter().enumerate() {
                stats[c].push(*s);
            }
        }
        // Out to r = 50 (a quarter of the box): the minimum sits well inside.
        let n = r.len().min(51);
        for (pl, c) in plots.iter_mut().zip([1, 0, 2]) {
            let m: Vec<f64> = stats[c][..n].iter().map(|s| s.0).collect();
            let e: Vec<f64> = stats[c][..n]
                .iter()
                .enumerate()
                .map(|(k, s)| if k % 5 == 0 { s.1 } else { 0.0 })
                .collect();
            pl.series
                .push(Series::new(format!("ζ = {z}")).with_points(&r[..n], &m, &e));
        }
    }
    Ok(plots)
}

/// The correlation lengths against ζ and γ.
struct Lengths<'a> {
    zeta: &'a SweepResult,
    gamma: &'a SweepResult,
    active: &'a [&'a str],
    box_side: f64,
}

impl Lengths<'_> {
    /// Fig. 3b and 3c at one pressure form, with their rows (`[ζ, γ]`) and claims.
    fn plots(
        &self,
        pressure: &str,
        [csv_z, csv_g]: [&mut Csv; 2],
        claims: &mut Vec<Claim>,
    ) -> Result<(Plot, Plot), SweepError> {
        let Self {
            zeta,
            gamma,
            active,
            box_side,
        } = *self;
        let mut pz = Plot::new(
            format!("Fig. 3b: correlation lengths against ζ (γ = 0.01, {pressure} pressure)"),
            "activity ζ",
            "first minimum of C(r) (nodes)",
        );
        let mut pg = Plot::new(
        format!("Fig. 3c: correlation lengths against γ (ζ = {ZETA_OF_GAMMA_SWEEP}, {pressure} pressure)"),
        "interface stiffness γ",
        "first minimum of C(r) (nodes)",
    );
        pz.hlines
            .push((box_side, format!("smoothing box side {box_side}")));
        pg.hlines
            .push((box_side, format!("smoothing box side {box_side}")));
        for (name, col) in FIELDS {
            let lz = by_value(zeta, pressure, active, col)?;
            let lg = by_value(gamma, pressure, &GAMMAS, col)?;
            for (csv, pts) in [(&mut *csv_z, &lz), (&mut *csv_g, &lg)] {
                for (x, (m, s), n) in pts {
                    csv.row([
                        cell(pressure),
                        cell(x),
                        cell(name),
                        cell(m),
                        cell(s),
                        cell(n),
                    ]);
                }
            }
            let series = |pts: &[AtValue]| {
                let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
                let m: Vec<f64> = pts.iter().map(|p| p.1 .0).collect();
                let e: Vec<f64> = pts.iter().map(|p| p.1 .1).collect();
                Series::new(format!("{name} length")).with_points(&x, &m, &e)
            };
            pz.series.push(series(&lz));
            pg.series.push(series(&lg));
            let (tz, tg) = (trend(&lz, -1.0), trend(&lg, 1.0));
            let floor = |pts: &[AtValue]| {
                pts.iter()
                    .map(|p| p.1 .0)
                    .filter(|v| v.is_finite())
                    .fold(f64::INFINITY, f64::min)
                    / box_side
            };
            claims.push(Claim::new(
                length_claim(pressure, name, true),
                format!(
                    "{}; the shortest is {}× the smoothing box ({box_side})",
                    tz.measured,
                    g(floor(&lz))
                ),
                tz.verdict,
                tz.why,
            ));
            claims.push(Claim::new(
                length_claim(pressure, name, false),
                format!(
                    "{}; the shortest is {}× the smoothing box ({box_side})",
                    tg.measured,
                    g(floor(&lg))
                ),
                tg.verdict,
                tg.why,
            ));
        }
        Ok((pz, pg))
    }
}

/// No net flow of the whole tissue: the mean cell velocity `U(t) = ⟨v_i⟩` over the frames of
/// the second half, against the cell speed, per run (the table) and per pressure form (a
/// claim each).
fn net_flows(
    p: &ReproduceParams,
    points: &[PointRuns],
    active: &[&str],
    claims: &mut Vec<Claim>,
) -> Result<Csv, SweepError> {
    let (_, from) = times(p.scale);
    let mut flow_csv = Csv::new(&[
        "pressure",
        "zeta",
        "seed",
        "net_flow",
        "cell_speed_rms",
        "ratio",
        "cells",
    ]);
    for pressure in PRESSURES {
        let mut ratios = Vec::new();
        let mut cells = 0usize;
        for z in active {
            for r in runs_of(points, pressure, z) {
                let (u, speed, n) = net_flow(&r.run, from)?;
                cells = n;
                flow_csv.row([
                    cell(pressure),
                    cell(z),
                    cell(r.seed),
                    sci(u),
                    sci(speed),
                    sci(u / speed),
                    cell(n),
                ]);
                ratios.push(u / speed);
            }
        }
        let (v, why) = rule_net_flow(&ratios, cells);
        claims.push(Claim::new(
            net_flow_claim(pressure),
            format!(
                "|⟨U⟩_t| / v_cell over {} runs: {}",
                ratios.len(),
                super::pm(mean_std(&ratios))
            ),
            v,
            why,
        ));
    }
    Ok(flow_csv)
}

/// Fig. 2a at L = 200 as the paper draws it: v_rms of the raw flow and of the flow smoothed
/// over the 3R box, time means over the analysed frames, against ζ: the table and a plot per
/// pressure form (where any value is positive).
fn v_rms_raw_smooth(points: &[PointRuns]) -> Result<(Csv, Vec<(String, Plot)>), SweepError> {
    let mut plots = Vec::new();
    let mut v_csv = Csv::new(&[
        "pressure",
        "zeta",
        "v_rms",
        "v_rms_std",
        "v_rms_smooth",
        "v_rms_smooth_std",
        "seeds",
    ]);
    for pressure in PRESSURES {
        let mut plot = Plot::new(
            format!("Fig. 2a at L = 200: v_rms raw and smoothed over 3R ({pressure} pressure)"),
            "activity ζ",
            "v_rms (mean ± std over seeds)",
        );
        plot.log_y = true;
        let (mut zs, mut raw, mut smooth) = (Vec::new(), Vec::new(), Vec::new());
        for z in ZETAS {
            let runs = runs_of(points, pressure, z);
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for run in &runs {
                let t = super::Table::read(&run.run.join("analysis/observables.csv"))?;
                let mean = |c: &str| {
                    t.f64s(c).ok().map_or(f64::NAN, |v| {
                        let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
                        v.iter().sum::<f64>() / v.len().max(1) as f64
                    })
                };
                a.push(mean("v_rms"));
                b.push(mean("v_rms_smooth"));
            }
            let (ma, sa) = mean_std(&a);
            let (mb, sb) = mean_std(&b);
            v_csv.row([
                cell(pressure),
                cell(z),
                sci(ma),
                sci(sa),
                sci(mb),
                sci(sb),
                cell(runs.len()),
            ]);
            zs.push(z.parse::<f64>().unwrap_or(f64::NAN));
            raw.push((ma, sa));
            smooth.push((mb, sb));
        }
        for (label, pts) in [("raw", &raw), ("smoothed over the 3R box", &smooth)] {
            let m: Vec<f64> = pts.iter().map(|p| p.0).collect();
            let e: Vec<f64> = pts.iter().map(|p| p.1).collect();
            plot.series
                .push(Series::new(label).with_points(&zs, &m, &e));
        }
        if plot
            .series
            .iter()
            .any(|s| s.points.iter().any(|p| p.1 > 0.0))
        {
            plots.push((format!("fig2a_v_rms_raw_smooth_{pressure}.png"), plot));
        }
    }
    Ok((v_csv, plots))
}

/// The figure's settings, for its verdict.
fn settings(p: &ReproduceParams, box_side: f64) -> String {
    let (t, from) = times(p.scale);
    format!(
        "- Paper scene on L = 200 (240 cells, as the paper's Fig. 2a), both pressure forms. ζ sweep at γ = 0.01: ζ ∈ {{{}}} (lengths for ζ ≥ {ACTIVE}); γ sweep at ζ = {ZETA_OF_GAMMA_SWEEP}: γ ∈ {{{}}}; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; integrator {}; a frame every 10 TU, analysed from t = {from} (the second half of the active phase).\n\
         - `monolayer analyze` on every run: v, ω and Q smoothed with a periodic {box_side}×{box_side} box (3R), their autocorrelations averaged over the frames; a length is the first minimum of the radially averaged correlation.\n\
         - Net flow: per run, `|⟨U⟩_t|`, the time mean over the analysed frames of the mean cell velocity `U = ⟨v_i⟩_i`, over the rms cell speed (`net_flow.csv`); the verdict compares the runs' mean ± 2 s.e. with `1/√N`.\n\
         - Fig. 2a as the paper draws it (L = 200): the time mean over the analysed frames of v_rms of the raw flow and of the flow smoothed over the 3R box (`v_rms_smooth` of `analysis/observables.csv`), mean ± std over seeds (`v_rms_raw_smooth.csv`, `fig2a_v_rms_raw_smooth_*.png`). The threshold figure's v_rms is the raw one.\n\
         - Files: `net_flow.csv`, `correlations.csv`, `lengths_vs_zeta.csv`, `lengths_vs_gamma.csv`, `fig3a_c_vorticity_*.png`, `c_velocity_*.png`, `c_q_*.png`, `fig3b_lengths_vs_zeta_*.png`, `fig3c_lengths_vs_gamma_*.png` (one per pressure form); the runs in `../sweeps/turbulence-*`.",
        ZETAS.join(", "),
        GAMMAS.join(", "),
        p.scale.seeds(),
        p.scale.integrator_name()
    )
}

/// The claim of a length's trend against ζ (`against_zeta`) or against γ.
fn length_claim(pressure: &str, name: &str, against_zeta: bool) -> String {
    if against_zeta {
        format!("9.4 ({pressure} pressure): the {name} length shrinks as ζ grows (γ = 0.01, ζ ≥ {ACTIVE})")
    } else {
        format!(
            "9.4 ({pressure} pressure): the {name} length grows with γ (ζ = {ZETA_OF_GAMMA_SWEEP})"
        )
    }
}

/// The claim of no net flow.
fn net_flow_claim(pressure: &str) -> String {
    format!("No net flow of the whole tissue ({pressure} pressure, γ = 0.01, ζ ≥ {ACTIVE}; the paper's periodic tissue has none)")
}

/// The figure's verdicts from its own tables in `dir` (`lengths_vs_zeta.csv`,
/// `lengths_vs_gamma.csv`, `net_flow.csv`, as [`make`] writes them), by the rules [`make`]
/// applies: each claim with its verdict, in [`make`]'s order. What a doc says of the figure is
/// checked against these (issue 54: no stale label stays in docs/reproduction.md).
///
/// # Errors
/// A table that is missing or lacks a column.
#[cfg(test)]
pub(crate) fn verdicts_from_tables(dir: &Path) -> Result<Vec<(String, Verdict)>, SweepError> {
    let read = |name: &str| super::Table::read(&dir.join(name));
    let (tz, tg, nf) = (
        read("lengths_vs_zeta.csv")?,
        read("lengths_vs_gamma.csv")?,
        read("net_flow.csv")?,
    );
    // The points of one pressure form and field of a lengths table, over its axis `axis`.
    let points = |t: &super::Table, axis: &str, pressure: &str, field: &str| {
        let (p, f) = (t.strs("pressure")?, t.strs("field")?);
        let (x, m, s, n) = (
            t.f64s(axis)?,
            t.f64s("length")?,
            t.f64s("length_std")?,
            t.f64s("seeds")?,
        );
        Ok::<Vec<AtValue>, SweepError>(
            (0..p.len())
                .filter(|&k| p[k] == pressure && f[k] == field)
                .map(|k| (x[k], (m[k], s[k]), n[k] as usize))
                .collect(),
        )
    };
    let mut out = Vec::new();
    for pressure in PRESSURES {
        for (name, _) in FIELDS {
            let lz = points(&tz, "zeta", pressure, name)?;
            let lg = points(&tg, "gamma", pressure, name)?;
            out.push((length_claim(pressure, name, true), trend(&lz, -1.0).verdict));
            out.push((length_claim(pressure, name, false), trend(&lg, 1.0).verdict));
        }
    }
    let (p, ratio, cells) = (nf.strs("pressure")?, nf.f64s("ratio")?, nf.f64s("cells")?);
    for pressure in PRESSURES {
        let rows: Vec<usize> = (0..p.len()).filter(|&k| p[k] == pressure).collect();
        let ratios: Vec<f64> = rows.iter().map(|&k| ratio[k]).collect();
        let n = rows.last().map_or(0, |&k| cells[k] as usize);
        out.push((net_flow_claim(pressure), rule_net_flow(&ratios, n).0));
    }
    Ok(out)
}

/// The net flow of a run: `|⟨U⟩_t|`, the time mean over the frames at `t ≥ from` of the mean
/// cell velocity `U = ⟨v_i⟩_i`, the rms cell speed over the same frames, and the number of
/// cells.
fn net_flow(run: &Path, from: f64) -> Result<(f64, f64, usize), SweepError> {
    let paths = super::pipeline::frame_paths(run, "the net flow")?;
    let (mut sum, mut speed2, mut k, mut n) = ([0.0f64; 2], 0.0, 0usize, 0usize);
    for path in &paths {
        let a =
            rundir::read_npz(path, &["time", "velocity"]).map_err(|source| SweepError::RunDir {
                point: run.display().to_string(),
                source,
            })?;
        if a[0].data.first().copied().unwrap_or(f64::NEG_INFINITY) < from {
            continue;
        }
        let v = &a[1].data;
        n = v.len() / 2;
        if n == 0 {
            continue;
        }
        let u = [
            v.iter().step_by(2).sum::<f64>() / n as f64,
            v.iter().skip(1).step_by(2).sum::<f64>() / n as f64,
        ];
        sum[0] += u[0];
        sum[1] += u[1];
        speed2 += v.iter().map(|x| x * x).sum::<f64>() / n as f64;
        k += 1;
    }
    if k == 0 {
        return Ok((f64::NAN, f64::NAN, n));
    }
    Ok((
        (sum[0] / k as f64).hypot(sum[1] / k as f64),
        (speed2 / k as f64).sqrt(),
        n,
    ))
}

/// No net flow: the ratios `|⟨U⟩_t| / v_cell` of the runs, against `1/√N`, the size of the mean of
/// N independent cell velocities at one instant (a time mean of uncorrelated frames would be
/// smaller still), by the rule of an absence ([`super::rule::Rule::absence`]) with `1/√N` the
/// smallest net flow that counts: holds when mean + 2 s.e. of the ratios lies below `1/√N`; does
/// not hold when the mean is resolved (mean − 2 s.e. > 0) and at least `1/√N`; inconclusive
/// otherwise.
fn rule_net_flow(ratios: &[f64], cells: usize) -> (Verdict, String) {
    let (m, se) = super::mean_se(ratios);
    if ratios.len() < 2 || cells == 0 || !m.is_finite() {
        return (
            Verdict::Inconclusive,
            "fewer than two runs with frames".into(),
        );
    }
    let bound = 1.0 / (cells as f64).sqrt();
    let rule = super::rule::Rule::absence(
        format!(
            "|⟨U⟩_t| / v_cell, against 1/√N (N = {cells}), the mean of N independent velocities"
        ),
        bound,
    );
    let o = rule.decide(m, se);
    (o.verdict, o.why)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lengths section of docs/reproduction.md states the verdicts that the figure's rules
    /// give on the figure's own tables, kept in `docs/data/lengths/` (the quick scale, as the
    /// section shows): a rule changed without its docs, or docs edited by hand, fail here.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let want = verdicts_from_tables(&crate::stored_tables("lengths")).unwrap();
        crate::assert_doc_verdicts("lengths", "**Verdicts (quick):**", &want);
    }

    #[test]
    fn the_net_flow_rule_gives_each_outcome() {
        assert_eq!(rule_net_flow(&[0.02, 0.03, 0.025], 240).0, Verdict::Holds);
        assert_eq!(
            rule_net_flow(&[0.3, 0.32, 0.31], 240).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            rule_net_flow(&[0.01, 0.12, 0.06], 240).0,
            Verdict::Inconclusive
        );
        assert_eq!(rule_net_flow(&[0.01], 240).0, Verdict::Inconclusive);
    }

    /// A change resolved by two standard errors and at least 10 % in the claimed direction
    /// holds; one resolved below 10 % (or against the claim) does not; the rest is
    /// inconclusive.
    #[test]
    fn trends_are_judged_by_their_standard_error() {
        // std 0.3 over 9 seeds: standard error 0.1 at each end, 0.14 for the change.
        // The smallest change that counts is 10 % of the first value, 1.
        let pts = |d: f64| vec![(0.0, (10.0, 0.3), 9), (1.0, (10.0 + d, 0.3), 9)];
        assert_eq!(trend(&pts(-1.5), -1.0).verdict, Verdict::Holds);
        assert_eq!(trend(&pts(1.5), 1.0).verdict, Verdict::Holds);
        // Against the claim, resolved: does not hold.
        assert_eq!(trend(&pts(0.5), -1.0).verdict, Verdict::DoesNotHold);
        // Resolved, but smaller than 10 % by two standard errors: does not hold.
        assert_eq!(trend(&pts(-0.5), -1.0).verdict, Verdict::DoesNotHold);
        // Neither: a change of 10 % within two standard errors.
        assert_eq!(trend(&pts(-0.9), -1.0).verdict, Verdict::Inconclusive);
        assert_eq!(
            trend(&[(0.0, (1.0, 0.1), 3)], 1.0).verdict,
            Verdict::Inconclusive
        );
    }
}
