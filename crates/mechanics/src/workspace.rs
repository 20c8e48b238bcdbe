//! The scratch memory of a step ([`Workspace`]) and what an evaluation leaves in it:
//! per-cell quantities ([`CellState`]) and the lattice sums ([`SumField`]).

use phasefield::{Cells, ComTable, Real};

use crate::evaluation::{CellState, SumField, N_SUMS};
use crate::scatter::LatticeSums;

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
    /// The node terms' lattice fields of scratch (adhesion: the Laplacian of `s1`), empty
    /// without such a term (`crate::node_terms::NodeTerm::scratch_fields`).
    pub(crate) node_scratch: Vec<f64>,
    /// The node terms' lattice fields of coefficients, two for each coefficient class, with
    /// adhesion or walls only (empty otherwise).
    pub(crate) node_terms: Vec<f64>,
    /// The node terms' constants `[k_p, c_p]` of each class.
    pub(crate) node_constants: Vec<[f64; 2]>,
    /// Each population's `s1_p`, for a node term that reads them (empty otherwise).
    pub(crate) population_sums: crate::node_terms::PopulationSums,
    /// Each population's constants in the current evaluation (one entry without populations).
    pub(crate) kind_constants: Vec<crate::terms::CellConstants>,
    /// With a cell nematic, each slot's nematic tensor `q_i`, its active tensor `ζ_Q q_i`,
    /// and the lattice fields its dynamics read (`crate::nematic_fields`), made on first use.
    pub(crate) nematic: NematicScratch,
    /// With friction between cells: the overlaps of the pairs, the velocities before the
    /// solve, and what the last solve did (`crate::friction`).
    pub(crate) friction: FrictionScratch,
}

/// Friction's buffers ([`TermScratch::friction`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct FrictionScratch {
    pub(crate) pairs: Vec<(u32, u32, f64)>,
    pub(crate) before: Vec<[f64; 2]>,
    pub(crate) solve: crate::friction::FrictionSolve,
}

/// The cell nematic's buffers ([`TermScratch::nematic`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct NematicScratch {
    pub(crate) q: Vec<[f64; 2]>,
    pub(crate) stress: Vec<[f64; 2]>,
    pub(crate) fields: Option<crate::scatter::LatticeSums<{ crate::nematic_fields::N_FIELDS }>>,
}

impl NematicScratch {
    fn heap_bytes(&self) -> usize {
        (self.q.capacity() + self.stress.capacity()) * std::mem::size_of::<[f64; 2]>()
            + self.fields.as_ref().map_or(0, |f| f.heap_bytes())
    }
}

impl TermScratch {
    /// Bytes of heap memory held.
    fn heap_bytes(&self) -> usize {
        self.cell_force.capacity() * std::mem::size_of::<[f64; 2]>()
            + (self.node_scratch.capacity() + self.node_terms.capacity())
                * std::mem::size_of::<f64>()
            + self.node_constants.capacity() * std::mem::size_of::<[f64; 2]>()
            + self.population_sums.heap_bytes()
            + self.kind_constants.capacity() * std::mem::size_of::<crate::terms::CellConstants>()
            + self.nematic.heap_bytes()
            + self.friction.pairs.capacity() * std::mem::size_of::<(u32, u32, f64)>()
            + self.friction.before.capacity() * std::mem::size_of::<[f64; 2]>()
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
            + crate::scratch::scratch_bytes()
    }

    /// Scratch memory for a tissue of this size.
    pub fn new(cells: &Cells<T>) -> Self {
        let n = cells.n_cells() * cells.patch_len();
        let lattice = cells.lattice();
        crate::scratch::prepare_scratch(cells.shape());
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
                node_scratch: Vec::new(),
                node_terms: Vec::new(),
                node_constants: Vec::with_capacity(4),
                population_sums: Default::default(),
                kind_constants: Vec::with_capacity(4),
                nematic: NematicScratch::default(),
                friction: FrictionScratch::default(),
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
