//! Saved states to start a new scene from (`[cells] init = "frame"`): the fields of a frame
//! (`frames/frame_STEP.npz`) or of a checkpoint (`checkpoints/checkpoint_STEP.npz`), read into
//! [`Cells`] in identity order on the patches they were saved on, and the initial tissue of a
//! scene built from them ([`initial_tissue`]).

use std::path::Path;

use mechanics::persist::Source;
use mechanics::Tissue;
use phasefield::{Cells, Lattice, PatchShape, Real};
use scene::{Scene, SceneError, MAX_SIDE};

use crate::checkpoint::CHECKPOINT_FORMAT;
use crate::frame::{read_npz, Array, FRAME_FORMATS_READ};
use crate::{Result, RunDirError};

/// The fields saved in `path`, a frame or a checkpoint (told apart by their arrays), as
/// [`Cells`] in identity order (cell `i` of the frame's arrays, `cell_id = i` of the
/// checkpoint's slots) on the patches they were saved on, widened exactly to `f64`.
///
/// # Errors
/// A missing or damaged file, or arrays that do not describe a state (wrong shapes,
/// non-finite values, origins off the lattice), naming the file and the array.
pub fn read_state(path: &Path) -> Result<Cells<f64>> {
    match read_npz(path, &["offset"]) {
        Ok(_) => read_checkpoint_state(path),
        Err(RunDirError::MissingArray { .. }) => read_frame_state(path),
        Err(e) => Err(e),
    }
}

/// The initial tissue of `scene`: from the saved state of `[cells] from` (a relative path is
/// taken from the current directory) when the scene has `init = "frame"`, otherwise from its
/// initial discs.
///
/// # Errors
/// The state cannot be read, or does not fit the scene (lattice, cell count).
pub fn initial_tissue<T: Real>(scene: &Scene) -> std::result::Result<Tissue<T>, StateError> {
    match initial_state(scene)? {
        None => Ok(scene.tissue::<T>()?),
        Some(state) => saved_terms(scene, scene.tissue_from_state::<T>(&state)?),
    }
}

/// `tissue` (built from the saved state `scene` starts from) with the state of its
/// extensions read from that file, cell by cell, where it has them (a frame or checkpoint of a
/// run with the same parts: the terms' state, each cell's population); parts the file lacks
/// keep the state the scene gave them.
///
/// # Errors
/// A damaged array in the file, or one that does not fit the scene (a population the scene
/// does not have).
pub fn saved_terms<T: Real>(
    scene: &Scene,
    tissue: Tissue<T>,
) -> std::result::Result<Tissue<T>, StateError> {
    let Some(from) = scene.init_from() else {
        return Ok(tissue);
    };
    let ext = tissue.extensions().clone();
    crate::checkpoint::read_extensions(Path::new(from), tissue, ext, Source::Frame).map_err(
        |error| StateError::Read {
            from: from.to_string(),
            error,
        },
    )
}

/// The arrays of a state file that are not the state of the cells' fields: those of
/// [`crate::frame::write_frame`] and [`crate::checkpoint::write_checkpoint`] that every run
/// writes. The rest are the extensions' and are carried by [`saved_terms`] when the scene has
/// the part that keeps them.
const CORE_ARRAYS: [&str; 22] = [
    "format",
    "step",
    "time",
    "zeta",
    "lattice",
    "patch",
    "id",
    "cell_id",
    "next_id",
    "centre",
    "velocity",
    "force",
    "cell_force",
    "area",
    "shape_tensor",
    "origin",
    "offset",
    "phi",
    "scene",
    "controller",
    "lineage",
    // What the terms saw of each cell in the last step (a checkpoint's, for a resume): a new
    // run starts it at zero.
    mechanics::persist::TERM_INPUTS,
];

/// The extensions' arrays of the saved state `scene` starts from (`init = "frame"`) that the
/// scene has no part to carry, such as `polarity.theta` from a polar run into a scene without
/// `[polarity]`: the new run starts without them, which a caller should say. Empty for the
/// other layouts. (The `lineage` of a checkpoint is never carried: a new run starts a lineage
/// of its own, its founders the cells of the file.)
///
/// # Errors
/// The file cannot be read.
pub fn not_carried(scene: &Scene) -> std::result::Result<Vec<String>, StateError> {
    let Some(from) = scene.init_from() else {
        return Ok(Vec::new());
    };
    Ok(not_carried_of(scene, &array_names(from)?))
}

/// The arrays of the state file `from`.
fn array_names(from: &str) -> std::result::Result<Vec<String>, StateError> {
    crate::frame::npz_names(Path::new(from)).map_err(|error| StateError::Read {
        from: from.to_string(),
        error,
    })
}

/// [`not_carried`] of a file whose arrays are `names`.
fn not_carried_of(scene: &Scene, names: &[String]) -> Vec<String> {
    let ext = scene.configured_extensions();
    let carried: Vec<String> = ext.frame_arrays().into_iter().map(|a| a.name).collect();
    names
        .iter()
        .filter(|n| !CORE_ARRAYS.contains(&n.as_str()) && !carried.contains(n))
        .cloned()
        .collect()
}

/// The saved state `scene` starts from (`init = "frame"`; `None` for the other layouts),
/// read and checked against the scene, so that a caller can refuse a scene before it writes
/// anything.
///
/// # Errors
/// The state cannot be read, or does not fit the scene (lattice, cell count).
pub fn initial_state(scene: &Scene) -> std::result::Result<Option<Cells<f64>>, StateError> {
    let Some(from) = scene.init_from() else {
        return Ok(None);
    };
    let state = read_state(Path::new(from)).map_err(|error| StateError::Read {
        from: from.to_string(),
        error,
    })?;
    scene.check_state(&state)?;
    check_populations(scene, Path::new(from))?;
    Ok(Some(state))
}

/// The scene's `[[population]]` counts against the `population` array of the saved state it
/// starts from, where the file has one (the file's assignment is what the run takes): a
/// scene that says 6 and 2 of a state holding 4 and 4 is refused with both.
///
/// # Errors
/// [`StateError::Scene`] with both counts and the keys to set.
fn check_populations(scene: &Scene, from: &Path) -> std::result::Result<(), StateError> {
    let kinds = &scene.file().population;
    let read = |error| StateError::Read {
        from: from.display().to_string(),
        error,
    };
    let names = crate::frame::npz_names(from).map_err(read)?;
    if kinds.is_empty() || !names.iter().any(|n| n == "population") {
        return Ok(());
    }
    let a = read_npz(from, &["population"]).map_err(read)?;
    let mut counts = vec![0usize; kinds.len()];
    for &k in &a[0].data {
        // A population the scene lacks is refused where the array is read.
        if let Some(c) = counts.get_mut(k as usize) {
            *c += 1;
        }
    }
    let want: Vec<usize> = kinds.iter().map(|p| p.count).collect();
    if counts != want {
        let list = |c: &[usize]| {
            c.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(StateError::Scene(SceneError::State {
            from: from.display().to_string(),
            problem: format!(
                "the state's population array has {} cells of populations 0 to {}, the scene's [[population]] counts are {}",
                list(&counts),
                kinds.len() - 1,
                list(&want)
            ),
            fix: format!(
                "set {} (the state's; its cells keep their populations)",
                counts
                    .iter()
                    .enumerate()
                    .map(|(k, n)| format!("population.{k}.count = {n}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }));
    }
    Ok(())
}

/// What a new user should be told about the saved state `scene` starts from
/// (`init = "frame"`): its arrays that the scene has no part to carry ([`not_carried`]), and
/// the scene's keys the state's arrays win over (`[polarity] angle` against the state's
/// `polarity.theta`, [`scene::SceneFile::initial_state_keys`]). The rules per key are in docs/scenes.md ("Starting from a saved
/// state").
///
/// # Errors
/// The file cannot be read.
pub fn state_warnings(scene: &Scene) -> std::result::Result<Vec<String>, StateError> {
    let Some(from) = scene.init_from() else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    // The file's arrays, read once for both warnings.
    let names = array_names(from)?;
    let dropped = not_carried_of(scene, &names);
    if !dropped.is_empty() {
        out.push(format!(
            "[cells] from = {from:?}: its arrays {} are not carried: the scene has no part that keeps them; add that part's table to the scene to carry them",
            dropped.join(", ")
        ));
    }
    for (array, key, value) in scene.file().initial_state_keys() {
        if names.contains(&array) {
            out.push(format!(
                "{key} = {value}: the cells start with the values of the state's {array} (from {from:?}), which win over the scene's; remove the key from the scene to say so, or start from a state without {array}"
            ));
        }
    }
    Ok(out)
}

/// What a new run of a scene needs before its directory is written, checked and read once
/// for every front end (`monolayer run`, Python's `monolayer.run`): the memory guard passed,
/// the saved state it starts from read (before `--overwrite` may remove the file it names),
/// and every warning to give about the scene and that state.
#[derive(Debug)]
pub struct NewRun {
    /// The saved state of `[cells] from` (`init = "frame"`), for [`crate::RunDir::create`].
    pub state: Option<Cells<f64>>,
    /// What the user should be told (the scene's [`Scene::warnings`], then
    /// [`state_warnings`]), to print once the directory is taken.
    pub warnings: Vec<String>,
}

/// Why a new run was refused before anything was written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PrepareError {
    /// The run would not fit in memory ([`crate::memory::check_memory`]).
    #[error(transparent)]
    Memory(#[from] crate::memory::MemoryError),
    /// The saved state cannot be read or does not fit the scene.
    #[error(transparent)]
    State(#[from] StateError),
}

/// Checks and reads what a new run of `scene` needs ([`NewRun`]) before anything is written:
/// the memory guard with `limit` (or the memory this process can use; `flag` is the front
/// end's way to raise it), then the saved state and the warnings.
///
/// # Errors
/// [`PrepareError`]: a run too large, or a saved state that cannot be used.
pub fn prepare_new_run(
    scene: &Scene,
    limit: Option<(f64, String)>,
    flag: &str,
) -> std::result::Result<NewRun, PrepareError> {
    crate::memory::check_memory(scene, 1, limit, flag)?;
    let state = initial_state(scene)?;
    let mut warnings = scene.warnings();
    warnings.extend(state_warnings(scene)?);
    Ok(NewRun { state, warnings })
}

/// Why the initial tissue of a scene could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StateError {
    /// The saved state cannot be read.
    #[error("[cells] from = {from:?}: {error}{}; give a frame (RUN/frames/frame_STEP.npz) or a checkpoint (RUN/checkpoints/checkpoint_STEP.npz) of a run on the scene's lattice", reason(error))]
    Read {
        /// The path, as the scene gives it.
        from: String,
        /// What went wrong (in the message, not repeated as a source).
        error: RunDirError,
    },
    /// The state does not fit the scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// The operating system's reason for an I/O error, which [`RunDirError`]'s message leaves to
/// its source.
fn reason(e: &RunDirError) -> String {
    match e {
        RunDirError::Io { source, .. } => format!(" ({source})"),
        _ => String::new(),
    }
}

fn bad(path: &Path, name: &str, reason: impl Into<String>) -> RunDirError {
    RunDirError::BadArray {
        path: path.to_path_buf(),
        name: name.into(),
        reason: reason.into(),
    }
}

/// The format number of a state file, checked against those this version reads.
fn check_format(path: &Path, a: &Array, known: std::ops::RangeInclusive<i64>) -> Result<()> {
    match a.scalar() {
        Some(f) if known.clone().any(|k| k as f64 == f) => Ok(()),
        _ => Err(bad(
            path,
            "format",
            format!("{:?}; this version reads {known:?}", a.data),
        )),
    }
}

/// The lattice of `[lx, ly]`.
fn lattice(path: &Path, a: &Array) -> Result<Lattice> {
    match a.data[..] {
        [lx, ly]
            if [lx, ly]
                .iter()
                .all(|&v| v.fract() == 0.0 && (8.0..=MAX_SIDE as f64).contains(&v)) =>
        {
            Ok(Lattice::new(lx as usize, ly as usize))
        }
        _ => Err(bad(
            path,
            "lattice",
            format!("{:?} is not [lx, ly] with sides in [8, {MAX_SIDE}]", a.data),
        )),
    }
}

/// The patch shape of `nx × ny` patches on `l`: `2m + 1` square, or the full domain.
fn patch_shape(path: &Path, l: Lattice, nx: u64, ny: u64) -> Result<PatchShape> {
    let square_odd = nx == ny && nx % 2 == 1 && nx >= 3;
    let margin = if square_odd && nx as usize <= l.lx.min(l.ly) {
        (nx as usize - 1) / 2
    } else if (nx as usize, ny as usize) == (l.lx, l.ly) {
        0
    } else {
        return Err(bad(
            path,
            "phi",
            format!(
                "patches of {nx}×{ny} are neither 2m+1 square nor the {}×{} lattice",
                l.lx, l.ly
            ),
        ));
    };
    PatchShape::new(l, margin).map_err(|e| bad(path, "phi", e.to_string()))
}

/// `n × 2` non-negative integers below the lattice sides, as node pairs.
fn nodes(
    path: &Path,
    name: &str,
    a: &Array,
    n: usize,
    below: [usize; 2],
) -> Result<Vec<[usize; 2]>> {
    if a.data.len() != 2 * n {
        return Err(bad(
            path,
            name,
            format!("{} values for {n} cells (want {n}×2)", a.data.len()),
        ));
    }
    a.data
        .chunks_exact(2)
        .enumerate()
        .map(|(i, p)| {
            let ok = |v: f64, l: usize| v >= 0.0 && v.fract() == 0.0 && v < l as f64;
            if ok(p[0], below[0]) && ok(p[1], below[1]) {
                Ok([p[0] as usize, p[1] as usize])
            } else {
                Err(bad(
                    path,
                    name,
                    format!(
                        "cell {i}: {p:?} is outside [0, {}) × [0, {})",
                        below[0], below[1]
                    ),
                ))
            }
        })
        .collect()
}

fn finite(path: &Path, name: &str, v: &[f64]) -> Result<()> {
    match v.iter().filter(|x| !x.is_finite()).count() {
        0 => Ok(()),
        k => Err(bad(
            path,
            name,
            format!("{k} non-finite values: the state is not one the model can have"),
        )),
    }
}

fn read_frame_state(path: &Path) -> Result<Cells<f64>> {
    let a = read_npz(path, &["format", "lattice", "origin", "phi"])?;
    check_format(path, &a[0], FRAME_FORMATS_READ)?;
    let l = lattice(path, &a[1])?;
    let phi = &a[3];
    let [n, nx, ny] = phi.shape[..] else {
        return Err(bad(
            path,
            "phi",
            format!("shape {:?}, want (cells, nx, ny)", phi.shape),
        ));
    };
    if n == 0 {
        return Err(bad(path, "phi", "the frame holds no cells"));
    }
    let shape = patch_shape(path, l, nx, ny)?;
    let origins = nodes(path, "origin", &a[2], n as usize, [l.lx, l.ly])?;
    finite(path, "phi", &phi.data)?;
    Ok(Cells::from_unrolled(l, shape, &origins, &phi.data))
}

fn read_checkpoint_state(path: &Path) -> Result<Cells<f64>> {
    let names = [
        "format", "lattice", "patch", "phi", "origin", "offset", "cell_id",
    ];
    let a = read_npz(path, &names)?;
    check_format(path, &a[0], CHECKPOINT_FORMAT..=CHECKPOINT_FORMAT)?;
    let l = lattice(path, &a[1])?;
    let (nx, ny) = match a[2].data[..] {
        [nx, ny] if nx >= 1.0 && ny >= 1.0 => (nx as u64, ny as u64),
        _ => {
            return Err(bad(
                path,
                "patch",
                format!("{:?} is not [nx, ny]", a[2].data),
            ))
        }
    };
    let shape = patch_shape(path, l, nx, ny)?;
    let n = a[6].data.len();
    if n == 0 || a[3].data.len() != n * shape.len() {
        return Err(bad(
            path,
            "phi",
            format!("{} values for {n} cells of {nx}×{ny}", a[3].data.len()),
        ));
    }
    finite(path, "phi", &a[3].data)?;
    let origin = nodes(path, "origin", &a[4], n, [l.lx, l.ly])?;
    let offset = nodes(path, "offset", &a[5], n, [shape.nx, shape.ny])?;
    // Slot `s` holds the cell whose identity is `cell_id[s]`; identity order takes, for each
    // identity `j`, the slot that holds it.
    let mut order = vec![usize::MAX; n];
    for (slot, &id) in a[6].data.iter().enumerate() {
        let ok = id >= 0.0 && id.fract() == 0.0 && id < n as f64;
        if !ok || order[id as usize] != usize::MAX {
            return Err(bad(
                path,
                "cell_id",
                format!("slot {slot} holds {id}: not a permutation of 0..{n}"),
            ));
        }
        order[id as usize] = slot;
    }
    let mut cells = Cells::from_storage(l, shape, a[3].data.clone(), origin, offset)
        .map_err(|r| bad(path, "phi", r))?;
    cells.permute(&order, &mut Vec::new());
    Ok(cells)
}
