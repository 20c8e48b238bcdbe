//! Race-free, thread-count-independent scatter of per-cell patch values onto the lattice.
//!
//! The lattice is cut into stripes of [`STRIPE_ROWS`] x-rows. Each stripe is owned by one
//! task, which visits the cells in index order and adds the contributions of the patch
//! columns that fall inside it. Every lattice node therefore receives its contributions in cell
//! order, whatever the number of threads: results are bit-for-bit reproducible.
//!
//! The `K` summed fields live in a [`LatticeSums`], stored stripe by stripe and, inside a
//! stripe, field by field: one lattice column of one field is a contiguous slice, so that a
//! run of patch rows ([`phasefield::RowRun`]) reads or writes it as one vectorisable loop.
//!
//! A stripe that no patch overlaps is zeroed once and then left alone, so a scene of a few
//! cells in a large box does no work per step on the nodes no cell covers.

use phasefield::{for_each_run_in_column, Cells, Lattice, Real, RowRuns, StencilRun};
use rayon::prelude::*;

/// Lattice x-rows per scatter stripe (fixed, so that the result never depends on threads).
pub const STRIPE_ROWS: usize = 8;

/// `K` lattice-wide fields written by [`scatter`]: the sums over cells of per-node values.
///
/// Stored stripe by stripe (see the module docs); read a field with [`LatticeSums::column`],
/// [`LatticeSums::get`] or [`LatticeSums::field`]. It also remembers which stripes may hold
/// non-zero values, so that the scatter can skip the stripes no cell overlaps.
#[derive(Debug, Clone)]
pub struct LatticeSums<const K: usize> {
    lattice: Lattice,
    data: Vec<f64>,
    dirty: Vec<bool>,
}

impl<const K: usize> LatticeSums<K> {
    /// `K` fields on `lattice`, all zero.
    pub fn new(lattice: Lattice) -> Self {
        Self {
            lattice,
            data: vec![0.0; lattice.len() * K],
            dirty: vec![false; lattice.lx.div_ceil(STRIPE_ROWS)],
        }
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        self.lattice
    }

    /// Where lattice column `x` of field 0 starts, and the distance from one field to the next.
    #[inline(always)]
    fn locate(&self, x: usize) -> (usize, usize) {
        let ly = self.lattice.ly;
        let x0 = x - x % STRIPE_ROWS;
        let rows = STRIPE_ROWS.min(self.lattice.lx - x0);
        (x0 * ly * K + (x - x0) * ly, rows * ly)
    }

    /// Lattice column `x` (rows `0..ly`) of field `c`.
    ///
    /// # Panics
    /// If `c >= K` or `x >= lx`.
    #[inline(always)]
    pub fn column(&self, c: usize, x: usize) -> &[f64] {
        assert!(c < K && x < self.lattice.lx);
        let (base, stride) = self.locate(x);
        let start = base + c * stride;
        &self.data[start..start + self.lattice.ly]
    }

    /// Lattice column `x` of every field.
    #[inline(always)]
    pub fn columns(&self, x: usize) -> [&[f64]; K] {
        std::array::from_fn(|c| self.column(c, x))
    }

    /// Field `c` at lattice node `node = x * ly + y`.
    pub fn get(&self, c: usize, node: usize) -> f64 {
        let ly = self.lattice.ly;
        self.column(c, node / ly)[node % ly]
    }

    /// Field `c` as one lattice-sized vector, index `x * ly + y`. Allocates.
    pub fn field(&self, c: usize) -> Vec<f64> {
        (0..self.lattice.lx)
            .flat_map(|x| self.column(c, x).iter().copied())
            .collect()
    }

    /// Every value of every field, in storage order (for sums whose order does not matter to
    /// the caller beyond being fixed).
    pub fn values(&self) -> &[f64] {
        &self.data
    }
}

/// Adds the contributions of every cell's patch to the `K` fields of `out`, which is
/// overwritten: nodes no patch covers are zero.
///
/// `add(cell_idx, run, dst)` is called for each [`StencilRun`] of each patch column, with
/// `dst[c]` the slice of field `c` on the lattice rows of the run (`dst[c][j]` is the node
/// of `run.c[j]`); it adds its values there. The stencil lets a value use derivatives of `φ_i`
/// without a buffer of its own.
pub fn scatter<const K: usize, T: Real, F>(
    cells: &Cells<T>,
    phi: &[T],
    out: &mut LatticeSums<K>,
    add: F,
) where
    F: Fn(usize, &StencilRun<'_, T>, [&mut [f64]; K]) + Sync,
{
    let lattice: Lattice = cells.lattice();
    assert_eq!(out.lattice, lattice, "the sums belong to another lattice");
    let shape = cells.shape();
    let map = cells.map();
    let (nx, ly) = (shape.nx, lattice.ly);
    let plen = shape.len();
    out.data
        .par_chunks_mut(STRIPE_ROWS * ly * K)
        .zip(out.dirty.par_iter_mut())
        .enumerate()
        .for_each(|(stripe, (chunk, dirty))| {
            // Zeroed before the first contribution, or at the end if there is none.
            let mut touched = false;
            let x0 = stripe * STRIPE_ROWS;
            let rows = chunk.len() / (ly * K);
            let mut parts = chunk.chunks_exact_mut(rows * ly);
            let mut fields: [&mut [f64]; K] = std::array::from_fn(|_| parts.next().unwrap());
            for i in 0..cells.n_cells() {
                let ox = map.origin[i][0];
                // (x0 − ox) mod lx without a division: this test runs for every cell in
                // every stripe.
                let mut u0 = x0 + lattice.lx - ox;
                if u0 >= lattice.lx {
                    u0 -= lattice.lx;
                }
                if u0 >= nx && u0 + rows <= lattice.lx {
                    continue;
                }
                if !touched {
                    if *dirty {
                        fields.iter_mut().for_each(|f| f.fill(0.0));
                    }
                    touched = true;
                }
                let xs = map.cell_x(shape, i);
                let runs = RowRuns::new(map.cell_y(shape, i));
                let cell = &phi[i * plen..(i + 1) * plen];
                for a in 0..nx {
                    let x = xs[a] as usize;
                    if x < x0 || x >= x0 + rows {
                        continue;
                    }
                    let base = (x - x0) * ly;
                    for_each_run_in_column(cell, shape, &runs, a, &mut |s| {
                        let start = base + s.run.y0;
                        let mut parts = fields.iter_mut();
                        let dst = std::array::from_fn(|_| {
                            let f = parts.next().expect("K fields");
                            &mut f[start..start + s.run.len]
                        });
                        add(i, &s, dst);
                    });
                }
            }
            if !touched && *dirty {
                fields.iter_mut().for_each(|f| f.fill(0.0));
            }
            *dirty = touched;
        });
}
