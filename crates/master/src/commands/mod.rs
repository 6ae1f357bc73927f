//! Subcommands of the `master` binary, one file each. To add one (characterise, root-locus,
//! contact-geometry, study...): write `src/commands/<name>.rs` with a `clap::Args` struct and
//! an `execute(&Args, &Context) -> Result<(), CommandError>`, declare it here and add a
//! variant to `Command` in `src/main.rs`.

use std::sync::atomic::AtomicBool;

pub mod assess;
pub mod characterise;
pub mod contact_geometry;
pub mod inspect;
pub mod root_locus;
pub mod run;
pub mod study;
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
    #[error(transparent)]
    Run(#[from] crate::system::RunError),
    #[error(transparent)]
    System(#[from] crate::system::SystemError),
    #[error(transparent)]
    Sweep(#[from] crate::runset::SweepError),
    #[error(transparent)]
    Fmu(#[from] crate::fmu::FmuError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    #[error("{0}")]
    Failed(String),
}
