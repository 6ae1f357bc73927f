//! Our FMUs coupled in the master agree with fmpy running each of them alone on the inputs the
//! master recorded: the master runs a coupled system and records every connected input and
//! output; tests/fmpy/drive_with_fmpy.py (generic: system JSON + master CSV in, one line per
//! instance out) replays each instance in fmpy's simulate_fmu with those inputs applied exactly
//! as the master applied them (see the script's doc for the Jacobi / Gauss-Seidel timing) and
//! compares every recorded output to rounding (relative 1e-9).
//!
//! Needs RAIL_PYTHON (the venv's python with fmpy; scripts/test.sh sets it) and dist/ (built by
//! scripts/test.sh); the coupled Python FMU case also needs RAIL_FOREIGN_FMUS (see
//! foreign_fmus.rs for why it runs in a child process).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;

use master::coupling::RunOptions;
use master::system::LoadedSystem;
use tests::{rail_python, workspace_root};

const CHILD: &str = "RAIL_PYFMU_COUPLED_CHILD";

fn dist_fmu(name: &str) -> PathBuf {
    let p = workspace_root().join("dist").join(name);
    assert!(
        p.exists(),
        "{} is missing: scripts/test.sh packages the FMUs into dist/ first",
        p.display()
    );
    std::path::absolute(p).unwrap()
}

const MS_SDM: &str = r#"{
  "instances": [
    {"name": "sdm", "fmu": "SDM", "parameters": {"mass": 0.5, "coupling_stiffness": 200.0, "coupling_damping": 1.0, "ground_stiffness": 20.0, "ground_damping": 0.2}},
    {"name": "ms", "fmu": "MS", "parameters": {"mass": 1.0, "stiffness": 100.0, "damping": 0.5, "initial_position": 0.1}}
  ],
  "connections": [
    {"from": "ms.position", "to": "sdm.input_position"},
    {"from": "ms.velocity", "to": "sdm.input_velocity"},
    {"from": "sdm.coupling_force", "to": "ms.force"}
  ],
  "stop_time": 1.0, "step": 0.001, "algorithm": "ALG" EXTRA
}"#;

fn ms_sdm(alg: &str, extra: &str) -> String {
    MS_SDM
        .replace(
            "\"SDM\"",
            &format!("\"{}\"", dist_fmu("SpringDamperMass.fmu").display()),
        )
        .replace(
            "\"MS\"",
            &format!("\"{}\"", dist_fmu("MassSpring.fmu").display()),
        )
        .replace("ALG", alg)
        .replace("EXTRA", extra)
}

/// Runs `system` in the master, replays it with fmpy, checks every instance agrees; returns
/// the script's lines.
fn master_vs_fmpy(python: &Path, system: &str) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    let sys_path = dir.path().join("system.json");
    std::fs::write(&sys_path, system).unwrap();
    let sys = LoadedSystem::load(&sys_path).unwrap();
    let out = sys.run(&RunOptions::default()).unwrap();
    let csv = dir.path().join("results.csv");
    master::output::write_csv_atomic(&csv, &out.header, out.rows()).unwrap();
    let script = workspace_root().join("tests/fmpy/drive_with_fmpy.py");
    let res = Command::new(python)
        .arg(&script)
        .arg(&sys_path)
        .arg(&csv)
        .arg(dir.path().join("report.json"))
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", python.display()));
    let stdout = String::from_utf8_lossy(&res.stdout).to_string();
    let stderr = String::from_utf8_lossy(&res.stderr);
    eprintln!("{stdout}{stderr}");
    assert!(
        res.status.success(),
        "master and fmpy disagree (or the replay failed):\n{stdout}\n{stderr}"
    );
    let lines: Vec<String> = stdout
        .lines()
        .filter(|l| l.starts_with("instance "))
        .map(str::to_string)
        .collect();
    for inst in &sys.desc.instances {
        let line = lines
            .iter()
            .find(|l| l.starts_with(&format!("instance {}:", inst.name)))
            .unwrap_or_else(|| panic!("no result for instance {}:\n{stdout}", inst.name));
        assert!(line.ends_with(": ok"), "{line}");
        // it compared a full run of values
        let n: usize = line
            .split_whitespace()
            .nth(2)
            .and_then(|x| x.parse().ok())
            .unwrap();
        assert!(n >= 1000, "{line}");
    }
    lines
}

#[test]
fn gauss_seidel_in_feedthrough_order() {
    let Some(py) = rail_python() else { return };
    let lines = master_vs_fmpy(&py, &ms_sdm("gauss-seidel", ""));
    // sdm steps after ms, so it used ms's outputs of the same macro step
    assert!(
        lines
            .iter()
            .any(|l| l.contains("instance sdm:") && l.contains("input_position+1")),
        "{lines:?}"
    );
}

#[test]
fn jacobi() {
    let Some(py) = rail_python() else { return };
    master_vs_fmpy(&py, &ms_sdm("jacobi", ""));
}

#[test]
fn gauss_seidel_reversed_order_and_step_multiple() {
    let Some(py) = rail_python() else { return };
    let sys = ms_sdm("gauss-seidel", r#", "order": ["sdm", "ms"]"#).replace(
        r#""initial_position": 0.1}"#,
        r#""initial_position": 0.1}, "step_multiple": 2"#,
    );
    let lines = master_vs_fmpy(&py, &sys);
    assert!(
        lines
            .iter()
            .any(|l| l.contains("instance ms:") && l.contains("force+1")),
        "{lines:?}"
    );
}

/// The pythonfmu FMU (not our binary) coupled with our SpringDamperMass: each agrees with fmpy.
#[test]
fn python_fmu_coupled_with_ours() {
    let Some(_) = rail_python() else { return };
    let Some(dir) = std::env::var_os("RAIL_FOREIGN_FMUS").map(PathBuf::from) else {
        eprintln!(
            "RAIL_FOREIGN_FMUS not set: run scripts/test.sh (it builds the foreign FMUs first)"
        );
        return;
    };
    let env_file = dir.join("python_env.txt");
    let env = std::fs::read_to_string(&env_file).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (scripts/test.sh generates it with tests/fmpy/make_pythonfmu.py)",
            env_file.display()
        )
    });
    let mut cmd = Command::new(std::env::current_exe().unwrap());
    cmd.args([
        "--exact",
        "python_fmu_coupled_in_child_process",
        "--nocapture",
        "--test-threads=1",
    ])
    .env(CHILD, "1");
    for (k, v) in env.lines().filter_map(|l| l.split_once('=')) {
        match k {
            "LIBPYTHON" => cmd.env("LD_PRELOAD", v),
            "PYTHONHOME" => cmd.env("PYTHONHOME", v),
            _ => &mut cmd,
        };
    }
    let out = cmd.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stderr}");
    assert!(out.status.success(), "child failed:\n{stdout}\n{stderr}");
    assert!(
        stdout.contains("1 passed"),
        "the child ran no test:\n{stdout}"
    );
    assert!(stdout.contains("instance osc:"), "{stdout}");
}

/// The body of [`python_fmu_coupled_with_ours`]; does nothing unless started by it.
#[test]
fn python_fmu_coupled_in_child_process() {
    if std::env::var_os(CHILD).is_none() {
        eprintln!("runs only as the child process of python_fmu_coupled_with_ours (needs LD_PRELOAD of libpython)");
        return;
    }
    let py = rail_python().unwrap();
    let dir = PathBuf::from(std::env::var_os("RAIL_FOREIGN_FMUS").unwrap());
    let osc = std::path::absolute(dir.join("PyOscillator.fmu")).unwrap();
    let system = format!(
        r#"{{
  "instances": [
    {{"name": "osc", "fmu": "{}", "parameters": {{"stiffness": 60.0, "initial_position": 0.02}}}},
    {{"name": "sdm", "fmu": "{}", "parameters": {{"coupling_stiffness": 80.0, "coupling_damping": 0.5}}}}
  ],
  "connections": [
    {{"from": "osc.position", "to": "sdm.input_position"}},
    {{"from": "osc.velocity", "to": "sdm.input_velocity"}},
    {{"from": "sdm.coupling_force", "to": "osc.force"}}
  ],
  "stop_time": 1.0, "step": 0.001
}}"#,
        osc.display(),
        dist_fmu("SpringDamperMass.fmu").display()
    );
    let lines = master_vs_fmpy(&py, &system);
    for l in lines {
        println!("{l}");
    }
}
