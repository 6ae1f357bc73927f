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
    // an archive given as the system would be read as JSON text ("not valid UTF-8")
    let is = |ext: &str| {
        args.system
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    if crate::ssp::is_ssp_path(&args.system) || is("fmu") {
        return Err(CommandError::Failed(format!(
            "'{}' is not a JSON system description: export-ssp writes one as an SSP (an SSP or \
             an FMU runs as it is: `master run {}`)",
            args.system.display(),
            args.system.display()
        )));
    }
    let sys = LoadedSystem::load(&args.system)?;
    let inputs: Vec<PathBuf> = std::iter::once(args.system.clone())
        .chain((0..sys.desc.instances.len()).map(|i| sys.fmu_path(i)))
        .collect();
    crate::output::check_outputs_apart(&inputs, std::slice::from_ref(&args.output))?;
    // a missing folder named as such (the write's error named its hidden temporary file)
    crate::output::check_folders_exist(std::slice::from_ref(&args.output))?;
    // a zip under another name is read as that (a .json as text, "not valid UTF-8")
    if !args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ssp"))
    {
        return Err(CommandError::Failed(format!(
            "'{}': an SSP is written as a .ssp file (a zip archive that hosts and `master run` \
             recognise by that extension)",
            args.output.display()
        )));
    }
    let summary = crate::ssp::export(&sys, &args.output)?;
    println!("{}: {summary}", args.output.display());
    // what SSP has no place for travels in the master's own annotation, which other hosts skip
    if sys.desc.algorithm == Algorithm::GaussSeidel {
        println!(
            "note: SSP has no coupling algorithm: `master run` on the archive couples \
             gauss-seidel (in the order, sweeps and halvings of the description), as the \
             master's annotation in it says; other hosts (libcosim, Ecos, fmpy) exchange \
             Jacobi-style"
        );
    }
    Ok(())
}
