//! The checks of [`crate::SceneFile::validate`], one per scene section (`[walls]`' geometry and
//! `[division]` have theirs in `crate::walls` and `crate::division`). Each returns the first bad
//! key of its section as a [`crate::SceneError`] naming the key, the value, the problem and a fix.

mod adhesion;
mod cells;
mod domain;
mod friction;
mod integrator;
mod model;
mod nematic;
mod polarity;
mod population;
mod run;
mod walls;

pub(crate) use adhesion::{adhesion, repulsion};
pub(crate) use cells::cells;
pub(crate) use domain::domain;
pub(crate) use friction::friction;
pub(crate) use integrator::integrator;
pub(crate) use model::model;
pub(crate) use nematic::nematic;
pub(crate) use polarity::polarity;
pub(crate) use population::population;
pub(crate) use run::run;
pub(crate) use walls::walls;

use crate::error::{invalid, SceneError};
use crate::file::AlignKind;

/// A term's alignment in `section` (`[polarity]`, `[nematic]`): a rate needs a target.
pub(crate) fn alignment(
    section: &'static str,
    align: AlignKind,
    rate: f64,
) -> Result<(), SceneError> {
    if rate > 0.0 && align == AlignKind::None {
        return Err(invalid(
            section,
            "align_rate",
            rate,
            "an alignment rate with align = \"none\" aligns to nothing",
            "set align = \"velocity\", \"force\" or \"shape\", or remove align_rate",
        ));
    }
    Ok(())
}

/// A term's initial angle in `section`, if given: a finite number.
pub(crate) fn initial_angle(section: &'static str, angle: Option<f64>) -> Result<(), SceneError> {
    if let Some(a) = angle.filter(|a| !a.is_finite()) {
        return Err(invalid(
            section,
            "angle",
            a,
            "the initial angle must be a finite number",
            "give it in radians (0 is along +x), or remove it for random angles",
        ));
    }
    Ok(())
}
