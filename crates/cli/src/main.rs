//! The `monolayer` binary: `monolayer run SCENE --out DIR`, and the commands that sweep,
//! analyse, reproduce, draw and export runs.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use monolayer_cli::run;
use monolayer_cli::say;
use monolayer_cli::sweep::{SweepAction, SweepOutcome};
use scene::Scene;
use study::analyze::{analyze, AnalyzeOptions};
use study::view::{export_vtk, render_run, RenderOptions};

/// Multi-phase-field simulations of cell monolayers (Mueller, Yeomans & Doostmohammadi, PRL 2019).
#[derive(Parser)]
#[command(name = "monolayer", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene file and write the series, frames and resolved scene into a directory.
    Run {
        /// The scene file (TOML).
        #[arg(required_unless_present = "resume")]
        scene: Option<PathBuf>,
        /// The output directory (created if missing).
        #[arg(long, required_unless_present = "resume", conflicts_with = "resume")]
        out: Option<PathBuf>,
        /// Continue the run in DIR from its latest checkpoint to the end of its scene (with
        /// `--set run.time=T`: extend a finished run). The directory ends as one
        /// uninterrupted run would have left it.
        #[arg(long, value_name = "DIR", conflicts_with = "scene")]
        resume: Option<PathBuf>,
        /// Worker threads (default: all cores). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Override a scene value, e.g. `--set model.zeta=0.005` (repeatable).
        #[arg(long = "set", value_name = "SECTION.KEY=VALUE")]
        set: Vec<String>,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
        /// Replace the results of an earlier run in the output directory.
        #[arg(long)]
        overwrite: bool,
        /// Refuse scenes whose memory estimate exceeds this, e.g. `8G` or `512M` (default:
        /// the memory available on this machine).
        #[arg(long, value_name = "BYTES")]
        max_memory: Option<String>,
    },
    /// Run a scene over a grid of values and seeds: each point an ordinary run directory under
    /// OUT/runs/, and OUT/summary.csv with one row per run. A second call with the same
    /// arguments redoes only the runs that did not finish.
    Sweep(SweepCmd),
    /// The activity threshold of a sweep: for every combination of its other axes, the
    /// activity where the late growth rate of ln v_rms first exceeds that of zeta = 0 from the
    /// same seeds (linear interpolation, with its bracket); writes DIR/threshold.csv.
    Threshold {
        /// A sweep directory (its summary.csv), whose axes include the activity with 0.
        dir: PathBuf,
        /// The activity's key as given to --vary.
        #[arg(long, default_value = "model.zeta")]
        key: String,
    },
    /// Reproduce a figure of the paper from its scene: the sweeps it needs (resumable, in
    /// OUT/sweeps/), its data as CSV, its plots as PNG and OUT/FIGURE/verdict.md, a verdict
    /// on each claim of the paper that it tests.
    Reproduce {
        /// threshold, lengths, defects, defect-fields, contractile, scaling, stability, bloch,
        /// run-length, channel, rotation, flocking, sorting, jamming, extrusion, friction,
        /// contractile-extensile, bend-splay, or all.
        figure: String,
        /// The output directory (created if missing; a second call resumes).
        #[arg(long)]
        out: PathBuf,
        /// quick (3 seeds, short runs, minutes per figure on 2 cores) or paper (5 seeds, the
        /// paper's sizes and integrator).
        #[arg(long, default_value = "quick")]
        scale: String,
        /// Runs at a time; each gets cores / jobs threads. Results do not depend on it.
        #[arg(long, default_value_t = 1)]
        jobs: usize,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Draw the frames of a run directory: one PNG per frame (each cell's contour φ_i = 1/2,
    /// filled by a quantity with a colour bar; on request the director, the ±1/2 defects, the
    /// flow and the deformation axes), and optionally a movie.
    Render(RenderCmd),
    /// Write a run directory as files other programs open.
    Export {
        #[command(subcommand)]
        format: ExportFormat,
    },
    /// Analyse a run directory: observables, correlations, defects and defect-centred
    /// averages, written into RUN_DIR/analysis/.
    Analyze {
        /// A directory written by `monolayer run`.
        run_dir: PathBuf,
        #[command(flatten)]
        analysis: AnalysisArgs,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// No summary (notes on missing or skipped frames are still printed).
        #[arg(long, short)]
        quiet: bool,
    },
}

/// The options of `monolayer analyze` (also those of `sweep --analyze`).
#[derive(clap::Args)]
struct AnalysisArgs {
    /// First time analysed (default: the end of relaxation).
    #[arg(long)]
    from: Option<f64>,
    /// Side of the smoothing box, odd (default: the odd side nearest 3R).
    #[arg(long = "box")]
    box_side: Option<usize>,
    /// Side of the defect-centred crops, odd (default: 101, or twice the lattice's shorter
    /// side plus one when that is smaller).
    #[arg(long)]
    crop: Option<usize>,
    /// Longest link of a defect between frames (default: R).
    #[arg(long)]
    max_link: Option<f64>,
    /// Largest separation of a created or annihilated pair (default: 2R).
    #[arg(long)]
    max_pair: Option<f64>,
    /// S_rms of a zeta = 0 run, to report S_rms relative to it.
    #[arg(long)]
    s_rms_baseline: Option<f64>,
}

impl AnalysisArgs {
    fn options(&self) -> AnalyzeOptions {
        AnalyzeOptions {
            from: self.from,
            box_side: self.box_side,
            crop_side: self.crop,
            max_link: self.max_link,
            max_pair: self.max_pair,
            s_rms_baseline: self.s_rms_baseline,
        }
    }

    fn given(&self) -> bool {
        self.options() != AnalyzeOptions::default()
    }
}

#[derive(Subcommand)]
enum ExportFormat {
    /// ParaView: one ImageData .vti per frame (phi_sum, cell_id, velocity, Q, director,
    /// pressure, stress), one PolyData .vtp of the cell centres per frame, and .pvd time series
    /// of both.
    Vtk {
        /// A directory written by `monolayer run`.
        run_dir: PathBuf,
        /// The directory of the files (default: RUN_DIR/vtk).
        #[arg(long)]
        out: Option<PathBuf>,
        /// `all`, or steps such as `0,500,1000`.
        #[arg(long, default_value = "all")]
        frames: String,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
    },
}

fn main() -> ExitCode {
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            // A sweep (or a figure's sweeps) stopped by a signal: resumable, not failed.
            let stopped = e.chain().find_map(|c| match c.downcast_ref() {
                Some(study::SweepError::Interrupted { signal, .. }) => Some(*signal),
                _ => None,
            });
            match stopped {
                Some(signal) => {
                    say!("{e:#}");
                    signal_exit(signal)
                }
                None => {
                    say!("error: {e:#}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}

/// The exit status of a process stopped by `signal`: 128 + its number, as a shell reports it.
fn signal_exit(signal: i32) -> ExitCode {
    ExitCode::from((128 + signal).clamp(0, 255) as u8)
}

/// What `run` prints at its end, and its exit status: 0, or 128 + the signal that stopped it.
fn finished(info: &run::RunInfo, dir: &std::path::Path, quiet: bool) -> ExitCode {
    if let Some((step, time, signal)) = info.stopped {
        // To nine digits: the clock sums steps (778.0000000000399 for 778).
        let time = (time * 1e9).round() / 1e9;
        // Printed even with --quiet: the run did not do what was asked.
        say!(
            "stopped at step {step} (t = {time}): resume with monolayer run --resume {}",
            dir.display()
        );
        return signal_exit(signal);
    }
    if !quiet {
        let resumed = info
            .resumed_from
            .map(|s| format!("resumed at step {s}, "))
            .unwrap_or_default();
        say!(
            "done: {resumed}{} steps in {:.2} s, {} frames in {}",
            info.steps,
            info.wall_s,
            info.frames,
            dir.display()
        );
    }
    ExitCode::SUCCESS
}

#[derive(clap::Args)]
struct SweepCmd {
    /// The scene file (TOML); with `--collect` it may be left out, and the sweep recorded in
    /// OUT is read.
    #[arg(required_unless_present = "collect")]
    scene: Option<PathBuf>,
    /// An axis of the grid, e.g. `--vary model.zeta=0.004,0.006` (repeatable; the last
    /// varies fastest).
    #[arg(long = "vary", value_name = "SECTION.KEY=V1,V2,...")]
    vary: Vec<String>,
    /// Seeds of each point, `A-B` or `A` (default: the scene's `[run] seed`).
    #[arg(long)]
    seeds: Option<String>,
    /// Override a scene value for every point (repeatable).
    #[arg(long = "set", value_name = "SECTION.KEY=VALUE")]
    set: Vec<String>,
    /// The sweep directory (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Runs at a time; each gets cores / jobs threads. Results do not depend on it.
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// No progress output.
    #[arg(long, short)]
    quiet: bool,
    /// Where the runs happen: `local` (here, the default) or `slurm` (writes
    /// OUT/slurm/sweep.sbatch, a job array of one task per run that is not complete).
    #[arg(long, default_value = "local", value_parser = ["local", "slurm"])]
    backend: String,
    /// With `--backend slurm`: submit the job array with `sbatch`.
    #[arg(long)]
    submit: bool,
    /// Only build OUT/summary.csv from the finished runs (after a SLURM sweep).
    #[arg(long, conflicts_with = "submit")]
    collect: bool,
    /// Threads of each run (default: cores / jobs; with `--backend slurm`, the CPUs of each
    /// task, default 1).
    #[arg(long)]
    threads: Option<usize>,
    /// Analyse every run (as `monolayer analyze`) and add the three correlation lengths,
    /// the defect density and the creation rate to the summary.
    #[arg(long)]
    analyze: bool,
    /// With `--analyze`: the options of `monolayer analyze`.
    #[command(flatten)]
    analysis: AnalysisArgs,
    /// Refuse a local sweep whose largest point, times --jobs, has a memory estimate above
    /// this, e.g. `8G` (default: the memory available on this machine).
    #[arg(long, value_name = "BYTES")]
    max_memory: Option<String>,
}

#[derive(clap::Args)]
struct RenderCmd {
    /// A directory written by `monolayer run`.
    run_dir: PathBuf,
    /// The directory of the PNGs (created if missing; not needed with --no-pngs).
    #[arg(long, required_unless_present = "no_pngs")]
    out: Option<PathBuf>,
    /// `all`, or steps such as `0,500,1000` (the numbers in frames/frame_STEP.npz).
    #[arg(long, default_value = "all")]
    frames: String,
    /// What fills the cells: none, velocity (|v_i|), pressure (the cell's mean P), area,
    /// deformation (|S_i|), id (a colour per cell), population ([[population]], a colour
    /// each, named in a legend), generation and lineage (with [division]: a colour per
    /// generation, named in a legend, or per founder).
    #[arg(long, default_value = "none")]
    colour: String,
    /// The director of the smoothed Q, as short segments.
    #[arg(long)]
    director: bool,
    /// The ±1/2 defects of the smoothed Q: a comet for +1/2 (tail along its orientation),
    /// three arms for -1/2.
    #[arg(long)]
    defects: bool,
    /// Whose director and defects --director and --defects draw: shape (the cells' shapes'
    /// Q) or nematic (the cells' own nematic field M = sum phi_i q_i, scenes with [nematic];
    /// the defects of analysis/defects_nematic.csv).
    #[arg(long, default_value = "shape")]
    director_of: String,
    /// Arrows of the velocity field.
    #[arg(long)]
    flow: bool,
    /// Each cell's principal deformation axis (with --colour none: the paper's Fig. 1b).
    #[arg(long)]
    axes: bool,
    /// Each cell's polarity as an arrow (scenes with [polarity]).
    #[arg(long)]
    polarity: bool,
    /// Each cell's own nematic axis as a segment (scenes with [nematic]).
    #[arg(long)]
    nematic: bool,
    /// Each cell's track: its centre through every frame of the run up to the one drawn.
    #[arg(long)]
    tracks: bool,
    /// The divisions (rings), extrusions (black ×) and deaths (grey ×) since the frame
    /// before, from lineage.csv (scenes with [division]).
    #[arg(long)]
    events: bool,
    /// The picture's width in pixels (default: 4 per node, from 400 to 1000).
    #[arg(long)]
    size: Option<u32>,
    /// The colour bar's range `LOW,HIGH` (default: each frame's own; fix it for movies).
    #[arg(long, value_name = "LOW,HIGH")]
    range: Option<String>,
    /// Also a movie of the frames: FILE.gif or FILE.apng (pure Rust) or FILE.mp4 (needs
    /// ffmpeg on the PATH).
    #[arg(long)]
    movie: Option<PathBuf>,
    /// Frames per second of the movie.
    #[arg(long, default_value_t = 5.0)]
    fps: f64,
    /// With --movie: no PNG per frame.
    #[arg(long, requires = "movie")]
    no_pngs: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress output.
    #[arg(long, short)]
    quiet: bool,
}

/// `monolayer sweep`.
fn sweep_command(cmd: SweepCmd) -> Result<ExitCode> {
    let SweepCmd {
        scene,
        vary,
        seeds,
        set,
        out,
        jobs,
        quiet,
        backend,
        submit,
        collect,
        threads,
        analyze,
        analysis,
        max_memory,
    } = cmd;
    anyhow::ensure!(
        analyze || !analysis.given(),
        "--from, --box, --crop, --max-link, --max-pair and --s-rms-baseline are options of the analysis: add --analyze"
    );
    anyhow::ensure!(
        !(analyze && backend == "slurm" && !collect),
        "--analyze runs after the runs: give it with --collect once the SLURM tasks are done"
    );
    anyhow::ensure!(jobs >= 1, "--jobs must be at least 1");
    anyhow::ensure!(threads != Some(0), "--threads must be at least 1");
    anyhow::ensure!(
        !submit || backend == "slurm",
        "--submit needs --backend slurm"
    );
    let action = if collect {
        SweepAction::Collect
    } else if backend == "slurm" {
        SweepAction::Slurm { submit }
    } else {
        SweepAction::Local
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let default_threads = match action {
        SweepAction::Slurm { .. } => 1,
        _ => (cores / jobs).max(1),
    };
    let args = monolayer_cli::sweep::SweepArgs {
        scene: scene.as_deref(),
        vary: &vary,
        seeds: seeds.as_deref(),
        set: &set,
        out: &out,
        jobs,
        threads: threads.unwrap_or(default_threads),
        quiet,
        action,
        max_memory: max_memory.as_deref(),
        analyze: analyze.then(|| analysis.options()),
    };
    match monolayer_cli::sweep::sweep(&args)? {
        SweepOutcome::Ran(info, n) if !quiet => say!(
            "done: {} of {n} runs taken ({} steps), {} already complete; summary in {}",
            info.ran,
            info.steps,
            info.skipped,
            out.join("summary.csv").display()
        ),
        SweepOutcome::JobArray(job, submitted) if !quiet => match (job.tasks, submitted) {
            (0, _) => say!("every run is complete; build the summary with --collect"),
            (n, Some(s)) => say!(
                "{s}: {n} array tasks from {}; when they are done, run monolayer sweep --collect --out {}",
                job.script.display(),
                out.display()
            ),
            (n, None) => say!(
                "wrote {} ({n} array tasks); submit it with sbatch, then run monolayer sweep --collect --out {}",
                job.script.display(),
                out.display()
            ),
        },
        SweepOutcome::Collected(n) if !quiet => {
            say!("summary of {n} runs in {}", out.join("summary.csv").display())
        }
        _ => {}
    }
    Ok(ExitCode::SUCCESS)
}

/// `monolayer render`.
fn render_command(cmd: RenderCmd) -> Result<ExitCode> {
    let RenderCmd {
        run_dir,
        out,
        frames,
        colour,
        director,
        defects,
        director_of,
        flow,
        axes,
        polarity,
        nematic,
        tracks,
        events,
        size,
        range,
        movie,
        fps,
        no_pngs,
        threads,
        quiet,
    } = cmd;
    let range = range
        .map(|r| {
            let v: Vec<f64> = r.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            match v[..] {
                [lo, hi] => Ok((lo, hi)),
                _ => Err(anyhow::anyhow!(
                    "--range {r}: give two numbers LOW,HIGH, e.g. --range 0,0.01"
                )),
            }
        })
        .transpose()?;
    let opts = RenderOptions {
        frames: frames.parse().map_err(anyhow::Error::msg)?,
        colour: colour.parse().map_err(anyhow::Error::msg)?,
        director,
        defects,
        director_of: director_of.parse().map_err(anyhow::Error::msg)?,
        flow,
        axes,
        polarity,
        nematic,
        tracks,
        events,
        size,
        range,
        movie,
        fps,
        pngs: !no_pngs,
    };
    // With --no-pngs only the movie is written, beside which nothing else goes.
    let out = out.unwrap_or_else(|| {
        let m = opts.movie.as_deref().unwrap_or(std::path::Path::new("."));
        m.parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."))
            .to_path_buf()
    });
    let mut progress = monolayer_cli::view::frames_progress("drawn", quiet);
    let info = pool(threads)?.install(|| render_run(&run_dir, &out, &opts, &mut progress))?;
    if !quiet {
        note_skipped(&info.notes, &run_dir);
        match &opts.movie {
            Some(m) if no_pngs => {
                say!("drew {} frames into {}", info.frames, m.display())
            }
            Some(m) => say!(
                "drew {} frames into {} and {}",
                info.frames,
                out.display(),
                m.display()
            ),
            None => say!("drew {} frames into {}", info.frames, out.display()),
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn real_main() -> Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run {
            scene,
            out,
            threads,
            set,
            quiet,
            overwrite,
            max_memory,
            resume,
        } => {
            if let Some(dir) = resume {
                let pool = pool(threads)?;
                let info =
                    pool.install(|| run::resume(&dir, &set, quiet, max_memory.as_deref()))?;
                return Ok(finished(&info, &dir, quiet));
            }
            let (Some(scene), Some(out)) = (scene, out) else {
                anyhow::bail!("give a scene and --out DIR, or --resume DIR");
            };
            let text = std::fs::read_to_string(&scene)
                .with_context(|| format!("cannot read scene file {}", scene.display()))?;
            let set = run::absolute_from(&scene, &text, &set)?;
            let parsed = Scene::parse(&text, &set)
                .with_context(|| format!("in scene {}", scene.display()))?;
            // The memory guard, the saved state (read before --out is prepared: --overwrite
            // may remove the frame it names) and the warnings, as every front end has them.
            let limit = monolayer_cli::guard::limit(max_memory.as_deref())?;
            let new = rundir::prepare_new_run(&parsed, limit, monolayer_cli::guard::MORE_MEMORY)
                .with_context(|| format!("in scene {}", scene.display()))?;
            let pool = pool(threads)?;
            let info = pool.install(|| run::run(&parsed, new, &out, overwrite, quiet))?;
            Ok(finished(&info, &out, quiet))
        }
        Command::Sweep(cmd) => sweep_command(cmd),
        Command::Reproduce {
            figure,
            out,
            scale,
            jobs,
            quiet,
        } => {
            anyhow::ensure!(jobs >= 1, "--jobs must be at least 1");
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            monolayer_cli::reproduce::run(
                &figure,
                &out,
                &scale,
                jobs,
                (cores / jobs).max(1),
                quiet,
            )?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Threshold { dir, key } => {
            let path = dir.join("summary.csv");
            let summary = std::fs::read_to_string(&path).with_context(|| {
                format!(
                    "cannot read {}: run monolayer sweep --out {} first",
                    path.display(),
                    dir.display()
                )
            })?;
            let table = study::threshold::threshold_table(&summary, &key)?;
            let out = dir.join("threshold.csv");
            std::fs::write(&out, &table)
                .with_context(|| format!("cannot write {}", out.display()))?;
            print!("{table}");
            for note in threshold_notes(&table) {
                say!("note: {note}");
            }
            say!("written to {}", out.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Render(cmd) => render_command(cmd),
        Command::Export {
            format:
                ExportFormat::Vtk {
                    run_dir,
                    out,
                    frames,
                    threads,
                    quiet,
                },
        } => {
            let out = out.unwrap_or_else(|| run_dir.join("vtk"));
            let frames = frames.parse().map_err(anyhow::Error::msg)?;
            let mut progress = monolayer_cli::view::frames_progress("exported", quiet);
            let info =
                pool(threads)?.install(|| export_vtk(&run_dir, &out, &frames, &mut progress))?;
            if !quiet {
                note_skipped(&info.notes, &run_dir);
                say!(
                    "exported {} frames; open {} (and cells.pvd) in ParaView",
                    info.frames,
                    out.join("fields.pvd").display()
                );
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Analyze {
            run_dir,
            analysis,
            threads,
            quiet,
        } => {
            let opts = analysis.options();
            let info = pool(threads)?.install(|| analyze(&run_dir, &opts))?;
            note_skipped(&info.notes, &run_dir);
            if quiet {
                return Ok(ExitCode::SUCCESS);
            }
            if info.cell_events > 0 {
                say!(
                    "{} divisions, extrusions and deaths, with their distances to the defects, in cell_events.csv",
                    info.cell_events
                );
            }
            say!(
                "analysed {} frames: {} defects, {} creation/annihilation events; results in {}",
                info.frames,
                info.defects,
                info.events,
                run_dir.join("analysis").display()
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn note_skipped(notes: &study::analyze::FrameNotes, run_dir: &std::path::Path) {
    let study::analyze::FrameNotes {
        partial,
        stray,
        missing,
        first_missing,
        complete,
    } = notes;
    if !complete {
        say!(
            "note: {} is not marked complete: the run is still being written or was killed (continue it with monolayer run --resume {0})",
            run_dir.display()
        );
    }
    if *partial > 0 {
        say!("note: skipped {partial} partially written frame(s)");
    }
    if let Some(first) = first_missing {
        say!(
            "note: {missing} frame(s) of the run's schedule are missing, the first at t ≈ {first:.3}: time differences and rates span the gap"
        );
    }
    if let Some(first) = stray.first() {
        say!(
            "note: ignored {} file(s) in frames/ that are not frame_STEP.npz (e.g. {first})",
            stray.len()
        );
    }
}

fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(monolayer_cli::guard::threads(n)?);
    }
    Ok(pool.build()?)
}

/// Why a row of `threshold.csv` has no estimate, in words: an empty `zeta_cr` means that the
/// sweep's activities do not bracket the threshold (the tour's two activities over 100 TU
/// cannot), which the table alone does not say.
fn threshold_notes(table: &str) -> Vec<String> {
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name);
    let (Some(cr), Some(lo), Some(hi), Some(act)) = (
        col("zeta_cr"),
        col("zeta_cr_lo"),
        col("zeta_cr_hi"),
        col("activities"),
    ) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (k, line) in lines.enumerate() {
        let v: Vec<&str> = line.split(',').collect();
        if v.get(cr).is_none_or(|c| !c.is_empty()) {
            continue;
        }
        let (lo, hi, n) = (
            v.get(lo).copied().unwrap_or(""),
            v.get(hi).copied().unwrap_or(""),
            v.get(act).copied().unwrap_or("?"),
        );
        let why = match (lo.is_empty(), hi.is_empty()) {
            (true, false) => format!("the growth of ln v_rms already exceeds ζ = 0's at the smallest activity {hi}, so the threshold lies below it (or the runs are too short to tell ζ = 0 from it)"),
            (false, true) => format!("no activity up to {lo} grows faster than ζ = 0, so the threshold lies above it"),
            _ => "no activity could be compared with ζ = 0".to_string(),
        };
        out.push(format!(
            "row {}: no estimate: {why}; the sweep has {n} activit{} beside ζ = 0. A threshold needs activities on both sides of it and runs long enough for the late growth rate (the paper's: --vary model.zeta=0,0.001,0.002,0.003,0.004,0.006,0.008 --set run.time=1000, or `monolayer reproduce threshold`)",
            k + 1,
            if n == "1" { "y" } else { "ies" }
        ));
    }
    out
}
