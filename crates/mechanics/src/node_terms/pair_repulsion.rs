//! Repulsion by pair of populations as a node term, the node-term contract's per-population
//! case (`super`) with two moments: the energy `(1/λ) Σ_{i≠j} κ_{p_i p_j} ∫φ_i²φ_j²`, with a
//! symmetric matrix `κ` over the populations, has for a cell `i` of population `p` the
//! derivative
//!
//! ```text
//! (2/λ) φ_i (Σ_q κ_pq s2_q − κ_pp φ_i²)
//!   = (2κ_pp/λ) φ_i (s2 − φ_i²)  +  φ_i (2/λ) Σ_q (κ_pq − κ_pp) s2_q,
//! ```
//!
//! with `s2_q` the sum of the squares of the fields of population `q` ([`PopulationSums`]).
//! The first part is the paper's repulsion with the cell's own `κ_pp`, which the cell's
//! constants carry (`Populations::params`); this term is the second, `a_p = (2/λ) Σ_q
//! (κ_pq − κ_pp) s2_q`. Its pressure: the cells' `U` has their own `κ_pp`, the lattice formula
//! [`crate::equations::pressure`] the tissue's κ, and the term adds the difference
//!
//! ```text
//! Σ_pq (2κ_pq/λ) X_p s2_q − (2κ/λ) X s2,     X_p = s1_p (paper form) or s2_p (interaction),
//! ```
//!
//! so that the pressure is the pair energy's `Σ_i δF/δφ_i` (or `Σ_i φ_i δF/δφ_i`), as with
//! one κ. With every `κ_pq = κ` it adds zero. Its lattice loops run column by column over
//! contiguous slices. The scene key `[repulsion] pairs` builds it (`Populations::with_repulsion`).

use super::{NodeTerm, PopulationSums};
use crate::evaluation::{SumField, N_SUMS};
use crate::params::PressureKind;
use crate::scatter::LatticeSums;

/// Repulsion with `κ_pq` for each pair of populations.
#[derive(Debug, Clone)]
pub(crate) struct PairRepulsion {
    /// `2κ_pq/λ` at `p * n + q`.
    c: Vec<f64>,
    /// `2(κ_pq − κ_pp)/λ` at `p * n + q`.
    d: Vec<f64>,
    /// `2κ/λ` of the tissue, which [`crate::equations::pressure`] used.
    c_tissue: f64,
    kind: PressureKind,
    n: usize,
}

impl PairRepulsion {
    /// The term of the symmetric matrix `kappa` (`n × n`, row by row) at the gradient
    /// coefficient `lambda`, in a tissue of repulsion `tissue_kappa` and pressure form `kind`.
    /// Panics unless `kappa` is square and symmetric: a scene validates its matrix before this.
    pub(crate) fn new(
        kappa: &[f64],
        n: usize,
        lambda: f64,
        tissue_kappa: f64,
        kind: PressureKind,
    ) -> Self {
        assert_eq!(kappa.len(), n * n, "κ is n × n");
        for p in 0..n {
            for q in 0..p {
                assert_eq!(kappa[p * n + q], kappa[q * n + p], "κ is symmetric");
            }
        }
        let rep = |k: f64| 2.0 * k / lambda;
        Self {
            c: kappa.iter().map(|&k| rep(k)).collect(),
            d: (0..n * n)
                .map(|pq| rep(kappa[pq]) - rep(kappa[(pq / n) * (n + 1)]))
                .collect(),
            c_tissue: rep(tissue_kappa),
            kind,
            n,
        }
    }
}

impl NodeTerm for PairRepulsion {
    fn per_population(&self) -> bool {
        true
    }

    fn population_moments(&self) -> usize {
        2
    }

    /// `a_p` for every population `p`.
    fn scratch_fields(&self) -> usize {
        self.n
    }

    fn add_pressure(
        &self,
        sums: &mut LatticeSums<N_SUMS>,
        populations: &PopulationSums,
        a: &mut [f64],
    ) {
        const I_S1: usize = SumField::S1.index();
        const I_S2: usize = SumField::S2.index();
        const I_P: usize = SumField::P.index();
        let n = self.n;
        assert_eq!(populations.populations(), n, "one sum per population");
        let lattice = sums.lattice();
        let (lx, ly) = (lattice.lx, lattice.ly);
        let nodes = lx * ly;
        // Per column: `u_p = Σ_q (2κ_pq/λ) s2_q` and `a_p = Σ_q d_pq s2_q` over contiguous
        // slices, then `P += Σ_p X_p u_p − (2κ/λ) X s2`.
        let mut u = vec![0.0; n * ly];
        for x in 0..lx {
            u.fill(0.0);
            for p in 0..n {
                let a_p = &mut a[p * nodes + x * ly..p * nodes + (x + 1) * ly];
                a_p.fill(0.0);
                let u_p = &mut u[p * ly..(p + 1) * ly];
                for q in 0..n {
                    let (c, d) = (self.c[p * n + q], self.d[p * n + q]);
                    for ((u, a), &s) in u_p
                        .iter_mut()
                        .zip(a_p.iter_mut())
                        .zip(populations.squares(q, x))
                    {
                        *u += c * s;
                        *a += d * s;
                    }
                }
            }
            let ([s1, s2], p_col) = sums.columns_read_write([I_S1, I_S2], I_P, x);
            let total = match self.kind {
                PressureKind::Paper => s1,
                PressureKind::Interaction => s2,
            };
            for (y, p_node) in p_col.iter_mut().enumerate() {
                *p_node -= self.c_tissue * total[y] * s2[y];
            }
            for p in 0..n {
                let x_p = match self.kind {
                    PressureKind::Paper => populations.column(p, x),
                    PressureKind::Interaction => populations.squares(p, x),
                };
                for ((p_node, &xp), &u) in p_col.iter_mut().zip(x_p).zip(&u[p * ly..(p + 1) * ly]) {
                    *p_node += xp * u;
                }
            }
        }
    }

    fn add_coefficients(
        &self,
        p: usize,
        scratch: &[f64],
        k0: usize,
        a: &mut [f64],
        _b: &mut [f64],
    ) {
        let nodes = scratch.len() / self.n;
        for (a, &v) in a.iter_mut().zip(&scratch[p * nodes + k0..]) {
            *a += v;
        }
    }
}
