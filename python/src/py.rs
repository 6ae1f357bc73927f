//! The pyo3 layer: classes and functions of `railfmu._railfmu`. Data crosses as JSON text
//! (system descriptions, jobs, reports: the master's own serde formats) and as native-endian
//! `f64` bytes (result tables, read by NumPy without a copy per value). Every run happens on a
//! thread of its own with the GIL released; the calling thread waits for it with the GIL
//! released too, waking every 50 ms to deliver progress to Python and to check for Ctrl-C
//! (which cancels the run at its next communication point and raises `KeyboardInterrupt`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::Mutex;
use std::time::Duration;

use pyo3::exceptions::{PyException, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PyFloat, PyInt, PyString};
use serde_json::Value;

use master::coupling::{Algorithm, FailedRun, RunOptions, SimError, SimOutput, Summary};
use master::output::check_outputs_apart;
use master::results::{
    csv_metadata_path, write_results, ResultsFormat, ResultsMetadata, RunContext,
};
use master::runset::{
    execute_with, format_by_size, run_job, Job, ResultsOptions, RunReport, RunSet, SweepError,
};
use master::slave::ScalarType;
use master::system::{LoadedSystem, PreparedSystem, RunError, SystemError};

use crate::assess::{self, AssessOptions};
use crate::{error_message, f64_from_bytes, f64_pybytes, results, runs};

pyo3::create_exception!(
    railfmu,
    Error,
    PyException,
    "Base class of every error of railfmu; the message is the master's."
);
pyo3::create_exception!(
    railfmu,
    SystemDescriptionError,
    Error,
    "A system or run-set description, a parameter name or a parameter value is invalid."
);
pyo3::create_exception!(
    railfmu,
    FmuError,
    Error,
    "An FMU cannot be opened, checked, loaded or instantiated."
);
pyo3::create_exception!(
    railfmu,
    SimulationError,
    Error,
    "A simulation stopped: an FMU failed or discarded a step, or a value is not finite."
);
pyo3::create_exception!(
    railfmu,
    OutputError,
    Error,
    "A result file or folder cannot be written or read."
);

pyo3::create_exception!(
    railfmu,
    AssessmentError,
    Error,
    "Signals cannot be assessed: an unknown column, too short a record, a recorded band narrower than the assessed one, a bad option."
);

fn system_err(e: &SystemError) -> PyErr {
    match e {
        SystemError::Fmu { .. } => FmuError::new_err(error_message(e)),
        _ => SystemDescriptionError::new_err(error_message(e)),
    }
}

fn ssp_err(e: &master::ssp::SspError) -> PyErr {
    match e {
        master::ssp::SspError::System(s) => system_err(s),
        master::ssp::SspError::Output(_) => OutputError::new_err(error_message(e)),
        // a missing stop time or step is given as the argument of System.load
        _ => SystemDescriptionError::new_err(
            error_message(e)
                .replace("with --stop-time)", "with System.load(..., stop_time=...))")
                .replace("with --step)", "with System.load(..., step=...))"),
        ),
    }
}

fn run_err(e: &RunError) -> PyErr {
    match e {
        RunError::System(s) => system_err(s),
        RunError::Fmu(_) => FmuError::new_err(error_message(e)),
        RunError::Sim(SimError::Cancelled { .. }) => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err(error_message(e))
        }
        RunError::Sim(_) => SimulationError::new_err(error_message(e)),
        RunError::Output(_) => OutputError::new_err(error_message(e)),
    }
}

fn sweep_err(e: &SweepError) -> PyErr {
    match e {
        SweepError::System(s) => system_err(s),
        SweepError::Output(_)
        | SweepError::Dir { .. }
        | SweepError::NotAFolder { .. }
        | SweepError::NotARunFolder { .. }
        | SweepError::NotARunTable { .. }
        | SweepError::AddedToRunFolder { .. }
        | SweepError::InputInRunFolder { .. }
        | SweepError::NoOutputFolder
        | SweepError::NotATablesFolder { .. }
        | SweepError::FolderInUse { .. } => OutputError::new_err(error_message(e)),
        SweepError::Pool { .. } => Error::new_err(error_message(e)),
    }
}

fn json_err(what: &str, e: &serde_json::Error) -> PyErr {
    SystemDescriptionError::new_err(format!("{what}: {e}"))
}

/// A Python value as the JSON value a system description would hold.
fn json_value(key: &str, ob: &Bound<'_, PyAny>) -> PyResult<Value> {
    if ob.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(ob.extract::<bool>()?));
    }
    if ob.is_instance_of::<PyInt>() {
        return match ob.extract::<i64>() {
            Ok(i) => Ok(Value::from(i)),
            Err(_) => Err(SystemDescriptionError::new_err(format!(
                "{key}: {ob} is not a 64-bit integer"
            ))),
        };
    }
    if ob.is_instance_of::<PyFloat>() {
        let x: f64 = ob.extract()?;
        return serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| {
                SystemDescriptionError::new_err(format!("{key}: {x} is not a finite number"))
            });
    }
    if ob.is_instance_of::<PyString>() {
        return Ok(Value::String(ob.extract()?));
    }
    let ty = ob.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "{key}: a start value is a bool, int, float or str, not {ty}"
    )))
}

/// `{"instance.variable": value}` from a Python dict.
fn json_parameters(parameters: Option<&Bound<'_, PyDict>>) -> PyResult<BTreeMap<String, Value>> {
    let mut out = BTreeMap::new();
    if let Some(d) = parameters {
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("parameter names are str, not {}", k.get_type()))
            })?;
            let value = json_value(&key, &v)?;
            out.insert(key, value);
        }
    }
    Ok(out)
}

/// What a background run tells the waiting Python thread.
enum Event {
    /// (macro steps done, total) of a single run.
    Steps(u64, u64),
    /// A run of a set finished: its name and its error, if it failed.
    Done(String, Option<String>),
}

/// Runs `work` on a scoped thread while this thread waits with the GIL released, handing each
/// event to `on_event` (with the GIL) and checking for signals. An exception of `on_event` or a
/// signal (Ctrl-C) sets `cancel`, waits for `work` to stop and is raised.
fn in_background<'s, T: Send>(
    py: Python<'_>,
    cancel: &'s AtomicBool,
    work: impl FnOnce(&Sender<Event>) -> T + Send + 's,
    on_event: impl FnMut(Python<'_>, Event) -> PyResult<()>,
) -> PyResult<T> {
    in_background_polling(py, cancel, work, on_event, None)
}

/// How often [`in_background_polling`] asks its `should_stop` (a Dask task asks its
/// scheduler, one round trip per call).
const STOP_POLL: Duration = Duration::from_secs(1);

/// [`in_background`], also setting `cancel` once `should_stop()` (called every
/// [`STOP_POLL`]) returns True; its exceptions are ignored.
fn in_background_polling<'s, T: Send>(
    py: Python<'_>,
    cancel: &'s AtomicBool,
    work: impl FnOnce(&Sender<Event>) -> T + Send + 's,
    mut on_event: impl FnMut(Python<'_>, Event) -> PyResult<()>,
    should_stop: Option<&Py<PyAny>>,
) -> PyResult<T> {
    let mut last_poll = std::time::Instant::now();
    let (tx, rx) = mpsc::channel::<Event>();
    let rx = Mutex::new(rx);
    std::thread::scope(|s| {
        let handle = s.spawn(move || work(&tx));
        let mut failure: Option<PyErr> = None;
        loop {
            let got = py.detach(|| {
                rx.lock()
                    .map(|r| r.recv_timeout(Duration::from_millis(50)))
                    .unwrap_or(Err(RecvTimeoutError::Disconnected))
            });
            match got {
                Ok(ev) => {
                    if failure.is_none() {
                        if let Err(e) = on_event(py, ev) {
                            cancel.store(true, Ordering::SeqCst);
                            failure = Some(e);
                        }
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if failure.is_none() {
                if let Err(e) = py.check_signals() {
                    cancel.store(true, Ordering::SeqCst);
                    failure = Some(e);
                }
            }
            if let Some(f) = should_stop.filter(|_| last_poll.elapsed() >= STOP_POLL) {
                last_poll = std::time::Instant::now();
                let stop = f.call0(py).and_then(|r| r.is_truthy(py)).unwrap_or(false);
                if stop {
                    cancel.store(true, Ordering::SeqCst);
                }
            }
        }
        let joined = py.detach(move || handle.join());
        match (failure, joined) {
            (Some(e), _) => Err(e),
            (None, Ok(v)) => Ok(v),
            (None, Err(_)) => Err(Error::new_err("internal: the run thread panicked")),
        }
    })
}

/// Results as (header, data bytes, texts, summary JSON, metadata JSON): the columns of the
/// master's files ([`results::expand`]), each text column's values by column index.
type Table<'py> = (
    Vec<String>,
    Bound<'py, PyBytes>,
    Vec<(usize, Vec<String>)>,
    String,
    String,
);

fn table<'py>(py: Python<'py>, out: SimOutput, ctx: &RunContext) -> PyResult<Table<'py>> {
    let summary = serde_json::to_string(&out.summary)
        .map_err(|e| Error::new_err(format!("internal: summary: {e}")))?;
    let meta = serde_json::to_string(&ResultsMetadata::of(&out, ctx))
        .map_err(|e| Error::new_err(format!("internal: metadata: {e}")))?;
    // the output is consumed: its values are held once here, then once in Python
    let t = results::expand_owned(out);
    Ok((t.header, f64_pybytes(py, &t.data)?, t.texts, summary, meta))
}

/// A system description with its FMUs opened, checked, unpacked and loaded once, and its
/// coupling plan built: many runs of it cost only their simulation. Immutable and shared by
/// threads.
#[pyclass(frozen, module = "railfmu._railfmu", name = "PreparedSystem")]
pub struct PySystem {
    prepared: PreparedSystem,
    models_json: String,
    /// An imported SSP's unpacked FMUs live as long as the system.
    _ssp: Option<master::ssp::ImportedSsp>,
}

impl PySystem {
    fn prepare(py: Python<'_>, system: LoadedSystem) -> PyResult<Self> {
        let prepared = py
            .detach(|| PreparedSystem::prepare(&system))
            .map_err(|e| run_err(&e))?;
        let archives = system.open_fmus().map_err(|e| system_err(&e))?;
        let models: Vec<_> = archives.iter().map(|a| &a.model).collect();
        let models_json = serde_json::to_string(&models)
            .map_err(|e| Error::new_err(format!("internal: model descriptions: {e}")))?;
        Ok(PySystem {
            prepared,
            models_json,
            _ssp: None,
        })
    }
}

impl PySystem {
    /// How messages name a run's own parameters and stop time: not by the description's
    /// file and line, which hold other values.
    fn run_label(&self) -> String {
        format!("{} with the run's arguments", self.prepared.system().file)
    }

    /// The description (FMU paths absolute; an SSP's as archive and member) with a run's
    /// start values and stop time, as JSON: the record of a run.
    fn run_description(
        &self,
        params: &BTreeMap<String, Value>,
        stop_time: Option<f64>,
    ) -> PyResult<Value> {
        let mut desc = self.prepared.system().resolved();
        for (key, value) in params {
            // every key named a variable of the system that ran
            let _ = desc.set_start_value(key, value.clone());
        }
        if let Some(t) = stop_time {
            desc.stop_time = t;
        }
        // an SSP's FMUs were unpacked into a temporary folder that goes with the system: each
        // is named by the archive and member it comes from, as `master run` records them
        if let Some(imported) = &self._ssp {
            imported.name_fmu_sources(&mut desc);
        }
        serde_json::to_value(&desc)
            .map_err(|e| Error::new_err(format!("internal: description: {e}")))
    }
}

#[pymethods]
impl PySystem {
    /// Loads a system description and prepares it: JSON (FMU paths relative to its folder),
    /// or an SSP (`.ssp` archive, or a bare `.ssd` next to its FMUs) as `master run` reads it.
    /// The communication step, stop time and coupling algorithm ("jacobi" or "gauss-seidel")
    /// can be given, replacing the description's (`master run --step --stop --algorithm`), and
    /// the variables to record (`master run --record`; an SSP records every output unless
    /// given).
    #[staticmethod]
    #[pyo3(signature = (path, step=None, stop_time=None, algorithm=None, record=None))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        step: Option<f64>,
        stop_time: Option<f64>,
        algorithm: Option<&str>,
        record: Option<Vec<String>>,
    ) -> PyResult<Self> {
        refuse_fmu(&path, false)?;
        let algorithm = algorithm.map(parse_algorithm).transpose()?;
        let record_only = master::system::SystemOverrides {
            from: master::system::OverridesFrom::PythonLoad,
            record: record.unwrap_or_default(),
            ..Default::default()
        };
        if master::ssp::is_ssp_path(&path) {
            let opts = master::ssp::ImportOptions {
                step,
                stop_time,
                algorithm,
            };
            let imported = master::ssp::import(&path, &opts).map_err(|e| ssp_err(&e))?;
            let mut loaded = imported.system.clone();
            loaded
                .apply_overrides(&record_only)
                .map_err(|e| system_err(&e))?;
            let mut system = Self::prepare(py, loaded)?;
            system._ssp = Some(imported);
            return Ok(system);
        }
        let mut system = LoadedSystem::load(&path).map_err(|e| system_err(&e))?;
        let overrides = master::system::SystemOverrides {
            step,
            stop_time,
            algorithm,
            ..record_only
        };
        system
            .apply_overrides(&overrides)
            .map_err(|e| system_err(&e))?;
        Self::prepare(py, system)
    }

    /// Parses JSON text (FMU paths relative to `base_dir`; `label` names it in messages).
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str, base_dir: PathBuf, label: &str) -> PyResult<Self> {
        let system =
            LoadedSystem::from_json_str(text, &base_dir, label).map_err(|e| system_err(&e))?;
        Self::prepare(py, system)
    }

    /// The name used in messages (the file path or label).
    #[getter]
    fn file(&self) -> String {
        self.prepared.system().file.clone()
    }

    /// The description as JSON, FMU paths made absolute.
    fn description_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.prepared.system().resolved())
            .map_err(|e| Error::new_err(format!("internal: description: {e}")))
    }

    /// The model description of each instance's FMU (same order) as a JSON list.
    fn models_json(&self) -> String {
        self.models_json.clone()
    }

    /// The CSV header of a run, as `master run` writes it: `time [s]` and each recorded
    /// variable's `name [unit]`, an Enumeration followed by its item names (`name (item)`).
    fn header(&self) -> Vec<String> {
        let mut h = vec!["time [s]".to_string()];
        for r in &self.prepared.plan().record {
            h.push(r.label.clone());
            if r.info.scalar_type() == ScalarType::Enumeration {
                h.push(results::item_label(&r.label));
            }
        }
        h
    }

    /// Validates start values (`{"instance.variable": value}`) and a stop time without running.
    #[pyo3(signature = (parameters=None, stop_time=None))]
    fn check(
        &self,
        parameters: Option<&Bound<'_, PyDict>>,
        stop_time: Option<f64>,
    ) -> PyResult<()> {
        let params = json_parameters(parameters)?;
        self.prepared
            .changes(&params, stop_time, &self.run_label())
            .map(|_| ())
            .map_err(|e| system_err(&e))
    }

    /// One run with the given start values and stop time; returns (header, data bytes, texts,
    /// summary JSON, metadata JSON) as [`table`]. `progress(steps_done, steps_total)` is
    /// called about a hundred times.
    #[pyo3(signature = (parameters=None, stop_time=None, progress=None))]
    fn run<'py>(
        &self,
        py: Python<'py>,
        parameters: Option<&Bound<'py, PyDict>>,
        stop_time: Option<f64>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Table<'py>> {
        let params = json_parameters(parameters)?;
        let changes = self
            .prepared
            .changes(&params, stop_time, &self.run_label())
            .map_err(|e| system_err(&e))?;
        let cancel = AtomicBool::new(false);
        let want_progress = progress.is_some();
        let prepared = &self.prepared;
        let cancel_ref = &cancel;
        let out = in_background(
            py,
            &cancel,
            move |tx| {
                let report = |k: u64, n: u64| {
                    let stride = (n / 100).max(1);
                    if want_progress && (k == n || k.is_multiple_of(stride)) {
                        let _ = tx.send(Event::Steps(k, n));
                    }
                };
                let opts = RunOptions {
                    cancel: Some(cancel_ref),
                    progress: Some(&report),
                    general_engine: false,
                };
                prepared.run_keeping_history(&changes, &opts)
            },
            |py, ev| match (&progress, ev) {
                (Some(cb), Event::Steps(k, n)) => cb.call1(py, (k, n)).map(|_| ()),
                _ => Ok(()),
            },
        )?;
        // the metadata describe the system as run, as those of a run of a run set do
        let ctx = RunContext {
            system: Some(self.run_description(&params, stop_time)?),
            ..RunContext::default()
        };
        match out {
            Ok(out) => table(py, out, &ctx),
            // a simulation that failed after its first row: the exception carries its history
            // (the Python side makes it `SimulationError.history`)
            Err(FailedRun {
                error: e @ RunError::Sim(_),
                history: Some(history),
            }) => {
                let history = pyo3::IntoPyObjectExt::into_py_any(table(py, *history, &ctx)?, py)?;
                Err(SimulationError::new_err((error_message(&e), history)))
            }
            Err(failed) => Err(run_err(&failed.error)),
        }
    }

    /// Runs one job of this system's run set (JSON, as from `load_run_set`), as a run set's
    /// worker does; returns (header, data bytes, summary JSON, columns JSON, None), or a
    /// failed run's error last with its history up to the failure in the other four (None
    /// when it failed before its first row): a failed simulation is the run's result, not an
    /// exception.
    /// `should_stop()`, when given, is called about once a second while the run goes on; once
    /// it returns True the run stops at its next communication point (a cancelled run, an
    /// error). An exception of it is taken as False: a check that cannot be made stops
    /// nothing.
    #[allow(clippy::type_complexity)]
    #[pyo3(signature = (job_json, should_stop=None))]
    fn run_job<'py>(
        &self,
        py: Python<'py>,
        job_json: &str,
        should_stop: Option<Py<PyAny>>,
    ) -> PyResult<(
        Option<Vec<String>>,
        Option<Bound<'py, PyBytes>>,
        Option<String>,
        Option<String>,
        Option<String>,
    )> {
        let job: Job = serde_json::from_str(job_json).map_err(|e| json_err("job", &e))?;
        let cancel = AtomicBool::new(false);
        let prepared = &self.prepared;
        let cancel_ref = &cancel;
        let job_ref = &job;
        let out = in_background_polling(
            py,
            &cancel,
            move |_| run_job(prepared, job_ref, cancel_ref),
            |_, _| Ok(()),
            should_stop.as_ref(),
        )?;
        match out {
            Ok(out) => {
                let (header, d, summary, c) = wire(py, out)?;
                Ok((Some(header), Some(d), Some(summary), Some(c), None))
            }
            // a run that failed after its first row: its history comes with its error
            Err(FailedRun {
                error,
                history: Some(h),
            }) => {
                let (header, d, summary, c) = wire(py, *h)?;
                Ok((Some(header), Some(d), Some(summary), Some(c), Some(error)))
            }
            Err(f) => Ok((None, None, None, None, Some(f.error))),
        }
    }

    /// Checks every job's start values and stop time against the FMUs (names, types,
    /// declared ranges), as each run would: a run set with a misspelt variable is refused
    /// before anything runs or is removed.
    fn check_jobs(&self, jobs_json: Vec<String>) -> PyResult<()> {
        let jobs = parse_jobs(&jobs_json)?;
        master::runset::check_jobs(&self.prepared, &jobs).map_err(|e| system_err(&e))
    }

    /// Runs jobs of this system's run set on `threads` threads, writing `<outdir>/<run>/` per
    /// job and `<outdir>/sweep.json` (the master's run-set folder), the results in `format`
    /// ("csv" or "parquet"; None: by size, as `master sweep`); `on_done(name, error)` is
    /// called as each run finishes; `kept_json`: the jobs of the set a resume keeps (their
    /// parameters are columns of every run's table too). Returns each job's report as JSON,
    /// in job order.
    #[pyo3(signature = (jobs_json, outdir, threads, on_done=None, format=None, kept_json=None))]
    #[allow(clippy::too_many_arguments)]
    fn run_jobs(
        &self,
        py: Python<'_>,
        jobs_json: Vec<String>,
        outdir: PathBuf,
        threads: usize,
        on_done: Option<Py<PyAny>>,
        format: Option<&str>,
        kept_json: Option<Vec<String>>,
    ) -> PyResult<Vec<String>> {
        let jobs = parse_jobs(&jobs_json)?;
        let kept = parse_jobs(&kept_json.unwrap_or_default())?;
        let results = ResultsOptions {
            format: match format {
                Some(f) => parse_format(f)?,
                None => format_by_size(&self.prepared, &jobs),
            },
            integer_columns: self
                .prepared
                .integer_parameters(jobs.iter().chain(&kept).flat_map(|j| j.parameters.keys())),
            kept_parameters: kept.into_iter().map(|j| j.parameters).collect(),
            ..ResultsOptions::default()
        };
        let cancel = AtomicBool::new(false);
        let prepared = &self.prepared;
        let cancel_ref = &cancel;
        let (jobs_ref, outdir_ref, results_ref) = (&jobs, &outdir, &results);
        let reports = in_background(
            py,
            &cancel,
            move |tx| {
                let tx = Mutex::new(tx.clone());
                execute_with(
                    jobs_ref,
                    outdir_ref,
                    threads,
                    false,
                    results_ref,
                    Some(cancel_ref),
                    |job| {
                        let r = run_job(prepared, job, cancel_ref);
                        if let Ok(tx) = tx.lock() {
                            let error = r.as_ref().err().map(|f| f.error.clone());
                            let _ = tx.send(Event::Done(job.name.clone(), error));
                        }
                        r
                    },
                )
            },
            |py, ev| match (&on_done, ev) {
                (Some(cb), Event::Done(name, error)) => cb.call1(py, (name, error)).map(|_| ()),
                _ => Ok(()),
            },
        )?;
        let reports = reports.map_err(|e| sweep_err(&e))?;
        reports.iter().map(report_json).collect()
    }
}

/// A run's output as `PreparedSystem.run_job` hands it to Python: header, data bytes, summary
/// JSON, columns JSON.
fn wire(
    py: Python<'_>,
    out: SimOutput,
) -> PyResult<(Vec<String>, Bound<'_, PyBytes>, String, String)> {
    let summary = serde_json::to_string(&out.summary)
        .map_err(|e| Error::new_err(format!("internal: summary: {e}")))?;
    let c = serde_json::to_string(&runs::ColumnsWire::of(&out))
        .map_err(|e| Error::new_err(format!("internal: columns: {e}")))?;
    let d = f64_pybytes(py, &out.data)?;
    Ok((out.header, d, summary, c))
}

/// Before a run set writes into `outdir`: refuses a run whose folder would replace a file or
/// folder that is not a run folder of an earlier sweep, then removes the earlier set's runs
/// that are not among `jobs_json` (all of this set's jobs, kept ones included), as
/// `master sweep` does.
#[pyfunction]
fn prepare_run_folder(outdir: PathBuf, jobs_json: Vec<String>) -> PyResult<()> {
    let jobs = parse_jobs(&jobs_json)?;
    master::runset::prepare_run_folder(&jobs, &outdir).map_err(|e| sweep_err(&e))
}

/// Before a run set writes `jobs_json` (the runs it computes, kept ones left out) into
/// `outdir`: refuses one whose earlier folder holds a file of the user's, then removes the
/// earlier folders and tables of these runs, so that a set killed midway (locally or on a
/// cluster) leaves no earlier run under their names, as `master sweep` does.
#[pyfunction]
fn clear_earlier_runs(outdir: PathBuf, jobs_json: Vec<String>) -> PyResult<()> {
    let jobs = parse_jobs(&jobs_json)?;
    master::runset::clear_earlier_runs(&jobs, &outdir).map_err(|e| sweep_err(&e))
}

/// Before a run set writes into `outdir`: refuses it when its report would replace one of
/// `inputs` (the run-set file, its base system, the FMUs), or when one of them lies in a run
/// folder the set replaces (`todo_json`: the runs it computes) or removes (an earlier set's
/// run not among `jobs_json`), as `master sweep` does.
#[pyfunction]
fn check_run_set_inputs(
    outdir: PathBuf,
    inputs: Vec<PathBuf>,
    jobs_json: Vec<String>,
    todo_json: Vec<String>,
) -> PyResult<()> {
    master::output::check_outputs_apart(&inputs, &[outdir.join("sweep.json")])
        .map_err(|e| OutputError::new_err(e.to_string()))?;
    let (jobs, todo) = (parse_jobs(&jobs_json)?, parse_jobs(&todo_json)?);
    master::runset::check_inputs_outside_runs(&inputs, &jobs, &todo, &outdir)
        .map_err(|e| sweep_err(&e))
}

fn report_json(r: &RunReport) -> PyResult<String> {
    serde_json::to_string(r).map_err(|e| Error::new_err(format!("internal: report: {e}")))
}

/// Refuses an FMU given where a system description (or, `run_set`, a run-set description) is
/// read, saying how a system of FMUs is described in Python (read as text, the archive would
/// only be "not valid UTF-8").
fn refuse_fmu(path: &Path, run_set: bool) -> PyResult<()> {
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fmu"))
    {
        return Ok(());
    }
    // an instance name has no dots
    let name = path
        .file_stem()
        .map_or("model".into(), |s| s.to_string_lossy().replace('.', "_"));
    let system = format!(
        "{{\"instances\": [{{\"name\": \"{name}\", \"fmu\": {}}}], \"stop_time\": 1.0, \
         \"step\": 0.001}}",
        serde_json::Value::String(path.display().to_string())
    );
    let (what, example, file) = if run_set {
        (
            "a run-set description",
            format!("railfmu.RunSet.from_dict({{\"system\": {system}, \"product\": {{...}}}})"),
            "a run-set file whose system names it",
        )
    } else {
        (
            "a system description",
            format!("railfmu.System.from_dict({system})"),
            "a JSON or SSP system file that names it",
        )
    };
    Err(SystemDescriptionError::new_err(format!(
        "'{}' is an FMU, not {what}: describe a system of its instances, e.g. {example}, or \
         load {file}",
        path.display()
    )))
}

/// Reads a run-set file: (resolved base system JSON, base label, each job as JSON).
#[pyfunction]
fn load_run_set(path: PathBuf) -> PyResult<(String, String, Vec<String>)> {
    refuse_fmu(&path, true)?;
    let (base, jobs) = RunSet::load(&path).map_err(|e| system_err(&e))?;
    run_set_parts(&base, &jobs)
}

/// Parses run-set JSON text (paths relative to `base_dir`, `label` names it in messages).
#[pyfunction]
fn run_set_from_json(
    text: &str,
    base_dir: PathBuf,
    label: &str,
) -> PyResult<(String, String, Vec<String>)> {
    let (base, jobs) =
        RunSet::from_str_with_base(text, &base_dir, label).map_err(|e| system_err(&e))?;
    run_set_parts(&base, &jobs)
}

fn run_set_parts(base: &LoadedSystem, jobs: &[Job]) -> PyResult<(String, String, Vec<String>)> {
    let desc = serde_json::to_string(&base.resolved())
        .map_err(|e| Error::new_err(format!("internal: base system: {e}")))?;
    let jobs = jobs
        .iter()
        .map(|j| serde_json::to_string(j).map_err(|e| Error::new_err(format!("internal: {e}"))))
        .collect::<PyResult<Vec<_>>>()?;
    Ok((desc, base.file.clone(), jobs))
}

/// The report (JSON) of a job whose run is complete in `outdir` in `format` ("csv" or
/// "parquet"), else None (also when its results are in the other format).
#[pyfunction]
fn completed_report(outdir: PathBuf, job_json: &str, format: &str) -> PyResult<Option<String>> {
    let job: Job = serde_json::from_str(job_json).map_err(|e| json_err("job", &e))?;
    runs::completed(&outdir, &job, parse_format(format)?)
        .as_ref()
        .map(report_json)
        .transpose()
}

/// The unit of each parameter (`instance.variable`) of the system described in `path` (a run
/// folder's `system.json`), from its FMUs' model descriptions (None: no unit, or no such
/// variable).
#[pyfunction]
fn parameter_units(path: PathBuf, names: Vec<String>) -> PyResult<Vec<Option<String>>> {
    let system = LoadedSystem::load(&path).map_err(|e| system_err(&e))?;
    runs::parameter_units(&system, &names).map_err(|e| system_err(&e))
}

/// Writes `<outdir>/sweep.json` from reports (JSON) in job order.
#[pyfunction]
fn write_sweep(outdir: PathBuf, reports_json: Vec<String>) -> PyResult<()> {
    let reports = reports_json
        .iter()
        .map(|r| serde_json::from_str::<RunReport>(r).map_err(|e| json_err("report", &e)))
        .collect::<PyResult<Vec<_>>>()?;
    runs::write_sweep(&outdir, &reports).map_err(|e| OutputError::new_err(error_message(&e)))
}

fn parse_jobs(jobs_json: &[String]) -> PyResult<Vec<Job>> {
    jobs_json
        .iter()
        .map(|j| serde_json::from_str::<Job>(j).map_err(|e| json_err("job", &e)))
        .collect()
}

/// A coupling algorithm by its name in a system description.
fn parse_algorithm(name: &str) -> PyResult<Algorithm> {
    serde_json::from_value(Value::String(name.to_string())).map_err(|_| {
        PyValueError::new_err(format!(
            "algorithm '{name}': expected 'jacobi' or 'gauss-seidel'"
        ))
    })
}

fn parse_format(format: &str) -> PyResult<ResultsFormat> {
    ResultsFormat::from_name(format).ok_or_else(|| {
        PyValueError::new_err(format!(
            "results format '{format}': expected 'csv' or 'parquet'"
        ))
    })
}

/// The results format ("csv" or "parquet") a local run set of the base system (resolved JSON)
/// chooses by size for these jobs, read from the FMUs' model descriptions (nothing loaded).
#[pyfunction]
fn results_format_by_size(
    base_json: &str,
    label: &str,
    jobs_json: Vec<String>,
) -> PyResult<String> {
    let base =
        LoadedSystem::from_json_str(base_json, Path::new(""), label).map_err(|e| system_err(&e))?;
    let jobs = parse_jobs(&jobs_json)?;
    let format = runs::format_by_description(&base, &jobs).map_err(|e| system_err(&e))?;
    Ok(format.extension().to_string())
}

/// Writes the folders of a run set's jobs from results computed elsewhere, one at a time, as
/// a local run set writes them (the same format; in Parquet every file with the constant
/// columns of all `jobs_json`).
#[pyclass(frozen, module = "railfmu._railfmu", name = "RunWriter")]
struct PyRunWriter {
    writer: runs::RunSetWriter,
}

#[pymethods]
impl PyRunWriter {
    /// `base_json` and `label`: the run set's base system (resolved JSON), whose FMUs' model
    /// descriptions say which parameters are Integers or Enumerations.
    #[new]
    #[pyo3(signature = (outdir, jobs_json, format, base_json, label, kept_json=None))]
    fn new(
        outdir: PathBuf,
        jobs_json: Vec<String>,
        format: &str,
        base_json: &str,
        label: &str,
        kept_json: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let jobs = parse_jobs(&jobs_json)?;
        let kept = parse_jobs(&kept_json.unwrap_or_default())?;
        let format = parse_format(format)?;
        // FMUs this process cannot read (workers reading their own paths; a broken FMU,
        // which fails every run on the workers) say nothing here: the tables then type each
        // parameter by its values alone
        let integers = LoadedSystem::from_json_str(base_json, Path::new(""), label)
            .ok()
            .and_then(|base| {
                runs::integer_parameters(
                    &base,
                    jobs.iter().chain(&kept).flat_map(|j| j.parameters.keys()),
                )
                .ok()
            })
            .unwrap_or_default();
        std::fs::create_dir_all(&outdir).map_err(|e| {
            OutputError::new_err(format!("cannot create '{}': {e}", outdir.display()))
        })?;
        Ok(PyRunWriter {
            writer: runs::RunSetWriter::new(&outdir, &jobs, &kept, format, integers),
        })
    }

    /// Writes the folder of a job from its results (header, data bytes, summary JSON,
    /// columns JSON, as `PreparedSystem.run_job` returns them) or from its error (with the
    /// others: the failed run's history, written into its folder); returns the report as
    /// JSON.
    #[pyo3(signature = (job_json, header=None, data=None, summary_json=None, columns_json=None, error=None))]
    fn write(
        &self,
        job_json: &str,
        header: Option<Vec<String>>,
        data: Option<&[u8]>,
        summary_json: Option<&str>,
        columns_json: Option<&str>,
        error: Option<String>,
    ) -> PyResult<String> {
        let job: Job = serde_json::from_str(job_json).map_err(|e| json_err("job", &e))?;
        let output = |header: Vec<String>, data: &[u8], summary: &str| -> PyResult<SimOutput> {
            let data = f64_from_bytes(data).map_err(OutputError::new_err)?;
            let summary: Summary =
                serde_json::from_str(summary).map_err(|e| json_err("summary", &e))?;
            // without columns: every column Real, no FMU variable in the metadata
            let wire: runs::ColumnsWire = match columns_json {
                Some(c) => serde_json::from_str(c).map_err(|e| json_err("columns", &e))?,
                None => runs::ColumnsWire::default(),
            };
            Ok(SimOutput {
                header,
                data,
                summary,
                columns: wire.columns,
                strings: wire.strings,
                decimation: None,
            })
        };
        let result = match (error, header, data, summary_json) {
            // a failed run with its history up to the failure
            (Some(error), Some(header), Some(data), Some(summary)) => Err(FailedRun {
                error,
                history: Some(Box::new(output(header, data, summary)?)),
            }),
            (Some(e), ..) => Err(e.into()),
            (None, Some(header), Some(data), Some(summary)) => Ok(output(header, data, summary)?),
            _ => Err(
                "internal: a run came back with neither results nor an error"
                    .to_string()
                    .into(),
            ),
        };
        report_json(&self.writer.write(&job, result))
    }

    /// The report (JSON) of a job whose set stopped before it finished: no folder is written
    /// for it, an earlier set's folder and table of its name are removed.
    fn not_finished(&self, job_json: &str, error: &str) -> PyResult<String> {
        let job: Job = serde_json::from_str(job_json).map_err(|e| json_err("job", &e))?;
        report_json(&self.writer.not_finished(&job, error))
    }
}

/// A results table read back: (header, data bytes, texts, metadata JSON or None).
type ReadTable<'py> = (
    Vec<String>,
    Bound<'py, PyBytes>,
    Vec<(usize, Vec<String>)>,
    Option<String>,
);

/// Reads a results file written by the master (CSV, with its metadata beside it when there
/// is one, or Parquet) as [`table`], every value exactly as written.
#[pyfunction]
fn read_results<'py>(py: Python<'py>, path: PathBuf) -> PyResult<ReadTable<'py>> {
    let (t, meta) = py
        .detach(|| results::read_results(&path))
        .map_err(OutputError::new_err)?;
    let meta = meta
        .map(|m| serde_json::to_string(&m))
        .transpose()
        .map_err(|e| Error::new_err(format!("internal: metadata: {e}")))?;
    Ok((t.header, f64_pybytes(py, &t.data)?, t.texts, meta))
}

/// Writes results as `master run` does, atomically: a CSV and its metadata file beside it
/// (`<name>.meta.json`), or with `parquet` a Parquet file holding its metadata. The table (header, data bytes, texts, as [`read_results`] gives
/// them) has its columns described by the metadata JSON (None: Reals, and Strings where there
/// are texts), which also gives the run's name, parameters and system description, if any;
/// `summary_json` is the run's summary (missing statistics are 0). `sampling_known`: false for
/// a table of unknown origin (its metadata then record no sampling, so that an assessment of
/// the file notes it, as one of the table did).
#[pyfunction]
#[pyo3(signature = (path, header, data, texts, metadata_json=None, summary_json=None, sampling_known=true, parquet=false))]
#[allow(clippy::too_many_arguments)] // the parts of a table, as Python holds them
fn write_results_file(
    path: PathBuf,
    header: Vec<String>,
    data: &[u8],
    texts: Vec<(usize, Vec<String>)>,
    metadata_json: Option<&str>,
    summary_json: Option<&str>,
    sampling_known: bool,
    parquet: bool,
) -> PyResult<()> {
    let meta = metadata_json
        .map(serde_json::from_str::<ResultsMetadata>)
        .transpose()
        .map_err(|e| OutputError::new_err(format!("results metadata: {e}")))?;
    let table = results::Table {
        header,
        data: f64_from_bytes(data).map_err(OutputError::new_err)?,
        texts,
    };
    let columns = meta.as_ref().map_or(&[][..], |m| &m.columns[..]);
    let mut out = results::collapse(&table, columns).map_err(OutputError::new_err)?;
    if let Some(s) = summary_json {
        out.summary = results::summary(s).map_err(OutputError::new_err)?;
    }
    let mut ctx = RunContext {
        sampling_unknown: !sampling_known,
        ..RunContext::default()
    };
    if let Some(m) = meta {
        out.decimation = m.sampling.and_then(|s| s.decimation);
        ctx.run = m.run;
        ctx.parameters = m.parameters;
        ctx.labels = m.labels;
        ctx.system = m.system;
    }
    let (format, paths) = if parquet {
        (ResultsFormat::Parquet, vec![path.clone()])
    } else {
        (
            ResultsFormat::Csv,
            vec![path.clone(), csv_metadata_path(&path)],
        )
    };
    check_outputs_apart(&[], &paths).map_err(|e| OutputError::new_err(error_message(&e)))?;
    write_results(&path, &out, format, &ctx).map_err(|e| OutputError::new_err(error_message(&e)))
}

/// The FMUs' and the master's messages since the last call, as (Python logging level, text),
/// and how many were dropped beyond the number kept.
#[pyfunction]
fn take_log() -> (Vec<(u32, String)>, usize) {
    let (messages, dropped) = master::fmu::logger::take_messages();
    let level = |l: log::Level| match l {
        log::Level::Error => 40,
        log::Level::Warn => 30,
        log::Level::Info => 20,
        log::Level::Debug | log::Level::Trace => 10,
    };
    (
        messages.into_iter().map(|(l, t)| (level(l), t)).collect(),
        dropped,
    )
}

/// Keeps messages of Python logging level `level` and above (DEBUG 10, INFO 20, WARNING 30,
/// ERROR 40; above ERROR, none).
#[pyfunction]
fn set_log_level(level: i64) {
    log::set_max_level(match level {
        i64::MIN..=10 => log::LevelFilter::Debug,
        11..=20 => log::LevelFilter::Info,
        21..=30 => log::LevelFilter::Warn,
        31..=40 => log::LevelFilter::Error,
        _ => log::LevelFilter::Off,
    });
}

/// EN 14363 assessment of a results file (CSV or Parquet), as `master assess`: options and
/// answer as JSON ([`crate::assess`]).
#[pyfunction]
fn assess_file(py: Python<'_>, path: PathBuf, options_json: &str) -> PyResult<String> {
    let options = assess_options(options_json)?;
    let answer = py.detach(|| -> PyResult<_> {
        let table = assess::table_from_file(&path).map_err(OutputError::new_err)?;
        assess::assess(&table, &options).map_err(AssessmentError::new_err)
    })?;
    assess_answer_json(&answer)
}

/// EN 14363 assessment of columns held by the caller: `names` (the first is the time) and the
/// row-major float64 `data`; `full_rate`: every communication point of a run (no decimation).
#[pyfunction]
#[pyo3(signature = (names, data, full_rate, options_json, metadata_json=None))]
fn assess_columns(
    py: Python<'_>,
    names: Vec<String>,
    data: &[u8],
    full_rate: bool,
    options_json: &str,
    metadata_json: Option<&str>,
) -> PyResult<String> {
    let options = assess_options(options_json)?;
    // the results' metadata (read back from a file, or of a run): their sampling and running
    // speed, as `master assess` reads them beside a file; metadata of another form (made by
    // hand) is left out, as a file without metadata
    let metadata = metadata_json
        .and_then(|m| serde_json::from_str::<master::results::ResultsMetadata>(m).ok());
    let answer = py
        .detach(|| {
            let table = assess::table_from_rows(names, &f64_from_bytes(data)?, full_rate)?;
            let table = match metadata {
                // a run's own results without a recorded sampling keep their full rate
                Some(m) if m.sampling.is_some() || !full_rate => {
                    table.with_metadata(Some(m)).map_err(|e| e.to_string())?
                }
                _ => table,
            };
            assess::assess(&table, &options)
        })
        .map_err(AssessmentError::new_err)?;
    assess_answer_json(&answer)
}

fn assess_options(json: &str) -> PyResult<AssessOptions> {
    serde_json::from_str(json).map_err(|e| AssessmentError::new_err(format!("options: {e}")))
}

fn assess_answer_json(answer: &assess::AssessAnswer) -> PyResult<String> {
    serde_json::to_string(answer).map_err(|e| Error::new_err(format!("internal: {e}")))
}

#[pymodule]
fn _railfmu(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // FMU logger messages and the master's warnings, kept for Python's logging (logger
    // "railfmu", railfmu._log), not printed on the process's stderr, which a notebook's user
    // does not see
    master::fmu::install_logger(log::LevelFilter::Warn);
    master::fmu::logger::capture_messages(true);
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add(
        "SystemDescriptionError",
        py.get_type::<SystemDescriptionError>(),
    )?;
    m.add("FmuError", py.get_type::<FmuError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("OutputError", py.get_type::<OutputError>())?;
    m.add("AssessmentError", py.get_type::<AssessmentError>())?;
    m.add_function(wrap_pyfunction!(take_log, m)?)?;
    m.add_function(wrap_pyfunction!(set_log_level, m)?)?;
    m.add_function(wrap_pyfunction!(assess_file, m)?)?;
    m.add_function(wrap_pyfunction!(assess_columns, m)?)?;
    m.add_class::<PySystem>()?;
    m.add_function(wrap_pyfunction!(load_run_set, m)?)?;
    m.add_function(wrap_pyfunction!(run_set_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(completed_report, m)?)?;
    m.add_function(wrap_pyfunction!(write_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(parameter_units, m)?)?;
    m.add_function(wrap_pyfunction!(results_format_by_size, m)?)?;
    m.add_class::<PyRunWriter>()?;
    m.add_function(wrap_pyfunction!(prepare_run_folder, m)?)?;
    m.add_function(wrap_pyfunction!(clear_earlier_runs, m)?)?;
    m.add_function(wrap_pyfunction!(check_run_set_inputs, m)?)?;
    m.add_function(wrap_pyfunction!(read_results, m)?)?;
    m.add_function(wrap_pyfunction!(write_results_file, m)?)?;
    Ok(())
}
