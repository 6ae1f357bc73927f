//! A small, tolerant reader for FMI 2.0 `modelDescription.xml`.
//!
//! Why not `fmi::schema::fmi2` (fmi-schema 0.8)? It drops the `unit` attribute of `Real`
//! variables (needed for the unit check of connections and for CSV headers), cannot tell an
//! absent `dependencies` attribute (= depends on everything) from an empty one (= depends on
//! nothing), and rejects any attribute it does not know (e.g. `canHandleMultipleSetPerTimeInstant`).
//! So the master reads the few things it needs itself, with `xmlparser`, and reports errors with
//! a line number. This is the only parse of the description: the binary is loaded and called
//! from it (see [`crate::fmu`]).

mod parse;
mod rules;

/// Error reading a modelDescription.xml. Lines are 1-based.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelDescriptionError {
    #[error("XML syntax error: {0}")]
    Xml(String),
    #[error("line {line}: <{element}> lacks the required attribute '{attribute}'")]
    MissingAttribute {
        element: String,
        attribute: String,
        line: usize,
    },
    #[error("line {line}: <{element} {attribute}=\"{value}\">: {reason}")]
    InvalidAttribute {
        element: String,
        attribute: String,
        value: String,
        line: usize,
        reason: String,
    },
    #[error("no <fmiModelDescription> root element")]
    NoRoot,
    #[error("variable '{name}' (line {line}) has no type element (Real, Integer, Boolean, String or Enumeration)")]
    NoType { name: String, line: usize },
    #[error(
        "variable '{name}' refers to declaredType '{declared}', which is not in TypeDefinitions"
    )]
    UnknownDeclaredType { name: String, declared: String },
    #[error("ModelStructure (line {line}) refers to variable index {index}, but there are only {count} variables")]
    IndexOutOfRange {
        index: usize,
        count: usize,
        line: usize,
    },
    #[error("ModelStructure/Outputs (line {line}): {reason}")]
    OutputStructure { line: usize, reason: String },
    #[error("variable name '{name}' is used twice")]
    DuplicateName { name: String },
    #[error("variable '{name}' (line {line}): invalid name: {reason}")]
    InvalidName {
        name: String,
        line: usize,
        reason: String,
    },
    #[error("variable '{name}' (line {line}): {reason}")]
    InvalidVariable {
        name: String,
        line: usize,
        reason: String,
    },
    #[error("variable '{name}' (line {line}) has valueReference {value_reference} like '{other}': {reason}")]
    ValueReference {
        name: String,
        line: usize,
        other: String,
        value_reference: u32,
        reason: String,
    },
}

/// Scalar type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
    Enumeration,
}

impl std::fmt::Display for VarType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
            VarType::Enumeration => "Enumeration",
        };
        f.write_str(s)
    }
}

/// FMI 2.0 causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
    Independent,
}

impl Causality {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "parameter" => Causality::Parameter,
            "calculatedParameter" => Causality::CalculatedParameter,
            "input" => Causality::Input,
            "output" => Causality::Output,
            "local" => Causality::Local,
            "independent" => Causality::Independent,
            _ => return None,
        })
    }
}

impl std::fmt::Display for Causality {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
            Causality::Independent => "independent",
        };
        f.write_str(s)
    }
}

/// FMI 2.0 variability.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "constant" => Variability::Constant,
            "fixed" => Variability::Fixed,
            "tunable" => Variability::Tunable,
            "discrete" => Variability::Discrete,
            "continuous" => Variability::Continuous,
            _ => return None,
        })
    }
}

impl std::fmt::Display for Variability {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            Variability::Constant => "constant",
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        };
        f.write_str(s)
    }
}

/// One `<ScalarVariable>`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Variable {
    pub name: String,
    pub value_reference: u32,
    pub causality: Causality,
    pub variability: Variability,
    /// `exact`, `approx` or `calculated` as written (None if absent).
    pub initial: Option<String>,
    pub var_type: VarType,
    /// Own `unit`, else the unit of its `declaredType`.
    pub unit: Option<String>,
    pub start: Option<String>,
    pub description: Option<String>,
    /// `declaredType` of the type element, if any (an Enumeration's items are its type's).
    pub declared_type: Option<String>,
    /// A Real's or Integer's declared `min` and `max` (its own, else its declared type's); a
    /// start value outside them is refused before a run (the FMU would refuse it at
    /// fmi2SetXXX, in every run).
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// A Real's `relativeQuantity` (its own, else its declared type's): the value is a
    /// difference, converted between units without their BaseUnit offsets (FMI 2.0, 2.2.7).
    pub relative_quantity: bool,
}

/// One `<Item>` of an Enumeration type.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnumItem {
    pub name: String,
    pub value: i32,
    pub description: Option<String>,
}

impl Variable {
    /// Whether a start value may be set before initialisation (FMI 2.0 section 2.2.7:
    /// parameters, inputs, and variables with initial = exact or approx).
    pub fn is_settable(&self) -> bool {
        self.variability != Variability::Constant
            && (matches!(self.causality, Causality::Parameter | Causality::Input)
                || matches!(self.initial.as_deref(), Some("exact") | Some("approx")))
    }
}

/// Co-simulation capabilities from `<CoSimulation>`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CoSimulationCaps {
    pub model_identifier: String,
    pub can_get_and_set_fmu_state: bool,
    pub can_serialize_fmu_state: bool,
    pub can_handle_variable_communication_step_size: bool,
    pub can_be_instantiated_only_once_per_process: bool,
}

/// `<DefaultExperiment>`.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct DefaultExperiment {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub step_size: Option<f64>,
}

/// One `<Unknown>` of `<ModelStructure><Outputs>`: indices are 0-based into `variables`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OutputDependency {
    pub output: usize,
    /// `None`: attribute absent, the output may depend on every known (inputs, states, time).
    pub depends_on: Option<Vec<usize>>,
}

/// What the master needs from a modelDescription.xml.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModelDescription {
    pub fmi_version: String,
    pub model_name: String,
    pub guid: String,
    pub co_simulation: Option<CoSimulationCaps>,
    pub has_model_exchange: bool,
    pub default_experiment: Option<DefaultExperiment>,
    pub variables: Vec<Variable>,
    pub outputs: Vec<OutputDependency>,
    /// Enumeration SimpleTypes of TypeDefinitions: type name -> items in declaration order.
    pub enumerations: std::collections::BTreeMap<String, Vec<EnumItem>>,
    /// UnitDefinitions with a BaseUnit: unit name -> its definition in SI base units.
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub units: std::collections::BTreeMap<String, BaseUnit>,
}

/// A unit in SI base units (FMI 2.0, 2.2.2 `BaseUnit`): value in SI = factor * value + offset,
/// with the exponents of kg, m, s, A, K, mol, cd and rad.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BaseUnit {
    pub exponents: [i64; 8],
    pub factor: f64,
    pub offset: f64,
}

/// The base units' attribute names, in the order of [`BaseUnit::exponents`].
pub const BASE_UNIT_NAMES: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

impl ModelDescription {
    /// Index and variable by exact name.
    pub fn variable(&self, name: &str) -> Option<(usize, &Variable)> {
        self.variables
            .iter()
            .enumerate()
            .find(|(_, v)| v.name == name)
    }

    /// The items of an Enumeration variable (empty for other types or an unknown type).
    pub fn enum_items(&self, v: &Variable) -> &[EnumItem] {
        match (&v.var_type, &v.declared_type) {
            (VarType::Enumeration, Some(t)) => {
                self.enumerations.get(t).map(Vec::as_slice).unwrap_or(&[])
            }
            _ => &[],
        }
    }

    /// The closest variable name (edit distance at most max(2, len/3)), for "did you mean".
    pub fn suggest(&self, name: &str) -> Option<&str> {
        let limit = (name.chars().count() / 3).max(2);
        self.variables
            .iter()
            .map(|v| (edit_distance(name, &v.name), v.name.as_str()))
            .filter(|(d, _)| *d <= limit)
            .min_by_key(|(d, _)| *d)
            .map(|(_, n)| n)
    }

    /// Whether input `input` (0-based variable index) feeds directly (algebraically) to at
    /// least one output, per ModelStructure/Outputs. An output without a `dependencies`
    /// attribute depends on everything; an output not listed at all is treated the same way
    /// (conservative).
    /// Whether output `output` depends directly on input `input` (both 0-based variable
    /// indices), per ModelStructure/Outputs; an unlisted output or one without `dependencies`
    /// depends on every input (conservative).
    pub fn output_depends_on(&self, output: usize, input: usize) -> bool {
        match self.outputs.iter().find(|o| o.output == output) {
            Some(OutputDependency {
                depends_on: Some(d),
                ..
            }) => d.contains(&input),
            _ => true,
        }
    }

    pub fn has_direct_feedthrough(&self, input: usize) -> bool {
        // linear in the number of variables: a set of the listed outputs, not a search per
        // output variable
        let listed: std::collections::HashSet<usize> =
            self.outputs.iter().map(|o| o.output).collect();
        let unlisted_output = self
            .variables
            .iter()
            .enumerate()
            .any(|(i, v)| v.causality == Causality::Output && !listed.contains(&i));
        unlisted_output
            || self.outputs.iter().any(|o| match &o.depends_on {
                None => true,
                Some(d) => d.contains(&input),
            })
    }
}

/// Levenshtein distance on chars.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

#[cfg(test)]
pub(crate) mod tests;
