//! `monolayer run`: relaxation at ζ = 0, then the active phase, with series rows and frames
//! on their schedules.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mechanics::{Tissue, Workspace};

use crate::output::{write_frame, SeriesWriter};
use crate::scene::Scene;

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

/// Runs a validated scene, writing into `out`. On a step error the output written so far is
/// kept and the error is returned.
pub fn run(scene: &Scene, out: &Path, quiet: bool) -> Result<RunInfo> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;
    std::fs::write(out.join("scene.toml"), scene.to_toml())?;
    let mut tissue: Tissue = scene.build()?;
    let mut ws = Workspace::new(&tissue.cells);
    let sched = scene.schedule();
    let step_params = scene.step_params();
    let mut series = SeriesWriter::create(out)?;
    let total = sched.relax_steps + sched.active_steps;
    let progress = Progress::new(total, quiet);
    let start = Instant::now();
    let mut frames = 0;
    for s in 0..=total {
        if s == sched.relax_steps {
            tissue.params.zeta = scene.model.zeta;
        }
        let want_series = s % sched.series_every == 0 || s == total;
        let want_frame = s % sched.frame_every == 0 || s == total;
        if want_series || want_frame {
            let o = tissue.observe(&mut ws);
            if want_series {
                series.row(&tissue, &o)?;
            }
            if want_frame {
                write_frame(out, &tissue, &ws)?;
                frames += 1;
            }
            progress.report(s, tissue.time, o.v_rms);
        }
        if s == total {
            break;
        }
        tissue.step(&mut ws, &step_params).with_context(|| {
            format!(
                "the run stopped; output up to step {} is kept in {}",
                tissue.step,
                out.display()
            )
        })?;
    }
    progress.finish();
    Ok(RunInfo {
        steps: total,
        wall_s: start.elapsed().as_secs_f64(),
        frames,
    })
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
