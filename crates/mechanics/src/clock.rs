//! The cell-cycle clock ([`Proliferation`]) and the lineage it keeps ([`LineageRecord`]):
//! when each cell divides, grows and dies, from its identity's noise (docs/model.md §11.5).
//! A leaf of the tissue's parts: the clock's decisions that read a tissue, and the changes
//! they make to it, are in [`crate::division`].

use crate::terms::NoiseKey;

/// Along which line a cell divides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SplitAxis {
    /// Across the long axis of the cell's deformation tensor `S_i` (the daughters lie along
    /// it: Hertwig's rule); a cell round to round-off (`|S_i|` below 1e-5 of the magnitudes
    /// summed into it) has none, and splits along a random direction as with `Random`.
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
    /// It was extruded: its area fell below the extrusion threshold.
    Extrusion,
    /// It died at the death rate (apoptosis).
    Death,
}

impl Ending {
    /// The word for outputs: `"division"`, `"extrusion"` or `"death"`.
    pub fn name(self) -> &'static str {
        match self {
            Ending::Division => "division",
            Ending::Extrusion => "extrusion",
            Ending::Death => "death",
        }
    }

    /// The inverse of [`Ending::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        [Ending::Division, Ending::Extrusion, Ending::Death]
            .into_iter()
            .find(|e| e.name() == name)
    }
}

/// One cell's line in the lineage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineageRecord {
    /// Its identity.
    pub id: usize,
    /// Its mother's identity (`None` for a founder).
    pub parent: Option<usize>,
    /// When it was born; for a founder, when its cycle started: the clock's start less a
    /// uniform fraction of its cycle, so that founders do not divide together (it can lie
    /// before the run, or inside its relaxation, while the founder is already there).
    pub birth: f64,
    /// When its life ended, and how (`None` while it lives).
    pub death: Option<(f64, Ending)>,
    /// Its centre of mass when its life ended (NaN while it lives).
    pub place: [f64; 2],
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
    /// ([`crate::division::cell_pressure`]) is above this (none: never waits).
    pub pressure_gate: Option<f64>,
    /// The extrusion rule: a cell whose area falls below this fraction of its target area
    /// is removed ([`crate::division::remove_extruded`]; none: no extrusion).
    pub extrusion: Option<f64>,
    /// The stress-based extrusion rule: a cell whose pressure ([`crate::division::cell_pressure`], the
    /// isotropic stress at the cell, compressive positive) rises above this is removed
    /// (none: no such rule).
    pub extrusion_pressure: Option<f64>,
    /// The death rate `k_d` per time unit (0: none): each cell's lifespan is drawn at its
    /// birth, exponential of mean `1/k_d`, and it is removed when its age passes it.
    pub death_rate: f64,
    /// The growth time `T_g` (0: none): once a cell's age reaches its cycle it grows, its
    /// target area ramping linearly from `πR²` to `2πR²` over `T_g`, and divides at
    /// `cycle + T_g`, so the mean time between divisions is `T₀ + 1/k + T_g`.
    pub growth_time: f64,
    pub(crate) seed: u64,
    pub(crate) lineage: Vec<LineageRecord>,
}

/// The noise stages of the clock, apart from the terms' and from each other.
const CYCLE_STAGE: u64 = 1 << 61;
const PHASE_STAGE: u64 = CYCLE_STAGE + 1;
pub(crate) const AXIS_STAGE: u64 = CYCLE_STAGE + 2;
const DEATH_STAGE: u64 = CYCLE_STAGE + 3;

impl Proliferation {
    /// A clock restored from its lineage (a checkpoint's), with the parameters and seed it
    /// was made with (`axis`, the gate and the rest as set by the `with_*` methods after).
    ///
    /// # Errors
    /// Two records of one identity.
    pub fn restore(
        t0: f64,
        rate: f64,
        seed: u64,
        records: impl IntoIterator<Item = LineageRecord>,
    ) -> Result<Self, String> {
        let mut p = Self::empty(t0, rate, seed);
        for r in records {
            if p.record_of(r.id).is_some() {
                return Err(format!("cell {} appears twice in the lineage", r.id));
            }
            p.record(r);
        }
        Ok(p)
    }

    /// Replaces the lineage with `records` (a checkpoint's), keeping the parameters.
    ///
    /// # Errors
    /// Two records of one identity.
    pub fn replace_lineage(
        &mut self,
        records: impl IntoIterator<Item = LineageRecord>,
    ) -> Result<(), String> {
        let mut restored = Self::restore(self.t0, self.rate, self.seed, records)?;
        std::mem::swap(&mut self.lineage, &mut restored.lineage);
        Ok(())
    }

    /// Every setting of the clock (not its lineage), for comparisons: those in effect
    /// ([`Proliferation::settings_in_effect`], which lists every field) and the seed.
    pub fn settings(&self) -> String {
        format!("{:?}", (self.settings_in_effect(), self.seed))
    }

    /// Every key of `[division]` in effect, as `(scene key, value)` (the destructuring has
    /// no `..`: a field added to the clock does not compile until it is listed, so that no
    /// backend runs a setting it has never heard of). The cycle is given as the clock holds
    /// it, `T₀` and the rate `k` of its exponential part.
    pub fn settings_in_effect(&self) -> Vec<(String, String)> {
        let Proliferation {
            t0,
            rate,
            axis,
            max_cells,
            pressure_gate,
            extrusion,
            extrusion_pressure,
            death_rate,
            growth_time,
            seed: _,
            lineage: _,
        } = self;
        let mut out = vec![
            (
                "[division] cycle_time".to_string(),
                format!("T0 = {t0}, k = {rate}"),
            ),
            (
                "[division] axis".into(),
                match axis {
                    SplitAxis::Long => "long",
                    SplitAxis::Random => "random",
                }
                .into(),
            ),
            ("[division] max_cells".into(), max_cells.to_string()),
        ];
        let optional = [
            ("pressure_gate", *pressure_gate),
            ("extrusion", *extrusion),
            ("extrusion_pressure", *extrusion_pressure),
            ("death_rate", (*death_rate > 0.0).then_some(*death_rate)),
            ("growth_time", (*growth_time > 0.0).then_some(*growth_time)),
        ];
        for (key, v) in optional {
            if let Some(v) = v {
                out.push((format!("[division] {key}"), v.to_string()));
            }
        }
        out
    }

    /// A clock of cycle `T₀ + Exp(1/k)` with the default options and no cell in its
    /// lineage: what [`Proliferation::starting_at`] and [`Proliferation::restore`] fill.
    pub(crate) fn empty(t0: f64, rate: f64, seed: u64) -> Self {
        Self {
            t0,
            rate,
            axis: SplitAxis::Long,
            max_cells: usize::MAX,
            pressure_gate: None,
            extrusion: None,
            extrusion_pressure: None,
            death_rate: 0.0,
            growth_time: 0.0,
            seed,
            lineage: Vec::new(),
        }
    }

    /// The same clock with the extrusion rule: cells whose area falls below `fraction` of
    /// their target area are removed.
    pub fn with_extrusion(mut self, fraction: f64) -> Self {
        self.extrusion = Some(fraction);
        self
    }

    /// The same clock with the stress-based extrusion rule: cells whose pressure
    /// ([`crate::division::cell_pressure`]) rises above `p_max` are removed.
    pub fn with_extrusion_pressure(mut self, p_max: f64) -> Self {
        self.extrusion_pressure = Some(p_max);
        self
    }

    /// Whether the clock removes cells by a rule on the last evaluation (area or pressure).
    pub fn extrudes(&self) -> bool {
        self.extrusion.is_some() || self.extrusion_pressure.is_some()
    }

    /// The same clock with a growth phase of `t_g` before each division.
    pub fn with_growth_time(mut self, t_g: f64) -> Self {
        self.growth_time = t_g;
        self
    }

    /// The target area of the cell of `r` at `now` as a multiple of `πR²`: 1, rising
    /// linearly to 2 over the growth time once its age passes its cycle.
    pub fn target_scale(&self, r: &LineageRecord, now: f64) -> f64 {
        if self.growth_time <= 0.0 {
            return 1.0;
        }
        1.0 + ((now - r.birth - r.cycle) / self.growth_time).clamp(0.0, 1.0)
    }

    /// Fills `out` (by identity, below `next_id`) with the target-area scale at `now` of the
    /// living cells `ids`; empty without a growth phase. Grows `out` only when identities are
    /// added.
    pub(crate) fn fill_target_scale(
        &self,
        ids: &[usize],
        next_id: usize,
        now: f64,
        out: &mut Vec<f64>,
    ) {
        if self.growth_time <= 0.0 {
            out.clear();
            return;
        }
        out.resize(next_id, 1.0);
        for &id in ids {
            out[id] = self
                .record_of(id)
                .map_or(1.0, |r| self.target_scale(r, now));
        }
    }

    /// The same clock with the death rate `k_d` per time unit.
    pub fn with_death_rate(mut self, k_d: f64) -> Self {
        self.death_rate = k_d;
        self
    }

    /// Bytes of heap memory held by the lineage.
    pub fn heap_bytes(&self) -> usize {
        self.lineage.capacity() * std::mem::size_of::<LineageRecord>()
    }

    /// The age at which the cell of `r` dies at the death rate (infinite without one): its
    /// lifespan counted from its birth, or for a founder from the clock's start (the death
    /// rate is a constant hazard, so a founder alive at the start has a lifespan of the same
    /// law ahead of it; its age then is `phase · cycle`, from its noise).
    pub(crate) fn death_age(&self, r: &LineageRecord) -> f64 {
        let at_start = if r.parent.is_none() {
            self.phase(r.id) * r.cycle
        } else {
            0.0
        };
        at_start + self.lifespan(r.id)
    }

    /// A founder's age at the start as a fraction of its cycle, from its noise.
    pub(crate) fn phase(&self, id: usize) -> f64 {
        NoiseKey {
            seed: self.seed,
            cell: id as u64,
            step: 0,
            stage: PHASE_STAGE,
        }
        .uniform()
    }

    /// The lifespan of the cell `id` at the death rate (infinite without one), drawn from its
    /// noise: exponential of mean `1/k_d`.
    pub(crate) fn lifespan(&self, id: usize) -> f64 {
        if self.death_rate <= 0.0 {
            return f64::INFINITY;
        }
        let u = NoiseKey {
            seed: self.seed,
            cell: id as u64,
            step: 0,
            stage: DEATH_STAGE,
        }
        .uniform();
        -u.ln() / self.death_rate
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
    pub(crate) fn cycle(&self, id: usize) -> f64 {
        let u = NoiseKey {
            seed: self.seed,
            cell: id as u64,
            step: 0,
            stage: CYCLE_STAGE,
        }
        .uniform();
        self.t0 - u.ln() / self.rate
    }

    pub(crate) fn record(&mut self, r: LineageRecord) {
        if self.lineage.len() <= r.id {
            self.lineage.resize(
                r.id + 1,
                LineageRecord {
                    id: usize::MAX,
                    parent: None,
                    birth: f64::NAN,
                    death: None,
                    place: [f64::NAN; 2],
                    generation: 0,
                    cycle: f64::NAN,
                },
            );
        }
        self.lineage[r.id] = r;
    }

    /// The lineage record of the cell `id`, if it has one (the lineage is indexed by
    /// identity, with holes for identities it never saw).
    pub(crate) fn record_of(&self, id: usize) -> Option<&LineageRecord> {
        self.lineage.get(id).filter(|r| r.id == id)
    }

    /// Every cell that has lived, by identity.
    pub fn lineage(&self) -> impl Iterator<Item = &LineageRecord> {
        self.lineage.iter().filter(|r| r.id != usize::MAX)
    }

    /// Records the end of the cell `id` at `time`, at `place`, for `why` (call it with the
    /// identity [`crate::Tissue::remove`] returns).
    pub fn removed(&mut self, id: usize, time: f64, place: [f64; 2], why: Ending) {
        if let Some(r) = self.lineage.get_mut(id).filter(|r| r.id == id) {
            r.death = Some((time, why));
            r.place = place;
        }
    }

    /// The time at which the cell `id` starts to grow (its birth plus its cycle; its target
    /// area then ramps over [`Proliferation::growth_time`]), if the clock knows it.
    pub fn growth_start(&self, id: usize) -> Option<f64> {
        self.record_of(id).map(|r| r.birth + r.cycle)
    }
}
