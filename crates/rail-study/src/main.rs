//! `master`: FMI 2.0 co-simulation master with the railway study (see `master --help`). The
//! generic subcommands come from [`master::cli`], the railway ones from [`rail_study::commands`].

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use master::cli::{run_command, GenericCommand, GlobalArgs};
use rail_study::commands;

#[derive(Debug, Parser)]
#[command(
    name = "master",
    version,
    about = "FMI 2.0 co-simulation master for the bogie / yaw damper FMUs"
)]
struct Cli {
    #[command(flatten)]
    global: GlobalArgs,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    #[command(flatten)]
    Generic(GenericCommand),
    /// Characterise the yaw dampers: hysteresis loops, FRFs, equivalent stiffness and damping.
    Characterise(commands::characterise::Args),
    /// Eigenvalues of the linear coach or bogie over speed: root locus, critical speed, mode.
    RootLocus(commands::root_locus::Args),
    /// Wheel/rail contact geometry from profiles: delta r, contact angles, equivalent conicity.
    ContactGeometry(commands::contact_geometry::Args),
    /// The stability study: passive, semi-active and full-active yaw dampers, EN 14363 report.
    Study(commands::study::Args),
    /// EN 14363 stability assessment of recorded signals (ours or a host's export).
    Assess(commands::assess::Args),
}

fn main() -> ExitCode {
    // A closed stdout (`master inspect X.fmu | head`) ends the process quietly, as for any
    // Unix tool, instead of a panic on the failed print.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    run_command(&cli.global, |ctx| match &cli.command {
        Command::Generic(c) => c.execute(ctx),
        Command::Characterise(a) => commands::characterise::execute(a, ctx),
        Command::RootLocus(a) => commands::root_locus::execute(a, ctx),
        Command::ContactGeometry(a) => commands::contact_geometry::execute(a, ctx),
        Command::Study(a) => commands::study::execute(a, ctx),
        Command::Assess(a) => commands::assess::execute(a, ctx),
    })
}
