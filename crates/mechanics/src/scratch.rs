//! Each thread's scratch for the per-cell passes of an evaluation (`crate::kernels`): a padded
//! copy of the patch it works on and what is gathered beside it. A leaf module, so that the
//! workspace can size it without importing the kernels.

use std::cell::RefCell;

use phasefield::kernel::PaddedPatch;
use phasefield::PatchShape;

/// The lattice sums the force pass reads, gathered beside each patch: `P`, `s2`, `Q_xx`, `Q_xy`.
pub(crate) const N_GATHERED: usize = 4;

thread_local! {
    /// Each thread's copy of the patch it works on, in the padded layout of [`PaddedPatch`]
    /// (one run per patch), with the four lattice fields the force pass reads gathered beside
    /// it (`P`, `s2`, `Q_xx`, `Q_xy`): sized for every thread of the pool when a workspace is
    /// made ([`prepare_scratch`]), and grown only when a thread meets a larger patch, so a step
    /// allocates nothing. A cell's results depend only on its own values, never on what the
    /// scratch held before, so they do not depend on which thread computed them.
    pub(crate) static PADDED: RefCell<PaddedPatch<N_GATHERED>> = RefCell::new(PaddedPatch::new());

    /// Each thread's gathered node-term coefficients (`a`, `b` of [`NodeTerms`]) beside the
    /// patch in [`PADDED`], in the same layout: used only with adhesion or walls, and made on
    /// the first evaluation that has them.
    pub(crate) static NODE_TERMS: RefCell<PaddedPatch<2>> = RefCell::new(PaddedPatch::new());
}

/// Sizes the scratch of every thread of the current rayon pool (the global one outside a pool)
/// for patches of this shape, so that no step allocates it: [`crate::Workspace::new`] calls
/// this. A thread of another pool makes its scratch on its first evaluation instead.
pub(crate) fn prepare_scratch(shape: &PatchShape) {
    rayon::broadcast(|_| PADDED.with_borrow_mut(|padded| padded.prepare(shape)));
}

/// Bytes of heap memory held by the scratch of the threads of the current rayon pool (the
/// global one outside a pool).
pub(crate) fn scratch_bytes() -> usize {
    rayon::broadcast(|_| PADDED.with_borrow(|padded| padded.heap_bytes()))
        .into_iter()
        .sum()
}

/// The bytes of one thread's scratch for patches of this shape: what
/// [`crate::Workspace::heap_bytes`] counts for each thread of a pool that has met no larger
/// patch.
pub fn thread_scratch_bytes(shape: &PatchShape) -> usize {
    PaddedPatch::<N_GATHERED>::bytes_for(shape)
}
