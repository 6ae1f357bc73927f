//! One FMU instance: the FMI 2.0 co-simulation state machine, value checks, logging and FMU
//! state, written once for every model. The C API (`capi`) is a thin shell over this; Rust tests
//! can drive a `Component` directly.

use std::any::Any;
use std::ffi::CString;

use serde::{Deserialize, Serialize};

use crate::erased::{ErasedModel, VrIndex};
use crate::model::{Diagnostics, InstanceContext, StepError};
use crate::state_bytes::{seal, strict_bincode, unseal};
use crate::variable::{Causality, VarType, Variability};

/// Result status of a call (fmi2Status without Pending, which needs asynchronous stepping).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
    Fatal,
}

/// The FMI 2.0 co-simulation states (FMI 2.0.4, section 4.2.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum FmiState {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
}

/// Where log messages go.
pub trait LogSink: Send {
    fn log(&mut self, status: Status, category: &str, message: &str);
}

/// A sink that keeps messages, shareable with the caller (for Rust-side tests and tools).
#[derive(Default, Debug, Clone)]
pub struct CollectLog {
    pub messages: std::sync::Arc<std::sync::Mutex<Vec<(Status, String, String)>>>,
}

impl CollectLog {
    /// The messages so far (status, category, text).
    pub fn take(&self) -> Vec<(Status, String, String)> {
        match self.messages.lock() {
            Ok(mut g) => std::mem::take(&mut *g),
            Err(_) => Vec::new(),
        }
    }
}

impl LogSink for CollectLog {
    fn log(&mut self, status: Status, category: &str, message: &str) {
        if let Ok(mut g) = self.messages.lock() {
            g.push((status, category.to_string(), message.to_string()));
        }
    }
}

/// A saved FMU state (fmi2FMUstate points to one of these).
pub struct Snapshot {
    /// Unique per content (a new one at each fmi2GetFMUstate that writes it): what the C API's
    /// cache of serialised bytes is keyed by, not the address a freed state's successor may get.
    id: u64,
    model: Box<dyn Any + Send>,
    time: f64,
    state: FmiState,
    start_time: f64,
    stop_time: Option<f64>,
}

#[derive(Serialize, Deserialize)]
struct SnapshotHeader {
    magic: [u8; 4],
    time: f64,
    state: FmiState,
    start_time: f64,
    stop_time: Option<f64>,
    model: Vec<u8>,
}

const MAGIC: [u8; 4] = *b"RFM2";

/// A new [`Snapshot::id`].
fn next_snapshot_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

impl Snapshot {
    /// See [`Snapshot::id`](Snapshot).
    pub fn id(&self) -> u64 {
        self.id
    }
}

/// What decides whether a value may be set, per variable (FMI 2.0 rules for co-simulation),
/// computed once per instance so that the checks of every fmi2Set* call are a lookup and a few
/// comparisons; a refused value is reported by the full checks ([`Component::check_settable`],
/// [`Component::check_range`]).
#[derive(Clone, Copy, Debug)]
struct SetRule {
    /// Settable in Instantiated and InitializationMode.
    before_step: bool,
    /// An input (what Initialization Mode's copy takes without being initialised again).
    input: bool,
    /// Settable in StepComplete.
    in_step: bool,
    /// The declared range (infinite when none).
    min: f64,
    max: f64,
    /// An enumeration's value is checked against its items (the full check).
    enumerated: bool,
}

impl SetRule {
    fn of(meta: &crate::variable::VarMeta) -> Self {
        let (c, v) = (meta.causality, meta.variability);
        SetRule {
            before_step: matches!(c, Causality::Parameter | Causality::Input)
                && v != Variability::Constant,
            input: c == Causality::Input,
            in_step: c == Causality::Input
                || (c == Causality::Parameter && v == Variability::Tunable),
            min: meta.min.unwrap_or(f64::NEG_INFINITY),
            max: meta.max.unwrap_or(f64::INFINITY),
            enumerated: meta.enumeration.is_some(),
        }
    }

    /// Whether the variable may be set in `state` (as [`Component::check_settable`] decides).
    fn settable(&self, state: FmiState) -> bool {
        match state {
            FmiState::Instantiated | FmiState::InitializationMode => self.before_step,
            FmiState::StepComplete => self.in_step,
            _ => false,
        }
    }

    /// Whether `value` passes [`Component::check_range`] without looking further: finite and
    /// within the range of a variable that is no enumeration.
    fn accepts(&self, value: f64) -> bool {
        !self.enumerated && value.is_finite() && value >= self.min && value <= self.max
    }
}

/// An FMU instance.
pub struct Component {
    model: Box<dyn ErasedModel>,
    /// In Initialization Mode: a copy of the model initialised with the values set so far,
    /// which the getters read (see [`Component::refresh_initial_outputs`]); None otherwise.
    initial_view: Option<Box<dyn ErasedModel>>,
    /// What the copy's initialisation reported, for the exit that takes it.
    initial_view_diag: Diagnostics,
    index: VrIndex,
    /// By declaration index.
    rules: Vec<SetRule>,
    /// The rules of the Reals by value reference (Real value references are 0, 1, ... in
    /// declaration order, see [`VrIndex`]): fmi2SetReal's common case without the lookup.
    real_rules: Vec<SetRule>,
    ctx: InstanceContext,
    sink: Box<dyn LogSink>,
    logging_on: bool,
    log_events: bool,
    log_calls: bool,
    state: FmiState,
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    last_successful_time: f64,
    outputs_dirty: bool,
    /// [`crate::FmuModel::MAX_COMMUNICATION_STEP_S`] of the model.
    max_step_s: f64,
    diag: Diagnostics,
    /// Strings returned by fmi2GetString stay valid until the next call on this instance.
    pub(crate) string_buffer: Vec<CString>,
}

fn state_name(s: FmiState) -> &'static str {
    match s {
        FmiState::Instantiated => "Instantiated",
        FmiState::InitializationMode => "InitializationMode",
        FmiState::StepComplete => "StepComplete",
        FmiState::StepFailed => "StepFailed",
        FmiState::Terminated => "Terminated",
        FmiState::Error => "Error",
    }
}

impl Component {
    pub fn new(
        model: Box<dyn ErasedModel>,
        ctx: InstanceContext,
        sink: Box<dyn LogSink>,
        logging_on: bool,
    ) -> Self {
        let index = VrIndex::new(model.metas());
        let rules: Vec<SetRule> = model.metas().iter().map(SetRule::of).collect();
        let real_rules = model
            .metas()
            .iter()
            .zip(&rules)
            .filter(|(m, _)| m.var_type == VarType::Real)
            .map(|(_, r)| *r)
            .collect();
        let max_step_s = model.max_communication_step_s();
        Component {
            model,
            initial_view: None,
            initial_view_diag: Diagnostics::default(),
            max_step_s,
            index,
            rules,
            real_rules,
            ctx,
            sink,
            logging_on,
            log_events: logging_on,
            log_calls: false,
            state: FmiState::Instantiated,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            last_successful_time: 0.0,
            outputs_dirty: true,
            diag: Diagnostics::default(),
            string_buffer: Vec::new(),
        }
    }

    pub fn state(&self) -> FmiState {
        self.state
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    pub fn instance_name(&self) -> &str {
        &self.ctx.instance_name
    }

    /// Log an error (always forwarded: a host needs to know why a call failed).
    pub fn error(&mut self, message: &str) -> Status {
        self.sink.log(Status::Error, "logStatusError", message);
        Status::Error
    }

    /// A status query the instance cannot answer: fmi2Discard (FMI 2.0, 4.2.3: "If a status
    /// is required which cannot be retrieved by the slave it returns fmi2Discard"); the
    /// instance stays as it was.
    pub fn status_unavailable(&mut self, message: &str) -> Status {
        self.sink.log(Status::Discard, "logStatusDiscard", message);
        Status::Discard
    }

    /// The instance can no longer be trusted (a call panicked part-way through): the calls the
    /// Error state refuses (steps, sets, initialisation, termination) are refused from now on
    /// until fmi2Reset, or until fmi2SetFMUstate restores a state saved before.
    pub fn enter_error_state(&mut self) {
        self.state = FmiState::Error;
        self.initial_view = None;
    }

    fn warning(&mut self, message: &str) {
        self.sink.log(Status::Warning, "logStatusWarning", message);
    }

    /// Trace an FMI call in the `logCalls` category (only when enabled: it formats a string).
    #[inline]
    pub fn trace(&mut self, call: &str) {
        if self.logging_on && self.log_calls {
            self.trace_call(call);
        }
    }

    #[cold]
    #[inline(never)]
    fn trace_call(&mut self, call: &str) {
        let msg = format!(
            "{call} (state {}, t = {:?})",
            state_name(self.state),
            self.time
        );
        self.sink.log(Status::Ok, "logCalls", &msg);
    }

    #[cold]
    #[inline(never)]
    fn wrong_state(&mut self, call: &str) -> Status {
        let msg = format!(
            "{call} is not allowed in state {} (FMI 2.0 co-simulation state machine)",
            state_name(self.state)
        );
        self.error(&msg)
    }

    /// Forward what the model reported; returns Warning if it warned.
    #[inline]
    fn flush_diagnostics(&mut self) -> Status {
        if self.diag.is_empty() {
            Status::Ok
        } else {
            self.forward_diagnostics()
        }
    }

    fn forward_diagnostics(&mut self) -> Status {
        let mut status = Status::Ok;
        let warnings = std::mem::take(&mut self.diag.warnings);
        for w in &warnings {
            self.warning(w);
            status = Status::Warning;
        }
        let events = std::mem::take(&mut self.diag.events);
        if self.logging_on && self.log_events {
            for e in &events {
                self.sink.log(Status::Ok, "logEvents", e);
            }
        }
        // Give the buffers back so the next call does not allocate.
        self.diag.warnings = warnings;
        self.diag.warnings.clear();
        self.diag.events = events;
        self.diag.events.clear();
        status
    }

    pub fn set_debug_logging(&mut self, logging_on: bool, categories: &[&str]) -> Status {
        for c in categories {
            if !crate::xml::LOG_CATEGORIES.iter().any(|(n, _)| n == c) {
                let msg = format!("fmi2SetDebugLogging: unknown log category '{c}'");
                return self.error(&msg);
            }
        }
        self.logging_on = logging_on;
        if categories.is_empty() {
            self.log_events = logging_on;
            self.log_calls = logging_on;
        } else {
            self.log_events = categories.contains(&"logEvents");
            self.log_calls = categories.contains(&"logCalls");
        }
        Status::Ok
    }

    pub fn setup_experiment(&mut self, start_time: f64, stop_time: Option<f64>) -> Status {
        if self.state != FmiState::Instantiated {
            return self.wrong_state("fmi2SetupExperiment");
        }
        if !start_time.is_finite() || stop_time.is_some_and(|s| !s.is_finite() || s < start_time) {
            let msg = format!(
                "fmi2SetupExperiment: invalid times (start {start_time}, stop {stop_time:?})"
            );
            return self.error(&msg);
        }
        self.start_time = start_time;
        self.time = start_time;
        self.last_successful_time = start_time;
        self.stop_time = stop_time;
        Status::Ok
    }

    pub fn enter_initialization_mode(&mut self) -> Status {
        if self.state != FmiState::Instantiated {
            return self.wrong_state("fmi2EnterInitializationMode");
        }
        self.state = FmiState::InitializationMode;
        self.outputs_dirty = true;
        Status::Ok
    }

    pub fn exit_initialization_mode(&mut self) -> Status {
        if self.state != FmiState::InitializationMode {
            return self.wrong_state("fmi2ExitInitializationMode");
        }
        self.outputs_dirty = true;
        match self.initial_view.take() {
            // the copy read in Initialization Mode is this model initialised, with the inputs
            // set since: it becomes the model (one initialisation per instance, whatever the
            // host read; `tests/initialization_mode.rs` runs an instance that read nothing
            // beside one that did, bit for bit)
            Some(view) => {
                self.model = view;
                self.diag = std::mem::take(&mut self.initial_view_diag);
            }
            None => {
                // a refused exit leaves Initialization Mode on, the model as the exit left it
                if let Err(e) = self.model.exit_initialization(&mut self.diag) {
                    let _ = self.flush_diagnostics();
                    let msg = format!("fmi2ExitInitializationMode: {e}");
                    return self.error(&msg);
                }
            }
        }
        if let Err(e) = self.model.update_outputs(&mut self.diag) {
            let _ = self.flush_diagnostics();
            let msg = format!("fmi2ExitInitializationMode: {e}");
            return self.error(&msg);
        }
        self.outputs_dirty = false;
        self.state = FmiState::StepComplete;
        self.flush_diagnostics()
    }

    pub fn terminate(&mut self) -> Status {
        match self.state {
            FmiState::StepComplete | FmiState::StepFailed => {
                // "the final values of all variables can be inquired" afterwards: outputs of
                // inputs set since the last computation are computed now, not left stale
                let status = self.refresh_model_outputs("fmi2Terminate");
                if status > Status::Warning {
                    return status;
                }
                self.state = FmiState::Terminated;
                status
            }
            _ => self.wrong_state("fmi2Terminate"),
        }
    }

    /// Back to the just-instantiated state: a fresh model with default values.
    pub fn reset(&mut self) -> Status {
        if let Err(e) = self.model.reset(&self.ctx) {
            let msg = format!("fmi2Reset: {e}");
            self.state = FmiState::Error;
            return self.error(&msg);
        }
        self.state = FmiState::Instantiated;
        self.initial_view = None;
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        self.last_successful_time = 0.0;
        self.outputs_dirty = true;
        self.string_buffer.clear();
        Status::Ok
    }

    fn can_get(&self) -> bool {
        matches!(
            self.state,
            FmiState::InitializationMode
                | FmiState::StepComplete
                | FmiState::StepFailed
                | FmiState::Terminated
                | FmiState::Error
        )
    }

    /// What the getters read: the initialised copy in Initialization Mode, else the model.
    #[inline]
    fn reader(&self) -> &dyn ErasedModel {
        match &self.initial_view {
            Some(view) => view.as_ref(),
            None => self.model.as_ref(),
        }
    }

    /// Outputs read in Initialization Mode are the ones fmi2ExitInitializationMode gives with
    /// the parameters and inputs set so far (FMI 2.0.4, 4.2.4: a host may solve its initial
    /// coupling in this mode). A model computes its initial outputs when it is initialised
    /// (its track, its states from the initial values), so a copy is initialised and read;
    /// the exit takes that copy as the model unless a parameter changed since. When the copy
    /// cannot be initialised (a parameter the exit refuses), the call warns with the reason
    /// and the values are the model's own as they stand (the exit then refuses with the same
    /// reason).
    #[cold]
    #[inline(never)]
    fn refresh_initial_outputs(&mut self, call: &str) -> Status {
        let mut view = self.model.duplicate();
        // the initialisation's messages are the exit's (it reports them when it takes the copy)
        let mut kept = Diagnostics::default();
        let initialised = view
            .exit_initialization(&mut kept)
            .and_then(|()| view.update_outputs(&mut Diagnostics::default()));
        match initialised {
            Ok(()) => {
                self.initial_view = Some(view);
                self.initial_view_diag = kept;
                self.outputs_dirty = false;
                Status::Ok
            }
            Err(e) => {
                self.initial_view = None;
                let status = self.refresh_model_outputs(call);
                // every read warns until the values set can be initialised
                self.outputs_dirty = true;
                if status > Status::Warning {
                    return status;
                }
                let msg = format!(
                    "{call} in Initialization Mode: the outputs are not those of the values set \
                     ({e}; fmi2ExitInitializationMode refuses them)"
                );
                self.warning(&msg);
                Status::Warning
            }
        }
    }

    fn refresh_outputs(&mut self, call: &str) -> Status {
        if self.outputs_dirty && self.state == FmiState::InitializationMode {
            // inputs set since the copy was initialised are in it too (see
            // `mirror_initial_inputs`): its outputs are computed again, as after the exit
            if let Some(view) = self.initial_view.as_mut() {
                if view.update_outputs(&mut Diagnostics::default()).is_ok() {
                    self.outputs_dirty = false;
                    return Status::Ok;
                }
            }
            return self.refresh_initial_outputs(call);
        }
        self.refresh_model_outputs(call)
    }

    /// Initialization Mode: Reals were set. Inputs go into the initialised copy as well (the
    /// model's initialisation does not read them, `tests/initialization_mode.rs` checks that
    /// the outputs read then are those after the exit), so a host iterating its initial
    /// coupling does not initialise a copy at every step; a parameter drops the copy.
    #[cold]
    #[inline(never)]
    fn mirror_initial_inputs(&mut self, vrs: &[u32], values: &[f64]) {
        let inputs = vrs
            .iter()
            .all(|&vr| self.real_rules.get(vr as usize).is_some_and(|r| r.input));
        let mirrored = inputs
            && self
                .initial_view
                .as_mut()
                .is_some_and(|view| view.set_reals(vrs, values).is_ok());
        if !mirrored {
            self.initial_view = None;
        }
    }

    fn refresh_model_outputs(&mut self, call: &str) -> Status {
        if self.outputs_dirty
            && matches!(
                self.state,
                FmiState::InitializationMode | FmiState::StepComplete
            )
        {
            if let Err(e) = self.model.update_outputs(&mut self.diag) {
                let _ = self.flush_diagnostics();
                let msg = format!("{call}: {e}");
                return self.error(&msg);
            }
            self.outputs_dirty = false;
            return self.flush_diagnostics();
        }
        Status::Ok
    }

    fn resolve(&mut self, call: &str, var_type: VarType, vr: u32) -> Result<usize, Status> {
        match self.index.lookup(var_type, vr) {
            Some(i) => Ok(i),
            None => Err(self.unknown(call, var_type, vr)),
        }
    }

    #[cold]
    #[inline(never)]
    fn unknown(&mut self, call: &str, var_type: VarType, vr: u32) -> Status {
        let msg = format!(
            "{call}: unknown value reference {vr} for type {}",
            var_type.xml_name()
        );
        self.error(&msg)
    }

    #[inline]
    fn check_get(&mut self, call: &str, nvr: usize, nvalue: usize) -> Status {
        if !self.can_get() {
            return self.wrong_state(call);
        }
        if nvr != nvalue {
            return self.count_mismatch(call, nvr, nvalue);
        }
        if self.outputs_dirty {
            self.refresh_outputs(call)
        } else {
            Status::Ok
        }
    }

    #[cold]
    #[inline(never)]
    fn count_mismatch(&mut self, call: &str, nvr: usize, nvalue: usize) -> Status {
        let msg = format!("{call}: {nvr} value references but {nvalue} values");
        self.error(&msg)
    }

    #[inline]
    pub fn get_real(&mut self, vrs: &[u32], values: &mut [f64]) -> Status {
        const CALL: &str = "fmi2GetReal";
        let status = self.check_get(CALL, vrs.len(), values.len());
        if status > Status::Warning {
            return status;
        }
        match self.reader().get_reals(vrs, values) {
            // whatever a host reads with fmi2OK is a number: a model whose parameters give
            // no finite value (before initialisation, where they are not yet checked, or
            // through a physics fault) says so instead
            Ok(()) => match values.iter().position(|v| !v.is_finite()) {
                None => status,
                Some(k) => self.non_finite_real(vrs[k], values[k]),
            },
            Err(vr) => self.unknown(CALL, VarType::Real, vr),
        }
    }

    /// fmi2GetReal found a value that is not finite: an error naming its variable.
    #[cold]
    #[inline(never)]
    fn non_finite_real(&mut self, vr: u32, value: f64) -> Status {
        let name = self.index.lookup(VarType::Real, vr).map_or_else(
            || vr.to_string(),
            |i| format!("'{}'", self.model.metas()[i].name),
        );
        let hint = if self.state == FmiState::StepComplete {
            "the model cannot compute it from its state and inputs"
        } else {
            "the parameters give no finite value (they are checked at \
             fmi2ExitInitializationMode, which names the one that is refused)"
        };
        let msg = format!("fmi2GetReal: {name} is {value} ({hint})");
        self.error(&msg)
    }

    pub fn get_integer(&mut self, vrs: &[u32], values: &mut [i32]) -> Status {
        let status = self.check_get("fmi2GetInteger", vrs.len(), values.len());
        if status > Status::Warning {
            return status;
        }
        // every value reference first: a refused call leaves the host's array as it was
        for vr in vrs {
            if let Err(s) = self.resolve("fmi2GetInteger", VarType::Integer, *vr) {
                return s;
            }
        }
        for (vr, out) in vrs.iter().zip(values.iter_mut()) {
            let i = match self.resolve("fmi2GetInteger", VarType::Integer, *vr) {
                Ok(i) => i,
                Err(s) => return s,
            };
            match self.reader().get_integer(i) {
                Some(v) => *out = v,
                None => return self.error("fmi2GetInteger: internal type mismatch"),
            }
        }
        status
    }

    pub fn get_boolean(&mut self, vrs: &[u32], values: &mut [bool]) -> Status {
        let status = self.check_get("fmi2GetBoolean", vrs.len(), values.len());
        if status > Status::Warning {
            return status;
        }
        for (vr, out) in vrs.iter().zip(values.iter_mut()) {
            let i = match self.resolve("fmi2GetBoolean", VarType::Boolean, *vr) {
                Ok(i) => i,
                Err(s) => return s,
            };
            match self.reader().get_boolean(i) {
                Some(v) => *out = v,
                None => return self.error("fmi2GetBoolean: internal type mismatch"),
            }
        }
        status
    }

    pub fn get_string(&mut self, vrs: &[u32], values: &mut [String]) -> Status {
        let status = self.check_get("fmi2GetString", vrs.len(), values.len());
        if status > Status::Warning {
            return status;
        }
        for (vr, out) in vrs.iter().zip(values.iter_mut()) {
            let i = match self.resolve("fmi2GetString", VarType::String, *vr) {
                Ok(i) => i,
                Err(s) => return s,
            };
            match self.reader().get_string(i) {
                Some(v) => *out = v,
                None => return self.error("fmi2GetString: internal type mismatch"),
            }
        }
        status
    }

    /// Whether variable `i` may be set now (FMI 2.0 rules for co-simulation).
    fn check_settable(&mut self, call: &str, i: usize) -> Result<(), Status> {
        if !matches!(
            self.state,
            FmiState::Instantiated | FmiState::InitializationMode | FmiState::StepComplete
        ) {
            return Err(self.wrong_state(call));
        }
        if self.rules.get(i).is_some_and(|r| r.settable(self.state)) {
            return Ok(());
        }
        let meta = &self.model.metas()[i];
        let (causality, variability) = (meta.causality, meta.variability);
        let name = self.model.metas()[i].name.clone();
        let msg = match (causality, variability, self.state) {
            (Causality::Parameter, Variability::Fixed, FmiState::StepComplete) => format!(
                "{call}: '{name}' is a fixed parameter; it can only be set before fmi2ExitInitializationMode"
            ),
            _ => format!(
                "{call}: '{name}' has causality {} and cannot be set",
                causality.xml_name()
            ),
        };
        Err(self.error(&msg))
    }

    fn check_range(&mut self, call: &str, i: usize, value: f64) -> Result<(), Status> {
        let meta = &self.model.metas()[i];
        if let Some(e) = meta.enumeration {
            if e.item(value as i32).is_none() {
                let msg = format!(
                    "{call}: '{}' = {value} is not an item of the enumeration {} ({})",
                    meta.name,
                    e.name,
                    e.item_list()
                );
                return Err(self.error(&msg));
            }
        }
        if !value.is_finite() {
            let msg = format!("{call}: '{}' = {value} is not a finite number", meta.name);
            return Err(self.error(&msg));
        }
        if meta.min.is_some_and(|lo| value < lo) || meta.max.is_some_and(|hi| value > hi) {
            let msg = format!(
                "{call}: '{}' = {value:?} is outside its range [{}, {}]",
                meta.name,
                meta.min.map_or("-inf".into(), |v| v.to_string()),
                meta.max.map_or("+inf".into(), |v| v.to_string())
            );
            return Err(self.error(&msg));
        }
        Ok(())
    }

    #[inline]
    fn check_set_common(&mut self, call: &str, nvr: usize, nvalue: usize) -> Result<(), Status> {
        if !matches!(
            self.state,
            FmiState::Instantiated | FmiState::InitializationMode | FmiState::StepComplete
        ) {
            return Err(self.wrong_state(call));
        }
        if nvr != nvalue {
            return Err(self.count_mismatch(call, nvr, nvalue));
        }
        Ok(())
    }

    /// Set Reals. All values are checked before any is applied: a rejected call changes nothing.
    #[inline]
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Status {
        const CALL: &str = "fmi2SetReal";
        if let Err(s) = self.check_set_common(CALL, vrs.len(), values.len()) {
            return s;
        }
        // the common case: every value reference is a Real whose rule accepts the value now
        let state = self.state;
        let accepted = vrs.iter().zip(values).all(|(&vr, &v)| {
            self.real_rules
                .get(vr as usize)
                .is_some_and(|r| r.settable(state) && r.accepts(v))
        });
        if !accepted {
            return self.set_real_checked(vrs, values);
        }
        self.outputs_dirty = true;
        if state == FmiState::InitializationMode {
            self.mirror_initial_inputs(vrs, values);
        }
        match self.model.set_reals(vrs, values) {
            Ok(()) => Status::Ok,
            Err(vr) => self.error(&format!("{CALL}: internal: no setter for Real {vr}")),
        }
    }

    /// [`Self::set_real`] with the full checks, which name the first refused value.
    #[cold]
    #[inline(never)]
    fn set_real_checked(&mut self, vrs: &[u32], values: &[f64]) -> Status {
        const CALL: &str = "fmi2SetReal";
        for (vr, v) in vrs.iter().zip(values) {
            let i = match self.resolve(CALL, VarType::Real, *vr) {
                Ok(i) => i,
                Err(s) => return s,
            };
            // the rule decides the common case; the full checks name what is refused
            let passes = self
                .rules
                .get(i)
                .is_some_and(|r| r.settable(self.state) && r.accepts(*v));
            if !passes {
                let checked = self
                    .check_settable(CALL, i)
                    .and_then(|()| self.check_range(CALL, i, *v));
                if let Err(s) = checked {
                    return s;
                }
            }
        }
        self.outputs_dirty = true;
        if self.state == FmiState::InitializationMode {
            self.mirror_initial_inputs(vrs, values);
        }
        match self.model.set_reals(vrs, values) {
            Ok(()) => Status::Ok,
            Err(vr) => self.error(&format!("{CALL}: internal: no setter for Real {vr}")),
        }
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> Status {
        const CALL: &str = "fmi2SetInteger";
        if let Err(s) = self.check_set_common(CALL, vrs.len(), values.len()) {
            return s;
        }
        for (vr, v) in vrs.iter().zip(values) {
            let checked = self
                .resolve(CALL, VarType::Integer, *vr)
                .and_then(|i| self.check_settable(CALL, i).map(|_| i))
                .and_then(|i| self.check_range(CALL, i, f64::from(*v)));
            if let Err(s) = checked {
                return s;
            }
        }
        for (vr, v) in vrs.iter().zip(values) {
            if let Some(i) = self.index.lookup(VarType::Integer, *vr) {
                self.model.set_integer(i, *v);
            }
        }
        // a parameter (or a non-Real input) set: Initialization Mode's copy is made again
        self.initial_view = None;
        self.outputs_dirty = true;
        Status::Ok
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[bool]) -> Status {
        const CALL: &str = "fmi2SetBoolean";
        if let Err(s) = self.check_set_common(CALL, vrs.len(), values.len()) {
            return s;
        }
        for vr in vrs {
            let checked = self
                .resolve(CALL, VarType::Boolean, *vr)
                .and_then(|i| self.check_settable(CALL, i));
            if let Err(s) = checked {
                return s;
            }
        }
        for (vr, v) in vrs.iter().zip(values) {
            if let Some(i) = self.index.lookup(VarType::Boolean, *vr) {
                self.model.set_boolean(i, *v);
            }
        }
        // a parameter (or a non-Real input) set: Initialization Mode's copy is made again
        self.initial_view = None;
        self.outputs_dirty = true;
        Status::Ok
    }

    pub fn set_string(&mut self, vrs: &[u32], values: &[&str]) -> Status {
        const CALL: &str = "fmi2SetString";
        if let Err(s) = self.check_set_common(CALL, vrs.len(), values.len()) {
            return s;
        }
        for vr in vrs {
            let checked = self
                .resolve(CALL, VarType::String, *vr)
                .and_then(|i| self.check_settable(CALL, i));
            if let Err(s) = checked {
                return s;
            }
        }
        for (vr, v) in vrs.iter().zip(values) {
            if let Some(i) = self.index.lookup(VarType::String, *vr) {
                self.model.set_string(i, v);
            }
        }
        // a parameter (or a non-Real input) set: Initialization Mode's copy is made again
        self.initial_view = None;
        self.outputs_dirty = true;
        Status::Ok
    }

    /// Tolerance for comparing a host's communication point with our time. Our time is the
    /// host's previous point plus its step, so the two differ only by how the host forms its
    /// next point (t += h, t0 + n h, integer nanoseconds converted): a few ulps of t. 16 ulps
    /// of t, plus a nanosecond and a billionth of the step, so that a point 1 ms off is
    /// refused at t = 1.7e9 s (an epoch start time) as at t = 0.
    fn time_tolerance(&self, step: f64) -> f64 {
        1.0e-9 * (1.0 + step.abs()) + 16.0 * f64::EPSILON * self.time.abs()
    }

    #[inline]
    pub fn do_step(&mut self, current: f64, step: f64) -> Status {
        // the common case in one test: step mode, a finite step from our own time (to the
        // tolerance), not beyond the stop time; anything else is named by `step_refused`
        let tol = self.time_tolerance(step);
        let target = current + step;
        let valid = self.state == FmiState::StepComplete
            && current.is_finite()
            && step.is_finite()
            && step >= 0.0
            && target.is_finite()
            // a positive step below the time resolution at `current` would not advance time
            && (target > current || step == 0.0)
            && (current - self.time).abs() <= tol
            && self.stop_time.is_none_or(|stop| target <= stop + tol);
        if !valid {
            return self.step_refused(current, step);
        }
        // Step from our own time to the host's target, so drift never accumulates.
        let effective = target - self.time;
        if effective > 0.0 {
            if effective > self.max_step_s {
                return self.step_too_long(effective);
            }
            if let Err(e) = self.model.do_step(self.time, effective, &mut self.diag) {
                return self.step_failed(e, effective);
            }
        }
        // a point within the tolerance before our time with a shorter step: time stays, it
        // never goes back without a restored state
        self.time = target.max(self.time);
        self.last_successful_time = self.time;
        // a model whose step computed its outputs needs no second computation before a read
        self.outputs_dirty = !(effective > 0.0 && self.model.step_computes_outputs());
        self.flush_diagnostics()
    }

    /// A step longer than the model takes at once: discarded before the model sees it.
    #[cold]
    #[inline(never)]
    fn step_too_long(&mut self, effective: f64) -> Status {
        let reason = format!(
            "communication step {effective:?} s is longer than {} s: take several shorter steps",
            self.max_step_s
        );
        self.step_failed(StepError::Discard(reason), effective)
    }

    /// fmi2DoStep refused before stepping: the first failed check, named.
    #[cold]
    #[inline(never)]
    fn step_refused(&mut self, current: f64, step: f64) -> Status {
        const CALL: &str = "fmi2DoStep";
        if self.state != FmiState::StepComplete {
            return self.wrong_state(CALL);
        }
        if !current.is_finite() || !step.is_finite() || step < 0.0 || !(current + step).is_finite()
        {
            let msg = format!("{CALL}: invalid communication point {current:?} or step {step:?}");
            return self.error(&msg);
        }
        if step > 0.0 && current + step == current {
            let msg = format!(
                "{CALL}: step {step:?} s is below the time resolution at t = {current:?} s \
                 (t + h == t): it would not advance time"
            );
            return self.error(&msg);
        }
        let tol = self.time_tolerance(step);
        if (current - self.time).abs() > tol {
            let msg = format!(
                "{CALL}: communication point {current:?} does not match the instance time {:?} \
                 (restore an FMU state to go back in time)",
                self.time
            );
            return self.error(&msg);
        }
        let target = current + step;
        if let Some(stop) = self.stop_time {
            if target > stop + tol {
                let msg = format!("{CALL}: step to {target:?} goes beyond the stop time {stop:?}");
                return self.error(&msg);
            }
        }
        let msg = format!("{CALL}: internal: step from {current:?} over {step:?} refused");
        self.error(&msg)
    }

    /// The model's step failed: discarded (the instance may be restored) or an error.
    #[cold]
    #[inline(never)]
    fn step_failed(&mut self, e: StepError, effective: f64) -> Status {
        const CALL: &str = "fmi2DoStep";
        let _ = self.flush_diagnostics();
        match e {
            StepError::Discard(reason) => {
                self.state = FmiState::StepFailed;
                let msg = format!(
                    "{CALL}: step from {:?} over {effective:?} s discarded: {reason}",
                    self.time
                );
                self.sink.log(Status::Discard, "logStatusDiscard", &msg);
                Status::Discard
            }
            StepError::Error(e) => {
                self.state = FmiState::Error;
                let msg = format!("{CALL}: step from {:?} failed: {e}", self.time);
                self.error(&msg)
            }
        }
    }

    /// fmi2GetXXXStatus is allowed after the first step only: step complete, step failed or
    /// terminated (FMI 2.0 co-simulation state machine, 4.2.4; the Reference FMUs' mask).
    pub fn check_status_query(&mut self, call: &str) -> Result<(), Status> {
        match self.state {
            FmiState::StepComplete | FmiState::StepFailed | FmiState::Terminated => Ok(()),
            _ => Err(self.wrong_state(call)),
        }
    }

    pub fn last_successful_time(&self) -> f64 {
        self.last_successful_time
    }

    pub fn is_terminated(&self) -> bool {
        self.state == FmiState::Terminated
    }

    /// Allowed in every state but Fatal, the Error state included (FMI 2.0, 4.2.4): a state
    /// taken there restores to the Error state, whose refusals keep the model from stepping.
    pub fn get_fmu_state(&mut self) -> Result<Box<Snapshot>, Status> {
        Ok(Box::new(Snapshot {
            id: next_snapshot_id(),
            model: self.model.snapshot(),
            time: self.time,
            state: self.state,
            start_time: self.start_time,
            stop_time: self.stop_time,
        }))
    }

    /// fmi2GetFMUstate with an existing state: overwrite it without a new allocation.
    pub fn update_fmu_state(&mut self, snapshot: &mut Snapshot) -> Status {
        if !self.model.update_snapshot(snapshot.model.as_mut()) {
            return self.error("fmi2GetFMUstate: the given FMU state belongs to another model");
        }
        snapshot.id = next_snapshot_id();
        snapshot.time = self.time;
        snapshot.state = self.state;
        snapshot.start_time = self.start_time;
        snapshot.stop_time = self.stop_time;
        Status::Ok
    }

    /// fmi2FreeFMUstate: a state of this model (a state of another model in the same binary
    /// is refused, not freed as if it were one of ours).
    pub fn check_own_fmu_state(&mut self, snapshot: &Snapshot) -> Status {
        if self.model.owns(snapshot.model.as_ref()) {
            Status::Ok
        } else {
            self.error("fmi2FreeFMUstate: the given FMU state belongs to another model")
        }
    }

    pub fn set_fmu_state(&mut self, snapshot: &Snapshot) -> Status {
        if !self.model.restore(snapshot.model.as_ref()) {
            return self.error("fmi2SetFMUstate: the given FMU state belongs to another model");
        }
        self.time = snapshot.time;
        self.last_successful_time = snapshot.time;
        self.state = snapshot.state;
        self.start_time = snapshot.start_time;
        self.stop_time = snapshot.stop_time;
        self.initial_view = None;
        self.outputs_dirty = true;
        Status::Ok
    }

    pub fn serialize_fmu_state(&mut self, snapshot: &Snapshot) -> Result<Vec<u8>, Status> {
        let Some(model) = self.model.serialize(snapshot.model.as_ref()) else {
            return Err(self.error("fmi2SerializeFMUstate: the FMU state cannot be serialised"));
        };
        let header = SnapshotHeader {
            magic: MAGIC,
            time: snapshot.time,
            state: snapshot.state,
            start_time: snapshot.start_time,
            stop_time: snapshot.stop_time,
            model,
        };
        let mut bytes = bincode::serialize(&header)
            .map_err(|e| self.error(&format!("fmi2SerializeFMUstate: {e}")))?;
        seal(&mut bytes);
        Ok(bytes)
    }

    pub fn deserialize_fmu_state(&mut self, bytes: &[u8]) -> Result<Box<Snapshot>, Status> {
        const CALL: &str = "fmi2DeSerializeFMUstate";
        // bytes altered, cut or extended since this FMU wrote them are refused whole here;
        // the checks below name what is wrong in a state that is sealed but still invalid
        let Some(bytes) = unseal(bytes) else {
            let msg = format!(
                "{CALL}: {} bytes are not exactly one serialised state of this FMU: their \
                 checksum does not match (altered, truncated or extended since it wrote them)",
                bytes.len()
            );
            return Err(self.error(&msg));
        };
        let header: SnapshotHeader = match strict_bincode(bytes) {
            Ok(h) => h,
            Err(e) => {
                let msg = format!(
                    "{CALL}: {} bytes are not exactly one serialised state of this FMU: {e}",
                    bytes.len()
                );
                return Err(self.error(&msg));
            }
        };
        if header.magic != MAGIC {
            return Err(self.error(&format!("{CALL}: not a serialised state of this FMU")));
        }
        let times_ok = header.time.is_finite()
            && header.start_time.is_finite()
            && header
                .stop_time
                .is_none_or(|s| s.is_finite() && s >= header.start_time);
        if !times_ok {
            let msg = format!(
                "{CALL}: the serialised state has an invalid time (t = {:?}, start {:?}, stop {:?})",
                header.time, header.start_time, header.stop_time
            );
            return Err(self.error(&msg));
        }
        let model = match self.model.deserialize(&header.model) {
            Ok(m) => m,
            Err(reason) => return Err(self.error(&format!("{CALL}: {reason}"))),
        };
        Ok(Box::new(Snapshot {
            id: next_snapshot_id(),
            model,
            time: header.time,
            state: header.state,
            start_time: header.start_time,
            stop_time: header.stop_time,
        }))
    }
}
