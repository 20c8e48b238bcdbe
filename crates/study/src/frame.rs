//! The frames of a run directory, read back: which there are ([`list_frames`], with what was
//! skipped or is missing, [`FrameNotes`]), the scene they were written with ([`read_scene`]),
//! and one frame's state rebuilt as a tissue ([`load_frame`]), with its parts' state restored
//! by [`rundir::read_extensions`], the same reader as a checkpoint's and `init = "frame"`'s.
//! The analysis ([`crate::analyze`]) and the views ([`crate::view`]) both read frames here.

use std::path::{Path, PathBuf};

use analysis::smooth::paper_box_side;
use mechanics::{Tissue, Workspace};
use phasefield::{Cells, Lattice, PatchShape, Real};
use rundir::{read_npz, Array, FRAME_FORMAT, FRAME_FORMATS_READ};
use scene::{Scene, SceneFile};

use crate::error::{input, Result};

/// What reading the frames of a run directory noticed, for the caller to report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameNotes {
    /// Partially written frames (`*.partial`) that were skipped.
    pub partial: usize,
    /// Other files in `frames/` that were skipped (names that are not `frame_STEP.npz`).
    pub stray: Vec<String>,
    /// Frames of the schedule (multiples of the scene's frame interval) between the first and
    /// the last frame that are not there: removed, or lost to a full disk.
    pub missing: u64,
    /// The time of the first missing frame.
    pub first_missing: Option<f64>,
    /// Whether the run is marked complete ([`rundir::is_complete`]); if not, it is still
    /// being written, was killed, or was written by a version before the mark.
    pub complete: bool,
}

/// A frame file of a run, with the clock it holds.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FrameFile {
    pub path: PathBuf,
    pub step: u64,
    pub time: f64,
}

/// The frames of a run directory.
pub(crate) struct FrameList {
    /// In the order of their `step` arrays.
    pub frames: Vec<FrameFile>,
    /// Files skipped, frames missing, completeness.
    pub notes: FrameNotes,
}

/// The frames of a run directory of `scene` in the order of their `step` arrays (not of their
/// names), each checked to be of a format this version reads; partial and stray files are
/// counted and skipped, and the steps of the scene's frame schedule without a frame noted.
pub(crate) fn list_frames(run_dir: &Path, scene: &Scene) -> Result<FrameList> {
    let dir = run_dir.join("frames");
    let entries = std::fs::read_dir(&dir).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound if std::fs::symlink_metadata(&dir).is_err() => {
            input(run_dir, "no frames/ directory: the run wrote no frame yet")
        }
        _ => input(
            &dir,
            format!("cannot be read ({e}); it should be the directory of frame_STEP.npz files the run wrote"),
        ),
    })?;
    let (mut frames, mut partial, mut stray) = (Vec::new(), 0, Vec::new());
    for e in entries {
        let p = e.map_err(|e| input(&dir, e.to_string()))?.path();
        let name = p
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("")
            .to_string();
        let digits = name
            .strip_prefix("frame_")
            .and_then(|n| n.strip_suffix(".npz"))
            .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()));
        if name.ends_with(".partial") {
            partial += 1;
        } else if digits.is_some() {
            frames.push(p);
        } else {
            stray.push(name);
        }
    }
    if frames.is_empty() {
        return Err(input(&dir, "holds no frame_STEP.npz"));
    }
    let mut frames = frames
        .into_iter()
        .map(|path| {
            let (step, time) = frame_clock(&path)?;
            Ok(FrameFile { path, step, time })
        })
        .collect::<Result<Vec<_>>>()?;
    frames.sort_by_key(|f| f.step);
    if let Some(w) = frames.windows(2).find(|w| w[0].step == w[1].step) {
        return Err(input(
            &w[1].path,
            format!(
                "holds step {}, as {} does: remove the copy",
                w[1].step,
                w[0].path.display()
            ),
        ));
    }
    stray.sort();
    let (missing, first_missing) = missing_frames(scene, &frames);
    Ok(FrameList {
        frames,
        notes: FrameNotes {
            partial,
            stray,
            missing,
            first_missing,
            complete: rundir::is_complete(run_dir),
        },
    })
}

/// The frames of the scene's schedule between the first and the last of `frames` (in step
/// order) that are not there: how many, and the time of the first. The schedule is every
/// multiple of the frame interval in steps with fixed steps, in model time with the adaptive
/// step (whose frames land on those times). Counted gap by gap, so a damaged step number
/// costs nothing.
fn missing_frames(scene: &Scene, frames: &[FrameFile]) -> (u64, Option<f64>) {
    let (mut count, mut first) = (0u64, None);
    for w in frames.windows(2) {
        let (n, t) = if scene.adaptive().is_some() {
            let every = scene.file().run.output_every;
            let tol = 1e-9 * every;
            let k0 = ((w[0].time + tol) / every).floor() + 1.0;
            let k1 = ((w[1].time - tol) / every).ceil() - 1.0;
            ((k1 - k0 + 1.0).max(0.0) as u64, k0 * every)
        } else {
            let every = scene.step_counts().frame_every;
            let (s0, s1) = (w[0].step, w[1].step);
            let n = ((s1 - 1) / every).saturating_sub(s0 / every);
            (
                n,
                (s0 / every + 1) as f64 * every as f64 * scene.step_params().dt,
            )
        };
        if n > 0 {
            count = count.saturating_add(n);
            first.get_or_insert(t);
        }
    }
    (count, first)
}

/// The default smoothing box of a scene: the odd side nearest 3R, at most the lattice's.
pub(crate) fn default_box(scene: &Scene) -> usize {
    let l = scene.lattice();
    paper_box_side(scene.file().cells.radius).min(l.lx.min(l.ly) | 1)
}

/// Reads the run's resolved scene.
pub(crate) fn read_scene(run_dir: &Path) -> Result<Scene> {
    if !run_dir.is_dir() {
        return Err(input(run_dir, "no run directory there"));
    }
    let path = run_dir.join("scene.toml");
    let text = std::fs::read_to_string(&path).map_err(|_| {
        input(
            run_dir,
            "not a monolayer run directory: scene.toml is missing",
        )
    })?;
    let file = SceneFile::parse(&text, &[]).map_err(|e| {
        input(
            &path,
            format!("does not parse with this version of monolayer: {e}"),
        )
    })?;
    // Read, not stepped: a term this program does not register is no reason to refuse.
    file.validate_for_reading()
        .map_err(|e| input(&path, e.to_string()))
}

/// The terms a frame's tissue is evaluated with: the scene's, or, where the scene names a
/// term this program does not register ([`Scene::unbuilt_terms`]), the whole-cell forces the
/// frame recorded (`cell_force`, the sum of every term's), so that the fields recomputed from
/// it (velocity, stress) are the run's without the term's code. A scene that has built-in
/// terms beside an unregistered one is refused by name: its recorded sum cannot be split.
fn frame_terms(path: &Path, scene: &Scene, n: usize) -> Result<mechanics::terms::Terms> {
    let unbuilt = scene.unbuilt_terms();
    if unbuilt.is_empty() {
        return Ok(scene.terms());
    }
    let built = scene.terms();
    if !built.is_empty() {
        return Err(input(
            path,
            format!(
                "the run's term {} is not registered in this program, and the run has built-in terms beside it, so the fields of its frames cannot be rebuilt from the recorded forces; read it with the program that registers {0} (scene::register_term)",
                unbuilt.join(", ")
            ),
        ));
    }
    // A frame without `cell_force` was written by a run with no term in effect (a run writes
    // it whenever it has terms): no whole-cell force.
    let names = rundir::npz_names(path).map_err(|e| input(path, e.to_string()))?;
    let f = if names.iter().any(|n| n == "cell_force") {
        let a = rundir::read_npz(path, &["cell_force"]).map_err(|e| input(path, e.to_string()))?;
        a.into_iter().next().map(|a| a.data).unwrap_or_default()
    } else {
        vec![0.0; 2 * n]
    };
    let f = &f;
    if f.len() != 2 * n || f.iter().any(|v| !v.is_finite()) {
        return Err(input(
            path,
            format!(
                "array 'cell_force' holds {} values, not 2 finite values for each of the {n} cells",
                f.len()
            ),
        ));
    }
    let mut terms = mechanics::terms::Terms::default();
    terms.add(std::sync::Arc::new(RecordedForces {
        name: unbuilt.join("+"),
        by_id: f.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
    }));
    Ok(terms)
}

/// The whole-cell forces a frame recorded, by cell identity: the forces of terms whose code
/// this program does not have, for re-evaluating the frame.
#[derive(Debug)]
struct RecordedForces {
    name: String,
    by_id: Vec<[f64; 2]>,
}

impl mechanics::terms::CellTerm for RecordedForces {
    fn name(&self) -> &str {
        &self.name
    }

    fn force(&self, cell: &mechanics::terms::CellContext<'_>, _: &[f64]) -> [f64; 2] {
        self.by_id.get(cell.id).copied().unwrap_or([0.0, 0.0])
    }
}

/// One frame as it was written, and its state rebuilt as a tissue.
pub(crate) struct LoadedFrame {
    pub tissue: Tissue,
    pub step: u64,
    /// The patch origins, `N × 2`.
    pub origins: Vec<[usize; 2]>,
    /// `φ`, `N × nx × ny`, as the frame stores it.
    pub phi: Vec<f64>,
    pub shapes: Vec<[f64; 2]>,
    pub centres: Vec<[f64; 2]>,
    pub velocities: Vec<[f64; 2]>,
    pub areas: Vec<f64>,
    /// The identity of each row (the frame's `id`; `0..N` in frames before format 3). The
    /// tissue numbers its cells by row, `0..N`.
    pub ids: Vec<usize>,
    /// Each cell's force by origin where the run recorded it (`[run] forces_by_origin`): the
    /// frame's arrays `force.ORIGIN`, `(name, N × 2 values)`; empty otherwise.
    pub force_parts: Vec<(String, Vec<f64>)>,
}

impl LoadedFrame {
    /// A tissue's state as a frame of it would hold it, without writing one: the cells in
    /// increasing identity with their quantities from the evaluation in `ws` (an observation
    /// of this very state), and the tissue rebuilt from them with its parts' state by row, as
    /// [`load_frame`] rebuilds it from the frame `rundir::write_frame` writes (the cell-cycle
    /// clock aside, as there; the tissue's own parameters and terms, where a frame has the
    /// scene's).
    ///
    /// # Errors
    /// The parts' state does not restore (a tissue whose parts disagree with its cells).
    pub(crate) fn from_state<T: Real>(tissue: &Tissue<T>, ws: &Workspace<T>) -> Result<Self> {
        let shape = tissue.cells().shape().clone();
        let len = shape.nx * shape.ny;
        let slots = tissue.slots();
        let n = slots.len();
        let ids: Vec<usize> = slots.iter().map(|&s| tissue.cell_ids()[s]).collect();
        let cs = ws.cell_states();
        let mut phi = vec![0.0; n * len];
        for (chunk, &slot) in phi.chunks_exact_mut(len).zip(&slots) {
            tissue.cells().unrolled_into(slot, chunk);
        }
        let origins: Vec<[usize; 2]> = slots
            .iter()
            .map(|&s| tissue.cells().map().origin[s])
            .collect();
        let cells = Cells::from_unrolled(tissue.lattice(), shape, &origins, &phi);
        let mut rebuilt = Tissue::from_state(
            cells,
            *tissue.params(),
            tissue.time(),
            tissue.iteration(),
            (0..n).collect(),
        );
        rebuilt.set_active(tissue.active());
        // The parts' per-cell arrays, the rows of the living cells (what a frame writes).
        let arrays = tissue.extensions().frame_arrays();
        let mut ext = tissue
            .extensions()
            .clone()
            .with(None::<mechanics::division::Proliferation>);
        ext.restore_arrays(
            n,
            mechanics::persist::Source::Frame,
            |name| {
                Ok(arrays.iter().find(|a| a.name == name).map(|a| {
                    let w = a.columns;
                    ids.iter()
                        .flat_map(|&i| a.values[i * w..(i + 1) * w].iter().copied())
                        .collect()
                }))
            },
            |name, why| {
                crate::error::AnalyzeError::Options(format!("the state's array {name} {why}"))
            },
        )?;
        let pick = |f: &dyn Fn(&mechanics::CellState) -> [f64; 2]| -> Vec<[f64; 2]> {
            slots.iter().map(|&s| f(&cs[s])).collect()
        };
        Ok(Self {
            tissue: rebuilt.with_extensions(ext),
            step: tissue.iteration(),
            origins,
            phi,
            shapes: pick(&|c| c.shape.components()),
            centres: slots.iter().map(|&s| ws.centres()[s]).collect(),
            velocities: pick(&|c| [c.velocity.x, c.velocity.y]),
            areas: slots.iter().map(|&s| cs[s].area).collect(),
            ids,
            force_parts: Vec::new(),
        })
    }

    /// The per-cell arrays of the frame's parts, row by row (the tissue numbers its cells by
    /// row): every array a frame writes for them ([`mechanics::Extensions::frame_arrays`]:
    /// each cell's population, the terms' state and what they derive, such as `polarity`).
    /// The ParaView files and the render's arrows are built from this one table, as Python's
    /// cell table is; an array of 2 columns is a vector.
    pub(crate) fn part_arrays(&self) -> Vec<mechanics::persist::StateArray> {
        self.tissue.extensions().frame_arrays()
    }

    /// `Σ_i φ_i` at every node, and the cell with the largest `φ_i` where that exceeds ½ (−1
    /// elsewhere).
    pub(crate) fn phi_sum_and_owner(&self, nx: usize, ny: usize) -> (Vec<f32>, Vec<i32>) {
        let frame = self;
        let l = frame.tissue.lattice();
        let mut sum = vec![0.0f64; l.len()];
        let mut best = vec![0.5f64; l.len()];
        let mut owner = vec![-1i32; l.len()];
        for (i, o) in frame.origins.iter().enumerate() {
            let phi = &frame.phi[i * nx * ny..(i + 1) * nx * ny];
            for u in 0..nx {
                let x = (o[0] + u) % l.lx;
                for v in 0..ny {
                    let k = x * l.ly + (o[1] + v) % l.ly;
                    let f = phi[u * ny + v];
                    sum[k] += f;
                    if f > best[k] {
                        best[k] = f;
                        owner[k] = i as i32;
                    }
                }
            }
        }
        (sum.into_iter().map(|v| v as f32).collect(), owner)
    }
}

fn pairs(a: &Array) -> Vec<[f64; 2]> {
    a.data.chunks_exact(2).map(|s| [s[0], s[1]]).collect()
}

/// The identity of each of the `n` rows of the frame at `path` (its `id`, checked: `n`
/// increasing whole numbers), or `0..n` for a frame from before format 3.
pub(crate) fn frame_ids(path: &Path, n: usize) -> Result<Vec<usize>> {
    match read_npz(path, &["id"]) {
        Ok(mut a) => {
            let ids = a.remove(0).data;
            let increasing = ids.windows(2).all(|w| w[0] < w[1]);
            if ids.len() != n || !increasing || ids.iter().any(|&v| !(v >= 0.0 && v.fract() == 0.0))
            {
                return Err(input(
                    path,
                    format!(
                        "array 'id' must hold {n} increasing cell identities, one per row of phi"
                    ),
                ));
            }
            Ok(ids.iter().map(|&v| v as usize).collect())
        }
        Err(rundir::RunDirError::MissingArray { .. }) => {
            // Frames before format 3 had no `id`: their rows are the cells `0..n`. A frame of
            // format 3 or later without it has lost it, and its rows cannot be told apart
            // once cells divide.
            let format = read_npz(path, &["format"])
                .ok()
                .and_then(|a| a[0].scalar())
                .unwrap_or(0.0);
            if format >= 3.0 {
                return Err(input(
                    path,
                    format!("array 'id' is missing from a frame of format {format}, which keeps each row's cell identity; the file is damaged: write it again (resume the run from a checkpoint before it) or remove it"),
                ));
            }
            Ok((0..n).collect())
        }
        Err(e) => Err(input(path, e.to_string())),
    }
}

/// Checks that every row identity `ids` of the frame at `path` (at time `time`) has a cell in
/// `lineage` that was alive then, as in the run that wrote both: a `lineage.csv` of another
/// run, or one cut short, would colour and place cells wrongly.
///
/// # Errors
/// The first identity the lineage does not know, or knows as not alive at `time`.
pub(crate) fn check_lineage(
    path: &Path,
    ids: &[usize],
    time: f64,
    lineage: &[mechanics::division::LineageRecord],
) -> Result<()> {
    for &id in ids {
        let alive = lineage
            .binary_search_by_key(&id, |r| r.id)
            .ok()
            .map(|k| &lineage[k])
            .filter(|r| r.id == id);
        let reason = match alive {
            None => format!("cell {id} of this frame is not in lineage.csv"),
            // A founder is there from the start, whatever its cycle's phase says.
            Some(r) if r.parent.is_some() && r.birth > time + 1e-9 => format!(
                "cell {id} of this frame (t = {time}) was born at t = {} by lineage.csv",
                r.birth
            ),
            Some(r) if r.death.is_some_and(|(t, _)| t < time - 1e-9) => format!(
                "cell {id} of this frame (t = {time}) is gone by t = {} in lineage.csv",
                r.death.map_or(f64::NAN, |d| d.0)
            ),
            Some(_) => continue,
        };
        return Err(input(
            path,
            format!("{reason}: the frame and lineage.csv are not of the same run; restore the run's own lineage.csv beside its frames"),
        ));
    }
    Ok(())
}

/// The per-cell arrays of the frame at `path` checked for its `n` cells on `lattice`: each of
/// the right length and finite (`phi` too), every patch origin a node of the lattice. Returns
/// the origins.
fn checked_cells(
    path: &Path,
    n: usize,
    lattice: Lattice,
    [origin, shape_tensor, centre, velocity, area, phi]: [&Array; 6],
) -> Result<Vec<[usize; 2]>> {
    for (name, a, len) in [
        ("origin", origin, 2 * n),
        ("shape_tensor", shape_tensor, 2 * n),
        ("centre", centre, 2 * n),
        ("velocity", velocity, 2 * n),
        ("area", area, n),
    ] {
        if a.data.len() != len {
            return Err(input(
                path,
                format!("{name} has {} values for {n} cells", a.data.len()),
            ));
        }
    }
    for (name, a) in [
        ("phi", &phi.data),
        ("shape_tensor", &shape_tensor.data),
        ("centre", &centre.data),
        ("velocity", &velocity.data),
        ("area", &area.data),
    ] {
        let bad = a.iter().filter(|v| !v.is_finite()).count();
        if bad > 0 {
            return Err(input(
                path,
                format!("array '{name}' holds {bad} non-finite values (NaN or infinite): the state is not one the model can have; analyse the frames before it with --from or rerun with a smaller dt"),
            ));
        }
    }
    let mut origins: Vec<[usize; 2]> = Vec::with_capacity(n);
    for (i, o) in origin.data.chunks_exact(2).enumerate() {
        let ok = |v: f64, l: usize| v >= 0.0 && v.fract() == 0.0 && v < l as f64;
        if !(ok(o[0], lattice.lx) && ok(o[1], lattice.ly)) {
            return Err(input(
                path,
                format!(
                    "array 'origin' puts patch {i} at {:?}, off the {}×{} lattice",
                    o, lattice.lx, lattice.ly
                ),
            ));
        }
        origins.push([o[0] as usize, o[1] as usize]);
    }
    Ok(origins)
}

/// One frame's state, rebuilt as a tissue.
pub(crate) fn load_frame(
    path: &Path,
    scene: &Scene,
    shape: &PatchShape,
    lattice: Lattice,
) -> Result<LoadedFrame> {
    // The format was checked when the frame was selected (`frame_time`).
    let arrays = read_npz(
        path,
        &[
            "step",
            "time",
            "zeta",
            "lattice",
            "origin",
            "phi",
            "shape_tensor",
            "centre",
            "velocity",
            "area",
        ],
    )
    .map_err(|e| {
        input(
            path,
            format!("the frame was written by another version or is damaged: {e}"),
        )
    })?;
    let [step, time, zeta, lat, origin, phi, shape_tensor, centre, velocity, area]: [Array; 10] =
        arrays
            .try_into()
            .expect("read_npz returns one array per name");
    let one = |a: &Array, name: &str| -> Result<f64> {
        a.scalar().ok_or_else(|| {
            input(
                path,
                format!("array '{name}' must hold one number, not {}", a.data.len()),
            )
        })
    };
    let (step, time, zeta) = (
        one(&step, "step")? as u64,
        one(&time, "time")?,
        one(&zeta, "zeta")?,
    );
    if lat.data != [lattice.lx as f64, lattice.ly as f64] {
        return Err(input(
            path,
            format!(
                "the frame is on a {:?} lattice but scene.toml says {}×{}",
                lat.data, lattice.lx, lattice.ly
            ),
        ));
    }
    // With `[division]` the number of cells changes: each frame has its own.
    let n = if scene.file().division.is_some() {
        phi.shape.first().map_or(0, |&n| n as usize)
    } else {
        scene.file().cells.count
    };
    let want = vec![n as u64, shape.nx as u64, shape.ny as u64];
    if phi.shape != want || n == 0 || n > scene.max_cells() {
        return Err(input(
            path,
            format!(
                "phi has shape {:?}, the scene implies {want:?} (at most {} cells)",
                phi.shape,
                scene.max_cells()
            ),
        ));
    }
    let ids = frame_ids(path, n)?;
    let origins = checked_cells(
        path,
        n,
        lattice,
        [&origin, &shape_tensor, &centre, &velocity, &area, &phi],
    )?;
    if !(time.is_finite() && zeta.is_finite()) {
        return Err(input(
            path,
            format!("time {time} or zeta {zeta} is not finite"),
        ));
    }
    let cells = Cells::from_unrolled(lattice, shape.clone(), &origins, &phi.data);
    // The scene's parts, their state then read from the frame as `init = "frame"` reads it
    // (the terms' state, each cell's population). Two differ from a run's: the terms are
    // the recorded forces where this program lacks a term's code (`frame_terms`), and there
    // is no cell-cycle clock, whose lineage a frame does not keep.
    let ext = scene
        .configured_extensions()
        .with(None::<mechanics::division::Proliferation>)
        .with(frame_terms(path, scene, n)?);
    let mut tissue = Tissue::from_state(
        cells,
        scene.model_params(zeta),
        time,
        step,
        (0..n).collect(),
    );
    // The terms act as they did in the run: from the end of the relaxation, with the state
    // the frame holds.
    tissue.set_active(time >= scene.file().run.relax_time * (1.0 - 1e-12));
    let tissue = rundir::read_extensions(path, tissue, ext, mechanics::persist::Source::Frame)
        .map_err(|e| input(path, e.to_string()))?;
    // The per-cell arrays must describe the cells of `phi`, in its order: each stored centre
    // must be the centre of mass of its field (to a tenth of a node: f32 storage rounds it by
    // about 1e-5), or pictures and ParaView files would put one cell's values on another.
    let centres = pairs(&centre);
    for (i, (c, m)) in centres.iter().zip(tissue.centres()).enumerate() {
        if lattice.distance(*c, *m) > 0.1 {
            return Err(input(
                path,
                format!(
                    "array 'centre' puts cell {i} at ({:.2}, {:.2}) but its phi has its centre of mass at ({:.2}, {:.2}): the per-cell arrays do not belong to the fields in this order (was the frame edited?); rewrite the frame or leave it out with --frames",
                    c[0], c[1], m[0], m[1]
                ),
            ));
        }
    }
    // The forces by origin, as recorded.
    let names = rundir::npz_names(path).map_err(|e| input(path, e.to_string()))?;
    let recorded: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| n.starts_with("force."))
        .collect();
    let force_parts = if recorded.is_empty() {
        Vec::new()
    } else {
        let arrays = read_npz(path, &recorded).map_err(|e| input(path, e.to_string()))?;
        let mut out = Vec::new();
        for (name, a) in recorded.iter().zip(arrays) {
            if a.data.len() != 2 * n || a.data.iter().any(|v| !v.is_finite()) {
                return Err(input(
                    path,
                    format!("array '{name}' holds {} values, not 2 finite values for each of the {n} cells", a.data.len()),
                ));
            }
            out.push((name.to_string(), a.data));
        }
        out
    };
    Ok(LoadedFrame {
        tissue,
        step,
        origins,
        phi: phi.data,
        shapes: pairs(&shape_tensor),
        centres,
        velocities: pairs(&velocity),
        areas: area.data,
        ids,
        force_parts,
    })
}

/// The step and time of a frame, after checking that this version can read it.
fn frame_clock(path: &Path) -> Result<(u64, f64)> {
    let a = read_npz(path, &["format", "step", "time"]).map_err(|e| {
        input(
            path,
            format!("the frame was written by another version or is damaged: {e}"),
        )
    })?;
    let scalar = |k: usize, name: &str| -> Result<f64> {
        a[k].scalar().filter(|v| v.is_finite()).ok_or_else(|| {
            input(
                path,
                format!(
                    "array '{name}' must hold one finite number, not {:?}",
                    a[k].data
                ),
            )
        })
    };
    let format = scalar(0, "format")? as i64;
    if !FRAME_FORMATS_READ.contains(&format) {
        return Err(input(
            path,
            format!(
                "the frame has format {format}, this version reads formats 1 to {FRAME_FORMAT}"
            ),
        ));
    }
    let step = scalar(1, "step")?;
    if step < 0.0 || step.fract() != 0.0 {
        return Err(input(
            path,
            format!("array 'step' holds {step}, not a step number"),
        ));
    }
    Ok((step as u64, scalar(2, "time")?))
}
