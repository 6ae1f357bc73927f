//! What FMI 2.0 requires of a modelDescription beyond its XML syntax, checked once when it is
//! read, so an FMU that breaks them is refused before any of its code runs:
//!
//! * names (2.2.9): non-empty, no control characters; with
//!   `variableNamingConvention="structured"` the standard's grammar;
//! * `modelIdentifier` (2.2.1): a C identifier, since it names the binary's file and prefixes
//!   its functions (a `/` or `..` in it would point outside `binaries/`);
//! * causality, variability and initial (2.2.7, the table of combinations) and the start value
//!   each combination requires or forbids;
//! * value references (2.2.7): variables of one base type sharing a value reference are aliases
//!   of one value, so at most one of them may carry a start value, either all or none of them
//!   are constants, and a parameter or input (a value the environment sets) is not the alias
//!   of an output or of another parameter or input (a value computed, or set twice).

use std::collections::HashMap;

use super::{Causality, ModelDescriptionError, VarType, Variability};

/// `initial` as written (or `None`) checked against the FMI 2.0 table for the causality and
/// variability; returns the effective initial (`None` where the table allows none).
pub(super) fn check_combination(
    causality: Causality,
    variability: Variability,
    initial: Option<&str>,
    var_type: VarType,
    has_start: bool,
) -> Result<Option<&'static str>, String> {
    use Causality as C;
    use Variability as V;
    if variability == V::Continuous && var_type != VarType::Real {
        return Err(format!(
            "a {var_type} variable cannot be continuous (only Real variables can)"
        ));
    }
    // FMI 2.0 table of section 2.2.7: the cases A to E of allowed initial values, the first
    // entry being the default.
    let allowed: &[&'static str] = match (causality, variability) {
        (C::Parameter, V::Fixed | V::Tunable) | (C::Output | C::Local, V::Constant) => &["exact"],
        (C::CalculatedParameter | C::Local, V::Fixed | V::Tunable) => &["calculated", "approx"],
        (C::Output | C::Local, V::Discrete | V::Continuous) => &["calculated", "exact", "approx"],
        (C::Input, V::Discrete | V::Continuous) | (C::Independent, V::Continuous) => &[],
        _ => {
            return Err(format!(
                "causality '{causality}' with variability '{variability}' is not allowed by \
                 FMI 2.0"
            ))
        }
    };
    let effective = match initial {
        None => allowed.first().copied(),
        Some(i) => match allowed.iter().find(|a| **a == i) {
            Some(a) => Some(*a),
            None if allowed.is_empty() => {
                return Err(format!(
                    "causality '{causality}' with variability '{variability}' takes no \
                     'initial' attribute, got initial=\"{i}\""
                ))
            }
            None => {
                return Err(format!(
                    "causality '{causality}' with variability '{variability}' allows initial \
                     {}, got initial=\"{i}\"",
                    allowed.join(" or ")
                ))
            }
        },
    };
    let needs_start = causality == C::Input || matches!(effective, Some("exact" | "approx"));
    let forbids_start = causality == C::Independent || effective == Some("calculated");
    if needs_start && !has_start {
        return Err(format!(
            "causality '{causality}', variability '{variability}', initial '{}' requires a \
             start value",
            effective.unwrap_or("-")
        ));
    }
    if forbids_start && has_start {
        return Err(format!(
            "causality '{causality}', initial '{}' must not have a start value",
            effective.unwrap_or("-")
        ));
    }
    Ok(effective)
}

/// A variable name under the model's naming convention (`structured` or, by default, `flat`).
pub(super) fn check_name(name: &str, structured: bool) -> Result<(), String> {
    if name.is_empty() {
        return Err("a variable name must not be empty".into());
    }
    if let Some(c) = name.chars().find(|c| c.is_control()) {
        return Err(format!(
            "a variable name must not contain the control character U+{:04X}",
            u32::from(c)
        ));
    }
    if structured && !is_structured_name(name) {
        return Err(
            "not a name of FMI 2.0's structured naming convention (2.2.9), e.g. \
             'body.position', 'x[1,2]', \"der(x)\" or a quoted 'name'"
                .into(),
        );
    }
    Ok(())
}

/// FMI 2.0 (2.2.9): `name = identifier | "der(" identifier ["," unsignedInteger] ")"`.
fn is_structured_name(name: &str) -> bool {
    let Some(inner) = name.strip_prefix("der(").and_then(|r| r.strip_suffix(')')) else {
        return identifier(name.as_bytes());
    };
    if identifier(inner.as_bytes()) {
        return true;
    }
    // der(x, 2): the order after the last ','
    inner
        .rfind(',')
        .is_some_and(|k| is_unsigned(&inner[k + 1..]) && identifier(&inner.as_bytes()[..k]))
}

fn is_unsigned(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|c| c.is_ascii_digit())
}

/// `identifier = B-name [arrayIndices] {"." B-name [arrayIndices]}`.
fn identifier(b: &[u8]) -> bool {
    let mut i = 0;
    loop {
        let Some(next) = b_name(b, i) else {
            return false;
        };
        i = next;
        if b.get(i) == Some(&b'[') {
            let Some(next) = array_indices(b, i) else {
                return false;
            };
            i = next;
        }
        match b.get(i) {
            None => return true,
            Some(b'.') => i += 1,
            Some(_) => return false,
        }
    }
}

fn nondigit(c: u8) -> bool {
    c == b'_' || c.is_ascii_alphabetic()
}

/// `B-name = nondigit {digit | nondigit} | Q-name`; returns the position after it.
fn b_name(b: &[u8], start: usize) -> Option<usize> {
    match b.get(start)? {
        b'\'' => {
            // Q-name = "'" (Q-char | escape) {Q-char | escape} "'"
            let mut i = start + 1;
            let mut chars = 0;
            loop {
                match b.get(i)? {
                    b'\'' if chars > 0 => return Some(i + 1),
                    b'\\' => {
                        if !b"'\"?\\abfnrtv".contains(b.get(i + 1)?) {
                            return None;
                        }
                        i += 2;
                    }
                    &c if nondigit(c)
                        || c.is_ascii_digit()
                        || b"!#$%&()*+,-./:;<>=?@[]^{}|~ ".contains(&c) =>
                    {
                        i += 1
                    }
                    _ => return None,
                }
                chars += 1;
            }
        }
        &c if nondigit(c) => {
            let mut i = start + 1;
            while b.get(i).is_some_and(|&c| nondigit(c) || c.is_ascii_digit()) {
                i += 1;
            }
            Some(i)
        }
        _ => None,
    }
}

/// `arrayIndices = "[" unsignedInteger {"," unsignedInteger} "]"`.
fn array_indices(b: &[u8], start: usize) -> Option<usize> {
    let mut i = start + 1;
    loop {
        let digits = b[i.min(b.len())..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        if digits == 0 {
            return None;
        }
        i += digits;
        match b.get(i)? {
            b',' => i += 1,
            b']' => return Some(i + 1),
            _ => return None,
        }
    }
}

/// `modelIdentifier`: a C identifier (FMI 2.0 2.2.1: "must be a valid C function name and
/// file name").
pub(super) fn check_model_identifier(id: &str) -> Result<(), String> {
    let mut chars = id.chars();
    let ok = chars
        .next()
        .is_some_and(|c| c == '_' || c.is_ascii_alphabetic())
        && chars.all(|c| c == '_' || c.is_ascii_alphanumeric());
    if ok {
        Ok(())
    } else {
        Err(
            "must be a C identifier (letters, digits and '_', not starting with a digit): it \
             names the binary's file and prefixes its functions"
                .into(),
        )
    }
}

/// One variable as the alias check sees it.
pub(super) struct AliasView<'a> {
    pub name: &'a str,
    pub line: usize,
    pub value_reference: u32,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    pub has_start: bool,
}

/// Variables of one base type (Real; Integer and Enumeration; Boolean; String) sharing a
/// value reference are aliases: at most one of them may have a start value (two would give one
/// value two start values), constants may not alias non-constants, and a parameter or input
/// may not alias a parameter, input or output. Each variable is compared with the first of its
/// value reference.
pub(super) fn check_aliases(vars: &[AliasView]) -> Result<(), ModelDescriptionError> {
    fn base(t: VarType) -> u8 {
        match t {
            VarType::Real => 0,
            VarType::Integer | VarType::Enumeration => 1,
            VarType::Boolean => 2,
            VarType::String => 3,
        }
    }
    // (base type, vr) -> first variable, first variable with a start value
    let mut first: HashMap<(u8, u32), (usize, Option<usize>)> = HashMap::new();
    for (i, v) in vars.iter().enumerate() {
        let key = (base(v.var_type), v.value_reference);
        let Some((f, with_start)) = first.get_mut(&key) else {
            first.insert(key, (i, v.has_start.then_some(i)));
            continue;
        };
        let other = &vars[*f];
        let clash = |reason: String| ModelDescriptionError::ValueReference {
            name: v.name.to_string(),
            line: v.line,
            other: other.name.to_string(),
            value_reference: v.value_reference,
            reason,
        };
        if (v.variability == Variability::Constant) != (other.variability == Variability::Constant)
        {
            return Err(clash(
                "a constant and a non-constant variable cannot be aliases".into(),
            ));
        }
        let set_by_environment =
            |c: Causality| matches!(c, Causality::Parameter | Causality::Input);
        let exposed = |c: Causality| set_by_environment(c) || c == Causality::Output;
        if (set_by_environment(v.causality) && exposed(other.causality))
            || (set_by_environment(other.causality) && exposed(v.causality))
        {
            return Err(clash(format!(
                "a parameter or input cannot be an alias of another parameter, input or output \
                 ('{}' is {}, '{}' is {})",
                v.name, v.causality, other.name, other.causality
            )));
        }
        if v.has_start && v.variability != Variability::Constant {
            if let Some(s) = with_start {
                let with = &vars[*s];
                return Err(ModelDescriptionError::ValueReference {
                    name: v.name.to_string(),
                    line: v.line,
                    other: with.name.to_string(),
                    value_reference: v.value_reference,
                    reason: "both have a start value, so they are not aliases of one value; \
                             give each variable its own value reference"
                        .into(),
                });
            }
            *with_start = Some(i);
        }
    }
    Ok(())
}
