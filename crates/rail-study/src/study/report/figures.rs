//! The study's figures, each an SVG with the CSV of its data: over speed, time histories, the
//! perturbation, MPPT and slow-valve runs, and the c_v sensitivity; drawn from the kept runs.

use std::path::Path;

use super::{label_of, stem, ActuatorBound, SEED_TABLE_4_3};
use crate::plot::Chart;
use crate::study::configurations::configuration;
use crate::study::run::{
    scenario, SpeedPoint, StudyError, StudyResults, HIL_CONFIGS, HISTORY_CONFIGS, HISTORY_DETAIL_S,
};
use crate::study::vehicle::{Signals, VehicleModel};
use master::output::write_csv_atomic;

/// (time, value) series of a column of a kept run, in display units via `scale`.
fn series(r: &StudyResults, run: &str, column: &str, scale: f64) -> Option<Vec<(f64, f64)>> {
    series_of(r.kept.get(run)?, column, scale)
}

/// [`series`] of the last [`HISTORY_DETAIL_S`] of a kept run at the full recorded rate.
fn tail_series(r: &StudyResults, run: &str, column: &str, scale: f64) -> Option<Points> {
    series_of(r.kept_tail.get(run)?, column, scale)
}

fn series_of(out: &master::coupling::SimOutput, column: &str, scale: f64) -> Option<Points> {
    let t = out.column("time")?;
    let y = out.column(column)?;
    Some(t.into_iter().zip(y).map(|(t, y)| (t, y * scale)).collect())
}

/// Writes a CSV of several equally sampled series side by side (time from the first).
fn write_series_csv(path: &Path, columns: &[(String, Vec<(f64, f64)>)]) -> Result<(), StudyError> {
    let Some(n) = columns.iter().map(|c| c.1.len()).min() else {
        return Ok(());
    };
    let mut header = vec!["time [s]".to_string()];
    header.extend(columns.iter().map(|c| c.0.clone()));
    let rows: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            // times to the nanosecond: k x 0.01 s reads 0.35, not 0.35000000000000003
            let mut row = vec![(columns[0].1[i].0 * 1e9).round() / 1e9];
            row.extend(columns.iter().map(|c| c.1[i].1));
            row
        })
        .collect();
    write_csv_atomic(path, &header, rows.iter().map(Vec::as_slice))?;
    Ok(())
}

/// A configuration's curve in a figure over speed: in its control family's panel, the passive
/// damper in grey in every panel, so that twelve curves never share one frame.
fn speed_curve(chart: Chart, id: &str, label: &str, points: Vec<(f64, f64)>) -> Chart {
    match configuration(id).map(|c| c.family.panel()) {
        Some(None) => chart.with_reference(label, points),
        Some(Some(panel)) => chart.with_series_in(panel, label, points),
        None => chart.with_series_in("other", label, points),
    }
}

/// The caption of a time history's detail figure in the report.
pub(super) const HISTORY_DETAIL_CAPTION: &str =
    "the same over the last 2 s at the full recorded rate, \
     where its cycles and switchings show (each panel scaled to its own run)";

/// A history's y axis: its description, a grey line that says what its scale means, and the
/// window of a moving mean the whole history is drawn as (the detail figure keeps every
/// sample).
#[derive(Clone, Copy)]
struct YAxis<'a> {
    label: &'a str,
    guide: Option<(f64, &'a str)>,
    mean_over_s: Option<f64>,
}

impl<'a> YAxis<'a> {
    const fn plain(label: &'a str) -> Self {
        YAxis {
            label,
            guide: None,
            mean_over_s: None,
        }
    }
}

/// The valve command's axis: which end is closed (the controllers' 0-10 V, (3.1)). An on/off
/// sky-hook switches within milliseconds, which 100 Hz samples of 40 s draw as a solid comb:
/// the whole history shows its 0.5 s moving mean, the share of time the valve is commanded
/// open.
const COMMAND_AXIS: YAxis<'static> = YAxis {
    label: "command [V]",
    guide: Some((10.0, "10 V: valve fully open (0 V: closed, most damping)")),
    mean_over_s: Some(0.5),
};

/// The command of a controller whose command moves slowly (MPPT: 1 s updates), every sample.
const SLOW_COMMAND_AXIS: YAxis<'static> = YAxis {
    mean_over_s: None,
    ..COMMAND_AXIS
};

/// The valve opening's axis.
const OPENING_AXIS: YAxis<'static> = YAxis {
    label: OPENING_LABEL,
    guide: Some((1.0, "1: valve fully open (0: closed, most damping)")),
    mean_over_s: None,
};

/// The centred moving mean of `s` (times in order) over `window_s`, fewer points near the
/// ends; a value that is not finite is left out of the windows holding it (NaN where a window
/// holds none).
pub(super) fn moving_mean(s: &[(f64, f64)], window_s: f64) -> Points {
    let half = 0.5 * window_s;
    let (mut lo, mut hi, mut sum, mut n) = (0usize, 0usize, 0.0, 0usize);
    s.iter()
        .map(|&(t, _)| {
            while hi < s.len() && s[hi].0 <= t + half {
                if s[hi].1.is_finite() {
                    sum += s[hi].1;
                    n += 1;
                }
                hi += 1;
            }
            while lo < hi && s[lo].0 < t - half {
                if s[lo].1.is_finite() {
                    sum -= s[lo].1;
                    n -= 1;
                }
                lo += 1;
            }
            (t, if n > 0 { sum / n as f64 } else { f64::NAN })
        })
        .collect()
}

const OPENING_LABEL: &str = "opening [-]";

/// (time, value) pairs of a series.
type Points = Vec<(f64, f64)>;

/// A time-history figure, one panel per run (`<stem>.svg`, its data `<stem>.csv`), and with
/// `detail` = (stem, title) the same over the last [`HISTORY_DETAIL_S`] of the record at the
/// full recorded rate, the rate appended to its title (written when every run's tail has the
/// same times); the stems written, `None` when no run has the column.
#[allow(clippy::too_many_arguments)]
fn history_chart(
    r: &StudyResults,
    dir: &Path,
    stem: &str,
    title: &str,
    y_axis: YAxis<'_>,
    runs: &[(&str, String)],
    column: &str,
    scale: f64,
    detail: Option<(&str, &str)>,
) -> Result<Option<(String, Option<String>)>, StudyError> {
    let y_label = y_axis.label;
    // (panel label, CSV header, points) of each run that has the column
    let of = |get: &dyn Fn(&str) -> Option<Points>| -> Vec<(&str, String, Points)> {
        runs.iter()
            .filter_map(|(label, run)| get(run).map(|s| (*label, format!("{label}: {y_label}"), s)))
            .collect()
    };
    let mut found = of(&|run| series(r, run, column, scale));
    if found.is_empty() {
        return Ok(None);
    }
    let mut whole_title = title.to_string();
    if let Some(w) = y_axis.mean_over_s {
        for (_, header, s) in &mut found {
            *s = moving_mean(s, w);
            header.push_str(&format!(", {w} s moving mean"));
        }
        whole_title.push_str(&format!(
            "; drawn as its {w} s moving mean (the detail shows every switch)"
        ));
    }
    let mut views = vec![(stem, whole_title, found, false)];
    let mut detail_written = None;
    if let Some((stem, title)) = detail {
        let tail = of(&|run| tail_series(r, run, column, scale));
        // one time grid for every run (one time column in the CSV, one rate in the title):
        // a run ended early by its FMU, or at another step, has none of its own here
        let grid = |s: &Points| s.iter().map(|p| p.0).collect::<Vec<f64>>();
        let same_grid = tail.windows(2).all(|w| grid(&w[0].2) == grid(&w[1].2));
        let rate_hz = tail.first().and_then(|(_, _, s)| rate_of(s));
        if let (Some(rate_hz), true) = (rate_hz, same_grid) {
            let title = format!(
                "{title} ({rate_hz:.0} Hz samples, unfiltered; each panel scaled to its run)"
            );
            views.push((stem, title, tail, true));
            detail_written = Some(stem.to_string());
        }
    }
    for (stem, title, found, own_scales) in views {
        let cols: Vec<(String, Points)> = found
            .iter()
            .map(|(_, header, s)| (header.clone(), s.clone()))
            .collect();
        write_series_csv(&dir.join(format!("{stem}.csv")), &cols)?;
        let mut chart = Chart::new(&title, "time [s]", y_label);
        for ((label, _, _), (_, points)) in found.iter().zip(cols) {
            chart = chart.with_series(label, points);
        }
        if let Some((value, label)) = y_axis.guide {
            chart = chart.with_guide(value, label);
        }
        if own_scales {
            // the whole history compares the runs on one scale; the detail shows the shape of
            // each, which one scale flattens where the passive damper hunts at 10 times the
            // others' amplitude
            chart = chart.with_own_y_per_panel();
        }
        chart
            .one_panel_per_series()
            .write_lines(&dir.join(format!("{stem}.svg")))?;
    }
    Ok(Some((stem.to_string(), detail_written)))
}

/// Writes a CSV of text cells (quoted where needed).
/// Draws `chart` as `<stem>.svg` in `out` and lists it in `figures` with its caption (the file
/// name is the stem's, never spelt twice).
fn publish(
    chart: Chart,
    out: &Path,
    stem: &str,
    caption: &'static str,
    figures: &mut Vec<(String, &'static str)>,
) -> Result<(), StudyError> {
    chart.write_lines(&out.join(format!("{stem}.svg")))?;
    figures.push((stem.into(), caption));
    Ok(())
}

fn write_text_csv(path: &Path, header: &[String], rows: &[Vec<String>]) -> Result<(), StudyError> {
    master::output::write_atomic(path, |w| {
        let line = |w: &mut dyn std::io::Write, f: &[String]| {
            let l: Vec<String> = f.iter().map(|x| master::output::csv_field(x)).collect();
            writeln!(w, "{}", l.join(",")).map_err(|source| master::output::OutputError::Io {
                path: path.to_path_buf(),
                source,
            })
        };
        line(w, header)?;
        for row in rows {
            line(w, row)?;
        }
        Ok(())
    })?;
    Ok(())
}

/// The figures over speed: EN 14363 rms (Fig. 4.24), and on the coach the car body's rms
/// and comfort; their CSVs.
pub(super) fn speed_figures(
    r: &StudyResults,
    out: &Path,
    figures: &mut Vec<(String, &'static str)>,
) -> Result<(), StudyError> {
    let coach = r.settings.vehicle == VehicleModel::Coach;
    // ---- rms vs speed (Fig. 4.24), car body vs speed (coach)
    let mut rows: Vec<Vec<String>> = Vec::new();
    let mut chart = Chart::new(
        if coach {
            "EN 14363 rms of the frame lateral acceleration over the axle boxes vs speed"
        } else {
            "EN 14363 rms of the wheelset lateral acceleration vs speed"
        },
        "speed [km/h]",
        "max sliding rms, band-passed [m/s^2]",
    )
    .with_limit(r.limit_mps2, &format!("a_lim = {:.2} m/s^2", r.limit_mps2))
    // a dot on each speed run: the sweep's steps and the bisection's refinements
    .with_markers();
    let mut carbody_chart = Chart::new(
        "car-body floor lateral acceleration vs speed (largest of front, mid, rear)",
        "speed [km/h]",
        "rms [m/s^2]",
    )
    .with_markers();
    let mut comfort_chart = Chart::new(
        "EN 12299 lateral ride comfort vs speed (W_d, largest of front, mid, rear; indicative: \
         5 s windows in 1 s steps over each run, not the standard's 5 minutes)",
        "speed [km/h]",
        "N_y = 6 a_YP95 [-]",
    )
    .with_markers()
    .with_guide(1.0, "N = 1: very comfortable below")
    .with_guide(2.0, "N = 2: comfortable below");
    let num = |v: Option<f64>| v.map_or("failed".into(), |v| format!("{v:.4}"));
    let (mut carbody_rows, mut comfort_rows) = (Vec::new(), Vec::new());
    for c in &r.configs {
        let pts: Vec<(f64, f64)> = c
            .curve()
            .iter()
            .filter_map(|p| p.rms.map(|v| (p.speed_kmh, v)))
            .collect();
        if !pts.is_empty() {
            chart = speed_curve(chart, c.id, c.label, pts);
        }
        let by_speed = |f: fn(&SpeedPoint) -> Option<f64>| -> Vec<(f64, f64)> {
            let mut v: Vec<(f64, f64)> = c
                .sweep
                .iter()
                .chain(&c.bisection)
                .filter_map(|p| f(p).map(|x| (p.speed_kmh, x)))
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            v
        };
        let cb = by_speed(SpeedPoint::carbody_rms);
        let ny = by_speed(SpeedPoint::comfort);
        for (v, x) in &cb {
            carbody_rows.push(vec![c.id.to_string(), format!("{v}"), format!("{x:.4}")]);
        }
        for (v, x) in &ny {
            comfort_rows.push(vec![c.id.to_string(), format!("{v}"), format!("{x:.4}")]);
        }
        if !cb.is_empty() {
            carbody_chart = speed_curve(carbody_chart, c.id, c.label, cb);
        }
        if !ny.is_empty() {
            comfort_chart = speed_curve(comfort_chart, c.id, c.label, ny);
        }
        for (kind, pts) in [("sweep", &c.sweep), ("bisection", &c.bisection)] {
            for p in pts.iter() {
                let mut row = vec![
                    c.id.to_string(),
                    kind.to_string(),
                    format!("{}", p.speed_kmh),
                    num(p.rms()),
                ];
                row.extend(p.per_seed.iter().map(|v| num(*v)));
                if coach {
                    row.push(num(p.carbody_rms()));
                    row.push(num(p.comfort()));
                    row.push(num(p.damper_stroke().map(|x| x * 1e3)));
                }
                rows.push(row);
            }
        }
    }
    let mut header: Vec<String> = ["configuration", "kind", "speed [km/h]", "rms max [m/s2]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    header.extend(
        r.settings
            .seeds
            .iter()
            .map(|s| format!("rms seed {s} [m/s2]")),
    );
    if coach {
        header.push("car-body rms max [m/s2]".into());
        header.push("comfort N_y max [-]".into());
        header.push("damper stroke max [mm]".into());
    }
    write_text_csv(
        &out.join(format!("{}.csv", stem::RMS_VS_SPEED)),
        &header,
        &rows,
    )?;
    if !r.configs.is_empty() {
        publish(
            chart,
            out,
            stem::RMS_VS_SPEED,
            "rms vs speed, a panel per control family with the passive damper in grey, a_lim dashed (Figs. 4.13, 4.23, 4.24)",
            figures,
        )?;
    }
    if coach && !r.configs.is_empty() {
        let head = |what: &str| -> Vec<String> {
            vec!["configuration".into(), "speed [km/h]".into(), what.into()]
        };
        write_text_csv(
            &out.join(format!("{}.csv", stem::CARBODY_VS_SPEED)),
            &head("car-body rms max [m/s2]"),
            &carbody_rows,
        )?;
        write_text_csv(
            &out.join(format!("{}.csv", stem::COMFORT_VS_SPEED)),
            &head("comfort N_y max [-]"),
            &comfort_rows,
        )?;
        publish(
            carbody_chart,
            out,
            stem::CARBODY_VS_SPEED,
            "car-body floor lateral acceleration rms vs speed, max over seeds",
            figures,
        )?;
        publish(
            comfort_chart,
            out,
            stem::COMFORT_VS_SPEED,
            "EN 12299 lateral comfort N_y vs speed, max over seeds",
            figures,
        )?;
    }
    Ok(())
}

/// The time histories at the history speed (Figs. 4.18, 4.21, 4.25-4.27), each with its
/// detail over the last seconds at the full rate.
pub(super) fn history_figures(
    r: &StudyResults,
    out: &Path,
    figures: &mut Vec<(String, &'static str)>,
) -> Result<(), StudyError> {
    let vehicle = r.settings.vehicle;
    let signals = Signals::of(vehicle);
    let coach = vehicle == VehicleModel::Coach;
    // ---- time histories at the history speed (Figs. 4.18, 4.21, 4.25, 4.26)
    let v_hist = r.settings.history_speed_kmh;
    let hist_runs: Vec<(&str, String)> = HISTORY_CONFIGS
        .iter()
        .map(|id| (label_of(id), scenario::history(id)))
        .collect();
    let semi_runs: Vec<(&str, String)> = hist_runs
        .iter()
        .filter(|(_, n)| !n.ends_with("full_active"))
        .cloned()
        .collect();
    let sampled = format!("{:.0} Hz samples, unfiltered", r.settings.stored_rate_hz);
    let title = |what: &str| format!("{what} at {v_hist:.0} km/h, irregular track ({sampled})");
    let detail_title = |what: &str| {
        format!("{what} over the last {HISTORY_DETAIL_S:.0} s at {v_hist:.0} km/h, irregular track")
    };
    let ws_y = signals.displacements[0].as_str();
    let acc = signals.stability[0].as_str();
    let (acc_what, damper_what) = if coach {
        (
            "front frame lateral acceleration over the leading axle",
            "front-left yaw damper force",
        )
    } else {
        (
            "front wheelset lateral acceleration",
            "left yaw damper force",
        )
    };
    let force = vehicle.first("damper", "damper.force");
    let command = vehicle.first("controller", "valve.command");
    // above the front bogie, where the yaw dampers act: the mid-length point, between the
    // bogies, moves least (sky-hook at 300 km/h: rms 0.20 front, 0.09 mid, 0.16 rear m/s^2)
    let carbody_front = signals.carbody.first().cloned().unwrap_or_default();
    let command_what = if coach {
        "front-left damper's valve command"
    } else {
        "left damper's valve command"
    };
    let mut histories = vec![
        ((stem::HISTORY_DISPLACEMENT, stem::HISTORY_DISPLACEMENT_DETAIL), "leading wheelset lateral displacement relative to the track", YAxis::plain("displacement [mm]"), ws_y, 1e3, &hist_runs, "wheelset displacement, passive / MPPT2 / sky-hook / full-active (Figs. 4.18, 4.21, 4.25)"),
        ((stem::HISTORY_ACCELERATION, stem::HISTORY_ACCELERATION_DETAIL), acc_what, YAxis::plain("acceleration [m/s^2]"), acc, 1.0, &hist_runs, "the assessed acceleration as recorded (the EN 14363 rms band-passes it first; Figs. 4.18, 4.21, 4.26)"),
        ((stem::HISTORY_FORCE, stem::HISTORY_FORCE_DETAIL), damper_what, YAxis::plain("force [kN]"), force.as_str(), 1e-3, &semi_runs, "damper force (Figs. 4.18, 4.21)"),
        ((stem::HISTORY_COMMAND, stem::HISTORY_COMMAND_DETAIL), command_what, COMMAND_AXIS, command.as_str(), 1.0, &semi_runs, "valve command MPPT2 vs sky-hook (Figs. 4.18, 4.21)"),
    ];
    if coach {
        histories.push((
            (stem::HISTORY_CARBODY, stem::HISTORY_CARBODY_DETAIL),
            "car-body floor lateral acceleration above the front bogie",
            YAxis::plain("acceleration [m/s^2]"),
            carbody_front.as_str(),
            1.0,
            &hist_runs,
            "what each damper concept transmits to the car body (the seed's future work)",
        ));
    }
    for ((stem, detail), what, ylab, col, scale, runs, caption) in histories {
        let detail_title = detail_title(what);
        let written = history_chart(
            r,
            out,
            stem,
            &title(what),
            ylab,
            runs,
            col,
            scale,
            Some((detail, &detail_title)),
        )?;
        if let Some((whole, detail)) = written {
            figures.push((whole, caption));
            if let Some(detail) = detail {
                figures.push((detail, HISTORY_DETAIL_CAPTION));
            }
        }
    }
    // full-active force tracking (Fig. 4.27): the last seconds at the full recorded rate
    // (the actuator lags its reference by about one 100 Hz sample)
    let fa = scenario::history("full_active");
    let (fa_force, fa_reference) = (
        vehicle.first("actuator", "damper.force"),
        vehicle.first("idf", "reference.force"),
    );
    let both = |get: &dyn Fn(&str) -> Option<Points>| get(&fa_force).zip(get(&fa_reference));
    let picked =
        both(&|c| tail_series(r, &fa, c, 1e-3)).or_else(|| both(&|c| series(r, &fa, c, 1e-3)));
    if let Some((f, fr)) = picked {
        let t_end = f.last().map_or(0.0, |p| p.0);
        let zoom = |s: &[(f64, f64)]| from_time(s, t_end - HISTORY_DETAIL_S);
        let rate_hz = rate_of(&f).unwrap_or(r.settings.stored_rate_hz);
        write_series_csv(
            &out.join(format!("{}.csv", stem::FULL_ACTIVE_FORCE)),
            &[
                ("actuator force [kN]".into(), f.clone()),
                ("reference c_v v [kN]".into(), fr.clone()),
            ],
        )?;
        let chart = Chart::new(
            &format!(
                "full-active, {first}: actuator force and IDF reference c_v v at {v_hist:.0} \
                 km/h, irregular track (last {HISTORY_DETAIL_S:.0} s, {rate_hz:.0} Hz samples)",
                first = if coach {
                    "front-left actuator"
                } else {
                    "left actuator"
                }
            ),
            "time [s]",
            "force [kN]",
        )
        .with_series("actuator force", zoom(&f))
        .with_series("reference c_v v", zoom(&fr));
        publish(
            chart,
            out,
            stem::FULL_ACTIVE_FORCE,
            "full-active force vs IDF reference (Fig. 4.27)",
            figures,
        )?;
    }
    Ok(())
}

/// The perturbation runs (Figs. 4.4-4.6, 5.11-5.13), the MPPT commands (4.16, 5.22) and the
/// slow-valve runs (5.19-5.25).
pub(super) fn hil_figures(
    r: &StudyResults,
    out: &Path,
    figures: &mut Vec<(String, &'static str)>,
) -> Result<(), StudyError> {
    let vehicle = r.settings.vehicle;
    let signals = Signals::of(vehicle);
    let coach = vehicle == VehicleModel::Coach;
    let ws_y = signals.displacements[0].as_str();
    let command = vehicle.first("controller", "valve.command");
    let opening = vehicle.first("damper", "valve.opening");
    // ---- perturbation (Figs. 4.4-4.6, 5.11-5.13, 5.16-5.18; R7)
    let mut pert_cols = Vec::new();
    let pert_title = format!(
        "passive, ideal track, {:.1} mm initial lateral displacement of the {}",
        r.settings.perturbation_lateral_m * 1e3,
        if coach { "both bogies" } else { "bogie" }
    );
    let mut chart = Chart::new(
        &pert_title,
        "time [s]",
        "leading wheelset lateral displacement relative to the track [mm]",
    );
    for p in &r.perturbation {
        if let Some(s) = series(r, &p.name, ws_y, 1e3) {
            let label = format!("{:.0} km/h", p.speed_kmh);
            chart = chart.with_series(&label, s.clone());
            pert_cols.push((format!("{label}: displacement [mm]"), s));
        }
    }
    if !pert_cols.is_empty() {
        write_series_csv(&out.join(format!("{}.csv", stem::PERTURBATION)), &pert_cols)?;
        publish(
            chart.one_panel_per_series(),
            out,
            stem::PERTURBATION,
            if coach {
                "initial-perturbation runs, passive coach, 240/280/300 km/h (Figs. 4.4-4.6, R16)"
            } else {
                "initial-perturbation runs, passive, 220/285/320 km/h (Figs. 5.11-5.13, R7)"
            },
            figures,
        )?;
    }

    // ---- MPPT valve commands (Figs. 4.16, 5.22) and the HIL runs (5.19-5.24)
    let v_low = r.settings.mppt_low_speed_kmh;
    let v_hil = r.settings.hil_speed_kmh;
    let first_damper = if coach {
        "front-left damper"
    } else {
        "left damper"
    };
    let hil_what = format!(
        "ideal track, {:.1} mm initial displacement",
        r.settings.perturbation_lateral_m * 1e3
    );
    let low_runs: Vec<(&str, String)> = ["mppt1", "mppt2"]
        .iter()
        .map(|id| (label_of(id), scenario::mppt_low(id)))
        .collect();
    if let Some((s, _)) = history_chart(
        r,
        out,
        stem::MPPT_COMMAND_CLOSED_START,
        &format!("MPPT valve command of the {first_damper} from a closed valve at {v_low:.0} km/h, irregular track"),
        SLOW_COMMAND_AXIS,
        &low_runs,
        &command,
        1.0,
        None,
    )? {
        figures.push((
            s,
            "MPPT1 vs MPPT2 valve command, closed start (Fig. 4.16, R10)",
        ));
    }
    let hil_runs: Vec<(&str, String)> = HIL_CONFIGS
        .iter()
        .map(|id| (label_of(id), scenario::hil(id)))
        .collect();
    let mppt_hil: Vec<(&str, String)> = hil_runs
        .iter()
        .filter(|(_, n)| n.contains("mppt"))
        .cloned()
        .collect();
    if let Some((s, _)) = history_chart(
        r,
        out,
        stem::MPPT_COMMAND_OPEN_START,
        &format!(
            "MPPT valve command of the {first_damper} from {:.0} V, slow valve, {v_hil:.0} km/h, {}",
            r.settings.hil_initial_command_v, hil_what
        ),
        SLOW_COMMAND_AXIS,
        &mppt_hil,
        &command,
        1.0,
        None,
    )? {
        figures.push((
            s,
            "MPPT1 vs MPPT2 valve command, open start, slow valve (Figs. 5.19, 5.21, 5.22, R10)",
        ));
    }
    if let Some((s, _)) = history_chart(
        r,
        out,
        stem::SLOW_VALVE_DISPLACEMENT,
        &format!(
            "leading wheelset displacement relative to the track at {v_hil:.0} km/h, {hil_what} \
             (each panel names its valve)"
        ),
        YAxis::plain("displacement [mm]"),
        &hil_runs,
        ws_y,
        1e3,
        None,
    )? {
        figures.push((
            s,
            "slow valve: sky-hook vs MPPT wheelset displacement (Figs. 5.19-5.24, R12)",
        ));
    }
    if let Some((s, _)) = history_chart(
        r,
        out,
        stem::SLOW_VALVE_OPENING,
        &format!(
            "actual valve opening of the {first_damper} at {v_hil:.0} km/h, {hil_what} (each \
             panel names its valve)"
        ),
        OPENING_AXIS,
        &hil_runs,
        &opening,
        1.0,
        None,
    )? {
        figures.push((
            s,
            "the valves' actual openings on the ideal track, slow and ideal valve (Fig. 5.25; the command beside the opening: skyhook_valve_zoom.svg)",
        ));
    }

    // Fig. 5.25: zoom on the on/off sky-hook's command and the valve's actual opening
    let slow = scenario::hil("skyhook_onoff_slow");
    if let (Some(cmd), Some(open), Some(disp)) = (
        series(r, &slow, &command, 0.1),
        series(r, &slow, &opening, 1.0),
        series(r, &slow, ws_y, 1e3),
    ) {
        // the second where the wheelset moves most: the sign law of (3.6) does not depend on
        // the amplitude, so once the hunting has died out the command keeps switching on a
        // motion of nanometres, and the second where it switches most shows nothing physical
        let t0 = busiest_second(&disp);
        let zoom = |s: &[(f64, f64)]| between(s, t0, t0 + 1.0);
        let peak_mm = zoom(&disp).iter().fold(0.0_f64, |m, p| m.max(p.1.abs()));
        write_series_csv(
            &out.join(format!("{}.csv", stem::SKYHOOK_VALVE_ZOOM)),
            &[
                ("slow valve: command / 10 V [-]".into(), cmd.clone()),
                ("slow valve: actual opening [-]".into(), open.clone()),
                ("leading wheelset displacement [mm]".into(), disp.clone()),
            ],
        )?;
        publish(
            Chart::new(
                &format!(
                    "on/off sky-hook, slow valve, {v_hil:.0} km/h, {hil_what}: command and actual \
                 opening over {t0:.0}-{:.0} s, the second where the leading wheelset moves most \
                 (up to {peak_mm:.2} mm; {:.0} Hz samples)",
                    t0 + 1.0,
                    r.settings.stored_rate_hz
                ),
                "time [s]",
                OPENING_LABEL,
            )
            .with_series("slow valve: command / 10 V", zoom(&cmd))
            .with_series("slow valve: actual opening", zoom(&open)),
            out,
            stem::SKYHOOK_VALVE_ZOOM,
            "on/off sky-hook: the slow valve cannot follow the switching command (Fig. 5.25, R12)",
            figures,
        )?;
    }
    Ok(())
}

/// The full-active damper's c_v sensitivity (Table 4-3): its CSV and two figures.
pub(super) fn cv_figures(
    r: &StudyResults,
    out: &Path,
    figures: &mut Vec<(String, &'static str)>,
) -> Result<(), StudyError> {
    // ---- c_v sensitivity (Table 4-3)
    let cv_header: Vec<String> = [
        "c_v [kNs/m]",
        "rms acc [m/s2]",
        "F_max [kN]",
        "rms force [kN]",
        "peak reference c_v v [kN]",
        "rms power F v [kW]",
        "rms hydraulic power [kW]",
        "seed rms acc [m/s2]",
        "seed F_max [kN]",
        "seed rms power [kW]",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let cv_rows: Vec<Vec<f64>> =
        r.cv.iter()
            .map(|c| {
                let cv = c.c_v_nspm.unwrap_or(f64::NAN) / 1e3;
                let m = c.metrics.as_ref();
                let seed = SEED_TABLE_4_3
                    .iter()
                    .find(|s| (s.0 - cv).abs() < 0.5)
                    .copied()
                    .unwrap_or((cv, f64::NAN, f64::NAN, f64::NAN));
                vec![
                    cv,
                    m.map_or(f64::NAN, |m| m.rms()),
                    m.map_or(f64::NAN, |m| m.peak_force_n / 1e3),
                    m.and_then(|m| m.rms_force_n).map_or(f64::NAN, |f| f / 1e3),
                    m.and_then(|m| m.peak_reference_force_n)
                        .map_or(f64::NAN, |f| f / 1e3),
                    m.and_then(|m| m.rms_power_w).map_or(f64::NAN, |p| p / 1e3),
                    m.and_then(|m| m.rms_hydraulic_power_w)
                        .map_or(f64::NAN, |p| p / 1e3),
                    seed.1,
                    seed.2,
                    seed.3,
                ]
            })
            .collect();
    write_csv_atomic(
        &out.join("cv_sensitivity.csv"),
        &cv_header,
        cv_rows.iter().map(Vec::as_slice),
    )?;
    // Table 4-3 as figures: ours beside the seed's, the trend R14 compares
    let ours = |col: usize| -> Vec<(f64, f64)> {
        cv_rows
            .iter()
            .filter(|row| row[0].is_finite() && row[col].is_finite())
            .map(|row| (row[0], row[col]))
            .collect()
    };
    let v_cv = r.settings.cv_speed_kmh;
    let ours_label = format!("ours, {v_cv:.0} km/h");
    // the data behind each figure: columns of the c_v table
    let columns_csv = |stem: &str, cols: &[usize]| {
        let header: Vec<String> = cols.iter().map(|&c| cv_header[c].clone()).collect();
        let rows: Vec<Vec<f64>> = cv_rows
            .iter()
            .map(|row| cols.iter().map(|&c| row[c]).collect())
            .collect();
        write_csv_atomic(
            &out.join(format!("{stem}.csv")),
            &header,
            rows.iter().map(Vec::as_slice),
        )
    };
    let (acceleration, peak, reference) = (ours(1), ours(2), ours(4));
    if acceleration.len() >= 2 {
        columns_csv(stem::CV_ACCELERATION, &[0, 1, 7])?;
        let chart = Chart::new(
            "full-active c_v sensitivity: EN 14363 rms acceleration (Table 4-3)",
            "c_v [kNs/m]",
            "rms acceleration [m/s^2]",
        )
        .with_markers()
        .with_series(&ours_label, acceleration)
        // the seed in grey in both c_v figures (a colour there means one of ours)
        .with_reference(
            "seed (Table 4-3, speed not given)",
            SEED_TABLE_4_3.iter().map(|s| (s.0, s.1)).collect(),
        )
        .with_limit(r.limit_mps2, &format!("a_lim = {:.2} m/s^2", r.limit_mps2));
        publish(
            chart,
            out,
            stem::CV_ACCELERATION,
            "full-active: rms acceleration vs c_v, ours and the seed's (Table 4-3, R14)",
            figures,
        )?;
    }
    if peak.len() >= 2 {
        columns_csv(stem::CV_FORCE, &[0, 2, 4, 8])?;
        let bound = ActuatorBound::of_default_actuator();
        let mut chart = Chart::new(
            "full-active c_v sensitivity: peak actuator force (Table 4-3)",
            "c_v [kNs/m]",
            "force [kN]",
        )
        .with_markers()
        // from 0: the peaks' spread reads against their size (the seed's 81-98 % of the bound)
        .with_y_from_zero()
        .with_series(&format!("{ours_label}: F_max"), peak);
        if reference.len() >= 2 {
            chart = chart.with_series(&format!("{ours_label}: peak reference c_v v"), reference);
        }
        let chart = chart
            .with_reference(
                "seed (Table 4-3, speed not given): F_max",
                SEED_TABLE_4_3.iter().map(|s| (s.0, s.2)).collect(),
            )
            .with_limit(
                bound.force_n / 1e3,
                &format!(
                    "force bound {:.1} kN ({:.0} bar on {:.2} cm^2)",
                    bound.force_n / 1e3,
                    bound.pressure_bar,
                    bound.area_cm2
                ),
            );
        publish(
            chart,
            out,
            stem::CV_FORCE,
            "full-active: peak force vs c_v against the actuator's force bound, ours and the seed's (Table 4-3, R14)",
            figures,
        )?;
    }
    Ok(())
}

/// The sampling rate of equally spaced points [Hz] (`None` for fewer than two, or no span).
fn rate_of(s: &[(f64, f64)]) -> Option<f64> {
    let span = s.last()?.0 - s.first()?.0;
    (span > 0.0).then(|| (s.len() - 1) as f64 / span)
}

/// The points of a time series from `t0` on (zoomed figures).
fn from_time(s: &[(f64, f64)], t0: f64) -> Vec<(f64, f64)> {
    s.iter().filter(|p| p.0 >= t0).copied().collect()
}

/// The points of `s` from `t0` to `t1`, both included.
pub(super) fn between(s: &[(f64, f64)], t0: f64, t1: f64) -> Vec<(f64, f64)> {
    s.iter()
        .filter(|p| p.0 >= t0 && p.0 <= t1 + 1e-9)
        .copied()
        .collect()
}

/// Start of the whole second of `s` (from its first time on) where its values vary most
/// (largest standard deviation); the last whole second when none varies.
pub(super) fn busiest_second(s: &[(f64, f64)]) -> f64 {
    let (Some(first), Some(last)) = (s.first(), s.last()) else {
        return 0.0;
    };
    let seconds = (last.0 - first.0).floor().max(1.0) as usize;
    let spread = |t0: f64| {
        let w = between(s, t0, t0 + 1.0);
        let n = w.len().max(1) as f64;
        let mean = w.iter().map(|p| p.1).sum::<f64>() / n;
        w.iter().map(|p| (p.1 - mean).powi(2)).sum::<f64>() / n
    };
    let mut best = (last.0 - 1.0).max(first.0);
    let mut most = spread(best);
    for k in 0..seconds {
        let t0 = first.0 + k as f64;
        let v = spread(t0);
        if v > most {
            (best, most) = (t0, v);
        }
    }
    best
}
