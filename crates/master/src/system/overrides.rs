//! Changes to a loaded system description given beside it (`master run --stop --set ...`,
//! Python's `System.load`): timing, coupling algorithm, start values, recorded variables and
//! FMU logging, so that a system runs at another speed or for longer without editing its file.

use serde_json::Value;

use super::{parameter_field, parse_set, split_ref, LoadedSystem, StartValueError, SystemError};
use crate::coupling::Algorithm;
use crate::show::text;

/// Who gives the changes: messages name them as that caller spells them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum OverridesFrom {
    /// `master run`: `--stop`, `--set`, ...
    #[default]
    CommandLine,
    /// Python's `System.load(step=..., stop_time=..., algorithm=...)`.
    PythonLoad,
}

/// What to change in a loaded system (`None` or empty: the description's own).
#[derive(Debug, Clone, Default)]
pub struct SystemOverrides {
    pub from: OverridesFrom,
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub step: Option<f64>,
    pub algorithm: Option<Algorithm>,
    /// `instance.variable=value` texts (values as `--set` takes them: JSON numbers,
    /// true/false, else text for a String or an Enumeration item).
    pub set: Vec<String>,
    /// Replaces the description's record list (`instance.variable` names).
    pub record: Vec<String>,
    /// Switches every instance's FMU logging on (loggingOn).
    pub logging: bool,
}

impl SystemOverrides {
    /// The changes given, named as their caller spells them (`--stop` or `stop_time`).
    pub fn given(&self) -> Vec<&'static str> {
        let python = self.from == OverridesFrom::PythonLoad;
        [
            ("--start", "start_time", self.start_time.is_some()),
            ("--stop", "stop_time", self.stop_time.is_some()),
            ("--step", "step", self.step.is_some()),
            ("--algorithm", "algorithm", self.algorithm.is_some()),
            ("--set", "parameters", !self.set.is_empty()),
            ("--record", "record", !self.record.is_empty()),
            ("--fmu-logging", "logging", self.logging),
        ]
        .into_iter()
        .filter(|(_, _, g)| *g)
        .map(|(cli, py, _)| if python { py } else { cli })
        .collect()
    }

    /// The start values of `--set` as (`instance.variable`, value); `Err`: a text without
    /// '='.
    fn start_values(&self) -> Result<Vec<(String, Value)>, &str> {
        self.set
            .iter()
            .map(|s| parse_set(s).ok_or(s.as_str()))
            .collect()
    }
}

impl LoadedSystem {
    /// Applies `o` to the description. Instances and the form of each `--set` are checked
    /// here; the values themselves when the system is prepared, as the file's are. A changed
    /// system is named "`<file> with --stop, ...`" in messages and without line numbers (they
    /// would point at the file's values, not the ones run); a field keeps its name in the
    /// description (`stop_time`).
    pub fn apply_overrides(&mut self, o: &SystemOverrides) -> Result<(), SystemError> {
        let given = o.given();
        if given.is_empty() {
            return Ok(());
        }
        let label = match o.from {
            OverridesFrom::CommandLine => format!("{} with {}", self.file, given.join(", ")),
            OverridesFrom::PythonLoad => {
                format!("{} with System.load's {}", self.file, given.join(", "))
            }
        };
        let invalid = |field: &str, reason: String| SystemError::Invalid {
            file: label.clone(),
            line: None,
            field: field.to_string(),
            reason,
        };
        for (field, value) in [
            ("start_time", o.start_time),
            ("stop_time", o.stop_time),
            ("step", o.step),
        ] {
            if let Some(x) = value.filter(|x| !x.is_finite()) {
                return Err(invalid(field, format!("must be a finite number, got {x}")));
            }
        }
        let mut desc = self.desc.clone();
        if let Some(t) = o.start_time {
            desc.start_time = t;
        }
        if let Some(t) = o.stop_time {
            desc.stop_time = t;
        }
        if let Some(h) = o.step {
            desc.step = h;
        }
        if let Some(a) = o.algorithm {
            desc.algorithm = a;
        }
        let start_values = o.start_values().map_err(|s| {
            let reason = "not of the form instance.variable=VALUE".to_string();
            invalid(&text(s).to_string(), reason)
        })?;
        // a field given here no longer comes from a converted description's files: named as
        // given (applied with the description, once every change is accepted)
        let python = o.from == OverridesFrom::PythonLoad;
        let given_as = |cli: &str, py: &str| if python { py } else { cli }.to_string();
        let mut origins = Vec::new();
        for (key, value) in start_values {
            if !self.origins.is_empty() {
                let at = split_ref(&key).and_then(|(inst, var)| {
                    let i = desc.instances.iter().position(|x| x.name == inst)?;
                    Some((i, var))
                });
                if let Some((i, var)) = at {
                    origins.push((
                        parameter_field(i, var),
                        given_as(&format!("--set {key}"), &format!("parameters '{key}'")),
                    ));
                }
            }
            desc.set_start_value(&key, value).map_err(|e| {
                let names: Vec<&str> = desc.instances.iter().map(|i| i.name.as_str()).collect();
                invalid(
                    &text(&key).to_string(),
                    match e {
                        StartValueError::NotAReference => {
                            "not of the form instance.variable".to_string()
                        }
                        StartValueError::UnknownInstance => {
                            format!("no such instance (instances: {})", names.join(", "))
                        }
                    },
                )
            })?;
        }
        if !o.record.is_empty() {
            desc.record = Some(o.record.clone());
        }
        if o.logging {
            desc.instances.iter_mut().for_each(|i| i.logging = true);
        }
        if !self.origins.is_empty() {
            for (field, cli, given) in [
                ("start_time", "--start", o.start_time.is_some()),
                ("stop_time", "--stop", o.stop_time.is_some()),
                ("step", "--step", o.step.is_some()),
            ] {
                if given {
                    origins.push((field.into(), given_as(cli, field)));
                }
            }
            self.origins.extend(origins);
        }
        self.desc = desc;
        self.file = label;
        self.text = None;
        Ok(())
    }
}
