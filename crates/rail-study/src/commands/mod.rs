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

/// An analysis subcommand as its output folder knows it: its name, which names its file list
/// `<name>.json`, and the file names it writes.
pub(crate) struct AnalysisCommand {
    pub name: &'static str,
    /// Whether a bare file name is one of the command's results: only such a name, listed in
    /// its earlier `<name>.json`, is removed from a reused folder or skipped as a result.
    pub owns: fn(&str) -> bool,
}

/// A CSV or SVG whose name starts with one of `prefixes`.
pub(crate) fn csv_or_svg_starting(name: &str, prefixes: &[&str]) -> bool {
    (name.ends_with(".csv") || name.ends_with(".svg"))
        && prefixes.iter().any(|p| name.starts_with(p))
}

/// An analysis command's output folder must be a folder or not exist yet, nor any folder
/// above it be a file or a link to nothing: checked before the computation, so that such a
/// path is named at once, not after the work.
pub(crate) fn check_out_folder(out: &Path) -> Result<(), CommandError> {
    // the nearest part of the path that exists decides (the rest is created)
    let Some(existing) = out
        .ancestors()
        .filter(|p| !p.as_os_str().is_empty())
        .find(|p| std::fs::symlink_metadata(p).is_ok())
    else {
        return Ok(());
    };
    let what = match std::fs::metadata(existing) {
        Ok(m) if m.is_dir() => return Ok(()),
        Ok(_) => "is a file, not a folder",
        Err(_) => "is a link to nothing, not a folder",
    };
    let named = if existing == out {
        format!("the output folder '{}'", out.display())
    } else {
        format!(
            "'{}', on the way to the output folder '{}',",
            existing.display(),
            out.display()
        )
    };
    Err(CommandError::Failed(format!("{named} {what}")))
}

/// Ends an analysis command: unless interrupted, collects its files (`add`), writes them into
/// `out` (only now, after everything is computed, and none over one of the files it read,
/// `inputs`) and prints `summary` with the file list.
///
/// The folder also gets `<command>.json`: the command, its command line and working folder,
/// its summary and the files it wrote.
/// A file of the command's kind ([`AnalysisCommand::owns`]) listed there by its previous run
/// into the same folder and not written this time (another mode, another amplitude, a figure
/// drawn only sometimes) is removed, so that the folder never mixes two runs' results;
/// nothing else in the folder is touched. A file that cannot be removed is warned about and
/// stays listed, for the next run to try again.
pub(crate) fn write_analysis(
    command: &AnalysisCommand,
    out: &Path,
    inputs: &[PathBuf],
    cancel: &AtomicBool,
    summary: &str,
    add: impl FnOnce(&mut Artefacts) -> Result<(), AnalysisError>,
) -> Result<(), CommandError> {
    write_analysis_with(
        command,
        out,
        inputs,
        cancel,
        summary,
        serde_json::Value::Null,
        add,
    )
}

/// [`write_analysis`] with the run's key numbers as `results` in `<command>.json` (a critical
/// speed, a verdict: what a script reads rather than parse the summary's text; `null` leaves
/// them out).
pub(crate) fn write_analysis_with(
    command: &AnalysisCommand,
    out: &Path,
    inputs: &[PathBuf],
    cancel: &AtomicBool,
    summary: &str,
    results: serde_json::Value,
    add: impl FnOnce(&mut Artefacts) -> Result<(), AnalysisError>,
) -> Result<(), CommandError> {
    check_cancel(cancel).map_err(failed)?;
    let mut files = Artefacts::default();
    add(&mut files).map_err(failed)?;
    // an interrupt while the files were made: nothing is written (exit status 130)
    check_cancel(cancel).map_err(failed)?;
    let written: Vec<String> = files.names().iter().map(|n| n.to_string()).collect();
    if let Some(n) = written.iter().find(|n| !(command.owns)(n)) {
        return Err(CommandError::Failed(format!(
            "internal: {} writes '{n}', which is not among its file names",
            command.name
        )));
    }
    let manifest_name = manifest_name(command.name);
    let mut paths: Vec<PathBuf> = files.names().iter().map(|n| out.join(n)).collect();
    paths.push(out.join(&manifest_name));
    master::output::check_outputs_apart(inputs, &paths)?;
    let stale: Vec<String> = written_before(out, command)
        .into_iter()
        .filter(|n| !written.contains(n))
        // a file read this time (a profile passed back in) stays
        .filter(|n| master::output::check_outputs_apart(inputs, &[out.join(n)]).is_ok())
        .collect();
    // the files and the list of them written in full before any replaces an earlier one (a
    // full disk must not leave the folder holding two runs' files)
    let manifest = |listed: &[String]| -> Result<Artefacts, CommandError> {
        let mut json = serde_json::json!({
            "command": command.name,
            // how these files were made, so that they can be told from another run's and
            // made again (the inputs as given, relative to the working directory)
            "command_line": std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect::<Vec<_>>(),
            "working_directory": std::env::current_dir()
                .map(|d| d.to_string_lossy().into_owned())
                .unwrap_or_default(),
            "summary": summary,
            "files": listed,
        });
        if !results.is_null() {
            json["results"] = results.clone();
        }
        let text = serde_json::to_string_pretty(&json)
            .map_err(|e| CommandError::Failed(format!("{manifest_name}: {e}")))?;
        let mut list = Artefacts::default();
        list.add_text(&manifest_name, text + "\n");
        Ok(list)
    };
    // the staged list also names the earlier files still to be removed, so that a process
    // ended in between leaves them listed for the next run; rewritten once they are gone
    let mut listed = written;
    let with_stale: Vec<String> = listed.iter().chain(&stale).cloned().collect();
    let mut list = manifest(&with_stale)?;
    let mut staged = files.stage_all(out)?;
    staged.extend(list.stage_all(out)?);
    // the last point at which an interrupt leaves the earlier files: the staged ones are
    // removed as they are dropped
    check_cancel(cancel).map_err(failed)?;
    crate::analysis::commit_all(staged)?;
    for name in &stale {
        if let Err(e) = master::output::remove_stale_file(&out.join(name)) {
            eprintln!(
                "warning: cannot remove '{}', a file of the previous {} run: {e}",
                out.join(name).display(),
                command.name
            );
            // listed for the next run to try again
            listed.push(name.clone());
        }
    }
    if !stale.is_empty() {
        list = manifest(&listed)?;
        list.write_all(out)?;
    }
    files.files.extend(list.files);
    print_report(summary, &files, out);
    Ok(())
}

/// `<command>.json`, the list of files an analysis command wrote into its folder.
fn manifest_name(command: &str) -> String {
    format!("{command}.json")
}

/// The files of the command's kind ([`AnalysisCommand::owns`]) that `<command>.json` in `out`
/// lists (an earlier run's), if it is a regular file of at most 1 MiB that reads as one; only
/// a bare file name (one plain path component) can be one.
pub(crate) fn written_before(out: &Path, command: &AnalysisCommand) -> Vec<String> {
    const LIMIT_BYTES: u64 = 1 << 20;
    let manifest = &out.join(manifest_name(command.name));
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
    let bare = |n: &str| {
        let mut parts = Path::new(n).components();
        matches!(parts.next(), Some(std::path::Component::Normal(_)))
            && parts.next().is_none()
            && !n.contains(['/', '\\', ':', '\0'])
    };
    json["files"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|v| v.as_str())
        .filter(|n| bare(n) && (command.owns)(n))
        .map(str::to_string)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::Ordering;

    /// An interrupt that arrives while the files are made leaves the earlier ones as they
    /// were (the command then exits 130): nothing is committed.
    #[test]
    fn an_interrupt_while_the_files_are_made_writes_nothing() {
        const COMMAND: AnalysisCommand = AnalysisCommand {
            name: "probe",
            owns: |n| n == "probe.csv",
        };
        let dir = tempfile::tempdir().unwrap();
        let earlier = dir.path().join("probe.csv");
        std::fs::write(&earlier, "earlier\n").unwrap();
        let cancel = AtomicBool::new(false);
        let r = write_analysis(&COMMAND, dir.path(), &[], &cancel, "s", |f| {
            f.add_text("probe.csv", "new\n".into());
            cancel.store(true, Ordering::SeqCst);
            Ok(())
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&earlier).unwrap(), "earlier\n");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("probe.csv")]);
        // not interrupted: written
        cancel.store(false, Ordering::SeqCst);
        write_analysis(&COMMAND, dir.path(), &[], &cancel, "s", |f| {
            f.add_text("probe.csv", "new\n".into());
            Ok(())
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&earlier).unwrap(), "new\n");
    }
}
