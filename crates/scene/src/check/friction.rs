//! The check of `[friction]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// `[friction]`: ξ_c zero or positive, and a tolerance the solver can reach.
pub(crate) fn friction(file: &SceneFile) -> Result<(), SceneError> {
    let Some(f) = &file.friction else {
        return Ok(());
    };
    if !(f.cells.is_finite() && f.cells >= 0.0) {
        return Err(invalid(
            "friction",
            "cells",
            f.cells,
            "the friction between cells must be zero or positive",
            "use ξ_c of order 0.01-1 per node of overlap (two touching cells of R = 8 overlap by about 2 nodes), or remove [friction]",
        ));
    }
    if !(f.tolerance > 1e-15 && f.tolerance <= 1e-3) {
        return Err(invalid(
            "friction",
            "tolerance",
            f.tolerance,
            "the solver's relative residual must be between 1e-15 and 1e-3",
            "use the default, 1e-10",
        ));
    }
    Ok(())
}
