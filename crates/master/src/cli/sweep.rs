//! `master sweep RUNSET.json [-o outdir] [--jobs N] [--resume] [--dask-scheduler ADDRESS]`:
//! parameter variations in parallel, on this machine or on a Dask cluster.

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::results::ResultsFormat;
use crate::runset::{
    check_added_files, check_given_one_way, check_inputs_outside_runs, check_start_values,
    completed, execute_with as run_all, format_by_description, lock_output_folder,
    prepare_run_folder, run_job, thread_pool, write_sweep_report, Job, ResultsOptions, RunReport,
    RunSet, NOT_STARTED,
};
use crate::system::PreparedSystem;

/// Run a base system with parameter variations (cartesian product and/or list) in parallel.
#[derive(Debug, clap::Args)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
pub struct Args {
    /// Run-set description (JSON).
    pub runset: PathBuf,
    /// Output folder: one sub-folder per run plus sweep.json.
    #[arg(short, long, default_value = "sweep-out")]
    pub output: PathBuf,
    /// Number of parallel runs (default: all cores). Not with --dask-scheduler, whose workers
    /// run the runs.
    #[arg(short, long, conflicts_with = "dask_scheduler")]
    pub jobs: Option<usize>,
    /// Run on a Dask cluster: one task per run, sent to this scheduler (e.g. tcp://host:8786).
    /// Done by the Python package railfmu (`python -m railfmu sweep`), which must be installed
    /// for the Python in $RAILFMU_PYTHON (default: python3), with dask.distributed.
    #[arg(long, value_name = "ADDRESS")]
    pub dask_scheduler: Option<String>,
    /// Keep the runs already complete in the output folder (summary ok, results present in the
    /// results format of this sweep, same resolved system) and run only the others; sweep.json
    /// then lists every run. The format is decided first (--format, else by size as a fresh
    /// sweep): runs kept in the other format are run again, so the folder stays in one format.
    #[arg(long)]
    pub resume: bool,
    /// Results format: csv (<run>/results.csv) or parquet (results/<run>.parquet, the folder
    /// reads as one table with each run's name and parameters as columns); default: Parquet
    /// when a run has 200000 values (rows x columns) or more, else CSV.
    #[arg(long, value_enum)]
    pub format: Option<ResultsFormat>,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    if let Some(address) = &args.dask_scheduler {
        return on_dask(args, address, ctx);
    }
    let (base, jobs) = RunSet::load(&args.runset)?;
    // the report the set writes must not replace the run-set file or its base system (a
    // run set named sweep.json swept into its own folder), nor one of the FMUs
    let mut inputs = vec![args.runset.clone(), PathBuf::from(&base.file)];
    inputs.extend(
        base.desc
            .instances
            .iter()
            .map(|i| base.base_dir.join(&i.fmu)),
    );
    crate::output::check_outputs_apart(&inputs, &[args.output.join("sweep.json")])?;
    // decided before the kept runs, over every job, so a resumed sweep writes the format a
    // fresh one would and keeps only runs complete in it
    let format = match args.format {
        Some(f) => f,
        None => format_by_description(&base, &jobs)?,
    };
    let kept: Vec<Option<RunReport>> = jobs
        .iter()
        .map(|j| {
            args.resume
                .then(|| completed(&args.output, j, format))
                .flatten()
        })
        .collect();
    let todo: Vec<Job> = jobs
        .iter()
        .zip(&kept)
        .filter(|(_, k)| k.is_none())
        .map(|(j, _)| j.clone())
        .collect();
    // the FMUs loaded and every run's start values checked before anything is removed
    let system = if !todo.is_empty() || !args.resume {
        let system = PreparedSystem::prepare(&base)?;
        // each run to be made; the enumerations over the whole set, kept runs too
        check_start_values(&system, &todo)?;
        check_given_one_way(&system, &jobs)?;
        Some(system)
    } else {
        None
    };
    if args.jobs == Some(0) {
        return Err(CommandError::Failed(
            "invalid option --jobs = 0: at least one run at a time (leave it out for one per \
             core)"
                .into(),
        ));
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = args.jobs.unwrap_or(cores);
    if threads > cores && todo.len() > cores {
        log::warn!(
            target: "master",
            "--jobs {threads} runs more runs at a time than the {cores} cores: they share the \
             cores (no faster) and each holds its results in memory"
        );
    }
    // the workers started before anything is removed: a count the system cannot start leaves
    // the earlier runs in place
    if !todo.is_empty() {
        drop(thread_pool(threads, todo.len())?);
    }
    // no input inside what the set replaces or removes (a run's system.json swept again), and
    // nothing of the user's in a folder it replaces
    check_inputs_outside_runs(&inputs, &jobs, &todo, &args.output)?;
    check_added_files(&todo, &args.output)?;
    // one set at a time in a folder: a second one would mix its runs into this one's
    let _lock = lock_output_folder(&args.output)?;
    // the runs of this set only: nothing of the user's is replaced by a run folder, and
    // runs of an earlier set into this folder are removed (the kept ones are in this set)
    prepare_run_folder(&jobs, &args.output)?;
    let mut fresh = Vec::new();
    if let Some(system) = system {
        let cancel = ctx.cancel;
        // the columns of the whole set, the kept runs' too
        let results = ResultsOptions {
            format,
            integer_columns: system
                .integer_parameters(jobs.iter().flat_map(|j| j.parameters.keys())),
            kept_parameters: jobs
                .iter()
                .zip(&kept)
                .filter(|(_, k)| k.is_some())
                .map(|(j, _)| j.parameters.clone())
                .collect(),
            ..ResultsOptions::default()
        };
        fresh = run_all(
            &todo,
            &args.output,
            threads,
            ctx.progress,
            &results,
            Some(cancel),
            |job| run_job(&system, job, cancel),
        )?;
    }
    let mut fresh = fresh.into_iter();
    let reports: Vec<RunReport> = kept
        .into_iter()
        .map(|k| k.or_else(|| fresh.next()))
        .collect::<Option<_>>()
        .ok_or_else(|| CommandError::Failed("internal: a run has no report".into()))?;
    if args.resume {
        write_sweep_report(&args.output, &reports)?;
        let n_kept = reports.len() - todo.len();
        println!("{n_kept} complete run(s) kept, {} run", todo.len());
    }
    let not_started = reports
        .iter()
        .filter(|r| r.error.as_deref() == Some(NOT_STARTED))
        .count();
    let failed: Vec<&str> = reports
        .iter()
        .filter(|r| !r.ok && r.error.as_deref() != Some(NOT_STARTED))
        .map(|r| r.name.as_str())
        .collect();
    for r in &reports {
        match (&r.summary, &r.error) {
            (Some(s), _) => println!("{}: ok, {s}", r.name),
            (None, Some(e)) if e != NOT_STARTED => match &r.history {
                Some(h) => println!(
                    "{}: FAILED: {e} (its history up to the failure is in {})",
                    r.name,
                    h.display()
                ),
                None => println!("{}: FAILED: {e}", r.name),
            },
            _ => {}
        }
    }
    let ok = reports.len() - failed.len() - not_started;
    println!(
        "{ok} of {} runs ok{}; see {}",
        reports.len(),
        if not_started > 0 {
            format!(", {not_started} not started")
        } else {
            String::new()
        },
        args.output.join("sweep.json").display()
    );
    if ctx.cancel.load(std::sync::atomic::Ordering::SeqCst) {
        return Err(CommandError::Failed(format!(
            "interrupted: {ok} of {} runs ok, {} failed or stopped, {not_started} not started; \
             `master sweep --resume` runs the others",
            reports.len(),
            failed.len()
        )));
    }
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CommandError::Failed(format!(
            "{} run(s) failed: {}",
            failed.len(),
            first_names(&failed, 10)
        )))
    }
}

/// The first `n` of `names`, and how many more there are (a set of 100 000 failed runs must
/// not print 100 000 names on one line).
fn first_names(names: &[&str], n: usize) -> String {
    let shown = names[..names.len().min(n)].join(", ");
    if names.len() > n {
        format!("{shown} and {} more (see sweep.json)", names.len() - n)
    } else {
        shown
    }
}

/// `--dask-scheduler`: the same run set through the Python package, which writes the same
/// run-set folder (the same format, chosen by size there when not given); its output and exit
/// status are this command's.
fn on_dask(args: &Args, address: &str, ctx: &Context) -> Result<(), CommandError> {
    let python = std::env::var_os("RAILFMU_PYTHON").unwrap_or_else(|| "python3".into());
    let mut cmd = std::process::Command::new(&python);
    cmd.args(["-m", "railfmu", "sweep"])
        .arg(&args.runset)
        .arg("-o")
        .arg(&args.output)
        .args(["--dask-scheduler", address]);
    if args.resume {
        cmd.arg("--resume");
    }
    if let Some(format) = args.format {
        cmd.args(["--format", format.extension()]);
    }
    if !ctx.progress {
        cmd.arg("--quiet");
    }
    let status = cmd.status().map_err(|e| {
        CommandError::Failed(format!(
            "--dask-scheduler needs the Python package railfmu: cannot start '{}': {e}",
            std::path::Path::new(&python).display()
        ))
    })?;
    if status.success() {
        Ok(())
    } else {
        Err(CommandError::Failed(format!(
            "the run set on the Dask cluster {address} did not complete ({status})"
        )))
    }
}
