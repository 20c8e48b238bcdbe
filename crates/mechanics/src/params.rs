//! Model and integrator parameters.

use phasefield::EnergyParams;
use serde::{Deserialize, Serialize};

/// Which definition of the tissue pressure `P` enters the stress `σ = −P𝕀 − ζQ` (docs/model.md §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PressureKind {
    /// `P = Σ_i (δF_rep/δφ_i − δF_CH/δφ_i − δF_area/δφ_i)`, the paper's supplementary
    /// definition. In terms of the global sums `s_n = Σ_i φ_i^n`, `sA = Σ_i φ_i A_i`:
    /// `P = (2κ/λ)(s1 s2 − s3) − (8γ/λ)(s1 − 3 s2 + 2 s3) + 2γλ ∇² s1 + (4μ/πR²)(s1 − sA/πR²)`.
    #[default]
    Paper,
    /// `P = Σ_i φ_i δF_rep/δφ_i = (2κ/λ)(s2² − s4)`, the form of the authors' later public code.
    Interaction,
}

/// Everything that defines the dynamics (docs/model.md §2–3).
///
/// Start from [`ModelParams::paper`] (the [`Default`] is the paper at ζ = 0) and change the
/// fields you need; the struct is `#[non_exhaustive]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct ModelParams {
    /// The free energy.
    pub energy: EnergyParams,
    /// Substrate friction ξ (paper: 2): `ξ v_i = F_i`. Larger values slow every cell equally.
    pub xi: f64,
    /// Activity ζ: `> 0` extensile (flowing above a threshold), `< 0` contractile.
    pub zeta: f64,
    /// Pressure definition.
    pub pressure: PressureKind,
    /// Cell–cell adhesion ω (docs/model.md §11.2; default 0, none): the energy
    /// `ωλ Σ_{i≠j} ∫∇φ_i·∇φ_j`, which lowers the energy of a shared interface.
    #[serde(default)]
    pub omega: f64,
}

impl Default for ModelParams {
    /// The paper's parameters at ζ = 0.
    fn default() -> Self {
        Self::paper(0.0)
    }
}

impl ModelParams {
    /// These parameters with the free energy `energy`.
    pub fn with_energy(mut self, energy: EnergyParams) -> Self {
        self.energy = energy;
        self
    }

    /// These parameters with cell–cell adhesion `omega`.
    pub fn with_adhesion(mut self, omega: f64) -> Self {
        self.omega = omega;
        self
    }

    /// These parameters at activity `zeta`.
    pub fn with_zeta(mut self, zeta: f64) -> Self {
        self.zeta = zeta;
        self
    }

    /// These parameters with friction `xi`.
    pub fn with_xi(mut self, xi: f64) -> Self {
        self.xi = xi;
        self
    }

    /// These parameters with the pressure form `pressure`.
    pub fn with_pressure(mut self, pressure: PressureKind) -> Self {
        self.pressure = pressure;
        self
    }

    /// The paper's parameters (γ = 0.01, μ = 3, λ = 2.5, κ = 0.1, R = 8, ξ = 2) at activity `zeta`.
    pub fn paper(zeta: f64) -> Self {
        Self {
            energy: EnergyParams::paper(),
            xi: 2.0,
            zeta,
            pressure: PressureKind::Paper,
            omega: 0.0,
        }
    }

    /// An upper estimate of the largest decay rate of the linearised dynamics around a relaxed
    /// interface: the diffusion `2γλ ∇²` (at most `16γλ` on the five-point stencil), the
    /// double-well (`8γ/λ`), the area constraint (local `4μ/πR²` plus its rank-one part
    /// `8μ/πR²`) and the repulsion (`2κ/λ` per unit overlap, counted twice).
    ///
    /// Heun and forward Euler are unstable on decaying modes when `dt · rate > 2`. Activity is
    /// not in this rate; see [`ModelParams::activity_dt_limit`].
    pub fn stiffness(&self) -> f64 {
        let e = &self.energy;
        let a0 = e.target_area();
        16.0 * e.gamma * e.lambda
            + 8.0 * e.gamma / e.lambda
            + 12.0 * e.mu / a0
            + 4.0 * e.kappa / e.lambda
    }

    /// The time-step limit that activity sets, an empirical fit to the measured stability map
    /// (`docs/stability.csv`): `ACTIVITY_DT · γ (ξ/ξ_paper)² / (ζ² · max(1, κ/κ_paper))`,
    /// infinite at ζ = 0.
    ///
    /// Active flows advect the interfaces, and central-difference advection under an explicit
    /// step is only stable while the interface diffusion (∝ γ) damps it: for forward Euler the
    /// classic bound is `dt < 2D/v²` with `v ∝ ζ/ξ`. The measured limits follow `γ/ζ²` (γ 0.005,
    /// 0.01 at ζ 0.04; ζ 0.04, 0.08 at γ 0.01) and fall further with a stronger repulsion
    /// (κ 0.4 halves the limit; κ 0.05 leaves it). The coefficient [`ACTIVITY_DT`] keeps the
    /// estimate 1.6–3.3× below every measured activity-limited case, Euler and Heun alike.
    /// Contractile activity (ζ < 0) is treated as extensile, which is conservative (measured at
    /// ζ = −0.04: 3.2 against 1.1 for ζ = +0.04).
    pub fn activity_dt_limit(&self) -> f64 {
        if self.zeta == 0.0 {
            return f64::INFINITY;
        }
        let e = &self.energy;
        let paper = Self::paper(0.0);
        let kappa_factor = (e.kappa / paper.energy.kappa).max(1.0);
        let xi_factor = (self.xi / paper.xi).powi(2);
        ACTIVITY_DT * e.gamma * xi_factor / (self.zeta * self.zeta * kappa_factor)
    }

    /// The largest time step the stability estimate allows: the smaller of the passive linear
    /// limit `2 / stiffness()` and the activity limit.
    pub fn max_stable_dt(&self) -> f64 {
        (2.0 / self.stiffness()).min(self.activity_dt_limit())
    }
}

/// The coefficient of [`ModelParams::activity_dt_limit`].
pub const ACTIVITY_DT: f64 = 0.1;

/// Time integration (docs/model.md §4).
///
/// The [`Default`] is the tuned integrator of the work–precision study
/// (`docs/performance.md`): dt 0.5, one Heun corrector. With the default patch margin
/// ([`phasefield::PatchShape::DEFAULT_MARGIN`]) it makes the centre-of-mass error after 20 TU
/// 20× smaller than the paper's margin 12 and dt 0.2, for less cost; dt 0.5 is stable with a
/// factor 8 to spare at the paper's parameters and a factor 2 at ζ = 0.04
/// (`docs/stability.csv`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct StepParams {
    /// Time step in model time units (default 0.5; paper: 0.2). The error of Heun falls as
    /// dt²; above [`ModelParams::max_stable_dt`] the explicit scheme may blow up.
    pub dt: f64,
    /// Heun corrector passes (default 1, the paper's predictor–corrector); 0 is forward
    /// Euler (first order), more passes iterate the trapezoidal rule (each costs one more
    /// evaluation and buys little).
    pub npc: usize,
}

impl Default for StepParams {
    fn default() -> Self {
        Self { dt: 0.5, npc: 1 }
    }
}

impl StepParams {
    /// Time step `dt` with `npc` corrector passes.
    pub const fn new(dt: f64, npc: usize) -> Self {
        Self { dt, npc }
    }

    /// The paper's integrator: dt 0.2, one corrector pass.
    pub fn paper() -> Self {
        Self::new(0.2, 1)
    }

    /// These parameters with time step `dt`.
    pub fn with_dt(mut self, dt: f64) -> Self {
        self.dt = dt;
        self
    }
}

/// Storage precision of the phase fields (arithmetic is always `f64`).
///
/// The default, [`Precision::F32`], was chosen by the work–precision study and the long runs
/// (`docs/performance.md`): at the default margin and dt its error equals f64's to two digits
/// after 20 TU and to five in the long-run statistics, it is up to 18 % faster and uses 25 %
/// less memory; it adds a floor of about 1e-6 in the centres and 1e-5 in φ.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// Double precision (the reference).
    F64,
    /// Single-precision storage, double-precision arithmetic (the default).
    #[default]
    F32,
}
