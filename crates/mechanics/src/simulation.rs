//! The driver of a run, in the Oceananigans way: a [`Simulation`] owns the model (a
//! [`Tissue`] and its [`Workspace`]), the stop criteria, and any number of callbacks and
//! output writers, each with a [`Schedule`].
//!
//! # The order of one iteration
//!
//! [`Simulation::run`] first sets ζ by the activity switch ([`Simulation::activity_from`]),
//! calls every callback's and writer's [`Callback::initialize`], then fires the schedules at
//! the starting state. Then, until a stop criterion holds:
//!
//! 1. every `sort_every` iterations the cells are re-sorted in memory
//!    ([`Tissue::sort_cells`]);
//! 2. the tissue takes one step; the state check ([`Simulation::set_check`], by default
//!    [`StateCheck`] at every step) runs at the step's chokepoint, before anything is
//!    overwritten;
//! 3. the activity switch sets ζ if the new iteration reaches it;
//! 4. the callbacks whose schedules fire run, in the order they were added, then the output
//!    writers whose schedules fire, in the order they were added.
//!
//! At the end every [`Callback::finalize`] runs (a writer can write the final state there).
//!
//! Callbacks see the state through an [`Observation`], which holds the tissue by shared
//! reference: observing cannot change what the dynamics use, so a run's results are
//! bit-identical whatever is observed and how often. Derived quantities are computed lazily,
//! once per iteration, the first time a callback asks ([`Observation::observables`]).

use std::time::{Duration, Instant};

use phasefield::Real;

use crate::adaptive::{AdaptiveParams, Controller};
use crate::backend::Backend;
use crate::fields::TissueFields;
use crate::observables::Observables;
use crate::params::StepParams;
use crate::step::{StateCheck, StepCheck};
use crate::tissue::Tissue;
use crate::workspace::Workspace;
use crate::StepError;

/// The keys that keep a tissue from dying out by `why` (`"death"` or `"extrusion"`).
fn extinct_fix(why: &str) -> &'static str {
    match why {
        "death" => "lower [division] death_rate",
        _ => "lower [division] extrusion (the area rule) or raise [division] extrusion_pressure (the pressure rule: above the cells' pressures at rest, 0.005–0.013 in the paper's tissue)",
    }
}

/// Iterations between re-sortings of the cells in memory by default
/// ([`Simulation::sort_every`]): cells move a fraction of a node per TU, so every few hundred
/// steps is plenty.
pub const DEFAULT_SORT_EVERY: u64 = 250;

/// When a callback, writer or check fires (after Oceananigans' schedules).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Schedule {
    /// At every iteration that is a multiple of `n` (the starting state included).
    IterationInterval(u64),
    /// At the first iteration at or after each multiple of the interval, in model time (to
    /// within 10⁻⁹ of the interval), the starting state included when its time is a multiple
    /// (a run resumed between two multiples waits for the next).
    TimeInterval(f64),
    /// At the first iteration after each interval of wall-clock time since the last firing
    /// (not at the starting state). Wall time never affects the results, only when an
    /// observation happens.
    WallTimeInterval(Duration),
}

/// Where the activity switches on.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Switch {
    /// At this iteration.
    Iteration(u64),
    /// At this model time.
    Time(f64),
}

/// The running state of a [`Schedule`].
#[derive(Debug, Clone)]
struct Timer {
    schedule: Schedule,
    next_time: f64,
    last_wall: Instant,
}

impl Timer {
    fn new(schedule: Schedule) -> Self {
        Self {
            schedule,
            next_time: f64::NEG_INFINITY,
            last_wall: Instant::now(),
        }
    }

    /// Whether [`Timer::fires`] would fire now (not at the starting state), without
    /// changing the timer.
    fn due(&self, iteration: u64, time: f64) -> bool {
        match self.schedule {
            Schedule::IterationInterval(n) => iteration.is_multiple_of(n.max(1)),
            Schedule::TimeInterval(dt) => time >= self.next_time - 1e-9 * dt,
            Schedule::WallTimeInterval(d) => self.last_wall.elapsed() >= d,
        }
    }

    fn fires(&mut self, iteration: u64, time: f64, initial: bool) -> bool {
        match self.schedule {
            Schedule::IterationInterval(n) => iteration.is_multiple_of(n.max(1)),
            Schedule::TimeInterval(dt) => {
                let tol = 1e-9 * dt;
                if initial {
                    // The first multiple at or after the start (a resumed run starts between).
                    self.next_time = ((time - tol) / dt).ceil() * dt;
                }
                if time >= self.next_time - tol {
                    self.next_time = (((time + tol) / dt).floor() + 1.0) * dt;
                    true
                } else {
                    false
                }
            }
            Schedule::WallTimeInterval(d) => {
                if initial {
                    self.last_wall = Instant::now();
                    return false;
                }
                let now = Instant::now();
                if now.duration_since(self.last_wall) >= d {
                    self.last_wall = now;
                    true
                } else {
                    false
                }
            }
        }
    }
}

/// The error a callback returns.
pub type CallbackError = Box<dyn std::error::Error + Send + Sync>;

/// Why a simulation stopped early.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimulationError {
    /// A step failed its check; the tissue holds the last good state.
    #[error(transparent)]
    Step(#[from] StepError),
    /// A callback or writer failed.
    #[error("{name} failed at step {iteration}")]
    Callback {
        /// The name it was added under.
        name: String,
        /// The iteration it was called at.
        iteration: u64,
        /// Its error.
        source: CallbackError,
    },
    /// Every cell died or was extruded: the last one was due to go too, and a tissue cannot
    /// be empty, so the run stops with it in place.
    #[error("every cell is gone at step {iteration} (t = {time:.3}): the last one (cell {cell}) was due for {why} too, and a tissue cannot be empty, so the run stops here; for a tissue that lasts, {}, or raise the division rate (lower [division] cycle_time)", extinct_fix(why))]
    Extinct {
        /// The iteration.
        iteration: u64,
        /// The time.
        time: f64,
        /// The last cell's identity.
        cell: usize,
        /// Why it was due to go: `"death"` or `"extrusion"`.
        why: &'static str,
    },
    /// Nothing would stop the run.
    #[error(
        "the simulation has no stop criterion: set stop_iteration, stop_time or wall_time_limit"
    )]
    NoStop,
}

/// What a callback reads of the state when it is called ([`Callback::needs`]): with the steps
/// on a device ([`crate::Simulation::with_backend`]) it decides what is brought back to the
/// host before the callback runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Needs {
    /// The clock, the parameters and what the host keeps of the tissue (the number of cells,
    /// the identities, the proliferation clock): nothing comes back from the device.
    Clock,
    /// That, and [`Observation::observables`]: the device reduces them and sends back the
    /// numbers ([`crate::backend::Backend::observe`]), not the fields.
    Observables,
    /// The fields (the tissue's state, the workspace, [`Observation::fields`]): the device's
    /// state is copied to the host first ([`crate::backend::Backend::sync`]).
    State,
}

/// Something called on a schedule during a run: a diagnostic, an output writer, a progress
/// report (after Oceananigans' `Callback` and ripgrep's `Sink`). Only [`Callback::call`] is
/// required; closures `FnMut(&mut Observation<T>) -> Result<(), CallbackError>` are callbacks.
pub trait Callback<T: Real>: Send {
    /// Called when the schedule fires.
    ///
    /// # Errors
    /// Whatever stops the run (e.g. a failed write).
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError>;

    /// What [`Callback::call`] reads of the state ([`Needs`]; the default, [`Needs::State`],
    /// is always right). A callback that says less must read no more: with the steps on a
    /// device, the host's fields are then those of an earlier step.
    fn needs(&self) -> Needs {
        Needs::State
    }

    /// Called once before the run, with the starting state (before the schedules fire).
    ///
    /// # Errors
    /// Whatever stops the run.
    fn initialize(&mut self, _obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        Ok(())
    }

    /// Called once after the run (also after an error), with the final state.
    ///
    /// # Errors
    /// Whatever should be reported.
    fn finalize(&mut self, _obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        Ok(())
    }
}

impl<T: Real, F> Callback<T> for F
where
    F: FnMut(&mut Observation<'_, T>) -> Result<(), CallbackError> + Send,
{
    fn call(&mut self, obs: &mut Observation<'_, T>) -> Result<(), CallbackError> {
        self(obs)
    }
}

/// A change to the state between steps (after LAMMPS' fixes and rapier's hooks): a protocol
/// that changes parameters, a perturbation, an event that rewrites fields. Fixes run after
/// the step and the activity switch, before the callbacks, in the order added; closures
/// `FnMut(&mut Tissue<T>) -> Result<(), CallbackError>` are fixes.
///
/// A fix must keep the number of cells and the patch shape (the workspace is sized for
/// them); one that changes fields should then call [`Tissue::recentre`], so that each patch
/// follows its cell. A fix must be a deterministic function of the state (noise from
/// [`crate::terms::NoiseKey`]), for runs to stay reproducible and resumable.
pub trait Fix<T: Real>: Send {
    /// Changes the state.
    ///
    /// # Errors
    /// Whatever stops the run.
    fn apply(&mut self, tissue: &mut Tissue<T>) -> Result<(), CallbackError>;
}

impl<T: Real, F> Fix<T> for F
where
    F: FnMut(&mut Tissue<T>) -> Result<(), CallbackError> + Send,
{
    fn apply(&mut self, tissue: &mut Tissue<T>) -> Result<(), CallbackError> {
        self(tissue)
    }
}

/// The state as a callback sees it: the tissue (read-only), the clock and derived quantities
/// computed on demand and cached for this iteration.
pub struct Observation<'a, T: Real> {
    /// Whether the host's fields are those of an earlier step (the steps are on a device and
    /// only the clock or the observables came back: see [`Needs`]).
    stale: bool,
    tissue: &'a Tissue<T>,
    ws: &'a mut Workspace<T>,
    observables: &'a mut Option<Observables>,
    wall_time: Duration,
    stop: &'a mut bool,
    controller: Option<Controller>,
}

impl<'a, T: Real> Observation<'a, T> {
    /// The tissue (borrowed for the whole observation, so that it can be held next to
    /// [`Observation::workspace`]).
    pub fn tissue(&self) -> &'a Tissue<T> {
        self.tissue
    }

    /// Steps taken.
    pub fn iteration(&self) -> u64 {
        self.tissue.iteration()
    }

    /// Model time.
    pub fn time(&self) -> f64 {
        self.tissue.time()
    }

    /// Wall time since [`Simulation::run`] was called.
    pub fn wall_time(&self) -> Duration {
        self.wall_time
    }

    /// The state of the step-size controller of an adaptive run ([`Simulation::adaptive`]),
    /// which a checkpoint keeps; `None` with fixed steps.
    pub fn controller(&self) -> Option<Controller> {
        self.controller
    }

    /// The observables of the current state, computed at the first call in this iteration
    /// ([`Tissue::observe`]) and cached for the other callbacks.
    pub fn observables(&mut self) -> Observables {
        if self.observables.is_none() {
            debug_assert!(
                !self.stale,
                "a callback that needs only the clock read the observables"
            );
            *self.observables = Some(self.tissue.observe(self.ws));
        }
        self.observables.expect("just computed")
    }

    /// The workspace, holding the per-cell quantities, lattice sums, tissue velocity and
    /// measured centres of the current state (evaluated on first use, as
    /// [`Observation::observables`]).
    pub fn workspace(&mut self) -> &Workspace<T> {
        debug_assert!(
            !self.stale,
            "a callback that needs no state read the workspace"
        );
        self.observables();
        self.ws
    }

    /// The lattice fields of the current state ([`Tissue::fields`]). Allocates.
    pub fn fields(&mut self) -> TissueFields {
        debug_assert!(
            !self.stale,
            "a callback that needs no state read the fields"
        );
        self.tissue.fields(self.ws)
    }

    /// Asks the simulation to stop after this iteration's callbacks.
    pub fn request_stop(&mut self) {
        *self.stop = true;
    }
}

/// Which hook of the callbacks [`Simulation::fire`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Hook {
    /// `call`, where the schedule fires after a step.
    Call,
    /// `call`, where the schedule fires at the starting state.
    Start,
    /// `initialize`, always.
    Initialize,
    /// `finalize`, always.
    Finalize,
}

struct Entry<T: Real> {
    name: String,
    timer: Timer,
    callback: Box<dyn Callback<T>>,
}

/// What a run did.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct RunInfo {
    /// Steps taken by this call of [`Simulation::run`].
    pub iterations: u64,
    /// Wall time of the call.
    pub wall_time: Duration,
}

/// A time-stepping driver: model, integrator, stop criteria and scheduled callbacks.
///
/// ```
/// use mechanics::prelude::*;
/// use phasefield::{init, Lattice, PatchShape};
///
/// let lattice = Lattice::new(48, 48);
/// let shape = PatchShape::new(lattice, 12).unwrap();
/// let cells = init::discs(lattice, shape, &[[16.0, 24.0], [30.0, 24.0]], 7.0, 2.5);
/// let tissue = Tissue::new(cells, ModelParams::paper(0.0));
/// let mut sim = Simulation::new(tissue, StepParams::paper()).stop_iteration(20);
/// sim.add_callback("v_rms", Schedule::IterationInterval(10), move |o: &mut Observation<f64>| {
///     assert!(o.observables().v_rms.is_finite());
///     Ok(())
/// });
/// let info = sim.run().unwrap();
/// assert_eq!((info.iterations, sim.tissue().iteration()), (20, 20));
/// ```
pub struct Simulation<T: Real = f64> {
    tissue: Tissue<T>,
    workspace: Workspace<T>,
    step_params: StepParams,
    stop_iteration: Option<u64>,
    stop_time: Option<f64>,
    wall_time_limit: Option<Duration>,
    activity: Option<(Switch, f64)>,
    adaptive: Option<(AdaptiveParams, Controller)>,
    sort_every: Option<u64>,
    check: (Timer, Box<dyn StepCheck>),
    callbacks: Vec<Entry<T>>,
    writers: Vec<Entry<T>>,
    fixes: Vec<(String, Timer, Box<dyn Fix<T>>)>,
    sort_scratch: Vec<T>,
    initialized: bool,
    /// The clock of the host's fields on a backend: when they were last uploaded or brought
    /// back (the host's clock runs ahead of its fields between syncs).
    synced_at: (u64, f64),
    backend: Option<Box<dyn Backend<T>>>,
}

impl<T: Real> Simulation<T> {
    /// A simulation of `tissue` with the integrator `step_params`, the default check at every
    /// step, re-sorting every [`DEFAULT_SORT_EVERY`] iterations, no callbacks and no stop
    /// criterion yet.
    pub fn new(tissue: Tissue<T>, step_params: StepParams) -> Self {
        let workspace = Workspace::new(tissue.cells());
        Self {
            tissue,
            workspace,
            step_params,
            stop_iteration: None,
            stop_time: None,
            wall_time_limit: None,
            activity: None,
            adaptive: None,
            sort_every: Some(DEFAULT_SORT_EVERY),
            check: (
                Timer::new(Schedule::IterationInterval(1)),
                Box::new(StateCheck::default()),
            ),
            callbacks: Vec::new(),
            writers: Vec::new(),
            fixes: Vec::new(),
            sort_scratch: Vec::new(),
            initialized: false,
            synced_at: (0, 0.0),
            backend: None,
        }
    }

    /// Cells divide by the clock `clock` after every step, and, with `extrusion = Some(f)`,
    /// cells whose area falls below `f πR²` are removed
    /// ([`crate::division::remove_extruded`]); both before the fixes and callbacks of the
    /// step ([`Tissue::proliferate`]). The tissue holds the clock
    /// ([`Tissue::with`], which this calls), so outputs see the lineage.
    pub fn with_proliferation(
        mut self,
        clock: crate::division::Proliferation,
        extrusion: Option<f64>,
    ) -> Self {
        let clock = match extrusion {
            Some(f) => clock.with_extrusion(f),
            None => clock,
        };
        self.tissue = self.tissue.with(clock);
        self
    }

    /// The division clock and its lineage ([`Tissue::proliferation`]).
    pub fn proliferation(&self) -> Option<&crate::division::Proliferation> {
        self.tissue.proliferation()
    }

    /// Stops when the tissue has taken `n` steps in all.
    pub fn stop_iteration(mut self, n: u64) -> Self {
        self.stop_iteration = Some(n);
        self
    }

    /// Stops at the first iteration at or after model time `t` (to within 10⁻⁹ dt).
    pub fn stop_time(mut self, t: f64) -> Self {
        self.stop_time = Some(t);
        self
    }

    /// Sets where the next [`Simulation::run`] stops, replacing both criteria: after `n`
    /// steps in all, at model time `t` (whichever comes first; `None` for neither). A
    /// simulation run again goes on from where it stopped, as one run would (a stop landed
    /// on by an adaptive step is the exception: it shortens the step before it). How a host
    /// steps a simulation piece by piece.
    pub fn set_stop(&mut self, iteration: Option<u64>, time: Option<f64>) {
        self.stop_iteration = iteration;
        self.stop_time = time;
    }

    /// The tissue, to change between runs: what a [`Fix`] does between steps, done now (a
    /// host's edit of the state, a term added). The next step starts from what is left.
    pub fn tissue_mut(&mut self) -> &mut Tissue<T> {
        &mut self.tissue
    }

    /// Evaluates the current state ([`Tissue::observe`]) and returns the tissue with the
    /// workspace that holds its per-cell quantities, lattice sums and tissue velocity.
    pub fn observe(&mut self) -> (&Tissue<T>, &Workspace<T>, Observables) {
        let o = self.tissue.observe(&mut self.workspace);
        (&self.tissue, &self.workspace, o)
    }

    /// The lattice fields of the current state ([`Tissue::fields`], evaluated first) with
    /// `Σ φ_i` at every node. Allocates.
    pub fn fields(&mut self) -> (TissueFields, Vec<f64>) {
        self.tissue.observe(&mut self.workspace);
        let f = self.tissue.fields(&mut self.workspace);
        (f, self.workspace.sum_field(crate::SumField::S1))
    }

    /// Stops after this much wall time.
    pub fn wall_time_limit(mut self, limit: Duration) -> Self {
        self.wall_time_limit = Some(limit);
        self
    }

    /// Holds ζ = 0 until iteration `iteration` and switches to activity `zeta` there (the
    /// relaxation protocol of docs/model.md §6). With `iteration = 0` the activity is on from the
    /// start.
    pub fn activity_from(mut self, iteration: u64, zeta: f64) -> Self {
        self.activity = Some((Switch::Iteration(iteration), zeta));
        self.apply_activity();
        self
    }

    /// Holds ζ = 0 until model time `time` and switches to activity `zeta` there; an
    /// adaptive run lands a step on `time` exactly.
    pub fn activity_from_time(mut self, time: f64, zeta: f64) -> Self {
        self.activity = Some((Switch::Time(time), zeta));
        self.apply_activity();
        self
    }

    /// Steps with the error-controlled time step of [`crate::adaptive`] instead of the fixed
    /// `dt` of the [`StepParams`] (of which only `npc = 1` is used), from the controller
    /// state `controller` ([`Controller::new`] with the first step, or the state a
    /// checkpoint kept). Every step lands exactly on the next firing time of each
    /// [`Schedule::TimeInterval`], on the activity switch and on the stop time, so outputs
    /// happen at their scheduled times; give an adaptive run a [`Simulation::stop_time`].
    pub fn adaptive(mut self, params: AdaptiveParams, controller: Controller) -> Self {
        self.adaptive = Some((params, controller));
        self
    }

    /// The controller state of an adaptive run.
    pub fn controller(&self) -> Option<Controller> {
        self.adaptive.map(|(_, c)| c)
    }

    /// Replaces the controller state of an adaptive run (a resumed run continues with the
    /// state its checkpoint kept); no effect with fixed steps.
    pub fn set_controller(&mut self, controller: Controller) {
        if let Some((_, c)) = &mut self.adaptive {
            *c = controller;
        }
    }

    /// Re-sorts the cells in memory every `n` iterations (`None`: never). Sorting changes
    /// sums over cells at round-off and speeds up large scenes.
    pub fn sort_every(mut self, n: Option<u64>) -> Self {
        self.sort_every = n.filter(|&n| n > 0);
        self
    }

    /// Replaces the state check at the step chokepoint and its schedule (by default
    /// [`StateCheck`] at every step). `Box::new(())` checks nothing.
    pub fn set_check(&mut self, schedule: Schedule, check: Box<dyn StepCheck>) {
        self.check = (Timer::new(schedule), check);
    }

    /// Adds a callback, run when `schedule` fires, before the output writers.
    pub fn add_callback(
        &mut self,
        name: impl Into<String>,
        schedule: Schedule,
        callback: impl Callback<T> + 'static,
    ) {
        self.callbacks.push(Entry {
            name: name.into(),
            timer: Timer::new(schedule),
            callback: Box::new(callback),
        });
    }

    /// Adds a fix ([`Fix`]), run after every step at which `schedule` fires (never at the
    /// starting state), before the callbacks.
    pub fn add_fix(
        &mut self,
        name: impl Into<String>,
        schedule: Schedule,
        fix: impl Fix<T> + 'static,
    ) {
        self.fixes
            .push((name.into(), Timer::new(schedule), Box::new(fix)));
    }

    /// Adds an output writer, run when `schedule` fires, after the callbacks.
    pub fn add_output_writer(
        &mut self,
        name: impl Into<String>,
        schedule: Schedule,
        writer: impl Callback<T> + 'static,
    ) {
        self.writers.push(Entry {
            name: name.into(),
            timer: Timer::new(schedule),
            callback: Box::new(writer),
        });
    }

    /// The tissue.
    pub fn tissue(&self) -> &Tissue<T> {
        &self.tissue
    }

    /// The workspace (holding what the last evaluation left).
    pub fn workspace(&self) -> &Workspace<T> {
        &self.workspace
    }

    /// The integrator.
    pub fn step_params(&self) -> &StepParams {
        &self.step_params
    }

    /// The tissue and its workspace.
    pub fn into_parts(self) -> (Tissue<T>, Workspace<T>) {
        (self.tissue, self.workspace)
    }

    /// Runs the steps on `backend` (a device, such as the `gpu` crate's) instead of the host.
    /// The tissue's fields are brought up to date from the device whenever a callback, a
    /// writer or a fix fires, and at the end of [`Simulation::run`]. The backend steps with
    /// the fixed step of the simulation's [`StepParams`]; [`Simulation::run`] refuses an
    /// adaptive simulation. Cells are not re-sorted (the device does not need it).
    pub fn with_backend(mut self, backend: Box<dyn Backend<T>>) -> Self {
        self.backend = Some(backend);
        self
    }

    /// The backend's name, when the steps run on one.
    pub fn backend_name(&self) -> Option<&str> {
        self.backend.as_deref().map(|b| b.name())
    }

    /// Whether the tissue has reached the run's end (its stop iteration or stop time; a wall
    /// time limit is not an end): a run stopped by a callback at its last step has done
    /// all it was asked.
    pub fn at_end(&self) -> bool {
        let t = &self.tissue;
        self.stop_iteration.is_some_and(|n| t.iteration() >= n)
            || self
                .stop_time
                .is_some_and(|s| t.time() >= s - 1e-9 * self.step_params.dt)
    }

    /// The iteration the run stops at, when a stop iteration is set.
    pub fn stop_at_iteration(&self) -> Option<u64> {
        self.stop_iteration
    }

    fn apply_activity(&mut self) {
        if let Some((at, zeta)) = self.activity {
            let on = match at {
                Switch::Iteration(n) => self.tissue.iteration() >= n,
                Switch::Time(t) => self.tissue.time() >= t,
            };
            self.tissue.params.zeta = if on { zeta } else { 0.0 };
            self.tissue.active = on;
        }
    }

    /// The time the next adaptive step must not pass: the stop time, the activity switch
    /// ahead, and the next firing of every time schedule.
    fn next_landing(&self) -> f64 {
        let now = self.tissue.time();
        let mut t = self.stop_time.unwrap_or(f64::INFINITY);
        if let Some((Switch::Time(s), _)) = self.activity {
            if s > now {
                t = t.min(s);
            }
        }
        let timers = self
            .callbacks
            .iter()
            .chain(&self.writers)
            .map(|e| &e.timer)
            .chain(self.fixes.iter().map(|f| &f.1))
            .chain(std::iter::once(&self.check.0));
        for timer in timers {
            if let Schedule::TimeInterval(_) = timer.schedule {
                if timer.next_time > now {
                    t = t.min(timer.next_time);
                }
            }
        }
        t
    }

    fn done(&self, start: Instant) -> bool {
        self.at_end() || self.wall_time_limit.is_some_and(|w| start.elapsed() >= w)
    }

    /// Runs `hook` of the callbacks, then of the writers (`call` only where the schedule
    /// fires).
    fn fire(&mut self, start: Instant, hook: Hook, stop: &mut bool) -> Result<(), SimulationError> {
        self.fire_with(start, hook, stop, None, false)
    }

    /// [`Simulation::fire`] with the observables already known (a device's), and whether
    /// the host's fields are stale.
    fn fire_with(
        &mut self,
        start: Instant,
        hook: Hook,
        stop: &mut bool,
        known: Option<Observables>,
        stale: bool,
    ) -> Result<(), SimulationError> {
        let mut observables = known;
        let (iteration, time) = (self.tissue.iteration(), self.tissue.time());
        for entry in self.callbacks.iter_mut().chain(self.writers.iter_mut()) {
            let go = match hook {
                Hook::Call | Hook::Start => entry.timer.fires(iteration, time, hook == Hook::Start),
                Hook::Initialize | Hook::Finalize => true,
            };
            if !go {
                continue;
            }
            let mut obs = Observation {
                stale,
                tissue: &self.tissue,
                ws: &mut self.workspace,
                observables: &mut observables,
                wall_time: start.elapsed(),
                stop,
                controller: self.adaptive.map(|(_, c)| c),
            };
            let r = match hook {
                Hook::Initialize => entry.callback.initialize(&mut obs),
                Hook::Finalize => entry.callback.finalize(&mut obs),
                Hook::Call | Hook::Start => entry.callback.call(&mut obs),
            };
            r.map_err(|source| SimulationError::Callback {
                name: entry.name.clone(),
                iteration,
                source,
            })?;
        }
        Ok(())
    }

    /// Runs until a stop criterion holds (see the module docs for the order of one
    /// iteration). It can be called again after raising the stop criterion, to continue:
    /// the initializers and the firing at the starting state happen in the first call only,
    /// the finalizers at the end of every call.
    ///
    /// # Errors
    /// [`SimulationError::NoStop`] without a stop criterion; the first step error (the tissue
    /// then holds the last good state) or callback error. The finalizers run in every case
    /// but the first.
    pub fn run(&mut self) -> Result<RunInfo, SimulationError> {
        if self.stop_iteration.is_none()
            && self.stop_time.is_none()
            && self.wall_time_limit.is_none()
        {
            return Err(SimulationError::NoStop);
        }
        let start = Instant::now();
        let first = self.tissue.iteration();
        let mut stop = false;
        if let Some(b) = &mut self.backend {
            if self.adaptive.is_some() {
                return Err(StepError::Backend {
                    backend: b.name().to_string(),
                    message: "the adaptive step runs on the host only; set [integrator] adaptive = false or backend = \"cpu\"".into(),
                }
                .into());
            }
            b.upload(&self.tissue)?;
            self.synced_at = (self.tissue.iteration(), self.tissue.time());
        }
        let mut result = self.run_loop(start, &mut stop);
        if self.backend.is_some() {
            let synced = self.sync_checked();
            if result.is_ok() {
                result = synced;
            }
        }
        let fin = self.fire(start, Hook::Finalize, &mut stop);
        result.and(fin)?;
        Ok(RunInfo {
            iterations: self.tissue.iteration() - first,
            wall_time: start.elapsed(),
        })
    }

    /// The device's state brought back to the host and checked there (the device checks a
    /// state at the start of each step only, so the last step of a run, and a state a writer
    /// reads between steps, are checked here): a state that fails the check is not taken, and
    /// the host keeps the last good state it had (the one it last brought back or uploaded).
    fn sync_checked(&mut self) -> Result<(), SimulationError> {
        let Some(backend) = self.backend.as_mut() else {
            return Ok(());
        };
        let Some(bound) = self.check.1.phi_bound() else {
            return backend
                .sync(&mut self.tissue)
                .map_err(SimulationError::from);
        };
        let mut fresh = self.tissue.clone();
        let synced = backend.sync(&mut fresh);
        // A step the device refused still brings back its last good state.
        if let Err(e) = fresh.check_state(bound, self.step_params.dt) {
            // The host keeps the fields it last had, at their own clock.
            let (iteration, time) = self.synced_at;
            self.tissue.set_clock(iteration, time);
            self.apply_activity();
            return Err(e.into());
        }
        self.tissue = fresh;
        self.synced_at = (self.tissue.iteration(), self.tissue.time());
        synced.map_err(SimulationError::from)
    }

    /// The fixes, callbacks and writers after a step on a backend: the host's copy of the
    /// state is brought up to date first when any of them fires, and a fix's change is taken
    /// back to the device.
    fn after_device_step(
        &mut self,
        start: Instant,
        stop: &mut bool,
    ) -> Result<(), SimulationError> {
        let (iteration, time) = (self.tissue.iteration(), self.tissue.time());
        let fix_due = self.fixes.iter().any(|(_, t, _)| t.due(iteration, time));
        // What the callbacks due now read: the most any of them needs.
        let needs = self
            .callbacks
            .iter()
            .chain(&self.writers)
            .filter(|e| e.timer.due(iteration, time))
            .map(|e| e.callback.needs())
            .max();
        let call_due = needs.is_some();
        let Some(backend) = self.backend.as_mut() else {
            return Ok(());
        };
        // The observables reduced on the device, when nothing due reads the fields (a series
        // row, a progress line); `None` from a backend that cannot (or whose queued steps
        // failed, which the sync then reports).
        let mut known = None;
        if !fix_due && needs == Some(Needs::Observables) {
            known = backend.observe(&self.tissue)?;
        }
        let synced = fix_due
            || match needs {
                Some(Needs::State) => true,
                Some(Needs::Observables) => known.is_none(),
                Some(Needs::Clock) | None => false,
            };
        if synced {
            self.sync_checked()?;
        }
        let backend = self.backend.as_mut().expect("checked above");
        if fix_due {
            apply_fixes(&mut self.fixes, &mut self.tissue)?;
            backend.upload(&self.tissue)?;
            self.synced_at = (iteration, time);
        }
        if call_due {
            self.fire_with(start, Hook::Call, stop, known, !synced)?;
        }
        Ok(())
    }

    /// The division clock after a step on a backend: [`Tissue::proliferate`] on the host,
    /// from the device's last evaluation, as the host's step leaves it in the workspace. The
    /// cells' quantities come back after a step only while something could happen (a division
    /// or a death due by age, or an extrusion rule, which reads the areas), the pressure only
    /// for a pressure gate with a division due or for the stress-based extrusion rule, the
    /// state only when an event is pending, and
    /// it goes back to the device after the events.
    fn proliferate_on_device(&mut self, before: f64) -> Result<(), SimulationError> {
        let Some(clock) = self.tissue.proliferation() else {
            return Ok(());
        };
        if !self.tissue.active() {
            return Ok(());
        }
        let timed = clock.timed_event_due(&self.tissue);
        if !timed && !clock.extrudes() {
            self.tissue.refresh_target_scale();
            return Ok(());
        }
        let pressure =
            (timed && clock.pressure_gate.is_some()) || clock.extrusion_pressure.is_some();
        let Some(backend) = self.backend.as_mut() else {
            return Ok(());
        };
        let Some(ev) = backend.evaluation(&self.tissue, pressure)? else {
            // A queued step failed (the sync says which), or the backend cannot.
            let name = backend.name().to_string();
            self.sync_checked()?;
            return Err(StepError::Backend {
                backend: name,
                message: "the backend does not bring back its evaluation, which the division clock reads; set [integrator] backend = \"cpu\"".into(),
            }
            .into());
        };
        self.workspace.fit(self.tissue.cells());
        self.workspace.take_device_evaluation(&ev);
        if !self
            .tissue
            .proliferation_pending(&self.workspace, before, timed)
        {
            self.tissue.refresh_target_scale();
            return Ok(());
        }
        self.sync_checked()?;
        let events = self.tissue.proliferate(&mut self.workspace);
        let backend = self.backend.as_mut().expect("checked above");
        // The device takes the events first, also when the run stops here, so that the last
        // sync finds the cells the host has.
        if !events.divisions.is_empty() || !events.removals.is_empty() {
            backend.upload(&self.tissue)?;
            self.synced_at = (self.tissue.iteration(), self.tissue.time());
        }
        if let Some((cell, why)) = events.spared {
            return Err(SimulationError::Extinct {
                iteration: self.tissue.iteration(),
                time: self.tissue.time(),
                cell,
                why: why.name(),
            });
        }
        Ok(())
    }

    fn run_loop(&mut self, start: Instant, stop: &mut bool) -> Result<(), SimulationError> {
        self.apply_activity();
        if !self.initialized {
            self.initialized = true;
            self.fire(start, Hook::Initialize, stop)?;
            self.fire(start, Hook::Start, stop)?;
            // A fix never fires at the starting state: this only sets a time schedule's next
            // firing.
            let (iteration, time) = (self.tissue.iteration(), self.tissue.time());
            for (_, timer, _) in &mut self.fixes {
                timer.fires(iteration, time, true);
            }
        }
        let mut none = ();
        while !*stop && !self.done(start) {
            let it = self.tissue.iteration();
            if let Some(backend) = &mut self.backend {
                backend.step(&self.tissue, &self.step_params)?;
                let before = self.tissue.time();
                self.tissue.advance_clock(self.step_params.dt);
                self.apply_activity();
                self.proliferate_on_device(before)?;
                self.after_device_step(start, stop)?;
                continue;
            }
            if self.sort_every.is_some_and(|k| it.is_multiple_of(k)) {
                self.tissue.sort_cells(&mut self.sort_scratch);
            }
            let t_end = match self.adaptive {
                Some(_) => self.next_landing(),
                None => f64::INFINITY,
            };
            let (timer, check) = &mut self.check;
            let checked = timer.fires(it, self.tissue.time(), false);
            let check: &mut dyn StepCheck = if checked { check.as_mut() } else { &mut none };
            match &mut self.adaptive {
                None => self
                    .tissue
                    .step_checked(&mut self.workspace, &self.step_params, check)?,
                Some((params, ctrl)) => {
                    self.tissue
                        .step_adaptive(&mut self.workspace, params, ctrl, t_end, check)?;
                }
            }
            self.apply_activity();
            let events = self.tissue.proliferate(&mut self.workspace);
            let (iteration, time) = (self.tissue.iteration(), self.tissue.time());
            if let Some((cell, why)) = events.spared {
                return Err(SimulationError::Extinct {
                    iteration,
                    time,
                    cell,
                    why: why.name(),
                });
            }
            apply_fixes(&mut self.fixes, &mut self.tissue)?;
            self.fire(start, Hook::Call, stop)?;
        }
        Ok(())
    }
}

/// The fixes whose schedule fires at the tissue's clock, in the order added: each changes the
/// tissue between steps (the host's copy; a device takes it back afterwards).
fn apply_fixes<T: Real>(
    fixes: &mut [(String, Timer, Box<dyn Fix<T>>)],
    tissue: &mut Tissue<T>,
) -> Result<(), SimulationError> {
    let (iteration, time) = (tissue.iteration(), tissue.time());
    for (name, timer, fix) in fixes {
        if timer.fires(iteration, time, false) {
            fix.apply(tissue)
                .map_err(|source| SimulationError::Callback {
                    name: name.clone(),
                    iteration,
                    source,
                })?;
        }
    }
    Ok(())
}
