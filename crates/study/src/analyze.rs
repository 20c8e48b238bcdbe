//! The analysis pipeline of a run directory (`monolayer analyze RUN_DIR`): from a run directory to the paper's quantities, in
//! `RUN_DIR/analysis/`.
//!
//! For every frame at or after `--from` (default: the end of relaxation) the state is rebuilt
//! from the frame's patches and evaluated by `mechanics` (the step's own code) into lattice
//! fields; `analysis` then smooths `v`, `ω` and `Q` with a periodic box (default the odd side
//! nearest 3R), accumulates their correlations, finds and orients the defects of the smoothed
//! `Q`, tracks them, and averages the raw fields around each defect in its own frame.

use std::path::{Path, PathBuf};

use analysis::correlation::{first_minimum, Correlator};
use analysis::crop::CropFields;
use analysis::crop::{DefectAverage, COMPONENTS};
use analysis::defects::net_charge;
use analysis::fields::{rms, s_rms, vorticity};
use analysis::smooth::{box_smooth, paper_box_side};
use analysis::tracking::{TrackParams, Tracker};
use mechanics::{Tissue, TissueFields, Workspace};
use phasefield::{Cells, Lattice, PatchShape};

use analysis::proximity::{mean_nearest_over, nearest};
use rundir::{npy, read_npz, write_npz, Array, FRAME_FORMAT, FRAME_FORMATS_READ};
use scene::{Scene, SceneFile};

/// What stops the analysis of a run, naming the file or option.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnalyzeError {
    /// A file of the run is missing, damaged or inconsistent with the scene.
    #[error("{}: {why}", path.display())]
    Input {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong, and what to do.
        why: String,
    },
    /// An option cannot be used.
    #[error("{0}")]
    Options(String),
    /// An output file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
}

type Result<T, E = AnalyzeError> = std::result::Result<T, E>;

pub(crate) fn input(path: &Path, why: impl Into<String>) -> AnalyzeError {
    AnalyzeError::Input {
        path: path.to_path_buf(),
        why: why.into(),
    }
}

/// The fields of a state that the defect-centred averages crop.
pub fn crop_fields(f: &TissueFields) -> CropFields<'_> {
    CropFields {
        vx: &f.vx,
        vy: &f.vy,
        sigma_xx: &f.sigma_xx,
        sigma_yy: &f.sigma_yy,
        sigma_xy: &f.sigma_xy,
        pressure: &f.pressure,
        qxx: &f.qxx,
        qxy: &f.qxy,
    }
}

/// The default side of the defect-centred crops: the paper's Fig. 4 window (4R on each
/// side of the defect for R = 8, with room around it).
pub const DEFAULT_CROP: usize = 101;

/// The crop side used when none is given: [`DEFAULT_CROP`], or on a lattice too small for
/// it, the largest side `analyze` accepts there (twice the shorter side plus one; beyond it a
/// crop only repeats the periodic lattice).
pub fn default_crop(lattice: phasefield::Lattice) -> usize {
    DEFAULT_CROP.min(2 * lattice.lx.min(lattice.ly) + 1)
}

/// Options of `monolayer analyze`; the default leaves every choice to the run's scene.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AnalyzeOptions {
    /// First time analysed (default: the scene's `relax_time`, the start of activity).
    pub from: Option<f64>,
    /// Side of the smoothing box (odd; default: the odd side nearest 3R).
    pub box_side: Option<usize>,
    /// Side of the defect-centred crops (odd; default [`default_crop`]: [`DEFAULT_CROP`], or
    /// twice the lattice's shorter side plus one when that is smaller).
    pub crop_side: Option<usize>,
    /// Longest link of a defect between frames (default R).
    pub max_link: Option<f64>,
    /// Largest separation of a created or annihilated pair (default 2R).
    pub max_pair: Option<f64>,
    /// `S_rms` of a ζ = 0 run, to report `S_rms` relative to it.
    pub s_rms_baseline: Option<f64>,
}

/// What an analysis found.
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyzeInfo {
    /// Frames analysed.
    pub frames: usize,
    /// Defects found over all frames.
    pub defects: usize,
    /// Creation and annihilation events.
    pub events: usize,
    /// Divisions, extrusions and deaths in the analysed time (`[division]`; 0 without).
    pub cell_events: usize,
    /// What reading the frames noticed.
    pub notes: FrameNotes,
}

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
            Some(r) if r.birth > time + 1e-9 => format!(
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
    // The populations by row: the frame's own when cells divide (daughters inherit), else
    // the scene's deal.
    let populations = scene.populations();
    let populations = if populations.is_empty() || scene.file().division.is_none() {
        populations
    } else {
        let rows = read_npz(path, &["population"])
            .map_err(|e| input(path, e.to_string()))?
            .remove(0)
            .data;
        populations
            .reassigned(&rows, n)
            .map_err(|r| input(path, format!("array 'population': {r}")))?
    };
    for (name, a, len) in [
        ("origin", &origin, 2 * n),
        ("shape_tensor", &shape_tensor, 2 * n),
        ("centre", &centre, 2 * n),
        ("velocity", &velocity, 2 * n),
        ("area", &area, n),
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
    if !(time.is_finite() && zeta.is_finite()) {
        return Err(input(
            path,
            format!("time {time} or zeta {zeta} is not finite"),
        ));
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
    let cells = Cells::from_unrolled(lattice, shape.clone(), &origins, &phi.data);
    let mut tissue = Tissue::from_state(
        cells,
        scene.model_params(zeta),
        time,
        step,
        (0..n).collect(),
    )
    .with_populations(populations)
    .with_terms(frame_terms(path, scene, n)?);
    if let Some(walls) = scene.walls() {
        tissue = tissue.with_walls(walls);
    }
    // The terms act as they did in the run: from the end of the relaxation, with the state
    // the frame holds.
    tissue.set_active(time >= scene.file().run.relax_time * (1.0 - 1e-12));
    let ext = tissue.extensions().clone();
    let tissue = rundir::read_extensions(path, tissue, ext, mechanics::extensions::Source::Frame)
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

/// Writes `text` to `path` whole: under a temporary name first, so that an error leaves no
/// empty or truncated table behind.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("partial");
    let err = |source| AnalyzeError::Write {
        path: path.to_path_buf(),
        source,
    };
    std::fs::write(&tmp, bytes).map_err(err)?;
    std::fs::rename(&tmp, path).map_err(err)
}

/// Appends one formatted line to a table held in a `String`.
macro_rules! row {
    ($buf:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($buf, $($arg)*);
    }};
}

/// Runs the analysis of `run_dir` into `run_dir/analysis/`.
///
/// # Errors
/// On a missing, partial or foreign run directory, with what is wrong.
pub fn analyze(run_dir: &Path, opts: &AnalyzeOptions) -> Result<AnalyzeInfo> {
    let scene = read_scene(run_dir)?;
    // One process at a time: not while a run or another analysis writes the directory.
    let _lock = rundir::lock_dir(run_dir).map_err(|e| input(run_dir, e.to_string()))?;
    let lattice = scene.lattice();
    let shape = scene.patch_shape();
    let FrameList { frames, notes } = list_frames(run_dir, &scene)?;
    let from = opts.from.unwrap_or(scene.file().run.relax_time);
    let radius = scene.file().cells.radius;
    let box_side = opts.box_side.unwrap_or_else(|| default_box(&scene));
    box_smooth(lattice, &vec![0.0; lattice.len()], box_side)
        .map_err(|e| AnalyzeError::Options(format!("--box {box_side}: {e}")))?;
    let crop_side = opts.crop_side.unwrap_or_else(|| default_crop(lattice));
    if crop_side % 2 != 1 {
        return Err(AnalyzeError::Options(
            "--crop must be odd (the defect sits on the centre node), e.g. 101".into(),
        ));
    }
    // A crop wraps the periodic lattice; beyond twice its side it only repeats it (and a
    // huge one exhausts memory: --crop 100001 asked for 10¹⁰ nodes per component).
    let most = 2 * lattice.lx.min(lattice.ly) + 1;
    if crop_side > most {
        return Err(AnalyzeError::Options(format!(
            "--crop {}: more than twice the lattice ({}×{}) only repeats it; use an odd side up to {most} (default 101)",
            crop_side, lattice.lx, lattice.ly
        )));
    }
    for (flag, v) in [
        ("--max-link", opts.max_link),
        ("--max-pair", opts.max_pair),
        ("--s-rms-baseline", opts.s_rms_baseline),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return Err(AnalyzeError::Options(format!(
                    "{flag} {v}: give a positive number (the defaults are R for --max-link and 2R for --max-pair)"
                )));
            }
        }
    }
    if opts.from.is_some_and(|f| !f.is_finite()) {
        return Err(AnalyzeError::Options(
            "--from must be a finite time (default: the end of relaxation)".into(),
        ));
    }
    let defaults = TrackParams::for_radius(radius);
    let params = TrackParams::new(
        opts.max_link.unwrap_or(defaults.max_link),
        opts.max_pair.unwrap_or(defaults.max_pair),
    );

    let selected: Vec<PathBuf> = frames
        .into_iter()
        .filter(|f| f.time >= from - 1e-9)
        .map(|f| f.path)
        .collect();
    if selected.is_empty() {
        return Err(AnalyzeError::Options(format!(
            "no frame at or after t = {from}; use --from with an earlier time"
        )));
    }

    let out = run_dir.join("analysis");
    std::fs::create_dir_all(&out).map_err(|source| AnalyzeError::Write {
        path: out.clone(),
        source,
    })?;
    let mut obs = String::new();
    row!(obs, "{}", rundir::OBSERVABLES_HEADER);
    let mut defects_csv = String::new();
    // Axes and angle conventions are in the README: a comment line here would be taken for
    // the header by pandas and numpy.
    row!(defects_csv, "frame,time,x,y,charge,angle,track");
    let mut events_csv = String::new();
    row!(events_csv, "frame,time,kind,x,y");

    let mut ws: Option<Workspace> = None;
    let mut corr = [
        Correlator::new(lattice),
        Correlator::new(lattice),
        Correlator::new(lattice),
    ];
    let mut tracker = Tracker::new(lattice, params);
    let mut avg = DefectAverage::new(crop_side);
    let mut info = AnalyzeInfo {
        frames: 0,
        defects: 0,
        events: 0,
        cell_events: 0,
        notes,
    };
    // With `[division]`: each frame's ±½ defects and the random baseline, for the distances
    // of the divisions and extrusions to the defects (`cell_events.csv`).
    let lineage = rundir::read_lineage(run_dir)
        .map_err(|e| input(&run_dir.join("lineage.csv"), e.to_string()))?;
    if lineage.is_none() && scene.file().division.is_some() {
        return Err(input(
            &run_dir.join("lineage.csv"),
            "is missing, but the run's scene has [division]: cell_events.csv (the divisions and extrusions against the defects) and the check of each frame's cells need it; restore the run's lineage.csv (a run rewrites it with every frame)".to_string(),
        ));
    }
    let mut near: Vec<FrameDefects> = Vec::new();
    let mut prev_time: Option<f64> = None;
    let area = lattice.len() as f64;
    // A wound's band: the solid of the walls during the relaxation, when they open after it.
    let wound: Option<Vec<bool>> = scene
        .walls()
        .filter(|w| w.open_when_active())
        .and_then(|w| {
            w.field(false)
                .map(|f| (0..lattice.len()).map(|k| f.is_solid(k)).collect())
        });
    let mut positions: Vec<analysis::motion::Positions> = Vec::new();
    let disc_centre = scene
        .file()
        .walls
        .as_ref()
        .filter(|w| w.kind == scene::WallKind::Disc)
        .map(|_| {
            [
                (lattice.lx as f64 - 1.0) / 2.0,
                (lattice.ly as f64 - 1.0) / 2.0,
            ]
        });
    for path in &selected {
        let frame = load_frame(path, &scene, &shape, lattice)?;
        if let Some(lineage) = &lineage {
            check_lineage(path, &frame.ids, frame.tissue.time(), lineage)?;
        }
        let (demix, polar) = mixing_and_order(&frame, &shape);
        // Each cell's shape index P/√A, averaged; and the centres for the MSD.
        let cells_n = frame.centres.len();
        let patch = shape.nx * shape.ny;
        let shape_index = if cells_n == 0 {
            f64::NAN
        } else {
            frame
                .phi
                .chunks_exact(patch)
                .map(|p| analysis::motion::shape_index(p, shape.nx, shape.ny))
                .sum::<f64>()
                / cells_n as f64
        };
        positions.push(analysis::motion::Positions {
            time: frame.tissue.time(),
            ids: frame.ids.clone(),
            centres: frame.centres.clone(),
        });
        // In a disc (or an ellipse), the cells' rotation about its centre.
        let rotation = disc_centre.map_or(f64::NAN, |c| {
            analysis::confinement::angular_order(&frame.centres, &frame.velocities, c)
        });
        // s1 = Σφ_i on the lattice: the tissue mask of the defects, a wound's gap and the
        // cover of the random points of `cell_events.csv`.
        let (phi_sum, _) = crate::view::phi_sum_and_owner(&frame, shape.nx, shape.ny);
        let phi_sum: Vec<f64> = phi_sum.iter().map(|&v| f64::from(v)).collect();
        let gap = wound.as_ref().map_or(f64::NAN, |band| {
            analysis::confinement::uncovered_fraction(&phi_sum, band)
        });
        let covered: Option<Vec<bool>> = lineage
            .as_ref()
            .map(|_| phi_sum.iter().map(|&v| v >= 0.5).collect());
        let LoadedFrame {
            tissue,
            shapes,
            step,
            ..
        } = frame;
        let ws = ws.get_or_insert_with(|| Workspace::new(tissue.cells()));
        // A run whose cells divide has its own number of cells in each frame.
        ws.fit(tissue.cells());
        let f = tissue.fields(ws);
        let smooth = |v: &[f64]| box_smooth(lattice, v, box_side).expect("checked above");
        let (svx, svy) = (smooth(&f.vx), smooth(&f.vy));
        let w = vorticity(lattice, &svx, &svy);
        let (sqxx, sqxy) = (smooth(&f.qxx), smooth(&f.qxy));
        corr[0].add(&[&svx, &svy]);
        corr[1].add(&[&w]);
        corr[2].add(&[&sqxx, &sqxy]);
        // Only defects in tissue, as `render` draws them (`view::in_tissue`): in the empty
        // space of a colony, a wound or a channel's wall `Q ≈ 0` and its angle is noise.
        let (_, found) = crate::view::in_tissue(lattice, box_side, &phi_sum, &sqxx, &sqxy)
            .map_err(|e| AnalyzeError::Options(e.to_string()))?;
        let tracks = tracker.push(&found);
        let time = tissue.time();
        for (d, t) in found.iter().zip(&tracks.track) {
            row!(
                defects_csv,
                "{step},{time:.6},{},{},{},{},{t}",
                d.x,
                d.y,
                d.charge,
                d.angle
            );
        }
        let (mut creations, mut annihilations) = (0, 0);
        for e in &tracks.events {
            match e.kind {
                analysis::tracking::EventKind::Creation => creations += 1,
                analysis::tracking::EventKind::Annihilation => annihilations += 1,
            }
            row!(
                events_csv,
                "{step},{time:.6},{},{},{}",
                e.kind.name(),
                e.x,
                e.y
            );
        }
        if let Some(mask) = &covered {
            let at = |q: f64| -> Vec<[f64; 2]> {
                found
                    .iter()
                    .filter(|d| d.charge == q)
                    .map(|d| [d.x, d.y])
                    .collect()
            };
            let (plus, minus) = (at(0.5), at(-0.5));
            let stride = (radius / 2.0).max(1.0) as usize;
            near.push(FrameDefects {
                time,
                random: [
                    mean_nearest_over(lattice, mask, &plus, stride),
                    mean_nearest_over(lattice, mask, &minus, stride),
                ],
                plus,
                minus,
            });
        }
        avg.add(lattice, &crop_fields(&f), &found);
        let n_plus = found.iter().filter(|d| d.charge == 0.5).count();
        let n_minus = found.iter().filter(|d| d.charge == -0.5).count();
        let s = s_rms(&shapes);
        let rate = match prev_time {
            Some(p) if time > p => creations as f64 / ((time - p) * area),
            _ => f64::NAN,
        };
        row!(
            obs,
            "{step},{time:.6},{:e},{:e},{:e},{n_plus},{n_minus},{},{},{:e},{creations},{annihilations},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            rms(&[&f.vx, &f.vy]),
            s,
            opts.s_rms_baseline.map_or(f64::NAN, |b| s / b),
            found.len() - n_plus - n_minus,
            net_charge(&found),
            found.len() as f64 / area,
            tracks.unpaired,
            rate,
            rms(&[&svx, &svy]),
            demix,
            polar,
            gap,
            rotation,
            shape_index,
            f.vx.iter().sum::<f64>() / area,
            f.vy.iter().sum::<f64>() / area
        );
        prev_time = Some(time);
        info.frames += 1;
        info.defects += found.len();
        info.events += tracks.events.len();
    }
    write_file(&out.join("observables.csv"), obs.as_bytes())?;
    let mut msd_csv = String::new();
    row!(msd_csv, "{}", rundir::MSD_HEADER);
    for p in analysis::motion::msd(&positions, [lattice.lx as f64, lattice.ly as f64]) {
        row!(
            msd_csv,
            "{:.6},{:e},{:e},{}",
            p.lag,
            p.msd,
            p.msd_raw,
            p.samples
        );
    }
    write_file(&out.join("msd.csv"), msd_csv.as_bytes())?;
    write_file(&out.join("defects.csv"), defects_csv.as_bytes())?;
    write_file(&out.join("defect_events.csv"), events_csv.as_bytes())?;
    if let Some(lineage) = &lineage {
        info.cell_events = write_cell_events(&out, lattice, lineage, &near)?;
    }

    let radial: Vec<Vec<f64>> = corr.iter().map(|c| c.radial()).collect();
    let mut c = String::new();
    row!(c, "r,c_velocity,c_vorticity,c_q");
    for r in 0..radial[0].len() {
        row!(
            c,
            "{r},{:e},{:e},{:e}",
            radial[0][r],
            radial[1][r],
            radial[2][r]
        );
    }
    write_file(&out.join("correlations.csv"), c.as_bytes())?;
    let mut l = String::new();
    row!(l, "field,length");
    for (name, r) in ["velocity", "vorticity", "q"].iter().zip(&radial) {
        row!(l, "{name},{}", first_minimum(r).unwrap_or(f64::NAN));
    }
    write_file(&out.join("lengths.csv"), l.as_bytes())?;
    write_averages(&out.join("defect_averages.npz"), &avg)?;
    Ok(info)
}

/// One analysed frame's ±½ defects, and the mean distance of a random point of its tissue
/// to the nearest of each.
struct FrameDefects {
    time: f64,
    plus: Vec<[f64; 2]>,
    minus: Vec<[f64; 2]>,
    random: [f64; 2],
}

/// Writes `cell_events.csv` (every division, extrusion and death of `lineage.csv` within the
/// analysed frames, at the frame nearest in time: the distance from where the cell ended to
/// the nearest +½ and −½ defect, and the same for a random point of the tissue) and
/// `cell_events_summary.csv` (their means by kind). Returns the number of events.
fn write_cell_events(
    out: &Path,
    lattice: Lattice,
    lineage: &[mechanics::division::LineageRecord],
    frames: &[FrameDefects],
) -> Result<usize> {
    let mut csv = String::new();
    row!(
        csv,
        "time,kind,id,x,y,frame_time,d_plus,d_minus,d_plus_random,d_minus_random"
    );
    let (Some(first), Some(last)) = (frames.first(), frames.last()) else {
        return Ok(0);
    };
    let half = if frames.len() > 1 {
        0.5 * (last.time - first.time) / (frames.len() - 1) as f64
    } else {
        0.0
    };
    // kind → (count, Σ d_plus, Σ d_plus_random, Σ d_minus, Σ d_minus_random), finite only.
    let mut sums: std::collections::BTreeMap<&str, [f64; 5]> = Default::default();
    let mut n = 0;
    for r in lineage {
        let Some((t, why)) = r.death else { continue };
        if t < first.time - half || t > last.time + half {
            continue;
        }
        let f = frames
            .iter()
            .min_by(|a, b| (a.time - t).abs().total_cmp(&(b.time - t).abs()))
            .expect("frames are not empty");
        let d = [
            nearest(lattice, r.place, &f.plus),
            nearest(lattice, r.place, &f.minus),
        ];
        let shown = |v: f64| {
            if v.is_finite() {
                format!("{v:e}")
            } else {
                "nan".into()
            }
        };
        row!(
            csv,
            "{t},{},{},{},{},{},{},{},{},{}",
            why.name(),
            r.id,
            r.place[0],
            r.place[1],
            f.time,
            shown(d[0]),
            shown(d[1]),
            shown(f.random[0]),
            shown(f.random[1])
        );
        let e = sums.entry(why.name()).or_default();
        if [d[0], d[1], f.random[0], f.random[1]]
            .iter()
            .all(|v| v.is_finite())
        {
            e[0] += 1.0;
            e[1] += d[0];
            e[2] += f.random[0];
            e[3] += d[1];
            e[4] += f.random[1];
        }
        n += 1;
    }
    write_file(&out.join("cell_events.csv"), csv.as_bytes())?;
    let mut summary = String::new();
    row!(
        summary,
        "kind,events,mean_d_plus,mean_d_plus_random,mean_d_minus,mean_d_minus_random"
    );
    for (kind, e) in &sums {
        let m = |v: f64| if e[0] > 0.0 { v / e[0] } else { f64::NAN };
        row!(
            summary,
            "{kind},{},{:e},{:e},{:e},{:e}",
            e[0],
            m(e[1]),
            m(e[2]),
            m(e[3]),
            m(e[4])
        );
    }
    write_file(&out.join("cell_events_summary.csv"), summary.as_bytes())?;
    Ok(n)
}

/// The demixing parameter of the frame's populations over the cells that touch
/// (`analysis::mixing`; NaN without populations), and the polar order `|⟨p_i⟩|` of the
/// cells' polarities (NaN without `[polarity]`).
fn mixing_and_order(frame: &LoadedFrame, shape: &PatchShape) -> (f64, f64) {
    let tissue = &frame.tissue;
    let pops = tissue.populations();
    let demix = if pops.is_empty() {
        f64::NAN
    } else {
        let (_, owner) = crate::view::phi_sum_and_owner(frame, shape.nx, shape.ny);
        let pairs = analysis::mixing::contacts(tissue.lattice(), &owner);
        let label: Vec<usize> = (0..tissue.n_cells())
            .map(|id| pops.population(id))
            .collect();
        analysis::mixing::demixing(&pairs, &label)
    };
    let polar = tissue.terms().state("polarity").map_or(f64::NAN, |theta| {
        let n = theta.len().max(1) as f64;
        let (c, s) = theta
            .iter()
            .fold((0.0, 0.0), |(c, s), t| (c + t.cos(), s + t.sin()));
        (c / n).hypot(s / n)
    });
    (demix, polar)
}

fn write_averages(path: &Path, avg: &DefectAverage) -> Result<()> {
    let err = |e: &dyn std::fmt::Display| input(path, e.to_string());
    let side = avg.side() as u64;
    let mut arrays = vec![
        (
            "n_plus".to_string(),
            npy(&[], [avg.n_plus as f64]).map_err(|e| err(&e))?,
        ),
        (
            "n_minus".to_string(),
            npy(&[], [avg.n_minus as f64]).map_err(|e| err(&e))?,
        ),
    ];
    for (plus, prefix) in [(true, "plus"), (false, "minus")] {
        for name in COMPONENTS {
            arrays.push((
                format!("{prefix}_{name}"),
                npy(&[side, side], avg.average(plus, name)).map_err(|e| err(&e))?,
            ));
        }
    }
    write_npz(path, arrays).map_err(|e| err(&e))
}
