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

/// Variables of one slave read or written together: their value references grouped by type
/// once, so a slave makes one call per type (fmi2GetReal, fmi2GetInteger, fmi2GetBoolean and
/// the setters) for the whole batch. Values are in the order of [`VarBatch::vars`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VarBatch {
    vars: Vec<VarRef>,
    groups: [TypeGroup; 3],
}

/// The variables of one type within a batch.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TypeGroup {
    /// Value references, in batch order.
    pub vrs: Vec<u32>,
    /// Position of each in the batch.
    pub positions: Vec<usize>,
}

impl VarBatch {
    pub fn new(vars: Vec<VarRef>) -> Self {
        let mut groups: [TypeGroup; 3] = Default::default();
        for (k, v) in vars.iter().enumerate() {
            let g = &mut groups[Self::slot(v.ty)];
            g.vrs.push(v.vr);
            g.positions.push(k);
        }
        VarBatch { vars, groups }
    }

    fn slot(ty: ScalarType) -> usize {
        match ty {
            ScalarType::Real => 0,
            ScalarType::Integer => 1,
            ScalarType::Boolean => 2,
        }
    }

    pub fn vars(&self) -> &[VarRef] {
        &self.vars
    }
    pub fn len(&self) -> usize {
        self.vars.len()
    }
    pub fn is_empty(&self) -> bool {
        self.vars.is_empty()
    }
    /// The variables of type `ty`.
    pub fn group(&self, ty: ScalarType) -> &TypeGroup {
        &self.groups[Self::slot(ty)]
    }
    /// Whether every variable is Real (then the batch's values are the Real group's).
    pub fn all_real(&self) -> bool {
        self.groups[0].vrs.len() == self.vars.len()
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
    /// Reads a batch, one call per type; `out.len() == batch.len()`.
    fn get(&mut self, batch: &VarBatch, out: &mut [f64]) -> Result<(), SlaveError>;
    /// Writes a batch, one call per type; `values.len() == batch.len()`.
    fn set(&mut self, batch: &VarBatch, values: &[f64]) -> Result<(), SlaveError>;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batch_groups_by_type_and_keeps_positions() {
        let b = VarBatch::new(vec![
            VarRef::real(4),
            VarRef {
                vr: 9,
                ty: ScalarType::Integer,
            },
            VarRef::real(1),
            VarRef {
                vr: 2,
                ty: ScalarType::Boolean,
            },
        ]);
        assert_eq!(b.len(), 4);
        assert!(!b.all_real());
        assert_eq!(b.group(ScalarType::Real).vrs, [4, 1]);
        assert_eq!(b.group(ScalarType::Real).positions, [0, 2]);
        assert_eq!(b.group(ScalarType::Integer).positions, [1]);
        assert_eq!(b.group(ScalarType::Boolean).vrs, [2]);
        assert!(VarBatch::new(vec![VarRef::real(0)]).all_real());
        assert!(VarBatch::default().is_empty());
    }
}
