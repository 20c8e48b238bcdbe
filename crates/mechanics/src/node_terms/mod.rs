//! Node terms: free-energy terms that act at the lattice nodes, inside the step's node loops,
//! one file each ([`adhesion`], [`pair_adhesion`], [`pair_repulsion`], [`walls`]). What a new one writes is the
//! [`NodeTerm`] trait; `kernels::evaluate` takes the terms of an evaluation as a list and never
//! names one.
//!
//! A node term's functional derivative is linear in `φ_i`, with coefficients that may depend
//! on the cell's population `p_i`:
//!
//! ```text
//! δF_node/δφ_i = a_p(x) φ_i + b_p(x) + c_p ∇²φ_i,     p = p_i,
//! ```
//!
//! with lattice fields `a_p`, `b_p` (the term fills them once per evaluation, after the
//! lattice sums are complete) and constants `c_p`; a term whose coefficients are the same for
//! every cell says so ([`NodeTerm::per_population`] false, the default) and is asked for them
//! once. It adds to the pressure the φ-weighted sum of that derivative over the cells, as an
//! interaction term: a single-cell part `k_p φ_i ∇²φ_i` that the scatter adds to `U`
//! (`equations::adhesion_pressure_cell_part` with `k_p`), and a lattice part it adds to `P`
//! itself. Besides the step's sums (`s1, s2, U, Q`, `P`) a term may read each population's
//! `s1_p = Σ_{i ∈ p} φ_i` and `s2_p = Σ_{i ∈ p} φ_i²` ([`PopulationSums`], scattered only
//! when a term asks for them) and keep lattice fields of its own between its pressure and its
//! coefficients ([`NodeTerm::scratch_fields`]).
//!
//! So the terms are dispatched once per evaluation, outside the loops: the loops see only the
//! summed coefficients of the cell's population (`a_p`, `b_p` gathered beside each patch,
//! `c_p` and `k_p` constants of the cell), the scatter and the force pass branch once on
//! whether there are any, and with none they are the paper's loops.
//!
//! Adding one: a file here with a type that implements [`NodeTerm`] (its formulas in
//! `crate::equations`), its place in `Tissue::node_terms` (`step.rs`), which builds the
//! evaluation's list from the tissue's parameters and extensions, and a scene table (as for any
//! term: ARCHITECTURE.md, "Adding a physics term").

pub(crate) mod adhesion;
pub(crate) mod pair_adhesion;
pub(crate) mod pair_repulsion;
pub(crate) mod walls;

pub(crate) use adhesion::Adhesion;
pub(crate) use pair_adhesion::PairAdhesion;
pub(crate) use pair_repulsion::PairRepulsion;
pub(crate) use walls::WallTerm;

use phasefield::{Cells, Lattice, Real};

use crate::evaluation::N_SUMS;
use crate::scatter::{scatter, LatticeSums};
use crate::terms::Populations;

/// A free-energy term that acts at the nodes (module docs).
pub(crate) trait NodeTerm: Sync {
    /// Whether its coefficients depend on the cell's population: such a term is asked for
    /// them once for each population, the others once for all (population 0).
    fn per_population(&self) -> bool {
        false
    }

    /// Which of each population's sums it reads ([`PopulationSums`]): 0 none, 1 `s1_p`, 2
    /// `s1_p` and `s2_p`.
    fn population_moments(&self) -> usize {
        0
    }

    /// `k_p` of its single-cell pressure part `k_p φ_i ∇²φ_i` for a cell of `population`,
    /// which the scatter adds to `U` (0: none).
    fn cell_pressure_coefficient(&self, _population: usize) -> f64 {
        0.0
    }

    /// `c_p` of its derivative's `c_p ∇²φ_i` for a cell of `population` (0: none).
    fn laplacian_coefficient(&self, _population: usize) -> f64 {
        0.0
    }

    /// How many lattice fields of scratch (one value per node each, index
    /// `field * nodes + x * ly + y`) it keeps between [`NodeTerm::add_pressure`] and
    /// [`NodeTerm::add_coefficients`].
    fn scratch_fields(&self) -> usize {
        0
    }

    /// Adds its lattice part of the pressure to `P` once the scatter has completed the sums,
    /// keeping in `scratch` what its coefficients need (adhesion: `∇²s1`). `populations` holds
    /// each population's `s1_p` when the term asked for them.
    fn add_pressure(
        &self,
        sums: &mut LatticeSums<N_SUMS>,
        populations: &PopulationSums,
        scratch: &mut [f64],
    );

    /// Adds its `a_p` and `b_p` for `population` to the lattice nodes `k0..k0 + a.len()` of
    /// `a` and `b`.
    fn add_coefficients(
        &self,
        population: usize,
        scratch: &[f64],
        k0: usize,
        a: &mut [f64],
        b: &mut [f64],
    );
}

/// The number of coefficient classes of an evaluation with the node terms `terms`: one per
/// population of `populations` (at least one) when a term's coefficients depend on it
/// ([`NodeTerm::per_population`]), otherwise one. The evaluation's classes and the size of its
/// coefficient buffer both come from here.
pub(crate) fn classes(terms: &[Option<&dyn NodeTerm>], populations: &Populations) -> usize {
    if terms.iter().flatten().any(|t| t.per_population()) {
        populations.kinds().len().max(1)
    } else {
        1
    }
}

/// Lattice fields per scatter of [`PopulationSums`]: one pass over the cells fills this many
/// (the sums of 4 populations, or of 2 with their squares).
const FIELDS_PER_PASS: usize = 4;

/// Each population's `s1_p = Σ_{i ∈ p} φ_i`, and where a term asks for it `s2_p = Σ_{i ∈ p}
/// φ_i²`, on the lattice, for the node terms that read them ([`NodeTerm::population_moments`]):
/// scattered after the step's sums, in cell order like them (so independent of the thread
/// count), [`FIELDS_PER_PASS`] fields a pass.
#[derive(Debug, Clone, Default)]
pub(crate) struct PopulationSums {
    passes: Vec<LatticeSums<FIELDS_PER_PASS>>,
    populations: usize,
    /// Fields per population: 1 (`s1_p`) or 2 (`s1_p`, `s2_p`).
    moments: usize,
}

impl PopulationSums {
    /// The number of populations summed (0 when no term asked).
    pub(crate) fn populations(&self) -> usize {
        self.populations
    }

    /// Lattice column `x` of field `m` of population `p`.
    fn field(&self, p: usize, m: usize, x: usize) -> &[f64] {
        assert!(p < self.populations, "population {p} is not summed");
        assert!(m < self.moments, "moment {m} is not summed");
        let f = p * self.moments + m;
        self.passes[f / FIELDS_PER_PASS].column(f % FIELDS_PER_PASS, x)
    }

    /// Lattice column `x` of `s1_p`.
    pub(crate) fn column(&self, p: usize, x: usize) -> &[f64] {
        self.field(p, 0, x)
    }

    /// Lattice column `x` of `s2_p` (summed when a term asked for two moments).
    pub(crate) fn squares(&self, p: usize, x: usize) -> &[f64] {
        self.field(p, 1, x)
    }

    /// Bytes of heap memory held.
    pub(crate) fn heap_bytes(&self) -> usize {
        self.passes.iter().map(LatticeSums::heap_bytes).sum()
    }

    /// Sums `populations` populations of the cells (`population_of(slot)`) on `lattice`, with
    /// `moments` fields each (1: `s1_p`; 2: `s1_p` and `s2_p`), allocating the passes on the
    /// first call that needs them.
    pub(crate) fn fill<T: Real>(
        &mut self,
        cells: &Cells<T>,
        phi: &[T],
        populations: usize,
        moments: usize,
        population_of: impl Fn(usize) -> usize + Sync,
    ) {
        assert!(
            moments == 1 || moments == 2,
            "one or two moments per population"
        );
        let lattice: Lattice = cells.lattice();
        let passes = (populations * moments).div_ceil(FIELDS_PER_PASS);
        if self.passes.len() != passes
            || self.passes.first().is_some_and(|s| s.lattice() != lattice)
        {
            self.passes = (0..passes)
                .map(|_| LatticeSums::for_cells(lattice, cells.n_cells(), cells.shape().nx))
                .collect();
        }
        self.populations = populations;
        self.moments = moments;
        for (pass, sums) in self.passes.iter_mut().enumerate() {
            let first = pass * FIELDS_PER_PASS;
            scatter::<FIELDS_PER_PASS, T, _, _, _>(
                cells,
                phi,
                sums,
                |i| {
                    // The cell's first field in this pass, if its population is one of the
                    // pass's (a population's moments share a pass: 4 is a multiple of both).
                    let field = (population_of(i) * moments)
                        .checked_sub(first)
                        .filter(|&f| f < FIELDS_PER_PASS);
                    move |run: &phasefield::kernel::StencilRun<'_, T>,
                          dst: [&mut [f64]; FIELDS_PER_PASS]| {
                        if let Some(f) = field {
                            let mut dst = dst.into_iter().skip(f);
                            let s1 = dst.next().expect("a field of the pass");
                            if moments == 1 {
                                run.add_to([], |s, []| [s.c], [s1]);
                            } else {
                                let s2 = dst.next().expect("a field of the pass");
                                run.add_to([], |s, []| [s.c, s.c * s.c], [s1, s2]);
                            }
                        }
                    }
                },
                |_| {},
            );
        }
    }
}

/// The five-point Laplacian of a periodic lattice field, read column by column
/// (`column(x)`, `ly` values each), into `out` (index `x * ly + y`): the adjoint gradient of the
/// forward-difference energies of adhesion.
pub(crate) fn laplacian_into<'a>(
    lattice: Lattice,
    column: impl Fn(usize) -> &'a [f64] + Sync,
    out: &mut [f64],
) {
    use rayon::prelude::*;
    let (lx, ly) = (lattice.lx, lattice.ly);
    assert_eq!(out.len(), lx * ly, "the Laplacian buffer holds the lattice");
    out.par_chunks_mut(ly).enumerate().for_each(|(x, out)| {
        let (xm, xp) = ((x + lx - 1) % lx, (x + 1) % lx);
        let (c0, cm, cp) = (column(x), column(xm), column(xp));
        for y in 0..ly {
            let (ym, yp) = (
                if y == 0 { ly - 1 } else { y - 1 },
                if y + 1 == ly { 0 } else { y + 1 },
            );
            out[y] = cm[y] + cp[y] + c0[ym] + c0[yp] - 4.0 * c0[y];
        }
    });
}

#[cfg(test)]
mod tests;
