//! Executing a run set: one job on the prepared system, the jobs in parallel, each run's
//! results written into a temporary folder and moved into place whole.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde_json::Value;

use super::{Job, RunReport, SweepError, PARQUET_FOLDER};
use crate::coupling::{CouplingPlan, FailedRun, RunOptions, SimOutput, Summary};
use crate::output::write_json_atomic;
use crate::results::{
    constant_kinds, with_integer_kinds, write_results, ConstantKind, ResultsFormat, RunContext,
};
use crate::system::{LoadedSystem, PreparedSystem, SystemDescription, SystemError};

/// The start values and stop time of every job, checked against the prepared system's FMUs
/// as each run would check them (variable names, types, declared ranges): a run set with a
/// misspelt variable is refused before anything runs or is removed, not failed run by run.
/// The jobs are also checked with [`check_given_one_way`].
pub fn check_jobs(system: &PreparedSystem, jobs: &[Job]) -> Result<(), SystemError> {
    check_start_values(system, jobs)?;
    check_given_one_way(system, jobs)
}

/// The per-run part of [`check_jobs`]: each job's start values and stop time.
pub fn check_start_values(system: &PreparedSystem, jobs: &[Job]) -> Result<(), SystemError> {
    for job in jobs {
        let run = format!("run '{}'", job.name);
        system.changes(&job.parameters, Some(job.system.stop_time), &run)?;
    }
    Ok(())
}

/// An Enumeration given by item name in some runs and by number in others is refused: the
/// set's results column would mix texts and numbers. `jobs`: the whole set (a resumed set's
/// kept runs too).
pub fn check_given_one_way(system: &PreparedSystem, jobs: &[Job]) -> Result<(), SystemError> {
    let integers = system.integer_parameters(jobs.iter().flat_map(|j| j.parameters.keys()));
    for key in &integers {
        let given = |text: bool| {
            jobs.iter().find_map(|j| {
                j.parameters
                    .get(key)
                    .filter(|v| v.is_string() == text)
                    .map(|v| (j.name.as_str(), v))
            })
        };
        if let (Some((a, name)), Some((b, number))) = (given(true), given(false)) {
            return Err(SystemError::Invalid {
                file: format!("run '{b}'"),
                line: None,
                field: key.clone(),
                reason: format!(
                    "given as the number {number} here and as the item name {name} in run \
                     '{a}': give it one way in every run, so that its results column has one \
                     type"
                ),
            });
        }
    }
    Ok(())
}

/// Runs one job of `system`'s run set (a job from [`RunSet::expand`](super::RunSet::expand) of that system: the same
/// instances, FMUs and timing; only start values and the stop time differ) on the prepared
/// FMUs: validates its start values, simulates, returns the output.
pub fn run_job(
    system: &PreparedSystem,
    job: &Job,
    cancel: &AtomicBool,
) -> Result<SimOutput, FailedRun<String>> {
    let run = format!("run '{}'", job.name);
    let base = &system.system().desc;
    let same_fmus = job.system.instances.len() == base.instances.len()
        && job
            .system
            .instances
            .iter()
            .zip(&base.instances)
            .zip(system.fmu_paths())
            .all(|((j, b), p)| {
                j.name == b.name && j.fmu == *p && j.step_multiple == b.step_multiple
            });
    if !same_fmus || job.system.step != base.step || job.system.start_time != base.start_time {
        return Err(format!(
            "{run}: not a run of the prepared system '{}' (instances, FMUs or timing differ)",
            system.system().file
        )
        .into());
    }
    // the report records the digests of the files now: a file replaced since the system was
    // loaded would be recorded for a run of the model loaded before
    for path in system.fmu_paths() {
        let loaded = system.fmu_digests().get(path.to_string_lossy().as_ref());
        match crate::input::file_digest(path) {
            None => {
                return Err(format!(
                    "{run}: the FMU '{}' cannot be read any more: the run's report could not \
                     name the model it ran",
                    path.display()
                )
                .into())
            }
            Some(now) if Some(&now) != loaded => {
                return Err(format!(
                    "{run}: the FMU '{}' changed since the run set loaded it: this run would \
                     be recorded for the new file; run the set again (a resumed set runs this \
                     run again)",
                    path.display()
                )
                .into())
            }
            Some(_) => {}
        }
    }
    let changes = system
        .changes(&job.parameters, Some(job.system.stop_time), &run)
        .map_err(|e| e.to_string())?;
    let opts = RunOptions {
        cancel: Some(cancel),
        progress: None,
        general_engine: false,
    };
    system
        .run_keeping_history(&changes, &opts)
        .map_err(|f| f.map(|e| e.to_string()))
}

/// How the runs of a run set write their results.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultsOptions {
    pub format: ResultsFormat,
    /// Constant columns besides the parameters, per run name (e.g. a study's configuration).
    pub labels: BTreeMap<String, BTreeMap<String, Value>>,
    /// The parameters that are Integers or Enumerations in their FMUs
    /// ([`PreparedSystem::integer_parameters`]) and the labels that are whole numbers by
    /// nature (a track seed): their Parquet columns are INT32 where every run gives a whole
    /// number, not float64.
    pub integer_columns: BTreeSet<String>,
    /// The parameters of the set's runs a resume keeps (not among the jobs run): each run's
    /// Parquet file gets the constant columns of the whole set, as a fresh set writes them (a
    /// folder reads with the first file's columns, so a column only the kept runs have was
    /// dropped from every run).
    pub kept_parameters: Vec<BTreeMap<String, Value>>,
}

impl Default for ResultsOptions {
    fn default() -> Self {
        ResultsOptions {
            format: ResultsFormat::Csv,
            labels: BTreeMap::new(),
            integer_columns: BTreeSet::new(),
            kept_parameters: Vec::new(),
        }
    }
}

/// Where the results of `job` go in `outdir` in `format`.
pub fn results_path(outdir: &Path, job_name: &str, format: ResultsFormat) -> PathBuf {
    match format {
        ResultsFormat::Csv => outdir.join(job_name).join("results.csv"),
        ResultsFormat::Parquet => outdir
            .join(PARQUET_FOLDER)
            .join(format!("{job_name}.parquet")),
    }
}

/// The format chosen by size for the runs of `system` (its longest job): Parquet from
/// [`crate::results::PARQUET_FROM_VALUES`] values on.
pub fn format_by_size(system: &PreparedSystem, jobs: &[Job]) -> ResultsFormat {
    format_by_plan(system.plan(), jobs)
}

/// [`format_by_size`] from the FMUs' model descriptions alone (no FMU is unpacked or
/// loaded): the format a fresh sweep of `base` chooses for `jobs`, decided before any run.
pub fn format_by_description(
    base: &LoadedSystem,
    jobs: &[Job],
) -> Result<ResultsFormat, SystemError> {
    let archives = base.open_fmus()?;
    let models: Vec<_> = archives.iter().map(|a| &a.model).collect();
    Ok(format_by_plan(&base.plan(&models)?, jobs))
}

/// [`format_by_size`] from the coupling plan alone, which the model descriptions give
/// ([`LoadedSystem::plan`]): a process that hands the runs to others chooses as a local run
/// set does without loading the FMUs.
pub fn format_by_plan(plan: &CouplingPlan, jobs: &[Job]) -> ResultsFormat {
    let stop = jobs
        .iter()
        .map(|j| j.system.stop_time)
        .fold(plan.stop_time, f64::max);
    let rows = ((stop - plan.start_time) / plan.step).max(0.0) as u64 + 1;
    ResultsFormat::by_size(rows, plan.record.len() as u64 + 1)
}

/// Prefix of a run folder being written (renamed onto the run's folder when complete).
const PARTIAL_PREFIX: &str = ".partial-";
/// Prefix of a previous run folder being replaced (removed right after the swap).
const REPLACED_PREFIX: &str = ".replaced-";

/// Runs all jobs on `threads` workers with `runner`, writing each run's folder and
/// `<outdir>/sweep.json`. Returns the reports in job order.
///
/// Each run is written into a fresh hidden folder in `outdir` and swapped onto
/// `<outdir>/<run>` only when complete (its description, its results if it succeeded, its
/// summary), so a rerun never leaves the previous run's results beside the new run's
/// description, and an interrupted sweep leaves no half-written run folder. The previous
/// `sweep.json` is removed first, so an interrupted sweep never leaves an old report looking
/// current; hidden folders left by an interrupted sweep are removed at the start. A runner
/// that panics fails its run (reported like any failure), never the sweep.
pub fn execute<F, E>(
    jobs: &[Job],
    outdir: &Path,
    threads: usize,
    show_progress: bool,
    runner: F,
) -> Result<Vec<RunReport>, SweepError>
where
    F: Fn(&Job) -> Result<SimOutput, E> + Sync,
    E: Into<FailedRun<String>>,
{
    execute_with(
        jobs,
        outdir,
        threads,
        show_progress,
        &ResultsOptions::default(),
        None,
        runner,
    )
}

/// [`execute`] with results written as `results` says. Once `cancel` is set no further run
/// starts: each run not started is reported as [`NOT_STARTED`] without a folder (an earlier
/// set's folder and table of its name are removed), so that an interrupted set of 100 000
/// runs ends at once and `sweep.json` still lists every run.
pub fn execute_with<F, E>(
    jobs: &[Job],
    outdir: &Path,
    threads: usize,
    show_progress: bool,
    results: &ResultsOptions,
    cancel: Option<&AtomicBool>,
    runner: F,
) -> Result<Vec<RunReport>, SweepError>
where
    F: Fn(&Job) -> Result<SimOutput, E> + Sync,
    E: Into<FailedRun<String>>,
{
    // the constant columns of the whole set: the jobs run now and the runs a resume keeps
    let constants = || {
        jobs.iter()
            .flat_map(|j| {
                j.parameters
                    .iter()
                    .chain(results.labels.get(&j.name).into_iter().flatten())
            })
            .chain(results.kept_parameters.iter().flatten())
    };
    let kinds = with_integer_kinds(
        constant_kinds(constants()),
        &results.integer_columns,
        constants(),
    );
    let dir_err = |source| SweepError::Dir {
        path: outdir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(outdir).map_err(dir_err)?;
    check_run_folders(jobs, outdir)?;
    check_added_files(jobs, outdir)?;
    // the threads first: a pool that cannot be started leaves the folder as it was
    let pool = thread_pool(threads, jobs.len())?;
    let report_path = outdir.join("sweep.json");
    match std::fs::remove_file(&report_path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(SweepError::Dir {
                path: report_path,
                source: e,
            })
        }
        _ => {}
    }
    remove_partial_folders(outdir);
    // an earlier set's runs of these names go now, not when each run ends: a process killed
    // in between (a second Ctrl-C, SIGKILL, the OOM killer) would leave them beside this
    // set's, each looking complete, under this set's run names
    for job in jobs {
        clear_earlier_run(job, outdir);
    }
    let bar = if show_progress {
        indicatif::ProgressBar::new(jobs.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs, {elapsed} elapsed, eta {eta} {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let reports: Vec<RunReport> = pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                if cancel.is_some_and(|c| c.load(Ordering::SeqCst)) {
                    return not_finished(job, outdir, NOT_STARTED);
                }
                let r = run_one_with(job, outdir, results, &kinds, &runner);
                bar.inc(1);
                if !r.ok {
                    let history = r.history.as_ref().map_or(String::new(), |h| {
                        format!(" (its history up to the failure is in {})", h.display())
                    });
                    bar.println(format!(
                        "run '{}' failed: {}{history}",
                        r.name,
                        r.error.as_deref().unwrap_or("")
                    ));
                }
                r
            })
            .collect()
    });
    bar.finish_and_clear();
    write_sweep_report(outdir, &reports)?;
    Ok(reports)
}

/// `report` as the run set's folder stores it: its results and history relative to `outdir`
/// (`run-000/results.csv`, `results/run-000.parquet`), so that they read from the folder
/// wherever the set was started from and wherever the folder is moved (they were relative to
/// the working folder the set ran in).
pub fn report_in_folder(report: &RunReport, outdir: &Path) -> RunReport {
    let inside = |p: &Option<PathBuf>| {
        p.as_ref().map(|p| {
            p.strip_prefix(outdir)
                .map_or_else(|_| p.clone(), Path::to_path_buf)
        })
    };
    RunReport {
        results: inside(&report.results),
        history: inside(&report.history),
        ..report.clone()
    }
}

/// Writes `<outdir>/sweep.json`: the reports in job order, their paths relative to `outdir`
/// ([`report_in_folder`]).
pub fn write_sweep_report(
    outdir: &Path,
    reports: &[RunReport],
) -> Result<(), crate::output::OutputError> {
    let stored: Vec<RunReport> = reports
        .iter()
        .map(|r| report_in_folder(r, outdir))
        .collect();
    write_json_atomic(&outdir.join("sweep.json"), &stored)
}

/// The pool of `threads` workers (at least one, at most one per job) that runs a set of
/// `n_jobs`; built before anything in the output folder changes, so that a count the system
/// cannot start (its thread or memory limits) is refused with the folder as it was.
pub fn thread_pool(threads: usize, n_jobs: usize) -> Result<rayon::ThreadPool, SweepError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.clamp(1, n_jobs.max(1)))
        .build()
        .map_err(|e| SweepError::Pool {
            jobs: threads,
            reason: e.to_string(),
        })
}

/// Removes an earlier set's run folder (one that holds only a run's files) and Parquet table of
/// `job`'s name.
fn clear_earlier_run(job: &Job, outdir: &Path) {
    let dest = outdir.join(&job.name);
    if holds_only_run_files(&dest) {
        let _ = std::fs::remove_dir_all(&dest);
    }
    let table = results_path(outdir, &job.name, ResultsFormat::Parquet);
    if crate::parquet_file::is_run_table(&table) {
        let _ = std::fs::remove_file(&table);
    }
}

/// Error of a run that an interrupted run set did not start.
pub const NOT_STARTED: &str = "not run: the run set was interrupted before this run started";

/// The report of a run that did not finish because its set stopped (`error` says how): no
/// folder is written for it, and an earlier set's run folder and Parquet table of its name
/// are removed, so that nothing of an earlier run looks like this one's result.
pub fn not_finished(job: &Job, outdir: &Path, error: &str) -> RunReport {
    clear_earlier_run(job, outdir);
    RunReport {
        name: job.name.clone(),
        parameters: job.parameters.clone(),
        ok: false,
        error: Some(error.to_string()),
        summary: None,
        results: None,
        history: None,
        fmu_digests: BTreeMap::new(),
    }
}

/// The files a run folder holds (a folder is swapped into place only with its description
/// and its report in it).
const RUN_FOLDER_FILES: [&str; 7] = [
    "system.json",
    "summary.json",
    "results.csv",
    "results.meta.json",
    "history.csv",
    "history.meta.json",
    "history.parquet",
];

/// The file in a failed run's folder that holds its rows up to the failure.
fn history_file(format: ResultsFormat) -> &'static str {
    match format {
        ResultsFormat::Csv => "history.csv",
        ResultsFormat::Parquet => "history.parquet",
    }
}

/// A run's `summary.json` larger than this is not one (a report is a few kilobytes).
const MAX_RUN_REPORT_BYTES: u64 = 16 << 20;

/// Whether `dir` may be a run folder written by a sweep: a folder holding nothing but the
/// files a run writes, among them its description or its report (an interrupted or altered
/// run of an earlier set).
fn holds_only_run_files(dir: &Path) -> bool {
    if !dir.symlink_metadata().is_ok_and(|m| m.is_dir()) {
        return false;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    for e in entries {
        let Ok(e) = e else { return false };
        let ours = RUN_FOLDER_FILES
            .iter()
            .any(|f| e.file_name().to_str() == Some(*f));
        if !(ours && e.file_type().is_ok_and(|t| t.is_file())) {
            return false;
        }
    }
    dir.join("system.json").is_file() || dir.join("summary.json").is_file()
}

/// Whether `dir` holds the report (`summary.json`) of the run of its own name.
fn holds_its_runs_report(dir: &Path) -> bool {
    let report = dir.join("summary.json");
    let small = report
        .symlink_metadata()
        .is_ok_and(|m| m.is_file() && m.len() <= MAX_RUN_REPORT_BYTES);
    let names_this_run = || -> Option<bool> {
        let r: RunReport = serde_json::from_str(&std::fs::read_to_string(&report).ok()?).ok()?;
        Some(dir.file_name()?.to_str()? == r.name)
    };
    small && names_this_run() == Some(true)
}

/// Whether `dir`, the folder of a run's name, is a run folder of an earlier set: one that
/// [`holds_only_run_files`], or a finished run's folder of that name with something added to it
/// since (which a run of the set that writes the folder refuses, [`check_added_files`]; a kept
/// run leaves it). Anything else there is the user's and is refused.
fn replaceable_run_folder(dir: &Path) -> bool {
    dir.symlink_metadata().is_ok_and(|m| m.is_dir())
        && (holds_only_run_files(dir) || holds_its_runs_report(dir))
}

/// Refuses a run of `jobs` (the runs a set is about to write) whose earlier folder holds a file
/// that no run writes (a note of the user's): the run would replace the folder with it.
pub fn check_added_files(jobs: &[Job], outdir: &Path) -> Result<(), SweepError> {
    for job in jobs {
        let dest = outdir.join(&job.name);
        if let Some(file) = added_to_run_folder(&dest) {
            return Err(SweepError::AddedToRunFolder {
                path: dest,
                run: job.name.clone(),
                file,
            });
        }
    }
    Ok(())
}

/// Removes an earlier set's run folder and table of each of `jobs`, the runs a set is about to
/// write, before the first of them starts ([`check_added_files`] first: nothing of the user's is
/// removed). A set killed midway then leaves no earlier run under its names.
pub fn clear_earlier_runs(jobs: &[Job], outdir: &Path) -> Result<(), SweepError> {
    check_added_files(jobs, outdir)?;
    for job in jobs {
        clear_earlier_run(job, outdir);
    }
    Ok(())
}

/// The first entry of `dir` that no run writes, if `dir` is a finished run's folder (its
/// report naming it) to which something was added since (a note of the user's).
fn added_to_run_folder(dir: &Path) -> Option<String> {
    // a link is no run folder of ours: nothing is removed through it
    if !dir.symlink_metadata().is_ok_and(|m| m.is_dir()) {
        return None;
    }
    if !holds_its_runs_report(dir) || holds_only_run_files(dir) {
        return None;
    }
    let entries = std::fs::read_dir(dir).ok()?;
    entries.flatten().find_map(|e| {
        let name = e.file_name().to_string_lossy().to_string();
        let ours =
            RUN_FOLDER_FILES.contains(&name.as_str()) && e.file_type().is_ok_and(|t| t.is_file());
        (!ours).then_some(name)
    })
}

/// Whether `dir` is a finished run folder of an earlier sweep, which a new set removes when
/// the run is not among its own: it [`holds_only_run_files`] and the run's report naming it
/// (a user's folder with a `system.json` or a `summary.json` of its own, or a run folder
/// copied under another name, is not one).
fn is_earlier_run_folder(dir: &Path) -> bool {
    holds_only_run_files(dir) && holds_its_runs_report(dir)
}

/// Refuses a run whose folder `<outdir>/<run>` would replace something that is not a run
/// folder of an earlier sweep (a file or folder of the user's, the run set itself).
pub fn check_run_folders(jobs: &[Job], outdir: &Path) -> Result<(), SweepError> {
    if outdir.as_os_str().is_empty() {
        // an empty path would be the working folder, which is not chosen by accident
        return Err(SweepError::NoOutputFolder);
    }
    for job in jobs {
        let dest = outdir.join(&job.name);
        if dest.symlink_metadata().is_ok() && !replaceable_run_folder(&dest) {
            return Err(SweepError::NotARunFolder {
                path: dest,
                run: job.name.clone(),
            });
        }
        // a run removes its earlier table whatever the format: a user's file of that name
        // (or a file the master cannot read as a run's table) is not one
        let table = results_path(outdir, &job.name, ResultsFormat::Parquet);
        if table.symlink_metadata().is_ok() && !crate::parquet_file::is_run_table(&table) {
            return Err(SweepError::NotARunTable {
                path: table,
                run: job.name.clone(),
            });
        }
    }
    Ok(())
}

/// Refuses an input (the run-set file, its base system, an FMU) that lies in what a set of
/// `jobs` (of which it writes `writes`) into `outdir` replaces or removes: the folder of a run
/// it writes, an earlier run's folder not in the set (sweeping around the `system.json` of an
/// earlier run into the same folder would remove the file being read, or rewrite it), or the
/// run's own files of such a folder that also holds the user's (which stay).
pub fn check_inputs_outside_runs(
    inputs: &[PathBuf],
    jobs: &[Job],
    writes: &[Job],
    outdir: &Path,
) -> Result<(), SweepError> {
    let Ok(out) = outdir.canonicalize() else {
        // not there yet: nothing lies in it
        return Ok(());
    };
    // the runs written (the kept ones of a resumed set stay), and the earlier runs not in
    // the set, which go
    let set: std::collections::HashSet<&str> = jobs.iter().map(|j| j.name.as_str()).collect();
    let written: std::collections::HashSet<&str> = writes.iter().map(|j| j.name.as_str()).collect();
    for input in inputs {
        let Ok(path) = input.canonicalize() else {
            continue;
        };
        let Ok(rest) = path.strip_prefix(&out) else {
            continue;
        };
        let mut parts = rest.components();
        let (Some(first), Some(second)) = (parts.next(), parts.next()) else {
            continue;
        };
        let directly_in_folder = parts.next().is_none();
        let first = first.as_os_str().to_string_lossy();
        let folder = out.join(&*first);
        // an earlier run's folder with the user's files in it keeps them (only the run's own
        // files go, see prepare_run_folder)
        let own_file = || {
            directly_in_folder
                && RUN_FOLDER_FILES.contains(&second.as_os_str().to_string_lossy().as_ref())
        };
        let replaced = written.contains(&*first)
            || (!set.contains(&*first)
                && (is_earlier_run_folder(&folder)
                    || (added_to_run_folder(&folder).is_some() && own_file())));
        if replaced {
            return Err(SweepError::InputInRunFolder {
                input: input.clone(),
                folder: outdir.join(&*first),
            });
        }
    }
    Ok(())
}

/// Held while a run set writes into its output folder: an exclusive `flock` on the folder
/// itself (no file is created in it), released when dropped or when the process ends. Python
/// run sets take the same lock (`fcntl.flock`), so two sets, from the command line or from
/// Python, never mix their runs in one folder.
pub struct OutputFolderLock {
    _folder: std::fs::File,
}

/// Takes the [`OutputFolderLock`] of `outdir` (created if needed), or says that another set
/// holds it.
pub fn lock_output_folder(outdir: &Path) -> Result<OutputFolderLock, SweepError> {
    if outdir.as_os_str().is_empty() {
        return Err(SweepError::NoOutputFolder);
    }
    let dir_err = |source| SweepError::Dir {
        path: outdir.to_path_buf(),
        source,
    };
    if outdir.exists() && !outdir.is_dir() {
        return Err(SweepError::NotAFolder {
            path: outdir.to_path_buf(),
        });
    }
    std::fs::create_dir_all(outdir).map_err(dir_err)?;
    let folder = std::fs::File::open(outdir).map_err(dir_err)?;
    if !crate::fmu::extract::try_lock(&folder) {
        return Err(SweepError::FolderInUse {
            path: outdir.to_path_buf(),
        });
    }
    Ok(OutputFolderLock { _folder: folder })
}

/// Readies `outdir` for a run set whose whole set of runs (kept ones included) is `jobs`:
/// refuses, before anything is removed, a run whose folder would replace what is not a run
/// folder ([`check_run_folders`]); then removes the runs of an earlier set that are not among
/// `jobs` (their run folders, told from a user's folder by holding only a run's files and the
/// run's report naming them, and their tables `results/<run>.parquet`, told from a user's
/// Parquet file by the metadata in the footer), so that the folder, and the results folder
/// read as one table, hold this set's runs only. Nothing else is touched.
pub fn prepare_run_folder(jobs: &[Job], outdir: &Path) -> Result<(), SweepError> {
    check_run_folders(jobs, outdir)?;
    // the tables are written into <outdir>/results: a link there would put them (and this
    // function's removals) outside the output folder
    let tables = outdir.join(PARQUET_FOLDER);
    if tables.symlink_metadata().is_ok_and(|m| !m.is_dir()) {
        return Err(SweepError::NotATablesFolder { path: tables });
    }
    let keep: std::collections::HashSet<&str> = jobs.iter().map(|j| j.name.as_str()).collect();
    let remove_err = |path: PathBuf| move |source| SweepError::Dir { path, source };
    if let Ok(entries) = std::fs::read_dir(outdir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if keep.contains(name.as_str()) || name.starts_with('.') {
                continue;
            }
            let path = e.path();
            if name == PARQUET_FOLDER {
                continue;
            }
            if is_earlier_run_folder(&path) {
                std::fs::remove_dir_all(&path).map_err(remove_err(path.clone()))?;
            } else if let Some(file) = added_to_run_folder(&path) {
                // an earlier run's folder with something of the user's in it: the run's own
                // files go (they would read as a run of this set), the user's stay
                for own in RUN_FOLDER_FILES {
                    let f = path.join(own);
                    if f.symlink_metadata().is_ok_and(|m| m.is_file()) {
                        std::fs::remove_file(&f).map_err(remove_err(f.clone()))?;
                    }
                }
                log::warn!(
                    target: "master",
                    "'{}' held an earlier run that is not in this set, and '{file}', which no \
                     run writes: the run's files are removed, the rest is left",
                    path.display()
                );
            }
        }
    }
    if let Ok(entries) = std::fs::read_dir(outdir.join(PARQUET_FOLDER)) {
        for e in entries.flatten() {
            let path = e.path();
            let run = path.file_stem().map(|s| s.to_string_lossy().to_string());
            // a table of an earlier set's run (our metadata in its footer), not any Parquet
            // file of the user's that happens to sit there
            if path.extension().is_some_and(|x| x == "parquet")
                && run.is_some_and(|r| !keep.contains(r.as_str()))
                && crate::parquet_file::is_run_table(&path)
            {
                std::fs::remove_file(&path).map_err(remove_err(path.clone()))?;
            }
        }
    }
    Ok(())
}

/// Removes the hidden run folders an interrupted sweep left in `outdir`.
pub fn remove_partial_folders(outdir: &Path) {
    let Ok(entries) = std::fs::read_dir(outdir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let name = name.to_string_lossy();
        if (name.starts_with(PARTIAL_PREFIX) || name.starts_with(REPLACED_PREFIX))
            && e.file_type().is_ok_and(|t| t.is_dir())
        {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// Puts the complete folder `new` in place of `dest` (which may exist from an earlier
/// sweep): the old folder is moved aside, the new one renamed onto `dest`, the old one
/// removed. On failure the old folder is put back.
fn swap_into_place(new: tempfile::TempDir, dest: &Path, outdir: &Path) -> Result<(), String> {
    let fail = |e: std::io::Error| format!("cannot move the run into '{}': {e}", dest.display());
    let old = if dest.symlink_metadata().is_ok() {
        let aside = tempfile::Builder::new()
            .prefix(REPLACED_PREFIX)
            .tempdir_in(outdir)
            .map_err(fail)?
            .keep();
        let aside = aside.join("old");
        std::fs::rename(dest, &aside).map_err(fail)?;
        Some(aside)
    } else {
        None
    };
    let new = new.keep();
    if let Err(e) = std::fs::rename(&new, dest) {
        if let Some(a) = &old {
            let _ = std::fs::rename(a, dest);
        }
        let _ = std::fs::remove_dir_all(&new);
        return Err(fail(e));
    }
    if let Some(a) = old {
        if let Some(holder) = a.parent() {
            let _ = std::fs::remove_dir_all(holder);
        }
    }
    Ok(())
}

/// Runs one job with `runner` and writes its folder `<outdir>/<job>/`: `system.json`, then
/// `results.csv` (if the run succeeded; `history.csv` if it failed after its first row, from
/// a runner whose error is a [`FailedRun`] with a history) and `summary.json` (each
/// atomically) into a fresh hidden folder, which is swapped onto `<outdir>/<job>` when
/// complete, so a run folder never mixes files of two runs and a run whose `summary.json`
/// says ok has all its files. A runner may also hand over results computed elsewhere (another
/// process or machine); a runner that panics fails the run.
pub fn run_one<F, E>(job: &Job, outdir: &Path, runner: &F) -> RunReport
where
    F: Fn(&Job) -> Result<SimOutput, E>,
    E: Into<FailedRun<String>>,
{
    run_one_with(
        job,
        outdir,
        &ResultsOptions::default(),
        &BTreeMap::new(),
        runner,
    )
}

/// [`run_one`] with results written as `results` says; `kinds` are the constant columns of
/// the whole run set. Parquet results go to `<outdir>/results/<job>.parquet`: an earlier
/// one is removed before the run, so a failed rerun leaves no stale results in the table.
pub fn run_one_with<F, E>(
    job: &Job,
    outdir: &Path,
    results: &ResultsOptions,
    kinds: &BTreeMap<String, ConstantKind>,
    runner: &F,
) -> RunReport
where
    F: Fn(&Job) -> Result<SimOutput, E>,
    E: Into<FailedRun<String>>,
{
    let dest = outdir.join(&job.name);
    let table_file = results_path(outdir, &job.name, ResultsFormat::Parquet);
    let mut report = RunReport {
        name: job.name.clone(),
        parameters: job.parameters.clone(),
        ok: false,
        error: None,
        summary: None,
        results: None,
        history: None,
        fmu_digests: job.system.fmu_digests(),
    };
    let prefix = format!("{PARTIAL_PREFIX}{}-", job.name);
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix);
    // the run's folder as the user's umask allows (a temporary folder would be 0700)
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o777));
    }
    let partial = match builder.tempdir_in(outdir) {
        Ok(d) => d,
        Err(e) => {
            report.error = Some(format!(
                "cannot create a folder in '{}': {e}",
                outdir.display()
            ));
            return report;
        }
    };
    let dir = partial.path().to_path_buf();
    match std::fs::remove_file(&table_file) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            report.error = Some(format!(
                "cannot remove the earlier results '{}': {e}",
                table_file.display()
            ));
            return report;
        }
        _ => {}
    }
    if results.format == ResultsFormat::Csv {
        // a CSV run set rerun over a Parquet one leaves no empty table folder behind (only
        // an empty folder is removed: other runs' files stay)
        let _ = std::fs::remove_dir(outdir.join(PARQUET_FOLDER));
    }
    let final_path = results_path(outdir, &job.name, results.format);
    let ctx = RunContext {
        run: Some(job.name.clone()),
        parameters: job.parameters.clone(),
        labels: results.labels.get(&job.name).cloned().unwrap_or_default(),
        system: serde_json::to_value(&job.system).ok(),
        kinds: kinds.clone(),
        sampling_unknown: false,
    };
    let result = (|| -> Result<Summary, String> {
        write_json_atomic(&dir.join("system.json"), &job.system).map_err(|e| e.to_string())?;
        let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            crate::fmu::logger::in_run(&job.name, || runner(job).map_err(Into::into))
        }))
        .unwrap_or_else(|p| {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(format!("the run panicked: {what}").into())
        });
        let out = match ran {
            Ok(out) => out,
            Err(failed) => {
                // the rows before the failure go into the run's folder, never into the
                // results table, which holds completed runs only
                if let Some(history) = failed.history {
                    let name = history_file(results.format);
                    if let Err(e) = write_results(&dir.join(name), &history, results.format, &ctx) {
                        return Err(format!(
                            "{}; also: its history could not be written: {e}",
                            failed.error
                        ));
                    }
                    report.history = Some(dest.join(name));
                }
                return Err(failed.error);
            }
        };
        let path = match results.format {
            ResultsFormat::Csv => dir.join("results.csv"),
            ResultsFormat::Parquet => {
                let folder = outdir.join(PARQUET_FOLDER);
                std::fs::create_dir_all(&folder)
                    .map_err(|e| format!("cannot create '{}': {e}", folder.display()))?;
                final_path.clone()
            }
        };
        write_results(&path, &out, results.format, &ctx).map_err(|e| e.to_string())?;
        Ok(out.summary)
    })();
    match result {
        Ok(s) => {
            report.ok = true;
            report.summary = Some(s);
            report.results = Some(final_path.clone());
        }
        Err(e) => report.error = Some(e),
    }
    let finished = write_json_atomic(
        &dir.join("summary.json"),
        &report_in_folder(&report, outdir),
    )
    .map_err(|e| e.to_string())
    .and_then(|()| swap_into_place(partial, &dest, outdir));
    if let Err(e) = finished {
        let _ = std::fs::remove_file(&table_file);
        report.ok = false;
        report.results = None;
        report.history = None;
        report.error = Some(match report.error.take() {
            Some(first) => format!("{first}; also: {e}"),
            None => e,
        });
    }
    report
}

/// The report of `job` in `outdir` if that run is complete in `format` and is the same run:
/// its `summary.json` says ok, its results are there in `format` (and not in the other
/// format), its `system.json` is the job's resolved system (same FMUs, start values, timing)
/// and the FMU files are the ones it ran (same digests). A failed, unfinished or changed run, or one whose results are in the other format,
/// gives `None` and is run again: a resumed run set stays in one format, so the Parquet folder
/// (or the CSV files) hold every run. The sweep decides `format` before (explicit, else
/// [`format_by_description`] over all its jobs, as a fresh sweep does).
pub fn completed(outdir: &Path, job: &Job, format: ResultsFormat) -> Option<RunReport> {
    let dir = outdir.join(&job.name);
    let mut report: RunReport =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).ok()?).ok()?;
    let system: SystemDescription =
        serde_json::from_str(&std::fs::read_to_string(dir.join("system.json")).ok()?).ok()?;
    let results = results_path(outdir, &job.name, format);
    let other = results_path(outdir, &job.name, format.other());
    let complete = report.ok
        && report.name == job.name
        && report.parameters == job.parameters
        && system == job.system
        // the same FMU files: a rebuilt or replaced FMU at the same path is another model
        && report.fmu_digests == job.system.fmu_digests()
        && report.results.as_deref().and_then(Path::file_name) == results.file_name()
        && results.is_file()
        && other.symlink_metadata().is_err()
        // a table cut short or replaced since is no result: its footer names this run
        && (format != ResultsFormat::Parquet
            || crate::parquet_file::footer_metadata(&results)
                .is_some_and(|m| m.run.as_deref() == Some(job.name.as_str())));
    report.results = Some(results);
    complete.then_some(report)
}
