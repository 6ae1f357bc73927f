//! The master runs FMUs whose binaries this project did not write and agrees with fmpy:
//! * `Container.fmu`: fmpy's container FMU (its own Rust binary) wrapping our MassSpring and
//!   SpringDamperMass, connected inside it;
//! * `PyOscillator.fmu`: a Python slave packaged by pythonfmu (a C++ binary embedding Python).
//!
//! scripts/test.sh builds them into target/foreign with tests/fmpy/make_container.py and
//! make_pythonfmu.py, which also simulate each with fmpy (`NAME.fmpy.csv`) and write the
//! one-instance system the master runs (`NAME.system.json`), and points RAIL_FOREIGN_FMUS there.
//!
//! Loading a pythonfmu binary outside Python: it leaves the Python C-API symbols undefined (in a
//! Python host they are already loaded), so the host must load libpython with global symbols
//! first. The test does that in a child process of itself started with `LD_PRELOAD` (and
//! `PYTHONHOME`, so the embedded interpreter finds its standard library wherever libpython sits),
//! from `python_env.txt`; a user does the same: `LD_PRELOAD=.../libpython3.11.so master run ...`.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};

use master::coupling::{RunOptions, SimOutput};
use master::system::LoadedSystem;
use tests::csv::read_csv;

const CHILD: &str = "RAIL_PYFMU_CHILD";

fn foreign_dir() -> Option<PathBuf> {
    match std::env::var_os("RAIL_FOREIGN_FMUS") {
        Some(d) => Some(d.into()),
        None => {
            tests::missing_external(
                "RAIL_FOREIGN_FMUS not set: run scripts/test.sh (it builds the foreign FMUs first)",
            );
            None
        }
    }
}

fn need(path: &Path) -> &Path {
    assert!(
        path.exists(),
        "{} is missing: scripts/test.sh generates it (tests/fmpy/make_container.py, make_pythonfmu.py)",
        path.display()
    );
    path
}

fn run_system(path: &Path, edit: impl FnOnce(&mut LoadedSystem)) -> SimOutput {
    let mut sys = LoadedSystem::load(need(path)).unwrap();
    edit(&mut sys);
    sys.run(&RunOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Same value to rounding: relative 1e-9, with a floor of 1e-15 of the column's scale for zeros.
fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-6 * scale)
}

/// Compares the master's output with fmpy's CSV at the rows `k` where `keep(k)`; returns the
/// number of values compared.
fn compare(name: &str, out: &SimOutput, fmpy: &Path, keep: impl Fn(usize) -> bool) -> usize {
    let (header, rows) = read_csv(need(fmpy)).unwrap();
    let time = out.column("time").unwrap();
    assert_eq!(
        time.len(),
        rows.len(),
        "{name}: master rows vs fmpy rows ({})",
        fmpy.display()
    );
    let mut n = 0;
    let mut worst: f64 = 0.0;
    for (j, col) in header.iter().enumerate().skip(1) {
        let ours = out
            .column(col)
            .unwrap_or_else(|| panic!("{name}: the master did not record {col}"));
        let scale = rows.iter().map(|r| r[j].abs()).fold(0.0, f64::max);
        for (k, row) in rows.iter().enumerate().filter(|(k, _)| keep(*k)) {
            assert!(
                (row[0] - time[k]).abs() < 1e-12,
                "{name}: time grid differs at row {k}"
            );
            assert!(
                close(ours[k], row[j], scale),
                "{name}: {col} at t = {}: master {} vs fmpy {}",
                row[0],
                ours[k],
                row[j]
            );
            worst = worst.max((ours[k] - row[j]).abs() / scale.max(1e-300));
            n += 1;
        }
    }
    eprintln!(
        "{name}: {n} values agree with fmpy, max difference {worst:.1e} of the column's range"
    );
    n
}

#[test]
fn container_fmu_agrees_with_fmpy() {
    let Some(dir) = foreign_dir() else { return };
    let out = run_system(&dir.join("Container.system.json"), |_| {});
    let n = compare("Container", &out, &dir.join("Container.fmpy.csv"), |_| true);
    assert!(n >= 4 * 2000, "{n} values");
    // the parameters went through the container to the components: the coupling force at t0
    // is coupling_stiffness * (0 - x1(0)) = 300 * (0 - 0.1)
    let f0 = out.column("box.coupling_force").unwrap()[0];
    assert!((f0 + 30.0).abs() < 1e-12, "{f0}");
}

/// Host-call robustness with a foreign FMU. fmpy's container declares no
/// canHandleVariableCommunicationStepSize (FMI 2.0 default: false), so it must always be stepped
/// with the same step. With a step multiple of 4 (dividing the 2000 steps) its windows are all
/// 4 ms; inside it takes 1 ms fixed steps with no inputs from outside, so at each of its points
/// it must equal fmpy's 1 ms run exactly (the held values in between are not compared). With a
/// multiple of 3 its last window would be cut to 2 ms: refused before any call, naming the flag.
#[test]
fn container_with_step_multiple_keeps_a_constant_step() {
    let Some(dir) = foreign_dir() else { return };
    let out = run_system(&dir.join("Container.system.json"), |s| {
        s.desc.instances[0].step_multiple = 4;
    });
    let last = out.column("time").unwrap().len() - 1;
    assert_eq!(last, 2000);
    let n = compare(
        "Container (step multiple 4)",
        &out,
        &dir.join("Container.fmpy.csv"),
        |k| k % 4 == 0,
    );
    assert!(n >= 4 * 500, "{n}");

    let mut sys = LoadedSystem::load(need(&dir.join("Container.system.json"))).unwrap();
    sys.desc.instances[0].step_multiple = 3;
    let e = sys.run(&RunOptions::default()).unwrap_err().to_string();
    assert!(
        e.contains("canHandleVariableCommunicationStepSize") && e.contains("step_multiple 3"),
        "{e}"
    );
}

/// A step that does not divide the stop time is refused before any FMU is loaded, naming the
/// field (not run with a last step of a different length).
#[test]
fn step_not_dividing_the_stop_time_is_refused() {
    let Some(dir) = foreign_dir() else { return };
    let mut sys = LoadedSystem::load(need(&dir.join("Container.system.json"))).unwrap();
    sys.desc.step = 0.003; // 2 s / 3 ms = 666.67
    let e = sys.run(&RunOptions::default()).unwrap_err().to_string();
    assert!(
        e.contains("step") && e.contains("not an integer multiple"),
        "{e}"
    );
}

/// FMI 2.0 allows `canHandleMultipleSetPerTimeInstant` on any ScalarVariable (fmpy writes it on
/// every variable of the container FMUs it builds; make_container.py leaves it out). The `fmi`
/// crate's parser (fmi-schema 0.8) rejects it ("unknown field"); the master strips it before
/// handing the description over, so such FMUs load.
#[test]
fn fmu_with_can_handle_multiple_set_per_time_instant_loads() {
    let Some(dir) = foreign_dir() else { return };
    let src = dir.join("Container.fmu");
    need(&src);
    let tmp = tempfile::tempdir().unwrap();
    let dst = tmp.path().join("Container.fmu");
    {
        let mut zin = zip::ZipArchive::new(std::fs::File::open(&src).unwrap()).unwrap();
        let mut zout = zip::ZipWriter::new(std::fs::File::create(&dst).unwrap());
        for i in 0..zin.len() {
            let mut f = zin.by_index(i).unwrap();
            let name = f.name().to_string();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut f, &mut data).unwrap();
            if name == "modelDescription.xml" {
                let xml = String::from_utf8(data).unwrap().replace(
                    "<ScalarVariable ",
                    "<ScalarVariable canHandleMultipleSetPerTimeInstant=\"true\" ",
                );
                data = xml.into_bytes();
            }
            zout.start_file(name, zip::write::SimpleFileOptions::default())
                .unwrap();
            std::io::Write::write_all(&mut zout, &data).unwrap();
        }
        zout.finish().unwrap();
    }
    let a = master::fmu::FmuArchive::open(&dst).unwrap();
    a.instantiate("box", false).unwrap();
}

/// Reads python_env.txt (KEY=VALUE lines) written by make_pythonfmu.py.
fn python_env(dir: &Path) -> Vec<(String, String)> {
    std::fs::read_to_string(need(&dir.join("python_env.txt")))
        .unwrap()
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

#[test]
fn python_fmu_agrees_with_fmpy() {
    let Some(dir) = foreign_dir() else { return };
    need(&dir.join("PyOscillator.fmu"));
    let env = python_env(&dir);
    let get = |k: &str| {
        env.iter()
            .find(|(n, _)| n == k)
            .map(|(_, v)| v.clone())
            .unwrap_or_else(|| panic!("python_env.txt has no {k}"))
    };
    let libpython = get("LIBPYTHON");
    need(Path::new(&libpython));
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "python_fmu_in_child_process",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD, "1")
        .env("LD_PRELOAD", &libpython)
        .env("PYTHONHOME", get("PYTHONHOME"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stderr}");
    assert!(out.status.success(), "child failed:\n{stdout}\n{stderr}");
    assert!(
        stdout.contains("1 passed"),
        "the child ran no test:\n{stdout}"
    );
    assert!(stderr.contains("PyOscillator: "), "{stderr}");
}

/// The body of [`python_fmu_agrees_with_fmpy`]; does nothing unless started by it.
#[test]
fn python_fmu_in_child_process() {
    if std::env::var_os(CHILD).is_none() {
        eprintln!("runs only as the child process of python_fmu_agrees_with_fmpy (needs LD_PRELOAD of libpython)");
        return;
    }
    let dir = foreign_dir().unwrap();
    let out = run_system(&dir.join("PyOscillator.system.json"), |_| {});
    // Real, Integer and Boolean outputs, compared at every row
    let n = compare(
        "PyOscillator",
        &out,
        &dir.join("PyOscillator.fmpy.csv"),
        |_| true,
    );
    assert!(n >= 5 * 1001, "{n} values");
    let steps = out.column("osc.steps").unwrap();
    assert_eq!(*steps.last().unwrap(), 1000.0);
    // the input force start value from the system file reached the Python object: the mean
    // position over the run is offset by roughly force / stiffness = 0.5 / 60
    let x = out.column("osc.position").unwrap();
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    assert!(mean > 0.002, "{mean}");
}
