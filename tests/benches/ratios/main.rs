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
//!    Peers: the same FMUs exported as one SSP (`master export-ssp`), run from the archive by
//!    our master and by two third-party C++ hosts, libcosim and Ecos (their Python packages
//!    call the C++ run-until loop, so no Python runs between steps).
//! 5. The studies' wall time (`master study` on 2 cores), when `BENCH_STUDY` names the study
//!    options (scripts/bench.sh sets it).
//! 6. Results files of one full-rate 15 s study run (the coach with four passive dampers):
//!    size and read time of Parquet against CSV, and the CSV decimated to 100 Hz; where the
//!    Parquet file's bytes go (time, signals, constant columns, footer).
//!
//! `bash scripts/bench.sh` builds what it needs and runs this; it writes docs/BENCHMARKS.md.
//! By hand: `cargo bench -p tests --bench ratios` (needs dist/). `BENCH_ONLY=coupled,fmpy`
//! measures only the named sections (`models`, `coupled`, `instructions`, `fmpy`, `runset`,
//! `peers`, `studies`, `results`) and writes to target/BENCHMARKS.md unless `BENCH_OUT` is set.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benchmark code

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use fmu_bogie2dof::perf::ReferenceTrack;
use fmu_damper::perf::DamperCase;

mod coupled;
mod instructions;
mod peers;
mod results_files;

use coupled::{direct_passive, front_displacement, largest_difference, master_timed, runset_wall};
use instructions::instructions_per_step;
use results_files::results_files;

/// Simulated time of the coupled runs [s].
pub(crate) const COUPLED_STOP_S: f64 = 10.0;
pub(crate) const STEP_S: f64 = 1e-3;
/// Runs of each coupled loop (the best counts; the rounds alternate the two loops).
pub(crate) const REPEATS: usize = 7;
/// Simulated time of fmpy's loop [s] (Python is slow; the figure is per simulated second).
pub(crate) const FMPY_STOP_S: f64 = 2.0;

pub(crate) fn repo() -> PathBuf {
    std::path::absolute(Path::new(env!("CARGO_MANIFEST_DIR")).join("..")).unwrap()
}

/// Whether section `name` is measured (`BENCH_ONLY` unset: every section).
fn wanted(name: &str) -> bool {
    std::env::var("BENCH_ONLY").map_or(true, |only| only.split(',').any(|s| s.trim() == name))
}

pub(crate) fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// CPU time (user + system, all threads) of this process [s]: the process CPU clock, to the
/// nanosecond (a run of a few ms would be lost in /proc/self/stat's 10 ms ticks).
pub(crate) fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for the call to write.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID) failed");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

pub(crate) struct Report {
    pub(crate) lines: Vec<String>,
}

impl Report {
    fn line(&mut self, text: String) {
        println!("{text}");
        self.lines.push(text);
    }
}

pub(crate) fn python() -> Option<PathBuf> {
    let p = std::env::var_os("RAIL_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join(".venv/bin/python"));
    p.exists().then_some(p)
}

/// Runs the repository's Python `script` (relative path) with the venv's Python and `args`:
/// its standard output, or why it did not run. Its temporary files (a peer host's unpacked
/// archives) go to a folder removed afterwards.
pub(crate) fn python_script(script: &str, args: &[&std::ffi::OsStr]) -> Result<String, String> {
    let py = python().ok_or("no Python with the hosts (set RAIL_PYTHON or create .venv)")?;
    let tmp = tempfile::tempdir().map_err(|e| e.to_string())?;
    let out = Command::new(&py)
        .env("TMPDIR", tmp.path())
        .arg(repo().join(script))
        .args(args)
        .output()
        .map_err(|e| format!("{}: {e}", py.display()))?;
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    if !out.status.success() {
        return Err(format!(
            "{script} failed: {text}{}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    Ok(text)
}

/// The number a script printed on its line `key value`.
pub(crate) fn reported(text: &str, key: &str) -> Result<f64, String> {
    text.lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(' '))
        .and_then(|x| x.trim().parse().ok())
        .ok_or_else(|| format!("no {key} in: {text}"))
}

/// fmpy's loop over the passive system: wall per simulated second, or why not measured.
fn fmpy_passive() -> Result<f64, String> {
    let system = repo().join("systems/passive.json");
    let stop = FMPY_STOP_S.to_string();
    let text = python_script(
        "tests/fmpy/bench_fmpy_system.py",
        &[system.as_os_str(), stop.as_ref(), "2".as_ref()],
    )?;
    reported(&text, "fmpy_wall_per_sim_s")
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
        let (direct, master) = (direct_passive(stop), master_timed(stop));
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
        let (mut direct, mut master) =
            (direct_passive(COUPLED_STOP_S), master_timed(COUPLED_STOP_S));
        let mut round_ratios = vec![master.per_sim_s / direct.per_sim_s];
        for _ in 1..REPEATS {
            let d = direct_passive(COUPLED_STOP_S);
            let m = master_timed(COUPLED_STOP_S);
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

    if wanted("peers") {
        r.line(String::new());
        r.line(format!(
            "## Peer hosts on the same SSP (the passive system exported by `master export-ssp`; Jacobi, 1 ms, {COUPLED_STOP_S} s simulated)"
        ));
        r.line(String::new());
        r.line(
            "libcosim and Ecos cannot set FMI 2.0 Enumeration parameters, so the bogie keeps \
             its defaults here (non-linear contact, ideal track) and starts from a 3 mm lateral \
             displacement at 300 km/h. Each host loads the archive untimed; the time is its own \
             run-until call (libcosim's `simulate_until`, Ecos's `step_until`; ours: the run of \
             the imported system, recording every output as `master run x.ssp` does), fastest \
             of 3 (ours: of 7). CPU is the process's user + system time over the call: a host \
             that steps the FMUs on worker threads uses more CPU than wall time."
                .into(),
        );
        r.line(String::new());
        let load = load_average();
        r.line(
            "| host | wall per simulated s | CPU per simulated s | wall / our master | CPU / our master | final front wheelset displacement |"
                .into(),
        );
        r.line("|---|---|---|---|---|---|".into());
        let runs = peers::peers();
        let ours = runs.iter().find_map(|(_, r)| r.as_ref().ok().copied());
        for (name, run) in &runs {
            match (run, ours) {
                (Ok(h), Some(o)) => r.line(format!(
                    "| {name} | {:.2} ms | {:.2} ms | {:.2} | {:.2} | {:.12e} m |",
                    h.wall_per_sim_s * 1e3,
                    h.cpu_per_sim_s * 1e3,
                    h.wall_per_sim_s / o.wall_per_sim_s,
                    h.cpu_per_sim_s / o.cpu_per_sim_s,
                    h.final_value
                )),
                (Err(why), _) => r.line(format!("| {name} | not measured: {why} | | | | |")),
                (Ok(_), None) => unreachable!("our master's run is measured first"),
            }
        }
        let finals: Vec<f64> = runs
            .iter()
            .filter_map(|(_, r)| r.as_ref().ok().map(|h| h.final_value))
            .collect();
        let spread = finals
            .iter()
            .fold(0.0f64, |a, x| a.max((x - finals[0]).abs()));
        r.line(format!(
            "- the hosts' final displacements differ by at most {spread:.1e} m; load average \
             before / after: {load} / {}",
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
        "# Benchmarks\n\nWritten by `bash scripts/bench.sh` (tests/benches/ratios/); every figure \
         below comes from one run on one machine, with the load average beside it.\n\n\
         Instructions per communication step of the coupled passive system (load-independent, \
         section `instructions`): the benchmark runs itself under `valgrind --tool=callgrind` \
         with `BENCH_COUPLED_ONCE_S=2` and `=4`, which run each of the coupled section's two \
         loops once, collecting only inside `ratios::coupled::master_passive` or \
         `ratios::coupled::direct_passive` (`--toggle-collect`); the difference of the counts between \
         the two runs, divided by 2000 steps, is the cost of one step without preparation, in \
         total and by where it runs.\n\n",
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
