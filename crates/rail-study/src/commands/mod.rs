//! The railway subcommands of the `master` binary, one file each (the generic ones are
//! [`master::cli`]). To add one: write `src/commands/<name>.rs` with a `clap::Args` struct and
//! an `execute(&Args, &Context) -> Result<(), CommandError>`, declare it here and add a variant
//! to `Command` in `src/main.rs`.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use master::cli::CommandError;

use crate::analysis::{check_cancel, print_report, AnalysisError, Artefacts};

pub mod assess;
pub mod characterise;
pub mod contact_geometry;
pub mod root_locus;
pub mod study;

/// A figure that cannot be drawn stops the command with its own message.
impl From<crate::plot::PlotError> for CommandError {
    fn from(e: crate::plot::PlotError) -> Self {
        CommandError::Other(Box::new(e))
    }
}

/// An analysis failure as a command error (the message names the model, file or option).
pub(crate) fn failed(e: AnalysisError) -> CommandError {
    CommandError::Failed(e.to_string())
}

/// Ends an analysis command: unless interrupted, collects its files (`add`), writes them into
/// `out` (only now, after everything is computed, and none over one of the files it read,
/// `inputs`) and prints `summary` with the file list.
pub(crate) fn write_analysis(
    out: &Path,
    inputs: &[PathBuf],
    cancel: &AtomicBool,
    summary: &str,
    add: impl FnOnce(&mut Artefacts) -> Result<(), AnalysisError>,
) -> Result<(), CommandError> {
    check_cancel(cancel).map_err(failed)?;
    let mut files = Artefacts::default();
    add(&mut files).map_err(failed)?;
    let paths: Vec<PathBuf> = files.names().iter().map(|n| out.join(n)).collect();
    master::output::check_outputs_apart(inputs, &paths)?;
    files.write_all(out)?;
    print_report(summary, &files, out);
    Ok(())
}
