//! FMU import: archive checks, unpacking and loading once, instantiating and driving FMI 2.0
//! co-simulation instances.
//!
//! * [`FmuArchive`] ([`archive`]): the checks with clear errors before anything is unpacked
//!   (file exists, is a zip, has modelDescription.xml, FMI version 2.0, co-simulation, GUID,
//!   platform binary `binaries/<platform>/<modelIdentifier>.so` present) and the parsed
//!   modelDescription ([`crate::model_description`], read once).
//! * [`PreparedFmu`] ([`prepared`]): the archive unpacked into a temporary folder and its
//!   binary loaded, once; shared (`Arc`) by every instance of a system and every run of a run
//!   set, across worker threads. An FMU that declares `canBeInstantiatedOnlyOncePerProcess`
//!   gets a private copy per instance instead (a separate file is a separate library image).
//! * [`FmuSlave`] ([`instance`]): one instance, driven through the FMI 2.0 C functions loaded
//!   with libloading by their fmi-sys types (module `library`); implements [`crate::slave::Slave`].
//! * [`FmuLogger`] ([`logger`]): the FMU logger callback (C, defensive against NULL strings,
//!   `%n` formats and endless messages) routes messages into the `log` facade with the
//!   instance name as target; this backend prints them with their category.
//! * [`extract`]: archive limits ([`ArchiveLimits`]), refused entries, locked extraction
//!   folders that a later process removes when their owner died.
//!
//! Why not the `fmi` crate for loading and calling: it parses the modelDescription a second time
//! with fmi-schema, which rejects attributes FMI 2.0 allows (`canHandleMultipleSetPerTimeInstant`,
//! written by fmpy on container FMUs), and each of its imports owns its own unpacked folder.
//! Driving the C functions from our own parse reads the description once and lets many instances
//! share one unpacked, loaded FMU.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::model_description::ModelDescriptionError;

pub mod archive;
pub mod extract;
pub mod instance;
mod library;
pub mod logger;
pub mod prepared;

pub use archive::FmuArchive;
pub use extract::{remove_stale_extractions, ArchiveLimits};
pub use instance::FmuSlave;
pub use logger::{install_logger, FmuLogger};
pub use prepared::PreparedFmu;

/// Why an FMU could not be opened or instantiated.
#[derive(Debug, thiserror::Error)]
pub enum FmuError {
    #[error("FMU '{path}' not found")]
    NotFound { path: PathBuf },
    #[error("cannot read FMU '{path}': {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("FMU '{path}' is not a valid zip archive: {reason}")]
    NotAZip { path: PathBuf, reason: String },
    #[error("FMU '{path}' has no modelDescription.xml at the top level")]
    NoModelDescription { path: PathBuf },
    #[error("FMU '{path}': modelDescription.xml: {source}")]
    ModelDescription {
        path: PathBuf,
        #[source]
        source: Box<ModelDescriptionError>,
    },
    #[error("FMU '{path}' is FMI version '{version}', only 2.0 is supported")]
    UnsupportedVersion { path: PathBuf, version: String },
    #[error("FMU '{path}' does not support co-simulation (no <CoSimulation> element)")]
    NotCoSimulation { path: PathBuf },
    #[error("FMU '{path}' has an empty guid")]
    NoGuid { path: PathBuf },
    #[error(
        "FMU '{path}' has no binary for this platform: expected '{expected}', found [{found}]"
    )]
    NoBinary {
        path: PathBuf,
        expected: String,
        found: String,
    },
    #[error("platform {os}/{arch} has no FMI 2.0 binary folder")]
    UnsupportedPlatform { os: String, arch: String },
    #[error("instance name '{name}' is not valid: {reason}")]
    InstanceName { name: String, reason: String },
    #[error(
        "FMU '{path}' is refused: {what}, more than the limit of {limit} (raise it with \
         the environment variable {variable})"
    )]
    TooLarge {
        path: PathBuf,
        what: String,
        limit: u64,
        variable: &'static str,
    },
    #[error("FMU '{path}' is refused: entry \"{entry}\": {reason}")]
    UnsafeEntry {
        path: PathBuf,
        entry: String,
        reason: String,
    },
    #[error(
        "environment variable {variable}='{}' is not a non-negative integer",
        crate::show::text(.value)
    )]
    LimitSetting {
        variable: &'static str,
        value: String,
    },
    #[error("FMU '{path}': cannot unpack it: {reason}")]
    Unpack { path: PathBuf, reason: String },
    #[error("FMU '{path}': cannot load or instantiate '{instance}': {reason}")]
    Load {
        path: PathBuf,
        instance: String,
        reason: String,
    },
}

/// FMI 2.0 platform folder and shared library suffix for this machine.
pub fn platform_binary_dir() -> Result<(&'static str, &'static str), FmuError> {
    let dir = match (std::env::consts::OS, std::env::consts::ARCH) {
        ("linux", "x86_64") | ("linux", "aarch64") => "linux64",
        ("linux", "x86") => "linux32",
        ("windows", "x86_64") => "win64",
        ("windows", "x86") => "win32",
        ("macos", _) => "darwin64",
        (os, arch) => {
            return Err(FmuError::UnsupportedPlatform {
                os: os.into(),
                arch: arch.into(),
            })
        }
    };
    Ok((dir, std::env::consts::DLL_SUFFIX))
}

static EXTRACTIONS: AtomicU64 = AtomicU64::new(0);

/// How many times this process has unpacked an FMU archive (every [`PreparedFmu`], plus the
/// private copies of FMUs that can be instantiated only once per process). For diagnostics and
/// tests: a prepared run set unpacks each FMU of its system once, however many runs it has.
pub fn extraction_count() -> u64 {
    EXTRACTIONS.load(Ordering::Relaxed)
}

fn count_extraction() {
    EXTRACTIONS.fetch_add(1, Ordering::Relaxed);
}
