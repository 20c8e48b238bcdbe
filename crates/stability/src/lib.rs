//! Linear stability of a monolayer's rest state (the `stability` floor of the layout: it sits
//! on `mechanics`, and `study` builds the `reproduce stability` figure on it).
//!
//! The random packings the paper starts from keep coarsening at ζ = 0, so their growth rate is
//! never a clean baseline. A hexagonal packing on a box commensurate with it ([`HexBox`]) relaxes
//! to a state whose cell speeds fall to a small residual ([`rest_state`]). About it, the
//! dynamics `x ↦ M(x)` of `n` time steps (`τ = n·dt`) has the Jacobian `J`, whose eigenvalues
//! `μ` give growth rates `σ = ln|μ|/τ`. The leading σ is measured in two independent ways:
//!
//! - [`growth_rate`]: a perturbation of norm `δ` integrated beside the base and renormalised
//!   after each application of `M` (power iteration in time); σ is the mean of
//!   `ln(|δ_k|/δ)/τ` once it has settled;
//! - [`arnoldi`]: Arnoldi iteration on `J v ≈ (M(x₀ + εv) − M(x₀))/ε`, with the Hessenberg
//!   eigenproblem solved by faer; it gives the leading eigenvalues and the leading mode.
//!
//! Both remove the two uniform translations of the whole tissue, which would be neutral on a
//! continuum; on the lattice they decay or grow slowly, and [`StepMap::translation_rates`]
//! measures them. The threshold ζ_cr is where the leading σ of the other modes crosses zero
//! ([`bisect`]).

#![warn(missing_docs)]

mod arnoldi;
mod bands;
mod bloch;
pub mod fit;
mod growth;
mod map;
mod rest;
#[cfg(test)]
mod tests;
mod threshold;

pub use arnoldi::{arnoldi, ArnoldiOptions, Ritz, Spectrum};
pub use bands::{lowest, refine_waves, wave_thresholds, WaveOptions, WavePoint, WaveThreshold};
pub use bloch::{box_wavevectors, repeat, BlochMap, BlochTiling};
pub use growth::{growth_rate, random_direction, settle, start_vector, Growth, GrowthOptions};
pub use map::{dot, max_change, norm, transfer, Operator, StepMap};
pub use rest::{rest_state, HexBox, Relaxation, RestState};
pub use threshold::{
    bisect, threshold, Bisection, Evaluation, Method, Threshold, ThresholdOptions, NARROWING_ROUNDS,
};

/// Why a stability computation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StabilityError {
    /// The packing or its patches do not fit.
    #[error("packing: {0}")]
    Packing(String),
    /// A time step failed.
    #[error("step: {0}")]
    Step(String),
    /// faer's eigensolver failed.
    #[error("eigenvalues of the Hessenberg matrix: {0}")]
    Eigen(String),
    /// σ has the same sign at both ends of the bracket.
    #[error("σ does not cross zero in ζ ∈ [{lo}, {hi}] (σ = {sigma_lo:.3e} and {sigma_hi:.3e}): widen the bracket")]
    NoCrossing {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
        /// σ at `lo`.
        sigma_lo: f64,
        /// σ at `hi`.
        sigma_hi: f64,
    },
}
