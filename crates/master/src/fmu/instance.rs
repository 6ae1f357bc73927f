//! One FMI 2.0 co-simulation instance driven through the C functions of its [`PreparedFmu`].

use std::ffi::CString;
use std::sync::Arc;

use fmi_sys::fmi2 as ffi;

use super::library::{callbacks, Fmi2Library};
use super::{FmuError, PreparedFmu};
use crate::slave::{FailStatus, ScalarType, Slave, SlaveError, StepStatus, VarBatch};

/// Instance names must be non-empty C strings.
pub(crate) fn check_instance_name(name: &str) -> Result<(), FmuError> {
    if name.is_empty() || name.contains('\0') {
        return Err(FmuError::InstanceName {
            name: name.replace('\0', "\\0"),
            reason: "must be non-empty and contain no NUL".into(),
        });
    }
    Ok(())
}

/// One instantiated FMU. Dropping it frees its saved FMU state and calls fmi2FreeInstance; the
/// unpacked folder and the library go when the last instance of its [`PreparedFmu`] is gone.
pub struct FmuSlave {
    component: ffi::fmi2Component,
    /// The single state slot for step retry (null until first saved).
    saved: ffi::fmi2FMUstate,
    name: String,
    can_state: bool,
    can_vary_step: bool,
    /// Scratch buffers of mixed-type batches (reused: no allocation per step).
    reals: Vec<f64>,
    ints: Vec<i32>,
    // The FMU may keep the pointer to its callbacks for its whole life.
    _callbacks: Box<ffi::fmi2CallbackFunctions>,
    fmu: Arc<PreparedFmu>,
}

impl std::fmt::Debug for FmuSlave {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FmuSlave({})", self.name)
    }
}

/// fmi2OK and fmi2Warning are success; anything else names the status.
fn status(s: ffi::fmi2Status) -> Result<(), FailStatus> {
    match s {
        ffi::fmi2Status_fmi2OK | ffi::fmi2Status_fmi2Warning => Ok(()),
        ffi::fmi2Status_fmi2Discard => Err(FailStatus::Discard),
        ffi::fmi2Status_fmi2Error => Err(FailStatus::Error),
        ffi::fmi2Status_fmi2Fatal => Err(FailStatus::Fatal),
        ffi::fmi2Status_fmi2Pending => Err(FailStatus::Other("fmi2Pending".into())),
        other => Err(FailStatus::Other(format!("unknown status {other}"))),
    }
}

impl FmuSlave {
    /// fmi2Instantiate of a co-simulation instance of `fmu`.
    pub(crate) fn new(
        fmu: Arc<PreparedFmu>,
        instance_name: &str,
        logging_on: bool,
    ) -> Result<Self, FmuError> {
        check_instance_name(instance_name)?;
        let load_err = |reason: String| FmuError::Load {
            path: fmu.archive().path.clone(),
            instance: instance_name.to_string(),
            reason,
        };
        let model = &fmu.archive().model;
        let name = CString::new(instance_name).map_err(|e| load_err(e.to_string()))?;
        let guid = CString::new(model.guid.as_str()).map_err(|e| load_err(e.to_string()))?;
        let callbacks = Box::new(callbacks());
        let lib = fmu.library();
        // SAFETY: all strings are NUL-terminated and outlive the call; the callbacks live as
        // long as the instance (boxed, freed after fmi2FreeInstance).
        let component = unsafe {
            (lib.instantiate)(
                name.as_ptr(),
                ffi::fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                fmu.resource_url().as_ptr(),
                &*callbacks,
                0,
                i32::from(logging_on),
            )
        };
        if component.is_null() {
            return Err(load_err("fmi2Instantiate returned NULL".into()));
        }
        let caps = model.co_simulation.as_ref();
        Ok(FmuSlave {
            component,
            saved: std::ptr::null_mut(),
            name: instance_name.to_string(),
            can_state: caps.is_some_and(|c| c.can_get_and_set_fmu_state) && lib.fmu_state.is_some(),
            can_vary_step: caps.is_some_and(|c| c.can_handle_variable_communication_step_size),
            reals: Vec::new(),
            ints: Vec::new(),
            _callbacks: callbacks,
            fmu,
        })
    }

    fn lib(&self) -> &Fmi2Library {
        self.fmu.library()
    }

    /// fmi2OK at once; any other status through [`Self::checked`] (kept out of line, so that
    /// the calls of a step stay small).
    #[inline(always)]
    fn check(&self, call: &'static str, s: ffi::fmi2Status) -> Result<(), SlaveError> {
        if s == ffi::fmi2Status_fmi2OK {
            return Ok(());
        }
        self.checked(call, s)
    }

    #[cold]
    #[inline(never)]
    fn checked(&self, call: &'static str, s: ffi::fmi2Status) -> Result<(), SlaveError> {
        status(s).map_err(|status| SlaveError {
            instance: self.name.clone(),
            call,
            status,
            reason: super::logger::take_errors(&self.name),
        })
    }

    fn internal(&self, call: &'static str, reason: &str) -> SlaveError {
        SlaveError {
            instance: self.name.clone(),
            call,
            status: FailStatus::Other(format!("internal: {reason}")),
            reason: None,
        }
    }

    fn absent(&self, call: &'static str) -> SlaveError {
        SlaveError {
            instance: self.name.clone(),
            call,
            status: FailStatus::Other(format!("the binary does not export {call}")),
            reason: None,
        }
    }

    fn missing(&self, call: &'static str) -> SlaveError {
        SlaveError {
            instance: self.name.clone(),
            call,
            status: FailStatus::Other("the FMU does not support FMU state".into()),
            reason: None,
        }
    }
}

impl Drop for FmuSlave {
    fn drop(&mut self) {
        let lib = self.fmu.library();
        // SAFETY: the component came from fmi2Instantiate of this library and is freed once;
        // a saved state belongs to it. Freeing is allowed in every state.
        unsafe {
            if let (Some(f), false) = (lib.fmu_state, self.saved.is_null()) {
                (f.free)(self.component, &mut self.saved);
            }
            (lib.free_instance)(self.component);
        }
    }
}

impl Slave for FmuSlave {
    fn name(&self) -> &str {
        &self.name
    }
    fn setup_experiment(&mut self, start_time: f64, stop_time: f64) -> Result<(), SlaveError> {
        // SAFETY (every call below): `component` is a live instance of this library; pointers
        // and lengths come from slices of matching length.
        let s = unsafe {
            (self.lib().setup_experiment)(self.component, 0, 0.0, start_time, 1, stop_time)
        };
        self.check("fmi2SetupExperiment", s)
    }
    fn enter_initialization_mode(&mut self) -> Result<(), SlaveError> {
        let s = unsafe { (self.lib().enter_initialization_mode)(self.component) };
        self.check("fmi2EnterInitializationMode", s)
    }
    fn exit_initialization_mode(&mut self) -> Result<(), SlaveError> {
        let s = unsafe { (self.lib().exit_initialization_mode)(self.component) };
        self.check("fmi2ExitInitializationMode", s)
    }
    fn get(&mut self, batch: &VarBatch, out: &mut [f64]) -> Result<(), SlaveError> {
        if out.len() != batch.len() {
            return Err(self.internal("fmi2GetReal", "batch and value lengths differ"));
        }
        let (c, lib) = (self.component, self.fmu.library());
        if batch.all_real() {
            if !out.is_empty() {
                let vrs = &batch.group(ScalarType::Real).vrs;
                let s = unsafe { (lib.get_real)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
                self.check("fmi2GetReal", s)?;
            }
            return Ok(());
        }
        let g = batch.group(ScalarType::Real);
        if !g.vrs.is_empty() {
            self.reals.resize(g.vrs.len(), 0.0);
            let s =
                unsafe { (lib.get_real)(c, g.vrs.as_ptr(), g.vrs.len(), self.reals.as_mut_ptr()) };
            self.check("fmi2GetReal", s)?;
            for (&k, &x) in g.positions.iter().zip(&self.reals) {
                out[k] = x;
            }
        }
        for (ty, call) in [
            (ScalarType::Integer, "fmi2GetInteger"),
            (ScalarType::Boolean, "fmi2GetBoolean"),
        ] {
            let g = batch.group(ty);
            if g.vrs.is_empty() {
                continue;
            }
            self.ints.resize(g.vrs.len(), 0);
            let get = if ty == ScalarType::Integer {
                lib.get_integer
            } else {
                lib.get_boolean
            };
            let s = unsafe { get(c, g.vrs.as_ptr(), g.vrs.len(), self.ints.as_mut_ptr()) };
            self.check(call, s)?;
            for (&k, &x) in g.positions.iter().zip(&self.ints) {
                // an fmi2Boolean is any non-zero integer for true
                out[k] = match ty {
                    ScalarType::Boolean if x != 0 => 1.0,
                    ScalarType::Boolean => 0.0,
                    _ => f64::from(x),
                };
            }
        }
        Ok(())
    }
    fn set(&mut self, batch: &VarBatch, values: &[f64]) -> Result<(), SlaveError> {
        if values.len() != batch.len() {
            return Err(self.internal("fmi2SetReal", "batch and value lengths differ"));
        }
        let (c, lib) = (self.component, self.fmu.library());
        let g = batch.group(ScalarType::Real);
        if batch.all_real() {
            // the common case: one fmi2SetReal with the values as they are
            if !g.vrs.is_empty() {
                let s = unsafe { (lib.set_real)(c, g.vrs.as_ptr(), g.vrs.len(), values.as_ptr()) };
                self.check("fmi2SetReal", s)?;
            }
            return Ok(());
        }
        if !g.vrs.is_empty() {
            self.reals.clear();
            self.reals.extend(g.positions.iter().map(|&k| values[k]));
            let s = unsafe { (lib.set_real)(c, g.vrs.as_ptr(), g.vrs.len(), self.reals.as_ptr()) };
            self.check("fmi2SetReal", s)?;
        }
        for (ty, call) in [
            (ScalarType::Integer, "fmi2SetInteger"),
            (ScalarType::Boolean, "fmi2SetBoolean"),
        ] {
            let g = batch.group(ty);
            if g.vrs.is_empty() {
                continue;
            }
            self.ints.clear();
            self.ints.extend(g.positions.iter().map(|&k| match ty {
                ScalarType::Boolean => i32::from(values[k] != 0.0),
                // values come from Integer outputs or validated parameters: exact
                _ => values[k].round() as i32,
            }));
            let set = if ty == ScalarType::Integer {
                lib.set_integer
            } else {
                lib.set_boolean
            };
            let s = unsafe { set(c, g.vrs.as_ptr(), g.vrs.len(), self.ints.as_ptr()) };
            self.check(call, s)?;
        }
        Ok(())
    }
    fn get_strings(&mut self, vrs: &[u32], out: &mut Vec<String>) -> Result<(), SlaveError> {
        out.clear();
        if vrs.is_empty() {
            return Ok(());
        }
        let Some(get) = self.lib().get_string else {
            return Err(self.absent("fmi2GetString"));
        };
        let mut ptrs: Vec<ffi::fmi2String> = vec![std::ptr::null(); vrs.len()];
        let s = unsafe { get(self.component, vrs.as_ptr(), vrs.len(), ptrs.as_mut_ptr()) };
        self.check("fmi2GetString", s)?;
        for p in ptrs {
            if p.is_null() {
                return Err(SlaveError {
                    instance: self.name.clone(),
                    call: "fmi2GetString",
                    status: FailStatus::Other("returned a NULL string".into()),
                    reason: None,
                });
            }
            // SAFETY: FMI 2.0 (2.1.7): the FMU's strings stay valid until its next call; they
            // are copied at once.
            let text = unsafe { std::ffi::CStr::from_ptr(p) };
            out.push(text.to_string_lossy().into_owned());
        }
        Ok(())
    }
    fn set_strings(&mut self, vrs: &[u32], values: &[&str]) -> Result<(), SlaveError> {
        if vrs.len() != values.len() {
            return Err(self.internal("fmi2SetString", "batch and value lengths differ"));
        }
        if vrs.is_empty() {
            return Ok(());
        }
        let Some(set) = self.lib().set_string else {
            return Err(self.absent("fmi2SetString"));
        };
        let mut texts = Vec::with_capacity(values.len());
        for v in values {
            texts.push(CString::new(*v).map_err(|_| SlaveError {
                instance: self.name.clone(),
                call: "fmi2SetString",
                status: FailStatus::Other(format!("the string {v:?} contains a NUL byte")),
                reason: None,
            })?);
        }
        let ptrs: Vec<ffi::fmi2String> = texts.iter().map(|t| t.as_ptr()).collect();
        let s = unsafe { set(self.component, vrs.as_ptr(), vrs.len(), ptrs.as_ptr()) };
        self.check("fmi2SetString", s)
    }
    fn terminate_requested(&mut self) -> bool {
        let Some(get) = self.lib().get_boolean_status else {
            return false;
        };
        let mut terminated: ffi::fmi2Boolean = 0;
        let s = unsafe {
            get(
                self.component,
                ffi::fmi2StatusKind_fmi2Terminated,
                &mut terminated,
            )
        };
        status(s).is_ok() && terminated != 0
    }
    fn last_successful_time(&mut self) -> Option<f64> {
        let get = self.lib().get_real_status?;
        let mut t: ffi::fmi2Real = f64::NAN;
        let s = unsafe {
            get(
                self.component,
                ffi::fmi2StatusKind_fmi2LastSuccessfulTime,
                &mut t,
            )
        };
        (status(s).is_ok() && t.is_finite()).then_some(t)
    }
    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), SlaveError> {
        if values.len() != vrs.len() {
            return Err(self.internal("fmi2SetReal", "value references and values differ"));
        }
        if vrs.is_empty() {
            return Ok(());
        }
        let (c, lib) = (self.component, self.fmu.library());
        // SAFETY: both slices hold vrs.len() elements and outlive the call
        let s = unsafe { (lib.set_real)(c, vrs.as_ptr(), vrs.len(), values.as_ptr()) };
        self.check("fmi2SetReal", s)
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<StepStatus, SlaveError> {
        let s = unsafe { (self.lib().do_step)(self.component, t, h, 1) };
        match status(s) {
            Ok(()) => Ok(StepStatus::Ok),
            Err(FailStatus::Discard) => {
                // the engine retries or reports the discard itself; its messages were logged
                let _ = super::logger::take_errors(&self.name);
                Ok(StepStatus::Discard)
            }
            Err(status) => Err(SlaveError {
                instance: self.name.clone(),
                call: "fmi2DoStep",
                status,
                reason: super::logger::take_errors(&self.name),
            }),
        }
    }
    fn can_save_state(&self) -> bool {
        self.can_state
    }
    fn can_vary_step(&self) -> bool {
        self.can_vary_step
    }
    fn save_state(&mut self) -> Result<(), SlaveError> {
        let Some(f) = self.lib().fmu_state else {
            return Err(self.missing("fmi2GetFMUstate"));
        };
        // a non-null slot is overwritten in place (FMI 2.0 section 2.1.8)
        let s = unsafe { (f.get)(self.component, &mut self.saved) };
        self.check("fmi2GetFMUstate", s)
    }
    fn restore_state(&mut self) -> Result<(), SlaveError> {
        let Some(f) = self.lib().fmu_state else {
            return Err(self.missing("fmi2SetFMUstate"));
        };
        if self.saved.is_null() {
            return Err(SlaveError {
                instance: self.name.clone(),
                call: "fmi2SetFMUstate",
                status: FailStatus::Other("no saved state".into()),
                reason: None,
            });
        }
        let s = unsafe { (f.set)(self.component, self.saved) };
        self.check("fmi2SetFMUstate", s)
    }
    fn terminate(&mut self) -> Result<(), SlaveError> {
        let s = unsafe { (self.lib().terminate)(self.component) };
        self.check("fmi2Terminate", s)
    }
}
