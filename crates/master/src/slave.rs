//! The co-simulation unit as the coupling algorithm sees it.
//!
//! [`crate::fmu::FmuSlave`] implements it for a real FMU; tests implement it in plain Rust, so
//! the coupling algorithm (Jacobi, Gauss-Seidel, step retry, initialisation, cancellation) is
//! tested without any shared library.

/// Scalar type of an exchanged or recorded value. Every value travels as `f64`: integers
/// are exact in `f64`, booleans are 0/1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ScalarType {
    Real,
    Integer,
    Boolean,
}

/// A variable of one slave: value reference plus type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct VarRef {
    pub vr: u32,
    pub ty: ScalarType,
}

impl VarRef {
    pub fn real(vr: u32) -> Self {
        VarRef {
            vr,
            ty: ScalarType::Real,
        }
    }
}

/// Outcome of a successful `do_step` call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepStatus {
    /// fmi2OK or fmi2Warning.
    Ok,
    /// fmi2Discard: the step was not completed; the master may retry with a smaller step.
    Discard,
}

/// Status of a failed call.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FailStatus {
    Discard,
    Error,
    Fatal,
    /// fmi2Pending or anything else the master does not support.
    Other(String),
}

impl std::fmt::Display for FailStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FailStatus::Discard => f.write_str("fmi2Discard"),
            FailStatus::Error => f.write_str("fmi2Error"),
            FailStatus::Fatal => f.write_str("fmi2Fatal"),
            FailStatus::Other(s) => f.write_str(s),
        }
    }
}

/// A failed call on one slave.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("instance '{instance}': {call} failed with {status}")]
pub struct SlaveError {
    pub instance: String,
    pub call: &'static str,
    pub status: FailStatus,
}

/// One co-simulation unit (FMI 2.0 co-simulation slave semantics).
pub trait Slave {
    fn name(&self) -> &str;
    /// fmi2SetupExperiment (no tolerance, with stop time).
    fn setup_experiment(&mut self, start_time: f64, stop_time: f64) -> Result<(), SlaveError>;
    fn enter_initialization_mode(&mut self) -> Result<(), SlaveError>;
    fn exit_initialization_mode(&mut self) -> Result<(), SlaveError>;
    /// Reads values; `out.len() == vars.len()`.
    fn get(&mut self, vars: &[VarRef], out: &mut [f64]) -> Result<(), SlaveError>;
    /// Writes values; `values.len() == vars.len()`.
    fn set(&mut self, vars: &[VarRef], values: &[f64]) -> Result<(), SlaveError>;
    /// fmi2DoStep(t, h, noSetFMUStatePriorToCurrentPoint = true).
    fn do_step(&mut self, t: f64, h: f64) -> Result<StepStatus, SlaveError>;
    /// Whether [`Slave::save_state`] / [`Slave::restore_state`] work (canGetAndSetFMUstate).
    fn can_save_state(&self) -> bool;
    /// canHandleVariableCommunicationStepSize: whether fmi2DoStep may be called with a step
    /// other than the first one (shortened last windows, retried sub-steps).
    fn can_vary_step(&self) -> bool;
    /// Saves the complete state into the slave's single save slot.
    fn save_state(&mut self) -> Result<(), SlaveError>;
    /// Restores the state saved last.
    fn restore_state(&mut self) -> Result<(), SlaveError>;
    fn terminate(&mut self) -> Result<(), SlaveError>;
}
