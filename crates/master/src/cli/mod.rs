//! The generic subcommands of the `master` binary (run, sweep, inspect, export-ssp; one file
//! each) and the
//! binary's common main ([`run_command`]: logger, Ctrl-C, error chain, exit status).
//!
//! The binary itself lives in the `rail-study` crate, which adds the railway subcommands:
//! its `Command` enum flattens [`GenericCommand`] and its `main` calls [`run_command`]. A
//! subcommand is a `clap::Args` struct plus an `execute(&Args, &Context) -> Result<(),
//! CommandError>`.

use std::io::IsTerminal;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

pub mod export_ssp;
pub mod inspect;
pub mod run;
pub mod sweep;

/// Shared state of a command invocation.
pub struct Context {
    /// Set by the Ctrl-C handler; long loops check it.
    pub cancel: &'static AtomicBool,
    /// Whether to draw progress bars (stderr is a terminal and not --quiet).
    pub progress: bool,
}

/// Error of any subcommand; the binary prints it and exits non-zero.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// Boxed: a run's error carries the FMU's messages and would make every result large.
    #[error(transparent)]
    Run(Box<crate::system::RunError>),
    #[error(transparent)]
    System(#[from] crate::system::SystemError),
    #[error(transparent)]
    Sweep(#[from] crate::runset::SweepError),
    #[error(transparent)]
    Fmu(#[from] crate::fmu::FmuError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error(transparent)]
    Ssp(#[from] crate::ssp::SspError),
    #[error("{0}")]
    Failed(String),
    /// A run failed after recording a history, which was written.
    #[error(
        "{error}\nthe history up to t = {time_s} s is in {path} (its metadata records the failure)"
    )]
    FailedWithHistory {
        error: Box<crate::system::RunError>,
        time_s: f64,
        path: String,
    },
    /// An error of a subcommand defined outside this crate (its source chain is printed).
    #[error(transparent)]
    Other(Box<dyn std::error::Error + Send + Sync>),
}

impl From<crate::system::RunError> for CommandError {
    fn from(e: crate::system::RunError) -> Self {
        CommandError::Run(Box::new(e))
    }
}

/// Options of every subcommand.
#[derive(Debug, clap::Args)]
pub struct GlobalArgs {
    /// Log level of the master and of FMU logger messages (error, warn, info, debug, trace).
    #[arg(long, global = true, default_value = "info")]
    pub log_level: log::LevelFilter,
    /// No progress bars.
    #[arg(short, long, global = true)]
    pub quiet: bool,
}

/// The generic subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum GenericCommand {
    /// Run one system description (or one FMU alone) and write results as CSV or Parquet.
    Run(run::Args),
    /// Run parameter variations of a system in parallel.
    Sweep(sweep::Args),
    /// Check an FMU and print its variables.
    Inspect(inspect::Args),
    /// Write a system description as a self-contained SSP (FMUs and parameter sets inside).
    ExportSsp(export_ssp::Args),
}

impl GenericCommand {
    pub fn execute(&self, ctx: &Context) -> Result<(), CommandError> {
        match self {
            GenericCommand::Run(a) => run::execute(a, ctx),
            GenericCommand::Sweep(a) => sweep::execute(a, ctx),
            GenericCommand::Inspect(a) => inspect::execute(a, ctx),
            GenericCommand::ExportSsp(a) => export_ssp::execute(a, ctx),
        }
    }
}

static CANCEL: AtomicBool = AtomicBool::new(false);

/// Runs `install` (the Ctrl-C and SIGTERM handler) and gives SIGHUP back the disposition it
/// had: the handler's crate takes SIGHUP with SIGTERM, which would turn a hang-up under
/// `nohup` (SIGHUP ignored) into a cancelled run.
#[cfg(unix)]
fn keeping_sighup<T>(install: impl FnOnce() -> T) -> T {
    // SAFETY: sigaction reads into / from a zero-initialised struct we own; no handler of
    // ours is installed by these calls, only the earlier disposition put back.
    let mut before: libc::sigaction = unsafe { std::mem::zeroed() };
    let saved = unsafe { libc::sigaction(libc::SIGHUP, std::ptr::null(), &mut before) } == 0;
    let out = install();
    if saved {
        // SAFETY: as above.
        unsafe { libc::sigaction(libc::SIGHUP, &before, std::ptr::null_mut()) };
    }
    out
}

#[cfg(not(unix))]
fn keeping_sighup<T>(install: impl FnOnce() -> T) -> T {
    install()
}

/// The main of a `master` binary: installs the FMU logger at the requested level and the
/// Ctrl-C handler (first Ctrl-C: stop at the next communication point; second: exit 130), runs
/// `command`, prints an error with its chain of causes. Exit status 0 on success, 130 after
/// Ctrl-C, 1 on any other error.
pub fn run_command<F>(global: &GlobalArgs, command: F) -> ExitCode
where
    F: FnOnce(&Context) -> Result<(), CommandError>,
{
    crate::fmu::install_logger(global.log_level);
    let installed = keeping_sighup(|| {
        ctrlc::set_handler(|| {
            if CANCEL.swap(true, Ordering::SeqCst) {
                // second Ctrl-C: give up immediately, without the files half written
                crate::output::give_up_unfinished();
                std::process::exit(130);
            }
            eprintln!(
                "interrupt: stopping at the next communication point (Ctrl-C again to abort)"
            );
        })
    });
    if let Err(e) = installed {
        eprintln!("warning: cannot install the Ctrl-C handler: {e}");
    }
    let ctx = Context {
        cancel: &CANCEL,
        progress: !global.quiet && std::io::stderr().is_terminal(),
    };
    match command(&ctx) {
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
