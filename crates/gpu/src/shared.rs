//! The structures the host and the kernels share ([`Params`], [`Kind`], [`Chunk`]), each
//! written once: [`shared_struct!`] gives the Rust definition and its WGSL declaration; and the
//! constants both sides use (`WG`, `CELL_STRIDE`).

use bytemuck::{Pod, Zeroable};

/// Invocations per workgroup (the shader's `WG`).
pub(crate) const WG: u32 = 256;
/// Floats per cell in the cell buffer (the shader's `CELL_STRIDE`).
pub(crate) const CELL_STRIDE: usize = 12;

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
pub(crate) type Kinds = [Kind; MAX_KINDS];

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
