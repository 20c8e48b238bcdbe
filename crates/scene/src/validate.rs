//! Validation of a [`SceneFile`] into a [`Scene`], once: the error names the key, the value,
//! what is wrong and how to fix it (ripgrep's `ConfigError`).

use phasefield::{init, Lattice, PatchShape};

use crate::file::{AlignKind, ComputeBackend, InitKind, SceneFile};
use crate::Scene;

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
    /// A saved state does not fit the scene (`init = "frame"`), or the scene was asked to
    /// build its tissue without the state it starts from.
    #[error("[cells] from = {from:?}: {problem}; {fix}")]
    State {
        /// The path of the saved state, as the scene gives it.
        from: String,
        /// What is wrong.
        problem: String,
        /// What to do.
        fix: String,
    },
}

/// The longest lattice side [`SceneFile::validate`] accepts.
pub const MAX_SIDE: usize = 65536;

/// The most steps a run may take (relaxation and activity together): 10⁹, days of wall time
/// for the smallest scenes, and far below where the step counter or the clock lose precision.
pub const MAX_STEPS: f64 = 1e9;

/// The adaptive step's tolerance when `[integrator] tolerance` is not given.
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// `v` with three significant digits, never rounded to 0.
pub(crate) fn sig3(v: f64) -> String {
    if v != 0.0 && !(0.01..1e4).contains(&v.abs()) {
        format!("{v:.2e}")
    } else {
        format!("{v:.3}")
    }
}

pub(crate) fn invalid(
    section: &'static str,
    key: &'static str,
    value: impl ToString,
    problem: impl Into<String>,
    fix: impl Into<String>,
) -> SceneError {
    SceneError::Invalid {
        section,
        key,
        value: readable(value.to_string()),
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// A number as a person reads it: `1e-300`, not three hundred zeros.
fn readable(v: String) -> String {
    match v.parse::<f64>() {
        Ok(x) if x != 0.0 && x.is_finite() && (x.abs() < 1e-4 || x.abs() >= 1e12) => {
            format!("{x:e}")
        }
        _ => v,
    }
}

impl SceneFile {
    /// What the GPU backend does not run, refused by key: the adaptive step, forward Euler,
    /// full-domain storage, f64 storage, and every section beyond the paper's model (named
    /// together, so one edit fixes them all).
    fn check_gpu(&self) -> Result<(), SceneError> {
        let it = &self.integrator;
        let gpu = |key, value: String, problem: &str, fix: &str| {
            invalid(
                "integrator",
                key,
                value,
                format!("the GPU backend {problem}"),
                format!("{fix}, or set backend = \"cpu\""),
            )
        };
        if it.adaptive {
            return Err(gpu("adaptive", "true".into(), "runs the fixed step only (its error estimate would need a second field on the device)", "set adaptive = false"));
        }
        if it.npc == 0 {
            return Err(gpu(
                "npc",
                "0".into(),
                "runs Heun's predictor–corrector, not forward Euler",
                "set npc = 1",
            ));
        }
        if it.margin == 0 {
            return Err(gpu(
                "margin",
                "0".into(),
                "stores every cell on a patch; the full domain is the CPU's reference setting",
                "set margin = 16 (or the paper's 12)",
            ));
        }
        if it.precision == mechanics::Precision::F64 {
            return Err(gpu(
                "precision",
                "\"f64\"".into(),
                "stores and computes in f32",
                "set precision = \"f32\"",
            ));
        }
        let mut sections = Vec::new();
        if self.polarity.is_some() {
            sections.push("[polarity]");
        }
        if self.adhesion.is_some() {
            sections.push("[adhesion]");
        }
        if !self.population.is_empty() {
            sections.push("[[population]]");
        }
        if self.walls.is_some() {
            sections.push("[walls]");
        }
        if self.division.is_some() {
            sections.push("[division]");
        }
        if !sections.is_empty() {
            return Err(gpu(
                "backend",
                "\"gpu\"".into(),
                &format!(
                    "runs the paper's minimal model only, and this scene has {}",
                    sections.join(", ")
                ),
                &format!("remove {} to run on the GPU", sections.join(", ")),
            ));
        }
        Ok(())
    }

    /// Checks every value once and returns the valid [`Scene`]; the error names the first bad
    /// key and how to fix it.
    ///
    /// # Errors
    /// [`SceneError::Invalid`] for the first problem found.
    pub fn validate(self) -> Result<Scene, SceneError> {
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
            if v > MAX_SIDE {
                return Err(invalid(
                    "domain",
                    key,
                    v,
                    format!("a side of more than {MAX_SIDE} nodes cannot be simulated (a {MAX_SIDE}² lattice alone takes tens of GB)"),
                    "use at most 65536 nodes per side (the paper uses 100; 3840 cells fit in 800²)",
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
        if c.radius.is_finite() && c.radius < 1.0 {
            return Err(invalid(
                "cells",
                "radius",
                c.radius,
                "a cell smaller than one node cannot be resolved",
                "use a radius of a few nodes (paper: 8)",
            ));
        }
        let r0 = self.init_radius();
        if c.init_radius.is_none() && r0 < 1.0 {
            return Err(invalid(
                "cells",
                "radius",
                c.radius,
                format!("the initial discs (radius R/2 = {r0} by default) must be at least one node wide"),
                "use a radius of 2 or more (paper: 8), or set init_radius = 1",
            ));
        }
        if !(r0.is_finite() && r0 >= 1.0 && r0 <= c.radius) {
            return Err(invalid(
                "cells",
                "init_radius",
                r0,
                "the initial disc radius must be at least one node (a smaller disc covers no node) and at most the radius",
                format!(
                    "leave it out (default R/2) or choose a value in [1, {}]",
                    c.radius
                ),
            ));
        }
        if let (InitKind::Positions, Some(p)) = (c.init, &c.positions) {
            if p.len() != c.count {
                return Err(invalid(
                    "cells",
                    "positions",
                    format!("[{} pairs]", p.len()),
                    format!("count = {} cells but {} positions", c.count, p.len()),
                    "give one [x, y] pair per cell, or set count to the number of positions",
                ));
            }
            // Two discs whose centres are closer than their radius start stacked: nothing
            // separates two identical fields at one place (the force between them is zero by
            // symmetry), so the run would go on with one cell on top of another.
            let periodic = Lattice::new(d.lx, d.ly);
            for i in 0..p.len() {
                for j in 0..i {
                    let dist = periodic.distance(p[i], p[j]);
                    if dist < r0 {
                        return Err(invalid(
                            "cells",
                            "positions",
                            format!("[..., {:?}, ..., {:?}, ...]", p[j], p[i]),
                            format!(
                                "cells {j} and {i} are {dist:.3} nodes apart (periodically), closer than the initial radius {r0}: they would start stacked"
                            ),
                            format!("place the centres at least {r0} apart (2R = {} for cells that just touch)", 2.0 * c.radius),
                        ));
                    }
                }
            }
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
            (InitKind::Random | InitKind::Hexagonal | InitKind::Frame, Some(_)) => {
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
        match (c.init, c.from.as_deref()) {
            (InitKind::Frame, None) => {
                return Err(invalid(
                    "cells",
                    "init",
                    "\"frame\"",
                    "no saved state is given",
                    "add from = \"RUN/frames/frame_STEP.npz\" (or a checkpoint, RUN/checkpoints/checkpoint_STEP.npz)",
                ));
            }
            (InitKind::Frame, Some(f)) if f.trim().is_empty() => {
                return Err(invalid(
                    "cells",
                    "from",
                    "\"\"",
                    "the path is empty",
                    "give the frame or checkpoint to start from, e.g. from = \"out/relaxed/frames/frame_00001000.npz\"",
                ));
            }
            (InitKind::Random | InitKind::Hexagonal | InitKind::Positions, Some(f)) => {
                return Err(invalid(
                    "cells",
                    "from",
                    format!("{f:?}"),
                    "a saved state is only read with init = \"frame\"",
                    "set init = \"frame\" or remove from",
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
        if !self.population.is_empty() {
            let total: usize = self.population.iter().map(|p| p.count).sum();
            if total != self.cells.count {
                return Err(invalid(
                    "population",
                    "count",
                    total,
                    format!(
                        "the populations' counts add up to {total}, but [cells] count = {}",
                        self.cells.count
                    ),
                    format!(
                        "make the counts add up to {}, or set [cells] count = {total}",
                        self.cells.count
                    ),
                ));
            }
            for (k, p) in self.population.iter().enumerate() {
                let which = format!("population {k} ({})", p.name(k));
                let checks: [(&'static str, Option<f64>, bool, &str); 8] = [
                    (
                        "gamma",
                        p.gamma,
                        p.gamma.is_none_or(|v| v.is_finite() && v >= 0.0),
                        "zero or positive (paper: 0.01)",
                    ),
                    (
                        "mu",
                        p.mu,
                        p.mu.is_none_or(|v| v.is_finite() && v >= 0.0),
                        "zero or positive (paper: 3)",
                    ),
                    (
                        "radius",
                        p.radius,
                        p.radius.is_none_or(|v| v.is_finite() && v >= 1.0),
                        "at least one node (paper: 8)",
                    ),
                    (
                        "xi",
                        p.xi,
                        p.xi.is_none_or(|v| v.is_finite() && v > 0.0),
                        "positive (paper: 2)",
                    ),
                    (
                        "zeta",
                        p.zeta,
                        p.zeta.is_none_or(f64::is_finite),
                        "a finite number, e.g. between -0.01 and 0.01",
                    ),
                    (
                        "alpha",
                        p.alpha,
                        p.alpha.is_none_or(f64::is_finite),
                        "a finite number, e.g. 0.04",
                    ),
                    (
                        "rotational_diffusion",
                        p.rotational_diffusion,
                        p.rotational_diffusion
                            .is_none_or(|v| v.is_finite() && v >= 0.0),
                        "zero or positive",
                    ),
                    (
                        "align_rate",
                        p.align_rate,
                        p.align_rate.is_none_or(|v| v.is_finite() && v >= 0.0),
                        "zero or positive",
                    ),
                ];
                for (key, value, ok, want) in checks {
                    if !ok {
                        return Err(invalid(
                            "population",
                            key,
                            value.unwrap_or(f64::NAN),
                            format!("in {which}, {key} must be {want}"),
                            format!(
                                "give {key} = a value {want}, or remove it to take the scene's"
                            ),
                        ));
                    }
                }
                if self.polarity.is_none() {
                    let polar = [
                        ("alpha", p.alpha),
                        ("rotational_diffusion", p.rotational_diffusion),
                        ("align_rate", p.align_rate),
                    ];
                    if let Some((key, Some(v))) = polar.into_iter().find(|(_, v)| v.is_some()) {
                        return Err(invalid(
                            "population",
                            key,
                            v,
                            format!("{which} sets a polarity parameter, but the scene has no [polarity]"),
                            "add a [polarity] table (alpha = 0 for cells that do not propel themselves), or remove the key",
                        ));
                    }
                }
            }
        }
        if let Some(a) = &self.adhesion {
            if !(a.omega.is_finite() && a.omega >= 0.0) {
                return Err(invalid(
                    "adhesion",
                    "omega",
                    a.omega,
                    "the adhesion strength must be zero or positive",
                    "use a value of order 0.01 (the reference code's cluster example), or remove [adhesion]",
                ));
            }
            // Two overlapping cells have the gradient energy λ(γ ± ω)|∇(φ1 ± φ2)|²/2: at ω ≥ γ
            // their difference costs nothing and a contact breaks into stripes of the lattice.
            let gamma = self
                .population
                .iter()
                .filter_map(|p| p.gamma)
                .fold(self.model.gamma, f64::min);
            if a.omega >= gamma {
                return Err(invalid(
                    "adhesion",
                    "omega",
                    a.omega,
                    format!("adhesion at or above the interface stiffness (gamma = {gamma}) makes the interface between two cells cost nothing, and contacts break into stripes at the lattice scale"),
                    format!("use omega below gamma, e.g. {}", gamma * 0.75),
                ));
            }
        }
        if let Some(p) = &self.polarity {
            if !p.alpha.is_finite() {
                return Err(invalid(
                    "polarity",
                    "alpha",
                    p.alpha,
                    "the propulsion force must be a finite number",
                    "use a force of order 0.01-0.1 (the reference code's examples use 0.04)",
                ));
            }
            if !(p.rotational_diffusion.is_finite() && p.rotational_diffusion >= 0.0) {
                return Err(invalid(
                    "polarity",
                    "rotational_diffusion",
                    p.rotational_diffusion,
                    "the rotational diffusion constant must be zero or positive",
                    "use D_r = 1/(persistence time), e.g. 4.5e-4 (the reference code's D-pol = 0.03 is D_r = D-pol^2/2)",
                ));
            }
            if !(p.align_rate.is_finite() && p.align_rate >= 0.0) {
                return Err(invalid(
                    "polarity",
                    "align_rate",
                    p.align_rate,
                    "the alignment rate must be zero or positive",
                    "use a rate of order 0.1 (the reference code's J-pol), or 0 for none",
                ));
            }
            if p.align_rate > 0.0 && p.align == AlignKind::None {
                return Err(invalid(
                    "polarity",
                    "align_rate",
                    p.align_rate,
                    "an alignment rate with align = \"none\" aligns to nothing",
                    "set align = \"velocity\", \"force\" or \"shape\", or remove align_rate",
                ));
            }
            if !(p.contact_inhibition.is_finite() && p.contact_inhibition >= 0.0) {
                return Err(invalid(
                    "polarity",
                    "contact_inhibition",
                    p.contact_inhibition,
                    "the contact inhibition must be zero or positive",
                    "use a value of order 1 (3 stalls a cell pressed with its own force to 5 %), or 0 for none",
                ));
            }
            if let Some(a) = p.angle.filter(|a| !a.is_finite()) {
                return Err(invalid(
                    "polarity",
                    "angle",
                    a,
                    "the initial angle must be a finite number",
                    "give it in radians (0 is along +x), or remove it for random angles",
                ));
            }
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
            if dt_max <= 0.0 {
                // γ = 0 with activity: nothing damps the advected interfaces at any dt.
                return Err(invalid("model", "gamma", m.gamma, format!("with zeta = {} and no line tension the explicit scheme is unstable at any dt (the activity limit of docs/stability.csv is proportional to gamma)", m.zeta), "use gamma > 0 (the paper uses 0.01), set zeta = 0, or set [integrator] stability_check = false to run at your own risk"));
            }
            if it.adaptive {
                return Err(invalid("integrator", "dt_max", it.dt_max.unwrap_or_default(), format!("the explicit scheme is unstable above dt ≈ {} for these parameters (a conservative estimate; docs/stability.csv), and the error estimate sees an instability only once it grows", sig3(dt_max)), format!("leave dt_max out (it is then {}) or set [integrator] stability_check = false to run above the estimate at your own risk", sig3(dt_max))));
            }
            return Err(invalid("integrator", "dt", it.dt, format!("the explicit scheme is unstable above dt ≈ {} for these parameters (a conservative estimate; docs/stability.csv)", sig3(dt_max)), format!("use dt ≤ {} (the paper uses 0.2), or set [integrator] stability_check = false to run above the estimate at your own risk", sig3(dt_max))));
        }
        if it.adaptive {
            let tolerance = it.tolerance.unwrap_or(DEFAULT_TOLERANCE);
            if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
                return Err(invalid(
                    "integrator",
                    "tolerance",
                    tolerance,
                    "the local error tolerance must lie between 0 and 1 (φ itself is of order 1)",
                    "use 1e-3 (about the default fixed step's error) or 1e-4 for more accuracy",
                ));
            }
            if let Some(v) = it.dt_max {
                if !(v.is_finite() && v > 0.0) {
                    return Err(invalid(
                        "integrator",
                        "dt_max",
                        v,
                        "the largest step must be positive",
                        "leave it out (the stability estimate) or give a positive step",
                    ));
                }
                // The fixed step's bound on the number of steps, for the largest adaptive one.
                let total = self.run.relax_time + self.run.time;
                if total / v > MAX_STEPS {
                    return Err(invalid(
                        "integrator",
                        "dt_max",
                        v,
                        format!(
                            "relax_time + time = {total} with steps of at most {} is more than the {MAX_STEPS:.0e} steps a run may take",
                            readable(v.to_string())
                        ),
                        format!(
                            "leave dt_max out (the stability estimate) or give at least {}",
                            sig3(total / MAX_STEPS)
                        ),
                    ));
                }
            }
            if it.npc != 1 {
                return Err(invalid(
                    "integrator",
                    "npc",
                    it.npc,
                    "the adaptive step is Heun with one corrector (its Euler predictor is the error estimate)",
                    "set npc = 1 or adaptive = false",
                ));
            }
        } else {
            for (key, v) in [("dt_max", it.dt_max), ("tolerance", it.tolerance)] {
                if let Some(v) = v {
                    return Err(invalid(
                        "integrator",
                        key,
                        v,
                        format!("{key} is only read with adaptive = true"),
                        format!("set adaptive = true or remove {key}"),
                    ));
                }
            }
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
        // A population's own radius needs the same room on the patch as the scene's.
        if it.margin != 0 {
            for (k, p) in self.population.iter().enumerate() {
                let r = p.radius.unwrap_or(c.radius);
                if (it.margin as f64) < r {
                    return Err(invalid(
                        "population",
                        "radius",
                        r,
                        format!(
                            "population {k} ({}) has radius {r}, more than the patch margin {} ([integrator] margin): its cells would be cut to the patch and end far below their target area",
                            p.name(k),
                            it.margin
                        ),
                        format!(
                            "set [integrator] margin ≥ radius + 2λ ≈ {}, or a radius of at most {} for this population",
                            (r + 2.0 * m.lambda).ceil(),
                            it.margin
                        ),
                    ));
                }
            }
        }
        if it.backend == ComputeBackend::Gpu {
            self.check_gpu()?;
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
        let steps = (r.relax_time + r.time) / it.dt;
        if steps > MAX_STEPS {
            let (key, v) = if r.relax_time > r.time {
                ("relax_time", r.relax_time)
            } else {
                ("time", r.time)
            };
            return Err(invalid(
                "run",
                key,
                v,
                format!(
                    "relax_time + time = {} at dt = {} is {steps:.3e} steps, more than the {MAX_STEPS:.0e} a run may take",
                    r.relax_time + r.time,
                    it.dt
                ),
                format!(
                    "shorten the run (at most {} TU at this dt) or raise [integrator] dt",
                    sig3(MAX_STEPS * it.dt)
                ),
            ));
        }
        for (key, v) in [
            ("output_every", Some(r.output_every)),
            ("series_every", r.series_every),
            ("checkpoint_every", r.checkpoint_every),
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
        if let Some(spec) = &self.division {
            crate::division::check(spec, &self)?;
        }
        if let Some(spec) = &self.walls {
            if spec.kind == crate::file::WallKind::Wound && self.run.relax_time <= 0.0 {
                return Err(invalid(
                    "run",
                    "relax_time",
                    self.run.relax_time,
                    "a wound ([walls] kind = \"wound\") is the band the cells relax beside, removed when the relaxation ends; with no relaxation it is removed before the first step, so the run would have no wound at all",
                    "set [run] relax_time > 0 (scenes/wound.toml uses 200), or remove [walls] for a run without a wound",
                ));
            }
        }
        let walls = match &self.walls {
            Some(spec) => Some(crate::walls::walls_of(
                spec,
                lattice,
                init::wall_clearance(r0),
            )?),
            None => None,
        };
        let Some(layout) = self.layout() else {
            // The state is read when the tissue is built (`Scene::tissue_from_state`).
            return Ok(Scene {
                file: self,
                centres: Vec::new(),
                walls,
            });
        };
        let centres = match init::positions_clear_of(
            lattice,
            c.count,
            r0,
            &layout,
            walls.as_ref().and_then(|w| w.field(false)),
        ) {
            Ok(centres) => centres,
            Err(e) => {
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
                    if walls.is_some() {
                        "use fewer cells, smaller init_radius, a larger [domain] or less wall (initial discs stay a disc radius and a node clear of the walls)"
                    } else {
                        "use fewer cells, smaller init_radius or a larger [domain]"
                    },
                ));
            }
        };
        Ok(Scene {
            file: self,
            centres,
            walls,
        })
    }

    /// The layout of the initial discs, or `None` when the scene starts from a saved state.
    fn layout(&self) -> Option<init::Layout> {
        Some(match self.cells.init {
            InitKind::Random => init::Layout::Random {
                seed: self.run.seed,
            },
            InitKind::Hexagonal => init::Layout::Hexagonal,
            InitKind::Positions => {
                init::Layout::Positions(self.cells.positions.clone().unwrap_or_default())
            }
            InitKind::Frame => return None,
        })
    }

    /// The stability estimate `ModelParams::max_stable_dt` of the active phase, when the
    /// scene's largest step is above it: `dt`, or with `adaptive` the given `dt_max` (the
    /// first step is cut to the estimate).
    pub(crate) fn dt_above_estimate(&self) -> Option<f64> {
        let dt_max = self.stability_estimate();
        let it = &self.integrator;
        let largest = if it.adaptive {
            it.dt_max.unwrap_or(0.0)
        } else {
            it.dt
        };
        (largest > dt_max).then_some(dt_max)
    }

    /// The stability estimate of the active phase.
    pub(crate) fn stability_estimate(&self) -> f64 {
        let base = self.model_params(self.model.zeta);
        // The smallest over the populations, each with its own constants.
        // A wall's repulsion relaxes φ at the rate (2κ_w/λ) w² ≤ 2κ_w/λ, which Heun's method
        // keeps stable for dt below λ/κ_w.
        let walls = self
            .walls
            .as_ref()
            .filter(|w| w.kappa > 0.0)
            .map_or(f64::INFINITY, |w| base.energy.lambda / w.kappa);
        self.population_kinds()
            .iter()
            .map(|p| p.params(&base).max_stable_dt())
            .fold(base.max_stable_dt().min(walls), f64::min)
    }
}
