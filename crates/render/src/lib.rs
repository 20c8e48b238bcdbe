//! # render
//!
//! Pictures drawn by monolayer itself, in pure Rust: no Python, no system library. Text uses
//! DejaVu Sans, bundled in the crate (`fonts/`, with its licence), so nothing needs
//! fontconfig.
//!
//! - [`TissuePicture`]: a tissue state, each cell's contour `φ_i = ½` filled by a quantity
//!   ([`Fill`]) on a colour bar, with on request the director, the ±½ defects, the flow and the
//!   deformation axes; → [`Picture`] → PNG, or one frame of a [`Movie`] (GIF, APNG, MP4);
//! - [`Plot`]: a line plot of [`Series`] with vertical error bars (the seed spread), axis
//!   labels, an optional logarithmic axis and a legend;
//! - [`Heatmap`]: a lattice slice (row `u`, column `v`) in a diverging colour map with a
//!   colour bar, optionally with arrows of a vector field, several to a picture
//!   ([`save_heatmaps`]).
//!
//! All draw from plain slices, so they serve measured fields as well as simulated ones. A
//! director field measured in an experiment, with its defects, and no cells:
//!
//! ```
//! use analysis::defects::detect;
//! use phasefield::Lattice;
//! use render::{LatticeVectors, TissuePicture};
//!
//! // A +1/2 defect at the centre of a 32 × 32 field: director angle θ = φ/2.
//! let (lx, ly) = (32, 32);
//! let (mut qxx, mut qxy) = (vec![0.0; lx * ly], vec![0.0; lx * ly]);
//! for x in 0..lx {
//!     for y in 0..ly {
//!         let phi = (y as f64 - 16.5).atan2(x as f64 - 16.5);
//!         (qxx[x * ly + y], qxy[x * ly + y]) = (phi.cos(), phi.sin());
//!     }
//! }
//! let mut p = TissuePicture::new(lx, ly, 256);
//! p.defects = detect(Lattice::new(lx, ly), &qxx, &qxy);
//! p.director = Some(LatticeVectors { a: qxx, b: qxy, every: 2 });
//! p.title = "measured director".into();
//! let dir = tempfile::tempdir()?;
//! p.draw()?.save_png(&dir.path().join("director.png"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A line plot:
//!
//! ```
//! use render::{Plot, Series};
//!
//! let dir = tempfile::tempdir()?;
//! let mut plot = Plot::new("v_rms against activity", "ζ", "v_rms");
//! plot.log_y = true;
//! plot.series.push(Series::new("γ = 0.01").with_points(
//!     &[0.0, 0.004, 0.008],
//!     &[1e-4, 3e-3, 9e-3],
//!     &[2e-5, 4e-4, 5e-4],
//! ));
//! plot.save_png(&dir.path().join("v_rms.png"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod heatmap;
mod movie;
mod plot;
mod raster;
mod tissue;

use std::path::PathBuf;
use std::sync::OnceLock;

pub use heatmap::{save_heatmaps, Heatmap};
pub use movie::{Movie, MovieKind};
pub use plot::{LegendAt, Plot, Series};
pub use raster::Picture;
pub use tissue::{
    category_colour, CellArrows, CellAxes, EventKind, EventMark, Fill, LatticeVectors, Patches,
    TissuePicture, MINUS, PLUS,
};

/// What stops a picture from being drawn, naming the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The picture could not be drawn or written.
    #[error("cannot draw {}: {why}", path.display())]
    Draw {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        why: String,
    },
    /// The data cannot be drawn.
    #[error("cannot draw {}: {why}", path.display())]
    Data {
        /// The file.
        path: PathBuf,
        /// What is wrong with the data.
        why: String,
    },
}

/// The font family every picture uses.
const FONT: &str = "sans-serif";

/// Registers the bundled font with plotters, once.
fn font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        let bytes: &'static [u8] = include_bytes!("../fonts/DejaVuSans.ttf");
        plotters::style::register_font(FONT, plotters::style::FontStyle::Normal, bytes)
            .map_err(|_| "the bundled font does not load".to_string())
    })
    .clone()
}

/// The colours of successive series (Tableau 10, as matplotlib's default cycle).
pub(crate) const PALETTE: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// The largest finite length `(a_k² + b_k²)^½` of a two-component field (0 when none is
/// finite): what arrows and director marks are scaled to.
pub(crate) fn largest_norm(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| a.hypot(*b))
        .filter(|m| m.is_finite())
        .fold(0.0f64, f64::max)
}
