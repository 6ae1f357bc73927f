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
pub use semi::{PassiveYawDamper, SemiActiveDamper, PLAUSIBLE_VELOCITY_MPS};

use model_description::{
    field_error, rename_fields_of, FieldError, FmuModel, ModelError, StepError,
};

use crate::error::{ParamError, StepError as PhysicsStepError};

/// Author string written to every modelDescription.xml of this crate.
const AUTHOR: &str = "rail-fmu project (fmu-damper)";

/// The physics names the parameter it rejects; the glue reports it under the FMI variable bound
/// to that field.
impl FieldError for ParamError {
    fn field(&self) -> Option<&str> {
        match self {
            ParamError::NotFinite { name, .. }
            | ParamError::NotPositive { name, .. }
            | ParamError::Negative { name, .. }
            | ParamError::OutOfRange { name, .. } => Some(name),
        }
    }
}

impl FieldError for PhysicsStepError {
    fn field(&self) -> Option<&str> {
        match self {
            PhysicsStepError::BadInput { name, .. } => Some(name),
            PhysicsStepError::BeyondStroke { .. } => Some("elongation_m"),
            PhysicsStepError::Param(p) => p.field(),
            _ => None,
        }
    }

    fn reason(&self) -> String {
        match self {
            PhysicsStepError::BadInput { value, .. } => format!("not finite ({value})"),
            other => other.to_string(),
        }
    }
}

/// A failed physics step of model `M`: an integrator failure or a non-finite state may go away
/// with a smaller communication step (fmi2Discard, state unchanged); anything else ends the run.
fn step_error<M: FmuModel>(e: &PhysicsStepError) -> StepError {
    match e {
        PhysicsStepError::Integration { .. } | PhysicsStepError::NonFinite { .. } => {
            StepError::Discard(rename_fields_of::<M>(&e.to_string()))
        }
        other => StepError::Error(field_error::<M>(other)),
    }
}

/// The parameters every damper FMU gained after its first release, declared last so the other
/// value references stay put; `$($shell).+` is the path to the physics parameters.
macro_rules! declare_appended_parameters {
    ($v:ident, $($shell:ident).+) => {
        model_description::declare! { $v;
            /// Maximum number of internal integrator steps (accepted + rejected) per
            /// communication step: bounds the work of one fmi2DoStep (real-time/HIL hosts).
            /// Reaching it returns fmi2Discard with a logged message and the state unchanged
            /// (restore an FMU state and retry with a smaller communication step). Default
            /// 20000, far above need (1-50 per 1 ms step)
            parameter "solver.max_internal_steps" [range = 1.0..=2147483647.0] => $($shell).+.solver.max_internal_steps;
            /// k_m: stiffness of the damper's installation (mountings, bushes) in series with it,
            /// 0 = rigid (default); MPE 2019: about 10 MN/m for a yaw damper
            parameter "damper.mounting_stiffness" [unit = "N/m", display_unit = "MN/m", min = 0.0] => $($shell).+.mounting_stiffness_n_per_m as model_description::ZeroIsNone;
        }
    };
}
pub(crate) use declare_appended_parameters;

/// [`model_description::FmuModel::check_restored`] of a shell whose physics (`what`, built
/// or not yet) must be the one its declared parameters give.
fn restored_physics(built_from_parameters: Option<bool>, what: &str) -> Result<(), String> {
    match built_from_parameters {
        Some(false) => Err(format!(
            "the {what}'s physics is not the one its declared parameters give (parameters \
             altered, or not valid)"
        )),
        _ => Ok(()),
    }
}

fn not_initialised() -> StepError {
    StepError::Error(ModelError::Other(
        "the physics is built in fmi2ExitInitializationMode; no step before it".into(),
    ))
}

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(SemiActiveDamper, PassiveYawDamper, FullActiveActuator);
