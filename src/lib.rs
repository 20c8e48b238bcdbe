//! The README of monolayer, whose Rust examples run as this crate's doc tests (from the
//! repository's root, where the README's paths start), and one crate that re-exports the
//! workspace's libraries for users who want a single dependency.
#![doc = include_str!("../README.md")]

pub use analysis;
#[cfg(feature = "gpu")]
pub use gpu;
pub use mechanics;
pub use phasefield;
#[cfg(feature = "render")]
pub use render;
#[cfg(feature = "reproduce")]
pub use reproduce;
pub use rundir;
pub use scene;
#[cfg(feature = "stability")]
pub use stability;
#[cfg(feature = "study")]
pub use study;

/// Everything a whole run needs, from a scene or by hand, in one `use monolayer::prelude::*;`:
/// the lattice, patches and initial states (`phasefield`), the model, its parameters, the
/// driver with its callbacks and fixes (`mechanics`), the physics terms and the trait a new
/// one implements (`mechanics::terms`), scenes (`scene`) and run directories (`rundir`).
pub mod prelude {
    pub use mechanics::prelude::*;
    pub use mechanics::terms::{
        Align, CellContext, CellTerm, NoiseKey, Polarity, Propulsion, Terms,
    };
    pub use mechanics::{
        AdaptiveParams, CellState, Controller, Fix, StateCheck, StepCheck, StepError, SumField,
    };
    pub use phasefield::{init, Cells, EnergyParams, Lattice, PatchShape, Real};
    pub use rundir::RunDir;
    pub use scene::Scene;
}
