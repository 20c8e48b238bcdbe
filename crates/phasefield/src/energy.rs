//! The free energy `F = F_CH + F_area + F_rep` and its functional derivatives
//! (docs/model.md §2; the supplementary formulas of Mueller, Yeomans & Doostmohammadi, PRL 2019).
//!
//! The discrete free energy whose exact gradient these derivatives are:
//!
//! ```text
//! F_CH   = Σ_i Σ_x [ (4γ/λ) φ_i² (1−φ_i)² + γλ |∇⁺φ_i|² ]        (∇⁺: forward differences)
//! F_area = Σ_i μ (1 − A_i/(πR²))²,   A_i = Σ_x φ_i²
//! F_rep  = (κ/λ) Σ_x Σ_{i<k} φ_i² φ_k²
//! ```
//!
//! The gradient of `γλ Σ_x |∇⁺φ|²` with respect to `φ(x)` is `−2γλ ∇²φ(x)` with the five-point
//! Laplacian, so [`EnergyParams::ch`] is the exact derivative of the discrete `F_CH`.

use serde::{Deserialize, Serialize};

use crate::lattice::Lattice;
use crate::Cells;

/// The parameters of the free energy.
///
/// Build it from [`EnergyParams::paper`] (also the [`Default`]) and change the fields you
/// need; the struct is `#[non_exhaustive]`, so new knobs do not break callers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct EnergyParams {
    /// Interface stiffness γ (paper: 0.01). Larger values make cells rounder and raise the
    /// activity threshold linearly.
    pub gamma: f64,
    /// Area constraint μ (paper: 3).
    pub mu: f64,
    /// Interface width λ (paper: 2.5), in lattice units.
    pub lambda: f64,
    /// Repulsion κ between overlapping cells (paper: 0.1).
    pub kappa: f64,
    /// Target radius R (paper: 8); the target area is πR².
    pub radius: f64,
}

impl Default for EnergyParams {
    /// [`EnergyParams::paper`].
    fn default() -> Self {
        Self::paper()
    }
}

impl EnergyParams {
    /// The parameters of the paper (γ = 0.01, μ = 3, λ = 2.5, κ = 0.1, R = 8).
    pub fn paper() -> Self {
        Self {
            gamma: 0.01,
            mu: 3.0,
            lambda: 2.5,
            kappa: 0.1,
            radius: 8.0,
        }
    }

    /// Target area πR².
    #[inline]
    pub fn target_area(&self) -> f64 {
        std::f64::consts::PI * self.radius * self.radius
    }

    /// `δF_CH/δφ_i = (8γ/λ) φ(1−φ)(1−2φ) − 2γλ ∇²φ`, given `φ` and its five-point Laplacian.
    pub fn ch(&self, phi: f64, laplacian: f64) -> f64 {
        self.coefficients().ch(phi, laplacian)
    }

    /// `δF_area/δφ_i = −(4μ/(πR²)) φ (1 − A_i/(πR²))`, given `φ` and the cell's area `A_i`.
    pub fn area(&self, phi: f64, area: f64) -> f64 {
        let c = self.coefficients();
        c.area_factor(area) * phi
    }

    /// `δF_rep/δφ_i = (2κ/λ) φ Σ_{k≠i} φ_k²`, given `φ` and `Σ_{k≠i} φ_k²` at the node.
    pub fn rep(&self, phi: f64, others_sq: f64) -> f64 {
        self.coefficients().rep(phi, others_sq)
    }

    /// The constant factors of the three derivatives, computed once so that a kernel does no
    /// division per node.
    pub fn coefficients(&self) -> EnergyCoefficients {
        let a0 = self.target_area();
        EnergyCoefficients {
            double_well: 8.0 * self.gamma / self.lambda,
            gradient: 2.0 * self.gamma * self.lambda,
            area: 4.0 * self.mu / a0,
            inv_target_area: 1.0 / a0,
            repulsion: 2.0 * self.kappa / self.lambda,
        }
    }

    /// The discrete free energy of a state (see the module docs). Allocates two lattice-sized
    /// fields; meant for tests and diagnostics, not for the time step.
    pub fn free_energy<T: crate::Real>(&self, cells: &Cells<T>) -> f64 {
        let lattice: Lattice = cells.lattice();
        let mut s2 = vec![0.0; lattice.len()];
        let mut s4 = vec![0.0; lattice.len()];
        let mut field = vec![0.0; lattice.len()];
        let mut total = 0.0;
        for i in 0..cells.n_cells() {
            field.iter_mut().for_each(|v| *v = 0.0);
            cells.add_to_lattice(i, &mut field);
            let mut area = 0.0;
            for x in 0..lattice.lx {
                let xp = (x + 1) % lattice.lx;
                for y in 0..lattice.ly {
                    let yp = (y + 1) % lattice.ly;
                    let p = field[lattice.index(x, y)];
                    let gx = field[lattice.index(xp, y)] - p;
                    let gy = field[lattice.index(x, yp)] - p;
                    total += 4.0 * self.gamma / self.lambda * p * p * (1.0 - p) * (1.0 - p)
                        + self.gamma * self.lambda * (gx * gx + gy * gy);
                    area += p * p;
                    s2[lattice.index(x, y)] += p * p;
                    s4[lattice.index(x, y)] += p * p * p * p;
                }
            }
            total += self.mu * (1.0 - area / self.target_area()).powi(2);
        }
        // Σ_{i<k} φ_i² φ_k² = ((Σ φ²)² − Σ φ⁴) / 2
        let rep: f64 = s2.iter().zip(&s4).map(|(a, b)| a * a - b).sum();
        total + self.kappa / self.lambda * 0.5 * rep
    }
}

/// The constant factors of the free-energy derivatives ([`EnergyParams::coefficients`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyCoefficients {
    /// `8γ/λ`.
    pub double_well: f64,
    /// `2γλ`.
    pub gradient: f64,
    /// `4μ/(πR²)`.
    pub area: f64,
    /// `1/(πR²)`.
    pub inv_target_area: f64,
    /// `2κ/λ`.
    pub repulsion: f64,
}

impl EnergyCoefficients {
    /// `δF_CH/δφ_i` (see [`EnergyParams::ch`]).
    #[inline(always)]
    pub fn ch(&self, phi: f64, laplacian: f64) -> f64 {
        self.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi) - self.gradient * laplacian
    }

    /// The factor `−(4μ/(πR²))(1 − A_i/(πR²))` of cell i, so that
    /// `δF_area/δφ_i = area_factor(A_i) · φ`; constant over a cell's patch.
    #[inline(always)]
    pub fn area_factor(&self, area: f64) -> f64 {
        -self.area * (1.0 - area * self.inv_target_area)
    }

    /// `δF_rep/δφ_i` (see [`EnergyParams::rep`]).
    #[inline(always)]
    pub fn rep(&self, phi: f64, others_sq: f64) -> f64 {
        self.repulsion * phi * others_sq
    }

    /// The whole functional derivative of the free energy at one node (docs/model.md §2):
    ///
    /// ```text
    /// δF/δφ_i = (8γ/λ) φ(1−φ)(1−2φ) − 2γλ ∇²φ − (4μ/πR²)(1 − A_i/πR²) φ + (2κ/λ) φ Σ_{k≠i} φ_k²
    /// ```
    ///
    /// given `φ = φ_i(x)`, its five-point Laplacian, the cell's [`area_factor`](Self::area_factor)
    /// and `Σ_{k≠i} φ_k²` at the node. It is the exact gradient of the discrete
    /// [`EnergyParams::free_energy`] (tested against finite differences).
    #[inline(always)]
    pub fn free_energy_derivative(
        &self,
        phi: f64,
        laplacian: f64,
        area_factor: f64,
        others_sq: f64,
    ) -> f64 {
        self.ch(phi, laplacian) + area_factor * phi + self.rep(phi, others_sq)
    }
}
