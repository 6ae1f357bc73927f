//! `master root-locus`: eigenvalues of the linear coach (`--model vehicle`, default) or the
//! linear 2-dof bogie (`--model bogie2dof`) over speed, linear critical speed and the mode at
//! onset (computation in [`crate::analysis::vehicle_locus`] and [`crate::analysis::locus`]).

use std::path::PathBuf;

use fmu_bogie2dof::Params;
use fmu_vehicle::VehicleParams;

use super::{csv_or_svg_starting, failed, write_analysis_with, AnalysisCommand};
use crate::analysis::locus::{
    bogie_onset, linearise_at_crossing, parse_damper_arg, root_locus, speed_grid_kmh, DamperArg,
    DamperSpec, Onset,
};
use crate::analysis::vehicle_locus::{vehicle_onset, vehicle_root_locus};
use crate::analysis::{AnalysisError, Artefacts};
use crate::study::VehicleModel;
use master::cli::{CommandError, Context};

/// The subcommand as its output folder knows it.
const COMMAND: AnalysisCommand = AnalysisCommand {
    name: "root-locus",
    owns,
};

/// The names of the files the subcommand writes.
fn owns(name: &str) -> bool {
    csv_or_svg_starting(name, &["root_locus", "damping_ratio", "hunting_frequency"])
}

/// Options of `master root-locus` (the description shown by `--help` is the `after_help`).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Eigenvalues of the linear coach (calibrated fmu-vehicle parameters, --model vehicle) or of the linear 2-dof bogie (calibrated fmu-bogie2dof parameters, --model bogie2dof) over speed. Prints the linear critical speed (bisection) and the mode at onset next to the seed's (coach: 280-290 km/h, R15; bogie: 270 km/h, about 21 rad/s, 3-4 Hz).\n\nFiles: root_locus_eigenvalues.csv (every eigenvalue per speed: real, imaginary, frequency, damping ratio, flag of the hunting mode; on the coach it is followed over speed from the mode that crosses), root_locus_hunting.csv (bogie) or root_locus_least_damped.csv (coach: the least-damped mode per speed with its kinetic-energy shares and name), root_locus.svg and root_locus_zoom.svg (points coloured by speed, the hunting mode ringed), damping_ratio.svg and hunting_frequency.svg (the hunting mode). Also root-locus.json: the summary and the files written; a run into the same folder removes the files of its previous run there that it does not write again."
)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
pub struct Args {
    /// Linear model: the coach (`vehicle`) or the 2-dof bogie (`bogie2dof`).
    #[arg(long, value_enum, default_value = "vehicle")]
    pub model: VehicleModel,
    /// First speed of the plotted locus [km/h]; the critical speed is searched from 18 to 716
    /// km/h whatever the plotted range.
    #[arg(
        long,
        value_name = "KMH",
        default_value_t = 100.0,
        allow_negative_numbers = true
    )]
    pub from: f64,
    /// Last speed of the plotted locus [km/h] (at most 716); the critical speed is searched
    /// up to 716 km/h whatever the plotted range.
    #[arg(
        long,
        value_name = "KMH",
        default_value_t = 400.0,
        allow_negative_numbers = true
    )]
    pub to: f64,
    /// Speed step [km/h].
    #[arg(
        long,
        value_name = "KMH",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    pub step: f64,
    /// Yaw damper (each of them): `passive` (the calibrated Maxwell representation of the
    /// coupled 30 % passive damper), `viscous:C`, `maxwell:K:C`, `kelvin:K:C` (N/m, N s/m;
    /// 120k = 120e3), `none`, or `semi-active:OPENING:STROKE[:FREQ]`: the hydraulic
    /// semi-active damper model with its valve fixed at OPENING (0 closed .. 1), linearised by
    /// its first harmonic at stroke amplitude STROKE [m] and FREQ [Hz], e.g.
    /// `semi-active:0:3e-3:5.5` (a closed valve at +-3 mm, 5.5 Hz); without FREQ, at the
    /// frequency of the mode that crosses (from 4 Hz, linearised again until it settles to
    /// 0.01 Hz; when nothing crosses, at the hunting mode's frequency at the top of the
    /// search). A stiffness lies within 1 kN/m .. 10 GN/m, a
    /// damping within 1 N s/m .. 100 MN s/m (or either is 0 where the law allows): beyond them
    /// the eigenvalues cannot be trusted.
    #[arg(long, default_value = "passive", value_parser = parse_damper_arg)]
    pub damper: DamperArg,
    /// Mounting (series) stiffness of each yaw damper's installation [N/m], 1 kN/m .. 10 GN/m,
    /// coach only [default: rigid].
    #[arg(long, value_name = "N_PER_M", allow_negative_numbers = true)]
    pub mounting_stiffness: Option<f64>,
    /// Equivalent conicity of the linear model [default: the calibrated value].
    #[arg(long, allow_negative_numbers = true)]
    pub conicity: Option<f64>,
    /// Output folder (created if needed; files are written only once everything is computed).
    #[arg(
        short = 'o',
        long,
        visible_alias = "output",
        value_name = "DIR",
        default_value = "results/root-locus"
    )]
    pub out: PathBuf,
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    super::check_out_folder(&args.out)?;
    let speeds = speed_grid_kmh(args.from, args.to, args.step).map_err(failed)?;
    if let Some(k) = args.mounting_stiffness {
        if !(k.is_finite() && k > 0.0) {
            return Err(CommandError::Failed(format!(
                "invalid option --mounting-stiffness = {k}: must be a finite stiffness > 0 N/m"
            )));
        }
    }
    if let Some(c) = args.conicity {
        if !(c.is_finite() && (0.0..=1.0).contains(&c)) {
            return Err(CommandError::Failed(format!(
                "invalid option --conicity = {}: must be an equivalent conicity within [0, 1]",
                master::show::num(c)
            )));
        }
    }
    // (summary, key numbers, files) of the model's locus
    type Files = Box<dyn FnOnce(&mut Artefacts) -> Result<(), AnalysisError>>;
    let (summary, results, files): (String, serde_json::Value, Files) = match args.model {
        VehicleModel::Coach => {
            let mut params = VehicleParams::default();
            if let Some(c) = args.conicity {
                params.wheel_rail.conicity = c;
            }
            let (damper, note) = resolve(args.damper, |spec| {
                vehicle_onset(&params, spec, args.mounting_stiffness)
            })?;
            let r = vehicle_root_locus(&params, damper, args.mounting_stiffness, &speeds)
                .map_err(failed)?;
            let summary = format!("{note}{}", r.summary());
            (
                summary,
                r.results_json(),
                Box::new(move |f| r.add_artefacts(f)),
            )
        }
        VehicleModel::Bogie2Dof => {
            if args.mounting_stiffness.is_some() {
                return Err(CommandError::Failed(
                    "--mounting-stiffness applies to --model vehicle only".into(),
                ));
            }
            let mut params = Params::default();
            if let Some(c) = args.conicity {
                params.conicity = c;
            }
            let (damper, note) = resolve(args.damper, |spec| bogie_onset(&params, spec))?;
            let r = root_locus(&params, damper, &speeds).map_err(failed)?;
            let summary = format!("{note}{}", r.summary());
            (
                summary,
                r.results_json(),
                Box::new(move |f| r.add_artefacts(f)),
            )
        }
    };
    write_analysis_with(
        &COMMAND,
        &args.out,
        &[],
        ctx.cancel,
        &summary,
        results,
        files,
    )
}

/// The damper of `arg`, a `semi-active` one given without its frequency linearised at the
/// crossing mode's ([`linearise_at_crossing`]; `onset` is the model's eigen-analysis), and a
/// line for the summary saying so (empty otherwise).
fn resolve(
    arg: DamperArg,
    onset: impl FnMut(DamperSpec) -> Result<Onset, String>,
) -> Result<(DamperSpec, String), CommandError> {
    let DamperSpec::Linearised(d) = arg.spec else {
        return Ok((arg.spec, String::new()));
    };
    if !arg.at_crossing {
        return Ok((arg.spec, String::new()));
    }
    let found = linearise_at_crossing(d, onset)
        .map_err(|e| CommandError::Failed(format!("--damper: {e}")))?;
    let d = found.damper;
    let hz = master::show::num((d.freq_hz * 100.0).round() / 100.0);
    let rounds = match found.rounds {
        1 => "1 eigen-analysis".to_string(),
        n => format!("{n} eigen-analyses"),
    };
    let note = if found.crossed {
        format!("damper linearised at the crossing mode's frequency, {hz} Hz (settled after {rounds})\n")
    } else if found.settled {
        format!(
            "no mode crosses: damper linearised at the hunting mode's frequency at the top of \
             the search, {hz} Hz (settled after {rounds})\n"
        )
    } else {
        format!(
            "no mode crosses at any frequency tried (the least-damped mode at the top of the \
             search hops between modes): damper linearised at {hz} Hz\n"
        )
    };
    Ok((DamperSpec::Linearised(d), note))
}
