//! `monolayer reproduce FIGURE`: the paper's figures from the paper's scene, each with its
//! data (CSV), its pictures (PNG, drawn by the `render` crate) and a verdict on every claim
//! of docs/model.md §9 that it tests (`verdict.md`).
//!
//! Every figure is one or more sweeps ([`study::run_points`]) in `OUT/sweeps/NAME/`, so an
//! interrupted `reproduce` resumes where it stopped and figures that share a sweep run it
//! once; the figure's own files go to `OUT/FIGURE/`. Two scales:
//! - [`Scale::Quick`]: 3 seeds, short runs, the default integrator (dt 0.5, margin 16, f32):
//!   each figure in minutes on 2 cores;
//! - [`Scale::Paper`]: 5 seeds, the paper's integrator (dt 0.2, margin 12), longer runs.
//!
//! The settings of each figure are written at the top of its `verdict.md`.

mod bend_splay;
mod bloch;
mod channel;
mod contractile;
mod contractile_extensile;
mod defect_fields;
mod defects;
mod extrusion;
mod flocking;
mod friction;
mod jamming;
mod lengths;
mod pipeline;
mod rotation;
mod rule;
mod rules;
mod run_length;
mod scaling;
mod sorting;
mod stability;
mod systematics;
mod table;
mod threshold;

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Arc;
use std::time::Instant;

use study::analyze::AnalyzeOptions;
use study::{
    analyze_points, run_points, write_summary, Seeds, SweepError, SweepParams, SweepSpec, Vary,
};

pub use bend_splay::BEND_SPLAY_SCENE;
pub use extrusion::EXTRUSION_SCENE;
pub use flocking::POLAR_SCENE;
pub use jamming::JAMMING_SCENE;
pub use rotation::DISC_SCENE;
pub use sorting::SORTING_SCENE;
pub use table::Table;

/// The paper's scene (docs/model.md §8): 60 cells of radius 8 in a periodic 100² box (15 cells per
/// 50²), γ = 0.01, relaxed at ζ = 0 for 200 TU. Figures change the box, the activity and the
/// run length with overrides.
pub const PAPER_SCENE: &str = "\
[domain]
lx = 100
ly = 100

[cells]
count = 60
radius = 8.0
init = \"random\"

[model]
gamma = 0.01
mu = 3.0
lambda = 2.5
kappa = 0.1
xi = 2.0
zeta = 0.0
pressure = \"paper\"

[run]
relax_time = 200.0
time = 400.0
seed = 1
output_every = 400.0
series_every = 1.0
";

/// How big a reproduction is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Minutes per figure on 2 cores: 3 seeds, short runs, the default integrator.
    Quick,
    /// The paper's sizes: 5 seeds, longer runs, the paper's integrator (dt 0.2, margin 12).
    Paper,
}

impl Scale {
    /// The seeds of every point.
    pub fn seeds(self) -> Seeds {
        match self {
            Self::Quick => Seeds { first: 1, last: 3 },
            Self::Paper => Seeds { first: 1, last: 5 },
        }
    }

    /// The integrator overrides.
    pub fn integrator(self) -> Vec<String> {
        match self {
            Self::Quick => vec!["integrator.dt=0.5".into(), "integrator.margin=16".into()],
            Self::Paper => vec!["integrator.dt=0.2".into(), "integrator.margin=12".into()],
        }
    }

    /// The integrator overrides as the verdicts state them, e.g. `dt=0.5 margin=16`.
    pub fn integrator_name(self) -> String {
        self.integrator().join(" ").replace("integrator.", "")
    }

    /// The time step of the figures whose scenes are not the paper's (they keep their scene's
    /// margin): the scene's 0.5 at the quick scale, the paper's 0.2 at the paper scale.
    pub(crate) fn own_dt(self) -> f64 {
        match self {
            Self::Quick => 0.5,
            Self::Paper => 0.2,
        }
    }

    /// [`Scale::own_dt`] as an override of the scene, where it is not the scene's own.
    pub(crate) fn own_dt_set(self) -> Option<String> {
        (self == Self::Paper).then(|| format!("integrator.dt={}", self.own_dt()))
    }

    /// The seeds `1..=quick` or `1..=paper`, for figures whose statistic needs more seeds than
    /// [`Scale::seeds`] gives.
    pub(crate) fn seeds_up_to(self, quick: u64, paper: u64) -> Seeds {
        Seeds {
            first: 1,
            last: match self {
                Self::Quick => quick,
                Self::Paper => paper,
            },
        }
    }

    /// Its name, as given to `--scale`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Quick => "quick",
            Self::Paper => "paper",
        }
    }
}

impl FromStr for Scale {
    type Err = SweepError;

    fn from_str(s: &str) -> Result<Self, SweepError> {
        match s {
            "quick" => Ok(Self::Quick),
            "paper" => Ok(Self::Paper),
            _ => Err(SweepError::Reproduce {
                why: format!("--scale {s}: write quick or paper"),
            }),
        }
    }
}

/// A figure of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Figure {
    /// Fig. 2a and 2b: v_rms and S_rms against ζ; ζ_cr against γ and L, both pressure forms.
    Threshold,
    /// Fig. 3 and the supplementary length figures: correlations and lengths against ζ and γ.
    Lengths,
    /// The supplementary defect figure: density and creation rate against ζ, charge in time.
    Defects,
    /// Fig. 4: flow and stress averaged around ±½ defects.
    DefectFields,
    /// Supplementary: contractile activity stays at rest.
    Contractile,
    /// Cost of subdomains against the full domain.
    Scaling,
    /// The threshold as the linear instability of an ordered rest state.
    Stability,
    /// The threshold of the infinite ordered tissue by Floquet–Bloch stability (issue 54).
    Bloch,
    /// The threshold of the random packing against the run length.
    RunLength,
    /// The critical width of flow in a channel against the activity (issue 28).
    Channel,
    /// Collective rotation of polar cells in a disc (issue 41).
    Rotation,
    /// The flocking transition of polar cells against their noise (issue 41).
    Flocking,
    /// Whether a mixture of two populations sorts (issue 41).
    Sorting,
    /// The solid–liquid transition of self-propelled cells (issue 41).
    Jamming,
    /// Where extruded cells are found, against the defects (issue 41).
    Extrusion,
    /// Whether friction between cells solidifies a tissue (issue 49).
    Friction,
    /// Whether contractile cells can form an extensile monolayer (issue 49).
    ContractileExtensile,
    /// Whether a uniform director of extensile cells is unstable to bend, contractile to splay
    /// (issue 49).
    BendSplay,
}

impl Figure {
    /// Every figure, in the order `all` makes them.
    pub const ALL: [Figure; 18] = [
        Self::Threshold,
        Self::Lengths,
        Self::Defects,
        Self::DefectFields,
        Self::Contractile,
        Self::Scaling,
        Self::Stability,
        Self::Bloch,
        Self::RunLength,
        Self::Channel,
        Self::Rotation,
        Self::Flocking,
        Self::Sorting,
        Self::Jamming,
        Self::Extrusion,
        Self::Friction,
        Self::ContractileExtensile,
        Self::BendSplay,
    ];

    /// Its name, as given on the command line and as its directory.
    pub fn name(self) -> &'static str {
        match self {
            Self::Threshold => "threshold",
            Self::Lengths => "lengths",
            Self::Defects => "defects",
            Self::DefectFields => "defect-fields",
            Self::Contractile => "contractile",
            Self::Scaling => "scaling",
            Self::Stability => "stability",
            Self::Bloch => "bloch",
            Self::RunLength => "run-length",
            Self::Channel => "channel",
            Self::Rotation => "rotation",
            Self::Flocking => "flocking",
            Self::Sorting => "sorting",
            Self::Jamming => "jamming",
            Self::Extrusion => "extrusion",
            Self::Friction => "friction",
            Self::ContractileExtensile => "contractile-extensile",
            Self::BendSplay => "bend-splay",
        }
    }

    /// What the figure shows.
    pub fn title(self) -> &'static str {
        match self {
            Self::Threshold => "The activity threshold (Fig. 2a, 2b)",
            Self::Lengths => "Correlation lengths in active turbulence (Fig. 3, supplement)",
            Self::Defects => "Defect density and creation (supplement)",
            Self::DefectFields => "Flow and stress around ±1/2 defects (Fig. 4)",
            Self::Contractile => "Contractile activity stays at rest (supplement)",
            Self::Scaling => "Cost of subdomains against the full domain (supplement)",
            Self::Stability => {
                "The threshold as the linear instability of a hexagonal rest state (issue 26)"
            }
            Self::Bloch => {
                "The threshold of the infinite ordered tissue by Floquet–Bloch stability (issue 54)"
            }
            Self::RunLength => {
                "The threshold of the random packing against the run length (issue 26)"
            }
            Self::Channel => "The critical width of flow in a channel (issue 28)",
            Self::Rotation => "Collective rotation of polar cells in a disc (issue 41)",
            Self::Flocking => "The flocking transition of polar cells against noise (issue 41)",
            Self::Sorting => "Sorting of a mixture of two populations (issue 41)",
            Self::Jamming => {
                "The solid–liquid transition of a tissue of self-propelled cells (issue 41)"
            }
            Self::Extrusion => "Extrusion against the ±1/2 defects (issue 41)",
            Self::Friction => "Friction between cells and the solid–liquid transition (issue 49)",
            Self::ContractileExtensile => {
                "Contractile cells and an extensile monolayer, by the cells' own nematic (issue 49)"
            }
            Self::BendSplay => {
                "Bend and splay instabilities of the cells' own nematic from a uniform director (issue 49)"
            }
        }
    }
}

impl FromStr for Figure {
    type Err = SweepError;

    fn from_str(s: &str) -> Result<Self, SweepError> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| SweepError::Reproduce {
                why: format!(
                    "no figure {s}: write one of {}, or all",
                    Self::ALL.map(Figure::name).join(", ")
                ),
            })
    }
}

/// A judgement on a claim.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The measurement agrees with the claim.
    Holds,
    /// The measurement contradicts the claim.
    DoesNotHold,
    /// The measurement cannot decide, with the reason given.
    Inconclusive,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Holds => "holds",
            Self::DoesNotHold => "does not hold",
            Self::Inconclusive => "inconclusive",
        })
    }
}

/// One claim of docs/model.md §9, what was measured and the verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    /// The claim, with its number in docs/model.md §9.
    pub claim: String,
    /// The measured value, with its seed spread.
    pub measured: String,
    /// The verdict.
    pub verdict: Verdict,
    /// Why.
    pub reason: String,
}

impl Claim {
    fn new(
        claim: impl Into<String>,
        measured: impl Into<String>,
        verdict: Verdict,
        reason: impl Into<String>,
    ) -> Self {
        Self {
            claim: claim.into(),
            measured: measured.into(),
            verdict,
            reason: reason.into(),
        }
    }
}

/// What a figure produced.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct FigureReport {
    /// The figure.
    pub figure: Figure,
    /// Its directory.
    pub dir: PathBuf,
    /// The claims it tests.
    pub claims: Vec<Claim>,
    /// Wall time of this call, seconds (a resumed figure counts only what it redid).
    pub wall_s: f64,
}

/// Told what a reproduction is doing. Nothing below the binary prints; the CLI shows this.
pub trait Reporter: Send + Sync {
    /// A sweep `name` starts, with `runs` runs and `steps` steps left to take.
    fn sweep(&self, name: &str, runs: usize, steps: u64);
    /// `n` more steps were taken.
    fn steps(&self, n: u64);
    /// A stage without steps (analysis, drawing) starts.
    fn stage(&self, what: &str);
}

/// The settings of a reproduction.
#[derive(Clone)]
#[non_exhaustive]
pub struct ReproduceParams {
    /// The output directory: sweeps in `OUT/sweeps/`, figures in `OUT/FIGURE/`.
    pub out: PathBuf,
    /// The scale.
    pub scale: Scale,
    /// How runs share the machine.
    pub sweep: SweepParams,
    /// Told of progress.
    pub reporter: Arc<dyn Reporter>,
    /// Stops the runs on a signal ([`ReproduceParams::with_interrupt`]; none by default).
    pub interrupt: rundir::Interrupt,
}

impl ReproduceParams {
    /// A reproduction into `out` at `scale`.
    pub fn new(
        out: PathBuf,
        scale: Scale,
        sweep: SweepParams,
        reporter: Arc<dyn Reporter>,
    ) -> Self {
        Self {
            out,
            scale,
            sweep,
            reporter,
            interrupt: rundir::Interrupt::never(),
        }
    }

    /// The same, with the runs stopped (resumably) when `interrupt` catches a signal.
    pub fn with_interrupt(mut self, interrupt: rundir::Interrupt) -> Self {
        self.interrupt = interrupt;
        self
    }

    fn figure_dir(&self, figure: Figure) -> Result<PathBuf, SweepError> {
        let d = self.out.join(figure.name());
        std::fs::create_dir_all(&d).map_err(|e| SweepError::write(figure.name(), &d, e))?;
        Ok(d)
    }
}

/// One sweep of a figure.
pub(crate) struct SweepJob {
    /// Its directory name under `OUT/sweeps/`.
    pub name: String,
    /// The scene ([`PAPER_SCENE`] for the paper's figures).
    pub scene: &'static str,
    /// Overrides of the scene.
    pub sets: Vec<String>,
    /// Axes, `key=V1,V2`.
    pub varies: Vec<String>,
    /// Analyse every run, with these options.
    pub analyze: Option<AnalyzeOptions>,
    /// The seeds, when not the scale's.
    pub seeds: Option<study::Seeds>,
}

/// A finished sweep: its directory and summary.
pub(crate) struct SweepResult {
    pub dir: PathBuf,
    pub summary: Table,
    pub points: Vec<study::Point>,
}

/// Runs (or resumes) a sweep of the figure and reads its summary.
pub(crate) fn sweep(p: &ReproduceParams, job: SweepJob) -> Result<SweepResult, SweepError> {
    let dir = p.out.join("sweeps").join(&job.name);
    let spec = SweepSpec {
        scene_text: job.scene.to_string(),
        sets: job.sets,
        varies: job
            .varies
            .iter()
            .map(|v| v.parse::<Vary>())
            .collect::<Result<_, _>>()?,
        seeds: Some(job.seeds.unwrap_or(p.scale.seeds())),
    };
    let points = spec.plan()?;
    std::fs::create_dir_all(&dir).map_err(|e| SweepError::write(&job.name, &dir, e))?;
    spec.save(&dir)?;
    let (todo, steps) = study::pending(&dir, &points);
    p.reporter.sweep(&job.name, todo.len(), steps);
    let rep = p.reporter.clone();
    run_points(
        &points,
        &dir,
        p.sweep,
        Arc::new(move |n| rep.steps(n)),
        &p.interrupt,
    )?;
    if let Some(opts) = &job.analyze {
        p.reporter.stage(&format!("analysing {}", job.name));
        analyze_points(&points, &dir, opts, p.sweep)?;
    }
    let path = write_summary(&dir, &spec.keys(), &points, job.analyze.is_some())?;
    let summary = Table::read(&path)?;
    Ok(SweepResult {
        dir,
        summary,
        points,
    })
}

/// Makes `figure` (see the module docs).
///
/// # Errors
/// A run that fails, a file that cannot be written, or a picture that cannot be drawn.
pub fn reproduce(figure: Figure, p: &ReproduceParams) -> Result<FigureReport, SweepError> {
    let start = Instant::now();
    let dir = p.figure_dir(figure)?;
    let made = match figure {
        Figure::Threshold => threshold::make(p)?,
        Figure::Lengths => lengths::make(p)?,
        Figure::Defects => defects::make(p)?,
        Figure::DefectFields => defect_fields::make(p)?,
        Figure::Contractile => contractile::make(p)?,
        Figure::Scaling => scaling::make(p)?,
        Figure::Stability => stability::make(p, &dir)?,
        Figure::Bloch => bloch::make(p, &dir)?,
        Figure::RunLength => run_length::make(p)?,
        Figure::Channel => channel::make(p)?,
        Figure::Rotation => rotation::make(p)?,
        Figure::Flocking => flocking::make(p)?,
        Figure::Sorting => sorting::make(p)?,
        Figure::Jamming => jamming::make(p)?,
        Figure::Extrusion => extrusion::make(p)?,
        Figure::Friction => friction::make(p)?,
        Figure::ContractileExtensile => contractile_extensile::make(p)?,
        Figure::BendSplay => bend_splay::make(p)?,
    };
    made.write_files(&dir)?;
    let wall_s = start.elapsed().as_secs_f64();
    write_verdict(&dir, figure, p.scale, &made.settings, &made.claims, wall_s)?;
    Ok(FigureReport {
        figure,
        dir,
        claims: made.claims,
        wall_s,
    })
}

fn write_verdict(
    dir: &Path,
    figure: Figure,
    scale: Scale,
    settings: &str,
    claims: &[Claim],
    wall_s: f64,
) -> Result<(), SweepError> {
    let mut s = format!(
        "# {}\n\nScale `{}`; made by `monolayer reproduce {} --scale {}` in {:.0} s of wall time (a resumed call counts only what it redid).\n\n## Settings\n\n{}\n\n## Verdicts\n\n| claim (docs/model.md §9, or the figure's section of docs/reproduction.md) | measured (± as the settings above state) | verdict | reason |\n|---|---|---|---|\n",
        figure.title(),
        scale.name(),
        figure.name(),
        scale.name(),
        wall_s,
        settings.trim()
    );
    for c in claims {
        s += &format!(
            "| {} | {} | **{}** | {} |\n",
            c.claim.replace('|', "\\|"),
            c.measured.replace('|', "\\|"),
            c.verdict,
            c.reason.replace('|', "\\|")
        );
    }
    write_text(&dir.join("verdict.md"), &s)
}

/// Writes a text file whole (under a temporary name first).
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), SweepError> {
    let tmp = path.with_extension("partial");
    let io = |e| SweepError::write("the figure", path, e);
    std::fs::write(&tmp, text).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}

/// A picture that cannot be drawn.
pub(crate) fn drawn(r: Result<(), render::RenderError>) -> Result<(), SweepError> {
    r.map_err(|e| SweepError::Reproduce { why: e.to_string() })
}

/// A mean and its spread (sample standard deviation) over seeds.
pub(crate) type Stat = (f64, f64);

/// A value on an axis, the statistics of a quantity there, and the number of runs.
pub(crate) type AtValue = (f64, Stat, usize);

/// Mean and sample standard deviation (0 for one value); NaN values are left out.
pub(crate) fn mean_std(v: &[f64]) -> (f64, f64) {
    let v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (m, 0.0);
    }
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// The mean of `v` and its standard error (the sample standard deviation over √n), from
/// [`mean_std`]; the error is NaN for fewer than two values.
pub(crate) fn mean_se(v: &[f64]) -> (f64, f64) {
    let (m, s) = mean_std(v);
    let n = v.iter().filter(|x| x.is_finite()).count();
    (
        m,
        if n < 2 {
            f64::NAN
        } else {
            s / (n as f64).sqrt()
        },
    )
}

/// The leave-one-out jackknife standard error of an estimate over `n` seeds, `estimate` making
/// it from a subset of the seed indices `0..n`: `√((n − 1)/n Σ_i (θ₍ᵢ₎ − θ̄)²)` over the
/// estimates `θ₍ᵢ₎` without seed `i`. NaN with fewer than three seeds, or when a subset has no
/// estimate.
pub(crate) fn jackknife(n: usize, estimate: impl Fn(&[usize]) -> Option<f64>) -> f64 {
    if n < 3 {
        return f64::NAN;
    }
    let leave: Option<Vec<f64>> = (0..n)
        .map(|out| estimate(&(0..n).filter(|&s| s != out).collect::<Vec<_>>()))
        .collect();
    let Some(leave) = leave else {
        return f64::NAN;
    };
    let m = leave.iter().sum::<f64>() / n as f64;
    let var = (n as f64 - 1.0) / n as f64 * leave.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
    var.sqrt()
}

/// The mean over the seeds `seeds` of per-seed rows `rows[seed][k]`, at every `k`.
pub(crate) fn seed_mean(rows: &[Vec<f64>], seeds: &[usize]) -> Vec<f64> {
    (0..rows.first().map_or(0, Vec::len))
        .map(|k| seeds.iter().map(|&s| rows[s][k]).sum::<f64>() / seeds.len() as f64)
        .collect()
}

/// A short number for tables and verdicts: 3 significant digits.
pub(crate) fn g(v: f64) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e4).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.2e}")
    }
}

/// `mean ± std`.
pub(crate) fn pm((m, s): (f64, f64)) -> String {
    format!("{} ± {}", g(m), g(s))
}

/// One run of a sweep: its values on the axes, its seed, its directory and its summary over
/// the window given.
#[derive(Clone)]
pub(crate) struct Rec {
    pub values: Vec<String>,
    pub seed: u64,
    pub run: PathBuf,
    pub summary: study::summary::RunSummary,
}

impl SweepResult {
    /// Every run, summarised over the second half of the first `time` TU of its active phase
    /// (the whole active phase when `time` is `None`). A run is deterministic, so its first
    /// `time` TU are the run of that length.
    pub(crate) fn records(&self, time: Option<f64>) -> Result<Vec<Rec>, SweepError> {
        self.points
            .iter()
            .map(|pt| {
                let r = &pt.scene.file().run;
                let run = study::run_dir(&self.dir, pt);
                let summary = study::summary::summarise(
                    &run,
                    study::summary::window(r.relax_time, time.unwrap_or(r.time).min(r.time)),
                )?;
                Ok(Rec {
                    values: pt.values.clone(),
                    seed: pt.seed,
                    run,
                    summary,
                })
            })
            .collect()
    }
}

/// The mean of `f` of the column `column` of a run's table `path` (e.g.
/// `analysis/observables.csv`) over its rows at or after the time `from` (the column `time`),
/// non-finite values left out; NaN without such rows.
pub(crate) fn late_mean(
    path: &Path,
    column: &str,
    from: f64,
    f: impl Fn(f64) -> f64,
) -> Result<f64, SweepError> {
    Ok(late_means(path, &[column], from, f)?[0])
}

/// [`late_mean`] of each of `columns`, from one reading of the table.
pub(crate) fn late_means(
    path: &Path,
    columns: &[&str],
    from: f64,
    f: impl Fn(f64) -> f64,
) -> Result<Vec<f64>, SweepError> {
    let t = Table::read(path)?;
    let times = t.f64s("time")?;
    columns
        .iter()
        .map(|column| {
            let values = t.f64s(column)?;
            let late: Vec<f64> = times
                .iter()
                .zip(&values)
                .filter(|(t, v)| **t >= from && v.is_finite())
                .map(|(_, v)| f(*v))
                .collect();
            Ok(if late.is_empty() {
                f64::NAN
            } else {
                late.iter().sum::<f64>() / late.len() as f64
            })
        })
        .collect()
}

/// The mean and spread over the runs `runs` of the columns `cols` of their table `file`
/// (e.g. `series.csv`), at every `every`-th row the runs share: `(value of the column
/// `index`, [(mean, std); cols])`. Empty without runs.
pub(crate) fn column_stats(
    runs: &[&Rec],
    file: &str,
    index: &str,
    cols: &[&str],
    every: usize,
) -> Result<Vec<(f64, Vec<Stat>)>, SweepError> {
    let tables: Vec<Table> = runs
        .iter()
        .map(|r| Table::read(&r.run.join(file)))
        .collect::<Result<_, _>>()?;
    let Some(first) = tables.first() else {
        return Ok(Vec::new());
    };
    let times = first.f64s(index)?;
    let data: Vec<Vec<Vec<f64>>> = tables
        .iter()
        .map(|t| {
            cols.iter()
                .map(|c| t.f64s(c))
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<_, _>>()?;
    let rows = data.iter().map(|d| d[0].len()).min().unwrap_or(0);
    Ok((0..rows.min(times.len()))
        .step_by(every.max(1))
        .map(|k| {
            let stats = (0..cols.len())
                .map(|c| mean_std(&data.iter().map(|d| d[c][k]).collect::<Vec<_>>()))
                .collect();
            (times[k], stats)
        })
        .collect())
}

/// Checks that the verdict table after the line `heading` in the section of `figure` in
/// docs/reproduction.md states, row by row, the claims and verdicts `want` (what the figure's
/// rules give on its stored tables, issue 54); panics naming the first claim that differs.
/// The directory of a figure's raw tables kept in the docs, `docs/data/PATH` (`FIGURE/SCALE`),
/// for the tests that compare the docs' verdicts with them.
#[cfg(test)]
pub(crate) fn stored_tables(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs/data")
        .join(path)
}

#[cfg(test)]
pub(crate) fn assert_doc_verdicts(figure: &str, heading: &str, want: &[(String, Verdict)]) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("docs/reproduction.md")).unwrap();
    let rows = doc_verdicts(&doc, figure, heading);
    assert_eq!(rows.len(), want.len(), "{figure}, {heading}: {rows:?}");
    for ((claim, verdict), (doc_claim, doc_verdict)) in want.iter().zip(&rows) {
        assert_eq!(claim, doc_claim);
        assert_eq!(
            &verdict.to_string(),
            doc_verdict,
            "{heading} {claim}: the docs say {doc_verdict}, the stored tables give {verdict}"
        );
    }
}

/// The rows of a figure's verdict table in a doc, as `(claim, verdict)`: the table after the
/// line `heading` in the section headed ``## `FIGURE` ``, its first and third cells (the
/// verdict without its bold), with escaped pipes (`\|`) kept inside their cells. Empty when the
/// section, the heading or the table is missing. For the tests that compare docs with the
/// verdicts of stored tables (issue 54).
#[cfg(test)]
pub(crate) fn doc_verdicts(doc: &str, figure: &str, heading: &str) -> Vec<(String, String)> {
    let lines: Vec<&str> = doc.lines().collect();
    let Some(sec) = lines.iter().position(|l| *l == format!("## `{figure}`")) else {
        return Vec::new();
    };
    let end = (sec + 1..lines.len())
        .find(|&k| lines[k].starts_with("## "))
        .unwrap_or(lines.len());
    let Some(head) = (sec..end).find(|&k| lines[k].trim() == heading) else {
        return Vec::new();
    };
    let cells = |line: &str| -> Vec<String> {
        let (mut out, mut cur, mut escaped) = (Vec::new(), String::new(), false);
        for c in line.trim().trim_matches('|').chars() {
            if c == '|' && !escaped {
                out.push(cur.trim().to_string());
                cur.clear();
            } else {
                cur.push(c);
            }
            escaped = c == '\\';
        }
        out.push(cur.trim().to_string());
        out
    };
    (head..end)
        .skip_while(|&k| !lines[k].starts_with('|'))
        .skip(2)
        .take_while(|&k| lines[k].starts_with('|'))
        .map(|k| cells(lines[k]))
        .filter(|c| c.len() >= 3)
        .map(|c| (c[0].clone(), c[2].trim_matches('*').to_string()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_numbers_read_back() {
        for f in Figure::ALL {
            assert_eq!(f.name().parse::<Figure>().unwrap(), f);
        }
        let e = "fig9".parse::<Figure>().unwrap_err().to_string();
        assert!(e.contains("threshold") && e.contains("all"), "{e}");
        assert_eq!("paper".parse::<Scale>().unwrap(), Scale::Paper);
        let (m, s) = mean_std(&[1.0, 2.0, 3.0, f64::NAN]);
        assert_eq!((m, s), (2.0, 1.0));
        assert_eq!(g(0.001234), "0.00123");
        assert_eq!(g(12.345), "12.3");
        assert_eq!(g(2.5e-5), "2.50e-5");
    }

    /// The paper scene is valid as it stands.
    #[test]
    fn the_paper_scene_validates() {
        scene::Scene::parse(PAPER_SCENE, &[]).unwrap();
    }
}
