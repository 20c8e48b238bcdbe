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
//! Not yet wired to scenes and outputs: frames, checkpoints, `analyze` and `render` assume a
//! fixed number of cells (issue 28 says what is left).

use phasefield::{ComTable, Real};

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
    /// The identity the next new cell gets: one more than the largest so far.
    pub fn next_id(&self) -> usize {
        self.cell_id.iter().max().map_or(0, |&m| m + 1)
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
        let lambda = self.params.energy.lambda;
        let new = self.cells.split(slot, self.centre[slot], dir, lambda);
        self.cell_id[slot] = a;
        self.cell_id.push(b);
        let kind = self.populations.population(mother) as u16;
        self.populations.add_cell(a, kind);
        self.populations.add_cell(b, kind);
        self.terms.extend_to(b + 1);
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

/// Along which line a cell divides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SplitAxis {
    /// Across the long axis of the cell's deformation tensor `S_i` (the daughters lie along
    /// it: Hertwig's rule).
    #[default]
    Long,
    /// A direction drawn uniformly from the noise of the cell and the step.
    Random,
}

/// Why a cell's life ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    /// It divided.
    Division,
    /// It was removed (extruded).
    Removal,
}

/// One cell's line in the lineage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineageRecord {
    /// Its identity.
    pub id: usize,
    /// Its mother's identity (`None` for a founder).
    pub parent: Option<usize>,
    /// When it was born (0 for a founder).
    pub birth: f64,
    /// When its life ended, and how (`None` while it lives).
    pub death: Option<(f64, Ending)>,
    /// Its generation: 0 for a founder, the mother's plus one for a daughter.
    pub generation: u32,
    /// Its cycle time: it divides at `birth + cycle`.
    pub cycle: f64,
}

/// A cell-cycle clock: each cell divides when its age reaches a cycle time drawn at its birth,
/// `T = T₀ + E` with `E` exponential of mean `1/k` (so a mean cycle `T₀ + 1/k`), from the
/// counter-based noise of its identity (docs/model.md §11.5). Founders' ages start at a
/// uniform fraction of their cycle, so that they do not divide together.
#[derive(Debug, Clone)]
pub struct Proliferation {
    /// The fixed part `T₀` of the cycle.
    pub t0: f64,
    /// The rate `k` of its exponential part.
    pub rate: f64,
    /// The axis of the split.
    pub axis: SplitAxis,
    /// At most this many cells: a cell due to divide waits while the tissue has them.
    pub max_cells: usize,
    /// Contact inhibition of proliferation: a cell due to divide waits while its pressure
    /// ([`cell_pressure`]) is above this (none: never waits).
    pub pressure_gate: Option<f64>,
    seed: u64,
    lineage: Vec<LineageRecord>,
}

/// The noise stages of the clock, apart from the terms' and from each other.
const CYCLE_STAGE: u64 = 1 << 61;
const PHASE_STAGE: u64 = CYCLE_STAGE + 1;
const AXIS_STAGE: u64 = CYCLE_STAGE + 2;

impl Proliferation {
    /// A clock of cycle `T₀ + Exp(1/k)` for the cells of `tissue` (its founders), with the
    /// noise of `seed`.
    pub fn new<T: Real>(t0: f64, rate: f64, seed: u64, tissue: &Tissue<T>) -> Self {
        let mut p = Self {
            t0,
            rate,
            axis: SplitAxis::Long,
            max_cells: usize::MAX,
            pressure_gate: None,
            seed,
            lineage: Vec::new(),
        };
        let mut ids: Vec<usize> = tissue.cell_ids().to_vec();
        ids.sort_unstable();
        for id in ids {
            let cycle = p.cycle(id);
            let phase = NoiseKey {
                seed,
                cell: id as u64,
                step: 0,
                stage: PHASE_STAGE,
            }
            .uniform();
            p.record(LineageRecord {
                id,
                parent: None,
                birth: tissue.time() - phase * cycle,
                death: None,
                generation: 0,
                cycle,
            });
        }
        p
    }

    /// The same clock with the split along `axis`.
    pub fn with_axis(mut self, axis: SplitAxis) -> Self {
        self.axis = axis;
        self
    }

    /// The same clock with contact inhibition of proliferation: a cell due to divide waits
    /// while its pressure is above `p_max`.
    pub fn with_pressure_gate(mut self, p_max: f64) -> Self {
        self.pressure_gate = Some(p_max);
        self
    }

    /// The same clock with at most `max_cells` cells.
    pub fn with_max_cells(mut self, max_cells: usize) -> Self {
        self.max_cells = max_cells;
        self
    }

    /// The cycle time of the cell `id`, drawn from its noise.
    fn cycle(&self, id: usize) -> f64 {
        let u = NoiseKey {
            seed: self.seed,
            cell: id as u64,
            step: 0,
            stage: CYCLE_STAGE,
        }
        .uniform();
        self.t0 - u.ln() / self.rate
    }

    fn record(&mut self, r: LineageRecord) {
        if self.lineage.len() <= r.id {
            self.lineage.resize(
                r.id + 1,
                LineageRecord {
                    id: usize::MAX,
                    parent: None,
                    birth: f64::NAN,
                    death: None,
                    generation: 0,
                    cycle: f64::NAN,
                },
            );
        }
        self.lineage[r.id] = r;
    }

    /// Every cell that has lived, by identity.
    pub fn lineage(&self) -> impl Iterator<Item = &LineageRecord> {
        self.lineage.iter().filter(|r| r.id != usize::MAX)
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
        let now = tissue.time();
        let mut due: Vec<(usize, usize)> = (0..tissue.n_cells())
            .map(|slot| (tissue.cell_ids()[slot], slot))
            .filter(|&(id, _)| {
                self.lineage
                    .get(id)
                    .is_some_and(|r| r.id == id && now - r.birth >= r.cycle)
            })
            .collect();
        if let Some(p_max) = self.pressure_gate {
            due.retain(|&(_, slot)| cell_pressure(tissue, ws, slot) <= p_max);
        }
        due.sort_unstable();
        let mut out = Vec::with_capacity(due.len());
        for (id, slot) in due {
            if tissue.n_cells() >= self.max_cells {
                break;
            }
            let direction = match self.axis {
                SplitAxis::Long => {
                    let (_, axis) = ws.cell(slot).shape.axis();
                    if axis.norm() > 0.0 {
                        [axis.x, axis.y]
                    } else {
                        [1.0, 0.0]
                    }
                }
                SplitAxis::Random => {
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
                }
            };
            let d = tissue.divide(slot, direction);
            let generation = self.lineage[id].generation + 1;
            self.lineage[id].death = Some((now, Ending::Division));
            for child in d.daughters {
                let cycle = self.cycle(child);
                self.record(LineageRecord {
                    id: child,
                    parent: Some(id),
                    birth: now,
                    death: None,
                    generation,
                    cycle,
                });
            }
            out.push(d);
        }
        if !out.is_empty() {
            ws.fit(tissue.cells());
        }
        out
    }

    /// Records the removal of the cell `id` at the tissue's time (call it with the identity
    /// [`Tissue::remove`] returns).
    pub fn removed(&mut self, id: usize, time: f64) {
        if let Some(r) = self.lineage.get_mut(id).filter(|r| r.id == id) {
            r.death = Some((time, Ending::Removal));
        }
    }
}

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
    mut lineage: Option<&mut Proliferation>,
) -> Vec<usize> {
    // Each cell's target radius by its population's override rules (`Populations::params`).
    let mut small: Vec<usize> = (0..tissue.n_cells())
        .map(|slot| (slot, tissue.cell_ids()[slot]))
        .filter(|&(slot, id)| {
            let pops = &tissue.populations;
            let r = pops
                .params(pops.population(id), &tissue.params)
                .energy
                .radius;
            ws.cell(slot).area < fraction * std::f64::consts::PI * r * r
        })
        .map(|(_, id)| id)
        .collect();
    small.sort_unstable();
    let mut out = Vec::new();
    for id in small {
        if tissue.n_cells() == 1 {
            break;
        }
        let slot = tissue
            .cell_ids()
            .iter()
            .position(|&i| i == id)
            .expect("a listed cell is there");
        tissue.remove(slot);
        if let Some(l) = lineage.as_deref_mut() {
            l.removed(id, tissue.time());
        }
        out.push(id);
    }
    if !out.is_empty() {
        ws.fit(tissue.cells());
    }
    out
}

#[cfg(test)]
mod tests;
