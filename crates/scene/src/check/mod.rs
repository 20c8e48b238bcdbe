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

pub(crate) use adhesion::adhesion;
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
