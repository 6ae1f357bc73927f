//! `master contact-geometry`: wheel/rail contact table (bogie format), Δr(y), tanγ(y) and
//! EN 15302 equivalent conicity from profiles (computation in [`crate::analysis::geometry`]).

use std::path::PathBuf;

use super::{CommandError, Context};
use crate::analysis::geometry::{
    contact_geometry, parse_inclination, GeometryInputs, ProfileSource,
};
use crate::analysis::{check_cancel, print_report, Artefacts};

/// Options of `master contact-geometry` (the description shown by `--help` is the `after_help`).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Wheel/rail contact geometry from profiles. Without options: EN 15302 case E1 (wheel A, rail A, 920 mm wheels, gauge 1435.16 mm) with the built-in benchmark profiles.\n\nProfile files: two numbers per line, lateral and vertical in mm (whitespace, comma or semicolon separated), '#' comments, optional header line; lateral positive towards the field side (flange at negative values), vertical up, wheel origin on the nominal rolling circle. A bad file stops the command with file:line and writes nothing.\n\nFiles: wheel_rail_table.csv (the bogie model's contact table format), contact_detail.csv, conicity.csv (1-7 mm), delta_r.svg, tan_gamma.svg, conicity.svg."
)]
pub struct Args {
    /// Wheel profile (both sides unless --wheel-right) [default: built-in EN 15302 wheel A].
    #[arg(long, value_name = "FILE")]
    pub wheel: Option<PathBuf>,
    /// Rail profile (both sides unless --rail-right) [default: built-in EN 15302 rail A].
    #[arg(long, value_name = "FILE")]
    pub rail: Option<PathBuf>,
    /// Right wheel profile, if different from the left (given in the same frame as a left one).
    #[arg(long, value_name = "FILE")]
    pub wheel_right: Option<PathBuf>,
    /// Right rail profile, if different from the left.
    #[arg(long, value_name = "FILE")]
    pub rail_right: Option<PathBuf>,
    /// Track gauge [mm], measured 14 mm below the top of rail.
    #[arg(long, value_name = "MM", default_value_t = 1435.16)]
    pub gauge: f64,
    /// Rail inclination to APPLY to the rail profiles: 1:40, 1:20, or 0 when the file already
    /// contains it (the built-in rail A does).
    #[arg(long, default_value = "0", value_parser = parse_inclination)]
    pub inclination: f64,
    /// Nominal rolling radius [mm] (left, and right unless --radius-right).
    #[arg(long, value_name = "MM", default_value_t = 460.0)]
    pub radius: f64,
    /// Nominal rolling radius of the right wheel [mm].
    #[arg(long, value_name = "MM")]
    pub radius_right: Option<f64>,
    /// The table covers y from -y_max to +y_max [mm].
    #[arg(long, value_name = "MM", default_value_t = 10.0)]
    pub y_max: f64,
    /// Table step in y [mm].
    #[arg(long, value_name = "MM", default_value_t = 0.05)]
    pub step: f64,
    /// Output folder (created if needed; files are written only once everything is computed).
    #[arg(long, value_name = "DIR", default_value = "results/contact-geometry")]
    pub out: PathBuf,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    let d = GeometryInputs::default();
    let file = |p: &Option<PathBuf>| p.as_ref().map(|p| ProfileSource::File(p.clone()));
    let wheel_left = file(&args.wheel).unwrap_or(d.wheel_left);
    let rail_left = file(&args.rail).unwrap_or(d.rail_left);
    let inputs = GeometryInputs {
        wheel_right: file(&args.wheel_right).unwrap_or_else(|| wheel_left.clone()),
        rail_right: file(&args.rail_right).unwrap_or_else(|| rail_left.clone()),
        wheel_left,
        rail_left,
        gauge_m: args.gauge * 1e-3,
        inclination: args.inclination,
        radius_left_m: args.radius * 1e-3,
        radius_right_m: args.radius_right.unwrap_or(args.radius) * 1e-3,
        y_max_m: args.y_max * 1e-3,
        step_m: args.step * 1e-3,
        ..d
    };
    let failed = |e| CommandError::Failed(format!("{e}"));
    let r = contact_geometry(&inputs).map_err(failed)?;
    check_cancel(ctx.cancel).map_err(failed)?;
    let mut files = Artefacts::default();
    r.add_artefacts(&mut files).map_err(failed)?;
    files.write_all(&args.out)?;
    print_report(&r.summary(), &files, &args.out);
    Ok(())
}
