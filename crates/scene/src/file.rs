//! The scene file as written ([`SceneFile`]): one TOML document that describes a run
//! completely, with `deny_unknown_fields` on every table and `--set section.key=value`
//! overrides (ripgrep's low-level arguments: close to the file, checked only for syntax).

use mechanics::terms::{Align, CellNematic, Polarity, Population, Populations, Propulsion, Terms};
use mechanics::{ModelParams, Precision, PressureKind, StepParams};
use phasefield::PatchShape;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use crate::error::SceneError;

/// `[domain]`: the periodic lattice.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    /// Nodes along x.
    pub lx: usize,
    /// Nodes along y.
    pub ly: usize,
}

/// How the cells are placed initially.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InitKind {
    /// Uniformly random, reproducible from `[run] seed`, initial discs not overlapping.
    #[default]
    Random,
    /// A near-hexagonal packing.
    Hexagonal,
    /// The centres in `[cells] positions`.
    Positions,
    /// The state saved in `[cells] from`: a frame (`RUN/frames/frame_STEP.npz`) or a
    /// checkpoint (`RUN/checkpoints/checkpoint_STEP.npz`) of a run on the same lattice with
    /// the same number of cells.
    Frame,
}

/// `[cells]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellsSpec {
    /// Number of cells.
    pub count: usize,
    /// Target radius R (target area πR²; paper: 8).
    #[serde(default = "default_radius")]
    pub radius: f64,
    /// Initial layout.
    #[serde(default)]
    pub init: InitKind,
    /// Centres for `init = "positions"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub positions: Option<Vec<[f64; 2]>>,
    /// The saved state for `init = "frame"`: a frame or checkpoint file (a relative path is
    /// taken from the scene file's directory by `monolayer run`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<String>,
    /// Radius of the initial discs (default R/2: cells start smaller than their target and
    /// grow during relaxation, docs/model.md §6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub init_radius: Option<f64>,
}

fn default_radius() -> f64 {
    8.0
}

/// `[model]`: the paper's parameters by default.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Model {
    /// Interface stiffness γ.
    pub gamma: f64,
    /// Area constraint μ.
    pub mu: f64,
    /// Interface width λ.
    pub lambda: f64,
    /// Repulsion κ.
    pub kappa: f64,
    /// Substrate friction ξ.
    pub xi: f64,
    /// Activity ζ after relaxation.
    pub zeta: f64,
    /// Pressure definition.
    pub pressure: PressureKind,
}

impl Default for Model {
    /// The paper's parameters ([`ModelParams::paper`]) at ζ = 0.
    fn default() -> Self {
        let p = ModelParams::paper(0.0);
        let e = p.energy;
        Self {
            gamma: e.gamma,
            mu: e.mu,
            lambda: e.lambda,
            kappa: e.kappa,
            xi: p.xi,
            zeta: p.zeta,
            pressure: p.pressure,
        }
    }
}

/// `[integrator]`.
///
/// The defaults (margin 16, dt 0.5, Heun, f32 storage) come from the front of the
/// work–precision study (`docs/performance.md`): for less than the cost of the paper's margin
/// 12 and dt 0.2 they make the
/// centre-of-mass error after 20 TU 20× smaller (4.6e-4 against 1.0e-2 nodes), because at
/// margin 12 the neglected patch tail dominates every time-step error. dt 0.5 is stable with
/// a factor 8 to spare at the paper's parameters and a factor 2 at ζ = 0.04
/// (`docs/stability.csv`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Integrator {
    /// Time step (default 0.5; the paper's scenes use 0.2).
    pub dt: f64,
    /// Heun corrector passes (1: predictor–corrector; 0: forward Euler).
    pub npc: usize,
    /// Patch margin m (patch side 2m+1; default 16, the paper's 12); 0 stores every cell on
    /// the full domain.
    pub margin: usize,
    /// Storage precision of the fields, `"f32"` (default) or `"f64"`. Arithmetic is always
    /// `f64`; `"f32"` rounds each stored value, which halves the memory the step moves and
    /// makes it up to 18 % faster. At the default margin and dt its error is that of `"f64"`
    /// to two digits after 20 TU and to five in the long-run statistics (work–precision
    /// study, `docs/performance.md`); it adds a floor of about 1e-6 in the centres and 1e-5
    /// in φ, so use `"f64"` for runs that aim below that (margin ≥ 20 with dt ≤ 0.1, or the
    /// full domain).
    pub precision: Precision,
    /// Refuse a `dt` above the stability estimate (default true). The estimate is 1.1–3.3×
    /// below the measured limits (`docs/stability.csv`); with `false` a run may go above it,
    /// and the step check still stops it, with its output kept, if it blows up.
    pub stability_check: bool,
    /// An error-controlled time step (`mechanics::adaptive`: Heun with its Euler predictor
    /// as the error estimate, a PI controller) instead of the fixed `dt`, which is then the
    /// first step (default false). Frames, rows and checkpoints land on their times.
    pub adaptive: bool,
    /// With `adaptive`: the largest local error per step, max over cells and nodes of
    /// |φ_Heun − φ_Euler| (default 1e-3; the global error after 20 TU is about 0.1 × this at
    /// the paper's parameters, `docs/performance.md`). Refused without `adaptive`, where it
    /// would have no effect.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// With `adaptive`: the largest step (default: the stability estimate of the active
    /// phase, as for a fixed `dt`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dt_max: Option<f64>,
    /// Where the steps run: `"cpu"` (default) or `"gpu"` (the `gpu` crate: wgpu on any Vulkan
    /// device; a binary built with `--features gpu`). The GPU runs the paper's minimal model
    /// with the fixed Heun step (`npc` ≥ 1) on patches (`margin` > 0), in f32 storage and f32
    /// arithmetic; other settings and the extra physics sections are refused by name.
    #[serde(skip_serializing_if = "ComputeBackend::is_cpu")]
    pub backend: ComputeBackend,
}

/// `[integrator] backend`: where the steps run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ComputeBackend {
    /// The CPU step of `mechanics` (threads: `--threads`).
    #[default]
    Cpu,
    /// The `gpu` crate's device step.
    Gpu,
}

/// Whether a value is its default 0 (a key a written scene leaves out).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl ComputeBackend {
    /// The default, which a written scene leaves out.
    pub fn is_cpu(&self) -> bool {
        *self == Self::Cpu
    }
}

impl Default for Integrator {
    /// The library's tuned defaults: [`StepParams::default`],
    /// [`PatchShape::DEFAULT_MARGIN`] and [`Precision::default`].
    fn default() -> Self {
        let step = StepParams::default();
        Self {
            dt: step.dt,
            npc: step.npc,
            margin: PatchShape::DEFAULT_MARGIN,
            precision: Precision::default(),
            stability_check: true,
            adaptive: false,
            tolerance: None,
            dt_max: None,
            backend: ComputeBackend::Cpu,
        }
    }
}

/// `[run]`: times in model time units.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Run {
    /// Relaxation at ζ = 0 before the activity is switched on.
    pub relax_time: f64,
    /// Active time after relaxation.
    pub time: f64,
    /// Seed of the random initial positions.
    pub seed: u64,
    /// Interval between frames (full fields).
    pub output_every: f64,
    /// Interval between rows of `series.csv` (default: `output_every`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub series_every: Option<f64>,
    /// Interval between checkpoints, from which `monolayer run --resume` continues (default:
    /// a twentieth of the run, so a killed run loses at most about 5 %; a checkpoint is also
    /// written every 10 minutes of wall time and at the end).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub checkpoint_every: Option<f64>,
    /// Whether each frame carries every cell's force split by its origin (`force.pressure`,
    /// `force.shape_activity`, …; default false: one evaluation more per part at each frame).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub forces_by_origin: bool,
}

impl Default for Run {
    fn default() -> Self {
        Self {
            relax_time: 0.0,
            time: 100.0,
            seed: 1,
            output_every: 10.0,
            series_every: None,
            checkpoint_every: None,
            forces_by_origin: false,
        }
    }
}

/// `[polarity]`: self-propulsion along a polarity with rotational diffusion and alignment
/// (docs/model.md §11.1, `mechanics::terms::Polarity`); absent: no self-propulsion.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolaritySpec {
    /// The propulsion force α per cell (the reference code's examples: 0.04); a cell alone
    /// moves at α/ξ.
    pub alpha: f64,
    /// The rotational diffusion constant D_r per time unit (default 0): the polarity's
    /// persistence time is 1/D_r. The reference code's `D-pol` is `√(2 D_r)`.
    #[serde(default)]
    pub rotational_diffusion: f64,
    /// What the polarity turns towards (default `"none"`).
    #[serde(default)]
    pub align: AlignKind,
    /// The alignment rate J per unit of the target's magnitude (default 0; the reference
    /// code's `J-pol`, 0.1 in its examples).
    #[serde(default)]
    pub align_rate: f64,
    /// How the propulsion is spread (default `"cell"`).
    #[serde(default)]
    pub propulsion: PropulsionKind,
    /// Every cell's initial angle in radians (0 along +x); absent: uniform on the circle,
    /// from `[run] seed`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
    /// Contact inhibition of locomotion η (default 0): the propulsion stalls as
    /// `α exp(−η max(0, −F·p)/α)` against the cells in front.
    #[serde(default)]
    pub contact_inhibition: f64,
}

/// `[nematic]`: a nematic inside each cell, with its own activity and dynamics
/// (docs/model.md §11.6, `mechanics::terms::CellNematic`); absent: none.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NematicSpec {
    /// The activity ζ_Q of the cells' nematics (> 0 extensile, < 0 contractile): the stress
    /// `−ζ_Q Σ_j φ_j q_j` beside the shape activity's `−ζ Σ_j φ_j S_j`, switched on after the
    /// relaxation like ζ.
    pub zeta: f64,
    /// The magnitude S of each cell's nematic `q = S (cos 2θ, sin 2θ)` (default 1).
    #[serde(default = "one")]
    pub order: f64,
    /// What the nematic's axis turns towards (default `"none"`): the cell's velocity, its
    /// interface force or its long axis.
    #[serde(default)]
    pub align: AlignKind,
    /// The alignment rate J per unit of the target's magnitude (default 0): near alignment θ
    /// relaxes at `J |target|` (the reference code's `J-nem` is J/2).
    #[serde(default)]
    pub align_rate: f64,
    /// The elastic constant K (default 0): the rate `K ⟨q_i × M⟩_i` that turns a cell's
    /// nematic towards its neighbours', `M = Σ_j φ_j q_j`.
    #[serde(default)]
    pub elastic: f64,
    /// The coupling W to the flow's rotation rate (default 0; 1 corotates the nematic with
    /// the flow).
    #[serde(default)]
    pub vorticity: f64,
    /// The rotational diffusion constant D_r per time unit (default 0; the reference code's
    /// `D-nem` is `√(2 D_r)`).
    #[serde(default)]
    pub rotational_diffusion: f64,
    /// Every cell's initial angle in radians (0 along +x); absent: uniform, from `[run] seed`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
}

fn one() -> f64 {
    1.0
}

impl NematicSpec {
    /// The term these keys describe (without the populations' own ζ_Q).
    pub fn term(&self) -> CellNematic {
        let n = CellNematic::new(self.zeta)
            .with_order(self.order)
            .with_alignment(self.align.align(), self.align_rate)
            .with_elastic(self.elastic)
            .with_vorticity(self.vorticity)
            .with_rotational_diffusion(self.rotational_diffusion);
        match self.angle {
            Some(theta) => n.with_initial_angle(theta),
            None => n,
        }
    }
}

/// `[friction]`: friction between overlapping cells (docs/model.md §11.8,
/// `mechanics::friction`); absent: none.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// ξ_c, the friction per unit of overlap `o_ij = Σ_x φ_i φ_j`:
    /// `ξ_i v_i = F_i − ξ_c Σ_j o_ij (v_i − v_j)`.
    pub cells: f64,
    /// The solver's relative residual (default 1e-10).
    #[serde(default = "friction_tolerance")]
    pub tolerance: f64,
}

fn friction_tolerance() -> f64 {
    1e-10
}

impl FrictionSpec {
    /// The part these keys describe.
    pub fn friction(&self) -> mechanics::friction::CellFriction {
        mechanics::friction::CellFriction::new(self.cells).with_tolerance(self.tolerance)
    }
}

/// `[adhesion]`: cell–cell adhesion (docs/model.md §11.2); absent: none.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdhesionSpec {
    /// The adhesion strength ω (the reference code's cluster example: 0.01): the energy
    /// `ωλ Σ_{i≠j} ∫∇φ_i·∇φ_j` of shared interfaces (default 0 when `pairs` is given).
    #[serde(default)]
    pub omega: f64,
    /// The adhesion ω_pq of each pair of populations, one row per `[[population]]` in order
    /// (symmetric): the energy `λ Σ_{i≠j} ω_{p_i p_j} ∫∇φ_i·∇φ_j`, so that an unlike contact's
    /// adhesion is free of the like ones (differential adhesion). In place of `omega`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pairs: Option<Vec<Vec<f64>>>,
}

/// `[repulsion]`: the repulsion of each pair of populations (docs/model.md §11.2); absent:
/// `[model] kappa` for every pair.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RepulsionSpec {
    /// κ_pq, one row per `[[population]]` in order (symmetric): the energy
    /// `(1/λ) Σ_{i<j} κ_{p_i p_j} ∫φ_i²φ_j²` in place of one κ for every pair (`[model] kappa`
    /// then no longer acts).
    pub pairs: Vec<Vec<f64>>,
}

/// `[walls] kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WallKind {
    /// Walls along x at the bottom and top rows (periodic in x), the free band `width` wide.
    Channel,
    /// Walls on all four edges.
    Box,
    /// Free inside a disc of `radius` (or an ellipse of `semi_axes`) centred in the domain.
    Disc,
    /// A band across the domain at its middle, `width` wide along x, removed when the
    /// activity switches on (after `[run] relax_time`): a wound that opens.
    Wound,
    /// Walls read from the image or array file `mask`.
    Mask,
}

/// `[walls]`: static walls that repel cells (and optionally adhere to them), docs/model.md
/// §11.4; absent: none.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallsSpec {
    /// The geometry.
    pub kind: WallKind,
    /// The decay length ℓ_w of the wall field `w = e^{−d/ℓ_w}` outside the solid, in nodes
    /// (default 1; the reference code's examples 0.5–1).
    #[serde(default = "default_wall_thickness")]
    pub thickness: f64,
    /// The wall repulsion κ_w (default 1, the reference code's examples).
    #[serde(default = "default_wall_kappa")]
    pub kappa: f64,
    /// The wall adhesion ω_w (default 0).
    #[serde(default)]
    pub omega: f64,
    /// The wall friction ξ_w per node of overlap with the wall (default 0): a cell moves at
    /// `F_i/(ξ + ξ_w Σ_x φ_i w)`. Left out of a written scene when 0, so that the scenes of runs
    /// made before the key existed read the same.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub friction: f64,
    /// `"channel"`: the free width in nodes (default `ly − 2`, one solid row at each edge);
    /// `"wound"`: the band's width (default `lx / 4`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    /// `"disc"`: its radius in nodes (default `min(lx, ly)/2 − 1`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// `"disc"`: an ellipse's semi-axes `[a, b]` along x and y instead of `radius`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub semi_axes: Option<[f64; 2]>,
    /// `"mask"`: a PNG image (`lx` pixels wide, `ly` high, its top row at y = ly − 1) whose
    /// bright pixels (luminance ≥ ½) are solid, or a `.npy` array of shape `(lx, ly)`,
    /// indexed `[x, y]`, whose non-zero entries are solid. A relative path is taken from the
    /// scene file's directory by `monolayer run`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mask: Option<String>,
    /// `"mask"`: swap solid and free (for a micropattern image whose bright pixels are where
    /// cells may be; default false).
    #[serde(default)]
    pub invert: bool,
}

fn default_wall_thickness() -> f64 {
    1.0
}

fn default_wall_kappa() -> f64 {
    1.0
}

/// `[division] axis`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DivisionAxis {
    /// Across the long axis of the cell's shape tensor (the daughters lie along it).
    #[default]
    Long,
    /// Along a uniformly random direction.
    Random,
}

/// `[division]`: cells divide by a cell-cycle clock, and are extruded or die (docs/model.md
/// §11.5); absent: the number of cells is fixed.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DivisionSpec {
    /// The mean cell-cycle time `T₀ + 1/k` in time units: a cell divides when its age
    /// reaches its cycle `T₀ + Exp(1/k)`, drawn at its birth.
    pub cycle_time: f64,
    /// The mean `1/k` of the cycle's exponential part (default a quarter of `cycle_time`;
    /// `cycle_time` itself gives a memoryless clock).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle_spread: Option<f64>,
    /// The growth time `T_g` (default 0): once a cell's age reaches its cycle, its target
    /// area ramps from `πR²` to `2πR²` over `T_g`, and it divides at the end; the mean time
    /// between divisions is then `cycle_time + growth_time`.
    #[serde(default)]
    pub growth_time: f64,
    /// The axis of the split (default `"long"`).
    #[serde(default)]
    pub axis: DivisionAxis,
    /// At most this many cells: a cell due to divide waits while the tissue has them
    /// (default twice the cells that fill the lattice, `2 lx ly/(πR²)`). The memory guard
    /// sizes the run for this many.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_cells: Option<usize>,
    /// A cell whose area `Σφ_i²` falls below this fraction of `πR²` is extruded (removed);
    /// absent or 0: no extrusion. The spec's example: 0.2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extrusion: Option<f64>,
    /// A death rate `k_d` per time unit (default 0): each cell is removed at an age drawn at
    /// its birth, exponential of mean `1/k_d`.
    #[serde(default)]
    pub death_rate: f64,
    /// Contact inhibition of proliferation: a cell due to divide waits while its pressure
    /// `p_i = Σφ_i P/Σφ_i` is above this; absent: never waits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_gate: Option<f64>,
    /// Stress-based extrusion: a cell whose pressure `p_i = Σφ_i P/Σφ_i` rises above this is
    /// removed; absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extrusion_pressure: Option<f64>,
}

/// `[[population]]`: a population of cells with parameters of their own (docs/model.md
/// §11.3); absent: every cell has `[model]`'s. The counts must add up to `[cells] count`;
/// cells are dealt to populations by a shuffle drawn from `[run] seed`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PopulationSpec {
    /// A name for outputs (default `"A"`, `"B"`, … by position).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Number of cells.
    pub count: usize,
    /// Interface stiffness γ (default `[model] gamma`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma: Option<f64>,
    /// Area constraint μ (default `[model] mu`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
    /// Target radius R (default `[cells] radius`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Friction ξ (default `[model] xi`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi: Option<f64>,
    /// Activity ζ (default `[model] zeta`), switched on after the relaxation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeta: Option<f64>,
    /// Propulsion α (default `[polarity] alpha`; needs `[polarity]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<f64>,
    /// Rotational diffusion D_r (default `[polarity] rotational_diffusion`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotational_diffusion: Option<f64>,
    /// Alignment rate J (default `[polarity] align_rate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub align_rate: Option<f64>,
    /// The activity ζ_Q of the cells' nematics (default `[nematic] zeta`; needs `[nematic]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nematic_zeta: Option<f64>,
    /// The nematic's alignment rate J (default `[nematic] align_rate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nematic_align_rate: Option<f64>,
    /// The nematic's elastic constant K (default `[nematic] elastic`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nematic_elastic: Option<f64>,
    /// The nematic's rotational diffusion D_r (default `[nematic] rotational_diffusion`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nematic_rotational_diffusion: Option<f64>,
}

impl PopulationSpec {
    /// Its own `[ζ_Q, J, K, D_r]` of the cells' nematic, where given.
    pub fn nematic_values(&self) -> [Option<f64>; 4] {
        [
            self.nematic_zeta,
            self.nematic_align_rate,
            self.nematic_elastic,
            self.nematic_rotational_diffusion,
        ]
    }

    /// The population's name: its own, or a letter by its position `k`.
    pub fn name(&self, k: usize) -> String {
        self.name.clone().unwrap_or_else(|| {
            let letter = (b'A' + (k % 26) as u8) as char;
            if k < 26 {
                letter.to_string()
            } else {
                format!("{letter}{}", k / 26)
            }
        })
    }
}

/// `[polarity] align`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AlignKind {
    /// No alignment: a persistent random walk.
    #[default]
    None,
    /// To the cell's own velocity (flocking).
    Velocity,
    /// To the interface force, away from the cells it presses against.
    Force,
    /// To the cell's long axis, the end nearer the polarity.
    Shape,
}

/// `[polarity] propulsion`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PropulsionKind {
    /// A whole-cell force α p.
    #[default]
    Cell,
    /// A force density α φ² p, summing to α A p (α per unit area).
    Density,
}

impl AlignKind {
    /// The alignment target it names.
    pub fn align(self) -> Align {
        match self {
            AlignKind::None => Align::None,
            AlignKind::Velocity => Align::Velocity,
            AlignKind::Force => Align::Force,
            AlignKind::Shape => Align::Shape,
        }
    }
}

impl PolaritySpec {
    /// The term these keys describe.
    pub fn term(&self) -> Polarity {
        let align = self.align.align();
        let propulsion = match self.propulsion {
            PropulsionKind::Cell => Propulsion::Cell,
            PropulsionKind::Density => Propulsion::Density,
        };
        let p = Polarity::new(self.alpha)
            .with_rotational_diffusion(self.rotational_diffusion)
            .with_alignment(align, self.align_rate)
            .with_propulsion(propulsion)
            .with_contact_inhibition(self.contact_inhibition);
        match self.angle {
            Some(theta) => p.with_initial_angle(theta),
            None => p,
        }
    }
}

/// A whole scene file, as written: parsed, not yet validated (validate it into a
/// [`crate::Scene`] with [`SceneFile::validate`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[domain]`.
    pub domain: Domain,
    /// `[cells]`.
    pub cells: CellsSpec,
    /// `[model]`.
    #[serde(default)]
    pub model: Model,
    /// `[integrator]`.
    #[serde(default)]
    pub integrator: Integrator,
    /// `[run]`.
    #[serde(default)]
    pub run: Run,
    /// `[polarity]`, when the cells are self-propelled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarity: Option<PolaritySpec>,
    /// `[friction]`, when overlapping cells drag each other.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionSpec>,
    /// `[nematic]`, when the cells carry a nematic of their own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nematic: Option<NematicSpec>,
    /// `[repulsion]`, when the repulsion depends on the pair of populations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repulsion: Option<RepulsionSpec>,
    /// `[adhesion]`, when the cells adhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adhesion: Option<AdhesionSpec>,
    /// `[[population]]`, when cells differ.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub population: Vec<PopulationSpec>,
    /// `[walls]`, when the cells are confined.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walls: Option<WallsSpec>,
    /// `[division]`, when cells divide.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub division: Option<DivisionSpec>,
    /// `[terms.NAME]`: the tables of terms from a user's crate, each handed to the builder
    /// registered under its name ([`crate::register_term`]).
    #[serde(default, rename = "terms", skip_serializing_if = "BTreeMap::is_empty")]
    pub user_terms: BTreeMap<String, toml::Table>,
}

impl SceneFile {
    /// Parses a scene from TOML text, applying `--set section.key=value` overrides first.
    ///
    /// # Errors
    /// [`SceneError::Parse`] on bad syntax, unknown keys, wrong types or bad overrides.
    pub fn parse(text: &str, overrides: &[String]) -> Result<Self, SceneError> {
        // The arrays of tables: `[population]` (one table) where `[[population]]` (a list)
        // is meant would otherwise get serde's "invalid type: map, expected a sequence", or
        // TOML's "duplicate key" when there are two.
        for section in ARRAYS_OF_TABLES {
            let single = format!("[{section}]");
            if let Some(k) = text.lines().position(|l| l.trim() == single) {
                return Err(SceneError::Parse(format!(
                    "line {}: [{section}] is written as one table, but {section}s are a list of tables: write [[{section}]] (two brackets) above each {section}",
                    k + 1
                )));
            }
        }
        let mut table: toml::Table =
            toml::from_str(text).map_err(|e| SceneError::Parse(e.to_string()))?;
        for o in overrides {
            apply_override(&mut table, o)?;
        }
        let mut file: Self = table.clone().try_into().map_err(|e: toml::de::Error| {
            let msg = e.to_string();
            match type_hint(&table, &msg) {
                Some(hint) => SceneError::Parse(format!("{}: {hint}", msg.trim_end())),
                None => SceneError::Parse(msg),
            }
        })?;
        if let Some(d) = &mut file.division {
            d.cycle_spread.get_or_insert(0.25 * d.cycle_time);
        }
        Ok(file)
    }

    /// The scene as TOML, with every default filled in.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("scenes always serialise")
    }

    /// Radius of the initial discs.
    pub fn init_radius(&self) -> f64 {
        self.cells.init_radius.unwrap_or(0.5 * self.cells.radius)
    }

    /// The model parameters at activity `zeta`.
    pub fn model_params(&self, zeta: f64) -> ModelParams {
        let m = &self.model;
        let mut energy = phasefield::EnergyParams::paper();
        energy.gamma = m.gamma;
        energy.mu = m.mu;
        energy.lambda = m.lambda;
        energy.kappa = m.kappa;
        energy.radius = self.cells.radius;
        ModelParams::paper(zeta)
            .with_energy(energy)
            .with_xi(m.xi)
            .with_pressure(m.pressure)
            .with_adhesion(self.adhesion.as_ref().map_or(0.0, |a| a.omega))
    }

    /// The physics terms beyond the minimal model, with the run's seed for their noise.
    pub fn terms(&self) -> Terms {
        let mut terms = Terms::new(self.run.seed);
        if let Some(p) = &self.polarity {
            let mut term = p.term();
            for (k, pop) in self.population.iter().enumerate() {
                if pop.alpha.is_some()
                    || pop.rotational_diffusion.is_some()
                    || pop.align_rate.is_some()
                {
                    term = term.with_population(
                        k,
                        pop.alpha,
                        pop.rotational_diffusion,
                        pop.align_rate,
                    );
                }
            }
            terms = terms.with(term);
        }
        if let Some(n) = &self.nematic {
            let mut term = n.term();
            for (k, pop) in self.population.iter().enumerate() {
                let own = pop.nematic_values();
                if own.iter().any(Option::is_some) {
                    term = term.with_population(k, own);
                }
            }
            terms = terms.with(term);
        }
        terms
    }

    /// The keys that set a term's initial per-cell state, each as `(the state's array in a
    /// frame, the scene key, its value)`: `("polarity.theta", "[polarity] angle", 0.3)`. A
    /// run that starts from a saved state holding that array takes the array's values, which
    /// win over the key (and the run says so).
    pub fn initial_state_keys(&self) -> Vec<(String, String, f64)> {
        let mut out = Vec::new();
        if let Some(a) = self.polarity.as_ref().and_then(|p| p.angle) {
            out.push(("polarity.theta".into(), "[polarity] angle".into(), a));
        }
        if let Some(a) = self.nematic.as_ref().and_then(|n| n.angle) {
            out.push(("nematic.theta".into(), "[nematic] angle".into(), a));
        }
        out
    }

    /// The populations of `[[population]]` (empty without), cells dealt by `[run] seed`.
    pub fn populations(&self) -> Populations {
        if self.population.is_empty() {
            return Populations::default();
        }
        let counts: Vec<usize> = self.population.iter().map(|p| p.count).collect();
        let pops = Populations::new(self.population_kinds(), &counts, self.run.seed);
        let pops = match self.adhesion.as_ref().and_then(|a| a.pairs.as_ref()) {
            Some(rows) => pops.with_adhesion(rows.iter().flatten().copied().collect()),
            None => pops,
        };
        match &self.repulsion {
            Some(r) => pops.with_repulsion(r.pairs.iter().flatten().copied().collect()),
            None => pops,
        }
    }

    /// The parameters each `[[population]]` overrides, in order.
    pub fn population_kinds(&self) -> Vec<Population> {
        self.population
            .iter()
            .map(|p| {
                let mut k = Population::new();
                k.gamma = p.gamma;
                k.mu = p.mu;
                k.radius = p.radius;
                k.xi = p.xi;
                k.zeta = p.zeta;
                k
            })
            .collect()
    }

    /// The integrator parameters.
    pub fn step_params(&self) -> StepParams {
        StepParams::new(self.integrator.dt, self.integrator.npc)
    }
}

/// A fix for serde's message `msg` about a value of the wrong type ("invalid type: ...
/// in `section.key`"), naming what the key takes: for a key of a fixed set of words, the
/// words, found by asking serde itself (the same table with the key set to a word no key
/// takes answers "unknown variant, expected one of ..."), so no list is kept by hand.
fn type_hint(table: &toml::Table, msg: &str) -> Option<String> {
    if !msg.contains("invalid type") {
        return None;
    }
    let key = msg
        .lines()
        .find_map(|l| l.trim().strip_prefix("in `")?.strip_suffix('`'))?;
    let (section, name) = key.split_once('.')?;
    let mut probe = table.clone();
    let toml::Value::Table(sec) = probe.get_mut(section)? else {
        return None;
    };
    sec.insert(name.into(), toml::Value::String("\u{1}".into()));
    let answer = match probe.try_into::<SceneFile>() {
        Err(e) => e.to_string(),
        Ok(_) => return None,
    };
    let words = answer
        .contains("unknown variant")
        .then(|| answer.split("expected ").nth(1)?.lines().next())
        .flatten()
        .map(|w| w.trim_start_matches("one of "));
    if let Some(words) = words {
        let first = words.split('`').nth(1).unwrap_or("...");
        return Some(format!(
            "{key} takes one of {words}: write {name} = \"{first}\" (in quotes) in the scene file, or --set {key}={first}"
        ));
    }
    let expected = msg.split("expected ").nth(1)?.lines().next()?;
    let what = match expected {
        "usize" | "u64" | "u32" | "i64" => "a whole number",
        "f64" | "f32" => "a number",
        "a boolean" | "bool" => "true or false",
        other => other,
    };
    Some(format!(
        "{key} takes {what} (docs/scenes.md lists every key with its default)"
    ))
}

/// The sections that are lists of tables (`[[population]]`).
const ARRAYS_OF_TABLES: [&str; 1] = ["population"];

fn apply_override(table: &mut toml::Table, o: &str) -> Result<(), SceneError> {
    let bad = |why: &str| {
        SceneError::Parse(format!(
            "--set {o}: {why}; write --set section.key=value, e.g. --set model.zeta=0.005"
        ))
    };
    let (path, value) = o.split_once('=').ok_or_else(|| bad("no '='"))?;
    let (section, key) = path
        .trim()
        .split_once('.')
        .ok_or_else(|| bad("the key needs a section"))?;
    let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {}", value.trim())) {
        Ok(mut t) => t.remove("v").expect("parsed"),
        Err(_) => {
            let v = value.trim();
            let digits = v.strip_prefix(['-', '+']).unwrap_or(v);
            if !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit() || c == '_') {
                return Err(bad(&format!(
                    "{v} is out of range (integers in a scene are at most {})",
                    i64::MAX
                )));
            }
            toml::Value::String(v.to_string())
        }
    };
    // An array of tables (`[[population]]`): `section.K.key` sets the key of its K-th table.
    if ARRAYS_OF_TABLES.contains(&section) && !table.contains_key(section) {
        return Err(bad(&format!(
            "the scene has no [[{section}]] tables, and --set changes a key of one that is there; add [[{section}]] tables to the scene file (docs/scenes.md lists their keys)"
        )));
    }
    if let Some(toml::Value::Array(items)) = table.get_mut(section) {
        let Some((index, key)) = key.split_once('.') else {
            return Err(bad(&format!(
                "[[{section}]] is a list of tables: name one by its position from 0, e.g. --set {section}.0.{key}=..."
            )));
        };
        let n = items.len();
        let item = index
            .parse::<usize>()
            .ok()
            .and_then(|k| items.get_mut(k))
            .ok_or_else(|| {
                bad(&format!(
                    "the scene has {n} [[{section}]] tables, numbered from 0; {index} is not one of them"
                ))
            })?;
        let toml::Value::Table(item) = item else {
            return Err(bad("that entry is not a table"));
        };
        item.insert(key.to_string(), value);
        return Ok(());
    }
    // A term's table (`[terms.NAME]`): `terms.NAME.key`.
    if section == "terms" {
        let Some((name, key)) = key.split_once('.') else {
            return Err(bad(&format!(
                "a term's key is named with its table: --set terms.{key}.KEY=..."
            )));
        };
        let terms = table
            .entry("terms")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let toml::Value::Table(terms) = terms else {
            return Err(bad("[terms] is not a table of term tables"));
        };
        let Some(toml::Value::Table(term)) = terms.get_mut(name) else {
            return Err(bad(&format!(
                "the scene has no [terms.{name}] table; add it to the scene file to switch the term on"
            )));
        };
        term.insert(key.to_string(), value);
        return Ok(());
    }
    let sec = table
        .entry(section.to_string())
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let toml::Value::Table(sec) = sec else {
        return Err(bad("that section is not a table"));
    };
    sec.insert(key.to_string(), value);
    Ok(())
}
