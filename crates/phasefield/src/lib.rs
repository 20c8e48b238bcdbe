//! # phasefield
//!
//! The lattice-level foundation of the multi-phase-field model of Mueller, Yeomans &
//! Doostmohammadi, *Emergence of active nematic behaviour in monolayers of isotropic cells*,
//! PRL 122, 048004 (2019).
//!
//! Principal types:
//! - [`Lattice`]: the periodic `lx × ly` lattice; node `(x, y)` has index `x * ly + y`.
//! - [`PatchShape`] and [`Cells`]: every cell's field `φ_i` on a periodic patch of side
//!   `2m + 1` that follows its centre of mass (or on the whole lattice, the full-domain
//!   reference), all cells in one contiguous buffer, stored as `f64` or `f32` ([`Real`]).
//! - [`EnergyParams`]: the free energy and its three functional derivatives.
//! - [`ComTable`]: centre of mass by Fourier phase.
//! - [`init`]: random, hexagonal or given initial positions, and tanh discs.
//!
//! This crate knows nothing about forces, velocities or time stepping (see `mechanics`).
//!
//! ```
//! use phasefield::{init, ComTable, EnergyParams, Lattice, PatchShape};
//!
//! let lattice = Lattice::new(64, 64);
//! let shape = PatchShape::new(lattice, 12).unwrap();
//! let cells = init::discs(lattice, shape, &[[63.5, 10.0]], 6.0, 2.5);
//! let com = ComTable::new(lattice);
//! let c = com.cell_centre(&cells, 0);
//! assert!((c[1] - 10.0).abs() < 1e-9);
//! let f = EnergyParams::paper().free_energy(&cells);
//! assert!(f.is_finite());
//! ```
#![deny(missing_docs)]

mod cells;
mod com;
mod energy;
pub mod init;
mod lattice;
mod padded;
mod real;
mod runs;
mod shape;
mod stencil;
pub mod walls;

pub use cells::{Cells, PatchMap};
pub use com::ComTable;
pub use energy::{EnergyCoefficients, EnergyParams};
pub use lattice::{min_image, wrap_real, Lattice};
pub use real::Real;
pub use shape::PatchShape;
pub use stencil::{for_each_stencil, for_each_stencil_at, Stencil};
pub use walls::{WallField, WallShape};

/// The SIMD machinery of the step's kernels: runs of patch rows, their stencils and lane sums.
///
/// Public only so that `mechanics` can build its kernels on it; it is not part of the stable
/// API and may change with any release. Use [`for_each_stencil`] (node by node) instead.
#[doc(hidden)]
pub mod kernel {
    pub use crate::padded::{PaddedParts, PaddedPatch};
    pub use crate::runs::{
        add_lanes, for_each_run_in_column, for_each_run_in_column_with, ColumnPlan, ColumnScratch,
        RowRun, RowRuns, StencilRun, LANES,
    };
    pub use crate::stencil::for_each_stencil_in_column;
}

/// Errors from building lattices, patches and initial states.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PhaseFieldError {
    /// The patch does not fit in the lattice.
    #[error("patch margin {margin} gives a patch of side {side}, larger than the {lx}×{ly} domain; use a margin of at most {}, or 0 for the full domain", (lx.min(ly) - 1) / 2)]
    PatchTooLarge {
        /// The requested margin.
        margin: usize,
        /// The resulting side `2m+1`.
        side: usize,
        /// Lattice side along x.
        lx: usize,
        /// Lattice side along y.
        ly: usize,
    },
    /// The initial discs do not fit.
    #[error("{n_cells} cells with initial discs of radius {disc_radius} do not fit in the domain (at most {max_cells})")]
    TooManyCells {
        /// Cells requested.
        n_cells: usize,
        /// Cells that fit.
        max_cells: usize,
        /// Radius of the initial discs.
        disc_radius: f64,
    },
    /// Given positions are unusable.
    #[error("bad initial positions: {0}")]
    BadPositions(String),
}
