//! `monolayer sweep`: a scene over a grid of values and seeds (the `study` crate), with one
//! progress bar for the whole sweep.

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use study::{run_points, write_summary, Seeds, SweepInfo, SweepParams, SweepSpec, Vary};

use study::analyze::AnalyzeOptions;

/// The arguments of `monolayer sweep`, as parsed.
#[derive(Debug, Clone)]
pub struct SweepArgs<'a> {
    /// The scene file (none with `--collect`: the sweep directory's record is read).
    pub scene: Option<&'a Path>,
    /// `--vary` arguments.
    pub vary: &'a [String],
    /// `--seeds`.
    pub seeds: Option<&'a str>,
    /// `--set` overrides.
    pub set: &'a [String],
    /// `--out`.
    pub out: &'a Path,
    /// `--jobs`.
    pub jobs: usize,
    /// Threads per run.
    pub threads: usize,
    /// `--quiet`.
    pub quiet: bool,
    /// What to do.
    pub action: SweepAction,
    /// `--max-memory`.
    pub max_memory: Option<&'a str>,
    /// `--analyze`: analyse every run (as `monolayer analyze`, from `--from`) and add the
    /// lengths and defect statistics to the summary.
    pub analyze: Option<AnalyzeOptions>,
}

/// What `monolayer sweep` does with its plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepAction {
    /// Run here (`--backend local`, the default), then write the summary.
    Local,
    /// Write a SLURM job array (`--backend slurm`), and submit it with `sbatch` if asked.
    Slurm {
        /// `--submit`.
        submit: bool,
    },
    /// Only write the summary of the finished runs (`--collect`).
    Collect,
}

/// What `monolayer sweep` did.
#[derive(Debug, Clone)]
pub enum SweepOutcome {
    /// Ran here: what ran, and the number of points.
    Ran(SweepInfo, usize),
    /// Wrote a job array (and the output of `sbatch`, if submitted).
    JobArray(study::JobArray, Option<String>),
    /// Collected the summary of this many points.
    Collected(usize),
}

/// Plans, runs (resumably) and summarises a sweep.
///
/// # Errors
/// A bad argument or scene (before anything runs), a failed run, or a file that cannot be
/// written.
pub fn sweep(a: &SweepArgs<'_>) -> Result<SweepOutcome> {
    let spec = match a.scene {
        None => SweepSpec::load(a.out)?,
        Some(path) => {
            let scene_text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read scene file {}", path.display()))?;
            SweepSpec {
                sets: crate::run::absolute_from(path, &scene_text, a.set)?,
                scene_text,
                varies: a
                    .vary
                    .iter()
                    .map(|v| v.parse::<Vary>())
                    .collect::<Result<Vec<_>, _>>()?,
                seeds: a.seeds.map(|s| s.parse::<Seeds>()).transpose()?,
            }
        }
    };
    let points = spec.plan().with_context(|| match a.scene {
        Some(p) => format!("in scene {}", p.display()),
        None => format!("in the sweep recorded in {}", a.out.display()),
    })?;
    if a.action == SweepAction::Local {
        if let Some(p) = points
            .iter()
            .find(|p| p.scene.backend() == scene::ComputeBackend::Gpu)
        {
            anyhow::bail!(
                "sweep point {}: [integrator] backend = \"gpu\": a local sweep runs its points on the CPU, several at a time; \
                 run GPU points one at a time with `monolayer run SCENE --set integrator.backend=gpu`, \
                 or write them as a SLURM job array (`--backend slurm`), whose tasks each run `monolayer run`",
                p.name
            );
        }
    }
    if a.action != SweepAction::Collect {
        // The saved states the points start from (init = "frame"), each read once and
        // checked against its points before anything runs.
        let mut checked = std::collections::HashSet::new();
        for p in &points {
            let s = p.scene.file();
            let key = (p.scene.init_from(), s.domain.lx, s.domain.ly, s.cells.count);
            if key.0.is_some() && checked.insert(key) {
                rundir::initial_state(&p.scene)
                    .with_context(|| format!("in sweep point {}", p.name))?;
            }
        }
        std::fs::create_dir_all(a.out)
            .with_context(|| format!("cannot create {}", a.out.display()))?;
        spec.save(a.out)?;
    }
    let keys = spec.keys();
    match a.action {
        SweepAction::Local => {
            // The largest point, as many at once as --jobs runs.
            let biggest = points.iter().max_by(|p, q| {
                p.scene
                    .memory_estimate()
                    .total_cmp(&q.scene.memory_estimate())
            });
            if let Some(p) = biggest {
                crate::guard::memory_of(&p.scene, a.jobs.min(points.len()), a.max_memory)
                    .with_context(|| format!("in sweep point {}", p.name))?;
            }
        }
        SweepAction::Collect => {
            if let Some(opts) = &a.analyze {
                study::analyze_points(&points, a.out, opts, SweepParams::new(a.jobs, a.threads))?;
            }
            write_summary(a.out, &keys, &points, a.analyze.is_some())?;
            return Ok(SweepOutcome::Collected(points.len()));
        }
        SweepAction::Slurm { submit } => {
            let binary = std::env::current_exe().context("cannot find the monolayer binary")?;
            let job = study::write_job_array(a.out, &points, &binary, a.threads)?;
            let submitted = if submit && job.tasks > 0 {
                let o = std::process::Command::new("sbatch")
                    .arg(&job.script)
                    .output()
                    .context("cannot run sbatch: is SLURM installed and on the PATH? Without --submit the script is written for you to submit")?;
                anyhow::ensure!(
                    o.status.success(),
                    "sbatch {} failed: {}",
                    job.script.display(),
                    String::from_utf8_lossy(&o.stderr).trim()
                );
                Some(String::from_utf8_lossy(&o.stdout).trim().to_string())
            } else {
                None
            };
            return Ok(SweepOutcome::JobArray(job, submitted));
        }
    }
    std::fs::create_dir_all(a.out).with_context(|| format!("cannot create {}", a.out.display()))?;
    let (_, total) = study::pending(a.out, &points);
    let bar = (!a.quiet && std::io::stderr().is_terminal()).then(|| {
        let b = ProgressBar::new(total);
        b.set_style(
            ProgressStyle::with_template(
                "{bar:40} {pos}/{len} steps  [{elapsed_precise} < {eta_precise}]",
            )
            .expect("valid template"),
        );
        b
    });
    let done = Arc::new(AtomicU64::new(0));
    let lines = std::sync::Mutex::new(crate::lines::Lines::new());
    let quiet = a.quiet;
    let progress_bar = bar.clone();
    let progress = Arc::new(move |n: u64| {
        let d = done.fetch_add(n, Ordering::Relaxed) + n;
        if let Some(b) = &progress_bar {
            b.set_position(d);
        } else if !quiet
            && lines
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .due(d as f64, total as f64)
        {
            crate::say!("{d}/{total} steps");
        }
    });
    let params = SweepParams::new(a.jobs, a.threads);
    let interrupt = rundir::Interrupt::install()?;
    let info = run_points(&points, a.out, params, progress, &interrupt)?;
    if let Some(b) = bar {
        b.finish();
    }
    if let Some(opts) = &a.analyze {
        study::analyze_points(&points, a.out, opts, SweepParams::new(a.jobs, a.threads))?;
    }
    write_summary(a.out, &keys, &points, a.analyze.is_some())?;
    Ok(SweepOutcome::Ran(info, points.len()))
}
