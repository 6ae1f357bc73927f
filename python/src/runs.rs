//! Run-set bookkeeping of the Python package: `sweep.json` over all runs of a resumed set, and a
//! run's folder written from results computed in another process. Which runs are complete is
//! the master's rule ([`completed`], re-exported).

use std::path::Path;

use master::coupling::SimOutput;
use master::output::{write_json_atomic, OutputError};
pub use master::runset::completed;
use master::runset::{run_one, Job, RunReport};

/// Writes `<outdir>/sweep.json`, the reports in job order (the master's format).
pub fn write_sweep(outdir: &Path, reports: &[RunReport]) -> Result<(), OutputError> {
    write_json_atomic(&outdir.join("sweep.json"), &reports)
}

/// Writes the folder of `job` from its outcome `result` (e.g. computed by a cluster worker),
/// exactly as a local run set writes it.
pub fn write_run(outdir: &Path, job: &Job, result: Result<SimOutput, String>) -> RunReport {
    let result = std::sync::Mutex::new(Some(result));
    run_one(job, outdir, &|_: &Job| {
        result
            .lock()
            .ok()
            .and_then(|mut r| r.take())
            .unwrap_or_else(|| Err("internal: results handed over twice".into()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use master::coupling::Summary;
    use master::system::SystemDescription;
    use std::collections::BTreeMap;

    fn job(name: &str, k: f64) -> Job {
        let system: SystemDescription = serde_json::from_value(serde_json::json!({
            "instances": [{"name": "ms", "fmu": "/abs/MassSpring.fmu", "parameters": {"k": k}}],
            "stop_time": 0.002, "step": 0.001
        }))
        .unwrap();
        let mut parameters = BTreeMap::new();
        parameters.insert("ms.k".to_string(), serde_json::json!(k));
        Job {
            name: name.into(),
            parameters,
            system,
        }
    }

    fn output() -> SimOutput {
        SimOutput {
            header: vec!["time [s]".into(), "ms.x [m]".into()],
            data: vec![0.0, 1.0, 0.001, 0.5, 0.002, 0.25],
            summary: Summary {
                steps: 2,
                rejected_steps: 0,
                simulated_time_s: 0.002,
                wall_time_s: 1e-4,
                realtime_ratio: 20.0,
                terminated: None,
            },
            columns: vec![],
            strings: vec![],
            decimation: None,
        }
    }

    #[test]
    fn a_written_run_is_complete_until_its_inputs_change() {
        let dir = tempfile::tempdir().unwrap();
        let j = job("run-000", 100.0);
        assert!(completed(dir.path(), &j).is_none());
        let report = write_run(dir.path(), &j, Ok(output()));
        assert!(report.ok, "{report:?}");
        let csv = std::fs::read_to_string(dir.path().join("run-000/results.csv")).unwrap();
        assert_eq!(csv, "time [s],ms.x [m]\n0,1\n0.001,0.5\n0.002,0.25\n");
        assert_eq!(completed(dir.path(), &j), Some(report.clone()));
        // another stiffness under the same name is another run
        assert!(completed(dir.path(), &job("run-000", 200.0)).is_none());
        // a lost results file makes the run incomplete
        std::fs::remove_file(dir.path().join("run-000/results.csv")).unwrap();
        assert!(completed(dir.path(), &j).is_none());
        write_sweep(dir.path(), &[report]).unwrap();
        let sweep: Vec<RunReport> =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("sweep.json")).unwrap())
                .unwrap();
        assert_eq!(sweep.len(), 1);
        assert_eq!(sweep[0].summary.as_ref().map(|s| s.steps), Some(2));
    }

    #[test]
    fn a_failed_run_is_written_and_never_complete() {
        let dir = tempfile::tempdir().unwrap();
        let j = job("bad", -1.0);
        let report = write_run(dir.path(), &j, Err("negative stiffness".into()));
        assert!(!report.ok);
        assert_eq!(report.error.as_deref(), Some("negative stiffness"));
        assert!(dir.path().join("bad/summary.json").is_file());
        assert!(!dir.path().join("bad/results.csv").exists());
        assert!(completed(dir.path(), &j).is_none());
    }
}
