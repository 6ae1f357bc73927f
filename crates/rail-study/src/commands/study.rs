//! `master study [--vehicle vehicle|bogie2dof] [--fmus DIR] [--out DIR] [--quick] [--jobs N]
//! [--speeds FROM:TO:STEP|V,V,...] [--seeds N,N,...] [--configurations ID,ID,...]
//! [--track-level low|high] [--cv-speed KM/H]`:
//! the stability study (see [`crate::study`]): speed sweep per configuration, critical speeds,
//! car-body acceleration and ride comfort (coach), perturbation runs, c_v sensitivity, time
//! histories; REPORT.md, SVG plots and CSVs under `--out`.

use std::path::PathBuf;
use std::time::Instant;

use crate::study::report::output_files;
use crate::study::run::{check_fmus, configurations_used};
use crate::study::{
    run_study_checked, write_outputs, Sources, StudyError, StudyOptions, StudySettings, Timing,
    TrackLevel, VehicleModel,
};
use master::cli::{CommandError, Context};
use master::results::ResultsFormat;
use master::show;

/// Run the stability study and write REPORT.md, plots and CSVs.
#[derive(Debug, clap::Args)]
// help texts for a terminal: `[unit]` and `<name>` are plain text, not links or HTML
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
pub struct Args {
    /// Vehicle model: the coach with four dampers (`vehicle`, RailVehicle.fmu) or the 2-dof
    /// bogie with two (`bogie2dof`, the seed's HIL configuration).
    #[arg(long, value_enum, default_value = "vehicle")]
    pub vehicle: VehicleModel,
    /// Folder with the FMUs (RailVehicle.fmu, Bogie2Dof.fmu, SemiActiveDamper.fmu, ...);
    /// default: `dist` in the current folder, else the `dist` of the workspace the binary was
    /// built in.
    #[arg(long)]
    pub fmus: Option<PathBuf>,
    /// Output folder. An earlier study's report, figures and tables in it are removed when
    /// the study starts (the user's other files stay).
    #[arg(
        short = 'o',
        long,
        visible_alias = "output",
        value_name = "DIR",
        default_value = "results"
    )]
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
    /// low-pass, about a third of the full-rate Parquet's size). The numbers come from the
    /// full-rate signals either way.
    #[arg(long, value_enum, default_value = "parquet")]
    pub format: ResultsFormat,
    /// Speed of the full-active c_v sensitivity runs (Table 4-3, R14) [km/h]. Default 380, the
    /// speed R13 names; the seed does not give the table's speed.
    #[arg(long, value_name = "KM/H")]
    pub cv_speed: Option<f64>,
    /// ERRI B176 level of the lateral alignment of every irregular-track run (it replaces the
    /// systems' `track.level`, as the study sets speed and seed): low (high-speed lines, the
    /// study's default) or high (2.9 times the low level's spectrum).
    #[arg(long, value_enum, default_value = "low")]
    pub track_level: TrackLevel,
    /// Speeds of the sweep [km/h], instead of the study's (full: 200-440 km/h on the coach,
    /// 200-400 on the bogie, in 10 km/h steps): `FROM:TO:STEP` (e.g. 250:350:5) or a list
    /// (e.g. 280,290,300). Critical speeds are refined by bisection between them as usual.
    #[arg(long, value_name = "FROM:TO:STEP|V,V,...", value_parser = parse_speeds)]
    pub speeds: Option<SpeedList>,
    /// Track seeds of the irregular-track runs, e.g. 1,2,3 (default: 1,2; --quick: 1); each
    /// sweep point, and each row of the c_v table, is the worst over them. The time-history runs
    /// use the first.
    #[arg(long, value_name = "N,N,...", value_parser = parse_seeds)]
    pub seeds: Option<SeedList>,
    /// Configurations of the sweep, e.g. passive,mppt1 (default: all of the vehicle's; ids as
    /// in systems/*.json: passive, mppt1, mppt2, skyhook_onoff, skyhook_continuous, their
    /// *_slow variants, skyhook_accel_onoff[_slow] on the coach, full_active). The c_v and
    /// time-history runs are made as usual.
    #[arg(long, value_name = "ID,ID,...", value_delimiter = ',')]
    pub configurations: Option<Vec<String>>,
}

/// The range of `--cv-speed` and `--speeds` [km/h]: the vehicle FMUs' running speed is
/// 1-200 m/s.
const SPEED_RANGE_KMH: std::ops::RangeInclusive<f64> = 10.0..=700.0;
/// At most this many sweep speeds (the full study has 25) and track seeds.
const MAX_SPEEDS: usize = 200;
const MAX_SEEDS: usize = 20;
/// The vehicle FMUs' `track.seed` is an FMI Integer (32-bit), from 0.
const MAX_SEED: u32 = i32::MAX as u32;

/// The sweep speeds of `--speeds` [km/h], ascending and distinct.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedList(pub Vec<f64>);

/// The track seeds of `--seeds`, in the order given, distinct.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedList(pub Vec<u32>);

fn parse_speed(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a speed in km/h", show::text(text)))?;
    if !SPEED_RANGE_KMH.contains(&v) {
        return Err(format!(
            "{} km/h: speeds must lie between {} and {} km/h",
            show::num(v),
            SPEED_RANGE_KMH.start(),
            SPEED_RANGE_KMH.end()
        ));
    }
    Ok(v)
}

/// Speeds are kept to 0.1 km/h, the resolution of the runs' names (`sweep-passive_v287.5_s1`).
fn to_tenth(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

/// `FROM:TO:STEP` or `V,V,...`, each to 0.1 km/h.
fn parse_speeds(text: &str) -> Result<SpeedList, String> {
    let mut speeds = match text.split(':').collect::<Vec<_>>()[..] {
        [from, to, step] => {
            let (from, to) = (parse_speed(from)?, parse_speed(to)?);
            let step: f64 = step
                .trim()
                .parse()
                .map_err(|_| format!("'{}' is not a speed step in km/h", show::text(step)))?;
            if !(step.is_finite() && step >= 0.1) || to < from {
                return Err(format!(
                    "{}: FROM:TO:STEP needs FROM <= TO and a step of at least 0.1 km/h",
                    show::text(text)
                ));
            }
            // slack for rounding only: TO is in when the step divides the range, never past it
            let n = ((to - from) / step + 1e-9).floor();
            if n >= MAX_SPEEDS as f64 {
                return Err(format!(
                    "{}: more than {MAX_SPEEDS} speeds",
                    show::text(text)
                ));
            }
            (0..=n as usize)
                .map(|k| to_tenth(from + k as f64 * step))
                .filter(|&v| v <= to_tenth(to))
                .collect()
        }
        [_] => text
            .split(',')
            .map(|v| parse_speed(v).map(to_tenth))
            .collect::<Result<Vec<_>, _>>()?,
        _ => {
            return Err(format!(
                "'{}': FROM:TO:STEP or a list V,V,...",
                show::text(text)
            ))
        }
    };
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    if speeds.len() > MAX_SPEEDS {
        return Err(format!("{} speeds, at most {MAX_SPEEDS}", speeds.len()));
    }
    Ok(SpeedList(speeds))
}

/// Every sweep run must cover one EN 14363 window of track after its start-up, or its speed
/// would count as unstable without being assessed.
fn check_assessable(settings: &StudySettings) -> Result<(), CommandError> {
    let en14363 = crate::en14363::StabilitySettings {
        skip_s: settings.skip_s,
        ..Default::default()
    };
    let (window_m, stop_s) = (en14363.window_m, settings.sweep_stop_s);
    match settings
        .speeds_kmh
        .iter()
        .find(|&&v| en14363.assessed_m(stop_s, v) < window_m)
    {
        Some(&v) => Err(CommandError::Failed(format!(
            "--speeds: at {v} km/h a sweep run ({stop_s} s, the first {} s skipped) covers {:.0} m \
             of track, less than one {window_m:.0} m EN 14363 window; the lowest speed this study \
             can assess is {:.1} km/h",
            settings.skip_s,
            en14363.assessed_m(stop_s, v),
            (window_m / en14363.assessed_m(stop_s, 1.0) * 10.0).ceil() / 10.0
        ))),
        None => Ok(()),
    }
}

/// `ids` in the study's order, each one of `available` (the vehicle's configurations).
fn chosen_configurations(
    ids: &[String],
    available: &[&'static str],
) -> Result<Vec<&'static str>, CommandError> {
    if let Some(bad) = ids.iter().find(|id| !available.contains(&id.trim())) {
        return Err(CommandError::Failed(format!(
            "--configurations: '{}' is not a configuration of this vehicle (one of {})",
            show::text(bad),
            available.join(", ")
        )));
    }
    Ok(available
        .iter()
        .copied()
        .filter(|a| ids.iter().any(|id| id.trim() == *a))
        .collect())
}

fn parse_seeds(text: &str) -> Result<SeedList, String> {
    let mut seeds: Vec<u32> = Vec::new();
    for part in text.split(',') {
        let seed: u32 = part
            .trim()
            .parse()
            .ok()
            .filter(|&s| s <= MAX_SEED)
            .ok_or_else(|| {
                format!(
                    "'{}' is not a track seed (0 to {MAX_SEED})",
                    show::text(part)
                )
            })?;
        if !seeds.contains(&seed) {
            seeds.push(seed);
        }
    }
    if seeds.len() > MAX_SEEDS {
        return Err(format!("{} seeds, at most {MAX_SEEDS}", seeds.len()));
    }
    Ok(SeedList(seeds))
}

impl From<StudyError> for CommandError {
    fn from(e: StudyError) -> Self {
        match e {
            StudyError::System(e) => CommandError::System(e),
            StudyError::Prepare(e) => CommandError::Run(Box::new(e)),
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
    if let Some(SpeedList(speeds)) = &args.speeds {
        settings.speeds_kmh = speeds.clone();
    }
    if let Some(SeedList(seeds)) = &args.seeds {
        settings.seeds = seeds.clone();
    }
    if let Some(ids) = &args.configurations {
        settings.configurations = chosen_configurations(ids, &settings.configurations)?;
    }
    check_assessable(&settings)?;
    if let Some(v) = args.cv_speed {
        if !SPEED_RANGE_KMH.contains(&v) {
            return Err(CommandError::Failed(format!(
                "--cv-speed {}: the speed of the c_v runs must lie between {} and {} km/h",
                show::num(v),
                SPEED_RANGE_KMH.start(),
                SPEED_RANGE_KMH.end()
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
    // A mistyped FMU folder is refused before anything of an earlier study is touched.
    check_fmus(
        &opts.sources,
        args.vehicle,
        &configurations_used(&settings)?,
    )?;
    // A study that cannot run (a system description that does not parse or names an unknown
    // variable) fails before the folder is touched. Then the folder is locked against a
    // second study or run set writing into it, and an interrupted or failed study must not
    // leave the previous study's results looking current: its report, figures and tables
    // are removed before the first run and written again only when every output is ready.
    let mut lock = None;
    let results = run_study_checked(&settings, &opts, || {
        lock = Some(master::runset::lock_output_folder(&args.out)?);
        remove_earlier_outputs(&args.out)?;
        // bisection rounds of an earlier study beyond this one's would be left beside its runs
        remove_batches(&args.out.join("runs"), "bisect-")
    })?;
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

/// Whether `out` holds an earlier study: its `study.json` is a regular file that reads as a
/// study's numbers (settings and configurations).
fn holds_earlier_study(out: &std::path::Path) -> bool {
    let path = out.join("study.json");
    if !std::fs::symlink_metadata(&path).is_ok_and(|m| m.file_type().is_file()) {
        return false;
    }
    master::input::read_text_file(&path, master::input::MAX_TEXT_FILE_BYTES)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .is_some_and(|v| v.get("settings").is_some() && v["configs"].is_array())
}

/// Removes the files an earlier study wrote into `out` ([`output_files`]: report, figures,
/// tables), if `out` holds one ([`holds_earlier_study`]): regular files (and symbolic links)
/// of these names only; a user's other files, and a folder or FIFO of such a name, stay, and
/// in a folder without an earlier study nothing is removed.
fn remove_earlier_outputs(out: &std::path::Path) -> Result<(), StudyError> {
    if !holds_earlier_study(out) {
        return Ok(());
    }
    for name in output_files() {
        let path = out.join(name);
        master::output::remove_stale_file(&path).map_err(|e| {
            StudyError::Folder(format!(
                "cannot remove the previous '{}': {e}",
                path.display()
            ))
        })?;
    }
    Ok(())
}

/// Removes the batch folders `<runs>/<prefix>*` an earlier study wrote (each holds its
/// `sweep.json` or run folders; anything else is left alone).
fn remove_batches(runs: &std::path::Path, prefix: &str) -> Result<(), StudyError> {
    let Ok(entries) = std::fs::read_dir(runs) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let path = e.path();
        let ours = e.file_name().to_string_lossy().starts_with(prefix)
            && e.file_type().is_ok_and(|t| t.is_dir())
            && path.join("sweep.json").is_file();
        if ours {
            // its runs and their tables as a run set's are removed (a file of the user's in a
            // run folder stays), then its report, then the folders left empty
            master::runset::prepare_run_folder(&[], &path)?;
            master::runset::remove_partial_folders(&path);
            let cannot = |err: std::io::Error| {
                StudyError::Folder(format!(
                    "cannot remove the earlier study's '{}': {err}",
                    path.display()
                ))
            };
            std::fs::remove_file(path.join("sweep.json")).map_err(cannot)?;
            let _ = std::fs::remove_dir(path.join(master::runset::PARQUET_FOLDER));
            let _ = std::fs::remove_dir(&path);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An earlier study's bisection batches go with their runs and reports, but a file of the
    /// user's in one stays (with the folder holding it).
    #[test]
    fn earlier_batches_go_but_a_users_file_stays() {
        let d = tempfile::tempdir().unwrap();
        let runs = d.path();
        for batch in ["bisect-1", "bisect-2"] {
            let run = runs.join(batch).join("r");
            std::fs::create_dir_all(&run).unwrap();
            std::fs::write(runs.join(batch).join("sweep.json"), "[]").unwrap();
            std::fs::write(run.join("system.json"), "{}").unwrap();
            std::fs::write(
                run.join("summary.json"),
                r#"{"name": "r", "parameters": {}, "ok": true, "error": null,
                    "summary": null, "results": null}"#,
            )
            .unwrap();
        }
        std::fs::write(runs.join("bisect-1").join("notes.txt"), "mine").unwrap();
        std::fs::create_dir(runs.join("bisect-1").join(".partial-r-x")).unwrap();
        std::fs::create_dir(runs.join("mine")).unwrap();
        remove_batches(runs, "bisect-").unwrap();
        assert!(!runs.join("bisect-2").exists());
        let left: Vec<String> = std::fs::read_dir(runs.join("bisect-1"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(left, ["notes.txt"]);
        assert!(runs.join("mine").is_dir());
    }

    #[test]
    fn speeds_as_a_range_or_a_list() {
        assert_eq!(
            parse_speeds("250:300:10").unwrap().0,
            [250.0, 260.0, 270.0, 280.0, 290.0, 300.0]
        );
        // the end is in when the step divides the range, not past it otherwise
        assert_eq!(parse_speeds("200:215:10").unwrap().0, [200.0, 210.0]);
        assert_eq!(parse_speeds("250:349:10").unwrap().0.last(), Some(&340.0));
        assert_eq!(parse_speeds("10:700:766").unwrap().0, [10.0]);
        assert_eq!(
            parse_speeds("280:280.3:0.1").unwrap().0,
            [280.0, 280.1, 280.2, 280.3]
        );
        // to 0.1 km/h, the runs' names: 300 and 300.04 are one speed
        assert_eq!(parse_speeds("300,300.04,287.46").unwrap().0, [287.5, 300.0]);
        assert_eq!(parse_speeds("300:300:5").unwrap().0, [300.0]);
        assert_eq!(
            parse_speeds("300, 280,290,280").unwrap().0,
            [280.0, 290.0, 300.0]
        );
        for bad in [
            "",
            "abc",
            "300:200:10",
            "200:300:0",
            "200:300:-5",
            "200:300:nan",
            "200:300:0.05",
            "5",
            "800",
            "nan",
            "inf",
            "200:300",
            "1:2:3:4",
            "10:700:0.001",
        ] {
            assert!(parse_speeds(bad).is_err(), "{bad:?} accepted");
        }
        let e = parse_speeds("200,9000").unwrap_err();
        assert!(e.contains("between 10 and 700 km/h"), "{e}");
    }

    #[test]
    fn configurations_keep_the_study_order_and_unknown_ones_are_refused() {
        let all = StudySettings::full(VehicleModel::Bogie2Dof).configurations;
        let ids = ["mppt1".to_string(), " passive".to_string()];
        assert_eq!(
            chosen_configurations(&ids, &all).unwrap(),
            ["passive", "mppt1"]
        );
        // the accelerometer sky-hook is the coach's
        let e = chosen_configurations(&["skyhook_accel_onoff".to_string()], &all).unwrap_err();
        assert!(
            e.to_string()
                .contains("not a configuration of this vehicle"),
            "{e}"
        );
        let coach = StudySettings::full(VehicleModel::Coach).configurations;
        assert!(chosen_configurations(&["skyhook_accel_onoff".to_string()], &coach).is_ok());
    }

    #[test]
    fn every_sweep_speed_covers_one_window() {
        let mut s = StudySettings::quick(VehicleModel::Bogie2Dof);
        assert!(check_assessable(&s).is_ok());
        // 12 s runs, 5 s skipped: 7 s cover 100 m from 51.5 km/h on
        s.speeds_kmh = vec![51.5, 300.0];
        assert!(check_assessable(&s).is_ok());
        s.speeds_kmh = vec![51.4, 300.0];
        let e = check_assessable(&s).unwrap_err().to_string();
        assert!(
            e.contains("at 51.4 km/h") && e.contains("is 51.5 km/h"),
            "{e}"
        );
    }

    #[test]
    fn an_earlier_studys_outputs_are_removed_and_nothing_else() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path();
        let earlier = [
            "REPORT.md",
            "study.json",
            "rms_vs_speed.svg",
            "rms_vs_speed.csv",
            "history_carbody.svg",
            "cv_sensitivity.csv",
        ];
        for f in earlier {
            std::fs::write(out.join(f), "an earlier study's").unwrap();
        }
        // without an earlier study's numbers, files of these names are the user's: kept
        remove_earlier_outputs(out).unwrap();
        for f in earlier {
            assert!(out.join(f).is_file(), "{f} removed");
        }
        std::fs::write(out.join("study.json"), r#"{"settings": {}, "configs": []}"#).unwrap();
        let users = [
            "notes.svg",
            "my_table.csv",
            "cv_sensitivity.svg",
            "REPORT.txt",
        ];
        for f in users {
            std::fs::write(out.join(f), "the user's").unwrap();
        }
        std::fs::create_dir(out.join("perturbation.svg")).unwrap();
        remove_earlier_outputs(out).unwrap();
        for f in earlier {
            assert!(!out.join(f).exists(), "{f} is left");
        }
        for f in users {
            assert_eq!(
                std::fs::read_to_string(out.join(f)).unwrap(),
                "the user's",
                "{f}"
            );
        }
        assert!(out.join("perturbation.svg").is_dir());
        // no folder yet: nothing to remove
        remove_earlier_outputs(&out.join("none")).unwrap();
    }

    #[test]
    fn seeds_as_a_list() {
        assert_eq!(parse_seeds("3,1,3").unwrap().0, [3, 1]);
        assert_eq!(parse_seeds("2147483647").unwrap().0, [MAX_SEED]);
        for bad in ["", "-1", "1.5", "2147483648", "a,b"] {
            assert!(parse_seeds(bad).is_err(), "{bad:?} accepted");
        }
        let many: Vec<String> = (0..21).map(|k| k.to_string()).collect();
        assert!(parse_seeds(&many.join(","))
            .unwrap_err()
            .contains("at most 20"));
    }
}
