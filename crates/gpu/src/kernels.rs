//! The step's pipelines and their bind groups: each kernel is compiled with the features'
//! constants and its own, laid out with the buffers its entry point uses
//! ([`crate::bindings::used_slots`]), and bound once per evaluation's role and chunk where it
//! reads a per-evaluation buffer (once otherwise).

use std::collections::HashMap;

use crate::bindings::{layout_entries, Slot};
use crate::features::{Extra, Feature, Hook};

/// Which φ arrays an evaluation reads and writes: a bind group's role.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// Evaluates φ; the predictor into `pred`, `R` into `k1`.
    Predict,
    /// Evaluates `pred` (0) or `spare` (1) as the last corrector, into φ, re-centred.
    Last(usize),
    /// Evaluates `pred` (0) or `spare` (1) as a middle corrector, into the other.
    Middle(usize),
}

impl Role {
    /// Every role, in the order of [`Role::index`].
    pub const ALL: [Role; 5] = [
        Role::Predict,
        Role::Last(0),
        Role::Last(1),
        Role::Middle(0),
        Role::Middle(1),
    ];

    fn index(self) -> usize {
        match self {
            Role::Predict => 0,
            Role::Last(k) => 1 + k,
            Role::Middle(k) => 3 + k,
        }
    }
}

/// The buffers of the step: one per slot, and the φ arrays and chunk uniforms per chunk.
pub(crate) struct Buffers {
    /// The buffer of each slot that does not change with the evaluation.
    pub fixed: HashMap<Slot, wgpu::Buffer>,
    pub phi: Vec<wgpu::Buffer>,
    pub pred: Vec<wgpu::Buffer>,
    pub k1: Vec<wgpu::Buffer>,
    /// The middle correctors' second array, with `npc` ≥ 2.
    pub spare: Option<Vec<wgpu::Buffer>>,
    /// What an evaluation that neither reads φ_old nor writes an output binds there.
    pub dummy: wgpu::Buffer,
    pub chunk_info: Vec<wgpu::Buffer>,
}

impl Buffers {
    /// The buffer at `slot` for chunk `k` in the role `role`.
    pub fn at(&self, slot: Slot, role: Role, k: usize) -> &wgpu::Buffer {
        let spare = |k: usize| self.spare.as_ref().map_or(&self.dummy, |s| &s[k]);
        match (slot, role) {
            (Slot::K1, _) => &self.k1[k],
            (Slot::Chunk, _) => &self.chunk_info[k],
            (Slot::X, Role::Predict) => &self.phi[k],
            (Slot::X, Role::Last(0) | Role::Middle(0)) => &self.pred[k],
            (Slot::X, _) => spare(k),
            (Slot::Old, Role::Predict) => &self.dummy,
            (Slot::Old, _) => &self.phi[k],
            (Slot::Out, Role::Predict) => &self.pred[k],
            (Slot::Out, Role::Middle(0)) => spare(k),
            (Slot::Out, Role::Middle(_)) => &self.pred[k],
            (Slot::Out, _) => &self.dummy,
            _ => &self.fixed[&slot],
        }
    }
}

/// One compiled kernel and its bind groups.
pub(crate) struct Kernel {
    pub pipeline: wgpu::ComputePipeline,
    /// By role and chunk, when it binds a per-evaluation buffer; one otherwise.
    groups: Vec<Vec<wgpu::BindGroup>>,
}

impl Kernel {
    /// Its bind group for chunk `k` of an evaluation in `role`.
    pub fn group(&self, role: Role, k: usize) -> &wgpu::BindGroup {
        if self.groups.len() == 1 {
            &self.groups[0][0]
        } else {
            &self.groups[role.index()][k]
        }
    }

    /// Sets its pipeline and bind group on `pass` and dispatches `groups` workgroups.
    pub fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        role: Role,
        k: usize,
        groups: (u32, u32),
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, self.group(role, k), &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }
}

/// Builds the kernels of one module.
pub(crate) struct Builder<'a> {
    pub device: &'a wgpu::Device,
    pub module: &'a wgpu::ShaderModule,
    /// The slots each entry point uses.
    pub used: HashMap<String, Vec<Slot>>,
    pub buffers: &'a Buffers,
    /// Every feature's constant, 1 when the feature is on.
    pub flags: Vec<(&'static str, f64)>,
}

impl Builder<'_> {
    /// The kernel `entry` with its own `constants` beside the features'.
    pub fn kernel(&self, entry: &str, constants: &[(&str, f64)]) -> Kernel {
        let d = self.device;
        let slots = &self.used[entry];
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(entry),
            entries: &layout_entries(slots),
        });
        let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(entry),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let all: Vec<(&str, f64)> = self
            .flags
            .iter()
            .copied()
            .chain(constants.iter().copied())
            .collect();
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&pipeline_layout),
            module: self.module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &all,
                ..Default::default()
            },
            cache: None,
        });
        let group = |role: Role, k: usize| {
            let entries: Vec<wgpu::BindGroupEntry<'_>> = slots
                .iter()
                .map(|&s| wgpu::BindGroupEntry {
                    binding: s.binding(),
                    resource: self.buffers.at(s, role, k).as_entire_binding(),
                })
                .collect();
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(entry),
                layout: &layout,
                entries: &entries,
            })
        };
        let groups = if slots.iter().any(|s| s.per_evaluation()) {
            let chunks = self.buffers.phi.len();
            Role::ALL
                .iter()
                .map(|&r| (0..chunks).map(|k| group(r, k)).collect())
                .collect()
        } else {
            vec![vec![group(Role::Predict, 0)]]
        };
        Kernel { pipeline, groups }
    }
}

/// The step's kernels.
pub(crate) struct Kernels {
    /// The cell pass of a step's first evaluation, with the check.
    pub cell_check: Kernel,
    /// The cell pass of the other evaluations.
    pub cell: Kernel,
    pub bin_clear: Kernel,
    pub bin_fill: Kernel,
    pub bin_sort: Kernel,
    pub lattice: Kernel,
    /// The force pass and update: the predictor, a middle corrector, the last corrector.
    pub predict: Kernel,
    pub correct: Kernel,
    pub correct_last: Kernel,
    pub count: Kernel,
    /// The observables' tissue velocity and its Σ |v|² per workgroup.
    pub velocity_sums: Kernel,
    pub velocity_reduce: Kernel,
    /// The features' own kernels, with when they run.
    pub extra: Vec<(Extra, Kernel)>,
}

impl Kernels {
    /// Every kernel of the step for the `features`.
    pub fn new(b: &Builder<'_>, features: &[Box<dyn Feature>]) -> Self {
        let extra = features
            .iter()
            .filter(|f| f.on())
            .flat_map(|f| f.kernels().iter())
            .map(|&e| {
                let mode = match e.hook {
                    Hook::Force { corrector } => vec![("MODE", f64::from(u8::from(corrector)))],
                    Hook::Lattice => Vec::new(),
                };
                (e, b.kernel(e.entry, &mode))
            })
            .collect();
        Self {
            cell_check: b.kernel("cell_sums", &[("CHECK", 1.0)]),
            cell: b.kernel("cell_sums", &[("CHECK", 0.0)]),
            bin_clear: b.kernel("bin_clear", &[]),
            bin_fill: b.kernel("bin_fill", &[]),
            bin_sort: b.kernel("bin_sort", &[]),
            lattice: b.kernel("lattice_sums", &[]),
            predict: b.kernel("force_update", &[("MODE", 0.0)]),
            correct: b.kernel("force_update", &[("MODE", 1.0)]),
            correct_last: b.kernel("force_update", &[("MODE", 2.0)]),
            count: b.kernel("count_step", &[]),
            velocity_sums: b.kernel("velocity_sums", &[]),
            velocity_reduce: b.kernel("velocity_reduce", &[]),
            extra,
        }
    }

    /// The features' kernels that run at `hook`.
    pub fn at(&self, hook: Hook) -> impl Iterator<Item = &Kernel> {
        self.extra
            .iter()
            .filter(move |(e, _)| e.hook == hook)
            .map(|(_, k)| k)
    }
}
