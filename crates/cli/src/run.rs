//! `monolayer run`: relaxation at ζ = 0, then the active phase, with series rows and frames
//! on their schedules.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mechanics::{Observables, Observer, Tissue, Workspace};
use phasefield::Real;

use crate::output::{write_frame, SeriesWriter};
use crate::scene::{Precision, Scene};

/// What a finished run reports.
#[derive(Debug, Clone, Copy)]
pub struct RunInfo {
    /// Steps taken.
    pub steps: u64,
    /// Wall time in seconds.
    pub wall_s: f64,
    /// Frames written.
    pub frames: usize,
}

/// Makes sure `out` holds no earlier run: with `overwrite`, removes its `series.csv`,
/// `scene.toml` and `frames/`; without, refuses.
///
/// # Errors
/// When `out` already holds a run and `overwrite` is false, or files cannot be removed.
pub fn prepare_output(out: &Path, overwrite: bool) -> Result<()> {
    let series = out.join("series.csv");
    if !series.exists() {
        return Ok(());
    }
    anyhow::ensure!(
        overwrite,
        "{} already holds a run (series.csv); choose another --out or pass --overwrite to replace it",
        out.display()
    );
    std::fs::remove_file(&series)?;
    let _ = std::fs::remove_file(out.join("scene.toml"));
    let frames = out.join("frames");
    if frames.exists() {
        std::fs::remove_dir_all(&frames)
            .with_context(|| format!("cannot remove {}", frames.display()))?;
    }
    Ok(())
}

/// Runs a validated scene, writing into `out`. On a step error the output written so far is
/// kept and the error is returned.
pub fn run(scene: &Scene, out: &Path, quiet: bool) -> Result<RunInfo> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;
    std::fs::write(out.join("scene.toml"), scene.to_toml())?;
    for w in scene.warnings() {
        eprintln!("warning: {w}");
    }
    match scene.integrator.precision {
        Precision::F64 => run_in::<f64>(scene, out, quiet),
        Precision::F32 => run_in::<f32>(scene, out, quiet),
    }
}

fn run_in<T: Real>(scene: &Scene, out: &Path, quiet: bool) -> Result<RunInfo> {
    let mut tissue: Tissue<T> = scene.build_in()?;
    let mut ws = Workspace::new(&tissue.cells);
    let protocol = scene.protocol();
    let sched = scene.schedule();
    let mut writer = Writer {
        out,
        series: SeriesWriter::create(out)?,
        frame_every: sched.frame_every,
        series_every: sched.series_every,
        frames: 0,
        progress: Progress::new(protocol.total_steps(), quiet),
    };
    let start = Instant::now();
    mechanics::run(&mut tissue, &mut ws, &protocol, &mut writer).with_context(|| {
        format!(
            "the run stopped; output up to step {} is kept in {}",
            tissue.step,
            out.display()
        )
    })?;
    writer.progress.finish();
    Ok(RunInfo {
        steps: protocol.total_steps(),
        wall_s: start.elapsed().as_secs_f64(),
        frames: writer.frames,
    })
}

/// Writes series rows and frames on their schedules.
struct Writer<'a> {
    out: &'a Path,
    series: SeriesWriter,
    frame_every: u64,
    series_every: u64,
    frames: usize,
    progress: Progress,
}

impl Writer<'_> {
    fn wants_frame(&self, step: u64, total: u64) -> bool {
        step.is_multiple_of(self.frame_every) || step == total
    }
    fn wants_series(&self, step: u64, total: u64) -> bool {
        step.is_multiple_of(self.series_every) || step == total
    }
}

impl Observer for Writer<'_> {
    type Error = anyhow::Error;

    fn wants(&self, step: u64, total: u64) -> bool {
        self.wants_frame(step, total) || self.wants_series(step, total)
    }

    fn observe<T: Real>(
        &mut self,
        tissue: &Tissue<T>,
        ws: &Workspace<T>,
        o: &Observables,
    ) -> Result<()> {
        let total = self.progress.total;
        if self.wants_series(tissue.step, total) {
            self.series.row(tissue, o)?;
        }
        if self.wants_frame(tissue.step, total) {
            write_frame(self.out, tissue, ws)?;
            self.frames += 1;
        }
        self.progress.report(tissue.step, tissue.time, o.v_rms);
        Ok(())
    }
}

/// A progress bar on a terminal, plain lines (about every 10 %) otherwise.
struct Progress {
    bar: Option<ProgressBar>,
    total: u64,
    quiet: bool,
    next_line: std::cell::Cell<u64>,
}

impl Progress {
    fn new(total: u64, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = ProgressBar::new(total);
            b.set_style(
                ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  {msg}  [{elapsed_precise} < {eta_precise}]",
                )
                .expect("valid template"),
            );
            b
        });
        Self {
            bar,
            total,
            quiet,
            next_line: std::cell::Cell::new(0),
        }
    }

    fn report(&self, step: u64, time: f64, v_rms: f64) {
        if let Some(b) = &self.bar {
            b.set_position(step);
            b.set_message(format!("t = {time:.1}  v_rms = {v_rms:.3e}"));
        } else if !self.quiet && (step >= self.next_line.get() || step == self.total) {
            eprintln!(
                "step {step}/{}  t = {time:.1}  v_rms = {v_rms:.3e}",
                self.total
            );
            self.next_line.set(step + self.total.div_ceil(10).max(1));
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish();
        }
    }
}
