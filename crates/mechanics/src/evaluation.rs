//! What one evaluation of the right-hand side leaves behind, per cell ([`CellState`]) and per
//! lattice node ([`SumField`]): a leaf module, so that the kernels that write these, the
//! terms that read them and the workspace that holds them need not import one another.

use nalgebra::Vector2;

use crate::geometry::TracelessTensor;

/// Fields of the lattice-wide sums of one evaluation.
pub(crate) const N_SUMS: usize = 6;

/// A lattice-wide sum left in the [`crate::Workspace`] by an evaluation (read it with
/// [`crate::Workspace::sum`] or [`crate::Workspace::sum_field`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum SumField {
    /// `s1 = Σ_i φ_i`.
    S1,
    /// `s2 = Σ_i φ_i²`.
    S2,
    /// `U = Σ_i U_i`, the part of the pressure that is a sum of single-cell terms
    /// ([`crate::equations::pressure_cell_part`]).
    U,
    /// `Q_xx = Σ_i φ_i S_i,xx`.
    Qxx,
    /// `Q_xy = Σ_i φ_i S_i,xy`.
    Qxy,
    /// The tissue pressure `P` ([`crate::equations::pressure`] of `s1`, `s2` and `U`),
    /// computed once per lattice node after the sums, for the force pass to read (where every
    /// cell over a node computed it again from the three sums).
    P,
}

impl SumField {
    /// Every field, in storage order.
    pub const ALL: [SumField; N_SUMS] =
        [Self::S1, Self::S2, Self::U, Self::Qxx, Self::Qxy, Self::P];

    /// Index in the storage of the sums.
    #[inline(always)]
    pub(crate) const fn index(self) -> usize {
        match self {
            Self::S1 => 0,
            Self::S2 => 1,
            Self::U => 2,
            Self::Qxx => 3,
            Self::Qxy => 4,
            Self::P => 5,
        }
    }
}

/// Per-cell quantities derived from the fields by one evaluation (by slot).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[non_exhaustive]
pub struct CellState {
    /// Area `A_i = Σ_x φ_i²`.
    pub area: f64,
    /// Deformation tensor `S_i` (docs/model.md §3).
    pub shape: TracelessTensor,
    /// Interface force `F_i` (pressure and active stress).
    pub force: Vector2<f64>,
    /// The whole-cell force of the physics terms, `Σ f_i` (`crate::terms`); zero without.
    pub cell_force: Vector2<f64>,
    /// Velocity `v_i = (F_i + Σ f_i) / ξ`.
    pub velocity: Vector2<f64>,
    /// Smallest `φ_i` on the patch.
    pub phi_min: f64,
    /// Largest `φ_i` on the patch.
    pub phi_max: f64,
    /// The cell's own drag `ξ_i` (the substrate's, plus a wall's friction): its velocity is
    /// `(F_i + Σ f_i)/ξ_i` without friction between cells (`crate::friction`).
    pub drag: f64,
    /// With a cell nematic whose dynamics read it (`crate::terms::CellNematic`), the mean
    /// over the cell of the nematic field `M = Σ_j φ_j q_j`, `⟨M⟩_i = Σ_x φ_i M / Σ_x φ_i`
    /// (`[xx, xy]`); zero otherwise.
    pub nematic_field: [f64; 2],
    /// With a cell nematic whose dynamics read it, the mean rotation rate of the flow over the
    /// cell, `⟨½ ∇ × u⟩_i` with `u = Σ_j φ_j v_j / max(Σ_j φ_j, ½)`; zero otherwise.
    pub vorticity: f64,
}
