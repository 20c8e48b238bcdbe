//! Stencils a run of rows at a time, for kernels the compiler can vectorise.
//!
//! A patch column (storage column `a`, rows `b = 0..ny`) is cut into at most five
//! [`RowRun`]s. Inside a run the storage rows are consecutive, the lattice rows are
//! consecutive (so a lattice field is read or written as one contiguous slice), and the
//! y-neighbours of the run's rows are the consecutive storage rows `ym0..` and `yp0..`. The
//! two patch-edge rows, whose y-neighbour wraps around the patch, are runs of one row each.
//! A kernel then sees five equal-length slices ([`StencilRun`]) and no index arithmetic, which
//! is the form in which loops are compiled to SIMD instructions.
//!
//! [`StencilRun::sum`] is the matching reduction: a sum over a run in
//! [`LANES`] interleaved partial results, the form in which a floating-point reduction is
//! vectorised. The order of the additions depends only on the run's length, never on the
//! number of threads.

use crate::patch::{PatchShape, Stencil};
use crate::real::Real;

/// Interleaved partial sums of [`StencilRun::sum`]: eight `f64`, one AVX-512 register or two AVX2.
pub const LANES: usize = 8;

/// Consecutive storage rows `b0..b0 + len` of a patch column that sit on consecutive lattice
/// rows `y0..y0 + len`, with their y-neighbours at storage rows `ym0..ym0 + len` and
/// `yp0..yp0 + len`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RowRun {
    /// First storage row.
    pub b0: usize,
    /// Rows in the run.
    pub len: usize,
    /// Lattice row of storage row `b0`.
    pub y0: usize,
    /// Storage row of the `y − 1` neighbour of `b0`.
    pub ym0: usize,
    /// Storage row of the `y + 1` neighbour of `b0`.
    pub yp0: usize,
}

/// The runs that cover the rows `0..ny` of every column of one patch (the same for all its
/// columns, since a patch's storage-to-lattice row map does not depend on the column).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowRuns {
    runs: [RowRun; 5],
    n: usize,
}

impl RowRuns {
    /// The runs of a patch whose storage row `b` sits on lattice row `ys[b]` (a patch's
    /// [`crate::PatchMap::cell_y`]).
    ///
    /// # Panics
    /// If `ys` is empty, or if consecutive rows of it jump more than twice (a patch row map
    /// wraps at most once in the patch and once on the lattice).
    pub fn new(ys: &[u32]) -> Self {
        Self::from_rows(ys.len(), |b| ys[b] as usize)
    }

    /// The runs of a patch without regard to the lattice: an edge row, the interior, an edge
    /// row (`y0` is the storage row). For kernels that touch no lattice field.
    pub fn patch(ny: usize) -> Self {
        Self::from_rows(ny, |b| b)
    }

    fn from_rows(ny: usize, ys: impl Fn(usize) -> usize) -> Self {
        assert!(ny > 0, "a patch has at least one row");
        let mut runs = Self {
            runs: [RowRun::default(); 5],
            n: 0,
        };
        if ny == 1 {
            runs.push(RowRun {
                b0: 0,
                len: 1,
                y0: ys(0),
                ym0: 0,
                yp0: 0,
            });
            return runs;
        }
        runs.push(RowRun {
            b0: 0,
            len: 1,
            y0: ys(0),
            ym0: ny - 1,
            yp0: 1,
        });
        let mut start = 1;
        for b in 2..ny {
            if ys(b) != ys(b - 1) + 1 {
                runs.push_interior(ys(start), start, b);
                start = b;
            }
        }
        if ny > 2 {
            runs.push_interior(ys(start), start, ny - 1);
        }
        runs.push(RowRun {
            b0: ny - 1,
            len: 1,
            y0: ys(ny - 1),
            ym0: ny - 2,
            yp0: 0,
        });
        runs
    }

    fn push_interior(&mut self, y0: usize, start: usize, end: usize) {
        if end > start {
            self.push(RowRun {
                b0: start,
                len: end - start,
                y0,
                ym0: start - 1,
                yp0: start + 1,
            });
        }
    }

    fn push(&mut self, run: RowRun) {
        assert!(
            self.n < self.runs.len(),
            "a patch row map jumps at most twice"
        );
        self.runs[self.n] = run;
        self.n += 1;
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
        let fields = fields.map(|f| &f[..n]);
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

    /// Sums `value(stencil, values)` over the run, component by component, where
    /// `values[m]` is `fields[m][j]`. The sum runs in [`LANES`] interleaved partial sums
    /// (`acc[l]` takes the elements `j ≡ l (mod LANES)`), added at the end in lane order,
    /// which is the form in which a floating-point reduction compiles to SIMD instructions.
    /// The elements past the last whole chunk go to the lanes they have in the chunk that ends
    /// at the run's end; a run shorter than [`LANES`] goes to lanes `0, 1, …`.
    ///
    /// The result is a fixed function of the values and the run's length, whatever the number
    /// of threads; it may differ in the last bits from a sequential sum.
    ///
    /// # Panics
    /// If a field is shorter than the run.
    #[inline(always)]
    pub fn sum<const M: usize, const K: usize>(
        &self,
        fields: [&[f64]; M],
        value: impl Fn(Stencil, [f64; M]) -> [f64; K],
    ) -> [f64; K] {
        let n = self.c.len();
        let fields = fields.map(|f| &f[..n]);
        let mut acc = [[0.0; LANES]; K];
        let mut j = 0;
        while j + LANES <= n {
            self.sum_chunk(&fields, j, 0, &value, &mut acc);
            j += LANES;
        }
        if j < n && n >= LANES {
            self.sum_chunk(&fields, n - LANES, LANES - (n - j), &value, &mut acc);
        } else {
            for (l, j) in (j..n).enumerate() {
                let s = Stencil {
                    c: self.c[j].to_f64(),
                    xm: self.xm[j].to_f64(),
                    xp: self.xp[j].to_f64(),
                    ym: self.ym[j].to_f64(),
                    yp: self.yp[j].to_f64(),
                };
                let v = value(s, std::array::from_fn(|m| fields[m][j]));
                for k in 0..K {
                    acc[k][l] += v[k];
                }
            }
        }
        acc.map(|a| a.iter().sum())
    }

    /// Adds the `LANES` elements from `j` to the partial sums, except the lanes below `skip`
    /// (already taken by an earlier chunk), which get a weight of zero: a multiply, not a
    /// branch, so that the chunk stays one SIMD computation.
    #[inline(always)]
    fn sum_chunk<const M: usize, const K: usize>(
        &self,
        fields: &[&[f64]; M],
        j: usize,
        skip: usize,
        value: &impl Fn(Stencil, [f64; M]) -> [f64; K],
        acc: &mut [[f64; LANES]; K],
    ) {
        let c = load(self.c, j);
        let (xm, xp) = (load(self.xm, j), load(self.xp, j));
        let (ym, yp) = (load(self.ym, j), load(self.yp, j));
        let f: [[f64; LANES]; M] = fields.map(|f| load(f, j));
        for l in 0..LANES {
            let s = Stencil {
                c: c[l],
                xm: xm[l],
                xp: xp[l],
                ym: ym[l],
                yp: yp[l],
            };
            let v = value(s, std::array::from_fn(|m| f[m][l]));
            let w = if l >= skip { 1.0 } else { 0.0 };
            for k in 0..K {
                acc[k][l] += w * v[k];
            }
        }
    }
}

/// `LANES` values of `s` from element `j`, widened to `f64`.
#[inline(always)]
fn load<T: Real>(s: &[T], j: usize) -> [f64; LANES] {
    let a: &[T; LANES] = s[j..j + LANES].try_into().expect("LANES elements");
    a.map(T::to_f64)
}

/// Calls `f` with the [`StencilRun`] of each run of storage column `a` of one patch.
///
/// # Panics
/// If `phi.len() != shape.len()`, `a >= shape.nx` or the runs are not a patch's of this shape.
#[inline(always)]
pub fn for_each_run_in_column<'a, T: Real, F: FnMut(StencilRun<'a, T>)>(
    phi: &'a [T],
    shape: &PatchShape,
    runs: &RowRuns,
    a: usize,
    f: &mut F,
) {
    let ny = shape.ny;
    let row = &phi[a * ny..(a + 1) * ny];
    let row_m = &phi[shape.xm[a] * ny..(shape.xm[a] + 1) * ny];
    let row_p = &phi[shape.xp[a] * ny..(shape.xp[a] + 1) * ny];
    for &run in runs.as_slice() {
        let RowRun {
            b0, len, ym0, yp0, ..
        } = run;
        f(StencilRun {
            run,
            c: &row[b0..b0 + len],
            xm: &row_m[b0..b0 + len],
            xp: &row_p[b0..b0 + len],
            ym: &row[ym0..ym0 + len],
            yp: &row[yp0..yp0 + len],
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::for_each_stencil;
    use crate::Lattice;
    use proptest::prelude::*;

    /// Every patch row map (any side, lattice height, origin and offset) is cut into runs that
    /// cover the rows once, in order, with contiguous lattice rows and the right periodic
    /// y-neighbours. Exhaustive over small sizes.
    #[test]
    fn runs_cover_every_row_once_with_contiguous_lattice_rows() {
        for ny in 1..=9 {
            for ly in ny..=12 {
                for oy in 0..ly {
                    for fy in 0..ny {
                        let ys: Vec<u32> = (0..ny)
                            .map(|b| ((oy + (b + ny - fy) % ny) % ly) as u32)
                            .collect();
                        let runs = RowRuns::new(&ys);
                        let mut next = 0;
                        for r in runs.as_slice() {
                            assert_eq!(r.b0, next, "runs in order, no gap: {ys:?}");
                            assert!(r.len > 0);
                            for j in 0..r.len {
                                let b = r.b0 + j;
                                assert_eq!(ys[b] as usize, r.y0 + j, "lattice rows: {ys:?}");
                                if ny > 1 {
                                    assert_eq!(r.ym0 + j, (b + ny - 1) % ny);
                                    assert_eq!(r.yp0 + j, (b + 1) % ny);
                                } else {
                                    assert_eq!((r.ym0, r.yp0), (0, 0));
                                }
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
        /// `map` hands each node exactly the stencil `for_each_stencil` does, and `sum` equals
        /// the sequential sum to round-off (the bound is a few ulps of the sum of magnitudes,
        /// since only the order of the additions differs).
        #[test]
        fn map_and_sum_agree_with_the_node_by_node_stencil(
            nx in 1usize..12,
            ny in 1usize..40,
            seed in any::<u64>(),
        ) {
            let shape = shape(nx, ny);
            let mut state = seed | 1;
            let phi: Vec<f64> = (0..shape.len())
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state >> 11) as f64 / (1u64 << 53) as f64 - 0.25
                })
                .collect();
            let value = |s: crate::Stencil, [w]: [f64; 1]| [s.laplacian() * w, s.dx() * s.dy()];
            let mut expected = vec![[0.0; 2]; shape.len()];
            let (mut seq, mut mag) = ([0.0; 2], 0.0);
            for_each_stencil(&phi, &shape, |k, s| {
                expected[k] = value(s, [k as f64]);
                seq[0] += expected[k][0];
                seq[1] += expected[k][1];
                mag += expected[k][0].abs() + expected[k][1].abs();
            });
            let runs = RowRuns::patch(shape.ny);
            let mut got = vec![[f64::NAN; 2]; shape.len()];
            let mut total = [0.0; 2];
            for a in 0..shape.nx {
                let weights: Vec<f64> = (0..shape.ny).map(|b| (a * shape.ny + b) as f64).collect();
                for_each_run_in_column(&phi, &shape, &runs, a, &mut |run| {
                    let (b0, n) = (run.run.b0, run.run.len);
                    let w = &weights[b0..b0 + n];
                    let out = &mut got[a * shape.ny + b0..][..n];
                    run.map([w], value, |j, v| out[j] = v);
                    let s = run.sum([w], value);
                    total[0] += s[0];
                    total[1] += s[1];
                });
            }
            prop_assert_eq!(&got, &expected);
            let tol = 8.0 * f64::EPSILON * mag;
            prop_assert!((total[0] - seq[0]).abs() <= tol && (total[1] - seq[1]).abs() <= tol);
        }
    }
}
