//! The trait a model crate implements; the glue does everything else.

use std::path::PathBuf;

use serde::{de::DeserializeOwned, Serialize};

use crate::variable::Variable;

/// Static facts about a model, written to modelDescription.xml and documentation/index.html.
#[derive(Clone, Copy, Debug)]
pub struct ModelInfo {
    /// modelName and modelIdentifier (the binary is `binaries/<platform>/<name>.so`).
    pub name: &'static str,
    pub description: &'static str,
    pub author: &'static str,
    pub version: &'static str,
    pub default_experiment: DefaultExperiment,
    /// HTML fragment for documentation/index.html: what the model is, its equations with the
    /// seed's equation numbers, its interpretations. The variable table is added by the glue.
    pub documentation_html: &'static str,
    /// Files shipped under `resources/` (path relative to resources/, bytes).
    pub resources: &'static [(&'static str, &'static [u8])],
}

#[derive(Clone, Copy, Debug)]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

/// What a model sees of its environment when it is created.
#[derive(Clone, Debug, Default)]
pub struct InstanceContext {
    pub instance_name: String,
    /// The unpacked `resources/` folder, when the host gave a file: URI.
    pub resource_dir: Option<PathBuf>,
}

/// An error a model reports; the glue turns it into fmi2Error plus a logged message.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ModelError {
    #[error("invalid parameter '{name}': {reason}")]
    InvalidParameter { name: String, reason: String },
    #[error("invalid input '{name}': {reason}")]
    InvalidInput { name: String, reason: String },
    #[error("{0}")]
    Other(String),
}

/// Outcome of a failed step.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum StepError {
    /// The step could not be completed (e.g. the solver did not converge with this step size);
    /// the model state is unchanged and the host may retry with a smaller step (fmi2Discard).
    #[error("step discarded: {0}")]
    Discard(String),
    /// The simulation cannot go on (fmi2Error).
    #[error("{0}")]
    Error(#[from] ModelError),
}

/// Messages a model wants logged (the glue forwards them to the host's logger, with a
/// category, and returns fmi2Warning from the call if any warning was raised).
#[derive(Debug, Default)]
pub struct Diagnostics {
    pub(crate) warnings: Vec<String>,
    pub(crate) events: Vec<String>,
}

impl Diagnostics {
    /// Something the host should know (e.g. a clamped command); the call returns fmi2Warning.
    pub fn warn(&mut self, message: impl Into<String>) {
        self.warnings.push(message.into());
    }

    /// An event worth logging in the `logEvents` category (only when debug logging is on).
    pub fn event(&mut self, message: impl Into<String>) {
        self.events.push(message.into());
    }

    pub fn is_empty(&self) -> bool {
        self.warnings.is_empty() && self.events.is_empty()
    }
}

/// A co-simulation model. Implement this and list the model in `export_fmus!`.
///
/// The model value holds parameters, inputs, states and outputs as plain data; FMU state
/// save/restore clones it and serialisation encodes it with bincode, so a restored run continues
/// bit for bit.
pub trait FmuModel: Clone + Send + Serialize + DeserializeOwned + 'static {
    const INFO: ModelInfo;

    /// The longest communication step one fmi2DoStep takes \[s\]: the glue discards a longer
    /// one (fmi2Discard, "take several shorter steps") before the model sees it, so that a
    /// model whose cost grows with the step does not keep a host waiting for minutes (or, at
    /// 1e300 s, for ever). Default: no limit.
    const MAX_COMMUNICATION_STEP_S: f64 = f64::INFINITY;

    /// The variables, in declaration order (this order sets value references and indices).
    fn variables() -> Vec<Variable<Self>>;

    /// A fresh instance with the default (start) values. Start values in modelDescription.xml
    /// are read from this instance through the getters, so the defaults have one source.
    fn instantiate(ctx: &InstanceContext) -> Result<Self, ModelError>;

    /// Called by fmi2ExitInitializationMode: validate parameters (naming the bad one) and compute
    /// consistent initial outputs.
    fn exit_initialization(&mut self, diag: &mut Diagnostics) -> Result<(), ModelError>;

    /// Called before outputs are read after inputs/parameters changed (e.g. outputs with direct
    /// feedthrough). Must not advance time.
    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        Ok(())
    }

    /// Advance from `time` to `time + step`. On error the model must be left as it was before
    /// the call (so a host can retry after fmi2Discard).
    fn do_step(&mut self, time: f64, step: f64, diag: &mut Diagnostics) -> Result<(), StepError>;

    /// A state decoded from bytes (fmi2DeSerializeFMUstate) holds, besides the variables the
    /// glue checks against their declarations, what the model derived from them at
    /// initialisation (its physics with a copy of the parameters): whether that still agrees
    /// with them. Bytes altered on purpose, with a valid checksum, are refused here rather
    /// than reaching the physics. Default: nothing derived to check.
    fn check_restored(&self) -> Result<(), String> {
        Ok(())
    }

    /// Whether a successful [`Self::do_step`] leaves the outputs exactly as
    /// [`Self::update_outputs`] would compute them at the new time with the held inputs. Then
    /// the outputs read after a step are not computed a second time (a co-simulation master
    /// reads them after every step); setting an input or parameter still recomputes them.
    fn step_computes_outputs(&self) -> bool {
        false
    }
}
