//! The check of `[model]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// The model's parameters.
pub(crate) fn model(file: &SceneFile) -> Result<(), SceneError> {
    let m = &file.model;
    for (key, v) in [("gamma", m.gamma), ("mu", m.mu), ("kappa", m.kappa)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(
                "model",
                key,
                v,
                "must be zero or positive",
                "use the paper's value (gamma 0.01, mu 3, kappa 0.1) as a start",
            ));
        }
    }
    if !(m.lambda.is_finite() && m.lambda > 0.0) {
        return Err(invalid(
            "model",
            "lambda",
            m.lambda,
            "the interface width must be positive",
            "use a width of a few nodes (paper: 2.5)",
        ));
    }
    if !(m.xi.is_finite() && m.xi > 0.0) {
        return Err(invalid(
            "model",
            "xi",
            m.xi,
            "the friction must be positive",
            "use the paper's value 2",
        ));
    }
    if !m.zeta.is_finite() {
        return Err(invalid(
            "model",
            "zeta",
            m.zeta,
            "the activity must be a finite number",
            "use a value between -0.01 and 0.01",
        ));
    }
    Ok(())
}
