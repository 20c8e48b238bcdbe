//! Free-energy derivatives against finite differences of the discrete energy; centre of mass.

use phasefield::{for_each_stencil, init, Cells, ComTable, EnergyParams, Lattice, PatchShape};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

use crate::strategies::node_or_half;

const L: usize = 9;

/// Random fields in [-0.1, 1.1] for `n` cells on the full `L × L` lattice.
fn random_state() -> impl Strategy<Value = Vec<f64>> {
    proptest::collection::vec(-0.1f64..1.1, 3 * L * L)
}

fn cells_from(values: &[f64]) -> Cells {
    let lattice = Lattice::new(L, L);
    let shape = PatchShape::new(lattice, 0).unwrap();
    let mut cells = Cells::zeros(lattice, shape, &[[0.0, 0.0]; 3]);
    cells.phi_mut().copy_from_slice(values);
    cells
}

/// The analytic `δF/δφ_i(k)` of the implementation.
fn analytic(e: &EnergyParams, cells: &Cells, i: usize, k: usize) -> f64 {
    let shape = cells.shape();
    let area: f64 = cells.cell_phi(i).iter().map(|p| p * p).sum();
    let others: f64 = (0..cells.n_cells())
        .filter(|&j| j != i)
        .map(|j| cells.cell_phi(j)[k].powi(2))
        .sum();
    let mut out = 0.0;
    for_each_stencil(cells.cell_phi(i), shape, |kk, s| {
        if kk == k {
            out = e.ch(s.c, s.laplacian()) + e.area(s.c, area) + e.rep(s.c, others);
        }
    });
    out
}

fn check_derivative(e: EnergyParams) {
    let mut runner = TestRunner::new(Config {
        cases: 24,
        ..Config::default()
    });
    runner
        .run(&(random_state(), 0..3usize, 0..L * L), |(values, i, k)| {
            let mut cells = cells_from(&values);
            let a = analytic(&e, &cells, i, k);
            // Central difference of the discrete energy: truncation O(h² F''') ~ 1e-10 and
            // round-off ε·F/h ~ 1e-16·10/1e-5 = 1e-10, so 1e-7 leaves a wide margin.
            let h = 1e-5;
            let idx = i * L * L + k;
            cells.phi_mut()[idx] = values[idx] + h;
            let fp = e.free_energy(&cells);
            cells.phi_mut()[idx] = values[idx] - h;
            let fm = e.free_energy(&cells);
            let fd = (fp - fm) / (2.0 * h);
            prop_assert!(
                (fd - a).abs() < 1e-7 * (1.0 + a.abs()),
                "analytic {a}, finite difference {fd}"
            );
            Ok(())
        })
        .unwrap();
}

/// Free-energy parameters with the given γ, μ, λ, κ and R.
fn energy(gamma: f64, mu: f64, lambda: f64, kappa: f64, radius: f64) -> EnergyParams {
    let mut e = EnergyParams::paper();
    (e.gamma, e.mu, e.lambda, e.kappa, e.radius) = (gamma, mu, lambda, kappa, radius);
    e
}

#[test]
fn cahn_hilliard_derivative_is_the_gradient_of_the_discrete_energy() {
    check_derivative(energy(0.7, 0.0, 2.5, 0.0, 3.0));
}

#[test]
fn area_derivative_is_the_gradient_of_the_discrete_energy() {
    check_derivative(energy(0.0, 3.0, 2.5, 0.0, 3.0));
}

#[test]
fn repulsion_derivative_is_the_gradient_of_the_discrete_energy() {
    check_derivative(energy(0.0, 0.0, 2.5, 0.4, 3.0));
}

#[test]
fn full_derivative_is_the_gradient_of_the_discrete_energy() {
    check_derivative(energy(0.3, 3.0, 1.7, 0.4, 3.0));
}

/// Exact (to round-off) on a disc symmetric about its storage, anywhere, including across
/// both periodic edges: about a node or a half-node in full-domain storage (even L), about a
/// node in a patch (an odd-sided patch is symmetric about its centre node only; a disc centred
/// on a half-node is cut asymmetrically and its centre is biased by the tail beyond the patch).
#[test]
fn centre_of_mass_is_exact_on_a_wrapped_disc() {
    let l = 60;
    let mut runner = TestRunner::new(Config {
        cases: 64,
        ..Config::default()
    });
    runner
        .run(
            &(node_or_half(l), prop_oneof![Just(0usize), Just(12usize)]),
            |(mut c, margin)| {
                if margin > 0 {
                    c = [c[0].floor(), c[1].floor()];
                }
                let lattice = Lattice::new(l, l);
                let shape = PatchShape::new(lattice, margin).unwrap();
                let cells = init::discs(lattice, shape, &[c], 6.3, 2.5);
                let com = ComTable::new(lattice);
                let got = com.cell_centre(&cells, 0);
                for s in 0..2 {
                    // A wrapped coordinate near 0 may come back near L: compare on the circle.
                    let d = phasefield::min_image(got[s] - c[s], l as f64);
                    // Round-off of atan2 scaled by L/2π: a few ε·L.
                    prop_assert!(d.abs() < 1e-12 * l as f64, "axis {s}: {c:?} -> {got:?}");
                }
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn centre_of_mass_follows_a_disc_across_both_edges() {
    let l = 48;
    let lattice = Lattice::new(l, l);
    let com = ComTable::new(lattice);
    for &c in &[
        [0.0, 0.0],
        [47.0, 1.0],
        [1.0, 47.0],
        [47.0, 47.0],
        [24.0, 46.0],
    ] {
        let cells = init::discs(
            lattice,
            PatchShape::new(lattice, 10).unwrap(),
            &[c],
            5.0,
            2.5,
        );
        let got = com.cell_centre(&cells, 0);
        for s in 0..2 {
            assert!(
                phasefield::min_image(got[s] - c[s], l as f64).abs() < 1e-12 * l as f64,
                "{c:?} -> {got:?}"
            );
            assert!((0.0..l as f64).contains(&got[s]));
        }
    }
}
