//! Adhesion by pair of populations as a node term, the node-term contract's per-population
//! case (`super`): the energy `λ Σ_{i≠j} ω_{p_i p_j} ∫∇φ_i·∇φ_j`, with a symmetric matrix `ω`
//! over the populations, has for a cell `i` of population `p` the derivative
//!
//! ```text
//! −Σ_{j≠i} c_{p p_j} ∇²φ_j = −Σ_q c_pq ∇²s1_q + c_pp ∇²φ_i,     c_pq = 2 ω_pq λ,
//! ```
//!
//! with `s1_q` the sum of the fields of population `q` ([`PopulationSums`]): `b_p = −Σ_q c_pq
//! ∇²s1_q` and the Laplacian coefficient `c_pp`. Its pressure, the φ-weighted sum of the
//! derivative, is `c_pp φ_i ∇²φ_i` per cell in the scatter and `Σ_p s1_p b_p` on the lattice.
//! With every `ω_pq = ω` it is [`super::Adhesion`] of `c = 2ωλ`, to round-off (the sums are
//! grouped by population). The scene key `[adhesion] pairs` builds it
//! (`Populations::with_adhesion`); `[adhesion] omega` is the uniform term.

use super::{laplacian_into, NodeTerm, PopulationSums};
use crate::equations::{adhesion_coefficient, adhesion_derivative, adhesion_pressure};
use crate::evaluation::{SumField, N_SUMS};
use crate::scatter::LatticeSums;

/// Adhesion with the coefficient `c_pq = 2 ω_pq λ` for each pair of populations.
#[derive(Debug, Clone)]
pub(crate) struct PairAdhesion {
    /// `c_pq` at `p * n + q`.
    c: Vec<f64>,
    n: usize,
}

impl PairAdhesion {
    /// The term of the symmetric matrix `omega` (`n × n`, row by row) at the gradient
    /// coefficient `lambda`. Panics unless `omega` is square and symmetric: a scene validates
    /// its matrix before this.
    pub(crate) fn new(omega: &[f64], n: usize, lambda: f64) -> Self {
        assert_eq!(omega.len(), n * n, "ω is n × n");
        for p in 0..n {
            for q in 0..p {
                assert_eq!(omega[p * n + q], omega[q * n + p], "ω is symmetric");
            }
        }
        Self {
            c: omega
                .iter()
                .map(|&w| adhesion_coefficient(w, lambda))
                .collect(),
            n,
        }
    }
}

impl NodeTerm for PairAdhesion {
    fn per_population(&self) -> bool {
        true
    }

    fn population_moments(&self) -> usize {
        1
    }

    fn cell_pressure_coefficient(&self, p: usize) -> f64 {
        self.c[p * self.n + p]
    }

    fn laplacian_coefficient(&self, p: usize) -> f64 {
        self.c[p * self.n + p]
    }

    /// `∇²s1_q` for every population `q`.
    fn scratch_fields(&self) -> usize {
        self.n
    }

    fn add_pressure(
        &self,
        sums: &mut LatticeSums<N_SUMS>,
        populations: &PopulationSums,
        lap: &mut [f64],
    ) {
        const I_P: usize = SumField::P.index();
        let n = self.n;
        assert_eq!(populations.populations(), n, "one sum per population");
        let lattice = sums.lattice();
        let (lx, ly) = (lattice.lx, lattice.ly);
        let nodes = lx * ly;
        for (q, out) in lap.chunks_exact_mut(nodes).enumerate() {
            laplacian_into(lattice, |x| populations.column(q, x), out);
        }
        for x in 0..lx {
            let p_col = sums.columns_read_write::<0>([], I_P, x).1;
            for (y, p_node) in p_col.iter_mut().enumerate() {
                let k = x * ly + y;
                let mut add = 0.0;
                for p in 0..n {
                    let s1 = populations.column(p, x)[y];
                    for q in 0..n {
                        add += adhesion_pressure(self.c[p * n + q], s1, lap[q * nodes + k]);
                    }
                }
                *p_node += add;
            }
        }
    }

    fn add_coefficients(&self, p: usize, lap: &[f64], k0: usize, _a: &mut [f64], b: &mut [f64]) {
        let (n, nodes) = (self.n, lap.len() / self.n);
        for (k, b) in b.iter_mut().enumerate() {
            for q in 0..n {
                *b += adhesion_derivative(self.c[p * n + q], lap[q * nodes + k0 + k], 0.0);
            }
        }
    }
}
