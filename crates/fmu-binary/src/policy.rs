//! What a binary in a platform folder must be: the right format and architecture, the fmi2
//! exports, and on Linux the portability baseline.

use std::fmt;

use crate::inspect::{Architecture, BinaryFormat, BinaryInfo};
use crate::platform::Platform;
use crate::version::SymbolVersion;

/// glibc baseline of the Linux binaries: manylinux2014's (CentOS 7), so they load on RHEL 7-9,
/// SLES 12/15, Ubuntu 14.04 and later.
pub const GLIBC_BASELINE: SymbolVersion = SymbolVersion::new(2, 17);

/// Newest libgcc_s symbol version allowed (GCC 4.8, the compiler of CentOS 7; manylinux2014).
pub const GCC_BASELINE: SymbolVersion = SymbolVersion::new(4, 8);

/// Libraries a portable Linux binary may need: glibc's own libraries, the loaders, libgcc_s.
pub const ALLOWED_LINUX_LIBRARIES: [&str; 8] = [
    "libc.so.6",
    "libm.so.6",
    "libpthread.so.0",
    "libdl.so.2",
    "libgcc_s.so.1",
    "ld-linux-x86-64.so.2",
    "ld-linux-aarch64.so.1",
    "ld-linux.so.2",
];

/// The Linux portability rules.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinuxPolicy {
    /// Newest `GLIBC_x.y` symbol version allowed.
    pub glibc: SymbolVersion,
    /// Newest `GCC_x.y` (libgcc_s) symbol version allowed.
    pub gcc: SymbolVersion,
    pub allowed_libraries: Vec<String>,
}

impl LinuxPolicy {
    /// The allowed libraries and libgcc_s baseline with this glibc baseline.
    pub fn with_glibc(glibc: SymbolVersion) -> Self {
        Self {
            glibc,
            gcc: GCC_BASELINE,
            allowed_libraries: ALLOWED_LINUX_LIBRARIES.map(String::from).to_vec(),
        }
    }
}

impl Default for LinuxPolicy {
    fn default() -> Self {
        Self::with_glibc(GLIBC_BASELINE)
    }
}

/// What [`check_binary`] asks of a binary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Policy {
    /// Linux (ELF) portability rules; `None` checks only format, architecture and exports
    /// (a binary built for the build machine's own glibc).
    pub linux: Option<LinuxPolicy>,
}

impl Policy {
    /// The portability baseline: glibc [`GLIBC_BASELINE`] and the allowed libraries.
    pub fn baseline() -> Self {
        Self {
            linux: Some(LinuxPolicy::default()),
        }
    }

    /// Format, architecture and exports only.
    pub fn native() -> Self {
        Self { linux: None }
    }
}

impl Default for Policy {
    fn default() -> Self {
        Self::baseline()
    }
}

/// One reason a binary does not fit its platform folder or the policy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Problem {
    WrongFormat {
        platform: Platform,
        found: BinaryFormat,
    },
    WrongArchitecture {
        platform: Platform,
        found: Architecture,
    },
    MissingExports {
        missing: Vec<String>,
        required: usize,
    },
    GlibcTooNew {
        needed: SymbolVersion,
        baseline: SymbolVersion,
        /// The symbol versions above the baseline, e.g. `GLIBC_2.35`.
        versions: Vec<String>,
    },
    SymbolVersionNotAllowed {
        library: String,
        version: String,
    },
    LibraryNotAllowed(String),
    SearchPath {
        kind: &'static str,
        value: String,
    },
    /// FMU level: a file in a platform folder that is not `<modelIdentifier>.<ext>`.
    UnexpectedFile {
        expected: Vec<String>,
    },
    /// FMU level: a folder under `binaries/` that is no known platform.
    UnknownPlatform(String),
    /// FMU level: a model identifier without a binary in a platform folder that has binaries.
    MissingBinary {
        platform: Platform,
        file: String,
    },
    /// FMU level: the file cannot be read as a shared library.
    Unreadable(String),
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Problem::WrongFormat { platform, found } => write!(
                f,
                "is a {found} binary, but {platform} needs {}",
                platform.format()
            ),
            Problem::WrongArchitecture { platform, found } => {
                let allowed: Vec<String> = platform
                    .architectures()
                    .iter()
                    .map(|a| a.to_string())
                    .collect();
                write!(
                    f,
                    "is built for {found}, but {platform} needs {}",
                    allowed.join(" or ")
                )
            }
            Problem::MissingExports { missing, required } if missing.len() == *required => {
                write!(f, "exports none of the {required} FMI 2.0 functions")
            }
            Problem::MissingExports { missing, required } => write!(
                f,
                "does not export {} of the {required} FMI 2.0 functions: {}",
                missing.len(),
                missing.join(", ")
            ),
            Problem::GlibcTooNew {
                needed,
                baseline,
                versions,
            } => write!(
                f,
                "needs glibc {needed}, newer than the baseline {baseline} ({})",
                versions.join(", ")
            ),
            Problem::SymbolVersionNotAllowed { library, version } => {
                write!(
                    f,
                    "needs symbol version {version} of {library}, which is not allowed"
                )
            }
            Problem::LibraryNotAllowed(lib) => write!(
                f,
                "needs {lib}, which is not one of glibc's own libraries or libgcc_s"
            ),
            Problem::SearchPath { kind, value } => {
                write!(f, "has {kind} '{value}' (a portable binary has none)")
            }
            Problem::UnexpectedFile { expected } => write!(
                f,
                "is not a model binary of this FMU (expected {})",
                expected.join(" or ")
            ),
            Problem::UnknownPlatform(folder) => {
                let known: Vec<&str> = Platform::ALL.iter().map(|p| p.folder()).collect();
                write!(
                    f,
                    "platform folder '{folder}' is none of {}",
                    known.join(", ")
                )
            }
            Problem::MissingBinary { platform, file } => {
                write!(f, "binaries/{platform}/{file} is missing")
            }
            Problem::Unreadable(reason) => f.write_str(reason),
        }
    }
}

/// Every problem of `info` as a binary of `platform` that must export `required_exports`.
/// An empty list means it fits.
pub fn check_binary(
    info: &BinaryInfo,
    platform: Platform,
    required_exports: &[&str],
    policy: &Policy,
) -> Vec<Problem> {
    let mut problems = Vec::new();
    if info.format != platform.format() {
        problems.push(Problem::WrongFormat {
            platform,
            found: info.format,
        });
        // Architecture and exports of a binary of the wrong kind say nothing more.
        return problems;
    }
    for image in &info.images {
        if !platform.architectures().contains(&image.architecture) {
            problems.push(Problem::WrongArchitecture {
                platform,
                found: image.architecture.clone(),
            });
        }
    }
    let missing = info.missing_exports(required_exports);
    if !missing.is_empty() {
        problems.push(Problem::MissingExports {
            missing: missing.into_iter().map(String::from).collect(),
            required: required_exports.len(),
        });
    }
    if let (BinaryFormat::Elf, Some(linux)) = (info.format, &policy.linux) {
        check_linux(info, linux, &mut problems);
    }
    problems
}

fn check_linux(info: &BinaryInfo, policy: &LinuxPolicy, problems: &mut Vec<Problem>) {
    for image in &info.images {
        let mut too_new = Vec::new();
        for need in &image.version_needs {
            let glibc = SymbolVersion::from_symbol_version(&need.version, "GLIBC_");
            let gcc = SymbolVersion::from_symbol_version(&need.version, "GCC_");
            match (glibc, gcc) {
                (Some(v), _) if v > policy.glibc => too_new.push(need.version.clone()),
                (Some(_), _) => {}
                (None, Some(v)) if v <= policy.gcc => {}
                _ => problems.push(Problem::SymbolVersionNotAllowed {
                    library: need.library.clone(),
                    version: need.version.clone(),
                }),
            }
        }
        if let Some(needed) = image.newest_glibc().filter(|v| *v > policy.glibc) {
            too_new.sort();
            too_new.dedup();
            problems.push(Problem::GlibcTooNew {
                needed,
                baseline: policy.glibc,
                versions: too_new,
            });
        }
        for lib in &image.needed_libraries {
            if !policy.allowed_libraries.iter().any(|a| a == lib) {
                problems.push(Problem::LibraryNotAllowed(lib.clone()));
            }
        }
        for (kind, value) in &image.search_paths {
            problems.push(Problem::SearchPath {
                kind,
                value: value.clone(),
            });
        }
    }
}
