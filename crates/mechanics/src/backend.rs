//! Where the time step runs: on the host (the default, [`crate::Tissue::step`]) or on a device
//! through a [`Backend`] (the `gpu` crate's), which [`crate::Simulation::with_backend`] drives.
//!
//! A backend holds its own copy of the state and steps it there; the [`crate::Tissue`] on the
//! host keeps the clock, the parameters and the identities, and its fields are brought up to
//! date ([`Backend::sync`]) only when something on the host reads them: a callback, a writer or
//! a fix whose schedule fires, and the end of a run. Everything else about a run (schedules,
//! outputs, checkpoints, the activity switch) is the driver's, the same for every backend.

use phasefield::Real;

use crate::extensions::Part;
use crate::params::StepParams;
use crate::tissue::Tissue;
use crate::StepError;

/// A place other than the host to run the fixed time step of [`crate::Tissue::step`].
///
/// The contract:
/// - [`Backend::step`] queues one Heun step of the tissue's current parameters (read from
///   `tissue`, so that the activity switch reaches the device) and may return before it ran;
///   the driver advances the tissue's clock;
/// - [`Backend::sync`] waits for the queued steps, then writes the device's state into the
///   tissue (fields, patch origins, centres). If a queued step failed its check, the state is
///   the last good one, the clock is set back to it, and the error is the step's;
/// - [`Backend::upload`] takes the tissue's state as the device's, after the host changed it.
pub trait Backend<T: Real>: Send {
    /// A short name for messages, such as `"gpu"`.
    fn name(&self) -> &str;

    /// Whether it runs the extension `part` of the model ([`crate::Tissue::parts`]); a
    /// tissue with a part its backend does not support is refused before any step
    /// ([`unsupported`]).
    fn supports(&self, part: Part) -> bool;

    /// Queues one step of size `params.dt` with `params.npc` corrector passes.
    ///
    /// # Errors
    /// [`StepError::Backend`] when the device cannot take the step.
    fn step(&mut self, tissue: &Tissue<T>, params: &StepParams) -> Result<(), StepError>;

    /// Waits for the queued steps and writes the device's state into `tissue`.
    ///
    /// # Errors
    /// The first failed step's error (the tissue then holds the last good state, with its
    /// clock), or [`StepError::Backend`].
    fn sync(&mut self, tissue: &mut Tissue<T>) -> Result<(), StepError>;

    /// Takes `tissue`'s state as the device's.
    ///
    /// # Errors
    /// [`StepError::Backend`] when the device cannot hold it.
    fn upload(&mut self, tissue: &Tissue<T>) -> Result<(), StepError>;
}

impl<T: Real> Tissue<T> {
    /// Replaces the state with one computed elsewhere (a [`Backend`]'s): every cell's field
    /// in logical patch order (index `a * ny + b` from its origin), the patches' origins and
    /// the centres of mass. Identities, parameters and the clock are kept.
    ///
    /// # Panics
    /// If the lengths do not fit the tissue's cells and patch shape.
    pub fn set_state_from_device(
        &mut self,
        phi: &[f32],
        origins: &[[usize; 2]],
        centres: &[[f64; 2]],
    ) {
        let n = self.cells.n_cells();
        assert!(
            origins.len() == n && centres.len() == n,
            "one origin and one centre per cell"
        );
        self.cells.set_logical_origins(origins);
        let dst = self.cells.phi_mut();
        assert_eq!(dst.len(), phi.len(), "one value per patch node");
        for (d, &s) in dst.iter_mut().zip(phi) {
            *d = T::from_f64(f64::from(s));
        }
        self.centre.copy_from_slice(centres);
    }

    /// Sets the clock: steps taken and model time (for a [`Backend`] that found a failed step
    /// and sets the clock back to the last good state).
    pub fn set_clock(&mut self, iteration: u64, time: f64) {
        self.iteration = iteration;
        self.time = time;
    }
}

/// The parts of `tissue` that a backend supporting only `supported` cannot run, each named
/// with its scene table (empty: it runs them all). The one refusal list: a backend declares
/// what it supports, and every check derives from [`crate::Tissue::parts`].
pub fn unsupported<T: Real>(tissue: &Tissue<T>, supported: &[Part]) -> Vec<String> {
    tissue
        .parts()
        .into_iter()
        .filter(|p| !supported.contains(p))
        .map(Part::describe)
        .collect()
}
