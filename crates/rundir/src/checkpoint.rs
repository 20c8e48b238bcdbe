//! Checkpoints, `checkpoints/checkpoint_STEP.npz`: the complete state of a run, from which
//! `monolayer run --resume` continues bit for bit.
//!
//! A checkpoint is a NumPy archive like a frame, but it holds the state as the simulation
//! stores it rather than as one reads it: φ in storage order and precision, each patch's
//! origin *and* storage offset, the centres as the step computed them, and the cells in
//! memory order with their identities. Together with the clock, the step and the resolved
//! scene (stored as text) that is everything a step depends on: the re-sort schedule and the
//! activity switch follow from the step number.
//!
//! | array | shape | meaning |
//! |---|---|---|
//! | `format` | `()` int64 | [`CHECKPOINT_FORMAT`] |
//! | `step`, `time`, `zeta` | `()` | clock and the activity in force |
//! | `lattice`, `patch` | `(2,)` int64 | `[lx, ly]`, `[nx, ny]` |
//! | `phi` | `(N·nx·ny,)` float32 or float64 | storage order of [`phasefield::Cells::phi`] |
//! | `origin`, `offset` | `(N, 2)` int64 | [`phasefield::PatchMap`] |
//! | `centre` | `(N, 2)` | [`mechanics::Tissue::centres`], slot order |
//! | `cell_id` | `(N,)` int64 | identity of each slot |
//! | `scene` | `(bytes,)` uint8 | the resolved scene (TOML) |
//! | `controller` | `(5,)` | adaptive runs only: [`mechanics::Controller::to_array`] |
//! | `TERM.VARIABLE` | `(M,)` | each physics term's per-cell state, by identity `0..M` (e.g. `polarity.theta`; [`mechanics::terms::Terms::variables`]; `M = N` while no cell divided) |
//! | `population` | `(M,)` int64 | with `[[population]]` and `[division]`: each identity's population |
//! | `lineage` | `(K, 9)` | with `[division]`: every cell that lived, one row each: id, parent (−1 for a founder), birth, death (NaN while alive), ending (0 alive, 1 division, 2 extrusion, 3 death), generation, cycle, and the centre `x, y` where it ended |
//!
//! Each is written under a temporary name, flushed to disk (`fsync`) and renamed, so a kill
//! at any moment leaves the previous checkpoint intact; the newest [`KEEP`] are kept.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use mechanics::division::{Ending, LineageRecord, Proliferation};
use mechanics::{Controller, Tissue};
use phasefield::{Cells, Real};

use crate::frame::{npy, read_npz, write_zip};
use crate::{Result, RunDirError};

/// Version of the checkpoint layout.
pub const CHECKPOINT_FORMAT: i64 = 1;

/// How many checkpoints are kept.
pub const KEEP: usize = 2;

/// The checkpoints of `dir`, oldest first, as `(step, path)`.
pub fn checkpoints(dir: &Path) -> Vec<(u64, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(dir.join("checkpoints")) else {
        return Vec::new();
    };
    let mut v: Vec<(u64, PathBuf)> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| {
            let step = p
                .file_name()?
                .to_str()?
                .strip_prefix("checkpoint_")?
                .strip_suffix(".npz")?
                .parse()
                .ok()?;
            Some((step, p))
        })
        .collect();
    v.sort();
    v
}

/// Writes a checkpoint of `tissue` with the resolved scene `scene_toml`, then removes all but
/// the newest [`KEEP`].
///
/// # Errors
/// I/O errors, naming the file.
pub fn write_checkpoint<T: Real>(
    dir: &Path,
    tissue: &Tissue<T>,
    controller: Option<Controller>,
    scene_toml: &str,
) -> Result<PathBuf> {
    let cdir = dir.join("checkpoints");
    std::fs::create_dir_all(&cdir).map_err(|e| RunDirError::io("create", &cdir, e))?;
    let path = cdir.join(format!("checkpoint_{:012}.npz", tissue.iteration()));
    let cells = tissue.cells();
    let (shape, map, l) = (cells.shape(), cells.map(), tissue.lattice());
    let n = tissue.n_cells() as u64;
    let pairs = |v: &[[usize; 2]]| {
        v.iter()
            .flat_map(|p| [p[0] as i64, p[1] as i64])
            .collect::<Vec<_>>()
    };
    let arrays = || -> std::io::Result<Vec<(&str, Vec<u8>)>> {
        Ok(vec![
            ("format", npy(&[], [CHECKPOINT_FORMAT])?),
            ("step", npy(&[], [tissue.iteration() as i64])?),
            ("time", npy(&[], [tissue.time()])?),
            ("zeta", npy(&[], [tissue.params().zeta])?),
            ("lattice", npy(&[2], [l.lx as i64, l.ly as i64])?),
            ("patch", npy(&[2], [shape.nx as i64, shape.ny as i64])?),
            (
                "phi",
                if T::NAME == "f32" {
                    npy(
                        &[cells.phi().len() as u64],
                        cells.phi().iter().map(|v| v.to_f64() as f32),
                    )?
                } else {
                    npy(
                        &[cells.phi().len() as u64],
                        cells.phi().iter().map(|v| v.to_f64()),
                    )?
                },
            ),
            ("origin", npy(&[n, 2], pairs(&map.origin))?),
            ("offset", npy(&[n, 2], pairs(&map.offset))?),
            (
                "centre",
                npy(&[n, 2], tissue.centres().iter().flatten().copied())?,
            ),
            (
                "cell_id",
                npy(&[n], tissue.cell_ids().iter().map(|&i| i as i64))?,
            ),
            (
                "scene",
                npy(&[scene_toml.len() as u64], scene_toml.bytes())?,
            ),
        ])
    };
    let mut arrays: Vec<(String, Vec<u8>)> = arrays()
        .map_err(|e| RunDirError::io("encode", &path, e))?
        .into_iter()
        .map(|(name, a)| (name.to_string(), a))
        .collect();
    for (name, values) in term_arrays(tissue) {
        let a =
            npy(&[values.len() as u64], values).map_err(|e| RunDirError::io("encode", &path, e))?;
        arrays.push((name, a));
    }
    if let Some(clock) = tissue.proliferation() {
        let pops = tissue.populations().of_cell();
        if !pops.is_empty() {
            let a = npy(&[pops.len() as u64], pops.iter().map(|&k| i64::from(k)))
                .map_err(|e| RunDirError::io("encode", &path, e))?;
            arrays.push(("population".into(), a));
        }
        let rows = lineage_rows(clock);
        let a = npy(&[rows.len() as u64, 9], rows.into_iter().flatten())
            .map_err(|e| RunDirError::io("encode", &path, e))?;
        arrays.push(("lineage".into(), a));
    }
    if let Some(c) = controller {
        let a = npy(&[5], c.to_array()).map_err(|e| RunDirError::io("encode", &path, e))?;
        arrays.push(("controller".into(), a));
    }
    // Stored, not deflated: the state is mostly noise in its low bits.
    write_zip(&path, arrays, zip::CompressionMethod::Stored, true)?;
    let all = checkpoints(dir);
    for (_, old) in all.iter().take(all.len().saturating_sub(KEEP)) {
        let _ = std::fs::remove_file(old);
    }
    Ok(path)
}

/// The resolved scene a checkpoint was written with.
///
/// # Errors
/// A file that is not a checkpoint of this format.
pub fn checkpoint_scene(path: &Path) -> Result<String> {
    let a = read_npz(path, &["format"])?;
    if a[0].data != [CHECKPOINT_FORMAT as f64] {
        return Err(RunDirError::BadArray {
            path: path.to_path_buf(),
            name: "format".into(),
            reason: format!(
                "format {:?}; this version reads {CHECKPOINT_FORMAT}",
                a[0].data
            ),
        });
    }
    // The scene is a uint8 array: read its raw bytes (read_npz widens numbers).
    let f = File::open(path).map_err(|e| RunDirError::io("open", path, e))?;
    let mut zip = zip::ZipArchive::new(BufReader::new(f)).map_err(|e| RunDirError::Archive {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let mut entry = zip
        .by_name("scene.npy")
        .map_err(|_| RunDirError::MissingArray {
            path: path.to_path_buf(),
            name: "scene".into(),
        })?;
    let mut bytes = Vec::new();
    entry
        .read_to_end(&mut bytes)
        .map_err(|e| RunDirError::io("read", path, e))?;
    let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| RunDirError::BadArray {
        path: path.to_path_buf(),
        name: "scene".into(),
        reason: e.to_string(),
    })?;
    let raw: Vec<u8> = npy.into_vec().map_err(|e| RunDirError::BadArray {
        path: path.to_path_buf(),
        name: "scene".into(),
        reason: e.to_string(),
    })?;
    String::from_utf8(raw).map_err(|e| RunDirError::BadArray {
        path: path.to_path_buf(),
        name: "scene".into(),
        reason: e.to_string(),
    })
}

/// The controller state of an adaptive run's checkpoint (`None` when the run had fixed
/// steps).
///
/// # Errors
/// A damaged `controller` array.
pub fn read_controller(path: &Path) -> Result<Option<Controller>> {
    match read_npz(path, &["controller"]) {
        Err(RunDirError::MissingArray { .. }) => Ok(None),
        Err(e) => Err(e),
        Ok(a) => match a[0].data[..] {
            [dt, e, n, r, l] if [dt, e, n, r, l].iter().all(|v| v.is_finite()) && dt > 0.0 => {
                Ok(Some(Controller::from_array([dt, e, n, r, l])))
            }
            _ => Err(RunDirError::BadArray {
                path: path.to_path_buf(),
                name: "controller".into(),
                reason: format!(
                    "{:?} is not [dt, err_prev, accepted, rejected, last_rejected]",
                    a[0].data
                ),
            }),
        },
    }
}

/// The tissue a checkpoint holds, for `scene` (whose lattice, patch and precision must be the
/// checkpoint's), exactly as it was.
///
/// # Errors
/// A damaged checkpoint or one that does not fit the scene, naming the file and the array.
pub fn read_checkpoint<T: Real>(path: &Path, scene: &scene::Scene) -> Result<Tissue<T>> {
    let names = [
        "format", "step", "time", "zeta", "lattice", "patch", "phi", "origin", "offset", "centre",
        "cell_id",
    ];
    let a = read_npz(path, &names)?;
    let bad = |name: &str, reason: String| RunDirError::BadArray {
        path: path.to_path_buf(),
        name: name.into(),
        reason,
    };
    if a[0].data != [CHECKPOINT_FORMAT as f64] {
        return Err(bad(
            "format",
            format!("{:?}; this version reads {CHECKPOINT_FORMAT}", a[0].data),
        ));
    }
    let one = |k: usize| -> Result<f64> {
        a[k].scalar()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(names[k], "must hold one finite number".into()))
    };
    let (step, time, zeta) = (one(1)? as u64, one(2)?, one(3)?);
    let l = scene.lattice();
    let shape = scene.patch_shape();
    if a[4].data != [l.lx as f64, l.ly as f64] || a[5].data != [shape.nx as f64, shape.ny as f64] {
        return Err(bad(
            "lattice",
            format!(
                "lattice {:?} and patch {:?} do not match the scene's {}×{} and {}×{}",
                a[4].data, a[5].data, l.lx, l.ly, shape.nx, shape.ny
            ),
        ));
    }
    let pairs = |k: usize| -> Vec<[usize; 2]> {
        a[k].data
            .chunks_exact(2)
            .map(|p| [p[0] as usize, p[1] as usize])
            .collect()
    };
    let phi: Vec<T> = a[6].data.iter().map(|&v| T::from_f64(v)).collect();
    if phi.iter().any(|v| !v.to_f64().is_finite()) {
        return Err(bad("phi", "holds non-finite values".into()));
    }
    let cells =
        Cells::from_storage(l, shape, phi, pairs(7), pairs(8)).map_err(|r| bad("phi", r))?;
    let centre: Vec<[f64; 2]> = a[9].data.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
    let ids: Vec<usize> = a[10].data.iter().map(|&v| v as usize).collect();
    let tissue = Tissue::restore(cells, scene.model_params(zeta), time, step, centre, ids)
        .map_err(|r| bad("cell_id", r))?
        .with_terms(scene.terms());
    let Some(restored) = scene.restored_clock(read_lineage(path)?) else {
        return read_terms(path, tissue.with_populations(scene.populations()), true);
    };
    let clock = restored.map_err(|r| bad("lineage", r))?;
    let populations = scene.populations();
    let populations = if populations.is_empty() {
        populations
    } else {
        let of_cell = read_npz(path, &["population"])?.remove(0).data;
        populations
            .reassigned(&of_cell, tissue.next_id())
            .map_err(|r| bad("population", r))?
    };
    let tissue = tissue
        .with_populations(populations)
        .with_proliferation(clock);
    read_terms(path, tissue, true)
}

/// How the `lineage` array codes why a cell's life ended (0: it lives).
const ENDING_CODES: [(Ending, f64); 3] = [
    (Ending::Division, 1.0),
    (Ending::Extrusion, 2.0),
    (Ending::Death, 3.0),
];

/// The lineage of `clock` as the rows of the checkpoint's `lineage` array.
fn lineage_rows(clock: &Proliferation) -> Vec<[f64; 9]> {
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

/// The lineage of a checkpoint (empty when it has none).
///
/// # Errors
/// A damaged `lineage` array.
fn read_lineage(path: &Path) -> Result<Vec<LineageRecord>> {
    let a = match read_npz(path, &["lineage"]) {
        Err(RunDirError::MissingArray { .. }) => return Ok(Vec::new()),
        Err(e) => return Err(e),
        Ok(mut a) => a.remove(0),
    };
    let bad = |reason: String| RunDirError::BadArray {
        path: path.to_path_buf(),
        name: "lineage".into(),
        reason,
    };
    if a.data.len() % 9 != 0 {
        return Err(bad(format!("{} values is not rows of 9", a.data.len())));
    }
    a.data
        .chunks_exact(9)
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
            {
                return Err(bad(format!("the row {r:?} is not a cell's lineage")));
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

/// The name of the array that holds a term's state variable (`polarity/theta` →
/// `polarity.theta`), in checkpoints and frames.
pub(crate) fn term_array_name(variable: &str) -> String {
    variable.replace('/', ".")
}

/// Every term state variable of `tissue` as (array name, values by identity).
pub(crate) fn term_arrays<T: Real>(tissue: &Tissue<T>) -> Vec<(String, Vec<f64>)> {
    tissue
        .terms()
        .variables()
        .into_iter()
        .map(|(name, values)| (term_array_name(&name), values))
        .collect()
}

/// `tissue` with the state of its terms from the arrays of `path` (a checkpoint or a frame,
/// cells in identity order). A missing array is an error when `required`, and otherwise
/// leaves the state as the terms initialised it (a frame of a run without the term).
///
/// # Errors
/// A damaged or missing array, naming the file and the array.
pub fn read_terms<T: Real>(
    path: &Path,
    mut tissue: Tissue<T>,
    required: bool,
) -> Result<Tissue<T>> {
    for (name, _) in tissue.terms().variables() {
        let array = term_array_name(&name);
        let values = match read_npz(path, &[&array]) {
            Ok(mut a) => a.remove(0).data,
            Err(RunDirError::MissingArray { .. }) if !required => continue,
            Err(e) => return Err(e),
        };
        if values.iter().any(|v| !v.is_finite()) {
            return Err(RunDirError::BadArray {
                path: path.to_path_buf(),
                name: array,
                reason: "holds non-finite values".into(),
            });
        }
        tissue
            .terms_mut()
            .set_variable(&name, &values)
            .map_err(|reason| RunDirError::BadArray {
                path: path.to_path_buf(),
                name: array.clone(),
                reason,
            })?;
    }
    Ok(tissue)
}
