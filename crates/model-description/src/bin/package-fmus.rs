//! Build every FMU crate of the workspace (release, feature `fmi-export`) and write
//! `dist/<Model>.fmu` for every model the built libraries carry.
//!
//! On Linux the libraries are built with cargo-zigbuild against glibc 2.17 (manylinux2014), so
//! the FMUs load on every distribution since 2014; `--native` builds with plain cargo for the
//! build machine's own glibc. `--binaries DIR` merges binaries built on other platforms into the
//! same FMUs; `--export-binaries DIR` writes this platform's binaries for such a merge.
//!
//! Usage: `cargo run --release -p model-description --bin package-fmus [-- OPTIONS]`

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use fmu_binary::{LinuxPolicy, SymbolVersion, GLIBC_BASELINE};
use model_description::capi::PackagedModel;
use model_description::package::{self, Platform, Policy};

const HELP: &str = "package-fmus [--out DIR] [--no-build] [--native | --glibc X.Y] [--binaries DIR] [--export-binaries DIR]

Builds the FMU crates (release, feature fmi-export) and writes DIR/<Model>.fmu
(default DIR: <workspace>/dist). Every binary is checked before anything is written.

  --out DIR              where the .fmu files go (default <workspace>/dist)
  --no-build             package what the last build left in target/
  --glibc X.Y            Linux: build with cargo-zigbuild against this glibc (default 2.17) and
                         refuse binaries that need a newer one
  --native               build with plain cargo for this machine (on Linux the binaries then
                         need this machine's glibc; for machines without zig)
  --binaries DIR         also put binaries built elsewhere into the FMUs: DIR/<platform>/
                         <modelIdentifier>.<dll|dylib|so> (platforms win32, win64, linux32,
                         linux64, darwin64, aarch64-linux, aarch64-darwin; DIR/binaries/ is used
                         if it exists); each is checked for its folder's format, architecture
                         and the FMI 2.0 exports
  --export-binaries DIR  write this platform's binaries as DIR/<platform>/<modelIdentifier>.<ext>
                         (for --binaries on another machine) instead of FMUs

cargo-zigbuild is looked up in <workspace>/target/tools/bin, then on PATH; zig as
`python -m ziglang` with <workspace>/.venv/bin/python (scripts/setup.sh installs both).";

struct Options {
    out: Option<PathBuf>,
    build: bool,
    native: bool,
    glibc: Option<SymbolVersion>,
    binaries: Option<PathBuf>,
    export_binaries: Option<PathBuf>,
}

fn parse_args() -> Result<Option<Options>, String> {
    let mut o = Options {
        out: None,
        build: true,
        native: false,
        glibc: None,
        binaries: None,
        export_binaries: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--out" => o.out = Some(value("--out")?.into()),
            "--no-build" => o.build = false,
            "--native" => o.native = true,
            "--glibc" => {
                let v = value("--glibc")?;
                o.glibc = Some(v.parse().map_err(|e| format!("--glibc: {e}"))?);
            }
            "--binaries" => o.binaries = Some(value("--binaries")?.into()),
            "--export-binaries" => o.export_binaries = Some(value("--export-binaries")?.into()),
            "-h" | "--help" => {
                println!("{HELP}");
                return Ok(None);
            }
            other => return Err(format!("unknown argument '{other}' (see --help)")),
        }
    }
    if o.native && o.glibc.is_some() {
        return Err("--glibc sets the baseline of the zig build; --native has none".into());
    }
    if o.export_binaries.is_some() && (o.binaries.is_some() || o.out.is_some()) {
        return Err("--export-binaries writes binaries, not FMUs: no --out or --binaries".into());
    }
    Ok(Some(o))
}

fn main() -> ExitCode {
    match parse_args() {
        Ok(Some(o)) => match run(&o) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("package-fmus: {e}");
                ExitCode::FAILURE
            }
        },
        Ok(None) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("package-fmus: {e}");
            ExitCode::from(2)
        }
    }
}

/// How the libraries are built and where they land.
struct Build {
    platform: Platform,
    /// `Some(triple)` for the zig build (`x86_64-unknown-linux-gnu`), `None` for plain cargo.
    zig_triple: Option<String>,
    policy: Policy,
}

impl Build {
    fn new(o: &Options) -> Result<Self, String> {
        let host = Platform::host().ok_or("this host is no FMI platform")?;
        if o.native {
            return Ok(Self {
                platform: host,
                zig_triple: None,
                policy: Policy::native(),
            });
        }
        if std::env::consts::OS != "linux" {
            return Err(format!(
                "the glibc-baseline build is for Linux hosts; on {} pass --native",
                std::env::consts::OS
            ));
        }
        let triple = format!("{}-unknown-linux-gnu", std::env::consts::ARCH);
        Ok(Self {
            platform: host,
            zig_triple: Some(triple),
            policy: Policy {
                linux: Some(LinuxPolicy::with_glibc(o.glibc.unwrap_or(GLIBC_BASELINE))),
            },
        })
    }

    fn lib_dir(&self, target: &Path) -> PathBuf {
        match &self.zig_triple {
            Some(t) => target.join(t).join("release"),
            None => target.join("release"),
        }
    }
}

/// A built library and the models it carries.
struct Library {
    path: PathBuf,
    bytes: Vec<u8>,
    models: Vec<PackagedModel>,
}

fn run(o: &Options) -> Result<(), String> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let root = root.canonicalize().unwrap_or(root);
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let build = Build::new(o)?;
    let crates = fmu_crates(&root)?;
    if o.build {
        cargo_build(&root, &build, &crates)?;
    }
    let libs = read_libraries(&build.lib_dir(&target), &crates)?;

    // Every library is checked for this platform before anything is written.
    let mut problems = Vec::new();
    let mut newest_glibc = None;
    for lib in &libs {
        for m in &lib.models {
            problems.extend(package::binary_problems_for(
                &lib.path,
                &lib.bytes,
                build.platform,
                m,
                &build.policy,
            ));
        }
        if let Ok(info) = fmu_binary::inspect(&lib.bytes) {
            newest_glibc = newest_glibc.max(info.newest_glibc());
        }
    }
    if !problems.is_empty() {
        return Err(package::PackageError::Binaries(problems).to_string());
    }
    if let Some(v) = newest_glibc {
        match &build.policy.linux {
            Some(l) => println!(
                "{} binaries need glibc {v} or newer (baseline {})",
                build.platform, l.glibc
            ),
            None => println!(
                "{} binaries need glibc {v} or newer (--native: this machine's glibc)",
                build.platform
            ),
        }
    }

    if let Some(dir) = &o.export_binaries {
        return export_binaries(dir, build.platform, &libs);
    }
    let foreign = match &o.binaries {
        Some(dir) => {
            let models: Vec<&PackagedModel> = libs.iter().flat_map(|l| &l.models).collect();
            package::read_binaries_dir(dir, &models, build.platform, &build.policy)
                .map_err(|e| e.to_string())?
        }
        None => BTreeMap::new(),
    };
    let out = o.out.clone().unwrap_or_else(|| root.join("dist"));
    for lib in &libs {
        for m in &lib.models {
            let mut binaries: Vec<(Platform, &[u8])> = vec![(build.platform, &lib.bytes)];
            for b in foreign.get(&m.identifier).into_iter().flatten() {
                binaries.push((b.platform, b.bytes.as_slice()));
            }
            binaries.sort_by_key(|(p, _)| *p);
            let path = package::write_fmu(&out, m, &binaries).map_err(|e| e.to_string())?;
            let platforms: Vec<&str> = binaries.iter().map(|(p, _)| p.folder()).collect();
            println!("wrote {} ({})", path.display(), platforms.join(", "));
        }
    }
    Ok(())
}

/// The library of each FMU crate in `lib_dir`, with the models its manifest lists.
fn read_libraries(lib_dir: &Path, crates: &[String]) -> Result<Vec<Library>, String> {
    let mut libs = Vec::new();
    for name in crates {
        let file_name = format!(
            "{}{}{}",
            std::env::consts::DLL_PREFIX,
            name.replace('-', "_"),
            std::env::consts::DLL_SUFFIX
        );
        let path = lib_dir.join(file_name);
        if !path.is_file() {
            return Err(format!(
                "{} missing: build first (without --no-build)",
                path.display()
            ));
        }
        let Some(models) = package::read_manifest(&path).map_err(|e| e.to_string())? else {
            continue;
        };
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        libs.push(Library {
            path,
            bytes,
            models,
        });
    }
    if libs.iter().all(|l| l.models.is_empty()) {
        return Err(format!("no FMU library found in {}", lib_dir.display()));
    }
    Ok(libs)
}

/// Write `dir/<platform>/<identifier>.<ext>` for every model (temporary name, then rename).
fn export_binaries(dir: &Path, platform: Platform, libs: &[Library]) -> Result<(), String> {
    let folder = dir.join(platform.folder());
    std::fs::create_dir_all(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    for lib in libs {
        for m in &lib.models {
            let target = folder.join(platform.library_file_name(&m.identifier));
            let tmp = folder.join(format!(".{}.tmp", m.identifier));
            std::fs::write(&tmp, &lib.bytes)
                .and_then(|_| std::fs::rename(&tmp, &target))
                .map_err(|e| format!("{}: {e}", target.display()))?;
            println!("wrote {}", target.display());
        }
    }
    Ok(())
}

/// Workspace members with a cdylib target and a feature `fmi-export`: the FMU crates.
fn fmu_crates(root: &Path) -> Result<Vec<String>, String> {
    #[derive(serde::Deserialize)]
    struct Metadata {
        packages: Vec<MetaPackage>,
    }
    #[derive(serde::Deserialize)]
    struct MetaPackage {
        name: String,
        targets: Vec<MetaTarget>,
        features: BTreeMap<String, Vec<String>>,
    }
    #[derive(serde::Deserialize)]
    struct MetaTarget {
        crate_types: Vec<String>,
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(root)
        .args([
            "metadata",
            "--no-deps",
            "--format-version",
            "1",
            "--offline",
        ])
        .output()
        .map_err(|e| format!("cannot run cargo metadata: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "cargo metadata failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let meta: Metadata =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("cargo metadata output: {e}"))?;
    let mut crates: Vec<String> = meta
        .packages
        .into_iter()
        .filter(|p| {
            p.features.contains_key("fmi-export")
                && p.targets
                    .iter()
                    .any(|t| t.crate_types.iter().any(|c| c == "cdylib"))
        })
        .map(|p| p.name)
        .collect();
    crates.sort();
    if crates.is_empty() {
        return Err("no workspace crate has a cdylib target and a feature fmi-export".into());
    }
    Ok(crates)
}

fn cargo_build(root: &Path, build: &Build, crates: &[String]) -> Result<(), String> {
    let mut cmd = match &build.zig_triple {
        Some(triple) => {
            let zigbuild = find_cargo_zigbuild(root)?;
            let glibc = build
                .policy
                .linux
                .as_ref()
                .map(|l| l.glibc)
                .unwrap_or(GLIBC_BASELINE);
            let mut c = Command::new(zigbuild);
            c.args(["zigbuild", "--target", &format!("{triple}.{glibc}")]);
            let venv_python = root.join(".venv/bin/python");
            if std::env::var_os("CARGO_ZIGBUILD_PYTHON_PATH").is_none() && venv_python.is_file() {
                c.env("CARGO_ZIGBUILD_PYTHON_PATH", venv_python);
            }
            c
        }
        None => {
            let mut c = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
            c.arg("build");
            c
        }
    };
    // zig reports its own include folders relative to the working directory when they lie
    // below it (a project-local .venv does), and cargo-zigbuild hands them to bindgen, whose
    // build scripts run elsewhere. Build from the filesystem root: zig strips only a working
    // directory that is a proper prefix ("/" + separator never is), so every path stays
    // absolute wherever the workspace lies (the temporary folder is no answer: a clone under
    // /tmp lies below it).
    let manifest = root.join("Cargo.toml");
    let filesystem_root = root.ancestors().last().unwrap_or(root);
    cmd.current_dir(filesystem_root)
        .arg("--manifest-path")
        .arg(&manifest)
        // the glue built into a shared library of its own (see model-description's feature
        // `fmu-library`): not turned on by `fmi-export`, which in-process tests use too
        .args([
            "--release",
            "--lib",
            "--features",
            "fmi-export,model-description/fmu-library",
        ]);
    for c in crates {
        cmd.args(["-p", c]);
    }
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run the build: {e}"))?;
    if !status.success() {
        let hint = if build.zig_triple.is_some() {
            " (zig missing? run `bash scripts/setup.sh`, or pass --native to build for this machine's glibc)"
        } else {
            ""
        };
        return Err(format!("cargo build failed ({status}){hint}"));
    }
    Ok(())
}

/// `<workspace>/target/tools/bin/cargo-zigbuild` (where scripts/setup.sh installs it), else
/// `cargo-zigbuild` on PATH.
fn find_cargo_zigbuild(root: &Path) -> Result<PathBuf, String> {
    let local = root.join("target/tools/bin/cargo-zigbuild");
    if local.is_file() {
        return Ok(local);
    }
    let on_path = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join("cargo-zigbuild"))
            .find(|p| p.is_file())
    });
    on_path.ok_or_else(|| {
        "cargo-zigbuild not found (in target/tools/bin or on PATH): run `bash scripts/setup.sh`, \
         or pass --native to build for this machine's glibc"
            .to_string()
    })
}
