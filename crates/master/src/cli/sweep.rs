//! `master sweep RUNSET.json [-o outdir] [--jobs N]`: parameter variations in parallel.

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::runset::{execute as run_all, run_job, RunSet};
use crate::system::PreparedSystem;

/// Run a base system with parameter variations (cartesian product and/or list) in parallel.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Run-set description (JSON).
    pub runset: PathBuf,
    /// Output folder: one sub-folder per run plus sweep.json.
    #[arg(short, long, default_value = "sweep-out")]
    pub output: PathBuf,
    /// Number of parallel runs (default: all cores).
    #[arg(short, long)]
    pub jobs: Option<usize>,
    /// Run on a Dask cluster: one task per run, sent to this scheduler (e.g. tcp://host:8786).
    /// Done by the Python package railfmu (`python -m railfmu sweep`), which must be installed
    /// for the Python in $RAILFMU_PYTHON (default: python3), with dask.distributed.
    #[arg(long, value_name = "ADDRESS")]
    pub dask_scheduler: Option<String>,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    if let Some(address) = &args.dask_scheduler {
        return on_dask(args, address, ctx);
    }
    let (base, jobs) = RunSet::load(&args.runset)?;
    let system = PreparedSystem::prepare(&base)?;
    let threads = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let cancel = ctx.cancel;
    let reports = run_all(&jobs, &args.output, threads, ctx.progress, |job| {
        run_job(&system, job, cancel)
    })?;
    let failed: Vec<&str> = reports
        .iter()
        .filter(|r| !r.ok)
        .map(|r| r.name.as_str())
        .collect();
    for r in &reports {
        match (&r.summary, &r.error) {
            (Some(s), _) => println!("{}: ok, {s}", r.name),
            (None, Some(e)) => println!("{}: FAILED: {e}", r.name),
            _ => {}
        }
    }
    println!(
        "{} of {} runs ok; see {}",
        reports.len() - failed.len(),
        reports.len(),
        args.output.join("sweep.json").display()
    );
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CommandError::Failed(format!(
            "{} run(s) failed: {}",
            failed.len(),
            failed.join(", ")
        )))
    }
}

/// `--dask-scheduler`: the same run set through the Python package, which writes the same
/// run-set folder; its output and exit status are this command's.
fn on_dask(args: &Args, address: &str, ctx: &Context) -> Result<(), CommandError> {
    let python = std::env::var_os("RAILFMU_PYTHON").unwrap_or_else(|| "python3".into());
    let mut cmd = std::process::Command::new(&python);
    cmd.args(["-m", "railfmu", "sweep"])
        .arg(&args.runset)
        .arg("-o")
        .arg(&args.output)
        .args(["--dask-scheduler", address]);
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
