//! The check of `[polarity]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// `[polarity]`: each key in range.
pub(crate) fn polarity(file: &SceneFile) -> Result<(), SceneError> {
    if let Some(p) = &file.polarity {
        if !p.alpha.is_finite() {
            return Err(invalid(
                "polarity",
                "alpha",
                p.alpha,
                "the propulsion force must be a finite number",
                "use a force of order 0.01-0.1 (the reference code's examples use 0.04)",
            ));
        }
        if !(p.rotational_diffusion.is_finite() && p.rotational_diffusion >= 0.0) {
            return Err(invalid(
                "polarity",
                "rotational_diffusion",
                p.rotational_diffusion,
                "the rotational diffusion constant must be zero or positive",
                "use D_r = 1/(persistence time), e.g. 4.5e-4 (the reference code's D-pol = 0.03 is D_r = D-pol^2/2)",
            ));
        }
        if !(p.align_rate.is_finite() && p.align_rate >= 0.0) {
            return Err(invalid(
                "polarity",
                "align_rate",
                p.align_rate,
                "the alignment rate must be zero or positive",
                "use a rate of order 0.1 (the reference code's J-pol), or 0 for none",
            ));
        }
        super::alignment("polarity", p.align, p.align_rate)?;
        if !(p.contact_inhibition.is_finite() && p.contact_inhibition >= 0.0) {
            return Err(invalid(
                "polarity",
                "contact_inhibition",
                p.contact_inhibition,
                "the contact inhibition must be zero or positive",
                "use a value of order 1 (3 stalls a cell pressed with its own force to 5 %), or 0 for none",
            ));
        }
        super::initial_angle("polarity", p.angle)?;
    }
    Ok(())
}
