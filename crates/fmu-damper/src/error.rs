//! Error types. Every error names the offending parameter or input so an FMU shell
//! can log it verbatim.

use thiserror::Error;

/// A parameter set failed validation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// The parameter is NaN or infinite.
    #[error("parameter `{name}` is not finite ({value})")]
    NotFinite { name: &'static str, value: f64 },
    /// The parameter must be strictly positive.
    #[error("parameter `{name}` must be > 0 (got {value})")]
    NotPositive { name: &'static str, value: f64 },
    /// The parameter must be non-negative.
    #[error("parameter `{name}` must be >= 0 (got {value})")]
    Negative { name: &'static str, value: f64 },
    /// The parameter lies outside its admissible range.
    #[error("parameter `{name}` = {value} is out of range: {reason}")]
    OutOfRange {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
}

/// A step (or an output evaluation) could not be completed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// An input is NaN or infinite.
    #[error("input `{name}` is not finite ({value})")]
    BadInput { name: &'static str, value: f64 },
    /// The communication step size is not usable.
    #[error("step size h = {h} s is not finite and > 0")]
    BadStepSize { h: f64 },
    /// The internal integrator could not complete the step.
    #[error("integration failed at t+{at_s} s of the step: {reason}")]
    Integration { at_s: f64, reason: &'static str },
    /// A state or output became non-finite (never returned as a number).
    #[error("non-finite value in `{name}`")]
    NonFinite { name: &'static str },
    /// The actuator's rod left its cylinder: the model has no end stops, so beyond the
    /// stroke it has no meaning (the model is unchanged).
    #[error(
        "the rod would be at {rod_mm:.1} mm, beyond the cylinder's half stroke of \
         {half_stroke_mm:.1} mm (the elongation, less the mounting's extension, must stay \
         within the stroke)"
    )]
    BeyondStroke { rod_mm: f64, half_stroke_mm: f64 },
    /// The parameters held by the model are invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
}

/// Checks a parameter is finite and > 0.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), ParamError> {
    if !value.is_finite() {
        Err(ParamError::NotFinite { name, value })
    } else if value <= 0.0 {
        Err(ParamError::NotPositive { name, value })
    } else {
        Ok(())
    }
}

/// Checks a parameter is finite and >= 0.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<(), ParamError> {
    if !value.is_finite() {
        Err(ParamError::NotFinite { name, value })
    } else if value < 0.0 {
        Err(ParamError::Negative { name, value })
    } else {
        Ok(())
    }
}

/// Checks a parameter is finite and within `[lo, hi]`.
pub(crate) fn in_range(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    reason: &'static str,
) -> Result<(), ParamError> {
    if !value.is_finite() {
        Err(ParamError::NotFinite { name, value })
    } else if value < lo || value > hi {
        Err(ParamError::OutOfRange {
            name,
            value,
            reason,
        })
    } else {
        Ok(())
    }
}

/// Checks an input is finite.
pub(crate) fn finite_input(name: &'static str, value: f64) -> Result<(), StepError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(StepError::BadInput { name, value })
    }
}

/// Checks an analysis argument is finite and > 0.
pub(crate) fn positive_input(name: &'static str, value: f64) -> Result<(), StepError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(StepError::BadInput { name, value })
    }
}

/// Checks an analysis opening argument lies in [0, 1].
pub(crate) fn check_opening_input(name: &'static str, value: f64) -> Result<(), StepError> {
    if value.is_finite() && (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(StepError::BadInput { name, value })
    }
}
