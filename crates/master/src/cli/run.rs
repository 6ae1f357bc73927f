//! `master run SYSTEM.json|SYSTEM.ssp|SYSTEM.ssd [-o results.csv]`: one co-simulation, results
//! as CSV.

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::coupling::{Algorithm, RunOptions};
use crate::output::{write_csv_atomic, write_json_atomic};
use crate::ssp::{self, ImportOptions};
use crate::system::LoadedSystem;

/// Run one system description and write the recorded variables as CSV.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// System description: JSON (FMU paths relative to its folder), or an SSP (a .ssp archive,
    /// or a .ssd next to its FMUs).
    pub system: PathBuf,
    /// Results CSV (time plus recorded variables, units in the header); written atomically.
    #[arg(short, long, default_value = "results.csv")]
    pub output: PathBuf,
    /// Also write the run summary (steps, wall time, real-time ratio) as JSON.
    #[arg(long)]
    pub summary: Option<PathBuf>,
    /// SSP only: communication step [s] (default: the SSP's libcosim or OMSimulator annotation).
    #[arg(long)]
    pub step: Option<f64>,
    /// SSP only: stop time [s] (default: the SSP's DefaultExperiment).
    #[arg(long)]
    pub stop_time: Option<f64>,
    /// SSP only: coupling algorithm, jacobi (default) or gauss-seidel.
    #[arg(long, value_parser = parse_algorithm)]
    pub algorithm: Option<Algorithm>,
}

fn parse_algorithm(s: &str) -> Result<Algorithm, String> {
    match s {
        "jacobi" => Ok(Algorithm::Jacobi),
        "gauss-seidel" => Ok(Algorithm::GaussSeidel),
        _ => Err(format!("'{s}' is neither jacobi nor gauss-seidel")),
    }
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    // an imported SSP's FMUs live in a temporary folder as long as `_imported` does
    let (sys, _imported) = if ssp::is_ssp_path(&args.system) {
        let opts = ImportOptions {
            step: args.step,
            stop_time: args.stop_time,
            algorithm: args.algorithm,
        };
        let imported = ssp::import(&args.system, &opts)?;
        (imported.system.clone(), Some(imported))
    } else {
        if args.step.is_some() || args.stop_time.is_some() || args.algorithm.is_some() {
            return Err(CommandError::Failed(
                "--step, --stop-time and --algorithm apply to SSPs; a JSON system description sets them itself".into(),
            ));
        }
        (LoadedSystem::load(&args.system)?, None)
    };
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
