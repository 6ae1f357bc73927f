use super::frame::wrap;
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

/// (x, y, text) of every `<text>` element.
fn texts(svg: &str) -> Vec<(f64, f64, String)> {
    let attr = |tag: &str, name: &str| -> f64 {
        let at = tag.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        tag[at..].split('"').next().unwrap().parse().unwrap()
    };
    svg.split("<text ")
        .skip(1)
        .map(|rest| {
            let (tag, body) = rest.split_once('>').unwrap();
            let tag = format!(" {tag}");
            let text = body.split("</text>").next().unwrap().trim().to_string();
            (attr(&tag, "x"), attr(&tag, "y"), text)
        })
        .collect()
}

/// The largest x of the polylines with more than two points: the data, not the legend's
/// swatches or a dashed limit's dashes.
fn data_right_edge(svg: &str) -> f64 {
    svg.split("<polyline ")
        .skip(1)
        .filter_map(|rest| {
            let points = rest.split("points=\"").nth(1)?.split('"').next()?;
            let xs: Vec<f64> = points
                .split_whitespace()
                .filter_map(|p| p.split(',').next()?.parse().ok())
                .collect();
            (xs.len() > 2).then(|| xs.into_iter().fold(f64::MIN, f64::max))
        })
        .fold(f64::MIN, f64::max)
}

fn found<'a>(all: &'a [(f64, f64, String)], text: &str) -> Vec<&'a (f64, f64, String)> {
    all.iter().filter(|t| t.2 == text).collect()
}

#[test]
fn the_legend_sits_right_of_every_data_point() {
    let ramp = |a: f64, b: f64| (0..50).map(|k| (k as f64, a + b * k as f64)).collect();
    let c = Chart::new("rms vs speed", "speed [km/h]", "rms [m/s^2]")
        .with_series("passive", ramp(1.0, 0.2))
        .with_series("MPPT1, ideal valve", ramp(9.0, -0.1))
        .with_limit(5.39, "a_lim = 5.39 m/s^2");
    let svg = c.to_svg(false).unwrap();
    let right = data_right_edge(&svg);
    assert!(right > 0.0);
    let all = texts(&svg);
    for label in ["passive", "MPPT1, ideal valve", "a_lim = 5.39 m/s^2"] {
        let at = found(&all, label);
        assert_eq!(at.len(), 1, "{label}: {all:?}");
        assert!(
            at[0].0 > right + 20.0,
            "{label} at x = {} <= {right}",
            at[0].0
        );
    }
    // the plot keeps its width; the legend column comes on top of it
    assert!(svg.contains(&format!("width=\"{}\"", 900 + c.legend_px())));
    assert!(c.legend_px() > 100);
}

#[test]
fn panels_stack_their_series_with_the_reference_and_the_limit_in_each() {
    let line = |y: f64| vec![(200.0, y), (300.0, y + 1.0), (400.0, y + 3.0)];
    let c = Chart::new("rms vs speed", "speed [km/h]", "rms [m/s^2]")
        .with_reference("passive", line(2.0))
        .with_series_in("MPPT", "MPPT1", line(0.5))
        .with_series_in("sky-hook", "on/off", line(0.7))
        .with_series_in("MPPT", "MPPT2", line(0.9))
        .with_limit(5.39, "a_lim");
    assert_eq!(c.panels, ["MPPT", "sky-hook"]);
    let svg = c.to_svg(false).unwrap();
    let all = texts(&svg);
    assert_eq!(found(&all, "passive").len(), 2, "reference in each panel");
    assert_eq!(found(&all, "a_lim").len(), 2, "limit in each panel");
    assert_eq!(found(&all, "MPPT1").len(), 1);
    assert_eq!(found(&all, "MPPT2").len(), 1);
    assert_eq!(found(&all, "on/off").len(), 1);
    let (mppt, skyhook) = (found(&all, "MPPT")[0].1, found(&all, "sky-hook")[0].1);
    assert!(mppt < skyhook, "panels top to bottom in order");
    // MPPT1 and MPPT2 listed in the upper panel's legend, on/off in the lower one
    assert!(found(&all, "MPPT2")[0].1 < skyhook && found(&all, "on/off")[0].1 > skyhook);
    // the shared x axis is described once, under the bottom panel; y in each panel
    assert_eq!(found(&all, "speed [km/h]").len(), 1);
    assert_eq!(found(&all, "rms [m/s^2]").len(), 2);
    let right = data_right_edge(&svg);
    assert!(found(&all, "MPPT1")[0].0 > right);
}

#[test]
fn one_panel_per_series_needs_no_legend() {
    let c = Chart::new("history", "time [s]", "displacement [mm]")
        .with_series("passive", vec![(0.0, 1.0), (1.0, -1.0), (2.0, 1.0)])
        .with_series("MPPT2", vec![(0.0, 0.5), (1.0, -0.5), (2.0, 0.5)])
        .one_panel_per_series();
    assert_eq!(c.panels, ["passive", "MPPT2"]);
    assert_eq!(c.legend_px(), 0);
    let svg = c.to_svg(false).unwrap();
    let all = texts(&svg);
    // each name once, as its panel's caption
    assert_eq!(found(&all, "passive").len(), 1);
    assert_eq!(found(&all, "MPPT2").len(), 1);
    assert!(svg.contains("width=\"900\""));
}

#[test]
fn long_titles_wrap_between_words() {
    assert_eq!(wrap("a bb ccc dddd", 6), ["a bb", "ccc", "dddd"]);
    assert_eq!(
        wrap("averyveryverylongword x", 5),
        ["averyveryverylongword", "x"]
    );
    assert!(wrap("", 10).is_empty());
    let title = "Root locus of the linear coach, 100 to 400 km/h (passive (Maxwell 16.9 MN/m \
                 in series with 104 kN s/m per damper, fmu-bogie2dof calibration))";
    let svg = Chart::new(title, "Re [1/s]", "Im [rad/s]")
        .with_series("poles", vec![(-1.0, 21.0), (0.2, 20.0)])
        .to_svg(true)
        .unwrap();
    let all = texts(&svg);
    let lines: Vec<_> = all
        .iter()
        .filter(|t| title.contains(t.2.as_str()) && t.2.len() > 20)
        .collect();
    assert!(lines.len() >= 2, "{all:?}");
    let joined: Vec<&str> = lines.iter().map(|t| t.2.as_str()).collect();
    assert_eq!(
        joined.join(" "),
        title.split_whitespace().collect::<Vec<_>>().join(" ")
    );
}

#[test]
fn a_huge_title_is_cut_to_three_lines_and_the_plot_still_drawn() {
    let title = "word ".repeat(2000);
    for panels in [false, true] {
        let mut c = Chart::new(&title, "x [s]", "y [m]")
            .with_series("a", vec![(0.0, 0.0), (1.0, 1.0), (2.0, 0.5)])
            .with_series("b", vec![(0.0, 1.0), (1.0, 0.0), (2.0, 0.2)]);
        if panels {
            c = c.one_panel_per_series();
        }
        let svg = c.to_svg(false).unwrap();
        let all = texts(&svg);
        let lines: Vec<_> = all.iter().filter(|t| t.2.starts_with("word")).collect();
        assert_eq!(lines.len(), 3, "{panels}");
        assert!(lines[2].2.ends_with(" ..."));
        assert!(data_right_edge(&svg) > 0.0, "the data are drawn");
    }
}

#[test]
fn a_huge_legend_label_is_cut_and_the_column_bounded() {
    let long = "x".repeat(5000);
    let c = Chart::new("t", "x [s]", "y [m]")
        .with_series(&long, vec![(0.0, 0.0), (1.0, 1.0), (2.0, 0.5)])
        .with_series("b", vec![(0.0, 1.0), (1.0, 0.0), (2.0, 0.2)]);
    assert_eq!(c.legend_px(), legend_width(60));
    assert!(c.legend_px() < 500);
    let svg = c.to_svg(false).unwrap();
    let all = texts(&svg);
    let cut: Vec<_> = all.iter().filter(|t| t.2.starts_with("xxx")).collect();
    assert_eq!(cut.len(), 1);
    assert_eq!(cut[0].2.chars().count(), 60);
    assert!(cut[0].2.ends_with(" ..."));
    // as a panel's caption: cut to 90
    let svg = c.one_panel_per_series().to_svg(false).unwrap();
    let all = texts(&svg);
    let caption: Vec<_> = all.iter().filter(|t| t.2.starts_with("xxx")).collect();
    assert_eq!(caption.len(), 1);
    assert_eq!(caption[0].2.chars().count(), 90);
}

#[test]
fn markers_put_a_dot_on_every_point() {
    let c = Chart::new("c_v", "c_v [kNs/m]", "force [kN]")
        .with_series("ours", vec![(210.0, 22.3), (270.0, 24.4), (330.0, 22.4)])
        .with_series("seed", vec![(210.0, 20.4), (270.0, 23.5)]);
    let dots = |svg: &str| svg.matches("<circle").count();
    assert_eq!(dots(&c.to_svg(false).unwrap()), 0);
    assert_eq!(dots(&c.with_markers().to_svg(false).unwrap()), 5);
}

#[test]
fn a_y_description_longer_than_a_panel_is_written_once_beside_the_stack() {
    let long = "leading wheelset lateral displacement relative to the track [mm]";
    let line = vec![(0.0, 1.0), (1.0, -1.0), (2.0, 1.0)];
    let c = Chart::new("perturbation", "time [s]", long)
        .with_series("240 km/h", line.clone())
        .with_series("280 km/h", line.clone())
        .with_series("300 km/h", line.clone())
        .one_panel_per_series();
    let svg = c.to_svg(false).unwrap();
    let all = texts(&svg);
    assert_eq!(found(&all, long).len(), 1, "{all:?}");
    // centred on the stack: between the first and the last panel's caption
    let y = found(&all, long)[0].1;
    assert!(found(&all, "240 km/h")[0].1 < y && y < found(&all, "300 km/h")[0].1);
    // a short one stays in each panel
    let c = Chart::new("history", "time [s]", "displacement [mm]")
        .with_series("240 km/h", line.clone())
        .with_series("280 km/h", line)
        .one_panel_per_series();
    let all = texts(&c.to_svg(false).unwrap());
    assert_eq!(found(&all, "displacement [mm]").len(), 2);
}

#[test]
fn a_panel_captioned_with_its_line_lists_only_the_limit() {
    let signal = "vehicle.frame_front.lateral_acceleration_leading_axle";
    let line = vec![(0.0, 4.0), (100.0, 5.0), (200.0, 6.0)];
    let c = Chart::new("EN 14363 rms", "position along the track [m]", "rms [m/s2]")
        .with_series(signal, line.clone())
        .with_series("rear", line)
        .with_limit(5.39, "limit")
        .one_panel_per_series();
    let svg = c.to_svg(false).unwrap();
    let all = texts(&svg);
    // the signal's name once, as its panel's caption; the limit in each panel's legend
    assert_eq!(found(&all, signal).len(), 1, "{all:?}");
    assert_eq!(found(&all, "rear").len(), 1, "{all:?}");
    assert_eq!(found(&all, "limit").len(), 2, "{all:?}");
    // a column wide enough for "limit", not for the signal's name
    assert_eq!(c.legend_px(), legend_width("limit".len()));
}

#[test]
fn panels_scale_their_own_y_axes_on_request_and_guides_are_listed() {
    let line = |a: f64| vec![(0.0, -a), (1.0, a), (2.0, -a)];
    let two = Chart::new("histories", "time [s]", "acceleration [m/s^2]")
        .with_series("passive", line(30.0))
        .with_series("MPPT2", line(0.2))
        .one_panel_per_series();
    // shared: the small run's panel reaches the large one's ticks; its own: only its own
    let tick_texts = |c: &Chart| -> Vec<String> {
        texts(&c.to_svg(false).unwrap())
            .into_iter()
            .map(|t| t.2)
            .collect()
    };
    let shared = tick_texts(&two);
    assert_eq!(
        shared.iter().filter(|t| *t == "30").count(),
        2,
        "{shared:?}"
    );
    let own = tick_texts(&two.clone().with_own_y_per_panel());
    assert_eq!(own.iter().filter(|t| *t == "30").count(), 1, "{own:?}");
    assert!(own.iter().any(|t| t == "0.2"), "{own:?}");
    // a guide is drawn in every panel and listed in its legend; from zero, 0 is a tick
    let c = Chart::new("comfort", "speed [km/h]", "N_y [-]")
        .with_series("MPPT", vec![(200.0, 1.2), (300.0, 1.4)])
        .with_guide(2.0, "N = 2: comfortable below")
        .with_y_from_zero();
    let all = tick_texts(&c);
    assert!(
        all.iter().any(|t| t == "N = 2: comfortable below"),
        "{all:?}"
    );
    assert!(all.iter().any(|t| t == "0"), "{all:?}");
    assert!(all.iter().any(|t| t == "2"), "{all:?}");
}
