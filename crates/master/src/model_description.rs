//! A small, tolerant reader for FMI 2.0 `modelDescription.xml`.
//!
//! Why not `fmi::schema::fmi2` (fmi-schema 0.8)? It drops the `unit` attribute of `Real`
//! variables (needed for the unit check of connections and for CSV headers), cannot tell an
//! absent `dependencies` attribute (= depends on everything) from an empty one (= depends on
//! nothing), and rejects any attribute it does not know (e.g. `canHandleMultipleSetPerTimeInstant`).
//! So the master reads the few things it needs itself, with `xmlparser`, and reports errors with
//! a line number. This is the only parse of the description: the binary is loaded and called
//! from it (see [`crate::fmu`]).

use std::collections::HashMap;

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
    #[error("variable name '{name}' is used twice")]
    DuplicateName { name: String },
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
}

fn line_of(text: &str, pos: usize) -> usize {
    text.as_bytes()[..pos.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

struct Elem<'a> {
    name: &'a str,
    line: usize,
    attrs: Vec<(&'a str, String)>,
}

impl Elem<'_> {
    fn get(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v.as_str())
    }
    fn req(&self, key: &str) -> Result<&str, ModelDescriptionError> {
        self.get(key)
            .ok_or_else(|| ModelDescriptionError::MissingAttribute {
                element: self.name.to_string(),
                attribute: key.to_string(),
                line: self.line,
            })
    }
    fn invalid(&self, key: &str, value: &str, reason: &str) -> ModelDescriptionError {
        ModelDescriptionError::InvalidAttribute {
            element: self.name.to_string(),
            attribute: key.to_string(),
            value: value.to_string(),
            line: self.line,
            reason: reason.to_string(),
        }
    }
    fn bool(&self, key: &str) -> Result<bool, ModelDescriptionError> {
        match self.get(key) {
            None | Some("false") | Some("0") => Ok(false),
            Some("true") | Some("1") => Ok(true),
            Some(v) => Err(self.invalid(key, v, "expected true or false")),
        }
    }
    fn f64(&self, key: &str) -> Result<Option<f64>, ModelDescriptionError> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => v
                .trim()
                .parse::<f64>()
                .map(Some)
                .map_err(|_| self.invalid(key, v, "expected a number")),
        }
    }
}

/// Replaces the five predefined XML entities and numeric character references.
fn unescape(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        rest = &rest[i..];
        let end = rest.find(';').unwrap_or(0);
        let ent = &rest[1..end.max(1)];
        let rep = match ent {
            "lt" => Some('<'),
            "gt" => Some('>'),
            "amp" => Some('&'),
            "quot" => Some('"'),
            "apos" => Some('\''),
            _ if ent.starts_with("#x") => u32::from_str_radix(&ent[2..], 16)
                .ok()
                .and_then(char::from_u32),
            _ if ent.starts_with('#') => ent[1..].parse::<u32>().ok().and_then(char::from_u32),
            _ => None,
        };
        match (end, rep) {
            (e, Some(c)) if e > 0 => {
                out.push(c);
                rest = &rest[e + 1..];
            }
            _ => {
                out.push('&');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

#[derive(Default)]
struct PendingVar {
    name: String,
    vr: u32,
    causality: Option<Causality>,
    variability: Option<Variability>,
    initial: Option<String>,
    description: Option<String>,
    line: usize,
    var_type: Option<VarType>,
    unit: Option<String>,
    declared_type: Option<String>,
    start: Option<String>,
}

impl ModelDescription {
    /// Parses the text of a modelDescription.xml.
    pub fn parse(xml: &str) -> Result<Self, ModelDescriptionError> {
        use xmlparser::{ElementEnd, Token, Tokenizer};

        let mut root_seen = false;
        let mut md = ModelDescription {
            fmi_version: String::new(),
            model_name: String::new(),
            guid: String::new(),
            co_simulation: None,
            has_model_exchange: false,
            default_experiment: None,
            variables: Vec::new(),
            outputs: Vec::new(),
        };
        // SimpleType name -> unit
        let mut type_units: HashMap<String, Option<String>> = HashMap::new();
        let mut current_type: Option<String> = None;
        let mut pending: Vec<PendingVar> = Vec::new();
        let mut output_lines: Vec<usize> = Vec::new();
        let mut stack: Vec<&str> = Vec::new();
        let mut current: Option<Elem> = None;

        for tok in Tokenizer::from(xml) {
            let tok = tok.map_err(|e| ModelDescriptionError::Xml(e.to_string()))?;
            match tok {
                Token::ElementStart { local, span, .. } => {
                    current = Some(Elem {
                        name: local.as_str(),
                        line: line_of(xml, span.start()),
                        attrs: Vec::new(),
                    });
                }
                Token::Attribute { local, value, .. } => {
                    if let Some(e) = current.as_mut() {
                        e.attrs.push((local.as_str(), unescape(value.as_str())));
                    }
                }
                Token::ElementEnd { end, .. } => match end {
                    ElementEnd::Open | ElementEnd::Empty => {
                        let Some(e) = current.take() else { continue };
                        let parent = stack.last().copied().unwrap_or("");
                        match (parent, e.name) {
                            ("", "fmiModelDescription") => {
                                root_seen = true;
                                md.fmi_version = e.req("fmiVersion")?.to_string();
                                md.model_name = e.req("modelName")?.to_string();
                                md.guid = e.req("guid")?.to_string();
                            }
                            ("fmiModelDescription", "CoSimulation") => {
                                md.co_simulation = Some(CoSimulationCaps {
                                    model_identifier: e.req("modelIdentifier")?.to_string(),
                                    can_get_and_set_fmu_state: e.bool("canGetAndSetFMUstate")?,
                                    can_serialize_fmu_state: e.bool("canSerializeFMUstate")?,
                                    can_handle_variable_communication_step_size: e
                                        .bool("canHandleVariableCommunicationStepSize")?,
                                    can_be_instantiated_only_once_per_process: e
                                        .bool("canBeInstantiatedOnlyOncePerProcess")?,
                                });
                            }
                            ("fmiModelDescription", "ModelExchange") => {
                                md.has_model_exchange = true
                            }
                            ("fmiModelDescription", "DefaultExperiment") => {
                                md.default_experiment = Some(DefaultExperiment {
                                    start_time: e.f64("startTime")?,
                                    stop_time: e.f64("stopTime")?,
                                    step_size: e.f64("stepSize")?,
                                });
                            }
                            ("TypeDefinitions", "SimpleType") => {
                                let n = e.req("name")?.to_string();
                                type_units.insert(n.clone(), None);
                                current_type = Some(n);
                            }
                            ("SimpleType", "Real") => {
                                if let Some(t) = &current_type {
                                    type_units.insert(t.clone(), e.get("unit").map(String::from));
                                }
                            }
                            ("ModelVariables", "ScalarVariable") => {
                                let vr_s = e.req("valueReference")?;
                                let vr = vr_s.trim().parse::<u32>().map_err(|_| {
                                    e.invalid(
                                        "valueReference",
                                        vr_s,
                                        "expected an unsigned integer",
                                    )
                                })?;
                                let causality = match e.get("causality") {
                                    None => None,
                                    Some(c) => Some(Causality::parse(c).ok_or_else(|| {
                                        e.invalid("causality", c, "unknown causality")
                                    })?),
                                };
                                let variability = match e.get("variability") {
                                    None => None,
                                    Some(c) => Some(Variability::parse(c).ok_or_else(|| {
                                        e.invalid("variability", c, "unknown variability")
                                    })?),
                                };
                                pending.push(PendingVar {
                                    name: e.req("name")?.to_string(),
                                    vr,
                                    causality,
                                    variability,
                                    initial: e.get("initial").map(String::from),
                                    description: e.get("description").map(String::from),
                                    line: e.line,
                                    ..Default::default()
                                });
                            }
                            ("ScalarVariable", ty) => {
                                let var_type = match ty {
                                    "Real" => Some(VarType::Real),
                                    "Integer" => Some(VarType::Integer),
                                    "Boolean" => Some(VarType::Boolean),
                                    "String" => Some(VarType::String),
                                    "Enumeration" => Some(VarType::Enumeration),
                                    _ => None,
                                };
                                if let (Some(t), Some(v)) = (var_type, pending.last_mut()) {
                                    v.var_type = Some(t);
                                    v.unit = e.get("unit").map(String::from);
                                    v.declared_type = e.get("declaredType").map(String::from);
                                    v.start = e.get("start").map(String::from);
                                }
                            }
                            ("Outputs", "Unknown") => {
                                let idx_s = e.req("index")?;
                                let index = idx_s
                                    .trim()
                                    .parse::<usize>()
                                    .ok()
                                    .filter(|&i| i >= 1)
                                    .ok_or_else(|| {
                                        e.invalid("index", idx_s, "expected an integer >= 1")
                                    })?;
                                let depends_on = match e.get("dependencies") {
                                    None => None,
                                    Some(d) => {
                                        let mut v = Vec::new();
                                        for part in d.split_whitespace() {
                                            let i = part
                                                .parse::<usize>()
                                                .ok()
                                                .filter(|&i| i >= 1)
                                                .ok_or_else(|| {
                                                    e.invalid(
                                                        "dependencies",
                                                        d,
                                                        "expected integers >= 1",
                                                    )
                                                })?;
                                            v.push(i - 1);
                                        }
                                        Some(v)
                                    }
                                };
                                md.outputs.push(OutputDependency {
                                    output: index - 1,
                                    depends_on,
                                });
                                output_lines.push(e.line);
                            }
                            _ => {}
                        }
                        if end == ElementEnd::Open {
                            stack.push(e.name);
                        } else if e.name == "SimpleType" {
                            current_type = None;
                        }
                    }
                    ElementEnd::Close(_, local) => {
                        stack.pop();
                        if local.as_str() == "SimpleType" {
                            current_type = None;
                        }
                    }
                },
                _ => {}
            }
        }
        if let Some(open) = current.as_ref().map(|e| e.name).or(stack.last().copied()) {
            return Err(ModelDescriptionError::Xml(format!(
                "unexpected end of file inside <{open}>"
            )));
        }
        if !root_seen {
            return Err(ModelDescriptionError::NoRoot);
        }
        let mut seen = std::collections::HashSet::new();
        for p in pending {
            let var_type = p.var_type.ok_or_else(|| ModelDescriptionError::NoType {
                name: p.name.clone(),
                line: p.line,
            })?;
            let unit = match (&p.unit, &p.declared_type) {
                (Some(u), _) => Some(u.clone()),
                (None, Some(d)) => type_units
                    .get(d)
                    .ok_or_else(|| ModelDescriptionError::UnknownDeclaredType {
                        name: p.name.clone(),
                        declared: d.clone(),
                    })?
                    .clone(),
                (None, None) => None,
            };
            if !seen.insert(p.name.clone()) {
                return Err(ModelDescriptionError::DuplicateName { name: p.name });
            }
            let causality = p.causality.unwrap_or(Causality::Local);
            // FMI 2.0 default variability is continuous (only Real may be continuous).
            let variability = p.variability.unwrap_or(if var_type == VarType::Real {
                Variability::Continuous
            } else {
                Variability::Discrete
            });
            md.variables.push(Variable {
                name: p.name,
                value_reference: p.vr,
                causality,
                variability,
                initial: p.initial,
                var_type,
                unit: unit.filter(|u| !u.is_empty()),
                start: p.start,
                description: p.description,
            });
        }
        let count = md.variables.len();
        for (o, line) in md.outputs.iter().zip(output_lines) {
            let bad = std::iter::once(o.output)
                .chain(o.depends_on.iter().flatten().copied())
                .find(|&i| i >= count);
            if let Some(i) = bad {
                return Err(ModelDescriptionError::IndexOutOfRange {
                    index: i + 1,
                    count,
                    line,
                });
            }
        }
        Ok(md)
    }

    /// Index and variable by exact name.
    pub fn variable(&self, name: &str) -> Option<(usize, &Variable)> {
        self.variables
            .iter()
            .enumerate()
            .find(|(_, v)| v.name == name)
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
    pub fn has_direct_feedthrough(&self, input: usize) -> bool {
        let listed = |i: usize| self.outputs.iter().any(|o| o.output == i);
        let unlisted_output = self
            .variables
            .iter()
            .enumerate()
            .any(|(i, v)| v.causality == Causality::Output && !listed(i));
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
pub(crate) mod tests {
    use super::*;

    /// A MassSpring-like description: params m, k, d; input force; outputs position, velocity
    /// (no direct feedthrough).
    pub const MASS_SPRING: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="MassSpring" guid="{abc}" canHandleMultipleSetPerTimeInstant="true">
  <CoSimulation modelIdentifier="MassSpring" canGetAndSetFMUstate="true"/>
  <UnitDefinitions><Unit name="m"><BaseUnit m="1"/></Unit></UnitDefinitions>
  <TypeDefinitions>
    <SimpleType name="Position"><Real quantity="Length" unit="m"/></SimpleType>
  </TypeDefinitions>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="1e-3"/>
  <ModelVariables>
    <ScalarVariable name="m" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/></ScalarVariable>
    <ScalarVariable name="k" valueReference="1" causality="parameter" variability="fixed"><Real start="100" unit="N/m"/></ScalarVariable>
    <ScalarVariable name="d" valueReference="2" causality="parameter" variability="fixed"><Real start="1" unit="N.s/m"/></ScalarVariable>
    <ScalarVariable name="force" valueReference="3" causality="input"><Real start="0" unit="N"/></ScalarVariable>
    <ScalarVariable name="position" valueReference="4" causality="output" initial="exact"><Real declaredType="Position" start="0.1"/></ScalarVariable>
    <ScalarVariable name="velocity" valueReference="5" causality="output" description="v &amp; co"><Real unit="m/s"/></ScalarVariable>
    <ScalarVariable name="n_steps" valueReference="0" causality="local"><Integer/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs>
      <Unknown index="5" dependencies=""/>
      <Unknown index="6" dependencies=""/>
    </Outputs>
  </ModelStructure>
</fmiModelDescription>"#;

    #[test]
    fn parses_variables_units_and_structure() {
        let md = ModelDescription::parse(MASS_SPRING).unwrap();
        assert_eq!(md.fmi_version, "2.0");
        assert_eq!(md.guid, "{abc}");
        let cs = md.co_simulation.as_ref().unwrap();
        assert_eq!(cs.model_identifier, "MassSpring");
        assert!(cs.can_get_and_set_fmu_state);
        assert_eq!(md.variables.len(), 7);
        let (i, pos) = md.variable("position").unwrap();
        assert_eq!(i, 4);
        assert_eq!(pos.unit.as_deref(), Some("m")); // through declaredType
        assert_eq!(pos.causality, Causality::Output);
        assert_eq!(
            md.variable("velocity").unwrap().1.description.as_deref(),
            Some("v & co")
        );
        assert_eq!(md.variable("n_steps").unwrap().1.var_type, VarType::Integer);
        assert_eq!(
            md.variable("n_steps").unwrap().1.variability,
            Variability::Discrete
        );
        assert_eq!(md.outputs[0].depends_on, Some(vec![]));
        assert!(!md.has_direct_feedthrough(3));
        assert_eq!(
            md.default_experiment.as_ref().unwrap().step_size,
            Some(1e-3)
        );
        assert!(md.variable("m").unwrap().1.is_settable());
        assert!(!md.variable("velocity").unwrap().1.is_settable());
        assert!(md.variable("position").unwrap().1.is_settable()); // initial="exact"
    }

    #[test]
    fn feedthrough_from_dependencies() {
        let xml = MASS_SPRING.replace(
            r#"<Unknown index="6" dependencies=""/>"#,
            r#"<Unknown index="6" dependencies="4"/>"#,
        );
        let md = ModelDescription::parse(&xml).unwrap();
        assert!(md.has_direct_feedthrough(3));
        // absent attribute: depends on everything
        let xml = MASS_SPRING.replace(
            r#"<Unknown index="6" dependencies=""/>"#,
            r#"<Unknown index="6"/>"#,
        );
        assert!(ModelDescription::parse(&xml)
            .unwrap()
            .has_direct_feedthrough(3));
    }

    #[test]
    fn errors_name_line_and_attribute() {
        let xml = MASS_SPRING.replace(r#"name="k" valueReference="1""#, r#"name="k""#);
        let e = ModelDescription::parse(&xml).unwrap_err();
        assert_eq!(
            e,
            ModelDescriptionError::MissingAttribute {
                element: "ScalarVariable".into(),
                attribute: "valueReference".into(),
                line: 11
            }
        );
        let xml = MASS_SPRING.replace(r#"causality="input""#, r#"causality="inptu""#);
        let e = ModelDescription::parse(&xml).unwrap_err().to_string();
        assert!(e.contains("line 13") && e.contains("inptu"), "{e}");
        let e = ModelDescription::parse("<fmiModelDescription fmiVersion=\"2.0\"").unwrap_err();
        assert!(matches!(e, ModelDescriptionError::Xml(_)), "{e:?}");
        let e = ModelDescription::parse("not xml at all").unwrap_err();
        assert!(matches!(
            e,
            ModelDescriptionError::Xml(_) | ModelDescriptionError::NoRoot
        ));
        let xml = MASS_SPRING.replace(r#"<Unknown index="6""#, r#"<Unknown index="60""#);
        let e = ModelDescription::parse(&xml).unwrap_err();
        assert!(matches!(
            e,
            ModelDescriptionError::IndexOutOfRange {
                index: 60,
                count: 7,
                ..
            }
        ));
        let xml = MASS_SPRING.replace("declaredType=\"Position\"", "declaredType=\"Pos\"");
        assert!(matches!(
            ModelDescription::parse(&xml).unwrap_err(),
            ModelDescriptionError::UnknownDeclaredType { .. }
        ));
    }

    #[test]
    fn suggestions() {
        let md = ModelDescription::parse(MASS_SPRING).unwrap();
        assert_eq!(md.suggest("forse"), Some("force"));
        assert_eq!(md.suggest("positon"), Some("position"));
        assert_eq!(md.suggest("completely_different"), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
