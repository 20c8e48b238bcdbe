//! `lineage.csv`: every cell that lived in a run whose cells divide (`[division]`), one row
//! each, rewritten whole (through a temporary name) with every frame and at the end.
//!
//! | column | meaning |
//! |---|---|
//! | `id` | the cell's identity (the frames' `id`) |
//! | `parent` | its mother's identity; empty for a founder |
//! | `birth` | when it was born, TU (a founder's is before the start: its age starts at a uniform fraction of its cycle) |
//! | `death` | when its life ended, TU; empty while it lives |
//! | `reason` | why it ended: `division`, `extrusion` or `death`; empty while it lives |
//! | `generation` | 0 for a founder, its mother's plus one for a daughter |
//! | `cycle` | its cell-cycle time, TU: it divides at `birth + cycle` unless it waits |
//! | `x`, `y` | its centre of mass where its life ended, nodes; empty while it lives |

use std::path::Path;

use mechanics::division::{Ending, LineageRecord, Proliferation};

use crate::{Result, RunDirError};

/// The header of `lineage.csv`.
pub const LINEAGE_HEADER: &str = "id,parent,birth,death,reason,generation,cycle,x,y";

/// Writes `dir/lineage.csv` from the lineage of `clock`.
///
/// # Errors
/// I/O errors, naming the file (the previous file is left whole).
pub fn write_lineage(dir: &Path, clock: &Proliferation) -> Result<()> {
    let mut text = format!("{LINEAGE_HEADER}\n");
    for r in clock.lineage() {
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
        text.push_str(&format!(
            "{},{},{},{},{},{},{},{},{}\n",
            r.id,
            r.parent.map_or(String::new(), |p| p.to_string()),
            r.birth,
            opt(r.death.map(|d| d.0)),
            r.death.map_or("", |d| d.1.name()),
            r.generation,
            r.cycle,
            opt(r.death.map(|_| r.place[0])),
            opt(r.death.map(|_| r.place[1])),
        ));
    }
    let path = dir.join("lineage.csv");
    let tmp = dir.join("lineage.csv.partial");
    std::fs::write(&tmp, text).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        RunDirError::io("write", &tmp, e)
    })?;
    std::fs::rename(&tmp, &path).map_err(|e| RunDirError::io("rename", &tmp, e))
}

/// Reads `dir/lineage.csv` back (`None` when the run has none: its cells did not divide).
///
/// # Errors
/// A file that is not a lineage table, naming the line.
pub fn read_lineage(dir: &Path) -> Result<Option<Vec<LineageRecord>>> {
    let path = dir.join("lineage.csv");
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(RunDirError::io("read", &path, e)),
    };
    let bad = |line: usize, reason: &str| RunDirError::BadArray {
        path: path.clone(),
        name: format!("line {line}"),
        reason: reason.into(),
    };
    let mut lines = text.lines();
    if lines.next() != Some(LINEAGE_HEADER) {
        return Err(bad(1, "not the header this version writes"));
    }
    lines
        .enumerate()
        .map(|(k, line)| {
            let f: Vec<&str> = line.split(',').collect();
            let parse = || -> Option<LineageRecord> {
                if f.len() != 9 {
                    return None;
                }
                // No number a lineage holds is NaN (it would make a cell's age meaningless;
                // a cycle may be infinite); an empty field is "none".
                let num = |s: &str| s.parse::<f64>().ok().filter(|v| !v.is_nan());
                let opt = |s: &str| {
                    if s.is_empty() {
                        Some(None)
                    } else {
                        num(s).map(Some)
                    }
                };
                let death = match (opt(f[3])?, f[4]) {
                    (None, "") => None,
                    (Some(t), why) => Some((t, Ending::from_name(why)?)),
                    _ => return None,
                };
                Some(LineageRecord {
                    id: f[0].parse().ok()?,
                    parent: if f[1].is_empty() {
                        None
                    } else {
                        Some(f[1].parse().ok()?)
                    },
                    birth: num(f[2]).filter(|b| b.is_finite())?,
                    death,
                    place: [
                        opt(f[7])?.unwrap_or(f64::NAN),
                        opt(f[8])?.unwrap_or(f64::NAN),
                    ],
                    generation: f[5].parse().ok()?,
                    cycle: num(f[6])?,
                })
            };
            parse().ok_or_else(|| {
                bad(
                    k + 2,
                    "not a row of id,parent,birth,death,reason,generation,cycle,x,y",
                )
            })
        })
        .collect::<Result<Vec<_>>>()
        .map(Some)
}
