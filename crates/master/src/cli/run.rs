//! `master run SYSTEM.json [-o results.csv]`: one co-simulation, results as CSV.

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::coupling::RunOptions;
use crate::output::{write_csv_atomic, write_json_atomic};
use crate::system::LoadedSystem;

/// Run one system description and write the recorded variables as CSV.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// System description (JSON); FMU paths are relative to its folder.
    pub system: PathBuf,
    /// Results CSV (time plus recorded variables, units in the header); written atomically.
    #[arg(short, long, default_value = "results.csv")]
    pub output: PathBuf,
    /// Also write the run summary (steps, wall time, real-time ratio) as JSON.
    #[arg(long)]
    pub summary: Option<PathBuf>,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    let sys = LoadedSystem::load(&args.system)?;
    let bar = if ctx.progress {
        indicatif::ProgressBar::new(0)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let progress = |k: u64, n: u64| {
        if k == 1 {
            bar.set_length(n);
        }
        if k.is_multiple_of(64) || k == n {
            bar.set_position(k);
        }
    };
    let opts = RunOptions {
        cancel: Some(ctx.cancel),
        progress: Some(&progress),
    };
    let out = sys.run(&opts);
    bar.finish_and_clear();
    let out = out?;
    write_csv_atomic(&args.output, &out.header, out.rows())?;
    if let Some(p) = &args.summary {
        write_json_atomic(p, &out.summary)?;
    }
    println!("{}: {}", args.output.display(), out.summary);
    Ok(())
}
