//! Stencils a run of rows at a time, for kernels the compiler can vectorise.
//!
//! A patch column (storage column `a`, rows `b = 0..ny`) is cut into [`RowRun`]s: storage
//! rows that sit on consecutive lattice rows, so that a lattice field is read or written as
//! one contiguous slice. A patch's rows wrap at most once in the patch (the storage offset)
//! and once on the lattice, so a column has at most three runs, and usually one or two.
//! [`for_each_run_in_column`] hands each run to a kernel as five equal-length slices
//! ([`StencilRun`]): the centres and the four neighbours. The y-neighbours come from a copy of
//! the column with one wrapped row at each end, so that the patch-periodic wrap costs no run of
//! its own. A kernel then has no index arithmetic, which is the form in which loops compile
//! to SIMD instructions.
//!
//! [`StencilRun::sum_into`] is the matching reduction: a sum over a run in [`LANES`]
//! interleaved partial sums, the form in which a floating-point reduction is vectorised. The
//! order of the additions depends only on the runs, never on the number of threads.

use crate::real::Real;
use crate::{PatchShape, Stencil};

/// Interleaved partial sums of [`StencilRun::sum_into`]: eight `f64`, one AVX-512 register or two AVX2.
pub const LANES: usize = 8;

/// Consecutive storage rows `b0..b0 + len` of a patch column that sit on consecutive lattice
/// rows `y0..y0 + len`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RowRun {
    /// First storage row.
    pub b0: usize,
    /// Rows in the run.
    pub len: usize,
    /// Lattice row of storage row `b0`.
    pub y0: usize,
}

/// The runs that cover the rows `0..ny` of every column of one patch (the same for all its
/// columns, since a patch's storage-to-lattice row map does not depend on the column).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowRuns {
    runs: [RowRun; 3],
    n: usize,
}

impl RowRuns {
    /// The runs of a patch whose storage row `b` sits on lattice row `ys[b]` (a patch's
    /// [`crate::PatchMap::cell_y`]).
    ///
    /// # Panics
    /// If `ys` is empty, or if it jumps more than twice (a patch row map wraps at most once in
    /// the patch and once on the lattice).
    pub fn new(ys: &[u32]) -> Self {
        assert!(!ys.is_empty(), "a patch has at least one row");
        let mut runs = Self {
            runs: [RowRun::default(); 3],
            n: 0,
        };
        let mut start = 0;
        for b in 1..=ys.len() {
            if b == ys.len() || ys[b] != ys[b - 1] + 1 {
                assert!(runs.n < 3, "a patch row map jumps at most twice: {ys:?}");
                runs.runs[runs.n] = RowRun {
                    b0: start,
                    len: b - start,
                    y0: ys[start] as usize,
                };
                runs.n += 1;
                start = b;
            }
        }
        runs
    }

    /// The runs, in storage order.
    #[inline]
    pub fn as_slice(&self) -> &[RowRun] {
        &self.runs[..self.n]
    }
}

/// The five-point stencils of one [`RowRun`] of a patch column: five slices of equal length,
/// element `j` of each holding the centre and the four neighbours of storage row `b0 + j`.
#[derive(Debug, Clone, Copy)]
pub struct StencilRun<'a, T> {
    /// The run.
    pub run: RowRun,
    /// Centre values.
    pub c: &'a [T],
    /// Values at `x − 1`.
    pub xm: &'a [T],
    /// Values at `x + 1`.
    pub xp: &'a [T],
    /// Values at `y − 1`.
    pub ym: &'a [T],
    /// Values at `y + 1`.
    pub yp: &'a [T],
}

impl<T: Real> StencilRun<'_, T> {
    /// The same run with every slice cut to the run's length, so that the compiler sees one
    /// length for all five, and one test of a chunk's end against it bounds all their loads
    /// (uncut, the force pass's chunk tested each slice: 15 compares and branches of 101).
    #[inline(always)]
    fn cut(&self) -> Self {
        let n = self.c.len();
        Self {
            run: self.run,
            c: self.c,
            xm: &self.xm[..n],
            xp: &self.xp[..n],
            ym: &self.ym[..n],
            yp: &self.yp[..n],
        }
    }

    /// Calls `store(j, value(stencil_j, values_j))` for every element `j` of the run, where
    /// `values_j[m]` is `fields[m][j]`: the form of an element-wise kernel that compiles to
    /// SIMD instructions (slices of the run's length, no index arithmetic). `store` should
    /// index slices cut to the run's length, so that it needs no bounds check.
    ///
    /// # Panics
    /// If a field is shorter than the run.
    #[inline(always)]
    pub fn map<const M: usize, const K: usize>(
        &self,
        fields: [&[f64]; M],
        value: impl Fn(Stencil, [f64; M]) -> [f64; K],
        mut store: impl FnMut(usize, [f64; K]),
    ) {
        let n = self.c.len();
        let (c, xm, xp, ym, yp) = (
            &self.c[..n],
            &self.xm[..n],
            &self.xp[..n],
            &self.ym[..n],
            &self.yp[..n],
        );
        let fields: [&[f64]; M] = std::array::from_fn(|m| &fields[m][..n]);
        for j in 0..n {
            let s = Stencil {
                c: c[j].to_f64(),
                xm: xm[j].to_f64(),
                xp: xp[j].to_f64(),
                ym: ym[j].to_f64(),
                yp: yp[j].to_f64(),
            };
            store(j, value(s, std::array::from_fn(|m| fields[m][j])));
        }
    }

    /// `out[k][j] = value(stencil_j, values_j)[k]` for every element `j` of the run, rounded
    /// to the output type: [`StencilRun::map`] for a kernel that writes its results, in
    /// chunks of [`LANES`] elements that compile to SIMD instructions (see
    /// [`StencilRun::add_to`]).
    ///
    /// # Panics
    /// If a field or an output is shorter than the run.
    #[inline(always)]
    pub fn write_to<const M: usize, const K: usize, O: Real>(
        &self,
        fields: [&[f64]; M],
        value: impl Fn(Stencil, [f64; M]) -> [f64; K],
        out: [&mut [O]; K],
    ) {
        self.map_chunks::<M, K, O, false>(fields, value, out);
    }

    /// `out[k][j] += value(stencil_j, values_j)[k]` for every element `j` of the run: the
    /// form of a scatter onto lattice fields.
    ///
    /// The run is cut into chunks of [`LANES`] elements, each loaded into registers, computed
    /// and stored as straight-line SIMD code: no loop for the compiler to vectorise, so no
    /// runtime overlap checks between the outputs and the inputs, and no scalar tail. The last
    /// chunk ends at the run's end and overlaps the one before it; its repeated lanes get a
    /// weight of zero (see `map_chunk`). A run shorter than [`LANES`] is
    /// done one element at a time. Each element is computed from the same inputs by the same
    /// operations as in [`StencilRun::map`], so the results are the same to the bit for
    /// finite values.
    ///
    /// # Panics
    /// If a field or an output is shorter than the run.
    #[inline(always)]
    pub fn add_to<const M: usize, const K: usize>(
        &self,
        fields: [&[f64]; M],
        value: impl Fn(Stencil, [f64; M]) -> [f64; K],
        out: [&mut [f64]; K],
    ) {
        self.map_chunks::<M, K, f64, true>(fields, value, out);
    }

    #[inline(always)]
    fn map_chunks<const M: usize, const K: usize, O: Real, const ADD: bool>(
        &self,
        fields: [&[f64]; M],
        value: impl Fn(Stencil, [f64; M]) -> [f64; K],
        out: [&mut [O]; K],
    ) {
        let this = self.cut();
        let n = this.c.len();
        assert!(fields.iter().all(|f| f.len() >= n) && out.iter().all(|o| o.len() >= n));
        let fields: [&[f64]; M] = std::array::from_fn(|m| &fields[m][..n]);
        // Not `out.map(…)`: an array map of `K` slices was a call per run, out of line (1.6
        // instructions per node-update in the scatter, issue 38).
        let mut outs = out.into_iter();
        let mut out: [&mut [O]; K] =
            std::array::from_fn(|_| &mut outs.next().expect("K outputs")[..n]);
        if n < LANES {
            this.map(fields, &value, |j, v| {
                for k in 0..K {
                    out[k][j] = O::from_f64(if ADD { out[k][j].to_f64() + v[k] } else { v[k] });
                }
            });
            return;
        }
        let mut j = 0;
        while j + LANES <= n {
            this.map_chunk::<M, K, O, ADD, LANES>(&fields, j, 0, &value, &mut out);
            // Opaque to the optimiser, so that LLVM's loop vectoriser leaves this loop alone:
            // on a long run (a padded patch) it vectorised the right-hand side's loop across
            // chunks, each vector gathered from four chunks: 164 instructions per chunk, against
            // about 100 with this barrier.
            j = std::hint::black_box(j + LANES);
        }
        if j < n {
            // As in `sum_into`: half a chunk when at most half of the last one is new.
            let skip = LANES - (n - j);
            if skip >= HALF {
                this.map_chunk::<M, K, O, ADD, HALF>(
                    &fields,
                    n - HALF,
                    skip - HALF,
                    &value,
                    &mut out,
                );
            } else {
                this.map_chunk::<M, K, O, ADD, LANES>(&fields, n - LANES, skip, &value, &mut out);
            }
        }
    }

    /// Writes or adds the `W` elements from `j`. Writing the elements below `skip` (done by an
    /// earlier chunk) again stores the same values; with `ADD` they get `0 × value` added, as in
    /// [`StencilRun::sum_into`]: a multiply, which compiles to clean SIMD code where a select
    /// did not (225 instructions for the 8 lanes instead of about 90). For a finite value this
    /// adds a zero, which leaves a sum unchanged: a sum that starts at `+0` is never `−0`.
    #[inline(always)]
    fn map_chunk<const M: usize, const K: usize, O: Real, const ADD: bool, const W: usize>(
        &self,
        fields: &[&[f64]; M],
        j: usize,
        skip: usize,
        value: &impl Fn(Stencil, [f64; M]) -> [f64; K],
        out: &mut [&mut [O]; K],
    ) {
        let mut v = [[0.0; W]; K];
        self.for_each_lane::<M, K, W>(fields, j, value, |l, r| {
            for k in 0..K {
                v[k][l] = r[k];
            }
        });
        for k in 0..K {
            let o: &mut [O; W] = (&mut out[k][j..j + W])
                .try_into()
                .expect("a chunk is W long");
            for l in 0..W {
                o[l] = if ADD {
                    let w = if l >= skip { 1.0 } else { 0.0 };
                    O::from_f64(o[l].to_f64() + w * v[k][l])
                } else {
                    O::from_f64(v[k][l])
                };
            }
        }
    }

    /// Adds `value(stencil, values)` of every element of the run to the [`LANES`] partial
    /// sums `acc`, component by component, where `values[m]` is `fields[m][j]`: element `j`
    /// goes to lane `j mod LANES`, except the elements past the last whole chunk, which go to
    /// the lanes they have in the chunk that ends at the run's end (a run shorter than
    /// [`LANES`] goes to lanes `0, 1, …`). This is the form in which a floating-point sum
    /// compiles to SIMD instructions; keep `acc` over all the runs of a patch and add its
    /// lanes once at the end ([`add_lanes`]).
    ///
    /// The result is a fixed function of the values and the runs, whatever the number of
    /// threads; it may differ in the last bits from a sequential sum.
    ///
    /// # Panics
    /// If a field is shorter than the run.
    #[inline(always)]
    pub fn sum_into<const M: usize, const K: usize>(
        &self,
        fields: [&[f64]; M],
        value: impl Fn(Stencil, [f64; M]) -> [f64; K],
        acc: &mut [[f64; LANES]; K],
    ) {
        let this = self.cut();
        let n = this.c.len();
        let fields: [&[f64]; M] = std::array::from_fn(|m| &fields[m][..n]);
        let mut j = 0;
        while j + LANES <= n {
            this.sum_chunk::<M, K, LANES, 0>(&fields, j, 0, &value, acc);
            // No optimisation barrier here, unlike `map_chunks`: LLVM does not vectorise this
            // loop across chunks (the partial sums carry a dependence from chunk to chunk), and
            // a `black_box` on `j` cost 2 instructions per chunk of the force pass and of the
            // shape tensor (callgrind, 85.7 → 85.0 instructions per node-update without it).
            j += LANES;
        }
        if j < n && n >= LANES {
            // The chunk that ends at the run's end, whose first lanes repeat the chunk before;
            // when at most half of it is new, only its second half is computed (the lanes the
            // first half would have added to get weight zero anyway): the same sums, to the bit.
            let skip = LANES - (n - j);
            if skip >= HALF {
                this.sum_chunk::<M, K, HALF, HALF>(&fields, n - HALF, skip, &value, acc);
            } else {
                this.sum_chunk::<M, K, LANES, 0>(&fields, n - LANES, skip, &value, acc);
            }
        } else if n < LANES {
            // A short run, one element at a time into lanes 0, 1, …
            this.map(fields, &value, |l, v| {
                for k in 0..K {
                    acc[k][l] += v[k];
                }
            });
        }
    }

    /// Adds the `W` elements from `j` to lanes `OFF..OFF + W` of the partial sums, except the
    /// lanes below `skip` (already taken by an earlier chunk), which get a weight of zero: a
    /// multiply, not a branch, so that the chunk stays one SIMD computation.
    #[inline(always)]
    fn sum_chunk<const M: usize, const K: usize, const W: usize, const OFF: usize>(
        &self,
        fields: &[&[f64]; M],
        j: usize,
        skip: usize,
        value: &impl Fn(Stencil, [f64; M]) -> [f64; K],
        acc: &mut [[f64; LANES]; K],
    ) {
        self.for_each_lane::<M, K, W>(fields, j, value, |l, v| {
            let w = if OFF + l >= skip { 1.0 } else { 0.0 };
            for k in 0..K {
                acc[k][OFF + l] += w * v[k];
            }
        });
    }

    /// Calls `lane(l, value(stencil, values))` for the `W` elements `j + l` from `j`, loaded
    /// and widened once: the one body of every chunk of [`StencilRun::sum_into`],
    /// [`StencilRun::write_to`] and [`StencilRun::add_to`]. (Handing each lane on, rather
    /// than returning an array of them, keeps `sum_into`'s chunk at its measured instruction
    /// count: the array cost it 1.3 instructions per node-update.)
    #[inline(always)]
    fn for_each_lane<const M: usize, const K: usize, const W: usize>(
        &self,
        fields: &[&[f64]; M],
        j: usize,
        value: &impl Fn(Stencil, [f64; M]) -> [f64; K],
        mut lane: impl FnMut(usize, [f64; K]),
    ) {
        let c = load::<T, W>(self.c, j);
        let (xm, xp) = (load::<T, W>(self.xm, j), load::<T, W>(self.xp, j));
        let (ym, yp) = (load::<T, W>(self.ym, j), load::<T, W>(self.yp, j));
        let f: [[f64; W]; M] = std::array::from_fn(|m| load(fields[m], j));
        for l in 0..W {
            let s = Stencil {
                c: c[l],
                xm: xm[l],
                xp: xp[l],
                ym: ym[l],
                yp: yp[l],
            };
            lane(l, value(s, std::array::from_fn(|m| f[m][l])));
        }
    }
}

/// The sums of [`LANES`] partial sums, each added in lane order.
#[inline(always)]
pub fn add_lanes<const K: usize>(acc: &[[f64; LANES]; K]) -> [f64; K] {
    std::array::from_fn(|k| acc[k].iter().sum())
}

/// Half a chunk: the width of the last chunk of a run when at most half of it is new.
const HALF: usize = LANES / 2;

/// `W` values of `s` from element `j`, widened to `f64`.
#[inline(always)]
fn load<T: Real, const W: usize>(s: &[T], j: usize) -> [f64; W] {
    let a = &s[j..j + W];
    std::array::from_fn(|l| a[l].to_f64())
}

/// Columns up to this many rows get their y-neighbours from a copy on the stack (see the
/// module docs); longer ones (full-domain storage) split their first and last rows into runs
/// of one row, whose cost is negligible there.
pub const MAX_COPIED_ROWS: usize = 64;

/// How the columns of one patch are cut into [`StencilRun`]s: the runs with the storage rows of
/// their y∓1 neighbours, the same for every column of the patch (its storage-to-lattice row
/// map does not depend on the column). Build it once per patch and sweep, not per column.
#[derive(Debug, Clone, Copy)]
pub struct ColumnPlan {
    /// Each piece: a run, and where its y−1 and y+1 neighbours start in the neighbour rows.
    pieces: [(RowRun, usize, usize); 5],
    count: usize,
    /// Whether the neighbours come from a copy of the column ([`ColumnScratch`]) or from the
    /// column itself (patches of more than [`MAX_COPIED_ROWS`] rows).
    copied: bool,
}

impl ColumnPlan {
    /// The plan for a patch of this shape whose rows are cut into `runs`.
    #[inline]
    pub fn new(shape: &PatchShape, runs: &RowRuns) -> Self {
        let ny = shape.ny;
        let mut plan = Self {
            pieces: [(RowRun::default(), 0, 0); 5],
            count: 0,
            copied: ny <= MAX_COPIED_ROWS,
        };
        // Each piece is a run with the storage rows of its y∓1 neighbours, taken from the
        // copy or from the row itself. ext[b] is row b − 1, periodic: the y−1 neighbours of
        // rows b0.. are ext[b0..], the y+1 neighbours ext[b0 + 2..].
        if plan.copied {
            for &run in runs.as_slice() {
                plan.pieces[plan.count] = (run, run.b0, run.b0 + 2);
                plan.count += 1;
            }
        } else {
            for &run in runs.as_slice() {
                // Cut off the patch's first and last rows, whose neighbours wrap.
                let end = run.b0 + run.len;
                let first = usize::from(run.b0 == 0);
                let last = usize::from(end == ny && run.len > first);
                let piece = |b0: usize, len: usize, ym0: usize, yp0: usize| {
                    let y0 = run.y0 + (b0 - run.b0);
                    (RowRun { b0, len, y0 }, ym0, yp0)
                };
                if first == 1 {
                    plan.pieces[plan.count] = piece(0, 1, ny - 1, 1);
                    plan.count += 1;
                }
                let (b0, b1) = (run.b0 + first, end - last);
                if b1 > b0 {
                    plan.pieces[plan.count] = piece(b0, b1 - b0, b0 - 1, b0 + 1);
                    plan.count += 1;
                }
                if last == 1 {
                    plan.pieces[plan.count] = piece(ny - 1, 1, ny - 2, 0);
                    plan.count += 1;
                }
            }
        }
        plan
    }
}

/// The copy of a column with one wrapped row at each end, from which the y-neighbours of its
/// runs are read: on the stack, and reused from column to column (made once per sweep, so that
/// it is not zeroed for every column).
#[derive(Debug, Clone, Copy)]
pub struct ColumnScratch<T>([T; MAX_COPIED_ROWS + 2]);

impl<T: Real> Default for ColumnScratch<T> {
    fn default() -> Self {
        Self([T::default(); MAX_COPIED_ROWS + 2])
    }
}

/// Calls `f` with the [`StencilRun`] of each run of storage column `a` of one patch, cut as
/// `plan` says, with `scratch` for the column's copy.
///
/// # Panics
/// If `phi.len() != shape.len()`, `a >= shape.nx` or the plan is not one for this shape.
#[inline(always)]
pub fn for_each_run_in_column_with<T: Real, F: FnMut(StencilRun<'_, T>)>(
    phi: &[T],
    shape: &PatchShape,
    plan: &ColumnPlan,
    scratch: &mut ColumnScratch<T>,
    a: usize,
    f: &mut F,
) {
    let ny = shape.ny;
    let [row, row_m, row_p] = shape.column_and_neighbours(phi, a);
    let neighbours: &[T] = if plan.copied {
        let ext = &mut scratch.0;
        ext[0] = row[ny - 1];
        ext[1..=ny].copy_from_slice(row);
        ext[ny + 1] = row[0];
        &ext[..]
    } else {
        row
    };
    // One call site of `f`, so that the kernel is inlined once.
    for &(run, ym0, yp0) in &plan.pieces[..plan.count] {
        let RowRun { b0, len, .. } = run;
        f(StencilRun {
            run,
            c: &row[b0..b0 + len],
            xm: &row_m[b0..b0 + len],
            xp: &row_p[b0..b0 + len],
            ym: &neighbours[ym0..ym0 + len],
            yp: &neighbours[yp0..yp0 + len],
        });
    }
}

/// Calls `f` with the [`StencilRun`] of each run of storage column `a` of one patch: the plan
/// and the scratch of [`for_each_run_in_column_with`] made for this column alone (for a sweep
/// over a whole patch, make them once and use that function).
///
/// # Panics
/// If `phi.len() != shape.len()`, `a >= shape.nx` or the runs are not a patch's of this shape.
#[inline(always)]
pub fn for_each_run_in_column<T: Real, F: FnMut(StencilRun<'_, T>)>(
    phi: &[T],
    shape: &PatchShape,
    runs: &RowRuns,
    a: usize,
    f: &mut F,
) {
    let plan = ColumnPlan::new(shape, runs);
    for_each_run_in_column_with(phi, shape, &plan, &mut ColumnScratch::default(), a, f);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::for_each_stencil;
    use crate::Lattice;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The lattice rows of storage rows `0..ny` of a patch with origin row `oy` and storage
    /// offset `fy` on a lattice of height `ly` (as `PatchMap` builds them).
    fn rows(ny: usize, ly: usize, oy: usize, fy: usize) -> Vec<u32> {
        (0..ny)
            .map(|b| ((oy + (b + ny - fy) % ny) % ly) as u32)
            .collect()
    }

    /// Every patch row map (any side, lattice height, origin and offset) is cut into at most
    /// three runs that cover the rows once, in order, with contiguous lattice rows.
    /// Exhaustive over small sizes.
    #[test]
    fn runs_cover_every_row_once_with_contiguous_lattice_rows() {
        for ny in 1..=9 {
            for ly in ny..=12 {
                for oy in 0..ly {
                    for fy in 0..ny {
                        let ys = rows(ny, ly, oy, fy);
                        let runs = RowRuns::new(&ys);
                        let mut next = 0;
                        for r in runs.as_slice() {
                            assert_eq!(r.b0, next, "runs in order, no gap: {ys:?}");
                            assert!(r.len > 0);
                            for j in 0..r.len {
                                assert_eq!(ys[r.b0 + j] as usize, r.y0 + j, "{ys:?}");
                            }
                            next += r.len;
                        }
                        assert_eq!(next, ny);
                    }
                }
            }
        }
    }

    /// A periodic `nx × ny` patch (the full domain of that lattice).
    fn shape(nx: usize, ny: usize) -> PatchShape {
        PatchShape::new(Lattice::new(nx, ny), 0).expect("margin 0 always fits")
    }

    proptest! {
        // A fixed seed: the same cases on every run and machine (nalgebra's
        // `TestRunner::deterministic()`).
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x6d6f_6e6f),
            ..ProptestConfig::default()
        })]

        /// `map` hands each node exactly the stencil `for_each_stencil` does, `write_to` and
        /// `add_to` store or add exactly its values, once per node, and `sum_into`
        /// gives the sequential sum to round-off (the bound is a few ulps of the sum of
        /// magnitudes, since only the order of the additions differs): on runs cut by any row
        /// map, for columns copied to the stack and for longer ones.
        #[test]
        fn map_and_sum_agree_with_the_node_by_node_stencil(
            nx in 1usize..8,
            ny in prop_oneof![1usize..40, MAX_COPIED_ROWS - 2..MAX_COPIED_ROWS + 6],
            extra in 0usize..5,
            oy in 0usize..1000,
            fy in 0usize..1000,
            seed in any::<u64>(),
        ) {
            let shape = shape(nx, ny);
            let ly = ny + extra;
            let runs = RowRuns::new(&rows(ny, ly, oy % ly, fy % ny));
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let phi: Vec<f64> = (0..shape.len()).map(|_| rng.random_range(-0.25..0.75)).collect();
            let value = |s: crate::Stencil, [w]: [f64; 1]| [s.laplacian() * w, s.dx() * s.dy()];
            let mut expected = vec![[0.0; 2]; shape.len()];
            let (mut seq, mut mag) = ([0.0; 2], 0.0);
            for_each_stencil(&phi, &shape, |k, s| {
                expected[k] = value(s, [k as f64]);
                seq[0] += expected[k][0];
                seq[1] += expected[k][1];
                mag += expected[k][0].abs() + expected[k][1].abs();
            });
            let mut got = vec![[f64::NAN; 2]; shape.len()];
            // write_to and add_to, component by component, onto a base that add_to adds to.
            let base: Vec<f64> = (0..shape.len()).map(|k| (k % 7) as f64 - 3.5).collect();
            let mut written = [vec![f64::NAN; shape.len()], vec![f64::NAN; shape.len()]];
            let mut added = [base.clone(), base.clone()];
            let mut acc = [[0.0; LANES]; 2];
            for a in 0..shape.nx {
                let weights: Vec<f64> = (0..shape.ny).map(|b| (a * shape.ny + b) as f64).collect();
                for_each_run_in_column(&phi, &shape, &runs, a, &mut |run| {
                    let (b0, n) = (run.run.b0, run.run.len);
                    let w = &weights[b0..b0 + n];
                    let k0 = a * shape.ny + b0;
                    let out = &mut got[k0..][..n];
                    run.map([w], value, |j, v| out[j] = v);
                    run.sum_into([w], value, &mut acc);
                    let [w0, w1] = &mut written;
                    run.write_to([w], value, [&mut w0[k0..k0 + n], &mut w1[k0..k0 + n]]);
                    let [a0, a1] = &mut added;
                    run.add_to([w], value, [&mut a0[k0..k0 + n], &mut a1[k0..k0 + n]]);
                });
            }
            prop_assert_eq!(&got, &expected);
            // Bit for bit: the chunked maps do each element's arithmetic as `map` does, and
            // every node is written, or added to, exactly once.
            for k in 0..shape.len() {
                for c in 0..2 {
                    prop_assert_eq!(written[c][k].to_bits(), expected[k][c].to_bits());
                    prop_assert_eq!(added[c][k].to_bits(), (base[k] + expected[k][c]).to_bits());
                }
            }
            let total = add_lanes(&acc);
            let tol = 8.0 * f64::EPSILON * mag;
            prop_assert!((total[0] - seq[0]).abs() <= tol && (total[1] - seq[1]).abs() <= tol);
        }
    }
}
