//! # custom-term
//!
//! How a library user adds a physics term to monolayer from their own crate, with
//! `monolayer` as the only dependency: an *active Ornstein–Uhlenbeck force* (the AOUP model
//! of active matter), a whole-cell force `f_i` with per-cell state that relaxes to zero and is
//! kicked by noise,
//!
//! ```text
//! df_i = −f_i/τ dt + (√(2D)/τ) dW_i,      ξ v_i = F_i + f_i,
//! ```
//!
//! so that `⟨f_x²⟩ = D/τ` in the stationary state and `⟨f_x(t) f_x(0)⟩ = (D/τ) e^{−t/τ}`. The term implements [`CellTerm`]: its state variables, their initial
//! value, the force they exert, their rate and their noise. The driver integrates the state
//! with the fields' Heun step, keys the noise by (seed, cell, step), stores the state by cell
//! identity and writes it to frames and checkpoints as `aoup.fx`, `aoup.fy`.
//!
//! ```
//! use custom_term::Aoup;
//! use monolayer::prelude::*;
//!
//! let lattice = Lattice::new(48, 48);
//! let shape = PatchShape::new(lattice, 14).unwrap();
//! let cells = init::discs(lattice, shape, &[[24.0, 24.0]], 8.0, 2.5);
//! let terms = Terms::new(7).with(Aoup { tau: 50.0, d: 1e-4 });
//! let mut tissue = Tissue::new(cells, ModelParams::paper(0.0)).with_terms(terms);
//! let mut ws = Workspace::new(tissue.cells());
//! for _ in 0..100 {
//!     tissue.step(&mut ws, &StepParams::default()).unwrap();
//! }
//! let f = tissue.terms().state("aoup").unwrap();
//! assert!(f.iter().all(|v| v.is_finite()));
//! ```
#![deny(missing_docs)]

use monolayer::prelude::*;

/// An active Ornstein–Uhlenbeck force on every cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aoup {
    /// The persistence time τ of the force.
    pub tau: f64,
    /// Its diffusion constant D: the stationary variance of each component is `D/τ`.
    pub d: f64,
}

impl CellTerm for Aoup {
    fn name(&self) -> &str {
        "aoup"
    }

    fn state_names(&self) -> &[&'static str] {
        &["fx", "fy"]
    }

    /// Drawn from the stationary distribution, so that a run starts in steady state.
    fn initial_state(&self, _id: usize, keys: &dyn Fn(u64) -> NoiseKey, out: &mut [f64]) {
        let sd = (self.d / self.tau).sqrt();
        out[0] = sd * keys(0).normal();
        out[1] = sd * keys(1).normal();
    }

    fn force(&self, cell: &CellContext<'_>, x: &[f64]) -> [f64; 2] {
        if cell.active {
            [x[0], x[1]]
        } else {
            [0.0; 2]
        }
    }

    fn rate(&self, _cell: &CellContext<'_>, x: &[f64], out: &mut [f64]) {
        out[0] = -x[0] / self.tau;
        out[1] = -x[1] / self.tau;
    }

    fn noise(&self, _cell: &CellContext<'_>, out: &mut [f64]) {
        let b = (2.0 * self.d).sqrt() / self.tau;
        out.fill(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 30 cells whose patches do not overlap (so that they do not interact) on one lattice,
    /// 3000 TU (60 τ): the force's stationary variance is `D/τ` and its autocorrelation at
    /// lag τ is `e^{−1}`, each within 10 % (the statistical error of the variance from about
    /// 30 × 30 independent windows is 5 %; the Heun scheme's bias at dt/τ = 0.01 is 1e-4);
    /// and every cell's velocity is `(F_i + f_i)/ξ`, with `F_i = 0` for a cell alone.
    #[test]
    fn the_force_is_an_ornstein_uhlenbeck_process_that_moves_the_cell() {
        let term = Aoup { tau: 50.0, d: 1e-4 };
        let (dt, steps) = (0.5, 6000);
        let lag = (term.tau / dt) as usize;
        // Patches of side 25 on a grid of spacing 32.
        let lattice = Lattice::new(192, 160);
        let shape = PatchShape::new(lattice, 12).unwrap();
        let centres: Vec<[f64; 2]> = (0..30)
            .map(|k| [16.0 + 32.0 * (k % 6) as f64, 16.0 + 32.0 * (k / 6) as f64])
            .collect();
        let cells = init::discs(lattice, shape, &centres, 8.0, 2.5);
        let terms = Terms::new(1).with(term);
        let mut t = Tissue::new(cells, ModelParams::paper(0.0)).with_terms(terms);
        let mut ws = Workspace::new(t.cells());
        let mut fx = vec![Vec::with_capacity(steps); centres.len()];
        for _ in 0..steps {
            t.step(&mut ws, &StepParams::new(dt, 1)).unwrap();
            let state = t.terms().state("aoup").unwrap();
            for (id, f) in fx.iter_mut().enumerate() {
                f.push(state[2 * id]);
            }
        }
        let (mut var, mut cov, mut n, mut n_cov) = (0.0, 0.0, 0.0, 0.0);
        for f in &fx {
            for (k, a) in f.iter().enumerate() {
                var += a * a;
                n += 1.0;
                if k + lag < f.len() {
                    cov += a * f[k + lag];
                    n_cov += 1.0;
                }
            }
        }
        for c in ws.cell_states() {
            let v = (c.force + c.cell_force) / t.params().xi;
            assert!((c.velocity - v).norm() < 1e-15);
            assert!(
                c.force.norm() < 1e-12,
                "a cell alone feels no interface force"
            );
        }
        let (var, cov) = (var / n, cov / n_cov);
        let expected = term.d / term.tau;
        assert!(
            (var / expected - 1.0).abs() < 0.1,
            "variance {var:e} against D/τ = {expected:e}"
        );
        let r = cov / var;
        assert!(
            (r / (-1.0f64).exp() - 1.0).abs() < 0.1,
            "autocorrelation at τ: {r} against 1/e"
        );
    }
}
