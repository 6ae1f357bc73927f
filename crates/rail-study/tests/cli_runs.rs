//! The generic subcommands `sweep` and `run` of the `master` binary on the example FMUs
//! `MassSpring` and `SpringDamperMass` from dist/ (built by scripts/test.sh before `cargo test`;
//! by hand: `cargo run --release -p model-description --bin package-fmus`).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::path::{Path, PathBuf};
use std::process::Command;

fn dist() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../dist")
}

/// `master --quiet run ARGS` in `dir`, which must succeed.
fn run_ok_in(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "run"])
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The two example FMUs coupled by position, velocity and force.
fn system_json(stop: f64) -> String {
    let d = dist();
    format!(
        r#"{{"instances": [
    {{"name": "sdm", "fmu": "{}", "parameters": {{"mass": 0.5, "coupling_stiffness": 200.0}}}},
    {{"name": "ms", "fmu": "{}", "parameters": {{"mass": 1.0, "initial_position": 0.1}}}}],
  "connections": [{{"from": "ms.position", "to": "sdm.input_position"}},
    {{"from": "ms.velocity", "to": "sdm.input_velocity"}},
    {{"from": "sdm.coupling_force", "to": "ms.force"}}],
  "stop_time": {stop}, "step": 0.001}}"#,
        d.join("SpringDamperMass.fmu").display(),
        d.join("MassSpring.fmu").display(),
    )
}

/// The times (first field) of a results CSV's rows after its header.
fn csv_times(csv: &str) -> Vec<f64> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect()
}

/// `dir/systems`, a copy of the shipped system descriptions (to be changed by a test).
fn copy_of_the_systems(dir: &Path) -> PathBuf {
    let systems = dir.join("systems");
    std::fs::create_dir_all(&systems).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../systems");
    for e in std::fs::read_dir(&shipped).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), systems.join(e.file_name())).unwrap();
    }
    systems
}

#[test]
fn sweep_runs_in_parallel_and_keeps_failures() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("system.json"), system_json(0.5)).unwrap();
    std::fs::write(
        dir.path().join("set.json"),
        r#"{"base": "system.json", "product": {"ms.stiffness": [50.0, 100.0, 200.0]},
            "runs": [{"name": "bad", "parameters": {"ms.initial_position": 1e308}}]}"#,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep"])
        .arg(dir.path().join("set.json"))
        .arg("-o")
        .arg(dir.path().join("out"))
        .args(["--jobs", "2"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stdout}\n{stderr}");
    let sweep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/sweep.json")).unwrap())
            .unwrap();
    let runs = sweep.as_array().unwrap();
    assert_eq!(runs.len(), 4);
    let mut finals = Vec::new();
    for r in &runs[..3] {
        assert_eq!(r["ok"], serde_json::json!(true), "{r}");
        let csv = std::fs::read_to_string(
            dir.path()
                .join("out")
                .join(r["name"].as_str().unwrap())
                .join("results.csv"),
        )
        .unwrap();
        assert_eq!(csv.lines().count(), 502);
        finals.push(csv.lines().last().unwrap().to_string());
    }
    assert!(finals[0] != finals[1] && finals[1] != finals[2]);
    // a run the FMU fails (a spring force that overflows): reported, the others kept, exit
    // code 1
    assert_eq!(runs[3]["ok"], serde_json::json!(false), "{}", runs[3]);
    assert!(
        runs[3]["error"]
            .as_str()
            .unwrap()
            .contains("'coupling_force' is -inf"),
        "{}",
        runs[3]
    );
    assert!(!dir.path().join("out/bad/results.csv").exists());
    assert_eq!(out.status.code(), Some(1));
    // a start value outside the model's declared range is refused before anything runs or
    // is written: the earlier set's folder stays as it was
    std::fs::write(
        dir.path().join("set.json"),
        r#"{"base": "system.json", "runs": [{"name": "light", "parameters": {"ms.mass": -1.0}}]}"#,
    )
    .unwrap();
    let before = std::fs::read(dir.path().join("out/sweep.json")).unwrap();
    let refused = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep"])
        .arg(dir.path().join("set.json"))
        .arg("-o")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("run 'light'") && stderr.contains("-1 kg is below its minimum 1e-9 kg"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(dir.path().join("out/sweep.json")).unwrap(),
        before
    );
    assert!(dir.path().join("out/run-000/results.csv").is_file());
    assert!(!dir.path().join("out/light").exists());
}

/// `master run` of a 2000 s system into `r.csv`, sent `signal` (a `kill` option) after
/// 800 ms: its output, and the folder it ran in.
fn interrupted_run(signal: &str) -> (std::process::Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    // long enough to be interrupted: 2000 s at 1 ms
    std::fs::write(dir.path().join("system.json"), system_json(2000.0)).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "run"])
        .arg(dir.path().join("system.json"))
        .arg("-o")
        .arg(dir.path().join("r.csv"))
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(800));
    let st = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    (child.wait_with_output().unwrap(), dir)
}

#[test]
fn ctrl_c_stops_cleanly_without_result_file() {
    let (out, dir) = interrupted_run("-INT");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("cancelled at t ="), "{stderr}");
    // both instances terminated through the state machine without complaint
    assert!(!stderr.contains("not allowed"), "{stderr}");
    assert!(!dir.path().join("r.csv").exists());
}

/// `master run SYSTEM.json` with `--stop --step --set --record`: the same results as the
/// description edited to say so, bit for bit; a change that does not fit is named as the
/// option's, without a line of the file, and writes nothing.
#[test]
fn run_changes_a_system_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("system.json"), system_json(0.5)).unwrap();
    let edited = system_json(0.2)
        .replace(
            "\"step\": 0.001",
            "\"step\": 0.002, \"record\": [\"ms.position\"]",
        )
        .replace(
            "\"coupling_stiffness\": 200.0",
            "\"coupling_stiffness\": 50.0",
        );
    assert_ne!(edited, system_json(0.2));
    std::fs::write(d.join("edited.json"), edited).unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_master"))
            .args(["--quiet", "run"])
            .args(args)
            .current_dir(d)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (code, stderr) = run(&["edited.json", "-o", "edited.csv"]);
    assert_eq!(code, Some(0), "{stderr}");
    let changes = [
        "--stop",
        "0.2",
        "--step",
        "0.002",
        "--set",
        "sdm.coupling_stiffness=50",
        "--record",
        "ms.position",
    ];
    let mut args = vec!["system.json", "-o", "changed.csv"];
    args.extend(changes);
    let (code, stderr) = run(&args);
    assert_eq!(code, Some(0), "{stderr}");
    let changed = std::fs::read_to_string(d.join("changed.csv")).unwrap();
    assert_eq!(changed.lines().next(), Some("time [s],ms.position [m]"));
    assert_eq!(changed.lines().count(), 102, "0.2 s at 2 ms and the header");
    assert_eq!(
        changed,
        std::fs::read_to_string(d.join("edited.csv")).unwrap()
    );
    // the start value made a difference
    let (code, stderr) = run(&[
        "system.json",
        "-o",
        "unset.csv",
        "--stop",
        "0.2",
        "--step",
        "0.002",
        "--record",
        "ms.position",
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_ne!(
        changed,
        std::fs::read_to_string(d.join("unset.csv")).unwrap()
    );
    // the metadata holds the description that was run
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("changed.meta.json")).unwrap())
            .unwrap();
    let text = meta.to_string();
    assert!(text.contains("\"coupling_stiffness\":50"), "{text}");
    assert!(text.contains("\"stop_time\":0.2"), "{text}");

    // --stop-time, as for an SSP, is the same option
    let (code, stderr) = run(&["system.json", "-o", "alias.csv", "--stop-time", "0.1"]);
    assert_eq!(code, Some(0), "{stderr}");
    let alias = std::fs::read_to_string(d.join("alias.csv")).unwrap();
    assert_eq!(alias.lines().count(), 102, "0.1 s at 1 ms and the header");
    // changes that do not fit: named as given, no output
    for (args, expected) in [
        (
            vec!["--set", "nobody.mass=1"],
            "system.json with --set: nobody.mass: no such instance (instances: sdm, ms)",
        ),
        (
            vec!["--set", "mass"],
            "mass: not of the form instance.variable=VALUE",
        ),
        (
            vec!["--set", "ms.mass=-1"],
            "system.json with --set: instances[1].parameters.mass: -1 kg is below its minimum",
        ),
        (
            vec!["--stop", "0.2", "--step", "0.003"],
            "system.json with --stop, --step: step: stop_time - start_time = 0.2 s is not an \
             integer multiple of step = 0.003 s",
        ),
        (
            // shorter than one step: no step at all, refused before the run
            vec!["--stop", "1e-12"],
            "system.json with --stop: step: stop_time - start_time = 1e-12 s is not an integer \
             multiple of step = 0.001 s",
        ),
        (
            vec!["--stop", "-1"],
            "system.json with --stop: stop_time: must be greater than start_time (0), got -1",
        ),
        (
            // greater than the start, but no time to end at
            vec!["--stop", "inf"],
            "system.json with --stop: stop_time: must be a finite number, got inf",
        ),
        (
            vec!["--record", "ms.nothing"],
            "system.json with --record: record[0]: unknown variable 'ms.nothing'",
        ),
    ] {
        let mut a = vec!["system.json", "-o", "bad.csv"];
        a.extend(args.iter().copied());
        let (code, stderr) = run(&a);
        assert_eq!(code, Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains(" line "), "{args:?}: {stderr}");
        assert!(!d.join("bad.csv").exists(), "{args:?}");
    }
    // a results name that says no format needs --format: without, nothing is run or written
    let (code, stderr) = run(&["system.json", "-o", "bad.out"]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains(
            "'bad.out' names no results format: name it .csv or .parquet, or give --format"
        ),
        "{stderr}"
    );
    assert!(!d.join("bad.out").exists() && !d.join("bad.meta.json").exists());
    let (code, stderr) = run(&["system.json", "-o", "named.out", "--format", "csv"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(d.join("named.out").is_file() && d.join("named.meta.json").is_file());
    // an FMU alone has no coupling to choose
    let fmu = dist().join("MassSpring.fmu");
    let (code, stderr) = run(&[
        fmu.to_str().unwrap(),
        "-o",
        "bad.csv",
        "--algorithm",
        "jacobi",
    ]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("--algorithm: an FMU run alone has no coupling"),
        "{stderr}"
    );
    // nor a start value without '='
    let (code, stderr) = run(&[fmu.to_str().unwrap(), "-o", "bad.csv", "--set", "mass"]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("--set: 'mass' is not of the form NAME=VALUE"),
        "{stderr}"
    );
    assert!(!d.join("bad.csv").exists());
}

/// `master inspect` reads the binaries without loading them: platform, format, architecture
/// and the newest glibc a Linux binary needs against the portable baseline.
#[test]
fn inspect_reports_platforms_and_the_glibc_a_binary_needs() {
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["inspect", "--no-load"])
        .arg(dist().join("MassSpring.fmu"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(
            "binaries/linux64/MassSpring.so: linux64, ELF (Linux) x86-64, needs glibc >= 2."
        ),
        "{text}"
    );
    // the packaged binaries meet the baseline: no warning
    assert!(!text.contains("warning:"), "{text}");
    assert!(
        text.contains("default experiment: start 0 s, stop 5 s, step 0.001 s"),
        "{text}"
    );
    // each variable's declared range beside its start value
    let mass = text.lines().find(|l| l.starts_with("mass ")).unwrap();
    assert!(mass.contains(" 1e-9..- "), "{mass}");
}

#[test]
fn a_sweep_does_not_write_its_report_over_its_own_run_set() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("system.json"), system_json(0.1)).unwrap();
    let set = r#"{"base": "system.json", "product": {"ms.stiffness": [50.0, 100.0]}}"#;
    std::fs::write(dir.path().join("sweep.json"), set).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .current_dir(dir.path())
        .args(["--quiet", "sweep", "sweep.json", "-o", "."])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("same file as the input"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("sweep.json")).unwrap(),
        set
    );
    assert!(!dir.path().join("run-000").exists());
}

/// `master study` checks its system descriptions before it touches the output folder, holds
/// the folder while it runs, and an interrupted study leaves no earlier result looking
/// current (the user's own files stay).
#[test]
fn a_study_checks_its_systems_first_and_holds_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // an earlier study: its report beside its numbers
    std::fs::write(out.join("REPORT.md"), "the earlier report").unwrap();
    std::fs::write(out.join("study.json"), r#"{"settings": {}, "configs": []}"#).unwrap();
    std::fs::write(out.join("notes.txt"), "the user's").unwrap();
    let systems = copy_of_the_systems(dir.path());
    let mppt2 = std::fs::read_to_string(systems.join("mppt2.json")).unwrap();
    let study = |extra: &[&str]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_master"));
        cmd.args(["--quiet", "study", "--quick", "--fmus"])
            .arg(dist())
            .arg("--out")
            .arg(&out)
            .args(extra)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        cmd
    };
    let bogie_with_systems = [
        "--vehicle",
        "bogie2dof",
        "--systems",
        systems.to_str().unwrap(),
    ];
    // a description that does not parse, one whose bogie instance has another name than the
    // study's start values use, one that is missing
    for (text, expected) in [
        ("{ not json".to_string(), "mppt2.json: line 1"),
        (
            mppt2
                .replace("\"bogie\"", "\"train\"")
                .replace("\"bogie.", "\"train."),
            "unknown instance 'bogie'",
        ),
    ] {
        std::fs::write(systems.join("mppt2.json"), text).unwrap();
        let r = study(&bogie_with_systems).output().unwrap();
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
        assert_eq!(
            std::fs::read_to_string(out.join("REPORT.md")).unwrap(),
            "the earlier report"
        );
        assert!(!out.join("runs").exists(), "{stderr}");
    }
    std::fs::remove_file(systems.join("mppt2.json")).unwrap();
    let r = study(&bogie_with_systems).output().unwrap();
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("mppt2.json"));
    assert!(out.join("REPORT.md").exists());

    // the coach's study runs long enough to be met by a second one and interrupted
    let first = study(&[]).spawn().unwrap();
    let started = std::time::Instant::now();
    while !out.join("runs/main").exists() {
        assert!(
            started.elapsed().as_secs() < 120,
            "the study did not start its runs"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let second = study(&[]).output().unwrap();
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("is writing into"), "{stderr}");
    let st = Command::new("kill")
        .args(["-INT", &first.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let r = first.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(130), "{stderr}");
    assert!(!out.join("REPORT.md").exists(), "{stderr}");
    assert!(!out.join("study.json").exists(), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "the user's"
    );
}

/// Ctrl-C during a large sweep: no further run starts, so it ends at once; sweep.json lists
/// every run (the ones not started without a folder), the message is one short line, and
/// `--resume` runs the others.
#[test]
fn an_interrupted_sweep_stops_at_once_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("system.json"), system_json(2.0)).unwrap();
    let stiffness: Vec<String> = (0..2000).map(|i| format!("{}", 100.0 + i as f64)).collect();
    std::fs::write(
        dir.path().join("set.json"),
        format!(
            r#"{{"base": "system.json", "product": {{"ms.stiffness": [{}]}}}}"#,
            stiffness.join(",")
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let sweep = |resume: bool| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_master"));
        cmd.args(["--quiet", "sweep"])
            .arg(dir.path().join("set.json"))
            .arg("-o")
            .arg(&out)
            .args(["--jobs", "2", "--format", "csv"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        if resume {
            cmd.arg("--resume");
        }
        cmd
    };
    let child = sweep(false).spawn().unwrap();
    let started = std::time::Instant::now();
    while !out.join("run-0000/summary.json").exists() {
        assert!(started.elapsed().as_secs() < 120, "no run finished");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let r = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(130), "{stderr}");
    let last = stderr.lines().last().unwrap_or("");
    assert!(
        last.starts_with("error: interrupted: ")
            && last.contains("not started")
            && last.len() < 200,
        "{stderr}"
    );
    let reports: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(reports.len(), 2000);
    let not_started: Vec<&str> = reports
        .iter()
        .filter(|r| {
            r["error"]
                == serde_json::json!("not run: the run set was interrupted before this run started")
        })
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    // a 2 s run takes about 4 ms: far from all had started
    assert!(
        not_started.len() > 1000,
        "{} not started",
        not_started.len()
    );
    assert!(not_started.iter().all(|n| !out.join(n).exists()));
    let r = sweep(true).output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let reports: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert!(reports.iter().all(|r| r["ok"] == serde_json::json!(true)));
    assert!(not_started
        .iter()
        .all(|n| out.join(n).join("results.csv").is_file()));
}

/// A run without -o writes results.csv (small results) and removes a results.parquet that an
/// earlier run of the master wrote there (it would read as this run's), but never a file of
/// that name without the master's metadata: the user's own.
#[test]
fn a_run_without_output_removes_only_the_masters_own_other_default_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("system.json"), system_json(0.1)).unwrap();
    let run = |args: &[&str]| run_ok_in(d, &[&["system.json"][..], args].concat());
    std::fs::write(d.join("results.parquet"), "the user's own").unwrap();
    run(&[]);
    assert!(d.join("results.csv").is_file() && d.join("results.meta.json").is_file());
    assert_eq!(
        std::fs::read_to_string(d.join("results.parquet")).unwrap(),
        "the user's own"
    );
    std::fs::remove_file(d.join("results.parquet")).unwrap();
    run(&["--format", "parquet"]);
    assert!(d.join("results.parquet").is_file());
    // the CSV of the first run is the master's: removed with its metadata
    assert!(!d.join("results.csv").exists() && !d.join("results.meta.json").exists());
    run(&[]);
    assert!(d.join("results.csv").is_file() && !d.join("results.parquet").exists());
}

/// The description in a run's metadata names its FMUs by absolute paths: saved anywhere, it
/// runs again and gives the same results (a relative path was relative to the original file).
#[test]
fn the_description_in_the_metadata_runs_again_from_another_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("fmus")).unwrap();
    for f in ["SpringDamperMass.fmu", "MassSpring.fmu"] {
        std::fs::copy(dist().join(f), d.join("fmus").join(f)).unwrap();
    }
    let relative = system_json(0.1).replace(&dist().join("").display().to_string(), "fmus/");
    assert!(relative.contains("\"fmus/MassSpring.fmu\""), "{relative}");
    std::fs::write(d.join("system.json"), relative).unwrap();
    let run = |dir: &Path, system: &str| {
        run_ok_in(dir, &[system, "-o", "r.csv"]);
        std::fs::read_to_string(dir.join("r.csv")).unwrap()
    };
    let first = run(d, "system.json");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("r.meta.json")).unwrap()).unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    std::fs::write(
        elsewhere.path().join("again.json"),
        meta["system"].to_string(),
    )
    .unwrap();
    assert_eq!(run(elsewhere.path(), "again.json"), first);
}

/// SIGTERM (a job scheduler's stop) ends a run as Ctrl-C does: at the next communication
/// point, without a results file.
#[test]
fn sigterm_stops_cleanly_without_result_file() {
    let (out, dir) = interrupted_run("-TERM");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("cancelled at t ="), "{stderr}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["system.json"], "{left:?}");
}

/// Every output's folder is checked before the run, and the results and the summary are
/// both written before either replaces an earlier file: a --summary that cannot be written
/// leaves the earlier results as they were.
#[test]
fn a_run_whose_outputs_cannot_all_be_written_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("system.json"), system_json(0.1)).unwrap();
    run_ok_in(d, &["system.json", "-o", "r.csv"]);
    let before = |name: &str| std::fs::read(d.join(name)).unwrap();
    let (csv, meta) = (before("r.csv"), before("r.meta.json"));
    let refused = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_master"))
            .args(["--quiet", "run", "system.json", "--set", "ms.mass=2"])
            .args(args)
            .current_dir(d)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    for args in [
        &["-o", "r.csv", "--summary", "nodir/s.json"][..],
        &["-o", "nodir/r.csv"][..],
    ] {
        let e = refused(args);
        assert!(e.contains("the folder 'nodir' does not exist"), "{e}");
    }
    // a summary path that exists as a folder: refused before the run too
    std::fs::create_dir(d.join("s.json")).unwrap();
    let e = refused(&["-o", "r.csv", "--summary", "s.json"]);
    assert!(e.contains("s.json"), "{e}");
    // a summary in a folder that takes no new file (/proc, not even for root): found before
    // the run by the probe file, and the earlier results stay
    let e = refused(&["-o", "r.csv", "--summary", "/proc/self/s.json"]);
    assert!(
        e.contains("cannot write into the folder '/proc/self' (for '/proc/self/s.json')"),
        "{e}"
    );
    assert_eq!(before("r.csv"), csv);
    assert_eq!(before("r.meta.json"), meta);
    let mut names: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["r.csv", "r.meta.json", "s.json", "system.json"]);
}

/// Under `nohup` (SIGHUP ignored) a hang-up does not stop a run: the handler that takes
/// Ctrl-C and SIGTERM leaves SIGHUP as it found it.
#[test]
fn a_hang_up_under_nohup_does_not_stop_a_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("system.json"), system_json(2000.0)).unwrap();
    let mut child = Command::new("nohup")
        .arg(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "run"])
        .arg(dir.path().join("system.json"))
        .arg("-o")
        .arg(dir.path().join("r.csv"))
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(800));
    let pid = child.id().to_string();
    let signal = |name: &str| {
        let st = Command::new("kill").args([name, &pid]).status().unwrap();
        assert!(st.success());
    };
    signal("-HUP");
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the run ended on SIGHUP"
    );
    signal("-INT");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("cancelled at t ="), "{stderr}");
}

/// A run that fails midway (a bogie without secondary suspension derails at 150 m/s) writes
/// its history up to the failure beside the results' name (`r.history.csv`), with the failure
/// in its metadata, and says where: neither an earlier run's results nor the truncated history
/// stay under the results' name.
#[test]
fn a_failed_run_writes_its_history_up_to_the_failure() {
    let dir = tempfile::tempdir().unwrap();
    let system = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../systems/passive.json");
    let out = dir.path().join("r.csv");
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_master"))
            .args(["--quiet", "run"])
            .arg(&system)
            .arg("-o")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap()
    };
    let ok = run(&["--stop", "0.1"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let failed = run(&[
        "--stop",
        "2",
        "--set",
        "bogie.vehicle.speed=150",
        "--set",
        "bogie.suspension.lateral_stiffness=0",
        "--set",
        "bogie.suspension.longitudinal_stiffness=0",
    ]);
    let stderr = String::from_utf8_lossy(&failed.stderr);
    assert_eq!(failed.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("derailment"), "{stderr}");
    // the history beside the results' name; the earlier run's results are gone (they would
    // read as this run's), and so is their metadata
    let history = dir.path().join("r.history.csv");
    assert!(
        stderr.contains(&format!("is in {}", history.display())),
        "{stderr}"
    );
    assert!(!out.exists() && !dir.path().join("r.meta.json").exists());
    let csv = std::fs::read_to_string(&history).unwrap();
    let last = *csv_times(&csv).last().unwrap();
    assert!(last > 0.1 && last < 2.0, "last row at {last} s");
    let meta: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("r.history.meta.json")).unwrap(),
    )
    .unwrap();
    let failure = &meta["summary"]["failed"];
    assert_eq!(failure["time_s"].as_f64(), Some(last), "{meta}");
    assert!(
        failure["error"].as_str().unwrap().contains("derailment"),
        "{failure}"
    );
    assert!(stderr.contains(&format!("up to t = {last} s")), "{stderr}");
    // a later complete run removes the history (it would read as this run's)
    let ok = run(&["--stop", "0.1"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    assert!(out.is_file() && !history.exists());
    assert!(!dir.path().join("r.history.meta.json").exists());
    // a results name without an extension: the history takes the format's, and a file of the
    // user's under the results' name stays
    let plain = dir.path().join("plain");
    std::fs::write(&plain, "the user's").unwrap();
    let failed = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "run"])
        .arg(&system)
        .arg("-o")
        .arg(&plain)
        .args([
            "--format",
            "csv",
            "--stop",
            "2",
            "--set",
            "bogie.vehicle.speed=150",
        ])
        .args(["--set", "bogie.suspension.lateral_stiffness=0"])
        .args(["--set", "bogie.suspension.longitudinal_stiffness=0"])
        .output()
        .unwrap();
    assert_eq!(failed.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&plain).unwrap(), "the user's");
    assert!(dir.path().join("plain.history.csv").is_file());
    assert!(dir.path().join("plain.history.meta.json").is_file());
    assert!(!dir.path().join("plain.meta.json").exists());
}

/// A sweep's run that fails midway (the derailing bogie above) keeps its history up to the
/// failure in its own folder, says where, and the set's other runs complete.
#[test]
fn a_sweeps_failed_run_keeps_its_history_in_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let system = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../systems/passive.json");
    std::fs::write(
        dir.path().join("set.json"),
        format!(
            r#"{{"base": "{}", "runs": [
  {{"name": "stable", "parameters": {{}}}},
  {{"name": "derails", "parameters": {{"bogie.vehicle.speed": 150,
    "bogie.suspension.lateral_stiffness": 0, "bogie.suspension.longitudinal_stiffness": 0}}}}]}}"#,
            system.display()
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["sweep", "set.json", "-o", "out", "--format", "csv"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let history = Path::new("out").join("derails").join("history.csv");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("derails: FAILED:") && l.contains("derailment")),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!(
            "(its history up to the failure is in {})",
            history.display()
        )),
        "{stdout}"
    );
    let folder = dir.path().join("out");
    assert!(folder.join("stable/results.csv").is_file());
    assert!(!folder.join("derails/results.csv").exists());
    let csv = std::fs::read_to_string(dir.path().join(&history)).unwrap();
    let last = *csv_times(&csv).last().unwrap();
    assert!(last > 0.1 && last < 2.0, "last row at {last} s");
    let meta: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(folder.join("derails/history.meta.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(meta["summary"]["failed"]["time_s"].as_f64(), Some(last));
    assert_eq!(meta["run"], "derails");
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(folder.join("derails/summary.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(report["ok"], false);
    assert!(
        report["error"].as_str().unwrap().contains("derailment"),
        "{report}"
    );
    // relative to the sweep's folder, where it reads from wherever the sweep ran
    assert_eq!(report["history"].as_str(), Some("derails/history.csv"));
    assert!(folder.join(report["history"].as_str().unwrap()).is_file());
}

/// A sweep whose output folder is a file names it, and leaves the file as it was.
#[test]
fn a_sweep_into_a_file_names_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("system.json"), system_json(0.01)).unwrap();
    std::fs::write(
        dir.path().join("set.json"),
        r#"{"base": "system.json", "runs": [{"name": "a", "parameters": {}}]}"#,
    )
    .unwrap();
    std::fs::write(dir.path().join("afile"), b"x").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep", "set.json", "-o", "afile"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("'afile' is a file, not a folder"), "{e}");
    assert_eq!(std::fs::read(dir.path().join("afile")).unwrap(), b"x");
    // no runs at a time is refused too, before the folder is made
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep", "set.json", "-o", "out", "--jobs", "0"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("invalid option --jobs = 0"), "{e}");
    assert!(!dir.path().join("out").exists());
}

/// An Enumeration parameter given by item name in one run and by number in another is refused
/// before anything runs (its Parquet column mixed 'high' and '0' as texts).
#[test]
fn an_enumeration_given_both_ways_in_a_set_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let system = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../systems/passive.json");
    std::fs::write(
        dir.path().join("set.json"),
        format!(
            r#"{{"base": "{}", "product": {{"bogie.track.level": ["high", 0]}}}}"#,
            system.display()
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args([
            "--quiet", "sweep", "set.json", "-o", "out", "--format", "parquet",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("bogie.track.level") && e.contains("give it one way in every run"),
        "{e}"
    );
    assert!(!dir.path().join("out").join("sweep.json").exists());
}

/// A run whose FMU file was replaced after its set loaded the FMU fails, naming the file: its
/// report would otherwise record the new file's digest for a run of the old model, and a
/// resumed set would keep it.
#[test]
fn a_run_whose_fmu_changed_since_its_set_loaded_it_fails() {
    use master::runset::{run_job, RunSet};
    use master::system::{LoadedSystem, PreparedSystem};
    let dir = tempfile::tempdir().unwrap();
    for f in ["MassSpring.fmu", "SpringDamperMass.fmu"] {
        std::fs::copy(dist().join(f), dir.path().join(f)).unwrap();
    }
    let text = system_json(0.01).replace(
        &dist().display().to_string(),
        &dir.path().display().to_string(),
    );
    let sys = LoadedSystem::from_json_str(&text, dir.path(), "system.json").unwrap();
    let prepared = PreparedSystem::prepare(&sys).unwrap();
    let set: RunSet =
        serde_json::from_str(r#"{"runs": [{"name": "a", "parameters": {}}]}"#).unwrap();
    let jobs = set.expand(&sys, "set.json").unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    assert!(run_job(&prepared, &jobs[0], &cancel).is_ok());
    // another build at the same path
    std::fs::copy(
        dist().join("SpringDamperMass.fmu"),
        dir.path().join("MassSpring.fmu"),
    )
    .unwrap();
    let e = run_job(&prepared, &jobs[0], &cancel).unwrap_err().error;
    assert!(
        e.contains("MassSpring.fmu' changed since the run set loaded it"),
        "{e}"
    );
}

/// A study's run that fails midway (the derailing bogie above, in CSV, whose stored rate is
/// decimated) keeps its history at the full rate, up to the row of the failure.
#[test]
fn a_studys_failed_run_keeps_its_full_rate_history() {
    let dir = tempfile::tempdir().unwrap();
    let systems = copy_of_the_systems(dir.path());
    let passive = std::fs::read_to_string(systems.join("passive.json")).unwrap();
    let derailing = passive.replace(
        "\"initial.yaw_angle\": 0.0",
        "\"initial.yaw_angle\": 0.0, \"suspension.lateral_stiffness\": 0, \
         \"suspension.longitudinal_stiffness\": 0",
    );
    assert_ne!(derailing, passive);
    std::fs::write(systems.join("passive.json"), derailing).unwrap();
    let out = dir.path().join("study");
    let r = Command::new(env!("CARGO_BIN_EXE_master"))
        .args([
            "--quiet",
            "study",
            "--quick",
            "--vehicle",
            "bogie2dof",
            "--fmus",
        ])
        .arg(dist())
        .arg("--systems")
        .arg(&systems)
        .args([
            "--configurations",
            "passive",
            "--speeds",
            "522",
            "--format",
            "csv",
        ])
        .args(["--jobs", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(stderr.contains("derailment"), "{stderr}");
    let run = out.join("runs/main/sweep-passive_v522_s1");
    let time = csv_times(&std::fs::read_to_string(run.join("history.csv")).unwrap());
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("history.meta.json")).unwrap())
            .unwrap();
    let failed = meta["summary"]["failed"]["time_s"].as_f64().unwrap();
    assert_eq!(time.last().copied(), Some(failed), "{stderr}");
    // every communication point of 1 ms, not the stored rate's
    assert_eq!(time.len(), (failed / 1e-3).round() as usize + 1);
    assert!(!run.join("results.csv").exists());
}

/// Results files take the user's umask (a private one keeps them private; they were always
/// 0644), and a number beyond 1e16 is written in exponent notation that reads back as the same
/// float (1e300 was 301 digits, which pandas reads as a Python integer).
#[test]
fn results_files_follow_the_umask_and_huge_numbers_stay_floats() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let fmu = dist().join("MassSpring.fmu");
    for (umask, mode) in [("077", 0o600), ("022", 0o644)] {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "umask {umask} && exec \"$0\" --quiet run \"$1\" --stop 0.003 \
                 --set initial_position=1e300 -o r{umask}.csv",
            ))
            .arg(env!("CARGO_BIN_EXE_master"))
            .arg(&fmu)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for file in [format!("r{umask}.csv"), format!("r{umask}.meta.json")] {
            let m = std::fs::metadata(dir.path().join(&file)).unwrap();
            assert_eq!(m.permissions().mode() & 0o777, mode, "{file}");
        }
    }
    let csv = std::fs::read_to_string(dir.path().join("r022.csv")).unwrap();
    let row: Vec<&str> = csv.lines().nth(1).unwrap().split(',').collect();
    let position = row
        .iter()
        .find(|f| f.contains('e'))
        .unwrap_or_else(|| panic!("no exponent in {row:?}"));
    assert!(position.len() < 30, "{position}");
    let x: f64 = position.parse().unwrap();
    assert!((x / 1e300 - 1.0).abs() < 1e-3, "{x}");
    // ordinary numbers stay as they were, a whole Real (the time) with its decimal point
    assert_eq!(row[0], "0.0");
}

/// An FMU's message in a run set names the run it comes from (runs in parallel interleave
/// their messages); a single run's does not.
#[test]
fn an_fmus_message_in_a_sweep_names_its_run() {
    let dir = tempfile::tempdir().unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../systems/passive.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(shipped).unwrap()).unwrap();
    v["stop_time"] = serde_json::json!(0.01);
    for inst in v["instances"].as_array_mut().unwrap() {
        let name = Path::new(inst["fmu"].as_str().unwrap())
            .file_name()
            .unwrap()
            .to_owned();
        inst["fmu"] = serde_json::json!(dist().join(name).to_str().unwrap());
    }
    let system = dir.path().join("base.json");
    std::fs::write(&system, v.to_string()).unwrap();
    std::fs::write(
        dir.path().join("set.json"),
        format!(
            r#"{{"base": "{}", "runs": [
  {{"name": "standing", "parameters": {{"bogie.vehicle.speed": 0}}}},
  {{"name": "running", "parameters": {{}}}}]}}"#,
            system.display()
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep", "set.json", "-o", "out", "--jobs", "2"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("run 'standing', FMU instance 'bogie':"),
        "{stderr}"
    );
    assert!(!stderr.contains("run 'running', FMU"), "{stderr}");
}
