//! Forces, symmetries and the stepper.

use mechanics::{PressureKind, SumField, Tissue, Workspace};
use phasefield::Lattice;

use crate::strategies::{advance, confluent, discs, tissue, HEUN, ZETAS};

const PRESSURES: [PressureKind; 2] = [PressureKind::Paper, PressureKind::Interaction];

/// Runs the same scene and its image under a lattice symmetry `node_map`, and checks that the
/// image's fields, centres and velocities are the images of the original's.
fn check_symmetry(
    l: usize,
    centres: &[[f64; 2]],
    node_map: impl Fn(usize, usize) -> (usize, usize),
    point_map: impl Fn([f64; 2]) -> [f64; 2],
    vec_map: impl Fn([f64; 2]) -> [f64; 2],
    zeta: f64,
    pressure: PressureKind,
) -> (f64, f64, f64) {
    let image: Vec<[f64; 2]> = centres.iter().map(|&c| point_map(c)).collect();
    let (mut a, mut wa) = tissue(discs(l, 12, centres, 6.0), zeta, pressure);
    let (mut b, mut wb) = tissue(discs(l, 12, &image, 6.0), zeta, pressure);
    advance(&mut a, &mut wa, 40, &HEUN);
    advance(&mut b, &mut wb, 40, &HEUN);
    a.refresh(&mut wa);
    b.refresh(&mut wb);
    let (mut e_phi, mut e_c, mut e_v): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let lat = Lattice::new(l, l);
    for i in 0..centres.len() {
        for x in 0..l {
            for y in 0..l {
                let (xx, yy) = node_map(x, y);
                e_phi =
                    e_phi.max((a.cells().value_at(i, x, y) - b.cells().value_at(i, xx, yy)).abs());
            }
        }
        let ca = point_map(a.centres()[i]);
        e_c = e_c.max(lat.distance(ca, b.centres()[i]));
        let va = vec_map(wa.cell(i).velocity.into());
        let vb: [f64; 2] = wb.cell(i).velocity.into();
        e_v = e_v.max((va[0] - vb[0]).abs().max((va[1] - vb[1]).abs()));
    }
    (e_phi, e_c, e_v)
}

const L: usize = 64;
const CENTRES: [[f64; 2]; 4] = [[10.3, 20.6], [22.1, 14.2], [30.7, 40.4], [62.2, 1.3]];

/// The discretisation is covariant under lattice translations, the 90° rotation and mirrors,
/// so the image trajectory equals the image of the trajectory up to the round-off of
/// different summation orders (the centre of mass uses other cos/sin values): 1e-10.
#[test]
fn translated_rotated_and_mirrored_states_give_the_image_trajectory() {
    let lf = L as f64;
    let wrap = |v: f64| phasefield::wrap_real(v, lf);
    for &zeta in &[0.0, 0.01] {
        for pressure in PRESSURES {
            let (tx, ty) = (17, 41);
            let t = check_symmetry(
                L,
                &CENTRES,
                |x, y| ((x + tx) % L, (y + ty) % L),
                |c| [wrap(c[0] + tx as f64), wrap(c[1] + ty as f64)],
                |v| v,
                zeta,
                pressure,
            );
            let r = check_symmetry(
                L,
                &CENTRES,
                |x, y| ((L - y) % L, x),
                |c| [wrap(-c[1]), c[0]],
                |v| [-v[1], v[0]],
                zeta,
                pressure,
            );
            let m = check_symmetry(
                L,
                &CENTRES,
                |x, y| ((L - x) % L, y),
                |c| [wrap(-c[0]), c[1]],
                |v| [-v[0], v[1]],
                zeta,
                pressure,
            );
            for (name, (e_phi, e_c, e_v)) in [("translation", t), ("rotation", r), ("mirror", m)] {
                eprintln!("{name} zeta={zeta} {pressure:?}: phi {e_phi:.1e} centre {e_c:.1e} velocity {e_v:.1e}");
                assert!(
                    e_phi < 1e-10 && e_c < 1e-10 && e_v < 1e-10,
                    "{name}: {e_phi} {e_c} {e_v}"
                );
            }
        }
    }
}

/// An isolated cell feels no force in the continuum (docs/model.md §3), and none on the lattice
/// either, to round-off:
/// - with the interaction pressure `P = 0`, and the active force `ζ S Σ φ ∂φ` vanishes because
///   the central-difference sum `Σ φ(x)(φ(x+1) − φ(x−1))` telescopes on the periodic patch;
/// - with the paper's pressure the self terms are `φ`, `∇²φ` (both cancel exactly against
///   `∂φ`: the operators commute and one is antisymmetric) and the double well, which the
///   force excludes (see `mechanics::evaluate`). Before those two choices the cell moved at
///   |v| = 5e-4 (lattice ∇²s1 against the patch-periodic stencil) and 2e-7 (double well).
///
/// Tolerance: a force is a sum of ~600 terms of size ≤ 1e-2, so round-off is ≤ 1e-15; 1e-14.
/// Without advection, the Fourier centre still moves by 0.0067 nodes while the off-lattice
/// initial disc relaxes (measured); 0.01 bounds it. Roundness: |S| over the trace of the
/// structure tensor, 1.4e-10 measured, bounded by 1e-8.
#[test]
fn an_isolated_cell_stays_at_rest_and_round() {
    for &zeta in &ZETAS {
        for pressure in PRESSURES {
            let (mut t, mut ws) = tissue(discs(L, 12, &[[20.3, 40.7]], 8.0), zeta, pressure);
            advance(&mut t, &mut ws, 100, &HEUN);
            let c0 = t.centres()[0];
            let mut vmax: f64 = 0.0;
            for _ in 0..500 {
                t.step(&mut ws, &HEUN).unwrap();
                let v = ws.cell(0).velocity;
                vmax = vmax.max(v[0].hypot(v[1]));
            }
            let drift = Lattice::new(L, L).distance(c0, t.centres()[0]);
            let o = t.observe(&mut ws);
            // Roundness: |S| against the trace of the structure tensor, Σ|∇φ|²/2.
            let cells = t.cells();
            let mut trace = 0.0;
            phasefield::for_each_stencil(cells.cell_phi(0), cells.shape(), |_, s| {
                trace += 0.5 * (s.dx() * s.dx() + s.dy() * s.dy());
            });
            let anisotropy = o.s_rms / trace;
            eprintln!("isolated zeta={zeta} {pressure:?}: vmax {vmax:.2e} drift {drift:.2e} |S|/trace {anisotropy:.2e} area {:.2}", o.area_mean);
            assert!(vmax < 1e-14, "{vmax}");
            assert!(drift < 0.01, "{drift}");
            assert!(anisotropy < 1e-8, "{anisotropy}");
        }
    }
}

#[test]
fn two_overlapping_cells_move_apart_with_equal_and_opposite_velocities() {
    for &zeta in &ZETAS {
        for pressure in PRESSURES {
            // Mirror-symmetric about x = 46 (a node), so the balance is exact to round-off.
            let (mut t, mut ws) = tissue(
                discs(100, 12, &[[40.0, 50.0], [52.0, 50.0]], 8.0),
                zeta,
                pressure,
            );
            t.refresh(&mut ws);
            let (v0, v1) = (ws.cell(0).velocity, ws.cell(1).velocity);
            assert!(v0[0] < 0.0 && v1[0] > 0.0, "they must repel: {v0:?} {v1:?}");
            assert!((v0[0] + v1[0]).abs() < 1e-14 && v0[1].abs() < 1e-14 && v1[1].abs() < 1e-14);
            let d0 = t.centres()[1][0] - t.centres()[0][0];
            advance(&mut t, &mut ws, 50, &HEUN);
            assert!(t.centres()[1][0] - t.centres()[0][0] > d0);
            // A generic pair, on no symmetry axis: equal and opposite to the net-force bound.
            let (t2, mut ws2) = tissue(
                discs(100, 12, &[[40.3, 47.1], [51.2, 53.9]], 8.0),
                zeta,
                pressure,
            );
            t2.refresh(&mut ws2);
            let (f0, f1) = (ws2.cell(0).force, ws2.cell(1).force);
            let rel =
                (f0[0] + f1[0]).hypot(f0[1] + f1[1]) / (f0[0].hypot(f0[1]) + f1[0].hypot(f1[1]));
            eprintln!("pair zeta={zeta} {pressure:?}: |F0+F1|/(|F0|+|F1|) = {rel:.2e}");
            assert!(rel < 1e-2, "{rel}");
        }
    }
}

fn net_force_ratio(ws: &Workspace) -> f64 {
    let (mut sx, mut sy, mut sabs) = (0.0, 0.0, 0.0);
    for c in ws.cell_states() {
        sx += c.force[0];
        sy += c.force[1];
        sabs += c.force[0].hypot(c.force[1]);
    }
    sx.hypot(sy) / sabs
}

#[test]
fn net_force_vanishes_on_mirror_symmetric_clusters() {
    for &zeta in &ZETAS {
        for pressure in PRESSURES {
            // Symmetric under x -> 92 - x and y -> 92 - y.
            let c = [
                [40.0, 40.0],
                [52.0, 40.0],
                [40.0, 52.0],
                [52.0, 52.0],
                [46.0, 46.0],
            ];
            let (t, mut ws) = tissue(discs(100, 12, &c, 7.0), zeta, pressure);
            t.refresh(&mut ws);
            let r = net_force_ratio(&ws);
            assert!(r < 1e-13, "zeta={zeta} {pressure:?}: {r}");
        }
    }
}

/// What the discretisation guarantees, at round-off: summing `F_i` over cells gives
/// `Σ_i F_i = Σ_x [P ∇s1 + ζ Q·∇s1] − Σ_i Σ_x P_i^self ∇φ_i`, since central differences are
/// linear and in full-domain storage `Σ_i ∇φ_i = ∇s1` exactly. Checked on random confluent
/// states (seeds, ζ in [−0.01, 0.01], both pressures), with the right-hand side built here from
/// the lattice fields and the node-by-node stencil, independently of the kernels. No term is a
/// discrete gradient, so the sum itself is not zero (it is set by how far `s1` is from
/// uniform); only the identity is exact. Tolerance: `8 n ε` times the sum of the magnitudes of
/// the terms, `n` the number of terms (faer's convention for sums).
#[test]
fn net_force_is_the_lattice_sum_it_reduces_to() {
    use mechanics::equations::{force_density, pressure_self_part};
    use phasefield::{for_each_stencil, init, Cells, PatchShape};
    use proptest::prelude::*;
    use proptest::test_runner::{Config, TestRng, TestRunner};
    let config = Config {
        cases: 6,
        ..Config::default()
    };
    let rng = TestRng::deterministic_rng(config.rng_algorithm);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let strategy = (
        0u64..10_000,
        -0.01f64..0.01,
        prop_oneof![Just(PressureKind::Paper), Just(PressureKind::Interaction)],
    );
    const L: usize = 48;
    runner
        .run(&strategy, |(seed, zeta, pressure)| {
            let lattice = Lattice::new(L, L);
            let n = ((L * L) as f64 * 15.0 / 2500.0).round() as usize;
            let centres =
                init::positions(lattice, n, 4.0, &init::Layout::Random { seed }).unwrap();
            let full = PatchShape::new(lattice, 0).unwrap();
            let cells: Cells = init::discs(lattice, full, &centres, 4.0, 2.5);
            let (mut t, mut ws) = tissue(cells, 0.0, pressure);
            advance(&mut t, &mut ws, 60, &HEUN);
            t.params_mut().zeta = zeta;
            let f = t.fields(&mut ws);
            let coef = t.params().energy.coefficients();
            let mut s1 = vec![0.0; lattice.len()];
            for i in 0..t.n_cells() {
                t.cells().add_to_lattice(i, &mut s1);
            }
            let (mut rhs, mut scale, mut terms) = ([0.0f64; 2], 0.0f64, 0usize);
            for x in 0..L {
                for y in 0..L {
                    let k = lattice.index(x, y);
                    let at = |dx: usize, dy: usize| s1[lattice.index((x + dx) % L, (y + dy) % L)];
                    let grad = [
                        0.5 * (at(1, 0) - at(L - 1, 0)),
                        0.5 * (at(0, 1) - at(0, L - 1)),
                    ];
                    let d = force_density(f.pressure[k], zeta, [f.qxx[k], f.qxy[k]], grad);
                    rhs = [rhs[0] + d[0], rhs[1] + d[1]];
                    scale += d[0].abs() + d[1].abs();
                    terms += 1;
                }
            }
            for i in 0..t.n_cells() {
                for_each_stencil(t.cells().cell_phi(i), t.cells().shape(), |_, s| {
                    let p = pressure_self_part(pressure, &coef, s.c);
                    let d = [p * s.dx(), p * s.dy()];
                    rhs = [rhs[0] - d[0], rhs[1] - d[1]];
                    scale += d[0].abs() + d[1].abs();
                    terms += 1;
                });
            }
            let sum = ws.cell_states().iter().fold([0.0, 0.0], |a, c| [a[0] + c.force.x, a[1] + c.force.y]);
            let err = (sum[0] - rhs[0]).hypot(sum[1] - rhs[1]);
            let tol = 8.0 * terms as f64 * f64::EPSILON * scale;
            eprintln!("net force seed={seed} {pressure:?} zeta={zeta:.4}: |ΣF| {:.3e}, identity error {err:.1e} (tolerance {tol:.1e})", sum[0].hypot(sum[1]));
            prop_assert!(sum[0].hypot(sum[1]) > 1e3 * tol, "the test must not be vacuous");
            prop_assert!(err <= tol, "{} > {}", err, tol);
            Ok(())
        })
        .unwrap();
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let run = |threads: usize| -> Tissue {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (mut t, mut ws) = confluent(100, 4, 20, PressureKind::Paper);
            t.params_mut().zeta = 0.01;
            advance(&mut t, &mut ws, 20, &HEUN);
            t
        })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(
        a.cells().phi(),
        b.cells().phi(),
        "bit-for-bit identical fields"
    );
    assert_eq!(a.centres(), b.centres());
    // And with single-precision storage.
    let run32 = |threads: usize| -> Tissue<f32> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (t, _) = confluent(100, 4, 20, PressureKind::Paper);
            let mut t = Tissue::new(t.cells().to_precision::<f32>(), *t.params());
            let mut ws = Workspace::new(t.cells());
            t.params_mut().zeta = 0.01;
            advance(&mut t, &mut ws, 20, &HEUN);
            t
        })
    };
    let (a, b) = (run32(1), run32(2));
    assert_eq!(
        a.cells().phi(),
        b.cells().phi(),
        "bit-for-bit identical f32 fields"
    );
    assert_eq!(a.centres(), b.centres());
}

/// Single-precision storage rounds every stored value to 2⁻²⁴ ≈ 6e-8 relative; over 100
/// steps (20 TU at ζ = 0.01, before chaos separates trajectories) the rounding errors add up
/// to at most about 100 × 6e-8 = 6e-6 in φ if they never cancel. The f32 run must stay that
/// close to the f64 run from the same state, and must differ from it (it really is f32).
#[test]
fn single_precision_storage_tracks_double_precision() {
    for pressure in PRESSURES {
        let (mut a, mut wa) = confluent(100, 7, 20, pressure);
        let mut b = Tissue::new(a.cells().to_precision::<f32>(), *a.params());
        let mut wb = Workspace::new(b.cells());
        a.params_mut().zeta = 0.01;
        b.params_mut().zeta = 0.01;
        advance(&mut a, &mut wa, 100, &HEUN);
        advance(&mut b, &mut wb, 100, &HEUN);
        let lat = a.lattice();
        let mut e_phi: f64 = 0.0;
        let mut e_c: f64 = 0.0;
        for i in 0..a.cells().n_cells() {
            e_c = e_c.max(lat.distance(a.centres()[i], b.centres()[i]));
            for x in 0..lat.lx {
                for y in 0..lat.ly {
                    e_phi = e_phi
                        .max((a.cells().value_at(i, x, y) - b.cells().value_at(i, x, y)).abs());
                }
            }
        }
        eprintln!("{pressure:?}: f32 against f64 after 100 steps: φ {e_phi:.2e}, centre {e_c:.2e}");
        assert!(e_phi > 1e-9 && e_phi < 6e-6, "φ error {e_phi:e}");
        assert!(e_c > 0.0 && e_c < 6e-6, "centre error {e_c:e}");
    }
}

/// The lattice fields are the step's own sums: `Σ_x Q = Σ_i S_i Σ_x φ_i`,
/// `Σ_x v = Σ_i v_i Σ_x φ_i`, and the stress is `−P𝕀 − ζQ`, to round-off. The pressure the
/// force pass reads, computed once per node after the scatter, is the pressure formula of the
/// other sums at every node, bit for bit.
#[test]
fn lattice_fields_are_consistent_with_the_cells() {
    use mechanics::equations::pressure as pressure_of;
    for pressure in PRESSURES {
        let (mut t, mut ws) = confluent(100, 5, 100, pressure);
        t.params_mut().zeta = 0.007;
        let f = t.fields(&mut ws);
        let coef = t.params().energy.coefficients();
        let [s1, s2, u] = [SumField::S1, SumField::S2, SumField::U].map(|s| ws.sum_field(s));
        for k in 0..f.pressure.len() {
            let p = pressure_of(pressure, &coef, s1[k], s2[k], u[k]);
            assert_eq!(f.pressure[k].to_bits(), p.to_bits(), "node {k}");
        }
        assert!(f.pressure.iter().any(|&p| p != 0.0));
        let (mut qx, mut qy, mut vx, mut vy) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..t.cells().n_cells() {
            let mass: f64 = t.cells().cell_phi(i).iter().sum();
            let c = ws.cell(i);
            qx += c.shape.xx * mass;
            qy += c.shape.xy * mass;
            vx += c.velocity[0] * mass;
            vy += c.velocity[1] * mass;
        }
        let sum = |v: &[f64]| v.iter().sum::<f64>();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-10 * (a.abs() + b.abs() + 1e-300);
        assert!(close(sum(&f.qxx), qx) && close(sum(&f.qxy), qy));
        assert!(close(sum(&f.vx), vx) && close(sum(&f.vy), vy));
        for k in (0..f.pressure.len()).step_by(97) {
            assert_eq!(f.sigma_xx[k], -f.pressure[k] - 0.007 * f.qxx[k]);
            assert_eq!(f.sigma_yy[k], -f.pressure[k] + 0.007 * f.qxx[k]);
            assert_eq!(f.sigma_xy[k], -0.007 * f.qxy[k]);
        }
    }
}

/// Sorting the cells along the Morton curve reorders storage only: by identity, the centres,
/// velocities and fields after 30 steps equal those of the unsorted run to round-off (sums
/// over cells run in another order).
#[test]
fn sorting_the_cells_changes_storage_not_physics() {
    let (mut a, mut wa) = confluent(100, 6, 20, PressureKind::Paper);
    let mut b = a.clone();
    let mut wb = Workspace::new(b.cells());
    let mut scratch = Vec::new();
    b.sort_cells(&mut scratch);
    assert!(
        b.cell_ids().iter().enumerate().any(|(j, &id)| j != id),
        "random cells get reordered"
    );
    a.params_mut().zeta = 0.01;
    b.params_mut().zeta = 0.01;
    advance(&mut a, &mut wa, 30, &HEUN);
    advance(&mut b, &mut wb, 30, &HEUN);
    a.refresh(&mut wa);
    b.refresh(&mut wb);
    let slots = b.slots();
    let lat = a.lattice();
    for id in 0..a.cells().n_cells() {
        let s = slots[id];
        assert!(lat.distance(a.centres()[id], b.centres()[s]) < 1e-10);
        let (va, vb) = (wa.cell(id).velocity, wb.cell(s).velocity);
        assert!((va[0] - vb[0]).abs() < 1e-12 && (va[1] - vb[1]).abs() < 1e-12);
        for x in (0..lat.lx).step_by(3) {
            for y in 0..lat.ly {
                assert!((a.cells().value_at(id, x, y) - b.cells().value_at(s, x, y)).abs() < 1e-10);
            }
        }
    }
}

/// Inside the documented stable region (|ζ| ≤ 0.04, γ ≤ 0.04, κ ≤ 0.4, λ in [1.5, 4], and dt at
/// most the scene validator's estimate `max_stable_dt`, which `docs/stability.csv` measures to
/// be 1.1–3.2× below the real limit there), no step of a random confluent state fails or goes
/// non-finite over 40 TU.
#[test]
fn no_step_fails_inside_the_stable_region() {
    use mechanics::{ModelParams, StepParams};
    use proptest::prelude::*;
    use proptest::test_runner::{Config, TestRng, TestRunner};
    let config = Config {
        cases: 8,
        ..Config::default()
    };
    let rng = TestRng::deterministic_rng(config.rng_algorithm);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let strategy = (
        0.005f64..0.04,
        0.05f64..0.4,
        1.5f64..4.0,
        -0.04f64..0.04,
        0.1f64..1.0,
        0u64..1000,
        0usize..2,
    );
    runner
        .run(
            &strategy,
            |(gamma, kappa, lambda, zeta, dt_frac, seed, npc)| {
                let (t0, _) = confluent(64, seed, 100, PressureKind::Paper);
                let mut p = ModelParams::paper(zeta);
                p.energy.gamma = gamma;
                p.energy.kappa = kappa;
                p.energy.lambda = lambda;
                let dt = dt_frac * p.max_stable_dt();
                let mut t = Tissue::new(t0.cells().clone(), p);
                let mut ws = Workspace::new(t.cells());
                let sp = StepParams::new(dt, npc);
                for _ in 0..(40.0 / dt).ceil() as usize {
                    prop_assert!(
                        t.step(&mut ws, &sp).is_ok(),
                        "γ {} κ {} λ {} ζ {} dt {} npc {}",
                        gamma,
                        kappa,
                        lambda,
                        zeta,
                        dt,
                        npc
                    );
                }
                let o = t.observe(&mut ws);
                prop_assert!(o.v_rms.is_finite() && o.phi_min > -PHI && o.phi_max < 1.0 + PHI);
                Ok(())
            },
        )
        .unwrap();
}

const PHI: f64 = mechanics::PHI_BOUND;

/// The scatter leaves the stripes that no patch overlaps alone once they are zero. When the
/// cells then move elsewhere, a reused workspace must still hold exactly the sums of a fresh
/// one: the stripes they left are cleared, the ones they entered start from zero.
#[test]
fn a_reused_workspace_has_the_sums_of_a_fresh_one_after_cells_move() {
    let here = discs(160, 12, &[[20.0, 30.0], [34.0, 30.0]], 7.0);
    let there = discs(160, 12, &[[110.0, 150.0], [158.0, 10.0]], 7.0);
    let (a, mut ws) = tissue(here, 0.01, PressureKind::Paper);
    a.refresh(&mut ws);
    a.observe(&mut ws);
    let (b, mut fresh) = tissue(there, 0.01, PressureKind::Paper);
    b.refresh(&mut fresh);
    b.observe(&mut fresh);
    // The same workspace, now for the moved cells.
    let _ = b.observe(&mut ws);
    let sums = |w: &Workspace| SumField::ALL.map(|f| w.sum_field(f));
    assert!(sums(&ws).iter().flatten().any(|&v| v != 0.0));
    assert_eq!(sums(&ws), sums(&fresh), "lattice sums");
    assert_eq!(
        ws.velocity_field(),
        fresh.velocity_field(),
        "velocity field"
    );
    // Nodes far from every patch hold zeros.
    let lattice = b.lattice();
    let far = lattice.index(40, 80);
    assert!(SumField::ALL.iter().all(|&f| ws.sum(f, far) == 0.0));
}
