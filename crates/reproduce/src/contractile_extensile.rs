//! `reproduce contractile-extensile`: can contractile cells form an extensile monolayer
//! (Balasubramaniam et al., Nat. Mater. 2021; issue 49)?
//!
//! Each cell carries two active stresses (docs/model.md §3 and §11.6): the shape activity
//! `−ζ S_i` (ζ > 0 extensile along the cell's long axis) and its own nematic's `−ζ_Q q_i`
//! (ζ_Q < 0 contractile along its axis), the axis turning to the cell's long axis at the rate
//! J. One sweep over ζ, ζ_Q and J on the paper's tissue of 240 cells measures, run by run:
//!
//! - **the cells' sign**: the active stress of each cell along its own long axis,
//!   `d_i = (ζ S_i + ζ_Q q_i) : Ŝ_i` with `Ŝ_i = S_i/|S_i|`, averaged over the cells and the
//!   analysed frames, over its scale `ζ⟨|S_i|⟩ + |ζ_Q| S`: a ratio in [−1, 1], negative for
//!   cells that contract along their long axis;
//! - **the monolayer's sign, from the +½ defects' motion**: over the +½ defects linked between
//!   consecutive frames (`analysis/defects.csv`), `Σ Δr·ĥ / Σ|Δr|` with `ĥ = −∇·Q/|∇·Q|` the
//!   direction of the comet's head: the mean cosine of the motion towards the head, in [−1, 1],
//!   positive for an extensile monolayer, negative for a contractile one;
//! - **the monolayer's sign, from the defect-centred flow**: the mean flow over the core (the
//!   disc of radius R) of the +½ defects' averaged crop, along the head, over the run's rms
//!   cell speed.
//!
//! A point's cells are contractile when the ratio is below −[`CELLS`] by the rule of an effect
//! (two standard errors over seeds), extensile when above +[`CELLS`]. Each of the two
//! monolayer measures reads extensile when it is at least +[`MONOLAYER`] by the rule of an
//! effect, contractile when at most −[`MONOLAYER`]. The monolayer is extensile when both
//! measures read extensile, contractile when both read contractile.

#[cfg(test)]
use std::path::Path;

use render::{Plot, Series};
use study::analyze::AnalyzeOptions;
use study::SweepError;

use super::pipeline::{cell, sci, Csv, Made};
use super::rule::Rule;
use super::{g, mean_se, Claim, ReproduceParams, Scale, SweepJob, Verdict};

/// The shape activity ζ of the sweep.
const ZETA: [&str; 2] = ["0", "0.005"];
/// The activity of the cells' own nematic ζ_Q (S = 1).
const ZETA_Q: [&str; 5] = ["-0.01", "-0.0075", "-0.005", "-0.0025", "0.005"];
/// The rate J at which each cell's nematic turns to its long axis.
const J: [&str; 2] = ["0", "0.3"];

/// The smallest dipole ratio of the cells that counts as a sign: a tenth of its scale.
pub(crate) const CELLS: f64 = 0.1;
/// The smallest monolayer ratio that counts as a sign: a fifth of its scale (the mean cosine
/// of the defects' motion towards their head; the core flow over the rms speed).
pub(crate) const MONOLAYER: f64 = 0.2;

/// The side of the box ([`super::defect_fields::tissue_sets`]) and the radius of its cells
/// (the core of a defect is the disc R).
const L: f64 = 200.0;
const R: f64 = 8.0;
/// The side of the defect-centred crops.
const CROP: usize = 61;

/// One run: its point (indices into [`ZETA`], [`ZETA_Q`], [`J`]), its seed and its three
/// ratios.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Run {
    pub zeta: usize,
    pub zeta_q: usize,
    pub j: usize,
    pub seed: u64,
    /// The cells' active stress along their long axis over its scale.
    pub cells: f64,
    /// The mean cosine of the +½ defects' motion towards their head.
    pub motion: f64,
    /// The core flow of the +½ defects towards their head over the rms cell speed.
    pub flow: f64,
}

/// A sign read by a rule: extensile, contractile, or neither resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sign {
    Extensile,
    Contractile,
    Undecided,
}

impl Sign {
    fn name(self) -> &'static str {
        match self {
            Self::Extensile => "extensile",
            Self::Contractile => "contractile",
            Self::Undecided => "not established",
        }
    }

    /// The sign of seed values `v` with `smallest` the size that counts: extensile when the
    /// rule of an effect on the mean holds, contractile when it holds on minus the mean. The
    /// two exclude each other (each needs the mean at least `smallest` on its side of 0).
    fn of(v: &[f64], smallest: f64) -> Self {
        let (m, se) = mean_se(v);
        let rule = Rule::effect("a sign", smallest);
        if rule.decide(m, se).verdict == Verdict::Holds {
            Self::Extensile
        } else if rule.decide(-m, se).verdict == Verdict::Holds {
            Self::Contractile
        } else {
            Self::Undecided
        }
    }

    /// Whether the rule of an effect says the monolayer is *not* extensile: the mean below
    /// `smallest` by two standard errors.
    fn not_extensile(v: &[f64], smallest: f64) -> bool {
        let (m, se) = mean_se(v);
        Rule::effect("a sign", smallest).decide(m, se).verdict == Verdict::DoesNotHold
    }
}

/// A point of the sweep with its seeds' ratios and the signs they read.
#[derive(Debug, Clone)]
pub(crate) struct Point {
    pub zeta: usize,
    pub zeta_q: usize,
    pub j: usize,
    pub cells: Vec<f64>,
    pub motion: Vec<f64>,
    pub flow: Vec<f64>,
}

impl Point {
    fn cells_sign(&self) -> Sign {
        Sign::of(&self.cells, CELLS)
    }

    /// The monolayer's sign: both measures' when they agree, otherwise not established.
    fn monolayer_sign(&self) -> Sign {
        match (
            Sign::of(&self.motion, MONOLAYER),
            Sign::of(&self.flow, MONOLAYER),
        ) {
            (a, b) if a == b => a,
            _ => Sign::Undecided,
        }
    }

    /// Whether one of the two measures says, by its rule, that the monolayer is not extensile.
    fn not_extensile(&self) -> bool {
        Sign::not_extensile(&self.motion, MONOLAYER) || Sign::not_extensile(&self.flow, MONOLAYER)
    }

    fn label(&self) -> String {
        format!(
            "ζ = {}, ζ_Q = {}, J = {}",
            ZETA[self.zeta], ZETA_Q[self.zeta_q], J[self.j]
        )
    }
}

/// The points of `runs`, in the order of the sweep, each with its seeds in seed order.
pub(crate) fn points(runs: &[Run]) -> Vec<Point> {
    let mut sorted: Vec<&Run> = runs.iter().collect();
    sorted.sort_by_key(|r| (r.zeta, r.zeta_q, r.j, r.seed));
    let mut out: Vec<Point> = Vec::new();
    for r in sorted {
        let same = out
            .last()
            .is_some_and(|p| (p.zeta, p.zeta_q, p.j) == (r.zeta, r.zeta_q, r.j));
        if !same {
            out.push(Point {
                zeta: r.zeta,
                zeta_q: r.zeta_q,
                j: r.j,
                cells: Vec::new(),
                motion: Vec::new(),
                flow: Vec::new(),
            });
        }
        let p = out.last_mut().expect("pushed");
        p.cells.push(r.cells);
        p.motion.push(r.motion);
        p.flow.push(r.flow);
    }
    out
}

/// "Contractile cells form an extensile monolayer" over `points`: holds when some point's
/// cells are contractile and its monolayer extensile by both measures; does not hold when at
/// least one point's cells are contractile and at every such point one measure says, by its
/// rule, that the monolayer is not extensile; inconclusive otherwise (no point with contractile
/// cells, or one that neither measure decides). The outcomes exclude each other: a point that
/// reads extensile by a measure's rule cannot read "not extensile" by the same rule.
pub(crate) fn verdict_contractile_cells(points: &[&Point]) -> (Verdict, String) {
    let contractile: Vec<&&Point> = points
        .iter()
        .filter(|p| p.cells_sign() == Sign::Contractile)
        .collect();
    if let Some(p) = contractile
        .iter()
        .find(|p| p.monolayer_sign() == Sign::Extensile)
    {
        return (
            Verdict::Holds,
            format!(
                "at {} the cells contract along their long axis (ratio {}) and the monolayer is extensile by both measures (defects' motion {}, core flow {})",
                p.label(),
                g(mean_se(&p.cells).0),
                g(mean_se(&p.motion).0),
                g(mean_se(&p.flow).0)
            ),
        );
    }
    if contractile.is_empty() {
        return (
            Verdict::Inconclusive,
            "no point has cells that contract along their long axis by the rule".into(),
        );
    }
    if contractile.iter().all(|p| p.not_extensile()) {
        (
            Verdict::DoesNotHold,
            format!(
                "at each of the {} points whose cells contract along their long axis, one measure at least puts the monolayer below the extensile size by two standard errors",
                contractile.len()
            ),
        )
    } else {
        (
            Verdict::Inconclusive,
            "some point with contractile cells has a monolayer that neither measure decides".into(),
        )
    }
}

/// "The two measures agree": holds when at least three points read a sign by both measures
/// and no point reads opposite signs; does not hold when some point reads extensile by one and
/// contractile by the other; inconclusive otherwise.
pub(crate) fn verdict_agree(points: &[Point]) -> (Verdict, String) {
    let read = |p: &Point| (Sign::of(&p.motion, MONOLAYER), Sign::of(&p.flow, MONOLAYER));
    let opposite: Vec<String> = points
        .iter()
        .filter(|p| {
            matches!(
                read(p),
                (Sign::Extensile, Sign::Contractile) | (Sign::Contractile, Sign::Extensile)
            )
        })
        .map(Point::label)
        .collect();
    if !opposite.is_empty() {
        return (
            Verdict::DoesNotHold,
            format!("opposite signs at {}", opposite.join("; ")),
        );
    }
    let both = points
        .iter()
        .filter(|p| {
            let (a, b) = read(p);
            a != Sign::Undecided && a == b
        })
        .count();
    if both >= 3 {
        (
            Verdict::Holds,
            format!("{both} points read the same sign by both measures, and none opposite signs"),
        )
    } else {
        (
            Verdict::Inconclusive,
            format!("{both} points read a sign by both measures: three needed"),
        )
    }
}

/// The points of `ps` whose cells contract along their long axis.
fn contractile_cells<'a>(ps: &[&'a Point]) -> Vec<&'a Point> {
    ps.iter()
        .copied()
        .filter(|p| p.cells_sign() == Sign::Contractile)
        .collect()
}

/// The claims and the table of points.
pub(crate) fn analyse(runs: &[Run]) -> (Vec<Claim>, Csv) {
    let pts = points(runs);
    let mut csv = Csv::new(&[
        "zeta",
        "zeta_q",
        "j",
        "seeds",
        "cells_ratio_mean",
        "cells_ratio_se",
        "cells",
        "motion_ratio_mean",
        "motion_ratio_se",
        "flow_ratio_mean",
        "flow_ratio_se",
        "monolayer",
    ]);
    for p in &pts {
        let (cm, cs) = mean_se(&p.cells);
        let (mm, ms) = mean_se(&p.motion);
        let (fm, fs) = mean_se(&p.flow);
        csv.row([
            cell(ZETA[p.zeta]),
            cell(ZETA_Q[p.zeta_q]),
            cell(J[p.j]),
            cell(p.cells.len()),
            sci(cm),
            sci(cs),
            cell(p.cells_sign().name()),
            sci(mm),
            sci(ms),
            sci(fm),
            sci(fs),
            cell(p.monolayer_sign().name()),
        ]);
    }
    let describe = |ps: &[&Point]| -> String {
        ps.iter()
            .map(|p| {
                format!(
                    "{}: cells {} ({}), monolayer {} (motion {}, flow {})",
                    p.label(),
                    p.cells_sign().name(),
                    g(mean_se(&p.cells).0),
                    p.monolayer_sign().name(),
                    g(mean_se(&p.motion).0),
                    g(mean_se(&p.flow).0)
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    };
    let with_shape: Vec<&Point> = pts.iter().filter(|p| ZETA[p.zeta] != "0").collect();
    let without: Vec<&Point> = pts.iter().filter(|p| ZETA[p.zeta] == "0").collect();
    let (vm, wm) = verdict_contractile_cells(&with_shape);
    let (vc, wc) = verdict_contractile_cells(&without);
    let (va, wa) = verdict_agree(&pts);
    let claims = vec![
        Claim::new(
            "contractile-extensile (issue 49): contractile cells can form an extensile monolayer (Balasubramaniam et al. 2021): with extensile shape activity ζ > 0 and a contractile nematic ζ_Q < 0, some point whose cells contract along their long axis has +½ defects that move towards their head and carry a flow towards it",
            format!(
                "the points with shape activity whose cells contract: {}",
                describe(&contractile_cells(&with_shape))
            ),
            vm,
            wm,
        ),
        Claim::new(
            "Control (contractile-extensile): without shape activity (ζ = 0), cells whose own nematic is contractile form an extensile monolayer (must not hold)",
            format!(
                "the points without shape activity whose cells contract: {}",
                describe(&contractile_cells(&without))
            ),
            vc,
            wc,
        ),
        Claim::new(
            "contractile-extensile (issue 49): the two measures of the monolayer's sign, the +½ defects' motion and the defect-centred flow, agree",
            describe(&pts.iter().collect::<Vec<_>>()),
            va,
            wa,
        ),
    ];
    (claims, csv)
}

/// The table of runs, the figure's raw data.
fn runs_csv(runs: &[Run]) -> Csv {
    let mut csv = Csv::new(&[
        "zeta",
        "zeta_q",
        "j",
        "seed",
        "cells_ratio",
        "motion_ratio",
        "flow_ratio",
    ]);
    for r in runs {
        csv.row([
            cell(ZETA[r.zeta]),
            cell(ZETA_Q[r.zeta_q]),
            cell(J[r.j]),
            cell(r.seed),
            sci(r.cells),
            sci(r.motion),
            sci(r.flow),
        ]);
    }
    csv
}

/// The runs of `contractile_extensile_runs.csv` in `dir`, as [`runs_csv`] wrote them.
#[cfg(test)]
fn runs_from_table(dir: &Path) -> Result<Vec<Run>, SweepError> {
    let t = super::Table::read(&dir.join("contractile_extensile_runs.csv"))?;
    let (z, zq, j) = (t.strs("zeta")?, t.strs("zeta_q")?, t.strs("j")?);
    let (seed, c, m, f) = (
        t.f64s("seed")?,
        t.f64s("cells_ratio")?,
        t.f64s("motion_ratio")?,
        t.f64s("flow_ratio")?,
    );
    let at = |axis: &[&str], v: &str| axis.iter().position(|a| *a == v).expect("on the axis");
    Ok((0..z.len())
        .map(|k| Run {
            zeta: at(&ZETA, &z[k]),
            zeta_q: at(&ZETA_Q, &zq[k]),
            j: at(&J, &j[k]),
            seed: seed[k] as u64,
            cells: c[k],
            motion: m[k],
            flow: f[k],
        })
        .collect())
}

/// The mean cosine of the +½ defects' motion towards their head, from a run's
/// `analysis/defects.csv` (columns `frame, time, x, y, charge, angle, track`): over the defects
/// of one track in consecutive frames at `t ≥ from`, `Σ Δr·ĥ / Σ|Δr|` with `ĥ = −(cos ψ, sin ψ)`
/// at the earlier frame (ψ the direction of ∇·Q, head to tail) and `Δr` the shortest periodic
/// displacement in a box of side `side`. NaN without a moving linked defect.
pub(crate) fn motion_ratio(t: &super::Table, from: f64, side: f64) -> Result<f64, SweepError> {
    let (frame, time, x, y) = (
        t.f64s("frame")?,
        t.f64s("time")?,
        t.f64s("x")?,
        t.f64s("y")?,
    );
    let (charge, angle, track) = (t.f64s("charge")?, t.f64s("angle")?, t.strs("track")?);
    // +½ defects by frame: (track, x, y, ψ).
    let mut by_frame: std::collections::BTreeMap<i64, Vec<(&str, f64, f64, f64)>> =
        Default::default();
    for k in 0..frame.len() {
        if charge[k] == 0.5 && time[k] >= from && angle[k].is_finite() {
            by_frame.entry(frame[k] as i64).or_default().push((
                track[k].as_str(),
                x[k],
                y[k],
                angle[k],
            ));
        }
    }
    let wrap = |d: f64| d - side * (d / side).round();
    let (mut along, mut length) = (0.0, 0.0);
    let frames: Vec<&Vec<_>> = by_frame.values().collect();
    for w in frames.windows(2) {
        for &(tr, x0, y0, psi) in w[0] {
            if let Some(&(_, x1, y1, _)) = w[1].iter().find(|d| d.0 == tr) {
                let (dx, dy) = (wrap(x1 - x0), wrap(y1 - y0));
                along -= dx * psi.cos() + dy * psi.sin();
                length += dx.hypot(dy);
            }
        }
    }
    Ok(if length > 0.0 {
        along / length
    } else {
        f64::NAN
    })
}

/// The cells' active stress along their long axis over its scale, from a run's frames at
/// `t ≥ from`: `Σ (ζ S_i + ζ_Q q_i) : Ŝ_i / Σ (ζ|S_i| + |ζ_Q| |q_i|)` over cells and frames
/// (cells with `S_i = 0` left out).
fn cells_ratio(
    run: &std::path::Path,
    from: f64,
    zeta: f64,
    zeta_q: f64,
) -> Result<f64, SweepError> {
    let paths = super::pipeline::frame_paths(run, "the cells' dipoles")?;
    let (mut num, mut den) = (0.0, 0.0);
    for path in &paths {
        let a = rundir::read_npz(path, &["time", "shape_tensor", "nematic"]).map_err(|source| {
            SweepError::RunDir {
                point: run.display().to_string(),
                source,
            }
        })?;
        if a[0].data.first().copied().unwrap_or(f64::NEG_INFINITY) < from {
            continue;
        }
        for (s, q) in a[1].data.chunks_exact(2).zip(a[2].data.chunks_exact(2)) {
            let n = s[0].hypot(s[1]);
            if n > 0.0 {
                num += zeta * n + zeta_q * (q[0] * s[0] + q[1] * s[1]) / n;
                den += zeta.abs() * n + zeta_q.abs() * q[0].hypot(q[1]);
            }
        }
    }
    Ok(num / den)
}

/// The sweep's runs, measured.
fn sweep_runs(p: &ReproduceParams, t: f64, from: f64) -> Result<Vec<Run>, SweepError> {
    let mut sets = super::defect_fields::tissue_sets(p.scale, t);
    sets.extend([
        // The table's required key, which the sweep's axis sets at each point.
        format!("nematic.zeta={}", ZETA_Q[0]),
        "nematic.align=\"shape\"".into(),
    ]);
    let res = super::sweep(
        p,
        SweepJob {
            scene: super::PAPER_SCENE,
            name: format!("contractile-extensile-{}", p.scale.name()),
            sets,
            varies: vec![
                format!("model.zeta={}", ZETA.join(",")),
                format!("nematic.zeta={}", ZETA_Q.join(",")),
                format!("nematic.align_rate={}", J.join(",")),
            ],
            analyze: Some(AnalyzeOptions {
                from: Some(from),
                crop_side: Some(CROP),
                ..AnalyzeOptions::default()
            }),
            seeds: None,
        },
    )?;
    let mut out = Vec::new();
    let at = |axis: &[&str], v: &str| axis.iter().position(|a| *a == v).expect("on the axis");
    for pt in res.points(None)? {
        let (z, zq, j) = (
            at(&ZETA, &pt.values[0]),
            at(&ZETA_Q, &pt.values[1]),
            at(&J, &pt.values[2]),
        );
        for r in &pt.runs {
            let defects = super::Table::read(&r.run.join("analysis/defects.csv"))?;
            let motion = motion_ratio(&defects, from, L)?;
            let crops =
                super::defect_fields::read_crops(&r.run.join("analysis/defect_averages.npz"))?;
            let core = super::defect_fields::disc_mean(&crops.2[0], R);
            let v_rms = super::late_mean(
                &r.run.join("analysis/observables.csv"),
                "v_rms",
                from,
                |v| v,
            )?;
            let zeta: f64 = ZETA[z].parse().unwrap_or(f64::NAN);
            let zeta_q: f64 = ZETA_Q[zq].parse().unwrap_or(f64::NAN);
            out.push(Run {
                zeta: z,
                zeta_q: zq,
                j,
                seed: r.seed,
                cells: cells_ratio(&r.run, from, zeta, zeta_q)?,
                motion,
                flow: -core / v_rms,
            });
        }
    }
    Ok(out)
}

/// The picture: each point's two monolayer ratios against its cells' ratio.
fn plot(runs: &[Run]) -> Plot {
    let pts = points(runs);
    let mut plot = Plot::new(
        "The monolayer's sign against its cells' (+: extensile, −: contractile)",
        "cells' active stress along their long axis, over its scale",
        "monolayer: +1/2 defects towards their head",
    );
    plot.hlines = vec![
        (MONOLAYER, "extensile".into()),
        (-MONOLAYER, "contractile".into()),
    ];
    for (name, f) in [
        (
            "defects' motion (mean cosine)",
            (|p: &Point| &p.motion) as fn(&Point) -> &Vec<f64>,
        ),
        ("core flow / v_rms", |p: &Point| &p.flow),
    ] {
        let (mut x, mut y, mut e) = (Vec::new(), Vec::new(), Vec::new());
        for p in &pts {
            let (m, se) = mean_se(f(p));
            x.push(mean_se(&p.cells).0);
            y.push(m);
            e.push(se);
        }
        plot.series
            .push(Series::new(name).with_points(&x, &y, &e).markers_only());
    }
    plot
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let t = match p.scale {
        Scale::Quick => 400.0,
        Scale::Paper => 1000.0,
    };
    let from = 200.0 + 0.5 * t;
    let runs = sweep_runs(p, t, from)?;
    p.reporter.stage("contractile-extensile: tables and plot");
    let (claims, points) = analyse(&runs);
    let settings = format!(
        "- The paper's tissue on L = {L} (240 cells, R = {R}, γ = 0.014), with shape activity ζ = {} and a nematic in each cell (`[nematic]`, S = 1, `align = \"shape\"`, K = W = D_r = 0) of activity ζ_Q = {} turning to the cell's long axis at J = {}; seeds {}.\n\
         - 200 TU of relaxation, then {t} TU; integrator {}; a frame every 10 TU, analysed from t = {from}.\n\
         - The cells' sign: `Σ (ζ S_i + ζ_Q q_i) : Ŝ_i / Σ (ζ|S_i| + |ζ_Q| S)` over cells and frames, the active stress along each cell's long axis over its scale; contractile cells when below −{CELLS} by the rule of an effect (2 s.e. over seeds), extensile when above +{CELLS}.\n\
         - The monolayer's sign, two ways: (1) the +½ defects linked between consecutive frames, `Σ Δr·ĥ / Σ|Δr|` with ĥ the direction of the head (−∇·Q); (2) the flow over the core (disc R) of the +½ defects' crop averaged in their frame, towards the head, over the run's v_rms. Each reads extensile when at least +{MONOLAYER} by the rule of an effect, contractile when at most −{MONOLAYER}; the monolayer is extensile (contractile) when both read so.\n\
         - Claim: some point with ζ > 0 whose cells are contractile has an extensile monolayer; it does not hold when at every such point one measure at least is below +{MONOLAYER} by 2 s.e. Control: the same claim at ζ = 0, where only the cells' own (contractile) nematic drives the flow; it must read \"does not hold\".\n\
         - Data: `contractile_extensile_runs.csv` (each run), `contractile_extensile.csv` (each point, with its signs), `signs.png`.",
        ZETA[1],
        ZETA_Q.join(", "),
        J.join(", "),
        p.scale.seeds(),
        p.scale.integrator_name(),
    );
    Ok(Made::new(claims, settings)
        .table("contractile_extensile_runs.csv", runs_csv(&runs))
        .table("contractile_extensile.csv", points)
        .plot("signs.png", plot(&runs)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic runs: ratios by point, 3 seeds scattered by ±`spread`.
    fn runs(
        cells: impl Fn(usize, usize, usize) -> f64,
        mono: impl Fn(usize, usize, usize) -> (f64, f64),
        spread: f64,
    ) -> Vec<Run> {
        let mut out = Vec::new();
        for zeta in 0..ZETA.len() {
            for zeta_q in 0..ZETA_Q.len() {
                for j in 0..J.len() {
                    for seed in 1..=3u64 {
                        let w = spread * (seed as f64 - 2.0);
                        let (m, f) = mono(zeta, zeta_q, j);
                        out.push(Run {
                            zeta,
                            zeta_q,
                            j,
                            seed,
                            cells: cells(zeta, zeta_q, j) + w,
                            motion: m + w,
                            flow: f - w,
                        });
                    }
                }
            }
        }
        out
    }

    fn verdicts(r: &[Run]) -> Vec<Verdict> {
        analyse(r).0.into_iter().map(|c| c.verdict).collect()
    }

    /// The cells' sign follows ζ_Q's when J aligns (contractile for ζ_Q < 0), extensile when
    /// not.
    fn cells(_: usize, zq: usize, j: usize) -> f64 {
        if j == 1 && zq < 4 {
            -0.5
        } else {
            0.5
        }
    }

    #[test]
    fn each_outcome_is_reached() {
        // The monolayer follows its cells: the claim does not hold, nor the control; the
        // measures agree.
        let follows = runs(
            cells,
            |z, zq, j| {
                let c = cells(z, zq, j);
                (0.6 * c, c)
            },
            0.02,
        );
        assert_eq!(
            verdicts(&follows),
            [Verdict::DoesNotHold, Verdict::DoesNotHold, Verdict::Holds]
        );
        // With shape activity, the monolayer is extensile whatever its cells: the claim holds;
        // without, it follows its cells and the control reads "does not hold".
        let shape_wins = runs(
            cells,
            |z, zq, j| {
                if z == 1 {
                    (0.4, 0.9)
                } else {
                    let c = cells(z, zq, j);
                    (0.6 * c, c)
                }
            },
            0.02,
        );
        assert_eq!(
            verdicts(&shape_wins),
            [Verdict::Holds, Verdict::DoesNotHold, Verdict::Holds]
        );
        // A monolayer at the edge of the size that counts, with seeds that scatter: neither
        // outcome; the measures agree nowhere with a sign, so that claim is inconclusive too.
        let edge = runs(cells, |_, _, _| (0.19, 0.19), 0.1);
        assert_eq!(
            verdicts(&edge),
            [
                Verdict::Inconclusive,
                Verdict::Inconclusive,
                Verdict::Inconclusive
            ]
        );
        // The measures read opposite signs: they do not agree.
        let opposite = runs(cells, |_, _, _| (0.5, -0.5), 0.02);
        assert_eq!(verdicts(&opposite)[2], Verdict::DoesNotHold);
        // The control fails when contractile cells alone make an extensile monolayer.
        let control = runs(cells, |_, _, _| (0.5, 0.9), 0.02);
        assert_eq!(verdicts(&control)[1], Verdict::Holds);
        // No contractile cells anywhere: inconclusive, whatever the monolayer.
        let none = runs(|_, _, _| 0.5, |_, _, _| (0.5, 0.9), 0.02);
        assert_eq!(verdicts(&none)[0], Verdict::Inconclusive);
    }

    /// Defects that step towards their head read +1, towards their tail −1, across 0; a step
    /// across the periodic boundary is the short one; an unlinked defect does not count.
    #[test]
    fn the_motion_ratio_of_synthetic_tracks() {
        let table = |rows: &[(u32, f64, f64, f64, &str)]| {
            let mut s = String::from("frame,time,x,y,charge,angle,track\n");
            for (f, x, y, psi, tr) in rows {
                s += &format!("{f},{},{x},{y},0.5,{psi},{tr}\n", 10 * f);
                // A −½ defect that moves does not count.
                s += &format!("{f},{},{},{y},-0.5,0,{tr}\n", 10 * f, x + 5.0 * *f as f64);
            }
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("defects.csv");
            std::fs::write(&path, s).unwrap();
            super::super::Table::read(&path).unwrap()
        };
        // ψ = 0: the tail is +x, the head −x. Two steps of 1 towards the head.
        let head = table(&[
            (0, 10.0, 5.0, 0.0, "1"),
            (1, 9.0, 5.0, 0.0, "1"),
            (2, 8.0, 5.0, 0.0, "1"),
        ]);
        assert!((motion_ratio(&head, 0.0, L).unwrap() - 1.0).abs() < 1e-12);
        // Towards the tail across the boundary (199.5 → 0.5): −1.
        let tail = table(&[(0, 199.5, 5.0, 0.0, "1"), (1, 0.5, 5.0, 0.0, "1")]);
        assert!((motion_ratio(&tail, 0.0, L).unwrap() + 1.0).abs() < 1e-12);
        // Across the axis (ψ = π/2, a step along x), and a defect without a partner.
        let across = table(&[
            (0, 10.0, 5.0, std::f64::consts::FRAC_PI_2, "1"),
            (1, 11.0, 5.0, std::f64::consts::FRAC_PI_2, "1"),
            (1, 50.0, 50.0, 0.0, "2"),
        ]);
        assert!(motion_ratio(&across, 0.0, L).unwrap().abs() < 1e-12);
        // Frames before `from` are left out: nothing moves after it.
        assert!(motion_ratio(&head, 15.0, L).unwrap().is_nan());
    }

    /// The contractile-extensile section of docs/reproduction.md states the verdicts of the
    /// stored runs, kept in `docs/data/contractile-extensile/quick/`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let runs = runs_from_table(&crate::stored_tables("contractile-extensile/quick")).unwrap();
        let want: Vec<(String, Verdict)> = analyse(&runs)
            .0
            .into_iter()
            .map(|c| (c.claim, c.verdict))
            .collect();
        crate::assert_doc_verdicts("contractile-extensile", "**Verdicts (quick):**", &want);
    }
}
