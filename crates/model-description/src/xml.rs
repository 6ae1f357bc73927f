//! modelDescription.xml writer.
//!
//! Why our own writer and not `fmi-schema`: as of 0.8, its FMI 2.0 types carry no unit/min/max on
//! Real variables and drop an empty `dependencies` list. An omitted list means "depends on every
//! input", which makes hosts (OMSimulator, for one) see false algebraic loops through a damper
//! whose force comes from a pressure state. The writer below is small and tested instead.

use std::collections::{BTreeSet, HashMap};
use std::fmt::Write as _;

use crate::enumeration::EnumType;
use crate::model::{FmuModel, InstanceContext, ModelInfo};
use crate::units;
use crate::variable::{Access, Causality, VarMeta, VarType, Variable};

/// A declaration that cannot yield a valid modelDescription.xml.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum DeclarationError {
    #[error("model {model}: duplicate variable name '{name}'")]
    DuplicateName { model: String, name: String },
    #[error("model {model}: '{name}' is not a valid structured variable name")]
    BadName { model: String, name: String },
    #[error("model {model}: variable '{name}' uses unknown unit '{unit}'")]
    UnknownUnit {
        model: String,
        name: String,
        unit: String,
    },
    #[error(
        "model {model}: variable '{name}': display unit '{display}' is not defined for '{unit}'"
    )]
    UnknownDisplayUnit {
        model: String,
        name: String,
        unit: String,
        display: String,
    },
    #[error(
        "model {model}: output '{name}' lists '{input}' as feedthrough, which is not an input"
    )]
    BadFeedthrough {
        model: String,
        name: String,
        input: String,
    },
    #[error("model {model}: variable '{name}': {reason}")]
    BadStart {
        model: String,
        name: String,
        reason: String,
    },
    #[error("model {model}: variable '{name}' has causality {causality} but a setter/getter that does not fit it")]
    BadAccess {
        model: String,
        name: String,
        causality: String,
    },
    #[error("model {model}: cannot create a default instance: {reason}")]
    Instantiate { model: String, reason: String },
    #[error(
        "model {model}: DefaultExperiment from {start} to {stop} s is not a whole number of \
         {step} s steps in floating point (strict hosts refuse it)"
    )]
    BadDefaultExperiment {
        model: String,
        start: f64,
        stop: f64,
        step: f64,
    },
    #[error("model {model}: enumeration type '{name}': {reason}")]
    BadEnumeration {
        model: String,
        name: String,
        reason: String,
    },
}

/// A start value read from the default instance.
#[derive(Clone, Debug, PartialEq)]
pub enum StartValue {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

/// Value reference of each variable, by declaration index: per type, in declaration order.
pub fn value_references<M>(vars: &[Variable<M>]) -> Vec<u32> {
    let mut next: HashMap<VarType, u32> = HashMap::new();
    vars.iter()
        .map(|v| {
            let counter = next.entry(v.meta.var_type).or_insert(0);
            let vr = *counter;
            *counter += 1;
            vr
        })
        .collect()
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    match chars.next() {
        Some(c) if c.is_ascii_alphabetic() || c == '_' => {}
        _ => return false,
    }
    chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// FMI 2.0 structured naming: identifiers joined by '.', each optionally followed by `[n]`.
pub fn is_structured_name(name: &str) -> bool {
    !name.is_empty()
        && name.split('.').all(|part| {
            let (ident, index) = match part.find('[') {
                Some(i) => (&part[..i], Some(&part[i..])),
                None => (part, None),
            };
            is_identifier(ident)
                && index.is_none_or(|ix| {
                    ix.len() > 2
                        && ix.ends_with(']')
                        && ix[1..ix.len() - 1].chars().all(|c| c.is_ascii_digit())
                })
        })
}

pub(crate) use fmu_binary::escape_attribute as escape;

pub(crate) fn fmt_real(x: f64) -> String {
    // Debug formatting is the shortest representation that parses back to the same f64.
    format!("{x:?}")
}

/// Check a declaration and read its start values from a default instance.
pub fn check_declaration<M: FmuModel>(
    vars: &[Variable<M>],
) -> Result<Vec<Option<StartValue>>, DeclarationError> {
    let model = M::INFO.name.to_string();
    let mut names = BTreeSet::new();
    for v in vars {
        let m = &v.meta;
        if !is_structured_name(&m.name) {
            return Err(DeclarationError::BadName {
                model,
                name: m.name.clone(),
            });
        }
        if !names.insert(m.name.as_str()) {
            return Err(DeclarationError::DuplicateName {
                model,
                name: m.name.clone(),
            });
        }
        if let Some(unit) = m.unit {
            let def = units::find(unit).ok_or_else(|| DeclarationError::UnknownUnit {
                model: model.clone(),
                name: m.name.clone(),
                unit: unit.to_string(),
            })?;
            if let Some(display) = m.display_unit {
                if !def.display.iter().any(|(n, _, _)| *n == display) {
                    return Err(DeclarationError::UnknownDisplayUnit {
                        model,
                        name: m.name.clone(),
                        unit: unit.to_string(),
                        display: display.to_string(),
                    });
                }
            }
        }
        let settable = v.access.is_settable();
        let needs_setter = matches!(m.causality, Causality::Parameter | Causality::Input);
        if settable != needs_setter {
            return Err(DeclarationError::BadAccess {
                model,
                name: m.name.clone(),
                causality: m.causality.xml_name().to_string(),
            });
        }
    }
    for v in vars {
        for input in &v.meta.feedthrough {
            let ok = vars
                .iter()
                .any(|w| w.meta.name == *input && w.meta.causality == Causality::Input);
            if !ok {
                return Err(DeclarationError::BadFeedthrough {
                    model,
                    name: v.meta.name.clone(),
                    input: input.to_string(),
                });
            }
        }
    }
    let de = M::INFO.default_experiment;
    if !default_experiment_is_exact(de.start_time, de.stop_time, de.step_size) {
        return Err(DeclarationError::BadDefaultExperiment {
            model,
            start: de.start_time,
            stop: de.stop_time,
            step: de.step_size,
        });
    }
    for e in enumeration_types(vars) {
        let bad = |reason: String| DeclarationError::BadEnumeration {
            model: model.clone(),
            name: e.name.to_string(),
            reason,
        };
        if !is_structured_name(e.name) {
            return Err(bad("not a valid type name".into()));
        }
        if vars.iter().any(|v| v.meta.name == e.name) {
            return Err(bad("a variable has the same name".into()));
        }
        let same_name = enumeration_types(vars)
            .iter()
            .filter(|o| o.name == e.name)
            .count();
        if same_name > 1 {
            return Err(bad("two different types have this name".into()));
        }
        if e.items.is_empty() {
            return Err(bad("no items".into()));
        }
        for (i, item) in e.items.iter().enumerate() {
            if e.items[..i]
                .iter()
                .any(|o| o.name == item.name || o.value == item.value)
            {
                return Err(bad(format!("item '{}' repeats a name or value", item.name)));
            }
        }
    }
    let instance =
        M::instantiate(&InstanceContext::default()).map_err(|e| DeclarationError::Instantiate {
            model: model.clone(),
            reason: e.to_string(),
        })?;
    vars.iter()
        .map(|v| {
            if !v.meta.has_start() {
                return Ok(None);
            }
            let start = match &v.access {
                Access::Real { get, .. } => {
                    let x = get(&instance);
                    if !x.is_finite() {
                        return Err(DeclarationError::BadStart {
                            model: model.clone(),
                            name: v.meta.name.clone(),
                            reason: format!("start value {x} is not finite"),
                        });
                    }
                    if v.meta.min.is_some_and(|lo| x < lo) || v.meta.max.is_some_and(|hi| x > hi) {
                        return Err(DeclarationError::BadStart {
                            model: model.clone(),
                            name: v.meta.name.clone(),
                            reason: format!("start value {x} outside [min, max]"),
                        });
                    }
                    StartValue::Real(x)
                }
                Access::Integer { get, .. } => {
                    let n = get(&instance);
                    if v.meta.enumeration.is_some_and(|e| e.item(n).is_none()) {
                        return Err(DeclarationError::BadStart {
                            model: model.clone(),
                            name: v.meta.name.clone(),
                            reason: format!("start value {n} is not an item of its enumeration"),
                        });
                    }
                    StartValue::Integer(n)
                }
                Access::Boolean { get, .. } => StartValue::Boolean(get(&instance)),
                Access::String { get, .. } => StartValue::String(get(&instance)),
            };
            Ok(Some(start))
        })
        .collect()
}

/// Whether `stop - start` is a whole number n of `step`s exactly in floating point: `(stop -
/// start) / step == n` and `start + n step == stop`. Strict hosts (fmusim) refuse a default
/// experiment where 0.3 / 1e-4 = 2999.9999999999995.
pub fn default_experiment_is_exact(start: f64, stop: f64, step: f64) -> bool {
    if !(start.is_finite() && stop.is_finite() && step.is_finite() && step > 0.0 && stop > start) {
        return false;
    }
    let ratio = (stop - start) / step;
    let n = ratio.round();
    ratio == n && start + n * step == stop
}

/// The Enumeration types the variables use, each once, in order of first use (types are
/// compared by value: two variables of one Rust enum share its type).
pub fn enumeration_types<M>(vars: &[Variable<M>]) -> Vec<&'static EnumType> {
    let mut types: Vec<&'static EnumType> = Vec::new();
    for e in vars.iter().filter_map(|v| v.meta.enumeration) {
        if !types.contains(&e) {
            types.push(e);
        }
    }
    types
}

/// Capability flags of the CoSimulation element. True only where the glue implements it.
pub const CAPABILITIES: &[(&str, &str)] = &[
    ("needsExecutionTool", "false"),
    // Every model integrates internally over whatever interval the host asks for.
    ("canHandleVariableCommunicationStepSize", "true"),
    // Inputs are held constant over a step (zero-order hold); fmi2SetRealInputDerivatives
    // returns fmi2Error.
    ("canInterpolateInputs", "false"),
    ("maxOutputDerivativeOrder", "0"),
    ("canRunAsynchronuously", "false"),
    // No process-global state: any number of instances per process, also across threads.
    ("canBeInstantiatedOnlyOncePerProcess", "false"),
    // Memory comes from Rust's allocator, never from the host's callbacks.
    ("canNotUseMemoryManagementFunctions", "true"),
    ("canGetAndSetFMUstate", "true"),
    ("canSerializeFMUstate", "true"),
    ("providesDirectionalDerivative", "false"),
];

/// Log categories offered to fmi2SetDebugLogging.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logEvents",
        "Model events (valve switching, controller updates, flange contact)",
    ),
    (
        "logStatusWarning",
        "Warnings (clamped inputs, held commands)",
    ),
    ("logStatusDiscard", "Discarded steps"),
    (
        "logStatusError",
        "Errors (bad calls, bad values, failed steps)",
    ),
    ("logCalls", "Every FMI call (very verbose)"),
];

/// The generated description: XML text with the GUID filled in, and the GUID.
pub struct Description {
    pub xml: String,
    pub guid: String,
}

/// Generate modelDescription.xml for `M`. The GUID is a name-based UUID (v5) of the XML
/// without its GUID, so it changes exactly when the interface (or a start value) changes.
pub fn model_description<M: FmuModel>() -> Result<Description, DeclarationError> {
    let vars = M::variables();
    let starts = check_declaration::<M>(&vars)?;
    let body = render::<M>(&vars, &starts);
    let guid = format!(
        "{{{}}}",
        uuid::Uuid::new_v5(&uuid::Uuid::NAMESPACE_OID, body.as_bytes())
    );
    Ok(Description {
        xml: body.replacen("@GUID@", &guid, 1),
        guid,
    })
}

/// The `copyright` attribute of every FMU.
pub const COPYRIGHT: &str = "Copyright (c) 2026 the rail-fmu authors";
/// The project's licence (SPDX expression, from the workspace manifest).
pub const LICENSE_ID: &str = env!("CARGO_PKG_LICENSE");
/// Where every FMU ships the licence texts, relative to the FMU's root.
const LICENSE_FILES: &str = "documentation/LICENSE-MIT.txt, documentation/LICENSE-APACHE.txt";
/// The licence texts of the project (the repository's LICENSE-MIT and LICENSE-APACHE).
pub const LICENSE_MIT: &str = include_str!("../../../LICENSE-MIT");
pub const LICENSE_APACHE: &str = include_str!("../../../LICENSE-APACHE");

fn render<M: FmuModel>(vars: &[Variable<M>], starts: &[Option<StartValue>]) -> String {
    let info: ModelInfo = M::INFO;
    let vrs = value_references(vars);
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        x,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="@GUID@" description="{}" author="{}" version="{}" copyright="{}" license="{}" generationTool="model-description {}" variableNamingConvention="structured" numberOfEventIndicators="0">"#,
        escape(info.name),
        escape(info.description),
        escape(info.author),
        escape(info.version),
        escape(COPYRIGHT),
        escape(&format!("{LICENSE_ID} ({LICENSE_FILES})")),
        env!("CARGO_PKG_VERSION"),
    );
    let _ = write!(
        x,
        r#"  <CoSimulation modelIdentifier="{}""#,
        escape(info.name)
    );
    for (k, v) in CAPABILITIES {
        let _ = write!(x, r#" {k}="{v}""#);
    }
    let _ = writeln!(x, "/>");

    let used: BTreeSet<&str> = vars.iter().filter_map(|v| v.meta.unit).collect();
    if !used.is_empty() {
        let _ = writeln!(x, "  <UnitDefinitions>");
        for def in units::UNITS.iter().filter(|u| used.contains(u.name)) {
            let _ = write!(x, r#"    <Unit name="{}""#, escape(def.name));
            if !def.base && def.display.is_empty() {
                let _ = writeln!(x, "/>");
                continue;
            }
            let _ = write!(x, ">");
            if def.base {
                let _ = write!(x, "<BaseUnit");
                for (attr, exp) in [
                    ("kg", def.kg),
                    ("m", def.m),
                    ("s", def.s),
                    ("A", def.a),
                    ("rad", def.rad),
                ] {
                    if exp != 0 {
                        let _ = write!(x, r#" {attr}="{exp}""#);
                    }
                }
                let _ = write!(x, "/>");
            }
            for (name, factor, offset) in def.display {
                let _ = write!(
                    x,
                    r#"<DisplayUnit name="{}" factor="{}" offset="{}"/>"#,
                    escape(name),
                    fmt_real(*factor),
                    fmt_real(*offset)
                );
            }
            let _ = writeln!(x, "</Unit>");
        }
        let _ = writeln!(x, "  </UnitDefinitions>");
    }

    let types = enumeration_types(vars);
    if !types.is_empty() {
        let _ = writeln!(x, "  <TypeDefinitions>");
        for e in &types {
            let _ = writeln!(
                x,
                r#"    <SimpleType name="{}" description="{}">"#,
                escape(e.name),
                escape(e.description)
            );
            let _ = writeln!(x, "      <Enumeration>");
            for item in e.items {
                let _ = writeln!(
                    x,
                    r#"        <Item name="{}" value="{}" description="{}"/>"#,
                    escape(item.name),
                    item.value,
                    escape(item.description)
                );
            }
            let _ = writeln!(x, "      </Enumeration>");
            let _ = writeln!(x, "    </SimpleType>");
        }
        let _ = writeln!(x, "  </TypeDefinitions>");
    }

    let _ = writeln!(x, "  <LogCategories>");
    for (name, desc) in LOG_CATEGORIES {
        let _ = writeln!(
            x,
            r#"    <Category name="{name}" description="{}"/>"#,
            escape(desc)
        );
    }
    let _ = writeln!(x, "  </LogCategories>");
    let de = info.default_experiment;
    let _ = writeln!(
        x,
        r#"  <DefaultExperiment startTime="{}" stopTime="{}" stepSize="{}"/>"#,
        fmt_real(de.start_time),
        fmt_real(de.stop_time),
        fmt_real(de.step_size)
    );

    let _ = writeln!(x, "  <ModelVariables>");
    for (i, v) in vars.iter().enumerate() {
        let m: &VarMeta = &v.meta;
        let _ = writeln!(x, "    <!-- index {} -->", i + 1);
        let _ = write!(
            x,
            r#"    <ScalarVariable name="{}" valueReference="{}" description="{}" causality="{}" variability="{}""#,
            escape(&m.name),
            vrs[i],
            escape(&m.description),
            m.causality.xml_name(),
            m.variability.xml_name()
        );
        if let Some(initial) = m.initial() {
            let _ = write!(x, r#" initial="{initial}""#);
        }
        let _ = write!(x, ">\n      <{}", m.type_element());
        if let Some(e) = m.enumeration {
            let _ = write!(x, r#" declaredType="{}""#, escape(e.name));
        }
        if let Some(Some(start)) = starts.get(i) {
            let s = match start {
                StartValue::Real(r) => fmt_real(*r),
                StartValue::Integer(n) => n.to_string(),
                StartValue::Boolean(b) => b.to_string(),
                StartValue::String(s) => escape(s),
            };
            let _ = write!(x, r#" start="{s}""#);
        }
        if m.var_type == VarType::Real {
            if let Some(unit) = m.unit {
                let _ = write!(x, r#" unit="{}""#, escape(unit));
            }
            if let Some(display) = m.display_unit {
                let _ = write!(x, r#" displayUnit="{}""#, escape(display));
            }
        }
        if matches!(m.var_type, VarType::Real | VarType::Integer) {
            let fmt = |b: f64| match m.var_type {
                VarType::Integer => format!("{}", b.round() as i64),
                _ => fmt_real(b),
            };
            if let Some(lo) = m.min {
                let _ = write!(x, r#" min="{}""#, fmt(lo));
            }
            if let Some(hi) = m.max {
                let _ = write!(x, r#" max="{}""#, fmt(hi));
            }
        }
        let _ = writeln!(x, "/>\n    </ScalarVariable>");
    }
    let _ = writeln!(x, "  </ModelVariables>");

    // ModelStructure. Indices are 1-based positions in ModelVariables.
    let index_of = |name: &str| vars.iter().position(|v| v.meta.name == name).map(|i| i + 1);
    let outputs: Vec<usize> = (0..vars.len())
        .filter(|&i| vars[i].meta.causality == Causality::Output)
        .collect();
    let exact_params: Vec<usize> = (0..vars.len())
        .filter(|&i| vars[i].meta.causality == Causality::Parameter)
        .map(|i| i + 1)
        .collect();
    let feedthrough = |i: usize| -> Vec<usize> {
        let mut d: Vec<usize> = vars[i]
            .meta
            .feedthrough
            .iter()
            .filter_map(|n| index_of(n))
            .collect();
        d.sort_unstable();
        d
    };
    let join = |d: &[usize]| {
        d.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let _ = writeln!(x, "  <ModelStructure>");
    if !outputs.is_empty() {
        let _ = writeln!(x, "    <Outputs>");
        for &i in &outputs {
            let _ = writeln!(
                x,
                r#"      <Unknown index="{}" dependencies="{}"/>"#,
                i + 1,
                join(&feedthrough(i))
            );
        }
        let _ = writeln!(x, "    </Outputs>");
    }
    // Initial unknowns: outputs and calculated parameters. At initialisation they may depend on
    // their feedthrough inputs and on every exact parameter.
    let initial_unknowns: Vec<usize> = (0..vars.len())
        .filter(|&i| {
            matches!(
                vars[i].meta.causality,
                Causality::Output | Causality::CalculatedParameter
            )
        })
        .collect();
    if !initial_unknowns.is_empty() {
        let _ = writeln!(x, "    <InitialUnknowns>");
        for &i in &initial_unknowns {
            let mut deps = feedthrough(i);
            deps.extend(exact_params.iter().copied());
            deps.sort_unstable();
            deps.dedup();
            let _ = writeln!(
                x,
                r#"      <Unknown index="{}" dependencies="{}"/>"#,
                i + 1,
                join(&deps)
            );
        }
        let _ = writeln!(x, "    </InitialUnknowns>");
    }
    let _ = writeln!(x, "  </ModelStructure>");
    let _ = writeln!(x, "</fmiModelDescription>");
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structured_names() {
        assert!(is_structured_name("damper_left.force"));
        assert!(is_structured_name("a.b[3].c"));
        assert!(!is_structured_name("1abc"));
        assert!(!is_structured_name("a..b"));
        assert!(!is_structured_name("a.b[]"));
        assert!(!is_structured_name("a b"));
        assert!(!is_structured_name(""));
    }

    #[test]
    fn escaping() {
        assert_eq!(escape(r#"<a & "b">"#), "&lt;a &amp; &quot;b&quot;&gt;");
    }

    #[test]
    fn default_experiments_that_strict_hosts_accept() {
        assert!(default_experiment_is_exact(0.0, 5.0, 1e-3));
        assert!(default_experiment_is_exact(0.0, 0.25, 1e-4));
        assert!(!default_experiment_is_exact(0.0, 0.3, 1e-4));
        assert!(!default_experiment_is_exact(0.0, 1.0, 0.0));
        assert!(!default_experiment_is_exact(0.0, 1.0, 0.3));
    }

    #[test]
    fn reals_round_trip() {
        for x in [0.1, 1.0e-10, 330e3, -2.5, 1.0 / 3.0] {
            let s = fmt_real(x);
            assert_eq!(s.parse::<f64>().ok(), Some(x), "{s}");
        }
    }
}
