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
//! | `next_id` | `()` int64 | the identity the next new cell gets ([`mechanics::Tissue::next_id`]) |
//! | `scene` | `(bytes,)` uint8 | the resolved scene (TOML) |
//! | `controller` | `(5,)` | adaptive runs only: [`mechanics::Controller::to_array`] |
//! | the extensions' state | | every array of [`mechanics::Extensions::state_arrays`], under its name: |
//! | `TERM.VARIABLE` | `(M,)` | each physics term's per-cell state, by identity `0..M` (e.g. `polarity.theta`; [`mechanics::terms::Terms::variables`]; `M = N` while no cell divided) |
//! | `population` | `(M,)` int64 | with `[[population]]`: each identity's population |
//! | `lineage` | `(K, 9)` | with `[division]`: every cell that lived, one row each: id, parent (−1 for a founder), birth, death (NaN while alive), ending (0 alive, 1 division, 2 extrusion, 3 death), generation, cycle, and the centre `x, y` where it ended |
//!
//! Each is written under a temporary name, flushed to disk (`fsync`) and renamed, so a kill
//! at any moment leaves the previous checkpoint intact; the newest [`KEEP`] are kept.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use mechanics::persist::Source;
use mechanics::{Controller, Extensions, Tissue};
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
            ("next_id", npy(&[], [tissue.next_id() as i64])?),
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
    for array in tissue.extensions().state_arrays() {
        let rows = (array.values.len() / array.columns) as u64;
        let shape = if array.columns == 1 {
            vec![rows]
        } else {
            vec![rows, array.columns as u64]
        };
        let a = if array.integer {
            npy(&shape, array.values.iter().map(|&v| v as i64))
        } else {
            npy(&shape, array.values.iter().copied())
        }
        .map_err(|e| RunDirError::io("encode", &path, e))?;
        arrays.push((array.name, a));
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
        .map_err(|r| bad("cell_id", r))?;
    // The identity the next new cell gets, which a removed cell's may exceed (checkpoints
    // before it was kept: one more than the largest identity of the lineage, if any).
    let mut tissue = tissue;
    let optional = |name: &str| match read_npz(path, &[name]) {
        Ok(mut a) => Ok(Some(a.remove(0).data)),
        Err(RunDirError::MissingArray { .. }) => Ok(None),
        Err(e) => Err(e),
    };
    let next = match optional("next_id")? {
        Some(v) => match v[..] {
            [n] if n >= 0.0 && n.fract() == 0.0 => Some(n as usize),
            _ => return Err(bad("next_id", format!("{v:?} is not one identity"))),
        },
        None => optional("lineage")?.map(|rows| {
            rows.chunks_exact(mechanics::persist::LINEAGE_COLUMNS)
                .map(|r| r[0] as usize + 1)
                .max()
                .unwrap_or(0)
        }),
    };
    if let Some(next) = next {
        tissue
            .set_next_id(next.max(tissue.next_id()))
            .map_err(|r| bad("next_id", r))?;
    }
    let ext = scene.extensions(&tissue);
    read_extensions(path, tissue, ext, Source::Checkpoint)
}

/// `tissue` with the extensions `ext` (the scene's, [`scene::Scene::extensions`]), their state
/// read from the arrays of `path` ([`mechanics::Extensions::restore_arrays`]): from a
/// checkpoint every array the parts keep, from a frame (cells in identity order) the
/// per-identity ones it has.
///
/// # Errors
/// A damaged or missing array, naming the file and the array.
pub fn read_extensions<T: Real>(
    path: &Path,
    tissue: Tissue<T>,
    mut ext: Extensions,
    source: Source,
) -> Result<Tissue<T>> {
    ext.restore_arrays(
        tissue.next_id(),
        source,
        |name| match read_npz(path, &[name]) {
            Ok(mut a) => Ok(Some(a.remove(0).data)),
            Err(RunDirError::MissingArray { .. }) => Ok(None),
            Err(e) => Err(e),
        },
        |name, reason| RunDirError::BadArray {
            path: path.to_path_buf(),
            name: name.into(),
            reason,
        },
    )?;
    Ok(tissue.with_extensions(ext))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mechanics::Part;

    /// A scene with every part of [`Part::ALL`]: polar cells of two populations that adhere,
    /// inside a disc wall, dividing on a short cycle, with friction between them. `without` leaves one table out.
    fn scene(without: Option<Part>) -> scene::Scene {
        let table = |part: Part, text: &str| -> String {
            if without == Some(part) {
                String::new()
            } else {
                text.to_string()
            }
        };
        let text = [
            "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 6\nradius = 6.0\n[model]\nzeta = 0.002\n",
            &table(
                Part::Terms,
                "[polarity]\nalpha = 0.02\nrotational_diffusion = 0.01\nalign = \"velocity\"\nalign_rate = 0.5\n",
            ),
            &table(Part::Adhesion, "[adhesion]\nomega = 0.002\n"),
            &table(
                Part::Populations,
                "[[population]]\ncount = 3\ngamma = 0.02\n[[population]]\ncount = 3\n",
            ),
            &table(
                Part::Walls,
                "[walls]\nkind = \"disc\"\nthickness = 1.0\nkappa = 1.0\n",
            ),
            &table(
                Part::Division,
                "[division]\ncycle_time = 4.0\ncycle_spread = 2.0\nmax_cells = 12\n",
            ),
            &table(Part::Friction, "[friction]\ncells = 0.1\n"),
            "[integrator]\ndt = 0.5\nmargin = 12\n[run]\nrelax_time = 2.0\ntime = 10.0\nseed = 3\n",
        ]
        .concat();
        scene::Scene::parse(&text, &[]).unwrap()
    }

    /// Every part is written to a checkpoint and restored from it: a tissue with all of
    /// [`Part::ALL`], run until cells have divided, comes back from its checkpoint with no
    /// part differing ([`mechanics::Extensions::differences`]); and the comparison sees each
    /// part, so a part a checkpoint forgot would fail this: the same checkpoint read for the
    /// scene without that part differs in exactly it. A part added to [`Part::ALL`] that the
    /// scene here does not configure fails the first assertion.
    /// A run resumed from a checkpoint is the uninterrupted one to the bit also when a term
    /// reads what the last step evaluation computed for a cell (contact inhibition and a
    /// density propulsion): the checkpoint keeps it (`term_inputs`). Without that array the
    /// resumed run's first step saw zeros, and the angles differed from there on.
    #[test]
    fn a_resumed_run_sees_what_its_terms_saw() {
        let text = "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 6\nradius = 6.0\n[model]\nzeta = 0.002\n[polarity]\nalpha = 0.0005\npropulsion = \"density\"\ncontact_inhibition = 2.0\nrotational_diffusion = 0.01\n[run]\nrelax_time = 0.0\n";
        let scene = scene::Scene::parse(text, &[]).unwrap();
        let sp = scene.step_params();
        let start = scene.simulation::<f64>().unwrap().tissue().clone();
        let steps = |t: &mut Tissue<f64>, ws: &mut mechanics::Workspace<f64>, n: usize| {
            for _ in 0..n {
                t.step(ws, &sp).unwrap();
            }
        };
        let mut whole = start.clone();
        let mut ws = mechanics::Workspace::new(whole.cells());
        steps(&mut whole, &mut ws, 20);
        let mut first = start.clone();
        let mut ws = mechanics::Workspace::new(first.cells());
        steps(&mut first, &mut ws, 10);
        let dir = tempfile::tempdir().unwrap();
        let path = write_checkpoint(dir.path(), &first, None, &scene.to_toml()).unwrap();
        let mut resumed: Tissue<f64> = read_checkpoint(&path, &scene).unwrap();
        let mut ws = mechanics::Workspace::new(resumed.cells());
        steps(&mut resumed, &mut ws, 10);
        assert_eq!(
            resumed.terms().state("polarity"),
            whole.terms().state("polarity"),
            "the angles"
        );
        assert!(resumed.cells().phi() == whole.cells().phi(), "the fields");
    }

    #[test]
    fn every_part_is_written_restored_and_compared() {
        let full = scene(None);
        let mut sim = full.simulation::<f64>().unwrap();
        sim.run().unwrap();
        let tissue = sim.tissue();
        assert_eq!(
            tissue.parts(),
            Part::ALL.to_vec(),
            "the scene has every part"
        );
        assert!(
            tissue.n_cells() > 6,
            "cells divided: {} cells",
            tissue.n_cells()
        );
        let dir = tempfile::tempdir().unwrap();
        let path = write_checkpoint(dir.path(), tissue, None, &full.to_toml()).unwrap();
        let back: Tissue<f64> = read_checkpoint(&path, &full).unwrap();
        assert_eq!(
            back.extensions().differences(tissue.extensions()),
            Vec::<Part>::new()
        );
        assert_eq!(back.parts(), tissue.parts());
        for part in Part::ALL {
            let other = scene(Some(part));
            let Ok(back) = read_checkpoint::<f64>(&path, &other) else {
                // A scene without the part may refuse the checkpoint outright (its arrays
                // do not fit): the part is not lost silently either way.
                continue;
            };
            let mut differ = back.extensions().differences(tissue.extensions());
            if back.parts() != tissue.parts() && !differ.contains(&part) {
                differ.push(part);
            }
            assert_eq!(differ, vec![part], "without {part:?}");
        }
    }

    /// `init = "frame"` names each extension array it does not carry, and only those: from
    /// a frame and a checkpoint of a run with every part, the same scene carries all of them
    /// (so [`crate::state::not_carried`]'s list of the cells' own arrays is complete), and
    /// a scene without polarity leaves out exactly the polarity's arrays.
    #[test]
    fn a_saved_state_names_what_a_new_scene_does_not_carry() {
        // At step 0: once cells divide, the populations' counts no longer add up to
        // `[cells] count`, which a scene must state.
        let full = scene(None);
        let sim = full.simulation::<f64>().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let frame = crate::frame::write_frame(dir.path(), sim.tissue(), sim.workspace()).unwrap();
        let checkpoint = write_checkpoint(dir.path(), sim.tissue(), None, &full.to_toml()).unwrap();
        // A frame also holds what the terms derive (the polarity's unit vector).
        let polar: [&[&str]; 2] = [&["polarity.theta", "polarity"], &["polarity.theta"]];
        for (path, polar) in [&frame, &checkpoint].into_iter().zip(polar) {
            let from = |s: &scene::Scene| {
                let set = [
                    "cells.init=\"frame\"".to_string(),
                    format!("cells.from={:?}", path.display().to_string()),
                ];
                scene::Scene::parse(&s.to_toml(), &set).unwrap()
            };
            assert_eq!(
                crate::state::not_carried(&from(&full)).unwrap(),
                Vec::<String>::new(),
                "{}",
                path.display()
            );
            assert_eq!(
                crate::state::not_carried(&from(&scene(Some(Part::Terms)))).unwrap(),
                polar,
                "{}",
                path.display()
            );
        }
    }
}
