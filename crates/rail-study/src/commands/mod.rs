//! The railway subcommands of the `master` binary, one file each (the generic ones are
//! [`master::cli`]). To add one: write `src/commands/<name>.rs` with a `clap::Args` struct and
//! an `execute(&Args, &Context) -> Result<(), CommandError>`, declare it here and add a variant
//! to `Command` in `src/main.rs`.

use master::cli::CommandError;

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
