//! `master root-locus`: eigenvalues of the linear bogie over speed, linear critical speed and
//! hunting frequency (computation in [`crate::analysis::locus`]).

use std::path::PathBuf;

use fmu_bogie2dof::Params;

use super::{failed, write_analysis};
use crate::analysis::locus::{parse_damper, root_locus, speed_grid_kmh, DamperSpec};
use master::cli::{CommandError, Context};

/// Options of `master root-locus` (the description shown by `--help` is the `after_help`).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Eigenvalues of the linear 2-dof bogie (calibrated fmu-bogie2dof parameters) over speed. Prints the linear critical speed (bisection) and the hunting frequency at onset next to the seed's (270 km/h, about 21 rad/s, 3-4 Hz).\n\nFiles: root_locus_eigenvalues.csv (every eigenvalue per speed: real, imaginary, frequency, damping ratio, hunting flag), root_locus_hunting.csv, root_locus.svg and root_locus_zoom.svg (points coloured by speed, hunting mode ringed), damping_ratio.svg, hunting_frequency.svg."
)]
pub struct Args {
    /// First speed [km/h].
    #[arg(long, value_name = "KMH", default_value_t = 100.0)]
    pub from: f64,
    /// Last speed [km/h] (at most 716).
    #[arg(long, value_name = "KMH", default_value_t = 400.0)]
    pub to: f64,
    /// Speed step [km/h].
    #[arg(long, value_name = "KMH", default_value_t = 5.0)]
    pub step: f64,
    /// Yaw damper per side: `passive` (the calibrated Maxwell representation of the coupled
    /// 30 % passive damper), `viscous:C`, `maxwell:K:C`, `kelvin:K:C` (N/m, N s/m; 120k =
    /// 120e3) or `none`.
    #[arg(long, default_value = "passive", value_parser = parse_damper)]
    pub damper: DamperSpec,
    /// Equivalent conicity of the linear model [default: the calibrated value].
    #[arg(long)]
    pub conicity: Option<f64>,
    /// Output folder (created if needed; files are written only once everything is computed).
    #[arg(long, value_name = "DIR", default_value = "results/root-locus")]
    pub out: PathBuf,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    let speeds = speed_grid_kmh(args.from, args.to, args.step).map_err(failed)?;
    let mut params = Params::default();
    if let Some(c) = args.conicity {
        params.conicity = c;
    }
    let r = root_locus(&params, args.damper, &speeds).map_err(failed)?;
    write_analysis(&args.out, ctx.cancel, &r.summary(), |f| r.add_artefacts(f))
}
