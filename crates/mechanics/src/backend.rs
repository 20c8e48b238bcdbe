//! Where the time step runs: on the host (the default, [`crate::Tissue::step`]) or on a device
//! through a [`Backend`] (the `gpu` crate's), which [`crate::Simulation::with_backend`] drives.
//!
//! A backend holds its own copy of the state and steps it there; the [`crate::Tissue`] on the
//! host keeps the clock, the parameters and the identities, and its fields are brought up to
//! date ([`Backend::sync`]) only when something on the host reads them: a callback, a writer or
//! a fix whose schedule fires, and the end of a run. Everything else about a run (schedules,
//! outputs, checkpoints, the activity switch) is the driver's, the same for every backend.

use phasefield::Real;

use crate::extensions::{Extensions, Part};
use crate::observables::Observables;
use crate::params::ModelParams;
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

    /// What the last evaluation on the device computed, for the division clock's decisions
    /// between steps ([`Tissue::proliferate`], which reads it from the workspace on the host):
    /// every cell's quantities by slot and, when `pressure`, the tissue pressure `P` per
    /// lattice node (a pressure gate's). `None` when the backend cannot, or when a queued step
    /// failed (the driver then syncs, which reports it).
    ///
    /// # Errors
    /// [`StepError::Backend`] when the device fails.
    fn evaluation(
        &mut self,
        tissue: &Tissue<T>,
        pressure: bool,
    ) -> Result<Option<DeviceEvaluation>, StepError> {
        let _ = (tissue, pressure);
        Ok(None)
    }

    /// The observables of the device's current state ([`Tissue::observe`]), reduced there so
    /// that only the numbers come back, not the fields; `tissue` gives the clock and the
    /// parameters. `None` when the backend cannot, or when a queued step failed: the driver
    /// then syncs, which reports the failure. The default is `None`.
    ///
    /// # Errors
    /// [`StepError::Backend`] when the device fails.
    fn observe(&mut self, tissue: &Tissue<T>) -> Result<Option<Observables>, StepError> {
        let _ = tissue;
        Ok(None)
    }
}

/// What a device's last evaluation computed ([`Backend::evaluation`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DeviceEvaluation {
    /// Every cell's quantities, by slot.
    pub cells: Vec<crate::CellState>,
    /// The tissue pressure `P` per lattice node (index `x * ly + y`), when it was asked for.
    pub pressure: Option<Vec<f64>>,
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

    /// Counts one step of `dt` taken (by a backend: the host's copy of the fields is brought
    /// up to date later, [`Backend::sync`]); every step of the tissue's own counts itself.
    pub(crate) fn advance_clock(&mut self, dt: f64) {
        self.iteration += 1;
        self.time += dt;
    }
}

/// The parts of the extensions `ext` (with the model's `params`) that a backend supporting only
/// `supported` cannot run, each named with its scene table (empty: it runs them all). The one
/// refusal list: a backend declares what it supports, and every check derives from
/// [`Extensions::parts`], for a tissue ([`crate::Tissue::extensions`]) as for a scene's
/// configured extensions.
pub fn unsupported(ext: &Extensions, params: &ModelParams, supported: &[Part]) -> Vec<String> {
    ext.parts(params)
        .into_iter()
        .filter(|p| !supported.contains(p))
        .map(Part::describe)
        .collect()
}

impl<T: phasefield::Real> crate::Workspace<T> {
    /// Takes what a device's last evaluation computed as this workspace's last evaluation:
    /// the cells' quantities, and the pressure where it came with them (the division clock's
    /// inputs, [`crate::Tissue::proliferate`]).
    ///
    /// # Panics
    /// If the counts do not fit the workspace (fit it to the tissue first).
    pub(crate) fn take_device_evaluation(&mut self, ev: &DeviceEvaluation) {
        assert_eq!(ev.cells.len(), self.cell_state.len(), "a state per cell");
        self.cell_state.copy_from_slice(&ev.cells);
        if let Some(p) = &ev.pressure {
            let lattice = self.sums.lattice();
            let ly = lattice.ly;
            assert_eq!(p.len(), lattice.len(), "a pressure per lattice node");
            for x in 0..lattice.lx {
                let (_, col) = self
                    .sums
                    .columns_read_write::<0>([], crate::SumField::P.index(), x);
                col.copy_from_slice(&p[x * ly..(x + 1) * ly]);
            }
        }
    }
}

/// The settings in effect (`settings`, [`Extensions::settings`]) that a backend which
/// implements `implemented` cannot run, each named as `KEY = VALUE`: a key it does not list,
/// or a value outside the values it lists for the key (`None`: every value). Empty: it runs
/// them all. A backend declares its settings, not only its parts, so that a setting added to
/// a part is refused by name where it has not been implemented.
pub fn unsupported_settings(
    settings: &[crate::extensions::Setting],
    implemented: &[(&str, Option<&[&str]>)],
) -> Vec<String> {
    settings
        .iter()
        .filter(|s| {
            !implemented.iter().any(|(key, values)| {
                *key == s.key && values.is_none_or(|v| v.contains(&s.value.as_str()))
            })
        })
        .map(|s| format!("{} = {}", s.key, s.value))
        .collect()
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use phasefield::{init, Lattice, PatchShape};

    use super::*;
    use crate::simulation::{Callback, CallbackError, Needs, Observation, Schedule, Simulation};
    use crate::workspace::Workspace;
    use crate::ModelParams;

    /// What the driver asked of [`HostBackend`].
    #[derive(Debug, Default, Clone, Copy, PartialEq)]
    struct Asked {
        syncs: usize,
        observes: usize,
    }

    /// A backend that steps its own copy of the tissue on the host, counts what the driver
    /// asks of it, and reduces the observables itself when `observes` (as a device would).
    struct HostBackend {
        own: Tissue<f64>,
        ws: Workspace<f64>,
        observes: bool,
        asked: Arc<Mutex<Asked>>,
    }

    impl Backend<f64> for HostBackend {
        fn name(&self) -> &str {
            "host"
        }
        fn supports(&self, _: Part) -> bool {
            true
        }
        fn step(&mut self, _: &Tissue<f64>, params: &StepParams) -> Result<(), StepError> {
            self.own.step(&mut self.ws, params)
        }
        fn sync(&mut self, tissue: &mut Tissue<f64>) -> Result<(), StepError> {
            self.asked.lock().unwrap().syncs += 1;
            *tissue = self.own.clone();
            Ok(())
        }
        fn upload(&mut self, tissue: &Tissue<f64>) -> Result<(), StepError> {
            self.own = tissue.clone();
            Ok(())
        }
        fn observe(&mut self, _: &Tissue<f64>) -> Result<Option<Observables>, StepError> {
            self.asked.lock().unwrap().observes += 1;
            Ok(self.observes.then(|| self.own.observe(&mut self.ws)))
        }
    }

    /// Records the observables it is called with, reading what `needs` says it reads.
    struct Reader {
        needs: Needs,
        seen: Arc<Mutex<Vec<Option<Observables>>>>,
    }

    impl Callback<f64> for Reader {
        fn call(&mut self, obs: &mut Observation<'_, f64>) -> Result<(), CallbackError> {
            let o = (self.needs != Needs::Clock).then(|| obs.observables());
            self.seen.lock().unwrap().push(o);
            Ok(())
        }
        fn needs(&self) -> Needs {
            self.needs
        }
    }

    fn tissue() -> Tissue<f64> {
        let lattice = Lattice::new(40, 40);
        let shape = PatchShape::new(lattice, 8).expect("margin 8 fits 40²");
        let centres = [[10.0, 12.0], [24.0, 14.0], [18.0, 28.0]];
        let cells = init::discs(lattice, shape, &centres, 6.0, 2.0);
        Tissue::new(cells, ModelParams::paper(0.02))
    }

    /// Runs 20 steps on a [`HostBackend`] with a callback of `needs` every 5 steps; what the
    /// backend was asked, and what the callback saw.
    fn run(needs: Needs, observes: bool) -> (Asked, Vec<Option<Observables>>) {
        let t = tissue();
        let asked = Arc::new(Mutex::new(Asked::default()));
        let backend = HostBackend {
            ws: Workspace::new(t.cells()),
            own: t.clone(),
            observes,
            asked: asked.clone(),
        };
        let seen = Arc::new(Mutex::new(Vec::new()));
        let mut sim = Simulation::new(t, StepParams::paper())
            .with_backend(Box::new(backend))
            .stop_iteration(20);
        let reader = Reader {
            needs,
            seen: seen.clone(),
        };
        sim.add_callback("reader", Schedule::IterationInterval(5), reader);
        sim.run().unwrap();
        let asked = *asked.lock().unwrap();
        let seen = seen.lock().unwrap().clone();
        (asked, seen)
    }

    /// The driver brings back from a backend only what the callbacks due need: nothing for
    /// the clock, the reduced observables for [`Needs::Observables`] (the state only when the
    /// backend cannot reduce them), the state for [`Needs::State`]; and the observables are
    /// the same whichever way they came. (Calls at steps 0, 5, 10, 15, 20; the run's end
    /// syncs once.)
    #[test]
    fn the_driver_brings_back_only_what_the_callbacks_need() {
        let (clock, _) = run(Needs::Clock, true);
        assert_eq!(
            clock,
            Asked {
                syncs: 1,
                observes: 0
            }
        );
        let (reduced, seen_reduced) = run(Needs::Observables, true);
        assert_eq!(
            reduced,
            Asked {
                syncs: 1,
                observes: 4
            }
        );
        let (fallback, seen_fallback) = run(Needs::Observables, false);
        assert_eq!(
            fallback,
            Asked {
                syncs: 5,
                observes: 4
            }
        );
        let (state, seen_state) = run(Needs::State, true);
        assert_eq!(
            state,
            Asked {
                syncs: 5,
                observes: 0
            }
        );
        assert_eq!(seen_reduced.len(), 5);
        assert_eq!(seen_reduced, seen_state);
        assert_eq!(seen_fallback, seen_state);
    }
}
