//! # scene
//!
//! Scene files of monolayer: one TOML document describes a run completely. Reading one is
//! in two steps, after ripgrep's low- and high-level arguments:
//!
//! - [`SceneFile`] mirrors the file (every table rejects unknown keys) and takes
//!   `--set section.key=value` overrides;
//! - [`SceneFile::validate`] checks every value once and returns a [`Scene`], a type that
//!   cannot hold an invalid scene; its error, [`SceneError`], names the key and the fix.
//!
//! A [`Scene`] builds the library objects: the initial [`Tissue`] and a ready
//! [`Simulation`] (relaxation at ζ = 0, then activity, stopping at the scene's end). The
//! defaults of every key come from the libraries ([`mechanics::StepParams::default`],
//! [`phasefield::PatchShape::DEFAULT_MARGIN`], [`mechanics::ModelParams::paper`]).
//!
//! Running a relaxed paper scene from Rust and printing v_rms, in a few lines:
//!
//! ```
//! use mechanics::prelude::*;
//! use scene::Scene;
//!
//! let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/paper.toml"))?;
//! // The paper's scene, shortened: 20 TU of relaxation, then 10 TU at its ζ.
//! let scene = Scene::parse(&text, &["run.relax_time=20".into(), "run.time=10".into()])?;
//! let mut sim = scene.simulation::<f32>()?;
//! sim.add_callback("print", Schedule::TimeInterval(10.0), |o: &mut Observation<f32>| {
//!     println!("t = {:5.1}  v_rms = {:.3e}", o.time(), o.observables().v_rms);
//!     Ok(())
//! });
//! sim.run()?;
//! assert!((sim.tissue().time() - 30.0).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod check;
mod division;
mod error;
mod file;
mod paths;
mod registry;
mod validate;
mod walls;

pub use error::{SceneError, MAX_SIDE, MAX_STEPS};
pub use file::{
    AdhesionSpec, AlignKind, CellsSpec, ComputeBackend, DivisionAxis, DivisionSpec, Domain,
    FrictionSpec, InitKind, Integrator, Model, NematicSpec, PolaritySpec, PopulationSpec,
    PropulsionKind, Run, SceneFile, WallKind, WallsSpec,
};
pub use paths::absolute_paths;
pub use registry::{register_term, registered_terms, TermBuilder, TermError};

use mechanics::{
    AdaptiveParams, Controller, ModelParams, Precision, Schedule, Simulation, StepParams, Tissue,
};
use phasefield::{init, Cells, Lattice, PatchShape, Real};

/// A valid scene: only [`SceneFile::validate`] (or [`Scene::parse`]) makes one, so every
/// value in it has been checked, and building from it cannot fail.
#[derive(Debug, Clone)]
pub struct Scene {
    pub(crate) file: SceneFile,
    /// The initial centres, computed by the validation (which checks that they fit).
    pub(crate) centres: Vec<[f64; 2]>,
    /// The walls of `[walls]`, built once by the validation (their fields are shared).
    pub(crate) walls: Option<mechanics::walls::Walls>,
    /// The terms of the `[terms.NAME]` tables, built once by the validation
    /// ([`register_term`]).
    pub(crate) user_terms: Vec<std::sync::Arc<dyn mechanics::terms::CellTerm>>,
    /// The `[terms.NAME]` tables whose terms this program does not register, kept for reading
    /// ([`SceneFile::validate_for_reading`]; empty after [`Scene::parse`]).
    pub(crate) unbuilt: Vec<String>,
}

/// When the writers of a run directory fire, and what frames carry
/// ([`Scene::output_schedules`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct OutputSchedules {
    /// Frames.
    pub frames: Schedule,
    /// Rows of `series.csv`.
    pub series: Schedule,
    /// Checkpoints (besides the wall-time ones and the one at the end).
    pub checkpoints: Schedule,
    /// Whether frames carry each cell's force by origin (`[run] forces_by_origin`).
    pub forces_by_origin: bool,
}

/// A scene's durations in steps (with the adaptive step, estimates from its first step).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct StepCounts {
    /// Relaxation steps at ζ = 0.
    pub relax_steps: u64,
    /// Active steps.
    pub active_steps: u64,
    /// Steps between frames.
    pub frame_every: u64,
    /// Steps between series rows.
    pub series_every: u64,
    /// Steps between checkpoints.
    pub checkpoint_every: u64,
}

impl StepCounts {
    /// All steps of the run.
    pub fn total_steps(&self) -> u64 {
        self.relax_steps + self.active_steps
    }
}

impl Scene {
    /// Parses and validates a scene from TOML text, applying `--set section.key=value`
    /// overrides first.
    ///
    /// # Errors
    /// [`SceneError::Parse`] on bad syntax, unknown keys, wrong types or bad overrides, and
    /// [`SceneError::Invalid`] for the first bad value.
    pub fn parse(text: &str, overrides: &[String]) -> Result<Self, SceneError> {
        SceneFile::parse(text, overrides)?.validate()
    }

    /// The scene's values, every default filled in.
    pub fn file(&self) -> &SceneFile {
        &self.file
    }

    /// The scene as TOML, with every default filled in: parsing it gives this scene again.
    pub fn to_toml(&self) -> String {
        self.file.to_toml()
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        Lattice::new(self.file.domain.lx, self.file.domain.ly)
    }

    /// The patch shape.
    pub fn patch_shape(&self) -> PatchShape {
        PatchShape::new(self.lattice(), self.file.integrator.margin).expect("validated")
    }

    /// An estimate of the memory a run of this scene needs at its peak, in bytes, computed
    /// from the scene alone (nothing is allocated): with `N` cells (with `[division]`, its
    /// `max_cells`, [`Scene::max_cells`]) of `p` patch nodes, `b`
    /// bytes per stored value (4 in f32, 8 in f64), `L` lattice nodes and `t` the threads this
    /// machine can run at once,
    ///
    /// `N p (4b + 16) + 64 L + 1024 N + t s + 16 MiB`:
    ///
    /// the fields and the three stage buffers of the step (`4b` per patch node), the f64 discs
    /// of the initial state or the f64 copy a frame is written from (`16`), the eight f64
    /// lattice fields of the step (five sums and the pressure) and of the flow (`64` per node;
    /// their stripe index is a few bytes per stripe), the
    /// per-cell state, each thread's copy of the patch it works on (`s`, about `56 p`:
    /// [`mechanics::thread_scratch_bytes`]), and the program itself. It bounds
    /// `Tissue::heap_bytes` + `Workspace::heap_bytes` from above (tested), so a scene it refuses
    /// could not have run.
    pub fn memory_estimate(&self) -> f64 {
        let n = self.max_cells() as f64;
        let shape = self.patch_shape();
        let p = (shape.nx * shape.ny) as f64;
        let b = match self.precision() {
            Precision::F32 => 4.0,
            Precision::F64 => 8.0,
        };
        let l = self.lattice().len() as f64;
        let threads = std::thread::available_parallelism().map_or(1, |t| t.get()) as f64;
        let scratch = threads * mechanics::thread_scratch_bytes(&shape) as f64;
        n * p * (4.0 * b + 16.0) + 64.0 * l + 1024.0 * n + scratch + 16.0 * 1024.0 * 1024.0
    }

    /// The storage precision of the fields.
    pub fn precision(&self) -> Precision {
        self.file.integrator.precision
    }

    /// Where the steps run (`[integrator] backend`).
    pub fn backend(&self) -> ComputeBackend {
        self.file.integrator.backend
    }

    /// The model parameters at activity `zeta`.
    pub fn model_params(&self, zeta: f64) -> ModelParams {
        self.file.model_params(zeta)
    }

    /// The integrator.
    pub fn step_params(&self) -> StepParams {
        self.file.step_params()
    }

    /// The activity after relaxation.
    pub fn zeta(&self) -> f64 {
        self.file.model.zeta
    }

    /// Steps for each phase and output interval (durations divided by dt, rounded).
    pub fn step_counts(&self) -> StepCounts {
        let dt = self.file.integrator.dt;
        let steps = |t: f64| (t / dt).round() as u64;
        let r = &self.file.run;
        let (relax_steps, active_steps) = (steps(r.relax_time), steps(r.time));
        StepCounts {
            relax_steps,
            active_steps,
            frame_every: steps(r.output_every).max(1),
            series_every: steps(r.series_every.unwrap_or(r.output_every)).max(1),
            checkpoint_every: match r.checkpoint_every {
                Some(c) => steps(c).max(1),
                None => (relax_steps + active_steps).div_ceil(20).max(1),
            },
        }
    }

    /// The settings of the adaptive time step (`[integrator] adaptive = true`), or `None` for
    /// fixed steps: the tolerance, the largest step (`dt_max`, by default the stability
    /// estimate) and the smallest, `(relax_time + time) / MAX_STEPS` (at least 1e-9), so that
    /// a run takes at most [`MAX_STEPS`] steps.
    pub fn adaptive(&self) -> Option<AdaptiveParams> {
        let it = &self.file.integrator;
        if !it.adaptive {
            return None;
        }
        let dt_max = it.dt_max.unwrap_or_else(|| self.file.stability_estimate());
        let mut p = AdaptiveParams::new(it.tolerance.unwrap_or(error::DEFAULT_TOLERANCE), dt_max);
        let r = &self.file.run;
        p.dt_min = ((r.relax_time + r.time) / MAX_STEPS).max(1e-9).min(dt_max);
        Some(p)
    }

    /// When the run directory's writers fire: frames, rows of `series.csv` and checkpoints
    /// every so many steps ([`Scene::step_counts`]), or with the adaptive step at their times
    /// (which the steps land on).
    pub fn output_schedules(&self) -> OutputSchedules {
        let r = &self.file.run;
        if self.file.integrator.adaptive {
            let total = r.relax_time + r.time;
            OutputSchedules {
                frames: Schedule::TimeInterval(r.output_every),
                series: Schedule::TimeInterval(r.series_every.unwrap_or(r.output_every)),
                checkpoints: Schedule::TimeInterval(
                    r.checkpoint_every.unwrap_or((total / 20.0).max(1e-6)),
                ),
                forces_by_origin: r.forces_by_origin,
            }
        } else {
            let c = self.step_counts();
            OutputSchedules {
                frames: Schedule::IterationInterval(c.frame_every),
                series: Schedule::IterationInterval(c.series_every),
                checkpoints: Schedule::IterationInterval(c.checkpoint_every),
                forces_by_origin: r.forces_by_origin,
            }
        }
    }

    /// The model time at the end of the run, `relax_time + time`.
    pub fn end_time(&self) -> f64 {
        let r = &self.file.run;
        r.relax_time + r.time
    }

    /// Warnings about the scene: a time step above the stability estimate, allowed by
    /// `[integrator] stability_check = false`.
    pub fn warnings(&self) -> Vec<String> {
        self.file
            .dt_above_estimate()
            .map(|dt_max| {
                let it = &self.file.integrator;
                let (key, v) = match it.dt_max {
                    Some(v) if it.adaptive => ("dt_max", v),
                    _ => ("dt", it.dt),
                };
                format!(
                    "[integrator] {key} = {v} is above the stability estimate {}; the run stops if it blows up",
                    error::sig3(dt_max)
                )
            })
            .into_iter()
            .collect()
    }

    /// The saved state the scene starts from (`[cells] from`, with `init = "frame"`), as
    /// the scene gives it; `None` for the other layouts.
    pub fn init_from(&self) -> Option<&str> {
        match self.file.cells.init {
            InitKind::Frame => self.file.cells.from.as_deref(),
            _ => None,
        }
    }

    /// The activity at step 0: ζ = 0 when there is a relaxation phase.
    fn initial_params(&self) -> ModelParams {
        let zeta = if self.step_counts().relax_steps > 0 {
            0.0
        } else {
            self.file.model.zeta
        };
        self.model_params(zeta)
    }

    /// The initial tissue (at ζ = 0 when there is a relaxation phase), with its fields stored
    /// in precision `T`: the initial discs are computed in `f64` and rounded once.
    ///
    /// # Errors
    /// [`SceneError::State`] for a scene that starts from a saved state (`init = "frame"`):
    /// read the state and use [`Scene::tissue_from_state`] (`rundir::initial_tissue` does
    /// both).
    pub fn tissue<T: Real>(&self) -> Result<Tissue<T>, SceneError> {
        self.check_built()?;
        if let Some(from) = self.init_from() {
            return Err(SceneError::State {
                from: from.to_string(),
                problem: "the scene starts from a saved state, which has not been read".into(),
                fix: "read it and build the tissue with Scene::tissue_from_state (rundir::initial_tissue does both)".into(),
            });
        }
        let f = &self.file;
        let cells = init::discs(
            self.lattice(),
            self.patch_shape(),
            &self.centres,
            f.init_radius(),
            f.model.lambda,
        );
        Ok(self.dressed(Tissue::new(
            cells.into_precision::<T>(),
            self.initial_params(),
        )))
    }

    /// `tissue` with the scene's extensions ([`Scene::extensions`]).
    fn dressed<T: Real>(&self, tissue: Tissue<T>) -> Tissue<T> {
        let ext = self.extensions(&tissue);
        tissue.with_extensions(ext)
    }

    /// Every extension the scene configures, before there is a tissue: the clock has no
    /// founders yet. What the parts are ([`Scene::parts`]) and which arrays they write follow
    /// from it; a run uses [`Scene::extensions`].
    pub fn configured_extensions(&self) -> mechanics::Extensions {
        mechanics::Extensions::none()
            .with(self.terms())
            .with(self.file.populations())
            .with(self.walls())
            .with(self.file.friction.as_ref().map(|f| f.friction()))
            .with(self.file.division.as_ref().map(|spec| {
                let (t0, rate) = spec.cycle();
                let clock =
                    mechanics::division::Proliferation::restore(t0, rate, self.file.run.seed, [])
                        .expect("an empty lineage has no cell twice");
                division::configure(clock, spec, &self.file)
            }))
    }

    /// The parts beyond the paper's model the scene has, in [`mechanics::Part::ALL`]'s
    /// order (what a backend must support to run it).
    pub fn parts(&self) -> Vec<mechanics::Part> {
        self.configured_extensions()
            .parts(&self.model_params(self.zeta()))
    }

    /// Every extension of the paper's model the scene configures, for `tissue` (its
    /// founders start the cell-cycle clock): the terms, the populations, the walls and the
    /// clock, as [`mechanics::Extensions`]. The one place a scene's extensions are built, for
    /// a new run and for a checkpoint's (whose state arrays then replace the parts' state,
    /// [`mechanics::Extensions::restore_arrays`]).
    pub fn extensions<T: Real>(&self, tissue: &Tissue<T>) -> mechanics::Extensions {
        self.configured_extensions().with(
            self.file
                .division
                .as_ref()
                .map(|spec| division::clock(spec, &self.file, tissue)),
        )
    }

    /// The most cells the run can hold: `[division] max_cells` (or its default) with
    /// `[division]`, else `[cells] count`.
    pub fn max_cells(&self) -> usize {
        match &self.file.division {
            Some(d) => d
                .max_cells
                .unwrap_or_else(|| division::default_max_cells(&self.file)),
            None => self.file.cells.count,
        }
    }

    /// The walls of `[walls]`, if any (a clone that shares the scene's wall fields).
    pub fn walls(&self) -> Option<mechanics::walls::Walls> {
        self.walls.clone()
    }

    /// The wall field during the relaxation and after it (none: no walls then), for outputs.
    pub fn wall_fields(&self) -> Option<(&phasefield::WallField, Option<&phasefield::WallField>)> {
        self.walls.as_ref().map(|w| {
            let during = w
                .field(false)
                .expect("walls have a field during the relaxation");
            (during, w.field(true))
        })
    }

    /// The `[terms.NAME]` tables whose terms this program does not register: a scene read for
    /// reading only ([`SceneFile::validate_for_reading`]) keeps them, and cannot be stepped.
    pub fn unbuilt_terms(&self) -> &[String] {
        &self.unbuilt
    }

    /// Refuses to build a tissue of a scene with an unregistered term, with the error
    /// [`Scene::parse`] gives for it.
    fn check_built(&self) -> Result<(), SceneError> {
        match self.unbuilt.first() {
            Some(name) => match registry::build(name, &self.file.user_terms[name]) {
                Err(e) => Err(e),
                // Registered since: parse the scene again to build it.
                Ok(_) => Err(SceneError::Term {
                    name: name.clone(),
                    key: String::new(),
                    problem: "the scene was read for reading only, before the term was registered"
                        .into(),
                    fix: "parse the scene again (Scene::parse) to step it".into(),
                }),
            },
            None => Ok(()),
        }
    }

    /// The populations of `[[population]]` (empty without), cells dealt by `[run] seed`.
    pub fn populations(&self) -> mechanics::terms::Populations {
        self.file.populations()
    }

    /// The physics terms beyond the minimal model (`[polarity]`, `[nematic]`), with the run's seed.
    pub fn terms(&self) -> mechanics::terms::Terms {
        let mut terms = self.file.terms();
        for term in &self.user_terms {
            terms.add(term.clone());
        }
        terms
    }

    /// The initial tissue from a saved state `state` (the fields of a frame or a checkpoint,
    /// cells in identity order, on any patch size): each cell's field is copied node for node
    /// onto a patch of the scene's margin centred on the cell's centre of mass (what lies
    /// outside the saved patch is zero, what lies outside the new one is dropped), rounded
    /// once to `T`. The clock starts at 0 with the scene's parameters; the cells' shapes,
    /// positions and identities are the state's.
    ///
    /// # Errors
    /// [`SceneError::State`] when the state's lattice or cell count is not the scene's.
    pub fn tissue_from_state<T: Real>(&self, state: &Cells<f64>) -> Result<Tissue<T>, SceneError> {
        self.check_built()?;
        self.check_state(state)?;
        let ids = (0..state.n_cells()).collect();
        let placed = Tissue::from_state(state.clone(), self.initial_params(), 0.0, 0, ids);
        let cells = state.resampled(self.patch_shape(), placed.centres());
        Ok(self.dressed(Tissue::new(
            cells.into_precision::<T>(),
            self.initial_params(),
        )))
    }

    /// Checks that a saved state fits the scene: the same lattice and the same number of
    /// cells (the patch size and precision may differ), every cell with an interior (its
    /// field reaching ½), and none in the solid of the scene's walls (more than half of its
    /// field there).
    ///
    /// # Errors
    /// [`SceneError::State`] naming what differs and the key to change.
    pub fn check_state(&self, state: &Cells<f64>) -> Result<(), SceneError> {
        let from = self.file.cells.from.clone().unwrap_or_default();
        let (l, sl) = (self.lattice(), state.lattice());
        if (l.lx, l.ly) != (sl.lx, sl.ly) {
            return Err(SceneError::State {
                from,
                problem: format!(
                    "the state is on a {}×{} lattice, the scene's [domain] is {}×{}",
                    sl.lx, sl.ly, l.lx, l.ly
                ),
                fix: format!(
                    "set [domain] lx = {}, ly = {} (a state cannot be moved to another lattice)",
                    sl.lx, sl.ly
                ),
            });
        }
        let n = self.file.cells.count;
        if state.n_cells() != n {
            return Err(SceneError::State {
                from,
                problem: format!(
                    "the state holds {} cells, the scene's [cells] count is {n}",
                    state.n_cells()
                ),
                fix: format!("set [cells] count = {}", state.n_cells()),
            });
        }
        // Each cell has an interior (a field zeroed by an edit of the frame has none, and its
        // shape index would be NaN in every table).
        let shape = state.shape();
        for i in 0..n {
            let max = state
                .cell_phi(i)
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            if max.is_nan() || max < 0.5 {
                return Err(SceneError::State {
                    from,
                    problem: format!(
                        "cell {i} of the state has no interior: its field never reaches ½ (max φ = {max:.3})"
                    ),
                    fix: format!(
                        "remove cell {i} from the state's arrays (and lower [cells] count by one), or restore its field"
                    ),
                });
            }
        }
        // No cell inside the walls: the wall's repulsion would crush it without a word.
        if let Some(walls) = self.walls() {
            let active = self.file.run.relax_time <= 0.0;
            if let Some(field) = walls.field(active) {
                let map = state.map();
                for i in 0..n {
                    let (xs, ys) = (map.cell_x(shape, i), map.cell_y(shape, i));
                    let (mut total, mut solid) = (0.0, 0.0);
                    for (a, &x) in xs.iter().enumerate() {
                        for (b, &y) in ys.iter().enumerate() {
                            let v = state.cell_phi(i)[a * shape.ny + b].max(0.0);
                            total += v;
                            if field.is_solid(x as usize * l.ly + y as usize) {
                                solid += v;
                            }
                        }
                    }
                    if solid > 0.5 * total {
                        return Err(SceneError::State {
                            from,
                            problem: format!(
                                "cell {i} of the state lies in the solid of [walls] ({:.0} % of its field), where the walls would crush it",
                                100.0 * solid / total
                            ),
                            fix: "remove the cell from the state's arrays (and lower [cells] count by one), or change [walls] so that it lies in the open".into(),
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// A simulation of the scene with fields stored in precision `T` (choose it from
    /// [`Scene::precision`]): the initial tissue, the integrator, ζ = 0 for `relax_time` and
    /// the scene's ζ after, stopping after `relax_time + time`. Add callbacks and writers,
    /// then [`Simulation::run`] it.
    ///
    /// # Errors
    /// As [`Scene::tissue`]: a scene that starts from a saved state needs
    /// [`Scene::simulation_from`].
    pub fn simulation<T: Real>(&self) -> Result<Simulation<T>, SceneError> {
        Ok(self.simulation_from(self.tissue::<T>()?))
    }

    /// A simulation of the scene from the initial tissue `tissue` (from [`Scene::tissue`] or
    /// [`Scene::tissue_from_state`]): the scene's integrator, ζ = 0 for `relax_time` and the
    /// scene's ζ after, stopping after `relax_time + time` counted from the tissue's step.
    ///
    /// With `[integrator] adaptive = true` the steps are error-controlled
    /// ([`Simulation::adaptive`], from `dt`), the activity switches on at `relax_time` and the
    /// run stops at `relax_time + time`, each landed on exactly.
    pub fn simulation_from<T: Real>(&self, tissue: Tissue<T>) -> Simulation<T> {
        let sim = Simulation::new(tissue, self.step_params());
        match self.adaptive() {
            Some(p) => sim
                .adaptive(p, Controller::new(self.file.integrator.dt))
                .activity_from_time(self.file.run.relax_time, self.zeta())
                .stop_time(self.end_time()),
            None => {
                let counts = self.step_counts();
                sim.activity_from(counts.relax_steps, self.zeta())
                    .stop_iteration(counts.total_steps())
            }
        }
    }
}

/// `Scene::parse(base, overrides)` must be refused with every string of `expect` in the
/// message (the key, the value, the fix): the one check of a bad value's refusal that the
/// scene's validation tests share (the command line's tests have its twin,
/// `crates/cli/tests/common`, which also checks the exit status and that nothing is written).
#[cfg(test)]
pub(crate) fn check_rejected(base: &str, overrides: &[&str], expect: &[&str]) {
    let set: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let e = match Scene::parse(base, &set) {
        Ok(_) => panic!("{overrides:?} must be refused"),
        Err(e) => e.to_string(),
    };
    for w in expect {
        assert!(e.contains(w), "{overrides:?}: {e:?} lacks {w:?}");
    }
}
