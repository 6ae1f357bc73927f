//! FMI 2.0 co-simulation shells over the damper physics (thin: the physics lives in
//! [`crate::semi_active`], [`crate::valve`], [`crate::full_active`]; the FMI machinery in
//! `model-description`).
//!
//! * [`SemiActiveDamper`]: semi-active yaw damper (3.38)-(3.45) with the by-pass valve command;
//! * [`PassiveYawDamper`]: the same damper with the valve fixed at 30 % (seed section 4.3);
//! * [`FullActiveActuator`]: full-active hydraulic actuator (3.46)-(3.66), rod imposed by the
//!   vehicle.
//!
//! Common behaviour (also in each FMU's documentation):
//! * force outputs are positive in **tension** (opposing extension) for every model;
//! * parameters are fixed; strictly positive quantities are declared with `min = 0` (FMI bounds
//!   are inclusive): a negative value is rejected when it is set, zero (and every cross-parameter
//!   condition) at `fmi2ExitInitializationMode` by the physics' validation, both naming the FMI
//!   variable;
//! * a step is computed on a copy of the physics and committed only on success: an integrator
//!   failure returns `fmi2Discard` with the state unchanged;
//! * NaN/inf inputs cannot arrive (the glue rejects them at set time); a non-finite result of the
//!   physics is never returned as a number.

/// The "Failed steps" section of the damper FMUs' documentation (the same behaviour for both:
/// the glue's fmi2Discard path over the physics' atomic steps).
macro_rules! failed_steps_doc {
    () => {
        r#"<h2>Failed steps</h2>
<p>A communication step that cannot be completed returns <b>fmi2Discard</b> with a logged
message (category logStatusDiscard) and leaves the model exactly as before the step: outputs
stay the last finite values, never NaN or inf. Two causes exist: the integrator's work bound
<code>solver.max_internal_steps</code> is reached (set it to bound the time of one fmi2DoStep on a
real-time host; the default 20000 is far above need), or an absurd but finite input makes a
state or output overflow (e.g. an elongation velocity of 1e300 m/s). The instance is then in
FMI's stepFailed state: restore an FMU state saved before the step (fmi2SetFMUstate) and retry,
with a smaller communication step or corrected inputs. Bad parameters or inputs detected by the
physics end the run with fmi2Error instead.</p>
"#
    };
}
pub(crate) use failed_steps_doc;

mod actuator;
mod semi;

pub use actuator::FullActiveActuator;
pub use semi::{PassiveYawDamper, SemiActiveDamper};

use model_description::{ModelError, StepError};

use crate::error::{ParamError, StepError as PhysicsStepError};

/// Author string written to every modelDescription.xml of this crate.
const AUTHOR: &str = "rail-fmu project (fmu-damper)";

/// Name of the physics field carried by a parameter error.
fn param_field(e: &ParamError) -> &'static str {
    match e {
        ParamError::NotFinite { name, .. }
        | ParamError::NotPositive { name, .. }
        | ParamError::Negative { name, .. }
        | ParamError::OutOfRange { name, .. } => name,
    }
}

/// Physics field name -> FMI variable name (unknown fields keep their physics name).
fn fmi_name(field: &'static str, map: &[(&'static str, &'static str)]) -> &'static str {
    map.iter()
        .find(|(f, _)| *f == field)
        .map_or(field, |(_, fmi)| *fmi)
}

/// `text` with every physics field name (a whole identifier token) replaced by its FMI name,
/// so messages such as "must exceed area_b_m2 * half_stroke_m" speak the FMU's language.
fn rename_fields(text: &str, map: &[(&'static str, &'static str)]) -> String {
    let is_ident = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.';
    let mut out = String::with_capacity(text.len() + 16);
    let mut rest = text;
    while let Some(start) = rest.find(is_ident) {
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let len = tail.find(|c: char| !is_ident(c)).unwrap_or(tail.len());
        // A sentence's full stop is not part of the name.
        let token = tail[..len].trim_end_matches('.');
        let token = if token.is_empty() {
            &tail[..len]
        } else {
            token
        };
        out.push_str(
            map.iter()
                .find(|(f, _)| *f == token)
                .map_or(token, |(_, fmi)| *fmi),
        );
        rest = &tail[token.len()..];
    }
    out.push_str(rest);
    out
}

/// A physics parameter error, renamed to the FMI variable.
fn param_error(e: &ParamError, map: &[(&'static str, &'static str)]) -> ModelError {
    let name = fmi_name(param_field(e), map);
    // The physics message names its fields; say which FMI variables those are.
    ModelError::InvalidParameter {
        name: name.to_string(),
        reason: rename_fields(&e.to_string(), map),
    }
}

/// A physics error outside a step (initialisation, output evaluation).
fn model_error(e: &PhysicsStepError, map: &[(&'static str, &'static str)]) -> ModelError {
    match e {
        PhysicsStepError::BadInput { name, value } => ModelError::InvalidInput {
            name: fmi_name(name, map).to_string(),
            reason: format!("not finite ({value})"),
        },
        PhysicsStepError::Param(p) => param_error(p, map),
        other => ModelError::Other(other.to_string()),
    }
}

/// A failed physics step: an integrator failure or a non-finite state may go away with a
/// smaller communication step (fmi2Discard, state unchanged); anything else ends the run.
fn step_error(e: &PhysicsStepError, map: &[(&'static str, &'static str)]) -> StepError {
    match e {
        PhysicsStepError::Integration { .. } | PhysicsStepError::NonFinite { .. } => {
            StepError::Discard(e.to_string())
        }
        other => StepError::Error(model_error(other, map)),
    }
}

/// Name, description and range of the integer parameter bounding the integrator's work.
const MAX_STEPS_NAME: &str = "solver.max_internal_steps";
const MAX_STEPS_DESCRIPTION: &str =
    "Maximum number of internal integrator steps (accepted + rejected) per communication step: \
     bounds the work of one fmi2DoStep (real-time/HIL hosts). Reaching it returns fmi2Discard \
     with a logged message and the state unchanged (restore an FMU state and retry with a \
     smaller communication step). Default 20000, far above need (1-50 per 1 ms step)";
const MAX_STEPS_RANGE: (f64, f64) = (1.0, i32::MAX as f64);

/// The physics' step limit as an FMI Integer (saturating).
fn steps_to_fmi(n: u32) -> i32 {
    i32::try_from(n).unwrap_or(i32::MAX)
}

/// An FMI Integer as the physics' step limit (the declared range keeps it >= 1; anything
/// else becomes 0, which the physics' validation rejects by name).
fn steps_from_fmi(x: i32) -> u32 {
    u32::try_from(x).unwrap_or(0)
}

fn not_initialised() -> StepError {
    StepError::Error(ModelError::Other(
        "the physics is built in fmi2ExitInitializationMode; no step before it".into(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_names_are_renamed_as_whole_tokens() {
        let map = [
            ("area_b_m2", "cylinder.area_b"),
            ("half_stroke_m", "cylinder.half_stroke"),
        ];
        assert_eq!(
            rename_fields(
                "`x` must be > area_b_m2 * half_stroke_m. area_b_m2x ...",
                &map
            ),
            "`x` must be > cylinder.area_b * cylinder.half_stroke. area_b_m2x ..."
        );
        assert_eq!(rename_fields("", &map), "");
    }
}

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(SemiActiveDamper, PassiveYawDamper, FullActiveActuator);
