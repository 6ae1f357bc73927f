//! SVG figures with plotters: line charts (several series, axis labels with units, legend,
//! optional horizontal limit line), stacked panels sharing their axes, and scatter plots (root
//! locus). Rendered into a string and written atomically.
//!
//! Every legend sits in a column right of the plotting area, never over the data; a chart
//! whose series would crowd one frame is split into panels (one per run of a time history,
//! one per controller family of a speed sweep), each with the grey reference series and the
//! limit line drawn again for comparison.

mod frame;
#[cfg(test)]
mod tests;

use std::path::Path;

use plotters::prelude::*;

use master::output::{write_bytes_atomic, OutputError};

use frame::{
    axis_desc_px, cut, draw_frame, draw_shared_y_desc, panel_plot_px, svg_figure, title_height_px,
    Frame, FrameSpec, MAX_PANEL_CHARS, PANEL_FONT_PX,
};
pub(crate) use frame::{
    colour, draw_err, draw_legend, draw_lines, draw_rule, legend_width, longest, render_svg,
    tick_label, LegendEntry, Rule, Swatch,
};

#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("plot '{title}': {reason}")]
    Data { title: String, reason: String },
    #[error("plot '{title}': drawing failed: {reason}")]
    Draw { title: String, reason: String },
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// (min, max) of an axis.
type Range = (f64, f64);

/// One named series of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// Index into [`Chart::panels`] (0 without panels).
    pub panel: usize,
    /// Drawn in grey in every panel, under the others (e.g. the passive damper).
    pub reference: bool,
}

/// A chart description.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    pub title: String,
    /// e.g. "time \[s\]"
    pub x_label: String,
    /// e.g. "lateral acceleration rms [m/s^2]"
    pub y_label: String,
    pub series: Vec<Series>,
    /// Horizontal line (value, label), e.g. the EN 14363 limit; in every panel.
    pub limit: Option<(f64, String)>,
    /// Captions of the stacked panels, top to bottom; empty: one frame.
    pub panels: Vec<String>,
    /// Width of the plot without the legend column \[px\].
    pub width: u32,
    /// Height of a one-frame chart \[px\].
    pub height: u32,
    /// Height of each panel \[px\].
    pub panel_height: u32,
    /// Dots on the lines' points (a few measured points, e.g. the c_v table).
    pub markers: bool,
    /// Grey dotted horizontal lines (value, label), e.g. the bounds of comfort classes; in
    /// every panel.
    pub guides: Vec<(f64, String)>,
    /// The y axis reaches 0 (a quantity whose spread reads against its size, e.g. forces).
    pub y_from_zero: bool,
    /// Each panel scales its y axis to its own data (the x axis stays shared): runs whose
    /// amplitudes differ tenfold, which one scale would flatten.
    pub own_y_per_panel: bool,
}

impl Chart {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            limit: None,
            panels: Vec::new(),
            width: 900,
            height: 560,
            panel_height: 230,
            markers: false,
            guides: Vec::new(),
            y_from_zero: false,
            own_y_per_panel: false,
        }
    }
    /// Adds a series (to the first panel, if there are panels).
    pub fn with_series(mut self, name: &str, points: Vec<(f64, f64)>) -> Self {
        self.series.push(Series {
            name: name.into(),
            points,
            panel: 0,
            reference: false,
        });
        self
    }
    /// Adds a series drawn in grey in every panel.
    pub fn with_reference(mut self, name: &str, points: Vec<(f64, f64)>) -> Self {
        self.series.push(Series {
            name: name.into(),
            points,
            panel: 0,
            reference: true,
        });
        self
    }
    /// Adds a series to the panel with this caption, begun below the others if new.
    pub fn with_series_in(mut self, panel: &str, name: &str, points: Vec<(f64, f64)>) -> Self {
        let p = match self.panels.iter().position(|c| c == panel) {
            Some(p) => p,
            None => {
                self.panels.push(panel.into());
                self.panels.len() - 1
            }
        };
        self.series.push(Series {
            name: name.into(),
            points,
            panel: p,
            reference: false,
        });
        self
    }
    /// Puts each series in a panel of its own, captioned with its name (time histories of
    /// several runs, which overlap into one band in a single frame).
    pub fn one_panel_per_series(mut self) -> Self {
        self.panels.clear();
        for s in self.series.iter_mut().filter(|s| !s.reference) {
            s.panel = self.panels.len();
            self.panels.push(s.name.clone());
        }
        self
    }
    /// Marks each point of the lines with a dot.
    pub fn with_markers(mut self) -> Self {
        self.markers = true;
        self
    }
    pub fn with_limit(mut self, value: f64, label: &str) -> Self {
        self.limit = Some((value, label.into()));
        self
    }
    /// Adds a grey dotted horizontal line, listed in the legend.
    pub fn with_guide(mut self, value: f64, label: &str) -> Self {
        self.guides.push((value, label.into()));
        self
    }
    /// Makes the y axis reach 0.
    pub fn with_y_from_zero(mut self) -> Self {
        self.y_from_zero = true;
        self
    }
    /// Gives each panel a y axis of its own (see [`Chart::own_y_per_panel`]).
    pub fn with_own_y_per_panel(mut self) -> Self {
        self.own_y_per_panel = true;
        self
    }

    /// The series of panel `p`: the references first (drawn under the others).
    fn panel_series(&self, p: usize) -> Vec<&Series> {
        let refs = self.series.iter().filter(|s| s.reference);
        let own = self
            .series
            .iter()
            .filter(|s| !s.reference && (self.panels.is_empty() || s.panel == p));
        refs.chain(own).collect()
    }

    /// The name of panel `p`'s only own line when its caption is that name (one panel per
    /// series): the legend does not repeat it.
    fn captioned_line(&self, p: usize) -> Option<&str> {
        let caption = self.panels.get(p)?;
        let mut own = self.series.iter().filter(|s| !s.reference && s.panel == p);
        match (own.next(), own.next()) {
            (Some(only), None) if &only.name == caption => Some(caption),
            _ => None,
        }
    }

    /// What panel `p`'s legend lists: its lines (but one its caption names) and the limit.
    fn legend_names(&self, p: usize) -> Vec<&str> {
        let captioned = self.captioned_line(p);
        self.panel_series(p)
            .into_iter()
            .filter(|s| s.reference || captioned.is_none())
            .map(|s| s.name.as_str())
            .chain(self.limit.iter().map(|(_, l)| l.as_str()))
            .chain(self.guides.iter().map(|(_, l)| l.as_str()))
            .collect()
    }

    /// Whether panel `p` needs a legend (a single frame always has one).
    fn needs_legend(&self, p: usize) -> bool {
        self.panels.is_empty() || !self.legend_names(p).is_empty()
    }

    /// The legend column's width, the same for every panel so that their plotting areas
    /// align: enough for the longest entry; none when no panel needs a legend.
    pub(crate) fn legend_px(&self) -> u32 {
        if self.panels.is_empty() {
            let names = self.series.iter().map(|s| s.name.as_str());
            let lines = self.limit.iter().chain(&self.guides);
            return legend_width(longest(names.chain(lines.map(|(_, l)| l.as_str()))));
        }
        let names = (0..self.panels.len()).flat_map(|p| self.legend_names(p));
        legend_width(longest(names))
    }

    fn ranges(&self) -> Result<(Range, Range), PlotError> {
        self.ranges_of(self.series.iter())
    }

    /// The axes' ranges over `series`, the horizontal lines and, with
    /// [`Chart::y_from_zero`], 0.
    fn ranges_of<'a>(
        &self,
        series: impl Iterator<Item = &'a Series>,
    ) -> Result<(Range, Range), PlotError> {
        let pts = series.flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        let mut any = false;
        for &(x, y) in pts {
            if x.is_finite() && y.is_finite() {
                any = true;
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if !any {
            return Err(PlotError::Data {
                title: self.title.clone(),
                reason: "no finite points".into(),
            });
        }
        for (v, _) in self.limit.iter().chain(&self.guides) {
            y0 = y0.min(*v);
            y1 = y1.max(*v);
        }
        if self.y_from_zero {
            y0 = y0.min(0.0);
            y1 = y1.max(0.0);
        }
        let pad = |a: f64, b: f64| {
            let d = if b > a {
                (b - a) * 0.05
            } else {
                a.abs().max(1.0) * 0.05
            };
            (a - d, b + d)
        };
        // a dot on an end point needs room beside it
        let xr = if x1 > x0 && !self.markers {
            (x0, x1)
        } else {
            pad(x0, x1)
        };
        Ok((xr, pad(y0, y1)))
    }

    /// Renders to an SVG string; `scatter` draws points instead of lines. With panels, they
    /// are stacked under the title and share both axes' ranges, so that they compare (the y
    /// range only without [`Chart::own_y_per_panel`]).
    pub fn to_svg(&self, scatter: bool) -> Result<String, PlotError> {
        let ((x0, x1), (y0, y1)) = self.ranges()?;
        let t = self.title.as_str();
        let legend_px = self.legend_px();
        let finite = |(x, y): (f64, f64)| x.is_finite() && y.is_finite();
        let body = |p: usize, chart: &mut Frame<'_, '_, _, _>| {
            let series = self.panel_series(p);
            let mut entries = if scatter {
                let mut entries = Vec::with_capacity(series.len());
                for (i, s) in series.iter().enumerate() {
                    let color = colour(i);
                    let pts = s.points.iter().copied().filter(|&p| finite(p));
                    chart
                        .draw_series(pts.map(|p| Circle::new(p, 3, color.filled())))
                        .map_err(|e| draw_err(t, &e))?;
                    entries.push(LegendEntry::new(&s.name, Swatch::Dot(color, 3)));
                }
                entries
            } else {
                draw_lines(chart, t, &series, self.markers, finite)?
            };
            if let Some(captioned) = self.captioned_line(p) {
                entries.retain(|e| e.label != captioned);
            }
            if let Some((v, label)) = &self.limit {
                entries.push(draw_rule(chart, t, ((x0, x1), *v), Rule::Limit, label)?);
            }
            for (v, label) in &self.guides {
                entries.push(draw_rule(chart, t, ((x0, x1), *v), Rule::Guide, label)?);
            }
            Ok(entries)
        };
        if self.panels.is_empty() {
            let labels = (self.x_label.as_str(), self.y_label.as_str());
            let size = (self.width, self.height);
            return render_svg(t, size, labels, (x0..x1, y0..y1), legend_px, |c| body(0, c));
        }
        let n = self.panels.len();
        let width = self.width + legend_px;
        let height = title_height_px(t, width) + self.panel_height * n as u32;
        // a y description longer than one panel is tall is written once beside the stack
        let shared_y = axis_desc_px(&self.y_label) > panel_plot_px(self.panel_height);
        svg_figure(t, (width, height), |panels| {
            for (p, area) in panels.split_evenly((n, 1)).iter().enumerate() {
                let last = p + 1 == n;
                let caption = cut(&self.panels[p], MAX_PANEL_CHARS);
                let spec = FrameSpec {
                    caption: Some((caption.as_str(), PANEL_FONT_PX)),
                    labels: (
                        if last { self.x_label.as_str() } else { "" },
                        if shared_y { "" } else { self.y_label.as_str() },
                    ),
                    legend_px,
                    legend: self.needs_legend(p),
                };
                // a panel without a finite point keeps the shared range
                let (py0, py1) = match self.own_y_per_panel {
                    true => self
                        .ranges_of(self.panel_series(p).into_iter())
                        .map_or((y0, y1), |r| r.1),
                    false => (y0, y1),
                };
                draw_frame(area, t, &spec, (x0..x1, py0..py1), |c| body(p, c))?;
            }
            if shared_y {
                draw_shared_y_desc(panels, t, &self.y_label)?;
            }
            Ok(())
        })
    }

    /// Line chart to an SVG file (atomic).
    pub fn write_lines(&self, path: &Path) -> Result<(), PlotError> {
        let svg = self.to_svg(false)?;
        Ok(write_bytes_atomic(path, svg.as_bytes())?)
    }

    /// Scatter chart to an SVG file (atomic), e.g. a root locus (x = real part, y = imaginary).
    pub fn write_scatter(&self, path: &Path) -> Result<(), PlotError> {
        let svg = self.to_svg(true)?;
        Ok(write_bytes_atomic(path, svg.as_bytes())?)
    }
}
