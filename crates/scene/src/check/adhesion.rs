//! The check of `[adhesion]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// `[adhesion]`: ω in range, below γ.
pub(crate) fn adhesion(file: &SceneFile) -> Result<(), SceneError> {
    if let Some(a) = &file.adhesion {
        if !(a.omega.is_finite() && a.omega >= 0.0) {
            return Err(invalid(
                "adhesion",
                "omega",
                a.omega,
                "the adhesion strength must be zero or positive",
                "use a value of order 0.01 (the reference code's cluster example), or remove [adhesion]",
            ));
        }
        // Two overlapping cells have the gradient energy λ(γ ± ω)|∇(φ1 ± φ2)|²/2: at ω ≥ γ
        // their difference costs nothing and a contact breaks into stripes of the lattice.
        let gamma = file
            .population
            .iter()
            .filter_map(|p| p.gamma)
            .fold(file.model.gamma, f64::min);
        if a.omega >= gamma {
            return Err(invalid(
                "adhesion",
                "omega",
                a.omega,
                format!("adhesion at or above the interface stiffness (gamma = {gamma}) makes the interface between two cells cost nothing, and contacts break into stripes at the lattice scale"),
                format!("use omega below gamma, e.g. {}", gamma * 0.75),
            ));
        }
    }
    Ok(())
}
