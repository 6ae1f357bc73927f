//! `master study [--vehicle vehicle|bogie2dof] [--fmus DIR] [--out DIR] [--quick] [--jobs N]
//! [--cv-speed KM/H]`:
//! the stability study (see [`crate::study`]): speed sweep per configuration, critical speeds,
//! car-body acceleration and ride comfort (coach), perturbation runs, c_v sensitivity, time
//! histories; REPORT.md, SVG plots and CSVs under `--out`.

use std::path::PathBuf;
use std::time::Instant;

use crate::study::{
    run_study, write_outputs, Sources, StudyError, StudyOptions, StudySettings, Timing, TrackLevel,
    VehicleModel,
};
use master::cli::{CommandError, Context};
use master::results::ResultsFormat;

/// Run the stability study and write REPORT.md, plots and CSVs.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Vehicle model: the coach with four dampers (`vehicle`, RailVehicle.fmu) or the 2-dof
    /// bogie with two (`bogie2dof`, the seed's HIL configuration).
    #[arg(long, value_enum, default_value = "vehicle")]
    pub vehicle: VehicleModel,
    /// Folder with the FMUs (RailVehicle.fmu, Bogie2Dof.fmu, SemiActiveDamper.fmu, ...).
    #[arg(long)]
    pub fmus: Option<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Reduced study for CI: 1 seed, shorter runs, fewer speeds, coarser bisection.
    #[arg(long)]
    pub quick: bool,
    /// Number of parallel runs (default: all cores).
    #[arg(short, long)]
    pub jobs: Option<usize>,
    /// Folder with <configuration>.json system descriptions to use instead of the built-in
    /// ones (the coach's generated systems, the bogie's systems/*.json).
    #[arg(long)]
    pub systems: Option<PathBuf>,
    /// Format of each run's stored results: parquet (full rate, runs/<batch>/results/) or
    /// csv (runs/<batch>/<run>/results.csv, decimated to 100 Hz through an anti-aliasing
    /// low-pass, about a tenth of the size). The numbers come from the full-rate signals
    /// either way.
    #[arg(long, value_enum, default_value = "parquet")]
    pub format: ResultsFormat,
    /// Speed of the full-active c_v sensitivity runs (Table 4-3, R14) [km/h]. Default 380, the
    /// speed R13 names; the seed does not give the table's speed.
    #[arg(long, value_name = "KM/H")]
    pub cv_speed: Option<f64>,
    /// ERRI B176 level of the lateral alignment of every irregular-track run (it replaces the
    /// systems' `track.level`, as the study sets speed and seed): low (the seed's high-speed
    /// line) or high (2.9 times the low level's spectrum).
    #[arg(long, value_enum, default_value = "low")]
    pub track_level: TrackLevel,
}

/// The range of `--cv-speed` [km/h]: the vehicle FMUs' running speed is 1-200 m/s.
const CV_SPEED_RANGE_KMH: std::ops::RangeInclusive<f64> = 10.0..=700.0;

impl From<StudyError> for CommandError {
    fn from(e: StudyError) -> Self {
        match e {
            StudyError::System(e) => CommandError::System(e),
            StudyError::Prepare(e) => CommandError::Run(e),
            StudyError::Sweep(e) => CommandError::Sweep(e),
            StudyError::Output(e) => CommandError::Output(e),
            StudyError::Plot(e) => e.into(),
            other => CommandError::Failed(other.to_string()),
        }
    }
}

pub fn execute(args: &Args, ctx: &Context) -> Result<(), CommandError> {
    let start = Instant::now();
    // Hundreds of runs: FMU warnings (e.g. an IDF spool command at its clamp) would drown the
    // progress bar. At the default level (info) only errors are shown; --log-level warn or
    // lower keeps them.
    if log::max_level() == log::LevelFilter::Info {
        log::set_max_level(log::LevelFilter::Error);
    }
    let mut settings = if args.quick {
        StudySettings::quick(args.vehicle)
    } else {
        StudySettings::full(args.vehicle)
    };
    settings.stored_format = args.format;
    settings.track_level = args.track_level;
    if let Some(v) = args.cv_speed {
        if !CV_SPEED_RANGE_KMH.contains(&v) {
            return Err(CommandError::Failed(format!(
                "--cv-speed {v}: the speed of the c_v runs must lie between {} and {} km/h",
                CV_SPEED_RANGE_KMH.start(),
                CV_SPEED_RANGE_KMH.end()
            )));
        }
        settings.cv_speed_kmh = v;
    }
    let threads = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let opts = StudyOptions {
        sources: Sources {
            fmus: args
                .fmus
                .clone()
                .unwrap_or_else(crate::study::run::default_fmu_dir),
            systems: args.systems.clone(),
        },
        out: args.out.clone(),
        threads,
        progress: ctx.progress,
        cancel: ctx.cancel,
    };
    eprintln!(
        "study ({}, {}): {} runs before bisection on {threads} threads, output in {}",
        if args.quick { "quick" } else { "full" },
        match args.vehicle {
            VehicleModel::Coach => "coach",
            VehicleModel::Bogie2Dof => "2-dof bogie",
        },
        settings.planned_runs(),
        args.out.display()
    );
    // An interrupted or failed study must not leave the previous report looking current: it
    // is removed before the first run and written again only when every output is ready.
    for old in ["REPORT.md", "study.json"] {
        match std::fs::remove_file(args.out.join(old)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(CommandError::Failed(format!(
                    "cannot remove the previous '{}': {e}",
                    args.out.join(old).display()
                )))
            }
            _ => {}
        }
    }
    let results = run_study(&settings, &opts)?;
    let timing = Timing {
        wall_s: start.elapsed().as_secs_f64(),
        threads,
    };
    write_outputs(&results, &args.out, &timing)?;
    for c in &results.configs {
        println!(
            "{:<36} critical speed {}",
            c.label,
            c.critical.map_or("n/a".into(), |k| k.describe())
        );
    }
    println!(
        "{} runs ({} failed), {:.0} s simulated in {:.1} s wall time: {:.1} simulated s per wall s; report: {}",
        results.runs,
        results.failures.len(),
        results.simulated_s,
        timing.wall_s,
        timing.sim_per_wall(&results),
        args.out.join("REPORT.md").display()
    );
    Ok(())
}
