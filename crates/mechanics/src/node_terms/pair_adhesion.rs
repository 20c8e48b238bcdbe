//! Adhesion by pair of populations as a node term, the node-term contract's per-population
//! case (`super`): the energy `λ Σ_{i≠j} ω_{p_i p_j} ∫∇φ_i·∇φ_j`, with a symmetric matrix `ω`
//! over the populations, has for a cell `i` of population `p` the derivative
//!
//! ```text
//! −Σ_{j≠i} c_{p p_j} ∇²φ_j = −Σ_q c_pq ∇²s1_q + c_pp ∇²φ_i,     c_pq = 2 ω_pq λ,
//! ```
//!
//! with `s1_q` the sum of the fields of population `q` ([`PopulationSums`]): `b_p = −Σ_q c_pq
//! ∇²s1_q = −∇²t_p` with `t_p = Σ_q c_pq s1_q` (one Laplacian per population), and the
//! Laplacian coefficient `c_pp`. Its pressure, the φ-weighted sum of the
//! derivative, is `c_pp φ_i ∇²φ_i` per cell in the scatter and `Σ_p s1_p b_p` on the lattice.
//! Its lattice loops run column by column over contiguous slices.
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

    /// `t_p = Σ_q c_pq s1_q` and its Laplacian for every population `p`: by linearity
    /// `Σ_q c_pq ∇²s1_q = ∇²t_p`, one Laplacian per population.
    fn scratch_fields(&self) -> usize {
        2 * self.n
    }

    fn add_pressure(
        &self,
        sums: &mut LatticeSums<N_SUMS>,
        populations: &PopulationSums,
        scratch: &mut [f64],
    ) {
        use rayon::prelude::*;
        const I_P: usize = SumField::P.index();
        let n = self.n;
        assert_eq!(populations.populations(), n, "one sum per population");
        let lattice = sums.lattice();
        let (lx, ly) = (lattice.lx, lattice.ly);
        let nodes = lx * ly;
        let (t, lap) = scratch.split_at_mut(n * nodes);
        // t_p, column by column (each column a sum over q of contiguous slices).
        t.par_chunks_mut(ly).enumerate().for_each(|(k, out)| {
            let (p, x) = (k / lx, k % lx);
            out.fill(0.0);
            for q in 0..n {
                let c = self.c[p * n + q];
                for (o, &s) in out.iter_mut().zip(populations.column(q, x)) {
                    *o += c * s;
                }
            }
        });
        for (p, out) in lap.chunks_exact_mut(nodes).enumerate() {
            let t_p = &t[p * nodes..(p + 1) * nodes];
            laplacian_into(lattice, |x| &t_p[x * ly..(x + 1) * ly], out);
        }
        // The lattice part of the pressure, `−Σ_pq c_pq s1_p ∇²s1_q = −Σ_p s1_p ∇²t_p`
        // ([`adhesion_pressure`] with c = 1).
        for x in 0..lx {
            let p_col = sums.columns_read_write::<0>([], I_P, x).1;
            for p in 0..n {
                let s1 = populations.column(p, x);
                let lap_t = &lap[p * nodes + x * ly..p * nodes + (x + 1) * ly];
                for ((out, &s), &l) in p_col.iter_mut().zip(s1).zip(lap_t) {
                    *out += adhesion_pressure(1.0, s, l);
                }
            }
        }
    }

    /// `b_p = −∇²t_p` ([`adhesion_derivative`] with c = 1).
    fn add_coefficients(
        &self,
        p: usize,
        scratch: &[f64],
        k0: usize,
        _a: &mut [f64],
        b: &mut [f64],
    ) {
        let nodes = scratch.len() / (2 * self.n);
        let lap_t = &scratch[(self.n + p) * nodes + k0..];
        for (b, &l) in b.iter_mut().zip(lap_t) {
            *b += adhesion_derivative(1.0, l, 0.0);
        }
    }
}
