//! Physics errors in the FMU's language. A physics crate names the field an error is about
//! (`speed_mps`, `valve.time_constant_s`); the declaration binds each FMI variable to a field
//! path (`params.speed_mps`), so the glue reports the error under the FMI name
//! (`vehicle.speed`) without any hand-written table.

use crate::model::{FmuModel, ModelError};
use crate::variable::{Causality, VarMeta};

/// A physics error that names the model field it is about.
pub trait FieldError: std::fmt::Display {
    /// The field (a path relative to any struct the model holds, e.g. `speed_mps` or
    /// `valve.time_constant_s`), or `None` if the error concerns no single field.
    fn field(&self) -> Option<&str>;

    /// The reason, without the field name if the physics' message starts with it (default: the
    /// whole message).
    fn reason(&self) -> String {
        self.to_string()
    }
}

/// The segments of a path such as `s.params.valve.time_constant_s` (indices kept).
fn segments(path: &str) -> impl DoubleEndedIterator<Item = &str> {
    path.split('.')
}

/// Whether `binding` ends with the segments of `field` (`params.valve.tau` ends with `valve.tau`
/// and with `tau`, not with `au`).
fn ends_with_field(binding: &str, field: &str) -> bool {
    let mut b = segments(binding).rev();
    segments(field).rev().all(|f| b.next() == Some(f))
}

/// The declared variable bound to physics field `field`: the one whose binding path ends with
/// it, preferring a parameter or an input when several match (an output may bind a same-named
/// field of the outputs struct). `None` if no variable, or several equally good ones, match.
pub fn variable_for_field<'a>(metas: &'a [VarMeta], field: &str) -> Option<&'a VarMeta> {
    if field.is_empty() {
        return None;
    }
    let matches: Vec<&VarMeta> = metas
        .iter()
        .filter(|m| {
            m.binding
                .as_deref()
                .is_some_and(|b| ends_with_field(b, field))
        })
        .collect();
    let settable: Vec<&VarMeta> = matches
        .iter()
        .copied()
        .filter(|m| m.causality.is_settable())
        .collect();
    match (settable.as_slice(), matches.as_slice()) {
        ([one], _) => Some(one),
        ([], [one]) => Some(one),
        _ => None,
    }
}

/// `text` with every physics field name in it (an identifier token containing '_', optionally
/// dotted or indexed: `area_b_m2`, `valve.time_constant_s`, `table_opening[2]`, or any token in
/// backticks) replaced by the FMI name of the variable bound to it, so messages such as "must
/// exceed area_b_m2 * half_stroke_m" speak the FMU's language. Plain words stay as they are.
pub fn rename_fields(text: &str, metas: &[VarMeta]) -> String {
    let is_ident = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '[' | ']');
    let mut out = String::with_capacity(text.len() + 16);
    let mut rest = text;
    while let Some(start) = rest.find(is_ident) {
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let len = tail.find(|c: char| !is_ident(c)).unwrap_or(tail.len());
        // A sentence's full stop is not part of the name.
        let trimmed = tail[..len].trim_end_matches('.');
        let token = if trimmed.is_empty() {
            &tail[..len]
        } else {
            trimmed
        };
        // a name in backticks is a field even without '_' (`cost`, `condition`)
        let quoted = out.ends_with('`') && tail[token.len()..].starts_with('`');
        let renamed = (token.contains('_') || quoted)
            .then(|| variable_for_field(metas, token))
            .flatten();
        out.push_str(renamed.map_or(token, |m| m.name.as_str()));
        rest = &tail[token.len()..];
    }
    out.push_str(rest);
    out
}

/// A physics error as the glue's error: under the FMI name of the variable bound to its field
/// (an invalid input if that variable is an input, else an invalid parameter), with the field
/// names in the reason renamed too. An error about no known field keeps its physics message.
pub fn field_error_in(metas: &[VarMeta], e: &dyn FieldError) -> ModelError {
    let reason = rename_fields(&e.reason(), metas);
    match e.field().and_then(|f| variable_for_field(metas, f)) {
        Some(m) if m.causality == Causality::Input => ModelError::InvalidInput {
            name: m.name.clone(),
            reason,
        },
        Some(m) => ModelError::InvalidParameter {
            name: m.name.clone(),
            reason,
        },
        None => match e.field() {
            Some(f) => ModelError::InvalidParameter {
                name: f.to_string(),
                reason,
            },
            None => ModelError::Other(reason),
        },
    }
}

/// [`rename_fields`] with the declaration of model `M` (on error paths only: the declaration is
/// built on each call).
pub fn rename_fields_of<M: FmuModel>(text: &str) -> String {
    rename_fields(text, &metas_of::<M>())
}

/// The declared variables of model `M` (built on each call: for error paths).
fn metas_of<M: FmuModel>() -> Vec<VarMeta> {
    M::variables().into_iter().map(|v| v.meta).collect()
}

/// [`field_error_in`] with the declaration of model `M` (errors are rare: the declaration is
/// built on the error path only).
pub fn field_error<M: FmuModel>(e: &dyn FieldError) -> ModelError {
    field_error_in(&metas_of::<M>(), e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variable::{VarType, Variability};

    fn meta(name: &str, binding: &str, causality: Causality) -> VarMeta {
        VarMeta {
            name: name.into(),
            description: String::new(),
            var_type: VarType::Real,
            causality,
            variability: Variability::Fixed,
            unit: None,
            display_unit: None,
            min: None,
            max: None,
            feedthrough: Vec::new(),
            binding: Some(binding.into()),
            enumeration: None,
        }
    }

    fn metas() -> Vec<VarMeta> {
        vec![
            meta("cylinder.area_b", "params.area_b_m2", Causality::Parameter),
            meta(
                "cylinder.half_stroke",
                "params.half_stroke_m",
                Causality::Parameter,
            ),
            meta(
                "valve.time_constant",
                "s.params.valve.time_constant_s",
                Causality::Parameter,
            ),
            meta("damper.elongation", "inputs.elongation_m", Causality::Input),
            meta("damper.stroke", "out.elongation_m", Causality::Output),
            meta("a.x", "p.x_m", Causality::Parameter),
            meta("b.x", "q.x_m", Causality::Parameter),
            meta("table.x[3]", "table_x[2]", Causality::Parameter),
            meta("cost.value", "board.out.cost", Causality::Output),
        ]
    }

    #[test]
    fn fields_map_by_path_suffix() {
        let m = metas();
        let name = |f| variable_for_field(&m, f).map(|v| v.name.as_str());
        assert_eq!(name("area_b_m2"), Some("cylinder.area_b"));
        assert_eq!(name("valve.time_constant_s"), Some("valve.time_constant"));
        assert_eq!(name("time_constant_s"), Some("valve.time_constant"));
        assert_eq!(
            name("params.valve.time_constant_s"),
            Some("valve.time_constant")
        );
        // A segment must match whole.
        assert_eq!(name("constant_s"), None);
        assert_eq!(name("other.time_constant_s"), None);
        // The input wins over an output bound to a same-named field.
        assert_eq!(name("elongation_m"), Some("damper.elongation"));
        // Two parameters with the same field name: ambiguous, not guessed.
        assert_eq!(name("x_m"), None);
        assert_eq!(name(""), None);
    }

    #[test]
    fn field_names_are_renamed_as_whole_tokens() {
        let m = metas();
        assert_eq!(
            rename_fields(
                "`x` must be > area_b_m2 * half_stroke_m. area_b_m2x contact ...",
                &m
            ),
            "`x` must be > cylinder.area_b * cylinder.half_stroke. area_b_m2x contact ..."
        );
        assert_eq!(rename_fields("", &m), "");
        // a plain word is a field only in backticks
        assert_eq!(
            rename_fields("non-finite output `cost` = inf: the cost is lost", &m),
            "non-finite output `cost.value` = inf: the cost is lost"
        );
        assert_eq!(
            rename_fields("must exceed table_x[2] = 1 (in [0, 1])", &m),
            "must exceed table.x[3] = 1 (in [0, 1])"
        );
    }

    struct E(&'static str);
    impl std::fmt::Display for E {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "`{}` is bad", self.0)
        }
    }
    impl FieldError for E {
        fn field(&self) -> Option<&str> {
            Some(self.0)
        }
    }

    #[test]
    fn errors_take_the_fmi_name_and_kind() {
        let m = metas();
        assert_eq!(
            field_error_in(&m, &E("half_stroke_m")),
            ModelError::InvalidParameter {
                name: "cylinder.half_stroke".into(),
                reason: "`cylinder.half_stroke` is bad".into()
            }
        );
        assert_eq!(
            field_error_in(&m, &E("elongation_m")),
            ModelError::InvalidInput {
                name: "damper.elongation".into(),
                reason: "`damper.elongation` is bad".into()
            }
        );
    }
}
