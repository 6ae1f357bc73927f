//! One FMU run without a system file: `master run MODEL.fmu` is the one-instance system this
//! builds, over the FMU's DefaultExperiment unless told otherwise.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;

use super::{InstanceSpec, LoadedSystem, SystemDescription, SystemError};
use crate::coupling::Algorithm;
use crate::fmu::FmuArchive;
use crate::model_description::{Causality, ModelDescription};
use crate::show::text;

/// What a single-FMU run changes from the FMU's own defaults.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SingleFmuOptions {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub step: Option<f64>,
    /// `NAME=VALUE` start values (parameters and inputs of any type).
    pub set: Vec<String>,
    /// Variables to record (default: every output).
    pub record: Vec<String>,
    pub logging: bool,
}

/// The timing of a run of `md` alone: (start, stop, step) from its DefaultExperiment where it
/// gives them, else fmpy's defaults (start 0 s, stop 1 s after the start, a round step that
/// makes 500 to 1000 steps).
pub fn default_timing(md: &ModelDescription) -> (f64, f64, f64) {
    let d = md.default_experiment.clone().unwrap_or_default();
    let start = d.start_time.unwrap_or(0.0);
    let stop = d.stop_time.unwrap_or(start + 1.0);
    let step = d.step_size.unwrap_or_else(|| round_step(stop - start));
    (start, stop, step)
}

/// A round step dividing `span_s` into 500 to 1000 steps: a power of ten times 1, 2, 4 or 5
/// (fmpy's `auto_interval`, so both give the same points).
pub fn round_step(span_s: f64) -> f64 {
    if !(span_s.is_finite() && span_s > 0.0) {
        return 1e-3;
    }
    let h = 10f64.powf(span_s.log10().round() - 3.0);
    let n = span_s / h;
    if n >= 2500.0 {
        h * 5.0
    } else if n >= 2000.0 {
        h * 4.0
    } else if n >= 1000.0 {
        h * 2.0
    } else if n <= 200.0 {
        h / 5.0
    } else if n <= 250.0 {
        h / 4.0
    } else if n <= 500.0 {
        h / 2.0
    } else {
        h
    }
}

/// The instance name of an FMU run alone: its modelIdentifier (a C identifier, so a valid
/// instance name), else "model".
pub fn instance_name(md: &ModelDescription) -> String {
    md.co_simulation
        .as_ref()
        .map(|c| c.model_identifier.clone())
        .filter(|n| !n.is_empty() && !n.contains('.'))
        .unwrap_or_else(|| "model".into())
}

/// Parses the text of `--set NAME=VALUE` as JSON where it is JSON (numbers, true/false, quoted
/// text), else as text (a String, or an Enumeration item name).
pub fn parse_set_value(text: &str) -> Value {
    serde_json::from_str::<Value>(text)
        .ok()
        .filter(|v| v.is_number() || v.is_boolean() || v.is_string())
        .unwrap_or_else(|| Value::String(text.to_string()))
}

/// A `--set NAME=VALUE` text as (NAME, value of [`parse_set_value`]), both trimmed; None
/// without '='.
pub fn parse_set(text: &str) -> Option<(String, Value)> {
    let (name, value) = text.split_once('=')?;
    Some((name.trim().to_string(), parse_set_value(value.trim())))
}

impl LoadedSystem {
    /// The one-instance system that runs the FMU at `path` alone.
    pub fn single_fmu(path: &Path, opts: &SingleFmuOptions) -> Result<Self, SystemError> {
        let file = path.display().to_string();
        let archive = FmuArchive::open(path).map_err(|source| SystemError::Fmu {
            file: file.clone(),
            field: "fmu".into(),
            source: Box::new(source),
        })?;
        let md = &archive.model;
        let invalid = |field: &str, reason: String| SystemError::Invalid {
            file: file.clone(),
            line: None,
            field: field.to_string(),
            reason,
        };
        let (start, stop, step) = default_timing(md);
        let start_time = opts.start_time.unwrap_or(start);
        let stop_time = opts.stop_time.unwrap_or(stop);
        let step = opts.step.unwrap_or(step);
        let name = instance_name(md);
        let mut parameters = BTreeMap::new();
        for s in &opts.set {
            let Some((k, v)) = parse_set(s) else {
                return Err(invalid(
                    "--set",
                    format!("'{}' is not of the form NAME=VALUE", text(s)),
                ));
            };
            parameters.insert(k, v);
        }
        let record = if opts.record.is_empty() {
            // every output, as fmpy records by default
            let outputs: Vec<String> = md
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .map(|v| format!("{name}.{}", v.name))
                .collect();
            Some(outputs)
        } else {
            Some(opts.record.iter().map(|r| format!("{name}.{r}")).collect())
        };
        let desc = SystemDescription {
            instances: vec![InstanceSpec {
                name,
                fmu: std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
                parameters,
                step_multiple: 1,
                logging: opts.logging,
            }],
            connections: vec![],
            start_time,
            stop_time,
            step,
            algorithm: Algorithm::GaussSeidel,
            order: None,
            record,
            init_sweeps: 1,
            max_step_halvings: 0,
        };
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok(LoadedSystem::from_description(desc, &base, &file))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_steps_make_500_to_1000_points() {
        assert_eq!(round_step(1.0), 2e-3);
        assert_eq!(round_step(2.0), 4e-3);
        assert_eq!(round_step(10.0), 2e-2);
        assert_eq!(round_step(0.3), 5e-4);
        for span in [0.01, 0.7, 3.0, 15.0, 120.0, 4e4] {
            let n = span / round_step(span);
            assert!((400.0..=1250.0).contains(&n), "{span}: {n}");
        }
    }
}
