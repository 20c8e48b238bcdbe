//! The one table of the step's buffers ([`Slot`], [`BINDINGS`]): it generates the kernels'
//! `@group(0) @binding(k)` declarations ([`declarations`]) and each pipeline's bind-group
//! layout ([`layout_entries`]), and the kernels' own use of the buffers, read from the
//! compiled module ([`used_slots`]), says which entries each pipeline binds. A buffer is
//! added in one place, here; its binding number is its place in the table.

/// How a kernel reaches a buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Access {
    /// A uniform block.
    Uniform,
    /// A storage buffer the kernels only read.
    Read,
    /// A storage buffer the kernels read and write.
    ReadWrite,
}

/// One buffer as the kernels declare it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Binding {
    /// Its name in WGSL.
    pub name: &'static str,
    /// Its WGSL type.
    pub ty: &'static str,
    /// How the kernels reach it.
    pub access: Access,
}

macro_rules! slots {
    ($($(#[$doc:meta])* $slot:ident => $name:literal: $ty:literal, $access:ident;)*) => {
        /// A buffer of the step, by its place in [`BINDINGS`] (its binding number).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u32)]
        pub(crate) enum Slot {
            $($(#[$doc])* $slot,)*
        }

        impl Slot {
            /// Every slot, in binding order.
            pub const ALL: &'static [Slot] = &[$(Slot::$slot),*];
        }

        /// The buffers of the step, in binding order.
        pub(crate) const BINDINGS: &[Binding] = &[
            $(Binding { name: $name, ty: $ty, access: Access::$access },)*
        ];
    };
}

slots! {
    /// The uniform parameters ([`crate::Params`]).
    Params => "prm": "Params", Uniform;
    /// The state evaluated (φ in the passes' sense), per chunk.
    X => "x_phi": "array<f32>", Read;
    /// φ_old of the step (the correctors read it; the last writes the new state there).
    Old => "old_phi": "array<f32>", ReadWrite;
    /// `R(φ)` of the first evaluation.
    K1 => "k1": "array<f32>", ReadWrite;
    /// The predictor's or a middle corrector's output.
    Out => "out_phi": "array<f32>", ReadWrite;
    /// Per cell, 12 floats: area, `S_xx`, `S_xy`, `φ_min`, `φ_max`, `F_x`, `F_y`, `v_x`,
    /// `v_y`, centre x, y, and the population index (a u32's bits, written by the host).
    Cell => "cell": "array<f32>", ReadWrite;
    /// Per cell: the lattice origin of its patch (x, y).
    Origin => "origin": "array<vec2<u32>>", ReadWrite;
    /// Per node (`x * ly + y`): `P`, `s2`, `Q_xx`, `Q_xy`, up to node `LAT_SPLIT` (the rest
    /// in [`Slot::LatHi`], so that a lattice of more than 2³¹ bytes fits; the kernels go
    /// through `lat_get` and `lat_set`).
    Lat => "lat": "array<vec4<f32>>", ReadWrite;
    /// The lattice sums from node `LAT_SPLIT` on.
    LatHi => "lat_hi": "array<vec4<f32>>", ReadWrite;
    /// Per bin: the number of cells whose origin lies in it.
    BinCount => "bin_count": "array<atomic<u32>>", ReadWrite;
    /// Per bin: `CAP` slots of cell indices, sorted.
    BinCells => "bin_cells": "array<u32>", ReadWrite;
    /// cos, sin of `2π x/lx` (lx of each), then of `2π y/ly` (ly of each).
    Trig => "trig": "array<vec2<f32>>", Read;
    /// The step's status: failed, overflow, steps done, the failing cell.
    Status => "status": "Status", ReadWrite;
    /// The chunk at hand ([`crate::Chunk`]).
    Chunk => "chunk": "Chunk", Uniform;
    /// Per node, with more than one chunk: the partial sums s1, s2, s3, s4 of the chunks
    /// before this one, split at `LAT_SPLIT` as [`Slot::Lat`] is.
    AccA => "acc_a": "array<vec4<f32>>", ReadWrite;
    /// [`Slot::AccA`] from node `LAT_SPLIT` on.
    AccAHi => "acc_a_hi": "array<vec4<f32>>", ReadWrite;
    /// Per node, with more than one chunk: own, `Q_xx`, `Q_xy` (and one unused).
    AccB => "acc_b": "array<vec4<f32>>", ReadWrite;
    /// [`Slot::AccB`] from node `LAT_SPLIT` on.
    AccBHi => "acc_b_hi": "array<vec4<f32>>", ReadWrite;
    /// The constants of each population ([`crate::Kind`]).
    Kinds => "kinds": "array<Kind, MAX_KINDS>", Uniform;
    /// Walls: `(w, ∇²w)` per node.
    Wall => "wall": "array<vec2<f32>>", Read;
    /// Adhesion: s1 per node.
    AdhS1 => "adh_s1": "array<f32>", ReadWrite;
    /// Adhesion: `∇²s1` per node.
    AdhLap => "adh_lap": "array<f32>", ReadWrite;
    /// Per workgroup of the lattice: Σ |v|² of the tissue velocity over its nodes.
    V2Part => "v2_part": "array<f32>", ReadWrite;
    /// Polarity: per cell, `POL_STRIDE` floats: θ, θ at the step's start, the rate there (or
    /// the stiffness that stopped the step), the noise kick b·N, the area and interface force
    /// of the last evaluation of a step (the propulsion's inputs), and the identity (a u32's
    /// bits).
    Pol => "pol": "array<f32>", ReadWrite;
    /// Growth: per slot, the time its target area starts to grow, less the growth's origin.
    Growth => "growth": "array<f32>", Read;
}

impl Slot {
    /// Its binding number.
    pub fn binding(self) -> u32 {
        self as u32
    }

    /// Its entry of [`BINDINGS`].
    pub fn info(self) -> Binding {
        BINDINGS[self as usize]
    }

    /// Whether the buffer bound here changes with the evaluation and the chunk (the φ arrays
    /// and the chunk's uniform); the others are the same for every bind group.
    pub fn per_evaluation(self) -> bool {
        matches!(
            self,
            Slot::X | Slot::Old | Slot::K1 | Slot::Out | Slot::Chunk
        )
    }
}

/// The WGSL declarations of every buffer, generated from [`BINDINGS`].
pub(crate) fn declarations() -> String {
    let mut out = String::new();
    for (k, b) in BINDINGS.iter().enumerate() {
        let space = match b.access {
            Access::Uniform => "uniform",
            Access::Read => "storage, read",
            Access::ReadWrite => "storage, read_write",
        };
        out.push_str(&format!(
            "@group(0) @binding({k}) var<{space}> {}: {};\n",
            b.name, b.ty
        ));
    }
    out
}

/// The bind-group layout entries of `slots`, from [`BINDINGS`].
pub(crate) fn layout_entries(slots: &[Slot]) -> Vec<wgpu::BindGroupLayoutEntry> {
    slots
        .iter()
        .map(|&s| wgpu::BindGroupLayoutEntry {
            binding: s.binding(),
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: match s.info().access {
                    Access::Uniform => wgpu::BufferBindingType::Uniform,
                    Access::Read => wgpu::BufferBindingType::Storage { read_only: true },
                    Access::ReadWrite => wgpu::BufferBindingType::Storage { read_only: false },
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect()
}

/// Which buffers each entry point of `source` uses, read from the module itself (naga's
/// analysis of every global each entry point and the functions it calls reach): by entry
/// point name, the slots in binding order. A buffer referenced only in a branch that an
/// override constant switches off counts as used (the analysis precedes the constants); the
/// backend binds a 16-byte placeholder there.
///
/// # Errors
/// The parser's or validator's message, for a module that does not compile (a bug of the
/// kernels: the tests compile every one).
pub(crate) fn used_slots(source: &str) -> Result<Vec<(String, Vec<Slot>)>, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| format!("{e:?}"))?;
    let mut out = Vec::new();
    for (k, entry) in module.entry_points.iter().enumerate() {
        let uses = info.get_entry_point(k);
        let mut slots: Vec<Slot> = module
            .global_variables
            .iter()
            .filter(|(h, _)| !uses[*h].is_empty())
            .filter_map(|(_, var)| {
                let b = var.binding.as_ref()?;
                (b.group == 0).then(|| Slot::ALL.get(b.binding as usize).copied())?
            })
            .collect();
        slots.sort_by_key(|s| s.binding());
        out.push((entry.name.clone(), slots));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The declarations name every slot once, at its own binding number, with its access.
    #[test]
    fn the_declarations_follow_the_table() {
        let d = declarations();
        assert_eq!(d.lines().count(), Slot::ALL.len());
        for &s in Slot::ALL {
            let line = d.lines().nth(s.binding() as usize).unwrap();
            assert!(
                line.starts_with(&format!("@group(0) @binding({}) ", s.binding())),
                "{line}"
            );
            assert!(line.contains(&format!(" {}: ", s.info().name)), "{line}");
        }
        assert!(d.contains("var<uniform> prm: Params;"));
        assert!(d.contains("var<storage, read> x_phi: array<f32>;"));
    }

    /// The analysis finds what each kernel reaches, through the functions it calls: the
    /// bins' clearing uses the parameters and the counts only; the lattice pass the walls'
    /// field (behind its override) and, through `use_cell`, the populations' constants.
    #[test]
    fn each_kernel_binds_what_it_uses() {
        let shape = phasefield::PatchShape::new(phasefield::Lattice::new(64, 64), 8).unwrap();
        let source = crate::shader_source(&shape, mechanics::PressureKind::Paper, 32);
        let used = used_slots(&source).unwrap();
        let of = |name: &str| &used.iter().find(|(n, _)| n == name).unwrap().1;
        assert_eq!(of("bin_clear"), &vec![Slot::Params, Slot::BinCount]);
        let lattice = of("lattice_sums");
        for s in [Slot::Wall, Slot::Kinds, Slot::Growth, Slot::X, Slot::Chunk] {
            assert!(lattice.contains(&s), "{s:?} in {lattice:?}");
        }
        for s in [Slot::K1, Slot::Out, Slot::Pol, Slot::Trig] {
            assert!(!lattice.contains(&s), "{s:?} in {lattice:?}");
        }
        assert_eq!(of("count_step"), &vec![Slot::Status]);
    }
}
