//! EN 14363 running-stability assessment for Python (`railfmu.assess_stability`): the same
//! computation and the same checks as `master assess` (`rail_study::analysis::assess`), on a
//! results file or on columns the caller holds (a run's results in memory). Options and the
//! answer cross as JSON.

use std::path::{Path, PathBuf};

use master::decimation::Sampling;
use rail_study::analysis::assess::{assess_checked, BandRemark, ResultsTable};
use rail_study::commands::assess::{AssessNumbers, Quantity};
use rail_study::en14363::StabilitySettings;
use serde::{Deserialize, Serialize};

/// What to assess and how (the options of `master assess`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AssessOptions {
    /// Column names, with or without their " [unit]".
    pub signals: Vec<String>,
    /// Constant speed over the record [km/h].
    pub speed_kmh: f64,
    /// "acceleration" (limit from the bogie mass) or "guiding_force" (from the wheel load).
    pub quantity: String,
    pub bogie_mass_t: f64,
    /// Needed for guiding forces only.
    pub wheel_load_kn: Option<f64>,
    /// Start-up excluded \[s\].
    pub skip_s: f64,
    /// Dominant frequency instead of the spectrum's peak \[Hz\].
    pub f0_hz: Option<f64>,
    /// Assess although the recorded band is narrower than the assessed one (a warning).
    pub accept_narrow_band: bool,
}

/// One signal's assessment.
#[derive(Debug, Clone, Serialize)]
pub struct SignalAnswer {
    pub name: String,
    pub dominant_frequency_hz: f64,
    pub band_hz: (f64, f64),
    pub max_rms: f64,
    pub stable: bool,
    /// Centre of each 100 m window along the track from the record's first sample \[m\] (the
    /// skipped start-up included).
    pub window_centre_m: Vec<f64>,
    pub rms: Vec<f64>,
}

/// The verdict over all signals.
#[derive(Debug, Clone, Serialize)]
pub struct AssessAnswer {
    pub quantity: String,
    /// "m/s2" or "kN".
    pub unit: &'static str,
    pub speed_kmh: f64,
    pub limit: f64,
    pub max_rms: f64,
    pub stable: bool,
    /// The band check's note (no sampling record) or, with `accept_narrow_band`, its warning.
    pub notes: Vec<String>,
    pub signals: Vec<SignalAnswer>,
}

/// The table of columns held in memory: `names[0]` is the time; `full_rate`: every
/// communication point of a run is there (no decimation), so the recorded band is the
/// Nyquist frequency.
pub fn table_from_columns(
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
    full_rate: bool,
) -> Result<ResultsTable, String> {
    if names.len() != columns.len() || names.len() < 2 {
        return Err(format!(
            "{} names for {} columns: a time column and at least one signal are needed",
            names.len(),
            columns.len()
        ));
    }
    let rows = columns[0].len();
    if columns.iter().any(|c| c.len() != rows) {
        return Err("columns of different lengths".into());
    }
    let mut table = ResultsTable {
        path: PathBuf::from("<results in memory>"),
        names,
        columns,
        sampling: None,
        described: full_rate,
        recorded_speed: None,
        text_columns: Vec::new(),
    };
    if full_rate {
        table.sampling = Some(Sampling::full_rate(
            table.sampling_rate_hz().map_err(|e| e.to_string())?,
        ));
    }
    Ok(table)
}

/// As [`table_from_columns`] from the row-major values of `names.len()` columns.
pub fn table_from_rows(
    names: Vec<String>,
    data: &[f64],
    full_rate: bool,
) -> Result<ResultsTable, String> {
    let n = names.len().max(1);
    if !data.len().is_multiple_of(n) {
        return Err(format!(
            "{} values do not fill rows of {n} columns",
            data.len()
        ));
    }
    let columns = (0..n)
        .map(|j| data.iter().skip(j).step_by(n).copied().collect())
        .collect();
    table_from_columns(names, columns, full_rate)
}

/// The table of a results file (CSV, whitespace separated, or Parquet).
pub fn table_from_file(path: &Path) -> Result<ResultsTable, String> {
    ResultsTable::load(path).map_err(|e| e.to_string())
}

/// The options the computation would refuse, named as the arguments of
/// `railfmu.assess_stability` (the same checks as `master assess`).
fn check_options(o: &AssessOptions, quantity: Quantity) -> Result<(), String> {
    if o.signals.is_empty() {
        return Err("signals: none given (name at least one column)".into());
    }
    AssessNumbers {
        speed_kmh: ("speed_kmh", o.speed_kmh),
        skip_s: ("skip_s", o.skip_s),
        f0_hz: ("f0_hz", o.f0_hz),
        bogie_mass_t: ("bogie_mass_t", o.bogie_mass_t),
        wheel_load_kn: ("wheel_load_kn", o.wheel_load_kn),
    }
    .check(quantity)
}

/// A message of the assessment with the command's option names replaced by the arguments of
/// `railfmu.assess_stability`.
fn python_names(message: &str) -> String {
    message.replace("--accept-narrow-band", "accept_narrow_band=True")
}

/// Assesses `table` as `master assess` would; `Err` is the message the command would print,
/// naming the arguments of `railfmu.assess_stability` instead of the command's options.
pub fn assess(table: &ResultsTable, options: &AssessOptions) -> Result<AssessAnswer, String> {
    let quantity = match options.quantity.as_str() {
        "acceleration" => Quantity::Acceleration,
        "guiding_force" | "guiding-force" => Quantity::GuidingForce,
        other => {
            return Err(format!(
                "quantity '{other}': expected 'acceleration' or 'guiding_force'"
            ))
        }
    };
    check_options(options, quantity)?;
    let settings = StabilitySettings {
        skip_s: options.skip_s,
        dominant_frequency_hz: options.f0_hz,
        ..StabilitySettings::default()
    };
    let (report, remark) = assess_checked(
        table,
        &options.signals,
        options.speed_kmh,
        quantity.criterion(
            options.bogie_mass_t,
            options.wheel_load_kn.unwrap_or(f64::NAN),
        ),
        &settings,
        options.accept_narrow_band,
    )
    .map_err(|e| python_names(&e.to_string()))?;
    let mut notes = match remark {
        None => Vec::new(),
        Some(BandRemark::Unrecorded(note)) => vec![note],
        Some(BandRemark::Narrow(e)) => vec![format!(
            "{} (assessed anyway: accept_narrow_band; the rms may be wrong)",
            python_names(&e.to_string())
        )],
    };
    notes.extend(report.notes());
    Ok(AssessAnswer {
        quantity: options.quantity.clone(),
        unit: report.unit(),
        speed_kmh: report.speed_kmh,
        limit: report.limit(),
        max_rms: report.max_rms(),
        stable: report.stable(),
        notes,
        signals: report
            .signals
            .iter()
            .map(|(name, a)| SignalAnswer {
                name: name.clone(),
                dominant_frequency_hz: a.dominant_frequency_hz,
                band_hz: a.band_hz,
                max_rms: a.max_rms,
                stable: a.stable,
                window_centre_m: a.rms.iter().map(|w| w.0).collect(),
                rms: a.rms.iter().map(|w| w.1).collect(),
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn options(signal: &str) -> AssessOptions {
        AssessOptions {
            signals: vec![signal.into()],
            speed_kmh: 300.0,
            quantity: "acceleration".into(),
            bogie_mass_t: 6.1,
            wheel_load_kn: None,
            skip_s: 0.0,
            f0_hz: None,
            accept_narrow_band: false,
        }
    }

    /// A 4 Hz sine of amplitude `amp` [m/s2] over 10 s at 1 kHz.
    fn sine(amp: f64) -> (Vec<String>, Vec<Vec<f64>>) {
        let t: Vec<f64> = (0..10_000).map(|k| k as f64 * 1e-3).collect();
        let a = t.iter().map(|t| amp * (2.0 * PI * 4.0 * t).sin()).collect();
        (vec!["time [s]".into(), "acc [m/s2]".into()], vec![t, a])
    }

    #[test]
    fn a_sine_has_its_rms_and_the_seeds_limit() {
        let (names, columns) = sine(8.0);
        let table = table_from_columns(names, columns, true).unwrap();
        let a = assess(&table, &options("acc")).unwrap();
        assert!((a.limit - 5.39).abs() < 1e-9, "{}", a.limit);
        // a sine of amplitude 8 has rms 8 / sqrt 2 = 5.657 > 5.39
        // (within 2 %: the largest of the sliding windows, edges of the zero-phase filter)
        assert!(
            (a.max_rms - 8.0 / 2f64.sqrt()).abs() < 0.11,
            "{}",
            a.max_rms
        );
        assert!(!a.stable && a.notes.is_empty());
        let s = &a.signals[0];
        assert!((s.dominant_frequency_hz - 4.0).abs() < 0.1);
        assert_eq!(s.window_centre_m.len(), s.rms.len());
        assert!(!s.rms.is_empty());
        let (names, columns) = sine(7.0);
        let table = table_from_columns(names, columns, true).unwrap();
        assert!(assess(&table, &options("acc")).unwrap().stable);
    }

    #[test]
    fn columns_without_a_sampling_record_get_a_note() {
        let (names, columns) = sine(1.0);
        let table = table_from_columns(names, columns, false).unwrap();
        let a = assess(&table, &options("acc")).unwrap();
        assert_eq!(a.notes.len(), 1, "{:?}", a.notes);
    }

    #[test]
    fn bad_options_and_tables_are_errors_naming_the_cause() {
        let (names, columns) = sine(1.0);
        let table = table_from_columns(names.clone(), columns.clone(), true).unwrap();
        let e = assess(&table, &options("nothing")).unwrap_err();
        assert!(e.contains("nothing"), "{e}");
        let mut o = options("acc");
        o.quantity = "jerk".into();
        assert!(assess(&table, &o).unwrap_err().contains("jerk"));
        // the options are named as the Python arguments, not as the command's options
        type Case = (&'static str, fn(&mut AssessOptions));
        let cases: [Case; 7] = [
            ("signals: none given", |o| o.signals.clear()),
            ("speed_kmh = -1: must be a speed > 0 km/h", |o| {
                o.speed_kmh = -1.0
            }),
            ("skip_s = -1: must be a time >= 0 s", |o| o.skip_s = -1.0),
            ("f0_hz = 0: must be a frequency > 0 Hz", |o| {
                o.f0_hz = Some(0.0)
            }),
            ("bogie_mass_t = 70: must be in (0, 60) t", |o| {
                o.bogie_mass_t = 70.0
            }),
            (
                "wheel_load_kn = -5: must be a static wheel load within 1 .. 300 kN",
                |o| {
                    o.quantity = "guiding_force".into();
                    o.wheel_load_kn = Some(-5.0);
                },
            ),
            ("speed_kmh = NaN", |o| o.speed_kmh = f64::NAN),
        ];
        for (want, change) in cases {
            let mut o = options("acc");
            change(&mut o);
            let e = assess(&table, &o).unwrap_err();
            assert!(e.contains(want) && !e.contains("--"), "{e}");
        }
        assert_eq!(
            python_names("record at a higher rate (or pass --accept-narrow-band to assess anyway)"),
            "record at a higher rate (or pass accept_narrow_band=True to assess anyway)"
        );
        let mut o = options("acc");
        o.skip_s = 9.9;
        assert!(assess(&table, &o).unwrap_err().contains("window"));
        assert!(table_from_columns(vec!["time".into()], vec![vec![0.0]], true).is_err());
        let mut short = columns;
        short[1].pop();
        assert!(table_from_columns(names, short, true).is_err());
    }
}
