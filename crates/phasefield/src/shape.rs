//! The shape of every cell's periodic patch ([`PatchShape`]) and its periodic neighbour
//! tables.
//!
//! Each cell's field `φ_i` is stored on a patch of `nx × ny` nodes.
//! In subdomain mode the patch is square with side `2m + 1` (m is the *margin*) and follows
//! the cell's centre of mass; in full-domain mode it is the whole lattice and never moves.
//!
//! A patch is periodic in itself (the paper's supplementary "domain decomposition" section).
//! Storage column `a` of cell `i` holds lattice column
//! `x = origin_x + ((a - offset_x) mod nx)  (mod lx)`, and likewise for rows.
//! When the patch moves by `d` nodes the columns that wrap around keep the values they had on
//! the far edge (near zero when the margin is large enough): the paper's algorithm changes only
//! `origin` and `offset`. [`crate::Cells::recentre`] then rotates the values into logical order
//! (`offset` back to `[0, 0]`), so that a patch column sits on consecutive lattice rows except
//! where it crosses the lattice's edge.
//!
//! All cells' values are one contiguous `Vec<f64>` with stride `patch_len`; within a patch the
//! storage index is `a * ny + b` (x slow, y contiguous, as on the [`Lattice`]).

use crate::lattice::Lattice;
use crate::PhaseFieldError;

/// The shape of every cell's patch and the periodic neighbour tables of its stencils.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PatchShape {
    /// Patch nodes along x.
    pub nx: usize,
    /// Patch nodes along y.
    pub ny: usize,
    /// The margin `m` (patch side `2m + 1`), or `None` in full-domain mode.
    pub margin: Option<usize>,
    /// `xm[a]`: the storage column left of `a`, periodic in the patch.
    pub xm: Vec<usize>,
    /// `xp[a]`: the storage column right of `a`, periodic in the patch.
    pub xp: Vec<usize>,
}

impl PatchShape {
    /// The tuned default margin m = 16 (patch side 33): from the work–precision study
    /// (`docs/performance.md`), it costs less than the paper's margin 12 at dt 0.5 and makes
    /// the centre-of-mass error after 20 TU 20× smaller, because at margin 12 the neglected
    /// tail of the tanh profile, `(1 − tanh((m − R)/λ))/2`, dominates every time-step error.
    pub const DEFAULT_MARGIN: usize = 16;

    /// A square patch of side `2 * margin + 1`, or the full lattice when `margin == 0`.
    ///
    /// # Errors
    /// [`PhaseFieldError::PatchTooLarge`] when `2 * margin + 1` exceeds a side of the lattice.
    pub fn new(lattice: Lattice, margin: usize) -> Result<Self, PhaseFieldError> {
        if margin == 0 {
            return Ok(Self::with_size(lattice.lx, lattice.ly, None));
        }
        let side = 2 * margin + 1;
        if side > lattice.lx || side > lattice.ly {
            return Err(PhaseFieldError::PatchTooLarge {
                margin,
                side,
                lx: lattice.lx,
                ly: lattice.ly,
            });
        }
        Ok(Self::with_size(side, side, Some(margin)))
    }

    fn with_size(nx: usize, ny: usize, margin: Option<usize>) -> Self {
        let xm = (0..nx).map(|a| (a + nx - 1) % nx).collect();
        let xp = (0..nx).map(|a| (a + 1) % nx).collect();
        Self {
            nx,
            ny,
            margin,
            xm,
            xp,
        }
    }

    /// Nodes in one patch.
    #[inline]
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// True in full-domain mode.
    pub fn is_full_domain(&self) -> bool {
        self.margin.is_none()
    }

    /// Storage column `a` of one patch's values and its periodic neighbours `a − 1`, `a + 1`.
    ///
    /// # Panics
    /// If `phi.len() != self.len()` or `a >= self.nx`.
    #[inline(always)]
    pub fn column_and_neighbours<'a, T>(&self, phi: &'a [T], a: usize) -> [&'a [T]; 3] {
        let ny = self.ny;
        let col = |c: usize| &phi[c * ny..(c + 1) * ny];
        [col(a), col(self.xm[a]), col(self.xp[a])]
    }
}
