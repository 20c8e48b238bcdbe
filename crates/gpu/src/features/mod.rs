//! The extensions of the paper's model on the device, one module each behind one trait,
//! [`Feature`]: its WGSL, the override constant that compiles it into the kernels, its
//! buffers, its fields of the uniforms, the data it writes and reads back, the kernels of its
//! own and the traffic it adds. [`GpuBackend`](crate::GpuBackend) holds them as a list
//! ([`all`]) and asks each in turn. A new feature is a module here, its WGSL file (`wgsl/`,
//! which the module includes), an entry of [`all`], its buffers in the binding table
//! (`bindings.rs`) and its uniforms in [`Params`] or [`Kind`](crate::Kind).

mod adhesion;
mod growth;
mod polarity;
mod walls;

use mechanics::terms::Terms;
use mechanics::{ModelParams, Tissue};
use phasefield::Real;

use crate::bindings::Slot;
use crate::shared::{Kinds, Params};

/// The extensions of the paper's model the GPU backend runs: the built-in polarity term,
/// adhesion, populations (per-cell constants, [`crate::Kind`]), walls and division (the
/// clock on the host, the growth on the device); a tissue with any other part of
/// [`mechanics::Part::ALL`] is refused by [`crate::GpuBackend::check`], naming it.
pub const SUPPORTED: &[mechanics::Part] = &[
    mechanics::Part::Terms,
    mechanics::Part::Adhesion,
    mechanics::Part::Populations,
    mechanics::Part::Walls,
    mechanics::Part::Division,
];

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
/// one refusal, for a tissue ([`crate::GpuBackend::check`]) and for a scene before anything is
/// written (the CLI's).
pub fn unsupported(ext: &mechanics::Extensions, params: &ModelParams) -> Vec<String> {
    let mut out = mechanics::backend::unsupported(ext, params, SUPPORTED);
    out.extend(mechanics::backend::unsupported_settings(
        &ext.settings(params),
        SETTINGS,
    ));
    out
}

/// What the features read of a tissue, whatever its precision: its parameters, its
/// extensions, the identity of each slot, whether the activity is on, and its clock.
pub(crate) struct View<'a> {
    pub params: &'a ModelParams,
    pub walls: Option<&'a mechanics::walls::Walls>,
    pub wall_field: Option<&'a phasefield::WallField>,
    pub terms: &'a Terms,
    pub proliferation: Option<&'a mechanics::division::Proliferation>,
    pub n_kinds: usize,
    pub ids: &'a [usize],
    pub active: bool,
    pub time: f64,
    /// The clock of the state on the device when it was last synced or uploaded (the
    /// backend's; the tissue's own until then).
    pub base: (u64, f64),
}

impl<'a> View<'a> {
    pub fn of<T: Real>(t: &'a Tissue<T>) -> Self {
        Self {
            params: t.params(),
            walls: t.walls(),
            wall_field: t.wall_field(),
            terms: t.terms(),
            proliferation: t.proliferation(),
            n_kinds: t.populations().kinds().len().max(1),
            ids: t.cell_ids(),
            active: t.active(),
            time: t.time(),
            base: (t.iteration(), t.time()),
        }
    }
}

/// The sizes the features' buffers scale with.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dims {
    /// Lattice nodes.
    pub nodes: u64,
    /// The most cells the buffers hold.
    pub cells: u64,
}

/// When a feature's own kernel runs in a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Hook {
    /// Once over the lattice, after the last chunk's lattice pass of every evaluation.
    Lattice,
    /// Once over the cells, after the force pass of the step's first evaluation (`MODE` 0)
    /// or of a corrector (`MODE` 1); not in an evaluation alone.
    Force { corrector: bool },
}

/// A kernel of a feature's own.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Extra {
    /// Its entry point.
    pub entry: &'static str,
    /// When it runs.
    pub hook: Hook,
}

/// Bytes a feature moves to and from device memory per evaluation: per patch node, per
/// lattice node, per cell ([`crate::GpuBackend::bytes_per_node_update`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Traffic {
    pub patch_node: f64,
    pub lattice_node: f64,
    pub cell: f64,
}

/// What the host keeps of a feature's state, written back at a sync.
pub(crate) struct Host<'a> {
    pub terms: &'a mut Terms,
    pub ids: &'a [usize],
}

/// One extension of the model on the device.
pub(crate) trait Feature: Send {
    /// Its WGSL (`wgsl/NAME.wgsl`): its override constant, its equations and its kernels,
    /// joined to the stages' files in every module, whether it is on or not.
    fn wgsl(&self) -> &'static str;

    /// The override constant that compiles it into the kernels (`WALLS`, …), 1 when on.
    fn constant(&self) -> &'static str;

    /// Whether the tissue the backend was built for has it.
    fn on(&self) -> bool;

    /// Its buffers and their bytes for `dims` with it on (16-byte placeholders stand in when
    /// it is off): what the backend allocates and the memory estimate adds up.
    fn buffers(&self, dims: Dims) -> Vec<(Slot, u64)>;

    /// Kernels of its own, and when they run.
    fn kernels(&self) -> &'static [Extra] {
        &[]
    }

    /// Writes its fields of the uniforms for a step of `view`.
    fn uniforms(&self, _view: &View<'_>, _params: &mut Params, _kinds: &mut Kinds) {}

    /// What to write into its buffers: at an upload of a state (`upload`), or before a step
    /// when what it reads changed; empty when nothing did.
    fn data(&mut self, _view: &View<'_>, _upload: bool) -> Vec<(Slot, Vec<u8>)> {
        Vec::new()
    }

    /// Whether a step of `view` still fits the kernels it was compiled with: why not.
    fn check(&self, _view: &View<'_>) -> Result<(), String> {
        Ok(())
    }

    /// The buffer and bytes per cell it reads back at a sync.
    fn readback(&self) -> Option<(Slot, usize)> {
        None
    }

    /// Writes back what it read ([`Feature::readback`], one row a slot) into the host's state.
    fn sync(&self, _rows: &[f32], _host: Host<'_>) -> Result<(), String> {
        Ok(())
    }

    /// The term and the stiffness of the slot `slot` when the kernels stopped a step with the
    /// failure `code` that is this feature's, from its rows read back.
    fn unstable(&self, _code: u32, _rows: &[f32], _slot: usize) -> Option<(&'static str, f64)> {
        None
    }

    /// The bytes it moves per evaluation.
    fn traffic(&self) -> Traffic {
        Traffic::default()
    }
}

/// Every feature, for a tissue that has those of `on` (walls, adhesion, polarity, growth).
pub(crate) fn all(on: On) -> Vec<Box<dyn Feature>> {
    vec![
        Box::new(walls::Walls::new(on.walls)),
        Box::new(adhesion::Adhesion::new(on.adhesion)),
        Box::new(polarity::Polarity::new(on.polarity)),
        Box::new(growth::Growth::new(on.growth)),
    ]
}

/// Which features a tissue has.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct On {
    pub walls: bool,
    pub adhesion: bool,
    pub polarity: bool,
    pub growth: bool,
}

impl On {
    /// Those of a tissue.
    pub fn of<T: Real>(t: &Tissue<T>) -> Self {
        Self {
            walls: t.walls().is_some(),
            adhesion: t.params().omega != 0.0,
            polarity: t.terms().polarity().is_some(),
            growth: t.proliferation().is_some_and(|c| c.growth_time > 0.0),
        }
    }

    /// Those the parts `parts` may hold (for an estimate made before a tissue exists:
    /// division counts as a growth phase, its upper bound).
    pub fn of_parts(parts: &[mechanics::Part]) -> Self {
        Self {
            walls: parts.contains(&mechanics::Part::Walls),
            adhesion: parts.contains(&mechanics::Part::Adhesion),
            polarity: parts.contains(&mechanics::Part::Terms),
            growth: parts.contains(&mechanics::Part::Division),
        }
    }
}
