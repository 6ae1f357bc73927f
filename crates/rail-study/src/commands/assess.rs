//! `master assess`: EN 14363 running-stability assessment of recorded signals (computation in
//! [`crate::analysis::assess`]).

use std::path::PathBuf;

use super::{csv_or_svg_starting, failed, write_analysis_with, AnalysisCommand};
use crate::analysis::assess::{assess_checked, BandRemark, Criterion, ResultsTable};
use crate::en14363::StabilitySettings;
use master::cli::{CommandError, Context};

/// The subcommand as its output folder knows it.
const COMMAND: AnalysisCommand = AnalysisCommand {
    name: "assess",
    owns,
};

/// The names of the files the subcommand writes.
fn owns(name: &str) -> bool {
    csv_or_svg_starting(name, &["assess"])
}

/// EN 14363 quantity of the signals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Quantity {
    /// Lateral acceleration of the bogie frame / wheelset [m/s2]; limit (12 - m_bogie/5)/2.
    Acceleration,
    /// Sum of guiding forces of a wheelset [N or kN]; limit (10 + 2 Q0/3)/2 kN.
    #[value(alias = "guiding_force")]
    GuidingForce,
}

/// Options of `master assess`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Applies the EN 14363 rms stability criterion as the seed does (section 4.2): band-pass +-2 Hz around the dominant frequency of each signal, rms over 100 m of track in 10 m steps at the given constant speed, maximum compared with the limit. Works on our results (`master run`, the study's runs; CSV or Parquet) or on a host's export (Simpack, ...): first column the time in seconds (a name ending in [ms] is read in milliseconds, another unit is refused), uniformly sampled (every time within 1 % of a step of the uniform grid, so a host's rounded or float32 times pass); separators comma, semicolon or whitespace; '#' comment lines; or a Parquet file. Units from the column names' ' [unit]': accelerations in m/s2 (or m/s^2, m/s²) or g, guiding forces in N or kN; a column without a unit is taken in m/s2 or N and the verdict says so, and a guiding force without a unit whose values stay below 1 kN as N (a force in kN) is refused. Our files record their sampling (Parquet inside, CSV in <name>.meta.json): a signal whose recorded band (Nyquist frequency, or the anti-aliasing filter of a decimated file) does not cover the assessed band is refused; they also record the running speed, which --speed must match. A given --f0 is named as given, and a spectrum peaking outside its band is noted.\n\nFiles: assess.csv (rms per window, window centres from the record's first sample), assess_summary.csv (per signal, with its f0 source, band, speed, quantity, assumed unit and band check), assess.svg (rms along the track with the limit). Exit status 0 whether or not the limit is exceeded (read the verdict line); 1 when the input cannot be assessed (nothing is written then). Also assess.json: the summary and the files written; a run into the same folder removes the files of its previous run there that it does not write again."
)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
pub struct Args {
    /// Results table (CSV, whitespace separated, or Parquet).
    pub table: PathBuf,
    /// Signal to assess: column name, with or without its " [unit]"; repeat for several
    /// (e.g. front and rear wheelset), the verdict takes the largest rms.
    #[arg(long = "signal", required = true, value_name = "COLUMN")]
    pub signals: Vec<String>,
    /// Vehicle speed over the record [km/h] (constant).
    #[arg(long, value_name = "KMH", allow_negative_numbers = true)]
    pub speed: f64,
    /// EN 14363 quantity of the signals.
    #[arg(long, value_enum, default_value = "acceleration")]
    pub quantity: Quantity,
    /// Bogie mass for the acceleration limit [t] (the seed's 6.1 t gives 5.39 m/s2).
    #[arg(
        long,
        value_name = "T",
        default_value_t = 6.1,
        allow_negative_numbers = true
    )]
    pub bogie_mass: f64,
    /// Static wheel load Q0 for the guiding-force limit [kN].
    #[arg(long, value_name = "KN", allow_negative_numbers = true)]
    pub wheel_load: Option<f64>,
    /// Start-up time excluded from the assessment [s].
    #[arg(
        long,
        value_name = "S",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub skip: f64,
    /// Dominant frequency [Hz] instead of the spectrum's peak (searched in 0.5-20 Hz).
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub f0: Option<f64>,
    /// Assess even when the file's metadata records a pass band narrower than the assessed
    /// band (a loud warning is printed instead of the refusal).
    #[arg(long)]
    pub accept_narrow_band: bool,
    /// Output folder (created if needed; files are written only once everything is computed).
    #[arg(
        short = 'o',
        long,
        visible_alias = "output",
        value_name = "DIR",
        default_value = "results/assess"
    )]
    pub out: PathBuf,
}

impl Quantity {
    /// The criterion of this quantity: the limit from the bogie mass \[t\] or the static wheel
    /// load \[kN\].
    /// (`wheel_load_kn` is not used for accelerations.)
    pub fn criterion(self, bogie_mass_t: f64, wheel_load_kn: f64) -> Criterion {
        match self {
            Quantity::Acceleration => Criterion::LateralAcceleration { bogie_mass_t },
            Quantity::GuidingForce => Criterion::GuidingForces {
                static_wheel_load_n: wheel_load_kn * 1e3,
            },
        }
    }
}

/// The numbers of an assessment as given, with the names they go by (the command's options
/// or the arguments of Python's `railfmu.assess_stability`).
pub struct AssessNumbers<'a> {
    pub speed_kmh: (&'a str, f64),
    pub skip_s: (&'a str, f64),
    pub f0_hz: (&'a str, Option<f64>),
    pub bogie_mass_t: (&'a str, f64),
    /// Needed for guiding forces only: no default, since the vehicles differ (the coach 54.2
    /// kN, the 2-dof bogie 70 kN).
    pub wheel_load_kn: (&'a str, Option<f64>),
}

/// The highest speed `assess` takes [km/h]: beyond, a number is not a rail vehicle's speed in
/// km/h (a speed in m/h, or a typing error), and the 10 m window step would be shorter than a
/// sample.
pub const MAX_SPEED_KMH: f64 = 1000.0;

impl AssessNumbers<'_> {
    /// The numbers the computation would refuse, as `NAME = VALUE: reason` (the computation's
    /// own messages name its internal parameters, e.g. the wheel load in N).
    pub fn check(&self, quantity: Quantity) -> Result<(), String> {
        let bad = |(name, value): (&str, f64), reason: &str| {
            Err(format!("{name} = {}: {reason}", master::show::num(value)))
        };
        let (_, speed) = self.speed_kmh;
        if !(speed.is_finite() && speed > 0.0) {
            return bad(self.speed_kmh, "must be a speed > 0 km/h");
        }
        if speed > MAX_SPEED_KMH {
            return bad(
                self.speed_kmh,
                "must be a rail vehicle's speed in km/h, at most 1000 km/h",
            );
        }
        let (_, skip) = self.skip_s;
        if !(skip.is_finite() && skip >= 0.0) {
            return bad(self.skip_s, "must be a time >= 0 s");
        }
        let (f0_name, f0) = self.f0_hz;
        if let Some(f) = f0.filter(|f| !(f.is_finite() && *f > 0.0)) {
            return bad((f0_name, f), "must be a frequency > 0 Hz");
        }
        let (_, mass) = self.bogie_mass_t;
        let (load_name, load) = self.wheel_load_kn;
        match (quantity, load) {
            (Quantity::Acceleration, _) if !(mass > 0.0 && mass < 60.0) => bad(
                self.bogie_mass_t,
                "must be in (0, 60) t (the limit (12 - m/5)/2 must stay > 0)",
            ),
            (Quantity::GuidingForce, None) => Err(format!(
                "{load_name}: needed for guiding forces, the static wheel load Q0 of the \
                 assessed vehicle in kN (the coach's 54.2, the 2-dof bogie's 70)"
            )),
            (Quantity::GuidingForce, Some(load))
                if !crate::en14363::STATIC_WHEEL_LOAD_RANGE_N.contains(&(load * 1e3)) =>
            {
                bad(
                    (load_name, load),
                    "must be a static wheel load within 1 .. 300 kN",
                )
            }
            _ => Ok(()),
        }
    }
}

/// The options the computation would refuse, named as given.
fn check_options(args: &Args) -> Result<(), CommandError> {
    AssessNumbers {
        speed_kmh: ("--speed", args.speed),
        skip_s: ("--skip", args.skip),
        f0_hz: ("--f0", args.f0),
        bogie_mass_t: ("--bogie-mass", args.bogie_mass),
        wheel_load_kn: ("--wheel-load", args.wheel_load),
    }
    .check(args.quantity)
    .map_err(|e| CommandError::Failed(format!("invalid option {e}")))
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    super::check_out_folder(&args.out)?;
    check_options(args)?;
    let criterion = args
        .quantity
        .criterion(args.bogie_mass, args.wheel_load.unwrap_or(f64::NAN));
    let settings = StabilitySettings {
        skip_s: args.skip,
        dominant_frequency_hz: args.f0,
        ..StabilitySettings::default()
    };
    let table = ResultsTable::load(&args.table).map_err(failed)?;
    let (report, remark) = assess_checked(
        &table,
        &args.signals,
        args.speed,
        criterion,
        &settings,
        args.accept_narrow_band,
    )
    .map_err(failed)?;
    // the band check goes into the summary (and assess.json) as well as to the terminal
    let mut summary = report.summary();
    let band_check = match remark {
        None => "covered",
        Some(BandRemark::Unrecorded(note)) => {
            summary.push_str(&format!("note: {note}\n"));
            "unrecorded"
        }
        Some(BandRemark::Narrow(e)) => {
            let warning = format!(
                "WARNING: {e}\nWARNING: assessed anyway (--accept-narrow-band): the rms above \
                 may be wrong\n"
            );
            eprint!("{warning}");
            summary.push_str(&warning);
            "narrower, accepted"
        }
    };
    write_analysis_with(
        &COMMAND,
        &args.out,
        std::slice::from_ref(&args.table),
        ctx.cancel,
        &summary,
        report.results_json(band_check),
        |f| report.add_artefacts(f, band_check),
    )
}
