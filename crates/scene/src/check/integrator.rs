//! The check of `[integrator]` (and of the settings the GPU backend refuses).

use crate::error::{invalid, readable, sig3, SceneError, DEFAULT_TOLERANCE, MAX_STEPS};
use crate::file::{ComputeBackend, SceneFile};
use phasefield::{Lattice, PatchShape};

/// The integrator: dt against the stability estimate, the adaptive step's keys, the correctors, the margin against every radius, the GPU's refusals, and the patch against the lattice.
pub(crate) fn integrator(file: &SceneFile) -> Result<(), SceneError> {
    let d = &file.domain;
    let c = &file.cells;
    let m = &file.model;
    let it = &file.integrator;
    if !(it.dt.is_finite() && it.dt > 0.0) {
        return Err(invalid(
            "integrator",
            "dt",
            it.dt,
            "the time step must be positive",
            "use the paper's 0.2",
        ));
    }
    if let Some(dt_max) = file.dt_above_estimate().filter(|_| it.stability_check) {
        if dt_max <= 0.0 {
            // γ = 0 with activity: nothing damps the advected interfaces at any dt.
            return Err(invalid("model", "gamma", m.gamma, format!("with zeta = {} and no line tension the explicit scheme is unstable at any dt (the activity limit of docs/stability.csv is proportional to gamma)", m.zeta), "use gamma > 0 (the paper uses 0.01), set zeta = 0, or set [integrator] stability_check = false to run at your own risk"));
        }
        if it.adaptive {
            return Err(invalid("integrator", "dt_max", it.dt_max.unwrap_or_default(), format!("the explicit scheme is unstable above dt ≈ {} for these parameters (a conservative estimate; docs/stability.csv), and the error estimate sees an instability only once it grows", sig3(dt_max)), format!("leave dt_max out (it is then {}) or set [integrator] stability_check = false to run above the estimate at your own risk", sig3(dt_max))));
        }
        return Err(invalid("integrator", "dt", it.dt, format!("the explicit scheme is unstable above dt ≈ {} for these parameters (a conservative estimate; docs/stability.csv)", sig3(dt_max)), format!("use dt ≤ {} (the paper uses 0.2), or set [integrator] stability_check = false to run above the estimate at your own risk", sig3(dt_max))));
    }
    if it.adaptive {
        let tolerance = it.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
            return Err(invalid(
                "integrator",
                "tolerance",
                tolerance,
                "the local error tolerance must lie between 0 and 1 (φ itself is of order 1)",
                "use 1e-3 (about the default fixed step's error) or 1e-4 for more accuracy",
            ));
        }
        if let Some(v) = it.dt_max {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    "integrator",
                    "dt_max",
                    v,
                    "the largest step must be positive",
                    "leave it out (the stability estimate) or give a positive step",
                ));
            }
            // The fixed step's bound on the number of steps, for the largest adaptive one.
            let total = file.run.relax_time + file.run.time;
            if total / v > MAX_STEPS {
                return Err(invalid(
                    "integrator",
                    "dt_max",
                    v,
                    format!(
                        "relax_time + time = {total} with steps of at most {} is more than the {MAX_STEPS:.0e} steps a run may take",
                        readable(v.to_string())
                    ),
                    format!(
                        "leave dt_max out (the stability estimate) or give at least {}",
                        sig3(total / MAX_STEPS)
                    ),
                ));
            }
        }
        if it.npc != 1 {
            return Err(invalid(
                "integrator",
                "npc",
                it.npc,
                "the adaptive step is Heun with one corrector (its Euler predictor is the error estimate)",
                "set npc = 1 or adaptive = false",
            ));
        }
    } else {
        for (key, v) in [("dt_max", it.dt_max), ("tolerance", it.tolerance)] {
            if let Some(v) = v {
                return Err(invalid(
                    "integrator",
                    key,
                    v,
                    format!("{key} is only read with adaptive = true"),
                    format!("set adaptive = true or remove {key}"),
                ));
            }
        }
    }
    if it.npc > 16 {
        return Err(invalid(
            "integrator",
            "npc",
            it.npc,
            "more than 16 corrector passes buy no accuracy",
            "use 1 (Heun) or 0 (Euler)",
        ));
    }
    if it.margin != 0 && (it.margin as f64) < c.radius {
        return Err(invalid(
            "integrator",
            "margin",
            it.margin,
            format!(
                "a patch margin smaller than the cell radius {} cuts the cells",
                c.radius
            ),
            format!(
                "use margin ≥ radius + 2λ ≈ {}, the paper's 12, or 0 for the full domain",
                (c.radius + 2.0 * m.lambda).ceil()
            ),
        ));
    }
    // A population's own radius needs the same room on the patch as the scene's.
    if it.margin != 0 {
        for (k, p) in file.population.iter().enumerate() {
            let r = p.radius.unwrap_or(c.radius);
            if (it.margin as f64) < r {
                return Err(invalid(
                    "population",
                    "radius",
                    r,
                    format!(
                        "population {k} ({}) has radius {r}, more than the patch margin {} ([integrator] margin): its cells would be cut to the patch and end far below their target area",
                        p.name(k),
                        it.margin
                    ),
                    format!(
                        "set [integrator] margin ≥ radius + 2λ ≈ {}, or a radius of at most {} for this population",
                        (r + 2.0 * m.lambda).ceil(),
                        it.margin
                    ),
                ));
            }
        }
    }
    if it.backend == ComputeBackend::Gpu {
        gpu_settings(file)?;
    }
    let lattice = Lattice::new(d.lx, d.ly);
    if let Err(e) = PatchShape::new(lattice, it.margin) {
        return Err(invalid(
            "integrator",
            "margin",
            it.margin,
            e.to_string(),
            "reduce the margin",
        ));
    }
    Ok(())
}

/// The integrator settings the GPU backend does not run, refused by key: the adaptive
/// step, forward Euler, full-domain storage, f64 storage. (The extensions it does not run
/// are refused by the CLI from what the backend declares, `gpu::SUPPORTED`, against
/// [`crate::Scene::parts`].)
fn gpu_settings(file: &SceneFile) -> Result<(), SceneError> {
    let it = &file.integrator;
    let gpu = |key, value: String, problem: &str, fix: &str| {
        invalid(
            "integrator",
            key,
            value,
            format!("the GPU backend {problem}"),
            format!("{fix}, or set backend = \"cpu\""),
        )
    };
    if it.adaptive {
        return Err(gpu(
            "adaptive",
            "true".into(),
            "runs the fixed step only (its error estimate would need a second field on the device)",
            "set adaptive = false",
        ));
    }
    if it.npc == 0 {
        return Err(gpu(
            "npc",
            "0".into(),
            "runs Heun's predictor–corrector, not forward Euler",
            "set npc = 1",
        ));
    }
    if it.margin == 0 {
        return Err(gpu(
            "margin",
            "0".into(),
            "stores every cell on a patch; the full domain is the CPU's reference setting",
            "set margin = 16 (or the paper's 12)",
        ));
    }
    if it.precision == mechanics::Precision::F64 {
        return Err(gpu(
            "precision",
            "\"f64\"".into(),
            "stores and computes in f32",
            "set precision = \"f32\"",
        ));
    }
    Ok(())
}
