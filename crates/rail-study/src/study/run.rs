//! Running the study: each configuration's system is prepared once for the whole study
//! ([`PreparedSystem`]: its FMUs opened, checked, unpacked and loaded once, its plan built
//! once), and every batch of runs goes through the master's run sets
//! ([`master::runset::execute_with`]: parallel on a rayon pool, one folder per run with
//! system.json / summary.json, failures kept); a run is its start values and stop time
//! ([`master::runset::run_job`]). The numbers of each run are computed from its full-rate
//! output inside the worker. Its results are stored at the full rate as Parquet
//! (`runs/<batch>/results/<run>.parquet`, with the configuration, speed and seed as
//! columns), or as CSV decimated to [`StudySettings::stored_rate_hz`] through an
//! anti-aliasing low-pass ([`master::decimation`]). The time histories the plots draw are
//! every n-th sample of the full-rate output, unfiltered (`every_nth_row`).

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

use serde_json::Value;

use crate::en14363::acceleration_limit;
use crate::study::config::{required_fmus, RunRequest, Sources};
use crate::study::configurations::{configuration, Configuration, Family};
use crate::study::critical::{Critical, CurvePoint};
use crate::study::metrics::{run_metrics, MetricSpec, RunMetrics, BOGIE_MASS_T};
use crate::study::settings::StudySettings;
use crate::study::vehicle::{Signals, VehicleModel};
use master::coupling::{FailedRun, SimOutput};
use master::decimation::{decimate, factor_for_rate};
use master::results::ResultsFormat;
use master::runset::{execute_with, run_job, Job, ResultsOptions, SweepError};
use master::system::{PreparedSystem, RunError, SystemError};

/// Why the study stopped.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("unknown configuration '{0}'")]
    UnknownConfiguration(String),
    #[error("FMU '{path}' not found: {hint}")]
    MissingFmu { path: PathBuf, hint: String },
    #[error(transparent)]
    System(#[from] SystemError),
    #[error(transparent)]
    Prepare(#[from] RunError),
    #[error(transparent)]
    Sweep(#[from] SweepError),
    #[error(transparent)]
    Output(#[from] master::output::OutputError),
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    #[error("{0}")]
    Folder(String),
    #[error("cancelled")]
    Cancelled,
}

/// How to run.
pub struct StudyOptions<'a> {
    pub sources: Sources,
    /// Output folder (runs go to `<out>/runs/<batch>/<run>/`).
    pub out: PathBuf,
    pub threads: usize,
    pub progress: bool,
    pub cancel: &'a AtomicBool,
}

/// rms of one speed of one configuration.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpeedPoint {
    pub speed_kmh: f64,
    /// EN 14363 rms per seed (max over the axle boxes), `None` for a failed run.
    pub per_seed: Vec<Option<f64>>,
    /// Car-body floor lateral acceleration rms per seed (coach), `None` for a failed run or
    /// without a car body [m/s^2].
    pub carbody_per_seed: Vec<Option<f64>>,
    /// EN 12299 lateral comfort N_y per seed (coach).
    pub comfort_per_seed: Vec<Option<f64>>,
    /// Yaw-damper stroke amplitude per seed, where the elongations are recorded (coach) \[m\].
    pub stroke_per_seed: Vec<Option<f64>>,
}

/// Max over seeds; `None` if any is missing (or there are none).
fn max_all(v: &[Option<f64>]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.iter().try_fold(0.0f64, |m, r| r.map(|r| m.max(r)))
}

impl SpeedPoint {
    /// Max over seeds; `None` if any run failed.
    pub fn rms(&self) -> Option<f64> {
        self.per_seed
            .iter()
            .try_fold(0.0f64, |m, r| r.map(|r| m.max(r)))
    }

    /// Car-body rms, max over seeds.
    pub fn carbody_rms(&self) -> Option<f64> {
        max_all(&self.carbody_per_seed)
    }

    /// N_y, max over seeds.
    pub fn comfort(&self) -> Option<f64> {
        max_all(&self.comfort_per_seed)
    }

    /// Yaw-damper stroke amplitude, max over seeds \[m\].
    pub fn damper_stroke(&self) -> Option<f64> {
        max_all(&self.stroke_per_seed)
    }
}

/// The sweep result of one configuration.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ConfigResult {
    pub id: &'static str,
    pub label: &'static str,
    pub seed_value: &'static str,
    pub reference: &'static str,
    /// Sweep points (sorted by speed).
    pub sweep: Vec<SpeedPoint>,
    /// Bisection points in the order run.
    pub bisection: Vec<SpeedPoint>,
    pub critical: Option<Critical>,
}

impl ConfigResult {
    pub fn curve(&self) -> Vec<CurvePoint> {
        let mut v: Vec<CurvePoint> = self
            .sweep
            .iter()
            .chain(&self.bisection)
            .map(|p| CurvePoint {
                speed_kmh: p.speed_kmh,
                rms: p.rms(),
            })
            .collect();
        v.sort_by(|a, b| a.speed_kmh.total_cmp(&b.speed_kmh));
        v
    }
    /// rms at a sweep speed (max over seeds).
    pub fn rms_at(&self, speed_kmh: f64) -> Option<f64> {
        self.sweep
            .iter()
            .chain(&self.bisection)
            .find(|p| (p.speed_kmh - speed_kmh).abs() < 1e-6)
            .and_then(SpeedPoint::rms)
    }
}

/// One named single run (perturbation, c_v, scenario).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct NamedRun {
    pub name: String,
    pub config: &'static str,
    pub speed_kmh: f64,
    /// c_v [N s/m] for the sensitivity runs.
    pub c_v_nspm: Option<f64>,
    pub metrics: Option<RunMetrics>,
    pub error: Option<String>,
}

/// Everything the report and the tests need.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StudyResults {
    pub settings: StudySettings,
    pub limit_mps2: f64,
    pub configs: Vec<ConfigResult>,
    pub perturbation: Vec<NamedRun>,
    pub cv: Vec<NamedRun>,
    /// history-*, mpptlow-*, hil-* runs by name.
    pub scenarios: Vec<NamedRun>,
    /// (run, error) of every failed run.
    pub failures: Vec<(String, String)>,
    pub runs: usize,
    pub simulated_s: f64,
    /// Sum of the runs' own wall times (CPU-side effort) \[s\].
    pub run_wall_s: f64,
    /// Outputs of the runs the plots need, decimated to the stored rate, by run name.
    #[serde(skip)]
    pub kept: BTreeMap<String, SimOutput>,
    /// The last [`HISTORY_DETAIL_S`] of the same runs at the full recorded rate (the detail
    /// figures: a valve switching within 10 ms falls between the stored rate's samples).
    #[serde(skip)]
    pub kept_tail: BTreeMap<String, SimOutput>,
}

impl StudyResults {
    pub fn config(&self, id: &str) -> Option<&ConfigResult> {
        self.configs.iter().find(|c| c.id == id)
    }
    pub fn scenario(&self, name: &str) -> Option<&NamedRun> {
        self.scenarios.iter().find(|r| r.name == name)
    }
}

/// What one request is for.
#[derive(Debug, Clone)]
struct Planned {
    request: RunRequest,
    keep: bool,
}

/// Per-run outcome collected from the workers.
#[derive(Debug, Default)]
struct Collected {
    metrics: BTreeMap<String, Result<RunMetrics, String>>,
    kept: BTreeMap<String, SimOutput>,
    kept_tail: BTreeMap<String, SimOutput>,
    simulated_s: f64,
    run_wall_s: f64,
    runs: usize,
}

struct Executor<'a> {
    settings: &'a StudySettings,
    opts: &'a StudyOptions<'a>,
    /// Each configuration's system, prepared on its first run.
    prepared: HashMap<&'static str, PreparedSystem>,
    /// The recorded signals the numbers are computed from.
    signals: Signals,
    collected: Collected,
}

/// Every `factor`-th row of `out` as recorded (the first always): what the figures draw. A
/// switching valve command then shows its 0 and 10 V and an opening stays within 0..1, where
/// the anti-aliasing low-pass of the stored CSV rings at each step (-0.8..11 V). For the
/// figures only: nothing above half the new rate is removed, so no spectrum is taken of it.
fn every_nth_row(out: &SimOutput, factor: usize) -> SimOutput {
    let w = out.header.len().max(1);
    let data = out
        .data
        .chunks_exact(w)
        .step_by(factor.max(1))
        .flatten()
        .copied()
        .collect();
    with_data(out, data)
}

/// The window of a time history's detail figure, at the end of the run \[s\]: over the whole
/// record a limit cycle or an on/off command fills its panel as a solid band; over 2 s its
/// cycles (8-10 at the hunting frequency) and switchings can be told apart.
pub const HISTORY_DETAIL_S: f64 = 2.0;

/// The rows of `out` from `seconds` before its last time on, as recorded.
fn last_rows(out: &SimOutput, seconds: f64) -> SimOutput {
    let w = out.header.len().max(1);
    let rows = out.data.chunks_exact(w);
    let t_end = rows.clone().next_back().map_or(0.0, |r| r[0]);
    // the times increase: the window is the rows counted from the end
    let n = rows
        .rev()
        .take_while(|r| r[0] >= t_end - seconds - 1e-9)
        .count();
    with_data(out, out.data[out.data.len() - n * w..].to_vec())
}

/// `out` with its rows replaced by `data` (the same columns).
fn with_data(out: &SimOutput, data: Vec<f64>) -> SimOutput {
    SimOutput {
        header: out.header.clone(),
        data,
        summary: out.summary.clone(),
        columns: out.columns.clone(),
        strings: out.strings.clone(),
        decimation: out.decimation.clone(),
    }
}

/// A recorded output of the given columns and rows (time first), for tests of what is drawn
/// and computed from one.
#[cfg(test)]
pub(crate) fn recorded(header: Vec<String>, data: Vec<f64>) -> SimOutput {
    let w = header.len().max(1);
    let times: Vec<f64> = data.chunks_exact(w).map(|r| r[0]).collect();
    let span_s = times.last().zip(times.first()).map_or(0.0, |(b, a)| b - a);
    SimOutput {
        header,
        data,
        summary: master::coupling::Summary {
            steps: times.len().saturating_sub(1) as u64,
            rejected_steps: 0,
            simulated_time_s: span_s,
            wall_time_s: 1.0,
            realtime_ratio: span_s,
            terminated: None,
            failed: None,
        },
        columns: vec![],
        strings: vec![],
        decimation: None,
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Executor<'_> {
    /// Prepares the configuration's system unless done before.
    fn prepare(&mut self, c: &'static Configuration) -> Result<(), StudyError> {
        if !self.prepared.contains_key(c.id) {
            let system = self.opts.sources.system(self.settings.vehicle, c)?;
            self.prepared
                .insert(c.id, PreparedSystem::prepare(&system)?);
        }
        Ok(())
    }

    /// The jobs of `planned`, in its order: each request given the study's track level, its
    /// configuration's system prepared.
    fn jobs_of(&mut self, planned: &mut [Planned]) -> Result<Vec<Job>, StudyError> {
        let mut jobs = Vec::with_capacity(planned.len());
        for p in planned {
            p.request.track_level = self.settings.track_level;
            self.prepare(p.request.config)?;
            let Some(system) = self.prepared.get(p.request.config.id) else {
                return Err(StudyError::UnknownConfiguration(p.request.config.id.into()));
            };
            jobs.push(p.request.job(system.system())?);
        }
        Ok(jobs)
    }

    /// Prepares the systems of `planned` and checks each run's start values against them, and
    /// that no earlier run folder of the main batch holds a file of the user's (the batch
    /// would replace it): refused before the earlier study's files are removed.
    fn check(&mut self, planned: &mut [Planned]) -> Result<(), StudyError> {
        let jobs = self.jobs_of(planned)?;
        for (p, job) in planned.iter().zip(&jobs) {
            if let Some(system) = self.prepared.get(p.request.config.id) {
                master::runset::check_jobs(system, std::slice::from_ref(job))?;
            }
        }
        let main = self.opts.out.join("runs").join("main");
        master::runset::check_run_folders(&jobs, &main)?;
        master::runset::check_added_files(&jobs, &main)?;
        Ok(())
    }

    /// Runs one batch in `<out>/runs/<batch>` and collects its numbers.
    fn run_batch(&mut self, batch: &str, mut planned: Vec<Planned>) -> Result<(), StudyError> {
        if planned.is_empty() {
            return Ok(());
        }
        let mut jobs = self.jobs_of(&mut planned)?;
        let prepared = &self.prepared;
        let mut specs: HashMap<String, (MetricSpec, bool, &PreparedSystem)> = HashMap::new();
        let mut results = ResultsOptions {
            format: self.settings.stored_format,
            integer_columns: BTreeSet::from(["track_seed".to_string()]),
            ..ResultsOptions::default()
        };
        for (p, job) in planned.iter().zip(&jobs) {
            let Some(system) = prepared.get(p.request.config.id) else {
                return Err(StudyError::UnknownConfiguration(p.request.config.id.into()));
            };
            results
                .integer_columns
                .extend(system.integer_parameters(job.parameters.keys()));
            let r = &p.request;
            results.labels.insert(
                r.name.clone(),
                BTreeMap::from([
                    ("configuration".to_string(), Value::from(r.config.id)),
                    ("speed_kmh".to_string(), Value::from(r.speed_kmh)),
                    (
                        "track_seed".to_string(),
                        r.seed.map_or(Value::Null, Value::from),
                    ),
                ]),
            );
            specs.insert(
                p.request.name.clone(),
                (
                    MetricSpec {
                        skip_s: self.settings.skip_s,
                        tail_s: self.settings.tail_s,
                        speed_kmh: p.request.speed_kmh,
                    },
                    p.keep,
                    system,
                ),
            );
        }
        // longest runs first: the pool's tail is then short
        jobs.sort_by(|a, b| {
            let cost = |j: &Job| {
                (j.system.stop_time - j.system.start_time) * j.system.instances.len() as f64
            };
            cost(b).total_cmp(&cost(a))
        });
        let metrics: Mutex<BTreeMap<String, Result<RunMetrics, String>>> =
            Mutex::new(BTreeMap::new());
        let kept: Mutex<BTreeMap<String, SimOutput>> = Mutex::new(BTreeMap::new());
        let kept_tail: Mutex<BTreeMap<String, SimOutput>> = Mutex::new(BTreeMap::new());
        let cancel = self.opts.cancel;
        let rate = self.settings.stored_rate_hz;
        let full_rate = self.settings.stored_format == ResultsFormat::Parquet;
        let signals = &self.signals;
        let runner = |job: &Job| -> Result<SimOutput, FailedRun<String>> {
            let Some((spec, keep, system)) = specs.get(&job.name) else {
                return Err(format!("internal: no metric spec for run '{}'", job.name).into());
            };
            // a failed run's history goes into its run folder at the full rate: decimated,
            // it would lose the rows nearest the failure
            let out = run_job(system, job, cancel)?;
            let m = run_metrics(&out, spec, signals).map_err(|e| e.to_string());
            lock(&metrics).insert(job.name.clone(), m);
            let factor = factor_for_rate(&out, rate);
            if *keep {
                lock(&kept).insert(job.name.clone(), every_nth_row(&out, factor));
                lock(&kept_tail).insert(job.name.clone(), last_rows(&out, HISTORY_DETAIL_S));
            }
            if full_rate {
                return Ok(out);
            }
            Ok(decimate(&out, factor).map_err(|e| e.to_string())?)
        };
        let dir = self.opts.out.join("runs").join(batch);
        // this batch's runs only (an earlier study's other runs would read as part of it)
        master::runset::prepare_run_folder(&jobs, &dir)?;
        let reports = execute_with(
            &jobs,
            &dir,
            self.opts.threads,
            self.opts.progress,
            &results,
            Some(cancel),
            runner,
        )?;
        if cancel.load(Ordering::SeqCst) {
            return Err(StudyError::Cancelled);
        }
        let mut metrics = metrics
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        for r in reports {
            self.collected.runs += 1;
            if let Some(s) = &r.summary {
                self.collected.simulated_s += s.simulated_time_s;
                self.collected.run_wall_s += s.wall_time_s;
            }
            let m = match (r.ok, metrics.remove(&r.name)) {
                (true, Some(m)) => m,
                (true, None) => Err("internal: run gave no metrics".to_string()),
                (false, Some(Err(e))) => Err(e),
                (false, _) => Err(r.error.unwrap_or_else(|| "run failed".to_string())),
            };
            self.collected.metrics.insert(r.name, m);
        }
        self.collected.kept.extend(
            kept.into_inner()
                .unwrap_or_else(std::sync::PoisonError::into_inner),
        );
        self.collected.kept_tail.extend(
            kept_tail
                .into_inner()
                .unwrap_or_else(std::sync::PoisonError::into_inner),
        );
        Ok(())
    }

    fn metric(&self, name: &str) -> Option<&Result<RunMetrics, String>> {
        self.collected.metrics.get(name)
    }

    fn named(&self, req: &RunRequest, c_v: Option<f64>) -> NamedRun {
        let (metrics, error) = match self.metric(&req.name) {
            Some(Ok(m)) => (Some(m.clone()), None),
            Some(Err(e)) => (None, Some(e.clone())),
            None => (None, Some("not run".to_string())),
        };
        NamedRun {
            name: req.name.clone(),
            config: req.config.id,
            speed_kmh: req.speed_kmh,
            c_v_nspm: c_v,
            metrics,
            error,
        }
    }

    /// The c_v runs of one gain, one per track seed, as one row `cv-<kNs/m>` of the table:
    /// each quantity the largest over the seeds ([`RunMetrics::largest_over`]); no numbers if
    /// a run failed (the error names it).
    fn largest_over_seeds(&self, runs: &[RunRequest], c_v: f64) -> NamedRun {
        let named: Vec<NamedRun> = runs.iter().map(|r| self.named(r, Some(c_v))).collect();
        let errors: Vec<String> = named
            .iter()
            .filter_map(|n| n.error.as_ref().map(|e| format!("{}: {e}", n.name)))
            .collect();
        let metrics: Vec<RunMetrics> = named.iter().filter_map(|n| n.metrics.clone()).collect();
        NamedRun {
            name: format!("cv-{:.0}", c_v / 1e3),
            config: named.first().map_or("full_active", |n| n.config),
            speed_kmh: named.first().map_or(0.0, |n| n.speed_kmh),
            c_v_nspm: Some(c_v),
            metrics: if errors.is_empty() {
                RunMetrics::largest_over(&metrics)
            } else {
                None
            },
            error: (!errors.is_empty()).then(|| errors.join("; ")),
        }
    }

    fn speed_point(&self, c: &'static Configuration, speed: f64, prefix: &str) -> SpeedPoint {
        let runs: Vec<Option<&RunMetrics>> = self
            .settings
            .seeds
            .iter()
            .map(|&s| {
                let name = sweep_request(prefix, c, speed, s, self.settings).name;
                self.metric(&name).and_then(|m| m.as_ref().ok())
            })
            .collect();
        SpeedPoint {
            speed_kmh: speed,
            per_seed: runs.iter().map(|m| m.map(RunMetrics::rms)).collect(),
            carbody_per_seed: runs
                .iter()
                .map(|m| m.and_then(|m| m.carbody_rms_mps2))
                .collect(),
            comfort_per_seed: runs.iter().map(|m| m.and_then(|m| m.comfort_ny)).collect(),
            stroke_per_seed: runs
                .iter()
                .map(|m| m.and_then(|m| m.damper_stroke_m))
                .collect(),
        }
    }
}

fn sweep_request(
    prefix: &str,
    c: &'static Configuration,
    speed: f64,
    seed: u32,
    s: &StudySettings,
) -> RunRequest {
    RunRequest::new(prefix, s.vehicle, c, speed, Some(seed), s.sweep_stop_s)
}

fn config_or_err(id: &str) -> Result<&'static Configuration, StudyError> {
    configuration(id).ok_or_else(|| StudyError::UnknownConfiguration(id.to_string()))
}

/// Names of the scenario runs (also used by the report and the tests).
pub mod scenario {
    /// Time histories at the history speed (Figs. 4.18, 4.21, 4.25).
    pub fn history(id: &str) -> String {
        format!("history-{id}")
    }
    /// MPPT from a closed valve at a low speed (Fig. 4.16, R10).
    pub fn mppt_low(id: &str) -> String {
        format!("mpptlow-{id}")
    }
    /// HIL-like runs at 260 km/h, ideal track, initial perturbation (Figs. 5.19-5.24, R12).
    pub fn hil(id: &str) -> String {
        format!("hil-{id}")
    }
}

/// Configurations of the time-history comparison (Figs. 4.18/4.21/4.25).
pub const HISTORY_CONFIGS: &[&str] = &["passive", "mppt2", "skyhook_onoff", "full_active"];
/// Configurations of the HIL-like runs.
pub const HIL_CONFIGS: &[&str] = &[
    "mppt1_slow",
    "mppt2_slow",
    "skyhook_onoff_slow",
    "skyhook_continuous_slow",
    "skyhook_onoff",
];

fn is_mppt(c: &Configuration) -> bool {
    matches!(c.family, Family::Mppt1 | Family::Mppt2)
}

/// Every MPPT board starts from the command `v` [V].
fn with_initial_command(r: RunRequest, c: &Configuration, v: f64) -> RunRequest {
    if is_mppt(c) {
        let keys = r
            .vehicle
            .per_position("controller", "valve.initial_command");
        keys.iter().fold(r, |r, k| r.with(k, Value::from(v)))
    } else {
        r
    }
}

/// Checks that every FMU the configurations need on `vehicle` is there; names the first
/// missing one.
pub fn check_fmus(
    sources: &Sources,
    vehicle: VehicleModel,
    configs: &[&Configuration],
) -> Result<(), StudyError> {
    for name in required_fmus(vehicle, configs) {
        let p = sources.fmus.join(&name);
        if !p.is_file() {
            return Err(StudyError::MissingFmu {
                path: p,
                hint: "build the FMUs first: cargo run --release -p model-description --bin package-fmus (writes dist/), or pass --fmus DIR".into(),
            });
        }
    }
    Ok(())
}

/// Every configuration the study runs: the swept ones and those of the perturbation, c_v and
/// scenario runs.
pub fn configurations_used(
    settings: &StudySettings,
) -> Result<Vec<&'static Configuration>, StudyError> {
    let mut used: Vec<&'static Configuration> = Vec::new();
    for id in settings
        .configurations
        .iter()
        .copied()
        .chain(["passive", "full_active", "mppt1", "mppt2"])
        .chain(HISTORY_CONFIGS.iter().copied())
        .chain(HIL_CONFIGS.iter().copied())
    {
        let c = config_or_err(id)?;
        if !used.contains(&c) {
            used.push(c);
        }
    }
    Ok(used)
}

/// Runs the whole study (sweep, bisection, perturbation, c_v, scenarios).
pub fn run_study(
    settings: &StudySettings,
    opts: &StudyOptions<'_>,
) -> Result<StudyResults, StudyError> {
    run_study_checked(settings, opts, || Ok(()))
}

/// [`run_study`], calling `before_first_run` once every configuration's system is prepared
/// (FMUs loaded, connections checked) and every run of the first batch has its start values
/// checked against the models: a study that cannot run fails before the caller touches its
/// output folder.
pub fn run_study_checked(
    settings: &StudySettings,
    opts: &StudyOptions<'_>,
    before_first_run: impl FnOnce() -> Result<(), StudyError>,
) -> Result<StudyResults, StudyError> {
    let configs: Vec<&'static Configuration> = settings
        .configurations
        .iter()
        .map(|id| config_or_err(id))
        .collect::<Result<_, _>>()?;
    let vehicle = settings.vehicle;
    check_fmus(&opts.sources, vehicle, &configurations_used(settings)?)?;
    let s = settings;
    let first_seed = s.seeds.first().copied().unwrap_or(1);
    let mut ex = Executor {
        settings,
        opts,
        prepared: HashMap::new(),
        signals: Signals::of(vehicle),
        collected: Collected::default(),
    };

    // ---- main batch: sweep, perturbation, c_v, scenarios
    let mut planned = Vec::new();
    for c in &configs {
        for &v in &s.speeds_kmh {
            for &seed in &s.seeds {
                planned.push(Planned {
                    request: sweep_request("sweep-", c, v, seed, s),
                    keep: false,
                });
            }
        }
    }
    let passive = config_or_err("passive")?;
    let perturbation: Vec<RunRequest> = s
        .perturbation_speeds_kmh
        .iter()
        .map(|&v| {
            RunRequest::new(
                "perturbation-",
                vehicle,
                passive,
                v,
                None,
                s.perturbation_stop_s,
            )
            .with(
                &vehicle.initial_lateral(),
                Value::from(s.perturbation_lateral_m),
            )
        })
        .collect();
    let full = config_or_err("full_active")?;
    // Table 4-3 over every track seed: each gain's row is the largest over them, as a sweep
    // point is (a peak force of one 10 s record is a small sample of its extremes)
    let keys = vehicle.per_position("idf", "reference.damping");
    let cv: Vec<(f64, Vec<RunRequest>)> = s
        .cv_values_nspm
        .iter()
        .map(|&c_v| {
            let runs = s
                .seeds
                .iter()
                .map(|&seed| {
                    let r = RunRequest::new(
                        "cv-",
                        vehicle,
                        full,
                        s.cv_speed_kmh,
                        Some(seed),
                        s.cv_stop_s,
                    )
                    .named(&format!("cv-{:.0}_s{seed}", c_v / 1e3));
                    keys.iter().fold(r, |r, k| r.with(k, Value::from(c_v)))
                })
                .collect();
            (c_v, runs)
        })
        .collect();
    let mut scenarios: Vec<RunRequest> = Vec::new();
    for id in HISTORY_CONFIGS {
        let c = config_or_err(id)?;
        let r = RunRequest::new(
            "",
            vehicle,
            c,
            s.history_speed_kmh,
            Some(first_seed),
            s.scenario_stop_s,
        )
        .named(&scenario::history(id));
        // Fig. 4.18 starts the MPPT from the maximum command (fully open)
        scenarios.push(with_initial_command(r, c, 10.0));
    }
    for id in ["mppt1", "mppt2"] {
        let c = config_or_err(id)?;
        let r = RunRequest::new(
            "",
            vehicle,
            c,
            s.mppt_low_speed_kmh,
            Some(first_seed),
            s.scenario_stop_s,
        )
        .named(&scenario::mppt_low(id));
        scenarios.push(with_initial_command(r, c, 0.0));
    }
    for id in HIL_CONFIGS {
        // ideal track + initial perturbation: the final amplitude is then the hunting motion
        // alone (on the irregular track a stable bogie still moves 3-4 mm relative to the rails)
        let c = config_or_err(id)?;
        let r = RunRequest::new("", vehicle, c, s.hil_speed_kmh, None, s.scenario_stop_s)
            .named(&scenario::hil(id))
            .with(
                &vehicle.initial_lateral(),
                Value::from(s.perturbation_lateral_m),
            );
        scenarios.push(with_initial_command(r, c, s.hil_initial_command_v));
    }
    for r in perturbation
        .iter()
        .chain(cv.iter().flat_map(|(_, runs)| runs))
        .chain(&scenarios)
    {
        planned.push(Planned {
            request: r.clone(),
            keep: true,
        });
    }
    ex.check(&mut planned)?;
    before_first_run()?;
    ex.run_batch("main", planned)?;

    let limit = acceleration_limit(BOGIE_MASS_T);
    let mut results: Vec<ConfigResult> = configs
        .iter()
        .map(|c| {
            let sweep: Vec<SpeedPoint> = s
                .speeds_kmh
                .iter()
                .map(|&v| ex.speed_point(c, v, "sweep-"))
                .collect();
            let mut r = ConfigResult {
                id: c.id,
                label: c.label,
                seed_value: c.seed_value,
                reference: c.reference,
                sweep,
                bisection: Vec::new(),
                critical: None,
            };
            r.critical = Critical::from_curve(&r.curve(), limit);
            r
        })
        .collect();

    // ---- bisection rounds (all configurations of a round in one parallel batch)
    if let Some(tol) = s.bisection_tol_kmh {
        for round in 1.. {
            let mut todo: Vec<(usize, f64)> = Vec::new();
            for (i, r) in results.iter().enumerate() {
                if let Some(m) = r.critical.and_then(|k| k.midpoint(tol)) {
                    todo.push((i, m));
                }
            }
            if todo.is_empty() {
                break;
            }
            let prefix = format!("bisect{round}-");
            let mut planned = Vec::new();
            for &(i, v) in &todo {
                for &seed in &s.seeds {
                    planned.push(Planned {
                        request: sweep_request(&prefix, configs[i], v, seed, s),
                        keep: false,
                    });
                }
            }
            ex.run_batch(&format!("bisect-{round}"), planned)?;
            for (i, v) in todo {
                let p = ex.speed_point(configs[i], v, &prefix);
                let unstable = !matches!(p.rms(), Some(v) if v <= limit);
                let r = &mut results[i];
                r.critical = r.critical.map(|k| k.refine(v, unstable));
                r.bisection.push(p);
            }
        }
    }

    let perturbation = perturbation.iter().map(|r| ex.named(r, None)).collect();
    let cv = cv
        .iter()
        .map(|(c_v, runs)| ex.largest_over_seeds(runs, *c_v))
        .collect();
    let scenarios = scenarios.iter().map(|r| ex.named(r, None)).collect();
    let failures = ex
        .collected
        .metrics
        .iter()
        .filter_map(|(n, m)| m.as_ref().err().map(|e| (n.clone(), e.clone())))
        .collect();
    Ok(StudyResults {
        settings: s.clone(),
        limit_mps2: limit,
        configs: results,
        perturbation,
        cv,
        scenarios,
        failures,
        runs: ex.collected.runs,
        simulated_s: ex.collected.simulated_s,
        run_wall_s: ex.collected.run_wall_s,
        kept: std::mem::take(&mut ex.collected.kept),
        kept_tail: std::mem::take(&mut ex.collected.kept_tail),
    })
}

/// Default FMU folder: `dist/` next to the current folder's workspace, else `dist`.
pub fn default_fmu_dir() -> PathBuf {
    let ws = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../dist");
    if Path::new("dist").is_dir() || !ws.is_dir() {
        PathBuf::from("dist")
    } else {
        ws
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valve command stepping from 0 to 10 V, 1 kHz, 1 s.
    fn switching_command() -> SimOutput {
        let data = (0..1000)
            .flat_map(|k| [k as f64 * 1e-3, if k < 503 { 0.0 } else { 10.0 }])
            .collect();
        recorded(
            vec!["time [s]".into(), "controller.valve.command [V]".into()],
            data,
        )
    }

    /// The figures' samples are the record's own values at every n-th time: a step stays a
    /// step between 0 and 10 V, where the stored CSV's anti-aliasing low-pass rings.
    #[test]
    fn figures_draw_every_nth_sample_as_recorded() {
        let out = switching_command();
        let drawn = every_nth_row(&out, 10);
        assert_eq!(drawn.header, out.header);
        let times = drawn.column("time").unwrap();
        assert_eq!(times.len(), 100);
        assert_eq!((times[0], times[1], times[99]), (0.0, 10e-3, 990e-3));
        let command = drawn.column("controller.valve.command").unwrap();
        assert!(
            command.iter().all(|&v| v == 0.0 || v == 10.0),
            "{command:?}"
        );
        assert_eq!((command[50], command[51]), (0.0, 10.0));
        // what the low-pass would have drawn
        let filtered = decimate(&out, 10).unwrap();
        let ringing = filtered.column("controller.valve.command").unwrap();
        assert!(ringing.iter().any(|&v| !(0.0..=10.0).contains(&v)));
        // factor 1 (or 0): every row
        // the last 0.1 s as recorded, both ends included
        let tail = last_rows(&out, 0.1);
        let times: Vec<f64> = tail
            .data
            .chunks_exact(out.header.len())
            .map(|r| r[0])
            .collect();
        let all: Vec<f64> = out
            .data
            .chunks_exact(out.header.len())
            .map(|r| r[0])
            .collect();
        assert_eq!(times, all[all.len() - times.len()..]);
        assert!(
            (times[times.len() - 1] - times[0] - 0.1).abs() < 1e-9,
            "{times:?}"
        );
        assert_eq!(every_nth_row(&out, 1).data, out.data);
        assert_eq!(every_nth_row(&out, 0).data, out.data);
    }
}
