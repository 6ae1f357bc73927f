//! `master inspect FMU`: check an FMU and print its variables.

use std::path::PathBuf;

use std::sync::Arc;

use super::{CommandError, Context};
use crate::fmu::{FmuArchive, PreparedFmu};

/// Check an FMU as `master run` does (archive entries and limits, modelDescription against
/// FMI 2.0, platform binary present, loadable and exporting every function the master calls,
/// GUID accepted by fmi2Instantiate) and list its variables.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The .fmu file.
    pub fmu: PathBuf,
    /// Print the parsed model description as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Check only the archive and its modelDescription: do not unpack, load or instantiate
    /// the binary (no code of the FMU runs).
    #[arg(long)]
    pub no_load: bool,
}

pub fn execute(args: &Args, _ctx: &Context) -> Result<(), CommandError> {
    // an SSP is a zip too: without this it read as an FMU with no modelDescription.xml
    if crate::ssp::is_ssp_path(&args.fmu) {
        return Err(CommandError::Failed(format!(
            "'{}' is an SSP, not an FMU: inspect its FMUs (its resources/*.fmu), or run it \
             with `master run {}`",
            args.fmu.display(),
            args.fmu.display()
        )));
    }
    let a = FmuArchive::open(&args.fmu)?;
    if !args.no_load {
        // the same path as a run: unpack, load, look up the functions, instantiate once
        let prepared = Arc::new(PreparedFmu::prepare(a.clone(), "inspect")?);
        drop(prepared.instantiate("inspect", false)?);
    }
    let md = &a.model;
    if args.json {
        let s =
            serde_json::to_string_pretty(md).map_err(|e| CommandError::Failed(e.to_string()))?;
        println!("{s}");
        return Ok(());
    }
    println!("model      {}", md.model_name);
    println!("fmiVersion {}", md.fmi_version);
    println!("guid       {}", md.guid);
    if let Some(cs) = &md.co_simulation {
        println!(
            "co-simulation: modelIdentifier {}, canGetAndSetFMUstate {}, canHandleVariableCommunicationStepSize {}",
            cs.model_identifier, cs.can_get_and_set_fmu_state, cs.can_handle_variable_communication_step_size
        );
    }
    if let Some(d) = &md.default_experiment {
        let given = |x: Option<f64>| x.map_or("not given".to_string(), |x| format!("{x} s"));
        println!(
            "default experiment: start {}, stop {}, step {}",
            given(d.start_time),
            given(d.stop_time),
            given(d.step_size)
        );
    }
    print_binaries(&args.fmu);
    let (start, stop, step) = crate::system::default_timing(md);
    let outputs = md
        .variables
        .iter()
        .filter(|v| v.causality == crate::model_description::Causality::Output)
        .count();
    println!(
        "master run {} alone: instance '{}', start {start} s, stop {stop} s, step {step} s, \
         records its {outputs} outputs",
        args.fmu.display(),
        crate::system::instance_name(md)
    );
    for (t, items) in &md.enumerations {
        let items: Vec<String> = items
            .iter()
            .map(|i| format!("{} = {}", i.value, i.name))
            .collect();
        println!("enumeration {t}: {}", items.join(", "));
    }
    println!();
    println!(
        "{:<32} {:>5} {:<12} {:<11} {:<8} {:<8} {:>10} {:<14}  description",
        "name", "vr", "causality", "variability", "type", "unit", "start", "range"
    );
    for v in &md.variables {
        // the declared bounds, in the variable's unit ("-" where none is declared)
        let bound = |b: Option<f64>| b.map_or("-".to_string(), |x| crate::show::num(x).to_string());
        let range = if v.min.is_none() && v.max.is_none() {
            "-".to_string()
        } else {
            format!("{}..{}", bound(v.min), bound(v.max))
        };
        println!(
            "{:<32} {:>5} {:<12} {:<11} {:<8} {:<8} {:>10} {:<14}  {}",
            v.name,
            v.value_reference,
            v.causality.to_string(),
            v.variability.to_string(),
            v.var_type.to_string(),
            v.unit.as_deref().unwrap_or("-"),
            v.start.as_deref().unwrap_or("-"),
            range,
            v.description.as_deref().unwrap_or("")
        );
    }
    Ok(())
}

/// One line per binary of the FMU (read from the files, not loaded): platform folder, format
/// and architecture, the newest glibc symbol version it needs (the oldest glibc it loads on),
/// and any portability problem against the manylinux2014 baseline, as a warning.
fn print_binaries(fmu: &std::path::Path) {
    let report = match fmu_binary::check_fmu(fmu, &fmu_binary::Policy::default()) {
        Ok(r) => r,
        Err(e) => {
            println!("binaries: cannot read them: {e}");
            return;
        }
    };
    for b in &report.binaries {
        let platform = b
            .platform
            .map_or_else(|| "unknown platform".to_string(), |p| p.to_string());
        let what = match &b.info {
            Some(info) => {
                let archs: Vec<String> = info
                    .images
                    .iter()
                    .map(|i| i.architecture.to_string())
                    .collect();
                let glibc = info.newest_glibc().map_or_else(
                    || "no glibc symbol versions".to_string(),
                    |v| format!("needs glibc >= {v}"),
                );
                format!("{platform}, {} {}, {glibc}", info.format, archs.join(" + "))
            }
            None => format!("{platform}, unreadable"),
        };
        println!("binary     {}: {what}", b.entry);
        for p in &b.problems {
            println!("  warning: {p}");
        }
    }
}
