//! Pictures and ParaView files of a run directory: `monolayer render` and
//! `monolayer export vtk`.
//!
//! Every frame is rebuilt as a tissue and evaluated by `mechanics` (as
//! [`crate::analyze`] does), so the pictures and the files show the fields the step itself
//! computes: `v = Σ_i φ_i v_i`, `Q = Σ_i φ_i S_i`, the pressure `P` of the run's pressure form
//! and the stress `σ = −P I − ζ Q`. The director and the defects are those of `Q` smoothed
//! with the analysis' box (the odd side nearest 3R), as in `analysis/defects.csv`.
//!
//! Pictures ([`render_run`]): `OUT/frame_STEP.png`, one per frame, and optionally a movie.
//! ParaView files ([`export_vtk`]): `OUT/fields_STEP.vti` (lattice fields), `OUT/cells_STEP.vtp`
//! (cell centres with their data), and `OUT/fields.pvd`, `OUT/cells.pvd`, the time series
//! ParaView opens.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use analysis::smooth::box_smooth;
use mechanics::division::{Ending, LineageRecord};
use mechanics::{TissueFields, Workspace};
use render::{
    CellArrows, CellAxes, EventKind, EventMark, Fill, LatticeVectors, Movie, Patches, RenderError,
    TissuePicture,
};
use rundir::vtk::{write_pvd, write_vti, write_vtp, VtkArray, VtkValues};
use rundir::RunDirError;
use scene::Scene;

use crate::error::AnalyzeError;
use crate::frame::{
    default_box, list_frames, load_frame, read_scene, FrameList, FrameNotes, LoadedFrame,
};
pub use crate::region::{in_tissue, TISSUE_COVER, TISSUE_Q};

/// What stops a render or an export.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ViewError {
    /// The run directory or one of its frames.
    #[error(transparent)]
    Run(#[from] AnalyzeError),
    /// An option that cannot be used.
    #[error("{0}")]
    Options(String),
    /// A picture or a movie.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A ParaView file.
    #[error(transparent)]
    Files(#[from] RunDirError),
    /// An output directory that cannot be made.
    #[error("cannot create {}: {source}", path.display())]
    Create {
        /// The directory.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
}

type Result<T, E = ViewError> = std::result::Result<T, E>;

/// Which frames: all, or the ones at these steps.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Frames {
    /// Every frame of the run.
    All,
    /// The frames at these steps, in this order.
    Steps(Vec<u64>),
}

impl FromStr for Frames {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "all" {
            return Ok(Self::All);
        }
        s.split(',')
            .map(|v| {
                v.trim().parse::<u64>().map_err(|_| {
                    format!("--frames {s}: '{v}' is not a step; give all or steps such as 0,500,1000 (the numbers in frames/frame_STEP.npz)")
                })
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Self::Steps)
    }
}

/// What fills the cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Colour {
    /// Light grey.
    None,
    /// The speed `|v_i|`.
    Velocity,
    /// The cell's mean pressure `Σ φ_i P / Σ φ_i` (diverging map about 0).
    Pressure,
    /// The area `Σ φ_i²`.
    Area,
    /// The deformation `|S_i| = (S_xx² + S_xy²)^½`.
    Deformation,
    /// Each cell its own colour.
    Id,
    /// Each cell by its population (`[[population]]`).
    Population,
    /// Each cell by its generation in `lineage.csv` (`[division]`): 0 for a founder.
    Generation,
    /// Each cell the colour of its founder (`[division]`): the clones of one cell share it.
    Lineage,
}

impl FromStr for Colour {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "none" => Self::None,
            "velocity" => Self::Velocity,
            "pressure" => Self::Pressure,
            "area" => Self::Area,
            "deformation" => Self::Deformation,
            "id" => Self::Id,
            "population" => Self::Population,
            "generation" => Self::Generation,
            "lineage" => Self::Lineage,
            _ => {
                return Err(format!(
                "--colour {s}: use none, velocity, pressure, area, deformation, id, population, generation or lineage"
            ))
            }
        })
    }
}

/// Which nematic field a picture's director and defects belong to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirectorOf {
    /// The cells' shapes: `Q = Σ φ_i S_i`.
    Shape,
    /// The cells' own nematic (`[nematic]`): `M = Σ φ_i q_i`.
    Nematic,
}

impl std::str::FromStr for DirectorOf {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "shape" => Ok(Self::Shape),
            "nematic" => Ok(Self::Nematic),
            _ => Err(format!(
                "--director-of {s}: use shape (the cells' shapes' Q) or nematic (the cells' own nematic field M, scenes with [nematic])"
            )),
        }
    }
}

/// Options of [`render_run`].
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Which frames.
    pub frames: Frames,
    /// What fills the cells.
    pub colour: Colour,
    /// The director of the smoothed `Q`.
    pub director: bool,
    /// The ±½ defects of the smoothed `Q`.
    pub defects: bool,
    /// Whose director and defects `director` and `defects` draw: the cells' shapes' `Q`
    /// (the default) or the cells' own nematic field `M = Σ φ_i q_i` (scenes with `[nematic]`),
    /// as `analysis/defects.csv` and `analysis/defects_nematic.csv` find them.
    pub director_of: DirectorOf,
    /// Arrows of the velocity field `Σ φ_i v_i`.
    pub flow: bool,
    /// Each cell's principal deformation axis (with `Colour::None`: the paper's Fig. 1b).
    pub axes: bool,
    /// Each cell's polarity, an arrow (scenes with `[polarity]`).
    pub polarity: bool,
    /// Each cell's own nematic axis, a segment (scenes with `[nematic]`).
    pub nematic: bool,
    /// Each cell's track: its centre through every frame up to the one drawn.
    pub tracks: bool,
    /// The divisions, extrusions and deaths of `lineage.csv` since the frame before (runs
    /// with `[division]`): a ring, a black ×, a grey ×.
    pub events: bool,
    /// The picture's width in pixels (default: 4 per node, from 400 to 1000).
    pub size: Option<u32>,
    /// The colour bar's range (default: each frame's own).
    pub range: Option<(f64, f64)>,
    /// Also a movie of the frames (`.gif`, `.apng`, `.mp4`).
    pub movie: Option<PathBuf>,
    /// The movie's frames per second.
    pub fps: f64,
    /// Write one PNG per frame (off: only the movie).
    pub pngs: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            frames: Frames::All,
            colour: Colour::None,
            director: false,
            defects: false,
            director_of: DirectorOf::Shape,
            flow: false,
            axes: false,
            polarity: false,
            nematic: false,
            tracks: false,
            events: false,
            size: None,
            range: None,
            movie: None,
            fps: 5.0,
            pngs: true,
        }
    }
}

/// What a render or an export wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewInfo {
    /// Frames drawn or exported.
    pub frames: usize,
    /// What reading the frames noticed.
    pub notes: FrameNotes,
    /// The files written (PNGs, the movie; or the `.pvd` collections).
    pub files: Vec<PathBuf>,
}

/// A run directory opened for pictures or export: its scene and the selected frames.
struct Run {
    scene: Scene,
    /// `lineage.csv`, by identity, when cells divide.
    lineage: Option<Vec<LineageRecord>>,
    frames: Vec<PathBuf>,
    /// Every frame of the run, with its step (the tracks are drawn through all of them).
    all: Vec<(u64, PathBuf)>,
    notes: FrameNotes,
}

impl Run {
    fn open(run_dir: &Path, which: &Frames) -> Result<Self> {
        let scene = read_scene(run_dir)?;
        let FrameList { frames: all, notes } = list_frames(run_dir, &scene)?;
        let every: Vec<(u64, PathBuf)> = all.iter().map(|f| (f.step, f.path.clone())).collect();
        let frames = match which {
            Frames::All => all.into_iter().map(|f| f.path).collect(),
            Frames::Steps(steps) => {
                let mut picked = Vec::new();
                for s in steps {
                    match all.iter().find(|f| f.step == *s) {
                        Some(f) => picked.push(f.path.clone()),
                        None => {
                            let (first, last) = (all[0].step, all[all.len() - 1].step);
                            return Err(ViewError::Options(format!(
                                "--frames: the run has no frame at step {s}; it has {} frames, steps {first} to {last} (see {})",
                                all.len(),
                                run_dir.join("frames").display()
                            )));
                        }
                    }
                }
                picked
            }
        };
        let lineage = rundir::read_lineage(run_dir).map_err(|e| {
            ViewError::Run(crate::error::input(
                &run_dir.join("lineage.csv"),
                e.to_string(),
            ))
        })?;
        Ok(Self {
            scene,
            lineage,
            frames,
            all: every,
            notes,
        })
    }

    /// Each cell's centre in every frame of the run up to step `last`, in order (the cells'
    /// tracks).
    /// A track follows a cell's identity (the frames' `id`), so a daughter's starts at its
    /// birth and a mother's ends at her division.
    fn tracks(&self, last: u64) -> Result<Vec<Vec<[f64; 2]>>> {
        let mut tracks: std::collections::BTreeMap<usize, Vec<[f64; 2]>> = Default::default();
        for (step, path) in self.all.iter().filter(|(s, _)| *s <= last) {
            let err = |e: rundir::RunDirError| {
                ViewError::Run(crate::error::input(
                    path,
                    format!("{e} (frame at step {step})"),
                ))
            };
            let a = rundir::read_npz(path, &["centre"]).map_err(err)?;
            let centres: Vec<[f64; 2]> = a[0].data.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
            let ids = crate::frame::frame_ids(path, centres.len())?;
            for (id, c) in ids.into_iter().zip(centres) {
                tracks.entry(id).or_default().push(c);
            }
        }
        Ok(tracks.into_values().collect())
    }

    fn load(&self, path: &Path) -> Result<LoadedFrame> {
        let frame = load_frame(
            path,
            &self.scene,
            &self.scene.patch_shape(),
            self.scene.lattice(),
        )?;
        if let Some(lineage) = &self.lineage {
            crate::frame::check_lineage(path, &frame.ids, frame.tissue.time(), lineage)?;
        }
        Ok(frame)
    }
}

fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| ViewError::Create {
        path: dir.to_path_buf(),
        source,
    })
}

/// Each cell's mean of a lattice field over its patch, weighted by `φ_i`.
fn cell_means(frame: &LoadedFrame, nx: usize, ny: usize, field: &[f64]) -> Vec<f64> {
    let l = frame.tissue.lattice();
    frame
        .origins
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let phi = &frame.phi[i * nx * ny..(i + 1) * nx * ny];
            let (mut num, mut den) = (0.0, 0.0);
            for u in 0..nx {
                let x = (o[0] + u) % l.lx;
                for v in 0..ny {
                    let y = (o[1] + v) % l.ly;
                    let w = phi[u * ny + v];
                    num += w * field[x * l.ly + y];
                    den += w;
                }
            }
            num / den
        })
        .collect()
}

/// The record of `id` in a lineage in increasing identity (as `lineage.csv` has it).
fn record(lineage: &[LineageRecord], id: usize) -> Option<&LineageRecord> {
    lineage
        .binary_search_by_key(&id, |r| r.id)
        .ok()
        .map(|k| &lineage[k])
}

/// The founder (generation 0) the cell `id` descends from, following `parent` up the lineage
/// (`id` itself when the lineage does not know it).
fn founder(lineage: &[LineageRecord], id: usize) -> usize {
    let mut id = id;
    while let Some(p) = record(lineage, id).and_then(|r| r.parent) {
        id = p;
    }
    id
}

/// What a picture of a frame reads besides the frame: the scene, the lineage (`None`
/// without `[division]`), and the cells' tracks up to the frame when they are drawn.
struct Context<'a> {
    scene: &'a Scene,
    lineage: Option<&'a [LineageRecord]>,
    tracks: Option<Vec<Vec<[f64; 2]>>>,
}

/// What fills the cells of a picture for `colour`: a value per cell with its label (the
/// pressure from the evaluated fields `f`), a category per cell with the legend's names
/// (populations, generations), a colour per key (identities, founders), or nothing.
fn fill(run: &Context<'_>, frame: &LoadedFrame, f: Option<&TissueFields>, colour: Colour) -> Fill {
    let shape = run.scene.patch_shape();
    let signed = colour == Colour::Pressure;
    let values: Option<(Vec<f64>, &str)> = match colour {
        Colour::None | Colour::Id | Colour::Lineage | Colour::Generation | Colour::Population => {
            None
        }
        Colour::Velocity => Some((
            frame.velocities.iter().map(|v| v[0].hypot(v[1])).collect(),
            "|v|",
        )),
        Colour::Area => Some((frame.areas.clone(), "area Σφ²")),
        Colour::Deformation => Some((
            frame.shapes.iter().map(|s| s[0].hypot(s[1])).collect(),
            "|S|",
        )),
        Colour::Pressure => Some((
            cell_means(frame, shape.nx, shape.ny, &f.expect("evaluated").pressure),
            "pressure P",
        )),
    };
    match (colour, values) {
        (Colour::Id, _) => Fill::Keys(frame.ids.clone()),
        // Categories, in a legend: each population by its name, each generation by number.
        (Colour::Population, _) => {
            let pops = frame.tissue.populations();
            Fill::Categories {
                of_cell: (0..frame.tissue.n_cells())
                    .map(|id| pops.population(id))
                    .collect(),
                names: (0..pops.kinds().len().max(1))
                    .map(|k| {
                        run.scene
                            .file()
                            .population
                            .get(k)
                            .map_or_else(|| "all cells".to_string(), |p| p.name(k))
                    })
                    .collect(),
            }
        }
        (Colour::Generation, _) => {
            let of_cell: Vec<usize> = frame
                .ids
                .iter()
                .map(|&id| {
                    record(run.lineage.unwrap_or_default(), id).map_or(0, |r| r.generation as usize)
                })
                .collect();
            let top = of_cell.iter().copied().max().unwrap_or(0);
            Fill::Categories {
                of_cell,
                names: (0..=top).map(|g| format!("generation {g}")).collect(),
            }
        }
        (Colour::Lineage, _) => Fill::Keys(
            frame
                .ids
                .iter()
                .map(|&id| founder(run.lineage.unwrap_or_default(), id))
                .collect(),
        ),
        (_, Some((values, label))) => Fill::Values {
            values,
            label: label.into(),
            signed,
        },
        _ => Fill::Plain,
    }
}

fn picture(
    run: &Context<'_>,
    frame: &LoadedFrame,
    ws: &mut Workspace,
    opts: &RenderOptions,
) -> Result<TissuePicture> {
    let l = run.scene.lattice();
    let shape = run.scene.patch_shape();
    let radius = run.scene.file().cells.radius;
    let size = opts
        .size
        .unwrap_or_else(|| (4 * l.lx).clamp(400, 1000) as u32);
    let mut p = TissuePicture::new(l.lx, l.ly, size);
    p.patches = Patches {
        nx: shape.nx,
        ny: shape.ny,
        origins: frame.origins.clone(),
        phi: frame.phi.clone(),
    };
    p.mark = radius;
    p.walls = frame.tissue.wall_field().map(|w| w.w().to_vec());
    let need_fields = opts.director || opts.defects || opts.flow || opts.colour == Colour::Pressure;
    let f: Option<TissueFields> = need_fields.then(|| frame.tissue.fields(ws));
    p.fill = fill(run, frame, f.as_ref(), opts.colour);
    p.range = opts.range;
    if let Some(f) = &f {
        if opts.director || opts.defects {
            let side = default_box(run.scene);
            let smooth = |v: &[f64]| box_smooth(l, v, side).expect("the box fits the lattice");
            let (fxx, fxy) = match (opts.director_of, &f.cell_nematic) {
                (DirectorOf::Shape, _) => (&f.qxx, &f.qxy),
                (DirectorOf::Nematic, Some([mxx, mxy])) => (mxx, mxy),
                (DirectorOf::Nematic, None) => {
                    return Err(ViewError::Options(
                        "--director-of nematic draws the cells' own nematic field, and this run has no [nematic]: leave the option out, or run a scene with [nematic]".into(),
                    ))
                }
            };
            let (mut qxx, mut qxy) = (smooth(fxx), smooth(fxy));
            // Only where there is tissue: the director of Q, and its defects, mean nothing in
            // the empty gaps between cells (between the initial discs, |Q| ≈ 0 and its angle
            // is noise). Tissue is where cells cover at least TISSUE_COVER of the smoothing box
            // and |Q| is at least TISSUE_Q: at the node for a director segment, averaged over
            // the box around it for a defect (|Q| vanishes at a defect's own core).
            let (phi_sum, _) = frame.phi_sum_and_owner(shape.nx, shape.ny);
            let phi_sum: Vec<f64> = phi_sum.iter().map(|&v| f64::from(v)).collect();
            let (tissue, defects) = in_tissue(l, side, &phi_sum, &qxx, &qxy)
                .map_err(|e| ViewError::Options(e.to_string()))?;
            if opts.defects {
                p.defects = defects;
            }
            for k in 0..tissue.len() {
                if !tissue[k] {
                    qxx[k] = 0.0;
                    qxy[k] = 0.0;
                }
            }
            if opts.director {
                p.director = Some(LatticeVectors {
                    a: qxx,
                    b: qxy,
                    every: ((radius / 2.0).round() as usize).max(2),
                });
            }
        }
        if opts.flow {
            p.flow = Some(LatticeVectors {
                a: f.vx.clone(),
                b: f.vy.clone(),
                every: (radius.round() as usize).max(2),
            });
        }
    }
    if opts.axes {
        p.axes = Some(CellAxes {
            centres: frame.centres.clone(),
            shapes: frame.shapes.clone(),
        });
    }
    p.tracks = run.tracks.clone();
    if opts.events {
        let now = frame.tissue.time();
        let since = now - run.scene.file().run.output_every;
        p.events = run
            .lineage
            .unwrap_or_default()
            .iter()
            .filter_map(|r| {
                let (t, why) = r.death?;
                (t > since + 1e-9 && t <= now + 1e-9).then_some(EventMark {
                    x: r.place[0],
                    y: r.place[1],
                    kind: match why {
                        Ending::Division => EventKind::Division,
                        Ending::Extrusion => EventKind::Extrusion,
                        Ending::Death => EventKind::Death,
                    },
                })
            })
            .collect();
    }
    let arrays = if opts.polarity || opts.nematic {
        frame.part_arrays()
    } else {
        Vec::new()
    };
    let vectors = |name: &str| {
        arrays
            .iter()
            .find(|a| a.name == name && a.columns == 2)
            .map(|v| v.values.chunks_exact(2).map(|d| [d[0], d[1]]).collect())
    };
    if opts.polarity {
        // The parts' first per-cell vector (a 2-column array of the frame: `polarity`, a
        // user's term's), not the cells' nematic, which is a tensor (drawn as axes below).
        let first = arrays
            .iter()
            .find(|a| a.columns == 2 && a.name != "nematic")
            .map(|a| a.name.clone());
        if let Some(directions) = first.and_then(|name| vectors(&name)) {
            p.polarity = Some(CellArrows {
                centres: frame.centres.clone(),
                directions,
            });
        }
    }
    if opts.nematic {
        if let Some(shapes) = vectors("nematic") {
            p.nematic = Some(CellAxes {
                centres: frame.centres.clone(),
                shapes,
            });
        }
    }
    let zetas = &run.scene.file().population;
    let zeta = if zetas.iter().any(|p| p.zeta.is_some()) {
        let each: Vec<String> = zetas
            .iter()
            .enumerate()
            .map(|(k, p)| format!("{} {}", p.name(k), p.zeta.unwrap_or(run.scene.zeta())))
            .collect();
        each.join(", ")
    } else {
        frame.tissue.params().zeta.to_string()
    };
    // With the cells' own nematic, its activity too.
    let zeta = match &run.scene.file().nematic {
        Some(n) => format!("{zeta}   ζ_Q = {}", n.zeta),
        None => zeta,
    };
    p.title = format!(
        "t = {}   ζ = {}   step {}",
        render_time(frame.tissue.time()),
        zeta,
        frame.step
    );
    Ok(p)
}

fn render_time(t: f64) -> String {
    // Clock sums of dt carry round-off: 1200.0000000001 is t = 1200.
    if (t - t.round()).abs() < 1e-6 {
        format!("{t:.0}")
    } else {
        format!("{t:.2}")
    }
}

/// The options of a picture that do not depend on the run: the range and the size.
fn check_picture_options(opts: &RenderOptions) -> Result<()> {
    if let Some((lo, hi)) = opts.range {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(ViewError::Options(format!(
                "--range {lo},{hi}: give two finite numbers, the low one first"
            )));
        }
    }
    if opts.size.is_some_and(|s| !(16..=8000).contains(&s)) {
        return Err(ViewError::Options(format!(
            "--size {}: use a width from 16 to 8000 pixels",
            opts.size.unwrap_or(0)
        )));
    }
    Ok(())
}

/// The options that draw from the lineage, refused where there is none (`lacking` says
/// where it is missing).
fn check_lineage_options(opts: &RenderOptions, has_lineage: bool, lacking: &str) -> Result<()> {
    if matches!(opts.colour, Colour::Generation | Colour::Lineage) && !has_lineage {
        return Err(ViewError::Options(format!(
            "--colour {}: {lacking} (its scene has no [division], so no cell divided); use --colour id",
            if opts.colour == Colour::Generation { "generation" } else { "lineage" },
        )));
    }
    if opts.events && !has_lineage {
        return Err(ViewError::Options(format!(
            "--events: {lacking} (its scene has no [division], so no cell divided or was extruded); leave --events out"
        )));
    }
    Ok(())
}

/// One picture of a tissue's current state, drawn as `monolayer render` draws a frame of it,
/// as PNG bytes, without a run directory: `ws` must hold an observation of this state
/// (`Simulation::observe`), and `scene` is the tissue's. The same picture, to the byte, as
/// the render of the frame `rundir::write_frame` would write of the state (with the
/// lineage beside it). `opts.frames`, the movie and the PNG switch are not read; `tracks`
/// is refused (a state in memory has no earlier frames to draw them through).
///
/// # Errors
/// An option that cannot be used, or a picture that cannot be drawn.
pub fn render_state<T: phasefield::Real>(
    scene: &Scene,
    tissue: &mechanics::Tissue<T>,
    ws: &Workspace<T>,
    opts: &RenderOptions,
) -> Result<Vec<u8>> {
    check_picture_options(opts)?;
    if opts.tracks {
        return Err(ViewError::Options(
            "--tracks: a state in memory has no earlier frames to draw the tracks through; render a run directory's frames for them".into(),
        ));
    }
    let lineage: Option<Vec<LineageRecord>> = tissue
        .proliferation()
        .map(|clock| clock.lineage().cloned().collect());
    check_lineage_options(opts, lineage.is_some(), "the simulation has no lineage")?;
    let frame = LoadedFrame::from_state(tissue, ws)?;
    let mut ws = Workspace::new(frame.tissue.cells());
    let context = Context {
        scene,
        lineage: lineage.as_deref(),
        tracks: None,
    };
    let pic = picture(&context, &frame, &mut ws, opts)?.draw()?;
    pic.png_bytes().map_err(|why| {
        ViewError::Options(format!("the picture could not be encoded as a PNG: {why}"))
    })
}

/// Draws the selected frames of `run_dir` into `out/frame_STEP.png` and, on request, a movie.
/// `progress(done, total)` is called before the first frame and after each.
///
/// # Errors
/// A run directory that cannot be read, a frame that is missing or damaged, an option that
/// cannot be used, or a file that cannot be written; files already written stay.
pub fn render_run(
    run_dir: &Path,
    out: &Path,
    opts: &RenderOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<ViewInfo> {
    check_picture_options(opts)?;
    if !opts.pngs && opts.movie.is_none() {
        return Err(ViewError::Options(
            "nothing to write: without PNGs, give --movie FILE".into(),
        ));
    }
    if let Some(m) = &opts.movie {
        render::MovieKind::of(m).map_err(ViewError::Options)?;
    }
    let run = Run::open(run_dir, &opts.frames)?;
    check_lineage_options(
        opts,
        run.lineage.is_some(),
        &format!("{} has no lineage.csv", run_dir.display()),
    )?;
    create_dir(out)?;
    let total = run.frames.len();
    progress(0, total);
    let mut ws: Option<Workspace> = None;
    let mut movie: Option<Movie> = None;
    let mut files = Vec::new();
    for (k, path) in run.frames.iter().enumerate() {
        let frame = run.load(path)?;
        let ws = ws.get_or_insert_with(|| Workspace::new(frame.tissue.cells()));
        // A run whose cells divide has its own number of cells in each frame.
        ws.fit(frame.tissue.cells());
        let context = Context {
            scene: &run.scene,
            lineage: run.lineage.as_deref(),
            tracks: if opts.tracks {
                Some(run.tracks(frame.step)?)
            } else {
                None
            },
        };
        let pic = picture(&context, &frame, ws, opts)?.draw()?;
        if let Some(m) = &opts.movie {
            if movie.is_none() {
                movie = Some(Movie::create(
                    m,
                    pic.width,
                    pic.height,
                    total as u32,
                    opts.fps,
                )?);
            }
            movie.as_mut().expect("created").push(&pic)?;
        }
        // After the movie has started, so that a movie that cannot be made (no ffmpeg)
        // stops the render before anything is written.
        if opts.pngs {
            let png = out.join(format!("frame_{:08}.png", frame.step));
            pic.save_png(&png)?;
            files.push(png);
        }
        progress(k + 1, total);
    }
    if let Some(m) = movie {
        m.finish()?;
        files.push(opts.movie.clone().expect("a movie was asked for"));
    }
    Ok(ViewInfo {
        frames: total,
        notes: run.notes.clone(),
        files,
    })
}

fn f32s(v: &[f64]) -> VtkValues {
    VtkValues::F32(v.iter().map(|&x| x as f32).collect())
}

fn interleave(parts: &[&[f64]]) -> VtkValues {
    let n = parts[0].len();
    VtkValues::F32(
        (0..n)
            .flat_map(|k| parts.iter().map(move |p| p[k] as f32))
            .collect(),
    )
}

/// The point arrays of one frame's `.vti` (see [`export_vtk`]).
fn field_arrays(frame: &LoadedFrame, f: &TissueFields, nx: usize, ny: usize) -> Vec<VtkArray> {
    let (phi_sum, owner) = frame.phi_sum_and_owner(nx, ny);
    let zero = vec![0.0; f.vx.len()];
    let (dx, dy): (Vec<f64>, Vec<f64>) = f
        .qxx
        .iter()
        .zip(&f.qxy)
        .map(|(&a, &b)| {
            let (s, th) = (a.hypot(b), 0.5 * b.atan2(a));
            (s * th.cos(), s * th.sin())
        })
        .unzip();
    // The owner's identity (the frames' `id`), −1 where no cell is.
    let owner = owner
        .into_iter()
        .map(|o| {
            if o < 0 {
                o
            } else {
                frame.ids[o as usize] as i32
            }
        })
        .collect();
    let mut arrays = vec![
        VtkArray::new("phi_sum", 1, VtkValues::F32(phi_sum)),
        VtkArray::new("cell_id", 1, VtkValues::I32(owner)),
        VtkArray::new("velocity", 3, interleave(&[&f.vx, &f.vy, &zero])),
        VtkArray::new("Q", 2, interleave(&[&f.qxx, &f.qxy])),
        VtkArray::new("director", 3, interleave(&[&dx, &dy, &zero])),
        VtkArray::new("pressure", 1, f32s(&f.pressure)),
        VtkArray::new("sigma_xx", 1, f32s(&f.sigma_xx)),
        VtkArray::new("sigma_yy", 1, f32s(&f.sigma_yy)),
        VtkArray::new("sigma_xy", 1, f32s(&f.sigma_xy)),
    ];
    if let Some(w) = frame.tissue.wall_field() {
        arrays.push(VtkArray::new("wall", 1, f32s(w.w())));
    }
    arrays
}

/// The points and point arrays of one frame's `.vtp` (see [`export_vtk`]).
fn cell_arrays(frame: &LoadedFrame) -> (Vec<[f64; 3]>, Vec<VtkArray>) {
    let points = frame.centres.iter().map(|c| [c[0], c[1], 0.0]).collect();
    let axis: Vec<f64> = frame
        .shapes
        .iter()
        .flat_map(|s| {
            let (m, th) = (s[0].hypot(s[1]), 0.5 * s[1].atan2(s[0]));
            [m * th.cos(), m * th.sin(), 0.0]
        })
        .collect();
    let arrays = vec![
        VtkArray::new(
            "cell_id",
            1,
            VtkValues::I32(frame.ids.iter().map(|&i| i as i32).collect()),
        ),
        VtkArray::new(
            "velocity",
            3,
            VtkValues::F64(
                frame
                    .velocities
                    .iter()
                    .flat_map(|v| [v[0], v[1], 0.0])
                    .collect(),
            ),
        ),
        VtkArray::new("deformation_axis", 3, VtkValues::F64(axis)),
        VtkArray::new(
            "shape_tensor",
            2,
            VtkValues::F64(frame.shapes.iter().flatten().copied().collect()),
        ),
        VtkArray::new("area", 1, VtkValues::F64(frame.areas.clone())),
    ];
    let mut arrays = arrays;
    // Every per-cell array of the parts, as Python's cell table has them: a whole number as
    // int32, a 2-column array as a vector `(x, y, 0)`.
    for a in frame.part_arrays() {
        let values = match (a.columns, a.integer) {
            (1, true) => VtkValues::I32(a.values.iter().map(|&v| v as i32).collect()),
            (2, _) => VtkValues::F64(
                a.values
                    .chunks_exact(2)
                    .flat_map(|v| [v[0], v[1], 0.0])
                    .collect(),
            ),
            _ => VtkValues::F64(a.values.clone()),
        };
        let components = if a.columns == 2 { 3 } else { a.columns };
        arrays.push(VtkArray::new(a.name, components, values));
    }
    // The forces by origin the run recorded (`[run] forces_by_origin`), as vectors.
    for (name, values) in &frame.force_parts {
        let v = values
            .chunks_exact(2)
            .flat_map(|v| [v[0], v[1], 0.0])
            .collect();
        arrays.push(VtkArray::new(name.clone(), 3, VtkValues::F64(v)));
    }
    (points, arrays)
}

/// Writes the selected frames of `run_dir` as ParaView files into `out`:
///
/// | file | what |
/// |---|---|
/// | `fields_STEP.vti` | ImageData `lx × ly × 1`, spacing 1; point arrays (float32 unless said): `phi_sum` `Σ_i φ_i`; `cell_id` (int32) the cell with the largest `φ_i` at the node, −1 where none exceeds ½; `velocity` `(v_x, v_y, 0)`; `Q` `(Q_xx, Q_xy)`; `director` `|Q| (cos θ, sin θ, 0)`; `pressure`; `sigma_xx`, `sigma_yy`, `sigma_xy`; with `[walls]` `wall`, the wall field `w` in effect at the frame's time |
/// | `cells_STEP.vtp` | PolyData, one vertex per cell at its centre; point arrays (float64): `cell_id` (int32), `velocity` `(v_x, v_y, 0)`, `deformation_axis` `|S| (cos θ_S, sin θ_S, 0)`, `shape_tensor` `(S_xx, S_xy)`, `area`; and every per-cell array of the scene's parts, as the frame has it (a whole number as int32, a 2-column array as a vector `(x, y, 0)`): with `[polarity]` `polarity.theta` and `polarity` `(p_x, p_y, 0)`, with `[[population]]` `population` (int32); with `[run] forces_by_origin`, each `force.ORIGIN` the frame holds, `(F_x, F_y, 0)` |
/// | `fields.pvd`, `cells.pvd` | the time series (each file with its frame's time) |
///
/// Every file also holds its time as the field `TimeValue`. `progress(done, total)` is called
/// before the first frame and after each.
///
/// # Errors
/// As [`render_run`].
pub fn export_vtk(
    run_dir: &Path,
    out: &Path,
    frames: &Frames,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<ViewInfo> {
    let run = Run::open(run_dir, frames)?;
    create_dir(out)?;
    let shape = run.scene.patch_shape();
    let l = run.scene.lattice();
    let total = run.frames.len();
    progress(0, total);
    let mut ws: Option<Workspace> = None;
    let (mut fields_pvd, mut cells_pvd) = (Vec::new(), Vec::new());
    for (k, path) in run.frames.iter().enumerate() {
        let frame = run.load(path)?;
        let ws = ws.get_or_insert_with(|| Workspace::new(frame.tissue.cells()));
        // A run whose cells divide has its own number of cells in each frame.
        ws.fit(frame.tissue.cells());
        let f = frame.tissue.fields(ws);
        let time = frame.tissue.time();
        let vti = format!("fields_{:08}.vti", frame.step);
        write_vti(
            &out.join(&vti),
            l.lx,
            l.ly,
            time,
            &field_arrays(&frame, &f, shape.nx, shape.ny),
        )?;
        let vtp = format!("cells_{:08}.vtp", frame.step);
        let (points, arrays) = cell_arrays(&frame);
        write_vtp(&out.join(&vtp), &points, time, &arrays)?;
        fields_pvd.push((time, vti));
        cells_pvd.push((time, vtp));
        progress(k + 1, total);
    }
    let (a, b) = (out.join("fields.pvd"), out.join("cells.pvd"));
    write_pvd(&a, &fields_pvd)?;
    write_pvd(&b, &cells_pvd)?;
    Ok(ViewInfo {
        frames: total,
        notes: run.notes.clone(),
        files: vec![a, b],
    })
}
