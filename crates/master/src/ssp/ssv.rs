//! Parameter sets (.ssv, `ssv:ParameterSet`) and parameter mappings (.ssm,
//! `ssm:ParameterMapping`), SSP 1.0 and 2.0, scalar values only.

use roxmltree::Node;

use super::xml::{
    self, check_single_children, content, elements, is, qualified, scalar, Ctx, NS_SSC, NS_SSM,
    NS_SSV,
};
use super::SspError;
use crate::show;

/// A scalar parameter value by SSP type family.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// The item name.
    Enumeration(String),
}

impl Value {
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Real(_) => "Real",
            Value::Integer(_) => "Integer",
            Value::Boolean(_) => "Boolean",
            Value::String(_) => "String",
            Value::Enumeration(_) => "Enumeration",
        }
    }
}

#[derive(Debug, Clone)]
pub(super) struct Parameter {
    pub name: String,
    pub value: Value,
    pub unit: Option<String>,
    pub line: usize,
}

#[derive(Debug, Clone)]
pub(super) struct ParameterSet {
    pub name: String,
    pub parameters: Vec<Parameter>,
    /// Units declared in the set (`ssv:Units`).
    pub units: Vec<super::ssd::UnitDef>,
}

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Transformation {
    Linear { factor: f64, offset: f64 },
    Boolean(Vec<(bool, bool)>),
    Integer(Vec<(i64, i64)>),
    Enumeration(Vec<(String, String)>),
}

#[derive(Debug, Clone)]
pub(super) struct MappingEntry {
    pub source: String,
    pub target: String,
    pub transformation: Option<Transformation>,
    pub line: usize,
}

#[derive(Debug, Clone)]
pub(super) struct Mapping {
    pub entries: Vec<MappingEntry>,
}

fn check_version(ctx: Ctx, n: Node) -> Result<(), SspError> {
    let v = ctx.req(n, "version")?.trim();
    if v == "1.0" || v == "2.0" || v.starts_with("1.0-") {
        Ok(())
    } else {
        Err(ctx.unsupported(n, format!("<{}> version '{}'", qualified(n), show::text(v))))
    }
}

/// Parses a whole .ssv file.
pub(super) fn parse_ssv(file: &str, text: &str) -> Result<ParameterSet, SspError> {
    let (doc, lines) = xml::parse(file, text)?;
    let ctx = Ctx {
        file,
        lines: &lines,
    };
    parse_set(ctx, doc.root_element())
}

/// Parses an `ssv:ParameterSet` element.
pub(super) fn parse_set(ctx: Ctx, n: Node) -> Result<ParameterSet, SspError> {
    if !is(n, NS_SSV, "ParameterSet") {
        return Err(ctx.err(
            n,
            format!(
                "expected <ssv:ParameterSet> of {NS_SSV}, found <{}>",
                qualified(n)
            ),
        ));
    }
    check_version(ctx, n)?;
    let mut set = ParameterSet {
        name: ctx.req(n, "name")?.to_string(),
        parameters: Vec::new(),
        units: Vec::new(),
    };
    // SSV 1.0 6: a parameter's name "MUST be unique within the parameter set"
    let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    check_single_children(ctx, n)?;
    for c in content(n) {
        match c.tag_name().name() {
            "Parameters" if is(c, NS_SSV, "Parameters") => {
                for p in elements(c) {
                    if !is(p, NS_SSV, "Parameter") {
                        return Err(ctx.unexpected(p));
                    }
                    let parameter = parse_parameter(ctx, p)?;
                    if let Some(first) = seen.insert(parameter.name.clone(), parameter.line) {
                        return Err(ctx.err(
                            p,
                            format!(
                                "parameter '{}' is given twice in set '{}' (first at line \
                                 {first}): a name is unique within a parameter set",
                                crate::show::text(&parameter.name),
                                crate::show::text(&set.name)
                            ),
                        ));
                    }
                    set.parameters.push(parameter);
                }
            }
            "Units" if is(c, NS_SSV, "Units") => {
                set.units = super::ssd::parse_units(ctx, c)?;
            }
            "Enumerations" | "Annotations" if c.tag_name().namespace() == Some(NS_SSV) => {}
            _ => return Err(ctx.unexpected(c)),
        }
    }
    Ok(set)
}

fn parse_parameter(ctx: Ctx, p: Node) -> Result<Parameter, SspError> {
    let name = ctx.req(p, "name")?.to_string();
    let mut value = None;
    let mut unit = None;
    for t in content(p) {
        // SSP 1.0 has no arrays; 2.0 gives their size as <ssc:Dimension>
        if t.tag_name().name() == "Dimension" {
            return Err(ctx.unsupported(t, format!("array parameter '{name}'")));
        }
        if t.tag_name().namespace() != Some(NS_SSV) {
            return Err(ctx.unexpected(t));
        }
        let bad = |what: &str| {
            ctx.err(
                t,
                format!("parameter '{name}': <ssv:{}> {what}", t.tag_name().name()),
            )
        };
        let v = match t.tag_name().name() {
            "Annotations" => continue,
            "Real" | "Float64" => {
                unit = t.attribute("unit").map(str::to_string);
                let s = scalar(ctx, t)?;
                Value::Real(
                    s.parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| bad(&format!("value \"{}\" is not a finite number", show::text(s))))?,
                )
            }
            "Integer" | "Int32" | "Int8" | "UInt8" | "Int16" | "UInt16" => {
                let s = scalar(ctx, t)?;
                let x = s
                    .parse::<i64>()
                    .map_err(|_| bad(&format!("value \"{}\" is not an integer", show::text(s))))?;
                Value::Integer(x)
            }
            "Boolean" => match scalar(ctx, t)? {
                "true" | "1" => Value::Boolean(true),
                "false" | "0" => Value::Boolean(false),
                s => return Err(bad(&format!("value \"{}\" is not true or false", show::text(s)))),
            },
            "String" => {
                if elements(t).next().is_some() {
                    return Err(ctx.unsupported(t, format!("array parameter '{name}'")));
                }
                Value::String(ctx.req(t, "value")?.to_string())
            }
            "Enumeration" => {
                if elements(t).next().is_some() {
                    return Err(ctx.unsupported(t, format!("array parameter '{name}'")));
                }
                Value::Enumeration(ctx.req(t, "value")?.trim().to_string())
            }
            other => {
                return Err(ctx.unsupported(
                    t,
                    format!("parameter '{name}' of type {other} (FMI 2.0 has Real, Integer, Boolean, String, Enumeration)"),
                ))
            }
        };
        if value.replace(v).is_some() {
            return Err(ctx.err(p, format!("parameter '{name}' has more than one value")));
        }
    }
    let value = value.ok_or_else(|| ctx.err(p, format!("parameter '{name}' has no value")))?;
    Ok(Parameter {
        name,
        value,
        unit,
        line: ctx.line(p),
    })
}

/// Parses a whole .ssm file.
pub(super) fn parse_ssm(file: &str, text: &str) -> Result<Mapping, SspError> {
    let (doc, lines) = xml::parse(file, text)?;
    let ctx = Ctx {
        file,
        lines: &lines,
    };
    parse_mapping(ctx, doc.root_element())
}

/// Parses an `ssm:ParameterMapping` element.
pub(super) fn parse_mapping(ctx: Ctx, n: Node) -> Result<Mapping, SspError> {
    if !is(n, NS_SSM, "ParameterMapping") {
        return Err(ctx.err(
            n,
            format!(
                "expected <ssm:ParameterMapping> of {NS_SSM}, found <{}>",
                qualified(n)
            ),
        ));
    }
    check_version(ctx, n)?;
    let mut entries = Vec::new();
    let mut targets: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for e in content(n) {
        match e.tag_name().name() {
            "MappingEntry" if is(e, NS_SSM, "MappingEntry") => {
                let mut transformation = None;
                for t in content(e) {
                    if t.tag_name().namespace() == Some(NS_SSM)
                        && t.tag_name().name() == "Annotations"
                    {
                        continue;
                    }
                    if t.tag_name().namespace() != Some(NS_SSC) {
                        return Err(ctx.unexpected(t));
                    }
                    // one transformation at most: a second replaced the first
                    if transformation
                        .replace(parse_transformation(ctx, t)?)
                        .is_some()
                    {
                        return Err(
                            ctx.err(t, "a <ssm:MappingEntry> holds more than one transformation")
                        );
                    }
                }
                check_single_children(ctx, e)?;
                let target = ctx.req(e, "target")?.to_string();
                // SSM 1.0 7: multiple parameters MUST NOT be mapped to the same name
                if let Some(first) = targets.insert(target.clone(), ctx.line(e)) {
                    return Err(ctx.err(
                        e,
                        format!(
                            "mapping target '{}' is mapped to twice (first at line {first}): \
                             one parameter per target",
                            crate::show::text(&target)
                        ),
                    ));
                }
                entries.push(MappingEntry {
                    source: ctx.req(e, "source")?.to_string(),
                    target,
                    transformation,
                    line: ctx.line(e),
                });
            }
            "Annotations" if e.tag_name().namespace() == Some(NS_SSM) => {}
            _ => return Err(ctx.unexpected(e)),
        }
    }
    Ok(Mapping { entries })
}

fn parse_transformation(ctx: Ctx, t: Node) -> Result<Transformation, SspError> {
    let entries = || elements(t).filter(|m| is(*m, NS_SSC, "MapEntry"));
    Ok(match t.tag_name().name() {
        "LinearTransformation" => Transformation::Linear {
            factor: ctx.f64(t, "factor")?.unwrap_or(1.0),
            offset: ctx.f64(t, "offset")?.unwrap_or(0.0),
        },
        "BooleanMappingTransformation" => {
            let mut v = Vec::new();
            for m in entries() {
                let s = ctx.bool(m, "source")?;
                let d = ctx.bool(m, "target")?;
                match (s, d) {
                    (Some(s), Some(d)) => v.push((s, d)),
                    _ => return Err(ctx.err(m, "<ssc:MapEntry> needs source and target")),
                }
            }
            Transformation::Boolean(v)
        }
        "IntegerMappingTransformation" => {
            let mut v = Vec::new();
            for m in entries() {
                match (ctx.i64(m, "source")?, ctx.i64(m, "target")?) {
                    (Some(s), Some(d)) => v.push((s, d)),
                    _ => return Err(ctx.err(m, "<ssc:MapEntry> needs source and target")),
                }
            }
            Transformation::Integer(v)
        }
        "EnumerationMappingTransformation" => {
            let mut v = Vec::new();
            for m in entries() {
                v.push((
                    ctx.req(m, "source")?.to_string(),
                    ctx.req(m, "target")?.to_string(),
                ));
            }
            Transformation::Enumeration(v)
        }
        _ => return Err(ctx.unexpected(t)),
    })
}

impl Transformation {
    /// Applies the transformation; `Err` is the reason it does not fit the value.
    pub fn apply(&self, v: &Value) -> Result<Value, String> {
        let no_entry = |s: String| format!("the mapping has no entry for {s}");
        match (self, v) {
            (Transformation::Linear { factor, offset }, Value::Real(x)) => {
                let y = factor * x + offset;
                if y.is_finite() {
                    Ok(Value::Real(y))
                } else {
                    Err(format!(
                        "{factor:?} x {x:?} + {offset:?} is {y}, not a finite number (the linear \
                         transformation overflows)"
                    ))
                }
            }
            (Transformation::Boolean(m), Value::Boolean(b)) => m
                .iter()
                .find(|(s, _)| s == b)
                .map(|(_, d)| Value::Boolean(*d))
                .ok_or_else(|| no_entry(b.to_string())),
            (Transformation::Integer(m), Value::Integer(i)) => m
                .iter()
                .find(|(s, _)| s == i)
                .map(|(_, d)| Value::Integer(*d))
                .ok_or_else(|| no_entry(i.to_string())),
            (Transformation::Enumeration(m), Value::Enumeration(e)) => m
                .iter()
                .find(|(s, _)| s == e)
                .map(|(_, d)| Value::Enumeration(d.clone()))
                .ok_or_else(|| no_entry(format!("'{e}'"))),
            (t, v) => Err(format!(
                "a {} transformation cannot apply to a {} value",
                match t {
                    Transformation::Linear { .. } => "linear",
                    Transformation::Boolean(_) => "Boolean mapping",
                    Transformation::Integer(_) => "Integer mapping",
                    Transformation::Enumeration(_) => "Enumeration mapping",
                },
                v.kind()
            )),
        }
    }
}
