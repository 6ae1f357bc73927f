//! Run-set bookkeeping of the Python package: `sweep.json` over all runs of a resumed set, and
//! the folders of runs computed in another process ([`RunSetWriter`]). Which runs are complete
//! in a format, and which format a run set chooses by size, are the master's rules
//! ([`completed`], [`format_by_description`], re-exported).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use master::coupling::{ColumnInfo, FailedRun, SimOutput};
use master::output::OutputError;
use master::results::{constant_kinds, with_integer_kinds, ConstantKind, ResultsFormat};
pub use master::runset::{completed, format_by_description};
use master::runset::{run_one_with, Job, ResultsOptions, RunReport};
use master::system::{split_ref, LoadedSystem, SystemError};

/// Writes `<outdir>/sweep.json`, the reports in job order (the master's format, paths relative
/// to the folder).
pub fn write_sweep(outdir: &Path, reports: &[RunReport]) -> Result<(), OutputError> {
    master::runset::write_sweep_report(outdir, reports)
}

/// The unit of each `instance.variable` in `names` (a run set's parameters), as the model
/// description of the instance's FMU declares it; `None` where it declares none or where
/// the name is not one of the system's variables.
pub fn parameter_units(
    system: &LoadedSystem,
    names: &[String],
) -> Result<Vec<Option<String>>, SystemError> {
    let archives = system.open_fmus()?;
    let instances = &system.desc.instances;
    Ok(names
        .iter()
        .map(|name| {
            let (inst, var) = split_ref(name)?;
            let i = instances.iter().position(|s| s.name == inst)?;
            let v = archives[i].model.variables.iter().find(|v| v.name == var)?;
            v.unit.clone()
        })
        .collect())
}

/// Of the `instance.variable` names `names` (a run set's parameters), those that are
/// Integers or Enumerations in their FMUs' model descriptions (nothing loaded): the columns a
/// run set's tables hold as integers, as a local run set's do.
pub fn integer_parameters<'a>(
    system: &LoadedSystem,
    names: impl IntoIterator<Item = &'a String>,
) -> Result<BTreeSet<String>, SystemError> {
    let archives = system.open_fmus()?;
    let models: Vec<_> = archives.iter().map(|a| &a.model).collect();
    Ok(system.integer_parameters(&models, names))
}

/// What a run's table carries besides its numbers (each column's FMU variable, the texts of
/// String values), sent along with the numbers when a run is computed in another process.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ColumnsWire {
    pub columns: Vec<ColumnInfo>,
    pub strings: Vec<String>,
}

impl ColumnsWire {
    pub fn of(out: &SimOutput) -> Self {
        ColumnsWire {
            columns: out.columns.clone(),
            strings: out.strings.clone(),
        }
    }
}

/// Writes the folders of a run set's jobs from outcomes computed elsewhere (e.g. by cluster
/// workers), one at a time as they arrive, exactly as a local run set writes them: the same
/// format, and in Parquet the constant columns of the whole set in every file.
pub struct RunSetWriter {
    outdir: PathBuf,
    results: ResultsOptions,
    kinds: BTreeMap<String, ConstantKind>,
}

impl RunSetWriter {
    /// The report of a run that did not finish because its set stopped: no folder, and an
    /// earlier set's folder and table of its name removed (as `master sweep` does).
    pub fn not_finished(&self, job: &Job, error: &str) -> RunReport {
        master::runset::not_finished(job, &self.outdir, error)
    }

    /// `integer_columns`: the parameters that are Integers or Enumerations in their FMUs
    /// ([`integer_parameters`]), held as integers in the tables as a local run set holds them.
    pub fn new(
        outdir: &Path,
        jobs: &[Job],
        kept: &[Job],
        format: ResultsFormat,
        integer_columns: BTreeSet<String>,
    ) -> Self {
        // the constant columns of the whole set, the runs a resume keeps too
        let parameters = || jobs.iter().chain(kept).flat_map(|j| &j.parameters);
        RunSetWriter {
            outdir: outdir.to_path_buf(),
            kinds: with_integer_kinds(constant_kinds(parameters()), &integer_columns, parameters()),
            results: ResultsOptions {
                format,
                integer_columns,
                ..ResultsOptions::default()
            },
        }
    }

    /// Writes the folder of `job` from its outcome `result`; returns its report.
    pub fn write(&self, job: &Job, result: Result<SimOutput, FailedRun<String>>) -> RunReport {
        let result = std::sync::Mutex::new(Some(result));
        run_one_with(job, &self.outdir, &self.results, &self.kinds, &|_: &Job| {
            result
                .lock()
                .ok()
                .and_then(|mut r| r.take())
                .unwrap_or_else(|| Err("internal: results handed over twice".to_string().into()))
        })
    }
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
                failed: None,
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
        assert!(completed(dir.path(), &j, ResultsFormat::Csv).is_none());
        let writer = RunSetWriter::new(
            dir.path(),
            std::slice::from_ref(&j),
            &[],
            ResultsFormat::Csv,
            BTreeSet::new(),
        );
        let report = writer.write(&j, Ok(output()));
        assert!(report.ok, "{report:?}");
        let csv = std::fs::read_to_string(dir.path().join("run-000/results.csv")).unwrap();
        assert_eq!(csv, "time [s],ms.x [m]\n0.0,1.0\n0.001,0.5\n0.002,0.25\n");
        assert_eq!(
            completed(dir.path(), &j, ResultsFormat::Csv),
            Some(report.clone())
        );
        // complete in CSV only: a Parquet run set runs it again
        assert!(completed(dir.path(), &j, ResultsFormat::Parquet).is_none());
        // another stiffness under the same name is another run
        assert!(completed(dir.path(), &job("run-000", 200.0), ResultsFormat::Csv).is_none());
        // a lost results file makes the run incomplete
        std::fs::remove_file(dir.path().join("run-000/results.csv")).unwrap();
        assert!(completed(dir.path(), &j, ResultsFormat::Csv).is_none());
        write_sweep(dir.path(), &[report]).unwrap();
        let sweep: Vec<RunReport> =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("sweep.json")).unwrap())
                .unwrap();
        assert_eq!(sweep.len(), 1);
        assert_eq!(sweep[0].summary.as_ref().map(|s| s.steps), Some(2));
    }

    #[test]
    fn runs_written_one_by_one_as_parquet_carry_the_constant_columns_of_the_set() {
        let dir = tempfile::tempdir().unwrap();
        let a = job("run-000", 100.0);
        let mut b = job("run-001", 200.0);
        b.parameters
            .insert("ms.label".to_string(), serde_json::json!("stiff"));
        let writer = RunSetWriter::new(
            dir.path(),
            &[a.clone(), b],
            &[],
            ResultsFormat::Parquet,
            BTreeSet::new(),
        );
        let report = writer.write(&a, Ok(output()));
        assert!(report.ok, "{report:?}");
        let file = dir.path().join("results/run-000.parquet");
        assert_eq!(report.results.as_deref(), Some(file.as_path()));
        assert!(!dir.path().join("run-000/results.csv").exists());
        assert_eq!(
            completed(dir.path(), &a, ResultsFormat::Parquet),
            Some(report)
        );
        assert!(completed(dir.path(), &a, ResultsFormat::Csv).is_none());
        let (columns, _) = master::parquet_file::read_parquet(&file).unwrap();
        let names: Vec<&str> = columns.iter().map(|(n, _)| n.as_str()).collect();
        // the other run's parameter is a column here too (null), so the files make one table
        assert_eq!(
            names,
            ["time [s]", "ms.x [m]", "run", "ms.k", "ms.label"],
            "{names:?}"
        );
    }

    #[test]
    fn a_failed_run_is_written_and_never_complete() {
        let dir = tempfile::tempdir().unwrap();
        let j = job("bad", -1.0);
        let writer = RunSetWriter::new(
            dir.path(),
            std::slice::from_ref(&j),
            &[],
            ResultsFormat::Csv,
            BTreeSet::new(),
        );
        let report = writer.write(&j, Err("negative stiffness".to_string().into()));
        assert!(!report.ok);
        assert_eq!(report.error.as_deref(), Some("negative stiffness"));
        assert!(dir.path().join("bad/summary.json").is_file());
        assert!(!dir.path().join("bad/results.csv").exists());
        assert!(completed(dir.path(), &j, ResultsFormat::Csv).is_none());
    }
}
