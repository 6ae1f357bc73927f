//! SVG figures with plotters: line charts (several series, axis labels with units, legend,
//! optional horizontal limit line) and scatter plots (root locus). Rendered into a string and
//! written atomically.

use std::path::Path;

use plotters::prelude::*;

use master::output::{write_bytes_atomic, OutputError};

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
}

/// A chart description.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    pub title: String,
    /// e.g. "time [s]"
    pub x_label: String,
    /// e.g. "lateral acceleration rms [m/s^2]"
    pub y_label: String,
    pub series: Vec<Series>,
    /// Horizontal line (value, label), e.g. the EN 14363 limit.
    pub limit: Option<(f64, String)>,
    pub width: u32,
    pub height: u32,
}

impl Chart {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            limit: None,
            width: 900,
            height: 560,
        }
    }
    pub fn with_series(mut self, name: &str, points: Vec<(f64, f64)>) -> Self {
        self.series.push(Series {
            name: name.into(),
            points,
        });
        self
    }
    pub fn with_limit(mut self, value: f64, label: &str) -> Self {
        self.limit = Some((value, label.into()));
        self
    }

    fn ranges(&self) -> Result<(Range, Range), PlotError> {
        let pts = self.series.iter().flat_map(|s| s.points.iter());
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
        if let Some((v, _)) = &self.limit {
            y0 = y0.min(*v);
            y1 = y1.max(*v);
        }
        let pad = |a: f64, b: f64| {
            let d = if b > a {
                (b - a) * 0.05
            } else {
                a.abs().max(1.0) * 0.05
            };
            (a - d, b + d)
        };
        let xr = if x1 > x0 { (x0, x1) } else { pad(x0, x1) };
        Ok((xr, pad(y0, y1)))
    }

    /// Renders to an SVG string; `scatter` draws points instead of lines.
    pub fn to_svg(&self, scatter: bool) -> Result<String, PlotError> {
        let ((x0, x1), (y0, y1)) = self.ranges()?;
        let draw = |e: &dyn std::fmt::Display| PlotError::Draw {
            title: self.title.clone(),
            reason: e.to_string(),
        };
        let mut svg = String::new();
        {
            let root =
                SVGBackend::with_string(&mut svg, (self.width, self.height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| draw(&e))?;
            let mut chart = ChartBuilder::on(&root)
                .caption(&self.title, ("sans-serif", 20))
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(70)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| draw(&e))?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .draw()
                .map_err(|e| draw(&e))?;
            for (i, s) in self.series.iter().enumerate() {
                let color = Palette99::pick(i).to_rgba();
                let pts = s
                    .points
                    .iter()
                    .copied()
                    .filter(|(x, y)| x.is_finite() && y.is_finite());
                if scatter {
                    chart
                        .draw_series(pts.map(|p| Circle::new(p, 3, color.filled())))
                        .map_err(|e| draw(&e))?
                        .label(&s.name)
                        .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
                } else {
                    chart
                        .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                        .map_err(|e| draw(&e))?
                        .label(&s.name)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                        });
                }
            }
            if let Some((v, label)) = &self.limit {
                let style = RED.stroke_width(1);
                chart
                    .draw_series(DashedLineSeries::new(vec![(x0, *v), (x1, *v)], 8, 5, style))
                    .map_err(|e| draw(&e))?
                    .label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(|e| draw(&e))?;
            root.present().map_err(|e| draw(&e))?;
        }
        Ok(svg)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_chart_has_labels_legend_and_limit() {
        let c = Chart::new("rms vs speed", "speed [km/h]", "rms [m/s^2]")
            .with_series("passive", vec![(200.0, 1.0), (300.0, 6.0)])
            .with_series("MPPT", vec![(200.0, 0.5), (300.0, 2.0)])
            .with_limit(5.39, "EN 14363 limit");
        let svg = c.to_svg(false).unwrap();
        for s in [
            "rms vs speed",
            "speed [km/h]",
            "passive",
            "MPPT",
            "EN 14363 limit",
            "<svg",
        ] {
            assert!(svg.contains(s), "missing {s}");
        }
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.svg");
        c.write_lines(&p).unwrap();
        assert!(
            std::fs::read_to_string(&p).unwrap().contains("polyline")
                || std::fs::read_to_string(&p).unwrap().contains("path")
        );
    }

    #[test]
    fn scatter_and_empty_data() {
        let c = Chart::new("root locus", "Re [1/s]", "Im [rad/s]")
            .with_series("poles", vec![(-1.0, 21.0), (0.2, 20.0)]);
        assert!(c.to_svg(true).unwrap().contains("circle"));
        let e = Chart::new("empty", "x", "y")
            .with_series("s", vec![(f64::NAN, 1.0)])
            .to_svg(false)
            .unwrap_err();
        assert!(e.to_string().contains("empty") && e.to_string().contains("no finite points"));
        // one single point still gets a valid range
        assert!(Chart::new("one", "x", "y")
            .with_series("s", vec![(1.0, 1.0)])
            .to_svg(false)
            .is_ok());
    }
}
