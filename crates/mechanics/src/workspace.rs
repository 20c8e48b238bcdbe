//! The scratch memory of a step ([`Workspace`]) and what an evaluation leaves in it:
//! per-cell quantities ([`CellState`]) and the lattice sums ([`SumField`]).

use nalgebra::Vector2;
use phasefield::{Cells, ComTable, Real};

use crate::geometry::TracelessTensor;
use crate::scatter::LatticeSums;

/// Fields of the lattice-wide sums of one evaluation.
pub(crate) const N_SUMS: usize = 6;

/// A lattice-wide sum left in the [`Workspace`] by an evaluation (read it with
/// [`Workspace::sum`] or [`Workspace::sum_field`]).
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
}

/// Scratch memory for [`crate::Tissue::step`] and the observations: built once, reused,
/// never serialised (after rapier's pipeline and faer's scratch memory).
///
/// After an evaluation (a step, or [`crate::Tissue::refresh`] / [`crate::Tissue::observe`])
/// it holds the per-cell quantities ([`Workspace::cell_states`]) and the lattice sums
/// ([`Workspace::sum_field`]) of the state evaluated last; after a step that is the state of
/// its last corrector pass, not the new state: observe to evaluate the current one.
#[derive(Debug, Clone)]
pub struct Workspace<T: Real = f64> {
    pub(crate) phi_old: Vec<T>,
    pub(crate) k1: Vec<T>,
    pub(crate) k2: Vec<T>,
    pub(crate) sums: LatticeSums<N_SUMS>,
    pub(crate) cell_state: Vec<CellState>,
    pub(crate) velocity_field: LatticeSums<2>,
    pub(crate) observed_centre: Vec<[f64; 2]>,
    /// The centres of mass of the state a fixed step ends in, computed in its corrector pass.
    pub(crate) next_centre: Vec<[f64; 2]>,
    /// The range `[min φ, max φ]` of each cell of that state, for the check after the step.
    pub(crate) next_range: Vec<[f64; 2]>,
    pub(crate) com: ComTable,
    /// The buffers of the physics terms in an evaluation.
    pub(crate) term_scratch: TermScratch,
}

/// The buffers an evaluation needs for the physics terms (docs/model.md §11), passed to it as
/// one: a new term's buffer goes here, not into every call of the evaluation.
#[derive(Debug, Clone, Default)]
pub(crate) struct TermScratch {
    /// The whole-cell forces of the terms for the next evaluation, by slot.
    pub(crate) cell_force: Vec<[f64; 2]>,
    /// The lattice Laplacian of `s1`, with adhesion only (empty otherwise).
    pub(crate) lap_s1: Vec<f64>,
    /// The node terms' two lattice fields of coefficients, with adhesion or walls only
    /// (empty otherwise).
    pub(crate) node_terms: Vec<f64>,
    /// Each population's constants in the current evaluation (one entry without populations).
    pub(crate) kind_constants: Vec<crate::terms::CellConstants>,
}

impl TermScratch {
    /// Bytes of heap memory held.
    fn heap_bytes(&self) -> usize {
        self.cell_force.capacity() * std::mem::size_of::<[f64; 2]>()
            + (self.lap_s1.capacity() + self.node_terms.capacity()) * std::mem::size_of::<f64>()
            + self.kind_constants.capacity() * std::mem::size_of::<crate::terms::CellConstants>()
    }
}

impl<T: Real> Workspace<T> {
    /// Bytes of heap memory held by the scratch buffers, lattice sums and tables, and by the
    /// patch scratch of every thread of the current rayon pool (the global one outside a pool;
    /// [`crate::thread_scratch_bytes`] per thread).
    pub fn heap_bytes(&self) -> usize {
        (self.phi_old.capacity() + self.k1.capacity() + self.k2.capacity())
            * std::mem::size_of::<T>()
            + self.sums.heap_bytes()
            + self.cell_state.capacity() * std::mem::size_of::<CellState>()
            + self.velocity_field.heap_bytes()
            + (self.observed_centre.capacity()
                + self.next_centre.capacity()
                + self.next_range.capacity())
                * std::mem::size_of::<[f64; 2]>()
            + self.term_scratch.heap_bytes()
            + self.com.heap_bytes()
            + crate::kernels::scratch_bytes()
    }

    /// Scratch memory for a tissue of this size.
    pub fn new(cells: &Cells<T>) -> Self {
        let n = cells.n_cells() * cells.patch_len();
        let lattice = cells.lattice();
        crate::kernels::prepare_scratch(cells.shape());
        Self {
            phi_old: vec![T::default(); n],
            k1: vec![T::default(); n],
            k2: vec![T::default(); n],
            sums: LatticeSums::for_cells(lattice, cells.n_cells(), cells.shape().nx),
            cell_state: vec![CellState::default(); cells.n_cells()],
            velocity_field: LatticeSums::for_cells(lattice, cells.n_cells(), cells.shape().nx),
            observed_centre: vec![[0.0; 2]; cells.n_cells()],
            next_centre: vec![[0.0; 2]; cells.n_cells()],
            next_range: vec![[0.0; 2]; cells.n_cells()],
            com: ComTable::new(lattice),
            term_scratch: TermScratch {
                cell_force: vec![[0.0; 2]; cells.n_cells()],
                lap_s1: Vec::new(),
                node_terms: Vec::new(),
                kind_constants: Vec::with_capacity(4),
            },
        }
    }

    /// Resizes the per-cell buffers for `cells` after its number of cells changed (a
    /// division or a removal): the buffers grow as `Vec`s do, so a run of divisions
    /// reallocates O(log N) times, and a step after a fit allocates nothing. What they held
    /// is not kept; the next step overwrites it.
    pub fn fit(&mut self, cells: &Cells<T>) {
        let n = cells.n_cells();
        let len = n * cells.patch_len();
        for v in [&mut self.phi_old, &mut self.k1, &mut self.k2] {
            v.resize(len, T::default());
        }
        self.cell_state.resize(n, CellState::default());
        for v in [
            &mut self.observed_centre,
            &mut self.next_centre,
            &mut self.next_range,
            &mut self.term_scratch.cell_force,
        ] {
            v.resize(n, [0.0; 2]);
        }
    }

    /// The right-hand side `R(φ)` of the last [`crate::Tissue::refresh`] or observation, in
    /// storage order (every cell's patch, stride `patch_len`).
    pub fn rhs(&self) -> &[T] {
        &self.k2
    }

    /// Per-cell quantities of the last evaluation, by slot.
    pub fn cell_states(&self) -> &[CellState] {
        &self.cell_state
    }

    /// The per-cell quantities of slot `slot` in the last evaluation.
    pub fn cell(&self, slot: usize) -> &CellState {
        &self.cell_state[slot]
    }

    /// Takes what a device's last evaluation computed as this workspace's last evaluation:
    /// the cells' quantities, and the pressure where it came with them (the division clock's
    /// inputs, [`crate::Tissue::proliferate`]).
    ///
    /// # Panics
    /// If the counts do not fit the workspace (fit it to the tissue first).
    pub(crate) fn take_device_evaluation(&mut self, ev: &crate::backend::DeviceEvaluation) {
        assert_eq!(ev.cells.len(), self.cell_state.len(), "a state per cell");
        self.cell_state.copy_from_slice(&ev.cells);
        if let Some(p) = &ev.pressure {
            let lattice = self.sums.lattice();
            let ly = lattice.ly;
            assert_eq!(p.len(), lattice.len(), "a pressure per lattice node");
            for x in 0..lattice.lx {
                let (_, col) = self
                    .sums
                    .columns_read_write::<0>([], SumField::P.index(), x);
                col.copy_from_slice(&p[x * ly..(x + 1) * ly]);
            }
        }
    }

    /// The sum `field` of the last evaluation at lattice node `node = x * ly + y`.
    pub fn sum(&self, field: SumField, node: usize) -> f64 {
        self.sums.get(field.index(), node)
    }

    /// The sum `field` of the last evaluation as one lattice-sized vector (index
    /// `x * ly + y`). Allocates.
    pub fn sum_field(&self, field: SumField) -> Vec<f64> {
        self.sums.field(field.index())
    }

    /// The tissue velocity `v = Σ_i φ_i v_i` of the last observation
    /// ([`crate::Tissue::observe`]), as `[v_x, v_y]` lattice-sized vectors. Allocates.
    pub fn velocity_field(&self) -> [Vec<f64>; 2] {
        [self.velocity_field.field(0), self.velocity_field.field(1)]
    }

    /// The centres of mass of the stored values, by slot, as the last observation measured
    /// them (see [`crate::Tissue::centres`] for the centres the step uses).
    pub fn centres(&self) -> &[[f64; 2]] {
        &self.observed_centre
    }
}
