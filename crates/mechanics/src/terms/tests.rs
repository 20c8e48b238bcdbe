//! Tests of the terms on isolated cells, where the model gives the answer: an isolated cell
//! feels no interface force (docs/model.md §3), so it moves at `v = Σ f_i / ξ`.

use nalgebra::Vector2;
use phasefield::{init, Lattice, PatchShape};
use rayon::prelude::*;

use super::*;
use crate::{ModelParams, StepParams, Tissue, Workspace};

/// One paper cell (R = 8, interface width `lambda`) on an `l × l` lattice with margin
/// `margin`, relaxed at rest (activity off) for 100 TU, with the terms `terms`.
fn relaxed(l: usize, margin: usize, lambda: f64, terms: Terms) -> (Tissue, Workspace) {
    let lattice = Lattice::new(l, l);
    let shape = PatchShape::new(lattice, margin).expect("the margin fits the lattice");
    let half = l as f64 / 2.0;
    let cells = init::discs(lattice, shape, &[[half, half]], 8.0, lambda);
    let mut p = ModelParams::paper(0.0);
    p.energy.lambda = lambda;
    let mut t = Tissue::new(cells, p).with(terms);
    let mut ws = Workspace::new(t.cells());
    t.set_active(false);
    for _ in 0..200 {
        t.step(&mut ws, &StepParams::default()).expect("stable");
    }
    t.set_active(true);
    (t, ws)
}

/// One paper cell on a 48² lattice with margin 14, relaxed at rest for 100 TU.
fn relaxed_cell(terms: Terms) -> (Tissue, Workspace) {
    relaxed(48, 14, 2.5, terms)
}

/// The displacement of a periodic centre from `a` to `b`, the shortest way round.
fn displacement(a: [f64; 2], b: [f64; 2], l: f64) -> Vector2<f64> {
    let d = |u: f64, v: f64| (v - u) - l * ((v - u) / l).round();
    Vector2::new(d(a[0], b[0]), d(a[1], b[1]))
}

/// One paper cell (R = 8, interface width `lambda`) on 64² with margin 16, relaxed at rest
/// for 100 TU, with a polarity `alpha` along x.
fn polar_cell(lambda: f64, alpha: f64) -> (Tissue, Workspace) {
    let pol = Polarity::new(alpha).with_initial_angle(0.0);
    relaxed(64, 16, lambda, Terms::new(1).with(pol))
}

/// T1.1 of the extensions: an isolated polar cell moves along its polarity at α/ξ.
///
/// Its velocity `v_i = α p_i/ξ` is exact (the interface force of an isolated cell is zero),
/// but its centre moves slower, by the dispersion of the central differences that advect
/// the interface: measured 1.83 % slower at the paper's interface width λ = 2.5 and 0.60 %
/// at λ = 5, over 100 TU after 50 TU of motion (1.82 % at dt 0.1 against 1.83 % at 0.5, so it
/// is the space discretisation; 0.8 % at λ = 4). The error falls by 3.1 for a doubling of λ
/// (second order would be 4; at λ = 5 the interface is no longer thin against R = 8).
/// Asserted: below 1 % at λ = 5 (the spec's bound), below 2.5 % at λ = 2.5, and a fall by
/// more than 2.5 for the doubling.
#[test]
fn an_isolated_polar_cell_moves_at_alpha_over_xi() {
    let mut err = Vec::new();
    for lambda in [2.5, 5.0] {
        let (mut t, mut ws) = polar_cell(lambda, 0.04);
        for _ in 0..100 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        let start = t.centres()[0];
        for _ in 0..200 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        let v = displacement(start, t.centres()[0], 64.0) / 100.0;
        assert!(v.y.abs() < 1e-9, "the cell moves along its polarity: {v:?}");
        err.push(1.0 - v.x / 0.02);
        // The velocity itself is α/ξ and the interface force zero.
        let c = &ws.cell_states()[0];
        assert!((c.velocity.x - 0.02).abs() < 1e-9 && c.force.norm() < 1e-9);
        assert!((c.cell_force.x - 0.04).abs() < 1e-15);
    }
    let (coarse, fine) = (err[0], err[1]);
    eprintln!("speed error: λ = 2.5 {coarse:e}, λ = 5 {fine:e}");
    assert!(fine.abs() < 0.01, "λ = 5: {fine:e} off α/ξ");
    assert!(coarse.abs() < 0.025, "λ = 2.5: {coarse:e} off α/ξ");
    assert!(
        coarse / fine > 2.5,
        "not second order: {coarse:e} then {fine:e}"
    );
}

/// Four cells on 48² (margin 10) at ζ = 0.01, for comparisons to the bit.
fn four_cells() -> Tissue {
    let lattice = Lattice::new(48, 48);
    let shape = PatchShape::new(lattice, 10).unwrap();
    let centres = [[12.0, 12.0], [25.0, 14.0], [18.0, 30.0], [34.0, 34.0]];
    let cells = init::discs(lattice, shape, &centres, 7.0, 2.5);
    Tissue::new(cells, ModelParams::paper(0.01))
}

/// A polarity that pushes with α = 0 and does not turn changes nothing: the step with it is
/// the step without terms, to the bit (the term path adds an exact zero).
#[test]
fn a_term_that_adds_nothing_changes_nothing_to_the_bit() {
    let run = |terms: Option<Terms>| {
        let mut t = four_cells();
        if let Some(terms) = terms {
            t = t.with(terms);
        }
        let mut ws = Workspace::new(t.cells());
        for _ in 0..30 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        t.cells().phi().to_vec()
    };
    let plain = run(None);
    let zero = run(Some(Terms::new(3).with(Polarity::new(0.0))));
    assert!(plain
        .iter()
        .zip(&zero)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
}

/// A user's term: a constant force on every cell (gravity on a tilted substrate).
#[derive(Debug)]
struct Tilt([f64; 2]);

impl CellTerm for Tilt {
    fn name(&self) -> &str {
        "tilt"
    }
    fn force(&self, _: &CellContext<'_>, _: &[f64]) -> [f64; 2] {
        self.0
    }
}

/// Alignment to the velocity relaxes at the predicted rate. A cell pushed by a constant force
/// `G x̂` besides its propulsion `α p` moves along `αp + G`; to first order in the angle δ of
/// p from x̂, the velocity's angle is `αδ/(α+G)`, so `dδ/dt = −J |v| Δ(v, p) = −J (G/ξ) δ`.
/// The measured decay rate of `ln δ` between δ = 0.1 and 0.02 is within 2 % of `J G/ξ`
/// (measured 0.04 % off; the first-order expansion's error at δ = 0.1 is 0.5 %).
#[test]
fn alignment_to_the_velocity_relaxes_at_the_predicted_rate() {
    let (alpha, g, j, xi) = (0.04, 0.02, 2.0, 2.0);
    let pol = Polarity::new(alpha)
        .with_alignment(Align::Velocity, j)
        .with_initial_angle(0.1);
    let (mut t, mut ws) = relaxed_cell(Terms::new(1).with(pol).with(Tilt([g, 0.0])));
    let theta = |t: &Tissue| t.terms().state("polarity").unwrap()[0];
    assert_eq!(theta(&t), 0.1, "the relaxation does not turn the polarity");
    let mut samples = Vec::new();
    while theta(&t) > 0.02 {
        t.step(&mut ws, &StepParams::default()).expect("stable");
        samples.push((t.time(), theta(&t).ln()));
    }
    // The least-squares slope of ln δ against t.
    let n = samples.len() as f64;
    let (mt, ml) = samples
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, l)| (a + t / n, b + l / n));
    let (sxy, sxx) = samples.iter().fold((0.0, 0.0), |(a, b), (t, l)| {
        (a + (t - mt) * (l - ml), b + (t - mt) * (t - mt))
    });
    let rate = -sxy / sxx;
    let expected = j * g / xi;
    eprintln!("alignment rate {rate} against {expected}");
    assert!(
        (rate / expected - 1.0).abs() < 0.02,
        "rate {rate} against J G/ξ = {expected}"
    );
}

/// T1.2 of the extensions: a polar cell with rotational diffusion is a persistent random
/// walk, `⟨p(t)·p(0)⟩ = e^{−D_r t}` and `MSD(t) = 2 v₀² τ [t − τ(1 − e^{−t/τ})]` with
/// `τ = 1/D_r`, `v₀ = α/ξ`. 64 seeds, each 2000 TU (20 τ), averaged over time origins every
/// 10 TU; at every lag up to 2τ the measured MSD and correlation are within 10 % of the
/// formulas. Measured: the MSD 3.3–3.8 % low at every lag (the centre moves 1.8 % slower
/// than α/ξ, see the test above, and the MSD goes as v₀²), the correlation within 4 % (at
/// 2τ, 0.141 against 0.135: `e^{−2}` from about 640 independent windows).
#[test]
fn rotational_diffusion_gives_a_persistent_random_walk() {
    let (alpha, xi, d_r) = (0.04, 2.0, 0.01);
    let (tau, v0) = (1.0 / d_r, alpha / xi);
    let (seeds, dt, every, t_end) = (64u64, 0.5, 20usize, 2000.0);
    let samples = (t_end / dt) as usize / every;
    let runs: Vec<Vec<([f64; 2], f64)>> = (0..seeds)
        .into_par_iter()
        .map(|seed| {
            let pol = Polarity::new(alpha).with_rotational_diffusion(d_r);
            let (mut t, mut ws) = relaxed_cell(Terms::new(seed).with(pol));
            // The centres unwrapped, so that a walk across the boundary is not folded.
            let mut pos = [0.0; 2];
            let mut last = t.centres()[0];
            let mut out = vec![(pos, t.terms().state("polarity").unwrap()[0])];
            for _ in 0..samples {
                for _ in 0..every {
                    t.step(&mut ws, &StepParams::new(dt, 1)).expect("stable");
                }
                let c = t.centres()[0];
                let d = displacement(last, c, 48.0);
                last = c;
                pos = [pos[0] + d.x, pos[1] + d.y];
                out.push((pos, t.terms().state("polarity").unwrap()[0]));
            }
            out
        })
        .collect();
    for lag_tau in [0.25, 0.5, 1.0, 2.0] {
        let lag = (lag_tau * tau / (dt * every as f64)).round() as usize;
        let t = lag as f64 * dt * every as f64;
        let (mut msd, mut corr, mut count) = (0.0, 0.0, 0.0);
        for run in &runs {
            for w in 0..run.len() - lag {
                let ((a, ta), (b, tb)) = (run[w], run[w + lag]);
                msd += (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2);
                corr += (tb - ta).cos();
                count += 1.0;
            }
        }
        let (msd, corr) = (msd / count, corr / count);
        let msd_expected = 2.0 * v0 * v0 * tau * (t - tau * (1.0 - (-t / tau).exp()));
        let corr_expected = (-t / tau).exp();
        eprintln!("t {t}: MSD {msd} / {msd_expected}, corr {corr} / {corr_expected}");
        assert!(
            (msd / msd_expected - 1.0).abs() < 0.1,
            "MSD at t = {t}: {msd} against {msd_expected}"
        );
        assert!(
            (corr / corr_expected - 1.0).abs() < 0.1,
            "⟨p(t)·p(0)⟩ at t = {t}: {corr} against {corr_expected}"
        );
    }
}

/// The noise is keyed by cell identity and step, so a run with terms is bit-identical for
/// any thread count, and re-sorting the cells (which moves them between slots) does not
/// change a cell's noise.
#[test]
fn terms_are_independent_of_threads_and_slots() {
    let run = |threads: usize, sort: bool| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let lattice = Lattice::new(64, 64);
            let shape = PatchShape::new(lattice, 10).unwrap();
            let centres = [[40.0, 40.0], [12.0, 12.0], [40.0, 12.0], [12.0, 40.0]];
            let cells = init::discs(lattice, shape, &centres, 7.0, 2.5);
            let pol = Polarity::new(0.05)
                .with_rotational_diffusion(0.05)
                .with_alignment(Align::Force, 1.0);
            let mut t =
                Tissue::new(cells, ModelParams::paper(0.005)).with(Terms::new(11).with(pol));
            let mut ws = Workspace::new(t.cells());
            let mut scratch = Vec::new();
            for _ in 0..40 {
                if sort {
                    t.sort_cells(&mut scratch);
                }
                t.step(&mut ws, &StepParams::default()).unwrap();
            }
            let slots = t.slots();
            let centres: Vec<[f64; 2]> = slots.iter().map(|&s| t.centres()[s]).collect();
            (t.terms().state("polarity").unwrap().to_vec(), centres)
        })
    };
    let reference = run(1, false);
    assert_eq!(run(2, false), reference);
    let sorted = run(1, true);
    // Sorting changes the order of lattice sums (round-off), never which noise a cell gets.
    for (a, b) in sorted.0.iter().zip(&reference.0) {
        assert!((a - b).abs() < 1e-9, "{a} {b}");
    }
}

/// What a term sees of a cell before an evaluation (`CellContext::state`: what the last
/// evaluation of a step computed for it, kept by identity) is the same whether the run is
/// observed between steps and whether its slots are re-sorted. Contact inhibition and a
/// density propulsion read it: observed after every step, the run gives the same angles and
/// centres to the bit; re-sorted half way, to the round-off of the reordered lattice sums (as
/// in `terms_are_independent_of_threads_and_slots`). Before, the next step's forces read the
/// observation's evaluation, and after a re-sort another cell's force and area by slot.
#[test]
fn what_a_term_sees_does_not_depend_on_observation_or_slot_order() {
    let run = |observe: bool, sort: bool| {
        let lattice = Lattice::new(64, 64);
        let shape = PatchShape::new(lattice, 10).unwrap();
        // Not in the order of the re-sort, so that it moves cells between slots.
        let centres = [
            [40.0, 40.0],
            [12.0, 12.0],
            [40.0, 12.0],
            [12.0, 40.0],
            [26.0, 27.0],
        ];
        let cells = init::discs(lattice, shape, &centres, 7.0, 2.5);
        let pol = Polarity::new(0.002)
            .with_propulsion(Propulsion::Density)
            .with_rotational_diffusion(0.05)
            .with_contact_inhibition(2.0);
        let mut t = Tissue::new(cells, ModelParams::paper(0.005)).with(Terms::new(11).with(pol));
        let mut ws = Workspace::new(t.cells());
        let mut scratch = Vec::new();
        let mut moved = false;
        for k in 0..40 {
            if sort && k == 20 {
                let before = t.cell_ids().to_vec();
                t.sort_cells(&mut scratch);
                moved = t.cell_ids() != before.as_slice();
            }
            t.step(&mut ws, &StepParams::default()).unwrap();
            if observe {
                t.observe(&mut ws);
            }
        }
        assert_eq!(moved, sort, "the re-sort moved cells");
        let slots = t.slots();
        let centres: Vec<[f64; 2]> = slots.iter().map(|&s| t.centres()[s]).collect();
        (t.terms().state("polarity").unwrap().to_vec(), centres)
    };
    let reference = run(false, false);
    assert_eq!(run(true, false), reference, "observed after every step");
    let sorted = run(false, true);
    for (a, b) in sorted.0.iter().zip(&reference.0) {
        assert!((a - b).abs() < 1e-9, "re-sorted: {a} {b}");
    }
    for (a, b) in sorted.1.iter().zip(&reference.1) {
        assert!(
            (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-9,
            "re-sorted: {a:?} {b:?}"
        );
    }
}

/// The discrete adhesion energy `F_adh = ωλ Σ_{i≠j} Σ_x ∇⁺φ_i·∇⁺φ_j` (forward differences, on
/// the periodic lattice) of full-domain fields `phi` (cell after cell).
fn adhesion_energy(omega: f64, lambda: f64, phi: &[f64], lx: usize, ly: usize) -> f64 {
    let n = phi.len() / (lx * ly);
    let grad = |i: usize, x: usize, y: usize| {
        let f = |x: usize, y: usize| phi[i * lx * ly + x * ly + y];
        [f((x + 1) % lx, y) - f(x, y), f(x, (y + 1) % ly) - f(x, y)]
    };
    let mut e = 0.0;
    for i in 0..n {
        for j in 0..n {
            if i == j {
                continue;
            }
            for x in 0..lx {
                for y in 0..ly {
                    let (a, b) = (grad(i, x, y), grad(j, x, y));
                    e += a[0] * b[0] + a[1] * b[1];
                }
            }
        }
    }
    omega * lambda * e
}

/// T2.1 of the extensions: the adhesion's part of `δF/δφ_i` in the step is the derivative of
/// the discrete energy [`adhesion_energy`] (whose adjoint gradient is the five-point
/// Laplacian), by central finite differences on three random 20 × 20 fields stored on the
/// full domain. The energy is quadratic, so the difference quotient is exact but for
/// round-off: agreement to 1e-10 of the largest derivative. The step's part is read as the
/// change of the right-hand side when ω is switched on, at a friction so large (1e200) that
/// advection is nil. The pressure gains `Σ_i φ_i δF_adh/δφ_i`, to round-off.
#[test]
fn adhesion_is_the_derivative_of_its_discrete_energy() {
    let (lx, ly) = (20, 20);
    let lattice = Lattice::new(lx, ly);
    let shape = PatchShape::new(lattice, 0).unwrap();
    let mut cells =
        phasefield::Cells::zeros(lattice, shape, &[[5.0, 5.0], [12.0, 9.0], [8.0, 15.0]]);
    let mut state = 12345u64;
    for v in cells.phi_mut() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        *v = (state >> 11) as f64 / (1u64 << 53) as f64;
    }
    let (omega, lambda) = (0.01, 2.5);
    let evaluate = |omega: f64| {
        let params = ModelParams::paper(0.0).with_xi(1e200).with_adhesion(omega);
        let t = Tissue::new(cells.clone(), params);
        let mut ws = Workspace::new(t.cells());
        t.refresh(&mut ws);
        (ws.k2.clone(), ws.sum_field(crate::SumField::P))
    };
    let ((r0, p0), (r1, p1)) = (evaluate(0.0), evaluate(omega));
    let phi = cells.phi().to_vec();
    let n = 3;
    let mut worst: f64 = 0.0;
    let mut largest: f64 = 0.0;
    for i in 0..n {
        for node in [0, 37, 150, 211, 399] {
            let k = i * lx * ly + node;
            let h = 1e-3;
            let (mut up, mut down) = (phi.clone(), phi.clone());
            up[k] += h;
            down[k] -= h;
            let fd = (adhesion_energy(omega, lambda, &up, lx, ly)
                - adhesion_energy(omega, lambda, &down, lx, ly))
                / (2.0 * h);
            let step = -(r1[k] - r0[k]);
            worst = worst.max((fd - step).abs());
            largest = largest.max(fd.abs());
        }
    }
    assert!(largest > 1e-3, "the test fields have adhesion: {largest}");
    assert!(worst < 1e-10 * largest, "{worst:e} off, of {largest:e}");
    // P gains Σ_i φ_i δF_adh/δφ_i.
    for node in 0..lx * ly {
        let expected: f64 = (0..n)
            .map(|i| phi[i * lx * ly + node] * -(r1[i * lx * ly + node] - r0[i * lx * ly + node]))
            .sum();
        let got = p1[node] - p0[node];
        assert!(
            (got - expected).abs() < 1e-12,
            "P at {node}: {got} against {expected}"
        );
    }
}

/// T2.2 of the extensions: a doublet (R = 8, centres 15 apart, γ = 0.02, μ = 5, λ = 3,
/// κ = 0.1, ξ = 1, no activity) relaxed for 400 TU: its contact, the overlap `Σ φ₁φ₂` and
/// the length of the contact line (the extent across the line of the nodes where both
/// fields exceed 0.25), grows with ω ∈ {0, 0.005, 0.01, 0.015}. (The extensions' ω = 0.02 is
/// ω = γ, where the gradient energy `λ(γ ± ω)` of the difference of the two fields vanishes and
/// the contact breaks into stripes at the lattice scale; scenes refuse ω ≥ γ.) An isolated
/// cell with adhesion feels no force.
/// Two cells of `scenes/doublet.toml` (R = 8, centres 15 apart on 64 × 48, γ = 0.02, μ = 5,
/// λ = 3, κ = 0.1, ξ = 1) with the uniform adhesion `omega`.
fn doublet(omega: f64) -> Tissue {
    let lattice = Lattice::new(64, 48);
    let shape = PatchShape::new(lattice, 16).unwrap();
    let cells = init::discs(lattice, shape, &[[24.5, 24.0], [39.5, 24.0]], 8.0, 3.0);
    let mut energy = phasefield::EnergyParams::paper();
    (energy.gamma, energy.mu, energy.lambda, energy.kappa) = (0.02, 5.0, 3.0, 0.1);
    let params = ModelParams::paper(0.0)
        .with_energy(energy)
        .with_xi(1.0)
        .with_adhesion(omega);
    Tissue::new(cells, params)
}

#[test]
fn a_doublet_adheres_more_with_omega() {
    let measure = |omega: f64| {
        let mut t = doublet(omega);
        let mut ws = Workspace::new(t.cells());
        for _ in 0..2000 {
            t.step(&mut ws, &StepParams::new(0.2, 1)).expect("stable");
        }
        let c = t.cells();
        let (mut overlap, mut rows) = (0.0, std::collections::BTreeSet::new());
        for x in 0..64 {
            for y in 0..48 {
                let (a, b) = (c.value_at(0, x, y), c.value_at(1, x, y));
                overlap += a * b;
                if a > 0.25 && b > 0.25 {
                    rows.insert(y);
                }
            }
        }
        (overlap, rows.len())
    };
    let results: Vec<(f64, usize)> = [0.0, 0.005, 0.01, 0.015]
        .iter()
        .map(|&w| measure(w))
        .collect();
    eprintln!("doublet (overlap, contact length) against omega: {results:?}");
    for w in results.windows(2) {
        assert!(w[1].0 > w[0].0, "the overlap does not grow: {results:?}");
        assert!(w[1].1 >= w[0].1, "the contact shrinks: {results:?}");
    }
    assert!(
        results[3].1 > results[0].1,
        "no longer contact: {results:?}"
    );
    // A cell alone: no adhesion force.
    let lattice = Lattice::new(48, 48);
    let shape = PatchShape::new(lattice, 14).unwrap();
    let cells = init::discs(lattice, shape, &[[24.0, 24.0]], 8.0, 2.5);
    let t = Tissue::new(cells, ModelParams::paper(0.0).with_adhesion(0.02));
    let mut ws = Workspace::new(t.cells());
    t.refresh(&mut ws);
    assert!(ws.cell(0).force.norm() < 1e-12, "{:?}", ws.cell(0).force);
}

/// What a doublet's populations are given (a pair matrix).
type Give<'a> = &'a dyn Fn(Populations) -> Populations;

/// The doublet of `a_doublet_adheres_more_with_omega` at adhesion `omega`, its two cells in
/// the populations `pairs` (their assignment, and what to give the populations: a matrix),
/// after 2000 steps of 0.2: its fields and `Σ_x (φ₀φ₁)^power` over the box.
fn stepped_doublet(omega: f64, pairs: Option<(&[u16], Give<'_>)>, power: i32) -> (Vec<f64>, f64) {
    let mut t = doublet(omega);
    if let Some((of_cell, give)) = pairs {
        let pops = Populations::from_assignment(vec![Population::new(); 2], of_cell.to_vec());
        t = t.with(give(pops));
    }
    let mut ws = Workspace::new(t.cells());
    for _ in 0..2000 {
        t.step(&mut ws, &StepParams::new(0.2, 1)).expect("stable");
    }
    let c = t.cells();
    let overlap: f64 = (0..64)
        .flat_map(|x| (0..48).map(move |y| (x, y)))
        .map(|(x, y)| (c.value_at(0, x, y) * c.value_at(1, x, y)).powi(power))
        .sum();
    (c.phi().to_vec(), overlap)
}

/// The largest difference of two fields.
fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Adhesion by pair of populations (issue 49, `Populations::with_adhesion`), through the step,
/// on the doublet of `a_doublet_adheres_more_with_omega` (2000 steps of 0.2):
/// - every pair the same steps as the uniform ω (to 1e-9 of φ: the sums are grouped by
///   population, so only round-off differs), and so does a like doublet under a diagonal
///   matrix;
/// - an unlike doublet with ω_ab = 0 (ω_aa = ω_bb = 0.015) keeps about the contact of the
///   doublet without adhesion: its overlap `Σ φ₀φ₁` moves by less than 10 % of what ω = 0.015
///   adds (measured: −7.6 %), where the like doublet gets all of it (the unlike value is free of
///   the like ones). Not to round-off: adhesion's part of a cell's own field,
///   `c(∇²φ_i − ∇²s1_p)`, cancels only up to the patch's truncation, for the uniform term too.
///   The patch (side 2m + 1 = 33) wraps its own rows where the lattice does not, and the tail
///   of this cell (R = 8, λ = 3) is 5e-3 at its edge: a lone cell's φ moves by 1.2e-4 in one
///   step of 0.2 at ω = 0.015, and by 1e-17 on a patch as large as the lattice.
#[test]
fn pair_adhesion_steps_as_the_adhesion_of_each_pair() {
    let doublet = |omega: f64, pairs: Option<(&[u16], Vec<f64>)>| match pairs {
        Some((of_cell, m)) => stepped_doublet(
            omega,
            Some((of_cell, &move |p: Populations| p.with_adhesion(m.clone()))),
            1,
        ),
        None => stepped_doublet(omega, None, 1),
    };
    let close = largest_difference;
    let w = 0.015;
    let (uniform, o_uniform) = doublet(w, None);
    let (_, o_none) = doublet(0.0, None);
    let added = o_uniform - o_none;
    assert!(
        added > 1.0,
        "adhesion adds to the overlap: {o_none} → {o_uniform}"
    );
    let (same, _) = doublet(0.0, Some((&[0, 1], vec![w; 4])));
    assert!(close(&same, &uniform) < 1e-9, "{}", close(&same, &uniform));
    let diagonal = vec![w, 0.0, 0.0, w];
    let (like, _) = doublet(0.0, Some((&[0, 0], diagonal.clone())));
    assert!(close(&like, &uniform) < 1e-9, "{}", close(&like, &uniform));
    let (_, o_unlike) = doublet(0.0, Some((&[0, 1], diagonal)));
    eprintln!("overlap: none {o_none}, uniform {o_uniform}, unlike with ω_ab = 0 {o_unlike}");
    assert!(
        (o_unlike - o_none).abs() < 0.1 * added,
        "{o_none} {o_unlike} {o_uniform}"
    );
}

/// Repulsion by pair of populations (issue 49, `Populations::with_repulsion`), through the
/// step, on the doublet of `a_doublet_adheres_more_with_omega` without adhesion (2000 steps of
/// 0.2):
/// - a matrix of the tissue's κ (0.1) everywhere steps as the tissue does, to 1e-9 of φ (only
///   round-off differs: the sums are grouped by population);
/// - under `κ_aa = κ_bb = 0.1`, `κ_ab = 0.8`, a like doublet (both cells in a) is the tissue's
///   to 1e-9, and an unlike one overlaps less: its `Σ φ₀²φ₁²`, what κ penalises, falls
///   (measured: 3.4e-4 against the like doublet's 3.6e-3, 9.5 %; asserted below 50 %).
#[test]
fn pair_repulsion_steps_as_the_repulsion_of_each_pair() {
    let run = |pairs: Option<(&[u16], Vec<f64>)>| match pairs {
        Some((of_cell, m)) => stepped_doublet(
            0.0,
            Some((of_cell, &move |p: Populations| p.with_repulsion(m.clone()))),
            2,
        ),
        None => stepped_doublet(0.0, None, 2),
    };
    let close = largest_difference;
    let kappa = ModelParams::paper(0.0).energy.kappa;
    let (tissue, o_tissue) = run(None);
    let (same, _) = run(Some((&[0, 1], vec![kappa; 4])));
    assert!(close(&same, &tissue) < 1e-9, "{}", close(&same, &tissue));
    let m = vec![kappa, 0.8, 0.8, kappa];
    let (like, _) = run(Some((&[0, 0], m.clone())));
    assert!(close(&like, &tissue) < 1e-9, "{}", close(&like, &tissue));
    let (_, o_unlike) = run(Some((&[0, 1], m)));
    eprintln!("Σ φ₀²φ₁²: like {o_tissue}, unlike at κ_ab = 0.8 {o_unlike}");
    assert!(o_tissue > 1e-3, "the doublet is in contact: {o_tissue}");
    assert!(o_unlike < 0.5 * o_tissue, "{o_unlike} against {o_tissue}");
}

/// T6.1 of the extensions: populations whose parameters are the tissue's (one overriding
/// every parameter with the tissue's own value, one overriding nothing) step exactly as the
/// tissue without populations, to the bit, at ζ ≠ 0.
#[test]
fn uniform_populations_are_the_scalar_model_to_the_bit() {
    let run = |pops: Option<Populations>| {
        let mut t = four_cells();
        if let Some(p) = pops {
            t = t.with(p);
        }
        let mut ws = Workspace::new(t.cells());
        for _ in 0..30 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        let f = t.fields(&mut ws);
        (t.cells().phi().to_vec(), f.qxx, f.sigma_xx)
    };
    let p = ModelParams::paper(0.01);
    let same = Population::new()
        .with_gamma(p.energy.gamma)
        .with_mu(p.energy.mu)
        .with_radius(p.energy.radius)
        .with_xi(p.xi)
        .with_zeta(p.zeta);
    let pops = Populations::new(vec![same, Population::new()], &[2, 2], 5);
    let (a, b) = (run(None), run(Some(pops)));
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.0), bits(&b.0), "fields");
    assert_eq!(bits(&a.1), bits(&b.1), "Q");
    assert_eq!(bits(&a.2), bits(&b.2), "stress");
}

/// Populations are dealt by a shuffle from the seed: the counts are kept, and both
/// populations are spread over the identities.
#[test]
fn populations_are_dealt_with_their_counts() {
    let pops = Populations::new(vec![Population::new(); 3], &[10, 20, 30], 4);
    let of = pops.of_cell();
    for (k, want) in [10, 20, 30].into_iter().enumerate() {
        assert_eq!(of.iter().filter(|&&p| p as usize == k).count(), want);
    }
    // Not in blocks: the first ten identities are not all population 0.
    assert!(of[..10].iter().any(|&p| p != 0));
    assert_eq!(
        Populations::new(vec![Population::new(); 3], &[10, 20, 30], 4),
        pops
    );
}

/// The alignment targets, on a cell given by hand: to the shape, the polarity turns towards
/// the nearer end of the long axis at rate `J |S| Δ`; to the force, towards the force at rate
/// `J |F| Δ`; inactive, not at all.
#[test]
fn alignment_targets_are_the_shape_axis_and_the_force() {
    // Long axis along x with |S| = 0.3; the force along +y.
    let state = crate::CellState {
        shape: crate::TracelessTensor::new(0.3, 0.0),
        force: Vector2::new(0.0, 0.02),
        ..Default::default()
    };
    let cell = |active| CellContext {
        id: 0,
        centre: [0.0; 2],
        state: &state,
        population: 0,
        active,
    };
    let rate = |align, theta: f64, active| {
        let mut out = [0.0];
        Polarity::new(0.04)
            .with_alignment(align, 2.0)
            .rate(&cell(active), &[theta], &mut out);
        out[0]
    };
    // p at +0.3 rad from +x: back towards +x; p at π − 0.3: towards −x (the nearer end).
    assert!((rate(Align::Shape, 0.3, true) - (-2.0 * 0.3 * 0.3)).abs() < 1e-12);
    assert!((rate(Align::Shape, std::f64::consts::PI - 0.3, true) - 2.0 * 0.3 * 0.3).abs() < 1e-12);
    // p along +x, F along +y: turns towards +y, Δ = −π/2.
    let expected = 2.0 * 0.02 * std::f64::consts::FRAC_PI_2;
    assert!((rate(Align::Force, 0.0, true) - expected).abs() < 1e-12);
    assert_eq!(rate(Align::Force, 0.0, false), 0.0);
}

/// Contact inhibition of locomotion: a cell pressed against along its polarity with a force
/// `α` pushes with `α e^{−η}` (to round-off), and not at all less when the force is behind it;
/// two cells driven head-on into each other (α = 0.04, 200 TU) press less, so they end farther
/// apart and overlap less, with η = 3 than without.
#[test]
fn contact_inhibition_stalls_the_propulsion() {
    let state = crate::CellState {
        force: Vector2::new(-0.04, 0.0),
        ..Default::default()
    };
    let cell = CellContext {
        id: 0,
        centre: [0.0; 2],
        state: &state,
        population: 0,
        active: true,
    };
    let pol = Polarity::new(0.04).with_contact_inhibition(3.0);
    let f = pol.force(&cell, &[0.0]);
    assert!((f[0] - 0.04 * (-3.0f64).exp()).abs() < 1e-15, "{f:?}");
    let behind = pol.force(&cell, &[std::f64::consts::PI]);
    assert!((behind[0] + 0.04).abs() < 1e-15, "{behind:?}");

    let head_on = |eta: f64| {
        let lattice = Lattice::new(80, 48);
        let shape = PatchShape::new(lattice, 14).unwrap();
        let cells = init::discs(lattice, shape, &[[28.0, 24.0], [52.0, 24.0]], 8.0, 2.5);
        let pol = Polarity::new(0.04).with_contact_inhibition(eta);
        let mut t = Tissue::new(cells, ModelParams::paper(0.0)).with(Terms::new(1).with(pol));
        t.terms_mut()
            .set_variable("polarity/theta", &[0.0, std::f64::consts::PI])
            .unwrap();
        let mut ws = Workspace::new(t.cells());
        for _ in 0..400 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        let c = t.cells();
        let overlap: f64 = (0..80)
            .flat_map(|x| (0..48).map(move |y| (x, y)))
            .map(|(x, y)| c.value_at(0, x, y) * c.value_at(1, x, y))
            .sum();
        let gap = displacement(t.centres()[0], t.centres()[1], 80.0).norm();
        (gap, overlap)
    };
    let (free, inhibited) = (head_on(0.0), head_on(3.0));
    eprintln!("head-on (distance, overlap): without {free:?}, with eta = 3 {inhibited:?}");
    assert!(
        inhibited.0 > free.0 && inhibited.1 < free.1,
        "{free:?} {inhibited:?}"
    );
}

/// A rejected adaptive step draws the same noise again: with rotational diffusion alone, every
/// accepted step of size h turns each cell by exactly `√h √(2 D_r) N(seed, cell, step)`, however
/// many attempts it took (the test makes the first attempts too large to be accepted).
#[test]
fn a_rejected_adaptive_step_replays_its_noise() {
    let lattice = Lattice::new(48, 48);
    let shape = PatchShape::new(lattice, 12).unwrap();
    let cells = init::discs(lattice, shape, &[[14.0, 14.0], [34.0, 30.0]], 6.0, 2.5);
    let d_r = 0.01;
    let pol = Polarity::new(0.04).with_rotational_diffusion(d_r);
    let mut t = Tissue::new(cells, ModelParams::paper(0.0)).with(Terms::new(9).with(pol));
    let mut ws = Workspace::new(t.cells());
    let params = crate::AdaptiveParams::new(1e-4, 2.0);
    let mut ctrl = crate::Controller::new(2.0);
    for _ in 0..20 {
        let before = t.terms().state("polarity").unwrap().to_vec();
        let step = t.iteration();
        let h = t
            .step_adaptive(&mut ws, &params, &mut ctrl, f64::INFINITY, &mut ())
            .unwrap();
        for (id, (a, b)) in before
            .iter()
            .zip(t.terms().state("polarity").unwrap())
            .enumerate()
        {
            let n = NoiseKey {
                seed: 9,
                cell: id as u64,
                step,
                stage: 0,
            }
            .normal();
            let expected = a + h.sqrt() * (2.0 * d_r).sqrt() * n;
            assert!(
                (b - expected).abs() < 1e-14,
                "step {step}, cell {id}: {b} against {expected}"
            );
        }
    }
    assert!(
        ctrl.rejected > 0,
        "no attempt was rejected, so nothing was tested"
    );
}

/// Arms [`FailsInTheCorrector`] (only its test uses it).
static ARMED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// A force that is not finite in Heun's corrector only (`NaN` while [`ARMED`]), as a host's
/// force that fails in its second call gives.
#[derive(Debug)]
struct FailsInTheCorrector;

impl CellTerm for FailsInTheCorrector {
    fn name(&self) -> &str {
        "fails"
    }
    fn force(&self, _: &CellContext<'_>, _: &[f64]) -> [f64; 2] {
        [0.0; 2]
    }
    fn forces(&self, cells: &CellBatch<'_>, _: &[f64], out: &mut [[f64; 2]]) {
        let nan = cells.stage() > 0.0 && ARMED.load(std::sync::atomic::Ordering::SeqCst);
        out.fill(if nan { [f64::NAN; 2] } else { [0.0; 2] });
    }
}

/// A whole-cell force that is not finite in the corrector stops the step with the tissue at
/// the step's start to the bit (fields, clock, the terms' state), whatever the number of
/// corrector passes: the fused last corrector writes over the start in place, so the force is
/// checked before it runs. Disarmed, the next step is the one an untouched copy takes.
#[test]
fn a_force_that_fails_in_the_corrector_leaves_the_step_start() {
    use std::sync::atomic::Ordering::SeqCst;
    for npc in [1, 2] {
        let terms = Terms::new(1)
            .with(Polarity::new(0.04).with_rotational_diffusion(0.01))
            .with(FailsInTheCorrector);
        let (mut t, mut ws) = relaxed_cell(terms);
        let sp = StepParams {
            npc,
            ..StepParams::default()
        };
        t.step(&mut ws, &sp).expect("stable");
        let (copy, phi, theta) = (
            t.clone(),
            t.cells().phi().to_vec(),
            t.terms().state("polarity").unwrap().to_vec(),
        );
        let (clock, time) = (t.iteration(), t.time());
        ARMED.store(true, SeqCst);
        let e = t.step(&mut ws, &sp);
        ARMED.store(false, SeqCst);
        let e = e.expect_err("a NaN force in the corrector");
        assert!(
            matches!(e, crate::StepError::NonFinite { cell_idx: 0, .. }),
            "{e}"
        );
        assert_eq!(t.cells().phi(), &phi[..], "npc {npc}: the fields");
        assert_eq!(
            t.terms().state("polarity").unwrap(),
            &theta[..],
            "npc {npc}: θ"
        );
        assert_eq!(
            (t.iteration(), t.time()),
            (clock, time),
            "npc {npc}: the clock"
        );
        t.step(&mut ws, &sp).expect("stable");
        let mut copy = copy;
        let mut ws2 = Workspace::new(copy.cells());
        copy.step(&mut ws2, &sp).expect("stable");
        assert_eq!(
            t.cells().phi(),
            copy.cells().phi(),
            "npc {npc}: goes on as before"
        );
    }
}

/// Five cells of R = 7 on 64², a centre cell (population 0) with four neighbours 13 away
/// along ±x and ±y (population 1), relaxed at rest for 50 TU; every nematic along x.
fn cross(zeta_q: f64) -> (Tissue, Workspace) {
    let lattice = Lattice::new(64, 64);
    let shape = PatchShape::new(lattice, 12).unwrap();
    let c = 32.0;
    let centres = [
        [c, c],
        [c + 13.0, c],
        [c - 13.0, c],
        [c, c + 13.0],
        [c, c - 13.0],
    ];
    let cells = init::discs(lattice, shape, &centres, 7.0, 2.5);
    let pops = Populations::from_assignment(
        vec![Population::new(), Population::new()],
        vec![0, 1, 1, 1, 1],
    );
    let nem = CellNematic::new(0.0)
        .with_population(0, [Some(zeta_q), None, None, None])
        .with_initial_angle(0.0);
    let mut t = Tissue::new(cells, ModelParams::paper(0.0))
        .with(pops)
        .with(Terms::new(1).with(nem));
    let mut ws = Workspace::new(t.cells());
    t.set_active(false);
    for _ in 0..100 {
        t.step(&mut ws, &StepParams::default()).expect("stable");
    }
    t.set_active(true);
    (t, ws)
}

/// T4.2 of the extensions, the sign: one cell whose nematic is fixed along x among passive
/// cells. With ζ_Q > 0 (extensile) the force it adds pushes its neighbours along x outward and
/// pulls those along y inward; with ζ_Q < 0 the reverse. The added force is the difference
/// of the interface forces with and without ζ_Q in one evaluation of the same fields: linear
/// in ζ_Q, so the two signs' are opposite to round-off (1e-12 of their size), and by the
/// cross's symmetry the neighbours' are mirror images (1e-9) and the active cell's own zero.
#[test]
fn an_extensile_cell_nematic_pushes_along_its_axis() {
    let added = |zeta_q: f64| {
        let (t, mut ws) = cross(zeta_q);
        t.refresh(&mut ws);
        let with: Vec<Vector2<f64>> = ws.cell_states().iter().map(|s| s.force).collect();
        // The same fields without the activity.
        let mut t0 = t.clone();
        t0.set_active(false);
        t0.refresh(&mut ws);
        let slots: Vec<usize> = (0..5)
            .map(|id| t.cell_ids().iter().position(|&i| i == id).unwrap())
            .collect();
        slots
            .iter()
            .map(|&s| with[s] - ws.cell_states()[s].force)
            .collect::<Vec<_>>()
    };
    let ext = added(0.01);
    let con = added(-0.01);
    eprintln!("added forces, extensile: {ext:?}");
    let size = ext[1].norm();
    assert!(size > 1e-6, "the nematic adds a force: {size:e}");
    // Outward along x, inward along y.
    assert!(ext[1].x > 0.0 && ext[2].x < 0.0, "{ext:?}");
    assert!(ext[3].y < 0.0 && ext[4].y > 0.0, "{ext:?}");
    for k in 0..5 {
        assert!((ext[k] + con[k]).norm() < 1e-12 * size, "linear in ζ_Q");
    }
    assert!((ext[1].x + ext[2].x).abs() < 1e-9 * size);
    assert!((ext[3].y + ext[4].y).abs() < 1e-9 * size);
    assert!(
        ext[0].norm() < 1e-9 * size,
        "the active cell itself: {:?}",
        ext[0]
    );
}

/// θ relaxes to its target's axis at the set rate: an isolated cell pushed by a constant
/// force `G x̂` moves at `v = G/ξ`, and its nematic aligned to the velocity at rate `J` turns
/// as `dδ/dt = −J |v| δ`. From δ = 0.1 and from π − 0.1 (the same axis, the other end) the
/// measured decay rate of ln δ down to δ = 0.02 is within 1 % of `J G/ξ` (the rate is exact
/// in δ; what is left is Heun's error at `J|v| dt = 0.01`).
#[test]
fn the_cell_nematic_relaxes_to_its_target_at_the_set_rate() {
    let (g, j, xi) = (0.02, 2.0, 2.0);
    for (start, axis) in [
        (0.1, 0.0),
        (std::f64::consts::PI - 0.1, std::f64::consts::PI),
    ] {
        let nem = CellNematic::new(0.0)
            .with_alignment(Align::Velocity, j)
            .with_initial_angle(start);
        let (mut t, mut ws) = relaxed_cell(Terms::new(1).with(nem).with(Tilt([g, 0.0])));
        let delta = |t: &Tissue| (t.terms().state("nematic").unwrap()[0] - axis).abs();
        let mut samples = Vec::new();
        while delta(&t) > 0.02 {
            t.step(&mut ws, &StepParams::default()).expect("stable");
            samples.push((t.time(), delta(&t).ln()));
        }
        let n = samples.len() as f64;
        let (mt, ml) = samples
            .iter()
            .fold((0.0, 0.0), |(a, b), (t, l)| (a + t / n, b + l / n));
        let (sxy, sxx) = samples.iter().fold((0.0, 0.0), |(a, b), (t, l)| {
            (a + (t - mt) * (l - ml), b + (t - mt) * (t - mt))
        });
        let rate = -sxy / sxx;
        let expected = j * g / xi;
        eprintln!("nematic alignment from {start}: rate {rate} against {expected}");
        assert!(
            (rate / expected - 1.0).abs() < 0.01,
            "{rate} against {expected}"
        );
    }
}

/// Sixteen cells on a square grid of spacing 12 on 48², relaxed at rest for 100 TU into a
/// confluent tissue, with the nematic's fields measured (`K ≠ 0`).
fn grid_tissue() -> (Tissue, Workspace) {
    let lattice = Lattice::new(48, 48);
    let shape = PatchShape::new(lattice, 12).unwrap();
    let centres: Vec<[f64; 2]> = (0..16)
        .map(|k| [6.0 + 12.0 * (k % 4) as f64, 6.0 + 12.0 * (k / 4) as f64])
        .collect();
    let cells = init::discs(lattice, shape, &centres, 6.8, 2.5);
    let nem = CellNematic::new(0.0)
        .with_elastic(1.0)
        .with_initial_angle(0.0);
    let mut t = Tissue::new(cells, ModelParams::paper(0.0)).with(Terms::new(1).with(nem));
    let mut ws = Workspace::new(t.cells());
    t.set_active(false);
    for _ in 0..200 {
        t.step(&mut ws, &StepParams::default()).expect("stable");
    }
    (t, ws)
}

/// The measured rotation rate of the flow is the closed form of rigid motions. For a
/// tessellation of cells moving rigidly with `v_j = Ω ẑ × c_j`, the flow's curl lies on the
/// interfaces, each weighted by `φ_i ≈ ½` there, and sums to `Ω d P_i / A_i` over a cell of
/// perimeter `P_i` and area `A_i` whose neighbours are `d` away; for a square cell of side `d`
/// that is `2Ω`, so `ω_i = Ω`. Measured on the four inner cells of a relaxed 4 × 4 grid
/// (the outer ones meet the periodic wrap of `c_j`): 0.900 Ω, the same for the four to
/// 1e-15. The 10 % are the grid's rounded corners, where the cells do not touch: the contact
/// perimeter is shorter than a square's. Asserted: within 15 %. A uniform translation turns
/// nothing: `|ω_i|` below 1e-3 of `V / d` (measured 1e-20 of V).
#[test]
fn the_vorticity_a_cell_feels_is_that_of_a_rigid_rotation() {
    let (t, mut ws) = grid_tissue();
    t.refresh(&mut ws);
    let centre = [24.0, 24.0];
    let omega = 1e-3;
    let q = vec![[1.0, 0.0]; 16];
    let slots: Vec<usize> = t.cell_ids().to_vec();
    let at = |id: usize| [6.0 + 12.0 * (id % 4) as f64, 6.0 + 12.0 * (id / 4) as f64];
    let states = &mut ws.cell_state;
    for (slot, &id) in slots.iter().enumerate() {
        let c = at(id);
        states[slot].velocity =
            Vector2::new(-omega * (c[1] - centre[1]), omega * (c[0] - centre[0]));
    }
    let mut fields = crate::scatter::LatticeSums::new(t.lattice());
    crate::nematic_fields::measure(t.cells(), t.cells().phi(), &q, states, &mut fields);
    for (slot, &id) in slots.iter().enumerate() {
        let inner = [5, 6, 9, 10].contains(&id);
        if inner {
            let w = states[slot].vorticity;
            eprintln!("cell {id}: ω = {w:e} against Ω = {omega:e}");
            assert!((w / omega - 1.0).abs() < 0.15, "cell {id}: {w:e}");
        }
    }
    let v = 1e-2;
    for s in states.iter_mut() {
        s.velocity = Vector2::new(v, 0.0);
    }
    crate::nematic_fields::measure(t.cells(), t.cells().phi(), &q, states, &mut fields);
    let worst = states.iter().map(|s| s.vorticity.abs()).fold(0.0, f64::max);
    eprintln!("translation: largest |ω| {worst:e}");
    assert!(worst < 1e-3 * v / 12.0, "{worst:e}");
    // Every cell's nematic along x: the mean field is along x too.
    for s in states.iter() {
        assert!(s.nematic_field[0] > 0.0 && s.nematic_field[1].abs() < 1e-12);
    }
}

/// The nematic's stress adds to the shape activity's: without populations, the interface
/// forces with ζ and ζ_Q both on are those with each alone, less those with neither, to 1e-12
/// of their size (one evaluation of the same fields; the sum's weights differ in rounding
/// only). A cell's own active tensor once made the step weight every `S_i` by 1 in place of
/// ζ, which this catches.
#[test]
fn the_cell_nematic_stress_adds_to_the_shape_activity() {
    // Four cells pressed into each other for 25 TU at rest, so that their shapes are not
    // round (a disc's `S_i` is zero).
    let mut pressed = four_cells();
    let mut ws = Workspace::new(pressed.cells());
    pressed.set_active(false);
    for _ in 0..50 {
        pressed.step(&mut ws, &StepParams::default()).unwrap();
    }
    pressed.set_active(true);
    let forces = |zeta: f64, zeta_q: f64| {
        let mut t = pressed.clone();
        t.params_mut().zeta = zeta;
        let t = t.with(Terms::new(3).with(CellNematic::new(zeta_q)));
        let mut ws = Workspace::new(t.cells());
        t.refresh(&mut ws);
        ws.cell_states().iter().map(|s| s.force).collect::<Vec<_>>()
    };
    let (both, shape, nematic, none) = (
        forces(0.01, 0.004),
        forces(0.01, 0.0),
        forces(0.0, 0.004),
        forces(0.0, 0.0),
    );
    let size = shape
        .iter()
        .chain(&nematic)
        .map(|f| f.norm())
        .fold(0.0, f64::max);
    assert!(size > 1e-4, "{size:e}");
    for i in 0..4 {
        let sum = shape[i] + nematic[i] - none[i];
        assert!(
            (both[i] - sum).norm() < 1e-12 * size,
            "cell {i}: {:?} against {sum:?}",
            both[i]
        );
    }
}

/// Forces by origin (issue 49): on the pressed four cells with every part on (ζ, the cells'
/// nematic, adhesion, channel walls and a polarity), each part is listed and not zero, and the
/// parts add up to the interface force plus the terms' whole-cell force to 1e-12 of the largest
/// part; the pressure part is the interface force of the same fields without any extension
/// (1e-12). A tissue without extensions has the pressure alone, equal to its force.
#[test]
fn the_forces_by_origin_add_up_to_the_force() {
    use crate::walls::Walls;
    use phasefield::{WallField, WallShape};
    let mut t = four_cells();
    let mut ws = Workspace::new(t.cells());
    t.set_active(false);
    for _ in 0..50 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    t.set_active(true);
    let plain = t.clone();
    t.params_mut().omega = 0.002;
    let field = WallField::of_shape(t.lattice(), &WallShape::Channel { width: 40.0 }, 1.0, 0.0);
    let terms = Terms::new(5)
        .with(Polarity::new(0.01))
        .with(CellNematic::new(0.004));
    let t = t.with(Walls::new(field, 1.0, 0.0)).with(terms);
    let parts = t.forces_by_origin(&mut ws);
    assert_eq!(
        parts.names,
        [
            "pressure",
            "shape_activity",
            "nematic_activity",
            "adhesion",
            "walls",
            "polarity"
        ]
    );
    let size = parts
        .parts
        .iter()
        .flatten()
        .map(|f| f[0].hypot(f[1]))
        .fold(0.0, f64::max);
    for (name, p) in parts.names.iter().zip(&parts.parts) {
        let largest = p.iter().map(|f| f[0].hypot(f[1])).fold(0.0, f64::max);
        assert!(largest > 1e-6 * size, "{name} is zero");
    }
    let states = ws.cell_states();
    for slot in 0..4 {
        let sum = parts
            .parts
            .iter()
            .fold([0.0; 2], |a, p| [a[0] + p[slot][0], a[1] + p[slot][1]]);
        let total = states[slot].force + states[slot].cell_force;
        assert!(
            (sum[0] - total.x).hypot(sum[1] - total.y) < 1e-12 * size,
            "slot {slot}: {sum:?} against {total:?}"
        );
    }
    let mut ws0 = Workspace::new(plain.cells());
    let mut passive = plain.clone();
    passive.params_mut().zeta = 0.0;
    passive.refresh(&mut ws0);
    for slot in 0..4 {
        let (a, b) = (parts.parts[0][slot], ws0.cell_states()[slot].force);
        assert!((a[0] - b.x).hypot(a[1] - b.y) < 1e-12 * size);
    }
    let alone = passive.forces_by_origin(&mut ws0);
    assert_eq!(alone.names, ["pressure"]);
    for slot in 0..4 {
        let f = ws0.cell_states()[slot].force;
        assert_eq!(alone.parts[0][slot], [f.x, f.y]);
    }
}

/// Each population's nematic has its own alignment rate: two lone cells pushed by `G x̂`,
/// population 0 at `J = 2` and population 1 at its own `J = 0.5`, turn from 0.1 rad towards
/// their velocity at `J_p G/ξ` each; after 40 TU `ln δ` has fallen by `J_p G t/ξ`, within 1 %
/// of each (the rate is exact in δ; Heun's error at `J|v| dt = 0.01` is below 1e-4).
#[test]
fn a_population_turns_its_nematic_at_its_own_rate() {
    let lattice = Lattice::new(96, 48);
    let shape = PatchShape::new(lattice, 14).unwrap();
    let cells = init::discs(lattice, shape, &[[24.0, 24.0], [72.0, 24.0]], 8.0, 2.5);
    let pops = Populations::from_assignment(vec![Population::new(); 2], vec![0, 1]);
    let (g, xi) = (0.02, 2.0);
    let nem = CellNematic::new(0.0)
        .with_alignment(Align::Velocity, 2.0)
        .with_initial_angle(0.1)
        .with_population(1, [None, Some(0.5), None, None]);
    let mut t = Tissue::new(cells, ModelParams::paper(0.0))
        .with(pops)
        .with(Terms::new(1).with(nem).with(Tilt([g, 0.0])));
    let mut ws = Workspace::new(t.cells());
    for _ in 0..80 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    let theta = t.terms().state("nematic").unwrap().to_vec();
    for (id, j) in [(0, 2.0), (1, 0.5)] {
        let fall = (0.1f64).ln() - theta[id].ln();
        let expected = j * g / xi * t.time();
        eprintln!("population {id}: ln δ fell by {fall}, expected {expected}");
        assert!(
            (fall / expected - 1.0).abs() < 0.01,
            "{fall} against {expected}"
        );
    }
}

/// The analysis's fields of a tissue with the cells' nematic: `Q` is still `Σ φ_j S_j` (to
/// 1e-12 of the same fields without the nematic), and the stress carries the nematic's part,
/// `σ_xx = −P − ζ Q_xx − ζ_Q S s1` and `σ_xy = −ζ Q_xy` for every axis along x (1e-12). The
/// fields once read the evaluation's weighted sums as `Q` and multiplied them by ζ again.
#[test]
fn the_fields_of_a_nematic_tissue_keep_q_and_carry_its_stress() {
    let mut t = four_cells();
    let mut ws = Workspace::new(t.cells());
    t.set_active(false);
    for _ in 0..50 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    t.set_active(true);
    let zq = 0.004;
    let plain = t.fields(&mut ws);
    let nem = t
        .clone()
        .with(Terms::new(2).with(CellNematic::new(zq).with_initial_angle(0.0)));
    let f = nem.fields(&mut ws);
    let s1 = ws.sum_field(crate::SumField::S1);
    let scale = plain
        .qxx
        .iter()
        .chain(&plain.pressure)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let zeta = t.params().zeta;
    for k in 0..s1.len() {
        assert!((f.qxx[k] - plain.qxx[k]).abs() < 1e-12 * scale);
        assert!((f.qxy[k] - plain.qxy[k]).abs() < 1e-12 * scale);
        let sxx = -f.pressure[k] - zeta * f.qxx[k] - zq * s1[k];
        assert!((f.sigma_xx[k] - sxx).abs() < 1e-12 * scale, "node {k}");
        assert!((f.sigma_xy[k] + zeta * f.qxy[k]).abs() < 1e-12 * scale);
    }
}

/// A term that aligns to the shape gets the shapes even without an active stress
/// (`CellTerm::needs_shapes`): at ζ = 0 the pressed four cells' polarities, aligned to their
/// long axes, turn in a step. (The step once skipped the shapes at ζ = 0, and the polarity
/// aligned to zero.)
#[test]
fn a_shape_alignment_sees_the_shapes_at_zero_activity() {
    let mut t = four_cells();
    t.params_mut().zeta = 0.0;
    let mut ws = Workspace::new(t.cells());
    for _ in 0..50 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    let pol = Polarity::new(0.0)
        .with_alignment(Align::Shape, 1.0)
        .with_initial_angle(0.3);
    let mut t = t.with(Terms::new(1).with(pol));
    for _ in 0..2 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    let theta = t.terms().state("polarity").unwrap();
    assert!(theta.iter().all(|&a| (a - 0.3).abs() > 1e-9), "{theta:?}");
}
