//! Race-free, thread-count-independent scatter of per-cell patch values onto the lattice.
//!
//! The lattice is cut into stripes of [`STRIPE_ROWS`] x-rows. Each stripe is owned by one
//! task, which visits the cells in index order and adds the contributions of the patch
//! columns that fall inside it. Every lattice node therefore receives its contributions in cell
//! order, whatever the number of threads: results are bit-for-bit reproducible.

use phasefield::{Cells, Lattice, Real, Stencil};
use rayon::prelude::*;

/// Lattice x-rows per scatter stripe (fixed, so that the result never depends on threads).
pub const STRIPE_ROWS: usize = 8;

/// Adds `value(cell_idx, k, stencil)` (K components) of every patch node `k` of every cell
/// to the lattice field `out`, laid out as `out[node * K + component]`. The stencil holds `φ_i`
/// at the node and its four neighbours on the periodic patch, widened to `f64`, so that a
/// value may use derivatives of `φ_i` without a buffer of its own. `out` is zeroed first.
///
/// # Panics
/// If `out.len() != lattice.len() * K`.
pub fn scatter<const K: usize, T: Real, F>(cells: &Cells<T>, phi: &[T], out: &mut [f64], value: F)
where
    F: Fn(usize, usize, &Stencil) -> [f64; K] + Sync,
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
                // (x0 − ox) mod lx without a division: this test runs for every cell in
                // every stripe.
                let mut u0 = x0 + lattice.lx - ox;
                if u0 >= lattice.lx {
                    u0 -= lattice.lx;
                }
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
                    let row = &cell[a * ny..(a + 1) * ny];
                    let row_m = &cell[shape.xm[a] * ny..(shape.xm[a] + 1) * ny];
                    let row_p = &cell[shape.xp[a] * ny..(shape.xp[a] + 1) * ny];
                    for b in 0..ny {
                        let k = a * ny + b;
                        let bm = if b == 0 { ny - 1 } else { b - 1 };
                        let bp = if b + 1 == ny { 0 } else { b + 1 };
                        let s = Stencil {
                            c: row[b].to_f64(),
                            xm: row_m[b].to_f64(),
                            xp: row_p[b].to_f64(),
                            ym: row[bm].to_f64(),
                            yp: row[bp].to_f64(),
                        };
                        let v = value(i, k, &s);
                        let node = &mut chunk[(base + ys[b] as usize) * K..][..K];
                        for c in 0..K {
                            node[c] += v[c];
                        }
                    }
                }
            }
        });
}
