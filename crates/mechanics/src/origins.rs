//! Each cell's force split by its origin (issue 49): the tissue pressure, the shape activity,
//! the cells' nematic activity, adhesion, walls, and each physics term's whole-cell force.
//!
//! The interface force is linear in the stress, and the stress is a sum over the parts of the
//! model (the pressure `P` is a sum of each part's contributions, the active stress of `ζ_i S_i`
//! and `ζ_Q q_i`). So each part's force is the interface force of an evaluation of the same
//! fields with that part alone, less that of the passive model (the pressure of the interfaces,
//! the area and the repulsion), which is a part itself; they add up to the interface force to
//! round-off; with friction between cells, its part completes the sum to `ξ_i v_i` (to the
//! solver's tolerance). Computed only when asked (a frame of a scene with `[run] forces_by_origin`,
//! Python's `sim.cells` then): one evaluation per part, against a hundred per frame interval.

use phasefield::Real;

use crate::step::Included;
use crate::{Extensions, ModelParams, Part, Tissue, Workspace};

/// Each cell's force by origin, by slot: `parts[k]` is named `names[k]`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ForcesByOrigin {
    /// The parts' names: `pressure`, then those there are of `shape_activity`,
    /// `nematic_activity`, `adhesion`, `walls`, then each term's name (`polarity`).
    pub names: Vec<String>,
    /// Each part's force on each slot.
    pub parts: Vec<Vec<[f64; 2]>>,
}

impl ForcesByOrigin {
    /// What each part means, for outputs.
    pub fn meaning(name: &str) -> String {
        match name {
            "pressure" => {
                "the tissue pressure's force: interfaces, area and repulsion (the passive model)"
                    .into()
            }
            "shape_activity" => "the shape activity's force, from -zeta sum_j phi_j S_j".into(),
            "nematic_activity" => {
                "the cells' nematic activity's force, from -zeta_Q sum_j phi_j q_j".into()
            }
            "adhesion" => "adhesion's force, through the pressure".into(),
            "walls" => "the walls' force, through the pressure".into(),
            "friction" => {
                "the friction of the overlapping cells, -xi_c sum_j o_ij (v_i - v_j)".into()
            }
            term => format!("the whole-cell force of the term {term}"),
        }
    }
}

impl Extensions {
    /// The names of the forces by origin of a tissue with these extensions and `params`,
    /// with the activity `active` ([`ForcesByOrigin::names`]; the terms' forces last).
    pub fn force_origins(&self, params: &ModelParams, active: bool) -> Vec<String> {
        self.force_parts(params, active)
            .into_iter()
            .map(|(name, _)| name.to_string())
            .chain(
                self.terms
                    .iter()
                    .filter(|t| t.has_force())
                    .map(|t| t.name().to_string()),
            )
            .chain(self.friction.is_some().then(|| "friction".to_string()))
            .collect()
    }

    /// The interface force's parts there are, with what each evaluation includes (the
    /// pressure's, the passive model, first).
    fn force_parts(&self, params: &ModelParams, active: bool) -> Vec<(&'static str, Included)> {
        let activity = self.populations.any_activity(params, active);
        let nematic = self.terms.nematic_stress(active);
        let has = |p: Part| self.has(p, params);
        [
            ("pressure", true, Included::NONE),
            (
                "shape_activity",
                activity,
                Included {
                    shape_activity: true,
                    ..Included::NONE
                },
            ),
            (
                "nematic_activity",
                nematic,
                Included {
                    nematic: true,
                    ..Included::NONE
                },
            ),
            (
                "adhesion",
                has(Part::Adhesion),
                Included {
                    adhesion: true,
                    ..Included::NONE
                },
            ),
            (
                "walls",
                has(Part::Walls),
                Included {
                    walls: true,
                    ..Included::NONE
                },
            ),
        ]
        .into_iter()
        .filter(|(_, on, _)| *on)
        .map(|(name, _, inc)| (name, inc))
        .collect()
    }
}

impl<T: Real> Tissue<T> {
    /// Each cell's force split by origin (docs/model.md §11.7: each part is the interface
    /// force of an evaluation with that part alone, less the passive model's); `ws` is left
    /// as [`Tissue::refresh`] leaves it. The parts add up to the interface force plus the
    /// terms' whole-cell force of that evaluation, to round-off.
    pub fn forces_by_origin(&self, ws: &mut Workspace<T>) -> ForcesByOrigin {
        let parts_of = self.ext.force_parts(&self.params, self.active);
        let forces_of = |inc: Included, ws: &mut Workspace<T>| -> Vec<[f64; 2]> {
            let Workspace {
                k2,
                sums,
                cell_state,
                term_scratch,
                ..
            } = ws;
            let _ = self.evaluate_parts(
                inc,
                true,
                k2,
                sums,
                cell_state,
                term_scratch,
                crate::kernels::Post::Nothing,
                0.0,
                None,
            );
            cell_state.iter().map(|s| [s.force.x, s.force.y]).collect()
        };
        let base = forces_of(Included::NONE, ws);
        let mut parts = vec![base.clone()];
        for (_, inc) in &parts_of[1..] {
            let with = forces_of(*inc, ws);
            parts.push(
                with.iter()
                    .zip(&base)
                    .map(|(w, b)| [w[0] - b[0], w[1] - b[1]])
                    .collect(),
            );
        }
        self.refresh(ws);
        if !self.ext.terms.is_empty() {
            let view = self.terms_view(ws.cell_states(), 0.0);
            parts.extend(self.ext.terms.forces_of_each(&view));
        }
        // Friction between cells, `−ξ_c Σ_j o_ij (v_i − v_j)` from the solved velocities.
        if let Some(f) = &self.ext.friction {
            parts.push(crate::friction::forces(
                &ws.term_scratch.friction.pairs,
                f.xi_c,
                ws.cell_states(),
            ));
        }
        // The names in the same order, from the one list of them.
        let names = self.ext.force_origins(&self.params, self.active);
        debug_assert_eq!(names.len(), parts.len());
        ForcesByOrigin { names, parts }
    }
}
