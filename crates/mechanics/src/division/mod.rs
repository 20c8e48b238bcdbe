//! Cell division and removal (issue 28, part 2; docs/model.md §11.5): the operations on a
//! tissue ([`Tissue::divide`], [`Tissue::remove`]) and a cell-cycle clock that decides when
//! cells divide ([`Proliferation`]), with the lineage of every cell.
//!
//! A division splits the mother's field along a line through its centre
//! ([`phasefield::Cells::split`]): `φ_a = φ_m χ`, `φ_b = φ_m − φ_a`, with
//! `χ = ½[1 + tanh(d/λ)]` and `d` the distance from the line, so the field is conserved node by
//! node. The daughters get new identities (the mother's ends), their mother's population and
//! fresh term state (a new polarity); their target area is the mother's, so each regrows from
//! about half of it under the area term. The number of cells changes: call
//! [`crate::Workspace::fit`] before the next step.
//!
//! A tissue holds its clock ([`Tissue::with`]), so that the outputs and
//! checkpoints that see the tissue see the lineage too; [`Tissue::proliferate`] applies it
//! after a step, and [`crate::Simulation`] calls it after every step.

use phasefield::{ComTable, Real};

use crate::clock::AXIS_STAGE;
pub use crate::clock::{Ending, LineageRecord, Proliferation, SplitAxis};
use crate::terms::NoiseKey;
use crate::tissue::Tissue;
use crate::workspace::Workspace;

/// What a division did: the mother's identity, the daughters' identities and slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Division {
    /// The mother's identity (it ends).
    pub mother: usize,
    /// The daughters' identities: `a` on the side of the direction, `b` on the other.
    pub daughters: [usize; 2],
    /// Their slots: `a` in the mother's, `b` the new last one.
    pub slots: [usize; 2],
}

impl<T: Real> Tissue<T> {
    /// The identity the next new cell gets: one more than the largest the tissue has ever
    /// had, living or not, so that an identity is never given twice (the lineage, the terms'
    /// state and the populations are by identity).
    pub fn next_id(&self) -> usize {
        self.next_id
    }

    /// Sets [`Tissue::next_id`], as a checkpoint kept it (at least one more than every
    /// living identity).
    ///
    /// # Errors
    /// A message when `next` is not above every living identity.
    pub fn set_next_id(&mut self, next: usize) -> Result<(), String> {
        let living = self.cell_id.iter().max().map_or(0, |&m| m + 1);
        if next < living {
            return Err(format!(
                "the next identity {next} is not above every living cell's (the largest is {})",
                living - 1
            ));
        }
        self.next_id = next;
        Ok(())
    }

    /// Divides the cell in slot `slot` along the line through its centre normal to
    /// `direction` (normalised here): see the module docs. The field of every other cell and
    /// its slot are unchanged. Allocates (the new patch, and the centres' table).
    ///
    /// # Panics
    /// If `slot` is out of range or `direction` is zero.
    pub fn divide(&mut self, slot: usize, direction: [f64; 2]) -> Division {
        let norm = direction[0].hypot(direction[1]);
        assert!(norm > 0.0, "a division needs a direction");
        let dir = [direction[0] / norm, direction[1] / norm];
        let mother = self.cell_id[slot];
        let a = self.next_id();
        let b = a + 1;
        self.next_id = b + 1;
        let lambda = self.params.energy.lambda;
        let new = self.cells.split(slot, self.centre[slot], dir, lambda);
        self.cell_id[slot] = a;
        self.cell_id.push(b);
        let kind = self.ext.populations.population(mother) as u16;
        self.ext.populations.add_cell(a, kind);
        self.ext.populations.add_cell(b, kind);
        self.ext.terms.extend_to(b + 1);
        let com = ComTable::new(self.lattice());
        let ca = com.cell_centre(&self.cells, slot);
        let cb = com.cell_centre(&self.cells, new);
        // The patches stay where the mother's was (the next step centres them), so that the
        // split conserves φ node by node.
        self.centre[slot] = ca;
        self.centre.push(cb);
        Division {
            mother,
            daughters: [a, b],
            slots: [slot, new],
        }
    }

    /// Removes the cell in slot `slot` (an extrusion or a death); the cell of the last slot
    /// moves into it. Returns the removed cell's identity.
    ///
    /// # Panics
    /// If `slot` is out of range, or it is the only cell.
    pub fn remove(&mut self, slot: usize) -> usize {
        assert!(self.n_cells() > 1, "a tissue keeps at least one cell");
        self.cells.swap_remove(slot);
        self.centre.swap_remove(slot);
        self.cell_id.swap_remove(slot)
    }
}

impl Proliferation {
    /// A clock of cycle `T₀ + Exp(1/k)` for the cells of `tissue` (its founders), with the
    /// noise of `seed`.
    pub fn new<T: Real>(t0: f64, rate: f64, seed: u64, tissue: &Tissue<T>) -> Self {
        Self::starting_at(t0, rate, seed, tissue, tissue.time())
    }

    /// [`Proliferation::new`] with the founders' clocks starting at `start` (the end of a
    /// relaxation, when [`Tissue::proliferate`] starts to act) rather than at the tissue's
    /// time.
    pub fn starting_at<T: Real>(
        t0: f64,
        rate: f64,
        seed: u64,
        tissue: &Tissue<T>,
        start: f64,
    ) -> Self {
        let mut p = Self::empty(t0, rate, seed);
        let mut ids: Vec<usize> = tissue.cell_ids().to_vec();
        ids.sort_unstable();
        for id in ids {
            let cycle = p.cycle(id);
            let phase = p.phase(id);
            p.record(LineageRecord {
                id,
                parent: None,
                birth: start - phase * cycle,
                death: None,
                place: [f64::NAN; 2],
                generation: 0,
                cycle,
            });
        }
        p
    }

    /// Divides every cell whose age has reached its cycle, in the order of their identities
    /// (so the result does not depend on the slots or the threads), records the lineage and
    /// fits `ws` to the new number of cells. `ws` must hold the last evaluation of `tissue`
    /// (the state after [`Tissue::step`]), whose deformation tensors give the long axes.
    /// Returns the divisions.
    pub fn divide_due<T: Real>(
        &mut self,
        tissue: &mut Tissue<T>,
        ws: &mut Workspace<T>,
    ) -> Vec<Division> {
        let due = self.due_divisions(tissue, ws, &[]);
        let (divisions, places) = divide_cells(tissue, ws, due);
        self.record_divisions(&divisions, &places, tissue.time());
        divisions
    }

    /// The divisions due in `tissue` now, decided from it and the evaluation in `ws` without
    /// changing either: every cell whose age has reached its cycle and growth, but those in
    /// `skip` (sorted; the cells about to be removed) and those the pressure gate holds back,
    /// in the order of identities, as many as the cap leaves room for; each as its identity,
    /// its slot and the direction of its split (its long axis, or a random one for a round
    /// cell or `axis = "random"`).
    fn due_divisions<T: Real>(
        &self,
        tissue: &Tissue<T>,
        ws: &Workspace<T>,
        skip: &[usize],
    ) -> Vec<PlannedDivision> {
        let now = tissue.time();
        let mut due: Vec<(usize, usize)> = (0..tissue.n_cells())
            .map(|slot| (tissue.cell_ids()[slot], slot))
            .filter(|&(id, _)| {
                self.record_of(id)
                    .is_some_and(|r| now - r.birth >= r.cycle + self.growth_time)
                    && skip.binary_search(&id).is_err()
            })
            .collect();
        if let Some(p_max) = self.pressure_gate {
            due.retain(|&(_, slot)| cell_pressure(tissue, ws, slot) <= p_max);
        }
        due.sort_unstable();
        // Each division adds a cell: the cap is reached after this many.
        due.truncate(self.max_cells.saturating_sub(tissue.n_cells()));
        due.into_iter()
            .map(|(id, slot)| {
                // The step computes S_i only when something needs it (activity, or a term):
                // the mother's own, from her field (a division changes only its mother's
                // field, so every mother's is as the step left it). A round cell (to
                // round-off) has no long axis.
                let long = match self.axis {
                    SplitAxis::Long => {
                        let (s, scale) = shape_tensor(tissue, slot);
                        let (magnitude, axis) = s.axis();
                        (magnitude > ROUND * scale).then(|| [axis.x, axis.y])
                    }
                    SplitAxis::Random => None,
                };
                let direction = long.unwrap_or_else(|| {
                    let theta = 2.0
                        * std::f64::consts::PI
                        * NoiseKey {
                            seed: self.seed,
                            cell: id as u64,
                            step: tissue.iteration(),
                            stage: AXIS_STAGE,
                        }
                        .uniform();
                    [theta.cos(), theta.sin()]
                });
                PlannedDivision {
                    id,
                    slot,
                    direction,
                }
            })
            .collect()
    }

    /// Records `divisions` in the lineage at `now`: each mother ends by division at her
    /// place (`places`, her centre before the split), each daughter is born with her own
    /// cycle, one generation on.
    fn record_divisions(&mut self, divisions: &[Division], places: &[[f64; 2]], now: f64) {
        for (d, &place) in divisions.iter().zip(places) {
            let id = d.mother;
            let generation = self.lineage[id].generation + 1;
            self.lineage[id].death = Some((now, Ending::Division));
            self.lineage[id].place = place;
            for child in d.daughters {
                let cycle = self.cycle(child);
                self.record(LineageRecord {
                    id: child,
                    parent: Some(id),
                    birth: now,
                    death: None,
                    place: [f64::NAN; 2],
                    generation,
                    cycle,
                });
            }
        }
    }

    /// Whether a division or a death is due in `tissue` now, by the cells' ages alone (the
    /// pressure gate and the cap may still hold a division back): what a device's driver asks
    /// before it brings the state back for [`Tissue::proliferate`].
    pub(crate) fn timed_event_due<T: Real>(&self, tissue: &Tissue<T>) -> bool {
        let now = tissue.time();
        // At the cap no division happens (the removals of the same step come after the
        // divisions), so a cell that waits for room is no event.
        let room = tissue.n_cells() < self.max_cells;
        tissue.cell_ids().iter().any(|&id| {
            self.record_of(id).is_some_and(|r| {
                (room && now - r.birth >= r.cycle + self.growth_time)
                    || (self.death_rate > 0.0 && now - r.birth >= self.death_age(r))
            })
        })
    }

    /// The cells of `tissue` whose age has passed their lifespan at the death rate, in the
    /// order of their identities.
    fn dead<T: Real>(&self, tissue: &Tissue<T>) -> Vec<usize> {
        if self.death_rate <= 0.0 {
            return Vec::new();
        }
        let now = tissue.time();
        let mut dead: Vec<usize> = tissue
            .cell_ids()
            .iter()
            .copied()
            .filter(|&id| {
                self.record_of(id)
                    .is_some_and(|r| now - r.birth >= self.death_age(r))
            })
            .collect();
        dead.sort_unstable();
        dead
    }
}

/// The slot of the cell `id`, which must be in `tissue`.
fn slot_of<T: Real>(tissue: &Tissue<T>, id: usize) -> usize {
    tissue
        .cell_ids()
        .iter()
        .position(|&i| i == id)
        .expect("a listed cell is there")
}

/// What [`Tissue::proliferate`] did after one step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellEvents {
    /// The divisions, in the order of the mothers' identities.
    pub divisions: Vec<Division>,
    /// The identities of the cells removed, with why.
    pub removals: Vec<(usize, Ending)>,
    /// The last cell, when it was due to be removed too (with why): a tissue cannot be
    /// empty, so it stays, and [`crate::Simulation::run`] stops the run
    /// ([`crate::SimulationError::Extinct`]).
    pub spared: Option<(usize, Ending)>,
}

impl<T: Real> Tissue<T> {
    /// Sets each identity's target-area factor from the clock (the growth phase) at `now`;
    /// nothing without a clock.
    fn refresh_target_scale_at(&mut self, now: f64) {
        if let Some(clock) = self.ext.proliferation.as_deref() {
            clock.fill_target_scale(&self.cell_id, self.next_id, now, &mut self.ext.target_scale);
        }
    }

    /// The clock and the lineage, if cells divide.
    pub fn proliferation(&self) -> Option<&Proliferation> {
        self.ext.proliferation.as_deref()
    }

    /// Brings the growth phase's target areas to the tissue's time, as [`Tissue::proliferate`]
    /// leaves them: for a device's driver after a step without events, so that what the host
    /// evaluates (a frame, an observation) sees them.
    pub(crate) fn refresh_target_scale(&mut self) {
        self.refresh_target_scale_at(self.time);
    }

    /// Whether [`Tissue::proliferate`] could do anything after this step, judged without the
    /// state where it can be: a division or death due by age (`timed`, the clock's
    /// `timed_event_due`, which the caller has asked already), or cells extruded by the areas
    /// of the evaluation in `ws`. For a device's driver, which brings the state back only
    /// then. The growth phase's target areas are brought to `before`, the time the step
    /// started from, as the host's last [`Tissue::proliferate`] would have left them (the
    /// extrusion rule reads them, and the device's step used them).
    pub(crate) fn proliferation_pending(
        &mut self,
        ws: &Workspace<T>,
        before: f64,
        timed: bool,
    ) -> bool {
        if !self.active {
            return false;
        }
        self.refresh_target_scale_at(before);
        let Some(clock) = self.proliferation() else {
            return false;
        };
        timed || !extruded(self, ws, clock).is_empty()
    }

    /// Applies the clock after a step: the divisions that are due, then deaths at the death
    /// rate, then the extrusion rule, each in the order of identities, and fits `ws` to the
    /// new number of cells. Nothing happens while the tissue is inactive (the relaxation of
    /// a scene, whose initial discs are smaller than the cells and would be extruded). `ws` must hold the evaluation of the current state (as
    /// [`Tissue::step`] leaves it). Does nothing without a clock.
    ///
    /// Every decision is taken on the state the step left, before any event (the evaluation
    /// in `ws` is by slot, and a removal moves a slot): the cells to extrude, then the cells
    /// that die (not already extruded), then the divisions due among the rest; the removals
    /// happen after the divisions. A tissue keeps at least one cell: when the last is due to go
    /// too it stays, and [`CellEvents::spared`] says so.
    pub fn proliferate(&mut self, ws: &mut Workspace<T>) -> CellEvents {
        if !self.active {
            return CellEvents::default();
        }
        // The clock decides from a read-only view of the tissue and the evaluation...
        let Some(clock) = self.proliferation() else {
            return CellEvents::default();
        };
        let mut removals: Vec<(usize, Ending)> = extruded(self, ws, clock)
            .into_iter()
            .map(|id| (id, Ending::Extrusion))
            .collect();
        for id in clock.dead(self) {
            if !removals.iter().any(|&(r, _)| r == id) {
                removals.push((id, Ending::Death));
            }
        }
        let mut skip: Vec<usize> = removals.iter().map(|&(id, _)| id).collect();
        skip.sort_unstable();
        let due = clock.due_divisions(self, ws, &skip);
        // ...the tissue changes, and the clock records what happened.
        let (divisions, mothers) = divide_cells(self, ws, due);
        let (removed, spared) = remove_cells(self, ws, removals);
        let now = self.time;
        if let Some(clock) = self.ext.proliferation.as_deref_mut() {
            clock.record_divisions(&divisions, &mothers, now);
            for &(id, why, place) in &removed {
                clock.removed(id, now, place, why);
            }
        }
        self.refresh_target_scale_at(now);
        let removals = removed.into_iter().map(|(id, why, _)| (id, why)).collect();
        CellEvents {
            divisions,
            removals,
            spared,
        }
    }
}

/// The deformation tensor `S_i` of the cell in slot `slot`, from its field
/// (`equations::shape_tensor_density` summed over the patch, as the step's first pass does).
/// With the scale of its round-off: the sum of the magnitudes `¼ |∇φ|²` of the densities
/// summed (each density's components are at most that), of which `S_i` of a round cell is a
/// cancellation.
fn shape_tensor<T: Real>(tissue: &Tissue<T>, slot: usize) -> (crate::TracelessTensor, f64) {
    let cells = tissue.cells();
    let mut acc = [0.0; 2];
    let mut scale = 0.0;
    phasefield::for_each_stencil(cells.cell_phi(slot), cells.shape(), |_, s| {
        let (dx, dy) = (s.diff_x(), s.diff_y());
        let [xx, xy] = crate::equations::shape_tensor_density([dx, dy]);
        acc[0] += 0.25 * xx;
        acc[1] += 0.25 * xy;
        scale += 0.125 * (dx * dx + dy * dy);
    });
    (crate::TracelessTensor::from(acc), scale)
}

/// How elongated a cell must be for its long axis to be its split axis: `|S_i|` above this
/// fraction of the magnitudes summed into it (f32 storage leaves `|S_i|` of a round cell at
/// about 1e-7 of them, so that its "long axis" would be round-off, another on every backend
/// and precision; below, the axis is drawn at random).
const ROUND: f64 = 1e-5;

/// The pressure of the cell in slot `slot`, `p_i = Σ_x φ_i P / Σ_x φ_i`, the tissue pressure
/// `P` of the last evaluation in `ws` weighted by the cell's field.
pub fn cell_pressure<T: Real>(tissue: &Tissue<T>, ws: &Workspace<T>, slot: usize) -> f64 {
    let cells = tissue.cells();
    let shape = cells.shape();
    let ly = cells.lattice().ly;
    let (xs, ys) = (
        cells.map().cell_x(shape, slot),
        cells.map().cell_y(shape, slot),
    );
    let phi = cells.cell_phi(slot);
    let (mut num, mut den) = (0.0, 0.0);
    for (a, &x) in xs.iter().enumerate() {
        for (b, &y) in ys.iter().enumerate() {
            let w = phi[a * shape.ny + b].to_f64();
            num += w * ws.sum(crate::SumField::P, x as usize * ly + y as usize);
            den += w;
        }
    }
    num / den
}

/// Removes, in the order of their identities, the cells whose area `A_i = Σ φ_i²` (from the
/// last evaluation in `ws`) is below `fraction` of their target area `πR_i²`: the extrusion
/// rule of docs/model.md §11.5 (a cell squeezed out of the layer loses its area in 2D). Keeps
/// at least one cell; records each removal in `lineage` when given, and fits `ws`. Returns the
/// removed identities.
pub fn remove_extruded<T: Real>(
    tissue: &mut Tissue<T>,
    ws: &mut Workspace<T>,
    fraction: f64,
    lineage: Option<&mut Proliferation>,
) -> Vec<usize> {
    let small = extruded_by_area(tissue, ws, fraction)
        .into_iter()
        .map(|id| (id, Ending::Extrusion))
        .collect();
    let (removed, _) = remove_cells(tissue, ws, small);
    if let Some(l) = lineage {
        for &(id, why, place) in &removed {
            l.removed(id, tissue.time(), place, why);
        }
    }
    removed.into_iter().map(|(id, _, _)| id).collect()
}

/// A division the clock has decided on: the mother's identity and slot, and the direction of
/// the split.
struct PlannedDivision {
    id: usize,
    slot: usize,
    direction: [f64; 2],
}

/// Splits each planned mother in its order ([`Tissue::divide`]) and fits `ws` when any did.
/// Returns the divisions and each mother's centre before her split, for the lineage.
fn divide_cells<T: Real>(
    tissue: &mut Tissue<T>,
    ws: &mut Workspace<T>,
    planned: Vec<PlannedDivision>,
) -> (Vec<Division>, Vec<[f64; 2]>) {
    let mut places = Vec::with_capacity(planned.len());
    let divisions: Vec<Division> = planned
        .into_iter()
        .map(|p| {
            debug_assert_eq!(tissue.cell_ids()[p.slot], p.id);
            places.push(tissue.centres()[p.slot]);
            tissue.divide(p.slot, p.direction)
        })
        .collect();
    if !divisions.is_empty() {
        ws.fit(tissue.cells());
    }
    (divisions, places)
}

/// The cells [`remove_cells`] removed, each with why and its centre when it went, and the
/// last one it had to keep (see [`CellEvents::spared`]).
type Removed = (Vec<(usize, Ending, [f64; 2])>, Option<(usize, Ending)>);

/// Removes the cells `ids` in their order while more than one cell is left, and fits `ws`
/// when any went.
fn remove_cells<T: Real>(
    tissue: &mut Tissue<T>,
    ws: &mut Workspace<T>,
    ids: Vec<(usize, Ending)>,
) -> Removed {
    let mut spared = None;
    let mut removed = Vec::with_capacity(ids.len());
    for (id, why) in ids {
        if tissue.n_cells() == 1 {
            spared = Some((id, why));
            continue;
        }
        let slot = slot_of(tissue, id);
        let place = tissue.centres()[slot];
        tissue.remove(slot);
        removed.push((id, why, place));
    }
    if !removed.is_empty() {
        ws.fit(tissue.cells());
    }
    (removed, spared)
}

/// The cells (by identity, sorted) that `clock`'s extrusion rules remove after the last
/// evaluation in `ws`: by area ([`Proliferation::extrusion`]) or by pressure
/// ([`Proliferation::extrusion_pressure`]).
fn extruded<T: Real>(tissue: &Tissue<T>, ws: &Workspace<T>, clock: &Proliferation) -> Vec<usize> {
    let mut out = clock
        .extrusion
        .map(|f| extruded_by_area(tissue, ws, f))
        .unwrap_or_default();
    if let Some(p_max) = clock.extrusion_pressure {
        out.extend(
            (0..tissue.n_cells())
                .filter(|&slot| cell_pressure(tissue, ws, slot) > p_max)
                .map(|slot| tissue.cell_ids()[slot]),
        );
        out.sort_unstable();
        out.dedup();
    }
    out
}

/// The cells whose area in the evaluation `ws` is below `fraction` of their target area, in
/// the order of their identities.
fn extruded_by_area<T: Real>(tissue: &Tissue<T>, ws: &Workspace<T>, fraction: f64) -> Vec<usize> {
    // Each cell's target radius by its population's override rules (`Populations::params`).
    let mut small: Vec<usize> = (0..tissue.n_cells())
        .map(|slot| (slot, tissue.cell_ids()[slot]))
        .filter(|&(slot, id)| {
            let pops = &tissue.ext.populations;
            let r = pops
                .params(pops.population(id), &tissue.params)
                .energy
                .radius;
            let scale = tissue.ext.target_scale.get(id).copied().unwrap_or(1.0);
            ws.cell(slot).area < fraction * scale * std::f64::consts::PI * r * r
        })
        .map(|(_, id)| id)
        .collect();
    small.sort_unstable();
    small
}

#[cfg(test)]
mod tests;
