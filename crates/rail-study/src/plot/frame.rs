//! What every figure shares: the title wrapped to the figure's width, a frame (axes with
//! their descriptions and units), the legend in a column right of the plotting area, the line
//! colours, and the lines and limit lines of [`super::Chart`].

use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{PlotError, Series};

/// A drawing area with axes, as [`render_svg`] hands it to the chart's own drawing.
pub(crate) type Frame<'a, 'b, X, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>;

/// Font size of legend entries (plotters writes 1/1.24 of it into the SVG) [px].
const LEGEND_FONT_PX: u32 = 15;
/// Height of a legend row [px].
const LEGEND_ROW_PX: i32 = 18;
/// Font size of a figure's title and of a panel's caption [px].
const TITLE_FONT_PX: u32 = 20;
pub(super) const PANEL_FONT_PX: u32 = 15;
/// Characters of a panel's caption at most (a signal's name may be a user's).
pub(super) const MAX_PANEL_CHARS: usize = 90;
/// Lines of a wrapped title at most; the rest is cut.
const MAX_TITLE_LINES: usize = 3;
/// Line colours in order (Tableau 10 without its grey, which marks references): distinct on
/// white and for the common colour-vision deficiencies, no pale yellow.
const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
];

/// The `i`-th line colour (repeating after [`PALETTE`]).
pub(crate) fn colour(i: usize) -> RGBAColor {
    PALETTE[i % PALETTE.len()].to_rgba()
}

/// Grey of a reference series drawn in every panel.
const REFERENCE_GREY: RGBColor = RGBColor(150, 150, 150);

pub(crate) fn draw_err(title: &str, e: &dyn std::fmt::Display) -> PlotError {
    PlotError::Draw {
        title: title.to_string(),
        reason: e.to_string(),
    }
}

/// Width of the legend column for entries of at most `chars` characters [px]: the sample
/// line, its gap, the text (about 0.56 em per character of a sans-serif font) and a margin;
/// 0 without entries.
pub(crate) fn legend_width(chars: usize) -> u32 {
    if chars == 0 {
        return 0;
    }
    let em = f64::from(LEGEND_FONT_PX) / 1.24;
    let text = (chars.min(MAX_LEGEND_CHARS) as f64 * 0.56 * em).ceil() as u32;
    36 + text + 12
}

/// Characters of a legend entry at most; a longer one is cut (the CSV beside the figure
/// keeps the full name).
const MAX_LEGEND_CHARS: usize = 60;

/// `text` cut to `max_chars` characters, the cut marked by " ...".
pub(super) fn cut(text: &str, max_chars: usize) -> String {
    if text.chars().count() <= max_chars {
        return text.to_string();
    }
    let mut cut: String = text.chars().take(max_chars.saturating_sub(4)).collect();
    cut.push_str(" ...");
    cut
}

/// The longest of `labels`, in characters.
pub(crate) fn longest<'a>(labels: impl IntoIterator<Item = &'a str>) -> usize {
    labels
        .into_iter()
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(0)
}

/// How a legend entry shows its series.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Swatch {
    /// A line of this colour and width [px].
    Line(RGBAColor, u32),
    /// A dashed line (a limit).
    Dashed(RGBAColor),
    /// A filled dot of this radius [px].
    Dot(RGBAColor, i32),
    /// A ring of this radius [px].
    Ring(RGBAColor, i32),
}

/// One legend entry: what the series is, and how it looks.
#[derive(Debug, Clone)]
pub(crate) struct LegendEntry {
    pub label: String,
    pub swatch: Swatch,
}

impl LegendEntry {
    pub fn new(label: impl Into<String>, swatch: Swatch) -> Self {
        LegendEntry {
            label: label.into(),
            swatch,
        }
    }
}

/// Draws `entries` top-down from pixel `(x, y)` of `area`: swatch, then label.
pub(crate) fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    entries: &[LegendEntry],
    (x, y): (i32, i32),
) -> Result<(), PlotError> {
    let font = ("sans-serif", LEGEND_FONT_PX)
        .into_font()
        .into_text_style(area)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (k, e) in entries.iter().enumerate() {
        let yk = y + LEGEND_ROW_PX / 2 + k as i32 * LEGEND_ROW_PX;
        let line = |dx0: i32, dx1: i32| vec![(x + dx0, yk), (x + dx1, yk)];
        let drawn = match e.swatch {
            Swatch::Line(c, w) => area.draw(&PathElement::new(line(0, 24), c.stroke_width(w))),
            Swatch::Dashed(c) => area
                .draw(&PathElement::new(line(0, 9), c.stroke_width(1)))
                .and_then(|()| area.draw(&PathElement::new(line(15, 24), c.stroke_width(1)))),
            Swatch::Dot(c, r) => area.draw(&Circle::new((x + 12, yk), r, c.filled())),
            Swatch::Ring(c, r) => area.draw(&Circle::new((x + 12, yk), r, c.stroke_width(2))),
        };
        drawn.map_err(|err| draw_err(title, &err))?;
        area.draw(&Text::new(
            cut(&e.label, MAX_LEGEND_CHARS),
            (x + 32, yk),
            font.clone(),
        ))
        .map_err(|err| draw_err(title, &err))?;
    }
    Ok(())
}

/// `text` in lines of at most `max_chars` characters, broken between words (a longer word
/// stands on its own line).
pub(crate) fn wrap(text: &str, max_chars: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= max_chars => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// Height of a title line [px].
const TITLE_LINE_PX: i32 = 24;

/// The lines of `title` on a figure `width_px` wide: wrapped between words, at most
/// [`MAX_TITLE_LINES`] (a title that long, a user's label in it, must not crowd out the plot).
fn title_lines(title: &str, width_px: u32) -> Vec<String> {
    // plotters writes 1/1.24 of the size into the SVG; a sans-serif character is ~0.56 em
    let char_px = 0.56 * f64::from(TITLE_FONT_PX) / 1.24;
    let max_chars = ((f64::from(width_px) - 24.0) / char_px).max(10.0) as usize;
    let mut lines = wrap(title, max_chars);
    if lines.len() > MAX_TITLE_LINES {
        lines.truncate(MAX_TITLE_LINES);
        lines[MAX_TITLE_LINES - 1].push_str(" ...");
    }
    lines
}

/// Height the title of a figure `width_px` wide takes above its frames [px].
pub(super) fn title_height_px(title: &str, width_px: u32) -> u32 {
    height_of_lines(title_lines(title, width_px).len())
}

/// Height of a title of `n` lines [px].
fn height_of_lines(n: usize) -> u32 {
    (12 + TITLE_LINE_PX * n.max(1) as i32) as u32
}

/// Writes the figure's title across the top of `root`, wrapped to its width, and returns the
/// area below it.
fn titled<'a>(
    root: &DrawingArea<SVGBackend<'a>, Shift>,
    title: &str,
) -> Result<DrawingArea<SVGBackend<'a>, Shift>, PlotError> {
    let (w, _) = root.dim_in_pixel();
    let lines = title_lines(title, w);
    let (top, rest) = root.split_vertically(height_of_lines(lines.len()));
    let style = ("sans-serif", TITLE_FONT_PX)
        .into_font()
        .into_text_style(root)
        .pos(Pos::new(HPos::Center, VPos::Top));
    for (k, line) in lines.into_iter().enumerate() {
        top.draw(&Text::new(
            line,
            (w as i32 / 2, 8 + k as i32 * TITLE_LINE_PX),
            style.clone(),
        ))
        .map_err(|e| draw_err(title, &e))?;
    }
    Ok(rest)
}

/// Font size of an axis description [px].
const AXIS_DESC_FONT_PX: u32 = 14;

/// Font size of the tick labels [px] (plotters' default, 12 px at its 1.24 scale, read as
/// about 7 pt in print).
const TICK_FONT_PX: u32 = 14;

/// Width of one character of an axis description [px], estimated as for the legend.
fn axis_desc_char_px() -> f64 {
    0.56 * f64::from(AXIS_DESC_FONT_PX) / 1.24
}

/// Length of an axis description on the figure [px].
pub(super) fn axis_desc_px(text: &str) -> u32 {
    (text.chars().count() as f64 * axis_desc_char_px()).ceil() as u32
}

/// Height of a panel's plotting area for a panel `panel_px` high: less its caption, the
/// margins and the tick labels below it [px].
pub(super) fn panel_plot_px(panel_px: u32) -> u32 {
    panel_px.saturating_sub(2 * 12 + PANEL_FONT_PX + 10 + 50)
}

/// Writes `text` once, rotated, at the left edge of `area` and centred on its height: the y
/// description of stacked panels, when it is longer than one panel is tall (each panel's own
/// ran into its neighbours). Cut to the area's height.
pub(super) fn draw_shared_y_desc(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    text: &str,
) -> Result<(), PlotError> {
    let (_, h) = area.dim_in_pixel();
    let text = cut(
        text,
        (f64::from(h.saturating_sub(20)) / axis_desc_char_px()) as usize,
    );
    let style = ("sans-serif", AXIS_DESC_FONT_PX)
        .into_font()
        .transform(FontTransform::Rotate270)
        .into_text_style(area)
        .pos(Pos::new(HPos::Center, VPos::Top));
    area.draw(&Text::new(text, (12, h as i32 / 2), style))
        .map_err(|e| draw_err(title, &e))
}

/// A figure of `size` as an SVG string: white background, the title, then `draw` on the area
/// below the title.
pub(super) fn svg_figure(
    title: &str,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), PlotError>,
) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(title, &e))?;
        draw(&titled(&root, title)?)?;
        root.present().map_err(|e| draw_err(title, &e))?;
    }
    Ok(svg)
}

/// What one frame of a figure shows besides its data.
pub(crate) struct FrameSpec<'s> {
    /// Caption above the frame (a panel's name), if any.
    pub caption: Option<(&'s str, u32)>,
    /// Axis descriptions with units; an empty x description leaves room for tick labels only
    /// (a panel above another sharing its x axis).
    pub labels: (&'s str, &'s str),
    /// Width of the legend column right of the plotting area [px].
    pub legend_px: u32,
    /// Whether the legend is drawn in that column.
    pub legend: bool,
}

/// Draws one frame into `area`: caption, axes with their descriptions, the data by `body`,
/// then the legend of the series `body` labelled, in the column right of the plotting area.
pub(crate) fn draw_frame<XR, YR, F>(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    spec: &FrameSpec<'_>,
    (xr, yr): (XR, YR),
    body: F,
) -> Result<(), PlotError>
where
    XR: AsRangedCoord<Value = f64>,
    YR: AsRangedCoord<Value = f64>,
    XR::CoordDescType: ValueFormatter<f64>,
    YR::CoordDescType: ValueFormatter<f64>,
    F: FnOnce(
        &mut Frame<'_, '_, XR::CoordDescType, YR::CoordDescType>,
    ) -> Result<Vec<LegendEntry>, PlotError>,
{
    let mut builder = ChartBuilder::on(area);
    if let Some((caption, px)) = spec.caption {
        builder.caption(caption, ("sans-serif", px));
    }
    let x_area = if spec.labels.0.is_empty() { 30 } else { 50 };
    let mut chart = builder
        .margin(12)
        .margin_right(12 + spec.legend_px)
        .x_label_area_size(x_area)
        .y_label_area_size(78)
        .build_cartesian_2d(xr, yr)
        .map_err(|e| draw_err(title, &e))?;
    let (x_span, y_span) = (chart.x_range(), chart.y_range());
    chart
        .configure_mesh()
        .label_style(("sans-serif", TICK_FONT_PX))
        .axis_desc_style(("sans-serif", AXIS_DESC_FONT_PX))
        .x_desc(spec.labels.0)
        .y_desc(spec.labels.1)
        .x_label_formatter(&|v| tick_label(*v, &x_span))
        .y_label_formatter(&|v| tick_label(*v, &y_span))
        .draw()
        .map_err(|e| draw_err(title, &e))?;
    let entries = body(&mut chart)?;
    if spec.legend && spec.legend_px > 0 {
        // in the column right of the plotting area, from its top: never over the data
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let (bx, by) = area.get_base_pixel();
        draw_legend(area, title, &entries, (xs.end - bx + 10, ys.start - by))?;
    }
    Ok(())
}

/// Renders a one-frame figure (white background, title, axes, the data by `body`, the
/// legend in a column of `legend_px` right of the plot) into an SVG string of `size` plus
/// that column.
pub(crate) fn render_svg<XR, YR, F>(
    title: &str,
    size: (u32, u32),
    labels: (&str, &str),
    ranges: (XR, YR),
    legend_px: u32,
    body: F,
) -> Result<String, PlotError>
where
    XR: AsRangedCoord<Value = f64>,
    YR: AsRangedCoord<Value = f64>,
    XR::CoordDescType: ValueFormatter<f64>,
    YR::CoordDescType: ValueFormatter<f64>,
    F: FnOnce(
        &mut Frame<'_, '_, XR::CoordDescType, YR::CoordDescType>,
    ) -> Result<Vec<LegendEntry>, PlotError>,
{
    let spec = FrameSpec {
        caption: None,
        labels,
        legend_px,
        legend: true,
    };
    svg_figure(title, (size.0 + legend_px, size.1), |area| {
        draw_frame(area, title, &spec, ranges, body)
    })
}

/// Each series as a line in the palette colour of its place among `series` (a reference
/// series in grey), with a dot on each point if `markers`; points failing `keep` are left
/// out. Returns their legend entries.
pub(crate) fn draw_lines<X, Y>(
    chart: &mut Frame<'_, '_, X, Y>,
    title: &str,
    series: &[&Series],
    markers: bool,
    keep: impl Fn((f64, f64)) -> bool,
) -> Result<Vec<LegendEntry>, PlotError>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let mut colour_index = 0;
    let mut entries = Vec::with_capacity(series.len());
    for s in series {
        let color = if s.reference {
            REFERENCE_GREY.to_rgba()
        } else {
            colour_index += 1;
            colour(colour_index - 1)
        };
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|&p| keep(p)).collect();
        if markers {
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
                .map_err(|e| draw_err(title, &e))?;
        }
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
            .map_err(|e| draw_err(title, &e))?;
        entries.push(LegendEntry::new(&s.name, Swatch::Line(color, 2)));
    }
    Ok(entries)
}

/// What a horizontal line across a chart marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Rule {
    /// A limit (EN 14363's a_lim): dashed red.
    Limit,
    /// A guide (a class boundary, a scale's end): dotted grey.
    Guide,
}

/// A horizontal line of `rule`'s style at `value` across `x_span`; returns its legend entry.
pub(crate) fn draw_rule<X, Y>(
    chart: &mut Frame<'_, '_, X, Y>,
    title: &str,
    (x_span, value): ((f64, f64), f64),
    rule: Rule,
    label: &str,
) -> Result<LegendEntry, PlotError>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let (colour, dash, gap) = match rule {
        Rule::Limit => (RED, 8, 5),
        Rule::Guide => (REFERENCE_GREY, 2, 4),
    };
    chart
        .draw_series(DashedLineSeries::new(
            vec![(x_span.0, value), (x_span.1, value)],
            dash,
            gap,
            colour.stroke_width(1),
        ))
        .map_err(|e| draw_err(title, &e))?;
    Ok(LegendEntry::new(label, Swatch::Dashed(colour.to_rgba())))
}

/// A tick value as a person writes it: 250 and 0.3, not 250.0 and 0.30000000000000004 (the
/// value rounded to 9 significant digits, then printed in its shortest form; within 1e-4 and
/// 1e6 in magnitude without an exponent). On an axis `span` that holds 0, a tick within 1e-9 of
/// the span's length of it is 0 (plotters gave 1.4e-17 for the 0 of a damping-ratio axis).
pub(crate) fn tick_label(v: f64, span: &std::ops::Range<f64>) -> String {
    let length = (span.end - span.start).abs();
    let holds_zero = span.start.min(span.end) <= 0.0 && span.start.max(span.end) >= 0.0;
    if holds_zero && v.abs() <= length * 1e-9 {
        return "0".to_string();
    }
    let rounded: f64 = format!("{v:.8e}").parse().unwrap_or(v);
    if rounded == 0.0 {
        "0".to_string()
    } else if (1e-4..1e6).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

#[cfg(test)]
mod tick_tests {
    use super::tick_label;

    #[test]
    fn ticks_print_as_written_by_hand() {
        let t = |v: f64| tick_label(v, &(-100.0..1e8));
        assert_eq!(t(250.0), "250");
        assert_eq!(t(0.1 + 0.2), "0.3");
        assert_eq!(t(-2.5), "-2.5");
        assert_eq!(t(-0.0), "0");
        assert_eq!(t(12.0), "12");
        assert_eq!(t(3.5e7), "3.5e7");
        // small values on an axis of their size, or one without 0 (a logarithmic one)
        assert_eq!(tick_label(1e-3, &(-0.01..0.01)), "0.001");
        assert_eq!(tick_label(2e-6, &(-1e-5..1e-5)), "2e-6");
        assert_eq!(tick_label(1e-10, &(1e-11..10.0)), "1e-10");
        // the zero of a damping-ratio axis, computed with a rounding error
        let zero = 1.3877787807814457e-17;
        assert_eq!(tick_label(zero, &(-0.11..0.17)), "0");
        assert_eq!(tick_label(0.05, &(-0.11..0.17)), "0.05");
    }
}
