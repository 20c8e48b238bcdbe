//! A run directory as one value, [`RunDir`]: it creates a new run or resumes one from its
//! newest checkpoint, holds the directory's lock while it lives, hands back the ready
//! [`Simulation`] with every writer attached, runs it until the end or until a signal
//! ([`Interrupt`]), and marks the run complete. `monolayer run`, `--resume` and every run of a
//! local sweep go through it, so they share one life cycle:
//!
//! 1. [`RunDir::create`] (a new run: the directory prepared, `scene.toml` written),
//!    [`RunDir::resume`] (`--resume`: the newest readable checkpoint whose scene is the run's
//!    own) or [`RunDir::resume_or_create`] (a sweep's point: resumed when it has such a
//!    checkpoint, started afresh otherwise);
//! 2. [`RunDir::simulation`]: the tissue (from the scene, a saved state or the checkpoint), the
//!    series and frame writers, the checkpoints, and a callback that stops the run after the
//!    step in progress when the [`Interrupt`] has caught a signal;
//! 3. [`RunDir::run`]: runs it and returns [`Outcome::Complete`] (the run is marked complete)
//!    or [`Outcome::Stopped`] (the final checkpoint is written; `monolayer run --resume DIR`
//!    continues it bit for bit).

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use mechanics::{
    Callback, CallbackError, Needs, Observation, RunInfo, Schedule, Simulation, SimulationError,
};
use phasefield::{Cells, Real};
use scene::Scene;

use crate::writers::{add_checkpoints_with, add_writers, add_writers_resumed, Written};
use crate::{checkpoint, RunDirError};

/// The lock file of a run directory: it exists while and after a process holds the directory
/// (an advisory `flock`, released by the operating system when the holder exits, however it
/// exits), and holds a line naming its holder.
pub const LOCK: &str = ".lock";

/// The least wall time between two checkpoints on the default schedule (a twentieth of the
/// run): short runs write their final one only, and long ones spend a bounded share of their
/// time on them. An explicit `[run] checkpoint_every` is kept as given.
pub const MIN_CHECKPOINT_WALL: Duration = Duration::from_secs(60);

/// Why a run directory cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// A file of the directory.
    #[error(transparent)]
    Files(#[from] RunDirError),
    /// Another process holds the directory.
    #[error("{} is in use by another monolayer process ({holder}); wait for it to finish, or stop it (a stopped run can be continued with monolayer run --resume {0})", dir.display())]
    Locked {
        /// The directory.
        dir: PathBuf,
        /// What the lock file says of its holder.
        holder: String,
    },
    /// Nothing to resume from.
    #[error("{0} has no checkpoint to resume from: a run writes one at the end, on a signal, on [run] checkpoint_every and after each 10 minutes of wall time (the first at least a minute in), and this one stopped before its first (it was killed, or a write failed, as on a full disk) or was not written by monolayer run; start it again with monolayer run {0}/scene.toml --out {0} --overwrite", dir.display())]
    NoCheckpoint {
        /// The directory.
        dir: PathBuf,
    },
    /// A checkpoint of another run.
    #[error("{} was not written by the run in {} (its scene differs from scene.toml: {diff}); remove it, or start a new run from it with [cells] init = \"frame\", from = \"{0}\"", path.display(), dir.display())]
    OtherRun {
        /// The checkpoint.
        path: PathBuf,
        /// The directory.
        dir: PathBuf,
        /// The lines that differ.
        diff: String,
    },
    /// A resumed run is already at its end.
    #[error("the run in {} is complete ({at}); extend it with --resume {0} --set run.time=T, T above {time}", dir.display())]
    Complete {
        /// The directory.
        dir: PathBuf,
        /// Where the checkpoint is, against the end.
        at: String,
        /// The run's active time.
        time: f64,
    },
    /// `--resume --set run.time=T` with `T` at or before the newest checkpoint.
    #[error("--set run.time would end the run at {end}, at or before its newest checkpoint {} (active time {time}); --resume only extends a run: give run.time above {time}, or start a new run", path.display())]
    Shortened {
        /// The checkpoint.
        path: PathBuf,
        /// Where the shortened run would end.
        end: String,
        /// The checkpoint's active time.
        time: f64,
    },
    /// `--resume` with an override other than `run.time` and `integrator.backend`.
    #[error("--resume continues the run as it was: only --set run.time=T (to extend it) and --set integrator.backend=cpu|gpu (where its steps run) can change; {key} would make it another run (start a new scene instead)")]
    Override {
        /// The key.
        key: String,
    },
    /// The scene in a checkpoint, or the initial tissue, is not valid.
    #[error("{context}")]
    Scene {
        /// Where.
        context: String,
        /// What.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The run stopped with an error (the tissue keeps the last good state).
    #[error(transparent)]
    Simulation(#[from] SimulationError),
    /// What [`RunDir::simulation_with`] was asked to do to the simulation before anything is
    /// written refused (a backend that cannot start, say).
    #[error("{0}")]
    Prepare(Box<dyn std::error::Error + Send + Sync>),
}

type Result<T> = std::result::Result<T, RunError>;

/// Catches SIGINT, SIGTERM and SIGHUP for the runs that check it: the first such signal asks
/// each run to stop after its step in progress (and write a checkpoint); a second one ends
/// the process at once with status 128 + its number. [`Interrupt::never`] catches nothing.
#[derive(Debug, Clone)]
pub struct Interrupt {
    signal: Arc<AtomicUsize>,
}

static INSTALLED: OnceLock<Interrupt> = OnceLock::new();

impl Interrupt {
    /// The process's handler, installed on the first call (later calls return the same).
    ///
    /// # Errors
    /// When the operating system refuses a handler.
    pub fn install() -> std::io::Result<Self> {
        if let Some(i) = INSTALLED.get() {
            return Ok(i.clone());
        }
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let caught = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for sig in [SIGINT, SIGTERM, SIGHUP] {
            // In this order: the second signal finds `caught` set and exits; the first sets it.
            signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, caught.clone())?;
            signal_hook::flag::register(sig, caught.clone())?;
            signal_hook::flag::register_usize(sig, signal.clone(), sig as usize)?;
        }
        Ok(INSTALLED.get_or_init(|| Self { signal }).clone())
    }

    /// A handle that never reports a signal (library use, tests).
    pub fn never() -> Self {
        Self {
            signal: Arc::new(AtomicUsize::new(0)),
        }
    }

    /// Asks the runs that hold this handle (or a clone) to stop after their step in
    /// progress, as if `signal` had come: how a host that catches its own interrupts (an
    /// embedding interpreter) stops a run. The second call does not end the process.
    pub fn raise(&self, signal: i32) {
        self.signal.store(signal.max(1) as usize, Ordering::SeqCst);
    }

    /// Forgets a raised or caught signal, so that the runs holding this handle can go on.
    pub fn clear(&self) {
        self.signal.store(0, Ordering::SeqCst);
    }

    /// The signal caught, if any.
    pub fn caught(&self) -> Option<i32> {
        match self.signal.load(Ordering::SeqCst) {
            0 => None,
            s => Some(s as i32),
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// It reached its end and is marked complete.
    Complete(RunInfo),
    /// A signal stopped it after a whole step; the final checkpoint is written.
    Stopped {
        /// The step it stopped at.
        step: u64,
        /// Its model time.
        time: f64,
        /// The signal.
        signal: i32,
        /// What this call did.
        info: RunInfo,
    },
}

/// Where the run's state comes from.
#[derive(Debug)]
enum Start {
    Scene,
    State(Box<Cells<f64>>),
    Checkpoint { path: PathBuf, step: u64 },
}

/// A run directory held by this process (see the module docs).
#[derive(Debug)]
pub struct RunDir {
    dir: PathBuf,
    scene: Scene,
    start: Start,
    interrupt: Interrupt,
    skipped: Vec<String>,
    _lock: File,
}

impl RunDir {
    /// A new run of `scene` in `dir` (created if missing), from `state` when the scene starts
    /// from a saved one (read before, since `overwrite` may remove it): takes the lock,
    /// prepares the directory ([`crate::prepare`]) and writes `scene.toml` and `run.json`.
    ///
    /// # Errors
    /// [`RunError::Locked`]; a directory that holds a run, without `overwrite`; I/O errors.
    pub fn create(
        dir: &Path,
        scene: Scene,
        state: Option<Cells<f64>>,
        overwrite: bool,
        interrupt: Interrupt,
    ) -> Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| RunDirError::io("create", dir, e))?;
        let lock = lock(dir)?;
        crate::prepare(dir, overwrite)?;
        // Also removes an earlier run's `complete` mark.
        crate::write_scene(dir, &scene)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            scene,
            start: match state {
                Some(s) => Start::State(Box::new(s)),
                None => Start::Scene,
            },
            interrupt,
            skipped: Vec::new(),
            _lock: lock,
        })
    }

    /// The run in `dir`, to be continued from its newest readable checkpoint, with `set`
    /// overrides of `run.time` (to extend it) and `integrator.backend` only. A checkpoint whose scene is not the one in
    /// `dir/scene.toml` (but for `run.time`) is refused; unreadable ones are skipped
    /// ([`RunDir::skipped`] says which and why).
    ///
    /// # Errors
    /// [`RunError::Locked`], [`RunError::Override`], [`RunError::NoCheckpoint`],
    /// [`RunError::OtherRun`], [`RunError::Complete`], or the last checkpoint's error when
    /// none can be read.
    pub fn resume(dir: &Path, set: &[String], interrupt: Interrupt) -> Result<Self> {
        // `run.time` extends a run; `integrator.backend` moves it between CPU and GPU (both
        // read and write the same checkpoint).
        let mut extends = false;
        for s in set {
            let key = s.split('=').next().unwrap_or("").trim();
            match key {
                "run.time" => extends = true,
                "integrator.backend" => {}
                _ => return Err(RunError::Override { key: key.into() }),
            }
        }
        if !dir.is_dir() {
            return Err(RunError::NoCheckpoint {
                dir: dir.to_path_buf(),
            });
        }
        let lock = lock(dir)?;
        let own = std::fs::read_to_string(dir.join("scene.toml"))
            .ok()
            .map(|s| legacy(&s));
        let all = checkpoint::checkpoints(dir);
        if all.is_empty() {
            return Err(RunError::NoCheckpoint {
                dir: dir.to_path_buf(),
            });
        }
        let mut skipped = Vec::new();
        let mut last_err = None;
        for (step, path) in all.iter().rev() {
            let scene = match read_scene(path, set) {
                Ok(s) => s,
                Err(e) => {
                    let mut why = e.to_string();
                    let mut cause = std::error::Error::source(&e);
                    while let Some(c) = cause {
                        why += &format!(": {c}");
                        cause = c.source();
                    }
                    skipped.push(format!("{}: {why}", path.display()));
                    last_err = Some(e);
                    continue;
                }
            };
            if let Some(own) = &own {
                let diff = scene_diff(own, &scene.to_toml());
                if !diff.is_empty() {
                    return Err(RunError::OtherRun {
                        path: path.clone(),
                        dir: dir.to_path_buf(),
                        diff,
                    });
                }
            }
            let time = crate::read_npz(path, &["time"])?[0]
                .scalar()
                .unwrap_or(f64::NAN);
            let total = scene.step_counts().total_steps();
            let (complete, at) = match scene.adaptive() {
                Some(_) => (
                    time >= scene.end_time() * (1.0 - 1e-12),
                    format!("t = {time} of {}", scene.end_time()),
                ),
                None => (*step >= total, format!("step {step} of {total}")),
            };
            if complete && extends {
                let end = match scene.adaptive() {
                    Some(_) => format!("t = {}", scene.end_time()),
                    None => format!("step {total}"),
                };
                return Err(RunError::Shortened {
                    path: path.clone(),
                    end,
                    // To nine digits: the clock sums steps (5.9999999999999964 for 6).
                    time: ((time - scene.file().run.relax_time).max(0.0) * 1e9).round() / 1e9,
                });
            }
            if complete {
                return Err(RunError::Complete {
                    dir: dir.to_path_buf(),
                    at,
                    time: scene.file().run.time,
                });
            }
            // Nothing is written yet: the scene, the analysis and the outputs from the
            // checkpoint on change in `RunDir::simulation`, once the simulation is ready to run
            // (a refusal before it leaves the directory as it was).
            return Ok(Self {
                dir: dir.to_path_buf(),
                scene,
                start: Start::Checkpoint {
                    path: path.clone(),
                    step: *step,
                },
                interrupt,
                skipped,
                _lock: lock,
            });
        }
        Err(last_err.expect("at least one checkpoint was tried"))
    }

    /// A sweep's point: `scene` resumed from the newest checkpoint in `dir` that holds this
    /// very scene and is not at its end, or started afresh (overwriting what `dir` holds).
    ///
    /// # Errors
    /// [`RunError::Locked`]; I/O errors.
    pub fn resume_or_create(dir: &Path, scene: Scene, interrupt: Interrupt) -> Result<Self> {
        if Self::resumable(dir, &scene) {
            match Self::resume(dir, &[], interrupt.clone()) {
                Ok(r) => return Ok(r),
                Err(e @ RunError::Locked { .. }) => return Err(e),
                Err(_) => {}
            }
        }
        Self::create(dir, scene, None, true, interrupt)
    }

    /// Whether `dir` holds a run of `scene` that [`RunDir::resume`] can continue: its
    /// `scene.toml` and its newest checkpoint's scene are `scene`.
    pub fn resumable(dir: &Path, scene: &Scene) -> bool {
        let own = scene.to_toml();
        std::fs::read_to_string(dir.join("scene.toml")).is_ok_and(|s| s == own)
            && checkpoint::checkpoints(dir)
                .last()
                .is_some_and(|(_, p)| checkpoint::checkpoint_scene(p).is_ok_and(|s| s == own))
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The run's resolved scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The step a resumed run continues from.
    pub fn resumed_from(&self) -> Option<u64> {
        match self.start {
            Start::Checkpoint { step, .. } => Some(step),
            _ => None,
        }
    }

    /// Checkpoints that [`RunDir::resume`] could not read, with the reason.
    pub fn skipped(&self) -> &[String] {
        &self.skipped
    }

    /// The run's simulation with its writers (series, frames, checkpoints) and the signal
    /// check attached; add more callbacks, then give it to [`RunDir::run`].
    ///
    /// # Errors
    /// A damaged checkpoint, a state that does not fit, I/O errors.
    pub fn simulation<T: Real>(&self) -> Result<(Simulation<T>, Written)> {
        self.simulation_with(Ok::<_, std::convert::Infallible>)
    }

    /// [`RunDir::simulation`] with `prepare` applied to the simulation before anything is
    /// written (a backend attached, say): when it refuses, a resumed run's directory is left
    /// as it was, byte for byte (its lock file aside).
    ///
    /// # Errors
    /// As [`RunDir::simulation`], and `prepare`'s error as [`RunError::Prepare`].
    pub fn simulation_with<T: Real, E>(
        &self,
        prepare: impl FnOnce(Simulation<T>) -> std::result::Result<Simulation<T>, E>,
    ) -> Result<(Simulation<T>, Written)>
    where
        E: Into<Box<dyn std::error::Error + Send + Sync>>,
    {
        let scene = &self.scene;
        let schedules = scene.output_schedules();
        let prepared = |sim| prepare(sim).map_err(|e| RunError::Prepare(e.into()));
        let (mut sim, written) = match &self.start {
            Start::Checkpoint { path, .. } => {
                let tissue = checkpoint::read_checkpoint::<T>(path, scene)?;
                let step = tissue.iteration();
                let mut sim = scene.simulation_from(tissue);
                if let Some(c) = checkpoint::read_controller(path)? {
                    sim.set_controller(c);
                }
                let mut sim = prepared(sim)?;
                // The run goes on: its scene (a longer run.time, another backend), and its
                // analysis, which described the run before, goes; the frames from the
                // checkpoint on are written again.
                crate::write_scene(&self.dir, scene)?;
                let analysis = self.dir.join("analysis");
                if analysis.exists() {
                    std::fs::remove_dir_all(&analysis)
                        .map_err(|e| RunDirError::io("remove", &analysis, e))?;
                }
                let w = add_writers_resumed(&mut sim, &self.dir, &schedules, step)?;
                (sim, w)
            }
            Start::State(state) => {
                let tissue = scene
                    .tissue_from_state::<T>(state)
                    .map_err(|e| initial_state(Box::new(e)))?;
                let tissue = crate::state::saved_terms(scene, tissue)
                    .map_err(|e| initial_state(Box::new(e)))?;
                let mut sim = prepared(scene.simulation_from(tissue))?;
                let w = add_writers(&mut sim, &self.dir, &schedules)?;
                (sim, w)
            }
            Start::Scene => {
                // The scene's discs, or the saved state its `[cells] from` names (a sweep's
                // point reads it here; `monolayer run` reads it before `--overwrite`).
                let tissue =
                    crate::initial_tissue::<T>(scene).map_err(|e| initial_state(Box::new(e)))?;
                let mut sim = prepared(scene.simulation_from(tissue))?;
                let w = add_writers(&mut sim, &self.dir, &schedules)?;
                (sim, w)
            }
        };
        let min_wall = scene
            .file()
            .run
            .checkpoint_every
            .is_none()
            .then_some(MIN_CHECKPOINT_WALL);
        add_checkpoints_with(
            &mut sim,
            &self.dir,
            schedules.checkpoints,
            &scene.to_toml(),
            min_wall,
        );
        sim.add_callback(
            "signal check",
            Schedule::IterationInterval(1),
            StopOnSignal(self.interrupt.clone()),
        );
        Ok((sim, written))
    }

    /// Runs `sim` (from [`RunDir::simulation`]) to its end, then marks the run complete; or,
    /// when a signal stops it before its end, leaves it resumable ([`Outcome::Stopped`]).
    ///
    /// # Errors
    /// The simulation's error (what was written so far is kept) or a failed mark.
    pub fn run<T: Real>(&self, sim: &mut Simulation<T>) -> Result<Outcome> {
        let info = sim.run()?;
        // A signal that came during the last step finds the run at its end, with its
        // final outputs and checkpoint written: it is complete, not stopped.
        if let (Some(signal), false) = (self.interrupt.caught(), sim.at_end()) {
            let t = sim.tissue();
            return Ok(Outcome::Stopped {
                step: t.iteration(),
                time: t.time(),
                signal,
                info,
            });
        }
        crate::mark_complete(&self.dir, &self.scene)?;
        Ok(Outcome::Complete(info))
    }
}

fn initial_state(source: Box<dyn std::error::Error + Send + Sync>) -> RunError {
    RunError::Scene {
        context: "the initial state".into(),
        source,
    }
}

/// The keys of two resolved scenes whose values differ, `run.time` aside, as
/// `key is B there, A here` (`other` is "there").
fn scene_diff(own: &str, other: &str) -> String {
    let entries = |s: &str| -> Vec<(String, String)> {
        let mut section = String::new();
        // The K-th table of an array of tables (`[[population]]`) is `population.K`, as in
        // `--set`, so that each is compared with its own.
        let mut counts = std::collections::HashMap::<String, usize>::new();
        s.lines()
            .filter_map(|l| {
                let l = l.trim();
                if l.starts_with('[') {
                    let name = l.trim_matches(|c| c == '[' || c == ']').to_string();
                    section = if l.starts_with("[[") {
                        let k = counts.entry(name.clone()).or_default();
                        *k += 1;
                        format!("{name}.{}", *k - 1)
                    } else {
                        name
                    };
                    return None;
                }
                let (k, v) = l.split_once('=')?;
                let key = format!("{section}.{}", k.trim());
                (key != "run.time" && key != "integrator.backend")
                    .then(|| (key, v.trim().to_string()))
            })
            .collect()
    };
    let (here, there) = (entries(own), entries(other));
    let value = |list: &[(String, String)], key: &str| {
        list.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone())
    };
    let mut out = Vec::new();
    for (key, v) in &there {
        match value(&here, key) {
            Some(h) if &h == v => {}
            h => out.push(format!(
                "{key} is {v} there, {} here",
                h.as_deref().unwrap_or("(none)")
            )),
        }
    }
    for (key, _) in &here {
        if value(&there, key).is_none() {
            out.push(format!("{key} is not set there"));
        }
    }
    out.join("; ")
}

/// A resolved scene written before `[integrator] tolerance` became adaptive-only: those carried
/// the default `tolerance = 0.001` in every scene, which now would be refused without
/// `adaptive = true` (where it had no effect).
fn legacy(text: &str) -> String {
    if !text.lines().any(|l| l.trim() == "adaptive = false") {
        return text.to_string();
    }
    text.lines()
        .filter(|l| l.trim() != "tolerance = 0.001")
        .map(|l| format!("{l}\n"))
        .collect()
}

/// The scene a checkpoint carries, with `set` applied.
fn read_scene(path: &Path, set: &[String]) -> Result<Scene> {
    let text = legacy(&checkpoint::checkpoint_scene(path)?);
    Scene::parse(&text, set).map_err(|e| RunError::Scene {
        context: format!("the scene in {}", path.display()),
        source: Box::new(e),
    })
}

/// Takes the lock of `dir` without waiting, and writes this process into it.
fn lock(dir: &Path) -> Result<File> {
    let path = dir.join(LOCK);
    let mut f = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|e| RunDirError::io("open", &path, e))?;
    match f.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = f.read_to_string(&mut holder);
            let holder = holder.trim();
            return Err(RunError::Locked {
                dir: dir.to_path_buf(),
                holder: if holder.is_empty() {
                    "its lock file names no process yet".into()
                } else {
                    holder.into()
                },
            });
        }
        Err(TryLockError::Error(e)) => return Err(RunDirError::io("lock", &path, e).into()),
    }
    let args: Vec<String> = std::env::args().collect();
    let line = format!(
        "pid {} since {}: {}\n",
        std::process::id(),
        utc(std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs())),
        args.join(" ")
    );
    let written = f
        .set_len(0)
        .and_then(|()| f.seek(SeekFrom::Start(0)))
        .and_then(|_| f.write_all(line.as_bytes()));
    written.map_err(|e| RunDirError::io("write", &path, e))?;
    Ok(f)
}

/// Takes the lock of `dir` (creating it) for as long as the returned value lives: for a
/// process that reads a run and writes beside it (`monolayer analyze`), or a sweep's directory.
///
/// # Errors
/// [`RunError::Locked`] while another process holds it; I/O errors.
pub fn lock_dir(dir: &Path) -> Result<DirLock> {
    std::fs::create_dir_all(dir).map_err(|e| RunDirError::io("create", dir, e))?;
    Ok(DirLock(lock(dir)?))
}

/// A held lock ([`lock_dir`]), released when dropped or when the process ends.
#[derive(Debug)]
pub struct DirLock(#[allow(dead_code)] File);

/// Stops the run after the step in progress once a signal is caught.
struct StopOnSignal(Interrupt);

impl<T: Real> Callback<T> for StopOnSignal {
    fn call(&mut self, obs: &mut Observation<'_, T>) -> std::result::Result<(), CallbackError> {
        if self.0.caught().is_some() {
            obs.request_stop();
        }
        Ok(())
    }

    /// It reads nothing of the state: on a device, it costs no copy (it is called every
    /// step; with the default it brought the whole state back after every step).
    fn needs(&self) -> Needs {
        Needs::Clock
    }
}

/// `secs` after the Unix epoch as a UTC date and time, `2026-12-05 08:45:12 UTC` (the civil
/// calendar from a day count, H. Hinnant's `civil_from_days`).
pub(crate) fn utc(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02}:{:02} UTC",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    /// The lock's date against dates known by other means: the epoch, a leap day, the end of
    /// a century year that is not a leap year, and one checked with `date -u -d @1764923112`.
    #[test]
    fn lock_dates_are_utc_calendar_dates() {
        assert_eq!(super::utc(0), "1970-01-01 00:00:00 UTC");
        assert_eq!(super::utc(951_782_400), "2000-02-29 00:00:00 UTC");
        assert_eq!(super::utc(4_107_542_399), "2100-02-28 23:59:59 UTC");
        assert_eq!(super::utc(1_764_923_112), "2025-12-05 08:25:12 UTC");
    }

    use super::scene_diff;

    /// A signal during the last step leaves a complete run (its final outputs are written),
    /// one a step earlier a stopped run that resumes: the two outcomes, from a handle
    /// raised by a callback at a chosen step.
    #[test]
    fn a_signal_at_the_last_step_completes_the_run() {
        use super::{Interrupt, Outcome, RunDir};
        use mechanics::{CallbackError, Observation, Schedule};
        let text = "[domain]\nlx = 40\nly = 40\n[cells]\ncount = 2\nradius = 5.0\n\
                    [run]\nrelax_time = 0\ntime = 2.0\noutput_every = 1.0\n";
        let scene = scene::Scene::parse(text, &[]).unwrap();
        let steps = scene.step_counts().total_steps();
        // The handle is checked before this callback: raised at step k, the run stops after k + 1.
        for (at, complete) in [(steps - 1, true), (steps - 2, false)] {
            let dir = tempfile::tempdir().unwrap();
            let out = dir.path().join("run");
            let interrupt = Interrupt::never();
            let run = RunDir::create(&out, scene.clone(), None, false, interrupt.clone()).unwrap();
            let (mut sim, _) = run.simulation::<f64>().unwrap();
            let raise = interrupt.clone();
            sim.add_callback(
                "raise",
                Schedule::IterationInterval(1),
                move |obs: &mut Observation<'_, f64>| -> Result<(), CallbackError> {
                    if obs.iteration() == at {
                        raise.raise(15);
                    }
                    Ok(())
                },
            );
            let outcome = run.run(&mut sim).unwrap();
            assert_eq!(
                matches!(outcome, Outcome::Complete(_)),
                complete,
                "raised at step {at} of {steps}: {outcome:?}"
            );
            assert_eq!(crate::is_complete(&out), complete);
        }
    }

    /// Each table of an array of tables is compared with its own: two `[[population]]`
    /// tables that agree give no difference (the first version compared every
    /// `population.*` key with the first table's, and refused to resume any run with two
    /// populations), and a change in the second is named with its index.
    #[test]
    fn arrays_of_tables_compare_table_by_table() {
        let a = "[run]\ntime = 5.0\n\n[[population]]\nname = \"stiff\"\ngamma = 0.05\n\n[[population]]\nname = \"soft\"\ngamma = 0.005\n";
        assert_eq!(scene_diff(a, &a.replace("time = 5.0", "time = 9.0")), "");
        let b = a.replace("gamma = 0.005", "gamma = 0.006");
        assert_eq!(
            scene_diff(a, &b),
            "population.1.gamma is 0.006 there, 0.005 here"
        );
    }
}
