//! A prepared system (FMUs unpacked and loaded once, plan built once, a run = start values plus
//! a stop time) gives bit for bit the results of preparing everything afresh from the run's own
//! system description, and unpacks each FMU once however many runs it serves, also when the
//! runs are spread over worker threads. With the example FMUs and with a study configuration.
//!
//! One test function: the extraction counter is process-wide, so nothing else in this test
//! binary may unpack FMUs at the same time.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use master::coupling::{RunOptions, SimOutput};
use master::fmu::extraction_count;
use master::runset::{execute, run_job, Job, RunSet};
use master::system::{LoadedSystem, PreparedSystem};
use rail_study::study::config::{RunRequest, Sources};
use rail_study::study::configurations::configuration;
use rail_study::study::VehicleModel;

fn dist() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../dist");
    assert!(
        d.join("Bogie2Dof.fmu").exists() && d.join("MassSpring.fmu").exists(),
        "dist/ incomplete: run scripts/test.sh (it packages the FMUs first)"
    );
    d
}

/// The job's own system description through JSON, as `master run` would read the run's
/// system.json: parsed, opened, unpacked, planned and instantiated for this run alone.
fn fresh(job: &Job) -> SimOutput {
    let text = serde_json::to_string(&job.system).unwrap();
    let sys = LoadedSystem::from_json_str(&text, Path::new("/"), &job.name).unwrap();
    sys.run(&RunOptions::default()).unwrap()
}

fn assert_bit_identical(a: &SimOutput, b: &SimOutput, what: &str) {
    assert_eq!(a.header, b.header, "{what}");
    assert_eq!(a.data.len(), b.data.len(), "{what}");
    let differing = a
        .data
        .iter()
        .zip(&b.data)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    assert_eq!(differing, 0, "{what}: {differing} values differ");
}

#[test]
fn prepared_runs_equal_fresh_runs_and_unpack_each_fmu_once() {
    let d = dist();
    let cancel = AtomicBool::new(false);

    // the example FMUs: a run set of 4 stiffnesses, on 2 worker threads
    let set = serde_json::json!({
        "system": {
            "instances": [
                {"name": "ms", "fmu": d.join("MassSpring.fmu"),
                 "parameters": {"mass": 1.0, "initial_position": 0.1}},
                {"name": "sdm", "fmu": d.join("SpringDamperMass.fmu"),
                 "parameters": {"mass": 0.5, "coupling_stiffness": 200.0}}
            ],
            "connections": [
                {"from": "ms.position", "to": "sdm.input_position"},
                {"from": "ms.velocity", "to": "sdm.input_velocity"},
                {"from": "sdm.coupling_force", "to": "ms.force"}
            ],
            "stop_time": 2.0, "step": 0.001
        },
        "product": {"ms.stiffness": [50.0, 80.0, 120.0, 200.0], "sdm.coupling_damping": [0.5]}
    });
    let (base, jobs) = RunSet::from_str_with_base(&set.to_string(), &d, "set.json").unwrap();
    let before = extraction_count();
    let system = PreparedSystem::prepare(&base).unwrap();
    let out = tempfile::tempdir().unwrap();
    let reports = execute(&jobs, out.path(), 2, false, |job| {
        run_job(&system, job, &cancel)
    })
    .unwrap();
    assert!(reports.iter().all(|r| r.ok), "{reports:?}");
    assert_eq!(
        extraction_count() - before,
        2,
        "two FMU files, unpacked once for 4 runs"
    );
    let mut finals = Vec::new();
    for job in &jobs {
        let prepared = run_job(&system, job, &cancel).unwrap();
        assert_bit_identical(&prepared, &fresh(job), &job.name);
        finals.push(*prepared.data.last().unwrap());
        // the run set's stored CSV is the same run
        let csv = std::fs::read_to_string(out.path().join(&job.name).join("results.csv")).unwrap();
        assert_eq!(csv.lines().count(), prepared.rows().count() + 1);
    }
    assert!(
        finals.windows(2).all(|w| w[0] != w[1]),
        "the stiffness changes the run"
    );

    // a study configuration (bogie, two semi-active dampers, two MPPT boards) at two speeds,
    // one with an extra start value and a shorter stop time
    let sources = Sources {
        fmus: d.clone(),
        systems: None,
    };
    let c = configuration("mppt2").unwrap();
    let b = VehicleModel::Bogie2Dof;
    let base = sources.system(b, c).unwrap();
    let before = extraction_count();
    let system = PreparedSystem::prepare(&base).unwrap();
    let distinct = rail_study::study::config::required_fmus(b, &[c]).len();
    assert_eq!(extraction_count() - before, distinct as u64);
    let runs = [
        RunRequest::new("t-", b, c, 300.0, Some(1), 3.0),
        RunRequest::new("t-", b, c, 250.0, None, 2.0).with(
            "controller_left.valve.initial_command",
            serde_json::json!(10.0),
        ),
    ];
    let jobs: Vec<Job> = runs.iter().map(|r| r.job(&base).unwrap()).collect();
    let prepared: Vec<SimOutput> = jobs
        .iter()
        .map(|j| run_job(&system, j, &cancel).unwrap())
        .collect();
    // a start value the model does not have fails that run only, naming it
    let bad = RunRequest::new("t-", b, c, 300.0, Some(1), 1.0).with("bogie.no_such", 1.into());
    let e = run_job(&system, &bad.job(&base).unwrap(), &cancel)
        .unwrap_err()
        .error;
    assert!(e.contains("unknown variable 'no_such'"), "{e}");
    assert_eq!(
        extraction_count() - before,
        distinct as u64,
        "runs unpack nothing"
    );
    for (job, p) in jobs.iter().zip(&prepared) {
        assert_bit_identical(p, &fresh(job), &job.name);
    }
}
