//! Running the points of a sweep, `--jobs` at a time, each in its own run directory under
//! `runs/`, resumably; then `summary.csv`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use mechanics::{Callback, CallbackError, Observation, Precision, Schedule};
use phasefield::Real;
use rundir::{Interrupt, Outcome, RunDir};

use crate::analyze::{analyze, AnalyzeOptions};
use crate::plan::Point;
use crate::summary::{analysis_columns, summarise, window, ANALYSIS_COLUMNS, SUMMARY_COLUMNS};
use crate::SweepError;

/// The file that marks a finished run; it holds the run's resolved scene
/// ([`rundir::COMPLETE`]).
pub use rundir::COMPLETE;

/// How a sweep shares the machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SweepParams {
    /// Runs at a time.
    pub jobs: usize,
    /// Threads of each run; `jobs × threads` should be the cores. Results do not depend on
    /// either.
    pub threads: usize,
}

impl SweepParams {
    /// `jobs` runs at a time with `threads` threads each (both at least 1).
    pub fn new(jobs: usize, threads: usize) -> Self {
        Self {
            jobs: jobs.max(1),
            threads: threads.max(1),
        }
    }
}

/// What a sweep did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SweepInfo {
    /// Runs taken in this call.
    pub ran: usize,
    /// Runs found complete and skipped.
    pub skipped: usize,
    /// Steps of the runs taken.
    pub steps: u64,
}

/// A run of a sweep that a signal stopped (resumable).
#[derive(Debug, Clone, PartialEq)]
pub struct Stopped {
    /// Its run directory.
    pub dir: PathBuf,
    /// The step it stopped at.
    pub step: u64,
    /// Its model time.
    pub time: f64,
}

/// The run directory of `point` in the sweep directory `dir`.
pub fn run_dir(dir: &Path, point: &Point) -> PathBuf {
    dir.join("runs").join(&point.name)
}

/// Whether `point` has a complete run in `dir` with the same resolved scene.
pub fn is_complete(dir: &Path, point: &Point) -> bool {
    std::fs::read_to_string(run_dir(dir, point).join(COMPLETE))
        .is_ok_and(|scene| scene == point.scene.to_toml())
}

/// The points still to run, and the steps they take.
pub fn pending<'a>(dir: &Path, points: &'a [Point]) -> (Vec<&'a Point>, u64) {
    let todo: Vec<&Point> = points.iter().filter(|p| !is_complete(dir, p)).collect();
    let steps = todo
        .iter()
        .map(|p| p.scene.step_counts().total_steps())
        .sum();
    (todo, steps)
}

/// Runs every point of `points` that has no complete run in `dir` yet, `params.jobs` at a
/// time, each through a [`RunDir`] (locked; resumed from its checkpoint when it has one of
/// the same scene, started afresh otherwise, which removes its earlier output and analysis).
/// `progress` is told of the steps taken, every 10 steps of each run. When `interrupt`
/// catches a signal, the runs in progress stop after their step with a checkpoint and no new
/// run starts: the same call later continues them.
///
/// # Errors
/// The first run that fails (its directory keeps what it wrote, and no `complete` mark);
/// runs already started finish first. [`SweepError::Interrupted`] after a signal.
pub fn run_points(
    points: &[Point],
    dir: &Path,
    params: SweepParams,
    progress: Arc<dyn Fn(u64) + Send + Sync>,
    interrupt: &Interrupt,
) -> Result<SweepInfo, SweepError> {
    let (todo, steps) = pending(dir, points);
    let stops = Mutex::new(Vec::new());
    in_jobs(&todo, params, |p| {
        run_point(p, dir, progress.clone(), interrupt, &stops)
    })?;
    if let Some(signal) = interrupt.caught() {
        let mut runs = stops.into_inner().unwrap_or_else(|p| p.into_inner());
        runs.sort_by(|a, b| a.dir.cmp(&b.dir));
        return Err(SweepError::Interrupted { signal, runs });
    }
    Ok(SweepInfo {
        ran: todo.len(),
        skipped: points.len() - todo.len(),
        steps,
    })
}

/// Calls `f` on every item, at most `params.jobs` at a time, each call inside a rayon pool
/// of `params.threads` threads (one pool per job, reused); stops starting new calls after the
/// first error.
///
/// The jobs are plain threads, not a rayon pool: a rayon worker that waits in another pool's
/// `install` keeps busy with its own pool's work, so an outer rayon pool would start more
/// than `jobs` calls at once (every item at once, in practice).
///
/// # Errors
/// The first error of `f`, or [`SweepError::Threads`] (converted) when a pool cannot start.
pub fn in_jobs<I: Sync, E: From<SweepError> + Send>(
    items: &[I],
    params: SweepParams,
    f: impl Fn(&I) -> Result<(), E> + Sync,
) -> Result<(), E> {
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let first_error: Mutex<Option<E>> = Mutex::new(None);
    let fail = |e: E| {
        failed.store(true, Ordering::SeqCst);
        let mut slot = first_error.lock().unwrap_or_else(|p| p.into_inner());
        slot.get_or_insert(e);
    };
    std::thread::scope(|scope| {
        for _ in 0..params.jobs.min(items.len()) {
            scope.spawn(|| {
                let pool = match rayon::ThreadPoolBuilder::new()
                    .num_threads(params.threads)
                    .build()
                {
                    Ok(p) => p,
                    Err(e) => return fail(SweepError::Threads(e.to_string()).into()),
                };
                while !failed.load(Ordering::SeqCst) {
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let Some(item) = items.get(k) else { break };
                    if let Err(e) = pool.install(|| f(item)) {
                        fail(e);
                    }
                }
            });
        }
    });
    match first_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Makes `point`'s run directory ready for a fresh run: no `complete` mark, no earlier
/// output, its resolved `scene.toml` written. Returns the directory.
pub(crate) fn prepare_point(dir: &Path, point: &Point) -> Result<PathBuf, SweepError> {
    let out = run_dir(dir, point);
    let rd = |source| SweepError::RunDir {
        point: point.name.clone(),
        source,
    };
    let _ = std::fs::remove_file(out.join(COMPLETE));
    rundir::prepare(&out, true).map_err(rd)?;
    rundir::write_scene(&out, &point.scene).map_err(rd)?;
    Ok(out)
}

fn run_point(
    point: &Point,
    dir: &Path,
    progress: Arc<dyn Fn(u64) + Send + Sync>,
    interrupt: &Interrupt,
    stops: &Mutex<Vec<Stopped>>,
) -> Result<(), SweepError> {
    let out = run_dir(dir, point);
    let rd = |source| SweepError::Held {
        point: point.name.clone(),
        source: Box::new(source),
    };
    if interrupt.caught().is_some() {
        return Ok(());
    }
    let run = RunDir::resume_or_create(&out, point.scene.clone(), interrupt.clone()).map_err(rd)?;
    let outcome = match point.scene.precision() {
        Precision::F64 => run_in::<f64>(&run, progress),
        Precision::F32 => run_in::<f32>(&run, progress),
    }
    .map_err(rd)?;
    if let Outcome::Stopped { step, time, .. } = outcome {
        let mut s = stops.lock().unwrap_or_else(|p| p.into_inner());
        s.push(Stopped {
            dir: out,
            step,
            time,
        });
    }
    Ok(())
}

fn run_in<T: Real>(
    run: &RunDir,
    progress: Arc<dyn Fn(u64) + Send + Sync>,
) -> Result<Outcome, rundir::RunError> {
    let (mut sim, _) = run.simulation::<T>()?;
    let reported = run.resumed_from().unwrap_or(0);
    sim.add_callback(
        "progress",
        Schedule::IterationInterval(10),
        Steps { progress, reported },
    );
    run.run(&mut sim)
}

/// Tells the sweep's progress of the steps taken.
struct Steps {
    progress: Arc<dyn Fn(u64) + Send + Sync>,
    reported: u64,
}

impl<T: Real> Callback<T> for Steps {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        let it = obs.iteration();
        (self.progress)(it - self.reported);
        self.reported = it;
        Ok(())
    }

    fn finalize(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        self.call(obs)
    }
}

/// Writes `dir/summary.csv`: one row per point, in plan order, with the value on each axis
/// (headed by its key, as given to `--vary`), `seed`, and the run's [`summarise`] over the
/// second half of its active phase ([`window`]); with `analysed`, also its
/// [`analysis_columns`].
///
/// # Errors
/// A point whose run is not complete (or not analysed), or whose files cannot be read.
pub fn write_summary(
    dir: &Path,
    keys: &[String],
    points: &[Point],
    analysed: bool,
) -> Result<PathBuf, SweepError> {
    let mut text = keys.iter().map(|k| format!("{k},")).collect::<String>();
    text += "seed,";
    text += SUMMARY_COLUMNS;
    if analysed {
        text += ",";
        text += ANALYSIS_COLUMNS;
    }
    text += "\n";
    for p in points {
        if !is_complete(dir, p) {
            return Err(SweepError::Incomplete {
                point: p.name.clone(),
            });
        }
        let r = &p.scene.file().run;
        let s = summarise(&run_dir(dir, p), window(r.relax_time, r.time))?;
        for v in &p.values {
            text += v;
            text += ",";
        }
        text += &format!("{},{}", p.seed, s.csv());
        if analysed {
            text += ",";
            text += &analysis_columns(&run_dir(dir, p))?;
        }
        text += "\n";
    }
    let path = dir.join("summary.csv");
    let tmp = dir.join("summary.csv.partial");
    let io = |source| SweepError::write("summary.csv", &path, source);
    std::fs::write(&tmp, text).map_err(io)?;
    std::fs::rename(&tmp, &path).map_err(io)?;
    Ok(path)
}

/// The mark of an analysed run, `analysis/complete`: it holds the options it was analysed
/// with.
fn analysis_mark(opts: &AnalyzeOptions) -> String {
    format!("{opts:?}\n")
}

/// Analyses ([`crate::analyze::analyze`]) every complete run of `points` in `dir` that has not
/// been analysed with `opts` yet, `params.jobs` at a time, and marks each analysed run.
///
/// # Errors
/// The first run that cannot be analysed, or whose mark cannot be written.
pub fn analyze_points(
    points: &[Point],
    dir: &Path,
    opts: &AnalyzeOptions,
    params: SweepParams,
) -> Result<(), SweepError> {
    let mark = analysis_mark(opts);
    let todo: Vec<PathBuf> = points
        .iter()
        .filter(|p| is_complete(dir, p))
        .map(|p| run_dir(dir, p))
        .filter(|r| {
            std::fs::read_to_string(r.join("analysis/complete")).map_or(true, |m| m != mark)
        })
        .collect();
    in_jobs(&todo, params, |run| -> Result<(), SweepError> {
        let path = run.join("analysis/complete");
        let _ = std::fs::remove_file(&path);
        analyze(run, opts).map_err(|source| SweepError::Analyze {
            run: run.clone(),
            source,
        })?;
        std::fs::write(&path, &mark).map_err(|source| SweepError::write("analysis", &path, source))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// At most `jobs` calls run at once, even when each call runs rayon work of its own; every
    /// item is called once; the first error stops the rest.
    #[test]
    fn in_jobs_keeps_to_its_jobs() {
        let active = AtomicUsize::new(0);
        let most = AtomicUsize::new(0);
        let calls = AtomicUsize::new(0);
        let items: Vec<u64> = (0..12).collect();
        in_jobs(
            &items,
            SweepParams::new(2, 2),
            |&i| -> Result<(), SweepError> {
                let now = active.fetch_add(1, Ordering::SeqCst) + 1;
                most.fetch_max(now, Ordering::SeqCst);
                calls.fetch_add(1, Ordering::SeqCst);
                let s: u64 = (0..200_000u64).into_par_iter().map(|k| k ^ i).sum();
                std::thread::sleep(std::time::Duration::from_millis(5 + s % 2));
                active.fetch_sub(1, Ordering::SeqCst);
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(calls.load(Ordering::SeqCst), 12);
        assert!(
            most.load(Ordering::SeqCst) <= 2,
            "{} at once",
            most.load(Ordering::SeqCst)
        );
        let r = in_jobs(&items, SweepParams::new(1, 1), |&i| {
            if i == 3 {
                Err(SweepError::Threads("boom".into()))
            } else {
                Ok(())
            }
        });
        assert!(r.unwrap_err().to_string().contains("boom"));
    }
}
