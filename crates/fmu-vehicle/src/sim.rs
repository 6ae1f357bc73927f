//! Closed loop with the stand-in yaw damper law of `vehicle-elements` evaluated beside the
//! model, co-simulation style (each damper's force from the outputs of the previous step,
//! held over the step). Used by the calibration and convergence tests; the coupled runs with
//! the hydraulic damper FMUs happen in the master.

pub use vehicle_elements::LoopDamper;
use vehicle_elements::{damper, ClosedLoopModel};

use crate::layout::N_DAMPERS;
use crate::model::{Inputs, Outputs, StepError, Vehicle};

/// The coach's four yaw-damper ports (front left, front right, rear left, rear right).
impl ClosedLoopModel<N_DAMPERS> for Vehicle {
    type Inputs = Inputs;
    type Outputs = Outputs;
    type Error = StepError;

    fn time_s(&self) -> f64 {
        Vehicle::time_s(self)
    }

    fn outputs(&self, inputs: &Inputs) -> Result<Outputs, StepError> {
        Vehicle::outputs(self, inputs)
    }

    fn step(&mut self, h_s: f64, inputs: &Inputs) -> Result<Outputs, StepError> {
        Vehicle::step(self, h_s, inputs)
    }

    fn set_track_lateral_m(inputs: &mut Inputs, track_lateral_m: f64) {
        inputs.track_lateral_m = track_lateral_m;
    }

    fn damper_motion(o: &Outputs) -> [(f64, f64); N_DAMPERS] {
        o.damper
            .map(|d| (d.elongation_m, d.elongation_velocity_mps))
    }

    fn set_damper_force_n(inputs: &mut Inputs, force_n: [f64; N_DAMPERS]) {
        inputs.damper_force_n = force_n;
    }
}

/// Runs `t_end` seconds with communication step h, the track input from `track_lateral_m`
/// (time -> alignment under the leading wheelset); calls `record` with every output.
pub fn run_closed_loop(
    vehicle: &mut Vehicle,
    damper: LoopDamper,
    h: f64,
    t_end: f64,
    track_lateral_m: &dyn Fn(f64) -> f64,
    record: &mut dyn FnMut(&Outputs),
) -> Result<(), StepError> {
    damper::run_closed_loop(vehicle, damper, h, t_end, track_lateral_m, record)
}
