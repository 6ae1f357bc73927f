//! The FMI 2.0 co-simulation C API, written once. `export_fmus!` (invoked by each FMU crate,
//! behind its `fmi-export` feature) defines the `fmi2*` symbols as one-line forwards to the
//! functions here. One binary may carry several models; `fmi2Instantiate` picks the model by
//! GUID, so the same library is shipped in each model's FMU under its modelIdentifier.
//!
//! Every function catches panics (none crosses the C boundary; the panic's message goes to
//! the host's logger, not to the host process's stderr), checks its pointers, and reports
//! failures through the host's logger with the message passed as a `%s` argument and every
//! '#' doubled (FMI 2.0 reserves '#' for variable references in log messages).

#![allow(clippy::missing_safety_doc)]

use std::ffi::{c_char, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use ffi::{
    fmi2Boolean, fmi2CallbackFunctions, fmi2CallbackLogger, fmi2Component,
    fmi2ComponentEnvironment, fmi2FMUstate, fmi2Integer, fmi2Real, fmi2Status, fmi2StatusKind,
    fmi2String, fmi2Type, fmi2ValueReference,
};
pub use fmi_sys::fmi2 as ffi;

use crate::component::{Component, LogSink, Snapshot, Status};
use crate::erased::{ErasedModel, Typed};
use crate::model::{FmuModel, InstanceContext, ModelError};
use crate::xml::{self, DeclarationError};

pub const FMI2_OK: fmi2Status = ffi::fmi2Status_fmi2OK;
pub const FMI2_WARNING: fmi2Status = ffi::fmi2Status_fmi2Warning;
pub const FMI2_DISCARD: fmi2Status = ffi::fmi2Status_fmi2Discard;
pub const FMI2_ERROR: fmi2Status = ffi::fmi2Status_fmi2Error;
pub const FMI2_FATAL: fmi2Status = ffi::fmi2Status_fmi2Fatal;

fn to_c(status: Status) -> fmi2Status {
    match status {
        Status::Ok => FMI2_OK,
        Status::Warning => FMI2_WARNING,
        Status::Discard => FMI2_DISCARD,
        Status::Error => FMI2_ERROR,
        Status::Fatal => FMI2_FATAL,
    }
}

/// One model a binary can instantiate.
pub struct ModelEntry {
    pub name: &'static str,
    pub create: fn(&InstanceContext) -> Result<Box<dyn ErasedModel>, ModelError>,
    pub describe: fn() -> Result<xml::Description, DeclarationError>,
    pub document: fn() -> Result<String, DeclarationError>,
    pub resources: &'static [(&'static str, &'static [u8])],
}

fn create_erased<M: FmuModel>(ctx: &InstanceContext) -> Result<Box<dyn ErasedModel>, ModelError> {
    Ok(Box::new(Typed::<M>::new(ctx)?))
}

/// The models of one binary, with their GUIDs worked out once: fmi2Instantiate compares the
/// host's GUID with each model's, which is a hash of its rendered model description (about
/// 2 M instructions per model), and a run set instantiates the same binary for every run.
pub struct Registry {
    pub models: &'static [ModelEntry],
    guids: std::sync::OnceLock<Vec<Result<String, String>>>,
}

impl Registry {
    pub const fn new(models: &'static [ModelEntry]) -> Self {
        Registry {
            models,
            guids: std::sync::OnceLock::new(),
        }
    }

    /// Each model's GUID, or why its description cannot be generated (in `models`' order).
    fn guids(&self) -> &[Result<String, String>] {
        self.guids.get_or_init(|| {
            self.models
                .iter()
                .map(|e| {
                    // a model whose description panics is refused on its own, not every model
                    // of the binary at every instantiation
                    match catch_unwind(e.describe) {
                        Ok(d) => d.map(|d| d.guid).map_err(|err| err.to_string()),
                        Err(payload) => Err(format!(
                            "internal error: the description of model '{}' panicked ({})",
                            e.name,
                            panic_text(payload.as_ref())
                        )),
                    }
                })
                .collect()
        })
    }
}

impl ModelEntry {
    pub const fn of<M: FmuModel>() -> Self {
        ModelEntry {
            name: M::INFO.name,
            create: create_erased::<M>,
            describe: xml::model_description::<M>,
            document: crate::doc::documentation_html::<M>,
            resources: M::INFO.resources,
        }
    }
}

/// What the packager reads from a binary (via `rfmi_manifest`).
#[derive(Serialize, Deserialize, Debug)]
pub struct PackagedModel {
    pub identifier: String,
    pub model_description_xml: String,
    pub documentation_html: String,
    pub resources: Vec<(String, Vec<u8>)>,
}

/// Build the manifest (bincode of `Vec<Result<PackagedModel, String>>`).
pub fn manifest(registry: &[ModelEntry]) -> Vec<u8> {
    let models: Vec<Result<PackagedModel, String>> = registry
        .iter()
        .map(|e| {
            let d = (e.describe)().map_err(|err| err.to_string())?;
            let html = (e.document)().map_err(|err| err.to_string())?;
            Ok(PackagedModel {
                identifier: e.name.to_string(),
                model_description_xml: d.xml,
                documentation_html: html,
                resources: e
                    .resources
                    .iter()
                    .map(|(p, b)| (p.to_string(), b.to_vec()))
                    .collect(),
            })
        })
        .collect();
    bincode::serialize(&models).unwrap_or_default()
}

/// Logger that forwards to the host's fmi2CallbackLogger.
struct HostLogger {
    callback: fmi2CallbackLogger,
    env: SendPtr,
    instance_name: CString,
}

struct SendPtr(fmi2ComponentEnvironment);
// SAFETY: the environment pointer is opaque to us; we only hand it back to the host's logger,
// which the standard requires to accept it from the thread that calls into the FMU.
unsafe impl Send for SendPtr {}

fn c_string_lossy(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// A log message as the host's logger receives it: FMI 2.0 (2.1.5) reserves '#' for variable
/// references such as `#r12#`, so a literal '#' is written '##'; NUL bytes become spaces.
pub fn host_message(message: &str) -> CString {
    c_string_lossy(&message.replace('#', "##"))
}

/// Most value references (or log categories) one call may pass. FMI sets no bound, but a
/// host passing a wrong count (e.g. 2^31-1) must get fmi2Error, not a read past its arrays or
/// an allocation abort; 2^20 is far above any model here (the largest has 63 variables).
pub const MAX_VALUES_PER_CALL: usize = 1 << 20;

/// Largest serialised FMU state accepted (256 MiB; the largest here, a bogie with a fine
/// contact table, is well below 1 MiB).
pub const MAX_STATE_BYTES: usize = 1 << 28;

fn too_many(cc: &mut CComponent, call: &str, n: usize) -> Status {
    cc.component.error(&format!(
        "{call}: {n} values in one call is more than the {MAX_VALUES_PER_CALL} this FMU accepts \
         (a wrong count?)"
    ))
}

impl LogSink for HostLogger {
    fn log(&mut self, status: Status, category: &str, message: &str) {
        if let Some(cb) = self.callback {
            let category = c_string_lossy(category);
            let message = host_message(message);
            // SAFETY: a logger the host gave us; the message goes in as a "%s" argument, never
            // as the format string, so '%' in a message cannot be misread.
            unsafe {
                cb(
                    self.env.0,
                    self.instance_name.as_ptr(),
                    to_c(status),
                    category.as_ptr(),
                    c"%s".as_ptr(),
                    message.as_ptr(),
                );
            }
        }
    }
}

/// The heap object behind an fmi2Component.
pub struct CComponent {
    component: Component,
    /// Cached bytes of the last serialised state (size query, then serialise), by the
    /// state's [`Snapshot::id`].
    serialized: Option<(u64, Vec<u8>)>,
    /// Booleans converted from/to fmi2Boolean, kept so that the get/set path allocates only
    /// when a call passes more values than any before.
    booleans: Vec<bool>,
}

unsafe fn str_arg<'a>(p: *const c_char) -> Option<&'a str> {
    if p.is_null() {
        None
    } else {
        CStr::from_ptr(p).to_str().ok()
    }
}

/// Turn a resource location URI into a path. Accepts file:///abs, file:/abs and
/// file://localhost/abs with %-escapes; other schemes are ignored (None).
pub fn resource_path(uri: &str) -> Option<PathBuf> {
    let rest = uri
        .strip_prefix("file://localhost")
        .or_else(|| uri.strip_prefix("file://"))
        .or_else(|| uri.strip_prefix("file:"))?;
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    let path = String::from_utf8(out).ok()?;
    Some(PathBuf::from(path))
}

/// Log through the callback before a component exists (instantiate failures).
unsafe fn early_log(functions: *const fmi2CallbackFunctions, name: *const c_char, msg: &str) {
    if functions.is_null() {
        return;
    }
    let f = &*functions;
    if let Some(cb) = f.logger {
        let message = host_message(msg);
        let fallback = c"";
        let name = if name.is_null() {
            fallback.as_ptr()
        } else {
            name
        };
        cb(
            f.componentEnvironment,
            name,
            FMI2_ERROR,
            c"logStatusError".as_ptr(),
            c"%s".as_ptr(),
            message.as_ptr(),
        );
    }
}

#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate(
    registry: &Registry,
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    guid: fmi2String,
    resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    install_panic_hook();
    call_count::enter();
    let result = catch_unwind(AssertUnwindSafe(|| {
        let fail = |msg: &str| {
            early_log(functions, instance_name, &format!("fmi2Instantiate: {msg}"));
            std::ptr::null_mut()
        };
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        let Some(name) = str_arg(instance_name).filter(|s| !s.is_empty()) else {
            return fail("instanceName must be a non-empty string");
        };
        if fmu_type != ffi::fmi2Type_fmi2CoSimulation {
            return fail("this FMU supports co-simulation only (fmuType must be fmi2CoSimulation)");
        }
        let Some(guid) = str_arg(guid) else {
            return fail("fmuGUID is missing");
        };
        let mut entry = None;
        for (e, known) in registry.models.iter().zip(registry.guids()) {
            match known {
                Ok(g) if g == guid => {
                    entry = Some(e);
                    break;
                }
                Ok(_) => {}
                Err(err) => return fail(err),
            }
        }
        let Some(entry) = entry else {
            let known: Vec<&str> = registry.models.iter().map(|e| e.name).collect();
            return fail(&format!(
                "GUID {guid} matches none of the models in this binary ({}); \
                 the modelDescription.xml and the binary are from different builds",
                known.join(", ")
            ));
        };
        let ctx = InstanceContext {
            instance_name: name.to_string(),
            resource_dir: str_arg(resource_location).and_then(resource_path),
        };
        let model = match (entry.create)(&ctx) {
            Ok(m) => m,
            Err(e) => return fail(&e.to_string()),
        };
        let f = &*functions;
        let logger = HostLogger {
            callback: f.logger,
            env: SendPtr(f.componentEnvironment),
            instance_name: c_string_lossy(name),
        };
        let component = Component::new(model, ctx, Box::new(logger), logging_on != 0);
        let c = Box::into_raw(Box::new(CComponent {
            component,
            serialized: None,
            booleans: Vec::new(),
        })) as fmi2Component;
        live_instances().push(c as usize);
        c
    }));
    call_count::leave();
    result.unwrap_or_else(|payload| {
        let msg = format!(
            "fmi2Instantiate: internal error (panic caught at the C boundary: {}); no instance \
             was created",
            panic_text(payload.as_ref())
        );
        let logged = catch_unwind(AssertUnwindSafe(|| {
            let has_logger = !functions.is_null() && (*functions).logger.is_some();
            if has_logger {
                early_log(functions, instance_name, &msg);
            }
            has_logger
        }));
        if !matches!(logged, Ok(true)) {
            report_on_stderr(&msg);
        }
        std::ptr::null_mut()
    })
}

/// A panic the host's logger cannot be told of (no logger, the report itself panicked, the
/// instance being freed): written to the process's stderr, as the standard hook would (the
/// hook of an FMU binary is silent, [`call_count`]); a failed write is ignored.
fn report_on_stderr(message: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "FMU: {message}");
}

/// The instances this binary gave out and has not freed. Only fmi2Instantiate and
/// fmi2FreeInstance look at it (a lock on every call would cost more than the call): a host
/// that frees an instance twice, or frees a pointer that is not one of ours, has nothing freed
/// instead of corrupting its heap. Any other call with a freed instance stays undefined.
static LIVE_INSTANCES: std::sync::Mutex<Vec<usize>> = std::sync::Mutex::new(Vec::new());

fn live_instances() -> std::sync::MutexGuard<'static, Vec<usize>> {
    // a panic while the lock is held cannot leave the list half-changed (push and swap_remove)
    LIVE_INSTANCES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Whether a panic now is one that [`with`] catches and reports through the host's logger, so
/// the panic hook stays silent for it.
///
/// In an FMU's binary (feature `fmu-library`, which package-fmus turns on) every panic is one:
/// its standard library is its own, no thread of its own runs, and every entry point catches
/// its panics and reports them through the host's logger, or on stderr where there is none
/// ([`report_on_stderr`]), so nothing is counted (a locked increment and
/// decrement on every call took about 3 % of a coupled run's wall time, and a thread-local
/// lookup through `__tls_get_addr` more). Where the glue is linked into a Rust program
/// calling the C API in-process (its tests), the calls running in any thread are counted, so
/// that the program's other panics keep their hook.
#[cfg(feature = "fmu-library")]
mod call_count {
    pub fn enter() {}
    pub fn leave() {}
    pub fn silent() -> bool {
        true
    }
}

#[cfg(not(feature = "fmu-library"))]
mod call_count {
    use std::sync::atomic::{AtomicUsize, Ordering};

    static CALLS_RUNNING: AtomicUsize = AtomicUsize::new(0);

    pub fn enter() {
        CALLS_RUNNING.fetch_add(1, Ordering::Relaxed);
    }
    pub fn leave() {
        CALLS_RUNNING.fetch_sub(1, Ordering::Relaxed);
    }
    pub fn silent() -> bool {
        CALLS_RUNNING.load(Ordering::Relaxed) > 0
    }
}

/// Installs (once) a panic hook that stays silent for a panic that an `fmi2*` call reports
/// through the host's logger, and leaves every other panic to the hook before it (see
/// [`call_count`]).
fn install_panic_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !call_count::silent() {
                previous(info);
            }
        }));
    });
}

/// The text of a caught panic's payload (`panic!` with a message gives a `&str` or a
/// `String`).
fn panic_text(payload: &(dyn std::any::Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("no message")
        // the first line, at most 300 characters (a panic message may hold a backtrace or data)
        .lines()
        .next()
        .map_or("", |l| {
            l.char_indices().nth(300).map_or(l, |(i, _)| &l[..i])
        })
}

pub unsafe fn free_instance(c: fmi2Component) {
    if c.is_null() {
        return;
    }
    {
        let mut live = live_instances();
        let Some(i) = live.iter().position(|&p| p == c as usize) else {
            // freed already, or not ours: the host has no logger left to tell
            return;
        };
        live.swap_remove(i);
    }
    let dropped = catch_unwind(AssertUnwindSafe(|| {
        drop(Box::from_raw(c as *mut CComponent));
    }));
    if let Err(payload) = dropped {
        report_on_stderr(&format!(
            "fmi2FreeInstance: internal error (panic caught at the C boundary: {})",
            panic_text(payload.as_ref())
        ));
    }
}

/// Run `f` on the component behind `c`, catching panics: the call returns fmi2Error and the
/// instance goes to the Error state, so a panic is not repeated on every later call (a state
/// the host handed in may break an invariant the physics relies on).
pub unsafe fn with(
    c: fmi2Component,
    call: &str,
    f: impl FnOnce(&mut CComponent) -> Status,
) -> fmi2Status {
    if c.is_null() {
        return FMI2_ERROR;
    }
    let cc = &mut *(c as *mut CComponent);
    call_count::enter();
    let result = catch_unwind(AssertUnwindSafe(|| {
        cc.component.trace(call);
        f(&mut *cc)
    }));
    call_count::leave();
    match result {
        Ok(s) => to_c(s),
        Err(payload) => {
            let cc = &mut *(c as *mut CComponent);
            let msg = format!(
                "{call}: internal error (panic caught at the C boundary: {}); the instance is \
                 in the Error state (fmi2Reset, or fmi2SetFMUstate of a saved state)",
                panic_text(payload.as_ref())
            );
            let reported = catch_unwind(AssertUnwindSafe(|| {
                cc.component.enter_error_state();
                cc.component.error(&msg);
            }));
            if reported.is_err() {
                report_on_stderr(&msg);
            }
            FMI2_ERROR
        }
    }
}

#[cfg(test)]
#[path = "capi_tests.rs"]
mod tests;

unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts(p, n))
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts_mut(p, n))
    }
}

fn null_arg(cc: &mut CComponent, call: &str) -> Status {
    cc.component
        .error(&format!("{call}: a required pointer argument is NULL"))
}

pub unsafe fn set_debug_logging(
    c: fmi2Component,
    on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    with(c, "fmi2SetDebugLogging", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2SetDebugLogging", n);
        }
        let Some(cats) = slice(categories, n) else {
            return null_arg(cc, "fmi2SetDebugLogging");
        };
        let mut names = Vec::with_capacity(n);
        for &p in cats {
            match str_arg(p) {
                Some(s) => names.push(s),
                None => return null_arg(cc, "fmi2SetDebugLogging"),
            }
        }
        cc.component.set_debug_logging(on != 0, &names)
    })
}

pub unsafe fn setup_experiment(
    c: fmi2Component,
    _tolerance_defined: fmi2Boolean,
    _tolerance: fmi2Real,
    start: fmi2Real,
    stop_defined: fmi2Boolean,
    stop: fmi2Real,
) -> fmi2Status {
    with(c, "fmi2SetupExperiment", |cc| {
        cc.component
            .setup_experiment(start, (stop_defined != 0).then_some(stop))
    })
}

pub unsafe fn enter_initialization_mode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2EnterInitializationMode", |cc| {
        cc.component.enter_initialization_mode()
    })
}

pub unsafe fn exit_initialization_mode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2ExitInitializationMode", |cc| {
        cc.component.exit_initialization_mode()
    })
}

pub unsafe fn terminate(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2Terminate", |cc| cc.component.terminate())
}

pub unsafe fn reset(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2Reset", |cc| {
        cc.serialized = None;
        cc.component.reset()
    })
}

pub unsafe fn get_real(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    with(c, "fmi2GetReal", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2GetReal", n);
        }
        match (slice(vr, n), slice_mut(value, n)) {
            (Some(vr), Some(value)) => cc.component.get_real(vr, value),
            _ => null_arg(cc, "fmi2GetReal"),
        }
    })
}

pub unsafe fn get_integer(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    with(c, "fmi2GetInteger", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2GetInteger", n);
        }
        match (slice(vr, n), slice_mut(value, n)) {
            (Some(vr), Some(value)) => cc.component.get_integer(vr, value),
            _ => null_arg(cc, "fmi2GetInteger"),
        }
    })
}

pub unsafe fn get_boolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    with(c, "fmi2GetBoolean", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2GetBoolean", n);
        }
        match (slice(vr, n), slice_mut(value, n)) {
            (Some(vr), Some(value)) => {
                let mut buf = std::mem::take(&mut cc.booleans);
                buf.clear();
                buf.resize(n, false);
                let s = cc.component.get_boolean(vr, &mut buf);
                if s <= Status::Warning {
                    for (o, b) in value.iter_mut().zip(&buf) {
                        *o = fmi2Boolean::from(*b);
                    }
                }
                cc.booleans = buf;
                s
            }
            _ => null_arg(cc, "fmi2GetBoolean"),
        }
    })
}

pub unsafe fn get_string(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    with(c, "fmi2GetString", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2GetString", n);
        }
        match (slice(vr, n), slice_mut(value, n)) {
            (Some(vr), Some(value)) => {
                let mut buf = vec![String::new(); n];
                let s = cc.component.get_string(vr, &mut buf);
                if s <= Status::Warning {
                    // Valid until the next call on this instance (FMI 2.0, 2.1.7).
                    cc.component.string_buffer = buf.iter().map(|b| c_string_lossy(b)).collect();
                    for (o, b) in value.iter_mut().zip(&cc.component.string_buffer) {
                        *o = b.as_ptr();
                    }
                }
                s
            }
            _ => null_arg(cc, "fmi2GetString"),
        }
    })
}

pub unsafe fn set_real(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    with(c, "fmi2SetReal", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2SetReal", n);
        }
        match (slice(vr, n), slice(value, n)) {
            (Some(vr), Some(value)) => cc.component.set_real(vr, value),
            _ => null_arg(cc, "fmi2SetReal"),
        }
    })
}

pub unsafe fn set_integer(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    with(c, "fmi2SetInteger", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2SetInteger", n);
        }
        match (slice(vr, n), slice(value, n)) {
            (Some(vr), Some(value)) => cc.component.set_integer(vr, value),
            _ => null_arg(cc, "fmi2SetInteger"),
        }
    })
}

pub unsafe fn set_boolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    with(c, "fmi2SetBoolean", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2SetBoolean", n);
        }
        match (slice(vr, n), slice(value, n)) {
            (Some(vr), Some(value)) => {
                let mut buf = std::mem::take(&mut cc.booleans);
                buf.clear();
                buf.extend(value.iter().map(|v| *v != 0));
                let s = cc.component.set_boolean(vr, &buf);
                cc.booleans = buf;
                s
            }
            _ => null_arg(cc, "fmi2SetBoolean"),
        }
    })
}

pub unsafe fn set_string(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2String,
) -> fmi2Status {
    with(c, "fmi2SetString", |cc| {
        if n > MAX_VALUES_PER_CALL {
            return too_many(cc, "fmi2SetString", n);
        }
        match (slice(vr, n), slice(value, n)) {
            (Some(vr), Some(value)) => {
                let mut strs = Vec::with_capacity(n);
                for &p in value {
                    match str_arg(p) {
                        Some(s) => strs.push(s),
                        None => {
                            return cc
                                .component
                                .error("fmi2SetString: a value is NULL or not valid UTF-8")
                        }
                    }
                }
                cc.component.set_string(vr, &strs)
            }
            _ => null_arg(cc, "fmi2SetString"),
        }
    })
}

pub unsafe fn get_fmu_state(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    with(c, "fmi2GetFMUstate", |cc| {
        if state.is_null() {
            return null_arg(cc, "fmi2GetFMUstate");
        }
        if (*state).is_null() {
            match cc.component.get_fmu_state() {
                Ok(snapshot) => {
                    *state = Box::into_raw(snapshot) as fmi2FMUstate;
                    Status::Ok
                }
                Err(s) => s,
            }
        } else {
            // bytes serialised from this state before are out of date now: its id changes
            let snapshot = &mut *((*state) as *mut Snapshot);
            cc.component.update_fmu_state(snapshot)
        }
    })
}

pub unsafe fn set_fmu_state(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    with(c, "fmi2SetFMUstate", |cc| {
        if state.is_null() {
            return null_arg(cc, "fmi2SetFMUstate");
        }
        cc.component.set_fmu_state(&*(state as *const Snapshot))
    })
}

pub unsafe fn free_fmu_state(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    with(c, "fmi2FreeFMUstate", |cc| {
        if state.is_null() {
            return null_arg(cc, "fmi2FreeFMUstate");
        }
        if !(*state).is_null() {
            let ptr = (*state) as *mut Snapshot;
            let own = cc.component.check_own_fmu_state(&*ptr);
            if own != Status::Ok {
                return own;
            }
            if cc
                .serialized
                .as_ref()
                .is_some_and(|(id, _)| *id == (*ptr).id())
            {
                cc.serialized = None;
            }
            drop(Box::from_raw(ptr));
            *state = std::ptr::null_mut();
        }
        Status::Ok
    })
}

unsafe fn serialized_bytes(cc: &mut CComponent, state: fmi2FMUstate) -> Result<&[u8], Status> {
    let key = (*(state as *const Snapshot)).id();
    let cached = cc.serialized.as_ref().is_some_and(|(p, _)| *p == key);
    if !cached {
        let bytes = cc
            .component
            .serialize_fmu_state(&*(state as *const Snapshot))?;
        cc.serialized = Some((key, bytes));
    }
    match &cc.serialized {
        Some((_, b)) => Ok(b.as_slice()),
        None => Err(Status::Error),
    }
}

pub unsafe fn serialized_fmu_state_size(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    with(c, "fmi2SerializedFMUstateSize", |cc| {
        if state.is_null() || size.is_null() {
            return null_arg(cc, "fmi2SerializedFMUstateSize");
        }
        // Always re-serialise here: the state may have been updated in place since.
        cc.serialized = None;
        match serialized_bytes(cc, state) {
            Ok(b) => {
                *size = b.len();
                Status::Ok
            }
            Err(s) => s,
        }
    })
}

pub unsafe fn serialize_fmu_state(
    c: fmi2Component,
    state: fmi2FMUstate,
    buffer: *mut ffi::fmi2Byte,
    size: usize,
) -> fmi2Status {
    with(c, "fmi2SerializeFMUstate", |cc| {
        if state.is_null() || buffer.is_null() {
            return null_arg(cc, "fmi2SerializeFMUstate");
        }
        let bytes = match serialized_bytes(cc, state) {
            Ok(b) => b.to_vec(),
            Err(s) => return s,
        };
        cc.serialized = None;
        if bytes.len() > size {
            return cc.component.error(&format!(
                "fmi2SerializeFMUstate: buffer of {size} bytes is too small ({} needed)",
                bytes.len()
            ));
        }
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer as *mut u8, bytes.len());
        Status::Ok
    })
}

pub unsafe fn deserialize_fmu_state(
    c: fmi2Component,
    buffer: *const ffi::fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    with(c, "fmi2DeSerializeFMUstate", |cc| {
        if state.is_null() {
            return null_arg(cc, "fmi2DeSerializeFMUstate");
        }
        if size > MAX_STATE_BYTES {
            return cc.component.error(&format!(
                "fmi2DeSerializeFMUstate: {size} bytes is more than the {MAX_STATE_BYTES} a \
                 serialised state of this FMU can have (a wrong size?)"
            ));
        }
        let Some(bytes) = slice(buffer as *const u8, size) else {
            return null_arg(cc, "fmi2DeSerializeFMUstate");
        };
        match cc.component.deserialize_fmu_state(bytes) {
            Ok(snapshot) => {
                // `*state` is an output only (FMI 2.0, 2.1.8): what it held on entry is the
                // host's, maybe a state it still uses or an uninitialised pointer; never freed
                *state = Box::into_raw(snapshot) as fmi2FMUstate;
                Status::Ok
            }
            Err(s) => s,
        }
    })
}

/// Not supported (providesDirectionalDerivative = false).
pub unsafe fn unsupported(c: fmi2Component, call: &'static str, why: &'static str) -> fmi2Status {
    with(c, call, |cc| cc.component.error(&format!("{call}: {why}")))
}

pub unsafe fn do_step(c: fmi2Component, t: fmi2Real, h: fmi2Real) -> fmi2Status {
    with(c, "fmi2DoStep", |cc| cc.component.do_step(t, h))
}

/// A status query: a NULL value pointer is an error and the state must allow the query;
/// `answer` gives the value, or `None` for a status kind this FMU does not provide (steps are
/// never asynchronous; the models never end the simulation early): fmi2Discard, as FMI 2.0,
/// 4.2.3, says, not fmi2Error, which would end the host's run.
unsafe fn status_query<T>(
    c: fmi2Component,
    call: &'static str,
    value: *mut T,
    unavailable: &str,
    answer: impl FnOnce(&CComponent) -> Option<T>,
) -> fmi2Status {
    with(c, call, |cc| {
        if value.is_null() {
            return null_arg(cc, call);
        }
        if let Err(s) = cc.component.check_status_query(call) {
            return s;
        }
        match answer(cc) {
            Some(v) => {
                *value = v;
                Status::Ok
            }
            None => cc
                .component
                .status_unavailable(&format!("{call}: {unavailable}")),
        }
    })
}

pub unsafe fn get_status(
    c: fmi2Component,
    _kind: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    status_query(
        c,
        "fmi2GetStatus",
        value,
        "no asynchronous step to report on (canRunAsynchronuously = false)",
        |_| None,
    )
}

pub unsafe fn get_integer_status(
    c: fmi2Component,
    _kind: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    status_query(
        c,
        "fmi2GetIntegerStatus",
        value,
        "no Integer status is defined for co-simulation",
        |_| None,
    )
}

pub unsafe fn get_string_status(
    c: fmi2Component,
    _kind: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    status_query(
        c,
        "fmi2GetStringStatus",
        value,
        "no pending status (canRunAsynchronuously = false)",
        |_| None,
    )
}

pub unsafe fn get_real_status(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    status_query(
        c,
        "fmi2GetRealStatus",
        value,
        "only fmi2LastSuccessfulTime is available",
        |cc| {
            (kind == ffi::fmi2StatusKind_fmi2LastSuccessfulTime)
                .then(|| cc.component.last_successful_time())
        },
    )
}

pub unsafe fn get_boolean_status(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    // the models never ask to end the simulation early
    status_query(
        c,
        "fmi2GetBooleanStatus",
        value,
        "only fmi2Terminated is available",
        |_| (kind == ffi::fmi2StatusKind_fmi2Terminated).then_some(0),
    )
}

pub fn types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn version() -> *const c_char {
    c"2.0".as_ptr()
}

/// Keeps `c_void` in the public signature list used by the macro.
pub type Opaque = c_void;

/// Define the FMI 2.0 co-simulation symbols of a binary carrying the given models.
///
/// Invoke once per FMU crate, behind its `fmi-export` feature (two crates exporting the same
/// `fmi2*` symbols cannot be linked into one program, e.g. the master).
#[macro_export]
macro_rules! export_fmus {
    ($($model:ty),+ $(,)?) => {
        #[doc(hidden)]
        pub static __FMU_REGISTRY: $crate::capi::Registry =
            $crate::capi::Registry::new(&[$($crate::capi::ModelEntry::of::<$model>()),+]);

        #[doc(hidden)]
        pub mod __fmi2_exports {
            #![allow(non_snake_case, clippy::missing_safety_doc)]
            use $crate::capi as c;
            use $crate::capi::ffi::*;
            use std::os::raw::c_char;

            /// Packaging manifest (not an FMI function): bincode of the models' descriptions.
            #[no_mangle]
            pub unsafe extern "C" fn rfmi_manifest(len: *mut usize) -> *const u8 {
                static MANIFEST: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
                let bytes = MANIFEST.get_or_init(|| {
                    std::panic::catch_unwind(|| c::manifest(super::__FMU_REGISTRY.models))
                        .unwrap_or_default()
                });
                if !len.is_null() {
                    *len = bytes.len();
                }
                bytes.as_ptr()
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetTypesPlatform() -> *const c_char { c::types_platform() }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetVersion() -> *const c_char { c::version() }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetDebugLogging(c_: fmi2Component, on: fmi2Boolean, n: usize, cats: *const fmi2String) -> fmi2Status { c::set_debug_logging(c_, on, n, cats) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Instantiate(name: fmi2String, ty: fmi2Type, guid: fmi2String, res: fmi2String, f: *const fmi2CallbackFunctions, visible: fmi2Boolean, logging: fmi2Boolean) -> fmi2Component { c::instantiate(&super::__FMU_REGISTRY, name, ty, guid, res, f, visible, logging) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeInstance(c_: fmi2Component) { c::free_instance(c_) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetupExperiment(c_: fmi2Component, tol_def: fmi2Boolean, tol: fmi2Real, start: fmi2Real, stop_def: fmi2Boolean, stop: fmi2Real) -> fmi2Status { c::setup_experiment(c_, tol_def, tol, start, stop_def, stop) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c_: fmi2Component) -> fmi2Status { c::enter_initialization_mode(c_) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c_: fmi2Component) -> fmi2Status { c::exit_initialization_mode(c_) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Terminate(c_: fmi2Component) -> fmi2Status { c::terminate(c_) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Reset(c_: fmi2Component) -> fmi2Status { c::reset(c_) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetReal(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *mut fmi2Real) -> fmi2Status { c::get_real(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetInteger(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *mut fmi2Integer) -> fmi2Status { c::get_integer(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBoolean(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *mut fmi2Boolean) -> fmi2Status { c::get_boolean(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetString(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *mut fmi2String) -> fmi2Status { c::get_string(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetReal(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *const fmi2Real) -> fmi2Status { c::set_real(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetInteger(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *const fmi2Integer) -> fmi2Status { c::set_integer(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetBoolean(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *const fmi2Boolean) -> fmi2Status { c::set_boolean(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetString(c_: fmi2Component, vr: *const fmi2ValueReference, n: usize, v: *const fmi2String) -> fmi2Status { c::set_string(c_, vr, n, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetFMUstate(c_: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status { c::get_fmu_state(c_, s) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetFMUstate(c_: fmi2Component, s: fmi2FMUstate) -> fmi2Status { c::set_fmu_state(c_, s) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeFMUstate(c_: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status { c::free_fmu_state(c_, s) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(c_: fmi2Component, s: fmi2FMUstate, size: *mut usize) -> fmi2Status { c::serialized_fmu_state_size(c_, s, size) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(c_: fmi2Component, s: fmi2FMUstate, buf: *mut fmi2Byte, size: usize) -> fmi2Status { c::serialize_fmu_state(c_, s, buf, size) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(c_: fmi2Component, buf: *const fmi2Byte, size: usize, s: *mut fmi2FMUstate) -> fmi2Status { c::deserialize_fmu_state(c_, buf, size, s) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(c_: fmi2Component, _u: *const fmi2ValueReference, _nu: usize, _z: *const fmi2ValueReference, _nz: usize, _dv: *const fmi2Real, _dz: *mut fmi2Real) -> fmi2Status { c::unsupported(c_, "fmi2GetDirectionalDerivative", "not provided (providesDirectionalDerivative = false)") }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(c_: fmi2Component, _vr: *const fmi2ValueReference, _n: usize, _order: *const fmi2Integer, _v: *const fmi2Real) -> fmi2Status { c::unsupported(c_, "fmi2SetRealInputDerivatives", "inputs are held constant over a step (canInterpolateInputs = false)") }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(c_: fmi2Component, _vr: *const fmi2ValueReference, _n: usize, _order: *const fmi2Integer, _v: *mut fmi2Real) -> fmi2Status { c::unsupported(c_, "fmi2GetRealOutputDerivatives", "not provided (maxOutputDerivativeOrder = 0)") }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DoStep(c_: fmi2Component, t: fmi2Real, h: fmi2Real, _no_prior: fmi2Boolean) -> fmi2Status { c::do_step(c_, t, h) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CancelStep(c_: fmi2Component) -> fmi2Status { c::unsupported(c_, "fmi2CancelStep", "steps are never asynchronous (canRunAsynchronuously = false)") }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(c_: fmi2Component, k: fmi2StatusKind, v: *mut fmi2Status) -> fmi2Status { c::get_status(c_, k, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealStatus(c_: fmi2Component, k: fmi2StatusKind, v: *mut fmi2Real) -> fmi2Status { c::get_real_status(c_, k, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(c_: fmi2Component, k: fmi2StatusKind, v: *mut fmi2Integer) -> fmi2Status { c::get_integer_status(c_, k, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(c_: fmi2Component, k: fmi2StatusKind, v: *mut fmi2Boolean) -> fmi2Status { c::get_boolean_status(c_, k, v) }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(c_: fmi2Component, k: fmi2StatusKind, v: *mut fmi2String) -> fmi2Status { c::get_string_status(c_, k, v) }
        }
    };
}
