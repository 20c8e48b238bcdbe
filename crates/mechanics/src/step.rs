//! The time step (Heun's predictor–corrector, docs/model.md §4), the check at its chokepoint, and
//! the evaluations that observe a state without stepping it.

use phasefield::{ComTable, Real};
use rayon::prelude::*;

use crate::equations::{adhesion_coefficient, heun_corrector, heun_predictor, wall_coefficients};
use crate::evaluation::{CellState, N_SUMS};
use crate::kernels::{evaluate, EvalInput, EvalScratch, Post};
use crate::node_terms::{Adhesion, NodeTerm, PairAdhesion, PairRepulsion, WallTerm};
use crate::params::StepParams;
use crate::scatter::LatticeSums;
use crate::terms::CellsView;
use crate::tissue::Tissue;
use crate::workspace::{TermScratch, Workspace};
use crate::StepError;

/// The parts of the model an evaluation includes: all of them in a step; one at a time in
/// the evaluations that split the force by origin (`crate::origins`). The tissue pressure of
/// the passive model (interfaces, area, repulsion) is always in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Included {
    pub(crate) shape_activity: bool,
    pub(crate) nematic: bool,
    pub(crate) adhesion: bool,
    pub(crate) walls: bool,
    pub(crate) cell_forces: bool,
    pub(crate) friction: bool,
}

impl Included {
    /// Every part.
    pub(crate) const ALL: Included = Included {
        shape_activity: true,
        nematic: true,
        adhesion: true,
        walls: true,
        cell_forces: true,
        friction: true,
    };

    /// The passive model alone.
    pub(crate) const NONE: Included = Included {
        shape_activity: false,
        nematic: false,
        adhesion: false,
        walls: false,
        cell_forces: false,
        friction: false,
    };
}

/// How far outside `[0, 1]` a phase field may go before the step is declared unstable.
///
/// Central-difference advection lets φ reach about −0.05 and 1.5 at ζ = 0.01 in stable runs
/// (runs of the authors' reference code); a value beyond `−2` or `3` only occurs on the way
/// to a blow-up.
pub const PHI_BOUND: f64 = 2.0;

/// A check at the step chokepoint: called with the per-cell quantities of the step's first
/// evaluation of the current state, before anything is overwritten, so that an error leaves
/// the tissue at the last good state (after rapier's quarantine and Oceananigans' NaN
/// checker, never inside a kernel).
///
/// `()` checks nothing; [`StateCheck`] is the default.
pub trait StepCheck: Send {
    /// Checks the state about to be stepped.
    ///
    /// # Errors
    /// The reason not to take the step.
    fn check(&mut self, at: CheckPoint, cells: &[CellState]) -> Result<(), StepError>;

    /// The band `b` that the new state of a step must stay in, `[−b, 1 + b]`, finite, checked
    /// after the step before it replaces the old one (so that a blow-up in a run's last step
    /// is an error too, and the tissue keeps the last good state); `None` (the default) for
    /// no check after the step.
    fn phi_bound(&self) -> Option<f64> {
        None
    }
}

/// Where a [`StepCheck`] is called: the clock of the state about to be stepped and the step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct CheckPoint {
    /// Steps taken so far.
    pub iteration: u64,
    /// Model time.
    pub time: f64,
    /// The time step about to be taken.
    pub dt: f64,
}

impl StepCheck for () {
    fn check(&mut self, _: CheckPoint, _: &[CellState]) -> Result<(), StepError> {
        Ok(())
    }
}

/// The default check: every area, force and field range is finite
/// ([`StepError::NonFinite`]), and every field stays inside `[−bound, 1 + bound]`
/// ([`StepError::Unstable`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateCheck {
    /// The band around `[0, 1]` (default [`PHI_BOUND`]).
    pub bound: f64,
}

impl Default for StateCheck {
    fn default() -> Self {
        Self { bound: PHI_BOUND }
    }
}

impl StepCheck for StateCheck {
    fn check(&mut self, at: CheckPoint, cells: &[CellState]) -> Result<(), StepError> {
        let b = self.bound;
        for (i, c) in cells.iter().enumerate() {
            let finite = c.area.is_finite()
                && c.force.iter().all(|f| f.is_finite())
                && c.cell_force.iter().all(|f| f.is_finite())
                && c.phi_min.is_finite()
                && c.phi_max.is_finite();
            if !finite {
                return Err(StepError::NonFinite {
                    step: at.iteration,
                    time: at.time,
                    cell_idx: i,
                });
            }
            if c.phi_min < -b || c.phi_max > 1.0 + b {
                return Err(StepError::Unstable {
                    step: at.iteration,
                    time: at.time,
                    cell_idx: i,
                    phi: if c.phi_min < -b { c.phi_min } else { c.phi_max },
                    dt: at.dt,
                });
            }
        }
        Ok(())
    }

    fn phi_bound(&self) -> Option<f64> {
        Some(self.bound)
    }
}

/// The error of a state at `(step, time)` whose slot `slot` has the range `range` outside
/// `[−b, 1 + b]` (or a non-finite centre, `nan`): [`StepError::NonFinite`] when anything is
/// not finite, [`StepError::Unstable`] with the offending bound otherwise.
fn range_error(
    slot: usize,
    range: [f64; 2],
    nan: bool,
    (step, time): (u64, f64),
    dt: f64,
    b: f64,
) -> StepError {
    if nan || !range[0].is_finite() || !range[1].is_finite() {
        StepError::NonFinite {
            step,
            time,
            cell_idx: slot,
        }
    } else {
        StepError::Unstable {
            step,
            time,
            cell_idx: slot,
            phi: if range[0] < -b { range[0] } else { range[1] },
            dt,
        }
    }
}

/// Whether a field's range `[min, max]` is finite and inside `[−b, 1 + b]`.
fn range_ok(range: [f64; 2], b: f64) -> bool {
    range[0] >= -b && range[1] <= 1.0 + b
}

impl<T: Real> Tissue<T> {
    /// Advances the state by one time step `dt` with `npc` Heun corrector passes, with the
    /// default [`StateCheck`] at the chokepoint.
    ///
    /// Allocates nothing. On error the tissue is left at the last good state.
    ///
    /// # Errors
    /// [`StepError::NonFinite`] if a cell's area or force is not finite, and
    /// [`StepError::Unstable`] if a field has left `[−PHI_BOUND, 1 + PHI_BOUND]`.
    pub fn step(
        &mut self,
        ws: &mut Workspace<T>,
        step_params: &StepParams,
    ) -> Result<(), StepError> {
        self.step_checked(ws, step_params, &mut StateCheck::default())
    }

    /// [`Tissue::step`] with the given check at the chokepoint (`&mut ()` for none).
    ///
    /// # Errors
    /// Whatever `check` returns; the tissue is then left unchanged.
    pub fn step_checked(
        &mut self,
        ws: &mut Workspace<T>,
        step_params: &StepParams,
        check: &mut (impl StepCheck + ?Sized),
    ) -> Result<(), StepError> {
        let dt = step_params.dt;
        // The predictor and the last corrector pass are fused into the evaluations before
        // them (`Post`): two sweeps over every field and two parallel loops fewer per step
        // (tested to be the separate sweeps to the bit). Adhesion and walls add their
        // derivative inside the force pass too (`kernels::NodeTerms`).
        self.start_step(ws, dt, Some(dt), check)?;
        // The check after the step (issue 53): the new state is finite and inside the band,
        // before it replaces the old one, so that a step that blows up (the last of a run
        // included) leaves the last good state and says so.
        let bound = check.phi_bound();
        // With friction between cells every corrector is the separate sweep (the evaluation
        // must finish its velocities before the update).
        let fused = self.ext.friction.is_none();
        for pass in 0..step_params.npc {
            if pass + 1 < step_params.npc || !fused {
                if let Err(slot) = self.correct::<false>(ws, dt) {
                    return Err(self.abandon_step(ws, slot));
                }
            } else {
                self.correct_last(ws, dt, bound)?;
            }
        }
        if step_params.npc == 0 || !fused {
            if let Some(b) = bound {
                self.check_new_state(ws, dt, b)?;
            }
        }
        self.advance_clock(dt);
        if step_params.npc > 0 && fused {
            // The last corrector pass measured the new centres (`Post::Correct`).
            self.move_patches_to(&ws.next_centre);
        } else {
            self.update_centres(&ws.com);
        }
        Ok(())
    }

    /// The start of a step of size `dt`: `k1 = R(φ)` of the current state into `ws.k1`, the
    /// check at the chokepoint, then the state moved into `ws.phi_old` without a copy.
    ///
    /// With `predict = Some(h)` the fields are then the predictor `φ + h k1`, which the
    /// evaluation wrote cell by cell into the spare buffer (`ws.phi_old` before the swap), so
    /// that a failed check still leaves the state untouched. With `None` the fields hold
    /// whatever the spare buffer held, for [`Tissue::predict`] to overwrite.
    ///
    /// # Errors
    /// Whatever `check` returns; the tissue is then unchanged.
    pub(crate) fn start_step(
        &mut self,
        ws: &mut Workspace<T>,
        dt: f64,
        predict: Option<f64>,
        check: &mut (impl StepCheck + ?Sized),
    ) -> Result<(), StepError> {
        let Workspace {
            phi_old,
            k1,
            sums,
            cell_state,
            term_scratch,
            ..
        } = ws;
        // With friction between cells the predictor is a sweep of its own, after the
        // velocities are solved (below).
        let fused = self.ext.friction.is_none();
        let post = match predict {
            Some(h) if fused => Post::Predict { h, out: phi_old },
            _ => Post::Nothing,
        };
        let shapes = self.step_needs_shapes();
        // (Stage 0 never refuses: the check below reports a force that is not finite.)
        let _ = self.evaluate_fields(shapes, k1, sums, cell_state, term_scratch, post, 0.0, None);
        let at = CheckPoint {
            iteration: self.iteration,
            time: self.time,
            dt,
        };
        check.check(at, cell_state)?;
        if !self.ext.terms.is_empty() {
            if let Some((term, stiffness, cell)) =
                self.ext.terms.stiffest(&self.terms_view(cell_state, 0.0))
            {
                if stiffness.is_nan() || stiffness * dt > 2.0 {
                    return Err(StepError::TermUnstable {
                        step: self.iteration,
                        time: self.time,
                        term: term.to_string(),
                        cell,
                        stiffness,
                        dt,
                    });
                }
            }
        }
        self.cells.swap_phi(phi_old);
        if !self.ext.terms.is_empty() {
            let (terms, view) = self.terms_and_view(cell_state);
            terms.begin(&view);
        }
        if let Some(h) = predict {
            self.ext.terms.predict(h);
            if !fused {
                self.predict_fields(ws, h);
            }
        }
        Ok(())
    }

    /// The walls in effect, with their coefficients.
    fn wall_term(&self) -> Option<WallTerm<'_>> {
        let walls = self.ext.walls.as_ref()?;
        Some(WallTerm {
            field: walls.field(self.active)?,
            coefficients: wall_coefficients(walls.kappa, walls.omega, self.params.energy.lambda),
        })
    }

    /// What the terms see of every slot, with the per-cell quantities `cells`.
    pub(crate) fn terms_view<'a>(&'a self, cells: &'a [CellState], stage: f64) -> CellsView<'a> {
        CellsView {
            time: self.time + stage,
            stage,
            cells,
            by_id: None,
            ids: &self.cell_id,
            centres: &self.centre,
            centre_of: None,
            active: self.active,
            populations: &self.ext.populations,
            iteration: self.iteration,
        }
    }

    /// The terms, to change their state, with what they see of every slot (the per-cell
    /// quantities `cells`): borrowed from disjoint fields of the tissue, so nothing is moved.
    fn terms_and_view<'a>(
        &'a mut self,
        cells: &'a [CellState],
    ) -> (&'a mut crate::terms::Terms, CellsView<'a>) {
        let view = CellsView {
            time: self.time,
            stage: 0.0,
            cells,
            by_id: None,
            ids: &self.cell_id,
            centres: &self.centre,
            centre_of: None,
            active: self.active,
            populations: &self.ext.populations,
            iteration: self.iteration,
        };
        (&mut self.ext.terms, view)
    }

    /// Back to the state before the step, from a corrector whose evaluation refused to start
    /// (a whole-cell force of slot `slot` not finite: see [`Tissue::evaluate_fields`]): the
    /// fields hold a predicted or corrected state and `ws.phi_old` the step's start, which
    /// nothing has overwritten yet; the terms go back to the state they saved at the start.
    pub(crate) fn abandon_step(&mut self, ws: &mut Workspace<T>, slot: usize) -> StepError {
        self.cells.swap_phi(&mut ws.phi_old);
        self.ext.terms.restore();
        StepError::NonFinite {
            step: self.iteration,
            time: self.time,
            cell_idx: slot,
        }
    }

    /// The last corrector pass of a fixed step of size `h`: `k2 = R(φ)` of the predicted
    /// fields, with `φ_old + h/2 (k1 + k2)` written over `ws.k1` cell by cell right after
    /// each cell's `k2`, its centre of mass into `ws.next_centre` and its range into
    /// `ws.next_range`; then, when the new state passes the check after the step (`bound`:
    /// see [`StepCheck::phi_bound`]), swapped in: the fields hold the new state, `ws.phi_old`
    /// the old one and `ws.k1` the predicted one. (The adaptive step, which may have to go
    /// back to `φ_old`, and the earlier passes of several use [`Tissue::correct`].)
    ///
    /// # Errors
    /// A whole-cell force that is not finite, with nothing overwritten (see
    /// [`Tissue::abandon_step`]), or a new state that fails the check: the tissue is then
    /// back at the step's start, the last good state.
    pub(crate) fn correct_last(
        &mut self,
        ws: &mut Workspace<T>,
        h: f64,
        bound: Option<f64>,
    ) -> Result<(), StepError> {
        let Workspace {
            phi_old,
            k1,
            k2,
            sums,
            cell_state,
            com,
            next_centre,
            next_range,
            term_scratch,
            ..
        } = ws;
        if let Err(slot) = self.evaluate_fields(
            self.step_needs_shapes(),
            k2,
            sums,
            cell_state,
            term_scratch,
            Post::Correct {
                h,
                k1,
                old: phi_old,
                com,
                centres: next_centre,
                ranges: next_range,
            },
            h,
            Some(com),
        ) {
            return Err(self.abandon_step(ws, slot));
        }
        if let Some(b) = bound {
            let bad = next_range
                .iter()
                .zip(next_centre.iter())
                .position(|(r, c)| !range_ok(*r, b) || !c.iter().all(|x| x.is_finite()));
            if let Some(slot) = bad {
                let (range, centre) = (next_range[slot], next_centre[slot]);
                let nan = !centre.iter().all(|x| x.is_finite());
                let err = self.after_step_error(slot, range, nan, h, b);
                // The fields hold the predicted state and `phi_old` the step's start.
                return Err(self.abandon_with(ws, err));
            }
        }
        self.cells.swap_phi(k1);
        if !self.ext.terms.is_empty() {
            let (terms, view) = self.terms_and_view(cell_state);
            terms.correct(&view, h);
        }
        Ok(())
    }

    /// The error of a new state (the step from `self.iteration` of size `h`) whose slot
    /// `slot` has the range `range` (or a non-finite centre, `nan`), outside `[−b, 1 + b]`.
    fn after_step_error(
        &self,
        slot: usize,
        range: [f64; 2],
        nan: bool,
        h: f64,
        b: f64,
    ) -> StepError {
        range_error(slot, range, nan, (self.iteration + 1, self.time + h), h, b)
    }

    /// The check after a step whose new state is in the fields (a sweep of its own: the
    /// adaptive step and Euler's; the fixed Heun step checks inside its last corrector).
    ///
    /// # Errors
    /// A slot outside `[−b, 1 + b]` or not finite; the tissue is then back at the step's
    /// start, from `ws.phi_old`.
    pub(crate) fn check_new_state(
        &mut self,
        ws: &mut Workspace<T>,
        h: f64,
        b: f64,
    ) -> Result<(), StepError> {
        match self.first_out_of_band(b) {
            Some((slot, range)) => {
                let err = self.after_step_error(slot, range, false, h, b);
                Err(self.abandon_with(ws, err))
            }
            None => Ok(()),
        }
    }

    /// Checks the fields as they are: every value finite and inside `[−b, 1 + b]`
    /// ([`PHI_BOUND`] by default). A backend's driver checks the state it brings back with
    /// it, since the device's own check runs at the start of each step only.
    ///
    /// # Errors
    /// [`StepError::NonFinite`] or [`StepError::Unstable`] for the first slot that is not,
    /// at the tissue's clock.
    pub fn check_state(&self, b: f64, dt: f64) -> Result<(), StepError> {
        match self.first_out_of_band(b) {
            Some((slot, range)) => Err(range_error(
                slot,
                range,
                false,
                (self.iteration, self.time),
                dt,
                b,
            )),
            None => Ok(()),
        }
    }

    /// The first slot whose field is not finite or leaves `[−b, 1 + b]`, with its range.
    fn first_out_of_band(&self, b: f64) -> Option<(usize, [f64; 2])> {
        let plen = self.cells.patch_len();
        let phi = self.cells.phi();
        let slot = phi
            .par_chunks(plen)
            .position_first(|c| !range_ok(crate::kernels::field_range(c), b))?;
        Some((
            slot,
            crate::kernels::field_range(&phi[slot * plen..(slot + 1) * plen]),
        ))
    }

    /// Back to the step's start (in `ws.phi_old`) from a predicted or corrected state that
    /// failed its check, with `err` as the reason.
    fn abandon_with(&mut self, ws: &mut Workspace<T>, err: StepError) -> StepError {
        self.cells.swap_phi(&mut ws.phi_old);
        self.ext.terms.restore();
        err
    }

    /// The predictor `φ = φ_old + h k1` (forward Euler) from what [`Tissue::start_step`]
    /// left in `ws`.
    pub(crate) fn predict(&mut self, ws: &Workspace<T>, h: f64) {
        self.ext.terms.predict(h);
        self.predict_fields(ws, h);
    }

    /// The fields' part of [`Tissue::predict`].
    fn predict_fields(&mut self, ws: &Workspace<T>, h: f64) {
        let phi = self.cells.phi_mut();
        phi.par_iter_mut()
            .zip(ws.phi_old.par_iter().zip(ws.k1.par_iter()))
            .for_each(|(p, (o, r))| *p = T::from_f64(heun_predictor(o.to_f64(), h, r.to_f64())));
    }

    /// A corrector pass of a step of size `h`: `k2 = R(φ)` of the fields as they are (the
    /// predicted state), then `φ = φ_old + h/2 (k1 + k2)`. With `ESTIMATE`, also returns
    /// `max |k2 − k1|` over every node (the adaptive step's error estimate; a maximum is exact
    /// in any order), otherwise 0 without computing it.
    ///
    /// # Errors
    /// As [`Tissue::correct_last`]; the fields are then still the predicted ones.
    pub(crate) fn correct<const ESTIMATE: bool>(
        &mut self,
        ws: &mut Workspace<T>,
        h: f64,
    ) -> Result<f64, usize> {
        let Workspace {
            phi_old,
            k1,
            k2,
            sums,
            cell_state,
            term_scratch,
            com,
            ..
        } = ws;
        self.evaluate_fields(
            self.step_needs_shapes(),
            k2,
            sums,
            cell_state,
            term_scratch,
            Post::Nothing,
            h,
            Some(com),
        )?;
        if !self.ext.terms.is_empty() {
            let (terms, view) = self.terms_and_view(cell_state);
            terms.correct(&view, h);
        }
        let updates = self
            .cells
            .phi_mut()
            .par_iter_mut()
            .zip(phi_old.par_iter())
            .zip(k1.par_iter().zip(k2.par_iter()));
        Ok(if ESTIMATE {
            updates
                .map(|((p, o), (r1, r2))| {
                    let (r1, r2) = (r1.to_f64(), r2.to_f64());
                    *p = T::from_f64(heun_corrector(o.to_f64(), h, r1, r2));
                    (r2 - r1).abs()
                })
                .reduce(|| 0.0, f64::max)
        } else {
            updates.for_each(|((p, o), (r1, r2))| {
                *p = T::from_f64(heun_corrector(o.to_f64(), h, r1.to_f64(), r2.to_f64()))
            });
            0.0
        })
    }

    /// Whether a step computes the deformation tensors and `Q`: only the active force uses
    /// them (see [`evaluate`]).
    fn step_needs_shapes(&self) -> bool {
        self.ext.populations.any_activity(&self.params, self.active) || self.ext.terms.need_shapes()
    }

    /// [`evaluate`] of the current fields, into `out` and the workspace parts given.
    fn evaluate_fields(
        &self,
        shapes: bool,
        out: &mut [T],
        sums: &mut LatticeSums<N_SUMS>,
        cell_state: &mut [CellState],
        scratch: &mut TermScratch,
        post: Post<'_, T>,
        stage: f64,
        com: Option<&ComTable>,
    ) -> Result<(), usize> {
        self.evaluate_parts(
            Included::ALL,
            shapes,
            out,
            sums,
            cell_state,
            scratch,
            post,
            stage,
            com,
        )
    }

    /// [`Tissue::evaluate_fields`] with only the parts of the model `inc` (the evaluations
    /// that split the force by origin, `crate::origins`).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn evaluate_parts(
        &self,
        inc: Included,
        shapes: bool,
        out: &mut [T],
        sums: &mut LatticeSums<N_SUMS>,
        cell_state: &mut [CellState],
        scratch: &mut TermScratch,
        post: Post<'_, T>,
        stage: f64,
        com: Option<&ComTable>,
    ) -> Result<(), usize> {
        let TermScratch {
            cell_force,
            node_scratch,
            node_terms: node_terms_buf,
            node_constants,
            population_sums,
            kind_constants,
            nematic: nematic_scratch,
            friction: friction_scratch,
        } = scratch;
        // Friction between cells couples the velocities, so the right-hand side is corrected
        // after the evaluation: never in an evaluation fused with an update (`Post`).
        let friction = self.ext.friction.as_ref().filter(|_| inc.friction);
        debug_assert!(
            friction.is_none() || matches!(post, Post::Nothing),
            "friction between cells in a fused evaluation"
        );
        // The cell nematic (docs/model.md §11.6): each slot's tensor `q_i` from the terms'
        // state of this stage (in a corrector, the predicted angles), and its active tensor
        // `ζ_Q q_i` while the activity is on.
        let nematic = self.ext.terms.nematic().filter(|_| inc.nematic);
        let cell_stress = match nematic {
            Some((nem, theta)) => {
                let n = self.cell_id.len();
                let crate::workspace::NematicScratch { q, stress, .. } = nematic_scratch;
                q.clear();
                q.extend(self.cell_id.iter().map(|&id| nem.tensor(theta[id])));
                if self.ext.terms.nematic_stress(self.active) {
                    stress.clear();
                    stress.extend((0..n).map(|slot| {
                        let z = nem.zeta_of(self.ext.populations.population(self.cell_id[slot]));
                        [z * q[slot][0], z * q[slot][1]]
                    }));
                    Some(&stress[..])
                } else {
                    None
                }
            }
            None => None,
        };
        // The node terms of this evaluation, in a fixed order (adhesion, pair repulsion, then
        // walls: the order their pressures and coefficients are added in).
        // Adhesion: one ω for every pair, or an ω for each pair of populations (the scene
        // gives one or the other).
        let adhesion = (inc.adhesion && self.params.omega != 0.0).then(|| Adhesion {
            c: adhesion_coefficient(self.params.omega, self.params.energy.lambda),
        });
        let pair_adhesion = self
            .ext
            .populations
            .adhesion()
            .filter(|_| inc.adhesion)
            .map(|m| {
                PairAdhesion::new(
                    m,
                    self.ext.populations.kinds().len(),
                    self.params.energy.lambda,
                )
            });
        // Repulsion by pair of populations: part of the passive model, always in.
        let pair_repulsion = self.ext.populations.repulsion().map(|m| {
            PairRepulsion::new(
                m,
                self.ext.populations.kinds().len(),
                self.params.energy.lambda,
                self.params.energy.kappa,
                self.params.pressure,
            )
        });
        let walls = self.wall_term().filter(|_| inc.walls);
        let node_terms: [Option<&dyn NodeTerm>; 4] = [
            adhesion.as_ref().map(|t| t as &dyn NodeTerm),
            pair_adhesion.as_ref().map(|t| t as &dyn NodeTerm),
            pair_repulsion.as_ref().map(|t| t as &dyn NodeTerm),
            walls.as_ref().map(|t| t as &dyn NodeTerm),
        ];
        // Their lattice scratch, made on its first use (the one allocation of a run with
        // adhesion).
        let nodes = self.lattice().len();
        let n: usize = node_terms
            .iter()
            .flatten()
            .map(|t| t.scratch_fields() * nodes)
            .sum();
        if node_scratch.len() != n {
            node_scratch.resize(n, 0.0);
        }
        // Their coefficients, two fields per class (made on first use too).
        let classes = crate::node_terms::classes(&node_terms, &self.ext.populations);
        let m = if node_terms.iter().any(Option::is_some) {
            2 * classes * nodes
        } else {
            0
        };
        if node_terms_buf.len() != m {
            node_terms_buf.resize(m, 0.0);
        }
        // The terms' whole-cell forces of the current state, from the per-cell quantities the
        // last evaluation left (see `CellContext::state`).
        let cell_force = if self.ext.terms.is_empty() || !inc.cell_forces {
            None
        } else {
            // In a corrector the fields are the predicted state: its centres of mass,
            // measured only for a term that asks for them.
            let predicted = |slot: usize| match com {
                Some(com) => com.cell_centre(&self.cells, slot),
                None => self.centre[slot],
            };
            let mut view = self.terms_view(cell_state, stage);
            view.centre_of = Some(&predicted);
            self.ext.terms.forces(&view, cell_force);
            // In a corrector (`stage > 0`), a force that is not finite refuses the evaluation
            // before the fused corrector overwrites the step's start (`Post::Correct`), so that
            // the step can go back to it (`Tissue::abandon_step`). At the step's start the
            // chokepoint's check reports it (`StateCheck`).
            if stage > 0.0 {
                if let Some(slot) = cell_force
                    .iter()
                    .position(|f| !(f[0].is_finite() && f[1].is_finite()))
                {
                    return Err(slot);
                }
            }
            Some(&cell_force[..])
        };
        let input = EvalInput {
            params: &self.params,
            cells: &self.cells,
            phi: self.cells.phi(),
            shapes,
            shape_activity: inc.shape_activity,
            cell_force,
            cell_stress,
            populations: &self.ext.populations,
            ids: &self.cell_id,
            active: self.active,
            growth: &self.ext.target_scale,
            node_terms: &node_terms,
            wall_friction: self.ext.walls.as_ref().and_then(|w| {
                (w.friction != 0.0)
                    .then(|| w.field(self.active).map(|f| (f, w.friction)))
                    .flatten()
            }),
        };
        let scratch = EvalScratch {
            sums,
            cell_state,
            node_scratch,
            node_coefficients: node_terms_buf,
            node_constants,
            population_sums,
            kind_constants,
        };
        evaluate(&input, out, scratch, post);
        if let Some(f) = friction {
            let crate::workspace::FrictionScratch {
                pairs,
                before,
                solve,
            } = friction_scratch;
            crate::friction::pair_overlaps(&self.cells, pairs);
            before.clear();
            before.extend(cell_state.iter().map(|s| [s.velocity.x, s.velocity.y]));
            *solve = crate::friction::solve(cell_state, pairs, f);
            crate::friction::correct_rhs(&self.cells, out, before, cell_state);
        }
        // What the nematic's dynamics read of the fields just evaluated (the corrector wrote
        // the new state elsewhere: the fields are still those evaluated).
        if inc == Included::ALL && nematic.is_some_and(|(n, _)| n.reads_fields()) {
            let fields = nematic_scratch.fields.get_or_insert_with(|| {
                LatticeSums::for_cells(self.lattice(), self.cells.n_cells(), self.cells.shape().nx)
            });
            crate::nematic_fields::measure(
                &self.cells,
                self.cells.phi(),
                &nematic_scratch.q,
                cell_state,
                fields,
            );
        }
        Ok(())
    }

    /// Evaluates the derived quantities of the current state (areas, shapes, forces,
    /// velocities, the lattice sums) into `ws`, and measures the centres of mass of the
    /// stored values into [`Workspace::centres`], without stepping.
    ///
    /// Takes `&self`: observing never changes what the dynamics use, and the next step
    /// overwrites everything this leaves in `ws`.
    pub fn refresh(&self, ws: &mut Workspace<T>) {
        let Workspace {
            k2,
            sums,
            cell_state,
            observed_centre,
            com,
            term_scratch,
            ..
        } = ws;
        self.compute_centres_into(com, observed_centre);
        self.evaluate_fields(
            true,
            k2,
            sums,
            cell_state,
            term_scratch,
            Post::Nothing,
            0.0,
            None,
        )
        .ok();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelParams;
    use phasefield::{init, Lattice, PatchShape};

    /// Five cells on 48² with margin 8 at ζ = 0.02: active enough that patches move within the
    /// steps taken, so the centres measured inside the corrector pass decide real moves.
    fn tissue<T: Real>() -> Tissue<T> {
        let lattice = Lattice::new(48, 48);
        let shape = PatchShape::new(lattice, 8).expect("margin 8 fits 48²");
        let centres = [
            [10.0, 12.0],
            [22.5, 14.0],
            [35.0, 11.0],
            [16.0, 30.0],
            [30.5, 33.0],
        ];
        let cells = init::discs(lattice, shape, &centres, 6.0, 2.0).into_precision::<T>();
        Tissue::new(cells, ModelParams::paper(0.02))
    }

    /// The same step as separate sweeps: `start_step` without the predictor, `predict`, every
    /// corrector pass by `correct`, then the centres measured in a loop of their own.
    fn step_in_sweeps<T: Real>(t: &mut Tissue<T>, ws: &mut Workspace<T>, sp: &StepParams) {
        t.start_step(ws, sp.dt, None, &mut StateCheck::default())
            .expect("stable");
        t.predict(ws, sp.dt);
        for _ in 0..sp.npc {
            t.correct::<false>(ws, sp.dt).expect("finite forces");
        }
        t.advance_clock(sp.dt);
        t.update_centres(&ws.com);
    }

    fn fused_step_is_the_sweeps_to_the_bit<T: Real>() {
        for npc in [0, 1, 2] {
            let sp = StepParams::new(0.5, npc);
            let (mut fused, mut sweeps) = (tissue::<T>(), tissue::<T>());
            let (mut ws_f, mut ws_s) = (
                Workspace::new(fused.cells()),
                Workspace::new(sweeps.cells()),
            );
            let mut moved = 0;
            for _ in 0..40 {
                let before = fused.cells().map().origin.clone();
                fused.step(&mut ws_f, &sp).expect("stable");
                step_in_sweeps(&mut sweeps, &mut ws_s, &sp);
                moved += usize::from(fused.cells().map().origin != before);
                let same = fused
                    .cells()
                    .phi()
                    .iter()
                    .zip(sweeps.cells().phi())
                    .all(|(a, b)| a.to_f64().to_bits() == b.to_f64().to_bits());
                assert!(same, "{} npc {npc}: fields differ", T::NAME);
                assert_eq!(fused.centres(), sweeps.centres(), "{} npc {npc}", T::NAME);
                assert_eq!(fused.cells().map().origin, sweeps.cells().map().origin);
            }
            assert!(
                moved > 0,
                "{} npc {npc}: no patch moved, the test would see no move",
                T::NAME
            );
        }
    }

    /// The fixed step does its predictor, its last corrector and the centres inside the
    /// evaluations (`Post`); the values must be those of the separate sweeps, to the bit, for
    /// forward Euler, one and two corrector passes, in both storage precisions.
    #[test]
    fn the_fused_step_equals_the_separate_sweeps_to_the_bit() {
        fused_step_is_the_sweeps_to_the_bit::<f64>();
        fused_step_is_the_sweeps_to_the_bit::<f32>();
    }

    /// A tissue without line tension (γ = 0) at ζ = 0.02 and dt = 2, which blows up within
    /// a few hundred steps (nothing smooths the interfaces).
    fn blowing_up<T: Real>() -> Tissue<T> {
        let mut t = tissue::<T>();
        t.params_mut().energy.gamma = 0.0;
        t
    }

    /// Issue 53: the check runs after every step, the last one included. A step whose new
    /// state leaves the band (or is not finite) is an error, and the tissue keeps the state
    /// before it, to the bit: the last good one. The state it refused is bad (the same step
    /// taken without a check fails `check_state`), and every state before it passed. For
    /// forward Euler, one and two corrector passes, and the adaptive step.
    #[test]
    fn a_step_that_blows_up_is_an_error_and_leaves_the_last_good_state() {
        for npc in [0, 1, 2] {
            let sp = StepParams::new(2.0, npc);
            let mut t = blowing_up::<f64>();
            let mut ws = Workspace::new(t.cells());
            let mut failed = None;
            for _ in 0..3000 {
                let before = t.clone();
                match t.step(&mut ws, &sp) {
                    Ok(()) => t
                        .check_state(PHI_BOUND, sp.dt)
                        .expect("a state that passed"),
                    Err(e) => {
                        failed = Some((before, e));
                        break;
                    }
                }
            }
            let (before, err) = failed.unwrap_or_else(|| panic!("npc {npc}: no blow-up"));
            assert!(
                matches!(
                    err,
                    StepError::Unstable { .. } | StepError::NonFinite { .. }
                ),
                "{err}"
            );
            assert_eq!(t.iteration(), before.iteration(), "npc {npc}: the clock");
            assert!(
                t.cells()
                    .phi()
                    .iter()
                    .zip(before.cells().phi())
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "npc {npc}: the fields are the last good state"
            );
            assert_eq!(t.centres(), before.centres());
            // The refused step, taken without a check, makes a bad state.
            let mut unchecked = before.clone();
            let mut ws = Workspace::new(unchecked.cells());
            unchecked
                .step_checked(&mut ws, &sp, &mut ())
                .expect("no check");
            assert!(
                unchecked.check_state(PHI_BOUND, sp.dt).is_err(),
                "npc {npc}"
            );
            // Its step is the one that would have been taken.
            let step = match err {
                StepError::Unstable { step, .. } | StepError::NonFinite { step, .. } => step,
                _ => unreachable!(),
            };
            assert_eq!(step, before.iteration() + 1, "npc {npc}: {err}");
        }
    }

    /// The adaptive step checks its accepted state too.
    #[test]
    fn an_adaptive_step_that_blows_up_leaves_the_last_good_state() {
        // A tolerance so loose that every step is accepted: the check must catch the blow-up.
        let params = crate::AdaptiveParams::new(1e9, 2.0);
        let mut ctrl = crate::Controller::new(2.0);
        let mut t = blowing_up::<f64>();
        let mut ws = Workspace::new(t.cells());
        for _ in 0..3000 {
            let before = t.clone();
            match t.step_adaptive(
                &mut ws,
                &params,
                &mut ctrl,
                f64::INFINITY,
                &mut StateCheck::default(),
            ) {
                Ok(_) => t.check_state(PHI_BOUND, 2.0).expect("a state that passed"),
                Err(e) => {
                    assert!(
                        matches!(e, StepError::Unstable { .. } | StepError::NonFinite { .. }),
                        "{e}"
                    );
                    assert_eq!(t.iteration(), before.iteration());
                    assert_eq!(t.cells().phi(), before.cells().phi());
                    return;
                }
            }
        }
        panic!("no blow-up");
    }

    /// Patches are stored in logical order since issue 14, but a checkpoint written before
    /// keeps each patch's storage offset, and the step must still be right for it: the same
    /// cells stored with offsets (every patch cut inside its columns and rows) step as their
    /// logical-order copy does. Only the order of the additions in the per-cell sums differs,
    /// so the fields agree to round-off: measured 4e-16 after 40 steps, asserted at 1e-12.
    /// The offset patches are rotated into logical order when they move, which must not
    /// change a value either.
    #[test]
    fn patches_stored_with_an_offset_step_as_in_logical_order() {
        let mut start = tissue::<f64>();
        let mut ws = Workspace::new(start.cells());
        let sp = StepParams::new(0.5, 1);
        for _ in 0..10 {
            start.step(&mut ws, &sp).expect("stable");
        }
        let cells = start.cells();
        let (lattice, shape) = (cells.lattice(), cells.shape().clone());
        let (nx, ny, n) = (shape.nx, shape.ny, cells.n_cells());
        assert!(cells.map().offset.iter().all(|&f| f == [0, 0]));
        // Storage column (u + fx) mod nx, row (v + fy) mod ny holds logical node (u, v).
        let offsets: Vec<[usize; 2]> = (0..n).map(|i| [(3 + i) % nx, (5 + 2 * i) % ny]).collect();
        let mut phi = vec![0.0; cells.phi().len()];
        for (i, &[fx, fy]) in offsets.iter().enumerate() {
            let logical = cells.cell_phi(i);
            let stored = &mut phi[i * nx * ny..(i + 1) * nx * ny];
            for u in 0..nx {
                for v in 0..ny {
                    stored[(u + fx) % nx * ny + (v + fy) % ny] = logical[u * ny + v];
                }
            }
        }
        let origin = cells.map().origin.clone();
        let with_offsets = phasefield::Cells::from_storage(lattice, shape, phi, origin, offsets)
            .expect("a valid storage");
        let (mut a, mut b) = (
            Tissue::new(with_offsets, ModelParams::paper(0.02)),
            Tissue::new(cells.clone(), ModelParams::paper(0.02)),
        );
        let (mut ws_a, mut ws_b) = (Workspace::new(a.cells()), Workspace::new(b.cells()));
        let mut worst: f64 = 0.0;
        for _ in 0..40 {
            a.step(&mut ws_a, &sp).expect("stable");
            b.step(&mut ws_b, &sp).expect("stable");
            assert_eq!(a.cells().map().origin, b.cells().map().origin);
            for i in 0..n {
                for x in 0..lattice.lx {
                    for y in 0..lattice.ly {
                        let d = a.cells().value_at(i, x, y) - b.cells().value_at(i, x, y);
                        worst = worst.max(d.abs());
                    }
                }
            }
        }
        assert!(
            worst < 1e-12,
            "offset and logical storage differ by {worst:e}"
        );
        // Every offset above is non-zero, so an offset of [0, 0] is a patch rotated on a move.
        let rotated = a
            .cells()
            .map()
            .offset
            .iter()
            .filter(|&&f| f == [0, 0])
            .count();
        assert!(rotated > 0, "no patch moved, so no rotation was tested");
    }
}
