use super::*;
use std::f64::consts::PI;

fn sine_table(amp: f64, f: f64, fs: f64, secs: f64, unit: &str) -> String {
    let n = (secs * fs) as usize;
    let mut s = format!("time [s],\"a, quoted [{unit}]\",other [m]\n");
    for k in 0..n {
        let t = k as f64 / fs;
        s.push_str(&format!("{t},{},{}\n", amp * (2.0 * PI * f * t).sin(), 0.0));
    }
    s
}

/// A name given without its unit that fits several columns asks for the unit; a full name
/// that two columns share names the file's fault instead.
#[test]
fn a_column_is_found_by_its_name_and_ambiguity_is_named() {
    let text = "time [s],a [m/s2],a [g],b [m],b [m]\n0,1,2,3,4\n0.1,1,2,3,4\n";
    let t = ResultsTable::parse(text, Path::new("x.csv")).unwrap();
    assert_eq!(t.find("a [g]").unwrap(), 2);
    let e = t.find("a").unwrap_err().to_string();
    assert!(e.contains("give the full name with its unit"), "{e}");
    let e = t.find("b [m]").unwrap_err().to_string();
    assert!(
        e.contains("2 columns are named 'b [m]': the file must name each column once"),
        "{e}"
    );
}

#[test]
fn the_time_column_is_read_in_seconds_or_milliseconds_and_any_other_unit_refused() {
    let in_s = sine_table(6.0, 4.0, 500.0, 10.0, "m/s2");
    let rate = |text: &str| {
        ResultsTable::parse(text, Path::new("x.csv"))
            .unwrap()
            .sampling_rate_hz()
    };
    assert_eq!(rate(&in_s).unwrap(), 500.0);
    // the same samples with the time in ms
    let in_ms: String = in_s
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                l.replace("time [s]", "time [ms]")
            } else {
                let (t, rest) = l.split_once(',').unwrap();
                format!("{},{rest}", t.parse::<f64>().unwrap() * 1e3)
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!((rate(&in_ms).unwrap() - 500.0).abs() < 1e-9);
    let in_min = in_s.replacen("time [s]", "time [min]", 1);
    let e = rate(&in_min).unwrap_err().to_string();
    assert!(
        e.contains("the time column 'time [min]' is in min: give it in s (or ms)"),
        "{e}"
    );
}

/// The lateral-acceleration criterion (6.1 t bogie, 300 km/h) on the quoted column of a
/// sine table of `amp` m/s2 at `f` Hz, `secs` long at 500 Hz.
fn assess_sine(amp: f64, f: f64, secs: f64) -> AssessReport {
    let text = sine_table(amp, f, 500.0, secs, "m/s2");
    let table = ResultsTable::parse(&text, Path::new("x.csv")).unwrap();
    assess_table(
        &table,
        &["a, quoted".to_string()],
        300.0,
        Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
        &StabilitySettings::default(),
    )
    .unwrap()
}

#[test]
fn sine_of_known_rms_is_assessed_against_the_limit() {
    // amplitude 6 m/s2 -> rms 4.24 < 5.39; amplitude 8 -> 5.66 > 5.39
    for (amp, stable) in [(6.0, true), (8.0, false)] {
        let r = assess_sine(amp, 4.0, 10.0);
        let a = &r.signals[0].1;
        assert!((a.dominant_frequency_hz - 4.0).abs() < 0.1, "{a:?}");
        assert!((r.limit() - 5.39).abs() < 1e-12);
        assert!(
            (a.max_rms - amp / 2f64.sqrt()).abs() < 0.02 * amp,
            "{} vs {}",
            a.max_rms,
            amp / 2f64.sqrt()
        );
        assert_eq!(r.stable(), stable);
        let mut files = Artefacts::default();
        r.add_artefacts(&mut files, "covered").unwrap();
        assert_eq!(
            files.names(),
            vec!["assess.csv", "assess.svg", "assess_summary.csv"]
        );
        assert!(r.summary().contains(if stable {
            "verdict: stable"
        } else {
            "verdict: unstable"
        }));
    }
}

/// The guiding-force criterion (70 kN wheel load) on the quoted column of a 20 kN sine
/// table at 300 km/h, its header's unit replaced by `header_unit` (None: no unit).
fn assess_forces(header_unit: Option<&str>) -> Result<AssessReport, AnalysisError> {
    assess_force_sine(20.0, header_unit)
}

/// [`assess_forces`] of a sine of amplitude `amp` (in the header's unit).
fn assess_force_sine(amp: f64, header_unit: Option<&str>) -> Result<AssessReport, AnalysisError> {
    let text = sine_table(amp, 5.0, 500.0, 10.0, "kN");
    let text = match header_unit {
        Some(u) => text.replace("[kN]", &format!("[{u}]")),
        None => text.replace(" [kN]", ""),
    };
    let table = ResultsTable::parse(&text, Path::new("f.csv")).unwrap();
    assess_table(
        &table,
        &["a, quoted".to_string()],
        300.0,
        Criterion::GuidingForces {
            static_wheel_load_n: 70e3,
        },
        &StabilitySettings::default(),
    )
}

#[test]
fn a_band_clamped_below_2_1_hz_is_noted() {
    let at = |f: f64| assess_sine(6.0, f, 20.0);
    assert!(at(4.0).band_notes().is_empty());
    let low = at(1.0);
    let notes = low.band_notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("dominant frequency 1.00 Hz") && notes[0].contains("clamped to 0.1 Hz"),
        "{notes:?}"
    );
    assert!(low.summary().contains("note: signal 'a, quoted'"));
}

#[test]
fn a_column_without_a_unit_is_assessed_with_a_note_saying_what_was_assumed() {
    // 20 kN as N
    let r = assess_force_sine(20e3, None).unwrap();
    assert_eq!(r.unitless, ["a, quoted"]);
    let summary = r.summary();
    assert!(
        summary.contains("note: column 'a, quoted' names no unit: its values were taken in N"),
        "{summary}"
    );
    // the verdict itself says that it rests on an assumed unit
    assert!(
        summary.contains("of the limit; with the unit of 'a, quoted' assumed, see the note)"),
        "{summary}"
    );
    // 20 kN as kN without a unit would pass any limit as N: refused, asking for the unit
    let e = assess_forces(None).unwrap_err().to_string();
    assert!(
        e.contains("column 'a, quoted' names no unit and its largest value is 20")
            && e.contains("likely in kN; name its unit in the header ('a, quoted [kN]'"),
        "{e}"
    );
    // a labelled column gets no note, whatever its size
    let r = assess_forces(Some("kN")).unwrap();
    assert!(r.unit_notes().is_empty() && !r.summary().contains("note:"));
    assert!(!r.summary().contains("assumed"));
    assert!(assess_force_sine(20.0, Some("N")).is_ok());
}

#[test]
fn accelerations_in_g_are_converted() {
    let table = |unit: &str| {
        let text = sine_table(8.0 / 9.806_65, 4.0, 500.0, 10.0, unit);
        ResultsTable::parse(&text, Path::new("g.csv")).unwrap()
    };
    let assess = |t: &ResultsTable| {
        assess_table(
            t,
            &["a, quoted".to_string()],
            300.0,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings::default(),
        )
    };
    let in_g = assess(&table("g")).unwrap();
    let in_si = assess_sine(8.0, 4.0, 10.0);
    let (g, si) = (in_g.max_rms(), in_si.max_rms());
    assert!((g - si).abs() < 1e-9 * si, "{g} vs {si}");
    assert!(assess(&table("m/s\u{b2}")).is_ok());
    let e = assess(&table("m/s")).unwrap_err().to_string();
    assert!(e.contains("wrong unit"), "{e}");
}

#[test]
fn a_given_f0_is_named_as_given_and_a_spectrum_peak_outside_its_band_noted() {
    let text = sine_table(8.0, 4.0, 500.0, 20.0, "m/s2");
    let table = ResultsTable::parse(&text, Path::new("x.csv")).unwrap();
    let with_f0 = |f0: f64| {
        assess_table(
            &table,
            &["a, quoted".to_string()],
            300.0,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings {
                dominant_frequency_hz: Some(f0),
                ..StabilitySettings::default()
            },
        )
        .unwrap()
    };
    // f0 at the hunting frequency: named as given, no note
    let r = with_f0(4.2);
    assert!(
        r.summary().contains("a, quoted: f0 (given) 4.20 Hz"),
        "{}",
        r.summary()
    );
    assert!(r.band_notes().is_empty(), "{:?}", r.band_notes());
    // f0 far from it: the hunting is filtered out, and the note says so
    let r = with_f0(10.0);
    let notes = r.band_notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("f0 = 10.00 Hz was given, but its spectrum peaks at 4.0")
            && notes[0].contains("outside the assessed band 8.00-12.00 Hz"),
        "{notes:?}"
    );
    assert!(r.stable(), "the hunting is out of the band");
    // without f0 the summary names the spectrum's peak
    assert!(assess_sine(8.0, 4.0, 10.0)
        .summary()
        .contains("a, quoted: dominant 4.0"));
}

#[test]
fn window_positions_count_from_the_records_start() {
    let text = sine_table(6.0, 4.0, 500.0, 20.0, "m/s2");
    let table = ResultsTable::parse(&text, Path::new("x.csv")).unwrap();
    let first = |skip_s: f64| {
        let r = assess_table(
            &table,
            &["a, quoted".to_string()],
            300.0,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings {
                skip_s,
                ..StabilitySettings::default()
            },
        )
        .unwrap();
        r.signals[0].1.rms[0].0
    };
    // 2 s at 300 km/h skipped: 166.7 m further along the track
    let shift = first(2.0) - first(0.0);
    assert!((shift - 2.0 * 300.0 / 3.6).abs() < 1e-6, "{shift}");
}

#[test]
fn a_speed_unlike_the_recorded_running_speed_is_refused() {
    let meta: ResultsMetadata = serde_json::from_value(serde_json::json!({
        "version": 1,
        "columns": [],
        "summary": {"steps": 1, "rejected_steps": 0, "simulated_time_s": 1.0,
                    "wall_time_s": 1.0, "realtime_ratio": 1.0},
        "system": {"instances": [
            {"name": "vehicle", "parameters": {"running.speed": 86.111}},
            {"name": "damper", "parameters": {"damper.speed": 3.0}}
        ]}
    }))
    .unwrap();
    assert_eq!(
        recorded_speed(&meta),
        Some(("vehicle.running.speed".to_string(), 86.111))
    );
    // a run set's own value wins over the system's
    let mut run = meta.clone();
    run.parameters
        .insert("vehicle.running.speed".into(), serde_json::json!(83.333));
    assert_eq!(recorded_speed(&run).unwrap().1, 83.333);
    // two vehicles at different speeds: no one speed
    let mut two = meta.clone();
    two.parameters
        .insert("bogie.vehicle.speed".into(), serde_json::json!(50.0));
    assert_eq!(recorded_speed(&two), None);

    let text = sine_table(6.0, 4.0, 500.0, 20.0, "m/s2");
    let mut table = ResultsTable::parse(&text, Path::new("r.csv")).unwrap();
    table.recorded_speed = recorded_speed(&meta);
    let at = |kmh: f64| {
        assess_table(
            &table,
            &["a, quoted".to_string()],
            kmh,
            Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
            &StabilitySettings::default(),
        )
    };
    assert!(at(310.0).is_ok());
    // the m/s value given as km/h
    let e = at(86.111).unwrap_err().to_string();
    assert!(
        e.contains("the speed given, 86.111 km/h, is not the running speed its metadata records: 'vehicle.running.speed' = 86.111 m/s (310 km/h)"),
        "{e}"
    );
}

#[test]
fn forces_in_kn_are_converted_and_wrong_units_refused() {
    let text = sine_table(20.0, 5.0, 500.0, 10.0, "kN");
    let table = ResultsTable::parse(&text, Path::new("f.csv")).unwrap();
    let r = assess_table(
        &table,
        &["a, quoted".to_string()],
        300.0,
        Criterion::GuidingForces {
            static_wheel_load_n: 70e3,
        },
        &StabilitySettings::default(),
    )
    .unwrap();
    // reported in kN: 20 kN amplitude -> 14.1 kN rms against (10 + 2*70/3)/2 = 28.3 kN
    assert!(
        (r.signals[0].1.max_rms - 14.14).abs() < 0.3,
        "{:?}",
        r.signals[0].1.max_rms
    );
    assert!(r.stable());
    let e = assess_table(
        &table,
        &["a, quoted".to_string()],
        300.0,
        Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
        &StabilitySettings::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("wrong unit"), "{e}");
}

#[test]
fn bad_tables_name_the_file_and_line() {
    let p = Path::new("bad.csv");
    let e = ResultsTable::parse("time,a\n0,1\n0.1,x\n", p).unwrap_err();
    assert!(
        e.to_string().contains("bad.csv:3") && e.to_string().contains("'x'"),
        "{e}"
    );
    let e = ResultsTable::parse("time,a\nx,1\n", p).unwrap_err();
    assert!(
        e.to_string().contains("bad.csv:2: 'x' in column 'time'"),
        "{e}"
    );
    // a text column (a recorded String, an Enumeration's item) is left out; asking for it
    // says why
    let csv = "time,model,model (item),a,label\n0,1,nonlinear,2,AA\n0.1,1,nonlinear,3,\n";
    let t = ResultsTable::parse(csv, p).unwrap();
    assert_eq!(t.names, vec!["time", "model", "a"]);
    assert_eq!(t.columns[2], vec![2.0, 3.0]);
    let e = t.find("model (item)").unwrap_err().to_string();
    assert!(
        e.contains("bad.csv:2: 'nonlinear' in column 'model (item)' is not a number"),
        "{e}"
    );
    assert!(e.ends_with("signal 'model (item)' is not numeric"), "{e}");
    let e = t.find("label").unwrap_err().to_string();
    assert!(e.contains("bad.csv:2: 'AA'"), "{e}");
    // a String is quoted by our writer: text whatever it holds (a number, NaN, a line
    // break); a column with a value that is not finite is left out, named when asked for
    let csv = "time,s,t,u,a,b\n0,\"12\",\"NaN\",\"two\nlines\",2,inf\n0.1,\"13\",\"x\",\"y\",3,1\n";
    let t = ResultsTable::parse(csv, p).unwrap();
    assert_eq!(t.names, vec!["time", "a"]);
    assert_eq!(t.columns[1], vec![2.0, 3.0]);
    let e = t.find("b").unwrap_err().to_string();
    assert!(
        e.contains("bad.csv:2: inf in column 'b' is not finite"),
        "{e}"
    );
    let e = t.find("s").unwrap_err().to_string();
    assert!(e.contains("'12' in column 's' is not a number"), "{e}");
    // a quoted field left open is named at the line its record starts on
    let e = ResultsTable::parse("time,a\n0,1\n0.1,\"2\n", p).unwrap_err();
    assert!(
        e.to_string()
            .contains("bad.csv:3: unterminated quoted field"),
        "{e}"
    );
    let e = ResultsTable::parse("time,a\n0,1,2\n", p).unwrap_err();
    assert!(e.to_string().contains("bad.csv:2"), "{e}");
    let e = ResultsTable::parse("time,a\n0,NaN\n", p).unwrap_err();
    assert!(e.to_string().contains("not finite"), "{e}");
    let e = ResultsTable::parse("# only a comment\n", p).unwrap_err();
    assert!(e.to_string().contains("no header"), "{e}");
    // whitespace and semicolons, comments
    let t = ResultsTable::parse("# c\ntime a b\n0 1 2\n1 3 4\n", p).unwrap();
    assert_eq!(t.columns[2], vec![2.0, 4.0]);
    let t = ResultsTable::parse("time;a\n0;1\n", p).unwrap();
    assert_eq!(t.names, vec!["time", "a"]);
    // metadata of another recording: 10 Hz recorded beside a 1 kHz time column
    let mut t = ResultsTable::parse("time,a\n0,1\n0.001,2\n0.002,3\n", p).unwrap();
    t.sampling = Some(Sampling {
        rate_hz: 10.0,
        passband_hz: 5.0,
        decimation: None,
    });
    let e = t.clone().check_recorded_rate().unwrap_err().to_string();
    assert!(
        e.contains("records a sampling rate of 10 Hz") && e.contains("1000 Hz"),
        "{e}"
    );
    t.sampling = Some(Sampling {
        rate_hz: 1000.0,
        passband_hz: 500.0,
        decimation: None,
    });
    assert!(t.check_recorded_rate().is_ok());
    // a whitespace-separated header carries units as the others do
    let t = ResultsTable::parse("time [ms]   a [m/s2]\n0 1\n1 3\n", p).unwrap();
    assert_eq!(t.names, vec!["time [ms]", "a [m/s2]"]);
    assert_eq!(t.columns[1], vec![1.0, 3.0]);
    // unknown signal lists the available ones
    let e = t.find("b").unwrap_err();
    assert!(e.to_string().contains("the signals are: a"), "{e}");
    // non-uniform time
    let t = ResultsTable::parse("time,a\n0,1\n0.1,1\n0.3,1\n0.4,1\n", p).unwrap();
    let e = t.sampling_rate_hz().unwrap_err();
    assert!(e.to_string().contains("not uniformly sampled"), "{e}");
    // one missing sample in a long record is named where it is, against the usual step
    let mut text = String::from("time,a\n");
    for k in (0..1000).filter(|&k| k != 700) {
        text.push_str(&format!("{},1\n", k as f64 * 1e-3));
    }
    let e = ResultsTable::parse(&text, p)
        .unwrap()
        .sampling_rate_hz()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("(step 0.002 s after t = 0.699 s, where the others are 0.001 s)"),
        "{e}"
    );
    // a host's rounded times are uniform: 1024 Hz printed to six decimals, 200 Hz through
    // a float32 column (steps of 0.005000114 s beside 0.005 s), 1024 Hz to 9 digits
    let rounded = |fs: f64, print: &dyn Fn(f64) -> String| {
        let mut text = String::from("time,a\n");
        for k in 0..(20.0 * fs) as usize {
            text.push_str(&format!("{},1\n", print(k as f64 / fs)));
        }
        ResultsTable::parse(&text, p).unwrap().sampling_rate_hz()
    };
    let hz = rounded(1024.0, &|t| format!("{t:.6}")).unwrap();
    assert!((hz - 1024.0).abs() < 1e-3, "{hz}");
    let hz = rounded(200.0, &|t| format!("{}", t as f32)).unwrap();
    assert!((hz - 200.0).abs() < 1e-3, "{hz}");
    // a long float32 column, whose rounding grows with t (1 kHz over 200 s)
    let mut text = String::from("time,a\n");
    for k in 0..200_000 {
        text.push_str(&format!("{},1\n", (k as f64 * 1e-3) as f32));
    }
    let hz = ResultsTable::parse(&text, p)
        .unwrap()
        .sampling_rate_hz()
        .unwrap();
    assert!((hz - 1000.0).abs() < 1e-2, "{hz}");
    assert!(rounded(1024.0, &|t| format!("{t:.8e}")).is_ok());
    // ... but times rounded coarser than the step (1024 Hz to the millisecond) are not
    let e = rounded(1024.0, &|t| format!("{t:.3}")).unwrap_err();
    assert!(e.to_string().contains("not uniformly sampled"), "{e}");
    // a NaN or an infinity inside the time column of columns given as such (Python's
    // assess_stability; a file's are refused when read): a NaN passes every step comparison
    for bad in [f64::NAN, f64::INFINITY] {
        let mut t = ResultsTable::parse("time,a\n0,1\n0.1,1\n0.2,1\n0.3,1\n", p).unwrap();
        t.columns[0][2] = bad;
        let e = t.sampling_rate_hz().unwrap_err().to_string();
        assert!(e.contains("the time column (first column) holds"), "{e}");
        assert!(e.contains("at sample 3"), "{e}");
    }
}

#[test]
fn too_short_records_are_refused() {
    let table = ResultsTable::parse(
        &sine_table(1.0, 4.0, 200.0, 1.0, "m/s2"),
        Path::new("s.csv"),
    )
    .unwrap();
    let e = assess_table(
        &table,
        &["other".to_string()],
        200.0,
        Criterion::LateralAcceleration { bogie_mass_t: 6.1 },
        &StabilitySettings::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("less than one 100 m window"), "{e}");
}
