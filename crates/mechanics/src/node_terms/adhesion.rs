//! Adhesion between cells (docs/model.md §11.2) as a node term: the energy
//! `ωλ Σ_{i≠j} ∫∇φ_i·∇φ_j` has the derivative `−c Σ_{j≠i} ∇²φ_j = −c ∇²s1 + c ∇²φ_i`
//! (`equations::adhesion_derivative`, `c = 2ωλ`): `b = −c ∇²s1` and the Laplacian coefficient
//! `c`; its pressure is `c φ_i ∇²φ_i` per cell in the scatter and `−c s1 ∇²s1` on the lattice.

use super::{laplacian_into, NodeTerm, PopulationSums};
use crate::equations::{adhesion_derivative, adhesion_pressure};
use crate::evaluation::{SumField, N_SUMS};
use crate::scatter::LatticeSums;

/// Adhesion of coefficient `c` ([`crate::equations::adhesion_coefficient`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Adhesion {
    pub c: f64,
}

impl NodeTerm for Adhesion {
    fn cell_pressure_coefficient(&self, _population: usize) -> f64 {
        self.c
    }

    fn laplacian_coefficient(&self, _population: usize) -> f64 {
        self.c
    }

    fn scratch_fields(&self) -> usize {
        1
    }

    /// The lattice Laplacian of `s1` into `scratch` (index `x * ly + y`), and the cross term
    /// `−c s1 ∇²s1` ([`adhesion_pressure`]) added to the pressure.
    fn add_pressure(
        &self,
        sums: &mut LatticeSums<N_SUMS>,
        _populations: &PopulationSums,
        lap_s1: &mut [f64],
    ) {
        const I_S1: usize = SumField::S1.index();
        const I_P: usize = SumField::P.index();
        let lattice = sums.lattice();
        {
            let sums: &LatticeSums<N_SUMS> = sums;
            laplacian_into(lattice, |x| sums.column(I_S1, x), lap_s1);
        }
        let ly = lattice.ly;
        for x in 0..lattice.lx {
            let ([s1], p) = sums.columns_read_write([I_S1], I_P, x);
            for ((p, &s1), &lap) in p.iter_mut().zip(s1).zip(&lap_s1[x * ly..(x + 1) * ly]) {
                *p += adhesion_pressure(self.c, s1, lap);
            }
        }
    }

    fn add_coefficients(
        &self,
        _population: usize,
        lap_s1: &[f64],
        k0: usize,
        _a: &mut [f64],
        b: &mut [f64],
    ) {
        for (b, &lap) in b.iter_mut().zip(&lap_s1[k0..]) {
            *b += adhesion_derivative(self.c, lap, 0.0);
        }
    }
}
