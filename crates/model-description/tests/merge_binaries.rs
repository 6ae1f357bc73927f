//! Merging binaries built on other platforms into the FMUs (`package-fmus --binaries DIR`),
//! with real foreign-format binaries compiled here at test time from tests/fixtures/fmi2_stub.c:
//! Windows DLLs with mingw-w64 (64- and 32-bit; scripts/test.sh installs it), macOS dylibs with
//! zig (the venv's ziglang, which the Linux build uses anyway) and a Linux .so with the system
//! C compiler. Right ones land in the FMU; wrong ones are refused with a message
//! naming the file and the reason, and no FMU is written.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;

use model_description::capi::PackagedModel;
use model_description::package::{self, PackageError, Platform, Policy};

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/fmi2_stub.c");

/// Compile the fixture into `out` with `compiler` (extra `args`), or fail saying what to install.
fn compile(compiler: &str, args: &[&str], out: &Path) {
    let status = Command::new(compiler)
        .args(["-shared", "-O1", "-o"])
        .arg(out)
        .arg(FIXTURE)
        .args(args)
        .status()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run {compiler} ({e}): install gcc-mingw-w64-x86-64 and gcc-mingw-w64-i686 \
                 (scripts/test.sh does)"
            )
        });
    assert!(status.success(), "{compiler} failed on {FIXTURE}");
}

struct Fixtures {
    _dir: tempfile::TempDir,
    dll64: PathBuf,
    dll32: PathBuf,
    dll64_without_exports: PathBuf,
    linux_so: PathBuf,
}

fn fixtures() -> Fixtures {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let f = Fixtures {
        dll64: p("stub64.dll"),
        dll32: p("stub32.dll"),
        dll64_without_exports: p("noexports64.dll"),
        linux_so: p("stub.so"),
        _dir: dir,
    };
    compile("x86_64-w64-mingw32-gcc", &[], &f.dll64);
    compile("i686-w64-mingw32-gcc", &[], &f.dll32);
    compile(
        "x86_64-w64-mingw32-gcc",
        &["-DNO_FMI2_EXPORTS"],
        &f.dll64_without_exports,
    );
    compile("cc", &["-fPIC"], &f.linux_so);
    f
}

const VENV_PYTHON: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../.venv/bin/python");

/// macOS dylibs of the fixture for x86-64 and arm64, compiled with `python -m ziglang cc`.
fn macos_dylibs(dir: &Path) -> (PathBuf, PathBuf) {
    let build = |target: &str| {
        let out = dir.join(format!("stub-{target}.dylib"));
        let status = Command::new(VENV_PYTHON)
            .args([
                "-m", "ziglang", "cc", "-target", target, "-shared", "-O1", "-o",
            ])
            .arg(&out)
            .arg(FIXTURE)
            .status()
            .unwrap_or_else(|e| {
                panic!("{VENV_PYTHON} -m ziglang: {e} (scripts/setup.sh installs it)")
            });
        assert!(status.success(), "zig cc -target {target} failed");
        out
    };
    (build("x86_64-macos"), build("aarch64-macos"))
}

/// A universal Mach-O file of `slices` as (cputype, cpusubtype, image), laid out as lipo does:
/// big-endian fat header, each slice aligned to 16 KiB (values from mach/machine.h).
fn universal(slices: &[(u32, u32, &[u8])]) -> Vec<u8> {
    const ALIGN: u32 = 14;
    let mut out = Vec::new();
    out.extend_from_slice(&0xcafe_babe_u32.to_be_bytes());
    out.extend_from_slice(&(slices.len() as u32).to_be_bytes());
    let mut offset = 1u32 << ALIGN;
    let mut layout = Vec::new();
    for (cputype, cpusubtype, bytes) in slices {
        let size = bytes.len() as u32;
        for field in [*cputype, *cpusubtype, offset, size, ALIGN] {
            out.extend_from_slice(&field.to_be_bytes());
        }
        layout.push(offset);
        offset = (offset + size).div_ceil(1 << ALIGN) * (1 << ALIGN);
    }
    for ((_, _, bytes), at) in slices.iter().zip(layout) {
        out.resize(at as usize, 0);
        out.extend_from_slice(bytes);
    }
    out
}

fn model(identifier: &str) -> PackagedModel {
    PackagedModel {
        identifier: identifier.into(),
        model_description_xml: format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{identifier}" guid="{{00000000-0000-0000-0000-000000000000}}">
  <CoSimulation modelIdentifier="{identifier}"/>
  <ModelVariables/>
  <ModelStructure/>
</fmiModelDescription>
"#
        ),
        documentation_html: "<html></html>".into(),
        resources: Vec::new(),
    }
}

/// A `binaries` folder with `files` as (platform folder, file name, source).
fn binaries_dir(files: &[(&str, &str, &Path)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (folder, name, source) in files {
        let d = dir.path().join(folder);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::copy(source, d.join(name)).unwrap();
    }
    dir
}

fn merge_problems(dir: &Path, models: &[&PackagedModel]) -> Vec<String> {
    match package::read_binaries_dir(dir, models, Platform::Linux64, &Policy::baseline()) {
        Err(PackageError::Binaries(problems)) => problems,
        Err(other) => panic!("expected binary problems, got {other}"),
        Ok(found) => panic!("expected binary problems, got {} binaries", found.len()),
    }
}

#[test]
fn a_windows_dll_is_checked_and_merged_next_to_the_linux_binary() {
    let f = fixtures();
    let m = model("Stub");
    let dir = binaries_dir(&[
        ("win64", "Stub.dll", &f.dll64),
        ("win32", "Stub.dll", &f.dll32),
    ]);
    let found =
        package::read_binaries_dir(dir.path(), &[&m], Platform::Linux64, &Policy::baseline())
            .unwrap();
    let stub = &found["Stub"];
    let platforms: Vec<Platform> = stub.iter().map(|b| b.platform).collect();
    assert_eq!(platforms, [Platform::Win32, Platform::Win64]);

    let linux = std::fs::read(&f.linux_so).unwrap();
    let mut binaries: Vec<(Platform, &[u8])> = vec![(Platform::Linux64, &linux)];
    binaries.extend(stub.iter().map(|b| (b.platform, b.bytes.as_slice())));
    let out = tempfile::tempdir().unwrap();
    let fmu = package::write_fmu(out.path(), &m, &binaries).unwrap();

    let report = fmu_binary::check_fmu(&fmu, &Policy::baseline()).unwrap();
    assert!(report.is_ok(), "{report:#?}");
    assert_eq!(
        report.platforms(),
        [Platform::Linux64, Platform::Win32, Platform::Win64]
    );
    let entries: Vec<&str> = report.binaries.iter().map(|b| b.entry.as_str()).collect();
    assert_eq!(
        entries,
        [
            "binaries/linux64/Stub.so",
            "binaries/win32/Stub.dll",
            "binaries/win64/Stub.dll"
        ]
    );
    let win64 = &report.binaries[2];
    let info = win64.info.as_ref().unwrap();
    assert_eq!(info.format, fmu_binary::BinaryFormat::Pe);
    assert_eq!(
        info.images[0].architecture,
        fmu_binary::Architecture::X86_64
    );
    assert!(info
        .missing_exports(&fmu_binary::fmi2_cosimulation_api())
        .is_empty());
    // The DLL's bytes go into the FMU unchanged.
    let mut zip = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut zip.by_name("binaries/win64/Stub.dll").unwrap(),
        &mut bytes,
    )
    .unwrap();
    assert_eq!(bytes, std::fs::read(&f.dll64).unwrap());
}

#[test]
fn a_universal_macos_dylib_goes_to_darwin64_and_a_wrong_slice_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let (x86_64, arm64) = macos_dylibs(tmp.path());
    let fat = tmp.path().join("universal.dylib");
    let (a, b) = (
        std::fs::read(&x86_64).unwrap(),
        std::fs::read(&arm64).unwrap(),
    );
    std::fs::write(
        &fat,
        universal(&[(0x0100_0007, 3, &a), (0x0100_000c, 0, &b)]),
    )
    .unwrap();
    let m = model("Stub");

    let dir = binaries_dir(&[
        ("darwin64", "Stub.dylib", &fat),
        ("aarch64-darwin", "Stub.dylib", &arm64),
    ]);
    let found =
        package::read_binaries_dir(dir.path(), &[&m], Platform::Linux64, &Policy::baseline())
            .unwrap();
    let platforms: Vec<Platform> = found["Stub"].iter().map(|b| b.platform).collect();
    assert_eq!(platforms, [Platform::Aarch64Darwin, Platform::Darwin64]);
    let info = fmu_binary::inspect(&std::fs::read(&fat).unwrap()).unwrap();
    assert!(info.universal);
    let archs: Vec<_> = info.images.iter().map(|i| i.architecture.clone()).collect();
    assert_eq!(
        archs,
        [
            fmu_binary::Architecture::X86_64,
            fmu_binary::Architecture::Aarch64
        ]
    );
    // Mach-O's leading underscore is not part of the FMI name.
    assert!(info
        .missing_exports(&fmu_binary::fmi2_cosimulation_api())
        .is_empty());

    let dir = binaries_dir(&[
        ("aarch64-darwin", "Stub.dylib", &fat),
        ("win64", "Stub.dll", &arm64),
    ]);
    let all = merge_problems(dir.path(), &[&m]).join("\n");
    assert!(
        all.contains("aarch64-darwin/Stub.dylib (for aarch64-darwin): is built for x86-64, but aarch64-darwin needs aarch64"),
        "{all}"
    );
    assert!(
        all.contains(
            "win64/Stub.dll (for win64): is a Mach-O (macOS) binary, but win64 needs PE (Windows)"
        ),
        "{all}"
    );
}

#[test]
fn a_linux_library_in_the_win64_folder_is_refused() {
    let f = fixtures();
    let dir = binaries_dir(&[("win64", "Stub.dll", &f.linux_so)]);
    let problems = merge_problems(dir.path(), &[&model("Stub")]);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0].contains("win64/Stub.dll")
            && problems[0].contains("is a ELF (Linux) binary, but win64 needs PE (Windows)"),
        "{problems:?}"
    );
}

#[test]
fn a_dll_without_the_fmi2_functions_is_refused() {
    let f = fixtures();
    let dir = binaries_dir(&[("win64", "Stub.dll", &f.dll64_without_exports)]);
    let problems = merge_problems(dir.path(), &[&model("Stub")]);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0]
            .contains("win64/Stub.dll (for win64): exports none of the 34 FMI 2.0 functions"),
        "{problems:?}"
    );
}

#[test]
fn a_32_bit_dll_in_the_win64_folder_is_refused() {
    let f = fixtures();
    let dir = binaries_dir(&[("win64", "Stub.dll", &f.dll32)]);
    let problems = merge_problems(dir.path(), &[&model("Stub")]);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0].contains("is built for x86 (32-bit), but win64 needs x86-64"),
        "{problems:?}"
    );
}

#[test]
fn unknown_folders_files_and_the_own_platform_are_refused_all_at_once() {
    let f = fixtures();
    let dir = binaries_dir(&[
        ("windows64", "Stub.dll", &f.dll64),
        ("win64", "Other.dll", &f.dll64),
        ("linux64", "Stub.so", &f.linux_so),
        ("win32", "Stub.dll", &f.dll64),
    ]);
    let problems = merge_problems(dir.path(), &[&model("Stub")]);
    let all = problems.join("\n");
    assert_eq!(problems.len(), 4, "{all}");
    assert!(all.contains("linux64 is built here"), "{all}");
    assert!(
        all.contains(
            "win64/Other.dll: not a binary of a model packaged here (expected one of Stub.dll)"
        ),
        "{all}"
    );
    assert!(
        all.contains(
            "win32/Stub.dll (for win32): is built for x86-64, but win32 needs x86 (32-bit)"
        ),
        "{all}"
    );
    assert!(all.contains("'windows64' is no platform folder"), "{all}");
}

// ---- The command line on the real FMU libraries (scripts/test.sh packages them first) ----

fn package_fmus(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_package-fmus"))
        .arg("--no-build")
        .args(args)
        .output()
        .unwrap()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

fn zip_entry(fmu: &Path, name: &str) -> Vec<u8> {
    let mut zip = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut zip.by_name(name).unwrap(), &mut bytes).unwrap();
    bytes
}

#[test]
fn package_fmus_merges_a_windows_dll_into_the_real_fmus() {
    let f = fixtures();
    let dir = binaries_dir(&[
        ("win64", "MassSpring.dll", &f.dll64),
        ("win64", "SpringDamperMass.dll", &f.dll64),
    ]);
    let plain = tempfile::tempdir().unwrap();
    let out = package_fmus(&["--out", plain.path().to_str().unwrap()]);
    assert!(
        out.status.success(),
        "package-fmus --no-build failed (package the FMUs first: \
         cargo run --release -p model-description --bin package-fmus): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let merged = tempfile::tempdir().unwrap();
    let out = package_fmus(&[
        "--binaries",
        dir.path().to_str().unwrap(),
        "--out",
        merged.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("MassSpring.fmu (linux64, win64)"),
        "{stdout}"
    );
    assert!(stdout.contains("Bogie2Dof.fmu (linux64)"), "{stdout}");
    assert_eq!(files_in(merged.path()), files_in(plain.path()));

    let fmu = merged.path().join("MassSpring.fmu");
    let report = fmu_binary::check_fmu(&fmu, &Policy::baseline()).unwrap();
    assert!(report.is_ok(), "{report:#?}");
    assert_eq!(report.platforms(), [Platform::Linux64, Platform::Win64]);
    // Same modelDescription (and GUID) and the same Linux binary as without the merge.
    let plain_fmu = plain.path().join("MassSpring.fmu");
    for entry in ["modelDescription.xml", "binaries/linux64/MassSpring.so"] {
        assert_eq!(
            zip_entry(&fmu, entry),
            zip_entry(&plain_fmu, entry),
            "{entry}"
        );
    }
    assert_eq!(
        zip_entry(&fmu, "binaries/win64/MassSpring.dll"),
        std::fs::read(&f.dll64).unwrap()
    );
    // Reproducible: merging again gives the same bytes.
    let again = tempfile::tempdir().unwrap();
    let out = package_fmus(&[
        "--binaries",
        dir.path().to_str().unwrap(),
        "--out",
        again.path().to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert_eq!(
        std::fs::read(&fmu).unwrap(),
        std::fs::read(again.path().join("MassSpring.fmu")).unwrap()
    );
    // fmpy (the project's venv) validates the merged FMU.
    let python = VENV_PYTHON;
    let out = Command::new(python)
        .args([
            "-c",
            "import sys; from fmpy.validation import validate_fmu; p = validate_fmu(sys.argv[1]); \
             print(*p, sep='\\n'); sys.exit(1 if p else 0)",
        ])
        .arg(&fmu)
        .output()
        .unwrap_or_else(|e| panic!("{python}: {e} (scripts/setup.sh creates the venv with fmpy)"));
    assert!(
        out.status.success(),
        "fmpy validate: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn package_fmus_writes_nothing_when_a_foreign_binary_is_wrong() {
    let f = fixtures();
    let cases: [(&str, &Path, &str); 3] = [
        (
            "Linux .so in win64",
            &f.linux_so,
            "but win64 needs PE (Windows)",
        ),
        (
            "DLL without the fmi2 exports",
            &f.dll64_without_exports,
            "exports none of the 34 FMI 2.0 functions",
        ),
        (
            "32-bit DLL in win64",
            &f.dll32,
            "is built for x86 (32-bit), but win64 needs x86-64",
        ),
    ];
    for (what, wrong, message) in cases {
        // One good DLL beside the wrong one: the good one must not be written either.
        let dir = binaries_dir(&[
            ("win64", "MassSpring.dll", &f.dll64),
            ("win64", "SpringDamperMass.dll", wrong),
        ]);
        let out_dir = tempfile::tempdir().unwrap();
        let out = package_fmus(&[
            "--binaries",
            dir.path().to_str().unwrap(),
            "--out",
            out_dir.path().to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
        assert!(
            stderr.contains("win64/SpringDamperMass.dll") && stderr.contains(message),
            "{what}: {stderr}"
        );
        assert!(stderr.contains("no FMU written"), "{what}: {stderr}");
        assert!(!stderr.contains("MassSpring.dll"), "{what}: {stderr}");
        assert_eq!(files_in(out_dir.path()), Vec::<String>::new(), "{what}");
    }
}
