//! Instructions per communication step of the coupled section's two loops, counted by
//! callgrind (load-independent): the benchmark runs itself under it.

use std::path::Path;
use std::process::Command;

use crate::STEP_S;

/// Instructions per communication step of the coupled section's two loops, each counted by
/// callgrind on its own (`--toggle-collect`), and where the master's extra ones go.
pub struct StepInstructions {
    pub master: f64,
    pub direct: f64,
    /// The master's extra instructions per step by where they run: in the master's executable
    /// (the master crate: the loop's own physics is not in it); in the FMU binaries beyond the
    /// plain loop's code (the same physics: the FMI glue and the FMU shells); in the system
    /// libraries (libm, memory copies) beyond the plain loop's.
    pub master_side: f64,
    pub fmu_side: f64,
    pub system: f64,
    /// Calls into the FMUs' C API per step.
    pub fmi_calls: f64,
}

/// Self cost by where it runs ([`StepInstructions`]) in one callgrind profile.
#[derive(Default, Clone, Copy)]
struct Costs {
    total: f64,
    executable: f64,
    fmu_binaries: f64,
    system: f64,
    /// calls into functions named `fmi2...` (the FMUs' C API)
    fmi_calls: f64,
}

/// [`Costs`] from a callgrind output file (format: valgrind's callgrind manual, "Callgrind
/// Format Specification"): the self cost of each function under the object that holds it
/// (`ob=`; a name in the plain loop's executable and in an FMU binary are two functions), and
/// the calls (`calls=`) to functions named `fmi2...`. Works on FMU binaries without a symbol
/// table too (their functions are addresses; the exported `fmi2...` entry points keep their
/// names).
fn profile_costs(profile: &str, executable: &Path) -> Costs {
    let mut costs = Costs::default();
    let exe = executable.to_string_lossy();
    // compressed names: "ob=(3) /path" the first time, "ob=(3)" after
    let mut objects: std::collections::HashMap<String, String> = Default::default();
    let mut functions: std::collections::HashMap<String, String> = Default::default();
    let mut object = String::new();
    let mut callee = String::new();
    // the cost line after "calls=" is the call's inclusive cost, not the caller's own
    let mut call_cost_next = false;
    let name = |table: &mut std::collections::HashMap<String, String>, spec: &str| -> String {
        let spec = spec.trim();
        match spec.strip_prefix('(').and_then(|r| r.split_once(')')) {
            Some((id, rest)) if !rest.trim().is_empty() => {
                table.insert(id.to_string(), rest.trim().to_string());
                rest.trim().to_string()
            }
            Some((id, _)) => table.get(id).cloned().unwrap_or_default(),
            None => spec.to_string(),
        }
    };
    for line in profile.lines() {
        if let Some(total) = line.strip_prefix("totals:") {
            costs.total = total.trim().parse().unwrap_or(0.0);
        } else if let Some(spec) = line.strip_prefix("ob=") {
            object = name(&mut objects, spec);
        } else if let Some(spec) = line.strip_prefix("fn=") {
            name(&mut functions, spec);
        } else if let Some(spec) = line.strip_prefix("cfn=") {
            callee = name(&mut functions, spec);
        } else if let Some(spec) = line.strip_prefix("cob=") {
            name(&mut objects, spec);
        } else if let Some(calls) = line.strip_prefix("calls=") {
            if callee.starts_with("fmi2") {
                let n = calls.split_whitespace().next().unwrap_or("0");
                costs.fmi_calls += n.parse::<f64>().unwrap_or(0.0);
            }
            call_cost_next = true;
        } else if line.starts_with(|c: char| c.is_ascii_digit() || "+-*".contains(c)) {
            if std::mem::take(&mut call_cost_next) {
                continue;
            }
            let ir: f64 = line
                .split_whitespace()
                .nth(1)
                .and_then(|n| n.parse().ok())
                .unwrap_or(0.0);
            if object == exe {
                costs.executable += ir;
            } else if object.contains("/binaries/") {
                costs.fmu_binaries += ir;
            } else {
                costs.system += ir;
            }
        }
    }
    costs
}

/// [`StepInstructions`]: this benchmark runs itself under callgrind with
/// `BENCH_COUPLED_ONCE_S` = 2 and 4 s, collecting only inside one loop at a time; the
/// difference between the two runs, over 2000 steps, is the cost per step without the
/// preparation (unpacking, loading, track synthesis).
pub fn instructions_per_step() -> Result<StepInstructions, String> {
    let found = Command::new("valgrind").arg("--version").output();
    if !found.is_ok_and(|o| o.status.success()) {
        return Err("valgrind not found (Debian: apt install valgrind)".into());
    }
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let steps = 2.0 / STEP_S;
    let mut per_step = Vec::new();
    for function in ["master_passive", "direct_passive"] {
        let mut profiles = Vec::new();
        for stop_s in [2, 4] {
            let file = dir.path().join(format!("callgrind.{function}.{stop_s}"));
            let run = Command::new("valgrind")
                .arg("--tool=callgrind")
                .arg(format!("--callgrind-out-file={}", file.display()))
                .arg(format!("--toggle-collect=ratios::coupled::{function}*"))
                .arg(&exe)
                .arg("--bench")
                .env("BENCH_COUPLED_ONCE_S", stop_s.to_string())
                .output()
                .map_err(|e| e.to_string())?;
            if !run.status.success() {
                return Err(format!(
                    "callgrind run of {stop_s} s failed: {}",
                    String::from_utf8_lossy(&run.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                ));
            }
            let profile = std::fs::read_to_string(&file).map_err(|e| e.to_string())?;
            profiles.push(profile_costs(&profile, &exe));
        }
        let (short, long) = (profiles[0], profiles[1]);
        let step = Costs {
            total: (long.total - short.total) / steps,
            executable: (long.executable - short.executable) / steps,
            fmu_binaries: (long.fmu_binaries - short.fmu_binaries) / steps,
            system: (long.system - short.system) / steps,
            fmi_calls: (long.fmi_calls - short.fmi_calls) / steps,
        };
        if step.total <= 0.0 {
            return Err(format!(
                "no instructions counted inside ratios::coupled::{function}"
            ));
        }
        per_step.push(step);
    }
    let (master, direct) = (per_step[0], per_step[1]);
    Ok(StepInstructions {
        master: master.total,
        direct: direct.total,
        master_side: master.executable,
        fmu_side: master.fmu_binaries - direct.executable,
        system: master.system - direct.system,
        fmi_calls: master.fmi_calls,
    })
}
