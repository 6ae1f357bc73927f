//! `master`: FMI 2.0 co-simulation master (see `master --help`).

use std::io::IsTerminal;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use master::commands::{self, CommandError, Context};

static CANCEL: AtomicBool = AtomicBool::new(false);

#[derive(Debug, Parser)]
#[command(
    name = "master",
    version,
    about = "FMI 2.0 co-simulation master for the bogie / yaw damper FMUs"
)]
struct Cli {
    /// Log level of the master and of FMU logger messages (error, warn, info, debug, trace).
    #[arg(long, global = true, default_value = "info")]
    log_level: log::LevelFilter,
    /// No progress bars.
    #[arg(short, long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run one system description and write results as CSV.
    Run(commands::run::Args),
    /// Run parameter variations of a system in parallel.
    Sweep(commands::sweep::Args),
    /// Check an FMU and print its variables.
    Inspect(commands::inspect::Args),
    /// Characterise the yaw dampers: hysteresis loops, FRFs, equivalent stiffness and damping.
    Characterise(commands::characterise::Args),
    /// Eigenvalues of the linear bogie over speed: root locus, critical speed, hunting frequency.
    RootLocus(commands::root_locus::Args),
    /// Wheel/rail contact geometry from profiles: delta r, contact angles, equivalent conicity.
    ContactGeometry(commands::contact_geometry::Args),
    /// The stability study: passive, semi-active and full-active yaw dampers, EN 14363 report.
    Study(commands::study::Args),
    /// EN 14363 stability assessment of recorded signals (ours or a host's export).
    Assess(commands::assess::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    master::fmu::install_logger(cli.log_level);
    if let Err(e) = ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            // second Ctrl-C: give up immediately
            std::process::exit(130);
        }
        eprintln!("interrupt: stopping at the next communication point (Ctrl-C again to abort)");
    }) {
        eprintln!("warning: cannot install the Ctrl-C handler: {e}");
    }
    let ctx = Context {
        cancel: &CANCEL,
        progress: !cli.quiet && std::io::stderr().is_terminal(),
    };
    let res: Result<(), CommandError> = match &cli.command {
        Command::Run(a) => commands::run::execute(a, &ctx),
        Command::Sweep(a) => commands::sweep::execute(a, &ctx),
        Command::Inspect(a) => commands::inspect::execute(a, &ctx),
        Command::Characterise(a) => commands::characterise::execute(a, &ctx),
        Command::RootLocus(a) => commands::root_locus::execute(a, &ctx),
        Command::ContactGeometry(a) => commands::contact_geometry::execute(a, &ctx),
        Command::Study(a) => commands::study::execute(a, &ctx),
        Command::Assess(a) => commands::assess::execute(a, &ctx),
    };
    match res {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            let mut src = std::error::Error::source(&e);
            while let Some(s) = src {
                // thiserror(transparent) repeats the message; print only new information
                let msg = s.to_string();
                if !e.to_string().contains(&msg) {
                    eprintln!("  caused by: {msg}");
                }
                src = s.source();
            }
            if CANCEL.load(Ordering::SeqCst) {
                ExitCode::from(130)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
