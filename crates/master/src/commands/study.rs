//! `master study` (being written).

use super::{CommandError, Context};

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn execute(_args: &Args, _ctx: &Context) -> Result<(), CommandError> {
    Err(CommandError::Failed("not implemented yet".into()))
}
