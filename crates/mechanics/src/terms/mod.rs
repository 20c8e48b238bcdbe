//! Physics terms beyond the paper's minimal model, and the place to put a new one
//! (docs/model.md §11).
//!
//! A term plugs into the step in one of these ways:
//! - a **whole-cell force** `f_i` added to the interface force before the velocity,
//!   `ξ_i v_i = F_i + Σ_terms f_i` ([`CellTerm::force`]);
//! - **per-cell state** `x_i` with its own dynamics `dx_i = r(x_i, cell) dt + b dW`
//!   ([`CellTerm::rate`], [`CellTerm::noise`]), integrated by the same Heun predictor and
//!   corrector as the fields (the stochastic Heun scheme, with one noise increment per step
//!   used by both stages), and stored by cell identity so that re-sorting, checkpoints and
//!   resumes carry it;
//! - a **force density or free-energy derivative** inside the node loops: these are built in,
//!   configured by plain parameters that the kernels read, since a loop that must vectorise
//!   cannot call a trait object per node;
//! - a **fix**: anything that changes the state between steps ([`crate::Fix`], run by
//!   [`crate::Simulation::add_fix`]).
//!
//! A [`CellTerm`] may live in another crate (the workspace's `examples/custom-term` crate
//! implements one). [`Polarity`] (self-propulsion with rotational diffusion and alignment) is
//! the built-in one, written against the same trait.
//!
//! With no term configured the step does what it did before the terms existed, to the bit.
//!
//! Noise is counter-based ([`NoiseKey`]): a deviate is a function of (seed, cell identity,
//! step, stage), never of the thread count, the slot order or what was drawn before.

mod nematic;
mod noise;
mod polarity;
mod populations;

use std::fmt;
use std::sync::Arc;

use nalgebra::Vector2;

pub use nematic::{
    elastic_rate, nematic_alignment_rate, nematic_angle, nematic_tensor, CellNematic,
};
pub use noise::{normal_of_words, philox4x32_10, uniform_of_word, NoiseKey};
pub use polarity::{alignment_rate, alignment_target, propulsion, Align, Polarity, Propulsion};
pub use populations::{CellConstants, Population, Populations};

use crate::evaluation::CellState;

/// What a term sees of one cell when it is asked for a force or a rate.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct CellContext<'a> {
    /// The cell's identity (its index in the initial state).
    pub id: usize,
    /// Its centre of mass, as the step placed its patch.
    pub centre: [f64; 2],
    /// What the evaluation the term is called after computed for it. In
    /// [`CellTerm::force`], which is called *before* an evaluation, this is what the last
    /// evaluation of a step computed for this cell, kept by identity (at the start of a run,
    /// after a resume and for a new cell, zero): an observation's evaluation between steps, or
    /// a re-sort of the slots, does not change it. A whole-cell force should depend mostly on
    /// the term's own state.
    pub state: &'a CellState,
    /// The cell's population (0 without populations).
    pub population: usize,
    /// Whether activity is on (off during the relaxation of docs/model.md §6; see
    /// [`crate::Simulation::activity_from`]). Active terms (propulsion, its noise and
    /// alignment) do nothing while it is off.
    pub active: bool,
}

/// A physics term with a whole-cell force and per-cell state (see the [module docs](self)).
///
/// Every method has a default that contributes nothing, so a term implements only what it
/// adds. A term holds parameters only; its per-cell state is kept by the [`Terms`] it is
/// added to. Implementations must be deterministic functions of their arguments (noise comes
/// through [`CellTerm::noise`], drawn by the driver from counter-based keys).
pub trait CellTerm: Send + Sync + fmt::Debug + std::any::Any {
    /// A short name, unique within a tissue: the prefix of its state in outputs and
    /// checkpoints.
    fn name(&self) -> &str;

    /// The names of its per-cell state variables; empty (the default) for none.
    fn state_names(&self) -> &[&'static str] {
        &[]
    }

    /// What state variable `variable` means, for the run's `run.json` (the default names it
    /// as a physics term's per-cell state).
    fn describe_state(&self, variable: &str) -> String {
        format!(
            "the per-cell state variable {}/{variable} of a physics term",
            self.name()
        )
    }

    /// Per-cell quantities derived from a cell's state `x` that frames write beside the state
    /// (polarity: the unit vector of its angle), each as `(array name, meaning, values)`, the
    /// same names and lengths for every cell; empty (the default) for none.
    fn derived(&self, x: &[f64]) -> Vec<(&'static str, &'static str, Vec<f64>)> {
        let _ = x;
        Vec::new()
    }

    /// The settings of this term in effect, each as `(scene key, value)`, for a backend to
    /// compare with what it implements ([`crate::Extensions::settings`]): by default the
    /// term's table `[terms.NAME]` as one setting, which no device implements (a term of a
    /// user's runs on the host). A built-in term lists each key, so that a backend refuses
    /// one it lacks by name.
    fn settings(&self) -> Vec<(String, String)> {
        vec![(
            format!("[terms.{}]", self.name()),
            "a physics term whose code runs on the host".into(),
        )]
    }

    /// Tissue-level observables the term defines from its state, over the cells whose
    /// identities are `ids` (`x` holds `state_names().len()` values per identity), each as
    /// `(name, value)`: the polar order `|⟨p_i⟩|` of [`Polarity`], for example. The analysis
    /// of a run (`observables.csv`) reads them here, so that a term brings its own; empty (the
    /// default) for none.
    fn observables(&self, x: &[f64], ids: &[usize]) -> Vec<(&'static str, f64)> {
        let _ = (x, ids);
        Vec::new()
    }

    /// The initial state of cell `id` into `out` (`state_names().len()` values); `keys(k)` is
    /// a distinct [`NoiseKey`] for each `k`, to draw from.
    fn initial_state(&self, id: usize, keys: &dyn Fn(u64) -> NoiseKey, out: &mut [f64]) {
        let _ = (id, keys);
        out.fill(0.0);
    }

    /// Whether the term's dynamics read the cells' deformation tensors (`CellContext::state`'s
    /// `shape`): every evaluation of a step then computes them, which it otherwise does only
    /// with an active stress. False by default; the built-in terms say true when they align
    /// to the shape.
    fn needs_shapes(&self) -> bool {
        false
    }

    /// Whether the term has a whole-cell force (true by default; a term with state only, such
    /// as the cells' nematic, says false, and its force is then not listed among the forces by
    /// origin).
    fn has_force(&self) -> bool {
        true
    }

    /// The whole-cell force on the cell with state `x`, added to its interface force before
    /// the velocity `v_i = (F_i + Σ f_i)/ξ_i` is formed.
    fn force(&self, cell: &CellContext<'_>, x: &[f64]) -> [f64; 2] {
        let _ = (cell, x);
        [0.0; 2]
    }

    /// The whole-cell forces on every cell at once into `out` (one per slot of `cells`),
    /// where `x` is the term's state of every identity (`state_names().len()` values each).
    /// The default asks [`CellTerm::force`] cell by cell; a term that is cheaper in bulk (one
    /// call into another language per evaluation, say) overrides this instead.
    fn forces(&self, cells: &CellBatch<'_>, x: &[f64], out: &mut [[f64; 2]]) {
        let len = self.state_names().len();
        for (slot, f) in out.iter_mut().enumerate() {
            let cell = cells.context(slot);
            *f = self.force(&cell, &x[cell.id * len..(cell.id + 1) * len]);
        }
    }

    /// The deterministic rate `dx/dt` of the state `x` into `out`, from the cell as the
    /// evaluation at this state left it.
    fn rate(&self, cell: &CellContext<'_>, x: &[f64], out: &mut [f64]) {
        let _ = (cell, x);
        out.fill(0.0);
    }

    /// How fast the deterministic rate relaxes the state `x` (the largest `|∂ rate/∂x|`, per
    /// unit time): Heun's step of size `dt` is stable while `stiffness · dt ≤ 2`, and the step
    /// refuses to go on beyond ([`crate::StepError::TermUnstable`]). The default, 0, is for a
    /// term without a relaxing rate.
    fn stiffness(&self, cell: &CellContext<'_>, x: &[f64]) -> f64 {
        let _ = (cell, x);
        0.0
    }

    /// The amplitude `b` of the additive noise `b dW` of each state variable into `out`
    /// (`dW` a Wiener increment, `⟨dW²⟩ = dt`).
    fn noise(&self, cell: &CellContext<'_>, out: &mut [f64]) {
        let _ = cell;
        out.fill(0.0);
    }
}

/// One term and its per-cell state, by cell identity.
#[derive(Debug, Clone)]
struct Entry {
    term: Arc<dyn CellTerm>,
    /// State variables per cell.
    len: usize,
    /// The state `x`, `len` values per identity.
    x: Vec<f64>,
    /// The state at the start of the step.
    old: Vec<f64>,
    /// The rate at the start of the step.
    rate1: Vec<f64>,
    /// The noise of the step, `b N` (per √dt).
    kick: Vec<f64>,
    /// Scratch for a rate.
    scratch: Vec<f64>,
}

impl Entry {
    /// Sizes the state for identities below `n_new` and gives those from `n` on their
    /// initial state (`t`: the term's place among the terms, which its keys carry).
    fn extend(&mut self, t: usize, seed: u64, n: usize, n_new: usize) {
        let len = self.len;
        for v in [&mut self.x, &mut self.old, &mut self.rate1, &mut self.kick] {
            v.resize(n_new * len, 0.0);
        }
        for id in n..n_new {
            let key = |k: u64| NoiseKey {
                seed,
                cell: id as u64,
                step: 0,
                stage: INITIAL_STAGE + ((t as u64) << 16) + k,
            };
            self.term
                .initial_state(id, &key, &mut self.x[id * len..(id + 1) * len]);
        }
    }
}

/// The terms of a tissue with their per-cell state: built with [`Terms::new`] and
/// [`Terms::with`], attached by [`crate::Tissue::with`].
#[derive(Debug, Clone, Default)]
pub struct Terms {
    entries: Vec<Entry>,
    seed: u64,
    /// Cells whose state is allocated (0 before the terms are attached to a tissue).
    n: usize,
    /// What the last evaluation of a step computed for each identity (`CellContext::state`
    /// in [`CellTerm::force`]), kept here by identity when the step's stages begin and
    /// correct, so that an observation's evaluation between steps, or a re-sort of the slots,
    /// changes nothing the terms see. Zero for an identity no step has evaluated yet (a new
    /// run, a resumed one, a new cell).
    last: Vec<CellState>,
}

/// The `stage` of a key of an initial state: far from the terms' stages of a step.
const INITIAL_STAGE: u64 = 1 << 62;

impl Terms {
    /// No terms, with the seed of their noise.
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            ..Self::default()
        }
    }

    /// These terms and `term`.
    ///
    /// # Panics
    /// If a term of the same name is already there.
    pub fn with(mut self, term: impl CellTerm + 'static) -> Self {
        self.add(Arc::new(term));
        self
    }

    /// Adds a shared term.
    ///
    /// # Panics
    /// If a term of the same name is already there.
    pub fn add(&mut self, term: Arc<dyn CellTerm>) {
        assert!(
            self.get(term.name()).is_none(),
            "a term named {:?} is already there",
            term.name()
        );
        let len = term.state_names().len();
        self.entries.push(Entry {
            term,
            len,
            x: Vec::new(),
            old: Vec::new(),
            rate1: Vec::new(),
            kick: Vec::new(),
            scratch: vec![0.0; len],
        });
        // The new term's state for the identities there are; the others keep theirs.
        let (n, seed, t) = (self.n, self.seed, self.entries.len() - 1);
        self.last.resize(n, CellState::default());
        self.entries
            .last_mut()
            .expect("just pushed")
            .extend(t, seed, 0, n);
    }

    /// Whether there is no term.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The seed of the terms' noise.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The terms, in the order added.
    pub fn iter(&self) -> impl Iterator<Item = &dyn CellTerm> {
        self.entries.iter().map(|e| &*e.term)
    }

    /// The number of terms.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// The built-in [`Polarity`] with its place among the terms (the place its noise keys
    /// carry), if it is one of them: what a backend that runs only the built-in terms (the
    /// GPU's) looks for.
    pub fn polarity(&self) -> Option<(usize, &Polarity)> {
        self.entries.iter().enumerate().find_map(|(t, e)| {
            let any: &dyn std::any::Any = &*e.term;
            any.downcast_ref::<Polarity>().map(|p| (t, p))
        })
    }

    /// The built-in [`CellNematic`] with its state by identity (`θ_i`), if it is one of the
    /// terms: what an evaluation reads for the nematic's stress and fields.
    pub fn nematic(&self) -> Option<(&CellNematic, &[f64])> {
        self.entries.iter().find_map(|e| {
            let any: &dyn std::any::Any = &*e.term;
            any.downcast_ref::<CellNematic>().map(|n| (n, &e.x[..]))
        })
    }

    /// Whether the cells' nematic adds to the stress with the activity `active` (a `ζ_Q` that
    /// is not zero, and the activity on): the one rule by which an evaluation weights its
    /// active tensors (`kernels::evaluate`), the analysis's fields undo that weighting and
    /// the forces by origin list the nematic's part.
    pub(crate) fn nematic_stress(&self, active: bool) -> bool {
        active && self.nematic().is_some_and(|(n, _)| n.is_active())
    }

    /// Whether a term's dynamics read the cells' deformation tensors (an alignment to the
    /// shape), so that every evaluation of a step must compute them.
    pub(crate) fn need_shapes(&self) -> bool {
        self.iter().any(|t| t.needs_shapes())
    }

    /// The term named `name`.
    pub fn get(&self, name: &str) -> Option<&dyn CellTerm> {
        self.iter().find(|t| t.name() == name)
    }

    /// The per-cell state of the term named `name`: `state_names().len()` values per cell,
    /// by identity.
    pub fn state(&self, name: &str) -> Option<&[f64]> {
        self.entries
            .iter()
            .find(|e| e.term.name() == name)
            .map(|e| &e.x[..])
    }

    /// Every state variable of every term as `(term/variable, values by identity)`, for
    /// outputs and checkpoints.
    pub fn variables(&self) -> Vec<(String, Vec<f64>)> {
        let mut out = Vec::new();
        for e in &self.entries {
            for (k, v) in e.term.state_names().iter().enumerate() {
                let values = (0..self.n).map(|id| e.x[id * e.len + k]).collect();
                out.push((format!("{}/{v}", e.term.name()), values));
            }
        }
        out
    }

    /// The meaning of each state variable `term/variable` ([`CellTerm::describe_state`]).
    pub fn meanings(&self) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for e in &self.entries {
            for v in e.term.state_names() {
                out.push((format!("{}/{v}", e.term.name()), e.term.describe_state(v)));
            }
        }
        out
    }

    /// Every term's tissue-level observables ([`CellTerm::observables`]) over the cells
    /// whose identities are `ids`, term by term in the order added.
    pub fn observables(&self, ids: &[usize]) -> Vec<(&'static str, f64)> {
        self.entries
            .iter()
            .flat_map(|e| e.term.observables(&e.x, ids))
            .collect()
    }

    /// Every quantity the terms derive from their state ([`CellTerm::derived`]) as
    /// `(array name, meaning, columns, values by identity)`.
    pub fn derived(&self) -> Vec<(String, String, usize, Vec<f64>)> {
        let mut out: Vec<(String, String, usize, Vec<f64>)> = Vec::new();
        for e in &self.entries {
            let first = out.len();
            for id in 0..self.n {
                let x = &e.x[id * e.len..(id + 1) * e.len];
                for (k, (name, meaning, values)) in e.term.derived(x).into_iter().enumerate() {
                    if id == 0 {
                        out.push((
                            name.to_string(),
                            meaning.to_string(),
                            values.len(),
                            Vec::new(),
                        ));
                    }
                    out[first + k].3.extend(values);
                }
            }
            if self.n == 0 {
                let x = vec![0.0; e.len];
                for (name, meaning, values) in e.term.derived(&x) {
                    out.push((
                        name.to_string(),
                        meaning.to_string(),
                        values.len(),
                        Vec::new(),
                    ));
                }
            }
        }
        out
    }

    /// Sets the state variable `term/variable` ([`Terms::variables`]' names) from values by
    /// identity, as a checkpoint kept them.
    ///
    /// # Errors
    /// A message when no term has that variable or the count is not the number of cells.
    pub fn set_variable(&mut self, name: &str, values: &[f64]) -> Result<(), String> {
        let n = self.n;
        let (term, var) = name
            .split_once('/')
            .ok_or_else(|| format!("{name:?} is not of the form term/variable"))?;
        let e = self
            .entries
            .iter_mut()
            .find(|e| e.term.name() == term)
            .ok_or_else(|| format!("no term named {term:?}"))?;
        let k = e
            .term
            .state_names()
            .iter()
            .position(|v| *v == var)
            .ok_or_else(|| format!("the term {term:?} has no variable {var:?}"))?;
        if values.len() != n {
            return Err(format!("{} values of {name} for {n} cells", values.len()));
        }
        for (id, v) in values.iter().enumerate() {
            e.x[id * e.len + k] = *v;
        }
        Ok(())
    }

    /// Allocates and initialises the state of `n` cells (what [`crate::Tissue::with`]
    /// does); a no-op when it is there already.
    pub(crate) fn initialise(&mut self, n: usize) {
        if self.n == n {
            return;
        }
        for e in &mut self.entries {
            for v in [&mut e.x, &mut e.old, &mut e.rate1, &mut e.kick] {
                v.clear();
            }
        }
        self.last.clear();
        self.n = 0;
        self.extend_to(n);
    }

    /// Allocates and initialises the state of the identities `n..n_new` (new cells of a
    /// division), keeping the state of the others; a no-op when it is there already.
    pub(crate) fn extend_to(&mut self, n_new: usize) {
        if n_new <= self.n || self.entries.is_empty() {
            self.n = self.n.max(n_new);
            return;
        }
        self.last.resize(n_new, CellState::default());
        let (n, seed) = (self.n, self.seed);
        for (t, e) in self.entries.iter_mut().enumerate() {
            e.extend(t, seed, n, n_new);
        }
        self.n = n_new;
    }

    /// Bytes of heap memory held by the state.
    pub(crate) fn heap_bytes(&self) -> usize {
        self.entries
            .iter()
            .map(|e| {
                (e.x.capacity()
                    + e.old.capacity()
                    + e.rate1.capacity()
                    + e.kick.capacity()
                    + e.scratch.capacity())
                    * 8
            })
            .sum::<usize>()
            + self.last.capacity() * std::mem::size_of::<CellState>()
    }

    /// The whole-cell forces of the current state into `out` (by slot): each term's
    /// [`CellTerm::forces`], summed from zero in the terms' order.
    pub(crate) fn forces(&self, view: &CellsView<'_>, out: &mut [[f64; 2]]) {
        // What the terms see of each cell: the last step evaluation's, by identity.
        let view = &CellsView {
            by_id: Some(&self.last),
            ..*view
        };
        let batch = CellBatch { view };
        let mut terms = self.entries.iter();
        let Some(first) = terms.next() else {
            out.fill([0.0; 2]);
            return;
        };
        first.term.forces(&batch, &first.x, out);
        for f in out.iter_mut() {
            *f = [0.0 + f[0], 0.0 + f[1]];
        }
        let mut more = Vec::new();
        for e in terms {
            more.resize(out.len(), [0.0; 2]);
            e.term.forces(&batch, &e.x, &mut more);
            for (f, g) in out.iter_mut().zip(&more) {
                *f = [f[0] + g[0], f[1] + g[1]];
            }
        }
    }

    /// Each term's whole-cell forces of the current state (by slot), for the terms that have
    /// a force ([`CellTerm::has_force`]), in the terms' order: the parts [`Terms::forces`]
    /// sums.
    pub(crate) fn forces_of_each(&self, view: &CellsView<'_>) -> Vec<Vec<[f64; 2]>> {
        let view = &CellsView {
            by_id: Some(&self.last),
            ..*view
        };
        let batch = CellBatch { view };
        self.entries
            .iter()
            .filter(|e| e.term.has_force())
            .map(|e| {
                let mut out = vec![[0.0; 2]; view.cells.len()];
                e.term.forces(&batch, &e.x, &mut out);
                out
            })
            .collect()
    }

    /// The stiffest cell of the stiffest term ([`CellTerm::stiffness`]) as `(term's name,
    /// stiffness, cell identity)`, or `None` when no term relaxes its state. Allocates nothing.
    pub(crate) fn stiffest(&self, view: &CellsView<'_>) -> Option<(&str, f64, usize)> {
        let mut worst: Option<(&str, f64, usize)> = None;
        for e in &self.entries {
            let len = e.len;
            for slot in 0..view.cells.len() {
                let cell = view.context(slot);
                let k = e
                    .term
                    .stiffness(&cell, &e.x[cell.id * len..(cell.id + 1) * len]);
                if k > worst.as_ref().map_or(0.0, |w| w.1) || k.is_nan() {
                    worst = Some((e.term.name(), k, cell.id));
                }
            }
        }
        worst
    }

    /// The start of a step from `view.iteration`: keeps the state, its rate and the step's
    /// noise for [`Terms::predict`] and [`Terms::correct`].
    pub(crate) fn begin(&mut self, view: &CellsView<'_>) {
        self.remember(view);
        let iteration = view.iteration;
        let seed = self.seed;
        for (t, e) in self.entries.iter_mut().enumerate() {
            let len = e.len;
            if len == 0 {
                continue;
            }
            e.old.copy_from_slice(&e.x);
            // Identities that are no longer in the tissue (divided or removed) keep their last
            // state: no rate, no kick (a resumed run, which does not keep these, agrees).
            e.rate1.fill(0.0);
            e.kick.fill(0.0);
            for slot in 0..view.cells.len() {
                let cell = view.context(slot);
                let r = cell.id * len..(cell.id + 1) * len;
                e.term.rate(&cell, &e.x[r.clone()], &mut e.rate1[r.clone()]);
                e.term.noise(&cell, &mut e.scratch);
                for (k, (kick, b)) in e.kick[r].iter_mut().zip(&e.scratch).enumerate() {
                    *kick = if *b == 0.0 {
                        0.0
                    } else {
                        let key = NoiseKey {
                            seed,
                            cell: cell.id as u64,
                            step: iteration,
                            stage: ((t as u64) << 16) + k as u64,
                        };
                        b * key.normal()
                    };
                }
            }
        }
    }

    /// The predictor `x = x_old + h r_1 + √h b N` from what [`Terms::begin`] kept (again
    /// after a rejected adaptive attempt, with the same noise).
    pub(crate) fn predict(&mut self, h: f64) {
        let sqrt_h = h.sqrt();
        for e in &mut self.entries {
            for (((x, o), r), k) in e.x.iter_mut().zip(&e.old).zip(&e.rate1).zip(&e.kick) {
                *x = o + h * r + sqrt_h * k;
            }
        }
    }

    /// A corrector: `x = x_old + h/2 (r_1 + r(x)) + √h b N`, with `r(x)` from the evaluation
    /// of the predicted state that `view` holds.
    pub(crate) fn correct(&mut self, view: &CellsView<'_>, h: f64) {
        self.remember(view);
        let sqrt_h = h.sqrt();
        for e in &mut self.entries {
            let len = e.len;
            if len == 0 {
                continue;
            }
            for slot in 0..view.cells.len() {
                let cell = view.context(slot);
                let r = cell.id * len..(cell.id + 1) * len;
                e.term.rate(&cell, &e.x[r.clone()], &mut e.scratch);
                for (k, i) in r.enumerate() {
                    e.x[i] = e.old[i] + 0.5 * h * (e.rate1[i] + e.scratch[k]) + sqrt_h * e.kick[i];
                }
            }
        }
    }

    /// The identities whose state is allocated (`0..identities()`).
    pub fn identities(&self) -> usize {
        self.n
    }

    /// What the terms see of the cell `id` before an evaluation (`CellContext::state`: what
    /// the last evaluation of a step computed for it), or `None` for an identity the terms do
    /// not hold. For a backend that steps elsewhere and keeps it itself.
    pub fn last_evaluation(&self, id: usize) -> Option<&CellState> {
        self.last.get(id)
    }

    /// Sets what the terms see of the cell `id` before an evaluation (see
    /// [`Terms::last_evaluation`]); nothing for an identity they do not hold.
    pub fn set_last_evaluation(&mut self, id: usize, state: CellState) {
        if let Some(s) = self.last.get_mut(id) {
            *s = state;
        }
    }

    /// Keeps what the evaluation `view` holds for each cell, by identity ([`Terms::last`]).
    fn remember(&mut self, view: &CellsView<'_>) {
        if self.entries.is_empty() {
            return;
        }
        for (slot, &id) in view.ids.iter().enumerate() {
            self.last[id] = view.cells[slot];
        }
    }

    /// Back to the state at the start of the step (a failed adaptive step).
    pub(crate) fn restore(&mut self) {
        for e in &mut self.entries {
            e.x.copy_from_slice(&e.old);
        }
    }
}

/// The per-cell data terms are called with, by slot.
pub(crate) struct CellsView<'a> {
    /// The model time of the state evaluated: the step's start, or (in a corrector) its end.
    pub(crate) time: f64,
    /// The time from the state the step started from to the one evaluated: 0, or `h` in a
    /// corrector.
    pub(crate) stage: f64,
    pub(crate) cells: &'a [CellState],
    /// What a term's `CellContext::state` is, by identity, where it is not `cells` by slot
    /// (the terms' forces: the last step evaluation's, [`Terms::last`]).
    pub(crate) by_id: Option<&'a [CellState]>,
    pub(crate) ids: &'a [usize],
    pub(crate) centres: &'a [[f64; 2]],
    /// The centre of mass of the cell in a slot in the state evaluated, measured on demand
    /// (in a corrector, of the predicted fields); `None`: `centres`.
    pub(crate) centre_of: Option<&'a dyn Fn(usize) -> [f64; 2]>,
    pub(crate) active: bool,
    pub(crate) populations: &'a Populations,
    /// The iteration of the state the step starts from.
    pub(crate) iteration: u64,
}

impl std::fmt::Debug for CellsView<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CellsView")
            .field("time", &self.time)
            .field("stage", &self.stage)
            .field("cells", &self.cells.len())
            .finish_non_exhaustive()
    }
}

impl<'a> CellsView<'a> {
    fn context(&self, slot: usize) -> CellContext<'a> {
        let id = self.ids[slot];
        CellContext {
            id,
            centre: self.centres[slot],
            state: match self.by_id {
                Some(states) => &states[id],
                None => &self.cells[slot],
            },
            population: self.populations.population(self.ids[slot]),
            active: self.active,
        }
    }
}

/// What a term sees of every cell at once ([`CellTerm::forces`]): the cells in slot order,
/// and the time of the state an evaluation is of.
#[derive(Debug, Clone, Copy)]
pub struct CellBatch<'a> {
    view: &'a CellsView<'a>,
}

impl<'a> CellBatch<'a> {
    /// The number of cells.
    pub fn len(&self) -> usize {
        self.view.cells.len()
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.view.cells.is_empty()
    }

    /// The model time of the state the evaluation is of: the step's start in Heun's
    /// predictor stage, its end (`t + h`) in the corrector.
    pub fn time(&self) -> f64 {
        self.view.time
    }

    /// The time from the state the step started from to the state evaluated: 0 in the
    /// predictor stage, `h` in the corrector.
    pub fn stage(&self) -> f64 {
        self.view.stage
    }

    /// What [`CellTerm::force`] sees of the cell in `slot`.
    pub fn context(&self, slot: usize) -> CellContext<'a> {
        self.view.context(slot)
    }

    /// The position of the cell in `slot` in the state evaluated: its centre of mass at the
    /// step's start in the predictor, that of Heun's predicted field in the corrector
    /// (measured on each call, a pass over the cell's patch), so that a force that depends
    /// on position is integrated to second order like the fields.
    /// ([`CellContext::centre`] is the step's start in both stages.)
    pub fn position(&self, slot: usize) -> [f64; 2] {
        match self.view.centre_of {
            Some(f) => f(slot),
            None => self.view.centres[slot],
        }
    }
}

/// The signed angle from `a` to `b`, in (−π, π]: `atan2(a × b, a · b)`.
pub fn signed_angle(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    (a.x * b.y - a.y * b.x).atan2(a.dot(&b))
}

#[cfg(test)]
mod tests;
