//! Build every FMU crate of the workspace (release, feature `fmi-export`) and write
//! `dist/<Model>.fmu` for every model the built libraries carry.
//!
//! Usage: `cargo run --release -p model-description --bin package-fmus [-- --out DIR] [--no-build]`

use std::path::PathBuf;
use std::process::{Command, ExitCode};

use model_description::package;

fn main() -> ExitCode {
    let mut out = None;
    let mut build = true;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => out = args.next().map(PathBuf::from),
            "--no-build" => build = false,
            "-h" | "--help" => {
                println!("package-fmus [--out DIR] [--no-build]\n\nBuilds the FMU crates in release mode with feature fmi-export and writes DIR/<Model>.fmu (default DIR: <workspace>/dist).");
                return ExitCode::SUCCESS;
            }
            other => {
                eprintln!("package-fmus: unknown argument '{other}' (see --help)");
                return ExitCode::from(2);
            }
        }
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = out.unwrap_or_else(|| root.join("dist"));
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    if build {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let status = Command::new(cargo)
            .current_dir(&root)
            .args([
                "build",
                "--release",
                "--workspace",
                "--lib",
                "--features",
                "fmi-export",
            ])
            .status();
        match status {
            Ok(s) if s.success() => {}
            Ok(s) => {
                eprintln!("package-fmus: cargo build failed ({s})");
                return ExitCode::FAILURE;
            }
            Err(e) => {
                eprintln!("package-fmus: cannot run cargo: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    let release = target.join("release");
    let mut libs: Vec<PathBuf> = match std::fs::read_dir(&release) {
        Ok(rd) => rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension().is_some_and(|x| x == "so")
                    && p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with("lib"))
            })
            .collect(),
        Err(e) => {
            eprintln!("package-fmus: {}: {e}", release.display());
            return ExitCode::FAILURE;
        }
    };
    libs.sort();
    let mut written = 0;
    for lib in libs {
        let models = match package::read_manifest(&lib) {
            Ok(Some(m)) => m,
            Ok(None) => continue,
            Err(e) => {
                eprintln!("package-fmus: {e}");
                return ExitCode::FAILURE;
            }
        };
        let binary = match std::fs::read(&lib) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("package-fmus: {}: {e}", lib.display());
                return ExitCode::FAILURE;
            }
        };
        for m in &models {
            match package::write_fmu(&out, m, &binary, "linux64") {
                Ok(p) => {
                    println!("wrote {}", p.display());
                    written += 1;
                }
                Err(e) => {
                    eprintln!("package-fmus: {e}");
                    return ExitCode::FAILURE;
                }
            }
        }
    }
    if written == 0 {
        eprintln!(
            "package-fmus: no FMU library found in {}",
            release.display()
        );
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
