//! The project's benchmark: every speed figure and ratio, measured in one run on this machine,
//! with the load average beside each (speed is never asserted; tests do not time anything).
//!
//! 1. Each model alone, physics called directly, 1 ms communication steps: Bogie2Dof
//!    non-linear on the internal irregular track, the damper and actuator cases, the
//!    controller boards, RailVehicle non-linear.
//! 2. The coupled passive system (`systems/passive.json`: Bogie2Dof + two PassiveYawDamper
//!    FMUs from dist/, Gauss-Seidel, 1 ms) in our master, against the same physics stepped in
//!    the same order in plain Rust (no FMI); both must end in the same state to rounding
//!    (checked).
//!    The instructions per step of both loops, counted by callgrind (load-independent; needs
//!    valgrind): the benchmark runs itself under it.
//! 3. fmpy driving the same three FMUs in a Python loop, same order and step.
//! 4. A run set of 4 runs of that system on 2 worker threads against 1.
//! 5. The studies' wall time (`master study` on 2 cores), when `BENCH_STUDY` names the study
//!    options (scripts/bench.sh sets it).
//! 6. Results files of one full-rate 15 s study run (the coach with four passive dampers):
//!    size and read time of Parquet against CSV, and the CSV decimated to 100 Hz; where the
//!    Parquet file's bytes go (time, signals, constant columns, footer).
//!
//! `bash scripts/bench.sh` builds what it needs and runs this; it writes docs/BENCHMARKS.md.
//! By hand: `cargo bench -p tests --bench ratios` (needs dist/). `BENCH_ONLY=coupled,fmpy`
//! measures only the named sections (`models`, `coupled`, `instructions`, `fmpy`, `runset`,
//! `studies`, `results`) and
//! writes to target/BENCHMARKS.md unless `BENCH_OUT` is set.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benchmark code

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use fmu_bogie2dof::model::{Bogie, Inputs};
use fmu_bogie2dof::params::{Params, PsdLevel, TrackSource};
use fmu_bogie2dof::perf::ReferenceTrack;
use fmu_damper::perf::DamperCase;
use fmu_damper::semi_active::{SemiActiveDamper, SemiActiveInputs, SemiActiveParams};
use master::coupling::{RunOptions, SimOutput};
use master::runset::{execute, run_job, RunSet};
use master::system::{LoadedSystem, PreparedSystem};

/// Simulated time of the coupled runs [s].
const COUPLED_STOP_S: f64 = 10.0;
const STEP_S: f64 = 1e-3;
/// Runs of each coupled loop (the best counts; the rounds alternate the two loops).
const REPEATS: usize = 7;
/// Simulated time of fmpy's loop [s] (Python is slow; the figure is per simulated second).
const FMPY_STOP_S: f64 = 2.0;

fn repo() -> PathBuf {
    std::path::absolute(Path::new(env!("CARGO_MANIFEST_DIR")).join("..")).unwrap()
}

/// Whether section `name` is measured (`BENCH_ONLY` unset: every section).
fn wanted(name: &str) -> bool {
    std::env::var("BENCH_ONLY").map_or(true, |only| only.split(',').any(|s| s.trim() == name))
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// CPU time (user + system) of this process [s], from /proc/self/stat.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    rest.split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse::<f64>().ok())
        .sum::<f64>()
        / 100.0
}

struct Report {
    lines: Vec<String>,
}

impl Report {
    fn line(&mut self, text: String) {
        println!("{text}");
        self.lines.push(text);
    }
}

/// The passive system with its stop time replaced.
fn passive_system(stop_s: f64) -> LoadedSystem {
    let path = repo().join("systems/passive.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["stop_time"] = serde_json::json!(stop_s);
    LoadedSystem::from_json_str(&v.to_string(), &repo().join("systems"), "passive.json").unwrap()
}

/// The recorded variables of `systems/passive.json`, in its order (the direct run records the
/// same values).
const PASSIVE_RECORD: [&str; 7] = [
    "bogie.wheelset_front.lateral_displacement_relative",
    "bogie.wheelset_rear.lateral_displacement_relative",
    "bogie.wheelset_front.lateral_acceleration",
    "bogie.wheelset_rear.lateral_acceleration",
    "bogie.wheelset_front.guiding_force",
    "damper_left.damper.force",
    "damper_right.damper.force",
];

/// A coupled run: best wall time of the simulation loop per simulated second, and the recorded
/// rows of the last run after the start (time, then [`PASSIVE_RECORD`]).
struct Timed {
    per_sim_s: f64,
    rows: Vec<f64>,
}

/// Master: preparation (unpacking and loading the FMUs) is not timed. Returns the best wall
/// time per simulated second and the last run's output; its rows are taken outside (see
/// [`master_timed`]), so that callgrind's inclusive count of this function holds the runs
/// and no extraction of result columns.
#[inline(never)]
fn master_passive(stop_s: f64, repeats: usize) -> (f64, SimOutput) {
    let system = PreparedSystem::prepare(&passive_system(stop_s)).unwrap();
    let changes = system
        .changes(&std::collections::BTreeMap::new(), None, "bench")
        .unwrap();
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let started = Instant::now();
        let out = system.run(&changes, &RunOptions::default()).unwrap();
        best = best.min(started.elapsed().as_secs_f64());
        last = Some(out);
    }
    (best / stop_s, last.unwrap())
}

/// [`master_passive`] with the recorded rows of its last run after the start (time, then
/// [`PASSIVE_RECORD`]).
fn master_timed(stop_s: f64, repeats: usize) -> Timed {
    let (per_sim_s, out) = master_passive(stop_s, repeats);
    let time = out.column("time").unwrap();
    let columns: Vec<Vec<f64>> = PASSIVE_RECORD
        .iter()
        .map(|c| out.column(c).unwrap())
        .collect();
    let mut rows = Vec::with_capacity(time.len() * (1 + columns.len()));
    for k in 1..time.len() {
        rows.push(time[k]);
        rows.extend(columns.iter().map(|c| c[k]));
    }
    Timed { per_sim_s, rows }
}

/// The front wheelset's displacement in the last row.
fn front_displacement(rows: &[f64]) -> f64 {
    rows[rows.len() - PASSIVE_RECORD.len()]
}

/// The largest difference between the direct and the master's rows, relative to the largest
/// magnitude of its column.
fn largest_difference(direct: &[f64], master: &[f64]) -> f64 {
    assert_eq!(direct.len(), master.len(), "not as many recorded values");
    let width = 1 + PASSIVE_RECORD.len();
    (0..width)
        .map(|c| {
            let column = |rows: &[f64]| rows.iter().skip(c).step_by(width).copied().collect();
            let (d, m): (Vec<f64>, Vec<f64>) = (column(direct), column(master));
            let scale = d.iter().fold(0.0f64, |a, x| a.max(x.abs())).max(1e-300);
            d.iter()
                .zip(&m)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
                / scale
        })
        .fold(0.0, f64::max)
}

/// The same physics, parameters, order and step without FMI; records the same 7 values per
/// step as the system's record list: the bogie's outputs at the end of the step with the
/// dampers' new forces (as the master reads them after the dampers set them).
#[inline(never)]
fn direct_passive(stop_s: f64, repeats: usize) -> Timed {
    let n = (stop_s / STEP_S).round() as usize;
    let mut best = f64::INFINITY;
    let mut rec: Vec<f64> = Vec::with_capacity((n + 1) * 8);
    for _ in 0..repeats {
        rec.clear();
        let params = Params {
            speed_mps: 83.333_333_333_333_33,
            track: TrackSource::Internal {
                level: PsdLevel::Low,
                seed: 1,
            },
            initial_lateral_m: 0.0,
            initial_yaw_rad: 0.0,
            ..Params::default()
        };
        let started = Instant::now();
        let mut bogie = Bogie::new(params).unwrap();
        let mut left = SemiActiveDamper::new(SemiActiveParams::passive_reference()).unwrap();
        let mut right = SemiActiveDamper::new(SemiActiveParams::passive_reference()).unwrap();
        let mut inputs = Inputs::default();
        let mut out = bogie.outputs(&inputs).unwrap();
        for k in 0..n {
            let _t = k as f64 * STEP_S;
            out = bogie.step(STEP_S, &inputs).unwrap();
            let l = left
                .step(
                    STEP_S,
                    &SemiActiveInputs {
                        elongation_m: out.damper_left_elongation_m,
                        elongation_velocity_mps: out.damper_left_velocity_mps,
                        ..SemiActiveInputs::default()
                    },
                )
                .unwrap();
            let r = right
                .step(
                    STEP_S,
                    &SemiActiveInputs {
                        elongation_m: out.damper_right_elongation_m,
                        elongation_velocity_mps: out.damper_right_velocity_mps,
                        ..SemiActiveInputs::default()
                    },
                )
                .unwrap();
            inputs.damper_left_force_n = l.force_n;
            inputs.damper_right_force_n = r.force_n;
            let now = bogie.outputs(&inputs).unwrap();
            rec.extend_from_slice(&[
                now.time_s,
                now.wheelset_front_rel_track_m,
                now.wheelset_rear_rel_track_m,
                now.wheelset_front_acc_mps2,
                now.wheelset_rear_acc_mps2,
                now.guiding_force_front_n,
                l.force_n,
                r.force_n,
            ]);
        }
        best = best.min(started.elapsed().as_secs_f64());
        std::hint::black_box(&out);
    }
    Timed {
        per_sim_s: best / stop_s,
        rows: rec,
    }
}

fn python() -> Option<PathBuf> {
    let p = std::env::var_os("RAIL_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join(".venv/bin/python"));
    p.exists().then_some(p)
}

/// fmpy's loop over the passive system: wall per simulated second, or why not measured.
fn fmpy_passive() -> Result<f64, String> {
    let py = python().ok_or("no python with fmpy (set RAIL_PYTHON or create .venv)")?;
    let out = Command::new(&py)
        .arg(repo().join("tests/fmpy/bench_fmpy_system.py"))
        .arg(repo().join("systems/passive.json"))
        .arg(FMPY_STOP_S.to_string())
        .arg("2")
        .output()
        .map_err(|e| format!("{}: {e}", py.display()))?;
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    if !out.status.success() {
        return Err(format!(
            "bench_fmpy_system.py failed: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    text.lines()
        .find_map(|l| l.strip_prefix("fmpy_wall_per_sim_s "))
        .and_then(|x| x.trim().parse().ok())
        .ok_or_else(|| format!("unexpected output: {text}"))
}

/// A run set of 4 speeds of the passive system on `threads` workers: (wall [s], CPU [s]).
fn runset_wall(threads: usize) -> (f64, f64) {
    let path = repo().join("systems/passive.json");
    let mut base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    base["stop_time"] = serde_json::json!(COUPLED_STOP_S);
    let set = serde_json::json!({
        "system": base,
        "product": {"bogie.vehicle.speed": [69.4, 75.0, 80.6, 86.1]}
    });
    let (base, jobs) =
        RunSet::from_str_with_base(&set.to_string(), &repo().join("systems"), "bench").unwrap();
    let out = tempfile::tempdir().unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let started = Instant::now();
    let cpu0 = cpu_seconds();
    let system = PreparedSystem::prepare(&base).unwrap();
    let reports = execute(&jobs, out.path(), threads, false, |job| {
        run_job(&system, job, &cancel)
    })
    .unwrap();
    let wall = started.elapsed().as_secs_f64();
    assert!(reports.iter().all(|r| r.ok), "a run failed: {reports:?}");
    (wall, cpu_seconds() - cpu0)
}

/// Instructions per communication step of the coupled section's two loops, each counted by
/// callgrind on its own (`--toggle-collect`), and where the master's extra ones go.
struct StepInstructions {
    master: f64,
    direct: f64,
    /// The master's extra instructions per step by where they run: in the master's executable
    /// (the master crate: the loop's own physics is not in it); in the FMU binaries beyond the
    /// plain loop's code (the same physics: the FMI glue and the FMU shells); in the system
    /// libraries (libm, memory copies) beyond the plain loop's.
    master_side: f64,
    fmu_side: f64,
    system: f64,
    /// Calls into the FMUs' C API per step.
    fmi_calls: f64,
}

/// Self cost by where it runs ([`StepInstructions`]) in one callgrind profile.
#[derive(Default, Clone, Copy)]
struct Costs {
    total: f64,
    executable: f64,
    fmu_binaries: f64,
    system: f64,
    /// calls into functions named `fmi2...` (the FMUs' C API)
    fmi_calls: f64,
}

/// [`Costs`] from `callgrind_annotate --tree=caller`: each function's line ("*", self cost,
/// then the object that holds it) and its callers' lines above it ("<", with their calls).
/// Works on FMU binaries without a symbol table too (their functions are addresses; the
/// exported `fmi2...` entry points keep their names).
fn profile_costs(annotated: &str, executable: &Path) -> Costs {
    let mut costs = Costs::default();
    let exe = executable.to_string_lossy();
    let mut calls_in = 0.0;
    // "  5,737,449 ( 3.98%)  *  ./string/...S:__memcpy_avx_unaligned_erms [/usr/lib/...]"
    // "  1,224,000 ( 0.85%)  <  ???:<master::...>::do_step (12,000x) [/path/exe]"
    for line in annotated.lines() {
        let parsed = line.trim_start().split_once(' ').and_then(|(count, rest)| {
            let count = count.replace(',', "").parse::<f64>().ok()?;
            Some((count, rest.split_once(')')?.1.trim()))
        });
        let Some((count, located)) = parsed else {
            calls_in = 0.0;
            continue;
        };
        if located == "PROGRAM TOTALS" {
            costs.total = count;
            continue;
        }
        let (located, object) = match located.rsplit_once(" [") {
            Some((l, o)) => (l, o.trim_end_matches(']')),
            None => (located, ""),
        };
        if let Some(caller) = located.strip_prefix('<') {
            calls_in += caller
                .rsplit_once(" (")
                .and_then(|(_, n)| n.strip_suffix("x)"))
                .and_then(|n| n.replace(',', "").parse::<f64>().ok())
                .unwrap_or(0.0);
            continue;
        }
        let Some(own) = located.strip_prefix('*') else {
            continue;
        };
        let function = own.trim().split_once(':').map_or("", |(_, f)| f);
        if function.starts_with("fmi2") {
            costs.fmi_calls += calls_in;
        }
        calls_in = 0.0;
        if object == exe {
            costs.executable += count;
        } else if object.contains("/binaries/") {
            costs.fmu_binaries += count;
        } else {
            costs.system += count;
        }
    }
    costs
}

/// [`StepInstructions`]: this benchmark runs itself under callgrind with
/// `BENCH_COUPLED_ONCE_S` = 2 and 4 s, collecting only inside one loop at a time; the
/// difference between the two runs, over 2000 steps, is the cost per step without the
/// preparation (unpacking, loading, track synthesis).
fn instructions_per_step() -> Result<StepInstructions, String> {
    let found = Command::new("valgrind").arg("--version").output();
    if !found.is_ok_and(|o| o.status.success()) {
        return Err("valgrind not found (Debian: apt install valgrind)".into());
    }
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let steps = 2.0 / STEP_S;
    let mut per_step = Vec::new();
    for function in ["master_passive", "direct_passive"] {
        let mut profiles = Vec::new();
        for stop_s in [2, 4] {
            let file = dir.path().join(format!("callgrind.{function}.{stop_s}"));
            let run = Command::new("valgrind")
                .arg("--tool=callgrind")
                .arg(format!("--callgrind-out-file={}", file.display()))
                .arg(format!("--toggle-collect=ratios::{function}*"))
                .arg(&exe)
                .arg("--bench")
                .env("BENCH_COUPLED_ONCE_S", stop_s.to_string())
                .output()
                .map_err(|e| e.to_string())?;
            if !run.status.success() {
                return Err(format!(
                    "callgrind run of {stop_s} s failed: {}",
                    String::from_utf8_lossy(&run.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                ));
            }
            let annotated = Command::new("callgrind_annotate")
                .args(["--threshold=100", "--tree=caller"])
                .arg(&file)
                .output()
                .map_err(|e| e.to_string())?;
            profiles.push(profile_costs(
                &String::from_utf8_lossy(&annotated.stdout),
                &exe,
            ));
        }
        let (short, long) = (profiles[0], profiles[1]);
        let step = Costs {
            total: (long.total - short.total) / steps,
            executable: (long.executable - short.executable) / steps,
            fmu_binaries: (long.fmu_binaries - short.fmu_binaries) / steps,
            system: (long.system - short.system) / steps,
            fmi_calls: (long.fmi_calls - short.fmi_calls) / steps,
        };
        if step.total <= 0.0 {
            return Err(format!("no instructions counted inside ratios::{function}"));
        }
        per_step.push(step);
    }
    let (master, direct) = (per_step[0], per_step[1]);
    Ok(StepInstructions {
        master: master.total,
        direct: direct.total,
        master_side: master.executable,
        fmu_side: master.fmu_binaries - direct.executable,
        system: master.system - direct.system,
        fmi_calls: master.fmi_calls,
    })
}

/// `master study OPTIONS` into a temporary folder: (wall [s], its last line).
fn study_wall(options: &str) -> Result<(f64, String), String> {
    let master = repo().join("target/release/master");
    if !master.exists() {
        return Err(format!("{} not built", master.display()));
    }
    let out = tempfile::tempdir().map_err(|e| e.to_string())?;
    let started = Instant::now();
    let run = Command::new(&master)
        .arg("--quiet")
        .arg("study")
        .args(options.split_whitespace())
        .arg("--fmus")
        .arg(repo().join("dist"))
        .arg("--out")
        .arg(out.path())
        .output()
        .map_err(|e| e.to_string())?;
    let wall = started.elapsed().as_secs_f64();
    if !run.status.success() {
        return Err(String::from_utf8_lossy(&run.stderr).into_owned());
    }
    let text = String::from_utf8_lossy(&run.stdout);
    // the summary line without the temporary report path
    let last = text.lines().last().unwrap_or("");
    let last = last.split("; report:").next().unwrap_or(last);
    Ok((wall, last.to_string()))
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    // One run of each of the coupled section's two loops over this many simulated seconds,
    // for instruction counts (see docs/BENCHMARKS.md): nothing else is measured or written.
    if let Ok(stop) = std::env::var("BENCH_COUPLED_ONCE_S") {
        let stop: f64 = stop
            .parse()
            .expect("BENCH_COUPLED_ONCE_S: simulated seconds");
        let (direct, master) = (direct_passive(stop, 1), master_timed(stop, 1));
        println!(
            "final front wheelset displacement: direct {:e} m, master {:e} m; largest relative \
             difference of the recorded values {:.1e}",
            front_displacement(&direct.rows),
            front_displacement(&master.rows),
            largest_difference(&direct.rows, &master.rows)
        );
        return;
    }
    let dist = repo().join("dist");
    if !dist.join("Bogie2Dof.fmu").exists() || !dist.join("PassiveYawDamper.fmu").exists() {
        eprintln!("dist/ has no Bogie2Dof.fmu / PassiveYawDamper.fmu: run `bash scripts/bench.sh`");
        std::process::exit(1);
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut r = Report { lines: Vec::new() };
    r.line(format!(
        "machine: {cores} cores; load average (1/5/15 min) at the start: {}",
        load_average()
    ));
    r.line(String::new());
    if wanted("models") {
        r.line("## Each model alone (physics called directly, 1 ms steps, one core)".into());
        r.line(String::new());
        r.line("| model | real-time factor | load average |".into());
        r.line("|---|---|---|".into());
        let rtf = fmu_bogie2dof::perf::realtime_factor(ReferenceTrack::InternalIrregular, 10.0, 5)
            .unwrap();
        r.line(format!(
            "| Bogie2Dof non-linear, 320 km/h, internal irregular track (target >= 500) | {rtf:.0} x | {} |",
            load_average()
        ));
        for case in DamperCase::ALL {
            let ns = fmu_damper::perf::ns_per_step(case, 5000, 7).unwrap();
            r.line(format!(
                "| damper: {} | {:.0} x ({ns:.0} ns per step) | {} |",
                case.name(),
                1e6 / ns,
                load_average()
            ));
        }
        for case in fmu_controller::perf::ControllerCase::ALL {
            let ns = fmu_controller::perf::ns_per_step(case, 5000, 7).unwrap();
            r.line(format!(
                "| controller: {} | {:.0} x ({ns:.0} ns per step) | {} |",
                case.name(),
                1e6 / ns,
                load_average()
            ));
        }
        let vehicle = vehicle_rtf();
        r.line(format!(
            "| RailVehicle non-linear, 300 km/h, high-level irregular track, 4 Maxwell dampers | {vehicle:.0} x | {} |",
            load_average()
        ));
    }
    // wall per simulated second of our master, for the fmpy ratio
    let mut master_s = None;
    if wanted("coupled") {
        r.line(String::new());
        r.line(format!(
            "## Coupled passive system (Bogie2Dof + 2 PassiveYawDamper, Gauss-Seidel, 1 ms, {COUPLED_STOP_S} s simulated, best of {REPEATS})"
        ));
        r.line(String::new());
        let load = load_average();
        // in alternation, so that a change of the machine's load falls on both loops
        let (mut direct, mut master) = (
            direct_passive(COUPLED_STOP_S, 1),
            master_timed(COUPLED_STOP_S, 1),
        );
        let mut round_ratios = vec![master.per_sim_s / direct.per_sim_s];
        for _ in 1..REPEATS {
            let d = direct_passive(COUPLED_STOP_S, 1);
            let m = master_timed(COUPLED_STOP_S, 1);
            round_ratios.push(m.per_sim_s / d.per_sim_s);
            if d.per_sim_s < direct.per_sim_s {
                direct = d;
            }
            if m.per_sim_s < master.per_sim_s {
                master = m;
            }
        }
        round_ratios.sort_by(f64::total_cmp);
        let (t_direct, t_master) = (direct.per_sim_s, master.per_sim_s);
        let fin_master = front_displacement(&master.rows);
        // The FMUs' binaries are built against glibc 2.17, whose libm may round exp/pow in the
        // last bit differently from the build machine's: the two agree to rounding, not bit for
        // bit, and over 10 s the rounding grows to about 1e-6 of a column's largest value.
        let relative = largest_difference(&direct.rows, &master.rows);
        assert!(
            relative <= 1e-5,
            "direct and master recorded values differ by {relative:e} (relative to their \
             column): not the same computation"
        );
        r.line(format!(
            "- our master: {:.0} x real time ({:.2} ms per simulated second; target >= 300 x)",
            1.0 / t_master,
            t_master * 1e3
        ));
        r.line(format!(
            "- the same physics in plain Rust: {:.0} x real time ({:.2} ms per simulated second)",
            1.0 / t_direct,
            t_direct * 1e3
        ));
        r.line(format!(
            "- ratio master / direct Rust: {:.2} (target <= 1.1), best against best; the {REPEATS} \
             rounds (one run of each loop in turn) gave {:.2} to {:.2}, median {:.2}; both record \
             the same values (largest difference {relative:.1e} of its column's largest \
             magnitude; final front wheelset displacement {fin_master:.6e} m)",
            t_master / t_direct,
            round_ratios[0],
            round_ratios[round_ratios.len() - 1],
            round_ratios[round_ratios.len() / 2]
        ));
        r.line(format!(
            "- load average before / after: {load} / {}",
            load_average()
        ));
        master_s = Some(t_master);
    }
    if wanted("fmpy") {
        match fmpy_passive() {
            Ok(t_fmpy) => r.line(format!(
                "- fmpy Python loop: {:.1} x real time; ratio fmpy / master: {} (load {})",
                1.0 / t_fmpy,
                master_s.map_or("not measured".into(), |t| format!("{:.1}", t_fmpy / t)),
                load_average()
            )),
            Err(why) => r.line(format!("- fmpy loop: not measured ({why})")),
        }
    }
    if wanted("runset") {
        let (w1, c1) = runset_wall(1);
        let (w2, c2) = runset_wall(2);
        r.line(format!(
            "- run set of 4 runs of {COUPLED_STOP_S} s: --jobs 1 {w1:.2} s, --jobs 2 {w2:.2} s, speed-up {:.2} (cores used {:.2} / {:.2}; load {})",
            w1 / w2,
            c1 / w1,
            c2 / w2,
            load_average()
        ));
    }

    if wanted("instructions") {
        r.line(String::new());
        r.line(
            "## Instructions per step of the coupled passive system (callgrind, load-independent)"
                .into(),
        );
        r.line(String::new());
        match instructions_per_step() {
            Ok(n) => {
                r.line(format!(
                    "- our master: {:.2} k instructions per 1 ms step; the same physics in plain \
                     Rust: {:.2} k; ratio {:.3} (target <= 1.1)",
                    n.master / 1e3,
                    n.direct / 1e3,
                    n.master / n.direct
                ));
                r.line(format!(
                    "- where the {:.2} k extra instructions of a step go ({:.0} calls into the \
                     FMUs' C API per step): the master's executable (the master crate) {:.2} k; \
                     the FMU binaries beyond the same physics in the plain loop (the FMI glue \
                     and the FMU shells) {:.2} k; the system libraries (libm, memory copies) \
                     {:.2} k",
                    (n.master - n.direct) / 1e3,
                    n.fmi_calls,
                    n.master_side / 1e3,
                    n.fmu_side / 1e3,
                    n.system / 1e3
                ));
                r.line(format!(
                    "- 1.1 leaves {:.0} instructions per step for the {:.0} calls, both sides' \
                     checks included: about {:.0} per call",
                    0.1 * n.direct,
                    n.fmi_calls,
                    0.1 * n.direct / n.fmi_calls.max(1.0)
                ));
            }
            Err(why) => r.line(format!("- skipped: {why}")),
        }
    }

    if let (true, Ok(studies)) = (wanted("studies"), std::env::var("BENCH_STUDY")) {
        r.line(String::new());
        r.line("## Studies (the `master` binary, all cores)".into());
        r.line(String::new());
        for options in studies.split(';').filter(|s| !s.trim().is_empty()) {
            let load = load_average();
            match study_wall(options) {
                Ok((wall, last)) => r.line(format!(
                    "- `master study {}`: {wall:.1} s wall (load before {load}); {last}",
                    options.trim()
                )),
                Err(why) => r.line(format!(
                    "- `master study {}`: failed: {why}",
                    options.trim()
                )),
            }
        }
    }

    if wanted("results") {
        results_files(&mut r);
    }

    let mut md = String::from(
        "# Benchmarks\n\nWritten by `bash scripts/bench.sh` (tests/benches/ratios.rs); every figure \
         below comes from one run on one machine, with the load average beside it.\n\n\
         Instructions per communication step of the coupled passive system (load-independent, \
         section `instructions`): the benchmark runs itself under `valgrind --tool=callgrind` \
         with `BENCH_COUPLED_ONCE_S=2` and `=4`, which run each of the coupled section's two \
         loops once, collecting only inside `ratios::master_passive` or \
         `ratios::direct_passive` (`--toggle-collect`); the difference of the counts between \
         the two runs, divided by 2000 steps, is the cost of one step without preparation, in \
         total and per function.\n\n",
    );
    for l in &r.lines {
        let _ = writeln!(md, "{l}");
    }
    let path = std::env::var_os("BENCH_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("target/BENCHMARKS.md"));
    match std::fs::write(&path, md) {
        Ok(()) => println!("written to {}", path.display()),
        Err(e) => eprintln!("cannot write {}: {e}", path.display()),
    }
}

/// RailVehicle non-linear at 300 km/h on high-level track with four Maxwell dampers, 1 ms:
/// median real-time factor of 5 runs of 5 s from a vehicle that has run 2 s.
fn vehicle_rtf() -> f64 {
    use fmu_vehicle::calibration::{PASSIVE_MAXWELL_C_NS_PER_M, PASSIVE_MAXWELL_K_N_PER_M};
    use fmu_vehicle::sim::{run_closed_loop, LinearDamper};
    use fmu_vehicle::{ModelKind, Vehicle, VehicleParams};
    let damper = LinearDamper::Maxwell {
        k: PASSIVE_MAXWELL_K_N_PER_M,
        c: PASSIVE_MAXWELL_C_NS_PER_M,
    };
    let p = VehicleParams {
        speed_mps: 300.0 / 3.6,
        model: ModelKind::NonLinear,
        track: fmu_vehicle::TrackSource::Internal {
            level: fmu_vehicle::PsdLevel::High,
            seed: 1,
        },
        ..VehicleParams::default()
    };
    let mut warm = Vehicle::new(p).unwrap();
    run_closed_loop(&mut warm, damper, STEP_S, 2.0, &|_| 0.0, &mut |_| {}).unwrap();
    let mut f: Vec<f64> = (0..5)
        .map(|_| {
            let mut m = warm.clone();
            let started = Instant::now();
            run_closed_loop(&mut m, damper, STEP_S, 5.0, &|_| 0.0, &mut |_| {}).unwrap();
            std::hint::black_box(m.state()[0]);
            5.0 / started.elapsed().as_secs_f64()
        })
        .collect();
    f.sort_by(f64::total_cmp);
    f[2]
}

/// Size and read time of the results of one full-rate 15 s run of the coach study
/// (passive, 300 km/h, track seed 1) as Parquet and as CSV, and of the CSV decimated to
/// 100 Hz through the anti-aliasing filter; read as `master assess` reads them
/// ([`rail_study::analysis::assess::ResultsTable::load`]), best of 5.
fn results_files(r: &mut Report) {
    use master::decimation::decimate;
    use master::results::{write_results, ResultsFormat, RunContext};
    use rail_study::analysis::assess::ResultsTable;
    use rail_study::study::config::{RunRequest, Sources};
    use rail_study::study::configurations::configuration;
    use rail_study::study::VehicleModel;
    let sources = Sources {
        fmus: repo().join("dist"),
        systems: None,
    };
    let Some(passive) = configuration("passive") else {
        return r.line("- results files: no passive configuration".into());
    };
    let system = match sources.system(VehicleModel::Coach, passive) {
        Ok(s) => s,
        Err(e) => return r.line(format!("- results files: not measured ({e})")),
    };
    let prepared = PreparedSystem::prepare(&system).unwrap();
    let job = RunRequest::new("", VehicleModel::Coach, passive, 300.0, Some(1), 15.0)
        .job(&system)
        .unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let out = run_job(&prepared, &job, &cancel).unwrap();
    let dir = tempfile::tempdir().unwrap();
    // as a run set stores it: the run's name and parameters as constant columns
    let ctx = RunContext {
        run: Some("sweep-passive_v300_s1".into()),
        parameters: job.parameters.clone(),
        ..RunContext::default()
    };
    let files = [
        (
            "Parquet, full rate",
            "full.parquet",
            ResultsFormat::Parquet,
            1,
        ),
        ("CSV, full rate", "full.csv", ResultsFormat::Csv, 1),
        (
            "CSV, 100 Hz (anti-aliased)",
            "small.csv",
            ResultsFormat::Csv,
            10,
        ),
    ];
    r.line(String::new());
    r.line(format!(
        "## Results files of one 15 s run (coach, passive, 300 km/h: {} rows x {} columns at 1 kHz)",
        out.rows().count(),
        out.header.len()
    ));
    r.line(String::new());
    r.line("| file | size | read time (best of 5) | load average |".into());
    r.line("|---|---|---|---|".into());
    let mut sizes = Vec::new();
    for (what, name, format, factor) in files {
        let path = dir.path().join(name);
        write_results(&path, &decimate(&out, factor).unwrap(), format, &ctx).unwrap();
        let bytes = std::fs::metadata(&path).unwrap().len();
        let best = (0..5)
            .map(|_| {
                let started = Instant::now();
                let t = ResultsTable::load(&path).unwrap();
                std::hint::black_box(t.columns.len());
                started.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min);
        sizes.push((bytes, best));
        r.line(format!(
            "| {what} | {:.2} MB | {:.1} ms | {} |",
            bytes as f64 / 1e6,
            best * 1e3,
            load_average()
        ));
    }
    r.line(format!(
        "- full rate: Parquet / CSV size {:.2}, read time {:.2}; Parquet at the full rate / CSV at 100 Hz size {:.2}",
        sizes[0].0 as f64 / sizes[1].0 as f64,
        sizes[0].1 / sizes[1].1,
        sizes[0].0 as f64 / sizes[2].0 as f64
    ));
    parquet_columns(r, &dir.path().join("full.parquet"), &out.header, sizes[2].0);
}

/// Where the bytes of a full-rate Parquet results file go: the compressed size of each
/// column chunk (from the file's footer), grouped as the time, the recorded signals and the
/// constant columns (run name and parameters), against the CSV at 100 Hz (`csv_100hz_bytes`).
fn parquet_columns(r: &mut Report, path: &Path, header: &[String], csv_100hz_bytes: u64) {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    let reader = SerializedFileReader::new(std::fs::File::open(path).unwrap()).unwrap();
    let meta = reader.metadata();
    let rows = meta.file_metadata().num_rows() as f64;
    let mut time = 0i64;
    let mut signals: Vec<(String, i64)> = Vec::new();
    let mut constants = (0usize, 0i64);
    for g in meta.row_groups() {
        for c in g.columns() {
            let name = c.column_path().string();
            let bytes = c.compressed_size();
            if name == header[0] {
                time += bytes;
            } else if header.contains(&name) {
                match signals.iter_mut().find(|(n, _)| *n == name) {
                    Some(s) => s.1 += bytes,
                    None => signals.push((name, bytes)),
                }
            } else {
                constants.0 += 1;
                constants.1 += bytes;
            }
        }
    }
    let file = std::fs::metadata(path).unwrap().len() as i64;
    let signal_bytes: i64 = signals.iter().map(|s| s.1).sum();
    let mut per_value: Vec<f64> = signals.iter().map(|s| s.1 as f64 / rows).collect();
    per_value.sort_by(f64::total_cmp);
    let rest = file - time - signal_bytes - constants.1;
    r.line(String::new());
    r.line("Where the full-rate Parquet file's bytes go (compressed column chunks; float64, zstd level 3, byte-stream split):".into());
    r.line(String::new());
    r.line("| columns | count | bytes | bytes per row and column |".into());
    r.line("|---|---|---|---|".into());
    r.line(format!("| time | 1 | {time} | {:.2} |", time as f64 / rows));
    if let (Some(lo), Some(hi)) = (per_value.first(), per_value.last()) {
        r.line(format!(
            "| signals | {} | {signal_bytes} | {:.2} ({lo:.2} to {hi:.2}) |",
            signals.len(),
            signal_bytes as f64 / rows / signals.len() as f64
        ));
    }
    r.line(format!(
        "| run name and parameters (constant) | {} | {} | {:.3} |",
        constants.0,
        constants.1,
        constants.1 as f64 / rows / constants.0.max(1) as f64
    ));
    r.line(format!(
        "| footer and metadata (units, FMU variables, system) | | {rest} | |"
    ));
    r.line(format!(
        "- the CSV at 100 Hz is {:.2} bytes per full-rate row and column; the full-rate signals alone take {:.2} times the whole 100 Hz CSV",
        csv_100hz_bytes as f64 / rows / header.len() as f64,
        signal_bytes as f64 / csv_100hz_bytes as f64
    ));
}
