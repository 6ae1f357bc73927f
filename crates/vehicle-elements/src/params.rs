//! The error of a rejected parameter and the range checks that produce it.

use model_description::FieldError;

/// A parameter is out of its admissible range; names the parameter and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid parameter `{name}`: {reason}")]
pub struct ParamError {
    /// Field of the model's parameter struct, dotted for nested ones (`carbody.mass_kg`).
    pub name: &'static str,
    /// Why it was rejected.
    pub reason: String,
}

impl ParamError {
    /// The error for field `name`.
    pub fn new(name: &'static str, reason: impl Into<String>) -> Self {
        Self {
            name,
            reason: reason.into(),
        }
    }
}

/// The physics names the parameter it rejects (a field of the parameter struct); the FMI glue
/// reports it under the FMI variable bound to that field.
impl FieldError for ParamError {
    fn field(&self) -> Option<&str> {
        Some(self.name)
    }

    fn reason(&self) -> String {
        self.reason.clone()
    }
}

/// `v` is finite.
pub fn finite(name: &'static str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ParamError::new(name, format!("must be finite, got {v}")))
    }
}

/// `v` is finite and > 0.
pub fn positive(name: &'static str, v: f64) -> Result<(), ParamError> {
    finite(name, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, format!("must be > 0, got {v}")))
    }
}

/// `v` is finite and >= 0.
pub fn non_negative(name: &'static str, v: f64) -> Result<(), ParamError> {
    finite(name, v)?;
    if v >= 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, format!("must be >= 0, got {v}")))
    }
}

/// `v` is finite and within [lo, hi]; `why` says where the bounds come from.
pub fn in_range(name: &'static str, v: f64, lo: f64, hi: f64, why: &str) -> Result<(), ParamError> {
    finite(name, v)?;
    if v >= lo && v <= hi {
        Ok(())
    } else {
        Err(ParamError::new(
            name,
            format!("must be within [{lo}, {hi}] ({why}), got {v}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_field_and_the_bound() {
        assert_eq!(finite("a", 1.0), Ok(()));
        let e = finite("a", f64::NAN).unwrap_err();
        assert_eq!(
            (e.name, e.reason.as_str()),
            ("a", "must be finite, got NaN")
        );
        assert_eq!(positive("b", 0.0).unwrap_err().reason, "must be > 0, got 0");
        assert_eq!(
            positive("b", f64::INFINITY).unwrap_err().reason,
            "must be finite, got inf"
        );
        assert_eq!(non_negative("c", 0.0), Ok(()));
        assert_eq!(
            non_negative("c", -1.0).unwrap_err().reason,
            "must be >= 0, got -1"
        );
        assert_eq!(in_range("d", 1.0, 0.0, 1.0, "why"), Ok(()));
        assert_eq!(
            in_range("d", 2.0, 0.0, 1.0, "why").unwrap_err().to_string(),
            "invalid parameter `d`: must be within [0, 1] (why), got 2"
        );
        assert_eq!(FieldError::field(&ParamError::new("x.y", "r")), Some("x.y"));
    }
}
