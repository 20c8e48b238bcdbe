//! `monolayer.Simulation` (a scene stepped in memory, steered from Python), and the run
//! directories (`run`, `resume`) and pictures (`render`) of the command line.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};

use mechanics::Precision;
use mechanics::{CallbackError, Observation, Schedule, Simulation, Tissue};
use phasefield::Real;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use rundir::{Interrupt, Outcome, RunDir};

use crate::cells::{cells_dict, fields_dict, phi_arrays};
use crate::force::{ErrorSlot, PyForce};
use crate::interrupt;
use crate::scene::{scene_error, PyScene};

/// A simulation in one of the two precisions of `[integrator] precision`.
enum Inner {
    F64(Simulation<f64>),
    F32(Simulation<f32>),
}

/// `$body` with `$s` bound to the simulation, whatever its precision.
macro_rules! with_sim {
    ($inner:expr, $s:ident => $body:expr) => {
        match $inner {
            Inner::F64($s) => $body,
            Inner::F32($s) => $body,
        }
    };
}

/// Where the progress is reported: a Python function of the model time, called at least
/// every `every` TU.
#[derive(Default)]
struct Progress {
    func: Option<Py<PyAny>>,
    next: f64,
    every: f64,
}

type ProgressSlot = Arc<Mutex<Option<Progress>>>;

/// The first error of the Python code a run called, taken out of its slot.
fn take(slot: &ErrorSlot) -> Option<PyErr> {
    slot.lock().unwrap_or_else(|p| p.into_inner()).take()
}

fn keep(slot: &ErrorSlot, e: PyErr) {
    slot.lock()
        .unwrap_or_else(|p| p.into_inner())
        .get_or_insert(e);
}

/// The callback every simulation run from Python has, after every step: stops on Ctrl-C
/// (raising `interrupt` for a run directory's checkpoint), on an error of Python code called
/// in the run, and reports the progress.
fn watcher<T: Real>(
    errors: ErrorSlot,
    progress: ProgressSlot,
    raise: Option<Interrupt>,
) -> impl FnMut(&mut Observation<'_, T>) -> Result<(), CallbackError> + Send {
    move |obs| {
        if interrupt::caught() {
            match &raise {
                Some(i) => i.raise(2),
                None => obs.request_stop(),
            }
        }
        if errors.lock().map_or(true, |e| e.is_some()) {
            obs.request_stop();
        }
        let mut p = progress.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(Progress {
            func: Some(f),
            next,
            every,
        }) = p.as_mut()
        {
            let t = obs.time();
            if t >= *next {
                *next = t + *every;
                let r = Python::attach(|py| f.bind(py).call1((t,)).map(|_| ()));
                if let Err(e) = r {
                    keep(&errors, e);
                    obs.request_stop();
                }
            }
        }
        Ok(())
    }
}

/// A rayon pool of `threads` (all the cores for `None`).
fn pool(threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    if threads == Some(0) {
        return Err(PyValueError::new_err(
            "threads = 0: give a number of threads of at least 1, or None for every core",
        ));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the threads: {e}")))
}

/// The command line's memory guard ([`rundir::memory::check_memory`]): a scene larger than
/// the memory this process can still use raises `MemoryError` with the estimate and the keys
/// to change, instead of an abort in the allocator.
fn memory_guard(scene: &::scene::Scene) -> PyResult<()> {
    rundir::memory::check_memory(scene, 1, None, MORE_MEMORY)
        .map_err(|e| pyo3::exceptions::PyMemoryError::new_err(e.to_string()))
}

/// What Python can do about a run too large for the memory (no flag raises the limit).
const MORE_MEMORY: &str = "run it where more memory is free";

/// The most steps one call takes (2**62: about 10¹⁸, far beyond any run).
const STEP_MAX: u64 = 1 << 62;

/// A whole number from a Python int or a NumPy integer (anything with `__index__`), in
/// `0..=max`, for the argument `arg` of `call`: a `ValueError` that names both and the range
/// otherwise, and a `TypeError` for what is not a whole number.
pub(crate) fn whole(call: &str, arg: &str, v: &Bound<'_, PyAny>, max: u64) -> PyResult<u64> {
    let index = v.call_method0("__index__").map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "{call}: {arg} = {}: give a whole number (an int), not a {}",
            v.repr().map(|r| r.to_string()).unwrap_or_default(),
            v.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    let out_of_range = || {
        PyValueError::new_err(format!(
            "{call}: {arg} = {}: give a whole number from 0 to {max}",
            index.str().map(|r| r.to_string()).unwrap_or_default()
        ))
    };
    let n: i128 = index.extract().map_err(|_| out_of_range())?;
    if n < 0 || n > i128::from(max) {
        return Err(out_of_range());
    }
    Ok(n as u64)
}

/// [`whole`] of an optional argument.
pub(crate) fn opt_whole(
    call: &str,
    arg: &str,
    v: Option<&Bound<'_, PyAny>>,
    max: u64,
) -> PyResult<Option<u64>> {
    v.filter(|v| !v.is_none())
        .map(|v| whole(call, arg, v, max))
        .transpose()
}

/// The most threads a pool is asked for.
const THREADS_MAX: u64 = 4096;

/// What a call into a simulation that is stepping gets.
const BUSY: &str = "this Simulation is stepping (its step or run_until is running, in this thread or another), and cannot be read or changed until that returns: a force gets the cells as its argument `cells`, a callback its observation `obs.cells`, and a fix its edit `e` (use those instead of the simulation's own methods); threads that share one simulation must take turns (hold a threading.Lock around each call)";

/// A step error as Python sees it: `RuntimeError` with the message of the command line.
fn run_error(e: impl std::fmt::Display) -> PyErr {
    PyRuntimeError::new_err(e.to_string())
}

/// A scene simulated in memory, stepped and steered from Python.
#[pyclass(module = "monolayer._native", name = "Simulation")]
pub struct PySimulation {
    inner: Mutex<Inner>,
    pool: rayon::ThreadPool,
    scene: PyScene,
    errors: ErrorSlot,
    progress: ProgressSlot,
    forces: AtomicUsize,
}

impl PySimulation {
    /// The simulation, unless it is stepping: a force, callback or fix of this simulation
    /// that calls one of its methods, or a second thread, gets an error that says why.
    fn inner(&self) -> PyResult<MutexGuard<'_, Inner>> {
        match self.inner.try_lock() {
            Ok(g) => Ok(g),
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(BUSY)),
        }
    }

    /// Runs to the stop criteria `(iteration, time)` with the lock released, then raises
    /// what stopped it early: Ctrl-C, an error of Python code, a step error.
    fn run_to(
        &self,
        py: Python<'_>,
        stop: (Option<u64>, Option<f64>),
        progress: Option<Py<PyAny>>,
    ) -> PyResult<()> {
        let end = stop.1.unwrap_or(f64::INFINITY);
        let now = self.time()?;
        *self.progress.lock().unwrap_or_else(|p| p.into_inner()) = Some(Progress {
            func: progress,
            next: now,
            every: if end.is_finite() {
                ((end - now) / 200.0).max(0.0)
            } else {
                0.0
            },
        });
        let _armed = interrupt::Armed::new(py);
        let mut guard = self.inner()?;
        let inner: &mut Inner = &mut guard;
        let pool = &self.pool;
        let result = py.detach(|| {
            pool.install(|| {
                with_sim!(inner, s => {
                    s.set_stop(stop.0, stop.1);
                    s.run().map(|_| ())
                })
            })
        });
        drop(guard);
        self.progress
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take();
        if let Some(e) = take(&self.errors) {
            return Err(e);
        }
        if interrupt::caught() {
            let (it, t) = (self.iteration()?, self.time()?);
            return interrupt::deliver(
                py,
                format!("stopped after step {it} (t = {t}); the simulation can go on"),
            );
        }
        result.map_err(run_error)
    }
}

/// `every` (model time) or `steps` (iterations) as a schedule.
/// `steps` is a Python int or NumPy integer ([`opt_whole`], named after `call`).
fn schedule(
    call: &str,
    every: Option<f64>,
    steps: Option<&Bound<'_, PyAny>>,
) -> PyResult<Schedule> {
    let steps = opt_whole(call, "steps", steps, STEP_MAX)?;
    match (every, steps) {
        (Some(t), None) if t > 0.0 && t.is_finite() => Ok(Schedule::TimeInterval(t)),
        (None, Some(n)) if n > 0 => Ok(Schedule::IterationInterval(n)),
        (None, None) => Ok(Schedule::IterationInterval(1)),
        _ => Err(PyValueError::new_err(
            "give every=T (model time, T > 0) or steps=N (N ≥ 1), not both",
        )),
    }
}

/// What a callback sees: the time, the step and the cells' columns at that state.
#[pyclass(module = "monolayer._native", name = "Observation")]
pub struct PyObservation {
    #[pyo3(get)]
    time: f64,
    #[pyo3(get)]
    iteration: u64,
    #[pyo3(get)]
    cells: Py<PyDict>,
    stop: Arc<AtomicBool>,
}

#[pymethods]
impl PyObservation {
    /// Asks the run to stop after this step's callbacks (`run` then returns normally).
    fn stop(&self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

/// A change to the state between steps (a fix): what `fn(edit)` asks, applied after it
/// returns.
#[pyclass(module = "monolayer._native", name = "Edit")]
pub struct PyEdit {
    #[pyo3(get)]
    time: f64,
    #[pyo3(get)]
    iteration: u64,
    /// The identities of the living cells, in increasing order.
    #[pyo3(get)]
    ids: Vec<usize>,
    states: Vec<(String, Vec<f64>)>,
    asked: Vec<Change>,
}

enum Change {
    Param(String, f64),
    State(String, Vec<f64>),
}

#[pymethods]
impl PyEdit {
    /// Sets a model parameter: `zeta`, `xi`, `gamma`, `mu`, `lambda`, `kappa`, `omega`.
    fn set_param(&mut self, name: String, value: f64) -> PyResult<()> {
        if !value.is_finite() {
            return Err(PyValueError::new_err(format!(
                "set_param({name:?}, {value}): give a finite value"
            )));
        }
        if !PARAMS.contains(&name.as_str()) {
            return Err(PyValueError::new_err(format!(
                "set_param({name:?}): no such parameter; use one of {}",
                PARAMS.join(", ")
            )));
        }
        self.asked.push(Change::Param(name, value));
        Ok(())
    }

    /// The per-cell state `name` of a term (`"polarity.theta"`), one value per identity
    /// `0..max(id)+1`.
    fn state(&self, name: &str) -> PyResult<Vec<f64>> {
        self.states
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "no per-cell state {name:?}; the scene has {}",
                    names(&self.states)
                ))
            })
    }

    /// Sets the per-cell state `name` of a term, one value per identity (as [`state`] gives).
    fn set_state(&mut self, name: String, values: Vec<f64>) -> PyResult<()> {
        let Some((_, now)) = self.states.iter().find(|(n, _)| *n == name) else {
            return Err(PyValueError::new_err(format!(
                "no per-cell state {name:?}; the scene has {}",
                names(&self.states)
            )));
        };
        if values.len() != now.len() || values.iter().any(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "set_state({name:?}): give {} finite values, one per identity",
                now.len()
            )));
        }
        self.asked.push(Change::State(name, values));
        Ok(())
    }
}

const PARAMS: [&str; 7] = ["zeta", "xi", "gamma", "mu", "lambda", "kappa", "omega"];

fn names(states: &[(String, Vec<f64>)]) -> String {
    if states.is_empty() {
        "none".into()
    } else {
        states
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The scene a simulation was built from, to validate an edit's parameters as the scene's
/// own keys are validated (`set_param("xi", -1)` is refused as `model.xi = -1` would be).
#[derive(Clone)]
struct ParamCheck {
    text: String,
    set: Vec<String>,
}

impl ParamCheck {
    fn new(scene: &PyScene) -> Self {
        let set = match &scene.path {
            Some(p) => ::scene::absolute_paths(p, &scene.text, &scene.set)
                .unwrap_or_else(|_| scene.set.clone()),
            None => scene.set.clone(),
        };
        Self {
            text: scene.text.clone(),
            set,
        }
    }

    /// The scene key of an edit's parameter.
    fn key(name: &str) -> String {
        match name {
            "omega" => "adhesion.omega".into(),
            other => format!("model.{other}"),
        }
    }

    /// Validates the changes `asked` together, as `--set` overrides of the scene.
    fn check(&self, asked: &[(String, f64)]) -> PyResult<()> {
        let mut set = self.set.clone();
        set.extend(asked.iter().map(|(n, v)| format!("{}={v:?}", Self::key(n))));
        ::scene::Scene::parse(&self.text, &set)
            .map(|_| ())
            .map_err(|e| {
                let what: Vec<String> = asked
                    .iter()
                    .map(|(n, v)| format!("set_param({n:?}, {v})"))
                    .collect();
                PyValueError::new_err(format!(
                    "{}: the scene refuses it as {}: {e}",
                    what.join(", "),
                    asked
                        .iter()
                        .map(|(n, _)| Self::key(n))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }
}

/// Calls `func(edit)` on the state of `tissue`, then applies what it asked, once `check`
/// has validated its parameters (nothing is applied otherwise).
fn apply_edit<T: Real>(
    py: Python<'_>,
    func: &Py<PyAny>,
    tissue: &mut Tissue<T>,
    check: &ParamCheck,
) -> PyResult<()> {
    let mut ids: Vec<usize> = tissue.cell_ids().to_vec();
    ids.sort_unstable();
    let states = tissue
        .terms()
        .variables()
        .into_iter()
        .map(|(n, v)| (n.replacen('/', ".", 1), v))
        .collect();
    let edit = Bound::new(
        py,
        PyEdit {
            time: tissue.time(),
            iteration: tissue.iteration(),
            ids,
            states,
            asked: Vec::new(),
        },
    )?;
    func.bind(py).call1((edit.clone(),))?;
    let asked = std::mem::take(&mut edit.borrow_mut().asked);
    let params: Vec<(String, f64)> = asked
        .iter()
        .filter_map(|c| match c {
            Change::Param(n, v) => Some((n.clone(), *v)),
            Change::State(..) => None,
        })
        .collect();
    if !params.is_empty() {
        check.check(&params)?;
    }
    for change in asked {
        match change {
            Change::Param(name, v) => {
                let p = tissue.params_mut();
                match name.as_str() {
                    "zeta" => p.zeta = v,
                    "xi" => p.xi = v,
                    "gamma" => p.energy.gamma = v,
                    "mu" => p.energy.mu = v,
                    "lambda" => p.energy.lambda = v,
                    "kappa" => p.energy.kappa = v,
                    "omega" => p.omega = v,
                    _ => unreachable!("checked by set_param"),
                }
            }
            Change::State(name, values) => tissue
                .terms_mut()
                .set_variable(&name.replacen('.', "/", 1), &values)
                .map_err(PyValueError::new_err)?,
        }
    }
    Ok(())
}

#[pymethods]
impl PySimulation {
    #[new]
    #[pyo3(signature = (scene, threads=None, backend="cpu"))]
    fn new(
        py: Python<'_>,
        scene: PyScene,
        threads: Option<&Bound<'_, PyAny>>,
        backend: &str,
    ) -> PyResult<Self> {
        let threads = opt_whole("Simulation", "threads", threads, THREADS_MAX)?.map(|t| t as usize);
        match backend {
            "cpu" => {}
            "gpu" => {
                return Err(PyValueError::new_err(
                    "backend = \"gpu\": the Python package is built without the GPU backend; run GPU scenes with the command line (`cargo build --release -p monolayer-cli --features gpu`), or use backend=\"cpu\"",
                ))
            }
            other => {
                return Err(PyValueError::new_err(format!(
                    "backend = {other:?}: use \"cpu\""
                )))
            }
        }
        let pool = pool(threads)?;
        let s = &scene.scene;
        if s.backend() != scene::ComputeBackend::Cpu {
            return Err(PyValueError::new_err(
                "[integrator] backend = \"gpu\": the Python package is built without the GPU backend, and a Simulation does not move a GPU scene to the CPU without a word; set it to \"cpu\" (scene.set(\"integrator.backend\", \"cpu\")), or run the scene with the command line",
            ));
        }
        memory_guard(s)?;
        // What the command line's `run` warns of, as Python warnings.
        let said = rundir::state_warnings(s).map_err(|e| scene_error(None, e))?;
        for w in said {
            py.import("warnings")?.call_method1("warn", (w,))?;
        }
        let build = |e: rundir::StateError| scene_error(None, e);
        let inner = match s.precision() {
            Precision::F64 => {
                Inner::F64(s.simulation_from(rundir::initial_tissue::<f64>(s).map_err(build)?))
            }
            Precision::F32 => {
                Inner::F32(s.simulation_from(rundir::initial_tissue::<f32>(s).map_err(build)?))
            }
        };
        let errors: ErrorSlot = Arc::default();
        let progress: ProgressSlot = Arc::default();
        let sim = Self {
            inner: Mutex::new(inner),
            pool,
            scene,
            errors: errors.clone(),
            progress: progress.clone(),
            forces: AtomicUsize::new(0),
        };
        with_sim!(&mut *sim.inner()?, s => s.add_callback(
            "python",
            Schedule::IterationInterval(1),
            watcher(errors.clone(), progress.clone(), None),
        ));
        Ok(sim)
    }

    /// The scene.
    #[getter]
    fn scene(&self) -> PyScene {
        self.scene.clone()
    }

    /// The model time.
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(with_sim!(&mut *self.inner()?, s => s.tissue().time()))
    }

    /// Steps taken.
    #[getter]
    fn iteration(&self) -> PyResult<u64> {
        Ok(with_sim!(&mut *self.inner()?, s => s.tissue().iteration()))
    }

    /// The number of cells.
    #[getter]
    fn n_cells(&self) -> PyResult<usize> {
        Ok(with_sim!(&mut *self.inner()?, s => s.tissue().n_cells()))
    }

    /// Takes `n` steps (the interpreter's lock released).
    fn step(&self, py: Python<'_>, n: &Bound<'_, PyAny>) -> PyResult<()> {
        let it = self.iteration()?;
        let n = whole("step(n)", "n", n, STEP_MAX - it.min(STEP_MAX))?;
        self.run_to(py, (Some(it + n), None), None)
    }

    /// Runs to model time `until` (the scene's end by default); `progress(t)` is called
    /// about 200 times on the way.
    #[pyo3(signature = (until=None, progress=None))]
    fn run_until(
        &self,
        py: Python<'_>,
        until: Option<f64>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<()> {
        let until = until.unwrap_or_else(|| self.scene.scene.end_time());
        if !until.is_finite() {
            return Err(PyValueError::new_err("until: give a finite model time"));
        }
        // With fixed steps, the step count (a clock summed step by step drifts from the
        // multiples of dt over thousands of steps); an adaptive run lands on the time.
        let (adaptive, dt) = {
            let i = &self.scene.scene.file().integrator;
            (i.adaptive, i.dt)
        };
        if adaptive {
            return self.run_to(py, (None, Some(until)), progress);
        }
        let now = self.time()?;
        // The first step at or after `until` (a clock within 1e-9 steps of it lands on it);
        // where that is not `until`, a warning says where the run stopped and why.
        let ahead = ((until - now) / dt - 1e-9).ceil().max(0.0);
        if ahead >= STEP_MAX as f64 {
            return Err(PyValueError::new_err(format!(
                "run_until(until={until}): {ahead:.3e} steps of dt = {dt} from t = {now}; give a time fewer than 2**62 steps ahead"
            )));
        }
        let ahead = ahead as u64;
        let stop = self.iteration()? + ahead;
        let lands = now + ahead as f64 * dt;
        if until > now && (lands - until).abs() > 1e-9 * dt.max(until.abs()) {
            let msg = format!(
                "run_until(until={until}) stops at t = {lands} (step {stop}), the first step at or after it: the time step is fixed at dt = {dt}; give a multiple of dt, or set integrator.adaptive = true to land on any time"
            );
            py.import("warnings")?.call_method1("warn", (msg,))?;
        }
        self.run_to(py, (Some(stop), Some(until.max(now) + 0.5 * dt)), progress)
    }

    /// The cells' columns (a dict of 1-D NumPy arrays, copies); with `[run] forces_by_origin`
    /// also each cell's force by origin, `force.ORIGIN.x` and `.y`.
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let by_origin = self.scene.scene.file().run.forces_by_origin;
        with_sim!(&mut *self.inner()?, s => {
            let (t, ws, _) = s.observe();
            let d = cells_dict(py, t, ws)?;
            if by_origin {
                let mut own = mechanics::Workspace::new(t.cells());
                let parts = t.forces_by_origin(&mut own);
                let slots = t.slots();
                for (name, f) in parts.names.iter().zip(&parts.parts) {
                    for (k, axis) in ["x", "y"].into_iter().enumerate() {
                        let values: Vec<f64> = slots.iter().map(|&s| f[s][k]).collect();
                        d.set_item(format!("force.{name}.{axis}"), crate::cells::column(py, values)?)?;
                    }
                }
            }
            Ok(d)
        })
    }

    /// Every cell's field on its patch: `(phi, origin, id)`, copies.
    fn phi<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        with_sim!(&mut *self.inner()?, s => phi_arrays(py, s.tissue()))
    }

    /// The lattice fields (a dict of NumPy arrays, copies).
    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (l, f, phi_sum) = with_sim!(&mut *self.inner()?, s => {
            let (f, phi_sum) = s.fields();
            (s.tissue().lattice(), f, phi_sum)
        });
        fields_dict(py, l, f, phi_sum)
    }

    /// The observables of the paper's series (a dict of floats).
    fn observables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let o = with_sim!(&mut *self.inner()?, s => s.observe().2);
        let d = PyDict::new(py);
        for (k, v) in [
            ("v_rms", o.v_rms),
            ("s_rms", o.s_rms),
            ("area_mean", o.area_mean),
            ("area_min", o.area_min),
            ("area_max", o.area_max),
            ("cell_speed_rms", o.cell_speed_rms),
            ("phi_min", o.phi_min),
            ("phi_max", o.phi_max),
        ] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// Calls `func(observation)` on a schedule while the simulation runs (every step by
    /// default; `every` in model time, or `steps`).
    #[pyo3(signature = (func, every=None, steps=None))]
    fn add_callback(
        &self,
        func: Py<PyAny>,
        every: Option<f64>,
        steps: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let schedule = schedule("add_callback", every, steps)?;
        let errors = self.errors.clone();
        macro_rules! callback {
            ($s:ident, $T:ty) => {{
                let errors = errors.clone();
                let func = Python::attach(|py| func.clone_ref(py));
                $s.add_callback(
                    "python callback",
                    schedule,
                    move |obs: &mut Observation<'_, $T>| -> Result<(), CallbackError> {
                        let stop = Arc::new(AtomicBool::new(false));
                        let (time, iteration) = (obs.time(), obs.iteration());
                        let tissue = obs.tissue();
                        let ws = obs.workspace();
                        let r = Python::attach(|py| -> PyResult<()> {
                            let cells = cells_dict(py, tissue, ws)?.unbind();
                            let o = PyObservation {
                                time,
                                iteration,
                                cells,
                                stop: stop.clone(),
                            };
                            func.bind(py).call1((o,))?;
                            Ok(())
                        });
                        if let Err(e) = r {
                            keep(&errors, e);
                            obs.request_stop();
                        }
                        if stop.load(Ordering::SeqCst) {
                            obs.request_stop();
                        }
                        Ok(())
                    },
                )
            }};
        }
        match &mut *self.inner()? {
            Inner::F64(s) => callback!(s, f64),
            Inner::F32(s) => callback!(s, f32),
        }
        Ok(())
    }

    /// Adds a whole-cell force `func(t, cells) -> (n, 2) array`, called at every evaluation
    /// (both stages of each step) with the cells' columns `id`, `population`, `x`, `y`,
    /// `vx`, `vy`, `area`.
    #[pyo3(signature = (func, name=None))]
    fn add_force(&self, func: Py<PyAny>, name: Option<String>) -> PyResult<()> {
        let k = self.forces.fetch_add(1, Ordering::SeqCst) + 1;
        let name = name.unwrap_or_else(|| format!("python_force_{k}"));
        let taken = with_sim!(&mut *self.inner()?, s => s.tissue().terms().get(&name).is_some());
        if taken {
            return Err(PyValueError::new_err(format!(
                "a force or term named {name:?} is there already; give another name"
            )));
        }
        let term = Arc::new(PyForce {
            name,
            func,
            error: self.errors.clone(),
        });
        with_sim!(&mut *self.inner()?, s => s.tissue_mut().terms_mut().add(term));
        Ok(())
    }

    /// Changes the state now: `func(edit)` (a [`PyEdit`]) asks for changes, applied when it
    /// returns, as a fix would between two steps.
    fn edit(&self, py: Python<'_>, func: Py<PyAny>) -> PyResult<()> {
        let check = ParamCheck::new(&self.scene);
        with_sim!(&mut *self.inner()?, s => apply_edit(py, &func, s.tissue_mut(), &check))
    }

    /// Calls `func(edit)` after every step at which the schedule fires (every step by
    /// default), before the callbacks: a fix.
    #[pyo3(signature = (func, every=None, steps=None))]
    fn add_fix(
        &self,
        func: Py<PyAny>,
        every: Option<f64>,
        steps: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let schedule = schedule("add_fix", every, steps)?;
        let errors = self.errors.clone();
        let check = ParamCheck::new(&self.scene);
        macro_rules! fix {
            ($s:ident, $T:ty) => {{
                $s.add_fix(
                    "python fix",
                    schedule,
                    move |t: &mut Tissue<$T>| -> Result<(), CallbackError> {
                        if let Err(e) = Python::attach(|py| apply_edit(py, &func, t, &check)) {
                            keep(&errors, e);
                        }
                        Ok(())
                    },
                )
            }};
        }
        match &mut *self.inner()? {
            Inner::F64(s) => fix!(s, f64),
            Inner::F32(s) => fix!(s, f32),
        }
        Ok(())
    }

    /// The state as a run directory's frame, drawn by the command line's renderer: PNG bytes.
    #[pyo3(signature = (colour="none", **options))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        colour: &str,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        // Drawn in memory, as `monolayer render` draws the frame of this state.
        let opts = render_options(None, colour, options)?;
        let scene = &self.scene.scene;
        let png = with_sim!(&mut *self.inner()?, s => {
            let (t, ws, _) = s.observe();
            study::view::render_state(scene, t, ws, &opts)
                .map_err(|e| PyValueError::new_err(e.to_string().replace("--", "")))?
        });
        Ok(PyBytes::new(py, &png))
    }

    fn __repr__(&self) -> PyResult<String> {
        let (n, t) = with_sim!(&mut *self.inner()?, s => (s.tissue().n_cells(), s.tissue().time()));
        Ok(format!("Simulation({n} cells at t = {t})"))
    }
}

/// Renders frames of the run directory `dir` (`steps`, or all) with `colour` and the boolean
/// `options` of `monolayer render` (`director`, `defects`, `flow`, `axes`, `polarity`, `nematic`,
/// `tracks`, `events`) and `size`: `(step, PNG bytes)` for each.
fn render_in(
    dir: &Path,
    steps: Option<Vec<u64>>,
    colour: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(u64, Vec<u8>)>> {
    let opts = render_options(steps, colour, options)?;
    let out = tempfile::tempdir().map_err(|e| PyOSError::new_err(e.to_string()))?;
    let info = study::view::render_run(dir, out.path(), &opts, &mut |_, _| {})
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    info.files
        .iter()
        .map(|f| {
            let step = f
                .file_stem()
                .and_then(|s| s.to_str())
                .and_then(|s| s.strip_prefix("frame_"))
                .and_then(|s| s.parse().ok())
                .unwrap_or(0);
            std::fs::read(f)
                .map(|b| (step, b))
                .map_err(|e| PyOSError::new_err(format!("{}: {e}", f.display())))
        })
        .collect()
}

/// The render options of `monolayer render` from Python's arguments: the frames `steps`
/// (all for `None`), `colour`, and the boolean options and `size`, `range`.
fn render_options(
    steps: Option<Vec<u64>>,
    colour: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<study::view::RenderOptions> {
    use study::view::{Colour, Frames, RenderOptions};
    let mut opts = RenderOptions {
        colour: colour
            .parse::<Colour>()
            .map_err(|e| PyValueError::new_err(e.replace("--colour", "colour")))?,
        frames: steps.map_or(Frames::All, Frames::Steps),
        ..RenderOptions::default()
    };
    if let Some(o) = options {
        for (k, v) in o.iter() {
            let k: String = k.extract()?;
            match k.as_str() {
                "size" => opts.size = Some(v.extract()?),
                "range" => opts.range = Some(v.extract()?),
                "director_of" => {
                    let of: String = v.extract()?;
                    opts.director_of = of.parse().map_err(|e: String| {
                        PyValueError::new_err(e.replace("--director-of", "director_of"))
                    })?;
                }
                flag => {
                    let on: bool = v.extract()?;
                    match flag {
                        "director" => opts.director = on,
                        "defects" => opts.defects = on,
                        "flow" => opts.flow = on,
                        "axes" => opts.axes = on,
                        "polarity" => opts.polarity = on,
                        "nematic" => opts.nematic = on,
                        "tracks" => opts.tracks = on,
                        "events" => opts.events = on,
                        _ => {
                            return Err(PyValueError::new_err(format!(
                            "render: no option {flag:?}; use size, range, director, defects, director_of, flow, axes, polarity, nematic, tracks or events"
                        )))
                        }
                    }
                }
            }
        }
    }
    Ok(opts)
}

/// Frames of a run directory drawn by the command line's renderer: `[(step, PNG bytes)]`.
#[pyfunction]
#[pyo3(signature = (dir, steps=None, colour="none", **options))]
pub fn render_dir<'py>(
    py: Python<'py>,
    dir: PathBuf,
    steps: Option<Vec<u64>>,
    colour: &str,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Vec<(u64, Bound<'py, PyBytes>)>> {
    Ok(render_in(&dir, steps, colour, options)?
        .into_iter()
        .map(|(s, b)| (s, PyBytes::new(py, &b)))
        .collect())
}

/// Drives the run directory `dir` to its end (or a Ctrl-C) with the lock released, on
/// `pool`. A run that cannot be built is refused before its first step; `fresh` is then the
/// directory this call created, removed again so that the refusal leaves nothing behind.
fn drive<T: Real>(
    py: Python<'_>,
    dir: &RunDir,
    pool: rayon::ThreadPool,
    progress: Option<Py<PyAny>>,
    interrupt: Interrupt,
    fresh: Option<&std::path::Path>,
) -> PyResult<Py<PyDict>> {
    let (mut sim, written) = match dir.simulation::<T>() {
        Ok(built) => built,
        Err(e) => {
            if let Some(out) = fresh {
                let _ = std::fs::remove_dir_all(out);
            }
            return Err(run_error(e));
        }
    };
    let errors: ErrorSlot = Arc::default();
    let now = sim.tissue().time();
    let end = dir.scene().end_time();
    let progress: ProgressSlot = Arc::new(Mutex::new(Some(Progress {
        func: progress,
        next: now,
        every: ((end - now) / 200.0).max(0.0),
    })));
    sim.add_callback(
        "python",
        Schedule::IterationInterval(1),
        watcher(errors.clone(), progress, Some(interrupt)),
    );
    let _armed = interrupt::Armed::new(py);
    let outcome = py.detach(|| pool.install(|| dir.run(&mut sim)));
    if let Some(e) = take(&errors) {
        return Err(e);
    }
    let outcome = outcome.map_err(run_error)?;
    match outcome {
        Outcome::Complete(info) => {
            let d = PyDict::new(py);
            d.set_item("steps", info.iterations)?;
            d.set_item("wall_s", info.wall_time.as_secs_f64())?;
            d.set_item("frames", written.frames())?;
            d.set_item("dir", dir.dir())?;
            Ok(d.unbind())
        }
        Outcome::Stopped { step, time, .. } => {
            interrupt::deliver(
                py,
                format!(
                    "stopped at step {step} (t = {}): resume with monolayer.resume({:?})",
                    (time * 1e9).round() / 1e9,
                    dir.dir().display().to_string()
                ),
            )?;
            unreachable!("deliver raises")
        }
    }
}

fn drive_any(
    py: Python<'_>,
    dir: &RunDir,
    pool: rayon::ThreadPool,
    progress: Option<Py<PyAny>>,
    interrupt: Interrupt,
    fresh: Option<&std::path::Path>,
) -> PyResult<Py<PyDict>> {
    match dir.scene().precision() {
        Precision::F64 => drive::<f64>(py, dir, pool, progress, interrupt, fresh),
        Precision::F32 => drive::<f32>(py, dir, pool, progress, interrupt, fresh),
    }
}

/// Runs `scene` into the run directory `out`, writing what `monolayer run` writes (frames,
/// series, checkpoints, the lock, `run.json`); returns what it did. Ctrl-C stops it after
/// the step in progress with a checkpoint, and raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (scene, out, overwrite=false, threads=None, progress=None))]
pub fn run_dir(
    py: Python<'_>,
    scene: &PyScene,
    out: PathBuf,
    overwrite: bool,
    threads: Option<&Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Py<PyDict>, Vec<String>)> {
    let threads = opt_whole("monolayer.run", "threads", threads, THREADS_MAX)?.map(|t| t as usize);
    let s = &scene.scene;
    if s.backend() != scene::ComputeBackend::Cpu {
        return Err(PyValueError::new_err(
            "[integrator] backend = \"gpu\": the Python package is built without the GPU backend; run it with the command line, or set integrator.backend = \"cpu\"",
        ));
    }
    // Before anything is allocated or written, as the command line checks it: a refused
    // run leaves no directory.
    let new = rundir::prepare_new_run(s, None, MORE_MEMORY).map_err(|e| match e {
        rundir::PrepareError::Memory(m) => pyo3::exceptions::PyMemoryError::new_err(m.to_string()),
        other => scene_error(scene.path.as_deref(), other),
    })?;
    let pool = pool(threads)?;
    let fresh = !out.exists();
    let warnings = new.warnings;
    let interrupt = Interrupt::never();
    let dir =
        RunDir::create(&out, s.clone(), new.state, overwrite, interrupt.clone()).map_err(|e| {
            // The command line's flags, as this function's keywords.
            PyOSError::new_err(e.to_string().replace(
                "choose another --out or pass --overwrite",
                "choose another out or pass overwrite=True",
            ))
        })?;
    let fresh = fresh.then_some(out.as_path());
    Ok((
        drive_any(py, &dir, pool, progress, interrupt, fresh)?,
        warnings,
    ))
}

/// Continues the run in `dir` from its latest checkpoint to the end of its scene (to
/// `run.time = time` when given, to extend it), as `monolayer run --resume`.
#[pyfunction]
#[pyo3(signature = (dir, time=None, threads=None, progress=None))]
pub fn resume_dir(
    py: Python<'_>,
    dir: PathBuf,
    time: Option<f64>,
    threads: Option<&Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Py<PyDict>> {
    let threads =
        opt_whole("monolayer.resume", "threads", threads, THREADS_MAX)?.map(|t| t as usize);
    let set: Vec<String> = time
        .map(|t| format!("run.time={t:?}"))
        .into_iter()
        .collect();
    let interrupt = Interrupt::never();
    let run = RunDir::resume(&dir, &set, interrupt.clone())
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    // (Nothing in the directory has changed yet: it does once the run starts.)
    memory_guard(run.scene())?;
    if run.scene().backend() != scene::ComputeBackend::Cpu {
        return Err(PyValueError::new_err(format!(
            "{}: its scene runs on the GPU ([integrator] backend = \"gpu\"), and the Python package is built without the GPU backend; resume it with the command line (monolayer run --resume {0}), or on the CPU with monolayer run --resume {0} --set integrator.backend=cpu",
            dir.display()
        )));
    }
    let pool = pool(threads)?;
    drive_any(py, &run, pool, progress, interrupt, None)
}
