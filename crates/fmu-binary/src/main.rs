//! `fmu-binary FMU...`: check every binary of each FMU (format, architecture, fmi2 exports,
//! and for Linux the glibc baseline, allowed libraries, no RPATH/RUNPATH); exit 1 on any problem.

use std::path::PathBuf;
use std::process::ExitCode;

use fmu_binary::{check_fmu, LinuxPolicy, Policy, SymbolVersion, GLIBC_BASELINE};

const HELP: &str = "fmu-binary [--glibc X.Y | --native] FMU...

Checks every binary of each FMU: a known platform folder, one binary per model identifier,
the format and architecture of its folder (PE for win*, Mach-O for darwin*, ELF for linux*),
the FMI 2.0 functions exported; for Linux also the newest glibc symbol version (at most
--glibc, default 2.17), only glibc's own libraries and libgcc_s, no RPATH/RUNPATH.
Exits 1 if any FMU has a problem.

  --glibc X.Y   newest glibc symbol version a Linux binary may need (default 2.17)
  --native      skip the Linux portability rules";

fn main() -> ExitCode {
    let mut glibc = GLIBC_BASELINE;
    let mut native = false;
    let mut fmus: Vec<PathBuf> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--glibc" => match args.next().map(|v| v.parse::<SymbolVersion>()) {
                Some(Ok(v)) => glibc = v,
                Some(Err(e)) => {
                    eprintln!("fmu-binary: --glibc: {e}");
                    return ExitCode::from(2);
                }
                None => {
                    eprintln!("fmu-binary: --glibc needs a version, e.g. 2.17");
                    return ExitCode::from(2);
                }
            },
            "--native" => native = true,
            "-h" | "--help" => {
                println!("{HELP}");
                return ExitCode::SUCCESS;
            }
            other if other.starts_with('-') => {
                eprintln!("fmu-binary: unknown option '{other}' (see --help)");
                return ExitCode::from(2);
            }
            _ => fmus.push(PathBuf::from(a)),
        }
    }
    if fmus.is_empty() {
        eprintln!("fmu-binary: no FMU given (see --help)");
        return ExitCode::from(2);
    }
    let policy = if native {
        Policy::native()
    } else {
        Policy {
            linux: Some(LinuxPolicy::with_glibc(glibc)),
        }
    };
    let mut failed = 0usize;
    for path in &fmus {
        let report = match check_fmu(path, &policy) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("fmu-binary: {e}");
                failed += 1;
                continue;
            }
        };
        let verdict = if report.is_ok() { "ok" } else { "FAILED" };
        let platforms: Vec<String> = report.platforms().iter().map(|p| p.to_string()).collect();
        println!(
            "{}: {verdict} (platforms: {})",
            path.display(),
            if platforms.is_empty() {
                "none".into()
            } else {
                platforms.join(", ")
            }
        );
        if !report.binaries.iter().any(|b| b.model_identifier.is_some()) {
            println!(
                "  problem: no binary for {}",
                report.model_identifiers.join(", ")
            );
        }
        for b in &report.binaries {
            let mut line = format!("  {}", b.entry);
            if let Some(info) = &b.info {
                let archs: Vec<String> = info
                    .images
                    .iter()
                    .map(|i| i.architecture.to_string())
                    .collect();
                line += &format!(": {} {}", info.format, archs.join(" + "));
                if let Some(v) = info.newest_glibc() {
                    line += &format!(", needs glibc {v}");
                }
                let mut libs: Vec<&str> = info
                    .images
                    .iter()
                    .flat_map(|i| i.needed_libraries.iter().map(String::as_str))
                    .collect();
                libs.sort();
                libs.dedup();
                if !libs.is_empty() {
                    line += &format!(", links {}", libs.join(" "));
                }
            }
            println!("{line}");
            for p in &b.problems {
                println!("    problem: {p}");
            }
        }
        if !report.is_ok() {
            failed += 1;
        }
    }
    println!(
        "fmu-binary: {} of {} FMUs ok{}",
        fmus.len() - failed,
        fmus.len(),
        match &policy.linux {
            Some(l) => format!(" (Linux baseline glibc {})", l.glibc),
            None => " (Linux portability rules not checked)".into(),
        }
    );
    if failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
