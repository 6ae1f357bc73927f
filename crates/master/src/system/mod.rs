//! System description (JSON): FMU instances, parameters, connections, timing, coupling,
//! recording; validated against the FMUs' model descriptions into a [`CouplingPlan`](crate::coupling::CouplingPlan).
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

use crate::coupling::{Algorithm, RunOptions, SimError, SimOutput};
use crate::fmu::{FmuArchive, FmuError};
use crate::model_description::{ModelDescription, VarType, Variable};
use crate::show::text;
use crate::slave::ScalarType;

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
    /// Communication step \[s\].
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

/// Why [`SystemDescription::set_start_value`] cannot set a value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StartValueError {
    /// The key is not of the form `instance.variable`.
    NotAReference,
    /// No instance of that name.
    UnknownInstance,
}

impl SystemDescription {
    /// The SHA-1 ([`file_digest`](crate::input::file_digest)) of every FMU file, by its path
    /// as the description gives it; a file that cannot be read is left out (its run fails on its
    /// own).
    pub fn fmu_digests(&self) -> BTreeMap<String, String> {
        self.instances
            .iter()
            .filter_map(|i| {
                let digest = crate::input::file_digest(&i.fmu)?;
                Some((i.fmu.to_string_lossy().into_owned(), digest))
            })
            .collect()
    }

    /// Sets the start value of `key` (`instance.variable`) in the description (its
    /// parameters; the variable itself is checked when the system is loaded).
    pub fn set_start_value(&mut self, key: &str, value: Value) -> Result<(), StartValueError> {
        let (inst, var) = split_ref(key).ok_or(StartValueError::NotAReference)?;
        let spec = self
            .instances
            .iter_mut()
            .find(|i| i.name == inst)
            .ok_or(StartValueError::UnknownInstance)?;
        spec.parameters.insert(var.to_string(), value);
        Ok(())
    }
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceSpec {
    pub name: String,
    pub fmu: PathBuf,
    /// Start values by variable name: numbers for Real/Integer, true/false for Boolean, text
    /// for String, an item name (or its integer) for Enumeration.
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
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
    /// Between variables of different units (each defined by a BaseUnit in its FMU's
    /// UnitDefinitions), the value is converted to the target's unit; `false` passes it
    /// unchanged whatever the units (SSP's `suppressUnitConversion="true"`).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub convert_units: bool,
}

fn yes() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
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

impl SystemError {
    /// A JSON syntax or schema error of `file`, with its line and column.
    pub fn json(file: &str, e: &serde_json::Error) -> Self {
        SystemError::Json {
            file: file.to_string(),
            line: e.line(),
            column: e.column(),
            message: e
                .to_string()
                .split(" at line ")
                .next()
                .unwrap_or("")
                .to_string(),
        }
    }
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
    /// For a description converted from another format (an SSP): where a field (a key as
    /// messages name it, `instances[0].parameters.k`, `connections[2]`) comes from in that
    /// format's own files, e.g. "parameter 'k' of set 'bogie' (resources/bogie.ssv line 10)";
    /// a message about the field, or about a part of it, names that instead.
    pub origins: BTreeMap<String, String>,
}

/// The field a start value of instance `instance` is named by in messages
/// (`instances[0].parameters.k`, a long or odd name shortened): also the key of its origin
/// in a converted description ([`LoadedSystem::origins`]).
pub(crate) fn parameter_field(instance: usize, name: &str) -> String {
    format!("instances[{instance}].parameters.{}", text(name))
}

/// Splits `instance.variable` at the first dot.
pub fn split_ref(s: &str) -> Option<(&str, &str)> {
    let (a, b) = s.split_once('.')?;
    (!a.is_empty() && !b.is_empty()).then_some((a, b))
}

pub(crate) fn type_of(t: VarType) -> ScalarType {
    match t {
        VarType::Real => ScalarType::Real,
        VarType::Integer => ScalarType::Integer,
        VarType::Enumeration => ScalarType::Enumeration,
        VarType::Boolean => ScalarType::Boolean,
        VarType::String => ScalarType::String,
    }
}

/// Converts a JSON start value to variable `var` of model `md`; `Err` is the reason. Reals
/// and Integers take numbers, Booleans true/false (or 0/1), Strings text (its value is its
/// index in `strings`, where it is added), Enumerations an item name or its integer value.
pub fn json_value_for(
    md: &ModelDescription,
    var: &Variable,
    v: &Value,
    strings: &mut Vec<String>,
) -> Result<f64, String> {
    let t = var.var_type;
    let items = md.enum_items(var);
    let item_names = || {
        items
            .iter()
            .map(|i| format!("'{}' ({})", i.name, i.value))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match (t, v) {
        (VarType::Real, Value::Number(n)) => n
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{n} is not a finite number")),
        (VarType::Integer | VarType::Enumeration, Value::Number(n)) => {
            let x = n
                .as_i64()
                .filter(|x| i32::try_from(*x).is_ok())
                .ok_or_else(|| format!("{n} is not a 32-bit integer (variable is {t})"))?;
            if t == VarType::Enumeration
                && !items.is_empty()
                && !items.iter().any(|i| i64::from(i.value) == x)
            {
                return Err(format!(
                    "{x} is no item of this enumeration; items: {}",
                    item_names()
                ));
            }
            Ok(x as f64)
        }
        (VarType::Enumeration, Value::String(name)) => items
            .iter()
            .find(|i| &i.name == name)
            .map(|i| f64::from(i.value))
            .ok_or_else(|| {
                format!(
                    "'{}' is no item of this enumeration; items: {}",
                    text(name),
                    item_names()
                )
            }),
        (VarType::Boolean, Value::Bool(b)) => Ok(if *b { 1.0 } else { 0.0 }),
        (VarType::Boolean, Value::Number(n)) if n.as_u64().is_some_and(|x| x <= 1) => {
            Ok(n.as_u64().unwrap_or(0) as f64)
        }
        (VarType::String, Value::String(text)) => {
            if text.contains('\0') {
                return Err("a String may not contain a NUL character".into());
            }
            let k = match strings.iter().position(|s| s == text) {
                Some(k) => k,
                None => {
                    strings.push(text.clone());
                    strings.len() - 1
                }
            };
            Ok(k as f64)
        }
        (t, Value::String(s)) => Err(format!(
            "a {t} variable cannot take the value {:?}",
            text(s)
        )),
        (t, v) => Err(format!(
            "a {t} variable cannot take the value {}",
            text(&v.to_string())
        )),
    }
}

impl LoadedSystem {
    /// Reads and parses a JSON file; FMU paths are relative to its folder.
    pub fn load(path: &Path) -> Result<Self, SystemError> {
        let text = crate::input::read_text_file(path, crate::input::MAX_TEXT_FILE_BYTES).map_err(
            |source| SystemError::Read {
                path: path.to_path_buf(),
                source,
            },
        )?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_json_str(&text, &base, &path.display().to_string())
    }

    /// Parses JSON text. `file` names it in messages.
    pub fn from_json_str(text: &str, base_dir: &Path, file: &str) -> Result<Self, SystemError> {
        let desc: SystemDescription =
            serde_json::from_str(text).map_err(|e| SystemError::json(file, &e))?;
        Ok(LoadedSystem {
            desc,
            file: file.to_string(),
            base_dir: base_dir.to_path_buf(),
            text: Some(text.to_string()),
            origins: BTreeMap::new(),
        })
    }

    /// Wraps an in-memory description (e.g. one run of a sweep).
    pub fn from_description(desc: SystemDescription, base_dir: &Path, file: &str) -> Self {
        LoadedSystem {
            desc,
            file: file.to_string(),
            base_dir: base_dir.to_path_buf(),
            text: None,
            origins: BTreeMap::new(),
        }
    }

    /// Where `field` comes from in the files of a converted description ([`Self::origins`]):
    /// its own entry, else that of the nearest field holding it, followed by the rest of the
    /// name (a connection's `from` and `to` are in its entry already).
    fn origin_of(&self, field: &str) -> Option<String> {
        if let Some(o) = self.origins.get(field) {
            return Some(o.clone());
        }
        let mut head = field;
        while let Some(cut) = head.rfind(['.', '[']) {
            head = &head[..cut];
            if let Some(o) = self.origins.get(head) {
                let rest = field[cut..].trim_start_matches('.');
                return Some(match rest {
                    "from" | "to" => o.clone(),
                    _ => format!("{o}: {rest}"),
                });
            }
        }
        None
    }

    /// Line of the value at `field` (`instances[3].name`) in the JSON text, else of the first
    /// occurrence of `"needle"` (a field the text does not hold as named).
    fn line_of(&self, field: &str, needle: &str) -> Option<usize> {
        let text = self.text.as_ref()?;
        let pos =
            locate::value_offset(text, field).or_else(|| text.find(&format!("\"{needle}\"")))?;
        Some(text[..pos].matches('\n').count() + 1)
    }

    fn invalid(
        &self,
        field: impl Into<String>,
        needle: &str,
        reason: impl Into<String>,
    ) -> SystemError {
        let field = field.into();
        if let Some(origin) = self.origin_of(&field) {
            return SystemError::Invalid {
                file: self.file.clone(),
                line: None,
                field: origin,
                reason: reason.into(),
            };
        }
        SystemError::Invalid {
            file: self.file.clone(),
            line: self.line_of(&field, needle),
            field,
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

    /// Of the parameter names `keys` (`instance.variable`), those that are Integers or
    /// Enumerations in their FMUs' model descriptions `models` (one per instance; the others,
    /// and names that are not the system's, are left out): the columns a run set's tables
    /// hold as integers.
    pub fn integer_parameters<'a>(
        &self,
        models: &[&ModelDescription],
        keys: impl IntoIterator<Item = &'a String>,
    ) -> std::collections::BTreeSet<String> {
        keys.into_iter()
            .filter(|key| {
                split_ref(key).is_some_and(|(inst, var)| {
                    self.instance_index(inst)
                        .and_then(|i| models[i].variable(var))
                        .is_some_and(|(_, v)| {
                            matches!(v.var_type, VarType::Integer | VarType::Enumeration)
                        })
                })
            })
            .cloned()
            .collect()
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
                format!("'{}' is not of the form 'instance.variable'", text(s)),
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
            return Err(self.invalid(field, s, format!("unknown instance '{}'{hint}", text(inst))));
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
                        "unknown variable '{}' in instance '{inst}' (model '{}'){hint}",
                        text(s),
                        md.model_name
                    ),
                ))
            }
        }
    }

    /// Opens the FMUs, validates, instantiates one instance per entry, simulates, and frees
    /// everything (also on error). For many runs of one system, prepare it once
    /// ([`PreparedSystem`]).
    pub fn run(&self, opts: &RunOptions) -> Result<SimOutput, RunError> {
        PreparedSystem::prepare(self)?.run(&RunChanges::default(), opts)
    }

    /// [`Self::run`], keeping the history of a run that fails (see
    /// [`FailedRun`](crate::coupling::FailedRun)).
    pub fn run_keeping_history(
        &self,
        opts: &RunOptions,
    ) -> Result<SimOutput, crate::coupling::FailedRun<RunError>> {
        PreparedSystem::prepare(self)?.run_keeping_history(&RunChanges::default(), opts)
    }
}

mod locate;
mod overrides;
mod plan;
mod prepared;
mod single;

pub use overrides::{OverridesFrom, SystemOverrides};
pub use prepared::{PreparedSystem, RunChanges};
pub use single::{
    default_timing, instance_name, parse_set, parse_set_value, round_step, SingleFmuOptions,
};

#[cfg(test)]
mod tests;
