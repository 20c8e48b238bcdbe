//! The state of a monolayer: [`Tissue`], its fields, parameters, clock and cell identities.

use nalgebra::Vector2;
use phasefield::{Cells, ComTable, Lattice, Real};
use rayon::prelude::*;

use crate::extensions::{ExtensionPart, Extensions, Part};
use crate::params::ModelParams;
use crate::terms::{Populations, Terms};
use crate::walls::Walls;

/// Side, in nodes, of the blocks of the Morton order used by [`Tissue::sort_cells`]: about
/// a cell radius, so that a block holds a cell or two.
pub(crate) const SORT_BLOCK: f64 = 8.0;

/// A monolayer: the fields of all cells, the parameters and the clock (the *model* of the
/// Model/Simulation split; [`crate::Simulation`] drives it).
///
/// The fields are stored in precision `T` (`f64`, the default, or `f32`; see
/// [`phasefield::Real`]); all arithmetic is done in `f64`.
///
/// Cells live in storage *slots*, which [`Tissue::sort_cells`] reorders; each slot remembers
/// the cell's *identity* (its index in the initial state, [`Tissue::cell_ids`]). Per-cell
/// accessors take a slot.
#[derive(Debug, Clone)]
pub struct Tissue<T: Real = f64> {
    pub(crate) cells: Cells<T>,
    pub(crate) params: ModelParams,
    pub(crate) time: f64,
    pub(crate) iteration: u64,
    /// The centre of mass of every slot, computed after each step; it placed the patches and
    /// is the sort key. Only the step writes it.
    pub(crate) centre: Vec<[f64; 2]>,
    pub(crate) cell_id: Vec<usize>,
    /// The identity the next new cell gets ([`Tissue::next_id`]).
    pub(crate) next_id: usize,
    /// Whether activity is on (the relaxation switch; see [`Tissue::set_active`]).
    pub(crate) active: bool,
    /// Every part of the model beyond the paper's (terms, populations, walls, division).
    pub(crate) ext: Extensions,
}

impl<T: Real> Tissue<T> {
    /// Bytes of heap memory held by the tissue: its fields, patch map, centres and ids.
    /// With [`crate::Workspace::heap_bytes`], the memory a simulation needs.
    pub fn heap_bytes(&self) -> usize {
        self.cells.heap_bytes()
            + self.ext.heap_bytes()
            + self.centre.capacity() * std::mem::size_of::<[f64; 2]>()
            + self.cell_id.capacity() * std::mem::size_of::<usize>()
    }

    /// A tissue from initial fields at time 0; centres of mass are computed and patches
    /// centred on them.
    pub fn new(cells: Cells<T>, params: ModelParams) -> Self {
        let n = cells.n_cells();
        let mut t = Self::from_state(cells, params, 0.0, 0, (0..n).collect());
        let com = ComTable::new(t.cells.lattice());
        t.update_centres(&com);
        t
    }

    /// A tissue from a saved state: fields (with their patch origins), parameters, clock
    /// and the identity of each slot (distinct; a permutation of `0..n_cells` unless cells
    /// have divided or been removed). The centres are computed from the fields; the patches
    /// stay where they are.
    ///
    /// # Panics
    /// If `cell_id` does not hold one distinct identity per cell.
    pub fn from_state(
        cells: Cells<T>,
        params: ModelParams,
        time: f64,
        iteration: u64,
        cell_id: Vec<usize>,
    ) -> Self {
        let n = cells.n_cells();
        assert!(
            cell_id.len() == n && distinct(&cell_id),
            "cell_id must hold {n} distinct identities"
        );
        let mut t = Self {
            centre: vec![[0.0; 2]; n],
            next_id: next_after(&cell_id),
            cell_id,
            cells,
            params,
            time,
            iteration,
            active: true,
            ext: Extensions::none(),
        };
        let com = ComTable::new(t.cells.lattice());
        let mut centre = std::mem::take(&mut t.centre);
        t.compute_centres_into(&com, &mut centre);
        t.centre = centre;
        t
    }

    /// A tissue restored exactly from a checkpoint: fields as stored, parameters, clock,
    /// the centres as the run held them (not recomputed, so that the next step is the one the
    /// run would have taken), and the identity of each slot.
    ///
    /// # Errors
    /// A message when the centres or identities do not fit the cells.
    pub fn restore(
        cells: Cells<T>,
        params: ModelParams,
        time: f64,
        iteration: u64,
        centre: Vec<[f64; 2]>,
        cell_id: Vec<usize>,
    ) -> Result<Self, String> {
        let n = cells.n_cells();
        if centre.len() != n || cell_id.len() != n || !distinct(&cell_id) {
            return Err(format!(
                "{} centres and identities {:?}… for {n} cells: not {n} distinct identities",
                centre.len(),
                &cell_id[..cell_id.len().min(4)]
            ));
        }
        if centre.iter().flatten().any(|c| !c.is_finite()) {
            return Err("a centre is not finite".into());
        }
        Ok(Self {
            cells,
            params,
            time,
            iteration,
            centre,
            next_id: next_after(&cell_id),
            cell_id,
            active: true,
            ext: Extensions::none(),
        })
    }

    /// This tissue with the extensions `ext` (all of them at once: what a scene builds),
    /// replacing any it had: the terms' per-cell state initialised from their seed where it
    /// is not there already, and the clock's growth factors set.
    ///
    /// # Panics
    /// If the populations do not assign every identity `0..`[`Tissue::next_id`], or the walls
    /// are on another lattice.
    pub fn with_extensions(mut self, ext: Extensions) -> Self {
        let Extensions {
            mut terms,
            populations,
            walls,
            proliferation,
            friction,
            target_scale: _,
        } = ext;
        assert!(
            populations.is_empty() || populations.of_cell().len() == self.next_id(),
            "{} cells assigned to populations, {} identities in the tissue",
            populations.of_cell().len(),
            self.next_id()
        );
        if let Some(w) = &walls {
            assert_eq!(
                w.field(false).map(|f| f.lattice()),
                Some(self.lattice()),
                "the walls' lattice is the tissue's"
            );
        }
        terms.initialise(self.next_id());
        self.ext = Extensions {
            terms,
            populations,
            walls,
            proliferation,
            friction,
            target_scale: Vec::new(),
        };
        self.refresh_target_scale();
        self
    }

    /// This tissue with the part `part` of the extensions in its place (the physics terms,
    /// the populations, the walls, the cell-cycle clock: [`ExtensionPart`]), replacing the
    /// one there, as [`Tissue::with_extensions`] takes them all.
    ///
    /// # Panics
    /// As [`Tissue::with_extensions`].
    pub fn with(mut self, part: impl ExtensionPart) -> Self {
        let ext = std::mem::take(&mut self.ext).with(part);
        self.with_extensions(ext)
    }

    /// The extensions of the paper's model this tissue has.
    pub fn extensions(&self) -> &Extensions {
        &self.ext
    }

    /// The parts beyond the paper's model this tissue has, in [`Part::ALL`]'s order (for a
    /// backend's refusal: [`crate::backend::Backend`]).
    pub fn parts(&self) -> Vec<Part> {
        self.ext.parts(&self.params)
    }

    /// The walls, if any.
    pub fn walls(&self) -> Option<&Walls> {
        self.ext.walls.as_ref()
    }

    /// The wall field in effect now (none without walls, or once a wound has opened).
    pub fn wall_field(&self) -> Option<&phasefield::WallField> {
        self.ext.walls.as_ref().and_then(|w| w.field(self.active))
    }

    /// The populations (empty when every cell has the tissue's parameters).
    pub fn populations(&self) -> &Populations {
        &self.ext.populations
    }

    /// The physics terms and their per-cell state.
    pub fn terms(&self) -> &Terms {
        &self.ext.terms
    }

    /// The physics terms, to restore their state from a checkpoint
    /// ([`Terms::set_variable`]) or change them between steps.
    pub fn terms_mut(&mut self) -> &mut Terms {
        &mut self.ext.terms
    }

    /// Whether activity is on: the active terms (ζ is set apart, by [`Tissue::params_mut`]) act
    /// only then. On by default; [`crate::Simulation::activity_from`] holds it off during the
    /// relaxation.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Switches activity on or off (see [`Tissue::active`]).
    pub fn set_active(&mut self, on: bool) {
        self.active = on;
    }

    /// The phase fields, slot by slot, to change between steps (a [`crate::Fix`]); call
    /// [`Tissue::recentre`] after a change that moves a cell.
    pub fn phi_mut(&mut self) -> &mut [T] {
        self.cells.phi_mut()
    }

    /// Recomputes every centre of mass from the fields and moves each patch onto its cell's
    /// centre, as a step does after its update.
    pub fn recentre(&mut self) {
        let com = ComTable::new(self.cells.lattice());
        self.update_centres(&com);
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        self.cells.lattice()
    }

    /// The phase fields, slot by slot.
    pub fn cells(&self) -> &Cells<T> {
        &self.cells
    }

    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.cells.n_cells()
    }

    /// The model parameters.
    pub fn params(&self) -> &ModelParams {
        &self.params
    }

    /// The model parameters, to change between steps (e.g. ζ after relaxation).
    pub fn params_mut(&mut self) -> &mut ModelParams {
        &mut self.params
    }

    /// Model time.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn iteration(&self) -> u64 {
        self.iteration
    }

    /// The centre of mass of every slot, as the last step computed it (the centres that
    /// placed the patches).
    ///
    /// When a patch has just moved, its wrapped row or column carries far-edge values
    /// (docs/model.md §5), so the centre of the stored values ([`crate::Workspace::centres`] after
    /// an observation) can differ from it by the neglected tail.
    pub fn centres(&self) -> &[[f64; 2]] {
        &self.centre
    }

    /// The centre of mass of slot `slot` (see [`Tissue::centres`]).
    pub fn centre(&self, slot: usize) -> Vector2<f64> {
        Vector2::from(self.centre[slot])
    }

    /// The identity of the cell in each slot: its index in the initial state, or for a
    /// daughter of a division the next unused number ([`Tissue::next_id`]).
    /// [`Tissue::sort_cells`] reorders the slots; outputs are written in identity order.
    pub fn cell_ids(&self) -> &[usize] {
        &self.cell_id
    }

    /// The slots in increasing order of their cells' identities: `slots()[k]` is where the
    /// cell with the `k`-th smallest identity is stored (while no cell has divided or been
    /// removed, where cell `k` is). Outputs write their rows in this order.
    pub fn slots(&self) -> Vec<usize> {
        let mut s: Vec<usize> = (0..self.cell_id.len()).collect();
        s.sort_unstable_by_key(|&slot| self.cell_id[slot]);
        s
    }

    /// Reorders the cells' storage along a Morton (Z-order) curve of their centres, in blocks
    /// of about a cell radius, so that cells next to each other in memory are next to each
    /// other on the lattice and the lattice-wide fields they touch stay in cache. The physics
    /// does not change; sums over cells run in another order, which changes results at the
    /// level of round-off. The key is [`Tissue::centres`], which only the step writes, so how
    /// a run is observed never changes the order. `scratch` carries the field values (see
    /// [`Cells::permute`]).
    pub fn sort_cells(&mut self, scratch: &mut Vec<T>) {
        let key = |c: [f64; 2]| -> u64 {
            let (x, y) = ((c[0] / SORT_BLOCK) as u64, (c[1] / SORT_BLOCK) as u64);
            let spread = |mut v: u64| {
                v &= 0xffff_ffff;
                v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
                v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
                v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
                v = (v | (v << 2)) & 0x3333_3333_3333_3333;
                (v | (v << 1)) & 0x5555_5555_5555_5555
            };
            spread(x) | (spread(y) << 1)
        };
        let mut order: Vec<usize> = (0..self.cells.n_cells()).collect();
        order.sort_by_key(|&j| (key(self.centre[j]), self.cell_id[j]));
        if order.iter().enumerate().all(|(j, &o)| j == o) {
            return;
        }
        self.cells.permute(&order, scratch);
        self.centre = order.iter().map(|&o| self.centre[o]).collect();
        self.cell_id = order.iter().map(|&o| self.cell_id[o]).collect();
    }

    /// Computes every centre of mass from the current patch values into `out`.
    pub(crate) fn compute_centres_into(&self, com: &ComTable, out: &mut [[f64; 2]]) {
        let cells = &self.cells;
        out.par_iter_mut()
            .enumerate()
            .for_each(|(i, c)| *c = com.cell_centre(cells, i));
    }

    /// Recomputes the centres and moves each patch onto its cell's centre.
    pub(crate) fn update_centres(&mut self, com: &ComTable) {
        let mut centre = std::mem::take(&mut self.centre);
        self.compute_centres_into(com, &mut centre);
        self.centre = centre;
        for i in 0..self.cells.n_cells() {
            self.cells.recentre(i, self.centre[i]);
        }
    }

    /// Takes `centres` (computed from the current fields, as [`Tissue::update_centres`] would
    /// compute them) as the centres, and moves each patch onto its cell's centre.
    pub(crate) fn move_patches_to(&mut self, centres: &[[f64; 2]]) {
        self.centre.copy_from_slice(centres);
        for i in 0..self.cells.n_cells() {
            self.cells.recentre(i, self.centre[i]);
        }
    }
}

/// One more than the largest of `ids` (0 for none).
fn next_after(ids: &[usize]) -> usize {
    ids.iter().max().map_or(0, |&m| m + 1)
}

/// Whether no identity appears twice.
fn distinct(ids: &[usize]) -> bool {
    let mut sorted = ids.to_vec();
    sorted.sort_unstable();
    sorted.windows(2).all(|w| w[0] != w[1])
}
