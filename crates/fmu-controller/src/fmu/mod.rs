//! FMI 2.0 co-simulation shells over the control laws (thin: all physics lives in
//! [`crate::mppt`], [`crate::skyhook`], [`crate::idf`]; the FMI machinery in `model-description`).
//!
//! * [`MpptController`]: MPPT valve control (3.2)-(3.5);
//! * [`SkyHookController`]: sky-hook on/off (3.13) and continuous (3.11);
//! * [`IdealDamperForceController`]: ideal damper force (3.14)-(3.15).
//!
//! Common behaviour (also in each FMU's documentation):
//! * the board samples at `start_time + k * sample_time`; the command computed from the inputs
//!   sampled at `t_k` becomes the output at `t_{k+1}` (one sample of computational delay), so no
//!   output depends on an input at the same instant: every output declares no direct
//!   feedthrough (`dependencies=""`), and a controller never closes an algebraic loop;
//! * NaN/inf inputs are rejected by the glue when they are set (fmi2Error, variable named in the
//!   log). The physics' hold-and-warn path (dropped samples, held command) therefore only
//!   reports internal faults; it is still logged (warning when a fault starts, event when it ends);
//! * a non-finite output of the physics (impossible within the declared ranges) ends the run
//!   with fmi2Error;
//! * logging is on change only: controller updates, overrides, saturation and switching are
//!   reported when they start or stop, never once per sample.

mod idf;
mod mppt;
mod skyhook;

pub use idf::IdealDamperForceController;
pub use mppt::MpptController;
pub use skyhook::SkyHookController;

use model_description::{ModelError, StepError};

use crate::{ParamError, StepError as PhysicsStepError};

/// Author string written to every modelDescription.xml of this crate.
const AUTHOR: &str = "rail-fmu project (fmu-controller)";

/// A physics parameter error, renamed to the FMI variable through `map` (physics field name ->
/// FMI name); unknown fields keep their physics name.
fn param_error(e: ParamError, map: &[(&str, &str)]) -> ModelError {
    let name = map
        .iter()
        .find(|(field, _)| *field == e.name)
        .map_or(e.name, |(_, fmi)| *fmi);
    ModelError::InvalidParameter {
        name: name.to_string(),
        reason: e.reason,
    }
}

fn invalid(name: impl Into<String>, reason: impl Into<String>) -> ModelError {
    ModelError::InvalidParameter {
        name: name.into(),
        reason: reason.into(),
    }
}

/// A failed physics step. Inputs are finite (the glue checks them at set time) and the step is
/// finite and positive (the glue checks it too), so the only realistic case is a non-finite
/// output: the controller state is then garbage and the run cannot go on (fmi2Error).
fn step_error(e: PhysicsStepError, inputs: &[(&str, &str)]) -> StepError {
    match e {
        PhysicsStepError::NonFiniteInput { name, value } => {
            let fmi = inputs
                .iter()
                .find(|(field, _)| *field == name)
                .map_or(name, |(_, fmi)| *fmi);
            StepError::Error(ModelError::InvalidInput {
                name: fmi.to_string(),
                reason: format!("not finite ({value})"),
            })
        }
        other => StepError::Error(ModelError::Other(other.to_string())),
    }
}

/// Integer parameter holding +1 / -1 (declared with range [-1, 1]; 0 is rejected at
/// initialisation by the physics' validation).
fn sign_to_int(x: f64) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(
    MpptController,
    SkyHookController,
    IdealDamperForceController
);
