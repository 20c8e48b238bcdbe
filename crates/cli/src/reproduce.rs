//! `monolayer reproduce FIGURE`: the `reproduce` figures, with a progress bar per
//! sweep and the verdicts printed at the end.

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use reproduce::{reproduce, Figure, FigureReport, Reporter, ReproduceParams, Scale};
use study::SweepParams;

/// Shows a reproduction's progress on stderr: a bar per sweep on a terminal, a line every
/// tenth of a sweep otherwise, nothing when quiet.
struct Progress {
    quiet: bool,
    bar: Mutex<Option<ProgressBar>>,
    done: AtomicU64,
    total: AtomicU64,
    lines: Mutex<crate::lines::Lines>,
}

impl Reporter for Progress {
    fn sweep(&self, name: &str, runs: usize, steps: u64) {
        if self.quiet {
            return;
        }
        let mut bar = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = bar.take() {
            b.finish();
        }
        self.done.store(0, Ordering::Relaxed);
        self.total.store(steps, Ordering::Relaxed);
        *self.lines.lock().unwrap_or_else(|e| e.into_inner()) = crate::lines::Lines::new();
        if runs == 0 {
            crate::say!("sweep {name}: every run is complete");
            return;
        }
        crate::say!("sweep {name}: {runs} runs, {steps} steps");
        if std::io::stderr().is_terminal() {
            let b = ProgressBar::new(steps);
            b.set_style(
                ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  [{elapsed_precise} < {eta_precise}]",
                )
                .expect("valid template"),
            );
            *bar = Some(b);
        }
    }

    fn steps(&self, n: u64) {
        if self.quiet {
            return;
        }
        let d = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let bar = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = bar.as_ref() {
            b.set_position(d);
        } else {
            let total = self.total.load(Ordering::Relaxed);
            let mut lines = self.lines.lock().unwrap_or_else(|e| e.into_inner());
            if lines.due(d as f64, total as f64) {
                crate::say!("  {d}/{total} steps");
            }
        }
    }

    fn stage(&self, what: &str) {
        if self.quiet {
            return;
        }
        if let Some(b) = self.bar.lock().unwrap_or_else(|e| e.into_inner()).take() {
            b.finish();
        }
        crate::say!("{what}");
    }
}

/// Makes `figure` (`all`: every figure in turn) into `out` and prints each verdict.
///
/// # Errors
/// A bad figure or scale name, or what stops a figure.
pub fn run(
    figure: &str,
    out: &Path,
    scale: &str,
    jobs: usize,
    threads: usize,
    quiet: bool,
) -> Result<Vec<FigureReport>> {
    let figures: Vec<Figure> = if figure == "all" {
        Figure::ALL.to_vec()
    } else {
        vec![figure.parse()?]
    };
    let scale: Scale = scale.parse()?;
    let reporter = Arc::new(Progress {
        quiet,
        bar: Mutex::new(None),
        done: AtomicU64::new(0),
        total: AtomicU64::new(0),
        lines: Mutex::new(crate::lines::Lines::new()),
    });
    let params = ReproduceParams::new(
        out.to_path_buf(),
        scale,
        SweepParams::new(jobs, threads),
        reporter.clone(),
    )
    .with_interrupt(rundir::Interrupt::install()?);
    let mut reports = Vec::new();
    for f in figures {
        let report = reproduce(f, &params)?;
        reporter.stage("");
        if !quiet {
            crate::say!(
                "{} ({:.0} s): {}",
                f.title(),
                report.wall_s,
                report.dir.join("verdict.md").display()
            );
            for c in &report.claims {
                crate::say!("  {}: {}", c.verdict, c.claim);
            }
        }
        reports.push(report);
    }
    Ok(reports)
}
