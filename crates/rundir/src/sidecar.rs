//! `run.json`: what a run directory's tables and frames mean, for a reader without this
//! crate: the version that wrote it, the precision, the lattice, the axes, and the unit of
//! every column. The CSVs stay plain tables (one header line, no comments).

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use crate::frame::FRAME_FORMAT;
use crate::series::SERIES_HEADER;
use crate::{Result, RunDirError};

/// The axes and angle conventions of every file.
pub const AXES: &str = "x is the first lattice index, y the second, right-handed; angles in radians counterclockwise from +x; a +1/2 defect's angle is the direction of div Q, a -1/2 defect's one of its three arms (modulo 2pi/3)";

/// The contents of `run.json`.
#[derive(Debug, Clone, Serialize)]
struct RunJson {
    monolayer_version: &'static str,
    frame_format: i64,
    scene: &'static str,
    precision: &'static str,
    lattice: [usize; 2],
    cells: usize,
    axes: &'static str,
    units: BTreeMap<&'static str, &'static str>,
    columns: BTreeMap<&'static str, BTreeMap<&'static str, &'static str>>,
    /// The per-cell arrays a frame has beyond the minimal model's, with their meaning.
    frame_arrays: BTreeMap<String, String>,
    /// The populations by index (the frame's `population` array), with their counts.
    populations: Vec<(String, usize)>,
}

/// The unit of a column of `series.csv` or of the analysis tables.
fn unit(column: &str) -> &'static str {
    match column {
        "step" | "frame" => "time steps",
        "time" => "TU",
        "zeta" => "force/length (model units)",
        "v_rms" | "v_rms_smooth" | "cell_speed_rms" | "v_mean_x" | "v_mean_y" | "v_shear_x" => {
            "nodes/TU"
        }
        "area_mean" | "area_min" | "area_max" => "nodes² (Σ φ²)",
        "x" | "y" | "r" | "length" => "nodes",
        "lag" => "TU",
        "msd" | "msd_raw" => "nodes²",
        "angle" => "radians",
        "defect_density" => "defects per node",
        "cells" | "divisions" | "extrusions" | "deaths" => "cells",
        "creation_rate" => "pair creations per node per TU",
        _ => "dimensionless",
    }
}

/// The frame arrays of the scene's extensions ([`mechanics::Extensions::frame_arrays`]), with
/// their meaning.
fn frame_arrays(scene: &scene::Scene) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    let terms = scene.terms();
    if !terms.is_empty() {
        m.insert(
            "cell_force".into(),
            "(N, 2): the physics terms' whole-cell force on each cell (force units), beside the interface force 'force'".into(),
        );
    }
    if scene.file().run.forces_by_origin {
        let ext = scene.configured_extensions();
        for name in ext.force_origins(&scene.model_params(scene.zeta()), true) {
            let meaning = mechanics::ForcesByOrigin::meaning(&name);
            m.insert(
                format!("force.{name}"),
                format!("(N, 2): {meaning}; the parts add up to force + cell_force, and with [friction] (its part included) to the drag times the velocity"),
            );
        }
    }
    for array in scene.configured_extensions().frame_arrays() {
        let shape = if array.columns == 1 {
            "(N,)".to_string()
        } else {
            format!("(N, {})", array.columns)
        };
        let dtype = if array.integer { " int64" } else { "" };
        m.insert(array.name, format!("{shape}{dtype}: {}", array.meaning));
    }
    m
}

/// Writes `dir/run.json` for a run of `scene`.
///
/// # Errors
/// When the file cannot be written.
pub fn write_run_json(dir: &Path, scene: &scene::Scene) -> Result<()> {
    let table = |header: &'static str| -> BTreeMap<&'static str, &'static str> {
        header.split(',').map(|c| (c, unit(c))).collect()
    };
    let lattice = scene.lattice();
    let json = RunJson {
        monolayer_version: env!("CARGO_PKG_VERSION"),
        frame_format: FRAME_FORMAT,
        scene: "scene.toml",
        precision: match scene.precision() {
            mechanics::Precision::F64 => "f64",
            _ => "f32",
        },
        lattice: [lattice.lx, lattice.ly],
        cells: scene.file().cells.count,
        axes: AXES,
        units: [
            ("length", "lattice nodes"),
            ("time", "model time units (TU)"),
            ("phi", "dimensionless, 0 outside a cell and 1 inside"),
        ]
        .into_iter()
        .collect(),
        columns: [
            ("series.csv", table(SERIES_HEADER)),
            ("analysis/observables.csv", table(crate::OBSERVABLES_HEADER)),
            (
                "analysis/defects.csv",
                table("frame,time,x,y,charge,angle,track"),
            ),
            ("analysis/defect_events.csv", table("frame,time,kind,x,y")),
            (
                "analysis/correlations.csv",
                table("r,c_velocity,c_vorticity,c_q"),
            ),
            ("analysis/lengths.csv", table("field,length")),
        ]
        .into_iter()
        .collect(),
        frame_arrays: frame_arrays(scene),
        populations: scene
            .file()
            .population
            .iter()
            .enumerate()
            .map(|(k, p)| (p.name(k), p.count))
            .collect(),
    };
    let path = dir.join("run.json");
    let text = serde_json::to_string_pretty(&json).expect("run.json always serialises");
    std::fs::write(&path, text + "\n").map_err(|e| RunDirError::io("write", &path, e))
}
