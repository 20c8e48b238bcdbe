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
use analysis::smooth::box_smooth;
use analysis::tracking::{TrackParams, Tracker};
use mechanics::{TissueFields, Workspace};
use phasefield::{Lattice, PatchShape};

use analysis::proximity::{mean_nearest_over, nearest};
use rundir::{npy, write_npz};

pub use crate::error::AnalyzeError;
use crate::error::{input, Result};
pub use crate::frame::FrameNotes;
use crate::frame::{
    check_lineage, default_box, list_frames, load_frame, read_scene, FrameList, LoadedFrame,
};

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
    let settings = Settings::checked(opts, &scene)?;

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
    let mut acc = Accumulator::new(&scene, &settings, lineage.is_some(), notes);
    for path in &selected {
        let frame = load_frame(path, &scene, &shape, lattice)?;
        if let Some(lineage) = &lineage {
            check_lineage(path, &frame.ids, frame.tissue.time(), lineage)?;
        }
        acc.add(frame, &shape, opts.s_rms_baseline)?;
    }
    acc.write(&out, lineage.as_deref())
}

/// The analysis's settings from its options and the scene, each checked: the smoothing box,
/// the crop of the defect averages and the tracking distances.
struct Settings {
    box_side: usize,
    crop_side: usize,
    track: TrackParams,
}

impl Settings {
    /// The settings of `opts` for `scene`, or the option that is wrong and what to give.
    fn checked(opts: &AnalyzeOptions, scene: &scene::Scene) -> Result<Self> {
        let lattice = scene.lattice();
        let radius = scene.file().cells.radius;
        let box_side = opts.box_side.unwrap_or_else(|| default_box(scene));
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
        Ok(Self {
            box_side,
            crop_side,
            track: params,
        })
    }
}

/// What the analysis gathers frame by frame, then writes ([`Accumulator::write`]): the rows
/// of its tables, the correlations, the defect tracks and averages, the cells' positions.
struct Accumulator {
    lattice: Lattice,
    box_side: usize,
    radius: f64,
    area: f64,
    /// A wound's band: the solid of the walls during the relaxation, when they open after it.
    wound: Option<Vec<bool>>,
    /// The centre of a disc's walls, for the rotation.
    disc_centre: Option<[f64; 2]>,
    /// Whether the run has a lineage (`cell_events.csv`).
    lineage: bool,
    obs: String,
    /// The columns the terms add (`CellTerm::observables`, beyond the documented
    /// `polar_order`), known once a frame is read.
    term_columns: Option<Vec<&'static str>>,
    defects_csv: String,
    /// With `[nematic]`, the defects of the cells' own nematic field `M` (`defects_nematic.csv`).
    nematic_defects_csv: Option<String>,
    events_csv: String,
    ws: Option<Workspace>,
    corr: [Correlator; 3],
    tracker: Tracker,
    avg: DefectAverage,
    info: AnalyzeInfo,
    near: Vec<FrameDefects>,
    prev_time: Option<f64>,
    positions: Vec<analysis::motion::Positions>,
}

impl Accumulator {
    fn new(scene: &scene::Scene, settings: &Settings, lineage: bool, notes: FrameNotes) -> Self {
        let lattice = scene.lattice();
        let mut defects_csv = String::new();
        // Axes and angle conventions are in the README: a comment line here would be taken
        // for the header by pandas and numpy.
        row!(defects_csv, "frame,time,x,y,charge,angle,track");
        let mut events_csv = String::new();
        row!(events_csv, "frame,time,kind,x,y");
        Self {
            lattice,
            box_side: settings.box_side,
            radius: scene.file().cells.radius,
            area: lattice.len() as f64,
            wound: scene
                .walls()
                .filter(|w| w.open_when_active())
                .and_then(|w| {
                    w.field(false)
                        .map(|f| (0..lattice.len()).map(|k| f.is_solid(k)).collect())
                }),
            disc_centre: scene
                .file()
                .walls
                .as_ref()
                .filter(|w| w.kind == scene::WallKind::Disc)
                .map(|_| {
                    [
                        (lattice.lx as f64 - 1.0) / 2.0,
                        (lattice.ly as f64 - 1.0) / 2.0,
                    ]
                }),
            lineage,
            obs: String::new(),
            term_columns: None,
            defects_csv,
            nematic_defects_csv: scene
                .file()
                .nematic
                .is_some()
                .then(|| "frame,time,x,y,charge,angle\n".to_string()),
            events_csv,
            ws: None,
            corr: [
                Correlator::new(lattice),
                Correlator::new(lattice),
                Correlator::new(lattice),
            ],
            tracker: Tracker::new(lattice, settings.track),
            avg: DefectAverage::new(settings.crop_side),
            info: AnalyzeInfo {
                frames: 0,
                defects: 0,
                events: 0,
                cell_events: 0,
                notes,
            },
            near: Vec::new(),
            prev_time: None,
            positions: Vec::new(),
        }
    }

    /// Adds a frame: its row of observables, its defects and their events, its fields to the
    /// correlations and the defect averages, its cells' positions.
    fn add(
        &mut self,
        frame: LoadedFrame,
        shape: &PatchShape,
        s_rms_baseline: Option<f64>,
    ) -> Result<()> {
        let Self {
            lattice,
            box_side,
            radius,
            area,
            wound,
            disc_centre,
            lineage,
            obs,
            term_columns,
            defects_csv,
            nematic_defects_csv,
            events_csv,
            ws,
            corr,
            tracker,
            avg,
            info,
            near,
            prev_time,
            positions,
        } = self;
        let (lattice, box_side, radius, area, lineage) =
            (*lattice, *box_side, *radius, *area, *lineage);
        let (demix, boundary, polar, term_obs) = mixing_and_order(&frame, shape);
        let columns = term_columns.get_or_insert_with(|| term_obs.iter().map(|o| o.0).collect());
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
        let (phi_sum, owner) = frame.phi_sum_and_owner(shape.nx, shape.ny);
        let phi_sum: Vec<f64> = phi_sum.iter().map(|&v| f64::from(v)).collect();
        let gap = wound.as_ref().map_or(f64::NAN, |band| {
            analysis::confinement::uncovered_fraction(&phi_sum, band)
        });
        let covered: Option<Vec<bool>> =
            lineage.then(|| phi_sum.iter().map(|&v| v >= 0.5).collect());
        // The centres of the 5-fold cells (Loewe et al., PRL 2020: extrusion starts near the
        // 5-fold disclinations of the triangulation of the centres), for `cell_events.csv`.
        let fivefold: Vec<[f64; 2]> = if covered.is_some() {
            let pairs = analysis::mixing::contacts(lattice, &owner);
            analysis::mixing::neighbour_counts(&pairs, frame.centres.len())
                .iter()
                .zip(&frame.centres)
                .filter(|(&c, _)| c == 5)
                .map(|(_, &p)| p)
                .collect()
        } else {
            Vec::new()
        };
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
        let (_, found) = crate::region::in_tissue(lattice, box_side, &phi_sum, &sqxx, &sqxy)
            .map_err(|e| AnalyzeError::Options(e.to_string()))?;
        // The cells' own nematic field's defects, found the same way (smoothed, in tissue).
        if let (Some(csv), Some([mxx, mxy])) = (nematic_defects_csv.as_mut(), &f.cell_nematic) {
            let (_, m_found) =
                crate::region::in_tissue(lattice, box_side, &phi_sum, &smooth(mxx), &smooth(mxy))
                    .map_err(|e| AnalyzeError::Options(e.to_string()))?;
            for d in &m_found {
                row!(
                    csv,
                    "{step},{:.6},{},{},{},{}",
                    tissue.time(),
                    d.x,
                    d.y,
                    d.charge,
                    d.angle
                );
            }
        }
        let tracks = tracker.push(&found);
        let time = tissue.time();
        let (creations, annihilations) =
            write_defect_rows(defects_csv, events_csv, step, time, &found, &tracks);
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
            let decoys = [
                decoys(lattice, mask, plus.len(), step, 1),
                decoys(lattice, mask, minus.len(), step, 2),
            ];
            let share_stride = (radius / 4.0).max(1.0) as usize;
            let share = |points: &[[f64; 2]]| {
                analysis::proximity::share_within(lattice, mask, points, radius, share_stride)
            };
            near.push(FrameDefects {
                time,
                near_random: [
                    share(&plus),
                    share(&minus),
                    share(&decoys[0]),
                    share(&fivefold),
                ],
                random: [
                    mean_nearest_over(lattice, mask, &plus, stride),
                    mean_nearest_over(lattice, mask, &minus, stride),
                ],
                decoy_random: [
                    mean_nearest_over(lattice, mask, &decoys[0], stride),
                    mean_nearest_over(lattice, mask, &decoys[1], stride),
                ],
                decoys,
                plus,
                minus,
                fivefold,
            });
        }
        avg.add(lattice, &crop_fields(&f), &found);
        let n_plus = found.iter().filter(|d| d.charge == 0.5).count();
        let n_minus = found.iter().filter(|d| d.charge == -0.5).count();
        let s = s_rms(&shapes);
        let rate = match *prev_time {
            Some(p) if time > p => creations as f64 / ((time - p) * area),
            _ => f64::NAN,
        };
        let mut line = format!(
            "{step},{time:.6},{:e},{:e},{:e},{n_plus},{n_minus},{},{},{:e},{creations},{annihilations},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            rms(&[&f.vx, &f.vy]),
            s,
            s_rms_baseline.map_or(f64::NAN, |b| s / b),
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
            f.vy.iter().sum::<f64>() / area,
            analysis::confinement::shear_across(&analysis::confinement::mean_over_x(
                &f.vx, lattice.lx, lattice.ly
            )),
            boundary
        );
        for name in columns.iter() {
            let v = term_obs
                .iter()
                .find(|o| o.0 == *name)
                .map_or(f64::NAN, |o| o.1);
            line += &format!(",{v:e}");
        }
        row!(obs, "{line}");
        *prev_time = Some(time);
        info.frames += 1;
        info.defects += found.len();
        info.events += tracks.events.len();
        Ok(())
    }

    /// Writes the tables and averages into `out`.
    fn write(
        self,
        out: &Path,
        lineage: Option<&[mechanics::division::LineageRecord]>,
    ) -> Result<AnalyzeInfo> {
        let Self {
            lattice,
            term_columns,
            obs,
            defects_csv,
            nematic_defects_csv,
            events_csv,
            corr,
            avg,
            mut info,
            near,
            positions,
            ..
        } = self;
        let mut header = rundir::OBSERVABLES_HEADER.to_string();
        for name in term_columns.iter().flatten() {
            header += &format!(",{name}");
        }
        write_file(
            &out.join("observables.csv"),
            format!("{header}\n{obs}").as_bytes(),
        )?;
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
        if let Some(csv) = nematic_defects_csv {
            write_file(&out.join("defects_nematic.csv"), csv.as_bytes())?;
        }
        write_file(&out.join("defect_events.csv"), events_csv.as_bytes())?;
        if let Some(lineage) = &lineage {
            info.cell_events = write_cell_events(out, lattice, lineage, &near)?;
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
}

/// The rows of `defects.csv` and `defect_events.csv` of one frame; the numbers of pair
/// creations and annihilations among its events.
fn write_defect_rows(
    defects_csv: &mut String,
    events_csv: &mut String,
    step: u64,
    time: f64,
    found: &[analysis::defects::Defect],
    tracks: &analysis::tracking::FrameTracks,
) -> (usize, usize) {
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
    (creations, annihilations)
}

/// One analysed frame's ±½ defects, and the mean distance of a random point of its tissue
/// to the nearest of each; and the control of issue 54: as many *decoys* of each charge as
/// there are defects, nodes of the tissue drawn at random in place of them, with the mean
/// distance of a random point to the nearest decoy. Events are no nearer decoys than random
/// points are, whatever draws them to defects.
struct FrameDefects {
    time: f64,
    plus: Vec<[f64; 2]>,
    minus: Vec<[f64; 2]>,
    random: [f64; 2],
    decoys: [Vec<[f64; 2]>; 2],
    decoy_random: [f64; 2],
    /// The centres of the 5-fold cells (five touching neighbours).
    fivefold: Vec<[f64; 2]>,
    /// The share of the tissue within one cell radius of a +½ defect, a −½ defect, a +½
    /// decoy and a 5-fold cell (`analysis::proximity::share_within`): the chance that a
    /// random point of the tissue is near one.
    near_random: [f64; 4],
}

/// `count` nodes where `mask` holds (index `x * ly + y`), drawn by a hash of `(step, salt,
/// k)` (SplitMix64), so that the same frame draws the same decoys in any run of the analysis.
fn decoys(lattice: Lattice, mask: &[bool], count: usize, step: u64, salt: u64) -> Vec<[f64; 2]> {
    let nodes: Vec<usize> = (0..mask.len()).filter(|&k| mask[k]).collect();
    if nodes.is_empty() {
        return Vec::new();
    }
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    (0..count as u64)
        .map(|k| {
            let h = mix(mix(step ^ salt.rotate_left(32)) ^ k);
            let node = nodes[(h % nodes.len() as u64) as usize];
            [(node / lattice.ly) as f64, (node % lattice.ly) as f64]
        })
        .collect()
}

/// Writes `cell_events.csv` (every division, extrusion and death of `lineage.csv` within the
/// analysed frames, at the last frame at or before it: the distance from where the cell ended to
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
        "time,kind,id,x,y,frame_time,d_plus,d_minus,d_plus_random,d_minus_random,d_plus_decoy,d_minus_decoy,d_plus_decoy_random,d_minus_decoy_random,d_fivefold,near_plus_random,near_minus_random,near_plus_decoy_random,near_fivefold_random"
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
        // The last frame at or before the event, where the cell still was (the first frame
        // for an event before it): in a frame after an extrusion its place may be a hole,
        // where no random point of the tissue can be, which biased the null (issue 49: the
        // decoys' enrichment read 0.5 at the nearest frame).
        let f = frames
            .iter()
            .rev()
            .find(|f| f.time <= t + 1e-9)
            .unwrap_or(first);
        let d = [
            nearest(lattice, r.place, &f.plus),
            nearest(lattice, r.place, &f.minus),
        ];
        let dd = [
            nearest(lattice, r.place, &f.decoys[0]),
            nearest(lattice, r.place, &f.decoys[1]),
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
            "{t},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            why.name(),
            r.id,
            r.place[0],
            r.place[1],
            f.time,
            shown(d[0]),
            shown(d[1]),
            shown(f.random[0]),
            shown(f.random[1]),
            shown(dd[0]),
            shown(dd[1]),
            shown(f.decoy_random[0]),
            shown(f.decoy_random[1]),
            shown(nearest(lattice, r.place, &f.fivefold)),
            shown(f.near_random[0]),
            shown(f.near_random[1]),
            shown(f.near_random[2]),
            shown(f.near_random[3])
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
/// (`analysis::mixing`; NaN without populations), the first population's radial order in a
/// free cluster (`analysis::mixing::radial_excess`, when the tissue has a free boundary: an
/// outside region of at least a cell's area `πR²`; NaN without populations or a free
/// boundary), the polar order `|⟨p_i⟩|` of the cells'
/// polarities (NaN without `[polarity]`), and every other observable the terms define, by
/// name (columns of their own at the end of `observables.csv`).
fn mixing_and_order(
    frame: &LoadedFrame,
    shape: &PatchShape,
) -> (f64, f64, f64, Vec<(&'static str, f64)>) {
    let tissue = &frame.tissue;
    let pops = tissue.populations();
    let (demix, boundary) = if pops.is_empty() {
        (f64::NAN, f64::NAN)
    } else {
        let (_, owner) = frame.phi_sum_and_owner(shape.nx, shape.ny);
        let pairs = analysis::mixing::contacts(tissue.lattice(), &owner);
        let label: Vec<usize> = (0..tissue.n_cells())
            .map(|id| pops.population(id))
            .collect();
        let cell_area = tissue.params().energy.target_area().ceil() as usize;
        let lattice = tissue.lattice();
        let on = analysis::mixing::free_boundary(lattice, &owner, label.len(), cell_area);
        let radial = if on.contains(&true) {
            analysis::mixing::radial_excess(
                &frame.centres,
                &label,
                0,
                lattice.lx as f64,
                lattice.ly as f64,
            )
        } else {
            f64::NAN
        };
        (analysis::mixing::demixing(&pairs, &label), radial)
    };
    // The terms' own observables (`CellTerm::observables`) over the frame's cells.
    let ids: Vec<usize> = (0..tissue.n_cells()).collect();
    let (polar, others): (Vec<_>, Vec<_>) = tissue
        .terms()
        .observables(&ids)
        .into_iter()
        .partition(|(name, _)| *name == "polar_order");
    (
        demix,
        boundary,
        polar.first().map_or(f64::NAN, |o| o.1),
        others,
    )
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
