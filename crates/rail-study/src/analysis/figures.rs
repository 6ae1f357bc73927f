//! Figures the linear charts of [`crate::plot`] cannot draw: line charts with logarithmic
//! axes (FRF moduli) and scatter plots whose points are coloured by a third variable (root
//! locus coloured by speed). Both render to an SVG string.

use std::ops::Range;

use plotters::coord::combinators::{BindKeyPoints, LogCoord, WithKeyPoints};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

use crate::plot::{
    draw_err, draw_lines, draw_rule, legend_width, longest, render_svg, Chart, LegendEntry,
    PlotError, Rule, Swatch,
};

/// Axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// Base-10 logarithmic; points with a non-positive coordinate on this axis are skipped.
    Log,
}

fn data_err(title: &str, reason: &str) -> PlotError {
    PlotError::Data {
        title: title.to_string(),
        reason: reason.to_string(),
    }
}

fn usable(p: (f64, f64), x: Scale, y: Scale) -> bool {
    p.0.is_finite()
        && p.1.is_finite()
        && (x == Scale::Linear || p.0 > 0.0)
        && (y == Scale::Linear || p.1 > 0.0)
}

/// Axis range from data extremes: 5 % padding on a linear axis, a factor 1.25 on a log axis
/// for y (x keeps the data span, e.g. the frequency band).
fn axis_range(lo: f64, hi: f64, scale: Scale, pad: bool) -> Range<f64> {
    match scale {
        Scale::Linear => {
            let d = if hi > lo {
                (hi - lo) * 0.05
            } else {
                lo.abs().max(1.0) * 0.05
            };
            if pad || hi <= lo {
                (lo - d)..(hi + d)
            } else {
                lo..hi
            }
        }
        Scale::Log => {
            if pad || hi <= lo {
                (lo / 1.25)..(hi * 1.25)
            } else {
                lo..hi
            }
        }
    }
}

/// Line chart with the given axis scales (linear/linear falls back to [`Chart::to_svg`]).
pub fn lines_svg(chart: &Chart, x: Scale, y: Scale) -> Result<String, PlotError> {
    if x == Scale::Linear && y == Scale::Linear {
        return chart.to_svg(false);
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &p in chart.series.iter().flat_map(|s| s.points.iter()) {
        if usable(p, x, y) {
            x0 = x0.min(p.0);
            x1 = x1.max(p.0);
            y0 = y0.min(p.1);
            y1 = y1.max(p.1);
        }
    }
    if x0 > x1 {
        return Err(data_err(
            &chart.title,
            "no finite points (positive on the logarithmic axes)",
        ));
    }
    if let Some((v, _)) = &chart.limit {
        if y == Scale::Linear || *v > 0.0 {
            y0 = y0.min(*v);
            y1 = y1.max(*v);
        }
    }
    let xr = axis_range(x0, x1, x, false);
    let yr = axis_range(y0, y1, y, true);
    let span = (xr.start, xr.end);
    match (x, y) {
        (Scale::Log, Scale::Log) => render(chart, log_axis(xr), log_axis(yr), span, x, y),
        (Scale::Log, Scale::Linear) => render(chart, log_axis(xr), yr, span, x, y),
        _ => render(chart, xr, log_axis(yr), span, x, y),
    }
}

/// A logarithmic axis with the ticks of [`log_ticks`]: plotters' own put no tick below the
/// range's first power of ten (a modulus from 0.25 to 15 had labels from 1 to 10 only) and
/// about a hundred light lines within one decade.
fn log_axis(r: Range<f64>) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = log_ticks(r.start, r.end);
    r.log_scale().with_key_points(bold).with_light_points(light)
}

/// Labelled ticks and light grid lines of a logarithmic axis over `lo..hi` (both > 0): grid
/// lines at 1..9 times each power of ten; labels at 1, 2 and 5 times a power of ten over up to
/// four decades, at the powers of ten over more (every second, third, ... beyond twelve), at
/// every grid line when that gives fewer than three, and at the ends when not even two
/// grid lines fall in the range.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    let in_range = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let multiples = |ms: &[f64], every: i32| -> Vec<f64> {
        (first..=last)
            .filter(|d| d.rem_euclid(every) == 0)
            // m / 10^-d for a negative d: 0.3, where 3 x 0.1 gives 0.30000000000000004
            .flat_map(|d| {
                ms.iter().map(move |m| {
                    if d >= 0 {
                        m * 10f64.powi(d)
                    } else {
                        m / 10f64.powi(-d)
                    }
                })
            })
            .filter(in_range)
            .collect()
    };
    let all = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
    let light = multiples(&all, 1);
    let decades = (hi / lo).log10();
    let mut bold = if decades <= 4.0 {
        multiples(&[1.0, 2.0, 5.0], 1)
    } else {
        multiples(&[1.0], (decades / 12.0).ceil().max(1.0) as i32)
    };
    if bold.len() < 3 {
        bold = light.clone();
    }
    if bold.len() < 2 {
        bold = vec![lo, hi];
    }
    (bold, light)
}

fn render<X, Y>(
    chart: &Chart,
    xr: X,
    yr: Y,
    x_span: (f64, f64),
    xs: Scale,
    ys: Scale,
) -> Result<String, PlotError>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let t = chart.title.as_str();
    let labels = (chart.x_label.as_str(), chart.y_label.as_str());
    let size = (chart.width, chart.height);
    let series: Vec<_> = chart.series.iter().collect();
    render_svg(t, size, labels, (xr, yr), chart.legend_px(), |ctx| {
        let mut entries = draw_lines(ctx, t, &series, chart.markers, |p| usable(p, xs, ys))?;
        match &chart.limit {
            Some((v, label)) if ys == Scale::Linear || *v > 0.0 => {
                entries.push(draw_rule(ctx, t, (x_span, *v), Rule::Limit, label)?);
            }
            _ => {}
        }
        Ok(entries)
    })
}

/// Viridis-like colour ramp, `u` in 0..1 (dark blue -> teal -> green -> yellow).
pub fn ramp(u: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let u = if u.is_finite() {
        u.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = u * (STOPS.len() - 1) as f64;
    let i = (f.floor() as usize).min(STOPS.len() - 2);
    let w = f - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * w).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Scatter plot with points coloured by a third variable `c` (e.g. speed), an optional
/// highlighted subset (drawn as larger red rings) and an optional dashed vertical line at
/// `x = 0` (stability boundary of a root locus).
#[derive(Debug, Clone, PartialEq)]
pub struct ColourScatter {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Name and unit of the colour variable, e.g. "km/h".
    pub c_unit: String,
    /// (x, y, c)
    pub points: Vec<(f64, f64, f64)>,
    /// (legend label, points)
    pub highlight: Option<(String, Vec<(f64, f64)>)>,
    pub zero_line_x: bool,
    /// Number of colour stops shown in the legend.
    pub legend_stops: usize,
    pub width: u32,
    pub height: u32,
}

impl ColourScatter {
    pub fn new(title: &str, x_label: &str, y_label: &str, c_unit: &str) -> Self {
        ColourScatter {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            c_unit: c_unit.into(),
            points: Vec::new(),
            highlight: None,
            zero_line_x: false,
            legend_stops: 5,
            width: 900,
            height: 640,
        }
    }

    pub fn to_svg(&self) -> Result<String, PlotError> {
        let t = self.title.as_str();
        let pts: Vec<(f64, f64, f64)> = self
            .points
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
            .collect();
        if pts.is_empty() {
            return Err(data_err(t, "no finite points"));
        }
        let fold = |f: fn(&(f64, f64, f64)) -> f64| {
            pts.iter()
                .map(f)
                .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)))
        };
        let (mut x0, mut x1) = fold(|p| p.0);
        let (y0, y1) = fold(|p| p.1);
        let (c0, c1) = fold(|p| p.2);
        if self.zero_line_x {
            x0 = x0.min(0.0);
            x1 = x1.max(0.0);
        }
        let xr = axis_range(x0, x1, Scale::Linear, true);
        let yr = axis_range(y0, y1, Scale::Linear, true);
        let cu = |c: f64| if c1 > c0 { (c - c0) / (c1 - c0) } else { 0.5 };
        let labels = (self.x_label.as_str(), self.y_label.as_str());
        let size = (self.width, self.height);
        let n = self.legend_stops.max(2);
        let stop = |k: usize| c0 + k as f64 / (n - 1) as f64 * (c1 - c0);
        let stop_labels: Vec<String> = (0..n)
            .map(|k| format!("{:.0} {}", stop(k), self.c_unit))
            .collect();
        let highlight = self.highlight.iter().map(|(l, _)| l.as_str());
        let legend = legend_width(longest(
            highlight.chain(stop_labels.iter().map(String::as_str)),
        ));
        render_svg(t, size, labels, (xr.clone(), yr.clone()), legend, |ctx| {
            if self.zero_line_x {
                let style = BLACK.mix(0.6).stroke_width(1);
                ctx.draw_series(DashedLineSeries::new(
                    vec![(0.0, yr.start), (0.0, yr.end)],
                    6,
                    4,
                    style,
                ))
                .map_err(|e| draw_err(t, &e))?;
            }
            ctx.draw_series(
                pts.iter()
                    .map(|&(x, y, c)| Circle::new((x, y), 3, ramp(cu(c)).filled())),
            )
            .map_err(|e| draw_err(t, &e))?;
            let mut entries = Vec::new();
            if let Some((label, hp)) = &self.highlight {
                let hp: Vec<(f64, f64)> = hp
                    .iter()
                    .copied()
                    .filter(|p| p.0.is_finite() && p.1.is_finite())
                    .collect();
                ctx.draw_series(
                    hp.into_iter()
                        .map(|p| Circle::new(p, 6, RED.stroke_width(2))),
                )
                .map_err(|e| draw_err(t, &e))?;
                entries.push(LegendEntry::new(label, Swatch::Ring(RED.to_rgba(), 6)));
            }
            for (k, label) in stop_labels.iter().enumerate() {
                let color = ramp(k as f64 / (n - 1) as f64).to_rgba();
                entries.push(LegendEntry::new(label, Swatch::Dot(color, 4)));
            }
            Ok(entries)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_label_every_decade_part_of_the_range() {
        // the damper modulus: 0.25 to 15 kN/mm
        let (bold, light) = log_ticks(0.25, 15.0);
        assert_eq!(bold, [0.5, 1.0, 2.0, 5.0, 10.0]);
        assert_eq!(light.first(), Some(&0.3));
        assert_eq!(light.last(), Some(&10.0));
        assert_eq!(light.len(), 7 + 9 + 1);
        // a frequency band of 0.5 to 20 Hz keeps 1-2-5
        assert_eq!(log_ticks(0.5, 20.0).0, [0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        // six decades: the powers of ten
        assert_eq!(
            log_ticks(1e-3, 1e3).0,
            [1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1e3]
        );
        // thirty decades: every third
        let wide = log_ticks(1e-15, 1e15).0;
        assert_eq!(wide.len(), 11);
        // a narrow range: every grid line, or its ends
        assert_eq!(log_ticks(3.5, 8.5).0, [4.0, 5.0, 6.0, 7.0, 8.0]);
        assert_eq!(log_ticks(3.1, 3.9).0, [3.1, 3.9]);
        assert!(log_ticks(0.0, 1.0).0.is_empty());
    }

    #[test]
    fn log_log_chart_skips_non_positive_points() {
        let c = Chart::new("FRF", "frequency [Hz]", "|H| [1/s]")
            .with_series("full", vec![(1.0, 10.0), (10.0, 5.0), (100.0, 0.0)])
            .with_series("reduced", vec![(1.0, 9.0), (100.0, 1.0)]);
        let svg = lines_svg(&c, Scale::Log, Scale::Log).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("full") && svg.contains("reduced"));
        let zeros = Chart::new("zeros", "f", "m").with_series("z", vec![(1.0, 0.0), (2.0, 0.0)]);
        let e = lines_svg(&zeros, Scale::Log, Scale::Log).unwrap_err();
        assert!(e.to_string().contains("zeros"), "{e}");
        // log x, linear y (phase plot)
        let ph = Chart::new("phase", "f", "deg").with_series("p", vec![(1.0, -10.0), (5.0, -90.0)]);
        assert!(lines_svg(&ph, Scale::Log, Scale::Linear).is_ok());
    }

    #[test]
    fn ramp_ends_and_coloured_scatter() {
        assert_eq!(ramp(0.0), RGBColor(68, 1, 84));
        assert_eq!(ramp(1.0), RGBColor(253, 231, 37));
        assert_eq!(ramp(f64::NAN), RGBColor(68, 1, 84));
        let mut s = ColourScatter::new("locus", "Re [1/s]", "Im [rad/s]", "km/h");
        s.points = vec![(-1.0, 20.0, 100.0), (0.5, 21.0, 300.0)];
        s.highlight = Some(("hunting".into(), vec![(0.5, 21.0)]));
        s.zero_line_x = true;
        let svg = s.to_svg().unwrap();
        assert!(svg.contains("hunting") && svg.contains("300 km/h") && svg.contains("circle"));
        s.points.clear();
        assert!(s.to_svg().is_err());
    }
}
