//! The driver of a whole run: relaxation at ζ = 0, then activity, with an observer called on
//! the steps it asks for (after Oceananigans' `Simulation` and ripgrep's `Sink`).

use phasefield::Real;

use crate::observables::Observables;
use crate::params::StepParams;
use crate::tissue::{Tissue, Workspace};
use crate::StepError;

/// What a run does, in steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Protocol {
    /// Steps at ζ = 0 before the activity is switched on (MODEL.md §6).
    pub relax_steps: u64,
    /// Steps at activity `zeta`.
    pub active_steps: u64,
    /// The activity after relaxation.
    pub zeta: f64,
    /// The integrator.
    pub step: StepParams,
    /// Steps between re-sortings of the cells along a space-filling curve
    /// ([`Tissue::sort_cells`]); `None` never sorts. Cells move a fraction of a node per TU,
    /// so every few hundred steps is plenty.
    pub sort_every: Option<u64>,
}

impl Protocol {
    /// Total steps.
    pub fn total_steps(&self) -> u64 {
        self.relax_steps + self.active_steps
    }
}

/// Receives the state on the steps it asks for. Observables are computed only on those steps.
pub trait Observer {
    /// The observer's own error; step errors convert into it.
    type Error: From<StepError>;

    /// Whether to observe the state after `step` steps of the run (`0..=total`).
    fn wants(&self, step: u64, total: u64) -> bool;

    /// Called with the tissue, its freshly evaluated workspace and its observables.
    ///
    /// # Errors
    /// Whatever stops the run (e.g. a failed write).
    fn observe<T: Real>(
        &mut self,
        tissue: &Tissue<T>,
        ws: &Workspace<T>,
        obs: &Observables,
    ) -> Result<(), Self::Error>;
}

/// No observer: `&mut ()` runs the protocol and observes nothing.
impl Observer for () {
    type Error = StepError;
    fn wants(&self, _: u64, _: u64) -> bool {
        false
    }
    fn observe<T: Real>(
        &mut self,
        _: &Tissue<T>,
        _: &Workspace<T>,
        _: &Observables,
    ) -> Result<(), StepError> {
        Ok(())
    }
}

/// Runs `protocol` on `tissue`, calling `observer` on the steps it wants.
///
/// ζ is 0 during relaxation and `protocol.zeta` from step `relax_steps` on.
///
/// # Errors
/// The first step error or observer error; the tissue is left at the last good state.
pub fn run<T: Real, O: Observer>(
    tissue: &mut Tissue<T>,
    ws: &mut Workspace<T>,
    protocol: &Protocol,
    observer: &mut O,
) -> Result<(), O::Error> {
    let total = protocol.total_steps();
    let mut scratch = Vec::new();
    tissue.params.zeta = if protocol.relax_steps > 0 {
        0.0
    } else {
        protocol.zeta
    };
    for s in 0..=total {
        if s == protocol.relax_steps {
            tissue.params.zeta = protocol.zeta;
        }
        if observer.wants(s, total) {
            let o = tissue.observe(ws);
            observer.observe(tissue, ws, &o)?;
        }
        if s == total {
            break;
        }
        if protocol.sort_every.is_some_and(|k| s % k == 0) {
            tissue.sort_cells(&mut scratch);
        }
        tissue.step(ws, &protocol.step)?;
    }
    Ok(())
}
