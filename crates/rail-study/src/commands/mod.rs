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
///
/// The folder also gets `<command>.json`: the command, its summary and the files it wrote.
/// A file listed there by the command's previous run into the same folder and not written
/// this time (another mode, another amplitude, a figure drawn only sometimes) is removed, so
/// that the folder never mixes two runs' results; nothing else in the folder is touched.
pub(crate) fn write_analysis(
    command: &str,
    out: &Path,
    inputs: &[PathBuf],
    cancel: &AtomicBool,
    summary: &str,
    add: impl FnOnce(&mut Artefacts) -> Result<(), AnalysisError>,
) -> Result<(), CommandError> {
    check_cancel(cancel).map_err(failed)?;
    let mut files = Artefacts::default();
    add(&mut files).map_err(failed)?;
    let manifest_name = manifest_name(command);
    let written: Vec<String> = files.names().iter().map(|n| n.to_string()).collect();
    let manifest = serde_json::json!({
        "command": command,
        "summary": summary,
        "files": written,
    });
    let text = serde_json::to_string_pretty(&manifest)
        .map_err(|e| CommandError::Failed(format!("{manifest_name}: {e}")))?;
    files.add_text(&manifest_name, text + "\n");
    let paths: Vec<PathBuf> = files.names().iter().map(|n| out.join(n)).collect();
    master::output::check_outputs_apart(inputs, &paths)?;
    let stale: Vec<PathBuf> = written_before(out, command)
        .into_iter()
        .filter(|n| *n != manifest_name && !written.contains(n))
        .map(|n| out.join(n))
        // a file read this time (a profile passed back in) stays
        .filter(|p| master::output::check_outputs_apart(inputs, std::slice::from_ref(p)).is_ok())
        .collect();
    files.write_all(out)?;
    for path in stale {
        master::output::remove_stale_file(&path).map_err(|source| {
            CommandError::Output(master::output::OutputError::Io { path, source })
        })?;
    }
    print_report(summary, &files, out);
    Ok(())
}

/// `<command>.json`, the list of files an analysis command wrote into its folder.
fn manifest_name(command: &str) -> String {
    format!("{command}.json")
}

/// The files that `<command>.json` in `out` lists (an earlier run's), if it is a regular file
/// of at most 1 MiB that reads as one; only bare file names (a name with a folder in it, `.`
/// or `..` is not the command's).
pub(crate) fn written_before(out: &Path, command: &str) -> Vec<String> {
    const LIMIT_BYTES: u64 = 1 << 20;
    let manifest = &out.join(manifest_name(command));
    let regular = std::fs::symlink_metadata(manifest)
        .is_ok_and(|m| m.file_type().is_file() && m.len() <= LIMIT_BYTES);
    if !regular {
        return Vec::new();
    }
    let Ok(text) = std::fs::read_to_string(manifest) else {
        return Vec::new();
    };
    let Ok(json) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    json["files"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|v| v.as_str())
        .filter(|n| !n.is_empty() && *n != "." && *n != ".." && !n.contains(['/', '\\', '\0']))
        .map(str::to_string)
        .collect()
}
