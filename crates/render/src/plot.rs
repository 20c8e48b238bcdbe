//! Line plots with error bars and a legend.

use std::path::Path;

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::{font, RenderError, FONT, PALETTE};

/// One curve: points `(x, y)` with a vertical error bar of half-width `err` (0: none).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Its legend entry (empty: none).
    pub label: String,
    /// The points, drawn in this order; non-finite ones are left out.
    pub points: Vec<(f64, f64, f64)>,
    /// Join the points with a line (default) or only mark them.
    pub line: bool,
    /// Mark each point with a dot (default).
    pub markers: bool,
}

impl Series {
    /// An empty series with a legend entry, drawn as a line with markers.
    pub fn new(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            points: Vec::new(),
            line: true,
            markers: true,
        }
    }

    /// With the points `x`, `y` and error bars `err` (the shortest length of the three).
    pub fn with_points(mut self, x: &[f64], y: &[f64], err: &[f64]) -> Self {
        self.points = x
            .iter()
            .zip(y)
            .zip(err)
            .map(|((&x, &y), &e)| (x, y, e))
            .collect();
        self
    }

    /// Only markers, no line.
    pub fn markers_only(mut self) -> Self {
        self.line = false;
        self.markers = true;
        self
    }

    /// Only a line, no markers (for dense series such as time series).
    pub fn line_only(mut self) -> Self {
        self.line = true;
        self.markers = false;
        self
    }
}

/// A line plot: series, axis labels, a title and a legend.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Plot {
    /// The title.
    pub title: String,
    /// The x-axis label.
    pub x_label: String,
    /// The y-axis label.
    pub y_label: String,
    /// Logarithmic x axis (non-positive values are left out).
    pub log_x: bool,
    /// Logarithmic y axis (non-positive values are left out).
    pub log_y: bool,
    /// A linear x axis that reaches 0 (for a claim about an intercept or proportionality).
    pub zero_x: bool,
    /// A linear y axis that reaches 0.
    pub zero_y: bool,
    /// The curves.
    pub series: Vec<Series>,
    /// Horizontal reference lines `(y, label)`, drawn dashed.
    pub hlines: Vec<(f64, String)>,
    /// Size in pixels.
    pub size: (u32, u32),
    /// Where the legend goes.
    pub legend: LegendAt,
}

/// A corner of the plot for the legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendAt {
    /// Upper left (the default).
    #[default]
    UpperLeft,
    /// Upper right.
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
}

impl Plot {
    /// An empty plot, 800 × 560 pixels, linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
            zero_x: false,
            zero_y: false,
            series: Vec::new(),
            hlines: Vec::new(),
            size: (800, 560),
            legend: LegendAt::UpperLeft,
        }
    }

    /// The points of every series that can be drawn on these axes.
    fn drawable(&self) -> Vec<Vec<(f64, f64, f64)>> {
        let ok = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
        self.series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .copied()
                    .filter(|&(x, y, _)| ok(x, self.log_x) && ok(y, self.log_y))
                    .map(|(x, y, e)| (x, y, if e.is_finite() { e.abs() } else { 0.0 }))
                    .collect()
            })
            .collect()
    }

    /// Draws the plot into a PNG at `path`.
    ///
    /// # Errors
    /// [`RenderError::Data`] when no series has a drawable point, [`RenderError::Draw`] when
    /// the file cannot be written.
    pub fn save_png(&self, path: &Path) -> Result<(), RenderError> {
        let draw = |why: String| RenderError::Draw {
            path: path.to_path_buf(),
            why,
        };
        font().map_err(draw)?;
        let pts = self.drawable();
        let all: Vec<(f64, f64, f64)> = pts.iter().flatten().copied().collect();
        if all.is_empty() {
            return Err(RenderError::Data {
                path: path.to_path_buf(),
                why: format!("\"{}\" has no finite point to draw", self.title),
            });
        }
        let mut xs: Vec<f64> = all.iter().map(|p| p.0).collect();
        let mut ys: Vec<f64> = all.iter().flat_map(|p| [p.1 - p.2, p.1 + p.2]).collect();
        if self.zero_x && !self.log_x {
            xs.push(0.0);
        }
        if self.zero_y && !self.log_y {
            ys.push(0.0);
        }
        ys.extend(self.hlines.iter().map(|h| h.0).filter(|v| v.is_finite()));
        if self.log_y {
            let floor = all.iter().map(|p| p.1).fold(f64::INFINITY, f64::min) * 0.5;
            ys.retain(|&y| y >= floor);
        }
        let xr = range(&xs, self.log_x);
        let yr = range(&ys, self.log_y);
        let root = BitMapBackend::new(path, self.size).into_drawing_area();
        let result = match (self.log_x, self.log_y) {
            (false, false) => self.draw_on(&root, &pts, lin(xr), lin(yr)),
            (true, false) => self.draw_on(&root, &pts, (xr.0..xr.1).log_scale(), lin(yr)),
            (false, true) => self.draw_on(&root, &pts, lin(xr), (yr.0..yr.1).log_scale()),
            (true, true) => self.draw_on(
                &root,
                &pts,
                (xr.0..xr.1).log_scale(),
                (yr.0..yr.1).log_scale(),
            ),
        };
        result.map_err(draw)?;
        root.present().map_err(|e| draw(e.to_string()))
    }

    fn draw_on<X, Y>(
        &self,
        root: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
        pts: &[Vec<(f64, f64, f64)>],
        x: X,
        y: Y,
    ) -> Result<(), String>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let e = |e: DrawingAreaErrorKind<_>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(78)
            .build_cartesian_2d(x, y)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 18))
            .light_line_style(RGBColor(235, 235, 235))
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(e)?;
        let (x0, x1) = {
            let r = chart.x_range();
            (r.start, r.end)
        };
        for (k, (value, label)) in self.hlines.iter().enumerate() {
            let grey = RGBColor(90, 90, 90);
            let line = DashedLineSeries::new([(x0, *value), (x1, *value)], 6, 4, grey.into());
            let s = chart.draw_series(line).map_err(e)?;
            if !label.is_empty() {
                s.label(label.clone())
                    .legend(move |(px, py)| PathElement::new(vec![(px, py), (px + 20, py)], grey));
            }
            let _ = k;
        }
        let mut legend = false;
        for (k, (series, p)) in self.series.iter().zip(pts).enumerate() {
            let (r, g, b) = PALETTE[k % PALETTE.len()];
            let colour = RGBColor(r, g, b);
            if p.is_empty() {
                continue;
            }
            chart
                .draw_series(p.iter().filter(|q| q.2 > 0.0).map(|&(x, y, err)| {
                    ErrorBar::new_vertical(x, y - err, y, y + err, colour.stroke_width(1), 8)
                }))
                .map_err(e)?;
            if series.line {
                chart
                    .draw_series(LineSeries::new(
                        p.iter().map(|q| (q.0, q.1)),
                        colour.stroke_width(2),
                    ))
                    .map_err(e)?;
            }
            let radius = if series.markers { 4 } else { 0 };
            let marks = chart
                .draw_series(
                    p.iter()
                        .map(|q| Circle::new((q.0, q.1), radius, colour.filled())),
                )
                .map_err(e)?;
            if !series.label.is_empty() {
                legend = true;
                marks.label(series.label.clone()).legend(move |(px, py)| {
                    EmptyElement::at((px + 10, py))
                        + PathElement::new(vec![(-10, 0), (10, 0)], colour.stroke_width(2))
                        + Circle::new((0, 0), radius, colour.filled())
                });
            }
        }
        if legend || self.hlines.iter().any(|h| !h.1.is_empty()) {
            chart
                .configure_series_labels()
                .position(match self.legend {
                    LegendAt::UpperLeft => SeriesLabelPosition::UpperLeft,
                    LegendAt::UpperRight => SeriesLabelPosition::UpperRight,
                    LegendAt::LowerLeft => SeriesLabelPosition::LowerLeft,
                    LegendAt::LowerRight => SeriesLabelPosition::LowerRight,
                })
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font((FONT, 15))
                .draw()
                .map_err(e)?;
        }
        Ok(())
    }
}

fn lin(r: (f64, f64)) -> RangedCoordf64 {
    (r.0..r.1).into()
}

/// A range holding `v` with a margin of 5 % (a factor on a log axis); a single value gets a
/// unit-wide range.
fn range(v: &[f64], log: bool) -> (f64, f64) {
    let (lo, hi) = v
        .iter()
        .copied()
        .filter(|x| x.is_finite() && (!log || *x > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = ((h - l) * 0.05).max(0.05);
        let (a, b) = ((l - pad).floor(), (h + pad).ceil());
        // Data within two decades: the axis runs between whole decades, so that it carries at
        // least two labelled ticks (a log axis labels powers of ten; one that spans less than a
        // decade can show a single label, as the threshold figure's v_rms axis did).
        if b - a <= 2.0 {
            (10f64.powf(a), 10f64.powf(b))
        } else {
            (10f64.powf(l - pad), 10f64.powf(h + pad))
        }
    } else if hi == lo {
        let w = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        (lo - w, hi + w)
    } else {
        let pad = (hi - lo) * 0.05;
        (lo - pad, hi + pad)
    }
}

/// A tick label: plain for moderate magnitudes, scientific otherwise.
pub(crate) fn tick(v: f64) -> String {
    let a = v.abs();
    // Round-off residue of a tick meant to be 0.
    if a < 1e-15 {
        "0".into()
    } else if (1e-3..1e4).contains(&a) {
        // Three significant digits, trailing zeros dropped.
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.digits$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            &s
        };
        s.to_string()
    } else {
        format!("{v:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_hold_the_data_with_a_margin() {
        assert_eq!(range(&[0.0, 10.0], false), (-0.5, 10.5));
        let (lo, hi) = range(&[1e-3, 1e-1], true);
        assert!((lo.log10() + 3.1).abs() < 1e-12 && (hi.log10() + 0.9).abs() < 1e-12);
        assert_eq!(range(&[2.0], false), (1.8, 2.2));
        // Within two decades: whole decades, so at least two labelled ticks.
        let (lo, hi) = range(&[2e-3, 5e-2], true);
        assert!((lo.log10() + 3.0).abs() < 1e-12 && (hi.log10() + 1.0).abs() < 1e-12);
        let (lo, hi) = range(&[0.0021, 0.0027], true);
        assert!((lo.log10() + 3.0).abs() < 1e-12 && (hi.log10() + 2.0).abs() < 1e-12);
        assert_eq!(tick(0.0050), "0.005");
        assert_eq!(tick(0.00115), "0.00115");
        assert_eq!(tick(20.0), "20");
        assert_eq!(tick(1.7e-18), "0");
        assert_eq!(tick(2.5e-4), "2.5e-4");
    }
}
