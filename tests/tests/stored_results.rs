//! The stored results of a study run read back by `master assess` (the same code,
//! [`rail_study::analysis::assess`]): the full-rate Parquet file gives the study's own EN 14363
//! rms and verdict to 0.1 %; the same run stored as CSV decimated to 100 Hz through the
//! anti-aliasing low-pass stays within 1 % of the full-rate rms at the same dominant
//! frequency, closer than plain sample picking, and within 0.5 % with the frequency found in
//! each file; a file decimated below what the assessed band needs is refused. One passive bogie
//! run at 300 km/h on track seed 1 (the scenario runs of the study are cut to 1 s: only the
//! sweep run is assessed). Needs `dist/`; run in release.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use master::decimation::decimate;
use master::parquet_file::read_results_parquet;
use master::results::{write_results, ResultsFormat, RunContext};
use rail_study::analysis::assess::{assess_table, check_bandwidth, Criterion, ResultsTable};
use rail_study::en14363::StabilitySettings;
use rail_study::study::metrics::BOGIE_MASS_T;
use rail_study::study::vehicle::Signals;
use rail_study::study::{run_study, Sources, StudyOptions, StudySettings, VehicleModel};

static CANCEL: AtomicBool = AtomicBool::new(false);

fn dist() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../dist")
}

/// `master assess` on `path` as a user would call it on a study run: every stability signal
/// at the run's speed, the study's start-up skip, the dominant frequency found or `f0`.
/// (verdict stable, max rms, bandwidth check, dominant frequency of the first signal)
fn assess(
    path: &Path,
    settings: &StudySettings,
    f0: Option<f64>,
) -> (bool, f64, Result<Option<String>, String>, f64) {
    let table = ResultsTable::load(path).unwrap();
    let signals = Signals::of(VehicleModel::Bogie2Dof).stability;
    let stability = StabilitySettings {
        skip_s: settings.skip_s,
        dominant_frequency_hz: f0,
        ..StabilitySettings::default()
    };
    let report = assess_table(
        &table,
        &signals,
        300.0,
        Criterion::LateralAcceleration {
            bogie_mass_t: BOGIE_MASS_T,
        },
        &stability,
    )
    .unwrap();
    let band = check_bandwidth(&table, &report).map_err(|e| e.to_string());
    let f = report.signals[0].1.dominant_frequency_hz;
    (report.stable(), report.max_rms(), band, f)
}

#[test]
fn assess_on_a_stored_study_run_gives_the_study_number() {
    if !dist().join("Bogie2Dof.fmu").is_file() {
        panic!("dist/ has no Bogie2Dof.fmu: build the FMUs first (package-fmus)");
    }
    let settings = StudySettings {
        configurations: vec!["passive"],
        speeds_kmh: vec![300.0],
        seeds: vec![1],
        bisection_tol_kmh: None,
        perturbation_speeds_kmh: vec![],
        cv_values_nspm: vec![],
        scenario_stop_s: 1.0,
        ..StudySettings::quick(VehicleModel::Bogie2Dof)
    };
    assert_eq!(settings.stored_format, ResultsFormat::Parquet);
    let out = tempfile::tempdir().unwrap();
    let opts = StudyOptions {
        sources: Sources {
            fmus: dist(),
            systems: None,
        },
        out: out.path().to_path_buf(),
        threads: 2,
        progress: false,
        cancel: &CANCEL,
    };
    let results = run_study(&settings, &opts).unwrap();
    let own = results.config("passive").unwrap().sweep[0].per_seed[0].unwrap();
    let limit = results.limit_mps2;
    let table = out.path().join("runs/main/results");
    let stored: Vec<PathBuf> = std::fs::read_dir(&table)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("sweep-"))
        })
        .collect();
    assert_eq!(stored.len(), 1, "{stored:?}");
    let file = &stored[0];

    // the full-rate Parquet file: the study's number and verdict
    let (stable, rms, band, f0) = assess(file, &settings, None);
    assert!(
        ((rms - own) / own).abs() < 1e-3,
        "assess {rms} vs the study's {own}"
    );
    assert_eq!(stable, own <= limit);
    assert_eq!(band, Ok(None));

    // the same run decimated to 100 Hz through the anti-aliasing filter, stored as CSV
    let (full, meta) = read_results_parquet(file).unwrap();
    let ctx = RunContext {
        run: meta.run.clone(),
        ..RunContext::default()
    };
    let csv = out.path().join("decimated.csv");
    write_results(
        &csv,
        &decimate(&full, 10).unwrap(),
        ResultsFormat::Csv,
        &ctx,
    )
    .unwrap();
    // as a user calls it (dominant frequency found in each file): the Welch segment that finds
    // it lasts 8.192 s at any rate, so the 100 Hz file finds the full-rate frequency and rms
    let (found_stable, found_rms, band, found_f0) = assess(&csv, &settings, None);
    assert_eq!(band, Ok(None));
    eprintln!(
        "assess found: full rate {f0:.5} Hz rms {rms:.5}, 100 Hz {found_f0:.5} Hz rms \
         {found_rms:.5} ({:+.3} %)",
        100.0 * (found_rms / rms - 1.0)
    );
    // measured: 5.9976 against 5.9949 Hz, rms +0.28 % (the anti-aliasing filter's share, as at
    // the given frequency below); with 512-sample segments at 100 Hz the rms differed by 3.2 %
    assert!(
        (found_f0 - f0).abs() < 0.01,
        "dominant frequency at 100 Hz {found_f0} vs full rate {f0}"
    );
    assert!(
        ((found_rms - rms) / rms).abs() < 5e-3,
        "100 Hz file {found_rms} vs full rate {rms}"
    );
    assert_eq!(found_stable, stable);
    // at the full-rate file's frequency the difference is the decimation's alone
    let f0 = Some(f0);
    let (_, full_rms, _, _) = assess(file, &settings, f0);
    let (_, filtered, band, _) = assess(&csv, &settings, f0);
    assert_eq!(band, Ok(None));
    let filtered_err = ((filtered - full_rms) / full_rms).abs();
    assert!(
        filtered_err < 1e-2,
        "100 Hz anti-aliased {filtered} vs full rate {full_rms}"
    );
    // plain sample picking folds the content above 50 Hz into the band: a larger error
    let w = full.header.len();
    let picked = master::coupling::SimOutput {
        data: full
            .data
            .chunks(w)
            .step_by(10)
            .flat_map(|r| r.iter().copied())
            .collect(),
        ..full.clone()
    };
    let picked_csv = out.path().join("picked.csv");
    write_results(&picked_csv, &picked, ResultsFormat::Csv, &ctx).unwrap();
    let (_, picked, _, _) = assess(&picked_csv, &settings, f0);
    let picked_err = ((picked - full_rms) / full_rms).abs();
    assert!(
        picked_err > 2.0 * filtered_err,
        "picked {picked} and anti-aliased {filtered} vs full rate {full_rms}"
    );
    eprintln!(
        "EN 14363 max rms at {f0:?} Hz: full rate {full_rms:.4}, 100 Hz anti-aliased \
         {filtered:.4} ({:+.2} %), 100 Hz picked {picked:.4} ({:+.2} %)",
        100.0 * (filtered / full_rms - 1.0),
        100.0 * (picked / full_rms - 1.0)
    );

    // decimated to 20 Hz the file carries 4.5 Hz at most: below the assessed band, refused
    let narrow = out.path().join("narrow.csv");
    write_results(
        &narrow,
        &decimate(&full, 50).unwrap(),
        ResultsFormat::Csv,
        &ctx,
    )
    .unwrap();
    let table = ResultsTable::load(&narrow).unwrap();
    let sampling = table.sampling.clone().unwrap();
    assert!(sampling.passband_hz < 5.0, "{sampling:?}");
    let report = assess_table(
        &table,
        &Signals::of(VehicleModel::Bogie2Dof).stability,
        300.0,
        Criterion::LateralAcceleration {
            bogie_mass_t: BOGIE_MASS_T,
        },
        &StabilitySettings {
            skip_s: settings.skip_s,
            dominant_frequency_hz: Some(5.0),
            ..StabilitySettings::default()
        },
    )
    .unwrap();
    let e = check_bandwidth(&table, &report).unwrap_err().to_string();
    assert!(
        e.contains("narrow.csv") && e.contains("--accept-narrow-band"),
        "{e}"
    );
}
