use super::*;
use crate::study::critical::Critical;
use crate::study::metrics::RunMetrics;
use crate::study::run::{scenario, ConfigResult, NamedRun, SpeedPoint, HISTORY_DETAIL_S};
use crate::study::settings::StudySettings;
use crate::study::vehicle::{Signals, VehicleModel};
use std::collections::BTreeMap;

fn metrics(rms: f64, amp: f64, cmd: Option<f64>) -> RunMetrics {
    RunMetrics {
        rms_by_signal: vec![rms, rms * 0.9],
        frequency_hz: 4.0,
        tail_amplitude_m: amp,
        max_displacement_m: amp * 1.2,
        peak_force_n: 20e3,
        rms_force_n: Some(5e3),
        peak_reference_force_n: None,
        rms_power_w: Some(250.0),
        rms_hydraulic_power_w: Some(8000.0),
        tail_command_v: cmd,
        tail_command_by_damper_v: cmd.into_iter().collect(),
        carbody_rms_mps2: None,
        comfort_ny: None,
        damper_stroke_m: None,
    }
}

fn results() -> StudyResults {
    results_on(VehicleModel::Bogie2Dof)
}

fn results_on(vehicle: VehicleModel) -> StudyResults {
    let cfg = |id: &'static str, k: Critical| {
        let c = configuration(id).unwrap();
        ConfigResult {
            id: c.id,
            label: c.label,
            seed_value: c.seed_value,
            reference: c.reference,
            sweep: vec![
                SpeedPoint {
                    speed_kmh: 280.0,
                    per_seed: vec![Some(3.0), Some(2.0)],
                    carbody_per_seed: vec![Some(0.2), Some(0.25)],
                    comfort_per_seed: vec![Some(1.5), Some(1.25)],
                    stroke_per_seed: vec![Some(1.2e-3), Some(1.5e-3)],
                },
                SpeedPoint {
                    speed_kmh: 290.0,
                    per_seed: vec![Some(6.0), None],
                    carbody_per_seed: vec![Some(0.5), None],
                    comfort_per_seed: vec![Some(3.0), None],
                    stroke_per_seed: vec![Some(4.0e-3), None],
                },
            ],
            bisection: vec![],
            critical: Some(k),
        }
    };
    let named =
        |name: &str, config: &'static str, v: f64, cv: Option<f64>, m: Option<RunMetrics>| {
            NamedRun {
                name: name.into(),
                config,
                speed_kmh: v,
                c_v_nspm: cv,
                error: m.is_none().then(|| "boom".to_string()),
                metrics: m,
            }
        };
    StudyResults {
        settings: StudySettings {
            speeds_kmh: vec![280.0, 290.0],
            ..StudySettings::quick(vehicle)
        },
        limit_mps2: 5.39,
        configs: vec![
            cfg(
                "passive",
                Critical::Between {
                    stable_kmh: 280.0,
                    unstable_kmh: 290.0,
                },
            ),
            cfg("mppt2", Critical::Above { max_kmh: 400.0 }),
        ],
        perturbation: vec![named(
            "perturbation-passive_v220_ideal",
            "passive",
            220.0,
            None,
            Some(metrics(0.1, 1e-4, None)),
        )],
        cv: vec![
            named(
                "cv-210",
                "full_active",
                380.0,
                Some(210e3),
                Some(metrics(7.0, 5e-3, None)),
            ),
            named("cv-270", "full_active", 380.0, Some(270e3), None),
        ],
        scenarios: vec![named(
            "hil-mppt2_slow",
            "mppt2_slow",
            260.0,
            None,
            Some(metrics(1.0, 1e-3, Some(3.5))),
        )],
        failures: vec![("cv-270".into(), "boom".into())],
        runs: 7,
        simulated_s: 70.0,
        run_wall_s: 10.0,
        kept: BTreeMap::new(),
        kept_tail: BTreeMap::new(),
    }
}

#[test]
fn report_has_the_tables_the_timing_and_the_failures() {
    let r = results();
    let t = Timing {
        wall_s: 7.0,
        threads: 2,
    };
    assert!((t.sim_per_wall(&r) - 10.0).abs() < 1e-12);
    assert_eq!(gain_over_passive(&r, "mppt2"), Some(110.0));
    let md = report_markdown(&r, &t, &[("rms_vs_speed".into(), "caption")]);
    for s in [
        "| passive (valve 30 % open) | 290.0 (stable at 280.0) | - | - | 280-300 km/h | R8 |",
        "| MPPT2, ideal valve | > 400 | - | >= +110 |",
        "**10.0 simulated seconds per wall-clock second**",
        "| 210 | 7.00 | 20.0 | 5.00 | - | 0.250 | 8.00 | 7.08 | 20.4 | 0.357 |",
        "| 270 | failed | failed | failed | failed | failed | failed | 5.98 |",
        "| hil-mppt2_slow (MPPT2, slow valve) | 260 | 3.50 | 1.00 |",
        "`cv-270`: boom",
        "`rms_vs_speed.svg`",
        "Track seed 1, one run per c_v.",
    ] {
        assert!(md.contains(s), "missing {s:?} in\n{md}");
    }
    // over several seeds each c_v row is their worst, and the report says so
    let mut two = r.clone();
    two.settings.seeds = vec![1, 2];
    let md = report_markdown(&two, &t, &[]);
    assert!(
        md.contains("Each row is the largest over the track seeds 1, 2 (one run per seed)"),
        "{md}"
    );
}

#[test]
fn speeds_within_the_limit_above_a_burst_are_listed_as_ranges() {
    let point = |v: f64, rms: Option<f64>| SpeedPoint {
        speed_kmh: v,
        per_seed: vec![rms],
        carbody_per_seed: vec![],
        comfort_per_seed: vec![],
        stroke_per_seed: vec![],
    };
    let mut c = results().configs.remove(0);
    c.sweep = vec![
        point(290.0, Some(3.0)),
        point(300.0, Some(6.0)), // burst: first exceedance
        point(310.0, Some(4.0)),
        point(320.0, Some(5.0)),
        point(330.0, Some(5.5)),
        point(340.0, Some(2.0)),
        point(350.0, None), // failed run: not counted as within the limit
    ];
    c.critical = Some(Critical::Between {
        stable_kmh: 295.0,
        unstable_kmh: 297.5,
    });
    assert_eq!(within_limit_above(&c, 5.39), "310-320, 340");
    c.critical = Some(Critical::Above { max_kmh: 350.0 });
    assert_eq!(within_limit_above(&c, 5.39), "-");
    c.critical = Some(Critical::Between {
        stable_kmh: 335.0,
        unstable_kmh: 345.0,
    });
    assert_eq!(within_limit_above(&c, 5.39), "-");
}

/// Every output file of `r` written into a new temporary folder, and the report's text.
fn outputs_of(r: &StudyResults) -> (tempfile::TempDir, String) {
    let d = tempfile::tempdir().unwrap();
    let timing = Timing {
        wall_s: 1.0,
        threads: 1,
    };
    let text = write_outputs(r, d.path(), &timing).unwrap();
    (d, text)
}

#[test]
fn outputs_are_written_even_without_time_histories() {
    let r = results();
    let (d, text) = outputs_of(&r);
    assert!(text.contains("Critical speeds"));
    for f in [
        "REPORT.md",
        "rms_vs_speed.csv",
        "rms_vs_speed.svg",
        "cv_sensitivity.csv",
        "study.json",
    ] {
        assert!(d.path().join(f).exists(), "{f}");
    }
    let csv = std::fs::read_to_string(d.path().join("rms_vs_speed.csv")).unwrap();
    assert!(
        csv.contains("passive,sweep,290,failed,6.0000,failed"),
        "{csv}"
    );
    assert!(!d.path().join("history_displacement.svg").exists());
}

#[test]
fn every_file_the_outputs_write_is_one_a_new_study_removes_first() {
    let names = output_files();
    for vehicle in [VehicleModel::Bogie2Dof, VehicleModel::Coach] {
        let (d, _) = outputs_of(&results_on(vehicle));
        for e in std::fs::read_dir(d.path()).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            assert!(names.contains(&name), "{vehicle:?}: {name} is not listed");
        }
    }
}

#[test]
fn the_coach_report_has_the_car_body_beside_the_en14363_verdict() {
    let r = results_on(VehicleModel::Coach);
    assert_eq!(comfort_speeds(&r), [280.0, 290.0]);
    let md = report_markdown(
        &r,
        &Timing {
            wall_s: 1.0,
            threads: 1,
        },
        &[],
    );
    for s in [
        "on the coach",
        "## Car body: lateral acceleration and ride comfort",
        "| passive (valve 30 % open) | 280 | 3.00 | met | 0.250 | 1.50 | 1.50 |",
        "| passive (valve 30 % open) | 290 | failed | run failed | failed | failed | - |",
        "R16, Figs. 4.4-4.6",
        DIFFERENCES_COACH,
    ] {
        assert!(md.contains(s), "missing {s:?} in\n{md}");
    }
    assert!(!report_markdown(
        &results(),
        &Timing {
            wall_s: 1.0,
            threads: 1
        },
        &[]
    )
    .contains("Car body"));
    let (d, _) = outputs_of(&r);
    for f in ["carbody_vs_speed.svg", "comfort_vs_speed.svg"] {
        assert!(d.path().join(f).exists(), "{f}");
    }
    // figures over speed: a panel per control family present, the passive damper in each
    for f in [
        "rms_vs_speed.svg",
        "carbody_vs_speed.svg",
        "comfort_vs_speed.svg",
    ] {
        let svg = std::fs::read_to_string(d.path().join(f)).unwrap();
        for s in [
            ">\nMPPT\n<",
            ">\npassive (valve 30 % open)\n<",
            ">\nMPPT2, ideal valve\n<",
        ] {
            assert!(svg.contains(s), "{f}: missing {s:?}");
        }
        assert!(
            !svg.contains(">\nfull-active\n<"),
            "{f}: a panel without a curve"
        );
    }
    let csv = std::fs::read_to_string(d.path().join("rms_vs_speed.csv")).unwrap();
    assert!(
        csv.contains("passive,sweep,280,3.0000,3.0000,2.0000,0.2500,1.5000,1.5000"),
        "{csv}"
    );
}

#[test]
fn force_bound_note_names_the_saturated_gains_from_the_runs() {
    let bound = ActuatorBound::of_default_actuator();
    // 100 bar on the 25.16 cm^2 annulus of Table 3-2
    assert!((bound.force_n - 25_160.0).abs() < 1.0, "{bound:?}");
    let mut r = results_on(VehicleModel::Coach);
    assert_eq!(force_bound_note(&r.cv), None, "no reference recorded");
    let with_reference = |cv: f64, peak: f64, reference: f64| NamedRun {
        name: format!("cv-{cv:.0}"),
        config: "full_active",
        speed_kmh: 380.0,
        c_v_nspm: Some(cv * 1e3),
        error: None,
        metrics: Some(RunMetrics {
            peak_force_n: peak,
            peak_reference_force_n: Some(reference),
            ..metrics(2.0, 1e-3, None)
        }),
    };
    r.cv = vec![
        with_reference(210.0, 22.3e3, 32.3e3),
        with_reference(390.0, 19.0e3, 21.4e3),
    ];
    let note = force_bound_note(&r.cv).unwrap();
    for s in [
        "piston give 25.2 kN",
        "At c_v 210 / 390 kNs/m",
        "up to 32.3 / 21.4 kN",
        "delivered up to 22.3 / 19.0 kN",
        "exceeded the bound at c_v 210 kNs/m",
        "81 / 93 / 92 / 98 %",
    ] {
        assert!(note.contains(s), "missing {s:?} in {note}");
    }
    let md = report_markdown(
        &r,
        &Timing {
            wall_s: 1.0,
            threads: 1,
        },
        &[],
    );
    assert!(md.contains(&note), "the report carries the note");
    // Table 4-3 as figures, with the table's columns behind them
    let (d, text) = outputs_of(&r);
    let svg = std::fs::read_to_string(d.path().join("cv_force.svg")).unwrap();
    for s in [
        "force bound 25.2 kN (100 bar on 25.16 cm^2)",
        "seed (Table 4-3, speed not given): F_max",
        "ours, 380 km/h: peak reference c_v v",
    ] {
        assert!(svg.contains(s), "cv_force.svg: missing {s:?}");
    }
    let csv = std::fs::read_to_string(d.path().join("cv_force.csv")).unwrap();
    assert_eq!(
        csv.lines().collect::<Vec<_>>(),
        [
            "c_v [kNs/m],F_max [kN],peak reference c_v v [kN],seed F_max [kN]",
            "210,22.3,32.3,20.369",
            "390,19,21.4,24.57"
        ]
    );
    assert!(d.path().join("cv_acceleration.svg").exists());
    assert!(
        text.contains("`cv_force.svg` (data `cv_force.csv`)"),
        "{text}"
    );
}

#[test]
fn the_valve_zoom_takes_the_second_where_the_command_switches() {
    // switching from 0 to 33 s, then settled (the coach's sky-hook on the slow valve)
    let cmd: Vec<(f64, f64)> = (0..4000)
        .map(|i| {
            let t = i as f64 * 0.01;
            let amplitude = if t < 33.0 { 1.0 + t / 100.0 } else { 1e-20 };
            (t, amplitude * (t * 40.0).sin())
        })
        .collect();
    assert_eq!(super::busiest_second(&cmd), 32.0);
    // nothing varies: the last second
    let flat: Vec<(f64, f64)> = (0..4001).map(|i| (i as f64 * 0.01, 0.0)).collect();
    assert_eq!(super::busiest_second(&flat), 39.0);
    let w = super::between(&flat, 39.0, 40.0);
    assert_eq!((w.len(), w[0].0, w[100].0), (101, 39.0, 40.0));
    assert_eq!(super::busiest_second(&[]), 0.0);
}

/// Each time history has a detail figure over the last 2 s of the same runs at the full
/// recorded rate (its CSV holds those rows, the whole figure's the stored ones), and the report
/// shows both.
#[test]
fn time_histories_have_a_detail_figure_of_their_last_two_seconds() {
    let mut r = results();
    let column = Signals::of(VehicleModel::Bogie2Dof).displacements[0].clone();
    let run = |fs: f64, t0: f64, t_end: f64| {
        let n = ((t_end - t0) * fs).round() as usize + 1;
        let data: Vec<f64> = (0..n)
            .flat_map(|k| {
                let t = t0 + k as f64 / fs;
                [t, 5e-3 * (2.0 * std::f64::consts::PI * 4.0 * t).sin()]
            })
            .collect();
        crate::study::run::recorded(vec!["time [s]".into(), format!("{column} [m]")], data)
    };
    let name = scenario::history("passive");
    r.kept.insert(name.clone(), run(100.0, 0.0, 40.0));
    r.kept_tail.insert(name, run(1000.0, 38.0, 40.0));
    let (d, text) = outputs_of(&r);
    let times = |stem: &str| -> Vec<f64> {
        std::fs::read_to_string(d.path().join(format!("{stem}.csv")))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect()
    };
    let whole = times(stem::HISTORY_DISPLACEMENT);
    assert_eq!((whole.len(), whole[0], whole[4000]), (4001, 0.0, 40.0));
    let detail = times(stem::HISTORY_DISPLACEMENT_DETAIL);
    assert_eq!(
        (detail.len(), detail[0], detail[detail.len() - 1]),
        (2001, 38.0, 40.0)
    );
    let svg = std::fs::read_to_string(d.path().join("history_displacement_detail.svg")).unwrap();
    assert!(
        svg.contains("over the last 2 s") && svg.contains("1000 Hz") && svg.contains("time [s]"),
        "{svg}"
    );
    let svg = std::fs::read_to_string(d.path().join("history_displacement.svg")).unwrap();
    assert!(svg.contains("(100 Hz"), "{svg}");
    assert!(text.contains("history_displacement_detail.svg"), "{text}");
    assert!(
        super::HISTORY_DETAIL_CAPTION.contains(&format!("last {HISTORY_DETAIL_S:.0} s")),
        "the caption names another window than HISTORY_DETAIL_S"
    );
    // a run whose tail has other times (ended early): no detail figure, none in the report
    r.kept_tail
        .insert(scenario::history("mppt2"), run(1000.0, 37.0, 39.0));
    r.kept
        .insert(scenario::history("mppt2"), run(100.0, 0.0, 39.0));
    let (d, text) = outputs_of(&r);
    assert!(d.path().join("history_displacement.svg").is_file());
    assert!(!d.path().join("history_displacement_detail.svg").exists());
    assert!(!text.contains("history_displacement_detail"), "{text}");
}

#[test]
fn the_moving_mean_of_a_switching_signal_is_its_duty_cycle() {
    // 0/10 V switching every 10 ms (100 Hz samples): on a third of the time
    let s: Vec<(f64, f64)> = (0..1000)
        .map(|k| (k as f64 * 0.01, if k % 3 == 0 { 10.0 } else { 0.0 }))
        .collect();
    let m = super::moving_mean(&s, 0.5);
    assert_eq!(m.len(), s.len());
    for &(t, v) in &m[50..950] {
        assert!((v - 10.0 / 3.0).abs() < 0.2, "{t}: {v}");
    }
    // the ends average what the window holds
    assert!((m[0].1 - 10.0 * 9.0 / 26.0).abs() < 1e-12, "{}", m[0].1);
    assert!(super::moving_mean(&[(0.0, 2.0)], 0.5) == [(0.0, 2.0)]);
    // a NaN is left out of its windows only
    let mut gap = s.clone();
    gap[500].1 = f64::NAN;
    let m = super::moving_mean(&gap, 0.5);
    assert!(m.iter().all(|p| p.1.is_finite()));
    assert!((m[900].1 - 10.0 / 3.0).abs() < 0.2, "{}", m[900].1);
}
