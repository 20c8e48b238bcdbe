//! The state of a monolayer ([`Tissue`]), its scratch memory ([`Workspace`]) and the time step.
//!
//! One evaluation of the right-hand side `R(φ)` (MODEL.md §3–4) runs three passes:
//! 1. per cell, in parallel: area `A_i = Σ φ_i²` and deformation tensor `S_i`;
//! 2. scatter onto the lattice, stripe-parallel in cell order: `s1, s2`, the part `U` of the
//!    pressure that is a sum of single-cell terms, `Q_xx, Q_xy` (see [`pressure`]);
//! 3. per cell, in parallel: the force `F_i = Σ_x [(P − P_i^self) ∇φ_i + ζ Q·∇φ_i]` (see
//!    [`evaluate`] for the self term), the velocity
//!    `v_i = F_i/ξ`, then `R_i = −v_i·∇φ_i − δF/δφ_i` on the same patch while it is in cache.

use phasefield::{
    add_lanes, for_each_run_in_column, Cells, ComTable, Lattice, Real, RowRuns, Stencil, LANES,
};
use rayon::prelude::*;

use crate::params::{ModelParams, PressureKind, StepParams};
use crate::scatter::{scatter, LatticeSums};
use crate::StepError;

/// Fields of the global (lattice-wide) sums.
pub const N_GLOBAL: usize = 5;
/// Index of the field `s1 = Σ φ_i` in the global sums.
pub const G_S1: usize = 0;
/// Index of `s2 = Σ φ_i²`.
pub const G_S2: usize = 1;
/// Index of `U`, the part of the pressure that is linear in the cells' contributions:
/// `P = (2κ/λ) s1 s2 + U` (paper) or `P = (2κ/λ) s2² + U` (interaction); see [`pressure`].
pub const G_U: usize = 2;
/// Index of `Q_xx = Σ φ_i S_i,xx`.
pub const G_QXX: usize = 3;
/// Index of `Q_xy = Σ φ_i S_i,xy`.
pub const G_QXY: usize = 4;

/// The pressure at a node from its global sums `s1`, `s2` and `U` (MODEL.md §3).
///
/// Paper: `P = (2κ/λ)(s1 s2 − s3) − (8γ/λ)(s1 − 3 s2 + 2 s3) + 2γλ Σ_i ∇²φ_i
/// + (4μ/πR²)(s1 − sA/πR²)`, of which every term but `(2κ/λ) s1 s2` is a sum over cells of a
/// function of `φ_i` alone; the scatter adds those into `U`. The Laplacians are taken on each
/// cell's periodic patch: on the full domain this is `∇² s1`, and on patches it is the form
/// whose self term `Σ_x ∇²φ_i ∂φ_i` vanishes exactly, so that an isolated cell feels no force.
/// Interaction: `P = (2κ/λ)(s2² − s4)`, with `U = −(2κ/λ) s4`.
#[inline(always)]
pub fn pressure(kind: PressureKind, repulsion: f64, s1: f64, s2: f64, u: f64) -> f64 {
    match kind {
        PressureKind::Paper => repulsion * s1 * s2 + u,
        PressureKind::Interaction => repulsion * s2 * s2 + u,
    }
}

/// Side, in nodes, of the blocks of the Morton order used by [`Tissue::sort_cells`]: about
/// a cell radius, so that a block holds a cell or two.
pub const SORT_BLOCK: f64 = 8.0;

/// Per-cell quantities derived from the fields by one evaluation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CellState {
    /// Area `A_i = Σ_x φ_i²`.
    pub area: f64,
    /// Deformation tensor `[S_xx, S_xy]` (MODEL.md §3; `S_yy = −S_xx`).
    pub shape: [f64; 2],
    /// Interface force `F_i`.
    pub force: [f64; 2],
    /// Velocity `v_i = F_i / ξ`.
    pub velocity: [f64; 2],
    /// Smallest `φ_i` on the patch.
    pub phi_min: f64,
    /// Largest `φ_i` on the patch.
    pub phi_max: f64,
}

/// A monolayer: the fields of all cells, the parameters and the clock.
///
/// The fields are stored in precision `T` (`f64`, the default, or `f32`; see
/// [`phasefield::Real`]); all arithmetic is done in `f64`.
#[derive(Debug, Clone)]
pub struct Tissue<T: Real = f64> {
    /// The phase fields.
    pub cells: Cells<T>,
    /// The model parameters (ζ may be changed between steps, e.g. after relaxation).
    pub params: ModelParams,
    /// Model time.
    pub time: f64,
    /// Steps taken.
    pub step: u64,
    /// Centre of mass of every cell (updated after every step).
    pub centre: Vec<[f64; 2]>,
    /// The identity of the cell in each storage slot: its index in the initial state.
    /// [`Tissue::sort_cells`] reorders the slots; outputs are written in identity order.
    pub cell_id: Vec<usize>,
}

/// Scratch memory for [`Tissue::step`]: built once, reused, never serialised.
#[derive(Debug, Clone)]
pub struct Workspace<T: Real = f64> {
    phi_old: Vec<T>,
    k1: Vec<T>,
    k2: Vec<T>,
    /// The global sums, `N_GLOBAL` lattice fields (see the `G_*` indices), written by each
    /// evaluation.
    pub global: LatticeSums<N_GLOBAL>,
    /// Per-cell derived quantities of the last evaluation.
    pub cell_state: Vec<CellState>,
    /// Two lattice fields for derived quantities (e.g. the tissue velocity).
    pub field2: LatticeSums<2>,
    com: ComTable,
}

impl<T: Real> Workspace<T> {
    /// Scratch memory for a tissue of this size.
    pub fn new(cells: &Cells<T>) -> Self {
        let n = cells.n_cells() * cells.patch_len();
        let lattice = cells.lattice();
        Self {
            phi_old: vec![T::default(); n],
            k1: vec![T::default(); n],
            k2: vec![T::default(); n],
            global: LatticeSums::for_cells(lattice, cells.n_cells(), cells.shape().nx),
            cell_state: vec![CellState::default(); cells.n_cells()],
            field2: LatticeSums::for_cells(lattice, cells.n_cells(), cells.shape().nx),
            com: ComTable::new(lattice),
        }
    }
}

impl<T: Real> Tissue<T> {
    /// A tissue from initial fields; centres of mass are computed and patches centred on them.
    pub fn new(cells: Cells<T>, params: ModelParams) -> Self {
        let mut t = Self {
            centre: vec![[0.0; 2]; cells.n_cells()],
            cell_id: (0..cells.n_cells()).collect(),
            cells,
            params,
            time: 0.0,
            step: 0,
        };
        let com = ComTable::new(t.cells.lattice());
        t.update_centres(&com);
        t
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        self.cells.lattice()
    }

    /// Reorders the cells' storage along a Morton (Z-order) curve of their centres, in blocks
    /// of [`SORT_BLOCK`] nodes, so that cells next to each other in memory are next to each
    /// other on the lattice and the lattice-wide fields they touch stay in cache. The physics
    /// does not change; sums over cells run in another order, which changes results at the
    /// level of round-off. `scratch` carries the field values (see [`Cells::permute`]).
    pub fn sort_cells(&mut self, scratch: &mut Vec<T>) {
        let key = |c: [f64; 2]| -> u64 {
            let (x, y) = ((c[0] / SORT_BLOCK) as u64, (c[1] / SORT_BLOCK) as u64);
            let spread = |mut v: u64| {
                v &= 0xffff_ffff;
                v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
                v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
                v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
                v = (v | (v << 2)) & 0x3333_3333_3333_3333;
                (v | (v << 1)) & 0x5555_5555_5555_5555
            };
            spread(x) | (spread(y) << 1)
        };
        let mut order: Vec<usize> = (0..self.cells.n_cells()).collect();
        order.sort_by_key(|&j| (key(self.centre[j]), self.cell_id[j]));
        if order.iter().enumerate().all(|(j, &o)| j == o) {
            return;
        }
        self.cells.permute(&order, scratch);
        self.centre = order.iter().map(|&o| self.centre[o]).collect();
        self.cell_id = order.iter().map(|&o| self.cell_id[o]).collect();
    }

    /// Slot of every cell identity: `slots()[id]` is where cell `id` is stored.
    pub fn slots(&self) -> Vec<usize> {
        let mut s = vec![0; self.cell_id.len()];
        for (slot, &id) in self.cell_id.iter().enumerate() {
            s[id] = slot;
        }
        s
    }

    /// Recomputes every centre of mass from the current patch values.
    fn compute_centres(&mut self, com: &ComTable) {
        let cells = &self.cells;
        self.centre
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, c)| *c = com.cell_centre(cells, i));
    }

    /// Recomputes the centres and moves each patch onto its cell's centre.
    fn update_centres(&mut self, com: &ComTable) {
        self.compute_centres(com);
        for i in 0..self.cells.n_cells() {
            self.cells.recentre(i, self.centre[i]);
        }
    }

    /// Evaluates the derived quantities of the current state (areas, shapes, forces,
    /// velocities, the global sums and the pressure) into `ws`, without stepping, and
    /// recomputes the centres of mass from the patches as they are now.
    ///
    /// After a step, [`Tissue::centre`] holds the centres that placed the patches; when a patch
    /// has just moved, the row or column that wrapped around carries far-edge values (MODEL.md
    /// §5), so the centre of the stored values can differ from it by the neglected tail.
    pub fn refresh(&mut self, ws: &mut Workspace<T>) {
        self.compute_centres(&ws.com);
        let Workspace {
            k2,
            global,
            cell_state,
            ..
        } = ws;
        evaluate(
            &self.params,
            &self.cells,
            self.cells.phi(),
            true,
            k2,
            global,
            cell_state,
        );
    }

    /// Advances the state by one time step `dt` with `npc` Heun corrector passes.
    ///
    /// Allocates nothing. The state is checked at the start of the step, before anything is
    /// overwritten: on error the tissue is left at the last good state.
    ///
    /// # Errors
    /// [`StepError::NonFinite`] if a cell's area or force is not finite, and
    /// [`StepError::Unstable`] if a field has left `[−PHI_BOUND, 1 + PHI_BOUND]`.
    pub fn step(
        &mut self,
        ws: &mut Workspace<T>,
        step_params: &StepParams,
    ) -> Result<(), StepError> {
        let dt = step_params.dt;
        let shapes = self.params.zeta != 0.0;
        let Workspace {
            phi_old,
            k1,
            k2,
            global,
            cell_state,
            com,
            ..
        } = ws;
        evaluate(
            &self.params,
            &self.cells,
            self.cells.phi(),
            shapes,
            k1,
            global,
            cell_state,
        );
        self.check(cell_state, dt)?;
        // The state moves into `phi_old` without a copy; the predictor overwrites the buffer
        // that held the previous step's `phi_old`.
        self.cells.swap_phi(phi_old);
        let phi = self.cells.phi_mut();
        phi.par_iter_mut()
            .zip(phi_old.par_iter().zip(k1.par_iter()))
            .for_each(|(p, (o, r))| *p = T::from_f64(o.to_f64() + dt * r.to_f64()));
        for _ in 0..step_params.npc {
            evaluate(
                &self.params,
                &self.cells,
                self.cells.phi(),
                shapes,
                k2,
                global,
                cell_state,
            );
            let phi = self.cells.phi_mut();
            phi.par_iter_mut()
                .zip(phi_old.par_iter())
                .zip(k1.par_iter().zip(k2.par_iter()))
                .for_each(|((p, o), (r1, r2))| {
                    *p = T::from_f64(o.to_f64() + 0.5 * dt * (r1.to_f64() + r2.to_f64()))
                });
        }
        self.step += 1;
        self.time += dt;
        self.update_centres(com);
        Ok(())
    }

    fn check(&self, cell_state: &[CellState], dt: f64) -> Result<(), StepError> {
        for (i, c) in cell_state.iter().enumerate() {
            let finite = c.area.is_finite()
                && c.force[0].is_finite()
                && c.force[1].is_finite()
                && c.phi_min.is_finite()
                && c.phi_max.is_finite();
            if !finite {
                return Err(StepError::NonFinite {
                    step: self.step,
                    time: self.time,
                    cell_idx: i,
                });
            }
            if c.phi_min < -PHI_BOUND || c.phi_max > 1.0 + PHI_BOUND {
                return Err(StepError::Unstable {
                    step: self.step,
                    time: self.time,
                    cell_idx: i,
                    phi: if c.phi_min < -PHI_BOUND {
                        c.phi_min
                    } else {
                        c.phi_max
                    },
                    dt,
                });
            }
        }
        Ok(())
    }
}

/// How far outside `[0, 1]` a phase field may go before the step is declared unstable.
///
/// Central-difference advection lets φ reach about −0.05 and 1.5 at ζ = 0.01 in stable runs
/// (reference code, `../shared/reference`); a value beyond `−2` or `3` only occurs on the way
/// to a blow-up.
pub const PHI_BOUND: f64 = 2.0;

/// Pass 1 for one cell: area, range and, with `SHAPE`, the deformation tensor.
#[inline(always)]
fn cell_sums<T: Real, const SHAPE: bool>(
    cell: &[T],
    shape: &phasefield::PatchShape,
    runs: &RowRuns,
    st: &mut CellState,
) {
    // Area and range need no stencil: one pass over the patch in LANES partial results.
    let mut area = [0.0; LANES];
    let (mut hi, mut neg_lo) = ([f64::NEG_INFINITY; LANES], [f64::NEG_INFINITY; LANES]);
    let mut chunks = cell.chunks_exact(LANES);
    for chunk in &mut chunks {
        for l in 0..LANES {
            let c = chunk[l].to_f64();
            area[l] += c * c;
            hi[l] = hi[l].max(c);
            neg_lo[l] = neg_lo[l].max(-c);
        }
    }
    for (l, c) in chunks.remainder().iter().enumerate() {
        let c = c.to_f64();
        area[l] += c * c;
        hi[l] = hi[l].max(c);
        neg_lo[l] = neg_lo[l].max(-c);
    }
    st.area = area.iter().sum();
    st.phi_max = hi.into_iter().fold(f64::NEG_INFINITY, f64::max);
    st.phi_min = -neg_lo.into_iter().fold(f64::NEG_INFINITY, f64::max);
    let mut acc = [[0.0; LANES]; 2];
    if SHAPE {
        for a in 0..shape.nx {
            for_each_run_in_column(cell, shape, runs, a, &mut |run| {
                let value = |s: Stencil, []: [f64; 0]| {
                    let (dx, dy) = (s.dx(), s.dy());
                    [0.5 * (dy * dy - dx * dx), -(dx * dy)]
                };
                run.sum_into([], value, &mut acc);
            });
        }
    }
    st.shape = add_lanes(&acc);
}

/// One evaluation of the right-hand side `R(φ)` into `rhs`, with every intermediate quantity
/// (global sums, pressure, per-cell state) left in the buffers for inspection.
///
/// With `shapes` false the deformation tensors are not computed (left zero), and so neither is
/// `Q`: the step passes `shapes = (ζ ≠ 0)`, since only the active force needs them, which saves
/// 9 % of a passive step (960 cells, 1 thread: 16.2 → 14.7 ms). Observations always compute them.
///
/// Every kernel works on runs of patch rows ([`phasefield::StencilRun`]), whose lattice rows
/// are contiguous, so that its loops compile to SIMD instructions; per-cell sums are taken in
/// [`phasefield::LANES`] interleaved partial sums ([`phasefield::lanes`]).
#[allow(clippy::too_many_arguments)]
pub fn evaluate<T: Real>(
    params: &ModelParams,
    cells: &Cells<T>,
    phi: &[T],
    shapes: bool,
    rhs: &mut [T],
    global: &mut LatticeSums<N_GLOBAL>,
    cell_state: &mut [CellState],
) {
    let shape = cells.shape();
    let plen = shape.len();
    let ny = shape.ny;
    let energy = params.energy;
    let zeta = params.zeta;
    let patch_runs = RowRuns::patch(ny);

    // 1. Per cell: area, deformation tensor, range.
    cell_state
        .par_iter_mut()
        .zip(phi.par_chunks(plen))
        .for_each(|(st, cell)| {
            if shapes {
                cell_sums::<T, true>(cell, shape, &patch_runs, st);
            } else {
                cell_sums::<T, false>(cell, shape, &patch_runs, st);
            }
        });

    // 2. Global sums.
    let coef = energy.coefficients();
    let kind = params.pressure;
    {
        let cs: &[CellState] = cell_state;
        scatter::<N_GLOBAL, T, _>(cells, phi, global, |i, run, sums| {
            let c = &cs[i];
            let n = run.c.len();
            let [s1, s2, u, qxx, qxy] = sums;
            let (s1, s2, u) = (&mut s1[..n], &mut s2[..n], &mut u[..n]);
            let (qxx, qxy) = (&mut qxx[..n], &mut qxy[..n]);
            let area_factor = coef.area_factor(c.area);
            let [sxx, sxy] = c.shape;
            let store = |j: usize, [p, p2, uj]: [f64; 3]| {
                s1[j] += p;
                s2[j] += p2;
                u[j] += uj;
                qxx[j] += p * sxx;
                qxy[j] += p * sxy;
            };
            match kind {
                PressureKind::Paper => run.map(
                    [],
                    |s, []| {
                        let p = s.c;
                        let p2 = p * p;
                        let u = -coef.repulsion * p2 * p
                            - coef.double_well * p * (1.0 - p) * (1.0 - 2.0 * p)
                            + coef.gradient * s.laplacian()
                            - area_factor * p;
                        [p, p2, u]
                    },
                    store,
                ),
                PressureKind::Interaction => run.map(
                    [],
                    |s, []| [s.c, s.c * s.c, -coef.repulsion * s.c.powi(4)],
                    store,
                ),
            }
        });
    }

    // 3. Forces, velocities and the right-hand side.
    let g: &LatticeSums<N_GLOBAL> = global;
    let map = cells.map();
    let xi = params.xi;
    // The paper's P contains cell i's own double-well term −(8γ/λ) φ_i(1−φ_i)(1−2φ_i). Its
    // contribution to F_i is the integral of a gradient, zero in the continuum, but its central
    // difference sum is not zero on the lattice and would propel isolated cells (|v| ~ 2e-7
    // off the lattice's symmetry points). It is removed here; the other self terms
    // (∇²φ_i ∇φ_i with the patch Laplacian, and φ_i ∇φ_i) already sum to zero exactly on a
    // periodic patch.
    let c_self = match params.pressure {
        PressureKind::Paper => coef.double_well,
        PressureKind::Interaction => 0.0,
    };
    // P = rep · first · s2 + U, with first = s1 (paper) or s2 (interaction).
    let first = match params.pressure {
        PressureKind::Paper => G_S1,
        PressureKind::Interaction => G_S2,
    };
    rhs.par_chunks_mut(plen)
        .zip(phi.par_chunks(plen))
        .zip(cell_state.par_iter_mut())
        .enumerate()
        .for_each(|(i, ((out, cell), st))| {
            let xs = map.cell_x(shape, i);
            let runs = RowRuns::new(map.cell_y(shape, i));
            let mut acc = [[0.0; LANES]; 2];
            for (a, &x) in xs.iter().enumerate() {
                let cols = g.columns(x as usize);
                for_each_run_in_column(cell, shape, &runs, a, &mut |run| {
                    let y = run.run.y0..run.run.y0 + run.run.len;
                    let fields = [
                        &cols[G_S2][y.clone()],
                        &cols[G_U][y.clone()],
                        &cols[G_QXX][y.clone()],
                        &cols[G_QXY][y.clone()],
                        &cols[first][y],
                    ];
                    let value = |s: Stencil, [s2, u, qxx, qxy, s_first]: [f64; 5]| {
                        let p = coef.repulsion * s_first * s2
                            + u
                            + c_self * s.c * (1.0 - s.c) * (1.0 - 2.0 * s.c);
                        let (dx, dy) = (s.dx(), s.dy());
                        [
                            p * dx + zeta * (qxx * dx + qxy * dy),
                            p * dy + zeta * (qxy * dx - qxx * dy),
                        ]
                    };
                    run.sum_into(fields, value, &mut acc);
                });
            }
            let [fx, fy] = add_lanes(&acc);
            let (vx, vy) = (fx / xi, fy / xi);
            st.force = [fx, fy];
            st.velocity = [vx, vy];
            let area_factor = coef.area_factor(st.area);
            for (a, &x) in xs.iter().enumerate() {
                let s2_col = g.column(G_S2, x as usize);
                let out_col = &mut out[a * ny..(a + 1) * ny];
                for_each_run_in_column(cell, shape, &runs, a, &mut |run| {
                    let (y0, b0, n) = (run.run.y0, run.run.b0, run.run.len);
                    let o = &mut out_col[b0..b0 + n];
                    run.map(
                        [&s2_col[y0..y0 + n]],
                        |s, [s2]| {
                            let others = s2 - s.c * s.c;
                            let dfdphi = coef.ch(s.c, s.laplacian())
                                + area_factor * s.c
                                + coef.rep(s.c, others);
                            [-(vx * s.dx() + vy * s.dy()) - dfdphi]
                        },
                        |j, [v]| o[j] = T::from_f64(v),
                    );
                });
            }
        });
}
