//! The kernels' WGSL source: the constants of a patch shape and pressure form, the shared
//! structures, the buffers' declarations, then the files of `wgsl/`: what every stage shares,
//! the equations, one file per stage of the step and one per feature.

use mechanics::PressureKind;
use phasefield::PatchShape;

use crate::shared::{Chunk, Kind, Params, MAX_KINDS, WG};

/// The stages' files of `wgsl/`, in the order they are joined (WGSL's module-scope
/// declarations may come in any order; this one reads from the general to the particular);
/// each feature's file follows ([`crate::features::Feature::wgsl`]).
const STAGES: [&str; 7] = [
    include_str!("wgsl/common.wgsl"),
    include_str!("wgsl/equations.wgsl"),
    include_str!("wgsl/cells.wgsl"),
    include_str!("wgsl/bins.wgsl"),
    include_str!("wgsl/lattice.wgsl"),
    include_str!("wgsl/force.wgsl"),
    include_str!("wgsl/observe.wgsl"),
];

/// The WGSL source of the step for patches of `shape` and the pressure form `kind`, with
/// `cap` cells per bin: the constants, the shared structures, the buffers' declarations
/// (`bindings.rs`) and the stage and feature files of `wgsl/`, in one module.
pub fn shader_source(shape: &PatchShape, kind: PressureKind, cap: u32) -> String {
    shader_source_split(shape, kind, cap, u32::MAX, Variant::Plain)
}

/// [`shader_source`] with the lattice arrays split into two bindings at node `split`, in the
/// kernels' `variant`.
pub(crate) fn shader_source_split(
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
         const LOCAL_LEN: u32 = {ll}u;\n{params}{kind}{chunk}{bindings}{stages}{features}",
        params = Params::WGSL,
        kind = Kind::WGSL,
        chunk = Chunk::WGSL,
        bindings = crate::bindings::declarations(),
        stages = STAGES.concat(),
        features = crate::features::all(crate::features::On::default())
            .iter()
            .map(|f| f.wgsl())
            .collect::<String>(),
        npt = plen.div_ceil(WG),
        paper = u32::from(kind == PressureKind::Paper),
        lp = u32::from(local),
        ll = if local { plen } else { 1 },
    )
}

/// Which form of the kernels a backend runs ([`crate::GpuOptions::variant`]): each computes the same
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
