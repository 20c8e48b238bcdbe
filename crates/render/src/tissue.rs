//! Pictures of a tissue state: each cell's contour `φ_i = ½`, the cells filled by a
//! quantity with a colour bar, and on request the director, the ±½ defects, the flow and each
//! cell's principal deformation axis (the paper's Fig. 1b view).
//!
//! Everything is drawn from plain arrays: the patches as a frame stores them, per-cell values,
//! and lattice-sized slices (index `x * ly + y`) for the director and the flow. With no cells,
//! a [`TissuePicture`] draws a measured director or flow field alone.
//!
//! **Geometry.** x points right and y up, as in the analysis (right-handed, angles
//! counterclockwise from +x). Lattice node `(x, y)` sits at the point `(x, y)`; the picture
//! shows `[0, lx) × [0, ly)` at `size / lx` pixels per node. The lattice is periodic, and so
//! is the picture: cells, segments and marks that cross an edge come back on the other side.
//!
//! **Contours.** `φ_i` is interpolated bilinearly between nodes at every pixel. A pixel
//! belongs to the cell with the largest `φ_i` there if that exceeds ½, else to no cell; a
//! contour pixel is a cell's pixel with a neighbour (of four) that is not the cell's. So the
//! line between a cell and the background lies just inside `φ_i = ½`, and two touching
//! cells each draw their side of `φ_i = φ_j`.

use std::f64::consts::PI;

use analysis::defects::Defect;
use plotters::prelude::*;

use crate::plot::tick;
use crate::raster::{diverging, id_colour, viridis, Canvas, Clip, Picture};
use crate::{font, RenderError, FONT};

/// The cells' patches, laid out as a frame stores them: `phi[(i * nx + u) * ny + v]` is
/// `φ_i` at node `((origin_i,x + u) mod lx, (origin_i,y + v) mod ly)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Patches {
    /// Patch nodes along x.
    pub nx: usize,
    /// Patch nodes along y.
    pub ny: usize,
    /// The lattice node of each patch's element `[0, 0]`.
    pub origins: Vec<[usize; 2]>,
    /// The values, `N × nx × ny`.
    pub phi: Vec<f64>,
}

/// How the cells are filled.
#[derive(Debug, Clone, PartialEq)]
pub enum Fill {
    /// All cells light grey.
    Plain,
    /// Each cell its own colour (no colour bar).
    Id,
    /// Each cell the colour of its key (no colour bar): cells of one key share a colour, and
    /// a cell keeps its colour from picture to picture (keys: identities, or each cell's
    /// founder for a lineage).
    Keys(Vec<usize>),
    /// Each cell the colour of its category (a population, a generation), from a palette of
    /// distinct colours, with the categories' names in a legend right of the field.
    Categories {
        /// Each cell's category, an index into `names`.
        of_cell: Vec<usize>,
        /// The categories' names, for the legend.
        names: Vec<String>,
    },
    /// One value per cell, on a colour bar.
    Values {
        /// The values, one per cell.
        values: Vec<f64>,
        /// The colour bar's label.
        label: String,
        /// A diverging map, symmetric about 0 (for signed quantities such as the pressure);
        /// otherwise viridis.
        signed: bool,
    },
}

/// A cell event drawn on a picture: a division (a green ring), an extrusion (a black ×) or a
/// death (a grey ×), at the centre where the cell was.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventMark {
    /// Position along x.
    pub x: f64,
    /// Position along y.
    pub y: f64,
    /// What happened.
    pub kind: EventKind,
}

/// What an [`EventMark`] marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// A cell divided.
    Division,
    /// A cell was extruded.
    Extrusion,
    /// A cell died.
    Death,
}

/// A vector or director field on the lattice, drawn every `every` nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct LatticeVectors {
    /// First component, lattice-sized (index `x * ly + y`).
    pub a: Vec<f64>,
    /// Second component.
    pub b: Vec<f64>,
    /// Nodes between marks along each axis.
    pub every: usize,
}

/// Each cell's principal deformation axis: a segment through its centre along
/// `θ = ½ atan2(S_xy, S_xx)`, with a length proportional to `|S| = (S_xx² + S_xy²)^½`.
#[derive(Debug, Clone, PartialEq)]
pub struct CellAxes {
    /// The centres `[x, y]`.
    pub centres: Vec<[f64; 2]>,
    /// The shape tensors `[S_xx, S_xy]`.
    pub shapes: Vec<[f64; 2]>,
}

/// Each cell's polarity `p_i` (docs/model.md §11.1): an arrow from its centre, a cell radius
/// long.
#[derive(Debug, Clone, PartialEq)]
pub struct CellArrows {
    /// The centres `[x, y]`.
    pub centres: Vec<[f64; 2]>,
    /// The unit vectors `[p_x, p_y]`.
    pub directions: Vec<[f64; 2]>,
}

/// A picture of a tissue state; [`TissuePicture::draw`] makes it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TissuePicture {
    /// Lattice side along x.
    pub lx: usize,
    /// Lattice side along y.
    pub ly: usize,
    /// The cells (may be empty).
    pub patches: Patches,
    /// How the cells are filled.
    pub fill: Fill,
    /// The colour bar's range; `None`: the values' own (`±max |v|` when signed).
    pub range: Option<(f64, f64)>,
    /// The nematic tensor `(Q_xx, Q_xy)`, drawn as director segments `θ = ½ atan2(Q_xy, Q_xx)`.
    pub director: Option<LatticeVectors>,
    /// A velocity field `(v_x, v_y)`, drawn as arrows scaled to the largest.
    pub flow: Option<LatticeVectors>,
    /// Defects: a comet for +½ (dot at the core, tail along the orientation `ψ`, i.e.
    /// `∇·Q`, so the head is the dot's side opposite the tail), a three-armed mark for −½
    /// (arms at `ψ + 2πk/3`), a ring for any other charge.
    pub defects: Vec<Defect>,
    /// Cell events to mark (divisions, extrusions, deaths), at the cells' centres.
    pub events: Vec<EventMark>,
    /// Principal deformation axes, one per cell.
    pub axes: Option<CellAxes>,
    /// Polarities, one arrow per cell.
    pub polarity: Option<CellArrows>,
    /// The cells' own nematics `[q_xx, q_xy]` (docs/model.md §11.6), one headless segment per
    /// cell along its axis, its length in proportion to `|q|`.
    pub nematic: Option<CellAxes>,
    /// Each cell's track, its centres in time order (a jump of more than half the lattice is a
    /// crossing of the periodic boundary, not drawn).
    pub tracks: Option<Vec<Vec<[f64; 2]>>>,
    /// The size of marks (defects, the longest axis), in lattice units; about a cell radius.
    pub mark: f64,
    /// The title over the picture.
    pub title: String,
    /// The field's width in pixels (its height follows the lattice's aspect).
    pub size: u32,
    /// The wall field `w` (index `x * ly + y`; 1 on solid nodes), drawn in grey where no
    /// cell is.
    pub walls: Option<Vec<f64>>,
}

/// Colours of the overlays.
const CONTOUR: [u8; 3] = [40, 40, 40];
const EMPTY: [u8; 3] = [255, 255, 255];
const PLAIN: [u8; 3] = [222, 226, 232];
const DIRECTOR: [u8; 3] = [15, 15, 15];
const FLOW: [u8; 3] = [200, 0, 150];
/// Colour of +½ marks.
pub const PLUS: [u8; 3] = [230, 85, 13];
/// Colour of −½ marks.
pub const MINUS: [u8; 3] = [0, 90, 200];
const AXIS: [u8; 3] = [200, 20, 20];
const POLARITY: [u8; 3] = [10, 110, 40];
const NEMATIC: [u8; 3] = [110, 40, 170];
const TRACK: [u8; 3] = [60, 60, 160];
const WALL: [u8; 3] = [140, 140, 140];
const DIVISION: [u8; 3] = [20, 150, 60];

const TITLE_PX: u32 = 36;
const BAR_PX: u32 = 110;
const PAD_PX: u32 = 6;

impl TissuePicture {
    /// A picture of an `lx × ly` lattice with no cells and nothing on it, `size` pixels wide.
    pub fn new(lx: usize, ly: usize, size: u32) -> Self {
        Self {
            lx,
            ly,
            patches: Patches::default(),
            fill: Fill::Plain,
            range: None,
            director: None,
            flow: None,
            defects: Vec::new(),
            events: Vec::new(),
            axes: None,
            polarity: None,
            nematic: None,
            tracks: None,
            mark: 8.0,
            title: String::new(),
            size,
            walls: None,
        }
    }

    /// Pixels per lattice node.
    pub fn scale(&self) -> f64 {
        self.size as f64 / self.lx as f64
    }

    /// Where the lattice point `(x, y)` lands in the picture, in continuous pixel
    /// coordinates (pixel `(i, j)` covers `[i, i+1) × [j, j+1)`, rows from the top).
    pub fn to_pixel(&self, x: f64, y: f64) -> (f64, f64) {
        let s = self.scale();
        (
            PAD_PX as f64 + x * s,
            (TITLE_PX + self.field_height()) as f64 - y * s,
        )
    }

    fn field_height(&self) -> u32 {
        ((self.ly as f64 * self.scale()).round() as u32).max(1)
    }

    fn check(&self) -> Result<(), String> {
        let p = &self.patches;
        let n = p.origins.len();
        if self.lx == 0 || self.ly == 0 {
            return Err("the lattice is empty".into());
        }
        if !(1..=20_000).contains(&self.size) {
            return Err(format!(
                "a picture {} pixels wide; use a size from 1 to 20000",
                self.size
            ));
        }
        if n > 0 && (p.phi.len() != n * p.nx * p.ny || p.nx < 2 || p.ny < 2) {
            return Err(format!(
                "{} values of phi for {n} patches of {}×{}",
                p.phi.len(),
                p.nx,
                p.ny
            ));
        }
        if let Fill::Values { values, .. } = &self.fill {
            if values.len() != n {
                return Err(format!("{} fill values for {n} cells", values.len()));
            }
        }
        if let Fill::Categories { of_cell, names } = &self.fill {
            if of_cell.len() != n {
                return Err(format!("{} categories for {n} cells", of_cell.len()));
            }
            if let Some(&k) = of_cell.iter().find(|&&k| k >= names.len()) {
                return Err(format!(
                    "category {k} of a cell, but {} names in the legend",
                    names.len()
                ));
            }
        }
        let len = self.lx * self.ly;
        if let Some(w) = &self.walls {
            if w.len() != len {
                return Err(format!(
                    "the wall field has {} values for a {}×{} lattice",
                    w.len(),
                    self.lx,
                    self.ly
                ));
            }
        }
        for (name, f) in [("director", &self.director), ("flow", &self.flow)] {
            if let Some(f) = f {
                if f.a.len() != len || f.b.len() != len || f.every == 0 {
                    return Err(format!(
                        "the {name} field has {} values for a {}×{} lattice",
                        f.a.len(),
                        self.lx,
                        self.ly
                    ));
                }
            }
        }
        for a in [&self.axes, &self.nematic].into_iter().flatten() {
            if a.centres.len() != n || a.shapes.len() != n {
                return Err(format!("{} axes for {n} cells", a.centres.len()));
            }
        }
        Ok(())
    }

    /// The colour bar's range.
    fn bar_range(&self) -> Option<(f64, f64)> {
        let Fill::Values { values, signed, .. } = &self.fill else {
            return None;
        };
        let (lo, hi) = self.range.unwrap_or_else(|| {
            let fin = values.iter().copied().filter(|v| v.is_finite());
            if *signed {
                let m = fin.fold(0.0f64, |m, v| m.max(v.abs()));
                (-m, m)
            } else {
                fin.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(v), h.max(v))
                })
            }
        });
        if !(lo.is_finite() && hi.is_finite()) {
            Some((0.0, 1.0))
        } else if hi > lo {
            Some((lo, hi))
        } else {
            let w = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
            Some((lo - w, hi + w))
        }
    }

    fn colour_of(&self, t: f64, signed: bool) -> [u8; 3] {
        if signed {
            diverging(2.0 * t - 1.0)
        } else {
            viridis(t)
        }
    }

    /// Draws the picture.
    ///
    /// # Errors
    /// [`RenderError::Data`] (with the empty path) when the arrays do not fit the lattice.
    pub fn draw(&self) -> Result<Picture, RenderError> {
        let data = |why: String| RenderError::Data {
            path: Default::default(),
            why,
        };
        self.check().map_err(data)?;
        let (fw, fh) = (self.size, self.field_height());
        let bar = self.bar_range();
        let legend = matches!(self.fill, Fill::Categories { .. });
        let width = PAD_PX
            + fw
            + if bar.is_some() || legend {
                BAR_PX
            } else {
                PAD_PX
            };
        let height = TITLE_PX + fh + PAD_PX;
        let mut pic = Picture::filled(width, height, EMPTY);
        self.draw_cells(&mut pic, bar);
        let clip = Clip {
            x0: PAD_PX as i64,
            y0: TITLE_PX as i64,
            x1: (PAD_PX + fw) as i64,
            y1: (TITLE_PX + fh) as i64,
        };
        let mut canvas = Canvas {
            pic: &mut pic,
            clip,
        };
        self.draw_overlays(&mut canvas);
        self.draw_events(&mut canvas);
        if let Some(range) = bar {
            self.draw_bar_colours(&mut pic, range);
        }
        self.draw_legend_swatches(&mut pic);
        self.draw_text(&mut pic, bar)
            .map_err(|why| RenderError::Draw {
                path: Default::default(),
                why,
            })?;
        Ok(pic)
    }

    /// The cell raster: owner and fill of every field pixel, then the contours.
    fn draw_cells(&self, pic: &mut Picture, bar: Option<(f64, f64)>) {
        let (fw, fh) = (self.size as usize, self.field_height() as usize);
        let s = self.scale();
        // Lattice-pixel buffers, row qy = 0 at the bottom (y up).
        let mut best = vec![0.5f32; fw * fh];
        let mut owner = vec![-1i32; fw * fh];
        let p = &self.patches;
        let (nx, ny) = (p.nx, p.ny);
        // Pixel columns whose centres fall in [x, x+1).
        let span = |x: usize, n: usize| {
            let lo = ((x as f64 * s - 0.5).ceil().max(0.0) as usize).min(n);
            let hi = ((((x + 1) as f64) * s - 0.5).ceil().max(0.0) as usize).min(n);
            lo..hi
        };
        let cols: Vec<_> = (0..self.lx).map(|x| span(x, fw)).collect();
        let rows: Vec<_> = (0..self.ly).map(|y| span(y, fh)).collect();
        for (i, o) in p.origins.iter().enumerate() {
            let phi = &p.phi[i * nx * ny..(i + 1) * nx * ny];
            for u in 0..nx - 1 {
                let x = (o[0] + u) % self.lx;
                for v in 0..ny - 1 {
                    let k = u * ny + v;
                    let (f00, f01, f10, f11) = (phi[k], phi[k + 1], phi[k + ny], phi[k + ny + 1]);
                    if f00.max(f01).max(f10).max(f11) <= 0.5 {
                        continue;
                    }
                    let y = (o[1] + v) % self.ly;
                    for px in cols[x].clone() {
                        let tx = (px as f64 + 0.5) / s - x as f64;
                        let (a, b) = (f00 + tx * (f10 - f00), f01 + tx * (f11 - f01));
                        for qy in rows[y].clone() {
                            let ty = (qy as f64 + 0.5) / s - y as f64;
                            let val = (a + ty * (b - a)) as f32;
                            let j = qy * fw + px;
                            if val > best[j] {
                                best[j] = val;
                                owner[j] = i as i32;
                            }
                        }
                    }
                }
            }
        }
        let colours: Vec<[u8; 3]> = match (&self.fill, bar) {
            (Fill::Plain, _) => vec![PLAIN; p.origins.len()],
            (Fill::Id, _) => (0..p.origins.len()).map(id_colour).collect(),
            (Fill::Keys(keys), _) => keys.iter().map(|&k| id_colour(k)).collect(),
            (Fill::Categories { of_cell, .. }, _) => {
                of_cell.iter().map(|&k| category_colour(k)).collect()
            }
            (Fill::Values { values, signed, .. }, Some((lo, hi))) => values
                .iter()
                .map(|&v| self.colour_of((v - lo) / (hi - lo), *signed))
                .collect(),
            (Fill::Values { .. }, None) => unreachable!("values always have a range"),
        };
        for qy in 0..fh {
            let row = TITLE_PX as usize + fh - 1 - qy;
            for px in 0..fw {
                let j = qy * fw + px;
                let id = owner[j];
                let c = if id >= 0 {
                    let row_of = |q: usize| &owner[q * fw..(q + 1) * fw];
                    let (here, up, down) = (
                        row_of(qy),
                        row_of((qy + 1) % fh),
                        row_of((qy + fh - 1) % fh),
                    );
                    let edge = here[(px + 1) % fw] != id
                        || here[(px + fw - 1) % fw] != id
                        || up[px] != id
                        || down[px] != id;
                    if edge {
                        CONTOUR
                    } else {
                        colours[id as usize]
                    }
                } else if let Some(w) = &self.walls {
                    // The wall's grey, fading with its field outside the solid.
                    let x = (((px as f64 + 0.5) / s) as usize).min(self.lx - 1);
                    let y = (((qy as f64 + 0.5) / s) as usize).min(self.ly - 1);
                    let a = w[x * self.ly + y].clamp(0.0, 1.0);
                    std::array::from_fn(|c| {
                        (EMPTY[c] as f64 + a * (WALL[c] as f64 - EMPTY[c] as f64)).round() as u8
                    })
                } else {
                    EMPTY
                };
                let k = 3 * (row * pic.width as usize + PAD_PX as usize + px);
                pic.rgb[k..k + 3].copy_from_slice(&c);
            }
        }
    }

    /// Draws `f` at the lattice point `(x, y)` and at each periodic image whose marks can
    /// reach the field (`reach` lattice units around the point).
    fn periodic(
        &self,
        c: &mut Canvas<'_>,
        x: f64,
        y: f64,
        reach: f64,
        mut f: impl FnMut(&mut Canvas<'_>, (f64, f64), f64),
    ) {
        let s = self.scale();
        for dx in [-1.0, 0.0, 1.0] {
            for dy in [-1.0, 0.0, 1.0] {
                let (px, py) = self.to_pixel(x + dx * self.lx as f64, y + dy * self.ly as f64);
                if c.near(px, py, reach * s + 2.0) {
                    f(c, (px, py), s);
                }
            }
        }
    }

    fn draw_overlays(&self, c: &mut Canvas<'_>) {
        let s = self.scale();
        let line_w = (0.25 * s).clamp(1.0, 3.0);
        let sites = |every: usize| {
            let (lx, ly) = (self.lx, self.ly);
            (0..lx)
                .step_by(every)
                .flat_map(move |x| (0..ly).step_by(every).map(move |y| (x, y)))
        };
        if let Some(d) = &self.director {
            let half = 0.4 * d.every as f64;
            for (x, y) in sites(d.every) {
                let k = x * self.ly + y;
                let (qxx, qxy) = (d.a[k], d.b[k]);
                if !(qxx.is_finite() && qxy.is_finite()) || qxx == 0.0 && qxy == 0.0 {
                    continue;
                }
                let th = 0.5 * qxy.atan2(qxx);
                let (ex, ey) = (th.cos() * half * s, -th.sin() * half * s);
                self.periodic(c, x as f64, y as f64, half, |c, (px, py), _| {
                    c.line((px - ex, py - ey), (px + ex, py + ey), line_w, DIRECTOR)
                });
            }
        }
        if let Some(f) = &self.flow {
            let vmax = crate::largest_norm(&f.a, &f.b);
            if vmax > 0.0 {
                let len = 0.9 * f.every as f64 / vmax;
                for (x, y) in sites(f.every) {
                    let k = x * self.ly + y;
                    let (a, b) = (f.a[k] * len, f.b[k] * len);
                    if !(a.is_finite() && b.is_finite()) || a.hypot(b) < 0.05 * f.every as f64 {
                        continue;
                    }
                    self.periodic(c, x as f64, y as f64, f.every as f64, |c, p, s| {
                        arrow(c, p, (a * s, b * s), line_w, FLOW);
                    });
                }
            }
        }
        for (axes, colour) in [(&self.axes, AXIS), (&self.nematic, NEMATIC)] {
            let Some(CellAxes { centres, shapes }) = axes else {
                continue;
            };
            let smax = shapes
                .iter()
                .map(|s| s[0].hypot(s[1]))
                .filter(|m| m.is_finite())
                .fold(0.0f64, f64::max);
            if smax > 0.0 {
                for (ctr, sh) in centres.iter().zip(shapes) {
                    let m = sh[0].hypot(sh[1]);
                    if !(m.is_finite() && ctr[0].is_finite() && ctr[1].is_finite()) {
                        continue;
                    }
                    let th = 0.5 * sh[1].atan2(sh[0]);
                    let half = 0.9 * self.mark * m / smax;
                    let (ex, ey) = (th.cos() * half * s, -th.sin() * half * s);
                    self.periodic(c, ctr[0], ctr[1], half, |c, (px, py), _| {
                        c.line((px - ex, py - ey), (px + ex, py + ey), 1.5 * line_w, colour);
                        c.disc(px, py, 1.2 * line_w, colour);
                    });
                }
            }
        }
        if let Some(tracks) = &self.tracks {
            let (hx, hy) = (0.5 * self.lx as f64, 0.5 * self.ly as f64);
            for track in tracks {
                for w in track.windows(2) {
                    let ([x0, y0], [x1, y1]) = (w[0], w[1]);
                    if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite())
                        || (x1 - x0).abs() > hx
                        || (y1 - y0).abs() > hy
                    {
                        continue;
                    }
                    let (a, b) = (self.to_pixel(x0, y0), self.to_pixel(x1, y1));
                    c.line(a, b, line_w, TRACK);
                }
            }
        }
        if let Some(CellArrows {
            centres,
            directions,
        }) = &self.polarity
        {
            let len = 0.9 * self.mark;
            for (ctr, p) in centres.iter().zip(directions) {
                if !(ctr.iter().chain(p).all(|v| v.is_finite())) {
                    continue;
                }
                let (a, b) = (p[0] * len, p[1] * len);
                self.periodic(c, ctr[0], ctr[1], len, |c, (px, py), s| {
                    arrow(c, (px, py), (a * s, b * s), 1.5 * line_w, POLARITY);
                    c.disc(px, py, 1.2 * line_w, POLARITY);
                });
            }
        }
        let r = (0.22 * self.mark * s).max(3.0);
        let w = (0.1 * self.mark * s).clamp(2.0, 5.0);
        for d in &self.defects {
            if !(d.x.is_finite() && d.y.is_finite()) {
                continue;
            }
            let ang = if d.angle.is_finite() { d.angle } else { 0.0 };
            let tail = 0.8 * self.mark * s;
            self.periodic(c, d.x, d.y, self.mark, |c, (px, py), _| {
                if d.charge == 0.5 {
                    let end = (px + ang.cos() * tail, py - ang.sin() * tail);
                    c.line((px, py), end, w, PLUS);
                    c.disc(px, py, r, PLUS);
                } else if d.charge == -0.5 {
                    for k in 0..3 {
                        let a = ang + 2.0 * PI * k as f64 / 3.0;
                        let end = (px + a.cos() * 0.75 * tail, py - a.sin() * 0.75 * tail);
                        c.line((px, py), end, w, MINUS);
                    }
                    c.disc(px, py, 0.6 * r, MINUS);
                } else {
                    for k in 0..24 {
                        let a = 2.0 * PI * k as f64 / 24.0;
                        c.disc(px + r * a.cos(), py + r * a.sin(), 0.4 * w, CONTOUR);
                    }
                }
            });
        }
    }

    /// The cell events: rings for divisions, crosses for extrusions and deaths.
    fn draw_events(&self, c: &mut Canvas<'_>) {
        let s = self.scale();
        let r = (0.45 * self.mark * s).max(5.0);
        let w = (0.12 * self.mark * s).clamp(2.0, 5.0);
        for e in &self.events {
            if !(e.x.is_finite() && e.y.is_finite()) {
                continue;
            }
            self.periodic(c, e.x, e.y, self.mark, |c, (px, py), _| match e.kind {
                EventKind::Division => {
                    for k in 0..32 {
                        let a = 2.0 * PI * k as f64 / 32.0;
                        c.disc(px + r * a.cos(), py + r * a.sin(), 0.5 * w, DIVISION);
                    }
                }
                EventKind::Extrusion | EventKind::Death => {
                    let col = if e.kind == EventKind::Extrusion {
                        [0, 0, 0]
                    } else {
                        [110, 110, 110]
                    };
                    let d = 0.75 * r;
                    c.line((px - d, py - d), (px + d, py + d), w, col);
                    c.line((px - d, py + d), (px + d, py - d), w, col);
                }
            });
        }
    }

    /// The colour bar's gradient, right of the field.
    fn draw_bar_colours(&self, pic: &mut Picture, (_lo, _hi): (f64, f64)) {
        let Fill::Values { signed, .. } = &self.fill else {
            return;
        };
        let (x0, x1) = (PAD_PX + self.size + 14, PAD_PX + self.size + 34);
        let (y0, y1) = (TITLE_PX + 10, TITLE_PX + self.field_height() - 10);
        for y in y0..y1 {
            let t = 1.0 - (y - y0) as f64 / (y1 - y0 - 1).max(1) as f64;
            let c = self.colour_of(t, *signed);
            for x in x0..x1 {
                let k = 3 * (y as usize * pic.width as usize + x as usize);
                pic.rgb[k..k + 3].copy_from_slice(&c);
            }
        }
    }

    /// The legend's colour swatches, one row per category, right of the field (as many as
    /// fit; [`LEGEND_ROW`] pixels apart).
    fn draw_legend_swatches(&self, pic: &mut Picture) {
        let Fill::Categories { names, .. } = &self.fill else {
            return;
        };
        let x0 = PAD_PX + self.size + 10;
        for k in 0..self.legend_rows(names.len()) {
            let y0 = TITLE_PX + 10 + LEGEND_ROW * k as u32;
            let c = category_colour(k);
            for y in y0..y0 + 12 {
                for x in x0..x0 + 12 {
                    let i = 3 * (y as usize * pic.width as usize + x as usize);
                    pic.rgb[i..i + 3].copy_from_slice(&c);
                }
            }
        }
    }

    /// How many of `n` categories the legend has room for.
    fn legend_rows(&self, n: usize) -> usize {
        n.min(((self.field_height().saturating_sub(20)) / LEGEND_ROW) as usize)
    }

    /// Title, colour-bar ticks and label, through plotters with the bundled font.
    fn draw_text(&self, pic: &mut Picture, bar: Option<(f64, f64)>) -> Result<(), String> {
        font()?;
        let (w, h) = (pic.width, pic.height);
        let root = BitMapBackend::with_buffer(&mut pic.rgb, (w, h)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| e.to_string();
        let title = TextStyle::from((FONT, 20).into_font()).color(&BLACK);
        root.draw_text(&self.title, &title, (PAD_PX as i32 + 4, 8))
            .map_err(e)?;
        if let (Some((lo, hi)), Fill::Values { label, .. }) = (bar, &self.fill) {
            let small = TextStyle::from((FONT, 13).into_font()).color(&BLACK);
            let x = (PAD_PX + self.size + 38) as i32;
            let (y0, y1) = (TITLE_PX + 10, TITLE_PX + self.field_height() - 10);
            for k in 0..5 {
                let t = k as f64 / 4.0;
                let y = y1 as f64 - 1.0 - t * (y1 - y0 - 1) as f64;
                root.draw_text(&tick(lo + t * (hi - lo)), &small, (x, y as i32 - 6))
                    .map_err(e)?;
            }
            root.draw_text(
                label,
                &small,
                ((PAD_PX + self.size + 8) as i32, TITLE_PX as i32 - 8),
            )
            .map_err(e)?;
        }
        if let Fill::Categories { names, .. } = &self.fill {
            let small = TextStyle::from((FONT, 13).into_font()).color(&BLACK);
            let x = (PAD_PX + self.size + 26) as i32;
            let rows = self.legend_rows(names.len());
            for (k, name) in names.iter().take(rows).enumerate() {
                let y = (TITLE_PX + 9 + LEGEND_ROW * k as u32) as i32;
                let text = if k + 1 == rows && rows < names.len() {
                    format!("… {} more", names.len() - k)
                } else {
                    name.clone()
                };
                root.draw_text(&text, &small, (x, y)).map_err(e)?;
            }
        }
        root.present().map_err(|e| e.to_string())
    }
}

/// Pixels between the rows of a legend.
const LEGEND_ROW: u32 = 18;

/// The colour of category `k`: Okabe and Ito's eight colours, distinct to readers with any
/// common colour-vision deficiency, repeated beyond eight.
pub fn category_colour(k: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [230, 159, 0],
        [86, 180, 233],
        [0, 158, 115],
        [240, 228, 66],
        [0, 114, 178],
        [213, 94, 0],
        [204, 121, 167],
        [153, 153, 153],
    ];
    PALETTE[k % PALETTE.len()]
}

/// An arrow from the pixel `from` along the lattice vector `(a, b)` in pixels (y up), with a
/// head of two strokes at ±0.45 rad, a third of the shaft long.
fn arrow(c: &mut Canvas<'_>, from: (f64, f64), (a, b): (f64, f64), width: f64, colour: [u8; 3]) {
    let tip = (from.0 + a, from.1 - b);
    c.line(from, tip, width, colour);
    let (hx, hy) = (-0.35 * a, 0.35 * b);
    for ang in [0.45f64, -0.45] {
        let (cs, sn) = (ang.cos(), ang.sin());
        let end = (tip.0 + cs * hx - sn * hy, tip.1 + sn * hx + cs * hy);
        c.line(tip, end, width, colour);
    }
}
