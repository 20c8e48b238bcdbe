//! `monolayer sweep`: a scene over a grid of values and seeds (the `study` crate), with one
//! progress bar for the whole sweep.

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use study::{plan, run_points, write_summary, Seeds, SweepInfo, SweepParams, Vary};

/// The arguments of `monolayer sweep`, as parsed.
#[derive(Debug, Clone)]
pub struct SweepArgs<'a> {
    /// The scene file.
    pub scene: &'a Path,
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
}

/// Plans, runs (resumably) and summarises a sweep.
///
/// # Errors
/// A bad argument or scene (before anything runs), a failed run, or a file that cannot be
/// written.
pub fn sweep(a: &SweepArgs<'_>) -> Result<(SweepInfo, usize)> {
    let text = std::fs::read_to_string(a.scene)
        .with_context(|| format!("cannot read scene file {}", a.scene.display()))?;
    let varies = a
        .vary
        .iter()
        .map(|v| v.parse::<Vary>())
        .collect::<Result<Vec<_>, _>>()?;
    let seeds = a.seeds.map(|s| s.parse::<Seeds>()).transpose()?;
    let points = plan(&text, a.set, &varies, seeds)
        .with_context(|| format!("in scene {}", a.scene.display()))?;
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
    let next_line = Arc::new(AtomicU64::new(0));
    let (quiet, tick) = (a.quiet, total.div_ceil(10).max(1));
    let progress_bar = bar.clone();
    let progress = Arc::new(move |n: u64| {
        let d = done.fetch_add(n, Ordering::Relaxed) + n;
        if let Some(b) = &progress_bar {
            b.set_position(d);
        } else if !quiet && d >= next_line.load(Ordering::Relaxed) {
            next_line.store(d + tick, Ordering::Relaxed);
            eprintln!("{d}/{total} steps");
        }
    });
    let params = SweepParams::new(a.jobs, a.threads);
    let info = run_points(&points, a.out, params, progress)?;
    if let Some(b) = bar {
        b.finish();
    }
    let keys: Vec<String> = varies.iter().map(|v| v.key.clone()).collect();
    write_summary(a.out, &keys, &points)?;
    Ok((info, points.len()))
}
