//! The bytes of every buffer of the step ([`Sizes`]): what the backend allocates, and what
//! the memory estimate ([`GpuMemory`]) adds up, from one computation.

use phasefield::{Lattice, PatchShape};

use crate::bindings::Slot;
use crate::features::{self, Dims, On};

use crate::shared::{Kinds, Params};
use crate::shared::{CELL_STRIDE, WG};

/// The smallest buffer: what stands in for one a state does not need.
pub(crate) const PLACEHOLDER: u64 = 16;

/// The bytes of the step's buffers for one layout.
#[derive(Debug, Clone)]
pub(crate) struct Sizes {
    /// One φ array: every cell's patch in f32, before it is split into chunks.
    pub phi_array: u64,
    /// The φ arrays of a step: 3 (φ, the predictor, `R(φ)`), 4 with `npc` ≥ 2.
    pub phi_arrays: u64,
    /// Every other buffer bound at a slot, with its bytes (placeholders included).
    pub slots: Vec<(Slot, u64)>,
}

impl Sizes {
    /// The buffers of `n` cells on patches of `shape` on `lattice`, stepped with `npc`
    /// corrector passes, with the lattice arrays' first binding `split` nodes long, the
    /// chunks' partial sums when `several` chunks, and the features `on`.
    pub fn of(
        lattice: Lattice,
        shape: &PatchShape,
        n: usize,
        npc: usize,
        split: usize,
        several: bool,
        on: On,
    ) -> Self {
        let nodes = lattice.len();
        let (lo, hi) = (nodes.min(split) as u64, nodes.saturating_sub(split) as u64);
        let (nb, cap) = bins(lattice, shape, n);
        let n = n as u64;
        let some = |needed: bool, bytes: u64| {
            if needed {
                bytes.max(PLACEHOLDER)
            } else {
                PLACEHOLDER
            }
        };
        let mut slots = vec![
            (Slot::Params, std::mem::size_of::<Params>() as u64),
            (Slot::Cell, some(true, n * CELL_STRIDE as u64 * 4)),
            (Slot::Origin, some(true, n * 8)),
            (Slot::Lat, some(true, lo * 16)),
            (Slot::LatHi, some(hi > 0, hi * 16)),
            (Slot::BinCount, some(true, u64::from(nb) * 4)),
            (
                Slot::BinCells,
                some(true, u64::from(nb) * u64::from(cap) * 4),
            ),
            (Slot::Trig, some(true, (lattice.lx + lattice.ly) as u64 * 8)),
            (Slot::Status, PLACEHOLDER),
            (Slot::AccA, some(several, lo * 16)),
            (Slot::AccAHi, some(several && hi > 0, hi * 16)),
            (Slot::AccB, some(several, lo * 16)),
            (Slot::AccBHi, some(several && hi > 0, hi * 16)),
            (Slot::Kinds, std::mem::size_of::<Kinds>() as u64),
            (
                Slot::V2Part,
                some(true, u64::from((nodes as u32).div_ceil(WG)) * 4),
            ),
        ];
        let dims = Dims {
            nodes: nodes as u64,
            cells: n,
        };
        for f in features::all(on) {
            for (slot, bytes) in f.buffers(dims) {
                slots.push((slot, some(f.on(), bytes)));
            }
        }
        Self {
            phi_array: n * shape.len() as u64 * 4,
            phi_arrays: if npc >= 2 { 4 } else { 3 },
            slots,
        }
    }

    /// Every buffer together.
    pub fn total(&self) -> u64 {
        self.phi_arrays * self.phi_array + self.slots.iter().map(|&(_, b)| b).sum::<u64>()
    }
}

/// What the device holds, in bytes, for a state: for the memory estimate and its refusal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuMemory {
    /// One φ array (all cells' patches in f32), before it is split into chunks.
    pub phi_array: u64,
    /// The φ arrays of a step: 3 (φ, the predictor, `R(φ)`), 4 with `npc` ≥ 2.
    pub phi_arrays: u64,
    /// Every buffer together.
    pub total: u64,
}

impl GpuMemory {
    /// The device memory of `n_cells` cells on patches of `shape` on `lattice`, stepped with
    /// `npc` corrector passes, with the extensions `parts`: the buffers the backend allocates
    /// (`Sizes`), with the lattice in one binding and the chunks' partial sums counted (an
    /// upper bound: a state in one chunk needs none), and division counted with its growth
    /// phase.
    pub fn estimate(
        lattice: Lattice,
        shape: &PatchShape,
        n_cells: usize,
        npc: usize,
        parts: &[mechanics::Part],
    ) -> Self {
        let sizes = Sizes::of(
            lattice,
            shape,
            n_cells,
            npc,
            usize::MAX,
            true,
            On::of_parts(parts),
        );
        Self {
            phi_array: sizes.phi_array,
            phi_arrays: sizes.phi_arrays,
            total: sizes.total(),
        }
    }

    /// The estimate in words, for messages: `"3 φ arrays of 1.23 GB, 3.80 GB in all"`.
    pub fn describe(&self) -> String {
        format!(
            "{} φ arrays of {:.2} GB, {:.2} GB in all",
            self.phi_arrays,
            self.phi_array as f64 / 1e9,
            self.total as f64 / 1e9
        )
    }
}

/// The bins of patch origins for the gather: `(number of bins, cells per bin)`. A bin is at
/// least a patch wide, so the patches over a node have their origins in the node's bin or the
/// one before it, in each direction.
pub(crate) fn bins(lattice: Lattice, shape: &PatchShape, n_cells: usize) -> (u32, u32) {
    let (nbx, nby) = bin_grid(lattice, shape);
    let nb = nbx * nby;
    let per_bin = n_cells.div_ceil(nb as usize) as u32;
    let cap = (8 * per_bin).max(32).min(n_cells.max(1) as u32);
    (nb, cap)
}

pub(crate) fn bin_grid(lattice: Lattice, shape: &PatchShape) -> (u32, u32) {
    (
        (lattice.lx / shape.nx).max(1) as u32,
        (lattice.ly / shape.ny).max(1) as u32,
    )
}
