//! Walls (docs/model.md §11.4) as a node term: a static wall field `w` whose energy
//! `Σ_i Σ_x [(κ_w/λ) φ_i² w² + 2ω_wλ ∇φ_i·∇w]` has the derivative
//! `(2κ_w/λ) w² φ_i − 2ω_wλ ∇²w` (`equations::wall_derivative`): `a = (2κ_w/λ) w²`,
//! `b = −2ω_wλ ∇²w`; its pressure (`equations::wall_pressure`) is a lattice pass after the
//! scatter.

use phasefield::WallField;

use super::{NodeTerm, PopulationSums};
use crate::equations::{wall_derivative, wall_pressure};
use crate::evaluation::{SumField, N_SUMS};
use crate::scatter::LatticeSums;

/// The walls of an evaluation: the field in effect and its coefficients
/// ([`crate::equations::wall_coefficients`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct WallTerm<'a> {
    pub field: &'a WallField,
    pub coefficients: [f64; 2],
}

impl NodeTerm for WallTerm<'_> {
    /// [`wall_pressure`] added node by node once the scatter has completed the sums.
    fn add_pressure(
        &self,
        sums: &mut LatticeSums<N_SUMS>,
        _populations: &PopulationSums,
        _scratch: &mut [f64],
    ) {
        const I_S1: usize = SumField::S1.index();
        const I_S2: usize = SumField::S2.index();
        const I_P: usize = SumField::P.index();
        let lattice = sums.lattice();
        let ly = lattice.ly;
        let (w, lap) = (self.field.w(), self.field.laplacian());
        for x in 0..lattice.lx {
            let ([s1, s2], p) = sums.columns_read_write([I_S1, I_S2], I_P, x);
            let range = x * ly..(x + 1) * ly;
            for (((p, &s2), &s1), (&w, &lap)) in p
                .iter_mut()
                .zip(s2)
                .zip(s1)
                .zip(w[range.clone()].iter().zip(&lap[range]))
            {
                *p += wall_pressure(self.coefficients, s1, s2, w, lap);
            }
        }
    }

    fn add_coefficients(
        &self,
        _population: usize,
        _scratch: &[f64],
        k0: usize,
        a: &mut [f64],
        b: &mut [f64],
    ) {
        let (w, lap_w) = (&self.field.w()[k0..], &self.field.laplacian()[k0..]);
        for (k, (a, b)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
            *a += wall_derivative(self.coefficients, 1.0, w[k], 0.0);
            *b += wall_derivative(self.coefficients, 0.0, w[k], lap_w[k]);
        }
    }
}
