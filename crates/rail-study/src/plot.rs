//! SVG figures with plotters: line charts (several series, axis labels with units, legend,
//! optional horizontal limit line) and scatter plots (root locus). Rendered into a string and
//! written atomically.

use std::path::Path;

use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
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

/// A drawing area with axes, as [`render_svg`] hands it to the chart's own drawing.
pub(crate) type Frame<'a, 'b, X, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>;

pub(crate) fn draw_err(title: &str, e: &dyn std::fmt::Display) -> PlotError {
    PlotError::Draw {
        title: title.to_string(),
        reason: e.to_string(),
    }
}

/// Renders what every chart shares (white background, caption, axes with their descriptions,
/// the legend box last, at its default place unless `legend`) into an SVG string; `body`
/// draws the data.
pub(crate) fn render_svg<XR, YR, F>(
    title: &str,
    size: (u32, u32),
    (x_label, y_label): (&str, &str),
    (xr, yr): (XR, YR),
    legend: Option<SeriesLabelPosition>,
    body: F,
) -> Result<String, PlotError>
where
    XR: AsRangedCoord<Value = f64>,
    YR: AsRangedCoord<Value = f64>,
    XR::CoordDescType: ValueFormatter<f64>,
    YR::CoordDescType: ValueFormatter<f64>,
    F: FnOnce(&mut Frame<'_, '_, XR::CoordDescType, YR::CoordDescType>) -> Result<(), PlotError>,
{
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(title, &e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xr, yr)
            .map_err(|e| draw_err(title, &e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| draw_err(title, &e))?;
        body(&mut chart)?;
        let mut labels = chart.configure_series_labels();
        if let Some(p) = legend {
            labels.position(p);
        }
        labels
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| draw_err(title, &e))?;
        root.present().map_err(|e| draw_err(title, &e))?;
    }
    Ok(svg)
}

/// Each series as a line in its palette colour with a legend entry; points failing `keep` are
/// left out.
pub(crate) fn draw_lines<X, Y>(
    chart: &mut Frame<'_, '_, X, Y>,
    title: &str,
    series: &[Series],
    keep: impl Fn((f64, f64)) -> bool,
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for (i, s) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|&p| keep(p)).collect();
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
            .map_err(|e| draw_err(title, &e))?
            .label(&s.name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    Ok(())
}

/// A dashed red horizontal line at `value` across `x_span`, with a legend entry.
pub(crate) fn draw_limit<X, Y>(
    chart: &mut Frame<'_, '_, X, Y>,
    title: &str,
    x_span: (f64, f64),
    value: f64,
    label: &str,
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let style = RED.stroke_width(1);
    chart
        .draw_series(DashedLineSeries::new(
            vec![(x_span.0, value), (x_span.1, value)],
            8,
            5,
            style,
        ))
        .map_err(|e| draw_err(title, &e))?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    Ok(())
}

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
        let t = self.title.as_str();
        let labels = (self.x_label.as_str(), self.y_label.as_str());
        let size = (self.width, self.height);
        render_svg(t, size, labels, (x0..x1, y0..y1), None, |chart| {
            let finite = |(x, y): (f64, f64)| x.is_finite() && y.is_finite();
            if scatter {
                for (i, s) in self.series.iter().enumerate() {
                    let color = Palette99::pick(i).to_rgba();
                    let pts = s.points.iter().copied().filter(|&p| finite(p));
                    chart
                        .draw_series(pts.map(|p| Circle::new(p, 3, color.filled())))
                        .map_err(|e| draw_err(t, &e))?
                        .label(&s.name)
                        .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
                }
            } else {
                draw_lines(chart, t, &self.series, finite)?;
            }
            match &self.limit {
                Some((v, label)) => draw_limit(chart, t, (x0, x1), *v, label),
                None => Ok(()),
            }
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
