//! `master export-ssp SYSTEM.json OUT.ssp`: a system description as a self-contained SSP.

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::coupling::Algorithm;
use crate::system::LoadedSystem;

/// Write a JSON system description as an SSP 1.0 archive: its FMUs under resources/, one
/// parameter set per instance (resources/INSTANCE.ssv), connections, units, the default
/// experiment and the step (as libcosim and OMSimulator annotations).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// System description (JSON).
    pub system: PathBuf,
    /// The .ssp to write (atomically).
    pub output: PathBuf,
}

pub fn execute(args: &Args, _ctx: &Context) -> Result<(), CommandError> {
    let sys = LoadedSystem::load(&args.system)?;
    let inputs: Vec<PathBuf> = std::iter::once(args.system.clone())
        .chain((0..sys.desc.instances.len()).map(|i| sys.fmu_path(i)))
        .collect();
    crate::output::check_outputs_apart(&inputs, std::slice::from_ref(&args.output))?;
    let summary = crate::ssp::export(&sys, &args.output)?;
    println!("{}: {summary}", args.output.display());
    if sys.desc.algorithm == Algorithm::GaussSeidel {
        println!(
            "note: SSP has no coupling algorithm; hosts reading it (libcosim, Ecos, fmpy) and `master run` on it exchange Jacobi-style (gauss-seidel with `master run --algorithm gauss-seidel`)"
        );
    }
    Ok(())
}
