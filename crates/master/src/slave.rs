//! The co-simulation unit as the coupling algorithm sees it.
//!
//! [`crate::fmu::FmuSlave`] implements it for a real FMU; tests implement it in plain Rust, so
//! the coupling algorithm (Jacobi, Gauss-Seidel, step retry, initialisation, cancellation) is
//! tested without any shared library.

/// Scalar type of an exchanged or recorded value. Every value travels as `f64`: integers
/// and enumeration values are exact in `f64`, booleans are 0/1, and a String is the index of
/// its text in the run's [`StringTable`] (so a string value is copied, compared and recorded
/// like any other).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ScalarType {
    Real,
    Integer,
    Boolean,
    /// Read and written with fmi2GetInteger / fmi2SetInteger (FMI 2.0 section 2.2.3).
    Enumeration,
    String,
}

impl std::fmt::Display for ScalarType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ScalarType::Real => "Real",
            ScalarType::Integer => "Integer",
            ScalarType::Boolean => "Boolean",
            ScalarType::Enumeration => "Enumeration",
            ScalarType::String => "String",
        })
    }
}

/// The texts of the String values of one run; a String value is the index of its text here
/// (as `f64`). Texts are interned, so equal strings have equal indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StringTable {
    texts: Vec<String>,
    index: std::collections::HashMap<String, usize>,
}

impl StringTable {
    /// A table holding `texts` at their positions.
    pub fn from_texts(texts: &[String]) -> Self {
        let mut t = StringTable::default();
        for s in texts {
            let k = t.texts.len();
            t.texts.push(s.clone());
            t.index.entry(s.clone()).or_insert(k);
        }
        t
    }
    /// The value of `s` (its index, added if new).
    pub fn intern(&mut self, s: &str) -> f64 {
        if let Some(&k) = self.index.get(s) {
            return k as f64;
        }
        let k = self.texts.len();
        self.texts.push(s.to_string());
        self.index.insert(s.to_string(), k);
        k as f64
    }
    /// The text of a String value (`None` if it is no index of this table).
    pub fn text(&self, value: f64) -> Option<&str> {
        if value >= 0.0 && value.fract() == 0.0 {
            self.texts.get(value as usize).map(String::as_str)
        } else {
            None
        }
    }
    pub fn texts(&self) -> &[String] {
        &self.texts
    }
    pub fn into_texts(self) -> Vec<String> {
        self.texts
    }
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
    groups: [TypeGroup; 4],
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
        let mut groups: [TypeGroup; 4] = Default::default();
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
            // an Enumeration is read and written as an Integer: one call for both
            ScalarType::Integer | ScalarType::Enumeration => 1,
            ScalarType::Boolean => 2,
            ScalarType::String => 3,
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
    /// The variables of type `ty` (Integer and Enumeration share one group).
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
#[error(
    "instance '{instance}': {call} failed with {status}{}",
    reason.as_deref().map(|r| format!(": {r}")).unwrap_or_default()
)]
pub struct SlaveError {
    pub instance: String,
    pub call: &'static str,
    pub status: FailStatus,
    /// What the FMU logged with that status during the call (its logger messages), if
    /// anything: the cause, also where the log is not seen (Python, a Dask worker).
    pub reason: Option<Box<str>>,
}

/// One co-simulation unit (FMI 2.0 co-simulation slave semantics).
pub trait Slave {
    fn name(&self) -> &str;
    /// fmi2SetupExperiment (no tolerance, with stop time).
    fn setup_experiment(&mut self, start_time: f64, stop_time: f64) -> Result<(), SlaveError>;
    fn enter_initialization_mode(&mut self) -> Result<(), SlaveError>;
    fn exit_initialization_mode(&mut self) -> Result<(), SlaveError>;
    /// Reads a batch, one call per numeric type; `out.len() == batch.len()`. The String
    /// positions are left as they are (the master reads them with [`Slave::get_strings`]).
    fn get(&mut self, batch: &VarBatch, out: &mut [f64]) -> Result<(), SlaveError>;
    /// Writes a batch, one call per numeric type; `values.len() == batch.len()`. The String
    /// positions are ignored (the master writes them with [`Slave::set_strings`]).
    fn set(&mut self, batch: &VarBatch, values: &[f64]) -> Result<(), SlaveError>;
    /// Writes Reals by value reference in one call (`values.len() == vrs.len()`): the inputs
    /// of one instance gathered from several sources. The default goes through
    /// [`Slave::set`].
    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), SlaveError> {
        let batch = VarBatch::new(vrs.iter().map(|&vr| VarRef::real(vr)).collect());
        self.set(&batch, values)
    }
    /// fmi2GetString of `vrs` into `out` (cleared first, one text per reference).
    fn get_strings(&mut self, vrs: &[u32], out: &mut Vec<String>) -> Result<(), SlaveError> {
        let _ = (vrs, out);
        Err(SlaveError {
            instance: self.name().to_string(),
            call: "fmi2GetString",
            status: FailStatus::Other("this slave has no String variables".into()),
            reason: None,
        })
    }
    /// fmi2SetString of `vrs` to `values` (same length).
    fn set_strings(&mut self, vrs: &[u32], values: &[&str]) -> Result<(), SlaveError> {
        let _ = (vrs, values);
        Err(SlaveError {
            instance: self.name().to_string(),
            call: "fmi2SetString",
            status: FailStatus::Other("this slave has no String variables".into()),
            reason: None,
        })
    }
    /// After a step returned fmi2Discard: whether the slave asks to end the simulation
    /// (fmi2GetBooleanStatus(fmi2Terminated) is true, FMI 2.0 section 4.2.3), as opposed to a
    /// step a smaller step could complete.
    fn terminate_requested(&mut self) -> bool {
        false
    }
    /// After a step that ended the simulation: how far the slave got
    /// (fmi2GetRealStatus(fmi2LastSuccessfulTime)), if it says.
    fn last_successful_time(&mut self) -> Option<f64> {
        None
    }
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
        // Enumerations go with the Integers (one fmi2GetInteger call), Strings apart
        let b = VarBatch::new(vec![
            VarRef {
                vr: 3,
                ty: ScalarType::Enumeration,
            },
            VarRef {
                vr: 5,
                ty: ScalarType::String,
            },
            VarRef {
                vr: 7,
                ty: ScalarType::Integer,
            },
        ]);
        assert_eq!(b.group(ScalarType::Integer).vrs, [3, 7]);
        assert_eq!(b.group(ScalarType::Enumeration).positions, [0, 2]);
        assert_eq!(b.group(ScalarType::String).vrs, [5]);
        assert_eq!(b.group(ScalarType::String).positions, [1]);
    }

    #[test]
    fn string_table_interns_and_looks_up() {
        let mut t = StringTable::from_texts(&["a".into(), "b".into()]);
        assert_eq!(t.intern("b"), 1.0);
        assert_eq!(t.intern("c,\"q\""), 2.0);
        assert_eq!(t.text(2.0), Some("c,\"q\""));
        assert_eq!(t.text(0.0), Some("a"));
        assert_eq!(t.text(3.0), None);
        assert_eq!(t.text(0.5), None);
        assert_eq!(t.text(-1.0), None);
        assert_eq!(t.texts().len(), 3);
    }
}
