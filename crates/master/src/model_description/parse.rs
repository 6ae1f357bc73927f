//! The reader of modelDescription.xml: an `xmlparser` token stream into [`ModelDescription`],
//! errors with line numbers.

use std::collections::HashMap;

use super::*;

/// Line numbers of byte positions met in increasing order: each call counts only the newlines
/// since the previous one, so numbering a whole file stays linear in its size.
struct LineCounter<'a> {
    text: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> LineCounter<'a> {
    fn new(text: &'a str) -> Self {
        LineCounter {
            text: text.as_bytes(),
            pos: 0,
            line: 1,
        }
    }

    /// 1-based line of byte `pos` (positions before the previous one give its line).
    fn line_of(&mut self, pos: usize) -> usize {
        let pos = pos.min(self.text.len());
        if pos > self.pos {
            self.line += self.text[self.pos..pos]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            self.pos = pos;
        }
        self.line
    }
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
    /// A boolean attribute that may be absent.
    fn optional_bool(&self, key: &str) -> Result<Option<bool>, ModelDescriptionError> {
        self.get(key).map(|_| self.bool(key)).transpose()
    }
    /// The value of `key` must read as a value of type `t` (xs:double, xs:int, xs:boolean; a
    /// String anything), as the FMI 2.0 schema types them: a start value or bound that does
    /// not is a broken modelDescription.xml, not a value to guess at (FMI Library would read
    /// `1.5` as the Integer 1).
    fn typed(&self, key: &str, t: VarType) -> Result<(), ModelDescriptionError> {
        match t {
            VarType::Real => self.f64(key).map(|_| ()),
            // xs:boolean collapses whitespace, which the capability flags' bool() does not
            VarType::Boolean => match self.get(key) {
                Some(v) if !matches!(v.trim(), "true" | "false" | "1" | "0") => {
                    Err(self.invalid(key, v, "expected true or false"))
                }
                _ => Ok(()),
            },
            VarType::Integer | VarType::Enumeration => match self.get(key) {
                Some(v) if v.trim().parse::<i32>().is_err() => {
                    Err(self.invalid(key, v, "expected a 32-bit integer"))
                }
                _ => Ok(()),
            },
            VarType::String => Ok(()),
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

/// Longest entity reference looked for after a '&' ("#x10FFFF" is 8): a stray '&' costs at
/// most this much scanning, so unescaping stays linear in the text.
const MAX_ENTITY_LEN: usize = 10;

/// Replaces the five predefined XML entities and numeric character references. A reference to
/// a character XML 1.0 forbids (NUL, most control characters) is an error: it would end a C
/// string early when the text reaches the FMU.
fn unescape(s: &str) -> Result<String, String> {
    if !s.contains('&') {
        return Ok(s.to_string());
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        rest = &rest[i..];
        let window = &rest.as_bytes()[..rest.len().min(MAX_ENTITY_LEN + 2)];
        let end = window.iter().position(|&b| b == b';').unwrap_or(0);
        let ent = rest.get(1..end.max(1)).unwrap_or("");
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
            (_, Some(c)) if u32::from(c) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => {
                return Err(format!(
                    "the character reference &{ent}; is a control character XML does not allow"
                ));
            }
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
    Ok(out)
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
    min: Option<f64>,
    max: Option<f64>,
    relative_quantity: Option<bool>,
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
            enumerations: Default::default(),
            units: Default::default(),
        };
        let mut current_unit: Option<String> = None;
        // SimpleType name -> unit, and a Real's or Integer's (min, max)
        let mut type_units: HashMap<String, Option<String>> = HashMap::new();
        let mut type_ranges: HashMap<String, (Option<f64>, Option<f64>)> = HashMap::new();
        // a Real SimpleType's relativeQuantity
        let mut type_relative: HashMap<String, bool> = HashMap::new();
        // bounds are checked to be numbers of their type where they are read
        let bound = |e: &Elem, key: &str| e.get(key).and_then(|x| x.trim().parse::<f64>().ok());
        let mut current_type: Option<String> = None;
        let mut pending: Vec<PendingVar> = Vec::new();
        let mut output_lines: Vec<usize> = Vec::new();
        let mut stack: Vec<&str> = Vec::new();
        let mut current: Option<Elem> = None;
        let mut lines = LineCounter::new(xml);
        let mut structured_names = false;

        for tok in Tokenizer::from(xml) {
            let tok = tok.map_err(|e| ModelDescriptionError::Xml(e.to_string()))?;
            match tok {
                Token::ElementStart { local, span, .. } => {
                    current = Some(Elem {
                        name: local.as_str(),
                        line: lines.line_of(span.start()),
                        attrs: Vec::new(),
                    });
                }
                Token::Attribute {
                    local, value, span, ..
                } => {
                    if let Some(e) = current.as_mut() {
                        let text = unescape(value.as_str()).map_err(|reason| {
                            ModelDescriptionError::InvalidAttribute {
                                element: e.name.to_string(),
                                attribute: local.as_str().to_string(),
                                value: value.as_str().chars().take(40).collect(),
                                line: lines.line_of(span.start()),
                                reason,
                            }
                        })?;
                        e.attrs.push((local.as_str(), text));
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
                                for (key, value) in
                                    [("modelName", &md.model_name), ("guid", &md.guid)]
                                {
                                    if value.chars().any(char::is_control) {
                                        return Err(e.invalid(
                                            key,
                                            value,
                                            "contains a control character",
                                        ));
                                    }
                                }
                                structured_names = match e.get("variableNamingConvention") {
                                    None | Some("flat") => false,
                                    Some("structured") => true,
                                    Some(v) => {
                                        return Err(e.invalid(
                                            "variableNamingConvention",
                                            v,
                                            "expected flat or structured",
                                        ))
                                    }
                                };
                            }
                            ("fmiModelDescription", "CoSimulation") => {
                                let id = e.req("modelIdentifier")?;
                                rules::check_model_identifier(id)
                                    .map_err(|r| e.invalid("modelIdentifier", id, &r))?;
                                md.co_simulation = Some(CoSimulationCaps {
                                    model_identifier: id.to_string(),
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
                            ("UnitDefinitions", "Unit") => {
                                current_unit = Some(e.req("name")?.to_string());
                            }
                            ("Unit", "BaseUnit") => {
                                // read for comparing units only (SSP import): a definition
                                // that does not read is left out, not an error of the FMU
                                let exponent = |key: &str| match e.get(key) {
                                    None => Some(0),
                                    Some(v) => v.trim().parse::<i64>().ok(),
                                };
                                let number = |key: &str, default: f64| match e.get(key) {
                                    None => Some(default),
                                    Some(v) => {
                                        v.trim().parse::<f64>().ok().filter(|x| x.is_finite())
                                    }
                                };
                                let mut exponents = [0i64; 8];
                                let mut readable = true;
                                for (x, key) in exponents.iter_mut().zip(super::BASE_UNIT_NAMES) {
                                    match exponent(key) {
                                        Some(v) => *x = v,
                                        None => readable = false,
                                    }
                                }
                                if let (Some(name), true, Some(factor), Some(offset)) = (
                                    &current_unit,
                                    readable,
                                    number("factor", 1.0),
                                    number("offset", 0.0),
                                ) {
                                    md.units.insert(
                                        name.clone(),
                                        super::BaseUnit {
                                            exponents,
                                            factor,
                                            offset,
                                        },
                                    );
                                }
                            }
                            ("TypeDefinitions", "SimpleType") => {
                                let n = e.req("name")?.to_string();
                                type_units.insert(n.clone(), None);
                                current_type = Some(n);
                            }
                            ("SimpleType", "Real") => {
                                e.typed("min", VarType::Real)?;
                                e.typed("max", VarType::Real)?;
                                if let Some(t) = &current_type {
                                    type_units.insert(t.clone(), e.get("unit").map(String::from));
                                    type_ranges
                                        .insert(t.clone(), (bound(&e, "min"), bound(&e, "max")));
                                    if let Some(r) = e.optional_bool("relativeQuantity")? {
                                        type_relative.insert(t.clone(), r);
                                    }
                                }
                            }
                            ("SimpleType", "Integer") => {
                                e.typed("min", VarType::Integer)?;
                                e.typed("max", VarType::Integer)?;
                                if let Some(t) = &current_type {
                                    type_ranges
                                        .insert(t.clone(), (bound(&e, "min"), bound(&e, "max")));
                                }
                            }
                            ("SimpleType", "Enumeration") => {
                                if let Some(t) = &current_type {
                                    md.enumerations.insert(t.clone(), Vec::new());
                                }
                            }
                            ("Enumeration", "Item") => {
                                if let Some(items) = current_type
                                    .as_ref()
                                    .and_then(|t| md.enumerations.get_mut(t))
                                {
                                    let v = e.req("value")?;
                                    let value = v.trim().parse::<i32>().map_err(|_| {
                                        e.invalid("value", v, "expected a 32-bit integer")
                                    })?;
                                    items.push(EnumItem {
                                        name: e.req("name")?.to_string(),
                                        value,
                                        description: e.get("description").map(String::from),
                                    });
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
                                if let Some(t) = var_type {
                                    e.typed("start", t)?;
                                    if matches!(
                                        t,
                                        VarType::Real | VarType::Integer | VarType::Enumeration
                                    ) {
                                        e.typed("min", t)?;
                                        e.typed("max", t)?;
                                    }
                                }
                                if let (Some(t), Some(v)) = (var_type, pending.last_mut()) {
                                    v.var_type = Some(t);
                                    v.unit = e.get("unit").map(String::from);
                                    v.declared_type = e.get("declaredType").map(String::from);
                                    v.start = e.get("start").map(String::from);
                                    if matches!(t, VarType::Real | VarType::Integer) {
                                        v.min = bound(&e, "min");
                                        v.max = bound(&e, "max");
                                    }
                                    if t == VarType::Real {
                                        v.relative_quantity =
                                            e.optional_bool("relativeQuantity")?;
                                    }
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
                                // FMI 2.0 (2.2.8): one kind per dependency, of the five
                                // kinds; the kinds without the dependencies mean nothing
                                if let Some(kinds) = e.get("dependenciesKind") {
                                    let n = kinds.split_whitespace().count();
                                    if let Some(k) = kinds.split_whitespace().find(|k| {
                                        !["dependent", "constant", "fixed", "tunable", "discrete"]
                                            .contains(k)
                                    }) {
                                        return Err(e.invalid(
                                            "dependenciesKind",
                                            kinds,
                                            &format!("'{k}' is not one of dependent, constant, fixed, tunable, discrete"),
                                        ));
                                    }
                                    if depends_on.as_ref().map(Vec::len) != Some(n) {
                                        return Err(e.invalid(
                                            "dependenciesKind",
                                            kinds,
                                            &format!(
                                                "{n} kind(s) for {} dependencies",
                                                depends_on
                                                    .as_ref()
                                                    .map_or("absent".to_string(), |d| d
                                                        .len()
                                                        .to_string())
                                            ),
                                        ));
                                    }
                                }
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
        let mut lines_of_vars = Vec::with_capacity(pending.len());
        for p in pending {
            rules::check_name(&p.name, structured_names).map_err(|reason| {
                ModelDescriptionError::InvalidName {
                    name: p.name.clone(),
                    line: p.line,
                    reason,
                }
            })?;
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
            let (type_min, type_max) = p
                .declared_type
                .as_ref()
                .and_then(|d| type_ranges.get(d))
                .copied()
                .unwrap_or_default();
            let (min, max) = (p.min.or(type_min), p.max.or(type_max));
            let relative_quantity = p
                .relative_quantity
                .or_else(|| {
                    p.declared_type
                        .as_ref()
                        .and_then(|d| type_relative.get(d).copied())
                })
                .unwrap_or(false);
            if let (Some(lo), Some(hi)) = (min, max) {
                if lo > hi {
                    return Err(ModelDescriptionError::InvalidVariable {
                        name: p.name.clone(),
                        line: p.line,
                        reason: format!("min {lo} is greater than max {hi}"),
                    });
                }
            }
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
            rules::check_combination(
                causality,
                variability,
                p.initial.as_deref(),
                var_type,
                p.start.is_some(),
            )
            .map_err(|reason| ModelDescriptionError::InvalidVariable {
                name: p.name.clone(),
                line: p.line,
                reason,
            })?;
            lines_of_vars.push(p.line);
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
                declared_type: p.declared_type,
                min,
                max,
                relative_quantity,
            });
        }
        let views: Vec<rules::AliasView> = md
            .variables
            .iter()
            .zip(&lines_of_vars)
            .map(|(v, &line)| rules::AliasView {
                name: &v.name,
                line,
                value_reference: v.value_reference,
                var_type: v.var_type,
                causality: v.causality,
                variability: v.variability,
                has_start: v.start.is_some(),
            })
            .collect();
        rules::check_aliases(&views)?;
        let count = md.variables.len();
        for (o, &line) in md.outputs.iter().zip(&output_lines) {
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
        check_output_structure(&md, &output_lines, &lines_of_vars)?;
        Ok(md)
    }
}

/// FMI 2.0 (2.2.8): ModelStructure/Outputs lists every variable of causality output exactly
/// once and nothing else, and an output depends only on knowns: inputs, states (locals) and
/// the independent variable, not on a parameter, another output or itself. (The indices are
/// checked to be in range before.)
fn check_output_structure(
    md: &ModelDescription,
    lines: &[usize],
    variable_lines: &[usize],
) -> Result<(), ModelDescriptionError> {
    let mut listed = vec![false; md.variables.len()];
    for (o, &line) in md.outputs.iter().zip(lines) {
        let fail = |reason: String| Err(ModelDescriptionError::OutputStructure { line, reason });
        let v = &md.variables[o.output];
        if v.causality != Causality::Output {
            return fail(format!(
                "index {} is '{}', whose causality is {}, not output",
                o.output + 1,
                v.name,
                v.causality
            ));
        }
        if std::mem::replace(&mut listed[o.output], true) {
            return fail(format!("output '{}' is listed twice", v.name));
        }
        for &d in o.depends_on.iter().flatten() {
            let known = &md.variables[d];
            if !matches!(
                known.causality,
                Causality::Input | Causality::Local | Causality::Independent
            ) {
                let what = if d == o.output {
                    "itself".to_string()
                } else {
                    format!(
                        "'{}', a variable of causality {}",
                        known.name, known.causality
                    )
                };
                return fail(format!(
                    "output '{}' depends on {what} (index {}); an output depends on inputs, \
                     states and the independent variable only",
                    v.name,
                    d + 1
                ));
            }
        }
    }
    for ((v, &l), &line) in md.variables.iter().zip(&listed).zip(variable_lines) {
        if v.causality == Causality::Output && !l {
            return Err(ModelDescriptionError::InvalidVariable {
                name: v.name.clone(),
                line,
                reason: "an output not listed in ModelStructure/Outputs".into(),
            });
        }
    }
    Ok(())
}
