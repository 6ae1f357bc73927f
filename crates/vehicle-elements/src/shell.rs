//! What the FMU shells of the two rail-vehicle models do alike: hold the inputs, build the
//! physics at initialisation (previewing its outputs before), evaluate its outputs and take a
//! host step on it, with the physics' errors in the FMU's language.

use model_description::{
    field_error, rename_fields_of, FieldError, FmuModel, ModelError, StepError,
};
use serde::{Deserialize, Serialize};

use crate::step::{host_step, InputError, MAX_SUBSTEPS};
use crate::substep::MIN_SUBSTEP_S;

/// A rail-vehicle model's physics as its FMU shell drives it.
pub trait ShellPhysics: Clone + Sized {
    /// Parameters the physics is built from.
    type Params: Clone;
    /// Inputs held over a step.
    type Inputs: Default;
    /// Outputs of an evaluation or a step.
    type Outputs: Default;
    /// Refused parameters.
    type BuildError: FieldError;
    /// A failed evaluation or step.
    type StepError: std::fmt::Display;

    /// `params` as the preview before initialisation uses them: ideal track, built-in contact
    /// table (no file is read, no input is needed).
    fn preview_params(params: &Self::Params) -> Self::Params;
    /// The physics of `params`.
    fn build(params: Self::Params) -> Result<Self, Self::BuildError>;
    /// Outputs of the current state with `inputs`.
    fn outputs(&self, inputs: &Self::Inputs) -> Result<Self::Outputs, Self::StepError>;
    /// One step of `h` \[s\] with `inputs` held; the physics is unchanged when it fails.
    fn step(&mut self, h: f64, inputs: &Self::Inputs) -> Result<Self::Outputs, Self::StepError>;
    /// The step or input refused in `e`, if that is what it is.
    fn input_error(e: &Self::StepError) -> Option<&InputError>;
    /// Whether `e` is a diverged state (which a smaller step may avoid).
    fn diverged(e: &Self::StepError) -> bool;
    /// The largest internal sub-step of the integration \[s\].
    fn substep_s(&self) -> f64;
}

/// Implements [`ShellPhysics`] in a model crate whose physics has the inherent `new(params)`,
/// `outputs(&inputs)` and `step(h, &inputs)`, whose parameters have the fields `track` and
/// `contact` (the built-in table being `$contact::WornSurrogate`) and whose step error has the
/// variants `Input(InputError)` and `Diverged { .. }`:
///
/// ```ignore
/// vehicle_elements::shell_physics!(Bogie: Params, Inputs, Outputs, ModelError, StepError, ContactSource);
/// ```
#[macro_export]
macro_rules! shell_physics {
    ($physics:ident: $params:ident, $inputs:ty, $outputs:ty, $build_error:ty, $step_error:ident, $contact:ident) => {
        impl $crate::ShellPhysics for $physics {
            type Params = $params;
            type Inputs = $inputs;
            type Outputs = $outputs;
            type BuildError = $build_error;
            type StepError = $step_error;

            fn preview_params(params: &$params) -> $params {
                $params {
                    track: $crate::track::TrackSource::None,
                    contact: $contact::WornSurrogate,
                    ..params.clone()
                }
            }

            fn build(params: $params) -> Result<Self, $build_error> {
                $physics::new(params)
            }

            fn outputs(&self, inputs: &$inputs) -> Result<$outputs, $step_error> {
                $physics::outputs(self, inputs)
            }

            fn step(&mut self, h: f64, inputs: &$inputs) -> Result<$outputs, $step_error> {
                $physics::step(self, h, inputs)
            }

            fn input_error(e: &$step_error) -> Option<&$crate::InputError> {
                match e {
                    $step_error::Input(i) => Some(i),
                    _ => None,
                }
            }

            fn diverged(e: &$step_error) -> bool {
                matches!(e, $step_error::Diverged { .. })
            }

            fn substep_s(&self) -> f64 {
                $physics::substep_s(self)
            }
        }
    };
}

/// A failed evaluation or step, reported under the FMI input it names (if any).
struct StepFault<'a, P: ShellPhysics>(&'a P::StepError);

impl<P: ShellPhysics> std::fmt::Display for StepFault<'_, P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl<P: ShellPhysics> FieldError for StepFault<'_, P> {
    fn field(&self) -> Option<&str> {
        P::input_error(self.0).and_then(|i| i.field())
    }

    fn reason(&self) -> String {
        match P::input_error(self.0) {
            Some(i) => i.reason(),
            None => self.0.to_string(),
        }
    }
}

/// The part of a rail-vehicle FMU that does not depend on its parameters' FMI form: the held
/// inputs, the physics (built at initialisation) and its last outputs.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(bound(
    serialize = "P: Serialize, P::Inputs: Serialize, P::Outputs: Serialize",
    deserialize = "P: Deserialize<'de>, P::Inputs: Deserialize<'de>, P::Outputs: Deserialize<'de>"
))]
pub struct Shell<P: ShellPhysics> {
    /// Inputs as last set.
    pub inputs: P::Inputs,
    /// The physics, from fmi2ExitInitializationMode on.
    pub physics: Option<P>,
    /// Outputs of the last evaluation or step.
    pub out: P::Outputs,
}

impl<P: ShellPhysics> Shell<P> {
    /// No physics yet, default inputs, outputs previewed from `params`.
    pub fn new(params: &P::Params) -> Self {
        let mut shell = Self {
            inputs: P::Inputs::default(),
            physics: None,
            out: P::Outputs::default(),
        };
        shell.preview(params);
        shell
    }

    /// Outputs before initialisation (the state of the start values on ideal track with the
    /// built-in table): indicative only; parameters are validated at
    /// fmi2ExitInitializationMode, so a refused set keeps the last outputs.
    pub fn preview(&mut self, params: &P::Params) {
        if let Ok(p) = P::build(P::preview_params(params)) {
            if let Ok(o) = p.outputs(&self.inputs) {
                self.out = o;
            }
        }
    }

    /// Takes the physics built at initialisation with its outputs; errors are those of FMU
    /// model `M`.
    pub fn initialize<M: FmuModel>(&mut self, physics: P) -> Result<(), ModelError> {
        self.out = physics
            .outputs(&self.inputs)
            .map_err(|e| field_error::<M>(&StepFault::<P>(&e)))?;
        self.physics = Some(physics);
        Ok(())
    }

    /// Outputs of the physics with the current inputs, or the preview from `params` before
    /// initialisation.
    pub fn update_outputs<M: FmuModel>(&mut self, params: &P::Params) -> Result<(), ModelError> {
        match &self.physics {
            Some(p) => {
                self.out = p
                    .outputs(&self.inputs)
                    .map_err(|e| field_error::<M>(&StepFault::<P>(&e)))?
            }
            None => self.preview(params),
        }
        Ok(())
    }

    /// One host step of `step_s` of FMU model `M` (see [`host_step`]). A diverged state or an
    /// unusable step size may be avoided with a smaller step (fmi2Discard); a non-finite input
    /// (named) or any other failure cannot (fmi2Error). The physics is unchanged after either.
    pub fn do_step<M: FmuModel>(&mut self, step_s: f64) -> Result<(), StepError> {
        let Some(p) = &mut self.physics else {
            return Err(StepError::Error(ModelError::Other(
                "the physics is built in fmi2ExitInitializationMode; no step before it".into(),
            )));
        };
        // a bounded time per call: parameters that need a very short sub-step (a light body
        // on stiff springs) would compute a long step for hours
        // a model refuses parameters that need a sub-step below MIN_SUBSTEP_S: a shorter one
        // comes from a corrupted FMU state, which a shorter communication step does not mend
        if p.substep_s().is_nan() || p.substep_s() < MIN_SUBSTEP_S {
            return Err(StepError::Error(ModelError::Other(format!(
                "internal sub-step {:?} s is below the shortest a model builds ({MIN_SUBSTEP_S} \
                 s): the internal sub-step comes from a corrupted FMU state",
                p.substep_s()
            ))));
        }
        let substeps = step_s / p.substep_s();
        if substeps > MAX_SUBSTEPS as f64 {
            return Err(StepError::Discard(format!(
                "a step of {step_s:?} s takes {substeps:.2e} internal sub-steps of {:?} s, \
                 more than the {MAX_SUBSTEPS} one call computes: take shorter communication \
                 steps",
                p.substep_s()
            )));
        }
        let inputs = &self.inputs;
        let map = |e: P::StepError| match P::input_error(&e) {
            _ if P::diverged(&e) => StepError::Discard(rename_fields_of::<M>(&e.to_string())),
            Some(InputError::InvalidStep { .. }) => StepError::Discard(e.to_string()),
            Some(InputError::TooManySubsteps { .. }) => StepError::Error(ModelError::Other(
                format!("{e} (the internal sub-step comes from a corrupted FMU state)"),
            )),
            Some(InputError::NonFiniteInput { .. }) => {
                StepError::Error(field_error::<M>(&StepFault::<P>(&e)))
            }
            None => StepError::Error(ModelError::Other(rename_fields_of::<M>(&e.to_string()))),
        };
        self.out = host_step(p, step_s, |p, h| p.step(h, inputs)).map_err(map)?;
        Ok(())
    }
}
