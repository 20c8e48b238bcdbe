//! Lattice slices as colour maps with a colour bar, optionally with arrows of a vector field.

use std::path::Path;

use plotters::prelude::*;

use crate::plot::tick;
use crate::{font, RenderError, FONT};

/// A square slice of a field around a point, `side × side`, indexed `[u * side + v]`, drawn
/// with `u` to the right and `v` up, centred on the middle node.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Heatmap {
    /// The panel's title.
    pub title: String,
    /// Nodes per side.
    pub side: usize,
    /// The values, `side²`; non-finite ones are drawn grey.
    pub values: Vec<f64>,
    /// Arrows of a vector field `(a_u, a_v)`, each `side²`, drawn every `arrow_every` nodes.
    pub arrows: Option<(Vec<f64>, Vec<f64>)>,
    /// Director lines (headless segments) of a nematic field given as `(Q_xx, Q_xy)`: at
    /// angle `½ atan2(Q_xy, Q_xx)`, length ∝ `|Q|`.
    pub director: Option<(Vec<f64>, Vec<f64>)>,
    /// Nodes between arrows.
    pub arrow_every: usize,
    /// The names of the horizontal (`u`) and vertical (`v`) axes; empty draws none.
    pub axes: (String, String),
}

impl Heatmap {
    /// A panel of `values` (`side²`, indexed `[u * side + v]`).
    pub fn new(title: impl Into<String>, side: usize, values: Vec<f64>) -> Self {
        Self {
            title: title.into(),
            side,
            values,
            arrows: None,
            director: None,
            arrow_every: (side / 12).max(1),
            axes: (String::new(), String::new()),
        }
    }

    /// With names on the horizontal (`u`) and vertical (`v`) axes.
    pub fn with_axes(mut self, u: impl Into<String>, v: impl Into<String>) -> Self {
        self.axes = (u.into(), v.into());
        self
    }

    /// With arrows of the vector field `(a_u, a_v)` over the colours.
    pub fn with_arrows(mut self, au: Vec<f64>, av: Vec<f64>) -> Self {
        self.arrows = Some((au, av));
        self
    }

    /// With director lines of the nematic field `(Q_xx, Q_xy)` over the colours.
    pub fn with_director(mut self, qxx: Vec<f64>, qxy: Vec<f64>) -> Self {
        self.director = Some((qxx, qxy));
        self
    }

    fn check(&self) -> Result<(), String> {
        let n = self.side * self.side;
        if self.side == 0 || self.values.len() != n {
            return Err(format!(
                "panel \"{}\" has {} values for a side of {}",
                self.title,
                self.values.len(),
                self.side
            ));
        }
        if let Some((a, b)) = self.arrows.as_ref().or(self.director.as_ref()) {
            if a.len() != n || b.len() != n {
                return Err(format!(
                    "panel \"{}\": arrows of the wrong size",
                    self.title
                ));
            }
        }
        Ok(())
    }
}

/// Blue (negative) through white (0) to red (positive), for `t` in [−1, 1]: the map of
/// [`crate::raster`], as a plotters colour.
fn diverging(t: f64) -> RGBColor {
    let [r, g, b] = crate::raster::diverging(t);
    RGBColor(r, g, b)
}

/// Draws `panels` into one PNG at `path`, `cols` to a row, each `panel_px` pixels wide, with
/// a `title` over all. Each panel has its own symmetric colour scale, `±max |value|`, and a
/// colour bar.
///
/// # Errors
/// [`RenderError::Data`] for a panel whose sizes do not match, [`RenderError::Draw`] when the
/// file cannot be written.
pub fn save_heatmaps(
    path: &Path,
    title: &str,
    panels: &[Heatmap],
    cols: usize,
    panel_px: u32,
) -> Result<(), RenderError> {
    let data = |why: String| RenderError::Data {
        path: path.to_path_buf(),
        why,
    };
    let draw = |why: String| RenderError::Draw {
        path: path.to_path_buf(),
        why,
    };
    if panels.is_empty() {
        return Err(data("no panel to draw".into()));
    }
    for p in panels {
        p.check().map_err(data)?;
    }
    font().map_err(draw)?;
    let cols = cols.clamp(1, panels.len());
    let rows = panels.len().div_ceil(cols);
    let bar = 84;
    let (w, h) = (cols as u32 * (panel_px + bar), rows as u32 * panel_px + 40);
    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| draw(e.to_string());
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, (FONT, 24)).map_err(e)?;
    let cells = root.split_evenly((rows, cols));
    for (panel, area) in panels.iter().zip(cells.iter()) {
        let (main, side_bar) = area.split_horizontally(panel_px);
        draw_panel(panel, &main, &side_bar).map_err(draw)?;
    }
    root.present().map_err(|e| draw(e.to_string()))
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

fn draw_panel(p: &Heatmap, main: &Area<'_>, bar: &Area<'_>) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let half = (p.side / 2) as f64;
    let scale = p
        .values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = if scale > 0.0 { scale } else { 1.0 };
    let mut chart = ChartBuilder::on(main)
        .caption(&p.title, (FONT, 18))
        .margin(6)
        .x_label_area_size(if p.axes.0.is_empty() { 28 } else { 46 })
        .y_label_area_size(if p.axes.1.is_empty() { 36 } else { 54 })
        .build_cartesian_2d(-half - 0.5..half + 0.5, -half - 0.5..half + 0.5)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(&p.axes.0)
        .y_desc(&p.axes.1)
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 12))
        .x_labels(5)
        .y_labels(5)
        .draw()
        .map_err(e)?;
    let s = p.side;
    chart
        .draw_series((0..s * s).map(|k| {
            let (u, v) = ((k / s) as f64 - half, (k % s) as f64 - half);
            let val = p.values[k];
            let c = if val.is_finite() {
                diverging(val / scale)
            } else {
                RGBColor(160, 160, 160)
            };
            Rectangle::new([(u - 0.5, v - 0.5), (u + 0.5, v + 0.5)], c.filled())
        }))
        .map_err(e)?;
    if let Some((au, av)) = &p.arrows {
        let every = p.arrow_every.max(1);
        let amax = crate::largest_norm(au, av);
        if amax > 0.0 {
            let len = 0.9 * every as f64 / amax;
            let centre = s / 2;
            let mut lines = Vec::new();
            for iu in (centre % every..s).step_by(every) {
                for iv in (centre % every..s).step_by(every) {
                    let k = iu * s + iv;
                    let (a, b) = (au[k] * len, av[k] * len);
                    if !(a.is_finite() && b.is_finite()) || a.hypot(b) < 1e-3 {
                        continue;
                    }
                    let (x, y) = (iu as f64 - half, iv as f64 - half);
                    let (tx, ty) = (x + a, y + b);
                    let (hx, hy) = (-a * 0.3, -b * 0.3);
                    let rot = |c: f64, s: f64| (tx + c * hx - s * hy, ty + s * hx + c * hy);
                    let (c, sn) = (0.45f64.cos(), 0.45f64.sin());
                    lines.push(vec![(x, y), (tx, ty)]);
                    lines.push(vec![rot(c, sn), (tx, ty), rot(c, -sn)]);
                }
            }
            chart
                .draw_series(
                    lines
                        .into_iter()
                        .map(|l| PathElement::new(l, BLACK.stroke_width(1))),
                )
                .map_err(e)?;
        }
    }
    if let Some((qxx, qxy)) = &p.director {
        let every = p.arrow_every.max(1);
        let qmax = crate::largest_norm(qxx, qxy);
        if qmax > 0.0 {
            let centre = s / 2;
            let mut lines = Vec::new();
            for iu in (centre % every..s).step_by(every) {
                for iv in (centre % every..s).step_by(every) {
                    let k = iu * s + iv;
                    let m = qxx[k].hypot(qxy[k]);
                    if !m.is_finite() || m < 1e-3 * qmax {
                        continue;
                    }
                    let th = 0.5 * qxy[k].atan2(qxx[k]);
                    let half_len = 0.45 * every as f64 * m / qmax;
                    let (a, b) = (half_len * th.cos(), half_len * th.sin());
                    let (x, y) = (iu as f64 - half, iv as f64 - half);
                    lines.push(vec![(x - a, y - b), (x + a, y + b)]);
                }
            }
            chart
                .draw_series(
                    lines
                        .into_iter()
                        .map(|l| PathElement::new(l, BLACK.stroke_width(2))),
                )
                .map_err(e)?;
        }
    }
    // The colour bar.
    let mut cb = ChartBuilder::on(bar)
        .margin_top(34)
        .margin_bottom(34)
        .margin_right(40)
        .y_label_area_size(0)
        .right_y_label_area_size(38)
        .build_cartesian_2d(0.0..1.0, -scale..scale)
        .map_err(e)?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .label_style((FONT, 11))
        .y_labels(5)
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(e)?;
    let steps = 100;
    cb.draw_series((0..steps).map(|k| {
        let (a, b) = (
            -scale + 2.0 * scale * k as f64 / steps as f64,
            -scale + 2.0 * scale * (k + 1) as f64 / steps as f64,
        );
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            diverging((a + b) / (2.0 * scale)).filled(),
        )
    }))
    .map_err(e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::diverging;

    #[test]
    fn the_colour_map_is_white_at_zero_and_saturates_at_the_ends() {
        assert_eq!(diverging(0.0), plotters::style::RGBColor(247, 247, 247));
        assert_eq!(diverging(1.0), diverging(7.0));
        assert_eq!(diverging(-1.0), plotters::style::RGBColor(33, 102, 172));
    }
}
