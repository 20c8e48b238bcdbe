//! Node terms: free-energy terms that act at the lattice nodes, inside the step's node loops,
//! one file each ([`adhesion`], [`walls`]). What a new one writes is the [`NodeTerm`] trait;
//! `kernels::evaluate` takes the terms of an evaluation as a list and never names one.
//!
//! A node term's functional derivative is linear in `φ_i`,
//!
//! ```text
//! δF_node/δφ_i = a(x) φ_i + b(x) + c ∇²φ_i,
//! ```
//!
//! with lattice fields `a`, `b` (the term fills them once per evaluation, after the lattice
//! sums are complete) and a constant `c`; it adds to the pressure the φ-weighted sum of that
//! derivative over the cells, as an interaction term: a single-cell part `k φ_i ∇²φ_i` that the
//! scatter adds to `U` (`equations::adhesion_pressure_cell_part` with `k`), and a lattice part
//! it adds to `P` itself. So the terms are dispatched once per evaluation, outside the loops:
//! the loops see only the summed coefficients (`a`, `b` gathered beside each patch, `c` and `k`
//! constants), the scatter and the force pass branch once on whether there are any, and with
//! none they are the paper's loops.
//!
//! Adding one: a file here with a type that implements [`NodeTerm`] (its formulas in
//! `crate::equations`), its place in `Tissue::node_terms` (`step.rs`), which builds the
//! evaluation's list from the tissue's parameters and extensions, and a scene table (as for any
//! term: ARCHITECTURE.md, "Adding a physics term").

pub(crate) mod adhesion;
pub(crate) mod walls;

pub(crate) use adhesion::Adhesion;
pub(crate) use walls::WallTerm;

use crate::evaluation::N_SUMS;
use crate::scatter::LatticeSums;

/// A free-energy term that acts at the nodes (module docs).
pub(crate) trait NodeTerm: Sync {
    /// `k` of its single-cell pressure part `k φ_i ∇²φ_i`, which the scatter adds to `U`
    /// (0: none).
    fn cell_pressure_coefficient(&self) -> f64 {
        0.0
    }

    /// `c` of its derivative's `c ∇²φ_i` (0: none).
    fn laplacian_coefficient(&self) -> f64 {
        0.0
    }

    /// Whether it needs the lattice scratch field (one value per node) between
    /// [`NodeTerm::add_pressure`] and [`NodeTerm::add_coefficients`].
    fn needs_scratch(&self) -> bool {
        false
    }

    /// Adds its lattice part of the pressure to `P` once the scatter has completed the sums,
    /// keeping in `scratch` what its coefficients need (adhesion: `∇²s1`).
    fn add_pressure(&self, sums: &mut LatticeSums<N_SUMS>, scratch: &mut [f64]);

    /// Adds its `a` and `b` to the lattice nodes `k0..k0 + a.len()` of `a` and `b`.
    fn add_coefficients(&self, scratch: &[f64], k0: usize, a: &mut [f64], b: &mut [f64]);
}
