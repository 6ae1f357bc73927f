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

/// `exit_initialization`, `update_outputs` and `do_step` of a board FMU, the same for the three
/// controllers (inside `impl FmuModel`). The model provides the field `board` (a [`Board`]) and
/// the methods `build()` (controller and outputs from the parameters), `reported_after_init()`
/// (what the log counts as already reported at the start) and `report(t_end, &out, diag)` (log
/// changes).
///
/// `board_life_cycle!(instantiate)` also writes `instantiate`: the law's default parameters
/// (the single source of the start values), for a model whose fields are `params` and `board`.
macro_rules! board_life_cycle {
    (instantiate) => {
        fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
            let params = Default::default();
            Ok(Self {
                board: $crate::fmu::Board::new::<Self>(&params)?,
                params,
            })
        }

        board_life_cycle!();
    };
    () => {
        fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
            self.build()?;
            self.board.reported = self.reported_after_init();
            self.board.initialized = true;
            Ok(())
        }

        fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
            // No output depends on the current inputs (one-sample board delay). In
            // initialization mode, preview the initial outputs of the parameters set so far;
            // invalid values are reported by exit_initialization.
            if !self.board.initialized {
                let _ = self.build();
            }
            Ok(())
        }

        fn do_step(
            &mut self,
            time: f64,
            step: f64,
            diag: &mut Diagnostics,
        ) -> Result<(), StepError> {
            let board = &mut self.board;
            let out = board
                .ctrl
                .step(step, &board.inputs)
                .map_err(|e| $crate::fmu::step_error::<Self>(&e))?;
            self.report(time + step, &out, diag);
            self.board.out = out;
            Ok(())
        }
    };
}

/// The two status outputs every board declares last, after its own (inside `variables()`):
/// `$fault_doc` describes `board.input_fault` for that board (default: any input).
macro_rules! declare_board_status {
    ($v:ident) => {
        declare_board_status!(
            $v,
            " True if an input of the last step was not finite (sample dropped, command held)"
        );
    };
    ($v:ident, $fault_doc:literal) => {
        model_description::declare! { $v;
            #[doc = $fault_doc]
            output "board.input_fault" => board.out.input_fault;
            /// Board samples dropped because of non-finite inputs since the start
            output "board.dropped_samples" => board.out.dropped_samples;
        }
    };
}

mod idf;
mod mppt;
mod skyhook;

pub use idf::IdealDamperForceController;
pub use mppt::MpptController;
pub use skyhook::SkyHookController;

use model_description::{
    field_error, rename_fields_of, Diagnostics, FieldError, FmuModel, ModelError, StepError,
};
use serde::{Deserialize, Serialize};

use crate::{ParamError, StepError as PhysicsStepError};

/// A board's control law as its FMU builds it: from its parameters, with its outputs at the
/// start (its step is the law's own `step(h, &inputs)`).
trait BoardLaw: Sized {
    type Params: Clone;
    type Inputs: Default;
    type Outputs;
    fn new(params: Self::Params) -> Result<Self, ParamError>;
    fn outputs(&self) -> Self::Outputs;
}

/// [`BoardLaw`] for a law whose inherent `new` and `outputs` have its types.
macro_rules! board_law {
    ($law:ty, $params:ty, $inputs:ty, $outputs:ty) => {
        impl BoardLaw for $law {
            type Params = $params;
            type Inputs = $inputs;
            type Outputs = $outputs;
            fn new(params: $params) -> Result<Self, ParamError> {
                <$law>::new(params)
            }
            fn outputs(&self) -> $outputs {
                <$law>::outputs(self)
            }
        }
    };
}

board_law!(
    crate::Idf,
    crate::IdfParams,
    crate::IdfInputs,
    crate::IdfOutputs
);
board_law!(
    crate::Mppt,
    crate::MpptParams,
    crate::MpptInputs,
    crate::MpptOutputs
);
board_law!(
    crate::SkyHook,
    crate::SkyHookParams,
    crate::SkyHookInputs,
    crate::SkyHookOutputs
);

/// What a board FMU holds beside its parameters: the sampled inputs, the law `L`, its last
/// outputs, whether initialisation is over, and `R`, what its log last reported.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(bound(
    serialize = "L: Serialize, L::Inputs: Serialize, L::Outputs: Serialize, R: Serialize",
    deserialize = "L: Deserialize<'de>, L::Inputs: Deserialize<'de>, L::Outputs: Deserialize<'de>, \
                   R: Deserialize<'de>"
))]
struct Board<L: BoardLaw, R> {
    inputs: L::Inputs,
    ctrl: L,
    out: L::Outputs,
    /// Set by exit_initialization; before it the outputs preview the parameters being set.
    initialized: bool,
    reported: R,
}

impl<L: BoardLaw, R: Default> Board<L, R> {
    /// The law of FMU `M` from `params` with its initial outputs, default inputs, nothing
    /// reported yet.
    fn new<M: FmuModel>(params: &L::Params) -> Result<Self, ModelError> {
        let ctrl = L::new(params.clone()).map_err(|e| field_error::<M>(&e))?;
        Ok(Self {
            inputs: L::Inputs::default(),
            out: ctrl.outputs(),
            ctrl,
            initialized: false,
            reported: R::default(),
        })
    }

    /// The law rebuilt from `params` with its initial outputs; a refused parameter is reported
    /// under FMU `M`'s variable.
    fn build<M: FmuModel>(&mut self, params: &L::Params) -> Result<(), ModelError> {
        self.ctrl = L::new(params.clone()).map_err(|e| field_error::<M>(&e))?;
        self.out = self.ctrl.outputs();
        Ok(())
    }
}

/// Author string written to every modelDescription.xml of this crate.
const AUTHOR: &str = "rail-fmu project (fmu-controller)";

/// The physics names the parameter it rejects (a field of its `*Params`); the glue reports it
/// under the FMI variable bound to that field.
impl FieldError for ParamError {
    fn field(&self) -> Option<&str> {
        Some(self.name)
    }

    fn reason(&self) -> String {
        self.reason.clone()
    }
}

impl FieldError for PhysicsStepError {
    fn field(&self) -> Option<&str> {
        match self {
            PhysicsStepError::NonFiniteInput { name, .. } => Some(name),
            _ => None,
        }
    }

    fn reason(&self) -> String {
        match self {
            PhysicsStepError::NonFiniteInput { value, .. } => format!("not finite ({value})"),
            other => other.to_string(),
        }
    }
}

/// A failed physics step of model `M`. Inputs are finite (the glue checks them at set time) and
/// the step is finite and positive (the glue checks it too). A step holding too many board
/// samples changed nothing, and a shorter one will do (fmi2Discard); otherwise an output
/// became non-finite: the controller state is then garbage and the run cannot go on
/// (fmi2Error).
fn step_error<M: FmuModel>(e: &PhysicsStepError) -> StepError {
    match e {
        PhysicsStepError::TooManySamples { .. } => {
            StepError::Discard(rename_fields_of::<M>(&e.to_string()))
        }
        _ => StepError::Error(field_error::<M>(e)),
    }
}

/// Log the start (warning) and the end (event) of the physics' hold path for non-finite
/// samples; `reported` is the state last logged.
fn report_input_fault(
    t_end: f64,
    input_fault: bool,
    dropped_samples: u64,
    reported: &mut bool,
    diag: &mut Diagnostics,
) {
    if input_fault != *reported {
        if input_fault {
            diag.warn(format!(
                "t = {t_end:.6} s: non-finite input, samples dropped and command held \
                 ({dropped_samples} dropped so far)"
            ));
        } else {
            diag.event(format!("t = {t_end:.6} s: inputs finite again"));
        }
        *reported = input_fault;
    }
}

#[cfg(feature = "fmi-export")]
model_description::export_fmus!(
    MpptController,
    SkyHookController,
    IdealDamperForceController
);
