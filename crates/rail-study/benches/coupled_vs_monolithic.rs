//! Ratios measured in one run (not a test; speed is never asserted):
//! * wall time per simulated second of MassSpring + SpringDamperMass coupled in the master
//!   (the FMUs from dist/, Gauss-Seidel, 1 ms) vs the same physics (crate fmu-examples, linked
//!   directly, no FMI) stepped in the same order in plain Rust;
//! * fmpy driving the same two FMUs in a Python loop (tests/fmpy/bench_fmpy_loop.py, same step
//!   and order) vs the master;
//! * a run set of 8 runs of that system on 2 worker threads vs 1 (the master's `sweep --jobs`).
//!
//! `cargo bench -p rail-study --bench coupled_vs_monolithic`; needs dist/ (scripts/test.sh or
//! `cargo run --release -p model-description --bin package-fmus`); the fmpy ratio needs the
//! venv (RAIL_PYTHON or .venv/bin/python). Prints the ratios and writes target/bench-ratios.txt.
//! All three simulations must end in the same state (checked), so they compute the same thing.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // benchmark code

mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use common::cpu_seconds;
use fmu_examples::{MassSpring, SpringDamperMass};
use master::coupling::RunOptions;
use master::runset::{execute, run_job, RunSet};
use master::system::LoadedSystem;
use master::system::PreparedSystem;
use model_description::{Diagnostics, FmuModel, InstanceContext};

const STOP: f64 = 10.0;
const STEP: f64 = 1e-3;
const REPEATS: usize = 5;
/// Long enough that each run set job is dominated by simulation, not by unpacking and writing.
const RUNSET_STOP: f64 = 60.0;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn system_json(dist: &Path, stop: f64) -> String {
    format!(
        r#"{{
  "instances": [
    {{"name": "ms", "fmu": "{}", "parameters": {{"mass": 1.0, "stiffness": 100.0, "damping": 0.5, "initial_position": 0.1}}}},
    {{"name": "sdm", "fmu": "{}", "parameters": {{"mass": 0.5, "coupling_stiffness": 200.0, "coupling_damping": 1.0, "ground_stiffness": 0.0, "ground_damping": 0.0}}}}
  ],
  "connections": [
    {{"from": "ms.position", "to": "sdm.input_position"}},
    {{"from": "ms.velocity", "to": "sdm.input_velocity"}},
    {{"from": "sdm.coupling_force", "to": "ms.force"}}
  ],
  "stop_time": {stop}, "step": {STEP}, "algorithm": "gauss-seidel"
}}"#,
        dist.join("MassSpring.fmu").display(),
        dist.join("SpringDamperMass.fmu").display()
    )
}

/// Master: best wall time of the simulation loop (initialisation included, unpacking and
/// loading the FMUs not) per simulated second, and the final (ms.position, sdm.position).
fn master_run(dist: &Path) -> (f64, (f64, f64)) {
    let sys = LoadedSystem::from_json_str(&system_json(dist, STOP), dist, "bench").unwrap();
    let mut best = f64::INFINITY;
    let mut last = (0.0, 0.0);
    for _ in 0..REPEATS {
        let out = sys.run(&RunOptions::default()).unwrap();
        best = best.min(out.summary.wall_time_s);
        last = (
            *out.column("ms.position").unwrap().last().unwrap(),
            *out.column("sdm.position").unwrap().last().unwrap(),
        );
    }
    (best / STOP, last)
}

/// The same physics, same Gauss-Seidel order and step, called directly; records the same 8
/// values per step as the master's default record.
fn direct_run() -> (f64, (f64, f64)) {
    let ctx = InstanceContext::default();
    let n = (STOP / STEP).round() as usize;
    let mut best = f64::INFINITY;
    let mut last = (0.0, 0.0);
    let mut rec: Vec<f64> = Vec::with_capacity((n + 1) * 9);
    for _ in 0..REPEATS {
        rec.clear();
        let mut diag = Diagnostics::default();
        let mut ms = MassSpring::instantiate(&ctx).unwrap();
        ms.mass_kg = 1.0;
        ms.stiffness_n_per_m = 100.0;
        ms.damping_ns_per_m = 0.5;
        ms.initial_position_m = 0.1;
        let mut sdm = SpringDamperMass::instantiate(&ctx).unwrap();
        sdm.mass_kg = 0.5;
        sdm.coupling_stiffness_n_per_m = 200.0;
        sdm.coupling_damping_ns_per_m = 1.0;
        sdm.ground_stiffness_n_per_m = 0.0;
        sdm.ground_damping_ns_per_m = 0.0;
        let started = Instant::now();
        ms.exit_initialization(&mut diag).unwrap();
        sdm.exit_initialization(&mut diag).unwrap();
        sdm.input_position_m = ms.position_m;
        sdm.input_velocity_mps = ms.velocity_mps;
        ms.force_n = sdm.coupling_force();
        for k in 0..n {
            let t = k as f64 * STEP;
            let t1 = if k + 1 == n {
                STOP
            } else {
                (k + 1) as f64 * STEP
            };
            ms.do_step(t, t1 - t, &mut diag).unwrap();
            sdm.input_position_m = ms.position_m;
            sdm.input_velocity_mps = ms.velocity_mps;
            sdm.do_step(t, t1 - t, &mut diag).unwrap();
            ms.force_n = sdm.coupling_force();
            rec.extend_from_slice(&[
                t1,
                ms.force_n,
                ms.position_m,
                ms.velocity_mps,
                sdm.input_position_m,
                sdm.input_velocity_mps,
                sdm.coupling_force(),
                sdm.position_m,
                sdm.velocity_mps,
            ]);
        }
        best = best.min(started.elapsed().as_secs_f64());
        last = (ms.position_m, sdm.position_m);
        std::hint::black_box(&rec);
    }
    (best / STOP, last)
}

fn python() -> Option<PathBuf> {
    let p = std::env::var_os("RAIL_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join(".venv/bin/python"));
    p.exists().then_some(p)
}

/// fmpy's loop: (wall per simulated second, final positions), or why not measured.
fn fmpy_run(dist: &Path) -> Result<(f64, (f64, f64)), String> {
    let py = python().ok_or("no python with fmpy (set RAIL_PYTHON or create .venv)")?;
    let out = std::process::Command::new(&py)
        .arg(repo().join("tests/fmpy/bench_fmpy_loop.py"))
        .arg(dist)
        .arg(STOP.to_string())
        .arg(STEP.to_string())
        .arg("3")
        .output()
        .map_err(|e| format!("{}: {e}", py.display()))?;
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    if !out.status.success() {
        return Err(format!(
            "bench_fmpy_loop.py failed: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let field = |key: &str| -> Vec<f64> {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .map(|r| {
                r.split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect()
            })
            .unwrap_or_default()
    };
    let wall = field("fmpy_wall_per_sim_s ");
    let fin = field("fmpy_final ");
    if wall.len() != 1 || fin.len() != 2 {
        return Err(format!("unexpected output: {text}"));
    }
    Ok((wall[0], (fin[0], fin[1])))
}

/// A run set of 8 runs (RUNSET_STOP s simulated each, stiffness varied) on `threads` workers: wall time.
fn runset_wall(dist: &Path, threads: usize) -> (f64, f64) {
    let base: serde_json::Value = serde_json::from_str(&system_json(dist, RUNSET_STOP)).unwrap();
    let set = serde_json::json!({
        "system": base,
        "product": {"ms.stiffness": [60.0, 70.0, 80.0, 90.0, 100.0, 110.0, 120.0, 130.0]}
    });
    let (base, jobs) = RunSet::from_str_with_base(&set.to_string(), dist, "bench-runset").unwrap();
    assert_eq!(jobs.len(), 8);
    let out = tempfile::tempdir().unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let started = Instant::now();
    let cpu0 = cpu_seconds(false);
    let system = PreparedSystem::prepare(&base).unwrap();
    let reports = execute(&jobs, out.path(), threads, false, |job| {
        run_job(&system, job, &cancel)
    })
    .unwrap();
    let wall = started.elapsed().as_secs_f64();
    let cpu = cpu_seconds(false) - cpu0;
    assert!(reports.iter().all(|r| r.ok), "a run failed: {reports:?}");
    (wall, cpu)
}

fn same(a: (f64, f64), b: (f64, f64)) -> bool {
    (a.0 - b.0).abs() <= 1e-12 * (1.0 + a.0.abs()) && (a.1 - b.1).abs() <= 1e-12 * (1.0 + a.1.abs())
}

fn main() {
    let dist = repo().join("dist");
    if !dist.join("MassSpring.fmu").exists() || !dist.join("SpringDamperMass.fmu").exists() {
        eprintln!("dist/ has no MassSpring.fmu / SpringDamperMass.fmu: run scripts/test.sh or package-fmus first");
        return;
    }
    let dist = std::path::absolute(&dist).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());

    let (t_direct, fin_direct) = direct_run();
    let (t_master, fin_master) = master_run(&dist);
    assert!(
        same(fin_direct, fin_master),
        "direct {fin_direct:?} vs master {fin_master:?}: not the same computation"
    );
    let fmpy = fmpy_run(&dist);
    if let Ok((_, fin)) = &fmpy {
        assert!(
            same(*fin, fin_master),
            "fmpy {fin:?} vs master {fin_master:?}: not the same computation"
        );
    }
    let (rs1, cpu1) = runset_wall(&dist, 1);
    let (rs2, cpu2) = runset_wall(&dist, 2);
    // other processes on the machine bias every number (the speed-up most): show the load
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();

    let mut lines = vec![
        format!(
            "coupled MassSpring + SpringDamperMass, Gauss-Seidel, step {STEP} s, {STOP} s simulated, best of {REPEATS}; {cores} cores"
        ),
        format!(
            "wall time per simulated second: direct Rust {:.3e} s, master (FMI) {:.3e} s",
            t_direct, t_master
        ),
        format!(
            "ratio master / direct Rust (cost of FMI + co-simulation master): {:.2}",
            t_master / t_direct
        ),
    ];
    match &fmpy {
        Ok((t_fmpy, _)) => {
            lines.push(format!(
                "wall time per simulated second: fmpy Python loop {t_fmpy:.3e} s"
            ));
            lines.push(format!(
                "ratio fmpy loop / master: {:.2}",
                t_fmpy / t_master
            ));
            lines.push(format!(
                "ratio fmpy loop / direct Rust: {:.1}",
                t_fmpy / t_direct
            ));
        }
        Err(why) => lines.push(format!("fmpy loop: not measured ({why})")),
    }
    lines.push(format!(
        "run set, 8 runs of {RUNSET_STOP} s: --jobs 1 {rs1:.3} s, --jobs 2 {rs2:.3} s, speed-up {:.2}",
        rs1 / rs2
    ));
    lines.push(format!(
        "run set CPU time / wall time (cores actually used): --jobs 1 {:.2}, --jobs 2 {:.2}",
        cpu1 / rs1,
        cpu2 / rs2
    ));
    lines.push(format!(
        "load average during the run (1/5/15 min): {}",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    ));
    for l in &lines {
        println!("{l}");
    }
    let path = repo().join("target/bench-ratios.txt");
    let _ = std::fs::create_dir_all(repo().join("target"));
    match std::fs::write(&path, lines.join("\n") + "\n") {
        Ok(()) => println!("written to {}", path.display()),
        Err(e) => eprintln!("cannot write {}: {e}", path.display()),
    }
}
