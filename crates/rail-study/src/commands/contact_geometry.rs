//! `master contact-geometry`: wheel/rail contact table (bogie format), Δr(y), tanγ(y) and
//! EN 15302 equivalent conicity from profiles (computation in [`crate::analysis::geometry`]).

use std::path::PathBuf;

use wheel_rail::RadiusConvention;

use super::{failed, write_analysis, AnalysisCommand};
use crate::analysis::geometry::fleet::{fleet, profiles_in, ProfileFolder};
use crate::analysis::geometry::{
    contact_geometry, parse_inclination, GeometryInputs, ProfileSource,
};
use master::cli::{CommandError, Context};

/// The subcommand as its output folder knows it.
const COMMAND: AnalysisCommand = AnalysisCommand {
    name: "contact-geometry",
    owns,
};

/// The names of the files the subcommand writes.
fn owns(name: &str) -> bool {
    [
        "wheel_rail_table.csv",
        "contact_detail.csv",
        "conicity.csv",
        "delta_r.svg",
        "tan_gamma.svg",
        "conicity.svg",
        "fleet_conicity.csv",
        "fleet_conicity_3mm.svg",
    ]
    .contains(&name)
}

/// How unequal wheel radii enter (`--radius-convention`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RadiusConventionArg {
    /// EN 15302: the radius difference is an offset of delta r (contact search with equal radii).
    En15302Offset,
    /// The rigid wheelset rolled by the radius difference (the bogie tables' geometry).
    RigidRoll,
}

impl From<RadiusConventionArg> for RadiusConvention {
    fn from(a: RadiusConventionArg) -> Self {
        match a {
            RadiusConventionArg::En15302Offset => RadiusConvention::En15302Offset,
            RadiusConventionArg::RigidRoll => RadiusConvention::RigidRoll,
        }
    }
}

/// Options of `master contact-geometry` (the description shown by `--help` is the `after_help`).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Wheel/rail contact geometry from profiles. Without options: EN 15302 case E1 (wheel A, rail A, 920 mm wheels, gauge 1435.16 mm) with the built-in benchmark profiles.\n\nProfile files: two numbers per line, lateral and vertical in mm (whitespace, comma or semicolon separated), '#' comments, optional header line; lateral positive towards the field side (flange at negative values), vertical up, wheel origin on the nominal rolling circle. The wheels' origins are placed 1500 mm apart: a back-to-back distance of 1360 mm for profiles whose origin lies 70 mm from the wheel's back face (EN 15302's profiles, S1002's taping line); for a measured profile with another datum, or another wheelset, give --back-to-back (and --back-face-offset, the back face's distance from the profile's origin): 1 mm off changes tan gamma_e at 3 mm by about a third. A bad file stops the command with file:line and writes nothing.\n\nUnequal radii (--radius-right): delta r, contact_detail.csv and the conicity follow --radius-convention (EN 15302's offset by default, named in the CSV headers); wheel_rail_table.csv is always the rigid wheelset's (rigid-roll), the geometry the bogie model feels.\n\nThe conicity is EN 15302 Annex B (with the Annex C regression and the harmonic linearisation beside it), 0 on a flat tread; an amplitude without a value is an error naming it and why (exit code 1, nothing written).\n\nFiles: wheel_rail_table.csv (the bogie model's contact table format), contact_detail.csv (with the located two-point contacts), conicity.csv (from 1 mm, or 10 table steps of --step if more, to --amplitude-max), delta_r.svg, tan_gamma.svg, conicity.svg. With --wheels or --wheel-dir (a fleet of wheel profiles, each on both wheels): fleet_conicity.csv (a row per profile) and fleet_conicity_3mm.svg instead; a profile without a complete table (unreadable, or an amplitude without a conicity) gets a row with its reason and no numbers, and the command exits with status 1 naming it (nothing is written when no profile has a table). Also contact-geometry.json: the summary and the files written; a run into the same folder removes the files of its previous run there that it does not write again (the other mode's), and a --wheel-dir folder's earlier results (these names) are not read as profiles."
)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
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
    /// Track gauge [mm], measured 14 mm below the top of rail: 1425-1480 (tight to wide standard
    /// gauge; the wheelset's rolling circles are 1500 mm apart, its flanges about 1425 mm).
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 1435.16,
        allow_negative_numbers = true
    )]
    pub gauge: f64,
    /// Rail inclination to APPLY to the rail profiles: 1:40, 1:20, or 0 when the file already
    /// contains it (rail A, built in or from its file, does: refused on it).
    #[arg(long, default_value = "0", value_parser = parse_inclination, allow_hyphen_values = true)]
    pub inclination: f64,
    /// Nominal rolling radius [mm] (left, and right unless --radius-right).
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 460.0,
        allow_negative_numbers = true
    )]
    pub radius: f64,
    /// Nominal rolling radius of the right wheel [mm].
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub radius_right: Option<f64>,
    /// The table covers y from -y_max to +y_max [mm], a whole number of --step. Rows beyond the
    /// flange limit repeat the limit's values, and the vehicle FMUs take the table's end as
    /// derailment: this sets where they stop.
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 10.0,
        allow_negative_numbers = true
    )]
    pub y_max: f64,
    /// Table step in y [mm].
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 0.05,
        allow_negative_numbers = true
    )]
    pub step: f64,
    /// Largest amplitude of the conicity curve [mm].
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 7.0,
        allow_negative_numbers = true
    )]
    pub amplitude_max: f64,
    /// Back-to-back distance of the wheels [mm] (1360 nominal): the wheels stand by their back
    /// faces instead of their profile origins (1500 mm apart, which is 1360 back to back only
    /// for origins 70 mm from the back faces). With --back-face-offset.
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub back_to_back: Option<f64>,
    /// Distance from each wheel's back face to its profile's origin [mm] (S1002's taping line:
    /// 70), used with --back-to-back.
    #[arg(
        long,
        value_name = "MM",
        default_value_t = 70.0,
        allow_negative_numbers = true,
        requires = "back_to_back"
    )]
    pub back_face_offset: f64,
    /// How unequal wheel radii enter delta r and the conicity.
    #[arg(long, value_enum, default_value = "en15302-offset")]
    pub radius_convention: RadiusConventionArg,
    /// Fleet mode: these wheel profiles, each on both wheels, into one conicity table.
    #[arg(long, value_name = "FILE", num_args = 1.., conflicts_with_all = ["wheel", "wheel_right"])]
    pub wheels: Vec<PathBuf>,
    /// Fleet mode: every profile file (.dat, .txt, .csv, .prf) of this folder, by name.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["wheel", "wheel_right"])]
    pub wheel_dir: Option<PathBuf>,
    /// Output folder (created if needed; files are written only once everything is computed).
    #[arg(
        short = 'o',
        long,
        visible_alias = "output",
        value_name = "DIR",
        default_value = "results/contact-geometry"
    )]
    pub out: PathBuf,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    super::check_out_folder(&args.out)?;
    let d = GeometryInputs::default();
    // the profile files read (those of --wheel-dir are found later)
    let mut read: Vec<PathBuf> = [&args.wheel, &args.rail, &args.wheel_right, &args.rail_right]
        .into_iter()
        .flatten()
        .chain(&args.wheels)
        .cloned()
        .collect();
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
        amplitude_max_m: args.amplitude_max * 1e-3,
        radius_convention: args.radius_convention.into(),
        back_to_back: args
            .back_to_back
            .map(|b| (b * 1e-3, args.back_face_offset * 1e-3)),
        ..d
    };
    if !args.wheels.is_empty() || args.wheel_dir.is_some() {
        let mut wheels: Vec<ProfileSource> = args
            .wheels
            .iter()
            .map(|p| ProfileSource::File(p.clone()))
            .collect();
        let mut folder = ProfileFolder::default();
        if let Some(dir) = &args.wheel_dir {
            // a run into that folder left its results there: they are not profiles
            folder = profiles_in(dir, owns).map_err(failed)?;
            read.extend(folder.files.iter().cloned());
            wheels.extend(folder.files.iter().cloned().map(ProfileSource::File));
        }
        let r = fleet(&inputs, &wheels, ctx.cancel).map_err(failed)?;
        let summary = r.summary(&folder);
        write_analysis(&COMMAND, &args.out, &read, ctx.cancel, &summary, |f| {
            r.add_artefacts(f)
        })?;
        // the others' table is written; the run still fails, naming the profiles without one
        return match r.incomplete() {
            Some(e) => Err(CommandError::Failed(e)),
            None => Ok(()),
        };
    }
    let r = contact_geometry(&inputs, ctx.cancel).map_err(failed)?;
    write_analysis(&COMMAND, &args.out, &read, ctx.cancel, &r.summary(), |f| {
        r.add_artefacts(f)
    })
}
