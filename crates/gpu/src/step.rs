//! The buffers of the GPU step, its pipelines, and the recording of steps.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use mechanics::backend::Backend;
use mechanics::{PressureKind, StepError, StepParams, Tissue};
use phasefield::{Lattice, PatchShape, Real};
use wgpu::util::DeviceExt;

use crate::device::{Device, GpuError};

/// The extensions of the paper's model the GPU backend runs: adhesion (a lattice pass for the
/// Laplacian of `s1`), populations (per-cell constants, [`Kind`]) and walls (a static lattice
/// field); a tissue with any other part of [`mechanics::Part::ALL`] is refused by
/// [`GpuBackend::check`], naming it.
pub const SUPPORTED: &[mechanics::Part] = &[
    mechanics::Part::Terms,
    mechanics::Part::Adhesion,
    mechanics::Part::Populations,
    mechanics::Part::Walls,
    mechanics::Part::Division,
];

/// Invocations per workgroup (the shader's `WG`).
const WG: u32 = 256;
/// Workgroups along one dimension of a dispatch (Vulkan's guaranteed minimum).
const MAX_GROUPS: u32 = 65_535;
/// Floats per cell in the cell buffer (the shader's `CELL_STRIDE`).
const CELL_STRIDE: usize = 12;
/// Floats per cell of the polarity's buffer (`pol` in step.wgsl).
const POL_STRIDE: usize = 8;
/// Steps recorded before they are submitted.
const BATCH: usize = 16;

const SOURCE: &str = include_str!("step.wgsl");

/// The WGSL source of the step for patches of `shape` and the pressure form `kind`, with
/// `cap` cells per bin: the file `step.wgsl` after its constants.
pub fn shader_source(shape: &PatchShape, kind: PressureKind, cap: u32) -> String {
    shader_source_split(shape, kind, cap, u32::MAX, Variant::Plain)
}

/// The settings of the parts the kernels implement, by scene key, with the values they take
/// (`None`: any value): every key of `[polarity]` (the built-in term; a term of a user's,
/// `[terms.NAME]`, runs on the host and is not here), adhesion, each population's constants,
/// the walls' coefficients and a wound, and the division clock's keys (the clock runs on the
/// host; the device takes its growth factors). A setting added to a part is refused on the GPU
/// by name until it is implemented there and listed here.
pub const SETTINGS: &[(&str, Option<&[&str]>)] = &[
    ("[polarity] alpha", None),
    ("[polarity] propulsion", Some(&["cell", "density"])),
    ("[polarity] rotational_diffusion", None),
    (
        "[polarity] align",
        Some(&["none", "velocity", "force", "shape"]),
    ),
    ("[polarity] align_rate", None),
    ("[polarity] angle", None),
    ("[polarity] contact_inhibition", None),
    ("[adhesion] omega", None),
    ("[[population]] gamma", None),
    ("[[population]] mu", None),
    ("[[population]] radius", None),
    ("[[population]] xi", None),
    ("[[population]] zeta", None),
    ("[[population]] alpha", None),
    ("[[population]] rotational_diffusion", None),
    ("[[population]] align_rate", None),
    ("[walls] kappa", None),
    ("[walls] omega", None),
    ("[walls] kind", None),
    ("[division] cycle_time", None),
    ("[division] axis", None),
    ("[division] max_cells", None),
    ("[division] pressure_gate", None),
    ("[division] extrusion", None),
    ("[division] extrusion_pressure", None),
    ("[division] death_rate", None),
    ("[division] growth_time", None),
];

/// What of the extensions `ext` (with the model's `params`) the GPU backend does not run, each
/// named: the parts it does not declare ([`SUPPORTED`], with [`mechanics::Part::describe`]),
/// then the settings in effect it does not implement ([`SETTINGS`], by key and value: a
/// physics term of a user's, a value the kernels do not know). Empty: it runs them all. The
/// one refusal, for a tissue ([`GpuBackend::check`]) and for a scene before anything is
/// written (the CLI's).
pub fn unsupported(ext: &mechanics::Extensions, params: &mechanics::ModelParams) -> Vec<String> {
    let mut out = mechanics::backend::unsupported(ext, params, SUPPORTED);
    out.extend(mechanics::backend::unsupported_settings(
        &ext.settings(params),
        SETTINGS,
    ));
    out
}

/// The code of what a polarity aligns to in the kernels (`Params::pol_align`); `None` for a
/// rule they do not know.
fn align_code(align: mechanics::terms::Align) -> Option<u32> {
    use mechanics::terms::Align;
    match align {
        Align::None => Some(0),
        Align::Velocity => Some(1),
        Align::Force => Some(2),
        Align::Shape => Some(3),
        _ => None,
    }
}

/// [`shader_source`] with the lattice arrays split into two bindings at node `split`, in the
/// kernels' `variant`.
fn shader_source_split(
    shape: &PatchShape,
    kind: PressureKind,
    cap: u32,
    split: u32,
    variant: Variant,
) -> String {
    let (nx, ny) = (shape.nx as u32, shape.ny as u32);
    let plen = nx * ny;
    let margin = shape.margin.unwrap_or(0) as u32;
    let local = variant == Variant::SharedPatch;
    format!(
        "const NX: u32 = {nx}u;\nconst NY: u32 = {ny}u;\nconst PLEN: u32 = {plen}u;\n\
         const NPT: u32 = {npt}u;\nconst MARGIN: u32 = {margin}u;\nconst CAP: u32 = {cap}u;\n\
         const PAPER: u32 = {paper}u;\nconst LAT_SPLIT: u32 = {split}u;\n\
         const MAX_KINDS: u32 = {MAX_KINDS}u;\nconst LOCAL_PATCH: u32 = {lp}u;\n\
         const LOCAL_LEN: u32 = {ll}u;\n{params}{kind}{chunk}{SOURCE}",
        params = Params::WGSL,
        kind = Kind::WGSL,
        chunk = Chunk::WGSL,
        npt = plen.div_ceil(WG),
        paper = u32::from(kind == PressureKind::Paper),
        lp = u32::from(local),
        ll = if local { plen } else { 1 },
    )
}

/// Which form of the kernels a backend runs ([`GpuOptions::variant`]): each computes the same
/// numbers; which is faster only a device can say (`docs/gpu_check.sh` times both).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Variant {
    /// Every stencil reads its five values from the φ array in device memory.
    #[default]
    Plain,
    /// The cell and force passes load each cell's patch into workgroup memory once and read
    /// their stencils there: one read of device memory per patch node and pass where the plain
    /// kernels make five (most of them cached), for `4 · PLEN` bytes of workgroup memory
    /// (3.6 kB at margin 12, 6.6 kB at margin 16). The same arithmetic on the same values:
    /// the same bits.
    SharedPatch,
}

impl Variant {
    /// Its name, as `gpu_check` takes it: `plain` or `shared-patch`.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Plain => "plain",
            Variant::SharedPatch => "shared-patch",
        }
    }

    /// The variant named `name` ([`Variant::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        [Variant::Plain, Variant::SharedPatch]
            .into_iter()
            .find(|v| v.name() == name)
    }
}

/// One evaluation on the device ([`GpuBackend::evaluate`]).
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// `R(φ)` of every cell, in logical patch order.
    pub rhs: Vec<f32>,
    /// Per lattice node (`x * ly + y`): `P`, `s2`, `Q_xx`, `Q_xy`.
    pub lattice: Vec<[f32; 4]>,
    /// Per cell, 12 floats: area, `S_xx`, `S_xy`, `φ_min`, `φ_max`, `F_x`, `F_y`, `v_x`,
    /// `v_y`, and the centre of the last step.
    pub cells: Vec<f32>,
}

/// A structure shared by the host and the kernels, written once: the Rust definition
/// (`#[repr(C)]`, `Pod`) and its WGSL declaration (`WGSL`, which [`shader_source`] prepends
/// to the kernels) come from the same list of fields, so they cannot drift. Every field is
/// `f32` or `u32` (4 bytes, aligned to 4 in both languages, checked at compile time), and the
/// size is a multiple of 16 (a uniform block's rule), so the two layouts are the same field
/// by field.
macro_rules! shared_struct {
    ($(#[$meta:meta])* $vis:vis struct $name:ident { $($(#[$fmeta:meta])* $field:ident: $ty:ident,)* }) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
        $vis struct $name {
            $($(#[$fmeta])* pub $field: $ty,)*
        }

        impl $name {
            /// The WGSL declaration of this structure.
            pub const WGSL: &'static str = concat!(
                "struct ", stringify!($name), " {\n",
                $("    ", stringify!($field), ": ", stringify!($ty), ",\n",)*
                "}\n"
            );
        }

        const _: () = {
            $(assert!(
                std::mem::size_of::<$ty>() == 4 && std::mem::align_of::<$ty>() == 4,
                "shared structures hold f32 and u32 only"
            );)*
            let fields = [$(stringify!($field)),*].len();
            assert!(std::mem::size_of::<$name>() == 4 * fields);
            assert!(std::mem::size_of::<$name>() % 16 == 0, "pad to 16 bytes");
        };
    };
}

shared_struct! {
    /// The uniform parameters of the kernels (the shader's `Params`).
    pub struct Params {
        /// `8γ/λ` ([`phasefield::EnergyCoefficients`], as the next four).
        double_well: f32,
        /// `2γλ`.
        gradient: f32,
        /// `4μ/πR²`.
        area: f32,
        /// `1/πR²`.
        inv_target_area: f32,
        /// `2κ/λ`.
        repulsion: f32,
        /// The activity ζ.
        zeta: f32,
        /// The friction ξ.
        xi: f32,
        /// The time step.
        dt: f32,
        /// Lattice nodes along x.
        lx: u32,
        /// Lattice nodes along y.
        ly: u32,
        /// Bins along x.
        nbx: u32,
        /// Bins along y.
        nby: u32,
        /// Cells.
        n_cells: u32,
        /// Workgroups along x of a per-cell dispatch (the rest along y).
        grid_x: u32,
        /// The band around `[0, 1]` that a field may not leave ([`mechanics::PHI_BOUND`]).
        bound: f32,
        /// The walls' `2κ_w/λ` ([`mechanics::equations::wall_coefficients`]; 0 without walls
        /// in effect).
        wall_repulsion: f32,
        /// The walls' `2ω_wλ`.
        wall_adhesion: f32,
        /// The cells' adhesion coefficient `c = 2ωλ`
        /// ([`mechanics::equations::adhesion_coefficient`]; 0 without adhesion).
        adhesion: f32,
        /// What the polarity aligns to (`POLARITY`): 0 nothing, 1 the velocity, 2 the
        /// interface force, 3 the long axis ([`mechanics::terms::Align`]).
        pol_align: u32,
        /// 1 when the propulsion is a density (`α A_i`), 0 a whole-cell force (`α`).
        pol_density: u32,
        /// Contact inhibition of locomotion η ([`mechanics::terms::Polarity`]).
        pol_inhibition: f32,
        /// 1 while activity is on (the active terms act only then).
        pol_active: u32,
        /// The seed of the terms' noise, low and high words (Philox's key).
        seed_lo: u32,
        /// The seed's high word.
        seed_hi: u32,
        /// The iteration of the state on the device when it was last synced or uploaded,
        /// low and high words: a step's noise is drawn for `step + status.steps`.
        step_lo: u32,
        /// Its high word.
        step_hi: u32,
        /// The polarity's noise stage, folded to 32 bits (`terms::NoiseKey`: its place `t`
        /// among the terms, `t << 16`).
        pol_stage: u32,
        /// The division clock's growth time `T_g` (`GROWTH`; 0 without a growth phase).
        growth_time: f32,
        /// The model time of the state on the device when it was last synced, less the
        /// growth's origin (the time of the last upload): a step's time is this plus
        /// `status.steps · dt`.
        growth_now: f32,
        /// Padding to 16 bytes.
        pad0: u32,
        /// Padding to 16 bytes.
        pad1: u32,
        /// Padding to 16 bytes.
        pad2: u32,
    }
}

shared_struct! {
    /// The constants of one population in an evaluation (the shader's `Kind`,
    /// [`mechanics::terms::CellConstants`]): one entry, the tissue's, without populations.
    pub struct Kind {
        /// `8γ/λ` with the population's γ.
        double_well: f32,
        /// `2γλ`.
        gradient: f32,
        /// `4μ/πR²` with its μ and R.
        area: f32,
        /// `1/πR²`.
        inv_target_area: f32,
        /// Its friction ξ.
        xi: f32,
        /// The weight of its `S_i` in the active stress (its ζ when the populations' ζ differ,
        /// 1 otherwise).
        zeta_weight: f32,
        /// Its propulsion `α` (0 without polarity).
        alpha: f32,
        /// The amplitude `√(2 D_r)` of its polarity's noise.
        noise: f32,
        /// Its alignment rate `J`.
        align_rate: f32,
        /// Padding to 16 bytes.
        pad0: u32,
        /// Padding to 16 bytes.
        pad1: u32,
        /// Padding to 16 bytes.
        pad2: u32,
    }
}

/// The most populations the device holds constants for (a uniform array of [`Kind`]).
pub const MAX_KINDS: usize = 16;

/// The uniform table of every population's constants.
type Kinds = [Kind; MAX_KINDS];

shared_struct! {
    /// The cells of one chunk (the shader's `Chunk`): cells `lo .. lo + count`, whose φ sit at
    /// `(i − lo) · PLEN` in the dispatch's arrays; `first` and `last` (0 or 1) say whether the
    /// lattice pass starts or ends the sums over chunks.
    pub struct Chunk {
        /// The first cell.
        lo: u32,
        /// How many cells.
        count: u32,
        /// Whether this is the first chunk.
        first: u32,
        /// Whether this is the last chunk.
        last: u32,
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
    /// `npc` corrector passes, with the extensions `parts` (walls and adhesion hold 8 bytes a
    /// lattice node each, polarity 32 bytes a cell, division 4).
    pub fn estimate(
        lattice: Lattice,
        shape: &PatchShape,
        n_cells: usize,
        npc: usize,
        parts: &[mechanics::Part],
    ) -> Self {
        let n = n_cells as u64;
        let per_node_parts: u64 = parts
            .iter()
            .map(|p| match p {
                mechanics::Part::Walls | mechanics::Part::Adhesion => 8,
                _ => 0,
            })
            .sum();
        // The polarity's row of each cell, and with division each cell's growth start.
        let per_cell_parts: u64 = parts
            .iter()
            .map(|p| match p {
                mechanics::Part::Terms => POL_STRIDE as u64 * 4,
                mechanics::Part::Division => 4,
                _ => 0,
            })
            .sum();
        let phi_array = n * shape.len() as u64 * 4;
        let phi_arrays = if npc >= 2 { 4 } else { 3 };
        let (nb, cap) = bins(lattice, shape, n_cells);
        let total = phi_arrays * phi_array
            + n * (CELL_STRIDE as u64 * 4 + 8 + per_cell_parts)
            + lattice.len() as u64 * (16 + 32 + per_node_parts)
            + u64::from(nb) * (4 + 4 * u64::from(cap))
            + (lattice.lx + lattice.ly) as u64 * 8;
        Self {
            phi_array,
            phi_arrays,
            total,
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
fn chunks(n: usize, per: usize) -> Vec<(usize, usize)> {
    let per = per.max(1);
    (0..n.div_ceil(per).max(1))
        .map(|k| (k * per, per.min(n - (k * per).min(n))))
        .collect()
}

/// The bins of patch origins for the gather: `(number of bins, cells per bin)`. A bin is at
/// least a patch wide, so the patches over a node have their origins in the node's bin or the
/// one before it, in each direction.
fn bins(lattice: Lattice, shape: &PatchShape, n_cells: usize) -> (u32, u32) {
    let (nbx, nby) = bin_grid(lattice, shape);
    let nb = nbx * nby;
    let per_bin = n_cells.div_ceil(nb as usize) as u32;
    let cap = (8 * per_bin).max(32).min(n_cells.max(1) as u32);
    (nb, cap)
}

fn bin_grid(lattice: Lattice, shape: &PatchShape) -> (u32, u32) {
    (
        (lattice.lx / shape.nx).max(1) as u32,
        (lattice.ly / shape.ny).max(1) as u32,
    )
}

/// A grid of workgroups for `n` of them: `(x, y)` with `x ≤ 65535`.
fn grid(n: u32) -> (u32, u32) {
    let x = n.clamp(1, MAX_GROUPS);
    (x, n.div_ceil(x).max(1))
}

struct Pipelines {
    cell_check: wgpu::ComputePipeline,
    cell: wgpu::ComputePipeline,
    bin_clear: wgpu::ComputePipeline,
    bin_fill: wgpu::ComputePipeline,
    bin_sort: wgpu::ComputePipeline,
    lattice: wgpu::ComputePipeline,
    /// The Laplacian of s1 and the adhesion's cross pressure, with adhesion.
    adhesion: Option<wgpu::ComputePipeline>,
    predict: wgpu::ComputePipeline,
    correct: wgpu::ComputePipeline,
    /// With polarity, the angle's predictor and corrector (`polarity_update`).
    polarity: Option<[wgpu::ComputePipeline; 2]>,
    correct_last: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    /// The observables' tissue velocity and its Σ |v|² per workgroup.
    velocity_sums: wgpu::ComputePipeline,
    velocity_reduce: wgpu::ComputePipeline,
}

/// The bind groups of one step, one per chunk each: which φ array each evaluation reads and
/// writes.
struct Groups {
    /// Evaluates `phi`; the predictor into `pred`, `R` into `k1`.
    predict: Vec<wgpu::BindGroup>,
    /// Evaluates `pred` (and `spare`) as the last corrector, into `phi`, re-centred.
    last: [Vec<wgpu::BindGroup>; 2],
    /// Evaluates `pred` (`spare`) as a middle corrector, into `spare` (`pred`).
    middle: [Vec<wgpu::BindGroup>; 2],
}

/// The GPU backend: the state and every buffer of the step on the device, and the steps
/// recorded since they were last submitted.
///
/// Storage and arithmetic are f32 (the CPU default stores f32 and computes in f64): the cost
/// of the f32 arithmetic against the CPU is measured by the tests and docs/performance.md.
pub struct GpuBackend {
    dev: Device,
    pipelines: Pipelines,
    groups: Groups,
    /// The chunks of cells, `(lo, count)`, and the φ and `R(φ)` arrays of each.
    chunks: Vec<(usize, usize)>,
    phi: Vec<wgpu::Buffer>,
    k1: Vec<wgpu::Buffer>,
    lat: wgpu::Buffer,
    lat_hi: wgpu::Buffer,
    /// The nodes in `lat`; the rest are in `lat_hi`.
    lat_split: usize,
    cell: wgpu::Buffer,
    origin: wgpu::Buffer,
    status: wgpu::Buffer,
    params_buf: wgpu::Buffer,
    lattice: Lattice,
    shape: PatchShape,
    n_cells: usize,
    npc: usize,
    params: Params,
    kinds: Kinds,
    kinds_buf: wgpu::Buffer,
    /// The wall field, and which field it holds (the address of the tissue's, or `None`).
    wall: wgpu::Buffer,
    wall_uploaded: Option<usize>,
    /// Whether the kernels were compiled with walls and with adhesion.
    walls: bool,
    adhesion: bool,
    /// s1 and its Laplacian per lattice node, with adhesion (bound, never read by the host).
    _adhesion_buffers: [wgpu::Buffer; 2],
    /// Σ |v|² per workgroup of the lattice ([`GpuBackend::observables`]).
    v2_part: wgpu::Buffer,
    /// With polarity, each cell's angle and its step's scratch (`POL_STRIDE` floats a slot).
    pol: wgpu::Buffer,
    polarity: bool,
    /// With a growth phase, each slot's growth start less `growth_origin`.
    growth_buf: wgpu::Buffer,
    growth: bool,
    /// The model time the growth starts are measured from (the last upload's).
    growth_origin: f64,
    /// The most cells the buffers hold (`[division] max_cells` with division).
    capacity: usize,
    /// Each chunk's uniform, rewritten when the number of cells changes.
    chunk_info: Vec<wgpu::Buffer>,
    /// The chunks of the cells there are now, `(lo, count)`: the first `active.len()` of
    /// `chunks`, the last of them perhaps partly filled.
    active: Vec<(usize, usize)>,
    /// Bytes copied from the device to the host so far ([`GpuBackend::bytes_read`]).
    bytes_read: Arc<AtomicU64>,
    groups_cells: (u32, u32),
    groups_nodes: (u32, u32),
    groups_bins: u32,
    encoder: Option<wgpu::CommandEncoder>,
    recorded: usize,
    /// The clock at the last sync or upload, and the size of every step queued since.
    base: (u64, f64),
    queued: Vec<f64>,
}

impl std::fmt::Debug for GpuBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuBackend")
            .field("adapter", &self.dev.describe())
            .field("n_cells", &self.n_cells)
            .field("chunks", &self.chunks.len())
            .finish_non_exhaustive()
    }
}

impl GpuBackend {
    /// Opens a device ([`Device::open`]) and builds the backend for `tissue` stepped with
    /// `step`.
    ///
    /// # Errors
    /// See [`GpuBackend::on`].
    pub fn new<T: Real>(tissue: &Tissue<T>, step: &StepParams) -> Result<Self, GpuError> {
        Self::check(tissue, step)?;
        Self::on(Device::open()?, tissue, step)
    }

    /// What the GPU backend refuses in a tissue and step, before any device is opened: the
    /// model's extensions (each named), full-domain storage, and forward Euler.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] or [`GpuError::Setting`].
    pub fn check<T: Real>(tissue: &Tissue<T>, step: &StepParams) -> Result<(), GpuError> {
        let ext = unsupported(tissue.extensions(), tissue.params());
        if !ext.is_empty() {
            return Err(GpuError::Unsupported(ext.join(", ")));
        }
        let kinds = tissue.populations().kinds().len();
        if kinds > MAX_KINDS {
            return Err(GpuError::Setting(format!(
                "the GPU backend holds at most {MAX_KINDS} populations, and this scene has {kinds}: merge some [[population]] tables or run with backend = \"cpu\""
            )));
        }
        if tissue.cells().shape().margin.is_none() {
            return Err(GpuError::Setting(
                "the GPU backend needs patches: [integrator] margin = 0 (the full-domain reference) runs with backend = \"cpu\"".into(),
            ));
        }
        if step.npc == 0 {
            return Err(GpuError::Setting(
                "the GPU backend runs Heun's method, with at least one corrector: set [integrator] npc = 1 (forward Euler, npc = 0, runs with backend = \"cpu\")".into(),
            ));
        }
        Ok(())
    }

    /// The backend on an open device.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] or [`GpuError::Setting`] (see [`GpuBackend::check`]);
    /// [`GpuError::TooLarge`] when a φ array passes the device's largest binding (the
    /// figures in the message).
    pub fn on<T: Real>(
        dev: Device,
        tissue: &Tissue<T>,
        step: &StepParams,
    ) -> Result<Self, GpuError> {
        Self::with_options(dev, tissue, step, GpuOptions::default())
    }

    /// The backend on an open device, laid out as `options` say.
    ///
    /// The per-cell φ arrays are split into chunks of at most the device's largest binding;
    /// when the buffers do not fit the device's memory, the error gives the estimate.
    ///
    /// # Errors
    /// As [`GpuBackend::on`].
    pub fn with_options<T: Real>(
        dev: Device,
        tissue: &Tissue<T>,
        step: &StepParams,
        options: GpuOptions,
    ) -> Result<Self, GpuError> {
        Self::check(tissue, step)?;
        let cells = tissue.cells();
        let (lattice, shape, n_now) = (cells.lattice(), cells.shape().clone(), cells.n_cells());
        // With division, every per-cell buffer holds the clock's most cells (`max_cells`):
        // the events change the number of cells between steps, not the buffers.
        let n = tissue
            .proliferation()
            .map_or(n_now, |c| c.max_cells.max(n_now));
        let mem = GpuMemory::estimate(lattice, &shape, n, step.npc, &tissue.parts());
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
        let chunks = chunks(n, per_chunk);
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
        let (lo_nodes, hi_nodes) = (nodes.min(split), nodes.saturating_sub(split));
        // Allocation failures (the state does not fit the device) are caught here and
        // reported with the estimate, not left to a later panic.
        let oom = dev.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let (nb, cap) = bins(lattice, &shape, n);
        let (nbx, nby) = bin_grid(lattice, &shape);
        let d = &dev.device;
        let storage = |label: &str, bytes: u64, extra: wgpu::BufferUsages| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE | extra,
                mapped_at_creation: false,
            })
        };
        let copy = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        let per_chunk_array = |label: &str| -> Vec<wgpu::Buffer> {
            chunks
                .iter()
                .map(|&(_, count)| storage(label, count as u64 * patch_bytes, copy))
                .collect()
        };
        let phi = per_chunk_array("phi");
        let pred = per_chunk_array("pred");
        let k1 = per_chunk_array("k1");
        let spare = (step.npc >= 2).then(|| per_chunk_array("spare"));
        let dummy = storage("dummy", 16, copy);
        // The lattice arrays, each in one binding of up to `split` nodes and one of the rest;
        // the chunks' partial sums only where there is more than one chunk.
        let lattice_array = |label: &str, nodes: usize, needed: bool| {
            storage(label, if needed { nodes as u64 * 16 } else { 16 }, copy)
        };
        let several = chunks.len() > 1;
        let lat = lattice_array("lattice sums", lo_nodes, true);
        let lat_hi = lattice_array("lattice sums, second", hi_nodes, hi_nodes > 0);
        let acc = [
            lattice_array("chunk sums a", lo_nodes, several),
            lattice_array("chunk sums a, second", hi_nodes, several && hi_nodes > 0),
            lattice_array("chunk sums b", lo_nodes, several),
            lattice_array("chunk sums b, second", hi_nodes, several && hi_nodes > 0),
        ];
        let chunk_info: Vec<wgpu::Buffer> = chunks
            .iter()
            .enumerate()
            .map(|(k, &(lo, count))| {
                let v = Chunk {
                    lo: lo as u32,
                    count: count as u32,
                    first: u32::from(k == 0),
                    last: u32::from(k + 1 == chunks.len()),
                };
                d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("chunk"),
                    contents: bytemuck::bytes_of(&v),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                })
            })
            .collect();
        let cell = storage("cell", (n * CELL_STRIDE * 4) as u64, copy);
        let origin = storage("origin", (n * 8) as u64, copy);
        let bin_count = storage("bin counts", u64::from(nb) * 4, copy);
        let bin_cells = storage("bin cells", u64::from(nb) * u64::from(cap) * 4, copy);
        let status = storage("status", 16, copy);
        let tab = |l: usize| {
            (0..l).map(move |s| {
                let t = 2.0 * std::f64::consts::PI * s as f64 / l as f64;
                [t.cos() as f32, t.sin() as f32]
            })
        };
        let trig_values: Vec<[f32; 2]> = tab(lattice.lx).chain(tab(lattice.ly)).collect();
        let trig = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("trig"),
            contents: bytemuck::cast_slice(&trig_values),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let groups_cells = grid(per_chunk as u32);
        let params = Params {
            double_well: 0.0,
            gradient: 0.0,
            area: 0.0,
            inv_target_area: 0.0,
            repulsion: 0.0,
            zeta: 0.0,
            xi: 1.0,
            dt: 0.0,
            lx: lattice.lx as u32,
            ly: lattice.ly as u32,
            nbx,
            nby,
            n_cells: n as u32,
            grid_x: groups_cells.0,
            bound: mechanics::PHI_BOUND as f32,
            wall_repulsion: 0.0,
            wall_adhesion: 0.0,
            adhesion: 0.0,
            pol_align: 0,
            pol_density: 0,
            pol_inhibition: 0.0,
            pol_active: 0,
            seed_lo: 0,
            seed_hi: 0,
            step_lo: 0,
            step_hi: 0,
            pol_stage: 0,
            growth_time: 0.0,
            growth_now: 0.0,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        };
        // The wall field (w, ∇²w per node), written by `set_uniforms` whenever the field in
        // effect changes (a wound opens when the activity starts); a placeholder without walls.
        let walls = tissue.walls().is_some();
        let wall = storage(
            "wall",
            if walls { lattice.len() as u64 * 8 } else { 16 },
            copy,
        );
        let w = f64::from(u8::from(walls));
        // With adhesion, s1 and its Laplacian per lattice node.
        let adhesion = tissue.params().omega != 0.0;
        let adh_s1 = storage(
            "adhesion s1",
            if adhesion {
                lattice.len() as u64 * 4
            } else {
                16
            },
            copy,
        );
        let adh_lap = storage(
            "adhesion laplacian",
            if adhesion {
                lattice.len() as u64 * 4
            } else {
                16
            },
            copy,
        );
        let a = f64::from(u8::from(adhesion));
        // With polarity, each cell's angle and its step's scratch (`POL_STRIDE` floats).
        let polarity = tissue.terms().polarity().is_some();
        let pol = storage(
            "polarity",
            if polarity {
                (n * POL_STRIDE * 4) as u64
            } else {
                16
            },
            copy,
        );
        let pf = f64::from(u8::from(polarity));
        // With a growth phase before divisions, each slot's growth start (`growth`).
        let growth = tissue.proliferation().is_some_and(|c| c.growth_time > 0.0);
        let growth_buf = storage("growth", if growth { n as u64 * 4 } else { 16 }, copy);
        let gf = f64::from(u8::from(growth));
        // Σ |v|² per workgroup of the lattice, for the observables.
        let v2_part = storage(
            "v2 per workgroup",
            u64::from((lattice.len() as u32).div_ceil(WG)) * 4,
            copy,
        );
        let params_buf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: std::mem::size_of::<Params>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let kinds_buf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("kinds"),
            size: std::mem::size_of::<Kinds>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });

        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("step.wgsl"),
            source: wgpu::ShaderSource::Wgsl(
                shader_source_split(
                    &shape,
                    tissue.params().pressure,
                    cap,
                    split as u32,
                    options.variant,
                )
                .into(),
            ),
        });
        let storage_entry = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let mut entries = vec![wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }];
        for b in 1..=11 {
            entries.push(storage_entry(b, b == 1 || b == 10));
        }
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 12,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        });
        for b in 13..=17 {
            entries.push(storage_entry(b, false));
        }
        entries.push(storage_entry(19, true));
        entries.push(storage_entry(20, false));
        entries.push(storage_entry(21, false));
        entries.push(storage_entry(22, false));
        entries.push(storage_entry(23, false));
        entries.push(storage_entry(24, true));
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 18,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        });
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("step"),
            entries: &entries,
        });
        let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("step"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str, constants: &[(&str, f64)]| {
            d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                cache: None,
            })
        };
        let pipelines = Pipelines {
            cell_check: pipeline("cell_sums", &[("CHECK", 1.0)]),
            cell: pipeline("cell_sums", &[("CHECK", 0.0)]),
            bin_clear: pipeline("bin_clear", &[]),
            bin_fill: pipeline("bin_fill", &[]),
            bin_sort: pipeline("bin_sort", &[]),
            lattice: pipeline(
                "lattice_sums",
                &[("WALLS", w), ("ADHESION", a), ("GROWTH", gf)],
            ),
            adhesion: adhesion.then(|| pipeline("adhesion_lattice", &[])),
            predict: pipeline(
                "force_update",
                &[
                    ("MODE", 0.0),
                    ("WALLS", w),
                    ("ADHESION", a),
                    ("POLARITY", pf),
                    ("GROWTH", gf),
                ],
            ),
            correct: pipeline(
                "force_update",
                &[
                    ("MODE", 1.0),
                    ("WALLS", w),
                    ("ADHESION", a),
                    ("POLARITY", pf),
                    ("GROWTH", gf),
                ],
            ),
            correct_last: pipeline(
                "force_update",
                &[
                    ("MODE", 2.0),
                    ("WALLS", w),
                    ("ADHESION", a),
                    ("POLARITY", pf),
                    ("GROWTH", gf),
                ],
            ),
            polarity: polarity.then(|| {
                [
                    pipeline("polarity_update", &[("MODE", 0.0), ("GROWTH", gf)]),
                    pipeline("polarity_update", &[("MODE", 1.0), ("GROWTH", gf)]),
                ]
            }),
            count: pipeline("count_step", &[]),
            velocity_sums: pipeline("velocity_sums", &[]),
            velocity_reduce: pipeline("velocity_reduce", &[]),
        };
        let group = |k: usize, x: &wgpu::Buffer, old: &wgpu::Buffer, out: &wgpu::Buffer| {
            let bufs: [&wgpu::Buffer; 25] = [
                &params_buf,
                x,
                old,
                &k1[k],
                out,
                &cell,
                &origin,
                &lat,
                &bin_count,
                &bin_cells,
                &trig,
                &status,
                &chunk_info[k],
                &acc[0],
                &lat_hi,
                &acc[1],
                &acc[2],
                &acc[3],
                &kinds_buf,
                &wall,
                &adh_s1,
                &adh_lap,
                &v2_part,
                &pol,
                &growth_buf,
            ];
            let entries: Vec<wgpu::BindGroupEntry<'_>> = bufs
                .iter()
                .enumerate()
                .map(|(b, buf)| wgpu::BindGroupEntry {
                    binding: b as u32,
                    resource: buf.as_entire_binding(),
                })
                .collect();
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &layout,
                entries: &entries,
            })
        };
        let per = |f: &dyn Fn(usize) -> wgpu::BindGroup| (0..chunks.len()).map(f).collect();
        let spare_of = |k: usize| spare.as_ref().map_or(&dummy, |s| &s[k]);
        let groups = Groups {
            predict: per(&|k| group(k, &phi[k], &dummy, &pred[k])),
            last: [
                per(&|k| group(k, &pred[k], &phi[k], &dummy)),
                per(&|k| group(k, spare_of(k), &phi[k], &dummy)),
            ],
            middle: [
                per(&|k| group(k, &pred[k], &phi[k], spare_of(k))),
                per(&|k| group(k, spare_of(k), &phi[k], &pred[k])),
            ],
        };
        if let Some(e) = pollster::block_on(oom.pop()) {
            return Err(GpuError::TooLarge(format!(
                "{n} cells on patches of {}×{} need {} on the device ({}), which could not allocate them ({e}); reduce [cells] count or [integrator] margin",
                shape.nx,
                shape.ny,
                mem.describe(),
                dev.describe()
            )));
        }
        let nodes = (lattice.len() as u32).div_ceil(WG);
        let mut backend = Self {
            pipelines,
            groups,
            chunks,
            phi,
            k1,
            lat,
            lat_hi,
            lat_split: lo_nodes,
            cell,
            origin,
            status,
            params_buf,
            kinds: [Kind::zeroed(); MAX_KINDS],
            kinds_buf,
            wall,
            wall_uploaded: None,
            walls,
            adhesion,
            _adhesion_buffers: [adh_s1, adh_lap],
            v2_part,
            pol,
            polarity,
            growth_buf,
            growth,
            growth_origin: 0.0,
            capacity: n,
            chunk_info,
            active: Vec::new(),
            bytes_read: Arc::new(AtomicU64::new(0)),
            lattice,
            shape,
            n_cells: n_now,
            npc: step.npc,
            params,
            groups_cells,
            groups_nodes: grid(nodes),
            groups_bins: nb.div_ceil(WG),
            encoder: None,
            recorded: 0,
            base: (tissue.iteration(), tissue.time()),
            queued: Vec::new(),
            dev,
        };
        backend.upload_state(tissue)?;
        Ok(backend)
    }

    /// The adapter, described.
    pub fn adapter(&self) -> String {
        self.dev.describe()
    }

    /// The uniforms of a step of `tissue` of size `dt`: the parameters and every population's
    /// constants, as the host's step takes them ([`mechanics::terms::Populations::constants`]:
    /// with populations of their own ζ, the force's ζ is 1 and each `S_i` is weighted by its
    /// cell's).
    fn uniforms_of<T: Real>(&self, tissue: &Tissue<T>, dt: f64) -> (Params, Kinds) {
        let p = tissue.params();
        let c = p.energy.coefficients();
        let (zeta, constants) = tissue.populations().constants(p, tissue.active());
        let mut kinds = [Kind::zeroed(); MAX_KINDS];
        for (k, c) in kinds.iter_mut().zip(&constants) {
            *k = Kind {
                double_well: c.coef.double_well as f32,
                gradient: c.coef.gradient as f32,
                area: c.coef.area as f32,
                inv_target_area: c.coef.inv_target_area as f32,
                xi: c.xi as f32,
                zeta_weight: c.zeta_weight as f32,
                alpha: 0.0,
                noise: 0.0,
                align_rate: 0.0,
                pad0: 0,
                pad1: 0,
                pad2: 0,
            };
        }
        let polarity = tissue.terms().polarity();
        if let Some((_, pol)) = polarity {
            for (k, kind) in kinds.iter_mut().enumerate().take(constants.len()) {
                let [alpha, d_r, rate] = pol.values(k);
                kind.alpha = alpha as f32;
                kind.noise = (2.0 * d_r).sqrt() as f32;
                kind.align_rate = rate as f32;
            }
        }
        let seed = tissue.terms().seed();
        let (iteration, _) = self.base;
        let [wall_repulsion, wall_adhesion] = match (tissue.walls(), tissue.wall_field()) {
            (Some(w), Some(_)) => {
                mechanics::equations::wall_coefficients(w.kappa, w.omega, p.energy.lambda)
            }
            _ => [0.0; 2],
        };
        let adhesion = mechanics::equations::adhesion_coefficient(p.omega, p.energy.lambda);
        let params = Params {
            adhesion: adhesion as f32,
            wall_repulsion: wall_repulsion as f32,
            wall_adhesion: wall_adhesion as f32,
            double_well: c.double_well as f32,
            gradient: c.gradient as f32,
            area: c.area as f32,
            inv_target_area: c.inv_target_area as f32,
            repulsion: c.repulsion as f32,
            zeta: zeta as f32,
            xi: p.xi as f32,
            dt: dt as f32,
            pol_align: polarity.and_then(|(_, p)| align_code(p.align)).unwrap_or(0),
            pol_density: polarity.map_or(0, |(_, p)| {
                u32::from(p.propulsion == mechanics::terms::Propulsion::Density)
            }),
            pol_inhibition: polarity.map_or(0.0, |(_, p)| p.contact_inhibition as f32),
            pol_active: u32::from(tissue.active()),
            seed_lo: seed as u32,
            seed_hi: (seed >> 32) as u32,
            step_lo: iteration as u32,
            step_hi: (iteration >> 32) as u32,
            pol_stage: polarity.map_or(0, |(t, _)| (t as u32) << 16),
            growth_time: tissue.proliferation().map_or(0.0, |c| c.growth_time as f32),
            growth_now: (self.base.1 - self.growth_origin) as f32,
            ..self.params
        };
        (params, kinds)
    }

    /// Takes the uniforms of a step of `tissue` of size `dt`, writing what changed; whether
    /// anything did.
    fn set_uniforms<T: Real>(&mut self, tissue: &Tissue<T>, dt: f64) -> bool {
        // The wall field in effect, when it is not the one on the device.
        let field = tissue.wall_field();
        let key = field.map(|f| f as *const phasefield::WallField as usize);
        if key != self.wall_uploaded {
            self.flush();
            if let Some(f) = field {
                let values: Vec<[f32; 2]> = f
                    .w()
                    .iter()
                    .zip(f.laplacian())
                    .map(|(&w, &l)| [w as f32, l as f32])
                    .collect();
                self.dev
                    .queue
                    .write_buffer(&self.wall, 0, bytemuck::cast_slice(&values));
            }
            self.wall_uploaded = key;
        }
        let (params, kinds) = self.uniforms_of(tissue, dt);
        let changed = params != self.params || kinds != self.kinds;
        if changed {
            // A change (the activity switch) applies from this step on: the steps recorded
            // before it go first.
            self.flush();
            self.params = params;
            self.kinds = kinds;
            let q = &self.dev.queue;
            q.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&self.params));
            q.write_buffer(&self.kinds_buf, 0, bytemuck::cast_slice(&self.kinds));
        }
        changed
    }

    fn upload_state<T: Real>(&mut self, tissue: &Tissue<T>) -> Result<(), GpuError> {
        let cells = tissue.cells();
        if cells.n_cells() > self.capacity || cells.shape().len() != self.shape.len() {
            return Err(GpuError::Setting(format!(
                "the backend was built for at most {} cells, and the tissue has {}: build a new backend",
                self.capacity,
                cells.n_cells()
            )));
        }
        self.n_cells = cells.n_cells();
        self.params.n_cells = self.n_cells as u32;
        // The chunks the cells fill now, and their uniforms (the last filled one ends the
        // lattice pass's sums).
        self.active = self
            .chunks
            .iter()
            .map(|&(lo, cap)| (lo, cap.min(self.n_cells.saturating_sub(lo))))
            .take_while(|&(_, count)| count > 0)
            .collect();
        if self.active.is_empty() {
            self.active.push((0, 0));
        }
        for (k, &(lo, count)) in self.active.iter().enumerate() {
            let v = Chunk {
                lo: lo as u32,
                count: count as u32,
                first: u32::from(k == 0),
                last: u32::from(k + 1 == self.active.len()),
            };
            self.dev
                .queue
                .write_buffer(&self.chunk_info[k], 0, bytemuck::bytes_of(&v));
        }
        let plen = self.shape.len();
        let mut values = vec![0.0f32; self.n_cells * plen];
        let mut patch = vec![0.0f64; plen];
        for (i, out) in values.chunks_exact_mut(plen).enumerate() {
            cells.unrolled_into(i, &mut patch);
            for (o, &v) in out.iter_mut().zip(&patch) {
                *o = v as f32;
            }
        }
        let origins: Vec<[u32; 2]> = cells
            .map()
            .origin
            .iter()
            .map(|o| [o[0] as u32, o[1] as u32])
            .collect();
        let q = &self.dev.queue;
        for (&(lo, count), buf) in self.active.iter().zip(&self.phi) {
            q.write_buffer(
                buf,
                0,
                bytemuck::cast_slice(&values[lo * plen..(lo + count) * plen]),
            );
        }
        q.write_buffer(&self.origin, 0, bytemuck::cast_slice(&origins));
        q.write_buffer(&self.status, 0, bytemuck::cast_slice(&[0u32; 4]));
        // The cell buffer: the centres and each slot's population index (slot 11, a u32's
        // bits); the rest is computed by every evaluation before it is read.
        let mut per_cell = vec![0.0f32; self.n_cells * CELL_STRIDE];
        let (ids, pops) = (tissue.cell_ids(), tissue.populations());
        for ((row, centre), &id) in per_cell
            .chunks_exact_mut(CELL_STRIDE)
            .zip(tissue.centres())
            .zip(ids)
        {
            row[9] = centre[0] as f32;
            row[10] = centre[1] as f32;
            row[11] = f32::from_bits(pops.population(id) as u32);
        }
        q.write_buffer(&self.cell, 0, bytemuck::cast_slice(&per_cell));
        // The polarity's angle of each slot, what the last step evaluation computed for the
        // cell as the host's terms keep it (zero for a run that starts), and its identity (the
        // noise's key).
        if self.polarity {
            let theta = polarity_angles(tissue);
            let mut rows = vec![0.0f32; self.n_cells * POL_STRIDE];
            for (row, &id) in rows.chunks_exact_mut(POL_STRIDE).zip(ids) {
                row[0] = theta[id] as f32;
                if let Some(last) = tissue.terms().last_evaluation(id) {
                    row[4] = last.area as f32;
                    row[5] = last.force.x as f32;
                    row[6] = last.force.y as f32;
                }
                row[7] = f32::from_bits(id as u32);
            }
            q.write_buffer(&self.pol, 0, bytemuck::cast_slice(&rows));
        }
        // Each slot's growth start (its birth plus its cycle, from the clock's lineage), from
        // this upload's time, which the steps' times are counted from.
        self.growth_origin = tissue.time();
        if self.growth {
            let clock = tissue.proliferation().expect("a growth phase has a clock");
            let starts: Vec<f32> = ids
                .iter()
                .map(|&id| {
                    clock
                        .growth_start(id)
                        .map_or(f32::INFINITY, |g| (g - self.growth_origin) as f32)
                })
                .collect();
            q.write_buffer(&self.growth_buf, 0, bytemuck::cast_slice(&starts));
        }
        self.base = (tissue.iteration(), tissue.time());
        self.queued.clear();
        let dt = f64::from(self.params.dt);
        self.params.dt = f32::NAN; // written whatever it was
        self.set_uniforms(tissue, dt);
        Ok(())
    }

    /// Submits the steps recorded so far.
    fn flush(&mut self) {
        if let Some(enc) = self.encoder.take() {
            self.dev.queue.submit(Some(enc.finish()));
            self.recorded = 0;
        }
    }

    /// Records one step into the pending command encoder.
    fn record(&mut self) {
        self.record_passes(false);
    }

    /// One evaluation of the current state, as a step's first (with its check), without
    /// stepping: `R(φ)`, the lattice sums and the per-cell quantities, read back.
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn evaluate<T: Real>(
        &mut self,
        tissue: &Tissue<T>,
        dt: f64,
    ) -> Result<Evaluation, GpuError> {
        self.flush();
        self.set_uniforms(tissue, dt);
        self.record_passes(true);
        self.flush();
        let plen = self.shape.len();
        let rhs = self.read_chunks(&self.k1, plen)?;
        let mut lat = self.read(&self.lat, self.lat_split as u64 * 16)?;
        let rest = self.lattice.len() - self.lat_split;
        if rest > 0 {
            lat.extend(self.read(&self.lat_hi, rest as u64 * 16)?);
        }
        Ok(Evaluation {
            rhs: bytemuck::cast_slice(&rhs).to_vec(),
            lattice: bytemuck::cast_slice(&lat).to_vec(),
            cells: self.cell_quantities()?,
        })
    }

    fn record_passes(&mut self, evaluate_only: bool) {
        let enc = self.encoder.get_or_insert_with(|| {
            self.dev
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("steps"),
                })
        });
        let p = &self.pipelines;
        let g = &self.groups;
        let (cx, cy) = self.groups_cells;
        let (nx, ny) = self.groups_nodes;
        // The chunks the cells fill now.
        let na = self.active.len();
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("step"),
            timestamp_writes: None,
        });
        // The bins of this step's patch origins.
        pass.set_bind_group(0, &g.predict[0], &[]);
        pass.set_pipeline(&p.bin_clear);
        pass.dispatch_workgroups(self.groups_bins, 1, 1);
        pass.set_pipeline(&p.bin_fill);
        pass.dispatch_workgroups((self.n_cells as u32).div_ceil(WG), 1, 1);
        pass.set_pipeline(&p.bin_sort);
        pass.dispatch_workgroups(self.groups_bins, 1, 1);
        // k1 = R(φ) with the check, and the predictor.
        let passes = if evaluate_only { 0 } else { self.npc };
        // Each evaluation's cell pass, bind groups and force pass, and which of the polarity's
        // updates follows it (0: the predictor, 1: a corrector).
        let first = (&p.cell_check, &g.predict, &p.predict, 0);
        for (cell, group, force, update) in std::iter::once(first).chain((0..passes).map(|pass| {
            let last = pass + 1 == self.npc;
            let group = if last {
                &g.last[pass % 2]
            } else {
                &g.middle[pass % 2]
            };
            let force = if last { &p.correct_last } else { &p.correct };
            (&p.cell, group, force, 1)
        })) {
            // Each pass over every chunk before the next pass: the lattice sums need every
            // cell's area and shape, the forces every node's sums (chunk by chunk, in order).
            let group = &group[..na];
            pass.set_pipeline(cell);
            for g in group {
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(cx, cy, 1);
            }
            pass.set_pipeline(&p.lattice);
            for g in group {
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(nx, ny, 1);
            }
            // With adhesion, the Laplacian of s1 once the last chunk has written s1.
            if let Some(adhesion) = &p.adhesion {
                pass.set_pipeline(adhesion);
                pass.dispatch_workgroups(nx, ny, 1);
            }
            pass.set_pipeline(force);
            for g in group {
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(cx, cy, 1);
            }
            // The polarity's predictor after the first evaluation, its corrector after the
            // others; not in an evaluation alone.
            if let (Some(polarity), false) = (&p.polarity, evaluate_only) {
                pass.set_pipeline(&polarity[update]);
                pass.set_bind_group(0, &group[0], &[]);
                pass.dispatch_workgroups((self.n_cells as u32).div_ceil(WG), 1, 1);
            }
        }
        if !evaluate_only {
            pass.set_pipeline(&p.count);
            pass.dispatch_workgroups(1, 1, 1);
        }
        drop(pass);
        self.recorded += 1;
    }

    /// Copies a per-chunk array (`per_cell` floats a cell) to the host, chunk after chunk.
    fn read_chunks(&self, arrays: &[wgpu::Buffer], per_cell: usize) -> Result<Vec<u8>, GpuError> {
        let mut out = Vec::with_capacity(self.n_cells * per_cell * 4);
        for (&(_, count), buf) in self.active.iter().zip(arrays) {
            out.extend(self.read(buf, (count * per_cell * 4) as u64)?);
        }
        Ok(out)
    }

    /// Submits the steps queued so far and waits until the device has run them, without
    /// reading anything back (for timing).
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn wait(&mut self) -> Result<(), GpuError> {
        self.flush();
        self.dev
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Lost(e.to_string()))
    }

    /// Bytes the step moves to and from device memory per node-update (one cell's patch node
    /// in one step), counted from the kernels: per evaluation the cell pass reads φ (4), the
    /// gather reads φ once more (4), the force pass reads φ and the node's sums (4 + 16) and
    /// writes `R` and the new φ (8; the corrector also reads `R` and φⁿ, 8 more); the lattice
    /// sums write 16 bytes a lattice node, 2 evaluations a step, counted per patch node with
    /// `lattice_nodes / patch_nodes`. With `K` chunks the lattice pass runs once per chunk
    /// over the whole lattice, and every chunk but the last writes its partial sums (32 bytes
    /// a node) that the next reads (32 more): `64 (K − 1)` bytes a lattice node and
    /// evaluation (about 39 B per node-update at 10⁶ cells in 3 chunks). Neighbours of the
    /// stencil and the bins' lists are taken as cached.
    ///
    /// The extensions add, per evaluation: walls 8 bytes a patch node (the force pass reads
    /// (w, ∇²w)) and 8 a lattice node (the lattice pass reads them); adhesion 4 bytes a patch
    /// node (the force pass reads ∇²s1) and 44 a lattice node (the lattice pass writes s1, the
    /// adhesion pass reads it, writes ∇²s1 and reads and writes `P, s2, Q`); polarity 88
    /// bytes a cell and evaluation (0.2 B a node-update on patches of 30²).
    pub fn bytes_per_node_update(&self) -> f64 {
        let predictor = 4.0 + 4.0 + 4.0 + 16.0 + 8.0;
        let corrector = predictor + 8.0;
        let correctors = self.npc as f64;
        let per_patch_node =
            self.lattice.len() as f64 / (self.n_cells * self.shape.len()).max(1) as f64;
        let chunks = 64.0 * self.active.len().saturating_sub(1) as f64;
        let (walls, adhesion) = (
            f64::from(u8::from(self.walls)),
            f64::from(u8::from(self.adhesion)),
        );
        let parts_patch = 8.0 * walls + 4.0 * adhesion;
        let parts_lattice = 8.0 * walls + 44.0 * adhesion;
        let lattice = (16.0 + chunks + parts_lattice) * (1.0 + correctors) * per_patch_node;
        // The polarity: per cell and evaluation, the force pass reads 4 floats, and its update
        // reads up to 11 and writes up to 7: 88 bytes a cell, counted per patch node.
        let polarity = if self.polarity {
            88.0 * (1.0 + correctors) / self.shape.len() as f64
        } else {
            0.0
        };
        predictor + correctors * corrector + parts_patch * (1.0 + correctors) + lattice + polarity
    }

    /// The number of chunks the per-cell arrays are split into.
    pub fn n_chunks(&self) -> usize {
        self.active.len()
    }

    /// Copies `bytes` of `buffer` to the host.
    fn read(&self, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, GpuError> {
        let d = &self.dev.device;
        let staging = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes.max(16),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        self.bytes_read.fetch_add(bytes, Ordering::Relaxed);
        self.dev.queue.submit(Some(enc.finish()));
        let (tx, rx) = mpsc::channel();
        staging
            .slice(..bytes)
            .map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
        d.poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Lost(e.to_string()))?;
        rx.recv()
            .map_err(|e| GpuError::Lost(e.to_string()))?
            .map_err(|e| GpuError::Lost(e.to_string()))?;
        let data = staging
            .slice(..bytes)
            .get_mapped_range()
            .map_err(|e| GpuError::Lost(e.to_string()))?
            .to_vec();
        staging.unmap();
        Ok(data)
    }

    /// The per-cell quantities of the last evaluation, per slot: area, `S_xx`, `S_xy`,
    /// `φ_min`, `φ_max`, `F`, `v` and the centre (12 floats each, the last unused).
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn cell_quantities(&mut self) -> Result<Vec<f32>, GpuError> {
        self.flush();
        self.cell_quantities_now()
    }

    /// Bytes copied from the device to the host since the backend was made: what a test
    /// reads to show that the observables bring back no fields.
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read.load(Ordering::Relaxed)
    }

    /// The counter of [`GpuBackend::bytes_read`], to read while a simulation owns the backend.
    pub fn bytes_read_counter(&self) -> Arc<AtomicU64> {
        Arc::clone(&self.bytes_read)
    }

    /// Whether a queued step failed its check or overflowed a bin (read from the status).
    fn failed(&self) -> Result<bool, GpuError> {
        let status = self.read(&self.status, 16)?;
        let [failed, overflow, _, _]: [u32; 4] = bytemuck::pod_read_unaligned(&status);
        Ok(failed != 0 || overflow != 0)
    }

    /// The observables of the device's current state ([`mechanics::Observables`], as
    /// [`Tissue::observe`] computes them on the host): one evaluation of the state, the
    /// tissue velocity `Σ φ_i v_i` per node and `Σ |v|²` reduced per workgroup, then only the
    /// per-cell quantities (48 bytes a cell) and the workgroups' sums (4 bytes per 256 nodes)
    /// come back, never the fields. `None` when a queued step failed, or the evaluation did
    /// (the sync reports it).
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn observables<T: Real>(
        &mut self,
        tissue: &Tissue<T>,
    ) -> Result<Option<mechanics::Observables>, GpuError> {
        // (A queued step that failed leaves the status set, and the kernels below halt on it:
        // the one read of the status after them says both.)
        self.set_uniforms(tissue, f64::from(self.params.dt));
        self.record_passes(true);
        {
            let enc = self.encoder.as_mut().expect("just recorded");
            let p = &self.pipelines;
            let (nx, ny) = self.groups_nodes;
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("observables"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&p.velocity_sums);
            for g in &self.groups.predict[..self.active.len()] {
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(nx, ny, 1);
            }
            pass.set_pipeline(&p.velocity_reduce);
            pass.dispatch_workgroups(nx, ny, 1);
        }
        self.flush();
        if self.failed()? {
            return Ok(None);
        }
        let q = self.cell_quantities_now()?;
        let (nx, ny) = self.groups_nodes;
        let parts = self.read(&self.v2_part, u64::from(nx * ny) * 4)?;
        let v2: f64 = bytemuck::cast_slice::<u8, f32>(&parts)
            .iter()
            .map(|&v| f64::from(v))
            .sum();
        let o = mechanics::Observables::from_cells(
            v2 / self.lattice.len() as f64,
            q.chunks_exact(CELL_STRIDE)
                .map(|row| mechanics::CellObservables::from(&cell_state_of(row))),
        );
        Ok(Some(o))
    }

    /// What the last evaluation of the queued steps computed ([`Backend::evaluation`]): the
    /// per-cell quantities (48 bytes a cell) and, when `pressure`, `P` per lattice node (16
    /// bytes a node, of which the first 4 are kept). `None` when a queued step failed.
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn device_evaluation(
        &mut self,
        pressure: bool,
    ) -> Result<Option<mechanics::backend::DeviceEvaluation>, GpuError> {
        self.flush();
        if self.failed()? {
            return Ok(None);
        }
        let q = self.cell_quantities_now()?;
        let cells = q.chunks_exact(CELL_STRIDE).map(cell_state_of).collect();
        let pressure = if pressure {
            let mut lat = self.read(&self.lat, self.lat_split as u64 * 16)?;
            let rest = self.lattice.len() - self.lat_split;
            if rest > 0 {
                lat.extend(self.read(&self.lat_hi, rest as u64 * 16)?);
            }
            let lat: &[[f32; 4]] = bytemuck::cast_slice(&lat);
            Some(lat.iter().map(|v| f64::from(v[0])).collect())
        } else {
            None
        };
        Ok(Some(mechanics::backend::DeviceEvaluation {
            cells,
            pressure,
        }))
    }

    /// The per-cell quantities as they are on the device now (after a flush).
    fn cell_quantities_now(&self) -> Result<Vec<f32>, GpuError> {
        let bytes = self.read(&self.cell, (self.n_cells * CELL_STRIDE * 4) as u64)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// The state on the device: every cell's field in logical patch order and the patches'
    /// origins.
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn state(&mut self) -> Result<(Vec<f32>, Vec<[usize; 2]>), GpuError> {
        self.flush();
        let phi = self.read_chunks(&self.phi, self.shape.len())?;
        let origin = self.read(&self.origin, (self.n_cells * 8) as u64)?;
        let origin: &[[u32; 2]] = bytemuck::cast_slice(&origin);
        Ok((
            bytemuck::cast_slice(&phi).to_vec(),
            origin
                .iter()
                .map(|o| [o[0] as usize, o[1] as usize])
                .collect(),
        ))
    }

    fn error(message: String) -> StepError {
        StepError::Backend {
            backend: "gpu".into(),
            message,
        }
    }
}

impl<T: Real> Backend<T> for GpuBackend {
    fn supports(&self, part: mechanics::Part) -> bool {
        SUPPORTED.contains(&part)
    }

    fn name(&self) -> &str {
        "gpu"
    }

    fn step(&mut self, tissue: &Tissue<T>, params: &StepParams) -> Result<(), StepError> {
        if params.npc != self.npc {
            return Err(Self::error(format!(
                "the backend was built for {} corrector passes, and the step asks for {}",
                self.npc, params.npc
            )));
        }
        if (tissue.params().omega != 0.0) != self.adhesion {
            return Err(Self::error(format!(
                "the backend was built {} adhesion, and the tissue's ω is now {}: build a new backend for it",
                if self.adhesion { "with" } else { "without" },
                tissue.params().omega
            )));
        }
        self.set_uniforms(tissue, params.dt);
        self.record();
        self.queued.push(params.dt);
        if self.recorded >= BATCH {
            self.flush();
        }
        Ok(())
    }

    fn sync(&mut self, tissue: &mut Tissue<T>) -> Result<(), StepError> {
        self.flush();
        let status = self
            .read(&self.status, 16)
            .map_err(|e| Self::error(e.to_string()))?;
        let status: [u32; 4] = bytemuck::pod_read_unaligned(&status);
        let [failed, overflow, steps, cell] = status;
        let (phi, origins) = self.state().map_err(|e| Self::error(e.to_string()))?;
        let quantities = self
            .cell_quantities()
            .map_err(|e| Self::error(e.to_string()))?;
        let centres: Vec<[f64; 2]> = if steps > 0 {
            quantities
                .chunks_exact(CELL_STRIDE)
                .map(|c| [f64::from(c[9]), f64::from(c[10])])
                .collect()
        } else {
            tissue.centres().to_vec()
        };
        tissue.set_state_from_device(&phi, &origins, &centres);
        let pol: Vec<f32> = if self.polarity {
            let bytes = self
                .read(&self.pol, (self.n_cells * POL_STRIDE * 4) as u64)
                .map_err(|e| Self::error(e.to_string()))?;
            bytemuck::cast_slice(&bytes).to_vec()
        } else {
            Vec::new()
        };
        if self.polarity {
            let mut theta = polarity_angles(tissue);
            let ids = tissue.cell_ids().to_vec();
            for (row, &id) in pol.chunks_exact(POL_STRIDE).zip(&ids) {
                theta[id] = f64::from(row[0]);
                let mut last = mechanics::CellState::default();
                last.area = f64::from(row[4]);
                last.force = mechanics::Vector2::new(f64::from(row[5]), f64::from(row[6]));
                tissue.terms_mut().set_last_evaluation(id, last);
            }
            tissue
                .terms_mut()
                .set_variable("polarity/theta", &theta)
                .map_err(Self::error)?;
        }
        let done = steps as usize;
        let time = self.base.1 + self.queued.iter().take(done).sum::<f64>();
        let iteration = self.base.0 + done as u64;
        let dt = self.queued.get(done).copied().unwrap_or(0.0);
        self.queue_reset();
        self.base = (iteration, time);
        if overflow != 0 {
            tissue.set_clock(iteration, time);
            return Err(Self::error(format!(
                "more cells than a bin of the gather holds ({} per bin) met in one place; the cells are far denser than a confluent tissue: check the initial state",
                bins(self.lattice, &self.shape, self.n_cells).1
            )));
        }
        if failed != 0 {
            tissue.set_clock(iteration, time);
            let slot = cell as usize;
            let q = &quantities[slot * CELL_STRIDE..(slot + 1) * CELL_STRIDE];
            let (lo, hi) = (f64::from(q[3]), f64::from(q[4]));
            if failed == 3 {
                return Err(StepError::TermUnstable {
                    step: iteration,
                    time,
                    term: "polarity".into(),
                    cell: tissue.cell_ids()[slot],
                    stiffness: f64::from(pol[slot * POL_STRIDE + 2]),
                    dt,
                });
            }
            return Err(if failed == 2 {
                StepError::NonFinite {
                    step: iteration,
                    time,
                    cell_idx: slot,
                }
            } else {
                StepError::Unstable {
                    step: iteration,
                    time,
                    cell_idx: slot,
                    phi: if lo < -mechanics::PHI_BOUND { lo } else { hi },
                    dt,
                }
            });
        }
        Ok(())
    }

    fn upload(&mut self, tissue: &Tissue<T>) -> Result<(), StepError> {
        self.flush();
        self.upload_state(tissue)
            .map_err(|e| Self::error(e.to_string()))
    }

    fn evaluation(
        &mut self,
        tissue: &Tissue<T>,
        pressure: bool,
    ) -> Result<Option<mechanics::backend::DeviceEvaluation>, StepError> {
        let _ = tissue;
        self.device_evaluation(pressure)
            .map_err(|e| Self::error(e.to_string()))
    }

    fn observe(&mut self, tissue: &Tissue<T>) -> Result<Option<mechanics::Observables>, StepError> {
        self.observables(tissue)
            .map_err(|e| Self::error(e.to_string()))
    }
}

/// A cell's row of the cell buffer (area, `S_xx`, `S_xy`, `φ_min`, `φ_max`, `F`, `v`, the
/// centre, the population) as the host's per-cell quantities (the terms' force is not kept).
fn cell_state_of(row: &[f32]) -> mechanics::CellState {
    let c = |k: usize| f64::from(row[k]);
    let mut st = mechanics::CellState::default();
    st.area = c(0);
    st.shape = mechanics::TracelessTensor::from([c(1), c(2)]);
    st.force = mechanics::Vector2::new(c(5), c(6));
    st.velocity = mechanics::Vector2::new(c(7), c(8));
    st.phi_min = c(3);
    st.phi_max = c(4);
    st
}

/// The polarity's angle of every identity, as the host holds it.
fn polarity_angles<T: Real>(tissue: &Tissue<T>) -> Vec<f64> {
    tissue
        .terms()
        .state("polarity")
        .map(<[f64]>::to_vec)
        .unwrap_or_default()
}

impl GpuBackend {
    /// Clears the step counter and the queue after a sync.
    fn queue_reset(&mut self) {
        self.queued.clear();
        self.dev
            .queue
            .write_buffer(&self.status, 8, bytemuck::cast_slice(&[0u32]));
    }
}
