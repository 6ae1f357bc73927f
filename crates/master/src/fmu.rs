//! FMU import: archive checks, loading and driving one FMI 2.0 co-simulation instance.
//!
//! What the `fmi` crate (0.8, feature `fmi2`) provides and is used here: unpacking the archive
//! into a temporary folder (`fmi::import::from_path`), loading the shared library
//! (libloading + bindgen'ed `Fmi2Binding`), `fmi2Instantiate` with the GUID and resource URL
//! (`Fmi2Import::instantiate_cs`), the typed calls (`Common`, `CoSimulation` traits),
//! get/set FMU state, and `fmi2FreeInstance` (+ freeing saved states) when the instance drops.
//!
//! What it lacks, written here by hand:
//! * the archive checks with clear errors before anything is loaded (file exists, is a zip,
//!   has modelDescription.xml, FMI version 2.0, co-simulation, GUID, platform binary
//!   `binaries/<platform>/<modelIdentifier>.so` present) -- `fmi` would fail later and less
//!   clearly;
//! * reading the modelDescription (units, dependencies): see [`crate::model_description`];
//! * a backend for its logger: fmi-sys routes the FMU's `fmi2CallbackLogger` into the `log`
//!   facade with the instance name as target and the status mapped to a level (OK -> info,
//!   Warning -> warn, Discard -> trace, Error/Fatal -> error); [`FmuLogger`] prints that.
//!   Limitation: fmi-sys 0.6 drops the log *category* and offers no way to pass our own
//!   callback struct, so the category cannot be shown without replacing the whole instance
//!   layer (not done);
//! * mapping integer/boolean values to the master's `f64` exchange, and
//!   [`FmuSlave`]'s single state slot for step retry.

use std::path::{Path, PathBuf};

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common, FmuState, InstanceCS};
use fmi::fmi2::Fmi2Error;
use fmi::traits::FmiStatus;

use crate::model_description::{ModelDescription, ModelDescriptionError};
use crate::slave::{FailStatus, ScalarType, Slave, SlaveError, StepStatus, VarRef};

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

/// A checked FMU archive (not yet unpacked or loaded).
#[derive(Debug, Clone)]
pub struct FmuArchive {
    pub path: PathBuf,
    pub model: ModelDescription,
}

impl FmuArchive {
    /// Opens and checks an FMU: zip, modelDescription.xml, FMI 2.0, co-simulation, GUID and the
    /// binary for this platform.
    pub fn open(path: &Path) -> Result<Self, FmuError> {
        use std::io::Read;
        let pb = path.to_path_buf();
        let file = std::fs::File::open(path).map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                FmuError::NotFound { path: pb.clone() }
            } else {
                FmuError::Io {
                    path: pb.clone(),
                    source,
                }
            }
        })?;
        let mut zip = zip::ZipArchive::new(file).map_err(|e| FmuError::NotAZip {
            path: pb.clone(),
            reason: e.to_string(),
        })?;
        let mut xml = String::new();
        {
            let mut entry = zip
                .by_name("modelDescription.xml")
                .map_err(|_| FmuError::NoModelDescription { path: pb.clone() })?;
            entry
                .read_to_string(&mut xml)
                .map_err(|source| FmuError::Io {
                    path: pb.clone(),
                    source,
                })?;
        }
        let model = ModelDescription::parse(&xml).map_err(|source| FmuError::ModelDescription {
            path: pb.clone(),
            source: Box::new(source),
        })?;
        if model.fmi_version.trim() != "2.0" {
            return Err(FmuError::UnsupportedVersion {
                path: pb,
                version: model.fmi_version.clone(),
            });
        }
        let Some(cs) = &model.co_simulation else {
            return Err(FmuError::NotCoSimulation { path: pb });
        };
        if model.guid.trim().is_empty() {
            return Err(FmuError::NoGuid { path: pb });
        }
        let (dir, suffix) = platform_binary_dir()?;
        let expected = format!("binaries/{dir}/{}{suffix}", cs.model_identifier);
        if zip.by_name(&expected).is_err() {
            let found: Vec<&str> = zip
                .file_names()
                .filter(|n| n.starts_with("binaries/") && !n.ends_with('/'))
                .collect();
            return Err(FmuError::NoBinary {
                path: pb,
                expected,
                found: found.join(", "),
            });
        }
        Ok(FmuArchive {
            path: path.to_path_buf(),
            model,
        })
    }

    /// Unpacks, loads the binary and instantiates one co-simulation instance.
    /// `logging_on` is passed to fmi2Instantiate (FMU debug logging).
    pub fn instantiate(&self, instance_name: &str, logging_on: bool) -> Result<FmuSlave, FmuError> {
        if instance_name.is_empty() || instance_name.contains('\0') {
            return Err(FmuError::InstanceName {
                name: instance_name.replace('\0', "\\0"),
                reason: "must be non-empty and contain no NUL".into(),
            });
        }
        let load_err = |reason: String| FmuError::Load {
            path: self.path.clone(),
            instance: instance_name.to_string(),
            reason,
        };
        let import = import_fmi2(&self.path).map_err(load_err)?;
        let instance = import
            .instantiate_cs(instance_name, false, logging_on)
            .map_err(|e| load_err(e.to_string()))?;
        let can_state = self
            .model
            .co_simulation
            .as_ref()
            .is_some_and(|c| c.can_get_and_set_fmu_state);
        let can_vary_step = self
            .model
            .co_simulation
            .as_ref()
            .is_some_and(|c| c.can_handle_variable_communication_step_size);
        Ok(FmuSlave {
            instance,
            saved: None,
            can_state,
            can_vary_step,
            name: instance_name.to_string(),
            _import: import,
        })
    }
}

/// One instantiated FMU. Dropping it calls fmi2FreeInstance (through the `fmi` crate) and then
/// removes the unpacked folder.
pub struct FmuSlave {
    // Field order matters: the instance (and its library) drop before the unpacked folder.
    instance: InstanceCS,
    saved: Option<FmuState>,
    can_state: bool,
    can_vary_step: bool,
    name: String,
    _import: Fmi2Import,
}

impl std::fmt::Debug for FmuSlave {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FmuSlave({})", self.name)
    }
}

fn fail(e: Fmi2Error) -> FailStatus {
    match e {
        Fmi2Error::Discard => FailStatus::Discard,
        Fmi2Error::Error => FailStatus::Error,
        Fmi2Error::Fatal => FailStatus::Fatal,
        other => FailStatus::Other(other.to_string()),
    }
}

impl FmuSlave {
    fn err(&self, call: &'static str, e: Fmi2Error) -> SlaveError {
        SlaveError {
            instance: self.name.clone(),
            call,
            status: fail(e),
        }
    }
    fn check<T>(&self, call: &'static str, r: Result<T, Fmi2Error>) -> Result<T, SlaveError> {
        r.map_err(|e| self.err(call, e))
    }
}

impl Slave for FmuSlave {
    fn name(&self) -> &str {
        &self.name
    }
    fn setup_experiment(&mut self, start_time: f64, stop_time: f64) -> Result<(), SlaveError> {
        let r = Common::setup_experiment(&mut self.instance, None, start_time, Some(stop_time));
        self.check("fmi2SetupExperiment", r).map(|_| ())
    }
    fn enter_initialization_mode(&mut self) -> Result<(), SlaveError> {
        let r = Common::enter_initialization_mode(&mut self.instance);
        self.check("fmi2EnterInitializationMode", r).map(|_| ())
    }
    fn exit_initialization_mode(&mut self) -> Result<(), SlaveError> {
        let r = Common::exit_initialization_mode(&mut self.instance);
        self.check("fmi2ExitInitializationMode", r).map(|_| ())
    }
    fn get(&mut self, vars: &[VarRef], out: &mut [f64]) -> Result<(), SlaveError> {
        for (v, o) in vars.iter().zip(out.iter_mut()) {
            let vr = [v.vr];
            match v.ty {
                ScalarType::Real => {
                    let mut x = [0.0];
                    let r = self.instance.get_real(&vr, &mut x);
                    self.check("fmi2GetReal", r)?;
                    *o = x[0];
                }
                ScalarType::Integer => {
                    let mut x = [0];
                    let r = self.instance.get_integer(&vr, &mut x);
                    self.check("fmi2GetInteger", r)?;
                    *o = f64::from(x[0]);
                }
                ScalarType::Boolean => {
                    let mut x = [0];
                    let r = self.instance.get_boolean(&vr, &mut x);
                    self.check("fmi2GetBoolean", r)?;
                    *o = if x[0] != 0 { 1.0 } else { 0.0 };
                }
            }
        }
        Ok(())
    }
    fn set(&mut self, vars: &[VarRef], values: &[f64]) -> Result<(), SlaveError> {
        for (v, &x) in vars.iter().zip(values) {
            let vr = [v.vr];
            match v.ty {
                ScalarType::Real => {
                    let r = self.instance.set_real(&vr, &[x]);
                    self.check("fmi2SetReal", r)?;
                }
                ScalarType::Integer => {
                    // values come from Integer outputs or validated parameters: exact
                    let r = self.instance.set_integer(&vr, &[x.round() as i32]);
                    self.check("fmi2SetInteger", r)?;
                }
                ScalarType::Boolean => {
                    let r = self.instance.set_boolean(&vr, &[i32::from(x != 0.0)]);
                    self.check("fmi2SetBoolean", r)?;
                }
            }
        }
        Ok(())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<StepStatus, SlaveError> {
        match self.instance.do_step(t, h, true) {
            Ok(_) => Ok(StepStatus::Ok),
            Err(Fmi2Error::Discard) => Ok(StepStatus::Discard),
            Err(e) => Err(self.err("fmi2DoStep", e)),
        }
    }
    fn can_save_state(&self) -> bool {
        self.can_state
    }
    fn can_vary_step(&self) -> bool {
        self.can_vary_step
    }
    fn save_state(&mut self) -> Result<(), SlaveError> {
        match &self.saved {
            Some(s) => {
                let r = self.instance.update_fmu_state(s).ok();
                self.check("fmi2GetFMUstate", r).map(|_| ())
            }
            None => {
                let r = self.instance.get_fmu_state();
                self.saved = Some(self.check("fmi2GetFMUstate", r)?);
                Ok(())
            }
        }
    }
    fn restore_state(&mut self) -> Result<(), SlaveError> {
        let Some(s) = &self.saved else {
            return Err(SlaveError {
                instance: self.name.clone(),
                call: "fmi2SetFMUstate",
                status: FailStatus::Other("no saved state".into()),
            });
        };
        let r = self.instance.set_fmu_state(s).ok();
        self.check("fmi2SetFMUstate", r).map(|_| ())
    }
    fn terminate(&mut self) -> Result<(), SlaveError> {
        let r = Common::terminate(&mut self.instance);
        self.check("fmi2Terminate", r).map(|_| ())
    }
}

/// A `log` backend that prints FMU messages (target = instance name) and the master's own
/// messages to stderr as `[level] instance: message`.
pub struct FmuLogger;

impl log::Log for FmuLogger {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::max_level()
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            let from_fmu = record.module_path() == Some("logger");
            if from_fmu {
                eprintln!(
                    "[{}] FMU instance '{}': {}",
                    record.level(),
                    record.target(),
                    record.args()
                );
            } else if record.target().starts_with("master") {
                eprintln!("[{}] {}", record.level(), record.args());
            }
        }
    }
    fn flush(&self) {}
}

static LOGGER: FmuLogger = FmuLogger;

/// Installs [`FmuLogger`] (once per process; later calls only change the level).
pub fn install_logger(level: log::LevelFilter) {
    let _ = log::set_logger(&LOGGER);
    log::set_max_level(level);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn write_zip(path: &Path, files: &[(&str, &[u8])]) {
        let f = std::fs::File::create(path).unwrap();
        let mut z = zip::ZipWriter::new(f);
        for (name, data) in files {
            z.start_file(*name, zip::write::SimpleFileOptions::default())
                .unwrap();
            z.write_all(data).unwrap();
        }
        z.finish().unwrap();
    }

    const MD: &str = crate::model_description::tests::MASS_SPRING;

    #[test]
    fn missing_file() {
        let e = FmuArchive::open(Path::new("/no/such/thing.fmu")).unwrap_err();
        assert!(matches!(e, FmuError::NotFound { .. }));
        assert!(e.to_string().contains("/no/such/thing.fmu"));
    }

    #[test]
    fn garbage_is_not_a_zip() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("bad.fmu");
        std::fs::write(&p, b"this is not a zip file at all").unwrap();
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(matches!(e, FmuError::NotAZip { .. }), "{e}");
        assert!(e.to_string().contains("bad.fmu"));
    }

    #[test]
    fn zip_checks() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("x.fmu");
        let (dir, suf) = platform_binary_dir().unwrap();
        let bin = format!("binaries/{dir}/MassSpring{suf}");

        write_zip(&p, &[("readme.txt", b"hi")]);
        assert!(matches!(
            FmuArchive::open(&p).unwrap_err(),
            FmuError::NoModelDescription { .. }
        ));

        write_zip(&p, &[("modelDescription.xml", b"<fmiModelDescription <<")]);
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(matches!(e, FmuError::ModelDescription { .. }), "{e}");

        let v1 = MD.replace("fmiVersion=\"2.0\"", "fmiVersion=\"3.0\"");
        write_zip(&p, &[("modelDescription.xml", v1.as_bytes()), (&bin, b"")]);
        let e = FmuArchive::open(&p).unwrap_err();
        assert!(matches!(e, FmuError::UnsupportedVersion { ref version, .. } if version == "3.0"));

        let me = MD.replace(
            "<CoSimulation modelIdentifier=\"MassSpring\" canGetAndSetFMUstate=\"true\"/>",
            "<ModelExchange modelIdentifier=\"MassSpring\"/>",
        );
        write_zip(&p, &[("modelDescription.xml", me.as_bytes()), (&bin, b"")]);
        assert!(matches!(
            FmuArchive::open(&p).unwrap_err(),
            FmuError::NotCoSimulation { .. }
        ));

        let ng = MD.replace("guid=\"{abc}\"", "guid=\"\"");
        write_zip(&p, &[("modelDescription.xml", ng.as_bytes()), (&bin, b"")]);
        assert!(matches!(
            FmuArchive::open(&p).unwrap_err(),
            FmuError::NoGuid { .. }
        ));

        write_zip(
            &p,
            &[
                ("modelDescription.xml", MD.as_bytes()),
                ("binaries/win64/MassSpring.dll", b""),
            ],
        );
        let e = FmuArchive::open(&p).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains(&bin) && msg.contains("binaries/win64/MassSpring.dll"),
            "{msg}"
        );

        write_zip(&p, &[("modelDescription.xml", MD.as_bytes()), (&bin, b"")]);
        let a = FmuArchive::open(&p).unwrap();
        assert_eq!(a.model.model_name, "MassSpring");
        // an empty "binary" cannot be loaded: a typed error, no panic
        let e = a.instantiate("ms", false).unwrap_err();
        assert!(matches!(e, FmuError::Load { .. }), "{e}");
        let e = a.instantiate("bad\0name", false).unwrap_err();
        assert!(matches!(e, FmuError::InstanceName { .. }));
    }
}

/// Attributes that FMI 2.0 allows but fmi-schema 0.8 (behind the `fmi` crate) rejects as
/// "unknown field"; fmpy writes the first on every variable of its container FMUs. They carry
/// nothing the master uses, so they are removed before the `fmi` crate parses the description.
const ATTRIBUTES_UNKNOWN_TO_FMI_SCHEMA: &[&str] = &["canHandleMultipleSetPerTimeInstant"];

fn strip_attributes(xml: &str, names: &[&str]) -> String {
    let mut out = xml.to_string();
    for name in names {
        let key = format!(" {name}=\"");
        while let Some(start) = out.find(&key) {
            let value_start = start + key.len();
            let Some(len) = out[value_start..].find('"') else {
                break;
            };
            out.replace_range(start..value_start + len + 1, "");
        }
    }
    out
}

/// `fmi::import::from_path`, but with the description cleaned of attributes fmi-schema 0.8
/// does not know (see [`ATTRIBUTES_UNKNOWN_TO_FMI_SCHEMA`]).
fn import_fmi2(path: &Path) -> Result<Fmi2Import, String> {
    use fmi::traits::FmiImport;
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut archive = zip::ZipArchive::new(file).map_err(|e| e.to_string())?;
    let dir = tempfile::Builder::new()
        .prefix("fmi-rs")
        .tempdir()
        .map_err(|e| e.to_string())?;
    archive.extract(dir.path()).map_err(|e| e.to_string())?;
    let xml = std::fs::read_to_string(dir.path().join("modelDescription.xml"))
        .map_err(|e| e.to_string())?;
    let xml = strip_attributes(&xml, ATTRIBUTES_UNKNOWN_TO_FMI_SCHEMA);
    Fmi2Import::new(dir, &xml).map_err(|e| e.to_string())
}

#[cfg(test)]
mod strip_tests {
    use super::strip_attributes;

    #[test]
    fn removes_only_the_named_attribute() {
        let xml = r#"<ScalarVariable canHandleMultipleSetPerTimeInstant="true" name="a" valueReference="0"/>"#;
        assert_eq!(
            strip_attributes(xml, &["canHandleMultipleSetPerTimeInstant"]),
            r#"<ScalarVariable name="a" valueReference="0"/>"#
        );
    }
}
