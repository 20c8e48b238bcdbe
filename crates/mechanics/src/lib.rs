//! # mechanics
//!
//! Turns a state of the multi-phase-field model (a [`phasefield::Cells`]) into forces and
//! advances it in time (docs/model.md §3–4; Mueller, Yeomans & Doostmohammadi, PRL 122, 048004, 2019).
//!
//! Principal types:
//! - [`ModelParams`] (with [`PressureKind`]) and [`StepParams`]: the physics and the
//!   integrator, with documented defaults.
//! - [`Tissue`]: the model, fields, parameters and clock; [`Tissue::step`] advances it by
//!   one time step, [`Tissue::observe`] and [`Tissue::fields`] evaluate it without stepping.
//! - [`Workspace`]: all scratch memory of a step, built once; the step allocates nothing.
//! - [`Simulation`]: the driver, with stop criteria and scheduled [`Callback`]s and output
//!   writers ([`Schedule`], [`Observation`]).
//! - [`equations`]: each equation of docs/model.md §3–4 as one named function.
//! - [`Observables`], [`TissueFields`]: what a state looks like, as scalars or lattice fields;
//!   vectors are nalgebra [`Vector2`]s and `S_i`, `Q` are [`TracelessTensor`]s.
//!
//! The equations, as implemented (see [`equations`] for each, and the crate `phasefield` for
//! `δF/δφ_i`):
//! - deformation `S_i = −Σ_x [∇φ_i ∇φ_iᵀ − ½|∇φ_i|²𝕀]`, nematic field `Q(x) = Σ_i φ_i(x) S_i`;
//! - stress `σ = −P𝕀 − ζQ`, with the pressure `P` of [`equations::pressure`];
//! - force `F_i = Σ_x [(P − P_i^self) ∇φ_i + ζ Q·∇φ_i]`, velocity `v_i = F_i/ξ`;
//! - `∂_t φ_i = R_i = −v_i·∇φ_i − δF/δφ_i`, by Heun's predictor–corrector (or forward Euler).
//!
//! Every result is independent of the number of rayon threads, bit for bit: per-cell sums run
//! inside one task and lattice-wide sums add cells in index order.
//!
//! Stepping a tissue by hand, then its observables and fields:
//!
//! ```
//! use mechanics::prelude::*;
//! use phasefield::{init, Lattice, PatchShape};
//!
//! let lattice = Lattice::new(48, 48);
//! let shape = PatchShape::new(lattice, 12).unwrap();
//! let cells = init::discs(lattice, shape, &[[16.0, 24.0], [30.0, 24.0]], 7.0, 2.5);
//! let mut tissue = Tissue::new(cells, ModelParams::paper(0.005));
//! let mut ws = Workspace::new(tissue.cells());
//! for _ in 0..10 {
//!     tissue.step(&mut ws, &StepParams::paper()).unwrap();
//! }
//! let o = tissue.observe(&mut ws);
//! assert!(o.area_mean > 100.0 && o.v_rms.is_finite());
//! // The two cells repel: their velocities point apart along x.
//! let (v0, v1) = (ws.cell(0).velocity, ws.cell(1).velocity);
//! assert!(v0.x < 0.0 && v1.x > 0.0);
//! // The long axis of a cell from its deformation tensor.
//! let (_, axis) = ws.cell(0).shape.axis();
//! assert!((axis.norm() - 1.0).abs() < 1e-12);
//! // Lattice fields: pressure, Q, velocity and stress.
//! let f = tissue.fields(&mut ws);
//! assert_eq!(f.pressure.len(), 48 * 48);
//! ```
#![deny(missing_docs)]

pub mod adaptive;
pub mod backend;
mod clock;
pub mod division;
pub mod equations;
mod evaluation;
pub mod extensions;
mod fields;
pub mod friction;
mod geometry;
mod kernels;
mod nematic_fields;
mod node_terms;
mod observables;
mod origins;
mod params;
pub mod persist;
mod scatter;
mod scratch;
mod simulation;
mod step;
pub mod terms;
mod tissue;
pub mod walls;
mod workspace;

pub use adaptive::{AdaptiveParams, Controller};
pub use evaluation::{CellState, SumField};
pub use extensions::{ExtensionPart, Extensions, Part, Setting};
pub use fields::TissueFields;
pub use geometry::TracelessTensor;
pub use nalgebra::Vector2;
pub use observables::{CellObservables, Observables};
pub use origins::ForcesByOrigin;
pub use params::{ModelParams, Precision, PressureKind, StepParams, ACTIVITY_DT};
pub use scratch::thread_scratch_bytes;
pub use simulation::{
    Callback, CallbackError, Fix, Needs, Observation, RunInfo, Schedule, Simulation,
    SimulationError, DEFAULT_SORT_EVERY,
};
pub use step::{CheckPoint, StateCheck, StepCheck, PHI_BOUND};
pub use tissue::Tissue;
pub use workspace::Workspace;

/// The types most programs need: `use mechanics::prelude::*;`.
pub mod prelude {
    pub use crate::{
        Callback, CallbackError, Fix, ModelParams, Needs, Observables, Observation, Precision,
        PressureKind, Schedule, Simulation, StepParams, Tissue, TissueFields, TracelessTensor,
        Vector2, Workspace,
    };
}

/// Why a time step could not be taken.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StepError {
    /// A field or force became NaN or infinite.
    #[error("cell {cell_idx} became non-finite at step {step} (t = {time:.3}); the time step is too large or the parameters are unstable: reduce [integrator] dt")]
    NonFinite {
        /// Step at which it was found.
        step: u64,
        /// Model time at which it was found.
        time: f64,
        /// The first offending cell.
        cell_idx: usize,
    },
    /// A field left the band of values that stable runs stay in.
    #[error("cell {cell_idx} reached φ = {phi:.3} at step {step} (t = {time:.3}), outside [-{b}, {}]: the integration is blowing up; reduce [integrator] dt (now {dt}), e.g. to {}", 1.0 + PHI_BOUND, dt / 2.0, b = PHI_BOUND)]
    Unstable {
        /// Step at which it was found.
        step: u64,
        /// Model time at which it was found.
        time: f64,
        /// The first offending cell.
        cell_idx: usize,
        /// The offending value.
        phi: f64,
        /// The time step in use.
        dt: f64,
    },
    /// The adaptive step cannot meet its tolerance with a step of at least its minimum.
    #[error("at step {step} (t = {time:.3}) the adaptive time step fell to {dt:.2e}, below its minimum, to keep the local error under {tolerance:.1e}: the flow is too fast for the tolerance or the run is blowing up; raise [integrator] tolerance or lower dt_max")]
    StepTooSmall {
        /// Step at which it happened.
        step: u64,
        /// Model time at which it happened.
        time: f64,
        /// The step the controller asked for.
        dt: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// A physics term's state relaxes too fast for the time step (its stiffness `k` with
    /// `k·dt > 2`, where Heun's step is unstable): the polarity's alignment rate, say.
    #[error("at step {step} (t = {time:.3}) the {term} term of cell {cell} relaxes its state at a rate {stiffness:.3e} per time unit, and the step dt = {dt} is unstable above 2/dt = {limit:.3e}: lower the term's rate (for the built-in polarity and nematic, [{term}] align_rate, or the population's) by {factor:.1}× or more, or [integrator] dt", limit = 2.0 / dt, factor = stiffness * dt / 2.0)]
    TermUnstable {
        /// Step at which it was found.
        step: u64,
        /// Model time at which it was found.
        time: f64,
        /// The term's name.
        term: String,
        /// The identity of the stiffest cell.
        cell: usize,
        /// Its stiffness (per time unit).
        stiffness: f64,
        /// The time step.
        dt: f64,
    },
    /// The device of a [`backend::Backend`] failed or cannot run what was asked.
    #[error("the {backend} backend: {message}")]
    Backend {
        /// The backend's name.
        backend: String,
        /// What went wrong, with what to do.
        message: String,
    },
}
