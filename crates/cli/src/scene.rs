//! The scene file: one TOML document that describes a run completely.
//!
//! Parsing is in two steps (after ripgrep's low/high arguments): [`Scene`] mirrors the file
//! and rejects unknown keys; [`Scene::validate`] checks every value and names the key and the
//! fix of the first problem; [`Scene::build`] turns a valid scene into library objects.

use mechanics::{ModelParams, PressureKind, Protocol, StepParams, Tissue};
use phasefield::{init, EnergyParams, Lattice, PatchShape, Real};
use serde::{Deserialize, Serialize};

/// A problem with a scene, naming the key and the fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be parsed (syntax, unknown key, wrong type).
    #[error("{0}")]
    Parse(String),
    /// A value is out of range.
    #[error("[{section}] {key} = {value}: {problem}; {fix}")]
    Invalid {
        /// The TOML table.
        section: &'static str,
        /// The key in it.
        key: &'static str,
        /// The offending value, as written.
        value: String,
        /// What is wrong.
        problem: String,
        /// What to do.
        fix: String,
    },
}

fn invalid(
    section: &'static str,
    key: &'static str,
    value: impl ToString,
    problem: impl Into<String>,
    fix: impl Into<String>,
) -> SceneError {
    SceneError::Invalid {
        section,
        key,
        value: value.to_string(),
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// `[domain]`: the periodic lattice.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    /// Nodes along x.
    pub lx: usize,
    /// Nodes along y.
    pub ly: usize,
}

/// How the cells are placed initially.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InitKind {
    /// Uniformly random, reproducible from `[run] seed`, initial discs not overlapping.
    #[default]
    Random,
    /// A near-hexagonal packing.
    Hexagonal,
    /// The centres in `[cells] positions`.
    Positions,
}

/// `[cells]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellsSpec {
    /// Number of cells.
    pub count: usize,
    /// Target radius R (target area πR²; paper: 8).
    #[serde(default = "default_radius")]
    pub radius: f64,
    /// Initial layout.
    #[serde(default)]
    pub init: InitKind,
    /// Centres for `init = "positions"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub positions: Option<Vec<[f64; 2]>>,
    /// Radius of the initial discs (default R/2: cells start smaller than their target and
    /// grow during relaxation, MODEL.md §6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub init_radius: Option<f64>,
}

fn default_radius() -> f64 {
    8.0
}

/// `[model]`: the paper's parameters by default.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Model {
    /// Interface stiffness γ.
    pub gamma: f64,
    /// Area constraint μ.
    pub mu: f64,
    /// Interface width λ.
    pub lambda: f64,
    /// Repulsion κ.
    pub kappa: f64,
    /// Substrate friction ξ.
    pub xi: f64,
    /// Activity ζ after relaxation.
    pub zeta: f64,
    /// Pressure definition.
    pub pressure: PressureKind,
}

impl Default for Model {
    fn default() -> Self {
        let e = EnergyParams::paper();
        Self {
            gamma: e.gamma,
            mu: e.mu,
            lambda: e.lambda,
            kappa: e.kappa,
            xi: 2.0,
            zeta: 0.0,
            pressure: PressureKind::Paper,
        }
    }
}

/// `[integrator]`.
///
/// The defaults (margin 16, dt 0.5, Heun, f32 storage) come from the front of the
/// work–precision study (`docs/performance.md`): for less than the cost of the paper's margin
/// 12 and dt 0.2 they make the
/// centre-of-mass error after 20 TU 20× smaller (4.6e-4 against 1.0e-2 nodes), because at
/// margin 12 the neglected patch tail dominates every time-step error. dt 0.5 is stable with
/// a factor 8 to spare at the paper's parameters and a factor 2 at ζ = 0.04
/// (`docs/stability.csv`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Integrator {
    /// Time step (default 0.5; the paper's scenes use 0.2).
    pub dt: f64,
    /// Heun corrector passes (1: predictor–corrector; 0: forward Euler).
    pub npc: usize,
    /// Patch margin m (patch side 2m+1; default 16, the paper's 12); 0 stores every cell on
    /// the full domain.
    pub margin: usize,
    /// Storage precision of the fields, `"f32"` (default) or `"f64"`. Arithmetic is always
    /// `f64`; `"f32"` rounds each stored value, which halves the memory the step moves and
    /// makes it up to 18 % faster. At the default margin and dt its error is that of `"f64"`
    /// to two digits after 20 TU and to five in the long-run statistics (work–precision
    /// study, `docs/performance.md`); it adds a floor of about 1e-6 in the centres and 1e-5
    /// in φ, so use `"f64"` for runs that aim below that (margin ≥ 20 with dt ≤ 0.1, or the
    /// full domain).
    pub precision: Precision,
    /// Refuse a `dt` above the stability estimate (default true). The estimate is 1.1–3.3×
    /// below the measured limits (`docs/stability.csv`); with `false` a run may go above it,
    /// and the step check still stops it, with its output kept, if it blows up.
    pub stability_check: bool,
}

/// Storage precision of the phase fields (`[integrator] precision`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// Double precision (the reference).
    F64,
    /// Single-precision storage, double-precision arithmetic (the default).
    #[default]
    F32,
}

impl Default for Integrator {
    fn default() -> Self {
        Self {
            dt: 0.5,
            npc: 1,
            margin: 16,
            precision: Precision::F32,
            stability_check: true,
        }
    }
}

/// `[run]`: times in model time units.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Run {
    /// Relaxation at ζ = 0 before the activity is switched on.
    pub relax_time: f64,
    /// Active time after relaxation.
    pub time: f64,
    /// Seed of the random initial positions.
    pub seed: u64,
    /// Interval between frames (full fields).
    pub output_every: f64,
    /// Interval between rows of `series.csv` (default: `output_every`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub series_every: Option<f64>,
}

impl Default for Run {
    fn default() -> Self {
        Self {
            relax_time: 0.0,
            time: 100.0,
            seed: 1,
            output_every: 10.0,
            series_every: None,
        }
    }
}

/// A whole scene file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// `[domain]`.
    pub domain: Domain,
    /// `[cells]`.
    pub cells: CellsSpec,
    /// `[model]`.
    #[serde(default)]
    pub model: Model,
    /// `[integrator]`.
    #[serde(default)]
    pub integrator: Integrator,
    /// `[run]`.
    #[serde(default)]
    pub run: Run,
}

/// Steps between re-sortings of the cells in memory (see `mechanics::Tissue::sort_cells`).
pub const SORT_EVERY: u64 = 250;

/// The number of steps for a duration, and the steps between outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Schedule {
    /// Relaxation steps at ζ = 0.
    pub relax_steps: u64,
    /// Active steps.
    pub active_steps: u64,
    /// Steps between frames.
    pub frame_every: u64,
    /// Steps between series rows.
    pub series_every: u64,
}

impl Scene {
    /// Parses a scene from TOML text, applying `--set section.key=value` overrides first.
    ///
    /// # Errors
    /// [`SceneError::Parse`] on bad syntax, unknown keys, wrong types or bad overrides.
    pub fn parse(text: &str, overrides: &[String]) -> Result<Self, SceneError> {
        let mut table: toml::Table =
            toml::from_str(text).map_err(|e| SceneError::Parse(e.to_string()))?;
        for o in overrides {
            apply_override(&mut table, o)?;
        }
        let scene: Scene = table
            .try_into()
            .map_err(|e: toml::de::Error| SceneError::Parse(e.to_string()))?;
        Ok(scene)
    }

    /// The scene as TOML, with every default filled in.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("scenes always serialise")
    }

    /// Radius of the initial discs.
    pub fn init_radius(&self) -> f64 {
        self.cells.init_radius.unwrap_or(0.5 * self.cells.radius)
    }

    /// The model parameters at activity `zeta`.
    pub fn model_params(&self, zeta: f64) -> ModelParams {
        let m = &self.model;
        ModelParams {
            energy: EnergyParams {
                gamma: m.gamma,
                mu: m.mu,
                lambda: m.lambda,
                kappa: m.kappa,
                radius: self.cells.radius,
            },
            xi: m.xi,
            zeta,
            pressure: m.pressure,
        }
    }

    /// The integrator parameters.
    pub fn step_params(&self) -> StepParams {
        StepParams {
            dt: self.integrator.dt,
            npc: self.integrator.npc,
        }
    }

    /// Steps for each phase and output interval.
    pub fn schedule(&self) -> Schedule {
        let dt = self.integrator.dt;
        let steps = |t: f64| (t / dt).round() as u64;
        Schedule {
            relax_steps: steps(self.run.relax_time),
            active_steps: steps(self.run.time),
            frame_every: steps(self.run.output_every).max(1),
            series_every: steps(self.run.series_every.unwrap_or(self.run.output_every)).max(1),
        }
    }

    /// The run protocol: relaxation, activity, integrator.
    pub fn protocol(&self) -> Protocol {
        let sched = self.schedule();
        Protocol {
            relax_steps: sched.relax_steps,
            active_steps: sched.active_steps,
            zeta: self.model.zeta,
            step: self.step_params(),
            sort_every: Some(SORT_EVERY),
        }
    }

    /// Checks every value; the error names the first bad key and how to fix it.
    ///
    /// # Errors
    /// [`SceneError::Invalid`] for the first problem found.
    pub fn validate(&self) -> Result<(), SceneError> {
        let d = &self.domain;
        for (key, v) in [("lx", d.lx), ("ly", d.ly)] {
            if v < 8 {
                return Err(invalid(
                    "domain",
                    key,
                    v,
                    "the domain is too small",
                    "use at least 8 nodes per side (the paper uses 100)",
                ));
            }
        }
        let c = &self.cells;
        if c.count == 0 {
            return Err(invalid(
                "cells",
                "count",
                0,
                "a scene needs at least one cell",
                "set count to 1 or more",
            ));
        }
        if !(c.radius.is_finite() && c.radius > 0.0) {
            return Err(invalid(
                "cells",
                "radius",
                c.radius,
                "the radius must be positive",
                "use a radius of a few nodes (paper: 8)",
            ));
        }
        let r0 = self.init_radius();
        if !(r0.is_finite() && r0 > 0.0 && r0 <= c.radius) {
            return Err(invalid(
                "cells",
                "init_radius",
                r0,
                "the initial disc radius must be positive and at most the radius",
                "leave it out (default R/2) or choose a value in (0, radius]",
            ));
        }
        match (c.init, &c.positions) {
            (InitKind::Positions, None) => {
                return Err(invalid(
                    "cells",
                    "init",
                    "\"positions\"",
                    "no positions are given",
                    "add positions = [[x, y], ...] with one pair per cell",
                ));
            }
            (InitKind::Random | InitKind::Hexagonal, Some(_)) => {
                return Err(invalid(
                    "cells",
                    "positions",
                    "[...]",
                    "positions are only read with init = \"positions\"",
                    "set init = \"positions\" or remove positions",
                ));
            }
            _ => {}
        }
        let m = &self.model;
        for (key, v) in [("gamma", m.gamma), ("mu", m.mu), ("kappa", m.kappa)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(
                    "model",
                    key,
                    v,
                    "must be zero or positive",
                    "use the paper's value (gamma 0.01, mu 3, kappa 0.1) as a start",
                ));
            }
        }
        if !(m.lambda.is_finite() && m.lambda > 0.0) {
            return Err(invalid(
                "model",
                "lambda",
                m.lambda,
                "the interface width must be positive",
                "use a width of a few nodes (paper: 2.5)",
            ));
        }
        if !(m.xi.is_finite() && m.xi > 0.0) {
            return Err(invalid(
                "model",
                "xi",
                m.xi,
                "the friction must be positive",
                "use the paper's value 2",
            ));
        }
        if !m.zeta.is_finite() {
            return Err(invalid(
                "model",
                "zeta",
                m.zeta,
                "the activity must be a finite number",
                "use a value between -0.01 and 0.01",
            ));
        }
        let it = &self.integrator;
        if !(it.dt.is_finite() && it.dt > 0.0) {
            return Err(invalid(
                "integrator",
                "dt",
                it.dt,
                "the time step must be positive",
                "use the paper's 0.2",
            ));
        }
        if let Some(dt_max) = self.dt_above_estimate().filter(|_| it.stability_check) {
            return Err(invalid("integrator", "dt", it.dt, format!("the explicit scheme is unstable above dt ≈ {dt_max:.3} for these parameters (a conservative estimate; docs/stability.csv)"), format!("use dt ≤ {dt_max:.3} (the paper uses 0.2), or set [integrator] stability_check = false to run above the estimate at your own risk")));
        }
        if it.npc > 16 {
            return Err(invalid(
                "integrator",
                "npc",
                it.npc,
                "more than 16 corrector passes buy no accuracy",
                "use 1 (Heun) or 0 (Euler)",
            ));
        }
        if it.margin != 0 && (it.margin as f64) < c.radius {
            return Err(invalid(
                "integrator",
                "margin",
                it.margin,
                format!(
                    "a patch margin smaller than the cell radius {} cuts the cells",
                    c.radius
                ),
                format!(
                    "use margin ≥ radius + 2λ ≈ {}, the paper's 12, or 0 for the full domain",
                    (c.radius + 2.0 * m.lambda).ceil()
                ),
            ));
        }
        let lattice = Lattice::new(d.lx, d.ly);
        if let Err(e) = PatchShape::new(lattice, it.margin) {
            return Err(invalid(
                "integrator",
                "margin",
                it.margin,
                e.to_string(),
                "reduce the margin",
            ));
        }
        let r = &self.run;
        for (key, v) in [("relax_time", r.relax_time), ("time", r.time)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(
                    "run",
                    key,
                    v,
                    "times must be zero or positive",
                    "give the time in model units (paper: 0.2 per step)",
                ));
            }
        }
        for (key, v) in [
            ("output_every", Some(r.output_every)),
            ("series_every", r.series_every),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v >= it.dt) {
                    return Err(invalid(
                        "run",
                        key,
                        v,
                        format!("the interval must be at least one time step ({})", it.dt),
                        "use a multiple of dt",
                    ));
                }
            }
        }
        let layout = self.layout();
        if let Err(e) = init::positions(lattice, c.count, r0, &layout) {
            let key = if c.init == InitKind::Positions {
                "positions"
            } else {
                "count"
            };
            return Err(invalid(
                "cells",
                key,
                if key == "count" {
                    c.count.to_string()
                } else {
                    "[...]".into()
                },
                e.to_string(),
                "use fewer cells, smaller init_radius or a larger [domain]",
            ));
        }
        Ok(())
    }

    fn layout(&self) -> init::Layout {
        match self.cells.init {
            InitKind::Random => init::Layout::Random {
                seed: self.run.seed,
            },
            InitKind::Hexagonal => init::Layout::Hexagonal,
            InitKind::Positions => {
                init::Layout::Positions(self.cells.positions.clone().unwrap_or_default())
            }
        }
    }

    /// Warnings about a valid scene: a time step above the stability estimate, allowed by
    /// `[integrator] stability_check = false`.
    pub fn warnings(&self) -> Vec<String> {
        self.dt_above_estimate()
            .map(|dt_max| {
                format!(
                    "[integrator] dt = {} is above the stability estimate {dt_max:.3}; the run stops if it blows up",
                    self.integrator.dt
                )
            })
            .into_iter()
            .collect()
    }

    /// The stability estimate `ModelParams::max_stable_dt` of the active phase, when the
    /// scene's dt is above it.
    fn dt_above_estimate(&self) -> Option<f64> {
        let dt_max = self.model_params(self.model.zeta).max_stable_dt();
        (self.integrator.dt > dt_max).then_some(dt_max)
    }

    /// Builds the initial tissue (at ζ = 0 when there is a relaxation phase), stored in
    /// `f64` whatever the scene's precision (see [`Scene::build_in`]).
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub fn build(&self) -> Result<Tissue, SceneError> {
        self.build_in::<f64>()
    }

    /// Builds the initial tissue with its fields stored in precision `T`. The initial discs
    /// are computed in `f64` and rounded once.
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub fn build_in<T: Real>(&self) -> Result<Tissue<T>, SceneError> {
        self.validate()?;
        let lattice = Lattice::new(self.domain.lx, self.domain.ly);
        let shape = PatchShape::new(lattice, self.integrator.margin).expect("validated");
        let r0 = self.init_radius();
        let centres =
            init::positions(lattice, self.cells.count, r0, &self.layout()).expect("validated");
        let cells = init::discs(lattice, shape, &centres, r0, self.model.lambda);
        let zeta = if self.schedule().relax_steps > 0 {
            0.0
        } else {
            self.model.zeta
        };
        Ok(Tissue::new(
            cells.into_precision::<T>(),
            self.model_params(zeta),
        ))
    }
}

fn apply_override(table: &mut toml::Table, o: &str) -> Result<(), SceneError> {
    let bad = |why: &str| {
        SceneError::Parse(format!(
            "--set {o}: {why}; write --set section.key=value, e.g. --set model.zeta=0.005"
        ))
    };
    let (path, value) = o.split_once('=').ok_or_else(|| bad("no '='"))?;
    let (section, key) = path
        .trim()
        .split_once('.')
        .ok_or_else(|| bad("the key needs a section"))?;
    let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {}", value.trim())) {
        Ok(mut t) => t.remove("v").expect("parsed"),
        Err(_) => toml::Value::String(value.trim().to_string()),
    };
    let sec = table
        .entry(section.to_string())
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let toml::Value::Table(sec) = sec else {
        return Err(bad("that section is not a table"));
    };
    sec.insert(key.to_string(), value);
    Ok(())
}
