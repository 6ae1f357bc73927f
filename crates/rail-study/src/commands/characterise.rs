//! `master characterise [damper|actuator|all]`: hysteresis loops, FRFs and equivalent
//! stiffness/damping of the semi-active yaw damper, FRFs of the full-active actuator
//! (seed 3.3.4, 3.4.4; computation in [`crate::analysis::damper`] and
//! [`crate::analysis::actuator`]).

use std::path::PathBuf;

use fmu_damper::{ActuatorParams, SemiActiveParams};

use super::{csv_or_svg_starting, failed, write_analysis, AnalysisCommand};
use crate::analysis::actuator::{characterise_actuator, ActuatorOptions};
use crate::analysis::damper::{characterise_damper, DamperOptions};
use master::cli::{CommandError, Context};

/// The subcommand as its output folder knows it.
const COMMAND: AnalysisCommand = AnalysisCommand {
    name: "characterise",
    owns,
};

/// The names of the files the subcommand writes.
fn owns(name: &str) -> bool {
    csv_or_svg_starting(name, &["damper_", "actuator_"])
}

/// Which model to characterise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// Semi-active damper (default parameters): loops at 4 Hz, 1 and 3 mm, openings 0/20/50/100 %;
    /// force/displacement FRF at 1 mm, openings 0/20/30/50/100 %.
    Damper,
    /// Full-active actuator (Table 3-2): FRF u -> rod velocity, rod free, full-order,
    /// reduced-order and linearised models at |u| = alpha and 0.3 alpha.
    Actuator,
    /// Both.
    All,
}

/// Options of `master characterise` (the description shown by `--help` is the `after_help`).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Characterise the yaw dampers. Writes CSVs and SVG figures into --out and prints the R1 peak-force table and the R3 eigenfrequency next to the seed's values.\n\nFiles (damper): damper_hysteresis.csv, damper_hysteresis_<A>mm_force_displacement.svg, damper_hysteresis_<A>mm_force_velocity.svg, damper_peak_forces.csv, damper_frf.csv, damper_frf_{modulus,phase,k_eq,c_eq}.svg. Files (actuator): actuator_frf.csv (a phase is NaN where the modulus is zero: an amplitude inside the valve's dead zone moves nothing), actuator_frf_{modulus,phase}_alpha.svg. Also characterise.json: the summary and the files written; a run into the same folder removes the files of its previous run there that it does not write again (another model or amplitude)."
)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
pub struct Args {
    /// What to characterise.
    #[arg(value_enum, default_value_t = Target::All)]
    pub target: Target,
    /// Output folder (created if needed; files are written only once everything is computed).
    #[arg(
        short = 'o',
        long,
        visible_alias = "output",
        value_name = "DIR",
        default_value = "results/characterise"
    )]
    pub out: PathBuf,
    /// Number of log-spaced frequencies of the damper FRF (2 to 10000).
    #[arg(long, default_value_t = 25, value_parser = frf_points)]
    pub damper_freqs: usize,
    /// Lowest damper FRF frequency [Hz] (at least 0.001 Hz: each frequency is simulated over
    /// whole periods).
    #[arg(long, default_value_t = 0.5, value_parser = frequency_hz)]
    pub damper_f_min: f64,
    /// Highest damper FRF frequency [Hz] (at most 1e5 Hz).
    #[arg(long, default_value_t = 20.0, value_parser = frequency_hz)]
    pub damper_f_max: f64,
    /// Number of log-spaced frequencies of the actuator FRF (2 to 10000).
    #[arg(long, default_value_t = 30, value_parser = frf_points)]
    pub actuator_freqs: usize,
    /// Lowest actuator FRF frequency [Hz] (at least 0.01 Hz: the full-order model is
    /// integrated over whole periods within a bounded number of internal steps; with the
    /// spool at alpha the free rod leaves its stroke below about 0.35 Hz, which is refused
    /// naming this option).
    #[arg(long, default_value_t = 1.0, value_parser = actuator_frequency_hz)]
    pub actuator_f_min: f64,
    /// Highest actuator FRF frequency [Hz] (at most 1e5 Hz).
    #[arg(long, default_value_t = 320.0, value_parser = actuator_frequency_hz)]
    pub actuator_f_max: f64,
}

/// A number of FRF frequencies: 2 to 10000 (each is a simulation of its own).
fn frf_points(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if (2..=10_000).contains(&n) => Ok(n),
        _ => Err(format!("'{text}' is not a whole number from 2 to 10000")),
    }
}

/// An FRF frequency: 0.001 to 1e5 Hz. Each frequency is simulated over whole periods, so a
/// frequency of 1e-300 Hz would run for ever and 1e10 would take billions of steps.
fn frequency_hz(text: &str) -> Result<f64, String> {
    frequency_within(text, 1e-3)
}

/// An actuator FRF frequency: 0.01 to 1e5 Hz (at 0.001 Hz the full-order model's integration
/// over a period exceeds its internal step limit).
fn actuator_frequency_hz(text: &str) -> Result<f64, String> {
    frequency_within(text, 1e-2)
}

fn frequency_within(text: &str, lowest_hz: f64) -> Result<f64, String> {
    let f: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if !(lowest_hz..=1e5).contains(&f) {
        return Err(format!(
            "{} Hz is outside {lowest_hz} to 1e5 Hz",
            master::show::num(f)
        ));
    }
    Ok(f)
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    super::check_out_folder(&args.out)?;
    let (mut damper, mut actuator) = (None, None);
    if matches!(args.target, Target::Damper | Target::All) {
        let opts = DamperOptions {
            frf_points: args.damper_freqs,
            frf_band_hz: (args.damper_f_min, args.damper_f_max),
            ..DamperOptions::default()
        };
        damper = Some(
            characterise_damper(&SemiActiveParams::default(), &opts, ctx.cancel).map_err(failed)?,
        );
    }
    if matches!(args.target, Target::Actuator | Target::All) {
        let opts = ActuatorOptions {
            points: args.actuator_freqs,
            band_hz: (args.actuator_f_min, args.actuator_f_max),
            ..ActuatorOptions::default()
        };
        actuator = Some(
            characterise_actuator(&ActuatorParams::default(), &opts, ctx.cancel).map_err(failed)?,
        );
    }
    let summary = damper
        .iter()
        .map(|r| r.summary())
        .chain(actuator.iter().map(|r| r.summary()));
    let summary: String = summary.collect();
    write_analysis(&COMMAND, &args.out, &[], ctx.cancel, &summary, |f| {
        if let Some(r) = &damper {
            r.add_artefacts(f)?;
        }
        match &actuator {
            Some(r) => r.add_artefacts(f),
            None => Ok(()),
        }
    })
}
