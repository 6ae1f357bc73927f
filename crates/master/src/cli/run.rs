//! `master run SYSTEM.json|SYSTEM.ssp|SYSTEM.ssd [-o results.csv] [--format csv|parquet]` or
//! `master run MODEL.fmu`, each with `[--stop ..] [--set ..]` and the other changes of
//! [`SystemOverrides`]: one co-simulation, results as CSV or Parquet.

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::coupling::{Algorithm, FailedRun, RunOptions};
use crate::output::{check_outputs_apart, json_unfinished};
use crate::results::{
    csv_metadata_path, prepare_results, remove_results, ResultsFormat, RunContext,
};
use crate::ssp::{self, ImportOptions};
use crate::system::{LoadedSystem, OverridesFrom, SingleFmuOptions, SystemOverrides};

/// Run one system description, or one FMU alone, and write the recorded variables as CSV or
/// Parquet.
#[derive(Debug, clap::Args)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
pub struct Args {
    /// System description: JSON (FMU paths relative to its folder), an SSP (a .ssp archive,
    /// or a .ssd next to its FMUs), or an .fmu to run alone over its DefaultExperiment.
    pub system: PathBuf,
    /// Results file (time plus recorded variables, units in the header); written atomically.
    /// Named .csv, .parquet or .pq, or any name with --format.
    /// Default: results.csv, or results.parquet for large results (see --format); the other
    /// one of these two, written by an earlier run (its metadata says so), is then removed
    /// (a CSV with its metadata file); a file of that name without it stays.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Results format; default: by the extension of --output (.csv, .parquet), else Parquet
    /// from 200000 values (rows x columns) on, CSV below. A CSV has its metadata (units,
    /// FMU variables, sampling, summary) in <name>.meta.json beside it; Parquet inside.
    #[arg(long, value_enum)]
    pub format: Option<ResultsFormat>,
    /// Also write the run summary (steps, wall time, real-time ratio) as JSON.
    #[arg(long)]
    pub summary: Option<PathBuf>,
    /// Communication step [s]. Default: the description's; an SSP's libcosim or OMSimulator
    /// annotation; an FMU alone, its DefaultExperiment's, else 1/500 to 1/1000 of the run as
    /// fmpy.
    #[arg(long, allow_negative_numbers = true)]
    pub step: Option<f64>,
    /// Start time [s]. Default: the description's; the SSP's or FMU's DefaultExperiment's,
    /// else 0.
    #[arg(long, allow_negative_numbers = true)]
    pub start: Option<f64>,
    /// Stop time [s]. Default: the description's; the SSP's or FMU's DefaultExperiment's
    /// (an FMU without one: start + 1).
    #[arg(long, visible_alias = "stop-time", allow_negative_numbers = true)]
    pub stop: Option<f64>,
    /// Coupling algorithm, jacobi or gauss-seidel. Default: the description's (gauss-seidel
    /// unless it says); for an SSP the one `master export-ssp` kept in it, else jacobi. Not
    /// for an FMU alone.
    #[arg(long, value_parser = parse_algorithm)]
    pub algorithm: Option<Algorithm>,
    /// Start value of a parameter or input, NAME=VALUE (repeatable): NAME is
    /// instance.variable in a system, the variable's name for an FMU alone; numbers,
    /// true/false, text for Strings, an item name or integer for Enumerations. Replaces the
    /// description's value.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Variables to record, replacing the description's list (instance.variable in a system,
    /// the variable's name for an FMU alone; default: the description's, every output of an
    /// FMU alone).
    #[arg(long, num_args = 1.., value_name = "NAME")]
    pub record: Vec<String>,
    /// Switch the FMUs' own logging on (loggingOn), every instance of a system.
    #[arg(long)]
    pub fmu_logging: bool,
}

fn parse_algorithm(s: &str) -> Result<Algorithm, String> {
    match s {
        "jacobi" => Ok(Algorithm::Jacobi),
        "gauss-seidel" => Ok(Algorithm::GaussSeidel),
        _ => Err(format!(
            "'{}' is neither jacobi nor gauss-seidel",
            crate::show::text(s)
        )),
    }
}

impl Args {
    fn is_fmu(&self) -> bool {
        self.system
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("fmu"))
    }
    /// What a system (JSON or SSP) changes in its description.
    fn overrides(&self) -> SystemOverrides {
        SystemOverrides {
            from: OverridesFrom::CommandLine,
            start_time: self.start,
            stop_time: self.stop,
            step: self.step,
            algorithm: self.algorithm,
            set: self.set.clone(),
            record: self.record.clone(),
            logging: self.fmu_logging,
        }
    }
}

/// Where a failed run's history goes: `<stem>.history.<ext>` beside its results' name
/// (`r.csv` -> `r.history.csv`; a name without an extension, `r`, gets the format's:
/// `r.history.csv`, whose metadata `r.history.meta.json` is not the results').
fn history_path(results: &std::path::Path, format: ResultsFormat) -> PathBuf {
    let name = results
        .file_name()
        .map_or_else(|| "results".into(), |s| s.to_string_lossy().into_owned());
    let name = match (results.extension(), results.file_stem()) {
        (Some(ext), Some(stem)) => format!(
            "{}.history.{}",
            stem.to_string_lossy(),
            ext.to_string_lossy()
        ),
        _ => format!("{name}.history.{}", format.extension()),
    };
    results.with_file_name(name)
}

/// The results file of a run without --output: `results.csv` or `results.parquet` in the
/// current folder.
fn default_output(format: ResultsFormat) -> PathBuf {
    PathBuf::from(format!("results.{}", format.extension()))
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    // a name that says no format would get one by the results' size, and a CSV's metadata
    // file beside it that a later Parquet run to the same name would leave behind
    if let (None, Some(output)) = (args.format, &args.output) {
        if ResultsFormat::of_path(output).is_none() {
            return Err(CommandError::Failed(format!(
                "'{}' names no results format: name it .csv or .parquet, or give --format",
                output.display()
            )));
        }
    }
    // an imported SSP's FMUs live in a temporary folder as long as `imported` does
    let (sys, imported) = if args.is_fmu() {
        if args.algorithm.is_some() {
            return Err(CommandError::Failed(
                "--algorithm: an FMU run alone has no coupling".into(),
            ));
        }
        let opts = SingleFmuOptions {
            start_time: args.start,
            stop_time: args.stop,
            step: args.step,
            set: args.set.clone(),
            record: args.record.clone(),
            logging: args.fmu_logging,
        };
        (LoadedSystem::single_fmu(&args.system, &opts)?, None)
    } else if ssp::is_ssp_path(&args.system) {
        let opts = ImportOptions {
            step: args.step,
            stop_time: args.stop,
            algorithm: args.algorithm,
        };
        let imported = ssp::import(&args.system, &opts)?;
        let mut sys = imported.system.clone();
        sys.apply_overrides(&args.overrides())?;
        (sys, Some(imported))
    } else {
        let mut sys = LoadedSystem::load(&args.system)?;
        sys.apply_overrides(&args.overrides())?;
        (sys, None)
    };
    // the files it reads: the system file, every FMU (those of an archive are unpacked) and
    // the parameter and mapping files beside a bare .ssd
    let inputs: Vec<PathBuf> = std::iter::once(args.system.clone())
        .chain((0..sys.desc.instances.len()).map(|i| sys.fmu_path(i)))
        .chain(imported.iter().flat_map(|i| i.files_read.iter().cloned()))
        .collect();
    let written = |output: &PathBuf, format: ResultsFormat| {
        let mut files = vec![output.clone()];
        if format == ResultsFormat::Csv {
            files.push(csv_metadata_path(output));
        }
        files.extend(args.summary.iter().cloned());
        files
    };
    // the format, unless the results' size decides it: checked before the run as far as
    // the files are known then (a named --output, with its metadata file if CSV), and once
    // more after the run only for what the run decided
    let chosen = args
        .format
        .or_else(|| args.output.as_deref().and_then(ResultsFormat::of_path));
    let known = match &args.output {
        Some(output) => written(output, chosen.unwrap_or(ResultsFormat::Parquet)),
        None => args.summary.iter().cloned().collect::<Vec<_>>(),
    };
    check_outputs_apart(&inputs, &known)?;
    crate::output::check_folders_exist(&known)?;
    // a file named for one format does not take the other's content
    if let (Some(format), Some(output)) = (args.format, &args.output) {
        if let Some(named) = ResultsFormat::of_path(output).filter(|&n| n != format) {
            return Err(CommandError::Failed(format!(
                "'{}' is named as a {} file but --format {} writes {}: name it .{} or leave \
                 --format out",
                output.display(),
                named.extension(),
                format.extension(),
                format.extension(),
                format.extension()
            )));
        }
    }
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
        general_engine: false,
    };
    let out = sys.run_keeping_history(&opts);
    bar.finish_and_clear();
    // a run that fails (not one stopped by Ctrl-C) writes its history up to the failure
    // beside the results' name (`<name>.history.<ext>`, marked in its metadata), so that it can
    // be looked into, and an earlier run's results under the name are removed: neither they
    // nor a truncated history read as this run's results
    let (out, failure) = match out {
        Ok(out) => (out, None),
        Err(FailedRun {
            error,
            history: Some(history),
        }) => (*history, Some(error)),
        Err(failed) => return Err(failed.error.into()),
    };
    let cancel = ctx.cancel;
    // the files of the run: its results, or a failed run's history
    let write = || -> Result<PathBuf, CommandError> {
        let format = chosen.unwrap_or_else(|| {
            ResultsFormat::by_size(out.rows().count() as u64, out.header.len() as u64)
        });
        let results_name = args
            .output
            .clone()
            .unwrap_or_else(|| default_output(format));
        let output = match failure {
            Some(_) => history_path(&results_name, format),
            None => results_name.clone(),
        };
        // decided before anything is written: the history's metadata must not make a file of
        // the user's under the results' name look like ours
        let earlier_results_ours = failure.is_some()
            && crate::results::written_by_master(&results_name, format)
            && check_outputs_apart(&inputs, &written(&results_name, format)).is_ok();
        let earlier_history = history_path(&results_name, format);
        let earlier_history_ours = failure.is_none()
            && crate::results::written_by_master(&earlier_history, format)
            && check_outputs_apart(&inputs, &written(&earlier_history, format)).is_ok();
        if failure.is_some() {
            check_outputs_apart(&inputs, &written(&output, format))?;
            crate::output::check_folders_exist(&written(&output, format))?;
        }
        if args.output.is_none() || (chosen.is_none() && format == ResultsFormat::Csv) {
            // the files the run's size decided, checked as the others were before the run
            check_outputs_apart(&inputs, &written(&output, format))?;
            crate::output::check_folders_exist(&written(&output, format))?;
        }
        // FMU paths absolute, so that the description runs again from wherever it is saved; an
        // SSP's FMUs were unpacked into a temporary folder that goes after the run: each is
        // named by the archive and member it comes from
        let described = match &imported {
            Some(i) => {
                let mut d = sys.desc.clone();
                i.name_fmu_sources(&mut d);
                d
            }
            None => sys.resolved(),
        };
        let run_context = RunContext {
            system: serde_json::to_value(&described).ok(),
            ..RunContext::default()
        };
        // every file written before any earlier one is replaced
        let results = prepare_results(&output, &out, format, &run_context)?;
        let summary = match &args.summary {
            Some(p) => Some(json_unfinished(p, &out.summary)?),
            None => None,
        };
        // Ctrl-C or SIGTERM while the files were written: nothing replaces the earlier ones (the
        // unfinished files are removed when dropped), exit status 130 as after a cancelled run
        if cancel.load(std::sync::atomic::Ordering::SeqCst) {
            return Err(CommandError::Failed(
                "interrupted while writing the results: nothing written".into(),
            ));
        }
        results.commit()?;
        if let Some(summary) = summary {
            summary.commit()?;
        }
        if earlier_results_ours {
            // the results an earlier run wrote under this name (the master's only, and not an
            // input): they would read as this run's
            remove_results(&results_name, format)?;
        }
        if earlier_history_ours {
            // an earlier failed run's history beside these results would read as this run's
            remove_results(&earlier_history, format)?;
        }
        if args.output.is_none() {
            // the default file of the other format, from an earlier run, would read as a result
            // of this one (unless it is an input or the --summary file, which stay)
            let other = default_output(format.other());
            // only a results file of the master's (its metadata reads as such): a user's own
            // results.csv or results.parquet stays
            let ours = crate::results::written_by_master(&other, format.other());
            if ours && check_outputs_apart(&inputs, &written(&other, format.other())).is_ok() {
                remove_results(&other, format.other())?;
            }
        }
        Ok(output)
    };
    let written_to = write();
    if let Some(error) = failure {
        return Err(match written_to {
            Ok(path) => CommandError::FailedWithHistory {
                error: Box::new(error),
                time_s: out.summary.failed.as_ref().map_or(f64::NAN, |f| f.time_s),
                path: path.display().to_string(),
            },
            // the run's own error first: why it failed matters more than its history
            Err(e) => CommandError::Failed(format!(
                "{error}\nits history up to the failure was not written: {e}"
            )),
        });
    }
    let output = written_to?;
    println!("{}: {}", output.display(), out.summary);
    if let Some(t) = &out.summary.terminated {
        println!(
            "the simulation was ended by instance '{}' (fmi2Terminated) at t = {} s; results up to there",
            t.instance, t.time_s
        );
    }
    Ok(())
}
