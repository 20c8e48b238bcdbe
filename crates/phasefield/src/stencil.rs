//! The five-point stencil ([`Stencil`]) and its node-by-node loops over a patch, the
//! reference form of every kernel (the step's kernels use `crate::runs`).

use crate::real::Real;
use crate::shape::PatchShape;

/// The values of the five-point stencil around one node.
#[derive(Debug, Clone, Copy)]
pub struct Stencil {
    /// Centre value.
    pub c: f64,
    /// Value at `x - 1`.
    pub xm: f64,
    /// Value at `x + 1`.
    pub xp: f64,
    /// Value at `y - 1`.
    pub ym: f64,
    /// Value at `y + 1`.
    pub yp: f64,
}

impl Stencil {
    /// Central difference `∂x f = (f[x+1] − f[x−1]) / 2`.
    #[inline(always)]
    pub fn dx(&self) -> f64 {
        0.5 * self.diff_x()
    }
    /// Central difference `∂y f = (f[y+1] − f[y−1]) / 2`.
    #[inline(always)]
    pub fn dy(&self) -> f64 {
        0.5 * self.diff_y()
    }
    /// The undivided central difference `f[x+1] − f[x−1] = 2 ∂x f`.
    ///
    /// For kernels that are homogeneous in the gradient: they take the factor ½ once, outside
    /// their loop, instead of once per node. Since scaling by a power of 2 is exact in
    /// floating point (away from overflow and subnormal numbers), `(v/2)·(2∂f)` and `v·∂f`, or
    /// `½ Σ 2g` and `Σ g`, are the same numbers to the bit.
    #[inline(always)]
    pub fn diff_x(&self) -> f64 {
        self.xp - self.xm
    }
    /// The undivided central difference `f[y+1] − f[y−1] = 2 ∂y f` (see [`Stencil::diff_x`]).
    #[inline(always)]
    pub fn diff_y(&self) -> f64 {
        self.yp - self.ym
    }
    /// Five-point Laplacian `f[x+1] + f[x−1] + f[y+1] + f[y−1] − 4 f`.
    #[inline(always)]
    pub fn laplacian(&self) -> f64 {
        self.xp + self.xm + self.yp + self.ym - 4.0 * self.c
    }
}

/// Calls `f(k, stencil)` for every node `k = a * ny + b` of one patch, with periodic wrap
/// inside the patch.
///
/// # Panics
/// If `phi.len() != shape.len()`.
#[inline(always)]
pub fn for_each_stencil<T: Real, F: FnMut(usize, Stencil)>(
    phi: &[T],
    shape: &PatchShape,
    mut f: F,
) {
    for_each_stencil_at(phi, shape, |k, _, _, s| f(k, s));
}

/// Calls `f(k, a, b, stencil)` for every node `k = a * ny + b` (storage column `a`, row `b`)
/// of one patch, with periodic wrap inside the patch; rows are visited in order, so that a
/// kernel can look up per-column data once per column.
///
/// # Panics
/// If `phi.len() != shape.len()`.
#[inline(always)]
pub fn for_each_stencil_at<T: Real, F: FnMut(usize, usize, usize, Stencil)>(
    phi: &[T],
    shape: &PatchShape,
    mut f: F,
) {
    assert_eq!(phi.len(), shape.len());
    for a in 0..shape.nx {
        for_each_stencil_in_column(phi, shape, a, &mut f);
    }
}

/// Calls `f(k, a, b, stencil)` for every row `b` of storage column `a` of one patch
/// (`k = a * ny + b`), with periodic wrap inside the patch: the column loop of
/// [`for_each_stencil_at`], for kernels that visit only some columns (the lattice scatter).
///
/// # Panics
/// If `phi.len() != shape.len()` or `a >= shape.nx`.
#[inline(always)]
pub fn for_each_stencil_in_column<T: Real, F: FnMut(usize, usize, usize, Stencil)>(
    phi: &[T],
    shape: &PatchShape,
    a: usize,
    f: &mut F,
) {
    let ny = shape.ny;
    let [row, row_m, row_p] = shape.column_and_neighbours(phi, a);
    let k0 = a * ny;
    if ny == 1 {
        f(
            k0,
            a,
            0,
            Stencil {
                c: row[0].to_f64(),
                xm: row_m[0].to_f64(),
                xp: row_p[0].to_f64(),
                ym: row[0].to_f64(),
                yp: row[0].to_f64(),
            },
        );
        return;
    }
    f(
        k0,
        a,
        0,
        Stencil {
            c: row[0].to_f64(),
            xm: row_m[0].to_f64(),
            xp: row_p[0].to_f64(),
            ym: row[ny - 1].to_f64(),
            yp: row[1].to_f64(),
        },
    );
    for b in 1..ny - 1 {
        f(
            k0 + b,
            a,
            b,
            Stencil {
                c: row[b].to_f64(),
                xm: row_m[b].to_f64(),
                xp: row_p[b].to_f64(),
                ym: row[b - 1].to_f64(),
                yp: row[b + 1].to_f64(),
            },
        );
    }
    f(
        k0 + ny - 1,
        a,
        ny - 1,
        Stencil {
            c: row[ny - 1].to_f64(),
            xm: row_m[ny - 1].to_f64(),
            xp: row_p[ny - 1].to_f64(),
            ym: row[ny - 2].to_f64(),
            yp: row[0].to_f64(),
        },
    );
}
