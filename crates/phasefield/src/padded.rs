//! A patch copied with its ghost rows and columns, so that a whole patch is one [`StencilRun`].
//!
//! [`PaddedPatch::fill`] copies a patch's values (widened to `f64`) into columns of `ny + 2`
//! rows, each with the wrapped row above and below it, between two wrapped columns. In that
//! layout the four neighbours of every node sit at fixed distances (`±1`, `±(ny + 2)`), so the
//! nodes from the patch's first to its last are one run of `(nx − 1)(ny + 2) + ny` positions:
//! one sweep with no per-column set-up and a single overlapping last chunk, at the price of
//! computing the two ghost rows between columns too (8 % more positions at side 25, 6 % at 33),
//! whose values the kernels weight by zero ([`PaddedParts::mask`]). Lattice fields that a
//! kernel reads are gathered into the same layout ([`PaddedPatch::gather`]), and a kernel that
//! writes per node writes into [`PaddedParts::out`], copied back by [`PaddedPatch::store`].
//!
//! This replaced, for the per-cell passes of the step, the column by column sweeps of
//! [`crate::kernel::for_each_run_in_column_with`], whose per-column set-up (slices, the lattice
//! columns, the column's copy for its y-neighbours, and a last chunk of which at most a few
//! lanes are new) was about half of the step's instructions (`docs/performance.md`).

use crate::real::Real;
use crate::runs::{RowRun, RowRuns, StencilRun};
use crate::PatchShape;

/// A patch in the padded layout, with up to `M` lattice fields gathered beside it and a buffer
/// for per-node results: the scratch of one thread, reused from cell to cell (it allocates only
/// when it first meets a larger patch).
#[derive(Debug, Clone, Default)]
pub struct PaddedPatch<const M: usize> {
    nx: usize,
    ny: usize,
    /// The padded values: `nx + 2` columns of `ny + 2` rows; column `a + 1`, row `b + 1` holds
    /// storage node `(a, b)`.
    phi: Vec<f64>,
    /// 1 where a position of the run is a patch node, 0 on the ghost rows between columns.
    mask: Vec<f64>,
    /// `M` gathered fields of `len()` positions each, field `m` at `m * len()..`.
    fields: Vec<f64>,
    /// Per-node results of a kernel, `len()` positions.
    out: Vec<f64>,
}

/// The parts of a [`PaddedPatch`] a kernel works with at once, borrowed together.
#[derive(Debug)]
pub struct PaddedParts<'a, const M: usize> {
    /// The stencils of every position of the run.
    pub run: StencilRun<'a, f64>,
    /// 1 at a patch node, 0 at a ghost row: multiply a per-node value by it before summing.
    pub mask: &'a [f64],
    /// The gathered lattice fields, each `run`'s length (0 at the ghost rows).
    pub fields: [&'a [f64]; M],
    /// Per-node results, `run`'s length; [`PaddedPatch::store`] copies the patch nodes back.
    pub out: &'a mut [f64],
}

impl<const M: usize> PaddedPatch<M> {
    /// An empty scratch; [`PaddedPatch::fill`] sizes it.
    pub fn new() -> Self {
        Self::default()
    }

    /// Rows per padded column.
    #[inline(always)]
    fn stride(&self) -> usize {
        self.ny + 2
    }

    /// Positions in the run: from node `(0, 0)` to node `(nx − 1, ny − 1)`.
    #[inline(always)]
    pub fn len(&self) -> usize {
        lengths(self.nx, self.ny).1
    }

    /// Bytes of heap memory held by the buffers.
    pub fn heap_bytes(&self) -> usize {
        (self.phi.capacity() + self.mask.capacity() + self.fields.capacity() + self.out.capacity())
            * std::mem::size_of::<f64>()
    }

    /// The bytes [`PaddedPatch::heap_bytes`] reports once the scratch is prepared for `shape`
    /// and nothing larger: `8 ((nx + 2)(ny + 2) + (M + 2) n)`, `n` the run's length.
    pub fn bytes_for(shape: &PatchShape) -> usize {
        let (padded, n) = lengths(shape.nx, shape.ny);
        (padded + (M + 2) * n) * std::mem::size_of::<f64>()
    }

    /// True before the first [`PaddedPatch::fill`].
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sizes the buffers for `shape` ([`PaddedPatch::fill`] does it too); the gathered fields
    /// are zeroed when the shape changes, so that the ghost rows hold finite values. Buffers
    /// only grow: a scratch that has seen a patch this large allocates nothing here.
    pub fn prepare(&mut self, shape: &PatchShape) {
        if (self.nx, self.ny) == (shape.nx, shape.ny) {
            return;
        }
        self.nx = shape.nx;
        self.ny = shape.ny;
        let ((padded, n), p) = (lengths(shape.nx, shape.ny), self.stride());
        // `reserve_exact`, so that a scratch holds what `bytes_for` says.
        let exact = |v: &mut Vec<f64>, len: usize| {
            v.clear();
            v.reserve_exact(len);
        };
        exact(&mut self.phi, padded);
        self.phi.resize(padded, 0.0);
        exact(&mut self.mask, n);
        self.mask
            .extend((0..n).map(|k| if k % p < shape.ny { 1.0 } else { 0.0 }));
        exact(&mut self.fields, M * n);
        self.fields.resize(M * n, 0.0);
        exact(&mut self.out, n);
        self.out.resize(n, 0.0);
    }

    /// Copies one patch's values (`shape.len()` of them, in storage order), widened to `f64`,
    /// with the wrapped rows and columns: the patch is periodic in its storage indices, as in
    /// [`crate::for_each_stencil`].
    ///
    /// # Panics
    /// If `phi.len() != shape.len()`.
    pub fn fill<T: Real>(&mut self, phi: &[T], shape: &PatchShape) {
        assert_eq!(phi.len(), shape.len(), "one patch's values");
        self.prepare(shape);
        let (nx, ny, p) = (self.nx, self.ny, self.stride());
        for (a, src) in phi.chunks_exact(ny).enumerate() {
            let dst = &mut self.phi[(a + 1) * p..(a + 2) * p];
            dst[0] = src[ny - 1].to_f64();
            // A plain loop, which LLVM vectorises (8 values a step) or, in f64, makes a
            // `memcpy` of: `copy_widened` cost twice as much here (9.9 against 6.0 instructions
            // per node-update for the two fills of an evaluation).
            for (d, s) in dst[1..=ny].iter_mut().zip(src) {
                *d = s.to_f64();
            }
            dst[ny + 1] = src[0].to_f64();
        }
        // The ghost columns, corners included (a stencil centred on a ghost row reads them).
        let (left, right) = (shape.xm[0], shape.xp[nx - 1]);
        self.phi.copy_within((left + 1) * p..(left + 2) * p, 0);
        self.phi
            .copy_within((right + 1) * p..(right + 2) * p, (nx + 1) * p);
    }

    /// Gathers `M` lattice fields for the filled patch: `columns(x)` gives lattice column `x` of
    /// each field (rows `0..ly`), `xs[a]` is the lattice column of storage column `a`, and
    /// `runs` cut every column's storage rows into runs of consecutive lattice rows.
    ///
    /// # Panics
    /// If `xs` has not one entry per column, or a run reaches past a column or a field.
    // Never inlined, here and in `store`: inlined into the force pass, LLVM compiled the copies
    // less well (0.8 instructions per node-update more in the minimal model).
    #[inline(never)]
    pub fn gather<'f>(
        &mut self,
        xs: &[u32],
        runs: &RowRuns,
        columns: impl Fn(usize) -> [&'f [f64]; M],
    ) {
        assert_eq!(xs.len(), self.nx, "a lattice column for every patch column");
        let (n, p) = (self.len(), self.stride());
        let mut parts = self.fields.chunks_exact_mut(n.max(1));
        let mut fields: [&mut [f64]; M] =
            std::array::from_fn(|_| parts.next().expect("M fields of len() each"));
        for (a, &x) in xs.iter().enumerate() {
            let cols = columns(x as usize);
            for &RowRun { b0, len, y0 } in runs.as_slice() {
                let at = a * p + b0;
                let mut dst = fields.iter_mut();
                copy_runs::<M>(
                    std::array::from_fn(|_| &mut dst.next().expect("M fields")[at..at + len]),
                    std::array::from_fn(|m| &cols[m][y0..y0 + len]),
                );
            }
        }
    }

    /// The gathered fields alone (for a scratch that gathers beside another one's patch, in
    /// the same layout: [`PaddedPatch::prepare`] it with the same shape, then
    /// [`PaddedPatch::gather`]).
    pub fn gathered(&self) -> [&[f64]; M] {
        let n = self.len();
        std::array::from_fn(|m| &self.fields[m * n..(m + 1) * n])
    }

    /// The run, the mask, the gathered fields and the output buffer, borrowed together.
    pub fn parts(&mut self) -> PaddedParts<'_, M> {
        let (n, p) = (self.len(), self.stride());
        let start = p + 1;
        let phi = &self.phi[..];
        let fields = &self.fields[..];
        PaddedParts {
            run: StencilRun {
                run: RowRun {
                    b0: 0,
                    len: n,
                    y0: 0,
                },
                c: &phi[start..start + n],
                xm: &phi[start - p..start - p + n],
                xp: &phi[start + p..start + p + n],
                ym: &phi[start - 1..start - 1 + n],
                yp: &phi[start + 1..start + 1 + n],
            },
            mask: &self.mask,
            fields: std::array::from_fn(|m| &fields[m * n..(m + 1) * n]),
            out: &mut self.out,
        }
    }

    /// Copies the patch nodes of the output buffer into `out` (one patch, storage order),
    /// rounded to its type.
    ///
    /// # Panics
    /// If `out` is not one patch of the filled shape.
    #[inline(never)]
    pub fn store<T: Real>(&self, out: &mut [T]) {
        let (ny, p) = (self.ny, self.stride());
        assert_eq!(out.len(), self.nx * ny, "one patch's values");
        for (a, dst) in out.chunks_exact_mut(ny).enumerate() {
            for (d, s) in dst.iter_mut().zip(&self.out[a * p..a * p + ny]) {
                *d = T::from_f64(*s);
            }
        }
    }
}

/// `dst[m][j] = src[m][j]` for every `m` and `j` (the slices of equal length), in
/// straight-line chunks of four, the last one overlapping the one before. Written as
/// `copy_from_slice`, each copy of a run was a call to `memcpy`, whose set-up is most of the
/// cost of copying 25 values: the force pass's gather of five lattice sums took 14.3
/// instructions per node-update that way, 12.1 this way.
#[inline(always)]
fn copy_runs<const M: usize>(dst: [&mut [f64]; M], src: [&[f64]; M]) {
    const W: usize = 4;
    let n = src[0].len();
    let src = src.map(|s| &s[..n]);
    let dst = dst.map(|d| &mut d[..n]);
    assert!(dst.iter().all(|d| d.len() == n), "equal lengths");
    if n < W {
        for m in 0..M {
            for j in 0..n {
                dst[m][j] = src[m][j];
            }
        }
        return;
    }
    let mut j = 0;
    loop {
        for m in 0..M {
            dst[m][j..j + W].copy_from_slice(&src[m][j..j + W]);
        }
        if j + W == n {
            break;
        }
        // The next chunk, or the last W elements. Opaque to the optimiser, which would
        // otherwise see the loop as M copies and call `memcpy` for each.
        j = std::hint::black_box((j + W).min(n - W));
    }
}

/// The lengths of a padded patch of `nx × ny` nodes: its values with the ghost rows and
/// columns, `(nx + 2)(ny + 2)`, and its run, `(nx − 1)(ny + 2) + ny` (0 for no patch).
#[inline(always)]
fn lengths(nx: usize, ny: usize) -> (usize, usize) {
    let p = ny + 2;
    let run = if nx == 0 { 0 } else { (nx - 1) * p + ny };
    ((nx + 2) * p, run)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::for_each_stencil;
    use crate::runs::{add_lanes, LANES};
    use crate::Lattice;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A scratch prepared for a shape holds what `bytes_for` says, and a smaller shape
    /// afterwards allocates nothing more.
    #[test]
    fn a_prepared_scratch_holds_what_bytes_for_says() {
        for (nx, ny) in [(1, 1), (25, 25), (33, 33), (7, 19)] {
            let shape = PatchShape::new(Lattice::new(nx, ny), 0).unwrap();
            let mut padded = PaddedPatch::<4>::new();
            padded.prepare(&shape);
            assert_eq!(padded.heap_bytes(), PaddedPatch::<4>::bytes_for(&shape));
            let small = PatchShape::new(Lattice::new(1, 1), 0).unwrap();
            padded.prepare(&small);
            assert_eq!(padded.heap_bytes(), PaddedPatch::<4>::bytes_for(&shape));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x7061_6464),
            ..ProptestConfig::default()
        })]

        /// At every patch node the padded run hands the stencil `for_each_stencil` does (to the
        /// bit: the same values, copied), the gathered fields are the lattice values of the
        /// node (cut by any row map, as the force pass reads them), `store` puts each node's
        /// output back on its node, and the masked sum over the run is the sequential sum to
        /// round-off (only the order of the additions differs; the ghost rows add zero): for
        /// patches of any side, reused across sizes.
        #[test]
        fn the_padded_run_is_the_node_by_node_stencil(
            sizes in proptest::collection::vec((1usize..12, 1usize..30, 0usize..5, 0usize..1000, 0usize..1000), 1..4),
            seed in any::<u64>(),
        ) {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut padded = PaddedPatch::<2>::new();
            for (nx, ny, extra, oy, ox) in sizes {
                let lattice = Lattice::new(nx + extra, ny + extra);
                let shape = PatchShape::new(Lattice::new(nx, ny), 0).expect("margin 0 always fits");
                let phi: Vec<f32> = (0..shape.len()).map(|_| rng.random_range(-0.25f32..0.75)).collect();
                // Lattice fields, and where the patch sits: origin (ox, oy), wrapping at the edge.
                let fields: Vec<Vec<f64>> = (0..2)
                    .map(|_| (0..lattice.lx * lattice.ly).map(|_| rng.random_range(-1.0..1.0)).collect())
                    .collect();
                let xs: Vec<u32> = (0..nx).map(|a| ((ox + a) % lattice.lx) as u32).collect();
                let ys: Vec<u32> = (0..ny).map(|b| ((oy + b) % lattice.ly) as u32).collect();
                let runs = RowRuns::new(&ys);
                padded.fill(&phi, &shape);
                let ly = lattice.ly;
                padded.gather(&xs, &runs, |x| [&fields[0][x * ly..(x + 1) * ly], &fields[1][x * ly..(x + 1) * ly]]);
                let value = |s: crate::Stencil, [w, f]: [f64; 2]| [w * s.laplacian() * f, w * s.dx() * s.dy()];
                let mut expected = vec![[0.0; 2]; shape.len()];
                let (mut seq, mut mag) = ([0.0; 2], 0.0);
                for_each_stencil(&phi, &shape, |k, s| {
                    let (a, b) = (k / ny, k % ny);
                    let f = fields[0][xs[a] as usize * ly + ys[b] as usize];
                    expected[k] = value(s, [1.0, f]);
                    seq[0] += expected[k][0];
                    seq[1] += expected[k][1];
                    mag += expected[k][0].abs() + expected[k][1].abs();
                });
                let PaddedParts { run, mask, fields: gathered, out } = padded.parts();
                let mut acc = [[0.0; LANES]; 2];
                run.sum_into([mask, gathered[0]], value, &mut acc);
                run.map([mask, gathered[0]], value, |j, v| out[j] = v[0]);
                let mut stored = vec![f64::NAN; shape.len()];
                padded.store(&mut stored);
                for a in 0..nx {
                    for b in 0..ny {
                        let k = a * ny + b;
                        prop_assert_eq!(stored[k].to_bits(), expected[k][0].to_bits());
                    }
                }
                let total = add_lanes(&acc);
                let tol = 8.0 * f64::EPSILON * mag;
                prop_assert!((total[0] - seq[0]).abs() <= tol && (total[1] - seq[1]).abs() <= tol,
                    "{total:?} vs {seq:?}");
            }
        }
    }
}
