//! System description (JSON): FMU instances, parameters, connections, timing, coupling,
//! recording; validated against the FMUs' model descriptions into a [`CouplingPlan`].
//!
//! ```json
//! {
//!   "instances": [
//!     {"name": "ms",  "fmu": "dist/MassSpring.fmu", "parameters": {"m": 1.0, "k": 100.0}},
//!     {"name": "sdm", "fmu": "dist/SpringDamperMass.fmu", "step_multiple": 1}
//!   ],
//!   "connections": [
//!     {"from": "ms.position", "to": "sdm.input_position"},
//!     {"from": "sdm.coupling_force", "to": "ms.force"}
//!   ],
//!   "start_time": 0.0, "stop_time": 1.0, "step": 0.001,
//!   "algorithm": "gauss-seidel",          // or "jacobi"; default gauss-seidel
//!   "order": ["ms", "sdm"],               // optional; default derived from feedthrough
//!   "record": ["ms.position"],            // optional; default all outputs + connected inputs
//!   "init_sweeps": 3, "max_step_halvings": 0
//! }
//! ```
//! FMU paths are relative to the JSON file's folder. Variables are `instance.variable`, split at
//! the first dot (instance names may not contain dots; variable names may).
//!
//! Interpretations: a unit mismatch is an error only when both variables declare a unit
//! (an FMU that declares none is taken as "unknown", not "dimensionless"). The Gauss-Seidel
//! order is a topological order of the graph with an edge A -> B for each connection A.y -> B.u
//! where u feeds directly through to an output of B (ModelStructure/Outputs): such a B must see
//! A's new outputs. Cycles (algebraic loops) are broken in declaration order with a warning.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::coupling::{
    simulate, topological_order, Algorithm, CouplingPlan, PlanConnection, PlanInstance, Recorded,
    RunOptions, SimError, SimOutput,
};
use crate::fmu::{FmuArchive, FmuError, FmuSlave};
use crate::model_description::{Causality, ModelDescription, VarType};
use crate::slave::{ScalarType, Slave, VarRef};

fn default_alg() -> Algorithm {
    Algorithm::GaussSeidel
}
fn default_sweeps() -> usize {
    3
}
fn one() -> u32 {
    1
}

/// The JSON system description.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SystemDescription {
    pub instances: Vec<InstanceSpec>,
    #[serde(default)]
    pub connections: Vec<ConnectionSpec>,
    #[serde(default)]
    pub start_time: f64,
    pub stop_time: f64,
    /// Communication step [s].
    pub step: f64,
    #[serde(default = "default_alg")]
    pub algorithm: Algorithm,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<Vec<String>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record: Option<Vec<String>>,
    #[serde(default = "default_sweeps")]
    pub init_sweeps: usize,
    #[serde(default)]
    pub max_step_halvings: u32,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceSpec {
    pub name: String,
    pub fmu: PathBuf,
    /// Start values by variable name (numbers for Real/Integer, true/false for Boolean).
    #[serde(default)]
    pub parameters: BTreeMap<String, Value>,
    /// This instance steps every `step_multiple` communication steps.
    #[serde(default = "one")]
    pub step_multiple: u32,
    /// Passed to fmi2Instantiate as loggingOn.
    #[serde(default)]
    pub logging: bool,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConnectionSpec {
    pub from: String,
    pub to: String,
}

/// A problem with a system description; always names the file and field.
#[derive(Debug, thiserror::Error)]
pub enum SystemError {
    #[error("cannot read '{path}': {source}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: line {line}, column {column}: {message}")]
    Json {
        file: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{file}{}: {field}: {reason}", .line.map(|l| format!(" line {l}")).unwrap_or_default())]
    Invalid {
        file: String,
        line: Option<usize>,
        field: String,
        reason: String,
    },
    #[error("{file}: {field}: {source}")]
    Fmu {
        file: String,
        field: String,
        #[source]
        source: Box<FmuError>,
    },
}

/// Anything that stops `master run`.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    System(#[from] SystemError),
    #[error(transparent)]
    Fmu(#[from] FmuError),
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// A system description together with where it came from (for paths and error lines).
#[derive(Debug, Clone)]
pub struct LoadedSystem {
    pub desc: SystemDescription,
    /// Name used in messages (the file path, or a label).
    pub file: String,
    /// Folder FMU paths are relative to.
    pub base_dir: PathBuf,
    /// JSON text, if any, for line numbers in messages.
    pub text: Option<String>,
}

/// Splits `instance.variable` at the first dot.
pub fn split_ref(s: &str) -> Option<(&str, &str)> {
    let (a, b) = s.split_once('.')?;
    (!a.is_empty() && !b.is_empty()).then_some((a, b))
}

fn type_of(t: VarType) -> Option<ScalarType> {
    match t {
        VarType::Real => Some(ScalarType::Real),
        // An Enumeration's value is an Integer (FMI 2.0: fmi2SetInteger / fmi2GetInteger).
        VarType::Integer | VarType::Enumeration => Some(ScalarType::Integer),
        VarType::Boolean => Some(ScalarType::Boolean),
        VarType::String => None,
    }
}

/// Converts a JSON start value to the variable's type; `Err` is the reason.
pub fn json_value_for(t: VarType, v: &Value) -> Result<f64, String> {
    match (t, v) {
        (VarType::Real, Value::Number(n)) => n
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{n} is not a finite number")),
        (VarType::Integer | VarType::Enumeration, Value::Number(n)) => n
            .as_i64()
            .filter(|x| i32::try_from(*x).is_ok())
            .map(|x| x as f64)
            .ok_or_else(|| format!("{n} is not a 32-bit integer (variable is {t})")),
        (VarType::Boolean, Value::Bool(b)) => Ok(if *b { 1.0 } else { 0.0 }),
        (t, v) => Err(format!("a {t} variable cannot take the value {v}")),
    }
}

impl LoadedSystem {
    /// Reads and parses a JSON file; FMU paths are relative to its folder.
    pub fn load(path: &Path) -> Result<Self, SystemError> {
        let text = std::fs::read_to_string(path).map_err(|source| SystemError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_json_str(&text, &base, &path.display().to_string())
    }

    /// Parses JSON text. `file` names it in messages.
    pub fn from_json_str(text: &str, base_dir: &Path, file: &str) -> Result<Self, SystemError> {
        let desc: SystemDescription =
            serde_json::from_str(text).map_err(|e| SystemError::Json {
                file: file.to_string(),
                line: e.line(),
                column: e.column(),
                message: e
                    .to_string()
                    .split(" at line ")
                    .next()
                    .unwrap_or("")
                    .to_string(),
            })?;
        Ok(LoadedSystem {
            desc,
            file: file.to_string(),
            base_dir: base_dir.to_path_buf(),
            text: Some(text.to_string()),
        })
    }

    /// Wraps an in-memory description (e.g. one run of a sweep).
    pub fn from_description(desc: SystemDescription, base_dir: &Path, file: &str) -> Self {
        LoadedSystem {
            desc,
            file: file.to_string(),
            base_dir: base_dir.to_path_buf(),
            text: None,
        }
    }

    /// Line of the first occurrence of `"needle"` in the JSON text.
    fn line_of(&self, needle: &str) -> Option<usize> {
        let text = self.text.as_ref()?;
        let quoted = format!("\"{needle}\"");
        let pos = text.find(&quoted)?;
        Some(text[..pos].matches('\n').count() + 1)
    }

    fn invalid(
        &self,
        field: impl Into<String>,
        needle: &str,
        reason: impl Into<String>,
    ) -> SystemError {
        SystemError::Invalid {
            file: self.file.clone(),
            line: self.line_of(needle),
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Absolute (or base-relative) path of instance `i`'s FMU.
    pub fn fmu_path(&self, i: usize) -> PathBuf {
        let p = &self.desc.instances[i].fmu;
        if p.is_absolute() {
            p.clone()
        } else {
            self.base_dir.join(p)
        }
    }

    /// The description with FMU paths made absolute (self-contained, e.g. for sweep jobs).
    pub fn resolved(&self) -> SystemDescription {
        let mut d = self.desc.clone();
        for (i, inst) in d.instances.iter_mut().enumerate() {
            let p = self.fmu_path(i);
            inst.fmu = std::path::absolute(&p).unwrap_or(p);
        }
        d
    }

    /// Opens and checks every instance's FMU (no binary is loaded).
    pub fn open_fmus(&self) -> Result<Vec<FmuArchive>, SystemError> {
        let mut cache: HashMap<PathBuf, FmuArchive> = HashMap::new();
        let mut out = Vec::new();
        for i in 0..self.desc.instances.len() {
            let p = self.fmu_path(i);
            let a = match cache.get(&p) {
                Some(a) => a.clone(),
                None => {
                    let a = FmuArchive::open(&p).map_err(|source| SystemError::Fmu {
                        file: self.file.clone(),
                        field: format!("instances[{i}].fmu"),
                        source: Box::new(source),
                    })?;
                    cache.insert(p, a.clone());
                    a
                }
            };
            out.push(a);
        }
        Ok(out)
    }

    fn instance_index(&self, name: &str) -> Option<usize> {
        self.desc.instances.iter().position(|i| i.name == name)
    }

    /// Resolves `instance.variable` (for messages: `field`).
    fn resolve<'m>(
        &self,
        field: &str,
        s: &str,
        models: &[&'m ModelDescription],
    ) -> Result<(usize, usize, &'m crate::model_description::Variable), SystemError> {
        let Some((inst, var)) = split_ref(s) else {
            return Err(self.invalid(
                field,
                s,
                format!("'{s}' is not of the form 'instance.variable'"),
            ));
        };
        let Some(i) = self.instance_index(inst) else {
            let names: Vec<&str> = self
                .desc
                .instances
                .iter()
                .map(|i| i.name.as_str())
                .collect();
            let hint = names
                .iter()
                .filter(|n| crate::model_description::edit_distance(n, inst) <= 2)
                .map(|n| format!(" (did you mean '{n}'?)"))
                .next()
                .unwrap_or_else(|| format!(" (instances: {})", names.join(", ")));
            return Err(self.invalid(field, s, format!("unknown instance '{inst}'{hint}")));
        };
        let md = models[i];
        match md.variable(var) {
            Some((vi, v)) => Ok((i, vi, v)),
            None => {
                let hint = md
                    .suggest(var)
                    .map(|n| format!(" (did you mean '{inst}.{n}'?)"))
                    .unwrap_or_default();
                Err(self.invalid(
                    field,
                    s,
                    format!(
                        "unknown variable '{s}' in instance '{inst}' (model '{}'){hint}",
                        md.model_name
                    ),
                ))
            }
        }
    }

    /// Validates against the model descriptions (one per instance, same order) and builds the
    /// coupling plan. No FMU binary is needed.
    pub fn plan(&self, models: &[&ModelDescription]) -> Result<CouplingPlan, SystemError> {
        let d = &self.desc;
        if d.instances.is_empty() {
            return Err(self.invalid("instances", "instances", "at least one instance is needed"));
        }
        if models.len() != d.instances.len() {
            return Err(self.invalid(
                "instances",
                "instances",
                "internal: one model description per instance expected",
            ));
        }
        if !(d.step.is_finite() && d.step > 0.0) {
            return Err(self.invalid(
                "step",
                "step",
                format!("must be a positive number, got {}", d.step),
            ));
        }
        if !(d.start_time.is_finite() && d.stop_time.is_finite() && d.stop_time > d.start_time) {
            return Err(self.invalid(
                "stop_time",
                "stop_time",
                format!(
                    "must be greater than start_time ({}), got {}",
                    d.start_time, d.stop_time
                ),
            ));
        }
        let span = d.stop_time - d.start_time;
        let n = (span / d.step).round();
        if (n * d.step - span).abs() > 1e-9 * span.max(d.step) {
            return Err(self.invalid(
                "step",
                "step",
                format!(
                    "stop_time - start_time = {span} s is not an integer multiple of step = {} s",
                    d.step
                ),
            ));
        }
        let mut instances = Vec::new();
        for (i, inst) in d.instances.iter().enumerate() {
            let f = format!("instances[{i}].name");
            if inst.name.is_empty() || inst.name.contains('.') || inst.name.contains('\0') {
                return Err(self.invalid(
                    f,
                    &inst.name,
                    format!(
                        "'{}' is not a valid instance name (non-empty, no '.')",
                        inst.name
                    ),
                ));
            }
            if d.instances[..i].iter().any(|o| o.name == inst.name) {
                return Err(self.invalid(
                    f,
                    &inst.name,
                    format!("instance name '{}' is used twice", inst.name),
                ));
            }
            if inst.step_multiple == 0 {
                return Err(self.invalid(
                    format!("instances[{i}].step_multiple"),
                    "step_multiple",
                    "must be >= 1",
                ));
            }
            let md = models[i];
            let mut params = Vec::new();
            let mut parameter_names = Vec::new();
            for (name, value) in &inst.parameters {
                let field = format!("instances[{i}].parameters.{name}");
                let Some((_, v)) = md.variable(name) else {
                    let hint = md
                        .suggest(name)
                        .map(|n| format!(" (did you mean '{n}'?)"))
                        .unwrap_or_default();
                    return Err(self.invalid(
                        field,
                        name,
                        format!(
                            "unknown variable '{name}' in model '{}'{hint}",
                            md.model_name
                        ),
                    ));
                };
                if !v.is_settable() {
                    return Err(self.invalid(
                        field,
                        name,
                        format!("'{name}' has causality '{}' and variability '{}' and cannot be given a start value", v.causality, v.variability),
                    ));
                }
                let Some(ty) = type_of(v.var_type) else {
                    return Err(self.invalid(
                        field,
                        name,
                        format!("{} variables are not supported", v.var_type),
                    ));
                };
                let x = json_value_for(v.var_type, value)
                    .map_err(|r| self.invalid(field.clone(), name, r))?;
                params.push((
                    VarRef {
                        vr: v.value_reference,
                        ty,
                    },
                    x,
                ));
                parameter_names.push(name.clone());
            }
            instances.push(PlanInstance {
                name: inst.name.clone(),
                step_multiple: inst.step_multiple,
                parameters: params,
                parameter_names,
            });
        }

        let mut connections = Vec::new();
        let mut inputs_taken: HashMap<(usize, usize), usize> = HashMap::new();
        let mut feedthrough_edges = Vec::new();
        for (ci, c) in d.connections.iter().enumerate() {
            let ff = format!("connections[{ci}].from");
            let tf = format!("connections[{ci}].to");
            let (fi, fvi, fv) = self.resolve(&ff, &c.from, models)?;
            let (ti, tvi, tv) = self.resolve(&tf, &c.to, models)?;
            if fv.causality != Causality::Output {
                return Err(self.invalid(
                    ff,
                    &c.from,
                    format!(
                        "'{}' has causality '{}', only outputs can be connection sources",
                        c.from, fv.causality
                    ),
                ));
            }
            if tv.causality != Causality::Input {
                return Err(self.invalid(
                    tf,
                    &c.to,
                    format!(
                        "'{}' has causality '{}', only inputs can be connection targets",
                        c.to, tv.causality
                    ),
                ));
            }
            if fi == ti {
                return Err(self.invalid(tf, &c.to, "connects an instance to itself"));
            }
            if fv.var_type != tv.var_type {
                return Err(self.invalid(
                    format!("connections[{ci}]"),
                    &c.to,
                    format!(
                        "type mismatch: '{}' is {} but '{}' is {}",
                        c.from, fv.var_type, c.to, tv.var_type
                    ),
                ));
            }
            let Some(ty) = type_of(fv.var_type) else {
                return Err(self.invalid(
                    format!("connections[{ci}]"),
                    &c.from,
                    format!("{} connections are not supported", fv.var_type),
                ));
            };
            if let (Some(uf), Some(ut)) = (&fv.unit, &tv.unit) {
                if uf != ut {
                    return Err(self.invalid(
                        format!("connections[{ci}]"),
                        &c.to,
                        format!(
                            "unit mismatch: '{}' is in [{uf}] but '{}' is in [{ut}]",
                            c.from, c.to
                        ),
                    ));
                }
            }
            if let Some(prev) = inputs_taken.insert((ti, tvi), ci) {
                return Err(self.invalid(
                    tf,
                    &c.to,
                    format!("input '{}' is already driven by connections[{prev}]", c.to),
                ));
            }
            if models[ti].has_direct_feedthrough(tvi) {
                feedthrough_edges.push((fi, ti));
            }
            let _ = fvi;
            connections.push(PlanConnection {
                from_instance: fi,
                from: VarRef {
                    vr: fv.value_reference,
                    ty,
                },
                to_instance: ti,
                to: VarRef {
                    vr: tv.value_reference,
                    ty,
                },
                label: c.from.clone(),
            });
        }

        let order = match &d.order {
            Some(names) => {
                let mut order = Vec::new();
                for (k, n) in names.iter().enumerate() {
                    let Some(i) = self.instance_index(n) else {
                        return Err(self.invalid(
                            format!("order[{k}]"),
                            n,
                            format!("unknown instance '{n}'"),
                        ));
                    };
                    if order.contains(&i) {
                        return Err(self.invalid(
                            format!("order[{k}]"),
                            n,
                            format!("instance '{n}' appears twice"),
                        ));
                    }
                    order.push(i);
                }
                if order.len() != d.instances.len() {
                    let missing: Vec<&str> = (0..d.instances.len())
                        .filter(|i| !order.contains(i))
                        .map(|i| d.instances[i].name.as_str())
                        .collect();
                    return Err(self.invalid(
                        "order",
                        "order",
                        format!("must list every instance; missing: {}", missing.join(", ")),
                    ));
                }
                order
            }
            None => {
                let (order, broken) = topological_order(d.instances.len(), &feedthrough_edges);
                if !broken.is_empty() && d.algorithm == Algorithm::GaussSeidel {
                    let names: Vec<&str> = broken
                        .iter()
                        .map(|&i| d.instances[i].name.as_str())
                        .collect();
                    log::warn!(target: "master", "{}: algebraic loop through direct feedthrough; Gauss-Seidel order breaks it at {}", self.file, names.join(", "));
                }
                order
            }
        };

        let label = |i: usize, v: &crate::model_description::Variable| match &v.unit {
            Some(u) => format!("{}.{} [{u}]", d.instances[i].name, v.name),
            None => format!("{}.{}", d.instances[i].name, v.name),
        };
        let mut record = Vec::new();
        match &d.record {
            Some(list) => {
                for (k, s) in list.iter().enumerate() {
                    let (i, _, v) = self.resolve(&format!("record[{k}]"), s, models)?;
                    let Some(ty) = type_of(v.var_type) else {
                        return Err(self.invalid(
                            format!("record[{k}]"),
                            s,
                            format!("{} variables cannot be recorded", v.var_type),
                        ));
                    };
                    record.push(Recorded {
                        instance: i,
                        var: VarRef {
                            vr: v.value_reference,
                            ty,
                        },
                        label: label(i, v),
                    });
                }
            }
            None => {
                for (i, md) in models.iter().enumerate() {
                    for (vi, v) in md.variables.iter().enumerate() {
                        let connected_input =
                            v.causality == Causality::Input && inputs_taken.contains_key(&(i, vi));
                        if v.causality == Causality::Output || connected_input {
                            if let Some(ty) = type_of(v.var_type) {
                                record.push(Recorded {
                                    instance: i,
                                    var: VarRef {
                                        vr: v.value_reference,
                                        ty,
                                    },
                                    label: label(i, v),
                                });
                            }
                        }
                    }
                }
            }
        }

        Ok(CouplingPlan {
            start_time: d.start_time,
            stop_time: d.stop_time,
            step: d.step,
            instances,
            connections,
            algorithm: d.algorithm,
            order,
            record,
            init_sweeps: d.init_sweeps,
            max_step_halvings: d.max_step_halvings,
        })
    }

    /// Opens the FMUs, validates, instantiates one instance per entry, simulates, and frees
    /// everything (also on error).
    pub fn run(&self, opts: &RunOptions) -> Result<SimOutput, RunError> {
        let archives = self.open_fmus()?;
        let models: Vec<&ModelDescription> = archives.iter().map(|a| &a.model).collect();
        let plan = self.plan(&models)?;
        let mut slaves: Vec<FmuSlave> = Vec::new();
        for (a, inst) in archives.iter().zip(&self.desc.instances) {
            slaves.push(a.instantiate(&inst.name, inst.logging)?);
        }
        let mut refs: Vec<&mut dyn Slave> =
            slaves.iter_mut().map(|s| s as &mut dyn Slave).collect();
        let out = simulate(&plan, &mut refs, opts)?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model_description::tests::MASS_SPRING;

    /// SpringDamperMass as the example FMU will declare it.
    pub const SDM: &str = r#"<fmiModelDescription fmiVersion="2.0" modelName="SpringDamperMass" guid="g2">
  <CoSimulation modelIdentifier="SpringDamperMass" canGetAndSetFMUstate="true"/>
  <ModelVariables>
    <ScalarVariable name="m" valueReference="0" causality="parameter" variability="fixed"><Real start="1" unit="kg"/></ScalarVariable>
    <ScalarVariable name="k" valueReference="1" causality="parameter" variability="fixed"><Real start="1" unit="N/m"/></ScalarVariable>
    <ScalarVariable name="d" valueReference="2" causality="parameter" variability="fixed"><Real start="1" unit="N.s/m"/></ScalarVariable>
    <ScalarVariable name="input_position" valueReference="3" causality="input"><Real start="0" unit="m"/></ScalarVariable>
    <ScalarVariable name="input_velocity" valueReference="4" causality="input"><Real start="0" unit="m/s"/></ScalarVariable>
    <ScalarVariable name="coupling_force" valueReference="5" causality="output"><Real unit="N"/></ScalarVariable>
    <ScalarVariable name="position" valueReference="6" causality="output"><Real unit="m"/></ScalarVariable>
    <ScalarVariable name="velocity" valueReference="7" causality="output"><Real unit="m/s"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="8" causality="parameter" variability="fixed"><Integer start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs>
    <Unknown index="6" dependencies="4 5"/>
    <Unknown index="7" dependencies=""/>
    <Unknown index="8" dependencies=""/>
  </Outputs></ModelStructure>
</fmiModelDescription>"#;

    const SYS: &str = r#"{
  "instances": [
    {"name": "sdm", "fmu": "SpringDamperMass.fmu", "parameters": {"k": 200.0, "mode": 1}},
    {"name": "ms", "fmu": "MassSpring.fmu", "parameters": {"m": 1.0, "k": 100.0}}
  ],
  "connections": [
    {"from": "ms.position", "to": "sdm.input_position"},
    {"from": "ms.velocity", "to": "sdm.input_velocity"},
    {"from": "sdm.coupling_force", "to": "ms.force"}
  ],
  "stop_time": 1.0,
  "step": 0.001
}"#;

    fn models() -> (ModelDescription, ModelDescription) {
        (
            ModelDescription::parse(SDM).unwrap(),
            ModelDescription::parse(MASS_SPRING).unwrap(),
        )
    }

    fn plan_of(text: &str) -> Result<CouplingPlan, SystemError> {
        let (a, b) = models();
        let s = LoadedSystem::from_json_str(text, Path::new("/x"), "sys.json")?;
        s.plan(&[&a, &b])
    }

    fn err_of(text: &str) -> String {
        plan_of(text).unwrap_err().to_string()
    }

    #[test]
    fn valid_system_gives_feedthrough_order_and_default_record() {
        let p = plan_of(SYS).unwrap();
        // sdm's coupling_force feeds through from its inputs: ms must step first
        assert_eq!(p.order, vec![1, 0]);
        assert_eq!(p.algorithm, Algorithm::GaussSeidel);
        assert_eq!(p.connections.len(), 3);
        assert_eq!(
            p.instances[0].parameters,
            vec![
                (
                    VarRef {
                        vr: 1,
                        ty: ScalarType::Real
                    },
                    200.0
                ),
                (
                    VarRef {
                        vr: 8,
                        ty: ScalarType::Integer
                    },
                    1.0
                ),
            ]
        );
        let labels: Vec<&str> = p.record.iter().map(|r| r.label.as_str()).collect();
        assert_eq!(
            labels,
            vec![
                "sdm.input_position [m]",
                "sdm.input_velocity [m/s]",
                "sdm.coupling_force [N]",
                "sdm.position [m]",
                "sdm.velocity [m/s]",
                "ms.force [N]",
                "ms.position [m]",
                "ms.velocity [m/s]",
            ]
        );
    }

    #[test]
    fn explicit_order_and_record() {
        let t = SYS.replace("\"step\": 0.001", "\"step\": 0.001, \"order\": [\"sdm\", \"ms\"], \"record\": [\"ms.position\"], \"algorithm\": \"jacobi\"");
        let p = plan_of(&t).unwrap();
        assert_eq!(p.order, vec![0, 1]);
        assert_eq!(p.algorithm, Algorithm::Jacobi);
        assert_eq!(p.record.len(), 1);
        let t = SYS.replace("\"step\": 0.001", "\"step\": 0.001, \"order\": [\"sdm\"]");
        assert!(err_of(&t).contains("missing: ms"));
    }

    #[test]
    fn unknown_variable_names_field_line_and_suggestion() {
        let t = SYS.replace("\"sdm.coupling_force\"", "\"sdm.coupling_forse\"");
        let e = err_of(&t);
        assert_eq!(
            e,
            "sys.json line 9: connections[2].from: unknown variable 'sdm.coupling_forse' in instance 'sdm' (model 'SpringDamperMass') (did you mean 'sdm.coupling_force'?)"
        );
        let t = SYS.replace("\"to\": \"ms.force\"", "\"to\": \"mss.force\"");
        assert!(
            err_of(&t).contains("connections[2].to: unknown instance 'mss' (did you mean 'ms'?)")
        );
        let t = SYS.replace("\"k\": 100.0", "\"kk\": 100.0");
        let e = err_of(&t);
        assert!(
            e.contains("instances[1].parameters.kk: unknown variable 'kk'")
                && e.contains("did you mean 'k'"),
            "{e}"
        );
    }

    #[test]
    fn causality_type_and_unit_checks() {
        let t = SYS.replace("\"from\": \"ms.position\"", "\"from\": \"ms.force\"");
        assert!(err_of(&t).contains("connections[0].from: 'ms.force' has causality 'input'"));
        let t = SYS.replace("\"to\": \"ms.force\"", "\"to\": \"ms.velocity\"");
        assert!(err_of(&t).contains("only inputs can be connection targets"));
        // unit mismatch: position [m] -> input_velocity [m/s]
        let t = SYS.replace(
            "{\"from\": \"ms.velocity\", \"to\": \"sdm.input_velocity\"}",
            "{\"from\": \"ms.position\", \"to\": \"sdm.input_velocity\"}",
        );
        let e = err_of(&t);
        assert!(e.contains("connections[1]: unit mismatch: 'ms.position' is in [m] but 'sdm.input_velocity' is in [m/s]"), "{e}");
        // type mismatch needs an Integer output: make ms.velocity Integer
        let (a, _) = models();
        let ms_int = MASS_SPRING.replace("<Real unit=\"m/s\"/>", "<Integer/>");
        let b = ModelDescription::parse(&ms_int).unwrap();
        let s = LoadedSystem::from_json_str(SYS, Path::new("/x"), "sys.json").unwrap();
        let e = s.plan(&[&a, &b]).unwrap_err().to_string();
        assert!(
            e.contains("type mismatch: 'ms.velocity' is Integer but 'sdm.input_velocity' is Real"),
            "{e}"
        );
        // the same input twice
        let t = SYS.replace(
            "{\"from\": \"ms.velocity\", \"to\": \"sdm.input_velocity\"}",
            "{\"from\": \"ms.position\", \"to\": \"sdm.input_position\"}",
        );
        assert!(err_of(&t).contains(
            "connections[1].to: input 'sdm.input_position' is already driven by connections[0]"
        ));
    }

    #[test]
    fn parameter_value_checks() {
        let t = SYS.replace("\"mode\": 1", "\"mode\": 1.5");
        assert!(err_of(&t).contains("instances[0].parameters.mode: 1.5 is not a 32-bit integer"));
        let t = SYS.replace("\"mode\": 1", "\"mode\": true");
        assert!(err_of(&t).contains("Integer variable cannot take the value true"));
        let t = SYS.replace("\"k\": 200.0", "\"coupling_force\": 2.0");
        assert!(err_of(&t).contains("causality 'output'"));
    }

    #[test]
    fn malformed_json_and_timing() {
        let e = err_of("{\n  \"instances\": [\n  }");
        assert!(e.starts_with("sys.json: line 3, column 3:"), "{e}");
        let e = err_of(&SYS.replace("\"step\"", "\"stpe\""));
        assert!(e.contains("unknown field `stpe`"), "{e}");
        assert!(err_of(&SYS.replace("0.001", "-1")).contains("step: must be a positive number"));
        assert!(err_of(&SYS.replace("0.001", "0.3")).contains("not an integer multiple"));
        assert!(
            err_of(&SYS.replace("\"stop_time\": 1.0", "\"stop_time\": 0.0")).contains("stop_time")
        );
        let e = err_of(&SYS.replace("\"name\": \"ms\"", "\"name\": \"sdm\""));
        assert!(
            e.contains("instances[1].name: instance name 'sdm' is used twice"),
            "{e}"
        );
        let e = err_of(&SYS.replace("\"name\": \"ms\"", "\"name\": \"m.s\""));
        assert!(e.contains("not a valid instance name"), "{e}");
    }

    #[test]
    fn missing_fmu_names_the_field() {
        let s = LoadedSystem::from_json_str(SYS, Path::new("/nonexistent"), "sys.json").unwrap();
        let e = s.open_fmus().unwrap_err().to_string();
        assert!(
            e.contains("instances[0].fmu") && e.contains("/nonexistent/SpringDamperMass.fmu"),
            "{e}"
        );
        let r = s.resolved();
        assert_eq!(
            r.instances[1].fmu,
            PathBuf::from("/nonexistent/MassSpring.fmu")
        );
    }
}
