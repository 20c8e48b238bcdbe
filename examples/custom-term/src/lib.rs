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
//! let mut tissue = Tissue::new(cells, ModelParams::paper(0.0)).with(terms);
//! let mut ws = Workspace::new(tissue.cells());
//! for _ in 0..100 {
//!     tissue.step(&mut ws, &StepParams::default()).unwrap();
//! }
//! let f = tissue.terms().state("aoup").unwrap();
//! assert!(f.iter().all(|v| v.is_finite()));
//! ```
//!
//! A program that registers it ([`register`]) can name it in a scene file, with its own table,
//! and run, stop and resume such a scene through a run directory like any other:
//!
//! ```toml
//! [terms.aoup]
//! tau = 50.0   # the persistence time τ
//! d = 1e-4     # the diffusion constant D
//! ```
#![deny(missing_docs)]

use std::sync::Arc;

use monolayer::prelude::*;
use monolayer::scene::TermError;

/// Registers the term under the name `aoup` for every scene this process reads: a table
/// `[terms.aoup]` with `tau` (positive) and `d` (zero or positive) switches it on.
pub fn register() {
    monolayer::scene::register_term("aoup", |table| {
        for key in table.keys() {
            if key != "tau" && key != "d" {
                return Err(TermError::new(
                    key.as_str(),
                    "is not a key of the aoup term",
                    "use tau and d",
                ));
            }
        }
        let tau = TermError::number(table, "aoup", "tau")?;
        let d = TermError::number(table, "aoup", "d")?;
        if tau <= 0.0 {
            return Err(TermError::new(
                "tau",
                format!("{tau} is not a positive persistence time"),
                "use a time longer than the step, e.g. tau = 50",
            ));
        }
        if d < 0.0 {
            return Err(TermError::new(
                "d",
                format!("{d} is negative"),
                "use d ≥ 0, e.g. d = 1e-4",
            ));
        }
        Ok(Arc::new(Aoup { tau, d }) as Arc<dyn CellTerm>)
    });
}

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
    use monolayer::rundir::{Interrupt, RunDir};

    /// The paper scene, small, with the term named in it.
    const SCENE: &str = "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 12\n\
        [terms.aoup]\ntau = 20.0\nd = 1e-4\n\
        [run]\nrelax_time = 10\ntime = 20\noutput_every = 5\nseed = 4\n";

    fn run(dir: &std::path::Path, set: &[String]) {
        let scene = Scene::parse(SCENE, set).unwrap();
        let run = RunDir::create(dir, scene, None, false, Interrupt::never()).unwrap();
        let (mut sim, _) = run.simulation::<f32>().unwrap();
        run.run(&mut sim).unwrap();
    }

    fn files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
        let mut v: Vec<_> = std::fs::read_dir(dir.join("frames"))
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                (p.display().to_string(), std::fs::read(&p).unwrap())
            })
            .collect();
        v.sort();
        v.push((
            "series".into(),
            std::fs::read(dir.join("series.csv")).unwrap(),
        ));
        v.into_iter()
            .map(|(n, b)| (n.rsplit('/').next().unwrap().to_string(), b))
            .collect()
    }

    /// A term of this crate, named in a scene file: its table reaches the builder, its state is
    /// in every frame (`aoup.fx`, `aoup.fy`) and in checkpoints, and a run stopped half way
    /// and resumed through `RunDir` ends byte-identical to an uninterrupted one. A bad key, a
    /// bad value and an unregistered name are refused with the table and the key.
    #[test]
    fn a_registered_term_runs_from_a_scene_and_resumes_bit_for_bit() {
        register();
        let tmp = tempfile::tempdir().unwrap();
        let (full, half) = (tmp.path().join("full"), tmp.path().join("half"));
        run(&full, &[]);
        run(&half, &["run.time=10".into()]);
        let resumed = RunDir::resume(&half, &["run.time=20".into()], Interrupt::never()).unwrap();
        let (mut sim, _) = resumed.simulation::<f32>().unwrap();
        resumed.run(&mut sim).unwrap();
        let (want, got) = (files(&full), files(&half));
        assert_eq!(want.len(), got.len());
        for (w, g) in want.iter().zip(&got) {
            assert!(w == g, "{} differs after the resume", w.0);
        }
        let last = full.join("frames").join(&want[want.len() - 2].0);
        let fx = monolayer::rundir::read_npz(&last, &["aoup.fx"]).unwrap();
        assert_eq!(fx[0].data.len(), 12);
        assert!(fx[0].data.iter().any(|&v| v != 0.0));
        for (set, says) in [
            (
                "terms.aoup.tau=-1",
                "[terms.aoup] tau: -1 is not a positive",
            ),
            ("terms.aoup.speed=1", "[terms.aoup] speed: is not a key"),
            (
                "terms.aoup.d=\"x\"",
                "[terms.aoup] d: \"x\" is not a finite number",
            ),
        ] {
            let e = Scene::parse(SCENE, &[set.into()]).unwrap_err().to_string();
            assert!(e.starts_with(says), "{set}: {e}");
        }
        let e = Scene::parse(&SCENE.replace("aoup]", "oua]"), &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("[terms.oua]: no term named \"oua\" is registered") && e.contains("aoup"),
            "{e}"
        );
    }

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
        let mut t = Tissue::new(cells, ModelParams::paper(0.0)).with(terms);
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
