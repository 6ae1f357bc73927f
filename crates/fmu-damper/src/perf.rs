//! Reference workloads of the damper models for benchmarks (the figures come from
//! `cargo bench -p fmu-damper --bench per_step` or from any bench command that calls
//! [`ns_per_step`]; tests never time anything).
//!
//! Each case drives one model as a bogie would in the coupled study: 1 ms communication
//! steps, a 3 mm stroke at 4 Hz (the hunting frequency, R6) plus a 0.2 mm ripple at 17 Hz so
//! that no two periods are the same; the semi-active damper with a valve command switching
//! between 2 and 8 V every 60 ms (as a sky-hook or MPPT board would), the actuator with an
//! IDF-like spool command of 0.6 mm in phase with the velocity.

use std::f64::consts::PI;

use model_description::timing::median_ns_per_step;

use crate::full_active::{Actuator, ActuatorInputs, ActuatorModel, ActuatorParams};
use crate::semi_active::{SemiActiveDamper, SemiActiveInputs, SemiActiveParams};
use crate::valve::ValveParams;
use crate::{ParamError, StepError};

/// Communication step of the reference cases \[s\].
pub const REFERENCE_STEP_S: f64 = 1e-3;

/// One reference case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DamperCase {
    /// Passive reference damper (semi-active at a fixed 30 % opening).
    Passive,
    /// Semi-active damper, ideal valve, switching command.
    SemiActiveIdealValve,
    /// Semi-active damper, slow (real) valve, switching command.
    SemiActiveRealValve,
    /// Full-active actuator, full order, rod imposed.
    ActuatorFullOrder,
    /// Full-active actuator, reduced order, rod imposed.
    ActuatorReducedOrder,
}

impl DamperCase {
    /// Every case, in report order.
    pub const ALL: [DamperCase; 5] = [
        DamperCase::Passive,
        DamperCase::SemiActiveIdealValve,
        DamperCase::SemiActiveRealValve,
        DamperCase::ActuatorFullOrder,
        DamperCase::ActuatorReducedOrder,
    ];

    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            DamperCase::Passive => "passive (30 % fixed)",
            DamperCase::SemiActiveIdealValve => "semi-active, ideal valve",
            DamperCase::SemiActiveRealValve => "semi-active, slow valve",
            DamperCase::ActuatorFullOrder => "actuator, full order",
            DamperCase::ActuatorReducedOrder => "actuator, reduced order",
        }
    }
}

/// Elongation \[m\] and its velocity [m/s] at step `k`.
pub fn stroke(k: u64) -> (f64, f64) {
    let t = k as f64 * REFERENCE_STEP_S;
    let (w1, w2) = (2.0 * PI * 4.0, 2.0 * PI * 17.0);
    (
        3e-3 * (w1 * t).sin() + 0.2e-3 * (w2 * t).sin(),
        3e-3 * w1 * (w1 * t).cos() + 0.2e-3 * w2 * (w2 * t).cos(),
    )
}

/// Valve command \[V\] at step `k`: 2 and 8 V alternating every 60 ms.
pub fn valve_command(k: u64) -> f64 {
    if (k / 60) % 2 == 1 {
        8.0
    } else {
        2.0
    }
}

/// Length of the precomputed input sequence (5 s; it repeats after that) \[steps\].
pub const INPUT_STEPS: usize = 5000;

/// The model of one case, ready to step, and its precomputed inputs (so the measured loop
/// holds no trigonometry).
#[derive(Debug, Clone)]
pub struct DamperWorkload {
    model: DamperModel,
    semi_inputs: Vec<SemiActiveInputs>,
    actuator_inputs: Vec<ActuatorInputs>,
}

#[derive(Debug, Clone)]
enum DamperModel {
    Semi(SemiActiveDamper),
    Actuator(Actuator),
}

/// Errors of a reference run.
#[derive(Debug, thiserror::Error)]
pub enum PerfError {
    /// The model could not be built.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

impl DamperWorkload {
    /// Model of `case` with its default parameters.
    pub fn new(case: DamperCase) -> Result<Self, PerfError> {
        let semi = |p: SemiActiveParams| SemiActiveDamper::new(p).map(DamperModel::Semi);
        let act = |model: ActuatorModel| {
            Actuator::new(ActuatorParams {
                model,
                ..ActuatorParams::default()
            })
            .map(DamperModel::Actuator)
        };
        let model = match case {
            DamperCase::Passive => semi(SemiActiveParams::passive_reference())?,
            DamperCase::SemiActiveIdealValve => semi(SemiActiveParams::default())?,
            DamperCase::SemiActiveRealValve => semi(SemiActiveParams {
                valve: ValveParams::real(),
                ..SemiActiveParams::default()
            })?,
            DamperCase::ActuatorFullOrder => act(ActuatorModel::FullOrder)?,
            DamperCase::ActuatorReducedOrder => act(ActuatorModel::ReducedOrder)?,
        };
        let (mut semi_inputs, mut actuator_inputs) = (Vec::new(), Vec::new());
        for k in 0..INPUT_STEPS as u64 {
            let (x, v) = stroke(k);
            match model {
                DamperModel::Semi(_) => semi_inputs.push(SemiActiveInputs {
                    elongation_m: x,
                    elongation_velocity_mps: v,
                    valve_command_v: valve_command(k),
                }),
                DamperModel::Actuator(_) => actuator_inputs.push(ActuatorInputs {
                    spool_command_m: 0.6e-3 * v / (3e-3 * 2.0 * PI * 4.0),
                    load_force_n: 0.0,
                    elongation_m: x,
                    elongation_velocity_mps: v,
                }),
            }
        }
        Ok(Self {
            model,
            semi_inputs,
            actuator_inputs,
        })
    }

    /// Steps `k0..k0 + steps` (inputs of step k: entry k mod [`INPUT_STEPS`]); returns the sum
    /// of the forces (keeps the work observable).
    #[inline(never)]
    pub fn run_steps(&mut self, k0: u64, steps: u64) -> Result<f64, PerfError> {
        let mut sum = 0.0;
        for k in k0..k0 + steps {
            let i = (k % INPUT_STEPS as u64) as usize;
            sum += match &mut self.model {
                DamperModel::Semi(d) => d.step(REFERENCE_STEP_S, &self.semi_inputs[i])?.force_n,
                DamperModel::Actuator(a) => {
                    a.step(REFERENCE_STEP_S, &self.actuator_inputs[i])?.force_n
                }
            };
        }
        Ok(sum)
    }
}

/// Warm-up before timing: 1 s (four stroke periods), so the state is periodic.
pub const WARM_UP_STEPS: u64 = 1000;

/// Wall-clock nanoseconds per 1 ms step of `case` on one core: the median of `repeats` runs of
/// `steps` steps each, after [`WARM_UP_STEPS`] untimed steps on the same model.
pub fn ns_per_step(case: DamperCase, steps: u64, repeats: usize) -> Result<f64, PerfError> {
    let mut model = DamperWorkload::new(case)?;
    model.run_steps(0, WARM_UP_STEPS)?;
    median_ns_per_step(WARM_UP_STEPS, steps, repeats, |k0, n| {
        model.run_steps(k0, n)
    })
}
