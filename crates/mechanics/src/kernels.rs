//! One evaluation of the right-hand side `R(φ)` (docs/model.md §3–4) in three passes, built from
//! the named functions of [`crate::equations`]:
//! 1. per cell, in parallel: area `A_i = Σ φ_i²`, range and deformation tensor `S_i`;
//! 2. scatter onto the lattice, stripe-parallel in cell order: `s1, s2`, `U`, `Q_xx, Q_xy`
//!    ([`crate::SumField`]), then, stripe by stripe while it is in cache, the pressure `P` of
//!    each lattice node from its sums;
//! 3. per cell, in parallel: the force `F_i`, the velocity `v_i`, then `R_i` on the same patch
//!    while it is in cache.
//!
//! Every kernel works on runs of stencils (`phasefield::kernel::StencilRun`), so that its loops
//! compile to SIMD instructions; per-cell sums are taken in `LANES` interleaved partial sums.
//! The per-cell passes (1 and 3) sweep each patch as one run of a padded copy
//! (`phasefield::kernel::PaddedPatch`, each thread's own), with the lattice sums they read
//! gathered beside it; the scatter (2) writes lattice columns, so it goes column by column.
//! This is machinery: nothing here is public. Each thread's scratch is in [`crate::scratch`].

use nalgebra::Vector2;
use phasefield::kernel::{add_lanes, PaddedParts, PaddedPatch, StencilRun, LANES};
use phasefield::{Cells, ComTable, EnergyCoefficients, PatchShape, Real, Stencil};
use rayon::prelude::*;

use crate::equations::{
    adhesion_derivative, adhesion_pressure_cell_part, force_density, heun_corrector,
    heun_predictor, nematic_density, pressure, pressure_cell_part, pressure_self_coefficient,
    pressure_self_part_with, rhs, velocity,
};
use crate::evaluation::{CellState, SumField, N_SUMS};
use crate::geometry::TracelessTensor;
use crate::node_terms::{NodeTerm, PopulationSums};
use crate::params::{ModelParams, PressureKind};
use crate::scatter::{scatter, LatticeSums};
use crate::terms::{CellConstants, Populations};

// Where each lattice sum is stored.
const I_S2: usize = SumField::S2.index();
const I_QXX: usize = SumField::Qxx.index();
const I_QXY: usize = SumField::Qxy.index();
const I_P: usize = SumField::P.index();

use crate::scratch::{NODE_TERMS, N_GATHERED, PADDED};

/// Pass 1 for one cell: area, range and, with `SHAPE`, the deformation tensor.
#[inline(always)]
fn cell_sums<T: Real, const SHAPE: bool>(cell: &[T], shape: &PatchShape, st: &mut CellState) {
    // Area and range need no stencil: passes over the patch in LANES partial results, which
    // compile to clean SIMD code; the three in one loop were shuffled between registers (56
    // instructions per chunk of 8). `if c > m { c } else { m }` is one SIMD max instruction,
    // where `f64::max`, which must return the other operand of a NaN, is five. A NaN is
    // skipped either way, and caught by the area, which it makes NaN.
    let mut area = [0.0; LANES];
    let (mut hi, mut lo) = ([f64::NEG_INFINITY; LANES], [f64::INFINITY; LANES]);
    let larger = |m: f64, c: f64| if c > m { c } else { m };
    let smaller = |m: f64, c: f64| if c < m { c } else { m };
    let chunks = cell.chunks_exact(LANES);
    let rest = chunks.remainder();
    for chunk in chunks.clone() {
        for l in 0..LANES {
            let c = chunk[l].to_f64();
            area[l] += c * c;
        }
    }
    // The range in one pass (the two extremes together compile to one SIMD max and one min
    // per vector; a pass for each cost 0.6 instructions per node-update more, issue 38).
    for chunk in chunks {
        for l in 0..LANES {
            let c = chunk[l].to_f64();
            hi[l] = larger(hi[l], c);
            lo[l] = smaller(lo[l], c);
        }
    }
    for (l, c) in rest.iter().enumerate() {
        let c = c.to_f64();
        area[l] += c * c;
        hi[l] = larger(hi[l], c);
        lo[l] = smaller(lo[l], c);
    }
    st.area = area.iter().sum();
    st.phi_max = hi.into_iter().fold(f64::NEG_INFINITY, f64::max);
    st.phi_min = lo.into_iter().fold(f64::INFINITY, f64::min);
    // The accumulators live inside the closure and come back by value: when they were a local
    // of this function borrowed into it, and `LocalKey::with` was not inlined here (as after
    // the physics terms grew `evaluate`), LLVM kept them in memory and stored all of them at
    // every chunk of 8 nodes: 118 instructions a chunk where this loop takes 32 (issue 38,
    // 11.6 of the 17 instructions per node-update the minimal model had gained).
    let acc = if SHAPE {
        PADDED.with_borrow_mut(|padded| shape_sum(padded, cell, shape))
    } else {
        [0.0; 2]
    };
    st.shape = TracelessTensor::from(acc.map(|s| 0.25 * s));
}

/// The deformation tensor's sum over the padded patch `run` (`mask` weighting its nodes), in
/// `LANES` partial sums of each
/// component (four times `S_i`: see below). A function of its own, never inlined, so that its
/// chunk loop is compiled alone with its accumulators in registers: inlined into the
/// thread-local access of a larger `evaluate`, LLVM split the loop into scalar and 128-bit
/// pieces (85–118 instructions a chunk of 8 nodes where this takes 32; issue 38).
#[inline(never)]
fn shape_sum<T: Real>(
    padded: &mut PaddedPatch<N_GATHERED>,
    cell: &[T],
    shape: &PatchShape,
) -> [f64; 2] {
    padded.fill(cell, shape);
    let PaddedParts { run, mask, .. } = padded.parts();
    // `shape_tensor_density` of the undivided differences (`Stencil::diff_x`, twice the
    // gradient), without its constant factors: `dy² − dx²` and `dx dy`. The density is
    // quadratic in the gradient, so it is 4× its value; the factors (½ and −1 of the density,
    // ¼ of the differences) are taken once on the sums, by `from_sums`. Each is a power of two
    // or a sign, so the result is the same to the bit as the density's sum.
    let value = move |s: Stencil, [w]: [f64; 1]| {
        let (dx, dy) = (s.diff_x(), s.diff_y());
        [w * (dy * dy - dx * dx), w * (dx * dy)]
    };
    let mut acc = [[0.0; LANES]; 2];
    run.sum_into([mask], value, &mut acc);
    let [xx, xy] = add_lanes(&acc);
    // `0 − xy`, not `−xy`: a zero sum gives +0, as the density's sum does.
    [0.5 * xx, 0.0 - xy]
}

/// What one evaluation reads: the state, the parameters, the terms' whole-cell forces, each
/// slot's identity with the per-identity constants (populations, the growth factors), and the
/// node terms ([`crate::node_terms`], `None` for one that is absent).
#[derive(Clone, Copy)]
pub(crate) struct EvalInput<'a, T: Real> {
    pub params: &'a ModelParams,
    pub cells: &'a Cells<T>,
    pub phi: &'a [T],
    /// Whether to compute the deformation tensors and `Q` (see [`evaluate`]).
    pub shapes: bool,
    /// Whether the shape activity `ζ_i S_i` enters the stress (off only in the evaluations
    /// that split the force by origin, `crate::origins`).
    pub shape_activity: bool,
    pub cell_force: Option<&'a [[f64; 2]]>,
    /// Each slot's active tensor `T_i` beside `ζ_i S_i` (the cell nematic's `ζ_Q q_i`), which
    /// the stress takes as `−Σ_j φ_j T_j`; `None` without.
    pub cell_stress: Option<&'a [[f64; 2]]>,
    pub populations: &'a Populations,
    pub ids: &'a [usize],
    pub active: bool,
    pub growth: &'a [f64],
    pub node_terms: &'a [Option<&'a dyn NodeTerm>],
    /// The walls' field in effect and their friction `ξ_w`, when it is not zero
    /// ([`crate::walls::wall_overlap`]).
    pub wall_friction: Option<(&'a phasefield::WallField, f64)>,
}

/// Where one evaluation writes what it computes on the way (all of it left for inspection).
pub(crate) struct EvalScratch<'a> {
    pub sums: &'a mut LatticeSums<N_SUMS>,
    pub cell_state: &'a mut [CellState],
    /// The node terms' lattice fields of scratch, one after the other in the order of the
    /// terms ([`NodeTerm::scratch_fields`] each).
    pub node_scratch: &'a mut [f64],
    /// The node terms' `a_p` and `b_p`, two lattice fields for each coefficient class (one
    /// class, or one per population when a term's coefficients depend on it).
    pub node_coefficients: &'a mut [f64],
    /// The node terms' `[k_p, c_p]` of each class.
    pub node_constants: &'a mut Vec<[f64; 2]>,
    /// Each population's `s1_p`, filled when a node term reads them.
    pub population_sums: &'a mut PopulationSums,
    pub kind_constants: &'a mut Vec<CellConstants>,
}

/// What the last pass of [`evaluate`] does with each cell's right-hand side `k` once it has it,
/// while the cell's fields are in cache: a Heun update that would otherwise be a sweep of its
/// own over every field, and a parallel loop of its own. The values are those of the separate
/// sweeps ([`crate::equations`]), to the bit.
pub(crate) enum Post<'a, T> {
    /// Nothing.
    Nothing,
    /// The predictor into `out`: `out = φ + h k`.
    Predict { h: f64, out: &'a mut [T] },
    /// The corrector over `k1`, node by node once it has been read: `k1 = φ_old + h/2 (k1 + k)`,
    /// so that `old = φ_old` survives the step until its check; then the centre of mass of
    /// the new field into `centres` (by Fourier phase, as [`ComTable::centre_of_mass`]
    /// computes it after a step) and its range `[min φ, max φ]` into `ranges`: the loop over
    /// the cells that the step would otherwise need for them.
    Correct {
        h: f64,
        k1: &'a mut [T],
        old: &'a [T],
        com: &'a ComTable,
        centres: &'a mut [[f64; 2]],
        ranges: &'a mut [[f64; 2]],
    },
}

/// [`Post`] for one cell: its slices of the fields the update reads and writes.
enum CellPost<'c, T> {
    Nothing,
    Predict {
        h: f64,
        out: &'c mut [T],
    },
    Correct {
        h: f64,
        k1: &'c mut [T],
        old: &'c [T],
        com: &'c ComTable,
        centre: &'c mut [f64; 2],
        range: &'c mut [f64; 2],
    },
}

/// One evaluation of the right-hand side `R(φ)` into `rhs_out`, with every intermediate
/// quantity (lattice sums, per-cell state) left in the buffers for inspection.
///
/// With `shapes` false the deformation tensors are not computed (left zero), and so neither is
/// `Q`: the step passes `shapes = (ζ ≠ 0)`, since only the active force needs them, which saves
/// 9 % of a passive step (960 cells, 1 thread: 16.2 → 14.7 ms). Observations always compute them.
///
/// The pressure form is dispatched outside the loops, and the force loop has no branch on it:
/// it reads the pressure `P` that the scatter computed per lattice node ([`SumField::P`]), and
/// the self term is weighted 1 (paper) or 0 (interaction), an identity tested in `equations`.
/// (Reading `P`, where each cell computed it again from `s1`, `s2` and `U`, gathers one field
/// less and takes 9 instructions from the force chunk: 87.5 → 85.7 instructions per
/// node-update, with the same results to the bit.) (A version monomorphised on the
/// form was 9 % slower on the paper scene, 1 thread, measured alternately; so were some
/// rearrangements of this function that only renamed or regrouped its locals: its speed
/// depends on how LLVM inlines the closures, so time it after any change, with the whole-run
/// command in `docs/performance.md`.)
pub(crate) fn evaluate<T: Real>(
    input: &EvalInput<'_, T>,
    rhs_out: &mut [T],
    scratch: EvalScratch<'_>,
    post: Post<'_, T>,
) {
    let EvalInput {
        params,
        cells,
        phi,
        shapes,
        shape_activity,
        cell_force,
        cell_stress,
        populations: pops,
        ids,
        active,
        growth,
        node_terms: terms,
        wall_friction,
    } = *input;
    let EvalScratch {
        sums: global,
        cell_state,
        node_scratch,
        node_coefficients: node_buf,
        node_constants,
        population_sums,
        kind_constants,
    } = scratch;
    let shape = cells.shape();
    let plen = shape.len();
    let energy = params.energy;
    // With populations of their own ζ the scatter weights each S_i by ζ_i and the force takes
    // the weighted sum as it is; otherwise the sum is Q and the force multiplies it by ζ.
    // A cell's own active tensor (`cell_stress`) is added to its weighted `S_i`, so the sum
    // is weighted then too.
    let mixed = pops.mixed_zeta(params, active) || cell_stress.is_some();
    let zeta = if mixed { 1.0 } else { params.zeta };
    // Each population's constants, computed once per evaluation (the scatter asks for a
    // cell's once per patch column).
    pops.fill_constants(params, active, mixed, kind_constants);
    let kind_constants: &[CellConstants] = kind_constants;
    // A growing cell (division's growth phase) has its target area scaled by `growth[id]`.
    let constants = |i: usize| {
        let mut k = kind_constants[pops.population(ids[i])];
        if let Some(&g) = growth.get(ids[i]) {
            k.coef.area /= g;
            k.coef.inv_target_area /= g;
        }
        k
    };

    // 1. Per cell: area, deformation tensor, range.
    cell_state
        .par_iter_mut()
        .zip(phi.par_chunks(plen))
        .for_each(|(st, cell)| {
            if shapes {
                cell_sums::<T, true>(cell, shape, st);
            } else {
                cell_sums::<T, false>(cell, shape, st);
            }
        });

    // The node terms' coefficient classes (`crate::node_terms`): one, or one per population
    // when a term's coefficients depend on it; each class's summed `[k_p, c_p]`.
    let per_population = class_constants(terms, pops, node_constants);
    let class = |i: usize| {
        if per_population {
            pops.population(ids[i])
        } else {
            0
        }
    };
    let node_constants: &[[f64; 2]] = node_constants;

    // 2. Lattice sums.
    let coef = energy.coefficients();
    let kind = params.pressure;
    lattice_sums(
        cells,
        phi,
        global,
        cell_state,
        (kind, &coef),
        &constants,
        &class,
        node_constants,
        cell_stress,
        shape_activity,
    );

    // Each population's `s1_p`, for the node terms that read them; then the terms' lattice
    // parts of the pressure, then their coefficients, gathered by the force pass.
    let node_terms = node_term_pass(
        cells,
        phi,
        (pops, ids),
        terms,
        global,
        NodeBuffers {
            scratch: node_scratch,
            coefficients: node_buf,
            constants: node_constants,
            population_sums,
        },
    );

    // 3. Forces, velocities and the right-hand side.
    let g: &LatticeSums<N_SUMS> = global;
    let map = cells.map();
    let ly = cells.lattice().ly;
    let force_input = ForceInput {
        global: g,
        shape,
        ly,
        zeta,
        cell_force,
    };
    let body = |i: usize, out: &mut [T], cell: &[T], st: &mut CellState, post: CellPost<'_, T>| {
        let xs = map.cell_x(shape, i);
        let CellConstants { coef, xi, .. } = constants(i);
        // A cell on a wall with friction: `(ξ + ξ_w o_i) v_i = F_i`.
        let xi = match wall_friction {
            None => xi,
            Some((field, f)) => {
                xi + f * crate::walls::wall_overlap(field, cell, shape, xs, map.cell_y(shape, i))
            }
        };
        let c_self = pressure_self_coefficient(kind, &coef);
        let node = node_terms.as_ref().map(|n| n.of_class(class(i)));
        force_and_rhs(&force_input, i, xs, coef, xi, c_self, node, cell, st, out);
        // The Heun update of this cell, while its fields are in cache.
        let out: &[T] = out;
        match post {
            CellPost::Nothing => {}
            CellPost::Predict { h, out: pred } => {
                for ((e, p), r) in pred.iter_mut().zip(cell).zip(out) {
                    *e = T::from_f64(heun_predictor(p.to_f64(), h, r.to_f64()));
                }
            }
            CellPost::Correct {
                h,
                k1,
                old,
                com,
                centre,
                range,
            } => {
                for ((e, o), r2) in k1.iter_mut().zip(old).zip(out) {
                    *e = T::from_f64(heun_corrector(o.to_f64(), h, e.to_f64(), r2.to_f64()));
                }
                *range = field_range(k1);
                *centre = com.centre_of_mass(k1, shape, xs, map.cell_y(shape, i));
            }
        }
    };
    for_each_cell(rhs_out, phi, cell_state, cells.n_cells(), plen, post, body);
}

/// The node terms' coefficient classes (`crate::node_terms`): one, or one per population of
/// `pops` when a term's coefficients depend on it (the value returned); each class's summed
/// `[k_p, c_p]` into `node_constants`.
fn class_constants(
    terms: &[Option<&dyn NodeTerm>],
    pops: &Populations,
    node_constants: &mut Vec<[f64; 2]>,
) -> bool {
    let classes = crate::node_terms::classes(terms, pops);
    node_constants.clear();
    node_constants.extend((0..classes).map(|p| {
        let asked = |t: &&dyn NodeTerm| if t.per_population() { p } else { 0 };
        let sum = |f: fn(&dyn NodeTerm, usize) -> f64| {
            terms.iter().flatten().map(|t| f(*t, asked(t))).sum::<f64>()
        };
        [
            sum(|t, p| t.cell_pressure_coefficient(p)),
            sum(|t, p| t.laplacian_coefficient(p)),
        ]
    }));
    terms.iter().flatten().any(|t| t.per_population())
}

/// Pass 3's loop over the cells, in parallel: `body(i, out, cell, state, post)` for each cell
/// `i` with its slices of the right-hand side, the fields, its state and of what `post`
/// updates (the predictor's or the corrector's fields, its centre and range). Inlined into
/// [`evaluate`], whose code it was.
#[inline(always)]
fn for_each_cell<T: Real>(
    rhs_out: &mut [T],
    phi: &[T],
    cell_state: &mut [CellState],
    n_cells: usize,
    plen: usize,
    post: Post<'_, T>,
    body: impl Fn(usize, &mut [T], &[T], &mut CellState, CellPost<'_, T>) + Sync,
) {
    let cells_iter = rhs_out
        .par_chunks_mut(plen)
        .zip(phi.par_chunks(plen))
        .zip(cell_state.par_iter_mut());
    match post {
        Post::Nothing => cells_iter
            .enumerate()
            .for_each(|(i, ((out, cell), st))| body(i, out, cell, st, CellPost::Nothing)),
        Post::Predict { h, out: pred } => {
            assert_eq!(
                pred.len(),
                phi.len(),
                "the predictor's field holds every cell"
            );
            cells_iter
                .zip(pred.par_chunks_mut(plen))
                .enumerate()
                .for_each(|(i, (((out, cell), st), pred))| {
                    body(i, out, cell, st, CellPost::Predict { h, out: pred })
                });
        }
        Post::Correct {
            h,
            k1,
            old,
            com,
            centres,
            ranges,
        } => {
            assert_eq!(
                old.len(),
                phi.len(),
                "the corrector's field holds every cell"
            );
            assert_eq!(k1.len(), phi.len(), "k1 holds every cell");
            assert_eq!(centres.len(), n_cells, "a centre for every cell");
            assert_eq!(ranges.len(), n_cells, "a range for every cell");
            cells_iter
                .zip(old.par_chunks(plen))
                .zip(k1.par_chunks_mut(plen).zip(centres.par_iter_mut()))
                .zip(ranges.par_iter_mut())
                .enumerate()
                .for_each(|(i, (((((out, cell), st), old), (k1, centre)), range))| {
                    let post = CellPost::Correct {
                        h,
                        k1,
                        old,
                        com,
                        centre,
                        range,
                    };
                    body(i, out, cell, st, post)
                });
        }
    }
}

/// Pass 2's scatter: every cell's `s1, s2, U, Q_xx, Q_xy` onto the lattice, then the pressure
/// `P` of each node, with the pressure form `kind` (and the energy coefficients `coef`), each
/// cell's constants and coefficient class, and the node terms' `[k_p, c_p]` of each class.
/// One scatter (`scatter_sums`) with the single-cell part of the pressure that each node adds
/// to `U` for each pressure form, and with the node terms' `k_p φ ∇²φ` added: the choice is
/// made once per evaluation, and each node loop is compiled alone with its form (without
/// adhesion the loops are what they were). Inlined into [`evaluate`], whose code it was.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn lattice_sums<T: Real>(
    cells: &Cells<T>,
    phi: &[T],
    global: &mut LatticeSums<N_SUMS>,
    cs: &[CellState],
    (kind, coef): (PressureKind, &EnergyCoefficients),
    constants: &(impl Fn(usize) -> CellConstants + Sync),
    class: &(impl Fn(usize) -> usize + Sync),
    node_constants: &[[f64; 2]],
    cell_stress: Option<&[[f64; 2]]>,
    shape_activity: bool,
) {
    let coef = *coef;
    // Whether a node term has a single-cell pressure `k_p φ ∇²φ` (adhesion's).
    let cell_part = node_constants.iter().any(|k| k[0] != 0.0);
    // What the scatter needs of cell `i`, once per cell and stripe: its energy
    // coefficients, its area factor, its deformation tensor weighted by its ζ and the
    // node terms' `k_p` of its class.
    let per_cell = |i: usize| {
        let k = constants(i);
        let [sxx, sxy] = if shape_activity {
            cs[i].shape.components()
        } else {
            [0.0; 2]
        };
        let sh = match cell_stress {
            None => [k.zeta_weight * sxx, k.zeta_weight * sxy],
            Some(t) => [k.zeta_weight * sxx + t[i][0], k.zeta_weight * sxy + t[i][1]],
        };
        let k_node = node_constants[class(i)][0];
        (k.coef, k.coef.area_factor(cs[i].area), sh, k_node)
    };
    let node = move |p: f64, u: f64, sh: [f64; 2]| {
        let [q_xx, q_xy] = nematic_density(p, sh);
        [p, p * p, u, q_xx, q_xy]
    };
    // The pressure, once per lattice node, where the force pass would compute it again for
    // every cell over the node: the same formula on the same sums, so the same values to
    // the bit.
    let finish = |[s1, s2, u, _, _, p]: [&mut [f64]; N_SUMS]| {
        for (((p, &s1), &s2), &u) in p.iter_mut().zip(&*s1).zip(&*s2).zip(&*u) {
            *p = pressure(kind, &coef, s1, s2, u);
        }
    };
    // One scatter (`scatter_sums`) with the single-cell part of the pressure that each
    // node adds to `U` for each pressure form, and with the node terms' `k_p φ ∇²φ` added:
    // the choice is made once per evaluation, and each node loop is compiled alone with
    // its form (without adhesion the loops are what they were).
    match (kind, cell_part) {
        (PressureKind::Paper, false) => scatter_sums(
            cells,
            phi,
            global,
            &per_cell,
            node,
            &finish,
            move |coef, s, a, _| {
                pressure_cell_part(PressureKind::Paper, coef, s.c, s.laplacian(), a)
            },
        ),
        (PressureKind::Interaction, false) => scatter_sums(
            cells,
            phi,
            global,
            &per_cell,
            node,
            &finish,
            move |coef, s, _, _| pressure_cell_part(PressureKind::Interaction, coef, s.c, 0.0, 0.0),
        ),
        (kind, true) => scatter_sums(
            cells,
            phi,
            global,
            &per_cell,
            node,
            &finish,
            move |coef, s, a, k_node| {
                let (p, lap) = (s.c, s.laplacian());
                pressure_cell_part(kind, coef, p, lap, a)
                    + adhesion_pressure_cell_part(k_node, p, lap)
            },
        ),
    }
}

/// The node terms' buffers of an evaluation ([`EvalScratch`]).
struct NodeBuffers<'a> {
    scratch: &'a mut [f64],
    coefficients: &'a mut [f64],
    constants: &'a [[f64; 2]],
    population_sums: &'a mut PopulationSums,
}

/// The node terms after the scatter: each population's `s1_p` for the terms that read them
/// (with the populations `pops` and each slot's identity `ids`), the terms' lattice parts of
/// the pressure into `global`, then their coefficients of every class, which it returns for
/// the force pass (`None` without node terms). Inlined into [`evaluate`], whose code it was.
#[inline(always)]
fn node_term_pass<'a, T: Real>(
    cells: &Cells<T>,
    phi: &[T],
    (pops, ids): (&Populations, &[usize]),
    terms: &[Option<&dyn NodeTerm>],
    global: &mut LatticeSums<N_SUMS>,
    buffers: NodeBuffers<'a>,
) -> Option<ClassCoefficients<'a>> {
    let NodeBuffers {
        scratch: node_scratch,
        coefficients: node_buf,
        constants: node_constants,
        population_sums,
    } = buffers;
    let moments = terms
        .iter()
        .flatten()
        .map(|t| t.population_moments())
        .max()
        .unwrap_or(0);
    if moments > 0 {
        let n = pops.kinds().len().max(1);
        population_sums.fill(cells, phi, n, moments, |i| pops.population(ids[i]));
    }
    let nodes = cells.lattice().len();
    {
        let mut rest: &mut [f64] = node_scratch;
        for t in terms.iter().flatten() {
            let (mine, after) = std::mem::take(&mut rest).split_at_mut(t.scratch_fields() * nodes);
            t.add_pressure(global, population_sums, mine);
            rest = after;
        }
    }
    terms.iter().any(Option::is_some).then(|| {
        fill_node_terms(terms, node_scratch, nodes, node_buf);
        ClassCoefficients {
            fields: node_buf,
            constants: node_constants,
            nodes,
        }
    })
}

/// Pass 2: every cell's `s1, s2, U, Q_xx, Q_xy` scattered onto the lattice (`scatter`), then
/// `finish` stripe by stripe (the pressure). `per_cell(i)` is what the scatter needs of cell
/// `i` (energy coefficients, area factor, ζ-weighted `S_i`, the node terms' `k_p`), `node` its
/// sums at one node, and `cell_u(coef, stencil, area_factor, k_p)` the single-cell part of the
/// pressure a node adds to `U`: the one thing the pressure forms and the node terms change,
/// each a closure of its own, so that each node loop is compiled with its form alone.
#[inline(always)]
fn scatter_sums<T, C, N, F, U>(
    cells: &Cells<T>,
    phi: &[T],
    global: &mut LatticeSums<N_SUMS>,
    per_cell: &C,
    node: N,
    finish: &F,
    cell_u: U,
) where
    T: Real,
    C: Fn(usize) -> (EnergyCoefficients, f64, [f64; 2], f64) + Sync,
    N: Fn(f64, f64, [f64; 2]) -> [f64; 5] + Copy + Sync,
    F: Fn([&mut [f64]; N_SUMS]) + Sync,
    U: Fn(&EnergyCoefficients, &Stencil, f64, f64) -> f64 + Copy + Sync,
{
    scatter::<N_SUMS, T, _, _, _>(
        cells,
        phi,
        global,
        |i| {
            let (coef, area_factor, sh, k_node) = per_cell(i);
            move |run: &StencilRun<'_, T>, [s1, s2, u, qxx, qxy, _]: [&mut [f64]; N_SUMS]| {
                run.add_to(
                    [],
                    move |s, []| node(s.c, cell_u(&coef, &s, area_factor, k_node), sh),
                    [s1, s2, u, qxx, qxy],
                )
            }
        },
        finish,
    );
}

/// What the force pass reads besides the cell: the lattice sums, the patch shape, the lattice
/// height, ζ (1 when the sums are ζ-weighted) and the terms' whole-cell forces.
struct ForceInput<'a> {
    global: &'a LatticeSums<N_SUMS>,
    shape: &'a PatchShape,
    ly: usize,
    zeta: f64,
    cell_force: Option<&'a [[f64; 2]]>,
}

/// Pass 3 for cell `i`, on its patch in the thread's padded scratch: the force `F_i`, the
/// velocity `v_i` (into `st`), then the right-hand side `R_i` into `out`, with the node terms'
/// coefficients of its class `node_terms`. A function of its
/// own, never inlined, so that its two chunk loops are compiled with this cell's values alone
/// in the registers, whatever `evaluate` around it grows into (issue 38: inlined there, the
/// loops took 4–20 % more instructions depending on the rest of `evaluate`).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn force_and_rhs<T: Real>(
    input: &ForceInput<'_>,
    i: usize,
    xs: &[u32],
    coef: EnergyCoefficients,
    xi: f64,
    c_self: f64,
    node_terms: Option<NodeTerms<'_>>,
    cell: &[T],
    st: &mut CellState,
    out: &mut [T],
) {
    let ForceInput {
        global: g,
        shape,
        ly,
        zeta,
        cell_force,
    } = *input;
    PADDED.with_borrow_mut(|padded| {
        padded.fill(cell, shape);
        padded.gather(xs, g.cell_runs(i), |x| {
            let cols = g.columns(x);
            [cols[I_P], cols[I_S2], cols[I_QXX], cols[I_QXY]]
        });
        let PaddedParts {
            run,
            mask,
            fields: [p_all, s2, qxx, qxy],
            out: flat,
        } = padded.parts();
        let mut acc = [[0.0; LANES]; 2];
        // `move`: the coefficients are copied into the closure, so that they stay in
        // registers across the chunk loop's optimisation barrier (by reference, each chunk
        // loaded them again).
        // The undivided differences (twice the gradient, `Stencil::diff_x`) here and in
        // the right-hand side, the ½ taken once per cell: the force density is linear in
        // the gradient, so the sum is twice the force, and `v/2 · 2∇φ` is `v · ∇φ`, both
        // exactly (scaling by 2 is), with a multiplication fewer per derivative and node.
        let value = move |s: Stencil, [w, p_all, qxx, qxy]: [f64; 4]| {
            let p = p_all - pressure_self_part_with(c_self, s.c);
            let [fx, fy] = force_density(p, zeta, [qxx, qxy], [s.diff_x(), s.diff_y()]);
            [w * fx, w * fy]
        };
        run.sum_into([mask, p_all, qxx, qxy], value, &mut acc);
        let force = add_lanes(&acc).map(|f| 0.5 * f);
        // The terms' whole-cell forces (`crate::terms`), added before the velocity.
        let v = match cell_force {
            None => velocity(force, xi),
            Some(f) => {
                let [gx, gy] = f[i];
                st.cell_force = Vector2::new(gx, gy);
                velocity([force[0] + gx, force[1] + gy], xi)
            }
        };
        let half_v = v.map(|c| 0.5 * c);
        st.force = Vector2::from(force);
        st.velocity = Vector2::from(v);
        st.drag = xi;
        let area_factor = coef.area_factor(st.area);
        match node_terms {
            None => run.write_to(
                [s2],
                move |s, [s2]| {
                    let others = s2 - s.c * s.c;
                    let dfdphi =
                        coef.free_energy_derivative(s.c, s.laplacian(), area_factor, others);
                    [rhs(half_v, [s.diff_x(), s.diff_y()], dfdphi)]
                },
                [flat],
            ),
            // Adhesion and walls: their derivative `a φ + b + c ∇²φ` (see `NodeTerms`),
            // with `a` and `b` gathered beside the patch (a branch outside the node loops).
            Some(NodeTerms { a, b, c_lap }) => NODE_TERMS.with_borrow_mut(|extra| {
                extra.prepare(shape);
                extra.gather(xs, g.cell_runs(i), |x| {
                    [&a[x * ly..(x + 1) * ly], &b[x * ly..(x + 1) * ly]]
                });
                let [ea, eb] = extra.gathered();
                run.write_to(
                    [s2, ea, eb],
                    move |s, [s2, ea, eb]| {
                        let others = s2 - s.c * s.c;
                        let lap = s.laplacian();
                        let dfdphi = coef.free_energy_derivative(s.c, lap, area_factor, others)
                            + node_derivative(ea, eb, c_lap, s.c, lap);
                        [rhs(half_v, [s.diff_x(), s.diff_y()], dfdphi)]
                    },
                    [flat],
                )
            }),
        }
        padded.store(out);
    });
}

/// The node terms' coefficients for one class of cells, summed over its terms
/// ([`crate::node_terms`]): `δF_node/δφ_i = a φ_i + b + c ∇²φ_i`, with the lattice fields `a`
/// and `b` (index `x * ly + y`) and the constant `c`.
#[derive(Debug, Clone, Copy)]
struct NodeTerms<'a> {
    a: &'a [f64],
    b: &'a [f64],
    c_lap: f64,
}

/// The node terms' coefficients of every class: `a_p`, `b_p` at fields `2p`, `2p + 1` of
/// `fields` (`nodes` values each) and `[k_p, c_p]` in `constants`.
struct ClassCoefficients<'a> {
    fields: &'a [f64],
    constants: &'a [[f64; 2]],
    nodes: usize,
}

impl ClassCoefficients<'_> {
    /// The coefficients of class `p`.
    fn of_class(&self, p: usize) -> NodeTerms<'_> {
        let n = self.nodes;
        NodeTerms {
            a: &self.fields[2 * p * n..(2 * p + 1) * n],
            b: &self.fields[(2 * p + 1) * n..(2 * p + 2) * n],
            c_lap: self.constants[p][1],
        }
    }
}

/// The terms' `a_p` and `b_p` of every class into `out` (two lattice fields of `nodes` values
/// per class, as [`ClassCoefficients`] reads them), each term adding its own in the order of
/// `terms`, reading its part of `scratch` ([`NodeTerm::scratch_fields`]). A term whose
/// coefficients are the same for every class is asked for population 0.
fn fill_node_terms(
    terms: &[Option<&dyn NodeTerm>],
    scratch: &[f64],
    nodes: usize,
    out: &mut [f64],
) {
    const CHUNK: usize = 4096;
    for (p, class) in out.chunks_exact_mut(2 * nodes).enumerate() {
        let (a, b) = class.split_at_mut(nodes);
        a.par_chunks_mut(CHUNK)
            .zip(b.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (a, b))| {
                a.fill(0.0);
                b.fill(0.0);
                // Each term with its part of the scratch, in order.
                let mut start = 0;
                for t in terms.iter().flatten() {
                    let len = t.scratch_fields() * nodes;
                    let asked = if t.per_population() { p } else { 0 };
                    t.add_coefficients(asked, &scratch[start..start + len], c * CHUNK, a, b);
                    start += len;
                }
            });
    }
}

/// The node terms' derivative at a node, `a φ + b + c ∇²φ` ([`NodeTerms`]; the Laplacian
/// part in the form of adhesion's, `equations::adhesion_derivative`, which it was first).
#[inline(always)]
fn node_derivative(a: f64, b: f64, c_lap: f64, phi: f64, laplacian: f64) -> f64 {
    a * phi + b + adhesion_derivative(c_lap, 0.0, laplacian)
}

/// `[min φ, max φ]` of a field, with a non-finite value reported as the range
/// `[−∞, +∞]`, so that a check of the range also catches NaN (the step's check after its
/// last corrector). Eight interleaved lanes, which compile to packed min/max; exact in any
/// order.
pub(crate) fn field_range<T: Real>(phi: &[T]) -> [f64; 2] {
    const L: usize = 8;
    let mut lo = [f64::INFINITY; L];
    let mut hi = [f64::NEG_INFINITY; L];
    // NaN is neither below nor above anything: counted apart, as `v != v`.
    let mut nan = [false; L];
    let chunks = phi.chunks_exact(L);
    let tail = chunks.remainder();
    for c in chunks {
        for j in 0..L {
            let v = c[j].to_f64();
            lo[j] = if v < lo[j] { v } else { lo[j] };
            hi[j] = if v > hi[j] { v } else { hi[j] };
            nan[j] |= v.is_nan();
        }
    }
    for (j, v) in tail.iter().enumerate() {
        let v = v.to_f64();
        lo[j] = if v < lo[j] { v } else { lo[j] };
        hi[j] = if v > hi[j] { v } else { hi[j] };
        nan[j] |= v.is_nan();
    }
    if nan.iter().any(|&n| n) {
        return [f64::NEG_INFINITY, f64::INFINITY];
    }
    [
        lo.iter().copied().fold(f64::INFINITY, f64::min),
        hi.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    ]
}
