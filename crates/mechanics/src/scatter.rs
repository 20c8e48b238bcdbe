//! Race-free, thread-count-independent scatter of per-cell patch values onto the lattice.
//!
//! The lattice is cut into stripes of [`STRIPE_ROWS`] x-rows. Each stripe is owned by one
//! task, which visits the cells in index order and adds the contributions of the patch
//! columns that fall inside it. Every lattice node therefore receives its contributions in cell
//! order, whatever the number of threads: results are bit-for-bit reproducible.

use phasefield::{Cells, Lattice, Real};
use rayon::prelude::*;

/// Lattice x-rows per scatter stripe (fixed, so that the result never depends on threads).
pub const STRIPE_ROWS: usize = 8;

/// Adds `value(cell_idx, k, φ)` (K components, with `φ` widened to `f64`) of every patch node `k` of every cell to the
/// lattice field `out`, laid out as `out[node * K + component]`. `out` is zeroed first.
///
/// # Panics
/// If `out.len() != lattice.len() * K`.
pub fn scatter<const K: usize, T: Real, F>(
    cells: &Cells<T>,
    phi: &[T],
    out: &mut [f64],
    value: F,
) where
    F: Fn(usize, usize, f64) -> [f64; K] + Sync,
{
    let lattice: Lattice = cells.lattice();
    let shape = cells.shape();
    let map = cells.map();
    let (nx, ny, ly) = (shape.nx, shape.ny, lattice.ly);
    let plen = shape.len();
    assert_eq!(out.len(), lattice.len() * K);
    out.par_chunks_mut(STRIPE_ROWS * ly * K)
        .enumerate()
        .for_each(|(stripe, chunk)| {
            chunk.iter_mut().for_each(|v| *v = 0.0);
            let x0 = stripe * STRIPE_ROWS;
            let rows = chunk.len() / (ly * K);
            for i in 0..cells.n_cells() {
                let ox = map.origin[i][0];
                let u0 = (x0 + lattice.lx - ox) % lattice.lx;
                if u0 >= nx && u0 + rows <= lattice.lx {
                    continue;
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
                    for b in 0..ny {
                        let k = a * ny + b;
                        let v = value(i, k, cell[k].to_f64());
                        let node = &mut chunk[(base + ys[b] as usize) * K..][..K];
                        for c in 0..K {
                            node[c] += v[c];
                        }
                    }
                }
            }
        });
}
