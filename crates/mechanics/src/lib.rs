//! # mechanics
//!
//! Turns a state of the multi-phase-field model (a [`phasefield::Cells`]) into forces and
//! advances it in time (MODEL.md §3–4; Mueller, Yeomans & Doostmohammadi, PRL 122, 048004, 2019).
//!
//! Principal types:
//! - [`ModelParams`] (with [`PressureKind`]) and [`StepParams`]: the physics and the integrator.
//! - [`Tissue`]: fields, parameters and clock; [`Tissue::step`] advances by one time step.
//! - [`Workspace`]: all scratch memory of a step, built once; the step allocates nothing.
//! - [`Observables`]: `v_rms`, `S_rms` and the area statistics of a state.
//! - [`run`] with a [`Protocol`] (relaxation, then activity) and an [`Observer`]: a whole run.
//!
//! The equations, as implemented:
//! - stress `σ = −P𝕀 − ζQ`, with `Q(x) = Σ_i φ_i(x) S_i`;
//! - force `F_i = Σ_x [P ∇φ_i + ζ Q·∇φ_i]`, velocity `v_i = F_i/ξ`;
//! - `∂_t φ_i = −v_i·∇φ_i − δF/δφ_i`, by Heun's predictor–corrector (or forward Euler).
//!
//! Every result is independent of the number of rayon threads, bit for bit: per-cell sums run
//! inside one task and lattice-wide sums add cells in index order ([`scatter`]).
//!
//! ```
//! use mechanics::{ModelParams, StepParams, Tissue, Workspace};
//! use phasefield::{init, Lattice, PatchShape};
//!
//! let lattice = Lattice::new(48, 48);
//! let shape = PatchShape::new(lattice, 12).unwrap();
//! let cells = init::discs(lattice, shape, &[[16.0, 24.0], [30.0, 24.0]], 7.0, 2.5);
//! let mut tissue = Tissue::new(cells, ModelParams::paper(0.0));
//! let mut ws = Workspace::new(&tissue.cells);
//! for _ in 0..10 {
//!     tissue.step(&mut ws, &StepParams { dt: 0.2, npc: 1 }).unwrap();
//! }
//! let o = tissue.observe(&mut ws);
//! assert!(o.area_mean > 100.0 && o.v_rms.is_finite());
//! ```
#![deny(missing_docs)]

mod fields;
mod observables;
mod params;
pub mod scatter;
mod simulation;
mod tissue;

pub use fields::TissueFields;
pub use observables::Observables;
pub use params::{ModelParams, PressureKind, StepParams, ACTIVITY_DT};
pub use simulation::{run, Observer, Protocol};
pub use tissue::{
    evaluate, pressure, CellState, Tissue, Workspace, G_QXX, G_QXY, G_S1, G_S2, G_U, N_GLOBAL,
    PHI_BOUND, SORT_BLOCK,
};

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
}
