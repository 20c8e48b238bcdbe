//! [`Extensions`]: every part of the model beyond the paper's minimal model, owned in one place.
//!
//! A tissue holds one `Extensions`: the physics terms with their per-cell state
//! ([`Terms`]), the populations ([`Populations`]), the walls ([`Walls`]) and the cell-cycle
//! clock with its lineage ([`Proliferation`]); adhesion is a parameter of the model
//! (`ModelParams::omega`) and has no state of its own. A scene builds it once
//! (`scene::Scene::extensions`), for a fresh run and for a resumed one alike, so that no part
//! can be forgotten on one path and not the other.
//!
//! Everything that has to follow the parts derives from this type rather than from a list of
//! its own:
//! - [`Part::ALL`] enumerates them, with their scene table and their name in messages;
//!   [`crate::Tissue::parts`] says which a tissue has, which a [`crate::backend::Backend`]
//!   compares with what it supports;
//! - [`Extensions::state_arrays`] is every array of state a part keeps (written to
//!   checkpoints, and the per-identity ones to frames), and [`Extensions::restore_arrays`]
//!   reads them back, so a checkpoint or frame writer and reader never name a part;
//! - [`Extensions::heap_bytes`] is their memory;
//! - [`Extensions::differences`] compares two, part by part (the test that a checkpoint
//!   restores every part uses it).
//!
//! A part added later adds a variant to [`Part`]; the `match`es on it below (which have no
//! wildcard) then fail to compile until its arrays, bytes and comparison are written.

use crate::clock::Proliferation;
use crate::friction::CellFriction;
use crate::params::ModelParams;
use crate::terms::{Populations, Terms};
use crate::walls::Walls;

/// One kind of extension of the paper's model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum Part {
    /// Whole-cell physics terms with per-cell state (`[polarity]`, `[nematic]`, a user's
    /// `CellTerm`).
    Terms,
    /// Adhesion between cells (`[adhesion]`; a model parameter, no state).
    Adhesion,
    /// Populations of cells with parameters of their own (`[[population]]`), and the
    /// repulsion of each pair of them (`[repulsion] pairs`).
    Populations,
    /// Walls and masks (`[walls]`; a static lattice field).
    Walls,
    /// Division, extrusion and death, with the lineage (`[division]`).
    Division,
    /// Friction between overlapping cells (`[friction]`; a parameter, no state).
    Friction,
}

impl Part {
    /// Every part, in a fixed order.
    pub const ALL: [Part; 6] = [
        Part::Terms,
        Part::Adhesion,
        Part::Populations,
        Part::Walls,
        Part::Division,
        Part::Friction,
    ];

    /// The scene tables that configure it, such as `"[walls]"` (the terms: the built-in
    /// polarity's, and a registered term's own).
    pub fn scene_table(self) -> &'static str {
        match self {
            Part::Terms => "[polarity], [nematic] or [terms.NAME]",
            Part::Adhesion => "[adhesion]",
            Part::Populations => "[[population]] and [repulsion]",
            Part::Walls => "[walls]",
            Part::Division => "[division]",
            Part::Friction => "[friction]",
        }
    }

    /// Its name in messages, with its scene table: `"walls ([walls])"`.
    pub fn describe(self) -> String {
        let name = match self {
            Part::Terms => "physics terms",
            Part::Adhesion => "adhesion",
            Part::Populations => "populations",
            Part::Walls => "walls",
            Part::Division => "division",
            Part::Friction => "friction between cells",
        };
        format!("{name} ({})", self.scene_table())
    }
}

/// The extensions of a tissue (module docs). `Default` is none: the paper's model.
#[derive(Debug, Clone, Default)]
pub struct Extensions {
    /// The physics terms, with their per-cell state by identity.
    pub(crate) terms: Terms,
    /// Per-cell parameters (empty: every cell has the tissue's).
    pub(crate) populations: Populations,
    /// Walls, if any.
    pub(crate) walls: Option<Walls>,
    /// The cell-cycle clock and the lineage, if cells divide.
    pub(crate) proliferation: Option<Box<Proliferation>>,
    /// Friction between overlapping cells, if any.
    pub(crate) friction: Option<CellFriction>,
    /// Each identity's target area as a multiple of `πR²` (the growth before a division;
    /// empty: 1 for every cell), derived from the clock after each step.
    pub(crate) target_scale: Vec<f64>,
}

/// One setting of a part in effect: the scene key that sets it and its value, as a scene
/// writes them. What a backend compares with what it implements
/// ([`crate::backend::unsupported_settings`]), so that a setting added to a part is refused by
/// name on a backend that has not implemented it, rather than ignored.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// The part it belongs to.
    pub part: Part,
    /// The scene key, such as `"[polarity] align"`.
    pub key: String,
    /// Its value, such as `"velocity"`.
    pub value: String,
}

impl Extensions {
    /// Every setting in effect of every part, in [`Part::ALL`]'s order (with the model's
    /// `params`, for adhesion). Each part lists its own from a destructuring of its type
    /// without `..` (the terms through [`crate::terms::CellTerm::settings`]), so a field added
    /// to a part does not compile until it is listed.
    pub fn settings(&self, params: &ModelParams) -> Vec<Setting> {
        let mut out = Vec::new();
        let mut add = |part: Part, key: String, value: String| {
            out.push(Setting { part, key, value });
        };
        for part in Part::ALL {
            match part {
                Part::Terms => {
                    for term in self.terms.iter() {
                        for (key, value) in term.settings() {
                            add(part, key, value);
                        }
                    }
                }
                Part::Adhesion => {
                    if params.omega != 0.0 {
                        add(part, "[adhesion] omega".into(), params.omega.to_string());
                    }
                    if let Some(m) = self.populations.adhesion() {
                        add(part, "[adhesion] pairs".into(), format!("{m:?}"));
                    }
                }
                Part::Populations => {
                    for (k, kind) in self.populations.kinds().iter().enumerate() {
                        let crate::terms::Population {
                            gamma,
                            mu,
                            radius,
                            xi,
                            zeta,
                        } = kind;
                        for (key, v) in [
                            ("gamma", gamma),
                            ("mu", mu),
                            ("radius", radius),
                            ("xi", xi),
                            ("zeta", zeta),
                        ] {
                            if let Some(v) = v {
                                add(
                                    part,
                                    format!("[[population]] {key}"),
                                    format!("{v} (population {k})"),
                                );
                            }
                        }
                    }
                    if let Some(m) = self.populations.repulsion() {
                        add(part, "[repulsion] pairs".into(), format!("{m:?}"));
                    }
                }
                Part::Walls => {
                    if let Some(w) = &self.walls {
                        for (key, value) in w.settings() {
                            add(part, key, value);
                        }
                    }
                }
                Part::Division => {
                    if let Some(clock) = &self.proliferation {
                        for (key, value) in clock.settings_in_effect() {
                            add(part, key, value);
                        }
                    }
                }
                Part::Friction => {
                    if let Some(f) = &self.friction {
                        for (key, value) in f.settings() {
                            add(part, key, value);
                        }
                    }
                }
            }
        }
        out
    }

    /// No extension: the paper's model.
    pub fn none() -> Self {
        Self::default()
    }

    /// These extensions with the part `part` in its place (replacing the one there, or
    /// removing it: `None::<Walls>`): the one builder of the parts, which
    /// [`Tissue::with`](crate::Tissue::with) goes through too.
    pub fn with(mut self, part: impl ExtensionPart) -> Self {
        part.place(&mut self);
        self
    }

    /// The physics terms.
    pub fn terms(&self) -> &Terms {
        &self.terms
    }

    /// The populations.
    pub fn populations(&self) -> &Populations {
        &self.populations
    }

    /// The walls, if any.
    pub fn walls(&self) -> Option<&Walls> {
        self.walls.as_ref()
    }

    /// The clock, if cells divide.
    pub fn proliferation(&self) -> Option<&Proliferation> {
        self.proliferation.as_deref()
    }

    /// The friction between cells, if any.
    pub fn friction(&self) -> Option<&CellFriction> {
        self.friction.as_ref()
    }

    /// The parts there are, in [`Part::ALL`]'s order (with the model's `params`: adhesion is
    /// one of them).
    pub fn parts(&self, params: &ModelParams) -> Vec<Part> {
        Part::ALL
            .into_iter()
            .filter(|&p| self.has(p, params))
            .collect()
    }

    /// Whether `part` is there (adhesion: `params.omega ≠ 0`, or an ω for each pair of
    /// populations).
    pub fn has(&self, part: Part, params: &ModelParams) -> bool {
        match part {
            Part::Terms => !self.terms.is_empty(),
            Part::Adhesion => params.omega != 0.0 || self.populations.adhesion().is_some(),
            Part::Populations => !self.populations.is_empty(),
            Part::Walls => self.walls.is_some(),
            Part::Division => self.proliferation.is_some(),
            Part::Friction => self.friction.is_some(),
        }
    }

    /// Bytes of heap memory held by every part.
    pub fn heap_bytes(&self) -> usize {
        Part::ALL
            .iter()
            .map(|part| match part {
                Part::Terms => self.terms.heap_bytes(),
                Part::Adhesion => 0,
                Part::Populations => std::mem::size_of_val(self.populations.of_cell()),
                Part::Walls => self.walls.as_ref().map_or(0, Walls::heap_bytes),
                Part::Division => {
                    self.proliferation.as_ref().map_or(0, |p| p.heap_bytes())
                        + self.target_scale.capacity() * std::mem::size_of::<f64>()
                }
                Part::Friction => 0,
            })
            .sum()
    }

    /// The parts in which `self` and `other` differ (the parts' configuration and state; the
    /// derived `target_scale` is left out): empty when they are the same.
    pub fn differences(&self, other: &Extensions) -> Vec<Part> {
        Part::ALL
            .into_iter()
            .filter(|&part| match part {
                Part::Terms => {
                    let names =
                        |t: &Terms| t.iter().map(|t| t.name().to_string()).collect::<Vec<_>>();
                    let seen = |t: &Terms| {
                        (0..t.identities())
                            .map(|id| {
                                t.last_evaluation(id)
                                    .map(|s| [s.area, s.force.x, s.force.y])
                            })
                            .collect::<Vec<_>>()
                    };
                    names(&self.terms) != names(&other.terms)
                        || self.terms.variables() != other.terms.variables()
                        || seen(&self.terms) != seen(&other.terms)
                }
                Part::Adhesion => self.populations.adhesion() != other.populations.adhesion(),
                Part::Populations => {
                    self.populations.of_cell() != other.populations.of_cell()
                        || self.populations.repulsion() != other.populations.repulsion()
                        || format!("{:?}", self.populations.kinds())
                            != format!("{:?}", other.populations.kinds())
                }
                Part::Walls => match (&self.walls, &other.walls) {
                    (None, None) => false,
                    (Some(a), Some(b)) => !a.same_as(b),
                    _ => true,
                },
                Part::Division => match (&self.proliferation, &other.proliferation) {
                    (None, None) => false,
                    (Some(a), Some(b)) => {
                        // Compared as printed: a living cell's NaN death equals itself there.
                        let lineage =
                            |c: &Proliferation| format!("{:?}", c.lineage().collect::<Vec<_>>());
                        lineage(a) != lineage(b) || a.settings() != b.settings()
                    }
                    _ => true,
                },
                Part::Friction => self.friction != other.friction,
            })
            .collect()
    }
}

/// A part of the model beyond the paper's, as the builders take it ([`Extensions::with`],
/// [`Tissue::with`](crate::Tissue::with)): the physics terms, the populations, the walls and
/// the cell-cycle clock, the last two also as an `Option` (`None` removes the part). Each
/// part's place is written once, here.
pub trait ExtensionPart {
    /// Puts this part into `ext`, replacing the one there.
    fn place(self, ext: &mut Extensions);
}

impl ExtensionPart for Terms {
    fn place(self, ext: &mut Extensions) {
        ext.terms = self;
    }
}

impl ExtensionPart for Populations {
    fn place(self, ext: &mut Extensions) {
        ext.populations = self;
    }
}

impl ExtensionPart for Option<Walls> {
    fn place(self, ext: &mut Extensions) {
        ext.walls = self;
    }
}

impl ExtensionPart for Walls {
    fn place(self, ext: &mut Extensions) {
        Some(self).place(ext);
    }
}

impl ExtensionPart for Option<Proliferation> {
    fn place(self, ext: &mut Extensions) {
        ext.proliferation = self.map(Box::new);
    }
}

impl ExtensionPart for Option<CellFriction> {
    fn place(self, ext: &mut Extensions) {
        ext.friction = self;
    }
}

impl ExtensionPart for CellFriction {
    fn place(self, ext: &mut Extensions) {
        Some(self).place(ext);
    }
}

impl ExtensionPart for Proliferation {
    fn place(self, ext: &mut Extensions) {
        Some(self).place(ext);
    }
}
