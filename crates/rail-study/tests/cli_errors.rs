//! Bad input through the built binary: clear message naming the thing, non-zero exit, no
//! result file. No real FMU is needed: validation happens before any binary is loaded.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

const MS_MD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="MassSpring" guid="{1}">
  <CoSimulation modelIdentifier="MassSpring"/>
  <ModelVariables>
    <ScalarVariable name="mass" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/></ScalarVariable>
    <ScalarVariable name="force" valueReference="1" causality="input"><Real start="0" unit="N"/></ScalarVariable>
    <ScalarVariable name="position" valueReference="2" causality="output"><Real unit="m"/></ScalarVariable>
    <ScalarVariable name="velocity" valueReference="3" causality="output"><Real unit="m/s"/></ScalarVariable>
    <ScalarVariable name="count" valueReference="4" causality="output"><Integer/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs>
    <Unknown index="3" dependencies=""/><Unknown index="4" dependencies=""/><Unknown index="5" dependencies=""/>
  </Outputs></ModelStructure>
</fmiModelDescription>"#;

const DAMPER_MD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Damper" guid="{2}">
  <CoSimulation modelIdentifier="Damper"/>
  <ModelVariables>
    <ScalarVariable name="velocity" valueReference="0" causality="input"><Real start="0" unit="m/s"/></ScalarVariable>
    <ScalarVariable name="force" valueReference="1" causality="output"><Real unit="N"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2" dependencies="1"/></Outputs></ModelStructure>
</fmiModelDescription>"#;

fn fake_fmu(dir: &Path, file: &str, id: &str, md: &str) -> PathBuf {
    let p = dir.join(file);
    let mut z = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    z.start_file("modelDescription.xml", o).unwrap();
    z.write_all(md.as_bytes()).unwrap();
    z.start_file(format!("binaries/linux64/{id}.so"), o)
        .unwrap();
    z.write_all(b"not really a library").unwrap();
    z.finish().unwrap();
    p
}

const SYSTEM: &str = r#"{
  "instances": [
    {"name": "body", "fmu": "MassSpring.fmu", "parameters": {"mass": 2.0}},
    {"name": "damper", "fmu": "Damper.fmu"}
  ],
  "connections": [
    {"from": "body.velocity", "to": "damper.velocity"},
    {"from": "damper.force", "to": "body.force"}
  ],
  "stop_time": 1.0,
  "step": 0.001
}"#;

struct Case {
    dir: tempfile::TempDir,
}

impl Case {
    fn new(system: &str) -> Case {
        let dir = tempfile::tempdir().unwrap();
        fake_fmu(dir.path(), "MassSpring.fmu", "MassSpring", MS_MD);
        fake_fmu(dir.path(), "Damper.fmu", "Damper", DAMPER_MD);
        std::fs::write(dir.path().join("system.json"), system).unwrap();
        Case { dir }
    }
    fn path(&self, f: &str) -> PathBuf {
        self.dir.path().join(f)
    }
    /// Runs `master run system.json -o out.csv`; returns stderr after checking failure and
    /// that no result file (nor a temporary file) was left.
    fn run_fails(&self) -> String {
        let out = Command::new(env!("CARGO_BIN_EXE_master"))
            .args(["--quiet", "run"])
            .arg(self.path("system.json"))
            .arg("-o")
            .arg(self.path("out.csv"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!out.status.success(), "should fail; stderr: {stderr}");
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(!self.path("out.csv").exists(), "result file left behind");
        let leftovers: Vec<_> = std::fs::read_dir(self.dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().to_string())
            .filter(|n| n.starts_with(master::output::UNFINISHED_PREFIX))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
        stderr
    }
}

#[test]
fn missing_system_file() {
    let c = Case::new(SYSTEM);
    std::fs::remove_file(c.path("system.json")).unwrap();
    let e = c.run_fails();
    assert!(
        e.contains("cannot read") && e.contains("system.json"),
        "{e}"
    );
}

#[test]
fn malformed_json_names_line_and_column() {
    let c = Case::new(&SYSTEM.replace("\"step\": 0.001", "\"step\": 0.001,"));
    let e = c.run_fails();
    assert!(
        e.contains("system.json: line 12, column 1: trailing comma"),
        "{e}"
    );
    let c = Case::new(&SYSTEM.replace("\"stop_time\"", "\"stop_tiem\""));
    let e = c.run_fails();
    assert!(
        e.contains("unknown field `stop_tiem`") && e.contains("line 10"),
        "{e}"
    );
}

#[test]
fn missing_fmu() {
    let c = Case::new(SYSTEM);
    std::fs::remove_file(c.path("Damper.fmu")).unwrap();
    let e = c.run_fails();
    assert!(
        e.contains("instances[1].fmu") && e.contains("Damper.fmu") && e.contains("not found"),
        "{e}"
    );
}

#[test]
fn corrupt_zip() {
    let c = Case::new(SYSTEM);
    std::fs::write(c.path("Damper.fmu"), b"garbage garbage garbage").unwrap();
    let e = c.run_fails();
    assert!(
        e.contains("instances[1].fmu") && e.contains("not a valid zip"),
        "{e}"
    );
}

#[test]
fn unparsable_model_description() {
    let c = Case::new(SYSTEM);
    fake_fmu(
        c.dir.path(),
        "Damper.fmu",
        "Damper",
        &DAMPER_MD.replace("</ModelVariables>", ""),
    );
    let e = c.run_fails();
    assert!(
        e.contains("Damper.fmu") && e.contains("modelDescription.xml"),
        "{e}"
    );
}

#[test]
fn unknown_variable_in_connection() {
    let c = Case::new(&SYSTEM.replace("\"damper.force\"", "\"damper.forse\""));
    let e = c.run_fails();
    assert!(
        e.contains(
            "line 8: connections[1].from: unknown variable 'damper.forse' in instance 'damper'"
        ) && e.contains("did you mean 'damper.force'?"),
        "{e}"
    );
}

#[test]
fn unit_and_type_mismatch() {
    let c = Case::new(&SYSTEM.replace("\"body.velocity\"", "\"body.position\""));
    let e = c.run_fails();
    assert!(e.contains("connections[0]: unit mismatch: 'body.position' is in [m] but 'damper.velocity' is in [m/s]"), "{e}");
    let c = Case::new(&SYSTEM.replace("\"body.velocity\"", "\"body.count\""));
    let e = c.run_fails();
    assert!(
        e.contains("type mismatch: 'body.count' is Integer but 'damper.velocity' is Real"),
        "{e}"
    );
}

#[test]
fn fake_binary_fails_to_load_cleanly() {
    // everything validates; loading the fake .so fails with a typed error, no panic
    let c = Case::new(SYSTEM);
    let e = c.run_fails();
    assert!(e.contains("cannot load or instantiate 'body'"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn inspect_reports_bad_fmus_and_help_works() {
    let c = Case::new(SYSTEM);
    std::fs::write(c.path("bad.fmu"), b"xx").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .arg("inspect")
        .arg(c.path("bad.fmu"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad.fmu' is not a valid zip"));
    // inspect loads the binary as run does: the fake one fails the same way
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .arg("inspect")
        .arg(c.path("Damper.fmu"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot load or instantiate"));
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["inspect", "--no-load"])
        .arg(c.path("Damper.fmu"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("force") && text.contains("output") && text.contains("N"),
        "{text}"
    );
    for sub in ["run", "sweep", "inspect"] {
        let out = Command::new(env!("CARGO_BIN_EXE_master"))
            .args([sub, "--help"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{sub} --help");
        assert!(String::from_utf8_lossy(&out.stdout).contains("Usage: master"));
    }
}

#[test]
fn sweep_with_bad_runset_fails_without_output() {
    let c = Case::new(SYSTEM);
    std::fs::write(
        c.path("set.json"),
        r#"{"base": "system.json", "product": {"bodyy.mass": [1, 2]}}"#,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep"])
        .arg(c.path("set.json"))
        .arg("-o")
        .arg(c.path("out"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr)
        .contains("product.bodyy.mass: unknown instance 'bodyy'"));
    assert!(!c.path("out").exists());
}

#[test]
fn sweep_refuses_local_jobs_on_a_dask_cluster() {
    let c = Case::new(SYSTEM);
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "sweep", "set.json", "-j", "2"])
        .args(["--dask-scheduler", "tcp://127.0.0.1:1", "-o"])
        .arg(c.path("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("'--jobs <JOBS>' cannot be used with '--dask-scheduler <ADDRESS>'"),
        "{stderr}"
    );
    assert!(!c.path("out").exists());
}

/// A dimensionless bound is printed without its unit "1" ("2 is above its maximum 1", not
/// "2 1 is above its maximum 1 1"); a unit that is one keeps it.
#[test]
fn a_dimensionless_bound_is_printed_without_the_unit_one() {
    let md = MS_MD.replace(
        r#"<Real start="1" unit="kg"/>"#,
        r#"<Real start="0.5" unit="1" min="0" max="1"/>"#,
    );
    let c = Case::new(SYSTEM);
    fake_fmu(c.dir.path(), "MassSpring.fmu", "MassSpring", &md);
    let e = c.run_fails();
    assert!(
        e.contains("mass: 2 is above its maximum 1 (declared"),
        "{e}"
    );
}

/// An output path under a file is named as such before anything runs.
#[test]
fn an_output_folder_that_is_a_file_is_named() {
    let c = Case::new(SYSTEM);
    std::fs::write(c.path("afile"), b"x").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_master"))
        .args(["--quiet", "run", "system.json", "-o", "afile/x.csv"])
        .current_dir(c.dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("'afile' is not a folder"), "{e}");
    assert_eq!(std::fs::read(c.path("afile")).unwrap(), b"x");
}
