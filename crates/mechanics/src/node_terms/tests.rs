//! The node-term contract's per-population case, on [`PairAdhesion`]: its derivative against
//! the discrete energy, its pressure, and the uniform matrix against [`Adhesion`], each
//! through `kernels::evaluate` with the terms given as a list.

use phasefield::{Cells, Lattice, PatchShape};

use super::*;
use crate::equations::adhesion_coefficient;
use crate::evaluation::{CellState, SumField};
use crate::kernels::{evaluate, EvalInput, EvalScratch, Post};
use crate::terms::{Population, Populations};
use crate::{ModelParams, PressureKind};

const L: usize = 20;
const LAMBDA: f64 = 2.5;

/// Four cells of random values on the full 20 × 20 domain (a patch is the lattice), cells 0
/// and 2 of population 0, cells 1 and 3 of population 1.
fn random_cells() -> (Cells<f64>, Populations) {
    let lattice = Lattice::new(L, L);
    let shape = PatchShape::new(lattice, 0).unwrap();
    let centres = [[5.0, 5.0], [12.0, 9.0], [8.0, 15.0], [15.0, 15.0]];
    let mut cells = Cells::zeros(lattice, shape, &centres);
    let mut state = 12345u64;
    for v in cells.phi_mut() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        *v = (state >> 11) as f64 / (1u64 << 53) as f64;
    }
    let pops = Populations::from_assignment(vec![Population::new(); 2], vec![0, 1, 0, 1]);
    (cells, pops)
}

/// The right-hand side and the pressure field `P` of one evaluation with the node terms
/// `terms`, at a friction so large (1e200) that advection is nil: the right-hand side is then
/// `−δF/δφ_i`.
fn evaluate_with(
    cells: &Cells<f64>,
    pops: &Populations,
    terms: &[Option<&dyn NodeTerm>],
) -> (Vec<f64>, Vec<f64>) {
    evaluate_in(&ModelParams::paper(0.0).with_xi(1e200), cells, pops, terms)
}

/// [`evaluate_with`] with the model `params`.
fn evaluate_in(
    params: &ModelParams,
    cells: &Cells<f64>,
    pops: &Populations,
    terms: &[Option<&dyn NodeTerm>],
) -> (Vec<f64>, Vec<f64>) {
    let n = cells.n_cells();
    let nodes = cells.lattice().len();
    let ids: Vec<usize> = (0..n).collect();
    let classes = classes(terms, pops);
    let scratch_fields: usize = terms.iter().flatten().map(|t| t.scratch_fields()).sum();
    let mut sums = LatticeSums::for_cells(cells.lattice(), n, cells.shape().nx);
    let mut cell_state = vec![CellState::default(); n];
    let mut node_scratch = vec![0.0; scratch_fields * nodes];
    let mut node_coefficients = vec![0.0; 2 * classes * nodes];
    let (mut node_constants, mut kind_constants) = (Vec::new(), Vec::new());
    let mut population_sums = PopulationSums::default();
    let input = EvalInput {
        params,
        cells,
        phi: cells.phi(),
        shapes: true,
        cell_force: None,
        cell_stress: None,
        shape_activity: true,
        populations: pops,
        ids: &ids,
        active: true,
        growth: &[],
        node_terms: terms,
        wall_friction: None,
    };
    let scratch = EvalScratch {
        sums: &mut sums,
        cell_state: &mut cell_state,
        node_scratch: &mut node_scratch,
        node_coefficients: &mut node_coefficients,
        node_constants: &mut node_constants,
        population_sums: &mut population_sums,
        kind_constants: &mut kind_constants,
    };
    let mut rhs = vec![0.0; cells.phi().len()];
    evaluate(&input, &mut rhs, scratch, Post::Nothing);
    (rhs, sums.field(SumField::P.index()))
}

/// `F = λ Σ_{i≠j} ω_{p_i p_j} Σ_x ∇⁺φ_i·∇⁺φ_j` (forward differences, periodic) of full-domain
/// fields `phi`, with `ω` row by row over `n_pop` populations.
fn pair_energy(omega: &[f64], n_pop: usize, pop: &[u16], phi: &[f64]) -> f64 {
    let n = phi.len() / (L * L);
    let grad = |i: usize, x: usize, y: usize| {
        let f = |x: usize, y: usize| phi[i * L * L + x * L + y];
        [f((x + 1) % L, y) - f(x, y), f(x, (y + 1) % L) - f(x, y)]
    };
    let mut e = 0.0;
    for i in 0..n {
        for j in (0..n).filter(|&j| j != i) {
            let w = omega[pop[i] as usize * n_pop + pop[j] as usize];
            for x in 0..L {
                for y in 0..L {
                    let (a, b) = (grad(i, x, y), grad(j, x, y));
                    e += w * (a[0] * b[0] + a[1] * b[1]);
                }
            }
        }
    }
    LAMBDA * e
}

/// Pair adhesion's part of `δF/δφ_i` in the evaluation is the derivative of its discrete
/// energy [`pair_energy`], for a matrix whose three entries differ, by central differences
/// at nodes of every cell. The energy is quadratic, so the quotient is exact but for
/// round-off: agreement to 1e-10 of the largest derivative. A wrong population's
/// coefficients (the matrix's rows swapped) would be off by the differences of its entries,
/// 40 % of the derivative here. The pressure gains `Σ_i φ_i δF/δφ_i`, to round-off.
#[test]
fn pair_adhesion_is_the_derivative_of_its_discrete_energy() {
    let (cells, pops) = random_cells();
    let omega = [0.01, 0.004, 0.004, 0.02];
    let term = PairAdhesion::new(&omega, 2, LAMBDA);
    let (r0, p0) = evaluate_with(&cells, &pops, &[]);
    let (r1, p1) = evaluate_with(&cells, &pops, &[Some(&term)]);
    let phi = cells.phi().to_vec();
    let n = cells.n_cells();
    let (mut worst, mut largest): (f64, f64) = (0.0, 0.0);
    for i in 0..n {
        for node in [0, 37, 150, 211, 399] {
            let k = i * L * L + node;
            let h = 1e-3;
            let (mut up, mut down) = (phi.clone(), phi.clone());
            up[k] += h;
            down[k] -= h;
            let fd = (pair_energy(&omega, 2, pops.of_cell(), &up)
                - pair_energy(&omega, 2, pops.of_cell(), &down))
                / (2.0 * h);
            worst = worst.max((fd + (r1[k] - r0[k])).abs());
            largest = largest.max(fd.abs());
        }
    }
    assert!(largest > 1e-3, "the test fields have adhesion: {largest}");
    assert!(worst < 1e-10 * largest, "{worst:e} off, of {largest:e}");
    for node in 0..L * L {
        let expected: f64 = (0..n)
            .map(|i| phi[i * L * L + node] * -(r1[i * L * L + node] - r0[i * L * L + node]))
            .sum();
        let got = p1[node] - p0[node];
        assert!(
            (got - expected).abs() < 1e-12,
            "P at {node}: {got} against {expected}"
        );
    }
}

/// With every `ω_pq = ω`, pair adhesion is the uniform [`Adhesion`] of `c = 2ωλ`: the same
/// right-hand side and pressure to 1e-13 of their largest change (the sums are grouped by
/// population, so only round-off differs). With walls' kind of term beside it (here a second
/// uniform adhesion), the coefficients of a uniform term reach every class.
#[test]
fn a_uniform_matrix_is_adhesion() {
    let (cells, pops) = random_cells();
    let omega = 0.01;
    let pair = PairAdhesion::new(&[omega; 4], 2, LAMBDA);
    let uniform = Adhesion {
        c: adhesion_coefficient(omega, LAMBDA),
    };
    let (r0, _) = evaluate_with(&cells, &pops, &[]);
    for (with_pair, with_uniform) in [
        (
            vec![Some(&pair as &dyn NodeTerm)],
            vec![Some(&uniform as &dyn NodeTerm)],
        ),
        (
            vec![Some(&pair as &dyn NodeTerm), Some(&uniform)],
            vec![Some(&uniform as &dyn NodeTerm), Some(&uniform)],
        ),
    ] {
        let (ra, pa) = evaluate_with(&cells, &pops, &with_pair);
        let (rb, pb) = evaluate_with(&cells, &pops, &with_uniform);
        let scale = ra
            .iter()
            .zip(&r0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            scale > 1e-3,
            "adhesion changes the right-hand side: {scale}"
        );
        for (a, b) in ra.iter().zip(&rb) {
            assert!((a - b).abs() <= 1e-13 * scale, "{a} against {b}");
        }
        let p_scale = pb.iter().map(|p| p.abs()).fold(0.0, f64::max);
        for (a, b) in pa.iter().zip(&pb) {
            assert!((a - b).abs() <= 1e-13 * p_scale, "P {a} against {b}");
        }
    }
}

/// `F = (1/λ) Σ_{i<j} κ_{p_i p_j} Σ_x φ_i²φ_j²` of full-domain fields `phi`, with `κ` row by
/// row over `n_pop` populations.
fn pair_repulsion_energy(kappa: &[f64], n_pop: usize, pop: &[u16], phi: &[f64]) -> f64 {
    let n = phi.len() / (L * L);
    let mut e = 0.0;
    for i in 0..n {
        for j in (i + 1)..n {
            let k = kappa[pop[i] as usize * n_pop + pop[j] as usize];
            for x in 0..L * L {
                e += k * (phi[i * L * L + x] * phi[j * L * L + x]).powi(2);
            }
        }
    }
    e / LAMBDA
}

/// Pair repulsion (`[repulsion] pairs`), in both pressure forms: the change of `δF/δφ_i` from
/// the tissue's κ to a matrix whose three entries differ (the like entries through the cells'
/// constants, the unlike through the term) is the derivative of the change of the discrete
/// energy [`pair_repulsion_energy`], by fourth-order central differences at nodes of every
/// cell (the energy is quartic, so the quotient is exact but for round-off): agreement to
/// 1e-9 of the largest. A term that left out the like entries' correction, or took the
/// wrong population's row, is off by 30 % or more here. The pressure changes by the sum of
/// the derivatives' changes (paper form) or their φ-weighted sum (interaction form), to
/// round-off.
#[test]
fn pair_repulsion_is_the_derivative_of_its_discrete_energy() {
    let (cells, pops) = random_cells();
    let kappa = [0.3, 0.05, 0.05, 0.15];
    let tissue = [0.1; 4];
    let with = pops.clone().with_repulsion(kappa.to_vec());
    for kind in [PressureKind::Paper, PressureKind::Interaction] {
        let params = ModelParams::paper(0.0).with_xi(1e200).with_pressure(kind);
        let term = PairRepulsion::new(&kappa, 2, LAMBDA, params.energy.kappa, kind);
        assert_eq!(params.energy.lambda, LAMBDA, "the energy's λ");
        let (r0, p0) = evaluate_in(&params, &cells, &pops, &[]);
        let (r1, p1) = evaluate_in(&params, &cells, &with, &[Some(&term)]);
        let change = |phi: &[f64]| {
            pair_repulsion_energy(&kappa, 2, pops.of_cell(), phi)
                - pair_repulsion_energy(&tissue, 2, pops.of_cell(), phi)
        };
        let phi = cells.phi().to_vec();
        let n = cells.n_cells();
        let (mut worst, mut largest): (f64, f64) = (0.0, 0.0);
        for i in 0..n {
            for node in [0, 37, 150, 211, 399] {
                let k = i * L * L + node;
                let h = 1e-2;
                let at = |t: f64| {
                    let mut v = phi.clone();
                    v[k] += t;
                    change(&v)
                };
                let fd = (8.0 * (at(h) - at(-h)) - (at(2.0 * h) - at(-2.0 * h))) / (12.0 * h);
                worst = worst.max((fd + (r1[k] - r0[k])).abs());
                largest = largest.max(fd.abs());
            }
        }
        assert!(largest > 1e-3, "the test fields have repulsion: {largest}");
        assert!(
            worst < 1e-9 * largest,
            "{kind:?}: {worst:e} off, of {largest:e}"
        );
        for node in 0..L * L {
            let expected: f64 = (0..n)
                .map(|i| {
                    let k = i * L * L + node;
                    let weight = match kind {
                        PressureKind::Paper => 1.0,
                        PressureKind::Interaction => phi[k],
                    };
                    weight * -(r1[k] - r0[k])
                })
                .sum();
            let got = p1[node] - p0[node];
            assert!(
                (got - expected).abs() < 1e-12,
                "{kind:?}: P at {node}: {got} against {expected}"
            );
        }
    }
}

/// With every `κ_pq` the tissue's κ, pair repulsion changes nothing but round-off: the
/// right-hand side and the pressure to 1e-13 of their scale, in both pressure forms.
#[test]
fn a_uniform_repulsion_matrix_is_the_tissue_kappa() {
    let (cells, pops) = random_cells();
    for kind in [PressureKind::Paper, PressureKind::Interaction] {
        let params = ModelParams::paper(0.0).with_xi(1e200).with_pressure(kind);
        let kappa = [params.energy.kappa; 4];
        let term = PairRepulsion::new(&kappa, 2, LAMBDA, params.energy.kappa, kind);
        let with = pops.clone().with_repulsion(kappa.to_vec());
        let (r0, p0) = evaluate_in(&params, &cells, &pops, &[]);
        let (r1, p1) = evaluate_in(&params, &cells, &with, &[Some(&term)]);
        let scale = r0.iter().map(|r| r.abs()).fold(0.0, f64::max);
        for (a, b) in r0.iter().zip(&r1) {
            assert!((a - b).abs() <= 1e-13 * scale, "{kind:?}: {a} against {b}");
        }
        let p_scale = p0.iter().map(|p| p.abs()).fold(0.0, f64::max);
        for (a, b) in p0.iter().zip(&p1) {
            assert!(
                (a - b).abs() <= 1e-13 * p_scale,
                "{kind:?}: P {a} against {b}"
            );
        }
    }
}

/// Population sums are independent of the thread count and add up to `s1` (and `s2`): with
/// five populations (two passes of the scatter for `s1_p`, three for `s1_p` with `s2_p`),
/// `Σ_p s1_p` is `s1` and `Σ_p s2_p` is `s2` to round-off on 1 and 2 threads, and the two
/// thread counts agree to the bit.
#[test]
fn population_sums_add_up_to_s1_and_s2_on_any_thread_count() {
    let (cells, _) = random_cells();
    let pop_of = [0usize, 4, 2, 4];
    for moments in [1, 2] {
        let fill = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut sums = PopulationSums::default();
                sums.fill(&cells, cells.phi(), 5, moments, |i| pop_of[i]);
                let get = |m: usize| {
                    (0..5)
                        .flat_map(|p| (0..L).map(move |x| (p, x)))
                        .map(|(p, x)| {
                            if m == 0 {
                                sums.column(p, x).to_vec()
                            } else {
                                sums.squares(p, x).to_vec()
                            }
                        })
                        .collect::<Vec<_>>()
                };
                (0..moments).map(get).collect::<Vec<_>>()
            })
        };
        let (one, two) = (fill(1), fill(2));
        assert_eq!(one, two, "thread counts agree");
        let phi = cells.phi();
        for (m, by_pop) in one.iter().enumerate() {
            for x in 0..L {
                for y in 0..L {
                    let s: f64 = (0..4)
                        .map(|i| phi[i * L * L + x * L + y].powi(m as i32 + 1))
                        .sum();
                    let sum: f64 = (0..5).map(|p| by_pop[p * L + x][y]).sum();
                    assert!((s - sum).abs() < 1e-14, "moment {m}: {s} against {sum}");
                }
            }
            // Population 1 and 3 have no cells.
            assert!(by_pop[L..2 * L].iter().flatten().all(|&v| v == 0.0));
        }
    }
}
