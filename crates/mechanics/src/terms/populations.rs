//! Per-cell parameters: cells in populations, each with its own γ, μ, R, ξ and ζ
//! (docs/model.md §11.3).
//!
//! With per-cell values the equations keep their form with the cell's own constants:
//! `δF/δφ_i` with `γ_i, μ_i, R_i`; `v_i = F_i/ξ_i`; the active stress `−Σ_j ζ_j φ_j S_j`.
//! The pressure of the paper form, `P = Σ_i δF/δφ_i`, then holds the weighted sums
//! `Σ γ_j φ_j`, `Σ (μ_j/a_j) φ_j` … of the extensions' table; here they need no field of their
//! own, since every per-cell term of `P` is summed cell by cell into `U` already
//! ([`crate::equations::pressure_cell_part`] with the cell's coefficients). κ and λ stay global.
//!
//! A population without an override of a parameter takes the tissue's ([`crate::ModelParams`]),
//! so that populations that override nothing step exactly as the tissue without them, to the
//! bit. A population's ζ acts while the activity is on ([`crate::Tissue::active`]).

use phasefield::EnergyCoefficients;

use super::NoiseKey;

/// The `stage` of the keys of the shuffle that assigns cells to populations: apart from the
/// terms' and the division clock's (which had used `1 << 61` too, so that with one seed a
/// cell's population and its cycle time were drawn from the same numbers).
const SHUFFLE_STAGE: u64 = 1 << 60;
use crate::ModelParams;

/// The parameters one population overrides; `None` takes the tissue's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Population {
    /// Interface stiffness γ.
    pub gamma: Option<f64>,
    /// Area constraint μ.
    pub mu: Option<f64>,
    /// Target radius R.
    pub radius: Option<f64>,
    /// Friction ξ.
    pub xi: Option<f64>,
    /// Activity ζ.
    pub zeta: Option<f64>,
}

impl Population {
    /// A population that overrides nothing.
    pub fn new() -> Self {
        Self::default()
    }
    /// With its own γ.
    pub fn with_gamma(mut self, v: f64) -> Self {
        self.gamma = Some(v);
        self
    }
    /// With its own μ.
    pub fn with_mu(mut self, v: f64) -> Self {
        self.mu = Some(v);
        self
    }
    /// With its own R.
    pub fn with_radius(mut self, v: f64) -> Self {
        self.radius = Some(v);
        self
    }
    /// With its own ξ.
    pub fn with_xi(mut self, v: f64) -> Self {
        self.xi = Some(v);
        self
    }
    /// With its own ζ.
    pub fn with_zeta(mut self, v: f64) -> Self {
        self.zeta = Some(v);
        self
    }

    /// The model parameters of this population: the tissue's `base` with its own γ, μ, R, ξ
    /// and ζ where it gives them.
    pub fn params(&self, base: &ModelParams) -> ModelParams {
        let mut m = *base;
        m.energy.gamma = self.gamma.unwrap_or(m.energy.gamma);
        m.energy.mu = self.mu.unwrap_or(m.energy.mu);
        m.energy.radius = self.radius.unwrap_or(m.energy.radius);
        m.xi = self.xi.unwrap_or(m.xi);
        m.zeta = self.zeta.unwrap_or(m.zeta);
        m
    }
}

/// The populations of a tissue and the population of every cell (by identity).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Populations {
    kinds: Vec<Population>,
    of_cell: Vec<u16>,
    /// The adhesion ω_pq of each pair of populations, `n × n` row by row (symmetric), when it
    /// depends on the pair (`[adhesion] pairs`, docs/model.md §11.2).
    adhesion: Option<Vec<f64>>,
    /// The repulsion κ_pq of each pair of populations, `n × n` row by row (symmetric), when it
    /// depends on the pair (`[repulsion] pairs`, docs/model.md §11.2).
    repulsion: Option<Vec<f64>>,
}

/// A cell's constants in one evaluation (one set per population), as the step uses them and
/// a backend must ([`Populations::constants`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct CellConstants {
    /// The free energy's coefficients, with the population's γ, μ and R.
    pub coef: EnergyCoefficients,
    /// The friction ξ.
    pub xi: f64,
    /// The weight of the cell's `S_i` in the active stress's sum: 1 when every cell has the
    /// tissue's ζ (which then multiplies the sum), ζ_i otherwise.
    pub zeta_weight: f64,
}

impl Populations {
    /// Populations of `counts[k]` cells each with the parameters `kinds[k]`, the cells
    /// (identities `0..Σ counts`) dealt to them by a shuffle drawn from `seed`, so that the
    /// populations are mixed whatever the initial layout.
    ///
    /// # Panics
    /// If the lengths differ or there are more than 65536 populations.
    pub fn new(kinds: Vec<Population>, counts: &[usize], seed: u64) -> Self {
        assert_eq!(kinds.len(), counts.len(), "a count per population");
        assert!(kinds.len() <= 1 << 16, "at most 65536 populations");
        let mut of_cell: Vec<u16> = counts
            .iter()
            .enumerate()
            .flat_map(|(k, &c)| std::iter::repeat_n(k as u16, c))
            .collect();
        // Fisher–Yates from counter-based uniforms.
        for i in (1..of_cell.len()).rev() {
            let u = NoiseKey {
                seed,
                cell: i as u64,
                step: 0,
                stage: SHUFFLE_STAGE,
            }
            .uniform();
            let j = ((u * (i + 1) as f64) as usize).min(i);
            of_cell.swap(i, j);
        }
        Self {
            kinds,
            of_cell,
            adhesion: None,
            repulsion: None,
        }
    }

    /// These populations with the adhesion `omega` of each pair (`n × n` row by row, `n` the
    /// number of populations): the energy `λ Σ_{i≠j} ω_{p_i p_j} ∫∇φ_i·∇φ_j` in place of one ω
    /// for every pair, so that an unlike contact's adhesion is free of the like ones
    /// (differential adhesion).
    ///
    /// # Panics
    /// Unless `omega` is `n × n` and symmetric, every entry finite: a scene checks its matrix
    /// before this (naming the pair).
    pub fn with_adhesion(mut self, omega: Vec<f64>) -> Self {
        self.assert_pair_matrix(&omega, "ω_pq");
        self.adhesion = Some(omega);
        self
    }

    /// These populations with the repulsion `kappa` of each pair (`n × n` row by row): the
    /// energy `(1/λ) Σ_{i≠j} κ_{p_i p_j} ∫φ_i²φ_j²` in place of one κ for every pair. A cell
    /// of population `p` has `κ_pp` among its own constants ([`Populations::params`]), and
    /// the node term `PairRepulsion` adds what the unlike pairs differ by.
    ///
    /// # Panics
    /// Unless `kappa` is `n × n` and symmetric, every entry finite: a scene checks its matrix
    /// before this (naming the pair).
    pub fn with_repulsion(mut self, kappa: Vec<f64>) -> Self {
        self.assert_pair_matrix(&kappa, "κ_pq");
        self.repulsion = Some(kappa);
        self
    }

    fn assert_pair_matrix(&self, m: &[f64], what: &str) {
        let n = self.kinds.len();
        assert_eq!(m.len(), n * n, "{what} is n × n for n populations");
        for p in 0..n {
            for q in 0..n {
                assert!(m[p * n + q].is_finite(), "{what} is finite");
                assert_eq!(m[p * n + q], m[q * n + p], "{what} is symmetric");
            }
        }
    }

    /// The adhesion of each pair of populations (`n × n` row by row), when it depends on the
    /// pair.
    pub fn adhesion(&self) -> Option<&[f64]> {
        self.adhesion.as_deref()
    }

    /// The repulsion of each pair of populations (`n × n` row by row), when it depends on the
    /// pair.
    pub fn repulsion(&self) -> Option<&[f64]> {
        self.repulsion.as_deref()
    }

    /// The largest repulsion a cell of population `k` feels from any neighbour (the tissue's
    /// κ without a matrix): what the stability estimate takes.
    pub fn largest_repulsion(&self, k: usize, base: &ModelParams) -> f64 {
        let n = self.kinds.len();
        match &self.repulsion {
            Some(m) if k < n => m[k * n..(k + 1) * n].iter().copied().fold(0.0, f64::max),
            _ => base.energy.kappa,
        }
    }

    /// Populations with the given population of every cell, by identity.
    ///
    /// # Panics
    /// If a cell names a population that is not there.
    pub fn from_assignment(kinds: Vec<Population>, of_cell: Vec<u16>) -> Self {
        assert!(of_cell.iter().all(|&k| (k as usize) < kinds.len()));
        Self {
            kinds,
            of_cell,
            adhesion: None,
            repulsion: None,
        }
    }

    /// The same populations with the assignment `of_cell` as a saved file holds it (one
    /// population index per cell, as numbers), checked: `n` entries, each a whole index of a
    /// population that is there.
    ///
    /// # Errors
    /// A message with the count and the number of populations when they do not fit.
    pub fn reassigned(&self, of_cell: &[f64], n: usize) -> Result<Self, String> {
        let k = self.kinds.len();
        if of_cell.len() != n
            || of_cell
                .iter()
                .any(|&v| !(v >= 0.0 && v.fract() == 0.0 && (v as usize) < k))
        {
            return Err(format!(
                "{} entries for {n} cells, or one that is not the index of one of the {k} populations",
                of_cell.len()
            ));
        }
        Ok(Self {
            adhesion: self.adhesion.clone(),
            repulsion: self.repulsion.clone(),
            ..Self::from_assignment(
                self.kinds.clone(),
                of_cell.iter().map(|&v| v as u16).collect(),
            )
        })
    }

    /// Whether there are none (every cell has the tissue's parameters).
    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    /// The populations.
    pub fn kinds(&self) -> &[Population] {
        &self.kinds
    }

    /// Assigns the new identity `id` (the next one, `of_cell().len()`) to population `kind`:
    /// a daughter of a division, in its mother's population. A no-op without populations.
    pub(crate) fn add_cell(&mut self, id: usize, kind: u16) {
        if self.kinds.is_empty() {
            return;
        }
        assert_eq!(id, self.of_cell.len(), "identities are added in order");
        self.of_cell.push(kind);
    }

    /// The population of every cell, by identity.
    pub fn of_cell(&self) -> &[u16] {
        &self.of_cell
    }

    /// The population of cell `id` (0 without populations).
    pub fn population(&self, id: usize) -> usize {
        self.of_cell.get(id).map_or(0, |&k| k as usize)
    }

    /// Whether some population's ζ differs from the tissue's in an evaluation with `params`:
    /// the active stress is then `−Σ ζ_j φ_j S_j`, summed with each cell's weight (otherwise
    /// `−ζ Σ φ_j S_j`, as without populations, to the bit).
    pub(crate) fn mixed_zeta(&self, params: &ModelParams, active: bool) -> bool {
        (0..self.kinds.len()).any(|k| self.zeta(k, params, active) != params.zeta)
    }

    /// The model parameters of population `k` ([`Population::params`], with its own repulsion
    /// `κ_kk` when the repulsion depends on the pair; the tissue's `base` for a population
    /// that is not there).
    pub fn params(&self, k: usize, base: &ModelParams) -> ModelParams {
        let n = self.kinds.len();
        self.kinds.get(k).map_or(*base, |p| {
            let mut own = p.params(base);
            if let Some(m) = &self.repulsion {
                own.energy.kappa = m[k * n + k];
            }
            own
        })
    }

    /// The ζ of population `k`, with the activity on or off.
    pub fn zeta(&self, k: usize, params: &ModelParams, active: bool) -> f64 {
        match self.kinds.get(k).and_then(|p| p.zeta) {
            Some(z) if active => z,
            Some(_) => 0.0,
            None => params.zeta,
        }
    }

    /// The constants of every population in an evaluation with `params` into `out` (one entry,
    /// the tissue's, without populations), indexed by [`Populations::population`]. Allocates
    /// only when there are more populations than `out` held before.
    pub(crate) fn fill_constants(
        &self,
        params: &ModelParams,
        active: bool,
        mixed: bool,
        out: &mut Vec<CellConstants>,
    ) {
        out.clear();
        if self.kinds.is_empty() {
            // Weighted (a cell's own active tensor beside `S_i`): every cell by the tissue's ζ.
            out.push(CellConstants {
                coef: params.energy.coefficients(),
                xi: params.xi,
                zeta_weight: if mixed { params.zeta } else { 1.0 },
            });
            return;
        }
        out.extend((0..self.kinds.len()).map(|k| {
            let own = self.params(k, params);
            CellConstants {
                coef: own.energy.coefficients(),
                xi: own.xi,
                zeta_weight: if mixed {
                    self.zeta(k, params, active)
                } else {
                    1.0
                },
            }
        }));
    }

    /// What an evaluation with `params` and the activity `active` takes from the populations:
    /// the ζ that multiplies the active stress's sum (the tissue's, or 1 when the populations'
    /// ζ differ and each `S_i` is weighted by its own) and the constants of every population,
    /// indexed by [`Populations::population`] (one entry, the tissue's, without populations).
    /// The host's step uses the same (`kernels::evaluate`); a backend takes them from here.
    pub fn constants(&self, params: &ModelParams, active: bool) -> (f64, Vec<CellConstants>) {
        let mixed = self.mixed_zeta(params, active);
        let mut out = Vec::new();
        self.fill_constants(params, active, mixed, &mut out);
        (if mixed { 1.0 } else { params.zeta }, out)
    }

    /// Whether some cell has a non-zero ζ in an evaluation with `params`.
    pub(crate) fn any_activity(&self, params: &ModelParams, active: bool) -> bool {
        params.zeta != 0.0
            || (active && self.kinds.iter().any(|k| k.zeta.is_some_and(|z| z != 0.0)))
    }
}
