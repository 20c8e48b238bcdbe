//! Friction between cells (docs/model.md §11.8, issue 49): overlapping cells drag each other,
//!
//! ```text
//! ξ_i v_i = F_i + f_i − ξ_c Σ_j o_ij (v_i − v_j),     o_ij = Σ_x φ_i φ_j
//! ```
//!
//! with `ξ_i` the cell's own drag (the substrate's, and a wall's), `F_i + f_i` the interface
//! force and the terms' whole-cell forces, and `o_ij` the overlap of cells i and j. The system
//! `(D + ξ_c L) v = F + f`, with `D = diag(ξ_i)` and `L` the graph Laplacian of the overlaps,
//! is symmetric and positive definite (`L` is positive semidefinite for `o_ij ≥ 0`, `D` positive);
//! it is solved at every evaluation by conjugate gradients with the Jacobi preconditioner, for
//! x and y alike, from `v = (F + f)/ξ_i`, to a relative residual `‖b − A v‖ ≤ tol ‖b‖`.
//!
//! The overlaps are summed over the intersection of the two patches, for every pair of cells
//! whose patches intersect, each pair in a fixed order: the result does not depend on the
//! threads. The friction forces sum to zero (`L`'s columns do). Then each cell's right-hand side
//! is corrected for its new velocity, `R_i −= (v_i − v_i⁰)·∇φ_i` (central differences, zero
//! beyond the patch as in the force pass), so the step is not fused with its predictor and
//! corrector updates while friction is on.

use phasefield::{Cells, Real};
use rayon::prelude::*;

use crate::evaluation::CellState;

/// Friction between overlapping cells (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CellFriction {
    /// `ξ_c`, the friction per unit of overlap `o_ij = Σ_x φ_i φ_j`.
    pub xi_c: f64,
    /// The conjugate gradients' relative residual (default 1e-10).
    pub tolerance: f64,
}

impl CellFriction {
    /// Friction `xi_c` between cells, solved to a relative residual of 1e-10.
    pub fn new(xi_c: f64) -> Self {
        Self {
            xi_c,
            tolerance: 1e-10,
        }
    }

    /// With the solver's relative residual `tolerance`.
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// Its scene keys and values, for a backend to compare with what it implements.
    pub(crate) fn settings(&self) -> Vec<(String, String)> {
        let CellFriction { xi_c, tolerance } = self;
        vec![
            ("[friction] cells".into(), xi_c.to_string()),
            ("[friction] tolerance".into(), tolerance.to_string()),
        ]
    }
}

/// What the last solve did: the conjugate gradients' iterations (the larger of x's and y's)
/// and the relative residual reached (the larger of the two).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrictionSolve {
    /// Iterations.
    pub iterations: usize,
    /// `‖b − A v‖ / ‖b‖` at the end.
    pub residual: f64,
}

/// The overlaps `o_ij = Σ_x φ_i φ_j` of every pair `i < j` of slots whose patches intersect,
/// into `out` in order of `i` then `j` (negative sums, from the fields' undershoot where two
/// cells barely touch, are kept at zero so that `L` stays semidefinite).
pub fn pair_overlaps<T: Real>(cells: &Cells<T>, out: &mut Vec<(u32, u32, f64)>) {
    let n = cells.n_cells();
    let lattice = cells.lattice();
    let (lx, ly) = (lattice.lx, lattice.ly);
    let shape = cells.shape();
    let (nx, ny) = (shape.nx, shape.ny);
    let map = cells.map();
    let phi = cells.phi();
    let plen = shape.len();
    // The patches' shared columns (or rows) as runs contiguous in both storages, `(s_i, s_j,
    // len)`, when j's patch starts `d` nodes after i's on a periodic axis of length `l`, with
    // `w` nodes per patch stored from the offsets `f_i`, `f_j` (logical `u` is stored at
    // `(u + f) mod w`): so that the inner loop is a dot product of two slices.
    let shared = |d: usize,
                  w: usize,
                  l: usize,
                  fi: usize,
                  fj: usize,
                  out: &mut Vec<(usize, usize, usize)>| {
        out.clear();
        for u in 0..w {
            let v = if u >= d { u - d } else { u + l - d };
            if v < w {
                let si = if u + fi >= w { u + fi - w } else { u + fi };
                let sj = if v + fj >= w { v + fj - w } else { v + fj };
                match out.last_mut() {
                    Some((a, b, len)) if *a + *len == si && *b + *len == sj => *len += 1,
                    _ => out.push((si, sj, 1)),
                }
            }
        }
    };
    let per_cell: Vec<Vec<(u32, u32, f64)>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let [oxi, oyi] = map.origin[i];
            let [fxi, fyi] = map.offset[i];
            let ci = &phi[i * plen..(i + 1) * plen];
            let mut mine = Vec::new();
            let (mut cols, mut rows) = (Vec::with_capacity(nx), Vec::with_capacity(ny));
            for j in i + 1..n {
                let [oxj, oyj] = map.origin[j];
                // (Without divisions: this test runs for every pair of cells.)
                let dx = if oxj >= oxi {
                    oxj - oxi
                } else {
                    oxj + lx - oxi
                };
                let dy = if oyj >= oyi {
                    oyj - oyi
                } else {
                    oyj + ly - oyi
                };
                let near = |d: usize, w: usize, l: usize| d < w || d + w > l;
                if !(near(dx, nx, lx) && near(dy, ny, ly)) {
                    continue;
                }
                let [fxj, fyj] = map.offset[j];
                let cj = &phi[j * plen..(j + 1) * plen];
                shared(dx, nx, lx, fxi, fxj, &mut cols);
                shared(dy, ny, ly, fyi, fyj, &mut rows);
                let mut o = 0.0;
                for &(ai, aj, ncols) in &cols {
                    for c in 0..ncols {
                        let coli = &ci[(ai + c) * ny..(ai + c + 1) * ny];
                        let colj = &cj[(aj + c) * ny..(aj + c + 1) * ny];
                        for &(bi, bj, len) in &rows {
                            let (x, y) = (&coli[bi..bi + len], &colj[bj..bj + len]);
                            o += x
                                .iter()
                                .zip(y)
                                .map(|(a, b)| a.to_f64() * b.to_f64())
                                .sum::<f64>();
                        }
                    }
                }
                if o > 0.0 {
                    mine.push((i as u32, j as u32, o));
                }
            }
            mine
        })
        .collect();
    out.clear();
    out.extend(per_cell.into_iter().flatten());
}

/// `A v` of the friction system: `(ξ_i + ξ_c Σ_j o_ij) v_i − ξ_c Σ_j o_ij v_j`.
fn apply(drag: &[f64], pairs: &[(u32, u32, f64)], xi_c: f64, v: &[f64], out: &mut [f64]) {
    for ((o, d), v) in out.iter_mut().zip(drag).zip(v) {
        *o = d * v;
    }
    for &(i, j, w) in pairs {
        let (i, j) = (i as usize, j as usize);
        let f = xi_c * w * (v[i] - v[j]);
        out[i] += f;
        out[j] -= f;
    }
}

/// Solves `A v = b` for one component by Jacobi-preconditioned conjugate gradients from the
/// guess in `v`, to `‖b − A v‖ ≤ tol ‖b‖` or 1000 iterations: `(iterations, ‖r‖/‖b‖)`.
fn cg(
    drag: &[f64],
    pairs: &[(u32, u32, f64)],
    xi_c: f64,
    b: &[f64],
    v: &mut [f64],
    tol: f64,
) -> (usize, f64) {
    let n = b.len();
    let mut diag = drag.to_vec();
    for &(i, j, w) in pairs {
        diag[i as usize] += xi_c * w;
        diag[j as usize] += xi_c * w;
    }
    let dot = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
    let norm_b = dot(b, b).sqrt();
    if norm_b == 0.0 {
        v.fill(0.0);
        return (0, 0.0);
    }
    let mut r = vec![0.0; n];
    apply(drag, pairs, xi_c, v, &mut r);
    for (r, b) in r.iter_mut().zip(b) {
        *r = b - *r;
    }
    let mut z: Vec<f64> = r.iter().zip(&diag).map(|(r, d)| r / d).collect();
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut ap = vec![0.0; n];
    for k in 0..1000 {
        let res = dot(&r, &r).sqrt() / norm_b;
        if res <= tol {
            return (k, res);
        }
        apply(drag, pairs, xi_c, &p, &mut ap);
        let alpha = rz / dot(&p, &ap);
        for ((v, r), (p, ap)) in v.iter_mut().zip(r.iter_mut()).zip(p.iter().zip(&ap)) {
            *v += alpha * p;
            *r -= alpha * ap;
        }
        for ((z, r), d) in z.iter_mut().zip(&r).zip(&diag) {
            *z = r / d;
        }
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for (p, z) in p.iter_mut().zip(&z) {
            *p = z + beta * *p;
        }
    }
    (1000, dot(&r, &r).sqrt() / norm_b)
}

/// Solves the friction system for every cell's velocity (`cell_state`'s `force`, `cell_force`
/// and `drag` give `b` and `D`; its `velocity`, `(F + f)/ξ_i`, is the first guess and is
/// overwritten), with the overlaps `pairs`.
pub fn solve(
    cell_state: &mut [CellState],
    pairs: &[(u32, u32, f64)],
    friction: &CellFriction,
) -> FrictionSolve {
    let drag: Vec<f64> = cell_state.iter().map(|s| s.drag).collect();
    let mut out = FrictionSolve::default();
    for axis in 0..2 {
        let b: Vec<f64> = cell_state
            .iter()
            .map(|s| s.force[axis] + s.cell_force[axis])
            .collect();
        let mut v: Vec<f64> = cell_state.iter().map(|s| s.velocity[axis]).collect();
        let (k, res) = cg(&drag, pairs, friction.xi_c, &b, &mut v, friction.tolerance);
        out.iterations = out.iterations.max(k);
        out.residual = out.residual.max(res);
        for (s, v) in cell_state.iter_mut().zip(v) {
            s.velocity[axis] = v;
        }
    }
    out
}

/// The friction force on each cell, `−ξ_c Σ_j o_ij (v_i − v_j)`, from the overlaps `pairs`
/// and the velocities of `cell_state`: each pair's force added to one cell and taken from the
/// other, so they sum to zero to round-off.
pub fn forces(pairs: &[(u32, u32, f64)], xi_c: f64, cell_state: &[CellState]) -> Vec<[f64; 2]> {
    let mut out = vec![[0.0; 2]; cell_state.len()];
    for &(i, j, w) in pairs {
        let (i, j) = (i as usize, j as usize);
        let dv = cell_state[i].velocity - cell_state[j].velocity;
        let f = [xi_c * w * dv.x, xi_c * w * dv.y];
        out[i] = [out[i][0] - f[0], out[i][1] - f[1]];
        out[j] = [out[j][0] + f[0], out[j][1] + f[1]];
    }
    out
}

/// Corrects each cell's right-hand side `rhs` for the change of its velocity from `before`
/// to `cell_state`'s: `R_i −= (v_i − v_i⁰)·∇φ_i`, with central differences on the patch,
/// periodic in its storage indices as the force pass's stencil is.
pub(crate) fn correct_rhs<T: Real>(
    cells: &Cells<T>,
    rhs: &mut [T],
    before: &[[f64; 2]],
    cell_state: &[CellState],
) {
    let shape = cells.shape();
    let plen = shape.len();
    rhs.par_chunks_mut(plen)
        .zip(cells.phi().par_chunks(plen))
        .enumerate()
        .for_each(|(i, (out, phi))| {
            let dv = [
                cell_state[i].velocity.x - before[i][0],
                cell_state[i].velocity.y - before[i][1],
            ];
            if dv == [0.0, 0.0] {
                return;
            }
            // The patch is periodic in its storage indices, as the force pass's stencil is.
            phasefield::for_each_stencil(phi, shape, |k, s| {
                out[k] = T::from_f64(out[k].to_f64() - (dv[0] * s.dx() + dv[1] * s.dy()));
            });
        });
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};
    use phasefield::{init, Lattice, PatchShape};

    use super::*;
    use crate::terms::{CellContext, CellTerm, Terms};
    use crate::{ModelParams, StepParams, Tissue, Workspace};

    /// Pulls cell 0 along −x and cell 1 along +x with `G`: a doublet dragged apart.
    #[derive(Debug)]
    struct Apart(f64);

    impl CellTerm for Apart {
        fn name(&self) -> &str {
            "apart"
        }
        fn force(&self, cell: &CellContext<'_>, _: &[f64]) -> [f64; 2] {
            if cell.id == 0 {
                [-self.0, 0.0]
            } else {
                [self.0, 0.0]
            }
        }
    }

    /// Two cells of R = 8 whose centres are 14 apart on 64 × 48, relaxed at rest for 40 TU
    /// into a doublet, with the terms `terms`.
    fn doublet(terms: Terms) -> (Tissue, Workspace) {
        let lattice = Lattice::new(64, 48);
        let shape = PatchShape::new(lattice, 12).unwrap();
        let cells = init::discs(lattice, shape, &[[25.0, 24.0], [39.0, 24.0]], 8.0, 2.5);
        let mut t = Tissue::new(cells, ModelParams::paper(0.0)).with(terms);
        let mut ws = Workspace::new(t.cells());
        t.set_active(false);
        for _ in 0..80 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        t.set_active(true);
        (t, ws)
    }

    /// The overlap `Σ_x φ_0 φ_1` summed on the whole lattice, independently of the patches.
    fn lattice_overlap(t: &Tissue) -> f64 {
        let n = t.lattice().len();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        t.cells().add_to_lattice(0, &mut a);
        t.cells().add_to_lattice(1, &mut b);
        a.iter().zip(&b).map(|(x, y)| x * y).sum()
    }

    /// Two overlapping cells dragged apart by `±G` slow each other as the closed form says:
    /// by symmetry `v_1 = −v_0`, so `ξ v_1 = F_1 + G − 2 ξ_c o v_1`, `v_1 = (F_1 + G)/(ξ + 2 ξ_c
    /// o)`, with `F_1` the interface force and `o` the overlap summed on the lattice. Measured
    /// to 1e-9 of `v_1` (the solve's tolerance is 1e-10); the separation is slower than
    /// without friction by the factor `ξ/(ξ + 2 ξ_c o)`.
    #[test]
    fn a_doublet_dragged_apart_slows_as_the_closed_form_says() {
        let (g, xi_c) = (0.02, 0.05);
        let (t, mut ws) = doublet(Terms::new(1).with(Apart(g)));
        let free = {
            t.refresh(&mut ws);
            ws.cell_states()[t.cell_ids().iter().position(|&i| i == 1).unwrap()]
                .velocity
                .x
        };
        let t = t.with(CellFriction::new(xi_c));
        t.refresh(&mut ws);
        let slot = t.cell_ids().iter().position(|&i| i == 1).unwrap();
        let s = ws.cell_states()[slot];
        let o = lattice_overlap(&t);
        assert!(o > 1.0, "the cells overlap: {o}");
        let xi = t.params().xi;
        let expected = (s.force.x + g) / (xi + 2.0 * xi_c * o);
        eprintln!(
            "v_1 = {:e}, closed form {expected:e}, without friction {free:e}, o = {o}",
            s.velocity.x
        );
        assert!((s.velocity.x / expected - 1.0).abs() < 1e-9);
        assert!(s.velocity.x > 0.0 && s.velocity.x < free);
        let other = ws.cell_states()[1 - slot].velocity.x;
        assert!((other + s.velocity.x).abs() < 1e-9 * s.velocity.x.abs());
    }

    /// The pressed four cells with ζ and friction: the friction forces (`forces`) sum to zero
    /// (1e-14 of their largest), balance each cell's `ξ_i v_i − (F_i + f_i)` to the solve's
    /// tolerance (1e-12 of the largest `|F_i + f_i|`), the solve stops below its tolerance,
    /// and a step is the same on one thread and two, to the bit.
    #[test]
    fn friction_forces_sum_to_zero_and_the_solve_converges() {
        let lattice = Lattice::new(48, 48);
        let shape = PatchShape::new(lattice, 10).unwrap();
        let centres = [[12.0, 12.0], [25.0, 14.0], [18.0, 30.0], [34.0, 34.0]];
        let cells = init::discs(lattice, shape, &centres, 7.0, 2.5);
        let fr = CellFriction::new(0.3).with_tolerance(1e-12);
        let mut t = Tissue::new(cells, ModelParams::paper(0.01)).with(fr);
        let mut ws = Workspace::new(t.cells());
        for _ in 0..40 {
            t.step(&mut ws, &StepParams::default()).unwrap();
        }
        t.refresh(&mut ws);
        let f = forces(&ws.term_scratch.friction.pairs, 0.3, ws.cell_states());
        let largest = f.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let sum = f.iter().fold([0.0; 2], |a, v| [a[0] + v[0], a[1] + v[1]]);
        eprintln!("friction forces {f:?}, sum {sum:?}");
        assert!(largest > 1e-6, "friction acts: {largest:e}");
        assert!(sum[0].abs() < 1e-14 * largest && sum[1].abs() < 1e-14 * largest);
        let b = ws
            .cell_states()
            .iter()
            .map(|s| (s.force + s.cell_force).norm())
            .fold(0.0, f64::max);
        for (s, f) in ws.cell_states().iter().zip(&f) {
            let balance =
                s.drag * s.velocity - s.force - s.cell_force - nalgebra::Vector2::from(*f);
            assert!(balance.norm() < 1e-12 * b, "{balance:?}");
        }
        let solve = ws.term_scratch.friction.solve;
        assert!(solve.iterations > 0 && solve.residual <= 1e-12, "{solve:?}");
        let step = |threads: usize| {
            let mut t = t.clone();
            let mut ws = Workspace::new(t.cells());
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    for _ in 0..5 {
                        t.step(&mut ws, &StepParams::default()).unwrap();
                    }
                });
            t.cells().phi().to_vec()
        };
        assert!(step(1) == step(2), "the thread count changes the step");
    }

    /// Friction with `ξ_c = 0` steps as no friction, to the bit: its solve starts at the
    /// answer and changes nothing, and the separate sweeps it takes are the fused step's
    /// (`step.rs` tests that too).
    #[test]
    fn zero_friction_is_no_friction_to_the_bit() {
        let (t, _) = doublet(Terms::new(1).with(Apart(0.01)));
        let run = |t: &Tissue| {
            let mut t = t.clone();
            let mut ws = Workspace::new(t.cells());
            for _ in 0..20 {
                t.step(&mut ws, &StepParams::default()).unwrap();
            }
            t.cells().phi().to_vec()
        };
        assert!(run(&t) == run(&t.clone().with(CellFriction::new(0.0))));
    }

    /// The conjugate gradients against a dense solve (nalgebra's LU) of a random system of
    /// 30 cells with 60 overlaps: the residual is below the tolerance asked (1e-12) and the
    /// solution agrees to 1e-10.
    #[test]
    fn the_solver_reaches_its_tolerance() {
        let n = 30;
        let mut state = 12345u64;
        let mut rand = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pairs = Vec::new();
        for _ in 0..60 {
            let i = (rand() * n as f64) as u32;
            let j = (rand() * n as f64) as u32;
            if i < j {
                pairs.push((i, j, 20.0 * rand()));
            }
        }
        let drag: Vec<f64> = (0..n).map(|_| 1.0 + rand()).collect();
        let b: Vec<f64> = (0..n).map(|_| rand() - 0.5).collect();
        let xi_c = 0.4;
        let mut a = DMatrix::from_diagonal(&DVector::from_vec(drag.clone()));
        for &(i, j, w) in &pairs {
            let (i, j) = (i as usize, j as usize);
            a[(i, i)] += xi_c * w;
            a[(j, j)] += xi_c * w;
            a[(i, j)] -= xi_c * w;
            a[(j, i)] -= xi_c * w;
        }
        let dense = a.lu().solve(&DVector::from_vec(b.clone())).unwrap();
        let mut v: Vec<f64> = b.iter().zip(&drag).map(|(b, d)| b / d).collect();
        let (k, res) = cg(&drag, &pairs, xi_c, &b, &mut v, 1e-12);
        eprintln!("{k} iterations, residual {res:e}");
        assert!(res <= 1e-12 && k < 200);
        for (x, y) in v.iter().zip(dense.iter()) {
            assert!((x - y).abs() < 1e-10, "{x} against {y}");
        }
    }

    /// The right-hand side's correction is the advection of the velocity's change: an
    /// evaluation without a force, corrected to the velocity `v + G/ξ`, is the evaluation with
    /// the whole-cell force `G` (which moves the cell at that velocity), to 1e-15 of the
    /// right-hand side's largest value, node by node, patches' edges included (the stencil
    /// wraps there as the force pass's does; a zero beyond the edge was 3 % off).
    #[test]
    fn the_correction_is_the_advection_of_the_change() {
        let g = 0.03;
        let (plain, mut ws) = doublet(Terms::new(1).with(Apart(0.0)));
        plain.refresh(&mut ws);
        let mut k = ws.k2.clone();
        let before: Vec<[f64; 2]> = ws
            .cell_states()
            .iter()
            .map(|s| [s.velocity.x, s.velocity.y])
            .collect();
        let pulled = plain.clone().with(Terms::new(1).with(Apart(g)));
        let mut ws2 = Workspace::new(pulled.cells());
        pulled.refresh(&mut ws2);
        correct_rhs(pulled.cells(), &mut k, &before, ws2.cell_states());
        let largest = ws2.k2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = k
            .iter()
            .zip(&ws2.k2)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(worst < 1e-15 * largest.max(1.0), "{worst:e} of {largest:e}");
    }
}
