//! Race-free, thread-count-independent scatter of per-cell patch values onto the lattice.
//!
//! The lattice is cut into stripes of [`STRIPE_ROWS`] x-rows. Each stripe is owned by one
//! task, which visits the cells in index order and adds the contributions of the patch
//! columns that fall inside it. Every lattice node therefore receives its contributions in cell
//! order, whatever the number of threads: results are bit-for-bit reproducible.
//!
//! A stripe that no patch overlaps is zeroed once and then left alone ([`Stripes`]), so a
//! scene of a few cells in a large box does no work per step on the nodes no cell covers.

use phasefield::{for_each_stencil_in_column, Cells, Lattice, Real, Stencil};
use rayon::prelude::*;

/// Lattice x-rows per scatter stripe (fixed, so that the result never depends on threads).
pub const STRIPE_ROWS: usize = 8;

/// Which stripes of a scattered lattice field may hold non-zero values: the memory that lets
/// [`scatter`] skip the stripes no cell overlaps. One per field, kept with it.
#[derive(Debug, Clone)]
pub struct Stripes {
    dirty: Vec<bool>,
}

impl Stripes {
    /// For a field on `lattice` whose content is unknown: every stripe will be zeroed once.
    pub fn new(lattice: Lattice) -> Self {
        Self {
            dirty: vec![true; lattice.lx.div_ceil(STRIPE_ROWS)],
        }
    }
}

/// Adds `value(cell_idx, k, stencil)` (K components) of every patch node `k` of every cell
/// to the lattice field `out`, laid out as `out[node * K + component]`. The stencil holds `φ_i`
/// at the node and its four neighbours on the periodic patch, widened to `f64`, so that a
/// value may use derivatives of `φ_i` without a buffer of its own. `out` is overwritten:
/// nodes no patch covers are zero. `stripes` must be the one kept with `out` (nothing else may
/// write to `out` between calls).
///
/// # Panics
/// If `out.len() != lattice.len() * K` or `stripes` was made for another lattice.
pub fn scatter<const K: usize, T: Real, F>(
    cells: &Cells<T>,
    phi: &[T],
    out: &mut [f64],
    stripes: &mut Stripes,
    value: F,
) where
    F: Fn(usize, usize, &Stencil) -> [f64; K] + Sync,
{
    let lattice: Lattice = cells.lattice();
    let shape = cells.shape();
    let map = cells.map();
    let (nx, ly) = (shape.nx, lattice.ly);
    let plen = shape.len();
    assert_eq!(out.len(), lattice.len() * K);
    assert_eq!(stripes.dirty.len(), lattice.lx.div_ceil(STRIPE_ROWS));
    out.par_chunks_mut(STRIPE_ROWS * ly * K)
        .zip(stripes.dirty.par_iter_mut())
        .enumerate()
        .for_each(|(stripe, (chunk, dirty))| {
            // Zeroed before the first contribution, or at the end if there is none.
            let mut touched = false;
            let x0 = stripe * STRIPE_ROWS;
            let rows = chunk.len() / (ly * K);
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
                        chunk.iter_mut().for_each(|v| *v = 0.0);
                    }
                    touched = true;
                }
                let xs = map.cell_x(shape, i);
                let ys = map.cell_y(shape, i);
                let cell = &phi[i * plen..(i + 1) * plen];
                for a in 0..nx {
                    let x = xs[a] as usize;
                    if x < x0 || x >= x0 + rows {
                        continue;
                    }
                    let base = (x - x0) * ly;
                    for_each_stencil_in_column(cell, shape, a, &mut |k, _, b, s| {
                        let v = value(i, k, &s);
                        let node = &mut chunk[(base + ys[b] as usize) * K..][..K];
                        for c in 0..K {
                            node[c] += v[c];
                        }
                    });
                }
            }
            if !touched && *dirty {
                chunk.iter_mut().for_each(|v| *v = 0.0);
            }
            *dirty = touched;
        });
}
