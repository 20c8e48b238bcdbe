//! Validation of a [`SceneFile`] into a [`Scene`], once: the error names the key, the value,
//! what is wrong and how to fix it (ripgrep's `ConfigError`).

use phasefield::{init, Lattice};

use crate::file::{InitKind, SceneFile};
use crate::Scene;

use crate::error::{invalid, SceneError};

impl SceneFile {
    /// Checks every value once and returns the valid [`Scene`]; the error names the first bad
    /// key and how to fix it.
    ///
    /// # Errors
    /// [`SceneError::Invalid`] for the first problem found.
    pub fn validate(self) -> Result<Scene, SceneError> {
        self.validate_with(false)
    }

    /// [`SceneFile::validate`] for a program that reads a run and never steps it (`render`,
    /// `export vtk`, `analyze`, Python's `Run`): a `[terms.NAME]` table whose term this program
    /// does not register is kept in the file and listed by [`Scene::unbuilt_terms`], instead
    /// of refused; building a tissue of the scene then refuses ([`Scene::tissue`]).
    ///
    /// # Errors
    /// As [`SceneFile::validate`], but for unregistered terms.
    pub fn validate_for_reading(self) -> Result<Scene, SceneError> {
        self.validate_with(true)
    }

    fn validate_with(self, reading: bool) -> Result<Scene, SceneError> {
        // One check per section, in the order the keys depend on each other; each names
        // the first bad key and its fix.
        crate::check::domain(&self)?;
        crate::check::cells(&self)?;
        crate::check::model(&self)?;
        crate::check::population(&self)?;
        crate::check::adhesion(&self)?;
        crate::check::repulsion(&self)?;
        crate::check::polarity(&self)?;
        crate::check::nematic(&self)?;
        crate::check::friction(&self)?;
        crate::check::integrator(&self)?;
        crate::check::run(&self)?;
        if let Some(spec) = &self.division {
            crate::division::check(spec, &self)?;
        }
        crate::check::walls(&self)?;
        // The terms of `[terms.NAME]` tables, built once by their registered builders.
        let registered = crate::registry::registered_terms();
        let unbuilt: Vec<String> = self
            .user_terms
            .keys()
            .filter(|n| reading && !registered.contains(n))
            .cloned()
            .collect();
        let user_terms = self
            .user_terms
            .iter()
            .filter(|(name, _)| !unbuilt.contains(name))
            .map(|(name, table)| crate::registry::build(name, table))
            .collect::<Result<Vec<_>, _>>()?;
        let (d, c) = (&self.domain, &self.cells);
        let r0 = self.init_radius();
        let lattice = Lattice::new(d.lx, d.ly);
        let walls = match &self.walls {
            Some(spec) => Some(crate::walls::walls_of(
                spec,
                lattice,
                init::wall_clearance(r0),
            )?),
            None => None,
        };
        let Some(layout) = self.layout() else {
            // The state is read when the tissue is built (`Scene::tissue_from_state`).
            return Ok(Scene {
                file: self,
                centres: Vec::new(),
                walls,
                user_terms,
                unbuilt,
            });
        };
        let centres = match init::positions_clear_of(
            lattice,
            c.count,
            r0,
            &layout,
            walls.as_ref().and_then(|w| w.field(false)),
        ) {
            Ok(centres) => centres,
            Err(e) => {
                let key = if c.init == InitKind::Positions {
                    "positions"
                } else {
                    "count"
                };
                return Err(invalid(
                    "cells",
                    key,
                    if key == "count" {
                        c.count.to_string()
                    } else {
                        "[...]".into()
                    },
                    e.to_string(),
                    if walls.is_some() {
                        "use fewer cells, smaller init_radius, a larger [domain] or less wall (initial discs stay a disc radius and a node clear of the walls)"
                    } else {
                        "use fewer cells, smaller init_radius or a larger [domain]"
                    },
                ));
            }
        };
        Ok(Scene {
            file: self,
            centres,
            walls,
            user_terms,
            unbuilt,
        })
    }

    /// The layout of the initial discs, or `None` when the scene starts from a saved state.
    fn layout(&self) -> Option<init::Layout> {
        Some(match self.cells.init {
            InitKind::Random => init::Layout::Random {
                seed: self.run.seed,
            },
            InitKind::Hexagonal => init::Layout::Hexagonal,
            InitKind::Positions => {
                init::Layout::Positions(self.cells.positions.clone().unwrap_or_default())
            }
            InitKind::Frame => return None,
        })
    }

    /// The stability estimate `ModelParams::max_stable_dt` of the active phase, when the
    /// scene's largest step is above it: `dt`, or with `adaptive` the given `dt_max` (the
    /// first step is cut to the estimate).
    pub(crate) fn dt_above_estimate(&self) -> Option<f64> {
        let dt_max = self.stability_estimate();
        let it = &self.integrator;
        let largest = if it.adaptive {
            it.dt_max.unwrap_or(0.0)
        } else {
            it.dt
        };
        (largest > dt_max).then_some(dt_max)
    }

    /// The stability estimate of the active phase.
    pub(crate) fn stability_estimate(&self) -> f64 {
        let base = self.model_params(self.model.zeta);
        // The smallest over the populations, each with its own constants.
        // A wall's repulsion relaxes φ at the rate (2κ_w/λ) w² ≤ 2κ_w/λ, which Heun's method
        // keeps stable for dt below λ/κ_w.
        let walls = self
            .walls
            .as_ref()
            .filter(|w| w.kappa > 0.0)
            .map_or(f64::INFINITY, |w| base.energy.lambda / w.kappa);
        // Each population with its own constants and the largest repulsion it feels from any
        // neighbour (`[repulsion] pairs`).
        let pops = self.populations();
        (0..pops.kinds().len())
            .map(|k| {
                let mut own = pops.params(k, &base);
                own.energy.kappa = pops.largest_repulsion(k, &base);
                own.max_stable_dt()
            })
            .fold(base.max_stable_dt().min(walls), f64::min)
    }
}
