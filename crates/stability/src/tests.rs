//! Tests of the eigensolvers on matrices with known spectra, and of the whole method on the
//! smallest periodic packing (2 × 2 cells on 28 × 24 nodes), where a threshold takes seconds.

use std::sync::OnceLock;

use mechanics::{ModelParams, StepParams};

use crate::*;

/// A dense matrix as an [`Operator`], with τ = 1.
struct Dense {
    a: Vec<Vec<f64>>,
}

impl Operator for Dense {
    fn dim(&self) -> usize {
        self.a.len()
    }
    fn horizon(&self) -> f64 {
        1.0
    }
    fn apply(&mut self, v: &[f64], _eps: f64, out: &mut [f64]) -> Result<(), StabilityError> {
        for (o, row) in out.iter_mut().zip(&self.a) {
            *o = dot(row, v);
        }
        Ok(())
    }
}

/// An upper-triangular (so non-normal) 40 × 40 matrix with eigenvalues `0.9 − 0.02 k` on the
/// diagonal, except a 2 × 2 rotation block whose pair is `0.7 ± 0.2i`, and a coupling above.
fn known() -> Dense {
    let n = 40;
    let mut a = vec![vec![0.0; n]; n];
    for k in 0..n {
        a[k][k] = 0.9 - 0.02 * k as f64;
        for j in k + 1..n {
            a[k][j] = 0.05 * (((k * 7 + j * 3) % 11) as f64 / 11.0 - 0.5);
        }
    }
    // The block at rows 5, 6: [[0.7, −0.2], [0.2, 0.7]].
    a[5][5] = 0.7;
    a[6][6] = 0.7;
    a[5][6] = -0.2;
    a[6][5] = 0.2;
    Dense { a }
}

/// A full Krylov space holds the whole spectrum: Arnoldi recovers every eigenvalue, the complex
/// pair included, to round-off.
#[test]
fn arnoldi_recovers_a_known_spectrum() {
    let mut op = known();
    let s = arnoldi(
        &mut op,
        &ArnoldiOptions {
            krylov: 40,
            eps: 1.0,
            seed: 3,
        },
        None,
    )
    .unwrap();
    assert!((s.ritz[0].mu_re - 0.9).abs() < 1e-10, "{:?}", s.ritz[0]);
    assert!((s.sigma() - 0.9f64.ln()).abs() < 1e-10);
    let pair: Vec<&Ritz> = s.ritz.iter().filter(|r| r.mu_im.abs() > 1e-6).collect();
    assert_eq!(pair.len(), 2);
    for r in pair {
        assert!((r.mu_re - 0.7).abs() < 1e-10 && (r.mu_im.abs() - 0.2).abs() < 1e-10);
        assert!((r.omega.abs() - 0.2f64.atan2(0.7)).abs() < 1e-10);
    }
}

/// Fewer Krylov vectors than the dimension: the leading eigenvalue (gap 0.02 to the next)
/// converges, and its residual estimate bounds the error.
#[test]
fn a_short_krylov_space_finds_the_leading_eigenvalue() {
    let mut op = known();
    let s = arnoldi(
        &mut op,
        &ArnoldiOptions {
            krylov: 25,
            eps: 1.0,
            seed: 3,
        },
        None,
    )
    .unwrap();
    let err = (s.ritz[0].mu_re - 0.9).abs();
    assert!(err < 1e-6, "{:?}", s.ritz[0]);
    assert!(s.ritz[0].residual >= 0.1 * err);
}

/// Power iteration with several vectors converges to the leading eigenvalue; with one vector
/// it converges too, only more slowly (the gap is 0.02 of 0.9 per application).
#[test]
fn simultaneous_iteration_finds_the_leading_rate() {
    let exact = 0.9f64.ln();
    let mut op = known();
    let g4 = growth_rate(
        &mut op,
        &GrowthOptions {
            amplitude: 1.0,
            intervals: 200,
            vectors: 4,
            seed: 3,
        },
        None,
    )
    .unwrap();
    assert!((g4.sigma - exact).abs() < 1e-6, "{} vs {exact}", g4.sigma);
    assert!((g4.sigma - exact).abs() <= g4.sigma_err.max(1e-9) * 3.0 + 1e-9);
    let g1 = growth_rate(
        &mut op,
        &GrowthOptions {
            amplitude: 1.0,
            intervals: 200,
            vectors: 1,
            seed: 3,
        },
        None,
    )
    .unwrap();
    assert!((g1.sigma - exact).abs() < 1e-3, "{} vs {exact}", g1.sigma);
    // The direction found is the leading eigenvector e₀ (the matrix is upper triangular).
    assert!(g4.direction[0].abs() > 0.999, "{}", g4.direction[0]);
}

/// The rest state of the smallest packing, relaxed once for all tests.
fn tiny() -> &'static RestState {
    static REST: OnceLock<RestState> = OnceLock::new();
    REST.get_or_init(|| {
        let hex = HexBox::new(2, 2, 100.0 * 100.0 / 60.0).unwrap();
        let relax = Relaxation {
            margin: 11,
            ..Relaxation::default()
        };
        rest_state(&hex, &ModelParams::paper(0.0), &relax).unwrap()
    })
}

fn map_at(zeta: f64, dt: f64) -> StepMap {
    let steps = (50.0 / dt).round() as usize;
    StepMap::new(
        &tiny().tissue,
        &ModelParams::paper(zeta),
        StepParams::new(dt, 1),
        steps,
    )
    .unwrap()
}

#[test]
fn the_box_fits_the_packing() {
    let h = HexBox::new(6, 10, 100.0 * 100.0 / 60.0).unwrap();
    assert_eq!((h.lx, h.ly, h.n_cells()), (83, 120, 60));
    let [ax, ay] = h.spacings();
    assert!((ax - 83.0 / 6.0).abs() < 1e-12 && (ay - 24.0 / 3f64.sqrt()).abs() < 1e-12);
    assert!((h.anisotropy() - (ax / ay - 1.0)).abs() < 1e-15 && h.anisotropy().abs() < 2e-3);
    assert!(HexBox::new(6, 9, 166.0).is_err());
    // Tilings keep the spacings exactly; a box made afresh for 24 × 40 cells does not.
    for k in 1..=4 {
        let t = h.tiled(k);
        assert_eq!((t.lx, t.ly, t.n_cells()), (83 * k, 120 * k, 60 * k * k));
        assert_eq!(t.spacings(), h.spacings());
        assert_eq!(t.anisotropy(), h.anisotropy());
    }
    let fresh = HexBox::new(24, 40, 100.0 * 100.0 / 60.0).unwrap();
    assert_eq!((fresh.lx, fresh.ly), (333, 481));
    assert_ne!(fresh.anisotropy(), h.anisotropy());
}

/// The relaxation stops on its criterion, not its time limit.
#[test]
fn the_packing_relaxes_to_rest() {
    let r = tiny();
    assert!(
        r.phi_rate < Relaxation::default().phi_rate,
        "{}",
        r.phi_rate
    );
    assert!(r.time < Relaxation::default().max_time);
}

/// The forward difference is in its linear range: ε and ε/10 give the same `J v` to 1e-5 of
/// its norm (measured 4.5e-7: truncation O(ε) and round-off O(1e-16/ε) both far below).
#[test]
fn the_jacobian_vector_product_does_not_depend_on_epsilon() {
    let mut map = map_at(0.004, 0.5);
    let v = random_direction(&map, 5);
    let (mut a, mut b) = (vec![0.0; map.len()], vec![0.0; map.len()]);
    map.jvp(&v, 1e-5, &mut a).unwrap();
    map.jvp(&v, 1e-6, &mut b).unwrap();
    let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    assert!(norm(&d) < 1e-5 * norm(&a), "{} of {}", norm(&d), norm(&a));
}

/// Fixed points of Heun are those of the equations, and the slow modes are integrated far
/// inside Heun's accuracy: σ at dt 0.25 equals σ at dt 0.5 to 1e-7/TU (measured 6e-10 on the
/// 6 × 10 packing).
#[test]
fn the_growth_rate_does_not_depend_on_the_time_step() {
    let opts = ArnoldiOptions {
        krylov: 12,
        eps: 1e-5,
        seed: 1,
    };
    let a = arnoldi(&mut map_at(0.008, 0.5), &opts, None).unwrap();
    let b = arnoldi(&mut map_at(0.008, 0.25), &opts, None).unwrap();
    assert!(
        (a.sigma() - b.sigma()).abs() < 1e-7,
        "{} {}",
        a.sigma(),
        b.sigma()
    );
}

/// The two methods agree on the tiny packing (measured: 1.73504e-3 both at ζ = 0.008), the
/// rest state is stable at ζ = 0 and unstable at ζ = 0.008, and ζ_cr lies between.
#[test]
fn both_methods_find_the_same_threshold() {
    let mut map = map_at(0.008, 0.5);
    let a = arnoldi(
        &mut map,
        &ArnoldiOptions {
            krylov: 20,
            eps: 1e-5,
            seed: 1,
        },
        None,
    )
    .unwrap();
    let g = growth_rate(
        &mut map,
        &GrowthOptions {
            amplitude: 1e-4,
            intervals: 24,
            vectors: 4,
            seed: 2,
        },
        None,
    )
    .unwrap();
    assert!(a.sigma() > 0.0);
    let tol = 2.0 * (a.ritz[0].residual + g.sigma_err) + 1e-7;
    assert!(
        (a.sigma() - g.sigma).abs() < tol,
        "{} vs {}",
        a.sigma(),
        g.sigma
    );
    let t = threshold(
        &tiny().tissue,
        &ModelParams::paper(0.0),
        &Method::Arnoldi(ArnoldiOptions {
            krylov: 12,
            eps: 1e-5,
            seed: 1,
        }),
        &ThresholdOptions {
            step: StepParams::new(0.5, 1),
            steps: 100,
            lo: 0.0,
            hi: 0.008,
            tol: 1e-4,
            narrow: 2e-4,
        },
    )
    .unwrap();
    assert!(t.evaluations[0].sigma < 0.0 && t.evaluations[1].sigma > 0.0);
    assert!(t.zeta_cr > 0.004 && t.zeta_cr < 0.008, "{}", t.zeta_cr);
    // σ rises with ζ: the slope through the evaluations is positive.
    assert!(t.slope > 0.0);
}

/// The uniform translation is nearly neutral: pinned by the lattice, it decays at a rate far
/// below the shape modes' (measured −5.1e-4/TU against −2.8e-3 at ζ = 0), so projecting it out
/// removes a direction that would otherwise crowd the top of the spectrum near zero.
#[test]
fn the_translation_is_nearly_neutral() {
    let mut map = map_at(0.0, 0.5);
    let cells = tiny().tissue.cells();
    let shape = cells.shape();
    let (ny, len) = (shape.ny, shape.len());
    let phi = cells.phi();
    let mut t = vec![0.0; map.len()];
    for i in 0..cells.n_cells() {
        for a in 0..shape.nx {
            for b in 0..ny {
                t[i * len + a * ny + b] = 0.5
                    * (phi[i * len + shape.xp[a] * ny + b] - phi[i * len + shape.xm[a] * ny + b]);
            }
        }
    }
    let s = norm(&t);
    t.iter_mut().for_each(|x| *x /= s);
    let mut out = vec![0.0; map.len()];
    map.jvp(&t, 1e-5, &mut out).unwrap();
    let rate = norm(&out).ln() / map.horizon();
    assert!(rate.abs() < 1e-3, "{rate}");
    let mut p = t.clone();
    map.project(&mut p);
    assert!(norm(&p) < 1e-12, "the projection removes it: {}", norm(&p));
    // `translation_rates` measures the same mode's own component: within the norm's rate (the
    // Rayleigh quotient is at most the norm), and as small.
    let [sx, sy] = map.translation_rates(1e-5).unwrap();
    eprintln!("translation rates {sx:.3e} {sy:.3e}, norm rate {rate:.3e}");
    assert!(sx <= rate + 1e-9 && sx.abs() < 1e-3, "{sx} {rate}");
    assert!(sy.abs() < 1e-3, "{sy}");
}

/// The smallest packing's primitive cell, 2 × 2 cells on 28 × 24 nodes (the tiny box itself),
/// with its rest state laid on copies.
fn tiny_tiling() -> BlochTiling {
    BlochTiling {
        primitive: HexBox::new(2, 2, 100.0 * 100.0 / 60.0).unwrap(),
        reps: [1, 1],
        rest: tiny().clone(),
    }
}

/// A box of n × m primitive cells is the Bloch waves it allows: the box's leading growth rates
/// (Arnoldi on the whole 56 × 24 box, 8 cells) are those of the Bloch maps at q = (0, 0) and
/// (½, 0), each on one primitive cell, within the Ritz residuals (measured: 1.73504e-3 and
/// −3.45204e-3 both ways, differences below 1e-9).
#[test]
fn bloch_waves_make_up_the_box_spectrum() {
    let tiling = tiny_tiling();
    let p = ModelParams::paper(0.008);
    let step = StepParams::new(0.5, 1);
    let opts = ArnoldiOptions {
        krylov: 30,
        eps: 1e-5,
        seed: 1,
    };
    let boxed = tiling.supercell([2, 1], &p).unwrap();
    let whole = arnoldi(
        &mut StepMap::new(&boxed, &p, step, 100).unwrap(),
        &opts,
        None,
    )
    .unwrap();
    let qs = box_wavevectors([2, 1]);
    assert_eq!(qs, vec![[0.0, 0.0], [0.5, 0.0]]);
    let sectors: Vec<Spectrum> = qs
        .iter()
        .map(|&q| {
            let mut m = BlochMap::new(&tiling, &p, step, 100, [2, 1], q).unwrap();
            arnoldi(&mut m, &ArnoldiOptions { krylov: 20, ..opts }, None).unwrap()
        })
        .collect();
    // The box's three leading distinct rates, each found in a sector.
    let mut checked = 0;
    for r in whole.ritz.iter().filter(|r| r.residual < 1e-6).take(4) {
        let tol = 1e-7 + 2.0 * r.residual;
        let found = sectors
            .iter()
            .flat_map(|s| &s.ritz)
            .filter(|b| b.residual < 1e-6)
            .any(|b| (b.sigma - r.sigma).abs() < tol);
        assert!(found, "box rate {} in no sector: {sectors:?}", r.sigma);
        checked += 1;
    }
    assert!(checked >= 3, "{whole:?}");
    let lead = sectors.iter().map(Spectrum::sigma).fold(f64::MIN, f64::max);
    assert!(
        (lead - whole.sigma()).abs() < 1e-7,
        "{lead} {}",
        whole.sigma()
    );
}

/// A Bloch wave that no supercell fits exactly gives the same step on any supercell whose
/// copies read are beyond a step's reach from its edge: at q = (0.3, 0.3) the supercell
/// `supercell_for` picks (4 × 4 primitive cells, copies read 42 and 36 nodes from the edge
/// against a reach of 33) and a larger one (6 × 6) agree to 1e-6 (measured 3e-8, the forward
/// difference's own error); on 3 × 1 the edge is within reach and they do not (measured 1e-2).
#[test]
fn a_bloch_wave_does_not_depend_on_the_supercell() {
    let tiling = tiny_tiling();
    let p = ModelParams::paper(0.008);
    let step = StepParams::new(0.5, 1);
    let q = [0.3, 0.3];
    assert_eq!(tiling.reach(), 33);
    assert_eq!(tiling.supercell_for(q), [4, 4]);
    assert_eq!(tiling.supercell_for([0.5, 0.25]), [2, 4]);
    assert_eq!(tiling.supercell_for([0.0, 0.0]), [1, 1]);
    let mut large = BlochMap::new(&tiling, &p, step, 1, [6, 6], q).unwrap();
    let v = random_direction(&large, 7);
    let mut a = vec![0.0; v.len()];
    large.apply(&v, 1e-5, &mut a).unwrap();
    let differ = |reps: [usize; 2]| {
        let mut m = BlochMap::new(&tiling, &p, step, 1, reps, q).unwrap();
        let mut b = vec![0.0; v.len()];
        m.apply(&v, 1e-5, &mut b).unwrap();
        let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
        norm(&d) / norm(&a)
    };
    let far = differ(tiling.supercell_for(q));
    let near = differ([3, 1]);
    eprintln!("far {far:.1e} near {near:.1e}");
    assert!(far < 1e-6, "{far}");
    assert!(near > 1e-4, "the edge within reach must show: {near}");
}

/// The relaxed box is periodic with the primitive cell to round-off, and its supercells copy it
/// exactly.
#[test]
fn the_tiling_is_periodic() {
    let tiling = tiny_tiling();
    assert!(tiling.asymmetry() < 1e-12, "{}", tiling.asymmetry());
    let s = tiling.supercell([3, 2], &ModelParams::paper(0.0)).unwrap();
    assert_eq!(s.cells().n_cells(), 4 * 6);
    let n = s.cells().patch_len();
    let phi = s.cells().phi();
    for j in 0..s.cells().n_cells() {
        let p = (j / 6 % 2) * 6 + j % 2;
        assert_eq!(phi[j * n..(j + 1) * n], phi[p * n..(p + 1) * n]);
    }
    assert_eq!(box_wavevectors([1, 5]).len(), 3);
    assert_eq!(box_wavevectors([2, 2]).len(), 4);
}
