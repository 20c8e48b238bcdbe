//! The state of the model's parts as named arrays, for the writers and readers of state files
//! (`rundir`'s checkpoints and frames, `init = "frame"`): what each part keeps
//! ([`Extensions::state_arrays`], [`Extensions::frame_arrays`]) and how it is read back
//! ([`Extensions::restore_arrays`]). Plumbing, not physics: a program that steps a tissue never
//! needs it.
//!
//! The `match`es on [`Part`] here have no wildcard, so a part added later does not compile
//! until its arrays are written and read.

use crate::clock::{Ending, LineageRecord, Proliferation};
use crate::extensions::{Extensions, Part};

/// How the `lineage` array codes why a cell's life ended (0: it lives).
const ENDING_CODES: [(Ending, f64); 3] = [
    (Ending::Division, 1.0),
    (Ending::Extrusion, 2.0),
    (Ending::Death, 3.0),
];

/// An array of state kept by a part: what a checkpoint writes and reads back, and (those
/// [`StateArray::per_identity`]) what a frame writes, one row per living cell.
#[derive(Debug, Clone, PartialEq)]
pub struct StateArray {
    /// The array's name in checkpoints and frames, such as `"polarity.theta"`.
    pub name: String,
    /// The part that keeps it.
    pub part: Part,
    /// Values per row.
    pub columns: usize,
    /// Whether its values are whole numbers (written as int64).
    pub integer: bool,
    /// Whether it has one row per cell identity `0..next_id` (a frame writes the rows of the
    /// living cells, and `init = "frame"` reads them back); otherwise a table of its own (the
    /// lineage), kept by checkpoints only.
    pub per_identity: bool,
    /// Whether a checkpoint must hold it (otherwise the part keeps what the scene gave it:
    /// checkpoints written before the array existed).
    pub required: bool,
    /// What it holds, for the run's `run.json`.
    pub meaning: String,
    /// The values, row by row.
    pub values: Vec<f64>,
}

/// Where [`Extensions::restore_arrays`] reads from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// A checkpoint: every array, the required ones must be there.
    Checkpoint,
    /// A frame, for a new run that starts from it (`init = "frame"`): the per-identity
    /// arrays where the frame has them; the rest start as the scene says.
    Frame,
}

/// The name of the array of what the terms see of each cell ([`crate::terms::Terms::last_evaluation`]):
/// not of the form `term.variable`, so that no term's state can take it.
pub const TERM_INPUTS: &str = "term_inputs";

/// Columns of the `lineage` array: id, parent (−1 for a founder), birth, death (NaN while
/// alive), ending (0 alive, 1 division, 2 extrusion, 3 death), generation, cycle, and the
/// centre `x, y` where it ended.
pub const LINEAGE_COLUMNS: usize = 9;

/// The name of the array that holds a term's state variable (`polarity/theta` →
/// `polarity.theta`), in checkpoints and frames.
pub fn term_array_name(variable: &str) -> String {
    variable.replace('/', ".")
}

/// The lineage of `clock` as the rows of the `lineage` array ([`LINEAGE_COLUMNS`]).
pub fn lineage_rows(clock: &Proliferation) -> Vec<[f64; LINEAGE_COLUMNS]> {
    clock
        .lineage()
        .map(|r| {
            let (death, ending) = match r.death {
                None => (f64::NAN, 0.0),
                Some((t, why)) => {
                    let code = ENDING_CODES.iter().find(|(e, _)| *e == why);
                    (t, code.expect("every ending has a code").1)
                }
            };
            [
                r.id as f64,
                r.parent.map_or(-1.0, |p| p as f64),
                r.birth,
                death,
                ending,
                f64::from(r.generation),
                r.cycle,
                r.place[0],
                r.place[1],
            ]
        })
        .collect()
}

/// The lineage records of a `lineage` array's values, checked row by row.
///
/// # Errors
/// A message naming the first row that is not a cell's lineage.
pub fn read_lineage_rows(values: &[f64]) -> Result<Vec<LineageRecord>, String> {
    if !values.len().is_multiple_of(LINEAGE_COLUMNS) {
        return Err(format!(
            "{} values is not rows of {LINEAGE_COLUMNS}",
            values.len()
        ));
    }
    values
        .chunks_exact(LINEAGE_COLUMNS)
        .map(|r| {
            let whole = |v: f64| v >= 0.0 && v.fract() == 0.0;
            let ending = ENDING_CODES
                .iter()
                .find(|(_, code)| *code == r[4])
                .map(|(e, _)| *e);
            if !(whole(r[0]) && (r[1] == -1.0 || whole(r[1])) && whole(r[5]))
                || !r[2].is_finite()
                || !r[6].is_finite()
                || (r[4] != 0.0 && ending.is_none())
                || (ending.is_some() && !r[3].is_finite())
            {
                return Err(format!("the row {r:?} is not a cell's lineage"));
            }
            Ok(LineageRecord {
                id: r[0] as usize,
                parent: (r[1] >= 0.0).then_some(r[1] as usize),
                birth: r[2],
                death: ending.map(|e| (r[3], e)),
                place: [r[7], r[8]],
                generation: r[5] as u32,
                cycle: r[6],
            })
        })
        .collect()
}

impl Extensions {
    /// Every array of state the parts keep, part by part in [`Part::ALL`]'s order.
    pub fn state_arrays(&self) -> Vec<StateArray> {
        let mut out = Vec::new();
        for part in Part::ALL {
            match part {
                Part::Terms => {
                    let meanings = self.terms.meanings();
                    for ((name, values), (_, meaning)) in
                        self.terms.variables().into_iter().zip(meanings)
                    {
                        out.push(StateArray {
                            name: term_array_name(&name),
                            part,
                            columns: 1,
                            integer: false,
                            per_identity: true,
                            required: true,
                            meaning,
                            values,
                        });
                    }
                    // What the terms see of each cell before an evaluation (the last step
                    // evaluation's area and interface force), so that a resumed run's first
                    // step sees what the uninterrupted run's did. Checkpoints only; one
                    // written before it existed resumes with zeros, as a new run starts.
                    if !self.terms.is_empty() {
                        let values = (0..self.terms.identities())
                            .flat_map(|id| {
                                let s = self.terms.last_evaluation(id).copied().unwrap_or_default();
                                [s.area, s.force.x, s.force.y]
                            })
                            .collect();
                        out.push(StateArray {
                            name: TERM_INPUTS.into(),
                            part,
                            columns: 3,
                            integer: false,
                            per_identity: false,
                            required: false,
                            meaning: "what the physics terms see of each cell identity before an evaluation: the last step evaluation's area, and its interface force x, y".into(),
                            values,
                        });
                    }
                }
                Part::Adhesion | Part::Walls | Part::Friction => {}
                Part::Populations => {
                    if !self.populations.is_empty() {
                        out.push(StateArray {
                            name: "population".into(),
                            part,
                            columns: 1,
                            integer: true,
                            per_identity: true,
                            required: false,
                            meaning: "each cell's population, an index into 'populations'".into(),
                            values: self
                                .populations
                                .of_cell()
                                .iter()
                                .map(|&k| f64::from(k))
                                .collect(),
                        });
                    }
                }
                Part::Division => {
                    if let Some(clock) = &self.proliferation {
                        out.push(StateArray {
                            name: "lineage".into(),
                            part,
                            columns: LINEAGE_COLUMNS,
                            integer: false,
                            per_identity: false,
                            required: true,
                            meaning: "every cell that lived: id, parent (-1 for a founder), birth, death (NaN while alive), ending (0 alive, 1 division, 2 extrusion, 3 death), generation, cycle, x, y".into(),
                            values: lineage_rows(clock).into_iter().flatten().collect(),
                        });
                    }
                }
            }
        }
        out
    }

    /// The per-cell arrays a frame writes for the parts, by identity `0..next_id` (the frame
    /// keeps the rows of the living cells): the per-identity state arrays, then what the terms
    /// derive from their state ([`crate::terms::CellTerm::derived`], such as `polarity`), which
    /// no reader restores (they are not among [`Extensions::state_arrays`]).
    pub fn frame_arrays(&self) -> Vec<StateArray> {
        let mut out: Vec<StateArray> = self
            .state_arrays()
            .into_iter()
            .filter(|a| a.per_identity)
            .collect();
        for (name, meaning, columns, values) in self.terms.derived() {
            out.push(StateArray {
                name,
                part: Part::Terms,
                columns,
                integer: false,
                per_identity: true,
                required: false,
                meaning,
                values,
            });
        }
        out
    }

    /// Reads every part's state back from `read` (the values of an array by name, `None`
    /// when the file has no such array), for a tissue whose identities run below `n_ids`:
    /// from a checkpoint every array, the required ones needed; from a frame the
    /// per-identity ones it has. An array the file has replaces what the scene gave.
    ///
    /// # Errors
    /// `read`'s errors, and `bad(array, reason)` for a missing required array or values that
    /// do not fit (count, finiteness, whole numbers, a population that is not there).
    pub fn restore_arrays<E>(
        &mut self,
        n_ids: usize,
        source: Source,
        mut read: impl FnMut(&str) -> Result<Option<Vec<f64>>, E>,
        bad: impl Fn(&str, String) -> E,
    ) -> Result<(), E> {
        self.terms.initialise(n_ids);
        for array in self.state_arrays() {
            // A frame's per-identity arrays are renumbered `0..n_ids` with the cells.
            if source == Source::Frame && !array.per_identity {
                continue;
            }
            let Some(values) = read(&array.name)? else {
                if source == Source::Checkpoint && array.required {
                    return Err(bad(
                        &array.name,
                        "is missing, and the scene has the part that keeps it".into(),
                    ));
                }
                continue;
            };
            if array.per_identity && values.len() != n_ids {
                return Err(bad(
                    &array.name,
                    format!(
                        "holds {} values for {n_ids} cells: the file is not of this scene's run",
                        values.len()
                    ),
                ));
            }
            if values.iter().any(|v| !v.is_finite()) && array.part != Part::Division {
                return Err(bad(&array.name, "holds non-finite values".into()));
            }
            match array.part {
                Part::Terms if array.name == TERM_INPUTS => {
                    if values.len() != 3 * n_ids {
                        return Err(bad(
                            &array.name,
                            format!(
                                "holds {} values for {n_ids} cells of 3 columns: the file is not of this scene's run",
                                values.len()
                            ),
                        ));
                    }
                    for (id, row) in values.chunks_exact(3).enumerate() {
                        let s = crate::CellState {
                            area: row[0],
                            force: nalgebra::Vector2::new(row[1], row[2]),
                            ..Default::default()
                        };
                        self.terms.set_last_evaluation(id, s);
                    }
                }
                Part::Terms => {
                    let variable = array.name.replacen('.', "/", 1);
                    self.terms
                        .set_variable(&variable, &values)
                        .map_err(|r| bad(&array.name, r))?;
                }
                Part::Populations => {
                    self.populations = self
                        .populations
                        .reassigned(&values, n_ids)
                        .map_err(|r| bad(&array.name, r))?;
                }
                Part::Division => {
                    let records = read_lineage_rows(&values).map_err(|r| bad(&array.name, r))?;
                    if let Some(clock) = self.proliferation.as_deref_mut() {
                        clock
                            .replace_lineage(records)
                            .map_err(|r| bad(&array.name, r))?;
                    }
                }
                Part::Adhesion | Part::Walls | Part::Friction => {}
            }
        }
        let assigned = self.populations.of_cell().len();
        if !self.populations.is_empty() && assigned != n_ids {
            return Err(bad(
                "population",
                format!("assigns {assigned} cells, the state holds identities up to {n_ids}: the file lacks the array, so its cells' populations are not known"),
            ));
        }
        Ok(())
    }
}
