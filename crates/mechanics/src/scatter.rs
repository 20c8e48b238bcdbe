//! Race-free, thread-count-independent scatter of per-cell patch values onto the lattice.
//!
//! The lattice is cut into stripes of [`STRIPE_ROWS`] x-rows. Each stripe is owned by one
//! task, which visits the cells in index order and adds the contributions of the patch
//! columns that fall inside it. Every lattice node therefore receives its contributions in cell
//! order, whatever the number of threads: results are bit-for-bit reproducible.
//!
//! The `K` summed fields live in a [`LatticeSums`], stored stripe by stripe and, inside a
//! stripe, field by field: one lattice column of one field is a contiguous slice, so that a
//! run of patch rows (`phasefield::kernel::RowRun`) reads or writes it as one vectorisable loop.
//!
//! A stripe that no patch overlaps is zeroed once and then left alone, so a scene of a few
//! cells in a large box does no work per step on the nodes no cell covers.

use phasefield::kernel::{
    for_each_run_in_column_with, ColumnPlan, ColumnScratch, RowRuns, StencilRun,
};
use phasefield::{Cells, Lattice, Real};
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
    /// The cells that overlap each stripe, in index order: `members[offsets[s]..offsets[s + 1]]`
    /// (rebuilt by every scatter; kept here so that it is allocated once).
    offsets: Vec<usize>,
    members: Vec<u32>,
    /// The row runs of every patch (rebuilt by every scatter, once per cell where each stripe
    /// would find them again; [`LatticeSums::cell_runs`]).
    runs: Vec<RowRuns>,
}

impl<const K: usize> LatticeSums<K> {
    /// Bytes of heap memory held by the sums and the stripe index.
    pub(crate) fn heap_bytes(&self) -> usize {
        self.data.capacity() * std::mem::size_of::<f64>()
            + self.dirty.capacity()
            + self.offsets.capacity() * std::mem::size_of::<usize>()
            + self.members.capacity() * std::mem::size_of::<u32>()
            + self.runs.capacity() * std::mem::size_of::<RowRuns>()
    }

    /// `K` fields on `lattice`, all zero.
    pub fn new(lattice: Lattice) -> Self {
        Self {
            lattice,
            data: vec![0.0; lattice.len() * K],
            dirty: vec![false; lattice.lx.div_ceil(STRIPE_ROWS)],
            offsets: vec![0; lattice.lx.div_ceil(STRIPE_ROWS) + 1],
            members: Vec::new(),
            runs: Vec::new(),
        }
    }

    /// `K` fields on `lattice`, all zero, with room to index `n_cells` patches `nx` columns
    /// wide, so that no scatter of such cells allocates.
    pub fn for_cells(lattice: Lattice, n_cells: usize, nx: usize) -> Self {
        let mut sums = Self::new(lattice);
        sums.members
            .reserve_exact(n_cells * Self::most_stripes(sums.dirty.len(), nx));
        sums.runs.reserve_exact(n_cells);
        sums
    }

    /// The most stripes a patch `nx` columns wide can overlap.
    fn most_stripes(n_stripes: usize, nx: usize) -> usize {
        (nx / STRIPE_ROWS + 3).min(n_stripes)
    }

    /// Lists the cells that overlap each stripe, in index order (a counting sort by stripe):
    /// O(cells), where testing every cell in every stripe is O(cells × stripes).
    fn index_stripes(&mut self, origins: &[[usize; 2]], nx: usize) {
        let lx = self.lattice.lx;
        let n_stripes = self.dirty.len();
        // The stripes of the patch columns x = ox .. ox + nx (mod lx), each once: the part up
        // to the lattice's edge, then the wrapped part, without the stripes the first part
        // already holds.
        let stripes = |ox: usize| {
            let end = ox + nx;
            let first = ox / STRIPE_ROWS..=(end.min(lx) - 1) / STRIPE_ROWS;
            let wrapped = if end > lx {
                0..((end - lx - 1) / STRIPE_ROWS + 1).min(ox / STRIPE_ROWS)
            } else {
                0..0
            };
            first.chain(wrapped)
        };
        self.offsets.fill(0);
        for o in origins {
            for s in stripes(o[0]) {
                self.offsets[s + 1] += 1;
            }
        }
        for s in 0..n_stripes {
            self.offsets[s + 1] += self.offsets[s];
        }
        let total = self.offsets[n_stripes];
        if self.members.capacity() < total {
            // Room for every cell in its largest possible number of stripes, so that cells
            // moving later never make this grow again.
            let most = Self::most_stripes(n_stripes, nx);
            self.members.reserve_exact(origins.len() * most);
        }
        self.members.resize(total, 0);
        // `offsets[s]` is now the next free slot of stripe s; afterwards it is the end of
        // stripe s, which is the start of stripe s + 1, hence the shift below.
        for (i, o) in origins.iter().enumerate() {
            for s in stripes(o[0]) {
                self.members[self.offsets[s]] = i as u32;
                self.offsets[s] += 1;
            }
        }
        for s in (1..=n_stripes).rev() {
            self.offsets[s] = self.offsets[s - 1];
        }
        self.offsets[0] = 0;
    }

    /// The row runs of cell `i`'s patch as the last scatter found them.
    ///
    /// # Panics
    /// If no scatter of at least `i + 1` cells has run.
    #[inline]
    pub fn cell_runs(&self, i: usize) -> &RowRuns {
        &self.runs[i]
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

    /// Lattice column `x` of the fields `read`, and of field `write` to change (every read
    /// field before it).
    ///
    /// # Panics
    /// If a read field is not below `write`, `write >= K` or `x >= lx`.
    pub(crate) fn columns_read_write<const R: usize>(
        &mut self,
        read: [usize; R],
        write: usize,
        x: usize,
    ) -> ([&[f64]; R], &mut [f64]) {
        assert!(read.iter().all(|&r| r < write) && write < K && x < self.lattice.lx);
        let (base, stride) = self.locate(x);
        let ly = self.lattice.ly;
        let (a, b) = self.data.split_at_mut(base + write * stride);
        let a: &[f64] = a;
        (
            read.map(|r| &a[base + r * stride..base + r * stride + ly]),
            &mut b[..ly],
        )
    }

    /// The lattice.
    pub(crate) fn lattice(&self) -> Lattice {
        self.lattice
    }

    /// Lattice column `x` of every field.
    #[inline(always)]
    pub fn columns(&self, x: usize) -> [&[f64]; K] {
        assert!(x < self.lattice.lx);
        let (base, stride) = self.locate(x);
        let ly = self.lattice.ly;
        // The K columns of the stripe's fields, cut from one slice that holds them all (one
        // bounds check, where `column` per field does K).
        let all = &self.data[base..base + (K - 1) * stride + ly];
        std::array::from_fn(|c| &all[c * stride..c * stride + ly])
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
/// `add(cell_idx)` is called once for each cell and stripe its patch overlaps, and gives the
/// cell's adder, which is called for each [`StencilRun`] of each of its patch columns in the
/// stripe, with `dst[c]` the slice of field `c` on the lattice rows of the run (`dst[c][j]` is
/// the node of `run.c[j]`); it adds its values there. The stencil lets a value use derivatives
/// of `φ_i` without a buffer of its own. (Two levels, so that what depends on the cell alone
/// is computed once per cell and stripe, not once per run, and the adder is small enough to
/// be inlined into the column loop: with one closure taking the cell's index, the minimal
/// model's step called it out of line for each column, 5 instructions per node-update of
/// overhead; issue 38.)
///
/// `finish(fields)` is then called once for each stripe that a patch overlaps, with
/// `fields[c]` the stripe's part of field `c` (its lattice columns, one after the other), once
/// every cell has added to it: it may compute fields that are functions of the sums node by
/// node, while the stripe is in cache (the pressure, in [`crate::SumField::P`]). Stripes that no
/// patch overlaps hold zeros in every field, so such a function must map zeros to zero.
pub fn scatter<const K: usize, T: Real, F, A, G>(
    cells: &Cells<T>,
    phi: &[T],
    out: &mut LatticeSums<K>,
    add: F,
    finish: G,
) where
    F: Fn(usize) -> A + Sync,
    A: Fn(&StencilRun<'_, T>, [&mut [f64]; K]),
    G: Fn([&mut [f64]; K]) + Sync,
{
    let lattice: Lattice = cells.lattice();
    assert_eq!(out.lattice, lattice, "the sums belong to another lattice");
    let shape = cells.shape();
    let map = cells.map();
    let (nx, ly) = (shape.nx, lattice.ly);
    let plen = shape.len();
    out.index_stripes(&map.origin, nx);
    out.runs.clear();
    out.runs
        .extend((0..cells.n_cells()).map(|i| RowRuns::new(map.cell_y(shape, i))));
    let (offsets, members, all_runs) = (&out.offsets, &out.members, &out.runs);
    out.data
        .par_chunks_mut(STRIPE_ROWS * ly * K)
        .zip(out.dirty.par_iter_mut())
        .enumerate()
        .for_each(|(stripe, (chunk, dirty))| {
            let x0 = stripe * STRIPE_ROWS;
            let rows = chunk.len() / (ly * K);
            let mut parts = chunk.chunks_exact_mut(rows * ly);
            let mut fields: [&mut [f64]; K] = std::array::from_fn(|_| parts.next().unwrap());
            let overlapping = &members[offsets[stripe]..offsets[stripe + 1]];
            // A stripe that is not dirty holds zeros already.
            if *dirty {
                fields.iter_mut().for_each(|f| f.fill(0.0));
            }
            *dirty = !overlapping.is_empty();
            let mut scratch = ColumnScratch::default();
            for &i in overlapping {
                let i = i as usize;
                let cell = &phi[i * plen..(i + 1) * plen];
                scatter_cell(
                    cells,
                    cell,
                    i,
                    &all_runs[i],
                    x0,
                    &mut fields,
                    &mut scratch,
                    &add(i),
                );
            }
            if !overlapping.is_empty() {
                finish(fields);
            }
        });
}

/// One cell's columns in one stripe of [`scatter`]: `fields` are the stripe's parts of the
/// fields, from lattice column `x0` on. A function of its own, never inlined, so that the
/// adder's chunk loop is compiled with this cell's values alone in the registers (inlined
/// into the stripe loop, its coefficients were reloaded from the stack at every chunk: 95
/// instructions a chunk of 8 nodes where this takes 86; issue 38).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn scatter_cell<const K: usize, T: Real, A>(
    cells: &Cells<T>,
    cell: &[T],
    i: usize,
    runs: &RowRuns,
    x0: usize,
    fields: &mut [&mut [f64]; K],
    scratch: &mut ColumnScratch<T>,
    add: &A,
) where
    A: Fn(&StencilRun<'_, T>, [&mut [f64]; K]),
{
    let (shape, map) = (cells.shape(), cells.map());
    let (nx, lx, ly) = (shape.nx, cells.lattice().lx, cells.lattice().ly);
    let rows = fields[0].len() / ly;
    let plan = ColumnPlan::new(shape, runs);
    let ([ox, _], [fx, _]) = (map.origin[i], map.offset[i]);
    // The stripe's lattice columns that the patch covers, and their storage columns (the
    // inverse of `PatchMap::cell_x`: a patch is never wider than the lattice, so a lattice
    // column holds at most one of its columns). Each lattice node gets one value per cell
    // whatever the order of the columns, so the sums are those of a visit in storage order.
    for x in x0..x0 + rows {
        // u = (x − ox) mod lx, the logical column; a = (u + fx) mod nx.
        let u = if x >= ox { x - ox } else { x + lx - ox };
        if u >= nx {
            continue;
        }
        let a = if u + fx >= nx { u + fx - nx } else { u + fx };
        debug_assert_eq!(map.cell_x(shape, i)[a] as usize, x);
        let base = (x - x0) * ly;
        for_each_run_in_column_with(cell, shape, &plan, scratch, a, &mut |s| {
            let start = base + s.run.y0;
            let mut parts = fields.iter_mut();
            let dst = std::array::from_fn(|_| {
                let f = parts.next().expect("K fields");
                &mut f[start..start + s.run.len]
            });
            add(&s, dst);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stripe index lists each cell, in index order, in exactly the stripes that its patch
    /// columns fall in: exhaustive over origins, for lattices whose width is and is not a
    /// multiple of the stripe, and patches up to the lattice's width.
    #[test]
    fn each_stripe_lists_exactly_the_cells_whose_columns_fall_in_it() {
        for lx in [8, 13, 24, 30] {
            let lattice = Lattice::new(lx, 5);
            let n_stripes = lx.div_ceil(STRIPE_ROWS);
            for nx in [1, 3, 7, 9, lx - 1, lx] {
                let origins: Vec<[usize; 2]> = (0..lx).map(|ox| [ox, 0]).collect();
                let mut sums = LatticeSums::<1>::for_cells(lattice, origins.len(), nx);
                let capacity = sums.members.capacity();
                sums.index_stripes(&origins, nx);
                assert_eq!(sums.members.capacity(), capacity, "no allocation");
                for s in 0..n_stripes {
                    let listed: Vec<usize> = sums.members[sums.offsets[s]..sums.offsets[s + 1]]
                        .iter()
                        .map(|&i| i as usize)
                        .collect();
                    let expected: Vec<usize> = (0..origins.len())
                        .filter(|&i| (0..nx).any(|u| (origins[i][0] + u) % lx / STRIPE_ROWS == s))
                        .collect();
                    assert_eq!(listed, expected, "lx {lx}, nx {nx}, stripe {s}");
                }
            }
        }
    }
}
