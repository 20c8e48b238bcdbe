//! An error-controlled time step: Heun's method with its Euler predictor as the embedded
//! lower-order solution, a max-norm of their difference, and a PI step-size controller.
//!
//! One attempt of size `h` from `φ` computes `k1 = R(φ)`, the predictor `φ* = φ + h k1`
//! (forward Euler, order 1), `k2 = R(φ*)` and the corrector `φ⁺ = φ + h/2 (k1 + k2)` (Heun,
//! order 2). Their difference `φ⁺ − φ* = h/2 (k2 − k1)` estimates the local error of the
//! Euler step, `O(h²)`; the step keeps the Heun solution (local extrapolation). The error of
//! an attempt is
//!
//! `err = max over cells and nodes |h/2 (k2 − k1)| / tolerance`,
//!
//! accepted when `err ≤ 1`. A maximum is exact in any order, so the error, every decision of
//! the controller and the whole trajectory are bit-identical for any number of threads.
//!
//! The next step is, after Gustafsson's PI controller in the form of Hairer & Wanner (II,
//! IV.2), with `k = 2` the order of the estimate plus one:
//!
//! `h_new = h · clamp(safety · err^(−0.7/k) · err_prev^(0.4/k), 0.2, 2)`,
//!
//! not larger than `h` after a rejection, and within `[dt_min, dt_max]`. A rejected attempt
//! restores `φ` exactly (the state is swapped back, not recomputed) and retries with
//! `h · max(0.2, safety · err^(−1/k))`, reusing `k1`. A step is clipped to land exactly on
//! the time the caller asks for (an output time) without changing the controller's proposal.

use phasefield::Real;

use crate::step::StepCheck;
use crate::tissue::Tissue;
use crate::workspace::Workspace;
use crate::StepError;

/// The settings of the adaptive time step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct AdaptiveParams {
    /// The largest local error allowed per step, in units of φ (max-norm over cells and
    /// nodes of the Heun–Euler difference).
    pub tolerance: f64,
    /// The smallest step; a step that would need less stops the run with
    /// [`StepError::StepTooSmall`].
    pub dt_min: f64,
    /// The largest step (a stability cap: the error estimate of an explicit method sees an
    /// instability only once it grows).
    pub dt_max: f64,
    /// The safety factor of the controller.
    pub safety: f64,
}

impl AdaptiveParams {
    /// Adaptive steps with the local error tolerance `tolerance`, steps in `[1e-6, dt_max]`,
    /// safety 0.9.
    pub fn new(tolerance: f64, dt_max: f64) -> Self {
        Self {
            tolerance,
            dt_min: 1e-6,
            dt_max,
            safety: 0.9,
        }
    }
}

/// The state of the step-size controller: what a checkpoint must keep for a bitwise resume.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Controller {
    /// The step the next attempt tries.
    pub dt: f64,
    /// The error of the last accepted step (1 before the first).
    pub err_prev: f64,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected attempts.
    pub rejected: u64,
    /// Whether the last attempt was rejected (the next step then does not grow).
    pub last_rejected: bool,
}

impl Controller {
    /// A controller whose first attempt is `dt`.
    pub fn new(dt: f64) -> Self {
        Self {
            dt,
            err_prev: 1.0,
            accepted: 0,
            rejected: 0,
            last_rejected: false,
        }
    }

    /// A controller as a checkpoint kept it ([`Controller::to_array`]).
    pub fn from_array(a: [f64; 5]) -> Self {
        Self {
            dt: a[0],
            err_prev: a[1],
            accepted: a[2] as u64,
            rejected: a[3] as u64,
            last_rejected: a[4] != 0.0,
        }
    }

    /// The controller as five numbers, `[dt, err_prev, accepted, rejected, last_rejected]`,
    /// exact in f64 (the counts below 2⁵³).
    pub fn to_array(&self) -> [f64; 5] {
        [
            self.dt,
            self.err_prev,
            self.accepted as f64,
            self.rejected as f64,
            f64::from(u8::from(self.last_rejected)),
        ]
    }

    /// Evaluations of the right-hand side so far: two per attempt, one fewer per rejection
    /// (a retry reuses `k1`).
    pub fn evaluations(&self) -> u64 {
        2 * self.accepted + self.rejected
    }
}

/// Order of the error estimate plus one.
const K: f64 = 2.0;

impl<T: Real> Tissue<T> {
    /// One accepted adaptive step (Heun with one corrector, error-controlled; see
    /// [`crate::adaptive`]), ending no later than `t_end` (ignored when it is not ahead of the
    /// clock), with the check at the chokepoint. Returns the step taken. Allocates nothing.
    ///
    /// # Errors
    /// What `check` returns, or [`StepError::StepTooSmall`] when the error cannot be met with
    /// a step of at least `dt_min`; the tissue is then left at the last good state.
    pub fn step_adaptive(
        &mut self,
        ws: &mut Workspace<T>,
        params: &AdaptiveParams,
        ctrl: &mut Controller,
        t_end: f64,
        check: &mut (impl StepCheck + ?Sized),
    ) -> Result<f64, StepError> {
        // max/min rather than clamp: no panic on bounds a caller got wrong.
        ctrl.dt = ctrl.dt.max(params.dt_min).min(params.dt_max);
        // A t_end not ahead of the clock lands nowhere (a step never goes back).
        let remaining = if t_end > self.time {
            t_end - self.time
        } else {
            f64::INFINITY
        };
        // Land exactly on t_end when the proposal reaches it (or nearly).
        let attempt = |dt: f64| {
            let lands = dt >= remaining * (1.0 - 1e-12);
            (lands, if lands { remaining } else { dt })
        };
        // The first attempt's predictor is written by the evaluation of k1 (`Post::Predict`);
        // after a rejection `predict` writes the next one from the same k1.
        self.start_step(ws, ctrl.dt, Some(attempt(ctrl.dt).1), check)?;
        let mut first = true;
        loop {
            let (lands, h) = attempt(ctrl.dt);
            if !first {
                self.predict(ws, h);
            }
            first = false;
            let diff = match self.correct::<true>(ws, h) {
                Ok(d) => d,
                Err(slot) => return Err(self.abandon_step(ws, slot)),
            };
            let err = 0.5 * h * diff / params.tolerance;
            if err <= 1.0 {
                // The controller adapts the proposal only from full (unclipped) steps.
                if !lands || h >= ctrl.dt * (1.0 - 1e-12) {
                    let err = err.max(1e-10);
                    let fac = params.safety * err.powf(-0.7 / K) * ctrl.err_prev.powf(0.4 / K);
                    let fac = if ctrl.last_rejected {
                        fac.min(1.0)
                    } else {
                        fac
                    };
                    ctrl.dt = (ctrl.dt * fac.clamp(0.2, 2.0))
                        .max(params.dt_min)
                        .min(params.dt_max);
                    ctrl.err_prev = err;
                }
                if let Some(b) = check.phi_bound() {
                    self.check_new_state(ws, h, b)?;
                }
                ctrl.accepted += 1;
                ctrl.last_rejected = false;
                self.iteration += 1;
                self.time = if lands { t_end } else { self.time + h };
                self.update_centres(&ws.com);
                return Ok(h);
            }
            ctrl.rejected += 1;
            ctrl.last_rejected = true;
            let fac = (params.safety * err.powf(-1.0 / K)).clamp(0.2, 0.9);
            let next = h * fac;
            // NaN (a blow-up inside the attempt) stops too.
            if next.is_nan() || next < params.dt_min {
                // Back to the last good state.
                self.cells.swap_phi(&mut ws.phi_old);
                self.ext.terms.restore();
                return Err(StepError::StepTooSmall {
                    step: self.iteration,
                    time: self.time,
                    dt: next,
                    tolerance: params.tolerance,
                });
            }
            ctrl.dt = next;
        }
    }
}
