//! A minimal FMI 2.0 test host over the raw C ABI (fmi-sys bindings + libloading), used by the
//! end-to-end tests to drive the packaged FMUs exactly as a third-party host would.
//! End-to-end tests live in tests/tests/.

#![allow(clippy::missing_safety_doc)]

pub mod csv;

use std::ffi::{c_char, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use ffi::{fmi2CallbackFunctions, fmi2Component, fmi2Status};
pub use fmi_sys::fmi2 as ffi;

pub mod coach;
pub mod study;

extern "C" {
    fn test_logger(
        env: *mut c_void,
        instance: *const c_char,
        status: fmi2Status,
        category: *const c_char,
        format: *const c_char,
        ...
    );
}

/// One logged message as the host saw it.
#[derive(Clone, Debug)]
pub struct LogRecord {
    pub env: usize,
    pub instance: String,
    pub status: u32,
    pub category: Option<String>,
    pub format: Option<String>,
    pub message: String,
}

#[repr(C)]
struct TestEnv {
    record: unsafe extern "C" fn(
        *mut c_void,
        *const c_char,
        u32,
        *const c_char,
        *const c_char,
        *const c_char,
    ),
    log: *const Mutex<Vec<LogRecord>>,
}

unsafe fn opt_str(p: *const c_char) -> Option<String> {
    (!p.is_null()).then(|| CStr::from_ptr(p).to_string_lossy().into_owned())
}

unsafe extern "C" fn record(
    env: *mut c_void,
    instance: *const c_char,
    status: u32,
    category: *const c_char,
    format: *const c_char,
    message: *const c_char,
) {
    let e = &*(env as *const TestEnv);
    if let Ok(mut log) = (*e.log).lock() {
        log.push(LogRecord {
            env: env as usize,
            instance: opt_str(instance).unwrap_or_default(),
            status,
            category: opt_str(category),
            format: opt_str(format),
            message: opt_str(message).unwrap_or_default(),
        });
    }
}

/// An unpacked FMU with its binary loaded.
pub struct TestFmu {
    pub dir: tempfile::TempDir,
    pub binding: ffi::Fmi2Binding,
    pub model_description: String,
    pub guid: String,
    pub identifier: String,
}

fn attr(xml: &str, key: &str) -> Option<String> {
    let start = xml.find(&format!(" {key}=\""))? + key.len() + 3;
    let end = xml[start..].find('"')? + start;
    Some(xml[start..end].to_string())
}

impl TestFmu {
    /// Open `dist/<name>.fmu` of the workspace.
    pub fn open_dist(name: &str) -> Result<Self, String> {
        let path = workspace_root().join("dist").join(format!("{name}.fmu"));
        Self::open(&path)
    }

    pub fn open(path: &Path) -> Result<Self, String> {
        let file = std::fs::File::open(path).map_err(|e| {
            format!(
                "{}: {e} (build the FMUs first: cargo run --release -p model-description --bin package-fmus)",
                path.display()
            )
        })?;
        let mut zip = zip::ZipArchive::new(file).map_err(|e| e.to_string())?;
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        zip.extract(dir.path()).map_err(|e| e.to_string())?;
        let model_description = std::fs::read_to_string(dir.path().join("modelDescription.xml"))
            .map_err(|e| e.to_string())?;
        let guid = attr(&model_description, "guid").ok_or("no guid")?;
        let identifier = attr(&model_description, "modelIdentifier").ok_or("no identifier")?;
        let lib = dir
            .path()
            .join("binaries/linux64")
            .join(format!("{identifier}.so"));
        // SAFETY: loading the FMU's binary, as any host does.
        let binding = unsafe { ffi::Fmi2Binding::new(&lib) }.map_err(|e| e.to_string())?;
        Ok(TestFmu {
            dir,
            binding,
            model_description,
            guid,
            identifier,
        })
    }

    /// Value reference of a variable, read from modelDescription.xml.
    pub fn vr(&self, name: &str) -> Option<u32> {
        let key = format!("name=\"{name}\" valueReference=\"");
        let start = self.model_description.find(&key)? + key.len();
        let end = self.model_description[start..].find('"')? + start;
        self.model_description[start..end].parse().ok()
    }

    pub fn resource_uri(&self) -> String {
        format!("file://{}/resources", self.dir.path().display())
    }

    /// Instantiate with a logger that records every message.
    pub fn instantiate(&self, name: &str) -> Result<Instance<'_>, String> {
        self.instantiate_with_guid(name, &self.guid.clone())
    }

    pub fn instantiate_with_guid(&self, name: &str, guid: &str) -> Result<Instance<'_>, String> {
        let log = Arc::new(Mutex::new(Vec::new()));
        let env = Box::new(TestEnv {
            record,
            log: Arc::as_ptr(&log),
        });
        let env_ptr = Box::into_raw(env);
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(test_logger),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: env_ptr as *mut c_void,
        });
        let cname = CString::new(name).map_err(|e| e.to_string())?;
        let cguid = CString::new(guid).map_err(|e| e.to_string())?;
        let res = CString::new(self.resource_uri()).map_err(|e| e.to_string())?;
        // SAFETY: arguments live for the call; callbacks and env live as long as the instance.
        let component = unsafe {
            self.binding.fmi2Instantiate(
                cname.as_ptr(),
                ffi::fmi2Type_fmi2CoSimulation,
                cguid.as_ptr(),
                res.as_ptr(),
                &*callbacks,
                0,
                0,
            )
        };
        let instance = Instance {
            fmu: self,
            component,
            callbacks,
            env: env_ptr,
            log,
        };
        if component.is_null() {
            let msgs = instance.messages().join(" | ");
            return Err(format!("fmi2Instantiate returned NULL: {msgs}"));
        }
        Ok(instance)
    }
}

pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The python of the venv with fmpy and the SSP hosts (RAIL_PYTHON, which scripts/test.sh sets);
/// `None`, with a note on stderr, when it is not set, so a plain `cargo test` skips what needs it.
pub fn rail_python() -> Option<PathBuf> {
    let p = std::env::var_os("RAIL_PYTHON").map(PathBuf::from);
    if p.is_none() {
        missing_external("RAIL_PYTHON not set: run scripts/test.sh (it points it to the venv with fmpy, libcosimpy and ecospy)");
    }
    p
}

/// A test that needs something outside the crate (a Python with fmpy, files the test command
/// prepares) skips, saying why, under a plain `cargo test`. Under scripts/test.sh, which sets
/// RAIL_REQUIRE_EXTERNAL, it fails instead: the test command cannot pass without running it.
#[allow(clippy::panic)]
pub fn missing_external(what: &str) {
    if std::env::var_os("RAIL_REQUIRE_EXTERNAL").is_some() {
        panic!("{what} (RAIL_REQUIRE_EXTERNAL is set: the test must run)");
    }
    eprintln!("skipped: {what}");
}

/// One instance; freed on drop.
pub struct Instance<'a> {
    pub fmu: &'a TestFmu,
    pub component: fmi2Component,
    #[allow(dead_code)]
    callbacks: Box<fmi2CallbackFunctions>,
    env: *mut TestEnv,
    pub log: Arc<Mutex<Vec<LogRecord>>>,
}

// SAFETY: an FMU instance may be used from another thread as long as calls are not concurrent;
// the glue documents no thread affinity.
unsafe impl Send for Instance<'_> {}

impl Instance<'_> {
    pub fn env_ptr(&self) -> usize {
        self.env as usize
    }

    pub fn records(&self) -> Vec<LogRecord> {
        self.log.lock().map(|l| l.clone()).unwrap_or_default()
    }

    pub fn messages(&self) -> Vec<String> {
        self.records().into_iter().map(|r| r.message).collect()
    }

    pub fn b(&self) -> &ffi::Fmi2Binding {
        &self.fmu.binding
    }

    pub fn vr(&self, name: &str) -> u32 {
        self.fmu.vr(name).unwrap_or(u32::MAX)
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        unsafe {
            self.b().fmi2SetupExperiment(
                self.component,
                0,
                0.0,
                start,
                i32::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        }
    }

    pub fn enter_init(&self) -> fmi2Status {
        unsafe { self.b().fmi2EnterInitializationMode(self.component) }
    }

    pub fn exit_init(&self) -> fmi2Status {
        unsafe { self.b().fmi2ExitInitializationMode(self.component) }
    }

    /// setupExperiment + enter + exit initialisation.
    pub fn initialize(&self, start: f64) -> fmi2Status {
        let s = self.setup(start, None);
        if s != ffi::fmi2Status_fmi2OK {
            return s;
        }
        let s = self.enter_init();
        if s != ffi::fmi2Status_fmi2OK {
            return s;
        }
        self.exit_init()
    }

    pub fn set_real(&self, name: &str, value: f64) -> fmi2Status {
        let vr = [self.vr(name)];
        unsafe { self.b().fmi2SetReal(self.component, vr.as_ptr(), 1, &value) }
    }

    pub fn set_real_vr(&self, vr: u32, value: f64) -> fmi2Status {
        unsafe { self.b().fmi2SetReal(self.component, &vr, 1, &value) }
    }

    pub fn get_real(&self, name: &str) -> (fmi2Status, f64) {
        self.get_real_vr(self.vr(name))
    }

    pub fn get_real_vr(&self, vr: u32) -> (fmi2Status, f64) {
        let mut v = f64::NAN;
        let s = unsafe { self.b().fmi2GetReal(self.component, &vr, 1, &mut v) };
        (s, v)
    }

    pub fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        unsafe { self.b().fmi2DoStep(self.component, t, h, 1) }
    }

    pub fn reset(&self) -> fmi2Status {
        unsafe { self.b().fmi2Reset(self.component) }
    }

    pub fn terminate(&self) -> fmi2Status {
        unsafe { self.b().fmi2Terminate(self.component) }
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        unsafe {
            if !self.component.is_null() {
                self.fmu.binding.fmi2FreeInstance(self.component);
            }
            drop(Box::from_raw(self.env));
        }
    }
}

pub const OK: fmi2Status = ffi::fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = ffi::fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = ffi::fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = ffi::fmi2Status_fmi2Error;
