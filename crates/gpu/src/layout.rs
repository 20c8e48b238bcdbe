//! How the state is laid out on a device: the chunks of the per-cell arrays, the split of
//! the lattice arrays, the bins of the gather ([`Layout`]), and the buffers allocated from
//! their sizes ([`allocate`]).

use std::collections::HashMap;

use phasefield::{Lattice, PatchShape};
use wgpu::util::DeviceExt;

use crate::bindings::Slot;
use crate::device::{Device, GpuError};
use crate::kernels::Buffers;
use crate::memory::Sizes;
use crate::shader::Variant;
use crate::shared::Chunk;
use crate::shared::WG;

/// Workgroups along one dimension of a dispatch (Vulkan's guaranteed minimum).
const MAX_GROUPS: u32 = 65_535;

/// How the backend lays out the state (for tests and measurements; the defaults fit it to
/// the device).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// The most cells in one chunk of the per-cell φ arrays; `None`: as many as the device's
    /// largest storage binding holds (2³¹ − 1 bytes on Vulkan: about 490 k cells at margin
    /// 16). A smaller figure splits a small state into chunks, which tests the split.
    pub max_chunk_cells: Option<usize>,
    /// The most lattice nodes in the first binding of each lattice array (the rest go into a
    /// second); `None`: as many as a binding holds (2³¹ − 1 bytes: 1.3·10⁸ nodes of 16
    /// bytes, a lattice of 11 585² or about 800 k cells at the paper's density). A smaller
    /// figure splits a small lattice, which tests the split.
    pub max_lattice_nodes: Option<usize>,
    /// The form of the kernels ([`Variant`]; the plain one by default).
    pub variant: Variant,
}

/// The split of cells `0..n` into chunks of at most `per` cells: `(lo, count)` each.
pub(crate) fn chunks(n: usize, per: usize) -> Vec<(usize, usize)> {
    let per = per.max(1);
    (0..n.div_ceil(per).max(1))
        .map(|k| (k * per, per.min(n - (k * per).min(n))))
        .collect()
}

/// A grid of workgroups for `n` of them: `(x, y)` with `x ≤ 65535`.
pub(crate) fn grid(n: u32) -> (u32, u32) {
    let x = n.clamp(1, MAX_GROUPS);
    (x, n.div_ceil(x).max(1))
}

/// The chunks and the lattice split of a state on a device.
pub(crate) struct Layout {
    /// The most cells in a chunk.
    pub per_chunk: usize,
    /// The chunks, `(lo, count)`.
    pub chunks: Vec<(usize, usize)>,
    /// The most nodes in the first binding of a lattice array.
    pub split: usize,
}

impl Layout {
    /// The layout of `n` cells on patches of `shape` on `lattice` on the device `dev`, as
    /// `options` say.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when a patch, or the lattice in two bindings, passes the
    /// device's largest binding; [`GpuError::Setting`] when the shared-patch variant's
    /// workgroup memory does not fit.
    pub fn fit(
        dev: &Device,
        lattice: Lattice,
        shape: &PatchShape,
        n: usize,
        options: GpuOptions,
    ) -> Result<Self, GpuError> {
        let patch_bytes = shape.len() as u64 * 4;
        let fit = (dev.max_binding() / patch_bytes) as usize;
        if fit == 0 || n > u32::MAX as usize / 2 {
            return Err(GpuError::TooLarge(format!(
                "{n} cells on patches of {}×{}: the device's largest binding of {:.2} GB ({}) holds {fit} patches; reduce [integrator] margin or [cells] count",
                shape.nx,
                shape.ny,
                dev.max_binding() as f64 / 1e9,
                dev.describe()
            )));
        }
        let per_chunk = options
            .max_chunk_cells
            .unwrap_or(fit)
            .clamp(1, fit)
            .min(n.max(1));
        // The shared-patch variant's workgroup memory: the patch, beside the reduction's
        // 256 vec4s and a few words.
        if options.variant == Variant::SharedPatch {
            let need = patch_bytes + 16 * u64::from(WG) + 64;
            let have = u64::from(dev.limits.max_compute_workgroup_storage_size);
            if need > have {
                return Err(GpuError::Setting(format!(
                    "the shared-patch variant needs {need} bytes of workgroup memory for patches of {}×{}, and the device ({}) has {have}: use the plain variant, or reduce [integrator] margin",
                    shape.nx,
                    shape.ny,
                    dev.describe()
                )));
            }
        }
        let nodes = lattice.len();
        let split = options
            .max_lattice_nodes
            .unwrap_or(usize::MAX)
            .min((dev.max_binding() / 16) as usize)
            .min(u32::MAX as usize)
            .max(1);
        if nodes > 2 * split {
            return Err(GpuError::TooLarge(format!(
                "a lattice of {}×{} ({nodes} nodes) needs more than two bindings of {split} nodes for each of its arrays ({}); reduce [domain] lx and ly",
                lattice.lx,
                lattice.ly,
                dev.describe()
            )));
        }
        Ok(Self {
            per_chunk,
            chunks: chunks(n, per_chunk),
            split,
        })
    }
}

/// Every buffer of the step, of the bytes `sizes` gives: the φ arrays per chunk, the
/// chunks' uniforms, and one buffer per slot (the trigonometric table filled).
pub(crate) fn allocate(
    dev: &Device,
    lattice: Lattice,
    shape: &PatchShape,
    layout: &Layout,
    sizes: &Sizes,
    npc: usize,
) -> Buffers {
    let d = &dev.device;
    let copy = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
    let storage = |label: &str, bytes: u64| {
        d.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16),
            usage: wgpu::BufferUsages::STORAGE | copy,
            mapped_at_creation: false,
        })
    };
    let patch_bytes = shape.len() as u64 * 4;
    let per_chunk_array = |label: &str| -> Vec<wgpu::Buffer> {
        layout
            .chunks
            .iter()
            .map(|&(_, count)| storage(label, count as u64 * patch_bytes))
            .collect()
    };
    let n_chunks = layout.chunks.len();
    let chunk_info = layout
        .chunks
        .iter()
        .enumerate()
        .map(|(k, &(lo, count))| {
            let v = Chunk {
                lo: lo as u32,
                count: count as u32,
                first: u32::from(k == 0),
                last: u32::from(k + 1 == n_chunks),
            };
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("chunk"),
                contents: bytemuck::bytes_of(&v),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
        })
        .collect();
    let tab = |l: usize| {
        (0..l).map(move |s| {
            let t = 2.0 * std::f64::consts::PI * s as f64 / l as f64;
            [t.cos() as f32, t.sin() as f32]
        })
    };
    let trig: Vec<[f32; 2]> = tab(lattice.lx).chain(tab(lattice.ly)).collect();
    let fixed: HashMap<Slot, wgpu::Buffer> = sizes
        .slots
        .iter()
        .map(|&(slot, bytes)| {
            let name = slot.info().name;
            let buffer = match slot.info().access {
                crate::bindings::Access::Uniform => d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(name),
                    size: bytes,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                _ if slot == Slot::Trig => {
                    d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(name),
                        contents: bytemuck::cast_slice(&trig),
                        usage: wgpu::BufferUsages::STORAGE,
                    })
                }
                _ => storage(name, bytes),
            };
            (slot, buffer)
        })
        .collect();
    Buffers {
        fixed,
        phi: per_chunk_array("phi"),
        pred: per_chunk_array("pred"),
        k1: per_chunk_array("k1"),
        spare: (npc >= 2).then(|| per_chunk_array("spare")),
        dummy: storage("dummy", 16),
        chunk_info,
    }
}
