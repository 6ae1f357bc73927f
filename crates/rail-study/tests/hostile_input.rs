//! Hostile input through the built `master` binary, one test per class of bad input: a clear
//! message, exit status 1 (never 101, never a signal), nothing written outside the output
//! folder, no stale result. Real FMU code comes from tests/fixtures/hostile_fmu.c, compiled
//! here with the system C compiler; it misbehaves on request (HOSTILE_FMU_MODE).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/hostile_fmu.c");

const HOSTILE_MD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Hostile" guid="{hostile}" variableNamingConvention="structured">
  <CoSimulation modelIdentifier="Hostile" canHandleVariableCommunicationStepSize="true"/>
  <ModelVariables>
    <ScalarVariable name="y" valueReference="0" causality="output"><Real unit="s"/></ScalarVariable>
    <ScalarVariable name="gain" valueReference="1" causality="parameter" variability="fixed"><Real start="1"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1" dependencies=""/></Outputs></ModelStructure>
</fmiModelDescription>"#;

const SYSTEM: &str = r#"{
  "instances": [{"name": "h", "fmu": "Hostile.fmu"}],
  "stop_time": 0.01, "step": 0.001
}"#;

/// A case folder: `dir/case` holds the inputs and is the only place the master may write
/// (besides `dir/case/tmp`, its TMPDIR); `dir` itself must stay empty but for `case`.
struct Case {
    root: tempfile::TempDir,
}

impl Case {
    fn new() -> Case {
        let root = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(root.path().join("case/tmp")).unwrap();
        std::fs::write(root.path().join("case/system.json"), SYSTEM).unwrap();
        Case { root }
    }
    fn path(&self, f: &str) -> PathBuf {
        self.root.path().join("case").join(f)
    }
    fn write(&self, f: &str, text: &str) -> PathBuf {
        let p = self.path(f);
        std::fs::write(&p, text).unwrap();
        p
    }
    /// [`Case::master`] without extra environment, which must succeed.
    fn master_ok(&self, args: &[&str]) -> Output {
        let out = self.master(args, &[]);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    }
    /// Runs the master with `args` (paths relative to the case folder), TMPDIR in the case,
    /// extra environment `env`; kills it after 120 s (a hang fails the test).
    fn master(&self, args: &[&str], env: &[(&str, &str)]) -> Output {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_master"));
        cmd.current_dir(self.path(""))
            .arg("--quiet")
            .args(args)
            .env("TMPDIR", self.path("tmp"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        for (k, v) in env {
            cmd.env(k, v);
        }
        let child = cmd.spawn().unwrap();
        let pid = child.id();
        // read the pipes while waiting (a long message must not block the child)
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let _ = tx.send(child.wait_with_output());
        });
        let out = match rx.recv_timeout(Duration::from_secs(120)) {
            Ok(out) => out.unwrap(),
            Err(_) => {
                let _ = Command::new("kill").arg("-9").arg(pid.to_string()).status();
                panic!("master {args:?} hangs");
            }
        };
        // nothing outside the case folder
        let outside: Vec<_> = std::fs::read_dir(self.root.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .filter(|n| n != "case")
            .collect();
        assert!(outside.is_empty(), "written outside the case: {outside:?}");
        out
    }
    /// Runs and expects exit status 1; returns stderr.
    fn fails(&self, args: &[&str], env: &[(&str, &str)]) -> String {
        let out = self.master(args, env);
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(out.status.code(), Some(1), "master {args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        stderr
    }
    fn extraction_folders(&self) -> Vec<String> {
        std::fs::read_dir(self.path("tmp"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .filter(|n| n.starts_with("master-fmu-"))
            .collect()
    }
}

/// Compiles the hostile FMU's binary once per test process.
fn hostile_binary() -> PathBuf {
    static BUILT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BUILT
        .get_or_init(|| {
            let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
            std::fs::create_dir_all(&dir).unwrap();
            let so = dir.join("Hostile.so");
            let status = Command::new("cc")
                .args(["-shared", "-fPIC", "-O1", "-o"])
                .arg(&so)
                .arg(FIXTURE)
                .status()
                .expect("a C compiler (cc) is needed for this test");
            assert!(status.success(), "cc failed on {FIXTURE}");
            so
        })
        .clone()
}

/// Writes an FMU of `entries` (name, bytes) into the case.
fn zip_into(path: &Path, entries: &[(&str, &[u8])]) {
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    for (name, data) in entries {
        z.start_file(*name, o).unwrap();
        z.write_all(data).unwrap();
    }
    z.finish().unwrap();
}

fn hostile_fmu(case: &Case, md: &str) -> PathBuf {
    let so = std::fs::read(hostile_binary()).unwrap();
    let p = case.path("Hostile.fmu");
    zip_into(
        &p,
        &[
            ("modelDescription.xml", md.as_bytes()),
            ("binaries/linux64/Hostile.so", &so),
        ],
    );
    p
}

#[test]
fn run_names_never_escape_or_collide() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    for (runs, expected) in [
        (
            r#"[{"name": "..", "parameters": {}}]"#,
            "may not start with '.'",
        ),
        (
            r#"[{"name": ".", "parameters": {}}]"#,
            "may not start with '.'",
        ),
        (r#"[{"name": "", "parameters": {}}]"#, "must not be empty"),
        (
            r#"[{"name": "../../up", "parameters": {}}]"#,
            "would be the folder '.._.._up'",
        ),
        (
            r#"[{"name": "sweep.json", "parameters": {}}]"#,
            "report file",
        ),
        (
            r#"[{"name": "a/b", "parameters": {}}, {"name": "a_b", "parameters": {}}]"#,
            "'a/b' and 'a_b' would both write the folder 'a_b'",
        ),
        (
            r#"[{"name": "Fast", "parameters": {}}, {"name": "fast", "parameters": {}}]"#,
            "would both write the folder",
        ),
    ] {
        c.write(
            "set.json",
            &format!(r#"{{"base": "system.json", "runs": {runs}}}"#),
        );
        let e = c.fails(&["sweep", "set.json", "-o", "out"], &[]);
        assert!(e.contains(expected), "{runs}: {e}");
        assert!(!c.path("out").exists(), "{runs}: output folder created");
    }
    // separators and '..' inside a name stay inside the output folder
    c.write(
        "set.json",
        r#"{"base": "system.json", "runs": [{"name": "x/../../up", "parameters": {}},
             {"name": "/etc/passwd", "parameters": {}}]}"#,
    );
    let out = c.master(&["sweep", "set.json", "-o", "out"], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut runs: Vec<String> = std::fs::read_dir(c.path("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    runs.sort();
    assert_eq!(runs, ["_etc_passwd", "sweep.json", "x_.._.._up"]);
    assert!(c.path("out/x_.._.._up/results.csv").exists());
}

#[test]
fn rerun_replaces_the_run_folder_and_a_failed_sweep_reports_failure() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    c.write(
        "set.json",
        r#"{"base": "system.json", "runs": [{"name": "a", "parameters": {"h.gain": 2}}]}"#,
    );
    let out = c.master(&["sweep", "set.json", "-o", "out"], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(c.path("out/a/results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 12, "{csv}");
    // a file added to the run's folder is the user's: the run that would replace the folder
    // is refused, and nothing changes
    std::fs::write(c.path("out/a/notes.txt"), "mine").unwrap();
    c.write(
        "set.json",
        r#"{"base": "system.json", "runs": [{"name": "a", "parameters": {"h.gain": 13}}]}"#,
    );
    let e = c.fails(&["sweep", "set.json", "-o", "out"], &[]);
    assert!(e.contains("holds 'notes.txt', which no run writes"), "{e}");
    assert_eq!(
        std::fs::read_to_string(c.path("out/a/results.csv")).unwrap(),
        csv
    );
    assert!(c.path("out/sweep.json").is_file());
    std::fs::remove_file(c.path("out/a/notes.txt")).unwrap();
    // the same run now fails: its folder holds the new description and summary only
    let e = c.fails(&["sweep", "set.json", "-o", "out"], &[]);
    assert!(e.contains("1 run(s) failed: a"), "{e}");
    let mut files: Vec<String> = std::fs::read_dir(c.path("out/a"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    files.sort();
    assert_eq!(files, ["summary.json", "system.json"]);
    let summary = std::fs::read_to_string(c.path("out/a/summary.json")).unwrap();
    assert!(summary.contains("\"ok\": false"), "{summary}");
    let sweep = std::fs::read_to_string(c.path("out/sweep.json")).unwrap();
    assert!(sweep.contains("start value 'gain' = 13"), "{sweep}");
    // no hidden partial folders left
    let hidden: Vec<_> = std::fs::read_dir(c.path("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}

#[test]
fn a_sweep_into_a_used_folder_holds_its_own_runs_and_replaces_nothing_else() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    let sweep = |set: &str, format: &str| {
        c.write("set.json", set);
        c.master(&["sweep", "set.json", "-o", "out", "--format", format], &[])
    };
    let runs_from = |base: &str, names: &[&str]| {
        let list: Vec<String> = names
            .iter()
            .map(|n| format!(r#"{{"name": "{n}", "parameters": {{}}}}"#))
            .collect();
        format!(r#"{{"base": "{base}", "runs": [{}]}}"#, list.join(", "))
    };
    let runs = |names: &[&str]| runs_from("system.json", names);
    let listing = |dir: &str| {
        let mut names: Vec<String> = std::fs::read_dir(c.path(dir))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        names.sort();
        names
    };
    std::fs::create_dir_all(c.path("out")).unwrap();
    std::fs::write(c.path("out/notes.txt"), "the user's").unwrap();
    assert!(sweep(&runs(&["a", "b", "c"]), "parquet").status.success());
    assert!(sweep(&runs(&["b"]), "parquet").status.success());
    // the earlier set's other runs are gone, the user's file is not
    assert_eq!(listing("out"), ["b", "notes.txt", "results", "sweep.json"]);
    assert_eq!(listing("out/results"), ["b.parquet"]);
    // a run named like something that is not a run folder is refused, nothing replaced
    c.write("set.json", &runs(&["notes.txt"]));
    // the run set itself, in the output folder
    c.write("out/set.json", &runs_from("../system.json", &["set.json"]));
    for set_file in ["set.json", "out/set.json"] {
        let e = c.fails(&["sweep", set_file, "-o", "out"], &[]);
        assert!(e.contains("is not a run folder of an earlier sweep"), "{e}");
    }
    assert_eq!(
        std::fs::read_to_string(c.path("out/notes.txt")).unwrap(),
        "the user's"
    );
    assert!(c.path("out/set.json").is_file() && c.path("out/b").is_dir());
}

#[test]
fn huge_runs_are_refused_up_front() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    for (stop, step) in [("1e9", "1"), ("1", "1e-300")] {
        c.write(
            "big.json",
            &SYSTEM
                .replace("0.01", stop)
                .replace("\"step\": 0.001", &format!("\"step\": {step}")),
        );
        let e = c.fails(&["run", "big.json", "-o", "out.csv"], &[]);
        assert!(
            e.contains("communication steps, more than the 100000000 allowed")
                && e.contains("MASTER_MAX_STEPS"),
            "{e}"
        );
        assert!(!c.path("out.csv").exists());
        assert!(
            c.extraction_folders().is_empty(),
            "unpacked before refusing"
        );
    }
    // the limit is raised by its variable; the recorded values then bound the run
    let e = c.fails(
        &["run", "big.json", "-o", "out.csv"],
        &[("MASTER_MAX_STEPS", "1e400")],
    );
    assert!(e.contains("MASTER_MAX_STEPS='1e400' is not"), "{e}");
    // 7 lists of 20 values: 1.28e9 runs, refused before any is built
    let lists: Vec<String> = (0..7)
        .map(|i| format!("\"h.p{i}\": [{}]", vec!["1"; 20].join(",")))
        .collect();
    c.write(
        "set.json",
        &format!(
            r#"{{"base": "system.json", "product": {{{}}}}}"#,
            lists.join(",")
        ),
    );
    let e = c.fails(&["sweep", "set.json", "-o", "out"], &[]);
    assert!(
        e.contains("20 x 20 x 20 x 20 x 20 x 20 x 20 = 1.28e9 combinations")
            && e.contains("100000 runs"),
        "{e}"
    );
    assert!(!c.path("out").exists());
}

#[test]
fn a_damaged_binary_is_refused_before_it_is_loaded() {
    // the system loader faults inside dlopen on these (SIGBUS, SIGSEGV), taking the process
    // down before any error could be returned: they are read and refused first
    let c = Case::new();
    let so = std::fs::read(hostile_binary()).unwrap();
    let md = ("modelDescription.xml", HOSTILE_MD.as_bytes());
    let cut = &so[..4096];
    let mut zeroed = so.clone();
    zeroed[4096..].fill(0);
    for (what, binary) in [("cut short", cut), ("zeroed after its first page", &zeroed)] {
        zip_into(
            &c.path("Hostile.fmu"),
            &[md, ("binaries/linux64/Hostile.so", binary)],
        );
        for sub in [&["run", "system.json"][..], &["inspect", "Hostile.fmu"][..]] {
            let e = c.fails(sub, &[]);
            assert!(
                e.contains("binaries/linux64/Hostile.so")
                    && (e.contains("is not a loadable shared library")
                        || e.contains("malformed ELF file")),
                "{what}, {sub:?}: {e}"
            );
        }
    }
}

#[test]
fn archive_limits_and_unsafe_entries_are_refused_before_extraction() {
    let c = Case::new();
    let so = std::fs::read(hostile_binary()).unwrap();
    let bin = ("binaries/linux64/Hostile.so", so.as_slice());
    let md = ("modelDescription.xml", HOSTILE_MD.as_bytes());
    // a zip bomb, scaled down: 8 MB of zeros in a few kB, against a lowered limit
    let zeros = vec![0u8; 8 << 20];
    zip_into(
        &c.path("Hostile.fmu"),
        &[md, bin, ("resources/bomb", &zeros)],
    );
    assert!(std::fs::metadata(c.path("Hostile.fmu")).unwrap().len() < 200_000);
    for sub in [&["inspect", "Hostile.fmu"][..], &["run", "system.json"][..]] {
        let e = c.fails(sub, &[("MASTER_FMU_MAX_UNPACKED_BYTES", "4000000")]);
        assert!(
            e.contains("is refused: it unpacks to")
                && e.contains("more than the limit of 4000000")
                && e.contains("MASTER_FMU_MAX_UNPACKED_BYTES"),
            "{e}"
        );
    }
    // the same archive is accepted once the limit is raised
    let out = c.master(
        &["inspect", "Hostile.fmu"],
        &[("MASTER_FMU_MAX_UNPACKED_BYTES", "10000000")],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // an oversized modelDescription, entry counts
    let e = c.fails(
        &["inspect", "Hostile.fmu"],
        &[("MASTER_FMU_MAX_MODEL_DESCRIPTION_BYTES", "100")],
    );
    assert!(e.contains("its modelDescription.xml has"), "{e}");
    let e = c.fails(
        &["inspect", "Hostile.fmu"],
        &[("MASTER_FMU_MAX_ENTRIES", "2")],
    );
    assert!(
        e.contains("it has 3 entries, more than the limit of 2"),
        "{e}"
    );
    // zip-slip, absolute paths, links: refused, nothing written. The archive is unpacked in
    // <case>/tmp/master-fmu-*/, so "../../escaped.txt" would land in <case>/escaped.txt.
    let absolute = std::env::temp_dir().join(format!(
        "absolute-{}-{}.txt",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos()
    ));
    let absolute_entry = absolute.to_string_lossy().to_string();
    for (entry, reason) in [
        ("../../escaped.txt", "leaves the archive"),
        ("../escaped.txt", "leaves the archive"),
        (absolute_entry.as_str(), "leaves the archive"),
    ] {
        zip_into(&c.path("Hostile.fmu"), &[md, bin, (entry, b"x")]);
        let e = c.fails(&["run", "system.json"], &[]);
        assert!(e.contains(reason), "{entry}: {e}");
        for landed in [
            c.path("escaped.txt"),
            c.path("tmp/escaped.txt"),
            c.root.path().join("escaped.txt"),
            absolute.clone(),
        ] {
            assert!(
                !landed.exists(),
                "{entry} was written to {}",
                landed.display()
            );
        }
    }
    let mut z = zip::ZipWriter::new(std::fs::File::create(c.path("Hostile.fmu")).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    z.start_file("modelDescription.xml", o).unwrap();
    z.write_all(HOSTILE_MD.as_bytes()).unwrap();
    z.start_file("binaries/linux64/Hostile.so", o).unwrap();
    z.write_all(&so).unwrap();
    z.add_symlink("resources/link", "/etc/passwd", o).unwrap();
    z.finish().unwrap();
    let e = c.fails(&["inspect", "Hostile.fmu"], &[]);
    assert!(e.contains("symbolic links are not allowed"), "{e}");
    // a name stored twice (the zip reader keeps only the last copy): a second
    // modelDescription.xml, made by renaming an entry of the same length in place
    let other_md = HOSTILE_MD.replace("guid=\"{hostile}\"", "guid=\"{hostilf}\"");
    zip_into(
        &c.path("Hostile.fmu"),
        &[md, bin, ("modelDescriptioN.xml", other_md.as_bytes())],
    );
    let bytes = std::fs::read(c.path("Hostile.fmu")).unwrap();
    let (from, to): (&[u8], &[u8]) = (b"modelDescriptioN.xml", b"modelDescription.xml");
    let mut patched = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        if bytes[k..].starts_with(from) {
            patched.extend_from_slice(to);
            k += from.len();
        } else {
            patched.push(bytes[k]);
            k += 1;
        }
    }
    std::fs::write(c.path("Hostile.fmu"), &patched).unwrap();
    for sub in [&["inspect", "Hostile.fmu"][..], &["run", "system.json"][..]] {
        let e = c.fails(sub, &[]);
        assert!(
            e.contains("\"modelDescription.xml\": the name is used twice"),
            "{e}"
        );
    }
    assert!(c.extraction_folders().is_empty());
}

/// An instance name that is no safe archive member name (a space, `#`, `%`) is exported as a
/// safe member: the SSP runs (it referred to `resources/h #1%.ssv`, which the import reads as
/// a URI with a fragment); the coupling settings SSP has no place for travel in the master's
/// annotation.
#[test]
fn an_exported_ssp_runs_whatever_its_instance_names_and_keeps_its_coupling_settings() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    c.write(
        "odd.json",
        r#"{"instances": [{"name": "h #1%", "fmu": "Hostile.fmu", "parameters": {"gain": 2}}],
            "stop_time": 0.01, "step": 0.001, "init_sweeps": 7}"#,
    );
    let out = c.master(&["export-ssp", "odd.json", "odd.ssp"], &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("the master's annotation"), "{stdout}");
    let mut zip = zip::ZipArchive::new(std::fs::File::open(c.path("odd.ssp")).unwrap()).unwrap();
    let names: Vec<&str> = zip.file_names().collect();
    assert!(names.contains(&"resources/h__1_.ssv"), "{names:?}");
    let mut ssd = String::new();
    std::io::Read::read_to_string(&mut zip.by_name("SystemStructure.ssd").unwrap(), &mut ssd)
        .unwrap();
    assert!(
        ssd.contains(r#"<rfm:Coupling algorithm="gauss-seidel" initSweeps="7""#),
        "{ssd}"
    );
    let out = c.master(&["run", "odd.ssp", "-o", "odd.csv"], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // the results name the FMU by the archive and its member, not by the unpacked copy that
    // went with the run
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(c.path("odd.meta.json")).unwrap()).unwrap();
    let fmu = meta["system"]["instances"][0]["fmu"]
        .as_str()
        .unwrap()
        .to_string();
    let archive = c.path("odd.ssp").canonicalize().unwrap();
    assert_eq!(fmu, format!("{}:resources/Hostile.fmu", archive.display()));
}

/// A bare .ssd reads its parameter files beside it: a run's results or summary named as one
/// of them is refused before anything is written, as for the .ssd itself (the results
/// replaced the parameter set, and the system no longer loaded).
#[test]
fn a_run_does_not_write_over_the_parameter_files_of_a_bare_ssd() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    c.write(
        "p.json",
        r#"{"instances": [{"name": "h", "fmu": "Hostile.fmu", "parameters": {"gain": 2}}],
            "stop_time": 0.01, "step": 0.001}"#,
    );
    c.master_ok(&["export-ssp", "p.json", "p.ssp"]);
    let mut zip = zip::ZipArchive::new(std::fs::File::open(c.path("p.ssp")).unwrap()).unwrap();
    zip.extract(c.path("un")).unwrap();
    let ssv = c.path("un/resources/h.ssv");
    let before = std::fs::read(&ssv).unwrap();
    for args in [
        vec![
            "run",
            "un/SystemStructure.ssd",
            "-o",
            "un/resources/h.ssv",
            "--format",
            "csv",
        ],
        vec![
            "run",
            "un/SystemStructure.ssd",
            "-o",
            "r.csv",
            "--summary",
            "un/resources/h.ssv",
        ],
    ] {
        let e = c.fails(&args, &[]);
        assert!(e.contains("is the same file as the input"), "{e}");
        assert_eq!(std::fs::read(&ssv).unwrap(), before);
    }
    c.master_ok(&["run", "un/SystemStructure.ssd", "-o", "r.csv"]);
    // an archive into a folder that is not there is named as such (the error named the
    // write's hidden temporary file)
    let e = c.fails(&["export-ssp", "p.json", "nodir/x.ssp"], &[]);
    assert!(
        e.contains("nodir") && !e.contains(".master-unfinished"),
        "{e}"
    );
}

/// The FMUs inside an SSP unpack within the FMU limit, checked before a byte is written: a
/// small archive wrote its declared gigabytes to the temporary folder and was refused only
/// after (a limit of 4 GiB per entry, MASTER_FMU_MAX_UNPACKED_BYTES ignored).
#[test]
fn an_ssps_fmus_unpack_within_the_fmu_limit() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    c.master_ok(&["export-ssp", "system.json", "ok.ssp"]);
    let out = c.master(&["run", "ok.ssp", "-o", "ok.csv"], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // the same archive with its FMU replaced by 8 MB of zeros (a few kB compressed)
    rewrite_zip(&c.path("ok.ssp"), &c.path("bomb.ssp"), |name, data| {
        if name.ends_with(".fmu") {
            *data = vec![0u8; 8 << 20];
        }
    });
    assert!(std::fs::metadata(c.path("bomb.ssp")).unwrap().len() < 200_000);
    let e = c.fails(
        &["run", "bomb.ssp", "-o", "bomb.csv"],
        &[("MASTER_FMU_MAX_UNPACKED_BYTES", "4000000")],
    );
    assert!(
        e.contains("declares 8388608 bytes, more than the 4000000 bytes left")
            && e.contains("MASTER_FMU_MAX_UNPACKED_BYTES"),
        "{e}"
    );
    assert!(!c.path("bomb.csv").exists());
    // within the limit, the zeros are no FMU: refused before they are written out, named as
    // the archive's member, not as a temporary file (gone when the message is read)
    let e = c.fails(&["run", "bomb.ssp", "-o", "bomb.csv"], &[]);
    assert!(
        e.contains("bomb.ssp:resources/")
            && e.contains("not an FMU: it does not begin as a zip archive"),
        "{e}"
    );
    assert!(!e.contains("/tmp/") && !e.contains("master-fmu-"), "{e}");
}

#[test]
fn extraction_folders_of_a_killed_master_are_removed_by_the_next_one() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    // the FMU kills the process mid-run (SIGKILL: no destructor runs)
    let out = c.master(&["run", "system.json"], &[("HOSTILE_FMU_MODE", "kill")]);
    assert_eq!(out.status.code(), None, "expected death by signal");
    assert_eq!(
        c.extraction_folders().len(),
        1,
        "the killed run leaves its folder"
    );
    let out = c.master(&["run", "system.json", "-o", "out.csv"], &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        c.extraction_folders().is_empty(),
        "{:?}",
        c.extraction_folders()
    );
    assert!(c.path("out.csv").exists());
    // an SSP's folder of FMU members too
    c.master_ok(&["export-ssp", "system.json", "system.ssp"]);
    let out = c.master(&["run", "system.ssp"], &[("HOSTILE_FMU_MODE", "kill")]);
    assert_eq!(out.status.code(), None, "expected death by signal");
    assert_eq!(
        c.extraction_folders().len(),
        2,
        "the archive's and the FMU's"
    );
    c.master_ok(&["run", "system.ssp", "-o", "ssp.csv"]);
    assert!(
        c.extraction_folders().is_empty(),
        "{:?}",
        c.extraction_folders()
    );
}

#[test]
fn invalid_model_descriptions_are_refused_by_inspect_and_run_alike() {
    let c = Case::new();
    let cases = [
        (
            HOSTILE_MD.replace(
                "modelIdentifier=\"Hostile\"",
                "modelIdentifier=\"../../Hostile\"",
            ),
            "must be a C identifier",
        ),
        (
            HOSTILE_MD.replace("guid=\"{hostile}\"", "guid=\"{host&#0;ile}\""),
            "control character",
        ),
        (
            HOSTILE_MD.replace("valueReference=\"1\"", "valueReference=\"0\""),
            "has valueReference 0 like 'y': a parameter or input cannot be an alias",
        ),
        (
            HOSTILE_MD.replace("name=\"gain\"", "name=\"gain[1,]\""),
            "structured naming convention",
        ),
        (
            HOSTILE_MD.replace("<Real start=\"1\"/>", "<Real/>"),
            "requires a start value",
        ),
        (
            HOSTILE_MD.replace(
                "causality=\"parameter\" variability=\"fixed\"",
                "causality=\"input\" variability=\"fixed\"",
            ),
            "causality 'input' with variability 'fixed' is not allowed",
        ),
        (
            HOSTILE_MD
                .replace(
                    "causality=\"output\">",
                    "causality=\"output\" initial=\"calculated\">",
                )
                .replace("<Real unit=\"s\"/>", "<Real unit=\"s\" start=\"0\"/>"),
            "must not have a start value",
        ),
    ];
    for (md, expected) in &cases {
        hostile_fmu(&c, md);
        for sub in [&["inspect", "Hostile.fmu"][..], &["run", "system.json"][..]] {
            let e = c.fails(sub, &[]);
            assert!(e.contains(expected), "{sub:?} {expected}: {e}");
        }
    }
    // a binary without the FMI functions: inspect loads it as run does
    let dir = tempfile::tempdir().unwrap();
    let empty_c = dir.path().join("empty.c");
    std::fs::write(&empty_c, "int not_an_fmu(void) { return 0; }\n").unwrap();
    let so = dir.path().join("empty.so");
    assert!(Command::new("cc")
        .args(["-shared", "-fPIC", "-o"])
        .arg(&so)
        .arg(&empty_c)
        .status()
        .unwrap()
        .success());
    zip_into(
        &c.path("Hostile.fmu"),
        &[
            ("modelDescription.xml", HOSTILE_MD.as_bytes()),
            ("binaries/linux64/Hostile.so", &std::fs::read(&so).unwrap()),
        ],
    );
    for sub in [&["inspect", "Hostile.fmu"][..], &["run", "system.json"][..]] {
        let e = c.fails(sub, &[]);
        assert!(e.contains("does not export fmi2"), "{sub:?}: {e}");
    }
    let out = c.master(&["inspect", "--no-load", "Hostile.fmu"], &[]);
    assert!(out.status.success());
    // the binary's platform and newest glibc symbol version, read from the file
    hostile_fmu(&c, HOSTILE_MD);
    let out = c.master(&["inspect", "Hostile.fmu"], &[]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    let line = text
        .lines()
        .find(|l| l.starts_with("binary     binaries/linux64/Hostile.so: linux64, ELF"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("needs glibc >= 2."), "{line}");
}

#[test]
fn logger_messages_with_format_attacks_are_printed_not_executed() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    let out = c.master(
        &["--log-level", "info", "run", "system.json", "-o", "out.csv"],
        &[("HOSTILE_FMU_MODE", "log")],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("progress 100%n done (format not expanded: it contains %n)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("[ERROR] FMU instance '?': status 42 from nowhere"),
        "{stderr}"
    );
    let long = stderr
        .lines()
        .find(|l| l.contains("long: xxx"))
        .expect("the long message");
    assert!(long.len() < 66_000 && long.len() > 65_000, "{}", long.len());
}

#[test]
fn messages_show_a_long_text_by_its_beginning_and_a_huge_number_short() {
    let c = Case::new();
    let label = r#"<ScalarVariable name="label" valueReference="2" causality="parameter" variability="fixed"><String start="a"/></ScalarVariable>"#;
    hostile_fmu(
        &c,
        &HOSTILE_MD.replace("</ModelVariables>", &format!("{label}</ModelVariables>")),
    );
    let long = "x".repeat(10 << 20);
    let with = |name: &str| {
        SYSTEM.replace(
            r#""fmu": "Hostile.fmu""#,
            &format!(r#""fmu": "Hostile.fmu", "parameters": {{"{name}": "{long}"}}"#),
        )
    };
    let shown = "x".repeat(200);
    // a String start value the FMU refuses (its binary has no fmi2SetString)
    c.write("label.json", &with("label"));
    let e = c.fails(&["run", "label.json", "-o", "r.csv"], &[]);
    assert!(
        e.contains(&format!(
            "setting start value 'label' = \"{shown}\"... (10485760 bytes) failed"
        )),
        "{}",
        &e[..e.len().min(2000)]
    );
    assert!(e.len() < 2000, "{} bytes", e.len());
    // a text given to a Real
    c.write("gain.json", &with("gain"));
    let e = c.fails(&["run", "gain.json", "-o", "r.csv"], &[]);
    assert!(
        e.contains(&format!(
            "a Real variable cannot take the value \"{shown}\"... (10485760 bytes)"
        )),
        "{}",
        &e[..e.len().min(2000)]
    );
    assert!(e.len() < 2000, "{} bytes", e.len());
    // --set without '=', and an unknown variable to record
    let arg = "y".repeat(100_000);
    for args in [["--set", &arg], ["--record", &arg]] {
        let e = c.fails(
            &["run", "Hostile.fmu", args[0], args[1], "-o", "r.csv"],
            &[],
        );
        assert!(e.contains("... (100"), "{}", &e[..e.len().min(2000)]);
        assert!(e.len() < 2000, "{args:?}: {} bytes", e.len());
    }
    // huge and tiny numbers
    c.write(
        "huge.json",
        &SYSTEM.replace("\"stop_time\": 0.01", "\"stop_time\": 1e308"),
    );
    let e = c.fails(&["run", "huge.json", "-o", "r.csv"], &[]);
    assert!(e.contains("1e308 s at a step of 0.001 s"), "{e}");
    let e = c.fails(
        &["run", "Hostile.fmu", "--start", "1e308", "-o", "r.csv"],
        &[],
    );
    assert!(e.contains("start_time (1e308), got 1"), "{e}");
    let e = c.fails(
        &["run", "Hostile.fmu", "--stop", "1e-300", "-o", "r.csv"],
        &[],
    );
    // shorter than one step: refused with the description's checks
    assert!(
        e.contains("stop_time - start_time = 1e-300 s is not an integer multiple"),
        "{e}"
    );
    let e = c.fails(&["study", "--quick", "--cv-speed", "1e308"], &[]);
    assert!(e.contains("--cv-speed 1e308: "), "{e}");
    let out = c.master(&["study", "--quick", "--speeds", "250,1e308"], &[]);
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains(": 1e308 km/h: speeds must lie"), "{e}");
    assert!(!c.path("r.csv").exists() && !c.path("results").exists());
}

#[test]
fn a_default_results_file_leaves_no_other_format_beside_it() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    let run = |args: &[&str]| {
        let out = c.master(args, &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "master {args:?}: {stderr}");
    };
    let (csv, meta, parquet) = (
        c.path("results.csv"),
        c.path("results.meta.json"),
        c.path("results.parquet"),
    );
    c.write("results.txt", "the user's");
    c.write("results.meta.parquet", "the user's");
    run(&["run", "system.json", "--format", "parquet"]);
    assert!(parquet.is_file() && !csv.exists() && !meta.exists());
    // small results: CSV by default, and the Parquet file of the earlier run is gone
    run(&["run", "system.json"]);
    assert!(csv.is_file() && meta.is_file() && !parquet.exists());
    run(&["run", "system.json", "--format", "parquet"]);
    assert!(parquet.is_file() && !csv.exists() && !meta.exists());
    // a named output leaves the default files alone
    run(&["run", "system.json", "-o", "named.csv"]);
    assert!(parquet.is_file() && c.path("named.csv").is_file());
    // a folder of the default name is not removed
    std::fs::create_dir(&csv).unwrap();
    run(&["run", "system.json", "--format", "parquet"]);
    assert!(csv.is_dir() && parquet.is_file());
    for f in ["results.txt", "results.meta.parquet"] {
        assert_eq!(std::fs::read_to_string(c.path(f)).unwrap(), "the user's");
    }
}

#[test]
fn fifos_and_devices_are_refused_without_reading() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    let fifo = c.path("system.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let e = c.fails(&["run", "system.fifo"], &[]);
    assert!(e.contains("not a regular file"), "{e}");
    // an SSP (a .ssd or a .ssp) likewise, not as a missing file and without blocking
    for name in ["system.ssd", "system.ssp"] {
        assert!(Command::new("mkfifo")
            .arg(c.path(name))
            .status()
            .unwrap()
            .success());
        let e = c.fails(&["run", name], &[]);
        assert!(
            e.contains("not a regular file") && !e.contains("no such file"),
            "{name}: {e}"
        );
    }
    let e = c.fails(&["run", "/dev/zero"], &[]);
    assert!(e.contains("not a regular file"), "{e}");
    c.write(
        "fifo-fmu.json",
        &SYSTEM.replace("Hostile.fmu", "system.fifo"),
    );
    let e = c.fails(&["run", "fifo-fmu.json"], &[]);
    assert!(e.contains("not a regular file"), "{e}");
    // the tables and profiles of the analysis commands likewise (they would hang or fill
    // memory)
    for file in ["system.fifo", "/dev/zero"] {
        let args = [
            "assess", file, "--signal", "a", "--speed", "300", "--out", "o",
        ];
        let e = c.fails(&args, &[]);
        assert!(e.contains("not a regular file"), "{e}");
        for option in ["--wheel", "--rail"] {
            let e = c.fails(&["contact-geometry", option, file, "--out", "o"], &[]);
            assert!(e.contains("not a regular file"), "{e}");
        }
    }
    assert!(!c.path("o").exists());
}

#[test]
fn outputs_never_replace_an_input_or_a_device() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    let system = std::fs::read(c.path("system.json")).unwrap();
    let fmu = std::fs::read(c.path("Hostile.fmu")).unwrap();
    for args in [
        // --format: a name that says no format is refused before it is compared
        &["run", "system.json", "-o", "system.json", "--format", "csv"][..],
        &[
            "run",
            "system.json",
            "-o",
            "./Hostile.fmu",
            "--format",
            "parquet",
        ],
        &[
            "run",
            "system.json",
            "-o",
            "r.csv",
            "--summary",
            "system.json",
        ],
        &[
            "run",
            "system.json",
            "-o",
            "r.csv",
            "--summary",
            "r.meta.json",
        ],
        &["run", "Hostile.fmu", "-o", "Hostile.fmu", "--format", "csv"],
        &["export-ssp", "system.json", "system.json"],
        &["export-ssp", "system.json", "Hostile.fmu"],
    ] {
        let e = c.fails(args, &[]);
        assert!(e.contains("is the same file as the"), "{args:?}: {e}");
    }
    // a FIFO named as the results is refused, not replaced by a regular file
    let fifo = c.path("results.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let e = c.fails(
        &[
            "run",
            "system.json",
            "-o",
            "results.fifo",
            "--format",
            "csv",
        ],
        &[],
    );
    assert!(e.contains("not a regular file"), "{e}");
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    // a folder named as the summary: refused before the run, not after writing the results
    std::fs::create_dir_all(c.path("summary-folder")).unwrap();
    for args in [
        &[
            "run",
            "system.json",
            "-o",
            "r.csv",
            "--summary",
            "summary-folder",
        ][..],
        &["run", "system.json", "--summary", "summary-folder"],
    ] {
        let e = c.fails(args, &[]);
        assert!(
            e.contains("'summary-folder'") && e.contains("not a regular file"),
            "{e}"
        );
    }
    // a file named for one format does not get the other's content; an SSP is a .ssp
    let e = c.fails(
        &["run", "system.json", "--format", "csv", "-o", "r.parquet"],
        &[],
    );
    assert!(e.contains("--format csv writes csv: name it .csv"), "{e}");
    let e = c.fails(&["export-ssp", "system.json", "system.ssp.json"], &[]);
    assert!(e.contains("an SSP is written as a .ssp file"), "{e}");
    // an archive as the system to export is named for what it is, not read as JSON text
    let e = c.fails(&["export-ssp", "Hostile.fmu", "again.ssp"], &[]);
    assert!(
        e.contains("'Hostile.fmu' is not a JSON system description")
            && e.contains("`master run Hostile.fmu`"),
        "{e}"
    );
    // an SSP where an FMU or a JSON description is meant is named for what it is
    c.master_ok(&["export-ssp", "system.json", "exported.ssp"]);
    let e = c.fails(&["inspect", "exported.ssp"], &[]);
    assert!(e.contains("'exported.ssp' is an SSP, not an FMU"), "{e}");
    c.write(
        "ssp-set.json",
        r#"{"base": "exported.ssp", "runs": [{"name": "a", "parameters": {}}]}"#,
    );
    let e = c.fails(&["sweep", "ssp-set.json", "-o", "ssp-set"], &[]);
    assert!(
        e.contains("'exported.ssp' is an SSP: a run set's base is a JSON system description"),
        "{e}"
    );
    // one FMU file by two spellings is one member of the archive
    std::fs::create_dir_all(c.path("sub")).unwrap();
    c.write(
        "two.json",
        r#"{"instances": [{"name": "h", "fmu": "Hostile.fmu"},
                          {"name": "g", "fmu": "sub/../Hostile.fmu"}],
            "stop_time": 0.01, "step": 0.001}"#,
    );
    c.master_ok(&["export-ssp", "two.json", "two.ssp"]);
    let z = zip::ZipArchive::new(std::fs::File::open(c.path("two.ssp")).unwrap()).unwrap();
    let fmus: Vec<&str> = z.file_names().filter(|n| n.ends_with(".fmu")).collect();
    assert_eq!(fmus, ["resources/Hostile.fmu"]);
    for f in ["exported.ssp", "ssp-set.json", "two.json", "two.ssp"] {
        std::fs::remove_file(c.path(f)).unwrap();
    }
    std::fs::remove_dir(c.path("sub")).unwrap();
    let e = c.fails(&["run", "system.json", "-o", "r.out"], &[]);
    assert!(e.contains("'r.out' names no results format"), "{e}");
    assert_eq!(std::fs::read(c.path("system.json")).unwrap(), system);
    assert_eq!(std::fs::read(c.path("Hostile.fmu")).unwrap(), fmu);
    for f in [
        "r.csv",
        "r.meta.json",
        "r.parquet",
        "results.parquet",
        "results.csv",
        "system.ssp.json",
        "again.ssp",
        "r.out",
    ] {
        assert!(!c.path(f).exists(), "{f}");
    }
    // a command's files are all checked before the first is written: a folder in place of
    // one of them leaves the others as they were (it rewrote some, then failed)
    let geometry = |extra: &[&str]| {
        let mut args = vec!["contact-geometry", "--out", "cg"];
        args.extend_from_slice(extra);
        c.master(&args, &[])
    };
    let out = geometry(&[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names: Vec<std::path::PathBuf> = std::fs::read_dir(c.path("cg"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    let victim = names
        .iter()
        .find(|p| p.extension().is_some_and(|e| e == "csv"))
        .unwrap();
    std::fs::remove_file(victim).unwrap();
    std::fs::create_dir(victim).unwrap();
    let before: Vec<Vec<u8>> = names
        .iter()
        .filter(|p| *p != victim)
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    let e = c.fails(&["contact-geometry", "--out", "cg", "--gauge", "1440"], &[]);
    assert!(e.contains("not a regular file"), "{e}");
    let after: Vec<Vec<u8>> = names
        .iter()
        .filter(|p| *p != victim)
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    assert!(before == after, "files were rewritten before the refusal");
    // the assessment's files are not written over the table it reads
    let rows: String = (0..2001)
        .map(|k| {
            let t = k as f64 * 1e-3;
            format!("{t},{}\n", (2.0 * std::f64::consts::PI * 4.0 * t).sin())
        })
        .collect();
    std::fs::create_dir_all(c.path("as")).unwrap();
    let table = c.write("as/assess.csv", &format!("time [s],a [m/s2]\n{rows}"));
    let before = std::fs::read(&table).unwrap();
    let e = c.fails(
        &[
            "assess",
            "as/assess.csv",
            "--signal",
            "a",
            "--speed",
            "300",
            "--out",
            "as",
        ],
        &[],
    );
    assert!(e.contains("is the same file as the input"), "{e}");
    assert_eq!(std::fs::read(&table).unwrap(), before);
}

#[test]
fn a_variable_recorded_twice_is_refused() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    c.write(
        "twice.json",
        &SYSTEM.replace(
            "\"stop_time\"",
            "\"record\": [\"h.y\", \"h.gain\", \"h.y\"], \"stop_time\"",
        ),
    );
    let e = c.fails(&["run", "twice.json", "-o", "r.parquet"], &[]);
    assert!(
        e.contains("record[2]") && e.contains("recorded already (record[0])"),
        "{e}"
    );
    let e = c.fails(
        &[
            "run",
            "Hostile.fmu",
            "--record",
            "y",
            "--record",
            "y",
            "-o",
            "r.csv",
        ],
        &[],
    );
    assert!(e.contains("recorded already"), "{e}");
    assert!(!c.path("r.parquet").exists() && !c.path("r.csv").exists());
}

#[test]
fn a_study_that_cannot_start_leaves_an_earlier_one_whole() {
    let case = Case::new();
    std::fs::create_dir_all(case.path("out")).unwrap();
    std::fs::create_dir_all(case.path("no-fmus")).unwrap();
    let earlier = [
        "REPORT.md",
        "study.json",
        "rms_vs_speed.svg",
        "rms_vs_speed.csv",
        "history_force.svg",
        "cv_sensitivity.csv",
    ];
    for f in earlier {
        case.write(&format!("out/{f}"), "an earlier study's");
    }
    case.write("out/notes.svg", "the user's");
    // a mistyped FMU folder is refused before anything is touched
    let err = case.fails(
        &["study", "--quick", "--fmus", "no-fmus", "--out", "out"],
        &[],
    );
    assert!(err.contains("not found"), "{err}");
    for f in earlier {
        assert_eq!(
            std::fs::read_to_string(case.path(&format!("out/{f}"))).unwrap(),
            "an earlier study's"
        );
    }
    // FMUs that are no archives: refused when the systems are prepared, before anything is
    // touched (an interrupted study, which removes the earlier outputs, is in cli_runs.rs)
    for fmu in [
        "RailVehicle",
        "Bogie2Dof",
        "PassiveYawDamper",
        "SemiActiveDamper",
        "FullActiveActuator",
        "MpptController",
        "SkyHookController",
        "IdealDamperForceController",
    ] {
        case.write(&format!("no-fmus/{fmu}.fmu"), "not a zip archive");
    }
    let err = case.fails(
        &["study", "--quick", "--fmus", "no-fmus", "--out", "out"],
        &[],
    );
    assert!(!err.contains("not found"), "{err}");
    for f in earlier {
        assert_eq!(
            std::fs::read_to_string(case.path(&format!("out/{f}"))).unwrap(),
            "an earlier study's",
            "{f}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(case.path("out/notes.svg")).unwrap(),
        "the user's"
    );
    assert!(!case.path("out/runs").exists());
}

#[test]
fn a_study_option_out_of_range_is_refused_before_anything_is_touched() {
    let case = Case::new();
    std::fs::create_dir_all(case.path("out")).unwrap();
    let old = case.write("out/REPORT.md", "the previous report");
    for bad in [
        "--cv-speed=nan",
        "--cv-speed=-5",
        "--cv-speed=1e9",
        "--cv-speed=inf",
    ] {
        let err = case.fails(&["study", "--quick", "--out", "out", bad], &[]);
        assert!(
            err.contains("the speed of the c_v runs must lie between 10 and 700 km/h"),
            "{bad}: {err}"
        );
        assert_eq!(
            std::fs::read_to_string(&old).unwrap(),
            "the previous report",
            "{bad}"
        );
    }
    // a value outside the enumeration or a bad list is a usage error (exit status 2) saying
    // what is wrong
    for (option, value, reason) in [
        ("--track-level", "medium", "low, high"),
        ("--speeds", "300:200:10", "FROM <= TO"),
        ("--speeds", "10:700:1", "more than 200 speeds"),
        ("--speeds", "200:300:0.05", "at least 0.1 km/h"),
        ("--speeds", "250,1e9", "between 10 and 700 km/h"),
        ("--seeds", "1,-2", "not a track seed"),
    ] {
        let out = case.master(&["study", "--quick", "--out", "out", option, value], &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{option} {value}: {err}");
        assert!(
            err.contains(&format!("invalid value '{value}'")) && err.contains(reason),
            "{option} {value}: {err}"
        );
    }
    // a speed too low for one EN 14363 window in a sweep run
    let err = case.fails(
        &["study", "--quick", "--out", "out", "--speeds", "20,300"],
        &[],
    );
    assert!(err.contains("less than one 100 m EN 14363 window"), "{err}");
    // an unknown configuration (or the coach's accelerometer sky-hook on the bogie)
    for (vehicle, ids) in [
        ("vehicle", "passive,mppt9"),
        ("bogie2dof", "skyhook_accel_onoff"),
    ] {
        let err = case.fails(
            &[
                "study",
                "--quick",
                "--vehicle",
                vehicle,
                "--out",
                "out",
                "--configurations",
                ids,
            ],
            &[],
        );
        assert!(
            err.contains("is not a configuration of this vehicle (one of passive, "),
            "{ids}: {err}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(&old).unwrap(),
        "the previous report"
    );
}

/// An SSP whose libcosim and OMSimulator annotations give different communication steps runs
/// with libcosim's and says so (it was taken silently).
#[test]
fn an_ssp_with_two_different_steps_says_which_it_takes() {
    let c = Case::new();
    hostile_fmu(&c, HOSTILE_MD);
    c.master_ok(&["export-ssp", "system.json", "ok.ssp"]);
    let mut changed = false;
    rewrite_zip(&c.path("ok.ssp"), &c.path("two.ssp"), |name, data| {
        if name == "SystemStructure.ssd" {
            let text = String::from_utf8(std::mem::take(data)).unwrap();
            let at = text.find("baseStepSize=\"").unwrap() + "baseStepSize=\"".len();
            let end = at + text[at..].find('"').unwrap();
            let step: f64 = text[at..end].parse().unwrap();
            *data = format!("{}{}{}", &text[..at], 2.0 * step, &text[end..]).into_bytes();
            changed = true;
        }
    });
    assert!(changed);
    let out = c.master(&["run", "two.ssp", "-o", "two.csv"], &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("gives two communication steps"), "{stderr}");
}

/// Copies the archive `src` to `dst`, each entry's bytes passed through `edit` (its name, its
/// data to change in place).
fn rewrite_zip(src: &Path, dst: &Path, mut edit: impl FnMut(&str, &mut Vec<u8>)) {
    let mut src = zip::ZipArchive::new(std::fs::File::open(src).unwrap()).unwrap();
    let mut z = zip::ZipWriter::new(std::fs::File::create(dst).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    for i in 0..src.len() {
        let mut e = src.by_index(i).unwrap();
        let mut data = Vec::new();
        std::io::Read::read_to_end(&mut e, &mut data).unwrap();
        let name = e.name().to_string();
        edit(&name, &mut data);
        z.start_file(name.as_str(), o).unwrap();
        z.write_all(&data).unwrap();
    }
    z.finish().unwrap();
}
