use super::*;
use crate::coupling::tests::{two_mass_plan, MassSpring, Mock, SpringDamperMass};
use crate::coupling::{simulate, Algorithm, FailedRun, RunOptions, SimOutput};
use crate::results::ResultsFormat;
use std::sync::atomic::{AtomicBool, Ordering};

const BASE: &str = r#"{
  "instances": [{"name": "ms", "fmu": "MassSpring.fmu"}, {"name": "sdm", "fmu": "SDM.fmu"}],
  "stop_time": 0.1, "step": 0.001
}"#;

fn jobs(rs: &str) -> Result<Vec<Job>, SystemError> {
    let base = LoadedSystem::from_json_str(BASE, Path::new("/d"), "base.json").unwrap();
    let r: RunSet = serde_json::from_str(rs).unwrap();
    r.expand(&base, "set.json")
}

#[test]
fn product_and_list_expand() {
    let j = jobs(
        r#"{"product": {"ms.k": [1, 2, 3], "sdm.m": [true, false]},
                      "runs": [{"name": "extra run", "parameters": {"ms.k": 9}}]}"#,
    )
    .unwrap();
    assert_eq!(j.len(), 7);
    assert_eq!(j[0].name, "run-000");
    assert_eq!(j[6].name, "extra_run");
    let ks: Vec<String> = j[..6]
        .iter()
        .map(|j| format!("{}{}", j.parameters["ms.k"], j.parameters["sdm.m"]))
        .collect();
    assert_eq!(
        ks,
        ["1true", "1false", "2true", "2false", "3true", "3false"]
    );
    // more than 1000 runs: the names widen so that they sort as the runs do
    let values: Vec<String> = (0..1001).map(|i| i.to_string()).collect();
    let many = jobs(&format!(
        r#"{{"product": {{"ms.k": [{}]}}}}"#,
        values.join(",")
    ))
    .unwrap();
    assert_eq!(
        [
            many[0].name.as_str(),
            many[999].name.as_str(),
            many[1000].name.as_str()
        ],
        ["run-0000", "run-0999", "run-1000"]
    );
    assert_eq!(
        j[3].system.instances[0].parameters["k"],
        serde_json::json!(2)
    );
    assert_eq!(
        j[3].system.instances[1].parameters["m"],
        serde_json::json!(false)
    );
    assert_eq!(
        j[0].system.instances[0].fmu,
        PathBuf::from("/d/MassSpring.fmu")
    );
    assert_eq!(jobs("{}").unwrap().len(), 1);
}

#[test]
fn expansion_errors() {
    let e = jobs(r#"{"product": {"xx.k": [1]}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("product.xx.k: unknown instance 'xx'"), "{e}");
    let e = jobs(r#"{"runs": [{"name": "a", "parameters": {}}, {"name": "a", "parameters": {}}]}"#)
        .unwrap_err();
    assert!(e.to_string().contains("used twice"));
    let e = jobs(r#"{"product": {"ms.k": []}}"#).unwrap_err();
    assert!(e.to_string().contains("empty list"));
    let e = RunSet::jobs_from_str(
        "{\"base\": \"a.json\", \"system\": null, \"bogus\": 1}",
        Path::new("/"),
        "s.json",
    )
    .unwrap_err();
    assert!(e.to_string().contains("unknown field `bogus`"), "{e}");
}

#[test]
fn parallel_execution_keeps_every_result_and_reports_failures() {
    let j = jobs(r#"{"product": {"ms.k": [50, 100, -1, 200]}}"#).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // mock runner: the two-mass plan with ms.k from the job; k < 0 fails
    let runner = |job: &Job| -> Result<SimOutput, String> {
        let k = job.parameters["ms.k"].as_f64().unwrap();
        if k < 0.0 {
            return Err("negative stiffness".into());
        }
        let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.1);
        plan.instances[0].parameters[1].1 = k;
        let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
        simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).map_err(|e| e.to_string())
    };
    let reports = execute(&j, dir.path(), 2, false, runner).unwrap();
    assert_eq!(reports.len(), 4);
    assert_eq!(reports.iter().filter(|r| r.ok).count(), 3);
    assert_eq!(reports[2].error.as_deref(), Some("negative stiffness"));
    for r in &reports {
        let d = dir.path().join(&r.name);
        assert!(d.join("system.json").exists() && d.join("summary.json").exists());
        assert_eq!(d.join("results.csv").exists(), r.ok);
    }
    // different stiffness, different results
    let a = std::fs::read_to_string(dir.path().join("run-000/results.csv")).unwrap();
    let b = std::fs::read_to_string(dir.path().join("run-003/results.csv")).unwrap();
    assert_ne!(a, b);
    assert_eq!(a.lines().count(), 102);
    let sweep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("sweep.json")).unwrap())
            .unwrap();
    assert_eq!(sweep.as_array().unwrap().len(), 4);
    assert_eq!(sweep[2]["ok"], serde_json::json!(false));
}

/// An interrupted set starts no further run: the runs not started get a report (sweep.json
/// lists every run) but no folder, and an earlier set's folder or table of their names is
/// removed, not left looking like this set's result.
#[test]
fn an_interrupted_set_starts_no_further_run_and_leaves_no_earlier_result_under_its_names() {
    let j = jobs(r#"{"product": {"ms.k": [50, 100, 200, 400, 800, 1600]}}"#).unwrap();
    for format in [ResultsFormat::Csv, ResultsFormat::Parquet] {
        let dir = tempfile::tempdir().unwrap();
        let opts = ResultsOptions {
            format,
            ..ResultsOptions::default()
        };
        let run = |job: &Job| -> Result<SimOutput, String> {
            let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
            plan.instances[0].parameters[1].1 = job.parameters["ms.k"].as_f64().unwrap();
            let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
            let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
            simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default())
                .map_err(|e| e.to_string())
        };
        // an earlier, complete set of the same names
        let earlier = execute_with(&j, dir.path(), 1, false, &opts, None, run).unwrap();
        assert!(earlier.iter().all(|r| r.ok));
        // this one is interrupted during its second run (one thread: runs in order)
        let cancel = AtomicBool::new(false);
        let started = std::sync::atomic::AtomicUsize::new(0);
        let reports = execute_with(&j, dir.path(), 1, false, &opts, Some(&cancel), |job| {
            if started.fetch_add(1, Ordering::SeqCst) == 1 {
                cancel.store(true, Ordering::SeqCst);
                return Err("cancelled at t = 0.004 s".into());
            }
            run(job)
        })
        .unwrap();
        assert_eq!(started.load(Ordering::SeqCst), 2, "{format:?}");
        assert!(reports[0].ok && !reports[1].ok);
        let sweep: Vec<RunReport> =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("sweep.json")).unwrap())
                .unwrap();
        assert_eq!(sweep.len(), j.len());
        for (r, job) in reports.iter().zip(&j).skip(2) {
            assert_eq!(r.error.as_deref(), Some(NOT_STARTED));
            assert!(r.results.is_none() && r.summary.is_none());
            assert!(
                !dir.path().join(&job.name).exists(),
                "{format:?} {}",
                job.name
            );
            assert!(!results_path(dir.path(), &job.name, format).exists());
            assert!(completed(dir.path(), job, format).is_none());
        }
        // the stopped run has its folder with its error, as any failed run
        assert!(dir.path().join(&j[1].name).join("summary.json").is_file());
    }
}

#[test]
fn parquet_results_of_a_set_share_one_folder_and_a_failed_rerun_leaves_none() {
    let j = jobs(r#"{"product": {"ms.k": [50, 100, 200]}}"#).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let runner = |fail: Option<&'static str>| {
        move |job: &Job| -> Result<SimOutput, String> {
            if Some(job.name.as_str()) == fail {
                return Err("failed this time".into());
            }
            let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.05);
            plan.instances[0].parameters[1].1 = job.parameters["ms.k"].as_f64().unwrap();
            let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
            let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
            simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default())
                .map_err(|e| e.to_string())
        }
    };
    let opts = ResultsOptions {
        format: ResultsFormat::Parquet,
        ..ResultsOptions::default()
    };
    let reports = execute_with(&j, dir.path(), 2, false, &opts, None, runner(None)).unwrap();
    assert!(reports.iter().all(|r| r.ok));
    let table = dir.path().join(PARQUET_FOLDER);
    let mut files: Vec<String> = std::fs::read_dir(&table)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(
        files,
        ["run-000.parquet", "run-001.parquet", "run-002.parquet"]
    );
    assert_eq!(reports.len(), j.len());
    for (r, job) in reports.iter().zip(&j) {
        assert_eq!(r.name, job.name);
        assert!(!dir.path().join(&r.name).join("results.csv").exists());
        assert_eq!(
            r.results.as_deref(),
            Some(table.join(format!("{}.parquet", r.name)).as_path())
        );
        assert!(completed(dir.path(), job, ResultsFormat::Parquet).is_some());
        assert!(completed(dir.path(), job, ResultsFormat::Csv).is_none());
    }
    let (columns, meta) =
        crate::parquet_file::read_parquet(&table.join("run-001.parquet")).unwrap();
    assert_eq!(meta.unwrap().parameters["ms.k"], serde_json::json!(100));
    let k = columns.iter().find(|(n, _)| n == "ms.k").unwrap();
    assert_eq!(
        k.1,
        crate::parquet_file::ColumnData::Numbers(vec![Some(100.0); 51])
    );
    // a rerun in which run-001 fails leaves no stale results of it in the table
    let reports = execute_with(
        &j,
        dir.path(),
        2,
        false,
        &opts,
        None,
        runner(Some("run-001")),
    )
    .unwrap();
    assert!(!reports[1].ok && reports[0].ok);
    assert!(!table.join("run-001.parquet").exists());
    assert!(table.join("run-002.parquet").exists());
    assert!(run_folder_name("Results").is_err());
}

#[test]
fn a_users_file_where_a_runs_table_goes_is_refused_and_a_table_of_another_run_is_run_again() {
    let j = jobs(r#"{"product": {"ms.k": [50, 100]}}"#).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let table = out.join(PARQUET_FOLDER);
    std::fs::create_dir(&table).unwrap();
    // a fresh set, in either format: the user's file is refused before any run, and stays
    std::fs::write(table.join("run-000.parquet"), b"my own table").unwrap();
    for format in [ResultsFormat::Parquet, ResultsFormat::Csv] {
        let e = check_run_folders(&j, out).unwrap_err().to_string();
        assert!(
            e.contains("run-000.parquet") && e.contains("not the table of a run"),
            "{e}"
        );
        let opts = ResultsOptions {
            format,
            ..ResultsOptions::default()
        };
        let ran = execute_with(&j, out, 1, false, &opts, None, |_: &Job| {
            Err::<SimOutput, String>("must not run".into())
        });
        assert!(ran.is_err(), "{format:?}");
        assert_eq!(
            std::fs::read(table.join("run-000.parquet")).unwrap(),
            b"my own table"
        );
    }
    std::fs::remove_file(table.join("run-000.parquet")).unwrap();
    assert_eq!(resume(&j, out, ResultsFormat::Parquet).len(), 2);
    // run-001's table replaced by run-000's: not run-001's result, so run again on resume
    std::fs::copy(table.join("run-000.parquet"), table.join("run-001.parquet")).unwrap();
    assert!(completed(out, &j[0], ResultsFormat::Parquet).is_some());
    assert!(completed(out, &j[1], ResultsFormat::Parquet).is_none());
    assert_eq!(resume(&j, out, ResultsFormat::Parquet), ["run-001"]);
    assert!(completed(out, &j[1], ResultsFormat::Parquet).is_some());
}

#[test]
fn a_new_set_removes_an_earlier_sets_tables_only_not_a_users_parquet_files() {
    let three = jobs(r#"{"product": {"ms.k": [50, 100, 200]}}"#).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    assert_eq!(resume(&three, out, ResultsFormat::Parquet).len(), 3);
    let table = out.join(PARQUET_FOLDER);
    // a user's files beside the tables: a Parquet file of another program (here: a table of
    // ours stripped of its metadata would do as well; any bytes are not ours) and another file
    std::fs::write(table.join("measured_track.parquet"), b"PAR1 not ours PAR1").unwrap();
    std::fs::write(table.join("notes.txt"), b"kept").unwrap();
    // a set of two: the third run's table goes, the user's files stay
    let two = jobs(r#"{"product": {"ms.k": [50, 100]}}"#).unwrap();
    prepare_run_folder(&two, out).unwrap();
    assert_eq!(
        files_under(&table),
        [
            "measured_track.parquet",
            "notes.txt",
            "run-000.parquet",
            "run-001.parquet"
        ]
    );
    // a results folder that is a link is refused before anything is removed
    let elsewhere = tempfile::tempdir().unwrap();
    std::fs::write(elsewhere.path().join("run-009.parquet"), b"x").unwrap();
    let other = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(elsewhere.path(), other.path().join(PARQUET_FOLDER)).unwrap();
    let e = prepare_run_folder(&two, other.path()).unwrap_err();
    assert!(matches!(e, SweepError::NotATablesFolder { .. }), "{e}");
    assert!(elsewhere.path().join("run-009.parquet").exists());
}

#[test]
fn a_new_set_removes_an_earlier_sets_run_folders_only_not_a_users_folders() {
    let three = jobs(r#"{"product": {"ms.k": [50, 100, 200]}}"#).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    assert_eq!(resume(&three, out, ResultsFormat::Csv).len(), 3);
    // folders of the user's that hold a file named like a run's among their own files, or a
    // summary.json that is not a run's report
    let vehicle = out.join("my_vehicle");
    std::fs::create_dir(&vehicle).unwrap();
    std::fs::write(vehicle.join("system.json"), b"{}").unwrap();
    std::fs::write(vehicle.join("notes.txt"), b"kept").unwrap();
    let report = out.join("report");
    std::fs::create_dir(&report).unwrap();
    std::fs::write(report.join("summary.json"), b"{\"pages\": 3}").unwrap();
    std::fs::write(report.join("system.json"), b"{}").unwrap();
    // an earlier run's folder copied under another name is not that run's either
    let copy = out.join("backup");
    std::fs::create_dir(&copy).unwrap();
    for f in ["system.json", "summary.json", "results.csv"] {
        std::fs::copy(out.join("run-002").join(f), copy.join(f)).unwrap();
    }
    let two = jobs(r#"{"product": {"ms.k": [50, 100]}}"#).unwrap();
    prepare_run_folder(&two, out).unwrap();
    assert!(!out.join("run-002").exists(), "the earlier set's third run");
    assert!(out.join("run-000").join("results.csv").exists());
    for kept in [&vehicle, &report, &copy] {
        assert!(kept.is_dir(), "{}", kept.display());
    }
    assert!(vehicle.join("notes.txt").exists());
    // a run whose folder is one of those is refused, nothing removed
    let named = jobs(r#"{"runs": [{"name": "my_vehicle", "parameters": {}}]}"#).unwrap();
    let e = prepare_run_folder(&named, out).unwrap_err();
    assert!(matches!(e, SweepError::NotARunFolder { .. }), "{e}");
    assert!(out.join("run-000").exists() && vehicle.join("notes.txt").exists());
    // an empty path is not taken for the working folder
    let e = prepare_run_folder(&two, Path::new("")).unwrap_err();
    assert!(matches!(e, SweepError::NoOutputFolder), "{e}");
    assert!(lock_output_folder(Path::new("")).is_err());
}

/// Resumes a run set as `master sweep --resume` does: keeps the runs complete in `format`,
/// runs the others; returns the names run.
fn resume(j: &[Job], outdir: &Path, format: ResultsFormat) -> Vec<String> {
    let todo: Vec<Job> = j
        .iter()
        .filter(|job| completed(outdir, job, format).is_none())
        .cloned()
        .collect();
    let opts = ResultsOptions {
        format,
        ..ResultsOptions::default()
    };
    let reports = execute_with(&todo, outdir, 2, false, &opts, None, |job: &Job| {
        let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.02);
        plan.instances[0].parameters[1].1 = job.parameters["ms.k"].as_f64().unwrap();
        let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
        simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).map_err(|e| e.to_string())
    })
    .unwrap();
    assert!(reports.iter().all(|r| r.ok), "{reports:?}");
    reports.into_iter().map(|r| r.name).collect()
}

fn files_under(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if e.file_type().unwrap().is_dir() {
            out.extend(
                files_under(&e.path())
                    .into_iter()
                    .map(|f| format!("{name}/{f}")),
            );
        } else {
            out.push(name);
        }
    }
    out.sort();
    out
}

#[test]
fn a_run_set_resumed_in_the_other_format_reruns_every_run_into_one_format() {
    let j = jobs(r#"{"product": {"ms.k": [50, 100, 200]}}"#).unwrap();
    let names: Vec<String> = j.iter().map(|r| r.name.clone()).collect();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    assert_eq!(resume(&j, out, ResultsFormat::Csv), names);
    assert!(out.join("run-001/results.csv").is_file());
    // the same format keeps every run
    assert!(resume(&j, out, ResultsFormat::Csv).is_empty());
    // CSV runs resumed as Parquet: every run again, all in results/, no CSV left
    assert_eq!(resume(&j, out, ResultsFormat::Parquet), names);
    let files = files_under(out);
    let expected: Vec<String> = names
        .iter()
        .flat_map(|n| {
            [
                format!("results/{n}.parquet"),
                format!("{n}/summary.json"),
                format!("{n}/system.json"),
            ]
        })
        .chain(["sweep.json".to_string()])
        .collect();
    let mut expected = expected;
    expected.sort();
    assert_eq!(files, expected);
    for job in &j {
        let r = completed(out, job, ResultsFormat::Parquet).unwrap();
        assert_eq!(
            r.results,
            Some(results_path(out, &job.name, ResultsFormat::Parquet))
        );
    }
    assert!(resume(&j, out, ResultsFormat::Parquet).is_empty());
    let kept = tempfile::tempdir().unwrap();
    let table = kept.path().join("run-000.parquet");
    std::fs::copy(results_path(out, "run-000", ResultsFormat::Parquet), &table).unwrap();
    // and back to CSV: every run again, no Parquet file (nor an empty results/) left
    assert_eq!(resume(&j, out, ResultsFormat::Csv), names);
    let files = files_under(out);
    assert!(
        files.iter().all(|f| !f.ends_with(".parquet")) && !out.join("results").exists(),
        "{files:?}"
    );
    assert_eq!(
        files.iter().filter(|f| f.ends_with("/results.csv")).count(),
        3
    );
    // a run with results in both formats (e.g. an interrupted rerun) is complete in neither
    std::fs::create_dir_all(out.join("results")).unwrap();
    std::fs::copy(&table, results_path(out, "run-000", ResultsFormat::Parquet)).unwrap();
    assert!(completed(out, &j[0], ResultsFormat::Csv).is_none());
    assert!(completed(out, &j[0], ResultsFormat::Parquet).is_none());
    assert_eq!(resume(&j, out, ResultsFormat::Csv), ["run-000"]);
    assert!(!out.join("results").exists());
}

/// A resumed set runs again a run whose FMU file changed at the same path (a rebuilt or
/// replaced model): its report holds the digest of every FMU it loaded.
#[test]
fn a_run_whose_fmu_changed_since_is_not_complete() {
    let fmus = tempfile::tempdir().unwrap();
    let (ms, sdm) = (
        fmus.path().join("MassSpring.fmu"),
        fmus.path().join("SDM.fmu"),
    );
    std::fs::write(&ms, b"first build").unwrap();
    std::fs::write(&sdm, b"damper").unwrap();
    let base = LoadedSystem::from_json_str(BASE, fmus.path(), "base.json").unwrap();
    let set: RunSet = serde_json::from_str(r#"{"product": {"ms.k": [50]}}"#).unwrap();
    let j = set.expand(&base, "set.json").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let runner = |_: &Job| -> Result<SimOutput, String> {
        let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
        let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
        simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).map_err(|e| e.to_string())
    };
    let reports = execute(&j, dir.path(), 1, false, runner).unwrap();
    assert_eq!(reports[0].fmu_digests.len(), 2, "{:?}", reports[0]);
    assert!(completed(dir.path(), &j[0], ResultsFormat::Csv).is_some());
    std::fs::write(&ms, b"second build").unwrap();
    assert!(completed(dir.path(), &j[0], ResultsFormat::Csv).is_none());
    std::fs::write(&ms, b"first build").unwrap();
    assert!(completed(dir.path(), &j[0], ResultsFormat::Csv).is_some());
}

/// A run that fails after its first row keeps its history in its own folder (`history.csv`
/// or `history.parquet`, its metadata saying when and why), never in the results table; a
/// run that fails before its first row has none; a later set replaces such a folder.
#[test]
fn a_failed_run_keeps_its_history_in_its_folder() {
    use crate::coupling::simulate_keeping_history;
    use crate::slave::FailStatus;
    let j = jobs(r#"{"product": {"ms.k": [50, 100, 200]}}"#).unwrap();
    // run-001 fails from 0.03 s, run-002 before its first row
    let runner = |fail: bool| {
        move |job: &Job| -> Result<SimOutput, FailedRun<String>> {
            if fail && job.name == "run-002" {
                return Err("cannot instantiate".to_string().into());
            }
            let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.05);
            plan.instances[0].parameters[1].1 = job.parameters["ms.k"].as_f64().unwrap();
            let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
            let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
            if fail && job.name == "run-001" {
                b.hooks.fail_step_from = Some((0.03, FailStatus::Error));
            }
            simulate_keeping_history(&plan, &mut [&mut a, &mut b], &RunOptions::default())
                .map_err(|f| f.map(|e| e.to_string()))
        }
    };
    for format in [ResultsFormat::Csv, ResultsFormat::Parquet] {
        let dir = tempfile::tempdir().unwrap();
        let opts = ResultsOptions {
            format,
            ..ResultsOptions::default()
        };
        let reports = execute_with(&j, dir.path(), 2, false, &opts, None, runner(true)).unwrap();
        assert_eq!(
            reports.iter().map(|r| r.ok).collect::<Vec<_>>(),
            [true, false, false]
        );
        let (file, other) = match format {
            ResultsFormat::Csv => ("history.csv", "history.parquet"),
            ResultsFormat::Parquet => ("history.parquet", "history.csv"),
        };
        let history = dir.path().join("run-001").join(file);
        assert_eq!(reports[1].history.as_deref(), Some(history.as_path()));
        assert!(reports[1].results.is_none() && reports[2].history.is_none());
        assert!(!dir.path().join("run-001").join(other).exists());
        assert!(!dir.path().join("run-002").join(file).exists());
        // the table holds completed runs only
        assert!(!results_path(dir.path(), "run-001", format).exists());
        let (time, meta) = match format {
            ResultsFormat::Csv => {
                let text = std::fs::read_to_string(&history).unwrap();
                let time: Vec<f64> = text
                    .lines()
                    .skip(1)
                    .map(|l| l.split(',').next().unwrap().parse().unwrap())
                    .collect();
                (
                    time,
                    crate::results::read_metadata(&history).unwrap().unwrap(),
                )
            }
            ResultsFormat::Parquet => {
                let (out, meta) = crate::parquet_file::read_results_parquet(&history).unwrap();
                (out.column("time").unwrap(), meta)
            }
        };
        let last = *time.last().unwrap();
        assert!((0.025..0.035).contains(&last), "history up to {last} s");
        assert_eq!(time.len(), (last / 1e-3).round() as usize + 1);
        let failed = meta.summary.failed.as_ref().expect("summary.failed");
        assert_eq!(failed.time_s, last);
        assert_eq!(Some(failed.error.as_str()), reports[1].error.as_deref());
        // the report in the run's folder names it too, relative to the set's folder (as
        // sweep.json does: they read wherever the set ran from)
        let report: RunReport = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("run-001/summary.json")).unwrap(),
        )
        .unwrap();
        let in_folder = reports[1]
            .history
            .as_ref()
            .map(|h| h.strip_prefix(dir.path()).unwrap().to_path_buf());
        assert_eq!(report.history, in_folder);
        let sweep: Vec<RunReport> =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("sweep.json")).unwrap())
                .unwrap();
        assert_eq!(sweep[1].history, in_folder);
        assert!(dir
            .path()
            .join(sweep[1].history.as_ref().unwrap())
            .is_file());
        if let Some(r) = &sweep[0].results {
            assert!(r.is_relative() && dir.path().join(r).is_file(), "{r:?}");
        }
        // a set that completes the runs replaces the failed runs' folders whole
        let again = execute_with(&j, dir.path(), 2, false, &opts, None, runner(false)).unwrap();
        assert!(again.iter().all(|r| r.ok && r.history.is_none()));
        assert!(!history.exists());
        assert!(results_path(dir.path(), "run-001", format).exists());
    }
}

/// A set clears an earlier set's runs of its names before its first run starts, so that a
/// process killed mid-set (no chance to tidy up) leaves no earlier run under this set's names;
/// a note of the user's in an earlier run's folder is never removed: a run that would replace
/// that folder is refused before anything changes, an earlier run not in the set leaves the
/// note where it was (its own files go); and no input may lie in what the set replaces.
#[test]
fn earlier_runs_go_before_the_first_run_and_a_users_files_stay() {
    let j = jobs(r#"{"product": {"ms.k": [50, 100, 200]}}"#).unwrap();
    let run = |job: &Job| -> Result<SimOutput, String> {
        let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
        plan.instances[0].parameters[1].1 = job.parameters["ms.k"].as_f64().unwrap();
        let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
        simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).map_err(|e| e.to_string())
    };
    for format in [ResultsFormat::Csv, ResultsFormat::Parquet] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        let opts = ResultsOptions {
            format,
            ..ResultsOptions::default()
        };
        assert!(execute_with(&j, out, 1, false, &opts, None, run)
            .unwrap()
            .iter()
            .all(|r| r.ok));
        // the first run of the next set finds none of the earlier ones
        let seen_earlier = std::sync::Mutex::new(Vec::new());
        execute_with(&j, out, 1, false, &opts, None, |job: &Job| {
            if job.name == j[0].name {
                for other in &j {
                    let table = results_path(out, &other.name, ResultsFormat::Parquet);
                    if out.join(&other.name).exists() || table.exists() {
                        seen_earlier.lock().unwrap().push(other.name.clone());
                    }
                }
            }
            run(job)
        })
        .unwrap();
        assert_eq!(
            *seen_earlier.lock().unwrap(),
            Vec::<String>::new(),
            "{format:?}"
        );
        if format == ResultsFormat::Parquet {
            continue;
        }
        // a note in the folder of a run the set would replace: refused, nothing removed
        let note = out.join(&j[1].name).join("notes.md");
        std::fs::write(&note, "mine").unwrap();
        let before = std::fs::read_dir(out).unwrap().count();
        let e = prepare_run_folder(&j, out)
            .and_then(|()| execute_with(&j, out, 1, false, &opts, None, run).map(|_| ()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("holds 'notes.md', which no run writes: move it out"),
            "{e}"
        );
        assert_eq!(std::fs::read_to_string(&note).unwrap(), "mine");
        assert!(out.join(&j[1].name).join("results.csv").is_file());
        assert_eq!(std::fs::read_dir(out).unwrap().count(), before);
        // ... but a resumed set that keeps that run (writes only the others) goes ahead
        let others = vec![j[0].clone(), j[2].clone()];
        prepare_run_folder(&j, out).unwrap();
        assert!(check_inputs_outside_runs(std::slice::from_ref(&note), &j, &others, out).is_ok());
        let reports = execute_with(&others, out, 1, false, &opts, None, run).unwrap();
        assert!(reports.iter().all(|r| r.ok));
        assert!(note.is_file() && out.join(&j[1].name).join("results.csv").is_file());
        // the same folder's run left out of the next set: its files go, the note stays
        let fewer = vec![j[0].clone()];
        prepare_run_folder(&fewer, out).unwrap();
        let left: Vec<String> = std::fs::read_dir(out.join(&j[1].name))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(left, ["notes.md"]);
        assert!(
            !out.join(&j[2].name).exists(),
            "an earlier run only: removed"
        );
        // an input inside a run folder the set replaces, or an earlier run's: refused
        let inside = out.join(&j[0].name).join("system.json");
        let e = check_inputs_outside_runs(std::slice::from_ref(&inside), &j, &j, out).unwrap_err();
        assert!(
            e.to_string()
                .contains("which this sweep replaces or removes"),
            "{e}"
        );
        assert!(check_inputs_outside_runs(&[inside], &[], &[], out).is_err());
        let user_file = out.join("base.json");
        std::fs::write(&user_file, "{}").unwrap();
        assert!(check_inputs_outside_runs(&[user_file], &j, &j, out).is_ok());
        // an earlier run's folder not in the set that also holds a file of the user's keeps
        // that file (only the run's own files go): an input there is refused only when it is
        // one of the run's own files
        let mine = out.join(&j[0].name).join("mybase.json");
        std::fs::write(&mine, "{}").unwrap();
        let elsewhere = vec![j[2].clone()];
        assert!(check_inputs_outside_runs(
            std::slice::from_ref(&mine),
            &elsewhere,
            &elsewhere,
            out
        )
        .is_ok());
        let own = out.join(&j[0].name).join("system.json");
        assert!(check_inputs_outside_runs(&[own], &elsewhere, &elsewhere, out).is_err());
        std::fs::remove_file(&mine).unwrap();
        // an earlier run's folder that is a link (to an archive) with a note in it: nothing is
        // removed through the link
        let archive = tempfile::tempdir().unwrap();
        let archived = archive.path().join(&j[0].name);
        std::fs::rename(out.join(&j[0].name), &archived).unwrap();
        std::os::unix::fs::symlink(&archived, out.join(&j[0].name)).unwrap();
        std::fs::write(archived.join("notes.md"), "mine").unwrap();
        let in_archive = || std::fs::read_dir(&archived).unwrap().count();
        let files = in_archive();
        prepare_run_folder(&[], out).unwrap();
        assert_eq!(in_archive(), files, "files removed through a link");
    }
}
