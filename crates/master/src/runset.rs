//! Run sets: a base system plus parameter variations, run in parallel.
//!
//! ```json
//! {
//!   "base": "system.json",                       // or "system": { ...inline... }
//!   "product": {"bogie.speed_mps": [60, 70, 80], "controller.mode": [0, 1]},
//!   "runs": [{"name": "special", "parameters": {"bogie.speed_mps": 90}}]
//! }
//! ```
//! Every combination of `product` (cartesian, keys in alphabetical order) and every entry of
//! `runs` is one job; with neither, the base alone is run. Keys are `instance.variable`.
//! Each job is self-contained (its resolved system description, FMU paths absolute) and is
//! written to `<outdir>/<run>/system.json`, with `summary.json` beside it and its results:
//! as CSV `<outdir>/<run>/results.csv` (metadata in `results.meta.json`), as Parquet
//! `<outdir>/results/<run>.parquet`, a folder of Parquet files alone that reads as one table
//! (`pandas.read_parquet("<outdir>/results")`: every run with its name and parameters as
//! columns; see [`crate::results`]).
//! The base system is prepared once ([`PreparedSystem`]: FMUs unpacked and loaded once, plan
//! built once); a job is then its start values and stop time ([`run_job`]). Jobs run on a
//! rayon pool; each job instantiates its own FMU instances (never shared across threads) and
//! frees them when done. A failed job is reported in its own summary and in
//! `<outdir>/sweep.json`; the other jobs go on.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;
use serde_json::Value;

use crate::coupling::{CouplingPlan, RunOptions, SimOutput, Summary};
use crate::output::{write_json_atomic, OutputError};
use crate::results::{constant_kinds, write_results, ConstantKind, ResultsFormat, RunContext};
use crate::system::{split_ref, LoadedSystem, PreparedSystem, SystemDescription, SystemError};

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSet {
    /// Path of the base system JSON (relative to the run-set file).
    #[serde(default)]
    pub base: Option<PathBuf>,
    /// Inline base system (FMU paths relative to the run-set file).
    #[serde(default)]
    pub system: Option<SystemDescription>,
    #[serde(default)]
    pub product: BTreeMap<String, Vec<Value>>,
    #[serde(default)]
    pub runs: Vec<RunSpec>,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    #[serde(default)]
    pub name: Option<String>,
    pub parameters: BTreeMap<String, Value>,
}

/// One self-contained run (serialisable both ways: a job can be sent to another process).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Job {
    pub name: String,
    pub parameters: BTreeMap<String, Value>,
    pub system: SystemDescription,
}

/// Outcome of one job (also each run's `summary.json`, which reads back into it).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RunReport {
    pub name: String,
    pub parameters: BTreeMap<String, Value>,
    pub ok: bool,
    pub error: Option<String>,
    pub summary: Option<Summary>,
    pub results: Option<PathBuf>,
}

#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error(transparent)]
    System(#[from] SystemError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error("cannot create '{path}': {source}")]
    Dir {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot start {jobs} worker threads: {reason}")]
    Pool { jobs: usize, reason: String },
}

fn invalid(file: &str, field: String, reason: String) -> SystemError {
    SystemError::Invalid {
        file: file.to_string(),
        line: None,
        field,
        reason,
    }
}

/// Most runs a run set may expand to: a product beyond this is refused before any job is
/// built (a typo such as 1e6 values in one list should not fill the disk).
pub const MAX_RUNS: usize = 100_000;

/// The folder of a run set's Parquet results (`<outdir>/results/<run>.parquet`), a name no
/// run may have.
pub const PARQUET_FOLDER: &str = "results";

/// Longest run name (folder names are limited to 255 bytes on common file systems).
const MAX_RUN_NAME_LEN: usize = 200;

/// Folder-safe run name: characters other than ASCII letters, digits and `._-=` become `_`.
pub fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-=".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The folder name of a run: [`sanitize`]d, and refused when it could not be a folder of its
/// own inside the output folder: empty, `.`/`..` or any name starting with `.` (hidden, and
/// the prefix of the sweep's temporary folders), `sweep.json` (the sweep's report) or longer
/// than 200 characters. `Err` is the reason.
pub fn run_folder_name(name: &str) -> Result<String, String> {
    let folder = sanitize(name);
    if folder.is_empty() {
        return Err("a run name must not be empty".into());
    }
    if folder.starts_with('.') {
        return Err(format!(
            "run name '{name}' would be the folder '{folder}': a run folder may not start with \
             '.' ('.' and '..' are not folders of their own)"
        ));
    }
    if folder.eq_ignore_ascii_case("sweep.json") {
        return Err(format!(
            "run name '{name}' is the name of the sweep's report file"
        ));
    }
    if folder.eq_ignore_ascii_case(PARQUET_FOLDER) {
        return Err(format!(
            "run name '{name}' is the name of the folder of the run set's Parquet results"
        ));
    }
    if folder.len() > MAX_RUN_NAME_LEN {
        return Err(format!(
            "run name '{}...' is longer than {MAX_RUN_NAME_LEN} characters",
            &folder[..40]
        ));
    }
    Ok(folder)
}

impl RunSet {
    /// Reads a run-set file and expands it into jobs.
    pub fn load_jobs(path: &Path) -> Result<Vec<Job>, SystemError> {
        Ok(Self::load(path)?.1)
    }

    /// Reads a run-set file: its base system and its jobs.
    pub fn load(path: &Path) -> Result<(LoadedSystem, Vec<Job>), SystemError> {
        let text = crate::input::read_text_file(path, crate::input::MAX_TEXT_FILE_BYTES).map_err(
            |source| SystemError::Read {
                path: path.to_path_buf(),
                source,
            },
        )?;
        let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_str_with_base(&text, &base_dir, &path.display().to_string())
    }

    pub fn jobs_from_str(text: &str, base_dir: &Path, file: &str) -> Result<Vec<Job>, SystemError> {
        Ok(Self::from_str_with_base(text, base_dir, file)?.1)
    }

    /// Parses run-set text: its base system and its jobs.
    pub fn from_str_with_base(
        text: &str,
        base_dir: &Path,
        file: &str,
    ) -> Result<(LoadedSystem, Vec<Job>), SystemError> {
        let rs: RunSet = serde_json::from_str(text).map_err(|e| SystemError::json(file, &e))?;
        let base = match (&rs.base, &rs.system) {
            (Some(p), None) => LoadedSystem::load(&base_dir.join(p))?,
            (None, Some(s)) => LoadedSystem::from_description(s.clone(), base_dir, file),
            _ => {
                return Err(invalid(
                    file,
                    "base".into(),
                    "give exactly one of 'base' (a path) or 'system' (inline)".into(),
                ))
            }
        };
        let jobs = rs.expand(&base, file)?;
        Ok((base, jobs))
    }

    /// Expands into jobs with resolved (absolute-path) system descriptions.
    pub fn expand(&self, base: &LoadedSystem, file: &str) -> Result<Vec<Job>, SystemError> {
        let resolved = base.resolved();
        let mut sets: Vec<(Option<String>, BTreeMap<String, Value>, String)> = Vec::new();
        if !self.product.is_empty() {
            let keys: Vec<&String> = self.product.keys().collect();
            for k in &keys {
                if self.product[*k].is_empty() {
                    return Err(invalid(
                        file,
                        format!("product.{k}"),
                        "empty list of values".into(),
                    ));
                }
            }
            let total = self
                .product
                .values()
                .try_fold(1usize, |n, v| n.checked_mul(v.len()))
                .filter(|&n| n.saturating_add(self.runs.len()) <= MAX_RUNS)
                .ok_or_else(|| {
                    let sizes: Vec<String> =
                        self.product.values().map(|v| v.len().to_string()).collect();
                    let combinations: f64 = self.product.values().map(|v| v.len() as f64).product();
                    invalid(
                        file,
                        "product".into(),
                        format!(
                            "{} = {combinations:e} combinations plus {} listed runs are more than \
                             the {MAX_RUNS} runs a run set may have; split it into several run sets",
                            sizes.join(" x "),
                            self.runs.len()
                        ),
                    )
                })?;
            for mut idx in 0..total {
                let mut p = BTreeMap::new();
                for k in keys.iter().rev() {
                    let vals = &self.product[*k];
                    p.insert((*k).clone(), vals[idx % vals.len()].clone());
                    idx /= vals.len();
                }
                sets.push((None, p, "product".into()));
            }
        }
        for (i, r) in self.runs.iter().enumerate() {
            sets.push((r.name.clone(), r.parameters.clone(), format!("runs[{i}]")));
        }
        if sets.is_empty() {
            sets.push((Some("base".into()), BTreeMap::new(), String::new()));
        }
        if self.runs.len() > MAX_RUNS {
            return Err(invalid(
                file,
                "runs".into(),
                format!(
                    "{} runs are more than the {MAX_RUNS} a run set may have",
                    self.runs.len()
                ),
            ));
        }
        let mut jobs = Vec::new();
        // folder name (lower case: also distinct on case-insensitive file systems) -> run
        let mut folders: std::collections::HashMap<String, String> =
            std::collections::HashMap::new();
        for (n, (name, params, field)) in sets.into_iter().enumerate() {
            let mut sys = resolved.clone();
            for (key, value) in &params {
                let f = format!("{field}.{key}");
                let Some((inst, var)) = split_ref(key) else {
                    return Err(invalid(
                        file,
                        f,
                        format!("'{key}' is not of the form 'instance.variable'"),
                    ));
                };
                let Some(spec) = sys.instances.iter_mut().find(|i| i.name == inst) else {
                    return Err(invalid(file, f, format!("unknown instance '{inst}'")));
                };
                spec.parameters.insert(var.to_string(), value.clone());
            }
            let given = name.unwrap_or_else(|| format!("run-{n:03}"));
            let name = run_folder_name(&given).map_err(|r| invalid(file, field.clone(), r))?;
            if let Some(other) = folders.insert(name.to_ascii_lowercase(), given.clone()) {
                let reason = if other == given {
                    format!("run name '{name}' is used twice")
                } else {
                    format!(
                        "run names '{other}' and '{given}' would both write the folder '{name}' \
                         (run names are used twice or differ only in characters replaced by '_' \
                         or in case)"
                    )
                };
                return Err(invalid(file, field, reason));
            }
            jobs.push(Job {
                name,
                parameters: params,
                system: sys,
            });
        }
        Ok(jobs)
    }
}

/// Runs one job of `system`'s run set (a job from [`RunSet::expand`] of that system: the same
/// instances, FMUs and timing; only start values and the stop time differ) on the prepared
/// FMUs: validates its start values, simulates, returns the output.
pub fn run_job(
    system: &PreparedSystem,
    job: &Job,
    cancel: &AtomicBool,
) -> Result<SimOutput, String> {
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
        ));
    }
    let changes = system
        .changes(&job.parameters, Some(job.system.stop_time), &run)
        .map_err(|e| e.to_string())?;
    let opts = RunOptions {
        cancel: Some(cancel),
        progress: None,
        general_engine: false,
    };
    system.run(&changes, &opts).map_err(|e| e.to_string())
}

/// How the runs of a run set write their results.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultsOptions {
    pub format: ResultsFormat,
    /// Constant columns besides the parameters, per run name (e.g. a study's configuration).
    pub labels: BTreeMap<String, BTreeMap<String, Value>>,
}

impl Default for ResultsOptions {
    fn default() -> Self {
        ResultsOptions {
            format: ResultsFormat::Csv,
            labels: BTreeMap::new(),
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
pub fn execute<F>(
    jobs: &[Job],
    outdir: &Path,
    threads: usize,
    show_progress: bool,
    runner: F,
) -> Result<Vec<RunReport>, SweepError>
where
    F: Fn(&Job) -> Result<SimOutput, String> + Sync,
{
    execute_with(
        jobs,
        outdir,
        threads,
        show_progress,
        &ResultsOptions::default(),
        runner,
    )
}

/// [`execute`] with results written as `results` says.
pub fn execute_with<F>(
    jobs: &[Job],
    outdir: &Path,
    threads: usize,
    show_progress: bool,
    results: &ResultsOptions,
    runner: F,
) -> Result<Vec<RunReport>, SweepError>
where
    F: Fn(&Job) -> Result<SimOutput, String> + Sync,
{
    let kinds = constant_kinds(jobs.iter().flat_map(|j| {
        j.parameters
            .iter()
            .chain(results.labels.get(&j.name).into_iter().flatten())
    }));
    let dir_err = |source| SweepError::Dir {
        path: outdir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(outdir).map_err(dir_err)?;
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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.clamp(1, jobs.len().max(1)))
        .build()
        .map_err(|e| SweepError::Pool {
            jobs: threads,
            reason: e.to_string(),
        })?;
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
                let r = run_one_with(job, outdir, results, &kinds, &runner);
                bar.inc(1);
                if !r.ok {
                    bar.println(format!(
                        "run '{}' failed: {}",
                        r.name,
                        r.error.as_deref().unwrap_or("")
                    ));
                }
                r
            })
            .collect()
    });
    bar.finish_and_clear();
    write_json_atomic(&report_path, &reports)?;
    Ok(reports)
}

/// Removes the hidden run folders an interrupted sweep left in `outdir`.
fn remove_partial_folders(outdir: &Path) {
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
/// `results.csv` (if the run succeeded) and `summary.json` (each atomically) into a fresh
/// hidden folder, which is swapped onto `<outdir>/<job>` when complete, so a run folder never
/// mixes files of two runs and a run whose `summary.json` says ok has all its files. A runner
/// may also hand over results computed elsewhere (another process or machine); a runner that
/// panics fails the run.
pub fn run_one<F>(job: &Job, outdir: &Path, runner: &F) -> RunReport
where
    F: Fn(&Job) -> Result<SimOutput, String>,
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
pub fn run_one_with<F>(
    job: &Job,
    outdir: &Path,
    results: &ResultsOptions,
    kinds: &BTreeMap<String, ConstantKind>,
    runner: &F,
) -> RunReport
where
    F: Fn(&Job) -> Result<SimOutput, String>,
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
    };
    let partial = match tempfile::Builder::new()
        .prefix(&format!("{PARTIAL_PREFIX}{}-", job.name))
        .tempdir_in(outdir)
    {
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
    let result = (|| -> Result<Summary, String> {
        write_json_atomic(&dir.join("system.json"), &job.system).map_err(|e| e.to_string())?;
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| runner(job)))
            .unwrap_or_else(|p| {
                let what = p
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                Err(format!("the run panicked: {what}"))
            })?;
        let ctx = RunContext {
            run: Some(job.name.clone()),
            parameters: job.parameters.clone(),
            labels: results.labels.get(&job.name).cloned().unwrap_or_default(),
            system: serde_json::to_value(&job.system).ok(),
            kinds: kinds.clone(),
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
    let finished = write_json_atomic(&dir.join("summary.json"), &report)
        .map_err(|e| e.to_string())
        .and_then(|()| swap_into_place(partial, &dest, outdir));
    if let Err(e) = finished {
        let _ = std::fs::remove_file(&table_file);
        report.ok = false;
        report.results = None;
        report.error = Some(match report.error.take() {
            Some(first) => format!("{first}; also: {e}"),
            None => e,
        });
    }
    report
}

/// The report of `job` in `outdir` if that run is complete in `format` and is the same run:
/// its `summary.json` says ok, its results are there in `format` (and not in the other
/// format) and its `system.json` is the job's resolved system (same FMUs, start values,
/// timing). A failed, unfinished or changed run, or one whose results are in the other format,
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
        && report.results.as_deref().and_then(Path::file_name) == results.file_name()
        && results.is_file()
        && other.symlink_metadata().is_err();
    report.results = Some(results);
    complete.then_some(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::tests::{two_mass_plan, MassSpring, Mock, SpringDamperMass};
    use crate::coupling::{simulate, Algorithm};

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
        let e =
            jobs(r#"{"runs": [{"name": "a", "parameters": {}}, {"name": "a", "parameters": {}}]}"#)
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
            simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default())
                .map_err(|e| e.to_string())
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
        let reports = execute_with(&j, dir.path(), 2, false, &opts, runner(None)).unwrap();
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
        for r in &reports {
            assert!(!dir.path().join(&r.name).join("results.csv").exists());
            assert_eq!(
                r.results.as_deref(),
                Some(table.join(format!("{}.parquet", r.name)).as_path())
            );
            assert!(completed(dir.path(), &j[0], ResultsFormat::Parquet).is_some());
            assert!(completed(dir.path(), &j[0], ResultsFormat::Csv).is_none());
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
        let reports =
            execute_with(&j, dir.path(), 2, false, &opts, runner(Some("run-001"))).unwrap();
        assert!(!reports[1].ok && reports[0].ok);
        assert!(!table.join("run-001.parquet").exists());
        assert!(table.join("run-002.parquet").exists());
        assert!(run_folder_name("Results").is_err());
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
        let reports = execute_with(&todo, outdir, 2, false, &opts, |job: &Job| {
            let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.02);
            plan.instances[0].parameters[1].1 = job.parameters["ms.k"].as_f64().unwrap();
            let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
            let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
            simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default())
                .map_err(|e| e.to_string())
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
        std::fs::write(results_path(out, "run-000", ResultsFormat::Parquet), b"x").unwrap();
        assert!(completed(out, &j[0], ResultsFormat::Csv).is_none());
        assert!(completed(out, &j[0], ResultsFormat::Parquet).is_none());
        assert_eq!(resume(&j, out, ResultsFormat::Csv), ["run-000"]);
        assert!(!out.join("results").exists());
    }
}
