//! The check of `[run]`.

use crate::error::{invalid, sig3, SceneError, MAX_STEPS};
use crate::file::SceneFile;

/// The run's times and output intervals (against `dt`, and the step bound).
pub(crate) fn run(file: &SceneFile) -> Result<(), SceneError> {
    let it = &file.integrator;
    let r = &file.run;
    for (key, v) in [("relax_time", r.relax_time), ("time", r.time)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(
                "run",
                key,
                v,
                "times must be zero or positive",
                "give the time in model units (paper: 0.2 per step)",
            ));
        }
    }
    let steps = (r.relax_time + r.time) / it.dt;
    if steps > MAX_STEPS {
        let (key, v) = if r.relax_time > r.time {
            ("relax_time", r.relax_time)
        } else {
            ("time", r.time)
        };
        return Err(invalid(
            "run",
            key,
            v,
            format!(
                "relax_time + time = {} at dt = {} is {steps:.3e} steps, more than the {MAX_STEPS:.0e} a run may take",
                r.relax_time + r.time,
                it.dt
            ),
            format!(
                "shorten the run (at most {} TU at this dt) or raise [integrator] dt",
                sig3(MAX_STEPS * it.dt)
            ),
        ));
    }
    for (key, v) in [
        ("output_every", Some(r.output_every)),
        ("series_every", r.series_every),
        ("checkpoint_every", r.checkpoint_every),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v >= it.dt) {
                return Err(invalid(
                    "run",
                    key,
                    v,
                    format!("the interval must be at least one time step ({})", it.dt),
                    "use a multiple of dt",
                ));
            }
        }
    }
    Ok(())
}
