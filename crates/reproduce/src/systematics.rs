//! Systematic errors of a critical value (issue 54, item 5): the same measurement at half the
//! time step and on a grid twice as fine, each difference added to the statistical error in
//! quadrature.
//!
//! **A grid twice as fine** is the same physics with every length doubled in nodes. The step
//! `∂_t φ_i + v_i·∇φ_i = −∂F/∂φ_i(x)` is invariant when each node's derivative keeps its value
//! and the velocity doubles in nodes per TU (the same physical speed). Term by term
//! (docs/model.md §2, §3, §11):
//!
//! | key | factor | why |
//! |---|---|---|
//! | `[domain] lx`, `ly`, `[cells] radius`, `[model] lambda`, `[integrator] margin` | 2 | lengths |
//! | `[model] gamma` | 2 | `(4γ/λ)φ²(1−φ)²` and `−2γλ∇²φ` (∇² is ¼ as large) keep their value |
//! | `[model] kappa` | 2 | `(κ/λ) φ_i φ_j²` |
//! | `[model] mu` | 4 | `−4μ/(πR²)(1 − A/πR²) φ`: the target area is 4× as large |
//! | `[adhesion] omega` | 2 | `ωλ∇φ_i·∇φ_j`, as the gradient term |
//! | `[model] xi`, `zeta`, `[polarity] rotational_diffusion` | 1 | the force `Σ_x P ∇φ_i` doubles (4× the nodes, ½ the gradient), as the velocity must; `Q_i = Σ_x ∇φ∇φ` is unchanged; an angle's noise has no length |
//! | `[polarity] alpha` | 2 (whole-cell), ½ (density) | the force doubles: `α p`, or `α A p` with A 4× |
//! | `[polarity] align_rate` | ½ (velocity, force), 1 (shape) | `J |f|` with `|v|`, `|F|` doubled, `|S|` unchanged |
//!
//! `dt` is kept: the stiffest rate, `2γλ·8` of the Laplacian's largest eigenvalue, grows 4×
//! (from 0.4 to 1.6 per TU at the paper's γ), still well inside Heun's limit at dt = 0.5.
//! Parts whose scaling is not written here (walls, populations, division, contact
//! inhibition, terms of a user's) are refused by name.

use scene::{AlignKind, PropulsionKind, SceneFile};
use study::SweepError;

use super::g;

/// The overrides that put the scene `text` (with the overrides `sets` applied) on a grid twice
/// as fine: every key whose value depends on the grid spacing, as `section.key=value`, to be
/// applied after `sets`.
///
/// # Errors
/// [`SweepError::Reproduce`] for a scene that does not parse, or that has a part whose
/// scaling is not written here (named).
pub(crate) fn finer_grid(text: &str, sets: &[String]) -> Result<Vec<String>, SweepError> {
    let f = SceneFile::parse(text, sets).map_err(|e| SweepError::Reproduce {
        why: format!("the scene of a grid twice as fine: {e}"),
    })?;
    let refuse = |what: &str| {
        Err(SweepError::Reproduce {
            why: format!("a grid twice as fine is not written for {what}: run the systematics without it, or add its scaling to crates/reproduce/src/systematics.rs"),
        })
    };
    if f.walls.is_some() {
        return refuse("[walls]");
    }
    if !f.population.is_empty() {
        return refuse("[[population]]");
    }
    if f.division.is_some() {
        return refuse("[division]");
    }
    if !f.user_terms.is_empty() {
        return refuse("[terms.*]");
    }
    if f.cells.positions.is_some() || f.cells.from.is_some() || f.cells.init_radius.is_some() {
        return refuse("[cells] positions, from or init_radius");
    }
    let m = &f.model;
    let mut out = vec![
        format!("domain.lx={}", 2 * f.domain.lx),
        format!("domain.ly={}", 2 * f.domain.ly),
        format!("cells.radius={}", 2.0 * f.cells.radius),
        format!("model.lambda={}", 2.0 * m.lambda),
        format!("model.gamma={}", 2.0 * m.gamma),
        format!("model.kappa={}", 2.0 * m.kappa),
        format!("model.mu={}", 4.0 * m.mu),
        format!("integrator.margin={}", 2 * f.integrator.margin),
    ];
    if let Some(a) = &f.adhesion {
        out.push(format!("adhesion.omega={}", 2.0 * a.omega));
    }
    if let Some(p) = &f.polarity {
        if p.contact_inhibition != 0.0 {
            return refuse("[polarity] contact_inhibition");
        }
        let alpha = match p.propulsion {
            PropulsionKind::Cell => 2.0 * p.alpha,
            PropulsionKind::Density => 0.5 * p.alpha,
        };
        out.push(format!("polarity.alpha={alpha}"));
        let rate = match p.align {
            AlignKind::Velocity | AlignKind::Force => 0.5 * p.align_rate,
            _ => p.align_rate,
        };
        out.push(format!("polarity.align_rate={rate}"));
    }
    Ok(out)
}

/// The model's parameters on a grid twice as fine, by the table above: the lengths (R, λ) and
/// γ, κ, ω doubled, μ four times, ξ and ζ kept. For the figures that build a tissue from
/// [`mechanics::ModelParams`] rather than a scene (`stability`, `bloch`); a box, its cells'
/// patches (the margin) and the rest state's relaxation double their lengths beside it.
pub(crate) fn finer_params(p: &mechanics::ModelParams) -> mechanics::ModelParams {
    let mut f = *p;
    let e = &mut f.energy;
    e.radius *= 2.0;
    e.lambda *= 2.0;
    e.gamma *= 2.0;
    e.kappa *= 2.0;
    e.mu *= 4.0;
    f.omega *= 2.0;
    f
}

/// The smallest relative shift of a critical value at half the time step or on a grid twice
/// as fine that counts (the rule of an absence): 20 %, below the 30–50 % by which the two
/// pressure forms' thresholds differ, so that a shift under it leaves the comparisons standing.
pub(crate) const SHIFT: f64 = 0.2;

/// The override that halves the time step of the scene `text` with `sets`.
///
/// # Errors
/// [`SweepError::Reproduce`] for a scene that does not parse.
pub(crate) fn half_dt(text: &str, sets: &[String]) -> Result<String, SweepError> {
    let f = SceneFile::parse(text, sets).map_err(|e| SweepError::Reproduce {
        why: format!("the scene at half the time step: {e}"),
    })?;
    Ok(format!("integrator.dt={}", f.integrator.dt / 2.0))
}

/// A critical value with its statistical error and its two systematic shifts: the value at
/// half the time step and on a grid twice as fine, less the value itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Systematics {
    /// The value and its statistical error.
    pub value: f64,
    pub stat: f64,
    /// `value(dt/2) − value`, `value(h/2) − value` (NaN when not measured).
    pub dt: f64,
    pub grid: f64,
}

impl Systematics {
    /// The total error: statistical and both shifts in quadrature. A shift that could not be
    /// measured (NaN) makes the total NaN: an error bar without it would claim more than was
    /// measured.
    pub fn total(&self) -> f64 {
        (self.stat.powi(2) + self.dt.powi(2) + self.grid.powi(2)).sqrt()
    }

    /// `value ± total (stat s, dt d, grid h)` in words.
    pub fn describe(&self) -> String {
        format!(
            "{} ± {} (statistical {}, dt/2 shift {}, grid/2 shift {}, in quadrature)",
            g(self.value),
            g(self.total()),
            g(self.stat),
            g(self.dt),
            g(self.grid)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PAPER_SCENE;

    #[test]
    fn the_finer_grid_doubles_lengths_and_keeps_the_dynamics() {
        let sets = finer_grid(PAPER_SCENE, &["model.gamma=0.006".into()]).unwrap();
        let f = SceneFile::parse(
            PAPER_SCENE,
            &[vec!["model.gamma=0.006".to_string()], sets].concat(),
        )
        .unwrap();
        assert_eq!((f.domain.lx, f.domain.ly), (200, 200));
        assert_eq!(f.cells.radius, 16.0);
        assert_eq!(f.model.lambda, 5.0);
        assert_eq!(f.model.gamma, 0.012);
        assert_eq!(f.model.kappa, 0.2);
        assert_eq!(f.model.mu, 12.0);
        assert_eq!(f.model.zeta, 0.0);
        let walls = finer_grid(PAPER_SCENE, &["walls.kind=\"channel\"".into()]);
        assert!(matches!(walls, Err(SweepError::Reproduce { why }) if why.contains("[walls]")));
        assert_eq!(
            half_dt(PAPER_SCENE, &["integrator.dt=0.5".into()]).unwrap(),
            "integrator.dt=0.25"
        );
    }

    /// The physics of the scaling, on the model itself: an isolated cell relaxes to 4× the
    /// area (within 1 %), and a polar cell (whole-cell propulsion, `v = α/ξ`) moves at twice
    /// the speed in nodes per TU, so that the same time in TU covers the same distance in cell
    /// radii.
    #[test]
    fn the_finer_grid_is_the_same_cell_twice_as_large() {
        use mechanics::terms::{Polarity, Terms};
        use mechanics::{ModelParams, StepParams, Tissue, Workspace};
        use phasefield::{init, EnergyParams, Lattice, PatchShape};
        let run = |k: usize| {
            let k_f = k as f64;
            let lattice = Lattice::new(48 * k, 48 * k);
            let shape = PatchShape::new(lattice, 14 * k).unwrap();
            let r = 8.0 * k_f;
            let cells = init::discs(lattice, shape, &[[24.0 * k_f, 24.0 * k_f]], r, 2.5 * k_f);
            let mut e = EnergyParams::paper();
            (e.radius, e.lambda, e.gamma, e.kappa, e.mu) =
                (r, 2.5 * k_f, 0.01 * k_f, 0.1 * k_f, 3.0 * k_f * k_f);
            let mut params = ModelParams::paper(0.0);
            params.energy = e;
            let pol = Polarity::new(0.02 * k_f).with_initial_angle(0.0);
            let mut t = Tissue::new(cells, params).with(Terms::new(1).with(pol));
            let mut ws = Workspace::new(t.cells());
            let p = StepParams::default();
            t.set_active(false);
            for _ in 0..(100.0 / p.dt) as usize {
                t.step(&mut ws, &p).unwrap();
            }
            t.set_active(true);
            let x0 = t.centres()[0][0];
            for _ in 0..(100.0 / p.dt) as usize {
                t.step(&mut ws, &p).unwrap();
            }
            t.refresh(&mut ws);
            (ws.cell(0).area, (t.centres()[0][0] - x0) / 100.0)
        };
        let ((a1, v1), (a2, v2)) = (run(1), run(2));
        eprintln!(
            "area {a1} → {a2} (×{}), speed {v1} → {v2} (×{})",
            a2 / a1,
            v2 / v1
        );
        assert!((a2 / a1 / 4.0 - 1.0).abs() < 0.01, "{a1} {a2}");
        // The free speed α/ξ in nodes per TU: 0.01, and 0.02 on the finer grid. The centre lags
        // it on both grids, by the coarse grid's discretisation error (1.5 % here), and less on
        // the finer one (0.4 %): the refinement converges towards the same physical speed.
        let (e1, e2) = ((v1 / 0.01 - 1.0).abs(), (v2 / 0.02 - 1.0).abs());
        assert!(e1 < 0.02 && e2 < e1, "{v1} {v2}");
    }

    /// The parameters' scaling is the scenes': the paper scene put on a grid twice as fine
    /// builds the parameters that [`finer_params`] makes of its own.
    #[test]
    fn finer_params_scale_as_finer_scenes() {
        let sets = vec!["model.gamma=0.006".to_string()];
        let fine = finer_grid(PAPER_SCENE, &sets).unwrap();
        let params = |s: &[String]| {
            scene::Scene::parse(PAPER_SCENE, s)
                .unwrap()
                .model_params(0.005)
        };
        let coarse = params(&sets);
        assert_eq!(finer_params(&coarse), params(&[sets, fine].concat()));
    }

    #[test]
    fn the_total_adds_the_shifts_in_quadrature() {
        let s = Systematics {
            value: 5.0e-3,
            stat: 0.3e-3,
            dt: -0.4e-3,
            grid: 1.2e-3,
        };
        assert!((s.total() - 1.3e-3).abs() < 1e-15);
        assert!(Systematics { dt: f64::NAN, ..s }.total().is_nan());
        assert!(s.describe().contains("grid/2 shift"));
    }
}
