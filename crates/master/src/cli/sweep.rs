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
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
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
